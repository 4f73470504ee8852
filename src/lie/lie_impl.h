/* lie_impl.h -- private to src/lie: the coefficient functions with
 * removable singularities (series below a threshold), the SO(3) and 3-vector
 * kernels as inline functions (the integrators call them on their hot
 * path), and the type objects of the families.  Not part of the API. */
#ifndef DM_LIE_IMPL_H
#define DM_LIE_IMPL_H

#include <math.h>
#include <stddef.h>

#include "lie/lie.h"

/* {==== coefficient functions of t = theta^2 ============================
 * Below the threshold each is the Taylor series in t (Horner), above it the
 * closed form; the thresholds are where the closed form loses no more than
 * a few ulps to cancellation, and the series is truncated where its next
 * term is below 1e-17 relative (coefficients from exact rationals). */

static inline double dm_lie_horner(const double *c, int n, double t)
{
  double s = c[n - 1];
  int i;
  for (i = n - 2; i >= 0; i--)
    s = s * t + c[i];
  return s;
}

/* sin(th)/th */
static const double dm_lie_ser_sinc[] = {1.0, -1.0 / 6, 1.0 / 120, -1.0 / 5040, 1.0 / 362880,
                           -1.0 / 39916800};

static inline double dm_lie_sinc(double t)
{
  double th;
  if (t < 1e-2)
    return dm_lie_horner(dm_lie_ser_sinc, 6, t);
  th = sqrt(t);
  return sin(th) / th;
}

/* (1 - cos th)/th^2 = 2 sin^2(th/2)/th^2 */
static const double dm_lie_ser_cosc[] = {0.5, -1.0 / 24, 1.0 / 720, -1.0 / 40320, 1.0 / 3628800,
                           -1.0 / 479001600};

static inline double dm_lie_cosc(double t)
{
  double th, s;
  if (t < 1e-2)
    return dm_lie_horner(dm_lie_ser_cosc, 6, t);
  th = sqrt(t);
  s = sin(0.5 * th) / th;
  return 2.0 * s * s;
}

/* (th - sin th)/th^3 */
static const double dm_lie_ser_sinc3[] = {
  0.16666666666666666, -0.0083333333333333332, 0.00019841269841269841,
  -2.7557319223985893e-06, 2.505210838544172e-08, -1.6059043836821613e-10,
  7.6471637318198164e-13, -2.8114572543455206e-15, 8.2206352466243295e-18,
  -1.9572941063391263e-20, 3.8681701706306841e-23, -6.4469502843844736e-26,
  9.183689863795546e-29, -1.1309962886447716e-31, 1.2161250415535179e-34};

static inline double dm_lie_sinc3(double t)
{
  double th;
  if (t < 4.0)
    return dm_lie_horner(dm_lie_ser_sinc3, 15, t);
  th = sqrt(t);
  return (th - sin(th)) / (t * th);
}

/* (1 - (th/2) cot(th/2))/th^2: the coefficient of hat(w)^2 in dexp^-1 of
 * SO(3) (finite at th = pi, singular at 2 pi) */
static const double dm_lie_ser_dexpinv_coef[] = {
  0.083333333333333329, 0.0013888888888888889, 3.3068783068783071e-05,
  8.2671957671957675e-07, 2.08767569878681e-08, 5.2841901386874932e-10,
  1.3382536530684679e-11, 3.3896802963225827e-13, 8.5860620562778452e-15,
  2.1748686985580619e-16, 5.5090028283602295e-18, 1.3954464685812522e-19,
  3.5347070396294673e-21, 8.9535174270375463e-23, 2.2679524523376829e-24,
  5.7447906688722025e-26, 1.455172475614865e-27};

static inline double dm_lie_dexpinv_coef(double t)
{
  double th;
  if (t < 4.0)
    return dm_lie_horner(dm_lie_ser_dexpinv_coef, 17, t);
  th = sqrt(t);
  return (1.0 - 0.5 * th * cos(0.5 * th) / sin(0.5 * th)) / t;
}

/* (th^2/2 + cos th - 1)/th^4 */
static const double dm_lie_ser_coefE[] = {
  0.041666666666666664, -0.0013888888888888889, 2.4801587301587302e-05,
  -2.7557319223985888e-07, 2.08767569878681e-09, -1.1470745597729725e-11,
  4.7794773323873853e-14, -1.5619206968586225e-16, 4.1103176233121648e-19,
  -8.8967913924505741e-22, 1.6117375710961184e-24, -2.4795962632247976e-27,
  3.2798892370698378e-30, -3.7699876288159054e-33};

static inline double dm_lie_coefE(double t)
{
  if (t < 4.0)
    return dm_lie_horner(dm_lie_ser_coefE, 14, t);
  return (0.5 * t + cos(sqrt(t)) - 1.0) / (t * t);
}

/* (2 th - 3 sin th + th cos th)/(2 th^5) */
static const double dm_lie_ser_coefG[] = {
  0.0083333333333333332, -0.00039682539682539683, 8.2671957671957678e-06,
  -1.0020843354176688e-07, 8.0295219184108074e-10, -4.5882982390918896e-12,
  1.9680200780418645e-14, -6.5765081972994636e-17, 1.7615646957052136e-19,
  -3.8681701706306839e-22, 7.0916453128229206e-25, -1.1020427836554655e-27,
  1.4702951752382032e-30, -1.7025750581749252e-33};

static inline double dm_lie_coefG(double t)
{
  double th;
  if (t < 4.0)
    return dm_lie_horner(dm_lie_ser_coefG, 14, t);
  th = sqrt(t);
  return (2.0 * th - 3.0 * sin(th) + th * cos(th)) / (2.0 * t * t * th);
}

/* th/sin(th) for the logarithm (th in [0, pi/2] where it is used) */
static const double dm_lie_ser_invsinc[] = {1.0, 1.0 / 6, 7.0 / 360, 31.0 / 15120, 127.0 / 604800,
                           73.0 / 3421440};

static inline double dm_lie_invsinc(double t)
{
  double th;
  if (t < 1e-2)
    return dm_lie_horner(dm_lie_ser_invsinc, 6, t);
  th = sqrt(t);
  return th / sin(th);
}

/* The principal value of an angle, in (-pi, pi]. */
static inline double dm_lie_wrap(double a)
{
  double r = remainder(a, 2.0 * M_PI);
  return r <= -M_PI ? r + 2.0 * M_PI : r;
}

/* }====================================================================== */

/* {==== 3-vectors and 3x3 row-major matrices ============================ */

static inline void dm_v3_cross(const double *a, const double *b, double *c)
{
  double c0 = a[1] * b[2] - a[2] * b[1];
  double c1 = a[2] * b[0] - a[0] * b[2];
  double c2 = a[0] * b[1] - a[1] * b[0];
  c[0] = c0;
  c[1] = c1;
  c[2] = c2;
}

static inline double dm_v3_dot(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* C = A B (C may alias A or B): every product in a local first */
static inline void dm_m3_mul(const double *A, const double *B, double *C)
{
  double c0 = A[0] * B[0] + A[1] * B[3] + A[2] * B[6];
  double c1 = A[0] * B[1] + A[1] * B[4] + A[2] * B[7];
  double c2 = A[0] * B[2] + A[1] * B[5] + A[2] * B[8];
  double c3 = A[3] * B[0] + A[4] * B[3] + A[5] * B[6];
  double c4 = A[3] * B[1] + A[4] * B[4] + A[5] * B[7];
  double c5 = A[3] * B[2] + A[4] * B[5] + A[5] * B[8];
  double c6 = A[6] * B[0] + A[7] * B[3] + A[8] * B[6];
  double c7 = A[6] * B[1] + A[7] * B[4] + A[8] * B[7];
  double c8 = A[6] * B[2] + A[7] * B[5] + A[8] * B[8];
  C[0] = c0, C[1] = c1, C[2] = c2, C[3] = c3, C[4] = c4, C[5] = c5;
  C[6] = c6, C[7] = c7, C[8] = c8;
}

/* C = A^T B */
static inline void dm_m3_tmul(const double *A, const double *B, double *C)
{
  double T[9];
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      T[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
  for (i = 0; i < 9; i++)
    C[i] = T[i];
}

/* Solve A x = b for a 3x3 A by its adjugate (Cramer): 0, or -1 when
 * |det A| is not above 1e-300 or not finite.  b is overwritten by x.  Used
 * on the well-conditioned Jacobians of the rotation equations, where it
 * costs a third of a pivoting LU. */
static inline int dm_m3_solve(const double *A, double *b)
{
  double c0 = A[4] * A[8] - A[5] * A[7], c1 = A[5] * A[6] - A[3] * A[8];
  double c2 = A[3] * A[7] - A[4] * A[6];
  double det = A[0] * c0 + A[1] * c1 + A[2] * c2, x0, x1, x2;
  if (!(fabs(det) > 1e-300) || !isfinite(det))
    return -1;
  x0 = (c0 * b[0] + (A[2] * A[7] - A[1] * A[8]) * b[1] + (A[1] * A[5] - A[2] * A[4]) * b[2]) / det;
  x1 = (c1 * b[0] + (A[0] * A[8] - A[2] * A[6]) * b[1] + (A[2] * A[3] - A[0] * A[5]) * b[2]) / det;
  x2 = (c2 * b[0] + (A[1] * A[6] - A[0] * A[7]) * b[1] + (A[0] * A[4] - A[1] * A[3]) * b[2]) / det;
  b[0] = x0, b[1] = x1, b[2] = x2;
  return 0;
}

/* y = A x, y = A^T x (y may alias x) */
static inline void dm_m3_apply(const double *A, const double *x, double *y)
{
  double y0 = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
  double y1 = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
  double y2 = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
  y[0] = y0;
  y[1] = y1;
  y[2] = y2;
}

static inline void dm_m3_tapply(const double *A, const double *x, double *y)
{
  double y0 = A[0] * x[0] + A[3] * x[1] + A[6] * x[2];
  double y1 = A[1] * x[0] + A[4] * x[1] + A[7] * x[2];
  double y2 = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
  y[0] = y0;
  y[1] = y1;
  y[2] = y2;
}

/* M = d I + b hat(w) + c w w^T, written with leading dimension ld. */
static inline void dm_so3_poly_d(const double *w, double d, double b, double c, double *M,
                                 size_t ld)
{
  M[0] = d + c * w[0] * w[0];
  M[1] = c * w[0] * w[1] - b * w[2];
  M[2] = c * w[0] * w[2] + b * w[1];
  M[ld] = c * w[0] * w[1] + b * w[2];
  M[ld + 1] = d + c * w[1] * w[1];
  M[ld + 2] = c * w[1] * w[2] - b * w[0];
  M[2 * ld] = c * w[0] * w[2] - b * w[1];
  M[2 * ld + 1] = c * w[1] * w[2] + b * w[0];
  M[2 * ld + 2] = d + c * w[2] * w[2];
}

/* M = a I + b hat(w) + c hat(w)^2 = (a - c|w|^2) I + b hat(w) + c w w^T */
static inline void dm_so3_poly(const double *w, double a, double b, double c, double *M,
                               size_t ld)
{
  dm_so3_poly_d(w, a - c * dm_v3_dot(w, w), b, c, M, ld);
}

/* y = (a I + b hat(w) + c hat(w)^2) x (y may alias x) */
static inline void dm_so3_poly_apply(const double *w, double a, double b, double c,
                                     const double *x, double *y)
{
  double wx[3], wwx[3];
  dm_v3_cross(w, x, wx);
  dm_v3_cross(w, wx, wwx);
  y[0] = a * x[0] + b * wx[0] + c * wwx[0];
  y[1] = a * x[1] + b * wx[1] + c * wwx[1];
  y[2] = a * x[2] + b * wx[2] + c * wwx[2];
}

/* SO(3) exp (Rodrigues): cos(th) I + A hat(w) + B w w^T with A = sin th/th,
 * B = (1 - cos th)/th^2; one sine and cosine of th (the compiler pairs them),
 * 1 - cos th = sin^2 th/(1 + cos th) while cos th > 0 (no cancellation);
 * the series below t = 1e-2. */
static inline void dm_so3_exp(const double *w, double *R)
{
  double t = dm_v3_dot(w, w), A, B, d;
  if (t < 1e-2) {
    A = dm_lie_horner(dm_lie_ser_sinc, 6, t);
    B = dm_lie_horner(dm_lie_ser_cosc, 6, t);
    d = 1.0 - B * t;
  } else {
    double th = sqrt(t), s = sin(th), c = cos(th);
    A = s / th;
    B = (c > 0.0 ? s * s / (1.0 + c) : 1.0 - c) / t;
    d = c;
  }
  dm_so3_poly_d(w, d, A, B, R, 3);
}

/* SO(3) Cayley map I + (4/(4 + |w|^2)) (hat(w) + hat(w)^2/2) */
static inline void dm_so3_cay(const double *w, double *R)
{
  double k = 4.0 / (4.0 + dm_v3_dot(w, w));
  dm_so3_poly(w, 1.0, k, 0.5 * k, R, 3);
}

void dm_so3_log(const double *R, double *w);

/* }====================================================================== */

/* {==== family type objects and shared helpers =========================== */

extern const dm_lie_sym_type dm_lie_sym_rn, dm_lie_sym_tn, dm_lie_sym_so3,
  dm_lie_sym_se2, dm_lie_sym_se3, dm_lie_sym_product;
extern const dm_lie_type dm_lie_type_rn, dm_lie_type_so2, dm_lie_type_tn,
  dm_lie_type_so3, dm_lie_type_se2, dm_lie_type_se3, dm_lie_type_product;

/* Zero an r x c block with leading dimension ld. */
static inline void dm_lie_zero(double *M, size_t r, size_t c, size_t ld)
{
  size_t i, j;
  for (i = 0; i < r; i++)
    for (j = 0; j < c; j++)
      M[i * ld + j] = 0.0;
}

/* Polar factor of a 3x3 block (nearest rotation, det +1), in place. */
void dm_lie_polar3(double *R);
/* max |R^T R - I|, *det_ok = det R > 0 */
double dm_lie_orth_defect3(const double *R, int *det_ok);

/* }====================================================================== */

#endif
