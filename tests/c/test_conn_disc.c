/* test_conn_disc.c -- discrete connections (src/conn): the three properties
 * on random SO(3) data, hor / ver, lifts, reduction of pairs, the extended
 * pair-groupoid composition and holonomy, the continuous limit, the order
 * test, gauge changes, geometric phases of the platform, the three-link
 * cat, the rotor craft and the planar orbiter, the exact rule's failure of
 * fibre compatibility, error paths.  Reference values:
 * tests/data/conn/reference.py. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_integration.h>

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

static void rand_rot(const dm_lie_group *G, double *R)
{
  double w[3] = {urand(), urand(), urand()};
  dm_lie_exp(G, w, R);
}

/* a random point (x, R) of R^2 x SO(3) */
static void rand_q(const dm_lie_group *G, double *q, double scale)
{
  q[0] = scale * urand();
  q[1] = scale * urand();
  rand_rot(G, q + 2);
}

typedef struct fixture {
  dm_lie_group *G;
  dm_conn_bundle *B;
  dm_conn *C;
  dm_conn_dc *D;
} fixture;

static fixture twist_fixture(const char *rule)
{
  fixture f;
  f.G = dm_lie_so3(NULL);
  f.B = dm_conn_bundle_trivial(2, f.G, NULL);
  f.C = dm_conn_alloc(f.B, twist_A, NULL, 1, NULL, NULL);
  f.D = dm_conn_dc_alloc(dm_conn_rule_find(rule), f.B, f.C, NULL, NULL, NULL);
  return f;
}

static void fixture_free(fixture *f)
{
  dm_conn_dc_free(f->D);
  dm_conn_free(f->C);
  dm_conn_bundle_free(f->B);
  dm_lie_group_free(f->G);
}

/* the three properties and the derived maps on random data, midpoint rule of a non-constant
 * so(3)-valued form */
static void test_properties(void)
{
  fixture f = twist_fixture("midpoint");
  const dm_lie_group *G = f.G;
  double q0[11], q1[11], g0[9], g1[9], a[11], b[11], A[9], B[9], t[9], gi[9], e9[9], h1[11],
         v1[11], x0[2], x1[2], z[9], z2[9], r1[11], xs[8], qs[44], qs2[44];
  double w1 = 0, w2 = 0, w3 = 0, w4 = 0, w5 = 0, w6 = 0, w7 = 0, w8 = 0, w9 = 0, w10 = 0;
  int k, i;
  dm_lie_identity(G, e9);
  for (k = 0; k < 50; k++) {
    rand_q(G, q0, 1.5);
    rand_q(G, q1, 1.5);
    rand_rot(G, g0);
    rand_rot(G, g1);
    dm_conn_dc_eval(f.D, q0, q1, A, NULL);
    /* A_d(g0 q0, g1 q1) = g1 A_d g0^-1 */
    dm_conn_act(f.B, g0, q0, a);
    dm_conn_act(f.B, g1, q1, b);
    dm_conn_dc_eval(f.D, a, b, B, NULL);
    dm_lie_inverse(G, g0, gi);
    dm_lie_compose(G, g1, A, t);
    dm_lie_compose(G, t, gi, t);
    w1 = fmax(w1, maxdiff(B, t, 9));
    /* diagonal equivariance alone (g0 = g1) */
    dm_conn_act(f.B, g0, q1, b);
    dm_conn_dc_eval(f.D, a, b, B, NULL);
    dm_lie_compose(G, g0, A, t);
    dm_lie_compose(G, t, gi, t);
    w2 = fmax(w2, maxdiff(B, t, 9));
    /* A_d(q, g q) = g, A_d(q, q) = e */
    dm_conn_act(f.B, g1, q0, b);
    dm_conn_dc_eval(f.D, q0, b, B, NULL);
    w3 = fmax(w3, maxdiff(B, g1, 9));
    dm_conn_dc_eval(f.D, q0, q0, B, NULL);
    w3 = fmax(w3, maxdiff(B, e9, 9));
    /* ver . hor = (q0, q1), A_d(hor) = e, pi hor = pi (q0, q1) */
    dm_conn_dc_hor(f.D, q0, q1, h1, NULL);
    dm_conn_dc_ver(f.D, q0, q1, v1, NULL);
    dm_conn_act(f.B, A, h1, r1);
    w4 = fmax(w4, maxdiff(r1, q1, 11));
    dm_conn_fiber_diff(f.B, q0, v1, t, NULL);
    w4 = fmax(w4, maxdiff(t, A, 9));
    dm_conn_dc_eval(f.D, q0, h1, B, NULL);
    w4 = fmax(w4, maxdiff(B, e9, 9) + maxdiff(h1, q1, 2));
    /* lift from g q0 = g lift from q0 */
    for (i = 0; i < 8; i++)
      xs[i] = 1.2 * urand();
    xs[0] = q0[0];
    xs[1] = q0[1];
    dm_conn_dc_lift(f.D, xs, 4, q0, qs, NULL);
    dm_conn_act(f.B, g0, q0, a);
    dm_conn_dc_lift(f.D, xs, 4, a, qs2, NULL);
    for (i = 0; i < 4; i++) {
      dm_conn_act(f.B, g0, qs + 11 * i, r1);
      w5 = fmax(w5, maxdiff(r1, qs2 + 11 * i, 11));
    }
    /* unreduce(reduce(q0, q1), q0) = q1; reduce(g q0, g q1) = reduce(q0, q1) */
    dm_conn_dc_reduce(f.D, q0, q1, x0, x1, z, NULL);
    dm_conn_dc_unreduce(f.D, x0, x1, z, q0, r1, NULL);
    w6 = fmax(w6, maxdiff(r1, q1, 11));
    dm_conn_act(f.B, g0, q0, a);
    dm_conn_act(f.B, g0, q1, b);
    dm_conn_dc_reduce(f.D, a, b, x0, x1, z2, NULL);
    w7 = fmax(w7, maxdiff(z, z2, 9));
    /* zeta = g0^-1 g1 A(x0, x1) */
    dm_conn_dc_local(f.D, q0, q1, B, NULL);
    dm_lie_inverse(G, q0 + 2, gi);
    dm_lie_compose(G, gi, q1 + 2, t);
    dm_lie_compose(G, t, B, t);
    w8 = fmax(w8, maxdiff(t, z, 9));
    /* i_q(g) . i_q(h) = i_q(gh) */
    dm_conn_act(f.B, g1, q0, a);
    dm_conn_act(f.B, g0, a, a);
    dm_lie_compose(G, g0, g1, t);
    dm_conn_generator(f.B, q0, t, b);
    w9 = fmax(w9, maxdiff(a, b, 11));
    /* horizontal pairs: zeta = e exactly */
    dm_conn_dc_reduce(f.D, q0, h1, x0, x1, z, NULL);
    w10 = fmax(w10, maxdiff(z, e9, 9));
  }
  tap_ok(w1 < 1e-12, "A_d(g0 q0, g1 q1) = g1 A_d(q0, q1) g0^-1 (equivariance and fibre compatibility; %.1e)", w1);
  tap_ok(w2 < 1e-12, "diagonal equivariance: A_d(g q0, g q1) = g A_d g^-1 (%.1e)", w2);
  tap_ok(w3 < 1e-12, "splitting: A_d(q, g q) = g, A_d(q, q) = e (%.1e)", w3);
  tap_ok(w4 < 1e-12, "ver . hor = (q0, q1), A_d(hor) = e, same shapes (%.1e)", w4);
  tap_ok(w5 < 1e-12, "lift from g q0 = g . lift from q0 (%.1e)", w5);
  tap_ok(w6 < 1e-12 && w7 < 1e-12 && w8 < 1e-12,
         "unreduce(reduce) = id, reduce is G-invariant, zeta = g0^-1 g1 A (%.1e %.1e %.1e)", w6,
         w7, w8);
  tap_ok(w9 < 1e-13, "i_q(g) i_q(h) = i_q(gh) (%.1e)", w9);
  tap_ok(w10 < 1e-12, "horizontal pairs reduce to zeta = e (%.1e)", w10);
  fixture_free(&f);
}

/* Q = G: A_d(g0, g1) = g1 g0^-1, zeta = g0^-1 g1 */
static void test_QG(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(0, G, NULL);
  dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find("trivial"), B, NULL, NULL, NULL, NULL);
  double g0[9], g1[9], A[9], t[9], z[9], xa[1], xb[1];
  rand_rot(G, g0);
  rand_rot(G, g1);
  dm_conn_dc_eval(D, g0, g1, A, NULL);
  dm_lie_inverse(G, g0, t);
  dm_lie_compose(G, g1, t, t);
  tap_ok(maxdiff(A, t, 9) < 1e-15, "Q = G: A_d(g0, g1) = g1 g0^-1");
  dm_conn_dc_reduce(D, g0, g1, xa, xb, z, NULL);
  dm_lie_between(G, g0, g1, t);
  tap_ok(maxdiff(z, t, 9) < 1e-15, "Q = G: zeta = g0^-1 g1 (the LGVI's F_k)");
  dm_conn_dc_free(D);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the extended pair-groupoid composition */
static void test_compose(void)
{
  fixture f = twist_fixture("cayley");
  const dm_lie_group *G = f.G;
  double a0[11], a1[11], b0[11], b1[11], c0[11], c1[11], g[9], ab[11], bc[11], r1[11], r2[11],
         xs[12], qs[11], S[9], gq[11];
  double poly[12] = {0.3, 0.2, 1.1, -0.4, 0.8, 0.9, -0.5, 0.6, 0.1, -0.2, 0.3, 0.2};
  int k;
  rand_q(G, a0, 1);
  rand_q(G, a1, 1);
  rand_q(G, b1, 1);
  rand_q(G, c1, 1);
  /* b0 over a1's shape, c0 over b1's */
  memcpy(b0, a1, sizeof b0);
  rand_rot(G, g);
  dm_conn_act(f.B, g, a1, b0);
  rand_rot(G, g);
  dm_conn_act(f.B, g, b1, c0);
  dm_conn_dc_compose(f.D, a0, a1, b0, b1, ab, NULL);
  dm_conn_dc_compose(f.D, a0, ab, c0, c1, r1, NULL);
  dm_conn_dc_compose(f.D, b0, b1, c0, c1, bc, NULL);
  dm_conn_dc_compose(f.D, a0, a1, b0, bc, r2, NULL);
  tap_ok(maxdiff(r1, r2, 11) < 1e-12, "composition is associative (%.1e)", maxdiff(r1, r2, 11));
  dm_conn_dc_compose(f.D, a0, a1, a1, b1, r1, NULL);
  tap_ok(maxdiff(r1, b1, 11) < 1e-14, "agrees with the pair groupoid when q1 = q~0");
  dm_conn_act(f.B, g, b0, a1);
  dm_conn_dc_compose(f.D, b0, a1, b0, b1, r1, NULL);
  dm_conn_act(f.B, g, b1, r2);
  tap_ok(maxdiff(r1, r2, 11) < 1e-13, "agrees with the vertical composition (q, g q).(q, q1) = "
         "(q, g q1)");
  /* composing horizontal lifts of the edges, each at an arbitrary point */
  memcpy(xs, poly, sizeof poly);
  rand_q(G, a0, 1);
  a0[0] = xs[0];
  a0[1] = xs[1];
  memcpy(ab, a0, sizeof ab);
  for (k = 0; k < 5; k++) {
    rand_q(G, qs, 1);
    qs[0] = xs[2 * k];
    qs[1] = xs[2 * k + 1];
    dm_conn_dc_hlift(f.D, qs, xs + 2 * (k + 1), r1, NULL);
    if (k == 0)
      memcpy(ab, r1, sizeof ab), memcpy(b0, qs, sizeof b0);
    else
      dm_conn_dc_compose(f.D, b0, ab, qs, r1, ab, NULL);
  }
  dm_conn_dc_holonomy(f.D, xs, 6, b0, S, NULL, NULL, NULL);
  dm_conn_act(f.B, S, b0, gq);
  tap_ok(maxdiff(ab, gq, 11) < 1e-12, "composed lifts of a closed polygon = (q0, hol . q0) (%.1e)",
         maxdiff(ab, gq, 11));
  fixture_free(&f);
}

/* d/de A_d(q, q(e)) = A(v) of the parent, central differences O(e^2) */
static void test_limit(void)
{
  fixture f = twist_fixture("midpoint");
  double q[11], xd[2] = {0.7, -0.3}, xi[3] = {0.2, 0.9, -0.5}, lim[3], ref[3], err[2];
  int k;
  rand_q(f.G, q, 1);
  dm_conn_form(f.C, q, xd, xi, ref, NULL);
  for (k = 0; k < 2; k++) {
    dm_conn_dc_limit(f.D, q, xd, xi, k ? 5e-3 : 1e-2, lim, NULL);
    err[k] = maxdiff(lim, ref, 3);
  }
  tap_ok(err[1] < 1e-5 && err[0] / err[1] > 3.8 && err[0] / err[1] < 4.2,
         "continuous limit = A(v), errors %.2e, %.2e (O(eps^2))", err[0], err[1]);
  fixture_free(&f);
}

/* order test on the platform (I = m = 1) against transport */
static void test_order(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  plat_par p = {1, 1};
  dm_conn *C = dm_conn_alloc(B, plat_A, &p, 1, NULL, NULL);
  dm_conn_dc *ref = dm_conn_dc_alloc(dm_conn_rule_find("transport"), B, C, NULL, NULL, NULL);
  const char *names[3] = {"euler", "midpoint", "cayley"};
  const double want[3][4] = {{3.741e-03, 9.617e-04, 2.437e-04, 6.133e-05},
                             {5.315e-05, 6.579e-06, 8.133e-07, 1.009e-07},
                             {5.875e-05, 7.379e-06, 9.202e-07, 1.147e-07}};
  double q[3] = {1, 0.5, 0.3}, v[2] = {0.6, 0.8}, h[4] = {0.2, 0.1, 0.05, 0.025}, d[4], slope;
  dm_conn_topts o = {0, 1e-14};
  int r, k, ok;
  dm_conn_dc_set_topts(ref, &o);
  for (r = 0; r < 3; r++) {
    dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find(names[r]), B, C, NULL, NULL, NULL);
    dm_conn_dc_order(D, ref, q, v, h, 4, d, &slope, NULL);
    for (ok = 1, k = 0; k < 4; k++)
      ok &= fabs(d[k] - want[r][k]) < 1e-3 * want[r][k];
    tap_ok(ok && fabs(slope - (r ? 3.0 : 2.0)) < 0.1,
           "order test %s: defects %.3e %.3e %.3e %.3e, slope %.2f", names[r], d[0], d[1], d[2],
           d[3], slope);
    dm_conn_dc_free(D);
  }
  dm_conn_dc_free(ref);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* gauge change of a discrete connection */
static void kappa_of(const double *x, double *kp)
{
  kp[0] = 0.5 * x[0] * x[1];
  kp[1] = 0.3 * sin(x[0]);
  kp[2] = -0.2 + 0.4 * x[1];
}

typedef struct gauge_ctx {
  dm_conn_dc *D;
  const dm_lie_group *G;
} gauge_ctx;

/* A'(x0, x1) = k(x1) A(x0, x1) k(x0)^-1 */
static int gauge_pair(void *ud, const double *x0, const double *x1, double *A, dm_err *e)
{
  gauge_ctx *g = ud;
  double k0[3], k1[3], K0[9], K1[9], t[9];
  int st = dm_conn_dc_local(g->D, x0, x1, t, e);
  kappa_of(x0, k0);
  kappa_of(x1, k1);
  dm_lie_exp(g->G, k0, K0);
  dm_lie_exp(g->G, k1, K1);
  dm_lie_inverse(g->G, K0, K0);
  dm_lie_compose(g->G, K1, t, t);
  dm_lie_compose(g->G, t, K0, A);
  return st;
}

static void test_gauge(void)
{
  fixture f = twist_fixture("midpoint");
  const dm_lie_group *G = f.G;
  gauge_ctx gc = {f.D, f.G};
  dm_conn_dc *Dg = dm_conn_dc_alloc(dm_conn_rule_find("local"), f.B, NULL, gauge_pair, &gc, NULL);
  double xs[2 * 65], q0[11], qg[11], kp[3], K[9], Ki[9], S1[9], S2[9], P1[9], P2[9], t[9];
  int k, N = 64;
  for (k = 0; k <= N; k++) {
    double th = 2 * M_PI * k / N;
    xs[2 * k] = 0.3 + 0.8 * cos(th);
    xs[2 * k + 1] = -0.2 + 0.8 * sin(th);
  }
  xs[2 * N] = xs[0];
  xs[2 * N + 1] = xs[1];
  rand_q(G, q0, 1);
  q0[0] = xs[0];
  q0[1] = xs[1];
  memcpy(qg, q0, sizeof qg);
  kappa_of(q0, kp);
  dm_lie_exp(G, kp, K);
  dm_lie_inverse(G, K, Ki);
  dm_lie_compose(G, q0 + 2, Ki, qg + 2);
  dm_conn_dc_holonomy(f.D, xs, N + 1, q0, S1, P1, NULL, NULL);
  dm_conn_dc_holonomy(Dg, xs, N + 1, qg, S2, P2, NULL, NULL);
  tap_ok(dm_lie_dist(G, S1, S2) < 1e-13, "discrete gauge: spatial holonomy unchanged (%.1e)",
         dm_lie_dist(G, S1, S2));
  dm_lie_compose(G, K, P1, t);
  dm_lie_compose(G, t, Ki, t);
  tap_ok(dm_lie_dist(G, t, P2) < 1e-13 && dm_lie_dist(G, P1, P2) > 1e-3,
         "discrete gauge: body holonomy conjugated by k(x0) (%.1e)", dm_lie_dist(G, t, P2));
  dm_conn_dc_free(Dg);
  fixture_free(&f);
}

/* the platform around the annular sector, midpoint, second order */
static size_t sector(int N, double *xs)
{
  size_t n = 0;
  int k;
  for (k = 0; k < N; k++, n++)
    xs[2 * n] = 1.0 + (double)k / N, xs[2 * n + 1] = 0.0;
  for (k = 0; k < N; k++, n++)
    xs[2 * n] = 2 * cos(M_PI / 2 * k / N), xs[2 * n + 1] = 2 * sin(M_PI / 2 * k / N);
  for (k = 0; k < N; k++, n++)
    xs[2 * n] = 0.0, xs[2 * n + 1] = 2.0 - (double)k / N;
  for (k = 0; k < N; k++, n++)
    xs[2 * n] = cos(M_PI / 2 * (1 - (double)k / N)), xs[2 * n + 1] = sin(M_PI / 2 * (1 - (double)k / N));
  xs[2 * n] = 1.0;
  xs[2 * n + 1] = 0.0;
  return n + 1;
}

static void circle(double cx, double cy, double r, int N, double *xs)
{
  int k;
  for (k = 0; k <= N; k++) {
    xs[2 * k] = cx + r * cos(2 * M_PI * k / N);
    xs[2 * k + 1] = cy + r * sin(2 * M_PI * k / N);
  }
  xs[2 * N] = xs[0];
  xs[2 * N + 1] = xs[1];
}

static void test_platform_phase(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  plat_par p = {1, 1};
  dm_conn *C = dm_conn_alloc(B, plat_A, &p, 1, NULL, NULL);
  dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), B, C, NULL, NULL, NULL);
  double xs[2 * 1030], q0[3] = {1, 0, 0.25}, hol, err[3], S;
  const double want[3] = {-2.881934e-03, -7.194768e-04, -1.798060e-04};
  size_t n;
  int k;
  for (k = 0; k < 3; k++) {
    n = sector(8 << k, xs);
    dm_conn_dc_holonomy(D, xs, n, q0, NULL, NULL, &hol, NULL);
    err[k] = hol + 0.15 * M_PI;
  }
  tap_ok(fabs(err[0] / want[0] - 1) < 1e-6 && fabs(err[1] / want[1] - 1) < 1e-6 &&
         fabs(err[2] / want[2] - 1) < 1e-6, "platform sector, midpoint: errors %.6e %.6e %.6e "
         "(ratio %.2f)", err[0], err[1], err[2], err[1] / err[2]);
  circle(0, 0, 1, 1024, xs);
  q0[0] = 1;
  q0[1] = 0;
  dm_conn_dc_holonomy(D, xs, 1025, q0, &S, NULL, &hol, NULL);
  tap_near(hol, -M_PI, 2e-5, "platform: unit circle about the origin -> -2 pi m/(I + m) = -pi");
  dm_conn_dc_free(D);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the planar three-link cat */
typedef struct stokes {
  dm_conn *C;
  double cx, cy, r, rho;
} stokes;

static double stokes_t(double t, void *ud)
{
  stokes *s = ud;
  double x[2] = {s->cx + s->rho * cos(t), s->cy + s->rho * sin(t)}, b;
  dm_conn_curvature(s->C, x, 0, 1, &b, NULL);
  return b * s->rho;
}

static double stokes_r(double rho, void *ud)
{
  stokes *s = ud;
  gsl_integration_glfixed_table *T = gsl_integration_glfixed_table_alloc(40);
  gsl_function F = {stokes_t, s};
  double v;
  s->rho = rho;
  v = gsl_integration_glfixed(&F, 0, 2 * M_PI, T);
  gsl_integration_glfixed_table_free(T);
  return v;
}

static void test_cat(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn *C = dm_conn_alloc(B, cat_A, NULL, 0, NULL, NULL);
  dm_conn_dc *E = dm_conn_dc_alloc(dm_conn_rule_find("euler"), B, C, NULL, NULL, NULL),
             *M = dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), B, C, NULL, NULL, NULL);
  const double ex = -0.0093913753, eu[3] = {-2.4971e-02, -1.3227e-02, -6.7382e-03},
               mp[3] = {9.7560e-04, 2.5061e-04, 6.3080e-05};
  double xs[2 * 257], q0[3], he, hm, A[2], x0[2] = {0, 0}, okE = 1, okM = 1, sym;
  stokes s = {C, 1, 0.5, 0.5, 0};
  gsl_integration_glfixed_table *T = gsl_integration_glfixed_table_alloc(20);
  gsl_function F = {stokes_r, &s};
  double flux;
  dm_conn_topts ad = {0, 1e-12};
  int k;
  dm_conn_local(C, x0, A, NULL);
  tap_ok(fabs(A[0] - 7.0 / 27) < 1e-15 && fabs(A[1] - 7.0 / 27) < 1e-15, "cat: A(0, 0) = (7/27, 7/27)");
  for (k = 0; k < 3; k++) {
    circle(1, 0.5, 0.5, 8 << k, xs);
    q0[0] = xs[0];
    q0[1] = xs[1];
    q0[2] = 0.0;
    dm_conn_dc_holonomy(E, xs, (8 << k) + 1, q0, NULL, NULL, &he, NULL);
    dm_conn_dc_holonomy(M, xs, (8 << k) + 1, q0, NULL, NULL, &hm, NULL);
    okE = okE && fabs((he - ex) / eu[k] - 1) < 2e-4;
    okM = okM && fabs((hm - ex) / mp[k] - 1) < 2e-4;
    if (!okE || !okM)
      tap_diag("N = %d: euler %.4e midpoint %.4e", 8 << k, he - ex, hm - ex);
  }
  tap_ok(okE, "cat circle r = 0.5 about (1, 0.5): euler errors -2.50e-2, -1.32e-2, -6.74e-3 "
         "(first order)");
  tap_ok(okM, "cat: midpoint errors 9.76e-4, 2.51e-4, 6.31e-5 (second order)");
  circle(1, 0.5, 0.5, 4, xs);
  q0[0] = xs[0];
  q0[1] = xs[1];
  dm_conn_holonomy_polygon(C, xs, 2, q0, &ad, NULL, &he, NULL);
  flux = gsl_integration_glfixed(&F, 0, 0.5, T);
  gsl_integration_glfixed_table_free(T);
  tap_near(-flux, ex, 1e-8, "cat: Stokes, -(integral of the curvature over the disc) = %.10f",
           -flux);
  circle(1, -1, 1, 256, xs);
  q0[0] = xs[0];
  q0[1] = xs[1];
  dm_conn_dc_holonomy(M, xs, 257, q0, NULL, NULL, &hm, NULL);
  tap_near(hm, -0.2573921301, 5e-5, "cat: circle r = 1 about (1, -1): -0.2573921 (N = 256, "
           "midpoint)");
  circle(0, 0, 0.8, 64, xs);
  q0[0] = xs[0];
  q0[1] = xs[1];
  dm_conn_dc_holonomy(M, xs, 65, q0, NULL, NULL, &sym, NULL);
  tap_ok(fabs(sym) < 1e-15, "cat: a loop centred on (0, 0) gives 0 by symmetry (%.1e)", sym);
  dm_conn_dc_free(E);
  dm_conn_dc_free(M);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* every rule with exact exponential reproduces the product formula */
static void test_rotor_lift(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(3, G, NULL);
  rotor_par p = {{0.1, 0.2, 0.3}};
  dm_conn *C = dm_conn_alloc(B, rotor_A, &p, 1, NULL, NULL);
  const char *rules[3] = {"euler", "midpoint", "transport"};
  double loop[15] = {0, 0, 0, 1.3, 0, 0, 1.3, 0.9, 0, 0, 0.9, 0, 0, 0, 0}, q0[12], P[9],
         E[4][9], prod[9], w[3];
  int r, i;
  for (i = 0; i < 4; i++) {
    w[0] = w[1] = w[2] = 0.0;
    w[i % 2] = (i < 2 ? -1 : 1) * (i % 2 ? 0.9 : 1.3) * p.c[i % 2];
    dm_lie_exp(G, w, E[i]);
  }
  dm_lie_compose(G, E[0], E[1], prod);
  dm_lie_compose(G, prod, E[2], prod);
  dm_lie_compose(G, prod, E[3], prod);
  memset(q0, 0, sizeof q0);
  dm_lie_identity(G, q0 + 3);
  for (r = 0; r < 3; r++) {
    dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find(rules[r]), B, C, NULL, NULL, NULL);
    dm_conn_dc_holonomy(D, loop, 5, q0, NULL, P, NULL, NULL);
    tap_ok(maxdiff(P, prod, 9) < 1e-14, "rotor lift, %s: P = exp(-a u1) exp(-b u2) exp(a u1) "
           "exp(b u2) (%.1e)", rules[r], maxdiff(P, prod, 9));
    dm_conn_dc_free(D);
  }
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the planar orbiter, heading following the polar angle */
static void test_orbiter(void)
{
  dm_lie_group *G = dm_lie_so2(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
  dm_conn *C = dm_conn_alloc(B, orbiter_A, NULL, 1, NULL, NULL);
  dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find("transport"), B, C, NULL, NULL, NULL),
             *T = dm_conn_dc_alloc(dm_conn_rule_find("trivial"), B, NULL, NULL, NULL, NULL);
  double f0 = 0.4, q0[3], q1[3], a, b, xs[2 * 13], hol, S;
  dm_conn_topts ad = {0, 1e-14};
  dm_conn_dc_set_topts(D, &ad);
  q0[0] = 2 * cos(f0);
  q0[1] = 2 * sin(f0);
  q0[2] = 1.0;
  q1[0] = 2 * cos(f0 + M_PI / 4);
  q1[1] = 2 * sin(f0 + M_PI / 4);
  q1[2] = 1.0 + M_PI / 4;
  dm_conn_dc_eval(D, q0, q1, &a, NULL);
  dm_conn_dc_eval(T, q0, q1, &b, NULL);
  tap_ok(fabs(a) < 1e-14 && fabs(b - M_PI / 4) < 1e-15, "orbiter: A_d = 0 when the heading "
         "follows the polar angle, trivial connection pi/4 (%.1e)", a);
  circle(0, 0, 2, 12, xs);
  q0[0] = xs[0];
  q0[1] = xs[1];
  dm_conn_dc_holonomy(D, xs, 13, q0, &S, NULL, &hol, NULL);
  tap_near(hol, 2 * M_PI, 1e-13, "orbiter: once around the origin, lifted holonomy 2 pi");
  tap_ok(fabs(remainder(S, 2 * M_PI)) < 1e-13, "orbiter: the identity of SO(2)");
  dm_conn_dc_free(D);
  dm_conn_dc_free(T);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
}

/* the exact rule: equivariance and splitting hold, fibre compatibility
 * fails for non-abelian G; abelian = euler */
static void test_exact(void)
{
  dm_lie_group *G = dm_lie_so3(NULL);
  dm_conn_bundle *B = dm_conn_bundle_trivial(3, G, NULL);
  rotor_par p = {{1, 1, 1}};
  dm_conn *C = dm_conn_alloc(B, rotor_A, &p, 1, NULL, NULL);
  dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find("exact"), B, C, NULL, NULL, NULL);
  double q0[12] = {0}, q1[12] = {0.15, 0.2, -0.06}, w0[3] = {0.4, -0.3, 0.8},
         w1[3] = {0.5, -0.1, 0.9}, wh[3] = {0.2, 0.7, -0.4}, h[9], A[9], B2[9], hq1[12], t[9],
         a[12], hA[9], pi3[3] = {M_PI, 0, 0};
  dm_err e;
  dm_lie_exp(G, w0, q0 + 3);
  dm_lie_exp(G, w1, q1 + 3);
  dm_lie_exp(G, wh, h);
  dm_conn_dc_eval(D, q0, q1, A, NULL);
  dm_conn_act(B, h, q1, hq1);
  dm_conn_dc_eval(D, q0, hq1, B2, NULL);
  dm_lie_compose(G, h, A, hA);
  tap_near(dm_lie_dist(G, B2, hA), 0.0788, 1e-4,
           "exact rule: |log(A(q0, h q1) (h A(q0, q1))^-1)| = %.4f (fibre compatibility fails)",
           dm_lie_dist(G, B2, hA));
  dm_conn_act(B, h, q0, a);
  dm_conn_act(B, h, q1, hq1);
  dm_conn_dc_eval(D, a, hq1, B2, NULL);
  dm_lie_compose(G, h, A, t);
  dm_lie_inverse(G, h, hA);
  dm_lie_compose(G, t, hA, t);
  tap_ok(maxdiff(B2, t, 9) < 1e-14, "exact rule: diagonal equivariance holds");
  dm_conn_act(B, h, q0, a);
  dm_conn_dc_eval(D, q0, a, B2, NULL);
  tap_ok(maxdiff(B2, h, 9) < 1e-14, "exact rule: splitting A_d(q, g q) = g holds");
  /* the cut locus: g1 g0^-1 a rotation by pi */
  memcpy(q1, q0, sizeof q1);
  dm_lie_exp(G, pi3, h);
  dm_conn_act(B, h, q0, q1);
  tap_ok(dm_conn_dc_eval(D, q0, q1, B2, &e) == DM_EDOM && strstr(e.msg, "cut locus"),
         "exact rule at the cut locus: %s", e.msg);
  dm_conn_dc_free(D);
  dm_conn_free(C);
  dm_conn_bundle_free(B);
  dm_lie_group_free(G);
  {
    dm_lie_group *S = dm_lie_so2(NULL);
    dm_conn_bundle *Bp = dm_conn_bundle_trivial(2, S, NULL);
    plat_par pp = {1.3, 0.8};
    dm_conn *Cp = dm_conn_alloc(Bp, plat_A, &pp, 1, NULL, NULL);
    dm_conn_dc *X = dm_conn_dc_alloc(dm_conn_rule_find("exact"), Bp, Cp, NULL, NULL, NULL),
               *U = dm_conn_dc_alloc(dm_conn_rule_find("euler"), Bp, Cp, NULL, NULL, NULL);
    double r0[3] = {0.4, 0.9, 0.3}, r1[3] = {0.7, 0.5, 1.2}, ax, au;
    dm_conn_dc_eval(X, r0, r1, &ax, NULL);
    dm_conn_dc_eval(U, r0, r1, &au, NULL);
    tap_near(ax, au, 1e-15, "exact rule: equals euler for abelian G on a flat shape space");
    dm_conn_dc_free(X);
    dm_conn_dc_free(U);
    dm_conn_free(Cp);
    dm_conn_bundle_free(Bp);
    dm_lie_group_free(S);
  }
}

static int bad_pair(void *ud, const double *x0, const double *x1, double *A, dm_err *e)
{
  (void)ud;
  (void)x0;
  (void)x1;
  (void)e;
  A[0] = NAN;
  return DM_OK;
}

static void test_errors(void)
{
  fixture f = twist_fixture("midpoint");
  dm_conn_bundle *S = dm_conn_bundle_sphere_frames(NULL);
  dm_lie_group *SO2 = dm_lie_so2(NULL);
  dm_conn_bundle *B2 = dm_conn_bundle_trivial(2, SO2, NULL);
  dm_conn_dc *bad = dm_conn_dc_alloc(dm_conn_rule_find("local"), B2, NULL, bad_pair, NULL, NULL);
  double q0[11], q1[11], r[11], xs[6] = {0, 0, 1, 0, 0, 1}, g[9], c[3] = {0, 0, 0}, x1[2] = {1, 1};
  dm_err e;
  rand_q(f.G, q0, 1);
  rand_q(f.G, q1, 1);
  tap_ok(dm_conn_dc_compose(f.D, q0, q1, q0, q1, r, &e) == DM_EINVAL && strstr(e.msg, "do not meet"),
         "compose of pairs that do not meet: %s", e.msg);
  tap_ok(dm_conn_dc_holonomy(f.D, xs, 3, q0, g, NULL, NULL, &e) == DM_EINVAL &&
         strstr(e.msg, "not closed"), "holonomy of an open polygon: %s", e.msg);
  tap_ok(dm_conn_dc_lift(f.D, xs, 3, q0, r, &e) == DM_EINVAL && strstr(e.msg, "not over"),
         "lift from a point not over the first shape: %s", e.msg);
  tap_ok(dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), f.B, NULL, NULL, NULL, &e) == NULL &&
         strstr(e.msg, "continuous connection"), "midpoint without a connection: %s", e.msg);
  tap_ok(dm_conn_dc_alloc(dm_conn_rule_find("levi-civita"), f.B, NULL, NULL, NULL, &e) == NULL &&
         strstr(e.msg, "sphere-frame"), "levi-civita on a trivial bundle: %s", e.msg);
  tap_ok(dm_conn_dc_alloc(dm_conn_rule_find("euler"), S, f.C, NULL, NULL, &e) == NULL &&
         strstr(e.msg, "trivial bundle"), "euler on the sphere frames: %s", e.msg);
  tap_ok(dm_conn_dc_alloc(dm_conn_rule_find("euler"), B2, f.C, NULL, NULL, &e) == NULL &&
         strstr(e.msg, "another bundle"), "a connection of another bundle: %s", e.msg);
  tap_ok(dm_conn_dc_alloc(dm_conn_rule_find("mechanical"), B2, NULL, NULL, NULL, &e) == NULL &&
         strstr(e.msg, "discrete Lagrangian"), "mechanical without Ld: %s", e.msg);
  tap_ok(dm_conn_rule_find("simpson") == NULL && dm_conn_rule_find(NULL) == NULL,
         "unknown rule not found");
  tap_ok(dm_conn_dc_local(bad, c, x1, g, &e) == DM_EDOM && strstr(e.msg, "not finite"),
         "a local representation that is not finite: %s", e.msg);
  tap_ok(dm_conn_dc_limit(f.D, q0, xs, xs, 0.0, g, &e) == DM_EINVAL, "limit with eps = 0: %s",
         e.msg);
  dm_conn_dc_free(bad);
  dm_conn_dc_free(NULL);
  dm_conn_bundle_free(B2);
  dm_lie_group_free(SO2);
  dm_conn_bundle_free(S);
  fixture_free(&f);
}

int main(void)
{
  dm_gsl_init();
  srand(2385);
  test_properties();
  test_QG();
  test_compose();
  test_limit();
  test_order();
  test_gauge();
  test_platform_phase();
  test_cat();
  test_rotor_lift();
  test_orbiter();
  test_exact();
  test_errors();
  return tap_done();
}
