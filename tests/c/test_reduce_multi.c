/* test_reduce_multi.c -- reduction by r = 2 and r = 3 cyclic coordinates
 * (symbolic adjugate inverses of the locked inertia, vector mu): a
 * mechanical L = 1/2 |N(x) qdot|^2 + eps/2 |qdot|^2 - V(x) with a generic
 * shape-dependent N (every block of the mass matrix non-zero), s = 2 shape
 * coordinates.  Checks the commutative cube (unreduced Gauss 2 projected =
 * RSPRK, reconstructed theta = unreduced theta), the momentum shift
 * (classical), DR = RSPRK, the non-canonical defect, I A = M_theta,x and
 * I I^-1 = Id at a point, and the derivation errors for r > 3. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "reduce/routh.h"
#include "reduce_systems.h"
#include "tap.h"

static double vdiff(const double *a, const double *b, size_t n)
{
  double m = 0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* q = (theta_1..theta_r, x1, x2) */
static void build(rsys *S, size_t r)
{
  static const char *qn[] = {"t1", "t2", "t3", "t4", "x1", "x2"};
  static const char *vn[] = {"w1", "w2", "w3", "w4", "u1", "u2"};
  const char *q6[6], *v6[6];
  size_t n = r + 2, k, j;
  dm_expr x1, x2, T, V;
  for (k = 0; k < r; k++) {
    q6[k] = qn[k];
    v6[k] = vn[k];
  }
  q6[r] = "x1"; q6[r + 1] = "x2"; v6[r] = "u1"; v6[r + 1] = "u2";
  rs_syms(S, n, q6, v6, 0, NULL, NULL);
  x1 = S->q[r];
  x2 = S->q[r + 1];
  T = RC(0.0);
  for (k = 0; k < n; k++) {
    dm_expr row = RC(0.0);
    for (j = 0; j < n; j++) {
      dm_expr Nkj = RADD(RC(k == j ? 1.0 : 0.0),
                         RADD(RMUL(RC(0.3), RF("sin", RADD(x1, RC((double)(k + 2 * j))))),
                              RMUL(RMUL(RC(0.2), x2), RF("cos", RADD(RC((double)(k * j)), x1)))));
      row = RADD(row, RMUL(Nkj, S->v[j]));
    }
    T = RADD(T, RADD(RSQ(row), RMUL(RC(0.1), RSQ(S->v[k]))));
  }
  V = RADD(RMUL(RC(0.5), RADD(RSQ(x1), RSQ(x2))), RMUL(RC(0.1), dm_expr_powi(S->c, x1, 4)));
  S->L = RSUB(RMUL(RC(0.5), T), V);
}

static void run_r(size_t r)
{
  rsys S;
  dm_routh *red = NULL;
  dm_err e;
  size_t cyc[4] = {0, 1, 2, 3}, n = r + 2, i, j, k;
  double q0[6], v0[6], x0[2], s0[2], mu[3], th0[3];
  int st;
  build(&S, r);
  for (i = 0; i < n; i++) {
    q0[i] = i < r ? 0.1 * (double)(i + 1) : (i == r ? 0.43 : -0.27);
    v0[i] = 0.7 - 0.35 * (double)i;
  }
  st = rs_reduce(&S, r, cyc, NULL, &red, &e);
  if (!tap_is_int(st, DM_OK, "r = %zu: derived", r)) {
    tap_diag("%s", e.msg);
    return;
  }
  dm_routh_project_qv(red, q0, v0, x0, s0, mu, th0, &e);
  dm_routh_set_mu(red, mu, NULL);
  {
    /* I A = M_theta,x and I Iinv = Id at x0 */
    const dm_routh_exprs *X = dm_routh_exprs_get(red);
    double I[9], Ii[9], A[6], w[3], worst = 0, worst2 = 0, M[36];
    dm_routh_vals v;
    dm_expr *vars = malloc(n * sizeof *vars);
    memset(&v, 0, sizeof v);
    v.I = I; v.Iinv = Ii; v.A = A; v.Iinv_mu = w;
    dm_routh_eval(red, x0, NULL, &v, NULL);
    for (i = 0; i < n; i++)
      vars[i] = S.q[i];
    dm_expr_eval(S.c, n * n, X->M, M, n, vars, q0, NULL);
    free(vars);
    for (i = 0; i < r; i++)
      for (j = 0; j < 2; j++) {
        double acc = 0;
        for (k = 0; k < r; k++)
          acc += I[i * r + k] * A[k * 2 + j];
        worst = fmax(worst, fabs(acc - M[i * n + r + j]));
      }
    for (i = 0; i < r; i++)
      for (j = 0; j < r; j++) {
        double acc = 0;
        for (k = 0; k < r; k++)
          acc += I[i * r + k] * Ii[k * r + j];
        worst2 = fmax(worst2, fabs(acc - (i == j)));
      }
    tap_ok(worst <= 1e-14 && worst2 <= 1e-14, "r = %zu: I A = M_theta,x (%.2g), I I^-1 = Id (%.2g) "
           "with the symbolic adjugate", r, worst, worst2);
  }
  {
    dm_integ_opts o;
    dm_integrator *R = NULL, *C = NULL, *D = NULL, *F = NULL;
    double x[2], s[2], xc[2], sc[2], xd[2], sd[2], q[6], p[6], xp[2], sp[2], mup[3], thp[3];
    double th[3], dcube = 0, dth = 0, dcl = 0, ddr = 0, def = 1;
    dm_integ_opts_init(&o);
    o.stages = 2;
    st = dm_routh_integrator_new(red, "gauss", &o, &R, &e);
    st |= dm_routh_integrator_new(red, "classical", &o, &C, &e);
    st |= dm_routh_integrator_new(red, "dr:gauss", &o, &D, &e);
    st |= dm_integrator_new(dm_routh_full(red), "gauss", &o, &F, &e);
    dm_routh_integrator_set_theta(R, th0, NULL);
    memcpy(x, x0, sizeof x); memcpy(s, s0, sizeof s);
    memcpy(xc, x0, sizeof x); memcpy(sc, s0, sizeof s);
    memcpy(xd, x0, sizeof x); memcpy(sd, s0, sizeof s);
    memcpy(q, q0, sizeof q);
    dm_integrator_momentum(F, q0, v0, p, NULL);
    for (k = 0; k < 200 && st == DM_OK; k++) {
      st = dm_integrator_step(R, 0.02, x, s, x, s, &e);
      st |= dm_integrator_step(C, 0.02, xc, sc, xc, sc, &e);
      st |= dm_integrator_step(D, 0.02, xd, sd, xd, sd, &e);
      st |= dm_integrator_step(F, 0.02, q, p, q, p, &e);
      dm_routh_project(red, q, p, xp, sp, mup, thp, NULL);
      dm_routh_integrator_theta(R, th, NULL);
      dcube = fmax(dcube, fmax(vdiff(x, xp, 2), vdiff(s, sp, 2)));
      dth = fmax(dth, vdiff(th, thp, r));
      dcl = fmax(dcl, fmax(vdiff(x, xc, 2), vdiff(s, sc, 2)));
      ddr = fmax(ddr, fmax(vdiff(x, xd, 2), vdiff(s, sd, 2)));
    }
    if (st != DM_OK)
      tap_diag("%s", e.msg);
    tap_ok(st == DM_OK && dcube <= 1e-12 && dth <= 1e-12, "r = %zu: commutative cube over 200 steps: "
           "(x, s) %.2g, theta %.2g", r, dcube, dth);
    tap_ok(st == DM_OK && dcl <= 1e-12 && ddr <= 1e-12, "r = %zu: classical (momentum shift) %.2g and "
           "DR Galerkin-Gauss 2 %.2g equal RSPRK", r, dcl, ddr);
    dm_routh_symplecticity_defect(R, 0.05, x0, s0, &def, NULL);
    tap_ok(def <= 1e-10, "r = %zu: non-canonical symplecticity defect %.2g", r, def);
    dm_integrator_free(R);
    dm_integrator_free(C);
    dm_integrator_free(D);
    dm_integrator_free(F);
  }
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

int main(void)
{
  rsys S;
  dm_routh *red = NULL;
  dm_err e;
  size_t cyc[4] = {0, 1, 2, 3};
  int st;
  dm_gsl_init();
  run_r(2);
  run_r(3);
  build(&S, 4);
  st = rs_reduce(&S, 4, cyc, NULL, &red, &e);
  tap_ok(st == DM_EUNSUP && red == NULL && strstr(e.msg, "at most 3"), "r = 4 refused: %s", e.msg);
  dm_expr_ctx_free(S.c);
  return tap_done();
}
