/* run.h -- the run driver: one call integrates into a trajectory.
 *
 *   dm_run_opts o;
 *   dm_run_opts_init(&o);
 *   o.h = 0.05; o.nsteps = 20000; o.every = 10;
 *   dm_traj *tr = dm_run_traj_alloc(I, &e);
 *   st = dm_run(I, q, p, &o, tr, &res, &e);    // q, p: the start, then the end
 *
 * The run takes nsteps steps of h (or as many as reach t_end) from (t0, q,
 * p) with the integrator I and records a sample (t, q, p, v, diagnostics)
 * at step 0, every `every` steps and at the last step, with the times
 * t0 + k h.  q holds the nq numbers of a configuration (system.h: nq; n
 * but for systems on groups), p and v the n momenta and velocities, and
 * the trajectory's columns are the same (dm_run_traj_alloc: the system's
 * coordinate, momentum and velocity names).  Diagnostic columns, filled
 * as the samples are recorded: "energy" (E = p.v - L) and
 * "momentum_<coord>" (p of the coordinates the caller flags), or, for a
 * system with a momentum map (the spatial momentum on a group),
 * "momentum_<k>" = J_k(q, p) for the flagged k.  Metadata on the
 * trajectory, numbers as numbers (see trajectory.h): system, method,
 * stages (when they are a choice: dm_integrator_stages_chosen), h, order,
 * space (system.h), param.<name>; when the run ends: steps (completed),
 * status (the DM_* code, 0 for a complete run) and, for an early end,
 * message.
 *
 * Variable physical steps.  With an integrator whose families keep the
 * physical time themselves (DM_INTEG_VARSTEP: time transformations,
 * energy-momentum methods) h is the nominal step they are given; the
 * run calls dm_integrator_begin at the start, the sample times are the
 * integrator's clock I->t, a diagnostic column "h" holds the physical
 * length of the step that ended at each sample (at the start: of the
 * first step, as begin() knows it), and a run to t_end (nsteps = -1)
 * steps until the integrator reports it has reached t_end exactly, the
 * last step shortened (dm_integrator_step_until); metadata t_end is the
 * time reached.
 *
 * Early ends keep everything computed so far.  The run stops, records the
 * last good state if it is not a sample already, and returns the status:
 *  - DM_EINTR     dm_interrupted() (Ctrl-C), polled before every step, or
 *                 the progress callback returned non-zero;
 *  - DM_EDIVERGED a recorded sample has a non-finite state or energy, or
 *                 |E - E0| > max_energy_error * max(1, |E0|) (when > 0);
 *  - the failing step's status (DM_ENOCONV, DM_EDOM, ...);
 *  - DM_ENOMEM    a sample could not be stored.
 * The message counts steps from the start of the run ("step 4 of 100 from
 * t = 2.4 failed: <the step's own message>; the trajectory up to there is
 * kept") and formats numbers in the C locale (numfmt.h).  q and p hold the
 * last good state.  Argument errors (DM_EINVAL: h, steps, every, a
 * trajectory of the wrong shape or not empty, a non-finite start) change
 * nothing.
 *
 * Memory.  The trajectory's storage is reserved once for the samples the
 * run will record and trimmed to them at the end: 8 bytes per stored
 * number plus a constant.  With a sink, the trajectory holds at most
 * sink_every samples: each time it has that many (and at the end, also an
 * early one) the sink gets them and they are dropped; the trajectory
 * returned then holds the last sample only (the sink had it too).
 *
 * Progress.  With a progress callback the run goes in pieces of `piece`
 * steps (0: sized to about 0.1 s of computing each) and calls it after each
 * piece; without one it is one piece.  Pieces never change the numbers: a
 * run recorded in any pieces is bitwise the run in one.
 *
 * Ownership.  The caller owns I, q, p, the trajectory (dm_run_traj_alloc
 * returns one to release with dm_traj_free) and the result; dm_run
 * allocates a few n-vectors for the call and frees them.
 *
 * Thread safety.  dm_run keeps no state between calls and touches no global
 * except the process-wide interrupt flag, which it only reads: runs with
 * distinct integrators and trajectories may go on in parallel threads (or
 * MPI ranks), each computing exactly what it would alone.  An integrator
 * and a trajectory belong to one run at a time.  The progress callback
 * runs in the calling thread.
 */
#ifndef DM_RUN_H
#define DM_RUN_H

#include <stddef.h>

#include "core/status.h"
#include "core/trajectory.h"
#include "integrators/integrator.h"

/* What the progress callback sees. */
typedef struct dm_run_progress {
  long step, nsteps;      /* steps completed, steps asked for */
  double t;               /* time reached */
  double elapsed;         /* seconds since the run started (monotonic clock) */
} dm_run_progress;

/* Return 0 to go on, non-zero to stop the run (DM_EINTR). */
typedef int (*dm_run_progress_fn)(void *ctx, const dm_run_progress *pr);

/* Streaming: called with the trajectory holding the samples recorded since
 * the last call (in order; its columns and metadata as ever); return
 * DM_OK, or a status (and a message in e) to stop the run with it. */
typedef int (*dm_run_sink_fn)(void *ctx, const dm_traj *tr, dm_err *e);

typedef struct dm_run_opts {
  double t0;              /* start time (0) */
  double h;               /* step: finite, != 0 (NaN: not set) */
  long nsteps;            /* steps >= 0; -1 (default): reach t_end */
  double t_end;           /* with nsteps = -1: round((t_end - t0) / h) steps */
  long every;             /* record every `every` steps, >= 1 (1) */
  int energy;             /* add the energy column (1) */
  const unsigned char *momentum;  /* n flags: momentum_<coord> columns (NULL: none) */
  double max_energy_error;        /* > 0: runaway threshold (see above); 0: off */
  long piece;             /* steps per progress call (0: automatic) */
  dm_run_progress_fn progress;    /* NULL: none */
  void *progress_ctx;
  dm_run_sink_fn sink;    /* NULL: every sample stays in the trajectory */
  void *sink_ctx;
  long sink_every;        /* samples per call of the sink (0: 4096) */
} dm_run_opts;

/* How the run went (also on the trajectory as metadata). */
typedef struct dm_run_result {
  int status;             /* the return value */
  long steps, nsteps;     /* completed, asked for */
  double t;               /* time reached */
  size_t samples;         /* samples recorded */
  double residual, tol;   /* of the last Newton solve (I->stats) */
} dm_run_result;

void dm_run_opts_init(dm_run_opts *o);

/* The number of steps from t0 to t_end with h: DM_EINVAL (message with the
 * three numbers) when t_end cannot be reached (non-finite, behind the
 * start, or more than 9e15 steps). */
int dm_run_steps_to(double t0, double t_end, double h, long *nsteps, dm_err *e);

/* Bytes the trajectory of a run with these options will hold at most (the
 * samples at once -- all of them, or sink_every with a sink -- times the
 * columns, 8 bytes each), for a warning before memory runs out. */
size_t dm_run_bytes(const dm_integrator *I, const dm_run_opts *o);

/* An empty trajectory for runs of I: its coordinates (nq), p and v
 * columns (n each). */
dm_traj *dm_run_traj_alloc(const dm_integrator *I, dm_err *e);

/* Run I from (q, p) into tr (empty, from dm_run_traj_alloc or of the same
 * shape) as described above.  res may be NULL. */
int dm_run(dm_integrator *I, double *q, double *p, const dm_run_opts *o, dm_traj *tr,
           dm_run_result *res, dm_err *e);

#endif
