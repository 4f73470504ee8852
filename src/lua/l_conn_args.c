/* l_conn_args.c -- what the connection bindings read and push alike
 * (l_conn.h): option keys and transport options, shape points, lists of
 * them, group elements, and holonomy result tables. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lua/l_conn.h"

void dm_lua_conn_checkkeys(lua_State *L, int idx, const char *fname, const char *const *known)
{
  idx = lua_absindex(L, idx);
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    int ok = 0;
    size_t k;
    lua_pop(L, 1);
    if (lua_type(L, -1) == LUA_TSTRING)
      for (k = 0; known[k] != NULL && !ok; k++)
        ok = strcmp(lua_tostring(L, -1), known[k]) == 0;
    if (!ok) {
      luaL_Buffer b;
      luaL_buffinit(L, &b);
      for (k = 0; known[k] != NULL; k++) {
        if (k)
          luaL_addstring(&b, ", ");
        luaL_addstring(&b, known[k]);
      }
      luaL_pushresult(&b);
      luaL_error(L, "%s: unknown option '%s' (options: %s)", fname,
                 lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : luaL_typename(L, -2),
                 lua_tostring(L, -1));
    }
  }
}

void dm_lua_readtopts(lua_State *L, int idx, const char *fname, dm_conn_topts *o)
{
  lua_Integer n;
  o->substeps = 8;
  o->tol = 0.0;
  if (idx == 0 || lua_isnoneornil(L, idx))
    return;
  if (!lua_istable(L, idx))
    luaL_error(L, "%s: options must be a table {substeps = n, tol = t}, got %s", fname,
               luaL_typename(L, idx));
  n = dm_optintegerfield(L, idx, "substeps", 8);
  if (n < 1 || n > 1000000)
    luaL_error(L, "%s: substeps must be 1..1000000, got %d", fname, (int)n);
  o->substeps = (size_t)n;
  o->tol = dm_optnumberfield(L, idx, "tol", 0.0);
  if (!(o->tol >= 0.0) || (o->tol > 0.0 && o->tol < 1e-15))
    luaL_error(L, "%s: tol must be 0 (Magnus 4) or in [1e-15, ...) (adaptive), got %f", fname,
               o->tol);
}

size_t dm_lua_conn_readnums(lua_State *L, int idx, const char *what, double *x, size_t n)
{
  gsl_vector *v = dm_tovec(L, idx);
  size_t k;
  if (v != NULL) {
    if (v->size != n)
      luaL_error(L, "%s must have %d entries, got %d", what, (int)n, (int)v->size);
    for (k = 0; k < n; k++)
      x[k] = gsl_vector_get(v, k);
    return n;
  }
  if (n == 1 && lua_type(L, idx) == LUA_TNUMBER) {
    x[0] = lua_tonumber(L, idx);
    return 1;
  }
  if (!lua_istable(L, idx))
    luaL_error(L, "%s must be a vec or a list of %d numbers, got %s", what, (int)n,
               luaL_typename(L, idx));
  if ((size_t)luaL_len(L, idx) != n)
    luaL_error(L, "%s must have %d entries, got %d", what, (int)n, (int)luaL_len(L, idx));
  for (k = 0; k < n; k++) {
    lua_geti(L, idx, (lua_Integer)k + 1);
    if (lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "%s[%d] must be a number, got %s", what, (int)k + 1, luaL_typename(L, -1));
    x[k] = lua_tonumber(L, -1);
    lua_pop(L, 1);
  }
  return n;
}

void dm_lua_conn_readalgebra(lua_State *L, int idx, size_t dim, double *xi)
{
  gsl_vector *v;
  size_t k;
  if (dim == 1 && lua_type(L, idx) == LUA_TNUMBER) {
    xi[0] = lua_tonumber(L, idx);
    return;
  }
  v = dm_checkvector(L, idx, dim);
  for (k = 0; k < dim; k++)
    xi[k] = gsl_vector_get(v, k);
}

void dm_lua_readshape(lua_State *L, const dm_conn_bundle *B, int idx, const char *what, double *x)
{
  dm_err e;
  idx = lua_absindex(L, idx);
  if (B->nx == 0 && lua_isnoneornil(L, idx))
    return;
  dm_lua_conn_readnums(L, idx, what, x, B->nx);
  if (dm_conn_shape_check(B, x, what, &e) != DM_OK)
    luaL_error(L, "%s", e.msg);
}

double *dm_lua_readshapes(lua_State *L, const dm_conn_bundle *B, int idx, const char *what,
                          size_t *n)
{
  gsl_matrix *M = dm_tomat(L, idx);
  gsl_vector *buf;
  char w[160];
  size_t k, i;
  dm_err e;
  idx = lua_absindex(L, idx);
  if (M != NULL) {
    if (M->size2 != B->nx)
      luaL_error(L, "%s: a matrix with %d columns (one point per row) expected, got %d", what,
                 (int)B->nx, (int)M->size2);
    *n = M->size1;
    buf = dm_pushvec(L, *n * B->nx + 1);
    for (k = 0; k < *n; k++)
      for (i = 0; i < B->nx; i++)
        buf->data[k * B->nx + i] = gsl_matrix_get(M, k, i);
  } else {
    if (!lua_istable(L, idx))
      luaL_error(L, "%s: a list of shape points expected, got %s", what, luaL_typename(L, idx));
    *n = (size_t)luaL_len(L, idx);
    buf = dm_pushvec(L, *n * B->nx + 1);
    for (k = 0; k < *n; k++) {
      snprintf(w, sizeof w, "%s[%d]", what, (int)k + 1);
      lua_geti(L, idx, (lua_Integer)k + 1);
      dm_lua_conn_readnums(L, -1, w, buf->data + k * B->nx, B->nx);
      lua_pop(L, 1);
    }
  }
  for (k = 0; k < *n; k++) {
    snprintf(w, sizeof w, "%s[%d]", what, (int)k + 1);
    if (dm_conn_shape_check(B, buf->data + k * B->nx, w, &e) != DM_OK)
      luaL_error(L, "%s", e.msg);
  }
  return buf->data;
}

void dm_lua_readgroupelem(lua_State *L, int gidx, int idx, const char *what, double *g)
{
  const dm_lie_group *G = dm_lua_checkgroup(L, gidx);
  dm_lelem *el = dm_lua_toelem(L, idx);
  if (el != NULL) {
    if (!dm_lie_group_equal(el->G, G))
      luaL_error(L, "%s must be an element of %s, got an element of %s", what, G->name,
                 el->G->name);
    dm_lua_elem_numbers(L, el, what, g);
    return;
  }
  if (lua_type(L, idx) != LUA_TNUMBER && !lua_istable(L, idx) && dm_tovec(L, idx) == NULL)
    luaL_error(L, "%s must be an element of %s (or its %d coordinates), got %s", what, G->name,
               (int)G->nq, luaL_typename(L, idx));
  dm_lua_conn_readnums(L, idx, what, g, G->nq);
}

void dm_lua_pushgroupelem(lua_State *L, int gidx, const double *g)
{
  dm_lelem *el = dm_lua_newelem(L, gidx, 0);
  size_t i;
  for (i = 0; i < el->G->nq; i++)
    el->v[i].x = g[i];
}

static int holo_tostring(lua_State *L)
{
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  luaL_addstring(&b, "holonomy");
  if (lua_getfield(L, 1, "angle") == LUA_TNUMBER) {
    char num[32];
    dm_num_snprintf(num, sizeof num, "%.10g", lua_tonumber(L, -1));
    luaL_addstring(&b, ": angle ");
    luaL_addstring(&b, num);
  }
  lua_pop(L, 1);
  if (lua_getfield(L, 1, "axis") != LUA_TNIL) {
    luaL_addstring(&b, " about ");
    luaL_addstring(&b, dm_tolstring(L, -1, NULL));
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  if (lua_getfield(L, 1, "body") != LUA_TNIL) {
    luaL_addstring(&b, "; body ");
    luaL_addstring(&b, dm_tolstring(L, -1, NULL));
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  luaL_pushresult(&b);
  return 1;
}

void dm_lua_pushholonomy(lua_State *L, int gidx, const double *spatial, const double *body,
                         double lifted)
{
  const dm_lie_group *G = dm_lua_checkgroup(L, gidx);
  double w[DM_LIE_DIM_MAX], ang = NAN;
  gidx = lua_absindex(L, gidx);
  lua_createtable(L, 0, 4);
  dm_lua_pushgroupelem(L, gidx, spatial);
  lua_setfield(L, -2, "spatial");
  if (body != NULL) {
    dm_lua_pushgroupelem(L, gidx, body);
    lua_setfield(L, -2, "body");
  }
  if (G->kind == DM_LIE_SO2 || G->kind == DM_LIE_SE2 || (G->kind == DM_LIE_RN && G->dim == 1)) {
    ang = isfinite(lifted) ? lifted : (body ? body[0] : spatial[0]);
  } else if (G->kind == DM_LIE_SO3) {
    double n;
    dm_lie_log(G, body ? body : spatial, w);
    n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    ang = n;
    if (n > 0) {
      w[0] /= n;
      w[1] /= n;
      w[2] /= n;
      dm_pushvec_copy(L, w, 3);
      lua_setfield(L, -2, "axis");
    }
  }
  if (isfinite(ang)) {
    lua_pushnumber(L, ang);
    lua_setfield(L, -2, "angle");
  }
  if (luaL_newmetatable(L, "dmech.holonomy")) {
    lua_pushcfunction(L, holo_tostring);
    lua_setfield(L, -2, "__tostring");
  }
  lua_setmetatable(L, -2);
}
