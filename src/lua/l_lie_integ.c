/* l_lie_integ.c -- integrators of systems on Lie groups in Lua:
 * dm.integrator(sys, {method = "lgvi" | "lie:gauss" | "lie:gauss:cayley",
 * h =, stages =, tol =, maxiter =, simplified =}) for a dm.system{space =}
 * (through the system's __integrator), with run (into a trajectory of g,
 * mu, xi, energy and spatial momentum), step, the diagnostics, and
 * traj:group(k).  The numerics are src/lie (lie_system.h). */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lua/l_lie_sys.h"
#include "lua/l_integ.h"

typedef struct dm_llinteg {
  dm_integrator *I;             /* NULL once closed */
  const dm_lie_system *S;       /* borrowed; the system is user value 1 */
  double h;                     /* NAN: not set */
} dm_llinteg;

static int integ_gc(lua_State *L)
{
  dm_llinteg *li = luaL_checkudata(L, 1, DM_LIEINTEG_MT);
  dm_integrator_free(li->I);
  li->I = NULL;
  return 0;
}

static dm_llinteg *checkinteg(lua_State *L, int idx)
{
  dm_llinteg *li = luaL_checkudata(L, idx, DM_LIEINTEG_MT);
  if (li->I == NULL)
    luaL_error(L, "attempt to use a closed integrator");
  return li;
}

dm_integrator *dm_lua_lie_tointeg(lua_State *L, int idx, const dm_lie_system **S, double *h)
{
  dm_llinteg *li = luaL_testudata(L, idx, DM_LIEINTEG_MT);
  if (li == NULL || li->I == NULL)
    return NULL;
  *S = li->S;
  *h = li->h;
  return li->I;
}

/* the group userdata of the integrator's system */
static void push_space(lua_State *L, int idx)
{
  lua_getiuservalue(L, idx, 1);
  lua_getiuservalue(L, -1, 1);
  lua_remove(L, -2);
}

static double step_size(lua_State *L, const char *fname, double h)
{
  if (!isfinite(h) || !(h > 0.0))
    luaL_error(L, "%s: h must be a finite number > 0, got %f", fname, h);
  return h;
}

/* dm.integrator(sys, opts) */
int dm_lua_lie_integrator(lua_State *L)
{
  static const char *const keys[] = {"method", "h", "stages", "tol", "maxiter", "simplified",
                                     NULL};
  dm_llsys *ls = dm_lua_checklsys(L, 1);
  const char *method;
  dm_integ_opts opt;
  dm_llinteg *li;
  dm_err e;
  const dm_integrator_type *type;
  int st;
  if (lua_isnoneornil(L, 2)) {
    lua_settop(L, 1);
    lua_newtable(L);
  }
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  method = dm_optstringfield(L, 2, "method", "lgvi");
  if ((st = dm_lie_register_integrators(&e)) != DM_OK)
    return dm_lua_fail(L, "dm.integrator", st, &e);
  type = dm_integrator_select(dm_lie_system_base(ls->S), method, NULL, &e);
  if (type == NULL)
    return dm_lua_fail(L, "dm.integrator", e.status, &e);
  dm_integ_opts_init(&opt);
  li = lua_newuserdatauv(L, sizeof *li, 1);                  /* 3 */
  li->I = NULL;
  li->S = ls->S;
  li->h = NAN;
  luaL_setmetatable(L, DM_LIEINTEG_MT);
  lua_pushvalue(L, 1);
  lua_setiuservalue(L, 3, 1);
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    const char *const *k = keys;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key && *k && strcmp(*k, key) != 0)
      k++;
    if (key == NULL || *k == NULL)
      return luaL_error(L, "dm.integrator: unknown option %s for a system on a Lie group "
                        "(options: method, h, stages, tol, maxiter, simplified)",
                        dm_tolstring(L, -2, NULL));
    if (strcmp(key, "method") != 0) {
      double v;
      if (strcmp(key, "simplified") == 0 && lua_isboolean(L, -1))
        v = lua_toboolean(L, -1);
      else if (lua_type(L, -1) == LUA_TNUMBER)
        v = lua_tonumber(L, -1);
      else
        return luaL_error(L, "dm.integrator: option '%s' must be a number, got %s", key,
                          luaL_typename(L, -1));
      if (strcmp(key, "h") == 0)
        li->h = step_size(L, "dm.integrator", v);
      else if (!dm_integrator_has_option(type, key))
        return luaL_error(L, "dm.integrator: option '%s' does not apply to method '%s'", key,
                          method);
      else if ((st = dm_integ_opts_set_number(&opt, key, v, &e)) != DM_OK)
        return dm_lua_fail(L, "dm.integrator", st, &e);
    }
    lua_pop(L, 1);
  }
  if ((st = dm_integrator_new(dm_lie_system_base(ls->S), method, &opt, &li->I, &e)) != DM_OK)
    return dm_lua_fail(L, "dm.integrator", st, &e);
  lua_settop(L, 3);
  return 1;
}

static double get_h(lua_State *L, dm_llinteg *li, int idx, const char *fname)
{
  double h = li->h;
  if (idx != 0 && !lua_isnoneornil(L, idx))
    h = luaL_checknumber(L, idx);
  if (isnan(h))
    luaL_error(L, "%s: no step size: give h in dm.integrator(sys, {h = ...}) or to this call",
               fname);
  return step_size(L, fname, h);
}

/* {======================================================================
 * run and step
 * ======================================================================= */

/* I:run(state, {t = | steps =, every =, h =, ...}) -> traj[, message]:
 * the core run driver, as integ:run of every other system */
static int l_run(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  dm_lstate_lie s;
  if (lua_isnoneornil(L, 3)) {
    lua_settop(L, 2);
    lua_newtable(L);
  }
  luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  dm_lua_lie_readstate(L, li->I, li->S, 2, "run", &s);
  return dm_lua_integ_run(L, li->I, NULL, 3, li->h, s.t, s.g, s.mu);
}

/* I:step(state[, h]) -> state */
static int l_step(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  dm_lstate_lie s;
  double g1[DM_LIE_NQ_MAX], mu1[DM_LIE_DIM_MAX], xi1[DM_LIE_DIM_MAX], h;
  dm_err e;
  int st;
  dm_lua_lie_readstate(L, li->I, li->S, 2, "step", &s);
  h = get_h(L, li, 3, "step");
  if ((st = dm_integrator_step(li->I, h, s.g, s.mu, g1, mu1, &e)) != DM_OK ||
      (st = dm_lie_velocity(li->I, g1, mu1, xi1, &e)) != DM_OK)
    return dm_lua_fail(L, "step", st, &e);
  push_space(L, 1);
  dm_lua_lie_pushstate(L, -1, li->S, s.t + h, g1, mu1, xi1);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * diagnostics
 * ======================================================================= */

static int l_energy(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  dm_lstate_lie s;
  double E;
  dm_err e;
  int st;
  dm_lua_lie_readstate(L, li->I, li->S, 2, "energy", &s);
  if ((st = dm_lie_energy(li->I, s.g, s.mu, &E, &e)) != DM_OK)
    return dm_lua_fail(L, "energy", st, &e);
  lua_pushnumber(L, E);
  return 1;
}

static int l_momentum(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  const dm_lie_group *G = dm_lie_system_group(li->S);
  dm_lstate_lie s;
  double J[DM_LIE_DIM_MAX];
  dm_lua_lie_readstate(L, li->I, li->S, 2, "momentum", &s);
  dm_lie_spatial_momentum(G, s.g, s.mu, J);
  dm_pushvec_copy(L, J, G->dim);
  return 1;
}

static int l_casimirs(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  const dm_lie_group *G = dm_lie_system_group(li->S);
  dm_lstate_lie s;
  double c[DM_LIE_DIM_MAX + 1];
  size_t k;
  dm_lua_lie_readstate(L, li->I, li->S, 2, "casimirs", &s);
  k = dm_lie_casimirs(G, s.mu, c);
  dm_pushvec_copy(L, c, k);
  return 1;
}

static int l_symplecticity_defect(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  dm_lstate_lie s;
  double d, h;
  dm_err e;
  int st;
  dm_lua_lie_readstate(L, li->I, li->S, 2, "symplecticity_defect", &s);
  h = get_h(L, li, 3, "symplecticity_defect");
  if ((st = dm_lie_symplecticity_defect(li->I, h, s.g, s.mu, &d, &e)) != DM_OK)
    return dm_lua_fail(L, "symplecticity_defect", st, &e);
  lua_pushnumber(L, d);
  return 1;
}

static int l_reversal(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  dm_lstate_lie s;
  lua_Integer n;
  double d, h;
  dm_err e;
  int st;
  dm_lua_lie_readstate(L, li->I, li->S, 2, "reversal", &s);
  n = luaL_checkinteger(L, 3);
  if (n < 1)
    return luaL_error(L, "reversal: n must be >= 1, got %d", (int)n);
  h = get_h(L, li, 4, "reversal");
  if ((st = dm_lie_reversal(li->I, h, (long)n, s.g, s.mu, &d, &e)) != DM_OK)
    return dm_lua_fail(L, "reversal", st, &e);
  lua_pushnumber(L, d);
  return 1;
}

/* I:order_estimate{state =, t =, h = {...}} -> order, errors */
static int l_order_estimate(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  dm_lstate_lie s;
  double hs[64], err[64], order, T;
  size_t k, i;
  dm_err e;
  int st;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_getfield(L, 2, "state");
  dm_lua_lie_readstate(L, li->I, li->S, -1, "order_estimate", &s);
  lua_pop(L, 1);
  T = dm_optnumberfield(L, 2, "t", NAN);
  if (!(T > 0.0))
    return luaL_error(L, "order_estimate: t (the final time) must be > 0");
  if (lua_getfield(L, 2, "h") != LUA_TTABLE || (k = lua_rawlen(L, -1)) < 2 || k > 64)
    return luaL_error(L, "order_estimate: h must be a list of 2 to 64 step sizes");
  for (i = 0; i < k; i++) {
    lua_rawgeti(L, -1, (lua_Integer)i + 1);
    hs[i] = step_size(L, "order_estimate", luaL_checknumber(L, -1));
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  if ((st = dm_lie_order_estimate(li->S, li->I->name, &li->I->opt, s.g, s.mu, T, hs, k, err,
                                  &order, &e)) != DM_OK)
    return dm_lua_fail(L, "order_estimate", st, &e);
  lua_pushnumber(L, order);
  dm_pushvec_copy(L, err, k);
  return 2;
}

static int l_index(lua_State *L)
{
  dm_llinteg *li = checkinteg(L, 1);
  const char *k = dm_checkcstring(L, 2);
  if (luaL_getmetafield(L, 1, "__methods") != LUA_TNIL) {
    lua_pushvalue(L, 2);
    if (lua_rawget(L, -2) != LUA_TNIL)
      return 1;
  }
  if (strcmp(k, "method") == 0)
    lua_pushstring(L, li->I->name);
  else if (strcmp(k, "h") == 0)
    lua_pushnumber(L, li->h);
  else if (strcmp(k, "order") == 0)
    lua_pushinteger(L, li->I->order);
  else if (strcmp(k, "system") == 0)
    lua_getiuservalue(L, 1, 1);
  else
    return luaL_error(L, "integrator has no field '%s' (fields: method, h, order, system)", k);
  return 1;
}

static int l_tostring(lua_State *L)
{
  dm_llinteg *li = luaL_checkudata(L, 1, DM_LIEINTEG_MT);
  if (li->I == NULL)
    lua_pushliteral(L, "<Integrator (closed)>");
  else if (isnan(li->h))
    lua_pushfstring(L, "<Integrator %s (order %d) on '%s'>", li->I->name, li->I->order,
                    dm_lie_system_base(li->S)->name);
  else
    lua_pushfstring(L, "<Integrator %s (order %d) h=%f on '%s'>", li->I->name, li->I->order,
                    li->h, dm_lie_system_base(li->S)->name);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * traj:group(k)
 * ======================================================================= */

static int traj_group(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  lua_Integer k = luaL_checkinteger(L, 2);
  size_t len = dm_traj_len(tr);
  double g[DM_LIE_NQ_MAX];
  dm_lie_group **slot;
  dm_lelem *el;
  dm_err e;
  size_t i;
  if (k < 0)
    k += (lua_Integer)len + 1;
  if (k < 1 || (size_t)k > len)
    return luaL_error(L, "traj:group: sample %d out of range 1..%d", (int)k, (int)len);
  slot = dm_lua_newgroup(L);
  if (dm_lie_traj_group(tr, slot, &e) != DM_OK)
    return luaL_error(L, "traj:group: %s", e.msg);
  if (dm_lie_traj_element(tr, *slot, (size_t)k - 1, g, &e) != DM_OK)
    return luaL_error(L, "traj:group: %s", e.msg);
  el = dm_lua_newelem(L, -1, 0);
  for (i = 0; i < (*slot)->nq; i++)
    el->v[i].x = g[i];
  return 1;
}

static const dm_reg traj_ext[] = {
  {"group", traj_group, "traj:group(k) -> g",
   "The group element at sample k of a run of a system on a Lie group (k < 0 counts from the end)."},
  {NULL, NULL, NULL, NULL}
};

/* }====================================================================== */

static const dm_reg integ_methods[] = {
  {"run", l_run, "integ:run({g =, mu = | xi = [, t =]}, {t = | steps =, every =, h =, ...}) -> traj[, message]",
   "Integrate into a trajectory with the stored numbers of g, mu1.., xi1.., energy and the "
   "spatial momentum momentum_1.. (the run options of every integrator: progress, chunk, "
   "max_energy_error, sink, strict, warn; momentum = false drops the momentum columns); an "
   "early end returns what was computed and a message."},
  {"step", l_step, "integ:step(state[, h]) -> state", "One step: {t, g, mu, xi} at t + h."},
  {"energy", l_energy, "integ:energy(state) -> number", "The energy mu . xi - L at the state."},
  {"momentum", l_momentum, "integ:momentum(state) -> vec",
   "The spatial momentum Ad*_(g^-1) mu (conserved when L is invariant under left translations)."},
  {"casimirs", l_casimirs, "integ:casimirs(state) -> vec",
   "The Casimirs of the Lie-Poisson bracket at mu (SO3: |mu|^2; SE3: |p|^2 and w.p)."},
  {"symplecticity_defect", l_symplecticity_defect,
   "integ:symplecticity_defect(state[, h]) -> number",
   "The defect max |DPhi^T Omega DPhi - Omega| of the step map on T*G (left trivialization, "
   "central differences)."},
  {"reversal", l_reversal, "integ:reversal(state, n[, h]) -> number",
   "The distance from the start after n steps with h and n with -h (0 for symmetric methods)."},
  {"order_estimate", l_order_estimate,
   "integ:order_estimate{state =, t =, h = {h1, h2, ...}} -> order, errors",
   "The empirical order by step halving against a 6-stage lie:gauss reference."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_lieinteg(lua_State *L)
{
  static const luaL_Reg meta[] = {{"__index", l_index}, {"__gc", integ_gc}, {"__close", integ_gc},
                                  {"__tostring", l_tostring}, {NULL, NULL}};
  dm_newclass(L, DM_LIEINTEG_MT, "lieinteg", integ_methods, meta);
  lua_pop(L, 1);
  /* traj:group on the trajectory class */
  luaL_getmetatable(L, DM_TRAJ_MT);
  if (lua_getfield(L, -1, "__methods") == LUA_TTABLE)
    dm_register(L, "traj:", traj_ext);
  lua_pop(L, 2);
}
