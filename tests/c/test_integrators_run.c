/* test_integrators_run.c -- the run loop (sampling, interrupt, Newton
 * failure keeps the partial trajectory, sink stop), error paths (singular
 * Hessian, NaN state, domain errors, unknown method, stages out of range),
 * the option table and the registry. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/interrupt.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "integ_testsys.h"
#include "tap.h"

typedef struct rec {
  long n, stop_after, interrupt_after;
  double t[64], q[64], p[64], v[64];
} rec;

static int record(void *ctx, double t, const double *q, const double *p, const double *v)
{
  rec *r = ctx;
  if (r->n < 64) {
    r->t[r->n] = t;
    r->q[r->n] = q[0];
    r->p[r->n] = p[0];
    r->v[r->n] = v[0];
  }
  r->n++;
  if (r->interrupt_after && r->n == r->interrupt_after)
    dm_interrupt_raise();
  if (r->stop_after && r->n == r->stop_after)
    return DM_ENOMEM;          /* what dm_traj_sink returns when storage fails */
  return 0;
}

static void sampling(void)
{
  dm_system s;
  dm_integrator *I = NULL;
  rec r;
  dm_run_info info;
  double q = 1.0, p = 0.5, qq = 1.0, pp = 0.5;
  int st, k;
  dm_err e;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  memset(&r, 0, sizeof r);
  st = dm_integrator_run(I, 2.385, &q, &p, 0.1, 10, 3, record, &r, &info, &e);
  tap_ok(st == DM_OK && r.n == 5 && info.samples == 5 && info.steps == 10,
         "10 steps every 3: samples at steps 0, 3, 6, 9, 10 (%ld samples)", r.n);
  tap_ok(r.t[0] == 2.385 && fabs(r.t[1] - 2.685) < 1e-15 && fabs(r.t[4] - 3.385) < 1e-15 && fabs(info.t - 3.385) < 1e-15,
         "sample times t0 + k h (%.17g, %.17g)", r.t[1], r.t[4]);
  tap_ok(fabs(r.v[2] - r.p[2]) < 1e-15, "sampled velocity v(q, p) (= p for the pendulum)");
  for (k = 0; k < 10; k++)
    dm_integrator_step(I, 0.1, &qq, &pp, &qq, &pp, NULL);
  tap_ok(q == qq && p == pp && r.q[4] == q, "run state = 10 single steps (bitwise)");
  dm_integrator_free(I);
  dm_system_release(&s);
}

static void stops(void)
{
  dm_system s, kep;
  dm_integrator *I = NULL;
  rec r;
  dm_run_info info;
  double q = 1.0, p = 0.5;
  int st;
  dm_err e;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  dm_integrator_new(&s, "lobatto", NULL, &I, NULL);
  /* Ctrl-C: the flag raised from inside the run stops it before the next step */
  memset(&r, 0, sizeof r);
  r.interrupt_after = 3;
  dm_interrupt_clear();
  st = dm_integrator_run(I, 0.0, &q, &p, 0.1, 100, 2, record, &r, &info, &e);
  tap_ok(st == DM_EINTR && info.steps == 4 && r.n == 3 && fabs(info.t - 0.4) < 1e-15,
         "interrupt: DM_EINTR after step %ld (t = %g), %ld samples kept", info.steps, info.t, r.n);
  tap_ok(strstr(e.msg, "interrupted after step 4 of 100") != NULL, "message: %s", e.msg);
  dm_interrupt_clear();
  /* the sink refuses (out of memory): stop, keep the samples */
  memset(&r, 0, sizeof r);
  r.stop_after = 4;
  q = 1.0;
  p = 0.5;
  st = dm_integrator_run(I, 0.0, &q, &p, 0.1, 100, 1, record, &r, &info, &e);
  tap_ok(st == DM_ENOMEM && info.steps == 3 && r.n == 4, "sink failure stops the run (%s) after step %ld",
         dm_strstatus(st), info.steps);
  dm_integrator_free(I);

  /* Newton failure at a huge step (Kepler from apocentre, h = 0.8): the steps
   * before the failure and the last good state are kept */
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_integrator_new(&kep, "gauss", NULL, &I, NULL);
  {
    double qk[2] = {-1.6, 0.0}, pk[2] = {0.0, -0.5}, q3[2], p3[2];
    memset(&r, 0, sizeof r);
    st = dm_integrator_run(I, 0.0, qk, pk, 0.8, 20, 1, record, &r, &info, &e);
    tap_ok(st == DM_ENOCONV && info.steps == 3 && r.n == 4 && fabs(info.t - 2.4) < 1e-12,
           "Newton failure at h = 0.8: DM_ENOCONV after %ld steps, %ld samples kept", info.steps, r.n);
    tap_ok(strstr(e.msg, "step 4 of 20") && strstr(e.msg, "t = 2.4") && strstr(e.msg, "residual")
           && strstr(e.msg, "tol"), "message names step, time, residual, tolerance: %s", e.msg);
    tap_ok(info.residual > info.tol && info.tol > 0, "run info: update %.3g > tol %.3g", info.residual, info.tol);
    memcpy(q3, qk, sizeof q3);
    memcpy(p3, pk, sizeof p3);
    tap_ok(isfinite(q3[0]) && r.q[3] == q3[0], "q, p hold the last good state (the last sample)");
  }
  dm_integrator_free(I);
  dm_system_release(&kep);
  dm_system_release(&s);
}

/* Kepler's Lagrangian through a wrapper that raises the interrupt flag at
 * its calls number raise_at (as Ctrl-C would, in the middle of a run). */
typedef struct interrupting {
  dm_system inner;
  long calls, raise_at;
} interrupting;

static int interrupting_lag(void *data, const double *q, const double *v, const double *par,
                            unsigned what, dm_lag_out *out, void *work)
{
  interrupting *w = data;
  if (++w->calls == w->raise_at)
    dm_interrupt_raise();
  return w->inner.lagrangian(w->inner.data, q, v, par, what, out, work);
}

/* The fast path keeps the state in its own buffers and the caller's,
 * renamed from step to step, and copies it out at the end: after a stop
 * after k steps (k = 37, 38, 39: each buffer arrangement) q and p are
 * bitwise k single steps. */
static void fast_path_stops(void)
{
  for (long k = 37; k <= 39; k++) {
    interrupting w;
    dm_system s;
    dm_integrator *I = NULL, *J = NULL;
    double q[2] = {0.4, 0.1}, p[2] = {-0.2, 1.9}, qs[2] = {0.4, 0.1}, ps[2] = {-0.2, 1.9};
    long done = -1;
    dm_err e;
    dm_builtin_kepler(&w.inner, 2, 1.0, NULL);
    s = w.inner;
    s.lagrangian = interrupting_lag;
    s.data = &w;
    w.calls = 0;
    w.raise_at = 0;
    dm_integrator_new(&s, "trapezoid", NULL, &I, NULL);
    dm_integrator_new(&w.inner, "trapezoid", NULL, &J, NULL);
    w.raise_at = w.calls + 1 + k;       /* the force at the start, then one a step */
    dm_interrupt_clear();
    int st = dm_integrator_advance(I, 0.01, 1000, q, p, &done, &e);
    dm_interrupt_clear();
    for (long j = 0; j < done; j++)
      dm_integrator_step(J, 0.01, qs, ps, qs, ps, NULL);
    tap_ok(st == DM_EINTR && done == k && q[0] == qs[0] && q[1] == qs[1] && p[0] == ps[0] &&
           p[1] == ps[1], "Ctrl-C inside the fast path after %ld steps: q, p = %ld single "
           "steps (bitwise)", done, k);
    dm_integrator_free(I);
    dm_integrator_free(J);
    dm_system_release(&w.inner);
  }
}

/* The explicit fast path of the run loop is bitwise the same as stepping,
 * and it polls the interrupt flag; simplified and full Newton agree. */
static void fast_paths(void)
{
  dm_system kep;
  dm_integrator *I = NULL, *F = NULL;
  dm_integ_opts o;
  rec r;
  dm_run_info info;
  double q[2] = {0.4, 0.0}, p[2] = {0.0, 2.0}, qs[2] = {0.4, 0.0}, ps[2] = {0.0, 2.0};
  int k, st, jf = 0, js = 0;
  dm_err e;
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_integrator_new(&kep, "trapezoid", NULL, &I, NULL);
  st = dm_integrator_run(I, 0.0, q, p, 0.01, 5000, 1000, NULL, NULL, NULL, NULL);
  dm_integrator_reset(I);
  for (k = 0; k < 5000; k++)
    dm_integrator_step(I, 0.01, qs, ps, qs, ps, NULL);
  tap_ok(st == DM_OK && q[0] == qs[0] && q[1] == qs[1] && p[0] == ps[0] && p[1] == ps[1],
         "Stormer-Verlet run fast path = 5000 single steps (bitwise)");
  memset(&r, 0, sizeof r);
  r.interrupt_after = 2;
  dm_interrupt_clear();
  st = dm_integrator_run(I, 0.0, q, p, 0.01, 5000, 1000, record, &r, &info, &e);
  dm_interrupt_clear();
  tap_ok(st == DM_EINTR && info.steps == 1000 && r.n == 2, "interrupt inside the fast path: after step %ld",
         info.steps);
  dm_integrator_free(I);

  dm_integ_opts_init(&o);
  strcpy(o.iteration, "newton");          /* Newton, not the fixed-point iteration */
  dm_integrator_new(&kep, "gauss", &o, &I, NULL);
  o.simplified = 0;
  dm_integrator_new(&kep, "gauss", &o, &F, NULL);
  q[0] = qs[0] = 0.4;
  q[1] = qs[1] = 0.0;
  p[0] = ps[0] = 0.0;
  p[1] = ps[1] = 2.0;
  for (k = 0; k < 200; k++) {
    dm_integrator_step(I, 0.05, q, p, q, p, NULL);
    dm_integrator_step(F, 0.05, qs, ps, qs, ps, NULL);
    js += I->stats.jacs;
    jf += F->stats.jacs;
  }
  tap_ok(fabs(q[0] - qs[0]) + fabs(q[1] - qs[1]) + fabs(p[0] - ps[0]) + fabs(p[1] - ps[1]) < 1e-13 && js < jf,
         "simplified Newton = full Newton over 200 Kepler G2 steps (%.2g) with %d instead of %d factorisations",
         fabs(q[0] - qs[0]) + fabs(q[1] - qs[1]) + fabs(p[0] - ps[0]) + fabs(p[1] - ps[1]), js, jf);
  dm_integrator_free(I);
  dm_integrator_free(F);
  dm_system_release(&kep);
}

static void errors(void)
{
  dm_system s, sing, kep;
  dm_integrator *I = (dm_integrator *)1;
  dm_integ_opts o;
  dm_err e;
  dm_run_info info;
  double q = NAN, p = 0.5, q2[2] = {0.3, 0.2}, p2[2] = {0.1, 0.1}, v2[2];
  int st;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  tap_is_int(dm_integrator_new(&s, "leapfrog9", NULL, &I, &e), DM_ENOTFOUND, "unknown method rejected");
  tap_ok(I == NULL && strstr(e.msg, "leapfrog9") && strstr(e.msg, "gauss") && strstr(e.msg, "gsl:<stepper>"),
         "message lists the methods: %s", e.msg);
  dm_integ_opts_init(&o);
  o.stages = 21;
  tap_is_int(dm_integrator_new(&s, "gauss", &o, &I, &e), DM_EINVAL, "gauss stages = 21: %s", e.msg);
  tap_ok(strstr(e.msg, "out of range") != NULL, "message says out of range");
  o.stages = 1;
  tap_is_int(dm_integrator_new(&s, "lobatto", &o, &I, &e), DM_EINVAL, "lobatto stages = 1: %s", e.msg);
  o.stages = 2;
  tap_is_int(dm_integrator_new(&s, "midpoint", &o, &I, &e), DM_EINVAL, "midpoint stages = 2: %s", e.msg);
  o.stages = -3;
  tap_is_int(dm_integrator_new(&s, "gauss", &o, &I, &e), DM_EINVAL, "gauss stages = -3 rejected");
  dm_integ_opts_init(&o);
  o.tol = 0.0;
  tap_is_int(dm_integrator_new(&s, "gauss", &o, &I, &e), DM_EINVAL, "tol = 0 rejected: %s", e.msg);

  /* NaN state */
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  st = dm_integrator_run(I, 0.0, &q, &p, 0.1, 10, 1, NULL, NULL, &info, &e);
  tap_ok(st == DM_EDOM && strstr(e.msg, "NaN"), "NaN initial state: %s", e.msg);
  q = 1.0;
  st = dm_integrator_run(I, 0.0, &q, &p, 0.0, 10, 1, NULL, NULL, &info, &e);
  tap_ok(st == DM_EINVAL, "h = 0 rejected by run: %s", e.msg);
  st = dm_integrator_step(I, INFINITY, &q, &p, &q, &p, &e);
  tap_ok(st == DM_EINVAL, "infinite h rejected by step");
  p = 1e300;
  st = dm_integrator_step(I, 1e10, &q, &p, &q, &p, &e);
  tap_ok(st != DM_OK, "overflowing step reported (%s: %s)", dm_strstatus(st), e.msg);
  dm_integrator_free(I);

  /* singular Hessian d2L/dv2 */
  ts_singular(&sing);
  dm_integrator_new(&sing, "gauss", NULL, &I, NULL);
  st = dm_integrator_step(I, 0.1, q2, p2, q2, p2, &e);
  tap_ok(st == DM_ESINGULAR && strstr(e.msg, "not regular") && strstr(e.msg, "d2L/dv2"),
         "singular Hessian, Gauss step: %s", e.msg);
  st = dm_integrator_velocity(I, q2, p2, v2, 0, &e);
  tap_ok(st == DM_ESINGULAR && strstr(e.msg, "not regular"), "singular Hessian, velocity: %s", e.msg);
  dm_integrator_free(I);
  dm_integrator_new(&sing, "rk4", NULL, &I, NULL);
  st = dm_integrator_step(I, 0.1, q2, p2, q2, p2, &e);
  tap_ok(st == DM_ESINGULAR, "singular Hessian, rk4 step: DM_ESINGULAR");
  dm_integrator_free(I);

  /* a callback outside its domain: Kepler at the origin */
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_integrator_new(&kep, "trapezoid", NULL, &I, NULL);
  q2[0] = q2[1] = 0.0;
  st = dm_integrator_step(I, 0.1, q2, p2, q2, p2, &e);
  tap_ok(st == DM_EDOM && strstr(e.msg, "outside the domain"), "Kepler at the origin: %s", e.msg);
  dm_integrator_free(I);
  dm_system_release(&kep);
  dm_system_release(&s);
}

static void options_and_registry(void)
{
  dm_integ_opts o;
  dm_err e;
  double v = 0;
  const char *str = NULL, *variant = NULL;
  const dm_integrator_type *t, *g;
  size_t i;
  int all = 1;
  dm_integ_opts_init(&o);
  tap_is_int(dm_integ_opts_set_number(&o, "stages", 3, &e), DM_OK, "set stages = 3");
  tap_is_int(o.stages, 3, "stages field written through the descriptor");
  tap_is_int(dm_integ_opts_set_number(&o, "stages", 2.5, &e), DM_EINVAL, "stages = 2.5: %s", e.msg);
  tap_is_int(dm_integ_opts_set_number(&o, "tol", 1e-20, &e), DM_EINVAL, "tol = 1e-20 below eps: %s", e.msg);
  tap_is_int(dm_integ_opts_set_number(&o, "tol", 2.385e-12, &e), DM_OK, "tol = 2.385e-12");
  dm_integ_opts_get(&o, "tol", &v, NULL, NULL);
  tap_ok(v == 2.385e-12, "get tol");
  tap_is_int(dm_integ_opts_set_number(&o, "explicit", 0, &e), DM_OK, "explicit = false");
  tap_is_int(o.explicit_sv, 0, "explicit field");
  tap_is_int(dm_integ_opts_set_string(&o, "scheme", "kahanli8", &e), DM_OK, "scheme = kahanli8");
  dm_integ_opts_get(&o, "scheme", NULL, &str, NULL);
  tap_ok(str && strcmp(str, "kahanli8") == 0, "get scheme");
  tap_is_int(dm_integ_opts_set_string(&o, "stages", "two", &e), DM_EINVAL, "string for a number: %s", e.msg);
  tap_is_int(dm_integ_opts_set_number(&o, "scheme", 1, &e), DM_EINVAL, "number for a string");
  tap_is_int(dm_integ_opts_set_number(&o, "stepsize", 1, &e), DM_ENOTFOUND, "unknown option: %s", e.msg);
  g = dm_integrator_lookup("gsl:rk8pd", &variant);
  tap_ok(g && strcmp(g->name, "gsl") == 0 && variant && strcmp(variant, "rk8pd") == 0,
         "lookup gsl:rk8pd -> type gsl, variant rk8pd");
  tap_ok(dm_integrator_lookup("gaus", NULL) == NULL && dm_integrator_lookup("gausss", NULL) == NULL,
         "lookup needs the exact family name");
  for (i = 0; (t = dm_integrator_type_at(i)) != NULL; i++) {
    const char *const *on;
    if (!t->name || !t->summary || !t->alloc || !t->step || !t->free)
      all = 0;
    for (on = t->options; on && *on; on++)
      if (dm_integ_option_find(*on) == NULL && strcmp(*on, "tableau") != 0) {
        tap_diag("%s lists unknown option %s", t->name, *on);
        all = 0;
      }
  }
  tap_ok(all && i == dm_integrator_count() && i >= 8,
         "every registered type (%zu) is complete and lists only known options", i);
}

/* {==== registration: a family for another kind of system ================= */

static int copy_alloc(dm_integrator *I, dm_err *e)
{
  (void)e;
  I->state = I;              /* nothing to hold */
  I->order = 1;
  I->stages = 3;
  return DM_OK;
}

/* q1 = q0 + h p0 (a stand-in; the registry does not care) */
static int copy_step(dm_integrator *I, double h, const double *q0, const double *p0,
                     double *q1, double *p1, dm_err *e)
{
  size_t i;
  (void)e;
  for (i = 0; i < I->n; i++) {
    q1[i] = q0[i] + h * p0[i];
    p1[i] = p0[i];
  }
  return DM_OK;
}

static void copy_free(dm_integrator *I) { I->state = NULL; }

static const char *const test_kinds[] = {"test-kind", NULL};
static const char *const copy_names[] = {"drift", NULL};
static const dm_integrator_type copy_type = {
  .name = "gauss", .summary = "a test family answering to gauss and drift on test-kind systems",
  .alloc = copy_alloc, .step = copy_step, .free = copy_free,
  .kinds = test_kinds, .names = copy_names
};
static const dm_integrator_type clash_same = {
  .name = "drift", .summary = "clashes with copy_type", .alloc = copy_alloc, .step = copy_step,
  .kinds = test_kinds
};
static const dm_integrator_type clash_core = {
  .name = "mine", .summary = "answers to midpoint on Lagrangian systems", .alloc = copy_alloc,
  .step = copy_step, .names = (const char *const[]){"midpoint", NULL}
};
static const dm_integrator_type incomplete = {.name = "nostep", .alloc = copy_alloc};

static void registration(void)
{
  dm_system s, k;
  dm_integrator *I = NULL;
  const char *variant = "x";
  size_t count = dm_integrator_count();
  double q = 2.385, p = 0.5;
  dm_err e;
  int st;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  dm_builtin_pendulum(&k, 1.0, 1.0, 1.0, NULL);
  k.kind = "test-kind";
  st = dm_integrator_new(&k, "gauss", NULL, &I, &e);
  tap_ok(st == DM_ENOTFOUND && I == NULL && strstr(e.msg, "method 'gauss' does not apply to system")
         && strstr(e.msg, "(a test-kind system); it integrates lagrangian systems"),
         "before registration, 'gauss' on a test-kind system: %s", e.msg);
  tap_is_int(dm_integrator_register(&copy_type, &e), DM_OK, "a family for test-kind systems registers");
  tap_is_int(dm_integrator_register(&copy_type, &e), DM_OK, "registering it again is a no-op");
  tap_ok(dm_integrator_count() == count + 1 && dm_integrator_type_at(count) == &copy_type,
         "one more family, at the end (%zu)", dm_integrator_count());
  tap_ok(dm_integrator_find("test-kind", "gauss", &variant) == &copy_type && variant == NULL,
         "find(test-kind, gauss) is the new family");
  tap_ok(dm_integrator_find("test-kind", "drift", NULL) == &copy_type, "and so is its further name drift");
  tap_ok(dm_integrator_lookup("gauss", NULL) != &copy_type && dm_integrator_lookup("drift", NULL) == NULL,
         "Lagrangian systems still get the core gauss and no drift");
  tap_ok(dm_integrator_accepts(&copy_type, "test-kind") && !dm_integrator_accepts(&copy_type, NULL)
         && dm_integrator_accepts(dm_integrator_lookup("rk4", NULL), DM_SYSTEM_LAGRANGIAN),
         "accepts: by the kinds a family declares");
  st = dm_integrator_new(&k, "drift", NULL, &I, &e);
  tap_ok(st == DM_OK && I != NULL && I->type == &copy_type && strcmp(I->name, "drift") == 0
         && I->stages == 3, "dm_integrator_new on a test-kind system picks the new family by name");
  if (I != NULL) {
    st = dm_integrator_step(I, 0.1, &q, &p, &q, &p, &e);
    tap_ok(st == DM_OK && q == 2.385 + 0.1 * 0.5, "and steps with it");
  } else {
    tap_ok(0, "and steps with it");
  }
  dm_integrator_free(I);
  I = NULL;
  st = dm_integrator_new(&k, "rk4", NULL, &I, &e);
  tap_ok(st == DM_ENOTFOUND && strstr(e.msg, "method 'rk4' does not apply to system")
         && strstr(e.msg, "methods here: gauss, drift"), "rk4 on a test-kind system: %s", e.msg);
  st = dm_integrator_new(&s, "drift", NULL, &I, &e);
  tap_ok(st == DM_ENOTFOUND && strstr(e.msg, "it integrates test-kind systems"),
         "drift on a Lagrangian system names the kinds it applies to: %s", e.msg);
  st = dm_integrator_new(&k, "warp", NULL, &I, &e);
  tap_ok(st == DM_ENOTFOUND && strstr(e.msg, "unknown integration method 'warp' (known: gauss, drift)"),
         "an unknown name lists the methods of the kind: %s", e.msg);
  st = dm_integrator_register(&clash_same, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "family 'drift' answers to 'drift', which family 'gauss' already has"),
         "a second family answering to drift for test-kind is refused: %s", e.msg);
  st = dm_integrator_register(&clash_core, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "answers to 'midpoint'"),
         "a family answering to midpoint on Lagrangian systems is refused: %s", e.msg);
  st = dm_integrator_register(&incomplete, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "needs a name, alloc and step"), "a family without step: %s", e.msg);
  tap_ok(dm_integrator_count() == count + 1, "refused families are not added");
  dm_system_release(&k);
  dm_system_release(&s);
}

int main(void)
{
  dm_gsl_init();
  sampling();
  stops();
  fast_paths();
  fast_path_stops();
  errors();
  options_and_registry();
  registration();
  return tap_done();
}
