/* test_reduce_rsprk.c -- RSPRK on the double spherical pendulum (a
 * non-trivial connection and magnetic term; doc/reduce.md §9):
 *  1. momentum shift: sigma(RSPRK) = SPRK of the classical Routhian, both
 *     as the core engine on Rc directly and through the wrapped method;
 *  2. commutative cube: the unreduced SPRK started on J = mu, projected,
 *     equals RSPRK; the reconstructed theta equals the unreduced theta;
 *  3. order of RSPRK with Gauss s = 1, 2, 3 (fitted slope within 0.1);
 *  4. non-canonical symplecticity defect <= 1e-10 (and the canonical one is
 *     not small: the magnetic term matters);
 *  5. reconstruct() of a sampled reduced run, phase split, error path
 *     (singular inertia during a run keeps the partial trajectory);
 *  6. the stage programs (white box, routh_impl.h): one call per stage gives
 *     R^mu's derivatives and the reduced force bit for bit as the reduced
 *     system's callbacks, muA, kv, ib as gyro_r, K, dkv, dib as differences
 *     of muA, kv, ib, B = K^T - K; a stage leaving the domain of R^mu names
 *     the Routhian. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "core/trajectory.h"
#include "reduce/routh.h"
#include "reduce/routh_impl.h"
#include "reduce_systems.h"
#include "tap.h"

static const double PV[5] = {1.3, 0.8, 1.1, 0.9, 9.81};
/* full initial state (r1, theta1, r2, phi) and velocities: a quasi-periodic
 * motion near the steady conical rotation */
static const double Q0[4] = {0.6, 0.3, 0.5, 0.3}, V0[4] = {0.1, 3.3, -0.1, 0.2};

static dm_routh *make(rsys *S, double *x0, double *s0, double *mu)
{
  dm_routh *red = NULL;
  dm_err e;
  size_t cyc = 1;
  rs_dsp(S, PV, 0);
  if (rs_reduce(S, 1, &cyc, NULL, &red, &e) != DM_OK) {
    tap_diag("derive: %s", e.msg);
    return NULL;
  }
  if (dm_routh_project_qv(red, Q0, V0, x0, s0, mu, NULL, &e) != DM_OK)
    tap_diag("project: %s", e.msg);
  dm_routh_set_mu(red, mu, NULL);
  return red;
}

static double vdiff(const double *a, const double *b, size_t n)
{
  double m = 0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

static void shift_and_cube(void)
{
  rsys S;
  double x0[3], s0[3], mu, x[3], s[3], xc[3], sc[3], y[3], xk[3], yk[3], q[4], p[4], th;
  double dshift = 0, dwrap = 0, dcube = 0, dth = 0, dmu = 0, a[3], pf[4];
  dm_integ_opts o;
  dm_integrator *R = NULL, *C = NULL, *W = NULL, *F = NULL;
  dm_routh *red = make(&S, x0, s0, &mu);
  dm_err e;
  int k, st = DM_OK;
  if (red == NULL)
    return;
  dm_integ_opts_init(&o);
  o.stages = 2;
  st |= dm_routh_integrator_new(red, "gauss", &o, &R, &e);
  st |= dm_routh_integrator_new(red, "classical", &o, &W, &e);
  st |= dm_integrator_new(dm_routh_classical(red), "gauss", &o, &C, &e);
  st |= dm_integrator_new(dm_routh_full(red), "gauss", &o, &F, &e);
  if (!tap_ok(st == DM_OK, "RSPRK, wrapped classical, core SPRK on Rc and on the full system")) {
    tap_diag("%s", e.msg);
    return;
  }
  memcpy(x, x0, sizeof x);
  memcpy(s, s0, sizeof s);
  memcpy(xc, x0, sizeof x);
  memcpy(sc, s0, sizeof s);
  /* y0 = s0 + muA(x0): lift and read p_x */
  dm_routh_lift(red, NULL, x0, s0, q, p, NULL);
  y[0] = p[0];              /* shape momenta of the full p: indices 0, 2, 3 */
  y[1] = p[2];
  y[2] = p[3];
  memcpy(xk, x0, sizeof xk);
  memcpy(yk, y, sizeof yk);
  memcpy(q, Q0, sizeof q);
  dm_integrator_momentum(F, Q0, V0, pf, NULL);
  for (k = 0; k < 400 && st == DM_OK; k++) {
    double xp[3], sp[3], thr;
    st |= dm_integrator_step(R, 0.01, x, s, x, s, &e);
    st |= dm_integrator_step(W, 0.01, xc, sc, xc, sc, &e);
    st |= dm_integrator_step(C, 0.01, xk, yk, xk, yk, &e);
    st |= dm_integrator_step(F, 0.01, q, pf, q, pf, &e);
    if (st != DM_OK)
      break;
    /* sigma(x, s) = (x, s + muA(x)) against the SPRK of Rc */
    dm_routh_lift(red, NULL, x, s, NULL, p, NULL);
    a[0] = p[0]; a[1] = p[2]; a[2] = p[3];
    dshift = fmax(dshift, fmax(vdiff(x, xk, 3), vdiff(a, yk, 3)));
    dwrap = fmax(dwrap, fmax(vdiff(x, xc, 3), vdiff(s, sc, 3)));
    /* cube: project the unreduced state */
    dm_routh_project(red, q, pf, xp, sp, &thr, &th, NULL);
    dcube = fmax(dcube, fmax(vdiff(x, xp, 3), vdiff(s, sp, 3)));
    dmu = fmax(dmu, fabs(thr - mu));
    dm_routh_integrator_theta(R, &thr, NULL);
    dth = fmax(dth, fabs(thr + Q0[1] - th));
    dm_routh_integrator_theta(W, &thr, NULL);
    dth = fmax(dth, fabs(thr + Q0[1] - th));
  }
  if (st != DM_OK)
    tap_diag("step: %s", e.msg);
  tap_ok(st == DM_OK && dshift <= 1e-12,
         "momentum shift: sigma(RSPRK) = SPRK on the classical Routhian over 400 steps (max diff %.2g)",
         dshift);
  tap_ok(st == DM_OK && dwrap <= 1e-12, "method 'classical' (wrapped by sigma) = RSPRK (max diff %.2g)",
         dwrap);
  tap_ok(st == DM_OK && dcube <= 1e-12,
         "commutative cube: projected unreduced Gauss 2 = RSPRK on (x, s) (max diff %.2g)", dcube);
  tap_ok(st == DM_OK && dth <= 1e-12,
         "commutative cube: reconstructed theta (RSPRK Hamiltonian side, classical psi_mu) = "
         "unreduced theta (max diff %.2g)", dth);
  tap_ok(dmu <= 1e-13 * fabs(mu), "unreduced SPRK conserves J = mu = %.15g (drift %.2g)", mu, dmu);
  dm_integrator_free(R);
  dm_integrator_free(W);
  dm_integrator_free(C);
  dm_integrator_free(F);
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

static void orders_and_defect(void)
{
  rsys S;
  double x0[3], s0[3], mu, xr[3], sr[3];
  dm_integ_opts o;
  dm_routh *red = make(&S, x0, s0, &mu);
  dm_integrator *I = NULL;
  dm_err e;
  int stages;
  if (red == NULL)
    return;
  dm_integ_opts_init(&o);
  /* reference at T = 1: Gauss 4, h = 1/400 */
  o.stages = 4;
  dm_routh_integrator_new(red, "gauss", &o, &I, &e);
  memcpy(xr, x0, sizeof xr);
  memcpy(sr, s0, sizeof sr);
  dm_integrator_run(I, 0, xr, sr, 1.0 / 400, 400, 400, NULL, NULL, NULL, NULL);
  dm_integrator_free(I);
  for (stages = 1; stages <= 3; stages++) {
    double hs[4], err[4], slope, def = 0, cdef = 0;
    int k;
    o.stages = stages;
    dm_routh_integrator_new(red, "gauss", &o, &I, &e);
    for (k = 0; k < 4; k++) {
      long n = (stages == 1 ? 20 : 10) << k;
      double x[3], s[3];
      memcpy(x, x0, sizeof x);
      memcpy(s, s0, sizeof s);
      hs[k] = 1.0 / (double)n;
      dm_integrator_run(I, 0, x, s, hs[k], n, n, NULL, NULL, NULL, NULL);
      err[k] = fmax(vdiff(x, xr, 3), vdiff(s, sr, 3));
    }
    slope = dm_integrator_order_fit(hs, err, 4);
    tap_ok(fabs(slope - 2 * stages) <= 0.1, "RSPRK Gauss s = %d: fitted order %.3f (errors %.2g .. %.2g)",
           stages, slope, err[0], err[3]);
    dm_routh_symplecticity_defect(I, 0.05, x0, s0, &def, &e);
    dm_integrator_symplecticity_defect(I, 0.05, x0, s0, &cdef, NULL);
    tap_ok(def <= 1e-10 && cdef > 1e-4,
           "RSPRK Gauss s = %d preserves Omega_S - beta_mu: non-canonical defect %.2g (canonical "
           "defect %.2g: not symplectic for dx^ds alone)", stages, def, cdef);
    dm_integrator_free(I);
  }
  {
    double def = 1;
    o.stages = 3;
    dm_routh_integrator_new(red, "lobatto", &o, &I, &e);
    dm_routh_symplecticity_defect(I, 0.05, x0, s0, &def, &e);
    tap_ok(def <= 1e-10, "RSPRK Lobatto IIIA-IIIB s = 3: non-canonical defect %.2g", def);
    dm_integrator_free(I);
    o.stages = 2;
    dm_routh_integrator_new(red, "classical", &o, &I, &e);
    def = 1;
    dm_routh_symplecticity_defect(I, 0.05, x0, s0, &def, &e);
    tap_ok(def <= 1e-10, "classical Routhian SPRK pulled back by sigma: non-canonical defect %.2g", def);
    dm_integrator_free(I);
  }
  /* energy of the reduced system bounded over a long run */
  {
    double x[3], s[3], v[3], E0, E, worst = 0;
    long k;
    o.stages = 2;
    dm_routh_integrator_new(red, "gauss", &o, &I, &e);
    memcpy(x, x0, sizeof x);
    memcpy(s, s0, sizeof s);
    dm_integrator_velocity(I, x, s, v, 0, NULL);
    dm_integrator_energy(I, x, v, &E0, NULL);
    for (k = 0; k < 20; k++) {
      dm_integrator_run(I, 0, x, s, 0.02, 500, 500, NULL, NULL, NULL, NULL);
      dm_integrator_velocity(I, x, s, v, 0, NULL);
      dm_integrator_energy(I, x, v, &E, NULL);
      worst = fmax(worst, fabs((E - E0) / E0));
    }
    tap_ok(worst < 1e-7, "RSPRK Gauss 2, h = 0.02, 10^4 steps: reduced energy H_mu bounded "
           "(max rel. error %.2g)", worst);
    dm_integrator_free(I);
  }
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

static void reconstruct_and_phase(void)
{
  rsys S;
  double x0[3], s0[3], mu, th0 = 0.3, thr, q[4], p[4];
  dm_integ_opts o;
  dm_routh *red = make(&S, x0, s0, &mu);
  dm_integrator *I = NULL, *J = NULL, *F = NULL;
  dm_traj *rt, *full = NULL;
  dm_err e;
  int st;
  if (red == NULL)
    return;
  dm_integ_opts_init(&o);
  o.stages = 2;
  dm_routh_integrator_new(red, "gauss", &o, &I, &e);
  dm_routh_integrator_new(red, "gauss", &o, &J, &e);
  dm_integrator_new(dm_routh_full(red), "gauss", &o, &F, &e);
  rt = dm_traj_alloc(3, dm_routh_system(red)->coords, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL);
  {
    double x[3], s[3];
    memcpy(x, x0, sizeof x);
    memcpy(s, s0, sizeof s);
    st = dm_integrator_run(I, 0, x, s, 0.01, 300, 10, dm_traj_sink, rt, NULL, &e);
  }
  st |= dm_routh_reconstruct(red, J, 0.01, rt, &th0, &full, &e);
  if (!tap_ok(st == DM_OK && full && dm_traj_len(full) == 31, "reconstruct 31 samples (every 10 "
              "steps) into the full trajectory"))
    tap_diag("%s", e.msg);
  if (full) {
    double pf[4], dq = 0, dp = 0, qq[4], pp[4], t;
    size_t k;
    memcpy(q, Q0, sizeof q);
    q[1] = th0;
    dm_integrator_momentum(F, q, V0, pf, NULL);
    for (k = 0; k < 31; k++) {
      if (k)
        dm_integrator_run(F, 0, q, pf, 0.01, 10, 10, NULL, NULL, NULL, NULL);
      dm_traj_get(full, k, &t, qq, pp, NULL, NULL);
      dq = fmax(dq, vdiff(qq, q, 4));
      dp = fmax(dp, vdiff(pp, pf, 4));
    }
    tap_ok(dq <= 1e-12 && dp <= 1e-12, "reconstructed full trajectory = unreduced Gauss 2 from "
           "theta0 = 0.3 (max diff q %.2g, p %.2g)", dq, dp);
    dm_traj_free(full);
  }
  /* phase: dyn + geo is the midpoint reconstruction (for a closed loop the
   * split is the classical dynamic + geometric phase); check the identity
   * dyn + geo = sum psi_mu^midpoint along the sampled curve */
  {
    double dyn, geo, gap, sum = 0, psi, xa[3], xb[3];
    dm_routh_dr *dr = NULL;
    size_t k;
    st = dm_routh_phase(red, rt, &dyn, &geo, &gap, &e);
    dm_routh_dr_alloc(red, NULL, 0, 0, &dr, NULL);
    for (k = 0; k + 1 < dm_traj_len(rt); k++) {
      double t0, t1;
      dm_traj_get(rt, k, &t0, xa, NULL, NULL, NULL);
      dm_traj_get(rt, k + 1, &t1, xb, NULL, NULL, NULL);
      dm_routh_dr_psi(dr, t1 - t0, xa, xb, &psi, NULL, NULL);
      sum += psi;
    }
    tap_ok(st == DM_OK && fabs(dyn + geo - sum) <= 1e-13 && fabs(geo) > 1e-3 && gap > 0,
           "phase split: dynamic %.6f + geometric %.6f = midpoint reconstruction %.6f (gap %.3g)",
           dyn, geo, sum, gap);
    dm_routh_dr_free(dr);
  }
  /* Stokes: over a small circle of radius eps in the (r2, phi) plane,
   * mu * (geometric phase) = -B_r2phi(center) pi eps^2 + O(eps^4) */
  {
    const double c[3] = {0.55, 0.45, 0.4}, eps = 1e-2;
    double dyn, geo, gap, B[9], t, x[3], w;
    dm_traj *loop = dm_traj_alloc(3, NULL, 0, NULL);
    dm_routh_vals v;
    size_t k, N = 2000;
    for (k = 0; k <= N; k++) {
      t = 2 * M_PI * (double)k / (double)N;
      x[0] = c[0];
      x[1] = c[1] + eps * cos(t);
      x[2] = c[2] + eps * sin(t);
      dm_traj_append(loop, t, x, NULL, NULL, NULL, NULL);
    }
    memset(&v, 0, sizeof v);
    v.B = B;
    v.Iinv_mu = &w;
    dm_routh_eval(red, c, NULL, &v, NULL);
    st = dm_routh_phase(red, loop, &dyn, &geo, &gap, &e);
    tap_ok(st == DM_OK && gap < 1e-15 && fabs(mu * geo + B[5] * M_PI * eps * eps) <= 1e-4 * fabs(B[5] * M_PI * eps * eps)
           && fabs(dyn - 2 * M_PI * w) <= 1e-4 * fabs(dyn),
           "closed loop: mu * geometric phase %.10g = -B_r2phi pi eps^2 = %.10g (Stokes), dynamic "
           "phase %.8g ~ 2 pi I^-1 mu", mu * geo, -B[5] * M_PI * eps * eps, dyn);
    dm_traj_free(loop);
  }
  dm_routh_integrator_theta(I, &thr, NULL);
  (void)p;
  dm_traj_free(rt);
  dm_integrator_free(I);
  dm_integrator_free(J);
  dm_integrator_free(F);
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

/* free particle in the plane in polar coordinates, mu = 0, heading through
 * the origin: I = r^2 -> 0 */
static void singular_run(void)
{
  static const char *qn[] = {"r", "th"}, *vn[] = {"rd", "thd"};
  rsys S;
  dm_routh *red = NULL;
  dm_integrator *I = NULL;
  dm_traj *tr;
  dm_run_info info;
  dm_err e;
  size_t cyc = 1;
  double mu = 0.0, x = 0.3, s = -1.0;
  int st;
  rs_syms(&S, 2, qn, vn, 0, NULL, NULL);
  S.L = dm_expr_mul(S.c, dm_expr_const(S.c, 0.5),
                    dm_expr_add(S.c, dm_expr_powi(S.c, S.v[0], 2),
                                dm_expr_mul(S.c, dm_expr_powi(S.c, S.q[0], 2),
                                            dm_expr_powi(S.c, S.v[1], 2))));
  rs_reduce(&S, 1, &cyc, &mu, &red, &e);
  dm_routh_integrator_new(red, "midpoint", NULL, &I, &e);
  tr = dm_traj_alloc(1, NULL, DM_TRAJ_WITH_P, NULL);
  st = dm_integrator_run(I, 0, &x, &s, 0.1, 10, 1, dm_traj_sink, tr, &info, &e);
  tap_ok(st == DM_ESINGULAR && strstr(e.msg, "locked inertia") && info.steps == 2
         && dm_traj_len(tr) == 3 && fabs(x - 0.1) < 1e-15,
         "singular locked inertia during a run: DM_ESINGULAR after %ld steps, %zu samples kept: %s",
         info.steps, dm_traj_len(tr), e.msg);
  dm_traj_free(tr);
  dm_integrator_free(I);
  dm_routh_free(red);
  dm_expr_ctx_free(S.c);
}

/* The arrays of one stage-program call at (x, v), into buf */
static int stage_call(const dm_routh *red, int jac, const double *x, const double *v, double *buf,
                      double **o, double *work)
{
  const double *in[2] = {x, v};
  size_t k;
  for (k = 0; k < DM_RS_NARR; k++)
    o[k] = buf + k * 16;
  memset(buf, 0, DM_RS_NARR * 16 * sizeof *buf);
  return dm_bundle_run(jac ? &red->stage_j : &red->stage_r, in, red->s, red->par, o, ~0u, work);
}

static int same(const double *a, const double *b, size_t n)
{
  return memcmp(a, b, n * sizeof *a) == 0;
}

static void stage_programs(void)
{
  static const double PF[6] = {1.3, 0.8, 1.1, 0.9, 9.81, 0.37};
  const double x[3] = {0.61, 0.47, 0.29}, v[3] = {0.23, -0.41, 0.37}, dlt = 1e-6;
  double *work = NULL, br[DM_RS_NARR * 16], bj[DM_RS_NARR * 16], bp[DM_RS_NARR * 16];
  double bm[DM_RS_NARR * 16], *o[DM_RS_NARR], *oj[DM_RS_NARR], *op[DM_RS_NARR], *om[DM_RS_NARR];
  double tin[6], tout[64], muA[3], Lq[3], Lv[3], Lvv[9], Lvq[9], Lqq[9], F[3], Fq[9], Fv[9];
  int forced;
  for (forced = 0; forced < 2; forced++) {
    rsys S;
    dm_routh *red = NULL;
    dm_err e;
    size_t cyc = 1, a, b;
    double mu = 1.73, dK = 0, dB = 0, dkv = 0, dd = 0, dg = 0;
    const dm_system *rs;
    const char *tag = forced ? "forced dsp (tapes):" : "dsp (native when available):";
    dm_lag_out lo = {0, Lq, Lv, Lvv, Lvq, Lqq};
    int bad;
    rs_dsp(&S, PF, forced);
    /* native code (when a compiler works) for one, tapes for the other */
    if (!tap_ok(rs_reduce_native(&S, 1, &cyc, &mu, forced ? DM_NATIVE_NEVER : DM_NATIVE_AUTO,
                                 &red, &e) == DM_OK, "%s derive", tag)) {
      tap_diag("%s", e.msg);
      dm_expr_ctx_free(S.c);
      continue;
    }
    rs = &red->rsys;
    work = malloc((red->nwork + 8) * sizeof *work);
    bad = stage_call(red, 0, x, v, br, o, work) | stage_call(red, 1, x, v, bj, oj, work);
    rs->lagrangian(rs->data, x, v, red->par, DM_LAG_Q | DM_LAG_V, &lo, work);
    tap_ok(!bad && same(o[DM_RS_LQ], Lq, 3) && same(o[DM_RS_LV], Lv, 3),
           "%s gradient program: R_x, R_v bit for bit as the reduced system", tag);
    rs->lagrangian(rs->data, x, v, red->par, DM_LAG_ALL, &lo, work);
    tap_ok(same(oj[DM_RS_LQ], Lq, 3) && same(oj[DM_RS_LV], Lv, 3) && same(oj[DM_RS_LVV], Lvv, 9)
           && same(oj[DM_RS_LVQ], Lvq, 9) && same(oj[DM_RS_LQQ], Lqq, 9),
           "%s full program: R_x, R_v, R_vv, R_vx, R_xx bit for bit", tag);
    if (forced) {
      rs->force(rs->data, x, v, red->par, DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V, F, Fq, Fv, work);
      tap_ok(same(o[DM_RS_F], F, 3) && same(oj[DM_RS_F], F, 3) && same(oj[DM_RS_FQ], Fq, 9)
             && same(oj[DM_RS_FV], Fv, 9), "%s Fhat, Fhat_x, Fhat_v bit for bit as the "
             "reduced force (%.4g %.4g %.4g)", tag, F[0], F[1], F[2]);
    }
    memcpy(tin, x, sizeof x);
    memcpy(tin + 3, v, sizeof v);
    dm_rprog_run(&red->gyro_r, tin, red->par, tout, work);
    tap_ok(same(o[DM_RS_MUA], tout, 3) && same(o[DM_RS_KV], tout + 3, 3)
           && same(o[DM_RS_IB], tout + 6, 3) && vdiff(oj[DM_RS_MUA], tout, 3) <= 4e-15
           && vdiff(oj[DM_RS_KV], tout + 3, 3) <= 4e-15 && vdiff(oj[DM_RS_IB], tout + 6, 3) <= 4e-15,
           "%s muA, kv, ib as gyro_r (gradient: bit for bit; full: %.2g)", tag,
           fmax(vdiff(oj[DM_RS_KV], tout + 3, 3), vdiff(oj[DM_RS_IB], tout + 6, 3)));
    /* derivatives in x by central differences of the gradient program */
    for (b = 0; b < 3; b++) {
      double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
      xp[b] += dlt;
      xm[b] -= dlt;
      stage_call(red, 0, xp, v, bp, op, work);
      stage_call(red, 0, xm, v, bm, om, work);
      for (a = 0; a < 3; a++) {
        dK = fmax(dK, fabs((op[DM_RS_MUA][a] - om[DM_RS_MUA][a]) / (2 * dlt) - oj[DM_RS_K][a * 3 + b]));
        dkv = fmax(dkv, fabs((op[DM_RS_KV][a] - om[DM_RS_KV][a]) / (2 * dlt) - oj[DM_RS_DKV][a * 3 + b]));
        dkv = fmax(dkv, fabs((op[DM_RS_IB][a] - om[DM_RS_IB][a]) / (2 * dlt) - oj[DM_RS_DIB][a * 3 + b]));
        dB = fmax(dB, fabs(oj[DM_RS_B][a * 3 + b] - (oj[DM_RS_K][b * 3 + a] - oj[DM_RS_K][a * 3 + b])));
      }
    }
    tap_ok(dK <= 1e-8 && dkv <= 1e-8 && dB <= 1e-15,
           "%s K, dkv, dib against central differences (%.2g, %.2g), B = K^T - K (%.2g)",
           tag, dK, dkv, dB);
    /* the node helpers: muA and K at zero velocity */
    {
      double z[3] = {0, 0, 0}, K[9];
      bad = dm_routh_muA_K(red, x, muA, K, tin, work);
      stage_call(red, 1, x, z, bj, oj, work);
      dd = vdiff(muA, oj[DM_RS_MUA], 3) + vdiff(K, oj[DM_RS_K], 9);
      bad |= dm_routh_muA(red, x, muA, tin, tout, work);
      dg = vdiff(muA, oj[DM_RS_MUA], 3);
      tap_ok(!bad && dd == 0.0 && dg <= 4e-15 && fabs(muA[1]) > 0.1,
             "%s muA(x) = %.6g %.6g %.6g and K(x) at zero velocity (full program: same bits; "
             "gyro_r: %.2g)", tag, muA[0], muA[1], muA[2], dg);
    }
    /* outside the domain of R^mu (r1 > l1): the stage program reports it and
     * the step names the Routhian */
    {
      const double xo[3] = {1.11, 0.47, 0.29};
      int st;
      double x1[3] = {1.0, 0.47, 0.29}, s1[3] = {6.0, 0.1, 0.1};
      dm_integrator *I = NULL;
      bad = stage_call(red, 0, xo, v, br, o, work);
      dm_routh_integrator_new(red, "gauss", NULL, &I, NULL);
      st = dm_integrator_step(I, 0.2, x1, s1, x1, s1, &e);     /* a stage at r1 > 1.1 */
      tap_ok(bad == 1 && st == DM_EDOM && strstr(e.msg, "the Routhian is not finite") != NULL
             && strstr(e.msg, "x = (1,") == NULL && x1[0] == 1.0,
             "%s stage program outside the domain: non-finite reported, the step fails at a "
             "stage point naming the Routhian: %s", tag, e.msg);
      dm_integrator_free(I);
    }
    free(work);
    dm_routh_free(red);
    dm_expr_ctx_free(S.c);
  }
  /* J2 has no connection term (A = 0): zeros for muA and K, and the
   * classical method's Jacobian (built on them) stays symplectic */
  {
    rsys S;
    dm_routh *red = NULL;
    dm_integrator *I = NULL;
    size_t cyc = 1;
    double mu = 0.93, xj[2] = {1.07, 0.21}, sj[2] = {0.13, -0.08}, K[4] = {1, 1, 1, 1};
    double m2[2] = {1, 1}, def = 1;
    int bad;
    rs_j2(&S, 0.0123);
    rs_reduce(&S, 1, &cyc, &mu, &red, NULL);
    work = malloc((red->nwork + 8) * sizeof *work);
    bad = dm_routh_muA_K(red, xj, m2, K, tin, work);
    dm_routh_integrator_new(red, "classical", NULL, &I, NULL);
    dm_routh_symplecticity_defect(I, 0.05, xj, sj, &def, NULL);
    tap_ok(!bad && !red->has_gyro && vdiff(m2, K, 2) == 0.0 && vdiff(K, K + 2, 2) == 0.0
           && K[0] == 0.0 && def <= 1e-10, "J2 (no connection term): muA = K = 0, classical "
           "Jacobian defect %.2g", def);
    dm_integrator_free(I);
    free(work);
    dm_routh_free(red);
    dm_expr_ctx_free(S.c);
  }
}

int main(void)
{
  dm_gsl_init();
  shift_and_cube();
  orders_and_defect();
  reconstruct_and_phase();
  singular_run();
  stage_programs();
  return tap_done();
}
