/* l_traj.c -- Trajectory userdata: the Lua face of src/core/trajectory.h.
 *
 * A Trajectory userdata holds one dm_traj * (NULL while empty or after
 * close).  It is created empty with its metatable set before the trajectory
 * is allocated, so an error at any point leaves nothing half-built; __gc and
 * __close share one idempotent cleanup.  Columns cross to Lua as dm.vec
 * copies; samples are 1-based (negative indices count from the end).
 * Derive callbacks run under lua_pcall inside a trampoline and the error is
 * re-raised after dm_traj_derive has unwound (no longjmp over C memory).
 * Columns, samples and the traj.q / p / v proxies: l_traj_cols.c.
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

dm_traj *dm_ltraj_checkopen(lua_State *L, int idx)
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
  lua_pushinteger(L, (lua_Integer)dm_traj_len(dm_ltraj_checkopen(L, 1)));
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
    tr = dm_ltraj_checkopen(L, 1);
    if (strcmp(key, "t") == 0)
      dm_ltraj_pushcolumn(L, tr, 0);
    else if (key[1] == '\0' && (key[0] == 'q' || key[0] == 'p' || key[0] == 'v'))
      dm_ltraj_pushcolumns(L, 1, tr, key[0]);
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
    tr = dm_ltraj_checkopen(L, 1);
    k = dm_ltraj_sampleindex(lua_tointeger(L, 2), dm_traj_len(tr));
    if (k == (size_t)-1)
      lua_pushnil(L);
    else
      dm_ltraj_pushsample(L, tr, k);
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
    return dm_ltraj_nocolumn(L, 2, tr, name);
  dm_ltraj_pushcolumn(L, tr, j);
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
  dm_ltraj_pushsample(L, c->s->traj, c->s->k);
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
  dm_ltraj_pushcolumn(L, tr, j);
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
  dm_ltraj_pushcolumn(L, tr, found);
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
  dm_ltraj_open_cols(L);
  dm_register(L, "dm.", traj_funcs);
  dm_ltraj_open_build(L);
}
