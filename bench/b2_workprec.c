/* b2_workprec.c -- B2 work-precision, dmech methods and GSL, in C.
 *
 * Kepler e = 0.6 over 1000 periods (T = 2000 pi) and J2 over ~1000 orbits
 * (T = 12750): for each method and step size h (N = round(T/h) steps of
 * T/N) the CPU time of the run (median of up to BENCH_REPEAT = 3 runs; one
 * run when a run takes over 2 s), the error of the final (q, p) against
 * bench/data/reference.txt (2-norm) and max |H - H0| over every step (from
 * a separate, untimed run that samples each step).  dmech methods run on
 * the built-in C systems through dm_integrator_run (the explicit
 * Stormer-Verlet fast path for "trapezoid").  GSL rk8pd is driven directly
 * (hand-written right-hand side, gsl_odeiv2_evolve_apply) at a sweep of
 * tolerances epsabs = epsrel; its energy error is sampled at every accepted
 * step.  Writes <outdir>/b2_<problem>_c.tsv and prints the same table.
 * Usage: b2_workprec <kepler|j2|all> <outdir> <reference.txt>
 * BENCH_QUICK=1 drops the smallest step of every sweep.
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
#include "peers/refdata.h"

typedef struct method {
  const char *label, *name;
  int stages;
  double hk[8], hj[8];   /* step sizes for Kepler / J2, 0-terminated */
} method;

static const method methods[] = {
  {"dmech SV", "trapezoid", 0, {0.05, 0.02, 0.01, 0.005, 0.002, 0.001}, {0.2, 0.1, 0.05, 0.02, 0.01, 0.005}},
  {"dmech comp4 yoshida4", "composition:yoshida4", 0, {0.05, 0.02, 0.01, 0.005, 0.002},
   {0.2, 0.1, 0.05, 0.02, 0.01}},
  {"dmech comp6 kahanli6", "composition:kahanli6", 0, {0.1, 0.05, 0.02, 0.01, 0.005},
   {0.4, 0.2, 0.1, 0.05, 0.02}},
  {"dmech comp8 kahanli8", "composition:kahanli8", 0, {0.1, 0.05, 0.02, 0.01, 0.005},
   {0.4, 0.2, 0.1, 0.05, 0.02}},
  {"dmech Gauss s=2", "gauss", 2, {0.05, 0.02, 0.01, 0.005}, {0.2, 0.1, 0.05, 0.02}},
  {"dmech Gauss s=3", "gauss", 3, {0.1, 0.05, 0.02, 0.01}, {0.4, 0.2, 0.1, 0.05}},
  {"dmech Lobatto s=3", "lobatto", 3, {0.05, 0.02, 0.01, 0.005}, {0.2, 0.1, 0.05, 0.02}},
};

static const double gsl_tols[] = {1e-6, 1e-8, 1e-10, 1e-12, 1e-13, 1e-14, 0};

typedef struct hmon {
  int prob;
  double H0, max;
} hmon;

static int sink(void *ctx, double t, const double *q, const double *p, const double *v)
{
  hmon *m = ctx;
  double H = m->prob == GP_KEPLER ? kep_energy(q, p) : j2_energy(q, p);
  (void)t; (void)v;
  m->max = fmax(m->max, fabs(H - m->H0));
  return 0;
}

static FILE *out;

static void row(const char *prob, const char *impl, const char *label, const char *pname,
                double par, long steps, double cpu, int reps, double err, double dH)
{
  printf("%-8s %-24s %-4s %-9.3g %10ld %10.4f %4d %11.3e %11.3e\n", prob, label, pname, par, steps,
         cpu, reps, err, dH);
  fprintf(out, "%s\t%s\t%s\t%s\t%.17g\t%ld\t%.6g\t%d\t%.6e\t%.6e\n", prob, impl, label, pname, par,
          steps, cpu, reps, err, dH);
  fflush(out);
}

static void run_problem(int prob, const char *refpath, int R, int quick)
{
  const char *pn = prob == GP_KEPLER ? "kepler" : "j2";
  const double T = prob == GP_KEPLER ? KEP_T1000 : J2_T1000;
  const double *q0 = prob == GP_KEPLER ? kep_q0 : j2_q0, *p0 = prob == GP_KEPLER ? kep_p0 : j2_p0;
  size_t n = prob == GP_KEPLER ? 2 : 3;
  ref_point ref = {0, {0}, {0}, 0};
  dm_system sys;
  dm_err e;
  size_t mi;
  int have_ref = ref_load(refpath, pn, &ref) == 0, ti;
  if (!have_ref)
    fprintf(stderr, "b2: no reference for %s in %s: errors reported as NaN\n", pn, refpath);
  if (prob == GP_KEPLER)
    dm_builtin_kepler(&sys, 2, 1.0, &e);
  else
    dm_builtin_j2(&sys, J2_VALUE, &e);
  printf("\n## B2 %s, T = %.10g\n%-8s %-24s %-4s %-9s %10s %10s %4s %11s %11s\n", pn, T, "problem",
         "method", "par", "value", "steps", "cpu_s", "reps", "err_end", "max|dH|");
  for (mi = 0; mi < sizeof methods / sizeof methods[0]; mi++) {
    const method *M = &methods[mi];
    const double *hs = prob == GP_KEPLER ? M->hk : M->hj;
    int k, kmax = 0;
    while (kmax < 8 && hs[kmax] > 0)
      kmax++;
    if (quick && kmax > 2)
      kmax--;
    for (k = 0; k < kmax; k++) {
      long N = lround(T / hs[k]);
      double h = T / (double)N, q[3], p[3], t[16], err = NAN, cpu;
      dm_integ_opts o;
      dm_integrator *I = NULL;
      hmon mon;
      int r, reps = 0, st = DM_OK;
      dm_integ_opts_init(&o);
      o.stages = M->stages;
      if (dm_integrator_new(&sys, M->name, &o, &I, &e) != DM_OK) {
        printf("%-8s %-24s skipped: %s\n", pn, M->label, e.msg);
        break;
      }
      for (r = 0; r < R; r++) {
        double t0;
        memcpy(q, q0, n * sizeof(double));
        memcpy(p, p0, n * sizeof(double));
        dm_integrator_reset(I);
        t0 = bu_cpu();
        st = dm_integrator_run(I, 0.0, q, p, h, N, N, NULL, NULL, NULL, &e);
        t[reps++] = bu_cpu() - t0;
        if (st != DM_OK || t[reps - 1] > 2.0)
          break;
      }
      if (st != DM_OK) {
        printf("%-8s %-24s h=%g failed: %s\n", pn, M->label, hs[k], e.msg);
        dm_integrator_free(I);
        continue;
      }
      if (have_ref)
        err = ref_error(&ref, (long double)N * h, q, p);
      cpu = bu_median(t, reps);
      /* untimed run sampling every step */
      memcpy(q, q0, n * sizeof(double));
      memcpy(p, p0, n * sizeof(double));
      mon.prob = prob;
      mon.H0 = prob == GP_KEPLER ? kep_energy(q, p) : j2_energy(q, p);
      mon.max = 0.0;
      dm_integrator_reset(I);
      st = dm_integrator_run(I, 0.0, q, p, h, N, 1, sink, &mon, NULL, &e);
      row(pn, "dmech", M->label, "h", hs[k], N, cpu, reps, err, st == DM_OK ? mon.max : NAN);
      dm_integrator_free(I);
    }
  }
  for (ti = 0; gsl_tols[ti] > 0; ti++) {
    double y[6], t[16], dH = NAN, err = NAN, cpu;
    long steps = 0;
    int r, reps = 0, st = 0;
    if (quick && gsl_tols[ti + 1] == 0)
      break;
    for (r = 0; r < R; r++) {
      double t0;
      memcpy(y, q0, n * sizeof(double));
      memcpy(y + n, p0, n * sizeof(double));
      t0 = bu_cpu();
      st = gp_adaptive(gsl_odeiv2_step_rk8pd, prob, T, gsl_tols[ti], y, NULL, &steps);
      t[reps++] = bu_cpu() - t0;
      if (st != 0 || t[reps - 1] > 2.0)
        break;
    }
    if (st != 0) {
      printf("%-8s %-24s tol=%g failed (GSL status %d)\n", pn, "GSL rk8pd", gsl_tols[ti], st);
      continue;
    }
    if (have_ref)
      err = ref_error(&ref, T, y, y + n);
    cpu = bu_median(t, reps);
    memcpy(y, q0, n * sizeof(double));
    memcpy(y + n, p0, n * sizeof(double));
    gp_adaptive(gsl_odeiv2_step_rk8pd, prob, T, gsl_tols[ti], y, &dH, NULL);
    row(pn, "gsl", "GSL rk8pd", "tol", gsl_tols[ti], steps, cpu, reps, err, dH);
  }
  dm_system_release(&sys);
}

int main(int argc, char **argv)
{
  int R = bu_env_int("BENCH_REPEAT", 3), quick = bu_env_int("BENCH_QUICK", 0), p;
  char path[4096];
  if (argc < 4) {
    fprintf(stderr, "usage: b2_workprec <kepler|j2|all> <outdir> <reference.txt>\n");
    return 2;
  }
  if (R < 1)
    R = 1;
  if (R > 16)
    R = 16;
  dm_gsl_init();
  gsl_set_error_handler_off();
  bu_machine("B2 work-precision, dmech and GSL (bench/b2_workprec.c)");
  for (p = 0; p < 2; p++) {
    const char *pn = p == 0 ? "kepler" : "j2";
    if (strcmp(argv[1], "all") != 0 && strcmp(argv[1], pn) != 0)
      continue;
    snprintf(path, sizeof path, "%s/b2_%s_c.tsv", argv[2], pn);
    if ((out = fopen(path, "w")) == NULL) {
      perror(path);
      return 1;
    }
    fprintf(out, "problem\timpl\tmethod\tpar\tvalue\tsteps\tcpu_s\treps\terr_end\tmax_dH\n");
    run_problem(p == 0 ? GP_KEPLER : GP_J2, argv[3], R, quick);
    fclose(out);
  }
  return 0;
}
