/* expr_flat.c -- the machinery of the normal forms (expr_norm.c): sums and
 * products flattened into element lists, and the table that finds the
 * node of a sum or product from the multiset of its elements (so that
 * equal ones are one node whatever their order or grouping). */
#include <config.h>
#include "expr/expr_impl.h"
#include "expr/tape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define EXP_LIMIT ((int64_t)1 << 30)

enum { ADD = DM_EXPR_ADD, SUB = DM_EXPR_SUB, MUL = DM_EXPR_MUL,
       DIV = DM_EXPR_DIV, NEG = DM_EXPR_NEG, POWI = DM_EXPR_POWI };

static dm_expr oom(dm_expr_ctx *ctx)
{
  return dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
}

int dm_expr__sumlike(const dm_expr_ctx *ctx, dm_expr e)
{
  while (ctx->node[e].op == NEG)
    e = ctx->node[e].a;
  return ctx->node[e].op == ADD || ctx->node[e].op == SUB;
}

/* {==================================================================
 * flattening
 * =================================================================== */

int dm_expr__grow(void *pp, size_t *cap, size_t need, size_t size)
{
  if (need <= *cap)
    return 0;
  size_t c = *cap ? *cap : 64;
  while (c < need)
    c *= 2;
  void **p = pp;
  void *q = realloc(*p, c * size);
  if (q == NULL)
    return -1;
  *p = q;
  *cap = c;
  return 0;
}

dm_nel *dm_expr__new_el(dm_expr_ctx *ctx, dm_flat *f)
{
  if (f->n >= ctx->nelcap[f->w] &&
      dm_expr__grow(&ctx->nel[f->w], &ctx->nelcap[f->w], f->n + 1, sizeof(dm_nel)))
    return NULL;
  dm_nel *x = &ctx->nel[f->w][f->n++];
  memset(x, 0, sizeof *x);
  return x;
}

static inline int walk_push(dm_expr_ctx *ctx, size_t *ns, dm_expr e, int64_t ex)
{
  if (*ns >= ctx->walkcap &&
      dm_expr__grow(&ctx->walk, &ctx->walkcap, *ns + 1, sizeof(dm_nwalk)))
    return -1;
  ctx->walk[*ns].node = e;
  ctx->walk[*ns].e = ex;
  ++*ns;
  return 0;
}

/* A term: e = c*key (DM_NE_PLAIN) or c/key (DM_NE_RECIP). */
static double split(const dm_expr_ctx *ctx, dm_expr e, int32_t *key,
                    int32_t *kind)
{
  double c = 1, v;
  while (ctx->node[e].op == NEG) {
    c = -c;
    e = ctx->node[e].a;
  }
  const dm_node *nd = &ctx->node[e];
  if ((nd->op == MUL || nd->op == DIV) && dm_expr__isc(ctx, nd->a, &v)) {
    *key = nd->b;
    *kind = nd->op == MUL ? DM_NE_PLAIN : DM_NE_RECIP;
    return c * v;
  }
  *key = e;
  *kind = DM_NE_PLAIN;
  return c;
}

/* Terms of s*e appended to f; with merge, like terms are collected. */
int dm_expr__flatten_sum(dm_expr_ctx *ctx, dm_flat *f, dm_expr e, int s, int src,
                       int merge)
{
  size_t ns = 0;
  if (walk_push(ctx, &ns, e, s))
    return -1;
  while (ns > 0) {
    dm_expr x = ctx->walk[--ns].node;
    int sg = (int)ctx->walk[ns].e;
    const dm_node nd = ctx->node[x];
    double v;
    switch (nd.op) {
    case ADD:
    case SUB:
      if (walk_push(ctx, &ns, nd.b, nd.op == ADD ? sg : -sg) ||
          walk_push(ctx, &ns, nd.a, sg))
        return -1;
      continue;
    case NEG:
      if (dm_expr__sumlike(ctx, nd.a)) {
        if (walk_push(ctx, &ns, nd.a, -sg))
          return -1;
        continue;
      }
      break;
    case DM_EXPR_CONST:
      v = ctx->cval[nd.a];
      f->c += sg > 0 ? v : -v;
      f->hasc |= 1 << src;
      continue;
    default:
      break;
    }
    int32_t key, kind;
    double c = split(ctx, x, &key, &kind);
    if (sg < 0)
      c = -c;
    dm_nel *E = ctx->nel[f->w];
    size_t i = f->n;
    if (merge)
      for (i = 0; i < f->n; i++)
        if (E[i].key == key && E[i].k == kind)
          break;
    if (i < f->n) {
      E[i].c += c;
      continue;
    }
    dm_nel *y = dm_expr__new_el(ctx, f);
    if (y == NULL)
      return -1;
    y->key = key;
    y->k = kind;
    y->c = c;
    y->src = src;
  }
  return 0;
}

/* 1/w is exact (or w is 0, Inf or NaN, where 1/w is what x/w means). */
static int recip_exact(double w)
{
  if (w == 0 || isinf(w) || isnan(w))
    return 1;
  int ex;
  double m = frexp(w, &ex), r = 1.0 / w;
  return (m == 0.5 || m == -0.5) && isfinite(r) && r != 0;
}

/* Factors of e^ex appended to f.  Returns -1 out of memory, 1 when an
 * exponent grows too large (no normal form), else 0. */
int dm_expr__flatten_prod(dm_expr_ctx *ctx, dm_flat *f, dm_expr e, int64_t ex,
                        int src, int merge)
{
  size_t ns = 0;
  if (walk_push(ctx, &ns, e, ex))
    return -1;
  while (ns > 0) {
    dm_expr x = ctx->walk[--ns].node;
    int64_t k = ctx->walk[ns].e;
    const dm_node nd = ctx->node[x];
    switch (nd.op) {
    case DM_EXPR_CONST: {
      double v = ctx->cval[nd.a];
      if (k > 0) {
        f->c *= dm_tape_powi(v, (int)k);
      } else {
        double w = dm_tape_powi(v, (int)-k);
        if (recip_exact(w))
          f->c *= 1.0 / w;
        else
          f->d *= w;
      }
      continue;
    }
    case NEG:
      if (k & 1)
        f->c = -f->c;
      if (walk_push(ctx, &ns, nd.a, k))
        return -1;
      continue;
    case MUL:
    case DIV:
      if (walk_push(ctx, &ns, nd.b, nd.op == MUL ? k : -k) ||
          walk_push(ctx, &ns, nd.a, k))
        return -1;
      continue;
    case POWI: {
      int64_t k2 = k * nd.b;
      if (k2 > EXP_LIMIT || k2 < -EXP_LIMIT)
        return 1;
      if (walk_push(ctx, &ns, nd.a, k2))
        return -1;
      continue;
    }
    default:
      break;
    }
    dm_nel *E = ctx->nel[f->w];
    size_t i = f->n;
    if (merge)
      for (i = 0; i < f->n; i++)
        if (E[i].key == x)
          break;
    if (i < f->n) {
      int64_t s = (int64_t)E[i].k + k;
      if (s > EXP_LIMIT || s < -EXP_LIMIT)
        return 1;
      E[i].k = (int32_t)s;
      continue;
    }
    dm_nel *y = dm_expr__new_el(ctx, f);
    if (y == NULL)
      return -1;
    y->key = x;
    y->k = (int32_t)k;
    y->src = src;
  }
  return 0;
}

/* {==================================================================
 * the table of sums and products by element multiset
 * =================================================================== */

static double canon(double c)
{
  return isnan(c) ? NAN : c;
}

uint64_t dm_expr__hel(const dm_nel *x, int prod)
{
  uint64_t h = (uint64_t)(uint32_t)x->key * 0x9e3779b97f4a7c15ULL ^
               (uint64_t)(uint32_t)x->k * 0xc2b2ae3d27d4eb4fULL;
  if (!prod)
    h ^= dm_expr__mix64(dm_expr__dbits(canon(x->c)) + 0x165667b19e3779f9ULL);
  return dm_expr__mix64(h);
}

/* Hash of a multiset from the sum of its element hashes. */
uint64_t dm_expr__hfin(uint64_t s, size_t n, int prod)
{
  return dm_expr__mix64(s + (uint64_t)n * 0x27d4eb2f165667c5ULL +
               (prod ? 0x94d049bb133111ebULL : 0));
}

static int cmp_el(const void *p, const void *q)
{
  const dm_nel *x = p, *y = q;
  if (x->key != y->key)
    return x->key < y->key ? -1 : 1;
  if (x->k != y->k)
    return x->k < y->k ? -1 : 1;
  uint64_t a = dm_expr__dbits(canon(x->c)), b = dm_expr__dbits(canon(y->c));
  return (a > b) - (a < b);
}

/* 1 if node e is the sum / product of exactly the elements E[0..n). */
static int same(dm_expr_ctx *ctx, dm_expr e, int prod, const dm_nel *E,
                size_t n)
{
  dm_flat f = { 1, 0, prod ? 1.0 : 0.0, 1.0, 0 };
  int r = prod ? dm_expr__flatten_prod(ctx, &f, e, 1, 0, 0)
               : dm_expr__flatten_sum(ctx, &f, e, 1, 0, 0);
  if (r != 0)
    return 0;
  if (prod && (f.c != 1 || f.d != 1))
    return 0;
  if (!prod && f.hasc && f.c != 0) {
    dm_nel *y = dm_expr__new_el(ctx, &f);
    if (y == NULL)
      return 0;
    y->key = -1;
    y->k = DM_NE_CONST;
    y->c = f.c;
  }
  if (f.n != n)
    return 0;
  if (dm_expr__grow(&ctx->nel[1], &ctx->nelcap[1], 2 * n, sizeof(dm_nel)))
    return 0;
  dm_nel *A = ctx->nel[1], *B = A + n;
  for (size_t i = 0; i < n; i++) {
    B[i] = E[i];
    if (prod)
      A[i].c = B[i].c = 0;
  }
  if (n <= 12) {                       /* small: match pairs, no sort */
    for (size_t i = 0; i < n; i++) {
      size_t j = i;
      while (j < n && cmp_el(&A[i], &B[j]) != 0)
        j++;
      if (j == n)
        return 0;
      dm_nel t = B[i];                 /* used ones move to the front */
      B[i] = B[j];
      B[j] = t;
    }
    return 1;
  }
  qsort(A, n, sizeof *A, cmp_el);
  qsort(B, n, sizeof *B, cmp_el);
  for (size_t i = 0; i < n; i++)
    if (cmp_el(&A[i], &B[i]) != 0)
      return 0;
  return 1;
}

dm_expr dm_expr__probe(dm_expr_ctx *ctx, uint64_t h, int prod, const dm_nel *E,
                     size_t n)
{
  if (ctx->ftabcap == 0)
    return DM_EXPR_NONE;
  size_t mask = ctx->ftabcap - 1;
  for (size_t j = h & mask; ctx->ftab[j].node >= 0; j = (j + 1) & mask)
    if (ctx->ftab[j].h == h && same(ctx, ctx->ftab[j].node, prod, E, n))
      return ctx->ftab[j].node;
  return DM_EXPR_NONE;
}

static int ftab_put(dm_nslot *t, size_t cap, uint64_t h, dm_expr e)
{
  size_t j = h & (cap - 1);
  while (t[j].node >= 0) {
    if (t[j].node == e && t[j].h == h)
      return 0;
    j = (j + 1) & (cap - 1);
  }
  t[j].h = h;
  t[j].node = e;
  return 1;
}

int dm_expr__reg(dm_expr_ctx *ctx, uint64_t h, dm_expr e)
{
  if (e < 0)
    return -1;
  if (2 * (ctx->nftab + 1) > ctx->ftabcap) {
    size_t cap = ctx->ftabcap ? 2 * ctx->ftabcap : 1024;
    dm_nslot *t = malloc(cap * sizeof *t);
    if (t == NULL) {
      oom(ctx);
      return -1;
    }
    for (size_t j = 0; j < cap; j++)
      t[j].node = -1;
    for (size_t j = 0; j < ctx->ftabcap; j++)
      if (ctx->ftab[j].node >= 0)
        ftab_put(t, cap, ctx->ftab[j].h, ctx->ftab[j].node);
    free(ctx->ftab);
    ctx->ftab = t;
    ctx->ftabcap = cap;
  }
  ctx->nftab += (size_t)ftab_put(ctx->ftab, ctx->ftabcap, h, e);
  return 0;
}

