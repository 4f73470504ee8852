/* l_conn_cont.c -- continuous connections in Lua (src/conn/conn.h):
 *   A  = dm.connection{bundle = B, A = function(x, p) return {{...}} end, params = {...}}
 *   Am = dm.mechanical_connection{bundle = B, I = Ifun, C = Cfun}     -- A = I^-1 C
 *   Am = dm.mechanical_connection{bundle = B[, L = function(x, xdot, xi, p) ... end]}
 *   A:at(x) ; A:curvature(x, 1, 2) ; A:holonomy(curve, q0, {tol = 1e-12})
 * The functions are traced once into expressions (dm.trace rules: no
 * branches on symbolic values); A and its derivatives run as tapes. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_conn.h"
#include "lua/l_expr.h"
#include "lua/l_system.h"
#include "expr/native.h"
#include "core/trajectory.h"

typedef struct dm_lconn {
  dm_conn *C;                   /* NULL until built */
  size_t dim, nx, npar;
  dm_expr A[];                  /* dim * nx nodes of the Lua state's context */
} dm_lconn;

dm_conn *dm_lua_toconn(lua_State *L, int idx)
{
  dm_lconn *c = luaL_testudata(L, idx, DM_CONN_MT);
  return c != NULL ? c->C : NULL;
}

static dm_lconn *checklconn(lua_State *L, int idx)
{
  dm_lconn *c = luaL_testudata(L, idx, DM_CONN_MT);
  if (c == NULL || c->C == NULL)
    dm_argexpected(L, idx, "connection (dm.connection{...})", luaL_typename(L, idx));
  return c;
}

dm_conn *dm_lua_checkconn(lua_State *L, int idx)
{
  return checklconn(L, idx)->C;
}

static int conn_gc(lua_State *L)
{
  dm_lconn *c = luaL_checkudata(L, 1, DM_CONN_MT);
  dm_conn_free(c->C);
  c->C = NULL;
  return 0;
}

/* the connection's bundle userdata (user value field) */
static void conn_field(lua_State *L, int idx, const char *key)
{
  lua_getiuservalue(L, idx, 1);
  lua_getfield(L, -1, key);
  lua_remove(L, -2);
}

/* an empty connection userdata for the bundle at bidx; user value
 * {bundle = B, params = plist} (plist at pidx, may be 0) */
static dm_lconn *newconn(lua_State *L, int bidx, int pidx)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, bidx)->B;
  size_t n = B->G->dim * B->nx;
  dm_lconn *c;
  bidx = lua_absindex(L, bidx);
  pidx = pidx ? lua_absindex(L, pidx) : 0;
  c = lua_newuserdatauv(L, sizeof *c + (n + 1) * sizeof(dm_expr), 1);
  c->C = NULL;
  c->dim = B->G->dim;
  c->nx = B->nx;
  c->npar = 0;
  luaL_setmetatable(L, DM_CONN_MT);
  lua_createtable(L, 0, 2);
  lua_pushvalue(L, bidx);
  lua_setfield(L, -2, "bundle");
  if (pidx) {
    lua_pushvalue(L, pidx);
    lua_setfield(L, -2, "params");
  }
  lua_setiuservalue(L, -2, 1);
  return c;
}

/* params {name = value} or {{name, value}} at idx -> list pushed */
static void plist(lua_State *L, int idx, const char *fname)
{
  int k = 0;
  lua_newtable(L);
  if (lua_isnoneornil(L, idx))
    return;
  if (!lua_istable(L, idx))
    luaL_error(L, "%s: params must be a table {name = value, ...}, got %s", fname,
               luaL_typename(L, idx));
  if (luaL_len(L, idx) > 0) {
    int i;
    for (i = 1; i <= luaL_len(L, idx); i++) {
      lua_geti(L, idx, i);
      lua_rawseti(L, -2, ++k);
    }
    return;
  }
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "%s: params must map names to numbers", fname);
    lua_createtable(L, 2, 0);
    lua_pushvalue(L, -3);
    lua_rawseti(L, -2, 1);
    lua_pushvalue(L, -2);
    lua_rawseti(L, -2, 2);
    lua_rawseti(L, -4, ++k);
    lua_pop(L, 1);
  }
  /* sort by name for a stable order */
  lua_getglobal(L, "table");
  lua_getfield(L, -1, "sort");
  lua_pushvalue(L, -3);
  luaL_loadstring(L, "local a, b = ... return a[1] < b[1]");
  lua_call(L, 2, 0);
  lua_pop(L, 1);
}

/* parameter symbols of the list at lidx: pushes the symvec p, fills nodes
 * and values */
static size_t param_syms(lua_State *L, int lidx, dm_expr *par, double *val)
{
  const char *names[32];
  size_t n = (size_t)luaL_len(L, lidx), k;
  lidx = lua_absindex(L, lidx);
  if (n > 32)
    luaL_error(L, "connection: at most 32 parameters, got %d", (int)n);
  for (k = 0; k < n; k++) {
    lua_geti(L, lidx, (lua_Integer)k + 1);
    if (!lua_istable(L, -1))
      luaL_error(L, "connection: params[%d] must be {\"name\", value}", (int)k + 1);
    lua_geti(L, -1, 1);
    lua_geti(L, -2, 2);
    if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "connection: params[%d] must be {\"name\", value}", (int)k + 1);
    names[k] = lua_tostring(L, -2);
    val[k] = lua_tonumber(L, -1);
    lua_pop(L, 3);
  }
  dm_lua_pushsymvec(L, "p", n, names, NULL, DM_EXPR_PARAM);
  for (k = 0; k < n; k++) {
    lua_geti(L, -1, (lua_Integer)k + 1);
    par[k] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
  return n;
}

static void push_xsyms(lua_State *L, size_t nx, dm_expr *x)
{
  const char *names[DM_CONN_NX_MAX] = {NULL};
  char buf[DM_CONN_NX_MAX][12];
  size_t k;
  for (k = 0; k < nx; k++) {
    snprintf(buf[k], sizeof buf[k], "x%d", (int)k + 1);
    names[k] = buf[k];
  }
  dm_lua_pushsymvec(L, "x", nx, names, NULL, DM_EXPR_SYM);
  for (k = 0; k < nx; k++) {
    lua_geti(L, -1, (lua_Integer)k + 1);
    x[k] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
}

/* trace fn(x, p) at fidx returning an r x c matrix of expressions */
static void trace_matrix(lua_State *L, int fidx, int xidx, int pidx, size_t r, size_t c,
                         const char *what, dm_expr *out)
{
  size_t rows, cols, n;
  lua_pushvalue(L, fidx);
  lua_pushvalue(L, xidx);
  lua_pushvalue(L, pidx);
  dm_lua_trace(L, what, 2);
  n = dm_lua_toexprs(L, -1, what, out, r * c, &rows, &cols);
  if (!(n == r * c && ((rows == r && cols == c) || (r == 1 && rows == 1 && cols == c) ||
                       (c == 1 && rows == 1 && cols == r) || (r * c == 1 && cols == 0))))
    luaL_error(L, "%s must return a %dx%d matrix (a list of %d rows of %d), got %d values "
               "(%dx%d)", what, (int)r, (int)c, (int)r, (int)c, (int)n, (int)rows, (int)cols);
  lua_pop(L, 1);
}

/* native code for A_loc as dm.config.native says: "never" the tape,
 * "auto"/"wait" native when a compiler works (at once: a connection is
 * evaluated a few thousand times, not run in the background), "always"
 * native or an error */
static void conn_native(lua_State *L, dm_conn *C)
{
  int mode = dm_lua_native_mode(L);
  dm_err e;
  if (mode == DM_NATIVE_NEVER)
    return;
  if (dm_conn_native(C, NULL, &e) != DM_OK && mode == DM_NATIVE_ALWAYS)
    dm_lua_fail(L, "connection: native code", e.status, &e);
}

static const char *const conn_keys[] = {"bundle", "A", "params", NULL};

static int l_connection(lua_State *L)
{
  dm_lconn *c;
  const dm_conn_bundle *B;
  dm_expr x[DM_CONN_NX_MAX], par[32];
  double pv[32];
  dm_err e;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_lua_conn_checkkeys(L, 1, "dm.connection", conn_keys);
  lua_getfield(L, 1, "bundle");                       /* 2 */
  B = dm_lua_checkbundle(L, 2)->B;
  if (!dm_conn_bundle_is_trivial(B) || B->nx == 0)
    luaL_error(L, "dm.connection: a local connection form needs a trivial bundle S x G with "
               "shape dimension >= 1, got %s", B->name);
  lua_getfield(L, 1, "A");                            /* 3 */
  if (lua_isnil(L, 3)) {
    dm_lua_bundle_field(L, 2, "A");                   /* the bundle's own form */
    lua_replace(L, 3);
  }
  if (!lua_isfunction(L, 3))
    luaL_error(L, "dm.connection: A must be a function A(x, p) returning the %dx%d local form, "
               "got %s", (int)B->G->dim, (int)B->nx, luaL_typename(L, 3));
  lua_getfield(L, 1, "params");
  plist(L, 4, "dm.connection");                       /* 5 */
  c = newconn(L, 2, 5);                               /* 6 */
  c->npar = param_syms(L, 5, par, pv);                /* 7: p */
  push_xsyms(L, B->nx, x);                            /* 8: x */
  trace_matrix(L, 3, 8, 7, B->G->dim, B->nx, "dm.connection: A(x, p)", c->A);
  if ((c->C = dm_conn_expr_alloc(dm_lua_exprctx(L), B, x, c->A, c->npar, par, pv, &e)) == NULL)
    return dm_lua_fail(L, "dm.connection", e.status, &e);
  conn_native(L, c->C);
  lua_settop(L, 6);
  return 1;
}

static const char *const mech_keys[] = {"bundle", "I", "C", "L", "params", NULL};

static int l_mechanical(lua_State *L)
{
  dm_lconn *c;
  const dm_conn_bundle *B;
  dm_expr x[DM_CONN_NX_MAX], xd[DM_CONN_NX_MAX], xi[DM_LIE_DIM_MAX], par[32], l, *IC;
  double pv[32];
  size_t dim, nx, np;
  dm_err e;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_lua_conn_checkkeys(L, 1, "dm.mechanical_connection", mech_keys);
  lua_getfield(L, 1, "bundle");                       /* 2 */
  B = dm_lua_checkbundle(L, 2)->B;
  if (!dm_conn_bundle_is_trivial(B) || B->nx == 0)
    luaL_error(L, "dm.mechanical_connection: needs a trivial bundle S x G with shape dimension "
               ">= 1, got %s", B->name);
  dim = B->G->dim;
  nx = B->nx;
  lua_getfield(L, 1, "I");                            /* 3 */
  lua_getfield(L, 1, "C");                            /* 4 */
  lua_getfield(L, 1, "L");                            /* 5 */
  lua_getfield(L, 1, "params");
  plist(L, 6, "dm.mechanical_connection");            /* 7 */
  if (!lua_isnil(L, 3) || !lua_isnil(L, 4)) {
    if (!lua_isfunction(L, 3) || !lua_isfunction(L, 4))
      luaL_error(L, "dm.mechanical_connection: I and C must both be functions of (x, p)");
    c = newconn(L, 2, 7);                             /* 8 */
    c->npar = param_syms(L, 7, par, pv);              /* 9 */
    push_xsyms(L, nx, x);                             /* 10 */
    IC = lua_newuserdatauv(L, (dim * dim + dim * nx + 1) * sizeof *IC, 0);   /* 11 */
    trace_matrix(L, 3, 10, 9, dim, dim, "dm.mechanical_connection: I(x, p)", IC);
    trace_matrix(L, 4, 10, 9, dim, nx, "dm.mechanical_connection: C(x, p)", IC + dim * dim);
    c->C = dm_conn_mech_alloc(dm_lua_exprctx(L), B, x, IC, IC + dim * dim, c->npar, par, pv,
                              c->A, &e);
    if (c->C == NULL)
      return dm_lua_fail(L, "dm.mechanical_connection", e.status, &e);
    conn_native(L, c->C);
    lua_settop(L, 8);
    return 1;
  }
  if (!lua_isnil(L, 5)) {
    if (!lua_isfunction(L, 5))
      luaL_error(L, "dm.mechanical_connection: L must be a function l(x, xdot, xi, p), got %s",
                 luaL_typename(L, 5));
    dm_lua_trace_lagrangian(L, B, 5, 7, x, xd, xi, par, pv, &np, &l);
    c = newconn(L, 2, 7);
  } else if (dm_lua_bundle_lagrangian(L, 2, x, xd, xi, par, pv, &np, &l)) {
    dm_lua_bundle_field(L, 2, "params");            /* 8 */
    if (!lua_istable(L, 8)) {
      /* a system's bundle: the system's parameters */
      dm_lsystem *ls;
      size_t k;
      lua_pop(L, 1);
      dm_lua_bundle_field(L, 2, "system");
      ls = dm_lua_tosystem(L, -1);
      lua_pop(L, 1);
      lua_createtable(L, (int)np, 0);
      for (k = 0; ls != NULL && k < ls->npar; k++) {
        lua_createtable(L, 2, 0);
        lua_pushstring(L, ls->sys.params[k]);
        lua_rawseti(L, -2, 1);
        lua_pushnumber(L, ls->sys.par[k]);
        lua_rawseti(L, -2, 2);
        lua_rawseti(L, -2, (lua_Integer)k + 1);
      }
    }
    c = newconn(L, 2, 8);
  } else {
    return luaL_error(L, "dm.mechanical_connection: give I and C, or L, or a bundle with a "
                      "Lagrangian (dm.bundle{..., L = ...}, a built-in, or from a system)");
  }
  c->npar = np;
  c->C = dm_conn_lagrangian_alloc(dm_lua_exprctx(L), B, x, xd, xi, l, np, par, pv, c->A, &e);
  if (c->C == NULL)
    return dm_lua_fail(L, "dm.mechanical_connection", e.status, &e);
  conn_native(L, c->C);
  return 1;
}

/* {==== methods ============================================================= */

static const dm_conn_bundle *conn_bundle(lua_State *L, int idx)
{
  return dm_conn_bundle_of(dm_lua_checkconn(L, idx));
}

static int c_at(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  const dm_conn_bundle *B = conn_bundle(L, 1);
  double x[DM_CONN_NX_MAX];
  gsl_matrix *M;
  dm_err e;
  size_t a, i;
  dm_lua_readshape(L, B, 2, "at: x", x);
  M = dm_pushmat(L, c->dim, c->nx);
  {
    double A[DM_LIE_DIM_MAX * DM_CONN_NX_MAX];
    if (dm_conn_local(c->C, x, A, &e) != DM_OK)
      return dm_lua_fail(L, "at", e.status, &e);
    for (a = 0; a < c->dim; a++)
      for (i = 0; i < c->nx; i++)
        gsl_matrix_set(M, a, i, A[a * c->nx + i]);
  }
  return 1;
}

static void readvec(lua_State *L, int idx, size_t n, const char *what, double *out)
{
  gsl_vector *v;
  size_t k;
  if (n == 1 && lua_type(L, idx) == LUA_TNUMBER) {
    out[0] = lua_tonumber(L, idx);
    return;
  }
  if (!lua_istable(L, idx) && dm_tovec(L, idx) == NULL)
    luaL_error(L, "%s must be a vec or a list of %d numbers, got %s", what, (int)n,
               luaL_typename(L, idx));
  lua_pushvalue(L, idx);
  v = dm_checkvector(L, lua_gettop(L), n);
  for (k = 0; k < n; k++)
    out[k] = gsl_vector_get(v, k);
  lua_pop(L, 1);
}

static int c_form(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  double q[DM_CONN_NQ_MAX], xd[DM_CONN_NX_MAX], xi[DM_LIE_DIM_MAX], out[DM_LIE_DIM_MAX];
  dm_err e;
  lua_settop(L, 4);
  conn_field(L, 1, "bundle");
  dm_lua_readpoint(L, lua_gettop(L), 2, "form: q", q);
  readvec(L, 3, c->nx, "form: xdot", xd);
  readvec(L, 4, c->dim, "form: xi", xi);
  if (dm_conn_form(c->C, q, xd, xi, out, &e) != DM_OK)
    return dm_lua_fail(L, "form", e.status, &e);
  dm_pushvec_copy(L, out, c->dim);
  return 1;
}

static int c_hlift(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  double x[DM_CONN_NX_MAX], xd[DM_CONN_NX_MAX], xi[DM_LIE_DIM_MAX];
  dm_err e;
  dm_lua_readshape(L, conn_bundle(L, 1), 2, "hlift: x", x);
  readvec(L, 3, c->nx, "hlift: xdot", xd);
  if (dm_conn_hlift_vec(c->C, x, xd, xi, &e) != DM_OK)
    return dm_lua_fail(L, "hlift", e.status, &e);
  dm_pushvec_copy(L, xi, c->dim);
  return 1;
}

static int c_curvature(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  double x[DM_CONN_NX_MAX], b[DM_LIE_DIM_MAX];
  lua_Integer i = luaL_checkinteger(L, 3), j = luaL_checkinteger(L, 4);
  dm_err e;
  dm_lua_readshape(L, conn_bundle(L, 1), 2, "curvature: x", x);
  if (i < 1 || j < 1 || (size_t)i > c->nx || (size_t)j > c->nx)
    luaL_error(L, "curvature: directions must be 1..%d, got %d and %d", (int)c->nx, (int)i, (int)j);
  if (dm_conn_curvature(c->C, x, (size_t)i - 1, (size_t)j - 1, b, &e) != DM_OK)
    return dm_lua_fail(L, "curvature", e.status, &e);
  dm_pushvec_copy(L, b, c->dim);
  return 1;
}

/* A path at idx: a list of shape points (polygon), a function s -> x
 * (traced), or a list of such functions.  Pushes an anchor (userdata
 * owning the compiled curves) and fills *npieces, curves, uds; polygon
 * data into *xs / *n when it is one. */
typedef struct curves_ud {
  size_t n;
  dm_conn_curve *c[64];
} curves_ud;

static int curves_gc(lua_State *L)
{
  curves_ud *u = lua_touserdata(L, 1);
  size_t k;
  for (k = 0; k < u->n; k++)
    dm_conn_curve_free(u->c[k]);
  u->n = 0;
  return 0;
}

static int is_curve_list(lua_State *L, int idx)
{
  int r;
  if (lua_isfunction(L, idx))
    return 1;
  if (!lua_istable(L, idx) || luaL_len(L, idx) < 1)
    return 0;
  lua_geti(L, idx, 1);
  r = lua_isfunction(L, -1);
  lua_pop(L, 1);
  return r;
}

static curves_ud *read_curves(lua_State *L, const dm_conn_bundle *B, int idx, const char *fname,
                              double **xs, size_t *n)
{
  curves_ud *u;
  size_t np, k;
  dm_err e;
  idx = lua_absindex(L, idx);
  *xs = NULL;
  if (!is_curve_list(L, idx)) {
    char w[96];
    snprintf(w, sizeof w, "%s: curve", fname);
    *xs = dm_lua_readshapes(L, B, idx, w, n);
    return NULL;
  }
  np = lua_isfunction(L, idx) ? 1 : (size_t)luaL_len(L, idx);
  if (np > 64)
    luaL_error(L, "%s: at most 64 pieces, got %d", fname, (int)np);
  u = lua_newuserdatauv(L, sizeof *u, 0);
  u->n = 0;
  lua_createtable(L, 0, 1);
  lua_pushcfunction(L, curves_gc);
  lua_setfield(L, -2, "__gc");
  lua_setmetatable(L, -2);
  for (k = 0; k < np; k++) {
    dm_expr s, x[DM_CONN_NX_MAX];
    size_t m, rows, cols;
    if (lua_isfunction(L, idx))
      lua_pushvalue(L, idx);
    else
      lua_geti(L, idx, (lua_Integer)k + 1);
    if (!lua_isfunction(L, -1))
      luaL_error(L, "%s: curve piece %d must be a function s -> x(s), got %s", fname, (int)k + 1,
                 luaL_typename(L, -1));
    s = dm_expr_sym(dm_lua_exprctx(L), "s");
    dm_lua_pushexpr(L, s);
    dm_lua_trace(L, "the curve s -> x(s)", 1);
    m = dm_lua_toexprs(L, -1, "the curve x(s)", x, B->nx, &rows, &cols);
    if (m != B->nx)
      luaL_error(L, "%s: the curve must return %d shape coordinates, got %d", fname, (int)B->nx,
                 (int)m);
    lua_pop(L, 1);
    if ((u->c[k] = dm_conn_curve_alloc(dm_lua_exprctx(L), s, B->nx, x, &e)) == NULL)
      return dm_lua_fail(L, fname, e.status, &e), NULL;
    u->n = k + 1;
  }
  return u;
}

static const char *const topt_keys[] = {"substeps", "tol", NULL};

static int c_transport(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  const dm_conn_bundle *B = conn_bundle(L, 1);
  dm_conn_topts o;
  double *xs, H[DM_LIE_NQ_MAX], P[DM_LIE_NQ_MAX];
  size_t n, k;
  curves_ud *u;
  dm_err e;
  int st = DM_OK;
  lua_settop(L, 3);
  if (lua_istable(L, 3))
    dm_lua_conn_checkkeys(L, 3, "transport", topt_keys);
  dm_lua_readtopts(L, 3, "transport", &o);
  u = read_curves(L, B, 2, "transport", &xs, &n);
  if (u == NULL) {
    st = dm_conn_transport_polygon(c->C, xs, n, &o, H, &e);
  } else {
    dm_lie_identity(B->G, H);
    for (k = 0; k < u->n && st == DM_OK; k++)
      if ((st = dm_conn_transport(c->C, dm_conn_curve_eval, u->c[k], &o, P, &e)) == DM_OK)
        dm_lie_compose(B->G, H, P, H);
  }
  if (st != DM_OK)
    return dm_lua_fail(L, "transport", st, &e);
  conn_field(L, 1, "bundle");
  dm_lua_bundle_field(L, -1, "group");
  dm_lua_pushgroupelem(L, -1, H);
  return 1;
}

static int c_holonomy(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  const dm_conn_bundle *B = conn_bundle(L, 1);
  dm_conn_topts o;
  double *xs, q0[DM_CONN_NQ_MAX], S[DM_LIE_NQ_MAX], P[DM_LIE_NQ_MAX];
  size_t n;
  curves_ud *u;
  dm_err e;
  int st, bidx;
  lua_settop(L, 4);
  if (lua_istable(L, 4))
    dm_lua_conn_checkkeys(L, 4, "holonomy", topt_keys);
  dm_lua_readtopts(L, 4, "holonomy", &o);
  conn_field(L, 1, "bundle");
  bidx = lua_gettop(L);
  dm_lua_readpoint(L, bidx, 3, "holonomy: q0", q0);
  u = read_curves(L, B, 2, "holonomy", &xs, &n);
  if (u == NULL) {
    st = dm_conn_holonomy_polygon(c->C, xs, n, q0, &o, S, P, &e);
  } else {
    dm_conn_curve_fn f[64];
    size_t k;
    for (k = 0; k < u->n; k++)
      f[k] = dm_conn_curve_eval;
    st = dm_conn_holonomy(c->C, u->n, f, (void *const *)u->c, q0, &o, S, P, &e);
  }
  if (st != DM_OK)
    return dm_lua_fail(L, "holonomy", st, &e);
  dm_lua_bundle_field(L, bidx, "group");
  dm_lua_pushholonomy(L, lua_gettop(L), S, P,
                      B->G->abelian && B->G->dim == 1 ? P[0] : NAN);
  return 1;
}

static int c_phase(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  const dm_conn_bundle *B = conn_bundle(L, 1);
  double q0[DM_CONN_NQ_MAX], S[DM_LIE_NQ_MAX], P[DM_LIE_NQ_MAX], gap;
  size_t buf[DM_CONN_NX_MAX];
  const size_t *cols;
  dm_conn_topts o;
  dm_err e;
  int bidx;
  lua_settop(L, 4);
  if (lua_istable(L, 4))
    dm_lua_conn_checkkeys(L, 4, "phase", topt_keys);
  dm_lua_readtopts(L, 4, "phase", &o);
  conn_field(L, 1, "bundle");
  bidx = lua_gettop(L);
  cols = dm_lua_phase_cols(L, bidx, 2, 3, buf, q0);
  if (dm_conn_phase(c->C, dm_checktraj(L, 2), cols, q0, &o, S, P, &gap, &e) != DM_OK)
    return dm_lua_fail(L, "phase", e.status, &e);
  dm_lua_bundle_field(L, bidx, "group");
  dm_lua_pushholonomy(L, lua_gettop(L), S, P, B->G->abelian && B->G->dim == 1 ? P[0] : NAN);
  lua_pushnumber(L, gap);
  return 2;
}

void dm_lua_push_conn_exprs(lua_State *L, int gidx, const char *name, size_t nx,
                            const dm_expr *x, const dm_expr *A, size_t npar, const dm_expr *par,
                            const char *const *pnames, const double *pv)
{
  dm_lbundle *b;
  dm_lconn *c;
  size_t k;
  int bidx, pidx;
  dm_err e;
  gidx = lua_absindex(L, gidx);
  lua_createtable(L, 0, 4);                           /* dm.bundle{...} arguments */
  lua_pushinteger(L, (lua_Integer)nx);
  lua_setfield(L, -2, "shape_dim");
  lua_pushvalue(L, gidx);
  lua_setfield(L, -2, "group");
  lua_pushstring(L, name);
  lua_setfield(L, -2, "name");
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.core");
  lua_call(L, 1, 1);
  lua_getfield(L, -1, "bundle");
  lua_remove(L, -2);
  lua_insert(L, -2);
  lua_call(L, 1, 1);
  bidx = lua_gettop(L);
  b = dm_lua_checkbundle(L, bidx);
  lua_createtable(L, (int)npar, 0);
  for (k = 0; k < npar; k++) {
    lua_createtable(L, 2, 0);
    lua_pushstring(L, pnames[k]);
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, pv[k]);
    lua_rawseti(L, -2, 2);
    lua_rawseti(L, -2, (lua_Integer)k + 1);
  }
  pidx = lua_gettop(L);
  c = newconn(L, bidx, pidx);
  c->npar = npar;
  memcpy(c->A, A, b->B->G->dim * nx * sizeof *A);
  if ((c->C = dm_conn_expr_alloc(dm_lua_exprctx(L), b->B, x, A, npar, par, pv, &e)) == NULL)
    dm_lua_fail(L, "connection", e.status, &e);
  conn_native(L, c->C);
  lua_replace(L, bidx);
  lua_settop(L, bidx);
}

static int c_set_params(lua_State *L)
{
  dm_lconn *c = checklconn(L, 1);
  double pv[32];
  size_t k;
  dm_err e;
  luaL_checktype(L, 2, LUA_TTABLE);
  conn_field(L, 1, "params");
  for (k = 0; k < c->npar; k++) {
    lua_geti(L, -1, (lua_Integer)k + 1);
    lua_geti(L, -1, 1);
    lua_gettable(L, 2);
    if (lua_isnil(L, -1)) {
      lua_pop(L, 1);
      lua_geti(L, -1, 2);
    }
    if (lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "set_params: the value of parameter %d must be a number", (int)k + 1);
    pv[k] = lua_tonumber(L, -1);
    lua_pop(L, 2);
  }
  if (dm_conn_set_params(c->C, pv, &e) != DM_OK)
    return dm_lua_fail(L, "set_params", e.status, &e);
  /* keep the new values in the list */
  for (k = 0; k < c->npar; k++) {
    lua_geti(L, -1, (lua_Integer)k + 1);
    lua_pushnumber(L, pv[k]);
    lua_rawseti(L, -2, 2);
    lua_pop(L, 1);
  }
  lua_settop(L, 1);
  return 1;
}

/* "[a, b; c, d]" of the local form, each entry as a formula */
static void push_formula(lua_State *L, dm_lconn *c)
{
  luaL_Buffer b;
  size_t a, i;
  luaL_buffinit(L, &b);
  luaL_addchar(&b, '[');
  for (a = 0; a < c->dim; a++)
    for (i = 0; i < c->nx; i++) {
      char *s = dm_expr_to_string(dm_lua_exprctx(L), c->A[a * c->nx + i], 120, NULL);
      if (i > 0)
        luaL_addstring(&b, ", ");
      else if (a > 0)
        luaL_addstring(&b, "; ");
      luaL_addstring(&b, s ? s : "?");
      free(s);
    }
  luaL_addchar(&b, ']');
  luaL_pushresult(&b);
}

static int conn_tostring(lua_State *L)
{
  dm_lconn *c = luaL_checkudata(L, 1, DM_CONN_MT);
  if (c->C == NULL) {
    lua_pushliteral(L, "<Connection (freed)>");
    return 1;
  }
  push_formula(L, c);
  lua_pushfstring(L, "<Connection on %s: A(x) = %s>", dm_conn_bundle_of(c->C)->name,
                  lua_tostring(L, -1));
  return 1;
}

static int conn_index(lua_State *L)
{
  dm_lconn *c = luaL_checkudata(L, 1, DM_CONN_MT);
  const char *k = lua_tostring(L, 2);
  if (k != NULL && c->C != NULL) {
    if (strcmp(k, "A") == 0) {
      size_t a, i;
      lua_createtable(L, (int)c->dim, 0);
      for (a = 0; a < c->dim; a++) {
        lua_createtable(L, (int)c->nx, 0);
        for (i = 0; i < c->nx; i++) {
          dm_lua_pushexpr(L, c->A[a * c->nx + i]);
          lua_rawseti(L, -2, (lua_Integer)i + 1);
        }
        lua_rawseti(L, -2, (lua_Integer)a + 1);
      }
      return 1;
    }
    if (strcmp(k, "bundle") == 0 || strcmp(k, "params") == 0) {
      conn_field(L, 1, k);
      return 1;
    }
  }
  return dm_index_methods(L);
}

static const dm_reg conn_methods[] = {
  {"at", c_at, "A:at(x) -> mat", "The local connection form A_loc(x) (dim G x dim S): horizontal motion is g^-1 gdot = -A_loc(x) xdot."},
  {"form", c_form, "A:form(q, xdot, xi) -> vec",
   "The connection 1-form Ad_g (xi + A_loc(x) xdot) at q = (x, g), xi the body velocity g^-1 gdot."},
  {"hlift", c_hlift, "A:hlift(x, xdot) -> vec",
   "The horizontal lift of the shape velocity xdot as a body velocity xi = -A_loc(x) xdot."},
  {"curvature", c_curvature, "A:curvature(x, i, j) -> vec",
   "The curvature B_ij = d_i A_j - d_j A_i - [A_i, A_j] at x (exact derivatives through the expressions)."},
  {"transport", c_transport, "A:transport(curve[, {substeps = 8 | tol = t}]) -> g",
   "The body transport H of the horizontal lift along a curve (polygon, function s -> x(s) on [0, 1], or a list of them): g(1) = g(0) H."},
  {"holonomy", c_holonomy, "A:holonomy(loop, q0[, {substeps = 8 | tol = t}]) -> hol",
   "The holonomy of a closed curve from q0: a table {spatial, body, angle[, axis]} (Magnus 4 per piece, or adaptive rk8pd with tol)."},
  {"phase", c_phase, "A:phase(traj[, q0][, {substeps = 8 | tol = t}]) -> hol, gap",
   "The geometric phase of the shape path sampled by a trajectory (straight segments between samples): the body transport as a holonomy table, and the gap between its ends (0 for a loop)."},
  {"set_params", c_set_params, "A:set_params{name = value, ...} -> A",
   "Change the connection's parameters (no recompilation)."},
  {NULL, NULL, NULL, NULL}
};

/* }==== */

static const dm_reg cont_funcs[] = {
  {"connection", l_connection,
   "dm.connection{bundle = B, A = function(x, p) return {{...}, ...} end[, params = {...}]} -> A",
   "A continuous connection on a trivial bundle S x G given by its local form A_loc(x) (dim G rows of dim S entries), traced once and compiled."},
  {"mechanical_connection", l_mechanical,
   "dm.mechanical_connection{bundle = B, I = Ifun, C = Cfun | L = function(x, xdot, xi, p) ...[, params = {...}]} -> A",
   "The mechanical connection A = I(x)^-1 C(x) of a G-invariant kinetic energy (locked inertia I, coupling C), built symbolically, from I and C or from a reduced Lagrangian (default: the bundle's)."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_conn_cont(lua_State *L)
{
  int dm = lua_gettop(L);
  static const luaL_Reg meta[] = {{"__index", conn_index}, {"__gc", conn_gc},
                                  {"__close", conn_gc}, {"__tostring", conn_tostring},
                                  {NULL, NULL}};
  dm_newclass(L, DM_CONN_MT, "connection", conn_methods, meta);
  lua_pop(L, 1);
  lua_pushvalue(L, dm);
  dm_register(L, "dm.", cont_funcs);
  lua_settop(L, dm);
}
