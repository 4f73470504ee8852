/* test_integrators_kepler.c -- doc/integrators.md §12.5: Kepler e = 0.6 (q0 = (0.4, 0),
 * p0 = (0, 2), H = -1/2, angular momentum 0.8, period 2 pi): energy error
 * maxima over 10 periods for Stormer-Verlet and Gauss 1-3, no drift over
 * 1000 periods (linear fit of the per-period maxima), angular momentum to
 * round-off.  The 1000-period run is explicit Stormer-Verlet (6.3e5 steps). */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "tap.h"

static double energy(const double *q, const double *p)
{
  return 0.5 * (p[0] * p[0] + p[1] * p[1]) - 1.0 / sqrt(q[0] * q[0] + q[1] * q[1]);
}

/* Sink used for the sampled runs: max |H - H0| and max |J - J0| */
typedef struct emax {
  double dH, dJ;
  long n;
} emax;

static int sink(void *ctx, double t, const double *q, const double *p, const double *v)
{
  emax *m = ctx;
  double J = q[0] * p[1] - q[1] * p[0];
  (void)t;
  (void)v;
  m->dH = fmax(m->dH, fabs(energy(q, p) + 0.5));
  m->dJ = fmax(m->dJ, fabs(J - 0.8));
  m->n++;
  return 0;
}

static void maxima(void)
{
  static const struct {
    const char *m;
    int s;
    double h, want;
  } c[] = {
    {"trapezoid", 0, 0.01, 3.707e-4}, {"trapezoid", 0, 0.005, 9.263e-5}, {"trapezoid", 0, 0.0025, 2.316e-5},
    {"gauss", 1, 0.01, 4.22e-4}, {"gauss", 2, 0.05, 3.89e-6}, {"gauss", 2, 0.025, 2.50e-7},
    {"gauss", 3, 0.1, 1.21e-6}, {"gauss", 3, 0.05, 1.76e-8},
  };
  dm_system s;
  size_t i;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  for (i = 0; i < sizeof c / sizeof c[0]; i++) {
    dm_integ_opts o;
    dm_integrator *I = NULL;
    double q[2] = {0.4, 0.0}, p[2] = {0.0, 2.0};
    long n = (long)ceil(20.0 * M_PI / c[i].h);
    emax m = {0, 0, 0};
    dm_run_info info;
    int st;
    dm_integ_opts_init(&o);
    o.stages = c[i].s;
    dm_integrator_new(&s, c[i].m, &o, &I, NULL);
    st = dm_integrator_run(I, 0.0, q, p, c[i].h, n, 1, sink, &m, &info, NULL);
    tap_ok(st == DM_OK && m.n == n + 1 && fabs(m.dH / c[i].want - 1.0) <= 0.05,
           "Kepler %s%s h = %g: max |H - H0| over 10 periods %.4g (reference %.4g)",
           c[i].m, c[i].s ? (c[i].s == 1 ? " s=1" : c[i].s == 2 ? " s=2" : " s=3") : " (Stormer-Verlet)",
           c[i].h, m.dH, c[i].want);
    if (strcmp(c[i].m, "gauss") == 0 && c[i].s == 2)
      tap_ok(m.dJ <= 5e-13, "Kepler G2 h = %g: angular momentum error %.2g (quadratic invariant)", c[i].h, m.dJ);
    dm_integrator_free(I);
  }
  dm_system_release(&s);
}

/* 1000 periods of Stormer-Verlet h = 0.01: per-period maxima, linear fit. */
static void long_run(void)
{
  enum { NP = 1000 };
  static double pmax[NP];
  dm_system s;
  dm_integrator *I = NULL;
  double q[2] = {0.4, 0.0}, p[2] = {0.0, 2.0}, h = 0.01, T = 2 * M_PI, dJ = 0.0, all = 0.0;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, slope, mean;
  long k, n = (long)ceil(NP * T / h);
  int st = DM_OK;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "trapezoid", NULL, &I, NULL);
  memset(pmax, 0, sizeof pmax);
  for (k = 1; k <= n && st == DM_OK; k++) {
    long per = (long)floor((double)k * h / T);
    double dH;
    st = dm_integrator_step(I, h, q, p, q, p, NULL);
    dH = fabs(energy(q, p) + 0.5);
    if (per < NP)
      pmax[per] = fmax(pmax[per], dH);
    all = fmax(all, dH);
  }
  dJ = fabs(q[0] * p[1] - q[1] * p[0] - 0.8);
  for (k = 0; k < NP; k++) {
    sx += k;
    sxx += (double)k * k;
    sy += pmax[k];
    sxy += k * pmax[k];
  }
  slope = (NP * sxy - sx * sy) / (NP * sxx - sx * sx);
  mean = sy / NP;
  tap_ok(st == DM_OK && (I->flags & DM_INTEG_EXPLICIT), "Kepler: %ld explicit Stormer-Verlet steps", n);
  tap_ok(fabs(all / 3.707e-4 - 1.0) <= 0.05, "Kepler SV h = 0.01 over 1000 periods: max |H - H0| %.4g (reference 3.707e-4)", all);
  tap_ok(fabs(slope * NP) <= 1e-3 * mean,
         "Kepler no drift: trend of the per-period maxima over 1000 periods %.2g (mean maximum %.4g)",
         slope * NP, mean);
  tap_ok(dJ <= 5e-13, "Kepler angular momentum error after 1000 periods %.2g", dJ);
  dm_integrator_free(I);
  dm_system_release(&s);
}

int main(void)
{
  dm_gsl_init();
  maxima();
  long_run();
  return tap_done();
}
