/* so3.c -- the rotation group SO(3): the fixed 3x3 kernels (exp, log,
 * Jacobians, Cayley map, polar projection) and its type object.
 * Conventions and formulas: doc/lie.md; the small kernels also serve SE(3)
 * (se3.c) and the integrators (lie_impl.h has the inline ones). */
#include <config.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_linalg.h>

#include "lie/lie_impl.h"

/* {==== kernels ========================================================== */

/* log: the angle phi = atan2(|s|, c) from c = (tr R - 1)/2 and
 * s = vee(R - R^T)/2 = sin(phi) n is accurate at every angle.  For
 * phi < pi/2 the axis comes from s (w = (phi / sin phi) s, a series near
 * 0); beyond, from the symmetric part (R + R^T)/2 - c I = (1 - c) n n^T,
 * whose largest diagonal entry gives a component of n without
 * cancellation, with the sign of n . s (at exactly pi s = 0 and the
 * largest component is taken positive). */
void dm_so3_log(const double *R, double *w)
{
  double c = 0.5 * (R[0] + R[4] + R[8] - 1.0);
  double s[3], sn, phi;
  s[0] = 0.5 * (R[7] - R[5]);
  s[1] = 0.5 * (R[2] - R[6]);
  s[2] = 0.5 * (R[3] - R[1]);
  sn = sqrt(dm_v3_dot(s, s));
  phi = atan2(sn, c);
  if (c > 0.0) {
    double k = dm_lie_invsinc(phi * phi);
    w[0] = k * s[0];
    w[1] = k * s[1];
    w[2] = k * s[2];
  } else {
    double B[9], n[3], den = 1.0 - c, nn;
    int i, j, m = 0;
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++)
        B[3 * i + j] = 0.5 * (R[3 * i + j] + R[3 * j + i]) - (i == j ? c : 0.0);
    for (i = 1; i < 3; i++)
      if (B[4 * i] > B[4 * m])
        m = i;
    nn = sqrt(fmax(B[4 * m], 0.0) * den);
    for (i = 0; i < 3; i++)
      n[i] = i == m ? nn / den : B[3 * i + m] / nn;
    nn = sqrt(dm_v3_dot(n, n));
    if (dm_v3_dot(n, s) < 0.0)
      nn = -nn;
    for (i = 0; i < 3; i++)
      w[i] = phi * n[i] / nn;
  }
}

double dm_lie_orth_defect3(const double *R, int *det_ok)
{
  double P[9], m = 0.0, det;
  int i;
  dm_m3_tmul(R, R, P);
  P[0] -= 1.0;
  P[4] -= 1.0;
  P[8] -= 1.0;
  for (i = 0; i < 9; i++)
    m = fabs(P[i]) > m || P[i] != P[i] ? fabs(P[i]) : m;
  det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
        R[2] * (R[3] * R[7] - R[4] * R[6]);
  if (det_ok)
    *det_ok = det > 0.0;
  return m;
}

/* One Bjorck step R <- R (3 I - R^T R)/2: quadratic convergence to the
 * polar factor from a nearly orthogonal R. */
static void bjorck3(double *R)
{
  double a[9];
  int i;
  dm_m3_tmul(R, R, a);
  for (i = 0; i < 9; i++)
    a[i] = (i % 4 == 0 ? 1.5 : 0.0) - 0.5 * a[i];
  dm_m3_mul(R, a, R);
}

/* The polar factor.  Nearly orthogonal input (defect < 1e-4, det > 0: what
 * long products of rotations produce) takes Bjorck steps (two bring 1e-4
 * to round-off); anything else R <- U V^T from R = U S V^T (GSL's
 * one-sided Jacobi SVD on stack storage, no allocation), a reflection
 * turned into the nearest rotation by flipping the singular direction of
 * the smallest value, then one Bjorck step for the SVD's few ulps. */
void dm_lie_polar3(double *R)
{
  double a[9], v[9], s[3], d;
  gsl_matrix_view A = gsl_matrix_view_array(a, 3, 3), V = gsl_matrix_view_array(v, 3, 3);
  gsl_vector_view S = gsl_vector_view_array(s, 3);
  int i, j, m = 0, ok;
  d = dm_lie_orth_defect3(R, &ok);
  if (ok && d < 1e-4) {
    bjorck3(R);
    if (d > 1e-8)
      bjorck3(R);
    return;
  }
  memcpy(a, R, sizeof a);
  if (gsl_linalg_SV_decomp_jacobi(&A.matrix, &V.matrix, &S.vector) != 0)
    return;
  d = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
      a[2] * (a[3] * a[7] - a[4] * a[6]);
  d *= v[0] * (v[4] * v[8] - v[5] * v[7]) - v[1] * (v[3] * v[8] - v[5] * v[6]) +
       v[2] * (v[3] * v[7] - v[4] * v[6]);
  if (d < 0.0) {                      /* flip the direction of the smallest value */
    for (i = 1; i < 3; i++)
      if (s[i] < s[m])
        m = i;
    a[m] = -a[m];
    a[3 + m] = -a[3 + m];
    a[6 + m] = -a[6 + m];
  }
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      R[3 * i + j] = a[3 * i] * v[3 * j] + a[3 * i + 1] * v[3 * j + 1] + a[3 * i + 2] * v[3 * j + 2];
  bjorck3(R);
}

/* }====================================================================== */

/* {==== the type object ================================================== */

static void so3_identity(const dm_lie_group *G, double *g)
{
  static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  memcpy(g, I, sizeof I);
}

static void so3_compose(const dm_lie_group *G, const double *a, const double *b, double *ab)
{
  dm_m3_mul(a, b, ab);
}

static void so3_inverse(const dm_lie_group *G, const double *a, double *ai)
{
  double t;
  ai[0] = a[0];
  ai[4] = a[4];
  ai[8] = a[8];
  t = a[1], ai[1] = a[3], ai[3] = t;
  t = a[2], ai[2] = a[6], ai[6] = t;
  t = a[5], ai[5] = a[7], ai[7] = t;
}

static void so3_exp(const dm_lie_group *G, const double *xi, double *g)
{
  dm_so3_exp(xi, g);
}

static void so3_log(const dm_lie_group *G, const double *g, double *xi)
{
  dm_so3_log(g, xi);
}

static void so3_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      M[i * ld + j] = g[3 * i + j];
}

static void so3_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld)
{
  dm_so3_poly(xi, 0.0, 1.0, 0.0, M, ld);
}

static void so3_bracket(const dm_lie_group *G, const double *a, const double *b, double *c)
{
  dm_v3_cross(a, b, c);
}

/* V = I + B hat + C hat^2; V^-1 = I - hat/2 + D hat^2 */
static void so3_dexp(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  double t = dm_v3_dot(xi, xi);
  if (inv)
    dm_so3_poly(xi, 1.0, -0.5, dm_lie_dexpinv_coef(t), M, ld);
  else
    dm_so3_poly(xi, 1.0, dm_lie_cosc(t), dm_lie_sinc3(t), M, ld);
}

static void so3_cay(const dm_lie_group *G, const double *xi, double *g)
{
  dm_so3_cay(xi, g);
}

/* icay(R) = 2 vee(R - R^T)/(1 + tr R): undefined at angle pi */
static int so3_icay(const dm_lie_group *G, const double *g, double *xi)
{
  double d = 1.0 + g[0] + g[4] + g[8];
  if (!(d > 0.0))
    return DM_EDOM;
  xi[0] = 2.0 * (g[7] - g[5]) / d;
  xi[1] = 2.0 * (g[2] - g[6]) / d;
  xi[2] = 2.0 * (g[3] - g[1]) / d;
  return DM_OK;
}

/* dcay = (4/(4 + |w|^2)) (I + hat/2); inverse I - hat/2 + w w^T/4 */
static void so3_dcay(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  double t = dm_v3_dot(xi, xi);
  if (inv)
    dm_so3_poly(xi, 1.0 + 0.25 * t, -0.5, 0.25, M, ld);
  else {
    double k = 4.0 / (4.0 + t);
    dm_so3_poly(xi, k, 0.5 * k, 0.0, M, ld);
  }
}

static void so3_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  dm_so3_poly(xi, 0.0, 1.0, 0.0, A, ld);
}

static void so3_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  xi[0] = 0.5 * (A[2 * ld + 1] - A[ld + 2]);
  xi[1] = 0.5 * (A[2] - A[2 * ld]);
  xi[2] = 0.5 * (A[ld] - A[1]);
}

static void so3_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  so3_Ad(G, g, M, ld);
}

static int so3_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g)
{
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      g[3 * i + j] = M[i * ld + j];
  return DM_OK;
}

static void so3_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  dm_m3_apply(g, x, y);
}

static void so3_normalize(const dm_lie_group *G, double *g)
{
  dm_lie_polar3(g);
}

static double so3_defect(const dm_lie_group *G, const double *g, int *det_ok)
{
  return dm_lie_orth_defect3(g, det_ok);
}

/* LEFT: R hat(e_k) (column j of R hat(e_k) = R (e_k x e_j));
 * RIGHT: hat(e_k) R */
static void so3_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                          double *dg)
{
  double e[3] = {0, 0, 0}, E[9];
  e[k] = 1.0;
  dm_so3_poly(e, 0.0, 1.0, 0.0, E, 3);
  if (side == DM_LIE_LEFT)
    dm_m3_mul(g, E, dg);
  else
    dm_m3_mul(E, g, dg);
}

const dm_lie_type dm_lie_type_so3 = {
  "SO3", DM_LIE_SO3, so3_identity, so3_compose, so3_inverse, so3_exp, so3_log,
  so3_Ad, so3_ad, so3_bracket, so3_dexp, so3_cay, so3_icay, so3_dcay, so3_hat,
  so3_vee, so3_matrix, so3_from_matrix, so3_act, so3_normalize, so3_defect,
  so3_generator, &dm_lie_sym_so3
};

/* }====================================================================== */
