/* prk.c -- integrator from a user-supplied PRK tableau (option `tableau`,
 * built with dm_tableau_prk, which checks the symplecticity conditions
 * b_i at_ij + b_j a_ji = b_i b_j, b = bt).  Any such method applied to a
 * Lagrangian system is variational with L_d = h sum b_i L(Q_i, V_i). */
#include <config.h>
#include "integrators/integ_impl.h"

static const char *const prk_options[] = {"tableau", "h", "tol", "maxiter", "simplified", "linear", "iteration",
                                          NULL};

static int prk_alloc(dm_integrator *I, dm_err *e)
{
  const dm_tableau *t = I->opt.tableau;
  size_t wi, wj;
  double d;
  if (t == NULL)
    return dm_err_set(e, DM_EINVAL, "method 'prk' needs a tableau (option 'tableau')");
  d = dm_tableau_symplectic_defect(t, &wi, &wj);
  if (!(d <= 1e-13))
    return dm_err_set(e, DM_EINVAL, "prk: the tableau is not symplectic: defect %.3g at (i, j) = "
                      "(%zu, %zu)", d, wi + 1, wj == (size_t)-1 ? wi + 1 : wj + 1);
  return dm_prk_type_setup(I, t, e);
}

const dm_integrator_type dm_integ_prk = {
  .name = "prk",
  .summary = "symplectic partitioned Runge-Kutta method from a user tableau (a, b, at)",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES | DM_INTEG_EXACT_JAC,
  .options = prk_options,
  .alloc = prk_alloc,
  .step = dm_prk_type_step,
  .jacobian = dm_prk_type_jacobian,
  .dlegendre = dm_prk_type_dlegendre,
  .advance = dm_prk_type_advance,
  .reset = dm_prk_type_reset,
  .free = dm_prk_type_free,
};
