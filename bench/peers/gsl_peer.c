/* gsl_peer.c -- see gsl_peer.h. */
#include <config.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include "gsl_peer.h"
#include "problems.h"

static int rhs_kep(double t, const double y[], double dy[], void *par)
{
  (void)t; (void)par;
  dy[0] = y[2];
  dy[1] = y[3];
  kep_force(y, dy + 2);
  return GSL_SUCCESS;
}

static int rhs_j2(double t, const double y[], double dy[], void *par)
{
  (void)t; (void)par;
  dy[0] = y[3];
  dy[1] = y[4];
  dy[2] = y[5];
  j2_force(y, dy + 3);
  return GSL_SUCCESS;
}

static void fill_jac(int n, const double *D, double *J, double *dfdt)
{
  int i, j, N = 2 * n;
  memset(J, 0, (size_t)(N * N) * sizeof(double));
  for (i = 0; i < n; i++) {
    J[i * N + n + i] = 1.0;
    for (j = 0; j < n; j++)
      J[(n + i) * N + j] = D[i * n + j];
  }
  memset(dfdt, 0, (size_t)N * sizeof(double));
}

static int jac_kep(double t, const double y[], double *J, double dfdt[], void *par)
{
  double D[4];
  (void)t; (void)par;
  kep_dforce(y, D);
  fill_jac(2, D, J, dfdt);
  return GSL_SUCCESS;
}

static int jac_j2(double t, const double y[], double *J, double dfdt[], void *par)
{
  double D[9];
  (void)t; (void)par;
  j2_dforce(y, D);
  fill_jac(3, D, J, dfdt);
  return GSL_SUCCESS;
}

gsl_odeiv2_system gp_system(int prob)
{
  gsl_odeiv2_system s;
  if (prob == GP_KEPLER) {
    s.function = rhs_kep;
    s.jacobian = jac_kep;
    s.dimension = 4;
  } else {
    s.function = rhs_j2;
    s.jacobian = jac_j2;
    s.dimension = 6;
  }
  s.params = NULL;
  return s;
}

double gp_energy(int prob, const double *y)
{
  return prob == GP_KEPLER ? kep_energy(y, y + 2) : j2_energy(y, y + 3);
}

int gp_fixed(const gsl_odeiv2_step_type *T, int prob, double h, long N, double *y, double eps)
{
  gsl_odeiv2_system s = gp_system(prob);
  gsl_odeiv2_driver *d = gsl_odeiv2_driver_alloc_y_new(&s, T, h, eps, 0.0);
  double yerr[6], t = 0.0;
  long k;
  int st = GSL_SUCCESS;
  if (d == NULL)
    return GSL_ENOMEM;
  for (k = 0; k < N && st == GSL_SUCCESS; k++) {
    st = gsl_odeiv2_step_apply(d->s, t, h, y, yerr, NULL, NULL, &s);
    t += h;
  }
  gsl_odeiv2_driver_free(d);
  return st;
}

int gp_adaptive(const gsl_odeiv2_step_type *T, int prob, double t1, double tol, double *y,
                double *maxdH, long *nsteps)
{
  gsl_odeiv2_system s = gp_system(prob);
  size_t dim = s.dimension;
  gsl_odeiv2_step *st = gsl_odeiv2_step_alloc(T, dim);
  gsl_odeiv2_control *c = gsl_odeiv2_control_y_new(tol, tol);
  gsl_odeiv2_evolve *ev = gsl_odeiv2_evolve_alloc(dim);
  double t = 0.0, h = 1e-3, H0 = gp_energy(prob, y), m = 0.0;
  long k = 0;
  int rc = GSL_SUCCESS;
  while (t < t1) {
    rc = gsl_odeiv2_evolve_apply(ev, c, st, &s, &t, t1, &h, y);
    if (rc != GSL_SUCCESS)
      break;
    k++;
    if (maxdH)
      m = fmax(m, fabs(gp_energy(prob, y) - H0));
  }
  if (maxdH)
    *maxdH = m;
  if (nsteps)
    *nsteps = k;
  gsl_odeiv2_evolve_free(ev);
  gsl_odeiv2_control_free(c);
  gsl_odeiv2_step_free(st);
  return rc;
}
