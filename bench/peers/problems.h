/* problems.h -- the two benchmark problems written by hand (shared by the C
 * harnesses bench/b*.c and the C++ harness bench/peers/odeint_bench.cpp).
 *
 * Kepler e = 0.6 (doc/integrators.md §12.5): L = |v|^2/2 + 1/|q|, n = 2,
 *   q0 = (0.4, 0), p0 = (0, 2), H0 = -1/2, period 2 pi.
 * J2 satellite, Cartesian (doc/reduce.md §13, corrected potential):
 *   V = -1/|q| + (J2/|q|^3)(3 z^2/(2|q|^2) - 1/2), J2 = 0.05 (the thesis's
 *   value), q0 = (2, 0, 0.3), p0 = (0, 0.6, 0.1) (the example of plot_gallery.lua),
 *   osculating period about 12.7; "1000 orbits" = T = 12750.
 * Unit mass: p = v.  Everything is static inline; no allocation.
 */
#ifndef BENCH_PROBLEMS_H
#define BENCH_PROBLEMS_H

#include <math.h>

#define KEP_N 2
#define J2_N 3
#define J2_VALUE 0.05
#define KEP_T1000 (2000.0 * M_PI)   /* 1000 periods */
#define J2_T1000 12750.0            /* ~1000 orbits */

static const double kep_q0[2] = {0.4, 0.0}, kep_p0[2] = {0.0, 2.0};
static const double j2_q0[3] = {2.0, 0.0, 0.3}, j2_p0[3] = {0.0, 0.6, 0.1};

/* Kepler: f = -q/|q|^3 */
static inline void kep_force(const double *q, double *f)
{
  double r2 = q[0] * q[0] + q[1] * q[1], r = sqrt(r2), a = 1.0 / (r2 * r);
  f[0] = -q[0] * a;
  f[1] = -q[1] * a;
}

static inline double kep_energy(const double *q, const double *p)
{
  return 0.5 * (p[0] * p[0] + p[1] * p[1]) - 1.0 / sqrt(q[0] * q[0] + q[1] * q[1]);
}

/* df_i/dq_j (2x2, row-major) */
static inline void kep_dforce(const double *q, double *D)
{
  double r2 = q[0] * q[0] + q[1] * q[1], r = sqrt(r2), a = 1.0 / (r2 * r), b = 3.0 * a / r2;
  D[0] = -a + b * q[0] * q[0];
  D[1] = D[2] = b * q[0] * q[1];
  D[3] = -a + b * q[1] * q[1];
}

/* J2: f = -grad V */
static inline void j2_force(const double *q, double *f)
{
  const double x = q[0], y = q[1], z = q[2], J2 = J2_VALUE;
  const double r2 = x * x + y * y + z * z, R = sqrt(r2), iR = 1.0 / R;
  const double a = iR / r2, b = a / r2, c = b / r2;   /* R^-3, R^-5, R^-7 */
  const double g = a + J2 * (1.5 * b - 7.5 * z * z * c);
  f[0] = -x * g;
  f[1] = -y * g;
  f[2] = -z * g - 3.0 * J2 * z * b;
}

static inline double j2_energy(const double *q, const double *p)
{
  const double z = q[2], J2 = J2_VALUE;
  const double r2 = q[0] * q[0] + q[1] * q[1] + z * z, R = sqrt(r2);
  const double V = -1.0 / R + J2 / (r2 * R) * (1.5 * z * z / r2 - 0.5);
  return 0.5 * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + V;
}

/* df_i/dq_j = -d2V/dq_i dq_j (3x3, row-major) */
static inline void j2_dforce(const double *q, double *D)
{
  const double J2 = J2_VALUE, z = q[2];
  const double r2 = q[0] * q[0] + q[1] * q[1] + z * z, R = sqrt(r2), iR = 1.0 / R;
  const double a = iR / r2, b = a / r2, c = b / r2, d = c / r2;
  const double z2 = z * z;
  const double g = a + J2 * (1.5 * b - 7.5 * z2 * c);
  const double h = -3.0 * b - 7.5 * J2 * c + 52.5 * J2 * z2 * d;
  const double t = -15.0 * J2 * z * c;
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = i; j < 3; j++) {
      double H = (i == j ? g : 0.0) + q[i] * q[j] * h;
      if (j == 2)
        H += t * q[i] + (i == 2 ? t * q[j] + 3.0 * J2 * b : 0.0);
      D[i * 3 + j] = D[j * 3 + i] = -H;
    }
}

#endif
