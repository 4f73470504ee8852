/* l_dec_cochain.c -- Cochain: values on the primal k-simplices or on the
 * dual cells of a mesh, with degree and side.  Arithmetic only between
 * cochains of one type on one mesh; indexing is 1-based. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "core/numfmt.h"
#include "lua/l_dec.h"

dm_lcochain *dm_tocochain(lua_State *L, int arg)
{
  return luaL_testudata(L, arg, DM_COCHAIN_MT);
}

dm_lcochain *dm_checkcochain(lua_State *L, int arg)
{
  return luaL_checkudata(L, arg, DM_COCHAIN_MT);
}

dm_lcochain *dm_newcochain(lua_State *L, int mesh_idx, dm_ltype t)
{
  dm_lmesh *M;
  dm_lcochain *c;
  int n;
  mesh_idx = lua_absindex(L, mesh_idx);
  M = dm_checkmesh(L, mesh_idx);
  n = dm_dec_typesize(M->K, t);
  c = lua_newuserdatauv(L, sizeof *c + (size_t)n * sizeof(double), 1);
  c->K = M->K;
  c->t = t;
  c->n = n;
  c->v = (double *)(c + 1);
  memset(c->v, 0, (size_t)n * sizeof(double));
  luaL_setmetatable(L, DM_COCHAIN_MT);
  lua_pushvalue(L, mesh_idx);
  lua_setiuservalue(L, -2, 1);
  return c;
}

/* A new cochain of a's type on a's mesh (a at index idx). */
static dm_lcochain *like(lua_State *L, int idx)
{
  dm_lcochain *a = dm_checkcochain(L, idx);
  dm_lcochain *c;
  lua_getiuservalue(L, idx, 1);
  c = dm_newcochain(L, -1, a->t);
  lua_remove(L, -2);
  return c;
}

static int index_arg(lua_State *L, const dm_lcochain *c, int arg)
{
  lua_Integer i = luaL_checkinteger(L, arg);
  if (i < 1 || i > c->n)
    luaL_error(L, "cochain index %I out of range 1..%d", i, c->n);
  return (int)i - 1;
}

static int c_index(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  if (lua_type(L, 2) == LUA_TNUMBER) {
    lua_pushnumber(L, c->v[index_arg(L, c, 2)]);
    return 1;
  }
  luaL_getmetafield(L, 1, "__methods");
  lua_pushvalue(L, 2);
  lua_rawget(L, -2);
  return 1;
}

static int c_newindex(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  int i;
  if (lua_type(L, 2) != LUA_TNUMBER)
    return luaL_error(L, "cannot set field '%s' of a cochain", dm_tolstring(L, 2, NULL));
  i = index_arg(L, c, 2);
  c->v[i] = luaL_checknumber(L, 3);
  return 0;
}

static int c_len(lua_State *L)
{
  lua_pushinteger(L, dm_checkcochain(L, 1)->n);
  return 1;
}

static void same_type(lua_State *L, const char *op, const dm_lcochain *a, const dm_lcochain *b)
{
  if (a->K != b->K)
    luaL_error(L, "cochain %s cochain: the cochains live on different meshes", op);
  if (a->t.deg != b->t.deg || a->t.dual != b->t.dual)
    luaL_error(L, "cochain %s cochain: %s and %s", op, dm_dec_typename(L, a->t),
               dm_dec_typename(L, b->t));
}

static int addsub(lua_State *L, double sg, const char *op)
{
  dm_lcochain *a = dm_tocochain(L, 1), *b = dm_tocochain(L, 2), *c;
  int i;
  if (a == NULL || b == NULL)
    return luaL_error(L, "cochain %s %s: both operands must be cochains",
                      op, luaL_typename(L, a == NULL ? 1 : 2));
  same_type(L, op, a, b);
  c = like(L, 1);
  for (i = 0; i < c->n; i++)
    c->v[i] = a->v[i] + sg * b->v[i];
  return 1;
}

static int c_add(lua_State *L) { return addsub(L, 1.0, "+"); }
static int c_sub(lua_State *L) { return addsub(L, -1.0, "-"); }

static int c_mul(lua_State *L)
{
  int ci = dm_tocochain(L, 1) != NULL ? 1 : 2, i;
  dm_lcochain *a, *c;
  double s;
  if (!lua_isnumber(L, 3 - ci)) {
    if (dm_tocochain(L, 1) != NULL && dm_tocochain(L, 2) != NULL)
      return luaL_error(L, "cochain * cochain: use M:wedge(a, b) for the wedge product");
    return luaL_error(L, "cochain * %s: number expected", luaL_typename(L, 3 - ci));
  }
  s = lua_tonumber(L, 3 - ci);
  a = dm_checkcochain(L, ci);
  c = like(L, ci);
  for (i = 0; i < c->n; i++)
    c->v[i] = s * a->v[i];
  return 1;
}

static int c_div(lua_State *L)
{
  dm_lcochain *a = dm_checkcochain(L, 1), *c;
  double s = luaL_checknumber(L, 2);
  int i;
  c = like(L, 1);
  for (i = 0; i < c->n; i++)
    c->v[i] = a->v[i] / s;
  return 1;
}

static int c_unm(lua_State *L)
{
  dm_lcochain *a = dm_checkcochain(L, 1), *c = like(L, 1);
  int i;
  for (i = 0; i < c->n; i++)
    c->v[i] = -a->v[i];
  return 1;
}

static int c_tostring(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  luaL_Buffer b;
  char num[32];
  int i, shown = c->n < 6 ? c->n : 6;
  luaL_buffinit(L, &b);
  luaL_addstring(&b, dm_dec_typename(L, c->t));
  lua_pop(L, 1);
  lua_pushfstring(L, "[%d]{", c->n);
  luaL_addvalue(&b);
  for (i = 0; i < shown; i++) {
    dm_num_format(num, sizeof num, c->v[i]);
    if (i > 0)
      luaL_addstring(&b, ", ");
    luaL_addstring(&b, num);
  }
  luaL_addstring(&b, c->n > shown ? ", ...}" : "}");
  luaL_pushresult(&b);
  return 1;
}

static int c_totable(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  int i;
  lua_createtable(L, c->n, 0);
  for (i = 0; i < c->n; i++) {
    lua_pushnumber(L, c->v[i]);
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

static int c_vec(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  if (c->n == 0)
    return luaL_error(L, "cochain:vec: the cochain is empty");
  dm_pushvec_copy(L, c->v, (size_t)c->n);
  return 1;
}

static int c_norm(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  double p = luaL_optnumber(L, 2, 2.0), s = 0.0, m = 0.0;
  int i;
  if (!(p >= 1))
    return luaL_argerror(L, 2, "p >= 1 expected");
  for (i = 0; i < c->n; i++)
    m = fmax(m, fabs(c->v[i]));
  if (isinf(p) || m == 0.0) {
    lua_pushnumber(L, m);
    return 1;
  }
  for (i = 0; i < c->n; i++)
    s += pow(fabs(c->v[i]) / m, p);
  lua_pushnumber(L, m * pow(s, 1.0 / p));
  return 1;
}

static int c_degree(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  lua_pushinteger(L, c->t.deg);
  lua_pushstring(L, c->t.dual ? "dual" : "primal");
  return 2;
}

static int c_minmax(lua_State *L, int max)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  int i, k = 0;
  if (c->n == 0)
    return luaL_error(L, "cochain:%s: the cochain is empty", max ? "max" : "min");
  for (i = 1; i < c->n; i++)
    if (max ? c->v[i] > c->v[k] : c->v[i] < c->v[k])
      k = i;
  lua_pushnumber(L, c->v[k]);
  lua_pushinteger(L, k + 1);
  return 2;
}

static int c_min(lua_State *L) { return c_minmax(L, 0); }
static int c_max(lua_State *L) { return c_minmax(L, 1); }

static int c_sum(lua_State *L)
{
  dm_lcochain *c = dm_checkcochain(L, 1);
  double s = 0.0, comp = 0.0;
  int i;
  for (i = 0; i < c->n; i++) {          /* Kahan */
    double y = c->v[i] - comp, t = s + y;
    comp = (t - s) - y;
    s = t;
  }
  lua_pushnumber(L, s);
  return 1;
}

static int c_copy(lua_State *L)
{
  dm_lcochain *a = dm_checkcochain(L, 1), *c = like(L, 1);
  memcpy(c->v, a->v, (size_t)a->n * sizeof(double));
  return 1;
}

static int c_mesh(lua_State *L)
{
  dm_checkcochain(L, 1);
  lua_getiuservalue(L, 1, 1);
  return 1;
}

static const dm_reg cochain_methods[] = {
  {"totable", c_totable, "c:totable() -> {numbers}", "The values as a Lua table (1-based, in simplex order)."},
  {"vec", c_vec, "c:vec() -> vec", "The values as a dm.vec (a copy)."},
  {"norm", c_norm, "c:norm([p]) -> number",
   "The p-norm of the values (p = 2 by default, math.huge for the largest magnitude)."},
  {"degree", c_degree, "c:degree() -> k, \"primal\" | \"dual\"",
   "The degree of the cochain and whether it lives on primal simplices or dual cells."},
  {"min", c_min, "c:min() -> value, index", "The smallest value and its (1-based) index."},
  {"max", c_max, "c:max() -> value, index", "The largest value and its (1-based) index."},
  {"sum", c_sum, "c:sum() -> number", "The compensated sum of the values."},
  {"copy", c_copy, "c:copy() -> cochain", "An independent copy of the cochain."},
  {"mesh", c_mesh, "c:mesh() -> mesh", "The mesh the cochain lives on."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg cochain_meta[] = {
  {"__index", c_index}, {"__newindex", c_newindex}, {"__len", c_len},
  {"__add", c_add}, {"__sub", c_sub}, {"__mul", c_mul}, {"__div", c_div},
  {"__unm", c_unm}, {"__tostring", c_tostring}, {NULL, NULL}
};

void dm_open_cochain(lua_State *L)
{
  dm_newclass(L, DM_COCHAIN_MT, "cochain", cochain_methods, cochain_meta);
  lua_pop(L, 1);
}
