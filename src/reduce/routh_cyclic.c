/* routh_cyclic.c -- is a coordinate cyclic when the formula does not show
 * it?  A Lagrangian written in Cartesian velocities of a rotating system
 * (e.g. the double spherical pendulum with x1 = r1 cos(theta), ...) does
 * not depend on theta, yet sin(theta) and cos(theta) appear and dL/dtheta
 * is a sum that cancels only through trigonometric identities, which the
 * simplifier does not apply.  Here the derivative is evaluated at
 * pseudo-random points together with its "magnitude" M (the same DAG
 * evaluated with |a| + |b| for sums and differences, |a| |b| for products,
 * |a| / |b| for quotients, the absolute value of every other node): an
 * expression that vanishes identically stays at round-off relative to M,
 * one that does not is O(M) at generic points. */
#include <config.h>
#include "reduce/routh_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Relative size below which a value counts as a cancelled sum: a sum of k
 * terms of size M has round-off ~ k eps M; a real dependence is O(M). */
#define ZERO_REL 1e-10
#define NSAMPLE 24
#define NFINITE_MIN 8

typedef struct dag {
  dm_expr *node;        /* reachable nodes in ascending order (topological) */
  int32_t *pos;         /* node id -> position in node[], -1 if absent */
  size_t len, cap;
  double *val, *mag;
} dag;

static void dag_free(dag *g)
{
  free(g->node);
  free(g->pos);
  free(g->val);
  free(g->mag);
}

/* The nodes reachable from e (ids below e, since operands are made before
 * the nodes using them). */
static int dag_build(const dm_expr_ctx *ctx, dm_expr e, dag *g)
{
  size_t n = (size_t)e + 1, top = 0, k;
  dm_expr *stack;
  unsigned char *seen;
  memset(g, 0, sizeof *g);
  stack = malloc(n * sizeof *stack);
  seen = calloc(n, 1);
  g->pos = malloc(n * sizeof *g->pos);
  if (stack == NULL || seen == NULL || g->pos == NULL)
    goto fail;
  stack[top++] = e;
  seen[e] = 1;
  while (top > 0) {
    dm_expr x = stack[--top];
    int a, na = dm_expr_nargs(ctx, x);
    for (a = 0; a < na; a++) {
      dm_expr y = dm_expr_arg(ctx, x, a);
      if (y < 0 || y >= x)
        goto fail;
      if (!seen[y]) {
        seen[y] = 1;
        stack[top++] = y;
      }
    }
  }
  for (k = 0; k < n; k++)
    g->len += seen[k];
  g->node = malloc(g->len * sizeof *g->node);
  g->val = malloc(g->len * sizeof *g->val);
  g->mag = malloc(g->len * sizeof *g->mag);
  if (g->node == NULL || g->val == NULL || g->mag == NULL)
    goto fail;
  for (k = 0, g->len = 0; k < n; k++) {
    g->pos[k] = seen[k] ? (int32_t)g->len : -1;
    if (seen[k])
      g->node[g->len++] = (dm_expr)k;
  }
  free(stack);
  free(seen);
  return DM_OK;
fail:
  free(stack);
  free(seen);
  dag_free(g);
  return DM_ENOMEM;
}

/* Value and magnitude of every node at the point vars = vals. */
static void dag_eval(const dm_expr_ctx *ctx, dag *g, size_t nv, const dm_expr *vars,
                     const double *vals)
{
  size_t k, i;
  for (k = 0; k < g->len; k++) {
    dm_expr x = g->node[k];
    int op = dm_expr_kind(ctx, x), na = dm_expr_nargs(ctx, x);
    double a = 0, b = 0, ma = 0, mb = 0, v, m;
    if (na >= 1) {
      a = g->val[g->pos[dm_expr_arg(ctx, x, 0)]];
      ma = g->mag[g->pos[dm_expr_arg(ctx, x, 0)]];
    }
    if (na >= 2) {
      b = g->val[g->pos[dm_expr_arg(ctx, x, 1)]];
      mb = g->mag[g->pos[dm_expr_arg(ctx, x, 1)]];
    }
    switch (op) {
    case DM_EXPR_CONST:
      dm_expr_is_const(ctx, x, &v);
      m = fabs(v);
      break;
    case DM_EXPR_SYM:
    case DM_EXPR_PARAM:
      v = NAN;
      for (i = 0; i < nv; i++)
        if (vars[i] == x)
          v = vals[i];
      m = fabs(v);
      break;
    case DM_EXPR_ADD:
    case DM_EXPR_SUB:
      v = dm_expr_binary_value(op, a, b);
      m = ma + mb;
      break;
    case DM_EXPR_MUL:
      v = a * b;
      m = ma * mb;
      break;
    case DM_EXPR_DIV:
      v = a / b;
      m = ma / fabs(b);
      break;
    case DM_EXPR_NEG:
      v = -a;
      m = ma;
      break;
    case DM_EXPR_POWI: {
      int p = dm_expr_powi_exponent(ctx, x);
      v = pow(a, p);
      m = p >= 0 ? pow(ma, p) : fabs(v);
      break;
    }
    case DM_EXPR_SELECT: {
      double c = a;
      double t = g->val[g->pos[dm_expr_arg(ctx, x, 1)]], f = g->val[g->pos[dm_expr_arg(ctx, x, 2)]];
      double mt = g->mag[g->pos[dm_expr_arg(ctx, x, 1)]], mf = g->mag[g->pos[dm_expr_arg(ctx, x, 2)]];
      v = c != 0.0 ? t : f;
      m = c != 0.0 ? mt : mf;
      break;
    }
    default:
      v = na == 1 ? dm_expr_unary_value(op, a) : dm_expr_binary_value(op, a, b);
      m = fabs(v);
    }
    g->val[k] = v;
    g->mag[k] = m;
  }
}

static double uniform(unsigned long *seed)
{
  *seed = *seed * 6364136223846793005UL + 1442695040888963407UL;
  return (double)(*seed >> 11) / 9007199254740992.0;
}

int dm_routh_zero_by_eval(dm_expr_ctx *ctx, dm_expr d, const dm_routh_spec *sp,
                          size_t angle, double *worst)
{
  size_t n = sp->n, nv = 2 * n + sp->npar, i, k, finite = 0;
  dm_expr *vars;
  double *vals, rel = 0.0;
  unsigned long seed = 2385;
  dag g;
  int ok = 1;
  if (dag_build(ctx, d, &g) != DM_OK)
    return -1;
  vars = malloc(nv * sizeof *vars);
  vals = malloc(nv * sizeof *vals);
  if (vars == NULL || vals == NULL) {
    free(vars);
    free(vals);
    dag_free(&g);
    return -1;
  }
  memcpy(vars, sp->q, n * sizeof *vars);
  memcpy(vars + n, sp->v, n * sizeof *vars);
  if (sp->npar)
    memcpy(vars + 2 * n, sp->par, sp->npar * sizeof *vars);
  for (k = 0; k < NSAMPLE && ok; k++) {
    double v, m;
    for (i = 0; i < nv; i++) {
      double u = uniform(&seed), p0;
      if (i == angle)
        vals[i] = M_PI * (2.0 * u - 1.0);                  /* the tested coordinate */
      else if (i < n)
        vals[i] = 0.15 + 0.4 * u;                          /* other positions */
      else if (i < 2 * n)
        vals[i] = 2.0 * u - 1.0;                           /* velocities */
      else {
        p0 = sp->par_values ? sp->par_values[i - 2 * n] : 0.0;
        vals[i] = p0 != 0.0 ? p0 * (0.9 + 0.2 * u) : 0.5 + u;
      }
    }
    dag_eval(ctx, &g, nv, vars, vals);
    v = g.val[g.len - 1];
    m = g.mag[g.len - 1];
    if (!isfinite(v) || !isfinite(m))
      continue;
    finite++;
    if (v == 0.0)
      continue;
    rel = fmax(rel, fabs(v) / m);
    ok = fabs(v) <= ZERO_REL * m;
  }
  free(vars);
  free(vals);
  dag_free(&g);
  if (worst)
    *worst = rel;
  if (!ok)
    return 0;
  return finite >= NFINITE_MIN ? 1 : -1;
}
