/* test_conn_mech.c -- the discrete mechanical connection (src/conn): the
 * midpoint rule of a quadratic abelian Lagrangian (platform), the
 * Heisenberg holonomy = minus the shoelace area, a non-abelian rotor craft
 * (log-based discrete Lagrangian on SO(3)), the Kabsch rotation of free
 * particles, discrete Noether along DEL solutions and the prescribed-shape
 * DEL run reproducing the lift, the reduced discrete Lagrangian, Newton
 * failures. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_linalg.h>

#include "tap.h"
#include "conn_systems.h"
#include "conn/conn.h"
#include "core/smalllu.h"

static dm_expr_ctx *cx;
#define K(x) dm_expr_const(cx, (x))
#define ADD(a, b) dm_expr_add(cx, (a), (b))
#define SUB(a, b) dm_expr_sub(cx, (a), (b))
#define MUL(a, b) dm_expr_mul(cx, (a), (b))
#define DIV(a, b) dm_expr_div(cx, (a), (b))
#define SQ(a) dm_expr_mul(cx, (a), (a))

static double urand(void)
{
  return 2.0 * rand() / (double)RAND_MAX - 1.0;
}

static void syms(const char *pre, size_t n, dm_expr *out)
{
  char name[32];
  size_t i;
  for (i = 0; i < n; i++) {
    snprintf(name, sizeof name, "%s%zu", pre, i + 1);
    out[i] = dm_expr_sym(cx, name);
  }
}

/* L_d = h L(qbar, dq/h) for a Lagrangian given as a function of (q, v) nodes */
typedef dm_expr (*lag_fn)(const dm_expr *q, const dm_expr *v, const dm_expr *par);

static dm_expr midpoint_Ld(lag_fn L, size_t n, const dm_expr *q0, const dm_expr *q1,
                           const dm_expr *par, double h)
{
  dm_expr qb[16], v[16];
  size_t i;
  for (i = 0; i < n; i++) {
    qb[i] = MUL(K(0.5), ADD(q0[i], q1[i]));
    v[i] = DIV(SUB(q1[i], q0[i]), K(h));
  }
  return MUL(K(h), L(qb, v, par));
}

/* platform: q = (u, v, theta), par = (I, m) */
static dm_expr plat_L(const dm_expr *q, const dm_expr *v, const dm_expr *p)
{
  dm_expr a = SUB(v[0], MUL(v[2], q[1])), b = ADD(v[1], MUL(v[2], q[0]));
  return ADD(MUL(MUL(K(0.5), p[0]), SQ(v[2])), MUL(MUL(K(0.5), p[1]), ADD(SQ(a), SQ(b))));
}

/* Heisenberg: L = (xd^2 + yd^2)/2 + (zd + (x yd - y xd)/2)^2/2 */
static dm_expr heis_L(const dm_expr *q, const dm_expr *v, const dm_expr *p)
{
  dm_expr w = ADD(v[2], MUL(K(0.5), SUB(MUL(q[0], v[1]), MUL(q[1], v[0]))));
  (void)p;
  return MUL(K(0.5), ADD(ADD(SQ(v[0]), SQ(v[1])), SQ(w)));
}

static void test_platform(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  plat_par pp = {2.385, 0.7};
  dm_conn *C = dm_conn_alloc(B, plat_A, &pp, 1, NULL, NULL);
  dm_conn_dc *M = dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), B, C, NULL, NULL, NULL), *D;
  dm_expr q0[3], q1[3], par[2], Ld;
  double pv[2] = {2.385, 0.7}, x0[2], x1[2], a, b, worst = 0.0, J, qa[3], qb[3], z[1], y0[2],
         y1[2], ld, Ldv, vals[8];
  unsigned long solves, iters;
  dm_expr all[8];
  int k;
  dm_err e;
  syms("p0_", 3, q0);
  syms("p1_", 3, q1);
  par[0] = dm_expr_param(cx, "I");
  par[1] = dm_expr_param(cx, "m");
  Ld = midpoint_Ld(plat_L, 3, q0, q1, par, 0.1);
  D = dm_conn_dc_mechanical(B, cx, q0, q1, Ld, 2, par, pv, M, 0, 0, &e);
  tap_ok(D != NULL, "platform: discrete mechanical connection built%s%s", D ? "" : ": ",
         D ? "" : e.msg);
  for (k = 0; k < 40; k++) {
    x0[0] = urand(); x0[1] = urand();
    x1[0] = x0[0] + 0.5 * urand(); x1[1] = x0[1] + 0.5 * urand();
    dm_conn_dc_local(D, x0, x1, &a, NULL);
    dm_conn_dc_local(M, x0, x1, &b, NULL);
    worst = fmax(worst, fabs(a - b));
  }
  tap_ok(worst < 1e-13, "platform: mechanical = midpoint for the quadratic abelian L (%.1e)", worst);
  dm_conn_dc_newton_stats(D, &solves, &iters);
  tap_ok(solves == 40 && iters <= 2 * solves, "platform: %lu Newton iterations for %lu pairs "
         "from the midpoint guess", iters, solves);
  /* the momentum vanishes on horizontal pairs, and J_d = -D1 Ld . xi_Q(q0) */
  qa[0] = 0.3; qa[1] = -0.2; qa[2] = 1.0;
  x1[0] = 0.5; x1[1] = 0.4;
  dm_conn_dc_hlift(D, qa, x1, qb, NULL);
  dm_conn_dc_momentum(D, qa, qb, &J, NULL);
  tap_ok(fabs(J) < 1e-13, "platform: J_d = 0 on the horizontal lift (%.1e)", J);
  /* the reduced discrete Lagrangian: l_d(reduce(q0, q1)) = L_d(q0, q1), any g0 */
  qb[2] = 0.4;
  dm_conn_dc_reduce(D, qa, qb, y0, y1, z, NULL);
  dm_conn_dc_local(D, y0, y1, &a, NULL);
  memcpy(all, q0, sizeof q0);
  memcpy(all + 3, q1, sizeof q1);
  all[6] = par[0];
  all[7] = par[1];
  memcpy(vals, qa, 3 * sizeof *vals);
  memcpy(vals + 3, qb, 3 * sizeof *vals);
  vals[6] = pv[0];
  vals[7] = pv[1];
  dm_expr_eval(cx, 1, &Ld, &Ldv, 8, all, vals, NULL);
  vals[0] = y0[0]; vals[1] = y0[1]; vals[2] = 0.0;
  vals[3] = y1[0]; vals[4] = y1[1]; vals[5] = z[0] - a;     /* (x1, zeta A^-1) */
  dm_expr_eval(cx, 1, &Ld, &ld, 8, all, vals, NULL);
  tap_near(ld, Ldv, 1e-14, "reduced discrete Lagrangian: l_d(x0, x1, zeta) = L_d(q0, q1)");
  tap_ok(dm_conn_dc_set_mu(D, &J, &e) == DM_OK, "set_mu on an abelian group");
  dm_conn_dc_free(D);
  dm_conn_dc_free(M);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

static void test_heisenberg(void)
{
  dm_lie_group *G = dm_lie_rn(1, NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_expr q0[3], q1[3], Ld;
  dm_conn_dc *D;
  double sq[10] = {0, 0, 1, 0, 1, 1, 0, 1, 0, 0}, hex[14], qs[3] = {0, 0, 0.3}, S, P, lifted,
         x0[2] = {0.3, -1.1}, x1[2] = {0.7, 0.25}, A;
  int k;
  syms("h0_", 3, q0);
  syms("h1_", 3, q1);
  Ld = midpoint_Ld(heis_L, 3, q0, q1, NULL, 0.25);
  D = dm_conn_dc_mechanical(B, cx, q0, q1, Ld, 0, NULL, NULL, NULL, 0, 0, NULL);
  dm_conn_dc_local(D, x0, x1, &A, NULL);
  tap_near(-A, -0.5 * (x0[0] * x1[1] - x1[0] * x0[1]), 1e-15,
           "Heisenberg: dz = -(x0 y1 - x1 y0)/2 per step");
  dm_conn_dc_holonomy(D, sq, 5, qs, &S, &P, &lifted, NULL);
  tap_near(P, -1.0, 1e-14, "Heisenberg: unit square -> -1 (minus the area)");
  for (k = 0; k <= 6; k++) {
    hex[2 * k] = cos(2 * M_PI * k / 6);
    hex[2 * k + 1] = sin(2 * M_PI * k / 6);
  }
  hex[12] = hex[0];
  hex[13] = hex[1];
  qs[0] = 1.0;
  dm_conn_dc_holonomy(D, hex, 7, qs, &S, &P, &lifted, NULL);
  tap_near(P, -2.5980762113533156, 1e-14, "Heisenberg: regular hexagon -> -(N/2) sin(2 pi/N)");
  dm_conn_dc_free(D);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* rotor craft on T^3 x SO(3): L_d = h [1/2 w^T (II - K) w + 1/2 sum k_i (w_i + dphi_i/h)^2],
 * w = vee(log(R0^T R1))/h.  Horizontal: II w + K dphi/h = 0, so
 * A(phi0, phi1) = exp(II^-1 K dphi) exactly. */
static void test_rotor(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(3, G, NULL);
  const double II[3] = {2.0, 3.0, 4.5}, kk[3] = {0.2, 0.6, 0.45}, h = 0.1;
  dm_expr q0[12], q1[12], R0t[9], F[9], w[3], Ld = K(0.0);
  double x0[3] = {0.1, -0.3, 0.2}, x1[3] = {0.5, 0.2, -0.4}, A[9], Ae[9], u[3], qa[12], qb[12],
         r[3] = {0.3, -0.8, 0.5}, J[3];
  unsigned long solves, iters;
  dm_conn_dc *D;
  dm_err e;
  int i;
  syms("r0_", 12, q0);
  syms("r1_", 12, q1);
  dm_lie_sym_inverse(cx, G, q0 + 3, R0t, NULL);
  dm_lie_sym_compose(cx, G, R0t, q1 + 3, F, NULL);
  dm_lie_sym_log(cx, G, F, w, NULL);
  for (i = 0; i < 3; i++) {
    dm_expr wi = DIV(w[i], K(h)), dp = DIV(SUB(q1[i], q0[i]), K(h));
    Ld = ADD(Ld, MUL(K(0.5 * h * (II[i] - kk[i])), SQ(wi)));
    Ld = ADD(Ld, MUL(K(0.5 * h * kk[i]), SQ(ADD(wi, dp))));
  }
  D = dm_conn_dc_mechanical(B, cx, q0, q1, Ld, 0, NULL, NULL, NULL, 0, 0, &e);
  tap_ok(D != NULL, "rotor craft: discrete mechanical connection from a log-based L_d%s%s",
         D ? "" : ": ", D ? "" : e.msg);
  dm_conn_dc_local(D, x0, x1, A, NULL);
  for (i = 0; i < 3; i++)
    u[i] = kk[i] / II[i] * (x1[i] - x0[i]);
  dm_lie_exp(G, u, Ae);
  tap_ok(dm_lie_dist(G, A, Ae) < 1e-13, "rotor craft: mechanical A = exp(II^-1 K dphi) (%.1e)",
         dm_lie_dist(G, A, Ae));
  dm_conn_dc_newton_stats(D, &solves, &iters);
  tap_ok(iters >= 2 && iters <= 6, "rotor craft: Newton from the identity took %lu iterations",
         iters);
  memcpy(qa, x0, sizeof x0);
  dm_lie_exp(G, r, qa + 3);
  dm_conn_dc_hlift(D, qa, x1, qb, NULL);
  dm_conn_dc_momentum(D, qa, qb, J, NULL);
  tap_ok(fabs(J[0]) + fabs(J[1]) + fabs(J[2]) < 1e-12, "rotor craft: J_d = 0 on the lift");
  J[0] = J[1] = J[2] = 0.0;
  tap_ok(dm_conn_dc_set_mu(D, J, &e) == DM_OK, "set_mu(0) on SO(3) is allowed");
  J[1] = 0.1;
  tap_ok(dm_conn_dc_set_mu(D, J, &e) == DM_EUNSUP && strstr(e.msg, "abelian"),
         "set_mu(nonzero) on SO(3) refused: %s", e.msg);
  dm_conn_dc_free(D);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* Kabsch: R minimizing sum m_i |R y_i - x_i|^2 by the SVD of H = sum m_i y_i x_i^T */
static void kabsch(size_t n, const double *m, const double *X, const double *Y, double *R)
{
  gsl_matrix *H = gsl_matrix_calloc(3, 3), *V = gsl_matrix_alloc(3, 3);
  gsl_vector *S = gsl_vector_alloc(3), *w = gsl_vector_alloc(3);
  double d, U[9], Vm[9];
  size_t i, a, b, k;
  for (i = 0; i < n; i++)
    for (a = 0; a < 3; a++)
      for (b = 0; b < 3; b++)
        *gsl_matrix_ptr(H, a, b) += m[i] * Y[3 * i + a] * X[3 * i + b];
  gsl_linalg_SV_decomp(H, V, S, w);           /* H = U S V^T, U in H */
  for (a = 0; a < 9; a++) {
    U[a] = gsl_matrix_get(H, a / 3, a % 3);
    Vm[a] = gsl_matrix_get(V, a / 3, a % 3);
  }
  d = (Vm[0] * (Vm[4] * Vm[8] - Vm[5] * Vm[7]) - Vm[1] * (Vm[3] * Vm[8] - Vm[5] * Vm[6]) +
       Vm[2] * (Vm[3] * Vm[7] - Vm[4] * Vm[6])) *
      (U[0] * (U[4] * U[8] - U[5] * U[7]) - U[1] * (U[3] * U[8] - U[5] * U[6]) +
       U[2] * (U[3] * U[7] - U[4] * U[6]));
  for (a = 0; a < 3; a++)
    for (b = 0; b < 3; b++) {
      double s = 0.0;
      for (k = 0; k < 3; k++)
        s += Vm[3 * a + k] * (k == 2 && d < 0 ? -1.0 : 1.0) * U[3 * b + k];
      R[3 * a + b] = s;
    }
  gsl_matrix_free(H);
  gsl_matrix_free(V);
  gsl_vector_free(S);
  gsl_vector_free(w);
}

static void test_particles(void)
{
  const size_t n = 4;
  dm_conn_bundle *B = dm_conn_bundle_particles(n, NULL);
  const dm_lie_group *G = B->G;
  dm_expr x[12], y[12], Ld = K(0.0), mp[4];
  double m[4] = {1.0, 2.385, 0.7, 1.6}, X[12], Y[12], R[9], Ad[9], Ai[9], w[3], worst = 0.0,
         J[3], Jw[3], Z[12], h = 0.1;
  unsigned long solves, iters;
  dm_conn_dc *D, *D1;
  dm_err e;
  size_t i, a;
  int k;
  syms("x", 12, x);
  syms("y", 12, y);
  for (i = 0; i < n; i++) {
    char nm[8];
    snprintf(nm, sizeof nm, "m%zu", i + 1);
    mp[i] = dm_expr_param(cx, nm);
    for (a = 0; a < 3; a++)
      Ld = ADD(Ld, MUL(DIV(mp[i], K(2 * h)), SQ(SUB(y[3 * i + a], x[3 * i + a]))));
  }
  D = dm_conn_dc_mechanical(B, cx, x, y, Ld, n, mp, m, NULL, 0, 0, &e);
  tap_ok(D != NULL, "particles: discrete mechanical connection built");
  for (k = 0; k < 20; k++) {
    for (i = 0; i < 12; i++)
      X[i] = urand();
    w[0] = 0.8 * urand(); w[1] = 0.8 * urand(); w[2] = 0.8 * urand();
    dm_lie_exp(G, w, R);
    for (i = 0; i < n; i++) {
      dm_lie_act(G, R, X + 3 * i, Y + 3 * i);
      for (a = 0; a < 3; a++)
        Y[3 * i + a] += 0.2 * urand();
    }
    dm_conn_dc_eval(D, X, Y, Ad, NULL);
    dm_lie_inverse(G, Ad, Ai);
    kabsch(n, m, X, Y, R);
    worst = fmax(worst, dm_lie_dist(G, Ai, R));
  }
  tap_ok(worst < 1e-12, "particles: A_d^-1 = the Kabsch rotation (%.1e)", worst);
  dm_conn_dc_newton_stats(D, &solves, &iters);
  tap_diag("particles: %lu solves, %lu Newton iterations", solves, iters);
  /* J_d(X, Y) = (1/h) sum m_i x_i x y_i */
  dm_conn_dc_momentum(D, X, Y, J, NULL);
  Jw[0] = Jw[1] = Jw[2] = 0.0;
  for (i = 0; i < n; i++) {
    const double *p = X + 3 * i, *q = Y + 3 * i;
    Jw[0] += m[i] / h * (p[1] * q[2] - p[2] * q[1]);
    Jw[1] += m[i] / h * (p[2] * q[0] - p[0] * q[2]);
    Jw[2] += m[i] / h * (p[0] * q[1] - p[1] * q[0]);
  }
  tap_ok(fabs(J[0] - Jw[0]) + fabs(J[1] - Jw[1]) + fabs(J[2] - Jw[2]) < 1e-12,
         "particles: J_d = (1/h) sum m_i x_i x y_i");
  /* Newton failures: collinear particles (not group-regular), too few iterations */
  for (i = 0; i < n; i++) {
    X[3 * i] = 1.0 + (double)i;
    X[3 * i + 1] = X[3 * i + 2] = 0.0;
    Z[3 * i] = 0.5 + (double)i;
    Z[3 * i + 1] = 0.1 * (double)i;
    Z[3 * i + 2] = 0.0;
  }
  tap_ok(dm_conn_dc_eval(D, X, Z, Ad, &e) == DM_ESINGULAR && strstr(e.msg, "group-regular"),
         "collinear particles: %s", e.msg);
  D1 = dm_conn_dc_mechanical(B, cx, x, y, Ld, n, mp, m, NULL, 1e-15, 2, NULL);
  for (i = 0; i < 12; i++)
    X[i] = urand(), Y[i] = urand();
  tap_ok(dm_conn_dc_eval(D1, X, Y, Ad, &e) == DM_ENOCONV && strstr(e.msg, "did not converge in 2"),
         "two Newton iterations are not enough: %s", e.msg);
  dm_conn_dc_free(D);
  dm_conn_dc_free(D1);
  dm_conn_bundle_free(B);
}

/* DEL solutions of the platform's midpoint L_d keep J_d; with the shape
 * prescribed and J_d = 0, the group equation reproduces the lift */
typedef struct del {
  dm_expr q0[3], q1[3], q2[3], par[2];
  dm_expr F[3], JF[9];          /* D2 Ld(q0, q1) + D1 Ld(q1, q2), d/dq2 */
  dm_expr G1, dG1;              /* group part, d/dtheta2 */
} del;

static void del_build(del *d, dm_expr Ld01, dm_expr Ld12)
{
  dm_expr g01[3], g12[3];
  size_t i, j;
  dm_expr_grad(cx, Ld01, 3, d->q1, g01, NULL);
  dm_expr_grad(cx, Ld12, 3, d->q1, g12, NULL);
  for (i = 0; i < 3; i++) {
    d->F[i] = ADD(g01[i], g12[i]);
    for (j = 0; j < 3; j++)
      d->JF[3 * i + j] = dm_expr_diff(cx, d->F[i], d->q2[j]);
  }
  d->G1 = d->F[2];
  d->dG1 = dm_expr_diff(cx, d->G1, d->q2[2]);
}

static void del_eval(del *d, size_t ne, const dm_expr *ex, double *out, const double *a,
                     const double *b, const double *c, const double *pv)
{
  dm_expr vars[11];
  double vals[11];
  memcpy(vars, d->q0, sizeof d->q0);
  memcpy(vars + 3, d->q1, sizeof d->q1);
  memcpy(vars + 6, d->q2, sizeof d->q2);
  vars[9] = d->par[0];
  vars[10] = d->par[1];
  memcpy(vals, a, 3 * sizeof *a);
  memcpy(vals + 3, b, 3 * sizeof *b);
  memcpy(vals + 6, c, 3 * sizeof *c);
  vals[9] = pv[0];
  vals[10] = pv[1];
  dm_expr_eval(cx, ne, ex, out, 11, vars, vals, NULL);
}

static void test_noether(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  del d;
  dm_conn_dc *D;
  double pv[2] = {2.385, 0.7}, q[40][3], J0, J, worst = 0.0, F[3], JF[9], xs[40][2], qs[40][3],
         dev = 0.0, g, dg;
  size_t perm[3];
  int k, it, i;
  dm_expr Ld01, Ld12;
  syms("n0_", 3, d.q0);
  syms("n1_", 3, d.q1);
  syms("n2_", 3, d.q2);
  d.par[0] = dm_expr_param(cx, "I");
  d.par[1] = dm_expr_param(cx, "m");
  Ld01 = midpoint_Ld(plat_L, 3, d.q0, d.q1, d.par, 0.1);
  Ld12 = midpoint_Ld(plat_L, 3, d.q1, d.q2, d.par, 0.1);
  del_build(&d, Ld01, Ld12);
  D = dm_conn_dc_mechanical(B, cx, d.q0, d.q1, Ld01, 2, d.par, pv, NULL, 0, 0, NULL);
  /* a free DEL run from two points with nonzero momentum */
  q[0][0] = 0.4; q[0][1] = -0.3; q[0][2] = 0.1;
  q[1][0] = 0.45; q[1][1] = -0.25; q[1][2] = 0.18;
  dm_conn_dc_momentum(D, q[0], q[1], &J0, NULL);
  for (k = 1; k + 1 < 40; k++) {
    memcpy(q[k + 1], q[k], sizeof q[k]);
    for (i = 0; i < 3; i++)
      q[k + 1][i] += q[k][i] - q[k - 1][i];
    for (it = 0; it < 20; it++) {
      del_eval(&d, 3, d.F, F, q[k - 1], q[k], q[k + 1], pv);
      del_eval(&d, 9, d.JF, JF, q[k - 1], q[k], q[k + 1], pv);
      dm_smalllu_factor(JF, 3, perm);
      dm_smalllu_solve(JF, 3, perm, F);
      for (i = 0; i < 3; i++)
        q[k + 1][i] -= F[i];
      if (fabs(F[0]) + fabs(F[1]) + fabs(F[2]) < 1e-15)
        break;
    }
    dm_conn_dc_momentum(D, q[k], q[k + 1], &J, NULL);
    worst = fmax(worst, fabs(J - J0));
  }
  tap_ok(worst < 1e-13 && fabs(J0) > 0.1, "discrete Noether: J_d = %.6f constant along a DEL run "
         "(%.1e)", J0, worst);
  /* the shape prescribed, the group equation D2 Ld(q0, q1) + D1 Ld(q1, q2) = 0
   * (group part) solved for theta2, from a horizontal first pair */
  for (k = 0; k < 40; k++) {
    xs[k][0] = 0.6 * cos(0.2 * k);
    xs[k][1] = 0.3 * sin(0.37 * k);
  }
  qs[0][0] = xs[0][0]; qs[0][1] = xs[0][1]; qs[0][2] = 0.5;
  dm_conn_dc_lift(D, &xs[0][0], 40, qs[0], &qs[0][0], NULL);
  memcpy(q[0], qs[0], sizeof q[0]);
  memcpy(q[1], qs[1], sizeof q[1]);
  for (k = 1; k + 1 < 40; k++) {
    q[k + 1][0] = xs[k + 1][0];
    q[k + 1][1] = xs[k + 1][1];
    q[k + 1][2] = 2 * q[k][2] - q[k - 1][2];
    for (it = 0; it < 20; it++) {
      del_eval(&d, 1, &d.G1, &g, q[k - 1], q[k], q[k + 1], pv);
      del_eval(&d, 1, &d.dG1, &dg, q[k - 1], q[k], q[k + 1], pv);
      q[k + 1][2] -= g / dg;
      if (fabs(g / dg) < 1e-16)
        break;
    }
    dev = fmax(dev, fabs(q[k + 1][2] - qs[k + 1][2]));
  }
  tap_ok(dev < 1e-13, "prescribed shape: the group DEL equation reproduces lift() (%.1e)", dev);
  dm_conn_dc_free(D);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* free particles on the axes, +-(1,0,0), +-(0,2,0), +-(0,0,3), and Y = R X,
 * R the rotation by pi about e1: H = sum y x^T = R C is symmetric, so k = e
 * is a critical point of k -> sum |k y - x|^2 -- a saddle, not the minimum
 * k = R^-1.  Newton from the identity sits there: an error, not a silent
 * flip.  With R off by round-off the regularized steps escape to the
 * minimum. */
static void test_saddle(void)
{
  dm_conn_bundle *B = dm_conn_bundle_particles(6, NULL);
  const dm_lie_group *G = B->G;
  dm_expr x[18], y[18], Ld = K(0.0);
  double X[18] = {1, 0, 0, 0, 2, 0, 0, 0, 3, -1, 0, 0, 0, -2, 0, 0, 0, -3}, Y[18], R[9], A[9],
         w[3] = {M_PI, 0, 0};
  dm_conn_dc *D;
  dm_err e;
  int i;
  syms("sx", 18, x);
  syms("sy", 18, y);
  for (i = 0; i < 18; i++)
    Ld = ADD(Ld, MUL(K(5.0), SQ(SUB(y[i], x[i]))));
  D = dm_conn_dc_mechanical(B, cx, x, y, Ld, 0, NULL, NULL, NULL, 0, 0, &e);
  memset(R, 0, sizeof R);
  R[0] = 1.0;
  R[4] = R[8] = -1.0;
  for (i = 0; i < 6; i++)
    dm_lie_act(G, R, X + 3 * i, Y + 3 * i);
  tap_ok(dm_conn_dc_eval(D, X, Y, A, &e) == DM_ENOCONV && strstr(e.msg, "saddle"),
         "particles: a pair on a saddle of k -> Ld(q0, k q1) is an error: %s", e.msg);
  dm_lie_exp(G, w, R);                  /* the same up to round-off */
  R[1] += 1e-9;
  dm_lie_normalize(G, R);
  for (i = 0; i < 6; i++)
    dm_lie_act(G, R, X + 3 * i, Y + 3 * i);
  i = dm_conn_dc_eval(D, X, Y, A, NULL);
  tap_ok(i == DM_OK && dm_lie_dist(G, A, R) < 1e-12,
         "particles: next to the saddle the regularized steps reach the minimum (%.1e)",
         dm_lie_dist(G, A, R));
  dm_conn_dc_free(D);
  dm_conn_bundle_free(B);
}

static void test_errors(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *S = dm_conn_bundle_sphere_frames(NULL), *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn_dc *T = dm_conn_dc_alloc(dm_conn_rule_find("trivial"), B, NULL, NULL, NULL, NULL);
  dm_expr q0[9], q1[9];
  double J, qq[3] = {0, 0, 0};
  dm_err e;
  syms("s0_", 9, q0);
  syms("s1_", 9, q1);
  tap_ok(dm_conn_dc_mechanical(S, cx, q0, q1, q0[0], 0, NULL, NULL, NULL, 0, 0, &e) == NULL &&
         e.status == DM_EUNSUP, "mechanical on the sphere frames: %s", e.msg);
  tap_ok(dm_conn_dc_momentum(T, qq, qq, &J, &e) == DM_EINVAL &&
         strstr(e.msg, "not a discrete mechanical"), "momentum of a trivial connection: %s", e.msg);
  dm_conn_dc_free(T);
  dm_conn_bundle_free(S);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

int main(void)
{
  dm_gsl_init();
  srand(77);
  cx = dm_expr_ctx_alloc();
  test_platform();
  test_heisenberg();
  test_rotor();
  test_particles();
  test_noether();
  test_saddle();
  test_errors();
  dm_expr_ctx_free(cx);
  return tap_done();
}
