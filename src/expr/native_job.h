/* native_job.h -- native compilation in the background.
 *
 * A job compiles a tape (dm_native_compile or dm_native_compile_mapped) in
 * a worker thread while the caller goes on with the tape, and holds the
 * result until the caller takes it -- at a moment of its choosing (the
 * systems install it between steps: system.h, update).  One worker thread
 * per process runs the jobs one after the other in the order they were
 * started; each job compiles its translation units in parallel
 * (native.h).  The worker is started by the first job and never stops
 * the process from exiting: at exit the job in progress is cancelled.
 *
 * Failures (no compiler, a compiler error, a full disk, the code
 * disagreeing with the tape) end the job with its message and nothing
 * else happens: the caller keeps the tape.  A job never stops at Ctrl-C
 * (that interrupts the computation in the foreground, not the compiler in
 * the background); dm_native_job_wait does, when asked to, by cancelling
 * the job.
 *
 * Ownership: dm_native_job_start copies the maps and the typical point;
 * the tape is borrowed and must outlive the job.  dm_native_job_free
 * cancels a job that has not finished (its compilers are killed), waits
 * until the worker has let go of it, and releases it and a result not
 * taken; NULL is a no-op.  dm_native_job_take hands the result over (the
 * caller frees it with dm_native_free).
 *
 * Thread safety: a job is used by one thread (its owner) besides the
 * worker; the queue is shared by all threads, under a mutex.
 */
#ifndef DM_NATIVE_JOB_H
#define DM_NATIVE_JOB_H

#include <stddef.h>

#include "core/status.h"
#include "expr/native.h"
#include "expr/tape.h"

typedef struct dm_native_job dm_native_job;

enum dm_native_job_state {
  DM_NATIVE_JOB_QUEUED, DM_NATIVE_JOB_RUNNING, DM_NATIVE_JOB_DONE,
  DM_NATIVE_JOB_FAILED
};

/* Queue the compilation of t; inmap NULL: the flat function.  Errors:
 * DM_ENOMEM, DM_EFAILED (no thread could be started). */
int dm_native_job_start(const dm_tape *t, const double *in0, const double *par0,
                        const dm_native_map *inmap, size_t nmap,
                        const dm_native_map *outmap, dm_native_job **job, dm_err *err);
/* Where the job is (DM_NATIVE_JOB_*); never blocks. */
int dm_native_job_state(dm_native_job *job);
/* Wait for the job to end.  With interruptible, Ctrl-C (dm_interrupted)
 * cancels it and returns DM_EINTR.  Returns DM_OK when the code is ready,
 * else the job's status and message. */
int dm_native_job_wait(dm_native_job *job, int interruptible, dm_err *err);
/* The compiled code of a job that is DONE (once; NULL otherwise, with the
 * failure's status and message in err for a FAILED one). */
dm_native *dm_native_job_take(dm_native_job *job, dm_err *err);
void dm_native_job_free(dm_native_job *job);

#endif
