/* diagnostics.c -- structure checks offered as functions (doc/integrators.md §11):
 * step Jacobian and symplecticity defect, time reversal, empirical order. */
#include <config.h>
#include "integrators/integ_impl.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Central differences of the step map, for methods without an exact
 * Jacobian (gsl:*): relative perturbation 1e-5, accurate to about 1e-9. */
static int jacobian_fd(dm_integrator *I, double h, const double *q0, const double *p0,
                       double *DPhi, dm_err *e)
{
  size_t n = I->n, N = 2 * n, j, i;
  double *z = I->scratch + 2 * n, *zp = z + N, *zm = zp + N;
  int st;
  for (j = 0; j < N; j++) {
    double d;
    memcpy(z, q0, n * sizeof(double));
    memcpy(z + n, p0, n * sizeof(double));
    d = 1e-5 * fmax(1.0, fabs(z[j]));
    z[j] += d;
    if ((st = dm_integrator_step(I, h, z, z + n, zp, zp + n, e)) != DM_OK)
      return st;
    z[j] -= 2.0 * d;
    if ((st = dm_integrator_step(I, h, z, z + n, zm, zm + n, e)) != DM_OK)
      return st;
    for (i = 0; i < N; i++)
      DPhi[i * N + j] = (zp[i] - zm[i]) / (2.0 * d);
  }
  return DM_OK;
}

int dm_integrator_jacobian(dm_integrator *I, double h, const double *q0,
                           const double *p0, double *DPhi, dm_err *e)
{
  if (I->m > 0)
    return dm_err_set(e, DM_EUNSUP, "the step Jacobian in the containing space is not defined for "
                      "constrained systems");
  if (I->type->manifold_defect != NULL)
    return dm_err_set(e, DM_EUNSUP, "the step Jacobian in coordinates is not defined for "
                      "method '%s': its states live on a manifold (%s)", I->name,
                      I->sys->space != NULL ? I->sys->space : "not all of the coordinates");
  if (I->nq != I->n)
    return dm_err_set(e, DM_EUNSUP, "the step Jacobian in coordinates is not defined for a "
                      "configuration stored in %zu numbers with %zu velocities (a system on a "
                      "group has its own diagnostics)", I->nq, I->n);
  if (I->type->jacobian != NULL && (I->flags & DM_INTEG_EXACT_JAC))
    return I->type->jacobian(I, h, q0, p0, DPhi, e);
  return jacobian_fd(I, h, q0, p0, DPhi, e);
}

int dm_integrator_symplecticity_defect(dm_integrator *I, double h, const double *q0,
                                       const double *p0, double *defect, dm_err *e)
{
  size_t n = I->n, N = 2 * n, i, j, k;
  double *D, *JD, worst = 0.0;
  int st;
  if (I->type->manifold_defect != NULL)
    return I->type->manifold_defect(I, h, q0, p0, defect, e);
  D = malloc(2 * N * N * sizeof(double));
  if (D == NULL)
    return dm_err_set(e, DM_ENOMEM, "symplecticity defect: out of memory");
  JD = D + N * N;
  if ((st = dm_integrator_jacobian(I, h, q0, p0, D, e)) != DM_OK) {
    free(D);
    return st;
  }
  /* J = [[0, I], [-I, 0]]: (J D)_i = D_{n+i} for i < n, -D_{i-n} otherwise */
  for (i = 0; i < N; i++)
    for (j = 0; j < N; j++)
      JD[i * N + j] = i < n ? D[(n + i) * N + j] : -D[(i - n) * N + j];
  for (i = 0; i < N; i++)
    for (j = 0; j < N; j++) {
      double acc = 0.0, Jij;
      for (k = 0; k < N; k++)
        acc += D[k * N + i] * JD[k * N + j];
      Jij = (i < n && j == n + i) ? 1.0 : (i >= n && j == i - n) ? -1.0 : 0.0;
      worst = fmax(worst, fabs(acc - Jij));
    }
  free(D);
  *defect = worst;
  return DM_OK;
}

int dm_integrator_reversal(dm_integrator *I, double h, long n, const double *q0,
                           const double *p0, double *dev, dm_err *e)
{
  size_t d = I->n, i;
  double *q = I->scratch + 4 * d, *p = q + d;
  long k;
  int st;
  if (I->nq != d)
    return dm_err_set(e, DM_EUNSUP, "reversal in coordinates is not defined for a configuration "
                      "stored in %zu numbers with %zu velocities (a system on a group has its "
                      "own diagnostics)", I->nq, d);
  memcpy(q, q0, d * sizeof(double));
  memcpy(p, p0, d * sizeof(double));
  for (k = 0; k < 2 * n; k++)
    if ((st = dm_integrator_step(I, k < n ? h : -h, q, p, q, p, e)) != DM_OK)
      return st;
  *dev = 0.0;
  for (i = 0; i < d; i++)
    *dev = fmax(*dev, fmax(fabs(q[i] - q0[i]), fabs(p[i] - p0[i])));
  return DM_OK;
}

double dm_integrator_order_fit(const double *h, const double *err, size_t k)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0, den;
  size_t i;
  if (k < 2)
    return NAN;
  for (i = 0; i < k; i++) {
    double x, y;
    if (!(h[i] > 0.0 && err[i] > 0.0))
      return NAN;
    x = log(h[i]);
    y = log(err[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  den = (double)k * sxx - sx * sx;
  return den != 0.0 ? ((double)k * sxy - sx * sy) / den : NAN;
}

static int integrate_to(const dm_system *sys, const char *method, const dm_integ_opts *opts,
                        const double *q0, const double *p0, double T, double h,
                        double *q, double *p, dm_err *e)
{
  dm_integrator *I;
  long nsteps = lround(fabs(T / h));
  int st;
  if (nsteps < 1)
    nsteps = 1;
  if ((st = dm_integrator_new(sys, method, opts, &I, e)) != DM_OK)
    return st;
  memcpy(q, q0, sys->n * sizeof(double));
  memcpy(p, p0, sys->n * sizeof(double));
  st = dm_integrator_run(I, 0.0, q, p, T / (double)nsteps, nsteps, nsteps, NULL, NULL, NULL, e);
  dm_integrator_free(I);
  return st;
}

int dm_integrator_order_estimate(const dm_system *sys, const char *method,
                                 const dm_integ_opts *opts, const double *q0,
                                 const double *p0, double T, const double *h, size_t k,
                                 const double *qref, const double *pref, double *err,
                                 double *order, dm_err *e)
{
  size_t n = sys->n, i, j;
  double *buf, *qr, *pr, *q, *p, *errs, hmin = HUGE_VAL;
  int st = DM_OK;
  if (k < 2 || T == 0.0)
    return dm_err_set(e, DM_EINVAL, "order estimate: need at least 2 step sizes and T != 0");
  if ((buf = calloc(4 * n + k, sizeof(double))) == NULL)
    return dm_err_set(e, DM_ENOMEM, "order estimate: out of memory");
  qr = buf;
  pr = qr + n;
  q = pr + n;
  p = q + n;
  errs = p + n;
  for (i = 0; i < k; i++) {
    if (!(h[i] > 0.0)) {
      free(buf);
      return dm_err_set(e, DM_EINVAL, "order estimate: step sizes must be > 0");
    }
    hmin = fmin(hmin, h[i]);
  }
  if (qref && pref) {
    memcpy(qr, qref, n * sizeof(double));
    memcpy(pr, pref, n * sizeof(double));
  } else {
    /* reference: Gauss 6 (order 12), or Lobatto 6 (order 10) with
     * constraints, at an eighth of the smallest step; for systems of a
     * kind without these (on a sphere) the method itself at a 64th */
    dm_integ_opts ro;
    const char *ref = sys->m ? "lobatto" : "gauss";
    dm_integ_opts_init(&ro);
    ro.stages = 6;
    if (dm_integrator_find(sys->kind, ref, NULL) != NULL)
      st = integrate_to(sys, ref, &ro, q0, p0, T, hmin / 8, qr, pr, e);
    else
      st = integrate_to(sys, method, opts, q0, p0, T, hmin / 64, qr, pr, e);
  }
  for (i = 0; i < k && st == DM_OK; i++) {
    double s2 = 0.0;
    if ((st = integrate_to(sys, method, opts, q0, p0, T, h[i], q, p, e)) != DM_OK)
      break;
    for (j = 0; j < n; j++)
      s2 += (q[j] - qr[j]) * (q[j] - qr[j]) + (p[j] - pr[j]) * (p[j] - pr[j]);
    errs[i] = sqrt(s2);
    if (err)
      err[i] = errs[i];
  }
  if (st == DM_OK && order)
    *order = dm_integrator_order_fit(h, errs, k);
  free(buf);
  return st;
}
