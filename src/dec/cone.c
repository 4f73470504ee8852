/* cone.c -- the chain homotopy of a collapsible complex
 * (doc/exterior-calculus.md §10).
 *
 * Greedy elementary collapses (a free face tau of a unique maximal coface
 * sigma, highest dimension first) reduce K to one vertex w; replaying the
 * pairs backwards defines the cone operator p: C_k -> C_{k+1},
 *   p(sigma) = 0,   p(tau) = c (sigma - sum_{rho in d sigma, rho != tau} [sigma:rho] p(rho)),
 * c = [sigma:tau] = +-1, p(w) = 0.  Then p d + d p = I on k-chains for
 * k >= 1 and d p(v) = v - w on vertices; its transpose H = p^T is the
 * homotopy operator on cochains: H d + d H = I (k >= 1), H d f = f - f(w).
 * All entries are integers. */
#include <config.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dec/dec.h"

typedef struct {
  int k, tau, sigma;
  double c;
} pair;

typedef struct {
  int *data, len, cap;
} ivec;

static int ipush(ivec *v, int x)
{
  if (v->len == v->cap) {
    int cap = v->cap ? 2 * v->cap : 64, *d = realloc(v->data, (size_t)cap * sizeof *d);
    if (d == NULL)
      return -1;
    v->data = d;
    v->cap = cap;
  }
  v->data[v->len++] = x;
  return 0;
}

int dm_dec_homotopy(const dm_dec_complex *K, dm_sparse **p, int *apex, dm_err *e)
{
  int n = K->n, k, s, q, st = DM_OK, npairs = 0, total = 0;
  dm_sparse *cof[DM_DEC_MAXDIM + 1] = {NULL};   /* cof[k] = d[k]^T: k-simplex -> cofaces */
  int *ncof[DM_DEC_MAXDIM + 1] = {NULL};
  unsigned char *alive[DM_DEC_MAXDIM + 1] = {NULL};
  ivec queue[DM_DEC_MAXDIM + 1];
  pair *pairs = NULL;
  double *acc = NULL;
  memset(queue, 0, sizeof queue);
  for (k = 0; k < n; k++)
    p[k] = NULL;
  for (k = 0; k <= n; k++) {
    total += K->nsimp[k];
    alive[k] = malloc((size_t)K->nsimp[k] + 1);
    ncof[k] = calloc((size_t)K->nsimp[k] + 1, sizeof *ncof[k]);
    if (alive[k] == NULL || ncof[k] == NULL)
      goto nomem;
    memset(alive[k], 1, (size_t)K->nsimp[k]);
    if (k < n) {
      if ((cof[k] = dm_sparse_transpose(K->d[k], e)) == NULL)
        goto fail;
      for (s = 0; s < K->nsimp[k]; s++) {
        ncof[k][s] = cof[k]->rowptr[s + 1] - cof[k]->rowptr[s];
        if (ncof[k][s] == 1 && ipush(&queue[k], s) != 0)
          goto nomem;
      }
    }
  }
  pairs = malloc(((size_t)total / 2 + 1) * sizeof *pairs);
  if (pairs == NULL)
    goto nomem;
  for (;;) {
    int tau = -1, sigma = -1, pp;
    for (k = n - 1; k >= 0 && tau < 0; k--)
      while (queue[k].len > 0 && tau < 0) {
        int t = queue[k].data[--queue[k].len];
        if (!alive[k][t] || ncof[k][t] != 1)
          continue;
        for (pp = cof[k]->rowptr[t]; pp < cof[k]->rowptr[t + 1]; pp++)
          if (alive[k + 1][cof[k]->col[pp]])
            sigma = cof[k]->col[pp];
        if (sigma >= 0 && ncof[k + 1][sigma] == 0) {
          tau = t;
          break;
        }
        sigma = -1;
      }
    if (tau < 0)
      break;
    k++;                                    /* the loop left k one below */
    pairs[npairs].k = k;
    pairs[npairs].tau = tau;
    pairs[npairs].sigma = sigma;
    pairs[npairs++].c = dm_sparse_get(K->d[k], sigma, tau);
    alive[k][tau] = alive[k + 1][sigma] = 0;
    /* removing sigma and tau frees faces: their coface counts drop */
    for (q = 0; q < 2; q++) {
      int dim = q == 0 ? k + 1 : k, x = q == 0 ? sigma : tau;
      const dm_sparse *D;
      if (dim == 0)
        continue;
      D = K->d[dim - 1];
      for (pp = D->rowptr[x]; pp < D->rowptr[x + 1]; pp++) {
        int y = D->col[pp], p2;
        if (--ncof[dim - 1][y] == 1 && ipush(&queue[dim - 1], y) != 0)
          goto nomem;
        if (ncof[dim - 1][y] == 0 && dim - 1 > 0 && alive[dim - 1][y]) {
          const dm_sparse *Dy = K->d[dim - 2];
          for (p2 = Dy->rowptr[y]; p2 < Dy->rowptr[y + 1]; p2++)
            if (ncof[dim - 2][Dy->col[p2]] == 1 && ipush(&queue[dim - 2], Dy->col[p2]) != 0)
              goto nomem;
        }
      }
    }
  }
  if (npairs * 2 != total - 1) {
    int left[DM_DEC_MAXDIM + 1] = {0};
    char buf[160];
    int len = 0;
    for (k = 0; k <= n; k++)
      for (s = 0; s < K->nsimp[k]; s++)
        left[k] += alive[k][s];
    for (k = 0; k <= n && len < (int)sizeof buf; k++)
      len += snprintf(buf + len, sizeof buf - (size_t)len, "%s%d %d-simplices", k ? ", " : "", left[k], k);
    st = dm_err_set(e, DM_EFAILED,
                    "no collapse to a point (%s remain): the mesh is not contractible, or not collapsible in this order",
                    buf);
    goto fail;
  }
  for (s = 0; s < K->nsimp[0]; s++)
    if (alive[0][s])
      *apex = s;
  /* p row by row, pairs replayed backwards: p(tau) = c sigma - c sum [sigma:rho] p(rho) */
  {
    ivec rows[DM_DEC_MAXDIM], cols[DM_DEC_MAXDIM];
    int *start[DM_DEC_MAXDIM], *end[DM_DEC_MAXDIM], maxn = 0, a;
    double *vals[DM_DEC_MAXDIM];
    int nvals[DM_DEC_MAXDIM], capv[DM_DEC_MAXDIM];
    int *touched, *mark;
    memset(rows, 0, sizeof rows);
    memset(cols, 0, sizeof cols);
    for (k = 0; k <= n; k++)
      maxn = K->nsimp[k] > maxn ? K->nsimp[k] : maxn;
    acc = calloc((size_t)maxn + 1, sizeof *acc);
    touched = malloc(((size_t)maxn + 1) * sizeof *touched);
    mark = malloc(((size_t)maxn + 1) * sizeof *mark);
    for (s = 0; mark != NULL && s <= maxn; s++)
      mark[s] = -1;
    for (k = 0; k < n; k++) {
      start[k] = malloc(((size_t)K->nsimp[k] + 1) * sizeof *start[k]);
      end[k] = calloc((size_t)K->nsimp[k] + 1, sizeof *end[k]);
      vals[k] = NULL;
      nvals[k] = capv[k] = 0;
      for (s = 0; start[k] && s < K->nsimp[k]; s++)
        start[k][s] = 0;
    }
    for (a = npairs - 1; a >= 0 && acc && touched && mark; a--) {
      int kk = pairs[a].k, tau = pairs[a].tau, sigma = pairs[a].sigma, nt = 0, pp, r;
      double c = pairs[a].c;
      const dm_sparse *D = K->d[kk];
      acc[sigma] += c;
      touched[nt++] = sigma;
      mark[sigma] = a;
      for (pp = D->rowptr[sigma]; pp < D->rowptr[sigma + 1]; pp++) {
        int rho = D->col[pp];
        if (rho == tau)
          continue;
        for (r = start[kk][rho]; r < end[kk][rho]; r++) {
          int col = cols[kk].data[r];
          if (mark[col] != a) {
            mark[col] = a;
            touched[nt++] = col;
          }
          acc[col] -= c * D->val[pp] * vals[kk][r];
        }
      }
      start[kk][tau] = cols[kk].len;
      for (r = 0; r < nt; r++) {
        int col = touched[r];
        if (acc[col] != 0.0) {
          if (nvals[kk] == capv[kk]) {
            double *nv2 = realloc(vals[kk], (size_t)(capv[kk] ? 2 * capv[kk] : 256) * sizeof *nv2);
            if (nv2 == NULL)
              break;
            vals[kk] = nv2;
            capv[kk] = capv[kk] ? 2 * capv[kk] : 256;
          }
          if (ipush(&cols[kk], col) != 0)
            break;
          vals[kk][nvals[kk]++] = acc[col];
          acc[col] = 0.0;
        }
      }
      for (r = 0; r < nt; r++)
        acc[touched[r]] = 0.0;
      end[kk][tau] = cols[kk].len;
    }
    if (acc == NULL || touched == NULL || mark == NULL)
      st = dm_err_set(e, DM_ENOMEM, "homotopy: out of memory");
    for (k = 0; k < n && st == DM_OK; k++) {
      int cnt = 0, r, *ri, *ci;
      for (s = 0; s < K->nsimp[k]; s++)
        cnt += end[k][s] - start[k][s];
      ri = malloc(((size_t)cnt + 1) * sizeof *ri);
      ci = malloc(((size_t)cnt + 1) * sizeof *ci);
      double *vv = malloc(((size_t)cnt + 1) * sizeof *vv);
      if (ri == NULL || ci == NULL || vv == NULL) {
        st = dm_err_set(e, DM_ENOMEM, "homotopy: out of memory");
      } else {
        cnt = 0;
        for (s = 0; s < K->nsimp[k]; s++)
          for (r = start[k][s]; r < end[k][s]; r++) {
            ri[cnt] = s;
            ci[cnt] = cols[k].data[r];
            vv[cnt++] = vals[k][r];
          }
        if ((p[k] = dm_sparse_from_triplets(K->nsimp[k], K->nsimp[k + 1], cnt, ri, ci, vv, e)) == NULL)
          st = e != NULL ? e->status : DM_ENOMEM;
      }
      free(ri);
      free(ci);
      free(vv);
    }
    for (k = 0; k < n; k++) {
      free(start[k]);
      free(end[k]);
      free(vals[k]);
      free(cols[k].data);
      free(rows[k].data);
    }
    if (acc == NULL || touched == NULL || mark == NULL)
      st = dm_err_set(e, DM_ENOMEM, "homotopy: out of memory");
    free(touched);
    free(mark);
    if (st != DM_OK)
      goto fail;
  }
  goto done;
nomem:
  st = dm_err_set(e, DM_ENOMEM, "homotopy: out of memory");
fail:
  for (k = 0; k < n; k++) {
    dm_sparse_free(p[k]);
    p[k] = NULL;
  }
done:
  for (k = 0; k <= n; k++) {
    dm_sparse_free(cof[k]);
    free(ncof[k]);
    free(alive[k]);
    free(queue[k].data);
  }
  free(pairs);
  free(acc);
  return st;
}
