/* test_ensemble.c -- the ensemble driver: the thread count does not change
 * a bit, a member is what a lone run computes, reset integrators forget
 * their history (every family), the chaos indicators' known limits, a
 * failing member keeps the others, Ctrl-C keeps finished members,
 * parameter sweeps, per-member seeds, error paths. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/builtin_systems.h"
#include "core/ensemble.h"
#include "core/interrupt.h"
#include "core/run.h"
#include "integrators/integrator.h"
#include "tap.h"

/* Kepler orbits q = (0.5 + 0.0037 k, 0), p = (0, 1.3); member `bad` starts
 * at rest next to the centre (it falls in and fails); `interrupt_at`
 * raises Ctrl-C when its start is asked for. */
typedef struct starts {
  long bad, interrupt_at, fail_at;
  int with_par;
  double omega0;
} starts;

static int kepler_start(void *ctx, long k, double *q, double *p, double *par, dm_err *e)
{
  starts *s = ctx;
  if (k == s->fail_at)
    return dm_err_set(e, DM_ECALLBACK, "no start for member %ld", k);
  if (k == s->interrupt_at)
    dm_interrupt_raise();
  q[0] = 0.5 + 0.0037 * (double)k;
  q[1] = 0.0;
  p[0] = 0.0;
  p[1] = 1.3;
  if (k == s->bad) {
    q[0] = 1e-3;
    p[1] = 0.0;
  }
  (void)par;
  return DM_OK;
}

static int same_tables(const dm_traj *a, const dm_traj *b)
{
  size_t j;
  if (dm_traj_len(a) != dm_traj_len(b) || dm_traj_ncols(a) != dm_traj_ncols(b))
    return 0;
  for (j = 0; j < dm_traj_ncols(a); j++)
    if (strcmp(dm_traj_colname(a, j), dm_traj_colname(b, j)) != 0
        || memcmp(dm_traj_col(a, j), dm_traj_col(b, j), dm_traj_len(a) * sizeof(double)) != 0)
      return 0;
  return 1;
}

static double cell(const dm_traj *t, const char *col, size_t k)
{
  size_t j = dm_traj_find(t, col);
  return j == DM_TRAJ_NONE ? NAN : dm_traj_col(t, j)[k];
}

static long every = 50;

static dm_traj *run_ens(dm_integrator *I, unsigned reduce, long members, int threads,
                        long nsteps, starts *s, int *st, dm_err *e)
{
  dm_ens_opts o;
  dm_traj *t = NULL;
  dm_ens_opts_init(&o);
  o.members = members;
  o.threads = threads;
  o.run.h = 0.01;
  o.run.nsteps = nsteps;
  o.run.every = every;
  o.reduce = reduce;
  o.start = kepler_start;
  o.start_ctx = s;
  o.batch = 5;               /* several batches even for small tests */
  *st = dm_ensemble_run(I, &o, &t, NULL, e);
  return t;
}

#define ALL (DM_ENS_BIT(DM_ENS_FINAL) | DM_ENS_BIT(DM_ENS_ENERGY_ERROR) \
             | DM_ENS_BIT(DM_ENS_MIN_DISTANCE) | DM_ENS_VARIATIONAL)

static void threads_do_not_matter(void)
{
  dm_system s;
  dm_integrator *I;
  starts st0 = {-1, -1, -1, 0, 0};
  dm_traj *t1, *t2, *t3;
  dm_err e;
  int st;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  t1 = run_ens(I, ALL, 23, 1, 400, &st0, &st, &e);
  tap_ok(st == DM_OK && t1 != NULL && dm_traj_len(t1) == 23, "23 members on 1 thread: %s",
         st ? e.msg : "ok");
  t2 = run_ens(I, ALL, 23, 2, 400, &st0, &st, &e);
  t3 = run_ens(I, ALL, 23, 3, 400, &st0, &st, &e);
  tap_ok(t1 && t2 && t3 && same_tables(t1, t2) && same_tables(t1, t3),
         "2 and 3 threads give the 1-thread table bit for bit");
  {
    char names[256];
    dm_traj_names(t1, names, sizeof names);
    tap_ok(strcmp(names, "t, x, y, p_x, p_y, energy_error, min_distance, megno, fli, lyapunov, "
                  "status") == 0, "columns: %s", names);
  }
  tap_ok(cell(t1, "t", 7) == 4.0 && cell(t1, "status", 7) == 0.0
         && dm_traj_meta_get(t1, "method") != NULL && strcmp(dm_traj_meta_get(t1, "reduce"),
                                                              "final,energy_error,min_distance,megno,fli,lyapunov") == 0,
         "t = t_end, status 0, metadata (reduce = %s)", dm_traj_meta_get(t1, "reduce"));
  tap_ok(cell(t1, "energy_error", 3) < 1e-7 && cell(t1, "energy_error", 3) > 0,
         "energy error of Gauss s=2 at h = 0.01: %.3g", cell(t1, "energy_error", 3));
  /* started at apocentre r0 = 0.5111: the pericentre is 2a - r0, with
   * 1/a = 2/r0 - v^2; sampled at every step the minimum is that within
   * O(h^2) */
  dm_traj_free(t2);
  every = 1;
  t2 = run_ens(I, DM_ENS_BIT(DM_ENS_MIN_DISTANCE), 4, 2, 400, &st0, &st, &e);
  every = 50;
  {
    double r0 = 0.5 + 3 * 0.0037, a = 1.0 / (2.0 / r0 - 1.69), dmin = cell(t2, "min_distance", 3);
    tap_ok(dmin >= 2 * a - r0 - 1e-9 && dmin < 2 * a - r0 + 2e-3,
           "min distance = pericentre 2a - r0 = %.6f (sampled: %.6f)", 2 * a - r0, dmin);
  }
  dm_traj_free(t2);
  dm_traj_free(t1);
  dm_traj_free(t3);
  dm_integrator_free(I);
  dm_system_release(&s);
}

/* A member is bitwise what dm_run computes from the same start with a fresh
 * integrator -- for every family that integrates Kepler, so resetting an
 * integrator between members forgets all its history. */
static void member_is_a_lone_run(void)
{
  dm_system s;
  starts st0 = {-1, -1, -1, 0, 0};
  size_t f;
  int tested = 0, bad = 0;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  for (f = 0; f < dm_integrator_count(); f++) {
    const dm_integrator_type *T = dm_integrator_type_at(f);
    const char *method = strcmp(T->name, "gsl") == 0 ? "gsl:rk8pd" : T->name;
    dm_integrator *I = NULL;
    dm_traj *tab;
    dm_err e;
    int st;
    long k;
    if (!dm_integrator_accepts(T, NULL) || dm_integrator_new(&s, method, NULL, &I, NULL) != DM_OK)
      continue;
    tab = run_ens(I, DM_ENS_BIT(DM_ENS_FINAL), 6, 1, 120, &st0, &st, &e);
    for (k = 0; tab != NULL && k < 6; k++) {
      double q[2], p[2];
      dm_run_opts o;
      dm_run_result res;
      dm_integrator *J = NULL;
      dm_traj *tr;
      dm_integrator_new(&s, method, NULL, &J, NULL);
      kepler_start(&st0, k, q, p, NULL, NULL);
      dm_run_opts_init(&o);
      o.h = 0.01;
      o.nsteps = 120;
      o.every = 50;
      tr = dm_run_traj_alloc(J, NULL);
      dm_run(J, q, p, &o, tr, &res, NULL);
      if (q[0] != cell(tab, "x", k) || q[1] != cell(tab, "y", k) || p[0] != cell(tab, "p_x", k)
          || p[1] != cell(tab, "p_y", k)) {
        tap_diag("%s member %ld: %.17g vs %.17g", method, k, q[0], cell(tab, "x", k));
        bad++;
      }
      dm_traj_free(tr);
      dm_integrator_free(J);
    }
    tested += tab != NULL;
    dm_traj_free(tab);
    dm_integrator_free(I);
  }
  tap_ok(tested >= 6 && bad == 0, "%d families: every member equals a lone dm_run bitwise "
         "(%d differ)", tested, bad);
  dm_system_release(&s);
}

static int harmonic_start(void *ctx, long k, double *q, double *p, double *par, dm_err *e)
{
  starts *s = ctx;
  (void)e;
  q[0] = 0.3 + 0.1 * (double)k;
  p[0] = 0.2;
  if (par != NULL && s->with_par)
    par[0] = s->omega0 + 0.25 * (double)k;     /* the mass m */
  return DM_OK;
}

/* Known limits: <Y> -> 2 for the shear of Kepler orbits, -> 0 for the
 * isochronous oscillator; FLI ~ ln t and a vanishing Lyapunov estimate. */
static void indicators(void)
{
  dm_system s;
  dm_integrator *I;
  starts st0 = {-1, -1, -1, 0, 0};
  dm_ens_opts o;
  dm_traj *t = NULL;
  dm_err e;
  int st;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  t = run_ens(I, DM_ENS_VARIATIONAL, 2, 2, 20000, &st0, &st, &e);
  tap_near(cell(t, "megno", 0), 2.0, 0.05, "MEGNO of a Kepler orbit (t = 200) -> 2: %.4f",
           cell(t, "megno", 0));
  tap_ok(fabs(cell(t, "lyapunov", 0)) < 0.05, "finite-time Lyapunov exponent ~ ln(t)/t: %.3g",
         cell(t, "lyapunov", 0));
  {
    /* shear: |d| grows linearly, so doubling t adds ln 2 to the FLI */
    dm_traj *half = run_ens(I, DM_ENS_VARIATIONAL, 2, 2, 10000, &st0, &st, &e);
    double g = cell(t, "fli", 0) - cell(half, "fli", 0);
    tap_near(g, log(2.0), 0.03, "FLI(200) - FLI(100) = ln 2 for a Kepler orbit: %.4f", g);
    dm_traj_free(half);
  }
  dm_traj_free(t);
  dm_integrator_free(I);
  dm_system_release(&s);

  dm_builtin_harmonic(&s, 1.0, 1.7, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  dm_ens_opts_init(&o);
  o.members = 3;
  o.threads = 2;
  o.run.h = 0.05;
  o.run.nsteps = 4000;
  o.reduce = DM_ENS_VARIATIONAL;
  o.start = harmonic_start;
  o.start_ctx = &st0;
  st = dm_ensemble_run(I, &o, &t, NULL, &e);
  tap_ok(st == DM_OK && fabs(cell(t, "megno", 1)) < 0.02 && cell(t, "fli", 1) < 1.5,
         "oscillator (isochronous): MEGNO -> 0 (%.4f), FLI bounded (%.3f)", cell(t, "megno", 1),
         cell(t, "fli", 1));
  dm_traj_free(t);

  /* parameter sweep: member k has the mass m = 0.9 + 0.25 k (the mass
   * matrix follows), as a lone run on the system with that m */
  st0.with_par = 1;
  st0.omega0 = 0.9;
  o.params = 1;
  o.reduce = DM_ENS_BIT(DM_ENS_FINAL);
  o.run.nsteps = 300;
  st = dm_ensemble_run(I, &o, &t, NULL, &e);
  {
    int ok = st == DM_OK;
    long k;
    for (k = 0; ok && k < 3; k++) {
      dm_system s2;
      dm_integrator *J;
      double q, p, par;
      long done;
      dm_builtin_harmonic(&s2, 0.9 + 0.25 * (double)k, 1.7, NULL);
      dm_integrator_new(&s2, "gauss", NULL, &J, NULL);
      harmonic_start(&st0, k, &q, &p, &par, NULL);
      dm_integrator_advance(J, 0.05, 300, &q, &p, &done, NULL);
      ok = q == cell(t, "x", k) && p == cell(t, "p_x", k);
      dm_integrator_free(J);
      dm_system_release(&s2);
    }
    tap_ok(ok, "parameter sweep: each member is the run on its own mass (bitwise): %s",
           st ? e.msg : "ok");
    tap_ok(s.par[0] == 1.0 && s.mass[0] == 1.0, "the template system's parameter and mass are "
           "untouched");
  }
  dm_traj_free(t);
  dm_integrator_free(I);
  dm_system_release(&s);
}

static void failures_and_interrupts(void)
{
  dm_system s;
  dm_integrator *I;
  starts bad = {4, -1, -1, 0, 0}, good = {-1, -1, -1, 0, 0};
  dm_traj *tb, *tg;
  dm_err e;
  int st;
  size_t j;
  long k, same = 1;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  tb = run_ens(I, DM_ENS_BIT(DM_ENS_FINAL) | DM_ENS_BIT(DM_ENS_MEGNO), 9, 2, 300, &bad, &st, &e);
  tg = run_ens(I, DM_ENS_BIT(DM_ENS_FINAL) | DM_ENS_BIT(DM_ENS_MEGNO), 9, 2, 300, &good, &st, &e);
  tap_ok(tb != NULL && cell(tb, "status", 4) != 0 && cell(tb, "t", 4) < 3.0,
         "member 4 (falls into the centre) fails: status %g at t = %g", cell(tb, "status", 4),
         cell(tb, "t", 4));
  {
    const char *m = dm_traj_meta_get(tb, "failure.4");
    tap_ok(m != NULL && strncmp(m, "member 4: step ", 15) == 0 && strstr(m, "failed") != NULL,
           "its message names it: %s", m ? m : "(none)");
  }
  for (k = 0; k < 9; k++)
    for (j = 0; k != 4 && j < dm_traj_ncols(tb); j++)
      same &= dm_traj_col(tb, j)[k] == dm_traj_col(tg, j)[k];
  tap_ok(same && cell(tb, "failed", 0) != cell(tb, "failed", 0) /* no such column */
         && dm_traj_meta_get(tb, "failed") != NULL && strcmp(dm_traj_meta_get(tb, "failed"), "1") == 0,
         "the other 8 members are unchanged; failed = 1");
  dm_traj_free(tb);
  dm_traj_free(tg);

  /* Ctrl-C while member 12's start is asked for: members of the finished
   * batches (0-9) are kept, the rest are NaN with status DM_EINTR */
  {
    starts intr = {-1, 12, -1, 0, 0};
    tb = run_ens(I, DM_ENS_BIT(DM_ENS_FINAL), 20, 2, 100, &intr, &st, &e);
    tap_ok(st == DM_EINTR && tb != NULL && dm_traj_len(tb) == 20 && cell(tb, "status", 9) == 0
           && cell(tb, "status", 10) == DM_EINTR && isnan(cell(tb, "x", 15)),
           "Ctrl-C keeps the finished members (%s)", e.msg);
    tap_ok(strstr(e.msg, "10 of 20 members finished") != NULL, "message: %s", e.msg);
    dm_interrupt_clear();
    dm_traj_free(tb);
  }
  /* a callback error ends the call without a table */
  {
    starts fail = {-1, -1, 7, 0, 0};
    tb = run_ens(I, DM_ENS_BIT(DM_ENS_FINAL), 20, 2, 100, &fail, &st, &e);
    tap_ok(st == DM_ECALLBACK && tb == NULL && strcmp(e.msg, "no start for member 7") == 0,
           "a start callback's error is returned: %s", e.msg);
  }
  dm_integrator_free(I);
  dm_system_release(&s);
}

static void errors(void)
{
  dm_system s;
  dm_integrator *I;
  dm_ens_opts o;
  dm_traj *t = NULL;
  starts st0 = {-1, -1, -1, 0, 0};
  dm_err e;
  int st;
  dm_builtin_spherical_pendulum_r3(&s, 9.81, 1.0, 1.0, 0, NULL);
  dm_integrator_new(&s, "trapezoid", NULL, &I, NULL);
  dm_ens_opts_init(&o);
  o.members = 2;
  o.run.h = 0.01;
  o.run.nsteps = 3;
  o.start = kepler_start;
  o.start_ctx = &st0;
  o.reduce = DM_ENS_BIT(DM_ENS_MEGNO);
  st = dm_ensemble_run(I, &o, &t, NULL, &e);
  tap_ok(st == DM_EUNSUP && t == NULL && strstr(e.msg, "constrained systems") != NULL,
         "MEGNO of a constrained system: %s", e.msg);
  o.members = 0;
  st = dm_ensemble_run(I, &o, &t, NULL, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "need members >= 1 (got 0)") == 0, "%s", e.msg);
  o.members = 4611686018427387904L;
  st = dm_ensemble_run(I, &o, &t, NULL, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "need members <= 1000000000000 (got 4611686018427387904)"),
         "%s", e.msg);
  o.members = 2;
  o.reduce = 0;
  o.run.every = 0;
  st = dm_ensemble_run(I, &o, &t, NULL, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "need every >= 1 (got 0)") == 0, "%s", e.msg);
  dm_integrator_free(I);
  dm_system_release(&s);
}

static int cmp_ul(const void *a, const void *b)
{
  unsigned long x = *(const unsigned long *)a, y = *(const unsigned long *)b;
  return (x > y) - (x < y);
}

static void seeds(void)
{
  enum { K = 200000 };
  unsigned long *x = malloc(K * sizeof *x);
  long k, dup = 0, big = 0, diff = 0;
  for (k = 0; k < K; k++) {
    x[k] = dm_ens_seed(2385, k);
    big += x[k] > 0xffffffffUL;
    diff += dm_ens_seed(2386, k) != x[k];
  }
  qsort(x, K, sizeof *x, cmp_ul);
  for (k = 1; k < K; k++)
    dup += x[k] == x[k - 1];
  tap_ok(dup == 0 && big == 0, "200000 members get distinct 32-bit seeds (%ld repeats)", dup);
  tap_ok(diff > K - 10 && dm_ens_seed(2385, 17) == dm_ens_seed(2385, 17),
         "another seed gives other member seeds; the same gives the same");
  free(x);
}

int main(void)
{
  dm_gsl_init();
  threads_do_not_matter();
  member_is_a_lone_run();
  indicators();
  failures_and_interrupts();
  errors();
  seeds();
  return tap_done();
}
