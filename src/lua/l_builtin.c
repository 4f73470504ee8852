/* l_builtin.c -- dm.builtin.*: the hand-written C systems of
 * builtin_systems.h as System userdata (the same type as dm.system, without
 * expressions).  They are the speed references and cross-checks of traced
 * systems; parameters change through sys.params like any system. */
#include <config.h>
#include <string.h>

#include "lua/l_system.h"
#include "core/builtin_systems.h"

/* Optional table of options at argument 1 (nil or absent: defaults);
 * unknown keys raise, so a misspelt parameter is not silently ignored. */
static void check_opts(lua_State *L, const char *fname, const char *const *known)
{
  if (lua_isnoneornil(L, 1)) {
    lua_settop(L, 0);
    lua_newtable(L);
    return;
  }
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  lua_pushnil(L);
  while (lua_next(L, 1) != 0) {
    const char *const *k = known;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key != NULL && *k != NULL && strcmp(*k, key) != 0)
      k++;
    if (key == NULL || *k == NULL) {
      luaL_Buffer b;
      luaL_buffinit(L, &b);
      for (k = known; *k != NULL; k++) {
        luaL_addstring(&b, *k);
        if (k[1] != NULL)
          luaL_addstring(&b, ", ");
      }
      luaL_pushresult(&b);
      const char *list = lua_tostring(L, -1);
      luaL_error(L, "dm.builtin.%s: unknown option %s (options: %s)", fname,
                 luaL_tolstring(L, -3, NULL), list);
    }
    lua_pop(L, 1);
  }
}

/* Fill a new System through `make` (a builtin constructor bound by the
 * caller) and finish it. */
typedef int (*make_fn)(lua_State *L, dm_system *s, dm_err *e);

static int push_builtin(lua_State *L, const char *fname, make_fn make,
                        const char *const *cyclic)
{
  dm_err e;
  dm_lsystem *ls = dm_lua_system_new(L);
  int st = make(L, &ls->sys, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, fname, st, &e);
  dm_lua_system_finish(L, ls, cyclic);
  return 1;
}

static double num(lua_State *L, const char *key, double def)
{
  return dm_optnumberfield(L, 1, key, def);
}

static int mk_harmonic(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_harmonic(s, num(L, "omega", 1.0), e);
}

static int mk_pendulum(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_pendulum(s, num(L, "k", 1.0), e);
}

static int mk_kepler(lua_State *L, dm_system *s, dm_err *e)
{
  lua_Integer dim = dm_optintegerfield(L, 1, "dim", 2);
  if (dim != 2 && dim != 3)
    luaL_error(L, "dm.builtin.kepler: dim must be 2 or 3, got %d", (int)dim);
  return dm_builtin_kepler(s, (int)dim, num(L, "mu", 1.0), e);
}

static int mk_j2(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_j2(s, num(L, "J2", 0.05), e);
}

static int mk_damped(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_damped_oscillator(s, num(L, "omega", 1.0), num(L, "c", 0.1), e);
}

static int mk_sph(lua_State *L, dm_system *s, dm_err *e)
{
  return dm_builtin_spherical_pendulum(s, num(L, "g", 9.81), num(L, "l", 1.0), e);
}

static int mk_sph_r3(lua_State *L, dm_system *s, dm_err *e)
{
  const char *f = dm_optstringfield(L, 1, "form", "squared");
  int form = strcmp(f, "norm") == 0;
  if (!form && strcmp(f, "squared") != 0)
    luaL_error(L, "dm.builtin.spherical_pendulum_r3: form must be \"squared\" (|q|^2 - l^2) "
               "or \"norm\" (|q| - l), got \"%s\"", f);
  return dm_builtin_spherical_pendulum_r3(s, num(L, "g", 9.81), num(L, "l", 1.0), form, e);
}

static int b_harmonic(lua_State *L)
{
  static const char *const k[] = {"omega", NULL};
  check_opts(L, "harmonic", k);
  return push_builtin(L, "dm.builtin.harmonic", mk_harmonic, NULL);
}

static int b_pendulum(lua_State *L)
{
  static const char *const k[] = {"k", NULL};
  check_opts(L, "pendulum", k);
  return push_builtin(L, "dm.builtin.pendulum", mk_pendulum, NULL);
}

static int b_kepler(lua_State *L)
{
  static const char *const k[] = {"dim", "mu", NULL};
  check_opts(L, "kepler", k);
  return push_builtin(L, "dm.builtin.kepler", mk_kepler, NULL);
}

static int b_j2(lua_State *L)
{
  static const char *const k[] = {"J2", NULL};
  check_opts(L, "j2", k);
  return push_builtin(L, "dm.builtin.j2", mk_j2, NULL);
}

static int b_damped(lua_State *L)
{
  static const char *const k[] = {"omega", "c", NULL};
  check_opts(L, "damped", k);
  return push_builtin(L, "dm.builtin.damped", mk_damped, NULL);
}

static int b_sph(lua_State *L)
{
  static const char *const k[] = {"g", "l", NULL};
  static const char *const cyc[] = {"phi", NULL};
  check_opts(L, "spherical_pendulum", k);
  return push_builtin(L, "dm.builtin.spherical_pendulum", mk_sph, cyc);
}

static int b_sph_r3(lua_State *L)
{
  static const char *const k[] = {"g", "l", "form", NULL};
  check_opts(L, "spherical_pendulum_r3", k);
  return push_builtin(L, "dm.builtin.spherical_pendulum_r3", mk_sph_r3, NULL);
}

static const dm_reg builtin_funcs[] = {
  {"harmonic", b_harmonic, "dm.builtin.harmonic{omega=1} -> system",
   "Harmonic oscillator L = v^2/2 - omega^2 q^2/2 written in C."},
  {"pendulum", b_pendulum, "dm.builtin.pendulum{k=1} -> system",
   "Pendulum L = v^2/2 + k cos q (k = g/l) written in C."},
  {"kepler", b_kepler, "dm.builtin.kepler{dim=2, mu=1} -> system",
   "Kepler problem L = |v|^2/2 + mu/|q| in 2 or 3 Cartesian coordinates, written in C."},
  {"j2", b_j2, "dm.builtin.j2{J2=0.05} -> system",
   "J2 satellite in Cartesian (x, y, z), V = -1/|q| + J2/|q|^3 (3z^2/(2|q|^2) - 1/2), written in C."},
  {"damped", b_damped, "dm.builtin.damped{omega=1, c=0.1} -> system",
   "Harmonic oscillator with the damping force F = -c v (Lagrange-d'Alembert), written in C."},
  {"spherical_pendulum", b_sph, "dm.builtin.spherical_pendulum{g=9.81, l=1} -> system",
   "Spherical pendulum in angles (theta from the downward vertical, phi cyclic), written in C."},
  {"spherical_pendulum_r3", b_sph_r3,
   "dm.builtin.spherical_pendulum_r3{g=9.81, l=1, form=\"squared\"|\"norm\"} -> system",
   "Spherical pendulum in R^3 with the constraint |q|^2 - l^2 = 0 (or |q| - l = 0), written in C."},
  {NULL, NULL, NULL, NULL}
};

/* dm.builtin, and dm.systems: the catalog of lua/dmech/systems.lua, whose
 * module is an installer called with the dm table being built. */
void dm_open_builtin(lua_State *L)
{
  int dm = lua_gettop(L);
  lua_newtable(L);
  dm_register(L, "dm.builtin.", builtin_funcs);
  lua_setfield(L, dm, "builtin");
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.systems");
  lua_call(L, 1, 1);
  lua_pushvalue(L, dm);
  lua_call(L, 1, 0);
}
