/* test_integrators_traced.c -- the integrators on systems compiled from
 * expressions (dm_lagrangian_compile, tape mode) agree with the hand-written
 * built-in systems: J2 with Gauss 2 (implicit, exact Jacobians from the
 * tapes), Kepler with the explicit Stormer-Verlet path (separable structure
 * detected symbolically), the constrained spherical pendulum with Lobatto 3
 * and the damped oscillator with its force. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "tap.h"

typedef struct traced {
  dm_expr_ctx *ctx;
  dm_expr q[3], v[3], par[2];
} traced;

static void syms(traced *T, size_t n)
{
  static const char *qn[] = {"x", "y", "z"}, *vn[] = {"vx", "vy", "vz"};
  size_t i;
  T->ctx = dm_expr_ctx_alloc();
  for (i = 0; i < n; i++) {
    T->q[i] = dm_expr_sym(T->ctx, qn[i]);
    T->v[i] = dm_expr_sym(T->ctx, vn[i]);
  }
}

static dm_expr kinetic(traced *T, size_t n)
{
  dm_expr_ctx *c = T->ctx;
  dm_expr s = dm_expr_const(c, 0.0);
  size_t i;
  for (i = 0; i < n; i++)
    s = dm_expr_add(c, s, dm_expr_powi(c, T->v[i], 2));
  return dm_expr_mul(c, dm_expr_const(c, 0.5), s);
}

static dm_expr radius(traced *T, size_t n)
{
  dm_expr_ctx *c = T->ctx;
  dm_expr s = dm_expr_const(c, 0.0);
  size_t i;
  for (i = 0; i < n; i++)
    s = dm_expr_add(c, s, dm_expr_powi(c, T->q[i], 2));
  return dm_expr_call(c, "sqrt", 1, &s);
}

static int compile(traced *T, size_t n, dm_expr L, size_t npar, const double *pv, const dm_expr *force,
                   size_t m, const dm_expr *g, dm_system *s)
{
  dm_lagrangian_spec sp;
  dm_err e;
  int st;
  memset(&sp, 0, sizeof sp);
  sp.name = "traced";
  sp.n = n;
  sp.q = T->q;
  sp.v = T->v;
  sp.npar = npar;
  sp.par = T->par;
  sp.par_values = pv;
  sp.L = L;
  sp.force = force;
  sp.m = m;
  sp.constraints = g;
  sp.native = DM_NATIVE_NEVER;
  st = dm_lagrangian_compile(T->ctx, &sp, s, &e);
  if (st != DM_OK)
    tap_diag("compile: %s", e.msg);
  return st;
}

static double run_diff(const dm_system *a, const dm_system *b, const char *method, int stages,
                       double h, long n, const double *q0, const double *p0, unsigned *fa)
{
  dm_integ_opts o;
  dm_integrator *A = NULL, *B = NULL;
  double qa[3], pa[3], qb[3], pb[3], d = HUGE_VAL;
  size_t i, dim = a->n;
  int s1, s2;
  dm_integ_opts_init(&o);
  o.stages = stages;
  dm_integrator_new(a, method, &o, &A, NULL);
  dm_integrator_new(b, method, &o, &B, NULL);
  if (A && B) {
    memcpy(qa, q0, dim * sizeof(double));
    memcpy(pa, p0, dim * sizeof(double));
    memcpy(qb, q0, dim * sizeof(double));
    memcpy(pb, p0, dim * sizeof(double));
    s1 = dm_integrator_run(A, 0.0, qa, pa, h, n, n, NULL, NULL, NULL, NULL);
    s2 = dm_integrator_run(B, 0.0, qb, pb, h, n, n, NULL, NULL, NULL, NULL);
    if (s1 == DM_OK && s2 == DM_OK)
      for (d = 0, i = 0; i < dim; i++)
        d = fmax(d, fmax(fabs(qa[i] - qb[i]), fabs(pa[i] - pb[i])));
    *fa = A->flags;
  }
  dm_integrator_free(A);
  dm_integrator_free(B);
  return d;
}

int main(void)
{
  dm_gsl_init();
  {
    /* J2: V = -1/r + J2/r^3 (3 z^2/(2 r^2) - 1/2) */
    traced T;
    dm_system tr, bi;
    dm_expr r, V, L;
    double J2 = 0.05, d;
    const double q0[3] = {2.0, 0.0, 0.3}, p0[3] = {0.0, 0.6, 0.1};
    unsigned f = 0;
    dm_expr_ctx *c;
    syms(&T, 3);
    c = T.ctx;
    T.par[0] = dm_expr_param(c, "J2");
    r = radius(&T, 3);
    V = dm_expr_add(c, dm_expr_neg(c, dm_expr_div(c, dm_expr_const(c, 1.0), r)),
                    dm_expr_mul(c, dm_expr_div(c, T.par[0], dm_expr_powi(c, r, 3)),
                                dm_expr_sub(c, dm_expr_div(c, dm_expr_mul(c, dm_expr_const(c, 1.5),
                                                                          dm_expr_powi(c, T.q[2], 2)),
                                                           dm_expr_powi(c, r, 2)),
                                            dm_expr_const(c, 0.5))));
    L = dm_expr_sub(c, kinetic(&T, 3), V);
    tap_is_int(compile(&T, 3, L, 1, &J2, NULL, 0, NULL, &tr), DM_OK, "J2 Lagrangian compiled from expressions");
    dm_builtin_j2(&bi, J2, NULL);
    d = run_diff(&tr, &bi, "gauss", 2, 0.05, 200, q0, p0, &f);
    tap_ok(d < 1e-12 && !(f & DM_INTEG_EXPLICIT),
           "J2, Gauss 2, 200 steps: traced tape = hand-written C (%.2g)", d);
    dm_system_release(&tr);
    dm_system_release(&bi);
    dm_expr_ctx_free(c);
  }
  {
    traced T;
    dm_system tr, bi;
    double mu = 1.0, d;
    const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0};
    unsigned f = 0;
    syms(&T, 2);
    T.par[0] = dm_expr_param(T.ctx, "mu");
    compile(&T, 2, dm_expr_add(T.ctx, kinetic(&T, 2), dm_expr_div(T.ctx, T.par[0], radius(&T, 2))), 1, &mu,
            NULL, 0, NULL, &tr);
    dm_builtin_kepler(&bi, 2, mu, NULL);
    tap_ok((tr.flags & DM_SYS_SEPARABLE) && tr.mass != NULL, "traced Kepler detected separable");
    d = run_diff(&tr, &bi, "trapezoid", 0, 0.01, 10000, q0, p0, &f);
    tap_ok(d < 1e-12 && (f & DM_INTEG_EXPLICIT),
           "Kepler, explicit Stormer-Verlet, 1e4 steps: traced tape = hand-written C (%.2g)", d);
    dm_system_release(&tr);
    dm_system_release(&bi);
    dm_expr_ctx_free(T.ctx);
  }
  {
    /* spherical pendulum in R^3, g(q) = |q|^2 - l^2 */
    traced T;
    dm_system tr, bi;
    dm_expr_ctx *c;
    dm_expr L, g, r2;
    double pv[2] = {9.81, 1.3}, d, th = 1.2, ph = 0.3, L0 = 1.3;
    const double q0[3] = {L0 * sin(th) * cos(ph), L0 * sin(th) * sin(ph), -L0 * cos(th)};
    const double p0[3] = {L0 * (cos(th) * cos(ph) * 0.5 - sin(th) * sin(ph) * 1.5),
                          L0 * (cos(th) * sin(ph) * 0.5 + sin(th) * cos(ph) * 1.5), L0 * sin(th) * 0.5};
    unsigned f = 0;
    syms(&T, 3);
    c = T.ctx;
    T.par[0] = dm_expr_param(c, "g");
    T.par[1] = dm_expr_param(c, "l");
    L = dm_expr_sub(c, kinetic(&T, 3), dm_expr_mul(c, T.par[0], T.q[2]));
    r2 = dm_expr_add(c, dm_expr_add(c, dm_expr_powi(c, T.q[0], 2), dm_expr_powi(c, T.q[1], 2)),
                     dm_expr_powi(c, T.q[2], 2));
    g = dm_expr_sub(c, r2, dm_expr_powi(c, T.par[1], 2));
    compile(&T, 3, L, 2, pv, NULL, 1, &g, &tr);
    dm_builtin_spherical_pendulum_r3(&bi, 9.81, 1.3, 1.0, 0, NULL);
    d = run_diff(&tr, &bi, "lobatto", 3, 0.05, 200, q0, p0, &f);
    tap_ok(d < 1e-12, "spherical pendulum in R3, Lobatto 3 with stage multipliers: traced = C (%.2g)", d);
    d = run_diff(&tr, &bi, "trapezoid", 0, 0.05, 200, q0, p0, &f);
    tap_ok(d < 1e-12 && (f & DM_INTEG_EXPLICIT), "spherical pendulum, explicit RATTLE: traced = C (%.2g)", d);
    dm_system_release(&tr);
    dm_system_release(&bi);
    dm_expr_ctx_free(c);
  }
  {
    /* damped oscillator, F = -c v */
    traced T;
    dm_system tr, bi;
    dm_expr_ctx *c;
    dm_expr L, F;
    double pv[2] = {2.385, 0.1}, d;
    const double q0[1] = {0.7}, p0[1] = {0.2};
    unsigned f = 0;
    syms(&T, 1);
    c = T.ctx;
    T.par[0] = dm_expr_param(c, "omega");
    T.par[1] = dm_expr_param(c, "c");
    L = dm_expr_sub(c, kinetic(&T, 1),
                    dm_expr_mul(c, dm_expr_const(c, 0.5),
                                dm_expr_mul(c, dm_expr_powi(c, T.par[0], 2), dm_expr_powi(c, T.q[0], 2))));
    F = dm_expr_neg(c, dm_expr_mul(c, T.par[1], T.v[0]));
    compile(&T, 1, L, 2, pv, &F, 0, NULL, &tr);
    dm_builtin_damped_oscillator(&bi, 1.0, 2.385, 0.1, NULL);
    d = run_diff(&tr, &bi, "gauss", 2, 0.05, 400, q0, p0, &f);
    tap_ok(d < 1e-13, "damped oscillator, forced Gauss 2: traced = C (%.2g)", d);
    dm_system_release(&tr);
    dm_system_release(&bi);
    dm_expr_ctx_free(c);
  }
  return tap_done();
}
