/* traced.h -- the benchmark systems as a dmech user defines them: a
 * Lagrangian expression traced into the expression engine and compiled by
 * dm_lagrangian_compile (the path dm.system takes) to tapes or native code.
 *
 * bt_build(which, native, sys, &stats, err) builds system `which` into *sys
 * (release with dm_system_release) from a fresh expression context (freed
 * before returning).  native: DM_NATIVE_NEVER (tape) or DM_NATIVE_ALWAYS.
 * Returns a dm status. */
#ifndef BENCH_TRACED_H
#define BENCH_TRACED_H

#include "expr/lagrangian.h"
#include "core/status.h"
#include "core/system.h"

enum bt_which {
  BT_KEPLER,        /* L = |v|^2/2 + mu/|q|, n = 2 */
  BT_J2,            /* J2 Cartesian, n = 3, par J2 */
  BT_J2_CYL,        /* J2 cylindrical (r, theta, z) */
  BT_SPH_PEND,      /* spherical pendulum, spherical coordinates */
  BT_DSP_CART,      /* double spherical pendulum in R^3 x R^3, 2 constraints */
  BT_DSP_CYL,       /* double spherical pendulum, cylindrical (r1, th1, r2, th2) */
  BT_NSYS
};

extern const char *const bt_names[BT_NSYS];

int bt_build(int which, int native, dm_system *sys, dm_lagrangian_stats *st, dm_err *e);

#endif
