/* mpi.h -- the few MPI operations dmech needs, behind one small interface.
 *
 * dmech uses MPI (Open MPI) only to split ensembles over processes: the
 * same script runs on every rank (`mpirun -np 8 dmech sweep.lua`), each
 * rank runs its share of the members and the results are gathered.  Built
 * with MPI (configure --with-mpi, the default when mpicc is found;
 * DM_HAVE_MPI) and started by an MPI launcher (mpirun, srun: detected from
 * the environment), dm_mpi_start() initializes MPI (MPI_THREAD_FUNNELED:
 * only the thread that called it makes MPI calls) and registers
 * MPI_Finalize with atexit; otherwise dmech is one process of rank 0 and
 * size 1, and every function here is a cheap no-op -- so a program that is
 * not under mpirun never pays MPI's start-up.
 *
 * Errors: functions return DM_OK or DM_EFAILED with the MPI error text in
 * e.  dm_mpi_start fails (DM_EUNSUP) when a launcher started more than one
 * process but dmech was built without MPI: each would compute everything.
 *
 * Collectives (barrier, agree, allgather, bcast) must be called by every
 * rank in the same order.  Thread safety: call these from the thread that
 * called dm_mpi_start only.
 */
#ifndef DM_MPI_H
#define DM_MPI_H

#include <stddef.h>

#include "core/status.h"

/* Initialize MPI when started by a launcher (idempotent).  DM_OK also when
 * not under a launcher (then rank 0 of 1). */
int dm_mpi_start(dm_err *e);

/* 1 when built with MPI support. */
int dm_mpi_built(void);
/* 1 when MPI was initialized (several ranks possible). */
int dm_mpi_active(void);
int dm_mpi_rank(void);
int dm_mpi_size(void);
/* Processes of this job on this node (1 without MPI). */
int dm_mpi_local_size(void);
/* The name of the MPI library ("Open MPI v4.1.4, ...") or "none". */
const char *dm_mpi_library(void);

int dm_mpi_barrier(dm_err *e);

/* Agree on a status: every rank passes its own (st, e); all return the
 * first non-OK status by rank with its message prefixed "rank r: " (the
 * same on every rank), or DM_OK.  Never fails by itself beyond MPI
 * errors. */
int dm_mpi_agree(int st, dm_err *e);

/* Sum of x over the ranks, on every rank. */
int dm_mpi_sum_long(long *x, dm_err *e);

/* Every rank sends `count` bytes at `send`; every rank receives all of
 * them, rank by rank, in recv (malloc'ed, *recv_len bytes; counts[r] of
 * rank r when counts is not NULL: size entries).  Without MPI a copy. */
int dm_mpi_allgather_bytes(const void *send, size_t count, void **recv, size_t *recv_len,
                           size_t *counts, dm_err *e);

/* A counter shared by all ranks for dealing work dynamically: an MPI-3
 * window of one long on rank 0 (MPI_Win_allocate), read and advanced with
 * MPI_Fetch_and_op in a passive-target epoch (MPI_Win_lock_all), so a rank
 * takes the next items without the others taking part.  On one node Open
 * MPI serves it from shared memory (osc/sm).
 *
 * dm_mpi_counter_open is collective: every rank gets the counter at 0, or
 * every rank gets DM_EUNSUP with the reason (no one-sided component, a
 * build without MPI, a single process) and *c = NULL -- the caller then
 * deals the work statically.  dm_mpi_counter_take adds n and returns the
 * value before (*first; the items [first, first + n) are the caller's).
 * dm_mpi_counter_close makes every later take return a value beyond any
 * count (LONG_MAX / 2 or more): the others take no more;
 * dm_mpi_counter_closed reads the counter and says whether some rank
 * closed it (0 also when the read fails).
 * dm_mpi_counter_free is collective (every rank that opened it); NULL is a
 * no-op.  Calls from the thread that called dm_mpi_start only. */
typedef struct dm_mpi_counter dm_mpi_counter;
int dm_mpi_counter_open(dm_mpi_counter **c, dm_err *e);
int dm_mpi_counter_take(dm_mpi_counter *c, long n, long *first, dm_err *e);
int dm_mpi_counter_close(dm_mpi_counter *c, dm_err *e);
int dm_mpi_counter_closed(dm_mpi_counter *c);
void dm_mpi_counter_free(dm_mpi_counter *c);

/* End every rank of the job now (MPI_Abort) when MPI is active; no-op
 * otherwise.  For a process that is about to exit after an error, so that
 * no other rank is left waiting in a collective. */
void dm_mpi_fail(int code);

#endif
