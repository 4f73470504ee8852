/* sphere.c -- the unit sphere S^n in R^(n+1) as a Riemannian homogeneous
 * space: geodesic exponential and logarithm, distance, tangent projection,
 * and for S^2 = SO(3)/SO(2) the projection R -> R e3 and the rotation
 * carrying one point to another.  Angles come from
 * 2 atan2(|q - p|, |q + p|), accurate at every separation. */
#include <config.h>
#include <math.h>
#include <stdio.h>

#include "lie/lie_impl.h"

static double dot(size_t m, const double *a, const double *b)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < m; i++)
    s += a[i] * b[i];
  return s;
}

void dm_lie_sphere_exp(size_t n, const double *p, const double *v, double *q)
{
  double t = dot(n + 1, v, v), c = cos(sqrt(t)), s = dm_lie_sinc(t);
  size_t i;
  for (i = 0; i <= n; i++)
    q[i] = c * p[i] + s * v[i];
}

double dm_lie_sphere_dist(size_t n, const double *p, const double *q)
{
  double a = 0.0, b = 0.0;
  size_t i;
  for (i = 0; i <= n; i++) {
    a += (q[i] - p[i]) * (q[i] - p[i]);
    b += (q[i] + p[i]) * (q[i] + p[i]);
  }
  return 2.0 * atan2(sqrt(a), sqrt(b));
}

/* u = (q - p) + (|q - p|^2/2) p is q - (p.q) p without cancellation for
 * unit p, q; v = dist u/|u|. */
int dm_lie_sphere_log(size_t n, const double *p, const double *q, double *v, dm_err *e)
{
  double a = 0.0, th = dm_lie_sphere_dist(n, p, q), un, u[DM_LIE_DIM_MAX + 1];
  size_t i;
  if (n + 1 > DM_LIE_DIM_MAX + 1)
    return dm_err_set(e, DM_EINVAL, "sphere log: dimension %zu too large", n);
  for (i = 0; i <= n; i++)
    a += (q[i] - p[i]) * (q[i] - p[i]);
  for (i = 0; i <= n; i++)
    u[i] = (q[i] - p[i]) + 0.5 * a * p[i];
  un = sqrt(dot(n + 1, u, u));
  if (th == 0.0 || un == 0.0) {
    if (th > 1.0)
      return dm_err_set(e, DM_EDOM, "sphere log: q = -p (antipodal points), where the "
                        "direction of the geodesic is undefined");
    for (i = 0; i <= n; i++)
      v[i] = 0.0;
    return DM_OK;
  }
  for (i = 0; i <= n; i++)
    v[i] = th * u[i] / un;
  return DM_OK;
}

void dm_lie_sphere_tangent(size_t n, const double *p, const double *v, double *w)
{
  double d = dot(n + 1, v, p);
  size_t i;
  for (i = 0; i <= n; i++)
    w[i] = v[i] - d * p[i];
}

int dm_lie_sphere_normalize(size_t n, double *p, dm_err *e)
{
  double r = sqrt(dot(n + 1, p, p));
  size_t i;
  if (!(r > 0.0) || !isfinite(r))
    return dm_err_set(e, DM_EDOM, "sphere: cannot normalize a point of norm %g", r);
  for (i = 0; i <= n; i++)
    p[i] /= r;
  return DM_OK;
}

void dm_lie_sphere_project(const double *R, double *p)
{
  p[0] = R[2];
  p[1] = R[5];
  p[2] = R[8];
}

/* R = c I + hat(a) + a a^T/(1 + c), a = p0 x p1, c = p0.p1, with
 * 1 + c = |p0 + p1|^2/2 (no cancellation near the antipode) */
int dm_lie_sphere_rotation(const double *p0, const double *p1, double *R, dm_err *e)
{
  double a[3], s[3], c = dm_v3_dot(p0, p1), d;
  int i, j;
  dm_v3_cross(p0, p1, a);
  for (i = 0; i < 3; i++)
    s[i] = p0[i] + p1[i];
  d = 0.5 * dm_v3_dot(s, s);
  if (!(d > 0.0))
    return dm_err_set(e, DM_EDOM, "sphere rotation: p1 = -p0 (antipodal points), where the "
                      "rotation axis p0 x p1 is undefined");
  dm_so3_poly(a, c, 1.0, 0.0, R, 3);
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      R[3 * i + j] += a[i] * a[j] / d;
  return DM_OK;
}
