/* test_lie_integ.c -- systems on groups and their integrators (src/lie):
 * the free rigid body (J = diag(1, 2, 3), R0 = I, Pi0 = (1, 0.2, -0.5),
 * T = 10) with lgvi and lie:gauss (s = 1, 2; exp and Cayley charts):
 * errors against a 6-stage reference (which matches the published Pi(10)
 * and first row of R(10) to 1e-12), against the independent values of the
 * Moser-Veselov and natural-chart integrators (sum of the max errors of R
 * and Pi: 2.111e-2 ... 1.57e-9, within 1 %), orders by step halving; |Pi|,
 * spatial momentum and orthogonality over 1e4 steps without
 * normalization; energy (to round-off for lgvi, bounded for lie:gauss);
 * the heavy top (energy error 8.02e-4, 2.00e-4, 5.01e-5 for h = 0.01,
 * 0.005, 0.0025: order 2; vertical spatial momentum to round-off); the
 * reduced (Euler-Poincare) runs equal the unreduced ones bit for bit; a
 * non-invariant Lagrangian refused by the reduction; SE(3) with a central
 * potential (angular momentum about the origin); symplecticity defect on
 * T*G, time reversal, forcing (damping); the errors. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lie/lie_system.h"
#include "expr/native.h"
#include "lie_testsys.h"
#include "tap.h"

static dm_expr_ctx *ctx;
static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

static dm_integrator *make(const dm_lie_system *S, const char *method, int stages)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  dm_integ_opts_init(&o);
  o.stages = stages;
  if (dm_integrator_new(dm_lie_system_base(S), method, &o, &I, &e) != DM_OK)
    tap_diag("%s: %s", method, e.msg);
  return I;
}

/* n steps of h from (g, mu) in place */
static int steps(dm_integrator *I, double h, long n, double *g, double *mu)
{
  dm_err e;
  long k;
  for (k = 0; k < n; k++)
    if (dm_integrator_step(I, h, g, mu, g, mu, &e) != DM_OK) {
      tap_diag("step %ld: %s", k, e.msg);
      return -1;
    }
  return 0;
}

static double maxdiff(const double *a, const double *b, size_t n)
{
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return m != m ? INFINITY : m;
}

static double orth(const double *R)
{
  double P[9];
  size_t i, j, k;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++) {
      double s = 0;
      for (k = 0; k < 3; k++)
        s += R[3 * k + i] * R[3 * k + j];
      P[3 * i + j] = s - (i == j);
    }
  return maxdiff(P, P, 0) + fmax(fabs(P[0]), fmax(fabs(P[1]), fmax(fabs(P[2]), fmax(fabs(P[4]),
                                                   fmax(fabs(P[5]), fabs(P[8]))))));
}

static void free_body(dm_lie_system *S, const dm_lie_group *SO3)
{
  static const double Pref[3] = {0.97348168289841, 0.49933320763306, -0.30495862148193};
  static const double Rref1[3] = {0.78438310127859, 0.09955476735690, -0.61223524786236};
  static const struct { const char *m; int s; long n0; double err[3]; } cases[] = {
    {"lgvi", 0, 100, {2.111e-2, 5.253e-3, 1.312e-3}},
    {"lie:gauss", 1, 100, {8.507e-4, 2.126e-4, 5.316e-5}},
    {"lie:gauss", 2, 50, {4.02e-7, 2.51e-8, 1.57e-9}},
  };
  double gr[9], mr[3], g[9], mu[3];
  size_t c, k;
  dm_integrator *I = make(S, "lie:gauss", 6);
  memcpy(gr, I3, sizeof gr);
  mr[0] = 1, mr[1] = 0.2, mr[2] = -0.5;
  steps(I, 10.0 / 400, 400, gr, mr);
  dm_integrator_free(I);
  tap_ok(maxdiff(mr, Pref, 3) <= 1e-13 && maxdiff(gr, Rref1, 3) <= 1e-13,
         "reference (lie:gauss s = 6, h = 1/40) = published Pi(10) and R(10) row 1 (%.2g, %.2g)",
         maxdiff(mr, Pref, 3), maxdiff(gr, Rref1, 3));
  for (c = 0; c < 3; c++) {
    double err[3], hs[3];
    for (k = 0; k < 3; k++) {
      long n = cases[c].n0 << k;
      I = make(S, cases[c].m, cases[c].s);
      memcpy(g, I3, sizeof g);
      mu[0] = 1, mu[1] = 0.2, mu[2] = -0.5;
      steps(I, 10.0 / (double)n, n, g, mu);
      err[k] = maxdiff(g, gr, 9) + maxdiff(mu, mr, 3);
      hs[k] = 10.0 / (double)n;
      dm_integrator_free(I);
      tap_ok(fabs(err[k] / cases[c].err[k] - 1.0) <= 0.01, "%s s=%d n=%ld: error %.4g (published "
             "%.4g)", cases[c].m, cases[c].s, n, err[k], cases[c].err[k]);
    }
    {
      double ord = dm_integrator_order_fit(hs, err, 3), want = cases[c].s ? 2.0 * cases[c].s : 2;
      tap_ok(fabs(ord - want) <= 0.05, "%s s=%d: order %.3f (want %g)", cases[c].m, cases[c].s,
             ord, want);
    }
  }
  /* Cayley chart: order 4 too */
  {
    double err[3], hs[3];
    for (k = 0; k < 3; k++) {
      long n = 50L << k;
      I = make(S, "lie:gauss:cayley", 2);
      memcpy(g, I3, sizeof g);
      mu[0] = 1, mu[1] = 0.2, mu[2] = -0.5;
      steps(I, 10.0 / (double)n, n, g, mu);
      err[k] = maxdiff(g, gr, 9) + maxdiff(mu, mr, 3);
      hs[k] = 10.0 / (double)n;
      dm_integrator_free(I);
    }
    tap_ok(fabs(dm_integrator_order_fit(hs, err, 3) - 4.0) <= 0.1,
           "lie:gauss:cayley s=2: order %.3f (errors %.3g %.3g %.3g)",
           dm_integrator_order_fit(hs, err, 3), err[0], err[1], err[2]);
  }
  (void)SO3;
}

/* 1e4 steps of h = 0.5 without normalization: |Pi|, R Pi, R^T R */
static void conservation(dm_lie_system *S, const dm_lie_group *SO3)
{
  static const char *const m[4] = {"lgvi", "lie:gauss", "lie:gauss", "lie:gauss:cayley"};
  static const int s[4] = {0, 1, 2, 2};
  size_t c;
  for (c = 0; c < 4; c++) {
    dm_integrator *I = make(S, m[c], s[c]);
    double g[9], mu[3], J0[3], J[3], n0, dn = 0.0, dJ = 0.0, dO = 0.0, E0, E, dE = 0.0;
    dm_err e;
    long k;
    memcpy(g, I3, sizeof g);
    mu[0] = 1, mu[1] = 0.2, mu[2] = -0.5;
    n0 = sqrt(mu[0] * mu[0] + mu[1] * mu[1] + mu[2] * mu[2]);
    dm_lie_spatial_momentum(SO3, g, mu, J0);
    dm_lie_energy(I, g, mu, &E0, &e);
    for (k = 0; k < 10000; k++) {
      if (steps(I, 0.5, 1, g, mu) != 0)
        break;
      dm_lie_spatial_momentum(SO3, g, mu, J);
      dn = fmax(dn, fabs(sqrt(mu[0] * mu[0] + mu[1] * mu[1] + mu[2] * mu[2]) - n0));
      dJ = fmax(dJ, maxdiff(J, J0, 3));
      if (k % 100 == 0) {
        dO = fmax(dO, orth(g));
        dm_lie_energy(I, g, mu, &E, &e);
        dE = fmax(dE, fabs(E - E0));
      }
    }
    dO = fmax(dO, orth(g));
    tap_ok(dn <= 1e-13 && dJ <= 1e-13, "%s s=%d, 1e4 steps of 0.5: max ||Pi| - |Pi0|| = %.2g, "
           "max |R Pi - R0 Pi0| = %.2g (<= 1e-13)", m[c], s[c], dn, dJ);
    tap_ok(dO <= 1e-13, "%s s=%d: max |R^T R - I| = %.2g without normalization", m[c], s[c], dO);
    if (c == 0)
      tap_ok(dE <= 1e-13, "lgvi: energy conserved to round-off on the free body (%.2g)", dE);
    else
      tap_ok(dE <= 2e-2 && dE > 0, "%s s=%d: energy error bounded (%.2g)", m[c], s[c], dE);
    dm_integrator_free(I);
  }
}

static void heavy_top(const dm_lie_group *SO3)
{
  static const double want[3] = {8.02e-4, 2.00e-4, 5.01e-5};
  static const double par[6] = {1, 2, 3, 9.81, 0.3, 0};
  static const double Pend[3] = {-0.14191, -4.67277, -1.15312};
  dm_lie_system *S;
  dm_err e;
  double errs[3], hs[3];
  int k;
  if (lt_top(ctx, SO3, par, 0, 0, DM_NATIVE_NEVER, &S, &e) != DM_OK) {
    tap_ok(0, "heavy top: %s", e.msg);
    return;
  }
  for (k = 0; k < 3; k++) {
    double h = 0.01 / (1 << k), g[9], mu[3] = {0.5, 0.2, 1.0}, w[3] = {0.5, 0, 0}, E0, E;
    double J0[3], J[3], dE = 0.0, dJ = 0.0;
    long n = lround(10.0 / h), i;
    dm_integrator *I = make(S, "lgvi", 0);
    dm_lie_exp(SO3, w, g);
    dm_lie_energy(I, g, mu, &E0, &e);
    dm_lie_spatial_momentum(SO3, g, mu, J0);
    for (i = 0; i < n; i++) {
      steps(I, h, 1, g, mu);
      dm_lie_energy(I, g, mu, &E, &e);
      dm_lie_spatial_momentum(SO3, g, mu, J);
      dE = fmax(dE, fabs(E - E0));
      dJ = fmax(dJ, fabs(J[2] - J0[2]));
    }
    errs[k] = dE;
    hs[k] = h;
    tap_ok(fabs(dE / want[k] - 1) <= 0.01, "heavy top lgvi h=%g: max |E - E0| = %.4g (published "
           "%.3g)", h, dE, want[k]);
    tap_ok(dJ <= 1.5e-14 * 4, "heavy top h=%g: vertical spatial momentum to %.2g", h, dJ);
    if (k == 2)
      tap_ok(maxdiff(mu, Pend, 3) <= 1e-5, "heavy top h = 0.0025: Pi(10) = (%.5f, %.5f, %.5f) "
             "as published", mu[0], mu[1], mu[2]);
    dm_integrator_free(I);
  }
  tap_ok(fabs(dm_integrator_order_fit(hs, errs, 3) - 2.0) <= 0.02, "heavy top energy error "
         "order %.3f", dm_integrator_order_fit(hs, errs, 3));
  /* the non-structure-preserving reference: GSL rk4 on quaternions */
  {
    double g0[9], mu0[3] = {0.5, 0.2, 1.0}, w[3] = {0.5, 0, 0}, hs2[3] = {0.04, 0.02, 0.01}, er[3];
    double ord, d, E0, E, J0[3], J[3];
    dm_integ_opts o;
    dm_integrator *I = make(S, "gsl:rk4", 0);
    long i;
    dm_lie_exp(SO3, w, g0);
    dm_integ_opts_init(&o);
    int rc = dm_lie_order_estimate(S, "gsl:rk4", &o, g0, mu0, 1.0, hs2, 3, er, &ord, &e);
    tap_ok(rc == DM_OK && fabs(ord - 4.0) <= 0.1, "gsl:rk4 on quaternions: order %.3f", ord);
    rc = dm_lie_symplecticity_defect(I, 0.3, g0, mu0, &d, &e);
    tap_ok(rc == DM_OK && d > 1e-6, "gsl:rk4, h = 0.3: not symplectic (defect %.2g; the "
           "variational ones: <= 1e-8 at h = 0.1)", d);
    {
      double g[9], mu[3] = {0.5, 0.2, 1.0};
      memcpy(g, g0, sizeof g);
      dm_lie_energy(I, g, mu, &E0, &e);
      dm_lie_spatial_momentum(SO3, g, mu, J0);
      for (i = 0; i < 1000; i++)
        steps(I, 0.01, 1, g, mu);
      dm_lie_energy(I, g, mu, &E, &e);
      dm_lie_spatial_momentum(SO3, g, mu, J);
      tap_ok(fabs(J[2] - J0[2]) > 1e-12 && fabs(E - E0) > 1e-12, "gsl:rk4 drifts: energy %.2g, "
             "vertical momentum %.2g after 1000 steps", fabs(E - E0), fabs(J[2] - J0[2]));
    }
    dm_integrator_free(I);
    tap_ok(dm_integrator_new(dm_lie_system_base(S), "gsl:rk9", NULL, &I, &e) == DM_ENOTFOUND &&
               strstr(e.msg, "gsl: unknown stepper 'rk9'") != NULL, "gsl:rk9: %s", e.msg);
  }
  /* symplecticity (every variant), reversal (the symmetric ones: lgvi and
   * the exp chart with s = 1; polynomials in a chart based at g_k are not
   * the reversed family for s >= 2 or the Cayley chart) */
  {
    static const char *const m[5] = {"lgvi", "lie:gauss", "lie:gauss", "lie:gauss:cayley",
                                     "lie:gauss:cayley"};
    static const int s[5] = {0, 1, 2, 1, 2};
    int c;
    for (c = 0; c < 5; c++) {
      dm_integrator *I = make(S, m[c], s[c]);
      double g[9], mu[3] = {0.5, 0.2, 1.0}, w[3] = {0.5, 0.3, -0.2}, d, dev;
      int sym = c < 2;
      dm_lie_exp(SO3, w, g);
      int rc = dm_lie_symplecticity_defect(I, 0.1, g, mu, &d, &e);
      tap_ok(rc == DM_OK && d <= 1e-8, "%s s=%d: symplecticity defect on T*SO(3) %.2g", m[c], s[c],
             d);
      tap_ok(!!(I->flags & DM_INTEG_SYMMETRIC) == sym, "%s s=%d: %s", m[c], s[c],
             sym ? "symmetric" : "not flagged symmetric");
      dev = -1.0;
      if (sym) {
        rc = dm_lie_reversal(I, 0.05, 100, g, mu, &dev, &e);
        tap_ok(rc == DM_OK && dev <= 1e-12, "%s s=%d: 100 steps forward and back return to %.2g",
               m[c], s[c], dev);
      }
      dm_integrator_free(I);
    }
  }
  /* a non-invariant Lagrangian handed to the reduction */
  {
    dm_lie_system *R;
    int st = dm_lie_system_reduce(S, &R, &e);
    tap_ok(st == DM_EINVAL && strstr(e.msg, "euler_poincare: the Lagrangian is not invariant "
                                     "under left translations in SO3: d/de L(exp(e e_") == e.msg,
           "reduce refuses the heavy top: %s", e.msg);
  }
  dm_lie_system_free(S);
}

static void reduced(const dm_lie_group *SO3)
{
  static const double par[6] = {1.3, 2.1, 3.4, 0, 0, 0};
  dm_lie_system *S, *R;
  dm_err e;
  static const char *const m[3] = {"lgvi", "lie:gauss", "lie:gauss:cayley"};
  int c;
  if (lt_top(ctx, SO3, par, 0, 0, DM_NATIVE_NEVER, &S, &e) != DM_OK ||
      dm_lie_system_reduce(S, &R, &e) != DM_OK) {
    tap_ok(0, "reduction: %s", e.msg);
    return;
  }
  tap_ok(dm_lie_system_is_reduced(R) && !dm_lie_system_is_reduced(S), "the reduced system");
  for (c = 0; c < 3; c++) {
    dm_integrator *Iu = make(S, m[c], 3), *Ir = make(R, m[c], 3);
    double g[9], mu[3] = {0.5, 1.2, 0.3}, gr[9], mr[3] = {0.5, 1.2, 0.3}, w[3] = {0.2, -0.7, 1.1};
    dm_lie_exp(SO3, w, g);
    memcpy(gr, g, sizeof g);
    steps(Iu, 0.05, 1000, g, mu);
    steps(Ir, 0.05, 1000, gr, mr);
    tap_ok(maxdiff(mu, mr, 3) <= 1e-13 && maxdiff(g, gr, 9) <= 1e-13,
           "%s: reduced = unreduced after 1000 steps (mu %.2g, g %.2g)", m[c],
           maxdiff(mu, mr, 3), maxdiff(g, gr, 9));
    dm_integrator_free(Iu);
    dm_integrator_free(Ir);
  }
  {
    dm_lie_system *R2;
    tap_ok(dm_lie_system_reduce(R, &R2, &e) == DM_EINVAL && R2 == NULL &&
               strcmp(e.msg, "euler_poincare: 'top' is reduced already") == 0,
           "reducing twice: %s", e.msg);
  }
  dm_lie_system_free(R);
  dm_lie_system_free(S);
}

static void forcing(const dm_lie_group *SO3)
{
  static const double par[6] = {1, 2, 3, 0, 0, 0.2};
  dm_lie_system *S;
  dm_err e;
  static const char *const m[2] = {"lgvi", "lie:gauss"};
  int c;
  if (lt_top(ctx, SO3, par, 1, 0, DM_NATIVE_NEVER, &S, &e) != DM_OK) {
    tap_ok(0, "forced: %s", e.msg);
    return;
  }
  for (c = 0; c < 2; c++) {
    /* E(t) for damping -k Om with J = diag(1,2,3): dE/dt = -k |Om|^2; the
     * discrete energy follows E0 - k int |Om|^2 dt to O(h^2) */
    double errs[2], hs[2];
    int k;
    for (k = 0; k < 2; k++) {
      double h = 0.02 / (1 << k), g[9], mu[3] = {1, 0.2, -0.5}, E0, E, W = 0.0, xi[3], x0[3];
      long n = lround(2.0 / h), i;
      dm_integrator *I = make(S, m[c], 2);
      memcpy(g, I3, sizeof g);
      dm_lie_energy(I, g, mu, &E0, &e);
      dm_lie_velocity(I, g, mu, x0, &e);
      for (i = 0; i < n; i++) {
        steps(I, h, 1, g, mu);
        dm_lie_velocity(I, g, mu, xi, &e);
        W += 0.5 * h * 0.2 * (x0[0] * x0[0] + x0[1] * x0[1] + x0[2] * x0[2] + xi[0] * xi[0] +
                              xi[1] * xi[1] + xi[2] * xi[2]);
        memcpy(x0, xi, sizeof x0);
      }
      dm_lie_energy(I, g, mu, &E, &e);
      errs[k] = fabs(E - (E0 - W));
      hs[k] = h;
      tap_ok(E < E0 - 0.1 * W, "%s damped: energy %.6g -> %.6g (work %.6g)", m[c], E0, E, W);
      dm_integrator_free(I);
    }
    tap_ok(dm_integrator_order_fit(hs, errs, 2) >= 1.8, "%s damped: E0 - work - E = O(h^%.2f)",
           m[c], dm_integrator_order_fit(hs, errs, 2));
  }
  dm_lie_system_free(S);
}

static void se3(void)
{
  dm_lie_group *G = dm_lie_se3(NULL);
  dm_lie_system *S;
  dm_err e;
  static const char *const m[3] = {"lgvi", "lie:gauss", "lie:gauss"};
  static const int st[3] = {0, 1, 2};
  int c;
  if (lt_se3(ctx, G, DM_NATIVE_NEVER, &S, &e) != DM_OK) {
    tap_ok(0, "SE3 system: %s", e.msg);
    dm_lie_group_free(G);
    return;
  }
  for (c = 0; c < 3; c++) {
    dm_integrator *I = make(S, m[c], st[c]);
    double g[12], mu[6] = {0.3, -0.2, 0.5, 0.4, 1.0, -0.3}, xi0[6] = {0.2, 0.1, -0.3, 1, 0.5, 0.2};
    double J0[6], J[6], dL = 0.0, E0, E, dE = 0.0;
    long k;
    dm_lie_exp(G, xi0, g);
    dm_lie_spatial_momentum(G, g, mu, J0);
    dm_lie_energy(I, g, mu, &E0, &e);
    for (k = 0; k < 2000; k++) {
      if (steps(I, 0.05, 1, g, mu))
        break;
      dm_lie_spatial_momentum(G, g, mu, J);
      dL = fmax(dL, maxdiff(J, J0, 3));
      dm_lie_energy(I, g, mu, &E, &e);
      dE = fmax(dE, fabs(E - E0));
    }
    tap_ok(dL <= 1e-12, "SE3 %s s=%d: angular momentum about the origin to %.2g (2000 steps)",
           m[c], st[c], dL);
    tap_ok(dE <= 1e-2, "SE3 %s s=%d: energy error bounded (%.2g)", m[c], st[c], dE);
    dm_integrator_free(I);
  }
  {
    double g0[12], mu0[6] = {0.3, -0.2, 0.5, 0.4, 1.0, -0.3}, xi0[6] = {0.2, 0.1, -0.3, 1, 0.5, 0.2};
    double hs[3] = {0.2, 0.1, 0.05}, err[3], ord;
    dm_integ_opts o;
    dm_lie_exp(G, xi0, g0);
    dm_integ_opts_init(&o);
    o.stages = 2;
    int rc = dm_lie_order_estimate(S, "lie:gauss", &o, g0, mu0, 2.0, hs, 3, err, &ord, &e);
    tap_ok(rc == DM_OK && fabs(ord - 4) <= 0.15, "SE3 lie:gauss s=2: order estimate %.3f", ord);
    o.stages = 0;
    rc = dm_lie_order_estimate(S, "lgvi", &o, g0, mu0, 2.0, hs, 3, err, &ord, &e);
    tap_ok(rc == DM_OK && fabs(ord - 2) <= 0.1, "SE3 lgvi: order estimate %.3f", ord);
  }
  dm_lie_system_free(S);
  dm_lie_group_free(G);
}

static void errors(const dm_lie_group *SO3)
{
  dm_lie_system *S;
  dm_err e;
  dm_integrator *I;
  /* lgvi on a Lagrangian with a velocity coupling: refused with the reason */
  dm_expr g[9], xi[3], L;
  dm_lie_spec sp;
  lt_syms(ctx, "R", 9, g);
  lt_syms(ctx, "xi", 3, xi);
  L = dm_expr_add(ctx, dm_expr_mul(ctx, dm_expr_const(ctx, 0.5), dm_expr_powi(ctx, xi[0], 2)),
                  dm_expr_mul(ctx, g[0], dm_expr_powi(ctx, xi[1], 2)));
  L = dm_expr_add(ctx, L, dm_expr_powi(ctx, xi[2], 2));
  memset(&sp, 0, sizeof sp);
  sp.G = SO3;
  sp.g = g;
  sp.xi = xi;
  sp.L = L;
  sp.name = "coupled";
  tap_ok(dm_lie_system_compile(ctx, &sp, &S, &e) == DM_OK, "compile a configuration-dependent "
         "inertia");
  tap_ok(dm_integrator_new(dm_lie_system_base(S), "lgvi", NULL, &I, &e) == DM_EINVAL &&
             strcmp(e.msg, "lgvi: needs L = 1/2 xi^T J xi - U(g) with a constant kinetic matrix J "
                    "(free of g and xi) and no terms linear in xi; 'coupled' is not of that form "
                    "(use method 'lie:gauss')") == 0, "lgvi refuses it: %s", e.msg);
  tap_ok(dm_integrator_new(dm_lie_system_base(S), "gauss", NULL, &I, &e) == DM_ENOTFOUND,
         "a vector-space method on a Lie system: %s", e.msg);
  dm_lie_system_free(S);
  sp.g = NULL;
  tap_ok(dm_lie_system_compile(ctx, &sp, &S, &e) == DM_EINVAL, "spec without g: %s", e.msg);
  dm_lie_system_free(NULL);
}

int main(void)
{
  dm_lie_group *SO3;
  dm_lie_system *S;
  dm_err e;
  static const double par[6] = {1, 2, 3, 0, 0, 0};
  dm_gsl_init();
  ctx = dm_expr_ctx_alloc();
  SO3 = dm_lie_so3(NULL);
  tap_ok(dm_lie_register_integrators(&e) == DM_OK && dm_lie_register_integrators(&e) == DM_OK,
         "register the families (idempotent)");
  if (lt_top(ctx, SO3, par, 0, 0, DM_NATIVE_NEVER, &S, &e) != DM_OK) {
    tap_ok(0, "free body: %s", e.msg);
    return tap_done();
  }
  free_body(S, SO3);
  conservation(S, SO3);
  dm_lie_system_free(S);
  heavy_top(SO3);
  reduced(SO3);
  forcing(SO3);
  se3();
  errors(SO3);
  dm_lie_group_free(SO3);
  dm_expr_ctx_free(ctx);
  return tap_done();
}
