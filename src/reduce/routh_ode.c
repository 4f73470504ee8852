/* routh_ode.c -- the continuous Routh equations integrated by a GSL odeiv2
 * stepper: the non-symplectic references of the reduced dynamics (methods
 * rk4 and gsl:<stepper> on a reduced system).  The first-order system on
 * y = (x, s, theta) is
 *   xdot:  dR/dxdot (x, xdot) = s        (Newton; one step for a mechanical R)
 *   sdot = dR/dx (x, xdot) - i_xdot beta_mu + Fhat(x, xdot)
 *   thetadot = I^{-1} mu - A xdot        (numerically: J = mu, non-mechanical L)
 * with R the reduced system's Lagrangian (R^mu, or the classical Routhian
 * of a non-mechanical L, where beta does not appear) -- the Routh
 * equations ∂R/∂x - d/dt ∂R/∂xdot = i_xdot beta in the momentum s = ∂R/∂xdot.
 * theta rides along with the same stepper, so its order is the method's.
 * Fixed steps call gsl_odeiv2_step_apply; the explicit Runge-Kutta
 * steppers are offered (the implicit and multistep ones need the Jacobian
 * of this field, which is not formed). */
#include <config.h>
#include "reduce/routh_impl.h"
#include "core/smalllu.h"
#include "core/numfmt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

static const struct {
  const char *name;
  const gsl_odeiv2_step_type *const *type;
} steppers[] = {
  {"rk2", &gsl_odeiv2_step_rk2}, {"rk4", &gsl_odeiv2_step_rk4},
  {"rkf45", &gsl_odeiv2_step_rkf45}, {"rkck", &gsl_odeiv2_step_rkck},
  {"rk8pd", &gsl_odeiv2_step_rk8pd},
};
static const char *const implicit[] = {"rk1imp", "rk2imp", "rk4imp", "bsimp", "msadams", "msbdf",
                                       NULL};

struct dm_rode {
  dm_routh *red;
  gsl_odeiv2_step *step;
  gsl_odeiv2_system sys;
  size_t dim;
  double *y, *yerr, *xd, *Lq, *Lv, *M, *F, *tin, *tout, *twork;
  size_t *perm;
  void *rwork;                     /* reduced system callbacks / thetadot solve */
  dm_err err;
};

void dm_rode_free(dm_rode *O)
{
  if (O == NULL)
    return;
  if (O->step)
    gsl_odeiv2_step_free(O->step);
  free(O->y);
  free(O->perm);
  free(O->rwork);
  free(O);
}

/* xdot with dR/dxdot (x, xdot) = s from the previous xdot (Newton) */
static int velocity(dm_rode *O, const double *x, const double *s_)
{
  const dm_routh *red = O->red;
  const dm_system *R = &red->rsys;
  size_t d = red->s, i;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it;
  for (it = 0; it < 50; it++) {
    dm_lag_out o = {0, NULL, O->Lv, O->M, NULL, NULL};
    double dn;
    if (R->lagrangian(R->data, x, O->xd, red->par, DM_LAG_V | DM_LAG_VV, &o, O->rwork) != 0)
      return dm_err_set(&O->err, DM_EDOM, "the Routhian is outside its domain at x = %s",
                        dm_num_format_vec((char[200]){0}, 200, x, d));
    for (i = 0; i < d; i++)
      O->F[i] = O->Lv[i] - s_[i];
    if (dm_smalllu_factor(O->M, d, O->perm) != DM_OK)
      return dm_err_set(&O->err, DM_ESINGULAR, "d2R/dxdot2 is singular at x = %s",
                        dm_num_format_vec((char[200]){0}, 200, x, d));
    dm_smalllu_solve(O->M, d, O->perm, O->F);
    for (i = 0; i < d; i++)
      O->xd[i] -= O->F[i];
    dn = dm_rnorm_inf(O->F, d) / fmax(dm_rnorm_inf(O->xd, d), DBL_MIN);
    if (!isfinite(dn))
      return dm_err_set(&O->err, DM_EDOM, "the reduced velocity is not finite at x = %s",
                        dm_num_format_vec((char[200]){0}, 200, x, d));
    if (dm_rnorm_inf(O->F, d) == 0.0 || dm_newton_done(&stop, dn, 10 * DBL_EPSILON))
      return DM_OK;
  }
  return dm_err_set(&O->err, DM_ENOCONV, "the reduced Legendre map dR/dxdot = s did not converge");
}

static int field(double t, const double y[], double dydt[], void *params)
{
  dm_rode *O = params;
  const dm_routh *red = O->red;
  const dm_system *R = &red->rsys;
  size_t d = red->s, r = red->r, i;
  const double *x = y, *s_ = y + d;
  dm_lag_out o = {0, O->Lq, NULL, NULL, NULL, NULL};
  (void)t;
  if (velocity(O, x, s_) != DM_OK)
    return GSL_EBADFUNC;
  if (R->lagrangian(R->data, x, O->xd, red->par, DM_LAG_Q, &o, O->rwork) != 0) {
    dm_err_set(&O->err, DM_EDOM, "the Routhian is outside its domain");
    return GSL_EBADFUNC;
  }
  for (i = 0; i < d; i++) {
    dydt[i] = O->xd[i];
    dydt[d + i] = O->Lq[i];
  }
  if (R->force) {
    if (R->force(R->data, x, O->xd, red->par, DM_FORCE_F, O->F, NULL, NULL, O->rwork) != 0) {
      dm_err_set(&O->err, DM_EDOM, "the reduced force is outside its domain");
      return GSL_EBADFUNC;
    }
    for (i = 0; i < d; i++)
      dydt[d + i] += O->F[i];
  }
  if (red->general) {
    if (dm_routh_general_thetadot(red, x, O->xd, red->par, dydt + 2 * d, O->rwork)) {
      dm_err_set(&O->err, DM_EDOM, "J = mu has no solution thetadot here");
      return GSL_EBADFUNC;
    }
    return GSL_SUCCESS;
  }
  memcpy(O->tin, x, d * sizeof(double));
  memcpy(O->tin + d, O->xd, d * sizeof(double));
  if (red->has_gyro) {           /* gyro_r: muA, kv, ib = i_xdot B */
    dm_rprog_run(&red->gyro_r, O->tin, red->par, O->tout, O->twork);
    for (i = 0; i < d; i++)
      dydt[d + i] -= O->tout[2 * d + i];
  }
  dm_rprog_run(&red->thd, O->tin, red->par, O->tout, O->twork);
  memcpy(dydt + 2 * d, O->tout, r * sizeof(double));
  for (i = 0; i < 2 * d + r; i++)
    if (!isfinite(dydt[i])) {
      dm_err_set(&O->err, DM_EDOM, "the reduced vector field is not finite at x = %s (singular "
                 "locked inertia?)", dm_num_format_vec((char[200]){0}, 200, x, d));
      return GSL_EBADFUNC;
    }
  return GSL_SUCCESS;
}

int dm_rode_alloc(dm_routh *red, const char *stepper, dm_rode **out, int *order, dm_err *e)
{
  const gsl_odeiv2_step_type *T = NULL;
  size_t d = red->s, r = red->r, k, nout, wsz;
  dm_rode *O;
  double *p;
  *out = NULL;
  for (k = 0; k < sizeof steppers / sizeof steppers[0]; k++)
    if (strcmp(steppers[k].name, stepper) == 0)
      T = *steppers[k].type;
  if (T == NULL) {
    for (k = 0; implicit[k] != NULL; k++)
      if (strcmp(implicit[k], stepper) == 0)
        return dm_err_set(e, DM_EUNSUP, "gsl:%s on a reduced system: implicit and multistep "
                          "steppers need the Jacobian of the reduced vector field, which is not "
                          "formed; explicit ones: rk2, rk4, rkf45, rkck, rk8pd", stepper);
    return dm_err_set(e, DM_ENOTFOUND, "unknown GSL stepper '%s' for a reduced system (rk2, rk4, "
                      "rkf45, rkck, rk8pd)", stepper);
  }
  if (red->m > 0)
    return dm_err_set(e, DM_EUNSUP, "rk4 and gsl:<stepper> integrate the Routh equations without "
                      "constraints; use an RSPRK method (lobatto, midpoint) on a constrained "
                      "reduction");
  if ((O = calloc(1, sizeof *O)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  O->red = red;
  O->dim = 2 * d + r;
  nout = red->gyro_r.nout > red->thd.nout ? red->gyro_r.nout : red->thd.nout;
  wsz = red->rsys.work_size;
  if (red->general && dm_routh_general_work(red) > wsz)
    wsz = dm_routh_general_work(red);
  O->y = calloc(2 * O->dim + 5 * d + d * d + 2 * d + nout + red->nwork + 8, sizeof(double));
  O->perm = calloc(d ? d : 1, sizeof *O->perm);
  O->rwork = malloc(wsz + 8);
  O->step = gsl_odeiv2_step_alloc(T, O->dim);
  if (O->y == NULL || O->perm == NULL || O->rwork == NULL || O->step == NULL) {
    dm_rode_free(O);
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  p = O->y + O->dim;
  O->yerr = p; p += O->dim;
  O->xd = p; p += d;
  O->Lq = p; p += d;
  O->Lv = p; p += d;
  O->F = p; p += d;
  O->M = p; p += d * d;
  O->tin = p; p += 2 * d + d;
  O->tout = p; p += nout;
  O->twork = p;
  O->sys.function = field;
  O->sys.jacobian = NULL;
  O->sys.dimension = O->dim;
  O->sys.params = O;
  *order = (int)gsl_odeiv2_step_order(O->step);
  *out = O;
  return DM_OK;
}

void dm_rode_reset(dm_rode *O)
{
  gsl_odeiv2_step_reset(O->step);
  memset(O->xd, 0, O->red->s * sizeof(double));
}

int dm_rode_step(dm_rode *O, double h, const double *x0, const double *s0, double *x1, double *s1,
                 double *dtheta, dm_err *e)
{
  size_t d = O->red->s, r = O->red->r;
  int st;
  memcpy(O->y, x0, d * sizeof(double));
  memcpy(O->y + d, s0, d * sizeof(double));
  memset(O->y + 2 * d, 0, r * sizeof(double));
  O->err.status = DM_OK;
  O->err.msg[0] = '\0';
  st = gsl_odeiv2_step_apply(O->step, 0.0, h, O->y, O->yerr, NULL, NULL, &O->sys);
  if (st != GSL_SUCCESS) {
    if (e && O->err.status != DM_OK)
      *e = O->err;
    else
      dm_err_set(e, DM_EDOM, "GSL stepper failed (%s)", gsl_strerror(st));
    return O->err.status != DM_OK ? O->err.status : DM_EDOM;
  }
  memcpy(x1, O->y, d * sizeof(double));
  memcpy(s1, O->y + d, d * sizeof(double));
  if (dtheta)
    memcpy(dtheta, O->y + 2 * d, r * sizeof(double));
  return DM_OK;
}
