/* l_builtin.c -- the C implementations of catalogue systems
 * (src/core/builtin_systems.h), offered as dm.systems.<name>{impl = "c"}:
 * the same Lagrangian, coordinates and parameters as the traced entry,
 * written by hand -- the speed references and cross-checks of traced
 * systems.  The constructors are not part of `dm`: the opener hands them
 * to the catalogue (lua/dmech/systems.lua), which has already checked the
 * parameter names and types, as a table {name = constructor}; each takes a
 * table of parameter values (and the entry's options: dim, form). */
#include <config.h>
#include <string.h>

#include "lua/l_system.h"
#include "core/builtin_systems.h"

typedef int (*make_fn)(lua_State *L, dm_system *s, dm_err *e);

/* Fill a new System through `make` and finish it. */
static int push_builtin(lua_State *L, const char *fname, make_fn make, const char *const *cyclic)
{
  dm_err e;
  dm_lsystem *ls;
  luaL_checktype(L, 1, LUA_TTABLE);
  ls = dm_lua_system_new(L);
  int st = make(L, &ls->sys, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, fname, st, &e);
  dm_lua_system_finish(L, ls, cyclic);
  return 1;
}

static double num(lua_State *L, const char *key)
{
  return dm_optnumberfield(L, 1, key, 0.0);
}

static int mk_harmonic(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_harmonic(s, num(L, "m"), num(L, "omega"), e);
}

static int mk_damped(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_damped_oscillator(s, num(L, "m"), num(L, "omega"), num(L, "c"), e);
}

static int mk_pendulum(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_pendulum(s, num(L, "g"), num(L, "l"), num(L, "m"), e);
}

static int mk_kepler(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_kepler(s, (int)dm_optintegerfield(L, 1, "dim", 2), num(L, "mu"), e);
}

static int mk_j2(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_j2(s, num(L, "J2"), e);
}

static int mk_sph(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_spherical_pendulum(s, num(L, "g"), num(L, "l"), num(L, "m"), e);
}

static int mk_sph_r3(lua_State *L, dm_system *s, dm_err *e)
{
  int form = strcmp(dm_optstringfield(L, 1, "form", "squared"), "norm") == 0;
  return dm_builtin_spherical_pendulum_r3(s, num(L, "g"), num(L, "l"), num(L, "m"), form, e);
}

static int c_harmonic(lua_State *L) { return push_builtin(L, "dm.systems.harmonic", mk_harmonic, NULL); }
static int c_damped(lua_State *L) { return push_builtin(L, "dm.systems.damped", mk_damped, NULL); }
static int c_pendulum(lua_State *L) { return push_builtin(L, "dm.systems.pendulum", mk_pendulum, NULL); }
static int c_kepler(lua_State *L) { return push_builtin(L, "dm.systems.kepler", mk_kepler, NULL); }
static int c_j2(lua_State *L) { return push_builtin(L, "dm.systems.j2", mk_j2, NULL); }
static int c_sph_r3(lua_State *L)
{
  return push_builtin(L, "dm.systems.spherical_pendulum_r3", mk_sph_r3, NULL);
}
static int c_sph(lua_State *L)
{
  static const char *const cyc[] = {"phi", NULL};
  return push_builtin(L, "dm.systems.spherical_pendulum", mk_sph, cyc);
}

static const luaL_Reg c_impls[] = {
  {"harmonic", c_harmonic}, {"damped", c_damped}, {"pendulum", c_pendulum},
  {"kepler", c_kepler}, {"j2", c_j2}, {"spherical_pendulum", c_sph},
  {"spherical_pendulum_r3", c_sph_r3}, {NULL, NULL}
};

/* dm.systems: the catalog of lua/dmech/systems.lua, whose module is an
 * installer called with the dm table being built and the C constructors. */
void dm_open_builtin(lua_State *L)
{
  int dm = lua_gettop(L);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.systems");
  lua_call(L, 1, 1);
  lua_pushvalue(L, dm);
  luaL_newlib(L, c_impls);
  lua_call(L, 2, 0);
}
