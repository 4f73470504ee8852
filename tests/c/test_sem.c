/* test_sem.c -- symplectic-energy-momentum integrators (doc/beyond-fixed-steps.md §2):
 * the pendulum with midpoint SEM (step range, the discrete energy
 * recomputed from the trajectory in closed form, energy error maxima,
 * order 2 at the reached time), the harmonic oscillator (constant steps),
 * Gauss s = 2 SEM (order 4, discrete energy), the degenerate-energy
 * fallback (free particle; an energy level no step can match is flagged),
 * runs to t_end, errors. */
#include <config.h>
#include <float.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "core/run.h"
#include "integrators/integrator.h"
#include "integrators/sem.h"
#include "tap.h"

/* L = v^2/2 + k cos q (k = 0: a free particle); L = v^2/2 - q^2/2 (ho) */
typedef struct p1 { double k; int ho; } p1;

static int lag1(void *data, const double *q, const double *v, const double *par, unsigned what,
                dm_lag_out *o, void *work)
{
  const p1 *P = data;
  (void)par;
  (void)work;
  if (P->ho) {
    o->L = 0.5 * v[0] * v[0] - 0.5 * q[0] * q[0];
    if (what & DM_LAG_Q) o->Lq[0] = -q[0];
    if (what & DM_LAG_QQ) o->Lqq[0] = -1.0;
  } else {
    o->L = 0.5 * v[0] * v[0] + P->k * cos(q[0]);
    if (what & DM_LAG_Q) o->Lq[0] = -P->k * sin(q[0]);
    if (what & DM_LAG_QQ) o->Lqq[0] = -P->k * cos(q[0]);
  }
  if (what & DM_LAG_V) o->Lv[0] = v[0];
  if (what & DM_LAG_VV) o->Lvv[0] = 1.0;
  if (what & DM_LAG_VQ) o->Lvq[0] = 0.0;
  return 0;
}

static int force1(void *data, const double *q, const double *v, const double *par,
                  unsigned what, double *F, double *Fq, double *Fv, void *work)
{
  (void)data; (void)q; (void)par; (void)work;
  if (what & DM_FORCE_F) F[0] = -0.1 * v[0];
  if (what & DM_FORCE_Q) Fq[0] = 0.0;
  if (what & DM_FORCE_V) Fv[0] = -0.1;
  return 0;
}

static const char *const qname[] = {"q"};

static void make1(dm_system *s, p1 *P)
{
  memset(s, 0, sizeof *s);
  s->name = "pendulum";
  s->n = 1;
  s->coords = qname;
  s->lagrangian = lag1;
  s->data = P;
  s->flags = DM_SYS_MECHANICAL;
}

typedef struct run1 {
  double t[4096], q[4096], p[4096], h[4096];
  long len;
  double tN, qN, pN;
} run1;

/* A run of `steps` steps (or to t_end when steps < 0) into R. */
static int run_sem(dm_system *s, int stages, double h0, long steps, double t_end, double q0,
                   double p0, run1 *R, dm_integrator **keep)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_run_opts r;
  dm_err e;
  dm_traj *tr;
  double q = q0, p = p0;
  int st;
  dm_integ_opts_init(&o);
  o.stages = stages;
  if (dm_integrator_new(s, "sem", &o, &I, &e) != DM_OK) {
    printf("# %s\n", e.msg);
    return -1;
  }
  dm_run_opts_init(&r);
  r.h = h0;
  r.nsteps = steps;
  r.t_end = t_end;
  tr = dm_run_traj_alloc(I, &e);
  st = dm_run(I, &q, &p, &r, tr, NULL, &e);
  if (st != DM_OK)
    printf("# run: %s\n", e.msg);
  R->len = (long)dm_traj_len(tr);
  if (R->len > 4096)
    R->len = 4096;
  size_t hc = dm_traj_find(tr, "h");
  for (long k = 0; k < R->len; k++) {
    R->t[k] = dm_traj_col(tr, 0)[k];
    R->q[k] = dm_traj_col(tr, dm_traj_qcol(tr, 0))[k];
    R->p[k] = dm_traj_col(tr, dm_traj_pcol(tr, 0))[k];
    R->h[k] = dm_traj_col(tr, hc)[k];
  }
  R->tN = R->t[R->len - 1];
  R->qN = q;
  R->pN = p;
  dm_traj_free(tr);
  if (keep)
    *keep = I;
  else
    dm_integrator_free(I);
  return st;
}

/* midpoint Ed(q0, q1, h) = v^2/2 - k cos(qbar) */
static double ed_mid(double k, double q0, double q1, double h)
{
  double v = (q1 - q0) / h;
  return 0.5 * v * v - k * cos(0.5 * (q0 + q1));
}

/* A Gauss s = 6 reference at time T (steps of T/m). */
static void reference(dm_system *s, double T, double q0, double p0, double *q, double *p)
{
  dm_integ_opts o;
  dm_integrator *I;
  long m = (long)ceil(T / 0.01), done;
  dm_integ_opts_init(&o);
  o.stages = 6;
  dm_integrator_new(s, "gauss", &o, &I, NULL);
  *q = q0;
  *p = p0;
  dm_integrator_advance(I, T / (double)m, m, q, p, &done, NULL);
  dm_integrator_free(I);
}

static void pendulum(void)
{
  static run1 R;
  p1 P = {1.0, 0};
  dm_system s;
  double hs[3] = {0.1, 0.05, 0.025}, want[3] = {1.21e-4, 3.03e-5, 7.58e-6}, err[3];
  make1(&s, &P);
  for (int c = 0; c < 3; c++) {
    double hmin = HUGE_VAL, hmax = 0, dE = 0, dH = 0, E0, qr, pr;
    long steps = (long)(10.0 / hs[c]);
    int st = run_sem(&s, 1, hs[c], steps, NAN, 1.0, 0.5, &R, NULL);
    E0 = ed_mid(1.0, R.q[0], R.q[1], R.t[1] - R.t[0]);
    for (long k = 1; k < R.len; k++) {
      double hk = R.h[k];
      hmin = fmin(hmin, hk);
      hmax = fmax(hmax, hk);
      dE = fmax(dE, fabs(ed_mid(1.0, R.q[k - 1], R.q[k], hk) - E0));
      dH = fmax(dH, fabs(0.5 * R.p[k] * R.p[k] - cos(R.q[k]) - (0.125 - cos(1.0))));
    }
    tap_ok(st == DM_OK && R.len == steps + 1, "SEM pendulum h0 = %g: %ld steps", hs[c], steps);
    if (c == 0)
      tap_ok(fabs(hmin - 0.0895) < 5e-4 && fabs(hmax - 0.1004) < 5e-4 && hmin > 0,
             "SEM pendulum h0 = 0.1: steps in [%.5f, %.5f] (thesis example: [0.0895, 0.1004])",
             hmin, hmax);
    tap_ok(dE <= 1e-13, "SEM pendulum h0 = %g: the discrete energy of every step, recomputed "
           "from (q_k, q_k+1, h_k), is constant to %.2g", hs[c], dE);
    tap_ok(fabs(dH / want[c] - 1.0) <= 0.05, "SEM pendulum h0 = %g: max |H - H0| = %.4g "
           "(reference %.3g)", hs[c], dH, want[c]);
    tap_ok(fabs(R.h[R.len - 1] - (R.t[R.len - 1] - R.t[R.len - 2])) <= 1e-15 && R.h[0] == hs[c],
           "SEM pendulum h0 = %g: the h column holds the steps (first: h0)", hs[c]);
    reference(&s, R.tN, 1.0, 0.5, &qr, &pr);
    err[c] = hypot(R.qN - qr, R.pN - pr);
  }
  double o1 = log2(err[0] / err[1]), o2 = log2(err[1] / err[2]);
  tap_ok(fabs(o1 - 2.0) < 0.1 && fabs(o2 - 2.0) < 0.1, "SEM pendulum: error at the reached time "
         "%.3g, %.3g, %.3g: order %.3f, %.3f (2)", err[0], err[1], err[2], o1, o2);
  /* Gauss s = 2: order 4 and the discrete energy of the converged stages */
  for (int c = 0; c < 3; c++) {
    dm_integrator *I;
    double h0 = hs[c], qr, pr, E, dE = 0;
    long steps = (long)(10.0 / h0);
    run_sem(&s, 2, h0, steps - 1, NAN, 1.0, 0.5, &R, &I);
    E = dm_sem_energy_level(I);
    /* step once more and compare the last step's discrete energy */
    double q = R.qN, p = R.pN;
    for (int k = 0; k < 5; k++) {
      dm_integrator_step(I, h0, &q, &p, &q, &p, NULL);
      dE = fmax(dE, fabs(dm_sem_last_energy(I) - E));
    }
    tap_ok(dE <= 1e-13 * fmax(1.0, fabs(E)) && I->stats.flagged == 0,
           "SEM Gauss s=2 h0 = %g: discrete energy of the steps constant to %.2g", h0, dE);
    reference(&s, R.tN, 1.0, 0.5, &qr, &pr);
    err[c] = hypot(R.qN - qr, R.pN - pr);
    dm_integrator_free(I);
  }
  o1 = log2(err[0] / err[1]);
  o2 = log2(err[1] / err[2]);
  tap_ok(fabs(o1 - 4.0) < 0.1 && fabs(o2 - 4.0) < 0.1, "SEM Gauss s=2: errors %.3g, %.3g, "
         "%.3g: order %.3f, %.3f (4)", err[0], err[1], err[2], o1, o2);
  /* a run to t = 10 ends there exactly, with positive bounded steps */
  int st = run_sem(&s, 1, 0.1, -1, 10.0, 1.0, 0.5, &R, NULL);
  double hmin = HUGE_VAL, hmax = 0;
  for (long k = 1; k < R.len; k++) {
    hmin = fmin(hmin, R.t[k] - R.t[k - 1]);
    hmax = fmax(hmax, R.t[k] - R.t[k - 1]);
  }
  tap_ok(st == DM_OK && R.tN == 10.0 && hmin > 0 && hmax <= 0.4,
         "SEM run to t = 10: ends at t = %.17g, steps in (0, 4 h0]: [%.4g, %.4g]", R.tN, hmin,
         hmax);
}

static void oscillator(void)
{
  static run1 R;
  p1 P = {0.0, 1};
  dm_system s;
  double dh = 0, dE = 0, E0;
  make1(&s, &P);
  run_sem(&s, 1, 0.3, 200, NAN, 2.385, -0.7, &R, NULL);
  E0 = 0.5 * pow((R.q[1] - R.q[0]) / 0.3, 2) + 0.125 * pow(R.q[0] + R.q[1], 2);
  for (long k = 1; k < R.len; k++) {
    double hk = R.h[k], v = (R.q[k] - R.q[k - 1]) / hk;
    dh = fmax(dh, fabs(R.h[k] - 0.3));
    dE = fmax(dE, fabs(0.5 * v * v + 0.125 * pow(R.q[k] + R.q[k - 1], 2) - E0));
  }
  /* h solves Ed(h) = H_k/(1 + h^2/4) = E: the round-off walk of H_k moves h
   * by (1 + h^2/4)/(h^2/2) ~ 23 times its relative size */
  tap_ok(dh <= 1e-13 * 0.3 && dE <= 1e-14, "SEM harmonic oscillator: h_k = h0 to %.2g, discrete "
         "energy constant to %.2g (a quadratic invariant)", dh, dE);
}

static void fallback(void)
{
  static run1 R;
  p1 P = {0.0, 0};
  dm_system s;
  dm_integrator *I;
  double q = 0.3, p = 1.7, hmin = HUGE_VAL, hmax = 0;
  make1(&s, &P);
  /* free particle: Ed = p^2/2 for every h -- the Newton matrix is singular */
  int st = run_sem(&s, 1, 0.25, 40, NAN, 0.3, 1.7, &R, &I);
  tap_ok(st == DM_OK && fabs(R.qN - (0.3 + 1.7 * R.tN)) < 1e-13 && I->stats.flagged == 0
         && R.tN == 10.0,
         "SEM free particle (singular energy equation): the search keeps the energy, q = %.15g "
         "at t = %.6g", R.qN, R.tN);
  /* an unreachable level: every step is flagged, h stays in (0, 4 h0] */
  dm_sem_set_energy_level(I, 1.7 * 1.7 / 2 + 0.5, NULL);
  for (int k = 0; k < 5; k++) {
    double t0 = I->t;
    st |= dm_integrator_step(I, 0.25, &q, &p, &q, &p, NULL);
    hmin = fmin(hmin, I->t - t0);
    hmax = fmax(hmax, I->t - t0);
  }
  tap_ok(st == DM_OK && I->stats.flagged == 5 && hmin > 0 && hmax <= 1.0,
         "SEM unreachable energy level: %ld of 5 steps flagged 'energy not matched', steps in "
         "[%.3g, %.3g]", I->stats.flagged, hmin, hmax);
  dm_integrator_free(I);
}

static void errors(void)
{
  p1 P = {1.0, 0};
  dm_system s;
  dm_integrator *I = NULL;
  dm_integ_opts o;
  dm_err e;
  int st;
  make1(&s, &P);
  s.force = force1;
  dm_integ_opts_init(&o);
  st = dm_integrator_new(&s, "sem", &o, &I, &e);
  tap_ok(st == DM_EUNSUP && I == NULL && strcmp(e.msg, "sem: energy-momentum steps need a "
         "conservative, unconstrained system ('pendulum' has a force)") == 0,
         "sem on a forced system: %s", e.msg);
  s.force = NULL;
  o.stages = 21;
  st = dm_integrator_new(&s, "sem", &o, &I, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "stages = 21 out of range 1..20") != NULL,
         "sem stages = 21: %s", e.msg);
  tap_ok(dm_sem_set_energy_level(NULL, 1.0, &e) == DM_EINVAL, "set level on a non-sem: %s",
         e.msg);
}

int main(void)
{
  pendulum();
  oscillator();
  fallback();
  errors();
  return tap_done();
}
