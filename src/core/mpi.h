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

/* End every rank of the job now (MPI_Abort) when MPI is active; no-op
 * otherwise.  For a process that is about to exit after an error, so that
 * no other rank is left waiting in a collective. */
void dm_mpi_fail(int code);

#endif
