/* expr.c -- the expression context: node storage, hash-consing, names and
 * the simplifying constructors.  See expr.h for the contract. */
#include <config.h>
#include "expr_impl.h"
#include "tape.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NAME_MAX_LEN 255

/* {==================================================================
 * context, errors
 * =================================================================== */

dm_expr dm_expr__fail(dm_expr_ctx *ctx, int status, const char *fmt, ...)
{
  if (ctx->err.status == DM_OK) {
    va_list ap;
    ctx->err.status = status;
    va_start(ap, fmt);
    vsnprintf(ctx->err.msg, sizeof ctx->err.msg, fmt, ap);
    va_end(ap);
  }
  return DM_EXPR_NONE;
}

static dm_expr oom(dm_expr_ctx *ctx)
{
  return dm_expr__fail(ctx, DM_ENOMEM, "expression: out of memory");
}

dm_expr_ctx *dm_expr_ctx_alloc(void)
{
  dm_expr_ctx *ctx = calloc(1, sizeof *ctx);
  if (ctx == NULL)
    return NULL;
  ctx->hcap = 1024;
  ctx->ntcap = 64;
  ctx->htab = malloc(ctx->hcap * sizeof *ctx->htab);
  ctx->ntab = malloc(ctx->ntcap * sizeof *ctx->ntab);
  if (ctx->htab == NULL || ctx->ntab == NULL) {
    dm_expr_ctx_free(ctx);
    return NULL;
  }
  memset(ctx->htab, 0xff, ctx->hcap * sizeof *ctx->htab);
  memset(ctx->ntab, 0xff, ctx->ntcap * sizeof *ctx->ntab);
  dm_err_clear(&ctx->err);
  return ctx;
}

void dm_expr_ctx_free(dm_expr_ctx *ctx)
{
  if (ctx == NULL)
    return;
  for (size_t i = 0; i < ctx->nnames; i++)
    free(ctx->names[i]);
  free(ctx->names);
  free(ctx->node);
  free(ctx->cval);
  free(ctx->htab);
  free(ctx->ntab);
  free(ctx->memo);
  free(ctx->stamp);
  free(ctx->aux);
  free(ctx->stack);
  free(ctx->list);
  free(ctx);
}

const dm_err *dm_expr_ctx_err(const dm_expr_ctx *ctx) { return &ctx->err; }
void dm_expr_ctx_clear_err(dm_expr_ctx *ctx) { dm_err_clear(&ctx->err); }
size_t dm_expr_ctx_size(const dm_expr_ctx *ctx) { return ctx->n; }

/* {==================================================================
 * hash-consing
 * =================================================================== */

static uint64_t mix64(uint64_t h)
{
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}

static uint64_t dbits(double x)
{
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  return u;
}

static uint64_t node_hash(const dm_expr_ctx *ctx, int op, int32_t a,
                          int32_t b, int32_t c)
{
  uint64_t h = (uint64_t)op * 0x9e3779b97f4a7c15ULL;
  if (op == DM_EXPR_CONST)
    return mix64(h ^ dbits(ctx->cval[a]));
  h = mix64(h ^ (uint32_t)a);
  h = mix64(h ^ ((uint64_t)(uint32_t)b << 32 | (uint32_t)c));
  return h;
}

static int node_equal(const dm_expr_ctx *ctx, const dm_node *nd, int op,
                      int32_t a, int32_t b, int32_t c)
{
  if (nd->op != op)
    return 0;
  if (op == DM_EXPR_CONST)
    return dbits(ctx->cval[nd->a]) == dbits(ctx->cval[a]);
  return nd->a == a && nd->b == b && nd->c == c;
}

static int rehash(dm_expr_ctx *ctx)
{
  size_t cap = ctx->hcap * 2;
  int32_t *t = malloc(cap * sizeof *t);
  if (t == NULL)
    return -1;
  memset(t, 0xff, cap * sizeof *t);
  for (size_t i = 0; i < ctx->n; i++) {
    const dm_node *nd = &ctx->node[i];
    size_t j = node_hash(ctx, nd->op, nd->a, nd->b, nd->c) & (cap - 1);
    while (t[j] >= 0)
      j = (j + 1) & (cap - 1);
    t[j] = (int32_t)i;
  }
  free(ctx->htab);
  ctx->htab = t;
  ctx->hcap = cap;
  return 0;
}

/* The node (op, a, b, c), created if new.  For CONST, a indexes cval and
 * the slot is reused when an equal constant exists. */
static dm_expr cons(dm_expr_ctx *ctx, int op, int32_t a, int32_t b, int32_t c)
{
  if (2 * (ctx->n + 1) > ctx->hcap && rehash(ctx) != 0)
    return oom(ctx);
  size_t mask = ctx->hcap - 1;
  size_t j = node_hash(ctx, op, a, b, c) & mask;
  for (; ctx->htab[j] >= 0; j = (j + 1) & mask)
    if (node_equal(ctx, &ctx->node[ctx->htab[j]], op, a, b, c))
      return ctx->htab[j];
  if (ctx->n >= (size_t)INT32_MAX - 1)
    return dm_expr__fail(ctx, DM_ENOMEM, "expression: too many nodes");
  if (ctx->n == ctx->cap) {
    size_t cap = ctx->cap ? 2 * ctx->cap : 256;
    dm_node *p = realloc(ctx->node, cap * sizeof *p);
    if (p == NULL)
      return oom(ctx);
    ctx->node = p;
    ctx->cap = cap;
  }
  dm_node *nd = &ctx->node[ctx->n];
  nd->op = (uint8_t)op;
  nd->pad = 0;
  nd->a = a;
  nd->b = b;
  nd->c = c;
  if (op == DM_EXPR_SYM)
    nd->flags = DM_NF_SYM;
  else if (op == DM_EXPR_PARAM)
    nd->flags = DM_NF_PARAM;
  else if (op == DM_EXPR_CONST)
    nd->flags = 0;
  else {
    int k = dm_expr__arity(op);
    nd->flags = ctx->node[a].flags;
    if (k >= 2)
      nd->flags |= ctx->node[b].flags;
    if (k >= 3)
      nd->flags |= ctx->node[c].flags;
  }
  if (op == DM_EXPR_CONST)
    ctx->ncval++;            /* the tentative value becomes permanent */
  ctx->htab[j] = (int32_t)ctx->n;
  return (dm_expr)ctx->n++;
}

dm_expr dm_expr__cons(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b, dm_expr c)
{
  return cons(ctx, op, a, b, c);
}

/* The existing node (op, a, b, c) or DM_EXPR_NONE (not for CONST). */
static dm_expr find(const dm_expr_ctx *ctx, int op, int32_t a, int32_t b,
                    int32_t c)
{
  size_t mask = ctx->hcap - 1;
  for (size_t j = node_hash(ctx, op, a, b, c) & mask; ctx->htab[j] >= 0;
       j = (j + 1) & mask)
    if (node_equal(ctx, &ctx->node[ctx->htab[j]], op, a, b, c))
      return ctx->htab[j];
  return DM_EXPR_NONE;
}

/* A commutative node: b op a if that exists, else a op b as written, so
 * equal expressions are one node and printing keeps the user's order. */
static dm_expr cons_comm(dm_expr_ctx *ctx, int op, int32_t a, int32_t b)
{
  dm_expr e = find(ctx, op, b, a, -1);
  return e != DM_EXPR_NONE ? e : cons(ctx, op, a, b, -1);
}

dm_expr dm_expr_const(dm_expr_ctx *ctx, double x)
{
  if (isnan(x))
    x = NAN;                  /* one NaN */
  else if (x == 0)
    x = 0.0;                  /* no -0 */
  if (ctx->ncval == ctx->capcval) {
    size_t cap = ctx->capcval ? 2 * ctx->capcval : 64;
    double *p = realloc(ctx->cval, cap * sizeof *p);
    if (p == NULL)
      return oom(ctx);
    ctx->cval = p;
    ctx->capcval = cap;
  }
  ctx->cval[ctx->ncval] = x;  /* tentative: kept only if the node is new */
  return cons(ctx, DM_EXPR_CONST, (int32_t)ctx->ncval, -1, -1);
}

/* {==================================================================
 * names
 * =================================================================== */

static uint64_t str_hash(const char *s)
{
  uint64_t h = 1469598103934665603ULL;
  for (; *s; s++)
    h = (h ^ (unsigned char)*s) * 1099511628211ULL;
  return h;
}

static int name_rehash(dm_expr_ctx *ctx)
{
  size_t cap = ctx->ntcap * 2;
  int32_t *t = malloc(cap * sizeof *t);
  if (t == NULL)
    return -1;
  memset(t, 0xff, cap * sizeof *t);
  for (size_t i = 0; i < ctx->nnames; i++) {
    size_t j = str_hash(ctx->names[i]) & (cap - 1);
    while (t[j] >= 0)
      j = (j + 1) & (cap - 1);
    t[j] = (int32_t)i;
  }
  free(ctx->ntab);
  ctx->ntab = t;
  ctx->ntcap = cap;
  return 0;
}

/* Index of name, interned if new; -1 on error (recorded). */
static int32_t intern(dm_expr_ctx *ctx, const char *name)
{
  if (name == NULL || name[0] == '\0' || strlen(name) > NAME_MAX_LEN) {
    dm_expr__fail(ctx, DM_EINVAL, "expression: a name must have 1 to %d bytes",
                  NAME_MAX_LEN);
    return -1;
  }
  if (2 * (ctx->nnames + 1) > ctx->ntcap && name_rehash(ctx) != 0) {
    oom(ctx);
    return -1;
  }
  size_t mask = ctx->ntcap - 1, j = str_hash(name) & mask;
  for (; ctx->ntab[j] >= 0; j = (j + 1) & mask)
    if (strcmp(ctx->names[ctx->ntab[j]], name) == 0)
      return ctx->ntab[j];
  if (ctx->nnames == ctx->capnames) {
    size_t cap = ctx->capnames ? 2 * ctx->capnames : 16;
    char **p = realloc(ctx->names, cap * sizeof *p);
    if (p == NULL) {
      oom(ctx);
      return -1;
    }
    ctx->names = p;
    ctx->capnames = cap;
  }
  char *s = strdup(name);
  if (s == NULL) {
    oom(ctx);
    return -1;
  }
  ctx->names[ctx->nnames] = s;
  ctx->ntab[j] = (int32_t)ctx->nnames;
  return (int32_t)ctx->nnames++;
}

dm_expr dm_expr_sym(dm_expr_ctx *ctx, const char *name)
{
  int32_t k = intern(ctx, name);
  return k < 0 ? DM_EXPR_NONE : cons(ctx, DM_EXPR_SYM, k, -1, -1);
}

dm_expr dm_expr_param(dm_expr_ctx *ctx, const char *name)
{
  int32_t k = intern(ctx, name);
  return k < 0 ? DM_EXPR_NONE : cons(ctx, DM_EXPR_PARAM, k, -1, -1);
}

/* {==================================================================
 * simplifying constructors
 * =================================================================== */

#define K(x) dm_expr_const(ctx, (x))

static int isc(const dm_expr_ctx *ctx, dm_expr e, double *v)
{
  if (ctx->node[e].op != DM_EXPR_CONST)
    return 0;
  *v = ctx->cval[ctx->node[e].a];
  return 1;
}

static int check2(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (a == DM_EXPR_NONE || b == DM_EXPR_NONE)
    return 0;
  if (!dm_expr__valid(ctx, a) || !dm_expr__valid(ctx, b)) {
    dm_expr__fail(ctx, DM_EINVAL, "expression: invalid node handle");
    return 0;
  }
  return 1;
}

/* e = c * t with c a constant: returns c and sets *t (c = 1, t = e when e
 * has no constant factor). */
static double split_coef(const dm_expr_ctx *ctx, dm_expr e, dm_expr *t)
{
  const dm_node *nd = &ctx->node[e];
  double c;
  if (nd->op == DM_EXPR_MUL && isc(ctx, nd->a, &c)) {
    *t = nd->b;
    return c;
  }
  if (nd->op == DM_EXPR_NEG) {
    *t = nd->a;
    return -1.0;
  }
  *t = e;
  return 1.0;
}

/* e = t^n: returns n and sets *t (n = 1 for anything but POWI). */
static int split_pow(const dm_expr_ctx *ctx, dm_expr e, dm_expr *t)
{
  const dm_node *nd = &ctx->node[e];
  if (nd->op == DM_EXPR_POWI) {
    *t = nd->a;
    return nd->b;
  }
  *t = e;
  return 1;
}

/* a = f*x and b = f*y with a common non-constant factor f (products are
 * binary, so f is an operand of each): returns f and sets *x, *y. */
static dm_expr common_factor(const dm_expr_ctx *ctx, dm_expr a, dm_expr b,
                             dm_expr *x, dm_expr *y)
{
  const dm_node *na = &ctx->node[a], *nb = &ctx->node[b];
  if (na->op != DM_EXPR_MUL || nb->op != DM_EXPR_MUL)
    return DM_EXPR_NONE;
  double c;
  int32_t ao[2] = { na->a, na->b }, bo[2] = { nb->a, nb->b };
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++)
      if (ao[i] == bo[j] && !isc(ctx, ao[i], &c)) {
        *x = ao[1 - i];
        *y = bo[1 - j];
        return ao[i];
      }
  return DM_EXPR_NONE;
}

/* A node that prints with a leading minus: negative constant, -x, c*x with
 * c < 0, c/x with c < 0. */
static int negative_looking(const dm_expr_ctx *ctx, dm_expr e)
{
  const dm_node *nd = &ctx->node[e];
  double c;
  if (nd->op == DM_EXPR_NEG)
    return 1;
  if (isc(ctx, e, &c))
    return c < 0;
  if ((nd->op == DM_EXPR_MUL || nd->op == DM_EXPR_DIV) && isc(ctx, nd->a, &c))
    return c < 0;
  return 0;
}

dm_expr dm_expr_neg(dm_expr_ctx *ctx, dm_expr a)
{
  if (!check2(ctx, a, a))
    return DM_EXPR_NONE;
  const dm_node *nd = &ctx->node[a];
  double c;
  if (isc(ctx, a, &c))
    return K(-c);
  switch (nd->op) {
  case DM_EXPR_NEG:
    return nd->a;
  case DM_EXPR_SUB:
    return dm_expr_sub(ctx, nd->b, nd->a);
  case DM_EXPR_MUL:
    if (isc(ctx, nd->a, &c))
      return dm_expr_mul(ctx, K(-c), nd->b);
    break;
  default:
    break;
  }
  return cons(ctx, DM_EXPR_NEG, a, -1, -1);
}

dm_expr dm_expr_add(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (!check2(ctx, a, b))
    return DM_EXPR_NONE;
  double ca, cb;
  int ka = isc(ctx, a, &ca), kb = isc(ctx, b, &cb);
  if (ka && kb)
    return K(ca + cb);
  if (ka && ca == 0)
    return b;
  if (kb && cb == 0)
    return a;
  /* like terms */
  dm_expr ta, tb;
  ca = split_coef(ctx, a, &ta);
  cb = split_coef(ctx, b, &tb);
  if (ta == tb && !ka && !kb)
    return dm_expr_mul(ctx, K(ca + cb), ta);
  /* common constant factor: c*x + c*y -> c*(x + y), c*x - c*y likewise */
  if (!ka && !kb && (ca == cb || ca == -cb) && ca != 1 && ca != -1) {
    dm_expr s = ca == cb ? dm_expr_add(ctx, ta, tb) : dm_expr_sub(ctx, ta, tb);
    return dm_expr_mul(ctx, K(ca), s);
  }
  dm_expr f, fx, fy;
  if ((f = common_factor(ctx, a, b, &fx, &fy)) != DM_EXPR_NONE)
    return dm_expr_mul(ctx, f, dm_expr_add(ctx, fx, fy));
  /* x + (-y) -> x - y */
  if (negative_looking(ctx, b))
    return dm_expr_sub(ctx, a, dm_expr_neg(ctx, b));
  if (negative_looking(ctx, a))
    return dm_expr_sub(ctx, b, dm_expr_neg(ctx, a));
  if (ka) {                 /* constants last: x + 1 */
    dm_expr t = a;
    a = b;
    b = t;
  }
  return cons_comm(ctx, DM_EXPR_ADD, a, b);
}

dm_expr dm_expr_sub(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (!check2(ctx, a, b))
    return DM_EXPR_NONE;
  double ca, cb;
  int ka = isc(ctx, a, &ca), kb = isc(ctx, b, &cb);
  if (ka && kb)
    return K(ca - cb);
  if (kb && cb == 0)
    return a;
  if (ka && ca == 0)
    return dm_expr_neg(ctx, b);
  if (a == b)
    return K(0.0);
  if (ctx->node[a].op == DM_EXPR_NEG && !kb) {  /* -x - y -> -(x + y): the */
    dm_expr x = ctx->node[a].a;                 /* sign moves up where a   */
    return dm_expr_neg(ctx, dm_expr_add(ctx, x, b));  /* sum absorbs it   */
  }
  dm_expr ta, tb;
  ca = split_coef(ctx, a, &ta);
  cb = split_coef(ctx, b, &tb);
  if (ta == tb && !ka && !kb)
    return dm_expr_mul(ctx, K(ca - cb), ta);
  if (!ka && !kb && (ca == cb || ca == -cb) && ca != 1 && ca != -1) {
    dm_expr s = ca == cb ? dm_expr_sub(ctx, ta, tb) : dm_expr_add(ctx, ta, tb);
    return dm_expr_mul(ctx, K(ca), s);
  }
  dm_expr f, fx, fy;
  if ((f = common_factor(ctx, a, b, &fx, &fy)) != DM_EXPR_NONE)
    return dm_expr_mul(ctx, f, dm_expr_sub(ctx, fx, fy));
  if (negative_looking(ctx, b))
    return dm_expr_add(ctx, a, dm_expr_neg(ctx, b));
  return cons(ctx, DM_EXPR_SUB, a, b, -1);
}

dm_expr dm_expr_mul(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (!check2(ctx, a, b))
    return DM_EXPR_NONE;
  double ca, cb;
  if (isc(ctx, b, &cb) && !isc(ctx, a, &ca)) {   /* constant first */
    dm_expr t = a;
    a = b;
    b = t;
  }
  int ka = isc(ctx, a, &ca), kb = isc(ctx, b, &cb);
  if (ka && kb)
    return K(ca * cb);
  if (ka) {
    const dm_node *nb = &ctx->node[b];
    double c2;
    if (ca == 0)
      return K(0.0);
    if (ca == 1)
      return b;
    if ((nb->op == DM_EXPR_MUL || nb->op == DM_EXPR_DIV) && isc(ctx, nb->a, &c2)) {
      dm_expr t = nb->b, k = K(ca * c2);
      return nb->op == DM_EXPR_MUL ? dm_expr_mul(ctx, k, t)
                                   : dm_expr_div(ctx, k, t);
    }
    if (nb->op == DM_EXPR_NEG)
      return dm_expr_mul(ctx, K(-ca), nb->a);
    if (ca == -1)
      return dm_expr_neg(ctx, b);
    return cons(ctx, DM_EXPR_MUL, a, b, -1);
  }
  /* pull constant factors and signs to the front */
  dm_expr ta, tb;
  ca = split_coef(ctx, a, &ta);
  cb = split_coef(ctx, b, &tb);
  if (ca != 1 || cb != 1) {
    dm_expr k = K(ca * cb);
    return dm_expr_mul(ctx, k, dm_expr_mul(ctx, ta, tb));
  }
  /* x^m * x^n -> x^(m+n) */
  int na = split_pow(ctx, a, &ta), nb = split_pow(ctx, b, &tb);
  if (ta == tb && (long)na + nb != 0 && labs((long)na + nb) < INT32_MAX)
    return dm_expr_powi(ctx, ta, na + nb);
  return cons_comm(ctx, DM_EXPR_MUL, a, b);
}

/* 1/c is exact when c is a power of two (and 1/c does not overflow). */
static int exact_recip(double c)
{
  int ex;
  double m = frexp(c, &ex);
  return (m == 0.5 || m == -0.5) && isfinite(1.0 / c) && 1.0 / c != 0;
}

dm_expr dm_expr_div(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (!check2(ctx, a, b))
    return DM_EXPR_NONE;
  double ca, cb;
  int ka = isc(ctx, a, &ca), kb = isc(ctx, b, &cb);
  if (ka && kb)
    return K(ca / cb);
  if (kb) {
    if (cb == 1)
      return a;
    if (cb == -1)
      return dm_expr_neg(ctx, a);
    if (exact_recip(cb))
      return dm_expr_mul(ctx, K(1.0 / cb), a);
  }
  if (ka && ca == 0 && !kb)
    return K(0.0);
  if (ka && ca < 0) {       /* -c/x is -(c/x): negations cancel upwards */
    dm_expr k = K(-ca);
    return dm_expr_neg(ctx, dm_expr_div(ctx, k, b));
  }
  const dm_node *nb = &ctx->node[b];
  if (nb->op == DM_EXPR_NEG)
    return dm_expr_neg(ctx, dm_expr_div(ctx, a, nb->a));
  if (!ka) {
    dm_expr ta, tb;
    ca = split_coef(ctx, a, &ta);
    if (ca != 1) {          /* (c*x)/y -> c*(x/y), -x/y -> -(x/y) */
      dm_expr k = K(ca);
      return dm_expr_mul(ctx, k, dm_expr_div(ctx, ta, b));
    }
    if (!kb) {
      int na = split_pow(ctx, a, &ta), nbp = split_pow(ctx, b, &tb);
      if (ta == tb && (long)na - nbp != 0 && labs((long)na - nbp) < INT32_MAX)
        return dm_expr_powi(ctx, ta, na - nbp);
    }
  }
  return cons(ctx, DM_EXPR_DIV, a, b, -1);
}

/* x^n exactly as the tape and the native code compute it. */
double dm_expr__powi_value(double x, int n);
double dm_expr__powi_value(double x, int n)
{
  return dm_tape_powi(x, n);
}

dm_expr dm_expr_powi(dm_expr_ctx *ctx, dm_expr a, int n)
{
  if (!check2(ctx, a, a))
    return DM_EXPR_NONE;
  double c;
  if (n == 0)
    return K(1.0);
  if (n == 1)
    return a;
  if (isc(ctx, a, &c))
    return K(dm_expr__powi_value(c, n));
  const dm_node *nd = &ctx->node[a];
  if (nd->op == DM_EXPR_POWI) {
    long long m = (long long)nd->b * n;
    if (m > -INT32_MAX && m < INT32_MAX)
      return dm_expr_powi(ctx, nd->a, (int)m);
  }
  if (nd->op == DM_EXPR_NEG) {
    dm_expr p = dm_expr_powi(ctx, nd->a, n);
    return (n % 2 == 0) ? p : dm_expr_neg(ctx, p);
  }
  return cons(ctx, DM_EXPR_POWI, a, n, -1);
}

dm_expr dm_expr_pow(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (!check2(ctx, a, b))
    return DM_EXPR_NONE;
  double ca, cb;
  int ka = isc(ctx, a, &ca), kb = isc(ctx, b, &cb);
  if (ka && kb)
    return K(pow(ca, cb));
  if (kb) {
    if (cb == floor(cb) && fabs(cb) < 2147483647.0)
      return dm_expr_powi(ctx, a, (int)cb);
    if (cb == 0.5)
      return dm_expr_unary(ctx, DM_EXPR_SQRT, a);
  }
  if (ka && ca == 1)
    return K(1.0);
  return cons(ctx, DM_EXPR_POW, a, b, -1);
}

static double sign_of(double x)
{
  return x > 0 ? 1.0 : x < 0 ? -1.0 : x == 0 ? 0.0 : x;
}

/* The value of a unary op at a constant. */
double dm_expr__unary_value(int op, double x);
double dm_expr__unary_value(int op, double x)
{
  switch (op) {
  case DM_EXPR_NEG: return -x;
  case DM_EXPR_SQRT: return sqrt(x);
  case DM_EXPR_EXP: return exp(x);
  case DM_EXPR_LOG: return log(x);
  case DM_EXPR_SIN: return sin(x);
  case DM_EXPR_COS: return cos(x);
  case DM_EXPR_TAN: return tan(x);
  case DM_EXPR_ASIN: return asin(x);
  case DM_EXPR_ACOS: return acos(x);
  case DM_EXPR_ATAN: return atan(x);
  case DM_EXPR_SINH: return sinh(x);
  case DM_EXPR_COSH: return cosh(x);
  case DM_EXPR_TANH: return tanh(x);
  case DM_EXPR_ABS: return fabs(x);
  case DM_EXPR_SIGN: return sign_of(x);
  default: return NAN;
  }
}

/* The value of a binary op (not POWI) at constants. */
double dm_expr__binary_value(int op, double a, double b);
double dm_expr__binary_value(int op, double a, double b)
{
  switch (op) {
  case DM_EXPR_ADD: return a + b;
  case DM_EXPR_SUB: return a - b;
  case DM_EXPR_MUL: return a * b;
  case DM_EXPR_DIV: return a / b;
  case DM_EXPR_POW: return pow(a, b);
  case DM_EXPR_ATAN2: return atan2(a, b);
  case DM_EXPR_LT: return a < b;
  case DM_EXPR_LE: return a <= b;
  case DM_EXPR_GT: return a > b;
  case DM_EXPR_GE: return a >= b;
  case DM_EXPR_EQ: return a == b;
  case DM_EXPR_NE: return a != b;
  default: return NAN;
  }
}

dm_expr dm_expr_unary(dm_expr_ctx *ctx, int op, dm_expr a)
{
  if (op < DM_EXPR_NEG || op > DM_EXPR_SIGN)
    return dm_expr__fail(ctx, DM_EINVAL, "expression: %s is not a unary "
                         "operation", dm_expr_op_name(op));
  if (!check2(ctx, a, a))
    return DM_EXPR_NONE;
  if (op == DM_EXPR_NEG)
    return dm_expr_neg(ctx, a);
  double c;
  if (isc(ctx, a, &c))
    return K(dm_expr__unary_value(op, c));
  const dm_node *nd = &ctx->node[a];
  switch (op) {
  case DM_EXPR_ABS:
    if (nd->op == DM_EXPR_ABS)
      return a;
    if (nd->op == DM_EXPR_NEG)
      return dm_expr_unary(ctx, DM_EXPR_ABS, nd->a);
    break;
  case DM_EXPR_SQRT:        /* sqrt(x^2) = |x| exactly */
    if (nd->op == DM_EXPR_POWI && nd->b == 2)
      return dm_expr_unary(ctx, DM_EXPR_ABS, nd->a);
    break;
  case DM_EXPR_SIGN:
    if (nd->op == DM_EXPR_SIGN)
      return a;
    break;
  default:
    break;
  }
  return cons(ctx, op, a, -1, -1);
}

static dm_expr compare(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b)
{
  double ca, cb;
  if (isc(ctx, a, &ca) && isc(ctx, b, &cb))
    return K(dm_expr__binary_value(op, ca, cb));
  if (op == DM_EXPR_EQ || op == DM_EXPR_NE)
    return cons_comm(ctx, op, a, b);
  return cons(ctx, op, a, b, -1);
}

dm_expr dm_expr_binary(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b)
{
  if (op < DM_EXPR_ADD || op > DM_EXPR_NE)
    return dm_expr__fail(ctx, DM_EINVAL, "expression: %s is not a binary "
                         "operation", dm_expr_op_name(op));
  if (!check2(ctx, a, b))
    return DM_EXPR_NONE;
  switch (op) {
  case DM_EXPR_ADD: return dm_expr_add(ctx, a, b);
  case DM_EXPR_SUB: return dm_expr_sub(ctx, a, b);
  case DM_EXPR_MUL: return dm_expr_mul(ctx, a, b);
  case DM_EXPR_DIV: return dm_expr_div(ctx, a, b);
  case DM_EXPR_POW: return dm_expr_pow(ctx, a, b);
  case DM_EXPR_ATAN2: {
    double ca, cb;
    if (isc(ctx, a, &ca) && isc(ctx, b, &cb))
      return K(atan2(ca, cb));
    return cons(ctx, op, a, b, -1);
  }
  default:
    return compare(ctx, op, a, b);
  }
}

dm_expr dm_expr_select(dm_expr_ctx *ctx, dm_expr cond, dm_expr a, dm_expr b)
{
  if (!check2(ctx, cond, a) || !check2(ctx, a, b))
    return DM_EXPR_NONE;
  double c;
  if (isc(ctx, cond, &c))
    return c != 0 ? a : b;   /* NaN != 0: like the tape */
  if (a == b)
    return a;
  return cons(ctx, DM_EXPR_SELECT, cond, a, b);
}
