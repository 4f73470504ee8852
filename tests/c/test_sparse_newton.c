/* test_sparse_newton.c -- the PRK engine's Newton matrices solved dense
 * (LU) and sparse (KLU, prk_sparse.c) give the same states to round-off on
 * every kind of system: unconstrained (gyroscopic, not separable),
 * separable, forced (Lagrange-d'Alembert), constrained (Lobatto with
 * multipliers), a system without a pattern (built-in C), in both layouts
 * of the derivatives (dense arrays gathered, values on the pattern); the
 * step Jacobians agree too; the automatic choice and the option's error.
 * The fixed-point iteration of separable systems (option iteration) gives
 * Newton's states too, hands over to Newton when it contracts slowly,
 * and is refused where it does not apply. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "core/builtin_systems.h"
#include "core/sparse.h"
#include "core/status.h"
#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "integrators/integrator.h"
#include "tap.h"

#define NMAX 48
static dm_expr_ctx *C;

/* A chain of n masses: springs with a quartic term, fixed ends; kinds:
 * 0 gyroscopic (0.2 v_i sin(q_{i+1}) terms), 1 separable, 2 forced
 * (damping -c v_i q_i^2 on every other mass), 3 constrained (a planar
 * pendulum of n/2 bobs at unit distances, Cartesian: g_k = |x_k -
 * x_{k-1}|^2 - 1). */
static int make_system(int kind, size_t n, int layout, dm_system *s)
{
  dm_expr q[NMAX], v[NMAX], par[2], F[NMAX], g[NMAX];
  char nm[32];
  static int tag;
  tag++;
  for (size_t i = 0; i < n; i++) {
    snprintf(nm, sizeof nm, "x%zu_%d", i, tag);
    q[i] = dm_expr_sym(C, nm);
    snprintf(nm, sizeof nm, "v%zu_%d", i, tag);
    v[i] = dm_expr_sym(C, nm);
  }
  par[0] = dm_expr_param(C, "beta");
  par[1] = dm_expr_param(C, "c");
  double pv[2] = { 0.8, 0.3 };
  dm_expr L = dm_expr_const(C, 0.0), half = dm_expr_const(C, 0.5);
  size_t m = 0;
  if (kind == 3) {                        /* bobs (x, y), gravity along -y */
    for (size_t b = 0; 2 * b < n; b++) {
      dm_expr x = q[2 * b], y = q[2 * b + 1];
      L = dm_expr_add(C, L, dm_expr_mul(C, half, dm_expr_add(C, dm_expr_powi(C, v[2 * b], 2),
                                                            dm_expr_powi(C, v[2 * b + 1], 2))));
      L = dm_expr_sub(C, L, dm_expr_mul(C, dm_expr_const(C, 9.81), y));
      dm_expr dx = b ? dm_expr_sub(C, x, q[2 * b - 2]) : x;
      dm_expr dy = b ? dm_expr_sub(C, y, q[2 * b - 1]) : y;
      g[m++] = dm_expr_sub(C, dm_expr_add(C, dm_expr_powi(C, dx, 2), dm_expr_powi(C, dy, 2)),
                           dm_expr_const(C, 1.0));
    }
  } else {
    dm_expr prev = dm_expr_const(C, 0.0);
    for (size_t i = 0; i <= n; i++) {
      dm_expr d = i < n ? dm_expr_sub(C, q[i], prev) : dm_expr_neg(C, prev);
      L = dm_expr_sub(C, L, dm_expr_add(C, dm_expr_mul(C, half, dm_expr_powi(C, d, 2)),
                                        dm_expr_mul(C, par[0], dm_expr_powi(C, d, 4))));
      if (i < n) {
        L = dm_expr_add(C, L, dm_expr_mul(C, dm_expr_const(C, 0.5 + 0.1 * (double)(i % 3)),
                                          dm_expr_powi(C, v[i], 2)));
        if (kind == 0 && i + 1 < n)
          L = dm_expr_add(C, L, dm_expr_mul(C, dm_expr_const(C, 0.2),
                                            dm_expr_mul(C, v[i], dm_expr_unary(C, DM_EXPR_SIN,
                                                                               q[i + 1]))));
        prev = q[i];
      }
    }
    for (size_t i = 0; i < n; i++)
      F[i] = i % 2 ? dm_expr_mul(C, dm_expr_neg(C, par[1]),
                                 dm_expr_mul(C, v[i], dm_expr_powi(C, q[i], 2)))
                   : dm_expr_const(C, 0.0);
  }
  dm_lagrangian_spec sp = { .name = "chain", .n = n, .q = q, .v = v, .npar = 2, .par = par,
    .par_values = pv, .L = L, .force = kind == 2 ? F : NULL, .m = m,
    .constraints = m ? g : NULL, .native = DM_NATIVE_NEVER, .layout = layout };
  dm_err e;
  int st = dm_lagrangian_compile(C, &sp, s, &e);
  if (st != DM_OK)
    tap_diag("compile: %s", e.msg);
  return st;
}

static void start(int kind, size_t n, double *q, double *v)
{
  for (size_t i = 0; i < n; i++) {
    q[i] = 0.3 * sin(2.385 * (double)(i + 1));
    v[i] = 0.2 * cos(1.7 * (double)(i + 1));
  }
  if (kind == 3)                    /* on the constraints, velocities tangent */
    for (size_t b = 0; 2 * b < n; b++) {
      double a = 0.4 + 0.1 * (double)b, w = 0.3 - 0.05 * (double)b;
      double x0 = b ? q[2 * b - 2] : 0.0, y0 = b ? q[2 * b - 1] : 0.0;
      double vx0 = b ? v[2 * b - 2] : 0.0, vy0 = b ? v[2 * b - 1] : 0.0;
      q[2 * b] = x0 + sin(a);
      q[2 * b + 1] = y0 - cos(a);
      v[2 * b] = vx0 + w * cos(a);
      v[2 * b + 1] = vy0 + w * sin(a);
    }
}

static int run_it(const dm_system *s, const char *method, int stages, const char *mode,
                  const char *iteration, double h, int nsteps, double *out, int *linear,
                  long *fixed);

/* nsteps steps with linear = mode (Newton throughout: the linear solves
 * are what is compared); the end state (q, p) into out. */
static int run(const dm_system *s, const char *method, int stages, const char *mode,
               int nsteps, double *out, int *linear)
{
  return run_it(s, method, stages, mode, "newton", 0.02, nsteps, out, linear, NULL);
}

static int run_it(const dm_system *s, const char *method, int stages, const char *mode,
                  const char *iteration, double h, int nsteps, double *out, int *linear,
                  long *fixed)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  size_t n = s->n;
  int kind = s->m ? 3 : 0;
  dm_integ_opts_init(&o);
  o.stages = stages;
  o.explicit_sv = 0;
  snprintf(o.linear, sizeof o.linear, "%s", mode);
  snprintf(o.iteration, sizeof o.iteration, "%s", iteration);
  if (dm_integrator_new(s, method, &o, &I, &e) != DM_OK) {
    tap_diag("%s: %s", method, e.msg);
    return -1;
  }
  double q[NMAX], v[NMAX], p[NMAX];
  start(kind, n, q, v);
  if (s->pattern == NULL) {         /* the built-in Kepler problem: an orbit */
    static const double q0[3] = { 0.4, 0.0, 0.1 }, v0[3] = { 0.0, 2.0, 0.3 };
    memcpy(q, q0, sizeof q0);
    memcpy(v, v0, sizeof v0);
  }
  int st = dm_integrator_momentum(I, q, v, p, &e);
  for (int k = 0; k < nsteps && st == DM_OK; k++)
    st = dm_integrator_step(I, h, q, p, q, p, &e);
  if (st != DM_OK)
    tap_diag("%s step: %s", mode, e.msg);
  memcpy(out, q, n * sizeof *q);
  memcpy(out + n, p, n * sizeof *p);
  *linear = I->stats.linear;
  if (fixed != NULL)
    *fixed = I->stats.fixed_total;
  dm_integrator_free(I);
  return st;
}

static double rel(const double *a, const double *b, size_t k)
{
  double d = 0, m = 0;
  for (size_t i = 0; i < k; i++) {
    d = fmax(d, fabs(a[i] - b[i]));
    m = fmax(m, fabs(b[i]));
  }
  return d / (m > 0 ? m : 1);
}

static void compare(const char *what, const dm_system *s, const char *method, int stages,
                    int nsteps)
{
  double a[2 * NMAX], b[2 * NMAX];
  int la, lb;
  int sa = run(s, method, stages, "dense", nsteps, a, &la);
  int sb = run(s, method, stages, "sparse", nsteps, b, &lb);
  double d = rel(a, b, 2 * s->n);
  tap_ok(sa == DM_OK && sb == DM_OK && la == DM_LINEAR_DENSE && lb == DM_LINEAR_SPARSE &&
         d <= 1e-12, "%s, %s: sparse = dense after %d steps (rel. diff %.2g)", what, method,
         nsteps, d);
}

int main(void)
{
  dm_gsl_init();
  C = dm_expr_ctx_alloc();
  static const char *const kinds[] = { "gyroscopic chain", "separable chain", "forced chain" };
  dm_system s;
  for (int kind = 0; kind < 3; kind++)
    for (int layout = 1; layout <= 2; layout++) {
      char what[96];
      snprintf(what, sizeof what, "%s, %s derivatives", kinds[kind],
               layout == DM_LAG_LAYOUT_DENSE ? "dense" : "sparse");
      if (make_system(kind, 10, layout, &s) != DM_OK)
        continue;
      compare(what, &s, "gauss", 2, 100);
      if (layout == DM_LAG_LAYOUT_SPARSE)
        compare(what, &s, "lobatto", 3, 100);
      dm_system_release(&s);
    }
  if (make_system(3, 8, DM_LAG_LAYOUT_AUTO, &s) == DM_OK) {
    compare("constrained 4-bob pendulum", &s, "lobatto", 3, 100);
    compare("constrained 4-bob pendulum", &s, "trapezoid", 0, 100);
    compare("constrained 4-bob pendulum", &s, "midpoint", 0, 100);
    dm_system_release(&s);
  }
  /* a built-in C system has no pattern: every entry is in it */
  dm_builtin_kepler(&s, 3, 1.0, NULL);
  compare("built-in Kepler (no pattern)", &s, "gauss", 3, 200);
  dm_system_release(&s);

  /* the step Jacobians */
  if (make_system(2, 12, DM_LAG_LAYOUT_SPARSE, &s) == DM_OK) {
    double J1[4 * 144], J2[4 * 144], q[12], v[12], p[12];
    dm_integ_opts o;
    dm_integrator *I1 = NULL, *I2 = NULL;
    dm_integ_opts_init(&o);
    strcpy(o.linear, "dense");
    dm_integrator_new(&s, "gauss", &o, &I1, NULL);
    strcpy(o.linear, "sparse");
    dm_integrator_new(&s, "gauss", &o, &I2, NULL);
    start(2, 12, q, v);
    dm_integrator_momentum(I1, q, v, p, NULL);
    int st = dm_integrator_jacobian(I1, 0.02, q, p, J1, NULL);
    st |= dm_integrator_jacobian(I2, 0.02, q, p, J2, NULL);
    tap_ok(st == DM_OK && rel(J1, J2, 4 * 144) <= 1e-12,
           "forced chain: step Jacobian sparse = dense (rel. diff %.2g)", rel(J1, J2, 4 * 144));
    dm_integrator_free(I1);
    dm_integrator_free(I2);
    dm_system_release(&s);
  }

  /* auto: dense when small, sparse for a long chain; the option's error */
  {
    double out[2 * NMAX];
    int lin;
    make_system(0, 6, DM_LAG_LAYOUT_AUTO, &s);
    run(&s, "gauss", 2, "auto", 1, out, &lin);
    tap_is_int(lin, DM_LINEAR_DENSE, "auto: 6 coordinates, Gauss 2 (12 unknowns): dense");
    dm_system_release(&s);
    make_system(1, 40, DM_LAG_LAYOUT_AUTO, &s);
    run(&s, "gauss", 2, "auto", 1, out, &lin);
    tap_is_int(lin, DM_LINEAR_SPARSE, "auto: a chain of 40, Gauss 2 (80 unknowns): sparse");
    dm_integ_opts o;
    dm_integrator *I = NULL;
    dm_err e;
    dm_integ_opts_init(&o);
    strcpy(o.linear, "banded");
    int st = dm_integrator_new(&s, "gauss", &o, &I, &e);
    tap_ok(st == DM_EINVAL && strstr(e.msg, "'linear'") && strstr(e.msg, "banded"),
           "linear = banded: %s", e.msg);
    dm_system_release(&s);
  }
  /* the fixed-point iteration: the same stages as Newton's */
  {
    double a[2 * NMAX], b[2 * NMAX];
    int lin;
    long fa = -1, fb = -1;
    make_system(1, 40, DM_LAG_LAYOUT_AUTO, &s);
    static const char *const meth[] = { "gauss", "lobatto" };
    for (int k = 0; k < 2; k++) {
      int sa = run_it(&s, meth[k], 3 - k, "auto", "auto", 0.02, 200, a, &lin, &fa);
      int sb = run_it(&s, meth[k], 3 - k, "auto", "newton", 0.02, 200, b, &lin, &fb);
      tap_ok(sa == DM_OK && sb == DM_OK && fa == 200 && fb == 0 && rel(a, b, 80) <= 1e-12,
             "separable chain of 40, %s: fixed-point iteration (%ld of 200 steps) = Newton "
             "(rel. diff %.2g)", meth[k], fa, rel(a, b, 80));
    }
    /* large steps: the iteration contracts slowly, Newton takes over */
    int sa = run_it(&s, "gauss", 2, "auto", "auto", 0.6, 50, a, &lin, &fa);
    int sb = run_it(&s, "gauss", 2, "auto", "newton", 0.6, 50, b, &lin, &fb);
    tap_ok(sa == DM_OK && sb == DM_OK && fa < 50 && rel(a, b, 80) <= 1e-12,
           "h = 0.6: Newton takes over when the iteration is slow (fixed alone in %ld of 50 "
           "steps), the same states (rel. diff %.2g)", fa, rel(a, b, 80));
    dm_system_release(&s);
    /* asked for on a small system with a diagonal mass */
    make_system(1, 10, DM_LAG_LAYOUT_DENSE, &s);
    sa = run_it(&s, "gauss", 2, "auto", "fixed", 0.02, 100, a, &lin, &fa);
    sb = run_it(&s, "gauss", 2, "auto", "newton", 0.02, 100, b, &lin, &fb);
    tap_ok(sa == DM_OK && sb == DM_OK && fa == 100 && rel(a, b, 20) <= 1e-12,
           "iteration = fixed on 10 coordinates: the same states (rel. diff %.2g)",
           rel(a, b, 20));
    sa = run_it(&s, "gauss", 2, "auto", "auto", 0.02, 10, a, &lin, &fa);
    tap_ok(sa == DM_OK && fa == 10, "auto: the fixed-point iteration on 10 coordinates too");
    dm_system_release(&s);
    /* the systems it does not apply to; the option's error */
    static const char *const why[] = { "gyroscopic", "", "forced" };
    for (int kind = 0; kind <= 3; kind++) {
      if (kind == 1 || make_system(kind, 8, DM_LAG_LAYOUT_AUTO, &s) != DM_OK)
        continue;
      dm_integ_opts o;
      dm_integrator *I = NULL;
      dm_err e;
      dm_integ_opts_init(&o);
      strcpy(o.iteration, "fixed");
      const char *method = kind == 3 ? "lobatto" : "gauss";
      int st = dm_integrator_new(&s, method, &o, &I, &e);
      tap_ok(st == DM_EINVAL && strstr(e.msg, "iteration = \"fixed\" needs a separable"),
             "iteration = fixed on a %s system: %s", kind == 3 ? "constrained" : why[kind],
             e.msg);
      if (kind == 3) {
        strcpy(o.iteration, "quick");
        st = dm_integrator_new(&s, method, &o, &I, &e);
        tap_ok(st == DM_EINVAL && strstr(e.msg, "'iteration'") && strstr(e.msg, "quick"),
               "iteration = quick: %s", e.msg);
      }
      dm_system_release(&s);
    }
  }
  dm_expr_ctx_free(C);
  return tap_done();
}
