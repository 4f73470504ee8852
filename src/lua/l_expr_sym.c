/* l_expr_sym.c -- symbols in Lua: dm.sym, dm.syms, dm.param, symbolic
 * vectors (dm.symvec, dm.paramvec: read-only proxy tables) and dm.trace,
 * which calls a function on symbolic arguments.  Part of the expression
 * binding (l_expr.c); see l_expr.h. */
#include <config.h>
#include <stdio.h>
#include <string.h>

#include "lua/l_expr.h"

#define SYMVEC_MT "dmech.symvec"
#define LABELS_KEY "dmech.symvec.labels"
#define SYMVEC_DATA_KEY "dmech.symvec.data"

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

/* Add the elements of the data table at data to b, separated by ", ". */
static void add_elements(lua_State *L, luaL_Buffer *b, int data)
{
  lua_Integer n = (lua_Integer)lua_rawlen(L, data);
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, data, i);
    dm_tolstring(L, -1, NULL);
    lua_remove(L, -2);
    luaL_addvalue(b);
    if (i < n)
      luaL_addstring(b, ", ");
  }
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
    luaL_buffinit(L, &b);
    add_elements(L, &b, data);
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
  add_elements(L, &b, data);
  luaL_addstring(&b, "}");
  luaL_pushresult(&b);
  return 1;
}

/* Replace the data table at the top by a new proxy of it labelled label. */
static void data_to_proxy(lua_State *L, const char *label)
{
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
  data_to_proxy(L, label);
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
  data_to_proxy(L, label);
  lua_setfield(L, pdata, name);                     /* parent.name = proxy */
  lua_pop(L, 1);
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

/* {======================================================================
 * dm.trace
 * ======================================================================= */

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
 * registration
 * ======================================================================= */

static const dm_reg sym_funcs[] = {
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
  {"trace", l_trace, "dm.trace(f, {spec, ...}) -> result, arg1, ...",
   "Call f with symbolic arguments (a spec is a list of names with optional label, fmt, kind=\"param\"; a count; a name; or a symbolic vector) and return what it computed as expressions, then the arguments."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_expr_sym(lua_State *L)
{
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
  dm_register(L, "dm.", sym_funcs);
}
