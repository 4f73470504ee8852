/* l_lie_elem.c -- group elements in Lua: g * h (composition), g * x (the
 * action), g:inv(), g:log(), g:matrix(), g:Ad(), g[i] (a row of the matrix,
 * a component of R^n / T^n, a factor of a product), g.R, g.p, g.theta,
 * compact printing; numeric or symbolic (expression nodes) alike.
 * See l_lie.h. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_lie.h"
#include "lua/l_expr.h"

dm_lelem *dm_lua_newelem(lua_State *L, int gidx, int sym)
{
  const dm_lie_group *G;
  dm_lelem *el;
  size_t i;
  gidx = lua_absindex(L, gidx);
  G = dm_lua_checkgroup(L, gidx);
  el = lua_newuserdatauv(L, sizeof *el + G->nq * sizeof(dm_lslot), 1);
  el->G = G;
  el->sym = sym;
  for (i = 0; i < G->nq; i++)
    el->v[i].x = 0.0;
  luaL_setmetatable(L, DM_LIEELEM_MT);
  lua_pushvalue(L, gidx);
  lua_setiuservalue(L, -2, 1);
  return el;
}

dm_lelem *dm_lua_toelem(lua_State *L, int idx)
{
  return luaL_testudata(L, idx, DM_LIEELEM_MT);
}

dm_lelem *dm_lua_checkelem(lua_State *L, int idx, const char *fname)
{
  dm_lelem *el = dm_lua_toelem(L, idx);
  if (el == NULL)
    luaL_error(L, "%s: a group element expected, got %s", fname, luaL_typename(L, idx));
  return el;
}

void dm_lua_elemgroup(lua_State *L, int idx)
{
  lua_getiuservalue(L, idx, 1);
}

void dm_lua_elem_numbers(lua_State *L, const dm_lelem *el, const char *fname, double *out)
{
  size_t i;
  if (el->sym)
    luaL_error(L, "%s: needs a numeric %s element, got a symbolic one", fname, el->G->name);
  for (i = 0; i < el->G->nq; i++)
    out[i] = el->v[i].x;
}

void dm_lua_elem_nodes(lua_State *L, const dm_lelem *el, dm_expr *out)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  size_t i;
  for (i = 0; i < el->G->nq; i++)
    out[i] = el->sym ? el->v[i].e : dm_expr_const(ctx, el->v[i].x);
}

/* a new element of the same group as the element at idx */
static dm_lelem *new_like(lua_State *L, int idx, int sym)
{
  dm_lelem *el;
  dm_lua_elemgroup(L, idx);
  el = dm_lua_newelem(L, -1, sym);
  lua_remove(L, -2);
  return el;
}

static void set_vals(dm_lelem *el, const double *x, const dm_expr *ex)
{
  size_t i;
  for (i = 0; i < el->G->nq; i++) {
    if (el->sym)
      el->v[i].e = ex[i];
    else
      el->v[i].x = x[i];
  }
}

/* {======================================================================
 * methods
 * ======================================================================= */

static int e_inv(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:inv"), *r;
  const dm_lie_group *G = a->G;
  double x[DM_LIE_NQ_MAX];
  dm_expr ex[DM_LIE_NQ_MAX];
  dm_err e;
  if (a->sym) {
    dm_lua_elem_nodes(L, a, ex);
    if (dm_lie_sym_inverse(dm_lua_exprctx(L), G, ex, ex, &e) != DM_OK)
      return dm_lua_lie_symfail(L, "g:inv", &e);
  } else {
    dm_lua_elem_numbers(L, a, "g:inv", x);
    dm_lie_inverse(G, x, x);
  }
  r = new_like(L, 1, a->sym);
  set_vals(r, x, ex);
  return 1;
}

static int e_log(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:log");
  const dm_lie_group *G = a->G;
  double x[DM_LIE_NQ_MAX], xi[DM_LIE_DIM_MAX];
  dm_expr ex[DM_LIE_NQ_MAX], exi[DM_LIE_DIM_MAX];
  dm_err e;
  if (a->sym) {
    dm_lua_elem_nodes(L, a, ex);
    if (dm_lie_sym_log(dm_lua_exprctx(L), G, ex, exi, &e) != DM_OK)
      return dm_lua_lie_symfail(L, "g:log", &e);
  } else {
    dm_lua_elem_numbers(L, a, "g:log", x);
    dm_lie_log(G, x, xi);
  }
  dm_lua_pushvals(L, G->dim, a->sym, xi, exi);
  return 1;
}

static int e_matrix(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:matrix");
  const dm_lie_group *G = a->G;
  size_t m = G->msize;
  double *M = lua_newuserdatauv(L, m * m * sizeof *M, 0), x[DM_LIE_NQ_MAX];
  dm_expr *S = lua_newuserdatauv(L, m * m * sizeof *S, 0), ex[DM_LIE_NQ_MAX];
  dm_err e;
  if (a->sym) {
    dm_lua_elem_nodes(L, a, ex);
    if (dm_lie_sym_matrix(dm_lua_exprctx(L), G, ex, S, &e) != DM_OK)
      return dm_lua_lie_symfail(L, "g:matrix", &e);
  } else {
    dm_lua_elem_numbers(L, a, "g:matrix", x);
    dm_lie_matrix(G, x, M, m);
  }
  dm_lua_pushmatvals(L, m, m, a->sym, M, S);
  return 1;
}

static int e_Ad(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:Ad");
  const dm_lie_group *G = a->G;
  size_t n = G->dim;
  double *M = lua_newuserdatauv(L, n * n * sizeof *M, 0), x[DM_LIE_NQ_MAX];
  dm_expr *S = lua_newuserdatauv(L, n * n * sizeof *S, 0), ex[DM_LIE_NQ_MAX];
  dm_err e;
  if (a->sym) {
    dm_lua_elem_nodes(L, a, ex);
    if (dm_lie_sym_Ad(dm_lua_exprctx(L), G, ex, S, &e) != DM_OK)
      return dm_lua_lie_symfail(L, "g:Ad", &e);
  } else {
    dm_lua_elem_numbers(L, a, "g:Ad", x);
    dm_lie_Ad(G, x, M, n);
  }
  dm_lua_pushmatvals(L, n, n, a->sym, M, S);
  return 1;
}

/* the action g . x on R^kdim */
static int act(lua_State *L, int gi, int xi, const char *fname)
{
  dm_lelem *a = dm_lua_checkelem(L, gi, fname);
  const dm_lie_group *G = a->G;
  double g[DM_LIE_NQ_MAX], x[DM_LIE_NQ_MAX], y[DM_LIE_NQ_MAX];
  dm_expr eg[DM_LIE_NQ_MAX], ex[DM_LIE_NQ_MAX], ey[DM_LIE_NQ_MAX];
  dm_err e;
  char what[128];
  int sym;
  if (G->kdim > DM_LIE_NQ_MAX)
    return luaL_error(L, "%s: %s acts on R^%d, too large here", fname, G->name, (int)G->kdim);
  snprintf(what, sizeof what, "the point of R^%d that %s acts on", (int)G->kdim, G->name);
  sym = dm_lua_readvals(L, xi, G->kdim, fname, what, x, ex) | a->sym;
  if (sym) {
    dm_lua_elem_nodes(L, a, eg);
    if (dm_lie_sym_act(dm_lua_exprctx(L), G, eg, ex, ey, &e) != DM_OK)
      return dm_lua_lie_symfail(L, fname, &e);
  } else {
    dm_lua_elem_numbers(L, a, fname, g);
    dm_lie_act(G, g, x, y);
  }
  dm_lua_pushvals(L, G->kdim, sym, y, ey);
  return 1;
}

static int e_act(lua_State *L)
{
  return act(L, 1, 2, "g:act");
}

static int e_dist(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:dist"), *b = dm_lua_checkelem(L, 2, "g:dist");
  double x[DM_LIE_NQ_MAX], y[DM_LIE_NQ_MAX];
  if (!dm_lie_group_equal(a->G, b->G))
    return luaL_error(L, "g:dist: elements of %s and %s", a->G->name, b->G->name);
  dm_lua_elem_numbers(L, a, "g:dist", x);
  dm_lua_elem_numbers(L, b, "g:dist", y);
  lua_pushnumber(L, dm_lie_dist(a->G, x, y));
  return 1;
}

static int e_normalize(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:normalize"), *r;
  double x[DM_LIE_NQ_MAX];
  dm_lua_elem_numbers(L, a, "g:normalize", x);
  dm_lie_normalize(a->G, x);
  r = new_like(L, 1, 0);
  set_vals(r, x, NULL);
  return 1;
}

static int e_coords(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g:coords");
  double x[DM_LIE_NQ_MAX];
  dm_expr ex[DM_LIE_NQ_MAX];
  size_t i;
  for (i = 0; i < a->G->nq; i++) {
    x[i] = a->sym ? NAN : a->v[i].x;
    ex[i] = a->sym ? a->v[i].e : DM_EXPR_NONE;
  }
  dm_lua_pushvals(L, a->G->nq, a->sym, x, ex);
  return 1;
}

static int e_group(lua_State *L)
{
  dm_lua_checkelem(L, 1, "g:group");
  dm_lua_elemgroup(L, 1);
  return 1;
}

static int e_is_symbolic(lua_State *L)
{
  lua_pushboolean(L, dm_lua_checkelem(L, 1, "g:is_symbolic")->sym);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * metamethods
 * ======================================================================= */

static int e_mul(lua_State *L)
{
  dm_lelem *a = dm_lua_toelem(L, 1), *b = dm_lua_toelem(L, 2), *r;
  double x[DM_LIE_NQ_MAX], y[DM_LIE_NQ_MAX];
  dm_expr ex[DM_LIE_NQ_MAX], ey[DM_LIE_NQ_MAX];
  dm_err e;
  int sym;
  if (a == NULL)
    return luaL_error(L, "g * h: the left operand must be a group element, got %s",
                      luaL_typename(L, 1));
  if (b == NULL)
    return act(L, 1, 2, "g * x");
  if (!dm_lie_group_equal(a->G, b->G))
    return luaL_error(L, "g * h: elements of different groups (%s and %s)", a->G->name,
                      b->G->name);
  sym = a->sym || b->sym;
  if (sym) {
    dm_lua_elem_nodes(L, a, ex);
    dm_lua_elem_nodes(L, b, ey);
    if (dm_lie_sym_compose(dm_lua_exprctx(L), a->G, ex, ey, ex, &e) != DM_OK)
      return dm_lua_lie_symfail(L, "g * h", &e);
  } else {
    dm_lua_elem_numbers(L, a, "g * h", x);
    dm_lua_elem_numbers(L, b, "g * h", y);
    dm_lie_compose(a->G, x, y, x);
  }
  r = new_like(L, 1, sym);
  set_vals(r, x, ex);
  return 1;
}

static int e_tostring(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "tostring");
  double x[DM_LIE_NQ_MAX];
  char buf[512];
  if (a->sym) {
    lua_pushfstring(L, "<%s element (symbolic)>", a->G->name);
    return 1;
  }
  dm_lua_elem_numbers(L, a, "tostring", x);
  dm_lie_describe(a->G, x, buf, sizeof buf);
  lua_pushfstring(L, "<%s %s>", a->G->name, buf);
  return 1;
}

/* a group userdata for a sub-part (a factor, the rotation of SE3) */
static void push_subgroup(lua_State *L, const dm_lie_group *F)
{
  dm_err e;
  dm_lie_group **slot = dm_lua_newgroup(L);
  if ((*slot = dm_lie_group_copy(F, &e)) == NULL)
    dm_lua_fail(L, "element", e.status, &e);
}

/* the sub-element of a at storage offset off, of group F */
static void push_sub(lua_State *L, const dm_lelem *a, const dm_lie_group *F, size_t off)
{
  dm_lelem *r;
  push_subgroup(L, F);
  r = dm_lua_newelem(L, -1, a->sym);
  memcpy(r->v, a->v + off, F->nq * sizeof *r->v);
  lua_remove(L, -2);
}

static void push_slots(lua_State *L, const dm_lelem *a, size_t off, size_t n)
{
  size_t i;
  if (!a->sym) {
    double x[DM_LIE_NQ_MAX];
    for (i = 0; i < n; i++)
      x[i] = a->v[off + i].x;
    dm_pushvec_copy(L, x, n);
    return;
  }
  lua_createtable(L, (int)n, 0);
  for (i = 0; i < n; i++) {
    dm_lua_pushexpr(L, a->v[off + i].e);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
}

/* g[i]: a factor (products), a component (R^n, T^n), a row of the matrix */
static int index_int(lua_State *L, dm_lelem *a, lua_Integer i)
{
  const dm_lie_group *G = a->G;
  size_t m = G->msize, j;
  if (G->kind == DM_LIE_PRODUCT) {
    if (i < 1 || (size_t)i > G->nfac)
      return luaL_error(L, "%s element: factor %d out of range 1..%d", G->name, (int)i,
                        (int)G->nfac);
    push_sub(L, a, G->fac[i - 1], G->qoff[i - 1]);
    return 1;
  }
  if (G->kind == DM_LIE_RN || G->kind == DM_LIE_TN) {
    if (i < 1 || (size_t)i > G->nq)
      return luaL_error(L, "%s element: component %d out of range 1..%d", G->name, (int)i,
                        (int)G->nq);
    if (a->sym)
      dm_lua_pushexpr(L, a->v[i - 1].e);
    else
      lua_pushnumber(L, a->v[i - 1].x);
    return 1;
  }
  if (i < 1 || (size_t)i > m)
    return luaL_error(L, "%s element: row %d out of range 1..%d", G->name, (int)i, (int)m);
  {
    double x[DM_LIE_NQ_MAX], M[16];
    dm_expr ex[DM_LIE_NQ_MAX], S[16];
    dm_err e;
    if (a->sym) {
      dm_lua_elem_nodes(L, a, ex);
      if (dm_lie_sym_matrix(dm_lua_exprctx(L), G, ex, S, &e) != DM_OK)
        return dm_lua_lie_symfail(L, "g[i]", &e);
    } else {
      dm_lua_elem_numbers(L, a, "g[i]", x);
      dm_lie_matrix(G, x, M, m);
    }
    lua_createtable(L, (int)m, 0);
    for (j = 0; j < m; j++) {
      if (a->sym)
        dm_lua_pushexpr(L, S[(i - 1) * m + j]);
      else
        lua_pushnumber(L, M[(i - 1) * m + j]);
      lua_rawseti(L, -2, (lua_Integer)j + 1);
    }
  }
  return 1;
}

static int e_index(lua_State *L)
{
  dm_lelem *a = dm_lua_checkelem(L, 1, "g[k]");
  const dm_lie_group *G = a->G;
  const char *k;
  if (lua_isinteger(L, 2))
    return index_int(L, a, lua_tointeger(L, 2));
  if ((k = lua_tostring(L, 2)) == NULL)
    return luaL_error(L, "%s element: no field %s", G->name, dm_tolstring(L, 2, NULL));
  if (luaL_getmetafield(L, 1, "__methods") != LUA_TNIL) {
    lua_pushvalue(L, 2);
    if (lua_rawget(L, -2) != LUA_TNIL)
      return 1;
    lua_pop(L, 2);
  }
  if (strcmp(k, "R") == 0 && G->kind == DM_LIE_SE3) {
    dm_err e;
    dm_lie_group *S = dm_lie_so3(&e);
    if (S == NULL)
      return dm_lua_fail(L, "g.R", e.status, &e);
    {
      dm_lie_group **slot = dm_lua_newgroup(L);
      dm_lelem *r;
      *slot = S;
      r = dm_lua_newelem(L, -1, a->sym);
      memcpy(r->v, a->v, 9 * sizeof *r->v);
    }
    return 1;
  }
  if (strcmp(k, "p") == 0 && (G->kind == DM_LIE_SE3 || G->kind == DM_LIE_SE2)) {
    push_slots(L, a, G->kind == DM_LIE_SE3 ? 9 : 1, G->kind == DM_LIE_SE3 ? 3 : 2);
    return 1;
  }
  if (strcmp(k, "theta") == 0 && (G->kind == DM_LIE_SO2 || G->kind == DM_LIE_SE2)) {
    if (a->sym)
      dm_lua_pushexpr(L, a->v[0].e);
    else
      lua_pushnumber(L, a->v[0].x);
    return 1;
  }
  return luaL_error(L, "%s element has no field '%s' (g[i]: %s; fields: %s; methods: "
                    "help \"g\")", G->name, k,
                    G->kind == DM_LIE_PRODUCT ? "factor i"
                    : G->kind == DM_LIE_RN || G->kind == DM_LIE_TN ? "component i"
                                                                   : "row i of the matrix",
                    G->kind == DM_LIE_SE3 ? "R, p" : G->kind == DM_LIE_SE2 ? "theta, p"
                    : G->kind == DM_LIE_SO2 ? "theta" : "none");
}

/* }====================================================================== */

static const dm_reg elem_methods[] = {
  {"inv", e_inv, "g:inv() -> g^-1", "The inverse element."},
  {"log", e_log, "g:log() -> xi", "The principal logarithm (the algebra vector of g)."},
  {"matrix", e_matrix, "g:matrix() -> mat",
   "The matrix of g (SO3 3x3, SE3 4x4 homogeneous, products block diagonal)."},
  {"Ad", e_Ad, "g:Ad() -> mat", "The adjoint matrix of g."},
  {"act", e_act, "g:act(x) -> vec",
   "The action of g on a point (rotation of R^3, rigid motion, translation; the same as g * x)."},
  {"dist", e_dist, "g:dist(h) -> number", "The distance |log(g^-1 h)|."},
  {"normalize", e_normalize, "g:normalize() -> g",
   "The nearest group element (rotation blocks projected by their polar factor)."},
  {"coords", e_coords, "g:coords() -> vec",
   "The stored numbers (SO3: the matrix row by row; SE3: then p; SE2: theta, x, y)."},
  {"group", e_group, "g:group() -> G", "The group of g."},
  {"is_symbolic", e_is_symbolic, "g:is_symbolic() -> boolean",
   "True for an element made of expressions (inside a traced Lagrangian)."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_lieelem(lua_State *L)
{
  static const luaL_Reg meta[] = {{"__index", e_index}, {"__mul", e_mul},
                                  {"__tostring", e_tostring}, {NULL, NULL}};
  dm_newclass(L, DM_LIEELEM_MT, "g", elem_methods, meta);
  lua_pop(L, 1);
}
