/* test_run.c -- the run driver (core/run.h): samples and their times,
 * diagnostic columns, metadata as numbers, pieces that never change the
 * numbers, the progress callback, interrupts, failures counted from the
 * start of the run with the last good state kept, runaway detection,
 * argument errors, and runs in parallel threads computing exactly what
 * they compute alone. */
#include <config.h>
#include <math.h>
#include <pthread.h>
#include <string.h>
#include "core/status.h"
#include "core/interrupt.h"
#include "core/builtin_systems.h"
#include "core/run.h"
#include "integrators/integrator.h"
#include "integ_testsys.h"
#include "tap.h"

static int same_traj(const dm_traj *a, const dm_traj *b)
{
  size_t j, k;
  if (dm_traj_len(a) != dm_traj_len(b) || dm_traj_ncols(a) != dm_traj_ncols(b))
    return 0;
  for (j = 0; j < dm_traj_ncols(a); j++)
    for (k = 0; k < dm_traj_len(a); k++)
      if (memcmp(&dm_traj_col(a, j)[k], &dm_traj_col(b, j)[k], sizeof(double)) != 0)
        return 0;
  return 1;
}

static double meta_num(const dm_traj *tr, const char *key)
{
  double x = NAN;
  dm_traj_meta_number(tr, key, &x);
  return x;
}

static void sampling(void)
{
  dm_system s;
  dm_integrator *I = NULL;
  dm_traj *tr;
  dm_run_opts o;
  dm_run_result res;
  unsigned char mom[2] = {0, 1};
  double q[2] = {0.4, 0.0}, p[2] = {0.0, 2.0}, qq[2] = {0.4, 0.0}, pp[2] = {0.0, 2.0}, E;
  const double *t, *en;
  dm_err e;
  int st, k, ok = 1;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.t0 = 2.385;
  o.h = 0.1;
  o.nsteps = 10;
  o.every = 3;
  o.momentum = mom;
  st = dm_run(I, q, p, &o, tr, &res, &e);
  t = dm_traj_col(tr, 0);
  tap_ok(st == DM_OK && res.status == DM_OK && dm_traj_len(tr) == 5 && res.samples == 5
         && res.steps == 10 && res.nsteps == 10, "10 steps every 3: samples at steps 0, 3, 6, 9, 10");
  tap_ok(t[0] == 2.385 && t[1] == 2.385 + 3 * 0.1 && t[3] == 2.385 + 9 * 0.1
         && t[4] == 2.385 + 10 * 0.1 && res.t == t[4], "sample times t0 + k h");
  for (k = 0; k < 10; k++)
    dm_integrator_step(I, 0.1, qq, pp, qq, pp, NULL);
  tap_ok(memcmp(q, qq, sizeof q) == 0 && memcmp(p, pp, sizeof p) == 0
         && dm_traj_col(tr, 1)[4] == q[0], "q, p end where 10 single steps end (bitwise)");
  en = dm_traj_col(tr, dm_traj_find(tr, DM_TRAJ_ENERGY));
  for (k = 0; k < 5; k++) {
    double qk[2] = {dm_traj_col(tr, 1)[k], dm_traj_col(tr, 2)[k]};
    double vk[2] = {dm_traj_col(tr, 5)[k], dm_traj_col(tr, 6)[k]};
    dm_integrator_energy(I, qk, vk, &E, NULL);
    ok &= E == en[k];
  }
  tap_ok(ok && dm_traj_find(tr, "momentum_y") != DM_TRAJ_NONE
         && dm_traj_find(tr, "momentum_x") == DM_TRAJ_NONE
         && dm_traj_col(tr, dm_traj_find(tr, "momentum_y"))[2] == dm_traj_col(tr, 4)[2],
         "energy column E(q, v) of each sample; momentum_y = p_y as flagged");
  tap_ok(strcmp(dm_traj_meta_get(tr, "method"), "gauss") == 0 && meta_num(tr, "stages") == 2
         && meta_num(tr, "h") == 0.1 && meta_num(tr, "order") == 4 && meta_num(tr, "param.mu") == 1
         && meta_num(tr, "steps") == 10 && meta_num(tr, "status") == DM_OK
         && dm_traj_meta_get(tr, "message") == NULL && strcmp(dm_traj_meta_get(tr, "system"), s.name) == 0,
         "metadata as numbers: method, stages 2, h 0.1, order 4, param.mu, steps, status 0");
  dm_traj_free(tr);
  /* steps from a final time; steps = 0 records the start */
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 0.1;
  o.t0 = 1.0;
  o.t_end = 2.0;
  st = dm_run(I, q, p, &o, tr, &res, &e);
  tap_ok(st == DM_OK && res.steps == 10 && dm_traj_len(tr) == 11 && dm_traj_col(tr, 0)[10] == 1.0 + 10 * 0.1,
         "t_end = 2 from t0 = 1 with h = 0.1: 10 steps");
  dm_traj_free(tr);
  tr = dm_run_traj_alloc(I, NULL);
  o.nsteps = 0;
  st = dm_run(I, q, p, &o, tr, &res, &e);
  tap_ok(st == DM_OK && dm_traj_len(tr) == 1 && res.steps == 0, "steps = 0: the start only");
  dm_traj_free(tr);
  dm_integrator_free(I);
  dm_system_release(&s);
}

/* {==== pieces and progress ============================================== */

typedef struct prog {
  long calls, last_step, stop_at, raise_at;
  int monotone;
} prog;

static int on_progress(void *ctx, const dm_run_progress *pr)
{
  prog *g = ctx;
  g->calls++;
  g->monotone &= pr->step > g->last_step && pr->elapsed >= 0 && pr->nsteps == 1000;
  g->last_step = pr->step;
  if (g->raise_at && pr->step >= g->raise_at)
    dm_interrupt_raise();
  return g->stop_at && pr->step >= g->stop_at;
}

/* a non-mechanical system (Newton for v at every sample, warm-started) */
static dm_traj *rel_run(long piece, int with_progress, prog *g, long every, int *st)
{
  dm_system s;
  dm_integrator *I = NULL;
  dm_traj *tr;
  dm_run_opts o;
  double q = 0.3, p = 0.2;
  ts_relativistic(&s);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 0.05;
  o.nsteps = 1000;
  o.every = every;
  o.piece = piece;
  if (with_progress) {
    o.progress = on_progress;
    o.progress_ctx = g;
  }
  *st = dm_run(I, &q, &p, &o, tr, NULL, NULL);
  dm_integrator_free(I);
  return tr;
}

static void pieces(void)
{
  prog g;
  int st0, st;
  dm_traj *one = rel_run(0, 0, NULL, 7, &st0), *tr;
  long sizes[] = {1, 3, 7, 64, 0};
  size_t i;
  for (i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
    memset(&g, 0, sizeof g);
    g.monotone = 1;
    tr = rel_run(sizes[i], 1, &g, 7, &st);
    tap_ok(st0 == DM_OK && st == DM_OK && same_traj(one, tr) && g.monotone && g.calls >= 1
           && g.last_step == 1000 && (sizes[i] == 0 || g.calls == (1000 + sizes[i] - 1) / sizes[i]),
           "pieces of %ld steps (%ld progress calls) record bitwise the run in one piece",
           sizes[i], g.calls);
    dm_traj_free(tr);
  }
  dm_traj_free(one);
}

static void stops(void)
{
  prog g;
  int st;
  dm_traj *tr;
  dm_err e;
  dm_system s;
  dm_integrator *I = NULL;
  dm_run_opts o;
  dm_run_result res;
  double q = 0.3, p = 0.2;
  /* the progress callback asks to stop */
  memset(&g, 0, sizeof g);
  g.monotone = 1;
  g.stop_at = 100;
  ts_relativistic(&s);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 0.05;
  o.nsteps = 1000;
  o.every = 7;
  o.piece = 50;
  o.progress = on_progress;
  o.progress_ctx = &g;
  st = dm_run(I, &q, &p, &o, tr, &res, &e);
  tap_ok(st == DM_EINTR && res.steps == 100 && g.calls == 2 && dm_traj_len(tr) == 16
         && dm_traj_col(tr, 0)[15] == 100 * 0.05,
         "the progress callback stops the run after step 100: 15 samples + the last good state");
  tap_ok(strcmp(e.msg, "stopped by the progress callback after step 100 of 1000 (t = 5); the "
                "trajectory up to there is kept") == 0
         && strcmp(dm_traj_meta_get(tr, "message"), e.msg) == 0 && meta_num(tr, "status") == DM_EINTR
         && meta_num(tr, "steps") == 100, "message: %s", e.msg);
  dm_traj_free(tr);
  /* Ctrl-C raised during the run: stops before the next step */
  memset(&g, 0, sizeof g);
  g.monotone = 1;
  g.raise_at = 50;
  dm_interrupt_clear();
  tr = dm_run_traj_alloc(I, NULL);
  st = dm_run(I, &q, &p, &o, tr, &res, &e);
  tap_ok(st == DM_EINTR && res.steps == 50 && dm_traj_col(tr, 0)[dm_traj_len(tr) - 1] == o.t0 + 50 * 0.05
         && strcmp(e.msg, "interrupted after step 50 of 1000 (t = 2.5); the trajectory up to there is kept") == 0,
         "an interrupt keeps the state after step 50: %s", e.msg);
  dm_interrupt_clear();
  dm_traj_free(tr);
  dm_integrator_free(I);
}

/* Newton fails at step 4 (Kepler from apocentre with h = 0.8): in pieces of
 * 2 steps the message still counts from the start of the run. */
static void failure(void)
{
  dm_system s;
  dm_integrator *I = NULL;
  dm_traj *tr;
  dm_run_opts o;
  dm_run_result res;
  prog g;
  double q[2] = {-1.6, 0.0}, p[2] = {0.0, -0.5};
  dm_err e;
  int st;
  memset(&g, 0, sizeof g);
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 0.8;
  o.nsteps = 100;
  o.every = 10;
  o.piece = 2;
  o.progress = on_progress;
  o.progress_ctx = &g;
  st = dm_run(I, q, p, &o, tr, &res, &e);
  tap_ok(st == DM_ENOCONV && res.steps == 3 && dm_traj_len(tr) == 2 && dm_traj_col(tr, 0)[1] == 3 * 0.8
         && dm_traj_col(tr, 1)[1] == q[0] && dm_traj_col(tr, 3)[1] == p[0],
         "Newton failure: DM_ENOCONV after 3 steps; sample 0 and the last good state (step 3) = q, p");
  tap_ok(strncmp(e.msg, "step 4 of 100 from t = 2.4000000000000004 failed: Newton", 55) == 0
         && strstr(e.msg, "residual") && strstr(e.msg, "; the trajectory up to there is kept"),
         "in pieces of 2 steps the message counts from the start: %s", e.msg);
  tap_ok(res.residual > res.tol && res.tol > 0, "result: residual %.3g > tol %.3g", res.residual, res.tol);
  dm_traj_free(tr);
  dm_integrator_free(I);
  dm_system_release(&s);
}

/* }====================================================================== */

/* {==== runaway detection ================================================ */

static void runaway(void)
{
  static const char *const methods[] = {"gauss", "midpoint", "trapezoid", "rk4"};
  dm_system s, h;
  dm_integrator *I = NULL;
  dm_traj *tr;
  dm_run_opts o;
  dm_run_result res;
  double k = 1e12, q, p;
  dm_err e;
  size_t i;
  int st;
  ts_quartic(&s, &k);
  for (i = 0; i < sizeof methods / sizeof methods[0]; i++) {
    dm_integrator_new(&s, methods[i], NULL, &I, NULL);
    tr = dm_run_traj_alloc(I, NULL);
    dm_run_opts_init(&o);
    o.h = 100;
    o.nsteps = 100;
    q = 1.0;
    p = 0.0;
    st = dm_run(I, &q, &p, &o, tr, &res, &e);
    tap_ok(st != DM_OK && res.steps < 100 && dm_traj_len(tr) >= 1
           && strstr(e.msg, "the trajectory up to there is kept") != NULL,
           "%s, L = v^2/2 - 1e12 q^4/4 at h = 100 ends early (%s after %ld steps): %s", methods[i],
           dm_strstatus(st), res.steps, e.msg);
    dm_traj_free(tr);
    dm_integrator_free(I);
  }
  /* Gauss stays finite in q, p; the energy overflows first */
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  q = 1.0;
  p = 0.0;
  st = dm_run(I, &q, &p, &o, tr, &res, &e);
  tap_ok(st == DM_EDIVERGED && strstr(e.msg, "the energy became non-finite at step")
         && !isfinite(dm_traj_col(tr, dm_traj_find(tr, DM_TRAJ_ENERGY))[dm_traj_len(tr) - 1]),
         "gauss: DM_EDIVERGED, the sample with the non-finite energy recorded: %s", e.msg);
  dm_traj_free(tr);
  dm_integrator_free(I);
  /* a threshold on the energy error: explicit Stormer-Verlet beyond its
   * stability limit (h omega = 2.385 > 2) grows exponentially */
  dm_builtin_harmonic(&h, 1.0, 1.0, NULL);
  dm_integrator_new(&h, "trapezoid", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 2.385;
  o.nsteps = 50;
  o.max_energy_error = 1e3;
  q = 1.0;
  p = 0.0;
  st = dm_run(I, &q, &p, &o, tr, &res, &e);
  tap_ok(st == DM_EDIVERGED && res.steps > 1 && res.steps < 50 && dm_traj_len(tr) == (size_t)res.steps + 1
         && strstr(e.msg, "exceeds max_energy_error = 1000 x max(1, |E0|) at step"),
         "an energy error beyond max_energy_error ends the run at step %ld: %s", res.steps, e.msg);
  dm_traj_free(tr);
  tr = dm_run_traj_alloc(I, NULL);
  o.max_energy_error = 0;
  q = 1.0;
  p = 0.0;
  st = dm_run(I, &q, &p, &o, tr, &res, &e);
  tap_ok(st == DM_OK && res.steps == 50, "without the threshold the same run completes (%s)", dm_strstatus(st));
  dm_traj_free(tr);
  dm_integrator_free(I);
  dm_system_release(&h);
}

/* }====================================================================== */

static void arguments(void)
{
  dm_system s;
  dm_integrator *I = NULL;
  dm_traj *tr, *other;
  dm_run_opts o;
  double q[2] = {0.4, 0.0}, p[2] = {0.0, 2.0}, bad[2] = {NAN, 0.0};
  static const char *const one[] = {"x"};
  dm_err e;
  int st;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "trapezoid", NULL, &I, NULL);
  tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.nsteps = 10;
  st = dm_run(I, q, p, &o, tr, NULL, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "need a finite step h != 0") == 0 && dm_traj_ncols(tr) == 7
         && dm_traj_meta_count(tr) == 0, "no h: %s (the trajectory unchanged)", e.msg);
  o.h = 0.1;
  o.every = 0;
  st = dm_run(I, q, p, &o, tr, NULL, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "need every >= 1 (got 0)") == 0, "every = 0: %s", e.msg);
  dm_run_opts_init(&o);
  o.h = 0.1;
  o.t_end = -5;
  st = dm_run(I, q, p, &o, tr, NULL, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "the final time t = -5 cannot be reached from t0 = 0 with h = 0.1") == 0,
         "t_end behind the start: %s", e.msg);
  o.t_end = NAN;
  o.nsteps = 3;
  st = dm_run(I, bad, p, &o, tr, NULL, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "initial state contains NaN"), "NaN start: %s", e.msg);
  other = dm_traj_alloc(1, one, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL);
  st = dm_run(I, q, p, &o, other, NULL, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "must be empty, with 2 coordinates"), "wrong shape: %s", e.msg);
  dm_traj_free(other);
  st = dm_run(I, q, p, &o, tr, NULL, &e);
  tap_ok(st == DM_OK, "a good run into the same trajectory");
  st = dm_run(I, q, p, &o, tr, NULL, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "must be empty"), "a second run into it: %s", e.msg);
  dm_traj_free(tr);
  dm_integrator_free(I);
  dm_system_release(&s);
}

/* {==== threads: no hidden globals ======================================= */

typedef struct job {
  dm_system *sys;
  double q[2], p[2];
  dm_traj *tr;
  int st;
} job;

static void *run_job(void *arg)
{
  job *j = arg;
  dm_integrator *I = NULL;
  dm_run_opts o;
  dm_integrator_new(j->sys, "gauss", NULL, &I, NULL);
  j->tr = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 0.01;
  o.nsteps = 20000;
  o.every = 100;
  j->st = dm_run(I, j->q, j->p, &o, j->tr, NULL, NULL);
  dm_integrator_free(I);
  return NULL;
}

static void threads(void)
{
  enum { NJ = 4 };
  dm_system s;
  job alone[NJ], together[NJ];
  pthread_t th[NJ];
  int i, same = 1;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  for (i = 0; i < NJ; i++) {
    job j = {&s, {1.0 + 0.1 * i, 0.0}, {0.0, 0.9}, NULL, 0};
    alone[i] = j;
    together[i] = j;
    run_job(&alone[i]);
  }
  for (i = 0; i < NJ; i++)
    pthread_create(&th[i], NULL, run_job, &together[i]);
  for (i = 0; i < NJ; i++)
    pthread_join(th[i], NULL);
  for (i = 0; i < NJ; i++) {
    same &= alone[i].st == DM_OK && together[i].st == DM_OK && same_traj(alone[i].tr, together[i].tr);
    dm_traj_free(alone[i].tr);
    dm_traj_free(together[i].tr);
  }
  tap_ok(same, "%d runs on one system in %d threads record bitwise what each records alone", NJ, NJ);
  dm_system_release(&s);
}

/* }====================================================================== */

int main(void)
{
  dm_gsl_init();
  sampling();
  pieces();
  stops();
  failure();
  runaway();
  arguments();
  threads();
  return tap_done();
}
