/* expr_grad.c -- gradients by reverse accumulation (adjoints) on the DAG.
 *
 * Forward differentiation repeats the chain rule through shared
 * subexpressions once per variable; accumulating adjoints from the root
 * down visits each node once and expresses every partial derivative
 * through the adjoints of shared subexpressions (for L(|q|^2) the gradient
 * becomes 2 q_i L'(u) with L'(u) built once), which is what makes gradients
 * and Hessians (expr_hessian.c) compact. */
#include <config.h>
#include "expr/sweep_impl.h"

#include <stdlib.h>
#include <string.h>

static int acc(dm_expr_ctx *ctx, swp *S, dm_expr c, dm_expr w, dm_expr zero);

#define MUL(a, b) dm_expr_mul(ctx, (a), (b))
#define DIV(a, b) dm_expr_div(ctx, (a), (b))
#define ADD(a, b) dm_expr_add(ctx, (a), (b))
#define SUB(a, b) dm_expr_sub(ctx, (a), (b))
#define NEG(a) dm_expr_neg(ctx, (a))
#define UN(op, a) dm_expr_unary(ctx, (op), (a))
#define K(x) dm_expr_const(ctx, (x))

/* Pass the adjoint w of node x on to its operands. */
static int backprop(dm_expr_ctx *ctx, swp *S, dm_expr x, dm_expr w, dm_expr zero,
                    dm_expr one)
{
  const dm_node nd = ctx->node[x];
  dm_expr a = nd.a, b = nd.b, t;
  switch (nd.op) {
  case DM_EXPR_ADD:
    return acc(ctx, S, a, w, zero) | acc(ctx, S, b, w, zero);
  case DM_EXPR_SUB:
    return acc(ctx, S, a, w, zero) | acc(ctx, S, b, NEG(w), zero);
  case DM_EXPR_MUL:
    return acc(ctx, S, a, MUL(w, b), zero) | acc(ctx, S, b, MUL(w, a), zero);
  case DM_EXPR_DIV:                       /* d(a/b)/db = -(a/b)/b */
    if (acc(ctx, S, a, DIV(w, b), zero) != 0)
      return -1;
    if (!(ctx->node[b].flags & (DM_NF_SYM | DM_NF_PARAM)))
      return 0;
    t = DIV(x, b);
    return acc(ctx, S, b, NEG(MUL(w, t)), zero);
  case DM_EXPR_POWI:
    t = dm_expr_powi(ctx, a, nd.b - 1);
    return acc(ctx, S, a, MUL(w, MUL(K(nd.b), t)), zero);
  case DM_EXPR_POW:
    if (ctx->node[a].flags & (DM_NF_SYM | DM_NF_PARAM)) {
      t = dm_expr_pow(ctx, a, SUB(b, one));
      if (acc(ctx, S, a, MUL(w, MUL(b, t)), zero) != 0)
        return -1;
    }
    if (ctx->node[b].flags & (DM_NF_SYM | DM_NF_PARAM)) {
      t = UN(DM_EXPR_LOG, a);
      return acc(ctx, S, b, MUL(w, MUL(x, t)), zero);
    }
    return 0;
  case DM_EXPR_ATAN2: {                   /* atan2(a, b): angle of (b, a) */
    dm_expr a2 = dm_expr_powi(ctx, a, 2);
    dm_expr den = ADD(a2, dm_expr_powi(ctx, b, 2));
    t = DIV(b, den);
    if (acc(ctx, S, a, MUL(w, t), zero) != 0)
      return -1;
    t = DIV(a, den);
    return acc(ctx, S, b, NEG(MUL(w, t)), zero);
  }
  case DM_EXPR_NEG:
    return acc(ctx, S, a, NEG(w), zero);
  case DM_EXPR_SQRT:
    return acc(ctx, S, a, DIV(MUL(K(0.5), w), x), zero);
  case DM_EXPR_EXP:
    return acc(ctx, S, a, MUL(w, x), zero);
  case DM_EXPR_LOG:
    return acc(ctx, S, a, DIV(w, a), zero);
  case DM_EXPR_SIN:
    return acc(ctx, S, a, MUL(w, UN(DM_EXPR_COS, a)), zero);
  case DM_EXPR_COS:
    return acc(ctx, S, a, NEG(MUL(w, UN(DM_EXPR_SIN, a))), zero);
  case DM_EXPR_TAN:
    t = dm_expr_powi(ctx, x, 2);
    return acc(ctx, S, a, MUL(w, ADD(one, t)), zero);
  case DM_EXPR_ASIN:
  case DM_EXPR_ACOS:
    t = dm_expr_powi(ctx, a, 2);
    t = DIV(w, UN(DM_EXPR_SQRT, SUB(one, t)));
    return acc(ctx, S, a, nd.op == DM_EXPR_ASIN ? t : NEG(t), zero);
  case DM_EXPR_ATAN:
    t = dm_expr_powi(ctx, a, 2);
    return acc(ctx, S, a, DIV(w, ADD(one, t)), zero);
  case DM_EXPR_SINH:
    return acc(ctx, S, a, MUL(w, UN(DM_EXPR_COSH, a)), zero);
  case DM_EXPR_COSH:
    return acc(ctx, S, a, MUL(w, UN(DM_EXPR_SINH, a)), zero);
  case DM_EXPR_TANH:
    t = dm_expr_powi(ctx, x, 2);
    return acc(ctx, S, a, MUL(w, SUB(one, t)), zero);
  case DM_EXPR_ABS:
    return acc(ctx, S, a, MUL(w, UN(DM_EXPR_SIGN, a)), zero);
  case DM_EXPR_SELECT:
    t = dm_expr_select(ctx, a, w, zero);
    if (acc(ctx, S, b, t, zero) != 0)
      return -1;
    return acc(ctx, S, nd.c, dm_expr_select(ctx, a, zero, w), zero);
  default:                                /* leaves, sign, comparisons */
    return 0;
  }
}

/* {==================================================================
 * sweeps
 * =================================================================== */

int dm_expr__rows_push(rows *r, uint32_t j, dm_expr x)
{
  if (r->n == r->cap) {
    size_t c = r->cap ? 2 * r->cap : 256;
    uint32_t *i2 = realloc(r->idx, c * sizeof *i2);
    if (i2 == NULL)
      return -1;
    r->idx = i2;
    dm_expr *v2 = realloc(r->val, c * sizeof *v2);
    if (v2 == NULL)
      return -1;
    r->val = v2;
    r->cap = c;
  }
  r->idx[r->n] = j;
  r->val[r->n++] = x;
  return 0;
}

void dm_expr__rows_free(rows *r)
{
  free(r->idx);
  free(r->val);
  memset(r, 0, sizeof *r);
}

int dm_expr__cmp_ent(const void *a, const void *b)
{
  uint32_t x = ((const ent *)a)->j, y = ((const ent *)b)->j;
  return (x > y) - (x < y);
}

/* Adjoints (ctx->aux of the collected nodes): -2 independent of the
 * variables, -1 dependent without an adjoint yet, >= 0 the adjoint, <= -3
 * the chain -3 - A[c] of contributions not summed yet.  Contributions are
 * added one by one while the sum is short; past 8 terms the rest wait in
 * a chain and are summed at once when the node is reached
 * (dm_expr__sum_n), which keeps a node with k contributions linear in k
 * (adding them one by one flattens the growing sum each time: an N-body
 * potential's gradient entries have N - 1). */
static int acc(dm_expr_ctx *ctx, swp *S, dm_expr c, dm_expr w, dm_expr zero)
{
  if (w == DM_EXPR_NONE)
    return -1;
  int32_t *A = ctx->aux;
  if (w == zero || A[c] == -2)            /* -2: independent of the vars */
    return 0;
  if (A[c] == -1) {
    A[c] = w;
    return 0;
  }
  if (A[c] >= 0 && dm_expr__nlen(ctx, A[c], 0) < 8) {   /* short: add now */
    A[c] = dm_expr_add(ctx, A[c], w);
    return A[c] == DM_EXPR_NONE ? -1 : 0;
  }
  if (dm_expr__grow(&S->cb, &S->capcb, S->ncb + 2, sizeof *S->cb) ||
      (A[c] >= 0 && dm_expr__grow(&S->ch, &S->capch, S->nch + 1, sizeof *S->ch))) {
    dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    return -1;
  }
  if (A[c] >= 0) {                        /* a second one: a new chain */
    int32_t h = (int32_t)S->nch++;
    S->cb[S->ncb] = (contrib){ A[c], -1 };
    S->ch[h] = (chain){ (int32_t)S->ncb, (int32_t)S->ncb, 1 };
    S->ncb++;
    A[c] = -3 - h;
  }
  chain *C = &S->ch[-3 - A[c]];
  S->cb[S->ncb] = (contrib){ w, -1 };
  S->cb[C->last].next = (int32_t)S->ncb;
  C->last = (int32_t)S->ncb++;
  C->count++;
  return 0;
}

/* The adjoint of c with its pending contributions summed at once into *w
 * (< 0: no adjoint, as in A).  Returns -1 on failure (the context's error set). */
static int adjoint(dm_expr_ctx *ctx, swp *S, dm_expr c, dm_expr *w)
{
  int32_t *A = ctx->aux;
  *w = A[c];
  if (A[c] > -3)
    return 0;
  const chain *C = &S->ch[-3 - A[c]];
  dm_expr r;
  if (dm_expr__grow(&S->terms, &S->capterms, (size_t)C->count, sizeof *S->terms)) {
    dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    return -1;
  }
  size_t k = 0;
  for (int32_t e = C->first; e >= 0; e = S->cb[e].next)
    S->terms[k++] = S->cb[e].w;
  r = dm_expr__sum_n(ctx, k, S->terms);
  if (r == DM_EXPR_NONE)
    return -1;
  *w = A[c] = r;
  return 0;
}

static size_t vslot(int32_t x, size_t mask)
{
  return (size_t)dm_expr__mix64((uint64_t)(uint32_t)x) & mask;
}

/* Index of variable node x, or -1. */
long dm_expr__var_index(const swp *S, int32_t x)
{
  for (size_t j = vslot(x, S->vmask); S->vtab[j] >= 0; j = (j + 1) & S->vmask)
    if (S->vars[S->vtab[j]] == x)
      return S->vtab[j];
  return -1;
}

/* The variable table (the first index of a variable listed twice) and the
 * buffers; vars must be symbols or parameters (checked by the caller). */
int dm_expr__swp_init(dm_expr_ctx *ctx, swp *S, size_t n, const dm_expr *vars)
{
  memset(S, 0, sizeof *S);
  S->n = n;
  S->vars = vars;
  S->root = DM_EXPR_NONE;
  S->zero = dm_expr_const(ctx, 0.0);
  S->one = dm_expr_const(ctx, 1.0);
  if (S->zero == DM_EXPR_NONE || S->one == DM_EXPR_NONE)
    return -1;
  size_t cap = 16;
  while (cap < 2 * n)
    cap *= 2;
  S->vmask = cap - 1;
  S->vtab = malloc(cap * sizeof *S->vtab);
  S->touch = malloc((n ? n : 1) * sizeof *S->touch);
  S->tmp = malloc((n ? n : 1) * sizeof *S->tmp);
  if (S->vtab == NULL || S->touch == NULL || S->tmp == NULL)
    return -1;
  memset(S->vtab, 0xff, cap * sizeof *S->vtab);
  for (size_t i = 0; i < n; i++) {
    if (dm_expr__var_index(S, vars[i]) >= 0)
      continue;
    size_t j = vslot(vars[i], S->vmask);
    while (S->vtab[j] >= 0)
      j = (j + 1) & S->vmask;
    S->vtab[j] = (int32_t)i;
  }
  return 0;
}

void dm_expr__swp_free(swp *S)
{
  free(S->vtab);
  free(S->touch);
  free(S->tmp);
  free(S->cb);
  free(S->ch);
  free(S->terms);
}

long dm_expr__known_find(const swp *S, dm_expr x)
{
  size_t lo = 0, hi = S->nk;
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    if (S->knode[mid] < x)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (lo < S->nk && S->knode[lo] == x) ? (long)lo : -1;
}

static int sweep_stop(const dm_expr_ctx *ctx, dm_expr x, const void *data)
{
  const swp *S = data;
  if ((ctx->node[x].flags & (DM_NF_SYM | DM_NF_PARAM)) == 0)
    return 1;
  return x != S->root && dm_expr__known_find(S, x) >= 0;
}

int dm_expr__is_leafvar(const dm_expr_ctx *ctx, const swp *S, int32_t x, long *j)
{
  int op = ctx->node[x].op;
  if (op != DM_EXPR_SYM && op != DM_EXPR_PARAM)
    return 0;
  return (*j = dm_expr__var_index(S, x)) >= 0;
}

/* The nonzero derivatives of root in the variables, by accumulating
 * adjoints from root down (applying w * row(y) at known nodes y), appended
 * to out as one row (ascending variable index).  The cost is the size of
 * the part of root's DAG above the known nodes plus the known rows it
 * meets, whatever the number of variables.  Returns 0, or -1 (the
 * context's error is set). */
int dm_expr__sweep(dm_expr_ctx *ctx, swp *S, dm_expr root, rows *out)
{
  const dm_expr zero = S->zero;
  long j;
  S->root = root;
  long nl = dm_expr__collect_stop(ctx, 1, &root, sweep_stop, S);
  if (nl < 0) {
    dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    return -1;
  }
  /* aux: -2 independent of the vars, -1 dependent (no adjoint yet), else
   * the adjoint accumulated so far */
  int32_t *A = ctx->aux;
  const int32_t *list = ctx->list;
  for (long i = 0; i < nl; i++) {         /* children before parents */
    dm_expr x = list[i];
    const dm_node *nd = &ctx->node[x];
    int ar = dm_expr__arity(nd->op);
    A[x] = -2;
    if (!(nd->flags & (DM_NF_SYM | DM_NF_PARAM)))
      continue;
    if (dm_expr__is_leafvar(ctx, S, x, &j) ||
        (x != root && dm_expr__known_find(S, x) >= 0))
      A[x] = -1;
    else if ((ar >= 1 && A[nd->a] == -1) || (ar >= 2 && A[nd->b] == -1) ||
             (ar >= 3 && A[nd->c] == -1))
      A[x] = -1;
  }
  if (A[root] == -1)
    A[root] = S->one;
  size_t nt = 0;
  const uint32_t ep = ctx->epoch;
  S->ncb = S->nch = 0;
  for (long i = nl - 1; i >= 0; i--) {    /* parents before children */
    dm_expr x = list[i], w;
    long ki;
    if (adjoint(ctx, S, x, &w) != 0)
      return -1;
    if (w < 0)
      continue;
    if (x != root && (ki = dm_expr__known_find(S, x)) >= 0) {
      for (size_t k = S->koff[ki]; k < S->koff[ki + 1]; k++) {
        dm_expr v = S->vars[S->kr->idx[k]];
        if (ctx->stamp[v] != ep) {        /* a variable no path reached */
          ctx->stamp[v] = ep;
          A[v] = -1;
          S->touch[nt++] = S->kr->idx[k];
        }
        if (acc(ctx, S, v, MUL(w, S->kr->val[k]), zero) != 0)
          return -1;
      }
      continue;
    }
    if (backprop(ctx, S, x, w, zero, S->one) != 0)
      return -1;
  }
  size_t ne = 0;
  for (long i = 0; i < nl; i++)
    if (dm_expr__is_leafvar(ctx, S, list[i], &j) && A[list[i]] >= 0 && A[list[i]] != zero)
      S->tmp[ne++] = (ent){ (uint32_t)j, A[list[i]] };
  for (size_t t = 0; t < nt; t++) {
    dm_expr v = S->vars[S->touch[t]], w;
    if (adjoint(ctx, S, v, &w) != 0)
      return -1;
    if (w >= 0 && w != zero)
      S->tmp[ne++] = (ent){ S->touch[t], w };
  }
  qsort(S->tmp, ne, sizeof *S->tmp, dm_expr__cmp_ent);
  for (size_t k = 0; k < ne; k++)
    if (dm_expr__rows_push(out, S->tmp[k].j, S->tmp[k].x) != 0) {
      dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
      return -1;
    }
  return 0;
}

int dm_expr__check_vars(dm_expr_ctx *ctx, dm_expr e, size_t n,
                        const dm_expr *vars, const char *who, dm_err *err)
{
  if (!dm_expr__valid(ctx, e))
    return dm_err_set(err, DM_EINVAL, "%s: invalid expression handle", who);
  for (size_t i = 0; i < n; i++) {
    int op = dm_expr_kind(ctx, vars[i]);
    if (op != DM_EXPR_SYM && op != DM_EXPR_PARAM)
      return dm_err_set(err, DM_EINVAL, "%s: variable %zu is not a symbol "
                        "or parameter", who, i + 1);
  }
  return DM_OK;
}

/* Memoise (e, vars[i]) -> grad[i], keeping results computed earlier. */
static int memoise(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                   dm_expr *grad, dm_err *err)
{
  for (size_t i = 0; i < n; i++) {
    dm_expr m = dm_expr__memo_get(ctx, e, vars[i]);
    if (m >= 0)
      grad[i] = m;
    else if (dm_expr__memo_put(ctx, e, vars[i], grad[i]) != 0)
      return dm_err_set(err, DM_ENOMEM, "grad: out of memory");
  }
  return DM_OK;
}

/* A sparse row into a dense one (a variable listed twice gets the
 * derivative of its first listing). */
static void densify(const swp *S, const rows *r, size_t from, dm_expr *out)
{
  for (size_t i = 0; i < S->n; i++)
    out[i] = S->zero;
  for (size_t k = from; k < r->n; k++)
    out[r->idx[k]] = r->val[k];
  for (size_t i = 0; i < S->n; i++) {
    long f = dm_expr__var_index(S, S->vars[i]);
    if (f >= 0 && (size_t)f != i)
      out[i] = out[f];
  }
}

int dm_expr__oom_err(dm_err *err, const char *who)
{
  return dm_err_set(err, DM_ENOMEM, "%s: out of memory", who);
}

static int grad_impl(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                 dm_expr *grad, dm_err *err)
{
  int s = dm_expr__check_vars(ctx, e, n, vars, "grad", err);
  if (s != DM_OK)
    return s;
  swp S;
  rows r = { 0 };
  if (dm_expr__swp_init(ctx, &S, n, vars) != 0)
    s = dm_expr__oom_err(err, "grad");
  else if (dm_expr__sweep(ctx, &S, e, &r) != 0)
    s = dm_expr__status(ctx, err);
  else
    densify(&S, &r, 0, grad);
  dm_expr__swp_free(&S);
  dm_expr__rows_free(&r);
  if (s == DM_OK)
    s = memoise(ctx, e, n, vars, grad, err);
  return s;
}

/* {==================================================================
 * sparse results
 * =================================================================== */

void dm_expr_sparse_free(dm_expr_sparse *s)
{
  if (s == NULL)
    return;
  free(s->rowptr);
  free(s->col);
  free(s->val);
  memset(s, 0, sizeof *s);
}

size_t *dm_expr__rows_start(dm_expr_ctx *ctx, swp *S, size_t n, const dm_expr *vars,
                            size_t nrow)
{
  size_t *off = malloc((nrow + 1) * sizeof *off);
  if (off == NULL || dm_expr__swp_init(ctx, S, n, vars) != 0) {
    free(off);
    if (off != NULL)
      dm_expr__swp_free(S);
    return NULL;
  }
  return off;
}

/* Rows r (nrow of them, row i from off[i]) as a dm_expr_sparse (takes
 * the arrays of r). */
int dm_expr__to_sparse(rows *r, const size_t *off, size_t nrow, size_t ncol,
                       dm_expr_sparse *out)
{
  memset(out, 0, sizeof *out);
  out->rowptr = malloc((nrow + 1) * sizeof *out->rowptr);
  if (out->rowptr == NULL)
    return -1;
  memcpy(out->rowptr, off, (nrow + 1) * sizeof *off);
  out->nrow = nrow;
  out->ncol = ncol;
  out->nnz = r->n;
  out->col = r->idx;
  out->val = r->val;
  if (out->col == NULL) {               /* no entries at all */
    out->col = malloc(sizeof *out->col);
    out->val = malloc(sizeof *out->val);
    free(r->idx);
    free(r->val);
    if (out->col == NULL || out->val == NULL) {
      dm_expr_sparse_free(out);
      return -1;
    }
  }
  r->idx = NULL;
  r->val = NULL;
  r->n = r->cap = 0;
  return 0;
}

static int jacobian_sparse_impl(dm_expr_ctx *ctx, size_t m, const dm_expr *f,
                            size_t n, const dm_expr *vars, dm_expr_sparse *J,
                            dm_err *err)
{
  memset(J, 0, sizeof *J);
  for (size_t i = 0; i < m; i++) {
    int s = dm_expr__check_vars(ctx, f[i], i == 0 ? n : 0, vars, "jacobian", err);
    if (s != DM_OK)
      return s;
  }
  swp S;
  rows r = { 0 };
  size_t *off = dm_expr__rows_start(ctx, &S, n, vars, m);
  int s = DM_OK;
  if (off == NULL)
    return dm_expr__oom_err(err, "jacobian");
  for (size_t i = 0; s == DM_OK && i < m; i++) {
    off[i] = r.n;
    if (dm_expr__sweep(ctx, &S, f[i], &r) != 0)
      s = dm_expr__status(ctx, err);
  }
  off[m] = r.n;
  if (s == DM_OK && dm_expr__to_sparse(&r, off, m, n, J) != 0)
    s = dm_expr__oom_err(err, "jacobian");
  dm_expr__swp_free(&S);
  dm_expr__rows_free(&r);
  free(off);
  return s;
}

/* {==================================================================
 * the public entry points: a failure is also left in the context's error
 * when the caller passed no dm_err (as the node constructors report), so
 * that a caller reading the context learns why ("out of memory", not an
 * empty message)
 * =================================================================== */

int dm_expr__keep(dm_expr_ctx *ctx, int s, const dm_err *local)
{
  if (s != DM_OK && ctx->err.status == DM_OK && local->status != DM_OK)
    ctx->err = *local;
  return s;
}

int dm_expr_grad(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                 dm_expr *grad, dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return grad_impl(ctx, e, n, vars, grad, err);
  dm_err_clear(&local);
  return dm_expr__keep(ctx, grad_impl(ctx, e, n, vars, grad, &local), &local);
}

int dm_expr_jacobian_sparse(dm_expr_ctx *ctx, size_t m, const dm_expr *f,
                            size_t n, const dm_expr *vars, dm_expr_sparse *J,
                            dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return jacobian_sparse_impl(ctx, m, f, n, vars, J, err);
  dm_err_clear(&local);
  return dm_expr__keep(ctx, jacobian_sparse_impl(ctx, m, f, n, vars, J, &local), &local);
}
