/* test_native_job.c -- native code compiled in the background while the
 * tape runs: a swap from the tape to native code between steps and in the
 * middle of a run leaves the trajectory as it is (to round-off), the
 * background compilation survives a missing compiler and a full disk (the
 * tape stays, the message is kept), Ctrl-C does not kill it (it stops a
 * wait that asks for that), and a system freed while its code compiles
 * stops the compiler and leaves no files.  Writes only under
 * $DMECH_TESTTMP. */
#include <config.h>
#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include "core/interrupt.h"
#include "core/run.h"
#include "core/status.h"
#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "integrators/integrator.h"
#include "tap.h"

#define N 6
static dm_expr_ctx *C;
static char tmpdir[4200];
static int variant;             /* a fresh source (no cache hit) per system */

/* A chain of N masses with a quartic and a cosine coupling (not
 * separable: a velocity-dependent term), and an unused parameter whose
 * value makes each compiled source distinct. */
static int make_chain(int native, dm_system *s, dm_err *e)
{
  dm_expr q[N], v[N], par[2];
  char nm[32];
  for (int i = 0; i < N; i++) {
    snprintf(nm, sizeof nm, "x%d", i);
    q[i] = dm_expr_sym(C, nm);
    snprintf(nm, sizeof nm, "vx%d", i);
    v[i] = dm_expr_sym(C, nm);
  }
  par[0] = dm_expr_param(C, "b");
  par[1] = dm_expr_param(C, "c");
  double pv[2] = { 0.7, 0.1 };
  dm_expr L = dm_expr_mul(C, dm_expr_const(C, 1e-3 * ++variant), par[1]), prev = dm_expr_const(C, 0);
  for (int i = 0; i <= N; i++) {
    dm_expr d = i < N ? dm_expr_sub(C, q[i], prev) : dm_expr_neg(C, prev);
    L = dm_expr_sub(C, L, dm_expr_add(C, dm_expr_mul(C, dm_expr_const(C, 0.5), dm_expr_powi(C, d, 2)),
                                      dm_expr_mul(C, par[0], dm_expr_powi(C, d, 4))));
    if (i < N) {
      L = dm_expr_add(C, L, dm_expr_mul(C, dm_expr_const(C, 0.5), dm_expr_powi(C, v[i], 2)));
      L = dm_expr_add(C, L, dm_expr_mul(C, dm_expr_const(C, 0.05),
                                        dm_expr_mul(C, v[i], dm_expr_unary(C, DM_EXPR_COS, q[i]))));
      prev = q[i];
    }
  }
  dm_lagrangian_spec sp = { .name = "chain", .n = N, .q = q, .v = v, .npar = 2, .par = par,
                            .par_values = pv, .L = L, .native = native };
  return dm_lagrangian_compile(C, &sp, s, e);
}

static void start(double *q, double *p)
{
  for (int i = 0; i < N; i++) {
    q[i] = 0.3 * sin(2.385 * (i + 1));
    p[i] = 0.2 * cos(1.7 * (i + 1));
  }
}

static double maxdiff(const double *a, const double *b)
{
  double d = 0;
  for (int i = 0; i < N; i++)
    d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

static int count_entries(const char *dir)
{
  DIR *d = opendir(dir);
  int n = 0;
  if (d == NULL)
    return -1;
  for (struct dirent *e; (e = readdir(d)) != NULL;)
    n += strncmp(e->d_name, "dmech-", 6) == 0;
  closedir(d);
  return n;
}

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Step the background system until its code is installed (the swap
 * happens in dm_integrator_step, between steps), then more; the tape-only
 * system takes as many steps. */
static void test_step_swap(const char *method, int stages)
{
  dm_system st, sb;
  dm_err e;
  int s1 = make_chain(DM_NATIVE_NEVER, &st, &e), s2 = make_chain(DM_NATIVE_AUTO, &sb, &e);
  dm_lagrangian_native ns;
  dm_lagrangian_native_state(&sb, &ns, NULL);
  tap_ok(s1 == DM_OK && s2 == DM_OK && ns.pending > 0 && ns.native == 0,
         "%s: the system runs at once on the tape, its native code pending (%d bundles)",
         method, ns.pending);
  dm_integ_opts o;
  dm_integ_opts_init(&o);
  if (stages > 0)
    o.stages = stages;
  dm_integrator *It = NULL, *Ib = NULL;
  dm_integrator_new(&st, method, &o, &It, &e);
  dm_integrator_new(&sb, method, &o, &Ib, &e);
  double q[N], p[N], qb[N], pb[N];
  start(q, p);
  start(qb, pb);
  long k = 0, kswap = -1;
  int ok = It && Ib;
  double t0 = now();
  while (ok && kswap < 0 && now() - t0 < 30) {
    ok &= dm_integrator_step(Ib, 0.01, qb, pb, qb, pb, &e) == DM_OK;
    k++;
    dm_lagrangian_native_state(&sb, &ns, NULL);
    if (ns.pending == 0)
      kswap = k;
  }
  for (int j = 0; j < 50 && ok; j++, k++)
    ok &= dm_integrator_step(Ib, 0.01, qb, pb, qb, pb, &e) == DM_OK;
  for (long j = 0; j < k && ok; j++)
    ok &= dm_integrator_step(It, 0.01, q, p, q, p, &e) == DM_OK;
  dm_lagrangian_native_state(&sb, &ns, NULL);
  double d = fmax(maxdiff(q, qb), maxdiff(p, pb));
  tap_ok(ok && kswap > 1 && ns.native > 0 && ns.failed == 0,
         "%s: native code installed between steps %ld and %ld", method, kswap - 1, kswap);
  tap_ok(ok && d <= 1e-14, "%s: after %ld steps, tape then native = tape alone (max diff %.2g)",
         method, k, d);
  dm_integrator_free(It);
  dm_integrator_free(Ib);
  dm_system_release(&st);
  dm_system_release(&sb);
}

/* The run driver installs the code between pieces of one run. */
static void test_run_swap(void)
{
  dm_system st, sb;
  dm_err e;
  make_chain(DM_NATIVE_NEVER, &st, &e);
  make_chain(DM_NATIVE_AUTO, &sb, &e);
  dm_integrator *It = NULL, *Ib = NULL;
  dm_integrator_new(&st, "gauss", NULL, &It, &e);
  dm_integrator_new(&sb, "gauss", NULL, &Ib, &e);
  double q[N], p[N], qb[N], pb[N];
  start(q, p);
  start(qb, pb);
  dm_run_opts o;
  dm_run_opts_init(&o);
  o.h = 0.01;
  o.nsteps = 200000;
  o.every = 100000;
  dm_traj *ta = dm_run_traj_alloc(It, &e), *tb = dm_run_traj_alloc(Ib, &e);
  dm_lagrangian_native ns;
  dm_lagrangian_native_state(&sb, &ns, NULL);
  int pending0 = ns.pending;
  int s1 = dm_run(It, q, p, &o, ta, NULL, &e), s2 = dm_run(Ib, qb, pb, &o, tb, NULL, &e);
  dm_lagrangian_native_state(&sb, &ns, NULL);
  double d = fmax(maxdiff(q, qb), maxdiff(p, pb));
  tap_ok(s1 == DM_OK && s2 == DM_OK && pending0 > 0 && d <= 1e-12,
         "one run of 200000 Gauss steps started on the tape: the same end state as the tape "
         "alone (max diff %.2g; native now in %d bundles, %d pending)", d, ns.native,
         ns.pending);
  dm_traj_free(ta);
  dm_traj_free(tb);
  dm_integrator_free(It);
  dm_integrator_free(Ib);
  dm_system_release(&st);
  dm_system_release(&sb);
}

static void test_failures(void)
{
  dm_system s;
  dm_err e;
  dm_lagrangian_native ns;
  /* no compiler */
  const char *old = getenv("CC");
  char *saved = old ? strdup(old) : NULL;
  setenv("CC", "/nonexistent/dmech-cc", 1);
  int st = make_chain(DM_NATIVE_AUTO, &s, &e);
  if (saved) {                   /* the job keeps the $CC it started with */
    setenv("CC", saved, 1);
    free(saved);
  } else {
    unsetenv("CC");
  }
  int ws = dm_lagrangian_wait_native(&s, 0, &e);
  dm_lagrangian_native_state(&s, &ns, NULL);
  tap_ok(st == DM_OK && ws == DM_ENOTFOUND && ns.native == 0 && ns.failed > 0 &&
         strstr(e.msg, "dmech-cc"), "no compiler: the tape stays (%s)", e.msg);
  dm_integrator *I = NULL;
  double q[N], p[N];
  start(q, p);
  int ok = dm_integrator_new(&s, "gauss", NULL, &I, &e) == DM_OK;
  for (int k = 0; k < 20 && ok; k++)
    ok = dm_integrator_step(I, 0.01, q, p, q, p, &e) == DM_OK;
  tap_ok(ok, "and the system steps on");
  dm_integrator_free(I);
  dm_system_release(&s);

  /* a full disk: no file can grow (RLIMIT_FSIZE, SIGXFSZ ignored) */
  struct rlimit rl, low;
  getrlimit(RLIMIT_FSIZE, &rl);
  low = rl;
  low.rlim_cur = 16;
  void (*oldh)(int) = signal(SIGXFSZ, SIG_IGN);
  setrlimit(RLIMIT_FSIZE, &low);
  st = make_chain(DM_NATIVE_AUTO, &s, &e);
  ws = dm_lagrangian_wait_native(&s, 0, &e);
  setrlimit(RLIMIT_FSIZE, &rl);
  signal(SIGXFSZ, oldh);
  dm_lagrangian_native_state(&s, &ns, NULL);
  tap_ok(st == DM_OK && ws != DM_OK && ns.native == 0 && ns.failed > 0,
         "a full disk: the tape stays (%s)", e.msg);
  start(q, p);
  ok = dm_integrator_new(&s, "trapezoid", NULL, &I, &e) == DM_OK;
  for (int k = 0; k < 20 && ok; k++)
    ok = dm_integrator_step(I, 0.01, q, p, q, p, &e) == DM_OK;
  tap_ok(ok, "and the system steps on");
  dm_integrator_free(I);
  dm_system_release(&s);
  tap_is_int(count_entries(tmpdir), 0, "no build directory left behind");
}

static void test_interrupts(void)
{
  dm_system s;
  dm_err e;
  dm_lagrangian_native ns;
  /* Ctrl-C meant for the foreground does not stop the background */
  make_chain(DM_NATIVE_AUTO, &s, &e);
  dm_interrupt_raise();
  int ws = dm_lagrangian_wait_native(&s, 0, &e);
  dm_interrupt_clear();
  dm_lagrangian_native_state(&s, &ns, NULL);
  tap_ok(ws == DM_OK && ns.native > 0, "Ctrl-C during a background compilation: it goes on "
         "(%d bundles native)", ns.native);
  dm_system_release(&s);
  /* ... but stops a wait that asks for it; the tape stays */
  make_chain(DM_NATIVE_AUTO, &s, &e);
  dm_interrupt_raise();
  ws = dm_lagrangian_wait_native(&s, 1, &e);
  dm_interrupt_clear();
  dm_lagrangian_native_state(&s, &ns, NULL);
  tap_ok(ws == DM_EINTR && ns.pending == 0 && ns.native == 0,
         "an interruptible wait stops at Ctrl-C, the compilation cancelled (%s)", e.msg);
  dm_system_release(&s);
  /* freed while compiling: the compiler stopped, nothing left behind */
  make_chain(DM_NATIVE_AUTO, &s, &e);
  dm_system_release(&s);
  tap_is_int(count_entries(tmpdir), 0, "a system freed while its code compiles: no files "
             "left behind");
}

int main(void)
{
  dm_gsl_init();
  const char *tt = getenv("DMECH_TESTTMP");
  if (tt == NULL || *tt == '\0') {
    static char d[] = "/tmp/dmech-test-native-job-XXXXXX";
    tt = mkdtemp(d);
  }
  snprintf(tmpdir, sizeof tmpdir, "%s/native-tmp-job", tt);
  mkdir(tmpdir, 0700);
  setenv("TMPDIR", tmpdir, 1);
  static char cdir[4300];
  snprintf(cdir, sizeof cdir, "%s/cache-job", tt);
  setenv("XDG_CACHE_HOME", cdir, 1);
  C = dm_expr_ctx_alloc();
  /* no working cc at all: skip */
  dm_system s;
  dm_err e;
  if (make_chain(DM_NATIVE_ALWAYS, &s, &e) == DM_ENOTFOUND) {
    printf("1..0 # SKIP no C compiler\n");
    dm_expr_ctx_free(C);
    return 0;
  }
  dm_system_release(&s);
  test_step_swap("gauss", 2);
  test_step_swap("trapezoid", 0);
  test_run_swap();
  test_failures();
  test_interrupts();
  dm_expr_ctx_free(C);
  return tap_done();
}
