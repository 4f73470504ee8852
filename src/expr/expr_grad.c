/* expr_grad.c -- gradients by reverse accumulation (adjoints) on the DAG.
 *
 * Forward differentiation repeats the chain rule through shared
 * subexpressions once per variable; accumulating adjoints from the root
 * down visits each node once and expresses every partial derivative
 * through the adjoints of shared subexpressions (for L(|q|^2) the gradient
 * becomes 2 q_i L'(u) with L'(u) built once), which is what makes gradients
 * and Hessians (forward over reverse, expr_diff.c) compact. */
#include <config.h>
#include "expr/expr_impl.h"

#include <stdlib.h>
#include <string.h>

typedef struct swp swp;
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

/* Sparse rows of derivatives: (variable index, expression) entries,
 * ascending by index within a row, rows one after the other. */
typedef struct rows {
  size_t n, cap;
  uint32_t *idx;
  dm_expr *val;
} rows;

static int rows_push(rows *r, uint32_t j, dm_expr x)
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

static void rows_free(rows *r)
{
  free(r->idx);
  free(r->val);
  memset(r, 0, sizeof *r);
}

/* One entry of a row being gathered. */
typedef struct ent {
  uint32_t j;
  dm_expr x;
} ent;

static int cmp_ent(const void *a, const void *b)
{
  uint32_t x = ((const ent *)a)->j, y = ((const ent *)b)->j;
  return (x > y) - (x < y);
}

/* What the sweeps of one derivative computation share: the variables (a
 * hash table from node to index), and the nodes whose gradients are
 * already known (sorted handles, a sparse row each): a sweep does not
 * descend below them but applies the chain rule with their rows. */
/* Contributions to an adjoint waiting to be summed, in arrival order:
 * chain h holds entries first .. last (linked by next), count of them. */
typedef struct contrib {
  dm_expr w;
  int32_t next;
} contrib;
typedef struct chain {
  int32_t first, last, count;
} chain;

struct swp {
  size_t n;
  const dm_expr *vars;
  int32_t *vtab;            /* open addressing: variable indices, -1 empty */
  size_t vmask;
  size_t nk;                /* the first nk known nodes are in force */
  const int32_t *knode;
  const size_t *koff;       /* row k: kr->idx/val[koff[k] .. koff[k + 1]) */
  const rows *kr;
  dm_expr root, zero, one;
  uint32_t *touch;          /* n: variables reached through known rows */
  ent *tmp;                 /* n: the row being gathered */
  contrib *cb;              /* pending contributions of this sweep */
  size_t ncb, capcb;
  chain *ch;
  size_t nch, capch;
  dm_expr *terms;           /* a chain's terms being summed */
  size_t capterms;
};

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
static long var_index(const swp *S, int32_t x)
{
  for (size_t j = vslot(x, S->vmask); S->vtab[j] >= 0; j = (j + 1) & S->vmask)
    if (S->vars[S->vtab[j]] == x)
      return S->vtab[j];
  return -1;
}

/* The variable table (the first index of a variable listed twice) and the
 * buffers; vars must be symbols or parameters (checked by the caller). */
static int swp_init(dm_expr_ctx *ctx, swp *S, size_t n, const dm_expr *vars)
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
    if (var_index(S, vars[i]) >= 0)
      continue;
    size_t j = vslot(vars[i], S->vmask);
    while (S->vtab[j] >= 0)
      j = (j + 1) & S->vmask;
    S->vtab[j] = (int32_t)i;
  }
  return 0;
}

static void swp_free(swp *S)
{
  free(S->vtab);
  free(S->touch);
  free(S->tmp);
  free(S->cb);
  free(S->ch);
  free(S->terms);
}

static long known_find(const swp *S, dm_expr x)
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
  return x != S->root && known_find(S, x) >= 0;
}

static int is_leafvar(const dm_expr_ctx *ctx, const swp *S, int32_t x, long *j)
{
  int op = ctx->node[x].op;
  if (op != DM_EXPR_SYM && op != DM_EXPR_PARAM)
    return 0;
  return (*j = var_index(S, x)) >= 0;
}

/* The nonzero derivatives of root in the variables, by accumulating
 * adjoints from root down (applying w * row(y) at known nodes y), appended
 * to out as one row (ascending variable index).  The cost is the size of
 * the part of root's DAG above the known nodes plus the known rows it
 * meets, whatever the number of variables.  Returns 0, or -1 (the
 * context's error is set). */
static int sweep(dm_expr_ctx *ctx, swp *S, dm_expr root, rows *out)
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
    if (is_leafvar(ctx, S, x, &j) || (x != root && known_find(S, x) >= 0))
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
    if (x != root && (ki = known_find(S, x)) >= 0) {
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
    if (is_leafvar(ctx, S, list[i], &j) && A[list[i]] >= 0 && A[list[i]] != zero)
      S->tmp[ne++] = (ent){ (uint32_t)j, A[list[i]] };
  for (size_t t = 0; t < nt; t++) {
    dm_expr v = S->vars[S->touch[t]], w;
    if (adjoint(ctx, S, v, &w) != 0)
      return -1;
    if (w >= 0 && w != zero)
      S->tmp[ne++] = (ent){ S->touch[t], w };
  }
  qsort(S->tmp, ne, sizeof *S->tmp, cmp_ent);
  for (size_t k = 0; k < ne; k++)
    if (rows_push(out, S->tmp[k].j, S->tmp[k].x) != 0) {
      dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
      return -1;
    }
  return 0;
}

static int check_vars(dm_expr_ctx *ctx, dm_expr e, size_t n,
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
    long f = var_index(S, S->vars[i]);
    if (f >= 0 && (size_t)f != i)
      out[i] = out[f];
  }
}

static int oom_err(dm_err *err, const char *who)
{
  return dm_err_set(err, DM_ENOMEM, "%s: out of memory", who);
}

static int grad_impl(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                 dm_expr *grad, dm_err *err)
{
  int s = check_vars(ctx, e, n, vars, "grad", err);
  if (s != DM_OK)
    return s;
  swp S;
  rows r = { 0 };
  if (swp_init(ctx, &S, n, vars) != 0)
    s = oom_err(err, "grad");
  else if (sweep(ctx, &S, e, &r) != 0)
    s = dm_expr__status(ctx, err);
  else
    densify(&S, &r, 0, grad);
  swp_free(&S);
  rows_free(&r);
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

/* Rows r (nrow of them, row i from off[i]) as a dm_expr_sparse (takes
 * the arrays of r). */
static int to_sparse(rows *r, const size_t *off, size_t nrow, size_t ncol,
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
    int s = check_vars(ctx, f[i], i == 0 ? n : 0, vars, "jacobian", err);
    if (s != DM_OK)
      return s;
  }
  swp S;
  rows r = { 0 };
  size_t *off = malloc((m + 1) * sizeof *off);
  int s = DM_OK;
  if (off == NULL || swp_init(ctx, &S, n, vars) != 0) {
    free(off);
    if (off != NULL)
      swp_free(&S);
    return oom_err(err, "jacobian");
  }
  for (size_t i = 0; s == DM_OK && i < m; i++) {
    off[i] = r.n;
    if (sweep(ctx, &S, f[i], &r) != 0)
      s = dm_expr__status(ctx, err);
  }
  off[m] = r.n;
  if (s == DM_OK && to_sparse(&r, off, m, n, J) != 0)
    s = oom_err(err, "jacobian");
  swp_free(&S);
  rows_free(&r);
  free(off);
  return s;
}

/* {==================================================================
 * Hessians: reverse over reverse with preaccumulation
 * =================================================================== */

/* The rows are gradients of the gradient entries g_i.  Sweeping each g_i
 * separately would repeat the chain rule through the subexpressions the
 * rows share; instead every node that no single node dominates (in the DAG
 * of all g_i under a virtual root) gets its gradient once, children first,
 * and sweeps stop there.  For L(|q|^2) that is L''(u) * 2q_j, built once;
 * forward differentiation would rebuild the chain per variable.  Gradients
 * are sparse rows, so the cost is the size of the DAG of the g_i plus the
 * rows applied, never a multiple of the number of variables. */

static long pos_of(const int32_t *U, long nu, int32_t x)
{
  long lo = 0, hi = nu;
  while (lo < hi) {
    long mid = (lo + hi) / 2;
    if (U[mid] < x)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (lo < nu && U[lo] == x) ? lo : -1;
}

#define VROOT (-1)

static long lca(const long *idom, const long *depth, long a, long b)
{
  while (a != b) {
    if (a == VROOT || b == VROOT)
      return VROOT;
    if (depth[a] >= depth[b])
      a = idom[a];
    else
      b = idom[b];
  }
  return a;
}

/* The nodes (sorted) to preaccumulate, into *pnodes (malloc'ed). */
static long pick_nodes(dm_expr_ctx *ctx, size_t n, const dm_expr *g,
                       int32_t **pnodes)
{
  long nu = dm_expr__collect_vars(ctx, n, g);
  if (nu < 0)
    return -1;
  size_t sz = (size_t)(nu ? nu : 1);
  int32_t *U = malloc(sz * sizeof *U);
  long *idom = malloc(sz * sizeof *idom), *depth = malloc(sz * sizeof *depth);
  int32_t *P = malloc(sz * sizeof *P);
  uint8_t *isroot = calloc(sz, 1);
  long np = -1;
  if (U && idom && depth && P && isroot) {
    memcpy(U, ctx->list, sz * sizeof *U);
    for (long i = 0; i < nu; i++)
      idom[i] = -2;                      /* not reached yet */
    for (size_t i = 0; i < n; i++) {
      long p = pos_of(U, nu, g[i]);
      if (p >= 0) {
        idom[p] = VROOT;
        isroot[p] = 1;
      }
    }
    np = 0;
    for (long p = nu - 1; p >= 0; p--) { /* parents before children */
      const dm_node nd = ctx->node[U[p]];
      depth[p] = idom[p] < 0 ? 1 : depth[idom[p]] + 1;
      int ar = dm_expr__arity(nd.op);
      if (!(nd.flags & (DM_NF_SYM | DM_NF_PARAM)))
        continue;
      int32_t ch[3] = { nd.a, nd.b, nd.c };
      for (int j = 0; j < ar; j++) {
        long c = pos_of(U, nu, ch[j]);
        if (c >= 0)
          idom[c] = idom[c] == -2 ? p : lca(idom, depth, idom[c], p);
      }
    }
    /* sizes of the dominator subtrees (children have lower positions) */
    long *size = depth;                  /* depths are no longer needed */
    for (long p = 0; p < nu; p++)
      size[p] = 1;
    for (long p = 0; p < nu; p++)
      if (idom[p] >= 0)
        size[idom[p]] += size[p];
    const long T = 4;       /* dominated subtree size worth a gradient */
    for (long p = 0; p < nu; p++) {      /* ascending */
      const dm_node *nd = &ctx->node[U[p]];
      if (dm_expr__arity(nd->op) > 0 && (nd->flags & (DM_NF_SYM | DM_NF_PARAM))
          && idom[p] == VROOT && (isroot[p] || size[p] >= T))
        P[np++] = U[p];
    }
  }
  free(U);
  free(idom);
  free(depth);
  free(isroot);
  if (np < 0)
    free(P);
  else
    *pnodes = P;
  return np;
}

/* Operations (non-leaf nodes) needed for e, g[n] and the entries of H
 * together: the size of the tape they would compile to. */
static long cost(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *g,
                 const rows *H)
{
  size_t m = 1 + n + H->n, k = 0;
  dm_expr *roots = malloc(m * sizeof *roots);
  if (roots == NULL)
    return -1;
  roots[k++] = e;
  for (size_t i = 0; i < n; i++)
    roots[k++] = g[i];
  for (size_t i = 0; i < H->n; i++)
    roots[k++] = H->val[i];
  long nl = dm_expr__collect(ctx, m, roots), ops = 0;
  for (long i = 0; i < nl; i++)
    ops += dm_expr__arity(ctx->node[ctx->list[i]].op) > 0;
  free(roots);
  return nl < 0 ? -1 : ops;
}

/* Upper-triangle rows (j >= i) by sweeps that stop at preaccumulated
 * nodes (see above); off[i] is where row i starts in H. */
static int hessian_preacc(dm_expr_ctx *ctx, swp *S, const dm_expr *g,
                          rows *H, size_t *off)
{
  const size_t n = S->n;
  int32_t *P = NULL;
  size_t *koff = NULL;
  rows kr = { 0 }, row = { 0 };
  long np = pick_nodes(ctx, n, g, &P);
  int s = -1;
  if (np < 0 || (koff = malloc(((size_t)np + 1) * sizeof *koff)) == NULL) {
    dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
    goto done;
  }
  S->knode = P;
  S->koff = koff;
  S->kr = &kr;
  koff[0] = 0;
  for (long i = 0; i < np; i++) {
    S->nk = (size_t)i;                   /* the ones below are known */
    if (sweep(ctx, S, P[i], &kr) != 0)
      goto done;
    koff[i + 1] = kr.n;
  }
  S->nk = (size_t)np;
  for (size_t i = 0; i < n; i++) {
    off[i] = H->n;
    long ki = known_find(S, g[i]);
    size_t from = 0, to;
    const rows *src = &row;
    if (ki >= 0) {
      src = &kr;
      from = koff[ki];
      to = koff[ki + 1];
    } else {
      row.n = 0;
      if (sweep(ctx, S, g[i], &row) != 0)
        goto done;
      to = row.n;
    }
    for (size_t k = from; k < to; k++)
      if (src->idx[k] >= i && rows_push(H, src->idx[k], src->val[k]) != 0) {
        dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
        goto done;
      }
  }
  off[n] = H->n;
  s = 0;
done:
  S->nk = 0;
  S->kr = NULL;
  free(P);
  free(koff);
  rows_free(&kr);
  rows_free(&row);
  return s;
}

/* Upper-triangle rows by forward differentiation of the gradient entries
 * (memoised per variable, shared between rows), on the variables each
 * g_i depends on; 1 without building anything when that would visit more
 * than `budget` nodes (forward differentiation costs the size of g_i's
 * DAG per variable: quadratic for dense rows). */
static int hessian_forward(dm_expr_ctx *ctx, swp *S, const dm_expr *g,
                           long budget, rows *H, size_t *off)
{
  const size_t n = S->n;
  rows dep = { 0 };
  size_t *doff = malloc((n + 1) * sizeof *doff);
  long est = 0, j;
  int s = -1;
  if (doff == NULL)
    goto oom;
  for (size_t i = 0; i < n; i++) {
    doff[i] = dep.n;
    long nl = dm_expr__collect_vars(ctx, 1, &g[i]);
    if (nl < 0)
      goto oom;
    size_t nd = 0;
    for (long k = 0; k < nl; k++)
      if (is_leafvar(ctx, S, ctx->list[k], &j) && (size_t)j >= i) {
        S->tmp[nd++] = (ent){ (uint32_t)j, ctx->list[k] };
      }
    est += (long)nd * nl;
    if (est > budget) {
      s = 1;
      goto done;
    }
    qsort(S->tmp, nd, sizeof *S->tmp, cmp_ent);
    for (size_t k = 0; k < nd; k++)
      if (rows_push(&dep, S->tmp[k].j, S->tmp[k].x) != 0)
        goto oom;
  }
  doff[n] = dep.n;
  for (size_t i = 0; i < n; i++) {
    off[i] = H->n;
    for (size_t k = doff[i]; k < doff[i + 1]; k++) {
      dm_expr h = dm_expr_diff(ctx, g[i], S->vars[dep.idx[k]]);
      if (h == DM_EXPR_NONE)
        goto done;
      if (h != S->zero && rows_push(H, dep.idx[k], h) != 0)
        goto oom;
    }
  }
  off[n] = H->n;
  s = 0;
  goto done;
oom:
  dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
done:
  free(doff);
  rows_free(&dep);
  return s;
}

/* The upper triangle of the Hessian on its pattern (rows H, row i from
 * off[i]), n >= 1: both ways are built when forward differentiation is
 * affordable, and the one with fewer operations is kept.  Neither wins
 * everywhere (preaccumulation for radial potentials, forward for
 * trigonometric kinematics). */
static int hessian_rows(dm_expr_ctx *ctx, swp *S, dm_expr e, rows *H,
                        size_t *off, dm_err *err)
{
  const size_t n = S->n;
  dm_expr *g = malloc(n * sizeof *g);
  size_t *off2 = malloc((n + 1) * sizeof *off2);
  rows H2 = { 0 };
  int s;
  if (g == NULL || off2 == NULL) {
    s = oom_err(err, "hessian");
    goto done;
  }
  if ((s = dm_expr_grad(ctx, e, n, S->vars, g, err)) != DM_OK)
    goto done;
  if (hessian_preacc(ctx, S, g, H, off) != 0) {
    s = dm_expr__status(ctx, err);
    goto done;
  }
  long c1 = cost(ctx, e, n, g, H);
  if (c1 < 0) {
    s = oom_err(err, "hessian");
    goto done;
  }
  int f = hessian_forward(ctx, S, g, 50000 + 4 * c1, &H2, off2);
  if (f < 0) {
    s = dm_expr__status(ctx, err);
    goto done;
  }
  if (f == 0) {
    long c2 = cost(ctx, e, n, g, &H2);
    if (c2 < 0) {
      s = oom_err(err, "hessian");
      goto done;
    }
    if (c2 < c1) {
      rows t = *H;
      *H = H2;
      H2 = t;
      memcpy(off, off2, (n + 1) * sizeof *off);
    }
  }
done:
  free(g);
  free(off2);
  rows_free(&H2);
  return s;
}

static int hessian_sparse_impl(dm_expr_ctx *ctx, dm_expr e, size_t n,
                           const dm_expr *vars, dm_expr_sparse *H, dm_err *err)
{
  memset(H, 0, sizeof *H);
  int s = check_vars(ctx, e, n, vars, "hessian", err);
  if (s != DM_OK)
    return s;
  swp S;
  rows r = { 0 };
  size_t *off = malloc((n + 1) * sizeof *off);
  if (off == NULL || swp_init(ctx, &S, n, vars) != 0) {
    free(off);
    if (off != NULL)
      swp_free(&S);
    return oom_err(err, "hessian");
  }
  for (size_t i = 0; i < n && s == DM_OK; i++)
    if (var_index(&S, vars[i]) != (long)i)
      s = dm_err_set(err, DM_EINVAL, "hessian: variable %zu is listed twice", i + 1);
  off[0] = 0;
  if (s == DM_OK && n > 0)
    s = hessian_rows(ctx, &S, e, &r, off, err);
  if (s == DM_OK && to_sparse(&r, off, n, n, H) != 0)
    s = oom_err(err, "hessian");
  swp_free(&S);
  rows_free(&r);
  free(off);
  return s;
}

static int hessian_impl(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                    dm_expr *H, dm_err *err)
{
  int s = check_vars(ctx, e, n, vars, "hessian", err);
  if (s != DM_OK || n == 0)
    return s;
  swp S;
  rows r = { 0 };
  size_t *off = malloc((n + 1) * sizeof *off);
  if (off == NULL || swp_init(ctx, &S, n, vars) != 0) {
    free(off);
    if (off != NULL)
      swp_free(&S);
    return oom_err(err, "hessian");
  }
  s = hessian_rows(ctx, &S, e, &r, off, err);
  if (s == DM_OK) {
    for (size_t k = 0; k < n * n; k++)
      H[k] = S.zero;
    for (size_t i = 0; i < n; i++)
      for (size_t k = off[i]; k < off[i + 1]; k++)
        H[i * n + r.idx[k]] = H[r.idx[k] * n + i] = r.val[k];
    /* a variable listed twice: its rows and columns are those of its
     * first listing */
    for (size_t i = 0; i < n; i++)
      for (size_t j = 0; j < n; j++) {
        long fi = var_index(&S, vars[i]), fj = var_index(&S, vars[j]);
        if (fi != (long)i || fj != (long)j)
          H[i * n + j] = H[(size_t)fi * n + (size_t)fj];
      }
  }
  swp_free(&S);
  rows_free(&r);
  free(off);
  return s;
}

/* {==================================================================
 * the public entry points: a failure is also left in the context's error
 * when the caller passed no dm_err (as the node constructors report), so
 * that a caller reading the context learns why ("out of memory", not an
 * empty message)
 * =================================================================== */

static int keep(dm_expr_ctx *ctx, int s, const dm_err *local)
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
  return keep(ctx, grad_impl(ctx, e, n, vars, grad, &local), &local);
}

int dm_expr_jacobian_sparse(dm_expr_ctx *ctx, size_t m, const dm_expr *f,
                            size_t n, const dm_expr *vars, dm_expr_sparse *J,
                            dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return jacobian_sparse_impl(ctx, m, f, n, vars, J, err);
  dm_err_clear(&local);
  return keep(ctx, jacobian_sparse_impl(ctx, m, f, n, vars, J, &local), &local);
}

int dm_expr_hessian_sparse(dm_expr_ctx *ctx, dm_expr e, size_t n,
                           const dm_expr *vars, dm_expr_sparse *H, dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return hessian_sparse_impl(ctx, e, n, vars, H, err);
  dm_err_clear(&local);
  return keep(ctx, hessian_sparse_impl(ctx, e, n, vars, H, &local), &local);
}

int dm_expr_hessian(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                    dm_expr *H, dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return hessian_impl(ctx, e, n, vars, H, err);
  dm_err_clear(&local);
  return keep(ctx, hessian_impl(ctx, e, n, vars, H, &local), &local);
}
