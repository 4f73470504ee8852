/* test_integrators_prk.c -- Gauss and Lobatto (Galerkin PRK) integrators on
 * the reference problems of doc/integrators.md §12: the pendulum's one-step
 * values and orders, the analytic pendulum, the harmonic oscillator, Kepler
 * time reversal; symplecticity defect, discrete Legendre transforms / DEL
 * form / discrete momentum, non-separable and forced systems. */
#include <config.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_sf_elljac.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "tap.h"

static dm_integrator *make(const dm_system *s, const char *method, int stages, int expl)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  dm_integ_opts_init(&o);
  o.stages = stages;
  o.explicit_sv = expl;
  if (dm_integrator_new(s, method, &o, &I, &e) != DM_OK)
    tap_diag("cannot create %s: %s", method, e.msg);
  return I;
}

/* One step of the pendulum L = v^2/2 + cos q from (1, 0.5), h = 0.1 */
static void pendulum_one_step(void)
{
  static const struct {
    const char *m;
    int s, expl;
    double q1, p1;
  } ref[] = {
    {"midpoint", 0, 1, 1.0457319775935514958, 0.41463955187102991597},
    {"gauss", 1, 1, 1.0457319775935514958, 0.41463955187102991597},
    {"gauss", 2, 1, 1.045750310037518364, 0.41460947604204174098},
    {"gauss", 3, 1, 1.0457503205397358305, 0.41460947550868741033},
    {"trapezoid", 0, 1, 1.0457926450759605175, 0.41466034594502186448},
    {"trapezoid", 0, 0, 1.0457926450759605175, 0.41466034594502186448},
    {"lobatto", 2, 0, 1.0457926450759605175, 0.41466034594502186448},
    {"lobatto", 3, 1, 1.0457503318316956076, 0.41460947159014490595},
    {"lobatto", 4, 1, 1.0457503205353137737, 0.41460947550646890948},
  };
  dm_system s;
  size_t i;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  for (i = 0; i < sizeof ref / sizeof ref[0]; i++) {
    dm_integrator *I = make(&s, ref[i].m, ref[i].s, ref[i].expl);
    double q = 1.0, p = 0.5;
    dm_err e;
    int st = I ? dm_integrator_step(I, 0.1, &q, &p, &q, &p, &e) : DM_EFAILED;
    tap_ok(st == DM_OK && fabs(q - ref[i].q1) <= 1e-13 && fabs(p - ref[i].p1) <= 1e-13,
           "pendulum one step %s s=%d%s: q1 %.3g, p1 %.3g off (%s, %d Newton iterations)", ref[i].m, ref[i].s,
           ref[i].expl ? "" : " (Newton path)", q - ref[i].q1, p - ref[i].p1,
           I && (I->flags & DM_INTEG_EXPLICIT) ? "explicit" : "implicit", I ? I->stats.iters : -1);
    dm_integrator_free(I);
  }
  dm_system_release(&s);
}

/* Orders by step halving; pendulum to T = 2 against the exact value
 * (or T = 10 against a Gauss-6 reference for order 8). */
static void pendulum_orders(void)
{
  static const struct {
    const char *m;
    int s, order;
    double T, h0;
    size_t k;
  } cases[] = {
    {"gauss", 1, 2, 2, 0.2, 4}, {"gauss", 2, 4, 2, 0.2, 4}, {"gauss", 3, 6, 2, 0.2, 4},
    {"gauss", 4, 8, 10, 0.5, 5}, {"lobatto", 2, 2, 2, 0.2, 4}, {"lobatto", 3, 4, 2, 0.2, 4},
    {"lobatto", 4, 6, 2, 0.2, 4},
  };
  const double qx = 0.29104535735144390609, px = -1.0417697671437177188;
  dm_system s;
  size_t i, j;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    dm_integ_opts o;
    double h[5], err[5], ord = NAN, q0 = 1.0, p0 = 0.5;
    dm_err e;
    int st;
    dm_integ_opts_init(&o);
    o.stages = cases[i].s;
    for (j = 0; j < cases[i].k; j++)
      h[j] = cases[i].k == 5 ? cases[i].h0 * pow(0.8, (double)j) : cases[i].h0 / (1 << j);
    st = dm_integrator_order_estimate(&s, cases[i].m, &o, &q0, &p0, cases[i].T, h, cases[i].k,
                                      cases[i].T == 2 ? &qx : NULL, cases[i].T == 2 ? &px : NULL,
                                      err, &ord, &e);
    tap_ok(st == DM_OK && fabs(ord - cases[i].order) <= 0.1,
           "pendulum order %s s=%d: order %.3f (want %d), errors %.3e .. %.3e", cases[i].m, cases[i].s, ord,
           cases[i].order, err[0], err[cases[i].k - 1]);
    if (i == 0)
      tap_ok(fabs(err[1] - 9.401e-4) < 5e-8, "pendulum G1 error at n = 20 is 9.401e-4 (got %.4e)", err[1]);
  }
  dm_system_release(&s);
}

/* The analytic pendulum: q(0) = 0, p(0) = 2k has q = 2 asin(k sn(t|k^2)), p = 2k cn(t|k^2);
 * k = 1/2, t = 10, h = 0.1: signed errors in q of G1, G2, L2. */
static void pendulum_analytic(void)
{
  static const struct {
    const char *m;
    int s;
    double err;
  } c[] = {{"gauss", 1, 5.43e-3}, {"gauss", 2, 7.30e-7}, {"trapezoid", 0, -1.57e-3}};
  const double qx = 0.11425225501760429923, px = -0.99345891495522782714;
  double sn, cn, dn;
  dm_system s;
  size_t i;
  gsl_sf_elljac_e(10.0, 0.25, &sn, &cn, &dn);
  tap_ok(fabs(2 * asin(0.5 * sn) - qx) < 1e-13 && fabs(cn - px) < 1e-13,
         "analytic pendulum: reference q(10), p(10) from GSL elljac (%.2g, %.2g)", 2 * asin(0.5 * sn) - qx, cn - px);
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  for (i = 0; i < sizeof c / sizeof c[0]; i++) {
    dm_integrator *I = make(&s, c[i].m, c[i].s, 1);
    double q = 0.0, p = 1.0;
    int st = dm_integrator_run(I, 0.0, &q, &p, 0.1, 100, 100, NULL, NULL, NULL, NULL);
    tap_ok(st == DM_OK && fabs((q - qx) / c[i].err - 1.0) < 0.01,
           "analytic pendulum %s s=%d h = 0.1: error in q(10) %.4g (reference %.3g)", c[i].m, c[i].s, q - qx, c[i].err);
    dm_integrator_free(I);
  }
  dm_system_release(&s);
}

/* The harmonic oscillator: Gauss s rotates (omega q, p) by 2 arg P_s(i h omega) per step;
 * energy conserved to round-off; Stormer-Verlet has trace 2 - (h omega)^2
 * and is unstable for h omega > 2. */
static void harmonic_phase(void)
{
  const double w = 2.385, h = 0.1, z = h * w;
  /* numerators of the (s, s) Pade approximants of exp at i z */
  const double re[4] = {0, 1.0, 1.0 - z * z / 12, 1.0 - z * z / 10};
  const double im[4] = {0, z / 2, z / 2, z / 2 - z * z * z / 120};
  dm_system s;
  int sg;
  dm_builtin_harmonic(&s, 1.0, w, NULL);
  for (sg = 1; sg <= 3; sg++) {
    dm_integrator *I = make(&s, "gauss", sg, 1);
    double q = 0.7, p = -0.31, th = 2.0 * atan2(im[sg], re[sg]);
    double E0 = 0.5 * p * p + 0.5 * w * w * q * q, ang, E;
    int k;
    for (k = 0; k < 1000; k++)
      dm_integrator_step(I, h, &q, &p, &q, &p, NULL);
    E = 0.5 * p * p + 0.5 * w * w * q * q;
    /* u = w q + i p evolves as u0 exp(-i k theta) */
    ang = atan2(p, w * q) - atan2(-0.31, w * 0.7);
    ang = remainder(ang + 1000 * th, 2 * M_PI);
    tap_ok(fabs(ang) < 1e-12 && fabs(E - E0) < 1e-14 * 1000 * E0,
           "harmonic oscillator gauss s=%d: phase after 1000 steps off by %.2g rad, energy error %.2g", sg, ang,
           (E - E0) / E0);
    dm_integrator_free(I);
  }
  {
    dm_integrator *I = make(&s, "trapezoid", 0, 1);
    double D[4], q = 0.7, p = -0.31;
    int k;
    dm_integrator_jacobian(I, h, &q, &p, D, NULL);
    tap_near(D[0] + D[3], 2.0 - z * z, 1e-14, "harmonic oscillator Stormer-Verlet trace %.15g = 2 - (h w)^2", D[0] + D[3]);
    for (k = 0; k < 200; k++)
      dm_integrator_step(I, 2.1 / w, &q, &p, &q, &p, NULL);
    tap_ok(fabs(q) > 1e3, "harmonic oscillator Stormer-Verlet unstable at h w = 2.1 (|q| = %.3g after 200 steps)", fabs(q));
    dm_integrator_free(I);
  }
  dm_system_release(&s);
}

/* Time reversal: n steps with h then n with -h return to the start (Kepler e = 0.6). */
static void kepler_reversal(void)
{
  static const struct {
    const char *m;
    int s, expl;
  } ms[] = {{"midpoint", 0, 1}, {"gauss", 2, 1}, {"gauss", 3, 1}, {"trapezoid", 0, 1},
            {"trapezoid", 0, 0}, {"lobatto", 3, 1}, {"lobatto", 4, 1}};
  const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0};
  dm_system s;
  size_t i;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  for (i = 0; i < sizeof ms / sizeof ms[0]; i++) {
    dm_integrator *I = make(&s, ms[i].m, ms[i].s, ms[i].expl);
    double dev = NAN;
    int st = dm_integrator_reversal(I, 0.05, 200, q0, p0, &dev, NULL);
    tap_ok(st == DM_OK && dev <= 1e-12, "Kepler reversal %s s=%d%s: back-and-forth deviation %.2g", ms[i].m,
           ms[i].s, ms[i].expl ? "" : " (Newton)", dev);
    dm_integrator_free(I);
  }
  dm_system_release(&s);
}

/* Symplecticity defect of one step near the Kepler pericentre and for the
 * non-separable spherical pendulum in angles. */
static void defects(void)
{
  static const struct {
    const char *m;
    int s, expl;
  } ms[] = {{"midpoint", 0, 1}, {"gauss", 2, 1}, {"gauss", 3, 1}, {"gauss", 4, 1},
            {"trapezoid", 0, 1}, {"trapezoid", 0, 0}, {"lobatto", 3, 1}, {"lobatto", 4, 1}};
  const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0}, qs[2] = {1.2, 0.3}, ps[2] = {0.4, 2.9};
  dm_system kep, sph;
  size_t i;
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_builtin_spherical_pendulum(&sph, 9.81, 1.3, 1.0, NULL);
  for (i = 0; i < sizeof ms / sizeof ms[0]; i++) {
    dm_integrator *I = make(&kep, ms[i].m, ms[i].s, ms[i].expl);
    dm_integrator *J = make(&sph, ms[i].m, ms[i].s, ms[i].expl);
    double d1 = NAN, d2 = NAN;
    dm_integrator_symplecticity_defect(I, 0.05, q0, p0, &d1, NULL);
    dm_integrator_symplecticity_defect(J, 0.1, qs, ps, &d2, NULL);
    tap_ok(d1 <= 1e-12 && d2 <= 1e-12,
           "symplecticity defect %s s=%d%s: Kepler %.2g, spherical pendulum (non-separable) %.2g",
           ms[i].m, ms[i].s, ms[i].expl ? "" : " (Newton)", d1, d2);
    dm_integrator_free(I);
    dm_integrator_free(J);
  }
  dm_system_release(&kep);
  dm_system_release(&sph);
}

/* Discrete Legendre transforms, DEL stepping, discrete momentum. */
static void del_view(void)
{
  const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0};
  dm_system kep, sph;
  dm_integrator *G2, *M, *G1;
  double q1[2], p1[2], a0[2], a1[2], b0[2], b1[2], Ld, Ld1, q2[2], p2[2], q2d[2];
  dm_lag_out o;
  double Lv[2], Lq[2], L;
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  G2 = make(&kep, "gauss", 2, 1);
  dm_integrator_step(G2, 0.05, q0, p0, q1, p1, NULL);
  dm_integrator_dlegendre(G2, 0.05, q0, q1, a0, a1, &Ld, NULL);
  tap_ok(fabs(a0[0] - p0[0]) + fabs(a0[1] - p0[1]) < 1e-13 && fabs(a1[0] - p1[0]) + fabs(a1[1] - p1[1]) < 1e-13,
         "G2: p0 = -D1 Ld(q0, q1) and p1 = D2 Ld(q0, q1) reproduce the step (%.2g, %.2g)",
         fabs(a0[0] - p0[0]) + fabs(a0[1] - p0[1]), fabs(a1[0] - p1[0]) + fabs(a1[1] - p1[1]));
  /* DEL form: (q0, q1) -> q2 equals the (q, p) stepping */
  dm_integrator_step(G2, 0.05, q1, p1, q2, p2, NULL);
  dm_integrator_del_step(G2, 0.05, q0, q1, q2d, NULL);
  tap_ok(fabs(q2d[0] - q2[0]) + fabs(q2d[1] - q2[1]) < 1e-13, "G2: DEL step (q0, q1) -> q2 matches (%.2g)",
         fabs(q2d[0] - q2[0]) + fabs(q2d[1] - q2[1]));
  /* midpoint: closed form vs the engine's boundary problem (gauss s=1) */
  M = make(&kep, "midpoint", 0, 1);
  G1 = make(&kep, "gauss", 1, 1);
  dm_integrator_dlegendre(M, 0.05, q0, q1, a0, a1, &Ld, NULL);
  dm_integrator_dlegendre(G1, 0.05, q0, q1, b0, b1, &Ld1, NULL);
  tap_ok(fabs(a0[0] - b0[0]) + fabs(a0[1] - b0[1]) + fabs(a1[0] - b1[0]) + fabs(a1[1] - b1[1]) < 1e-13
         && fabs(Ld - Ld1) < 1e-15, "midpoint Ld closed form = Gauss-1 boundary problem (Ld %.17g)", Ld);
  {
    double qm[2] = {0.5 * (q0[0] + q1[0]), 0.5 * (q0[1] + q1[1])};
    double vm[2] = {(q1[0] - q0[0]) / 0.05, (q1[1] - q0[1]) / 0.05};
    memset(&o, 0, sizeof o);
    o.Lv = Lv;
    o.Lq = Lq;
    kep.lagrangian(kep.data, qm, vm, kep.par, DM_LAG_L, &o, NULL);
    L = o.L;
    tap_near(Ld, 0.05 * L, 1e-15, "midpoint Ld = h L((q0+q1)/2, (q1-q0)/h)");
  }
  dm_integrator_free(G2);
  dm_integrator_free(M);
  dm_integrator_free(G1);
  dm_system_release(&kep);

  /* discrete momentum along the cyclic phi of the spherical pendulum */
  dm_builtin_spherical_pendulum(&sph, 9.81, 1.3, 1.0, NULL);
  {
    dm_integrator *I = make(&sph, "gauss", 2, 1);
    const double xi[2] = {0.0, 1.0};
    double q[2] = {1.2, 0.3}, p[2] = {0.4, 2.9}, qa[2], Jfirst = 0, J = 0;
    int k, st = DM_OK;
    for (k = 0; k < 100 && st == DM_OK; k++) {
      memcpy(qa, q, sizeof q);
      st = dm_integrator_step(I, 0.1, q, p, q, p, NULL);
      st = st ? st : dm_integrator_discrete_momentum(I, 0.1, qa, q, xi, &J, NULL);
      if (k == 0)
        Jfirst = J;
    }
    tap_ok(st == DM_OK && fabs(J - 2.9) < 1e-13 && fabs(Jfirst - 2.9) < 1e-13,
           "discrete momentum J_d along phi conserved over 100 G2 steps (%.2g, %.2g)", Jfirst - 2.9, J - 2.9);
    dm_integrator_free(I);
  }
  dm_system_release(&sph);
}

/* Non-separable Newton path converges at order 4; forced damped oscillator
 * matches the exact solution at the method's order and the decay rate. */
static void nonseparable_and_forced(void)
{
  dm_system sph, dmp;
  dm_integ_opts o;
  double h[4] = {0.1, 0.05, 0.025, 0.0125}, err[4], ord = NAN;
  const double w = 2.385, c = 0.05, q0 = 0.7, v0 = 0.2;
  const double wd = sqrt(w * w - c * c / 4), T = 10.0;
  double qx, vx, A, B, ex;
  int s;
  dm_builtin_spherical_pendulum(&sph, 9.81, 1.3, 1.0, NULL);
  dm_integ_opts_init(&o);
  o.stages = 2;
  {
    double q[2] = {1.2, 0.3}, p[2] = {0.4, 2.9};
    int st = dm_integrator_order_estimate(&sph, "gauss", &o, q, p, 2.0, h, 4, NULL, NULL, err, &ord, NULL);
    tap_ok(st == DM_OK && fabs(ord - 4) < 0.1, "G2 on the non-separable spherical pendulum: order %.3f", ord);
  }
  dm_system_release(&sph);

  dm_builtin_damped_oscillator(&dmp, 1.0, w, c, NULL);
  A = q0;
  B = (v0 + 0.5 * c * q0) / wd;
  ex = exp(-0.5 * c * T);
  qx = ex * (A * cos(wd * T) + B * sin(wd * T));
  vx = ex * (-0.5 * c * (A * cos(wd * T) + B * sin(wd * T)) + wd * (B * cos(wd * T) - A * sin(wd * T)));
  for (s = 1; s <= 2; s++) {
    o.stages = s;
    int st = dm_integrator_order_estimate(&dmp, "gauss", &o, &q0, &v0, T, h, 4, &qx, &vx, err, &ord, NULL);
    tap_ok(st == DM_OK && fabs(ord - 2 * s) < 0.1,
           "forced (Lagrange-d'Alembert) G%d on the damped oscillator: order %.3f against the exact solution", s, ord);
  }
  {
    /* decay rate: least-squares slope of log E over 100 time units, numeric
     * vs exact (both ~ -c for light damping) */
    dm_integrator *I = make(&dmp, "gauss", 2, 1);
    double q = q0, p = v0, sx = 0, sy = 0, sxx = 0, sxy = 0, ey = 0, exy = 0, slope, eslope;
    int k, N = 2000;
    for (k = 1; k <= N; k++) {
      double t = 0.05 * k, E, Ee, qe, ve, f = exp(-0.5 * c * t);
      dm_integrator_step(I, 0.05, &q, &p, &q, &p, NULL);
      E = 0.5 * p * p + 0.5 * w * w * q * q;
      qe = f * (A * cos(wd * t) + B * sin(wd * t));
      ve = f * (-0.5 * c * (A * cos(wd * t) + B * sin(wd * t)) + wd * (B * cos(wd * t) - A * sin(wd * t)));
      Ee = 0.5 * ve * ve + 0.5 * w * w * qe * qe;
      sx += t;
      sxx += t * t;
      sy += log(E);
      sxy += t * log(E);
      ey += log(Ee);
      exy += t * log(Ee);
    }
    slope = (N * sxy - sx * sy) / (N * sxx - sx * sx);
    eslope = (N * exy - sx * ey) / (N * sxx - sx * sx);
    tap_ok(fabs(slope - eslope) < 1e-6 && fabs(eslope + c) < 0.02 * c,
           "damped oscillator energy decay rate %.8f (exact %.8f, -c = %.3f)", slope, eslope, -c);
    dm_integrator_free(I);
  }
  dm_system_release(&dmp);
}

int main(void)
{
  dm_gsl_init();
  pendulum_one_step();
  pendulum_orders();
  pendulum_analytic();
  harmonic_phase();
  kepler_reversal();
  defects();
  del_view();
  nonseparable_and_forced();
  return tap_done();
}
