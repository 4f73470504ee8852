/* native_job.c -- the background compiler: one worker thread per process,
 * a queue of jobs.  See native_job.h. */
#include <config.h>
#include "expr/native_job.h"
#include "expr/native_impl.h"
#include "core/interrupt.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct dm_native_job {
  const dm_tape *t;
  double *in0, *par0;
  dm_native_map *inmap, *outmap;
  size_t nmap;
  char *cc, *tmpdir;        /* the environment at the start */
  atomic_int cancel;        /* set under mu, polled by the worker's compiler runs */
  int state;                /* under mu */
  int status;
  dm_err err;
  dm_native *nat;
  dm_native_job *next;      /* the queue */
};

static pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t cv = PTHREAD_COND_INITIALIZER;   /* queued or finished */
static dm_native_job *head, *tail, *current;
static int worker_up, exiting;

static void *worker(void *arg)
{
  (void)arg;
  pthread_mutex_lock(&mu);
  for (;;) {
    while (head == NULL)
      pthread_cond_wait(&cv, &mu);
    dm_native_job *job = head;
    head = job->next;
    if (head == NULL)
      tail = NULL;
    job->next = NULL;
    job->state = DM_NATIVE_JOB_RUNNING;
    current = job;
    pthread_mutex_unlock(&mu);

    dm_native__set_cancel(&job->cancel);
    dm_native *nat = NULL;
    dm_err e;
    dm_err_clear(&e);
    int st = atomic_load(&job->cancel)
             ? dm_err_set(&e, DM_EINTR, "native: compilation cancelled")
             : dm_native__compile_with(job->t, job->in0, job->par0, job->inmap, job->nmap,
                                       job->outmap, &(dm_native_env){ job->cc, job->tmpdir },
                                       &nat, &e);
    dm_native__set_cancel(NULL);            /* the job may be freed once done */

    pthread_mutex_lock(&mu);
    job->nat = nat;
    job->status = st;
    job->err = e;
    job->state = st == DM_OK ? DM_NATIVE_JOB_DONE : DM_NATIVE_JOB_FAILED;
    current = NULL;
    pthread_cond_broadcast(&cv);
  }
  return NULL;
}

/* At exit: the job in progress is cancelled (its compilers killed and
 * its files removed) and the queue dropped, within about a second. */
static void at_exit(void)
{
  pthread_mutex_lock(&mu);
  exiting = 1;
  head = tail = NULL;
  if (current != NULL)
    atomic_store(&current->cancel, 1);
  for (int i = 0; i < 40 && current != NULL; i++) {
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += 25000000;
    if (ts.tv_nsec >= 1000000000) {
      ts.tv_sec++;
      ts.tv_nsec -= 1000000000;
    }
    pthread_cond_timedwait(&cv, &mu, &ts);
  }
  pthread_mutex_unlock(&mu);
}

/* Start the worker (under mu). */
static int start_worker(void)
{
  if (worker_up)
    return 0;
  pthread_attr_t at;
  pthread_t th;
  if (pthread_attr_init(&at) != 0)
    return -1;
  pthread_attr_setdetachstate(&at, PTHREAD_CREATE_DETACHED);
  int rc = pthread_create(&th, &at, worker, NULL);
  pthread_attr_destroy(&at);
  if (rc != 0)
    return -1;
  worker_up = 1;
  atexit(at_exit);
  return 0;
}

static void *dup_mem(const void *p, size_t n)
{
  if (p == NULL || n == 0)
    return NULL;
  void *q = malloc(n);
  if (q != NULL)
    memcpy(q, p, n);
  return q;
}

static void job_release(dm_native_job *job)
{
  dm_native_free(job->nat);
  free(job->in0);
  free(job->par0);
  free(job->inmap);
  free(job->outmap);
  free(job->cc);
  free(job->tmpdir);
  free(job);
}

int dm_native_job_start(const dm_tape *t, const double *in0, const double *par0,
                        const dm_native_map *inmap, size_t nmap,
                        const dm_native_map *outmap, dm_native_job **out, dm_err *err)
{
  *out = NULL;
  size_t nin = dm_tape_nin(t), npar = dm_tape_npar(t);
  dm_native_job *job = calloc(1, sizeof *job);
  if (job == NULL)
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  job->t = t;
  job->nmap = nmap;
  job->in0 = dup_mem(in0, nin * sizeof *in0);
  job->par0 = dup_mem(par0, npar * sizeof *par0);
  job->inmap = dup_mem(inmap, nin * sizeof *inmap);
  job->outmap = dup_mem(outmap, nmap * sizeof *outmap);
  const char *cc = getenv("CC"), *tmpdir = getenv("TMPDIR");
  job->cc = cc ? strdup(cc) : NULL;
  job->tmpdir = tmpdir ? strdup(tmpdir) : NULL;
  if ((cc && !job->cc) || (tmpdir && !job->tmpdir) ||
      (in0 && nin && !job->in0) || (par0 && npar && !job->par0) ||
      (inmap && nin && !job->inmap) || (outmap && nmap && !job->outmap)) {
    job_release(job);
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  }
  if (inmap != NULL && job->inmap == NULL) {   /* a tape without inputs */
    static const dm_native_map none = { 0, 0, 0 };
    job->inmap = dup_mem(&none, sizeof none);
    if (job->inmap == NULL) {
      job_release(job);
      return dm_err_set(err, DM_ENOMEM, "native: out of memory");
    }
  }
  pthread_mutex_lock(&mu);
  if (exiting || start_worker() != 0) {
    pthread_mutex_unlock(&mu);
    job_release(job);
    return dm_err_set(err, DM_EFAILED, "native: cannot start the background compiler");
  }
  job->state = DM_NATIVE_JOB_QUEUED;
  if (tail != NULL)
    tail->next = job;
  else
    head = job;
  tail = job;
  pthread_cond_broadcast(&cv);
  pthread_mutex_unlock(&mu);
  *out = job;
  return DM_OK;
}

int dm_native_job_state(dm_native_job *job)
{
  pthread_mutex_lock(&mu);
  int s = job->state;
  pthread_mutex_unlock(&mu);
  return s;
}

/* Take a queued job out of the queue (under mu). */
static void unqueue(dm_native_job *job)
{
  dm_native_job **pp = &head, *prev = NULL;
  while (*pp != NULL && *pp != job) {
    prev = *pp;
    pp = &(*pp)->next;
  }
  if (*pp == job) {
    *pp = job->next;
    if (tail == job)
      tail = prev;
  }
}

/* Cancel (under mu): a queued job fails at once, a running one when its
 * compiler has been stopped. */
static void cancel_locked(dm_native_job *job)
{
  atomic_store(&job->cancel, 1);
  if (job->state == DM_NATIVE_JOB_QUEUED) {
    unqueue(job);
    job->state = DM_NATIVE_JOB_FAILED;
    job->status = dm_err_set(&job->err, DM_EINTR, "native: compilation cancelled");
  }
}

int dm_native_job_wait(dm_native_job *job, int interruptible, dm_err *err)
{
  pthread_mutex_lock(&mu);
  while (job->state == DM_NATIVE_JOB_QUEUED || job->state == DM_NATIVE_JOB_RUNNING) {
    if (interruptible && dm_interrupted() && !atomic_load(&job->cancel))
      cancel_locked(job);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += 50000000;
    if (ts.tv_nsec >= 1000000000) {
      ts.tv_sec++;
      ts.tv_nsec -= 1000000000;
    }
    pthread_cond_timedwait(&cv, &mu, &ts);
  }
  int s = job->state == DM_NATIVE_JOB_DONE ? DM_OK : job->status;
  if (s != DM_OK && err != NULL)
    *err = job->err;
  pthread_mutex_unlock(&mu);
  return s;
}

dm_native *dm_native_job_take(dm_native_job *job, dm_err *err)
{
  dm_native *nat = NULL;
  pthread_mutex_lock(&mu);
  if (job->state == DM_NATIVE_JOB_DONE) {
    nat = job->nat;
    job->nat = NULL;
  } else if (job->state == DM_NATIVE_JOB_FAILED && err != NULL) {
    *err = job->err;
  }
  pthread_mutex_unlock(&mu);
  return nat;
}

void dm_native_job_free(dm_native_job *job)
{
  if (job == NULL)
    return;
  pthread_mutex_lock(&mu);
  cancel_locked(job);
  while (job->state == DM_NATIVE_JOB_RUNNING)
    pthread_cond_wait(&cv, &mu);
  pthread_mutex_unlock(&mu);
  job_release(job);
}
