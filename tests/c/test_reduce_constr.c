/* test_reduce_constr.c -- reduction with forcing and with holonomic
 * constraints (thesis §2.8, Theorems 2.14, 2.16, 2.17; doc/reduce.md §11):
 *  - reduced forced = projected forced: RSPRK on the reduced force equals the
 *    unreduced forced Gauss 2 projected, mu conserved, energy decays;
 *  - the double spherical pendulum in R^3 x R^3 (cylindrical coordinates of
 *    each bob with r_i^2 + z_i^2 = l_i^2) reduced by the simultaneous
 *    rotation, on the preshape space (r1, z1, r2, phi, z2): Lobatto IIIA-IIIB
 *    RSPRK with multipliers at every stage keeps |g| <= 1e-12 and tangent
 *    velocities, equals the projected unreduced constrained Lobatto run and
 *    the classical-Routhian run (momentum shift), and agrees with the
 *    cylindrical-coordinate RSPRK solution to the method's order (4);
 *  - forcing and constraints together (Theorem 2.17): reduced = projected;
 *  - Gauss s >= 2 with constraints is rejected. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "reduce/routh.h"
#include "reduce_systems.h"
#include "tap.h"

static const double PV[5] = {1.3, 0.8, 1.1, 0.9, 9.81};

static double vdiff(const double *a, const double *b, size_t n)
{
  double m = 0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

static void forced(void)
{
  const double pv[6] = {1.3, 0.8, 1.1, 0.9, 9.81, 0.4};
  const double Q0[4] = {0.6, 0.3, 0.5, 0.3}, V0[4] = {0.1, 3.3, -0.1, 0.2};
  rsys S;
  dm_routh *red = NULL;
  dm_integrator *R = NULL, *F = NULL;
  dm_integ_opts o;
  double x[3], s[3], mu, q[4], p[4], xp[3], sp[3], mup, dmax = 0, mmax = 0, v[3], E0, E1;
  size_t cyc = 1;
  dm_err e;
  int k, st;
  rs_dsp(&S, pv, 1);
  st = rs_reduce(&S, 1, &cyc, NULL, &red, &e);
  if (!tap_ok(st == DM_OK && dm_routh_exprs_get(red)->force != NULL,
              "damped double pendulum reduced (force with zero theta1 component)")) {
    tap_diag("%s", e.msg);
    return;
  }
  {
    char *f = dm_expr_to_string(S.c, dm_routh_exprs_get(red)->force[0], 0, NULL);
    tap_ok(f && strstr(f, "mu_theta1"), "reduced force substitutes thetadot on J = mu: Fhat_r1 = %.100s",
           f ? f : "?");
    free(f);
  }
  dm_routh_project_qv(red, Q0, V0, x, s, &mu, NULL, &e);
  dm_routh_set_mu(red, &mu, NULL);
  dm_integ_opts_init(&o);
  o.stages = 2;
  dm_routh_integrator_new(red, "gauss", &o, &R, &e);
  dm_integrator_new(dm_routh_full(red), "gauss", &o, &F, &e);
  memcpy(q, Q0, sizeof q);
  dm_integrator_momentum(F, Q0, V0, p, NULL);
  dm_integrator_velocity(R, x, s, v, 0, NULL);
  dm_integrator_energy(R, x, v, &E0, NULL);
  for (k = 0, st = DM_OK; k < 300 && st == DM_OK; k++) {
    st = dm_integrator_step(R, 0.01, x, s, x, s, &e);
    st |= dm_integrator_step(F, 0.01, q, p, q, p, &e);
    dm_routh_project(red, q, p, xp, sp, &mup, NULL, NULL);
    dmax = fmax(dmax, fmax(vdiff(x, xp, 3), vdiff(s, sp, 3)));
    mmax = fmax(mmax, fabs(mup - mu));
  }
  dm_integrator_velocity(R, x, s, v, 0, NULL);
  dm_integrator_energy(R, x, v, &E1, NULL);
  tap_ok(st == DM_OK && dmax <= 1e-12 && mmax <= 1e-13 * mu,
         "reduced forced RSPRK = projected unreduced forced Gauss 2 over 300 steps (max diff %.2g); "
         "mu conserved (%.2g)", dmax, mmax);
  tap_ok(E1 < E0 - 1e-3, "the damping dissipates the reduced energy (%.6f -> %.6f)", E0, E1);
  dm_integrator_free(R);
  dm_integrator_free(F);
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

/* state of the constrained full system from cylindrical data */
static void constrained_state(const double *Q4, const double *V4, double *q6, double *v6)
{
  double S1 = sqrt(PV[2] * PV[2] - Q4[0] * Q4[0]), S2 = sqrt(PV[3] * PV[3] - Q4[2] * Q4[2]);
  q6[0] = Q4[0]; q6[1] = Q4[1]; q6[2] = -S1; q6[3] = Q4[2]; q6[4] = Q4[3]; q6[5] = -S2;
  v6[0] = V4[0]; v6[1] = V4[1]; v6[2] = Q4[0] * V4[0] / S1;
  v6[3] = V4[2]; v6[4] = V4[3]; v6[5] = Q4[2] * V4[2] / S2;
}

static void constrained(void)
{
  const double Q4[4] = {0.6, 0.3, 0.5, 0.3}, V4[4] = {0.1, 3.3, -0.1, 0.2};
  rsys C, Y;
  dm_routh *rc = NULL, *ry = NULL;
  dm_integrator *I = NULL, *U = NULL, *K = NULL;
  dm_integ_opts o;
  double q6[6], v6[6], p6[6], y[5], sy[5], muc, xc[3], sc[3], muy, gmax = 0, tmax = 0, dcube = 0;
  double dcl = 0;
  size_t cyc = 1;
  dm_err e;
  int st, k;
  rs_dsp_constrained(&C, PV);
  st = rs_reduce(&C, 1, &cyc, NULL, &rc, &e);
  if (!tap_ok(st == DM_OK && dm_routh_system(rc)->m == 2 && dm_routh_system(rc)->n == 5,
              "R^3 x R^3 pendulum reduced to the preshape space (r1, z1, r2, phi, z2) with 2 "
              "constraints")) {
    tap_diag("%s", e.msg);
    return;
  }
  rs_dsp(&Y, PV, 0);
  rs_reduce(&Y, 1, &cyc, NULL, &ry, &e);
  constrained_state(Q4, V4, q6, v6);
  dm_routh_project_qv(rc, q6, v6, y, sy, &muc, NULL, &e);
  dm_routh_project_qv(ry, Q4, V4, xc, sc, &muy, NULL, &e);
  dm_routh_set_mu(rc, &muc, NULL);
  dm_routh_set_mu(ry, &muy, NULL);
  tap_ok(fabs(muc - muy) <= 1e-14 * muy, "same momentum in both charts: mu = %.16g / %.16g", muc, muy);
  dm_integ_opts_init(&o);
  o.stages = 3;
  st = dm_routh_integrator_new(rc, "lobatto", &o, &I, &e);
  st |= dm_integrator_new(dm_routh_full(rc), "lobatto", &o, &U, &e);
  st |= dm_routh_integrator_new(rc, "classical:lobatto", &o, &K, &e);
  if (!tap_ok(st == DM_OK, "constrained RSPRK Lobatto 3, unreduced constrained Lobatto 3, classical"))
    tap_diag("%s", e.msg);
  {
    double ya[5], sa[5], yk[5], sk[5], q[6], p[6], yp[5], sp[5], mup, g[2], xd[5];
    const dm_system *rs = dm_routh_system(rc);
    double *wk = malloc(rs->work_size + 8);
    memcpy(ya, y, sizeof ya);
    memcpy(sa, sy, sizeof sa);
    memcpy(yk, y, sizeof yk);
    memcpy(sk, sy, sizeof sk);
    memcpy(q, q6, sizeof q);
    dm_integrator_momentum(U, q6, v6, p6, NULL);
    memcpy(p, p6, sizeof p);
    for (k = 0, st = DM_OK; k < 200 && st == DM_OK; k++) {
      st = dm_integrator_step(I, 0.01, ya, sa, ya, sa, &e);
      st |= dm_integrator_step(U, 0.01, q, p, q, p, &e);
      st |= dm_integrator_step(K, 0.01, yk, sk, yk, sk, &e);
      rs->constraints(rs->data, ya, rs->par, DM_CONSTR_G, g, NULL, NULL, wk);
      gmax = fmax(gmax, fmax(fabs(g[0]), fabs(g[1])));
      dm_integrator_velocity(I, ya, sa, xd, 0, NULL);
      tmax = fmax(tmax, fabs(ya[0] * xd[0] + ya[1] * xd[1]) + fabs(ya[2] * xd[2] + ya[4] * xd[4]));
      dm_routh_project(rc, q, p, yp, sp, &mup, NULL, NULL);
      dcube = fmax(dcube, fmax(vdiff(ya, yp, 5), vdiff(sa, sp, 5)));
      dcl = fmax(dcl, fmax(vdiff(ya, yk, 5), vdiff(sa, sk, 5)));
    }
    free(wk);
    if (st != DM_OK)
      tap_diag("%s", e.msg);
    tap_ok(st == DM_OK && gmax <= 1e-12, "constraints held at every step: max |g| = %.2g", gmax);
    tap_ok(st == DM_OK && tmax <= 1e-12, "velocities tangent after the momentum projection: max "
           "|G v| = %.2g", tmax);
    tap_ok(st == DM_OK && dcube <= 1e-12, "Theorem 2.14: constrained RSPRK = projected unreduced "
           "constrained Lobatto 3 (max diff %.2g)", dcube);
    tap_ok(st == DM_OK && dcl <= 1e-12, "constrained: classical Routhian Lobatto (momentum shift) = "
           "RSPRK (max diff %.2g)", dcl);
  }
  /* order of agreement with the cylindrical chart */
  {
    double hs[3], err[3], sl;
    dm_integrator *Cy = NULL;
    for (k = 0; k < 3; k++) {
      long n = 20L << k;
      double ya[5], sa[5], xa[3], sa3[3];
      dm_routh_integrator_new(ry, "lobatto", &o, &Cy, &e);
      memcpy(ya, y, sizeof ya);
      memcpy(sa, sy, sizeof sa);
      memcpy(xa, xc, sizeof xa);
      memcpy(sa3, sc, sizeof sa3);
      hs[k] = 1.0 / (double)n;
      dm_integrator_run(I, 0, ya, sa, hs[k], n, n, NULL, NULL, NULL, NULL);
      dm_integrator_run(Cy, 0, xa, sa3, hs[k], n, n, NULL, NULL, NULL, NULL);
      err[k] = fmax(fabs(ya[0] - xa[0]), fmax(fabs(ya[2] - xa[1]), fabs(ya[3] - xa[2])));
      dm_integrator_free(Cy);
    }
    sl = dm_integrator_order_fit(hs, err, 3);
    tap_ok(fabs(sl - 4) <= 0.3, "constrained R^3 x R^3 RSPRK vs cylindrical RSPRK (Lobatto 3): "
           "difference at T = 1 shrinks with order %.2f (%.2g, %.2g, %.2g)", sl, err[0], err[1], err[2]);
  }
  dm_integrator_free(I);
  dm_integrator_free(U);
  dm_integrator_free(K);
  o.stages = 2;
  st = dm_routh_integrator_new(rc, "gauss", &o, &I, &e);
  tap_ok(st == DM_EUNSUP && I == NULL, "Gauss 2 with constraints rejected: %s", e.msg);
  dm_routh_free(rc);
  dm_routh_free(ry);
  dm_expr_ctx_free(C.c);
  dm_expr_ctx_free(Y.c);
}

/* Theorem 2.17: forcing and constraints together */
static void forced_constrained(void)
{
  const double Q4[4] = {0.6, 0.3, 0.5, 0.3}, V4[4] = {0.1, 3.3, -0.1, 0.2};
  rsys C;
  dm_routh *rc = NULL;
  dm_integrator *I = NULL, *U = NULL;
  dm_integ_opts o;
  double q6[6], v6[6], p6[6], y[5], sy[5], mu, yp[5], sp[5], mup, dmax = 0, mmax = 0, E0, E1, xd[5];
  size_t cyc = 1;
  dm_err e;
  int k, st;
  rs_dsp_constrained(&C, PV);
  C.forced = 1;
  C.F[0] = dm_expr_mul(C.c, dm_expr_const(C.c, -0.3), C.v[0]);
  C.F[1] = dm_expr_const(C.c, 0.0);
  C.F[2] = dm_expr_mul(C.c, dm_expr_const(C.c, -0.3), C.v[2]);
  C.F[3] = dm_expr_mul(C.c, dm_expr_const(C.c, -0.2), C.v[3]);
  C.F[4] = dm_expr_mul(C.c, dm_expr_const(C.c, -0.1), C.v[4]);
  C.F[5] = dm_expr_mul(C.c, dm_expr_const(C.c, -0.2), C.v[5]);
  st = rs_reduce(&C, 1, &cyc, NULL, &rc, &e);
  if (!tap_is_int(st, DM_OK, "damped R^3 x R^3 pendulum reduced on the preshape space")) {
    tap_diag("%s", e.msg);
    return;
  }
  constrained_state(Q4, V4, q6, v6);
  dm_routh_project_qv(rc, q6, v6, y, sy, &mu, NULL, &e);
  dm_routh_set_mu(rc, &mu, NULL);
  dm_integ_opts_init(&o);
  o.stages = 3;
  st = dm_routh_integrator_new(rc, "lobatto", &o, &I, &e);
  st |= dm_integrator_new(dm_routh_full(rc), "lobatto", &o, &U, &e);
  dm_integrator_momentum(U, q6, v6, p6, NULL);
  dm_integrator_velocity(I, y, sy, xd, 0, NULL);
  dm_integrator_energy(I, y, xd, &E0, NULL);
  for (k = 0; k < 200 && st == DM_OK; k++) {
    st = dm_integrator_step(I, 0.01, y, sy, y, sy, &e);
    st |= dm_integrator_step(U, 0.01, q6, p6, q6, p6, &e);
    dm_routh_project(rc, q6, p6, yp, sp, &mup, NULL, NULL);
    dmax = fmax(dmax, fmax(vdiff(y, yp, 5), vdiff(sy, sp, 5)));
    mmax = fmax(mmax, fabs(mup - mu));
  }
  dm_integrator_velocity(I, y, sy, xd, 0, NULL);
  dm_integrator_energy(I, y, xd, &E1, NULL);
  if (st != DM_OK)
    tap_diag("%s", e.msg);
  tap_ok(st == DM_OK && dmax <= 1e-12 && mmax <= 1e-13 * mu && E1 < E0 - 1e-3,
         "Theorem 2.17: forced constrained RSPRK = projected unreduced forced constrained Lobatto 3 "
         "(max diff %.2g), mu conserved (%.2g), energy %.5f -> %.5f", dmax, mmax, E0, E1);
  dm_integrator_free(I);
  dm_integrator_free(U);
  dm_routh_free(rc);
  dm_expr_ctx_free(C.c);
}

int main(void)
{
  dm_gsl_init();
  forced();
  constrained();
  forced_constrained();
  return tap_done();
}
