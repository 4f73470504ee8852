/* lagrangian.h -- a dm_system from symbolic expressions.
 *
 * dm_lagrangian_compile derives, exactly, everything the integrators need
 * from a Lagrangian expression L(q, v; par) (and optional generalized forces
 * F(q, v; par) and holonomic constraints g(q; par)): Lq, Lv, Lvv, Lvq, Lqq
 * (symmetric blocks derived on the upper triangle only), force Jacobians
 * Fq, Fv, the constraint Jacobian G and second derivatives H; compiles them
 * to tapes -- one for DM_LAG_GRAD requests (L, Lq, Lv), one for everything,
 * so gradient-only evaluations stay cheap, and for a separable L (below)
 * one for Lq alone (a function of q: the force of Stormer-Verlet) and one
 * for Lq, Lv, Lqq (the Newton matrix when Lvv is the mass); each request
 * runs the cheapest bundle that covers it; all from one rewriting of the
 * outputs (dm_tape_optimize), so that they agree bit for bit -- optionally
 * to native code (native.h), and fills a dm_system whose callbacks run
 * them.  On the tape path the outputs are laid out in the tape's slots as
 * in the caller's arrays, which are then copied whole.
 *
 * Every system gets the structural patterns of its second derivatives
 * (sys->pattern, system.h); with more than 32 coordinates (or layout
 * DM_LAG_LAYOUT_SPARSE) the Hessian is derived on its pattern only and the
 * bundles compute values on the patterns (dense requests are spread into
 * the caller's n x n arrays, zeros elsewhere); a separable system then has
 * sys->mass only up to 256 coordinates (pattern->mass always), and needs a
 * diagonal mass above that.  Constraint derivatives are always dense
 * (m n^2 doubles for the second ones).
 *
 * Structure detected symbolically:
 *  - DM_SYS_MECHANICAL when no entry of Lvv contains a velocity (L is
 *    quadratic in v);
 *  - DM_SYS_SEPARABLE when moreover Lvv contains no coordinate, Lvq is
 *    identically 0, Lv vanishes at v = 0 and Lvv is positive definite at
 *    the current parameters: `mass` then holds Lvv.  Lvv may depend on
 *    parameters; after changing sys->par call dm_lagrangian_refresh to
 *    re-evaluate the mass (it clears the flag when M stops being positive
 *    definite and sets it again when it is).
 *
 * Callbacks return 0, or 1 (recoverable, system.h) when an output of the
 * program that runs (the gradient one for DM_LAG_GRAD requests, else the
 * full one; requested or not) is NaN or infinite -- e.g. sqrt of a
 * negative number outside the domain; the requested arrays are then
 * unspecified.
 *
 * Requires dm_gsl_init() (GSL's abort handler off): the positive
 * definiteness test may make GSL report an error.
 *
 * Ownership: the system owns copies of the names, the parameter values,
 * the tapes and native objects; dm_system_release (free_data) frees them.
 * The expression context is only read during compilation and may be freed
 * afterwards.  On error nothing is allocated and *sys is zeroed.
 */
#ifndef DM_LAGRANGIAN_H
#define DM_LAGRANGIAN_H

#include <stddef.h>

#include "expr/expr.h"
#include "expr/native.h"
#include "core/status.h"
#include "core/system.h"

typedef struct dm_lagrangian_spec {
  const char *name;             /* may be NULL */
  size_t n;                     /* coordinates, >= 1 */
  const dm_expr *q, *v;         /* n symbols each, all distinct */
  size_t npar;
  const dm_expr *par;           /* npar parameters (or symbols) */
  const double *par_values;     /* npar initial values; NULL: zeros */
  const char *const *coord_names;  /* n; NULL: the names of q */
  const char *const *param_names;  /* npar; NULL: the names of par */
  dm_expr L;
  const dm_expr *force;         /* n, or NULL */
  size_t m;                     /* constraints */
  const dm_expr *constraints;   /* m, or NULL when m == 0 */
  int native;                   /* enum dm_native_mode */
  const double *q0, *v0;        /* a typical state for checking native
                                   code (may be NULL) */
  int layout;                   /* enum dm_lag_layout */
} dm_lagrangian_spec;

/* How the second derivatives are compiled: dense n x n arrays, or values
 * on their structural patterns (sys->pattern; the other layout is served
 * by spreading or gathering).  Auto: dense up to 32 coordinates. */
enum dm_lag_layout { DM_LAG_LAYOUT_AUTO = 0, DM_LAG_LAYOUT_DENSE, DM_LAG_LAYOUT_SPARSE };

int dm_lagrangian_compile(dm_expr_ctx *ctx, const dm_lagrangian_spec *spec,
                          dm_system *sys, dm_err *err);

/* The outputs the compiled system computes, for programs that compute
 * some of them along with other things (the Routh reduction's stage
 * programs) and must agree with the system bit for bit.  in: q then v (2n
 * symbols).  out gets L, Lq (n), Lv (n), Lvv (upper triangle, row by row),
 * Lvq (n x n, [i][j] = d2L/dv_i dq_j), Lqq (upper triangle): 1 + 2n +
 * n(n+1) + n^2 nodes; ow the same rewritten as the system's bundles compute
 * them (dm_tape_optimize).  Errors: the context's failure ("L: ..."),
 * DM_ENOMEM. */
int dm_lagrangian_outputs(dm_expr_ctx *ctx, dm_expr L, size_t n, const dm_expr *in,
                          dm_expr *out, dm_expr *ow, dm_err *err);
/* The same for a force F (n): out gets F, Fq (n x n), Fv (n x n),
 * rewritten. */
int dm_lagrangian_force_outputs(dm_expr_ctx *ctx, size_t n, const dm_expr *F,
                                const dm_expr *in, dm_expr *out, dm_err *err);

/* Re-evaluate `mass` after sys->par changed (no-op for a system whose Lvv
 * is not constant in q and v).  DM_EINVAL if sys was not made here. */
int dm_lagrangian_refresh(dm_system *sys, dm_err *err);

/* Native code with native = auto is compiled in the background (one
 * worker thread per process, native_job.h), the bundles the integrators
 * need first (Stormer-Verlet's force) first, while the tapes run; sys->update
 * (this function) installs what is ready, between steps (the run driver
 * calls it between pieces of a run).  Returns 1 while some is still on its
 * way.  A compilation that fails leaves the tape, with its message. */
int dm_lagrangian_update(const dm_system *sys);
/* Wait for the background compilation and install it; with interruptible,
 * Ctrl-C stops waiting (the compilation is cancelled, DM_EINTR).  DM_OK
 * when native code runs everywhere it was compiled for; else the first
 * failure's status and message (the tape runs there). */
int dm_lagrangian_wait_native(const dm_system *sys, int interruptible, dm_err *err);
/* Where native code stands: bundles running it, still compiling, failed
 * (with the first failure's message in err when there is one). */
typedef struct dm_lagrangian_native {
  int native, pending, failed;
} dm_lagrangian_native;
int dm_lagrangian_native_state(const dm_system *sys, dm_lagrangian_native *ns, dm_err *err);

/* What was built (for diagnostics and benchmarks). */
typedef struct dm_lagrangian_stats {
  size_t ninstr_grad, ninstr_all;     /* tape sizes */
  size_t nregs_all;
  int native_grad, native_all;        /* 1 when native code runs */
  size_t ninstr_force, ninstr_constr; /* 0 when absent */
  /* separable L (Lvv constant, Lvq = 0): the bundles Lq (of q alone) and
   * Lq, Lv, Lqq; 0 when not built */
  size_t ninstr_q, ninstr_sep;
  int native_q, native_sep;
  int sparse;                         /* 1: the sparse layout */
} dm_lagrangian_stats;

int dm_lagrangian_stats_get(const dm_system *sys, dm_lagrangian_stats *st);

#endif
