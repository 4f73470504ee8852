/* test_reduce_chart.c -- where the chart of a reduction is singular
 * (doc/reduce.md §15; thesis §2.10.4).  The double spherical pendulum in
 * V = R^3 x R^3 reduced by the simultaneous rotation in two charts besides the
 * cylindrical one (both bobs polar, singular at r1 = 0 and at r2 = 0):
 *   "bob 1 polar": (r1, theta1, z1) for bob 1, (xi2, eta2, z2) for bob 2
 *       (from bob 1) in the frame rotated by theta1 -- singular only at r1 = 0;
 *   "bob 2 polar": (R, Theta, Z) for the absolute position q1 + q2 of bob 2,
 *       (xi1, eta1, z1) for bob 1 in the frame rotated by Theta -- singular
 *       only at R = 0.
 * Asserted: I and A equal their closed forms; det Mtilde = (m1 m2)^3 c^2 / I
 * with c = r1 resp. R (the singular set is c = 0, where I stays regular: the
 * action is free there, the chart is not); the reduced RSPRK (Lobatto
 * IIIA-IIIB) equals the projected unreduced run (Theorem 2.14) and agrees
 * with the cylindrical chart in position space with order 4; the energy error
 * at a close approach r2 -> 0 is 1e-4-ish in the cylindrical chart and at
 * the h^4 level in both new charts, while at an r1 pass the bob 1 polar
 * chart spikes more than the cylindrical one (the spike follows the singular
 * set). */
#include <config.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "reduce/routh.h"
#include "reduce_systems.h"
#include "tap.h"

static const double PV[5] = {1.3, 0.8, 1.1, 0.9, 9.81};   /* m1, m2, l1, l2, g */
static const double PU[5] = {1.0, 1.0, 1.0, 1.0, 9.81};   /* the example's values */

enum { BOB1 = 1, BOB2 = 2 };

/* 1/2 m1 |u1|^2 + 1/2 m2 |U2|^2 - m1 g z1 - m2 g Z2 */
static dm_expr chart_L(rsys *S, const dm_expr *u1, const dm_expr *U2, dm_expr z1, dm_expr Z2)
{
  dm_expr T1 = RADD(RADD(RSQ(u1[0]), RSQ(u1[1])), RSQ(u1[2]));
  dm_expr T2 = RADD(RADD(RSQ(U2[0]), RSQ(U2[1])), RSQ(U2[2]));
  dm_expr T = RADD(RMUL(RMUL(RC(0.5), S->par[0]), T1), RMUL(RMUL(RC(0.5), S->par[1]), T2));
  dm_expr V = RMUL(S->par[4], RADD(RMUL(S->par[0], z1), RMUL(S->par[1], Z2)));
  return RSUB(T, V);
}

static void chart_sys(rsys *S, int which, const double *pv)
{
  static const char *q1n[] = {"r1", "theta1", "z1", "xi2", "eta2", "z2"};
  static const char *v1n[] = {"r1d", "theta1d", "z1d", "xi2d", "eta2d", "z2d"};
  static const char *q2n[] = {"R", "Theta", "Z", "xi1", "eta1", "z1"};
  static const char *v2n[] = {"Rd", "Thetad", "Zd", "xi1d", "eta1d", "z1d"};
  static const char *pn[] = {"m1", "m2", "l1", "l2", "g"};
  const dm_expr *q, *v;
  dm_expr w, pol[3], car[3];
  rs_syms(S, 6, which == BOB1 ? q1n : q2n, which == BOB1 ? v1n : v2n, 5, pn, pv);
  q = S->q;
  v = S->v;
  w = v[1];
  pol[0] = v[0];                      /* the polar point in its frame: (c, 0, z) */
  pol[1] = RMUL(q[0], w);
  pol[2] = v[2];
  car[0] = RSUB(v[3], RMUL(w, q[4]));  /* the other point in the rotating frame */
  car[1] = RADD(v[4], RMUL(w, q[3]));
  car[2] = v[5];
  S->m = 2;
  if (which == BOB1) {
    dm_expr U[3];
    int i;
    for (i = 0; i < 3; i++)
      U[i] = RADD(pol[i], car[i]);
    S->L = chart_L(S, pol, U, q[2], RADD(q[2], q[5]));
    S->g[0] = RSUB(RADD(RSQ(q[0]), RSQ(q[2])), RSQ(S->par[2]));
    S->g[1] = RSUB(RADD(RADD(RSQ(q[3]), RSQ(q[4])), RSQ(q[5])), RSQ(S->par[3]));
  } else {
    S->L = chart_L(S, car, pol, q[5], q[2]);
    S->g[0] = RSUB(RADD(RADD(RSQ(q[3]), RSQ(q[4])), RSQ(q[5])), RSQ(S->par[2]));
    S->g[1] = RSUB(RADD(RADD(RSQ(RSUB(q[0], q[3])), RSQ(q[4])), RSQ(RSUB(q[2], q[5]))),
                   RSQ(S->par[3]));
  }
}

/* Cartesian state (q1, q2 from bob 1) from the cylindrical data of rs_dsp
 * (r1, theta1, r2, phi) */
static void cartesian(const double *pv, const double *Q, const double *V, double *qx, double *vx)
{
  double r1 = Q[0], th = Q[1], r2 = Q[2], th2 = Q[1] + Q[3];
  double rd1 = V[0], thd = V[1], rd2 = V[2], thd2 = V[1] + V[3];
  double s1 = sqrt(pv[2] * pv[2] - r1 * r1), s2 = sqrt(pv[3] * pv[3] - r2 * r2);
  qx[0] = r1 * cos(th); qx[1] = r1 * sin(th); qx[2] = -s1;
  qx[3] = r2 * cos(th2); qx[4] = r2 * sin(th2); qx[5] = -s2;
  vx[0] = rd1 * cos(th) - r1 * thd * sin(th); vx[1] = rd1 * sin(th) + r1 * thd * cos(th);
  vx[2] = r1 * rd1 / s1;
  vx[3] = rd2 * cos(th2) - r2 * thd2 * sin(th2); vx[4] = rd2 * sin(th2) + r2 * thd2 * cos(th2);
  vx[5] = r2 * rd2 / s2;
}

/* chart state from the Cartesian one */
static void chart_state(int which, const double *qx, const double *vx, double *q, double *v)
{
  double X, Y, VX, VY, x, y, vxx, vyy, R, c, s, w, xi, eta;
  if (which == BOB1) {
    X = qx[0]; Y = qx[1]; VX = vx[0]; VY = vx[1];
    x = qx[3]; y = qx[4]; vxx = vx[3]; vyy = vx[4];
    q[2] = qx[2]; v[2] = vx[2]; q[5] = qx[5]; v[5] = vx[5];
  } else {
    X = qx[0] + qx[3]; Y = qx[1] + qx[4]; VX = vx[0] + vx[3]; VY = vx[1] + vx[4];
    x = qx[0]; y = qx[1]; vxx = vx[0]; vyy = vx[1];
    q[2] = qx[2] + qx[5]; v[2] = vx[2] + vx[5]; q[5] = qx[2]; v[5] = vx[2];
  }
  R = hypot(X, Y);
  c = X / R;
  s = Y / R;
  w = (X * VY - Y * VX) / (R * R);
  xi = c * x + s * y;
  eta = -s * x + c * y;
  q[0] = R; q[1] = atan2(Y, X); q[3] = xi; q[4] = eta;
  v[0] = c * VX + s * VY; v[1] = w;
  v[3] = c * vxx + s * vyy + w * eta;
  v[4] = -s * vxx + c * vyy - w * xi;
}

/* positions q1, q2 (6) from a chart's shape point and group angle;
 * which == 0: the cylindrical chart of rs_dsp, x = (r1, r2, phi) */
static void positions(int which, const double *pv, const double *x, double th, double *P)
{
  double c = cos(th), s = sin(th);
  if (which == 0) {
    P[0] = x[0] * c; P[1] = x[0] * s; P[2] = -sqrt(pv[2] * pv[2] - x[0] * x[0]);
    P[3] = x[1] * cos(th + x[2]); P[4] = x[1] * sin(th + x[2]);
    P[5] = -sqrt(pv[3] * pv[3] - x[1] * x[1]);
  } else if (which == BOB1) {           /* x = (r1, z1, xi2, eta2, z2) */
    P[0] = x[0] * c; P[1] = x[0] * s; P[2] = x[1];
    P[3] = x[2] * c - x[3] * s; P[4] = x[2] * s + x[3] * c; P[5] = x[4];
  } else {                               /* x = (R, Z, xi1, eta1, z1) */
    P[0] = x[2] * c - x[3] * s; P[1] = x[2] * s + x[3] * c; P[2] = x[4];
    P[3] = x[0] * c - P[0]; P[4] = x[0] * s - P[1]; P[5] = x[1] - x[4];
  }
}

static double det(const double *A, size_t n)
{
  gsl_matrix *M = gsl_matrix_alloc(n, n);
  gsl_permutation *p = gsl_permutation_alloc(n);
  int sg;
  double d;
  memcpy(M->data, A, n * n * sizeof(double));
  gsl_linalg_LU_decomp(M, p, &sg);
  d = gsl_linalg_LU_det(M, sg);
  gsl_matrix_free(M);
  gsl_permutation_free(p);
  return d;
}

/* I, A, det Mtilde at two points, one of them near the singular set */
static void formulas(int which)
{
  rsys S;
  dm_routh *red = NULL;
  size_t cyc = 1;
  dm_err e;
  const char *nm = which == BOB1 ? "bob 1 polar" : "bob 2 polar";
  static const double X[2][5] = {{0.7385, -0.8210, 0.3127, -0.4711, -0.6915},
                                 {1e-3, -1.0999995, -0.2384, 0.5712, -0.6690}};
  double m1 = PV[0], m2 = PV[1], I, A[5], Mt[25], Ae[5], dI = 0, dA = 0, ratio[2];
  dm_routh_vals val;
  int k, i;
  chart_sys(&S, which, PV);
  if (!tap_is_int(rs_reduce(&S, 1, &cyc, NULL, &red, &e), DM_OK, "%s: reduced by the rotation", nm)) {
    tap_diag("%s", e.msg);
    dm_expr_ctx_free(S.c);
    return;
  }
  tap_ok(dm_routh_system(red)->n == 5 && dm_routh_system(red)->m == 2,
         "%s: preshape space of dimension 5 with 2 constraints", nm);
  for (k = 0; k < 2; k++) {
    const double *x = X[k];
    memset(&val, 0, sizeof val);
    val.I = &I;
    val.A = A;
    val.Mtilde = Mt;
    if (dm_routh_eval(red, x, NULL, &val, &e) != DM_OK) {
      tap_ok(0, "%s: eval: %s", nm, e.msg);
      continue;
    }
    memset(Ae, 0, sizeof Ae);
    if (which == BOB1) {   /* I = m1 r1^2 + m2 ((r1 + xi)^2 + eta^2), A = m2/I (-eta, 0, -eta, r1 + xi, 0) */
      double Ie = m1 * x[0] * x[0] + m2 * ((x[0] + x[2]) * (x[0] + x[2]) + x[3] * x[3]);
      Ae[0] = Ae[2] = -m2 * x[3] / Ie;
      Ae[3] = m2 * (x[0] + x[2]) / Ie;
      dI = fmax(dI, fabs(I - Ie) / Ie);
      ratio[k] = det(Mt, 5) * I / (x[0] * x[0] * pow(m1 * m2, 3));
    } else {               /* I = m1 (xi^2 + eta^2) + m2 R^2, A = m1/I (0, 0, -eta, xi, 0) */
      double Ie = m1 * (x[2] * x[2] + x[3] * x[3]) + m2 * x[0] * x[0];
      Ae[2] = -m1 * x[3] / Ie;
      Ae[3] = m1 * x[2] / Ie;
      dI = fmax(dI, fabs(I - Ie) / Ie);
      ratio[k] = det(Mt, 5) * I / (x[0] * x[0] * pow(m1 * m2, 3));
    }
    for (i = 0; i < 5; i++)
      dA = fmax(dA, fabs(A[i] - Ae[i]));
    if (k == 1)
      tap_ok(I > 0.25, "%s: at c = %g the locked inertia stays regular (I = %.4f): the action is "
             "free there", nm, x[0], I);
  }
  tap_ok(dI <= 1e-14 && dA <= 1e-14, "%s: I and A equal their closed forms (%.1g, %.1g)", nm, dI, dA);
  tap_ok(fabs(ratio[0] - 1) <= 1e-12 && fabs(ratio[1] - 1) <= 1e-9,
         "%s: det Mtilde = (m1 m2)^3 c^2 / I at c = %g and %g (ratios - 1: %.1g, %.1g): the chart is "
         "singular exactly at c = %s = 0", nm, X[0][0], X[1][0], ratio[0] - 1, ratio[1] - 1,
         which == BOB1 ? "r1" : "R");
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

typedef struct chart {
  rsys S;
  dm_routh *red;
  dm_integrator *I;
  double x[6], s[6], mu, th0;
  int which;
} chart;

/* the chart reduced, projected from the cylindrical data, Lobatto 3 on it */
static int chart_open(chart *C, int which, const double *pv, const double *Q, const double *V)
{
  double qx[6], vx[6], q[6], v[6];
  size_t cyc = 1;
  dm_integ_opts o;
  dm_err e;
  int st;
  memset(C, 0, sizeof *C);
  C->which = which;
  if (which == 0) {
    rs_dsp(&C->S, pv, 0);
    memcpy(q, Q, 4 * sizeof(double));
    memcpy(v, V, 4 * sizeof(double));
  } else {
    chart_sys(&C->S, which, pv);
    cartesian(pv, Q, V, qx, vx);
    chart_state(which, qx, vx, q, v);
  }
  st = rs_reduce(&C->S, 1, &cyc, NULL, &C->red, &e);
  if (st == DM_OK)
    st = dm_routh_project_qv(C->red, q, v, C->x, C->s, &C->mu, &C->th0, &e);
  if (st == DM_OK)
    st = dm_routh_set_mu(C->red, &C->mu, &e);
  dm_integ_opts_init(&o);
  o.stages = 3;
  if (st == DM_OK)
    st = dm_routh_integrator_new(C->red, "lobatto", &o, &C->I, &e);
  if (st == DM_OK)
    st = dm_routh_integrator_set_theta(C->I, &C->th0, &e);
  if (st != DM_OK)
    tap_diag("chart %d: %s", which, e.msg);
  return st;
}

static void chart_close(chart *C)
{
  dm_integrator_free(C->I);
  dm_routh_free(C->red);
  dm_expr_ctx_free(C->S.c);
}

static double chart_energy(chart *C, const double *x, const double *s)
{
  double v[6], E = NAN;
  dm_integrator_velocity(C->I, x, s, v, 0, NULL);
  dm_integrator_energy(C->I, x, v, &E, NULL);
  return E;
}

/* Theorem 2.14 for the new charts and the order of agreement in position space */
static void agreement(void)
{
  const double Q[4] = {0.6, 0.3, 0.5, 0.3}, V[4] = {0.1, 3.3, -0.1, 0.2};
  chart C[3];
  double hs[3], err[2][3];
  int k, c, st = DM_OK;
  for (c = 0; c < 3; c++)
    st |= chart_open(&C[c], c, PV, Q, V);
  if (!tap_ok(st == DM_OK, "three charts reduced and projected from one state")) {
    for (c = 0; c < 3; c++)
      chart_close(&C[c]);
    return;
  }
  tap_ok(fabs(C[1].mu - C[0].mu) <= 1e-14 * C[0].mu && fabs(C[2].mu - C[0].mu) <= 1e-14 * C[0].mu,
         "the same momentum in all charts: %.16g, %.16g, %.16g", C[0].mu, C[1].mu, C[2].mu);
  /* Theorem 2.14: reduced = projected unreduced, in the bob 1 polar chart */
  {
    dm_integrator *U = NULL;
    dm_integ_opts o;
    dm_err e;
    double qx[6], vx[6], q[6], v[6], p[6], x[5], s[5], xp[5], sp[5], mup, d = 0;
    dm_integ_opts_init(&o);
    o.stages = 3;
    st = dm_integrator_new(dm_routh_full(C[1].red), "lobatto", &o, &U, &e);
    cartesian(PV, Q, V, qx, vx);
    chart_state(BOB1, qx, vx, q, v);
    dm_integrator_momentum(U, q, v, p, NULL);
    memcpy(x, C[1].x, sizeof x);
    memcpy(s, C[1].s, sizeof s);
    for (k = 0; k < 200 && st == DM_OK; k++) {
      st = dm_integrator_step(C[1].I, 0.01, x, s, x, s, &e);
      st |= dm_integrator_step(U, 0.01, q, p, q, p, &e);
      dm_routh_project(C[1].red, q, p, xp, sp, &mup, NULL, NULL);
      for (c = 0; c < 5; c++)
        d = fmax(d, fmax(fabs(x[c] - xp[c]), fabs(s[c] - sp[c])));
    }
    tap_ok(st == DM_OK && d <= 1e-12, "bob 1 polar: constrained RSPRK = projected unreduced "
           "constrained Lobatto 3 over 200 steps (max diff %.2g)", d);
    dm_integrator_free(U);
  }
  /* positions at T = 1, h = 1/20, 1/40, 1/80 */
  for (k = 0; k < 3; k++) {
    long n = 20L << k;
    double P[3][6];
    hs[k] = 1.0 / (double)n;
    for (c = 0; c < 3; c++) {
      double x[5], s[5], th;
      memcpy(x, C[c].x, sizeof x);
      memcpy(s, C[c].s, sizeof s);
      dm_routh_integrator_set_theta(C[c].I, &C[c].th0, NULL);
      dm_integrator_run(C[c].I, 0, x, s, hs[k], n, n, NULL, NULL, NULL, NULL);
      dm_routh_integrator_theta(C[c].I, &th, NULL);
      positions(c, PV, x, th, P[c]);
    }
    err[0][k] = err[1][k] = 0;
    for (c = 0; c < 6; c++) {
      err[0][k] = fmax(err[0][k], fabs(P[1][c] - P[0][c]));
      err[1][k] = fmax(err[1][k], fabs(P[2][c] - P[0][c]));
    }
  }
  for (c = 0; c < 2; c++) {
    double sl = dm_integrator_order_fit(hs, err[c], 3);
    tap_ok(fabs(sl - 4) <= 0.2, "%s vs cylindrical chart, positions q1, q2 at T = 1 (theta "
           "reconstructed): difference shrinks with order %.2f (%.2g, %.2g, %.2g)",
           c ? "bob 2 polar" : "bob 1 polar", sl, err[c][0], err[c][1], err[c][2]);
  }
  for (c = 0; c < 3; c++)
    chart_close(&C[c]);
}

/* energy error at a close approach r2 -> 0 (t ~ 5.85, r2 = 0.033) and at an
 * r1 pass (t ~ 4.53, r1 = 0.10) of the example's motion */
static void passes(void)
{
  const double Q[4] = {0.67, 0.0, 0.36, 0.68}, V[4] = {-0.22, 1.2, 0.24, -0.61};
  chart C[3];
  double r2pass[3] = {0}, r1pass[3] = {0}, rmin[2] = {1, 1};
  int c, k, st = DM_OK;
  for (c = 0; c < 3; c++)
    st |= chart_open(&C[c], c, PU, Q, V);
  for (c = 0; c < 3 && st == DM_OK; c++) {
    double x[5], s[5], E0 = chart_energy(&C[c], C[c].x, C[c].s), Ev;
    dm_err e;
    memcpy(x, C[c].x, sizeof x);
    memcpy(s, C[c].s, sizeof s);
    for (k = 1; k <= 600 && st == DM_OK; k++) {
      double t = 0.01 * k;
      st = dm_integrator_step(C[c].I, 0.01, x, s, x, s, &e);
      if (st != DM_OK)
        tap_diag("chart %d, step %d: %s", c, k, e.msg);
      Ev = fabs(chart_energy(&C[c], x, s) / E0 - 1);
      if (t >= 5.75 && t <= 5.95)
        r2pass[c] = fmax(r2pass[c], Ev);
      if (t >= 4.3 && t <= 4.8)
        r1pass[c] = fmax(r1pass[c], Ev);
      if (c == 0 && t >= 5.75 && t <= 5.95)
        rmin[1] = fmin(rmin[1], x[1]);
      if (c == 0 && t >= 4.3 && t <= 4.8)
        rmin[0] = fmin(rmin[0], x[0]);
    }
  }
  if (!tap_ok(st == DM_OK, "the example's motion to t = 6 in three charts (Lobatto 3, h = 0.01)")) {
    for (c = 0; c < 3; c++)
      chart_close(&C[c]);
    return;
  }
  tap_ok(rmin[1] < 0.04 && rmin[0] > 0.09 && rmin[0] < 0.12,
         "the passes: r2 down to %.3f for t in [5.75, 5.95], r1 down to %.3f for t in [4.3, 4.8]",
         rmin[1], rmin[0]);
  tap_ok(r2pass[0] >= 1e-5 && r2pass[1] <= 1e-7 && r2pass[2] <= 1e-7,
         "r2 pass: max |dE/E| %.2g in the cylindrical chart, %.2g bob 1 polar, %.2g bob 2 polar",
         r2pass[0], r2pass[1], r2pass[2]);
  tap_ok(r1pass[1] >= 5 * r1pass[0] && r1pass[2] <= 1e-7,
         "r1 pass: the spike follows the singular set r1 = 0: %.2g bob 1 polar vs %.2g cylindrical, "
         "%.2g bob 2 polar", r1pass[1], r1pass[0], r1pass[2]);
  for (c = 0; c < 3; c++)
    chart_close(&C[c]);
}

int main(void)
{
  formulas(BOB1);
  formulas(BOB2);
  agreement();
  passes();
  return tap_done();
}
