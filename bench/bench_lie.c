/* bench_lie.c -- the Lie group variational integrator (src/lie) against
 * references, in one run, printing ratios:
 *
 *  1. cost per step of dmech's lgvi (the free rigid body and the heavy top,
 *     the system traced from expressions, native code when a compiler
 *     works) against a hand-written C LGVI of the same algorithm
 *     (Moser-Veselov trace form, Newton on a J f + b f x J f = h P with the
 *     analytic Jacobian, the same tolerance and warm start);
 *  2. the free rigid body over 1e4 periods of Pi's motion: lgvi at
 *     h = 0.005 (2.2e7 steps) against GSL's adaptive rk8pd on the quaternion
 *     ODE (a hand-written right-hand side) with the tolerance tightened
 *     until its error at T (against rk8pd at 1e-13) is no larger than
 *     lgvi's: CPU of both and the conservation errors of |Pi|, the spatial
 *     momentum R Pi and the energy at T.
 *
 * Thread CPU time, median of `reps` runs (default 5).
 * usage: bench_lie [reps [tape]]   (tape: no native code for dmech's programs) */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "lie/lie_system.h"
#include "lie/lie_impl.h"
#include "expr/native.h"
#include "lie_testsys.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmpd(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *x, int n)
{
  qsort(x, (size_t)n, sizeof *x, cmpd);
  return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

/* {==== the hand-written LGVI ============================================== */

typedef struct hand {
  double J[9], Jd[9], Jinv[9], mgrz, h, f[3];
  int warm;
} hand;

static void m3inv(const double *A, double *B)
{
  double d = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
             A[2] * (A[3] * A[7] - A[4] * A[6]);
  B[0] = (A[4] * A[8] - A[5] * A[7]) / d, B[1] = (A[2] * A[7] - A[1] * A[8]) / d;
  B[2] = (A[1] * A[5] - A[2] * A[4]) / d, B[3] = (A[5] * A[6] - A[3] * A[8]) / d;
  B[4] = (A[0] * A[8] - A[2] * A[6]) / d, B[5] = (A[2] * A[3] - A[0] * A[5]) / d;
  B[6] = (A[3] * A[7] - A[4] * A[6]) / d, B[7] = (A[1] * A[6] - A[0] * A[7]) / d;
  B[8] = (A[0] * A[4] - A[1] * A[3]) / d;
}

/* M = mg rz (R^T e3) x e3 */
static void moment(const hand *H, const double *R, double *M)
{
  M[0] = H->mgrz * R[7];
  M[1] = -H->mgrz * R[6];
  M[2] = 0.0;
}

static void hand_step(hand *H, double *R, double *Pi)
{
  double P[3], r[3], F[9], M[3], h = H->h, d;
  int it, i, j;
  moment(H, R, M);
  for (i = 0; i < 3; i++) {
    P[i] = Pi[i] + 0.5 * h * M[i];
    r[i] = h * P[i];
  }
  if (!H->warm)
    dm_m3_apply(H->Jinv, r, H->f);
  for (it = 0; it < 50; it++) {
    double *f = H->f, t = f[0] * f[0] + f[1] * f[1] + f[2] * f[2], a, b, da, db, Jf[3], fJf[3];
    double G[3], A[9], Ai[9], fn;
    a = dm_lie_sinc(t);
    b = dm_lie_cosc(t);
    if (t < 1e-2) {
      da = 2 * (-1.0 / 6 + t / 60 - t * t / 1680);
      db = 2 * (-1.0 / 24 + t / 360 - t * t / 13440);
    } else {
      double th = sqrt(t), s = sin(th), c = cos(th);
      da = (th * c - s) / (t * th);
      db = (th * s - 2 * (1 - c)) / (t * t);
    }
    dm_m3_apply(H->J, f, Jf);
    dm_v3_cross(f, Jf, fJf);
    for (i = 0; i < 3; i++)
      G[i] = a * Jf[i] + b * fJf[i] - r[i];
    {
      double fh[9], Jh[9], fhJ[9];
      dm_so3_poly(f, 0, 1, 0, fh, 3);
      dm_m3_mul(fh, H->J, fhJ);
      dm_so3_poly(Jf, 0, 1, 0, Jh, 3);
      for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
          A[3 * i + j] = a * H->J[3 * i + j] + b * (fhJ[3 * i + j] - Jh[3 * i + j]) +
                         (Jf[i] * da + fJf[i] * db) * f[j];
    }
    m3inv(A, Ai);
    dm_m3_apply(Ai, G, G);
    for (i = 0; i < 3; i++)
      f[i] -= G[i];
    fn = fmax(fabs(f[0]), fmax(fabs(f[1]), fabs(f[2])));
    d = fmax(fabs(G[0]), fmax(fabs(G[1]), fabs(G[2]))) / (fn > 0 ? fn : 1);
    if (d <= 10 * 2.2e-16)
      break;
  }
  H->warm = 1;
  dm_so3_exp(H->f, F);
  dm_m3_mul(R, F, R);
  dm_m3_tapply(F, P, Pi);
  moment(H, R, M);
  for (i = 0; i < 3; i++)
    Pi[i] += 0.5 * h * M[i];
}

/* }====================================================================== */

/* {==== the quaternion ODE for GSL ====================================== */

typedef struct qode {
  double J[3];
  long nf;
} qode;

static int qrhs(double t, const double *y, double *dy, void *p)
{
  qode *Q = p;
  const double *q = y, *Pi = y + 4;
  double w[3] = {Pi[0] / Q->J[0], Pi[1] / Q->J[1], Pi[2] / Q->J[2]};
  (void)t;
  Q->nf++;
  dy[0] = 0.5 * (-q[1] * w[0] - q[2] * w[1] - q[3] * w[2]);
  dy[1] = 0.5 * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1]);
  dy[2] = 0.5 * (q[0] * w[1] + q[3] * w[0] - q[1] * w[2]);
  dy[3] = 0.5 * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0]);
  dm_v3_cross(Pi, w, dy + 4);                     /* Pi' = Pi x W */
  return GSL_SUCCESS;
}

static void quat_R(const double *q, double *R)
{
  double w = q[0], x = q[1], y = q[2], z = q[3], s = 2.0 / (w * w + x * x + y * y + z * z);
  R[0] = 1 - s * (y * y + z * z), R[1] = s * (x * y - w * z), R[2] = s * (x * z + w * y);
  R[3] = s * (x * y + w * z), R[4] = 1 - s * (x * x + z * z), R[5] = s * (y * z - w * x);
  R[6] = s * (x * z - w * y), R[7] = s * (y * z + w * x), R[8] = 1 - s * (x * x + y * y);
}

/* rk8pd with tolerance tol from (I, Pi0) to T: R, Pi at T, function evaluations */
static double rk8pd(double tol, double T, double *R, double *Pi, long *nf)
{
  qode Q = {{1, 2, 3}, 0};
  gsl_odeiv2_system sys = {qrhs, NULL, 7, &Q};
  gsl_odeiv2_driver *d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-3, tol, tol);
  double y[7] = {1, 0, 0, 0, 1, 0.2, -0.5}, t = 0, t0 = now();
  gsl_odeiv2_driver_apply(d, &t, T, y);
  t0 = now() - t0;
  gsl_odeiv2_driver_free(d);
  quat_R(y, R);
  memcpy(Pi, y + 4, 3 * sizeof *Pi);
  *nf = Q.nf;
  return t0;
}

/* }====================================================================== */

static void conservation(const double *R, const double *Pi, double *dn, double *dJ, double *dE)
{
  double n0 = sqrt(1 + 0.04 + 0.25), J[3], E0 = 0.5 * (1 + 0.04 / 2 + 0.25 / 3);
  dm_m3_apply(R, Pi, J);
  *dn = fabs(sqrt(Pi[0] * Pi[0] + Pi[1] * Pi[1] + Pi[2] * Pi[2]) - n0);
  *dJ = sqrt((J[0] - 1) * (J[0] - 1) + (J[1] - 0.2) * (J[1] - 0.2) + (J[2] + 0.5) * (J[2] + 0.5));
  *dE = fabs(0.5 * (Pi[0] * Pi[0] + Pi[1] * Pi[1] / 2 + Pi[2] * Pi[2] / 3) - E0);
}

int main(int argc, char **argv)
{
  int reps = argc > 1 ? atoi(argv[1]) : 5, r, c;
  dm_expr_ctx *ctx;
  dm_lie_group *SO3;
  dm_err e;
  dm_gsl_init();
  ctx = dm_expr_ctx_alloc();
  SO3 = dm_lie_so3(NULL);
  if (reps < 1)
    reps = 1;
  dm_lie_register_integrators(&e);
  printf("# bench_lie: thread CPU, median of %d runs\n", reps);
  printf("## 1. cost per lgvi step: dmech (traced L) against hand-written C, 1e6 steps\n");
  for (c = 0; c < 2; c++) {
    double par[6] = {1, 2, 3, c ? 9.81 : 0, 0.3, 0}, td[16], th[16], h = 0.01;
    dm_lie_system *S;
    dm_integrator *I;
    hand H;
    int native = argc > 2 && strcmp(argv[2], "tape") == 0 ? DM_NATIVE_NEVER : DM_NATIVE_AUTO;
    if (lt_top(ctx, SO3, par, 0, 0, native, &S, &e) != DM_OK ||
        dm_integrator_new(dm_lie_system_base(S), "lgvi", NULL, &I, &e) != DM_OK) {
      printf("error: %s\n", e.msg);
      return 1;
    }
    memset(&H, 0, sizeof H);
    H.J[0] = 1, H.J[4] = 2, H.J[8] = 3;
    for (int i = 0; i < 9; i++)
      H.Jd[i] = -H.J[i] + (i % 4 == 0 ? 3.0 : 0.0);
    m3inv(H.J, H.Jinv);
    H.mgrz = par[3] * par[4];
    H.h = h;
    for (r = 0; r < reps + 1 && r < 16; r++) {
      double g[9], mu[3] = {1, 0.2, -0.5}, R[9], Pi[3] = {1, 0.2, -0.5}, w[3] = {0.5, 0, 0}, t0;
      long k;
      dm_so3_exp(w, g);
      memcpy(R, g, sizeof R);
      H.warm = 0;
      t0 = now();
      for (k = 0; k < 1000000; k++)
        dm_integrator_step(I, h, g, mu, g, mu, NULL);
      td[r] = now() - t0;
      t0 = now();
      for (k = 0; k < 1000000; k++)
        hand_step(&H, R, Pi);
      th[r] = now() - t0;
    }
    {
      /* the same algorithm: the first 1000 steps agree to round-off (the
       * heavy top is chaotic: over 1e6 steps round-off differences grow) */
      double g[9], mu[3] = {1, 0.2, -0.5}, R[9], Pi[3] = {1, 0.2, -0.5}, w[3] = {0.5, 0, 0}, d = 0;
      long k;
      dm_so3_exp(w, g);
      memcpy(R, g, sizeof R);
      H.warm = 0;
      dm_integrator_reset(I);
      for (k = 0; k < 1000; k++) {
        dm_integrator_step(I, h, g, mu, g, mu, NULL);
        hand_step(&H, R, Pi);
      }
      for (k = 0; k < 3; k++)
        d = fmax(d, fabs(mu[k] - Pi[k]));
      for (k = 0; k < 9; k++)
        d = fmax(d, fabs(g[k] - R[k]));
      printf("  %-15s after 1000 steps dmech and the hand-written LGVI differ by %.2g\n",
             c ? "heavy top" : "free rigid body", d);
    }
    {
      double a = median(td + 1, reps), b = median(th + 1, reps);
      printf("  %-15s dmech %7.1f ns/step   hand-written C %7.1f ns/step   ratio %.2f (%s)\n",
             c ? "heavy top" : "free rigid body", 1e9 * a / 1e6, 1e9 * b / 1e6, a / b,
             native == DM_NATIVE_AUTO ? "native code when a compiler works" : "tape");
    }
    dm_integrator_free(I);
    dm_lie_system_free(S);
  }

  printf("## 2. free rigid body over 1e4 periods: lgvi against GSL rk8pd (quaternions) at "
         "equal accuracy\n");
  {
    double par[6] = {1, 2, 3, 0, 0, 0}, Tp, T, h = 0.005, Rl[9], Pl[3], Rr[9], Pr[3], Rref[9], Pref[3];
    double tl[16], el, ttol = 1e-6, trk = 0, err = HUGE_VAL, dn, dJ, dE;
    dm_lie_system *S;
    dm_integrator *I;
    long nf = 0, k, n;
    /* the period of Pi's motion, from lgvi at a fine step: the first return
     * of Pi_2 through its initial value with the same sign of Pi_2' */
    lt_top(ctx, SO3, par, 0, 0, DM_NATIVE_AUTO, &S, &e);
    dm_integrator_new(dm_lie_system_base(S), "lgvi", NULL, &I, &e);
    {
      double g[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, mu[3] = {1, 0.2, -0.5}, prev = 0.2, t = 0;
      int crossings = 0;
      Tp = 0;
      for (k = 0; k < 10000000 && crossings < 2; k++) {
        double m2;
        dm_integrator_step(I, 0.001, g, mu, g, mu, NULL);
        t += 0.001;
        m2 = mu[1];
        if ((prev - 0.2) * (m2 - 0.2) < 0)
          crossings++;
        if (crossings == 2)
          Tp = t - 0.001 * (m2 - 0.2) / (m2 - prev);
        prev = m2;
      }
    }
    T = 1e4 * Tp;
    n = lround(T / h);
    printf("  period of Pi %.6f, T = 1e4 periods = %.1f, lgvi h = %g (%ld steps)\n", Tp, T, h, n);
    /* reference: rk8pd at 1e-13 */
    rk8pd(1e-13, T, Rref, Pref, &nf);
    for (r = 0; r < 1; r++) {          /* one run: 2.2e7 steps */
      double t0;
      memcpy(Rl, (double[9]){1, 0, 0, 0, 1, 0, 0, 0, 1}, sizeof Rl);
      Pl[0] = 1, Pl[1] = 0.2, Pl[2] = -0.5;
      dm_integrator_reset(I);
      t0 = now();
      for (k = 0; k < n; k++)
        dm_integrator_step(I, T / (double)n, Rl, Pl, Rl, Pl, NULL);
      tl[r] = now() - t0;
    }
    el = 0;
    for (k = 0; k < 3; k++)
      el = fmax(el, fabs(Pl[k] - Pref[k]));
    for (k = 0; k < 9; k++)
      el = fmax(el, fabs(Rl[k] - Rref[k]));
    conservation(Rl, Pl, &dn, &dJ, &dE);
    printf("  lgvi          CPU %8.3f s  error at T %.3g  ||Pi|-|Pi0|| %.2g  |R Pi - R0 Pi0| %.2g  "
           "|E - E0| %.2g\n", tl[0], el, dn, dJ, dE);
    for (ttol = 1e-6; ttol >= 1e-14; ttol /= 10) {
      double ts[16];
      for (r = 0; r < reps && r < 16; r++)
        ts[r] = rk8pd(ttol, T, Rr, Pr, &nf);
      trk = median(ts, reps);
      err = 0;
      for (k = 0; k < 3; k++)
        err = fmax(err, fabs(Pr[k] - Pref[k]));
      for (k = 0; k < 9; k++)
        err = fmax(err, fabs(Rr[k] - Rref[k]));
      if (err <= el)
        break;
    }
    conservation(Rr, Pr, &dn, &dJ, &dE);
    printf("  gsl rk8pd     CPU %8.3f s  error at T %.3g  ||Pi|-|Pi0|| %.2g  |R Pi - R0 Pi0| %.2g  "
           "|E - E0| %.2g  (tol %.0e, %ld evaluations)\n", trk, err, dn, dJ, dE, ttol, nf);
    printf("  CPU ratio lgvi / rk8pd at equal accuracy: %.2f\n", tl[0] / trk);
    dm_integrator_free(I);
    dm_lie_system_free(S);
  }
  dm_lie_group_free(SO3);
  dm_expr_ctx_free(ctx);
  return 0;
}
