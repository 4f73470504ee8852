/* test_sphere_lgvi.c -- lgvi on the sphere (src/lie/sphere_lgvi.c) from C,
 * on a hand-written spherical pendulum L = (m/2)|v|^2 - m g x3 of kind
 * "sphere": the symplecticity defect on T*S^2 is small for lgvi and large
 * for a deliberately non-symplectic family (lgvi's step with p1 scaled by
 * 1.01: still on T*S^2, so only the form can tell); (x p)_3 conserved and
 * |x| = 1 to round-off over 10^4 steps; steps never allocate. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_system.h"
#include "lie/lie_integ_impl.h"
#include "interpose.h"
#include "tap.h"

static const double M = 1.7, G = 9.81;

static int pendulum(void *data, const double *q, const double *v, const double *par,
                    unsigned what, dm_lag_out *o, void *work)
{
  (void)data;
  (void)par;
  (void)work;
  if (what & DM_LAG_L)
    o->L = 0.5 * M * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - M * G * q[2];
  for (int i = 0; i < 3; i++) {
    if (what & DM_LAG_Q)
      o->Lq[i] = i == 2 ? -M * G : 0.0;
    if (what & DM_LAG_V)
      o->Lv[i] = M * v[i];
    for (int j = 0; j < 3; j++) {
      if (what & DM_LAG_VV)
        o->Lvv[3 * i + j] = i == j ? M : 0.0;
      if (what & DM_LAG_VQ)
        o->Lvq[3 * i + j] = 0.0;
      if (what & DM_LAG_QQ)
        o->Lqq[3 * i + j] = 0.0;
    }
  }
  return 0;
}

/* lgvi's step, then p1 scaled by 1.01 */
static int broken_step(dm_integrator *I, double h, const double *q0, const double *p0,
                       double *q1, double *p1, dm_err *e)
{
  int st = dm_sphere_integ_lgvi.step(I, h, q0, p0, q1, p1, e);
  for (int i = 0; i < 3; i++)
    p1[i] *= 1.01;
  return st;
}

static const char *const kinds[] = {DM_SYSTEM_SPHERE, NULL};
static dm_integrator_type broken;

int main(void)
{
  static const char *const coords[] = {"x1", "x2", "x3"};
  dm_system sys;
  dm_integrator *I = NULL, *B = NULL;
  dm_err e;
  double th = 2.385, ph = 0.3, x[3], p[3], d = -1.0, db = -1.0;
  double L0, r = 0.0, dl = 0.0;
  long before, k;
  int st;
  memset(&sys, 0, sizeof sys);
  sys.name = "spherical pendulum";
  sys.kind = DM_SYSTEM_SPHERE;
  sys.n = 3;
  sys.coords = coords;
  sys.lagrangian = pendulum;
  x[0] = sin(th) * cos(ph), x[1] = sin(th) * sin(ph), x[2] = cos(th);
  /* p = m (0.2 e_theta + 1.1 e_phi) */
  p[0] = M * (0.2 * cos(th) * cos(ph) - 1.1 * sin(ph));
  p[1] = M * (0.2 * cos(th) * sin(ph) + 1.1 * cos(ph));
  p[2] = M * (-0.2 * sin(th));
  broken = dm_sphere_integ_lgvi;
  broken.name = "lgvi_scaled_p";
  broken.summary = "lgvi with p1 scaled by 1.01 (a test's non-symplectic map)";
  broken.step = broken_step;
  broken.kinds = kinds;
  if ((st = dm_lie_register_integrators(&e)) == DM_OK)
    st = dm_integrator_register(&broken, &e);
  if (st == DM_OK)
    st = dm_integrator_new(&sys, "lgvi", NULL, &I, &e);
  if (st == DM_OK)
    st = dm_integrator_new(&sys, "lgvi_scaled_p", NULL, &B, &e);
  if (st != DM_OK) {
    tap_ok(0, "set-up: %s", e.msg);
    return tap_done();
  }
  st = dm_integrator_symplecticity_defect(I, 0.1, x, p, &d, &e);
  tap_ok(st == DM_OK && d < 1e-8, "lgvi: symplecticity defect on T*S^2 %.3g < 1e-8", d);
  st = dm_integrator_symplecticity_defect(B, 0.1, x, p, &db, &e);
  tap_ok(st == DM_OK && fabs(db - 0.01) < 5e-4,
         "p1 scaled by 1.01: defect %.4g ~ 0.01 (the form scaled by 1.01)", db);

  L0 = x[0] * p[1] - x[1] * p[0];
  before = ip_count;
  ip_fail_at(1);
  for (k = 0; k < 10000 && st == DM_OK; k++) {
    st = dm_integrator_step(I, 0.01, x, p, x, p, &e);
    r = fmax(r, fabs(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 1.0));
    dl = fmax(dl, fabs(x[0] * p[1] - x[1] * p[0] - L0));
  }
  ip_fail_at(0);
  tap_ok(st == DM_OK && ip_count == before, "10^4 steps: no allocation (%ld)",
         ip_count - before);
  tap_ok(r < 5e-15, "|x| = 1 to %.3g without projection", r);
  tap_ok(dl < 1e-13, "(x p)_3 conserved to %.3g (of %.6f)", dl, L0);
  st = dm_integrator_jacobian(I, 0.1, x, p, NULL, &e);
  tap_ok(st == DM_EUNSUP && strstr(e.msg, "its states live on a manifold (not all of the "
                                   "coordinates)") != NULL, "no Jacobian in coordinates: %s",
         e.msg);
  dm_integrator_free(I);
  dm_integrator_free(B);
  return tap_done();
}
