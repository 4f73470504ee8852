/* l_traj_cols.c -- what indexing a Trajectory gives (l_traj.h): columns
 * as dm.vec copies, samples as tables, the proxies traj.q / traj.p /
 * traj.v by coordinate name or number, and arrays of coordinates
 * (traj.q.x[3]).  Part of the Trajectory binding (l_traj.c). */
#include <config.h>
#include <stdio.h>
#include <string.h>

#include "lua/dmlua.h"
#include "lua/l_traj.h"
#include "core/trajectory.h"

#define COLS_MT "dmech.trajectory.columns"
#define ARR_MT "dmech.trajectory.array"

/* {======================================================================
 * columns and samples
 * ======================================================================= */

/* Push column j as a new vec. */
void dm_ltraj_pushcolumn(lua_State *L, const dm_traj *tr, size_t j)
{
  if (dm_traj_len(tr) == 0)
    luaL_error(L, "column '%s': the trajectory has no samples",
               dm_traj_colname(tr, j));
  dm_pushvec_copy(L, dm_traj_col(tr, j), dm_traj_len(tr));
}

/* Raise "no column 'x' (available: ...)" against argument arg. */
int dm_ltraj_nocolumn(lua_State *L, int arg, const dm_traj *tr, const char *name)
{
  dm_err e;
  dm_traj_lookup(tr, name, NULL, &e);
  return luaL_argerror(L, arg, e.msg);
}

/* 1-based sample index (negative: from the end) -> 0-based, or (size_t)-1. */
size_t dm_ltraj_sampleindex(lua_Integer k, size_t len)
{
  if (k >= 1 && (lua_Unsigned)k <= len)
    return (size_t)k - 1;
  if (k < 0 && (lua_Unsigned)0 - (lua_Unsigned)k <= len)
    return (size_t)((lua_Integer)len + k);
  return (size_t)-1;
}

/* Push sample k (0-based) as {t=, q=vec, p=vec, v=vec, <column>=number...}:
 * every column also appears under its own name (t, q, p, v win a clash). */
void dm_ltraj_pushsample(lua_State *L, const dm_traj *tr, size_t k)
{
  size_t j, i, nc = dm_traj_ncols(tr);
  const char *kinds[3] = {"q", "p", "v"};
  lua_createtable(L, 0, (int)nc + 4);
  for (j = 0; j < nc; j++) {
    lua_pushnumber(L, dm_traj_col(tr, j)[k]);
    lua_setfield(L, -2, dm_traj_colname(tr, j));
  }
  for (i = 0; i < 3; i++) {
    size_t n = i == 0 ? dm_traj_ncoords(tr) : dm_traj_nmomenta(tr);
    size_t j0 = i == 0 ? dm_traj_qcol(tr, 0) : i == 1 ? dm_traj_pcol(tr, 0)
                                                        : dm_traj_vcol(tr, 0);
    gsl_vector *x;
    if (n == 0 || j0 == DM_TRAJ_NONE)
      continue;
    x = dm_pushvec(L, n);
    for (j = 0; j < n; j++)
      x->data[j] = dm_traj_col(tr, j0 + j)[k];
    lua_setfield(L, -2, kinds[i]);
  }
  lua_pushnumber(L, dm_traj_col(tr, 0)[k]);
  lua_setfield(L, -2, "t");
}

/* traj.q / traj.p / traj.v: a small userdata (the kind) with the trajectory
 * as user value 1; indexing it by coordinate name (or number) gives the vec. */
void dm_ltraj_pushcolumns(lua_State *L, int tidx, const dm_traj *tr, char kind)
{
  char *u, list[400];
  if ((kind == 'p' && !(dm_traj_flags(tr) & DM_TRAJ_WITH_P))
      || (kind == 'v' && !(dm_traj_flags(tr) & DM_TRAJ_WITH_V)))
    luaL_error(L, "this trajectory stores no %s columns (available: %s)",
               kind == 'p' ? "momentum (p)" : "velocity (v)",
               dm_traj_names(tr, list, sizeof list));
  u = lua_newuserdatauv(L, 1, 1);
  *u = kind;
  lua_pushvalue(L, tidx);
  lua_setiuservalue(L, -2, 1);
  luaL_setmetatable(L, COLS_MT);
}

/* traj.q.x for an array of coordinates x[1] .. x[k] (dm.coords): a proxy
 * whose [i] is the column of x[i] (of the kind: q, p or v).  Pushes it and
 * returns 1, or 0 when there is no such array.  The trajectory (at the top
 * of the stack) is its user value. */
typedef struct arrproxy {
  char kind;
  size_t first, count;
} arrproxy;

static int push_array_proxy(lua_State *L, const dm_traj *tr, char kind, const char *name)
{
  size_t n = dm_traj_ncoords(tr), ln = strlen(name), first = n, count = 0;
  char want[DM_TRAJ_NAME_MAX + 32];
  if (kind != 'q' && dm_traj_named_momenta(tr))
    return 0;                     /* p and v are not per coordinate */
  for (size_t i = 0; i < n; i++) {
    const char *c = dm_traj_coord(tr, i);
    if (strncmp(c, name, ln) == 0 && c[ln] == '[') {
      snprintf(want, sizeof want, "%s[%zu]", name, count + 1);
      if (strcmp(c, want) != 0 || (count > 0 && i != first + count))
        break;                    /* not the array's next element */
      if (count == 0)
        first = i;
      count++;
    } else if (count > 0) {
      break;
    }
  }
  if (count == 0)
    return 0;
  int t = lua_gettop(L);
  arrproxy *u = lua_newuserdatauv(L, sizeof *u, 2);
  u->kind = kind;
  u->first = first;
  u->count = count;
  lua_pushvalue(L, t);
  lua_setiuservalue(L, -2, 1);
  lua_pushstring(L, name);
  lua_setiuservalue(L, -2, 2);
  luaL_setmetatable(L, ARR_MT);
  return 1;
}

static int arr_index(lua_State *L)
{
  arrproxy *u = luaL_checkudata(L, 1, ARR_MT);
  lua_Integer k = luaL_checkinteger(L, 2);
  lua_getiuservalue(L, 1, 1);
  dm_traj *tr = dm_ltraj_checkopen(L, -1);
  if (k < 1 || (lua_Unsigned)k > u->count) {
    lua_getiuservalue(L, 1, 2);
    return luaL_error(L, "index %d out of range 1..%d for the array %s", (int)k,
                      (int)u->count, lua_tostring(L, -1));
  }
  size_t i = u->first + (size_t)k - 1;
  size_t j = u->kind == 'q' ? dm_traj_qcol(tr, i) : u->kind == 'p' ? dm_traj_pcol(tr, i)
                                                                     : dm_traj_vcol(tr, i);
  dm_ltraj_pushcolumn(L, tr, j);
  return 1;
}

static int arr_len(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)((arrproxy *)luaL_checkudata(L, 1, ARR_MT))->count);
  return 1;
}

static int arr_tostring(lua_State *L)
{
  arrproxy *u = luaL_checkudata(L, 1, ARR_MT);
  lua_getiuservalue(L, 1, 2);
  lua_pushfstring(L, "<%c columns %s[1..%d] of a trajectory>", u->kind, lua_tostring(L, -1),
                  (int)u->count);
  return 1;
}

/* The name the i-th column of a kind is indexed by: the coordinate, or
 * for named momenta the column's own name. */
static const char *col_key(const dm_traj *tr, char kind, int named, size_t i)
{
  if (!named)
    return dm_traj_coord(tr, i);
  return dm_traj_colname(tr, kind == 'p' ? dm_traj_pcol(tr, i) : dm_traj_vcol(tr, i));
}

static int cols_index(lua_State *L)
{
  char kind = *(char *)luaL_checkudata(L, 1, COLS_MT);
  dm_traj *tr;
  size_t i, n, j;
  int named;
  lua_getiuservalue(L, 1, 1);
  tr = dm_ltraj_checkopen(L, -1);
  /* named momenta: p and v by their own column names */
  named = kind != 'q' && dm_traj_named_momenta(tr);
  n = kind == 'q' ? dm_traj_ncoords(tr) : dm_traj_nmomenta(tr);
  if (lua_type(L, 2) == LUA_TNUMBER) {
    lua_Integer k = luaL_checkinteger(L, 2);
    i = k >= 1 && (lua_Unsigned)k <= n ? (size_t)k - 1 : n;
  } else {
    const char *name = dm_checkcstring(L, 2);
    for (i = 0; i < n && strcmp(col_key(tr, kind, named, i), name) != 0; i++)
      ;
    if (i == n && push_array_proxy(L, tr, kind, name))
      return 1;
  }
  if (i == n) {
    const char *q = lua_type(L, 2) == LUA_TSTRING ? "'" : "";
    const char *key = dm_tolstring(L, 2, NULL);
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    lua_pushfstring(L, "no %s %s%s%s (%s: ", named ? "column" : "coordinate", q, key, q,
                    !named ? "coordinates" : kind == 'p' ? "momenta" : "velocities");
    luaL_addvalue(&b);
    for (j = 0; j < n; j++) {
      if (j > 0)
        luaL_addstring(&b, ", ");
      luaL_addstring(&b, col_key(tr, kind, named, j));
    }
    luaL_addchar(&b, ')');
    luaL_pushresult(&b);
    return luaL_error(L, "%s", lua_tostring(L, -1));
  }
  j = kind == 'q' ? dm_traj_qcol(tr, i) : kind == 'p' ? dm_traj_pcol(tr, i)
                                                        : dm_traj_vcol(tr, i);
  dm_ltraj_pushcolumn(L, tr, j);
  return 1;
}

static int cols_len(lua_State *L)
{
  char kind = *(char *)luaL_checkudata(L, 1, COLS_MT);
  dm_traj *tr;
  lua_getiuservalue(L, 1, 1);
  tr = dm_ltraj_checkopen(L, -1);
  lua_pushinteger(L, (lua_Integer)(kind == 'q' ? dm_traj_ncoords(tr) : dm_traj_nmomenta(tr)));
  return 1;
}

static int cols_tostring(lua_State *L)
{
  char kind = *(char *)luaL_checkudata(L, 1, COLS_MT);
  lua_pushfstring(L, "<%c columns of a trajectory>", kind);
  return 1;
}

/* }====================================================================== */

static const luaL_Reg cols_meta[] = {
  {"__index", cols_index},
  {"__len", cols_len},
  {"__tostring", cols_tostring},
  {NULL, NULL}
};

void dm_ltraj_open_cols(lua_State *L)
{
  luaL_newmetatable(L, ARR_MT);
  lua_pushcfunction(L, arr_index);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, arr_len);
  lua_setfield(L, -2, "__len");
  lua_pushcfunction(L, arr_tostring);
  lua_setfield(L, -2, "__tostring");
  lua_pop(L, 1);
  luaL_newmetatable(L, COLS_MT);
  luaL_setfuncs(L, cols_meta, 0);
  lua_pushliteral(L, "trajectory columns");
  lua_setfield(L, -2, "__name");
  lua_pop(L, 1);
}
