/* test_reduce_dr.c -- discrete Routh reduction on the double spherical
 * pendulum (doc/reduce.md §6-7):
 *  - psi_mu: the midpoint closed form equals the Galerkin-Gauss-1 Newton
 *    solution, J_d((0, x0), (psi, x1)) = mu holds, Dpsi matches differences;
 *  - the general DR form (with Ahat_1, Ahat_2) equals the shape components
 *    of DEL along a DEL trajectory (both ~ 0) -- the mu Dpsi terms cancel;
 *  - Theorem 2.3: the DEL trajectory of the full system projected to S
 *    equals the DR trajectory from the same (x0, x1), to solver tolerance,
 *    for the midpoint and the Galerkin-Gauss-2 discrete Lagrangians;
 *  - the position-momentum DR map is RSPRK (Lemma 2.9) and reconstructs
 *    theta; discrete momentum conserved; error path for forced systems. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "core/tableau.h"
#include "reduce/routh.h"
#include "reduce_systems.h"
#include "tap.h"

static const double PV[5] = {1.3, 0.8, 1.1, 0.9, 9.81};
static const double Q0[4] = {0.6, 0.3, 0.5, 0.3}, V0[4] = {0.1, 3.3, -0.1, 0.2};

static double vdiff(const double *a, const double *b, size_t n)
{
  double m = 0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

static void shape(const double *q, double *x)
{
  x[0] = q[0];
  x[1] = q[2];
  x[2] = q[3];
}

static void psi_checks(dm_routh *red, double mu)
{
  dm_routh_dr *m = NULL, *g = NULL;
  dm_tableau *t1 = NULL;
  const double x0[3] = {0.6, 0.5, 0.3}, x1[3] = {0.6031, 0.4962, 0.3118}, h = 0.05;
  double pm, pg, Dm[6], Dg[6], Dfd[6], worst = 0, J, q0[4], q1[4], p1[4];
  dm_integrator *F = NULL;
  dm_err e;
  size_t k;
  dm_tableau_gauss(1, &t1, NULL);
  dm_routh_dr_alloc(red, NULL, 0, 0, &m, &e);
  dm_routh_dr_alloc(red, t1, 0, 0, &g, &e);
  dm_routh_dr_psi(m, h, x0, x1, &pm, Dm, NULL);
  dm_routh_dr_psi(g, h, x0, x1, &pg, Dg, NULL);
  tap_ok(fabs(pm - pg) <= 1e-15 && vdiff(Dm, Dg, 6) <= 1e-13,
         "psi_mu: midpoint closed form %.17g = Galerkin-Gauss-1 Newton %.17g, Dpsi agree (%.2g)", pm,
         pg, vdiff(Dm, Dg, 6));
  for (k = 0; k < 6; k++) {
    double xa[3], xb[3], pp, pq, d = 1e-6;
    memcpy(xa, x0, sizeof xa);
    memcpy(xb, x1, sizeof xb);
    (k < 3 ? xa : xb)[k % 3] += d;
    dm_routh_dr_psi(m, h, xa, xb, &pp, NULL, NULL);
    (k < 3 ? xa : xb)[k % 3] -= 2 * d;
    dm_routh_dr_psi(m, h, xa, xb, &pq, NULL, NULL);
    Dfd[k] = (pp - pq) / (2 * d);
    worst = fmax(worst, fabs(Dfd[k] - Dm[k]));
  }
  tap_ok(worst <= 1e-8, "Dpsi_mu equals central differences (max diff %.2g)", worst);
  /* J_d((0, x0), (psi, x1)) = mu with the full system's midpoint transform */
  dm_integrator_new(dm_routh_full(red), "midpoint", NULL, &F, &e);
  q0[0] = x0[0]; q0[1] = 0; q0[2] = x0[1]; q0[3] = x0[2];
  q1[0] = x1[0]; q1[1] = pm; q1[2] = x1[1]; q1[3] = x1[2];
  dm_integrator_dlegendre(F, h, q0, q1, NULL, p1, NULL, &e);
  J = p1[1];
  tap_ok(fabs(J - mu) <= 1e-14 * fabs(mu), "J_d((0, x0), (psi_mu, x1)) = mu (%.17g vs %.17g)", J, mu);
  dm_integrator_free(F);
  dm_routh_dr_free(m);
  dm_routh_dr_free(g);
  dm_tableau_free(t1);
}

/* Theorem 2.3 with the method's DEL on the full system */
static void theorem23(dm_routh *red, const char *fmethod, int stages, const dm_tableau *t,
                      const char *label)
{
  dm_integ_opts o;
  dm_integrator *F = NULL;
  dm_routh_dr *dr = NULL;
  double q[3][4], p0[4], x[3][3], xdr[3], dmax = 0, rmax = 0, gmax = 0, h = 0.02, rd[3], rl[3];
  double jd, jd0 = 0, jmax = 0, xi[4] = {0, 1, 0, 0};
  dm_err e;
  int k, st = DM_OK;
  dm_integ_opts_init(&o);
  o.stages = stages;
  dm_integrator_new(dm_routh_full(red), fmethod, &o, &F, &e);
  dm_routh_dr_alloc(red, t, 0, 0, &dr, &e);
  memcpy(q[0], Q0, sizeof Q0);
  dm_integrator_momentum(F, Q0, V0, p0, NULL);
  dm_integrator_step(F, h, q[0], p0, q[1], p0, NULL);       /* (q0, q1) on J_d = mu */
  shape(q[0], x[0]);
  shape(q[1], x[1]);
  memcpy(xdr, x[1], sizeof xdr);
  {
    double xdr_prev[3], xdr_next[3];
    memcpy(xdr_prev, x[0], sizeof xdr_prev);
    dm_integrator_discrete_momentum(F, h, q[0], q[1], xi, &jd0, NULL);
    for (k = 0; k < 200 && st == DM_OK; k++) {
      st = dm_integrator_del_step(F, h, q[0], q[1], q[2], &e);
      if (st != DM_OK)
        break;
      shape(q[2], x[2]);
      dm_integrator_discrete_momentum(F, h, q[1], q[2], xi, &jd, NULL);
      jmax = fmax(jmax, fabs(jd - jd0));
      /* residuals along the DEL trajectory */
      st = dm_routh_dr_residual(dr, h, x[0], x[1], x[2], rd, rl, &e);
      rmax = fmax(rmax, fmax(vdiff(rd, rl, 3), fmax(fabs(rd[0]), fabs(rd[2]))));
      /* DR recursion on its own */
      if (st == DM_OK)
        st = dm_routh_dr_solve(dr, h, xdr_prev, xdr, xdr_next, 0, &e);
      memcpy(xdr_prev, xdr, sizeof xdr);
      memcpy(xdr, xdr_next, sizeof xdr);
      dmax = fmax(dmax, vdiff(xdr, x[2], 3));
      memcpy(q[0], q[1], sizeof q[0]);
      memcpy(q[1], q[2], sizeof q[0]);
      memcpy(x[0], x[1], sizeof x[0]);
      memcpy(x[1], x[2], sizeof x[0]);
    }
    gmax = fabs(jd0 - dm_routh_mu(red)[0]);
  }
  if (st != DM_OK)
    tap_diag("%s", e.msg);
  tap_ok(st == DM_OK && rmax <= 1e-11,
         "%s: general DR form (D Lhat - Ahat) = shape components of DEL along a DEL trajectory, both "
         "~ 0 (max %.2g)", label, rmax);
  tap_ok(st == DM_OK && dmax <= 1e-11, "%s: Theorem 2.3, DR trajectory = projected DEL trajectory over "
         "200 steps (max diff %.2g)", label, dmax);
  tap_ok(jmax <= 1e-12 * fabs(jd0) && gmax <= 1e-12 * fabs(jd0),
         "%s: discrete momentum J_d conserved by DEL (%.2g) and equal to mu (%.2g)", label, jmax, gmax);
  dm_routh_dr_free(dr);
  dm_integrator_free(F);
}

/* position-momentum DR = RSPRK (push-forward by Fhat), theta reconstruction */
static void dr_is_rsprk(dm_routh *red, double *x0, double *s0)
{
  const char *pairs[3][2] = {{"dr", "midpoint"}, {"dr:gauss", "gauss"}, {"dr:lobatto", "lobatto"}};
  dm_integ_opts o;
  dm_err e;
  int k, j;
  dm_integ_opts_init(&o);
  for (j = 0; j < 3; j++) {
    dm_integrator *D = NULL, *R = NULL;
    double xd[3], sd[3], xr[3], sr[3], tr, td, dmax = 0, tmax = 0;
    int st;
    o.stages = j == 0 ? 1 : j == 2 ? 3 : 2;
    st = dm_routh_integrator_new(red, pairs[j][0], &o, &D, &e);
    st |= dm_routh_integrator_new(red, pairs[j][1], &o, &R, &e);
    memcpy(xd, x0, sizeof xd);
    memcpy(sd, s0, sizeof sd);
    memcpy(xr, x0, sizeof xr);
    memcpy(sr, s0, sizeof sr);
    for (k = 0; k < 100 && st == DM_OK; k++) {
      st = dm_integrator_step(D, 0.02, xd, sd, xd, sd, &e);
      st |= dm_integrator_step(R, 0.02, xr, sr, xr, sr, &e);
      dm_routh_integrator_theta(D, &td, NULL);
      dm_routh_integrator_theta(R, &tr, NULL);
      dmax = fmax(dmax, fmax(vdiff(xd, xr, 3), vdiff(sd, sr, 3)));
      tmax = fmax(tmax, fabs(td - tr));
    }
    if (st != DM_OK)
      tap_diag("%s", e.msg);
    tap_ok(st == DM_OK && dmax <= 1e-12 && tmax <= 1e-12,
           "position-momentum DR (%s) = RSPRK %s over 100 steps: (x, s) diff %.2g, theta (psi_mu "
           "vs h sum b Thetadot) diff %.2g", pairs[j][0], pairs[j][1], dmax, tmax);
    dm_integrator_free(D);
    dm_integrator_free(R);
  }
}

/* the DR step Jacobian is exact: it equals central differences of the
 * step to their truncation error, and the non-canonical symplecticity
 * defect computed with it is at round-off (differences gave ~1e-10) */
static void dr_jacobian(dm_routh *red, const double *x0, const double *s0)
{
  static const char *const methods[3] = {"dr", "dr:gauss", "dr:lobatto"};
  dm_integ_opts o;
  dm_err e;
  int j;
  dm_integ_opts_init(&o);
  for (j = 0; j < 3; j++) {
    dm_integrator *D = NULL;
    double J[36], z[6], zp[6], zm[6], fd, worst = 0, def = 1, h = 0.05;
    int st, k, i;
    o.stages = j == 0 ? 1 : j == 2 ? 3 : 2;
    st = dm_routh_integrator_new(red, methods[j], &o, &D, &e);
    if (st == DM_OK)
      st = dm_integrator_jacobian(D, h, x0, s0, J, &e);
    for (k = 0; st == DM_OK && k < 6; k++) {
      double d = 1e-5;
      memcpy(z, x0, 3 * sizeof(double));
      memcpy(z + 3, s0, 3 * sizeof(double));
      z[k] += d;
      st |= dm_integrator_step(D, h, z, z + 3, zp, zp + 3, &e);
      z[k] -= 2 * d;
      st |= dm_integrator_step(D, h, z, z + 3, zm, zm + 3, &e);
      for (i = 0; i < 6; i++) {
        fd = (zp[i] - zm[i]) / (2 * d);
        worst = fmax(worst, fabs(fd - J[i * 6 + k]) / fmax(1.0, fabs(J[i * 6 + k])));
      }
    }
    if (st == DM_OK)
      st = dm_routh_symplecticity_defect(D, h, x0, s0, &def, &e);
    if (st != DM_OK)
      tap_diag("%s", e.msg);
    tap_ok(st == DM_OK && (D->flags & DM_INTEG_EXACT_JAC) && worst <= 1e-8,
           "%s: exact step Jacobian = central differences (rel. diff %.2g)", methods[j], worst);
    tap_ok(st == DM_OK && def <= 1e-13,
           "%s: non-canonical symplecticity defect with the exact Jacobian %.2g (round-off)",
           methods[j], def);
    dm_integrator_free(D);
  }
}

int main(void)
{
  rsys S;
  dm_routh *red = NULL;
  dm_tableau *g2 = NULL;
  dm_err e;
  size_t cyc = 1;
  double x0[3], s0[3], mu;
  dm_gsl_init();
  rs_dsp(&S, PV, 0);
  if (rs_reduce(&S, 1, &cyc, NULL, &red, &e) != DM_OK) {
    tap_ok(0, "derive: %s", e.msg);
    return tap_done();
  }
  dm_routh_project_qv(red, Q0, V0, x0, s0, &mu, NULL, NULL);
  dm_routh_set_mu(red, &mu, NULL);
  psi_checks(red, mu);
  theorem23(red, "midpoint", 1, NULL, "midpoint");
  dm_tableau_gauss(2, &g2, NULL);
  theorem23(red, "gauss", 2, g2, "Galerkin-Gauss 2");
  dr_is_rsprk(red, x0, s0);
  dr_jacobian(red, x0, s0);
  dm_tableau_free(g2);
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
  /* forced system: DR is not available, RSPRK is */
  {
    const double pv[6] = {1.3, 0.8, 1.1, 0.9, 9.81, 0.2};
    dm_integrator *I = NULL;
    int st;
    rs_dsp(&S, pv, 1);
    rs_reduce(&S, 1, &cyc, NULL, &red, &e);
    st = dm_routh_integrator_new(red, "dr", NULL, &I, &e);
    tap_ok(st == DM_EUNSUP && I == NULL && strstr(e.msg, "RSPRK"), "dr on a forced system: %s", e.msg);
    st = dm_routh_integrator_new(red, "nonsense", NULL, &I, &e);
    tap_ok(st == DM_ENOTFOUND && strstr(e.msg, "known:"), "unknown reduced method: %s", e.msg);
    dm_routh_free(red);
    dm_expr_ctx_free(S.c);
  }
  return tap_done();
}
