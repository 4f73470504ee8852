/* test_adapt.c -- time-transformed integrators "adapt:<method>"
 * (doc/beyond-fixed-steps.md §3) on the Kepler problem e = 0.9 against Kepler's
 * equation: orders of the transformed methods (implicit Poincare path with
 * a user monitor r^1.5, explicit path with the potential's monitor),
 * symplecticity defect of the step in the extended phase space (q, t, p,
 * p_t) at round-off, the Jacobian against differences, bounded energy
 * error and angular momentum to round-off over 100 periods, time
 * reversal, runs ending at t_end, a constrained system, errors. */
#include <config.h>
#include <float.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "core/run.h"
#include "integrators/integrator.h"
#include "integrators/adapt.h"
#include "tap.h"

#define ECC 0.9

static void kepler_exact(double e, double t, double *q, double *p)
{
  double M = fmod(t, 2 * M_PI), E = M + e * sin(M);
  for (int i = 0; i < 100; i++) {
    double d = (E - e * sin(E) - M) / (1 - e * cos(E));
    E -= d;
    if (fabs(d) < 1e-16)
      break;
  }
  q[0] = cos(E) - e;
  q[1] = sqrt(1 - e * e) * sin(E);
  p[0] = -sin(E) / (1 - e * cos(E));
  p[1] = sqrt(1 - e * e) * cos(E) / (1 - e * cos(E));
}

/* g = r^a over (q0, q1) */
static int mon_r(void *data, const double *q, const double *par, unsigned what, double *g,
                 double *gq, double *gqq, void *work)
{
  double a = *(const double *)data, r2 = q[0] * q[0] + q[1] * q[1], r = sqrt(r2);
  (void)par;
  (void)work;
  *g = pow(r, a);
  if (what & DM_MON_GRAD)
    for (int i = 0; i < 2; i++)
      gq[i] = a * pow(r, a - 2) * q[i];
  if (what & DM_MON_HESS)
    for (int i = 0; i < 2; i++)
      for (int j = 0; j < 2; j++)
        gqq[i * 2 + j] = a * pow(r, a - 2) * (i == j) + a * (a - 2) * pow(r, a - 4) * q[i] * q[j];
  return 0;
}

static double power15 = 1.5;
static const dm_monitor r15 = {mon_r, &power15, 0};

static dm_integrator *make(dm_system *s, const char *m, int stages, const dm_monitor *mon,
                           dm_err *e)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_integ_opts_init(&o);
  o.stages = stages;
  o.monitor = mon;
  o.order = 6;
  if (dm_integrator_new(s, m, &o, &I, e) != DM_OK)
    return NULL;
  return I;
}

/* Run to T from pericentre; error against the exact solution. */
static double kepler_error(dm_system *s, const char *m, int stages, const dm_monitor *mon,
                           double h, double T, double *tN)
{
  dm_err e;
  dm_integrator *I = make(s, m, stages, mon, &e);
  double q[2] = {1 - ECC, 0}, p[2] = {0, sqrt((1 + ECC) / (1 - ECC))}, qe[2], pe[2];
  dm_run_opts r;
  dm_traj *tr;
  int st;
  if (I == NULL) {
    printf("# %s\n", e.msg);
    return NAN;
  }
  dm_run_opts_init(&r);
  r.h = h;
  r.t_end = T;
  r.every = 1 << 30;
  tr = dm_run_traj_alloc(I, &e);
  st = dm_run(I, q, p, &r, tr, NULL, &e);
  if (st != DM_OK)
    printf("# %s\n", e.msg);
  *tN = dm_traj_col(tr, 0)[dm_traj_len(tr) - 1];
  kepler_exact(ECC, T, qe, pe);
  dm_traj_free(tr);
  dm_integrator_free(I);
  return st == DM_OK ? hypot(hypot(q[0] - qe[0], q[1] - qe[1]), hypot(p[0] - pe[0], p[1] - pe[1]))
                     : NAN;
}

static void orders(dm_system *s)
{
  static const struct {
    const char *m;
    int stages;
    const dm_monitor *mon;
    double h;
    int order;
    const char *what;
  } c[] = {
    {"adapt:gauss", 2, &r15, 0.02, 4, "Gauss s=2, monitor r^1.5 (implicit, Poincare)"},
    {"adapt:lobatto", 3, &r15, 0.02, 4, "Lobatto s=3, monitor r^1.5 (implicit)"},
    {"adapt:midpoint", 0, &r15, 0.005, 2, "midpoint, monitor r^1.5"},
    {"adapt:trapezoid", 0, NULL, 0.002, 2, "Stormer-Verlet, potential's monitor (explicit)"},
    {"adapt:composition", 0, NULL, 0.02, 6, "composition kahanli6, potential's monitor (explicit)"},
  };
  double T = 4 * M_PI;
  for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
    double err[3], tN[3], o1, o2;
    for (int k = 0; k < 3; k++)
      err[k] = kepler_error(s, c[i].m, c[i].stages, c[i].mon, c[i].h / (1 << k), T, &tN[k]);
    o1 = log2(err[0] / err[1]);
    o2 = log2(err[1] / err[2]);
    tap_ok(fabs(o1 - c[i].order) < 0.15 && fabs(o2 - c[i].order) < 0.1 && tN[0] == T
           && tN[2] == T, "Kepler e = 0.9, 2 periods, %s: errors %.3g %.3g %.3g, order %.2f %.2f "
           "(%d); ends at t = T", c[i].what, err[0], err[1], err[2], o1, o2, c[i].order);
  }
}

/* max |(D^T J D - J)_ij| / max(1, max|D|^2) in dimension 2N */
static double defect(const double *D, size_t N)
{
  size_t M = 2 * N, i, j, k;
  double worst = 0.0, big = 1.0;
  for (i = 0; i < M * M; i++)
    big = fmax(big, D[i] * D[i]);
  for (i = 0; i < M; i++)
    for (j = 0; j < M; j++) {
      double acc = 0.0;
      for (k = 0; k < N; k++)
        acc += D[k * M + i] * D[(N + k) * M + j] - D[(N + k) * M + i] * D[k * M + j];
      double want = (i < N && j == i + N) ? 1.0 : (i >= N && j == i - N) ? -1.0 : 0.0;
      worst = fmax(worst, fabs(acc - want));
    }
  return worst / big;
}

static void symplectic(dm_system *s)
{
  static const struct {
    const char *m;
    int stages;
    const dm_monitor *mon;
    double h;
  } c[] = {
    {"adapt:gauss", 2, &r15, 0.05},
    {"adapt:trapezoid", 0, NULL, 0.05},
    {"adapt:composition", 0, NULL, 0.05},
  };
  double q0[2] = {0.3, 0.12}, p0[2] = {-0.4, 2.385}, D[36], Dqp[16], Dfd[16];
  for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
    dm_err e;
    dm_integrator *I = make(s, c[i].m, c[i].stages, c[i].mon, &e);
    int st = dm_integrator_begin(I, c[i].h, 1.25, q0, p0, &e);
    st |= dm_adapt_extended_jacobian(I, c[i].h, q0, p0, D, &e);
    double big = 0;
    for (int k = 0; k < 36; k++)
      big = fmax(big, fabs(D[k]));
    tap_ok(st == DM_OK && defect(D, 3) <= 4e-15, "%s: symplecticity defect of the step in the "
           "extended phase space (q, t, p, p_t): %.2g (relative; max |D| = %.3g)", c[i].m,
           defect(D, 3), big);
    /* the (q, p) block against central differences of the step */
    st = dm_integrator_jacobian(I, c[i].h, q0, p0, Dqp, &e);
    double worst = 0.0, eps = 1e-6;
    for (int j = 0; j < 4; j++) {
      double qa[2], pa[2], qb[2], pb[2], q1[2], p1[2];
      memcpy(qa, q0, sizeof qa);
      memcpy(pa, p0, sizeof pa);
      memcpy(qb, q0, sizeof qb);
      memcpy(pb, p0, sizeof pb);
      (j < 2 ? qa : pa)[j % 2] += eps;
      (j < 2 ? qb : pb)[j % 2] -= eps;
      dm_integrator_step(I, c[i].h, qa, pa, qa, pa, NULL);
      dm_integrator_step(I, c[i].h, qb, pb, qb, pb, NULL);
      for (int r = 0; r < 4; r++) {
        q1[0] = (r < 2 ? qa : pa)[r % 2];
        p1[0] = (r < 2 ? qb : pb)[r % 2];
        Dfd[r * 4 + j] = (q1[0] - p1[0]) / (2 * eps);
      }
    }
    for (int k = 0; k < 16; k++)
      worst = fmax(worst, fabs(Dfd[k] - Dqp[k]));
    tap_ok(st == DM_OK && worst < 1e-7, "%s: the (q, p) block of the step Jacobian agrees with "
           "central differences to %.2g", c[i].m, worst);
    dm_integrator_free(I);
  }
}

/* 100 periods at e = 0.9: per-period maxima of |H - H0| without a trend,
 * angular momentum to round-off */
static void long_time(dm_system *s)
{
  dm_err e;
  dm_integrator *I = make(s, "adapt:gauss", 2, &r15, &e);
  double q[2] = {1 - ECC, 0}, p[2] = {0, sqrt((1 + ECC) / (1 - ECC))}, H0 = -0.5;
  double J0 = q[0] * p[1] - q[1] * p[0], dJ = 0, first = 0, last = 0, all = 0;
  int st = dm_integrator_begin(I, 0.05, 0.0, q, p, &e), per = 0;
  long steps = 0;
  while (st == DM_OK && per < 100) {
    int reached = 0;
    double pmax = 0;
    while (st == DM_OK && !reached) {
      st = dm_integrator_step_until(I, 0.05, 2 * M_PI * (per + 1), q, p, q, p, &reached, &e);
      double H = 0.5 * (p[0] * p[0] + p[1] * p[1]) - 1 / hypot(q[0], q[1]);
      pmax = fmax(pmax, fabs(H - H0));
      dJ = fmax(dJ, fabs(q[0] * p[1] - q[1] * p[0] - J0));
      steps++;
    }
    if (per < 10)
      first = fmax(first, pmax);
    if (per >= 90)
      last = fmax(last, pmax);
    all = fmax(all, pmax);
    per++;
  }
  tap_ok(st == DM_OK && last <= 1.1 * first && all <= 1.1 * first && first < 1e-6,
         "adapt:gauss r^1.5, h = 0.05, e = 0.9, 100 periods (%ld steps): max |H - H0| %.3g in the "
         "first ten periods, %.3g in the last ten: bounded", steps, first, last);
  tap_ok(dJ <= 1e-13, "adapt:gauss r^1.5: angular momentum conserved to %.2g (quadratic "
         "invariant of the transformed Lagrangian)", dJ);
  tap_ok(fabs(I->t - 200 * M_PI) == 0.0, "step_until: the clock ends at 100 periods exactly "
         "(%.17g)", I->t);
  dm_integrator_free(I);
}

static void reversal(dm_system *s)
{
  static const char *const m[] = {"adapt:gauss", "adapt:composition"};
  for (int i = 0; i < 2; i++) {
    dm_err e;
    dm_integrator *I = make(s, m[i], 2, i == 0 ? &r15 : NULL, &e);
    double q[2] = {1 - ECC, 0}, p[2] = {0, sqrt((1 + ECC) / (1 - ECC))}, dev;
    double q0[2] = {q[0], q[1]}, p0[2] = {p[0], p[1]};
    int st = dm_integrator_begin(I, 0.05, 0.75, q, p, &e);
    for (int k = 0; k < 200; k++)
      st |= dm_integrator_step(I, 0.05, q, p, q, p, &e);
    double tmid = I->t;
    for (int k = 0; k < 200; k++)
      st |= dm_integrator_step(I, -0.05, q, p, q, p, &e);
    dev = fmax(fmax(fabs(q[0] - q0[0]), fabs(q[1] - q0[1])),
               fmax(fabs(p[0] - p0[0]), fabs(p[1] - p0[1])));
    tap_ok(st == DM_OK && dev <= 1e-11 && fabs(I->t - 0.75) <= 1e-12 && tmid > 6,
           "%s: 200 steps forward (to t = %.4g) and back: state within %.2g, clock %.3g from t0",
           m[i], tmid, dev, fabs(I->t - 0.75));
    dm_integrator_free(I);
  }
}

/* the driver: h column, t_end, samples */
static void driver(dm_system *s)
{
  dm_err e;
  dm_integrator *I = make(s, "adapt:gauss", 2, &r15, &e);
  double q[2] = {1 - ECC, 0}, p[2] = {0, sqrt((1 + ECC) / (1 - ECC))}, worst = 0, tend;
  dm_run_opts r;
  dm_run_result res;
  dm_traj *tr = dm_run_traj_alloc(I, &e);
  dm_run_opts_init(&r);
  r.h = 0.05;
  r.t_end = 2 * M_PI;
  int st = dm_run(I, q, p, &r, tr, &res, &e);
  size_t hc = dm_traj_find(tr, "h"), len = dm_traj_len(tr);
  const double *t = dm_traj_col(tr, 0), *h = dm_traj_col(tr, hc);
  for (size_t k = 1; k < len; k++)
    worst = fmax(worst, fabs(h[k] - (t[k] - t[k - 1])));
  tap_ok(st == DM_OK && hc < dm_traj_ncols(tr) && len == (size_t)res.steps + 1 && worst < 1e-14
         && t[len - 1] == 2 * M_PI && dm_traj_meta_number(tr, "t_end", &tend) == 1
         && tend == 2 * M_PI, "run to t = 2 pi: %zu samples, column h = the steps (to %.2g), "
         "ends at t_end exactly", len, worst);
  tap_ok(h[0] > 0 && fabs(h[0] - 0.05 * pow(1 - ECC, 1.5)) < 1e-15 && res.t == 2 * M_PI,
         "the first sample's h is g(q0) h = %.6g", h[0]);
  dm_traj_free(tr);
  /* steps = 10: ten fictitious steps, the clock is the integrator's */
  tr = dm_run_traj_alloc(I, &e);
  dm_run_opts_init(&r);
  r.h = 0.05;
  r.nsteps = 10;
  q[0] = 1 - ECC;
  q[1] = 0;
  p[0] = 0;
  p[1] = sqrt((1 + ECC) / (1 - ECC));
  st = dm_run(I, q, p, &r, tr, &res, &e);
  tap_ok(st == DM_OK && dm_traj_len(tr) == 11 && dm_traj_col(tr, 0)[10] == res.t && res.t < 0.1,
         "run of 10 fictitious steps: t = %.6g", res.t);
  dm_traj_free(tr);
  dm_integrator_free(I);
}

/* a spherical pendulum in R^3 (one constraint), monitor 1 + z^2/2 */
static int mon_z(void *data, const double *q, const double *par, unsigned what, double *g,
                 double *gq, double *gqq, void *work)
{
  (void)data;
  (void)par;
  (void)work;
  *g = 1 + 0.5 * q[2] * q[2];
  if (what & DM_MON_GRAD) {
    gq[0] = gq[1] = 0;
    gq[2] = q[2];
  }
  if (what & DM_MON_HESS) {
    memset(gqq, 0, 9 * sizeof *gqq);
    gqq[8] = 1;
  }
  return 0;
}

static void constrained(void)
{
  static const dm_monitor mz = {mon_z, NULL, 0};
  dm_system s;
  dm_err e;
  dm_integrator *I;
  double q[3] = {sin(0.8), 0, -cos(0.8)}, p[3] = {0, 0.9, 0}, dl = 0, dE = 0, E0;
  int st;
  dm_builtin_spherical_pendulum_r3(&s, 9.81, 1.0, 1.0, 0, NULL);
  I = make(&s, "adapt:lobatto", 3, &mz, &e);
  E0 = 0.5 * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + 9.81 * q[2];
  st = I ? dm_integrator_begin(I, 0.02, 0, q, p, &e) : DM_EINVAL;
  for (int k = 0; st == DM_OK && k < 500; k++) {
    st = dm_integrator_step(I, 0.02, q, p, q, p, &e);
    dl = fmax(dl, fabs(sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) - 1));
    dE = fmax(dE, fabs(0.5 * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + 9.81 * q[2] - E0));
  }
  tap_ok(st == DM_OK && dl < 1e-13 && dE < 1e-4, "adapt:lobatto s=3 on the spherical pendulum "
         "in R^3 (constraint |q| = 1), monitor 1 + z^2/2: constraint to %.2g, |dE| %.2g, t = %.4g",
         dl, dE, I ? I->t : 0);
  dm_integrator_free(I);
  dm_system_release(&s);
}

/* g = q^2 (one coordinate): 0 at q = 0 */
static int mon_q2(void *data, const double *q, const double *par, unsigned what, double *g,
                  double *gq, double *gqq, void *work)
{
  (void)data;
  (void)par;
  (void)work;
  *g = q[0] * q[0];
  if (what & DM_MON_GRAD)
    gq[0] = 2 * q[0];
  if (what & DM_MON_HESS)
    gqq[0] = 2;
  return 0;
}

static void errors(dm_system *kep)
{
  static const dm_monitor mq2 = {mon_q2, NULL, 0};
  dm_system s;
  dm_err e;
  dm_integrator *I = NULL;
  dm_integ_opts o;
  int st;
  double q[1] = {0.5}, p[1] = {0.2};
  dm_integ_opts_init(&o);
  st = dm_integrator_new(kep, "adapt", &o, &I, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "adapt: name the method to transform, adapt:<method> "
         "(e.g. adapt:gauss)") == 0, "method 'adapt' alone: %s", e.msg);
  st = dm_integrator_new(kep, "adapt:adapt:gauss", &o, &I, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "a time transformation of a time transformation") != NULL,
         "adapt:adapt:gauss: %s", e.msg);
  st = dm_integrator_new(kep, "adapt:nosuch", &o, &I, &e);
  tap_ok(st == DM_ENOTFOUND && strstr(e.msg, "unknown integration method 'nosuch'") != NULL,
         "adapt:nosuch: %s", e.msg);
  dm_builtin_harmonic(&s, 1.0, 2.0, NULL);
  st = dm_integrator_new(&s, "adapt:gauss", &o, &I, &e);
  st |= dm_integrator_begin(I, 0.1, 0, q, p, &e);
  tap_ok(st == DM_EDOM && strcmp(e.msg, "adapt: the potential's monitor needs U = -V = L(q, 0) "
         "> 0 (an attractive potential); not so at q = (0.5): give adapt.monitor") == 0,
         "the potential's monitor on a harmonic oscillator: %s", e.msg);
  dm_integrator_free(I);
  dm_system_release(&s);
  dm_builtin_pendulum(&s, 9.81, 1.0, 1.0, NULL);
  o.monitor = &mq2;
  st = dm_integrator_new(&s, "adapt:gauss", &o, &I, &e);
  tap_ok(st == DM_OK, "adapt:gauss with a monitor on a pendulum");
  q[0] = 0.0;
  st = dm_integrator_begin(I, 0.1, 0, q, p, &e);
  tap_ok(st == DM_EDOM && strstr(e.msg, "the monitor must be finite and > 0; not so at q = (0)")
         != NULL, "a monitor vanishing at the start: %s", e.msg);
  dm_integrator_free(I);
  dm_system_release(&s);
}

int main(void)
{
  dm_system kep;
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  orders(&kep);
  symplectic(&kep);
  long_time(&kep);
  reversal(&kep);
  driver(&kep);
  constrained();
  errors(&kep);
  dm_system_release(&kep);
  return tap_done();
}
