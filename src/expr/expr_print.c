/* expr_print.c -- expressions as readable infix text with minimal
 * parentheses.  Iterative (explicit stack), so deep expressions are safe;
 * output is cut at a caller-given length because a DAG printed as a tree
 * can be exponentially long. */
#include <config.h>
#include "expr/expr_impl.h"
#include "core/numfmt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* {==================================================================
 * growable output
 * =================================================================== */

typedef struct sbuf {
  char *s;
  size_t len, cap, max;
  int cut, nomem;
} sbuf;

static void put(sbuf *b, const char *s)
{
  size_t k = strlen(s);
  if (b->cut || b->nomem)
    return;
  if (b->max && b->len + k > b->max) {
    k = b->max - b->len;
    b->cut = 1;
  }
  if (b->len + k + 4 > b->cap) {
    size_t cap = b->cap ? b->cap : 64;
    while (cap < b->len + k + 4)
      cap *= 2;
    char *p = realloc(b->s, cap);
    if (p == NULL) {
      b->nomem = 1;
      return;
    }
    b->s = p;
    b->cap = cap;
  }
  memcpy(b->s + b->len, s, k);
  b->len += k;
  b->s[b->len] = '\0';
  if (b->cut)
    memcpy(b->s + b->len, "...", 4);   /* room reserved above */
}

/* {==================================================================
 * precedence
 * =================================================================== */

enum { P_CMP = 0, P_ADD = 1, P_MUL = 2, P_UNARY = 3, P_POW = 4, P_ATOM = 5 };

/* Prints with a leading minus (follow the left spine of products). */
static int negative_looking(const dm_expr_ctx *ctx, dm_expr e)
{
  double c;
  while (ctx->node[e].op == DM_EXPR_MUL || ctx->node[e].op == DM_EXPR_DIV)
    e = ctx->node[e].a;
  if (ctx->node[e].op == DM_EXPR_NEG)
    return 1;
  return dm_expr_is_const(ctx, e, &c) && c < 0;
}

static int prec(const dm_expr_ctx *ctx, dm_expr e)
{
  const dm_node *nd = &ctx->node[e];
  switch (nd->op) {
  case DM_EXPR_CONST: {
    double c = ctx->cval[nd->a];
    return c < 0 ? P_UNARY : P_ATOM;
  }
  case DM_EXPR_ADD: case DM_EXPR_SUB: return P_ADD;
  case DM_EXPR_MUL: case DM_EXPR_DIV: return P_MUL;
  case DM_EXPR_NEG: return prec(ctx, nd->a) == P_MUL ? P_MUL : P_UNARY;
  case DM_EXPR_POW: case DM_EXPR_POWI: return P_POW;
  case DM_EXPR_LT: case DM_EXPR_LE: case DM_EXPR_GT: case DM_EXPR_GE:
  case DM_EXPR_EQ: case DM_EXPR_NE: return P_CMP;
  default: return P_ATOM;
  }
}

static const char *infix(int op)
{
  switch (op) {
  case DM_EXPR_ADD: return " + ";
  case DM_EXPR_SUB: return " - ";
  case DM_EXPR_MUL: return "*";
  case DM_EXPR_DIV: return "/";
  case DM_EXPR_POW: return "^";
  case DM_EXPR_LT: return " < ";
  case DM_EXPR_LE: return " <= ";
  case DM_EXPR_GT: return " > ";
  case DM_EXPR_GE: return " >= ";
  case DM_EXPR_EQ: return " == ";
  case DM_EXPR_NE: return " ~= ";
  default: return NULL;
  }
}

/* Least precedence an operand must have to go without parentheses. */
static void operand_req(int op, int *left, int *right)
{
  switch (op) {
  case DM_EXPR_ADD: *left = P_ADD; *right = P_ADD; break;
  case DM_EXPR_SUB: *left = P_ADD; *right = P_MUL; break;
  case DM_EXPR_MUL: *left = P_MUL; *right = P_MUL; break;
  case DM_EXPR_DIV: *left = P_MUL; *right = P_UNARY; break;
  case DM_EXPR_POW: *left = P_ATOM; *right = P_POW; break;
  default: *left = P_ADD; *right = P_ADD; break;   /* comparisons */
  }
}

/* {==================================================================
 * printer
 * =================================================================== */

typedef struct frame {
  int32_t e;
  uint8_t stage, parens;
} frame;

typedef struct fstack {
  frame *f;
  size_t n, cap;
} fstack;

static int push(fstack *st, const dm_expr_ctx *ctx, dm_expr e, int req,
                int right)
{
  if (st->n == st->cap) {
    size_t cap = st->cap ? 2 * st->cap : 64;
    frame *p = realloc(st->f, cap * sizeof *p);
    if (p == NULL)
      return -1;
    st->f = p;
    st->cap = cap;
  }
  frame *fr = &st->f[st->n++];
  fr->e = e;
  fr->stage = 0;
  fr->parens = prec(ctx, e) < req || (right && negative_looking(ctx, e));
  return 0;
}

/* Advance the top frame by one step; returns -1 when out of memory. */
static int step(fstack *st, const dm_expr_ctx *ctx, sbuf *b)
{
  frame *fr = &st->f[st->n - 1];
  const dm_node nd = ctx->node[fr->e];
  const char *op = infix(nd.op);
  int arity = dm_expr__arity(nd.op), l, r;
  char num[48];
  if (fr->stage == 0 && fr->parens)
    put(b, "(");
  if (arity == 0) {                                 /* leaf */
    if (nd.op == DM_EXPR_CONST) {
      dm_num_format(num, sizeof num, ctx->cval[nd.a]);
      put(b, num);
    } else {
      put(b, ctx->names[nd.a]);
    }
    goto done;
  }
  if (nd.op == DM_EXPR_POWI) {
    if (fr->stage == 0) {
      fr->stage = 1;
      return push(st, ctx, nd.a, P_ATOM, 0);
    }
    snprintf(num, sizeof num, "^%d", nd.b);
    put(b, num);
    goto done;
  }
  if (nd.op == DM_EXPR_NEG) {
    if (fr->stage == 0) {
      put(b, "-");
      fr->stage = 1;
      return push(st, ctx, nd.a, P_MUL, 1);
    }
    goto done;
  }
  if (op != NULL) {                                 /* infix binary */
    operand_req(nd.op, &l, &r);
    if (fr->stage == 0) {
      fr->stage = 1;
      return push(st, ctx, nd.a, l, 0);
    }
    if (fr->stage == 1) {
      put(b, op);
      fr->stage = 2;
      return push(st, ctx, nd.b, r, 1);
    }
    goto done;
  }
  /* function call */
  if (fr->stage == 0) {
    put(b, dm_expr_op_name(nd.op));
    put(b, "(");
  }
  if (fr->stage < arity) {
    int k = fr->stage++;
    if (k > 0)
      put(b, ", ");
    return push(st, ctx, k == 0 ? nd.a : k == 1 ? nd.b : nd.c, P_CMP, 0);
  }
  put(b, ")");
done:
  if (st->f[st->n - 1].parens)
    put(b, ")");
  st->n--;
  return 0;
}

char *dm_expr_to_string(dm_expr_ctx *ctx, dm_expr e, size_t max_len,
                        dm_err *err)
{
  if (!dm_expr__valid(ctx, e)) {
    dm_err_set(err, DM_EINVAL, "tostring: invalid expression handle");
    return NULL;
  }
  sbuf b = { NULL, 0, 0, max_len, 0, 0 };
  fstack st = { NULL, 0, 0 };
  put(&b, "");
  int bad = push(&st, ctx, e, P_CMP, 0);
  while (!bad && st.n > 0 && !b.cut && !b.nomem)
    bad = step(&st, ctx, &b);
  free(st.f);
  if (bad || b.nomem) {
    free(b.s);
    dm_err_set(err, DM_ENOMEM, "tostring: out of memory");
    return NULL;
  }
  return b.s;
}
