/* galerkin.h -- the Galerkin discrete Lagrangian of a PRK tableau as a
 * two-point function with first and second derivatives.
 *
 * Given (q0, q1) and a step h, the boundary problem for the stage
 * velocities V_i and the momentum p0 (doc/integrators.md; Suris; thesis
 * Thm 2.12)
 *   Lv(Q_i, V_i) - p0 - h sum_j at_ij W_j = 0,   Q_i = q0 + h sum_j a_ij V_j,
 *   sum_j b_j V_j = (q1 - q0)/h,                 W_j = Lq(Q_j, V_j) + F(Q_j, V_j)
 * is solved by Newton with the exact Jacobian; then
 *   Ld = h sum_j b_j L(Q_j, V_j),  p0 = -D1 Ld,  p1 = p0 + h sum_j b_j W_j = D2 Ld
 * (with a generalized force F, p0 and p1 are the forced discrete Legendre
 * transforms of Lagrange-d'Alembert: -D1 Ld - F_d^- and D2 Ld + F_d^+), and,
 * when asked, the second derivatives d00 = dp0/dq0, d01 = dp0/dq1,
 * d10 = dp1/dq0, d11 = dp1/dq1 (n x n, row-major) by the implicit function
 * theorem at the solution.  The PRK integrators' discrete Legendre
 * transforms (dm_integrator_dlegendre) and the discrete Routh equations
 * (src/reduce) both use this one solver.
 *
 * Ownership.  dm_galerkin_alloc copies the tableau and allocates every
 * workspace (a solve never allocates); the system is borrowed and must
 * outlive the solver; dm_galerkin_free(NULL) is a no-op.
 *
 * Errors.  DM_EINVAL (h = 0, a constrained system), DM_EDOM (L or F outside
 * its domain at a stage point, or a non-finite residual), DM_ECALLBACK,
 * DM_ESINGULAR (singular boundary problem), DM_ENOCONV (no convergence in
 * maxiter iterations: the update and h in the message), DM_ENOMEM (alloc).
 *
 * Thread safety.  A solver holds per-call state: one thread at a time per
 * solver; solvers on one system may run in parallel threads.
 */
#ifndef DM_GALERKIN_H
#define DM_GALERKIN_H

#include <stddef.h>
#include "core/status.h"
#include "core/system.h"
#include "core/tableau.h"

typedef struct dm_galerkin dm_galerkin;

/* A solver for sys (unconstrained; a force is included) and tableau t;
 * Newton stops at the scaled update tol (src/core/newton.h) or fails after
 * maxiter iterations. */
int dm_galerkin_alloc(const dm_system *sys, const dm_tableau *t, double tol, int maxiter,
                      dm_galerkin **out, dm_err *e);
void dm_galerkin_free(dm_galerkin *g);

/* Solve for (q0, q1) with step h: *Ld, p0, p1 (any may be NULL) and, when
 * d00 != NULL, the four second-derivative blocks (all four then needed).
 * warm != 0 starts Newton from the previous solution when the last solve
 * succeeded (a continuation in q0, q1), else from V = (q1 - q0)/h, p0 = 0. */
int dm_galerkin_solve(dm_galerkin *g, double h, const double *q0, const double *q1, double *Ld,
                      double *p0, double *p1, double *d00, double *d01, double *d10,
                      double *d11, int warm, dm_err *e);

/* Newton iterations of the last solve. */
int dm_galerkin_iters(const dm_galerkin *g);

#endif
