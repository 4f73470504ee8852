/* l_conn.c -- bundles and their points in Lua (src/conn/conn.h):
 *   B = dm.bundle{shape_dim = 2, group = dm.lie.SO2()}        -- S x G
 *   B = dm.bundle{system = sys, acts_on = {"theta"}}          -- from a dm.system
 *   B = dm.bundle{name = "platform", I = 1, m = 1}            -- the catalog (dm.bundles)
 *   S = dm.sphere_frames() ; P = dm.bundle{name = "particles", n = 4}
 *   q = B:point{x = {0.5, 0}, g = 0} ; B:proj(q) ; B:act(g, q) ...
 * the reduced Lagrangian a bundle carries, and the columns of a trajectory
 * that sample its shape.  Points: l_conn_point.c; the readers the
 * connection bindings share: l_conn_args.c.  See l_conn.h. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_conn.h"
#include "lua/l_expr.h"
#include "lua/l_system.h"
#include "core/trajectory.h"

/* {==== bundles ============================================================= */

static dm_lbundle *tobundle(lua_State *L, int idx)
{
  return luaL_testudata(L, idx, DM_BUNDLE_MT);
}

dm_lbundle *dm_lua_checkbundle(lua_State *L, int idx)
{
  dm_lbundle *b = tobundle(L, idx);
  if (b == NULL || b->B == NULL)
    dm_argexpected(L, idx, "bundle (dm.bundle{...})", luaL_typename(L, idx));
  return b;
}

void dm_lua_bundle_field(lua_State *L, int bidx, const char *key)
{
  lua_getiuservalue(L, bidx, 1);
  lua_getfield(L, -1, key);
  lua_remove(L, -2);
}

static int bundle_gc(lua_State *L)
{
  dm_lbundle *b = luaL_checkudata(L, 1, DM_BUNDLE_MT);
  dm_conn_bundle_free(b->B);
  b->B = NULL;
  return 0;
}

/* an empty bundle userdata with its user value table {group = G} (the
 * group userdata at gidx) */
static dm_lbundle *newbundle(lua_State *L, int gidx)
{
  dm_lbundle *b;
  gidx = lua_absindex(L, gidx);
  b = lua_newuserdatauv(L, sizeof *b, 1);
  b->B = NULL;
  luaL_setmetatable(L, DM_BUNDLE_MT);
  lua_newtable(L);
  lua_pushvalue(L, gidx);
  lua_setfield(L, -2, "group");
  lua_setiuservalue(L, -2, 1);
  return b;
}

static void set_uv(lua_State *L, int bidx, const char *key, int vidx)
{
  bidx = lua_absindex(L, bidx);
  vidx = lua_absindex(L, vidx);
  lua_getiuservalue(L, bidx, 1);
  lua_pushvalue(L, vidx);
  lua_setfield(L, -2, key);
  lua_pop(L, 1);
}

/* params: {name = value, ...} (sorted by name) or {{"name", value}, ...}
 * into a list {{name, value}, ...} pushed on the stack */
static void read_params(lua_State *L, int idx, const char *fname)
{
  int n = 0, k;
  lua_newtable(L);
  if (lua_isnoneornil(L, idx))
    return;
  if (!lua_istable(L, idx))
    luaL_error(L, "%s: params must be a table of numbers by name, got %s", fname,
               luaL_typename(L, idx));
  if (luaL_len(L, idx) > 0) {
    for (k = 1; k <= luaL_len(L, idx); k++) {
      lua_geti(L, idx, k);
      if (!lua_istable(L, -1))
        luaL_error(L, "%s: params[%d] must be {\"name\", value}", fname, k);
      lua_geti(L, -1, 1);
      lua_geti(L, -2, 2);
      if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
        luaL_error(L, "%s: params[%d] must be {\"name\", value}", fname, k);
      lua_pop(L, 2);
      lua_rawseti(L, -2, ++n);
    }
    return;
  }
  /* dictionary: collect the names, sort them */
  lua_newtable(L);
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "%s: params must map names to numbers (key %s)", fname,
                 luaL_typename(L, -2));
    lua_pop(L, 1);
    lua_pushvalue(L, -1);
    lua_rawseti(L, -3, ++n);
  }
  lua_getglobal(L, "table");
  lua_getfield(L, -1, "sort");
  lua_pushvalue(L, -3);
  lua_call(L, 1, 0);
  lua_pop(L, 1);
  for (k = 1; k <= n; k++) {
    lua_createtable(L, 2, 0);
    lua_geti(L, -2, k);
    lua_pushvalue(L, -1);
    lua_rawseti(L, -3, 1);
    lua_gettable(L, idx);
    lua_rawseti(L, -2, 2);
    lua_rawseti(L, -3, k);
  }
  lua_pop(L, 1);
}

static const char *const bundle_keys[] = {"shape_dim", "group", "L", "A", "params", "name",
                                          "system", "acts_on", "n", NULL};

/* a trivial bundle over the shape coordinates of a traced system, the
 * group acting by translation on the coordinates acts_on */
static int bundle_from_system(lua_State *L, int o)
{
  dm_lsystem *ls;
  size_t r, k, i, nshape = 0;
  int gidx;
  dm_lbundle *b;
  dm_err e;
  lua_getfield(L, o, "system");
  ls = dm_lua_checktraced(L, -1, "dm.bundle");
  lua_getfield(L, o, "acts_on");
  if (!lua_istable(L, -1) || luaL_len(L, -1) < 1)
    luaL_error(L, "dm.bundle: acts_on must list the coordinates the group moves ({\"theta\"})");
  r = (size_t)luaL_len(L, -1);
  lua_newtable(L);                      /* index list: acts (1-based) */
  for (k = 1; k <= r; k++) {
    long j = -1;
    lua_geti(L, -2, (lua_Integer)k);
    if (lua_type(L, -1) != LUA_TSTRING ||
        (j = dm_lua_system_coord(ls, lua_tostring(L, -1))) < 0)
      luaL_error(L, "dm.bundle: acts_on[%d] is not a coordinate of system '%s'", (int)k,
                 ls->sys.name);
    if (!ls->cyclic[j])
      luaL_error(L, "dm.bundle: the Lagrangian of '%s' depends on %s: the group does not act "
                 "by symmetries", ls->sys.name, lua_tostring(L, -1));
    lua_pop(L, 1);
    lua_pushinteger(L, j + 1);
    lua_rawseti(L, -2, (lua_Integer)k);
  }
  lua_getfield(L, o, "group");
  if (lua_isnil(L, -1)) {
    dm_lie_group **slot;
    lua_pop(L, 1);
    slot = dm_lua_newgroup(L);
    *slot = r == 1 ? dm_lie_so2(&e) : dm_lie_torus(r, &e);
    if (*slot == NULL)
      return dm_lua_fail(L, "dm.bundle", e.status, &e);
  }
  gidx = lua_gettop(L);
  if (dm_lua_checkgroup(L, gidx)->dim != r || !dm_lua_checkgroup(L, gidx)->abelian ||
      dm_lua_checkgroup(L, gidx)->nq != r)
    luaL_error(L, "dm.bundle: the group acting on %d coordinates by translation must be "
               "abelian of dimension %d (R^n, SO(2), T^n), got %s", (int)r, (int)r,
               dm_lua_checkgroup(L, gidx)->name);
  nshape = ls->n - r;
  b = newbundle(L, gidx);
  if ((b->B = dm_conn_bundle_trivial(nshape, dm_lua_checkgroup(L, gidx), &e)) == NULL)
    return dm_lua_fail(L, "dm.bundle", e.status, &e);
  snprintf(b->B->name, sizeof b->B->name, "%s / %s", ls->sys.name, dm_lua_checkgroup(L, gidx)->name);
  set_uv(L, -1, "system", o + 1);
  set_uv(L, -1, "acts", gidx - 1);
  (void)i;
  return 1;
}

static int l_bundle(lua_State *L)
{
  lua_Integer m;
  dm_lbundle *b;
  dm_err e;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  lua_getfield(L, 1, "name");
  if (lua_type(L, -1) == LUA_TSTRING) {
    const char *name = lua_tostring(L, -1);
    if (strcmp(name, "sphere_frames") == 0 || strcmp(name, "sphere frames") == 0) {
      dm_lie_group **slot = dm_lua_newgroup(L);
      if ((*slot = dm_lie_so2(&e)) == NULL)
        return dm_lua_fail(L, "dm.bundle", e.status, &e);
      b = newbundle(L, -1);
      if ((b->B = dm_conn_bundle_sphere_frames(&e)) == NULL)
        return dm_lua_fail(L, "dm.bundle", e.status, &e);
      return 1;
    }
    if (strcmp(name, "particles") == 0) {
      lua_Integer n = dm_optintegerfield(L, 1, "n", 0);
      dm_lie_group **slot = dm_lua_newgroup(L);
      if ((*slot = dm_lie_so3(&e)) == NULL)
        return dm_lua_fail(L, "dm.bundle", e.status, &e);
      b = newbundle(L, -1);
      if (n < 2 || n > DM_CONN_NX_MAX / 3)
        luaL_error(L, "dm.bundle: particles needs n = 2..%d, got %d", DM_CONN_NX_MAX / 3, (int)n);
      if ((b->B = dm_conn_bundle_particles((size_t)n, &e)) == NULL)
        return dm_lua_fail(L, "dm.bundle", e.status, &e);
      return 1;
    }
    if (lua_isnil(L, (lua_getfield(L, 1, "shape_dim"), -1))) {
      /* the catalog: dm.bundles[name](opts) */
      lua_getglobal(L, "require");
      lua_pushliteral(L, "dmech.core");
      lua_call(L, 1, 1);
      lua_getfield(L, -1, "bundles");
      if (!lua_istable(L, -1) || (lua_getfield(L, -1, name), !lua_isfunction(L, -1)))
        luaL_error(L, "dm.bundle: no built-in bundle '%s' (see dm.bundles: platform, cat, "
                   "heisenberg, rotor, orbiter; and sphere_frames, particles)", name);
      lua_pushvalue(L, 1);
      lua_call(L, 1, 1);
      return 1;
    }
    lua_pop(L, 1);
  }
  dm_lua_conn_checkkeys(L, 1, "dm.bundle", bundle_keys);
  lua_getfield(L, 1, "system");
  if (!lua_isnil(L, -1)) {
    lua_pop(L, 2);
    return bundle_from_system(L, 1);
  }
  lua_settop(L, 1);
  lua_getfield(L, 1, "group");                  /* 2 */
  if (dm_lua_togroup(L, 2) == NULL)
    luaL_error(L, "dm.bundle: group must be a Lie group (dm.lie.SO2(), ...), got %s",
               luaL_typename(L, 2));
  m = dm_optintegerfield(L, 1, "shape_dim", -1);
  if (m < 0 || m > DM_CONN_NX_MAX)
    luaL_error(L, "dm.bundle: shape_dim must be 0..%d, got %d", DM_CONN_NX_MAX, (int)m);
  lua_getfield(L, 1, "L");                      /* 3 */
  if (!lua_isnil(L, 3) && !lua_isfunction(L, 3))
    luaL_error(L, "dm.bundle: L must be a function l(x, xdot, xi, p), got %s", luaL_typename(L, 3));
  lua_getfield(L, 1, "params");
  read_params(L, 4, "dm.bundle");               /* 5 */
  b = newbundle(L, 2);                          /* 6 */
  if ((b->B = dm_conn_bundle_trivial((size_t)m, dm_lua_checkgroup(L, 2), &e)) == NULL)
    return dm_lua_fail(L, "dm.bundle", e.status, &e);
  set_uv(L, 6, "L", 3);
  set_uv(L, 6, "params", 5);
  lua_getfield(L, 1, "A");
  if (!lua_isnil(L, -1) && !lua_isfunction(L, -1))
    luaL_error(L, "dm.bundle: A must be a function A(x, p) (the bundle's connection form), got %s",
               luaL_typename(L, -1));
  set_uv(L, 6, "A", -1);
  lua_pop(L, 1);
  lua_getfield(L, 1, "name");
  if (lua_type(L, -1) == LUA_TSTRING)
    snprintf(b->B->name, sizeof b->B->name, "%s", lua_tostring(L, -1));
  lua_pop(L, 1);
  return 1;
}

static int l_sphere_frames(lua_State *L)
{
  lua_settop(L, 0);
  lua_createtable(L, 0, 1);
  lua_pushliteral(L, "sphere_frames");
  lua_setfield(L, 1, "name");
  return l_bundle(L);
}

int dm_lua_bundle_lagrangian(lua_State *L, int bidx, dm_expr *xs, dm_expr *xd, dm_expr *xi,
                             dm_expr *par, double *parval, size_t *npar, dm_expr *l)
{
  dm_lbundle *b = dm_lua_checkbundle(L, bidx);
  const dm_conn_bundle *B = b->B;
  size_t k;
  int top = lua_gettop(L);
  bidx = lua_absindex(L, bidx);
  dm_lua_bundle_field(L, bidx, "system");
  if (!lua_isnil(L, -1)) {
    dm_lsystem *ls = dm_lua_tosystem(L, -1);
    unsigned char acts[256] = {0};
    size_t ns = 0, na = 0;
    dm_lua_bundle_field(L, bidx, "acts");
    for (k = 1; k <= (size_t)luaL_len(L, -1); k++) {
      lua_geti(L, -1, (lua_Integer)k);
      acts[lua_tointeger(L, -1) - 1] = 1;
      xi[na++] = ls->v[lua_tointeger(L, -1) - 1];
      lua_pop(L, 1);
    }
    for (k = 0; k < ls->n; k++)
      if (!acts[k]) {
        xs[ns] = ls->q[k];
        xd[ns++] = ls->v[k];
      }
    if (ls->npar > 32)
      luaL_error(L, "mechanical connection: at most 32 parameters");
    for (k = 0; k < ls->npar; k++) {
      par[k] = ls->par[k];
      parval[k] = ls->sys.par[k];
    }
    *npar = ls->npar;
    *l = ls->L;
    lua_settop(L, top);
    return 1;
  }
  lua_pop(L, 1);
  dm_lua_bundle_field(L, bidx, "L");
  if (lua_isnil(L, -1)) {
    lua_settop(L, top);
    return 0;
  }
  dm_lua_bundle_field(L, bidx, "params");
  dm_lua_trace_lagrangian(L, B, top + 1, top + 2, xs, xd, xi, par, parval, npar, l);
  lua_settop(L, top);
  return 1;
}

void dm_lua_trace_lagrangian(lua_State *L, const dm_conn_bundle *B, int fidx, int pidx,
                             dm_expr *xs, dm_expr *xd, dm_expr *xi, dm_expr *par, double *parval,
                             size_t *npar, dm_expr *l)
{
  const char *xn[DM_CONN_NX_MAX], *dn[DM_CONN_NX_MAX], *gn[DM_LIE_DIM_MAX], *pn[32];
  char names[3][DM_CONN_NX_MAX > DM_LIE_DIM_MAX ? DM_CONN_NX_MAX : DM_LIE_DIM_MAX][16];
  size_t k, nx = B->nx, dim = B->G->dim, np;
  int top = lua_gettop(L);
  fidx = lua_absindex(L, fidx);
  pidx = lua_absindex(L, pidx);
  for (k = 0; k < nx; k++) {
    snprintf(names[0][k], 16, "x%d", (int)k + 1);
    snprintf(names[1][k], 16, "xdot%d", (int)k + 1);
    xn[k] = names[0][k];
    dn[k] = names[1][k];
  }
  for (k = 0; k < dim; k++) {
    snprintf(names[2][k], 16, "xi%d", (int)k + 1);
    gn[k] = names[2][k];
  }
  np = lua_istable(L, pidx) ? (size_t)luaL_len(L, pidx) : 0;
  if (np > 32)
    luaL_error(L, "Lagrangian: at most 32 parameters");
  /* the names stay referenced by the list at pidx while we trace */
  for (k = 0; k < np; k++) {
    lua_geti(L, pidx, (lua_Integer)k + 1);
    lua_geti(L, -1, 1);
    lua_geti(L, -2, 2);
    if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
      luaL_error(L, "Lagrangian: params[%d] must be {\"name\", value}", (int)k + 1);
    pn[k] = lua_tostring(L, -2);
    parval[k] = lua_tonumber(L, -1);
    lua_pop(L, 3);
  }
  lua_pushvalue(L, fidx);
  dm_lua_pushsymvec(L, "x", nx, xn, NULL, DM_EXPR_SYM);
  dm_lua_pushsymvec(L, "xdot", nx, dn, NULL, DM_EXPR_SYM);
  dm_lua_pushsymvec(L, "xi", dim, gn, NULL, DM_EXPR_SYM);
  dm_lua_pushsymvec(L, "p", np, pn, NULL, DM_EXPR_PARAM);
  for (k = 0; k < np; k++) {
    lua_geti(L, -1, (lua_Integer)k + 1);
    par[k] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
  for (k = 0; k < nx; k++) {
    lua_geti(L, -4, (lua_Integer)k + 1);
    xs[k] = dm_lua_toexpr(L, -1);
    lua_geti(L, -4, (lua_Integer)k + 1);
    xd[k] = dm_lua_toexpr(L, -1);
    lua_pop(L, 2);
  }
  for (k = 0; k < dim; k++) {
    lua_geti(L, -2, (lua_Integer)k + 1);
    xi[k] = dm_lua_toexpr(L, -1);
    lua_pop(L, 1);
  }
  dm_lua_trace(L, "the Lagrangian l(x, xdot, xi, p)", 4);
  if ((*l = dm_lua_toexpr(L, -1)) == DM_EXPR_NONE)
    luaL_error(L, "the Lagrangian l(x, xdot, xi, p) must return an expression or a number, "
               "got %s", luaL_typename(L, -1));
  *npar = np;
  lua_settop(L, top);
}

const size_t *dm_lua_phase_cols(lua_State *L, int bidx, int tidx, int q0idx, size_t *buf,
                                double *q0)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, bidx)->B;
  struct dm_traj *T = dm_checktraj(L, tidx);
  const size_t *cols = NULL;
  size_t k;
  bidx = lua_absindex(L, bidx);
  if (!dm_conn_bundle_is_trivial(B))
    luaL_error(L, "phase: needs a trivial bundle S x G, got the %s bundle", B->type->name);
  if (dm_traj_ncoords(T) != B->nx) {
    dm_lsystem *ls;
    dm_lua_bundle_field(L, bidx, "system");
    ls = dm_lua_tosystem(L, -1);
    lua_pop(L, 1);
    if (ls == NULL)
      luaL_error(L, "phase: the trajectory has %d coordinates, the shape space %d", 
                 (int)dm_traj_ncoords(T), (int)B->nx);
    dm_lua_bundle_field(L, bidx, "acts");
    {
      unsigned char acts[256] = {0};
      size_t ns = 0, i;
      for (k = 1; k <= (size_t)luaL_len(L, -1); k++) {
        lua_geti(L, -1, (lua_Integer)k);
        acts[lua_tointeger(L, -1) - 1] = 1;
        lua_pop(L, 1);
      }
      for (i = 0; i < ls->n && ns < B->nx; i++)
        if (!acts[i]) {
          size_t j = dm_traj_find(T, ls->sys.coords[i]);
          if (j == DM_TRAJ_NONE)
            luaL_error(L, "phase: the trajectory has no column '%s'", ls->sys.coords[i]);
          buf[ns++] = j;
        }
    }
    lua_pop(L, 1);
    cols = buf;
  }
  if (q0idx != 0 && !lua_isnoneornil(L, q0idx)) {
    dm_lua_readpoint(L, bidx, q0idx, "phase: q0", q0);
  } else {
    for (k = 0; k < B->nx; k++)
      q0[k] = dm_traj_col(T, cols ? cols[k] : dm_traj_qcol(T, k))[0];
    dm_lie_identity(B->G, q0 + B->nx);
  }
  return cols;
}

/* }==== */

/* {==== bundle methods ====================================================== */

static int b_point(lua_State *L)
{
  dm_lbundle *b = dm_lua_checkbundle(L, 1);
  double q[DM_CONN_NQ_MAX];
  luaL_checktype(L, 2, LUA_TTABLE);
  dm_lua_point_from_table(L, 1, 2, "point", q);
  dm_lua_pushpoint(L, 1, q);
  (void)b;
  return 1;
}

static int b_proj(lua_State *L)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, 1)->B;
  double q[DM_CONN_NQ_MAX], x[DM_CONN_NX_MAX];
  dm_lua_readpoint(L, 1, 2, "proj: q", q);
  dm_conn_proj(B, q, x);
  dm_pushvec_copy(L, x, B->nx);
  return 1;
}

static int b_act(lua_State *L)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, 1)->B;
  double q[DM_CONN_NQ_MAX], g[DM_LIE_NQ_MAX], gq[DM_CONN_NQ_MAX];
  lua_settop(L, 3);
  dm_lua_bundle_field(L, 1, "group");
  dm_lua_readgroupelem(L, -1, 2, "act: g", g);
  dm_lua_readpoint(L, 1, 3, "act: q", q);
  dm_conn_act(B, g, q, gq);
  dm_lua_pushpoint(L, 1, gq);
  return 1;
}

static int b_fiber_diff(lua_State *L)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, 1)->B;
  double q[DM_CONN_NQ_MAX], q2[DM_CONN_NQ_MAX], g[DM_LIE_NQ_MAX], gap;
  dm_err e;
  dm_lua_readpoint(L, 1, 2, "fiber_diff: q", q);
  dm_lua_readpoint(L, 1, 3, "fiber_diff: q2", q2);
  gap = dm_conn_shape_gap(B, q, q2);
  if (!(gap <= 1e-9))
    luaL_error(L, "fiber_diff: q and q2 are not on one fibre (their shapes differ by %f)", gap);
  if (dm_conn_fiber_diff(B, q, q2, g, &e) != DM_OK)
    return dm_lua_fail(L, "fiber_diff", e.status, &e);
  dm_lua_bundle_field(L, 1, "group");
  dm_lua_pushgroupelem(L, -1, g);
  return 1;
}

static int b_section(lua_State *L)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, 1)->B;
  double q[DM_CONN_NQ_MAX], x[DM_CONN_NX_MAX];
  dm_err e;
  dm_lua_readshape(L, B, 2, "section: x", x);
  if (dm_conn_section(B, x, q, &e) != DM_OK)
    return dm_lua_fail(L, "section", e.status, &e);
  dm_lua_pushpoint(L, 1, q);
  return 1;
}

static int b_trivialize(lua_State *L)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, 1)->B;
  double q[DM_CONN_NQ_MAX], x[DM_CONN_NX_MAX], g[DM_LIE_NQ_MAX];
  dm_err e;
  dm_lua_readpoint(L, 1, 2, "trivialize: q", q);
  if (dm_conn_trivialize(B, q, x, g, &e) != DM_OK)
    return dm_lua_fail(L, "trivialize", e.status, &e);
  dm_pushvec_copy(L, x, B->nx);
  dm_lua_bundle_field(L, 1, "group");
  dm_lua_pushgroupelem(L, -1, g);
  lua_remove(L, -2);
  return 2;
}

static int b_tostring(lua_State *L)
{
  dm_lbundle *b = luaL_checkudata(L, 1, DM_BUNDLE_MT);
  if (b->B == NULL) {
    lua_pushliteral(L, "<Bundle (freed)>");
    return 1;
  }
  lua_pushfstring(L, "<Bundle %s (%s): shape dim %d, group %s>", b->B->name, b->B->type->name,
                  (int)b->B->dimS, b->B->G->name);
  return 1;
}

static const dm_reg bundle_methods[] = {
  {"point", b_point, "B:point{x = {...}, g = ...} | {R = R} | {q = {...}} -> point",
   "A point of the bundle: shape coordinates and group element (S x G), a frame R (sphere frames), or coordinates (particles)."},
  {"proj", b_proj, "B:proj(q) -> vec", "The shape point of q (chart coordinates)."},
  {"act", b_act, "B:act(g, q) -> point", "The left action g . q of the structure group."},
  {"fiber_diff", b_fiber_diff, "B:fiber_diff(q, q2) -> g",
   "The group element g with q2 = g . q (q and q2 on one fibre)."},
  {"section", b_section, "B:section(x) -> point",
   "The point of the bundle's section over the shape point x (error when the bundle has none)."},
  {"trivialize", b_trivialize, "B:trivialize(q) -> x, g",
   "The shape point and group element with q = g . section(x)."},
  {NULL, NULL, NULL, NULL}
};

static int bundle_index(lua_State *L)
{
  dm_lbundle *b = luaL_checkudata(L, 1, DM_BUNDLE_MT);
  const char *k = lua_tostring(L, 2);
  if (k != NULL && b->B != NULL) {
    if (strcmp(k, "group") == 0) {
      dm_lua_bundle_field(L, 1, "group");
      return 1;
    }
    if (strcmp(k, "shape_dim") == 0) {
      lua_pushinteger(L, (lua_Integer)b->B->dimS);
      return 1;
    }
    if (strcmp(k, "name") == 0) {
      lua_pushstring(L, b->B->name);
      return 1;
    }
    if (strcmp(k, "kind") == 0) {
      lua_pushstring(L, b->B->type->name);
      return 1;
    }
    if (strcmp(k, "L") == 0 || strcmp(k, "params") == 0 || strcmp(k, "system") == 0) {
      dm_lua_bundle_field(L, 1, k);
      return 1;
    }
  }
  return dm_index_methods(L);
}

/* }==== */

static const dm_reg conn_funcs[] = {
  {"bundle", l_bundle,
   "dm.bundle{shape_dim = m, group = G[, L = l, params = {...}]} | {name = \"platform\", ...} | {system = sys, acts_on = {...}} -> B",
   "A principal bundle: the trivial S x G, a built-in one by name (dm.bundles, sphere_frames, particles), or the shape space of a dm.system whose group moves the coordinates acts_on."},
  {"sphere_frames", l_sphere_frames, "dm.sphere_frames() -> B",
   "The frame bundle SO(3) -> S^2 (p = R e3) with SO(2) turning the frame about p."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_conn(lua_State *L)
{
  int dm = lua_gettop(L);
  static const luaL_Reg bmeta[] = {{"__index", bundle_index}, {"__gc", bundle_gc},
                                   {"__close", bundle_gc}, {"__tostring", b_tostring},
                                   {NULL, NULL}};
  dm_newclass(L, DM_BUNDLE_MT, "B", bundle_methods, bmeta);
  lua_pop(L, 1);
  dm_lua_open_conn_point(L);
  lua_pushvalue(L, dm);
  dm_register(L, "dm.", conn_funcs);
  lua_pop(L, 1);
  lua_settop(L, dm);
  dm_lua_open_conn_cont(L);
  dm_lua_open_conn_disc(L);
  dm_lua_open_conn_dmech(L);
  dm_lua_open_conn_mesh(L);
  lua_settop(L, dm);
  /* the catalog lua/dmech/bundles.lua and dm.plot_convergence
   * (lua/dmech/convergence.lua): installers called with dm */
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.bundles");
  lua_call(L, 1, 1);
  lua_pushvalue(L, dm);
  lua_call(L, 1, 0);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.convergence");
  lua_call(L, 1, 1);
  lua_pushvalue(L, dm);
  lua_call(L, 1, 0);
  lua_settop(L, dm);
}
