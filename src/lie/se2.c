/* se2.c -- the planar rigid motions SE(2): elements (theta, x, y) with the
 * angle unwrapped, algebra (omega, vx, vy).  With J the rotation by pi/2,
 * exp(omega, v) = (omega, W v), W = sinc I + omega cosc J, and the
 * Jacobians are block triangular (doc/lie.md). */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lie/lie_impl.h"

static void se2_identity(const dm_lie_group *G, double *g)
{
  g[0] = g[1] = g[2] = 0.0;
}

static void se2_compose(const dm_lie_group *G, const double *a, const double *b, double *ab)
{
  double c = cos(a[0]), s = sin(a[0]);
  double x = a[1] + c * b[1] - s * b[2], y = a[2] + s * b[1] + c * b[2];
  ab[0] = a[0] + b[0];
  ab[1] = x;
  ab[2] = y;
}

static void se2_inverse(const dm_lie_group *G, const double *a, double *ai)
{
  double c = cos(a[0]), s = sin(a[0]);
  double x = -(c * a[1] + s * a[2]), y = -(-s * a[1] + c * a[2]);
  ai[0] = -a[0];
  ai[1] = x;
  ai[2] = y;
}

static void se2_exp(const dm_lie_group *G, const double *xi, double *g)
{
  double w = xi[0], t = w * w, A = dm_lie_sinc(t), B = w * dm_lie_cosc(t);
  double x = A * xi[1] - B * xi[2], y = B * xi[1] + A * xi[2];
  g[0] = w;
  g[1] = x;
  g[2] = y;
}

/* W^-1 = a I - (phi/2) J, a = (phi/2) cot(phi/2) = 1 - phi^2 D(phi^2) */
static void se2_log(const dm_lie_group *G, const double *g, double *xi)
{
  double phi = dm_lie_wrap(g[0]), a = 1.0 - phi * phi * dm_lie_dexpinv_coef(phi * phi);
  double h = 0.5 * phi, x = a * g[1] + h * g[2], y = -h * g[1] + a * g[2];
  xi[0] = phi;
  xi[1] = x;
  xi[2] = y;
}

static void se2_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  double c = cos(g[0]), s = sin(g[0]);
  M[0] = 1.0, M[1] = 0.0, M[2] = 0.0;
  M[ld] = g[2], M[ld + 1] = c, M[ld + 2] = -s;
  M[2 * ld] = -g[1], M[2 * ld + 1] = s, M[2 * ld + 2] = c;
}

static void se2_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld)
{
  M[0] = 0.0, M[1] = 0.0, M[2] = 0.0;
  M[ld] = xi[2], M[ld + 1] = 0.0, M[ld + 2] = -xi[0];
  M[2 * ld] = -xi[1], M[2 * ld + 1] = xi[0], M[2 * ld + 2] = 0.0;
}

static void se2_bracket(const dm_lie_group *G, const double *a, const double *b, double *c)
{
  double x = -a[0] * b[2] + b[0] * a[2], y = a[0] * b[1] - b[0] * a[1];
  c[0] = 0.0;
  c[1] = x;
  c[2] = y;
}

/* [[1, 0], [a, W]] with a = (B vy + w C vx, -B vx + w C vy) (the sum of
 * ad^k/(k+1)!); inverse [[1, 0], [-W^-1 a, W^-1]] */
static void se2_dexp(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  double w = xi[0], t = w * w, B = dm_lie_cosc(t), C = w * dm_lie_sinc3(t);
  double a0 = B * xi[2] + C * xi[1], a1 = -B * xi[1] + C * xi[2];
  double W00, W01, W10, W11;
  if (!inv) {
    double A = dm_lie_sinc(t), Bw = w * B;
    W00 = A, W01 = -Bw, W10 = Bw, W11 = A;
  } else {
    double a = 1.0 - t * dm_lie_dexpinv_coef(t), h = 0.5 * w, b0, b1;
    W00 = a, W01 = h, W10 = -h, W11 = a;
    b0 = -(W00 * a0 + W01 * a1);
    b1 = -(W10 * a0 + W11 * a1);
    a0 = b0, a1 = b1;
  }
  M[0] = 1.0, M[1] = 0.0, M[2] = 0.0;
  M[ld] = a0, M[ld + 1] = W00, M[ld + 2] = W01;
  M[2 * ld] = a1, M[2 * ld + 1] = W10, M[2 * ld + 2] = W11;
}

/* cay(w, v) = (2 atan(w/2), (I - wJ/2)^-1 v), (I - wJ/2)^-1 = k (I + wJ/2),
 * k = 1/(1 + w^2/4) */
static void se2_cay(const dm_lie_group *G, const double *xi, double *g)
{
  double w = xi[0], k = 4.0 / (4.0 + w * w);
  double x = k * (xi[1] - 0.5 * w * xi[2]), y = k * (xi[2] + 0.5 * w * xi[1]);
  g[0] = 2.0 * atan(0.5 * w);
  g[1] = x;
  g[2] = y;
}

static int se2_icay(const dm_lie_group *G, const double *g, double *xi)
{
  double phi = dm_lie_wrap(g[0]), w, x, y;
  if (!(fabs(phi) < M_PI))
    return DM_EDOM;
  w = 2.0 * tan(0.5 * phi);
  x = g[1] + 0.5 * w * g[2];
  y = g[2] - 0.5 * w * g[1];
  xi[0] = w;
  xi[1] = x;
  xi[2] = y;
  return DM_OK;
}

/* [[k, 0], [-A J u/2, A]] with A = (I - wJ/2)^-1, u = (I + wJ/2)^-1 v,
 * k = 4/(4 + w^2); inverse [[1/k, 0], [J u/(2k), I - wJ/2]] */
static void se2_dcay(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  double w = xi[0], k = 4.0 / (4.0 + w * w);
  double u0 = k * (xi[1] + 0.5 * w * xi[2]), u1 = k * (xi[2] - 0.5 * w * xi[1]);
  double Ju0 = -u1, Ju1 = u0, d, b0, b1, A00, A01, A10, A11;
  if (!inv) {
    A00 = k, A01 = -0.5 * w * k, A10 = 0.5 * w * k, A11 = k;
    d = k;
    b0 = -0.5 * (A00 * Ju0 + A01 * Ju1);
    b1 = -0.5 * (A10 * Ju0 + A11 * Ju1);
  } else {
    A00 = 1.0, A01 = 0.5 * w, A10 = -0.5 * w, A11 = 1.0;
    d = 1.0 / k;
    b0 = 0.5 * Ju0 / k;
    b1 = 0.5 * Ju1 / k;
  }
  M[0] = d, M[1] = 0.0, M[2] = 0.0;
  M[ld] = b0, M[ld + 1] = A00, M[ld + 2] = A01;
  M[2 * ld] = b1, M[2 * ld + 1] = A10, M[2 * ld + 2] = A11;
}

static void se2_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  A[0] = 0.0, A[1] = -xi[0], A[2] = xi[1];
  A[ld] = xi[0], A[ld + 1] = 0.0, A[ld + 2] = xi[2];
  A[2 * ld] = 0.0, A[2 * ld + 1] = 0.0, A[2 * ld + 2] = 0.0;
}

static void se2_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  xi[0] = 0.5 * (A[ld] - A[1]);
  xi[1] = A[2];
  xi[2] = A[ld + 2];
}

static void se2_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  double c = cos(g[0]), s = sin(g[0]);
  M[0] = c, M[1] = -s, M[2] = g[1];
  M[ld] = s, M[ld + 1] = c, M[ld + 2] = g[2];
  M[2 * ld] = 0.0, M[2 * ld + 1] = 0.0, M[2 * ld + 2] = 1.0;
}

static int se2_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g)
{
  double c = M[0], s = M[ld];
  if (fabs(M[ld + 1] - c) > 1e-12 || fabs(M[1] + s) > 1e-12 ||
      fabs(c * c + s * s - 1.0) > 1e-10 || fabs(M[2 * ld]) > 1e-12 ||
      fabs(M[2 * ld + 1]) > 1e-12 || fabs(M[2 * ld + 2] - 1.0) > 1e-12)
    return DM_EDOM;
  g[0] = atan2(s, c);
  g[1] = M[2];
  g[2] = M[ld + 2];
  return DM_OK;
}

static void se2_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  double c = cos(g[0]), s = sin(g[0]), a = x[0], b = x[1];
  y[0] = g[1] + c * a - s * b;
  y[1] = g[2] + s * a + c * b;
}

static void se2_normalize(const dm_lie_group *G, double *g)
{
}

static double se2_defect(const dm_lie_group *G, const double *g, int *det_ok)
{
  if (det_ok)
    *det_ok = 1;
  return 0.0;
}

/* LEFT: (1, 0, 0), (0, R e1), (0, R e2); RIGHT: (1, J p), (0, e1), (0, e2) */
static void se2_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                          double *dg)
{
  double c = cos(g[0]), s = sin(g[0]);
  dg[0] = k == 0 ? 1.0 : 0.0;
  if (side == DM_LIE_LEFT) {
    dg[1] = k == 1 ? c : k == 2 ? -s : 0.0;
    dg[2] = k == 1 ? s : k == 2 ? c : 0.0;
  } else {
    dg[1] = k == 0 ? -g[2] : k == 1 ? 1.0 : 0.0;
    dg[2] = k == 0 ? g[1] : k == 2 ? 1.0 : 0.0;
  }
}

const dm_lie_type dm_lie_type_se2 = {
  "SE2", DM_LIE_SE2, se2_identity, se2_compose, se2_inverse, se2_exp, se2_log,
  se2_Ad, se2_ad, se2_bracket, se2_dexp, se2_cay, se2_icay, se2_dcay, se2_hat,
  se2_vee, se2_matrix, se2_from_matrix, se2_act, se2_normalize, se2_defect,
  se2_generator, &dm_lie_sym_se2
};
