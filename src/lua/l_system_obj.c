/* l_system_obj.c -- the System object seen from Lua: conversion methods
 * (energy, momentum, velocity, ...), parameters (sys:set, the sys.params
 * proxy), fields (names, flags, the expressions L, dLdq, ... as printable
 * values) and __tostring.  The constructor is in l_system.c. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_system.h"
#include "lua/l_expr.h"

#define PARAMS_MT "dmech.params"

/* The params proxy: a userdata pointing at its system (anchored in the
 * proxy's user value).  Stored as the system's user value 1. */
void dm_lsystem_push_params(lua_State *L, int sys)
{
  dm_lsystem **pp;
  sys = lua_absindex(L, sys);
  pp = lua_newuserdatauv(L, sizeof *pp, 1);
  *pp = lua_touserdata(L, sys);
  luaL_setmetatable(L, PARAMS_MT);
  lua_pushvalue(L, sys);
  lua_setiuservalue(L, -2, 1);
  lua_setiuservalue(L, sys, 1);
}

/* {======================================================================
 * methods: conversions
 * ======================================================================= */

static dm_lsystem *checksys(lua_State *L)
{
  return dm_lua_checksystem(L, 1);
}

/* The state table {q=, v=} | {q=, p=} at argument 2 (v wins when both are
 * given): q into ls->buf, v into buf + n (from p by the Legendre solve),
 * and p into buf + 2n when the state gives it (returns 1, else 0). */
static int read_state(lua_State *L, dm_lsystem *ls, const char *fname)
{
  char what[64];
  double *q = ls->buf, *v = q + ls->n, *p = v + ls->n;
  int has_v, has_p;
  dm_err e;
  int st;
  if (lua_type(L, 2) != LUA_TTABLE || lua_rawlen(L, 2) > 0)
    luaL_error(L, "%s: a state {q=, v=} or {q=, p=} expected, got %s (sys:%s(q, v) is written "
               "sys:%s{q = q, v = v})", fname, lua_type(L, 2) == LUA_TTABLE ? "a list"
               : luaL_typename(L, 2), fname, fname);
  lua_settop(L, 3);
  if (lua_getfield(L, 2, "q") == LUA_TNIL)
    luaL_error(L, "%s: the state needs q", fname);
  snprintf(what, sizeof what, "%s: state.q", fname);
  dm_lua_system_readvec(L, ls, -1, what, q);
  has_v = lua_getfield(L, 2, "v") != LUA_TNIL;
  has_p = lua_getfield(L, 2, "p") != LUA_TNIL;
  if (!has_v && !has_p)
    luaL_error(L, "%s: the state needs v or p", fname);
  if (has_p) {
    snprintf(what, sizeof what, "%s: state.p", fname);
    dm_lua_system_readvec(L, ls, -1, what, p);
  }
  if (has_v) {
    snprintf(what, sizeof what, "%s: state.v", fname);
    dm_lua_system_readvec(L, ls, -2, what, v);
  } else if ((st = dm_integrator_velocity(ls->conv, q, p, v, 0, &e)) != DM_OK) {
    dm_lua_fail(L, fname, st, &e);
  }
  lua_settop(L, 3);
  return has_p;
}

static int s_momentum(lua_State *L)
{
  dm_lsystem *ls = checksys(L);
  double *p = ls->buf + 2 * ls->n;
  dm_err e;
  int st;
  if (!read_state(L, ls, "momentum")
      && (st = dm_integrator_momentum(ls->conv, ls->buf, ls->buf + ls->n, p, &e)) != DM_OK)
    return dm_lua_fail(L, "momentum", st, &e);
  if (!lua_isnoneornil(L, 3)) {
    lua_pushnumber(L, p[dm_lsystem_checkcoord(L, ls, 3)]);
    return 1;
  }
  dm_pushvec_copy(L, p, ls->n);
  return 1;
}

static int s_velocity(lua_State *L)
{
  dm_lsystem *ls = checksys(L);
  read_state(L, ls, "velocity");
  dm_pushvec_copy(L, ls->buf + ls->n, ls->n);
  return 1;
}

static int s_energy(lua_State *L)
{
  dm_lsystem *ls = checksys(L);
  dm_err e;
  double E;
  int st;
  read_state(L, ls, "energy");
  if ((st = dm_integrator_energy(ls->conv, ls->buf, ls->buf + ls->n, &E, &e)) != DM_OK)
    return dm_lua_fail(L, "energy", st, &e);
  lua_pushnumber(L, E);
  return 1;
}

static int s_lagrangian(lua_State *L)
{
  dm_lsystem *ls = checksys(L);
  dm_lag_out o;
  void *work;
  int st;
  read_state(L, ls, "lagrangian");
  work = lua_newuserdatauv(L, ls->sys.work_size + 8, 0);
  memset(&o, 0, sizeof o);
  o.Lq = ls->buf + 3 * ls->n;
  o.Lv = ls->buf + 4 * ls->n;
  st = ls->sys.lagrangian(ls->sys.data, ls->buf, ls->buf + ls->n, ls->sys.par, DM_LAG_L, &o, work);
  if (st < 0)
    return luaL_error(L, "lagrangian: the Lagrangian of '%s' failed (status %d)", ls->sys.name, st);
  lua_pushnumber(L, st == 0 ? o.L : (double)NAN);
  return 1;
}

/* Validate every entry of {name = value} before changing anything. */
static int s_set(lua_State *L)
{
  dm_lsystem *ls = checksys(L);
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    if (lua_type(L, -2) != LUA_TSTRING)
      return luaL_error(L, "set: parameter names are strings, got %s", luaL_typename(L, -2));
    dm_lsystem_checkparam(L, ls, -2);
    if (lua_type(L, -1) != LUA_TNUMBER)
      return luaL_error(L, "set: parameter '%s' needs a number, got %s", lua_tostring(L, -2),
                        luaL_typename(L, -1));
    dm_lsystem_checkfinite(L, "set", lua_tostring(L, -2), lua_tonumber(L, -1));
    lua_pop(L, 1);
  }
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    dm_lua_system_setparam(L, ls, (size_t)dm_lua_system_param(ls, lua_tostring(L, -2)),
                           lua_tonumber(L, -1));
    lua_pop(L, 1);
  }
  lua_settop(L, 1);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * fields: names, flags, expressions
 * ======================================================================= */

static void push_strings(lua_State *L, const char *const *s, size_t n, const unsigned char *sel)
{
  lua_Integer k = 0;
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++)
    if (sel == NULL || sel[i]) {
      lua_pushstring(L, s[i]);
      lua_rawseti(L, -2, ++k);
    }
}

/* "{a, b, ...}" of a list of expressions (or of such lists). */
static int exprlist_tostring(lua_State *L)
{
  luaL_Buffer b;
  lua_Integer n = (lua_Integer)lua_rawlen(L, 1);
  luaL_buffinit(L, &b);
  luaL_addchar(&b, '{');
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, 1, i);
    dm_tolstring(L, -1, NULL);
    lua_remove(L, -2);
    luaL_addvalue(&b);
    if (i < n)
      luaL_addstring(&b, ", ");
  }
  luaL_addchar(&b, '}');
  luaL_pushresult(&b);
  return 1;
}

/* A plain list of expressions that prints as one. */
static void set_exprlist_mt(lua_State *L)
{
  if (luaL_newmetatable(L, "dmech.exprlist")) {
    lua_pushcfunction(L, exprlist_tostring);
    lua_setfield(L, -2, "__tostring");
  }
  lua_setmetatable(L, -2);
}

static void push_exprs(lua_State *L, const dm_expr *x, size_t n)
{
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++) {
    dm_lua_pushexpr(L, x[i]);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  set_exprlist_mt(L);
}

/* Derivatives of L: kind 'q' / 'v' gradient, "vv", "vq", "qq" matrices. */
static void push_derivative(lua_State *L, dm_lsystem *ls, const char *kind)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  size_t n = ls->n;
  dm_expr *g = lua_newuserdatauv(L, (n + n * n) * sizeof *g, 0);
  dm_expr *H = g + n;
  const dm_expr *a = kind[0] == 'q' ? ls->q : ls->v;
  const dm_expr *b = kind[1] == 'q' ? ls->q : ls->v;
  if (dm_expr_grad(ctx, ls->L, n, a, g, NULL) != DM_OK)
    dm_lua_ctx_raise(L, ctx);
  if (kind[1] == '\0') {
    push_exprs(L, g, n);
    return;
  }
  if (dm_expr_jacobian(ctx, n, g, n, b, H, NULL) != DM_OK)
    dm_lua_ctx_raise(L, ctx);
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++) {
    push_exprs(L, H + i * n, n);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  set_exprlist_mt(L);
}

static int expr_field(lua_State *L, dm_lsystem *ls, const char *k)
{
  static const struct { const char *name, *kind; } der[] = {
    {"dLdq", "q"}, {"dLdv", "v"}, {"d2Ldv2", "vv"}, {"d2Ldvdq", "vq"}, {"d2Ldq2", "qq"}
  };
  size_t i;
  int known = strcmp(k, "L") == 0 || strcmp(k, "force") == 0 || strcmp(k, "constraints") == 0 ||
              strcmp(k, "q") == 0 || strcmp(k, "v") == 0 || strcmp(k, "p") == 0;
  for (i = 0; i < sizeof der / sizeof der[0]; i++)
    known |= strcmp(k, der[i].name) == 0;
  if (!known)
    return 0;
  if (!ls->traced)
    return luaL_error(L, "system.%s: '%s' is a built-in C system without expressions", k,
                      ls->sys.name);
  if (strcmp(k, "L") == 0) {
    dm_lua_pushexpr(L, ls->L);
  } else if (strcmp(k, "q") == 0 || strcmp(k, "v") == 0) {   /* the traced symbols */
    dm_lua_pushsymvec(L, k, ls->n, ls->sys.coords, k[0] == 'v' ? "v_%s" : NULL, DM_EXPR_SYM);
  } else if (strcmp(k, "p") == 0) {
    dm_lua_pushsymvec(L, "p", ls->npar, ls->sys.params, NULL, DM_EXPR_PARAM);
  } else if (strcmp(k, "force") == 0) {
    if (ls->force)
      push_exprs(L, ls->force, ls->n);
    else
      lua_pushnil(L);
  } else if (strcmp(k, "constraints") == 0) {
    if (ls->m)
      push_exprs(L, ls->constr, ls->m);
    else
      lua_pushnil(L);
  } else {
    for (i = 0; strcmp(k, der[i].name) != 0; i++)
      ;
    push_derivative(L, ls, der[i].kind);
  }
  return 1;
}

static int system_index(lua_State *L)
{
  dm_lsystem *ls = luaL_checkudata(L, 1, DM_SYSTEM_MT);
  const char *k;
  if (lua_getfield(L, lua_upvalueindex(1), dm_checkcstring(L, 2)) != LUA_TNIL)
    return 1;
  k = lua_tostring(L, 2);
  if (ls->sys.lagrangian == NULL)
    return luaL_error(L, "attempt to use a closed system");
  if (strcmp(k, "name") == 0)
    lua_pushstring(L, ls->sys.name);
  else if (strcmp(k, "n") == 0)
    lua_pushinteger(L, (lua_Integer)ls->n);
  else if (strcmp(k, "m") == 0)
    lua_pushinteger(L, (lua_Integer)ls->m);
  else if (strcmp(k, "coords") == 0)
    push_strings(L, ls->sys.coords, ls->n, NULL);
  else if (strcmp(k, "cyclic") == 0)
    push_strings(L, ls->sys.coords, ls->n, ls->cyclic);
  else if (strcmp(k, "params") == 0)
    lua_getiuservalue(L, 1, 1);
  else if (strcmp(k, "traced") == 0)
    lua_pushboolean(L, ls->traced);
  else if (strcmp(k, "native") == 0 || strcmp(k, "compiling") == 0 ||
           strcmp(k, "native_error") == 0) {
    int nat, pend, want_error = strcmp(k, "native_error") == 0;
    dm_lsystem_native(L, ls, &nat, &pend, want_error);
    if (!want_error)
      lua_pushboolean(L, strcmp(k, "native") == 0 ? nat : pend);
  }
  else if (strcmp(k, "separable") == 0)
    lua_pushboolean(L, (ls->sys.flags & DM_SYS_SEPARABLE) != 0);
  else if (strcmp(k, "mechanical") == 0)
    lua_pushboolean(L, (ls->sys.flags & (DM_SYS_MECHANICAL | DM_SYS_SEPARABLE)) != 0);
  else if (strcmp(k, "forced") == 0)
    lua_pushboolean(L, ls->sys.force != NULL);
  else if (!expr_field(L, ls, k))
    return luaL_error(L, "system has no field or method '%s' (fields: name, n, m, coords, "
                      "params, cyclic, traced, native, compiling, native_error, separable, "
                      "mechanical, forced, q, v, p, "
                      "L, dLdq, dLdv, d2Ldv2, d2Ldvdq, d2Ldq2, force, constraints)", k);
  return 1;
}

static int system_tostring(lua_State *L)
{
  dm_lsystem *ls = luaL_checkudata(L, 1, DM_SYSTEM_MT);
  luaL_Buffer b;
  char num[32];
  if (ls->sys.lagrangian == NULL) {
    lua_pushliteral(L, "<system (closed)>");
    return 1;
  }
  luaL_buffinit(L, &b);
  lua_pushfstring(L, "<system '%s': %d coords (", ls->sys.name, (int)ls->n);
  luaL_addvalue(&b);
  for (size_t i = 0; i < ls->n; i++) {
    const struct dm_lcoordarray *G = NULL;
    for (size_t g = 0; g < ls->ngroups; g++)
      if (ls->groups[g].first == i && ls->groups[g].count > 0)
        G = &ls->groups[g];
    if (G != NULL) {                  /* an array: x[1..n], not n names */
      lua_pushfstring(L, "%s[1..%d]", G->name, (int)G->count);
      luaL_addvalue(&b);
      i += G->count - 1;
    }
    else
      luaL_addstring(&b, ls->sys.coords[i]);
    luaL_addstring(&b, i + 1 < ls->n ? ", " : ")");
  }
  for (size_t i = 0; i < ls->npar; i++) {
    if (i == 8 && ls->npar > 10) {    /* one line: the first 8 and a count */
      lua_pushfstring(L, " ... (%d parameters)", (int)ls->npar);
      luaL_addvalue(&b);
      break;
    }
    luaL_addstring(&b, i == 0 ? ", " : " ");
    luaL_addstring(&b, ls->sys.params[i]);
    luaL_addchar(&b, '=');
    dm_num_format(num, sizeof num, ls->sys.par[i]);
    luaL_addstring(&b, num);
  }
  if (ls->m) {
    lua_pushfstring(L, ", %d constraint%s", (int)ls->m, ls->m == 1 ? "" : "s");
    luaL_addvalue(&b);
  }
  if (ls->sys.force)
    luaL_addstring(&b, ", forced");
  int nat, pend;
  dm_lsystem_native(L, ls, &nat, &pend, 0);
  luaL_addstring(&b, ls->traced ? (nat ? "; traced, native" : pend ? "; traced, compiling"
                                                                  : "; traced, tape")
                                : "; built-in C");
  if (ls->sys.flags & DM_SYS_SEPARABLE)
    luaL_addstring(&b, ", separable");
  else if (ls->sys.flags & DM_SYS_MECHANICAL)
    luaL_addstring(&b, ", mechanical");
  luaL_addchar(&b, '>');
  luaL_pushresult(&b);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * the params proxy
 * ======================================================================= */

static dm_lsystem *proxy_sys(lua_State *L)
{
  dm_lsystem *ls = *(dm_lsystem **)luaL_checkudata(L, 1, PARAMS_MT);
  if (ls->sys.lagrangian == NULL)
    luaL_error(L, "attempt to use the parameters of a closed system");
  return ls;
}

static int params_index(lua_State *L)
{
  dm_lsystem *ls = proxy_sys(L);
  lua_pushnumber(L, ls->sys.par[dm_lsystem_checkparam(L, ls, 2)]);
  return 1;
}

static int params_newindex(lua_State *L)
{
  dm_lsystem *ls = proxy_sys(L);
  long i = dm_lsystem_checkparam(L, ls, 2);
  if (lua_type(L, 3) != LUA_TNUMBER)
    return luaL_error(L, "parameter '%s' needs a number, got %s", ls->sys.params[i],
                      luaL_typename(L, 3));
  dm_lsystem_checkfinite(L, "params", ls->sys.params[i], lua_tonumber(L, 3));
  dm_lua_system_setparam(L, ls, (size_t)i, lua_tonumber(L, 3));
  return 0;
}

static int params_next(lua_State *L)
{
  dm_lsystem *ls = proxy_sys(L);
  long i = lua_isnil(L, 2) ? 0 : dm_lua_system_param(ls, dm_checkcstring(L, 2)) + 1;
  if (i < 0 || (size_t)i >= ls->npar)
    return 0;
  lua_pushstring(L, ls->sys.params[i]);
  lua_pushnumber(L, ls->sys.par[i]);
  return 2;
}

static int params_pairs(lua_State *L)
{
  proxy_sys(L);
  lua_pushcfunction(L, params_next);
  lua_pushvalue(L, 1);
  lua_pushnil(L);
  return 3;
}

static int params_len(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)proxy_sys(L)->npar);
  return 1;
}

static int params_tostring(lua_State *L)
{
  dm_lsystem *ls = proxy_sys(L);
  luaL_Buffer b;
  char num[32];
  luaL_buffinit(L, &b);
  luaL_addchar(&b, '{');
  for (size_t i = 0; i < ls->npar; i++) {
    luaL_addstring(&b, i ? ", " : "");
    luaL_addstring(&b, ls->sys.params[i]);
    luaL_addstring(&b, " = ");
    dm_num_format(num, sizeof num, ls->sys.par[i]);
    luaL_addstring(&b, num);
  }
  luaL_addchar(&b, '}');
  luaL_pushresult(&b);
  return 1;
}

/* }====================================================================== */

static const luaL_Reg params_meta[] = {
  {"__index", params_index}, {"__newindex", params_newindex}, {"__pairs", params_pairs},
  {"__len", params_len}, {"__tostring", params_tostring}, {NULL, NULL}
};

static const luaL_Reg system_meta[] = {
  {"__gc", dm_lsystem_gc}, {"__close", dm_lsystem_gc}, {"__tostring", system_tostring},
  {NULL, NULL}
};

static const dm_reg system_methods[] = {
  {"energy", s_energy, "sys:energy{q=, v= | p=} -> number",
   "The energy E = p.v - L of a state (q and v, or q and p: v then solves dL/dv = p)."},
  {"momentum", s_momentum, "sys:momentum{q=, v= | p=}[, coord] -> vec | number",
   "The conjugate momenta p = dL/dv of a state (the Legendre transform), or the component of one coordinate."},
  {"velocity", s_velocity, "sys:velocity{q=, p= | v=} -> v",
   "The velocity of a state: v solving dL/dv (q, v) = p by Newton (one step for mechanical L); raises when d2L/dv2 is singular."},
  {"lagrangian", s_lagrangian, "sys:lagrangian{q=, v= | p=} -> number",
   "The value of the Lagrangian at a state."},
  {"set", s_set, "sys:set{name = value, ...} -> sys",
   "Change parameters (all checked first); compiled code reads them at once, nothing is recompiled."},
  {NULL, NULL, NULL, NULL}
};

static const dm_field system_fields[] = {
  {"name", "sys.name -> string", "The system's name."},
  {"n", "sys.n -> integer", "The number of coordinates."},
  {"m", "sys.m -> integer", "The number of holonomic constraints."},
  {"coords", "sys.coords -> {name, ...}", "The coordinate names in order."},
  {"params", "sys.params -> params", "The parameters, read and set by name: sys.params.J2 = 0.05."},
  {"cyclic", "sys.cyclic -> {name, ...}", "The coordinates that L does not depend on."},
  {"traced", "sys.traced -> boolean", "True for a system traced from a Lua L (false: built-in C)."},
  {"native", "sys.native -> boolean", "True when the traced derivatives run as native code (else the tape)."},
  {"compiling", "sys.compiling -> boolean", "True while the native code is being compiled in the background."},
  {"native_error", "sys.native_error -> string | nil", "Why the native code could not be built, or nil."},
  {"separable", "sys.separable -> boolean", "True when L = 1/2 v.M v - V(q) with a constant M."},
  {"mechanical", "sys.mechanical -> boolean", "True when L is quadratic in the velocities."},
  {"forced", "sys.forced -> boolean", "True when the system has a Lagrange-d'Alembert force."},
  {"q", "sys.q -> symvec", "The traced coordinate symbols (q.x, q[1])."},
  {"v", "sys.v -> symvec", "The traced velocity symbols (v.x is v_x)."},
  {"p", "sys.p -> symvec", "The parameter symbols."},
  {"L", "sys.L -> expr", "The traced Lagrangian, an expression."},
  {"dLdq", "sys.dLdq -> {expr, ...}", "The derivatives dL/dq, expressions."},
  {"dLdv", "sys.dLdv -> {expr, ...}", "The momenta dL/dv, expressions."},
  {"d2Ldv2", "sys.d2Ldv2 -> {{expr, ...}, ...}", "The mass matrix d2L/dv2, expressions."},
  {"d2Ldvdq", "sys.d2Ldvdq -> {{expr, ...}, ...}", "The mixed derivatives d2L/dvdq, expressions."},
  {"d2Ldq2", "sys.d2Ldq2 -> {{expr, ...}, ...}", "The second derivatives d2L/dq2, expressions."},
  {"force", "sys.force -> {expr, ...} | nil", "The traced force, or nil."},
  {"constraints", "sys.constraints -> {expr, ...} | nil", "The traced constraints g(q) = 0, or nil."},
  {NULL, NULL, NULL}
};

void dm_lsystem_open_class(lua_State *L)
{
  dm_newclass(L, PARAMS_MT, "params", NULL, params_meta);
  lua_pop(L, 1);
  dm_newclass(L, DM_SYSTEM_MT, "system", system_methods, system_meta);
  lua_getfield(L, -1, "__methods");
  lua_pushcclosure(L, system_index, 1);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
  dm_doc_fields(L, "system", system_fields);
}
