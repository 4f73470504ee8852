/* adapt.h -- structure-preserving adaptive steps by a time transformation
 * (methods "adapt:<method>", doc/beyond-fixed-steps.md §3).
 *
 * The physical time runs as dt/ds = g(q) > 0 in a fictitious time s in
 * which the steps are fixed.  With the energy E0 of the start latched, the
 * Poincare transformation K = g(q) (H(q, p) - E0) is integrated by the
 * named method in the extended phase space (q, t, p, p_t), through the
 * Lagrangian g(q) (L(q, w/g(q)) + E0) + (s - g(q))^2/2 of (q, t) with
 * velocities (w, s) (the last term makes t a coordinate whose conjugate
 * momentum stays 0, discrete Noether theorem): every Lagrangian method of
 * the registry applies, symplectic ones stay symplectic in the extended
 * phase space, and the physical time is integrated by the method's own
 * quadrature, t_{k+1} = t_k + h sum_i b_i g(Q_i).  For a separable L with
 * the potential's monitor g = (U(q0)/U(q))^a, U = -V, the methods
 * "trapezoid" and "composition" (trapezoid base) take the explicit path:
 * Stormer-Verlet and its compositions on the separable extended
 * Hamiltonian f(T(p) + p_t) - f(U(q)), f' = g as a function of U (the
 * logarithmic Hamiltonian of Mikkola-Tanikawa and Preto-Tremaine for
 * a = 1), equal to K's flow on the energy surface.
 *
 * The family is VARSTEP (integrator.h): begin latches E0 (and U(q0)),
 * steps keep I->t and I->dt, step_until ends a step at a given physical
 * time by a secant iteration on the fictitious step.
 *
 * Ownership and threads as in integrator.h; the monitor is borrowed.
 * Errors: DM_EUNSUP for a forced system, DM_EINVAL without an inner
 * method, the inner method's errors, DM_EDOM when the monitor leaves its
 * domain (g not finite and positive, U <= 0 for the potential's monitor).
 */
#ifndef DM_ADAPT_H
#define DM_ADAPT_H

#include "integrators/integrator.h"

/* Is I a time-transformed integrator ("adapt:<method>")? */
int dm_adapt_is(const dm_integrator *I);

/* The energy level E0 latched by begin (NaN before). */
double dm_adapt_energy_level(const dm_integrator *I);

/* The Jacobian of one step in the extended phase space (q, t, p, p_t),
 * 2(n+1) x 2(n+1) row-major, at (q0, t = I->t, p0, p_t = -E0) (begins at
 * (q0, p0) when the integrator has not begun). */
int dm_adapt_extended_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                               double *D, dm_err *e);

/* The monitor g(q) of I at q (begins nothing; DM_EDOM outside its domain). */
int dm_adapt_monitor_value(dm_integrator *I, const double *q, double *g, dm_err *e);

/* A monitor whose g(q) is the Lagrangian of `field` at (q, 0) (a system
 * compiled from the expression g(q), e.g. by the Lua binding): gradient
 * Lq and Hessian Lqq.  field is borrowed; n must match the integrated
 * system's. */
void dm_adapt_monitor_from_system(dm_monitor *mon, const dm_system *field);
/* The work bytes such a monitor needs (for field). */
size_t dm_adapt_monitor_work(const dm_system *field);

#endif
