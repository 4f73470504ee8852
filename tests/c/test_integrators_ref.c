/* test_integrators_ref.c -- non-symplectic references (rk4, gsl:*), the
 * user-tableau prk family, and a non-mechanical Lagrangian. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "core/tableau.h"
#include "integrators/integrator.h"
#include "integ_testsys.h"
#include "tap.h"

static dm_integrator *make(const dm_system *s, const char *m, const dm_integ_opts *o)
{
  dm_integrator *I = NULL;
  dm_err e;
  if (dm_integrator_new(s, m, o, &I, &e) != DM_OK)
    tap_diag("%s: %s", m, e.msg);
  return I;
}

static void rk4(void)
{
  const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0};
  dm_system pen, kep;
  dm_integrator *I, *G;
  double h[4] = {0.2, 0.1, 0.05, 0.025}, err[4], ord = NAN, q = 1.0, p = 0.5, d = NAN, dev = NAN;
  double De[16], Dn[16], dmax = 0.0;
  int i;
  dm_builtin_pendulum(&pen, 1.0, 1.0, 1.0, NULL);
  dm_integrator_order_estimate(&pen, "rk4", NULL, &q, &p, 2.0, h, 4, NULL, NULL, err, &ord, NULL);
  tap_ok(fabs(ord - 4) < 0.1, "rk4: order %.3f", ord);
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  I = make(&kep, "rk4", NULL);
  dm_integrator_symplecticity_defect(I, 0.05, q0, p0, &d, NULL);
  dm_integrator_reversal(I, 0.05, 200, q0, p0, &dev, NULL);
  tap_ok(d > 1e-6 && dev > 1e-6, "rk4 is not symplectic (defect %.2g) and not symmetric (reversal %.2g)", d, dev);
  /* GSL's rk4 returns two classical steps of h/2 (step doubling): compare
   * with two rk4 steps, and the product of the two exact rk4 Jacobians with
   * central differences of gsl:rk4 */
  G = make(&kep, "gsl:rk4", NULL);
  {
    double D1[16], D2[16], z[4], qa[2], pa[2], qb[2], pb[2];
    int a, b, c, k;
    dm_integrator_jacobian(I, 0.025, q0, p0, D1, NULL);
    dm_integrator_step(I, 0.025, q0, p0, z, z + 2, NULL);
    dm_integrator_jacobian(I, 0.025, z, z + 2, D2, NULL);
    for (a = 0; a < 4; a++)
      for (b = 0; b < 4; b++) {
        De[a * 4 + b] = 0.0;
        for (c = 0; c < 4; c++)
          De[a * 4 + b] += D2[a * 4 + c] * D1[c * 4 + b];
      }
    dm_integrator_jacobian(G, 0.05, q0, p0, Dn, NULL);
    for (i = 0; i < 16; i++)
      dmax = fmax(dmax, fabs(De[i] - Dn[i]));
    tap_ok(dmax < 1e-7, "rk4 exact step Jacobians = finite differences of gsl:rk4 (%.2g)", dmax);
    memcpy(qa, q0, sizeof qa);
    memcpy(pa, p0, sizeof pa);
    memcpy(qb, q0, sizeof qb);
    memcpy(pb, p0, sizeof pb);
    for (k = 0; k < 100; k++) {
      dm_integrator_step(I, 0.005, qa, pa, qa, pa, NULL);
      dm_integrator_step(I, 0.005, qa, pa, qa, pa, NULL);
      dm_integrator_step(G, 0.01, qb, pb, qb, pb, NULL);
    }
    tap_ok(fabs(qa[0] - qb[0]) + fabs(qa[1] - qb[1]) + fabs(pa[0] - pb[0]) + fabs(pa[1] - pb[1]) < 1e-12,
           "gsl:rk4 with h = two rk4 steps of h/2 after 100 Kepler steps (%.2g)",
           fabs(qa[0] - qb[0]) + fabs(qa[1] - qb[1]) + fabs(pa[0] - pb[0]) + fabs(pa[1] - pb[1]));
  }
  dm_integrator_free(I);
  dm_integrator_free(G);
  dm_system_release(&kep);
  dm_system_release(&pen);
}

/* doc/integrators.md §13: gsl rk4imp with fixed h is two Gauss-2 steps of h/2. */
static void gsl_crosscheck(void)
{
  dm_system pen;
  dm_integ_opts o;
  dm_integrator *R, *G2;
  double qr = 1.0, pr = 0.5, qg = 1.0, pg = 0.5;
  int k, st = DM_OK;
  dm_err e;
  dm_builtin_pendulum(&pen, 1.0, 1.0, 1.0, NULL);
  dm_integ_opts_init(&o);
  o.epsabs = 1e-8;
  o.epsrel = 0.0;
  R = make(&pen, "gsl:rk4imp", &o);
  dm_integ_opts_init(&o);
  o.stages = 2;
  G2 = make(&pen, "gauss", &o);
  for (k = 0; k < 20 && st == DM_OK; k++)
    st = dm_integrator_step(R, 0.1, &qr, &pr, &qr, &pr, &e);
  for (k = 0; k < 40; k++)
    dm_integrator_step(G2, 0.05, &qg, &pg, &qg, &pg, NULL);
  tap_ok(fabs(qg - 0.29104536341722818) < 1e-14, "rk4imp cross-check: G2 h = 0.05, 40 steps: q = %.17g", qg);
  tap_ok(st == DM_OK && fabs(qr - qg) < 5e-11,
         "rk4imp cross-check: gsl:rk4imp h = 0.1 (epsabs 1e-8) matches G2 with h/2: q = %.17g (diff %.2g)", qr, qr - qg);
  dm_integrator_free(R);
  dm_integrator_free(G2);

  /* rk8pd fixed steps, adaptive rkf45, msadams: accuracy at T = 2 */
  {
    static const struct {
      const char *m;
      int adaptive;
      double h, tol;
    } c[] = {{"gsl:rk8pd", 0, 0.1, 1e-10}, {"gsl:rkf45", 1, 0.5, 1e-9}, {"gsl:msadams", 1, 0.1, 1e-9},
             {"gsl:bsimp", 1, 0.5, 1e-8}};
    size_t i;
    for (i = 0; i < sizeof c / sizeof c[0]; i++) {
      dm_integrator *I;
      double q = 1.0, p = 0.5;
      dm_run_info info;
      dm_integ_opts_init(&o);
      o.adaptive = c[i].adaptive;
      o.epsabs = o.epsrel = 1e-12;
      I = make(&pen, c[i].m, &o);
      st = I ? dm_integrator_run(I, 0.0, &q, &p, c[i].h, lround(2.0 / c[i].h), 1000, NULL, NULL, &info, &e)
             : DM_EFAILED;
      tap_ok(st == DM_OK && fabs(q - 0.29104535735144390609) < c[i].tol && fabs(p + 1.0417697671437177188) < c[i].tol,
             "%s%s to T = 2: error %.2g (order %d)", c[i].m, c[i].adaptive ? " (adaptive)" : "",
             fmax(fabs(q - 0.29104535735144390609), fabs(p + 1.0417697671437177188)), I ? I->order : -1);
      dm_integrator_free(I);
    }
  }
  {
    dm_integrator *I = (dm_integrator *)1;
    tap_is_int(dm_integrator_new(&pen, "gsl:rk5", NULL, &I, &e), DM_ENOTFOUND, "unknown GSL stepper rejected");
    tap_ok(I == NULL && strstr(e.msg, "rk5") && strstr(e.msg, "rk8pd"), "message: %s", e.msg);
    tap_is_int(dm_integrator_new(&pen, "gsl", NULL, &I, &e), DM_ENOTFOUND, "gsl without a stepper rejected");
    tap_is_int(dm_integrator_new(&pen, "gsl:msbdf", NULL, &I, &e), DM_EINVAL,
               "multistep stepper with fixed steps rejected: %s", e.msg);
  }
  dm_system_release(&pen);
}

/* User tableaus: Lobatto IIIA-IIIB s=3 typed in gives the lobatto method;
 * the symplectic partner of RK4 (repeated nodes) is a symplectic PRK. */
static void user_prk(void)
{
  const double r = 1.0 / 24;
  const double a3[] = {0, 0, 0, 5 * r, 8 * r, -r, 4 * r, 16 * r, 4 * r};
  const double b3[] = {1.0 / 6, 2.0 / 3, 1.0 / 6};
  const double at3[] = {1.0 / 6, -1.0 / 6, 0, 1.0 / 6, 1.0 / 3, 0, 1.0 / 6, 5.0 / 6, 0};
  const double rk4a[] = {0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1, 0};
  const double rk4b[] = {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6};
  const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0};
  dm_tableau *t3, *t4;
  dm_system pen, kep;
  dm_integ_opts o;
  dm_integrator *U, *L;
  double qu = 1.0, pu = 0.5, ql = 1.0, pl = 0.5, d = NAN;
  double h[4] = {0.2, 0.1, 0.05, 0.025}, err[4], ord = NAN, q = 1.0, p = 0.5;
  dm_err e;
  int k;
  dm_builtin_pendulum(&pen, 1.0, 1.0, 1.0, NULL);
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_tableau_prk(3, a3, b3, at3, NULL, NULL, 0, &t3, NULL);
  dm_integ_opts_init(&o);
  o.tableau = t3;
  U = make(&pen, "prk", &o);
  dm_integ_opts_init(&o);
  o.stages = 3;
  L = make(&pen, "lobatto", &o);
  for (k = 0; k < 10; k++) {
    dm_integrator_step(U, 0.1, &qu, &pu, &qu, &pu, NULL);
    dm_integrator_step(L, 0.1, &ql, &pl, &ql, &pl, NULL);
  }
  tap_ok(fabs(qu - ql) < 1e-14 && fabs(pu - pl) < 1e-14 && (U->flags & DM_INTEG_SYMMETRIC),
         "prk with the Lobatto IIIA-IIIB 3 table = lobatto s=3 (%.2g)", fabs(qu - ql) + fabs(pu - pl));
  dm_integrator_free(U);
  dm_integrator_free(L);

  dm_tableau_prk(4, rk4a, rk4b, NULL, NULL, NULL, 0, &t4, NULL);
  dm_integ_opts_init(&o);
  o.tableau = t4;
  U = make(&kep, "prk", &o);
  dm_integrator_symplecticity_defect(U, 0.05, q0, p0, &d, NULL);
  dm_integrator_order_estimate(&pen, "prk", &o, &q, &p, 2.0, h, 4, NULL, NULL, err, &ord, NULL);
  tap_ok(d < 1e-12 && fabs(ord - 4) < 0.1,
         "prk: RK4 with its symplectic partner (repeated nodes): defect %.2g, order %.3f", d, ord);
  dm_integrator_free(U);
  dm_integ_opts_init(&o);
  tap_is_int(dm_integrator_new(&pen, "prk", &o, &U, &e), DM_EINVAL, "prk without a tableau: %s", e.msg);
  /* a hand-built non-symplectic table is refused by the family as well */
  t4->at[1] = 0.25;
  o.tableau = t4;
  tap_is_int(dm_integrator_new(&pen, "prk", &o, &U, &e), DM_EINVAL, "prk with a broken table: %s", e.msg);
  dm_tableau_free(t3);
  dm_tableau_free(t4);
  dm_system_release(&pen);
  dm_system_release(&kep);
}

/* Non-mechanical L: iterative velocity Newton, Gauss order and symplecticity,
 * energy conservation, domain errors. */
static void relativistic(void)
{
  dm_system s;
  dm_integ_opts o;
  dm_integrator *I;
  double q = 0.3, p = 0.4, v = 0.0, pp, d = NAN, E0, E1, qa, pa;
  double h[4] = {0.2, 0.1, 0.05, 0.025}, err[4], ord = NAN;
  dm_err e;
  int k, st;
  ts_relativistic(&s);
  dm_integ_opts_init(&o);
  o.stages = 2;
  I = make(&s, "gauss", &o);
  st = dm_integrator_velocity(I, &q, &p, &v, 0, &e);
  dm_integrator_momentum(I, &q, &v, &pp, NULL);
  tap_ok(st == DM_OK && fabs(v - 0.4 / sqrt(1.16)) < 1e-15 && fabs(pp - p) < 1e-15,
         "non-mechanical L: v(q, p) by Newton = p / sqrt(1 + p^2) (%.17g)", v);
  dm_integrator_symplecticity_defect(I, 0.1, &q, &p, &d, NULL);
  qa = q;
  pa = p;
  dm_integrator_order_estimate(&s, "gauss", &o, &qa, &pa, 2.0, h, 4, NULL, NULL, err, &ord, NULL);
  tap_ok(d < 1e-12 && fabs(ord - 4) < 0.1, "non-mechanical L, G2: defect %.2g, order %.3f", d, ord);
  dm_integrator_energy(I, &q, &v, &E0, NULL);
  for (k = 0; k < 1000; k++)
    dm_integrator_step(I, 0.1, &q, &p, &q, &p, NULL);
  dm_integrator_velocity(I, &q, &p, &v, 0, NULL);
  dm_integrator_energy(I, &q, &v, &E1, NULL);
  tap_ok(fabs(E1 - E0) < 1e-6, "non-mechanical L, G2 h = 0.1: energy error %.2g after 1000 steps", E1 - E0);
  v = 1.5;
  st = dm_integrator_energy(I, &q, &v, &E1, &e);
  tap_ok(st == DM_EDOM && strstr(e.msg, "outside the domain"), "|v| > 1 is a domain error: %s", e.msg);
  dm_integrator_free(I);
}

int main(void)
{
  dm_gsl_init();
  rk4();
  gsl_crosscheck();
  user_prk();
  relativistic();
  return tap_done();
}
