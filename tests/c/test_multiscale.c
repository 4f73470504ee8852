/* test_multiscale.c -- multiscale variational integration (doc/beyond-fixed-steps.md
 * §4): the 1-D multiscale finite elements exact at the nodes (against the
 * exact solution; linear elements homogenise wrongly), the Filon weights
 * (values, Simpson at theta = 0, an oscillatory integral at w = 10..1000,
 * exactness of the phase-sampled rule), the stiff-spring pendulum from
 * k = 1e4 to 1e8 at fixed steps (slow and fast errors against DOP853,
 * Gauss s = 2 losing the fast phase), the estimate of the fast frequency,
 * errors. */
#include <config.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_integration.h>
#include "core/status.h"
#include "core/system.h"
#include "fields/fields.h"
#include "integrators/integrator.h"
#include "integrators/multiscale.h"
#include "tap.h"

/* {==== 1-D MsFEM: a(y) = 10/(1 + 0.95 sin 2 pi y), f = x^2, eps = 0.025 */

static int coef_a(void *d, double y, double *out)
{
  (void)d;
  *out = 10.0 / (1.0 + 0.95 * sin(2 * M_PI * y));
  return 0;
}

static int load_f(void *d, double x, double *out)
{
  (void)d;
  *out = x * x;
  return 0;
}

static int phi_exact(void *d, double x, double *out)
{
  double eps = *(double *)d;
  *out = (x + 0.95 * eps * (1 - cos(2 * M_PI * x / eps)) / (2 * M_PI)) / 10.0;
  return 0;
}

static void msfem(void)
{
  /* the exact solution at x = 0.25, 0.5, 0.75 (computed in 30-digit arithmetic) */
  static const double u[3] = {-0.0020212505476684960, -0.0035985842096029269,
                              -0.0035719382667358944};
  double eps = 0.025, x[17], U[17];
  dm_msfem_problem P = {coef_a, load_f, phi_exact, NULL, NULL, &eps, eps, 0};
  for (int withphi = 1; withphi >= 0; withphi--) {
    P.Phi = withphi ? phi_exact : NULL;
    for (size_t N = 4; N <= 16; N *= 2) {
      int st = dm_msfem1d(&P, N, DM_MSFEM_MULTISCALE, x, U, NULL);
      double err = 0;
      for (int k = 1; k <= 3; k++)
        err = fmax(err, fabs(U[k * N / 4] - u[k - 1]));
      tap_ok(st == DM_OK && err <= 1e-12, "multiscale elements, N = %zu, Phi %s: nodal error "
             "%.2g (exact at the nodes)", N, withphi ? "closed-form" : "by quadrature", err);
    }
  }
  double emax[3];
  for (size_t N = 4, r = 0; N <= 16; N *= 2, r++) {
    emax[r] = 0;
    double ue[17];                        /* the exact u at every node */
    dm_msfem1d(&P, N, DM_MSFEM_MULTISCALE, x, ue, NULL);
    dm_msfem1d(&P, N, DM_MSFEM_LINEAR, x, U, NULL);
    for (size_t k = 1; k < N; k++)
      emax[r] = fmax(emax[r], fabs(U[k] - ue[k]));
  }
  tap_ok(emax[0] > 2.3e-3 && emax[2] < 2.8e-3 && emax[1] > 2.3e-3 && emax[1] < 2.8e-3,
         "linear elements homogenise with the arithmetic mean of a: max nodal error %.3g, %.3g, "
         "%.3g for N = 4, 8, 16 (max |u| = 3.9e-3)", emax[0], emax[1], emax[2]);
  dm_err e;
  tap_ok(dm_msfem1d(&P, 2, DM_MSFEM_MULTISCALE, x, U, &e) == DM_EINVAL
         && strcmp(e.msg, "msfem: need 3 <= N <= 1e6 elements, got 2") == 0, "N = 2: %s", e.msg);
}

/* }==== */

/* {==== Filon weights */

static double oscf(double x, void *p)
{
  (void)p;
  return 1.0 / (1.0 + x);
}

static void filon(void)
{
  double c3[3] = {0, 0.5, 1}, b[6];
  int st = dm_filon_weights(3, c3, 10.0, b, NULL);
  static const double want[6] = {0.023785369152793, 0.087203502774801, -0.010789307724057,
                                 0.036473416668186, -0.067398172517673, 0.060230233464658};
  double err = 0;
  for (int i = 0; i < 6; i++)
    err = fmax(err, fabs(b[i] - want[i]));
  tap_ok(st == DM_OK && err < 1e-14, "Filon-Lobatto weights, nodes 0, 1/2, 1, theta = 10: to %.2g",
         err);
  dm_filon_weights(3, c3, 0.0, b, NULL);
  tap_ok(fabs(b[0] - 1.0 / 6) < 1e-15 && fabs(b[2] - 2.0 / 3) < 1e-15 && fabs(b[4] - 1.0 / 6) < 1e-15
         && b[1] == 0 && b[3] == 0, "theta = 0: Simpson's weights");
  /* both branches agree where they meet (|theta| = nu + 1 = 4) */
  double bl[6], bh[6];
  dm_filon_weights(3, c3, 4.0 - 1e-12, bl, NULL);
  dm_filon_weights(3, c3, 4.0, bh, NULL);
  err = 0;
  for (int i = 0; i < 6; i++)
    err = fmax(err, fabs(bl[i] - bh[i]));
  tap_ok(err < 1e-12, "the Gauss rule and the moment recursion agree at theta = 4: %.2g", err);
  /* int_0^1 e^{iwx}/(1+x) dx: the 3-node rule against QAWO */
  static const double ws[3] = {10, 100, 1000}, errs[3] = {1.6e-3, 9.6e-6, 1.4e-7};
  gsl_integration_workspace *w = gsl_integration_workspace_alloc(1000);
  for (int k = 0; k < 3; k++) {
    gsl_integration_qawo_table *tc = gsl_integration_qawo_table_alloc(ws[k], 1.0, GSL_INTEG_COSINE, 30);
    gsl_integration_qawo_table *ts = gsl_integration_qawo_table_alloc(ws[k], 1.0, GSL_INTEG_SINE, 30);
    gsl_function F = {oscf, NULL};
    double re, im, ae;
    gsl_integration_qawo(&F, 0, 1e-15, 1e-14, 1000, w, tc, &re, &ae);
    gsl_integration_qawo(&F, 0, 1e-15, 1e-14, 1000, w, ts, &im, &ae);
    dm_filon_weights(3, c3, ws[k], b, NULL);
    double qr = 0, qi = 0;
    for (int i = 0; i < 3; i++) {
      qr += b[2 * i] * oscf(c3[i], NULL);
      qi += b[2 * i + 1] * oscf(c3[i], NULL);
    }
    double e = hypot(qr - re, qi - im);
    tap_ok(fabs(e / errs[k] - 1) < 0.1, "int_0^1 e^{iwx}/(1+x) dx, w = %g: 3-node Filon-Lobatto "
           "error %.3g (%.2g; Simpson's rule: O(1))", ws[k], e, errs[k]);
    gsl_integration_qawo_table_free(tc);
    gsl_integration_qawo_table_free(ts);
  }
  gsl_integration_workspace_free(w);
  /* the phase-sampled rule is exact for G = (polynomial in t) x (trig polynomial of
   * degree < K/2 in the phase): int_0^h t^2 cos(2wt) + t sin(wt) + 3 dt */
  double c4[4], C[32], h = 0.37, om = 41.3;
  dm_tableau_lobatto_nodes(4, c4, NULL);
  dm_filon_phase_weights(4, c4, 8, h, om, C, NULL);
  double q = 0;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 8; j++) {
      double t = c4[i] * h, ph = 2 * M_PI * j / 8;
      q += C[i * 8 + j] * (t * t * cos(2 * ph) + t * sin(ph) + 3);
    }
  double W2 = 2 * om, ex = 3 * h
    + (h * h * sin(W2 * h) / W2 + 2 * h * cos(W2 * h) / (W2 * W2) - 2 * sin(W2 * h) / (W2 * W2 * W2))
    + (sin(om * h) / (om * om) - h * cos(om * h) / om);
  tap_ok(fabs(q - ex) < 1e-14, "phase-sampled Filon rule (4 nodes, 8 phases), w h = %.1f: exact "
         "for t^2 cos 2wt + t sin wt + 3 (%.2g)", om * h, fabs(q - ex));
}

/* }==== */

/* {==== the stiff-spring pendulum, q = (a, theta) */

typedef struct stiffp {
  double m, g, l, k;
} stiffp;

static int stiff_lag(void *data, const double *q, const double *v, const double *par,
                     unsigned what, dm_lag_out *o, void *work)
{
  const stiffp *P = data;
  double a = q[0], th = q[1], ad = v[0], td = v[1], r = P->l + a, c = cos(th), s = sin(th);
  (void)par;
  (void)work;
  o->L = 0.5 * P->m * (ad * ad + r * r * td * td) + P->m * P->g * r * c - 0.5 * P->k * a * a;
  if (what & DM_LAG_Q) {
    o->Lq[0] = P->m * r * td * td + P->m * P->g * c - P->k * a;
    o->Lq[1] = -P->m * P->g * r * s;
  }
  if (what & DM_LAG_V) {
    o->Lv[0] = P->m * ad;
    o->Lv[1] = P->m * r * r * td;
  }
  if (what & DM_LAG_VV) {
    o->Lvv[0] = P->m;
    o->Lvv[1] = o->Lvv[2] = 0;
    o->Lvv[3] = P->m * r * r;
  }
  if (what & DM_LAG_VQ) {
    o->Lvq[0] = o->Lvq[1] = o->Lvq[3] = 0;
    o->Lvq[2] = 2 * P->m * r * td;
  }
  if (what & DM_LAG_QQ) {
    o->Lqq[0] = P->m * td * td - P->k;
    o->Lqq[1] = o->Lqq[2] = -P->m * P->g * s;
    o->Lqq[3] = -P->m * P->g * r * c;
  }
  return 0;
}

static const char *const stiff_names[] = {"a", "theta"};

static void stiff_make(dm_system *s, stiffp *P)
{
  memset(s, 0, sizeof *s);
  s->name = "stiff pendulum";
  s->n = 2;
  s->coords = stiff_names;
  s->lagrangian = stiff_lag;
  s->data = P;
  s->flags = DM_SYS_MECHANICAL;
}

/* theta0 = 0.5, fast energy 0.05: a0 = g cos(theta0)/k + sqrt(2 Ef/k); run to T = 3 */
static void stiff_run(double k, const char *method, double h, double omega, double *a,
                      double *th)
{
  stiffp P = {1, 9.81, 1, k};
  dm_system s;
  dm_integ_opts o;
  dm_integrator *I;
  double q[2] = {9.81 * cos(0.5) / k + sqrt(0.1 / k), 0.5}, p[2] = {0, 0};
  long done;
  stiff_make(&s, &P);
  dm_integ_opts_init(&o);
  o.omega = omega;
  strcpy(o.fast, "a");
  o.stages = 2;
  dm_integrator_new(&s, method, &o, &I, NULL);
  dm_integrator_begin(I, h, 0, q, p, NULL);
  dm_integrator_advance(I, h, lround(3.0 / h), q, p, &done, NULL);
  *a = q[0];
  *th = q[1];
  dm_integrator_free(I);
}

static void stiff(void)
{
  /* a(3), theta(3) by scipy's DOP853, rtol 1e-13, atol 1e-16 */
  static const struct {
    double k, a, th;
  } ref[3] = {{1e4, 9.747612707117677e-04, -4.919159638455836e-01},
              {1e6, -3.001966172219972e-04, -4.924250571123753e-01},
              {1e8, -1.875974233711089e-05, -4.924302411230893e-01}};
  static const struct {
    int r;
    double h, dth;
  } c[] = {{0, 0.1, 7.7e-6}, {0, 0.05, 7.3e-7}, {0, 0.025, 1.9e-8},
           {1, 0.1, 7.5e-8}, {1, 0.05, 7.9e-8}, {1, 0.025, 7.9e-8}, {2, 0.05, 8e-10}};
  double at05[3];
  for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
    double a, th, k = ref[c[i].r].k, A = sqrt(0.1 / k);
    stiff_run(k, "multiscale", c[i].h, sqrt(k), &a, &th);
    double dth = fabs(th - ref[c[i].r].th), fa = fabs(a - ref[c[i].r].a) / A;
    if (c[i].h == 0.05)
      at05[c[i].r] = dth;
    tap_ok(fabs(dth / c[i].dth - 1) < 0.3 && (k < 1e6 || fa <= 3e-3),
           "stiff pendulum k = %g, h = %g (h w = %g): |d theta(3)| = %.2g (%.2g), fast "
           "relative error %.2g", k, c[i].h, c[i].h * sqrt(k), dth, c[i].dth, fa);
  }
  tap_ok(at05[1] <= at05[0] && at05[2] <= at05[1], "at h = 0.05 the slow error does not grow "
         "with k: %.2g, %.2g, %.2g for k = 1e4, 1e6, 1e8", at05[0], at05[1], at05[2]);
  double a, th;
  stiff_run(1e6, "gauss", 0.05, 0, &a, &th);
  tap_ok(fabs(a - ref[1].a) / sqrt(0.1 / 1e6) > 0.05, "Gauss s=2 at k = 1e6, h = 0.05 loses "
         "the fast phase: relative error %.2g", fabs(a - ref[1].a) / sqrt(0.1 / 1e6));
  /* the estimate of the fast frequency, and a run with it */
  for (int r = 0; r < 3; r++) {
    stiffp P = {1, 9.81, 1, ref[r].k};
    dm_system s;
    double q[2] = {9.81 * cos(0.5) / ref[r].k + sqrt(0.1 / ref[r].k), 0.5}, p[2] = {0, 0}, w;
    size_t co = 9;
    stiff_make(&s, &P);
    int st = dm_multiscale_frequency(&s, q, p, &w, &co, NULL);
    tap_ok(st == DM_OK && co == 0 && fabs(w / sqrt(ref[r].k) - 1) < 3e-4, "fast frequency "
           "estimated at k = %g: %.8g (sqrt k = %g), coordinate a", ref[r].k, w, sqrt(ref[r].k));
  }
  stiff_run(1e6, "multiscale", 0.05, 0, &a, &th);
  tap_ok(fabs(th - ref[1].th) < 2e-7, "multiscale with the estimated frequency, k = 1e6: "
         "|d theta(3)| = %.2g", fabs(th - ref[1].th));
}

static void errors(void)
{
  stiffp P = {1, 9.81, 1, 1e4};
  dm_system s;
  dm_integ_opts o;
  dm_integrator *I = NULL;
  dm_err e;
  double q[2] = {0.01, 0.5}, p[2] = {0, 0};
  stiff_make(&s, &P);
  dm_integ_opts_init(&o);
  o.omega = 100;
  strcpy(o.fast, "b");
  int st = dm_integrator_new(&s, "multiscale", &o, &I, &e);
  st = st ? st : dm_integrator_begin(I, 0.1, 0, q, p, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "multiscale: fast = 'b' names no coordinate of "
         "'stiff pendulum'") == 0, "an unknown fast coordinate: %s", e.msg);
  dm_integrator_free(I);
  o.omega = -1;
  tap_ok(dm_integrator_new(&s, "multiscale", &o, &I, &e) == DM_EINVAL
         && strstr(e.msg, "omega must be finite and >= 0") != NULL, "omega < 0: %s", e.msg);
  o.omega = 0;
  P.k = -1e4;          /* a repelling spring, the pendulum upside down: no oscillation */
  strcpy(o.fast, "a");
  dm_integrator_new(&s, "multiscale", &o, &I, NULL);
  q[1] = M_PI;
  st = dm_integrator_begin(I, 0.1, 0, q, p, &e);
  tap_ok(st == DM_EDOM && strstr(e.msg, "no oscillatory mode at the start") != NULL,
         "an unstable spring: %s", e.msg);
  dm_integrator_free(I);
}

/* }==== */

int main(void)
{
  msfem();
  filon();
  stiff();
  errors();
  return tap_done();
}
