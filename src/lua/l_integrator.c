/* l_integrator.c -- dm.integrator(sys, {method=, h=, ...}): options mapped
 * by name through dm_integ_options, user PRK tableaus, states read from
 * tables, one step, the discrete Legendre transforms, DEL steps, discrete
 * momentum and the structure diagnostics (symplecticity defect, time
 * reversal, step Jacobian).  integ:run lives in l_integ_run.c, dm.tableau
 * and integ:order_estimate in l_integ_diag.c.  See l_integ.h. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_integ.h"

/* {======================================================================
 * life cycle
 * ======================================================================= */

static void integ_release(dm_linteg *li)
{
  dm_integrator_free(li->I);
  free(li->buf);
  li->I = NULL;
  li->buf = NULL;
}

static int integ_gc(lua_State *L)
{
  integ_release(luaL_checkudata(L, 1, DM_INTEG_MT));
  return 0;
}

static void build(lua_State *L, dm_linteg *li, const char *fname)
{
  dm_integrator *I;
  dm_err e;
  int st = dm_integrator_new(&li->ls->sys, li->method, &li->opt, &I, &e);
  if (st != DM_OK)
    dm_lua_fail(L, fname, st, &e);
  dm_integrator_free(li->I);
  li->I = I;
  li->gen = li->ls->gen;
}

dm_linteg *dm_linteg_check(lua_State *L, int idx)
{
  dm_linteg *li = luaL_checkudata(L, idx, DM_INTEG_MT);
  if (li->I == NULL)
    luaL_error(L, "attempt to use a closed integrator");
  if (li->ls->sys.lagrangian == NULL)
    luaL_error(L, "attempt to use an integrator whose system was closed");
  if (li->gen != li->ls->gen)
    build(L, li, "integrator (rebuilt after a parameter change)");
  return li;
}

dm_integrator *dm_lua_tointegrator(lua_State *L, int idx)
{
  return dm_linteg_check(L, idx)->I;
}

dm_lsystem *dm_linteg_checksystem(lua_State *L, int idx)
{
  dm_lsystem *ls = dm_lua_tosystem(L, idx);
  if (ls != NULL)
    return ls;
  if (luaL_testudata(L, idx, DM_SYSTEM_MT) != NULL)
    luaL_error(L, "attempt to use a closed system");
  idx = lua_absindex(L, idx);
  if (luaL_getmetafield(L, idx, "__system") != LUA_TNIL) {
    lua_pushvalue(L, idx);
    lua_call(L, 1, 1);
    if ((ls = dm_lua_tosystem(L, -1)) != NULL) {
      lua_replace(L, idx);
      return ls;
    }
    lua_pop(L, 1);
  }
  dm_argexpected(L, idx, "system", luaL_typename(L, idx));
  return NULL;
}

/* dm.integrator(sys, {method=, h=, ...}) */
int dm_lua_integrator(lua_State *L)
{
  if (luaL_getmetafield(L, 1, "__integrator") != LUA_TNIL) {  /* objects making their own */
    lua_insert(L, 1);
    lua_call(L, lua_gettop(L) - 1, 1);
    return 1;
  }
  dm_lsystem *ls = dm_linteg_checksystem(L, 1);
  const char *method;
  double h;
  if (lua_isnoneornil(L, 2)) {
    lua_settop(L, 1);
    lua_newtable(L);
  }
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  dm_linteg *li = lua_newuserdatauv(L, sizeof *li, 2);        /* 3 */
  memset(li, 0, sizeof *li);
  luaL_setmetatable(L, DM_INTEG_MT);
  lua_pushvalue(L, 1);
  lua_setiuservalue(L, 3, 1);
  li->ls = ls;
  dm_linteg_parse(L, 2, "dm.integrator", NULL, &ls->sys, &li->opt, &method, &h);  /* 4: box */
  lua_setiuservalue(L, 3, 2);
  if (strlen(method) >= sizeof li->method)
    return luaL_error(L, "dm.integrator: method name too long");
  strcpy(li->method, method);
  li->h = h;
  if ((li->buf = calloc(10 * ls->n, sizeof *li->buf)) == NULL)
    return luaL_error(L, "out of memory");
  build(L, li, "dm.integrator");
  lua_settop(L, 3);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * states
 * ======================================================================= */

double dm_linteg_h(lua_State *L, dm_linteg *li, int idx)
{
  double h = li->h;
  if (!lua_isnoneornil(L, idx)) {
    h = luaL_checknumber(L, idx);
    if (h == 0.0 || !isfinite(h))
      luaL_argerror(L, idx, "finite non-zero step size expected");
  }
  if (isnan(h))
    luaL_error(L, "no step size: give h in dm.integrator(sys, {h = ...}), set integ.h, or pass "
               "it to this call");
  return h;
}

static void check_finite(lua_State *L, const double *x, size_t n, const char *fname,
                         const char *what)
{
  char num[32];
  for (size_t i = 0; i < n; i++)
    if (!isfinite(x[i])) {
      dm_num_format(num, sizeof num, fabs(x[i]));
      luaL_error(L, "%s: state.%s contains NaN or Inf (component %d = %s)", fname, what,
                 (int)i + 1, num);
    }
}

/* "<fname>: state.<field>" into what (size 96): the label of error
 * messages, built on every call -- by concatenation, which costs a few
 * nanoseconds where snprintf cost ~10% of a per-call step (perf). */
static void state_label(char *what, size_t size, const char *fname, const char *field)
{
  static const char mid[] = ": state.";
  size_t a = strlen(fname), b = strlen(field), k = 0;
  if (a > size - sizeof mid - b - 1)
    a = size > sizeof mid + b + 1 ? size - sizeof mid - b - 1 : 0;
  memcpy(what, fname, a);
  k = a;
  memcpy(what + k, mid, sizeof mid - 1);
  k += sizeof mid - 1;
  if (k + b >= size)
    b = size - k - 1;
  memcpy(what + k, field, b);
  what[k + b] = '\0';
}

/* A reduced state made by red:project carries the mu it was projected at
 * (state.mu: a number, or one per cyclic coordinate); the momentum values
 * are the last parameters of a reduced system (mu_<theta>).  A run at
 * another mu would compute, silently, the motion of another state. */
static void check_state_mu(lua_State *L, const dm_lsystem *ls, int idx, const char *fname)
{
  double mu[16];
  size_t r = 0, a;
  int t = lua_getfield(L, idx, "mu");
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    return;
  }
  if (t == LUA_TNUMBER) {
    mu[r++] = lua_tonumber(L, -1);
  } else if (dm_tovec(L, -1) != NULL || t == LUA_TTABLE) {
    size_t k = dm_tovec(L, -1) ? dm_tovec(L, -1)->size : lua_rawlen(L, -1);
    for (a = 1; a <= k && r < 16; a++) {
      if (lua_geti(L, -1, (lua_Integer)a) != LUA_TNUMBER)
        luaL_error(L, "%s: state.mu[%d] must be a number", fname, (int)a);
      mu[r++] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
  } else {
    luaL_error(L, "%s: state.mu must be a number or a list of numbers, got %s", fname,
               luaL_typename(L, -1));
  }
  lua_pop(L, 1);
  if (r == 0 || r > ls->npar)
    luaL_error(L, "%s: state.mu has %d values, the reduction has %d momenta at most", fname,
               (int)r, (int)ls->npar);
  for (a = 0; a < r; a++) {
    size_t i = ls->npar - r + a;
    double cur = ls->sys.par[i];
    if (mu[a] != cur) {
      char was[DM_NUM_BUFSIZE], now[DM_NUM_BUFSIZE];
      dm_num_format(was, sizeof was, mu[a]);
      dm_num_format(now, sizeof now, cur);
      luaL_error(L, "%s: the state was projected at %s = %s but the reduction's %s is %s: "
                 "red:set{mu = %s} runs the projected motion; without state.mu the shape "
                 "state runs at the current mu", fname, ls->sys.params[i], was,
                 ls->sys.params[i], now, was);
    }
  }
}

void dm_lua_readstate(lua_State *L, dm_lsystem *ls, dm_integrator *I, int idx,
                      const char *fname, double *buf, dm_lstate *s)
{
  size_t n = ls->n;
  char what[96];
  dm_err e;
  int st, have_p;
  idx = lua_absindex(L, idx);
  s->q = buf;
  s->p = buf + n;
  s->v = buf + 2 * n;
  if (lua_type(L, idx) != LUA_TTABLE)
    luaL_error(L, "%s: state {q = ..., p = ...} or {q = ..., v = ...} expected, got %s", fname,
               luaL_typename(L, idx));
  if (ls->sys.kind != NULL && strcmp(ls->sys.kind, "routh") == 0)
    check_state_mu(L, ls, idx, fname);
  if (lua_getfield(L, idx, "q") == LUA_TNIL)
    luaL_error(L, "%s: the state has no field 'q' (coordinates)", fname);
  state_label(what, sizeof what, fname, "q");
  dm_lua_system_readvec(L, ls, -1, what, s->q);
  lua_pop(L, 1);
  check_finite(L, s->q, n, fname, "q");
  s->t = 0.0;
  if (lua_getfield(L, idx, "t") != LUA_TNIL) {
    if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(lua_tonumber(L, -1)))
      luaL_error(L, "%s: state.t must be a finite number, got %s", fname,
                 dm_tolstring(L, -1, NULL));
    s->t = lua_tonumber(L, -1);
  }
  lua_pop(L, 1);
  have_p = lua_getfield(L, idx, "p") != LUA_TNIL;
  if (!have_p) {
    lua_pop(L, 1);
    if (lua_getfield(L, idx, "v") == LUA_TNIL)
      luaL_error(L, "%s: the state needs momenta p or velocities v besides q", fname);
  }
  state_label(what, sizeof what, fname, have_p ? "p" : "v");
  dm_lua_system_readvec(L, ls, -1, what, have_p ? s->p : s->v);
  lua_pop(L, 1);
  check_finite(L, have_p ? s->p : s->v, n, fname, have_p ? "p" : "v");
  if (!have_p) {
    if ((st = dm_integrator_momentum(I, s->q, s->v, s->p, &e)) != DM_OK)
      dm_lua_fail(L, fname, st, &e);
    check_finite(L, s->p, n, fname, "p (from the Legendre map)");
    memcpy(buf + 3 * n, s->v, n * sizeof *buf);
    st = dm_integrator_velocity(I, s->q, s->p, buf + 3 * n, 1, &e);
  } else {
    st = dm_integrator_velocity(I, s->q, s->p, s->v, 0, &e);
  }
  if (st != DM_OK)
    dm_lua_fail(L, fname, st, &e);
}

void dm_linteg_readstate(lua_State *L, dm_linteg *li, int idx, const char *fname,
                         dm_lstate *s)
{
  dm_lua_readstate(L, li->ls, li->I, idx, fname, li->buf, s);
}

void dm_linteg_pushstate(lua_State *L, const dm_linteg *li, double t, const double *q,
                         const double *p, const double *v)
{
  size_t n = li->ls->n;
  lua_createtable(L, 0, 4);
  lua_pushnumber(L, t);
  lua_setfield(L, -2, "t");
  dm_pushvec_copy(L, q, n);
  lua_setfield(L, -2, "q");
  dm_pushvec_copy(L, p, n);
  lua_setfield(L, -2, "p");
  if (v != NULL) {
    dm_pushvec_copy(L, v, n);
    lua_setfield(L, -2, "v");
  }
}

/* }====================================================================== */

/* {======================================================================
 * one step, discrete Legendre transforms, DEL, discrete momentum
 * ======================================================================= */

/* Expected numerical failures (Newton, domain) return nil, message. */
static int soft_fail(lua_State *L, const char *fname, int st, const dm_err *e)
{
  if (st == DM_ENOCONV || st == DM_EDOM || st == DM_ESINGULAR) {
    lua_pushnil(L);
    lua_pushfstring(L, "%s: %s", fname, e->msg[0] ? e->msg : dm_strstatus(st));
    return 2;
  }
  return dm_lua_fail(L, fname, st, e);
}

static int i_step(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  double h = dm_linteg_h(L, li, 3);
  size_t n = li->ls->n;
  double *q1 = li->buf + 4 * n, *p1 = q1 + n, *v1 = p1 + n;
  dm_lstate s;
  dm_err e;
  int st;
  dm_linteg_readstate(L, li, 2, "step", &s);
  if ((st = dm_integrator_step(li->I, h, s.q, s.p, q1, p1, &e)) != DM_OK)
    return soft_fail(L, "step", st, &e);
  memcpy(v1, s.v, n * sizeof *v1);
  if ((st = dm_integrator_velocity(li->I, q1, p1, v1, 1, &e)) != DM_OK)
    return soft_fail(L, "step", st, &e);
  /* variable physical steps: the step's own length */
  dm_linteg_pushstate(L, li, s.t + (dm_integrator_varstep(li->I) ? li->I->dt : h), q1, p1, v1);
  return 1;
}

static int i_defect(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  double h = dm_linteg_h(L, li, 3), d;
  dm_lstate s;
  dm_err e;
  int st;
  dm_linteg_readstate(L, li, 2, "symplecticity_defect", &s);
  if ((st = dm_integrator_symplecticity_defect(li->I, h, s.q, s.p, &d, &e)) != DM_OK)
    return dm_lua_fail(L, "symplecticity_defect", st, &e);
  lua_pushnumber(L, d);
  return 1;
}

static int i_jacobian(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  double h = dm_linteg_h(L, li, 3);
  size_t N = 2 * li->ls->n;
  dm_lstate s;
  dm_err e;
  int st;
  dm_linteg_readstate(L, li, 2, "jacobian", &s);
  gsl_matrix *D = dm_pushmat(L, N, N);
  if ((st = dm_integrator_jacobian(li->I, h, s.q, s.p, D->data, &e)) != DM_OK)
    return dm_lua_fail(L, "jacobian", st, &e);
  return 1;
}

static int i_reversal(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  lua_Integer k = luaL_checkinteger(L, 3);
  double h = dm_linteg_h(L, li, 4), d;
  dm_lstate s;
  dm_err e;
  int st;
  luaL_argcheck(L, k >= 1, 3, "number of steps >= 1 expected");
  dm_linteg_readstate(L, li, 2, "reversal", &s);
  if ((st = dm_integrator_reversal(li->I, h, (long)k, s.q, s.p, &d, &e)) != DM_OK)
    return soft_fail(L, "reversal", st, &e);
  lua_pushnumber(L, d);
  return 1;
}

/* q0, q1 from arguments 2, 3 into buf[0..2n). */
static void read_q0q1(lua_State *L, dm_linteg *li, const char *fname)
{
  char what[64];
  size_t n = li->ls->n;
  snprintf(what, sizeof what, "%s: q0", fname);
  dm_lua_system_readvec(L, li->ls, 2, what, li->buf);
  snprintf(what, sizeof what, "%s: q1", fname);
  dm_lua_system_readvec(L, li->ls, 3, what, li->buf + n);
  check_finite(L, li->buf, 2 * n, fname, "q0/q1");
}

static int i_dlegendre(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  double h = dm_linteg_h(L, li, 4), Ld;
  size_t n = li->ls->n;
  dm_err e;
  int st;
  read_q0q1(L, li, "dlegendre");
  double *p0 = li->buf + 2 * n, *p1 = p0 + n;
  if ((st = dm_integrator_dlegendre(li->I, h, li->buf, li->buf + n, p0, p1, &Ld, &e)) != DM_OK)
    return soft_fail(L, "dlegendre", st, &e);
  dm_pushvec_copy(L, p0, n);
  dm_pushvec_copy(L, p1, n);
  lua_pushnumber(L, Ld);
  return 3;
}

static int i_del_step(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  double h = dm_linteg_h(L, li, 4);
  size_t n = li->ls->n;
  dm_err e;
  int st;
  read_q0q1(L, li, "del_step");
  double *q2 = li->buf + 2 * n;
  if ((st = dm_integrator_del_step(li->I, h, li->buf, li->buf + n, q2, &e)) != DM_OK)
    return soft_fail(L, "del_step", st, &e);
  dm_pushvec_copy(L, q2, n);
  return 1;
}

/* integ:discrete_momentum(q0, q1, coord | xi[, h]) */
static int i_discrete_momentum(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  double h = dm_linteg_h(L, li, 5), J;
  size_t n = li->ls->n;
  double *xi = li->buf + 2 * n;
  dm_err e;
  int st;
  read_q0q1(L, li, "discrete_momentum");
  if (lua_type(L, 4) == LUA_TSTRING) {
    long i = dm_lua_system_coord(li->ls, lua_tostring(L, 4));
    if (i < 0)
      return luaL_error(L, "discrete_momentum: no coordinate '%s' in system '%s'",
                        lua_tostring(L, 4), li->ls->sys.name);
    memset(xi, 0, n * sizeof *xi);
    xi[i] = 1.0;
  } else if (!lua_isnoneornil(L, 4)) {
    dm_lua_system_readvec(L, li->ls, 4, "discrete_momentum: xi", xi);
  } else {
    return luaL_argerror(L, 4, "coordinate name or direction xi expected");
  }
  if ((st = dm_integrator_discrete_momentum(li->I, h, li->buf, li->buf + n, xi, &J, &e)) != DM_OK)
    return soft_fail(L, "discrete_momentum", st, &e);
  lua_pushnumber(L, J);
  return 1;
}

static int i_reset(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  dm_integrator_reset(li->I);
  lua_settop(L, 1);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * fields and metamethods
 * ======================================================================= */

static void push_stats(lua_State *L, const dm_integ_stats *s)
{
  lua_createtable(L, 0, 7);
  lua_pushinteger(L, s->iters);
  lua_setfield(L, -2, "iters");
  lua_pushinteger(L, s->jacs);
  lua_setfield(L, -2, "jacs");
  lua_pushnumber(L, s->residual);
  lua_setfield(L, -2, "residual");
  lua_pushnumber(L, s->tol);
  lua_setfield(L, -2, "tol");
  lua_pushinteger(L, s->steps);
  lua_setfield(L, -2, "steps");
  lua_pushinteger(L, s->iters_total);
  lua_setfield(L, -2, "iters_total");
  lua_pushinteger(L, s->flagged);
  lua_setfield(L, -2, "flagged");
  lua_pushinteger(L, s->fixed_total);
  lua_setfield(L, -2, "fixed_steps");
  if (s->linear != 0) {
    lua_pushstring(L, s->linear == DM_LINEAR_SPARSE ? "sparse" : "dense");
    lua_setfield(L, -2, "linear");
  }
  if (s->nnz > 0) {
    lua_pushinteger(L, (lua_Integer)s->nnz);
    lua_setfield(L, -2, "nnz");
  }
}

static int flag_field(lua_State *L, const dm_linteg *li, const char *k)
{
  static const struct { const char *name; unsigned bit; } flags[] = {
    {"symplectic", DM_INTEG_SYMPLECTIC}, {"symmetric", DM_INTEG_SYMMETRIC},
    {"explicit", DM_INTEG_EXPLICIT}, {"variational", DM_INTEG_VARIATIONAL},
    {"exact_jacobian", DM_INTEG_EXACT_JAC}, {"variable_steps", DM_INTEG_VARSTEP}
  };
  for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++)
    if (strcmp(k, flags[i].name) == 0) {
      lua_pushboolean(L, (li->I->flags & flags[i].bit) != 0);
      return 1;
    }
  return 0;
}

static int integ_index(lua_State *L)
{
  const char *k = dm_checkcstring(L, 2);
  if (lua_getfield(L, lua_upvalueindex(1), k) != LUA_TNIL)
    return 1;
  dm_linteg *li = dm_linteg_check(L, 1);
  if (strcmp(k, "h") == 0) {
    if (isnan(li->h))
      lua_pushnil(L);
    else
      lua_pushnumber(L, li->h);
  } else if (strcmp(k, "method") == 0) {
    lua_pushstring(L, li->method);
  } else if (strcmp(k, "family") == 0) {
    lua_pushstring(L, li->I->type->name);
  } else if (strcmp(k, "stages") == 0) {
    if (li->I->stages > 0)
      lua_pushinteger(L, li->I->stages);
    else
      lua_pushnil(L);
  } else if (strcmp(k, "order") == 0) {
    lua_pushinteger(L, li->I->order);
  } else if (strcmp(k, "system") == 0) {
    lua_getiuservalue(L, 1, 1);
  } else if (strcmp(k, "stats") == 0) {
    push_stats(L, &li->I->stats);
  } else if (strcmp(k, "summary") == 0) {
    lua_pushstring(L, li->I->type->summary);
  } else if (!flag_field(L, li, k)) {
    return luaL_error(L, "integrator has no field or method '%s' (fields: h, method, family, stages, "
                      "order, system, stats, summary, symplectic, symmetric, explicit, "
                      "variational, exact_jacobian, variable_steps)", k);
  }
  return 1;
}

static int integ_newindex(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  const char *k = dm_checkcstring(L, 2);
  double h;
  if (strcmp(k, "h") != 0)
    return luaL_error(L, "integrator field '%s' is read-only (only h can be set)", k);
  h = lua_tonumber(L, 3);
  if (lua_type(L, 3) != LUA_TNUMBER || h == 0.0 || !isfinite(h))
    return luaL_error(L, "integ.h must be a finite non-zero number, got %s",
                      dm_tolstring(L, 3, NULL));
  li->h = h;
  li->opt.h = h;
  return 0;
}

static int integ_tostring(lua_State *L)
{
  dm_linteg *li = luaL_checkudata(L, 1, DM_INTEG_MT);
  luaL_Buffer b;
  char num[DM_NUM_BUFSIZE];
  if (li->I == NULL) {
    lua_pushliteral(L, "<integrator (closed)>");
    return 1;
  }
  luaL_buffinit(L, &b);
  lua_pushfstring(L, "<integrator %s", li->method);
  luaL_addvalue(&b);
  if (dm_integrator_stages_chosen(li->I)) {
    lua_pushfstring(L, " s=%d", li->I->stages);
    luaL_addvalue(&b);
  }
  if (li->I->order > 0) {
    lua_pushfstring(L, " order %d", li->I->order);
    luaL_addvalue(&b);
  }
  if (!isnan(li->h)) {
    dm_num_format(num, sizeof num, li->h);
    luaL_addstring(&b, " h=");
    luaL_addstring(&b, num);
  }
  lua_pushfstring(L, " on '%s' (%s%s%s)>", li->ls->sys.name,
                  (li->I->flags & DM_INTEG_EXPLICIT) ? "explicit" : "implicit",
                  (li->I->flags & DM_INTEG_SYMPLECTIC) ? ", symplectic" : "",
                  (li->I->flags & DM_INTEG_SYMMETRIC) ? ", symmetric" : "");
  luaL_addvalue(&b);
  luaL_pushresult(&b);
  return 1;
}

/* }====================================================================== */

static const luaL_Reg integ_meta[] = {
  {"__gc", integ_gc}, {"__close", integ_gc}, {"__tostring", integ_tostring},
  {"__newindex", integ_newindex}, {NULL, NULL}
};

static const dm_reg integ_methods[] = {
  {"step", i_step, "integ:step(state[, h]) -> state | nil, message",
   "One step from {q=, p=} or {q=, v=} (t optional) to a new state {t, q, p, v}; a Newton "
   "failure returns nil and a message with the residual and tolerance."},
  {"run", dm_linteg_run,
   "integ:run(state, {steps= | t=, every=1, h=, progress=, energy=true, momentum={coords}, chunk=, max_energy_error=, strict=false, warn=true, sink=, sink_every=4096}) -> traj[, message]",
   "Integrate in C to step `steps` or time t, recording every `every` steps a Trajectory with "
   "t, q, p, v, energy and momentum_<coord> columns (cyclic coordinates by default); Ctrl-C, a "
   "failure (Newton, domain) or a runaway (non-finite state or energy; |E - E0| > "
   "max_energy_error max(1, |E0|) when given) returns the trajectory so far (tr.status, "
   "tr.message say how it ended) and a second value, a message saying at which step and time "
   "it stopped, with a warning on stderr (warn = false or dm.config.warn = false: none); "
   "strict = true (or dm.config.strict) makes an early end an error; traj:meta() records "
   "method, stages, h, order, steps, status and message; progress (default: stdout is a "
   "terminal) shows a line on stderr for runs over 0.5 s, chunk= fixes its steps per update.  sink = function(traj) or "
   "\"file.csv\" or \"file.h5\" streams the samples: every sink_every samples (and at the end) the function "
   "gets a trajectory holding them, or they are appended to the file (which appears at the end, "
   "also an early one; an HDF5 file then carries the run's steps, status and message), then dropped, and the run returns the last sample only; a run whose "
   "trajectory would take more than dm.config.memory_limit bytes (default half the physical "
   "memory) prints a warning first; for methods with variable steps (integ.variable_steps) t "
   "is the physical time, a column h holds the step lengths and t = T ends exactly at T."},
  {"symplecticity_defect", i_defect, "integ:symplecticity_defect(state[, h]) -> number",
   "The largest entry of |DPhi^T J DPhi - J| for one step at the state, DPhi by implicit differentiation of the "
   "step equations (exact Jacobians); on a sphere the defect of dx ^ dp restricted to T*S^n "
   "(DPhi along it by central differences, doc/lie.md)."},
  {"jacobian", i_jacobian, "integ:jacobian(state[, h]) -> mat",
   "The 2n x 2n Jacobian D(q1, p1)/D(q0, p0) of one step at the state."},
  {"reversal", i_reversal, "integ:reversal(state, n[, h]) -> number",
   "Take n steps with h, then n with -h, and return the max-norm distance from the start "
   "(round-off for symmetric methods)."},
  {"dlegendre", i_dlegendre, "integ:dlegendre(q0, q1[, h]) -> p0, p1, Ld",
   "Discrete Legendre transforms p0 = -D1 Ld(q0, q1), p1 = D2 Ld(q0, q1) and the discrete "
   "Lagrangian of a variational method."},
  {"del_step", i_del_step, "integ:del_step(q0, q1[, h]) -> q2",
   "One step of the discrete Euler-Lagrange equations in two-point form."},
  {"discrete_momentum", i_discrete_momentum,
   "integ:discrete_momentum(q0, q1, coord | xi[, h]) -> number",
   "The discrete momentum J_d = xi . D2 Ld(q0, q1) along a coordinate or a direction xi "
   "(conserved by DEL when Ld is invariant)."},
  {"order_estimate", dm_linteg_order_estimate,
   "integ:order_estimate{state=, t=, h={h1, h2, ...}[, reference=state]} -> order, errors",
   "Integrate to time t with this integrator's method and options at each step size and fit the "
   "slope of log(error) against log(h); the reference is Gauss 6 (Lobatto 6 with constraints) "
   "at h_min/8 unless given (on a sphere, where neither applies: the method at h_min/64)."},
  {"reset", i_reset, "integ:reset() -> integ",
   "Forget the step history (predictor, compensated-summation carries) and the statistics."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg integ_funcs[] = {
  {"integrator", dm_lua_integrator,
   "dm.integrator(sys | red, {method=\"gauss\", stages=, h=, tol=, maxiter=, simplified=, order=, "
   "scheme=, base=, explicit=, tableau=, adaptive=, epsabs=, epsrel=}) -> integ",
   "A one-step integrator for a system; the system's kind picks the method families "
   "(dm.methods(sys) lists them).  Lagrangian systems: midpoint, gauss, trapezoid "
   "(Stormer-Verlet), lobatto, prk (tableau={a=, b=[, at=, bt=, c=]}, symplecticity checked), "
   "composition, rk4 and gsl:<stepper>.  A Routh reduction (dm.routh) or its reduced system: "
   "gauss | midpoint | lobatto | trapezoid | prk (RSPRK), dr[:gauss | :lobatto] (discrete Routh "
   "equations), classical[:<method>] (SPRK of the classical Routhian with the momentum shift).  "
   "An option that does not apply to the method is an error."},
  {NULL, NULL, NULL, NULL}
};

static const dm_field integ_fields[] = {
  {"h", "integ.h -> number", "The step size (settable: integ.h = 0.01)."},
  {"method", "integ.method -> string", "The method name as given (\"gauss\", \"gsl:rk8pd\", ...)."},
  {"family", "integ.family -> string", "The registered family that implements the method."},
  {"stages", "integ.stages -> integer | nil", "The number of stages, for Runge-Kutta type methods."},
  {"order", "integ.order -> integer", "The classical order of the method."},
  {"system", "integ.system -> sys", "The system being integrated."},
  {"stats", "integ.stats -> table", "Newton statistics of the last step and totals (iters, jacs, residual, tol, steps, iters_total; fixed_steps: steps the fixed-point iteration solved alone; linear = \"dense\" | \"sparse\" and nnz: the Newton matrices)."},
  {"summary", "integ.summary -> string", "One line describing the method family."},
  {"symplectic", "integ.symplectic -> boolean", "True for a symplectic method."},
  {"symmetric", "integ.symmetric -> boolean", "True for a symmetric (time-reversible) method."},
  {"explicit", "integ.explicit -> boolean", "True for an explicit method."},
  {"variational", "integ.variational -> boolean", "True for a variational integrator (a discrete Lagrangian)."},
  {"exact_jacobian", "integ.exact_jacobian -> boolean", "True when Newton uses the exact Jacobian of the step."},
  {"variable_steps", "integ.variable_steps -> boolean",
   "True when the physical length of a step is the method's own (adapt = {...}, sem): runs record "
   "the physical time in t and the step lengths in a column h, and t = T ends exactly at T."},
  {NULL, NULL, NULL}
};

void dm_open_integrator(lua_State *L)
{
  dm_linteg_open_opts(L);
  dm_linteg_open_adapt(L);
  dm_newclass(L, DM_INTEG_MT, "integrator", integ_methods, integ_meta);
  lua_getfield(L, -1, "__methods");
  lua_pushcclosure(L, integ_index, 1);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
  dm_register(L, "dm.", integ_funcs);
  dm_register(L, "dm.", dm_linteg_diag_funcs);
  dm_doc_fields(L, "integrator", integ_fields);
  dm_linteg_doc_options(L);
}
