/* ensemble.h -- many runs of one integrator: a thread pool over the run
 * driver, built-in reductions, chaos indicators, MPI distribution.
 *
 *   dm_ens_opts o;
 *   dm_ens_opts_init(&o);
 *   o.members = 1000; o.threads = 2; o.run.h = 0.01; o.run.nsteps = 5000;
 *   o.reduce = DM_ENS_BIT(DM_ENS_FINAL) | DM_ENS_BIT(DM_ENS_MEGNO);
 *   o.start = my_start; o.start_ctx = &data;     // member k's (q, p[, par])
 *   st = dm_ensemble_run(I, &o, &table, &sum, &e);
 *
 * Every member starts from the state the start callback gives it and runs
 * nsteps steps of h (or to t_end) with its own copy of the integrator I (a
 * new dm_integrator per worker thread on I's system, method and options,
 * reset before every member), so a member computes exactly what it would
 * alone: the results are bitwise the same for any number of threads and
 * of MPI ranks.  The outcome is a trajectory with no coordinates
 * (trajectory.h, n = 0) holding one row per member, in member order:
 *   "t"               the time the member reached (t_end unless it ended early)
 *   reducer columns   in the order of enum dm_ens_reducer (below) for the
 *                     reducers asked for, then the user columns
 *   "status"          0, or the DM_E* code of the member's early end
 * and the metadata of a run (system, method, stages, h, order, param.*),
 * plus "members", "steps" (asked for), "every", "t0", "reduce" (the
 * reducer names, comma separated), "failed" (the count) and, for the
 * first DM_ENS_MAX_MESSAGES failed members, "failure.<number>" = the
 * member's message.  Member numbers in messages and keys are k + index_base.
 *
 * Built-in reducers, computed in the worker threads in C:
 *   final          q and p at the end: columns named like a trajectory's
 *                  ("x", ..., "p_x", ...; for a system on a group the
 *                  stored numbers of g and "mu1", ...)
 *   energy_error   max |E - E0| over the samples (every `every` steps and
 *                  the last), E = p.v - L
 *   min_distance   min over the samples of the Euclidean norm of the
 *                  coordinates (the nq numbers of q) flagged in `dist`
 *                  (all when NULL)
 *   megno          mean exponential growth of nearby orbits <Y> of the
 *                  step map: the tangent vector d_k = DPhi(x_{k-1}) d_{k-1}
 *                  through the exact step Jacobian (integrator.h), with
 *                  y_k = ln(|d_k| / |d_{k-1}|), Y_N = (2/N) sum k y_k and
 *                  <Y>_N = (1/N) sum Y_j -> 2 for quasi-periodic orbits
 *                  with shear, 0 for isochronous ones, ~ lambda t / 2 for
 *                  chaotic ones (doc/ensembles.md)
 *   fli            fast Lyapunov indicator max_k ln |d_k| (natural log)
 *   lyapunov       ln |d_N| / (t_N - t0), the finite-time largest
 *                  Lyapunov exponent
 * with d_0 = (1, ..., 1) / sqrt(2n).  The variational reducers take one
 * step Jacobian per step (integrators without an exact one use central
 * differences; constrained systems and systems on groups have none:
 * DM_EUNSUP).
 *
 * User reduction: with a `user` callback every member is run by dm_run
 * into a trajectory of its own (run.h: samples, energy column, metadata),
 * and after each batch the callback is called in the calling thread, in
 * member order, with that trajectory to write nuser values (columns
 * user_names); built-in reducers are not combined with it.
 *
 * Early ends.  A member that fails (a Newton failure, a non-finite state,
 * the runaway test max_energy_error of run.h) keeps what it computed up to
 * its last good state (t, final state, indicators so far), gets the status
 * and a message "member 17: step 40 of 5000 from t = 0.39 failed: ...",
 * and the other members go on; dm_ensemble_run still returns DM_OK, with
 * the count in sum->failed.  Ctrl-C (dm_interrupted(), polled before every
 * step) or a non-zero return of the progress callback stops the members
 * in flight (status DM_EINTR, their state so far) and starts no more
 * (status DM_EINTR, t and values NaN): dm_ensemble_run returns DM_EINTR
 * and the table with every finished member.  An error of a callback
 * (DM_ECALLBACK with its message), DM_ENOMEM or DM_EINVAL (options)
 * returns no table.
 *
 * MPI.  With `distributed` set and the process one of several MPI ranks
 * (mpi.h), the ranks take batches of members from a counter they share
 * (dm_mpi_counter_take; batches of about 1/(2 size) of the members left,
 * shrinking toward the end) -- or, without MPI one-sided communication,
 * rank r runs the members k = r, r + size, ... and the summary's note says
 * so -- and the rows are gathered to every rank in member order, so each
 * rank returns the whole table, whoever ran which member; every rank
 * must make the same call (start and user callbacks are called on the rank
 * that runs the member).  A failure of one rank (callback error, memory) is
 * agreed on by all, which return it ("rank 1: ..."), so none is left
 * waiting.
 *
 * Output.  With `output` set the table is also written to that HDF5 file
 * (trajectory_h5.h), once, by all ranks together (dm_traj_save_h5_shared:
 * parallel HDF5 when available, else rank 0); a file that cannot be
 * written returns its status (DM_EIO) and the message, with the table.
 *
 * Parameters.  With `params` set the start callback also writes the
 * member's npar parameter values (preset to the system's); members then
 * run on per-thread copies of the system (own parameters, and the mass
 * matrix of a separable system re-evaluated through the system's
 * callbacks), and the integrator copy is rebuilt when the values change.
 *
 * Code compiled in the background (system.h: update) is waited for and
 * installed before the first member, so every member runs the same code.
 *
 * Threads.  `threads` workers (0: the online processors, divided among
 * the MPI ranks of this node) take members one at a time; the callbacks
 * run in the calling thread only, between batches of members.  The
 * integrator I is only read (its system, method and options): I and its
 * system must not change during the call.  Systems and integrators must be
 * usable from several threads on distinct integrators (system.h,
 * integrator.h); dm_ensemble_run itself keeps no global state and may run
 * concurrently with others.
 *
 * Ownership.  *out is a new trajectory for the caller (dm_traj_free); the
 * trajectories given to the user callback belong to the ensemble and are
 * freed after the call.
 */
#ifndef DM_ENSEMBLE_H
#define DM_ENSEMBLE_H

#include <stddef.h>

#include "core/run.h"
#include "core/status.h"
#include "core/trajectory.h"
#include "integrators/integrator.h"

enum dm_ens_reducer {
  DM_ENS_FINAL = 0,
  DM_ENS_ENERGY_ERROR,
  DM_ENS_MIN_DISTANCE,
  DM_ENS_MEGNO,
  DM_ENS_FLI,
  DM_ENS_LYAPUNOV,
  DM_ENS_NREDUCERS
};
#define DM_ENS_BIT(r) (1u << (r))
#define DM_ENS_VARIATIONAL \
  (DM_ENS_BIT(DM_ENS_MEGNO) | DM_ENS_BIT(DM_ENS_FLI) | DM_ENS_BIT(DM_ENS_LYAPUNOV))

#define DM_ENS_MAX_MESSAGES 100   /* failure messages kept as metadata */
#define DM_ENS_MAX_MEMBERS 1000000000000L   /* 10^12 members per call */

/* Member k's start: q (nq numbers, system.h: n but on groups), p (n); par
 * (npar, preset to the system's
 * values) only with opts.params.  Return DM_OK, or a status with e filled
 * to stop the ensemble. */
typedef int (*dm_ens_start_fn)(void *ctx, long k, double *q, double *p, double *par,
                               dm_err *e);
/* Member k's user values out[0 .. nuser) from its trajectory (status and
 * message of the run in the trajectory's metadata). */
typedef int (*dm_ens_user_fn)(void *ctx, long k, dm_traj *tr, double *out, dm_err *e);

typedef struct dm_ens_progress {
  long done, total;       /* members finished (this rank), members of this rank */
  long failed;
  double elapsed;         /* seconds */
} dm_ens_progress;
/* Called in the calling thread about 4 times a second; non-zero stops. */
typedef int (*dm_ens_progress_fn)(void *ctx, const dm_ens_progress *pr);

typedef struct dm_ens_opts {
  long members;                 /* >= 1 */
  int threads;                  /* >= 0 (0: automatic) */
  dm_run_opts run;              /* t0, h, nsteps | t_end, every, max_energy_error */
  unsigned reduce;              /* DM_ENS_BIT(...) of built-in reducers */
  const unsigned char *dist;    /* nq flags for min_distance (NULL: all) */
  dm_ens_start_fn start;        /* required */
  void *start_ctx;
  int params;                   /* start writes parameters */
  dm_ens_user_fn user;          /* NULL: built-in reducers only */
  void *user_ctx;
  size_t nuser;                 /* user columns */
  const char *const *user_names;
  dm_ens_progress_fn progress;  /* NULL: none */
  void *progress_ctx;
  long batch;                   /* members per batch (0: automatic) */
  int index_base;               /* member numbers in messages: k + index_base */
  int distributed;              /* split over MPI ranks when there are several */
  const char *output;           /* NULL, or an HDF5 file for the table (below) */
} dm_ens_opts;

typedef struct dm_ens_summary {
  long members, done, failed;   /* over all ranks */
  int status;                   /* the return value */
  double elapsed;               /* seconds, this rank */
  char note[DM_ERRMSG_MAX];     /* "", or why several ranks dealt the members
                                   cyclically instead of from a shared counter */
} dm_ens_summary;

void dm_ens_opts_init(dm_ens_opts *o);

/* Name of reducer r ("final", "energy_error", "min_distance", "megno",
 * "fli", "lyapunov"), NULL out of range; index of a name or -1. */
const char *dm_ens_reducer_name(int r);
int dm_ens_reducer_find(const char *name);

/* A 32-bit seed for member k from one seed: for a fixed seed a bijection
 * of k mod 2^32 (so distinct members get distinct seeds), well mixed. */
unsigned long dm_ens_seed(unsigned long seed, long k);

/* Run the ensemble (see above).  sum may be NULL. */
int dm_ensemble_run(const dm_integrator *I, const dm_ens_opts *o, dm_traj **out,
                    dm_ens_summary *sum, dm_err *e);

#endif
