/* run.c -- the run driver: an integrator into a trajectory, in pieces
 * between progress calls, sampling, diagnostics, runaway detection and the
 * last good state on an early end.  See run.h. */
#include <config.h>
#include "core/run.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/interrupt.h"
#include "core/numfmt.h"

void dm_run_opts_init(dm_run_opts *o)
{
  memset(o, 0, sizeof *o);
  o->h = NAN;
  o->nsteps = -1;
  o->t_end = NAN;
  o->every = 1;
  o->energy = 1;
}

int dm_run_steps_to(double t0, double t_end, double h, long *nsteps, dm_err *e)
{
  double x = (t_end - t0) / h;
  if (!isfinite(x) || x < -0.5 || x > 9e15) {
    char a[DM_NUM_BUFSIZE], b[DM_NUM_BUFSIZE], c[DM_NUM_BUFSIZE];
    dm_num_format(a, sizeof a, t_end);
    dm_num_format(b, sizeof b, t0);
    dm_num_format(c, sizeof c, h);
    return dm_err_set(e, DM_EINVAL, "the final time t = %s cannot be reached from t0 = %s "
                      "with h = %s", a, b, c);
  }
  *nsteps = lround(x);
  return DM_OK;
}

dm_traj *dm_run_traj_alloc(const dm_integrator *I, dm_err *e)
{
  const dm_system *s = I->sys;
  if (s->pnames != NULL || s->vnames != NULL || I->nq != I->n)
    return dm_traj_alloc_state(I->nq, s->coords, I->n, s->pnames, s->vnames,
                               DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, e);
  return dm_traj_alloc(I->n, s->coords, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, e);
}

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int finite_vec(const double *x, size_t n)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    s += x[i] * 0.0;
  return s == 0.0;                  /* NaN for any NaN or Inf */
}

/* {==== the state of one run ============================================ */

typedef struct run {
  dm_integrator *I;
  dm_run_opts *o;         /* the run's copy: nsteps is set when a run "until"
                           * reaches t_end */
  dm_traj *tr;
  size_t n, nq;           /* velocities (momenta); numbers per configuration */
  double *q, *p;          /* the caller's state (nq, n), advanced in place */
  double *v, *extra, *J;  /* n; one value per extra column; the momentum map (n) */
  size_t next;            /* extra columns: energy (if any) then momenta */
  int have_v;             /* v holds the previous sample's velocity (a guess) */
  int check_E;            /* energy computed at every sample */
  double E0;
  long k, last;           /* steps done; step of the last sample (-1: none) */
  size_t samples;
  int varstep;            /* the integrator keeps the physical time (I->t) */
  int until;              /* varstep run to t_end: nsteps unknown until reached */
  double *q1, *p1;        /* nq, n: the step of an "until" run */
  char t_text[DM_NUM_BUFSIZE], of_text[32];
} run;

/* The time after k steps: t0 + k h, or the integrator's own clock. */
static double time_at(const run *r, long k)
{
  return r->varstep ? r->I->t : r->o->t0 + (double)k * r->o->h;
}

static const char *time_text(run *r, long k)
{
  dm_num_format(r->t_text, sizeof r->t_text, time_at(r, k));
  return r->t_text;
}

/* " of <nsteps>" (empty while a run "until" t_end does not know it) */
static const char *of_text(run *r)
{
  if (r->until)
    r->of_text[0] = '\0';
  else
    snprintf(r->of_text, sizeof r->of_text, " of %ld", r->o->nsteps);
  return r->of_text;
}

static size_t sink_block(const dm_run_opts *o)
{
  return o->sink_every > 0 ? (size_t)o->sink_every : 4096;
}

/* The samples held so far to the sink, then dropped. */
static int flush(run *r, dm_err *e)
{
  dm_err le;
  dm_err_clear(&le);
  if (dm_traj_len(r->tr) == 0)
    return DM_OK;
  int st = r->o->sink(r->o->sink_ctx, r->tr, &le);
  dm_traj_clear(r->tr);
  if (st != DM_OK)
    return dm_err_set(e, st, "step %ld%s (t = %s): the sink failed: %s", r->k, of_text(r),
                      time_text(r, r->k), le.msg[0] ? le.msg : dm_strstatus(st));
  return DM_OK;
}


/* Record the state after r->k steps: velocity, energy, momenta; the
 * runaway tests.  DM_EDIVERGED for a non-finite state (not recorded) or
 * energy (recorded, then the run stops). */
static int record(run *r, dm_err *e)
{
  const dm_run_opts *o = r->o;
  size_t i, j = 0, n = r->n;
  double E = NAN;
  dm_err le;
  int st;
  if (!finite_vec(r->q, r->nq) || !finite_vec(r->p, n))
    return dm_err_set(e, DM_EDIVERGED, "the state became non-finite (NaN or Inf) by step %ld"
                      "%s (t = %s): the run diverged", r->k, of_text(r), time_text(r, r->k));
  if ((st = dm_integrator_velocity(r->I, r->q, r->p, r->v, r->have_v, &le)) != DM_OK) {
    if (r->last >= 0)
      return dm_err_set(e, st, "step %ld%s (t = %s): no velocity for the state: %s", r->k,
                        of_text(r), time_text(r, r->k), le.msg);
    return dm_err_set(e, st, "%s", le.msg);
  }
  r->have_v = 1;
  if (r->check_E && dm_integrator_energy(r->I, r->q, r->v, &E, NULL) != DM_OK)
    E = NAN;
  if (o->energy)
    r->extra[j++] = E;
  if (o->momentum != NULL && r->I->sys->momentum_map != NULL)
    r->I->sys->momentum_map(r->I->sys, r->q, r->p, r->J);
  for (i = 0; i < n; i++)
    if (o->momentum != NULL && o->momentum[i])
      r->extra[j++] = r->I->sys->momentum_map != NULL ? r->J[i] : r->p[i];
  if (r->varstep)
    r->extra[j++] = r->I->dt;
  if ((st = dm_traj_append(r->tr, time_at(r, r->k), r->q, r->p, r->v, r->extra, &le)) != DM_OK)
    return dm_err_set(e, st, "step %ld%s (t = %s): the sample could not be stored: %s",
                      r->k, of_text(r), time_text(r, r->k), le.msg);
  r->last = r->k;
  r->samples++;
  if (o->sink != NULL && dm_traj_len(r->tr) >= sink_block(o) &&
      (st = flush(r, e)) != DM_OK)
    return st;
  if (!r->check_E)
    return DM_OK;
  if (r->samples == 1)
    r->E0 = E;
  if (!isfinite(E))
    return dm_err_set(e, DM_EDIVERGED, "the energy became non-finite at step %ld%s "
                      "(t = %s): the run diverged", r->k, of_text(r), time_text(r, r->k));
  if (o->max_energy_error > 0 && fabs(E - r->E0) > o->max_energy_error * fmax(1.0, fabs(r->E0))) {
    char a[DM_NUM_BUFSIZE], b[DM_NUM_BUFSIZE];
    dm_num_format(a, sizeof a, fabs(E - r->E0));
    dm_num_format(b, sizeof b, o->max_energy_error);
    return dm_err_set(e, DM_EDIVERGED, "the energy error |E - E0| = %s exceeds "
                      "max_energy_error = %s x max(1, |E0|) at step %ld%s (t = %s): the run "
                      "diverged", a, b, r->k, of_text(r), time_text(r, r->k));
  }
  return DM_OK;
}

/* }====================================================================== */

/* {==== set-up and the end ============================================== */

static int check_args(const dm_integrator *I, const double *q, const double *p,
                      const dm_run_opts *o, const dm_traj *tr, dm_err *e)
{
  size_t n = I->n, nq = I->nq;
  if (!isfinite(o->h) || o->h == 0.0)
    return dm_err_set(e, DM_EINVAL, "need a finite step h != 0");
  if (!isfinite(o->t0))
    return dm_err_set(e, DM_EINVAL, "the start time t0 must be finite");
  if (o->nsteps < 0)
    return dm_err_set(e, DM_EINVAL, "need steps >= 0 or a final time");
  if (o->every < 1)
    return dm_err_set(e, DM_EINVAL, "need every >= 1 (got %ld)", o->every);
  if (!(o->max_energy_error >= 0))
    return dm_err_set(e, DM_EINVAL, "max_energy_error must be >= 0");
  if (o->piece < 0)
    return dm_err_set(e, DM_EINVAL, "need piece >= 0 (0: automatic)");
  if (tr == NULL || dm_traj_ncoords(tr) != nq || dm_traj_nmomenta(tr) != n
      || (dm_traj_flags(tr) & (DM_TRAJ_WITH_P | DM_TRAJ_WITH_V)) != (DM_TRAJ_WITH_P | DM_TRAJ_WITH_V)
      || dm_traj_len(tr) != 0 || dm_traj_ncols(tr) != 1 + nq + 2 * n)
    return dm_err_set(e, DM_EINVAL, "the trajectory must be empty, with %zu coordinates, "
                      "p and v columns and no other (dm_run_traj_alloc)", nq);
  if (!finite_vec(q, nq) || !finite_vec(p, n))
    return dm_err_set(e, DM_EINVAL, "the initial state contains NaN or Inf");
  return DM_OK;
}

/* Samples the trajectory holds at most at once. */
static size_t held_samples(const dm_run_opts *o)
{
  size_t want = (size_t)(o->nsteps > 0 ? o->nsteps : 0) / (size_t)o->every + 2;
  return o->sink != NULL && sink_block(o) < want ? sink_block(o) : want;
}

size_t dm_run_bytes(const dm_integrator *I, const dm_run_opts *o)
{
  size_t cols = 1 + I->nq + 2 * I->n + (o->energy ? 1 : 0);
  for (size_t i = 0; o->momentum != NULL && i < I->n; i++)
    cols += o->momentum[i] != 0;
  long nsteps = o->nsteps;
  if (nsteps < 0 && isfinite(o->t_end) && isfinite(o->h) && o->h != 0.0 &&
      dm_run_steps_to(o->t0, o->t_end, o->h, &nsteps, NULL) != DM_OK)
    nsteps = 0;
  dm_run_opts t = *o;
  t.nsteps = nsteps < 0 ? 0 : nsteps;
  if (t.every < 1)
    t.every = 1;
  return held_samples(&t) * cols * sizeof(double);
}

/* Diagnostic columns and the metadata known before the run. */
static int prepare(run *r, dm_err *e)
{
  const dm_system *s = r->I->sys;
  const dm_run_opts *o = r->o;
  size_t i;
  int st = DM_OK;
  char key[300];
  if (o->energy)
    st = dm_traj_add_column(r->tr, DM_TRAJ_ENERGY, DM_TRAJ_DIAG, NULL, 0, e);
  for (i = 0; st == DM_OK && i < r->n; i++)
    if (o->momentum != NULL && o->momentum[i]) {
      char name[DM_TRAJ_NAME_MAX + 1];
      if (s->momentum_map != NULL)
        snprintf(name, sizeof name, "%s%zu", DM_TRAJ_MOMENTUM, i + 1);
      else
        snprintf(name, sizeof name, "%s%s", DM_TRAJ_MOMENTUM, dm_traj_coord(r->tr, i));
      st = dm_traj_add_column(r->tr, name, DM_TRAJ_DIAG, NULL, 0, e);
    }
  /* variable physical steps: their lengths as a column */
  if (st == DM_OK && r->varstep)
    st = dm_traj_add_column(r->tr, "h", DM_TRAJ_DIAG, NULL, 0, e);
  if (st == DM_OK && s->name != NULL)
    st = dm_traj_meta_set(r->tr, "system", s->name, e);
  if (st == DM_OK)
    st = dm_traj_meta_set(r->tr, "method", r->I->name, e);
  if (st == DM_OK && dm_integrator_stages_chosen(r->I))
    st = dm_traj_meta_set_number(r->tr, "stages", r->I->stages, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(r->tr, "h", o->h, e);
  if (st == DM_OK && r->I->order > 0)
    st = dm_traj_meta_set_number(r->tr, "order", r->I->order, e);
  if (st == DM_OK && s->space != NULL)
    st = dm_traj_meta_set(r->tr, "space", s->space, e);
  for (i = 0; st == DM_OK && i < s->npar; i++) {
    snprintf(key, sizeof key, "param.%s", s->params ? s->params[i] : "?");
    st = dm_traj_meta_set_number(r->tr, key, s->par[i], e);
  }
  /* exactly the samples the run will hold at once (best effort: without
   * it the storage grows by doubling); a run "until" t_end guesses */
  if (st == DM_OK && r->until) {
    dm_run_opts t = *o;
    double guess = (o->t_end - o->t0) / o->h;
    t.nsteps = guess < 1e6 ? (long)guess : 1000000L;
    dm_traj_reserve(r->tr, held_samples(&t), NULL);
  } else if (st == DM_OK) {
    dm_traj_reserve(r->tr, held_samples(o), NULL);
  }
  return st;
}

static int run_it(dm_integrator *I, double *q, double *p, const dm_run_opts *opts,
                  dm_traj *tr, dm_run_result *res, dm_err *e);

static void finish(run *r, int st, const dm_err *e, dm_run_result *res)
{
  dm_traj_meta_set_number(r->tr, "steps", (double)r->k, NULL);
  if (r->varstep)
    dm_traj_meta_set_number(r->tr, "t_end", time_at(r, r->k), NULL);
  dm_traj_meta_set_number(r->tr, "status", st, NULL);
  dm_traj_meta_set(r->tr, "message", st != DM_OK ? e->msg : NULL, NULL);
  if (res != NULL) {
    res->status = st;
    res->steps = r->k;
    res->nsteps = r->o->nsteps;
    res->t = time_at(r, r->k);
    res->samples = r->samples;
    res->residual = r->I->stats.residual;
    res->tol = r->I->stats.tol;
  }
}

/* }====================================================================== */

/* {==== the loop ========================================================= */

/* Steps up to `end`, recording at every multiple of `every` and at the last
 * step.  On failure e holds the run's message. */
/* A run "until" t_end with variable physical steps: one step at a time,
 * the last one shortened by the integrator to end at t_end. */
static int advance_until(run *r, long end, dm_err *e)
{
  dm_run_opts *o = r->o;
  size_t n = r->n;
  dm_err le;
  while (r->k < end) {
    int st, reached = 0;
    if (dm_interrupted())
      return dm_err_set(e, DM_EINTR, "interrupted after step %ld (t = %s)", r->k,
                        time_text(r, r->k));
    dm_err_clear(&le);
    st = dm_integrator_step_until(r->I, o->h, o->t_end, r->q, r->p, r->q1, r->p1, &reached,
                                  &le);
    if (st != DM_OK)
      return dm_err_set(e, st, "step %ld from t = %s failed: %s", r->k + 1, time_text(r, r->k),
                        le.msg[0] ? le.msg : dm_strstatus(st));
    memcpy(r->q, r->q1, r->nq * sizeof *r->q);
    memcpy(r->p, r->p1, n * sizeof *r->p);
    r->k++;
    if (reached) {
      o->nsteps = r->k;
      r->until = 0;
    }
    if ((reached || r->k % o->every == 0) && (st = record(r, e)) != DM_OK)
      return st;
    if (reached)
      break;
  }
  return DM_OK;
}

static int advance_to(run *r, long end, dm_err *e)
{
  const dm_run_opts *o = r->o;
  dm_err le;
  if (r->until)
    return advance_until(r, end, e);
  while (r->k < end) {
    long next = (r->k / o->every + 1) * o->every, stop, got = 0;
    int st;
    if (next > o->nsteps)
      next = o->nsteps;
    stop = next < end ? next : end;
    dm_err_clear(&le);
    st = dm_integrator_advance(r->I, o->h, stop - r->k, r->q, r->p, &got, &le);
    r->k += got;
    if (st == DM_EINTR)
      return dm_err_set(e, DM_EINTR, "interrupted after step %ld%s (t = %s)", r->k,
                        of_text(r), time_text(r, r->k));
    if (st != DM_OK)
      return dm_err_set(e, st, "step %ld%s from t = %s failed: %s", r->k + 1, of_text(r),
                        time_text(r, r->k), le.msg[0] ? le.msg : dm_strstatus(st));
    if (r->k == next && (st = record(r, e)) != DM_OK)
      return st;
  }
  return DM_OK;
}

/* dm_run with a message record that is never NULL */
static int run_it(dm_integrator *I, double *q, double *p, const dm_run_opts *opts,
                  dm_traj *tr, dm_run_result *res, dm_err *e)
{
  dm_run_opts o = *opts;
  run r;
  double start, piece_start;
  long P;
  int st, bg;
  dm_err_clear(e);
  memset(&r, 0, sizeof r);
  r.varstep = dm_integrator_varstep(I);
  if (r.varstep && isfinite(o.t_end) && o.nsteps < 0 && isfinite(o.h) && o.h != 0.0) {
    /* physical time is the integrator's: step until t_end is reached */
    if ((st = dm_run_steps_to(o.t0, o.t_end, o.h, &o.nsteps, e)) != DM_OK)
      return st;
    if (o.t_end != o.t0) {
      r.until = 1;
      o.nsteps = LONG_MAX / 2;
    } else {
      o.nsteps = 0;
    }
  }
  if (isfinite(o.t_end) && o.nsteps < 0 && isfinite(o.h) && o.h != 0.0
      && (st = dm_run_steps_to(o.t0, o.t_end, o.h, &o.nsteps, e)) != DM_OK)
    return st;
  if ((st = check_args(I, q, p, &o, tr, e)) != DM_OK)
    return st;
  r.I = I;
  r.o = &o;
  r.tr = tr;
  r.n = I->n;
  r.nq = I->nq;
  r.q = q;
  r.p = p;
  r.last = -1;
  r.check_E = o.energy || o.max_energy_error > 0;
  if ((r.v = calloc(5 * r.n + r.nq + 2, sizeof *r.v)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  r.extra = r.v + r.n;            /* energy, n momenta, the step length */
  r.J = r.extra + r.n + 2;
  r.q1 = r.J + r.n;
  r.p1 = r.q1 + r.nq;
  if ((st = dm_integrator_begin(I, o.h, o.t0, q, p, e)) != DM_OK) {
    free(r.v);
    return st;
  }
  if ((st = prepare(&r, e)) != DM_OK || (st = record(&r, e)) != DM_OK) {
    if (r.samples == 0) {
      dm_traj_clear(tr);
      free(r.v);
      return st;
    }
    goto done;
  }
  start = now();
  /* code compiled in the background is installed between pieces, which
   * are then ~0.1 s long even without a progress callback */
  bg = I->sys->update != NULL && I->sys->update(I->sys);
  P = o.piece > 0 ? o.piece
      : o.progress != NULL || bg ? (o.every < 64 ? 64 : o.every) : o.nsteps;
  while (r.k < o.nsteps) {
    long end = o.nsteps - r.k > P ? r.k + P : o.nsteps;
    piece_start = now();
    if ((st = advance_to(&r, end, e)) != DM_OK)
      break;
    if (bg) {
      bg = I->sys->update(I->sys);
      if (o.piece == 0 && o.progress == NULL) {
        double dt = now() - piece_start;
        P = dt > 1e-3 ? (long)((double)P * fmin(16.0, fmax(0.5, 0.1 / dt))) : 16 * P;
        if (P < 1)
          P = 1;
        if (!bg)
          P = o.nsteps;            /* nothing more to come: the rest at once */
      }
    }
    if (o.progress != NULL) {
      dm_run_progress pr;
      double tn = now(), dt = tn - piece_start;
      pr.step = r.k;
      pr.nsteps = o.nsteps;
      pr.t = time_at(&r, r.k);
      if (r.until)                 /* estimated from the time reached */
        pr.nsteps = pr.t != o.t0 ? (long)((double)r.k * (o.t_end - o.t0) / (pr.t - o.t0))
                                 : r.k + 1;
      pr.elapsed = tn - start;
      if (o.progress(o.progress_ctx, &pr) != 0) {
        if (r.k < o.nsteps)
          st = dm_err_set(e, DM_EINTR, "stopped by the progress callback after step %ld"
                          "%s (t = %s)", r.k, of_text(&r), time_text(&r, r.k));
        break;
      }
      if (o.piece == 0) {          /* aim at ~0.1 s per piece */
        P = dt > 1e-3 ? (long)((double)P * fmin(16.0, fmax(0.5, 0.1 / dt))) : 16 * P;
        if (P < 1)
          P = 1;
      }
    }
  }
  /* the last good state when the run stopped between samples */
  if (st != DM_OK && st != DM_EDIVERGED && r.last != r.k) {
    dm_err ign;
    record(&r, &ign);
  }
done:
  if (o.sink != NULL) {
    /* the rest to the sink; the last sample stays */
    dm_err se;
    int fs = flush(&r, st == DM_OK ? e : &se);
    if (fs != DM_OK && st == DM_OK)
      st = fs;
    if (r.last >= 0 && r.last == r.k)
      dm_traj_append(tr, time_at(&r, r.last), r.q, r.p, r.v, r.extra, NULL);
  }
  dm_traj_shrink(tr);                /* 8 bytes per number stored */
  if (st != DM_OK) {
    size_t len = strlen(e->msg);
    snprintf(e->msg + len, sizeof e->msg - len, "; the trajectory up to there is kept");
  }
  finish(&r, st, e, res);
  free(r.v);
  return st;
}

int dm_run(dm_integrator *I, double *q, double *p, const dm_run_opts *opts, dm_traj *tr,
           dm_run_result *res, dm_err *e)
{
  dm_err err;
  int st;
  if (res != NULL) {
    memset(res, 0, sizeof *res);
    res->nsteps = opts->nsteps;
  }
  st = run_it(I, q, p, opts, tr, res, &err);
  if (res != NULL)
    res->status = st;
  if (e != NULL)
    *e = err;
  return st;
}
