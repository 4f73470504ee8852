/* complex.c -- building a pure simplicial complex from its top simplices:
 * faces of every dimension by radix sort, face tables, the exact exterior
 * derivatives, boundary subcomplex, manifold and orientation checks. */
#include <config.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dec/dec.h"

/* {==== local faces ========================================================== */

static int popcount(unsigned m)
{
  int c = 0;
  for (; m != 0; m &= m - 1)
    c++;
  return c;
}

/* Masks with k+1 of the n+1 bits set, in lexicographic order of the vertex
 * tuples they select (bit i = local vertex i). */
static int face_masks(int n, int k, unsigned *out)
{
  int idx[DM_DEC_MAXDIM + 1], i, cnt = 0;
  for (i = 0; i <= k; i++)
    idx[i] = i;
  for (;;) {
    unsigned m = 0;
    for (i = 0; i <= k; i++)
      m |= 1u << idx[i];
    out[cnt++] = m;
    for (i = k; i >= 0 && idx[i] == n - k + i; i--)
      ;
    if (i < 0)
      return cnt;
    idx[i]++;
    for (i = i + 1; i <= k; i++)
      idx[i] = idx[i - 1] + 1;
  }
}

unsigned dm_dec_face_mask(int n, int k, int j)
{
  unsigned masks[32];
  int cnt = face_masks(n, k, masks);
  return (j >= 0 && j < cnt) ? masks[j] : 0u;
}

int dm_dec_face_index(int n, unsigned mask)
{
  unsigned masks[32];
  int k = popcount(mask) - 1, cnt, j;
  if (k < 0 || k > n)
    return -1;
  cnt = face_masks(n, k, masks);
  for (j = 0; j < cnt; j++)
    if (masks[j] == mask)
      return j;
  return -1;
}

/* }==== */

void dm_dec_complex_free(dm_dec_complex *K)
{
  int k;
  if (K == NULL)
    return;
  for (k = 0; k <= DM_DEC_MAXDIM; k++) {
    free(K->simp[k]);
    free(K->face[k]);
    free(K->boundary[k]);
    if (k < DM_DEC_MAXDIM)
      dm_sparse_free(K->d[k]);
  }
  free(K->top);
  free(K->top_sign);
  free(K);
}

/* Parity of the permutation sorting v[0..m-1] (insertion sort in place). */
static int sort_parity(int *v, int m)
{
  int i, j, s = 1;
  for (i = 1; i < m; i++)
    for (j = i; j > 0 && v[j] < v[j - 1]; j--) {
      int t = v[j];
      v[j] = v[j - 1];
      v[j - 1] = t;
      s = -s;
    }
  return s;
}

/* Entries e = t * nf + j (local face j of top t, local vertex lists lv[j])
 * sorted lexicographically by their vertex tuples: one stable counting sort
 * per tuple position, last position first. */
static int radix_faces(const dm_dec_complex *K, int k, int nv, int nf,
                       int lv[][DM_DEC_MAXDIM + 1], int *perm, dm_err *e)
{
  int n = K->n, M = K->nsimp[n] * nf, pos, i;
  int *tmp = malloc(((size_t)M + 1) * sizeof *tmp);
  int *cnt = malloc(((size_t)nv + 1) * sizeof *cnt);
  const int *S = K->simp[n];
  if (tmp == NULL || cnt == NULL) {
    free(tmp);
    free(cnt);
    return dm_err_set(e, DM_ENOMEM, "complex: out of memory sorting %d faces", M);
  }
  for (i = 0; i < M; i++)
    perm[i] = i;
  for (pos = k; pos >= 0; pos--) {
    memset(cnt, 0, ((size_t)nv + 1) * sizeof *cnt);
    for (i = 0; i < M; i++) {
      int t = perm[i] / nf, j = perm[i] % nf;
      cnt[S[(size_t)t * (n + 1) + lv[j][pos]] + 1]++;
    }
    for (i = 0; i < nv; i++)
      cnt[i + 1] += cnt[i];
    for (i = 0; i < M; i++) {
      int t = perm[i] / nf, j = perm[i] % nf;
      tmp[cnt[S[(size_t)t * (n + 1) + lv[j][pos]]]++] = perm[i];
    }
    memcpy(perm, tmp, (size_t)M * sizeof *perm);
  }
  free(tmp);
  free(cnt);
  return DM_OK;
}

static int same_tuple(const int *S, int n, int lv1[], int t1, int lv2[], int t2, int k)
{
  int i;
  for (i = 0; i <= k; i++)
    if (S[(size_t)t1 * (n + 1) + lv1[i]] != S[(size_t)t2 * (n + 1) + lv2[i]])
      return 0;
  return 1;
}

/* The k-faces: sorted, deduplicated, numbered; face[k] and a representative
 * entry (t * nf + j) of every face in rep. */
static int build_faces(dm_dec_complex *K, int k, int nv, int **rep, dm_err *e)
{
  int n = K->n, nf = K->nface[k], ntop = K->nsimp[n], M = ntop * nf, i, j, cur = -1;
  unsigned masks[32];
  int lv[32][DM_DEC_MAXDIM + 1];
  int *perm = malloc(((size_t)M + 1) * sizeof *perm), st;
  const int *S = K->simp[n];
  face_masks(n, k, masks);
  for (j = 0; j < nf; j++) {
    int b, c = 0;
    for (b = 0; b <= n; b++)
      if (masks[j] & (1u << b))
        lv[j][c++] = b;
  }
  K->face[k] = malloc(((size_t)M + 1) * sizeof *K->face[k]);
  *rep = malloc(((size_t)M + 1) * sizeof **rep);
  if (perm == NULL || K->face[k] == NULL || *rep == NULL) {
    free(perm);
    return dm_err_set(e, DM_ENOMEM, "complex: out of memory for %d-faces", k);
  }
  if ((st = radix_faces(K, k, nv, nf, lv, perm, e)) != DM_OK) {
    free(perm);
    return st;
  }
  for (i = 0; i < M; i++) {
    int t = perm[i] / nf, jj = perm[i] % nf;
    if (cur < 0 || !same_tuple(S, n, lv[jj], t, lv[(*rep)[cur] % nf],
                               (*rep)[cur] / nf, k))
      (*rep)[++cur] = perm[i];
    K->face[k][perm[i]] = cur;
  }
  K->nsimp[k] = cur + 1;
  K->simp[k] = malloc(((size_t)K->nsimp[k] * (k + 1) + 1) * sizeof *K->simp[k]);
  if (K->simp[k] == NULL) {
    free(perm);
    return dm_err_set(e, DM_ENOMEM, "complex: out of memory for %d-faces", k);
  }
  for (i = 0; i < K->nsimp[k]; i++) {
    int t = (*rep)[i] / nf, jj = (*rep)[i] % nf, p;
    for (p = 0; p <= k; p++)
      K->simp[k][(size_t)i * (k + 1) + p] = S[(size_t)t * (n + 1) + lv[jj][p]];
  }
  free(perm);
  return DM_OK;
}

/* d_k: row of a (k+1)-simplex s = sum_i (-1)^i [faces without vertex i],
 * times top_sign for top simplices.  Columns come out increasing because
 * dropping a later vertex gives a lexicographically smaller face. */
static int build_d(dm_dec_complex *K, int k, const int *rep, dm_err *e)
{
  int n = K->n, nf = K->nface[k + 1], rows = K->nsimp[k + 1], r;
  dm_sparse *D = dm_sparse_alloc(rows, K->nsimp[k], rows * (k + 2), e);
  if (D == NULL)
    return e != NULL ? e->status : DM_ENOMEM;
  for (r = 0; r < rows; r++) {
    int entry = (k + 1 == n) ? r * nf : rep[r];
    int t = entry / nf, j = entry % nf, b, i = k + 1, p = r * (k + 2);
    unsigned m = dm_dec_face_mask(n, k + 1, j);
    double sg = (k + 1 == n) ? K->top_sign[t] : 1.0;
    D->rowptr[r + 1] = p + k + 2;
    for (b = n; b >= 0; b--) {
      if (!(m & (1u << b)))
        continue;
      D->col[p] = K->face[k][(size_t)t * K->nface[k] + dm_dec_face_index(n, m & ~(1u << b))];
      D->val[p++] = (i % 2 == 0 ? 1.0 : -1.0) * sg;
      i--;
    }
  }
  K->d[k] = D;
  return DM_OK;
}

/* Boundary subcomplex: (n-1)-faces with one coface and all their faces. */
static int build_boundary(dm_dec_complex *K, int **rep, dm_err *e)
{
  int n = K->n, k, i, p;
  int *cof = calloc((size_t)K->nsimp[n - 1] + 1, sizeof *cof);
  int *sum = calloc((size_t)K->nsimp[n - 1] + 1, sizeof *sum);
  const dm_sparse *D = K->d[n - 1];
  for (k = 0; k <= n; k++)
    K->boundary[k] = calloc((size_t)K->nsimp[k] + 1, 1);
  if (cof == NULL || sum == NULL || K->boundary[n] == NULL || K->boundary[0] == NULL) {
    free(cof);
    free(sum);
    return dm_err_set(e, DM_ENOMEM, "complex: out of memory");
  }
  for (p = 0; p < dm_sparse_nnz(D); p++) {
    cof[D->col[p]]++;
    sum[D->col[p]] += (int)D->val[p];
  }
  K->manifold = K->oriented = 1;
  for (i = 0; i < K->nsimp[n - 1]; i++) {
    if (cof[i] > 2)
      K->manifold = 0;
    if (cof[i] == 2 && sum[i] != 0)
      K->oriented = 0;
    if (cof[i] == 1) {
      int nf = K->nface[n - 1], t = rep[n - 1][i] / nf, j = rep[n - 1][i] % nf;
      unsigned m = dm_dec_face_mask(n, n - 1, j), sub;
      /* every non-empty submask of m is a face of the boundary face */
      for (sub = m; sub != 0; sub = (sub - 1) & m) {
        int kk = popcount(sub) - 1;
        K->boundary[kk][K->face[kk][(size_t)t * K->nface[kk] + dm_dec_face_index(n, sub)]] = 1;
      }
    }
  }
  free(cof);
  free(sum);
  return DM_OK;
}

static int binom(int a, int b)
{
  int r = 1, i;
  for (i = 1; i <= b; i++)
    r = r * (a - b + i) / i;
  return r;
}

static int check_input(int n, int nv, int ntop, const int *T, dm_err *e)
{
  int t, i, j;
  if (n < 1 || n > DM_DEC_MAXDIM)
    return dm_err_set(e, DM_EINVAL, "complex: dimension %d outside 1..%d", n, DM_DEC_MAXDIM);
  if (nv < 1 || ntop < 1)
    return dm_err_set(e, DM_EINVAL, "complex: %d vertices and %d simplices (at least one each expected)",
                      nv, ntop);
  for (t = 0; t < ntop; t++)
    for (i = 0; i <= n; i++) {
      int v = T[(size_t)t * (n + 1) + i];
      if (v < 0 || v >= nv)
        return dm_err_set(e, DM_EINVAL, "simplex %d: vertex %d outside 1..%d", t + 1, v + 1, nv);
      for (j = 0; j < i; j++)
        if (T[(size_t)t * (n + 1) + j] == v)
          return dm_err_set(e, DM_EINVAL, "simplex %d repeats vertex %d", t + 1, v + 1);
    }
  return DM_OK;
}

dm_dec_complex *dm_dec_complex_alloc(int n, int nv, int ntop, const int *T, dm_err *e)
{
  dm_dec_complex *K;
  int *rep[DM_DEC_MAXDIM + 1] = {NULL}, k, t, i, st;
  if (check_input(n, nv, ntop, T, e) != DM_OK)
    return NULL;
  K = calloc(1, sizeof *K);
  if (K == NULL)
    goto nomem;
  K->n = n;
  K->nsimp[n] = ntop;
  for (k = 0; k <= n; k++)
    K->nface[k] = binom(n + 1, k + 1);
  K->top = malloc((size_t)ntop * (n + 1) * sizeof *K->top);
  K->simp[n] = malloc((size_t)ntop * (n + 1) * sizeof *K->simp[n]);
  K->top_sign = malloc((size_t)ntop);
  K->face[n] = malloc((size_t)ntop * sizeof *K->face[n]);
  if (K->top == NULL || K->simp[n] == NULL || K->top_sign == NULL || K->face[n] == NULL)
    goto nomem;
  memcpy(K->top, T, (size_t)ntop * (n + 1) * sizeof *K->top);
  memcpy(K->simp[n], T, (size_t)ntop * (n + 1) * sizeof *K->simp[n]);
  for (t = 0; t < ntop; t++) {
    K->top_sign[t] = (signed char)sort_parity(K->simp[n] + (size_t)t * (n + 1), n + 1);
    K->face[n][t] = t;
  }
  /* duplicates among the top simplices: sort them like faces */
  {
    int *r = NULL, *saved_face = K->face[n], *saved_simp = K->simp[n];
    K->face[n] = NULL;
    st = build_faces(K, n, nv, &r, e);
    if (st == DM_OK && K->nsimp[n] != ntop) {
      int *seen = malloc((size_t)ntop * sizeof *seen), a = -1, b = -1;
      for (i = 0; seen != NULL && i < ntop; i++)
        seen[i] = -1;
      for (t = 0; seen != NULL && t < ntop && a < 0; t++) {
        if (seen[K->face[n][t]] >= 0) {
          a = seen[K->face[n][t]];
          b = t;
        }
        seen[K->face[n][t]] = t;
      }
      free(seen);
      st = dm_err_set(e, DM_EINVAL, "simplices %d and %d have the same vertices", a + 1, b + 1);
    }
    free(r);
    free(K->face[n]);
    if (K->simp[n] != saved_simp)
      free(K->simp[n]);
    K->face[n] = saved_face;
    K->simp[n] = saved_simp;
    K->nsimp[n] = ntop;
    if (st != DM_OK)
      goto fail;
  }
  for (k = 0; k < n; k++)
    if ((st = build_faces(K, k, nv, &rep[k], e)) != DM_OK)
      goto fail;
  if (K->nsimp[0] != nv) {
    for (i = 0; i < nv && i < K->nsimp[0] && K->simp[0][i] == i; i++)
      ;
    dm_err_set(e, DM_EINVAL, "vertex %d belongs to no simplex (only pure complexes are supported)",
               i + 1);
    goto fail;
  }
  for (k = 0; k < n; k++)
    if ((st = build_d(K, k, rep[k + 1], e)) != DM_OK)
      goto fail;
  if ((st = build_boundary(K, rep, e)) != DM_OK)
    goto fail;
  for (k = 0; k <= n; k++)
    free(rep[k]);
  return K;
nomem:
  dm_err_set(e, DM_ENOMEM, "complex of %d simplices: out of memory", ntop);
fail:
  for (k = 0; k <= n; k++)
    free(rep[k]);
  dm_dec_complex_free(K);
  return NULL;
}

/* Binary search in the lexicographically sorted table of k-simplices. */
int dm_dec_find(const dm_dec_complex *K, int k, const int *v)
{
  int s[DM_DEC_MAXDIM + 1], lo, hi, i;
  if (k < 0 || k > K->n)
    return -1;
  memcpy(s, v, (size_t)(k + 1) * sizeof *s);
  sort_parity(s, k + 1);
  if (k == K->n) {            /* top simplices keep the input order */
    for (i = 0; i < K->nsimp[k]; i++)
      if (memcmp(K->simp[k] + (size_t)i * (k + 1), s, (size_t)(k + 1) * sizeof *s) == 0)
        return i;
    return -1;
  }
  lo = 0;
  hi = K->nsimp[k] - 1;
  while (lo <= hi) {
    int mid = lo + (hi - lo) / 2, c = 0;
    const int *r = K->simp[k] + (size_t)mid * (k + 1);
    for (i = 0; i <= k && c == 0; i++)
      c = (r[i] > s[i]) - (r[i] < s[i]);
    if (c == 0)
      return mid;
    if (c < 0)
      lo = mid + 1;
    else
      hi = mid - 1;
  }
  return -1;
}

static void face_name(const dm_dec_complex *K, int k, int s, char *buf, size_t size)
{
  int i, len = 0;
  for (i = 0; i <= k && len < (int)size; i++)
    len += snprintf(buf + len, size - (size_t)len, "%s%d", i ? "," : "(",
                    K->simp[k][(size_t)s * (k + 1) + i] + 1);
  if (len < (int)size)
    snprintf(buf + len, size - (size_t)len, ")");
}

int dm_dec_complex_defect(const dm_dec_complex *K, int *a, int *b, int *f)
{
  dm_sparse *Dt;
  int i, kind = 0;
  if (K->manifold && K->oriented)
    return 0;
  if ((Dt = dm_sparse_transpose(K->d[K->n - 1], NULL)) == NULL)
    return -1;
  for (i = 0; i < Dt->nrows && kind == 0; i++) {
    int c = Dt->rowptr[i + 1] - Dt->rowptr[i], p = Dt->rowptr[i];
    if (c > 2 || (c == 2 && Dt->val[p] == Dt->val[p + 1])) {
      kind = c > 2 ? 1 : 2;
      *a = Dt->col[p];
      *b = Dt->col[p + 1];
      *f = i;
    }
  }
  dm_sparse_free(Dt);
  return kind;
}

int dm_dec_complex_check(const dm_dec_complex *K, dm_err *e)
{
  int n = K->n, i, p;
  const dm_sparse *D = K->d[n - 1];
  dm_sparse *Dt;
  static const char *const facename[] = {"vertex", "vertex", "edge", "triangle", "tetrahedron"};
  char buf[96];
  if (K->manifold && K->oriented)
    return DM_OK;
  Dt = dm_sparse_transpose(D, e);
  if (Dt == NULL)
    return e != NULL ? e->status : DM_ENOMEM;
  for (i = 0; i < Dt->nrows; i++) {
    int c = Dt->rowptr[i + 1] - Dt->rowptr[i];
    p = Dt->rowptr[i];
    face_name(K, n - 1, i, buf, sizeof buf);
    if (c > 2) {
      dm_err_set(e, DM_EINVAL, "non-manifold: %s %s is a face of %d simplices (%d, %d, %d%s)",
                 facename[n], buf, c, Dt->col[p] + 1, Dt->col[p + 1] + 1, Dt->col[p + 2] + 1,
                 c > 3 ? ", ..." : "");
      dm_sparse_free(Dt);
      return DM_EINVAL;
    }
    if (c == 2 && Dt->val[p] == Dt->val[p + 1]) {
      dm_err_set(e, DM_EINVAL,
                 "inconsistent orientation: simplices %d and %d induce the same orientation on their shared %s %s",
                 Dt->col[p] + 1, Dt->col[p + 1] + 1, facename[n], buf);
      dm_sparse_free(Dt);
      return DM_EINVAL;
    }
  }
  dm_sparse_free(Dt);
  return DM_OK;
}
