/* b_adapt.c -- adaptive steps that keep the structure, against GSL's
 * adaptive rk8pd, on the eccentric Kepler orbit (doc/benchmarks.md, B6;
 * doc/beyond-fixed-steps.md §3): 1000 periods at e = 0.6, 0.9, 0.99 from the
 * pericentre (q0 = (1 - e, 0), p0 = (0, sqrt((1 + e)/(1 - e))), a = 1).
 *
 * dmech: the time-transformed order-8 composition (adapt:composition,
 * kahanli8) with the potential's monitor g = U(q0)/U(q) (Sundman's
 * dt = r ds; the explicit drift-kick-drift path), the built-in C Kepler
 * system, fixed fictitious steps h = 2 pi r_p / N (N ~ steps per orbit),
 * the run driver ending at T exactly.  GSL: gsl_odeiv2_step_rk8pd with the
 * standard y-control (epsabs = epsrel = tol) on the hand-written right-hand
 * side (bench/peers/gsl_peer.c).  Error: 2-norm of (q, p) - exact(T)
 * (Kepler's equation).  CPU: median of 3 runs (process CPU time).  For
 * each method the CPU to reach an error of 1e-4 is interpolated log-log
 * between the sweep points that straddle it; the ratio is GSL / dmech.
 * Energy: a second run of each method at the point closest to 1e-4 samples
 * |H - H0| at every step; the maxima over the first and the last tenth of
 * the periods show drift or its absence.
 *
 * Usage: b_adapt [periods]  (default 1000; BENCH_REPEAT runs per median). */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "core/builtin_systems.h"
#include "core/run.h"
#include "integrators/integrator.h"
#include "peers/benchutil.h"
#include "peers/gsl_peer.h"

#define TARGET 1e-4
#define NPTS 12
#define NTOL 19

static void exact(double e, double t, double *y)
{
  double M = fmod(t, 2 * M_PI), E = M + e * sin(M);
  for (int i = 0; i < 200; i++) {
    double d = (E - e * sin(E) - M) / (1 - e * cos(E));
    E -= d;
    if (fabs(d) < 1e-16)
      break;
  }
  y[0] = cos(E) - e;
  y[1] = sqrt(1 - e * e) * sin(E);
  y[2] = -sin(E) / (1 - e * cos(E));
  y[3] = sqrt(1 - e * e) * cos(E) / (1 - e * cos(E));
}

static void start(double e, double *y)
{
  y[0] = 1 - e;
  y[1] = 0;
  y[2] = 0;
  y[3] = sqrt((1 + e) / (1 - e));
}

static double err_at(double e, double T, const double *y)
{
  double z[4], s = 0;
  exact(e, T, z);
  for (int i = 0; i < 4; i++)
    s += (y[i] - z[i]) * (y[i] - z[i]);
  return sqrt(s);
}

static double energy(const double *y)
{
  return 0.5 * (y[2] * y[2] + y[3] * y[3]) - 1 / hypot(y[0], y[1]);
}

/* {==== dmech ============================================================ */

typedef struct dmrun {
  dm_system sys;
  dm_integrator *I;
} dmrun;

static int dm_setup(dmrun *d)
{
  dm_integ_opts o;
  dm_err e;
  dm_builtin_kepler(&d->sys, 2, 1.0, NULL);
  dm_integ_opts_init(&o);
  o.order = 8;
  if (dm_integrator_new(&d->sys, "adapt:composition", &o, &d->I, &e) != DM_OK) {
    fprintf(stderr, "b_adapt: %s\n", e.msg);
    return -1;
  }
  return 0;
}

/* One run to T; y = the end. */
static int dm_go(dmrun *d, double e, double T, double h, double *y)
{
  double q[2], p[2];
  dm_run_opts r;
  dm_traj *tr;
  dm_err er;
  int st;
  start(e, y);
  q[0] = y[0];
  q[1] = y[1];
  p[0] = y[2];
  p[1] = y[3];
  dm_run_opts_init(&r);
  r.h = h;
  r.t_end = T;
  r.every = 1L << 40;
  r.energy = 0;
  tr = dm_run_traj_alloc(d->I, &er);
  st = dm_run(d->I, q, p, &r, tr, NULL, &er);
  if (st != DM_OK)
    fprintf(stderr, "b_adapt: dmech run: %s\n", er.msg);
  dm_traj_free(tr);
  y[0] = q[0];
  y[1] = q[1];
  y[2] = p[0];
  y[3] = p[1];
  return st;
}

/* Per-period maxima of |H - H0| at every step: first and last tenth. */
static void dm_drift(dmrun *d, double e, int periods, double h, double *first, double *last,
                     long *steps)
{
  double y[4], q[2], p[2], H0;
  int st = DM_OK;
  start(e, y);
  H0 = energy(y);
  q[0] = y[0]; q[1] = y[1]; p[0] = y[2]; p[1] = y[3];
  *first = *last = 0;
  dm_integrator_begin(d->I, h, 0.0, q, p, NULL);
  *steps = 0;
  for (int k = 0; k < periods && st == DM_OK; k++) {
    int reached = 0;
    double m = 0;
    while (!reached && st == DM_OK) {
      st = dm_integrator_step_until(d->I, h, 2 * M_PI * (k + 1), q, p, q, p, &reached, NULL);
      y[0] = q[0]; y[1] = q[1]; y[2] = p[0]; y[3] = p[1];
      m = fmax(m, fabs(energy(y) - H0));
      (*steps)++;
    }
    if (k < periods / 10)
      *first = fmax(*first, m);
    if (k >= periods - periods / 10)
      *last = fmax(*last, m);
  }
}

/* }====================================================================== */

/* {==== GSL rk8pd ======================================================== */

static void gsl_drift(double e, int periods, double tol, double *first, double *last, long *steps)
{
  gsl_odeiv2_system s = gp_system(GP_KEPLER);
  gsl_odeiv2_step *st = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 4);
  gsl_odeiv2_control *c = gsl_odeiv2_control_y_new(tol, tol);
  gsl_odeiv2_evolve *ev = gsl_odeiv2_evolve_alloc(4);
  double y[4], t = 0, h = 1e-3, H0;
  start(e, y);
  H0 = energy(y);
  *first = *last = 0;
  *steps = 0;
  for (int k = 0; k < periods; k++) {
    double t1 = 2 * M_PI * (k + 1), m = 0;
    while (t < t1) {
      if (gsl_odeiv2_evolve_apply(ev, c, st, &s, &t, t1, &h, y) != GSL_SUCCESS)
        break;
      m = fmax(m, fabs(energy(y) - H0));
      (*steps)++;
    }
    if (k < periods / 10)
      *first = fmax(*first, m);
    if (k >= periods - periods / 10)
      *last = fmax(*last, m);
  }
  gsl_odeiv2_evolve_free(ev);
  gsl_odeiv2_control_free(c);
  gsl_odeiv2_step_free(st);
}

/* }====================================================================== */

/* CPU at err = TARGET by log-log interpolation between the sweep points that
 * straddle it (errors decreasing along the sweep); NaN when not reached. */
static double at_target(const double *cpu, const double *err, int n, int *idx)
{
  *idx = -1;
  for (int i = 0; i < n; i++)
    if (err[i] <= TARGET) {
      *idx = i;
      if (i == 0)
        return cpu[0];
      double a = log(err[i - 1]), b = log(err[i]), w = (log(TARGET) - a) / (b - a);
      if (!(err[i - 1] > TARGET) || !isfinite(w))
        return cpu[i];
      return exp(log(cpu[i - 1]) + w * (log(cpu[i]) - log(cpu[i - 1])));
    }
  return NAN;
}

int main(int argc, char **argv)
{
  static const double ecc[] = {0.6, 0.9, 0.99};
  static const double nper[NPTS] = {8, 10, 12, 14, 17, 20, 24, 28, 34, 40, 48, 56};
  static const double tols[NTOL] = {1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10,
                                    3e-11, 1e-11, 3e-12, 1e-12, 3e-13, 1e-13, 3e-14, 1e-14,
                                    3e-15, 1e-15};
  int periods = argc > 1 ? atoi(argv[1]) : 1000, rep = bu_env_int("BENCH_REPEAT", 3);
  double T = 2 * M_PI * periods;
  dmrun d;
  gsl_set_error_handler_off();
  if (dm_setup(&d) != 0)
    return 1;
  bu_machine("b_adapt");
  printf("# Kepler, %d periods from the pericentre; error = |(q, p) - exact(T)|; CPU median of %d\n",
         periods, rep);
  printf("# dmech: adapt:composition (kahanli8, order 8), monitor U(q0)/U(q) (Sundman), "
         "h = 2 pi r_p / N\n# GSL: rk8pd, y-control epsabs = epsrel = tol\n");
  for (size_t c = 0; c < sizeof ecc / sizeof ecc[0]; c++) {
    double e = ecc[c], rp = 1 - e, cd[NPTS], ed[NPTS], cg[NTOL], eg[NTOL], y[4], x[16];
    int id, ig;
    printf("\n## e = %g\n%-10s %-12s %-12s %-12s\n", e, "dmech N", "h", "error", "cpu s");
    for (int i = 0; i < NPTS; i++) {
      double h = 2 * M_PI * rp / nper[i];
      for (int k = 0; k < rep; k++) {
        double t0 = bu_cpu();
        dm_go(&d, e, T, h, y);
        x[k] = bu_cpu() - t0;
      }
      cd[i] = bu_median(x, rep);
      ed[i] = err_at(e, T, y);
      printf("%-10g %-12.4g %-12.3e %-12.4f\n", nper[i], h, ed[i], cd[i]);
    }
    printf("%-10s %-12s %-12s %-12s\n", "GSL tol", "", "error", "cpu s");
    int ng = 0;
    for (int i = 0; i < NTOL; i++) {
      long ns;
      for (int k = 0; k < rep; k++) {
        double t0 = bu_cpu();
        start(e, y);
        gp_adaptive(gsl_odeiv2_step_rk8pd, GP_KEPLER, T, tols[i], y, NULL, &ns);
        x[k] = bu_cpu() - t0;
      }
      cg[i] = bu_median(x, rep);
      eg[i] = err_at(e, T, y);
      printf("%-10.0e %-12s %-12.3e %-12.4f\n", tols[i], "", eg[i], cg[i]);
      ng = i + 1;
      if (eg[i] <= 0.1 * TARGET)          /* reached, with one point past it */
        break;
    }
    double td = at_target(cd, ed, NPTS, &id), tg = at_target(cg, eg, ng, &ig);
    if (isfinite(tg))
      printf("CPU to error <= 1e-4 after %d periods (e = %g): dmech %.4f s, GSL rk8pd %.4f s: "
             "ratio GSL/dmech %.2f\n", periods, e, td, tg, tg / td);
    else
      printf("CPU to error <= 1e-4 after %d periods (e = %g): dmech %.4f s, GSL rk8pd not "
             "reached (smallest error %.3g at tol %.0e, %.4f s: ratio > %.2f)\n", periods, e, td,
             eg[ng - 1], tols[ng - 1], cg[ng - 1], cg[ng - 1] / td);
    if (id >= 0 && ig >= 0) {
      double f, l;
      long ns;
      dm_drift(&d, e, periods, 2 * M_PI * rp / nper[id], &f, &l, &ns);
      printf("energy max |H - H0| (first / last tenth of the periods): dmech N = %g: "
             "%.3g / %.3g (%ld steps)", nper[id], f, l, ns);
      gsl_drift(e, periods, tols[ig], &f, &l, &ns);
      printf("; GSL tol %.0e: %.3g / %.3g (%ld steps)\n", tols[ig], f, l, ns);
    }
  }
  dm_integrator_free(d.I);
  dm_system_release(&d.sys);
  return 0;
}
