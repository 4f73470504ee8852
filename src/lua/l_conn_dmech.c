/* l_conn_dmech.c -- the discrete mechanical connection in Lua
 * (src/conn/conn.h):
 *   Dm = dm.discrete_mechanical_connection{bundle = B, Ld = function(q0, q1, p) ... end}
 *   Dm = dm.discrete_mechanical_connection{bundle = B, L = l, h = 0.1, mu = 0.5}
 * Ld is traced once on symbolic points (or the midpoint Ld is built from a
 * reduced Lagrangian l) and compiled; the result is a discrete connection
 * (l_conn_disc.c) with the methods of one.  See l_conn.h. */
#include <config.h>
#include <stdio.h>

#include "lua/l_conn.h"
#include "lua/l_expr.h"

/* symbolic points for Ld: trivial bundles {x = symvec, g = element},
 * others a symvec of nq; nodes into q */
static void push_sympoint(lua_State *L, int bidx, const char *tag, dm_expr *q)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, bidx)->B;
  const char *names[DM_CONN_NQ_MAX];
  char buf[DM_CONN_NQ_MAX][16];
  size_t k;
  bidx = lua_absindex(L, bidx);
  if (dm_conn_bundle_is_trivial(B)) {
    dm_lelem *el;
    lua_createtable(L, 0, 2);
    for (k = 0; k < B->nx; k++) {
      snprintf(buf[k], sizeof buf[k], "x%s_%d", tag, (int)k + 1);
      names[k] = buf[k];
    }
    dm_lua_pushsymvec(L, "x", B->nx, names, NULL, DM_EXPR_SYM);
    for (k = 0; k < B->nx; k++) {
      lua_geti(L, -1, (lua_Integer)k + 1);
      q[k] = dm_lua_toexpr(L, -1);
      lua_pop(L, 1);
    }
    lua_setfield(L, -2, "x");
    dm_lua_bundle_field(L, bidx, "group");
    el = dm_lua_newelem(L, -1, 1);
    for (k = 0; k < B->G->nq; k++) {
      snprintf(buf[0], sizeof buf[0], "g%s_%d", tag, (int)k + 1);
      el->v[k].e = q[B->nx + k] = dm_expr_sym(dm_lua_exprctx(L), buf[0]);
    }
    lua_remove(L, -2);
    lua_setfield(L, -2, "g");
    return;
  }
  for (k = 0; k < B->nq; k++) {
    snprintf(buf[k], sizeof buf[k], "q%s_%d", tag, (int)k + 1);
    names[k] = buf[k];
  }
  dm_lua_pushsymvec(L, "q", B->nq, names, NULL, DM_EXPR_SYM);
  for (k = 0; k < B->nq; k++) {
    lua_geti(L, -1, (lua_Integer)k + 1);
    q[k] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
}

static const char *const dm_keys[] = {"bundle", "Ld", "L", "h", "guess", "params", "tol", "maxit",
                                      "mu", NULL};

static int l_discrete_mechanical(lua_State *L)
{
  const dm_conn_bundle *B;
  dm_conn_dc **D;
  dm_conn_dc *guess = NULL;
  dm_expr *q0, *q1, Ld, par[32], xs[DM_CONN_NX_MAX], xd[DM_CONN_NX_MAX], xi[DM_LIE_DIM_MAX], l;
  double pv[32], tol, mu[DM_LIE_DIM_MAX];
  size_t np = 0, k;
  lua_Integer maxit;
  dm_err e;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_lua_conn_checkkeys(L, 1, "dm.discrete_mechanical_connection", dm_keys);
  lua_getfield(L, 1, "bundle");                       /* 2 */
  B = dm_lua_checkbundle(L, 2)->B;
  lua_getfield(L, 1, "guess");                        /* 3 */
  if (!lua_isnil(L, 3) && (guess = dm_lua_todconn(L, 3)) == NULL)
    luaL_error(L, "dm.discrete_mechanical_connection: guess must be a discrete connection, got %s",
               luaL_typename(L, 3));
  tol = dm_optnumberfield(L, 1, "tol", 1e-14);
  maxit = dm_optintegerfield(L, 1, "maxit", 50);
  if (!(tol > 0.0) || maxit < 1 || maxit > 10000)
    luaL_error(L, "dm.discrete_mechanical_connection: tol must be > 0 and maxit 1..10000");
  q0 = lua_newuserdatauv(L, 2 * (B->nq + 1) * sizeof *q0, 0);   /* 4: scratch */
  q1 = q0 + B->nq + 1;
  lua_getfield(L, 1, "Ld");                           /* 5 */
  lua_getfield(L, 1, "L");                            /* 6 */
  lua_getfield(L, 1, "params");                       /* 7 */
  if (!lua_isnil(L, 5)) {
    const char *names[32];
    if (!lua_isfunction(L, 5))
      luaL_error(L, "dm.discrete_mechanical_connection: Ld must be a function Ld(q0, q1, p), "
                 "got %s", luaL_typename(L, 5));
    if (!lua_isnil(L, 7) && !lua_istable(L, 7))
      luaL_error(L, "dm.discrete_mechanical_connection: params must be a table");
    lua_newtable(L);                                  /* 8: {{name, value}} */
    if (lua_istable(L, 7)) {
      lua_pushnil(L);
      while (lua_next(L, 7) != 0) {
        if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER || np >= 32)
          luaL_error(L, "dm.discrete_mechanical_connection: params must map names to numbers");
        lua_createtable(L, 2, 0);
        lua_pushvalue(L, -3);
        lua_rawseti(L, -2, 1);
        lua_pushvalue(L, -2);
        lua_rawseti(L, -2, 2);
        lua_rawseti(L, 8, (lua_Integer)++np);
        lua_pop(L, 1);
      }
    }
    for (k = 0; k < np; k++) {
      lua_geti(L, 8, (lua_Integer)k + 1);
      lua_geti(L, -1, 1);
      names[k] = lua_tostring(L, -1);
      lua_geti(L, -2, 2);
      pv[k] = lua_tonumber(L, -1);
      lua_pop(L, 3);
    }
    lua_pushvalue(L, 5);
    push_sympoint(L, 2, "0", q0);
    push_sympoint(L, 2, "1", q1);
    dm_lua_pushsymvec(L, "p", np, names, NULL, DM_EXPR_PARAM);
    for (k = 0; k < np; k++) {
      lua_geti(L, -1, (lua_Integer)k + 1);
      par[k] = dm_lua_toexpr(L, -1);
      lua_pop(L, 1);
    }
    dm_lua_trace(L, "the discrete Lagrangian Ld(q0, q1, p)", 3);
    if ((Ld = dm_lua_toexpr(L, -1)) == DM_EXPR_NONE)
      luaL_error(L, "dm.discrete_mechanical_connection: Ld must return an expression or a "
                 "number, got %s", luaL_typename(L, -1));
    lua_pop(L, 1);
  } else {
    double h = dm_optnumberfield(L, 1, "h", 1.0);
    int have;
    if (!dm_conn_bundle_is_trivial(B))
      luaL_error(L, "dm.discrete_mechanical_connection: Ld(q0, q1, p) expected for the %s bundle",
                 B->type->name);
    if (!lua_isnil(L, 6)) {
      if (!lua_isfunction(L, 6))
        luaL_error(L, "dm.discrete_mechanical_connection: L must be a function l(x, xdot, xi, p)");
      if (lua_isnil(L, 7)) {
        lua_newtable(L);
        lua_replace(L, 7);
      }
      dm_lua_trace_lagrangian(L, B, 6, 7, xs, xd, xi, par, pv, &np, &l);
      have = 1;
    } else {
      have = dm_lua_bundle_lagrangian(L, 2, xs, xd, xi, par, pv, &np, &l);
    }
    if (!have)
      luaL_error(L, "dm.discrete_mechanical_connection: give Ld = function(q0, q1, p), or L, or "
                 "a bundle with a Lagrangian");
    push_sympoint(L, 2, "0", q0);
    push_sympoint(L, 2, "1", q1);
    lua_pop(L, 2);
    if (dm_conn_midpoint_ld(dm_lua_exprctx(L), B, q0, q1, xs, xd, xi, l, h, &Ld, &e) != DM_OK)
      return dm_lua_fail(L, "dm.discrete_mechanical_connection", e.status, &e);
  }
  lua_settop(L, 4);
  D = dm_lua_newdconn(L, 2);                          /* 5 */
  if (guess)
    dm_lua_dconn_setfield(L, 5, "guess", 3);
  *D = dm_conn_dc_mechanical(B, dm_lua_exprctx(L), q0, q1, Ld, np, par, pv, guess, tol,
                             (int)maxit, &e);
  if (*D == NULL)
    return dm_lua_fail(L, "dm.discrete_mechanical_connection", e.status, &e);
  lua_getfield(L, 1, "mu");
  if (!lua_isnil(L, -1)) {
    dm_lua_conn_readalgebra(L, lua_gettop(L), B->G->dim, mu);
    if (dm_conn_dc_set_mu(*D, mu, &e) != DM_OK)
      return dm_lua_fail(L, "dm.discrete_mechanical_connection", e.status, &e);
  }
  lua_settop(L, 5);
  return 1;
}

static const dm_reg dmech_funcs[] = {
  {"discrete_mechanical_connection", l_discrete_mechanical,
   "dm.discrete_mechanical_connection{bundle = B, Ld = function(q0, q1, p) ... end | L = l[, h = 1, guess = Ad, params = {...}, tol = 1e-14, maxit = 50, mu = 0]} -> Dm",
   "The discrete mechanical connection of a G-invariant discrete Lagrangian (pairs with zero discrete momentum are horizontal), solved by Newton on the group; L gives the midpoint Ld = h l(xbar, dx/h, log(g0^-1 g1)/h)."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_conn_dmech(lua_State *L)
{
  int dm = lua_gettop(L);
  lua_pushvalue(L, dm);
  dm_register(L, "dm.", dmech_funcs);
  lua_settop(L, dm);
}
