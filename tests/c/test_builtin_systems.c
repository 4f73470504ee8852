/* test_builtin_systems.c -- every derivative of every built-in system
 * against central differences of the lower derivative, J2 potential values,
 * parameters, domain errors, release. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "tap.h"

#define NMAX 3

static void lag(const dm_system *s, const double *q, const double *v, unsigned what, double *L,
                double *Lq, double *Lv, double *Lvv, double *Lvq, double *Lqq)
{
  dm_lag_out o = {0, Lq, Lv, Lvv, Lvq, Lqq};
  s->lagrangian(s->data, q, v, s->par, what, &o, NULL);
  if (L)
    *L = o.L;
}

/* max relative mismatch between analytic first/second derivatives and
 * central differences (step 1e-6) */
static double check_lag(const dm_system *s, const double *q, const double *v)
{
  size_t n = s->n, i, j;
  double Lq[NMAX], Lv[NMAX], Lvv[NMAX * NMAX], Lvq[NMAX * NMAX], Lqq[NMAX * NMAX], worst = 0;
  lag(s, q, v, DM_LAG_ALL, NULL, Lq, Lv, Lvv, Lvq, Lqq);
  for (j = 0; j < n; j++) {
    double qp[NMAX], qm[NMAX], vp[NMAX], vm[NMAX], Lp, Lm, d = 1e-6;
    double Lqp[NMAX], Lqm[NMAX], Lvp[NMAX], Lvm[NMAX];
    memcpy(qp, q, n * sizeof(double));
    memcpy(qm, q, n * sizeof(double));
    memcpy(vp, v, n * sizeof(double));
    memcpy(vm, v, n * sizeof(double));
    qp[j] += d;
    qm[j] -= d;
    vp[j] += d;
    vm[j] -= d;
    lag(s, qp, v, DM_LAG_GRAD, &Lp, Lqp, Lvp, NULL, NULL, NULL);
    lag(s, qm, v, DM_LAG_GRAD, &Lm, Lqm, Lvm, NULL, NULL, NULL);
    worst = fmax(worst, fabs((Lp - Lm) / (2 * d) - Lq[j]) / fmax(1, fabs(Lq[j])));
    for (i = 0; i < n; i++) {
      worst = fmax(worst, fabs((Lqp[i] - Lqm[i]) / (2 * d) - Lqq[i * n + j]) / fmax(1, fabs(Lqq[i * n + j])));
      worst = fmax(worst, fabs((Lvp[i] - Lvm[i]) / (2 * d) - Lvq[i * n + j]) / fmax(1, fabs(Lvq[i * n + j])));
    }
    lag(s, q, vp, DM_LAG_GRAD, &Lp, Lqp, Lvp, NULL, NULL, NULL);
    lag(s, q, vm, DM_LAG_GRAD, &Lm, Lqm, Lvm, NULL, NULL, NULL);
    worst = fmax(worst, fabs((Lp - Lm) / (2 * d) - Lv[j]) / fmax(1, fabs(Lv[j])));
    for (i = 0; i < n; i++)
      worst = fmax(worst, fabs((Lvp[i] - Lvm[i]) / (2 * d) - Lvv[i * n + j]) / fmax(1, fabs(Lvv[i * n + j])));
  }
  return worst;
}

static double check_constr(const dm_system *s, const double *q)
{
  size_t n = s->n, i, j;
  double g, G[NMAX], H[NMAX * NMAX], worst = 0;
  s->constraints(s->data, q, s->par, DM_CONSTR_G | DM_CONSTR_DG | DM_CONSTR_D2G, &g, G, H, NULL);
  for (j = 0; j < n; j++) {
    double qp[NMAX], qm[NMAX], gp, gm, Gp[NMAX], Gm[NMAX], d = 1e-6;
    memcpy(qp, q, n * sizeof(double));
    memcpy(qm, q, n * sizeof(double));
    qp[j] += d;
    qm[j] -= d;
    s->constraints(s->data, qp, s->par, DM_CONSTR_G | DM_CONSTR_DG, &gp, Gp, NULL, NULL);
    s->constraints(s->data, qm, s->par, DM_CONSTR_G | DM_CONSTR_DG, &gm, Gm, NULL, NULL);
    worst = fmax(worst, fabs((gp - gm) / (2 * d) - G[j]));
    for (i = 0; i < n; i++)
      worst = fmax(worst, fabs((Gp[i] - Gm[i]) / (2 * d) - H[i * n + j]));
  }
  return worst;
}

int main(void)
{
  dm_system s;
  dm_err e;
  const double q3[3] = {1.1, -0.7, 0.45}, v3[3] = {0.3, 0.9, -0.2};
  double L, d;
  int form;

  dm_builtin_harmonic(&s, 1.0, 2.385, NULL);
  tap_ok(check_lag(&s, q3, v3) < 1e-8 && s.n == 1 && (s.flags & DM_SYS_SEPARABLE) && s.mass[0] == 1.0,
         "harmonic oscillator derivatives (%.2g)", check_lag(&s, q3, v3));
  dm_system_release(&s);
  tap_ok(s.lagrangian == NULL && s.data == NULL, "dm_system_release zeroes the system");

  dm_builtin_pendulum(&s, 1.0, 1.0, 1.0, NULL);
  tap_ok(check_lag(&s, q3, v3) < 1e-8, "pendulum derivatives (%.2g)", check_lag(&s, q3, v3));
  lag(&s, q3, v3, DM_LAG_L, &L, NULL, NULL, NULL, NULL, NULL);
  tap_near(L, 0.045 + cos(1.1), 1e-15, "pendulum L = v^2/2 + cos q");
  s.par[0] = 2.385;
  lag(&s, q3, v3, DM_LAG_L, &L, NULL, NULL, NULL, NULL, NULL);
  tap_near(L, 0.045 + 2.385 * cos(1.1), 1e-15, "changing par[k] changes L without rebuilding");
  dm_system_release(&s);

  dm_builtin_kepler(&s, 2, 1.0, NULL);
  tap_ok(check_lag(&s, q3, v3) < 1e-8 && s.n == 2, "Kepler 2-D derivatives (%.2g)", check_lag(&s, q3, v3));
  {
    double z[2] = {0, 0};
    dm_lag_out o = {0, NULL, NULL, NULL, NULL, NULL};
    tap_ok(s.lagrangian(s.data, z, v3, s.par, DM_LAG_L, &o, NULL) > 0, "Kepler at the origin: recoverable failure");
  }
  dm_system_release(&s);
  dm_builtin_kepler(&s, 3, 1.5, NULL);
  tap_ok(check_lag(&s, q3, v3) < 1e-8 && s.n == 3, "Kepler 3-D derivatives (%.2g)", check_lag(&s, q3, v3));
  dm_system_release(&s);
  tap_is_int(dm_builtin_kepler(&s, 4, 1.0, &e), DM_EINVAL, "Kepler in 4-D rejected: %s", e.msg);

  dm_builtin_j2(&s, 0.05, NULL);
  tap_ok(check_lag(&s, q3, v3) < 1e-8, "J2 derivatives (%.2g)", check_lag(&s, q3, v3));
  {
    /* V = -1/r + (J2/r^3)(3 z^2/(2 r^2) - 1/2) at q3: doc/reduce.md §13 */
    double r = sqrt(1.1 * 1.1 + 0.7 * 0.7 + 0.45 * 0.45);
    double V = -1 / r + 0.05 / (r * r * r) * (1.5 * 0.45 * 0.45 / (r * r) - 0.5);
    double T = 0.5 * (0.09 + 0.81 + 0.04);
    lag(&s, q3, v3, DM_LAG_L, &L, NULL, NULL, NULL, NULL, NULL);
    tap_near(L, T - V, 1e-15, "J2 L = |v|^2/2 - V with the corrected (attractive) potential");
    s.par[0] = 0.0;
    lag(&s, q3, v3, DM_LAG_L, &L, NULL, NULL, NULL, NULL, NULL);
    tap_near(L, T + 1 / r, 1e-15, "J2 = 0 is Kepler");
  }
  dm_system_release(&s);

  dm_builtin_damped_oscillator(&s, 1.0, 2.385, 0.1, NULL);
  {
    double F, Fq, Fv;
    s.force(s.data, q3, v3, s.par, DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V, &F, &Fq, &Fv, NULL);
    tap_ok(F == -0.1 * 0.3 && Fq == 0.0 && Fv == -0.1 && check_lag(&s, q3, v3) < 1e-8,
           "damped oscillator: F = -c v, Fv = -c");
  }
  dm_system_release(&s);

  for (form = 0; form <= 1; form++) {
    dm_builtin_spherical_pendulum_r3(&s, 9.81, 1.3, 1.0, form, NULL);
    d = check_constr(&s, q3);
    tap_ok(check_lag(&s, q3, v3) < 1e-8 && d < 1e-8 && s.m == 1,
           "spherical pendulum in R3, g form %d: derivatives, constraint gradient and Hessian (%.2g)", form, d);
    dm_system_release(&s);
  }
  tap_is_int(dm_builtin_spherical_pendulum_r3(&s, 9.81, 1.3, 1.0, 2, &e), DM_EINVAL, "constraint form 2 rejected");

  dm_builtin_spherical_pendulum(&s, 9.81, 1.3, 1.0, NULL);
  tap_ok(check_lag(&s, q3, v3) < 1e-8 && (s.flags & DM_SYS_MECHANICAL) && !(s.flags & DM_SYS_SEPARABLE),
         "spherical pendulum in angles: derivatives (%.2g), mechanical, not separable", check_lag(&s, q3, v3));
  dm_system_release(&s);
  return tap_done();
}
