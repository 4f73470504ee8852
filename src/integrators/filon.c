/* filon.c -- Filon weights for the Lagrange basis of any nodes and the
 * phase-sampled weight matrix of the multiscale integrators
 * (doc/beyond-fixed-steps.md §4.2).  See multiscale.h. */
#include <config.h>
#include "integrators/multiscale.h"

#include <complex.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_linalg.h>

#define NUMAX 12

/* l_i(x) by the product formula */
static double lagrange(size_t nu, const double *c, size_t i, double x)
{
  double v = 1.0;
  for (size_t k = 0; k < nu; k++)
    if (k != i)
      v *= (x - c[k]) / (c[i] - c[k]);
  return v;
}

/* into nu complex numbers */
static int weights(size_t nu, const double *c, double theta, double complex *b, dm_err *e)
{
  size_t i, j, r;
  if (nu < 1 || nu > NUMAX)
    return dm_err_set(e, DM_EINVAL, "filon: 1..%d nodes, got %zu", NUMAX, nu);
  for (i = 0; i < nu; i++) {
    if (!(c[i] >= 0.0 && c[i] <= 1.0))
      return dm_err_set(e, DM_EINVAL, "filon: node %zu = %g outside [0, 1]", i, c[i]);
    for (j = 0; j < i; j++)
      if (c[i] == c[j])
        return dm_err_set(e, DM_EINVAL, "filon: nodes %zu and %zu coincide", j, i);
  }
  if (!isfinite(theta))
    return dm_err_set(e, DM_EINVAL, "filon: theta must be finite");
  if (fabs(theta) < (double)nu + 1.0) {
    /* 20-point Gauss-Legendre on [0, 1]: polynomial of degree nu - 1 times
     * e^{i theta x} with |theta| < nu + 1, to round-off */
    gsl_integration_glfixed_table *t = gsl_integration_glfixed_table_alloc(20);
    if (t == NULL)
      return dm_err_set(e, DM_ENOMEM, "filon: out of memory");
    for (i = 0; i < nu; i++)
      b[i] = 0.0;
    for (size_t g = 0; g < 20; g++) {
      double x, w;
      gsl_integration_glfixed_point(0.0, 1.0, g, &x, &w, t);
      double complex ph = cexp(I * theta * x);
      for (i = 0; i < nu; i++)
        b[i] += w * lagrange(nu, c, i, x) * ph;
    }
    gsl_integration_glfixed_table_free(t);
    return DM_OK;
  }
  /* moments and the monomial coefficients of l_i (V a = e_i, V_kr = c_k^r) */
  double complex mu[NUMAX], eit = cexp(I * theta);
  double V[NUMAX * NUMAX], coef[NUMAX];
  size_t perm_data[NUMAX];
  gsl_permutation perm = {nu, perm_data};
  int signum;
  mu[0] = (eit - 1.0) / (I * theta);
  for (r = 1; r < nu; r++)
    mu[r] = (eit - (double)r * mu[r - 1]) / (I * theta);
  for (i = 0; i < nu; i++)
    for (r = 0; r < nu; r++)
      V[i * nu + r] = pow(c[i], (double)r);
  gsl_matrix_view Vm = gsl_matrix_view_array(V, nu, nu);
  if (gsl_linalg_LU_decomp(&Vm.matrix, &perm, &signum) != GSL_SUCCESS)
    return dm_err_set(e, DM_ESINGULAR, "filon: singular Vandermonde matrix");
  for (i = 0; i < nu; i++) {
    gsl_vector_view cv = gsl_vector_view_array(coef, nu);
    gsl_vector_set_basis(&cv.vector, i);
    gsl_linalg_LU_svx(&Vm.matrix, &perm, &cv.vector);
    b[i] = 0.0;
    for (r = 0; r < nu; r++)
      b[i] += coef[r] * mu[r];
  }
  return DM_OK;
}

int dm_filon_weights(size_t nu, const double *c, double theta, double *b, dm_err *e)
{
  double complex z[NUMAX];
  int st = weights(nu, c, theta, z, e);
  for (size_t i = 0; st == DM_OK && i < nu; i++) {
    b[2 * i] = creal(z[i]);
    b[2 * i + 1] = cimag(z[i]);
  }
  return st;
}

int dm_filon_phase_weights(size_t nu, const double *c, size_t K, double h, double omega,
                           double *C, dm_err *e)
{
  double complex b[NUMAX];
  size_t i, j;
  long n, nmax = ((long)K - 1) / 2;          /* |n| < K/2 */
  int st;
  if (K < 1 || K > 1024)
    return dm_err_set(e, DM_EINVAL, "filon: 1..1024 phases, got %zu", K);
  if (!isfinite(h) || !isfinite(omega))
    return dm_err_set(e, DM_EINVAL, "filon: h and omega must be finite");
  memset(C, 0, nu * K * sizeof *C);
  for (n = -nmax; n <= nmax; n++) {
    if ((st = weights(nu, c, (double)n * omega * h, b, e)) != DM_OK)
      return st;
    for (i = 0; i < nu; i++)
      for (j = 0; j < K; j++)
        C[i * K + j] += h / (double)K
                        * creal(b[i] * cexp(-I * (double)n * 2.0 * M_PI * (double)j / (double)K));
  }
  return DM_OK;
}
