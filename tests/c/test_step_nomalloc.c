/* test_step_nomalloc.c -- "no malloc inside a time step", checked: this
 * program defines malloc, calloc, realloc and free itself (forwarding to the
 * C library's through dlsym(RTLD_NEXT)), so every allocation in the process
 * -- dmech's, GSL's, libc's -- goes through a counter.  After one warm-up
 * step, steps and runs of every integrator family (implicit PRK with and
 * without simplified Newton, constraints, forces, explicit Stormer-Verlet
 * and RATTLE, compositions, rk4, traced tape systems, the reduced RSPRK)
 * must allocate nothing.  Allocation at setup is counted too, as a sanity
 * check that the counter works.
 *
 * Also: the explicit Stormer-Verlet path for the three mass structures it
 * specialises (unit, diagonal, full M) against the linear map of the method
 * on a harmonic system, and against the implicit Lobatto IIIA-IIIB s=2
 * engine (the same method by Newton).
 *
 * Needs glibc >= 2.34 (dlsym in libc); elsewhere the counting part skips. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_vector.h>

#include "core/status.h"
#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "core/builtin_systems.h"
#include "core/smalllu.h"
#include "integrators/integrator.h"
#include "reduce/routh.h"
#include "reduce_systems.h"
#include "tap.h"

#if defined(__linux__) && defined(__GLIBC__) && defined(__GLIBC_PREREQ)
#if __GLIBC_PREREQ(2, 34)
#define DM_COUNT_MALLOC 1
#endif
#endif

/* {==== the counting allocator =========================================== */

#ifdef DM_COUNT_MALLOC
#include <dlfcn.h>

static void *(*next_malloc)(size_t);
static void *(*next_calloc)(size_t, size_t);
static void *(*next_realloc)(void *, size_t);
static void (*next_free)(void *);
static long n_alloc;
static int counting, resolving;
/* dlsym may calloc before the real calloc is known: serve it from here */
static _Alignas(16) char boot[4096];
static size_t boot_used;

static void *boot_alloc(size_t n)
{
  void *p;
  n = (n + 15) & ~(size_t)15;
  if (boot_used + n > sizeof boot)
    return NULL;
  p = boot + boot_used;
  boot_used += n;
  return p;                       /* static storage: already zero */
}

static void resolve(void)
{
  resolving = 1;
  *(void **)&next_malloc = dlsym(RTLD_NEXT, "malloc");
  *(void **)&next_calloc = dlsym(RTLD_NEXT, "calloc");
  *(void **)&next_realloc = dlsym(RTLD_NEXT, "realloc");
  *(void **)&next_free = dlsym(RTLD_NEXT, "free");
  resolving = 0;
}

void *malloc(size_t n)
{
  if (next_malloc == NULL) {
    if (resolving)
      return boot_alloc(n);
    resolve();
  }
  n_alloc += counting;
  return next_malloc(n);
}

void *calloc(size_t a, size_t b)
{
  if (next_calloc == NULL) {
    if (resolving)
      return b && a > (size_t)-1 / b ? NULL : boot_alloc(a * b);
    resolve();
  }
  n_alloc += counting;
  return next_calloc(a, b);
}

void *realloc(void *p, size_t n)
{
  if (next_realloc == NULL)
    resolve();
  n_alloc += counting;
  return next_realloc(p, n);
}

void free(void *p)
{
  if ((char *)p >= boot && (char *)p < boot + sizeof boot)
    return;
  if (next_free == NULL)
    resolve();
  next_free(p);
}
#endif

static void count_begin(void)
{
#ifdef DM_COUNT_MALLOC
  n_alloc = 0;
  counting = 1;
#endif
}

static long count_end(void)
{
#ifdef DM_COUNT_MALLOC
  counting = 0;
  return n_alloc;
#else
  return 0;
#endif
}

/* }======================================================================= */

/* One integrator: a warm-up step, then K steps, then a run of K steps, each
 * counted; the run path of the explicit methods differs from the step path. */
static void check_steps(const char *label, const dm_system *sys, const char *method, int stages,
                        int simplified, double h, const double *q0, const double *p0)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  double q[16], p[16];
  size_t n = sys->n;
  long k, na, nb;
  int st = DM_OK;
  dm_integ_opts_init(&o);
  o.stages = stages;
  o.simplified = simplified;
  count_begin();
  if (dm_integrator_new(sys, method, &o, &I, &e) != DM_OK) {
    count_end();
    tap_ok(0, "%s: %s", label, e.msg);
    return;
  }
  na = count_end();
  memcpy(q, q0, n * sizeof(double));
  memcpy(p, p0, n * sizeof(double));
  st = dm_integrator_step(I, h, q, p, q, p, &e);
  count_begin();
  for (k = 0; k < 50 && st == DM_OK; k++)
    st = dm_integrator_step(I, h, q, p, q, p, &e);
  nb = count_end();
  tap_ok(st == DM_OK, "%s: 50 steps %s", label, st == DM_OK ? "done" : e.msg);
  tap_is_int(nb, 0, "%s: no allocation in 50 steps (setup: %ld)", label, na);
  count_begin();
  st = dm_integrator_run(I, 0.0, q, p, h, 50, 50, NULL, NULL, NULL, &e);
  nb = count_end();
  tap_ok(st == DM_OK, "%s: run of 50 steps %s", label, st == DM_OK ? "done" : e.msg);
  tap_is_int(nb, 0, "%s: no allocation in a run of 50 steps", label);
  dm_integrator_free(I);
}

static void test_builtin(void)
{
  dm_system j2, kep, sph, damp;
  const double qj[3] = {2.0, 0.0, 0.3}, pj[3] = {0.0, 0.6, 0.1};
  const double qk[2] = {0.4, 0.0}, pk[2] = {0.0, 2.0};
  const double qs[3] = {0.6, 0.0, -0.8}, ps[3] = {0.0, 1.2, 0.0};
  const double qd[1] = {2.385}, pd[1] = {0.0};
  dm_builtin_j2(&j2, 0.05, NULL);
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_builtin_spherical_pendulum_r3(&sph, 9.81, 1.0, 1.0, 0, NULL);
  dm_builtin_damped_oscillator(&damp, 1.0, 2.385, 0.1, NULL);
  check_steps("J2 Gauss 2", &j2, "gauss", 2, 1, 0.05, qj, pj);
  check_steps("J2 Gauss 3, full Newton", &j2, "gauss", 3, 0, 0.05, qj, pj);
  check_steps("Kepler Lobatto 3", &kep, "lobatto", 3, 1, 0.01, qk, pk);
  check_steps("Kepler Stormer-Verlet", &kep, "trapezoid", 0, 1, 0.01, qk, pk);
  check_steps("Kepler composition (default scheme)", &kep, "composition", 0, 1, 0.01, qk, pk);
  check_steps("Kepler rk4", &kep, "rk4", 0, 1, 0.01, qk, pk);
  check_steps("spherical pendulum RATTLE", &sph, "trapezoid", 0, 1, 0.01, qs, ps);
  check_steps("spherical pendulum midpoint + constraint", &sph, "midpoint", 0, 1, 0.01, qs, ps);
  check_steps("spherical pendulum Lobatto 3 + constraint", &sph, "lobatto", 3, 1, 0.01, qs, ps);
  check_steps("damped oscillator Gauss 2 (force)", &damp, "gauss", 2, 1, 0.05, qd, pd);
  dm_system_release(&j2);
  dm_system_release(&kep);
  dm_system_release(&sph);
  dm_system_release(&damp);
}

/* A chain of 9 anharmonic oscillators, L = |v|^2/2 - sum (k q_i^2/2 +
 * q_i^4/4) - c sum q_i q_{i+1}: Gauss 4 on it has 36 unknowns (above the
 * small LU's former limit of 32, where GSL allocated per factorisation). */
static int chain_lag(void *data, const double *q, const double *v, const double *par,
                     unsigned what, dm_lag_out *o, void *work)
{
  const double k = 2.385, c = 0.3;
  size_t i, j;
  (void)data;
  (void)par;
  (void)work;
  if (what & DM_LAG_L) {
    o->L = 0.0;
    for (i = 0; i < 9; i++)
      o->L += 0.5 * v[i] * v[i] - 0.5 * k * q[i] * q[i] - 0.25 * q[i] * q[i] * q[i] * q[i]
              - (i + 1 < 9 ? c * q[i] * q[i + 1] : 0.0);
  }
  for (i = 0; i < 9; i++) {
    if (what & DM_LAG_Q)
      o->Lq[i] = -k * q[i] - q[i] * q[i] * q[i] - (i > 0 ? c * q[i - 1] : 0.0)
                 - (i + 1 < 9 ? c * q[i + 1] : 0.0);
    if (what & DM_LAG_V)
      o->Lv[i] = v[i];
    for (j = 0; j < 9; j++) {
      if (what & DM_LAG_VV)
        o->Lvv[i * 9 + j] = i == j ? 1.0 : 0.0;
      if (what & DM_LAG_VQ)
        o->Lvq[i * 9 + j] = 0.0;
      if (what & DM_LAG_QQ)
        o->Lqq[i * 9 + j] = i == j ? -k - 3.0 * q[i] * q[i]
                            : (i == j + 1 || j == i + 1) ? -c : 0.0;
    }
  }
  return 0;
}

static void test_chain(void)
{
  static const double M[81] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0,
                               0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0,
                               0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0,
                               0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
  const double q0[9] = {0.7, -0.3, 0.2, 0.5, -0.6, 0.1, 0.4, -0.2, 0.3};
  const double p0[9] = {0.2, 0.1, -0.4, 0.3, 0.0, -0.1, 0.25, 0.15, -0.3};
  dm_system sys;
  memset(&sys, 0, sizeof sys);
  sys.name = "oscillator chain";
  sys.n = 9;
  sys.flags = DM_SYS_SEPARABLE | DM_SYS_MECHANICAL;
  sys.mass = M;
  sys.lagrangian = chain_lag;
  check_steps("9-oscillator chain Gauss 4 (36 unknowns)", &sys, "gauss", 4, 1, 0.05, q0, p0);
  check_steps("9-oscillator chain Gauss 8 (72 unknowns), full Newton", &sys, "gauss", 8, 0, 0.1,
              q0, p0);
}

/* J2 traced from expressions, evaluated by the tape */
static void test_traced(void)
{
  static const char *qn[] = {"x", "y", "z"}, *vn[] = {"vx", "vy", "vz"};
  const double qj[3] = {2.0, 0.0, 0.3}, pj[3] = {0.0, 0.6, 0.1}, J2 = 0.05;
  dm_expr_ctx *c = dm_expr_ctx_alloc();
  dm_expr q[3], v[3], par, T, R2, R, V;
  dm_lagrangian_spec sp;
  dm_system sys;
  dm_err e;
  size_t i;
  for (i = 0; i < 3; i++) {
    q[i] = dm_expr_sym(c, qn[i]);
    v[i] = dm_expr_sym(c, vn[i]);
  }
  par = dm_expr_param(c, "J2");
  T = dm_expr_const(c, 0.0);
  R2 = dm_expr_const(c, 0.0);
  for (i = 0; i < 3; i++) {
    T = dm_expr_add(c, T, dm_expr_powi(c, v[i], 2));
    R2 = dm_expr_add(c, R2, dm_expr_powi(c, q[i], 2));
  }
  R = dm_expr_call(c, "sqrt", 1, &R2);
  /* V = -1/R + J2/R^3 (1.5 z^2/R^2 - 0.5) */
  V = dm_expr_add(c, dm_expr_div(c, dm_expr_const(c, -1.0), R),
                  dm_expr_mul(c, dm_expr_div(c, par, dm_expr_powi(c, R, 3)),
                              dm_expr_sub(c, dm_expr_div(c, dm_expr_mul(c, dm_expr_const(c, 1.5),
                                                                        dm_expr_powi(c, q[2], 2)),
                                                         R2),
                                          dm_expr_const(c, 0.5))));
  memset(&sp, 0, sizeof sp);
  sp.name = "J2 (traced)";
  sp.n = 3;
  sp.q = q;
  sp.v = v;
  sp.npar = 1;
  sp.par = &par;
  sp.par_values = &J2;
  sp.L = dm_expr_sub(c, dm_expr_mul(c, dm_expr_const(c, 0.5), T), V);
  sp.native = DM_NATIVE_NEVER;
  if (dm_lagrangian_compile(c, &sp, &sys, &e) != DM_OK) {
    tap_ok(0, "traced J2: %s", e.msg);
    dm_expr_ctx_free(c);
    return;
  }
  check_steps("traced J2 (tape) Gauss 2", &sys, "gauss", 2, 1, 0.05, qj, pj);
  check_steps("traced J2 (tape) Stormer-Verlet", &sys, "trapezoid", 0, 1, 0.01, qj, pj);
  dm_system_release(&sys);
  dm_expr_ctx_free(c);
}

/* the reduced double spherical pendulum (RSPRK on the shape space) */
static void test_reduced(void)
{
  static const double pv[5] = {1.0, 2.385, 1.0, 0.8, 9.81};
  static const double Q0[4] = {0.5, 0.0, 0.4, 0.7}, V0[4] = {0.1, 1.3, -0.2, 0.4};
  rsys S;
  dm_routh *red = NULL;
  dm_integrator *I = NULL;
  dm_integ_opts o;
  dm_err e;
  size_t cyc = 1;
  double x[3], s[3], mu;
  long k, nb;
  int st;
  rs_dsp(&S, pv, 0);
  if (rs_reduce(&S, 1, &cyc, NULL, &red, &e) != DM_OK) {
    tap_ok(0, "reduction: %s", e.msg);
    dm_expr_ctx_free(S.c);
    return;
  }
  dm_routh_project_qv(red, Q0, V0, x, s, &mu, NULL, NULL);
  dm_routh_set_mu(red, &mu, NULL);
  for (int lob = 0; lob <= 1; lob++) {
    const char *label = lob ? "RSPRK Lobatto 3" : "RSPRK Gauss 2";
    dm_integ_opts_init(&o);
    o.stages = lob ? 3 : 2;
    if (dm_routh_integrator_new(red, lob ? "lobatto" : "gauss", &o, &I, &e) != DM_OK) {
      tap_ok(0, "%s: %s", label, e.msg);
      continue;
    }
    st = dm_integrator_step(I, 0.01, x, s, x, s, &e);
    count_begin();
    for (k = 0; k < 50 && st == DM_OK; k++)
      st = dm_integrator_step(I, 0.01, x, s, x, s, &e);
    if (st == DM_OK)
      st = dm_integrator_run(I, 0.0, x, s, 0.01, 50, 50, NULL, NULL, NULL, &e);
    nb = count_end();
    tap_ok(st == DM_OK, "%s: 50 steps and a run of 50 %s", label, st == DM_OK ? "done" : e.msg);
    tap_is_int(nb, 0, "%s: no allocation in 100 steps", label);
    dm_integrator_free(I);
  }
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

static void test_counter_works(void)
{
#ifdef DM_COUNT_MALLOC
  double a[36], b[6];
  size_t perm[40];
  gsl_vector *x;
  long na;
  count_begin();
  x = gsl_vector_alloc(3);       /* in libgsl: interposition reaches shared libraries */
  gsl_vector_free(x);
  na = count_end();
  tap_ok(na >= 1, "the counter sees GSL's allocations (%ld in gsl_vector_alloc)", na);
  for (int i = 0; i < 36; i++)
    a[i] = (i % 7 == 0) ? 2.385 * 6 : 1.0 / (double)(i + 2);
  for (int i = 0; i < 6; i++)
    b[i] = 2.385 - i;
  count_begin();
  dm_smalllu_factor(a, 6, perm);
  dm_smalllu_solve(a, 6, perm, b);
  tap_is_int(count_end(), 0, "smalllu 6x6: factor + solve allocate nothing");
#endif
}

/* {==== explicit Stormer-Verlet with unit, diagonal and full mass ========= */

typedef struct harm {
  double M[4], K[4];
} harm;

/* L = 1/2 v^T M v - 1/2 q^T K q, n = 2 */
static int harm_lag(void *data, const double *q, const double *v, const double *par,
                    unsigned what, dm_lag_out *o, void *work)
{
  const harm *H = data;
  size_t i, j;
  (void)par;
  (void)work;
  if (what & DM_LAG_L) {
    o->L = 0.0;
    for (i = 0; i < 2; i++)
      for (j = 0; j < 2; j++)
        o->L += 0.5 * (v[i] * H->M[i * 2 + j] * v[j] - q[i] * H->K[i * 2 + j] * q[j]);
  }
  for (i = 0; i < 2; i++) {
    if (what & DM_LAG_Q)
      o->Lq[i] = -(H->K[i * 2] * q[0] + H->K[i * 2 + 1] * q[1]);
    if (what & DM_LAG_V)
      o->Lv[i] = H->M[i * 2] * v[0] + H->M[i * 2 + 1] * v[1];
  }
  for (i = 0; i < 4; i++) {
    if (what & DM_LAG_VV)
      o->Lvv[i] = H->M[i];
    if (what & DM_LAG_VQ)
      o->Lvq[i] = 0.0;
    if (what & DM_LAG_QQ)
      o->Lqq[i] = -H->K[i];
  }
  return 0;
}

/* n steps of Stormer-Verlet in long double: the reference */
static void sv_exact(const harm *H, double h, int nsteps, const double *q0, const double *p0,
                     double *q1, double *p1)
{
  long double q[2] = {q0[0], q0[1]}, p[2] = {p0[0], p0[1]}, det, Mi[4];
  det = (long double)H->M[0] * H->M[3] - (long double)H->M[1] * H->M[2];
  Mi[0] = H->M[3] / det;
  Mi[1] = -H->M[1] / det;
  Mi[2] = -H->M[2] / det;
  Mi[3] = H->M[0] / det;
  for (int k = 0; k < nsteps; k++) {
    long double ph[2], u[2];
    for (int i = 0; i < 2; i++)
      ph[i] = p[i] - 0.5L * h * (H->K[i * 2] * q[0] + H->K[i * 2 + 1] * q[1]);
    for (int i = 0; i < 2; i++)
      u[i] = Mi[i * 2] * ph[0] + Mi[i * 2 + 1] * ph[1];
    for (int i = 0; i < 2; i++)
      q[i] += h * u[i];
    for (int i = 0; i < 2; i++)
      p[i] = ph[i] - 0.5L * h * (H->K[i * 2] * q[0] + H->K[i * 2 + 1] * q[1]);
  }
  q1[0] = (double)q[0];
  q1[1] = (double)q[1];
  p1[0] = (double)p[0];
  p1[1] = (double)p[1];
}

static void test_verlet_mass(void)
{
  static const harm cases[3] = {
    {{1.0, 0.0, 0.0, 1.0}, {2.385, 0.4, 0.4, 1.1}},
    {{2.385, 0.0, 0.0, 0.5}, {2.385, 0.4, 0.4, 1.1}},
    {{2.385, 0.3, 0.3, 1.2}, {2.385, 0.4, 0.4, 1.1}},
  };
  static const char *names[3] = {"unit", "diagonal", "full"};
  const double q0[2] = {0.7, -0.3}, p0[2] = {0.2, 0.9}, h = 0.05;
  for (int c = 0; c < 3; c++) {
    harm H = cases[c];
    dm_system sys;
    dm_integ_opts o;
    dm_integrator *Ie = NULL, *Ii = NULL;
    double qe[2], pe[2], qi[2], pi[2], qx[2], px[2], de = 0.0, di = 0.0;
    int flags;
    memset(&sys, 0, sizeof sys);
    sys.name = "harmonic 2-dof";
    sys.n = 2;
    sys.flags = DM_SYS_SEPARABLE | DM_SYS_MECHANICAL;
    sys.mass = H.M;
    sys.lagrangian = harm_lag;
    sys.data = &H;
    dm_integ_opts_init(&o);
    dm_integrator_new(&sys, "trapezoid", &o, &Ie, NULL);
    o.explicit_sv = 0;
    dm_integrator_new(&sys, "trapezoid", &o, &Ii, NULL);
    flags = Ie ? (int)Ie->flags : 0;
    tap_ok(Ie && Ii && (flags & DM_INTEG_EXPLICIT), "%s mass: explicit and implicit trapezoid",
           names[c]);
    if (!Ie || !Ii) {
      dm_integrator_free(Ie);
      dm_integrator_free(Ii);
      continue;
    }
    memcpy(qe, q0, sizeof qe);
    memcpy(pe, p0, sizeof pe);
    memcpy(qi, q0, sizeof qi);
    memcpy(pi, p0, sizeof pi);
    dm_integrator_run(Ie, 0.0, qe, pe, h, 400, 400, NULL, NULL, NULL, NULL);
    dm_integrator_run(Ii, 0.0, qi, pi, h, 400, 400, NULL, NULL, NULL, NULL);
    sv_exact(&H, h, 400, q0, p0, qx, px);
    for (int i = 0; i < 2; i++) {
      de = fmax(de, fmax(fabs(qe[i] - qx[i]), fabs(pe[i] - px[i])));
      di = fmax(di, fmax(fabs(qe[i] - qi[i]), fabs(pe[i] - pi[i])));
    }
    tap_ok(de <= 2e-14, "%s mass: 400 explicit steps = the method's linear map to %.2g",
           names[c], de);
    tap_ok(di <= 2e-13, "%s mass: explicit = implicit Lobatto IIIA-IIIB 2 to %.2g", names[c], di);
    /* the run loop's fast path (in chunks of 7 steps, then continued by
     * single steps) computes what single steps compute, bit for bit */
    {
      double qr[2], pr[2], qs[2], ps[2];
      memcpy(qr, q0, sizeof qr);
      memcpy(pr, p0, sizeof pr);
      memcpy(qs, q0, sizeof qs);
      memcpy(ps, p0, sizeof ps);
      dm_integrator_reset(Ie);
      dm_integrator_run(Ie, 0.0, qr, pr, h, 250, 7, NULL, NULL, NULL, NULL);
      for (int k = 0; k < 150; k++)
        dm_integrator_step(Ie, h, qr, pr, qr, pr, NULL);
      dm_integrator_reset(Ie);
      for (int k = 0; k < 400; k++)
        dm_integrator_step(Ie, h, qs, ps, qs, ps, NULL);
      tap_ok(memcmp(qr, qs, sizeof qr) == 0 && memcmp(pr, ps, sizeof pr) == 0,
             "%s mass: run in chunks of 7 + 150 steps = 400 single steps (bitwise)", names[c]);
    }
    /* compositions: the run loop's fused substeps = step() by step() */
    for (int sc = 0; sc < 2; sc++) {
      dm_integrator *Ic = NULL;
      dm_integ_opts oc;
      double qr[2], pr[2], qs[2], ps[2];
      dm_integ_opts_init(&oc);
      oc.order = sc ? 8 : 4;
      if (dm_integrator_new(&sys, "composition", &oc, &Ic, NULL) != DM_OK) {
        tap_ok(0, "%s mass: composition", names[c]);
        continue;
      }
      memcpy(qr, q0, sizeof qr);
      memcpy(pr, p0, sizeof pr);
      memcpy(qs, q0, sizeof qs);
      memcpy(ps, p0, sizeof ps);
      dm_integrator_run(Ic, 0.0, qr, pr, h, 100, 7, NULL, NULL, NULL, NULL);
      for (int k = 0; k < 20; k++)
        dm_integrator_step(Ic, h, qr, pr, qr, pr, NULL);
      dm_integrator_reset(Ic);
      for (int k = 0; k < 120; k++)
        dm_integrator_step(Ic, h, qs, ps, qs, ps, NULL);
      tap_ok(memcmp(qr, qs, sizeof qr) == 0 && memcmp(pr, ps, sizeof pr) == 0 &&
             Ic->stats.steps == 120, "%s mass: composition order %d, run in chunks of 7 + 20 "
             "steps = 120 single steps (bitwise)", names[c], oc.order);
      dm_integrator_free(Ic);
    }
    /* velocities of a separable system: v = M^{-1} p, whatever the guess,
     * with the mass of the moment (the system's parameters may change it) */
    {
      double v0[2], v1[2], r = 0.0, r2 = 0.0;
      dm_integrator_velocity(Ie, q0, p0, v0, 0, NULL);
      v1[0] = 100.0;
      v1[1] = -3.0;
      dm_integrator_velocity(Ie, q0, p0, v1, 1, NULL);
      for (int i = 0; i < 2; i++)
        r = fmax(r, fabs(H.M[i * 2] * v0[0] + H.M[i * 2 + 1] * v0[1] - p0[i]));
      tap_ok(r <= 4e-16 && memcmp(v0, v1, sizeof v0) == 0,
             "%s mass: velocity = M^-1 p (|M v - p| = %.2g), the same bits from any guess",
             names[c], r);
      H.M[0] *= 2.385;                /* the mass changed (as a parameter would) */
      count_begin();
      dm_integrator_velocity(Ie, q0, p0, v0, 1, NULL);
      long na2 = count_end();
      for (int i = 0; i < 2; i++)
        r2 = fmax(r2, fabs(H.M[i * 2] * v0[0] + H.M[i * 2 + 1] * v0[1] - p0[i]));
      tap_ok(r2 <= 1e-15 && na2 == 0, "%s mass: after the mass changed, velocity = the new "
             "M^-1 p (|M v - p| = %.2g), refactored without allocating", names[c], r2);
      H.M[0] /= 2.385;
    }
    dm_integrator_free(Ie);
    dm_integrator_free(Ii);
  }
}

/* A composition whose force fails in the middle of a step: the run stops
 * there and keeps the state after the last whole step. */
typedef struct failing {
  harm H;
  long calls, fail_at;
} failing;

static int failing_lag(void *data, const double *q, const double *v, const double *par,
                       unsigned what, dm_lag_out *o, void *work)
{
  failing *F = data;
  if (++F->calls == F->fail_at)
    return 1;
  return harm_lag(&F->H, q, v, par, what, o, work);
}

static void test_comp_failure(void)
{
  failing F = {{{2.385, 0.3, 0.3, 1.2}, {2.385, 0.4, 0.4, 1.1}}, 0, 0};
  const double q0[2] = {0.7, -0.3}, p0[2] = {0.2, 0.9}, h = 0.05;
  double q[2], p[2], qs[2], ps[2];
  dm_system sys;
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_run_info info;
  dm_err e;
  int st;
  memset(&sys, 0, sizeof sys);
  sys.name = "harmonic 2-dof, failing";
  sys.n = 2;
  sys.flags = DM_SYS_SEPARABLE | DM_SYS_MECHANICAL;
  sys.mass = F.H.M;
  sys.lagrangian = failing_lag;
  sys.data = &F;
  dm_integ_opts_init(&o);
  o.order = 4;
  dm_integrator_new(&sys, "composition", &o, &I, NULL);
  memcpy(q, q0, sizeof q);
  memcpy(p, p0, sizeof p);
  F.fail_at = 1 + 10 * 3 + 2;       /* the initial force, 10 steps, 2 substeps into step 11 */
  st = dm_integrator_run(I, 0.0, q, p, h, 50, 50, NULL, NULL, &info, &e);
  dm_integrator_reset(I);
  F.fail_at = 0;
  memcpy(qs, q0, sizeof qs);
  memcpy(ps, p0, sizeof ps);
  for (int k = 0; k < 10; k++)
    dm_integrator_step(I, h, qs, ps, qs, ps, NULL);
  tap_ok(st == DM_EDOM && info.steps == 10 && memcmp(q, qs, sizeof q) == 0 &&
         memcmp(p, ps, sizeof p) == 0, "composition: a force failing inside step 11 stops the "
         "run after 10 steps, with their state (status %d, %ld steps)", st, info.steps);
  dm_integrator_free(I);
}

/* }======================================================================= */

int main(void)
{
  dm_gsl_init();
#ifndef DM_COUNT_MALLOC
  tap_diag("allocation counting needs glibc >= 2.34 on Linux: counts read 0");
#endif
  test_counter_works();
  test_builtin();
  test_chain();
  test_traced();
  test_reduced();
  test_verlet_mass();
  test_comp_failure();
  return tap_done();
}
