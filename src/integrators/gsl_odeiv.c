/* gsl_odeiv.c -- GSL odeiv2 steppers as non-symplectic references,
 * method "gsl:<stepper>" (rk2, rk4, rkf45, rkck, rk8pd, rk1imp, rk2imp,
 * rk4imp, bsimp, msadams, msbdf) on the Hamiltonian form y = (q, p),
 * ydot = (v(q, p), Lq + F), with the exact Jacobian for the implicit ones.
 * Fixed steps call gsl_odeiv2_step_apply directly (the driver's
 * apply_fixed_step would reject steps whose error estimate exceeds the
 * tolerances); the stepper stays attached to a driver, whose tolerances
 * epsabs/epsrel the implicit and multistep steppers use internally.
 * Option adaptive = true integrates each h with gsl_odeiv2_driver_apply;
 * the multistep msadams and msbdf require it.  Note (doc/integrators.md §13): rk4imp with a fixed step
 * h takes two Gauss-2 steps of h/2 (step doubling); its internal Newton
 * uses the driver tolerances.  The step Jacobian is not available in closed
 * form (finite differences are used by the diagnostics). */
#include <config.h>
#include "integrators/integ_impl.h"

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
  {"rk8pd", &gsl_odeiv2_step_rk8pd}, {"rk1imp", &gsl_odeiv2_step_rk1imp},
  {"rk2imp", &gsl_odeiv2_step_rk2imp}, {"rk4imp", &gsl_odeiv2_step_rk4imp},
  {"bsimp", &gsl_odeiv2_step_bsimp}, {"msadams", &gsl_odeiv2_step_msadams},
  {"msbdf", &gsl_odeiv2_step_msbdf},
};

typedef struct gsl_state {
  dm_integrator *I;
  gsl_odeiv2_system sys;
  gsl_odeiv2_driver *d;
  double *y, *yerr, *hq1, *hp1;
  double last_h, t;
  int hist;
  dm_err err;
} gsl_state;

static const char *const gsl_options[] = {"h", "adaptive", "epsabs", "epsrel", NULL};

static int rhs(double t, const double y[], double dydt[], void *params)
{
  gsl_state *S = params;
  size_t n = S->I->n;
  (void)t;
  return dm_legendre_field(S->I->leg, y, y + n, dydt, dydt + n, &S->err) == DM_OK ? GSL_SUCCESS
                                                                              : GSL_EBADFUNC;
}

static int jac(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
  gsl_state *S = params;
  size_t n = S->I->n;
  (void)t;
  memset(dfdt, 0, 2 * n * sizeof(double));
  return dm_legendre_field_jac(S->I->leg, y, y + n, dfdy, &S->err) == DM_OK ? GSL_SUCCESS
                                                                        : GSL_EBADFUNC;
}

static void gsl_free_state(dm_integrator *I)
{
  gsl_state *S = I->state;
  if (S) {
    if (S->d)
      gsl_odeiv2_driver_free(S->d);
    free(S->y);
    free(S);
  }
  I->state = NULL;
}

static int gsl_alloc(dm_integrator *I, dm_err *e)
{
  const gsl_odeiv2_step_type *T = NULL;
  gsl_state *S;
  size_t i, n = I->n;
  for (i = 0; i < sizeof steppers / sizeof steppers[0]; i++)
    if (strcmp(I->variant, steppers[i].name) == 0)
      T = *steppers[i].type;
  if (T == NULL)
    return dm_err_set(e, DM_ENOTFOUND, "unknown GSL stepper '%s' in method '%s' (known: rk2, rk4, "
                      "rkf45, rkck, rk8pd, rk1imp, rk2imp, rk4imp, bsimp, msadams, msbdf)",
                      I->variant, I->name);
  if (!I->opt.adaptive && (T == gsl_odeiv2_step_msadams || T == gsl_odeiv2_step_msbdf))
    return dm_err_set(e, DM_EINVAL, "%s is a variable-order multistep method driven by its error "
                      "control: use it with adaptive = true", I->name);
  if ((S = calloc(1, sizeof *S)) == NULL || (S->y = calloc(6 * n, sizeof(double))) == NULL) {
    free(S);
    return dm_err_set(e, DM_ENOMEM, "gsl: out of memory");
  }
  I->state = S;
  S->I = I;
  S->yerr = S->y + 2 * n;
  S->hq1 = S->yerr + 2 * n;
  S->hp1 = S->hq1 + n;
  S->sys.function = rhs;
  S->sys.jacobian = jac;
  S->sys.dimension = 2 * n;
  S->sys.params = S;
  S->d = gsl_odeiv2_driver_alloc_y_new(&S->sys, T, 1e-3, I->opt.epsabs, I->opt.epsrel);
  if (S->d == NULL) {
    gsl_free_state(I);
    return dm_err_set(e, DM_ENOMEM, "gsl: cannot allocate the odeiv2 driver");
  }
  I->order = (int)gsl_odeiv2_step_order(S->d->s);
  I->flags = DM_INTEG_FORCES | (I->opt.adaptive ? DM_INTEG_ADAPTIVE : 0u);
  return DM_OK;
}

static int gsl_step(dm_integrator *I, double h, const double *q0, const double *p0,
                    double *q1, double *p1, dm_err *e)
{
  gsl_state *S = I->state;
  size_t n = I->n;
  double t = 0.0;
  int gs;
  int cont = S->hist && memcmp(q0, S->hq1, n * sizeof(double)) == 0
             && memcmp(p0, S->hp1, n * sizeof(double)) == 0 && h == S->last_h;
  memcpy(S->y, q0, n * sizeof(double));
  memcpy(S->y + n, p0, n * sizeof(double));
  if (!cont) {
    gsl_odeiv2_driver_reset_hstart(S->d, h);
    S->t = 0.0;
  }
  t = S->t;
  dm_err_clear(&S->err);
  S->hist = 0;
  if (I->opt.adaptive) {
    gs = gsl_odeiv2_driver_apply(S->d, &t, S->t + h, S->y);
  } else {
    gs = gsl_odeiv2_step_apply(S->d->s, t, h, S->y, S->yerr, NULL, NULL, &S->sys);
    t += h;
  }
  if (gs != GSL_SUCCESS) {
    if (S->err.status != DM_OK)
      return dm_err_set(e, S->err.status, "%s", S->err.msg);
    return dm_err_set(e, dm_from_gsl(gs) == DM_OK ? DM_EFAILED : dm_from_gsl(gs),
                      "GSL stepper '%s' failed: %s (GSL status %d, h = %g)", I->variant,
                      gsl_strerror(gs), gs, h);
  }
  memcpy(q1, S->y, n * sizeof(double));
  memcpy(p1, S->y + n, n * sizeof(double));
  memcpy(S->hq1, S->y, n * sizeof(double));
  memcpy(S->hp1, S->y + n, n * sizeof(double));
  S->last_h = h;
  S->t = t;
  S->hist = 1;
  I->stats.steps++;
  return DM_OK;
}

static void gsl_reset(dm_integrator *I)
{
  gsl_state *S = I->state;
  S->hist = 0;
  gsl_odeiv2_driver_reset(S->d);
}

const dm_integrator_type dm_integ_gsl = {
  .name = "gsl",
  .summary = "GSL odeiv2 stepper gsl:<name> on (q, p) (non-symplectic reference; fixed or adaptive steps)",
  .order = 0,
  .flags = DM_INTEG_FORCES,
  .options = gsl_options,
  .alloc = gsl_alloc,
  .step = gsl_step,
  .jacobian = NULL,
  .dlegendre = NULL,
  .advance = NULL,
  .reset = gsl_reset,
  .free = gsl_free_state,
};
