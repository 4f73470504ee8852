/* lie_sym.c -- the symbolic group layer: coefficient functions as selects
 * between their series and closed forms (the numeric thresholds and
 * coefficients of lie_impl.h), 3x3 helpers, the SO(3) exponential and
 * logarithm, products, and the entry points of lie.h that dispatch to the
 * families' symbolic tables and turn the context's error into a status. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lie/lie_sym_impl.h"

/* {==== coefficients ===================================================== */

/* select(t < thr, series(t), closed(ts)) with ts = select(t < thr, thr, t):
 * the closed form is built on a safe argument, so that neither its value
 * nor any of its derivatives is infinite or NaN where the series is taken
 * (reverse-mode gradients multiply the unselected branch's partials by
 * zero, and 0 * Inf would be NaN). */
static E series(dm_expr_ctx *c, E t, const double *co, int n, double thr,
                E (*closed)(dm_expr_ctx *, E))
{
  E cond = s_bin(c, DM_EXPR_LT, t, s_k(c, thr)), s = s_k(c, co[n - 1]);
  int i;
  for (i = n - 2; i >= 0; i--)
    s = s_add(c, s_mul(c, s, t), s_k(c, co[i]));
  return s_sel(c, cond, s, closed(c, s_sel(c, cond, s_k(c, thr), t)));
}

#define NCO(a) ((int)(sizeof(a) / sizeof(a[0])))

static E sinc_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t);
  return s_div(c, s_un(c, DM_EXPR_SIN, th), th);
}

E dm_lie_sym_sinc(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_sinc, NCO(dm_lie_ser_sinc), 1e-2, sinc_closed);
}

static E cosc_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t);
  E s = s_div(c, s_un(c, DM_EXPR_SIN, s_scale(c, 0.5, th)), th);
  return s_scale(c, 2.0, s_mul(c, s, s));
}

E dm_lie_sym_cosc(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_cosc, NCO(dm_lie_ser_cosc), 1e-2, cosc_closed);
}

static E sinc3_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t);
  return s_div(c, s_sub(c, th, s_un(c, DM_EXPR_SIN, th)), s_mul(c, t, th));
}

E dm_lie_sym_sinc3(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_sinc3, NCO(dm_lie_ser_sinc3), 4.0, sinc3_closed);
}

static E dexpinv_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t), h = s_scale(c, 0.5, th);
  E cot = s_div(c, s_un(c, DM_EXPR_COS, h), s_un(c, DM_EXPR_SIN, h));
  return s_div(c, s_sub(c, s_k(c, 1.0), s_mul(c, h, cot)), t);
}

E dm_lie_sym_dexpinv_coef(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_dexpinv_coef, NCO(dm_lie_ser_dexpinv_coef), 4.0,
                dexpinv_closed);
}

static E coefE_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t);
  E num = s_sub(c, s_add(c, s_scale(c, 0.5, t), s_un(c, DM_EXPR_COS, th)), s_k(c, 1.0));
  return s_div(c, num, s_mul(c, t, t));
}

E dm_lie_sym_coefE(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_coefE, NCO(dm_lie_ser_coefE), 4.0, coefE_closed);
}

static E coefG_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t);
  E num = s_add(c, s_sub(c, s_scale(c, 2.0, th), s_scale(c, 3.0, s_un(c, DM_EXPR_SIN, th))),
                s_mul(c, th, s_un(c, DM_EXPR_COS, th)));
  return s_div(c, num, s_scale(c, 2.0, s_mul(c, s_mul(c, t, t), th)));
}

E dm_lie_sym_coefG(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_coefG, NCO(dm_lie_ser_coefG), 4.0, coefG_closed);
}

static E invsinc_closed(dm_expr_ctx *c, E t)
{
  E th = s_un(c, DM_EXPR_SQRT, t);
  return s_div(c, th, s_un(c, DM_EXPR_SIN, th));
}

E dm_lie_sym_invsinc(dm_expr_ctx *c, E t)
{
  return series(c, t, dm_lie_ser_invsinc, NCO(dm_lie_ser_invsinc), 1e-2, invsinc_closed);
}

E dm_lie_sym_wrap(dm_expr_ctx *c, E a)
{
  return s_bin(c, DM_EXPR_ATAN2, s_un(c, DM_EXPR_SIN, a), s_un(c, DM_EXPR_COS, a));
}

/* }====================================================================== */

/* {==== 3x3 helpers and the SO(3) exponential and logarithm ============== */

void dm_lie_sym_m3_mul(dm_expr_ctx *c, const E *A, const E *B, E *C)
{
  E T[9];
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++)
      T[3 * i + j] = s_add(c, s_add(c, s_mul(c, A[3 * i], B[j]), s_mul(c, A[3 * i + 1], B[3 + j])),
                           s_mul(c, A[3 * i + 2], B[6 + j]));
  memcpy(C, T, sizeof T);
}

void dm_lie_sym_so3_poly(dm_expr_ctx *c, const E *w, E a, E b, E cc, E *M, size_t ld)
{
  dm_lie_sym_so3_poly_d(c, w, s_sub(c, a, s_mul(c, cc, s_dot3(c, w, w))), b, cc, M, ld);
}

void dm_lie_sym_so3_poly_d(dm_expr_ctx *c, const E *w, E d, E b, E cc, E *M, size_t ld)
{
  int i, j;
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++) {
      E v = s_mul(c, cc, s_mul(c, w[i], w[j]));
      if (i == j)
        v = s_add(c, d, v);
      else {
        int k = 3 - i - j;      /* hat(w)_ij = -eps_ijk w_k */
        int sgn = ((j - i + 3) % 3 == 1) ? -1 : 1;
        E h = s_mul(c, b, w[k]);
        v = sgn < 0 ? s_sub(c, v, h) : s_add(c, v, h);
      }
      M[i * ld + j] = v;
    }
}

void dm_lie_sym_so3_poly_apply(dm_expr_ctx *c, const E *w, E a, E b, E cc, const E *x, E *y)
{
  E wx[3], wwx[3], r[3];
  int i;
  s_cross(c, w, x, wx);
  s_cross(c, w, wx, wwx);
  for (i = 0; i < 3; i++)
    r[i] = s_add(c, s_add(c, s_mul(c, a, x[i]), s_mul(c, b, wx[i])), s_mul(c, cc, wwx[i]));
  memcpy(y, r, sizeof r);
}

void dm_lie_sym_m3_apply(dm_expr_ctx *c, const E *A, int trans, const E *x, E *y)
{
  E r[3];
  int i;
  for (i = 0; i < 3; i++) {
    E a0 = trans ? A[i] : A[3 * i], a1 = trans ? A[3 + i] : A[3 * i + 1];
    E a2 = trans ? A[6 + i] : A[3 * i + 2];
    r[i] = s_add(c, s_add(c, s_mul(c, a0, x[0]), s_mul(c, a1, x[1])), s_mul(c, a2, x[2]));
  }
  memcpy(y, r, sizeof r);
}

static E cos_closed(dm_expr_ctx *c, E t)
{
  return s_un(c, DM_EXPR_COS, s_un(c, DM_EXPR_SQRT, t));
}

void dm_lie_sym_so3_exp(dm_expr_ctx *c, const E *w, E *R)
{
  E t = s_dot3(c, w, w), B = dm_lie_sym_cosc(c, t), cond = s_bin(c, DM_EXPR_LT, t, s_k(c, 1e-2));
  E d = s_sel(c, cond, s_sub(c, s_k(c, 1.0), s_mul(c, B, t)),
              cos_closed(c, s_sel(c, cond, s_k(c, 1e-2), t)));
  dm_lie_sym_so3_poly_d(c, w, d, dm_lie_sym_sinc(c, t), B, R, 3);
}

/* asin(sqrt u)/sqrt(u), series in u = sin^2 phi (exact rationals) */
static const double asinc_ser[] = {
  1, 0.16666666666666666, 0.074999999999999997, 0.044642857142857144, 0.030381944444444444,
  0.022372159090909092, 0.017352764423076924, 0.013964843750000001, 0.011551800896139705,
  0.0097616095291940784};

/* The branches of dm_so3_log with u = |s|^2 = sin^2 phi as the variable
 * near the identity (phi/sin phi = asin(sqrt u)/sqrt u, a series in u below
 * 1e-2: smooth at R = I, where phi = sqrt(u) is not) and the symmetric part
 * beyond pi/2; every branch is built on arguments made safe where another
 * branch is taken (see series()).  At exactly angle pi the value is that of
 * the numeric code; the logarithm is not differentiable there. */
void dm_lie_sym_so3_log(dm_expr_ctx *c, const E *R, E *w)
{
  E one = s_k(c, 1.0), half = s_k(c, 0.5), zero = s_k(c, 0.0);
  E cs = s_mul(c, half, s_sub(c, s_add(c, s_add(c, R[0], R[4]), R[8]), one));
  E s[3], B[9], den, u, small, us, k, pos, cn, phi, n[3][3], m0, m1, ser;
  int i, j, m;
  s[0] = s_mul(c, half, s_sub(c, R[7], R[5]));
  s[1] = s_mul(c, half, s_sub(c, R[2], R[6]));
  s[2] = s_mul(c, half, s_sub(c, R[3], R[1]));
  u = s_dot3(c, s, s);
  pos = s_bin(c, DM_EXPR_GT, cs, zero);
  /* near the identity */
  small = s_bin(c, DM_EXPR_LT, u, s_k(c, 1e-2));
  us = s_sel(c, small, half, u);
  ser = s_k(c, asinc_ser[NCO(asinc_ser) - 1]);
  for (i = NCO(asinc_ser) - 2; i >= 0; i--)
    ser = s_add(c, s_mul(c, ser, u), s_k(c, asinc_ser[i]));
  k = s_sel(c, small, ser,
            s_div(c, s_bin(c, DM_EXPR_ATAN2, s_un(c, DM_EXPR_SQRT, us), s_sel(c, pos, cs, half)),
                  s_un(c, DM_EXPR_SQRT, us)));
  /* beyond pi/2: cos phi made -1 where this branch is not taken */
  cn = s_sel(c, pos, s_neg(c, one), cs);
  phi = s_bin(c, DM_EXPR_ATAN2, s_un(c, DM_EXPR_SQRT, s_sel(c, pos, one, u)), cn);
  den = s_sub(c, one, cn);
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++) {
      E b = s_mul(c, half, s_add(c, R[3 * i + j], R[3 * j + i]));
      B[3 * i + j] = i == j ? s_sub(c, b, cn) : b;
    }
  for (m = 0; m < 3; m++) {
    E x = s_mul(c, B[4 * m], den), nn, len, sg;
    nn = s_un(c, DM_EXPR_SQRT, s_sel(c, s_bin(c, DM_EXPR_GT, x, s_k(c, 1e-12)), x, one));
    for (i = 0; i < 3; i++)
      n[m][i] = i == m ? s_div(c, nn, den) : s_div(c, B[3 * i + m], nn);
    len = s_un(c, DM_EXPR_SQRT, s_dot3(c, n[m], n[m]));
    sg = s_sel(c, s_bin(c, DM_EXPR_LT, s_dot3(c, n[m], s), zero), s_neg(c, len), len);
    for (i = 0; i < 3; i++)
      n[m][i] = s_div(c, s_mul(c, phi, n[m][i]), sg);
  }
  m0 = s_mul(c, s_bin(c, DM_EXPR_GE, B[0], B[4]), s_bin(c, DM_EXPR_GE, B[0], B[8]));
  m1 = s_bin(c, DM_EXPR_GE, B[4], B[8]);
  for (i = 0; i < 3; i++)
    w[i] = s_sel(c, pos, s_mul(c, k, s[i]),
                 s_sel(c, m0, n[0][i], s_sel(c, m1, n[1][i], n[2][i])));
}

/* }====================================================================== */

/* {==== products ========================================================= */

#define FAC(G, i) ((const dm_lie_group *)(G)->fac[i])
#define SYM(F) ((F)->type->sym)

static void zero(dm_expr_ctx *c, E *M, size_t r, size_t cl, size_t ld)
{
  size_t i, j;
  E z = s_k(c, 0.0);
  for (i = 0; i < r; i++)
    for (j = 0; j < cl; j++)
      M[i * ld + j] = z;
}

static void pr_identity(dm_expr_ctx *c, const dm_lie_group *G, E *g)
{
  size_t i;
  for (i = 0; i < G->nfac; i++)
    SYM(FAC(G, i))->identity(c, FAC(G, i), g + G->qoff[i]);
}

static void pr_compose(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab)
{
  size_t i, o;
  for (i = 0; i < G->nfac; i++) {
    o = G->qoff[i];
    SYM(FAC(G, i))->compose(c, FAC(G, i), a + o, b + o, ab + o);
  }
}

static void pr_inverse(dm_expr_ctx *c, const dm_lie_group *G, const E *a, E *ai)
{
  size_t i, o;
  for (i = 0; i < G->nfac; i++) {
    o = G->qoff[i];
    SYM(FAC(G, i))->inverse(c, FAC(G, i), a + o, ai + o);
  }
}

static void pr_exp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  size_t i;
  for (i = 0; i < G->nfac; i++)
    SYM(FAC(G, i))->exp(c, FAC(G, i), xi + G->xoff[i], g + G->qoff[i]);
}

static void pr_log(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  size_t i;
  for (i = 0; i < G->nfac; i++)
    SYM(FAC(G, i))->log(c, FAC(G, i), g + G->qoff[i], xi + G->xoff[i]);
}

static void pr_cay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g)
{
  size_t i;
  for (i = 0; i < G->nfac; i++)
    SYM(FAC(G, i))->cay(c, FAC(G, i), xi + G->xoff[i], g + G->qoff[i]);
}

static void pr_icay(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi)
{
  size_t i;
  for (i = 0; i < G->nfac; i++)
    SYM(FAC(G, i))->icay(c, FAC(G, i), g + G->qoff[i], xi + G->xoff[i]);
}

static void pr_Ad(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  size_t i, o;
  zero(c, M, G->dim, G->dim, ld);
  for (i = 0; i < G->nfac; i++) {
    o = G->xoff[i];
    SYM(FAC(G, i))->Ad(c, FAC(G, i), g + G->qoff[i], M + o * ld + o, ld);
  }
}

static void pr_ad(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *M, size_t ld)
{
  size_t i, o;
  zero(c, M, G->dim, G->dim, ld);
  for (i = 0; i < G->nfac; i++) {
    o = G->xoff[i];
    SYM(FAC(G, i))->ad(c, FAC(G, i), xi + o, M + o * ld + o, ld);
  }
}

static void pr_dexp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M, size_t ld)
{
  size_t i, o;
  zero(c, M, G->dim, G->dim, ld);
  for (i = 0; i < G->nfac; i++) {
    o = G->xoff[i];
    SYM(FAC(G, i))->dexp(c, FAC(G, i), xi + o, inv, M + o * ld + o, ld);
  }
}

static void pr_dcay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int inv, E *M, size_t ld)
{
  size_t i, o;
  zero(c, M, G->dim, G->dim, ld);
  for (i = 0; i < G->nfac; i++) {
    o = G->xoff[i];
    SYM(FAC(G, i))->dcay(c, FAC(G, i), xi + o, inv, M + o * ld + o, ld);
  }
}

static void pr_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, size_t ld)
{
  size_t i, o;
  zero(c, A, G->msize, G->msize, ld);
  for (i = 0; i < G->nfac; i++) {
    o = G->moff[i];
    SYM(FAC(G, i))->hat(c, FAC(G, i), xi + G->xoff[i], A + o * ld + o, ld);
  }
}

static void pr_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, size_t ld, E *xi)
{
  size_t i, o;
  for (i = 0; i < G->nfac; i++) {
    o = G->moff[i];
    SYM(FAC(G, i))->vee(c, FAC(G, i), A + o * ld + o, ld, xi + G->xoff[i]);
  }
}

static void pr_matrix(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, size_t ld)
{
  size_t i, o;
  zero(c, M, G->msize, G->msize, ld);
  for (i = 0; i < G->nfac; i++) {
    o = G->moff[i];
    SYM(FAC(G, i))->matrix(c, FAC(G, i), g + G->qoff[i], M + o * ld + o, ld);
  }
}

static void pr_act(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *x, E *y)
{
  size_t i, o;
  for (i = 0; i < G->nfac; i++) {
    o = G->koff[i];
    SYM(FAC(G, i))->act(c, FAC(G, i), g + G->qoff[i], x + o, y + o);
  }
}

static void pr_generator(dm_expr_ctx *c, const dm_lie_group *G, const E *g, size_t k, int side,
                         E *dg)
{
  size_t i = 0, a;
  for (a = 0; a < G->nq; a++)
    dg[a] = s_k(c, 0.0);
  while (k >= G->xoff[i + 1])
    i++;
  SYM(FAC(G, i))->generator(c, FAC(G, i), g + G->qoff[i], k - G->xoff[i], side,
                             dg + G->qoff[i]);
}

const dm_lie_sym_type dm_lie_sym_product = {
  pr_identity, pr_compose, pr_inverse, pr_exp, pr_log, pr_Ad, pr_ad, pr_dexp, pr_cay,
  pr_icay, pr_dcay, pr_hat, pr_vee, pr_matrix, pr_act, pr_generator
};

/* }====================================================================== */

/* {==== entry points ===================================================== */

static int done(dm_expr_ctx *c, const E *out, size_t n, dm_err *e)
{
  const dm_err *ce = dm_expr_ctx_err(c);
  size_t i;
  if (ce->status != DM_OK)
    return dm_err_set(e, ce->status, "%s", ce->msg);
  for (i = 0; i < n; i++)
    if (out[i] == DM_EXPR_NONE)
      return dm_err_set(e, DM_EINVAL, "Lie group (symbolic): invalid expression");
  return DM_OK;
}

int dm_lie_sym_identity(dm_expr_ctx *c, const dm_lie_group *G, E *g, dm_err *e)
{
  G->type->sym->identity(c, G, g);
  return done(c, g, G->nq, e);
}

int dm_lie_sym_compose(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab,
                       dm_err *e)
{
  E t[DM_LIE_NQ_MAX];
  G->type->sym->compose(c, G, a, b, t);
  memcpy(ab, t, G->nq * sizeof *ab);
  return done(c, ab, G->nq, e);
}

int dm_lie_sym_inverse(dm_expr_ctx *c, const dm_lie_group *G, const E *a, E *ai, dm_err *e)
{
  E t[DM_LIE_NQ_MAX];
  G->type->sym->inverse(c, G, a, t);
  memcpy(ai, t, G->nq * sizeof *ai);
  return done(c, ai, G->nq, e);
}

int dm_lie_sym_exp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g, dm_err *e)
{
  E t[DM_LIE_NQ_MAX];
  G->type->sym->exp(c, G, xi, t);
  memcpy(g, t, G->nq * sizeof *g);
  return done(c, g, G->nq, e);
}

int dm_lie_sym_log(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi, dm_err *e)
{
  E t[DM_LIE_DIM_MAX];
  G->type->sym->log(c, G, g, t);
  memcpy(xi, t, G->dim * sizeof *xi);
  return done(c, xi, G->dim, e);
}

int dm_lie_sym_Ad(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, dm_err *e)
{
  G->type->sym->Ad(c, G, g, M, G->dim);
  return done(c, M, G->dim * G->dim, e);
}

int dm_lie_sym_ad(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *M, dm_err *e)
{
  G->type->sym->ad(c, G, xi, M, G->dim);
  return done(c, M, G->dim * G->dim, e);
}

int dm_lie_sym_matvec(dm_expr_ctx *c, size_t n, const E *M, int trans, const E *x, E *y,
                      dm_err *e)
{
  E t[DM_LIE_DIM_MAX];
  size_t i, j;
  for (i = 0; i < n; i++) {
    E s = s_k(c, 0.0);
    for (j = 0; j < n; j++)
      s = s_add(c, s, s_mul(c, trans ? M[j * n + i] : M[i * n + j], x[j]));
    t[i] = s;
  }
  memcpy(y, t, n * sizeof *y);
  return done(c, y, n, e);
}

int dm_lie_sym_bracket(dm_expr_ctx *c, const dm_lie_group *G, const E *a, const E *b, E *ab,
                       dm_err *e)
{
  E M[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];
  G->type->sym->ad(c, G, a, M, G->dim);
  return dm_lie_sym_matvec(c, G->dim, M, 0, b, ab, e);
}

static const E *side_arg(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int side, E *buf)
{
  size_t i;
  if (side != DM_LIE_LEFT)
    return xi;
  for (i = 0; i < G->dim; i++)
    buf[i] = s_neg(c, xi[i]);
  return buf;
}

int dm_lie_sym_dexp(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int side, E *M,
                    dm_err *e)
{
  E b[DM_LIE_DIM_MAX];
  G->type->sym->dexp(c, G, side_arg(c, G, xi, side, b), 0, M, G->dim);
  return done(c, M, G->dim * G->dim, e);
}

int dm_lie_sym_dexpinv(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int side, E *M,
                       dm_err *e)
{
  E b[DM_LIE_DIM_MAX];
  G->type->sym->dexp(c, G, side_arg(c, G, xi, side, b), 1, M, G->dim);
  return done(c, M, G->dim * G->dim, e);
}

int dm_lie_sym_cay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *g, dm_err *e)
{
  E t[DM_LIE_NQ_MAX];
  G->type->sym->cay(c, G, xi, t);
  memcpy(g, t, G->nq * sizeof *g);
  return done(c, g, G->nq, e);
}

int dm_lie_sym_icay(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *xi, dm_err *e)
{
  E t[DM_LIE_DIM_MAX];
  G->type->sym->icay(c, G, g, t);
  memcpy(xi, t, G->dim * sizeof *xi);
  return done(c, xi, G->dim, e);
}

int dm_lie_sym_dcay(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int side, E *M,
                    dm_err *e)
{
  E b[DM_LIE_DIM_MAX];
  G->type->sym->dcay(c, G, side_arg(c, G, xi, side, b), 0, M, G->dim);
  return done(c, M, G->dim * G->dim, e);
}

int dm_lie_sym_dcayinv(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, int side, E *M,
                       dm_err *e)
{
  E b[DM_LIE_DIM_MAX];
  G->type->sym->dcay(c, G, side_arg(c, G, xi, side, b), 1, M, G->dim);
  return done(c, M, G->dim * G->dim, e);
}

int dm_lie_sym_hat(dm_expr_ctx *c, const dm_lie_group *G, const E *xi, E *A, dm_err *e)
{
  G->type->sym->hat(c, G, xi, A, G->msize);
  return done(c, A, G->msize * G->msize, e);
}

int dm_lie_sym_vee(dm_expr_ctx *c, const dm_lie_group *G, const E *A, E *xi, dm_err *e)
{
  E t[DM_LIE_DIM_MAX];
  G->type->sym->vee(c, G, A, G->msize, t);
  memcpy(xi, t, G->dim * sizeof *xi);
  return done(c, xi, G->dim, e);
}

int dm_lie_sym_matrix(dm_expr_ctx *c, const dm_lie_group *G, const E *g, E *M, dm_err *e)
{
  G->type->sym->matrix(c, G, g, M, G->msize);
  return done(c, M, G->msize * G->msize, e);
}

int dm_lie_sym_act(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *x, E *y,
                   dm_err *e)
{
  E t[DM_LIE_NQ_MAX];
  G->type->sym->act(c, G, g, x, t);
  memcpy(y, t, G->kdim * sizeof *y);
  return done(c, y, G->kdim, e);
}

int dm_lie_sym_generator(dm_expr_ctx *c, const dm_lie_group *G, const E *g, size_t k, int side,
                         E *dg, dm_err *e)
{
  G->type->sym->generator(c, G, g, k, side, dg);
  return done(c, dg, G->nq, e);
}

int dm_lie_sym_trivialize(dm_expr_ctx *c, const dm_lie_group *G, const E *g, const E *grad,
                          int side, E *out, dm_err *e)
{
  E dg[DM_LIE_NQ_MAX];
  size_t k, a;
  for (k = 0; k < G->dim; k++) {
    E s = s_k(c, 0.0);
    G->type->sym->generator(c, G, g, k, side, dg);
    for (a = 0; a < G->nq; a++)
      s = s_add(c, s, s_mul(c, grad[a], dg[a]));
    out[k] = s;
  }
  return done(c, out, G->dim, e);
}

/* }====================================================================== */
