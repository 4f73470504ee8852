/* l_integ_adapt.c -- the `adapt` option of dm.integrator: a time
 * transformation of the method (src/integrators/adapt.h).
 *
 *   adapt = true                        the potential's monitor, power 1
 *   adapt = {power = a}                 g = (U(q0)/U(q))^a, U = -V
 *   adapt = {monitor = function(q, p, par) return ... end}
 *
 * A monitor function is traced once with symbolic q, p and parameters
 * (like L) and compiled by the expression engine into a scalar field of q
 * with its gradient and Hessian (dm_lagrangian_compile of g as a
 * "Lagrangian" of q); it must not depend on p.  The compiled field lives
 * in a userdata ("dmech.monitorbox") anchored by the integrator.  Part of
 * the integrator binding (l_integ.h). */
#include <config.h>
#include <string.h>

#include "expr/lagrangian.h"
#include "integrators/adapt.h"
#include "lua/l_expr.h"
#include "lua/l_integ.h"

#define MONBOX_MT "dmech.monitorbox"

typedef struct monbox {
  dm_system field;          /* zeroed until compiled */
  dm_monitor mon;
} monbox;

static int monbox_gc(lua_State *L)
{
  monbox *b = luaL_checkudata(L, 1, MONBOX_MT);
  dm_system_release(&b->field);
  return 0;
}

/* Trace adapt.monitor (at the top) and compile it into a new box (pushed,
 * replacing the function). */
static void compile_monitor(lua_State *L, const char *fname, const dm_system *sys,
                            dm_integ_opts *opt)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  size_t n = sys->n, npar = sys->npar, i, rows, cols;
  int fn = lua_gettop(L), qv, vv, pv, parv, st;
  dm_expr g, *sym;
  dm_lagrangian_spec sp;
  dm_err e;
  char what[160];
  monbox *b = lua_newuserdatauv(L, sizeof *b, 0);
  memset(b, 0, sizeof *b);
  luaL_setmetatable(L, MONBOX_MT);
  int box = lua_gettop(L);
  dm_lua_pushsymvec(L, "q", n, sys->coords, NULL, DM_EXPR_SYM);
  qv = lua_gettop(L);
  dm_lua_pushsymvec(L, "v", n, sys->coords, "v_%s", DM_EXPR_SYM);
  vv = lua_gettop(L);
  dm_lua_pushsymvec(L, "p", n, sys->coords, "p_%s", DM_EXPR_SYM);
  pv = lua_gettop(L);
  dm_lua_pushsymvec(L, "par", npar, sys->params, NULL, DM_EXPR_PARAM);
  parv = lua_gettop(L);
  /* 4 (q, v, p, par) x n nodes, kept in a userdata so an error leaks nothing */
  sym = lua_newuserdatauv(L, (3 * n + npar + 1) * sizeof *sym, 0);
  for (i = 0; i < n; i++) {
    lua_geti(L, qv, (lua_Integer)i + 1);
    sym[i] = dm_lua_toexpr(L, -1);
    lua_geti(L, vv, (lua_Integer)i + 1);
    sym[n + i] = dm_lua_toexpr(L, -1);
    lua_geti(L, pv, (lua_Integer)i + 1);
    sym[2 * n + i] = dm_lua_toexpr(L, -1);
    lua_pop(L, 3);
  }
  for (i = 0; i < npar; i++) {
    lua_geti(L, parv, (lua_Integer)i + 1);
    sym[3 * n + i] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
  snprintf(what, sizeof what, "adapt.monitor of system '%s'", sys->name ? sys->name : "?");
  lua_pushvalue(L, fn);
  lua_pushvalue(L, qv);
  lua_pushvalue(L, pv);
  lua_pushvalue(L, parv);
  dm_lua_trace(L, what, 3);
  if (lua_isnil(L, -1))
    luaL_error(L, "%s: %s returned nothing (return an expression of q)", fname, what);
  dm_lua_toexprs(L, -1, what, &g, 1, &rows, &cols);
  if (rows != 1 || cols != 0)
    luaL_error(L, "%s: %s must return one expression, got a list", fname, what);
  for (i = 0; i < n; i++)
    if (dm_expr_depends(ctx, g, 1, &sym[2 * n + i]))
      luaL_error(L, "%s: %s must be a function of the coordinates q only (it depends on p.%s)",
                 fname, what, sys->coords ? sys->coords[i] : "?");
  memset(&sp, 0, sizeof sp);
  sp.name = "monitor";
  sp.n = n;
  sp.q = sym;
  sp.v = sym + n;
  sp.npar = npar;
  sp.par = sym + 3 * n;
  sp.par_values = sys->par;
  sp.coord_names = sys->coords;
  sp.param_names = sys->params;
  sp.L = g;
  sp.native = DM_NATIVE_NEVER;
  if ((st = dm_lagrangian_compile(ctx, &sp, &b->field, &e)) != DM_OK)
    dm_lua_fail(L, fname, st, &e);
  dm_adapt_monitor_from_system(&b->mon, &b->field);
  opt->monitor = &b->mon;
  lua_settop(L, box);
  lua_replace(L, fn);
}

int dm_linteg_parse_adapt(lua_State *L, int idx, const char *fname, const dm_system *sys,
                          dm_integ_opts *opt, int own)
{
  int t = lua_getfield(L, idx, "adapt");
  if (t == LUA_TNIL || (t == LUA_TBOOLEAN && !lua_toboolean(L, -1))) {
    lua_pop(L, 1);
    return 0;
  }
  if (t != LUA_TBOOLEAN && t != LUA_TTABLE)
    luaL_error(L, "%s: option 'adapt' must be true or a table {monitor = function(q, p, par) "
               "... end | power = a}, got %s", fname, luaL_typename(L, -1));
  opt->monitor = NULL;
  if (t == LUA_TTABLE) {
    int a = lua_gettop(L), mt, pt;
    lua_pushnil(L);
    while (lua_next(L, a) != 0) {
      const char *k = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
      if (k == NULL || (strcmp(k, "monitor") != 0 && strcmp(k, "power") != 0))
        luaL_error(L, "%s: unknown field %s%s%s in adapt (fields: monitor, power)", fname,
                   k ? "'" : "[", luaL_tolstring(L, -2, NULL), k ? "'" : "]");
      lua_pop(L, 1);
    }
    mt = lua_getfield(L, a, "monitor");
    pt = lua_getfield(L, a, "power");
    if (mt != LUA_TNIL && pt != LUA_TNIL)
      luaL_error(L, "%s: adapt: give monitor or power, not both (power is the exponent of the "
                 "potential's monitor)", fname);
    if (pt != LUA_TNIL) {
      double x = lua_tonumber(L, -1);
      if (lua_type(L, -1) != LUA_TNUMBER || !(x >= 0.0 && x <= 8.0))
        luaL_error(L, "%s: adapt.power must be a number in [0, 8], got %s", fname,
                   luaL_tolstring(L, -1, NULL));
      opt->power = x;
    }
    lua_pop(L, 1);
    if (mt != LUA_TNIL) {
      if (mt != LUA_TFUNCTION)
        luaL_error(L, "%s: adapt.monitor must be a function(q, p, par) returning g(q) > 0, "
                   "got %s", fname, luaL_typename(L, -1));
      compile_monitor(L, fname, sys, opt);
      lua_setfield(L, own, "monitor");
    } else {
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
  return 1;
}

static const luaL_Reg monbox_meta[] = {{"__gc", monbox_gc}, {NULL, NULL}};

void dm_linteg_open_adapt(lua_State *L)
{
  dm_newclass(L, MONBOX_MT, "monitorbox", NULL, monbox_meta);
  lua_pop(L, 1);
}
