/* wedge.c -- the primal-primal wedge product with barycentric or
 * circumcentric weights (doc/exterior-calculus.md §8):
 *
 *   <a ^ b, s> = 1/p! sum over permutations t of (0..p) of
 *                sign(t) w_{t(k)}(s) a([v_t(0)..v_t(k)]) b([v_t(k)..v_t(p)])
 *
 * for a k-cochain a, an l-cochain b, p = k + l, s = [v_0..v_p] (sorted for
 * p < n, the stored orientation for p = n). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dec/dec.h"
#include "dec/dec_impl.h"

#define NV (DM_DEC_MAXDIM + 1)

static int parity_sort(int *v, int m)
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

/* Value of the q-cochain c on the ordered simplex L (q+1 vertices); the
 * top simplex top is used when q = n. */
static double value(const dm_dec_complex *K, int q, const double *c, const int *L, int top)
{
  int s[NV], sg, id;
  memcpy(s, L, (size_t)(q + 1) * sizeof *s);
  sg = parity_sort(s, q + 1);
  if (q == K->n)
    return sg * K->top_sign[top] * c[top];
  id = dm_dec_find(K, q, s);
  return id < 0 ? 0.0 : sg * c[id];
}

/* All permutations of 0..m-1 with their signs (m <= NV). */
static int permutations(int m, int perm[][NV], int *sign)
{
  int cnt = 0, a[NV] = {0}, c[NV] = {0}, i, s = 1;
  for (i = 0; i < m; i++) {
    a[i] = i;
    c[i] = 0;
  }
  memcpy(perm[cnt], a, sizeof a);
  sign[cnt++] = s;
  i = 0;
  while (i < m) {                          /* Heap's algorithm */
    if (c[i] < i) {
      int j = (i % 2 == 0) ? 0 : c[i], t = a[j];
      a[j] = a[i];
      a[i] = t;
      s = -s;
      memcpy(perm[cnt], a, sizeof a);
      sign[cnt++] = s;
      c[i]++;
      i = 0;
    } else {
      c[i] = 0;
      i++;
    }
  }
  return cnt;
}

int dm_dec_wedge(const dm_dec_geom *G, int k, const double *a, int l, const double *b,
                 int weights, double *out, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, p = k + l, s, np, i, j, q;
  static const double fact[] = {1, 1, 2, 6, 24, 120};
  int perm[120][NV], sign[120];
  if (k < 0 || l < 0 || p > n)
    return dm_err_set(e, DM_EINVAL, "wedge: degrees %d + %d exceed the dimension %d", k, l, n);
  if (weights != DM_DEC_WEDGE_BARYCENTRIC && weights != DM_DEC_WEDGE_CIRCUMCENTRIC)
    return dm_err_set(e, DM_EINVAL, "wedge: unknown weights %d", weights);
  np = permutations(p + 1, perm, sign);
  for (s = 0; s < K->nsimp[p]; s++) {
    int v[NV];
    double w[NV], acc = 0.0;
    memcpy(v, p == n ? K->top + (size_t)s * (n + 1) : K->simp[p] + (size_t)s * (p + 1),
           (size_t)(p + 1) * sizeof *v);
    if (weights == DM_DEC_WEDGE_BARYCENTRIC) {
      for (i = 0; i <= p; i++)
        w[i] = 1.0 / (p + 1);
    } else {
      /* |s cap *v| / |s| from the flag sums inside s alone (sorted order) */
      double D[NV * NV], vol[1 << NV], piece[1 << NV];
      const int *sv = K->simp[p] + (size_t)s * (p + 1);
      for (i = 0; i <= p; i++)
        for (j = 0; j <= p; j++) {
          int ed[2] = {sv[i], sv[j]}, id = i == j ? -1 : dm_dec_find(K, 1, ed);
          D[i * (p + 1) + j] = id < 0 ? 0.0 : G->len2[id];
        }
      if (p == 0) {
        w[0] = 1.0;
      } else {
        if (dm_dec__top_pieces(p, D, 0, vol, piece) != 0)
          return dm_err_set(e, DM_EDOM, "wedge: degenerate %d-simplex %d", p, s + 1);
        for (i = 0; i <= p; i++)             /* map sorted -> stored order */
          for (j = 0; j <= p; j++)
            if (sv[j] == v[i])
              w[i] = piece[1u << j] / vol[(1u << (p + 1)) - 1];
      }
    }
    for (q = 0; q < np; q++) {
      int L1[NV], L2[NV];
      for (i = 0; i <= k; i++)
        L1[i] = v[perm[q][i]];
      for (i = 0; i <= l; i++)
        L2[i] = v[perm[q][k + i]];
      acc += sign[q] * w[perm[q][k]] * value(K, k, a, L1, s) * value(K, l, b, L2, s);
    }
    out[s] = acc / fact[p];
  }
  return DM_OK;
}

/* Value of a dual cochain on the dual cell of the ordered simplex L (q+1
 * vertices): the dual orientation follows the primal one. */
static double dual_value(const dm_dec_complex *K, int q, const double *c, const int *L, int top)
{
  int s[NV], sg, id;
  memcpy(s, L, (size_t)(q + 1) * sizeof *s);
  sg = parity_sort(s, q + 1);
  if (q == K->n)                      /* the top simplex itself */
    return sg * K->top_sign[top] * c[top];
  id = dm_dec_find(K, q, s);
  return id < 0 ? 0.0 : sg * c[id];
}

/* The thesis's dual-dual wedge (Def 3.25), purely combinatorial:
 *   <a ^ b, *rho> = sum over top s > rho of sign(s, [others, rho])
 *     sum_{t in S_{k+l}} sign(t) a(*[o_t(0..l-1), rho]) b(*[o_t(l..k+l-1), rho])
 * for a dual k-cochain a (N_{n-k} values) and a dual l-cochain b; rho runs
 * over the (n-k-l)-simplices.  No property beyond anti-commutativity is
 * claimed. */
int dm_dec_wedge_dual(const dm_dec_complex *K, int k, const double *a, int l, const double *b,
                      double *out, dm_err *e)
{
  int n = K->n, p = k + l, q = n - p, t, np, i, j, w;
  int perm[120][NV], sign[120];
  if (k < 0 || l < 0 || p > n)
    return dm_err_set(e, DM_EINVAL, "dual wedge: degrees %d + %d exceed the dimension %d", k, l, n);
  memset(out, 0, (size_t)K->nsimp[q] * sizeof *out);
  np = p > 0 ? permutations(p, perm, sign) : 1;
  if (p == 0) {
    perm[0][0] = 0;
    sign[0] = 1;
  }
  for (t = 0; t < K->nsimp[n]; t++) {
    const int *top = K->top + (size_t)t * (n + 1);
    int nf = K->nface[q];
    for (j = 0; j < nf; j++) {
      int rho = K->face[q][(size_t)t * nf + j], ord[NV], others[NV], no = 0, c = 0, par;
      const int *rv = K->simp[q] + (size_t)rho * (q + 1);
      double acc = 0.0;
      for (i = 0; i <= n; i++) {
        int in = 0;
        for (w = 0; w <= q; w++)
          in |= top[i] == rv[w];
        if (!in)
          others[no++] = top[i];
      }
      for (i = 0; i < no; i++)
        ord[c++] = others[i];
      for (w = 0; w <= q; w++)
        ord[c++] = rv[w];
      /* parity of ord against the stored orientation of the top simplex */
      {
        int pos[NV], x;
        for (i = 0; i <= n; i++)
          for (x = 0; x <= n; x++)
            if (ord[i] == top[x])
              pos[i] = x;
        par = parity_sort(pos, n + 1);
      }
      for (i = 0; i < np; i++) {
        int L1[NV], L2[NV], m = 0;
        for (w = 0; w < l; w++)
          L1[m++] = others[perm[i][w]];
        for (w = 0; w <= q; w++)
          L1[m++] = rv[w];
        m = 0;
        for (w = l; w < p; w++)
          L2[m++] = others[perm[i][w]];
        for (w = 0; w <= q; w++)
          L2[m++] = rv[w];
        acc += sign[i] * dual_value(K, n - k, a, L1, t) * dual_value(K, n - l, b, L2, t);
      }
      out[rho] += par * acc;
    }
  }
  return DM_OK;
}
