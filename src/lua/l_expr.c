/* l_expr.c -- symbolic expressions in Lua: dm.sym, arithmetic
 * metamethods, dm.sin..., comparisons for dm.select, calculus methods,
 * symbolic vectors, dm.trace.  Numbers stay numbers: dm.sin(0.5) is
 * math.sin(0.5); math.sin does not take expressions.  See l_expr.h. */
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
#define SYMVEC_MT "dmech.symvec"
#define LABELS_KEY "dmech.symvec.labels"
#define SYMVEC_DATA_KEY "dmech.symvec.data"
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

/* {======================================================================
 * symbols and symbolic vectors
 * ======================================================================= */

static int l_sym(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  dm_lua_pushexpr(L, dm_expr_sym(dm_lua_exprctx(L), name));
  return 1;
}

static int l_param(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  dm_lua_pushexpr(L, dm_expr_param(dm_lua_exprctx(L), name));
  return 1;
}

/* dm.syms "r theta z" -> r, theta, z */
static int l_syms(lua_State *L)
{
  const char *s = dm_checkcstring(L, 1);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  int n = 0;
  while (*s) {
    while (*s == ' ' || *s == '\t' || *s == ',' || *s == '\n')
      s++;
    const char *b = s;
    while (*s && *s != ' ' && *s != '\t' && *s != ',' && *s != '\n')
      s++;
    if (s > b) {
      lua_pushlstring(L, b, (size_t)(s - b));
      dm_expr e = dm_expr_sym(ctx, lua_tostring(L, -1));
      lua_pop(L, 1);
      luaL_checkstack(L, 1, "too many symbols");
      dm_lua_pushexpr(L, e);
      n++;
    }
  }
  if (n == 0)
    return luaL_argerror(L, 1, "no symbol names");
  return n;
}

static int lua_next_wrapper(lua_State *L)
{
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 2);
  if (lua_next(L, 1))
    return 2;
  lua_pushnil(L);
  return 1;
}

/* A symbolic vector is an empty proxy table; its elements live in a data
 * table (registry: proxy -> data, weak keys), so nothing can be assigned. */
static void push_symvec_data(lua_State *L, int proxy)
{
  lua_getfield(L, LUA_REGISTRYINDEX, SYMVEC_DATA_KEY);
  lua_pushvalue(L, proxy);
  lua_rawget(L, -2);
  lua_remove(L, -2);
}

static const char *symvec_label(lua_State *L, int proxy)
{
  const char *label = "vector";
  lua_getfield(L, LUA_REGISTRYINDEX, LABELS_KEY);
  lua_pushvalue(L, proxy);
  if (lua_rawget(L, -2) == LUA_TSTRING)
    label = lua_tostring(L, -1);      /* kept alive by the labels table */
  lua_pop(L, 2);
  return label;
}

int dm_lua_issymvec(lua_State *L, int idx)
{
  if (lua_type(L, idx) != LUA_TTABLE || !lua_getmetatable(L, idx))
    return 0;
  luaL_getmetatable(L, SYMVEC_MT);
  int is = lua_rawequal(L, -1, -2);
  lua_pop(L, 2);
  return is;
}

static int symvec_index(lua_State *L)
{
  push_symvec_data(L, 1);
  if (lua_type(L, -1) == LUA_TTABLE) {
    lua_pushvalue(L, 2);
    if (lua_rawget(L, -2) != LUA_TNIL)
      return 1;
    lua_pop(L, 1);
  }
  int data = lua_gettop(L);
  const char *label = symvec_label(L, 1);
  if (lua_type(L, 2) == LUA_TSTRING) {
    luaL_Buffer b;
    lua_Integer n = (lua_Integer)lua_rawlen(L, data);
    luaL_buffinit(L, &b);
    for (lua_Integer i = 1; i <= n; i++) {
      lua_rawgeti(L, data, i);
      dm_tolstring(L, -1, NULL);
      lua_remove(L, -2);
      luaL_addvalue(&b);
      if (i < n)
        luaL_addstring(&b, ", ");
    }
    luaL_pushresult(&b);
    return luaL_error(L, "no element '%s' in %s (elements: %s)",
                      lua_tostring(L, 2), label, lua_tostring(L, -1));
  }
  if (lua_isinteger(L, 2))
    return luaL_error(L, "index %d out of range 1..%d for %s",
                      (int)lua_tointeger(L, 2), (int)lua_rawlen(L, data), label);
  return luaL_error(L, "bad index into %s (number or name expected, got %s)",
                    label, luaL_typename(L, 2));
}

static int symvec_newindex(lua_State *L)
{
  return luaL_error(L, "a symbolic vector is read-only");
}

static int symvec_len(lua_State *L)
{
  push_symvec_data(L, 1);
  lua_pushinteger(L, (lua_Integer)lua_rawlen(L, -1));
  return 1;
}

static int symvec_pairs(lua_State *L)
{
  lua_pushcfunction(L, lua_next_wrapper);
  push_symvec_data(L, 1);
  lua_pushnil(L);
  return 3;
}

static int symvec_tostring(lua_State *L)
{
  push_symvec_data(L, 1);
  int data = lua_gettop(L);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  luaL_addstring(&b, symvec_label(L, 1));
  luaL_addstring(&b, "{");
  lua_Integer n = (lua_Integer)lua_rawlen(L, data);
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, data, i);
    dm_tolstring(L, -1, NULL);
    lua_remove(L, -2);
    luaL_addvalue(&b);
    if (i < n)
      luaL_addstring(&b, ", ");
  }
  luaL_addstring(&b, "}");
  luaL_pushresult(&b);
  return 1;
}

void dm_lua_pushsymvec(lua_State *L, const char *label, size_t n,
                       const char *const *elems, const char *fmt, int kind)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  lua_createtable(L, (int)n, (int)n);               /* data */
  for (size_t i = 0; i < n; i++) {
    char name[300];
    if (fmt != NULL && strstr(fmt, "%s") != NULL)
      snprintf(name, sizeof name, fmt, elems[i]);   /* fmt checked by caller */
    else
      snprintf(name, sizeof name, "%s", elems[i]);
    dm_lua_pushexpr(L, kind == DM_EXPR_PARAM ? dm_expr_param(ctx, name)
                                             : dm_expr_sym(ctx, name));
    lua_pushvalue(L, -1);
    lua_rawseti(L, -3, (lua_Integer)i + 1);
    lua_setfield(L, -2, elems[i]);
  }
  lua_newtable(L);                                  /* proxy */
  luaL_setmetatable(L, SYMVEC_MT);
  lua_getfield(L, LUA_REGISTRYINDEX, SYMVEC_DATA_KEY);
  lua_pushvalue(L, -2);
  lua_pushvalue(L, -4);
  lua_rawset(L, -3);
  lua_pop(L, 1);
  lua_getfield(L, LUA_REGISTRYINDEX, LABELS_KEY);
  lua_pushvalue(L, -2);
  lua_pushstring(L, label);
  lua_rawset(L, -3);
  lua_pop(L, 1);
  lua_remove(L, -2);                                /* leave the proxy */
}

void dm_lua_symvec_group(lua_State *L, int idx, const char *name, size_t first,
                         size_t count, const char *label)
{
  idx = lua_absindex(L, idx);
  push_symvec_data(L, idx);
  int pdata = lua_gettop(L);
  lua_createtable(L, (int)count, 0);               /* data */
  for (size_t i = 0; i < count; i++) {
    lua_rawgeti(L, pdata, (lua_Integer)(first + i) + 1);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  lua_newtable(L);                                  /* proxy */
  luaL_setmetatable(L, SYMVEC_MT);
  lua_getfield(L, LUA_REGISTRYINDEX, SYMVEC_DATA_KEY);
  lua_pushvalue(L, -2);
  lua_pushvalue(L, -4);
  lua_rawset(L, -3);
  lua_pop(L, 1);
  lua_getfield(L, LUA_REGISTRYINDEX, LABELS_KEY);
  lua_pushvalue(L, -2);
  lua_pushstring(L, label);
  lua_rawset(L, -3);
  lua_pop(L, 1);
  lua_setfield(L, pdata, name);                     /* parent.name = proxy */
  lua_pop(L, 2);
}

/* A format must contain exactly one %s and no other conversion. */
static const char *checkfmt(lua_State *L, int arg)
{
  const char *fmt = luaL_optstring(L, arg, "%s");
  const char *p = strchr(fmt, '%');
  if (p == NULL || p[1] != 's' || strchr(p + 2, '%') != NULL)
    luaL_argerror(L, arg, "format with exactly one %s expected");
  return fmt;
}

/* Element names from a table of strings or a count (label1..labelN). */
static size_t symvec_names(lua_State *L, int arg, const char *label,
                           const char ***names)
{
  size_t n;
  if (lua_isinteger(L, arg)) {
    lua_Integer k = lua_tointeger(L, arg);
    luaL_argcheck(L, k >= 1 && k <= 100000, arg, "size out of range");
    n = (size_t)k;
  } else {
    luaL_checktype(L, arg, LUA_TTABLE);
    n = lua_rawlen(L, arg);
    luaL_argcheck(L, n >= 1, arg, "non-empty list of names expected");
  }
  const char **v = lua_newuserdatauv(L, n * sizeof *v, 0);
  for (size_t i = 0; i < n; i++) {
    luaL_checkstack(L, 2, "too many names");
    if (lua_isinteger(L, arg)) {
      lua_pushfstring(L, "%s%d", label, (int)i + 1);
    } else if (lua_rawgeti(L, arg, (lua_Integer)i + 1) != LUA_TSTRING) {
      return (size_t)luaL_argerror(L, arg, lua_pushfstring(L, "name expected "
                                   "at index %d, got %s", (int)i + 1,
                                   luaL_typename(L, -1)));
    }
    v[i] = lua_tostring(L, -1);     /* kept alive by the stack until done */
  }
  *names = v;
  return n;
}

/* dm.symvec(label, names | n [, fmt]) */
static int l_symvec(lua_State *L)
{
  const char *label = dm_checkcstring(L, 1);
  const char *fmt = checkfmt(L, 3);
  lua_settop(L, 3);
  const char **names;
  size_t n = symvec_names(L, 2, label, &names);
  dm_lua_pushsymvec(L, label, n, names, fmt, DM_EXPR_SYM);
  return 1;
}

/* dm.paramvec(label, names) */
static int l_paramvec(lua_State *L)
{
  const char *label = dm_checkcstring(L, 1);
  lua_settop(L, 2);
  const char **names;
  size_t n = symvec_names(L, 2, label, &names);
  dm_lua_pushsymvec(L, label, n, names, NULL, DM_EXPR_PARAM);
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

/* Turn the traced result at the top into expressions (lists elementwise,
 * one level of nesting). */
static void result_to_exprs(lua_State *L)
{
  if (lua_type(L, -1) != LUA_TTABLE) {
    dm_lua_pushexpr(L, dm_lua_checkexpr(L, lua_gettop(L)));
    lua_replace(L, -2);
    return;
  }
  int t = lua_gettop(L);
  size_t n = (size_t)luaL_len(L, t);
  lua_createtable(L, (int)n, 0);
  for (size_t i = 1; i <= n; i++) {
    if (lua_geti(L, t, (lua_Integer)i) == LUA_TTABLE &&
        !luaL_testudata(L, -1, DM_EXPR_MT))
      result_to_exprs(L);
    else {
      dm_expr e = dm_lua_toexpr(L, -1);
      if (e == DM_EXPR_NONE)
        luaL_error(L, "trace: result %d is a %s, expression or number "
                   "expected", (int)i, luaL_typename(L, -1));
      lua_pop(L, 1);
      dm_lua_pushexpr(L, e);
    }
    lua_rawseti(L, -2, (lua_Integer)i);
  }
  lua_replace(L, t);
}

/* One argument of dm.trace from its spec at idx (pushed). */
static void trace_arg(lua_State *L, int idx, int k)
{
  static const char *const labels[] = { "x", "y", "z", "u", "w" };
  char label[16];
  snprintf(label, sizeof label, "%s", k <= 5 ? labels[k - 1] : "a");
  if (k > 5)
    snprintf(label, sizeof label, "a%d", k);
  if (lua_type(L, idx) == LUA_TSTRING) {
    dm_lua_pushexpr(L, dm_expr_sym(dm_lua_exprctx(L), lua_tostring(L, idx)));
  } else if (lua_isinteger(L, idx) ||
             (lua_type(L, idx) == LUA_TTABLE && !dm_lua_issymvec(L, idx))) {
    int kind = DM_EXPR_SYM;
    const char *fmt = NULL, *lab = label;
    if (lua_type(L, idx) == LUA_TTABLE) {
      lab = dm_optstringfield(L, idx, "label", label);
      fmt = dm_optstringfield(L, idx, "fmt", NULL);
      const char *kd = dm_optstringfield(L, idx, "kind", "sym");
      if (strcmp(kd, "param") == 0)
        kind = DM_EXPR_PARAM;
      else if (strcmp(kd, "sym") != 0)
        luaL_error(L, "trace: argument %d: kind must be 'sym' or 'param'", k);
      if (fmt != NULL) {
        const char *p = strchr(fmt, '%');
        if (p == NULL || p[1] != 's' || strchr(p + 2, '%') != NULL)
          luaL_error(L, "trace: argument %d: fmt needs exactly one %%s", k);
      }
    }
    int top = lua_gettop(L);
    const char **names;
    size_t n = symvec_names(L, idx, lab, &names);
    dm_lua_pushsymvec(L, lab, n, names, fmt, kind);
    lua_replace(L, top + 1);
    lua_settop(L, top + 1);
  } else if (lua_type(L, idx) == LUA_TTABLE || luaL_testudata(L, idx, DM_EXPR_MT)) {
    lua_pushvalue(L, idx);          /* a symbolic vector or an expression */
  } else {
    luaL_error(L, "trace: argument %d: names, a count, a symbolic vector or "
               "a symbol expected, got %s", k, luaL_typename(L, idx));
  }
}

/* dm.trace(f, {spec1, spec2, ...}) -> result, arg1, arg2, ... */
static int l_trace(lua_State *L)
{
  luaL_checktype(L, 1, LUA_TFUNCTION);
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  int n = (int)lua_rawlen(L, 2);
  luaL_checkstack(L, 2 * n + 8, "too many arguments");
  for (int k = 1; k <= n; k++) {          /* args at 3 .. n+2 */
    lua_rawgeti(L, 2, k);
    int spec = lua_gettop(L);
    trace_arg(L, spec, k);
    lua_replace(L, spec);
  }
  lua_pushvalue(L, 1);
  for (int k = 1; k <= n; k++)
    lua_pushvalue(L, 2 + k);
  dm_lua_trace(L, "the traced function", n);
  result_to_exprs(L);
  lua_insert(L, 3);                       /* result, then the arguments */
  return n + 1;
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
  {"sym", l_sym, "dm.sym(name) -> expr",
   "The symbol called name (the same name is always the same symbol)."},
  {"syms", l_syms, "dm.syms(\"r theta z\") -> r, theta, z",
   "Several symbols at once, from names separated by blanks or commas."},
  {"param", l_param, "dm.param(name) -> expr",
   "The parameter called name: a symbol whose value compiled functions take from their parameters."},
  {"symvec", l_symvec, "dm.symvec(label, {names} | n[, fmt]) -> symbolic vector",
   "A read-only vector of symbols reachable as q[2] and q.theta; symbol names follow fmt (default \"%s\", with n: label1..labeln)."},
  {"paramvec", l_paramvec, "dm.paramvec(label, {names}) -> symbolic vector",
   "A read-only vector of parameters reachable by index and by name."},
  {"expr", l_expr, "dm.expr(x) -> expr",
   "The expression of a number (or the expression itself)."},
  {"isexpr", l_isexpr, "dm.isexpr(x) -> boolean",
   "True when x is a symbolic expression."},
  {"trace", l_trace, "dm.trace(f, {spec, ...}) -> result, arg1, ...",
   "Call f with symbolic arguments (a spec is a list of names with optional label, fmt, kind=\"param\"; a count; a name; or a symbolic vector) and return what it computed as expressions, then the arguments."},
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
  luaL_newmetatable(L, SYMVEC_MT);
  lua_pushcfunction(L, symvec_index);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, symvec_newindex);
  lua_setfield(L, -2, "__newindex");
  lua_pushcfunction(L, symvec_len);
  lua_setfield(L, -2, "__len");
  lua_pushcfunction(L, symvec_pairs);
  lua_setfield(L, -2, "__pairs");
  lua_pushcfunction(L, symvec_tostring);
  lua_setfield(L, -2, "__tostring");
  lua_pushstring(L, "symvec");
  lua_setfield(L, -2, "__name");
  lua_pop(L, 1);
  lua_newtable(L);                                  /* symvec -> label */
  lua_createtable(L, 0, 1);
  lua_pushstring(L, "k");
  lua_setfield(L, -2, "__mode");
  lua_setmetatable(L, -2);
  lua_setfield(L, LUA_REGISTRYINDEX, LABELS_KEY);
  lua_newtable(L);                                  /* symvec -> data */
  lua_createtable(L, 0, 1);
  lua_pushstring(L, "k");
  lua_setfield(L, -2, "__mode");
  lua_setmetatable(L, -2);
  lua_setfield(L, LUA_REGISTRYINDEX, SYMVEC_DATA_KEY);
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
