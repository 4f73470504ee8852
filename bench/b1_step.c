/* b1_step.c -- B1: cost of one step, side by side in one run.
 *
 *  (a) Kepler e = 0.6, Stormer-Verlet h = 0.01
 *  (b) J2 (Cartesian), 2-stage Gauss h = 0.05
 * each as: hand-written C of the same algorithm (bench/peers/hand.h; the
 * reference, ratio 1), dmech on the hand-written C built-in system
 * (builtin_systems.h), dmech on a traced Lagrangian compiled to a tape and
 * to native code (bench/peers/traced.c, the C path dm.system uses), and GSL
 * odeiv2 rk4imp driven directly with a hand-written right-hand side.
 * dmech variants go through dm_integrator_run (what a user's run calls).
 * Per variant: the step count is calibrated so one run takes ~BENCH_B1_SEC
 * (default 0.15 s); R runs (BENCH_REPEAT, default 7) are interleaved across
 * the variants and the median CPU time per step is printed with its ratio
 * to the hand-written code.  A separate run of 10^4 steps from the same
 * start compares the final state with the hand-written one (same algorithm:
 * agreement to ~1e-12).
 */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "core/status.h"
#include "peers/benchutil.h"
#include "peers/gsl_peer.h"
#include "peers/hand.h"
#include "peers/problems.h"
#include "peers/traced.h"

enum { K_HAND_SV, K_HAND_SV_KAHAN, K_HAND_G2, K_DMECH, K_DMECH_STEP, K_GSL };

typedef struct variant {
  const char *name;
  int kind, prob;               /* prob: GP_KEPLER or GP_J2 */
  double h;
  dm_integrator *I;             /* dmech variants */
  dm_system sys;
  int have_sys;
  const gsl_odeiv2_step_type *gt;
  double eps;
  long N;                       /* calibrated steps per timed run */
  double t[64];
  double iters;                 /* Newton iterations per step (implicit) */
  double dev;                   /* final-state deviation from the hand code */
  int ok;
  char why[160];
} variant;

/* one run of N steps from the problem's start; CPU seconds (< 0: failure) */
static double run(variant *V, long N, double *q, double *p)
{
  size_t n = V->prob == GP_KEPLER ? 2 : 3;
  double y[6], t0, t1;
  dm_err e;
  int st = 0;
  long k;
  memcpy(q, V->prob == GP_KEPLER ? kep_q0 : j2_q0, n * sizeof(double));
  memcpy(p, V->prob == GP_KEPLER ? kep_p0 : j2_p0, n * sizeof(double));
  if (V->kind == K_GSL) {
    memcpy(y, q, n * sizeof(double));
    memcpy(y + n, p, n * sizeof(double));
  }
  if (V->I)
    dm_integrator_reset(V->I);
  t0 = bu_cpu();
  switch (V->kind) {
  case K_HAND_SV:
    if (V->prob == GP_KEPLER)
      hand_sv_kepler(V->h, N, q, p);
    else
      hand_sv_j2(V->h, N, q, p);
    break;
  case K_HAND_SV_KAHAN:
    hand_sv_kahan_kepler(V->h, N, q, p);
    break;
  case K_HAND_G2:
    V->iters = (double)(V->prob == GP_KEPLER ? hand_gauss2_kepler(V->h, N, q, p)
                                             : hand_gauss2_j2(V->h, N, q, p)) / (double)N;
    break;
  case K_DMECH:
    st = dm_integrator_run(V->I, 0.0, q, p, V->h, N, N, NULL, NULL, NULL, &e);
    break;
  case K_DMECH_STEP:
    for (k = 0; k < N && st == DM_OK; k++)
      st = dm_integrator_step(V->I, V->h, q, p, q, p, &e);
    break;
  case K_GSL:
    st = gp_fixed(V->gt, V->prob, V->h, N, y, V->eps);
    break;
  }
  t1 = bu_cpu();
  if (V->kind == K_GSL) {
    memcpy(q, y, n * sizeof(double));
    memcpy(p, y + n, n * sizeof(double));
  }
  if (V->I && V->I->stats.steps > 0)
    V->iters = (double)V->I->stats.iters_total / (double)V->I->stats.steps;
  if (st != 0) {
    snprintf(V->why, sizeof V->why, "%.150s", V->kind == K_GSL ? "GSL step failed" : e.msg);
    return -1.0;
  }
  return t1 - t0;
}

static void dmech_variant(variant *V, const char *name, int prob, double h, const char *method,
                          int stages, int traced_mode, int kind)
{
  dm_err e;
  dm_integ_opts o;
  memset(V, 0, sizeof *V);
  V->name = name;
  V->kind = kind;
  V->prob = prob;
  V->h = h;
  V->ok = 1;
  if (traced_mode < 0) {
    if (prob == GP_KEPLER)
      dm_builtin_kepler(&V->sys, 2, 1.0, &e);
    else
      dm_builtin_j2(&V->sys, J2_VALUE, &e);
  } else if (bt_build(prob == GP_KEPLER ? BT_KEPLER : BT_J2, traced_mode, &V->sys, NULL, &e) != DM_OK) {
    V->ok = 0;
    snprintf(V->why, sizeof V->why, "skipped: %.140s", e.msg);
    return;
  }
  V->have_sys = 1;
  dm_integ_opts_init(&o);
  o.stages = stages;
  if (dm_integrator_new(&V->sys, method, &o, &V->I, &e) != DM_OK) {
    V->ok = 0;
    snprintf(V->why, sizeof V->why, "skipped: %.140s", e.msg);
  }
}

static void plain_variant(variant *V, const char *name, int prob, double h, int kind)
{
  memset(V, 0, sizeof *V);
  V->name = name;
  V->kind = kind;
  V->prob = prob;
  V->h = h;
  V->ok = 1;
}

static void bench(const char *title, variant *Vs, int nv, int R, double target)
{
  double q[3], p[3], qr[3], pr[3], q1[3], p1[3];
  size_t n = Vs[0].prob == GP_KEPLER ? 2 : 3, i;
  int v, r;
  double ref;
  printf("\n## %s\n", title);
  /* agreement run */
  run(&Vs[0], 10000, qr, pr);
  for (v = 0; v < nv; v++) {
    variant *V = &Vs[v];
    if (!V->ok)
      continue;
    if (run(V, 10000, q1, p1) < 0) {
      V->ok = 0;
      continue;
    }
    V->dev = 0.0;
    for (i = 0; i < n; i++)
      V->dev = fmax(V->dev, fmax(fabs(q1[i] - qr[i]), fabs(p1[i] - pr[i])));
    /* calibrate */
    V->N = 1000;
    for (;;) {
      double t = run(V, V->N, q, p);
      if (t < 0) {
        V->ok = 0;
        break;
      }
      if (t >= 0.3 * target || V->N > 100000000L) {
        V->N = (long)((double)V->N * target / fmax(t, 1e-6));
        if (V->N < 100)
          V->N = 100;
        break;
      }
      V->N *= 4;
    }
  }
  for (r = 0; r < R; r++)
    for (v = 0; v < nv; v++)
      if (Vs[v].ok)
        Vs[v].t[r] = run(&Vs[v], Vs[v].N, q, p) / (double)Vs[v].N;
  ref = Vs[0].ok ? bu_median(Vs[0].t, R) : NAN;
  printf("%-44s %10s %9s %8s %11s %12s\n", "variant", "ns/step", "x hand", "steps", "iter/step",
         "|dy| 1e4 st");
  for (v = 0; v < nv; v++) {
    variant *V = &Vs[v];
    double m;
    if (!V->ok) {
      printf("%-44s %s\n", V->name, V->why[0] ? V->why : "failed");
      continue;
    }
    m = v == 0 ? ref : bu_median(V->t, R);
    printf("%-44s %10.1f %9.2f %8ld", V->name, 1e9 * m, m / ref, V->N);
    if (V->iters > 0)
      printf(" %11.2f", V->iters);
    else
      printf(" %11s", "-");
    printf(" %12.2e\n", V->dev);
  }
}

int main(void)
{
  int R = bu_env_int("BENCH_REPEAT", 7), i;
  const char *ts = getenv("BENCH_B1_SEC");
  double target = ts && *ts ? atof(ts) : 0.15;
  variant K[8], J[6];
  dm_gsl_init();
  if (R < 1)
    R = 1;
  if (R > 64)
    R = 64;
  bu_machine("B1 per-step cost (bench/b1_step.c, C harness linking libdmcore)");
  printf("# median of %d interleaved runs, each ~%.2f s CPU; ratios are to the hand-written C "
         "of the same algorithm, measured in this run\n", R, target);

  plain_variant(&K[0], "hand-written leapfrog (plain C)", GP_KEPLER, 0.01, K_HAND_SV);
  plain_variant(&K[1], "hand-written leapfrog + Kahan summation", GP_KEPLER, 0.01, K_HAND_SV_KAHAN);
  dmech_variant(&K[2], "dmech, built-in C system", GP_KEPLER, 0.01, "trapezoid", 0, -1, K_DMECH);
  dmech_variant(&K[3], "dmech, traced L, tape", GP_KEPLER, 0.01, "trapezoid", 0, DM_NATIVE_NEVER, K_DMECH);
  dmech_variant(&K[4], "dmech, traced L, native", GP_KEPLER, 0.01, "trapezoid", 0, DM_NATIVE_ALWAYS,
                K_DMECH);
  dmech_variant(&K[5], "dmech, built-in, step() per call", GP_KEPLER, 0.01, "trapezoid", 0, -1,
                K_DMECH_STEP);
  plain_variant(&K[6], "GSL rk4imp, hand rhs+Jacobian (not SV)", GP_KEPLER, 0.01, K_GSL);
  K[6].gt = gsl_odeiv2_step_rk4imp;
  K[6].eps = 1e-10;
  plain_variant(&K[7], "GSL rk4 (explicit, not SV)", GP_KEPLER, 0.01, K_GSL);
  K[7].gt = gsl_odeiv2_step_rk4;
  K[7].eps = 1e-10;
  bench("B1a Kepler e=0.6, Stormer-Verlet, h = 0.01", K, 8, R, target);

  plain_variant(&J[0], "hand-written Gauss-2, simplified Newton", GP_J2, 0.05, K_HAND_G2);
  dmech_variant(&J[1], "dmech gauss s=2, built-in C system", GP_J2, 0.05, "gauss", 2, -1, K_DMECH);
  dmech_variant(&J[2], "dmech gauss s=2, traced L, tape", GP_J2, 0.05, "gauss", 2, DM_NATIVE_NEVER,
                K_DMECH);
  dmech_variant(&J[3], "dmech gauss s=2, traced L, native", GP_J2, 0.05, "gauss", 2, DM_NATIVE_ALWAYS,
                K_DMECH);
  plain_variant(&J[4], "GSL rk4imp (= 3 Gauss-2 solves/step)", GP_J2, 0.05, K_GSL);
  J[4].gt = gsl_odeiv2_step_rk4imp;
  J[4].eps = 1e-10;
  bench("B1b J2 Cartesian, 2-stage Gauss, h = 0.05", J, 5, R, target);

  for (i = 0; i < 8; i++) {
    dm_integrator_free(K[i].I);
    if (K[i].have_sys)
      dm_system_release(&K[i].sys);
  }
  for (i = 0; i < 5; i++) {
    dm_integrator_free(J[i].I);
    if (J[i].have_sys)
      dm_system_release(&J[i].sys);
  }
  return 0;
}
