/* vecmath.h -- inline helpers for the short vectors of the numerical
 * kernels (a few entries: a call to memcpy, memcmp, fmax or a norm loop
 * costs more than the work): copy, bitwise equality, NaN-propagating
 * maxima, the infinity norm.  Used by the LU kernel (smalllu.c), the
 * integrators and the reduced integrators.  Header only; nothing fails.
 */
#ifndef DM_VECMATH_H
#define DM_VECMATH_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* y = x, n doubles, as an inline loop: the copies of a step are a few
 * doubles each and a memcpy call costs more than the copy.  (No restrict:
 * GCC would turn the loop back into a memmove call.) */
static inline void dm_vcopy(double *y, const double *x, size_t n)
{
  size_t i;
  for (i = 0; i < n; i++)
    y[i] = x[i];
}

/* x and y bitwise equal (memcmp semantics, inline). */
static inline int dm_same(const double *x, const double *y, size_t n)
{
  size_t i;
  for (i = 0; i < n; i++) {
    uint64_t a, b;
    memcpy(&a, x + i, sizeof a);
    memcpy(&b, y + i, sizeof b);
    if (a != b)
      return 0;
  }
  return 1;
}

/* max(a, b), NaN when either is NaN (fmax drops NaNs and is a libm call
 * at -O2). */
static inline double dm_max2(double a, double b)
{
  return a > b || a != a ? a : b;
}

static inline double dm_max3(double a, double b, double c)
{
  return dm_max2(dm_max2(a, b), c);
}

/* max |x_i|, NaN when some x_i is NaN (+-Inf gives Inf).  Inline and
 * without a branch per entry: it runs several times per Newton iteration on
 * vectors of a few entries, where a call to a loop with fmax or an early
 * return cost ~10% of a Gauss-2 step (perf).  Two max chains halve the
 * latency of the maxsd dependency. */
static inline double dm_norm_inf(const double *x, size_t n)
{
  double m0 = 0.0, m1 = 0.0;
  int nan = 0;
  size_t i;
  for (i = 0; i + 1 < n; i += 2) {
    double a = fabs(x[i]), b = fabs(x[i + 1]);
    m0 = a > m0 ? a : m0;
    m1 = b > m1 ? b : m1;
    nan |= (a != a) | (b != b);
  }
  if (i < n) {
    double a = fabs(x[i]);
    m0 = a > m0 ? a : m0;
    nan |= a != a;
  }
  return nan ? NAN : m0 > m1 ? m0 : m1;
}

#endif
