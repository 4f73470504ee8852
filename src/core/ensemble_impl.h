/* ensemble_impl.h -- private to ensemble.c and ensemble_member.c: the
 * ensemble's state, its workers, and the functions one member runs with.
 * See ensemble.h. */
#ifndef DM_ENSEMBLE_IMPL_H
#define DM_ENSEMBLE_IMPL_H

#include <pthread.h>
#include <stdatomic.h>

#include "core/ensemble.h"

typedef struct ens ens;

typedef struct worker {
  ens *E;
  pthread_t tid;
  dm_integrator *I;
  dm_system sys;            /* a copy with its own parameters (params mode) */
  dm_sys_pattern pat;
  double *par, *mass, *pmass, *lag, *work;
  int have_par;             /* sys.par holds some member's parameters */
  int running;              /* its thread was started */
  double *q, *p, *v, *qs, *ps, *D, *d, *dn;
} worker;

struct ens {
  const dm_integrator *I0;  /* read only before the first callback */
  const dm_system *sys;     /* I0's system */
  char method[2 * DM_INTEG_STRMAX];
  dm_integ_opts opt;        /* I0's options (copies: the callbacks may rebuild I0) */
  const dm_ens_opts *o;
  dm_run_opts run;          /* nsteps resolved */
  size_t n, nq, npar, nvals;  /* momenta, numbers per q; values per row: t, reducers,
                               user, status */
  size_t col_status;
  int variational, samples, user;
  /* this rank's members: k = first + j * stride, j < count (dealt
   * cyclically), or k = idx[j] (taken in batches from the shared counter,
   * doc/ensembles.md §6); cap slots allocated */
  long first, stride, count, cap, *idx;
  struct dm_mpi_counter *counter;   /* the shared counter (dynamic dealing) */
  double *rows;             /* cap x nvals */
  char **msg;               /* cap */
  /* the batch */
  long b0, nb;
  double *q0, *p0, *par0;   /* nb x nq, nb x n, nb x npar */
  dm_traj **traj;           /* nb (user mode) */
  atomic_long next, done, failed;
  atomic_int stop;
  pthread_mutex_t mu;
  pthread_cond_t cv;
  int nworkers;
  worker *w;
};

static inline long member_of(const ens *E, long j)
{
  return E->idx != NULL ? E->idx[j] : E->first + j * E->stride;
}

/* A worker's buffers, system copy (params mode) and integrator; free. */
int dm_ens__worker_init(ens *E, worker *w, dm_err *e);
void dm_ens__worker_free(worker *w);
/* Run batch slot i with the built-in reducers / into a trajectory of its
 * own for the user reduction, writing its row (and message). */
void dm_ens__builtin_member(worker *w, long i);
void dm_ens__user_member(worker *w, long i);

#endif
