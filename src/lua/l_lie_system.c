/* l_lie_system.c -- systems on Lie groups in Lua: dm.system{space = G,
 * L = function(g, xi, p) ... end, force = ..., params = ...} (called by
 * dm.system when `space` is given), dm.euler_poincare(sys), and the
 * states {g =, xi = | mu = [, t =]} shared with the integrators
 * (l_lie_integ.c).  A system is a userdata "dmech.liesystem" owning a
 * dm_lie_system; its user value 1 is the group userdata of its space. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_lie_sys.h"
#include "lua/l_system.h"
#include "lua/l_expr.h"
#include "expr/native.h"

/* {======================================================================
 * the userdata
 * ======================================================================= */

static int sys_gc(lua_State *L)
{
  dm_llsys *ls = luaL_checkudata(L, 1, DM_LIESYS_MT);
  dm_lie_system_free(ls->S);
  ls->S = NULL;
  return 0;
}

dm_llsys *dm_lua_tolsys(lua_State *L, int idx)
{
  dm_llsys *ls = luaL_testudata(L, idx, DM_LIESYS_MT);
  return ls != NULL && ls->S != NULL ? ls : NULL;
}

dm_llsys *dm_lua_checklsys(lua_State *L, int idx)
{
  dm_llsys *ls = dm_lua_tolsys(L, idx);
  if (ls == NULL)
    dm_argexpected(L, idx, "system on a Lie group (dm.system{space = ...})",
                   luaL_typename(L, idx));
  return ls;
}

/* a new empty userdata; user value 1 = the group userdata at gidx */
static dm_llsys *newsys(lua_State *L, int gidx)
{
  dm_llsys *ls;
  gidx = lua_absindex(L, gidx);
  ls = lua_newuserdatauv(L, sizeof *ls, 1);
  ls->S = NULL;
  luaL_setmetatable(L, DM_LIESYS_MT);
  lua_pushvalue(L, gidx);
  lua_setiuservalue(L, -2, 1);
  return ls;
}

/* }====================================================================== */

/* {======================================================================
 * dm.system{space = ...}
 * ======================================================================= */

/* trace field `field` of t with the arguments at args[0..3): one
 * expression (scalar) or want of them into out */
static void trace(lua_State *L, int t, const char *field, const int *args, int scalar,
                  size_t want, dm_expr *out, const char *sysname)
{
  char what[160];
  size_t cnt, rows, cols;
  int i;
  if (lua_getfield(L, t, field) != LUA_TFUNCTION)
    luaL_error(L, "dm.system: field '%s' must be a function, got %s", field, luaL_typename(L, -1));
  snprintf(what, sizeof what, "%s of system '%s'", field, sysname);
  for (i = 0; i < 3; i++)
    lua_pushvalue(L, args[i]);
  dm_lua_trace(L, what, 3);
  if (lua_isnil(L, -1))
    luaL_error(L, "dm.system: %s returned nothing", what);
  cnt = dm_lua_toexprs(L, -1, what, NULL, 0, &rows, &cols);
  if (scalar && cols != 0)
    luaL_error(L, "dm.system: %s must return one expression, got a list of %d", what, (int)cnt);
  if (rows != 1 || cnt != want)
    luaL_error(L, "dm.system: %s must return a list of %d expressions (one per algebra "
               "coordinate of the space), got %d value%s", what, (int)want, (int)cnt,
               cnt == 1 ? "" : "s");
  dm_lua_toexprs(L, -1, what, out, want, NULL, NULL);
  lua_pop(L, 1);
}

static int native_mode(lua_State *L, int t)
{
  int mode = dm_lua_native_mode(L), type = lua_getfield(L, t, "native");
  if (type == LUA_TBOOLEAN)
    mode = lua_toboolean(L, -1) ? DM_NATIVE_ALWAYS : DM_NATIVE_NEVER;
  else if (type == LUA_TSTRING)
    mode = dm_native_mode_parse(lua_tostring(L, -1));
  else if (type != LUA_TNIL)
    mode = -1;
  if (mode < 0)
    luaL_error(L, "dm.system: native must be \"auto\", \"always\", \"never\" or a boolean");
  lua_pop(L, 1);
  return mode;
}

int dm_lua_lie_system(lua_State *L)
{
  static const char *const keys[] = {"space", "L", "force", "params", "name", "native", NULL};
  const dm_lie_group *G;
  dm_lie_spec sp;
  dm_llsys *ls;
  dm_err e;
  const char **pnames;
  double *pvals;
  size_t npar, i, nq, n;
  int args[3], st;
  dm_expr *g, *xi, *par, L0, F[DM_LIE_DIM_MAX];
  const char *name;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  if (dm_unknownkey(L, 1, keys))
    return luaL_error(L, "dm.system: unknown field %s for a system on a Lie group (fields: "
                      "space, L, force, params, name, native)", dm_tolstring(L, -1, NULL));
  lua_getfield(L, 1, "space");                              /* 2 */
  if ((G = dm_lua_togroup(L, 2)) == NULL)
    return luaL_error(L, "dm.system: field 'space' must be a Lie group (dm.lie.SO3(), "
                      "dm.lie.product(...)) or a sphere (dm.lie.sphere(n)), got %s",
                      luaL_typename(L, 2));
  name = dm_optstringfield(L, 1, "name", "system");
  nq = G->nq;
  n = G->dim;
  lua_getfield(L, 1, "L");
  if (!lua_isfunction(L, -1))
    return luaL_error(L, "dm.system: field 'L' must be a function L(g, xi, p) returning the "
                      "Lagrangian, got %s", luaL_typename(L, -1));
  lua_pop(L, 1);
  npar = dm_lsystem_read_params(L, 1, &pnames, &pvals);                /* 3 params, 4 names, 5 vals */
  g = lua_newuserdatauv(L, (nq + n + npar + 1) * sizeof *g, 0);  /* 6 */
  xi = g + nq;
  par = xi + n;
  ls = newsys(L, 2);                                        /* 7 */
  /* the symbolic element: symbols named like the trajectory's columns */
  {
    char (*gn)[DM_LIE_NAME_MAX] = lua_newuserdatauv(L, nq * sizeof *gn, 0);   /* 8 */
    dm_expr_ctx *ctx = dm_lua_exprctx(L);
    dm_lelem *el = dm_lua_newelem(L, 2, 1);                                  /* 9 */
    dm_lie_coord_names(G, gn);
    args[0] = lua_gettop(L);
    for (i = 0; i < nq; i++)
      g[i] = el->v[i].e = dm_expr_sym(ctx, gn[i]);
  }
  {
    const char *xn[DM_LIE_DIM_MAX];
    char xb[DM_LIE_DIM_MAX][16];
    for (i = 0; i < n; i++) {
      snprintf(xb[i], sizeof xb[i], "xi%zu", i + 1);
      xn[i] = xb[i];
    }
    dm_lua_pushsymvec(L, "xi", n, xn, NULL, DM_EXPR_SYM);   /* 10 */
    args[1] = lua_gettop(L);
    for (i = 0; i < n; i++) {
      lua_geti(L, args[1], (lua_Integer)i + 1);
      xi[i] = dm_lua_toexpr(L, -1);
      lua_pop(L, 1);
    }
  }
  dm_lua_pushsymvec(L, "p", npar, pnames, NULL, DM_EXPR_PARAM);  /* 11 */
  args[2] = lua_gettop(L);
  for (i = 0; i < npar; i++) {
    lua_geti(L, args[2], (lua_Integer)i + 1);
    par[i] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
  trace(L, 1, "L", args, 1, 1, &L0, name);
  if (lua_getfield(L, 1, "force") != LUA_TNIL)
    trace(L, 1, "force", args, 0, n, F, name);
  lua_pop(L, 1);
  memset(&sp, 0, sizeof sp);
  sp.name = name;
  sp.G = G;
  sp.g = g;
  sp.xi = xi;
  sp.npar = npar;
  sp.par = par;
  sp.par_values = pvals;
  sp.param_names = pnames;
  sp.L = L0;
  lua_getfield(L, 1, "force");
  sp.force = lua_isnil(L, -1) ? NULL : F;
  lua_pop(L, 1);
  sp.native = native_mode(L, 1);
  if ((st = dm_lie_register_integrators(&e)) != DM_OK ||
      (st = dm_lie_system_compile(dm_lua_exprctx(L), &sp, &ls->S, &e)) != DM_OK)
    return dm_lua_fail(L, "dm.system", st, &e);
  lua_pushvalue(L, 7);
  return 1;
}

/* dm.euler_poincare(sys) */
static int l_euler_poincare(lua_State *L)
{
  dm_llsys *ls = dm_lua_checklsys(L, 1), *r;
  dm_err e;
  int st;
  lua_getiuservalue(L, 1, 1);
  r = newsys(L, -1);
  if ((st = dm_lie_system_reduce(ls->S, &r->S, &e)) != DM_OK)
    return luaL_error(L, "%s", e.msg);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * states
 * ======================================================================= */

void dm_lua_lie_readstate(lua_State *L, dm_integrator *I, const dm_lie_system *S, int idx,
                          const char *fname, dm_lstate_lie *st)
{
  const dm_lie_group *G = dm_lie_system_group(S);
  dm_lelem *el;
  dm_err e;
  dm_expr ex[DM_LIE_NQ_MAX];
  size_t n = G->dim;
  int has_mu, has_xi, rc;
  idx = lua_absindex(L, idx);
  if (lua_type(L, idx) != LUA_TTABLE)
    luaL_error(L, "%s: the state must be a table {g =, mu = | xi = [, t =]}, got %s", fname,
               luaL_typename(L, idx));
  lua_getfield(L, idx, "g");
  if ((el = dm_lua_toelem(L, -1)) == NULL)
    luaL_error(L, "%s: state.g must be an element of %s (G.exp{...}, G.element(...)), got %s",
               fname, G->name, luaL_typename(L, -1));
  if (!dm_lie_group_equal(el->G, G))
    luaL_error(L, "%s: state.g must be an element of %s, got an element of %s", fname, G->name,
               el->G->name);
  dm_lua_elem_numbers(L, el, fname, st->g);
  lua_pop(L, 1);
  if (dm_lie_check(G, st->g, 1e-10, &e) != DM_OK)
    luaL_error(L, "%s: state.g: %s (g:normalize() projects it onto the group)", fname, e.msg);
  st->t = dm_optnumberfield(L, idx, "t", 0.0);
  has_mu = lua_getfield(L, idx, "mu") != LUA_TNIL;
  has_xi = lua_getfield(L, idx, "xi") != LUA_TNIL;
  if (!has_mu && !has_xi)
    luaL_error(L, "%s: the state needs mu (body momentum) or xi (body velocity)", fname);
  if (has_mu) {
    if (dm_lua_readvals(L, -2, n, fname, "state.mu", st->mu, ex))
      luaL_error(L, "%s: state.mu must be numbers", fname);
  } else {
    if (dm_lua_readvals(L, -1, n, fname, "state.xi", st->xi, ex))
      luaL_error(L, "%s: state.xi must be numbers", fname);
    if ((rc = dm_lie_momentum(I, st->g, st->xi, st->mu, &e)) != DM_OK)
      dm_lua_fail(L, fname, rc, &e);
  }
  lua_pop(L, 2);
  for (size_t i = 0; i < n; i++)
    if (!isfinite(st->mu[i]))
      luaL_error(L, "%s: state.%s contains NaN or Inf", fname, has_mu ? "mu" : "xi");
  if ((rc = dm_lie_velocity(I, st->g, st->mu, st->xi, &e)) != DM_OK)
    dm_lua_fail(L, fname, rc, &e);
}

void dm_lua_lie_pushstate(lua_State *L, int gidx, const dm_lie_system *S, double t,
                          const double *g, const double *mu, const double *xi)
{
  const dm_lie_group *G = dm_lie_system_group(S);
  size_t n = G->dim, i;
  dm_lelem *el;
  gidx = lua_absindex(L, gidx);
  lua_createtable(L, 0, 4);
  lua_pushnumber(L, t);
  lua_setfield(L, -2, "t");
  el = dm_lua_newelem(L, gidx, 0);
  for (i = 0; i < G->nq; i++)
    el->v[i].x = g[i];
  lua_setfield(L, -2, "g");
  dm_pushvec_copy(L, mu, n);
  lua_setfield(L, -2, "mu");
  dm_pushvec_copy(L, xi, n);
  lua_setfield(L, -2, "xi");
}

/* }====================================================================== */

/* {======================================================================
 * methods
 * ======================================================================= */

static int s_tostring(lua_State *L)
{
  dm_llsys *ls = dm_lua_checklsys(L, 1);
  const dm_lie_system *S = ls->S;
  const dm_lie_group *G = dm_lie_system_group(S);
  lua_pushfstring(L, "<System '%s' on %s%s: dim %d>", dm_lie_system_base(S)->name, G->name,
                  dm_lie_system_is_reduced(S) ? " (reduced, Euler-Poincare)" : "", (int)G->dim);
  return 1;
}

static int s_space(lua_State *L)
{
  dm_lua_checklsys(L, 1);
  lua_getiuservalue(L, 1, 1);
  return 1;
}

/* The index of the parameter named by the string at idx, or an error
 * from `fname` naming the system. */
static size_t lie_param_index(lua_State *L, const dm_system *b, int idx, const char *fname)
{
  const char *name = lua_tostring(L, idx);
  for (size_t i = 0; i < b->npar; i++)
    if (strcmp(b->params[i], name) == 0)
      return i;
  return (size_t)luaL_error(L, "%s: no parameter '%s' in system '%s'", fname, name, b->name);
}

static int s_param(lua_State *L)
{
  dm_llsys *ls = dm_lua_checklsys(L, 1);
  dm_lie_system *S = ls->S;
  const dm_system *b = dm_lie_system_base(S);
  size_t i;
  dm_checkcstring(L, 2);
  i = lie_param_index(L, b, 2, "sys:param");
  if (lua_isnoneornil(L, 3)) {
    lua_pushnumber(L, b->par[i]);
    return 1;
  }
  dm_lsystem_checkfinite(L, "sys:param", b->params[i], luaL_checknumber(L, 3));
  dm_lie_system_par(S)[i] = lua_tonumber(L, 3);
  dm_lie_system_params_changed(S);
  lua_settop(L, 1);
  return 1;
}

/* sys:set{name = value, ...}, as for systems in coordinates: every entry
 * is checked before any parameter changes. */
static int s_set(lua_State *L)
{
  dm_llsys *ls = dm_lua_checklsys(L, 1);
  dm_lie_system *S = ls->S;
  const dm_system *b = dm_lie_system_base(S);
  luaL_checktype(L, 2, LUA_TTABLE);
  for (int pass = 0; pass < 2; pass++) {
    lua_pushnil(L);
    while (lua_next(L, 2) != 0) {
      if (pass == 0) {
        if (lua_type(L, -2) != LUA_TSTRING)
          return luaL_error(L, "set: parameter names are strings, got %s", luaL_typename(L, -2));
        lie_param_index(L, b, -2, "set");
        if (lua_type(L, -1) != LUA_TNUMBER)
          return luaL_error(L, "set: parameter '%s' needs a number, got %s", lua_tostring(L, -2),
                            luaL_typename(L, -1));
        dm_lsystem_checkfinite(L, "set", lua_tostring(L, -2), lua_tonumber(L, -1));
      } else {
        dm_lie_system_par(S)[lie_param_index(L, b, -2, "set")] = lua_tonumber(L, -1);
      }
      lua_pop(L, 1);
    }
  }
  dm_lie_system_params_changed(S);
  lua_settop(L, 1);
  return 1;
}

static int s_is_reduced(lua_State *L)
{
  lua_pushboolean(L, dm_lie_system_is_reduced(dm_lua_checklsys(L, 1)->S));
  return 1;
}

static int s_names(lua_State *L)
{
  dm_llsys *ls = dm_lua_checklsys(L, 1);
  const dm_lie_system *S = ls->S;
  const char *const *gn = dm_lie_system_gnames(S);
  size_t i, nq = dm_lie_system_group(S)->nq;
  lua_createtable(L, (int)nq, 0);
  for (i = 0; i < nq; i++) {
    lua_pushstring(L, gn[i]);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

static int s_integrator(lua_State *L)
{
  return dm_lua_lie_integrator(L);
}

static const dm_reg sys_methods[] = {
  {"space", s_space, "sys:space() -> G", "The Lie group the system lives on."},
  {"param", s_param, "sys:param(name[, value]) -> number | sys",
   "Read or set a parameter (integrators pick the new value up at their next step)."},
  {"set", s_set, "sys:set{name = value, ...} -> sys",
   "Set parameters by name, all checked (known names, finite numbers) before any changes."},
  {"is_reduced", s_is_reduced, "sys:is_reduced() -> boolean",
   "True for the Euler-Poincare (reduced) form made by dm.euler_poincare."},
  {"names", s_names, "sys:names() -> {name, ...}",
   "The names of the stored numbers of g (the symbols of L and the trajectory columns)."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg lie_sys_funcs[] = {
  {"euler_poincare", l_euler_poincare, "dm.euler_poincare(sys) -> sys",
   "The reduced (discrete Euler-Poincare) form of a system on a group whose Lagrangian is "
   "invariant under left translations: integrators step mu alone and reconstruct g; an error "
   "names the derivative that is not invariant."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_liesys(lua_State *L)
{
  static const luaL_Reg meta[] = {{"__gc", sys_gc}, {"__tostring", s_tostring},
                                  {"__integrator", s_integrator}, {NULL, NULL}};
  dm_newclass(L, DM_LIESYS_MT, "liesystem", sys_methods, meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", lie_sys_funcs);
}

/* }====================================================================== */
