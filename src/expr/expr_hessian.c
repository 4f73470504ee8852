/* expr_hessian.c -- Hessians of expressions: reverse over reverse with
 * preaccumulation, or forward over reverse when that builds fewer
 * operations, on the reverse sweeps of expr_grad.c. */
#include <config.h>
#include "expr/sweep_impl.h"

#include <stdlib.h>
#include <string.h>

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
    if (dm_expr__sweep(ctx, S, P[i], &kr) != 0)
      goto done;
    koff[i + 1] = kr.n;
  }
  S->nk = (size_t)np;
  for (size_t i = 0; i < n; i++) {
    off[i] = H->n;
    long ki = dm_expr__known_find(S, g[i]);
    size_t from = 0, to;
    const rows *src = &row;
    if (ki >= 0) {
      src = &kr;
      from = koff[ki];
      to = koff[ki + 1];
    } else {
      row.n = 0;
      if (dm_expr__sweep(ctx, S, g[i], &row) != 0)
        goto done;
      to = row.n;
    }
    for (size_t k = from; k < to; k++)
      if (src->idx[k] >= i && dm_expr__rows_push(H, src->idx[k], src->val[k]) != 0) {
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
  dm_expr__rows_free(&kr);
  dm_expr__rows_free(&row);
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
      if (dm_expr__is_leafvar(ctx, S, ctx->list[k], &j) && (size_t)j >= i) {
        S->tmp[nd++] = (ent){ (uint32_t)j, ctx->list[k] };
      }
    est += (long)nd * nl;
    if (est > budget) {
      s = 1;
      goto done;
    }
    qsort(S->tmp, nd, sizeof *S->tmp, dm_expr__cmp_ent);
    for (size_t k = 0; k < nd; k++)
      if (dm_expr__rows_push(&dep, S->tmp[k].j, S->tmp[k].x) != 0)
        goto oom;
  }
  doff[n] = dep.n;
  for (size_t i = 0; i < n; i++) {
    off[i] = H->n;
    for (size_t k = doff[i]; k < doff[i + 1]; k++) {
      dm_expr h = dm_expr_diff(ctx, g[i], S->vars[dep.idx[k]]);
      if (h == DM_EXPR_NONE)
        goto done;
      if (h != S->zero && dm_expr__rows_push(H, dep.idx[k], h) != 0)
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
  dm_expr__rows_free(&dep);
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
    s = dm_expr__oom_err(err, "hessian");
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
    s = dm_expr__oom_err(err, "hessian");
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
      s = dm_expr__oom_err(err, "hessian");
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
  dm_expr__rows_free(&H2);
  return s;
}

static int hessian_sparse_impl(dm_expr_ctx *ctx, dm_expr e, size_t n,
                           const dm_expr *vars, dm_expr_sparse *H, dm_err *err)
{
  memset(H, 0, sizeof *H);
  int s = dm_expr__check_vars(ctx, e, n, vars, "hessian", err);
  if (s != DM_OK)
    return s;
  swp S;
  rows r = { 0 };
  size_t *off = dm_expr__rows_start(ctx, &S, n, vars, n);
  if (off == NULL)
    return dm_expr__oom_err(err, "hessian");
  for (size_t i = 0; i < n && s == DM_OK; i++)
    if (dm_expr__var_index(&S, vars[i]) != (long)i)
      s = dm_err_set(err, DM_EINVAL, "hessian: variable %zu is listed twice", i + 1);
  off[0] = 0;
  if (s == DM_OK && n > 0)
    s = hessian_rows(ctx, &S, e, &r, off, err);
  if (s == DM_OK && dm_expr__to_sparse(&r, off, n, n, H) != 0)
    s = dm_expr__oom_err(err, "hessian");
  dm_expr__swp_free(&S);
  dm_expr__rows_free(&r);
  free(off);
  return s;
}

static int hessian_impl(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                    dm_expr *H, dm_err *err)
{
  int s = dm_expr__check_vars(ctx, e, n, vars, "hessian", err);
  if (s != DM_OK || n == 0)
    return s;
  swp S;
  rows r = { 0 };
  size_t *off = dm_expr__rows_start(ctx, &S, n, vars, n);
  if (off == NULL)
    return dm_expr__oom_err(err, "hessian");
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
        long fi = dm_expr__var_index(&S, vars[i]), fj = dm_expr__var_index(&S, vars[j]);
        if (fi != (long)i || fj != (long)j)
          H[i * n + j] = H[(size_t)fi * n + (size_t)fj];
      }
  }
  dm_expr__swp_free(&S);
  dm_expr__rows_free(&r);
  free(off);
  return s;
}

/* {==================================================================
 * the public entry points (a failure also left in the context's error
 * when the caller passed no dm_err, as in expr_grad.c)
 * =================================================================== */

int dm_expr_hessian_sparse(dm_expr_ctx *ctx, dm_expr e, size_t n,
                           const dm_expr *vars, dm_expr_sparse *H, dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return hessian_sparse_impl(ctx, e, n, vars, H, err);
  dm_err_clear(&local);
  return dm_expr__keep(ctx, hessian_sparse_impl(ctx, e, n, vars, H, &local), &local);
}

int dm_expr_hessian(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
                    dm_expr *H, dm_err *err)
{
  dm_err local;
  if (err != NULL)
    return hessian_impl(ctx, e, n, vars, H, err);
  dm_err_clear(&local);
  return dm_expr__keep(ctx, hessian_impl(ctx, e, n, vars, H, &local), &local);
}
