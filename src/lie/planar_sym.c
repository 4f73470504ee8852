/* planar_sym.c -- R^n, SO(2), T^n and SE(2) on expressions: the formulas
 * of abelian.c and se2.c node for node.  Angles: log is atan2(sin, cos),
 * the principal value in (-pi, pi]. */
#include <config.h>
#include <string.h>

#include "lie/lie_sym_impl.h"

static E K(dm_expr_ctx *c, double x)
{
  return s_k(c, x);
}

static void zero(dm_expr_ctx *c, E *M, size_t r, size_t cl, size_t ld)
{
  size_t i, j;
  for (i = 0; i < r; i++)
    for (j = 0; j < cl; j++)
      M[i * ld + j] = K(c, 0);
}

/* {==== shared by the abelian groups ===================================== */

static void ab_identity(dm_expr_ctx *c, const dm_lie_group *G, E *g)
{
  size_t i;
  for (i = 0; i < G->nq; i++)
    g[i] = K(c, 0);
}

static void ab_compose(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab)
{
  size_t i;
  for (i = 0; i < G->nq; i++)
    ab[i] = s_add(c, a[i], b[i]);
}

static void ab_inverse(dm_expr_ctx *c, const dm_lie_group *G, const E *a, E *ai)
{
  size_t i;
  for (i = 0; i < G->nq; i++)
    ai[i] = s_neg(c, a[i]);
}

static void ab_copy(dm_expr_ctx *c, const dm_lie_group *G, const E *x, E *y)
{
  memmove(y, x, G->nq * sizeof *y);
}

static void ab_Ad(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  size_t i;
  zero(c, M, G->dim, G->dim, ld);
  for (i = 0; i < G->dim; i++)
    M[i * ld + i] = K(c, 1);
}

static void ab_ad(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *M, size_t ld)
{
  zero(c, M, G->dim, G->dim, ld);
}

static void ab_dexp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M, size_t ld)
{
  ab_Ad(c, G, NULL, M, ld);
}

static void ab_generator(dm_expr_ctx *c, const dm_lie_group *G, const E *g, size_t k, int side,
                         E *dg)
{
  size_t i;
  for (i = 0; i < G->nq; i++)
    dg[i] = K(c, i == k ? 1.0 : 0.0);
}

/* }====================================================================== */

/* {==== R^n ============================================================== */

static void rn_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, size_t ld)
{
  size_t i, n = G->n;
  zero(c, A, n + 1, n + 1, ld);
  for (i = 0; i < n; i++)
    A[i * ld + n] = xi[i];
}

static void rn_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, size_t ld, E *xi)
{
  size_t i, n = G->n;
  for (i = 0; i < n; i++)
    xi[i] = A[i * ld + n];
}

static void rn_matrix(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  size_t i, n = G->n;
  rn_hat(c, G, g, M, ld);
  for (i = 0; i <= n; i++)
    M[i * ld + i] = K(c, 1);
}

const dm_lie_sym_type dm_lie_sym_rn = {
  ab_identity, ab_compose, ab_inverse, ab_copy, ab_copy, ab_Ad, ab_ad, ab_dexp, ab_copy,
  ab_copy, ab_dexp, rn_hat, rn_vee, rn_matrix, ab_compose, ab_generator
};

/* }====================================================================== */

/* {==== SO(2), T^n ======================================================= */

static void tn_log(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    xi[i] = dm_lie_sym_wrap(c, g[i]);
}

static void tn_cay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    g[i] = s_scale(c, 2, s_un(c, DM_EXPR_ATAN, s_scale(c, 0.5, xi[i])));
}

static void tn_icay(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    xi[i] = s_scale(c, 2, s_un(c, DM_EXPR_TAN, s_scale(c, 0.5, dm_lie_sym_wrap(c, g[i]))));
}

static void tn_dcay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                    size_t ld)
{
  size_t i;
  zero(c, M, G->n, G->n, ld);
  for (i = 0; i < G->n; i++) {
    E d = s_add(c, K(c, 4), s_mul(c, xi[i], xi[i]));
    M[i * ld + i] = inv ? s_scale(c, 0.25, d) : s_div(c, K(c, 4), d);
  }
}

static void tn_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, size_t ld)
{
  size_t i, m = 2 * G->n;
  zero(c, A, m, m, ld);
  for (i = 0; i < G->n; i++) {
    A[2 * i * ld + 2 * i + 1] = s_neg(c, xi[i]);
    A[(2 * i + 1) * ld + 2 * i] = xi[i];
  }
}

static void tn_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, size_t ld, E *xi)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    xi[i] = s_scale(c, 0.5, s_sub(c, A[(2 * i + 1) * ld + 2 * i], A[2 * i * ld + 2 * i + 1]));
}

static void tn_matrix(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  size_t i, m = 2 * G->n;
  zero(c, M, m, m, ld);
  for (i = 0; i < G->n; i++) {
    E cs = s_un(c, DM_EXPR_COS, g[i]), sn = s_un(c, DM_EXPR_SIN, g[i]);
    M[2 * i * ld + 2 * i] = cs;
    M[2 * i * ld + 2 * i + 1] = s_neg(c, sn);
    M[(2 * i + 1) * ld + 2 * i] = sn;
    M[(2 * i + 1) * ld + 2 * i + 1] = cs;
  }
}

static void tn_act(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *x, E *y)
{
  size_t i;
  for (i = 0; i < G->n; i++) {
    E cs = s_un(c, DM_EXPR_COS, g[i]), sn = s_un(c, DM_EXPR_SIN, g[i]);
    E a = x[2 * i], b = x[2 * i + 1];
    y[2 * i] = s_sub(c, s_mul(c, cs, a), s_mul(c, sn, b));
    y[2 * i + 1] = s_add(c, s_mul(c, sn, a), s_mul(c, cs, b));
  }
}

const dm_lie_sym_type dm_lie_sym_tn = {
  ab_identity, ab_compose, ab_inverse, ab_copy, tn_log, ab_Ad, ab_ad, ab_dexp, tn_cay,
  tn_icay, tn_dcay, tn_hat, tn_vee, tn_matrix, tn_act, ab_generator
};

/* }====================================================================== */

/* {==== SE(2) ============================================================ */

static void se2_identity(dm_expr_ctx *c, const dm_lie_group *G, E *g)
{
  g[0] = g[1] = g[2] = K(c, 0);
}

/* R(a) (x, y) */
static void rot(dm_expr_ctx *c, E a, E x, E y, E *rx, E *ry)
{
  E cs = s_un(c, DM_EXPR_COS, a), sn = s_un(c, DM_EXPR_SIN, a);
  *rx = s_sub(c, s_mul(c, cs, x), s_mul(c, sn, y));
  *ry = s_add(c, s_mul(c, sn, x), s_mul(c, cs, y));
}

static void se2_compose(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab)
{
  E x, y, t = s_add(c, a[0], b[0]);
  rot(c, a[0], b[1], b[2], &x, &y);
  ab[1] = s_add(c, a[1], x);
  ab[2] = s_add(c, a[2], y);
  ab[0] = t;
}

static void se2_inverse(dm_expr_ctx *c, const dm_lie_group *G, const E *a, E *ai)
{
  E x, y, t = s_neg(c, a[0]);
  rot(c, t, a[1], a[2], &x, &y);
  ai[1] = s_neg(c, x);
  ai[2] = s_neg(c, y);
  ai[0] = t;
}

static void se2_exp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  E w = xi[0], t = s_mul(c, w, w), A = dm_lie_sym_sinc(c, t);
  E B = s_mul(c, w, dm_lie_sym_cosc(c, t));
  E x = s_sub(c, s_mul(c, A, xi[1]), s_mul(c, B, xi[2]));
  E y = s_add(c, s_mul(c, B, xi[1]), s_mul(c, A, xi[2]));
  g[0] = w, g[1] = x, g[2] = y;
}

static void se2_log(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  E phi = dm_lie_sym_wrap(c, g[0]), t = s_mul(c, phi, phi);
  E a = s_sub(c, K(c, 1), s_mul(c, t, dm_lie_sym_dexpinv_coef(c, t))), h = s_scale(c, 0.5, phi);
  E x = s_add(c, s_mul(c, a, g[1]), s_mul(c, h, g[2]));
  E y = s_sub(c, s_mul(c, a, g[2]), s_mul(c, h, g[1]));
  xi[0] = phi, xi[1] = x, xi[2] = y;
}

static void se2_Ad(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  E cs = s_un(c, DM_EXPR_COS, g[0]), sn = s_un(c, DM_EXPR_SIN, g[0]);
  M[0] = K(c, 1), M[1] = K(c, 0), M[2] = K(c, 0);
  M[ld] = g[2], M[ld + 1] = cs, M[ld + 2] = s_neg(c, sn);
  M[2 * ld] = s_neg(c, g[1]), M[2 * ld + 1] = sn, M[2 * ld + 2] = cs;
}

static void se2_ad(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *M, size_t ld)
{
  M[0] = K(c, 0), M[1] = K(c, 0), M[2] = K(c, 0);
  M[ld] = xi[2], M[ld + 1] = K(c, 0), M[ld + 2] = s_neg(c, xi[0]);
  M[2 * ld] = s_neg(c, xi[1]), M[2 * ld + 1] = xi[0], M[2 * ld + 2] = K(c, 0);
}

static void se2_dexp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                     size_t ld)
{
  E w = xi[0], t = s_mul(c, w, w), B = dm_lie_sym_cosc(c, t);
  E C = s_mul(c, w, dm_lie_sym_sinc3(c, t));
  E a0 = s_add(c, s_mul(c, B, xi[2]), s_mul(c, C, xi[1]));
  E a1 = s_add(c, s_neg(c, s_mul(c, B, xi[1])), s_mul(c, C, xi[2]));
  E W00, W01, W10, W11;
  if (!inv) {
    E A = dm_lie_sym_sinc(c, t), Bw = s_mul(c, w, B);
    W00 = A, W01 = s_neg(c, Bw), W10 = Bw, W11 = A;
  } else {
    E a = s_sub(c, K(c, 1), s_mul(c, t, dm_lie_sym_dexpinv_coef(c, t))), h = s_scale(c, 0.5, w);
    E b0, b1;
    W00 = a, W01 = h, W10 = s_neg(c, h), W11 = a;
    b0 = s_neg(c, s_add(c, s_mul(c, W00, a0), s_mul(c, W01, a1)));
    b1 = s_neg(c, s_add(c, s_mul(c, W10, a0), s_mul(c, W11, a1)));
    a0 = b0, a1 = b1;
  }
  M[0] = K(c, 1), M[1] = K(c, 0), M[2] = K(c, 0);
  M[ld] = a0, M[ld + 1] = W00, M[ld + 2] = W01;
  M[2 * ld] = a1, M[2 * ld + 1] = W10, M[2 * ld + 2] = W11;
}

static void se2_cay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  E w = xi[0], k = s_div(c, K(c, 4), s_add(c, K(c, 4), s_mul(c, w, w))), hw = s_scale(c, 0.5, w);
  E x = s_mul(c, k, s_sub(c, xi[1], s_mul(c, hw, xi[2])));
  E y = s_mul(c, k, s_add(c, xi[2], s_mul(c, hw, xi[1])));
  g[0] = s_scale(c, 2, s_un(c, DM_EXPR_ATAN, hw));
  g[1] = x, g[2] = y;
}

static void se2_icay(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  E w = s_scale(c, 2, s_un(c, DM_EXPR_TAN, s_scale(c, 0.5, dm_lie_sym_wrap(c, g[0]))));
  E hw = s_scale(c, 0.5, w);
  E x = s_add(c, g[1], s_mul(c, hw, g[2])), y = s_sub(c, g[2], s_mul(c, hw, g[1]));
  xi[0] = w, xi[1] = x, xi[2] = y;
}

static void se2_dcay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M,
                     size_t ld)
{
  E w = xi[0], k = s_div(c, K(c, 4), s_add(c, K(c, 4), s_mul(c, w, w))), hw = s_scale(c, 0.5, w);
  E u0 = s_mul(c, k, s_add(c, xi[1], s_mul(c, hw, xi[2])));
  E u1 = s_mul(c, k, s_sub(c, xi[2], s_mul(c, hw, xi[1])));
  E Ju0 = s_neg(c, u1), Ju1 = u0, d, b0, b1, A00, A01, A10, A11;
  if (!inv) {
    A00 = k, A01 = s_neg(c, s_mul(c, hw, k)), A10 = s_mul(c, hw, k), A11 = k;
    d = k;
    b0 = s_scale(c, -0.5, s_add(c, s_mul(c, A00, Ju0), s_mul(c, A01, Ju1)));
    b1 = s_scale(c, -0.5, s_add(c, s_mul(c, A10, Ju0), s_mul(c, A11, Ju1)));
  } else {
    A00 = K(c, 1), A01 = hw, A10 = s_neg(c, hw), A11 = K(c, 1);
    d = s_div(c, K(c, 1), k);
    b0 = s_div(c, s_scale(c, 0.5, Ju0), k);
    b1 = s_div(c, s_scale(c, 0.5, Ju1), k);
  }
  M[0] = d, M[1] = K(c, 0), M[2] = K(c, 0);
  M[ld] = b0, M[ld + 1] = A00, M[ld + 2] = A01;
  M[2 * ld] = b1, M[2 * ld + 1] = A10, M[2 * ld + 2] = A11;
}

static void se2_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, size_t ld)
{
  A[0] = K(c, 0), A[1] = s_neg(c, xi[0]), A[2] = xi[1];
  A[ld] = xi[0], A[ld + 1] = K(c, 0), A[ld + 2] = xi[2];
  A[2 * ld] = K(c, 0), A[2 * ld + 1] = K(c, 0), A[2 * ld + 2] = K(c, 0);
}

static void se2_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, size_t ld, E *xi)
{
  E w = s_scale(c, 0.5, s_sub(c, A[ld], A[1])), x = A[2], y = A[ld + 2];
  xi[0] = w, xi[1] = x, xi[2] = y;
}

static void se2_matrix(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  E cs = s_un(c, DM_EXPR_COS, g[0]), sn = s_un(c, DM_EXPR_SIN, g[0]);
  M[0] = cs, M[1] = s_neg(c, sn), M[2] = g[1];
  M[ld] = sn, M[ld + 1] = cs, M[ld + 2] = g[2];
  M[2 * ld] = K(c, 0), M[2 * ld + 1] = K(c, 0), M[2 * ld + 2] = K(c, 1);
}

static void se2_act(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *x, E *y)
{
  E rx, ry;
  rot(c, g[0], x[0], x[1], &rx, &ry);
  y[0] = s_add(c, g[1], rx);
  y[1] = s_add(c, g[2], ry);
}

static void se2_generator(dm_expr_ctx *c, const dm_lie_group *G, const E *g, size_t k, int side,
                          E *dg)
{
  E cs = s_un(c, DM_EXPR_COS, g[0]), sn = s_un(c, DM_EXPR_SIN, g[0]), z = K(c, 0);
  dg[0] = K(c, k == 0 ? 1.0 : 0.0);
  if (side == DM_LIE_LEFT) {
    dg[1] = k == 1 ? cs : k == 2 ? s_neg(c, sn) : z;
    dg[2] = k == 1 ? sn : k == 2 ? cs : z;
  } else {
    dg[1] = k == 0 ? s_neg(c, g[2]) : k == 1 ? K(c, 1) : z;
    dg[2] = k == 0 ? g[1] : k == 2 ? K(c, 1) : z;
  }
}

const dm_lie_sym_type dm_lie_sym_se2 = {
  se2_identity, se2_compose, se2_inverse, se2_exp, se2_log, se2_Ad, se2_ad, se2_dexp,
  se2_cay, se2_icay, se2_dcay, se2_hat, se2_vee, se2_matrix, se2_act, se2_generator
};

/* }====================================================================== */
