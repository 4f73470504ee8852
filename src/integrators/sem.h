/* sem.h -- symplectic-energy-momentum integrators (method "sem", stages s;
 * doc/beyond-fixed-steps.md §2).
 *
 * The step size is an unknown of the discrete variational principle: with
 * the Galerkin discrete Lagrangian Ld(q0, q1, h) of the Gauss s-stage
 * method (s = 1: midpoint) and its discrete energy
 *   Ed = -dLd/dh = sum_i b_i E(Q_i, V_i),   E(q, v) = Lv(q, v).v - L(q, v),
 * a step from (q0, p0) solves p0 = -D1 Ld(q0, q1, h), Ed(q0, q1, h) = E
 * for q1 and h (Newton on the stage velocities and h), then p1 = D2 Ld and
 * t1 = t0 + h.  The energy level E is that of one fixed Galerkin step of
 * the nominal size h0 from the start (begin; not H(q0, p0), for which the
 * energy equation has no small-h solution); Ed is then conserved to the
 * solver's tolerance and the order is 2s.  Where the energy equation
 * degenerates (dEd/dh -> 0, e.g. near turning points) Newton is replaced by
 * a bracketed search in h with inner fixed-h solves: a root of Ed(h) - E
 * when one is bracketed, else the minimiser of (Ed(h) - E)^2, and the
 * step is counted in I->stats.flagged ("energy not matched").  Steps stay
 * in (0, 4 h0].  The family is VARSTEP (integrator.h); step_until ends a
 * run at t_end with one fixed Galerkin step of the remaining time.
 * Unforced, unconstrained Lagrangian systems only (DM_EUNSUP).
 */
#ifndef DM_SEM_H
#define DM_SEM_H

#include "integrators/integrator.h"

/* Is I an energy-momentum integrator ("sem")? */
int dm_sem_is(const dm_integrator *I);

/* The energy level Ed of the run (NaN before begin). */
double dm_sem_energy_level(const dm_integrator *I);

/* Impose the energy level E for the following steps (after begin, which
 * sets it from the first fixed step). */
int dm_sem_set_energy_level(dm_integrator *I, double E, dm_err *e);

/* Ed of the last step, evaluated at its converged stages (NaN before). */
double dm_sem_last_energy(const dm_integrator *I);

#endif
