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

/* adj[c] += w */
static int acc(dm_expr_ctx *ctx, dm_expr c, dm_expr w, dm_expr zero)
{
  if (w == DM_EXPR_NONE)
    return -1;
  int32_t *A = ctx->aux;
  if (w == zero || A[c] == -2)            /* -2: independent of the vars */
    return 0;
  A[c] = A[c] == -1 ? w : dm_expr_add(ctx, A[c], w);
  return A[c] == DM_EXPR_NONE ? -1 : 0;
}

#define MUL(a, b) dm_expr_mul(ctx, (a), (b))
#define DIV(a, b) dm_expr_div(ctx, (a), (b))
#define ADD(a, b) dm_expr_add(ctx, (a), (b))
#define SUB(a, b) dm_expr_sub(ctx, (a), (b))
#define NEG(a) dm_expr_neg(ctx, (a))
#define UN(op, a) dm_expr_unary(ctx, (op), (a))
#define K(x) dm_expr_const(ctx, (x))

/* Pass the adjoint w of node x on to its operands. */
static int backprop(dm_expr_ctx *ctx, dm_expr x, dm_expr w, dm_expr zero,
                    dm_expr one)
{
  const dm_node nd = ctx->node[x];
  dm_expr a = nd.a, b = nd.b, t;
  switch (nd.op) {
  case DM_EXPR_ADD:
    return acc(ctx, a, w, zero) | acc(ctx, b, w, zero);
  case DM_EXPR_SUB:
    return acc(ctx, a, w, zero) | acc(ctx, b, NEG(w), zero);
  case DM_EXPR_MUL:
    return acc(ctx, a, MUL(w, b), zero) | acc(ctx, b, MUL(w, a), zero);
  case DM_EXPR_DIV:                       /* d(a/b)/db = -(a/b)/b */
    if (acc(ctx, a, DIV(w, b), zero) != 0)
      return -1;
    if (!(ctx->node[b].flags & (DM_NF_SYM | DM_NF_PARAM)))
      return 0;
    t = DIV(x, b);
    return acc(ctx, b, NEG(MUL(w, t)), zero);
  case DM_EXPR_POWI:
    t = dm_expr_powi(ctx, a, nd.b - 1);
    return acc(ctx, a, MUL(w, MUL(K(nd.b), t)), zero);
  case DM_EXPR_POW:
    if (ctx->node[a].flags & (DM_NF_SYM | DM_NF_PARAM)) {
      t = dm_expr_pow(ctx, a, SUB(b, one));
      if (acc(ctx, a, MUL(w, MUL(b, t)), zero) != 0)
        return -1;
    }
    if (ctx->node[b].flags & (DM_NF_SYM | DM_NF_PARAM)) {
      t = UN(DM_EXPR_LOG, a);
      return acc(ctx, b, MUL(w, MUL(x, t)), zero);
    }
    return 0;
  case DM_EXPR_ATAN2: {                   /* atan2(a, b): angle of (b, a) */
    dm_expr a2 = dm_expr_powi(ctx, a, 2);
    dm_expr den = ADD(a2, dm_expr_powi(ctx, b, 2));
    t = DIV(b, den);
    if (acc(ctx, a, MUL(w, t), zero) != 0)
      return -1;
    t = DIV(a, den);
    return acc(ctx, b, NEG(MUL(w, t)), zero);
  }
  case DM_EXPR_NEG:
    return acc(ctx, a, NEG(w), zero);
  case DM_EXPR_SQRT:
    return acc(ctx, a, DIV(MUL(K(0.5), w), x), zero);
  case DM_EXPR_EXP:
    return acc(ctx, a, MUL(w, x), zero);
  case DM_EXPR_LOG:
    return acc(ctx, a, DIV(w, a), zero);
  case DM_EXPR_SIN:
    return acc(ctx, a, MUL(w, UN(DM_EXPR_COS, a)), zero);
  case DM_EXPR_COS:
    return acc(ctx, a, NEG(MUL(w, UN(DM_EXPR_SIN, a))), zero);
  case DM_EXPR_TAN:
    t = dm_expr_powi(ctx, x, 2);
    return acc(ctx, a, MUL(w, ADD(one, t)), zero);
  case DM_EXPR_ASIN:
  case DM_EXPR_ACOS:
    t = dm_expr_powi(ctx, a, 2);
    t = DIV(w, UN(DM_EXPR_SQRT, SUB(one, t)));
    return acc(ctx, a, nd.op == DM_EXPR_ASIN ? t : NEG(t), zero);
  case DM_EXPR_ATAN:
    t = dm_expr_powi(ctx, a, 2);
    return acc(ctx, a, DIV(w, ADD(one, t)), zero);
  case DM_EXPR_SINH:
    return acc(ctx, a, MUL(w, UN(DM_EXPR_COSH, a)), zero);
  case DM_EXPR_COSH:
    return acc(ctx, a, MUL(w, UN(DM_EXPR_SINH, a)), zero);
  case DM_EXPR_TANH:
    t = dm_expr_powi(ctx, x, 2);
    return acc(ctx, a, MUL(w, SUB(one, t)), zero);
  case DM_EXPR_ABS:
    return acc(ctx, a, MUL(w, UN(DM_EXPR_SIGN, a)), zero);
  case DM_EXPR_SELECT:
    t = dm_expr_select(ctx, a, w, zero);
    if (acc(ctx, b, t, zero) != 0)
      return -1;
    return acc(ctx, nd.c, dm_expr_select(ctx, a, zero, w), zero);
  default:                                /* leaves, sign, comparisons */
    return 0;
  }
}

/* {==================================================================
 * sweeps
 * =================================================================== */

/* Nodes whose full gradients are known (sorted handles, gradients n each):
 * a sweep does not descend below them but applies the chain rule. */
typedef struct known {
  size_t nk, n;
  const int32_t *node;
  const dm_expr *grad;      /* nk * n */
  dm_expr root;
} known;

static long known_find(const known *k, dm_expr x)
{
  size_t lo = 0, hi = k ? k->nk : 0;
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    if (k->node[mid] < x)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (k && lo < k->nk && k->node[lo] == x) ? (long)lo : -1;
}

static int sweep_stop(const dm_expr_ctx *ctx, dm_expr x, const void *data)
{
  const known *k = data;
  if ((ctx->node[x].flags & (DM_NF_SYM | DM_NF_PARAM)) == 0)
    return 1;
  return x != k->root && known_find(k, x) >= 0;
}

/* out[j] = d root / d vars[j] by accumulating adjoints from root down,
 * applying out = w * grad(y) at the known nodes y. */
static int sweep(dm_expr_ctx *ctx, dm_expr root, size_t n, const dm_expr *vars,
                 known *k, dm_expr *out, dm_err *err)
{
  dm_expr zero = dm_expr_const(ctx, 0.0), one = dm_expr_const(ctx, 1.0);
  if (zero == DM_EXPR_NONE || one == DM_EXPR_NONE)
    return dm_expr__status(ctx, err);
  known none = { 0, n, NULL, NULL, root };
  if (k == NULL)
    k = &none;
  k->root = root;
  /* the variables are collected too: known nodes may lead to variables
   * that no traversed path reaches */
  dm_expr *roots = malloc((n + 1) * sizeof *roots);
  if (roots == NULL)
    return dm_err_set(err, DM_ENOMEM, "grad: out of memory");
  roots[0] = root;
  memcpy(roots + 1, vars, n * sizeof *roots);
  long nl = dm_expr__collect_stop(ctx, n + 1, roots, sweep_stop, k);
  free(roots);
  if (nl < 0)
    return dm_err_set(err, DM_ENOMEM, "grad: out of memory");
  /* aux: -2 independent of the vars, -1 dependent (no adjoint yet), else
   * the adjoint accumulated so far */
  int32_t *A = ctx->aux;
  for (long i = 0; i < nl; i++)
    A[ctx->list[i]] = -2;
  for (size_t i = 0; i < n; i++)
    A[vars[i]] = -1;                      /* all collected */
  for (long i = 0; i < nl; i++) {         /* children before parents */
    dm_expr x = ctx->list[i];
    const dm_node *nd = &ctx->node[x];
    int ar = dm_expr__arity(nd->op);
    if (A[x] != -2 || !(nd->flags & (DM_NF_SYM | DM_NF_PARAM)))
      continue;
    if (x != root && known_find(k, x) >= 0)
      A[x] = -1;
    else if ((ar >= 1 && A[nd->a] == -1) || (ar >= 2 && A[nd->b] == -1) ||
             (ar >= 3 && A[nd->c] == -1))
      A[x] = -1;
  }
  if (A[root] == -1)
    A[root] = one;
  for (long i = nl - 1; i >= 0; i--) {    /* parents before children */
    dm_expr x = ctx->list[i], w = ctx->aux[x];
    long ki;
    if (w < 0)
      continue;
    if (x != root && (ki = known_find(k, x)) >= 0) {
      for (size_t j = 0; j < n; j++) {
        dm_expr gj = k->grad[(size_t)ki * n + j];
        if (gj != zero && acc(ctx, vars[j], MUL(w, gj), zero) != 0)
          return dm_expr__status(ctx, err);
      }
      continue;
    }
    if (backprop(ctx, x, w, zero, one) != 0)
      return dm_expr__status(ctx, err);
  }
  for (size_t i = 0; i < n; i++) {
    dm_expr v = vars[i];
    out[i] = A[v] >= 0 ? A[v] : zero;
  }
  return DM_OK;
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

int dm_expr_grad(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                 dm_expr *grad, dm_err *err)
{
  int s = check_vars(ctx, e, n, vars, "grad", err);
  if (s == DM_OK)
    s = sweep(ctx, e, n, vars, NULL, grad, err);
  if (s == DM_OK)
    s = memoise(ctx, e, n, vars, grad, err);
  return s;
}

/* {==================================================================
 * Hessians: reverse over reverse with preaccumulation
 * =================================================================== */

/* The rows are gradients of the gradient entries g_i.  Sweeping each g_i
 * separately would repeat the chain rule through the subexpressions the
 * rows share; instead every node that no single node dominates (in the DAG
 * of all g_i under a virtual root) gets its full gradient once, children
 * first, and sweeps stop there.  For L(|q|^2) that is L''(u) * 2q_j, built
 * once; forward differentiation would rebuild the chain per variable. */

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
  long np = -1;
  if (U && idom && depth && P) {
    memcpy(U, ctx->list, sz * sizeof *U);
    for (long i = 0; i < nu; i++)
      idom[i] = -2;                      /* not reached yet */
    for (size_t i = 0; i < n; i++) {
      long p = pos_of(U, nu, g[i]);
      if (p >= 0)
        idom[p] = VROOT;
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
      int root = 0;
      for (size_t i = 0; i < n; i++)
        root |= g[i] == U[p];
      if (dm_expr__arity(nd->op) > 0 && (nd->flags & (DM_NF_SYM | DM_NF_PARAM))
          && idom[p] == VROOT && (root || size[p] >= T))
        P[np++] = U[p];
    }
  }
  free(U);
  free(idom);
  free(depth);
  if (np < 0)
    free(P);
  else
    *pnodes = P;
  return np;
}

/* Operations (non-leaf nodes) needed for e, g[n] and the upper triangle
 * of H together: the size of the tape they would compile to. */
static long cost(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *g,
                 const dm_expr *H)
{
  size_t m = 1 + n + n * (n + 1) / 2, k = 0;
  dm_expr *roots = malloc(m * sizeof *roots);
  if (roots == NULL)
    return -1;
  roots[k++] = e;
  for (size_t i = 0; i < n; i++)
    roots[k++] = g[i];
  for (size_t i = 0; i < n; i++)
    for (size_t j = i; j < n; j++)
      roots[k++] = H[i * n + j];
  long nl = dm_expr__collect(ctx, m, roots), ops = 0;
  for (long i = 0; i < nl; i++)
    ops += dm_expr__arity(ctx->node[ctx->list[i]].op) > 0;
  free(roots);
  return nl < 0 ? -1 : ops;
}

/* Rows by sweeps that stop at preaccumulated nodes (see above). */
static int hessian_preacc(dm_expr_ctx *ctx, size_t n, const dm_expr *vars,
                          const dm_expr *g, dm_expr *H, dm_err *err)
{
  dm_expr *G = NULL, *row = malloc(n * sizeof *row);
  int32_t *P = NULL;
  long np = row ? pick_nodes(ctx, n, g, &P) : -1;
  if (np < 0 || !(G = malloc(((size_t)np + 1) * n * sizeof *G))) {
    free(P);
    free(row);
    return dm_err_set(err, DM_ENOMEM, "hessian: out of memory");
  }
  known k = { 0, n, P, G, DM_EXPR_NONE };
  int s = DM_OK;
  for (long i = 0; s == DM_OK && i < np; i++) {
    k.nk = (size_t)i;                    /* the ones below are known */
    s = sweep(ctx, P[i], n, vars, &k, G + (size_t)i * n, err);
  }
  k.nk = (size_t)np;
  for (size_t i = 0; s == DM_OK && i < n; i++) {
    long ki = known_find(&k, g[i]);
    if (ki >= 0)
      memcpy(row, G + (size_t)ki * n, n * sizeof *row);
    else
      s = sweep(ctx, g[i], n, vars, &k, row, err);
    for (size_t j = i; s == DM_OK && j < n; j++)
      H[i * n + j] = H[j * n + i] = row[j];
  }
  free(G);
  free(P);
  free(row);
  return s;
}

/* Rows by forward differentiation of the gradient entries (memoised per
 * variable, shared between rows). */
static int hessian_forward(dm_expr_ctx *ctx, size_t n, const dm_expr *vars,
                           const dm_expr *g, dm_expr *H, dm_err *err)
{
  for (size_t i = 0; i < n; i++)
    for (size_t j = i; j < n; j++) {
      dm_expr h = dm_expr_diff(ctx, g[i], vars[j]);
      if (h == DM_EXPR_NONE)
        return dm_expr__status(ctx, err);
      H[i * n + j] = H[j * n + i] = h;
    }
  return DM_OK;
}

int dm_expr_hessian(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                    dm_expr *H, dm_err *err)
{
  int s = check_vars(ctx, e, n, vars, "hessian", err);
  if (s != DM_OK || n == 0)
    return s;
  /* Neither way wins everywhere (preaccumulation for radial potentials,
   * forward for trigonometric kinematics): build both, keep the smaller. */
  dm_expr *g = malloc(n * sizeof *g), *H2 = malloc(n * n * sizeof *H2);
  if (g == NULL || H2 == NULL) {
    free(g);
    free(H2);
    return dm_err_set(err, DM_ENOMEM, "hessian: out of memory");
  }
  s = dm_expr_grad(ctx, e, n, vars, g, err);
  if (s == DM_OK)
    s = hessian_preacc(ctx, n, vars, g, H, err);
  if (s == DM_OK)
    s = hessian_forward(ctx, n, vars, g, H2, err);
  if (s == DM_OK) {
    long c1 = cost(ctx, e, n, g, H), c2 = cost(ctx, e, n, g, H2);
    if (c1 < 0 || c2 < 0)
      s = dm_err_set(err, DM_ENOMEM, "hessian: out of memory");
    else if (c2 < c1)
      memcpy(H, H2, n * n * sizeof *H);
  }
  free(g);
  free(H2);
  return s;
}
