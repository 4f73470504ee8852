/* se3.c -- the rigid motions SE(3): elements (R, p) stored as R row-major
 * then p, algebra coordinates (omega, v) with the rotation first.  The
 * exponential's Jacobian is block triangular, [[V, 0], [Q, V]] with V the
 * SO(3) Jacobian and Q the coupling block in closed form (doc/lie.md). */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lie/lie_impl.h"

static void hat3(const double *w, double *W)
{
  dm_so3_poly(w, 0.0, 1.0, 0.0, W, 3);
}

static void m3_axpy(double a, const double *X, double *Y)
{
  int i;
  for (i = 0; i < 9; i++)
    Y[i] += a * X[i];
}

/* The coupling block Q(w, v) of the right-trivialized dexp:
 * Q = V/2 + C (WV + VW + WVW) + E (WWV + VWW - 3 WVW) + G (WVWW + WWVW)
 * with W = hat(w), V = hat(v) and the series-safe coefficients C, E, G. */
static void se3_Q(const double *w, const double *v, double *Q)
{
  double t = dm_v3_dot(w, w), C = dm_lie_sinc3(t), E = dm_lie_coefE(t), G = dm_lie_coefG(t);
  double W[9], V[9], WV[9], VW[9], WVW[9], WWV[9], VWW[9], X[9], Y[9];
  int i;
  hat3(w, W);
  hat3(v, V);
  dm_m3_mul(W, V, WV);
  dm_m3_mul(V, W, VW);
  dm_m3_mul(WV, W, WVW);
  dm_m3_mul(W, WV, WWV);
  dm_m3_mul(VW, W, VWW);
  for (i = 0; i < 9; i++)
    Q[i] = 0.5 * V[i] + C * (WV[i] + VW[i] + WVW[i]) + E * (WWV[i] + VWW[i] - 3.0 * WVW[i]);
  dm_m3_mul(WVW, W, X);
  dm_m3_mul(W, WVW, Y);
  m3_axpy(G, X, Q);
  m3_axpy(G, Y, Q);
}

static void put3(const double *A, double *M, size_t ld)
{
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      M[i * ld + j] = A[3 * i + j];
}

/* [[A, 0], [B, A]] into a 6x6 block */
static void put_tri(const double *A, const double *B, double *M, size_t ld)
{
  put3(A, M, ld);
  dm_lie_zero(M + 3, 3, 3, ld);
  put3(B, M + 3 * ld, ld);
  put3(A, M + 3 * ld + 3, ld);
}

static void se3_identity(const dm_lie_group *G, double *g)
{
  static const double I[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  memcpy(g, I, sizeof I);
}

static void se3_compose(const dm_lie_group *G, const double *a, const double *b, double *ab)
{
  double p[3];
  dm_m3_apply(a, b + 9, p);
  p[0] += a[9];
  p[1] += a[10];
  p[2] += a[11];
  dm_m3_mul(a, b, ab);
  ab[9] = p[0];
  ab[10] = p[1];
  ab[11] = p[2];
}

static void se3_inverse(const dm_lie_group *G, const double *a, double *ai)
{
  double p[3];
  dm_m3_tapply(a, a + 9, p);
  dm_lie_type_so3.inverse(G, a, ai);
  ai[9] = -p[0];
  ai[10] = -p[1];
  ai[11] = -p[2];
}

static void se3_exp(const dm_lie_group *G, const double *xi, double *g)
{
  double t = dm_v3_dot(xi, xi), p[3];
  dm_so3_poly_apply(xi, 1.0, dm_lie_cosc(t), dm_lie_sinc3(t), xi + 3, p);
  dm_so3_exp(xi, g);
  memcpy(g + 9, p, sizeof p);
}

static void se3_log(const dm_lie_group *G, const double *g, double *xi)
{
  double w[3], t;
  dm_so3_log(g, w);
  t = dm_v3_dot(w, w);
  dm_so3_poly_apply(w, 1.0, -0.5, dm_lie_dexpinv_coef(t), g + 9, xi + 3);
  memcpy(xi, w, sizeof w);
}

/* Ad_(R,p) = [[R, 0], [hat(p) R, R]] */
static void se3_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  double P[9], PR[9];
  hat3(g + 9, P);
  dm_m3_mul(P, g, PR);
  put_tri(g, PR, M, ld);
}

static void se3_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld)
{
  double W[9], V[9];
  hat3(xi, W);
  hat3(xi + 3, V);
  put_tri(W, V, M, ld);
}

static void se3_bracket(const dm_lie_group *G, const double *a, const double *b, double *c)
{
  double w[3], v1[3], v2[3];
  dm_v3_cross(a, b, w);
  dm_v3_cross(a, b + 3, v1);
  dm_v3_cross(b, a + 3, v2);
  c[0] = w[0];
  c[1] = w[1];
  c[2] = w[2];
  c[3] = v1[0] - v2[0];
  c[4] = v1[1] - v2[1];
  c[5] = v1[2] - v2[2];
}

/* [[V, 0], [Q, V]]; inverse [[V^-1, 0], [-V^-1 Q V^-1, V^-1]] */
static void se3_dexp(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  double t = dm_v3_dot(xi, xi), V[9], Q[9];
  se3_Q(xi, xi + 3, Q);
  if (!inv) {
    dm_so3_poly(xi, 1.0, dm_lie_cosc(t), dm_lie_sinc3(t), V, 3);
    put_tri(V, Q, M, ld);
  } else {
    double T[9];
    int i;
    dm_so3_poly(xi, 1.0, -0.5, dm_lie_dexpinv_coef(t), V, 3);
    dm_m3_mul(V, Q, T);
    dm_m3_mul(T, V, T);
    for (i = 0; i < 9; i++)
      T[i] = -T[i];
    put_tri(V, T, M, ld);
  }
}

/* (I - hat(w)/2)^-1 = I + k (hat/2 + hat^2/4), k = 4/(4 + |w|^2);
 * (I + hat(w)/2)^-1 the same with -w */
static void se3_cay(const dm_lie_group *G, const double *xi, double *g)
{
  double k = 4.0 / (4.0 + dm_v3_dot(xi, xi)), p[3];
  dm_so3_poly_apply(xi, 1.0, 0.5 * k, 0.25 * k, xi + 3, p);
  dm_so3_cay(xi, g);
  memcpy(g + 9, p, sizeof p);
}

static int se3_icay(const dm_lie_group *G, const double *g, double *xi)
{
  double w[3];
  if (dm_lie_type_so3.icay(G, g, w) != DM_OK)
    return DM_EDOM;
  dm_so3_poly_apply(w, 1.0, -0.5, 0.0, g + 9, xi + 3);
  memcpy(xi, w, sizeof w);
  return DM_OK;
}

/* dcay(w, v) = [[dcay_SO3(w), 0], [A hat(u)/2, A]] with A = (I - hat(w)/2)^-1
 * and u = (I + hat(w)/2)^-1 v (from dcay_X Y = (I - X/2)^-1 Y (I + X/2)^-1
 * in the 4x4 representation); inverse [[dcay_SO3^-1, 0], [-hat(u) D^-1/2,
 * I - hat(w)/2]]. */
static void se3_dcay(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  double t = dm_v3_dot(xi, xi), k = 4.0 / (4.0 + t), u[3], U[9], A[9], D[9], B[9];
  int i;
  dm_so3_poly_apply(xi, 1.0, -0.5 * k, 0.25 * k, xi + 3, u);
  hat3(u, U);
  if (!inv) {
    dm_so3_poly(xi, k, 0.5 * k, 0.0, D, 3);
    dm_so3_poly(xi, 1.0, 0.5 * k, 0.25 * k, A, 3);
    dm_m3_mul(A, U, B);
    for (i = 0; i < 9; i++)
      B[i] *= 0.5;
  } else {
    dm_so3_poly(xi, 1.0 + 0.25 * t, -0.5, 0.25, D, 3);
    dm_so3_poly(xi, 1.0, -0.5, 0.0, A, 3);
    dm_m3_mul(U, D, B);
    for (i = 0; i < 9; i++)
      B[i] *= -0.5;
  }
  put3(D, M, ld);
  dm_lie_zero(M + 3, 3, 3, ld);
  put3(B, M + 3 * ld, ld);
  put3(A, M + 3 * ld + 3, ld);
}

static void se3_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  int i;
  dm_so3_poly(xi, 0.0, 1.0, 0.0, A, ld);
  for (i = 0; i < 3; i++)
    A[i * ld + 3] = xi[3 + i];
  for (i = 0; i < 4; i++)
    A[3 * ld + i] = 0.0;
}

static void se3_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  int i;
  dm_lie_type_so3.vee(G, A, ld, xi);
  for (i = 0; i < 3; i++)
    xi[3 + i] = A[i * ld + 3];
}

static void se3_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  int i;
  put3(g, M, ld);
  for (i = 0; i < 3; i++)
    M[i * ld + 3] = g[9 + i];
  for (i = 0; i < 3; i++)
    M[3 * ld + i] = 0.0;
  M[3 * ld + 3] = 1.0;
}

static int se3_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g)
{
  int i, j;
  for (i = 0; i < 3; i++)
    if (fabs(M[3 * ld + i]) > 1e-12)
      return DM_EDOM;
  if (fabs(M[3 * ld + 3] - 1.0) > 1e-12)
    return DM_EDOM;
  for (i = 0; i < 3; i++) {
    for (j = 0; j < 3; j++)
      g[3 * i + j] = M[i * ld + j];
    g[9 + i] = M[i * ld + 3];
  }
  return DM_OK;
}

static void se3_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  dm_m3_apply(g, x, y);
  y[0] += g[9];
  y[1] += g[10];
  y[2] += g[11];
}

static void se3_normalize(const dm_lie_group *G, double *g)
{
  dm_lie_polar3(g);
}

static double se3_defect(const dm_lie_group *G, const double *g, int *det_ok)
{
  return dm_lie_orth_defect3(g, det_ok);
}

/* LEFT: k < 3: (R hat(e_k), 0), else (0, R e_(k-3));
 * RIGHT: k < 3: (hat(e_k) R, e_k x p), else (0, e_(k-3)) */
static void se3_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                          double *dg)
{
  double e[3] = {0, 0, 0};
  memset(dg, 0, 12 * sizeof *dg);
  if (k < 3) {
    dm_lie_type_so3.generator(G, g, k, side, dg);
    if (side == DM_LIE_RIGHT) {
      e[k] = 1.0;
      dm_v3_cross(e, g + 9, dg + 9);
    }
  } else if (side == DM_LIE_LEFT) {
    dg[9] = g[k - 3];
    dg[10] = g[3 + k - 3];
    dg[11] = g[6 + k - 3];
  } else {
    dg[9 + k - 3] = 1.0;
  }
}

const dm_lie_type dm_lie_type_se3 = {
  "SE3", DM_LIE_SE3, se3_identity, se3_compose, se3_inverse, se3_exp, se3_log,
  se3_Ad, se3_ad, se3_bracket, se3_dexp, se3_cay, se3_icay, se3_dcay, se3_hat,
  se3_vee, se3_matrix, se3_from_matrix, se3_act, se3_normalize, se3_defect,
  se3_generator, &dm_lie_sym_se3
};
