/* lie_sym_impl.h -- private to src/lie: short builders over an expression
 * context for the symbolic group operations (every builder passes
 * DM_EXPR_NONE through, so a chain is checked once at its end), the
 * series-or-closed-form coefficients as selects, and 3x3 helpers.  Not part
 * of the API. */
#ifndef DM_LIE_SYM_IMPL_H
#define DM_LIE_SYM_IMPL_H

#include "lie/lie_impl.h"
#include "expr/expr.h"

typedef dm_expr E;

static inline E s_k(dm_expr_ctx *c, double x) { return dm_expr_const(c, x); }
static inline E s_add(dm_expr_ctx *c, E a, E b) { return dm_expr_add(c, a, b); }
static inline E s_sub(dm_expr_ctx *c, E a, E b) { return dm_expr_sub(c, a, b); }
static inline E s_mul(dm_expr_ctx *c, E a, E b) { return dm_expr_mul(c, a, b); }
static inline E s_div(dm_expr_ctx *c, E a, E b) { return dm_expr_div(c, a, b); }
static inline E s_neg(dm_expr_ctx *c, E a) { return dm_expr_neg(c, a); }
static inline E s_un(dm_expr_ctx *c, int op, E a) { return dm_expr_unary(c, op, a); }
static inline E s_bin(dm_expr_ctx *c, int op, E a, E b) { return dm_expr_binary(c, op, a, b); }
static inline E s_sel(dm_expr_ctx *c, E cond, E a, E b) { return dm_expr_select(c, cond, a, b); }
static inline E s_scale(dm_expr_ctx *c, double k, E a) { return dm_expr_mul(c, s_k(c, k), a); }

/* a . b, a x b of 3-vectors */
static inline E s_dot3(dm_expr_ctx *c, const E *a, const E *b)
{
  return s_add(c, s_add(c, s_mul(c, a[0], b[0]), s_mul(c, a[1], b[1])), s_mul(c, a[2], b[2]));
}

static inline void s_cross(dm_expr_ctx *c, const E *a, const E *b, E *r)
{
  E r0 = s_sub(c, s_mul(c, a[1], b[2]), s_mul(c, a[2], b[1]));
  E r1 = s_sub(c, s_mul(c, a[2], b[0]), s_mul(c, a[0], b[2]));
  E r2 = s_sub(c, s_mul(c, a[0], b[1]), s_mul(c, a[1], b[0]));
  r[0] = r0, r[1] = r1, r[2] = r2;
}

/* the coefficient functions of lie_impl.h as expressions of t = theta^2 */
E dm_lie_sym_sinc(dm_expr_ctx *c, E t);
E dm_lie_sym_cosc(dm_expr_ctx *c, E t);
E dm_lie_sym_sinc3(dm_expr_ctx *c, E t);
E dm_lie_sym_dexpinv_coef(dm_expr_ctx *c, E t);
E dm_lie_sym_coefE(dm_expr_ctx *c, E t);
E dm_lie_sym_coefG(dm_expr_ctx *c, E t);
E dm_lie_sym_invsinc(dm_expr_ctx *c, E t);
/* the principal value of an angle in (-pi, pi] (atan2(sin, cos)) */
E dm_lie_sym_wrap(dm_expr_ctx *c, E a);

/* C = A B (3x3, row-major; C may alias A or B) */
void dm_lie_sym_m3_mul(dm_expr_ctx *c, const E *A, const E *B, E *C);
/* M = a I + b hat(w) + cc hat(w)^2 with leading dimension ld */
void dm_lie_sym_so3_poly(dm_expr_ctx *c, const E *w, E a, E b, E cc, E *M, size_t ld);
/* M = d I + b hat(w) + cc w w^T */
void dm_lie_sym_so3_poly_d(dm_expr_ctx *c, const E *w, E d, E b, E cc, E *M, size_t ld);
/* y = (a I + b hat(w) + cc hat(w)^2) x (y may alias x) */
void dm_lie_sym_so3_poly_apply(dm_expr_ctx *c, const E *w, E a, E b, E cc, const E *x, E *y);
/* y = A x, y = A^T x for 3x3 A (y may alias x) */
void dm_lie_sym_m3_apply(dm_expr_ctx *c, const E *A, int trans, const E *x, E *y);
/* the SO(3) exponential and logarithm */
void dm_lie_sym_so3_exp(dm_expr_ctx *c, const E *w, E *R);
void dm_lie_sym_so3_log(dm_expr_ctx *c, const E *R, E *w);

#endif
