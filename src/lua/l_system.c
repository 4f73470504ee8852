/* l_system.c -- dm.system{...}: a Lagrangian written as a Lua function,
 * traced once with symbolic vectors and compiled (dm_lagrangian_compile) to
 * a dm_system; conversions (momentum, velocity, energy), parameters
 * settable after creation, the expressions as printable values.  The
 * userdata layout is shared with other bindings through l_system.h. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/numfmt.h"
#include "lua/l_system.h"
#include "lua/l_expr.h"
#include "expr/lagrangian.h"
#include "expr/native.h"


/* {======================================================================
 * life cycle
 * ======================================================================= */

static void system_release(dm_lsystem *ls)
{
  dm_integrator_free(ls->conv);
  dm_system_release(&ls->sys);
  free(ls->q);
  free(ls->v);
  free(ls->par);
  free(ls->force);
  free(ls->constr);
  free(ls->cyclic);
  free(ls->buf);
  for (size_t g = 0; g < ls->ngroups; g++)
    free(ls->groups[g].name);
  free(ls->groups);
  memset(ls, 0, sizeof *ls);
  ls->L = DM_EXPR_NONE;
}

int dm_lsystem_gc(lua_State *L)
{
  system_release(luaL_checkudata(L, 1, DM_SYSTEM_MT));
  return 0;
}

dm_lsystem *dm_lua_system_new(lua_State *L)
{
  dm_lsystem *ls = lua_newuserdatauv(L, sizeof *ls, 1);
  memset(ls, 0, sizeof *ls);
  ls->L = DM_EXPR_NONE;
  luaL_setmetatable(L, DM_SYSTEM_MT);
  return ls;
}

dm_lsystem *dm_lua_tosystem(lua_State *L, int idx)
{
  dm_lsystem *ls = luaL_testudata(L, idx, DM_SYSTEM_MT);
  return ls != NULL && ls->sys.lagrangian != NULL ? ls : NULL;
}

dm_lsystem *dm_lua_checksystem(lua_State *L, int idx)
{
  dm_lsystem *ls = dm_lua_tosystem(L, idx);
  if (ls == NULL && luaL_testudata(L, idx, DM_SYSTEM_MT) != NULL)
    luaL_error(L, "attempt to use a closed system");
  if (ls == NULL)
    dm_argexpected(L, idx, "system", luaL_typename(L, idx));
  return ls;
}

dm_lsystem *dm_lua_checktraced(lua_State *L, int idx, const char *what)
{
  dm_lsystem *ls = dm_lua_checksystem(L, idx);
  if (!ls->traced)
    luaL_error(L, "%s needs a system defined by a Lagrangian (dm.system{...}); '%s' is a "
               "built-in C system without expressions", what, ls->sys.name);
  return ls;
}

void dm_lua_system_finish(lua_State *L, dm_lsystem *ls, const char *const *cyclic)
{
  dm_err e;
  int st;
  ls->n = ls->sys.n;
  ls->npar = ls->sys.npar;
  ls->m = ls->sys.m;
  if (ls->cyclic == NULL && (ls->cyclic = calloc(ls->n, 1)) == NULL)
    luaL_error(L, "out of memory");
  for (; cyclic != NULL && *cyclic != NULL; cyclic++) {
    long i = dm_lua_system_coord(ls, *cyclic);
    if (i >= 0)
      ls->cyclic[i] = 1;
  }
  if ((ls->buf = calloc(6 * ls->n, sizeof *ls->buf)) == NULL)
    luaL_error(L, "out of memory");
  /* the Legendre maps live in the integrator layer: a midpoint integrator
   * (any method would do) provides them */
  if ((st = dm_integrator_new(&ls->sys, "midpoint", NULL, &ls->conv, &e)) != DM_OK)
    dm_lua_fail(L, "system", st, &e);
  dm_lsystem_push_params(L, -1);
}

/* }====================================================================== */

/* {======================================================================
 * names, parameters, vectors
 * ======================================================================= */

long dm_lua_system_coord(const dm_lsystem *ls, const char *name)
{
  for (size_t i = 0; i < ls->sys.n; i++)
    if (ls->sys.coords != NULL && strcmp(ls->sys.coords[i], name) == 0)
      return (long)i;
  return -1;
}

long dm_lua_system_param(const dm_lsystem *ls, const char *name)
{
  for (size_t i = 0; i < ls->sys.npar; i++)
    if (ls->sys.params != NULL && strcmp(ls->sys.params[i], name) == 0)
      return (long)i;
  return -1;
}

/* "a, b, c" of n names onto the stack. */
const char *dm_lsystem_names(lua_State *L, const char *const *names, size_t n)
{
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (size_t i = 0; i < n; i++) {
    if (i > 0)
      luaL_addstring(&b, ", ");
    luaL_addstring(&b, names[i]);
  }
  if (n == 0)
    luaL_addstring(&b, "none");
  luaL_pushresult(&b);
  return lua_tostring(L, -1);
}

long dm_lsystem_checkparam(lua_State *L, const dm_lsystem *ls, int arg)
{
  const char *name = dm_checkcstring(L, arg);
  long i = dm_lua_system_param(ls, name);
  if (i < 0)
    luaL_error(L, "no parameter '%s' in system '%s' (parameters: %s)", name, ls->sys.name,
               dm_lsystem_names(L, ls->sys.params, ls->sys.npar));
  return i;
}

long dm_lsystem_checkcoord(lua_State *L, const dm_lsystem *ls, int arg)
{
  const char *name = dm_checkcstring(L, arg);
  long i = dm_lua_system_coord(ls, name);
  if (i < 0)
    luaL_error(L, "no coordinate '%s' in system '%s' (coordinates: %s)", name, ls->sys.name,
               dm_lsystem_names(L, ls->sys.coords, ls->sys.n));
  return i;
}

/* A NaN or infinite parameter would be blamed on the state much later
 * ("Newton did not converge at step 1"): refuse it where it is given. */
void dm_lsystem_checkfinite(lua_State *L, const char *what, const char *name, double x)
{
  char buf[DM_NUM_BUFSIZE];
  if (!isfinite(x)) {
    dm_num_format(buf, sizeof buf, x);
    luaL_error(L, "%s: parameter '%s' must be a finite number, got %s", what, name, buf);
  }
}

void dm_lua_system_setparam(lua_State *L, dm_lsystem *ls, size_t i, double x)
{
  dm_err e;
  ls->sys.par[i] = x;
  ls->gen++;
  if (ls->sys.refresh && ls->sys.refresh(&ls->sys, &e) != DM_OK)
    dm_lua_fail(L, "parameter", e.status, &e);
}

/* The array called name, or -1. */
static long find_group(const dm_lsystem *ls, const char *name)
{
  for (size_t g = 0; g < ls->ngroups; g++)
    if (strcmp(ls->groups[g].name, name) == 0)
      return (long)g;
  return -1;
}

/* The array holding coordinate k, or -1. */
static long group_of(const dm_lsystem *ls, size_t k)
{
  for (size_t g = 0; g < ls->ngroups; g++)
    if (k >= ls->groups[g].first && k < ls->groups[g].first + ls->groups[g].count)
      return (long)g;
  return -1;
}

void dm_lua_system_readvec(lua_State *L, const dm_lsystem *ls, int idx,
                           const char *what, double *out)
{
  size_t n = ls->n, k;
  gsl_vector *v;
  idx = lua_absindex(L, idx);
  if ((v = dm_tovec(L, idx)) != NULL) {
    if (v->size != n)
      luaL_error(L, "%s: vector of length %d expected, got length %d", what, (int)n,
                 (int)v->size);
    for (k = 0; k < n; k++)
      out[k] = gsl_vector_get(v, k);
    return;
  }
  if (lua_type(L, idx) != LUA_TTABLE)
    luaL_error(L, "%s: vec or table of %d numbers expected, got %s", what, (int)n,
               luaL_typename(L, idx));
  k = lua_rawlen(L, idx);
  if (k > 0) {
    if (k != n)
      luaL_error(L, "%s: vector of length %d expected, got length %d", what, (int)n, (int)k);
    for (k = 0; k < n; k++) {
      int isnum;
      lua_rawgeti(L, idx, (lua_Integer)k + 1);
      out[k] = lua_tonumberx(L, -1, &isnum);
      if (!isnum || lua_type(L, -1) != LUA_TNUMBER)
        luaL_error(L, "%s: number expected at index %d, got %s", what, (int)k + 1,
                   luaL_typename(L, -1));
      lua_pop(L, 1);
    }
    return;
  }
  /* keyed by coordinate names, arrays by their names */
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    if (lua_type(L, -2) != LUA_TSTRING || (dm_lua_system_coord(ls, lua_tostring(L, -2)) < 0 &&
                                          find_group(ls, lua_tostring(L, -2)) < 0)) {
      const char *key = dm_tolstring(L, -2, NULL);
      const char *known = dm_lsystem_names(L, ls->sys.coords, n);
      luaL_error(L, "%s: unknown coordinate %s (coordinates: %s)", what, key, known);
    }
    lua_pop(L, 1);
  }
  for (size_t g = 0; g < ls->ngroups; g++) {
    const struct dm_lcoordarray *G = &ls->groups[g];
    if (lua_getfield(L, idx, G->name) == LUA_TNIL) {
      lua_pop(L, 1);
      continue;
    }
    if (lua_type(L, -1) != LUA_TTABLE || lua_rawlen(L, -1) != G->count)
      luaL_error(L, "%s: %s must be a list of %d numbers (the array %s[1..%d])", what, G->name,
                 (int)G->count, G->name, (int)G->count);
    for (size_t i = 0; i < G->count; i++) {
      int isnum;
      lua_rawgeti(L, -1, (lua_Integer)i + 1);
      out[G->first + i] = lua_tonumberx(L, -1, &isnum);
      if (!isnum || lua_type(L, -1) != LUA_TNUMBER)
        luaL_error(L, "%s: number expected at %s[%d], got %s", what, G->name, (int)i + 1,
                   luaL_typename(L, -1));
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  for (k = 0; k < n; k++) {
    int isnum;
    long g = group_of(ls, k);
    if (g >= 0) {                     /* given by the array's name? */
      int given = lua_getfield(L, idx, ls->groups[g].name) != LUA_TNIL;
      lua_pop(L, 1);
      if (given)
        continue;
    }
    lua_getfield(L, idx, ls->sys.coords[k]);
    out[k] = lua_tonumberx(L, -1, &isnum);
    if (!isnum || lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "%s: %s for coordinate '%s'", what,
                 lua_isnil(L, -1) ? "no value" : "number expected", ls->sys.coords[k]);
    lua_pop(L, 1);
  }
}

/* }====================================================================== */

/* {======================================================================
 * dm.system{...}
 * ======================================================================= */

/* Names used as symbols and column names: identifiers. */
static int is_ident(const char *s)
{
  if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || *s == '_'))
    return 0;
  for (s++; *s; s++)
    if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || *s == '_' ||
          (*s >= '0' && *s <= '9')))
      return 0;
  return 1;
}

#define COORDS_MT "dmech.coords"

/* dm.coords(name, n): an array of n coordinates name[1] .. name[n] for
 * dm.system's coords (alone or in the list). */
static int l_coords(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  lua_Integer n = luaL_checkinteger(L, 2);
  if (!is_ident(name))
    luaL_argerror(L, 1, "a name (letters, digits, _) expected");
  luaL_argcheck(L, n >= 1 && n <= 1000000, 2, "1 to 1000000 coordinates expected");
  lua_createtable(L, 0, 2);
  lua_pushvalue(L, 1);
  lua_setfield(L, -2, "name");
  lua_pushinteger(L, n);
  lua_setfield(L, -2, "n");
  luaL_setmetatable(L, COORDS_MT);
  return 1;
}

static int coords_tostring(lua_State *L)
{
  lua_getfield(L, 1, "name");
  lua_getfield(L, 1, "n");
  lua_pushfstring(L, "coords %s[1..%d]", lua_tostring(L, -2), (int)lua_tointeger(L, -1));
  return 1;
}

/* A dm.coords object at idx? */
static int is_coords(lua_State *L, int idx)
{
  if (lua_type(L, idx) != LUA_TTABLE || !lua_getmetatable(L, idx))
    return 0;
  luaL_getmetatable(L, COORDS_MT);
  int is = lua_rawequal(L, -1, -2);
  lua_pop(L, 2);
  return is;
}

static int cmp_names(const void *a, const void *b)
{
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* coords = {"r", "theta", ...} with dm.coords arrays among them (or one
 * array alone): pushes a userdata array of names (kept alive by the table
 * at t, and by a table of the names made for arrays, also pushed), and
 * the arrays into ls->groups. */
static const char **read_coords(lua_State *L, int t, dm_lsystem *ls, size_t *n)
{
  const char **names;
  int type = lua_getfield(L, t, "coords"), c = lua_gettop(L);
  if (is_coords(L, c)) {                    /* dm.coords alone: a list of it */
    lua_createtable(L, 1, 0);
    lua_pushvalue(L, c);
    lua_rawseti(L, -2, 1);
    lua_replace(L, c);
  }
  size_t len = type == LUA_TTABLE ? lua_rawlen(L, c) : 0;
  if (len == 0)
    luaL_error(L, "dm.system: field 'coords' must be a non-empty list of coordinate names "
               "(or arrays: dm.coords(name, n)), got %s", luaL_typename(L, c));
  /* count, and the arrays */
  *n = 0;
  for (size_t i = 0; i < len; i++) {
    lua_rawgeti(L, c, (lua_Integer)i + 1);
    if (is_coords(L, -1)) {
      lua_getfield(L, -1, "n");
      *n += (size_t)lua_tointeger(L, -1);
      lua_pop(L, 1);
      ls->ngroups++;
    } else {
      *n += 1;
    }
    lua_pop(L, 1);
  }
  if (ls->ngroups > 0 && (ls->groups = calloc(ls->ngroups, sizeof *ls->groups)) == NULL)
    luaL_error(L, "out of memory");
  names = lua_newuserdatauv(L, *n * sizeof *names, 0);
  lua_createtable(L, 0, 0);                     /* anchors the made names */
  int anchor = lua_gettop(L);
  size_t k = 0, g = 0;
  for (size_t i = 0; i < len; i++) {
    lua_rawgeti(L, c, (lua_Integer)i + 1);
    if (is_coords(L, -1)) {
      lua_getfield(L, -1, "name");
      lua_getfield(L, -2, "n");
      const char *an = lua_tostring(L, -2);
      size_t cnt = (size_t)lua_tointeger(L, -1);
      if ((ls->groups[g].name = strdup(an)) == NULL)
        luaL_error(L, "out of memory");
      ls->groups[g].first = k;
      ls->groups[g++].count = cnt;
      for (size_t j = 0; j < cnt; j++) {
        lua_pushfstring(L, "%s[%d]", an, (int)j + 1);
        names[k++] = lua_tostring(L, -1);
        lua_rawseti(L, anchor, (lua_Integer)k);
      }
      lua_pop(L, 3);
      continue;
    }
    if (lua_type(L, -1) != LUA_TSTRING || !is_ident(lua_tostring(L, -1)))
      luaL_error(L, "dm.system: coordinate %d must be a name (letters, digits, _) or "
                 "dm.coords(name, n), got %s", (int)i + 1, dm_tolstring(L, -1, NULL));
    names[k++] = lua_tostring(L, -1);
    lua_pop(L, 1);
  }
  /* names used twice (also an array's name as a coordinate): sorted */
  const char **sorted = malloc((*n + ls->ngroups + 1) * sizeof *sorted);
  if (sorted == NULL)
    luaL_error(L, "out of memory");
  memcpy(sorted, names, *n * sizeof *sorted);
  for (g = 0; g < ls->ngroups; g++)
    sorted[*n + g] = ls->groups[g].name;
  qsort(sorted, *n + ls->ngroups, sizeof *sorted, cmp_names);
  for (size_t i = 1; i < *n + ls->ngroups; i++)
    if (strcmp(sorted[i - 1], sorted[i]) == 0) {
      char dup[300];
      snprintf(dup, sizeof dup, "%s", sorted[i]);
      free(sorted);
      luaL_error(L, "dm.system: coordinate '%s' is listed twice", dup);
    }
  free(sorted);
  return names;             /* the anchor table stays on the stack */
}

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static size_t read_params_raw(lua_State *L, int t, const char ***pn, double **pv)
{
  size_t n = 0, k = 0;
  int type = lua_getfield(L, t, "params"), p = lua_gettop(L), pairs;
  if (type != LUA_TNIL && type != LUA_TTABLE)
    luaL_error(L, "dm.system: field 'params' must be a table {name = value} or "
               "{{name, value}, ...}, got %s", luaL_typename(L, p));
  pairs = type == LUA_TTABLE && lua_rawlen(L, p) > 0;
  if (type == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, p) != 0) {
      n++;
      lua_pop(L, 1);
    }
  }
  const char **names = lua_newuserdatauv(L, (n + 1) * sizeof *names, 0);
  double *vals = lua_newuserdatauv(L, (n + 1) * sizeof *vals, 0);
  for (size_t i = 0; pairs && i < n; i++) {
    if (lua_rawgeti(L, p, (lua_Integer)i + 1) != LUA_TTABLE ||
        lua_rawgeti(L, -1, 1) != LUA_TSTRING || lua_rawgeti(L, -2, 2) != LUA_TNUMBER)
      luaL_error(L, "dm.system: params entry %d must be {name, number}", (int)i + 1);
    names[k] = lua_tostring(L, -2);
    vals[k++] = lua_tonumber(L, -1);
    lua_pop(L, 3);
  }
  if (!pairs && type == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, p) != 0) {
      if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
        luaL_error(L, "dm.system: params must map names to numbers (got %s = %s)",
                   luaL_typename(L, -2), luaL_typename(L, -1));
      names[k++] = lua_tostring(L, -2);
      lua_pop(L, 1);
    }
    qsort(names, n, sizeof *names, cmp_str);
    for (k = 0; k < n; k++) {
      lua_getfield(L, p, names[k]);
      vals[k] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
  }
  *pn = names;
  *pv = vals;
  return n;
}

/* The parameters with names that are identifiers, each once, and finite
 * values: the same rules for every kind of system (coordinates, groups,
 * spheres). */
size_t dm_lsystem_read_params(lua_State *L, int t, const char ***pn, double **pv)
{
  size_t n = read_params_raw(L, t, pn, pv);
  const char **names = *pn;
  for (size_t k = 0; k < n; k++) {
    if (!is_ident(names[k]))
      luaL_error(L, "dm.system: parameter name '%s' must be letters, digits and _", names[k]);
    dm_lsystem_checkfinite(L, "dm.system", names[k], (*pv)[k]);
    for (size_t j = 0; j < k; j++)
      if (strcmp(names[j], names[k]) == 0)
        luaL_error(L, "dm.system: parameter '%s' is listed twice", names[k]);
  }
  return n;
}

/* Trace field `field` (a function) of the table t with the symbolic
 * vectors at args[0..nargs); convert its result to nodes: one expression
 * when scalar, else want of them (0: any number >= 1) as a list (or a bare
 * expression when want == 1).  Returns the count; nodes malloc'ed into
 * *out. */
static size_t trace_field(lua_State *L, int t, const char *field, const int *args, int nargs,
                          int scalar, size_t want, dm_expr **out, const char *sysname)
{
  char what[160];
  size_t cnt, rows, cols;
  if (lua_getfield(L, t, field) != LUA_TFUNCTION)
    luaL_error(L, "dm.system: field '%s' must be a function, got %s", field, luaL_typename(L, -1));
  snprintf(what, sizeof what, "%s of system '%s'", field, sysname);
  for (int i = 0; i < nargs; i++)
    lua_pushvalue(L, args[i]);
  dm_lua_trace(L, what, nargs);
  if (lua_isnil(L, -1))
    luaL_error(L, "dm.system: %s returned nothing (return %s)", what,
               scalar ? "an expression" : "a list of expressions");
  cnt = dm_lua_toexprs(L, -1, what, NULL, 0, &rows, &cols);
  if (scalar && cols != 0)
    luaL_error(L, "dm.system: %s must return one expression, got a list of %d", what, (int)cnt);
  if (rows != 1 && want == 0)
    luaL_error(L, "dm.system: %s must return an expression or a flat list of them, got a "
               "nested list", what);
  if (rows != 1 || (want > 0 && cnt != want))
    luaL_error(L, "dm.system: %s must return a list of %d expressions (one per coordinate), "
               "got %d value%s", what, (int)want, (int)cnt, cnt == 1 ? "" : "s");
  if ((*out = malloc(cnt * sizeof **out)) == NULL)
    luaL_error(L, "out of memory");
  dm_lua_toexprs(L, -1, what, *out, cnt, NULL, NULL);
  lua_pop(L, 1);
  return cnt;
}

static int cmp_expr(const void *a, const void *b)
{
  dm_expr x = *(const dm_expr *)a, y = *(const dm_expr *)b;
  return (x > y) - (x < y);
}

/* A coordinate is cyclic when neither L nor the force nor the constraints
 * contain it: the symbols of all of them collected once (sorted), each
 * coordinate looked up -- linear in the size of the expressions, not n
 * times it. */
static void detect_cyclic(lua_State *L, dm_lsystem *ls)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  size_t nroots = 1 + (ls->force ? ls->n : 0) + ls->m, k = 0, nv = 0;
  dm_expr *roots = malloc(nroots * sizeof *roots);
  if (roots == NULL)
    luaL_error(L, "out of memory");
  roots[k++] = ls->L;
  for (size_t i = 0; ls->force && i < ls->n; i++)
    roots[k++] = ls->force[i];
  for (size_t i = 0; i < ls->m; i++)
    roots[k++] = ls->constr[i];
  dm_expr *vars = NULL;
  int oom = 0;
  for (size_t r = 0; r < nroots && !oom; r++) {
    long c = dm_expr_free_vars(ctx, roots[r], NULL, 0);
    dm_expr *nv2 = c > 0 ? realloc(vars, (nv + (size_t)c) * sizeof *vars) : vars;
    oom = c > 0 && nv2 == NULL;
    if (!oom)
      vars = nv2;
    if (!oom && c > 0)
      nv += (size_t)dm_expr_free_vars(ctx, roots[r], vars + nv, (size_t)c);
  }
  free(roots);
  if (oom) {
    free(vars);
    luaL_error(L, "out of memory");
  }
  if (nv > 0)
    qsort(vars, nv, sizeof *vars, cmp_expr);
  for (size_t i = 0; i < ls->n; i++)
    ls->cyclic[i] = nv == 0 || bsearch(&ls->q[i], vars, nv, sizeof *vars, cmp_expr) == NULL;
  free(vars);
}

static int native_mode(lua_State *L, int t)
{
  int mode = dm_lua_native_mode(L), type = lua_getfield(L, t, "native");
  if (type == LUA_TBOOLEAN)
    mode = lua_toboolean(L, -1) ? DM_NATIVE_ALWAYS : DM_NATIVE_NEVER;
  else if (type == LUA_TSTRING)
    mode = dm_native_mode_parse(lua_tostring(L, -1));
  else if (type != LUA_TNIL)
    mode = -1;
  if (mode < 0)
    luaL_error(L, "dm.system: native must be \"auto\", \"wait\", \"always\", \"never\" or a "
               "boolean");
  lua_pop(L, 1);
  return mode;
}

/* A misspelt field (Lagrangian =, constraint =) was silently ignored. */
static void check_fields(lua_State *L, int t)
{
  static const char *const known[] = {"name", "coords", "params", "L", "force",
                                      "constraints", "native", NULL};
  if (dm_unknownkey(L, t, known)) {
    int str = lua_type(L, -1) == LUA_TSTRING;
    const char *key = dm_tolstring(L, -1, NULL);
    luaL_error(L, "dm.system: unknown field %s%s%s (fields: name, coords, params, L, "
               "force, constraints, native)", str ? "'" : "[", key, str ? "'" : "]");
  }
}

/* dm.system{name=, coords=, params=, L=, force=, constraints=, native=} */
static int l_system(lua_State *L)
{
  dm_lagrangian_spec sp;
  dm_lagrangian_stats st;
  dm_err e;
  const char **coords, **pnames;
  double *pvals;
  size_t n, npar, m = 0;
  int args[3], s;
  size_t sphere = 0;                              /* n of S^n, or 0 */
  luaL_checktype(L, 1, LUA_TTABLE);
  if (lua_getfield(L, 1, "space") != LUA_TNIL    /* a system on a Lie group */
      && (sphere = dm_lua_tosphere(L, -1)) == 0)
    return dm_lua_lie_system(L);
  lua_settop(L, 1);
  if (sphere > 0)
    dm_lua_sphere_fields(L, sphere);
  check_fields(L, 1);
  const char *name = dm_optstringfield(L, 1, "name", "system");
  dm_lsystem *ls = dm_lua_system_new(L);             /* 2 */
  coords = read_coords(L, 1, ls, &n);
  npar = dm_lsystem_read_params(L, 1, &pnames, &pvals);
  int mode = native_mode(L, 1);
  lua_getfield(L, 1, "L");
  if (!lua_isfunction(L, -1))
    return luaL_error(L, "dm.system: field 'L' must be a function L(q, v, p) returning the "
                      "Lagrangian, got %s", luaL_typename(L, -1));
  lua_pop(L, 1);
  dm_lua_pushsymvec(L, "q", n, coords, NULL, DM_EXPR_SYM);
  args[0] = lua_gettop(L);
  dm_lua_pushsymvec(L, "v", n, coords, "v_%s", DM_EXPR_SYM);
  args[1] = lua_gettop(L);
  for (size_t g = 0; g < ls->ngroups; g++) {        /* q.x[i], v.x[i] */
    const struct dm_lcoordarray *G = &ls->groups[g];
    lua_pushfstring(L, "q.%s", G->name);
    dm_lua_symvec_group(L, args[0], G->name, G->first, G->count, lua_tostring(L, -1));
    lua_pushfstring(L, "v.%s", G->name);
    dm_lua_symvec_group(L, args[1], G->name, G->first, G->count, lua_tostring(L, -1));
    lua_pop(L, 2);
  }
  dm_lua_pushsymvec(L, "p", npar, pnames, NULL, DM_EXPR_PARAM);
  args[2] = lua_gettop(L);

  ls->n = n;
  ls->npar = npar;
  ls->q = malloc(n * sizeof *ls->q);
  ls->v = malloc(n * sizeof *ls->v);
  ls->par = malloc((npar + 1) * sizeof *ls->par);
  ls->cyclic = calloc(n, 1);
  if (!ls->q || !ls->v || !ls->par || !ls->cyclic)
    return luaL_error(L, "out of memory");
  for (size_t i = 0; i < n; i++) {
    lua_geti(L, args[0], (lua_Integer)i + 1);
    ls->q[i] = dm_lua_toexpr(L, -1);
    lua_geti(L, args[1], (lua_Integer)i + 1);
    ls->v[i] = dm_lua_toexpr(L, -1);
    lua_pop(L, 2);
  }
  for (size_t i = 0; i < npar; i++) {
    lua_geti(L, args[2], (lua_Integer)i + 1);
    ls->par[i] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
  dm_expr *Lx;
  trace_field(L, 1, "L", args, 3, 1, 1, &Lx, name);
  ls->L = Lx[0];
  free(Lx);
  if (lua_getfield(L, 1, "force") != LUA_TNIL)
    trace_field(L, 1, "force", args, 3, 0, n, &ls->force, name);
  lua_pop(L, 1);
  if (lua_getfield(L, 1, "constraints") != LUA_TNIL) {
    int cargs[2] = {args[0], args[2]};
    m = trace_field(L, 1, "constraints", cargs, 2, 0, 0, &ls->constr, name);
  }
  lua_pop(L, 1);
  ls->m = m;

  memset(&sp, 0, sizeof sp);
  sp.name = name;
  sp.n = n;
  sp.q = ls->q;
  sp.v = ls->v;
  sp.npar = npar;
  sp.par = ls->par;
  sp.par_values = pvals;
  sp.coord_names = coords;
  sp.param_names = pnames;
  sp.L = ls->L;
  sp.force = ls->force;
  sp.m = m;
  sp.constraints = ls->constr;
  sp.native = mode;
  if ((s = dm_lagrangian_compile(dm_lua_exprctx(L), &sp, &ls->sys, &e)) != DM_OK)
    return dm_lua_fail(L, "dm.system", s, &e);
  if (m >= n)
    return luaL_error(L, "dm.system: %d constraint%s on %d coordinate%s leave%s no motion "
                      "(at most %d independent constraint%s)", (int)m, m == 1 ? "" : "s",
                      (int)n, n == 1 ? "" : "s", m == 1 ? "s" : "", (int)n - 1,
                      n == 2 ? "" : "s");

  ls->traced = 1;
  ls->sys.refresh = dm_lagrangian_refresh;     /* its separable mass follows the parameters */
  if (dm_lagrangian_stats_get(&ls->sys, &st) == DM_OK)
    ls->native = st.native_all;
  if (mode == DM_NATIVE_WAIT && !ls->native) {     /* asked to wait for it: say why not */
    dm_lagrangian_native ns;
    dm_err_clear(&e);
    if (dm_lagrangian_native_state(&ls->sys, &ns, &e) == DM_OK && ns.native == 0 && e.msg[0]) {
      lua_pushfstring(L, "dm.system: '%s' runs on the tape (%s)", name, e.msg);
      dm_lua_warning(L, lua_tostring(L, -1));
      lua_pop(L, 1);
    }
  }
  detect_cyclic(L, ls);
  lua_pushvalue(L, 2);
  dm_lua_system_finish(L, ls, NULL);
  if (sphere > 0) {              /* after its conversions are made (as on R^(n+1)) */
    dm_lua_sphere_system(L, &ls->sys, sphere);
    memset(ls->cyclic, 0, ls->n);  /* the sphere couples the coordinates */
  }
  return 1;
}

void dm_lsystem_native(lua_State *L, dm_lsystem *ls, int *native, int *pending,
                       int want_error)
{
  dm_lagrangian_native ns;
  dm_err e;
  dm_err_clear(&e);
  *native = ls->native;
  *pending = 0;
  if (ls->traced && dm_lagrangian_native_state(&ls->sys, &ns, NULL) == DM_OK) {
    dm_lagrangian_update(&ls->sys);
    dm_lagrangian_native_state(&ls->sys, &ns, &e);
    *native = ls->native = ns.native > 0;
    *pending = ns.pending > 0;
  }
  if (want_error) {
    if (e.msg[0])
      lua_pushstring(L, e.msg);
    else
      lua_pushnil(L);
  }
}

/* }====================================================================== */

static const dm_reg system_funcs[] = {
  {"system", l_system,
   "dm.system{name=, coords={...}, params={name=value} | {{name, value}, ...}, L=function(q, v, p), "
   "force=function(q, v, p), constraints=function(q, p), native=} -> system",
   "A mechanical system from a Lagrangian written in Lua (traced once with symbolic q, v, p: "
   "q.r or q[1], v.r, p.J2), with an optional generalized force (a list of n components, "
   "Lagrange-d'Alembert) and holonomic constraints g(q) = 0; every derivative is exact and "
   "compiled; params given as a map are ordered by name.  native (default dm.config.native): "
   "\"auto\" runs at once on the tape while native code compiles in the background and "
   "takes over between steps (sys.compiling, sys.native, sys.native_error); \"wait\" "
   "compiles first (Ctrl-C, no compiler: the tape, with a warning); \"always\" compiles first and fails without a "
   "compiler; \"never\" keeps the tape.  coords may hold arrays dm.coords(name, n): "
   "coordinates name[1] .. name[n], q.name[i] in L.  space = dm.lie.SO3() (a group) or "
   "dm.lie.sphere(n) makes a system on that space (help(dm.lie.sphere))."},
  {"coords", l_coords, "dm.coords(name, n) -> coordinate array",
   "An array of n coordinates name[1] .. name[n] for dm.system's coords, alone or in the "
   "list with names and other arrays (coords = {\"theta\", dm.coords(\"x\", 64)}): in L, "
   "q.name[i] and v.name[i] (#q.name = n); states may give it as {name = {...}}; "
   "trajectories name its columns name[i] (traj.q.name[i])."},
  {NULL, NULL, NULL, NULL}
};

static const char *const system_keys[] = {"name", "coords", "params", "L", "force",
                                          "constraints", "native", NULL};

void dm_open_system(lua_State *L)
{
  dm_lsystem_open_class(L);
  if (luaL_newmetatable(L, COORDS_MT)) {
    lua_pushcfunction(L, coords_tostring);
    lua_setfield(L, -2, "__tostring");
  }
  lua_pop(L, 1);
  dm_register(L, "dm.", system_funcs);
  dm_doc_options(L, "dm.system", system_keys);
}
