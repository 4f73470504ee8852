/* expr.c -- the expression context: node storage, hash-consing, names and
 * the simplifying constructors.  See expr.h for the contract. */
#include <config.h>
#include "expr/expr_impl.h"
#include "expr/tape.h"

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
  ctx->htag = malloc(ctx->hcap * sizeof *ctx->htag);
  ctx->ntab = malloc(ctx->ntcap * sizeof *ctx->ntab);
  if (ctx->htab == NULL || ctx->htag == NULL || ctx->ntab == NULL) {
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
  free(ctx->htag);
  free(ctx->ntab);
  free(ctx->memo);
  free(ctx->stamp);
  free(ctx->aux);
  free(ctx->stack);
  free(ctx->list);
  dm_expr__norm_free(ctx);
  free(ctx);
}

const dm_err *dm_expr_ctx_err(const dm_expr_ctx *ctx) { return &ctx->err; }
void dm_expr_ctx_clear_err(dm_expr_ctx *ctx) { dm_err_clear(&ctx->err); }
size_t dm_expr_ctx_size(const dm_expr_ctx *ctx) { return ctx->n; }

/* {==================================================================
 * hash-consing
 * =================================================================== */

static uint64_t node_hash(const dm_expr_ctx *ctx, int op, int32_t a,
                          int32_t b, int32_t c)
{
  uint64_t h = (uint64_t)op * 0x9e3779b97f4a7c15ULL;
  if (op == DM_EXPR_CONST)
    return dm_expr__mix64(h ^ dm_expr__dbits(ctx->cval[a]));
  h = dm_expr__mix64(h ^ (uint32_t)a);
  h = dm_expr__mix64(h ^ ((uint64_t)(uint32_t)b << 32 | (uint32_t)c));
  return h;
}

static int node_equal(const dm_expr_ctx *ctx, const dm_node *nd, int op,
                      int32_t a, int32_t b, int32_t c)
{
  if (nd->op != op)
    return 0;
  if (op == DM_EXPR_CONST)
    return dm_expr__dbits(ctx->cval[nd->a]) == dm_expr__dbits(ctx->cval[a]);
  return nd->a == a && nd->b == b && nd->c == c;
}

static int rehash(dm_expr_ctx *ctx)
{
  size_t cap = ctx->hcap * 2;
  int32_t *t = malloc(cap * sizeof *t);
  uint32_t *g = malloc(cap * sizeof *g);
  if (t == NULL || g == NULL) {
    free(t);
    free(g);
    return -1;
  }
  memset(t, 0xff, cap * sizeof *t);
  for (size_t i = 0; i < ctx->n; i++) {
    const dm_node *nd = &ctx->node[i];
    uint64_t h = node_hash(ctx, nd->op, nd->a, nd->b, nd->c);
    size_t j = h & (cap - 1);
    while (t[j] >= 0)
      j = (j + 1) & (cap - 1);
    t[j] = (int32_t)i;
    g[j] = (uint32_t)(h >> 32);
  }
  free(ctx->htab);
  free(ctx->htag);
  ctx->htab = t;
  ctx->htag = g;
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
  uint64_t h = node_hash(ctx, op, a, b, c);
  uint32_t tag = (uint32_t)(h >> 32);
  size_t j = h & mask;
  for (; ctx->htab[j] >= 0; j = (j + 1) & mask)   /* the tag spares a */
    if (ctx->htag[j] == tag &&                    /* look at the node */
        node_equal(ctx, &ctx->node[ctx->htab[j]], op, a, b, c))
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
  nd->len = 0;
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
  ctx->htag[j] = tag;
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
  uint64_t h = node_hash(ctx, op, a, b, c);
  uint32_t tag = (uint32_t)(h >> 32);
  for (size_t j = h & mask; ctx->htab[j] >= 0; j = (j + 1) & mask)
    if (ctx->htag[j] == tag && node_equal(ctx, &ctx->node[ctx->htab[j]], op, a, b, c))
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

dm_expr dm_expr__k(dm_expr_ctx *ctx, double x)
{
  return dm_expr_const(ctx, x);
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

/* x^n exactly as the tape and the native code compute it. */
double dm_expr__powi_value(double x, int n);
double dm_expr__powi_value(double x, int n)
{
  return dm_tape_powi(x, n);
}

dm_expr dm_expr_pow(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (!dm_expr__check2(ctx, a, b))
    return DM_EXPR_NONE;
  double ca, cb;
  int ka = dm_expr__isc(ctx, a, &ca), kb = dm_expr__isc(ctx, b, &cb);
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
double dm_expr_unary_value(int op, double x)
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
double dm_expr_binary_value(int op, double a, double b)
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
  if (!dm_expr__check2(ctx, a, a))
    return DM_EXPR_NONE;
  if (op == DM_EXPR_NEG)
    return dm_expr_neg(ctx, a);
  double c;
  if (dm_expr__isc(ctx, a, &c))
    return K(dm_expr_unary_value(op, c));
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
  if (dm_expr__isc(ctx, a, &ca) && dm_expr__isc(ctx, b, &cb))
    return K(dm_expr_binary_value(op, ca, cb));
  if (op == DM_EXPR_EQ || op == DM_EXPR_NE)
    return cons_comm(ctx, op, a, b);
  return cons(ctx, op, a, b, -1);
}

dm_expr dm_expr_binary(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b)
{
  if (op < DM_EXPR_ADD || op > DM_EXPR_NE)
    return dm_expr__fail(ctx, DM_EINVAL, "expression: %s is not a binary "
                         "operation", dm_expr_op_name(op));
  if (!dm_expr__check2(ctx, a, b))
    return DM_EXPR_NONE;
  switch (op) {
  case DM_EXPR_ADD: return dm_expr_add(ctx, a, b);
  case DM_EXPR_SUB: return dm_expr_sub(ctx, a, b);
  case DM_EXPR_MUL: return dm_expr_mul(ctx, a, b);
  case DM_EXPR_DIV: return dm_expr_div(ctx, a, b);
  case DM_EXPR_POW: return dm_expr_pow(ctx, a, b);
  case DM_EXPR_ATAN2: {
    double ca, cb;
    if (dm_expr__isc(ctx, a, &ca) && dm_expr__isc(ctx, b, &cb))
      return K(atan2(ca, cb));
    return cons(ctx, op, a, b, -1);
  }
  default:
    return compare(ctx, op, a, b);
  }
}

dm_expr dm_expr_select(dm_expr_ctx *ctx, dm_expr cond, dm_expr a, dm_expr b)
{
  if (!dm_expr__check2(ctx, cond, a) || !dm_expr__check2(ctx, a, b))
    return DM_EXPR_NONE;
  double c;
  if (dm_expr__isc(ctx, cond, &c))
    return c != 0 ? a : b;   /* NaN != 0: like the tape */
  if (a == b)
    return a;
  return cons(ctx, DM_EXPR_SELECT, cond, a, b);
}
