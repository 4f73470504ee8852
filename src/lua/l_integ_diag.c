/* l_integ_diag.c -- dm.tableau (inspect PRK coefficients), dm.methods (the
 * registered integrators) and integ:order_estimate (empirical order by step
 * halving against a reference).  Part of the integrator binding. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_integ.h"

static int tab_gc(lua_State *L)
{
  dm_tableau **t = lua_touserdata(L, 1);
  dm_tableau_free(*t);
  *t = NULL;
  return 0;
}

/* A box owning a tableau until the function returns (errors included). */
static dm_tableau **push_box(lua_State *L)
{
  dm_tableau **t = lua_newuserdatauv(L, sizeof *t, 0);
  *t = NULL;
  lua_createtable(L, 0, 1);
  lua_pushcfunction(L, tab_gc);
  lua_setfield(L, -2, "__gc");
  lua_setmetatable(L, -2);
  return t;
}

static void push_tableau(lua_State *L, const dm_tableau *t)
{
  size_t s = t->s;
  double defect = dm_tableau_symplectic_defect(t, NULL, NULL);
  lua_createtable(L, 0, 11);
  lua_pushstring(L, t->name);
  lua_setfield(L, -2, "name");
  lua_pushinteger(L, (lua_Integer)s);
  lua_setfield(L, -2, "s");
  lua_pushinteger(L, t->order);
  lua_setfield(L, -2, "order");
  dm_pushvec_copy(L, t->c, s);
  lua_setfield(L, -2, "c");
  dm_pushvec_copy(L, t->b, s);
  lua_setfield(L, -2, "b");
  dm_pushvec_copy(L, t->bt, s);
  lua_setfield(L, -2, "bt");
  memcpy(dm_pushmat(L, s, s)->data, t->a, s * s * sizeof(double));
  lua_setfield(L, -2, "a");
  memcpy(dm_pushmat(L, s, s)->data, t->at, s * s * sizeof(double));
  lua_setfield(L, -2, "at");
  lua_pushboolean(L, (t->flags & DM_TAB_SYMPLECTIC) != 0);
  lua_setfield(L, -2, "symplectic");
  lua_pushboolean(L, (t->flags & DM_TAB_SYMMETRIC) != 0);
  lua_setfield(L, -2, "symmetric");
  lua_pushnumber(L, defect);
  lua_setfield(L, -2, "defect");
}

/* dm.tableau("gauss" | "lobatto", s) | ("galerkin", {c...}) |
 * ("midpoint" | "trapezoid") */
static int l_tableau(lua_State *L)
{
  static const char *const kinds[] = {"gauss", "lobatto", "galerkin", "midpoint", "trapezoid",
                                      NULL};
  int kind = dm_checkoption(L, 1, NULL, kinds);
  dm_tableau **box = push_box(L);
  double c[DM_TABLEAU_SMAX];
  lua_Integer s = 0;
  dm_err e;
  int st;
  if (kind <= 1) {
    s = luaL_checkinteger(L, 2);
    if (s < (kind == 0 ? 1 : 2) || s > DM_TABLEAU_SMAX)
      return luaL_error(L, "dm.tableau: %s needs %d <= s <= %d stages, got %d", kinds[kind],
                        kind == 0 ? 1 : 2, DM_TABLEAU_SMAX, (int)s);
  }
  if (kind == 0 || kind == 3)
    st = dm_tableau_gauss(kind == 0 ? (size_t)s : 1, box, &e);
  else if (kind == 1 || kind == 4)
    st = dm_tableau_lobatto(kind == 1 ? (size_t)s : 2, box, &e);
  else {
    gsl_vector *v = dm_checkvector(L, 2, 0);
    if (v->size > DM_TABLEAU_SMAX)
      return luaL_error(L, "dm.tableau: at most %d nodes", DM_TABLEAU_SMAX);
    for (size_t i = 0; i < v->size; i++)
      c[i] = gsl_vector_get(v, i);
    st = dm_tableau_galerkin(v->size, c, box, &e);
  }
  if (st != DM_OK)
    return dm_lua_fail(L, "dm.tableau", st, &e);
  push_tableau(L, *box);
  return 1;
}

/* dm.methods([sys | kind]) -> {name = summary, ...}: the families for that
 * kind of system (default: Lagrangian), under each name they answer to */
static int l_methods(lua_State *L)
{
  const char *kind = NULL;
  size_t i, count = dm_integrator_count();
  if (lua_type(L, 1) == LUA_TSTRING)
    kind = lua_tostring(L, 1);
  else if (!lua_isnoneornil(L, 1))
    kind = dm_linteg_checksystem(L, 1)->sys.kind;
  lua_newtable(L);
  for (i = 0; i < count; i++) {
    const dm_integrator_type *t = dm_integrator_type_at(i);
    const char *const *a;
    if (!dm_integrator_accepts(t, kind))
      continue;
    lua_pushstring(L, t->summary);
    lua_setfield(L, -2, strcmp(t->name, "gsl") == 0 ? "gsl:<stepper>" : t->name);
    for (a = t->names; a != NULL && *a != NULL; a++) {
      lua_pushstring(L, t->summary);
      lua_setfield(L, -2, *a);
    }
  }
  return 1;
}

/* integ:order_estimate{state=, t=, h={...}[, reference=state]}: this
 * integrator's method and options (its tableau included) at each step */
int dm_linteg_order_estimate(lua_State *L)
{
  static const char *const keys[] = {"state", "t", "h", "reference", NULL};
  dm_linteg *li = dm_linteg_check(L, 1);
  dm_lsystem *ls = li->ls;
  dm_lstate s, ref;
  double T, order, *hs, *err, *buf;
  size_t k, n = ls->n;
  dm_err e;
  int st;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    const char *const *kk = keys;
    while (*kk && !(lua_type(L, -2) == LUA_TSTRING && strcmp(*kk, lua_tostring(L, -2)) == 0))
      kk++;
    if (*kk == NULL)
      return luaL_error(L, "order_estimate: unknown option %s (options: state, t, h, reference; "
                        "the method and its options are the integrator's)",
                        dm_tolstring(L, -2, NULL));
    lua_pop(L, 1);
  }
  T = dm_optnumberfield(L, 2, "t", NAN);
  if (!isfinite(T) || T == 0.0)
    return luaL_error(L, "order_estimate: field 't' (the final time, != 0) is required");
  if (lua_getfield(L, 2, "h") != LUA_TTABLE || (k = lua_rawlen(L, -1)) < 2)
    return luaL_error(L, "order_estimate: field 'h' must list at least 2 step sizes");
  buf = lua_newuserdatauv(L, (2 * k + 8 * n) * sizeof *buf, 0);
  hs = buf;
  err = hs + k;
  for (size_t i = 0; i < k; i++) {
    lua_rawgeti(L, -2, (lua_Integer)i + 1);
    hs[i] = lua_tonumber(L, -1);
    if (lua_type(L, -1) != LUA_TNUMBER || !(hs[i] > 0))
      return luaL_error(L, "order_estimate: h[%d] must be a positive number", (int)i + 1);
    lua_pop(L, 1);
  }
  if (lua_getfield(L, 2, "state") == LUA_TNIL)
    return luaL_error(L, "order_estimate: field 'state' (the initial state) is required");
  dm_lua_readstate(L, ls, ls->conv, -1, "order_estimate", err + k, &s);
  ref.q = NULL;
  if (lua_getfield(L, 2, "reference") != LUA_TNIL)
    dm_lua_readstate(L, ls, ls->conv, -1, "order_estimate: reference", err + k + 4 * n, &ref);
  st = dm_integrator_order_estimate(&ls->sys, li->method, &li->opt, s.q, s.p, T, hs, k,
                                    ref.q ? ref.q : NULL, ref.q ? ref.p : NULL, err, &order, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, "order_estimate", st, &e);
  lua_pushnumber(L, order);
  dm_pushvec_copy(L, err, k);
  return 2;
}

const dm_reg dm_linteg_diag_funcs[] = {
  {"tableau", l_tableau,
   "dm.tableau(\"gauss\" | \"lobatto\", s) | dm.tableau(\"galerkin\", {c...}) | "
   "dm.tableau(\"midpoint\" | \"trapezoid\") -> {name, s, order, c, b, bt, a, at, symplectic, symmetric, defect}",
   "The partitioned Runge-Kutta coefficients of a Galerkin method (usable as tableau= of method \"prk\")."},
  {"methods", l_methods, "dm.methods([sys | kind]) -> {name = summary, ...}",
   "The integration methods dm.integrator knows for a kind of system (default: Lagrangian "
   "systems; a system, a Routh reduction, or a kind such as \"routh\"), with one line each."},
  {NULL, NULL, NULL, NULL}
};
