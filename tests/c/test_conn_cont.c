/* test_conn_cont.c -- bundles and continuous connections (src/conn):
 * bundle actions and fibre differences, the platform curvature (closed
 * form), the rotor craft's curvature and square-loop holonomy (product of
 * exponentials), continuous transport around the annular sector, Magnus
 * order 4, shrinking loops -> curvature, gauge independence, connections
 * from expressions and from a Lagrangian, error paths.  Reference values:
 * tests/data/conn/reference.py. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "conn_systems.h"
#include "conn/conn.h"

static double urand(void)
{
  return 2.0 * rand() / (double)RAND_MAX - 1.0;
}

static double maxdiff(const double *a, const double *b, size_t n)
{
  double d = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

static void test_bundles(void)
{
  dm_err e;
  dm_lie_group *SO3 = dm_lie_so3(NULL);
  dm_conn_bundle *T = dm_conn_bundle_trivial(2, SO3, &e), *S = dm_conn_bundle_sphere_frames(&e),
                 *P = dm_conn_bundle_particles(3, &e);
  double w[3] = {0.4, -0.7, 1.1}, h[9], q[11], hq[11], g[9], x[9], gg[9], R[9], th, pq[9], r[9];
  int i;
  tap_ok(T && S && P, "bundles built: %s | %s | %s", T->name, S->name, P->name);
  dm_lie_exp(SO3, w, h);
  q[0] = 2.385;
  q[1] = -0.5;
  w[0] = 0.3;
  dm_lie_exp(SO3, w, q + 2);
  dm_conn_act(T, h, q, hq);
  dm_conn_fiber_diff(T, q, hq, g, &e);
  tap_ok(maxdiff(g, h, 9) < 1e-14 && hq[0] == q[0] && hq[1] == q[1],
         "trivial: fiber_diff(q, h.q) = h, shape unchanged");
  /* sphere frames: theta.R = R Rz(theta), p = R e3 fixed */
  dm_lie_exp(SO3, w, R);
  th = 2.1;
  dm_conn_act(S, &th, R, pq);
  dm_conn_fiber_diff(S, R, pq, g, &e);
  dm_conn_proj(S, R, x);
  dm_conn_proj(S, pq, x + 3);
  tap_near(g[0], 2.1, 1e-14, "sphere frames: fiber_diff recovers the angle");
  tap_ok(maxdiff(x, x + 3, 3) < 1e-15, "sphere frames: the action keeps p = R e3");
  tap_ok(dm_conn_section(S, x, pq, &e) == DM_EUNSUP && strstr(e.msg, "no global section"),
         "sphere frames: no global section (%s)", e.msg);
  /* particles: fibre difference and trivialization */
  for (i = 0; i < 9; i++)
    r[i] = urand();
  dm_conn_act(P, h, r, pq);
  tap_ok(dm_conn_fiber_diff(P, r, pq, g, &e) == DM_OK && maxdiff(g, h, 9) < 1e-13,
         "particles: fiber_diff(q, R q) = R");
  dm_conn_trivialize(P, r, x, gg, &e);
  dm_conn_act(P, gg, x, pq);
  tap_ok(maxdiff(pq, r, 9) < 1e-14, "particles: q = g . section(x) for (x, g) = trivialize(q)");
  dm_conn_proj(P, pq, pq);
  tap_ok(maxdiff(pq, x, 9) < 1e-14 && fabs(x[1]) + fabs(x[2]) + fabs(x[5]) < 1e-15 && x[4] > 0,
         "particles: the shape is the canonical representative");
  r[3] = 2 * r[0];
  r[4] = 2 * r[1];
  r[5] = 2 * r[2];
  tap_ok(dm_conn_shape_check(P, r, "point", &e) == DM_EDOM && strstr(e.msg, "collinear"),
         "particles: collinear configuration refused (%s)", e.msg);
  tap_ok(dm_conn_bundle_particles(1, &e) == NULL && e.status == DM_EINVAL,
         "particles: n = 1 refused (%s)", e.msg);
  x[0] = 0.6;
  x[1] = 0.0;
  x[2] = 0.81;
  tap_ok(dm_conn_shape_check(S, x, "p", &e) == DM_EDOM && strstr(e.msg, "unit sphere"),
         "sphere frames: a point off the sphere refused (%s)", e.msg);
  dm_conn_bundle_free(T);
  dm_conn_bundle_free(S);
  dm_conn_bundle_free(P);
  dm_conn_bundle_free(NULL);
  dm_lie_group_free(SO3);
}

/* platform curvature dA = 2 m I/(I + m rho^2)^2, by finite
 * differences (1e-7) and exactly */
static void test_platform_curvature(void)
{
  dm_lie_group *SO2 = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, SO2, NULL);
  plat_par p = {2.385, 0.7};
  dm_conn *Cfd = dm_conn_alloc(B, plat_A, &p, 0, NULL, NULL),
          *Cex = dm_conn_alloc(B, plat_A, &p, 1, NULL, NULL);
  double x[2], b1, b2, D, worst1 = 0.0, worst2 = 0.0;
  int k;
  for (k = 0; k < 20; k++) {
    x[0] = 2.0 * urand();
    x[1] = 2.0 * urand();
    D = p.I + p.m * (x[0] * x[0] + x[1] * x[1]);
    dm_conn_curvature(Cfd, x, 0, 1, &b1, NULL);
    dm_conn_curvature(Cex, x, 0, 1, &b2, NULL);
    worst1 = fmax(worst1, fabs(b1 - 2 * p.m * p.I / (D * D)));
    worst2 = fmax(worst2, fabs(b2 - 2 * p.m * p.I / (D * D)));
  }
  tap_ok(worst1 < 1e-7, "platform: finite-difference curvature = 2 m I/(I + m rho^2)^2 "
         "(max error %.2e)", worst1);
  tap_ok(worst2 < 1e-14, "platform: exact curvature (max error %.2e)", worst2);
  dm_conn_curvature(Cex, x, 1, 0, &b1, NULL);
  tap_near(b1, -b2, 1e-15, "curvature is antisymmetric");
  dm_conn_free(Cfd);
  dm_conn_free(Cex);
  dm_conn_bundle_free(B);
  dm_lie_group_free(SO2);
}

/* rotor craft, B(e1, e2) = -(u1 x u2)^; square loop holonomy */
static void test_rotor(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(3, G, NULL);
  rotor_par p = {{0.1, 0.2, 0.3}};
  dm_conn *C = dm_conn_alloc(B, rotor_A, &p, 1, NULL, NULL);
  double x[3] = {0.3, -1.2, 2.0}, b[3], q0[12], P[9], S[9], w[3], E[4][9], prod[9], t[9];
  double loop[15], ratio[2];
  const double ref[3] = {-0.00199005466931, 0.00099253561449, 0.0198341672719};
  dm_conn_topts o = {1, 0.0};
  int k, i;
  dm_conn_curvature(C, x, 0, 1, b, NULL);
  tap_ok(fabs(b[0]) + fabs(b[1]) < 1e-16 && fabs(b[2] + 0.02) < 1e-16,
         "rotor: B(e1, e2) = -(u1 x u2) = (0, 0, -0.02)");
  for (k = 0; k < 3; k++) {
    double a = k == 0 ? 1.0 : (k == 1 ? 0.1 : 0.01);
    double pts[5][3] = {{0, 0, 0}, {a, 0, 0}, {a, a, 0}, {0, a, 0}, {0, 0, 0}};
    memcpy(loop, pts, sizeof pts);
    memset(q0, 0, sizeof q0);
    dm_lie_identity(G, q0 + 3);
    dm_conn_holonomy_polygon(C, loop, 5, q0, &o, S, P, NULL);
    /* exp(-a u1) exp(-a u2) exp(a u1) exp(a u2) */
    for (i = 0; i < 4; i++) {
      w[0] = w[1] = w[2] = 0.0;
      w[i % 2] = (i < 2 ? -a : a) * p.c[i % 2];
      dm_lie_exp(G, w, E[i]);
    }
    dm_lie_compose(G, E[0], E[1], t);
    dm_lie_compose(G, t, E[2], prod);
    dm_lie_compose(G, prod, E[3], prod);
    if (k == 0) {
      tap_ok(maxdiff(P, prod, 9) < 1e-15, "rotor: square loop holonomy = product of exponentials");
      dm_lie_log(G, P, w);
      tap_ok(maxdiff(w, ref, 3) < 1e-13, "rotor: log P at a = b = 1 = (%.7g, %.7g, %.7g)", w[0],
             w[1], w[2]);
    } else {
      dm_lie_log(G, P, w);
      w[2] -= 0.02 * a * a;
      ratio[k - 1] = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) / (a * a);
    }
  }
  tap_ok(ratio[0] / ratio[1] > 9.9 && ratio[1] < 2.3e-5,
         "rotor: |log P/(ab) - (0, 0, 0.02)| = %.2e, %.2e at a = 0.1, 0.01 (O(a))", ratio[0],
         ratio[1]);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the four pieces of the annular sector r in [1, 2], phi in [0, pi/2] */
static int sector_piece(void *ud, double s, double *x, double *dx, dm_err *e)
{
  int k = *(const int *)ud;
  double ph;
  (void)e;
  switch (k) {
  case 0: x[0] = 1 + s; x[1] = 0; dx[0] = 1; dx[1] = 0; break;
  case 1: ph = M_PI / 2 * s; x[0] = 2 * cos(ph); x[1] = 2 * sin(ph);
    dx[0] = -M_PI * sin(ph); dx[1] = M_PI * cos(ph); break;
  case 2: x[0] = 0; x[1] = 2 - s; dx[0] = 0; dx[1] = -1; break;
  default: ph = M_PI / 2 * (1 - s); x[0] = cos(ph); x[1] = sin(ph);
    dx[0] = M_PI / 2 * sin(ph); dx[1] = -M_PI / 2 * cos(ph); break;
  }
  return DM_OK;
}

/* continuous transport around the sector = -0.15 pi */
static void test_sector(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  plat_par p = {1, 1};
  dm_conn *C = dm_conn_alloc(B, plat_A, &p, 1, NULL, NULL);
  int ids[4] = {0, 1, 2, 3};
  dm_conn_curve_fn f[4] = {sector_piece, sector_piece, sector_piece, sector_piece};
  void *uds[4] = {&ids[0], &ids[1], &ids[2], &ids[3]};
  double q0[3] = {1, 0, 0.7}, S, P;
  dm_conn_topts mag = {64, 0.0}, ad = {0, 1e-13};
  dm_conn_holonomy(C, 4, f, uds, q0, &mag, &S, &P, NULL);
  tap_near(P, -0.15 * M_PI, 1e-12, "sector: Magnus transport = -0.15 pi");
  tap_near(S, -0.15 * M_PI, 1e-12, "sector: spatial = body (abelian)");
  dm_conn_holonomy(C, 4, f, uds, q0, &ad, &S, &P, NULL);
  tap_near(P, -0.15 * M_PI, 1e-12, "sector: adaptive rk8pd transport = -0.15 pi");
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

typedef struct circ {
  double c[2], r;
} circ;

static int circle_curve(void *ud, double s, double *x, double *dx, dm_err *e)
{
  const circ *c = ud;
  double t = 2 * M_PI * s;
  (void)e;
  x[0] = c->c[0] + c->r * cos(t);
  x[1] = c->c[1] + c->r * sin(t);
  dx[0] = -2 * M_PI * c->r * sin(t);
  dx[1] = 2 * M_PI * c->r * cos(t);
  return DM_OK;
}

/* Magnus 4: errors against rk8pd fall by 16 per halving */
static void test_magnus_order(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn *C = dm_conn_alloc(B, twist_A, NULL, 1, NULL, NULL);
  circ c = {{0.4, -0.3}, 1.3};
  double Href[9], H[9], err[3];
  dm_conn_topts ad = {0, 1e-13};
  int k;
  dm_conn_transport(C, circle_curve, &c, &ad, Href, NULL);
  for (k = 0; k < 3; k++) {
    dm_conn_topts o = {(size_t)(8 << k), 0.0};
    dm_conn_transport(C, circle_curve, &c, &o, H, NULL);
    err[k] = dm_lie_dist(G, H, Href);
  }
  tap_ok(err[0] / err[1] > 14 && err[1] / err[2] > 14 && err[2] < 1e-5,
         "twist: Magnus 4 errors %.2e %.2e %.2e (ratios %.1f %.1f)", err[0], err[1], err[2],
         err[0] / err[1], err[1] / err[2]);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* small counter-clockwise squares: log P/eps^2 -> -B_12 */
static void test_shrinking_loops(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn *C = dm_conn_alloc(B, twist_A, NULL, 1, NULL, NULL);
  double x[2] = {0.7, -0.4}, b[3], err[3], q0[11], P[9], w[3];
  dm_conn_topts o = {4, 0.0};
  int k, a;
  dm_conn_curvature(C, x, 0, 1, b, NULL);
  for (k = 0; k < 3; k++) {
    double eps = 0.04 / (1 << k);
    double loop[10] = {x[0], x[1], x[0] + eps, x[1], x[0] + eps, x[1] + eps, x[0], x[1] + eps,
                       x[0], x[1]};
    q0[0] = x[0];
    q0[1] = x[1];
    dm_lie_identity(G, q0 + 2);
    dm_conn_holonomy_polygon(C, loop, 5, q0, &o, NULL, P, NULL);
    dm_lie_log(G, P, w);
    for (a = 0; a < 3; a++)
      w[a] = w[a] / (eps * eps) + b[a];
    err[k] = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  tap_ok(err[0] / err[1] > 1.9 && err[1] / err[2] > 1.9 && err[2] < 0.01,
         "twist: |log P/eps^2 + B| = %.2e %.2e %.2e (O(eps))", err[0], err[1], err[2]);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* gauge change sigma' = k(x) sigma, k = exp(kappa(x)):
 * A' = Ad_k A + (dk) k^-1, (dk) k^-1 = dexp_kappa (dkappa) (right) */
static void kappa_of(const double *x, double *kp, double *dk)
{
  kp[0] = 0.5 * x[0] * x[1];
  kp[1] = 0.3 * sin(x[0]);
  kp[2] = -0.2 + 0.4 * x[1];
  dk[0] = 0.5 * x[1];          dk[1] = 0.5 * x[0];
  dk[2] = 0.3 * cos(x[0]);     dk[3] = 0.0;
  dk[4] = 0.0;                 dk[5] = 0.4;
}

static int gauge_A(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  const dm_lie_group *G = ud;
  double A0[6], kp[3], dk[6], k[9], Ad[9], J[9];
  int a, b, i;
  (void)dA;
  twist_A(NULL, x, A0, NULL, e);
  kappa_of(x, kp, dk);
  dm_lie_exp(G, kp, k);
  dm_lie_Ad(G, k, Ad, 3);
  dm_lie_dexp(G, kp, DM_LIE_RIGHT, J, 3);
  for (a = 0; a < 3; a++)
    for (i = 0; i < 2; i++) {
      double s = 0.0;
      for (b = 0; b < 3; b++)
        s += Ad[3 * a + b] * A0[2 * b + i] + J[3 * a + b] * dk[2 * b + i];
      A[2 * a + i] = s;
    }
  return DM_OK;
}

static void test_gauge(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn *C = dm_conn_alloc(B, twist_A, NULL, 1, NULL, NULL),
          *Cg = dm_conn_alloc(B, gauge_A, G, 0, NULL, NULL);
  circ c = {{0.2, 0.5}, 0.9};
  dm_conn_curve_fn f[1] = {circle_curve};
  void *uds[1] = {&c};
  double q0[11], qg[11], w[3] = {0.3, -1.1, 0.6}, kp[3], dk[6], k[9], ki[9], S1[9], S2[9],
         P1[9], P2[9], t[9];
  dm_conn_topts ad = {0, 1e-13};
  q0[0] = qg[0] = 1.1;
  q0[1] = qg[1] = 0.5;
  dm_lie_exp(G, w, q0 + 2);
  kappa_of(q0, kp, dk);
  dm_lie_exp(G, kp, k);
  dm_lie_inverse(G, k, ki);
  dm_lie_compose(G, q0 + 2, ki, qg + 2);                /* g' = g k^-1 */
  dm_conn_holonomy(C, 1, f, uds, q0, &ad, S1, P1, NULL);
  dm_conn_holonomy(Cg, 1, f, uds, qg, &ad, S2, P2, NULL);
  tap_ok(dm_lie_dist(G, S1, S2) < 1e-10, "gauge: spatial holonomy unchanged (%.2e)",
         dm_lie_dist(G, S1, S2));
  dm_lie_compose(G, k, P1, t);
  dm_lie_compose(G, t, ki, t);
  tap_ok(dm_lie_dist(G, P2, t) < 1e-10 && dm_lie_dist(G, P1, P2) > 1e-3,
         "gauge: body holonomy conjugated by k(x0) (%.2e)", dm_lie_dist(G, P2, t));
  dm_conn_free(C);
  dm_conn_free(Cg);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the connection form: A(hor) = 0, A(xi_Q) = xi, equivariance */
static void test_form(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn *C = dm_conn_alloc(B, twist_A, NULL, 1, NULL, NULL);
  double q[11], hq[11], xd[2] = {0.6, -1.3}, xi[3], zero[2] = {0, 0}, out[3], out2[3], w[3],
         h[9], body[3], v[3] = {0.2, 0.5, -0.9}, gi[9], Adh[3];
  q[0] = 0.4;
  q[1] = 1.2;
  w[0] = 1.0; w[1] = -0.2; w[2] = 0.5;
  dm_lie_exp(G, w, q + 2);
  dm_conn_hlift_vec(C, q, xd, xi, NULL);
  dm_conn_form(C, q, xd, xi, out, NULL);
  tap_ok(fabs(out[0]) + fabs(out[1]) + fabs(out[2]) < 1e-15, "form: the horizontal lift has A = 0");
  dm_lie_inverse(G, q + 2, gi);
  dm_lie_Ad_apply(G, gi, v, body);                    /* xi_Q = (0, g Ad_g^-1 v) */
  dm_conn_form(C, q, zero, body, out, NULL);
  tap_ok(fabs(out[0] - v[0]) + fabs(out[1] - v[1]) + fabs(out[2] - v[2]) < 1e-14,
         "form: A(xi_Q) = xi");
  w[0] = -0.3; w[1] = 0.8; w[2] = 0.1;
  dm_lie_exp(G, w, h);
  dm_conn_act(B, h, q, hq);
  dm_conn_form(C, q, xd, v, out, NULL);
  dm_conn_form(C, hq, xd, v, out2, NULL);
  dm_lie_Ad_apply(G, h, out, Adh);
  tap_ok(fabs(out2[0] - Adh[0]) + fabs(out2[1] - Adh[1]) + fabs(out2[2] - Adh[2]) < 1e-14,
         "form: equivariant, A(h q) = Ad_h A(q)");
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the platform from expressions: given A, from (I, C), from l(x, xdot, xi) */
static void test_expr(void)
{
  dm_expr_ctx *c = dm_expr_ctx_alloc();
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_expr x[2], xd[2], xi, par[2], A[2], I, Cm[2], D, l, u, v, Aout[2], vu, vv;
  double pv[2] = {2.385, 0.7}, X[2] = {0.9, -0.35}, a1[2], a2[2], a3[2], a4[2], b1, b2;
  plat_par p = {2.385, 0.7};
  dm_conn *C1, *C2, *C3, *Cr = dm_conn_alloc(B, plat_A, &p, 1, NULL, NULL), *Cbad;
  dm_err e;
  x[0] = u = dm_expr_sym(c, "u");
  x[1] = v = dm_expr_sym(c, "v");
  xd[0] = dm_expr_sym(c, "ud");
  xd[1] = dm_expr_sym(c, "vd");
  xi = dm_expr_sym(c, "w");
  par[0] = dm_expr_param(c, "I");
  par[1] = dm_expr_param(c, "m");
  D = dm_expr_add(c, par[0], dm_expr_mul(c, par[1], dm_expr_add(c, dm_expr_mul(c, u, u),
                                                                   dm_expr_mul(c, v, v))));
  A[0] = dm_expr_div(c, dm_expr_neg(c, dm_expr_mul(c, par[1], v)), D);
  A[1] = dm_expr_div(c, dm_expr_mul(c, par[1], u), D);
  C1 = dm_conn_expr_alloc(c, B, x, A, 2, par, pv, &e);
  I = D;
  Cm[0] = dm_expr_neg(c, dm_expr_mul(c, par[1], v));
  Cm[1] = dm_expr_mul(c, par[1], u);
  C2 = dm_conn_mech_alloc(c, B, x, &I, Cm, 2, par, pv, NULL, &e);
  /* l = I_p/2 w^2 + m/2 ((ud - w v)^2 + (vd + w u)^2) */
  vu = dm_expr_sub(c, xd[0], dm_expr_mul(c, xi, v));
  vv = dm_expr_add(c, xd[1], dm_expr_mul(c, xi, u));
  l = dm_expr_add(c, dm_expr_mul(c, dm_expr_const(c, 0.5), dm_expr_mul(c, par[0],
                                                                          dm_expr_mul(c, xi, xi))),
                  dm_expr_mul(c, dm_expr_mul(c, dm_expr_const(c, 0.5), par[1]),
                              dm_expr_add(c, dm_expr_mul(c, vu, vu), dm_expr_mul(c, vv, vv))));
  C3 = dm_conn_lagrangian_alloc(c, B, x, xd, &xi, l, 2, par, pv, Aout, &e);
  tap_ok(C1 && C2 && C3, "platform from expressions, from (I, C) and from l");
  dm_conn_local(C1, X, a1, NULL);
  dm_conn_local(C2, X, a2, NULL);
  dm_conn_local(C3, X, a3, NULL);
  dm_conn_local(Cr, X, a4, NULL);
  tap_ok(maxdiff(a1, a4, 2) < 1e-15 && maxdiff(a2, a4, 2) < 1e-15 && maxdiff(a3, a4, 2) < 1e-15,
         "the three agree with the closed form");
  dm_conn_curvature(C3, X, 0, 1, &b1, NULL);
  dm_conn_curvature(Cr, X, 0, 1, &b2, NULL);
  tap_near(b1, b2, 1e-14, "curvature of the mechanical connection from l: exact");
  pv[0] = 1.0;
  pv[1] = 1.0;
  dm_conn_set_params(C3, pv, NULL);
  dm_conn_local(C3, X, a3, NULL);
  tap_near(a3[1], X[0] / (1 + X[0] * X[0] + X[1] * X[1]), 1e-15, "set_params: I = m = 1");
  /* not quadratic: l + w^4 */
  Cbad = dm_conn_lagrangian_alloc(c, B, x, xd, &xi, dm_expr_add(c, l, dm_expr_powi(c, xi, 4)),
                                  2, par, pv, NULL, &e);
  tap_ok(Cbad == NULL && e.status == DM_EINVAL && strstr(e.msg, "not quadratic"),
         "a Lagrangian not quadratic in the velocities refused (%s)", e.msg);
  tap_ok(dm_conn_set_params(Cr, pv, &e) == DM_EINVAL, "set_params on a C connection: %s", e.msg);
  dm_conn_free(C1);
  dm_conn_free(C2);
  dm_conn_free(C3);
  dm_conn_free(Cr);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
  dm_expr_ctx_free(c);
}

static void test_errors(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL), *B0 = dm_conn_bundle_trivial(0, G, NULL),
                 *S = dm_conn_bundle_sphere_frames(NULL);
  dm_conn *C = dm_conn_alloc(B, orbiter_A, NULL, 1, NULL, NULL);
  double open[6] = {1, 0, 0, 1, -1, 0.1}, q0[3] = {1, 0, 0}, P, x[2] = {0, 0}, A[2], b;
  double through[8] = {1, 0, 0, 0, -1, 0, 1, 0};
  dm_conn_topts ad = {0, 1e-10};
  dm_err e;
  tap_ok(dm_conn_holonomy_polygon(C, open, 3, q0, NULL, NULL, &P, &e) == DM_EINVAL &&
         strstr(e.msg, "not closed"), "an open loop refused: %s", e.msg);
  tap_ok(dm_conn_local(C, x, A, &e) == DM_EDOM && strstr(e.msg, "origin"),
         "a callback failure passes through: %s", e.msg);
  tap_ok(dm_conn_holonomy_polygon(C, through, 4, q0, &ad, NULL, &P, &e) == DM_EDOM,
         "a loop through the singularity fails: %s", e.msg);
  tap_ok(dm_conn_curvature(C, q0, 0, 2, &b, &e) == DM_EINVAL && strstr(e.msg, "1..2"),
         "curvature direction out of range: %s", e.msg);
  tap_ok(dm_conn_alloc(B0, orbiter_A, NULL, 1, NULL, &e) == NULL && e.status == DM_EINVAL,
         "no continuous connection on Q = G: %s", e.msg);
  tap_ok(dm_conn_alloc(S, orbiter_A, NULL, 1, NULL, &e) == NULL && e.status == DM_EUNSUP,
         "no local form on the sphere frames: %s", e.msg);
  dm_conn_free(C);
  dm_conn_free(NULL);
  dm_conn_bundle_free(B);
  dm_conn_bundle_free(B0);
  dm_conn_bundle_free(S);
  dm_lie_group_free(G);
}

int main(void)
{
  dm_gsl_init();
  srand(12);
  test_bundles();
  test_platform_curvature();
  test_rotor();
  test_sector();
  test_magnus_order();
  test_shrinking_loops();
  test_gauge();
  test_form();
  test_expr();
  test_errors();
  return tap_done();
}
