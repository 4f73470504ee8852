/* bench_conn.c -- connections (doc/bundles-connections-holonomy.md §10):
 *
 * 1. Holonomy of a closed 10^4-vertex shape loop by the midpoint discrete
 *    connection, cost per vertex: dmech (dm_conn_dc_holonomy on the
 *    mechanical connection derived from the reduced Lagrangian, A = I^-1 C
 *    compiled to tapes) against a hand-written C loop of the same rule
 *    (closed-form A_loc, exp, multiply), for the three-link cat (SO(2))
 *    and the rotor craft (SO(3)).  Both must agree to round-off.
 * 2. The discrete mechanical connection: Newton iterations and cost per
 *    pair for the platform (midpoint L_d, abelian, from the midpoint guess)
 *    and free particles under SO(3) (from the identity; reference: the
 *    Kabsch rotation by GSL's SVD, the closed form of the same answer).
 *
 * Each variant runs `reps` times (interleaved after a warm-up), thread CPU
 * time, median.  usage: bench_conn [reps [native]] (native = 0: the cat's
 * A_loc runs as a tape, else native code when a compiler works) */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_linalg.h>

#include "conn/conn.h"

#define NV 10000

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *t, int n)
{
  qsort(t, (size_t)n, sizeof *t, cmp);
  return t[n / 2];
}

static dm_expr_ctx *cx;
#define K(x) dm_expr_const(cx, (x))
#define ADD(a, b) dm_expr_add(cx, (a), (b))
#define SUB(a, b) dm_expr_sub(cx, (a), (b))
#define MUL(a, b) dm_expr_mul(cx, (a), (b))
#define SQ(a) dm_expr_mul(cx, (a), (a))

/* {==== the cat ============================================================= */

/* the reduced Lagrangian of the three-link cat (lua/dmech/bundles.lua) */
static dm_expr cat_l(const dm_expr *x, const dm_expr *xd, dm_expr xi)
{
  dm_expr c[3][2], cm[2], T, third = K(1.0 / 3);
  int i, a;
  c[0][0] = K(0);
  c[0][1] = K(0);
  c[1][0] = SUB(K(-0.5), MUL(K(0.5), dm_expr_unary(cx, DM_EXPR_COS, x[0])));
  c[1][1] = MUL(K(-0.5), dm_expr_unary(cx, DM_EXPR_SIN, x[0]));
  c[2][0] = ADD(K(0.5), MUL(K(0.5), dm_expr_unary(cx, DM_EXPR_COS, x[1])));
  c[2][1] = MUL(K(0.5), dm_expr_unary(cx, DM_EXPR_SIN, x[1]));
  for (a = 0; a < 2; a++)
    cm[a] = MUL(third, ADD(ADD(c[0][a], c[1][a]), c[2][a]));
  T = MUL(K(1.0 / 24), ADD(ADD(SQ(xi), SQ(ADD(xi, xd[0]))), SQ(ADD(xi, xd[1]))));
  for (i = 0; i < 3; i++) {
    dm_expr r[2], v[2];
    for (a = 0; a < 2; a++) {
      r[a] = SUB(c[i][a], cm[a]);
      v[a] = ADD(MUL(dm_expr_diff(cx, r[a], x[0]), xd[0]), MUL(dm_expr_diff(cx, r[a], x[1]), xd[1]));
    }
    v[0] = SUB(v[0], MUL(xi, r[1]));
    v[1] = ADD(v[1], MUL(xi, r[0]));
    T = ADD(T, MUL(K(0.5), ADD(SQ(v[0]), SQ(v[1]))));
  }
  return T;
}

/* the same A_loc by hand: centres relative to the centre of mass */
static void cat_A_hand(double x1, double x2, double *A)
{
  double s1 = sin(x1), c1 = cos(x1), s2 = sin(x2), c2 = cos(x2);
  double c[3][2] = {{0, 0}, {-0.5 - 0.5 * c1, -0.5 * s1}, {0.5 + 0.5 * c2, 0.5 * s2}};
  double d1[3][2] = {{0, 0}, {0.5 * s1, -0.5 * c1}, {0, 0}};
  double d2[3][2] = {{0, 0}, {0, 0}, {-0.5 * s2, 0.5 * c2}};
  double cm[2], m1[2], m2[2], num1 = 1.0 / 12, num2 = 1.0 / 12, den = 0.25;
  int i, a;
  for (a = 0; a < 2; a++) {
    cm[a] = (c[0][a] + c[1][a] + c[2][a]) / 3;
    m1[a] = (d1[0][a] + d1[1][a] + d1[2][a]) / 3;
    m2[a] = (d2[0][a] + d2[1][a] + d2[2][a]) / 3;
  }
  for (i = 0; i < 3; i++) {
    double rx = c[i][0] - cm[0], ry = c[i][1] - cm[1];
    den += rx * rx + ry * ry;
    num1 += rx * (d1[i][1] - m1[1]) - ry * (d1[i][0] - m1[0]);
    num2 += rx * (d2[i][1] - m2[1]) - ry * (d2[i][0] - m2[0]);
  }
  A[0] = num1 / den;
  A[1] = num2 / den;
}

/* the midpoint lift by hand: theta_{k+1} = theta_k - A(xbar) dx */
static double cat_hand(const double *xs, size_t n)
{
  double th = 0.0, A[2];
  size_t k;
  for (k = 0; k + 1 < n; k++) {
    const double *a = xs + 2 * k, *b = a + 2;
    cat_A_hand(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), A);
    th -= A[0] * (b[0] - a[0]) + A[1] * (b[1] - a[1]);
  }
  return th;
}

/* }==== */

/* {==== the rotor craft ===================================================== */

static const double RI[3] = {1.0, 1.2, 1.5}, RK[3] = {0.5, 0.45, 0.4};

static dm_expr rotor_l(const dm_expr *x, const dm_expr *xd, const dm_expr *xi)
{
  dm_expr T = K(0);
  int i;
  (void)x;
  for (i = 0; i < 3; i++) {
    T = ADD(T, MUL(K(0.5 * (RI[i] - RK[i])), SQ(xi[i])));
    T = ADD(T, MUL(K(0.5 * RK[i]), SQ(ADD(xi[i], xd[i]))));
  }
  return T;
}

/* Rodrigues exp(hat w) into R (row-major) */
static void rodrigues(const double *w, double *R)
{
  double t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], t = sqrt(t2), a, b;
  if (t2 < 1e-8) {
    a = 1.0 - t2 / 6.0;
    b = 0.5 - t2 / 24.0;
  } else {
    a = sin(t) / t;
    b = (1.0 - cos(t)) / t2;
  }
  R[0] = 1 - b * (w[1] * w[1] + w[2] * w[2]);
  R[1] = -a * w[2] + b * w[0] * w[1];
  R[2] = a * w[1] + b * w[0] * w[2];
  R[3] = a * w[2] + b * w[0] * w[1];
  R[4] = 1 - b * (w[0] * w[0] + w[2] * w[2]);
  R[5] = -a * w[0] + b * w[1] * w[2];
  R[6] = -a * w[1] + b * w[0] * w[2];
  R[7] = a * w[0] + b * w[1] * w[2];
  R[8] = 1 - b * (w[0] * w[0] + w[1] * w[1]);
}

/* g_{k+1} = g_k A^-1, A = exp(diag(k/I) dphi): g <- g exp(-diag(k/I) dphi) */
static void rotor_hand(const double *xs, size_t n, double *g)
{
  double w[3], E[9], t[9];
  size_t k;
  int i, j, l;
  memset(g, 0, 9 * sizeof *g);
  g[0] = g[4] = g[8] = 1.0;
  for (k = 0; k + 1 < n; k++) {
    for (i = 0; i < 3; i++)
      w[i] = -(RK[i] / RI[i]) * (xs[3 * (k + 1) + i] - xs[3 * k + i]);
    rodrigues(w, E);
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++) {
        double s = 0.0;
        for (l = 0; l < 3; l++)
          s += g[3 * i + l] * E[3 * l + j];
        t[3 * i + j] = s;
      }
    memcpy(g, t, sizeof t);
  }
}

/* }==== */

/* {==== particles (Kabsch) =================================================== */

static void kabsch(size_t n, const double *X, const double *Y, gsl_matrix *H, gsl_matrix *V,
                   gsl_vector *S, gsl_vector *w, double *R)
{
  size_t i, a, b, k;
  double U[9], Vm[9], d;
  gsl_matrix_set_zero(H);
  for (i = 0; i < n; i++)
    for (a = 0; a < 3; a++)
      for (b = 0; b < 3; b++)
        *gsl_matrix_ptr(H, a, b) += Y[3 * i + a] * X[3 * i + b];
  gsl_linalg_SV_decomp(H, V, S, w);
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
}

/* }==== */

static void syms(const char *pre, size_t n, dm_expr *out)
{
  char name[32];
  size_t i;
  for (i = 0; i < n; i++) {
    snprintf(name, sizeof name, "%s%zu", pre, i + 1);
    out[i] = dm_expr_sym(cx, name);
  }
}

int main(int argc, char **argv)
{
  int reps = argc > 1 ? atoi(argv[1]) : 9, r, native = argc > 2 ? atoi(argv[2]) : 1;
  double *xs = malloc(3 * (NV + 1) * sizeof *xs), tA[64], tB[64];
  dm_err e;
  size_t k;
  if (reps < 1 || reps > 64)
    reps = 9;
  dm_gsl_init();
  cx = dm_expr_ctx_alloc();
  printf("bench_conn: thread CPU time, median of %d runs\n\n", reps);

  /* ---- the cat ---- */
  {
    dm_lie_group *G = dm_lie_so2(NULL);
    dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
    dm_expr x[2], xd[2], xi;
    dm_conn *C;
    dm_conn_dc *D;
    double q0[3], hol = 0, hand = 0;
    syms("cx", 2, x);
    syms("cxd", 2, xd);
    xi = dm_expr_sym(cx, "cxi");
    C = dm_conn_lagrangian_alloc(cx, B, x, xd, &xi, cat_l(x, xd, xi), 0, NULL, NULL, NULL, &e);
    if (native && dm_conn_native(C, NULL, &e) != DM_OK)
      printf("(no native code: %s)\n", e.msg);
    D = dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), B, C, NULL, NULL, &e);
    for (k = 0; k <= NV; k++) {
      double s = 2 * M_PI * (double)k / NV;
      xs[2 * k] = 2.0 + 0.97 * cos(s);
      xs[2 * k + 1] = -2.0 + 0.97 * sin(s);
    }
    xs[2 * NV] = xs[0];
    xs[2 * NV + 1] = xs[1];
    q0[0] = xs[0];
    q0[1] = xs[1];
    q0[2] = 0.0;
    for (r = -1; r < reps; r++) {
      double t0 = now();
      dm_conn_dc_holonomy(D, xs, NV + 1, q0, NULL, NULL, &hol, NULL);
      double t1 = now();
      hand = cat_hand(xs, NV + 1);
      double t2 = now();
      if (r >= 0) {
        tA[r] = t1 - t0;
        tB[r] = t2 - t1;
      }
    }
    printf("holonomy, three-link cat (SO(2)), midpoint, %d vertices:\n", NV);
    printf("  dmech (A = I^-1 C from l, %s)%s %8.1f ns/vertex\n", native ? "native" : "tape",
           native ? "" : "  ", 1e9 * median(tA, reps) / NV);
    printf("  hand-written C loop               %8.1f ns/vertex\n", 1e9 * median(tB, reps) / NV);
    printf("  ratio dmech/hand %.2f   holonomy %.15f, hand %.15f (diff %.1e)\n\n",
           median(tA, reps) / median(tB, reps), hol, hand, fabs(hol - hand));
    dm_conn_dc_free(D);
    dm_conn_free(C);
    dm_conn_bundle_free(B);
    dm_lie_group_free(G);
  }

  /* ---- the rotor craft ---- */
  {
    dm_lie_group *G = dm_lie_so3(NULL);
    dm_conn_bundle *B = dm_conn_bundle_trivial(3, G, NULL);
    dm_expr x[3], xd[3], xi[3];
    dm_conn *C;
    dm_conn_dc *D;
    double q0[12], P[9], hand[9];
    syms("rx", 3, x);
    syms("rxd", 3, xd);
    syms("rxi", 3, xi);
    C = dm_conn_lagrangian_alloc(cx, B, x, xd, xi, rotor_l(x, xd, xi), 0, NULL, NULL, NULL, &e);
    D = dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), B, C, NULL, NULL, &e);
    for (k = 0; k <= NV; k++) {
      double s = 2 * M_PI * (double)k / NV;
      xs[3 * k] = cos(3 * s) - 1;
      xs[3 * k + 1] = sin(2 * s);
      xs[3 * k + 2] = 0.5 * sin(s);
    }
    memset(q0, 0, sizeof q0);
    dm_lie_identity(G, q0 + 3);
    for (r = -1; r < reps; r++) {
      double t0 = now();
      dm_conn_dc_holonomy(D, xs, NV + 1, q0, NULL, P, NULL, NULL);
      double t1 = now();
      rotor_hand(xs, NV + 1, hand);
      double t2 = now();
      if (r >= 0) {
        tA[r] = t1 - t0;
        tB[r] = t2 - t1;
      }
    }
    {
      double d = 0;
      int i;
      for (i = 0; i < 9; i++)
        d = fmax(d, fabs(P[i] - hand[i]));
      printf("holonomy, rotor craft (SO(3)), midpoint, %d vertices:\n", NV);
      printf("  dmech (A = I^-1 C from l, tape)   %8.1f ns/vertex\n", 1e9 * median(tA, reps) / NV);
      printf("  hand-written C loop               %8.1f ns/vertex\n", 1e9 * median(tB, reps) / NV);
      printf("  ratio dmech/hand %.2f   max |P - P_hand| %.1e\n\n", median(tA, reps) / median(tB, reps), d);
    }
    dm_conn_dc_free(D);
    dm_conn_free(C);
    dm_conn_bundle_free(B);
    dm_lie_group_free(G);
  }

  /* ---- the discrete mechanical connection ---- */
  {
    dm_lie_group *G = dm_lie_so2(NULL);
    dm_conn_bundle *B = dm_conn_bundle_trivial(2, G, NULL);
    dm_expr q0[3], q1[3], qb[3], v[3], Ld, a, b;
    const double h = 0.1;
    dm_conn *C;
    dm_conn_dc *M, *D;
    unsigned long s0, i0, s1, i1;
    double A, Am, worst = 0;
    const int npairs = 2000;
    int i;
    syms("p0_", 3, q0);
    syms("p1_", 3, q1);
    for (i = 0; i < 3; i++) {
      qb[i] = MUL(K(0.5), ADD(q0[i], q1[i]));
      v[i] = MUL(K(1 / h), SUB(q1[i], q0[i]));
    }
    a = SUB(v[0], MUL(v[2], qb[1]));
    b = ADD(v[1], MUL(v[2], qb[0]));
    Ld = MUL(K(h), ADD(MUL(K(0.5), SQ(v[2])), MUL(K(0.5), ADD(SQ(a), SQ(b)))));
    {
      dm_expr x[2], xd[2], xi;
      syms("px", 2, x);
      syms("pxd", 2, xd);
      xi = dm_expr_sym(cx, "pxi");
      dm_expr aa = SUB(xd[0], MUL(xi, x[1])), bb = ADD(xd[1], MUL(xi, x[0]));
      C = dm_conn_lagrangian_alloc(cx, B, x, xd, &xi,
                                   ADD(MUL(K(0.5), SQ(xi)), MUL(K(0.5), ADD(SQ(aa), SQ(bb)))), 0,
                                   NULL, NULL, NULL, &e);
    }
    M = dm_conn_dc_alloc(dm_conn_rule_find("midpoint"), B, C, NULL, NULL, &e);
    D = dm_conn_dc_mechanical(B, cx, q0, q1, Ld, 0, NULL, NULL, M, 0, 0, &e);
    srand(5);
    for (k = 0; k < (size_t)npairs; k++) {
      xs[4 * k] = 2.0 * rand() / RAND_MAX - 1;
      xs[4 * k + 1] = 2.0 * rand() / RAND_MAX - 1;
      xs[4 * k + 2] = xs[4 * k] + 0.2 * (2.0 * rand() / RAND_MAX - 1);
      xs[4 * k + 3] = xs[4 * k + 1] + 0.2 * (2.0 * rand() / RAND_MAX - 1);
    }
    dm_conn_dc_newton_stats(D, &s0, &i0);
    for (r = -1; r < reps; r++) {
      double t0 = now();
      for (k = 0; k < (size_t)npairs; k++)
        dm_conn_dc_local(D, xs + 4 * k, xs + 4 * k + 2, &A, NULL);
      double t1 = now();
      for (k = 0; k < (size_t)npairs; k++)
        dm_conn_dc_local(M, xs + 4 * k, xs + 4 * k + 2, &Am, NULL);
      double t2 = now();
      if (r >= 0) {
        tA[r] = t1 - t0;
        tB[r] = t2 - t1;
      }
    }
    for (k = 0; k < (size_t)npairs; k++) {
      dm_conn_dc_local(D, xs + 4 * k, xs + 4 * k + 2, &A, NULL);
      dm_conn_dc_local(M, xs + 4 * k, xs + 4 * k + 2, &Am, NULL);
      worst = fmax(worst, fabs(A - Am));
    }
    dm_conn_dc_newton_stats(D, &s1, &i1);
    printf("discrete mechanical connection, platform (midpoint L_d, SO(2)), %d pairs:\n", npairs);
    printf("  Newton iterations per pair %.2f (from the midpoint guess)\n",
           (double)(i1 - i0) / (double)(s1 - s0));
    printf("  dmech %.0f ns/pair; the midpoint rule it reproduces %.0f ns/pair (ratio %.1f); "
           "max difference %.1e\n\n", 1e9 * median(tA, reps) / npairs, 1e9 * median(tB, reps) / npairs,
           median(tA, reps) / median(tB, reps), worst);
    dm_conn_dc_free(D);
    dm_conn_dc_free(M);
    dm_conn_free(C);
    dm_conn_bundle_free(B);
    dm_lie_group_free(G);
  }
  {
    const size_t n = 6;
    dm_conn_bundle *B = dm_conn_bundle_particles(n, NULL);
    dm_expr x[18], y[18], Ld = K(0);
    dm_conn_dc *D;
    gsl_matrix *H = gsl_matrix_alloc(3, 3), *V = gsl_matrix_alloc(3, 3);
    gsl_vector *S = gsl_vector_alloc(3), *w = gsl_vector_alloc(3);
    const int npairs = 500;
    double *X = malloc(2 * 18 * npairs * sizeof *X), A[9], Rk[9], Ai[9], worst = 0;
    unsigned long s0, i0, s1, i1;
    size_t i;
    syms("kx", 18, x);
    syms("ky", 18, y);
    for (i = 0; i < 18; i++)
      Ld = ADD(Ld, MUL(K(0.5 / 0.1), SQ(SUB(y[i], x[i]))));
    D = dm_conn_dc_mechanical(B, cx, x, y, Ld, 0, NULL, NULL, NULL, 0, 0, &e);
    srand(7);
    for (k = 0; k < (size_t)npairs; k++) {
      double wv[3] = {0.8 * (2.0 * rand() / RAND_MAX - 1), 0.8 * (2.0 * rand() / RAND_MAX - 1),
                      0.8 * (2.0 * rand() / RAND_MAX - 1)}, Rt[9];
      rodrigues(wv, Rt);
      for (i = 0; i < 18; i++)
        X[36 * k + i] = 2.0 * rand() / RAND_MAX - 1;
      for (i = 0; i < n; i++) {
        int a, c;
        for (a = 0; a < 3; a++) {
          double s = 0.0;
          for (c = 0; c < 3; c++)
            s += Rt[3 * a + c] * X[36 * k + 3 * i + c];
          X[36 * k + 18 + 3 * i + a] = s + 0.1 * (2.0 * rand() / RAND_MAX - 1);
        }
      }
    }
    dm_conn_dc_newton_stats(D, &s0, &i0);
    for (r = -1; r < reps; r++) {
      double t0 = now();
      for (k = 0; k < (size_t)npairs; k++)
        dm_conn_dc_eval(D, X + 36 * k, X + 36 * k + 18, A, NULL);
      double t1 = now();
      for (k = 0; k < (size_t)npairs; k++)
        kabsch(n, X + 36 * k, X + 36 * k + 18, H, V, S, w, Rk);
      double t2 = now();
      if (r >= 0) {
        tA[r] = t1 - t0;
        tB[r] = t2 - t1;
      }
    }
    dm_conn_dc_newton_stats(D, &s1, &i1);
    for (k = 0; k < (size_t)npairs; k++) {
      int a;
      dm_conn_dc_eval(D, X + 36 * k, X + 36 * k + 18, A, NULL);
      kabsch(n, X + 36 * k, X + 36 * k + 18, H, V, S, w, Rk);
      for (a = 0; a < 3; a++) {
        int c;
        for (c = 0; c < 3; c++)
          Ai[3 * a + c] = A[3 * c + a];
      }
      for (a = 0; a < 9; a++)
        worst = fmax(worst, fabs(Ai[a] - Rk[a]));
    }
    printf("discrete mechanical connection, %zu free particles (SO(3)), %d pairs:\n", n, npairs);
    printf("  Newton iterations per pair %.2f (from the identity; rotations up to 0.8 sqrt3 rad)\n",
           (double)(i1 - i0) / (double)(s1 - s0));
    printf("  dmech %.0f ns/pair; Kabsch by GSL SVD %.0f ns/pair (ratio %.1f); max |A_d^-1 - R| %.1e\n",
           1e9 * median(tA, reps) / npairs, 1e9 * median(tB, reps) / npairs,
           median(tA, reps) / median(tB, reps), worst);
    dm_conn_dc_free(D);
    dm_conn_bundle_free(B);
    gsl_matrix_free(H);
    gsl_matrix_free(V);
    gsl_vector_free(S);
    gsl_vector_free(w);
    free(X);
  }
  dm_expr_ctx_free(cx);
  free(xs);
  return 0;
}
