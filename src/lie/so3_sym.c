/* so3_sym.c -- SO(3) and SE(3) on expressions: the formulas of so3.c and
 * se3.c node for node (same coefficients, same branches as selects). */
#include <config.h>
#include <string.h>

#include "lie/lie_sym_impl.h"

static E K(dm_expr_ctx *c, double x)
{
  return s_k(c, x);
}

static void hat3(dm_expr_ctx *c, const E *w, E *W)
{
  dm_lie_sym_so3_poly(c, w, K(c, 0), K(c, 1), K(c, 0), W, 3);
}

static void put3(const E *A, E *M, size_t ld)
{
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      M[i * ld + j] = A[3 * i + j];
}

static void put_tri(dm_expr_ctx *c, const E *A, const E *B, E *M, size_t ld)
{
  int i, j;
  put3(A, M, ld);
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      M[i * ld + 3 + j] = K(c, 0);
  put3(B, M + 3 * ld, ld);
  put3(A, M + 3 * ld + 3, ld);
}

/* {==== SO(3) ============================================================ */

static void so3_identity(dm_expr_ctx *c, const dm_lie_group *G, E *g)
{
  int i;
  for (i = 0; i < 9; i++)
    g[i] = K(c, i % 4 == 0 ? 1.0 : 0.0);
}

static void so3_compose(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab)
{
  dm_lie_sym_m3_mul(c, a, b, ab);
}

static void so3_inverse(dm_expr_ctx *c, const dm_lie_group *G, const E *a, E *ai)
{
  E t[9];
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      t[3 * i + j] = a[3 * j + i];
  memcpy(ai, t, sizeof t);
}

static void so3_exp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  dm_lie_sym_so3_exp(c, xi, g);
}

static void so3_log(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  dm_lie_sym_so3_log(c, g, xi);
}

static void so3_Ad(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  put3(g, M, ld);
}

static void so3_ad(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *M, size_t ld)
{
  dm_lie_sym_so3_poly(c, xi, K(c, 0), K(c, 1), K(c, 0), M, ld);
}

static void so3_dexp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                     size_t ld)
{
  E t = s_dot3(c, xi, xi);
  if (inv)
    dm_lie_sym_so3_poly(c, xi, K(c, 1), K(c, -0.5), dm_lie_sym_dexpinv_coef(c, t), M, ld);
  else
    dm_lie_sym_so3_poly(c, xi, K(c, 1), dm_lie_sym_cosc(c, t), dm_lie_sym_sinc3(c, t), M, ld);
}

/* 4/(4 + |w|^2) */
static E cayk(dm_expr_ctx *c, const E *w)
{
  return s_div(c, K(c, 4), s_add(c, K(c, 4), s_dot3(c, w, w)));
}

static void so3_cay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  E k = cayk(c, xi);
  dm_lie_sym_so3_poly(c, xi, K(c, 1), k, s_scale(c, 0.5, k), g, 3);
}

static void so3_icay(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  E d = s_add(c, s_add(c, s_add(c, K(c, 1), g[0]), g[4]), g[8]), f = s_div(c, K(c, 2), d);
  xi[0] = s_mul(c, f, s_sub(c, g[7], g[5]));
  xi[1] = s_mul(c, f, s_sub(c, g[2], g[6]));
  xi[2] = s_mul(c, f, s_sub(c, g[3], g[1]));
}

static void so3_dcay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                     size_t ld)
{
  if (inv)
    dm_lie_sym_so3_poly(c, xi, s_add(c, K(c, 1), s_scale(c, 0.25, s_dot3(c, xi, xi))),
                        K(c, -0.5), K(c, 0.25), M, ld);
  else {
    E k = cayk(c, xi);
    dm_lie_sym_so3_poly(c, xi, k, s_scale(c, 0.5, k), K(c, 0), M, ld);
  }
}

static void so3_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, size_t ld)
{
  dm_lie_sym_so3_poly(c, xi, K(c, 0), K(c, 1), K(c, 0), A, ld);
}

static void so3_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, size_t ld, E *xi)
{
  E h = K(c, 0.5);
  E x = s_mul(c, h, s_sub(c, A[2 * ld + 1], A[ld + 2]));
  E y = s_mul(c, h, s_sub(c, A[2], A[2 * ld]));
  E z = s_mul(c, h, s_sub(c, A[ld], A[1]));
  xi[0] = x, xi[1] = y, xi[2] = z;
}

static void so3_act(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *x, E *y)
{
  dm_lie_sym_m3_apply(c, g, 0, x, y);
}

static void so3_generator(dm_expr_ctx *c, const dm_lie_group *G, const E *g, size_t k, int side,
                          E *dg)
{
  E e[3], Eh[9];
  int i;
  for (i = 0; i < 3; i++)
    e[i] = K(c, (size_t)i == k ? 1.0 : 0.0);
  hat3(c, e, Eh);
  if (side == DM_LIE_LEFT)
    dm_lie_sym_m3_mul(c, g, Eh, dg);
  else
    dm_lie_sym_m3_mul(c, Eh, g, dg);
}

const dm_lie_sym_type dm_lie_sym_so3 = {
  so3_identity, so3_compose, so3_inverse, so3_exp, so3_log, so3_Ad, so3_ad, so3_dexp,
  so3_cay, so3_icay, so3_dcay, so3_hat, so3_vee, so3_Ad, so3_act, so3_generator
};

/* }====================================================================== */

/* {==== SE(3) ============================================================ */

static void se3_identity(dm_expr_ctx *c, const dm_lie_group *G, E *g)
{
  int i;
  so3_identity(c, G, g);
  for (i = 9; i < 12; i++)
    g[i] = K(c, 0);
}

static void se3_compose(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab)
{
  E p[3], R[9];
  int i;
  dm_lie_sym_m3_apply(c, a, 0, b + 9, p);
  for (i = 0; i < 3; i++)
    p[i] = s_add(c, p[i], a[9 + i]);
  dm_lie_sym_m3_mul(c, a, b, R);
  memcpy(ab, R, sizeof R);
  memcpy(ab + 9, p, sizeof p);
}

static void se3_inverse(dm_expr_ctx *c, const dm_lie_group *G, const E *a, E *ai)
{
  E p[3];
  int i;
  dm_lie_sym_m3_apply(c, a, 1, a + 9, p);
  so3_inverse(c, G, a, ai);
  for (i = 0; i < 3; i++)
    ai[9 + i] = s_neg(c, p[i]);
}

static void se3_exp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  E t = s_dot3(c, xi, xi), p[3];
  dm_lie_sym_so3_poly_apply(c, xi, K(c, 1), dm_lie_sym_cosc(c, t), dm_lie_sym_sinc3(c, t),
                            xi + 3, p);
  dm_lie_sym_so3_exp(c, xi, g);
  memcpy(g + 9, p, sizeof p);
}

static void se3_log(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  E w[3], v[3];
  dm_lie_sym_so3_log(c, g, w);
  dm_lie_sym_so3_poly_apply(c, w, K(c, 1), K(c, -0.5),
                            dm_lie_sym_dexpinv_coef(c, s_dot3(c, w, w)), g + 9, v);
  memcpy(xi, w, sizeof w);
  memcpy(xi + 3, v, sizeof v);
}

static void se3_Ad(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  E P[9], PR[9];
  hat3(c, g + 9, P);
  dm_lie_sym_m3_mul(c, P, g, PR);
  put_tri(c, g, PR, M, ld);
}

static void se3_ad(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *M, size_t ld)
{
  E W[9], V[9];
  hat3(c, xi, W);
  hat3(c, xi + 3, V);
  put_tri(c, W, V, M, ld);
}

/* the coupling block Q of se3.c */
static void se3_Q(dm_expr_ctx *c, const E *w, const E *v, E *Q)
{
  E t = s_dot3(c, w, w), C = dm_lie_sym_sinc3(c, t), Ec = dm_lie_sym_coefE(c, t);
  E Gc = dm_lie_sym_coefG(c, t);
  E W[9], V[9], WV[9], VW[9], WVW[9], WWV[9], VWW[9], X[9], Y[9];
  int i;
  hat3(c, w, W);
  hat3(c, v, V);
  dm_lie_sym_m3_mul(c, W, V, WV);
  dm_lie_sym_m3_mul(c, V, W, VW);
  dm_lie_sym_m3_mul(c, WV, W, WVW);
  dm_lie_sym_m3_mul(c, W, WV, WWV);
  dm_lie_sym_m3_mul(c, VW, W, VWW);
  dm_lie_sym_m3_mul(c, WVW, W, X);
  dm_lie_sym_m3_mul(c, W, WVW, Y);
  for (i = 0; i < 9; i++) {
    E q = s_add(c, s_scale(c, 0.5, V[i]), s_mul(c, C, s_add(c, s_add(c, WV[i], VW[i]), WVW[i])));
    q = s_add(c, q, s_mul(c, Ec, s_sub(c, s_add(c, WWV[i], VWW[i]), s_scale(c, 3, WVW[i]))));
    Q[i] = s_add(c, q, s_mul(c, Gc, s_add(c, X[i], Y[i])));
  }
}

static void se3_dexp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                     size_t ld)
{
  E t = s_dot3(c, xi, xi), V[9], Q[9];
  se3_Q(c, xi, xi + 3, Q);
  if (!inv) {
    dm_lie_sym_so3_poly(c, xi, K(c, 1), dm_lie_sym_cosc(c, t), dm_lie_sym_sinc3(c, t), V, 3);
    put_tri(c, V, Q, M, ld);
  } else {
    E T[9];
    int i;
    dm_lie_sym_so3_poly(c, xi, K(c, 1), K(c, -0.5), dm_lie_sym_dexpinv_coef(c, t), V, 3);
    dm_lie_sym_m3_mul(c, V, Q, T);
    dm_lie_sym_m3_mul(c, T, V, T);
    for (i = 0; i < 9; i++)
      T[i] = s_neg(c, T[i]);
    put_tri(c, V, T, M, ld);
  }
}

static void se3_cay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  E k = cayk(c, xi), p[3];
  dm_lie_sym_so3_poly_apply(c, xi, K(c, 1), s_scale(c, 0.5, k), s_scale(c, 0.25, k), xi + 3, p);
  so3_cay(c, G, xi, g);
  memcpy(g + 9, p, sizeof p);
}

static void se3_icay(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  E w[3], v[3];
  so3_icay(c, G, g, w);
  dm_lie_sym_so3_poly_apply(c, w, K(c, 1), K(c, -0.5), K(c, 0), g + 9, v);
  memcpy(xi, w, sizeof w);
  memcpy(xi + 3, v, sizeof v);
}

static void se3_dcay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                     size_t ld)
{
  E t = s_dot3(c, xi, xi), k = cayk(c, xi), u[3], U[9], A[9], D[9], B[9];
  int i, j;
  dm_lie_sym_so3_poly_apply(c, xi, K(c, 1), s_scale(c, -0.5, k), s_scale(c, 0.25, k), xi + 3, u);
  hat3(c, u, U);
  if (!inv) {
    dm_lie_sym_so3_poly(c, xi, k, s_scale(c, 0.5, k), K(c, 0), D, 3);
    dm_lie_sym_so3_poly(c, xi, K(c, 1), s_scale(c, 0.5, k), s_scale(c, 0.25, k), A, 3);
    dm_lie_sym_m3_mul(c, A, U, B);
    for (i = 0; i < 9; i++)
      B[i] = s_scale(c, 0.5, B[i]);
  } else {
    dm_lie_sym_so3_poly(c, xi, s_add(c, K(c, 1), s_scale(c, 0.25, t)), K(c, -0.5), K(c, 0.25),
                        D, 3);
    dm_lie_sym_so3_poly(c, xi, K(c, 1), K(c, -0.5), K(c, 0), A, 3);
    dm_lie_sym_m3_mul(c, U, D, B);
    for (i = 0; i < 9; i++)
      B[i] = s_scale(c, -0.5, B[i]);
  }
  put3(D, M, ld);
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      M[i * ld + 3 + j] = K(c, 0);
  put3(B, M + 3 * ld, ld);
  put3(A, M + 3 * ld + 3, ld);
}

static void se3_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, size_t ld)
{
  int i;
  dm_lie_sym_so3_poly(c, xi, K(c, 0), K(c, 1), K(c, 0), A, ld);
  for (i = 0; i < 3; i++)
    A[i * ld + 3] = xi[3 + i];
  for (i = 0; i < 4; i++)
    A[3 * ld + i] = K(c, 0);
}

static void se3_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, size_t ld, E *xi)
{
  int i;
  so3_vee(c, G, A, ld, xi);
  for (i = 0; i < 3; i++)
    xi[3 + i] = A[i * ld + 3];
}

static void se3_matrix(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  int i;
  put3(g, M, ld);
  for (i = 0; i < 3; i++) {
    M[i * ld + 3] = g[9 + i];
    M[3 * ld + i] = K(c, 0);
  }
  M[3 * ld + 3] = K(c, 1);
}

static void se3_act(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *x, E *y)
{
  int i;
  dm_lie_sym_m3_apply(c, g, 0, x, y);
  for (i = 0; i < 3; i++)
    y[i] = s_add(c, y[i], g[9 + i]);
}

static void se3_generator(dm_expr_ctx *c, const dm_lie_group *G, const E *g, size_t k, int side,
                          E *dg)
{
  int i;
  for (i = 0; i < 12; i++)
    dg[i] = K(c, 0);
  if (k < 3) {
    so3_generator(c, G, g, k, side, dg);
    if (side == DM_LIE_RIGHT) {
      E e[3];
      for (i = 0; i < 3; i++)
        e[i] = K(c, (size_t)i == k ? 1.0 : 0.0);
      s_cross(c, e, g + 9, dg + 9);
    }
  } else if (side == DM_LIE_LEFT) {
    for (i = 0; i < 3; i++)
      dg[9 + i] = g[3 * i + k - 3];
  } else {
    dg[9 + k - 3] = K(c, 1);
  }
}

const dm_lie_sym_type dm_lie_sym_se3 = {
  se3_identity, se3_compose, se3_inverse, se3_exp, se3_log, se3_Ad, se3_ad, se3_dexp,
  se3_cay, se3_icay, se3_dcay, se3_hat, se3_vee, se3_matrix, se3_act, se3_generator
};

/* }====================================================================== */
