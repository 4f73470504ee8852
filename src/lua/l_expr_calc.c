/* l_expr_calc.c -- expression methods: derivatives, substitution,
 * evaluation, inspection; conversion of lists of expressions.  Part of the
 * expression binding (l_expr.c). */
#include <config.h>
#include <stdio.h>
#include <string.h>

#include "lua/l_expr.h"

/* {======================================================================
 * lists of expressions and of variables
 * ======================================================================= */

static dm_expr elem_expr(lua_State *L, const char *what, int k)
{
  dm_expr e = dm_lua_toexpr(L, -1);
  if (e == DM_EXPR_NONE)
    luaL_error(L, "%s: element %d is a %s, expression or number expected",
               what, k, luaL_typename(L, -1));
  return e;
}

size_t dm_lua_toexprs(lua_State *L, int idx, const char *what, dm_expr *out,
                      size_t max, size_t *rows, size_t *cols)
{
  idx = lua_absindex(L, idx);
  size_t r = 1, c = 0, cnt = 0;
  if (lua_type(L, idx) != LUA_TTABLE) {
    lua_pushvalue(L, idx);
    dm_expr e = elem_expr(L, what, 1);
    lua_pop(L, 1);
    if (out && max > 0)
      out[0] = e;
    cnt = 1;
  } else {
    size_t n = (size_t)luaL_len(L, idx);
    if (n == 0)
      luaL_error(L, "%s: empty list", what);
    lua_geti(L, idx, 1);
    int nested = lua_type(L, -1) == LUA_TTABLE && !luaL_testudata(L, -1, DM_EXPR_MT);
    lua_pop(L, 1);
    if (nested) {
      r = n;
      for (size_t i = 1; i <= n; i++) {
        if (lua_geti(L, idx, (lua_Integer)i) != LUA_TTABLE)
          luaL_error(L, "%s: row %d is a %s, list expected", what, (int)i,
                     luaL_typename(L, -1));
        size_t m = (size_t)luaL_len(L, -1);
        if (i == 1)
          c = m;
        if (m != c || m == 0)
          luaL_error(L, "%s: rows must have the same non-zero length", what);
        for (size_t j = 1; j <= m; j++) {
          lua_geti(L, -1, (lua_Integer)j);
          dm_expr e = elem_expr(L, what, (int)((i - 1) * m + j));
          lua_pop(L, 1);
          if (out && cnt < max)
            out[cnt] = e;
          cnt++;
        }
        lua_pop(L, 1);
      }
    } else {
      c = n;
      for (size_t i = 1; i <= n; i++) {
        lua_geti(L, idx, (lua_Integer)i);
        dm_expr e = elem_expr(L, what, (int)i);
        lua_pop(L, 1);
        if (out && cnt < max)
          out[cnt] = e;
        cnt++;
      }
    }
  }
  if (rows) *rows = r;
  if (cols) *cols = c;
  return cnt;
}

/* Push a buffer (userdata) with the expressions at idx; returns it. */
static dm_expr *exprs_arg(lua_State *L, int idx, const char *what, size_t *n,
                          size_t *rows, size_t *cols)
{
  *n = dm_lua_toexprs(L, idx, what, NULL, 0, rows, cols);
  dm_expr *v = lua_newuserdatauv(L, *n * sizeof *v, 0);
  dm_lua_toexprs(L, idx, what, v, *n, NULL, NULL);
  return v;
}

/* The symbol or parameter called name among the free variables of the
 * roots, else a new symbol. */
static dm_expr resolve_name(lua_State *L, size_t nroot, const dm_expr *roots,
                            const char *name)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  for (size_t r = 0; r < nroot; r++) {
    dm_expr fv[256];
    long k = dm_expr_free_vars(ctx, roots[r], fv, 256);
    for (long i = 0; i < k && i < 256; i++)
      if (strcmp(dm_expr_name(ctx, fv[i]), name) == 0)
        return fv[i];
  }
  return dm_expr_sym(ctx, name);
}

/* Variables to differentiate by at idx: a symbol, a name, or a list of
 * them (a symbolic vector); buffer pushed. */
static dm_expr *vars_arg(lua_State *L, int idx, size_t nroot,
                         const dm_expr *roots, size_t *n)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  int single = lua_type(L, idx) != LUA_TTABLE;
  *n = single ? 1 : (size_t)luaL_len(L, idx);
  if (*n == 0)
    luaL_argerror(L, idx, "empty list of variables");
  dm_expr *v = lua_newuserdatauv(L, *n * sizeof *v, 0);
  for (size_t i = 0; i < *n; i++) {
    if (single)
      lua_pushvalue(L, idx);
    else
      lua_geti(L, idx, (lua_Integer)i + 1);
    if (lua_type(L, -1) == LUA_TSTRING) {
      v[i] = resolve_name(L, nroot, roots, lua_tostring(L, -1));
      if (v[i] == DM_EXPR_NONE)        /* a bad name: raise now, or the */
        dm_lua_ctx_raise(L, ctx);      /* context's error stays pending */
    } else {
      dm_expr *u = luaL_testudata(L, -1, DM_EXPR_MT);
      int op = u ? dm_expr_kind(ctx, *u) : -1;
      if (op != DM_EXPR_SYM && op != DM_EXPR_PARAM)
        dm_argexpected(L, idx, "symbol, parameter, name or a list of them",
                       u ? dm_expr_op_name(op) : luaL_typename(L, -1));
      v[i] = *u;
    }
    lua_pop(L, 1);
  }
  return v;
}

/* {======================================================================
 * calculus, substitution, evaluation, inspection
 * ======================================================================= */

static int e_diff(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr(L, 1);
  lua_Integer times = luaL_optinteger(L, 3, 1);
  luaL_argcheck(L, times >= 0 && times <= 64, 3, "order out of range 0..64");
  lua_settop(L, 2);
  size_t n;
  dm_expr *x = vars_arg(L, 2, 1, &e, &n);
  luaL_argcheck(L, n == 1, 2, "one variable expected");
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  for (lua_Integer k = 0; k < times && e != DM_EXPR_NONE; k++)
    e = dm_expr_diff(ctx, e, x[0]);
  dm_lua_pushexpr(L, e);
  return 1;
}

static int e_grad(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr(L, 1);
  size_t n;
  dm_expr *x = vars_arg(L, 2, 1, &e, &n);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++) {
    dm_lua_pushexpr(L, dm_expr_diff(ctx, e, x[i]));
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

static int e_hessian(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr(L, 1);
  size_t n;
  dm_expr *x = vars_arg(L, 2, 1, &e, &n);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  dm_expr *H = lua_newuserdatauv(L, n * n * sizeof *H, 0);
  dm_err err;
  dm_err_clear(&err);
  if (dm_expr_hessian(ctx, e, n, x, H, &err) != DM_OK) {
    if (err.msg[0] == '\0')
      return dm_lua_ctx_raise(L, ctx);
    dm_expr_ctx_clear_err(ctx);
    return luaL_error(L, "%s", err.msg);
  }
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++) {
    lua_createtable(L, (int)n, 0);
    for (size_t j = 0; j < n; j++) {
      dm_lua_pushexpr(L, H[i * n + j]);
      lua_rawseti(L, -2, (lua_Integer)j + 1);
    }
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

/* dm.jacobian({f1, ..., fm}, vars) -> {{df1/dx1, ...}, ...} */
static int l_jacobian(lua_State *L)
{
  size_t m, n;
  dm_expr *f = exprs_arg(L, 1, "jacobian", &m, NULL, NULL);
  dm_expr *x = vars_arg(L, 2, m, f, &n);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  lua_createtable(L, (int)m, 0);
  for (size_t i = 0; i < m; i++) {
    lua_createtable(L, (int)n, 0);
    for (size_t j = 0; j < n; j++) {
      dm_lua_pushexpr(L, dm_expr_diff(ctx, f[i], x[j]));
      lua_rawseti(L, -2, (lua_Integer)j + 1);
    }
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

/* Bindings {key = value} at idx for the expression e: keys are names
 * (every free symbol/parameter of e so named) or expressions. */
typedef struct binding {
  size_t n;
  dm_expr *from;
  int nums;                 /* values must be numbers (eval) */
  dm_expr *to;
  double *val;
} binding;

static void bindings(lua_State *L, int idx, dm_expr e, binding *b)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  luaL_checktype(L, idx, LUA_TTABLE);
  long nfv = dm_expr_free_vars(ctx, e, NULL, 0);
  dm_expr *fv = lua_newuserdatauv(L, (size_t)(nfv + 1) * sizeof *fv, 0);
  dm_expr_free_vars(ctx, e, fv, (size_t)nfv);
  size_t cap = 0;
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    cap += lua_type(L, -2) == LUA_TSTRING ? (size_t)nfv : 1;
    lua_pop(L, 1);
  }
  b->from = lua_newuserdatauv(L, (cap + 1) * sizeof *b->from, 0);
  b->to = lua_newuserdatauv(L, (cap + 1) * sizeof *b->to, 0);
  b->val = lua_newuserdatauv(L, (cap + 1) * sizeof *b->val, 0);
  b->n = 0;
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    int isnum = lua_type(L, -1) == LUA_TNUMBER;
    dm_expr to = DM_EXPR_NONE;
    if (b->nums && !isnum) {
      const char *tn = luaL_typename(L, -1);   /* before dm_tolstring pushes */
      luaL_error(L, "eval: the value of %s is a %s, number expected",
                 dm_tolstring(L, -2, NULL), tn);
    }
    if (!b->nums && (to = dm_lua_toexpr(L, -1)) == DM_EXPR_NONE) {
      const char *tn = luaL_typename(L, -1);
      luaL_error(L, "subs: the value of %s is a %s, expression or number "
                 "expected", dm_tolstring(L, -2, NULL), tn);
    }
    if (lua_type(L, -2) == LUA_TSTRING) {
      const char *name = lua_tostring(L, -2);
      for (long i = 0; i < nfv; i++)
        if (strcmp(dm_expr_name(ctx, fv[i]), name) == 0) {
          b->from[b->n] = fv[i];
          b->to[b->n] = to;
          b->val[b->n++] = lua_tonumber(L, -1);
        }
    } else {
      dm_expr *k = luaL_testudata(L, -2, DM_EXPR_MT);
      if (k == NULL)
        luaL_error(L, "%s: keys must be names or expressions, got %s",
                   b->nums ? "eval" : "subs", luaL_typename(L, -2));
      if (b->nums && dm_expr_kind(ctx, *k) != DM_EXPR_SYM &&
          dm_expr_kind(ctx, *k) != DM_EXPR_PARAM)
        luaL_error(L, "eval: keys must be symbols, parameters or names");
      b->from[b->n] = *k;
      b->to[b->n] = to;
      b->val[b->n++] = lua_tonumber(L, -1);
    }
    lua_pop(L, 1);
  }
}

static int e_subs(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr(L, 1), r;
  binding b = { 0, NULL, 0, NULL, NULL };
  bindings(L, 2, e, &b);
  dm_err err;
  if (dm_expr_subs(dm_lua_exprctx(L), 1, &e, &r, b.n, b.from, b.to, &err) != DM_OK)
    return dm_lua_fail(L, "subs", err.status, &err);
  dm_lua_pushexpr(L, r);
  return 1;
}

static int e_eval(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr(L, 1);
  binding b = { 0, NULL, 1, NULL, NULL };
  if (lua_isnoneornil(L, 2))
    lua_newtable(L), lua_replace(L, 2);
  bindings(L, 2, e, &b);
  dm_err err;
  double r;
  if (dm_expr_eval(dm_lua_exprctx(L), 1, &e, &r, b.n, b.from, b.val, &err) != DM_OK)
    return luaL_error(L, "%s", err.msg);
  lua_pushnumber(L, r);
  return 1;
}

static int e_equals(lua_State *L)
{
  dm_expr a = dm_lua_checkexpr_only(L, 1), b = dm_lua_toexpr(L, 2);
  lua_pushboolean(L, a == b);
  return 1;
}

static int e_op(lua_State *L)
{
  lua_pushstring(L, dm_expr_op_name(dm_expr_kind(dm_lua_exprctx(L), dm_lua_checkexpr_only(L, 1))));
  return 1;
}

static int e_args(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr_only(L, 1);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  int k = dm_expr_nargs(ctx, e);
  lua_createtable(L, k, 0);
  for (int i = 0; i < k; i++) {
    dm_lua_pushexpr(L, dm_expr_arg(ctx, e, i));
    lua_rawseti(L, -2, i + 1);
  }
  if (dm_expr_kind(ctx, e) == DM_EXPR_POWI) {     /* x^n: the exponent too */
    lua_pushinteger(L, dm_expr_powi_exponent(ctx, e));
    lua_rawseti(L, -2, 2);
  }
  return 1;
}

static int e_name(lua_State *L)
{
  const char *s = dm_expr_name(dm_lua_exprctx(L), dm_lua_checkexpr_only(L, 1));
  if (s)
    lua_pushstring(L, s);
  else
    lua_pushnil(L);
  return 1;
}

static int e_value(lua_State *L)
{
  double x;
  if (dm_expr_is_const(dm_lua_exprctx(L), dm_lua_checkexpr_only(L, 1), &x))
    lua_pushnumber(L, x);
  else
    lua_pushnil(L);
  return 1;
}

static int e_free(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr_only(L, 1);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  long k = dm_expr_free_vars(ctx, e, NULL, 0);
  dm_expr *fv = lua_newuserdatauv(L, (size_t)(k + 1) * sizeof *fv, 0);
  dm_expr_free_vars(ctx, e, fv, (size_t)k);
  lua_createtable(L, (int)k, 0);
  for (long i = 0; i < k; i++) {
    dm_lua_pushexpr(L, fv[i]);
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

static int e_depends(lua_State *L)
{
  dm_expr e = dm_lua_checkexpr_only(L, 1);
  size_t n;
  dm_expr *x = vars_arg(L, 2, 1, &e, &n);
  lua_pushboolean(L, dm_expr_depends(dm_lua_exprctx(L), e, n, x));
  return 1;
}

/* {======================================================================
 * registration
 * ======================================================================= */

const dm_reg dm_lexpr_methods[] = {
  {"diff", e_diff, "e:diff(x[, n]) -> expr",
   "The derivative (n-th, default first) of e with respect to the symbol or parameter x (or its name)."},
  {"grad", e_grad, "e:grad(vars) -> {expr, ...}",
   "The gradient of e with respect to a list of symbols (a symbolic vector, names or symbols)."},
  {"hessian", e_hessian, "e:hessian(vars) -> {{expr, ...}, ...}",
   "The symmetric matrix of second derivatives of e (upper triangle derived, mirrored)."},
  {"subs", e_subs, "e:subs{x = value, [sym] = expr, ...} -> expr",
   "Replace symbols or parameters (by name or by expression) with numbers or expressions, simplifying again."},
  {"eval", e_eval, "e:eval{x = number, ...} -> number",
   "The value of e with its symbols and parameters set by name or by expression; unbound ones are an error."},
  {"equals", e_equals, "e:equals(f) -> boolean",
   "True when e and f are structurally the same expression (equal expressions are one shared node)."},
  {"op", e_op, "e:op() -> string",
   "The operation at the root of e: \"add\", \"mul\", \"sin\", \"sym\", \"const\", ..."},
  {"args", e_args, "e:args() -> {expr, ...}",
   "The operands of the root operation of e (for x^n with integer n: {x, n})."},
  {"name", e_name, "e:name() -> string | nil",
   "The name of a symbol or parameter, nil for anything else."},
  {"value", e_value, "e:value() -> number | nil",
   "The number of a constant expression, nil for anything else."},
  {"free", e_free, "e:free() -> {expr, ...}",
   "The symbols and parameters e depends on, in order of creation."},
  {"depends", e_depends, "e:depends(x | vars) -> boolean",
   "True when e contains the symbol x or any of the listed symbols."},
  {NULL, NULL, NULL, NULL}
};

const dm_reg dm_lexpr_calc_funcs[] = {
  {"jacobian", l_jacobian, "dm.jacobian({f1, ..., fm}, vars) -> {{expr, ...}, ...}",
   "The m-by-n matrix of derivatives df_i/dx_j of a list of expressions."},
  {NULL, NULL, NULL, NULL}
};
