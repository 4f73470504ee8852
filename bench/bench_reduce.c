/* bench_reduce.c -- the double spherical pendulum (doc/reduce.md §14): cost per
 * step and accuracy, at equal h, of
 *   RSPRK on the shape space (r1, r2, phi)       3 dof            (reduced)
 *   SPRK on the unreduced system (r1, th1, r2, phi) 4 dof         (same chart)
 * for Gauss s = 2 and Lobatto IIIA-IIIB s = 3, and of the constrained
 * formulations with Lobatto 3 and multipliers at every stage:
 *   RSPRK on the preshape space of R^3 x R^3 (r1, z1, r2, phi, z2), 2 constraints
 *   SPRK on Cartesian R^3 x R^3 (x1, y1, z1, x2, y2, z2), 2 constraints.
 * Every system is derived from expressions by the program itself (the
 * reduced ones by dm_routh_derive) and runs native code when a C compiler
 * works (else tapes; the header line says which).  Accuracy: max-norm error
 * of (r1, r2, phi) at T = 5 against RSPRK Gauss 4 with h/16.  Each variant
 * runs `reps` times (interleaved, after a warm-up), thread CPU time, median.
 *
 * usage: bench_reduce [reps] */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/status.h"
#include "expr/lagrangian.h"
#include "reduce/routh.h"
#include "reduce_systems.h"

static const double PV[5] = {1.3, 0.8, 1.1, 0.9, 9.81};
static const double Q0[4] = {0.6, 0.3, 0.5, 0.3}, V0[4] = {0.1, 3.3, -0.1, 0.2};
#define H 0.01
#define T 5.0

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

typedef struct variant {
  const char *label;
  int dof, m;
  dm_integrator *I;
  double q0[6], p0[6];
  int kind;                 /* 0: shape (0,1,2); 1: full cyl (0,2,3); 2: preshape (0,2,3); 3: Cartesian */
  double t[64], err, ns;
} variant;

static void shape_of(const variant *v, const double *q, double *x)
{
  switch (v->kind) {
  case 0: x[0] = q[0]; x[1] = q[1]; x[2] = q[2]; break;
  case 1: case 2: x[0] = q[0]; x[1] = q[2]; x[2] = q[3]; break;
  default: {
    double a1 = atan2(q[1], q[0]), a2 = atan2(q[4], q[3]), ph = a2 - a1;
    while (ph - Q0[3] > M_PI) ph -= 2 * M_PI;
    while (ph - Q0[3] < -M_PI) ph += 2 * M_PI;
    x[0] = hypot(q[0], q[1]);
    x[1] = hypot(q[3], q[4]);
    x[2] = ph;
  }
  }
}

/* Cartesian R^3 x R^3 with |q_i|^2 = l_i^2 */
static int cartesian(rsys *S, dm_system *sys, dm_err *e)
{
  static const char *qn[] = {"x1", "y1", "z1", "x2", "y2", "z2"};
  static const char *vn[] = {"vx1", "vy1", "vz1", "vx2", "vy2", "vz2"};
  static const char *pn[] = {"m1", "m2", "l1", "l2", "g"};
  dm_lagrangian_spec sp;
  dm_expr T1, T2, V;
  size_t i;
  rs_syms(S, 6, qn, vn, 5, pn, PV);
  T1 = RC(0.0);
  T2 = RC(0.0);
  for (i = 0; i < 3; i++) {
    T1 = RADD(T1, RSQ(S->v[i]));
    T2 = RADD(T2, RSQ(RADD(S->v[i], S->v[3 + i])));
  }
  V = RADD(RMUL(RMUL(S->par[0], S->par[4]), S->q[2]),
           RMUL(RMUL(S->par[1], S->par[4]), RADD(S->q[2], S->q[5])));
  S->L = RSUB(RADD(RMUL(RMUL(RC(0.5), S->par[0]), T1), RMUL(RMUL(RC(0.5), S->par[1]), T2)), V);
  S->g[0] = RSUB(RADD(RADD(RSQ(S->q[0]), RSQ(S->q[1])), RSQ(S->q[2])), RSQ(S->par[2]));
  S->g[1] = RSUB(RADD(RADD(RSQ(S->q[3]), RSQ(S->q[4])), RSQ(S->q[5])), RSQ(S->par[3]));
  memset(&sp, 0, sizeof sp);
  sp.name = "double spherical pendulum (Cartesian R3xR3)";
  sp.n = 6; sp.q = S->q; sp.v = S->v; sp.npar = 5; sp.par = S->par; sp.par_values = PV;
  sp.L = S->L; sp.m = 2; sp.constraints = S->g; sp.native = DM_NATIVE_AUTO;
  return dm_lagrangian_compile(S->c, &sp, sys, e);
}

int main(int argc, char **argv)
{
  int reps = argc > 1 ? atoi(argv[1]) : 7, k, j, nv = 0;
  long nsteps = lround(T / H);
  rsys Sd, Sc, Sx;
  dm_routh *red = NULL, *rc = NULL;
  dm_system cart;
  dm_integ_opts o;
  dm_err e;
  size_t cyc = 1;
  double x0[3], s0[3], mu, xref[3], sref[3], y0[5], sy0[5], muc, q6[6], v6[6];
  variant V[6];
  dm_lagrangian_stats ls;
  if (reps < 1)
    reps = 1;
  if (reps > 64)
    reps = 64;
  dm_gsl_init();
  rs_dsp(&Sd, PV, 0);
  rs_dsp_constrained(&Sc, PV);
  if (rs_reduce_native(&Sd, 1, &cyc, NULL, DM_NATIVE_AUTO, &red, &e) != DM_OK ||
      rs_reduce_native(&Sc, 1, &cyc, NULL, DM_NATIVE_AUTO, &rc, &e) != DM_OK ||
      cartesian(&Sx, &cart, &e) != DM_OK) {
    fprintf(stderr, "bench_reduce: %s\n", e.msg);
    return 1;
  }
  dm_routh_project_qv(red, Q0, V0, x0, s0, &mu, NULL, NULL);
  dm_routh_set_mu(red, &mu, NULL);
  {
    double S1 = sqrt(PV[2] * PV[2] - Q0[0] * Q0[0]), S2 = sqrt(PV[3] * PV[3] - Q0[2] * Q0[2]);
    double th = Q0[1], th2 = Q0[1] + Q0[3], w = V0[1], w2 = V0[1] + V0[3];
    double q6c[6] = {Q0[0], Q0[1], -S1, Q0[2], Q0[3], -S2};
    double v6c[6] = {V0[0], V0[1], Q0[0] * V0[0] / S1, V0[2], V0[3], Q0[2] * V0[2] / S2};
    dm_routh_project_qv(rc, q6c, v6c, y0, sy0, &muc, NULL, NULL);
    dm_routh_set_mu(rc, &muc, NULL);
    q6[0] = Q0[0] * cos(th); q6[1] = Q0[0] * sin(th); q6[2] = -S1;
    q6[3] = Q0[2] * cos(th2); q6[4] = Q0[2] * sin(th2); q6[5] = -S2;
    v6[0] = V0[0] * cos(th) - Q0[0] * w * sin(th); v6[1] = V0[0] * sin(th) + Q0[0] * w * cos(th);
    v6[2] = v6c[2];
    v6[3] = V0[2] * cos(th2) - Q0[2] * w2 * sin(th2); v6[4] = V0[2] * sin(th2) + Q0[2] * w2 * cos(th2);
    v6[5] = v6c[5];
  }
  /* reference */
  {
    dm_integrator *R = NULL;
    dm_integ_opts_init(&o);
    o.stages = 4;
    dm_routh_integrator_new(red, "gauss", &o, &R, NULL);
    memcpy(xref, x0, sizeof xref);
    memcpy(sref, s0, sizeof sref);
    dm_integrator_run(R, 0, xref, sref, H / 16, 16 * nsteps, 16 * nsteps, NULL, NULL, NULL, NULL);
    dm_integrator_free(R);
  }
  memset(V, 0, sizeof V);
#define ADD(lbl, dof_, m_, kind_, mk)                                          \
  do {                                                                         \
    variant *v = &V[nv++];                                                     \
    v->label = lbl; v->dof = dof_; v->m = m_; v->kind = kind_;                 \
    if ((mk) != DM_OK) { fprintf(stderr, "bench_reduce: %s: %s\n", lbl, e.msg); return 1; } \
  } while (0)
  dm_integ_opts_init(&o);
  o.stages = 2;
  ADD("RSPRK Gauss 2, shape space", 3, 0, 0, dm_routh_integrator_new(red, "gauss", &o, &v->I, &e));
  memcpy(V[0].q0, x0, sizeof x0); memcpy(V[0].p0, s0, sizeof s0);
  ADD("SPRK Gauss 2, unreduced", 4, 0, 1, dm_integrator_new(dm_routh_full(red), "gauss", &o, &v->I, &e));
  memcpy(V[1].q0, Q0, sizeof Q0); dm_integrator_momentum(V[1].I, Q0, V0, V[1].p0, NULL);
  o.stages = 3;
  ADD("RSPRK Lobatto 3, shape space", 3, 0, 0, dm_routh_integrator_new(red, "lobatto", &o, &v->I, &e));
  memcpy(V[2].q0, x0, sizeof x0); memcpy(V[2].p0, s0, sizeof s0);
  ADD("SPRK Lobatto 3, unreduced", 4, 0, 1, dm_integrator_new(dm_routh_full(red), "lobatto", &o, &v->I, &e));
  memcpy(V[3].q0, Q0, sizeof Q0); dm_integrator_momentum(V[3].I, Q0, V0, V[3].p0, NULL);
  ADD("RSPRK Lobatto 3, R3xR3 preshape + 2 constraints", 5, 2, 2,
      dm_routh_integrator_new(rc, "lobatto", &o, &v->I, &e));
  memcpy(V[4].q0, y0, sizeof y0); memcpy(V[4].p0, sy0, sizeof sy0);
  ADD("SPRK Lobatto 3, Cartesian R3xR3 + 2 constraints", 6, 2, 3,
      dm_integrator_new(&cart, "lobatto", &o, &v->I, &e));
  memcpy(V[5].q0, q6, sizeof q6); dm_integrator_momentum(V[5].I, q6, v6, V[5].p0, NULL);
  for (k = -1; k < reps; k++)          /* k = -1: warm-up */
    for (j = 0; j < nv; j++) {
      variant *v = &V[j];
      double q[6], p[6], t0, x[3];
      int st;
      memcpy(q, v->q0, sizeof q);
      memcpy(p, v->p0, sizeof p);
      dm_integrator_reset(v->I);
      t0 = now();
      st = dm_integrator_run(v->I, 0, q, p, H, nsteps, nsteps, NULL, NULL, NULL, &e);
      if (st != DM_OK) {
        fprintf(stderr, "bench_reduce: %s: %s\n", v->label, e.msg);
        return 1;
      }
      if (k >= 0)
        v->t[k] = (now() - t0) / (double)nsteps * 1e9;
      shape_of(v, q, x);
      v->err = fmax(fabs(x[0] - xref[0]), fmax(fabs(x[1] - xref[1]), fabs(x[2] - xref[2])));
    }
  dm_lagrangian_stats_get(dm_routh_full(red), &ls);
  printf("bench-reduce: double spherical pendulum, h = %g, T = %g (%ld steps), %d reps (median), "
         "%s code\n", H, T, nsteps, reps, ls.native_all ? "native" : "tape");
  printf("%-50s %4s %2s %11s %8s %12s\n", "method", "dof", "m", "ns/step", "ratio", "err(T)");
  for (j = 0; j < nv; j++) {
    variant *v = &V[j];
    qsort(v->t, (size_t)reps, sizeof(double), cmp);
    v->ns = v->t[reps / 2];
  }
  for (j = 0; j < nv; j++) {
    variant *v = &V[j];
    const variant *ref = (j < 4) ? &V[j | 1] : &V[5];
    printf("%-50s %4d %2d %11.0f %8.2f %12.3e\n", v->label, v->dof, v->m, v->ns, v->ns / ref->ns,
           v->err);
  }
  printf("(ratio: to the unreduced SPRK with the same tableau; constrained rows: to the Cartesian one)\n");
  for (j = 0; j < nv; j++)
    dm_integrator_free(V[j].I);
  dm_routh_free(red);
  dm_routh_free(rc);
  dm_system_release(&cart);
  dm_expr_ctx_free(Sd.c);
  dm_expr_ctx_free(Sc.c);
  dm_expr_ctx_free(Sx.c);
  return 0;
}
