/* derham.c -- the de Rham map: integrals of forms over primal simplices by
 * fixed quadrature rules. */
#include <config.h>
#include <math.h>
#include <stdlib.h>

#include "core/interrupt.h"
#include "dec/dec.h"

/* Gauss-Legendre, 3 points on [0, 1]: exact to degree 5. */
static const double gl_t[3] = {0.11270166537925831, 0.5, 0.8872983346207417};
static const double gl_w[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};

/* Triangle, 7 points (Radon / Dunavant degree 5), barycentric; weights sum 1. */
static const double tri_b[7][3] = {
  {1.0 / 3, 1.0 / 3, 1.0 / 3},
  {0.059715871789770, 0.470142064105115, 0.470142064105115},
  {0.470142064105115, 0.059715871789770, 0.470142064105115},
  {0.470142064105115, 0.470142064105115, 0.059715871789770},
  {0.797426985353087, 0.101286507323456, 0.101286507323456},
  {0.101286507323456, 0.797426985353087, 0.101286507323456},
  {0.101286507323456, 0.101286507323456, 0.797426985353087}};
static const double tri_w[7] = {0.225, 0.132394152788506, 0.132394152788506,
                                0.132394152788506, 0.125939180544827,
                                0.125939180544827, 0.125939180544827};

/* Tetrahedron, 5 points, degree 3 (Keast): -4/5 at the centroid, 9/20 at the
 * points with barycentrics (1/2, 1/6, 1/6, 1/6). */
static const double tet_w[5] = {-0.8, 0.45, 0.45, 0.45, 0.45};

static double orient_det(const double *X, int N, const int *v, int n)
{
  double a[3][3];
  int i, c;
  for (i = 0; i < n; i++)
    for (c = 0; c < n; c++)
      a[i][c] = X[(size_t)v[i + 1] * N + c] - X[(size_t)v[0] * N + c];
  if (n == 2)
    return a[0][0] * a[1][1] - a[0][1] * a[1][0];
  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
         a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

int dm_dec_derham(const dm_dec_geom *G, int k, dm_dec_fn f, void *ud, double *out,
                  dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, N = G->N, s, q, c, i;
  double x[8], val[8];
  if (G->X == NULL)
    return dm_err_set(e, DM_EUNSUP, "de Rham map: an intrinsic mesh has no coordinates");
  if (N > 8)
    return dm_err_set(e, DM_EUNSUP, "de Rham map: at most 8 coordinates");
  if (k == 0) {
    for (s = 0; s < K->nsimp[0]; s++) {
      if (f(G->X + (size_t)s * N, val, ud) != 0)
        return dm_err_set(e, DM_ECALLBACK, "de Rham map: the function failed at vertex %d", s + 1);
      out[s] = val[0];
    }
    return DM_OK;
  }
  if (k == 1) {
    for (s = 0; s < K->nsimp[1]; s++) {
      const double *a = G->X + (size_t)K->simp[1][2 * s] * N;
      const double *b = G->X + (size_t)K->simp[1][2 * s + 1] * N;
      double acc = 0.0;
      for (q = 0; q < 3; q++) {
        double dot = 0.0;
        for (c = 0; c < N; c++)
          x[c] = a[c] + gl_t[q] * (b[c] - a[c]);
        if (f(x, val, ud) != 0)
          return dm_err_set(e, DM_ECALLBACK, "de Rham map: the function failed on edge %d", s + 1);
        for (c = 0; c < N; c++)
          dot += val[c] * (b[c] - a[c]);
        acc += gl_w[q] * dot;
      }
      out[s] = acc;
      if ((s & 4095) == 0 && dm_interrupted())
        return dm_err_set(e, DM_EINTR, "de Rham map: interrupted");
    }
    return DM_OK;
  }
  if (k == n && n == N && (n == 2 || n == 3)) {
    for (s = 0; s < K->nsimp[n]; s++) {
      const int *v = K->top + (size_t)s * (n + 1);
      double det = orient_det(G->X, N, v, n), acc = 0.0;
      int np = n == 2 ? 7 : 5;
      for (q = 0; q < np; q++) {
        double b[4];
        if (n == 2) {
          b[0] = tri_b[q][0]; b[1] = tri_b[q][1]; b[2] = tri_b[q][2];
        } else {
          for (i = 0; i < 4; i++)
            b[i] = q == 0 ? 0.25 : (i == q - 1 ? 0.5 : 1.0 / 6);
        }
        for (c = 0; c < N; c++) {
          x[c] = 0.0;
          for (i = 0; i <= n; i++)
            x[c] += b[i] * G->X[(size_t)v[i] * N + c];
        }
        if (f(x, val, ud) != 0)
          return dm_err_set(e, DM_ECALLBACK, "de Rham map: the function failed on simplex %d", s + 1);
        acc += (n == 2 ? tri_w[q] : tet_w[q]) * val[0];
      }
      out[s] = acc * det / (n == 2 ? 2.0 : 6.0);
    }
    return DM_OK;
  }
  return dm_err_set(e, DM_EUNSUP,
                    "de Rham map of %d-forms on a %d-dimensional mesh in R^%d: only degrees 0, 1 and n = N are supported",
                    k, n, N);
}
