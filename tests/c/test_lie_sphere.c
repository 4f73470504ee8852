/* test_lie_sphere.c -- the sphere S^n of src/lie: exp and log inverse to
 * each other and the distance accurate from 1e-9 to pi (S^3), the
 * antipode's errors, the rotation carrying p0 to p1 on S^2 (also 1e-6 from
 * the antipode, where the axis is conditioning-limited), the projection
 * R e3 of that section. */
#include <config.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_rng.h>

#include "lie/lie.h"
#include "lie/lie_impl.h"
#include "tap.h"

static gsl_rng *rng;

static double urand(double a, double b)
{
  return a + (b - a) * gsl_rng_uniform(rng);
}

static void rand_unit3(double *n)
{
  double r;
  do {
    n[0] = urand(-1, 1), n[1] = urand(-1, 1), n[2] = urand(-1, 1);
    r = dm_v3_dot(n, n);
  } while (r > 1.0 || r < 1e-2);
  r = sqrt(r);
  n[0] /= r, n[1] /= r, n[2] /= r;
}

static double maxdiff(const double *a, const double *b, size_t n)
{
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return isnan(m) ? INFINITY : m;
}

static double vnorm(const double *a, size_t n)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    s += a[i] * a[i];
  return sqrt(s);
}

static void test_sphere(void)
{
  double p[4], q[4], v[4], r[4], worst = 0.0, worstd = 0.0, R[9];
  dm_err e;
  int i, k;
  for (i = 0; i < 100; i++) {
    double th = i < 50 ? urand(1e-9, 3.1) : M_PI - urand(1e-9, 1e-3), vn;
    for (k = 0; k < 4; k++)
      p[k] = urand(-1, 1), v[k] = urand(-1, 1);
    dm_lie_sphere_normalize(3, p, NULL);
    dm_lie_sphere_tangent(3, p, v, v);
    vn = vnorm(v, 4);
    for (k = 0; k < 4; k++)
      v[k] *= th / vn;
    dm_lie_sphere_exp(3, p, v, q);
    worstd = fmax(worstd, fabs(dm_lie_sphere_dist(3, p, q) - th) / th);
    if (dm_lie_sphere_log(3, p, q, r, NULL) == DM_OK)
      worst = fmax(worst, maxdiff(r, v, 4) / th);
    else
      worst = INFINITY;
  }
  tap_ok(worstd <= 1e-12, "S3: dist(p, exp_p v) = |v| from 1e-9 to pi (%.2g relative)", worstd);
  tap_ok(worst <= 1e-9, "S3: log_p(exp_p v) = v (%.2g relative)", worst);
  p[0] = 0, p[1] = 0, p[2] = 1;
  q[0] = 0, q[1] = 0, q[2] = -1;
  tap_ok(dm_lie_sphere_log(2, p, q, v, &e) == DM_EDOM &&
             strcmp(e.msg, "sphere log: q = -p (antipodal points), where the direction of the "
                    "geodesic is undefined") == 0, "S2 log at the antipode: '%s'", e.msg);
  tap_ok(dm_lie_sphere_rotation(p, q, R, &e) == DM_EDOM &&
             strstr(e.msg, "sphere rotation: p1 = -p0") == e.msg,
         "S2 rotation to the antipode: '%s'", e.msg);
  worst = worstd = 0.0;
  for (i = 0; i < 100; i++) {
    double y[3], d;
    int ok;
    rand_unit3(p);
    rand_unit3(q);
    if (i % 3 == 0)
      for (k = 0; k < 3; k++)
        q[k] = -p[k] + urand(-1e-6, 1e-6);
    dm_lie_sphere_normalize(2, q, NULL);
    dm_lie_sphere_rotation(p, q, R, NULL);
    dm_m3_apply(R, p, y);
    d = maxdiff(y, q, 3) + dm_lie_orth_defect3(R, &ok);
    if (!ok)
      d = INFINITY;
    /* the formula divides by 1 + p0.p1: errors ~ eps/(1 + c); near the
     * antipode the axis p0 x p1 (~1e-6) is known to ~eps/1e-6 */
    if (i % 3 == 0)
      worstd = fmax(worstd, d);
    else
      worst = fmax(worst, d * (1.0 + dm_v3_dot(p, q)));
  }
  tap_ok(worst <= 2e-15, "S2 rotation carries p0 to p1 and is a rotation (error x (1 + p0.p1): "
         "%.2g)", worst);
  tap_ok(worstd <= 1e-9, "S2 rotation 1e-6 from the antipode: conditioning-limited (%.2g)",
         worstd);
  {
    double e3[3] = {0, 0, 1}, y[3];
    rand_unit3(q);
    dm_lie_sphere_rotation(e3, q, R, NULL);
    dm_lie_sphere_project(R, y);
    tap_ok(maxdiff(y, q, 3) <= 1e-15, "S2 projection of the section R(e3 -> p) is p");
  }
}


int main(void)
{
  dm_gsl_init();
  rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, 2385);
  test_sphere();
  gsl_rng_free(rng);
  return tap_done();
}
