/* ensemble_member.c -- one member of an ensemble in a worker thread: the
 * worker's integrator (rebuilt on the member's parameters, on a private
 * copy of the system), the steps from sample to sample, the built-in
 * reducers and the chaos indicators from the step Jacobian
 * (doc/ensembles.md §3), or a dm_run of its own for a user reduction.
 * See ensemble.h and ensemble_impl.h. */
#include <config.h>
#include "core/ensemble_impl.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_linalg.h>

#include "core/interrupt.h"
#include "core/numfmt.h"

static int finite_vec(const double *x, size_t n)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    s += x[i] * 0.0;
  return s == 0.0;
}

/* {==== workers ============================================================ */

/* The member's message, "member <number>: <text>", kept in E->msg. */
static void member_message(ens *E, long j, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;

static void member_message(ens *E, long j, const char *fmt, ...)
{
  char text[DM_ERRMSG_MAX + 64];
  int len;
  va_list ap;
  len = snprintf(text, sizeof text, "member %ld: ", member_of(E, j) + E->o->index_base);
  va_start(ap, fmt);
  vsnprintf(text + len, sizeof text - (size_t)len, fmt, ap);
  va_end(ap);
  free(E->msg[j]);
  E->msg[j] = strdup(text);    /* NULL when out of memory: the status remains */
}

void dm_ens__worker_free(worker *w)
{
  dm_integrator_free(w->I);
  free(w->par);
  free(w->mass);
  free(w->pmass);
  free(w->lag);
  free(w->work);
  free(w->q);
  memset(w, 0, sizeof *w);
}

/* Buffers, the system copy (params mode) and the integrator. */
int dm_ens__worker_init(ens *E, worker *w, dm_err *e)
{
  const dm_system *s = E->sys;
  size_t n = E->n, nq = E->nq, big = n * n, k;
  memset(w, 0, sizeof *w);
  w->E = E;
  /* q (nq) p v (n) qs (nq) ps (n), D (4 n^2), d dn (2n each) */
  if ((w->q = calloc(2 * nq + 3 * n + 4 * n * n + 4 * n + 1, sizeof(double))) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  w->p = w->q + nq;
  w->v = w->p + n;
  w->qs = w->v + n;
  w->ps = w->qs + nq;
  w->D = w->ps + n;
  w->d = w->D + 4 * n * n;
  w->dn = w->d + 2 * n;
  if (E->o->params) {
    w->sys = *s;
    if (s->pattern != NULL) {
      w->pat = *s->pattern;
      w->sys.pattern = &w->pat;
      if (s->pattern->vv.nnz > big) big = s->pattern->vv.nnz;
      if (s->pattern->vq.nnz > big) big = s->pattern->vq.nnz;
      if (s->pattern->qq.nnz > big) big = s->pattern->qq.nnz;
    }
    w->par = calloc(E->npar + 1, sizeof(double));
    w->mass = calloc(n * n + 1, sizeof(double));
    w->pmass = calloc(big + 1, sizeof(double));
    w->lag = calloc(2 * n + 3 * big + 1, sizeof(double));
    w->work = malloc(s->work_size + 8);
    if (w->par == NULL || w->mass == NULL || w->pmass == NULL || w->lag == NULL
        || w->work == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory");
    for (k = 0; k < E->npar; k++)
      w->par[k] = s->par[k];
    w->sys.par = w->par;
    return DM_OK;          /* the integrator is built for the first member */
  }
  return dm_integrator_new(s, E->method, &E->opt, &w->I, e);
}

/* The mass matrix of a separable system at the copy's parameters, through
 * the system's own callback (Lvv is constant: any q, v = 0); the flag is
 * dropped when M is not positive definite there. */
static int refresh_mass(worker *w, const double *q, dm_err *e)
{
  const dm_system *s0 = w->E->sys;
  size_t n = w->E->n, big;
  dm_lag_out out;
  double *v = w->v;
  if (!(s0->flags & DM_SYS_SEPARABLE))
    return DM_OK;
  big = n * n;
  memset(v, 0, n * sizeof *v);
  memset(&out, 0, sizeof out);
  out.Lq = w->lag;
  out.Lv = w->lag + n;
  out.Lvq = w->lag + 2 * n;
  out.Lqq = out.Lvq + (w->pat.vq.nnz > big ? w->pat.vq.nnz : big);
  w->sys.flags = s0->flags;
  w->sys.mass = NULL;
  w->pat.mass = NULL;
  if (s0->mass != NULL) {
    gsl_matrix_view M;
    double *C = w->pmass;
    out.Lvv = w->mass;
    if (s0->lagrangian(s0->data, q, v, w->par, DM_LAG_VV, &out, w->work) != 0)
      return dm_err_set(e, DM_EDOM, "the mass matrix cannot be evaluated at these parameters");
    memcpy(C, w->mass, n * n * sizeof *C);
    M = gsl_matrix_view_array(C, n, n);
    if (gsl_linalg_cholesky_decomp1(&M.matrix) != GSL_SUCCESS) {
      w->sys.flags &= ~(unsigned)DM_SYS_SEPARABLE;
      return DM_OK;
    }
    w->sys.mass = w->mass;
  }
  if (s0->pattern != NULL && s0->pattern->mass != NULL) {
    out.Lvv = w->pmass;
    if (s0->lagrangian(s0->data, q, v, w->par, DM_LAG_VV | DM_LAG_SPARSE, &out, w->work) != 0)
      return dm_err_set(e, DM_EDOM, "the mass matrix cannot be evaluated at these parameters");
    w->pat.mass = w->pmass;
  }
  return DM_OK;
}

/* Ready the worker's integrator for member j (batch slot i): reset, or
 * rebuilt on the member's parameters. */
static int prepare(worker *w, long i, dm_err *e)
{
  ens *E = w->E;
  const double *par = E->par0 + (size_t)i * E->npar;
  int st;
  if (!E->o->params || (w->have_par && w->I != NULL
                        && memcmp(par, w->par, E->npar * sizeof *par) == 0)) {
    dm_integrator_reset(w->I);
    return DM_OK;
  }
  memcpy(w->par, par, E->npar * sizeof *par);
  w->have_par = 1;
  dm_integrator_free(w->I);
  w->I = NULL;
  if ((st = refresh_mass(w, E->q0 + (size_t)i * E->nq, e)) != DM_OK)
    return st;
  return dm_integrator_new(&w->sys, E->method, &E->opt, &w->I, e);
}

/* }====================================================================== */

/* {==== one member with the built-in reducers ============================ */

typedef struct acc {
  double E0, dE, dmin;
  double S, Ysum, L, fli;   /* MEGNO and FLI sums */
} acc;

static double dist_of(const ens *E, const double *q)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < E->nq; i++)
    if (E->o->dist == NULL || E->o->dist[i])
      s += q[i] * q[i];
  return sqrt(s);
}

static const char *time_text(const ens *E, long k, char *buf)
{
  dm_num_format(buf, DM_NUM_BUFSIZE, E->run.t0 + (double)k * E->run.h);
  return buf;
}

/* The state after k steps (q, p): finiteness, energy, distance.  The last
 * good sample is kept in qs, ps. */
static int sample(worker *w, long j, long k, acc *a, int first)
{
  ens *E = w->E;
  size_t n = E->n;
  unsigned r = E->o->reduce;
  char tb[DM_NUM_BUFSIZE];
  dm_err le;
  if (!finite_vec(w->q, E->nq) || !finite_vec(w->p, n)) {
    member_message(E, j, "the state became non-finite (NaN or Inf) by step %ld of %ld (t = %s): "
                   "the run diverged", k, E->run.nsteps, time_text(E, k, tb));
    return DM_EDIVERGED;
  }
  if ((r & DM_ENS_BIT(DM_ENS_ENERGY_ERROR)) || E->run.max_energy_error > 0) {
    double En = NAN;
    int st = dm_integrator_velocity(w->I, w->q, w->p, w->v, !first, &le);
    if (st == DM_OK)
      st = dm_integrator_energy(w->I, w->q, w->v, &En, &le);
    if (st != DM_OK) {
      member_message(E, j, "step %ld of %ld (t = %s): no velocity or energy for the state: %s",
                     k, E->run.nsteps, time_text(E, k, tb), le.msg);
      return st;
    }
    if (first)
      a->E0 = En;
    if (!isfinite(En)) {
      member_message(E, j, "the energy became non-finite at step %ld of %ld (t = %s): the run "
                     "diverged", k, E->run.nsteps, time_text(E, k, tb));
      return DM_EDIVERGED;
    }
    if (fabs(En - a->E0) > a->dE)
      a->dE = fabs(En - a->E0);
    if (E->run.max_energy_error > 0
        && fabs(En - a->E0) > E->run.max_energy_error * fmax(1.0, fabs(a->E0))) {
      char x[DM_NUM_BUFSIZE], y[DM_NUM_BUFSIZE];
      dm_num_format(x, sizeof x, fabs(En - a->E0));
      dm_num_format(y, sizeof y, E->run.max_energy_error);
      member_message(E, j, "the energy error |E - E0| = %s exceeds max_energy_error = %s x "
                     "max(1, |E0|) at step %ld of %ld (t = %s): the run diverged", x, y, k,
                     E->run.nsteps, time_text(E, k, tb));
      return DM_EDIVERGED;
    }
  }
  if (r & DM_ENS_BIT(DM_ENS_MIN_DISTANCE)) {
    double d = dist_of(E, w->q);
    if (first || d < a->dmin)
      a->dmin = d;
  }
  memcpy(w->qs, w->q, E->nq * sizeof *w->q);
  memcpy(w->ps, w->p, n * sizeof *w->p);
  return DM_OK;
}

/* One step of the state and of the tangent vector d (2n, unit length),
 * the step into scratch (a failed step leaves its outputs unspecified). */
static int tangent_step(worker *w, acc *a, long k, dm_err *le)
{
  size_t n = w->E->n, N = 2 * n, i, c;
  double nrm = 0.0, y;
  int st;
  if ((st = dm_integrator_jacobian(w->I, w->E->run.h, w->q, w->p, w->D, le)) != DM_OK)
    return st;
  if ((st = dm_integrator_step(w->I, w->E->run.h, w->q, w->p, w->dn, w->dn + n, le)) != DM_OK)
    return st;
  memcpy(w->q, w->dn, n * sizeof *w->q);
  memcpy(w->p, w->dn + n, n * sizeof *w->p);
  for (i = 0; i < N; i++) {
    double s = 0.0;
    for (c = 0; c < N; c++)
      s += w->D[i * N + c] * w->d[c];
    w->dn[i] = s;
    nrm += s * s;
  }
  nrm = sqrt(nrm);
  if (!(nrm > 0.0) || !isfinite(nrm))
    return dm_err_set(le, DM_EDIVERGED, "the tangent vector of the variational equations "
                      "became %s", nrm == 0.0 ? "zero" : "non-finite");
  for (i = 0; i < N; i++)
    w->d[i] = w->dn[i] / nrm;
  y = log(nrm);
  a->S += (double)(k + 1) * y;
  a->Ysum += 2.0 * a->S / (double)(k + 1);
  a->L += y;
  if (a->L > a->fli)
    a->fli = a->L;
  return DM_OK;
}

/* Steps from sample to sample; returns the status, *k the steps taken, and
 * leaves the last good state in qs, ps (its step in *ks). */
static int member_steps(worker *w, long i, long j, acc *a, long *kout, long *ks)
{
  ens *E = w->E;
  const dm_run_opts *ro = &E->run;
  long k = 0, N = ro->nsteps;
  size_t n = E->n, nq = E->nq, m;
  char tb[DM_NUM_BUFSIZE];
  dm_err le;
  int st;
  *kout = *ks = 0;
  memcpy(w->q, E->q0 + (size_t)i * nq, nq * sizeof *w->q);
  memcpy(w->p, E->p0 + (size_t)i * n, n * sizeof *w->p);
  memcpy(w->qs, w->q, nq * sizeof *w->q);
  memcpy(w->ps, w->p, n * sizeof *w->p);
  dm_err_clear(&le);
  if ((st = prepare(w, i, &le)) != DM_OK) {
    member_message(E, j, "%s", le.msg);
    return st;
  }
  for (m = 0; m < 2 * n; m++)
    w->d[m] = 1.0 / sqrt((double)(2 * n));
  if ((st = sample(w, j, 0, a, 1)) != DM_OK)
    return st;
  while (k < N) {
    long next = (k / ro->every + 1) * ro->every, got = 0;
    if (next > N)
      next = N;
    dm_err_clear(&le);
    if (E->variational) {
      while (k < next && st == DM_OK) {
        if (dm_interrupted())
          st = DM_EINTR;
        else if ((st = tangent_step(w, a, k, &le)) == DM_OK)
          k++;
      }
    } else {
      st = dm_integrator_advance(w->I, ro->h, next - k, w->q, w->p, &got, &le);
      k += got;
    }
    *kout = k;
    if (st == DM_EINTR) {
      member_message(E, j, "interrupted after step %ld of %ld (t = %s)", k, N,
                     time_text(E, k, tb));
      break;
    }
    if (st != DM_OK) {
      member_message(E, j, "step %ld of %ld from t = %s failed: %s", k + 1, N,
                     time_text(E, k, tb), le.msg[0] ? le.msg : dm_strstatus(st));
      break;
    }
    if ((st = sample(w, j, k, a, 0)) != DM_OK)
      return st;
    *ks = k;
  }
  /* stopped between samples: the state where it stopped is good */
  if (st != DM_OK && finite_vec(w->q, nq) && finite_vec(w->p, n)) {
    memcpy(w->qs, w->q, nq * sizeof *w->q);
    memcpy(w->ps, w->p, n * sizeof *w->p);
    *ks = k;
  }
  return st;
}

void dm_ens__builtin_member(worker *w, long i)
{
  ens *E = w->E;
  const dm_run_opts *ro = &E->run;
  long j = E->b0 + i, k, ks;
  size_t n = E->n, nq = E->nq, c = 0;
  double *row = E->rows + (size_t)j * E->nvals;
  unsigned r = E->o->reduce;
  acc a;
  int st;
  memset(&a, 0, sizeof a);
  st = member_steps(w, i, j, &a, &k, &ks);
  row[c++] = ro->t0 + (double)ks * ro->h;
  if (r & DM_ENS_BIT(DM_ENS_FINAL)) {
    memcpy(row + c, w->qs, nq * sizeof *row);
    memcpy(row + c + nq, w->ps, n * sizeof *row);
    c += nq + n;
  }
  if (r & DM_ENS_BIT(DM_ENS_ENERGY_ERROR))
    row[c++] = a.dE;
  if (r & DM_ENS_BIT(DM_ENS_MIN_DISTANCE))
    row[c++] = a.dmin;
  if (r & DM_ENS_BIT(DM_ENS_MEGNO))
    row[c++] = k > 0 ? a.Ysum / (double)k : NAN;
  if (r & DM_ENS_BIT(DM_ENS_FLI))
    row[c++] = a.fli;
  if (r & DM_ENS_BIT(DM_ENS_LYAPUNOV))
    row[c++] = k > 0 ? a.L / fabs((double)k * ro->h) : NAN;
  row[E->col_status] = st;
}

/* }====================================================================== */
/* {==== one member with a user reduction: a dm_run of its own ============ */

void dm_ens__user_member(worker *w, long i)
{
  ens *E = w->E;
  long j = E->b0 + i;
  size_t n = E->n, nq = E->nq;
  double *row = E->rows + (size_t)j * E->nvals;
  dm_run_result res;
  dm_err le;
  dm_traj *tr;
  int st;
  memcpy(w->q, E->q0 + (size_t)i * nq, nq * sizeof *w->q);
  memcpy(w->p, E->p0 + (size_t)i * n, n * sizeof *w->p);
  row[0] = NAN;
  if ((st = prepare(w, i, &le)) != DM_OK) {
    member_message(E, j, "%s", le.msg);
    row[E->col_status] = st;
    return;
  }
  if ((tr = dm_run_traj_alloc(w->I, &le)) == NULL) {
    member_message(E, j, "%s", le.msg);
    row[E->col_status] = le.status;
    return;
  }
  st = dm_run(w->I, w->q, w->p, &E->run, tr, &res, &le);
  if (st != DM_OK)
    member_message(E, j, "%s", le.msg);
  if (res.samples > 0)
    row[0] = E->run.t0 + (double)res.steps * E->run.h;
  E->traj[i] = tr;
  row[E->col_status] = st;
}

/* }====================================================================== */
