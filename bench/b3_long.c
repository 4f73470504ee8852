/* b3_long.c -- B3 long-time energy behaviour, dmech and GSL, in C.
 *
 * Kepler e = 0.6 over P periods (argument; the full run of doc/integrators.md
 * §12.5 is 10^5 with Stormer-Verlet h = 0.01, 6.3e7 steps).  Methods: dmech Stormer-Verlet
 * h = 0.01, dmech Gauss s=2 h = 0.05, dmech rk4 h = 0.01 (classical,
 * non-symplectic) on the built-in C system, and GSL rk8pd (adaptive,
 * epsabs = epsrel = 1e-10, driven directly).  For each: the CPU time of an
 * unmonitored run to t = 2 pi P, then a monitored run that samples
 * |H - H0| at every step (every accepted step for rk8pd) and keeps the
 * maximum per period.  Writes "method <TAB> period <TAB> max_dH" lines to
 * <outfile> and prints, per method, the CPU times, max |dH| overall, the
 * maxima over the first and the last tenth of the periods, and the slope
 * of a least-squares line through the per-period maxima (times P: the
 * trend over the whole run).
 * Usage: b3_long <periods> <outfile>
 */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "core/status.h"
#include "peers/benchutil.h"
#include "peers/gsl_peer.h"
#include "peers/problems.h"

typedef struct mon {
  double H0, P;
  long periods;
  double *pm;
} mon;

static int sink(void *ctx, double t, const double *q, const double *p, const double *v)
{
  mon *m = ctx;
  long k = (long)(t / m->P);
  double d = fabs(kep_energy(q, p) - m->H0);
  (void)v;
  if (k >= m->periods)
    k = m->periods - 1;
  if (d > m->pm[k])
    m->pm[k] = d;
  return 0;
}

static void summary(FILE *out, const char *label, long steps, double cpu0, double cpu1, const double *pm,
                    long P)
{
  double mx = 0, first = 0, last = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, slope;
  long i, tenth = P / 10 > 0 ? P / 10 : 1;
  for (i = 0; i < P; i++) {
    double x = (double)(i + 1);
    mx = fmax(mx, pm[i]);
    if (i < tenth)
      first = fmax(first, pm[i]);
    if (i >= P - tenth)
      last = fmax(last, pm[i]);
    sx += x;
    sy += pm[i];
    sxx += x * x;
    sxy += x * pm[i];
    fprintf(out, "%s\t%ld\t%.6e\n", label, i + 1, pm[i]);
  }
  slope = ((double)P * sxy - sx * sy) / ((double)P * sxx - sx * sx);
  printf("%-26s %11ld %9.3f %9.3f %11.3e %11.3e %11.3e %11.3e\n", label, steps, cpu0, cpu1, mx, first,
         last, slope * (double)P);
  printf("B3SUMMARY\t%s\t%ld\t%.4f\t%.4f\t%.6e\t%.6e\t%.6e\t%.6e\n", label, steps, cpu0, cpu1, mx, first,
         last, slope * (double)P);
}

int main(int argc, char **argv)
{
  static const struct {
    const char *label, *method;
    int stages;
    double h;
  } ms[] = {
    {"dmech SV h=0.01", "trapezoid", 0, 0.01},
    {"dmech Gauss s=2 h=0.05", "gauss", 2, 0.05},
    {"dmech comp8 kahanli8 h=0.05", "composition:kahanli8", 0, 0.05},
    {"dmech rk4 h=0.01", "rk4", 0, 0.01},
  };
  long P, steps;
  FILE *out;
  dm_system sys;
  dm_err e;
  size_t k;
  double *pm;
  const double Per = 2 * M_PI;
  if (argc < 3) {
    fprintf(stderr, "usage: b3_long <periods> <outfile>\n");
    return 2;
  }
  P = atol(argv[1]);
  if (P < 1 || (out = fopen(argv[2], "w")) == NULL) {
    fprintf(stderr, "b3_long: bad period count or cannot write %s\n", argv[2]);
    return 1;
  }
  pm = calloc((size_t)P, sizeof(double));
  dm_gsl_init();
  gsl_set_error_handler_off();
  dm_builtin_kepler(&sys, 2, 1.0, &e);
  bu_machine("B3 long time, dmech and GSL (bench/b3_long.c)");
  printf("\n## B3 Kepler e=0.6, %ld periods (t = %.6g)\n", P, P * Per);
  printf("%-26s %11s %9s %9s %11s %11s %11s %11s\n", "method", "steps", "cpu_s", "cpu_mon", "max|dH|",
         "max 1st10%", "max last10%", "trend");
  for (k = 0; k < sizeof ms / sizeof ms[0]; k++) {
    dm_integrator *I = NULL;
    dm_integ_opts o;
    double q[2], p[2], c0, cpu0, cpu1;
    mon m;
    int st;
    dm_integ_opts_init(&o);
    o.stages = ms[k].stages;
    if (dm_integrator_new(&sys, ms[k].method, &o, &I, &e) != DM_OK) {
      printf("%-26s skipped: %s\n", ms[k].label, e.msg);
      continue;
    }
    steps = lround((double)P * Per / ms[k].h);
    memcpy(q, kep_q0, sizeof q);
    memcpy(p, kep_p0, sizeof p);
    c0 = bu_cpu();
    st = dm_integrator_run(I, 0.0, q, p, ms[k].h, steps, steps, NULL, NULL, NULL, &e);
    cpu0 = bu_cpu() - c0;
    memcpy(q, kep_q0, sizeof q);
    memcpy(p, kep_p0, sizeof p);
    memset(pm, 0, (size_t)P * sizeof(double));
    m.H0 = kep_energy(q, p);
    m.P = Per;
    m.periods = P;
    m.pm = pm;
    dm_integrator_reset(I);
    c0 = bu_cpu();
    if (st == DM_OK)
      st = dm_integrator_run(I, 0.0, q, p, ms[k].h, steps, 1, sink, &m, NULL, &e);
    cpu1 = bu_cpu() - c0;
    if (st != DM_OK)
      printf("%-26s failed: %s\n", ms[k].label, e.msg);
    else
      summary(out, ms[k].label, steps, cpu0, cpu1, pm, P);
    dm_integrator_free(I);
  }
  {
    /* GSL rk8pd: per accepted step */
    gsl_odeiv2_system s = gp_system(GP_KEPLER);
    gsl_odeiv2_step *gs = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 4);
    gsl_odeiv2_control *gc = gsl_odeiv2_control_y_new(1e-10, 1e-10);
    gsl_odeiv2_evolve *ev = gsl_odeiv2_evolve_alloc(4);
    double y[4], t, h, T = (double)P * Per, H0, c0, cpu0 = 0, cpu1 = 0;
    long nst = 0;
    int pass, rc = GSL_SUCCESS;
    for (pass = 0; pass < 2 && rc == GSL_SUCCESS; pass++) {
      y[0] = kep_q0[0]; y[1] = kep_q0[1]; y[2] = kep_p0[0]; y[3] = kep_p0[1];
      H0 = kep_energy(y, y + 2);
      t = 0.0;
      h = 1e-3;
      nst = 0;
      gsl_odeiv2_evolve_reset(ev);
      gsl_odeiv2_step_reset(gs);
      memset(pm, 0, (size_t)P * sizeof(double));
      c0 = bu_cpu();
      while (t < T) {
        if ((rc = gsl_odeiv2_evolve_apply(ev, gc, gs, &s, &t, T, &h, y)) != GSL_SUCCESS)
          break;
        nst++;
        if (pass == 1) {
          long kk = (long)(t / Per);
          double d = fabs(kep_energy(y, y + 2) - H0);
          if (kk >= P)
            kk = P - 1;
          if (d > pm[kk])
            pm[kk] = d;
        }
      }
      if (pass == 0)
        cpu0 = bu_cpu() - c0;
      else
        cpu1 = bu_cpu() - c0;
    }
    if (rc != GSL_SUCCESS)
      printf("%-26s failed: GSL status %d\n", "GSL rk8pd tol 1e-10", rc);
    else
      summary(out, "GSL rk8pd tol 1e-10", nst, cpu0, cpu1, pm, P);
    gsl_odeiv2_evolve_free(ev);
    gsl_odeiv2_control_free(gc);
    gsl_odeiv2_step_free(gs);
  }
  dm_system_release(&sys);
  free(pm);
  fclose(out);
  return 0;
}
