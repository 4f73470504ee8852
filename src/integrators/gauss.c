/* gauss.c -- midpoint (Gauss s=1) and Gauss-Legendre Galerkin integrators
 * (doc/integrators.md §4): order 2s, symmetric, symplectic, conserve every
 * quadratic invariant the Lagrangian respects.  The step is the implicit
 * PRK of prk_engine.c on the Gauss table of tableau.c.
 *
 * Discrete-Lagrangian view.  The midpoint rule is the variational integrator
 * of L_d(q0, q1) = h L((q0+q1)/2, (q1-q0)/h); its discrete Legendre
 * transforms are computed here in closed form (with the Lagrange-d'Alembert
 * discrete forces F_d^- = F_d^+ = (h/2) F((q0+q1)/2, (q1-q0)/h)):
 *   p0 = Lv - (h/2)(Lq + F),   p1 = Lv + (h/2)(Lq + F).
 * For s >= 2, L_d = h sum b_i L(Q_i, V_i) at the stationary stages (Suris)
 * and the transforms come from the engine's boundary problem. */
#include <config.h>
#include "integrators/prk_impl.h"

#include <string.h>

static const char *const gauss_options[] = {"stages", "h", "tol", "maxiter", "simplified",
                                            "linear", "iteration", NULL};
static const char *const midpoint_options[] = {"h", "tol", "maxiter", "simplified", "linear",
                                               "iteration", NULL};

static int make(dm_integrator *I, size_t s, dm_err *e)
{
  dm_tableau *t;
  int st = dm_tableau_gauss(s, &t, e);
  if (st != DM_OK)
    return st;
  st = dm_prk_type_setup(I, t, e);
  dm_tableau_free(t);
  return st;
}

static int gauss_alloc(dm_integrator *I, dm_err *e)
{
  if (I->opt.stages < 0 || I->opt.stages > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "gauss: stages = %d out of range 1..%d", I->opt.stages,
                      DM_TABLEAU_SMAX);
  return make(I, I->opt.stages ? (size_t)I->opt.stages : 2, e);
}

static int midpoint_alloc(dm_integrator *I, dm_err *e)
{
  if (I->opt.stages != 0 && I->opt.stages != 1)
    return dm_err_set(e, DM_EINVAL, "midpoint has exactly 1 stage (got stages = %d); use 'gauss'",
                      I->opt.stages);
  return make(I, 1, e);
}

static int midpoint_dlegendre(dm_integrator *I, double h, const double *q0, const double *q1,
                              double *p0, double *p1, double *Ld, dm_err *e)
{
  dm_prk *P = I->state;
  size_t n = P->n, a;
  int st = dm_prk_dleg_check(P, h, e);
  if (st != DM_OK)
    return st;
  for (a = 0; a < n; a++) {
    P->Q[a] = 0.5 * (q0[a] + q1[a]);
    P->X[a] = (q1[a] - q0[a]) / h;
  }
  if ((st = dm_prk_eval_stage(P, 0, 0, 1, e)) != DM_OK)
    return st;
  for (a = 0; a < n; a++) {
    double lv = P->Lv[a], w = 0.5 * h * P->W[a];
    if (p0)
      p0[a] = lv - w;
    if (p1)
      p1[a] = lv + w;
  }
  if (Ld)
    *Ld = h * P->Lval[0];
  return DM_OK;
}

const dm_integrator_type dm_integ_midpoint = {
  .name = "midpoint",
  .summary = "implicit midpoint = Gauss 1, L_d = h L((q0+q1)/2, (q1-q0)/h); order 2, symmetric, symplectic",
  .order = 2,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES
    | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = midpoint_options,
  .alloc = midpoint_alloc,
  .step = dm_prk_type_step,
  .jacobian = dm_prk_type_jacobian,
  .dlegendre = midpoint_dlegendre,
  .advance = dm_prk_type_advance,
  .reset = dm_prk_type_reset,
  .free = dm_prk_type_free,
};

const dm_integrator_type dm_integ_gauss = {
  .name = "gauss",
  .summary = "Gauss-Legendre Galerkin integrator with s stages (default 2); order 2s, symmetric, symplectic "
    "(constraints only with s = 1)",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES
    | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = gauss_options,
  .alloc = gauss_alloc,
  .step = dm_prk_type_step,
  .jacobian = dm_prk_type_jacobian,
  .dlegendre = dm_prk_type_dlegendre,
  .advance = dm_prk_type_advance,
  .reset = dm_prk_type_reset,
  .free = dm_prk_type_free,
};
