/* expr_norm.c -- normal forms of sums and products, made when a node is
 * built: dm_expr_add, dm_expr_sub, dm_expr_neg, dm_expr_mul, dm_expr_div,
 * dm_expr_powi.
 *
 * A sum is a multiset of terms c*t (c a constant coefficient, t without
 * one) plus a constant; a product is a constant coefficient times a
 * multiset of factors b^n (n a nonzero integer; b not a product, quotient,
 * negation, integer power or constant).  Building one flattens both
 * operands (nested sums and products, differences, quotients, negations,
 * integer powers), collects like terms (c1*t + c2*t -> (c1 + c2)*t) and
 * equal bases (x^m*x^n -> x^(m+n)), drops what cancels, folds the
 * constants, and looks the multiset up in a table: equal sums or products
 * are one node whatever order or grouping they were written in.  A new
 * one is a binary tree over existing nodes -- the two operands' when
 * nothing was collected between them, else the longest existing prefix --
 * in the order of first appearance, so that printing keeps the written
 * order: the first positive term first, the constant last, the
 * coefficient first, negative exponents as one denominator
 * (2*m2*cos(phi)*r1*r2, x - 2*y + 3, 0.5*x^2/(y*z^3)).
 *
 * Identities and what they do to IEEE results (everything else is
 * reassociation: results may differ by rounding, and by where intermediate
 * results overflow):
 *  - t - t -> 0, 0*t -> 0, x/x -> 1 and x^m*x^n -> x^(m+n) (also for
 *    m + n = 0) give, where t or x is 0, +-Inf or NaN and the written form
 *    is NaN (Inf - Inf, 0*Inf, 0/0, Inf/Inf), the value the expression has
 *    everywhere else;
 *  - x/0 -> Inf*x and x/c -> (1/c)*x only when 1/c is exact;
 *  - no others: sqrt(x)^2 and (x^0.5)^2 stay, constants are not
 *    distributed over sums (0.5*(x + y) stays) except -1 (exact).
 * Sums and products of more than NORM_LIMIT elements are extended without
 * collecting, so that building a long sum term by term stays linear.
 * Flattening and the table of normal nodes are in expr_flat.c. */
#include <config.h>
#include "expr/expr_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NORM_LIMIT 256
#define EXP_LIMIT ((int64_t)1 << 30)

#define K(x) dm_expr__k(ctx, (x))

enum { ADD = DM_EXPR_ADD, SUB = DM_EXPR_SUB, MUL = DM_EXPR_MUL,
       DIV = DM_EXPR_DIV, NEG = DM_EXPR_NEG, POWI = DM_EXPR_POWI };

static dm_expr oom(dm_expr_ctx *ctx)
{
  return dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
}

void dm_expr__norm_free(dm_expr_ctx *ctx)
{
  free(ctx->nel[0]);
  free(ctx->nel[1]);
  free(ctx->walk);
  free(ctx->ftab);
}

/* Elements of a sum / factors of a product, as far as known. */
size_t dm_expr__nlen(const dm_expr_ctx *ctx, dm_expr e, int prod)
{
  double c;
  while (ctx->node[e].op == NEG)
    e = ctx->node[e].a;
  if (!prod && ctx->node[e].op == MUL && dm_expr__isc(ctx, ctx->node[e].a, &c))
    e = ctx->node[e].b;          /* c*(sum): the sum's terms */
  while (ctx->node[e].op == NEG)
    e = ctx->node[e].a;
  const dm_node *nd = &ctx->node[e];
  if (prod ? (nd->op == MUL || nd->op == DIV) : (nd->op == ADD || nd->op == SUB))
    return nd->len ? nd->len : 2;
  return 1;
}

static dm_expr node2(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b, size_t len)
{
  dm_expr r = dm_expr__cons(ctx, op, a, b, -1);
  if (r >= 0 && (op == ADD || op == SUB || op == MUL || op == DIV))
    ctx->node[r].len = (uint16_t)(len < 65535 ? len : 65535);
  return r;
}

static dm_expr node1(dm_expr_ctx *ctx, int op, dm_expr a, int32_t b)
{
  return dm_expr__cons(ctx, op, a, b, -1);
}

/* {==================================================================
 * building normal nodes
 * =================================================================== */

/* A term with coefficient c >= 0 (or NaN), for a place after + or -. */
static dm_expr term_node(dm_expr_ctx *ctx, const dm_nel *x, double c)
{
  if (x->k == DM_NE_CONST)
    return K(c);
  if (x->k == DM_NE_RECIP)
    return node2(ctx, DIV, K(c), x->key, 1);
  return c == 1 ? x->key : node2(ctx, MUL, K(c), x->key, 1);
}

/* The term alone, with its sign. */
static dm_expr signed_term(dm_expr_ctx *ctx, const dm_nel *x)
{
  if (x->k == DM_NE_CONST || !(x->c < 0))
    return term_node(ctx, x, x->c);
  if (x->k == DM_NE_RECIP)
    return node1(ctx, NEG, term_node(ctx, x, -x->c), -1);
  if (x->c == -1)
    return node1(ctx, NEG, x->key, -1);
  return node2(ctx, MUL, K(x->c), x->key, 1);
}

static dm_expr factor_node(dm_expr_ctx *ctx, const dm_nel *x)
{
  return x->k == 1 ? x->key : node1(ctx, POWI, x->key, x->k);
}

/* One element after + / - / *: its node and the operation. */
static dm_expr next_node(dm_expr_ctx *ctx, const dm_nel *x, int prod, int *op)
{
  if (prod) {
    *op = MUL;
    return factor_node(ctx, x);
  }
  *op = x->c < 0 ? SUB : ADD;
  return term_node(ctx, x, x->c < 0 ? -x->c : x->c);
}

/* The node of the sum (first element positive) or product (exponents
 * positive) of E[0..n), n >= 1.  E[0..k) came from the first operand, the
 * rest from the second (k = 0: no such split). */
static dm_expr build(dm_expr_ctx *ctx, dm_nel *E, size_t n, size_t k, int prod)
{
  int op;
  if (n == 1)
    return next_node(ctx, &E[0], prod, &op);
  uint64_t tot = 0, ha = 0;
  for (size_t i = 0; i < n; i++) {
    E[i].h = dm_expr__hel(&E[i], prod);
    tot += E[i].h;
    if (i < k)
      ha += E[i].h;
  }
  uint64_t hn = dm_expr__hfin(tot, n, prod);
  dm_expr r = dm_expr__probe(ctx, hn, prod, E, n);
  if (r != DM_EXPR_NONE)
    return r;
  if (k > 0 && k < n) {               /* both operands' parts exist? */
    dm_expr A = k == 1 ? next_node(ctx, &E[0], prod, &op)
                       : dm_expr__probe(ctx, dm_expr__hfin(ha, k, prod), prod, E, k);
    dm_expr B = DM_EXPR_NONE;
    op = prod ? MUL : ADD;
    if (A != DM_EXPR_NONE)
      B = n - k == 1 ? next_node(ctx, &E[k], prod, &op)
                     : dm_expr__probe(ctx, dm_expr__hfin(tot - ha, n - k, prod), prod, E + k,
                                      n - k);
    if (B != DM_EXPR_NONE) {
      r = node2(ctx, op, A, B, n);
      return dm_expr__reg(ctx, hn, r) ? DM_EXPR_NONE : r;
    }
  }
  /* the longest existing prefix, then one element at a time */
  size_t j = n - 1;
  uint64_t hp = tot - E[n - 1].h;
  r = DM_EXPR_NONE;
  for (; j >= 2; j--) {
    if ((r = dm_expr__probe(ctx, dm_expr__hfin(hp, j, prod), prod, E, j)) != DM_EXPR_NONE)
      break;
    hp -= E[j - 1].h;
  }
  if (r == DM_EXPR_NONE) {
    j = 1;
    hp = E[0].h;
    r = next_node(ctx, &E[0], prod, &op);
  }
  for (; j < n && r != DM_EXPR_NONE; j++) {
    hp += E[j].h;
    dm_expr t = next_node(ctx, &E[j], prod, &op);
    if (t == DM_EXPR_NONE)
      return DM_EXPR_NONE;
    r = node2(ctx, op, r, t, j + 1);
    if (dm_expr__reg(ctx, dm_expr__hfin(hp, j + 1, prod), r))
      return DM_EXPR_NONE;
  }
  return r;
}

/* {==================================================================
 * sums
 * =================================================================== */

/* The split after the first operand's elements (0: they are not first). */
static size_t split_at(const dm_nel *E, size_t n)
{
  size_t k = 0;
  while (k < n && E[k].src == 0)
    k++;
  for (size_t i = k; i < n; i++)
    if (E[i].src == 0)
      return 0;
  return k;
}

static void rotate_to_front(dm_nel *E, size_t h)
{
  dm_nel t = E[h];
  memmove(E + 1, E, h * sizeof *E);
  E[0] = t;
}

/* Past NORM_LIMIT terms: a + b without collecting. */
static dm_expr long_sum(dm_expr_ctx *ctx, dm_expr a, dm_expr b, int sb,
                        size_t la, size_t lb)
{
  if (b == DM_EXPR_NONE)                      /* -a */
    return ctx->node[a].op == NEG ? ctx->node[a].a : node1(ctx, NEG, a, -1);
  if (la < lb || lb > NORM_LIMIT)
    return node2(ctx, sb > 0 ? ADD : SUB, a, b, la + lb);
  dm_flat f = { 0, 0, 0, 1, 0 };
  if (dm_expr__flatten_sum(ctx, &f, b, sb, 1, 0))
    return oom(ctx);
  dm_expr r = a;
  for (size_t i = 0; i < f.n && r != DM_EXPR_NONE; i++) {
    int op;
    dm_nel x = ctx->nel[0][i];
    dm_expr t = next_node(ctx, &x, 0, &op);
    r = t == DM_EXPR_NONE ? t : node2(ctx, op, r, t, ++la);
  }
  if (r != DM_EXPR_NONE && f.hasc && f.c != 0)
    r = node2(ctx, f.c < 0 ? SUB : ADD, r, K(fabs(f.c)), ++la);
  return r;
}

static dm_expr build_sum(dm_expr_ctx *ctx, size_t n, size_t k, int hc,
                         dm_flat *f);

/* Reorder ctx->nel[0][0..n) so that the elements of the first operand
 * (src 0) come first, each group in its order: an expanded c*(sum)
 * appended its terms at the end, and the sum built before is then found
 * as the prefix (one new node per added term). */
static void stable_by_src(dm_expr_ctx *ctx, size_t n)
{
  dm_nel *E = ctx->nel[0];
  size_t k = 0;
  while (k < n && E[k].src == 0)
    k++;
  for (size_t i = k + 1; i < n; i++)
    if (E[i].src == 0) {
      dm_nel t = E[i];
      memmove(E + k + 1, E + k, (i - k) * sizeof *E);
      E[k++] = t;
    }
}

/* An element's place in the sort of merge_like. */
typedef struct elix {
  int32_t key, k;
  size_t i;
} elix;

static int cmp_ix(const void *x, const void *y)
{
  const elix *a = x, *b = y;
  if (a->key != b->key)
    return a->key < b->key ? -1 : 1;
  if (a->k != b->k)
    return a->k < b->k ? -1 : 1;
  return (a->i > b->i) - (a->i < b->i);
}

/* Like terms of ctx->nel[0][0..f->n) collected into their first
 * occurrence (coefficients added in the order they appear), by sorting an
 * index: what flattening with merge does, without its linear search per
 * element (used for long lists). */
static int merge_like(dm_expr_ctx *ctx, dm_flat *f)
{
  size_t n = f->n;
  if (n < 2)
    return 0;
  elix *t = malloc(n * sizeof *t);
  if (t == NULL)
    return -1;
  dm_nel *E = ctx->nel[0];
  for (size_t i = 0; i < n; i++)
    t[i] = (elix){ E[i].key, E[i].k, i };
  qsort(t, n, sizeof *t, cmp_ix);
  for (size_t a = 0, b; a < n; a = b) {
    for (b = a + 1; b < n && t[b].key == t[a].key && t[b].k == t[a].k; b++) {
      E[t[a].i].c += E[t[b].i].c;
      E[t[b].i].key = INT32_MIN;            /* merged away */
    }
  }
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (E[i].key != INT32_MIN)
      E[m++] = E[i];
  f->n = m;
  free(t);
  return 0;
}

static dm_expr finish_sum(dm_expr_ctx *ctx, dm_flat *f);

/* sa*a + sb*b (b may be DM_EXPR_NONE: sa*a). */
static dm_expr norm_sum(dm_expr_ctx *ctx, dm_expr a, int sa, dm_expr b, int sb)
{
  size_t la = dm_expr__nlen(ctx, a, 0), lb = b != DM_EXPR_NONE ? dm_expr__nlen(ctx, b, 0) : 0;
  if (la > NORM_LIMIT || lb > NORM_LIMIT)
    return long_sum(ctx, a, b, sb, la, lb);
  dm_flat f = { 0, 0, 0, 1, 0 };
  int lin = la + lb <= 16;              /* short: merge by linear search */
  if (dm_expr__flatten_sum(ctx, &f, a, sa, 0, 0) ||
      (b != DM_EXPR_NONE && dm_expr__flatten_sum(ctx, &f, b, sb, 1, lin)) ||
      (!lin && merge_like(ctx, &f)))
    return oom(ctx);
  return finish_sum(ctx, &f);
}

dm_expr dm_expr__sum_n(dm_expr_ctx *ctx, size_t k, const dm_expr *t)
{
  size_t tot = 0;
  for (size_t i = 0; i < k; i++) {
    if (!dm_expr__check2(ctx, t[i], t[i]))
      return DM_EXPR_NONE;
    tot += dm_expr__nlen(ctx, t[i], 0);
  }
  if (k == 0)
    return K(0.0);
  if (k == 1)
    return t[0];
  if (tot > NORM_LIMIT) {               /* long: extended without collecting */
    dm_expr r = t[0];
    for (size_t i = 1; i < k && r != DM_EXPR_NONE; i++)
      r = dm_expr_add(ctx, r, t[i]);
    return r;
  }
  dm_flat f = { 0, 0, 0, 1, 0 };
  for (size_t i = 0; i < k; i++)
    if (dm_expr__flatten_sum(ctx, &f, t[i], 1, i == 0 ? 0 : 1, 0))
      return oom(ctx);
  if (merge_like(ctx, &f))
    return oom(ctx);
  return finish_sum(ctx, &f);
}

/* The normal sum of the element list f (ctx->nel[0]). */
static dm_expr finish_sum(dm_expr_ctx *ctx, dm_flat *pf)
{
  dm_flat f = *pf;
  /* a collected term c*(sum) with c = +-1 is that sum's terms; a common
   * coefficient of every term (no constant) goes out: 0.5*x + 0.5*y ->
   * 0.5*(x + y) */
  dm_nel *E;
  size_t n, k;
  double gamma = 1;
  for (;;) {
    int expanded = 0, lin = f.n <= 16;
    for (size_t i = 0; i < f.n; i++) {
      dm_nel x = ctx->nel[0][i];
      if (x.k == DM_NE_PLAIN && (x.c == 1 || x.c == -1) && dm_expr__sumlike(ctx, x.key)) {
        ctx->nel[0][i].c = 0;
        expanded = 1;
        if (dm_expr__flatten_sum(ctx, &f, x.key, x.c > 0 ? 1 : -1, x.src, lin))
          return oom(ctx);
      }
    }
    if (expanded && !lin && merge_like(ctx, &f))
      return oom(ctx);
    E = ctx->nel[0];
    n = 0;
    for (size_t i = 0; i < f.n; i++)           /* drop t - t */
      if (E[i].c != 0)
        E[n++] = E[i];
    f.n = n;
    if (expanded)                  /* the first operand's terms first again */
      stable_by_src(ctx, n);
    k = split_at(E, n);
    if ((f.hasc && f.c != 0) || n < 2)
      break;
    double g = fabs(E[0].c);
    for (size_t i = 1; i < n && g != 1; i++)
      if (fabs(E[i].c) != g)
        g = 1;
    if (g == 1 || !isfinite(g))
      break;
    for (size_t i = 0; i < n; i++)
      E[i].c = E[i].c > 0 ? 1 : -1;
    gamma *= g;
  }
  int hc = f.hasc && f.c != 0;
  dm_expr r;
  if (n == 0)
    r = K(hc ? f.c : 0.0);
  else if (n == 1 && !hc)
    r = signed_term(ctx, &E[0]);
  else
    r = build_sum(ctx, n, k, hc, &f);
  return gamma != 1 && r != DM_EXPR_NONE ? dm_expr_mul(ctx, K(gamma), r) : r;
}

/* The sum of the n terms in ctx->nel[0] (split after k) and, when hc, the
 * constant f->c. */
static dm_expr build_sum(dm_expr_ctx *ctx, size_t n, size_t k, int hc,
                         dm_flat *f)
{
  dm_nel *E = ctx->nel[0];
  if (hc) {                    /* a's constant ends a's part, else the sum */
    dm_nel *y = dm_expr__new_el(ctx, f);
    if (y == NULL)
      return oom(ctx);
    E = ctx->nel[0];
    size_t at = f->hasc == 1 ? k : n;
    memmove(E + at + 1, E + at, (n - at) * sizeof *E);
    memset(&E[at], 0, sizeof *E);
    E[at].key = -1;
    E[at].k = DM_NE_CONST;
    E[at].c = f->c;
    E[at].src = f->hasc == 1 ? 0 : 1;
    k += f->hasc == 1;
    n++;
  }
  /* the first positive term goes first; all negative: -(...) unless a
   * positive constant can lead */
  size_t h = n;
  int negate = 0;
  for (size_t i = 0; i < n && h == n; i++)
    if (E[i].k != DM_NE_CONST && !(E[i].c < 0))
      h = i;
  if (h == n) {
    for (size_t i = 0; i < n && h == n; i++)
      if (E[i].k == DM_NE_CONST && E[i].c > 0)
        h = i;
    if (h == n) {
      negate = 1;
      for (size_t i = 0; i < n; i++) {
        E[i].c = -E[i].c;
        if (h == n && E[i].k != DM_NE_CONST)
          h = i;
      }
    }
  }
  if (h > 0) {
    if (h >= k)
      k = 0;
    rotate_to_front(E, h);
  }
  dm_expr r = build(ctx, E, n, k, 0);
  return negate && r != DM_EXPR_NONE ? node1(ctx, NEG, r, -1) : r;
}

/* {==================================================================
 * products
 * =================================================================== */

/* a^ea * b^eb * c0 as written (no normal form). */
static dm_expr raw_prod(dm_expr_ctx *ctx, dm_expr a, int64_t ea, dm_expr b,
                        int64_t eb, double c0)
{
  dm_expr r;
  if (b != DM_EXPR_NONE)
    r = node2(ctx, eb > 0 ? MUL : DIV, a, b,
              dm_expr__nlen(ctx, a, 1) + dm_expr__nlen(ctx, b, 1));
  else if (ea > INT32_MAX || ea < -INT32_MAX)
    return dm_expr__fail(ctx, DM_EINVAL, "expression: exponent too large");
  else
    r = ea == 1 ? a : node1(ctx, POWI, a, (int32_t)ea);
  return c0 == -1 ? node1(ctx, NEG, r, -1) : r;
}

/* c0 * a^ea * b^eb (b may be DM_EXPR_NONE); c0 is 1 or -1. */
static dm_expr norm_prod(dm_expr_ctx *ctx, dm_expr a, int64_t ea, dm_expr b,
                         int64_t eb, double c0)
{
  if (dm_expr__nlen(ctx, a, 1) > NORM_LIMIT ||
      (b != DM_EXPR_NONE && dm_expr__nlen(ctx, b, 1) > NORM_LIMIT))
    return raw_prod(ctx, a, ea, b, eb, c0);
  dm_flat f = { 0, 0, c0, 1, 0 };
  int s = ea > EXP_LIMIT || ea < -EXP_LIMIT ? 1
                                            : dm_expr__flatten_prod(ctx, &f, a, ea, 0, 0);
  if (s == 0 && b != DM_EXPR_NONE)
    s = dm_expr__flatten_prod(ctx, &f, b, eb, 1, 1);
  if (s < 0)
    return oom(ctx);
  if (s > 0)
    return raw_prod(ctx, a, ea, b, eb, c0);
  double c = f.c, d = f.d;
  if (c == 0)
    return K(0.0);                             /* 0*x -> 0 */
  if (d < 0) {
    c = -c;
    d = -d;
  }
  dm_nel *E = ctx->nel[0];
  size_t n = 0;
  for (size_t i = 0; i < f.n; i++)             /* drop x^0 */
    if (E[i].k != 0)
      E[n++] = E[i];
  if (n == 0)
    return K(c / d);
  if (d != 1) {                                /* 6*x/3 -> 2*x when exact */
    double q = c / d;
    if (isfinite(q) && fma(q, d, -c) == 0) {
      c = q;
      d = 1;
    }
  }
  if (n == 1 && E[0].k == 1 && d == 1) {
    if (c == 1)
      return E[0].key;
    if (c == -1 && dm_expr__sumlike(ctx, E[0].key))    /* -(x - y) -> y - x */
      return norm_sum(ctx, E[0].key, -1, DM_EXPR_NONE, 0);
  }
  /* numerator E[0..nn), denominator (exponents negated) after it */
  if (dm_expr__grow(&ctx->nel[0], &ctx->nelcap[0], 2 * n, sizeof(dm_nel)))
    return oom(ctx);
  E = ctx->nel[0];
  dm_nel *D = E + n;
  size_t nn = 0, nd = 0;
  for (size_t i = 0; i < n; i++) {
    if (E[i].k < 0) {
      D[nd] = E[i];
      D[nd++].k = -E[i].k;
    } else {
      E[nn++] = E[i];
    }
  }
  size_t kn = split_at(E, nn), kd = split_at(D, nd);
  dm_expr N = nn ? build(ctx, E, nn, kn, 1) : DM_EXPR_NONE;
  dm_expr Dn = nd ? build(ctx, D, nd, kd, 1) : DM_EXPR_NONE;
  if ((nn && N == DM_EXPR_NONE) || (nd && Dn == DM_EXPR_NONE))
    return DM_EXPR_NONE;
  if (d != 1)
    Dn = Dn == DM_EXPR_NONE ? K(d) : node2(ctx, MUL, K(d), Dn, nd);
  dm_expr T;
  if (Dn == DM_EXPR_NONE) {
    T = N;
  } else if (N == DM_EXPR_NONE) {              /* c/den */
    T = node2(ctx, DIV, K(c < 0 ? -c : c), Dn, n);
    return c < 0 ? node1(ctx, NEG, T, -1) : T;
  } else {
    T = node2(ctx, DIV, N, Dn, n);
  }
  if (c == 1)
    return T;
  if (c == -1)
    return node1(ctx, NEG, T, -1);
  return node2(ctx, MUL, K(c), T, n);
}

/* {==================================================================
 * the constructors
 * =================================================================== */

dm_expr dm_expr_add(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  return dm_expr__check2(ctx, a, b) ? norm_sum(ctx, a, 1, b, 1) : DM_EXPR_NONE;
}

dm_expr dm_expr_sub(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  return dm_expr__check2(ctx, a, b) ? norm_sum(ctx, a, 1, b, -1) : DM_EXPR_NONE;
}

dm_expr dm_expr_neg(dm_expr_ctx *ctx, dm_expr a)
{
  if (!dm_expr__check2(ctx, a, a))
    return DM_EXPR_NONE;
  double c;
  if (dm_expr__isc(ctx, a, &c))
    return K(-c);
  if (dm_expr__sumlike(ctx, a))
    return norm_sum(ctx, a, -1, DM_EXPR_NONE, 0);
  return norm_prod(ctx, a, 1, DM_EXPR_NONE, 0, -1.0);
}

dm_expr dm_expr_mul(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  return dm_expr__check2(ctx, a, b) ? norm_prod(ctx, a, 1, b, 1, 1.0) : DM_EXPR_NONE;
}

dm_expr dm_expr_div(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  return dm_expr__check2(ctx, a, b) ? norm_prod(ctx, a, 1, b, -1, 1.0) : DM_EXPR_NONE;
}

dm_expr dm_expr_powi(dm_expr_ctx *ctx, dm_expr a, int n)
{
  if (!dm_expr__check2(ctx, a, a))
    return DM_EXPR_NONE;
  if (n == 0)
    return K(1.0);
  return norm_prod(ctx, a, n, DM_EXPR_NONE, 0, 1.0);
}
