/* l_lie_sphere.c -- dm.lie.sphere(n): the unit sphere S^n as an object with
 * bound functions S.exp, S.log, S.dist, S.tangent, S.normalize and, for S^2
 * = SO(3)/SO(2), S.rotation and S.project.  The numerics are lie.h's
 * dm_lie_sphere_*.  See l_lie.h. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_lie.h"
#include "core/system.h"
#include "lie/lie_system.h"

/* {======================================================================
 * spheres S^n
 * ======================================================================= */

typedef struct lsphere {
  size_t n;
} lsphere;

static size_t checksphere(lua_State *L)
{
  return ((lsphere *)luaL_checkudata(L, 1, DM_LIESPHERE_MT))->n;
}

static void point(lua_State *L, int idx, size_t n, const char *fname, const char *what,
                  double *p)
{
  dm_expr ex[DM_LIE_DIM_MAX + 1];
  if (dm_lua_readvals(L, idx, n + 1, fname, what, p, ex))
    luaL_error(L, "%s: %s must be numbers", fname, what);
}

static int s_exp(lua_State *L)
{
  size_t n = checksphere(L);
  double p[DM_LIE_DIM_MAX + 1], v[DM_LIE_DIM_MAX + 1], q[DM_LIE_DIM_MAX + 1];
  point(L, 2, n, "S.exp", "p", p);
  point(L, 3, n, "S.exp", "v", v);
  dm_lie_sphere_exp(n, p, v, q);
  dm_pushvec_copy(L, q, n + 1);
  return 1;
}

static int s_log(lua_State *L)
{
  size_t n = checksphere(L);
  double p[DM_LIE_DIM_MAX + 1], q[DM_LIE_DIM_MAX + 1], v[DM_LIE_DIM_MAX + 1];
  dm_err e;
  point(L, 2, n, "S.log", "p", p);
  point(L, 3, n, "S.log", "q", q);
  if (dm_lie_sphere_log(n, p, q, v, &e) != DM_OK)
    return dm_lua_fail(L, "S.log", e.status, &e);
  dm_pushvec_copy(L, v, n + 1);
  return 1;
}

static int s_dist(lua_State *L)
{
  size_t n = checksphere(L);
  double p[DM_LIE_DIM_MAX + 1], q[DM_LIE_DIM_MAX + 1];
  point(L, 2, n, "S.dist", "p", p);
  point(L, 3, n, "S.dist", "q", q);
  lua_pushnumber(L, dm_lie_sphere_dist(n, p, q));
  return 1;
}

static int s_tangent(lua_State *L)
{
  size_t n = checksphere(L);
  double p[DM_LIE_DIM_MAX + 1], v[DM_LIE_DIM_MAX + 1];
  point(L, 2, n, "S.tangent", "p", p);
  point(L, 3, n, "S.tangent", "v", v);
  dm_lie_sphere_tangent(n, p, v, v);
  dm_pushvec_copy(L, v, n + 1);
  return 1;
}

static int s_normalize(lua_State *L)
{
  size_t n = checksphere(L);
  double p[DM_LIE_DIM_MAX + 1];
  dm_err e;
  point(L, 2, n, "S.normalize", "p", p);
  if (dm_lie_sphere_normalize(n, p, &e) != DM_OK)
    return dm_lua_fail(L, "S.normalize", e.status, &e);
  dm_pushvec_copy(L, p, n + 1);
  return 1;
}

/* S.rotation(p0, p1) -> SO3 element carrying p0 to p1 (S^2 only) */
static int s_rotation(lua_State *L)
{
  size_t n = checksphere(L), i;
  double p0[3], p1[3], R[9];
  dm_err e;
  dm_lie_group **slot;
  dm_lelem *el;
  if (n != 2)
    return luaL_error(L, "S.rotation: defined on S^2 only (this is S^%d)", (int)n);
  point(L, 2, n, "S.rotation", "p0", p0);
  point(L, 3, n, "S.rotation", "p1", p1);
  if (dm_lie_sphere_rotation(p0, p1, R, &e) != DM_OK)
    return dm_lua_fail(L, "S.rotation", e.status, &e);
  slot = dm_lua_newgroup(L);
  if ((*slot = dm_lie_so3(&e)) == NULL)
    return dm_lua_fail(L, "S.rotation", e.status, &e);
  el = dm_lua_newelem(L, lua_gettop(L), 0);
  for (i = 0; i < 9; i++)
    el->v[i].x = R[i];
  return 1;
}

/* S.project(R) -> R e3 (S^2 only) */
static int s_project(lua_State *L)
{
  size_t n = checksphere(L);
  dm_lelem *el = dm_lua_checkelem(L, 2, "S.project");
  double R[9], p[3];
  if (n != 2 || el->G->kind != DM_LIE_SO3)
    return luaL_error(L, "S.project: maps an SO3 element to S^2 (R e3)");
  dm_lua_elem_numbers(L, el, "S.project", R);
  dm_lie_sphere_project(R, p);
  dm_pushvec_copy(L, p, 3);
  return 1;
}

static const dm_reg sphere_funcs[] = {
  {"exp", s_exp, "S.exp(p, v) -> q", "The point reached from p along the geodesic with initial tangent v."},
  {"log", s_log, "S.log(p, q) -> v",
   "The tangent vector at p pointing to q of length dist(p, q); an error at the antipode."},
  {"dist", s_dist, "S.dist(p, q) -> number", "The great-circle distance, accurate at every angle."},
  {"tangent", s_tangent, "S.tangent(p, v) -> vec", "The projection of v onto the tangent space at p."},
  {"normalize", s_normalize, "S.normalize(p) -> vec", "The point p scaled onto the unit sphere."},
  {"rotation", s_rotation, "S.rotation(p0, p1) -> SO3 element",
   "S^2: the rotation about p0 x p1 carrying p0 to p1; an error when p1 = -p0."},
  {"project", s_project, "S.project(R) -> vec", "S^2 = SO(3)/SO(2): the point R e3."},
  {NULL, NULL, NULL, NULL}
};

static int sphere_fields(lua_State *L)
{
  size_t n = checksphere(L);
  const char *k = lua_tostring(L, 2);
  if (k != NULL && strcmp(k, "n") == 0) {
    lua_pushinteger(L, (lua_Integer)n);
    return 1;
  }
  return luaL_error(L, "S^%d has no field %s (fields: n)", (int)n, dm_tolstring(L, 2, NULL));
}

static int sphere_index(lua_State *L)
{
  return dm_lua_bound_index(L, "S.", sphere_fields);
}

static int sphere_tostring(lua_State *L)
{
  lua_pushfstring(L, "<sphere S^%d in R^%d>", (int)checksphere(L), (int)checksphere(L) + 1);
  return 1;
}

int dm_lua_lie_sphere(lua_State *L)
{
  lua_Integer n = luaL_optinteger(L, 1, 2);
  lsphere *s;
  if (n < 1 || n > DM_LIE_DIM_MAX)
    return luaL_error(L, "dm.lie.sphere: n must be in 1..%d, got %d", DM_LIE_DIM_MAX, (int)n);
  s = lua_newuserdatauv(L, sizeof *s, 1);
  s->n = (size_t)n;
  luaL_setmetatable(L, DM_LIESPHERE_MT);
  lua_newtable(L);
  lua_setiuservalue(L, -2, 1);
  return 1;
}

/* {======================================================================
 * systems on spheres: dm.system{space = dm.lie.sphere(n), ...}
 * ======================================================================= */

size_t dm_lua_tosphere(lua_State *L, int idx)
{
  lsphere *s = luaL_testudata(L, idx, DM_LIESPHERE_MT);
  return s != NULL ? s->n : 0;
}

/* Replace the table at 1 by a copy without 'space', with coords
 * x1 .. x(n+1) when it has none; constraints are refused (the sphere is
 * the constraint). */
void dm_lua_sphere_fields(lua_State *L, size_t n)
{
  luaL_checktype(L, 1, LUA_TTABLE);
  if (lua_getfield(L, 1, "constraints") != LUA_TNIL)
    luaL_error(L, "dm.system: a system on the sphere S^%d takes no 'constraints' (|x| = 1 is "
               "the space's)", (int)n);
  lua_pop(L, 1);
  lua_newtable(L);
  lua_pushnil(L);
  while (lua_next(L, 1) != 0) {
    if (lua_type(L, -2) == LUA_TSTRING && strcmp(lua_tostring(L, -2), "space") == 0) {
      lua_pop(L, 1);
      continue;
    }
    lua_pushvalue(L, -2);
    lua_insert(L, -2);
    lua_rawset(L, -4);
  }
  if (lua_getfield(L, -1, "coords") == LUA_TNIL) {
    lua_createtable(L, (int)n + 1, 0);
    for (size_t i = 0; i <= n; i++) {
      lua_pushfstring(L, "x%d", (int)i + 1);
      lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -3, "coords");
  }
  lua_pop(L, 1);
  lua_replace(L, 1);
}

/* S^2: the momentum map of SO(3) acting on it, the angular momentum x ^ p */
static void angular_momentum(const dm_system *sys, const double *x, const double *p, double *J)
{
  (void)sys;
  J[0] = x[1] * p[2] - x[2] * p[1];
  J[1] = x[2] * p[0] - x[0] * p[2];
  J[2] = x[0] * p[1] - x[1] * p[0];
}

/* Make the traced system one on S^n (kind "sphere", its families; on S^2
 * runs record the angular momentum). */
void dm_lua_sphere_system(lua_State *L, dm_system *sys, size_t n)
{
  static const char *const names[] = {"S^1", "S^2", "S^3", "S^4", "S^5", "S^6", "S^7", "S^8"};
  dm_err e;
  int st;
  if (sys->n != n + 1)
    luaL_error(L, "dm.system: a system on the sphere S^%d has %d coordinates (the point in "
               "R^%d), got %d", (int)n, (int)n + 1, (int)n + 1, (int)sys->n);
  if ((st = dm_lie_register_integrators(&e)) != DM_OK)
    dm_lua_fail(L, "dm.system", st, &e);
  sys->kind = DM_SYSTEM_SPHERE;
  sys->space = n <= 8 ? names[n - 1] : "S^n";
  if (n == 2)
    sys->momentum_map = angular_momentum;
}

/* }====================================================================== */

void dm_lua_open_liesphere(lua_State *L)
{
  static const luaL_Reg smeta[] = {{"__index", sphere_index}, {"__tostring", sphere_tostring},
                                   {NULL, NULL}};
  dm_lua_newclass_bound(L, DM_LIESPHERE_MT, "liesphere", "S.", sphere_funcs, smeta);
}
