/* bench_expr.c -- the expression engine against hand-written C.
 *
 * For the J2 satellite (doc/reduce.md §13, Cartesian) and the double
 * spherical pendulum (§14, cylindrical, written with cos(th2 - th1)
 * as a person would), evaluate L + gradient + all second derivatives
 * through the dm_system callback three ways -- tape, native code, and
 * hand-derived C of the same formulas -- and print ns per evaluation
 * (median of repeated runs) and the ratios.  Also times derive + compile
 * (tape) from a fresh context.  Targets: native <= 1.3x hand, tape <= 5x.
 */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "core/status.h"
#include "core/system.h"
#include "expr/tape.h"

dm_expr tx_parse(dm_expr_ctx *ctx, const char *s);

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);   /* not the time other
                                                   processes take */
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* {==================================================================
 * hand-written J2 (Cartesian): L = |v|^2/2 + 1/R - J2/R^3 (1.5 z^2/R^2 - 0.5)
 * =================================================================== */

static int j2_hand(void *data, const double *q, const double *v,
                   const double *par, unsigned what, dm_lag_out *o, void *work)
{
  (void)data; (void)work;
  const double J2 = par[0], x = q[0], y = q[1], z = q[2];
  const double r2 = x * x + y * y + z * z, R = sqrt(r2), iR = 1 / R;
  const double a = iR / r2, b = a / r2, c = b / r2, d = c / r2;   /* R^-3.. */
  const double z2 = z * z;
  const double V = -iR + J2 * (1.5 * z2 * b - 0.5 * a);
  const double g = a + J2 * (1.5 * b - 7.5 * z2 * c);
  o->L = 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - V;
  for (int i = 0; i < 3; i++) {
    o->Lq[i] = -q[i] * g;
    o->Lv[i] = v[i];
  }
  o->Lq[2] -= 3 * J2 * z * b;
  if (what & ~(unsigned)DM_LAG_GRAD) {
    const double h = -3 * b - 7.5 * J2 * c + 52.5 * J2 * z2 * d;
    const double t = -15 * J2 * z * c;
    for (int i = 0; i < 3; i++)
      for (int j = i; j < 3; j++) {
        double H = (i == j ? g : 0) + q[i] * q[j] * h;
        if (j == 2)
          H += t * q[i] + (i == 2 ? t * q[j] + 3 * J2 * b : 0);
        o->Lqq[i * 3 + j] = o->Lqq[j * 3 + i] = -H;
        o->Lvv[i * 3 + j] = o->Lvv[j * 3 + i] = i == j;
        o->Lvq[i * 3 + j] = o->Lvq[j * 3 + i] = 0;
      }
  }
  return 0;
}

static const char j2_src[] =
  "0.5*(vx^2 + vy^2 + vz^2) + 1/sqrt(x^2 + y^2 + z^2)"
  " - pJ2/sqrt(x^2 + y^2 + z^2)^3*(1.5*z^2/(x^2 + y^2 + z^2) - 0.5)";

/* {==================================================================
 * hand-written double spherical pendulum
 *   L = (M/2)(k1 vr1^2 + r1^2 vth1^2) + (m2/2)(k2 vr2^2 + r2^2 vth2^2)
 *     + m2 (C A + S B + D vr1 vr2) + g (M w1 + m2 w2),
 *   w_i = sqrt(l_i^2 - r_i^2), k_i = l_i^2/w_i^2, C, S = cos, sin(th2 - th1),
 *   A = vr1 vr2 + r1 r2 vth1 vth2, B = r1 vth1 vr2 - r2 vr1 vth2,
 *   D = r1 r2/(w1 w2), M = m1 + m2.
 * =================================================================== */

static int dsp_hand(void *data, const double *q, const double *v,
                    const double *par, unsigned what, dm_lag_out *o, void *work)
{
  (void)data; (void)work;
  const double m1 = par[0], m2 = par[1], l1 = par[2], l2 = par[3], g = par[4];
  const double r1 = q[0], r2 = q[2], vr1 = v[0], vt1 = v[1], vr2 = v[2], vt2 = v[3];
  const double M = m1 + m2, L1 = l1 * l1, L2 = l2 * l2;
  const double W1 = L1 - r1 * r1, W2 = L2 - r2 * r2, w1 = sqrt(W1), w2 = sqrt(W2);
  const double k1 = L1 / W1, k2 = L2 / W2, iw12 = 1 / (w1 * w2);
  const double C = cos(q[3] - q[1]), S = sin(q[3] - q[1]);
  const double A = vr1 * vr2 + r1 * r2 * vt1 * vt2, B = r1 * vt1 * vr2 - r2 * vr1 * vt2;
  const double D = r1 * r2 * iw12;
  const double D1 = r2 * L1 / (W1 * w1 * w2), D2 = r1 * L2 / (w1 * W2 * w2);
  const double k1p = 2 * L1 * r1 / (W1 * W1), k2p = 2 * L2 * r2 / (W2 * W2);
  const double vv = vr1 * vr2;
  o->L = 0.5 * M * (k1 * vr1 * vr1 + r1 * r1 * vt1 * vt1)
       + 0.5 * m2 * (k2 * vr2 * vr2 + r2 * r2 * vt2 * vt2)
       + m2 * (C * A + S * B + D * vv) + g * (M * w1 + m2 * w2);
  const double SA_CB = m2 * (S * A - C * B);
  o->Lq[0] = 0.5 * M * (k1p * vr1 * vr1 + 2 * r1 * vt1 * vt1)
           + m2 * (C * r2 * vt1 * vt2 + S * vt1 * vr2 + D1 * vv) - g * M * r1 / w1;
  o->Lq[1] = SA_CB;
  o->Lq[2] = 0.5 * m2 * (k2p * vr2 * vr2 + 2 * r2 * vt2 * vt2)
           + m2 * (C * r1 * vt1 * vt2 - S * vr1 * vt2 + D2 * vv) - g * m2 * r2 / w2;
  o->Lq[3] = -SA_CB;
  o->Lv[0] = M * k1 * vr1 + m2 * ((C + D) * vr2 - S * r2 * vt2);
  o->Lv[1] = M * r1 * r1 * vt1 + m2 * r1 * (C * r2 * vt2 + S * vr2);
  o->Lv[2] = m2 * k2 * vr2 + m2 * ((C + D) * vr1 + S * r1 * vt1);
  o->Lv[3] = m2 * r2 * r2 * vt2 + m2 * r2 * (C * r1 * vt1 - S * vr1);
  if (!(what & ~(unsigned)DM_LAG_GRAD))
    return 0;
  double *Vv = o->Lvv, *Vq = o->Lvq, *Q = o->Lqq;
  Vv[0] = M * k1; Vv[1] = 0; Vv[2] = m2 * (C + D); Vv[3] = -m2 * S * r2;
  Vv[5] = M * r1 * r1; Vv[6] = m2 * S * r1; Vv[7] = m2 * C * r1 * r2;
  Vv[10] = m2 * k2; Vv[11] = 0; Vv[15] = m2 * r2 * r2;
  Vv[4] = Vv[1]; Vv[8] = Vv[2]; Vv[12] = Vv[3]; Vv[9] = Vv[6]; Vv[13] = Vv[7];
  Vv[14] = Vv[11];
  const double Svr2 = S * vr2, Cr2vt2 = C * r2 * vt2, Svr1 = S * vr1, Cr1vt1 = C * r1 * vt1;
  Vq[0] = M * k1p * vr1 + m2 * D1 * vr2;
  Vq[1] = m2 * (Svr2 + Cr2vt2);
  Vq[2] = m2 * (D2 * vr2 - S * vt2);
  Vq[3] = -Vq[1];
  Vq[4] = 2 * M * r1 * vt1 + m2 * (Cr2vt2 + Svr2);
  Vq[5] = m2 * r1 * (S * r2 * vt2 - C * vr2);
  Vq[6] = m2 * r1 * C * vt2;
  Vq[7] = -Vq[5];
  Vq[8] = m2 * (D1 * vr1 + S * vt1);
  Vq[9] = m2 * (Svr1 - Cr1vt1);
  Vq[10] = m2 * (k2p * vr2 + D2 * vr1);
  Vq[11] = -Vq[9];
  Vq[12] = m2 * r2 * C * vt1;
  Vq[13] = m2 * r2 * (S * r1 * vt1 + C * vr1);
  Vq[14] = 2 * m2 * r2 * vt2 + m2 * (Cr1vt1 - Svr1);
  Vq[15] = -Vq[13];
  const double k1pp = 2 * L1 / (W1 * W1) + 8 * L1 * r1 * r1 / (W1 * W1 * W1);
  const double k2pp = 2 * L2 / (W2 * W2) + 8 * L2 * r2 * r2 / (W2 * W2 * W2);
  const double D11 = 3 * r1 * r2 * L1 / (W1 * W1 * w1 * w2);
  const double D12 = L1 * L2 / (W1 * w1 * W2 * w2);
  const double D22 = 3 * r1 * r2 * L2 / (w1 * W2 * W2 * w2);
  const double CA_SB = m2 * (C * A + S * B);
  Q[0] = 0.5 * M * (k1pp * vr1 * vr1 + 2 * vt1 * vt1) + m2 * D11 * vv - g * M * L1 / (W1 * w1);
  Q[1] = m2 * vt1 * (S * r2 * vt2 - C * vr2);
  Q[2] = m2 * (C * vt1 * vt2 + D12 * vv);
  Q[3] = -Q[1];
  Q[5] = -CA_SB;
  Q[6] = m2 * vt2 * (S * r1 * vt1 + C * vr1);
  Q[7] = CA_SB;
  Q[10] = 0.5 * m2 * (k2pp * vr2 * vr2 + 2 * vt2 * vt2) + m2 * D22 * vv - g * m2 * L2 / (W2 * w2);
  Q[11] = -Q[6];
  Q[15] = -CA_SB;
  Q[4] = Q[1]; Q[8] = Q[2]; Q[12] = Q[3]; Q[9] = Q[6]; Q[13] = Q[7]; Q[14] = Q[11];
  return 0;
}

static const char dsp_src[] =
  "0.5*(pm1 + pm2)*(pl1^2/(pl1^2 - r1^2)*vr1^2 + r1^2*vth1^2)"
  " + 0.5*pm2*(pl2^2/(pl2^2 - r2^2)*vr2^2 + r2^2*vth2^2)"
  " + pm2*(cos(th2 - th1)*(vr1*vr2 + r1*r2*vth1*vth2)"
  " + sin(th2 - th1)*(r1*vth1*vr2 - r2*vr1*vth2)"
  " + r1*r2*vr1*vr2/(sqrt(pl1^2 - r1^2)*sqrt(pl2^2 - r2^2)))"
  " + pg*((pm1 + pm2)*sqrt(pl1^2 - r1^2) + pm2*sqrt(pl2^2 - r2^2))";

/* {==================================================================
 * harness
 * =================================================================== */

typedef struct problem {
  const char *name, *src;
  size_t n, npar;
  const char *q[4], *v[4], *par[5];
  double par0[5], x0[8];
  dm_lag_fn hand;
} problem;

static const problem problems[] = {
  { "J2 satellite (Cartesian)", j2_src, 3, 1, { "x", "y", "z" },
    { "vx", "vy", "vz" }, { "pJ2" }, { 0.05 },
    { 1.2385, -0.4172, 0.6031, 0.21, 0.83, -0.17 }, j2_hand },
  { "double spherical pendulum", dsp_src, 4, 5, { "r1", "th1", "r2", "th2" },
    { "vr1", "vth1", "vr2", "vth2" }, { "pm1", "pm2", "pl1", "pl2", "pg" },
    { 1.0, 1.5, 1.0, 1.2, 9.81 },
    { 0.6, 0.3, 0.5, 1.1, 0.2, -0.4, 0.3, 0.7 }, dsp_hand },
};

static int build(dm_expr_ctx *ctx, const problem *p, int native, dm_system *s,
                 dm_err *err)
{
  dm_expr q[4], v[4], par[5];
  for (size_t i = 0; i < p->n; i++) {
    q[i] = dm_expr_sym(ctx, p->q[i]);
    v[i] = dm_expr_sym(ctx, p->v[i]);
  }
  for (size_t i = 0; i < p->npar; i++)
    par[i] = dm_expr_param(ctx, p->par[i]);
  dm_lagrangian_spec sp = { .name = p->name, .n = p->n, .q = q, .v = v,
    .npar = p->npar, .par = par, .par_values = p->par0,
    .L = tx_parse(ctx, p->src), .native = native, .q0 = p->x0, .v0 = p->x0 + p->n };
  return dm_lagrangian_compile(ctx, &sp, s, err);
}

#define NPTS 64

typedef struct outs {
  double Lq[4], Lv[4], Lvv[16], Lvq[16], Lqq[16];
} outs;

/* The variants compared, timed interleaved (run r of every variant, then
 * run r+1, ...) so that load from other processes hits them alike. */
typedef struct variant {
  const char *name;
  dm_lag_fn fn;
  void *data;
  const double *par;
  double med, min;
} variant;

static void sweep_points(const variant *v, size_t n, const double *X,
                         unsigned what, void *work, long reps, double *sink)
{
  outs o;
  dm_lag_out lo = { 0, o.Lq, o.Lv, o.Lvv, o.Lvq, o.Lqq };
  for (long r = 0; r < reps; r++)
    for (int k = 0; k < NPTS; k++) {
      v->fn(v->data, X + 2 * n * k, X + 2 * n * k + n, v->par, what, &lo, work);
      *sink += lo.L + o.Lq[0];
    }
}

/* ns per evaluation: median and minimum over RUNS interleaved runs. */
static void time_variants(variant *v, int nv, size_t n, const double *X,
                          unsigned what, void *work, double *sink)
{
  enum { RUNS = 31 };
  double t[8][RUNS];
  long reps = 1;
  for (;;) {                          /* calibrate the slowest to ~5 ms */
    double t0 = now();
    for (int i = 0; i < nv; i++)
      sweep_points(&v[i], n, X, what, work, reps, sink);
    if (now() - t0 > 0.005 * nv || reps > (1L << 24))
      break;
    reps *= 2;
  }
  for (int r = 0; r < RUNS; r++)
    for (int i = 0; i < nv; i++) {
      double t0 = now();
      sweep_points(&v[i], n, X, what, work, reps, sink);
      t[i][r] = (now() - t0) / ((double)reps * NPTS) * 1e9;
    }
  for (int i = 0; i < nv; i++) {
    qsort(t[i], RUNS, sizeof t[i][0], cmp_d);
    v[i].min = t[i][0];
    v[i].med = t[i][RUNS / 2];
  }
}

/* Largest relative difference between two evaluators at x. */
static double compare(const dm_system *a, dm_lag_fn hand, size_t n,
                      const double *par, const double *x)
{
  outs oa, ob;
  dm_lag_out la = { 0, oa.Lq, oa.Lv, oa.Lvv, oa.Lvq, oa.Lqq };
  dm_lag_out lb = { 0, ob.Lq, ob.Lv, ob.Lvv, ob.Lvq, ob.Lqq };
  void *w = malloc(a->work_size);
  a->lagrangian(a->data, x, x + n, par, DM_LAG_ALL, &la, w);
  hand(NULL, x, x + n, par, DM_LAG_ALL, &lb, NULL);
  free(w);
  double d = fabs(la.L - lb.L) / fmax(1, fabs(lb.L));
  const double *A[5] = { oa.Lq, oa.Lv, oa.Lvv, oa.Lvq, oa.Lqq };
  const double *B[5] = { ob.Lq, ob.Lv, ob.Lvv, ob.Lvq, ob.Lqq };
  for (int k = 0; k < 5; k++)
    for (size_t i = 0; i < (k < 2 ? n : n * n); i++)
      d = fmax(d, fabs(A[k][i] - B[k][i]) / fmax(1, fabs(B[k][i])));
  return d;
}

static double compile_ms(const problem *p)
{
  enum { RUNS = 11 };
  double t[RUNS];
  for (int r = 0; r < RUNS; r++) {
    double t0 = now();
    dm_expr_ctx *ctx = dm_expr_ctx_alloc();
    dm_system s;
    build(ctx, p, DM_NATIVE_NEVER, &s, NULL);
    t[r] = (now() - t0) * 1e3;
    dm_system_release(&s);
    dm_expr_ctx_free(ctx);
  }
  qsort(t, RUNS, sizeof *t, cmp_d);
  return t[RUNS / 2];
}

int main(void)
{
  dm_gsl_init();
  double sink = 0;
  int bad = 0;
  printf("# L + gradient + all second derivatives (Lvv, Lvq, Lqq) through the "
         "dm_system callback;\n# ns (thread CPU time) per evaluation, median and minimum of 31 interleaved runs over %d "
         "states; ratios to hand-written C\n", NPTS);
  for (size_t pi = 0; pi < sizeof problems / sizeof problems[0]; pi++) {
    const problem *p = &problems[pi];
    size_t n = p->n;
    double X[NPTS * 8];
    for (int k = 0; k < NPTS; k++)
      for (size_t i = 0; i < 2 * n; i++)
        X[2 * n * k + i] = p->x0[i] * (1 + 0.01 * ((k * 7 + (int)i * 3) % 11 - 5) / 5.0);
    dm_expr_ctx *ctx = dm_expr_ctx_alloc();
    dm_system st, sn;
    dm_err err;
    if (build(ctx, p, DM_NATIVE_NEVER, &st, &err) != DM_OK) {
      printf("%s: %s\n", p->name, err.msg);
      return 1;
    }
    int have_native = build(ctx, p, DM_NATIVE_ALWAYS, &sn, &err) == DM_OK;
    if (!have_native)
      printf("# native code unavailable: %s\n", err.msg);
    dm_lagrangian_stats ls;
    dm_lagrangian_stats_get(&st, &ls);
    double diff = compare(&st, p->hand, n, p->par0, p->x0);
    bad |= !(diff < 1e-12);
    void *work = malloc(st.work_size > 4096 ? st.work_size : 4096);
    printf("\n%s: tape %zu instructions (gradient tape %zu); hand vs tape max "
           "rel diff %.1e\n", p->name, ls.ninstr_all, ls.ninstr_grad, diff);
    printf("  %-10s %-8s %10s %8s %10s %8s\n", "request", "variant", "median ns",
           "ratio", "min ns", "ratio");
    static const unsigned whats[2] = { DM_LAG_ALL, DM_LAG_GRAD };
    static const char *const wname[2] = { "all", "gradient" };
    static const char *const target[3] = { "", "   (target <= 1.3)", "   (target <= 5)" };
    for (int wi = 0; wi < 2; wi++) {
      variant v[3] = { { "hand C", p->hand, NULL, p->par0, 0, 0 },
                       { "native", sn.lagrangian, sn.data, sn.par, 0, 0 },
                       { "tape", st.lagrangian, st.data, st.par, 0, 0 } };
      if (!have_native)
        v[1] = v[2];
      int nv = have_native ? 3 : 2;
      time_variants(v, nv, n, X, whats[wi], work, &sink);
      for (int i = 0; i < nv; i++)
        printf("  %-10s %-8s %10.1f %8.2f %10.1f %8.2f%s\n", wname[wi], v[i].name,
               v[i].med, v[i].med / v[0].med, v[i].min, v[i].min / v[0].min,
               target[i == 0 ? 0 : strcmp(v[i].name, "native") == 0 ? 1 : 2]);
    }
    printf("  derive + compile (tape) from a fresh context: %.3f ms (median of 11)\n",
           compile_ms(p));
    free(work);
    dm_system_release(&st);
    if (have_native)
      dm_system_release(&sn);
    dm_expr_ctx_free(ctx);
  }
  printf("# checksum %g\n", sink);
  if (bad)
    printf("# ERROR: hand-written code and tape disagree\n");
  return bad;
}
