/* flat.c -- discrete vector fields: the dual-to-primal flat, the
 * renormalised primal-primal sharp (doc/exterior-calculus.md §7), and the
 * algebraic contraction and Lie derivative of dual forms (§9). */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/smalllu.h"
#include "dec/dec.h"

/* <X^flat, e> = sum over top simplices s containing e of
 * (|*e cap s| / |*e|) X(s) . e_vec.  Edges with |*e| = 0 (a hypotenuse of
 * right triangles) take the plain average over their cofaces. */
int dm_dec_flat(const dm_dec_geom *G, const double *X, double *alpha, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, N = G->N, t, j, c, nf = K->nface[1];
  int *cnt;
  if (G->X == NULL)
    return dm_err_set(e, DM_EUNSUP, "flat: vector fields need an embedded mesh");
  cnt = calloc((size_t)K->nsimp[1] + 1, sizeof *cnt);
  if (cnt == NULL)
    return dm_err_set(e, DM_ENOMEM, "flat: out of memory");
  memset(alpha, 0, (size_t)K->nsimp[1] * sizeof *alpha);
  for (t = 0; t < K->nsimp[n]; t++)
    for (j = 0; j < nf; j++)
      cnt[K->face[1][(size_t)t * nf + j]]++;
  for (t = 0; t < K->nsimp[n]; t++)
    for (j = 0; j < nf; j++) {
      int ed = K->face[1][(size_t)t * nf + j];
      const double *a = G->X + (size_t)K->simp[1][2 * ed] * N;
      const double *b = G->X + (size_t)K->simp[1][2 * ed + 1] * N;
      double dot = 0.0, w = G->dual[1][ed] != 0.0 ? G->piece[1][(size_t)t * nf + j] / G->dual[1][ed]
                                                   : 1.0 / cnt[ed];
      for (c = 0; c < N; c++)
        dot += X[(size_t)t * N + c] * (b[c] - a[c]);
      alpha[ed] += w * dot;
    }
  free(cnt);
  return DM_OK;
}

/* Gradients of the barycentric coordinate functions of top simplex t:
 * grad[i * N + c], i = 0..n (local sorted order). */
static int bary_gradients(const dm_dec_geom *G, int t, double *grad)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, N = G->N, i, j, c;
  const int *v = K->simp[n] + (size_t)t * (n + 1);
  double E[DM_DEC_MAXDIM][8], Gm[DM_DEC_MAXDIM * DM_DEC_MAXDIM], rhs[DM_DEC_MAXDIM];
  size_t perm[DM_DEC_MAXDIM];
  for (i = 0; i < n; i++)
    for (c = 0; c < N; c++)
      E[i][c] = G->X[(size_t)v[i + 1] * N + c] - G->X[(size_t)v[0] * N + c];
  for (i = 0; i < n; i++)
    for (j = 0; j < n; j++) {
      double s = 0.0;
      for (c = 0; c < N; c++)
        s += E[i][c] * E[j][c];
      Gm[i * n + j] = s;
    }
  if (dm_smalllu_factor(Gm, (size_t)n, perm) != DM_OK)
    return DM_ESINGULAR;
  for (c = 0; c < N; c++) {               /* column c of G^-1 E */
    for (i = 0; i < n; i++)
      rhs[i] = E[i][c];
    dm_smalllu_solve(Gm, (size_t)n, perm, rhs);
    grad[c] = 0.0;
    for (i = 0; i < n; i++) {
      grad[(size_t)(i + 1) * N + c] = rhs[i];
      grad[c] -= rhs[i];
    }
  }
  return DM_OK;
}

int dm_dec_sharp(const dm_dec_geom *G, const double *alpha, double *V, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, N = G->N, t, i, w, c;
  double grad[(DM_DEC_MAXDIM + 1) * 8];
  if (G->X == NULL || N > 8)
    return dm_err_set(e, DM_EUNSUP, "sharp: vector fields need an embedded mesh (at most 8 coordinates)");
  for (i = 0; i < K->nsimp[0]; i++)
    if (G->dual[0][i] == 0.0)
      return dm_err_set(e, DM_ESINGULAR, "sharp: the dual cell of vertex %d has zero area", i + 1);
  memset(V, 0, (size_t)K->nsimp[0] * N * sizeof *V);
  for (t = 0; t < K->nsimp[n]; t++) {
    const int *v = K->simp[n] + (size_t)t * (n + 1);
    if (bary_gradients(G, t, grad) != DM_OK)
      return dm_err_set(e, DM_EDOM, "sharp: degenerate simplex %d", t + 1);
    for (i = 0; i <= n; i++) {
      double wt = G->piece[0][(size_t)t * (n + 1) + i] / G->dual[0][v[i]];
      for (w = 0; w <= n; w++) {
        int ed, lo, hi;
        double a;
        if (w == i)
          continue;
        lo = i < w ? i : w;
        hi = i < w ? w : i;
        ed = K->face[1][(size_t)t * K->nface[1] + dm_dec_face_index(n, (1u << lo) | (1u << hi))];
        a = (i < w ? 1.0 : -1.0) * alpha[ed];    /* alpha([v_i, v_w]); rows sorted */
        for (c = 0; c < N; c++)
          V[(size_t)v[i] * N + c] += wt * a * grad[(size_t)w * N + c];
      }
    }
  }
  return DM_OK;
}

/* i_X b = (-1)^(k(n-k)) *( (*b) ^ X^flat ) for a dual k-cochain b. */
int dm_dec_contract(const dm_dec_geom *G, int k, const double *beta, const double *X, int weights,
                    double *out, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, q = n - k, i, st;
  double *s = NULL, *f = NULL, *w = NULL, *star = NULL, sg = (k * (n - k)) % 2 ? -1.0 : 1.0;
  if (k < 1 || k > n)
    return dm_err_set(e, DM_EINVAL, "contraction: dual degree %d outside 1..%d", k, n);
  s = malloc(((size_t)K->nsimp[q] + 1) * sizeof *s);
  f = malloc(((size_t)K->nsimp[1] + 1) * sizeof *f);
  w = malloc(((size_t)K->nsimp[q + 1] + 1) * sizeof *w);
  star = malloc(((size_t)K->nsimp[q + 1] + 1) * sizeof *star);
  if (!s || !f || !w || !star) {
    st = dm_err_set(e, DM_ENOMEM, "contraction: out of memory");
    goto done;
  }
  if ((st = dm_dec_star(G, q, 1, s, e)) != DM_OK)            /* dual k -> primal n-k */
    goto done;
  for (i = 0; i < K->nsimp[q]; i++)
    s[i] *= beta[i];
  if ((st = dm_dec_flat(G, X, f, e)) != DM_OK ||
      (st = dm_dec_wedge(G, q, s, 1, f, weights, w, e)) != DM_OK)
    goto done;
  dm_dec_star(G, q + 1, 0, star, NULL);                       /* primal -> dual k-1 */
  for (i = 0; i < K->nsimp[q + 1]; i++)
    out[i] = sg * star[i] * w[i];
done:
  free(s);
  free(f);
  free(w);
  free(star);
  return st;
}

/* L_X b = i_X D b + D i_X b (Cartan) on dual k-cochains. */
int dm_dec_lie(const dm_dec_geom *G, int k, const double *beta, const double *X, int weights,
               double *out, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, st = DM_OK;
  double *db = NULL, *t1 = NULL, *ib = NULL;
  dm_sparse *D = NULL;
  if (k < 0 || k > n)
    return dm_err_set(e, DM_EINVAL, "Lie derivative: dual degree %d outside 0..%d", k, n);
  memset(out, 0, (size_t)K->nsimp[n - k] * sizeof *out);
  if (k < n) {                                   /* i_X (D b) */
    db = malloc(((size_t)K->nsimp[n - k - 1] + 1) * sizeof *db);
    t1 = malloc(((size_t)K->nsimp[n - k] + 1) * sizeof *t1);
    if (!db || !t1 || (D = dm_dec_dual_d(K, k, e)) == NULL) {
      st = D == NULL && db && t1 ? e->status : dm_err_set(e, DM_ENOMEM, "Lie derivative: out of memory");
      goto done;
    }
    dm_sparse_gemv(D, beta, db);
    if ((st = dm_dec_contract(G, k + 1, db, X, weights, t1, e)) != DM_OK)
      goto done;
    memcpy(out, t1, (size_t)K->nsimp[n - k] * sizeof *out);
    dm_sparse_free(D);
    D = NULL;
  }
  if (k > 0) {                                   /* D (i_X b) */
    int i;
    ib = malloc(((size_t)K->nsimp[n - k + 1] + 1) * sizeof *ib);
    free(t1);
    t1 = malloc(((size_t)K->nsimp[n - k] + 1) * sizeof *t1);
    if (!ib || !t1) {
      st = dm_err_set(e, DM_ENOMEM, "Lie derivative: out of memory");
      goto done;
    }
    if ((st = dm_dec_contract(G, k, beta, X, weights, ib, e)) != DM_OK)
      goto done;
    if ((D = dm_dec_dual_d(K, k - 1, e)) == NULL) {
      st = e != NULL ? e->status : DM_EFAILED;
      goto done;
    }
    dm_sparse_gemv(D, ib, t1);
    for (i = 0; i < K->nsimp[n - k]; i++)
      out[i] += t1[i];
  }
done:
  dm_sparse_free(D);
  free(db);
  free(t1);
  free(ib);
  return st;
}
