/* l_rng.c -- dm.rng(seed): GSL's Mersenne twister, seeded, as a userdata
 * "dmech.rng" (rng:uniform, rng:gaussian, rng:integer).  dm.ensemble hands
 * one to its generators (l_ensemble.h). */
#include <config.h>
#include <math.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "lua/l_ensemble.h"

#define RNG_MT "dmech.rng"

typedef struct lrng {
  gsl_rng *r;
} lrng;

gsl_rng *dm_lua_checkrng(lua_State *L, int idx)
{
  lrng *u = luaL_checkudata(L, idx, RNG_MT);
  if (u->r == NULL)
    luaL_argerror(L, idx, "random generator is closed");
  return u->r;
}

void dm_lua_pushrng(lua_State *L, unsigned long seed)
{
  lrng *u = lua_newuserdatauv(L, sizeof *u, 0);
  u->r = NULL;
  luaL_setmetatable(L, RNG_MT);
  if ((u->r = gsl_rng_alloc(gsl_rng_mt19937)) == NULL)
    luaL_error(L, "dm.rng: out of memory");
  gsl_rng_set(u->r, seed);
}

static int rng_gc(lua_State *L)
{
  lrng *u = luaL_checkudata(L, 1, RNG_MT);
  gsl_rng_free(u->r);
  u->r = NULL;
  return 0;
}

static int rng_tostring(lua_State *L)
{
  lrng *u = luaL_checkudata(L, 1, RNG_MT);
  lua_pushstring(L, u->r != NULL ? "<rng mt19937>" : "<rng (closed)>");
  return 1;
}

static lua_Integer check_seed(lua_State *L, int idx)
{
  lua_Integer s = luaL_checkinteger(L, idx);
  if (s < 0 || s > 0xffffffffLL)
    luaL_argerror(L, idx, "seed in 0 .. 2^32-1 expected");
  return s;
}

/* dm.rng(seed) */
static int l_rng(lua_State *L)
{
  dm_lua_pushrng(L, (unsigned long)check_seed(L, 1));
  return 1;
}

/* rng:uniform([a, b]) in [a, b), default [0, 1) */
static int rng_uniform(lua_State *L)
{
  gsl_rng *r = dm_lua_checkrng(L, 1);
  double a = luaL_optnumber(L, 2, 0.0), b = luaL_optnumber(L, 3, 1.0);
  if (!(a < b) || !isfinite(a) || !isfinite(b))
    return luaL_error(L, "rng:uniform: need finite a < b, got %f, %f", a, b);
  lua_pushnumber(L, a + (b - a) * gsl_rng_uniform(r));
  return 1;
}

/* rng:gaussian([sigma[, mean]]) */
static int rng_gaussian(lua_State *L)
{
  gsl_rng *r = dm_lua_checkrng(L, 1);
  double sigma = luaL_optnumber(L, 2, 1.0), mean = luaL_optnumber(L, 3, 0.0);
  if (!(sigma >= 0) || !isfinite(sigma) || !isfinite(mean))
    return luaL_error(L, "rng:gaussian: need a finite sigma >= 0 and mean");
  lua_pushnumber(L, mean + gsl_ran_gaussian_ziggurat(r, sigma));
  return 1;
}

/* rng:integer(n) in 1 .. n */
static int rng_integer(lua_State *L)
{
  gsl_rng *r = dm_lua_checkrng(L, 1);
  lua_Integer n = luaL_checkinteger(L, 2);
  if (n < 1 || n > 0xffffffffLL)
    return luaL_argerror(L, 2, "n in 1 .. 2^32-1 expected");
  lua_pushinteger(L, 1 + (lua_Integer)gsl_rng_uniform_int(r, (unsigned long)n));
  return 1;
}

/* }====================================================================== */

static const dm_reg rng_funcs[] = {
  {"rng", l_rng, "dm.rng(seed) -> rng",
   "A GSL Mersenne-twister random generator seeded with seed (0 .. 2^32-1); dm.ensemble gives its generators one per member, seeded from its seed and the member's number."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg rng_methods[] = {
  {"uniform", rng_uniform, "rng:uniform([a, b]) -> number",
   "A uniform deviate in [a, b) (default [0, 1))."},
  {"gaussian", rng_gaussian, "rng:gaussian([sigma[, mean]]) -> number",
   "A normal deviate with standard deviation sigma (1) and mean (0)."},
  {"integer", rng_integer, "rng:integer(n) -> integer",
   "A uniform integer in 1 .. n."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg rng_meta[] = {
  {"__gc", rng_gc},
  {"__close", rng_gc},
  {"__tostring", rng_tostring},
  {NULL, NULL}
};

void dm_open_rng(lua_State *L)
{
  dm_newclass(L, RNG_MT, "rng", rng_methods, rng_meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", rng_funcs);
}
