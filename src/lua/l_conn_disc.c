/* l_conn_disc.c -- discrete connections in Lua (src/conn/conn.h):
 *   Ad = dm.discrete_connection{from = A, rule = "midpoint"}   -- euler|cayley|transport|exact
 *   Ak = dm.discrete_connection{bundle = B, A = function(x0, x1) return g end}
 *   LC = dm.discrete_connection{bundle = dm.sphere_frames(), rule = "levi-civita"}
 *   Ad(q0, q1) ; Ad:lift(xs, q0) ; Ad:holonomy(loop, q0).angle ; Ad:reduce(q0, q1) ...
 *   dm.order_test(Ad, {ref = "transport", q = q0, v = {1, 0}, h = {0.1, 0.05}})
 * A user function A(x0, x1) is called from inside the C loops through a
 * protected trampoline; its errors come back as Lua errors once the loop
 * has unwound.  dm.discrete_mechanical_connection: l_conn_dmech.c. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_conn.h"
#include "lua/l_dec.h"

typedef struct tramp {
  lua_State *L;                 /* the state of the current call */
  int fref, gref;               /* registry: the function, the group userdata */
  size_t nx;
} tramp;

typedef struct dm_ldconn {
  dm_conn_dc *D;                /* NULL until built */
  tramp t;
} dm_ldconn;

dm_conn_dc *dm_lua_todconn(lua_State *L, int idx)
{
  dm_ldconn *d = luaL_testudata(L, idx, DM_DCONN_MT);
  return d != NULL ? d->D : NULL;
}

static dm_ldconn *checkld(lua_State *L, int idx)
{
  dm_ldconn *d = luaL_testudata(L, idx, DM_DCONN_MT);
  if (d == NULL || d->D == NULL)
    dm_argexpected(L, idx, "discrete connection (dm.discrete_connection{...})",
                   luaL_typename(L, idx));
  d->t.L = L;                   /* callbacks run in the caller's state */
  return d;
}

static int dconn_gc(lua_State *L)
{
  dm_ldconn *d = luaL_checkudata(L, 1, DM_DCONN_MT);
  dm_conn_dc_free(d->D);
  d->D = NULL;
  if (d->t.fref != LUA_NOREF) {
    luaL_unref(L, LUA_REGISTRYINDEX, d->t.fref);
    luaL_unref(L, LUA_REGISTRYINDEX, d->t.gref);
    d->t.fref = d->t.gref = LUA_NOREF;
  }
  return 0;
}

/* an empty discrete connection; user value {bundle = B} (bundle at bidx) */
static dm_ldconn *newdconn(lua_State *L, int bidx)
{
  dm_ldconn *d;
  bidx = lua_absindex(L, bidx);
  d = lua_newuserdatauv(L, sizeof *d, 1);
  d->D = NULL;
  d->t.L = L;
  d->t.fref = d->t.gref = LUA_NOREF;
  d->t.nx = 0;
  luaL_setmetatable(L, DM_DCONN_MT);
  lua_createtable(L, 0, 4);
  lua_pushvalue(L, bidx);
  lua_setfield(L, -2, "bundle");
  lua_setiuservalue(L, -2, 1);
  return d;
}

static void dfield(lua_State *L, int idx, const char *key)
{
  lua_getiuservalue(L, idx, 1);
  lua_getfield(L, -1, key);
  lua_remove(L, -2);
}

void dm_lua_dconn_setfield(lua_State *L, int idx, const char *key, int vidx)
{
  idx = lua_absindex(L, idx);
  vidx = lua_absindex(L, vidx);
  lua_getiuservalue(L, idx, 1);
  lua_pushvalue(L, vidx);
  lua_setfield(L, -2, key);
  lua_pop(L, 1);
}

dm_conn_dc **dm_lua_newdconn(lua_State *L, int bidx)
{
  return &newdconn(L, bidx)->D;
}

/* {==== the trampoline of A(x0, x1) ========================================= */

typedef struct tcall {
  tramp *t;
  const double *x0, *x1;
  double *A;
} tcall;

static int local_protected(lua_State *L)
{
  tcall *c = lua_touserdata(L, 1);
  lua_rawgeti(L, LUA_REGISTRYINDEX, c->t->fref);
  dm_pushvec_copy(L, c->x0, c->t->nx);
  dm_pushvec_copy(L, c->x1, c->t->nx);
  lua_call(L, 2, 1);
  lua_rawgeti(L, LUA_REGISTRYINDEX, c->t->gref);
  dm_lua_readgroupelem(L, -1, -2, "the value of A(x0, x1)", c->A);
  return 0;
}

static int local_cb(void *ud, const double *x0, const double *x1, double *A, dm_err *e)
{
  tramp *t = ud;
  lua_State *L = t->L;
  tcall c = {t, x0, x1, A};
  lua_pushcfunction(L, local_protected);
  lua_pushlightuserdata(L, &c);
  if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
    dm_err_set(e, DM_ECALLBACK, "%s", lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1)
                                                                    : "error in A(x0, x1)");
    lua_pop(L, 1);
    return DM_ECALLBACK;
  }
  return DM_OK;
}

/* }==== */

/* {==== constructors ======================================================== */

static const char *const dc_keys[] = {"from", "rule", "bundle", "A", "mesh", "substeps", "tol",
                                      NULL};

static int l_discrete_connection(lua_State *L)
{
  const dm_conn_rule *R;
  const dm_conn_bundle *B;
  dm_conn *parent = NULL;
  dm_ldconn *d;
  const char *rule;
  dm_conn_topts o;
  dm_err e;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_lua_conn_checkkeys(L, 1, "dm.discrete_connection", dc_keys);
  lua_getfield(L, 1, "mesh");
  if (!lua_isnil(L, 2)) {
    lua_getfield(L, 1, "rule");
    if (!lua_isnil(L, -1) && (lua_type(L, -1) != LUA_TSTRING ||
                              strcmp(lua_tostring(L, -1), "levi-civita") != 0))
      luaL_error(L, "dm.discrete_connection: a mesh carries the rule \"levi-civita\"");
    return dm_lua_meshconn_new(L, 2);
  }
  lua_settop(L, 1);
  lua_getfield(L, 1, "from");                         /* 2 */
  lua_getfield(L, 1, "bundle");                       /* 3 */
  lua_getfield(L, 1, "A");                            /* 4 */
  lua_getfield(L, 1, "rule");                         /* 5 */
  if (!lua_isnil(L, 2)) {
    parent = dm_lua_toconn(L, 2);
    if (parent == NULL)
      luaL_error(L, "dm.discrete_connection: from must be a continuous connection "
                 "(dm.connection{...}), got %s", luaL_typename(L, 2));
    lua_getiuservalue(L, 2, 1);
    lua_getfield(L, -1, "bundle");
    lua_replace(L, 3);
    lua_pop(L, 1);
  }
  if (lua_isnil(L, 3))
    luaL_error(L, "dm.discrete_connection: give from = <connection> or bundle = <bundle>");
  B = dm_lua_checkbundle(L, 3)->B;
  rule = lua_isnil(L, 5) ? (lua_isnil(L, 4) ? (parent ? "midpoint" : NULL) : "local")
                         : lua_tostring(L, 5);
  if (rule == NULL)
    luaL_error(L, "dm.discrete_connection: rule expected (\"trivial\", \"levi-civita\", or a "
               "function A(x0, x1)) for a bundle without a continuous connection");
  R = dm_conn_rule_find(rule);
  if (R == NULL || strcmp(rule, "mechanical") == 0) {
    if (R != NULL)
      luaL_error(L, "dm.discrete_connection: the mechanical rule is made by "
                 "dm.discrete_mechanical_connection{bundle = B, Ld = ...}");
    luaL_error(L, "dm.discrete_connection: unknown rule '%s' (euler, midpoint, cayley, "
               "transport, exact, trivial, local, levi-civita)", rule);
  }
  if (strcmp(rule, "local") == 0 && !lua_isfunction(L, 4))
    luaL_error(L, "dm.discrete_connection: rule \"local\" needs A = function(x0, x1) returning "
               "a group element, got %s", luaL_typename(L, 4));
  if (!lua_isnil(L, 4) && strcmp(rule, "local") != 0)
    luaL_error(L, "dm.discrete_connection: A is a local representation: rule must be \"local\"");
  dm_lua_readtopts(L, 1, "dm.discrete_connection", &o);
  d = newdconn(L, 3);                                 /* 6 */
  if (parent)
    dm_lua_dconn_setfield(L, 6, "parent", 2);
  if (strcmp(rule, "local") == 0) {
    lua_pushvalue(L, 4);
    d->t.fref = luaL_ref(L, LUA_REGISTRYINDEX);
    dm_lua_bundle_field(L, 3, "group");
    d->t.gref = luaL_ref(L, LUA_REGISTRYINDEX);
    d->t.nx = B->nx;
  }
  d->D = dm_conn_dc_alloc(R, B, parent, strcmp(rule, "local") == 0 ? local_cb : NULL, &d->t, &e);
  if (d->D == NULL)
    return dm_lua_fail(L, "dm.discrete_connection", e.status, &e);
  dm_conn_dc_set_topts(d->D, &o);
  lua_settop(L, 6);
  return 1;
}

/* }==== */

/* {==== methods ============================================================= */

/* the bundle pushed above the method's nargs arguments (missing ones nil) */
static int bundle_idx(lua_State *L, int didx, int nargs)
{
  lua_settop(L, nargs);
  dfield(L, didx, "bundle");
  return lua_gettop(L);
}

static int push_g(lua_State *L, int bidx, const double *g)
{
  dm_lua_bundle_field(L, bidx, "group");
  dm_lua_pushgroupelem(L, -1, g);
  lua_remove(L, -2);
  return 1;
}

/* The discrete connection at 1 and the pair (q0, q1) at 2, 3 named
 * "<what>: q0", "<what>: q1"; *b the index of the bundle pushed above. */
static dm_ldconn *pair_args(lua_State *L, const char *what, int *b, double *q0, double *q1)
{
  dm_ldconn *d = checkld(L, 1);
  char w[64];
  *b = bundle_idx(L, 1, 3);
  snprintf(w, sizeof w, "%s: q0", what);
  dm_lua_readpoint(L, *b, 2, w, q0);
  snprintf(w, sizeof w, "%s: q1", what);
  dm_lua_readpoint(L, *b, 3, w, q1);
  return d;
}

static int d_call(lua_State *L)
{
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], g[DM_LIE_NQ_MAX];
  int b;
  dm_ldconn *d = pair_args(L, "A_d", &b, q0, q1);
  dm_err e;
  if (dm_conn_dc_eval(d->D, q0, q1, g, &e) != DM_OK)
    return dm_lua_fail(L, "A_d", e.status, &e);
  return push_g(L, b, g);
}

static int d_at(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 3);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double x0[DM_CONN_NX_MAX], x1[DM_CONN_NX_MAX], g[DM_LIE_NQ_MAX];
  dm_err e;
  dm_lua_readshape(L, B, 2, "at: x0", x0);
  dm_lua_readshape(L, B, 3, "at: x1", x1);
  if (dm_conn_dc_local(d->D, x0, x1, g, &e) != DM_OK)
    return dm_lua_fail(L, "at", e.status, &e);
  return push_g(L, b, g);
}

static int hor_ver(lua_State *L, int ver)
{
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], r[DM_CONN_NQ_MAX];
  int b;
  dm_ldconn *d = pair_args(L, ver ? "ver" : "hor", &b, q0, q1);
  dm_err e;
  int st;
  st = ver ? dm_conn_dc_ver(d->D, q0, q1, r, &e) : dm_conn_dc_hor(d->D, q0, q1, r, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, ver ? "ver" : "hor", st, &e);
  dm_lua_pushpoint(L, b, q0);
  dm_lua_pushpoint(L, b, r);
  return 2;
}

static int d_hor(lua_State *L)
{
  return hor_ver(L, 0);
}

static int d_ver(lua_State *L)
{
  return hor_ver(L, 1);
}

static int d_hlift(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 3);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double q0[DM_CONN_NQ_MAX], x1[DM_CONN_NX_MAX], q1[DM_CONN_NQ_MAX];
  dm_err e;
  dm_lua_readpoint(L, b, 2, "hlift: q0", q0);
  dm_lua_readshape(L, B, 3, "hlift: x1", x1);
  if (dm_conn_dc_hlift(d->D, q0, x1, q1, &e) != DM_OK)
    return dm_lua_fail(L, "hlift", e.status, &e);
  dm_lua_pushpoint(L, b, q1);
  return 1;
}

static int d_lift(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 3);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double q0[DM_CONN_NQ_MAX], *xs;
  gsl_vector *qs;
  size_t n, k;
  dm_err e;
  dm_lua_readpoint(L, b, 3, "lift: q0", q0);
  xs = dm_lua_readshapes(L, B, 2, "lift: xs", &n);
  if (n < 1)
    luaL_error(L, "lift: at least one shape point expected");
  qs = dm_pushvec(L, n * B->nq);
  if (dm_conn_dc_lift(d->D, xs, n, q0, qs->data, &e) != DM_OK)
    return dm_lua_fail(L, "lift", e.status, &e);
  lua_createtable(L, (int)n, 0);
  for (k = 0; k < n; k++) {
    dm_lua_pushpoint(L, b, qs->data + k * B->nq);
    lua_rawseti(L, -2, (lua_Integer)k + 1);
  }
  return 1;
}

static int d_holonomy(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 3);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double q0[DM_CONN_NQ_MAX], *xs, S[DM_LIE_NQ_MAX], P[DM_LIE_NQ_MAX], lifted;
  int have_body;
  size_t n;
  dm_err e;
  dm_lua_readpoint(L, b, 3, "holonomy: q0", q0);
  xs = dm_lua_readshapes(L, B, 2, "holonomy: loop", &n);
  have_body = dm_conn_bundle_is_trivial(B) || B->G->abelian || B->type->trivialize != NULL;
  if (dm_conn_dc_holonomy(d->D, xs, n, q0, S, have_body ? P : NULL, &lifted, &e) != DM_OK)
    return dm_lua_fail(L, "holonomy", e.status, &e);
  dm_lua_bundle_field(L, b, "group");
  dm_lua_pushholonomy(L, lua_gettop(L), S, have_body ? P : NULL, lifted);
  return 1;
}

/* {q0, q1} at idx */
static void read_pair(lua_State *L, int b, int idx, const char *what, double *a0, double *a1)
{
  char w[64];
  if (!lua_istable(L, idx) || luaL_len(L, idx) != 2)
    luaL_error(L, "%s must be a pair {q0, q1}, got %s", what, luaL_typename(L, idx));
  snprintf(w, sizeof w, "%s[1]", what);
  lua_geti(L, idx, 1);
  dm_lua_readpoint(L, b, -1, w, a0);
  snprintf(w, sizeof w, "%s[2]", what);
  lua_geti(L, idx, 2);
  dm_lua_readpoint(L, b, -1, w, a1);
  lua_pop(L, 2);
}

static int d_compose(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 3);
  double a0[DM_CONN_NQ_MAX], a1[DM_CONN_NQ_MAX], b0[DM_CONN_NQ_MAX], b1[DM_CONN_NQ_MAX],
         c1[DM_CONN_NQ_MAX];
  dm_err e;
  read_pair(L, b, 2, "compose: first pair", a0, a1);
  read_pair(L, b, 3, "compose: second pair", b0, b1);
  if (dm_conn_dc_compose(d->D, a0, a1, b0, b1, c1, &e) != DM_OK)
    return dm_lua_fail(L, "compose", e.status, &e);
  lua_createtable(L, 2, 0);
  dm_lua_pushpoint(L, b, a0);
  lua_rawseti(L, -2, 1);
  dm_lua_pushpoint(L, b, c1);
  lua_rawseti(L, -2, 2);
  return 1;
}

static int d_reduce(lua_State *L)
{
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], x0[DM_CONN_NX_MAX], x1[DM_CONN_NX_MAX],
         z[DM_LIE_NQ_MAX];
  int b;
  dm_ldconn *d = pair_args(L, "reduce", &b, q0, q1);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  dm_err e;
  if (dm_conn_dc_reduce(d->D, q0, q1, x0, x1, z, &e) != DM_OK)
    return dm_lua_fail(L, "reduce", e.status, &e);
  dm_pushvec_copy(L, x0, B->nx);
  dm_pushvec_copy(L, x1, B->nx);
  push_g(L, b, z);
  return 3;
}

static int d_unreduce(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 5);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], x0[DM_CONN_NX_MAX], x1[DM_CONN_NX_MAX],
         z[DM_LIE_NQ_MAX];
  dm_err e;
  dm_lua_readshape(L, B, 2, "unreduce: x0", x0);
  dm_lua_readshape(L, B, 3, "unreduce: x1", x1);
  dm_lua_bundle_field(L, b, "group");
  dm_lua_readgroupelem(L, -1, 4, "unreduce: zeta", z);
  dm_lua_readpoint(L, b, 5, "unreduce: q0", q0);
  if (dm_conn_dc_unreduce(d->D, x0, x1, z, q0, q1, &e) != DM_OK)
    return dm_lua_fail(L, "unreduce", e.status, &e);
  dm_lua_pushpoint(L, b, q1);
  return 1;
}

static int d_split(lua_State *L)
{
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], x[DM_CONN_NX_MAX], g[DM_LIE_NQ_MAX];
  int b;
  dm_ldconn *d = pair_args(L, "split", &b, q0, q1);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  dm_err e;
  if (dm_conn_dc_eval(d->D, q0, q1, g, &e) != DM_OK)
    return dm_lua_fail(L, "split", e.status, &e);
  dm_conn_proj(B, q0, x);
  dm_pushvec_copy(L, x, B->nx);
  dm_conn_proj(B, q1, x);
  dm_pushvec_copy(L, x, B->nx);
  push_g(L, b, g);
  return 3;
}

static int d_limit(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 5);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double q[DM_CONN_NQ_MAX], xd[DM_CONN_NX_MAX], xi[DM_LIE_DIM_MAX], out[DM_LIE_DIM_MAX],
         eps = luaL_optnumber(L, 5, 1e-4);
  gsl_vector *v;
  size_t k;
  dm_err e;
  dm_lua_readpoint(L, b, 2, "limit: q", q);
  v = dm_checkvector(L, 3, B->nx);
  for (k = 0; k < B->nx; k++)
    xd[k] = gsl_vector_get(v, k);
  dm_lua_conn_readalgebra(L, 4, B->G->dim, xi);
  if (dm_conn_dc_limit(d->D, q, xd, xi, eps, out, &e) != DM_OK)
    return dm_lua_fail(L, "limit", e.status, &e);
  dm_pushvec_copy(L, out, B->G->dim);
  return 1;
}

static int d_phase(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  int b = bundle_idx(L, 1, 3);
  const dm_conn_bundle *B = dm_lua_checkbundle(L, b)->B;
  double q0[DM_CONN_NQ_MAX], S[DM_LIE_NQ_MAX], P[DM_LIE_NQ_MAX], gap;
  size_t buf[DM_CONN_NX_MAX];
  const size_t *cols = dm_lua_phase_cols(L, b, 2, 3, buf, q0);
  dm_err e;
  if (dm_conn_dc_phase(d->D, dm_checktraj(L, 2), cols, q0, S, P, &gap, &e) != DM_OK)
    return dm_lua_fail(L, "phase", e.status, &e);
  dm_lua_bundle_field(L, b, "group");
  dm_lua_pushholonomy(L, lua_gettop(L), S, P, B->G->abelian && B->G->dim == 1 ? P[0] : NAN);
  lua_pushnumber(L, gap);
  return 2;
}

static int d_momentum(lua_State *L)
{
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], J[DM_LIE_DIM_MAX];
  int b;
  dm_ldconn *d = pair_args(L, "momentum", &b, q0, q1);
  dm_err e;
  if (dm_conn_dc_momentum(d->D, q0, q1, J, &e) != DM_OK)
    return dm_lua_fail(L, "momentum", e.status, &e);
  dm_pushvec_copy(L, J, dm_conn_dc_bundle(d->D)->G->dim);
  return 1;
}

static int d_set_mu(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  double mu[DM_LIE_DIM_MAX];
  dm_err e;
  dm_lua_conn_readalgebra(L, 2, dm_conn_dc_bundle(d->D)->G->dim, mu);
  if (dm_conn_dc_set_mu(d->D, mu, &e) != DM_OK)
    return dm_lua_fail(L, "set_mu", e.status, &e);
  lua_settop(L, 1);
  return 1;
}

static int d_newton_stats(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1);
  unsigned long s, it;
  dm_conn_dc_newton_stats(d->D, &s, &it);
  lua_pushinteger(L, (lua_Integer)s);
  lua_pushinteger(L, (lua_Integer)it);
  return 2;
}

static int dconn_tostring(lua_State *L)
{
  dm_ldconn *d = luaL_checkudata(L, 1, DM_DCONN_MT);
  if (d->D == NULL) {
    lua_pushliteral(L, "<Discrete connection (freed)>");
    return 1;
  }
  dfield(L, 1, "parent");
  if (!lua_isnil(L, -1))
    lua_pushfstring(L, "<Discrete connection '%s' on %s, from %s>", dm_conn_dc_rule(d->D)->name,
                    dm_conn_dc_bundle(d->D)->name, dm_tolstring(L, -1, NULL));
  else
    lua_pushfstring(L, "<Discrete connection '%s' on %s>", dm_conn_dc_rule(d->D)->name,
                    dm_conn_dc_bundle(d->D)->name);
  return 1;
}

static int dconn_index(lua_State *L)
{
  dm_ldconn *d = luaL_checkudata(L, 1, DM_DCONN_MT);
  const char *k = lua_tostring(L, 2);
  if (k != NULL && d->D != NULL) {
    if (strcmp(k, "rule") == 0) {
      lua_pushstring(L, dm_conn_dc_rule(d->D)->name);
      return 1;
    }
    if (strcmp(k, "bundle") == 0 || strcmp(k, "parent") == 0 || strcmp(k, "guess") == 0) {
      dfield(L, 1, k);
      return 1;
    }
  }
  return dm_index_methods(L);
}

/* dm.order_test(Ad, {ref = "transport" | Dref, q = q0, v = {...}, h = {...}, tol = 1e-13}) */
static const char *const order_keys[] = {"ref", "q", "v", "h", "tol", NULL};

static int l_order_test(lua_State *L)
{
  dm_ldconn *d = checkld(L, 1), *r;
  int b;
  const dm_conn_bundle *B;
  double q[DM_CONN_NQ_MAX], v[DM_CONN_NX_MAX], h[64], def[64], slope;
  size_t nh, k;
  gsl_vector *hv, *out;
  dm_err e;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  dm_lua_conn_checkkeys(L, 2, "dm.order_test", order_keys);
  b = bundle_idx(L, 1, 2);                               /* 3 */
  B = dm_lua_checkbundle(L, b)->B;
  lua_getfield(L, 2, "q");
  dm_lua_readpoint(L, b, -1, "dm.order_test: q", q);
  lua_pop(L, 1);
  lua_getfield(L, 2, "v");
  dm_lua_readshape(L, B, -1, "dm.order_test: v", v);
  lua_pop(L, 1);
  lua_getfield(L, 2, "h");
  if (!lua_istable(L, -1) && dm_tovec(L, -1) == NULL)
    luaL_error(L, "dm.order_test: h must list the step sizes ({0.1, 0.05, 0.025})");
  hv = dm_checkvector(L, lua_gettop(L), 0);
  nh = hv->size;
  if (nh < 2 || nh > 64)
    luaL_error(L, "dm.order_test: 2 to 64 step sizes expected, got %d", (int)nh);
  for (k = 0; k < nh; k++)
    h[k] = gsl_vector_get(hv, k);
  lua_getfield(L, 2, "ref");                          /* the reference */
  if (lua_type(L, -1) == LUA_TSTRING || lua_isnil(L, -1)) {
    const char *rn = lua_isnil(L, -1) ? "transport" : lua_tostring(L, -1);
    const dm_conn_rule *R = dm_conn_rule_find(rn);
    dm_conn_topts o = {8, dm_optnumberfield(L, 2, "tol", 1e-13)};
    dfield(L, 1, "parent");
    if (R == NULL || dm_lua_toconn(L, -1) == NULL)
      luaL_error(L, "dm.order_test: ref \"%s\" needs a rule and a discrete connection made "
                 "from a continuous one (or give ref = <discrete connection>)", rn);
    r = newdconn(L, b);
    if ((r->D = dm_conn_dc_alloc(R, B, dm_lua_toconn(L, -2), NULL, NULL, &e)) == NULL)
      return dm_lua_fail(L, "dm.order_test", e.status, &e);
    dm_conn_dc_set_topts(r->D, &o);
    dm_lua_dconn_setfield(L, -1, "parent", -2);
  } else {
    r = checkld(L, lua_gettop(L));
  }
  if (dm_conn_dc_order(d->D, r->D, q, v, h, nh, def, &slope, &e) != DM_OK)
    return dm_lua_fail(L, "dm.order_test", e.status, &e);
  out = dm_pushvec(L, nh);
  for (k = 0; k < nh; k++)
    gsl_vector_set(out, k, def[k]);
  lua_pushnumber(L, slope);
  return 2;
}

static const dm_reg dconn_methods[] = {
  {"at", d_at, "Ad:at(x0, x1) -> g",
   "The local representation A(x0, x1) in G (trivial bundles): A_d(x0, g0, x1, g1) = g1 A(x0, x1) g0^-1."},
  {"hor", d_hor, "Ad:hor(q0, q1) -> q0, q1h", "The horizontal part (q0, A_d(q0, q1)^-1 q1) of a pair."},
  {"ver", d_ver, "Ad:ver(q0, q1) -> q0, q1v", "The vertical part (q0, A_d(q0, q1) q0) of a pair."},
  {"hlift", d_hlift, "Ad:hlift(q0, x1) -> q1", "The discrete horizontal lift of the shape point x1 at q0."},
  {"lift", d_lift, "Ad:lift(xs, q0) -> {q0, q1, ...}",
   "The horizontal lift of the shape polygon xs (a list of points or a matrix of rows) from q0."},
  {"holonomy", d_holonomy, "Ad:holonomy(loop, q0) -> hol",
   "The holonomy of a closed shape polygon from q0: {spatial, body, angle[, axis]}; for R, SO(2) the angle is lifted (counts whole turns)."},
  {"compose", d_compose, "Ad:compose({q0, q1}, {q2, q3}) -> {q0, q}",
   "The extended pair-groupoid composition (q0, A_d(q2, q1) q3), defined when q1 and q2 have the same shape."},
  {"reduce", d_reduce, "Ad:reduce(q0, q1) -> x0, x1, zeta",
   "The reduced pair: shapes and the body representative zeta = g0^-1 A_d(q0, q1) g0 (e on horizontal pairs)."},
  {"unreduce", d_unreduce, "Ad:unreduce(x0, x1, zeta, q0) -> q1", "The pair over (x0, x1) from q0 whose reduction is zeta."},
  {"split", d_split, "Ad:split(q0, q1) -> x0, x1, g",
   "A pair as shape motion and relative group element A_d (the decomposition of geometric control)."},
  {"limit", d_limit, "Ad:limit(q, xdot, xi[, eps = 1e-4]) -> vec",
   "The continuous limit d/de A_d(q, q(e)) at e = 0 by central differences, q(e) = (x + e xdot, g exp(e xi))."},
  {"phase", d_phase, "Ad:phase(traj[, q0]) -> hol, gap",
   "The geometric phase of the shape path sampled by a trajectory, lifted sample to sample: the body transport as a holonomy table, and the gap between its ends (0 for a loop)."},
  {"momentum", d_momentum, "Dm:momentum(q0, q1) -> vec",
   "The discrete momentum J_d(q0, q1) = D2 Ld(q0, q1) . xi_Q(q1) of a discrete mechanical connection."},
  {"set_mu", d_set_mu, "Dm:set_mu(mu) -> Dm",
   "Horizontal at momentum mu (J_d = mu) instead of 0: abelian groups only."},
  {"newton_stats", d_newton_stats, "Dm:newton_stats() -> solves, iterations",
   "How many Newton solves and iterations the discrete mechanical connection has done."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg disc_funcs[] = {
  {"discrete_connection", l_discrete_connection,
   "dm.discrete_connection{from = A[, rule = \"midpoint\"]} | {bundle = B, A = function(x0, x1) ... end} | {bundle = B, rule = \"levi-civita\" | \"trivial\"} | {mesh = M} -> Ad",
   "A discrete connection: from a continuous one by a rule (euler, midpoint, cayley, transport, exact), a user local representation, the Levi-Civita connection of the sphere frames or of a triangle mesh, or the trivial one."},
  {"order_test", l_order_test,
   "dm.order_test(Ad, {ref = \"transport\" | Dref, q = q0, v = {...}, h = {...}[, tol = 1e-13]}) -> defects, slope",
   "Defects |log(A_ref A_d^-1)| at q1 = (x0 + h v, g0) and the fitted slope (order = slope - 1)."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_conn_disc(lua_State *L)
{
  int dm = lua_gettop(L);
  static const luaL_Reg meta[] = {{"__index", dconn_index}, {"__gc", dconn_gc},
                                  {"__close", dconn_gc}, {"__tostring", dconn_tostring},
                                  {"__call", d_call}, {NULL, NULL}};
  dm_newclass(L, DM_DCONN_MT, "discrete_connection", dconn_methods, meta);
  lua_pop(L, 1);
  lua_pushvalue(L, dm);
  dm_register(L, "dm.", disc_funcs);
  lua_settop(L, dm);
}
