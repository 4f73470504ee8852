/* test_constraints.c -- holonomic constraints: the spherical pendulum in R^3
 * with |q| = l (both forms of g), stepped by RATTLE (explicit and implicit),
 * Lobatto IIIA-IIIB with multipliers at every stage, the constrained
 * midpoint and a composition of RATTLE: constraint and hidden constraint at
 * round-off every step, agreement with the spherical-coordinate solution at
 * the method's order, time reversal, and the error paths. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"
#include "tap.h"

static const double G = 9.81, L = 1.3;
static const double TH0 = 1.2, PH0 = 0.3, THD0 = 0.5, PHD0 = 1.5;

static void to_cart(double th, double ph, double thd, double phd, double *q, double *v)
{
  double st = sin(th), ct = cos(th), sp = sin(ph), cp = cos(ph);
  q[0] = L * st * cp;
  q[1] = L * st * sp;
  q[2] = -L * ct;
  v[0] = L * (ct * cp * thd - st * sp * phd);
  v[1] = L * (ct * sp * thd + st * cp * phd);
  v[2] = L * st * thd;
}

/* Reference at time T: Gauss 6 in spherical coordinates, mapped to R^3. */
static void reference(double T, double *q, double *v)
{
  dm_system s;
  dm_integ_opts o;
  dm_integrator *I = NULL;
  double x[2] = {TH0, PH0}, p[2], vv[2] = {THD0, PHD0};
  dm_builtin_spherical_pendulum(&s, G, L, 1.0, NULL);
  dm_integ_opts_init(&o);
  o.stages = 6;
  dm_integrator_new(&s, "gauss", &o, &I, NULL);
  dm_integrator_momentum(I, x, vv, p, NULL);
  dm_integrator_run(I, 0.0, x, p, T / 1000, 1000, 1000, NULL, NULL, NULL, NULL);
  dm_integrator_velocity(I, x, p, vv, 0, NULL);
  to_cart(x[0], x[1], vv[0], vv[1], q, v);
  dm_integrator_free(I);
  dm_system_release(&s);
}

typedef struct cmethod {
  const char *m;
  int stages, expl, form;
  const char *scheme;
  int order;
  double h0;
} cmethod;

static dm_integrator *make(const dm_system *s, const cmethod *c)
{
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  dm_integ_opts_init(&o);
  o.stages = c->stages;
  o.explicit_sv = c->expl;
  if (c->scheme)
    strcpy(o.scheme, c->scheme);
  if (dm_integrator_new(s, c->m, &o, &I, &e) != DM_OK)
    tap_diag("%s: %s", c->m, e.msg);
  return I;
}

static const char *label(const cmethod *c, char *buf, size_t len)
{
  snprintf(buf, len, "%s%s%s (g = %s)", c->m, c->stages == 3 ? " s=3" : c->stages == 4 ? " s=4" : "",
           c->expl ? "" : " implicit", c->form ? "|q| - l" : "|q|^2 - l^2");
  return buf;
}

static void manifold_and_order(void)
{
  static const cmethod cm[] = {
    {"trapezoid", 0, 1, 0, NULL, 2, 0.1},  {"trapezoid", 0, 0, 1, NULL, 2, 0.1},
    {"lobatto", 3, 1, 0, NULL, 4, 0.1},    {"lobatto", 3, 1, 1, NULL, 4, 0.1},
    {"lobatto", 4, 1, 0, NULL, 6, 0.2},    {"midpoint", 0, 1, 0, NULL, 2, 0.1},
    {"composition", 0, 1, 1, "yoshida4", 4, 0.05},
  };
  const double T = 1.5;
  double qr[3], vr[3];
  size_t i;
  reference(T, qr, vr);
  for (i = 0; i < sizeof cm / sizeof cm[0]; i++) {
    dm_system s;
    dm_integrator *I;
    double q[3], p[3], gmax = 0, tmax = 0, E0, Emax = 0, h[4], err[4], ord, dev = NAN;
    char buf[96];
    int k, j, st = DM_OK;
    dm_builtin_spherical_pendulum_r3(&s, G, L, 1.0, cm[i].form, NULL);
    I = make(&s, &cm[i]);
    to_cart(TH0, PH0, THD0, PHD0, q, p);
    E0 = 0.5 * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + G * q[2];
    for (k = 0; k < 400 && st == DM_OK; k++) {
      double r;
      st = dm_integrator_step(I, 0.05, q, p, q, p, NULL);
      r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      gmax = fmax(gmax, fabs(r - L));
      tmax = fmax(tmax, fabs(q[0] * p[0] + q[1] * p[1] + q[2] * p[2]) / L);
      Emax = fmax(Emax, fabs(0.5 * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + G * q[2] - E0));
    }
    tap_ok(st == DM_OK && gmax <= 1e-12 && tmax <= 1e-12 && Emax < 0.05 * fabs(E0),
           "%s, 400 steps h = 0.05: max ||q| - l| %.2g, max |qdot . grad g| %.2g, energy error %.2g",
           label(&cm[i], buf, sizeof buf), gmax, tmax, Emax);
    /* order against the spherical-coordinate solution */
    for (j = 0; j < 4; j++) {
      int n = (int)lround(T / (cm[i].h0 / (1 << j)));
      double qq[3], pp[3], e2 = 0;
      h[j] = T / n;
      dm_integrator_reset(I);
      to_cart(TH0, PH0, THD0, PHD0, qq, pp);
      dm_integrator_run(I, 0.0, qq, pp, h[j], n, n, NULL, NULL, NULL, NULL);
      for (k = 0; k < 3; k++)
        e2 += (qq[k] - qr[k]) * (qq[k] - qr[k]) + (pp[k] - vr[k]) * (pp[k] - vr[k]);
      err[j] = sqrt(e2);
    }
    ord = dm_integrator_order_fit(h, err, 4);
    tap_ok(fabs(ord - cm[i].order) <= 0.15,
           "%s agrees with the spherical-coordinate solution at order %.3f (want %d; errors %.2e .. %.2e)",
           label(&cm[i], buf, sizeof buf), ord, cm[i].order, err[0], err[3]);
    to_cart(TH0, PH0, THD0, PHD0, q, p);
    dm_integrator_reversal(I, 0.05, 100, q, p, &dev, NULL);
    tap_ok(dev <= 1e-12, "%s: time reversal %.2g", label(&cm[i], buf, sizeof buf), dev);
    dm_integrator_free(I);
    dm_system_release(&s);
  }
}

/* RATTLE explicit = implicit constrained Lobatto-2 Newton path */
static void rattle_paths(void)
{
  dm_system s;
  cmethod e1 = {"trapezoid", 0, 1, 0, NULL, 2, 0}, e0 = {"trapezoid", 0, 0, 0, NULL, 2, 0};
  dm_integrator *A, *B;
  double qa[3], pa[3], qb[3], pb[3], d = 0;
  int k, j;
  dm_builtin_spherical_pendulum_r3(&s, G, L, 1.0, 0, NULL);
  A = make(&s, &e1);
  B = make(&s, &e0);
  to_cart(TH0, PH0, THD0, PHD0, qa, pa);
  to_cart(TH0, PH0, THD0, PHD0, qb, pb);
  for (k = 0; k < 100; k++) {
    dm_integrator_step(A, 0.05, qa, pa, qa, pa, NULL);
    dm_integrator_step(B, 0.05, qb, pb, qb, pb, NULL);
  }
  for (j = 0; j < 3; j++)
    d = fmax(d, fmax(fabs(qa[j] - qb[j]), fabs(pa[j] - pb[j])));
  tap_ok((A->flags & DM_INTEG_EXPLICIT) && !(B->flags & DM_INTEG_EXPLICIT) && d < 1e-12,
         "explicit RATTLE (SHAKE Newton in the multiplier) = implicit constrained trapezoid (%.2g after 100 steps)", d);
  dm_integrator_free(A);
  dm_integrator_free(B);
  dm_system_release(&s);
}

static void errors(void)
{
  dm_system s;
  dm_integrator *I = (dm_integrator *)1;
  dm_integ_opts o;
  dm_err e;
  double q[3], p[3], D[36], d;
  int st;
  dm_builtin_spherical_pendulum_r3(&s, G, L, 1.0, 0, NULL);
  dm_integ_opts_init(&o);
  o.stages = 2;
  tap_is_int(dm_integrator_new(&s, "gauss", &o, &I, &e), DM_EUNSUP, "gauss s=2 with constraints: unsupported");
  tap_ok(I == NULL && strstr(e.msg, "lobatto") != NULL, "message points to lobatto: %s", e.msg);
  tap_is_int(dm_integrator_new(&s, "rk4", NULL, &I, &e), DM_EUNSUP, "rk4 with constraints: %s", e.msg);
  tap_is_int(dm_integrator_new(&s, "gsl:rk8pd", NULL, &I, &e), DM_EUNSUP, "gsl:rk8pd with constraints");
  dm_integrator_new(&s, "lobatto", NULL, &I, NULL);
  to_cart(TH0, PH0, THD0, PHD0, q, p);
  q[2] *= 1.01;
  st = dm_integrator_step(I, 0.05, q, p, q, p, &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "violates the constraints"), "start off the manifold: %s", e.msg);
  to_cart(TH0, PH0, THD0, PHD0, q, p);
  tap_is_int(dm_integrator_jacobian(I, 0.05, q, p, D, &e), DM_EUNSUP, "step Jacobian with constraints: %s", e.msg);
  tap_is_int(dm_integrator_symplecticity_defect(I, 0.05, q, p, &d, &e), DM_EUNSUP, "defect with constraints");
  tap_is_int(dm_integrator_dlegendre(I, 0.05, q, q, p, p, NULL, &e), DM_EUNSUP, "dlegendre with constraints");
  dm_integrator_free(I);
  s.constraints = NULL;
  tap_is_int(dm_integrator_new(&s, "trapezoid", NULL, &I, &e), DM_EINVAL, "m = 1 without a constraint function: %s", e.msg);
  dm_system_release(&s);
}

int main(void)
{
  dm_gsl_init();
  manifold_and_order();
  rattle_paths();
  errors();
  return tap_done();
}
