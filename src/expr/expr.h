/* expr.h -- the expression engine's DAG: build, simplify, differentiate,
 * substitute, evaluate and print symbolic expressions.
 *
 * A dm_expr_ctx owns every node.  A node is named by a small integer handle
 * (dm_expr) into its context; handles stay valid for the life of the context
 * and nodes never change.  Children always have smaller handles than their
 * parents, so ascending handle order is a topological order.
 *
 * Construction hash-conses (structurally equal nodes are one node) and
 * keeps sums and products in a normal form (expr_norm.c): flattened, like
 * terms collected (t + t -> 2*t, c1*t + c2*t -> (c1 + c2)*t, t - t -> 0),
 * equal factors collected into integer powers (x*x -> x^2, x^2*x -> x^3,
 * x/x -> 1, (x^m)^n -> x^(m*n)), constants folded, a coefficient common to
 * every term taken out (0.5*x + 0.5*y -> 0.5*(x + y)); sums and products
 * equal up to order and grouping are one node, which keeps the order of
 * first construction for printing (coefficient first, the first positive
 * term first, the constant last: 2*m2*cos(phi)*r1*r2, x - y + 3).  The
 * identities that change IEEE results (t - t, 0*t, x/x, x^m*x^n where x
 * is 0, Inf or NaN: the written form is NaN there) are listed in
 * expr_norm.c; apart from them, results differ by rounding only.
 *
 * Error behaviour: builders return DM_EXPR_NONE on failure (out of memory,
 * wrong arity, invalid handle, unknown name) and record the reason in the
 * context's sticky error (dm_expr_ctx_err); every builder returns
 * DM_EXPR_NONE when given DM_EXPR_NONE, so a chain of calls needs one check
 * at its end.  Functions returning int return a dm status and also fill the
 * dm_err they are given (may be NULL).
 *
 * Ownership: dm_expr_ctx_alloc / dm_expr_ctx_free.  Strings returned by
 * dm_expr_name belong to the context; dm_expr_to_string returns malloc'ed
 * memory the caller frees.  A context is not thread safe (one per Lua
 * state); compiled tapes (tape.h) are independent of it and are.
 */
#ifndef DM_EXPR_H
#define DM_EXPR_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

typedef int32_t dm_expr;
#define DM_EXPR_NONE ((dm_expr)-1)

typedef struct dm_expr_ctx dm_expr_ctx;

enum dm_expr_op {
  /* leaves */
  DM_EXPR_CONST, DM_EXPR_SYM, DM_EXPR_PARAM,
  /* binary */
  DM_EXPR_ADD, DM_EXPR_SUB, DM_EXPR_MUL, DM_EXPR_DIV, DM_EXPR_POW,
  DM_EXPR_ATAN2,
  /* comparisons: 1.0 when true, 0.0 when false (NaN compares false except ~=) */
  DM_EXPR_LT, DM_EXPR_LE, DM_EXPR_GT, DM_EXPR_GE, DM_EXPR_EQ, DM_EXPR_NE,
  /* x^n, n an int stored in the node (dm_expr_powi_exponent) */
  DM_EXPR_POWI,
  /* unary */
  DM_EXPR_NEG, DM_EXPR_SQRT, DM_EXPR_EXP, DM_EXPR_LOG, DM_EXPR_SIN,
  DM_EXPR_COS, DM_EXPR_TAN, DM_EXPR_ASIN, DM_EXPR_ACOS, DM_EXPR_ATAN,
  DM_EXPR_SINH, DM_EXPR_COSH, DM_EXPR_TANH, DM_EXPR_ABS,
  DM_EXPR_SIGN,          /* -1, 0, 1 (NaN for NaN); appears in d|x|/dx */
  /* select(cond, a, b): a where cond != 0, else b */
  DM_EXPR_SELECT,
  DM_EXPR_NOPS
};

/* ---- context ------------------------------------------------------------ */

dm_expr_ctx *dm_expr_ctx_alloc(void);
void dm_expr_ctx_free(dm_expr_ctx *ctx);            /* NULL: no-op */
/* The first error recorded since the last clear (status DM_OK if none). */
const dm_err *dm_expr_ctx_err(const dm_expr_ctx *ctx);
void dm_expr_ctx_clear_err(dm_expr_ctx *ctx);
/* Number of nodes in the context. */
size_t dm_expr_ctx_size(const dm_expr_ctx *ctx);

/* ---- building ------------------------------------------------------------- */

dm_expr dm_expr_const(dm_expr_ctx *ctx, double x);
/* A symbol / parameter with this name (the same name gives the same node;
 * a symbol and a parameter with one name are different nodes).  Names are
 * non-empty, at most 255 bytes. */
dm_expr dm_expr_sym(dm_expr_ctx *ctx, const char *name);
dm_expr dm_expr_param(dm_expr_ctx *ctx, const char *name);

dm_expr dm_expr_add(dm_expr_ctx *ctx, dm_expr a, dm_expr b);
dm_expr dm_expr_sub(dm_expr_ctx *ctx, dm_expr a, dm_expr b);
dm_expr dm_expr_mul(dm_expr_ctx *ctx, dm_expr a, dm_expr b);
dm_expr dm_expr_div(dm_expr_ctx *ctx, dm_expr a, dm_expr b);
dm_expr dm_expr_pow(dm_expr_ctx *ctx, dm_expr a, dm_expr b);
dm_expr dm_expr_powi(dm_expr_ctx *ctx, dm_expr a, int n);
dm_expr dm_expr_neg(dm_expr_ctx *ctx, dm_expr a);
/* Any unary op (DM_EXPR_NEG .. DM_EXPR_SIGN), binary op (ADD .. NE) or
 * SELECT; a wrong arity records DM_EINVAL. */
dm_expr dm_expr_unary(dm_expr_ctx *ctx, int op, dm_expr a);
dm_expr dm_expr_binary(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b);
dm_expr dm_expr_select(dm_expr_ctx *ctx, dm_expr cond, dm_expr a, dm_expr b);
/* The value of a unary op (NEG .. SIGN) or binary op (ADD .. NE, not POWI)
 * at numbers: what constant folding computes; comparisons give 1 or 0;
 * an op of the other kind gives NaN. */
double dm_expr_unary_value(int op, double x);
double dm_expr_binary_value(int op, double a, double b);
/* Apply a function by name ("sin", "atan2", "pow", "select", "lt", ...);
 * unknown name or wrong number of arguments records DM_ENOTFOUND or
 * DM_EINVAL with a message naming the function. */
dm_expr dm_expr_call(dm_expr_ctx *ctx, const char *fname, int nargs,
                     const dm_expr *args);
/* The op of a function name and its arity, or -1 when unknown. */
int dm_expr_func_lookup(const char *fname, int *arity);
/* Short name of an op: "add", "sin", "select", ... */
const char *dm_expr_op_name(int op);

/* ---- inspecting ------------------------------------------------------------ */

/* The op of e, or -1 for an invalid handle. */
int dm_expr_kind(const dm_expr_ctx *ctx, dm_expr e);
/* Number of operands (0 for leaves) and operand k (0-based). */
int dm_expr_nargs(const dm_expr_ctx *ctx, dm_expr e);
dm_expr dm_expr_arg(const dm_expr_ctx *ctx, dm_expr e, int k);
/* 1 and *x = value when e is a constant, else 0. */
int dm_expr_is_const(const dm_expr_ctx *ctx, dm_expr e, double *x);
int dm_expr_powi_exponent(const dm_expr_ctx *ctx, dm_expr e);
/* Name of a symbol or parameter, NULL otherwise. */
const char *dm_expr_name(const dm_expr_ctx *ctx, dm_expr e);
/* 1 if e contains a symbol / any parameter. */
int dm_expr_has_sym(const dm_expr_ctx *ctx, dm_expr e);
int dm_expr_has_param(const dm_expr_ctx *ctx, dm_expr e);
/* 1 if e contains any of the nodes vars[0..n-1] (0 on error). */
int dm_expr_depends(dm_expr_ctx *ctx, dm_expr e, size_t n,
                    const dm_expr *vars);
/* The symbols and parameters e depends on, in handle order: stores at most
 * max of them in out (may be NULL) and returns how many there are
 * (-1 on error). */
long dm_expr_free_vars(dm_expr_ctx *ctx, dm_expr e, dm_expr *out, size_t max);

/* ---- calculus (expr_diff.c) ------------------------------------------------ */

/* d e / d var, var a symbol or parameter.  Results are memoised per
 * (node, variable) for the life of the context, so derivatives of related
 * expressions share structure. */
dm_expr dm_expr_diff(dm_expr_ctx *ctx, dm_expr e, dm_expr var);
/* grad[i] = d e / d vars[i], by reverse accumulation (adjoints): one sweep
 * for all variables, sharing the chain rule through common
 * subexpressions; memoised like dm_expr_diff. */
int dm_expr_grad(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                 dm_expr *grad, dm_err *err);
/* J[i*n + j] = d f_i / d vars_j, i < m. */
int dm_expr_jacobian(dm_expr_ctx *ctx, size_t m, const dm_expr *f, size_t n,
                     const dm_expr *vars, dm_expr *J, dm_err *err);
/* H[i*n + j] = d2 e / d vars_i d vars_j; the upper triangle is derived and
 * mirrored.  Rows are gradients of the gradient entries, by reverse sweeps
 * that stop at preaccumulated shared subexpressions, or by forward
 * differentiation -- both are built (the second only when affordable: it
 * costs the size of a row's DAG per variable) and the one with fewer
 * operations is kept. */
int dm_expr_hessian(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                    dm_expr *H, dm_err *err);
/* Sparse derivatives.  Row i of a dm_expr_sparse holds the entries k in
 * [rowptr[i], rowptr[i+1]): column col[k] (ascending), expression val[k];
 * entries whose derivative is the constant 0 are left out (the structural
 * pattern as the simplifier sees it). */
typedef struct dm_expr_sparse {
  size_t nrow, ncol, nnz;
  size_t *rowptr;           /* nrow + 1 */
  uint32_t *col;            /* nnz */
  dm_expr *val;             /* nnz */
} dm_expr_sparse;
void dm_expr_sparse_free(dm_expr_sparse *s);   /* zeroes *s; NULL: no-op */
/* The upper triangle (col >= row) of the Hessian of e, the same expressions
 * as dm_expr_hessian, at a cost proportional to the size of the DAG of the
 * gradient (plus the entries), not to n times it; the variables must be
 * distinct (DM_EINVAL).  On error *H is zeroed. */
int dm_expr_hessian_sparse(dm_expr_ctx *ctx, dm_expr e, size_t n,
                           const dm_expr *vars, dm_expr_sparse *H, dm_err *err);
/* J(i, j) = d f_i / d vars_j on its pattern, one reverse sweep per row. */
int dm_expr_jacobian_sparse(dm_expr_ctx *ctx, size_t m, const dm_expr *f,
                            size_t n, const dm_expr *vars, dm_expr_sparse *J,
                            dm_err *err);
/* sum_i (d e / d vars_i) dir_i. */
dm_expr dm_expr_dirderiv(dm_expr_ctx *ctx, dm_expr e, size_t n,
                         const dm_expr *vars, const dm_expr *dir);
/* Replace each node from[k] (typically symbols or parameters) by to[k] in
 * the ne expressions e, writing out[ne]; simplification reapplies. */
int dm_expr_subs(dm_expr_ctx *ctx, size_t ne, const dm_expr *e, dm_expr *out,
                 size_t n, const dm_expr *from, const dm_expr *to, dm_err *err);
/* Numeric value of e with the symbols/parameters vars[k] set to vals[k];
 * an unbound symbol or parameter is DM_EINVAL naming it.  NaN results are
 * not errors (they propagate as IEEE says). */
int dm_expr_eval(dm_expr_ctx *ctx, size_t ne, const dm_expr *e, double *out,
                 size_t n, const dm_expr *vars, const double *vals,
                 dm_err *err);

/* ---- printing (expr_print.c) ------------------------------------------------ */

/* Readable infix with minimal parentheses, e.g. "0.5*(r^2 + z^2)",
 * "-1/sqrt(r^2 + z^2)", "select(x < 0, -x, x)"; numbers shortest round-trip.
 * Output longer than max_len bytes (0: no limit) ends in "...".  Returns a
 * malloc'ed string or NULL (out of memory / invalid handle; err filled). */
char *dm_expr_to_string(dm_expr_ctx *ctx, dm_expr e, size_t max_len,
                        dm_err *err);

#endif
