/* test_reduce_derive.c -- symbolic Routh reduction: the double spherical
 * pendulum's I, A, beta, V_mu against the closed forms of doc/reduce.md §14,
 * the J2 Routhian's centrifugal term (§13, symbolically and numerically),
 * set_mu without re-deriving, and the error paths (a cyclic coordinate L
 * depends on, a force with a cyclic component, a non-invariant constraint,
 * r > 3) and the numerical reduction of L with terms linear in v or not
 * quadratic in v. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "reduce/routh.h"
#include "reduce_systems.h"
#include "tap.h"

static double relerr(double got, double want)
{
  return fabs(got - want) / fmax(fabs(want), 1e-300);
}

static void dsp_closed_forms(void)
{
  const double pv[5] = {1.3, 0.8, 1.1, 0.9, 9.81}, mu = 0.537;
  const double r1 = 0.7385, r2 = 0.4127, ph = 1.234, x[3] = {r1, r2, ph};
  const double xd[3] = {0.31, -0.27, 0.45};
  double m1 = pv[0], m2 = pv[1], l1 = pv[2], l2 = pv[3], g = pv[4];
  double I, A[3], B[9], Iinv, Mt[9], thd, muA[3];
  double Ie, Ae[3], Be12, Be13, Be23, Vmu_e, worst;
  dm_routh_vals v;
  dm_routh *red = NULL;
  dm_err e;
  rsys S;
  size_t cyc = 1, i;
  int st;
  rs_dsp(&S, pv, 0);
  st = rs_reduce(&S, 1, &cyc, &mu, &red, &e);
  if (!tap_is_int(st, DM_OK, "double spherical pendulum reduced by theta1"))
    tap_diag("%s", e.msg);
  if (st != DM_OK)
    return;
  memset(&v, 0, sizeof v);
  v.I = &I; v.A = A; v.B = B; v.Iinv = &Iinv; v.Mtilde = Mt; v.thetadot = &thd; v.muA = muA;
  st = dm_routh_eval(red, x, xd, &v, &e);
  tap_is_int(st, DM_OK, "evaluation at (r1, r2, phi) = (0.7385, 0.4127, 1.234)");
  Ie = m1 * r1 * r1 + m2 * (r1 * r1 + r2 * r2 + 2 * r1 * r2 * cos(ph));
  Ae[0] = m2 / Ie * (-r2 * sin(ph));
  Ae[1] = m2 / Ie * (r1 * sin(ph));
  Ae[2] = m2 / Ie * (r2 * r2 + r1 * r2 * cos(ph));
  Be13 = -2 * mu * m1 * m2 * r1 * r2 * r2 / (Ie * Ie);
  Be23 = 2 * mu * m1 * m2 * r1 * r1 * r2 / (Ie * Ie);
  Be12 = 0.0;
  Vmu_e = -g * (m1 * sqrt(l1 * l1 - r1 * r1) + m2 * (sqrt(l1 * l1 - r1 * r1) + sqrt(l2 * l2 - r2 * r2)))
          + mu * mu / (2 * Ie);
  tap_ok(relerr(I, Ie) <= 1e-14, "locked inertia I = m1 r1^2 + m2 (r1^2 + r2^2 + 2 r1 r2 cos phi) "
         "= %.16g (rel. err %.2g)", I, relerr(I, Ie));
  worst = 0;
  for (i = 0; i < 3; i++)
    worst = fmax(worst, relerr(A[i], Ae[i]));
  tap_ok(worst <= 1e-14, "connection A = (m2/I)(-r2 sin phi, r1 sin phi, r2^2 + r1 r2 cos phi) "
         "(worst rel. err %.2g)", worst);
  tap_ok(relerr(B[2], Be13) <= 1e-14 && relerr(B[5], Be23) <= 1e-14 && fabs(B[1]) <= 1e-15
         && B[6] == -B[2] && B[7] == -B[5] && B[0] == 0 && Be12 == 0,
         "beta_mu = (2 mu m1 m2 r1 r2 / I^2)(r1 dr2 - r2 dr1) ^ dphi: B_r1phi = %.16g, "
         "B_r2phi = %.16g, B_r1r2 = %.2g (rel. errs %.2g, %.2g)", B[2], B[5], B[1],
         relerr(B[2], Be13), relerr(B[5], Be23));
  tap_ok(relerr(v.Vmu, Vmu_e) <= 1e-14, "amended potential V_mu = %.16g (rel. err %.2g)", v.Vmu,
         relerr(v.Vmu, Vmu_e));
  tap_ok(relerr(thd, mu / Ie - (Ae[0] * xd[0] + Ae[1] * xd[1] + Ae[2] * xd[2])) <= 1e-14
         && relerr(Iinv, 1 / Ie) <= 1e-14,
         "reconstruction thetadot = I^-1 mu - A xdot");
  /* Routhian = 1/2 xd^T Mt xd - V_mu, classical = R + mu A xd */
  {
    double q = 0, Rc_e;
    for (i = 0; i < 9; i++)
      q += xd[i / 3] * Mt[i] * xd[i % 3];
    tap_ok(relerr(v.R, 0.5 * q - v.Vmu) <= 1e-14, "R = 1/2 xdot^T Mtilde xdot - V_mu");
    Rc_e = v.R + mu * (Ae[0] * xd[0] + Ae[1] * xd[1] + Ae[2] * xd[2]);
    tap_ok(relerr(v.Rc, Rc_e) <= 1e-13 && relerr(muA[2], mu * Ae[2]) <= 1e-14,
           "classical Routhian Rc = R + mu^T A xdot");
  }
  /* Mtilde is the kinetic metric on the horizontal space: for the full
   * velocity v = (thetadot on J = mu with mu = 0, xdot), 1/2 v^T M v =
   * 1/2 xd^T Mt xd */
  {
    double mu0 = 0.0, K0;
    dm_routh_set_mu(red, &mu0, NULL);
    dm_routh_eval(red, x, xd, &v, NULL);
    K0 = v.R + v.V;        /* R + V = kinetic part when mu = 0 */
    tap_ok(fabs(v.Vmu - v.V) <= 1e-15 * fabs(v.V) && K0 > 0,
           "set_mu(0) without re-deriving: V_mu = V, horizontal kinetic energy %.6g > 0", K0);
    dm_routh_set_mu(red, &mu, NULL);
  }
  {
    const dm_routh_exprs *X = dm_routh_exprs_get(red);
    char *sA = dm_expr_to_string(S.c, X->A[2], 0, NULL), *sB = dm_expr_to_string(S.c, X->B[2], 0, NULL);
    tap_ok(sA && sB && strstr(sA, "m2") && strstr(sB, "mu_theta1"),
           "A and beta print as formulas: A_phi = %.120s", sA ? sA : "(null)");
    free(sA);
    free(sB);
  }
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

static void j2_centrifugal(void)
{
  const double mu = 1.1, x[2] = {1.7385, 0.4127}, xd[2] = {0.12, -0.31};
  dm_routh_vals v;
  dm_routh *red = NULL;
  dm_err e;
  rsys S;
  size_t cyc = 1;
  int st;
  rs_j2(&S, 0.05);
  st = rs_reduce(&S, 1, &cyc, &mu, &red, &e);
  if (!tap_is_int(st, DM_OK, "J2 satellite reduced by theta"))
    tap_diag("%s", e.msg);
  if (st != DM_OK)
    return;
  {
    const dm_routh_exprs *X = dm_routh_exprs_get(red);
    /* symbolic: V_mu - V is exactly mu^2 / (2 r^2), i.e. the amended term
     * does not depend on z and its second mu-derivative is 1/r^2 */
    dm_expr d1 = dm_expr_diff(S.c, X->Vmu, X->mu[0]);
    dm_expr d2 = dm_expr_diff(S.c, d1, X->mu[0]);
    dm_expr want = dm_expr_div(S.c, dm_expr_const(S.c, 1.0), dm_expr_powi(S.c, S.q[0], 2));
    char *s1 = dm_expr_to_string(S.c, d1, 0, NULL), *s2 = dm_expr_to_string(S.c, X->R, 0, NULL);
    char *s3 = dm_expr_to_string(S.c, d2, 0, NULL);
    tap_ok(!dm_expr_depends(S.c, d1, 1, &S.q[2]) && dm_expr_depends(S.c, X->R, 1, &X->mu[0])
           && d2 == want,
           "symbolic: R contains the centrifugal term mu^2/(2 r^2): dV_mu/dmu = %s, d2V_mu/dmu2 = %s",
           s1, s3);
    tap_diag("R^mu = %s", s2);
    tap_ok(X->A[0] != DM_EXPR_NONE && dm_expr_is_const(S.c, X->A[0], NULL)
           && dm_expr_is_const(S.c, X->B[1], NULL),
           "J2: A = 0 and beta = 0 symbolically");
    free(s1);
    free(s2);
    free(s3);
  }
  memset(&v, 0, sizeof v);
  dm_routh_eval(red, x, xd, &v, NULL);
  {
    double r = x[0], z = x[1], R = hypot(r, z), J2 = 0.05;
    double V = -1 / R + J2 / (R * R * R) * (1.5 * z * z / (R * R) - 0.5);
    double Re = 0.5 * (xd[0] * xd[0] + xd[1] * xd[1]) - V - mu * mu / (2 * r * r);
    tap_ok(relerr(v.R, Re) <= 1e-14, "numeric: R = 1/2 (rd^2 + zd^2) - V - mu^2/(2 r^2) = %.16g "
           "(rel. err %.2g)", v.R, relerr(v.R, Re));
  }
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

static void errors(void)
{
  rsys S;
  dm_routh *red = NULL;
  dm_err e;
  size_t cyc;
  int st;
  /* z is not cyclic for J2 */
  rs_j2(&S, 0.05);
  cyc = 2;
  st = rs_reduce(&S, 1, &cyc, NULL, &red, &e);
  tap_ok(st == DM_EINVAL && red == NULL && strstr(e.msg, "'z' is not a cyclic coordinate")
         && strstr(e.msg, "dL/dz = "), "L depends on z: %s", e.msg);
  /* force with a cyclic component */
  {
    dm_routh_spec sp;
    dm_expr F[3];
    size_t c1 = 1;
    F[0] = dm_expr_const(S.c, 0.0);
    F[1] = dm_expr_mul(S.c, dm_expr_const(S.c, -0.2), S.v[1]);
    F[2] = dm_expr_const(S.c, 0.0);
    memset(&sp, 0, sizeof sp);
    sp.n = 3; sp.q = S.q; sp.v = S.v; sp.npar = 1; sp.par = S.par; sp.par_values = S.pv;
    sp.L = S.L; sp.force = F; sp.r = 1; sp.cyclic = &c1;
    st = dm_routh_derive(S.c, &sp, &red, &e);
    tap_ok(st == DM_EINVAL && strstr(e.msg, "cyclic coordinate 'theta'") && strstr(e.msg, "thetad"),
           "force with a cyclic component: %s", e.msg);
    /* a force depending on theta */
    F[1] = dm_expr_const(S.c, 0.0);
    F[0] = dm_expr_call(S.c, "sin", 1, &S.q[1]);
    st = dm_routh_derive(S.c, &sp, &red, &e);
    tap_ok(st == DM_EINVAL && strstr(e.msg, "invariant"), "force depending on theta: %s", e.msg);
    /* constraint depending on theta */
    sp.force = NULL;
    sp.m = 1;
    F[0] = dm_expr_sub(S.c, S.q[1], S.q[0]);
    sp.constraints = F;
    st = dm_routh_derive(S.c, &sp, &red, &e);
    tap_ok(st == DM_EINVAL && strstr(e.msg, "constraint 1"), "constraint depending on theta: %s",
           e.msg);
    sp.m = 0;
    sp.constraints = NULL;
    /* terms linear in v, and a term rdot^4: no longer refused, reduced
     * numerically (J = mu solved for thetadot); compare with the hand
     * solutions thetadot = (mu - r)/r^2 and mu/r^2 */
    {
      const double x[2] = {1.7385, 0.4127}, xd[2] = {0.12, -0.31}, mu1 = 1.1;
      double r = x[0], z = x[1], R = hypot(r, z), J2 = 0.05, thd, Rc_e, w[1];
      double V = -1 / R + J2 / (R * R * R) * (1.5 * z * z / (R * R) - 0.5);
      dm_routh_vals v;
      int k;
      sp.mu = &mu1;
      for (k = 0; k < 2; k++) {
        sp.L = k == 0 ? dm_expr_add(S.c, S.L, dm_expr_mul(S.c, S.q[0], S.v[1]))
                      : dm_expr_add(S.c, S.L, dm_expr_powi(S.c, S.v[0], 4));
        st = dm_routh_derive(S.c, &sp, &red, &e);
        memset(&v, 0, sizeof v);
        v.thetadot = w;
        if (st == DM_OK)
          st = dm_routh_eval(red, x, xd, &v, &e);
        thd = k == 0 ? (mu1 - r) / (r * r) : mu1 / (r * r);
        Rc_e = 0.5 * (xd[0] * xd[0] + r * r * thd * thd + xd[1] * xd[1]) - V - mu1 * thd
               + (k == 0 ? r * thd : pow(xd[0], 4));
        tap_ok(st == DM_OK && !dm_routh_is_mechanical(red) && relerr(w[0], thd) <= 1e-15
               && relerr(v.Rc, Rc_e) <= 1e-14,
               "%s: reduced numerically, thetadot %.17g (hand %.17g), Rc %.17g (hand %.17g)",
               k == 0 ? "terms linear in v" : "rdot^4 (not quadratic)", w[0], thd, v.Rc, Rc_e);
        if (st != DM_OK)
          tap_diag("%s", e.msg);
        dm_routh_free(red);
        red = NULL;
      }
      sp.mu = NULL;
    }
    /* r out of range */
    sp.L = S.L;
    sp.r = 3;
    {
      size_t c3[3] = {0, 1, 2};
      sp.cyclic = c3;
      st = dm_routh_derive(S.c, &sp, &red, &e);
      tap_ok(st == DM_EINVAL && red == NULL, "r = n cyclic coordinates rejected: %s", e.msg);
    }
  }
  dm_expr_ctx_free(S.c);
}

int main(void)
{
  dm_gsl_init();
  dsp_closed_forms();
  j2_centrifugal();
  errors();
  return tap_done();
}
