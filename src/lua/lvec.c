/* lvec.c -- dm.vec: GSL vectors as Lua userdata.
 *
 * A vec owns its numbers inside the userdata block (no malloc, nothing to
 * free), or is a view into another object (a matrix row) kept alive through
 * user value 1.  Indexing is 1-based.  Arithmetic: + - between vecs, * and /
 * by scalars, * and / between vecs elementwise, unary minus; :dot for the
 * inner product.  Matrix products live in lmat.c.
 */
#include <config.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>

#include "lua/dmlua.h"

/* {======================================================================
 * construction and checking
 * ======================================================================= */

gsl_vector *dm_pushvec(lua_State *L, size_t n)
{
  dm_lvec *u;
  if (n == 0 || n > ((size_t)-1 - sizeof *u) / sizeof(double))
    luaL_error(L, "vector size %d out of range", (int)n);
  u = lua_newuserdatauv(L, sizeof *u + n * sizeof(double), 1);
  u->v.size = n;
  u->v.stride = 1;
  u->v.data = (double *)(u + 1);
  u->v.block = NULL;
  u->v.owner = 0;
  memset(u->v.data, 0, n * sizeof(double));
  luaL_setmetatable(L, DM_VEC_MT);
  return &u->v;
}

gsl_vector *dm_pushvec_copy(lua_State *L, const double *x, size_t n)
{
  gsl_vector *v = dm_pushvec(L, n);
  memcpy(v->data, x, n * sizeof(double));
  return v;
}

gsl_vector *dm_tovec(lua_State *L, int arg)
{
  dm_lvec *u = luaL_testudata(L, arg, DM_VEC_MT);
  return u != NULL ? &u->v : NULL;
}

gsl_vector *dm_checkvec(lua_State *L, int arg)
{
  return &((dm_lvec *)luaL_checkudata(L, arg, DM_VEC_MT))->v;
}

/* Copy a sequence table of numbers at arg into a new vec (pushed). */
static gsl_vector *vec_fromtable(lua_State *L, int arg)
{
  size_t i, n = lua_rawlen(L, arg);
  gsl_vector *v;
  if (n == 0)
    dm_argexpected(L, arg, "non-empty table of numbers", "empty table");
  v = dm_pushvec(L, n);
  for (i = 0; i < n; i++) {
    int isnum;
    double x;
    lua_rawgeti(L, arg, (lua_Integer)i + 1);
    x = lua_tonumberx(L, -1, &isnum);
    if (!isnum) {
      const char *msg = lua_pushfstring(L, "table of numbers expected, got %s at index %d",
                                        luaL_typename(L, -1), (int)i + 1);
      luaL_argerror(L, arg, msg);
    }
    v->data[i] = x;
    lua_pop(L, 1);
  }
  return v;
}

gsl_vector *dm_checkvector(lua_State *L, int arg, size_t n)
{
  gsl_vector *v;
  arg = lua_absindex(L, arg);
  v = dm_tovec(L, arg);
  if (v == NULL) {
    if (lua_type(L, arg) != LUA_TTABLE)
      dm_argexpected(L, arg, "vec or table of numbers", luaL_typename(L, arg));
    v = vec_fromtable(L, arg);
    lua_replace(L, arg);
  } else if (v->stride != 1) {
    gsl_vector *c = dm_pushvec(L, v->size);
    gsl_vector_memcpy(c, v);
    lua_replace(L, arg);
    v = c;
  }
  if (n != 0 && v->size != n) {
    const char *want = lua_pushfstring(L, "vector of length %d", (int)n);
    const char *got = lua_pushfstring(L, "length %d", (int)v->size);
    dm_argexpected(L, arg, want, got);
  }
  return v;
}

/* }====================================================================== */

/* {======================================================================
 * functions of dm
 * ======================================================================= */

static int l_vec(lua_State *L)
{
  int nargs = lua_gettop(L);
  if (nargs == 1 && lua_isinteger(L, 1)) {
    lua_Integer n = lua_tointeger(L, 1);
    if (n <= 0)
      return luaL_argerror(L, 1, lua_pushfstring(L, "positive size expected, got %I", n));
    dm_pushvec(L, (size_t)n);
  } else if (nargs == 1 && dm_tovec(L, 1) != NULL) {
    gsl_vector *src = dm_tovec(L, 1);
    gsl_vector_memcpy(dm_pushvec(L, src->size), src);
  } else if (nargs == 1 && lua_type(L, 1) == LUA_TTABLE) {
    vec_fromtable(L, 1);
  } else if (nargs >= 2) {
    int i;
    gsl_vector *v;
    for (i = 1; i <= nargs; i++)
      luaL_checknumber(L, i);
    v = dm_pushvec(L, (size_t)nargs);
    for (i = 1; i <= nargs; i++)
      v->data[i - 1] = lua_tonumber(L, i);
  } else {
    return dm_argexpected(L, 1, "size, table of numbers, vec or several numbers",
                          nargs == 0 ? "no value" : luaL_typename(L, 1));
  }
  return 1;
}

static int l_linspace(lua_State *L)
{
  double a = luaL_checknumber(L, 1), b = luaL_checknumber(L, 2);
  lua_Integer n = luaL_checkinteger(L, 3), i;
  gsl_vector *v;
  luaL_argcheck(L, n >= 2, 3, "at least 2 points expected");
  v = dm_pushvec(L, (size_t)n);
  for (i = 0; i < n; i++)
    v->data[i] = (i == n - 1) ? b : a + (b - a) * (double)i / (double)(n - 1);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * methods
 * ======================================================================= */

static gsl_vector *samelen(lua_State *L, int arg, const gsl_vector *v)
{
  return dm_checkvector(L, arg, v->size);
}

static int v_dot(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  gsl_vector *w = samelen(L, 2, v);
  double r;
  gsl_blas_ddot(v, w, &r);
  lua_pushnumber(L, r);
  return 1;
}

static int v_cross(lua_State *L)
{
  gsl_vector *a = dm_checkvec(L, 1), *b, *c;
  if (a->size != 3)
    return luaL_error(L, "cross: 3-vectors expected, got length %d", (int)a->size);
  b = dm_checkvector(L, 2, 3);
  c = dm_pushvec(L, 3);
#define A(i) gsl_vector_get(a, i)
#define B(i) gsl_vector_get(b, i)
  c->data[0] = A(1) * B(2) - A(2) * B(1);
  c->data[1] = A(2) * B(0) - A(0) * B(2);
  c->data[2] = A(0) * B(1) - A(1) * B(0);
#undef A
#undef B
  return 1;
}

static int v_norm(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  double p = luaL_optnumber(L, 2, 2.0), r = 0.0;
  size_t i;
  luaL_argcheck(L, p >= 1.0, 2, "p >= 1 expected");
  if (p == 2.0)
    r = gsl_blas_dnrm2(v);
  else if (p == 1.0)
    r = gsl_blas_dasum(v);
  else if (isinf(p)) {
    for (i = 0; i < v->size; i++)
      r = fmax(r, fabs(gsl_vector_get(v, i)));
  } else {
    double mx = 0.0;
    for (i = 0; i < v->size; i++)
      mx = fmax(mx, fabs(gsl_vector_get(v, i)));
    if (mx > 0.0) {
      for (i = 0; i < v->size; i++)
        r += pow(fabs(gsl_vector_get(v, i)) / mx, p);
      r = mx * pow(r, 1.0 / p);
    }
  }
  lua_pushnumber(L, r);
  return 1;
}

static int v_sum(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  double s = 0.0, c = 0.0;   /* Kahan-Babuska summation */
  size_t i;
  for (i = 0; i < v->size; i++) {
    double x = gsl_vector_get(v, i), t = s + x;
    c += fabs(s) >= fabs(x) ? (s - t) + x : (x - t) + s;
    s = t;
  }
  lua_pushnumber(L, s + c);
  return 1;
}

static int v_minmax(lua_State *L, int wantmax)
{
  gsl_vector *v = dm_checkvec(L, 1);
  size_t k = wantmax ? gsl_vector_max_index(v) : gsl_vector_min_index(v);
  lua_pushnumber(L, gsl_vector_get(v, k));
  lua_pushinteger(L, (lua_Integer)k + 1);
  return 2;
}
static int v_min(lua_State *L) { return v_minmax(L, 0); }
static int v_max(lua_State *L) { return v_minmax(L, 1); }

static int v_totable(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  size_t i;
  lua_createtable(L, (int)v->size, 0);
  for (i = 0; i < v->size; i++) {
    lua_pushnumber(L, gsl_vector_get(v, i));
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

static int v_copy(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  gsl_vector_memcpy(dm_pushvec(L, v->size), v);
  return 1;
}

static int v_map(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1), *r;
  size_t i;
  luaL_checktype(L, 2, LUA_TFUNCTION);
  r = dm_pushvec(L, v->size);
  for (i = 0; i < v->size; i++) {
    int isnum;
    lua_pushvalue(L, 2);
    lua_pushnumber(L, gsl_vector_get(v, i));
    lua_call(L, 1, 1);
    r->data[i] = lua_tonumberx(L, -1, &isnum);
    if (!isnum)
      return luaL_error(L, "map: function returned %s for element %d (number expected)",
                        luaL_typename(L, -1), (int)i + 1);
    lua_pop(L, 1);
  }
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * metamethods
 * ======================================================================= */

static size_t checkindex(lua_State *L, const gsl_vector *v, int arg)
{
  lua_Integer k = luaL_checkinteger(L, arg);
  if (k < 1 || (size_t)k > v->size)
    luaL_error(L, "vec index %I out of range 1..%d", k, (int)v->size);
  return (size_t)k - 1;
}

static int m_index(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  if (lua_type(L, 2) == LUA_TNUMBER) {
    lua_pushnumber(L, gsl_vector_get(v, checkindex(L, v, 2)));
    return 1;
  }
  return dm_index_methods(L);
}

static int m_newindex(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  size_t k;
  if (lua_type(L, 2) != LUA_TNUMBER)
    return luaL_error(L, "vec: cannot set field '%s' (only integer indices)",
                      dm_tolstring(L, 2, NULL));
  k = checkindex(L, v, 2);
  gsl_vector_set(v, k, luaL_checknumber(L, 3));
  return 0;
}

static int m_len(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)dm_checkvec(L, 1)->size);
  return 1;
}

/* The two operands of a binary metamethod as (vec, vec) of equal length, or
 * (vec, scalar) in either order; raises a clear error otherwise. */
typedef struct operands {
  gsl_vector *a, *b;
  double s;
  int scalar_first;   /* s op b */
} operands;

static void getoperands(lua_State *L, const char *op, operands *o)
{
  o->a = dm_tovec(L, 1);
  o->b = dm_tovec(L, 2);
  o->s = 0.0;
  o->scalar_first = 0;
  if (o->a != NULL && o->b != NULL) {
    if (o->a->size != o->b->size)
      luaL_error(L, "vec %s vec: lengths differ (%d and %d)", op,
                 (int)o->a->size, (int)o->b->size);
    return;
  }
  if (o->a != NULL && lua_type(L, 2) == LUA_TNUMBER) {
    o->s = lua_tonumber(L, 2);
    return;
  }
  if (o->b != NULL && lua_type(L, 1) == LUA_TNUMBER) {
    o->s = lua_tonumber(L, 1);
    o->a = o->b;
    o->b = NULL;
    o->scalar_first = 1;
    return;
  }
  luaL_error(L, "vec %s: vec or number operands expected, got %s and %s", op,
             luaL_typename(L, 1), luaL_typename(L, 2));
}

static int arith(lua_State *L, char op)
{
  char opname[2] = {op, 0};
  operands o;
  gsl_vector *r;
  size_t i;
  if (op == '*' && dm_tomat(L, 2) != NULL) {   /* row vector times matrix */
    lua_getfield(L, LUA_REGISTRYINDEX, "dmech.vecmat");
    lua_insert(L, 1);
    lua_call(L, 2, 1);
    return 1;
  }
  getoperands(L, opname, &o);     /* a number broadcasts: v + 1, 2 - v, 3 * v */
  r = dm_pushvec(L, o.a->size);
  for (i = 0; i < r->size; i++) {
    double x = gsl_vector_get(o.a, i);
    double y = o.b != NULL ? gsl_vector_get(o.b, i) : o.s;
    if (o.scalar_first) {
      double t = x; x = y; y = t;
    }
    switch (op) {
    case '+': r->data[i] = x + y; break;
    case '-': r->data[i] = x - y; break;
    case '*': r->data[i] = x * y; break;
    default:  r->data[i] = x / y; break;
    }
  }
  return 1;
}

static int m_add(lua_State *L) { return arith(L, '+'); }
static int m_sub(lua_State *L) { return arith(L, '-'); }
static int m_mul(lua_State *L) { return arith(L, '*'); }
static int m_div(lua_State *L) { return arith(L, '/'); }

static int m_unm(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1), *r = dm_pushvec(L, v->size);
  size_t i;
  for (i = 0; i < v->size; i++)
    r->data[i] = -gsl_vector_get(v, i);
  return 1;
}

static int m_eq(lua_State *L)
{
  gsl_vector *a = dm_tovec(L, 1), *b = dm_tovec(L, 2);
  int eq = a != NULL && b != NULL && a->size == b->size;
  size_t i;
  for (i = 0; eq && i < a->size; i++)
    eq = gsl_vector_get(a, i) == gsl_vector_get(b, i);
  lua_pushboolean(L, eq);
  return 1;
}

#define VEC_SHOW_MAX 100

static int m_tostring(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  luaL_Buffer b;
  char num[32];
  size_t i, n = v->size < VEC_SHOW_MAX ? v->size : VEC_SHOW_MAX;
  luaL_buffinit(L, &b);
  luaL_addstring(&b, "vec{");
  for (i = 0; i < n; i++) {
    if (i > 0)
      luaL_addstring(&b, ", ");
    dm_num_format(num, sizeof num, gsl_vector_get(v, i));
    luaL_addstring(&b, num);
  }
  if (n < v->size) {
    snprintf(num, sizeof num, ", ... (%d)", (int)v->size);
    luaL_addstring(&b, num);
  }
  luaL_addstring(&b, "}");
  luaL_pushresult(&b);
  return 1;
}

/* }====================================================================== */

static const dm_reg vec_methods[] = {
  {"dot", v_dot, "v:dot(w) -> number", "Inner product of v with a vec or table w of the same length."},
  {"cross", v_cross, "v:cross(w) -> vec", "Cross product of two 3-vectors."},
  {"norm", v_norm, "v:norm([p]) -> number", "The p-norm of v (default 2; p = math.huge gives the max norm)."},
  {"sum", v_sum, "v:sum() -> number", "Sum of the elements, with compensated summation."},
  {"min", v_min, "v:min() -> x, k", "Smallest element and its (1-based) index."},
  {"max", v_max, "v:max() -> x, k", "Largest element and its (1-based) index."},
  {"totable", v_totable, "v:totable() -> table", "The elements as a new Lua table."},
  {"copy", v_copy, "v:copy() -> vec", "An independent copy of v (also of a matrix-row view)."},
  {"map", v_map, "v:map(f) -> vec", "New vec with f applied to every element."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg vec_meta[] = {
  {"__index", m_index},
  {"__newindex", m_newindex},
  {"__len", m_len},
  {"__add", m_add},
  {"__sub", m_sub},
  {"__mul", m_mul},
  {"__div", m_div},
  {"__unm", m_unm},
  {"__eq", m_eq},
  {"__tostring", m_tostring},
  {NULL, NULL}
};

/* dm.format_number(x[, digits]): the text every number of dmech is printed
 * and written as (core/numfmt.h), or "%.<digits>g" in the C locale */
static int l_format_number(lua_State *L)
{
  char buf[DM_NUM_BUFSIZE];
  double x = luaL_checknumber(L, 1);
  lua_Integer digits = luaL_optinteger(L, 2, 0);
  luaL_argcheck(L, digits >= 0 && digits <= 17, 2, "digits from 1 to 17 expected (0: shortest)");
  if (digits == 0)
    dm_num_format(buf, sizeof buf, x);
  else
    dm_num_snprintf(buf, sizeof buf, "%.*g", (int)digits, x);
  lua_pushstring(L, buf);
  return 1;
}

static const dm_reg vec_funcs[] = {
  {"format_number", l_format_number, "dm.format_number(x[, digits]) -> string",
   "The shortest decimal that reads back as exactly x (\"0.1\", \"2.385\", \"1e-300\", "
   "\"nan\", \"inf\"), or x to that many significant digits (%g), with '.' whatever the "
   "locale: how dmech prints and writes numbers."},
  {"vec", l_vec, "dm.vec(n | {x1, ...} | v | x1, x2, ...) -> vec",
   "A vector of n zeros, or of the given numbers (a copy when given a vec)."},
  {"linspace", l_linspace, "dm.linspace(a, b, n) -> vec",
   "Vector of n equally spaced numbers from a to b, both included."},
  {NULL, NULL, NULL, NULL}
};


void dm_open_linalg(lua_State *L)
{
  dm_newclass(L, DM_VEC_MT, "vec", vec_methods, vec_meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", vec_funcs);
  dm_open_mat(L);
}
