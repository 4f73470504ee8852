/* l_lie.c -- dm.lie: the group objects (dm.lie.SO3() ...) and the functions
 * bound to them (G.exp{...}, G.log(g), G.Ad(g), G.hat{...}, ...) on
 * numbers or expressions.  Elements are l_lie_elem.c, spheres l_lie_sphere.c.
 * See l_lie.h. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_lie.h"
#include "lua/l_lie_sys.h"
#include "lua/l_expr.h"

/* {======================================================================
 * values in and out
 * ======================================================================= */

int dm_lua_lie_symfail(lua_State *L, const char *fname, const dm_err *e)
{
  dm_expr_ctx_clear_err(dm_lua_exprctx(L));
  return dm_lua_fail(L, fname, e->status, e);
}

int dm_lua_readvals(lua_State *L, int idx, size_t n, const char *fname, const char *what,
                    double *x, dm_expr *ex)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  gsl_vector *v;
  size_t k, len;
  int sym = 0;
  idx = lua_absindex(L, idx);
  if (n == 1 && (lua_type(L, idx) == LUA_TNUMBER || dm_lua_toexpr(L, idx) != DM_EXPR_NONE)) {
    sym = lua_type(L, idx) != LUA_TNUMBER;
    x[0] = sym ? NAN : lua_tonumber(L, idx);
    ex[0] = dm_lua_toexpr(L, idx);
    return sym;
  }
  if ((v = dm_tovec(L, idx)) != NULL) {
    if (v->size != n)
      return luaL_error(L, "%s: %s must have %d entries, got %d", fname, what, (int)n,
                        (int)v->size);
    for (k = 0; k < n; k++) {
      x[k] = gsl_vector_get(v, k);
      ex[k] = dm_expr_const(ctx, x[k]);
    }
    return 0;
  }
  if (lua_type(L, idx) != LUA_TTABLE)
    return luaL_error(L, "%s: %s must be a vec or a list of %d numbers, got %s", fname, what,
                      (int)n, luaL_typename(L, idx));
  len = (size_t)luaL_len(L, idx);
  if (len != n)
    return luaL_error(L, "%s: %s must have %d entries, got %d", fname, what, (int)n, (int)len);
  for (k = 0; k < n; k++) {
    lua_geti(L, idx, (lua_Integer)k + 1);
    if (lua_type(L, -1) == LUA_TNUMBER) {
      x[k] = lua_tonumber(L, -1);
      ex[k] = dm_expr_const(ctx, x[k]);
    } else if ((ex[k] = dm_lua_toexpr(L, -1)) != DM_EXPR_NONE) {
      x[k] = NAN;
      sym = 1;
    } else {
      return luaL_error(L, "%s: %s[%d] must be a number or an expression, got %s", fname, what,
                        (int)k + 1, luaL_typename(L, -1));
    }
    lua_pop(L, 1);
  }
  return sym;
}

void dm_lua_pushvals(lua_State *L, size_t n, int sym, const double *x, const dm_expr *ex)
{
  size_t k;
  if (!sym) {
    dm_pushvec_copy(L, x, n);
    return;
  }
  lua_createtable(L, (int)n, 0);
  for (k = 0; k < n; k++) {
    dm_lua_pushexpr(L, ex[k]);
    lua_rawseti(L, -2, (lua_Integer)k + 1);
  }
}

void dm_lua_pushmatvals(lua_State *L, size_t r, size_t c, int sym, const double *x,
                        const dm_expr *ex)
{
  size_t i, j;
  if (!sym) {
    gsl_matrix *M = dm_pushmat(L, r, c);
    for (i = 0; i < r; i++)
      for (j = 0; j < c; j++)
        gsl_matrix_set(M, i, j, x[i * c + j]);
    return;
  }
  lua_createtable(L, (int)r, 0);
  for (i = 0; i < r; i++) {
    lua_createtable(L, (int)c, 0);
    for (j = 0; j < c; j++) {
      dm_lua_pushexpr(L, ex[i * c + j]);
      lua_rawseti(L, -2, (lua_Integer)j + 1);
    }
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
}

/* A square matrix of n x n numbers or expressions (a mat, or a list of
 * rows) into x / ex (scratch owned by the caller); 1 when symbolic. */
static int readmat(lua_State *L, int idx, size_t n, const char *fname, double *x, dm_expr *ex)
{
  gsl_matrix *M = dm_tomat(L, idx);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  size_t i, j;
  int sym = 0;
  if (M != NULL) {
    if (M->size1 != n || M->size2 != n)
      return luaL_error(L, "%s: a %dx%d matrix expected, got %dx%d", fname, (int)n, (int)n,
                        (int)M->size1, (int)M->size2);
    for (i = 0; i < n; i++)
      for (j = 0; j < n; j++) {
        x[i * n + j] = gsl_matrix_get(M, i, j);
        ex[i * n + j] = dm_expr_const(ctx, x[i * n + j]);
      }
    return 0;
  }
  if (lua_type(L, idx) != LUA_TTABLE || (size_t)luaL_len(L, idx) != n)
    return luaL_error(L, "%s: a %dx%d matrix (mat or list of %d rows) expected, got %s", fname,
                      (int)n, (int)n, (int)n, luaL_typename(L, idx));
  for (i = 0; i < n; i++) {
    char what[32];
    lua_geti(L, idx, (lua_Integer)i + 1);
    snprintf(what, sizeof what, "row %d", (int)i + 1);
    sym |= dm_lua_readvals(L, -1, n, fname, what, x + i * n, ex + i * n);
    lua_pop(L, 1);
  }
  return sym;
}

/* }====================================================================== */

/* {======================================================================
 * group objects
 * ======================================================================= */

static int group_gc(lua_State *L)
{
  dm_lgroup *g = luaL_checkudata(L, 1, DM_LIEGROUP_MT);
  dm_lie_group_free(g->G);
  g->G = NULL;
  return 0;
}

dm_lie_group **dm_lua_newgroup(lua_State *L)
{
  dm_lgroup *g = lua_newuserdatauv(L, sizeof *g, 1);
  g->G = NULL;
  luaL_setmetatable(L, DM_LIEGROUP_MT);
  lua_newtable(L);
  lua_setiuservalue(L, -2, 1);
  return &g->G;
}

const dm_lie_group *dm_lua_togroup(lua_State *L, int idx)
{
  dm_lgroup *g = luaL_testudata(L, idx, DM_LIEGROUP_MT);
  return g != NULL ? g->G : NULL;
}

const dm_lie_group *dm_lua_checkgroup(lua_State *L, int idx)
{
  const dm_lie_group *G = dm_lua_togroup(L, idx);
  if (G == NULL)
    dm_argexpected(L, idx, "Lie group (dm.lie.SO3(), ...)", luaL_typename(L, idx));
  return G;
}

/* the element at idx, of group G; fname and the argument number in errors */
static dm_lelem *elem_of(lua_State *L, int idx, const dm_lie_group *G, const char *fname)
{
  dm_lelem *el = dm_lua_toelem(L, idx);
  if (el == NULL)
    luaL_error(L, "%s: argument #%d must be an element of %s, got %s", fname, idx - 1, G->name,
               luaL_typename(L, idx));
  if (!dm_lie_group_equal(el->G, G))
    luaL_error(L, "%s: argument #%d must be an element of %s, got an element of %s", fname,
               idx - 1, G->name, el->G->name);
  return el;
}

/* algebra vector at idx: numbers into x, nodes into ex; 1 if symbolic */
static int alg(lua_State *L, int idx, const dm_lie_group *G, const char *fname, double *x,
               dm_expr *ex)
{
  char what[128];
  snprintf(what, sizeof what, "the %s algebra vector", G->name);
  if (lua_isnoneornil(L, idx))
    luaL_error(L, "%s: %s (%d numbers) expected", fname, what, (int)G->dim);
  return dm_lua_readvals(L, idx, G->dim, fname, what, x, ex);
}

static int side_arg(lua_State *L, int idx, const char *fname)
{
  const char *s = luaL_optstring(L, idx, "right");
  if (strcmp(s, "right") == 0)
    return DM_LIE_RIGHT;
  if (strcmp(s, "left") == 0)
    return DM_LIE_LEFT;
  return luaL_error(L, "%s: side must be \"right\" or \"left\", got \"%s\"", fname, s);
}

#define GF(fname) const dm_lie_group *G = dm_lua_checkgroup(L, 1); const char *fn = (fname)

static int g_identity(lua_State *L)
{
  GF("G.identity");
  dm_lelem *el = dm_lua_newelem(L, 1, 0);
  double g[DM_LIE_NQ_MAX];
  size_t i;
  (void)fn;
  dm_lie_identity(G, g);
  for (i = 0; i < G->nq; i++)
    el->v[i].x = g[i];
  return 1;
}

/* a matrix argument: a mat or a list whose first entry is a list */
static int is_rows(lua_State *L, int idx)
{
  int t;
  if (dm_tomat(L, idx) != NULL)
    return 1;
  if (!lua_istable(L, idx))
    return 0;
  t = lua_geti(L, idx, 1);
  t = t == LUA_TTABLE || dm_tovec(L, -1) != NULL;
  lua_pop(L, 1);
  return t;
}

/* G.element(x [, {tol =, normalize =}]) */
static int g_element(lua_State *L)
{
  GF("G.element");
  double g[DM_LIE_NQ_MAX], tol = 1e-10;
  dm_expr ex[DM_LIE_NQ_MAX];
  int sym = 0, norm = 0;
  size_t i;
  dm_err e;
  dm_lelem *src, *el;
  if (!lua_isnoneornil(L, 3)) {
    luaL_checktype(L, 3, LUA_TTABLE);
    tol = dm_optnumberfield(L, 3, "tol", tol);
    lua_getfield(L, 3, "normalize");
    norm = lua_toboolean(L, -1);
    lua_pop(L, 1);
  }
  if ((src = dm_lua_toelem(L, 2)) != NULL) {
    elem_of(L, 2, G, fn);
    sym = src->sym;
    for (i = 0; i < G->nq; i++) {
      g[i] = sym ? NAN : src->v[i].x;
      ex[i] = sym ? src->v[i].e : DM_EXPR_NONE;
    }
  } else if (is_rows(L, 2)) {
    size_t ms = G->msize;
    dm_expr *mx = lua_newuserdatauv(L, ms * ms * sizeof *mx, 0);
    double *mv = lua_newuserdatauv(L, ms * ms * sizeof *mv, 0);
    if (readmat(L, 2, ms, fn, mv, mx))
      return luaL_error(L, "%s: a matrix of numbers expected (symbolic elements come from "
                        "G.exp or a traced Lagrangian)", fn);
    if (dm_lie_from_matrix(G, mv, ms, g, &e) != DM_OK)
      return dm_lua_fail(L, fn, e.status, &e);
    lua_pop(L, 2);
  } else {
    char what[128];
    snprintf(what, sizeof what, "the %s element (%d numbers)", G->name, (int)G->nq);
    if (lua_isnoneornil(L, 2))
      return luaL_error(L, "%s: %s or its matrix expected", fn, what);
    sym = dm_lua_readvals(L, 2, G->nq, fn, what, g, ex);
  }
  if (!sym) {
    if (norm)
      dm_lie_normalize(G, g);
    if (dm_lie_check(G, g, tol, &e) != DM_OK)
      return luaL_error(L, "%s: %s (normalize = true projects onto the group)", fn, e.msg);
  }
  el = dm_lua_newelem(L, 1, sym);
  for (i = 0; i < G->nq; i++) {
    if (sym)
      el->v[i].e = ex[i];
    else
      el->v[i].x = g[i];
  }
  return 1;
}

static void push_elem(lua_State *L, int gidx, const dm_lie_group *G, int sym, const double *x,
                      const dm_expr *ex)
{
  dm_lelem *el = dm_lua_newelem(L, gidx, sym);
  size_t i;
  for (i = 0; i < G->nq; i++) {
    if (sym)
      el->v[i].e = ex[i];
    else
      el->v[i].x = x[i];
  }
}

static int g_exp_cay(lua_State *L, int cay)
{
  GF(cay ? "G.cay" : "G.exp");
  double xi[DM_LIE_DIM_MAX], g[DM_LIE_NQ_MAX];
  dm_expr ex[DM_LIE_DIM_MAX], eg[DM_LIE_NQ_MAX];
  dm_err e;
  int sym = alg(L, 2, G, fn, xi, ex);
  if (sym) {
    int st = cay ? dm_lie_sym_cay(dm_lua_exprctx(L), G, ex, eg, &e)
                 : dm_lie_sym_exp(dm_lua_exprctx(L), G, ex, eg, &e);
    if (st != DM_OK)
      return dm_lua_lie_symfail(L, fn, &e);
  } else if (cay) {
    dm_lie_cay(G, xi, g);
  } else {
    dm_lie_exp(G, xi, g);
  }
  push_elem(L, 1, G, sym, g, eg);
  return 1;
}

static int g_exp(lua_State *L)
{
  return g_exp_cay(L, 0);
}

static int g_cay(lua_State *L)
{
  return g_exp_cay(L, 1);
}

static int g_log_icay(lua_State *L, int icay)
{
  GF(icay ? "G.icay" : "G.log");
  dm_lelem *el = elem_of(L, 2, G, fn);
  double g[DM_LIE_NQ_MAX], xi[DM_LIE_DIM_MAX];
  dm_expr eg[DM_LIE_NQ_MAX], ex[DM_LIE_DIM_MAX];
  dm_err e;
  if (el->sym) {
    int st;
    dm_lua_elem_nodes(L, el, eg);
    st = icay ? dm_lie_sym_icay(dm_lua_exprctx(L), G, eg, ex, &e)
              : dm_lie_sym_log(dm_lua_exprctx(L), G, eg, ex, &e);
    if (st != DM_OK)
      return dm_lua_lie_symfail(L, fn, &e);
  } else {
    dm_lua_elem_numbers(L, el, fn, g);
    if (!icay)
      dm_lie_log(G, g, xi);
    else if (dm_lie_icay(G, g, xi, &e) != DM_OK) {
      char d[160];
      dm_lie_describe(G, g, d, sizeof d);
      return luaL_error(L, "%s: %s; input: %s", fn, e.msg, d);
    }
  }
  dm_lua_pushvals(L, G->dim, el->sym, xi, ex);
  return 1;
}

static int g_log(lua_State *L)
{
  return g_log_icay(L, 0);
}

static int g_icay(lua_State *L)
{
  return g_log_icay(L, 1);
}

/* a dim x dim matrix of an element (Ad) or of an algebra vector (ad,
 * dexp, dexpinv, dcay, dcayinv) */
enum { M_AD, M_SMALLAD, M_DEXP, M_DEXPINV, M_DCAY, M_DCAYINV };

static int g_mat(lua_State *L, int which, const char *fname)
{
  GF(fname);
  size_t n = G->dim;
  int side = which >= M_DEXP ? side_arg(L, 3, fn) : DM_LIE_RIGHT;
  lua_settop(L, 2);
  double *M = lua_newuserdatauv(L, n * n * sizeof *M, 0);
  dm_expr *S = lua_newuserdatauv(L, n * n * sizeof *S, 0);
  double x[DM_LIE_NQ_MAX];
  dm_expr ex[DM_LIE_NQ_MAX];
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  int sym, st = DM_OK;
  dm_err e;
  if (which == M_AD) {
    dm_lelem *el = elem_of(L, 2, G, fn);
    sym = el->sym;
    if (sym) {
      dm_lua_elem_nodes(L, el, ex);
      st = dm_lie_sym_Ad(ctx, G, ex, S, &e);
    } else {
      dm_lua_elem_numbers(L, el, fn, x);
      dm_lie_Ad(G, x, M, n);
    }
  } else {
    sym = alg(L, 2, G, fn, x, ex);
    switch (which) {
    case M_SMALLAD:
      if (sym)
        st = dm_lie_sym_ad(ctx, G, ex, S, &e);
      else
        dm_lie_ad(G, x, M, n);
      break;
    case M_DEXP:
      if (sym)
        st = dm_lie_sym_dexp(ctx, G, ex, side, S, &e);
      else
        dm_lie_dexp(G, x, side, M, n);
      break;
    case M_DEXPINV:
      if (sym)
        st = dm_lie_sym_dexpinv(ctx, G, ex, side, S, &e);
      else
        dm_lie_dexpinv(G, x, side, M, n);
      break;
    case M_DCAY:
      if (sym)
        st = dm_lie_sym_dcay(ctx, G, ex, side, S, &e);
      else
        dm_lie_dcay(G, x, side, M, n);
      break;
    default:
      if (sym)
        st = dm_lie_sym_dcayinv(ctx, G, ex, side, S, &e);
      else
        dm_lie_dcayinv(G, x, side, M, n);
      break;
    }
  }
  if (st != DM_OK)
    return dm_lua_lie_symfail(L, fn, &e);
  dm_lua_pushmatvals(L, n, n, sym, M, S);
  return 1;
}

static int g_Ad(lua_State *L) { return g_mat(L, M_AD, "G.Ad"); }
static int g_ad(lua_State *L) { return g_mat(L, M_SMALLAD, "G.ad"); }
static int g_dexp(lua_State *L) { return g_mat(L, M_DEXP, "G.dexp"); }
static int g_dexpinv(lua_State *L) { return g_mat(L, M_DEXPINV, "G.dexpinv"); }
static int g_dcay(lua_State *L) { return g_mat(L, M_DCAY, "G.dcay"); }
static int g_dcayinv(lua_State *L) { return g_mat(L, M_DCAYINV, "G.dcayinv"); }

static int g_bracket(lua_State *L)
{
  GF("G.bracket");
  double a[DM_LIE_DIM_MAX], b[DM_LIE_DIM_MAX], c[DM_LIE_DIM_MAX];
  dm_expr ea[DM_LIE_DIM_MAX], eb[DM_LIE_DIM_MAX], ec[DM_LIE_DIM_MAX];
  dm_err e;
  int sym = alg(L, 2, G, fn, a, ea) | alg(L, 3, G, fn, b, eb);
  if (sym) {
    if (dm_lie_sym_bracket(dm_lua_exprctx(L), G, ea, eb, ec, &e) != DM_OK)
      return dm_lua_lie_symfail(L, fn, &e);
  } else {
    dm_lie_bracket(G, a, b, c);
  }
  dm_lua_pushvals(L, G->dim, sym, c, ec);
  return 1;
}

static int g_hat(lua_State *L)
{
  GF("G.hat");
  size_t m = G->msize;
  double x[DM_LIE_DIM_MAX], *A = lua_newuserdatauv(L, m * m * sizeof *A, 0);
  dm_expr ex[DM_LIE_DIM_MAX], *S = lua_newuserdatauv(L, m * m * sizeof *S, 0);
  dm_err e;
  int sym = alg(L, 2, G, fn, x, ex);
  if (sym) {
    if (dm_lie_sym_hat(dm_lua_exprctx(L), G, ex, S, &e) != DM_OK)
      return dm_lua_lie_symfail(L, fn, &e);
  } else {
    dm_lie_hat(G, x, A, m);
  }
  dm_lua_pushmatvals(L, m, m, sym, A, S);
  return 1;
}

static int g_vee(lua_State *L)
{
  GF("G.vee");
  size_t m = G->msize;
  double x[DM_LIE_DIM_MAX], *A = lua_newuserdatauv(L, m * m * sizeof *A, 0);
  dm_expr ex[DM_LIE_DIM_MAX], *S = lua_newuserdatauv(L, m * m * sizeof *S, 0);
  dm_err e;
  int sym;
  luaL_checkany(L, 2);
  sym = readmat(L, 2, m, fn, A, S);
  if (sym) {
    if (dm_lie_sym_vee(dm_lua_exprctx(L), G, S, ex, &e) != DM_OK)
      return dm_lua_lie_symfail(L, fn, &e);
  } else {
    dm_lie_vee(G, A, m, x);
  }
  dm_lua_pushvals(L, G->dim, sym, x, ex);
  return 1;
}

static int g_dist(lua_State *L)
{
  GF("G.dist");
  double a[DM_LIE_NQ_MAX], b[DM_LIE_NQ_MAX];
  dm_lua_elem_numbers(L, elem_of(L, 2, G, fn), fn, a);
  dm_lua_elem_numbers(L, elem_of(L, 3, G, fn), fn, b);
  lua_pushnumber(L, dm_lie_dist(G, a, b));
  return 1;
}

static const dm_reg group_funcs[] = {
  {"identity", g_identity, "G.identity() -> g", "The identity element of the group G."},
  {"element", g_element, "G.element(M | coords | g[, {tol = 1e-10, normalize = false}]) -> g",
   "An element of G from its matrix (dm.mat or list of rows), its coordinates (R^n: the "
   "vector, SO2: the angle, SE2: {theta, x, y}, SO3: the 9 entries row by row, SE3: those and p) "
   "or a copy; checked to be in the group within tol, or projected onto it with normalize."},
  {"exp", g_exp, "G.exp(xi) -> g",
   "The exponential of the algebra vector xi ({w1, w2, w3} for SO3, {w, v} rotation first for SE3); "
   "with expressions in xi the element is symbolic."},
  {"log", g_log, "G.log(g) -> xi",
   "The principal logarithm of g (rotation angles in [0, pi], accurate at and near pi)."},
  {"cay", g_cay, "G.cay(xi) -> g", "The Cayley map (I - A/2)^-1 (I + A/2) of hat(xi)."},
  {"icay", g_icay, "G.icay(g) -> xi",
   "The inverse Cayley map; an error at a rotation by pi, its cut locus."},
  {"Ad", g_Ad, "G.Ad(g) -> mat", "The adjoint matrix of g (dim x dim): Ad_g xi = vee(g hat(xi) g^-1)."},
  {"ad", g_ad, "G.ad(xi) -> mat", "The matrix of ad_xi = [xi, .] (dim x dim)."},
  {"bracket", g_bracket, "G.bracket(a, b) -> vec", "The Lie bracket [a, b] of two algebra vectors."},
  {"hat", g_hat, "G.hat(xi) -> mat", "The algebra vector xi as a matrix of the representation."},
  {"vee", g_vee, "G.vee(M) -> vec",
   "The algebra vector of a matrix (for a rotation block its skew-symmetric part)."},
  {"dexp", g_dexp, "G.dexp(xi[, \"right\" | \"left\"]) -> mat",
   "The derivative of exp at xi, right-trivialized (d exp(xi + e v) exp(xi)^-1) or left-trivialized."},
  {"dexpinv", g_dexpinv, "G.dexpinv(xi[, \"right\" | \"left\"]) -> mat",
   "The inverse of G.dexp(xi, side)."},
  {"dcay", g_dcay, "G.dcay(xi[, \"right\" | \"left\"]) -> mat",
   "The trivialized derivative of the Cayley map at xi."},
  {"dcayinv", g_dcayinv, "G.dcayinv(xi[, \"right\" | \"left\"]) -> mat",
   "The inverse of G.dcay(xi, side)."},
  {"dist", g_dist, "G.dist(g, h) -> number", "The distance |log(g^-1 h)|."},
  {NULL, NULL, NULL, NULL}
};

/* Call the function in upvalue 2 with the group (upvalue 1) as its first
 * argument, unless the call was G:f(...) (G already first). */
static int bound_call(lua_State *L)
{
  if (!(lua_gettop(L) >= 1 && lua_rawequal(L, 1, lua_upvalueindex(1)))) {
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
  }
  lua_pushvalue(L, lua_upvalueindex(2));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

/* __index for objects with bound functions: the cache in user value 1,
 * then the class's __methods (a bound closure is made, documented by
 * value, and cached), then the fields given by `fields`. */
int dm_lua_bound_index(lua_State *L, const char *prefix, int (*fields)(lua_State *))
{
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  if (lua_rawget(L, -2) != LUA_TNIL)
    return 1;
  lua_pop(L, 1);
  if (lua_type(L, 2) == LUA_TSTRING && luaL_getmetafield(L, 1, "__methods") != LUA_TNIL) {
    lua_pushvalue(L, 2);
    if (lua_rawget(L, -2) == LUA_TFUNCTION) {
      char name[64];
      lua_pushvalue(L, 1);
      lua_pushvalue(L, -2);
      lua_pushcclosure(L, bound_call, 2);
      snprintf(name, sizeof name, "%s%s", prefix, lua_tostring(L, 2));
      /* the same help as the unbound function */
      dm_pushdocs(L);
      if (lua_getfield(L, -1, name) == LUA_TTABLE) {
        lua_getfield(L, -1, "sig");
        lua_getfield(L, -2, "doc");
        dm_doc_add(L, name, lua_tostring(L, -2), lua_tostring(L, -1), -5);
        lua_pop(L, 2);
      }
      lua_pop(L, 2);
      lua_pushvalue(L, 2);
      lua_pushvalue(L, -2);
      lua_rawset(L, -6);                    /* cache */
      return 1;
    }
    lua_pop(L, 2);
  }
  lua_settop(L, 2);
  return fields(L);
}

static int group_fields(lua_State *L)
{
  const dm_lie_group *G = dm_lua_checkgroup(L, 1);
  const char *k = lua_tostring(L, 2);
  if (k == NULL)
    return luaL_error(L, "a Lie group has no field %s", dm_tolstring(L, 2, NULL));
  if (strcmp(k, "name") == 0)
    lua_pushstring(L, G->name);
  else if (strcmp(k, "dim") == 0)
    lua_pushinteger(L, (lua_Integer)G->dim);
  else if (strcmp(k, "nq") == 0)
    lua_pushinteger(L, (lua_Integer)G->nq);
  else if (strcmp(k, "msize") == 0)
    lua_pushinteger(L, (lua_Integer)G->msize);
  else if (strcmp(k, "abelian") == 0)
    lua_pushboolean(L, G->abelian);
  else if (strcmp(k, "factors") == 0) {
    size_t i;
    lua_createtable(L, (int)G->nfac, 0);
    for (i = 0; i < G->nfac; i++) {
      dm_err e;
      dm_lie_group **slot = dm_lua_newgroup(L);
      if ((*slot = dm_lie_group_copy(G->fac[i], &e)) == NULL)
        return dm_lua_fail(L, "factors", e.status, &e);
      lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
  } else
    return luaL_error(L, "%s has no field '%s' (fields: name, dim, nq, msize, abelian, factors; "
                      "functions: help \"G\")", G->name, k);
  return 1;
}

static int group_index(lua_State *L)
{
  return dm_lua_bound_index(L, "G.", group_fields);
}

static int group_tostring(lua_State *L)
{
  const dm_lie_group *G = dm_lua_checkgroup(L, 1);
  lua_pushfstring(L, "<Lie group %s, dim %d>", G->name, (int)G->dim);
  return 1;
}

static int group_eq(lua_State *L)
{
  const dm_lie_group *G = dm_lua_togroup(L, 1), *H = dm_lua_togroup(L, 2);
  lua_pushboolean(L, G && H && dm_lie_group_equal(G, H));
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * constructors: dm.lie.*
 * ======================================================================= */

static int push_new(lua_State *L, dm_lie_group *(*make)(dm_err *), const char *fname)
{
  dm_err e;
  dm_lie_group **slot = dm_lua_newgroup(L);
  if ((*slot = make(&e)) == NULL)
    return dm_lua_fail(L, fname, e.status, &e);
  return 1;
}

static int push_new_n(lua_State *L, dm_lie_group *(*make)(size_t, dm_err *), const char *fname)
{
  lua_Integer n = luaL_checkinteger(L, 1);
  dm_err e;
  dm_lie_group **slot;
  if (n < 1 || n > DM_LIE_DIM_MAX)
    return luaL_error(L, "%s: n must be in 1..%d, got %d", fname, DM_LIE_DIM_MAX, (int)n);
  slot = dm_lua_newgroup(L);
  if ((*slot = make((size_t)n, &e)) == NULL)
    return dm_lua_fail(L, fname, e.status, &e);
  return 1;
}

static int l_SO3(lua_State *L) { return push_new(L, dm_lie_so3, "dm.lie.SO3"); }
static int l_SE3(lua_State *L) { return push_new(L, dm_lie_se3, "dm.lie.SE3"); }
static int l_SO2(lua_State *L) { return push_new(L, dm_lie_so2, "dm.lie.SO2"); }
static int l_SE2(lua_State *L) { return push_new(L, dm_lie_se2, "dm.lie.SE2"); }
static int l_Rn(lua_State *L) { return push_new_n(L, dm_lie_rn, "dm.lie.Rn"); }
static int l_T(lua_State *L) { return push_new_n(L, dm_lie_torus, "dm.lie.T"); }

static int l_product(lua_State *L)
{
  const dm_lie_group *fac[DM_LIE_FAC_MAX];
  int n = lua_gettop(L), i;
  dm_err e;
  dm_lie_group **slot;
  if (n < 1)
    return luaL_error(L, "dm.lie.product: needs at least one group");
  if (n > DM_LIE_FAC_MAX)
    return luaL_error(L, "dm.lie.product: at most %d factors", DM_LIE_FAC_MAX);
  for (i = 1; i <= n; i++)
    fac[i - 1] = dm_lua_checkgroup(L, i);
  slot = dm_lua_newgroup(L);
  if ((*slot = dm_lie_product((size_t)n, fac, &e)) == NULL)
    return dm_lua_fail(L, "dm.lie.product", e.status, &e);
  return 1;
}

static int l_group(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  dm_err e;
  dm_lie_group **slot = dm_lua_newgroup(L);
  if ((*slot = dm_lie_group_parse(name, &e)) == NULL)
    return dm_lua_fail(L, "dm.lie.group", e.status, &e);
  return 1;
}

/* }====================================================================== */


static const dm_reg lie_funcs[] = {
  {"SO3", l_SO3, "dm.lie.SO3() -> G", "The rotation group SO(3): elements 3x3 rotation matrices."},
  {"SE3", l_SE3, "dm.lie.SE3() -> G",
   "The rigid motions SE(3): elements (R, p), algebra (w, v) with the rotation first."},
  {"SO2", l_SO2, "dm.lie.SO2() -> G", "The planar rotations SO(2): elements angles, stored unwrapped."},
  {"SE2", l_SE2, "dm.lie.SE2() -> G", "The planar rigid motions SE(2): elements (theta, x, y)."},
  {"Rn", l_Rn, "dm.lie.Rn(n) -> G", "The translations R^n (vector addition)."},
  {"T", l_T, "dm.lie.T(n) -> G", "The torus T^n: n unwrapped angles."},
  {"product", l_product, "dm.lie.product(G1, G2, ...) -> G",
   "The direct product of groups (products among them are flattened)."},
  {"group", l_group, "dm.lie.group(name) -> G",
   "The group with a name as G.name prints it (\"SO3\", \"SE3xT3\", \"R2\")."},
  {"sphere", dm_lua_lie_sphere, "dm.lie.sphere([n = 2]) -> S",
   "The unit sphere S^n in R^(n+1): S.exp, S.log, S.dist, S.tangent, S.normalize, and for S^2 "
   "S.rotation and S.project.  dm.system{space = S, L = function(x, v, p)} is a system on S^n "
   "in the coordinates x1 .. x(n+1) of R^(n+1), stepped by method \"lgvi\" (doc/lie.md)."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_newclass_bound(lua_State *L, const char *tname, const char *name,
                           const char *prefix, const dm_reg *funcs, const luaL_Reg *meta)
{
  luaL_newmetatable(L, tname);
  luaL_setfuncs(L, meta, 0);
  lua_pushstring(L, name);
  lua_setfield(L, -2, "__name");
  lua_newtable(L);
  dm_register(L, prefix, funcs);
  lua_setfield(L, -2, "__methods");
  lua_pop(L, 1);
}

void dm_open_lie(lua_State *L)
{
  static const luaL_Reg gmeta[] = {{"__index", group_index}, {"__gc", group_gc},
                                   {"__close", group_gc}, {"__tostring", group_tostring},
                                   {"__eq", group_eq}, {NULL, NULL}};
  dm_lua_newclass_bound(L, DM_LIEGROUP_MT, "liegroup", "G.", group_funcs, gmeta);
  dm_lua_open_liesphere(L);
  dm_lua_open_lieelem(L);
  dm_lua_open_liesys(L);
  dm_lua_open_lieinteg(L);
  lua_newtable(L);
  dm_register(L, "dm.lie.", lie_funcs);
  lua_setfield(L, -2, "lie");
}
