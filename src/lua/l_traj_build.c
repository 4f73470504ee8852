/* l_traj_build.c -- dm.trajectory{...}: a Trajectory from Lua data (times,
 * coordinate columns q/p/v by name, extra columns, metadata).  Every value is
 * converted into a vec anchored on the Lua stack before the trajectory is
 * filled, so an error at any point leaks nothing. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/dmlua.h"
#include "lua/l_traj.h"
#include "core/trajectory.h"

int dm_ltraj_setmeta(lua_State *L, dm_traj *tr, const char *key, int arg, dm_err *e)
{
  int t = lua_type(L, arg);
  if (t == LUA_TNIL)
    return dm_traj_meta_set(tr, key, NULL, e);
  if (t == LUA_TNUMBER)
    return dm_traj_meta_set_number(tr, key, lua_tonumber(L, arg), e);
  if (t == LUA_TSTRING)
    return dm_traj_meta_set(tr, key, dm_tocstring(L, arg, "metadata value"), e);
  if (t == LUA_TBOOLEAN) {
    int st = dm_traj_meta_set(tr, key, dm_tolstring(L, arg, NULL), e);
    lua_pop(L, 1);
    return st;
  }
  return dm_argexpected(L, arg, "string or number", luaL_typename(L, arg));
}

void dm_ltraj_pushmeta(lua_State *L, const dm_traj *tr, size_t i)
{
  const char *v;
  double x;
  if (dm_traj_meta_number_at(tr, i, &x)) {
    if (x == floor(x) && fabs(x) < 0x1p53)
      lua_pushinteger(L, (lua_Integer)x);
    else
      lua_pushnumber(L, x);
  } else {
    dm_traj_meta_at(tr, i, NULL, &v);
    lua_pushstring(L, v);
  }
}

/* {======================================================================
 * dm.trajectory{...}: a trajectory from Lua data
 * ======================================================================= */

/* The vec / table on the stack top, replaced there by a new vec (so it stays
 * anchored); `path` names the field in messages; len 0 means any length. */
static gsl_vector *field_values(lua_State *L, const char *path, size_t len)
{
  gsl_vector *v = dm_tovec(L, -1);
  size_t i, n;
  luaL_checkstack(L, 4, "too many columns");
  if (v != NULL) {
    gsl_vector *c = dm_pushvec(L, v->size);
    gsl_vector_memcpy(c, v);
    lua_replace(L, -2);
    v = c;
  } else if (lua_istable(L, -1) && (n = lua_rawlen(L, -1)) > 0) {
    int src = lua_gettop(L);
    v = dm_pushvec(L, n);
    for (i = 0; i < n; i++) {
      int isnum;
      lua_rawgeti(L, src, (lua_Integer)i + 1);
      v->data[i] = lua_tonumberx(L, -1, &isnum);
      if (!isnum)
        luaL_error(L, "bad argument #1 to 'trajectory' (field '%s': number expected "
                   "at index %I, got %s)", path, (lua_Integer)i + 1, luaL_typename(L, -1));
      lua_pop(L, 1);
    }
    lua_replace(L, src);
  } else {
    luaL_error(L, "bad argument #1 to 'trajectory' (field '%s': vec or non-empty table "
               "of numbers expected, got %s)", path,
               lua_istable(L, -1) ? "empty table" : luaL_typename(L, -1));
  }
  if (len != 0 && v->size != len)
    luaL_error(L, "bad argument #1 to 'trajectory' (field '%s': %I values expected "
               "(as many as t), got %I)", path, (lua_Integer)len, (lua_Integer)v->size);
  return v;
}

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* String keys of the table at idx, sorted (array in a userdata pushed). */
static const char **sorted_keys(lua_State *L, int idx, size_t *count, const char *what)
{
  size_t n = 0, k = 0;
  const char **keys;
  idx = lua_absindex(L, idx);
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    n++;
    lua_pop(L, 1);
  }
  keys = lua_newuserdatauv(L, (n ? n : 1) * sizeof *keys, 0);
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    if (lua_type(L, -2) != LUA_TSTRING)
      luaL_error(L, "bad argument #1 to 'trajectory' (field '%s': keys must be "
                 "column names, got a %s key)", what, luaL_typename(L, -2));
    keys[k++] = dm_tocstring(L, -2, "dm.trajectory");   /* anchored in the table */
    lua_pop(L, 1);
  }
  qsort(keys, n, sizeof *keys, cmp_str);
  *count = n;
  return keys;
}

static const char **coord_names(lua_State *L, size_t *n)
{
  const char **names;
  size_t i;
  if (lua_getfield(L, 1, "coords") == LUA_TNIL) {
    lua_pop(L, 1);
    if (lua_getfield(L, 1, "q") == LUA_TNIL) {
      *n = 0;
      return lua_newuserdatauv(L, sizeof *names, 0);
    }
    if (!lua_istable(L, -1))
      luaL_error(L, "bad argument #1 to 'trajectory' (field 'q': table of columns "
                 "expected, got %s)", luaL_typename(L, -1));
    return sorted_keys(L, -1, n, "q");
  }
  if (!lua_istable(L, -1))
    luaL_error(L, "bad argument #1 to 'trajectory' (field 'coords': table of names "
               "expected, got %s)", luaL_typename(L, -1));
  *n = lua_rawlen(L, -1);
  names = lua_newuserdatauv(L, (*n ? *n : 1) * sizeof *names, 0);
  for (i = 0; i < *n; i++) {
    if (lua_rawgeti(L, -2, (lua_Integer)i + 1) != LUA_TSTRING)
      luaL_error(L, "bad argument #1 to 'trajectory' (field 'coords': name %I is %s, "
                 "string expected)", (lua_Integer)i + 1, luaL_typename(L, -1));
    names[i] = dm_tocstring(L, -1, "dm.trajectory");
    lua_pop(L, 1);
  }
  return names;
}

/* Columns of group `g` (q, p, v) for the n coordinates, or NULL when the
 * group is absent; anchored on the stack. */
static const double **group_columns(lua_State *L, const char *g, const char *const *coords,
                                    size_t n, size_t len)
{
  const double **cols;
  size_t i;
  int gidx;
  if (lua_getfield(L, 1, g) == LUA_TNIL) {
    lua_pop(L, 1);
    return NULL;
  }
  if (!lua_istable(L, -1))
    luaL_error(L, "bad argument #1 to 'trajectory' (field '%s': table of columns "
               "expected, got %s)", g, luaL_typename(L, -1));
  gidx = lua_gettop(L);
  cols = lua_newuserdatauv(L, (n ? n : 1) * sizeof *cols, 0);
  for (i = 0; i < n; i++) {
    char path[DM_TRAJ_NAME_MAX + 8];
    snprintf(path, sizeof path, "%s.%s", g, coords[i]);
    if (lua_getfield(L, gidx, coords[i]) == LUA_TNIL)
      luaL_error(L, "bad argument #1 to 'trajectory' (field '%s' missing: every "
                 "coordinate needs a column)", path);
    cols[i] = field_values(L, path, len)->data;   /* stays on the stack */
  }
  {
    size_t extra;
    sorted_keys(L, gidx, &extra, g);
    lua_pop(L, 1);
    if (extra != n)
      luaL_error(L, "bad argument #1 to 'trajectory' (field '%s': %I columns for %I "
                 "coordinates)", g, (lua_Integer)extra, (lua_Integer)n);
  }
  return cols;
}

static int l_trajectory(lua_State *L)
{
  const char **coords, **xnames = NULL;
  const double **q, **p, **v, **x = NULL;
  gsl_vector *t;
  size_t n, len, nx = 0, i, k;
  unsigned flags;
  int tidx;
  double *row;
  dm_traj *tr;
  dm_err e;

  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  if (lua_getfield(L, 1, "t") == LUA_TNIL)
    return luaL_error(L, "bad argument #1 to 'trajectory' (field 't' missing: the "
                      "sample times)");
  t = field_values(L, "t", 0);
  len = t->size;
  coords = coord_names(L, &n);
  q = group_columns(L, "q", coords, n, len);
  if (q == NULL && n > 0)
    return luaL_error(L, "bad argument #1 to 'trajectory' (field 'q' missing: "
                      "'coords' names %I coordinates)", (lua_Integer)n);
  p = group_columns(L, "p", coords, n, len);
  v = group_columns(L, "v", coords, n, len);
  if (lua_getfield(L, 1, "columns") != LUA_TNIL) {
    int cidx = lua_gettop(L);
    if (!lua_istable(L, cidx))
      return luaL_error(L, "bad argument #1 to 'trajectory' (field 'columns': table "
                        "expected, got %s)", luaL_typename(L, cidx));
    xnames = sorted_keys(L, cidx, &nx, "columns");
    x = lua_newuserdatauv(L, (nx ? nx : 1) * sizeof *x, 0);
    for (i = 0; i < nx; i++) {
      char path[DM_TRAJ_NAME_MAX + 16];
      snprintf(path, sizeof path, "columns.%s", xnames[i]);
      lua_getfield(L, cidx, xnames[i]);
      x[i] = field_values(L, path, len)->data;
    }
  }
  flags = (p != NULL ? DM_TRAJ_WITH_P : 0) | (v != NULL ? DM_TRAJ_WITH_V : 0);
  row = lua_newuserdatauv(L, (3 * n + nx + 1) * sizeof *row, 0);
  tr = dm_pushtraj(L, n, coords, flags);
  tidx = lua_gettop(L);
  for (i = 0; i < nx; i++) {
    int diag = strcmp(xnames[i], DM_TRAJ_ENERGY) == 0
      || strncmp(xnames[i], DM_TRAJ_MOMENTUM, strlen(DM_TRAJ_MOMENTUM)) == 0;
    if (dm_traj_add_column(tr, xnames[i], diag ? DM_TRAJ_DIAG : DM_TRAJ_DATA, NULL,
                           0, &e) != DM_OK)
      return dm_lua_fail(L, "trajectory", e.status, &e);
  }
  if (dm_traj_reserve(tr, len, &e) != DM_OK)
    return dm_lua_fail(L, "trajectory", e.status, &e);
  for (k = 0; k < len; k++) {
    double *qr = row, *pr = row + n, *vr = row + 2 * n, *xr = row + 3 * n;
    for (i = 0; i < n; i++) {
      qr[i] = q[i][k];
      pr[i] = p != NULL ? p[i][k] : 0;
      vr[i] = v != NULL ? v[i][k] : 0;
    }
    for (i = 0; i < nx; i++)
      xr[i] = x[i][k];
    dm_traj_append(tr, t->data[k], qr, pr, vr, xr, NULL);  /* reserved: cannot fail */
  }
  if (lua_getfield(L, 1, "meta") != LUA_TNIL) {
    int midx = lua_gettop(L), top;
    size_t nm;
    const char **keys;
    if (!lua_istable(L, midx))
      return luaL_error(L, "bad argument #1 to 'trajectory' (field 'meta': table "
                        "expected, got %s)", luaL_typename(L, midx));
    keys = sorted_keys(L, midx, &nm, "meta");
    top = lua_gettop(L);
    for (i = 0; i < nm; i++) {
      lua_getfield(L, midx, keys[i]);
      if (lua_type(L, -1) != LUA_TSTRING && lua_type(L, -1) != LUA_TNUMBER)
        return luaL_error(L, "bad argument #1 to 'trajectory' (field 'meta.%s': string "
                          "or number expected, got %s)", keys[i], luaL_typename(L, -1));
      if (dm_ltraj_setmeta(L, tr, keys[i], lua_gettop(L), &e) != DM_OK)
        return luaL_error(L, "bad argument #1 to 'trajectory' (field 'meta': %s)", e.msg);
      lua_settop(L, top);
    }
  }
  lua_pushvalue(L, tidx);
  return 1;
}

/* }====================================================================== */

static const dm_reg build_funcs[] = {
  {"trajectory", l_trajectory,
   "dm.trajectory{t = values, coords = {...}, q = {name = values}, p = ..., v = ..., "
   "columns = {name = values}, meta = {key = value}} -> traj",
   "A trajectory built from Lua data (each values a vec or table as long as t)."},
  {NULL, NULL, NULL, NULL}
};

void dm_ltraj_open_build(lua_State *L)
{
  dm_register(L, "dm.", build_funcs);
}
