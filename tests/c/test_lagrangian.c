/* test_lagrangian.c -- dm_system from symbolic Lagrangians: the J2
 * satellite against its hand-derived gradient, the double spherical
 * pendulum against the complex step, structure flags, forces, constraints,
 * parameters changed after compiling, domain errors, error paths, native
 * code against the tape. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "core/status.h"
#include "core/system.h"
#include "tap.h"

dm_expr tx_parse(dm_expr_ctx *ctx, const char *s);
int tx_cstep(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
             const double *vals, size_t k, double *deriv);
extern const char tx_dsp_lagrangian[], tx_j2_lagrangian[];
extern const char *const tx_dsp_q[4], *const tx_dsp_v[4], *const tx_dsp_par[5];

static dm_expr_ctx *C;

typedef struct full {
  double L, Lq[8], Lv[8], Lvv[64], Lvq[64], Lqq[64];
} full;

static int call(dm_system *s, const double *q, const double *v, unsigned what,
                full *f)
{
  void *work = malloc(s->work_size);
  dm_lag_out o = { 0, f->Lq, f->Lv, f->Lvv, f->Lvq, f->Lqq };
  int r = s->lagrangian(s->data, q, v, s->par, what, &o, work);
  f->L = o.L;
  free(work);
  return r;
}

static void syms(const char *const *names, size_t n, dm_expr *out)
{
  for (size_t i = 0; i < n; i++)
    out[i] = names[i][0] == 'p' ? dm_expr_param(C, names[i]) : dm_expr_sym(C, names[i]);
}

/* {==================================================================
 * J2 satellite: hand-derived reference
 * =================================================================== */

static void test_j2(void)
{
  static const char *const qn[3] = { "x", "y", "z" }, *const vn[3] = { "vx", "vy", "vz" };
  dm_expr q[3], v[3], par;
  syms(qn, 3, q);
  syms(vn, 3, v);
  par = dm_expr_param(C, "pJ2");
  double J2 = 0.05;
  dm_lagrangian_spec sp = { .name = "J2", .n = 3, .q = q, .v = v, .npar = 1,
    .par = &par, .par_values = &J2, .L = tx_parse(C, tx_j2_lagrangian),
    .native = DM_NATIVE_NEVER };
  dm_system s;
  dm_err err;
  int st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_OK, "J2 system compiled");
  tap_ok(s.flags == (DM_SYS_MECHANICAL | DM_SYS_SEPARABLE), "J2: mechanical and separable");
  tap_ok(s.mass && s.mass[0] == 1 && s.mass[4] == 1 && s.mass[8] == 1 &&
         s.mass[1] == 0 && s.mass[5] == 0, "J2: mass is the identity");
  tap_ok(strcmp(s.coords[2], "z") == 0 && strcmp(s.params[0], "pJ2") == 0 &&
         strcmp(s.name, "J2") == 0, "names copied");

  double x[3] = { 1.2385, -0.4172, 0.6031 }, vv[3] = { 0.21, 0.83, -0.17 };
  full f;
  st = call(&s, x, vv, DM_LAG_ALL, &f);
  double R2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2], R = sqrt(R2);
  double V = -1 / R + J2 / (R2 * R) * (1.5 * x[2] * x[2] / R2 - 0.5);
  double T = 0.5 * (vv[0] * vv[0] + vv[1] * vv[1] + vv[2] * vv[2]), werr = 0;
  for (int i = 0; i < 3; i++) {
    double dV = x[i] / (R2 * R) + J2 * (-7.5 * x[2] * x[2] * x[i] / pow(R, 7)
                                        + 1.5 * x[i] / pow(R, 5));
    if (i == 2)
      dV += J2 * 3 * x[2] / pow(R, 5);
    werr = fmax(werr, fabs(f.Lq[i] + dV) / fabs(dV));
    werr = fmax(werr, fabs(f.Lv[i] - vv[i]));
  }
  tap_near(f.L, T - V, 1e-15, "J2: L at a point");
  tap_ok(st == 0 && werr < 4e-15, "J2: Lq = -grad V (hand-derived), Lv = v "
         "(max rel err %.2g)", werr);
  /* Lqq by central differences of the Lq callback */
  double h = 1e-5, ferr = 0, asym = 0;
  for (int j = 0; j < 3; j++) {
    double xp[3], xm[3];
    full fp, fm;
    memcpy(xp, x, sizeof xp);
    memcpy(xm, x, sizeof xm);
    xp[j] += h;
    xm[j] -= h;
    call(&s, xp, vv, DM_LAG_Q, &fp);
    call(&s, xm, vv, DM_LAG_Q, &fm);
    for (int i = 0; i < 3; i++) {
      ferr = fmax(ferr, fabs((fp.Lq[i] - fm.Lq[i]) / (2 * h) - f.Lqq[i * 3 + j]));
      asym = fmax(asym, fabs(f.Lqq[i * 3 + j] - f.Lqq[j * 3 + i]));
    }
  }
  tap_ok(ferr < 1e-9 && asym == 0, "J2: Lqq = central differences of Lq "
         "(err %.2g), exactly symmetric", ferr);
  double zero = 0;
  for (int i = 0; i < 9; i++)
    zero = fmax(zero, fabs(f.Lvq[i]));
  tap_ok(zero == 0, "J2: Lvq = 0");

  /* parameters changed after compiling */
  s.par[0] = 1.08e-3;
  call(&s, x, vv, DM_LAG_L, &f);
  double V2 = -1 / R + 1.08e-3 / (R2 * R) * (1.5 * x[2] * x[2] / R2 - 0.5);
  tap_near(f.L, T - V2, 1e-15, "J2: new J2 = 1.08e-3 takes effect without recompiling");
  dm_lagrangian_stats ls;
  dm_lagrangian_stats_get(&s, &ls);
  tap_diag("J2: L+grad %zu instructions, all %zu", ls.ninstr_grad, ls.ninstr_all);
  tap_ok(ls.ninstr_grad <= 30 && ls.ninstr_all <= 68, "J2: adjoints and "
         "preaccumulation keep the radial potential compact (%zu <= 30, "
         "%zu <= 68)", ls.ninstr_grad, ls.ninstr_all);
  dm_system_release(&s);
  tap_ok(s.data == NULL && s.lagrangian == NULL, "release zeroes the system");
}

static int make_dsp(dm_system *s, int native, dm_expr *vars, dm_expr *par,
                    dm_err *err);

/* Separable L: the bundles Lq (of q alone) and Lq, Lv, Lqq give what the
 * gradient and full bundles give, bit for bit, on the tape and in native
 * code; the Lq bundle does not read v. */
static void test_bundles(void)
{
  static const char *const qn[3] = { "x", "y", "z" }, *const vn[3] = { "vx", "vy", "vz" };
  dm_expr q[3], v[3], par;
  syms(qn, 3, q);
  syms(vn, 3, v);
  par = dm_expr_param(C, "pJ2");
  double J2 = 0.05, x[3] = { 1.2385, -0.4172, 0.6031 }, vv[3] = { 0.21, 0.83, -0.17 };
  double vnan[3] = { NAN, NAN, NAN };
  full ref[4];                  /* tape: Q, Q|V|QQ, GRAD, ALL */
  const unsigned ws[4] = { DM_LAG_Q, DM_LAG_Q | DM_LAG_V | DM_LAG_QQ, DM_LAG_GRAD, DM_LAG_ALL };
  for (int nat = 0; nat < 2; nat++) {
    dm_lagrangian_spec sp = { .name = "J2", .n = 3, .q = q, .v = v, .npar = 1,
      .par = &par, .par_values = &J2, .L = tx_parse(C, tx_j2_lagrangian),
      .native = nat ? DM_NATIVE_AUTO : DM_NATIVE_NEVER, .q0 = x, .v0 = vv };
    dm_system s;
    dm_lagrangian_stats ls;
    int st = dm_lagrangian_compile(C, &sp, &s, NULL);
    if (nat)                    /* compiled in the background: wait */
      dm_lagrangian_wait_native(&s, 0, NULL);
    dm_lagrangian_stats_get(&s, &ls);
    if (nat && !(ls.native_q && ls.native_sep)) {
      tap_ok(st == DM_OK, "# SKIP no C compiler");
      tap_ok(st == DM_OK, "# SKIP no C compiler");
      dm_system_release(&s);
      break;
    }
    const char *how = nat ? "native" : "tape";
    if (!nat) {
      tap_diag("J2 bundles: Lq %zu, Lq+Lv+Lqq %zu, L+grad %zu, all %zu instructions",
               ls.ninstr_q, ls.ninstr_sep, ls.ninstr_grad, ls.ninstr_all);
      tap_ok(st == DM_OK && ls.ninstr_q > 0 && ls.ninstr_q < ls.ninstr_grad &&
             ls.ninstr_sep > 0 && ls.ninstr_sep < ls.ninstr_all,
             "separable J2: the Lq and Lq+Lv+Lqq bundles are smaller than grad and all");
    }
    full f[4];
    int rc = 0, same = 1;
    for (int k = 0; k < 4; k++) {
      memset(&f[k], 0, sizeof f[k]);
      rc |= call(&s, x, vv, ws[k], &f[k]);
    }
    for (int k = 0; k < 4; k++) {
      same &= memcmp(f[k].Lq, f[3].Lq, 3 * sizeof(double)) == 0;
      if (ws[k] & DM_LAG_V)
        same &= memcmp(f[k].Lv, f[3].Lv, 3 * sizeof(double)) == 0;
      if (ws[k] & DM_LAG_QQ)
        same &= memcmp(f[k].Lqq, f[3].Lqq, 9 * sizeof(double)) == 0;
      if (nat)                  /* native = tape, request by request */
        same &= memcmp(f[k].Lq, ref[k].Lq, 3 * sizeof(double)) == 0 &&
                memcmp(f[k].Lqq, ref[k].Lqq, 9 * sizeof(double)) == 0 &&
                memcmp(f[k].Lv, ref[k].Lv, 3 * sizeof(double)) == 0;
      else
        ref[k] = f[k];
    }
    tap_ok(rc == 0 && same, "%s: Lq, Lv, Lqq the same bit for bit from every bundle%s", how,
           nat ? " and as on the tape" : "");
    /* Lq alone ignores v (NaN velocities); the gradient bundle sees them */
    full g;
    int r1 = call(&s, x, vnan, DM_LAG_Q, &g), r2 = call(&s, x, vnan, DM_LAG_GRAD, &f[0]);
    tap_ok(r1 == 0 && r2 == 1 && memcmp(g.Lq, f[3].Lq, 3 * sizeof(double)) == 0,
           "%s: an Lq request runs the bundle of q alone (v = NaN: %d), "
           "a gradient request sees v (%d)", how, r1, r2);
    dm_system_release(&s);
  }
  /* not separable: no extra bundles */
  dm_expr vars[8], dpar[5];
  dm_system d;
  dm_lagrangian_stats ls;
  make_dsp(&d, DM_NATIVE_NEVER, vars, dpar, NULL);
  dm_lagrangian_stats_get(&d, &ls);
  tap_ok(ls.ninstr_q == 0 && ls.ninstr_sep == 0, "double spherical pendulum: no separable bundles");
  dm_system_release(&d);
}

/* {==================================================================
 * double spherical pendulum against the complex step
 * =================================================================== */

static const double dsp_x[8] = { 0.6, 0.3, 0.5, 1.1, 0.2, -0.4, 0.3, 0.7 };
static double dsp_par[5] = { 1.0, 1.5, 1.0, 1.2, 9.81 };

static int make_dsp(dm_system *s, int native, dm_expr *vars, dm_expr *par,
                    dm_err *err)
{
  syms(tx_dsp_q, 4, vars);
  syms(tx_dsp_v, 4, vars + 4);
  syms(tx_dsp_par, 5, par);
  dm_lagrangian_spec sp = { .name = "double spherical pendulum", .n = 4,
    .q = vars, .v = vars + 4, .npar = 5, .par = par, .par_values = dsp_par,
    .L = tx_parse(C, tx_dsp_lagrangian), .native = native,
    .q0 = dsp_x, .v0 = dsp_x + 4 };
  return dm_lagrangian_compile(C, &sp, s, err);
}

static void test_dsp(void)
{
  dm_expr vars[8], par[5];
  dm_system s;
  dm_err err;
  int st = make_dsp(&s, DM_NATIVE_NEVER, vars, par, &err);
  tap_ok(st == DM_OK && s.flags == DM_SYS_MECHANICAL && s.mass == NULL,
         "double spherical pendulum: mechanical, not separable");
  dm_lagrangian_stats ls;
  dm_lagrangian_stats_get(&s, &ls);
  tap_diag("double spherical pendulum: L+grad %zu instructions, "
           "L+grad+Lvv+Lvq+Lqq %zu instructions, %zu registers",
           ls.ninstr_grad, ls.ninstr_all, ls.nregs_all);
  tap_ok(ls.ninstr_all <= 310, "CSE: full second derivatives in %zu <= 310 "
         "instructions", ls.ninstr_all);

  full f, g;
  double vals[13];
  memcpy(vals, dsp_x, sizeof dsp_x);
  memcpy(vals + 8, dsp_par, sizeof dsp_par);
  dm_expr all[13];
  memcpy(all, vars, sizeof vars);
  memcpy(all + 8, par, sizeof par);
  st = call(&s, dsp_x, dsp_x + 4, DM_LAG_ALL, &f);
  dm_expr L = tx_parse(C, tx_dsp_lagrangian), grad[8];
  dm_expr_grad(C, L, 8, vars, grad, NULL);
  double e1 = 0, e2 = 0, ref;
  for (int k = 0; k < 8; k++) {
    tx_cstep(C, L, 13, all, vals, (size_t)k, &ref);
    e1 = fmax(e1, fabs((k < 4 ? f.Lq[k] : f.Lv[k - 4]) - ref) / fmax(1, fabs(ref)));
  }
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      tx_cstep(C, grad[4 + i], 13, all, vals, 4 + (size_t)j, &ref);
      e2 = fmax(e2, fabs(f.Lvv[i * 4 + j] - ref) / fmax(1, fabs(ref)));
      tx_cstep(C, grad[4 + i], 13, all, vals, (size_t)j, &ref);
      e2 = fmax(e2, fabs(f.Lvq[i * 4 + j] - ref) / fmax(1, fabs(ref)));
      tx_cstep(C, grad[i], 13, all, vals, (size_t)j, &ref);
      e2 = fmax(e2, fabs(f.Lqq[i * 4 + j] - ref) / fmax(1, fabs(ref)));
    }
  tap_ok(st == 0 && e1 < 1e-14, "DSP: Lq, Lv = complex step (max rel err %.2g)", e1);
  tap_ok(e2 < 1e-13, "DSP: Lvv, Lvq, Lqq = complex step of the gradient "
         "(max rel err %.2g)", e2);
  call(&s, dsp_x, dsp_x + 4, DM_LAG_GRAD, &g);
  tap_ok(g.L == f.L && memcmp(g.Lq, f.Lq, 4 * sizeof(double)) == 0 &&
         memcmp(g.Lv, f.Lv, 4 * sizeof(double)) == 0,
         "gradient-only request (small tape) gives the same numbers");

  /* parameters: g = 1.62 (the Moon) */
  s.par[4] = 1.62;
  vals[12] = 1.62;
  call(&s, dsp_x, dsp_x + 4, DM_LAG_L, &g);
  double Lref;
  dm_expr_eval(C, 1, &L, &Lref, 13, all, vals, NULL);
  tap_near(g.L, Lref, 1e-15, "DSP: changing g after compiling");
  s.par[4] = dsp_par[4];

  /* outside the domain: r1 > l1 */
  double bad[8];
  memcpy(bad, dsp_x, sizeof bad);
  bad[0] = 1.25;
  tap_is_int(call(&s, bad, bad + 4, DM_LAG_ALL, &g), 1,
             "r1 > l1: the callback reports a recoverable failure (1)");

  /* native code: same numbers as the tape */
  dm_system sn;
  st = make_dsp(&sn, DM_NATIVE_AUTO, vars, par, &err);
  dm_lagrangian_wait_native(&sn, 0, NULL);
  dm_lagrangian_stats_get(&sn, &ls);
  if (ls.native_all) {
    full fn;
    call(&sn, dsp_x, dsp_x + 4, DM_LAG_ALL, &fn);
    double d = fabs(fn.L - f.L);
    for (int i = 0; i < 16; i++)
      d = fmax(d, fmax(fabs(fn.Lvv[i] - f.Lvv[i]), fmax(fabs(fn.Lvq[i] - f.Lvq[i]),
                                                        fabs(fn.Lqq[i] - f.Lqq[i]))));
    tap_ok(st == DM_OK && ls.native_grad && d <= 1e-15 * 100,
           "DSP native: same values as the tape (max diff %.2g)", d);
    double badq[8];
    memcpy(badq, dsp_x, sizeof badq);
    badq[0] = 1.25;
    full fb;
    fb.L = -7;
    int r = call(&sn, badq, badq + 4, DM_LAG_ALL, &fb);
    tap_ok(r == 1, "DSP native: r1 > l1 reports a recoverable failure (1)");
  } else {
    tap_ok(st == DM_OK, "# SKIP no C compiler: auto falls back to the tape");
    tap_ok(st == DM_OK, "# SKIP no C compiler");
  }
  dm_system_release(&sn);
  dm_system_release(&s);
}

/* {==================================================================
 * flags, forces, constraints
 * =================================================================== */

static unsigned flags_of(const char *Lsrc, dm_system *keep)
{
  dm_expr q = dm_expr_sym(C, "q"), v = dm_expr_sym(C, "v"), p[2];
  p[0] = dm_expr_param(C, "pm");
  p[1] = dm_expr_param(C, "pk");
  double pv[2] = { 2.385, 0.75 };
  dm_lagrangian_spec sp = { .n = 1, .q = &q, .v = &v, .npar = 2, .par = p,
                            .par_values = pv, .L = tx_parse(C, Lsrc) };
  dm_system s;
  if (dm_lagrangian_compile(C, &sp, &s, NULL) != DM_OK)
    return 999;
  unsigned f = s.flags;
  if (keep)
    *keep = s;
  else
    dm_system_release(&s);
  return f;
}

static void test_flags(void)
{
  tap_is_int(flags_of("0.5*pm*v^2 - 0.5*pk*q^2", NULL),
             DM_SYS_MECHANICAL | DM_SYS_SEPARABLE, "harmonic oscillator: separable");
  tap_is_int(flags_of("v^4/4 - q^2/2", NULL), 0, "v^4: not mechanical");
  tap_is_int(flags_of("0.5*v^2 + q*v - q^2", NULL), DM_SYS_MECHANICAL,
             "gyroscopic q*v: mechanical only");
  tap_is_int(flags_of("0.5*v^2 + 3*v - q^2", NULL), DM_SYS_MECHANICAL,
             "linear term 3*v: mechanical only");
  tap_is_int(flags_of("0.5*(1 + q^2)*v^2", NULL), DM_SYS_MECHANICAL,
             "position-dependent mass: mechanical only");
  tap_is_int(flags_of("-0.5*v^2 - q^2", NULL), DM_SYS_MECHANICAL,
             "negative mass: not separable");

  dm_system s;
  flags_of("0.5*pm*v^2 - 0.5*pk*q^2", &s);
  tap_ok(s.mass && s.mass[0] == 2.385, "mass = pm = 2.385");
  s.par[0] = 4.75;
  dm_lagrangian_refresh(&s, NULL);
  tap_ok(s.mass && s.mass[0] == 4.75 && (s.flags & DM_SYS_SEPARABLE),
         "refresh after changing pm: mass 4.75");
  s.par[0] = -1;
  dm_lagrangian_refresh(&s, NULL);
  tap_ok(s.mass == NULL && !(s.flags & DM_SYS_SEPARABLE),
         "refresh with pm < 0 clears SEPARABLE");
  dm_system_release(&s);
  dm_system other = { 0 };
  tap_is_int(dm_lagrangian_refresh(&other, NULL), DM_EINVAL,
             "refresh refuses a system made elsewhere");
}

static void test_force_constraints(void)
{
  static const char *const qn[2] = { "a", "b" }, *const vn[2] = { "va", "vb" };
  dm_expr q[2], v[2], p[2];
  syms(qn, 2, q);
  syms(vn, 2, v);
  p[0] = dm_expr_param(C, "pc");
  p[1] = dm_expr_param(C, "pl");
  double pv[2] = { 0.35, 2.385 };
  dm_expr F[2] = { tx_parse(C, "-pc*va + sin(b)"), tx_parse(C, "-pc*vb*a") };
  dm_expr g[2] = { tx_parse(C, "a^2 + b^2 - pl^2"), tx_parse(C, "a*b^3") };
  dm_lagrangian_spec sp = { .n = 2, .q = q, .v = v, .npar = 2, .par = p,
    .par_values = pv, .L = tx_parse(C, "0.5*(va^2 + vb^2) - b"),
    .force = F, .m = 2, .constraints = g };
  dm_system s;
  dm_err err;
  int st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_OK && s.force && s.constraints && s.m == 2, "forced, constrained system");
  double x[2] = { 1.5, -0.7 }, vv[2] = { 0.4, 2.2 }, Fo[2], Fq[4], Fv[4];
  double go[2], G[4], H[8];
  void *w = malloc(s.work_size);
  s.force(s.data, x, vv, s.par, DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V, Fo, Fq, Fv, w);
  int ok = Fo[0] == -0.35 * 0.4 + sin(-0.7) && Fo[1] == -0.35 * 2.2 * 1.5 &&
           Fq[0] == 0 && Fq[1] == cos(-0.7) && Fq[2] == -0.35 * 2.2 && Fq[3] == 0 &&
           Fv[0] == -0.35 && Fv[1] == 0 && Fv[2] == 0 && Fv[3] == -0.35 * 1.5;
  tap_ok(ok, "force F, Fq, Fv");
  s.constraints(s.data, x, s.par, DM_CONSTR_G | DM_CONSTR_DG | DM_CONSTR_D2G, go, G, H, w);
  const double want_g[2] = { 1.5 * 1.5 + 0.49 - 2.385 * 2.385, 1.5 * -0.343 };
  const double want_G[4] = { 3, -1.4, -0.343, 3 * 1.5 * 0.49 };
  const double want_H[8] = { 2, 0, 0, 2, 0, 3 * 0.49, 3 * 0.49, 6 * 1.5 * -0.7 };
  double e = 0;
  for (int i = 0; i < 8; i++) {
    if (i < 2) e = fmax(e, fabs(go[i] - want_g[i]));
    if (i < 4) e = fmax(e, fabs(G[i] - want_G[i]));
    e = fmax(e, fabs(H[i] - want_H[i]));
  }
  ok = e < 1e-15 && H[5] == H[6];
  tap_ok(ok, "constraints g, G, H (H symmetric per constraint; err %.2g)", e);

  /* the same through native code (it scatters into the arrays itself) */
  dm_system sn;
  sp.native = DM_NATIVE_AUTO;
  st = dm_lagrangian_compile(C, &sp, &sn, &err);
  dm_lagrangian_wait_native(&sn, 0, NULL);
  dm_lagrangian_stats ls;
  dm_lagrangian_stats_get(&sn, &ls);
  if (st == DM_OK && ls.native_all) {
    double F2[2], Fq2[4], Fv2[4], g2[2], G2[4], H2[8];
    void *w2 = malloc(sn.work_size);
    sn.force(sn.data, x, vv, sn.par, DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V, F2, Fq2, Fv2, w2);
    sn.constraints(sn.data, x, sn.par, DM_CONSTR_G | DM_CONSTR_DG | DM_CONSTR_D2G, g2, G2, H2, w2);
    int same = memcmp(F2, Fo, sizeof F2) == 0 && memcmp(Fq2, Fq, sizeof Fq) == 0 &&
               memcmp(Fv2, Fv, sizeof Fv) == 0 && memcmp(g2, go, sizeof go) == 0 &&
               memcmp(G2, G, sizeof G) == 0 && memcmp(H2, H, sizeof H) == 0;
    tap_ok(same, "native force and constraint callbacks = tape, bit for bit");
    double Fonly[2] = { -1, -1 };
    sn.force(sn.data, x, vv, sn.par, DM_FORCE_F, Fonly, NULL, NULL, w2);
    tap_ok(Fonly[0] == Fo[0] && Fonly[1] == Fo[1], "F alone: other arrays may be NULL");
    free(w2);
  } else {
    tap_ok(st == DM_OK, "# SKIP no C compiler");
    tap_ok(st == DM_OK, "# SKIP no C compiler");
  }
  dm_system_release(&sn);
  free(w);
  dm_system_release(&s);
}

static void test_errors(void)
{
  dm_expr q = dm_expr_sym(C, "q"), v = dm_expr_sym(C, "v"), w = dm_expr_sym(C, "w");
  dm_lagrangian_spec sp = { .n = 1, .q = &q, .v = &v, .L = tx_parse(C, "v^2 - w*q") };
  dm_system s;
  dm_err err;
  int st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "L depends on symbol 'w'") &&
         s.lagrangian == NULL, "unknown symbol in L: %s", err.msg);
  dm_expr g = tx_parse(C, "q + v");
  sp.L = tx_parse(C, "v^2");
  sp.m = 1;
  sp.constraints = &g;
  st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "constraint 1 depends on the velocity 'v'"),
         "velocity in a constraint: %s", err.msg);
  sp.m = 0;
  sp.constraints = NULL;
  sp.v = &q;
  st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "twice"), "q used as its own velocity: %s", err.msg);
  dm_expr notsym = tx_parse(C, "2*q");
  sp.v = &notsym;
  st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "velocity 1 is not a symbol"), "%s", err.msg);
  sp.v = &v;
  sp.n = 0;
  st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_is_int(st, DM_EINVAL, "n = 0 refused");
  sp.n = 1;
  (void)w;

  /* native modes without a compiler */
  const char *old = getenv("CC");
  char *saved = old ? strdup(old) : NULL;
  setenv("CC", "/nonexistent/cc", 1);
  sp.native = DM_NATIVE_ALWAYS;
  st = dm_lagrangian_compile(C, &sp, &s, &err);
  tap_ok(st == DM_ENOTFOUND && strstr(err.msg, "/nonexistent/cc"),
         "native = always without a compiler: %s", err.msg);
  sp.native = DM_NATIVE_AUTO;
  st = dm_lagrangian_compile(C, &sp, &s, &err);
  dm_err werr;
  int ws = dm_lagrangian_wait_native(&s, 0, &werr);
  dm_lagrangian_stats ls;
  dm_lagrangian_stats_get(&s, &ls);
  tap_ok(st == DM_OK && !ls.native_all, "native = auto without a compiler: the tape, silently");
  dm_lagrangian_native ns;
  dm_err nerr;
  dm_lagrangian_native_state(&s, &ns, &nerr);
  tap_ok(ws == DM_ENOTFOUND && ns.failed > 0 && ns.native == 0 && ns.pending == 0 &&
         strstr(nerr.msg, "/nonexistent/cc"),
         "the background compilation failed with its message: %s", nerr.msg);
  dm_system_release(&s);
  if (saved) {
    setenv("CC", saved, 1);
    free(saved);
  } else {
    unsetenv("CC");
  }
}

int main(void)
{
  dm_gsl_init();
  const char *tt = getenv("DMECH_TESTTMP");
  if (tt && *tt) {               /* native objects only under the build tree */
    static char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s/native-tmp-lagrangian", tt);
    mkdir(tmp, 0700);            /* may exist already */
    setenv("TMPDIR", tmp, 1);
  } else {
    setenv("XDG_CACHE_HOME", "/nonexistent-dmech-cache", 1);   /* no cache */
  }
  C = dm_expr_ctx_alloc();
  test_j2();
  test_dsp();
  test_bundles();
  test_flags();
  test_force_constraints();
  test_errors();
  dm_expr_ctx_free(C);
  return tap_done();
}
