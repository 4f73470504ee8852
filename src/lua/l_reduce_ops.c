/* l_reduce_ops.c -- methods of a Routh reduction (see l_reduce.h):
 * red:set, red:project, red:lift, red:reconstruct, red:phase, red:eval,
 * red:defect, red:integrator (red:discrete is in l_reduce_dr.c).  Scratch
 * memory lives in userdata, so an argument error never leaks; integrators
 * are made by dm.integrator (one option parser) and live on the stack. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_reduce.h"
#include "lua/l_conn.h"
#include "lua/l_expr.h"


/* scratch doubles owned by a new userdata (pushed) */
static double *scratch(lua_State *L, size_t n)
{
  double *p = lua_newuserdatauv(L, (n ? n : 1) * sizeof(double), 0);
  memset(p, 0, (n ? n : 1) * sizeof(double));
  return p;
}

/* the same after dropping everything above the first top arguments */
static double *scratch_top(lua_State *L, int top, size_t n)
{
  lua_settop(L, top);
  return scratch(L, n);
}

static dm_lsystem *sys_of(lua_State *L, int idx, int uv)
{
  dm_lsystem *ls;
  lua_getiuservalue(L, idx, uv);
  ls = lua_touserdata(L, -1);
  lua_pop(L, 1);          /* anchored by the reduction */
  if (ls->sys.lagrangian == NULL)
    luaL_error(L, "the reduction's %s system was closed", uv == 2 ? "full" : "reduced");
  return ls;
}

/* {==== integrators for reconstruct and defect ========================== */

/* dm.integrator(red, opts') pushed, its C integrator returned: opts' holds
 * the defaults (method, stages, h from `defaults`, a table index or 0)
 * when the options table at `opts` (or 0) names no method, then every
 * option of `opts` except those in skip.  *h: opts'.h or NAN.  Option
 * errors are the integrator's own. */
static dm_integrator *reduced_integrator(lua_State *L, int self, int opts, int defaults,
                                         const char *const *skip, double *h)
{
  const char *const *k;
  int t, user_method = opts && lua_getfield(L, opts, "method") != LUA_TNIL;
  if (opts)
    lua_pop(L, 1);
  lua_pushcfunction(L, dm_lua_integrator);
  lua_pushvalue(L, self);
  lua_newtable(L);
  t = lua_gettop(L);
  if (defaults && !user_method) {
    lua_pushnil(L);
    while (lua_next(L, defaults) != 0) {
      lua_pushvalue(L, -2);
      lua_insert(L, -2);
      lua_settable(L, t);
    }
  }
  if (opts) {
    lua_pushnil(L);
    while (lua_next(L, opts) != 0) {
      for (k = skip; *k && !(lua_type(L, -2) == LUA_TSTRING && strcmp(*k, lua_tostring(L, -2)) == 0); k++)
        ;
      if (*k) {
        lua_pop(L, 1);
        continue;
      }
      lua_pushvalue(L, -2);
      lua_insert(L, -2);
      lua_settable(L, t);
    }
  }
  *h = lua_getfield(L, t, "h") == LUA_TNUMBER ? lua_tonumber(L, -1) : NAN;
  lua_pop(L, 1);
  lua_call(L, 2, 1);
  return dm_lua_tointegrator(L, -1);
}

/* }====================================================================== */

/* {==== states ============================================================ */

/* Read the full state {q=, p=} | {q=, v=} at idx into q, p (n each). */
static void read_full_state(lua_State *L, dm_lrouth *u, int self, int idx, double *q, double *p,
                            const char *fname)
{
  dm_lsystem *fs = sys_of(L, self, 2);
  dm_routh *red = u->red;
  size_t n = fs->n;
  luaL_checktype(L, idx, LUA_TTABLE);
  if (lua_getfield(L, idx, "q") == LUA_TNIL)
    luaL_error(L, "%s: the full state needs q", fname);
  dm_lua_system_readvec(L, fs, -1, "state.q", q);
  lua_pop(L, 1);
  if (lua_getfield(L, idx, "p") != LUA_TNIL) {
    dm_lua_system_readvec(L, fs, -1, "state.p", p);
  } else {
    double *v = p + n;
    lua_pop(L, 1);
    if (lua_getfield(L, idx, "v") == LUA_TNIL)
      luaL_error(L, "%s: the full state needs p or v", fname);
    dm_lua_system_readvec(L, fs, -1, "state.v", v);
    {
      dm_lag_out o;
      const dm_system *S = dm_routh_full(red);
      double *w = scratch(L, S->work_size / sizeof(double) + 1);
      memset(&o, 0, sizeof o);
      o.Lv = p;
      if (S->lagrangian(S->data, q, v, S->par, DM_LAG_V, &o, w) != 0)
        luaL_error(L, "%s: L is outside its domain at this state", fname);
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
}

/* Read a reduced state {q=x, p=s} | {q=x, v=xdot} at idx into x, s. */
static void read_reduced_state(lua_State *L, dm_lrouth *u, int self, int idx, double *x,
                               double *s_, double *t, const char *fname)
{
  dm_lsystem *rs = sys_of(L, self, 1);
  dm_err e;
  int st;
  luaL_checktype(L, idx, LUA_TTABLE);
  if (lua_getfield(L, idx, "q") == LUA_TNIL)
    luaL_error(L, "%s: the reduced state needs q (the shape coordinates)", fname);
  dm_lua_system_readvec(L, rs, -1, "state.q", x);
  lua_pop(L, 1);
  if (t) {
    *t = 0.0;
    if (lua_getfield(L, idx, "t") != LUA_TNIL)
      *t = luaL_checknumber(L, -1);
    lua_pop(L, 1);
  }
  if (lua_getfield(L, idx, "p") != LUA_TNIL) {
    dm_lua_system_readvec(L, rs, -1, "state.p", s_);
  } else {
    double *xd = s_ + rs->n;
    lua_pop(L, 1);
    if (lua_getfield(L, idx, "v") == LUA_TNIL)
      luaL_error(L, "%s: the reduced state needs p (= dR/dxdot) or v", fname);
    dm_lua_system_readvec(L, rs, -1, "state.v", xd);
    if ((st = dm_routh_momentum(u->red, x, xd, s_, &e)) != DM_OK)
      dm_lua_fail(L, fname, st, &e);
  }
  lua_pop(L, 1);
}

/* A shape point with an optional velocity: {q = x[, v = xdot | p = s]}
 * at idx into x, xd (zeros without v or p; from p by the reduced Legendre
 * map); xd needs room for 2 s (scratch behind it). */
static void read_shape_state(lua_State *L, dm_lrouth *u, int self, int idx, double *x, double *xd,
                             const char *fname)
{
  dm_lsystem *rs = sys_of(L, self, 1);
  size_t s = rs->n;
  char what[64];
  dm_err e;
  int st;
  if (lua_type(L, idx) != LUA_TTABLE || lua_rawlen(L, idx) > 0)
    luaL_error(L, "%s: a reduced state {q = x[, v = xdot | p = s]} expected, got %s", fname,
               lua_type(L, idx) == LUA_TTABLE ? "a list" : luaL_typename(L, idx));
  if (lua_getfield(L, idx, "q") == LUA_TNIL)
    luaL_error(L, "%s: the state needs q (the shape coordinates)", fname);
  snprintf(what, sizeof what, "%s: state.q", fname);
  dm_lua_system_readvec(L, rs, -1, what, x);
  lua_pop(L, 1);
  memset(xd, 0, s * sizeof *xd);
  if (lua_getfield(L, idx, "v") != LUA_TNIL) {
    snprintf(what, sizeof what, "%s: state.v", fname);
    dm_lua_system_readvec(L, rs, -1, what, xd);
  } else if (lua_getfield(L, idx, "p") != LUA_TNIL) {
    snprintf(what, sizeof what, "%s: state.p", fname);
    dm_lua_system_readvec(L, rs, -1, what, xd + s);
    if ((st = dm_routh_velocity(u->red, x, xd + s, xd, &e)) != DM_OK)
      dm_lua_fail(L, fname, st, &e);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

static void push_state(lua_State *L, int with_t, double t, const double *q, const double *p,
                       const double *v, size_t n)
{
  lua_createtable(L, 0, 4);
  if (with_t) {
    lua_pushnumber(L, t);
    lua_setfield(L, -2, "t");
  }
  dm_pushvec_copy(L, q, n);
  lua_setfield(L, -2, "q");
  dm_pushvec_copy(L, p, n);
  lua_setfield(L, -2, "p");
  if (v) {
    dm_pushvec_copy(L, v, n);
    lua_setfield(L, -2, "v");
  }
}

/* }====================================================================== */

/* red:set{name = value, ..., mu = number | {...}}: the reduced system's
 * parameters (the original ones and mu_<theta>), mu for all momenta at
 * once; everything is checked before anything changes.  Through the
 * reduced System, so its refresh hook and generation count apply. */
static int m_set(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  dm_lsystem *rs = sys_of(L, 1, 1);
  double mu[DM_ROUTH_RMAX];
  int has_mu = 0;
  size_t a;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    if (lua_type(L, -2) == LUA_TSTRING && strcmp(lua_tostring(L, -2), "mu") == 0) {
      dm_lrouth_read_mu(L, -1, x->r, mu, "set (mu)");
      has_mu = 1;
    } else {
      if (lua_type(L, -2) != LUA_TSTRING)
        return luaL_error(L, "set: parameter names are strings, got %s", luaL_typename(L, -2));
      dm_lsystem_checkparam(L, rs, -2);
      if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(lua_tonumber(L, -1)))
        return luaL_error(L, "set: parameter '%s' needs a finite number, got %s",
                          lua_tostring(L, -2), luaL_typename(L, -1));
    }
    lua_pop(L, 1);
  }
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    if (strcmp(lua_tostring(L, -2), "mu") != 0)
      dm_lua_system_setparam(L, rs, (size_t)dm_lua_system_param(rs, lua_tostring(L, -2)),
                             lua_tonumber(L, -1));
    lua_pop(L, 1);
  }
  for (a = 0; has_mu && a < x->r; a++)
    dm_lua_system_setparam(L, rs, x->npar + a, mu[a]);
  lua_settop(L, 1);
  return 1;
}

static int m_project(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  size_t n = x->n, s = x->s, r = x->r;
  double *buf = scratch_top(L, 2, 3 * n + 3 * s), *q = buf, *p = q + n, *xx = p + 2 * n, *sx = xx + s;
  double *xd = sx + s, mu[DM_ROUTH_RMAX], th[DM_ROUTH_RMAX], t = 0;
  int with_t, st;
  dm_err e;
  read_full_state(L, u, 1, 2, q, p, "project");
  with_t = lua_getfield(L, 2, "t") != LUA_TNIL;
  if (with_t)
    t = luaL_checknumber(L, -1);
  lua_pop(L, 1);
  if ((st = dm_routh_project(u->red, q, p, xx, sx, mu, th, &e)) != DM_OK)
    return dm_lua_fail(L, "project", st, &e);
  /* the reduced state only means something at the state's own mu: the
   * reduction takes it (a run from the returned state at another mu would
   * silently compute a different motion) */
  if ((st = dm_routh_set_mu(u->red, mu, &e)) != DM_OK)
    return dm_lua_fail(L, "project", st, &e);
  sys_of(L, 1, 1)->gen++;
  if ((st = dm_routh_velocity(u->red, xx, sx, xd, &e)) != DM_OK)   /* Mtilde: mu-free */
    return dm_lua_fail(L, "project", st, &e);
  push_state(L, with_t, t, xx, sx, xd, s);
  dm_lrouth_push_numbers(L, mu, r);      /* the state remembers its mu: runs check it */
  lua_setfield(L, -2, "mu");
  dm_lrouth_push_numbers(L, mu, r);
  dm_lrouth_push_numbers(L, th, r);
  return 3;
}

static int m_lift(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  size_t n = x->n, s = x->s;
  double *buf = scratch_top(L, 3, 3 * n + 3 * s), *q = buf, *p = q + n, *v = p + n, *xx = v + n;
  double *sx = xx + s, th[DM_ROUTH_RMAX], t = 0;
  dm_err e;
  int st;
  read_reduced_state(L, u, 1, 2, xx, sx, &t, "lift");
  dm_lrouth_read_mu(L, 3, x->r, th, "lift (theta)");
  if ((st = dm_routh_lift_state(u->red, th, xx, sx, q, p, v, &e)) != DM_OK)
    return dm_lua_fail(L, "lift", st, &e);
  push_state(L, 1, t, q, p, v, n);
  return 1;
}

/* defaults {method =, stages =, h =} from the run that made traj (pushed) */
static void run_defaults(lua_State *L, const dm_traj *rt)
{
  const char *m = dm_traj_meta_get(rt, "method");
  double x;
  lua_createtable(L, 0, 3);
  if (m != NULL) {
    lua_pushstring(L, m);
    lua_setfield(L, -2, "method");
  }
  if (dm_traj_meta_number(rt, "stages", &x)) {
    lua_pushinteger(L, (lua_Integer)x);
    lua_setfield(L, -2, "stages");
  }
  if (dm_traj_meta_number(rt, "h", &x)) {
    lua_pushnumber(L, x);
    lua_setfield(L, -2, "h");
  }
}

static int m_reconstruct(lua_State *L)
{
  static const char *const skip[] = {"theta", NULL};
  dm_lrouth *u = dm_lrouth_check(L, 1);
  dm_traj *rt = dm_checktraj(L, 2);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  dm_integrator *I;
  dm_traj **slot, *out = NULL;
  double th[DM_ROUTH_RMAX], h;
  int st, opts = lua_isnoneornil(L, 3) ? 0 : 3;
  dm_err e;
  if (opts)
    luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  run_defaults(L, rt);                                          /* 4 */
  I = reduced_integrator(L, 1, opts, 4, skip, &h);              /* 5 */
  if (isnan(h))
    h = 0.0;
  if (opts)
    lua_getfield(L, 3, "theta");
  else
    lua_pushnil(L);
  dm_lrouth_read_mu(L, -1, x->r, th, "reconstruct (theta)");
  slot = dm_newtraj(L);
  st = dm_routh_reconstruct(u->red, I, h, rt, th, &out, &e);
  *slot = out;
  if (st != DM_OK && st != DM_EINTR)
    return dm_lua_fail(L, "red:reconstruct", st, &e);
  if (st == DM_EINTR) {
    lua_pushstring(L, e.msg);
    return 2;
  }
  return 1;
}

static int m_phase(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  dm_traj *loop = dm_checktraj(L, 2);
  size_t r = dm_routh_exprs_get(u->red)->r;
  double dyn[DM_ROUTH_RMAX], geo[DM_ROUTH_RMAX], gap;
  dm_err e;
  int st;
  if (!lua_isnoneornil(L, 3)) {
    /* the geometric part through a connection object (any group,
     * non-abelian included): its phase method on the same loop */
    if (dm_lua_toconn(L, 3) == NULL && dm_lua_todconn(L, 3) == NULL)
      return dm_argexpected(L, 3, "connection (continuous or discrete)", luaL_typename(L, 3));
    lua_settop(L, 3);
    lua_getfield(L, 3, "phase");
    lua_pushvalue(L, 3);
    lua_pushvalue(L, 2);
    lua_call(L, 2, 2);                        /* 4: hol, 5: gap */
    if (!dm_routh_is_mechanical(u->red)) {
      lua_pushnil(L);
      lua_insert(L, 4);
      return 3;
    }
  }
  st = dm_routh_phase(u->red, loop, dyn, geo, &gap, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, "phase", st, &e);
  dm_lrouth_push_numbers(L, dyn, r);
  if (lua_gettop(L) >= 6) {
    lua_insert(L, 4);                         /* dyn, hol, gap */
    return 3;
  }
  dm_lrouth_push_numbers(L, geo, r);
  lua_pushnumber(L, gap);
  return 3;
}

/* red:connection(): the mechanical connection A = I^-1 M_theta,x as a
 * connection object on shape x T^r (SO(2) for one cyclic coordinate) */
static int m_connection(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  const dm_system *sys = dm_routh_system(u->red);
  dm_expr par[64];
  dm_lie_group **slot;
  size_t k;
  dm_err e;
  if (!dm_routh_is_mechanical(u->red))
    return luaL_error(L, "connection: L is not mechanical, there is no mechanical connection");
  if (x->npar > 64)
    return luaL_error(L, "connection: at most 64 parameters");
  for (k = 0; k < x->npar; k++)
    par[k] = dm_expr_param(dm_lua_exprctx(L), sys->params[k]);
  slot = dm_lua_newgroup(L);
  if ((*slot = x->r == 1 ? dm_lie_so2(&e) : dm_lie_torus(x->r, &e)) == NULL)
    return dm_lua_fail(L, "connection", e.status, &e);
  dm_lua_push_conn_exprs(L, -1, sys->name, x->s, x->x, x->A, x->npar, par, sys->params,
                         sys->par);
  return 1;
}

static void push_mat(lua_State *L, const double *a, size_t rows, size_t cols)
{
  gsl_matrix *M;
  size_t i, j;
  if (rows == 1 || cols == 1) {
    dm_lrouth_push_numbers(L, a, rows * cols);
    return;
  }
  M = dm_pushmat(L, rows, cols);
  for (i = 0; i < rows; i++)
    for (j = 0; j < cols; j++)
      gsl_matrix_set(M, i, j, a[i * cols + j]);
}

static int m_eval(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  size_t r = x->r, s = x->s;
  double *buf = scratch_top(L, 2, 3 * s + 2 * r * r + 2 * r * s + 2 * r + s + 2 * s * s);
  double *xx = buf, *xd = xx + s, *I = xd + s, *Ii = I + r * r, *A = Ii + r * r, *w = A + r * s;
  double *muA = w + r, *Mt = muA + s, *B = Mt + s * s, *thd = B + s * s;
  dm_routh_vals v;
  dm_err e;
  int st;
  read_shape_state(L, u, 1, 2, xx, xd, "eval");
  if (!dm_routh_is_mechanical(u->red)) {
    memset(&v, 0, sizeof v);
    v.thetadot = thd;
    if ((st = dm_routh_eval(u->red, xx, xd, &v, &e)) != DM_OK)
      return dm_lua_fail(L, "eval", st, &e);
    lua_createtable(L, 0, 2);
    dm_lrouth_push_numbers(L, thd, r); lua_setfield(L, -2, "thetadot");
    lua_pushnumber(L, v.Rc); lua_setfield(L, -2, "classical");
    return 1;
  }
  v.I = I; v.Iinv = Ii; v.A = A; v.Iinv_mu = w; v.muA = muA; v.Mtilde = Mt; v.B = B;
  v.thetadot = thd;
  if ((st = dm_routh_eval(u->red, xx, xd, &v, &e)) != DM_OK)
    return dm_lua_fail(L, "eval", st, &e);
  lua_createtable(L, 0, 13);
  push_mat(L, I, r, r); lua_setfield(L, -2, "I");
  push_mat(L, Ii, r, r); lua_setfield(L, -2, "Iinv");
  if (r == 1)
    dm_pushvec_copy(L, A, s);
  else
    push_mat(L, A, r, s);
  lua_setfield(L, -2, "A");
  dm_lrouth_push_numbers(L, w, r); lua_setfield(L, -2, "Iinv_mu");
  dm_pushvec_copy(L, muA, s); lua_setfield(L, -2, "muA");
  push_mat(L, Mt, s, s); lua_setfield(L, -2, "Mtilde");
  push_mat(L, B, s, s); lua_setfield(L, -2, "B");
  dm_lrouth_push_numbers(L, thd, r); lua_setfield(L, -2, "thetadot");
  lua_pushnumber(L, v.detI); lua_setfield(L, -2, "detI");
  lua_pushnumber(L, v.V); lua_setfield(L, -2, "V");
  lua_pushnumber(L, v.Vmu); lua_setfield(L, -2, "amended");
  lua_pushnumber(L, v.R); lua_setfield(L, -2, "routhian");
  lua_pushnumber(L, v.Rc); lua_setfield(L, -2, "classical");
  return 1;
}

static int m_defect(lua_State *L)
{
  static const char *const skip[] = {NULL};
  dm_lrouth *u = dm_lrouth_check(L, 1);
  const dm_routh_exprs *x = dm_routh_exprs_get(u->red);
  size_t s = x->s;
  double *buf = scratch_top(L, 3, 3 * s), h, def;
  dm_integrator *I;
  dm_err e;
  int st;
  read_reduced_state(L, u, 1, 2, buf, buf + s, NULL, "defect");
  luaL_checktype(L, 3, LUA_TTABLE);
  I = reduced_integrator(L, 1, 3, 0, skip, &h);
  if (isnan(h))
    return luaL_error(L, "defect: give the step h in the options");
  if ((st = dm_routh_symplecticity_defect(I, h, buf, buf + s, &def, &e)) != DM_OK)
    return dm_lua_fail(L, "defect", st, &e);
  lua_pushnumber(L, def);
  return 1;
}

void dm_lrouth_integrator(lua_State *L, int idx, int opts)
{
  idx = lua_absindex(L, idx);
  if (opts)
    opts = lua_absindex(L, opts);
  lua_pushcfunction(L, dm_lua_integrator);
  lua_pushvalue(L, idx);
  if (opts)
    lua_pushvalue(L, opts);
  else
    lua_pushnil(L);
  lua_call(L, 2, 1);
}

static int m_integrator(lua_State *L)
{
  dm_lrouth_check(L, 1);
  dm_lrouth_integrator(L, 1, lua_isnoneornil(L, 2) ? 0 : 2);
  return 1;
}

const dm_reg dm_lrouth_methods[] = {
  {"set", m_set, "red:set{mu = number | {...}, name = value, ...} -> red",
   "Change the momentum value (mu: one per cyclic coordinate) and parameters of the reduction "
   "(red.params: the original ones and mu_<theta>), all checked first, without re-deriving anything."},
  {"project", m_project, "red:project{q=, p= | v= [, t=]} -> reduced_state, mu, theta",
   "Project a full state: x = shape part, s = p_x - mu^T A(x), mu = p_theta (the state's own), theta; "
   "the reduced state is {q = x, p = s, v = xdot}.  The reduction takes the state's mu (red.mu "
   "changes), so a reduced run from the returned state computes the motion of that state."},
  {"lift", m_lift, "red:lift(reduced_state[, theta]) -> {t=, q=, p=, v=}",
   "The full state over a reduced state (x, s) with the current mu: p_theta = mu, p_x = s + mu^T A, "
   "thetadot = I^-1 mu - A xdot."},
  {"reconstruct", m_reconstruct,
   "red:reconstruct(traj[, {theta=, method=, stages=, h=}]) -> trajectory",
   "The full trajectory over a reduced one: theta advanced by the reduced integrator's group "
   "increments between samples (Hamiltonian side for RSPRK, psi_mu for dr and classical); method, "
   "stages and h default to the run that made traj."},
  {"connection", m_connection, "red:connection() -> A",
   "The mechanical connection of the reduction as a connection object (dm.connection) on shape x SO(2) or T^r, for discrete rules, curvature and holonomy."},
  {"phase", m_phase, "red:phase(loop[, connection]) -> dynamic, geometric, gap",
   "Split the group advance over a (closed) shape loop into the dynamic part sum dt I^-1 mu and the "
   "geometric part -sum A(xbar) dx (midpoint rule); gap is the loop's closure defect.  With a "
   "connection object (any group, non-abelian too) the geometric part is its phase: a holonomy table."},
  {"eval", m_eval, "red:eval{q = x[, v = xdot | p = s]} -> {I=, Iinv=, A=, B=, Mtilde=, amended=, routhian=, ...}",
   "Numerical values of the derived objects at a reduced state (xdot = 0 without v or p) with the current mu."},
  {"discrete", dm_lrouth_discrete,
   "red:discrete{method = \"midpoint\" | \"gauss\" | \"lobatto\", stages =, h =} -> discrete",
   "The discrete Routh equations of the midpoint or Galerkin discrete Lagrangian of the full "
   "system in two-point form: psi_mu, the reduced discrete Lagrangian Lhat, its Legendre "
   "transforms, the DR residual and solve, reconstruction of tangent vectors."},
  {"defect", m_defect, "red:defect(reduced_state, {method=, stages=, h=}) -> number",
   "Non-canonical symplecticity defect |DPhi^T W(x1) DPhi - W(x0)| of one reduced step, "
   "W = [[-B, I], [-I, 0]] (the form Omega_S - beta_mu)."},
  {"integrator", m_integrator, "red:integrator{method=, stages=, h=, ...} -> integrator",
   "Same as dm.integrator(red, opts): RSPRK, dr or classical on the reduced system."},
  {NULL, NULL, NULL, NULL}
};
