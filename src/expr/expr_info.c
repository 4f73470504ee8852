/* expr_info.c -- inspecting nodes, names of operations, building by
 * function name.  See expr.h. */
#include <config.h>
#include "expr/expr_impl.h"

#include <string.h>

/* {==================================================================
 * inspecting
 * =================================================================== */

int dm_expr_kind(const dm_expr_ctx *ctx, dm_expr e)
{
  return dm_expr__valid(ctx, e) ? ctx->node[e].op : -1;
}

int dm_expr_nargs(const dm_expr_ctx *ctx, dm_expr e)
{
  return dm_expr__valid(ctx, e) ? dm_expr__arity(ctx->node[e].op) : 0;
}

dm_expr dm_expr_arg(const dm_expr_ctx *ctx, dm_expr e, int k)
{
  if (!dm_expr__valid(ctx, e) || k < 0 || k >= dm_expr__arity(ctx->node[e].op))
    return DM_EXPR_NONE;
  return k == 0 ? ctx->node[e].a : k == 1 ? ctx->node[e].b : ctx->node[e].c;
}

int dm_expr_is_const(const dm_expr_ctx *ctx, dm_expr e, double *x)
{
  if (!dm_expr__valid(ctx, e) || ctx->node[e].op != DM_EXPR_CONST)
    return 0;
  if (x != NULL)
    *x = ctx->cval[ctx->node[e].a];
  return 1;
}

int dm_expr_powi_exponent(const dm_expr_ctx *ctx, dm_expr e)
{
  if (!dm_expr__valid(ctx, e) || ctx->node[e].op != DM_EXPR_POWI)
    return 0;
  return ctx->node[e].b;
}

const char *dm_expr_name(const dm_expr_ctx *ctx, dm_expr e)
{
  if (!dm_expr__valid(ctx, e))
    return NULL;
  const dm_node *nd = &ctx->node[e];
  if (nd->op != DM_EXPR_SYM && nd->op != DM_EXPR_PARAM)
    return NULL;
  return ctx->names[nd->a];
}

int dm_expr_has_sym(const dm_expr_ctx *ctx, dm_expr e)
{
  return dm_expr__valid(ctx, e) && (ctx->node[e].flags & DM_NF_SYM);
}

int dm_expr_has_param(const dm_expr_ctx *ctx, dm_expr e)
{
  return dm_expr__valid(ctx, e) && (ctx->node[e].flags & DM_NF_PARAM);
}

/* {==================================================================
 * names of operations and functions
 * =================================================================== */

static const char *const op_names[DM_EXPR_NOPS] = {
  "const", "sym", "param", "add", "sub", "mul", "div", "pow", "atan2",
  "lt", "le", "gt", "ge", "eq", "ne", "powi", "neg", "sqrt", "exp", "log",
  "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "abs",
  "sign", "select"
};

const char *dm_expr_op_name(int op)
{
  return (op >= 0 && op < DM_EXPR_NOPS) ? op_names[op] : "?";
}

int dm_expr_func_lookup(const char *fname, int *arity)
{
  if (fname == NULL)
    return -1;
  for (int op = DM_EXPR_ADD; op < DM_EXPR_NOPS; op++) {
    if (op == DM_EXPR_POWI)
      continue;
    if (strcmp(fname, op_names[op]) == 0) {
      if (arity != NULL)
        *arity = dm_expr__arity(op);
      return op;
    }
  }
  return -1;
}

dm_expr dm_expr_call(dm_expr_ctx *ctx, const char *fname, int nargs,
                     const dm_expr *args)
{
  int arity;
  int op = dm_expr_func_lookup(fname, &arity);
  if (op < 0)
    return dm_expr__fail(ctx, DM_ENOTFOUND, "expression: unknown function "
                         "'%s'", fname ? fname : "(null)");
  if (nargs != arity)
    return dm_expr__fail(ctx, DM_EINVAL, "expression: %s expects %d "
                         "argument%s, got %d", fname, arity,
                         arity == 1 ? "" : "s", nargs);
  switch (arity) {
  case 1: return dm_expr_unary(ctx, op, args[0]);
  case 2: return dm_expr_binary(ctx, op, args[0], args[1]);
  default: return dm_expr_select(ctx, args[0], args[1], args[2]);
  }
}
