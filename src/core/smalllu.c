/* smalllu.c -- small dense LU with partial pivoting (see smalllu.h). */
#include <config.h>
#include "core/smalllu.h"
#include "core/status.h"
#include "core/vecmath.h"

#include <float.h>
#include <math.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_vector.h>

/* Right-looking elimination (the classical kji loop), rows swapped whole so
 * that the interchanges can be applied to b up front; the diagonal keeps
 * 1/U_kk, so the back substitution has no division on its dependency chain
 * (measured: a 6 x 6 solve 70 -> 50 ns).  Specialising it for
 * constant n (switch on n, always_inline copies) was measured: no gain at
 * -O2 (GCC keeps the loops), so one generic copy. */
static int factor_small(double *restrict a, size_t n, size_t *restrict perm)
{
  double amax = dm_norm_inf(a, n * n), tiny;
  size_t i, j, k;
  if (!(amax < HUGE_VAL))
    return DM_EDOM;
  tiny = 16.0 * (double)n * DBL_EPSILON * amax;
  for (k = 0; k < n; k++) {
    double *restrict rk = a + k * n, best = fabs(rk[k]), piv;
    size_t p = k;
    for (i = k + 1; i < n; i++) {
      double t = fabs(a[i * n + k]);
      if (t > best) {
        best = t;
        p = i;
      }
    }
    perm[k] = p;
    if (!(best > tiny))
      return DM_ESINGULAR;
    if (p != k) {
      double *restrict rp = a + p * n;
      for (j = 0; j < n; j++) {
        double t = rk[j];
        rk[j] = rp[j];
        rp[j] = t;
      }
    }
    piv = 1.0 / rk[k];
    rk[k] = piv;                     /* the solve multiplies by it */
    for (i = k + 1; i < n; i++) {
      double *restrict ri = a + i * n, f = ri[k] *= piv;
      if (f != 0.0)                  /* block-structured matrices: skip zero rows */
        for (j = k + 1; j < n; j++)
          ri[j] -= f * rk[j];
    }
  }
  return DM_OK;
}

static void solve_small(const double *restrict a, size_t n, const size_t *restrict perm,
                       double *restrict b)
{
  size_t i, j, k;
  for (k = 0; k < n; k++) {
    size_t p = perm[k];
    double t = b[k];
    b[k] = b[p];
    b[p] = t;
  }
  for (i = 1; i < n; i++) {
    double acc = b[i];
    for (j = 0; j < i; j++)
      acc -= a[i * n + j] * b[j];
    b[i] = acc;
  }
  for (i = n; i-- > 0;) {        /* b[i + 1], the newest, is used last */
    double acc = b[i];
    for (j = n - 1; j > i; j--)
      acc -= a[i * n + j] * b[j];
    b[i] = acc * a[i * n + i];
  }
}

int dm_gsl_lu_decomp(gsl_matrix *A, gsl_permutation *p, int *signum)
{
  size_t m = A->size1 < A->size2 ? A->size1 : A->size2;
  gsl_vector_uint *probe = gsl_vector_uint_alloc(m > 0 ? m : 1);
  if (probe == NULL)
    return DM_ENOMEM;
  gsl_vector_uint_free(probe);
  return gsl_linalg_LU_decomp(A, p, signum) == GSL_SUCCESS ? DM_OK : DM_EFAILED;
}

static int factor_gsl(double *a, size_t n, size_t *perm)
{
  gsl_matrix_view A = gsl_matrix_view_array(a, n, n);
  gsl_permutation P = {n, perm};
  double amax = dm_norm_inf(a, n * n), umin = HUGE_VAL;
  size_t i;
  int signum;
  if (!(amax < HUGE_VAL))
    return DM_EDOM;
  if (dm_gsl_lu_decomp(&A.matrix, &P, &signum) == DM_ENOMEM)
    return DM_ENOMEM;
  for (i = 0; i < n; i++) {
    double t = fabs(a[i * n + i]);
    umin = t < umin ? t : umin;
  }
  return umin > 16.0 * (double)n * DBL_EPSILON * amax ? DM_OK : DM_ESINGULAR;
}

int dm_smalllu_factor(double *a, size_t n, size_t *perm)
{
  return n <= DM_SMALLLU_NMAX ? factor_small(a, n, perm) : factor_gsl(a, n, perm);
}

void dm_smalllu_solve(const double *lu, size_t n, const size_t *perm, double *b)
{
  if (n <= DM_SMALLLU_NMAX) {
    solve_small(lu, n, perm, b);
  } else {
    gsl_matrix_const_view A = gsl_matrix_const_view_array(lu, n, n);
    gsl_permutation P = {n, (size_t *)perm};
    gsl_vector_view x = gsl_vector_view_array(b, n);
    gsl_linalg_LU_svx(&A.matrix, &P, &x.vector);
  }
}
