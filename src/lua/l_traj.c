/* l_traj.c -- Trajectory userdata: the Lua face of src/core/trajectory.h.
 *
 * A Trajectory userdata holds one dm_traj * (NULL while empty or after
 * close).  It is created empty with its metatable set before the trajectory
 * is allocated, so an error at any point leaves nothing half-built; __gc and
 * __close share one idempotent cleanup.  Columns cross to Lua as dm.vec
 * copies; samples are 1-based (negative indices count from the end).
 * Derive callbacks run under lua_pcall inside a trampoline and the error is
 * re-raised after dm_traj_derive has unwound (no longjmp over C memory).
 */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/dmlua.h"
#include "lua/l_traj.h"
#include "core/mpi.h"
#include "core/trajectory.h"
#include "core/trajectory_h5.h"

#define COLS_MT "dmech.trajectory.columns"
#define ARR_MT "dmech.trajectory.array"

typedef struct ltraj {
  dm_traj *tr;
  int busy;            /* a derive is running over it: no close, no derive */
  int replica;         /* every MPI rank holds the same table: rank 0 saves it */
} ltraj;

/* {======================================================================
 * construction and checking (C API in dmlua.h)
 * ======================================================================= */

dm_traj **dm_newtraj(lua_State *L)
{
  ltraj *u = lua_newuserdatauv(L, sizeof *u, 0);
  u->tr = NULL;
  u->busy = 0;
  u->replica = 0;
  luaL_setmetatable(L, DM_TRAJ_MT);
  return &u->tr;
}

void dm_traj_mark_replica(lua_State *L, int arg)
{
  ltraj *u = luaL_checkudata(L, arg, DM_TRAJ_MT);
  u->replica = 1;
}

dm_traj *dm_pushtraj(lua_State *L, size_t n, const char *const *coords,
                     unsigned flags)
{
  dm_traj **slot = dm_newtraj(L);
  dm_err e;
  *slot = dm_traj_alloc(n, coords, flags, &e);
  if (*slot == NULL)
    dm_lua_fail(L, "trajectory", e.status, &e);
  return *slot;
}

dm_traj *dm_totraj(lua_State *L, int arg)
{
  ltraj *u = luaL_testudata(L, arg, DM_TRAJ_MT);
  return u != NULL ? u->tr : NULL;
}

/* The trajectory of the Trajectory at idx inside a metamethod: a plain error
 * (not an argument error naming the metamethod) when it was closed. */
static dm_traj *open_traj(lua_State *L, int idx)
{
  ltraj *u = luaL_checkudata(L, idx, DM_TRAJ_MT);
  if (u->tr == NULL)
    luaL_error(L, "attempt to use a closed trajectory");
  return u->tr;
}

dm_traj *dm_checktraj(lua_State *L, int arg)
{
  ltraj *u = luaL_testudata(L, arg, DM_TRAJ_MT);
  if (u == NULL)
    luaL_typeerror(L, arg, "trajectory");
  if (u->tr == NULL)
    luaL_argerror(L, arg, "trajectory is closed");
  return u->tr;
}

/* }====================================================================== */

/* {======================================================================
 * columns and samples
 * ======================================================================= */

/* Push column j as a new vec. */
static void push_column(lua_State *L, const dm_traj *tr, size_t j)
{
  if (dm_traj_len(tr) == 0)
    luaL_error(L, "column '%s': the trajectory has no samples",
               dm_traj_colname(tr, j));
  dm_pushvec_copy(L, dm_traj_col(tr, j), dm_traj_len(tr));
}

/* Raise "no column 'x' (available: ...)" against argument arg. */
static int no_column(lua_State *L, int arg, const dm_traj *tr, const char *name)
{
  dm_err e;
  dm_traj_lookup(tr, name, NULL, &e);
  return luaL_argerror(L, arg, e.msg);
}

/* 1-based sample index (negative: from the end) -> 0-based, or (size_t)-1. */
static size_t sample_index(lua_Integer k, size_t len)
{
  if (k >= 1 && (lua_Unsigned)k <= len)
    return (size_t)k - 1;
  if (k < 0 && (lua_Unsigned)0 - (lua_Unsigned)k <= len)
    return (size_t)((lua_Integer)len + k);
  return (size_t)-1;
}

/* Push sample k (0-based) as {t=, q=vec, p=vec, v=vec, <column>=number...}:
 * every column also appears under its own name (t, q, p, v win a clash). */
static void push_sample(lua_State *L, const dm_traj *tr, size_t k)
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
static void push_columns_proxy(lua_State *L, int tidx, const dm_traj *tr, char kind)
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
  dm_traj *tr = open_traj(L, -1);
  if (k < 1 || (lua_Unsigned)k > u->count) {
    lua_getiuservalue(L, 1, 2);
    return luaL_error(L, "index %d out of range 1..%d for the array %s", (int)k,
                      (int)u->count, lua_tostring(L, -1));
  }
  size_t i = u->first + (size_t)k - 1;
  size_t j = u->kind == 'q' ? dm_traj_qcol(tr, i) : u->kind == 'p' ? dm_traj_pcol(tr, i)
                                                                     : dm_traj_vcol(tr, i);
  push_column(L, tr, j);
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
  tr = open_traj(L, -1);
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
  push_column(L, tr, j);
  return 1;
}

static int cols_len(lua_State *L)
{
  char kind = *(char *)luaL_checkudata(L, 1, COLS_MT);
  dm_traj *tr;
  lua_getiuservalue(L, 1, 1);
  tr = open_traj(L, -1);
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

/* {======================================================================
 * metamethods
 * ======================================================================= */

static int t_gc(lua_State *L)
{
  ltraj *u = luaL_checkudata(L, 1, DM_TRAJ_MT);
  if (u->busy)           /* only an explicit __close can get here */
    return luaL_error(L, "cannot close a trajectory while derive runs over it");
  dm_traj_free(u->tr);
  u->tr = NULL;
  return 0;
}

static int t_len(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)dm_traj_len(open_traj(L, 1)));
  return 1;
}

/* How the run that made tr ended: "success", "interrupted", "no
 * convergence", "diverged", ... (its status metadata), nil when no run made
 * it (built from data, or a file without it). */
static void push_status(lua_State *L, const dm_traj *tr)
{
  double st;
  if (dm_traj_meta_number(tr, "status", &st) && st == floor(st))
    lua_pushstring(L, dm_strstatus((int)st));
  else
    lua_pushnil(L);
}

static int t_index(lua_State *L)
{
  dm_traj *tr;
  luaL_checkudata(L, 1, DM_TRAJ_MT);
  if (lua_type(L, 2) == LUA_TSTRING) {
    const char *key = lua_tostring(L, 2);
    lua_getmetatable(L, 1);
    lua_getfield(L, -1, "__methods");
    if (lua_getfield(L, -1, key) != LUA_TNIL)
      return 1;        /* methods check the trajectory themselves */
    tr = open_traj(L, 1);
    if (strcmp(key, "t") == 0)
      push_column(L, tr, 0);
    else if (key[1] == '\0' && (key[0] == 'q' || key[0] == 'p' || key[0] == 'v'))
      push_columns_proxy(L, 1, tr, key[0]);
    else if (strcmp(key, "status") == 0)
      push_status(L, tr);
    else if (strcmp(key, "message") == 0)
      lua_pushstring(L, dm_traj_meta_get(tr, "message"));   /* nil when none */
    else
      lua_pushnil(L);
    return 1;
  }
  if (lua_isinteger(L, 2)) {
    size_t k;
    tr = open_traj(L, 1);
    k = sample_index(lua_tointeger(L, 2), dm_traj_len(tr));
    if (k == (size_t)-1)
      lua_pushnil(L);
    else
      push_sample(L, tr, k);
    return 1;
  }
  lua_pushnil(L);
  return 1;
}

static int t_tostring(lua_State *L)
{
  ltraj *u = luaL_checkudata(L, 1, DM_TRAJ_MT);
  dm_traj *tr = u->tr;
  luaL_Buffer b;
  char a[32], z[32];
  const char *sys, *method, *stages, *h;
  size_t len;
  if (tr == NULL) {
    lua_pushliteral(L, "<Trajectory (closed)>");
    return 1;
  }
  len = dm_traj_len(tr);
  luaL_buffinit(L, &b);
  if (dm_traj_meta_get(tr, "members") != NULL && dm_traj_ncoords(tr) == 0) {
    /* an ensemble's table: one row per member */
    char names[160];
    const char *failed = dm_traj_meta_get(tr, "failed");
    lua_pushfstring(L, "<Ensemble table: %I member%s (%s)", (lua_Integer)len, len == 1 ? "" : "s",
                    dm_traj_names(tr, names, sizeof names));
    luaL_addvalue(&b);
    if (failed != NULL && strcmp(failed, "0") != 0) {
      lua_pushfstring(L, ", %s failed", failed);
      luaL_addvalue(&b);
    }
  } else {
    lua_pushfstring(L, "<Trajectory %I sample%s", (lua_Integer)len, len == 1 ? "" : "s");
    luaL_addvalue(&b);
  }
  if (len > 0 && dm_traj_meta_get(tr, "members") == NULL) {
    /* ten digits: the end of a run reads 79289.95, not 79289.95000000001 */
    dm_num_snprintf(a, sizeof a, "%.10g", dm_traj_col(tr, 0)[0]);
    dm_num_snprintf(z, sizeof z, "%.10g", dm_traj_col(tr, 0)[len - 1]);
    lua_pushfstring(L, " t=[%s, %s]", a, z);
    luaL_addvalue(&b);
  }
  sys = dm_traj_meta_get(tr, "system");
  method = dm_traj_meta_get(tr, "method");
  stages = dm_traj_meta_get(tr, "stages");
  h = dm_traj_meta_get(tr, "h");
  if (sys != NULL) {
    luaL_addchar(&b, ' ');
    luaL_addstring(&b, sys);
  }
  if (method != NULL || h != NULL) {
    luaL_addstring(&b, " (");
    if (method != NULL)
      luaL_addstring(&b, method);
    if (method != NULL && stages != NULL) {
      luaL_addstring(&b, " s=");
      luaL_addstring(&b, stages);
    }
    if (h != NULL) {
      luaL_addstring(&b, method != NULL ? " h=" : "h=");
      luaL_addstring(&b, h);
    }
    luaL_addchar(&b, ')');
  }
  {
    double st;
    if (dm_traj_meta_number(tr, "status", &st) && st != 0 && st == floor(st)) {
      luaL_addstring(&b, ", ended early: ");
      luaL_addstring(&b, dm_strstatus((int)st));
    }
  }
  luaL_addchar(&b, '>');
  luaL_pushresult(&b);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * methods
 * ======================================================================= */

static int t_column(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  const char *name = dm_checkcstring(L, 2);
  size_t j = dm_traj_find(tr, name);
  if (j == DM_TRAJ_NONE)
    return no_column(L, 2, tr, name);
  push_column(L, tr, j);
  return 1;
}

static int t_names(lua_State *L)
{
  static const char *const kinds[] = {"t", "q", "p", "v", "diag", "derived",
                                      "data", "all", NULL};
  dm_traj *tr = dm_checktraj(L, 1);
  int want = dm_checkoption(L, 2, "all", kinds);
  size_t j, nc = dm_traj_ncols(tr);
  lua_Integer k = 0;
  lua_createtable(L, (int)nc, 0);
  for (j = 0; j < nc; j++)
    if (want == DM_TRAJ_DATA + 1 || dm_traj_colkind(tr, j) == want) {
      lua_pushstring(L, dm_traj_colname(tr, j));
      lua_rawseti(L, -2, ++k);
    }
  return 1;
}

static int t_kinds(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  size_t j, nc = dm_traj_ncols(tr);
  lua_createtable(L, 0, (int)nc);
  for (j = 0; j < nc; j++) {
    lua_pushstring(L, dm_traj_kindname(dm_traj_colkind(tr, j)));
    lua_setfield(L, -2, dm_traj_colname(tr, j));
  }
  return 1;
}

static int t_meta(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  size_t i;
  if (lua_isnoneornil(L, 2)) {
    lua_createtable(L, 0, (int)dm_traj_meta_count(tr));
    for (i = 0; i < dm_traj_meta_count(tr); i++) {
      const char *k;
      dm_traj_meta_at(tr, i, &k, NULL);
      dm_ltraj_pushmeta(L, tr, i);
      lua_setfield(L, -2, k);
    }
    return 1;
  }
  if (lua_gettop(L) >= 3) {
    const char *key = dm_checkcstring(L, 2);
    dm_err e;
    if (dm_ltraj_setmeta(L, tr, key, 3, &e) != DM_OK)
      return luaL_argerror(L, 2, e.msg);
    lua_settop(L, 1);
    return 1;
  }
  {
    const char *key = dm_checkcstring(L, 2);
    for (i = 0; i < dm_traj_meta_count(tr); i++) {
      const char *k;
      dm_traj_meta_at(tr, i, &k, NULL);
      if (strcmp(k, key) == 0) {
        dm_ltraj_pushmeta(L, tr, i);
        return 1;
      }
    }
    lua_pushnil(L);
  }
  return 1;
}

static int t_slice(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1), **slot;
  size_t len = dm_traj_len(tr);
  lua_Integer i = luaL_checkinteger(L, 2), j = luaL_optinteger(L, 3, -1);
  lua_Integer stride = luaL_optinteger(L, 4, 1);
  dm_err e;
  if (stride < 1)
    return luaL_argerror(L, 4, lua_pushfstring(L, "positive stride expected, got %I", stride));
  /* string.sub rules: negative from the end, clamped to [1, len] */
  if (i < 0)
    i = (lua_Unsigned)0 - (lua_Unsigned)i > len ? 1 : (lua_Integer)len + i + 1;
  else if (i == 0)
    i = 1;
  if (j < 0)
    j = (lua_Unsigned)0 - (lua_Unsigned)j > len ? 0 : (lua_Integer)len + j + 1;
  else if ((lua_Unsigned)j > len)
    j = (lua_Integer)len;
  if (i > j)
    i = j + 1;
  slot = dm_newtraj(L);
  *slot = dm_traj_slice(tr, (size_t)i - 1, (size_t)j, (size_t)stride, &e);
  if (*slot == NULL)
    return dm_lua_fail(L, "slice", e.status, &e);
  return 1;
}

/* ---- derive ---------------------------------------------------------------- */

typedef struct derive_ctx {
  lua_State *L;
  int fidx;            /* the callable */
  size_t m;            /* values per sample */
  const dm_traj_sample *s;  /* valid during a callback only */
  size_t k;                 /* the last sample handed to f */
  double t;
  double *out;
  int failed;          /* the error value is on the stack top */
} derive_ctx;

/* Read the m numbers f returned (multiple results, or one table / vec). */
static void derive_results(lua_State *L, derive_ctx *c, int base, int nret)
{
  size_t a;
  if (nret == 1 && c->m > 1 && (lua_istable(L, base) || dm_tovec(L, base) != NULL)) {
    for (a = 0; a < c->m; a++) {
      int isnum;
      lua_geti(L, base, (lua_Integer)a + 1);
      c->out[a] = lua_tonumberx(L, -1, &isnum);
      if (!isnum)
        luaL_error(L, "element %I of the result is %s (number expected)",
                   (lua_Integer)a + 1, luaL_typename(L, -1));
      lua_pop(L, 1);
    }
    return;
  }
  if ((size_t)nret < c->m)
    luaL_error(L, "the function returned %d value%s (%I number%s expected)", nret,
               nret == 1 ? "" : "s", (lua_Integer)c->m, c->m == 1 ? "" : "s");
  for (a = 0; a < c->m; a++) {
    int isnum;
    c->out[a] = lua_tonumberx(L, base + (int)a, &isnum);
    if (!isnum)
      luaL_error(L, "result %I is %s (number expected)", (lua_Integer)a + 1,
                 luaL_typename(L, base + (int)a));
  }
}

/* Protected: call f(sample) and store its numbers (stack: ctx, f). */
static int derive_call(lua_State *L)
{
  derive_ctx *c = lua_touserdata(L, 1);
  int base;
  lua_pushvalue(L, 2);
  push_sample(L, c->s->traj, c->s->k);
  base = lua_gettop(L) - 1;
  lua_call(L, 1, LUA_MULTRET);
  derive_results(L, c, base, lua_gettop(L) - base + 1);
  return 0;
}

static int derive_trampoline(void *ctx, const dm_traj_sample *s, double *out)
{
  derive_ctx *c = ctx;
  lua_State *L = c->L;
  c->s = s;
  c->k = s->k;
  c->t = s->t;
  c->out = out;
  lua_pushcfunction(L, derive_call);
  lua_pushlightuserdata(L, c);
  lua_pushvalue(L, c->fidx);
  if (lua_pcall(L, 2, 0, 0) != LUA_OK) {
    c->failed = 1;               /* leave the error value on the stack */
    return 1;
  }
  return 0;
}

static int is_callable(lua_State *L, int idx)
{
  if (lua_isfunction(L, idx))
    return 1;
  if (luaL_getmetafield(L, idx, "__call") == LUA_TNIL)
    return 0;
  lua_pop(L, 1);
  return 1;
}

static int t_derive(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  const char **names;
  size_t m, a;
  derive_ctx c;
  ltraj *u;
  dm_err e;
  int st;
  if (lua_type(L, 2) == LUA_TSTRING) {
    m = 1;
  } else if (lua_type(L, 2) == LUA_TTABLE && lua_rawlen(L, 2) > 0) {
    m = lua_rawlen(L, 2);
  } else {
    return dm_argexpected(L, 2, "column name or non-empty table of names",
                          lua_type(L, 2) == LUA_TTABLE ? "empty table" : luaL_typename(L, 2));
  }
  if (!is_callable(L, 3))
    return dm_argexpected(L, 3, "function", luaL_typename(L, 3));
  lua_settop(L, 3);
  names = lua_newuserdatauv(L, m * sizeof *names, 0);    /* index 4 */
  if (m == 1 && lua_type(L, 2) == LUA_TSTRING) {
    names[0] = lua_tostring(L, 2);
  } else {
    for (a = 0; a < m; a++) {
      if (lua_rawgeti(L, 2, (lua_Integer)a + 1) != LUA_TSTRING)
        return luaL_argerror(L, 2, lua_pushfstring(L, "name %I is %s (string expected)",
                                                    (lua_Integer)a + 1, luaL_typename(L, -1)));
      names[a] = lua_tostring(L, -1);    /* anchored in the table at 2 */
      lua_pop(L, 1);
    }
  }
  for (a = 0; a < m; a++) {
    size_t j = dm_traj_find(tr, names[a]);
    if (j != DM_TRAJ_NONE && dm_traj_colkind(tr, j) < DM_TRAJ_DIAG)
      return luaL_argerror(L, 2, lua_pushfstring(L, "column '%s' is a %s column and "
                           "cannot be replaced", names[a],
                           dm_traj_kindname(dm_traj_colkind(tr, j))));
  }
  c.L = L;
  c.fidx = 3;
  c.m = m;
  c.failed = 0;
  u = lua_touserdata(L, 1);
  if (u->busy)
    return luaL_error(L, "derive: already deriving columns of this trajectory");
  u->busy = 1;
  st = dm_traj_derive(tr, m, names, DM_TRAJ_DERIVED, derive_trampoline, &c,
                      DM_TRAJ_REPLACE, &e);
  u->busy = 0;
  if (c.failed) {
    char tbuf[32];
    dm_num_format(tbuf, sizeof tbuf, c.t);
    if (lua_type(L, -1) == LUA_TSTRING)
      return luaL_error(L, "derive '%s': at sample %I (t = %s): %s", names[0],
                        (lua_Integer)c.k + 1, tbuf, lua_tostring(L, -1));
    return lua_error(L);
  }
  if (st != DM_OK)
    return dm_lua_fail(L, "derive", st, &e);
  lua_settop(L, 1);
  return 1;
}

/* ---- files and diagnostics ------------------------------------------------- */

static int t_save(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  const char *path = dm_checkcstring(L, 2);
  dm_err e;
  if (((ltraj *)lua_touserdata(L, 1))->replica && dm_mpi_rank() != 0) {
    lua_pushboolean(L, 1);       /* rank 0 writes the table every rank holds */
    return 1;
  }
  if (dm_traj_save_any(tr, path, &e) != DM_OK) {
    luaL_pushfail(L);
    lua_pushstring(L, e.msg);
    return 2;
  }
  lua_pushboolean(L, 1);
  return 1;
}

static int l_load(lua_State *L)
{
  const char *path = dm_checkcstring(L, 1);
  dm_traj **slot = dm_newtraj(L);
  dm_err e;
  *slot = dm_traj_load_any(path, &e);
  if (*slot == NULL) {
    luaL_pushfail(L);
    lua_pushstring(L, e.msg);
    return 2;
  }
  return 1;
}

/* Push diagnostic column `name` or raise an error listing what exists. */
static int push_diag(lua_State *L, const dm_traj *tr, const char *name, const char *what)
{
  size_t j = dm_traj_find(tr, name);
  if (j == DM_TRAJ_NONE) {
    dm_err e;
    dm_traj_lookup(tr, name, NULL, &e);
    return luaL_error(L, "traj:%s(): %s; the integrator records this diagnostic",
                      what, e.msg);
  }
  push_column(L, tr, j);
  return 1;
}

static int t_energy(lua_State *L)
{
  return push_diag(L, dm_checktraj(L, 1), DM_TRAJ_ENERGY, "energy");
}

static int t_momentum(lua_State *L)
{
  dm_traj *tr = dm_checktraj(L, 1);
  size_t lp = strlen(DM_TRAJ_MOMENTUM), j, found = DM_TRAJ_NONE, count = 0;
  if (!lua_isnoneornil(L, 2)) {
    const char *name = dm_checkcstring(L, 2);
    lua_pushfstring(L, "%s%s", DM_TRAJ_MOMENTUM, name);
    return push_diag(L, tr, lua_tostring(L, -1), "momentum");
  }
  for (j = 0; j < dm_traj_ncols(tr); j++)
    if (strncmp(dm_traj_colname(tr, j), DM_TRAJ_MOMENTUM, lp) == 0) {
      found = j;
      count++;
    }
  if (count != 1)
    return luaL_error(L, "traj:momentum(): %s; name one: traj:momentum(\"theta\") "
                      "reads the column 'momentum_theta'", count == 0
                      ? "the trajectory has no momentum column"
                      : "the trajectory has several momentum columns");
  push_column(L, tr, found);
  return 1;
}

/* }====================================================================== */

static const dm_reg traj_methods[] = {
  {"column", t_column, "traj:column(name) -> vec",
   "A copy of the column called name (\"t\", \"r\", \"p_r\", \"v_r\", \"energy\", ...)."},
  {"names", t_names, "traj:names([kind]) -> {name, ...}",
   "Column names in order, optionally only those of one kind (t, q, p, v, diag, derived, data)."},
  {"kinds", t_kinds, "traj:kinds() -> {name = kind, ...}",
   "The kind of every column: t, q, p, v, diag, derived or data."},
  {"meta", t_meta, "traj:meta([key[, value]]) -> table | string | traj",
   "All metadata as a table, one value, or (with a value, nil removes) set a key."},
  {"slice", t_slice, "traj:slice(i[, j[, stride]]) -> traj",
   "A new trajectory of samples i, i+stride, ... up to j (string.sub rules: negative counts from the end)."},
  {"derive", t_derive, "traj:derive(name | {names}, f) -> traj",
   "Add (or recompute) derived columns whose values are f(sample) for every sample."},
  {"save", t_save, "traj:save(file) -> true | nil, message",
   "Write the trajectory atomically through a temporary file: HDF5 for a name ending in .h5 or .hdf5 (a dataset per column, metadata as attributes), else CSV (%.17g, metadata as comments); an ensemble table under MPI is written by rank 0."},
  {"energy", t_energy, "traj:energy() -> vec",
   "The energy diagnostic column recorded by the integrator."},
  {"momentum", t_momentum, "traj:momentum([name]) -> vec",
   "The momentum diagnostic column 'momentum_<name>' recorded by the integrator."},
  {NULL, NULL, NULL, NULL}
};

static const dm_field traj_fields[] = {
  {"t", "traj.t -> vec", "The times of the samples (the same as traj:column(\"t\"))."},
  {"q", "traj.q -> columns", "The coordinate columns by name or number: traj.q.x, traj.q[1] (vecs); an array of coordinates (dm.coords) by its name and index, traj.q.x[3] (#traj.q.x elements)."},
  {"p", "traj.p -> columns", "The momentum columns by coordinate name or number, when recorded."},
  {"v", "traj.v -> columns", "The velocity columns by coordinate name or number, when recorded."},
  {"status", "traj.status -> string | nil",
   "How the run that made it ended: \"success\", or why it stopped early (\"interrupted\", "
   "\"no convergence\", \"diverged\", ...); nil for a trajectory no run made."},
  {"message", "traj.message -> string | nil",
   "For a run that ended early, what happened (step, time, residual); else nil."},
  {NULL, NULL, NULL}
};

static const luaL_Reg traj_meta[] = {
  {"__index", t_index},
  {"__len", t_len},
  {"__tostring", t_tostring},
  {"__gc", t_gc},
  {"__close", t_gc},
  {NULL, NULL}
};

static const luaL_Reg cols_meta[] = {
  {"__index", cols_index},
  {"__len", cols_len},
  {"__tostring", cols_tostring},
  {NULL, NULL}
};

static const dm_reg traj_funcs[] = {
  {"load_trajectory", l_load, "dm.load_trajectory(file) -> traj | nil, message",
   "Read a trajectory or ensemble table saved by traj:save, CSV or HDF5 (by content), or a plain CSV / HDF5 file with a column t."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_traj(lua_State *L)
{
  dm_newclass(L, DM_TRAJ_MT, "trajectory", traj_methods, traj_meta);
  lua_pop(L, 1);
  dm_doc_fields(L, "trajectory", traj_fields);
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
  dm_register(L, "dm.", traj_funcs);
  dm_ltraj_open_build(L);
}
