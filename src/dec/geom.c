/* geom.c -- the metric of a complex: volumes, circumcentres and signed
 * circumcentric dual volumes (doc/exterior-calculus.md §3).
 *
 * Everything is computed from squared edge lengths, so the embedded and the
 * intrinsic mode share one code path: inside a top simplex with squared
 * distances D_ij, a k-face has Gram matrix G_ab = (D_0a + D_0b - D_ab)/2
 * (edges from its first vertex), volume sqrt(det G)/k! and circumcentre
 * barycentrics from G a = diag(G)/2; the squared distance between points
 * with barycentrics p and q is -(p-q)^T D (p-q)/2.
 *
 * Dual volumes are sums over flags s_k < s_{k+1} < ... < s_n inside every
 * top simplex of sign(flag) |[c(s_k), ..., c(s_n)]|, where the sign flips
 * whenever the circumcentre of s_{j+1} lies across s_j from the vertex of
 * s_{j+1} not in s_j (its barycentric coordinate is negative).  Triangles
 * take a closed form (the cotangent formula, equal to the flag sum). */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/smalllu.h"
#include "dec/dec.h"
#include "dec/dec_impl.h"

#define NV (DM_DEC_MAXDIM + 1)
#define NMASK (1 << NV)
#define WC_TOL 1e-12

static const double factorial[] = {1, 1, 2, 6, 24, 120};

static int popcount(unsigned m)
{
  int c = 0;
  for (; m != 0; m &= m - 1)
    c++;
  return c;
}

/* det of a small SPD-ish matrix (row-major, destroyed); 0 when singular to
 * working precision. */
static double small_det(double *a, int m)
{
  size_t perm[NV];
  double det = 1.0;
  int i;
  if (m == 0)
    return 1.0;
  if (dm_smalllu_factor(a, (size_t)m, perm) != DM_OK)
    return 0.0;
  for (i = 0; i < m; i++) {
    det /= a[i * m + i];                /* the diagonal holds 1/U_ii */
    if (perm[i] != (size_t)i)
      det = -det;
  }
  return det;
}

/* Volume and circumcentre barycentrics (over the k+1 vertices L) of a
 * simplex with squared distances D (NV x NV, local indices).  DM_EDOM when
 * degenerate. */
static int simplex_metric(int k, double D[NV][NV], const int *L, double *vol, double *b)
{
  double G[DM_DEC_MAXDIM * DM_DEC_MAXDIM], F[DM_DEC_MAXDIM * DM_DEC_MAXDIM];
  double rhs[DM_DEC_MAXDIM], det, s = 0.0;
  size_t perm[DM_DEC_MAXDIM];
  int a, c;
  if (k == 0) {
    *vol = 1.0;
    b[0] = 1.0;
    return DM_OK;
  }
  for (a = 0; a < k; a++) {
    for (c = 0; c < k; c++)
      G[a * k + c] = 0.5 * (D[L[0]][L[a + 1]] + D[L[0]][L[c + 1]] - D[L[a + 1]][L[c + 1]]);
    rhs[a] = 0.5 * G[a * k + a];
  }
  memcpy(F, G, sizeof(double) * (size_t)(k * k));
  det = small_det(F, k);
  if (!(det > 0))
    return DM_EDOM;
  *vol = sqrt(det) / factorial[k];
  memcpy(F, G, sizeof(double) * (size_t)(k * k));
  if (dm_smalllu_factor(F, (size_t)k, perm) != DM_OK)
    return DM_EDOM;
  dm_smalllu_solve(F, (size_t)k, perm, rhs);
  for (a = 0; a < k; a++) {
    b[a + 1] = rhs[a];
    s += rhs[a];
  }
  b[0] = 1.0 - s;
  return DM_OK;
}

/* {==== per top simplex ====================================================== */

typedef struct {
  int n;
  double D[NV][NV];
  double vol[NMASK];
  double bary[NMASK][NV];      /* circumcentre of mask, over the top's vertices */
  double piece[NMASK];         /* signed |*mask cap top| */
} topwork;

static int top_metric(topwork *w)
{
  unsigned m, full = (1u << (w->n + 1)) - 1;
  for (m = 1; m <= full; m++) {
    int L[NV], c = 0, i;
    double b[NV];
    for (i = 0; i <= w->n; i++)
      if (m & (1u << i))
        L[c++] = i;
    if (simplex_metric(c - 1, w->D, L, &w->vol[m], b) != DM_OK)
      return (int)m;
    memset(w->bary[m], 0, sizeof w->bary[m]);
    for (i = 0; i < c; i++)
      w->bary[m][L[i]] = b[i];
    w->piece[m] = 0.0;
  }
  return 0;
}

/* Volume of the simplex on the circumcentres of chain[0..len-1]. */
static double chain_volume(const topwork *w, const unsigned *chain, int len)
{
  double delta[NV][NV], G[NV * NV];
  int a, c, i, j, m = len - 1;
  if (m == 0)
    return 1.0;
  for (a = 0; a < m; a++)
    for (i = 0; i <= w->n; i++)
      delta[a][i] = w->bary[chain[a + 1]][i] - w->bary[chain[0]][i];
  for (a = 0; a < m; a++)
    for (c = 0; c <= a; c++) {
      double s = 0.0;
      for (i = 0; i <= w->n; i++)
        for (j = 0; j <= w->n; j++)
          s += delta[a][i] * w->D[i][j] * delta[c][j];
      G[a * m + c] = G[c * m + a] = -0.5 * s;
    }
  {
    double det = small_det(G, m);
    return det > 0 ? sqrt(det) / factorial[m] : 0.0;
  }
}

/* Depth-first over the flags below chain[len-1]; chain[0] is the current
 * face (the chain is stored face first). */
static void flags(topwork *w, unsigned *chain, int len, double sign)
{
  unsigned cur = chain[0];
  int i;
  w->piece[cur] += sign * chain_volume(w, chain, len);
  if (popcount(cur) == 1)
    return;
  memmove(chain + 1, chain, (size_t)len * sizeof *chain);
  for (i = 0; i <= w->n; i++)
    if (cur & (1u << i)) {
      chain[0] = cur & ~(1u << i);
      flags(w, chain, len + 1, w->bary[cur][i] >= 0 ? sign : -sign);
    }
  memmove(chain, chain + 1, (size_t)len * sizeof *chain);
}

/* Triangles: cotangent closed form of the same sums. */
static int triangle_pieces(topwork *w)
{
  double l2[3], c2a, cot[3], s = 0.0, wgt[3];
  int i;
  l2[0] = w->D[1][2];
  l2[1] = w->D[0][2];
  l2[2] = w->D[0][1];
  /* twice the area, from the Gram matrix at vertex 0 */
  {
    double g12 = 0.5 * (l2[2] + l2[1] - l2[0]);
    c2a = l2[2] * l2[1] - g12 * g12;
  }
  if (!(c2a > 0))
    return 7;
  c2a = sqrt(c2a);
  for (i = 0; i < 3; i++) {
    int j = (i + 1) % 3, k = (i + 2) % 3;
    cot[i] = 0.5 * (l2[j] + l2[k] - l2[i]) / c2a;   /* angle at vertex i */
  }
  w->vol[7] = 0.5 * c2a;
  w->piece[7] = 1.0;
  for (i = 0; i < 3; i++) {
    int j = (i + 1) % 3, k = (i + 2) % 3;
    unsigned edge = 7u & ~(1u << i);                 /* opposite vertex i */
    w->vol[1u << i] = 1.0;
    memset(w->bary[1u << i], 0, sizeof w->bary[1u << i]);
    w->bary[1u << i][i] = 1.0;
    w->vol[edge] = sqrt(l2[i]);
    w->piece[edge] = 0.5 * w->vol[edge] * cot[i];
    w->piece[1u << i] = (l2[k] * cot[k] + l2[j] * cot[j]) / 8.0;
    memset(w->bary[edge], 0, sizeof w->bary[edge]);
    w->bary[edge][j] = w->bary[edge][k] = 0.5;
    wgt[i] = l2[i] * cot[i];
    s += wgt[i];
  }
  for (i = 0; i < 3; i++)
    w->bary[7][i] = wgt[i] / s;
  return 0;
}

static int top_compute(topwork *w, int generic)
{
  unsigned chain[NV + 1];
  int bad;
  if (w->n == 2 && !generic)
    return triangle_pieces(w);
  bad = top_metric(w);
  chain[0] = (1u << (w->n + 1)) - 1;
  if (bad == 0)
    flags(w, chain, 1, 1.0);
  return bad;
}

int dm_dec__top_pieces(int n, const double *D, int generic, double *vol, double *piece)
{
  topwork w;
  int a, c, bad;
  unsigned m;
  w.n = n;
  for (a = 0; a <= n; a++)
    for (c = 0; c <= n; c++)
      w.D[a][c] = D[a * (n + 1) + c];
  bad = top_compute(&w, generic);
  for (m = 1; bad == 0 && m < (1u << (n + 1)); m++) {
    vol[m] = w.vol[m];
    piece[m] = w.piece[m];
  }
  return bad;
}

/* }==== */

void dm_dec_geom_free(dm_dec_geom *G)
{
  int k;
  if (G == NULL)
    return;
  free(G->X);
  free(G->len2);
  for (k = 0; k <= DM_DEC_MAXDIM; k++) {
    free(G->vol[k]);
    free(G->dual[k]);
    free(G->piece[k]);
    free(G->cc[k]);
  }
  free(G);
}

static void simplex_name(const dm_dec_complex *K, int k, int s, char *buf, size_t size)
{
  int i, len = 0;
  const int *v = k == K->n ? K->top + (size_t)s * (k + 1) : K->simp[k] + (size_t)s * (k + 1);
  for (i = 0; i <= k && len < (int)size; i++)
    len += snprintf(buf + len, size - (size_t)len, "%s%d", i ? "," : "(", v[i] + 1);
  if (len < (int)size)
    snprintf(buf + len, size - (size_t)len, ")");
}

/* Everything after the squared lengths are known. */
static int fill(dm_dec_geom *G, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, k, t, j;
  unsigned char *nwc[NV] = {NULL};
  for (k = 0; k <= n; k++) {
    size_t np = (size_t)K->nsimp[n] * K->nface[k];
    G->vol[k] = malloc(((size_t)K->nsimp[k] + 1) * sizeof(double));
    G->dual[k] = calloc((size_t)K->nsimp[k] + 1, sizeof(double));
    G->piece[k] = malloc((np + 1) * sizeof(double));
    nwc[k] = calloc((size_t)K->nsimp[k] + 1, 1);
    if (G->X != NULL)
      G->cc[k] = malloc(((size_t)K->nsimp[k] * G->N + 1) * sizeof(double));
    if (!G->vol[k] || !G->dual[k] || !G->piece[k] || !nwc[k] || (G->X && !G->cc[k]))
      goto nomem;
  }
  for (t = 0; t < K->nsimp[n]; t++) {
    topwork w;
    const int *v = K->simp[n] + (size_t)t * (n + 1);
    int a, c, bad;
    w.n = n;
    for (a = 0; a <= n; a++)
      for (c = 0; c <= n; c++)
        w.D[a][c] = a == c ? 0.0 : G->len2[K->face[1][(size_t)t * K->nface[1] +
                                                      dm_dec_face_index(n, (1u << a) | (1u << c))]];
    bad = top_compute(&w, 0);
    if (bad != 0) {
      int kk = popcount((unsigned)bad) - 1;
      char buf[96];
      simplex_name(K, kk, kk == n ? t : K->face[kk][(size_t)t * K->nface[kk] +
                                                    dm_dec_face_index(n, (unsigned)bad)],
                   buf, sizeof buf);
      dm_err_set(e, DM_EDOM, "degenerate %d-simplex %s (zero or imaginary volume)", kk, buf);
      goto fail;
    }
    for (k = 0; k <= n; k++)
      for (j = 0; j < K->nface[k]; j++) {
        unsigned m = dm_dec_face_mask(n, k, j);
        int g = K->face[k][(size_t)t * K->nface[k] + j], i;
        G->piece[k][(size_t)t * K->nface[k] + j] = w.piece[m];
        G->dual[k][g] += w.piece[m];
        G->vol[k][g] = w.vol[m];
        for (i = 0; i <= n && k >= 1; i++)
          if ((m & (1u << i)) && w.bary[m][i] <= WC_TOL)
            nwc[k][g] = 1;
        if (G->X != NULL) {
          int cc;
          for (cc = 0; cc < G->N; cc++) {
            double s = 0.0;
            for (i = 0; i <= n; i++)
              if (m & (1u << i))
                s += w.bary[m][i] * G->X[(size_t)v[i] * G->N + cc];
            G->cc[k][(size_t)g * G->N + cc] = s;
          }
        }
      }
  }
  for (k = 0; k <= n; k++) {
    int s;
    G->nonpos[k] = 0;
    for (s = 0; s < K->nsimp[k]; s++) {
      if (k == n)
        G->dual[k][s] = 1.0;
      if (!(G->dual[k][s] > 0))
        G->nonpos[k]++;
      if (nwc[k][s])
        G->not_well_centered++;
    }
    free(nwc[k]);
  }
  return DM_OK;
nomem:
  dm_err_set(e, DM_ENOMEM, "geometry: out of memory");
fail:
  for (k = 0; k <= n; k++)
    free(nwc[k]);
  return e != NULL ? e->status : DM_EFAILED;
}

static dm_dec_geom *geom_new(const dm_dec_complex *K, dm_err *e)
{
  dm_dec_geom *G = calloc(1, sizeof *G);
  if (G != NULL)
    G->len2 = malloc(((size_t)K->nsimp[1] + 1) * sizeof *G->len2);
  if (G == NULL || G->len2 == NULL) {
    dm_dec_geom_free(G);
    dm_err_set(e, DM_ENOMEM, "geometry: out of memory");
    return NULL;
  }
  G->K = K;
  return G;
}

dm_dec_geom *dm_dec_geom_alloc(const dm_dec_complex *K, int N, const double *X, dm_err *e)
{
  dm_dec_geom *G;
  int s, c;
  if (N < K->n) {
    dm_err_set(e, DM_EINVAL, "geometry: %d coordinates per vertex for a %d-dimensional complex",
               N, K->n);
    return NULL;
  }
  for (s = 0; s < K->nsimp[0] * N; s++)
    if (!isfinite(X[s])) {
      dm_err_set(e, DM_EDOM, "vertex %d: coordinate %d is not finite", s / N + 1, s % N + 1);
      return NULL;
    }
  if ((G = geom_new(K, e)) == NULL)
    return NULL;
  G->N = N;
  G->X = malloc((size_t)K->nsimp[0] * N * sizeof *G->X);
  if (G->X == NULL) {
    dm_dec_geom_free(G);
    dm_err_set(e, DM_ENOMEM, "geometry: out of memory");
    return NULL;
  }
  memcpy(G->X, X, (size_t)K->nsimp[0] * N * sizeof *G->X);
  for (s = 0; s < K->nsimp[1]; s++) {
    const double *a = X + (size_t)K->simp[1][2 * s] * N, *b = X + (size_t)K->simp[1][2 * s + 1] * N;
    double l = 0.0;
    for (c = 0; c < N; c++)
      l += (b[c] - a[c]) * (b[c] - a[c]);
    G->len2[s] = l;
  }
  if (fill(G, e) != DM_OK) {
    dm_dec_geom_free(G);
    return NULL;
  }
  return G;
}

dm_dec_geom *dm_dec_geom_alloc_intrinsic(const dm_dec_complex *K, const double *len2,
                                         dm_err *e)
{
  dm_dec_geom *G;
  int s;
  for (s = 0; s < K->nsimp[1]; s++)
    if (!(len2[s] > 0) || !isfinite(len2[s])) {
      char buf[64];
      simplex_name(K, 1, s, buf, sizeof buf);
      dm_err_set(e, DM_EDOM, "edge %s: squared length %g (positive expected)", buf, len2[s]);
      return NULL;
    }
  if ((G = geom_new(K, e)) == NULL)
    return NULL;
  memcpy(G->len2, len2, (size_t)K->nsimp[1] * sizeof *len2);
  if (fill(G, e) != DM_OK) {
    dm_dec_geom_free(G);
    return NULL;
  }
  return G;
}

int dm_dec_circumcenter_bary(const dm_dec_geom *G, int k, int s, double *b, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  const int *v;
  double D[NV][NV], vol;
  int L[NV], a, c;
  if (k < 0 || k > K->n || s < 0 || s >= K->nsimp[k])
    return dm_err_set(e, DM_EINVAL, "circumcentre: no %d-simplex %d", k, s + 1);
  v = K->simp[k] + (size_t)s * (k + 1);
  for (a = 0; a <= k; a++) {
    L[a] = a;
    for (c = 0; c <= k; c++) {
      int ed[2] = {v[a], v[c]}, id = a == c ? -1 : dm_dec_find(K, 1, ed);
      D[a][c] = id < 0 ? 0.0 : G->len2[id];
    }
  }
  if (simplex_metric(k, D, L, &vol, b) != DM_OK)
    return dm_err_set(e, DM_EDOM, "circumcentre: degenerate %d-simplex %d", k, s + 1);
  return DM_OK;
}
