/* expr_diff.c -- traversals of the DAG: symbolic differentiation (memoised
 * per variable), gradients, Jacobians, Hessians, substitution, numeric
 * evaluation, dependency queries.  All traversals are iterative (no
 * recursion), so arbitrarily deep expressions are safe. */
#include <config.h>
#include "expr/expr_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double dm_expr__powi_value(double x, int n);

/* {==================================================================
 * reachable sets
 * =================================================================== */

static int grow_i32(int32_t **p, size_t *cap, size_t need)
{
  if (need <= *cap)
    return 0;
  size_t c = *cap ? *cap : 256;
  while (c < need)
    c *= 2;
  int32_t *q = realloc(*p, c * sizeof *q);
  if (q == NULL)
    return -1;
  *p = q;
  *cap = c;
  return 0;
}

static int scratch_reserve(dm_expr_ctx *ctx)
{
  if (ctx->scap < ctx->n) {
    size_t c = ctx->cap;
    uint32_t *s = realloc(ctx->stamp, c * sizeof *s);
    if (s == NULL)
      return -1;
    ctx->stamp = s;
    int32_t *a = realloc(ctx->aux, c * sizeof *a);
    if (a == NULL)
      return -1;
    ctx->aux = a;
    memset(ctx->stamp + ctx->scap, 0, (c - ctx->scap) * sizeof *s);
    ctx->scap = c;
  }
  if (++ctx->epoch == 0) {        /* wrapped: forget every old mark */
    memset(ctx->stamp, 0, ctx->scap * sizeof *ctx->stamp);
    ctx->epoch = 1;
  }
  return 0;
}

static int cmp_i32(const void *x, const void *y)
{
  int32_t a = *(const int32_t *)x, b = *(const int32_t *)y;
  return (a > b) - (a < b);
}


/* Reachable nodes from roots, not descending below nodes where stop()
 * says so (they are still collected). */
static long collect(dm_expr_ctx *ctx, size_t nroot, const dm_expr *roots,
                    dm_expr__stop_fn stop, const void *data)
{
  if (scratch_reserve(ctx) != 0)
    return -1;
  const uint32_t ep = ctx->epoch;
  size_t nl = 0, ns = 0;
  int32_t lo = INT32_MAX, hi = -1;
  for (size_t r = 0; r < nroot; r++) {
    if (!dm_expr__valid(ctx, roots[r]))
      continue;
    if (grow_i32(&ctx->stack, &ctx->stackcap, ns + 1) != 0)
      return -1;
    ctx->stack[ns++] = roots[r];
    while (ns > 0) {
      int32_t e = ctx->stack[--ns];
      if (ctx->stamp[e] == ep)
        continue;
      ctx->stamp[e] = ep;
      if (grow_i32(&ctx->list, &ctx->listcap, nl + 1) != 0 ||
          grow_i32(&ctx->stack, &ctx->stackcap, ns + 3) != 0)
        return -1;
      ctx->list[nl++] = e;
      if (e < lo) lo = e;
      if (e > hi) hi = e;
      if (stop != NULL && stop(ctx, e, data))
        continue;
      const dm_node *nd = &ctx->node[e];
      int k = dm_expr__arity(nd->op);
      if (k >= 1 && ctx->stamp[nd->a] != ep) ctx->stack[ns++] = nd->a;
      if (k >= 2 && ctx->stamp[nd->b] != ep) ctx->stack[ns++] = nd->b;
      if (k >= 3 && ctx->stamp[nd->c] != ep) ctx->stack[ns++] = nd->c;
    }
  }
  if (nl > 1) {
    if ((size_t)(hi - lo) < 8 * nl) {      /* dense: scan the range */
      size_t k = 0;
      for (int32_t i = lo; i <= hi; i++)
        if (ctx->stamp[i] == ep)
          ctx->list[k++] = i;
    } else {
      qsort(ctx->list, nl, sizeof *ctx->list, cmp_i32);
    }
  }
  return (long)nl;
}

long dm_expr__collect(dm_expr_ctx *ctx, size_t n, const dm_expr *roots)
{
  return collect(ctx, n, roots, NULL, NULL);
}

long dm_expr__collect_stop(dm_expr_ctx *ctx, size_t n, const dm_expr *roots,
                           dm_expr__stop_fn stop, const void *data)
{
  return collect(ctx, n, roots, stop, data);
}


static int no_vars(const dm_expr_ctx *ctx, dm_expr e, const void *data)
{
  (void)data;
  return (ctx->node[e].flags & (DM_NF_SYM | DM_NF_PARAM)) == 0;
}

long dm_expr__collect_vars(dm_expr_ctx *ctx, size_t n, const dm_expr *roots)
{
  return collect(ctx, n, roots, no_vars, NULL);
}

int dm_expr_depends(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars)
{
  if (!dm_expr__valid(ctx, e) || no_vars(ctx, e, NULL))
    return 0;
  if (collect(ctx, 1, &e, no_vars, NULL) < 0) {
    dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    return 0;
  }
  for (size_t k = 0; k < n; k++)
    if (dm_expr__valid(ctx, vars[k]) && ctx->stamp[vars[k]] == ctx->epoch)
      return 1;
  return 0;
}

long dm_expr_free_vars(dm_expr_ctx *ctx, dm_expr e, dm_expr *out, size_t max)
{
  if (!dm_expr__valid(ctx, e))
    return -1;
  long nl = collect(ctx, 1, &e, no_vars, NULL);
  if (nl < 0) {
    dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    return -1;
  }
  long cnt = 0;
  for (long i = 0; i < nl; i++) {
    int op = ctx->node[ctx->list[i]].op;
    if (op == DM_EXPR_SYM || op == DM_EXPR_PARAM) {
      if (out != NULL && (size_t)cnt < max)
        out[cnt] = ctx->list[i];
      cnt++;
    }
  }
  return cnt;
}

/* {==================================================================
 * derivative memo
 * =================================================================== */

static size_t memo_slot(int32_t node, int32_t var, size_t mask)
{
  uint64_t h = ((uint64_t)(uint32_t)node << 32) | (uint32_t)var;
  h ^= h >> 29;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 32;
  return (size_t)h & mask;
}

int32_t dm_expr__memo_get(const dm_expr_ctx *ctx, int32_t node, int32_t var)
{
  if (ctx->memocap == 0)
    return -1;
  size_t mask = ctx->memocap - 1;
  for (size_t j = memo_slot(node, var, mask); ctx->memo[j].node >= 0;
       j = (j + 1) & mask)
    if (ctx->memo[j].node == node && ctx->memo[j].var == var)
      return ctx->memo[j].res;
  return -1;
}

int dm_expr__memo_put(dm_expr_ctx *ctx, int32_t node, int32_t var, int32_t res)
{
  if (2 * (ctx->nmemo + 1) > ctx->memocap) {
    size_t cap = ctx->memocap ? 2 * ctx->memocap : 1024;
    dm_memo_ent *t = malloc(cap * sizeof *t);
    if (t == NULL)
      return -1;
    for (size_t j = 0; j < cap; j++)
      t[j].node = -1;
    for (size_t j = 0; j < ctx->memocap; j++) {
      if (ctx->memo[j].node < 0)
        continue;
      size_t k = memo_slot(ctx->memo[j].node, ctx->memo[j].var, cap - 1);
      while (t[k].node >= 0)
        k = (k + 1) & (cap - 1);
      t[k] = ctx->memo[j];
    }
    free(ctx->memo);
    ctx->memo = t;
    ctx->memocap = cap;
  }
  size_t mask = ctx->memocap - 1, j = memo_slot(node, var, mask);
  while (ctx->memo[j].node >= 0)
    j = (j + 1) & mask;
  ctx->memo[j].node = node;
  ctx->memo[j].var = var;
  ctx->memo[j].res = res;
  ctx->nmemo++;
  return 0;
}

/* {==================================================================
 * differentiation
 * =================================================================== */

struct dstop { int32_t var; };

/* Do not descend into constant subtrees or nodes already differentiated. */
static int diff_stop(const dm_expr_ctx *ctx, dm_expr e, const void *data)
{
  const struct dstop *d = data;
  return no_vars(ctx, e, NULL) || dm_expr__memo_get(ctx, e, d->var) >= 0;
}

/* The derivative of node e given the derivatives of its operands (aux). */
static dm_expr diff_node(dm_expr_ctx *ctx, dm_expr e, dm_expr var,
                         dm_expr zero, dm_expr one)
{
  const dm_node nd = ctx->node[e];
  const int32_t *D = ctx->aux;
  dm_expr a = nd.a, b = nd.b, da = 0, db = 0;
  int k = dm_expr__arity(nd.op);
  if (k >= 1) da = D[a];
  if (k >= 2) db = D[b];
  switch (nd.op) {
  case DM_EXPR_CONST: return zero;
  case DM_EXPR_SYM:
  case DM_EXPR_PARAM: return e == var ? one : zero;
  case DM_EXPR_ADD: return dm_expr_add(ctx, da, db);
  case DM_EXPR_SUB: return dm_expr_sub(ctx, da, db);
  case DM_EXPR_MUL: {       /* operands built in a fixed order: node */
    dm_expr t1 = dm_expr_mul(ctx, da, b);     /* handles (and so printed */
    dm_expr t2 = dm_expr_mul(ctx, a, db);     /* operand order) must not */
    return dm_expr_add(ctx, t1, t2);          /* depend on the compiler  */
  }
  case DM_EXPR_DIV: {       /* (a/b)' = a'/b - (a/b)/b b'; (a/b)/b is shared */
    if (db == zero)         /* by the derivatives in every variable */
      return dm_expr_div(ctx, da, b);
    dm_expr q = dm_expr_div(ctx, e, b);
    dm_expr t = dm_expr_mul(ctx, q, db);
    if (da == zero)
      return dm_expr_neg(ctx, t);
    dm_expr u = dm_expr_div(ctx, da, b);
    return dm_expr_sub(ctx, u, t);
  }
  case DM_EXPR_POW: {
    dm_expr t = zero;
    if (db != zero) {
      dm_expr lg = dm_expr_unary(ctx, DM_EXPR_LOG, a);
      t = dm_expr_mul(ctx, dm_expr_mul(ctx, e, lg), db);
    }
    if (da != zero) {
      dm_expr pm1 = dm_expr_pow(ctx, a, dm_expr_sub(ctx, b, one));
      dm_expr u = dm_expr_mul(ctx, b, pm1);
      t = dm_expr_add(ctx, t, dm_expr_mul(ctx, u, da));
    }
    return t;
  }
  case DM_EXPR_POWI: {
    dm_expr c = dm_expr_const(ctx, nd.b);
    dm_expr p = dm_expr_powi(ctx, a, nd.b - 1);
    return dm_expr_mul(ctx, dm_expr_mul(ctx, c, p), da);
  }
  case DM_EXPR_ATAN2: {     /* (b a' - a b') / (a^2 + b^2) */
    dm_expr t1 = dm_expr_mul(ctx, b, da);
    dm_expr t2 = dm_expr_mul(ctx, a, db);
    dm_expr num = dm_expr_sub(ctx, t1, t2);
    dm_expr a2 = dm_expr_powi(ctx, a, 2);
    dm_expr b2 = dm_expr_powi(ctx, b, 2);
    return dm_expr_div(ctx, num, dm_expr_add(ctx, a2, b2));
  }
  case DM_EXPR_LT: case DM_EXPR_LE: case DM_EXPR_GT: case DM_EXPR_GE:
  case DM_EXPR_EQ: case DM_EXPR_NE: case DM_EXPR_SIGN:
    return zero;
  case DM_EXPR_NEG: return dm_expr_neg(ctx, da);
  case DM_EXPR_SQRT: {
    dm_expr half = dm_expr_const(ctx, 0.5);
    return dm_expr_div(ctx, dm_expr_mul(ctx, half, da), e);
  }
  case DM_EXPR_EXP: return dm_expr_mul(ctx, e, da);
  case DM_EXPR_LOG: return dm_expr_div(ctx, da, a);
  case DM_EXPR_SIN:
    return dm_expr_mul(ctx, dm_expr_unary(ctx, DM_EXPR_COS, a), da);
  case DM_EXPR_COS:
    return dm_expr_neg(ctx, dm_expr_mul(ctx, dm_expr_unary(ctx, DM_EXPR_SIN, a), da));
  case DM_EXPR_TAN: {
    dm_expr t2 = dm_expr_powi(ctx, e, 2);
    return dm_expr_mul(ctx, dm_expr_add(ctx, one, t2), da);
  }
  case DM_EXPR_ASIN:
  case DM_EXPR_ACOS: {
    dm_expr a2 = dm_expr_powi(ctx, a, 2);
    dm_expr s = dm_expr_unary(ctx, DM_EXPR_SQRT, dm_expr_sub(ctx, one, a2));
    dm_expr t = dm_expr_div(ctx, da, s);
    return nd.op == DM_EXPR_ASIN ? t : dm_expr_neg(ctx, t);
  }
  case DM_EXPR_ATAN: {
    dm_expr a2 = dm_expr_powi(ctx, a, 2);
    return dm_expr_div(ctx, da, dm_expr_add(ctx, one, a2));
  }
  case DM_EXPR_SINH:
    return dm_expr_mul(ctx, dm_expr_unary(ctx, DM_EXPR_COSH, a), da);
  case DM_EXPR_COSH:
    return dm_expr_mul(ctx, dm_expr_unary(ctx, DM_EXPR_SINH, a), da);
  case DM_EXPR_TANH: {
    dm_expr t2 = dm_expr_powi(ctx, e, 2);
    return dm_expr_mul(ctx, dm_expr_sub(ctx, one, t2), da);
  }
  case DM_EXPR_ABS:
    return dm_expr_mul(ctx, dm_expr_unary(ctx, DM_EXPR_SIGN, a), da);
  case DM_EXPR_SELECT:
    return dm_expr_select(ctx, a, D[b], D[nd.c]);
  default:
    return dm_expr__fail(ctx, DM_EINVAL, "expression: cannot differentiate %s",
                         dm_expr_op_name(nd.op));
  }
}

dm_expr dm_expr_diff(dm_expr_ctx *ctx, dm_expr e, dm_expr var)
{
  if (e == DM_EXPR_NONE || var == DM_EXPR_NONE)
    return DM_EXPR_NONE;
  if (!dm_expr__valid(ctx, e) || !dm_expr__valid(ctx, var))
    return dm_expr__fail(ctx, DM_EINVAL, "expression: invalid node handle");
  int vop = ctx->node[var].op;
  if (vop != DM_EXPR_SYM && vop != DM_EXPR_PARAM)
    return dm_expr__fail(ctx, DM_EINVAL, "expression: can only differentiate "
                         "with respect to a symbol or parameter, not %s",
                         dm_expr_op_name(vop));
  dm_expr zero = dm_expr_const(ctx, 0.0), one = dm_expr_const(ctx, 1.0);
  if (zero == DM_EXPR_NONE || one == DM_EXPR_NONE)
    return DM_EXPR_NONE;
  if (no_vars(ctx, e, NULL))
    return zero;
  int32_t r = dm_expr__memo_get(ctx, e, var);
  if (r >= 0)
    return r;
  struct dstop st = { var };
  long nl = collect(ctx, 1, &e, diff_stop, &st);
  if (nl < 0)
    return dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
  /* ctx->list may be reallocated by nothing below (constructors do not
   * traverse), but ctx->aux is indexed only by collected (old) nodes. */
  for (long i = 0; i < nl; i++) {
    int32_t x = ctx->list[i];
    if (no_vars(ctx, x, NULL)) {
      ctx->aux[x] = zero;
      continue;
    }
    int32_t m = dm_expr__memo_get(ctx, x, var);
    if (m < 0) {
      m = diff_node(ctx, x, var, zero, one);
      if (m == DM_EXPR_NONE)
        return DM_EXPR_NONE;
      if (dm_expr__memo_put(ctx, x, var, m) != 0)
        return dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    }
    ctx->aux[x] = m;
  }
  return ctx->aux[e];
}

int dm_expr__status(dm_expr_ctx *ctx, dm_err *err)
{
  if (err != NULL && ctx->err.status != DM_OK)
    *err = ctx->err;
  return ctx->err.status != DM_OK ? ctx->err.status : DM_EFAILED;
}

int dm_expr_jacobian(dm_expr_ctx *ctx, size_t m, const dm_expr *f, size_t n,
                     const dm_expr *vars, dm_expr *J, dm_err *err)
{
  for (size_t i = 0; i < m; i++) {
    int s = dm_expr_grad(ctx, f[i], n, vars, J + i * n, err);
    if (s != DM_OK)
      return s;
  }
  return DM_OK;
}

dm_expr dm_expr_dirderiv(dm_expr_ctx *ctx, dm_expr e, size_t n,
                         const dm_expr *vars, const dm_expr *dir)
{
  dm_expr s = dm_expr_const(ctx, 0.0);
  for (size_t i = 0; i < n; i++)
    s = dm_expr_add(ctx, s, dm_expr_mul(ctx, dm_expr_diff(ctx, e, vars[i]), dir[i]));
  return s;
}

/* {==================================================================
 * substitution and evaluation
 * =================================================================== */

/* Rebuild node x with operands replaced by their images in aux. */
static dm_expr rebuild(dm_expr_ctx *ctx, dm_expr x)
{
  const dm_node nd = ctx->node[x];
  const int32_t *A = ctx->aux;
  switch (dm_expr__arity(nd.op)) {
  case 0:
    return x;
  case 1:
    if (A[nd.a] == nd.a)
      return x;
    if (nd.op == DM_EXPR_POWI)
      return dm_expr_powi(ctx, A[nd.a], nd.b);
    return dm_expr_unary(ctx, nd.op, A[nd.a]);
  case 2:
    if (A[nd.a] == nd.a && A[nd.b] == nd.b)
      return x;
    return dm_expr_binary(ctx, nd.op, A[nd.a], A[nd.b]);
  default:
    if (A[nd.a] == nd.a && A[nd.b] == nd.b && A[nd.c] == nd.c)
      return x;
    return dm_expr_select(ctx, A[nd.a], A[nd.b], A[nd.c]);
  }
}

int dm_expr_subs(dm_expr_ctx *ctx, size_t ne, const dm_expr *e, dm_expr *out,
                 size_t n, const dm_expr *from, const dm_expr *to, dm_err *err)
{
  for (size_t k = 0; k < ne; k++)
    if (!dm_expr__valid(ctx, e[k]))
      return dm_err_set(err, DM_EINVAL, "subs: invalid expression handle");
  for (size_t k = 0; k < n; k++)
    if (!dm_expr__valid(ctx, from[k]) || !dm_expr__valid(ctx, to[k]))
      return dm_err_set(err, DM_EINVAL, "subs: invalid replacement handle");
  long nl = collect(ctx, ne, e, NULL, NULL);
  if (nl < 0)
    return dm_err_set(err, DM_ENOMEM, "subs: out of memory");
  for (long i = 0; i < nl; i++)
    ctx->aux[ctx->list[i]] = -1;
  for (size_t k = 0; k < n; k++)
    if (ctx->stamp[from[k]] == ctx->epoch)
      ctx->aux[from[k]] = to[k];
  for (long i = 0; i < nl; i++) {
    int32_t x = ctx->list[i];
    if (ctx->aux[x] >= 0)
      continue;
    dm_expr y = rebuild(ctx, x);
    if (y == DM_EXPR_NONE)
      return dm_expr__status(ctx, err);
    ctx->aux[x] = y;
  }
  for (size_t k = 0; k < ne; k++)
    out[k] = ctx->aux[e[k]];
  return DM_OK;
}

int dm_expr_eval(dm_expr_ctx *ctx, size_t ne, const dm_expr *e, double *out,
                 size_t n, const dm_expr *vars, const double *vals, dm_err *err)
{
  for (size_t k = 0; k < ne; k++)
    if (!dm_expr__valid(ctx, e[k]))
      return dm_err_set(err, DM_EINVAL, "eval: invalid expression handle");
  long nl = collect(ctx, ne, e, NULL, NULL);
  if (nl < 0)
    return dm_err_set(err, DM_ENOMEM, "eval: out of memory");
  double *val = malloc((size_t)(nl ? nl : 1) * sizeof *val);
  if (val == NULL)
    return dm_err_set(err, DM_ENOMEM, "eval: out of memory");
  for (long i = 0; i < nl; i++)
    ctx->aux[ctx->list[i]] = -1;
  for (size_t k = 0; k < n; k++)
    if (dm_expr__valid(ctx, vars[k]) && ctx->stamp[vars[k]] == ctx->epoch)
      ctx->aux[vars[k]] = -2 - (int32_t)k;
  for (long i = 0; i < nl; i++) {
    int32_t x = ctx->list[i];
    const dm_node nd = ctx->node[x];
    double v;
    if (ctx->aux[x] <= -2) {
      v = vals[-2 - ctx->aux[x]];
    } else if (nd.op == DM_EXPR_CONST) {
      v = ctx->cval[nd.a];
    } else if (nd.op == DM_EXPR_SYM || nd.op == DM_EXPR_PARAM) {
      free(val);
      return dm_err_set(err, DM_EINVAL, "eval: no value for %s '%s'",
                        nd.op == DM_EXPR_SYM ? "symbol" : "parameter",
                        ctx->names[nd.a]);
    } else {
      int k = dm_expr__arity(nd.op);
      double a = val[ctx->aux[nd.a]];
      double b = k >= 2 ? val[ctx->aux[nd.b]] : 0;
      if (nd.op == DM_EXPR_POWI)
        v = dm_expr__powi_value(a, nd.b);
      else if (k == 1)
        v = dm_expr_unary_value(nd.op, a);
      else if (k == 2)
        v = dm_expr_binary_value(nd.op, a, b);
      else
        v = a != 0 ? b : val[ctx->aux[nd.c]];
    }
    val[i] = v;
    ctx->aux[x] = (int32_t)i;
  }
  for (size_t k = 0; k < ne; k++)
    out[k] = val[ctx->aux[e[k]]];
  free(val);
  return DM_OK;
}
