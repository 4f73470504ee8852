/* test_integrators_comp.c -- symmetric compositions of Stormer-Verlet /
 * trapezoid / midpoint: orders 4, 6, 8 of every coefficient table,
 * explicit and implicit base steps agree, symplecticity, time reversal,
 * option errors. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "tap.h"

static dm_integrator *comp(const dm_system *s, const char *scheme, const char *base, int expl)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  dm_integ_opts_init(&o);
  strcpy(o.scheme, scheme);
  strcpy(o.base, base);
  o.explicit_sv = expl;
  if (dm_integrator_new(s, "composition", &o, &I, &e) != DM_OK)
    tap_diag("composition %s: %s", scheme, e.msg);
  return I;
}

static void orders(void)
{
  /* pendulum from (1, 0.5); step sequences keep the errors between 1e-2 and
   * 1e-13 so round-off does not enter the fit */
  static const struct {
    const char *scheme;
    int order;
    double T, h[5];
    size_t k;
  } cases[] = {
    {"yoshida4", 4, 2, {0.5, 0.25, 0.125, 0.0625}, 4},
    {"yoshida6", 6, 2, {0.25, 0.125, 0.0625, 0.03125}, 4},
    {"kahanli6", 6, 2, {0.25, 0.125, 0.0625, 0.03125}, 4},
    {"mclachlan8", 8, 10, {0.25, 0.2, 0.16, 0.125, 0.1}, 5},
    {"kahanli8", 8, 10, {0.25, 0.2, 0.16, 0.125, 0.1}, 5},
  };
  dm_system s;
  size_t i;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    dm_integ_opts o;
    double err[5], ord = NAN, q0 = 1.0, p0 = 0.5;
    int st;
    dm_integ_opts_init(&o);
    strcpy(o.scheme, cases[i].scheme);
    st = dm_integrator_order_estimate(&s, "composition", &o, &q0, &p0, cases[i].T, cases[i].h,
                                      cases[i].k, NULL, NULL, err, &ord, NULL);
    tap_ok(st == DM_OK && fabs(ord - cases[i].order) <= 0.1,
           "pendulum order, composition %s: order %.3f (want %d), errors %.3e .. %.3e", cases[i].scheme, ord,
           cases[i].order, err[0], err[cases[i].k - 1]);
  }
  {
    /* default table for each order; midpoint base */
    dm_integ_opts o;
    dm_integrator *I = NULL;
    double h[4] = {0.125, 0.0625, 0.03125, 0.015625}, err[4], ord = NAN, q0 = 1.0, p0 = 0.5;
    int order;
    for (order = 4; order <= 8; order += 2) {
      dm_integ_opts_init(&o);
      o.order = order;
      dm_integrator_new(&s, "composition", &o, &I, NULL);
      tap_ok(I && I->order == order, "composition order = %d selects a table of order %d", order,
             I ? I->order : -1);
      dm_integrator_free(I);
      I = NULL;
    }
    dm_integ_opts_init(&o);
    strcpy(o.base, "midpoint");
    dm_integrator_order_estimate(&s, "composition", &o, &q0, &p0, 2.0, h, 4, NULL, NULL, err, &ord, NULL);
    tap_ok(fabs(ord - 4) <= 0.1, "yoshida4 over the implicit midpoint: order %.3f", ord);
  }
  dm_system_release(&s);
}

static void structure(void)
{
  static const char *const schemes[] = {"yoshida4", "yoshida6", "kahanli6", "mclachlan8", "kahanli8"};
  const double q0[2] = {0.4, 0.0}, p0[2] = {0.0, 2.0};
  dm_system s;
  size_t i;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  for (i = 0; i < 5; i++) {
    dm_integrator *E = comp(&s, schemes[i], "trapezoid", 1), *N = comp(&s, schemes[i], "trapezoid", 0);
    double qe[2], pe[2], qn[2], pn[2], d = NAN, dev = NAN, diff;
    int k;
    memcpy(qe, q0, sizeof qe);
    memcpy(pe, p0, sizeof pe);
    memcpy(qn, q0, sizeof qn);
    memcpy(pn, p0, sizeof pn);
    for (k = 0; k < 20; k++) {
      dm_integrator_step(E, 0.05, qe, pe, qe, pe, NULL);
      dm_integrator_step(N, 0.05, qn, pn, qn, pn, NULL);
    }
    diff = fmax(fmax(fabs(qe[0] - qn[0]), fabs(qe[1] - qn[1])), fmax(fabs(pe[0] - pn[0]), fabs(pe[1] - pn[1])));
    tap_ok((E->flags & DM_INTEG_EXPLICIT) && !(N->flags & DM_INTEG_EXPLICIT) && diff < 1e-12,
           "%s: explicit Stormer-Verlet and implicit trapezoid bases agree (%.2g after 20 steps)",
           schemes[i], diff);
    dm_integrator_symplecticity_defect(E, 0.05, q0, p0, &d, NULL);
    dm_integrator_reversal(E, 0.05, 200, q0, p0, &dev, NULL);
    tap_ok(d <= 1e-12 && dev <= 1e-12, "%s: symplecticity defect %.2g, time reversal %.2g", schemes[i], d, dev);
    dm_integrator_free(E);
    dm_integrator_free(N);
  }
  dm_system_release(&s);
  /* non-separable system: composition of the implicit trapezoid */
  {
    dm_system sph;
    dm_integ_opts o;
    double h[4] = {0.05, 0.025, 0.0125, 0.00625}, err[4], ord = NAN, q[2] = {1.2, 0.3}, p[2] = {0.4, 2.9};
    double d = NAN;
    dm_integrator *I = NULL;
    dm_builtin_spherical_pendulum(&sph, 9.81, 1.3, 1.0, NULL);
    dm_integ_opts_init(&o);
    dm_integrator_order_estimate(&sph, "composition", &o, q, p, 2.0, h, 4, NULL, NULL, err, &ord, NULL);
    dm_integrator_new(&sph, "composition", &o, &I, NULL);
    dm_integrator_symplecticity_defect(I, 0.1, q, p, &d, NULL);
    tap_ok(fabs(ord - 4) <= 0.1 && d <= 1e-12 && !(I->flags & DM_INTEG_EXPLICIT),
           "yoshida4 on the non-separable spherical pendulum: order %.3f, defect %.2g", ord, d);
    dm_integrator_free(I);
    dm_system_release(&sph);
  }
}

static void errors(void)
{
  dm_system s;
  dm_integ_opts o;
  dm_integrator *I = (dm_integrator *)1;
  dm_err e;
  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  dm_integ_opts_init(&o);
  strcpy(o.scheme, "yoshida5");
  tap_is_int(dm_integrator_new(&s, "composition", &o, &I, &e), DM_ENOTFOUND, "unknown scheme rejected");
  tap_ok(I == NULL && strstr(e.msg, "yoshida5") && strstr(e.msg, "kahanli8"), "message: %s", e.msg);
  dm_integ_opts_init(&o);
  o.order = 5;
  tap_is_int(dm_integrator_new(&s, "composition", &o, &I, &e), DM_EINVAL, "order 5 rejected: %s", e.msg);
  dm_integ_opts_init(&o);
  strcpy(o.base, "rk4");
  tap_is_int(dm_integrator_new(&s, "composition", &o, &I, &e), DM_EINVAL, "base rk4 rejected: %s", e.msg);
  tap_is_int(dm_integrator_new(&s, "composition:kahanli6", NULL, &I, &e), DM_OK,
             "scheme as method variant composition:kahanli6");
  tap_ok(I && I->order == 6, "composition:kahanli6 has order 6");
  dm_integrator_free(I);
  dm_system_release(&s);
}

int main(void)
{
  dm_gsl_init();
  orders();
  structure();
  errors();
  return tap_done();
}
