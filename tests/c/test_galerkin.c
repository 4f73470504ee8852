/* test_galerkin.c -- the one Galerkin discrete-Lagrangian solver
 * (integrators/galerkin.h): the transforms invert the PRK step (forces
 * included), p0 = -D1 Ld and p1 = D2 Ld against differences of Ld, the
 * second derivatives against differences of p0 and p1, the symmetry of the
 * mixed derivative (dp1/dq0 = -(dp0/dq1)^T), warm starts, and every error. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "core/tableau.h"
#include "integrators/galerkin.h"
#include "integrators/integrator.h"
#include "integ_testsys.h"
#include "tap.h"

static double maxabs(const double *a, const double *b, size_t n)
{
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - (b ? b[i] : 0.0)));
  return m;
}

/* (q0, p0) -> (q1, p1) by the PRK step of the same tableau, then the
 * solver on (q0, q1) returns p0 and p1. */
static void inverts_step(const char *what, const dm_system *s, const char *method, int stages,
                         const double *q0, const double *p0, double h)
{
  dm_integrator *I = NULL;
  dm_integ_opts o;
  dm_tableau *t = NULL;
  dm_galerkin *g = NULL;
  double q1[3], p1[3], a0[3], a1[3], Ld;
  size_t n = s->n;
  dm_err e;
  int st;
  dm_integ_opts_init(&o);
  o.stages = stages;
  o.explicit_sv = 0;
  dm_integrator_new(s, method, &o, &I, NULL);
  if (strcmp(method, "gauss") == 0)
    dm_tableau_gauss((size_t)stages, &t, NULL);
  else
    dm_tableau_lobatto((size_t)stages, &t, NULL);
  dm_galerkin_alloc(s, t, 10 * 2.220446049250313e-16, 50, &g, NULL);
  dm_integrator_step(I, h, q0, p0, q1, p1, NULL);
  st = dm_galerkin_solve(g, h, q0, q1, &Ld, a0, a1, NULL, NULL, NULL, NULL, 0, &e);
  tap_ok(st == DM_OK && maxabs(a0, p0, n) < 1e-13 && maxabs(a1, p1, n) < 1e-13 && isfinite(Ld),
         "%s, %s s=%d: the transforms of (q0, q1) are the step's p0, p1 (%.2g, %.2g; %d iterations)",
         what, method, stages, maxabs(a0, p0, n), maxabs(a1, p1, n), dm_galerkin_iters(g));
  dm_galerkin_free(g);
  dm_tableau_free(t);
  dm_integrator_free(I);
}

/* first and second derivatives against central differences */
static void derivatives(const char *what, const dm_system *s, const dm_tableau *t, int forced,
                        const double *q0, const double *q1, double h)
{
  enum { N = 3 };
  dm_galerkin *g = NULL;
  size_t n = s->n, i, j;
  double p0[N], p1[N], d00[N * N], d01[N * N], d10[N * N], d11[N * N], Ld;
  double fd[4][N * N] = {{0}}, x0[N], x1[N], a0[N], a1[N], b0[N], b1[N], L1, L2;
  double e1 = 0, e2 = 0, sym = 0, scale = 0, eps = 1e-6;
  dm_err e;
  int st;
  dm_galerkin_alloc(s, t, 10 * 2.220446049250313e-16, 50, &g, NULL);
  st = dm_galerkin_solve(g, h, q0, q1, &Ld, p0, p1, d00, d01, d10, d11, 0, &e);
  for (j = 0; j < 2 * n; j++) {
    memcpy(x0, q0, n * sizeof x0[0]);
    memcpy(x1, q1, n * sizeof x1[0]);
    (j < n ? x0 : x1)[j % n] += eps;
    dm_galerkin_solve(g, h, x0, x1, &L1, a0, a1, NULL, NULL, NULL, NULL, 0, NULL);
    (j < n ? x0 : x1)[j % n] -= 2 * eps;
    dm_galerkin_solve(g, h, x0, x1, &L2, b0, b1, NULL, NULL, NULL, NULL, 0, NULL);
    if (!forced)      /* p0 = -D1 Ld, p1 = D2 Ld */
      e1 = fmax(e1, fabs((L1 - L2) / (2 * eps) - (j < n ? -p0[j] : p1[j - n])));
    for (i = 0; i < n; i++) {
      fd[j < n ? 0 : 1][i * n + j % n] = (a0[i] - b0[i]) / (2 * eps);
      fd[j < n ? 2 : 3][i * n + j % n] = (a1[i] - b1[i]) / (2 * eps);
    }
  }
  scale = fmax(fmax(maxabs(d00, NULL, n * n), maxabs(d11, NULL, n * n)), 1.0);
  e2 = fmax(fmax(maxabs(fd[0], d00, n * n), maxabs(fd[1], d01, n * n)),
            fmax(maxabs(fd[2], d10, n * n), maxabs(fd[3], d11, n * n))) / scale;
  for (i = 0; i < n; i++)
    for (j = 0; j < n; j++)
      sym = fmax(sym, fabs(d10[i * n + j] + d01[j * n + i]));
  tap_ok(st == DM_OK && e1 < 1e-7, "%s: D1 Ld = -p0, D2 Ld = p1 against differences of Ld (%.2g)",
         what, e1);
  tap_ok(e2 < 1e-6, "%s: dp0/dq0, dp0/dq1, dp1/dq0, dp1/dq1 against differences (rel. %.2g)",
         what, e2);
  if (!forced)
    tap_ok(sym < 1e-12 * scale, "%s: dp1/dq0 = -(dp0/dq1)^T (D1 D2 Ld symmetric; %.2g)", what, sym);
  dm_galerkin_free(g);
}

static void errors(void)
{
  dm_system s, c, r;
  dm_tableau *t = NULL;
  dm_galerkin *g = NULL;
  double q0[3] = {0.4, 0.1, 0}, q1[3] = {0.41, 0.12, 0}, p0[3], x = 0.3, y, k = 1e12;
  dm_err e;
  int st;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_tableau_gauss(2, &t, NULL);
  dm_galerkin_alloc(&s, t, 1e-15, 50, &g, NULL);
  st = dm_galerkin_solve(g, 0.0, q0, q1, NULL, p0, NULL, NULL, NULL, NULL, NULL, 0, &e);
  tap_ok(st == DM_EINVAL && strcmp(e.msg, "discrete Lagrangian needs h != 0") == 0, "h = 0: %s", e.msg);
  dm_galerkin_free(g);
  dm_galerkin_alloc(&s, t, 1e-15, 1, &g, NULL);
  st = dm_galerkin_solve(g, 0.05, q0, q1, NULL, p0, NULL, NULL, NULL, NULL, NULL, 0, &e);
  tap_ok(st == DM_ENOCONV && strstr(e.msg, "did not converge in 1 iterations (update"),
         "maxiter = 1: %s", e.msg);
  dm_galerkin_free(g);
  dm_builtin_spherical_pendulum_r3(&c, 9.81, 1.0, 1.0, 0, NULL);
  st = dm_galerkin_alloc(&c, t, 1e-15, 50, &g, &e);
  tap_ok(st == DM_EINVAL && g == NULL && strstr(e.msg, "unconstrained"), "constraints: %s", e.msg);
  ts_relativistic(&r);
  dm_galerkin_alloc(&r, t, 1e-15, 50, &g, NULL);
  y = x + 0.5;               /* |v| = 5 > 1: outside the domain */
  st = dm_galerkin_solve(g, 0.1, &x, &y, NULL, p0, NULL, NULL, NULL, NULL, NULL, 0, &e);
  tap_ok(st == DM_EDOM && strstr(e.msg, "outside its domain at a stage point"), "domain: %s", e.msg);
  dm_galerkin_free(g);
  /* a warm start from the previous solution converges in fewer iterations */
  ts_quartic(&r, &k);
  k = 2.385;
  dm_galerkin_alloc(&r, t, 1e-15, 50, &g, NULL);
  x = 0.7;
  y = 0.75;
  dm_galerkin_solve(g, 0.1, &x, &y, NULL, p0, NULL, NULL, NULL, NULL, NULL, 0, NULL);
  {
    int cold, warm;
    double p0w, p0c, y2 = y + 1e-7;
    dm_galerkin_solve(g, 0.1, &x, &y2, NULL, &p0w, NULL, NULL, NULL, NULL, NULL, 1, NULL);
    warm = dm_galerkin_iters(g);
    dm_galerkin_solve(g, 0.1, &x, &y2, NULL, &p0c, NULL, NULL, NULL, NULL, NULL, 0, NULL);
    cold = dm_galerkin_iters(g);
    tap_ok(warm < cold && fabs(p0w - p0c) < 1e-14, "warm start: %d iterations instead of %d, same p0",
           warm, cold);
  }
  dm_galerkin_free(g);
  dm_galerkin_free(NULL);
  dm_tableau_free(t);
  dm_system_release(&c);
  dm_system_release(&s);
}

int main(void)
{
  dm_system kep, j2, damp;
  dm_tableau *t = NULL;
  double kq0[2] = {0.4, 0.1}, kp0[2] = {0.2, 2.0}, kq1[2] = {0.41, 0.19};
  double jq0[3] = {2.0, 0.1, 0.3}, jp0[3] = {0.05, 2.4, 0.1}, jq1[3] = {2.01, 0.13, 0.305};
  double dq0[1] = {0.3}, dp0[1] = {-0.2}, dq1[1] = {0.31};
  dm_gsl_init();
  dm_builtin_kepler(&kep, 2, 1.0, NULL);
  dm_builtin_j2(&j2, 0.05, NULL);
  dm_builtin_damped_oscillator(&damp, 1.0, 2.385, 0.3, NULL);
  inverts_step("Kepler", &kep, "gauss", 2, kq0, kp0, 0.05);
  inverts_step("Kepler", &kep, "lobatto", 3, kq0, kp0, 0.05);
  inverts_step("J2", &j2, "gauss", 3, jq0, jp0, 0.05);
  inverts_step("damped oscillator (forced)", &damp, "gauss", 2, dq0, dp0, 0.1);
  inverts_step("damped oscillator (forced)", &damp, "lobatto", 4, dq0, dp0, 0.1);
  dm_tableau_gauss(2, &t, NULL);
  derivatives("Kepler, Gauss 2", &kep, t, 0, kq0, kq1, 0.05);
  derivatives("J2, Gauss 2", &j2, t, 0, jq0, jq1, 0.05);
  derivatives("damped oscillator, Gauss 2 (forced)", &damp, t, 1, dq0, dq1, 0.1);
  dm_tableau_free(t);
  dm_tableau_lobatto(3, &t, NULL);
  derivatives("J2, Lobatto 3", &j2, t, 0, jq0, jq1, 0.05);
  dm_tableau_free(t);
  errors();
  dm_system_release(&kep);
  dm_system_release(&j2);
  dm_system_release(&damp);
  return tap_done();
}
