/* mpi.c -- MPI start-up, rank queries and the collectives of the ensemble
 * driver; no-ops in a build without MPI or a process not started by an MPI
 * launcher.  See mpi.h. */
#include <config.h>
#include "core/mpi.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef DM_HAVE_MPI
#include <mpi.h>
#endif

/* Started by a launcher: the variables Open MPI's mpirun, PMIx and PMI
 * (Slurm's srun) set in every process they start; the job size when known,
 * else 1 (unknown), 0 when no launcher is seen. */
static long launcher_size(void)
{
  static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", NULL};
  const char *const *v;
  for (v = vars; *v != NULL; v++) {
    const char *s = getenv(*v);
    if (s != NULL && *s != '\0')
      return atol(s) > 0 ? atol(s) : 1;
  }
  return getenv("PMIX_RANK") != NULL ? 1 : 0;
}

#ifdef DM_HAVE_MPI

static int started, rank, size = 1, local_size = 1;
static char library[MPI_MAX_LIBRARY_VERSION_STRING];

static int mpi_error(dm_err *e, int code, const char *what)
{
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  if (MPI_Error_string(code, text, &len) != MPI_SUCCESS)
    snprintf(text, sizeof text, "error %d", code);
  return dm_err_set(e, DM_EFAILED, "MPI: %s failed: %s", what, text);
}

static void finalize(void)
{
  int done = 0;
  MPI_Finalized(&done);
  if (!done)
    MPI_Finalize();
}

int dm_mpi_start(dm_err *e)
{
  int provided, rc, inited = 0, len = 0;
  MPI_Comm node;
  if (started || launcher_size() == 0)
    return DM_OK;
  MPI_Initialized(&inited);
  if (!inited) {
    if ((rc = MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided)) != MPI_SUCCESS)
      return mpi_error(e, rc, "MPI_Init_thread");
    atexit(finalize);
  }
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node)
      == MPI_SUCCESS) {
    MPI_Comm_size(node, &local_size);
    MPI_Comm_free(&node);
  }
  MPI_Get_library_version(library, &len);
  library[strcspn(library, "\n,")] = '\0';
  started = 1;
  return DM_OK;
}

int dm_mpi_built(void) { return 1; }
int dm_mpi_active(void) { return started; }
int dm_mpi_rank(void) { return rank; }
int dm_mpi_size(void) { return size; }
int dm_mpi_local_size(void) { return local_size; }
const char *dm_mpi_library(void) { return started ? library : "MPI (not started)"; }

int dm_mpi_barrier(dm_err *e)
{
  int rc;
  if (!started)
    return DM_OK;
  if ((rc = MPI_Barrier(MPI_COMM_WORLD)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Barrier");
  return DM_OK;
}

int dm_mpi_agree(int st, dm_err *e)
{
  int mine, first, rc;
  if (!started || size == 1)
    return st;
  mine = st != DM_OK ? rank : size;
  if ((rc = MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Allreduce");
  if (first == size)
    return DM_OK;
  {
    struct { int status; char msg[DM_ERRMSG_MAX]; } m;
    memset(&m, 0, sizeof m);
    if (rank == first) {
      m.status = st;
      snprintf(m.msg, sizeof m.msg, "%s", e != NULL ? e->msg : dm_strstatus(st));
    }
    if ((rc = MPI_Bcast(&m, (int)sizeof m, MPI_BYTE, first, MPI_COMM_WORLD)) != MPI_SUCCESS)
      return mpi_error(e, rc, "MPI_Bcast");
    m.msg[sizeof m.msg - 1] = '\0';
    return dm_err_set(e, m.status, "rank %d: %s", first, m.msg);
  }
}

int dm_mpi_sum_long(long *x, dm_err *e)
{
  long in = *x;
  int rc;
  if (!started || size == 1)
    return DM_OK;
  if ((rc = MPI_Allreduce(&in, x, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Allreduce");
  return DM_OK;
}

/* Large gathers go in rounds of at most 1 GiB per rank, as MPI counts are
 * int. */
#define CHUNK ((size_t)1 << 30)

int dm_mpi_allgather_bytes(const void *send, size_t count, void **recv, size_t *recv_len,
                           size_t *counts, dm_err *e)
{
  unsigned long mine = count, *all;
  size_t total = 0, done_max = 0, r, *off;
  int *cnt, *dsp, rc;
  char *out;
  if (!started || size == 1) {
    if ((*recv = malloc(count ? count : 1)) == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory gathering %zu bytes", count);
    memcpy(*recv, send, count);
    *recv_len = count;
    if (counts != NULL)
      counts[0] = count;
    return DM_OK;
  }
  all = calloc((size_t)size, sizeof *all);
  off = calloc((size_t)size, sizeof *off);
  cnt = calloc((size_t)size, sizeof *cnt);
  dsp = calloc((size_t)size, sizeof *dsp);
  if (all == NULL || off == NULL || cnt == NULL || dsp == NULL) {
    free(all), free(off), free(cnt), free(dsp);
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  if ((rc = MPI_Allgather(&mine, 1, MPI_UNSIGNED_LONG, all, 1, MPI_UNSIGNED_LONG,
                          MPI_COMM_WORLD)) != MPI_SUCCESS) {
    free(all), free(off), free(cnt), free(dsp);
    return mpi_error(e, rc, "MPI_Allgather");
  }
  for (r = 0; r < (size_t)size; r++) {
    off[r] = total;
    total += all[r];
    if (all[r] > done_max)
      done_max = all[r];
    if (counts != NULL)
      counts[r] = all[r];
  }
  if ((out = malloc(total ? total : 1)) == NULL) {
    free(all), free(off), free(cnt), free(dsp);
    return dm_err_set(e, DM_ENOMEM, "out of memory gathering %zu bytes", total);
  }
  /* rounds: in round j every rank sends bytes [j CHUNK, (j+1) CHUNK) of its
   * part, received into a staging area laid out rank by rank */
  {
    size_t j, stage_len = 0;
    char *stage;
    for (r = 0; r < (size_t)size; r++)
      stage_len += all[r] < CHUNK ? all[r] : CHUNK;
    stage = malloc(stage_len ? stage_len : 1);
    if (stage == NULL) {
      free(out), free(all), free(off), free(cnt), free(dsp);
      return dm_err_set(e, DM_ENOMEM, "out of memory");
    }
    for (j = 0; j * CHUNK < done_max || j == 0; j++) {
      size_t lo = j * CHUNK, pos = 0;
      int sendn = count > lo ? (int)(count - lo < CHUNK ? count - lo : CHUNK) : 0;
      for (r = 0; r < (size_t)size; r++) {
        size_t n = all[r] > lo ? (all[r] - lo < CHUNK ? all[r] - lo : CHUNK) : 0;
        cnt[r] = (int)n;
        dsp[r] = (int)pos;
        pos += n;
      }
      rc = MPI_Allgatherv(sendn ? (const char *)send + lo : NULL, sendn, MPI_BYTE, stage, cnt,
                          dsp, MPI_BYTE, MPI_COMM_WORLD);
      if (rc != MPI_SUCCESS) {
        free(stage), free(out), free(all), free(off), free(cnt), free(dsp);
        return mpi_error(e, rc, "MPI_Allgatherv");
      }
      for (r = 0; r < (size_t)size; r++)
        memcpy(out + off[r] + lo, stage + dsp[r], (size_t)cnt[r]);
    }
    free(stage);
  }
  free(all), free(off), free(cnt), free(dsp);
  *recv = out;
  *recv_len = total;
  return DM_OK;
}

struct dm_mpi_counter {
  MPI_Win win;
  long *base;               /* the long on rank 0 */
};

int dm_mpi_counter_open(dm_mpi_counter **out, dm_err *e)
{
  dm_mpi_counter *c;
  char why[DM_ERRMSG_MAX] = "";
  int rc, ok, all_ok = 0, have_win = 0;
  *out = NULL;
  if (!started || size == 1)
    return dm_err_set(e, DM_EUNSUP, "one process: nothing to share");
  if ((c = calloc(1, sizeof *c)) == NULL)
    snprintf(why, sizeof why, "out of memory");
  else if ((rc = MPI_Win_allocate(rank == 0 ? (MPI_Aint)sizeof(long) : 0, (int)sizeof(long),
                                  MPI_INFO_NULL, MPI_COMM_WORLD, &c->base, &c->win))
           != MPI_SUCCESS) {
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(rc, text, &len) != MPI_SUCCESS)
      snprintf(text, sizeof text, "error %d", rc);
    snprintf(why, sizeof why, "MPI_Win_allocate failed: %s", text);
  } else {
    have_win = 1;
    MPI_Win_set_errhandler(c->win, MPI_ERRORS_RETURN);
    if ((rc = MPI_Win_lock_all(MPI_MODE_NOCHECK, c->win)) != MPI_SUCCESS)
      snprintf(why, sizeof why, "MPI_Win_lock_all failed (error %d)", rc);
    else if (rank == 0) {
      long zero = 0;
      if (MPI_Accumulate(&zero, 1, MPI_LONG, 0, 0, 1, MPI_LONG, MPI_REPLACE, c->win)
          != MPI_SUCCESS || MPI_Win_flush(0, c->win) != MPI_SUCCESS)
        snprintf(why, sizeof why, "cannot set the counter on rank 0");
    }
  }
  /* every rank learns whether all have it; the counter is 0 for everybody
   * after this (the reduction orders rank 0's store before any take) */
  ok = why[0] == '\0';
  if ((rc = MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD)) != MPI_SUCCESS)
    all_ok = 0;
  if (!all_ok) {
    if (have_win) {
      if (ok)
        MPI_Win_unlock_all(c->win);
      MPI_Win_free(&c->win);
    }
    free(c);
    if (why[0] == '\0')
      snprintf(why, sizeof why, "another rank has no one-sided communication");
    return dm_err_set(e, DM_EUNSUP, "MPI one-sided communication unavailable: %s", why);
  }
  *out = c;
  return DM_OK;
}

int dm_mpi_counter_take(dm_mpi_counter *c, long n, long *first, dm_err *e)
{
  int rc;
  if ((rc = MPI_Fetch_and_op(&n, first, MPI_LONG, 0, 0, MPI_SUM, c->win)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Fetch_and_op");
  if ((rc = MPI_Win_flush(0, c->win)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Win_flush");
  return DM_OK;
}

int dm_mpi_counter_close(dm_mpi_counter *c, dm_err *e)
{
  long end = LONG_MAX / 2, old;
  int rc;
  if ((rc = MPI_Fetch_and_op(&end, &old, MPI_LONG, 0, 0, MPI_REPLACE, c->win)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Fetch_and_op");
  if ((rc = MPI_Win_flush(0, c->win)) != MPI_SUCCESS)
    return mpi_error(e, rc, "MPI_Win_flush");
  return DM_OK;
}

int dm_mpi_counter_closed(dm_mpi_counter *c)
{
  long v = 0;
  if (MPI_Fetch_and_op(NULL, &v, MPI_LONG, 0, 0, MPI_NO_OP, c->win) != MPI_SUCCESS
      || MPI_Win_flush(0, c->win) != MPI_SUCCESS)
    return 0;
  return v >= LONG_MAX / 2;
}

void dm_mpi_counter_free(dm_mpi_counter *c)
{
  if (c == NULL)
    return;
  MPI_Win_unlock_all(c->win);
  MPI_Win_free(&c->win);
  free(c);
}

void dm_mpi_fail(int code)
{
  if (started)
    MPI_Abort(MPI_COMM_WORLD, code);
}

#else /* !DM_HAVE_MPI */

int dm_mpi_start(dm_err *e)
{
  long n = launcher_size();
  if (n > 1)
    return dm_err_set(e, DM_EUNSUP, "dmech runs under an MPI launcher (%ld processes) but was "
                      "built without MPI, so every process would run everything: rebuild with "
                      "Open MPI (apt-get install libopenmpi-dev openmpi-bin; ./configure "
                      "--with-mpi)", n);
  return DM_OK;
}

int dm_mpi_built(void) { return 0; }
int dm_mpi_active(void) { return 0; }
int dm_mpi_rank(void) { return 0; }
int dm_mpi_size(void) { return 1; }
int dm_mpi_local_size(void) { return 1; }
const char *dm_mpi_library(void) { return "none (built without MPI)"; }
int dm_mpi_barrier(dm_err *e) { (void)e; return DM_OK; }
int dm_mpi_agree(int st, dm_err *e) { (void)e; return st; }
int dm_mpi_sum_long(long *x, dm_err *e) { (void)x; (void)e; return DM_OK; }

int dm_mpi_allgather_bytes(const void *send, size_t count, void **recv, size_t *recv_len,
                           size_t *counts, dm_err *e)
{
  if ((*recv = malloc(count ? count : 1)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory gathering %zu bytes", count);
  memcpy(*recv, send, count);
  *recv_len = count;
  if (counts != NULL)
    counts[0] = count;
  return DM_OK;
}

struct dm_mpi_counter {
  long unused;
};

int dm_mpi_counter_open(dm_mpi_counter **c, dm_err *e)
{
  *c = NULL;
  return dm_err_set(e, DM_EUNSUP, "built without MPI");
}

int dm_mpi_counter_take(dm_mpi_counter *c, long n, long *first, dm_err *e)
{
  (void)c, (void)n, (void)e;
  *first = LONG_MAX / 2;
  return DM_OK;
}

int dm_mpi_counter_close(dm_mpi_counter *c, dm_err *e) { (void)c; (void)e; return DM_OK; }
int dm_mpi_counter_closed(dm_mpi_counter *c) { (void)c; return 0; }
void dm_mpi_counter_free(dm_mpi_counter *c) { (void)c; }
void dm_mpi_fail(int code) { (void)code; }

#endif
