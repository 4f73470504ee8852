/* l_expr.c -- symbolic expressions in Lua: the context, arithmetic
 * metamethods, dm.sin..., comparisons for dm.select, tracing, and the
 * opener of the expression binding.  Numbers stay numbers: dm.sin(0.5) is
 * math.sin(0.5); math.sin does not take expressions.  Symbols, symbolic
 * vectors and dm.trace: l_expr_sym.c; calculus: l_expr_calc.c; dm.fn:
 * l_expr_fn.c.  See l_expr.h. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lua/l_expr.h"
#include "expr/native.h"

/* The registry slot holding the context box and the box's metatable must
 * have different names: luaL_newmetatable stores the metatable in the
 * registry under its name, so one name for both made __gc's type check
 * fail at lua_close and leaked the whole context. */
#define CTX_KEY "dmech.exprctx"
#define CTX_MT "dmech.exprctx.mt"
#define TRACING_KEY "dmech.expr.tracing"
#define DM_KEY "dmech.expr.dm"
#define PRINT_MAX 100000

/* {======================================================================
 * context and conversions
 * ======================================================================= */

typedef struct ctxbox {
  dm_expr_ctx *ctx;
} ctxbox;

static int ctx_gc(lua_State *L)
{
  ctxbox *b = luaL_checkudata(L, 1, CTX_MT);
  dm_expr_ctx_free(b->ctx);
  b->ctx = NULL;
  return 0;
}

dm_expr_ctx *dm_lua_exprctx(lua_State *L)
{
  ctxbox *b;
  if (lua_getfield(L, LUA_REGISTRYINDEX, CTX_KEY) == LUA_TUSERDATA) {
    b = lua_touserdata(L, -1);
    lua_pop(L, 1);
    if (b->ctx != NULL)
      return b->ctx;
    luaL_error(L, "the expression context is closed");
  }
  lua_pop(L, 1);
  b = lua_newuserdatauv(L, sizeof *b, 0);
  b->ctx = NULL;
  if (luaL_newmetatable(L, CTX_MT)) {
    lua_pushcfunction(L, ctx_gc);
    lua_setfield(L, -2, "__gc");
  }
  lua_setmetatable(L, -2);
  b->ctx = dm_expr_ctx_alloc();
  if (b->ctx == NULL)
    luaL_error(L, "out of memory");
  lua_setfield(L, LUA_REGISTRYINDEX, CTX_KEY);
  return b->ctx;
}

dm_expr dm_lua_toexpr(lua_State *L, int idx)
{
  dm_expr *u = luaL_testudata(L, idx, DM_EXPR_MT);
  if (u != NULL)
    return *u;
  if (lua_type(L, idx) == LUA_TNUMBER) {
    dm_expr_ctx *ctx = dm_lua_exprctx(L);
    dm_expr e = dm_expr_const(ctx, lua_tonumber(L, idx));
    if (e == DM_EXPR_NONE)        /* out of memory, not a wrong operand */
      dm_lua_ctx_raise(L, ctx);
    return e;
  }
  return DM_EXPR_NONE;
}

dm_expr dm_lua_checkexpr(lua_State *L, int idx)
{
  dm_expr e = dm_lua_toexpr(L, idx);
  if (e == DM_EXPR_NONE)
    dm_argexpected(L, idx, "expression or number", luaL_typename(L, idx));
  return e;
}

/* Raise the context's error (and clear it). */
int dm_lua_ctx_raise(lua_State *L, dm_expr_ctx *ctx)
{
  char msg[DM_ERRMSG_MAX];
  const dm_err *e = dm_expr_ctx_err(ctx);
  snprintf(msg, sizeof msg, "%s", e->msg[0] ? e->msg : "expression: failed");
  dm_expr_ctx_clear_err(ctx);
  return luaL_error(L, "%s", msg);
}

void dm_lua_pushexpr(lua_State *L, dm_expr e)
{
  if (e == DM_EXPR_NONE)
    dm_lua_ctx_raise(L, dm_lua_exprctx(L));
  dm_expr *u = lua_newuserdatauv(L, sizeof *u, 0);
  *u = e;
  luaL_setmetatable(L, DM_EXPR_MT);
}

dm_expr dm_lua_checkexpr_only(lua_State *L, int idx)
{
  return *(dm_expr *)luaL_checkudata(L, idx, DM_EXPR_MT);
}

/* {======================================================================
 * arithmetic and the comparison trap
 * ======================================================================= */

static int arith(lua_State *L, const char *opname, int op)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  dm_expr a = dm_lua_toexpr(L, 1), b = dm_lua_toexpr(L, 2);
  if (a == DM_EXPR_NONE || b == DM_EXPR_NONE) {
    int bad = a == DM_EXPR_NONE ? 1 : 2;
    return luaL_error(L, "bad operand to '%s' (expression or number expected, "
                      "got %s)", opname, luaL_typename(L, bad));
  }
  dm_lua_pushexpr(L, op == DM_EXPR_NEG ? dm_expr_neg(ctx, a)
                                       : dm_expr_binary(ctx, op, a, b));
  return 1;
}

static int m_add(lua_State *L) { return arith(L, "+", DM_EXPR_ADD); }
static int m_sub(lua_State *L) { return arith(L, "-", DM_EXPR_SUB); }
static int m_mul(lua_State *L) { return arith(L, "*", DM_EXPR_MUL); }
static int m_div(lua_State *L) { return arith(L, "/", DM_EXPR_DIV); }
static int m_pow(lua_State *L) { return arith(L, "^", DM_EXPR_POW); }
static int m_unm(lua_State *L) { return arith(L, "-", DM_EXPR_NEG); }

static int m_unsupported(lua_State *L)
{
  return luaL_error(L, "operators %%, // and bitwise operators are not "
                    "defined for expressions");
}

/* `if x < 0` on an expression: there is no truth value to branch on.
 * Two branches on symbolic values cannot be caught at all: Lua decides
 * `x == 0` (an expression and a number) as false without calling __eq,
 * and `if x then` is true for any userdata.  The message says so, since
 * whoever meets this error may have written those too. */
static int branch_error(lua_State *L, const char *op, const char *fn)
{
  const char *what = NULL;
  if (lua_getfield(L, LUA_REGISTRYINDEX, TRACING_KEY) == LUA_TSTRING)
    what = lua_tostring(L, -1);
  return luaL_error(L, "branch on a symbolic value ('%s' on an expression)%s%s:"
                    " an expression has no truth value; use "
                    "dm.select(dm.%s(a, b), x, y) for a piecewise definition "
                    "(beware: 'x == 0' with a number is silently false and "
                    "'if x then' silently true while tracing; they need "
                    "dm.select too)",
                    op, what ? " in " : "", what ? what : "", fn);
}

static int m_lt(lua_State *L) { return branch_error(L, "<", "lt"); }
static int m_le(lua_State *L) { return branch_error(L, "<=", "le"); }
static int m_eq(lua_State *L) { return branch_error(L, "==", "eq"); }

static int m_tostring(lua_State *L)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  dm_err err;
  char *s = dm_expr_to_string(ctx, dm_lua_checkexpr_only(L, 1), PRINT_MAX, &err);
  if (s == NULL)
    return dm_lua_fail(L, "tostring", err.status, &err);
  lua_pushstring(L, s);
  free(s);
  return 1;
}

static int m_concat(lua_State *L)
{
  for (int i = 1; i <= 2; i++)
    if (luaL_testudata(L, i, DM_EXPR_MT)) {
      lua_pushcfunction(L, m_tostring);
      lua_pushvalue(L, i);
      lua_call(L, 1, 1);
      lua_replace(L, i);
    } else if (!lua_isstring(L, i)) {
      return luaL_error(L, "attempt to concatenate a %s value", luaL_typename(L, i));
    }
  lua_concat(L, 2);
  return 1;
}

/* {======================================================================
 * functions: numbers in, numbers out; expressions in, expressions out
 * ======================================================================= */

static int unary(lua_State *L, int op)
{
  const char *name = dm_expr_op_name(op);
  if (lua_gettop(L) != 1)
    return luaL_error(L, "dm.%s expects 1 argument, got %d", name, lua_gettop(L));
  if (lua_type(L, 1) == LUA_TNUMBER) {
    lua_pushnumber(L, dm_expr_unary_value(op, lua_tonumber(L, 1)));
    return 1;
  }
  dm_expr a = dm_lua_checkexpr(L, 1);
  dm_lua_pushexpr(L, dm_expr_unary(dm_lua_exprctx(L), op, a));
  return 1;
}

#define UNARY(fn, op) static int l_##fn(lua_State *L) { return unary(L, op); }
UNARY(sqrt, DM_EXPR_SQRT) UNARY(exp, DM_EXPR_EXP) UNARY(log, DM_EXPR_LOG)
UNARY(sin, DM_EXPR_SIN) UNARY(cos, DM_EXPR_COS) UNARY(tan, DM_EXPR_TAN)
UNARY(asin, DM_EXPR_ASIN) UNARY(acos, DM_EXPR_ACOS) UNARY(atan, DM_EXPR_ATAN)
UNARY(sinh, DM_EXPR_SINH) UNARY(cosh, DM_EXPR_COSH) UNARY(tanh, DM_EXPR_TANH)
UNARY(abs, DM_EXPR_ABS) UNARY(sign, DM_EXPR_SIGN)

static int numeric_args(lua_State *L, int n)
{
  for (int i = 1; i <= n; i++)
    if (lua_type(L, i) != LUA_TNUMBER)
      return 0;
  return 1;
}

static int binary(lua_State *L, int op)
{
  const char *name = dm_expr_op_name(op);
  if (lua_gettop(L) != 2)
    return luaL_error(L, "dm.%s expects 2 arguments, got %d", name, lua_gettop(L));
  if (numeric_args(L, 2)) {
    double r = dm_expr_binary_value(op, lua_tonumber(L, 1), lua_tonumber(L, 2));
    if (op >= DM_EXPR_LT && op <= DM_EXPR_NE)
      lua_pushboolean(L, r != 0.0);   /* comparisons of numbers are booleans */
    else
      lua_pushnumber(L, r);
    return 1;
  }
  dm_expr a = dm_lua_checkexpr(L, 1), b = dm_lua_checkexpr(L, 2);
  dm_lua_pushexpr(L, dm_expr_binary(dm_lua_exprctx(L), op, a, b));
  return 1;
}

#define BINARY(fn, op) static int l_##fn(lua_State *L) { return binary(L, op); }
BINARY(atan2, DM_EXPR_ATAN2) BINARY(pow, DM_EXPR_POW) BINARY(lt, DM_EXPR_LT)
BINARY(le, DM_EXPR_LE) BINARY(gt, DM_EXPR_GT) BINARY(ge, DM_EXPR_GE)
BINARY(eq, DM_EXPR_EQ) BINARY(ne, DM_EXPR_NE)

/* dm.select(cond, a, b): cond a boolean, a number (nonzero is true) or a
 * comparison expression. */
static int l_select(lua_State *L)
{
  if (lua_gettop(L) != 3)
    return luaL_error(L, "dm.select expects 3 arguments, got %d", lua_gettop(L));
  if (lua_type(L, 1) == LUA_TBOOLEAN || lua_type(L, 1) == LUA_TNUMBER) {
    int c = lua_type(L, 1) == LUA_TBOOLEAN ? lua_toboolean(L, 1)
                                           : lua_tonumber(L, 1) != 0;
    dm_lua_checkexpr(L, 2);
    dm_lua_checkexpr(L, 3);
    lua_pushvalue(L, c ? 2 : 3);
    return 1;
  }
  dm_expr c = dm_lua_checkexpr(L, 1), a = dm_lua_checkexpr(L, 2);
  dm_expr b = dm_lua_checkexpr(L, 3);
  dm_lua_pushexpr(L, dm_expr_select(dm_lua_exprctx(L), c, a, b));
  return 1;
}

/* dm.apply(name, args...): a function by name, for generated code. */
static int l_apply(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  int n = lua_gettop(L) - 1;
  dm_expr args[3] = { DM_EXPR_NONE, DM_EXPR_NONE, DM_EXPR_NONE };
  for (int i = 0; i < n && i < 3; i++)
    args[i] = dm_lua_checkexpr(L, i + 2);
  dm_lua_pushexpr(L, dm_expr_call(dm_lua_exprctx(L), name, n, args));
  return 1;
}

static int l_expr(lua_State *L)
{
  dm_lua_pushexpr(L, dm_lua_checkexpr(L, 1));
  return 1;
}

static int l_isexpr(lua_State *L)
{
  lua_pushboolean(L, luaL_testudata(L, 1, DM_EXPR_MT) != NULL);
  return 1;
}

/* {======================================================================
 * tracing
 * ======================================================================= */

void dm_lua_trace(lua_State *L, const char *what, int nargs)
{
  lua_pushstring(L, what);
  lua_setfield(L, LUA_REGISTRYINDEX, TRACING_KEY);
  int s = lua_pcall(L, nargs, 1, 0);
  lua_pushnil(L);
  lua_setfield(L, LUA_REGISTRYINDEX, TRACING_KEY);
  if (s != LUA_OK)
    lua_error(L);           /* the message already names the place */
}

/* {======================================================================
 * configuration and registration
 * ======================================================================= */

int dm_lua_native_mode(lua_State *L)
{
  int top = lua_gettop(L), mode = DM_NATIVE_AUTO;
  if (lua_getfield(L, LUA_REGISTRYINDEX, DM_KEY) == LUA_TTABLE &&
      lua_getfield(L, -1, "config") == LUA_TTABLE &&
      lua_getfield(L, -1, "native") != LUA_TNIL) {
    const char *s = lua_tostring(L, -1);
    mode = s ? dm_native_mode_parse(s) : -1;
    if (mode < 0)
      luaL_error(L, "dm.config.native must be \"auto\", \"wait\", \"always\" or "
                 "\"never\" (got %s)", dm_tolstring(L, -1, NULL));
  }
  lua_settop(L, top);
  return mode;
}

static const luaL_Reg expr_meta[] = {
  {"__add", m_add}, {"__sub", m_sub}, {"__mul", m_mul}, {"__div", m_div},
  {"__pow", m_pow}, {"__unm", m_unm}, {"__mod", m_unsupported},
  {"__idiv", m_unsupported}, {"__band", m_unsupported},
  {"__bor", m_unsupported}, {"__bxor", m_unsupported},
  {"__shl", m_unsupported}, {"__shr", m_unsupported},
  {"__bnot", m_unsupported}, {"__lt", m_lt}, {"__le", m_le}, {"__eq", m_eq},
  {"__tostring", m_tostring}, {"__concat", m_concat},
  {NULL, NULL}
};

static const dm_reg expr_funcs[] = {
  {"expr", l_expr, "dm.expr(x) -> expr",
   "The expression of a number (or the expression itself)."},
  {"isexpr", l_isexpr, "dm.isexpr(x) -> boolean",
   "True when x is a symbolic expression."},
  {"sqrt", l_sqrt, "dm.sqrt(x)", "Square root of a number or expression." },
  {"exp", l_exp, "dm.exp(x)", "Exponential of a number or expression; math.exp does not take expressions."},
  {"log", l_log, "dm.log(x)", "Natural logarithm of a number or expression; math.log does not take expressions."},
  {"sin", l_sin, "dm.sin(x)", "Sine of a number or expression; math.sin does not take expressions."},
  {"cos", l_cos, "dm.cos(x)", "Cosine of a number or expression; math.cos does not take expressions."},
  {"tan", l_tan, "dm.tan(x)", "Tangent of a number or expression; math.tan does not take expressions."},
  {"asin", l_asin, "dm.asin(x)", "Arc sine of a number or expression; math.asin does not take expressions."},
  {"acos", l_acos, "dm.acos(x)", "Arc cosine of a number or expression; math.acos does not take expressions."},
  {"atan", l_atan, "dm.atan(x)", "Arc tangent of a number or expression (one argument; see dm.atan2)."},
  {"atan2", l_atan2, "dm.atan2(y, x)", "The angle of the point (x, y), for numbers or expressions."},
  {"sinh", l_sinh, "dm.sinh(x)", "Hyperbolic sine of a number or expression."},
  {"cosh", l_cosh, "dm.cosh(x)", "Hyperbolic cosine of a number or expression."},
  {"tanh", l_tanh, "dm.tanh(x)", "Hyperbolic tangent of a number or expression."},
  {"abs", l_abs, "dm.abs(x)", "Absolute value of a number or expression; math.abs does not take expressions."},
  {"sign", l_sign, "dm.sign(x)", "The sign of a number or expression: -1, 0 or 1."},
  {"pow", l_pow, "dm.pow(x, y)", "The power x^y of numbers or expressions (the same as the ^ operator)."},
  {"select", l_select, "dm.select(cond, a, b)",
   "The value a where cond holds, else b: piecewise expressions (cond from dm.lt, dm.le, ...; a boolean or number picks at once)."},
  {"apply", l_apply, "dm.apply(name, x[, y[, z]]) -> expr",
   "Apply an operation by name (\"sin\", \"atan2\", \"select\", \"lt\", ...) to expressions or numbers."},
  {"lt", l_lt, "dm.lt(a, b)", "The condition a < b for dm.select (a boolean for two numbers)."},
  {"le", l_le, "dm.le(a, b)", "The condition a <= b for dm.select (a boolean for two numbers)."},
  {"gt", l_gt, "dm.gt(a, b)", "The condition a > b for dm.select (a boolean for two numbers)."},
  {"ge", l_ge, "dm.ge(a, b)", "The condition a >= b for dm.select (a boolean for two numbers)."},
  {"eq", l_eq, "dm.eq(a, b)", "The condition a == b for dm.select (a boolean for two numbers)."},
  {"ne", l_ne, "dm.ne(a, b)", "The condition a ~= b for dm.select (a boolean for two numbers)."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_expr(lua_State *L)
{
  int dm = lua_gettop(L);
  dm_newclass(L, DM_EXPR_MT, "expr", dm_lexpr_methods, expr_meta);
  lua_pop(L, 1);
  dm_open_expr_sym(L);                              /* dm.sym ... dm.trace */
  lua_pushvalue(L, dm);
  lua_setfield(L, LUA_REGISTRYINDEX, DM_KEY);
  dm_register(L, "dm.", expr_funcs);
  dm_register(L, "dm.", dm_lexpr_calc_funcs);
  if (lua_getfield(L, dm, "config") != LUA_TTABLE) {
    lua_pop(L, 1);
    lua_newtable(L);
    lua_pushvalue(L, -1);
    lua_setfield(L, dm, "config");
  }
  if (lua_getfield(L, -1, "native") == LUA_TNIL) {
    lua_pushstring(L, "auto");
    lua_setfield(L, -3, "native");
  }
  lua_pop(L, 2);
  dm_open_expr_fn(L);
}
