/* ensemble.c -- the ensemble driver: options, the result table, members in
 * batches (the start and user callbacks in the calling thread), a pool of
 * worker threads, progress and Ctrl-C, the MPI split and gather.  What one
 * member computes is ensemble_member.c.  See ensemble.h. */
#include <config.h>
#include "core/ensemble_impl.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "core/mpi.h"
#include "core/numfmt.h"
#include "core/trajectory_h5.h"

static const char *const reducer_names[DM_ENS_NREDUCERS] = {
  "final", "energy_error", "min_distance", "megno", "fli", "lyapunov"
};

void dm_ens_opts_init(dm_ens_opts *o)
{
  memset(o, 0, sizeof *o);
  dm_run_opts_init(&o->run);
  o->run.energy = 0;
}

const char *dm_ens_reducer_name(int r)
{
  return r >= 0 && r < DM_ENS_NREDUCERS ? reducer_names[r] : NULL;
}

int dm_ens_reducer_find(const char *name)
{
  int r;
  for (r = 0; r < DM_ENS_NREDUCERS; r++)
    if (strcmp(name, reducer_names[r]) == 0)
      return r;
  return -1;
}

/* murmur3's finalizer: a bijection of 32-bit words with full avalanche */
static uint32_t fmix32(uint32_t h)
{
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

unsigned long dm_ens_seed(unsigned long seed, long k)
{
  uint32_t base = fmix32((uint32_t)seed ^ fmix32((uint32_t)((uint64_t)seed >> 32) + 0x9e3779b9u));
  return fmix32(base + (uint32_t)k * 0x9e3779b9u);
}

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* {==== the pool ========================================================== */

static void *work(void *arg)
{
  worker *w = arg;
  ens *E = w->E;
  for (;;) {
    long i;
    if (atomic_load(&E->stop) || dm_interrupted())
      break;
    i = atomic_fetch_add(&E->next, 1);
    if (i >= E->nb)
      break;
    if (E->user)
      dm_ens__user_member(w, i);
    else
      dm_ens__builtin_member(w, i);
    if (E->rows[(size_t)(E->b0 + i) * E->nvals + E->col_status] != DM_OK)
      atomic_fetch_add(&E->failed, 1);
    if (atomic_fetch_add(&E->done, 1) + 1 == E->nb) {
      pthread_mutex_lock(&E->mu);
      pthread_cond_signal(&E->cv);
      pthread_mutex_unlock(&E->mu);
    }
  }
  return NULL;
}

/* Run the batch on the workers; progress and the stop request from the
 * calling thread, which runs the members itself if no thread can start. */
static void run_batch(ens *E, double t_start, long done_before)
{
  int t, started = 0;
  double last = now(), polled = last;
  atomic_store(&E->next, 0);
  atomic_store(&E->done, 0);
  for (t = 0; t < E->nworkers; t++) {
    E->w[t].running = pthread_create(&E->w[t].tid, NULL, work, &E->w[t]) == 0;
    started += E->w[t].running;
  }
  if (started == 0) {
    work(&E->w[0]);
    return;
  }
  pthread_mutex_lock(&E->mu);
  while (atomic_load(&E->done) < E->nb && !atomic_load(&E->stop)) {
    struct timespec until;
    double tn;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_nsec += 100000000L;
    if (until.tv_nsec >= 1000000000L) {
      until.tv_sec++;
      until.tv_nsec -= 1000000000L;
    }
    pthread_cond_timedwait(&E->cv, &E->mu, &until);
    if (dm_interrupted())
      atomic_store(&E->stop, 1);
    tn = now();
    /* another rank stopped (Ctrl-C there, an error): start no more */
    if (E->counter != NULL && tn - polled >= 0.25) {
      polled = tn;
      if (dm_mpi_counter_closed(E->counter))
        atomic_store(&E->stop, 1);
    }
    if (E->o->progress != NULL && tn - last >= 0.25 && !atomic_load(&E->stop)) {
      dm_ens_progress pr;
      last = tn;
      pr.done = done_before + atomic_load(&E->done);
      pr.total = E->idx != NULL ? E->o->members : E->count;
      pr.failed = atomic_load(&E->failed);
      pr.elapsed = tn - t_start;
      pthread_mutex_unlock(&E->mu);
      if (E->o->progress(E->o->progress_ctx, &pr) != 0)
        atomic_store(&E->stop, 1);
      pthread_mutex_lock(&E->mu);
    }
  }
  pthread_mutex_unlock(&E->mu);
  for (t = 0; t < E->nworkers; t++)
    if (E->w[t].running)
      pthread_join(E->w[t].tid, NULL);
}

/* }====================================================================== */

/* {==== set-up, the batches, the gather, the table ======================= */

static int check_opts(const dm_integrator *I, const dm_ens_opts *o, dm_run_opts *run,
                      dm_err *e)
{
  unsigned all = (1u << DM_ENS_NREDUCERS) - 1;
  int st;
  if (I == NULL || o == NULL)
    return dm_err_set(e, DM_EINVAL, "need an integrator and options");
  if (o->members < 1)
    return dm_err_set(e, DM_EINVAL, "need members >= 1 (got %ld)", o->members);
  if (o->members > DM_ENS_MAX_MEMBERS)
    return dm_err_set(e, DM_EINVAL, "need members <= %ld (got %ld): split the ensemble into "
                      "several calls", (long)DM_ENS_MAX_MEMBERS, o->members);
  if (o->threads < 0)
    return dm_err_set(e, DM_EINVAL, "need threads >= 1 (0: automatic), got %d", o->threads);
  if (o->start == NULL)
    return dm_err_set(e, DM_EINVAL, "need a start callback for the members' initial states");
  if (o->reduce & ~all)
    return dm_err_set(e, DM_EINVAL, "unknown reducer bits 0x%x", o->reduce & ~all);
  if (o->user != NULL && o->reduce != 0)
    return dm_err_set(e, DM_EINVAL, "a user reduction is not combined with built-in reducers");
  if (o->user == NULL && o->nuser != 0)
    return dm_err_set(e, DM_EINVAL, "user columns without a user reduction");
  if (o->user != NULL && o->nuser > 0 && o->user_names == NULL)
    return dm_err_set(e, DM_EINVAL, "the user columns need names");
  if (o->batch < 0)
    return dm_err_set(e, DM_EINVAL, "need batch >= 0 (0: automatic)");
  if ((o->reduce & DM_ENS_VARIATIONAL) && I->m > 0)
    return dm_err_set(e, DM_EUNSUP, "megno, fli and lyapunov need the step Jacobian, which "
                      "constrained systems do not have");
  if ((o->reduce & DM_ENS_VARIATIONAL) && I->nq != I->n)
    return dm_err_set(e, DM_EUNSUP, "megno, fli and lyapunov need the step Jacobian in "
                      "coordinates, which a configuration stored in %zu numbers with %zu "
                      "velocities (a system on a group) does not have", I->nq, I->n);
  *run = o->run;
  run->progress = NULL;
  run->piece = 0;
  run->energy = o->user != NULL;
  if (isfinite(run->t_end) && run->nsteps < 0 && isfinite(run->h) && run->h != 0.0
      && (st = dm_run_steps_to(run->t0, run->t_end, run->h, &run->nsteps, e)) != DM_OK)
    return st;
  if (!isfinite(run->h) || run->h == 0.0)
    return dm_err_set(e, DM_EINVAL, "need a finite step h != 0");
  if (!isfinite(run->t0))
    return dm_err_set(e, DM_EINVAL, "the start time t0 must be finite");
  if (run->nsteps < 0)
    return dm_err_set(e, DM_EINVAL, "need steps >= 0 or a final time");
  if (run->every < 1)
    return dm_err_set(e, DM_EINVAL, "need every >= 1 (got %ld)", run->every);
  if (!(run->max_energy_error >= 0))
    return dm_err_set(e, DM_EINVAL, "max_energy_error must be >= 0");
  return DM_OK;
}

/* The empty result table: t, the reducers' columns, the user's, status. */
static dm_traj *new_table(const ens *E, dm_err *e)
{
  const dm_system *s = E->I0->sys;
  unsigned r = E->o->reduce;
  dm_traj *tr = dm_traj_alloc(0, NULL, 0, e), *names = NULL;
  size_t i;
  int st = DM_OK, k;
  char buf[DM_TRAJ_NAME_MAX + 8];
  if (tr == NULL)
    return NULL;
  if (r & DM_ENS_BIT(DM_ENS_FINAL)) {
    /* the coordinate and momentum names as a run's trajectory spells them */
    if ((names = dm_run_traj_alloc(E->I0, e)) == NULL) {
      dm_traj_free(tr);
      return NULL;
    }
    for (i = 1; st == DM_OK && i < 1 + E->nq + E->n; i++)
      st = dm_traj_add_column(tr, dm_traj_colname(names, i), DM_TRAJ_DATA, NULL, 0, e);
    dm_traj_free(names);
  }
  for (k = DM_ENS_ENERGY_ERROR; st == DM_OK && k < DM_ENS_NREDUCERS; k++)
    if (r & DM_ENS_BIT(k))
      st = dm_traj_add_column(tr, reducer_names[k], DM_TRAJ_DATA, NULL, 0, e);
  for (i = 0; st == DM_OK && i < E->o->nuser; i++)
    st = dm_traj_add_column(tr, E->o->user_names[i], DM_TRAJ_DATA, NULL, 0, e);
  if (st == DM_OK)
    st = dm_traj_add_column(tr, "status", DM_TRAJ_DATA, NULL, 0, e);
  if (st == DM_OK && s->name != NULL)
    st = dm_traj_meta_set(tr, "system", s->name, e);
  if (st == DM_OK)
    st = dm_traj_meta_set(tr, "method", E->I0->name, e);
  if (st == DM_OK && dm_integrator_stages_chosen(E->I0))
    st = dm_traj_meta_set_number(tr, "stages", E->I0->stages, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "h", E->run.h, e);
  if (st == DM_OK && E->I0->order > 0)
    st = dm_traj_meta_set_number(tr, "order", E->I0->order, e);
  for (i = 0; st == DM_OK && i < s->npar; i++) {
    snprintf(buf, sizeof buf, "param.%s", s->params ? s->params[i] : "?");
    st = dm_traj_meta_set_number(tr, buf, s->par[i], e);
  }
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "members", (double)E->o->members, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "t0", E->run.t0, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "steps", (double)E->run.nsteps, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "every", (double)E->run.every, e);
  if (st == DM_OK) {
    char list[256] = "";
    for (k = 0; k < DM_ENS_NREDUCERS; k++)
      if (r & DM_ENS_BIT(k))
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? "," : "",
                 reducer_names[k]);
    if (E->user)
      snprintf(list, sizeof list, "user");
    st = dm_traj_meta_set(tr, "reduce", list, e);
  }
  if (st != DM_OK) {
    dm_traj_free(tr);
    return NULL;
  }
  return tr;
}

static void ens_free(ens *E)
{
  long j;
  int t;
  if (E->w != NULL)
    for (t = 0; t < E->nworkers; t++)
      dm_ens__worker_free(&E->w[t]);
  free(E->w);
  if (E->msg != NULL)
    for (j = 0; j < E->count; j++)
      free(E->msg[j]);
  free(E->msg);
  free(E->rows);
  free(E->idx);
  free(E->q0);
  if (E->traj != NULL)
    for (j = 0; j < E->nb; j++)
      dm_traj_free(E->traj[j]);
  free(E->traj);
  pthread_mutex_destroy(&E->mu);
  pthread_cond_destroy(&E->cv);
}

static int wait_for_code(const dm_system *sys, dm_err *e)
{
  struct timespec pause = {0, 5000000L};
  while (sys->update != NULL && sys->update(sys)) {
    if (dm_interrupted())
      return dm_err_set(e, DM_EINTR, "interrupted while the system's code was being compiled");
    nanosleep(&pause, NULL);
  }
  return DM_OK;
}

static int default_threads(void)
{
  long c = sysconf(_SC_NPROCESSORS_ONLN);
  int local = dm_mpi_local_size();
  if (c < 1)
    c = 1;
  c /= local > 0 ? local : 1;
  return c < 1 ? 1 : (int)c;
}

/* Start states (and parameters) of the batch from the callback. */
static int batch_starts(ens *E, dm_err *e)
{
  const dm_system *s = E->sys;
  long i;
  for (i = 0; i < E->nb; i++) {
    long j = E->b0 + i;
    double *row = E->rows + (size_t)j * E->nvals, *par = E->par0 + (size_t)i * E->npar;
    size_t c;
    int st;
    for (c = 0; c < E->nvals; c++)
      row[c] = NAN;
    row[E->col_status] = DM_EINTR;      /* until it runs */
    memcpy(par, s->par, E->npar * sizeof *par);
    dm_err_clear(e);
    st = E->o->start(E->o->start_ctx, member_of(E, j), E->q0 + (size_t)i * E->nq,
                     E->p0 + (size_t)i * E->n, E->o->params ? par : NULL, e);
    if (st != DM_OK) {
      if (e != NULL && e->msg[0] == '\0')
        dm_err_set(e, st, "%s", dm_strstatus(st));
      return st;
    }
  }
  return DM_OK;
}

/* The user reduction of the batch, in member order. */
static int batch_user(ens *E, dm_err *e)
{
  long i;
  for (i = 0; i < E->nb; i++) {
    long j = E->b0 + i;
    double *row = E->rows + (size_t)j * E->nvals;
    int st;
    if (E->traj[i] == NULL || dm_traj_len(E->traj[i]) == 0) {
      dm_traj_free(E->traj[i]);      /* no sample to reduce: the values stay NaN */
      E->traj[i] = NULL;
      continue;
    }
    dm_err_clear(e);
    st = E->o->user(E->o->user_ctx, member_of(E, j), E->traj[i], row + 1, e);
    dm_traj_free(E->traj[i]);
    E->traj[i] = NULL;
    if (st != DM_OK)
      return st;
  }
  return DM_OK;
}

/* This rank's members, batch by batch. */
static int run_local(ens *E, dm_err *e)
{
  long B = E->o->batch;
  double t0 = now();
  int st = DM_OK;
  if (B == 0)
    B = E->user ? 16L * E->nworkers : 4096L;
  for (E->b0 = 0; E->b0 < E->count && st == DM_OK; E->b0 += E->nb) {
    E->nb = E->count - E->b0 < B ? E->count - E->b0 : B;
    if ((st = batch_starts(E, e)) != DM_OK)
      break;
    if (!atomic_load(&E->stop) && !dm_interrupted())
      run_batch(E, t0, E->b0);
    if (E->user && (st = batch_user(E, e)) != DM_OK)
      break;
    if (atomic_load(&E->stop) || dm_interrupted()) {
      /* the rest stays "not run"; rows of later batches are set here */
      long j, c;
      for (j = E->b0 + E->nb; j < E->count; j++) {
        double *row = E->rows + (size_t)j * E->nvals;
        for (c = 0; c < (long)E->nvals; c++)
          row[c] = NAN;
        row[E->col_status] = DM_EINTR;
      }
      E->nb = E->count - E->b0;
      break;
    }
  }
  return st;
}

/* Room for n more slots (dynamic dealing; between batches only). */
static int grow(ens *E, long n, dm_err *e)
{
  long cap = E->cap;
  double *rows;
  char **msg;
  long *idx;
  if (E->count + n <= cap)
    return DM_OK;
  while (cap < E->count + n)
    cap = cap < 64 ? 64 : 2 * cap;
  if (cap > E->o->members)
    cap = E->o->members;
  if ((rows = realloc(E->rows, ((size_t)cap + 1) * E->nvals * sizeof *rows)) != NULL)
    E->rows = rows;
  if ((msg = realloc(E->msg, ((size_t)cap + 1) * sizeof *msg)) != NULL) {
    memset(msg + E->cap, 0, (size_t)(cap + 1 - E->cap) * sizeof *msg);
    E->msg = msg;
  }
  if ((idx = realloc(E->idx, ((size_t)cap + 1) * sizeof *idx)) != NULL)
    E->idx = idx;
  if (rows == NULL || msg == NULL || idx == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory for %ld members", cap);
  E->cap = cap;
  return DM_OK;
}

/* This rank's members, taken batch by batch from the counter shared by the
 * ranks (doc/ensembles.md §6): a batch is about 1/(2P) of the members not
 * yet taken, at least one per thread and at most the batch size, so the
 * batches shrink toward the end and the ranks finish together however
 * unequal the members' costs.  A rank that stops (Ctrl-C, the progress
 * callback, an error) closes the counter: the others see it within a
 * quarter of a second (run_batch), finish the members in flight, start no
 * more and take no more batches. */
static int run_dynamic(ens *E, dm_mpi_counter *C, int size, dm_err *e)
{
  long M = E->o->members, B = E->o->batch, seen = 0;
  double t0 = now();
  int st = DM_OK;
  if (B == 0)
    B = E->user ? 16L * E->nworkers : 4096L;
  E->counter = C;
  for (;;) {
    long want = (M - seen + 2L * size - 1) / (2L * size), k0, i;
    if (atomic_load(&E->stop) || dm_interrupted())
      break;
    if (want < E->nworkers)
      want = E->nworkers;
    if (want > B)
      want = B;
    if ((st = dm_mpi_counter_take(C, want, &k0, e)) != DM_OK || k0 >= M)
      break;
    E->nb = M - k0 < want ? M - k0 : want;
    seen = k0 + E->nb > seen ? k0 + E->nb : seen;
    if ((st = grow(E, E->nb, e)) != DM_OK)
      break;
    E->b0 = E->count;
    for (i = 0; i < E->nb; i++)
      E->idx[E->b0 + i] = k0 + i;
    E->count += E->nb;
    if ((st = batch_starts(E, e)) != DM_OK)
      break;
    if (!atomic_load(&E->stop) && !dm_interrupted())
      run_batch(E, t0, E->b0);
    if (E->user && (st = batch_user(E, e)) != DM_OK)
      break;
  }
  if (st != DM_OK || atomic_load(&E->stop) || dm_interrupted()) {
    dm_err le;
    dm_mpi_counter_close(C, &le);
  }
  E->counter = NULL;
  return st;
}

/* Pack this rank's messages as records "j\0text\0". */
static char *pack_messages(const ens *E, size_t *len)
{
  size_t total = 0, pos = 0;
  long j, kept = 0;
  char *buf;
  for (j = 0; j < E->count && kept < DM_ENS_MAX_MESSAGES; j++)
    if (E->msg[j] != NULL && E->rows[(size_t)j * E->nvals + E->col_status] != DM_EINTR) {
      total += 24 + strlen(E->msg[j]) + 1;
      kept++;
    }
  if ((buf = malloc(total + 1)) == NULL)
    return NULL;
  kept = 0;
  for (j = 0; j < E->count && kept < DM_ENS_MAX_MESSAGES; j++)
    if (E->msg[j] != NULL && E->rows[(size_t)j * E->nvals + E->col_status] != DM_EINTR) {
      pos += (size_t)sprintf(buf + pos, "%ld", member_of(E, j)) + 1;
      pos += (size_t)sprintf(buf + pos, "%s", E->msg[j]) + 1;
      kept++;
    }
  *len = pos;
  return buf;
}

static int cmp_long(const void *a, const void *b)
{
  long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* Gather every rank's rows and messages and write the table. */
static int gather(ens *E, dm_traj *tr, long *nfailed, long *nintr, dm_err *e)
{
  size_t size = (size_t)(E->o->distributed ? dm_mpi_size() : 1), r, rowb = E->nvals * sizeof(double);
  size_t *counts = calloc(size, sizeof *counts), len = 0, mlen = 0, pos;
  char *mine = NULL, *msgs = NULL;
  void *all = NULL;
  long M = E->o->members, k, nmsg = 0, failed = 0, intr = 0, *keys = NULL, *idx = NULL;
  const double *rows;
  double **rowp = NULL, *notrun = NULL;
  int st;
  if (counts == NULL || (mine = pack_messages(E, &mlen)) == NULL) {
    free(counts);
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  if (size > 1) {
    st = dm_mpi_allgather_bytes(E->rows, (size_t)E->count * rowb, &all, &len, counts, e);
    if (st == DM_OK) {
      void *m = NULL;
      st = dm_mpi_allgather_bytes(mine, mlen, &m, &mlen, NULL, e);
      msgs = m;
    }
    if (st == DM_OK && E->idx != NULL) {
      void *x = NULL;
      size_t xlen;
      st = dm_mpi_allgather_bytes(E->idx, (size_t)E->count * sizeof *E->idx, &x, &xlen, NULL, e);
      idx = x;
    }
  } else {
    all = E->rows;
    counts[0] = (size_t)E->count * rowb;
    msgs = mine;
    st = DM_OK;
  }
  if (st == DM_OK && (rowp = calloc((size_t)M, sizeof *rowp)) == NULL)
    st = dm_err_set(e, DM_ENOMEM, "out of memory");
  if (st == DM_OK && (notrun = malloc(rowb)) == NULL)
    st = dm_err_set(e, DM_ENOMEM, "out of memory");
  if (st != DM_OK)
    goto out;
  /* rank r's j-th row is member r + j size (cyclic), or the member its
   * j-th index says (dynamic: the indices gathered in the same order);
   * members nobody took (a stop) were not run */
  rows = all;
  for (r = 0, pos = 0, k = 0; r < size; r++) {
    long cnt = (long)(counts[r] / rowb), j;
    for (j = 0; j < cnt; j++, k++) {
      long m = idx != NULL ? idx[k] : E->idx != NULL ? E->idx[j] : (long)r + j * (long)size;
      rowp[m] = (double *)(rows + (pos / sizeof(double)) + (size_t)j * E->nvals);
    }
    pos += counts[r];
  }
  for (r = 0; r < E->nvals; r++)
    notrun[r] = NAN;
  notrun[E->col_status] = DM_EINTR;
  for (k = 0; k < M; k++)
    if (rowp[k] == NULL)
      rowp[k] = notrun;
  if ((st = dm_traj_reserve(tr, (size_t)M, e)) != DM_OK)
    goto out;
  for (k = 0; k < M && st == DM_OK; k++) {
    int s = (int)rowp[k][E->col_status];
    failed += s != DM_OK && s != DM_EINTR;
    intr += s == DM_EINTR;
    st = dm_traj_append(tr, rowp[k][0], NULL, NULL, NULL, rowp[k] + 1, e);
  }
  /* failure messages in member order */
  for (pos = 0; pos < mlen; pos += strlen(msgs + pos) + 1)
    nmsg++;
  nmsg /= 2;
  if (st == DM_OK && nmsg > 0 && (keys = malloc((size_t)nmsg * sizeof *keys)) != NULL) {
    long i = 0;
    char key[64];
    for (pos = 0; pos < mlen; i++) {
      keys[i] = atol(msgs + pos);
      pos += strlen(msgs + pos) + 1;
      pos += strlen(msgs + pos) + 1;
    }
    qsort(keys, (size_t)nmsg, sizeof *keys, cmp_long);
    for (i = 0; i < nmsg && i < DM_ENS_MAX_MESSAGES && st == DM_OK; i++)
      for (pos = 0; pos < mlen;) {
        long kk = atol(msgs + pos);
        pos += strlen(msgs + pos) + 1;
        if (kk == keys[i]) {
          snprintf(key, sizeof key, "failure.%ld", kk + E->o->index_base);
          st = dm_traj_meta_set(tr, key, msgs + pos, e);
          break;
        }
        pos += strlen(msgs + pos) + 1;
      }
  }
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "failed", (double)failed, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "interrupted", (double)intr, e);
  *nfailed = failed;
  *nintr = intr;
out:
  if (all != E->rows)
    free(all);
  if (msgs != mine)
    free(msgs);
  free(mine);
  free(keys);
  free(rowp);
  free(notrun);
  free(idx);
  free(counts);
  return st;
}

int dm_ensemble_run(const dm_integrator *I, const dm_ens_opts *o, dm_traj **out,
                    dm_ens_summary *sum, dm_err *e)
{
  ens E;
  dm_traj *tr = NULL;
  dm_err le;
  double t0 = now();
  int st, t, size = 1, rank = 0;
  long failed = 0, intr = 0, mine;
  dm_mpi_counter *C = NULL;
  char note[DM_ERRMSG_MAX + 96] = "";
  dm_err ce;
  *out = NULL;
  if (sum != NULL)
    memset(sum, 0, sizeof *sum);
  memset(&E, 0, sizeof E);
  pthread_mutex_init(&E.mu, NULL);
  pthread_cond_init(&E.cv, NULL);
  if (e == NULL)
    e = &le;
  dm_err_clear(e);
  if ((st = check_opts(I, o, &E.run, e)) != DM_OK)
    goto fail;            /* the same on every rank: nobody waits */
  /* code being compiled in the background: installed before any member
   * runs, so that every member runs the same code (a switch half-way would
   * change the last bits of some members, and update() must not run while
   * the workers use the system) */
  if ((st = wait_for_code(I->sys, e)) != DM_OK)
    goto fail;
  E.I0 = I;
  E.sys = I->sys;
  snprintf(E.method, sizeof E.method, "%s", I->name);
  E.opt = I->opt;
  E.o = o;
  E.n = I->n;
  E.nq = I->nq;
  E.npar = I->sys->npar;
  E.user = o->user != NULL;
  E.variational = (o->reduce & DM_ENS_VARIATIONAL) != 0;
  E.nvals = 1 + o->nuser + 1;
  if (o->reduce & DM_ENS_BIT(DM_ENS_FINAL))
    E.nvals += E.nq + E.n;
  for (t = DM_ENS_ENERGY_ERROR; t < DM_ENS_NREDUCERS; t++)
    E.nvals += (o->reduce & DM_ENS_BIT(t)) != 0;
  E.col_status = E.nvals - 1;
  if (o->distributed) {
    size = dm_mpi_size();
    rank = dm_mpi_rank();
  }
  /* several ranks take batches from a shared counter; without one-sided
   * communication they deal the members cyclically (every rank the same) */
  if (size > 1 && dm_mpi_counter_open(&C, &ce) != DM_OK)
    snprintf(note, sizeof note, "members dealt cyclically over the ranks, not balanced "
             "(%s)", ce.msg);
  E.first = rank;
  E.stride = size;
  E.count = C != NULL ? 0 : o->members > rank ? (o->members - rank + size - 1) / size : 0;
  mine = C != NULL ? o->members : E.count;
  E.nworkers = o->threads > 0 ? o->threads : default_threads();
  if (E.nworkers > mine)
    E.nworkers = mine > 0 ? (int)mine : 1;
  /* from here on every rank reaches the agreement below */
  if ((tr = new_table(&E, e)) == NULL)
    st = e->status;
  if (st == DM_OK) {
    long B = o->batch > 0 ? o->batch : E.user ? 16L * E.nworkers : 4096L;
    size_t nb = (size_t)(B < mine ? B : mine > 0 ? mine : 1);
    if (C == NULL) {
      E.rows = malloc(((size_t)E.count + 1) * E.nvals * sizeof *E.rows);
      E.msg = calloc((size_t)E.count + 1, sizeof *E.msg);
      E.cap = E.count;
    } else {
      st = grow(&E, 1, e);       /* the slots grow as batches are taken */
    }
    E.q0 = malloc((nb * (E.nq + E.n + E.npar) + 1) * sizeof *E.q0);
    E.traj = E.user ? calloc(nb, sizeof *E.traj) : NULL;
    E.w = calloc((size_t)E.nworkers, sizeof *E.w);
    if (st != DM_OK || E.rows == NULL || E.msg == NULL || E.q0 == NULL
        || (E.user && E.traj == NULL) || E.w == NULL) {
      st = dm_err_set(e, DM_ENOMEM, "out of memory for %ld members", mine);
    } else {
      E.p0 = E.q0 + nb * E.nq;
      E.par0 = E.p0 + nb * E.n;
    }
  }
  for (t = 0; st == DM_OK && t < E.nworkers; t++)
    st = dm_ens__worker_init(&E, &E.w[t], e);
  if (st == DM_OK)
    st = C != NULL ? run_dynamic(&E, C, size, e) : run_local(&E, e);
  else if (C != NULL)
    dm_mpi_counter_close(C, &ce);      /* this rank cannot run: the others stop too */
  dm_mpi_counter_free(C);              /* collective */
  C = NULL;
  if (o->distributed)
    st = dm_mpi_agree(st, e);
  if (st == DM_OK)
    st = gather(&E, tr, &failed, &intr, e);
  if (st != DM_OK)
    goto fail;
  ens_free(&E);
  *out = tr;
  st = intr > 0 ? DM_EINTR : DM_OK;
  if (o->output != NULL) {
    int ws = o->distributed ? dm_traj_save_h5_shared(tr, o->output, &le)
                            : dm_traj_save_h5(tr, o->output, &le);
    if (ws != DM_OK) {
      *e = le;
      st = ws;
    }
  }
  if (st == DM_EINTR)
    dm_err_set(e, DM_EINTR, "interrupted: %ld of %ld members finished; they are kept",
               o->members - intr, o->members);
  if (sum != NULL) {
    sum->members = o->members;
    sum->done = o->members - intr;
    sum->failed = failed;
    sum->status = st;
    sum->elapsed = now() - t0;
    snprintf(sum->note, sizeof sum->note, "%s", note);
  }
  return st;
fail:
  ens_free(&E);
  dm_traj_free(tr);
  if (sum != NULL)
    sum->status = st;
  return st;
}

/* }====================================================================== */
