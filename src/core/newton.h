/* newton.h -- the stopping rule of the Newton iterations in the implicit
 * integrators (src/integrators: PRK stages, SHAKE, velocity and
 * momentum-projection solves; src/reduce: RSPRK stages, discrete Routh
 * equations, Galerkin discrete Lagrangian).
 *
 * Stop when the scaled update d is <= tol, or, once d is below
 * DM_NEWTON_ACCEPT, when two updates failed to halve the best update so far
 * (the round-off floor of an ill-conditioned system, where updates bounce
 * around 1e-14 instead of decreasing).  The caller computes d (its own
 * scaling) and tests it for NaN/Inf first; a NaN d never stops.
 *
 * Usage:  dm_newton_test t = DM_NEWTON_TEST_INIT;
 *         for (...) { ...; if (dm_newton_done(&t, d, tol)) break; }
 * Header only, no allocation, no errors.
 */
#ifndef DM_NEWTON_H
#define DM_NEWTON_H

#include <math.h>

#define DM_NEWTON_ACCEPT 1e-10

typedef struct dm_newton_test {
  double best;   /* smallest update so far */
  int stall;     /* updates below DM_NEWTON_ACCEPT that did not halve best */
} dm_newton_test;

#define DM_NEWTON_TEST_INIT {HUGE_VAL, 0}

/* 1 when the iteration stops after an update of scaled size d. */
static inline int dm_newton_done(dm_newton_test *t, double d, double tol)
{
  if (d <= tol)
    return 1;
  if (d <= DM_NEWTON_ACCEPT && d > 0.5 * t->best)
    t->stall++;
  if (d < t->best)
    t->best = d;
  return t->stall >= 2;
}

#endif
