/* l_integ_opts.c -- integrator options from a Lua table, mapped by name
 * through dm_integ_options (one generic setter, no code per option), the
 * method name, and user PRK tableaus {a=, b=[, at=, bt=, c=]} checked for
 * symplecticity by dm_tableau_prk.  Part of the integrator binding. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "core/numfmt.h"
#include "lua/l_integ.h"

#define TABBOX_MT "dmech.tableaubox"

/* {======================================================================
 * options
 * ======================================================================= */

static int tabbox_gc(lua_State *L)
{
  dm_tableau **t = luaL_checkudata(L, 1, TABBOX_MT);
  dm_tableau_free(*t);
  *t = NULL;
  return 0;
}

/* k numbers of field `key` of the table at t (a vec, a list, or for
 * matrices a mat or a list of rows) into out; returns the count read
 * (0 when the field is absent).  Checks the size when want > 0. */
static size_t read_numbers(lua_State *L, int t, const char *key, int matrix, size_t want,
                           double *out, size_t max, const char *fname)
{
  size_t k = 0, rows, cols = 0;
  int f;
  if (lua_getfield(L, t, key) == LUA_TNIL) {
    lua_pop(L, 1);
    return 0;
  }
  f = lua_gettop(L);
  if (matrix && dm_tomat(L, f) != NULL) {
    gsl_matrix *M = dm_tomat(L, f);
    rows = M->size1;
    cols = M->size2;
    for (size_t i = 0; i < rows; i++)
      for (size_t j = 0; j < cols; j++)
        if (k < max)
          out[k++] = gsl_matrix_get(M, i, j);
  } else if (!matrix && dm_tovec(L, f) != NULL) {
    gsl_vector *v = dm_tovec(L, f);
    rows = v->size;
    for (size_t i = 0; i < rows; i++)
      if (k < max)
        out[k++] = gsl_vector_get(v, i);
  } else if (lua_type(L, f) == LUA_TTABLE) {
    rows = lua_rawlen(L, f);
    for (size_t i = 1; i <= rows; i++) {
      lua_rawgeti(L, f, (lua_Integer)i);
      if (matrix) {
        int r = lua_gettop(L);
        if (dm_tovec(L, r) == NULL && lua_type(L, r) != LUA_TTABLE)
          luaL_error(L, "%s: tableau.%s: row %d must be a list of numbers", fname, key, (int)i);
        size_t c = dm_tovec(L, r) ? dm_tovec(L, r)->size : lua_rawlen(L, r);
        if (i == 1)
          cols = c;
        if (c != cols)
          luaL_error(L, "%s: tableau.%s: rows of different lengths", fname, key);
        for (size_t j = 0; j < c; j++) {
          int isnum;
          double x;
          if (dm_tovec(L, r)) {
            x = gsl_vector_get(dm_tovec(L, r), j);
          } else {
            lua_rawgeti(L, r, (lua_Integer)j + 1);
            x = lua_tonumberx(L, -1, &isnum);
            if (!isnum)
              luaL_error(L, "%s: tableau.%s[%d][%d] must be a number", fname, key, (int)i,
                         (int)j + 1);
            lua_pop(L, 1);
          }
          if (k < max)
            out[k++] = x;
        }
      } else {
        int isnum;
        double x = lua_tonumberx(L, -1, &isnum);
        if (!isnum)
          luaL_error(L, "%s: tableau.%s[%d] must be a number", fname, key, (int)i);
        if (k < max)
          out[k++] = x;
      }
      lua_pop(L, 1);
    }
  } else {
    return (size_t)luaL_error(L, "%s: tableau.%s must be a %s, got %s", fname, key,
                              matrix ? "matrix (mat or list of rows)" : "vector (vec or list)",
                              luaL_typename(L, f));
  }
  if (want > 0 && (rows != want || (matrix && cols != want)))
    luaL_error(L, "%s: tableau.%s must be %d%s%d, got %d%s%d", fname, key, (int)want,
               matrix ? "x" : "", matrix ? (int)want : 0, (int)rows, matrix ? "x" : "",
               matrix ? (int)cols : 0);
  lua_pop(L, 1);
  return matrix ? rows : k;
}

/* tableau = {a=, b=[, at=, bt=, c=]}: a new tableau in a box (pushed). */
static dm_tableau *parse_tableau(lua_State *L, int idx, const char *fname)
{
  size_t s;
  double *buf;
  dm_tableau **box, *t;
  dm_err e;
  int st;
  if (lua_getfield(L, idx, "tableau") != LUA_TTABLE)
    luaL_error(L, "%s: method 'prk' needs tableau = {a = {{...}}, b = {...}[, at =, bt =, c =]}, "
               "got %s", fname, luaL_typename(L, -1));
  int t_idx = lua_gettop(L);
  buf = lua_newuserdatauv(L, (3 * DM_TABLEAU_SMAX + 2 * DM_TABLEAU_SMAX * DM_TABLEAU_SMAX) *
                          sizeof *buf, 0);
  double *b = buf, *bt = b + DM_TABLEAU_SMAX, *c = bt + DM_TABLEAU_SMAX;
  double *a = c + DM_TABLEAU_SMAX, *at = a + DM_TABLEAU_SMAX * DM_TABLEAU_SMAX;
  s = read_numbers(L, t_idx, "b", 0, 0, b, DM_TABLEAU_SMAX, fname);
  if (s < 1 || s > DM_TABLEAU_SMAX)
    luaL_error(L, "%s: tableau.b must list 1..%d weights, got %d", fname, DM_TABLEAU_SMAX, (int)s);
  if (read_numbers(L, t_idx, "a", 1, s, a, s * s, fname) == 0)
    luaL_error(L, "%s: tableau.a (the %dx%d q-part matrix) is missing", fname, (int)s, (int)s);
  int has_at = read_numbers(L, t_idx, "at", 1, s, at, s * s, fname) > 0;
  int has_bt = read_numbers(L, t_idx, "bt", 0, s, bt, s, fname) > 0;
  int has_c = read_numbers(L, t_idx, "c", 0, s, c, s, fname) > 0;
  box = lua_newuserdatauv(L, sizeof *box, 0);
  *box = NULL;
  luaL_setmetatable(L, TABBOX_MT);
  st = dm_tableau_prk(s, a, b, has_at ? at : NULL, has_bt ? bt : NULL, has_c ? c : NULL, 0.0,
                      &t, &e);
  if (st != DM_OK)
    luaL_error(L, "%s: %s", fname, e.msg);
  *box = t;
  lua_replace(L, t_idx);
  lua_settop(L, t_idx);
  return t;
}

/* "a, b, gsl:<stepper>": the methods for systems of this kind (pushed) */
void dm_linteg_push_methods(lua_State *L, const char *kind)
{
  size_t i, k = 0, count = dm_integrator_count();
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (i = 0; i < count; i++) {
    const dm_integrator_type *t = dm_integrator_type_at(i);
    const char *const *a;
    if (!dm_integrator_accepts(t, kind))
      continue;
    if (k++)
      luaL_addstring(&b, ", ");
    luaL_addstring(&b, t->name);
    if (strcmp(t->name, "gsl") == 0)
      luaL_addstring(&b, ":<stepper>");
    if (strcmp(t->name, "adapt") == 0)
      luaL_addstring(&b, ":<method>");
    for (a = t->names; a != NULL && *a != NULL; a++) {
      luaL_addstring(&b, ", ");
      luaL_addstring(&b, *a);
    }
  }
  luaL_pushresult(&b);
}

static int in_list(const char *const *list, const char *s)
{
  for (; list != NULL && *list != NULL; list++)
    if (strcmp(*list, s) == 0)
      return 1;
  return 0;
}

static void all_options(lua_State *L, const char *const *skip)
{
  luaL_Buffer b;
  const dm_option_desc *d;
  luaL_buffinit(L, &b);
  luaL_addstring(&b, "method, tableau");
  for (d = dm_integ_options; d->name != NULL; d++) {
    luaL_addstring(&b, ", ");
    luaL_addstring(&b, d->name);
  }
  luaL_addstring(&b, ", adapt");
  for (; skip != NULL && *skip != NULL; skip++) {
    luaL_addstring(&b, ", ");
    luaL_addstring(&b, *skip);
  }
  luaL_pushresult(&b);
}

static void set_option(lua_State *L, const dm_option_desc *d, const char *fname,
                       dm_integ_opts *opt)
{
  static const char *const kinds[] = {"an integer", "a number", "a boolean", "a string"};
  dm_err e;
  int st, t = lua_type(L, -1);
  double x = 0;
  if ((d->kind == DM_OPT_INT && !lua_isinteger(L, -1) &&
       !(t == LUA_TNUMBER && lua_tonumber(L, -1) == floor(lua_tonumber(L, -1)))) ||
      (d->kind == DM_OPT_DOUBLE && t != LUA_TNUMBER) ||
      (d->kind == DM_OPT_BOOL && t != LUA_TBOOLEAN) ||
      (d->kind == DM_OPT_STRING && t != LUA_TSTRING)) {
    char got[DM_NUM_BUFSIZE];
    if (t == LUA_TNUMBER)
      dm_num_format(got, sizeof got, lua_tonumber(L, -1));
    luaL_error(L, "%s: option '%s' must be %s, got %s", fname, d->name, kinds[d->kind],
               t == LUA_TNUMBER && d->kind == DM_OPT_INT ? got : luaL_typename(L, -1));
  }
  if (d->kind == DM_OPT_STRING) {
    st = dm_integ_opts_set_string(opt, d->name, lua_tostring(L, -1), &e);
  } else {
    x = d->kind == DM_OPT_BOOL ? (double)lua_toboolean(L, -1) : lua_tonumber(L, -1);
    st = dm_integ_opts_set_number(opt, d->name, x, &e);
  }
  if (st != DM_OK)
    luaL_error(L, "%s: %s", fname, e.msg);
}

void dm_linteg_parse(lua_State *L, int idx, const char *fname, const char *const *skip,
                     const dm_system *sys, dm_integ_opts *opt, const char **method, double *h)
{
  const dm_integrator_type *type;
  dm_err e;
  int given;
  idx = lua_absindex(L, idx);
  dm_integ_opts_init(opt);
  *method = sys->kind != NULL && strcmp(sys->kind, "sphere") == 0 ? "lgvi" : "gauss";
  *h = NAN;
  if (lua_getfield(L, idx, "method") != LUA_TNIL) {
    if (lua_type(L, -1) != LUA_TSTRING)
      luaL_error(L, "%s: option 'method' must be a string, got %s", fname, luaL_typename(L, -1));
    *method = lua_tostring(L, -1);
  }
  lua_pop(L, 1);
  if ((type = dm_integrator_select(sys, *method, NULL, &e)) == NULL)
    luaL_error(L, "%s: %s", fname, e.msg);
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    const dm_option_desc *d;
    if (key != NULL && (strcmp(key, "method") == 0 || strcmp(key, "adapt") == 0
                        || in_list(skip, key))) {
      lua_pop(L, 1);
      continue;
    }
    d = key ? dm_integ_option_find(key) : NULL;
    if (d == NULL && !(key && strcmp(key, "tableau") == 0)) {
      all_options(L, skip);
      const char *list = lua_tostring(L, -1);
      luaL_error(L, "%s: unknown option %s (options: %s)", fname, dm_tolstring(L, -3, NULL),
                 list);
    }
    if (!in_list(type->options, key)) {
      luaL_Buffer b;
      const char *const *o;
      luaL_buffinit(L, &b);
      for (o = type->options; o && *o; o++) {
        luaL_addstring(&b, *o);
        if (o[1] != NULL)
          luaL_addstring(&b, ", ");
      }
      luaL_pushresult(&b);
      luaL_error(L, "%s: option '%s' does not apply to method '%s' (its options: %s)", fname,
                 key, *method, lua_tostring(L, -1));
    }
    if (d != NULL) {
      set_option(L, d, fname, opt);
      if (strcmp(key, "h") == 0) {
        *h = lua_tonumber(L, -1);
        if (*h == 0.0 || !isfinite(*h))
          luaL_error(L, "%s: option 'h' must be a finite non-zero number, got %s", fname,
                     dm_tolstring(L, -1, NULL));
      }
    }
    lua_pop(L, 1);
  }
  /* what opt points to (a tableau, a monitor) is owned by one table */
  lua_createtable(L, 0, 3);
  int own = lua_gettop(L);
  /* families with a user tableau among other methods (the reduced ones)
   * read it only when given; "prk" itself requires it */
  lua_getfield(L, idx, "tableau");
  given = !lua_isnil(L, -1);
  lua_pop(L, 1);
  opt->tableau = NULL;
  if (in_list(type->options, "tableau") && (given || strcmp(type->name, "prk") == 0)) {
    opt->tableau = parse_tableau(L, idx, fname);
    lua_setfield(L, own, "tableau");
  }
  /* a time transformation of the method: "adapt:<method>" */
  if (dm_linteg_parse_adapt(L, idx, fname, sys, opt, own)) {
    lua_pushfstring(L, "adapt:%s", *method);
    *method = lua_tostring(L, -1);
    lua_setfield(L, own, "method");
  }
}

/* }====================================================================== */

/* The keys of dm.integrator's options table, for help and the prompt. */
void dm_linteg_doc_options(lua_State *L)
{
  const char *keys[64];
  size_t k = 0;
  const dm_option_desc *d;
  keys[k++] = "method";
  keys[k++] = "tableau";
  for (d = dm_integ_options; d->name != NULL && k + 2 < sizeof keys / sizeof keys[0]; d++)
    keys[k++] = d->name;
  keys[k++] = "adapt";
  keys[k] = NULL;
  dm_doc_options(L, "dm.integrator", keys);
  dm_linteg_doc_run(L);
}

static const luaL_Reg tabbox_meta[] = {{"__gc", tabbox_gc}, {NULL, NULL}};

void dm_linteg_open_opts(lua_State *L)
{
  dm_newclass(L, TABBOX_MT, "tableaubox", NULL, tabbox_meta);
  lua_pop(L, 1);
}
