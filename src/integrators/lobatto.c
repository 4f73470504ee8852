/* lobatto.c -- trapezoid (Lobatto IIIA-IIIB s=2) and Lobatto IIIA-IIIB
 * Galerkin integrators (doc/integrators.md §4): order 2s-2, symmetric,
 * symplectic.  For separable unforced L the s=2 step is explicit
 * Stormer-Verlet (RATTLE with constraints; verlet.c); otherwise the implicit
 * PRK engine.  With constraints every stage point lies on g(q) = 0
 * (multipliers at every stage, prk_constrained.c). */
#include <config.h>
#include "integrators/integ_impl.h"

static const char *const lobatto_options[] = {"stages", "h", "tol", "maxiter", "simplified",
                                              "explicit", "linear", "iteration", NULL};
static const char *const trapezoid_options[] = {"h", "tol", "maxiter", "simplified", "explicit",
                                                "linear", "iteration", NULL};

static int make(dm_integrator *I, size_t s, dm_err *e)
{
  dm_tableau *t;
  int st = dm_tableau_lobatto(s, &t, e);
  if (st != DM_OK)
    return st;
  st = dm_prk_type_setup(I, t, e);
  dm_tableau_free(t);
  return st;
}

static int lobatto_alloc(dm_integrator *I, dm_err *e)
{
  if (I->opt.stages == 1 || I->opt.stages < 0 || I->opt.stages > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "lobatto: stages = %d out of range 2..%d", I->opt.stages,
                      DM_TABLEAU_SMAX);
  return make(I, I->opt.stages ? (size_t)I->opt.stages : 3, e);
}

static int trapezoid_alloc(dm_integrator *I, dm_err *e)
{
  if (I->opt.stages != 0 && I->opt.stages != 2)
    return dm_err_set(e, DM_EINVAL, "trapezoid has exactly 2 stages (got stages = %d); use 'lobatto'",
                      I->opt.stages);
  return make(I, 2, e);
}

const dm_integrator_type dm_integ_trapezoid = {
  .name = "trapezoid",
  .summary = "trapezoid = Lobatto IIIA-IIIB 2, L_d = h/2 [L(q0,v) + L(q1,v)]; explicit Stormer-Verlet "
    "(RATTLE with constraints) for separable L; order 2",
  .order = 2,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES
    | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = trapezoid_options,
  .alloc = trapezoid_alloc,
  .step = dm_prk_type_step,
  .jacobian = dm_prk_type_jacobian,
  .dlegendre = dm_prk_type_dlegendre,
  .advance = dm_prk_type_advance,
  .reset = dm_prk_type_reset,
  .free = dm_prk_type_free,
};

const dm_integrator_type dm_integ_lobatto = {
  .name = "lobatto",
  .summary = "Lobatto IIIA-IIIB Galerkin integrator with s stages (default 3); order 2s-2, symmetric, "
    "symplectic; constraints with multipliers at every stage",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES
    | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = lobatto_options,
  .alloc = lobatto_alloc,
  .step = dm_prk_type_step,
  .jacobian = dm_prk_type_jacobian,
  .dlegendre = dm_prk_type_dlegendre,
  .advance = dm_prk_type_advance,
  .reset = dm_prk_type_reset,
  .free = dm_prk_type_free,
};
