/* lie_testsys.h -- systems on groups for the C tests of src/lie, built
 * with the expression engine directly: the rigid body on SO(3)
 * (L = 1/2 sum J_i Om_i^2 - m g rho . R^T e3, the heavy top when m g != 0)
 * and a rigid body on SE(3) with a translational kinetic energy and a
 * potential of the position. */
#ifndef DM_LIE_TESTSYS_H
#define DM_LIE_TESTSYS_H

#include <stdio.h>
#include <string.h>

#include "lie/lie_system.h"

/* symbols <p>1..<p>n */
static inline void lt_syms(dm_expr_ctx *c, const char *p, size_t n, dm_expr *out)
{
  char b[32];
  size_t i;
  for (i = 0; i < n; i++) {
    snprintf(b, sizeof b, "%s%zu", p, i + 1);
    out[i] = dm_expr_sym(c, b);
  }
}

/* the heavy top: params J1 J2 J3 mg rz (the centre of mass on the body's
 * third axis); mg = 0 is the free rigid body.  reduced: the Euler-Poincare
 * system.  force: a body torque -k xi (damping, k = param 6) when nonzero */
static inline int lt_top(dm_expr_ctx *c, const dm_lie_group *G, const double *par6, int force,
                         int reduced, int native, dm_lie_system **out, dm_err *e)
{
  static const char *const pn[6] = {"J1", "J2", "J3", "mg", "rz", "k"};
  dm_expr g[9], xi[3], par[6], L, F[3];
  dm_lie_spec sp;
  size_t i;
  lt_syms(c, "R", 9, g);
  lt_syms(c, "xi", 3, xi);
  for (i = 0; i < 6; i++)
    par[i] = dm_expr_param(c, pn[i]);
  L = dm_expr_const(c, 0.0);
  for (i = 0; i < 3; i++)
    L = dm_expr_add(c, L, dm_expr_mul(c, dm_expr_mul(c, dm_expr_const(c, 0.5), par[i]),
                                      dm_expr_powi(c, xi[i], 2)));
  /* U = mg rz R33 (the height of the centre of mass) */
  L = dm_expr_sub(c, L, dm_expr_mul(c, dm_expr_mul(c, par[3], par[4]), g[8]));
  for (i = 0; i < 3; i++)
    F[i] = dm_expr_neg(c, dm_expr_mul(c, par[5], xi[i]));
  memset(&sp, 0, sizeof sp);
  sp.name = "top";
  sp.G = G;
  sp.g = g;
  sp.xi = xi;
  sp.npar = 6;
  sp.par = par;
  sp.par_values = par6;
  sp.L = L;
  sp.force = force ? F : NULL;
  sp.native = native;
  sp.reduced = reduced;
  return dm_lie_system_compile(c, &sp, out, e);
}

/* a rigid body on SE(3): L = 1/2 (J Om.Om + m |v|^2) - 1/2 kp |p|^2 (a
 * spring to the origin: an isotropic potential, so angular momentum about
 * the origin and energy are conserved) */
static inline int lt_se3(dm_expr_ctx *c, const dm_lie_group *G, int native, dm_lie_system **out,
                         dm_err *e)
{
  static const double pv[5] = {1.3, 2.1, 3.4, 2.0, 1.5};
  static const char *const pn[5] = {"J1", "J2", "J3", "m", "kp"};
  dm_expr g[12], xi[6], par[5], L, h = dm_expr_const(c, 0.5);
  dm_lie_spec sp;
  size_t i;
  lt_syms(c, "g", 12, g);
  lt_syms(c, "w", 6, xi);
  for (i = 0; i < 5; i++)
    par[i] = dm_expr_param(c, pn[i]);
  L = dm_expr_const(c, 0.0);
  for (i = 0; i < 3; i++) {
    L = dm_expr_add(c, L, dm_expr_mul(c, dm_expr_mul(c, h, par[i]), dm_expr_powi(c, xi[i], 2)));
    L = dm_expr_add(c, L, dm_expr_mul(c, dm_expr_mul(c, h, par[3]), dm_expr_powi(c, xi[3 + i], 2)));
    L = dm_expr_sub(c, L, dm_expr_mul(c, dm_expr_mul(c, h, par[4]), dm_expr_powi(c, g[9 + i], 2)));
  }
  memset(&sp, 0, sizeof sp);
  sp.name = "se3 body";
  sp.G = G;
  sp.g = g;
  sp.xi = xi;
  sp.npar = 5;
  sp.par = par;
  sp.par_values = pv;
  sp.L = L;
  sp.native = native;
  return dm_lie_system_compile(c, &sp, out, e);
}

#endif
