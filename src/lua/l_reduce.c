/* l_reduce.c -- automatic Routh reduction from Lua (src/reduce/routh.h):
 *
 *   red = dm.routh(sys, {cyclic = {"theta"}, mu = 1.1})
 *   print(red.A, red.beta, red.amended, red.routhian)   -- derived formulas
 *   local I = dm.integrator(red, {method = "gauss", stages = 2, h = 0.05})
 *   local rt = I:run(red:project{q = q0, v = v0}, {steps = 1000})
 *   local full = red:reconstruct(rt, {theta = 0})
 *
 * A Routh reduction is a userdata "dmech.routh" holding the dm_routh, whose
 * owner is the reduced System userdata (user value 1; its free_data frees
 * the dm_routh, so integrators, which anchor their System, keep it alive);
 * user value 2 is the original System.  The metatable's __system gives
 * dm.integrator the reduced System, whose kind ("routh") selects the
 * reduced integrator families: "gauss" is RSPRK, "dr" the discrete Routh
 * equations, "classical" the SPRK of the classical Routhian.  Formulas are expression userdata; the connection,
 * the magnetic 2-form and matrices are Lua tables of expressions whose
 * tostring shows the form (e.g. "(m2*...)*dr1 + ...").  No numerics here. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_reduce.h"

static void routh_sys_free(dm_system *s)
{
  dm_routh_free(s->data);
  s->data = NULL;
}

/* 1 when the System in user value uv of the reduction at idx is closed */
static int closed_sys(lua_State *L, int idx, int uv)
{
  dm_lsystem *ls;
  int closed;
  lua_getiuservalue(L, idx, uv);
  ls = luaL_testudata(L, -1, DM_SYSTEM_MT);
  closed = ls == NULL || ls->sys.lagrangian == NULL;
  lua_pop(L, 1);
  return closed;
}

dm_lrouth *dm_lrouth_check(lua_State *L, int idx)
{
  dm_lrouth *u = luaL_checkudata(L, idx, DM_ROUTH_MT);
  idx = lua_absindex(L, idx);
  if (u->red != NULL && closed_sys(L, idx, 1))
    u->red = NULL;                /* freed with its reduced system */
  if (u->red == NULL)
    luaL_error(L, "attempt to use a closed Routh reduction");
  return u;
}

int dm_lrouth_isopen(lua_State *L, int idx)
{
  dm_lrouth *u = luaL_testudata(L, idx, DM_ROUTH_MT);
  idx = lua_absindex(L, idx);
  if (u == NULL)
    return 0;
  if (closed_sys(L, idx, 1))
    u->red = NULL;
  return u->red != NULL;
}

/* __close: close the reduced System, which owns the reduction (its
 * integrators then refuse to run); idempotent */
static int r_close(lua_State *L)
{
  dm_lrouth *u = luaL_checkudata(L, 1, DM_ROUTH_MT);
  lua_getiuservalue(L, 1, 1);
  if (luaL_testudata(L, -1, DM_SYSTEM_MT) != NULL) {
    lua_replace(L, 1);
    lua_settop(L, 1);
    dm_lsystem_gc(L);
  }
  u->red = NULL;
  return 0;
}

/* {======================================================================
 * dm.routh
 * ======================================================================= */

static size_t read_cyclic(lua_State *L, const dm_lsystem *ls, int o, size_t *cyc)
{
  size_t r = 0, k, len;
  int t = lua_getfield(L, o, "cyclic");
  if (t == LUA_TSTRING) {
    lua_createtable(L, 1, 0);
    lua_insert(L, -2);
    lua_rawseti(L, -2, 1);
  } else if (t != LUA_TTABLE) {
    luaL_error(L, "dm.routh: option 'cyclic' must name the cyclic coordinates ({\"theta\"}), got %s",
               luaL_typename(L, -1));
  }
  len = lua_rawlen(L, -1);
  if (len == 0 || len > DM_ROUTH_RMAX)
    luaL_error(L, "dm.routh: 1 to %d cyclic coordinates expected, got %d", DM_ROUTH_RMAX, (int)len);
  for (k = 1; k <= len; k++) {
    long i;
    if (lua_rawgeti(L, -1, (lua_Integer)k) != LUA_TSTRING)
      luaL_error(L, "dm.routh: cyclic[%d] must be a coordinate name, got %s", (int)k,
                 luaL_typename(L, -1));
    i = dm_lua_system_coord(ls, lua_tostring(L, -1));
    if (i < 0) {
      const char *bad = lua_tostring(L, -1);
      luaL_error(L, "dm.routh: no coordinate '%s' in system '%s' (coordinates: %s)", bad,
                 ls->sys.name, dm_lsystem_names(L, ls->sys.coords, ls->n));
    }
    for (size_t j = 0; j < r; j++)
      if (cyc[j] == (size_t)i)
        luaL_error(L, "dm.routh: cyclic coordinate '%s' is listed twice (cyclic[%d] and "
                   "cyclic[%d])", lua_tostring(L, -1), (int)j + 1, (int)k);
    cyc[r++] = (size_t)i;
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return r;
}

/* mu: a number (r = 1), a list / vec of r numbers, or nil (zeros) */
void dm_lrouth_read_mu(lua_State *L, int idx, size_t r, double *mu, const char *fname)
{
  size_t a;
  idx = lua_absindex(L, idx);
  for (a = 0; a < r; a++)
    mu[a] = 0.0;
  if (lua_isnoneornil(L, idx))
    return;
  if (lua_type(L, idx) == LUA_TNUMBER) {
    if (r != 1)
      luaL_error(L, "%s: mu needs %d values (one per cyclic coordinate)", fname, (int)r);
    mu[0] = lua_tonumber(L, idx);
  } else {
    gsl_vector *v;
    lua_pushvalue(L, idx);
    v = dm_checkvector(L, lua_gettop(L), r);
    for (a = 0; a < r; a++)
      mu[a] = gsl_vector_get(v, a);
    lua_pop(L, 1);
  }
  for (a = 0; a < r; a++)
    if (!isfinite(mu[a]))
      luaL_error(L, "%s: mu must be finite", fname);
}

static const char *const routh_keys[] = {"cyclic", "mu", "native", NULL};

static void check_keys(lua_State *L, int o, const char *const *keys, const char *fname)
{
  lua_pushnil(L);
  while (lua_next(L, o) != 0) {
    const char *const *k;
    int ok = 0;
    if (lua_type(L, -2) == LUA_TSTRING)
      for (k = keys; *k && !ok; k++)
        ok = strcmp(*k, lua_tostring(L, -2)) == 0;
    if (!ok) {
      lua_pop(L, 1);
      luaL_error(L, "%s: unknown option %s", fname, dm_tolstring(L, -1, NULL));
    }
    lua_pop(L, 1);
  }
}

static int l_routh(lua_State *L)
{
  dm_lsystem *ls = dm_lua_checktraced(L, 1, "dm.routh"), *rs;
  dm_routh_spec sp;
  dm_routh *red = NULL;
  dm_lrouth *u;
  size_t cyc[DM_ROUTH_RMAX];
  double mu[DM_ROUTH_RMAX];
  dm_err e;
  int st, native;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  check_keys(L, 2, routh_keys, "dm.routh");
  memset(&sp, 0, sizeof sp);
  sp.r = read_cyclic(L, ls, 2, cyc);
  lua_getfield(L, 2, "mu");
  dm_lrouth_read_mu(L, -1, sp.r, mu, "dm.routh");
  lua_pop(L, 1);
  native = dm_lua_native_mode(L);
  if (lua_getfield(L, 2, "native") != LUA_TNIL) {
    native = lua_type(L, -1) == LUA_TSTRING ? dm_native_mode_parse(lua_tostring(L, -1)) : -1;
    if (native < 0)
      luaL_error(L, "dm.routh: native must be \"auto\", \"always\" or \"never\"");
  }
  lua_settop(L, 2);
  u = lua_newuserdatauv(L, sizeof *u, 2);                     /* 3 */
  u->red = NULL;
  luaL_setmetatable(L, DM_ROUTH_MT);
  rs = dm_lua_system_new(L);                                  /* 4 */
  sp.name = ls->sys.name;
  sp.n = ls->n;
  sp.q = ls->q;
  sp.v = ls->v;
  sp.npar = ls->npar;
  sp.par = ls->par;
  sp.par_values = ls->sys.par;
  sp.coord_names = ls->sys.coords;
  sp.param_names = ls->sys.params;
  sp.L = ls->L;
  sp.force = ls->force;
  sp.m = ls->m;
  sp.constraints = ls->constr;
  sp.cyclic = cyc;
  sp.mu = mu;
  sp.native = native;
  st = dm_routh_derive(dm_lua_exprctx(L), &sp, &red, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, "dm.routh", st, &e);
  rs->sys = *dm_routh_system(red);          /* the System owns red from here on */
  rs->sys.free_data = routh_sys_free;
  u->red = red;
  dm_lua_system_finish(L, rs, NULL);
  lua_setiuservalue(L, 3, 1);
  lua_pushvalue(L, 1);
  lua_setiuservalue(L, 3, 2);
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * formulas as values
 * ======================================================================= */

static int is_zero(dm_expr_ctx *c, dm_expr e)
{
  double v;
  return dm_expr_is_const(c, e, &v) && v == 0.0;
}

static void add_expr(lua_State *L, luaL_Buffer *b, dm_expr e)
{
  char *s = dm_expr_to_string(dm_lua_exprctx(L), e, 0, NULL);
  luaL_addstring(b, s ? s : "?");
  free(s);
}

static int const_string(lua_State *L)
{
  lua_pushvalue(L, lua_upvalueindex(1));
  return 1;
}

/* Give the table at the top a metatable whose __tostring returns the
 * string on top of it (popped). */
static void set_tostring(lua_State *L, const char *name)
{
  lua_createtable(L, 0, 2);
  lua_insert(L, -2);
  lua_pushcclosure(L, const_string, 1);
  lua_setfield(L, -2, "__tostring");
  lua_pushstring(L, name);
  lua_setfield(L, -2, "__name");
  lua_setmetatable(L, -2);
}

static void push_list(lua_State *L, const dm_expr *e, size_t n)
{
  size_t i;
  lua_createtable(L, (int)n, 0);
  for (i = 0; i < n; i++) {
    dm_lua_pushexpr(L, e[i]);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
}

/* the string of the one-form sum_i e_i dx_i (e: s expressions), pushed */
static void form1_string(lua_State *L, const dm_routh *red, const dm_expr *e)
{
  const dm_routh_exprs *x = dm_routh_exprs_get(red);
  const dm_system *sys = dm_routh_system(red);
  dm_expr_ctx *c = dm_lua_exprctx(L);
  luaL_Buffer b;
  size_t i, k = 0;
  luaL_buffinit(L, &b);
  for (i = 0; i < x->s; i++) {
    if (is_zero(c, e[i]))
      continue;
    if (k++)
      luaL_addstring(&b, " + ");
    luaL_addstring(&b, "(");
    add_expr(L, &b, e[i]);
    luaL_addstring(&b, ")*d");
    luaL_addstring(&b, sys->coords[i]);
  }
  if (k == 0)
    luaL_addstring(&b, "0");
  luaL_pushresult(&b);
}

static void push_form1(lua_State *L, const dm_routh *red, const dm_expr *e)
{
  push_list(L, e, dm_routh_exprs_get(red)->s);
  form1_string(L, red, e);
  set_tostring(L, "routh 1-form");
}

/* A: for r = 1 the 1-form itself, else a list of r 1-forms */
static void push_connection(lua_State *L, const dm_routh *red)
{
  const dm_routh_exprs *x = dm_routh_exprs_get(red);
  const dm_system *sys = dm_routh_system(red);
  size_t a;
  luaL_Buffer b;
  if (x->r == 1) {
    push_form1(L, red, x->A);
    return;
  }
  lua_createtable(L, (int)x->r, 0);
  for (a = 0; a < x->r; a++) {
    push_form1(L, red, x->A + a * x->s);
    lua_rawseti(L, -2, (lua_Integer)a + 1);
  }
  luaL_buffinit(L, &b);
  for (a = 0; a < x->r; a++) {
    if (a)
      luaL_addstring(&b, "; ");
    luaL_addstring(&b, sys->params[x->npar + a]);
    luaL_addstring(&b, " direction: ");
    form1_string(L, red, x->A + a * x->s);
    luaL_addvalue(&b);
  }
  luaL_pushresult(&b);
  set_tostring(L, "routh connection");
}

static void push_form2(lua_State *L, dm_routh *red)
{
  const dm_routh_exprs *x = dm_routh_exprs_get(red);
  const dm_system *sys = dm_routh_system(red);
  dm_expr_ctx *c = dm_lua_exprctx(L);
  size_t s = x->s, i, j, k = 0;
  luaL_Buffer b;
  lua_createtable(L, (int)s, 0);
  for (i = 0; i < s; i++) {
    push_list(L, x->B + i * s, s);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  luaL_buffinit(L, &b);
  for (i = 0; i < s; i++)
    for (j = i + 1; j < s; j++) {
      if (dm_routh_vanishes(red, c, x->B[i * s + j]))    /* e.g. zero by Euler's theorem */
        continue;
      if (k++)
        luaL_addstring(&b, " + ");
      luaL_addstring(&b, "(");
      add_expr(L, &b, x->B[i * s + j]);
      luaL_addstring(&b, ")*d");
      luaL_addstring(&b, sys->coords[i]);
      luaL_addstring(&b, "^d");
      luaL_addstring(&b, sys->coords[j]);
    }
  if (k == 0)
    luaL_addstring(&b, "0");
  luaL_pushresult(&b);
  set_tostring(L, "routh 2-form");
}

/* a rows x cols matrix of expressions; 1 x 1 gives the expression itself */
static void push_matrix(lua_State *L, const dm_expr *e, size_t rows, size_t cols)
{
  luaL_Buffer b;
  size_t i, j;
  if (rows == 1 && cols == 1) {
    dm_lua_pushexpr(L, e[0]);
    return;
  }
  lua_createtable(L, (int)rows, 0);
  for (i = 0; i < rows; i++) {
    push_list(L, e + i * cols, cols);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  luaL_buffinit(L, &b);
  luaL_addstring(&b, "{");
  for (i = 0; i < rows; i++) {
    luaL_addstring(&b, i ? ", {" : "{");
    for (j = 0; j < cols; j++) {
      if (j)
        luaL_addstring(&b, ", ");
      add_expr(L, &b, e[i * cols + j]);
    }
    luaL_addstring(&b, "}");
  }
  luaL_addstring(&b, "}");
  luaL_pushresult(&b);
  set_tostring(L, "expression matrix");
}

void dm_lrouth_push_names(lua_State *L, const char *const *names, size_t n)
{
  size_t i;
  lua_createtable(L, (int)n, 0);
  for (i = 0; i < n; i++) {
    lua_pushstring(L, names[i]);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
}

void dm_lrouth_push_numbers(lua_State *L, const double *x, size_t n)
{
  if (n == 1)
    lua_pushnumber(L, x[0]);
  else
    dm_pushvec_copy(L, x, n);
}

/* }====================================================================== */

/* {======================================================================
 * fields, printing, the System dm.integrator integrates, opener
 * ======================================================================= */

static const char *const fields =
  "A, beta, amended, potential, routhian, classical, I, Iinv, Mtilde, M, Iinv_mu, muA, thetadot, "
  "force, constraints, mu, params, cyclic, shape, system, full, name, r, s, n";

/* fields that exist only for a mechanical L (derived formulas) */
static int mechanical_only(const char *k)
{
  static const char *const names[] = {"A", "beta", "amended", "potential", "routhian", "classical",
                                      "I", "Iinv", "Mtilde", "Iinv_mu", "muA", "thetadot", NULL};
  const char *const *p;
  for (p = names; *p; p++)
    if (strcmp(*p, k) == 0)
      return 1;
  return 0;
}

static int r_index(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  dm_routh *red = u->red;
  const dm_routh_exprs *x = dm_routh_exprs_get(red);
  const dm_system *rs = dm_routh_system(red), *fs = dm_routh_full(red);
  const char *k = dm_checkcstring(L, 2);
  if (lua_getfield(L, lua_upvalueindex(1), k) != LUA_TNIL)     /* methods */
    return 1;
  lua_pop(L, 1);
  if (!dm_routh_is_mechanical(red) && mechanical_only(k))
    return luaL_error(L, "red.%s: '%s' is not mechanical (L is not quadratic in the velocities), "
                      "so it has no locked inertia, connection or amended potential; its "
                      "reduction is the classical Routhian Rc = L - mu.thetadot on J = mu, "
                      "evaluated numerically (red:eval{q = x, v = xdot} gives Rc and thetadot)", k,
                      dm_routh_full(red)->name);
  if (strcmp(k, "A") == 0)
    push_connection(L, red);
  else if (strcmp(k, "beta") == 0)
    push_form2(L, red);
  else if (strcmp(k, "amended") == 0)
    dm_lua_pushexpr(L, x->Vmu);
  else if (strcmp(k, "potential") == 0)
    dm_lua_pushexpr(L, x->V);
  else if (strcmp(k, "routhian") == 0)
    dm_lua_pushexpr(L, x->R);
  else if (strcmp(k, "classical") == 0)
    dm_lua_pushexpr(L, x->Rc);
  else if (strcmp(k, "I") == 0)
    push_matrix(L, x->I, x->r, x->r);
  else if (strcmp(k, "Iinv") == 0)
    push_matrix(L, x->Iinv, x->r, x->r);
  else if (strcmp(k, "Mtilde") == 0)
    push_matrix(L, x->Mtilde, x->s, x->s);
  else if (strcmp(k, "M") == 0)
    push_matrix(L, x->M, x->n, x->n);
  else if (strcmp(k, "Iinv_mu") == 0)
    push_matrix(L, x->Iinv_mu, 1, x->r);
  else if (strcmp(k, "muA") == 0)
    push_form1(L, red, x->muA);
  else if (strcmp(k, "thetadot") == 0)
    push_matrix(L, x->thetadot, 1, x->r);
  else if (strcmp(k, "force") == 0) {
    if (x->force)
      push_list(L, x->force, x->s);
    else
      lua_pushnil(L);
  } else if (strcmp(k, "constraints") == 0) {
    if (x->constraints)
      push_list(L, x->constraints, x->m);
    else
      lua_pushnil(L);
  } else if (strcmp(k, "params") == 0) {
    lua_getiuservalue(L, 1, 1);               /* the reduced System's params proxy */
    lua_getfield(L, -1, "params");
  } else if (strcmp(k, "mu") == 0)
    dm_lrouth_push_numbers(L, dm_routh_mu(red), x->r);
  else if (strcmp(k, "cyclic") == 0) {
    size_t a;
    lua_createtable(L, (int)x->r, 0);
    for (a = 0; a < x->r; a++) {
      lua_pushstring(L, fs->coords[x->cyclic[a]]);
      lua_rawseti(L, -2, (lua_Integer)a + 1);
    }
  } else if (strcmp(k, "shape") == 0)
    dm_lrouth_push_names(L, rs->coords, x->s);
  else if (strcmp(k, "system") == 0)
    lua_getiuservalue(L, 1, 1);
  else if (strcmp(k, "full") == 0)
    lua_getiuservalue(L, 1, 2);
  else if (strcmp(k, "name") == 0)
    lua_pushstring(L, rs->name);
  else if (strcmp(k, "r") == 0)
    lua_pushinteger(L, (lua_Integer)x->r);
  else if (strcmp(k, "s") == 0)
    lua_pushinteger(L, (lua_Integer)x->s);
  else if (strcmp(k, "n") == 0)
    lua_pushinteger(L, (lua_Integer)x->n);
  else
    return luaL_error(L, "Routh reduction has no field or method '%s' (fields: %s; methods: "
                      "set, project, lift, reconstruct, phase, eval, discrete, defect, integrator)",
                      k, fields);
  return 1;
}

static int r_tostring(lua_State *L)
{
  dm_lrouth *u = luaL_checkudata(L, 1, DM_ROUTH_MT);
  const dm_routh_exprs *x;
  const dm_system *rs;
  luaL_Buffer b;
  size_t i;
  char num[32];
  if (closed_sys(L, 1, 1))
    u->red = NULL;
  if (u->red == NULL) {
    lua_pushliteral(L, "<routh (closed)>");
    return 1;
  }
  x = dm_routh_exprs_get(u->red);
  rs = dm_routh_system(u->red);
  luaL_buffinit(L, &b);
  luaL_addstring(&b, "<routh '");
  luaL_addstring(&b, rs->name);
  luaL_addstring(&b, "': shape (");
  for (i = 0; i < x->s; i++) {
    if (i)
      luaL_addstring(&b, ", ");
    luaL_addstring(&b, rs->coords[i]);
  }
  luaL_addstring(&b, ")");
  for (i = 0; i < x->r; i++) {
    luaL_addstring(&b, i ? ", " : "; ");
    luaL_addstring(&b, rs->params[x->npar + i]);
    luaL_addstring(&b, "=");
    dm_num_format(num, sizeof num, dm_routh_mu(u->red)[i]);
    luaL_addstring(&b, num);
  }
  if (!dm_routh_is_mechanical(u->red)) {
    luaL_addstring(&b, "; numerical (L is not quadratic in the velocities)");
  } else {
    int zero = 1;
    dm_expr_ctx *c = dm_lua_exprctx(L);
    for (i = 0; i < x->s * x->s; i++)
      zero &= dm_routh_vanishes(u->red, c, x->B[i]);
    luaL_addstring(&b, zero ? "; beta = 0" : "; magnetic term beta != 0");
  }
  if (x->m) {
    lua_pushfstring(L, "; %d constraints", (int)x->m);
    luaL_addvalue(&b);
  }
  if (x->force)
    luaL_addstring(&b, "; forced");
  luaL_addstring(&b, ">");
  luaL_pushresult(&b);
  return 1;
}

/* __system: the reduced System that dm.integrator(red, ...) integrates */
static int r_system(lua_State *L)
{
  dm_lrouth_check(L, 1);
  lua_getiuservalue(L, 1, 1);
  return 1;
}

static const dm_reg routh_funcs[] = {
  {"routh", l_routh, "dm.routh(sys, {cyclic = {\"theta\", ...}[, mu = number | {...}][, native = mode]}) -> routh",
   "Routh reduction by cyclic coordinates, derived symbolically: locked inertia, mechanical "
   "connection A, amended potential, Routhian, classical Routhian, magnetic 2-form beta; "
   "dm.integrator(red, {method = ...}) runs RSPRK (gauss, midpoint, lobatto, trapezoid, prk), "
   "the discrete Routh equations (dr, dr:gauss, dr:lobatto), classical-Routhian SPRK "
   "(classical[:method]) or the continuous Routh equations (rk4, gsl:<stepper>, as references) on "
   "the reduced state (x, s = dR/dxdot); red:discrete gives the two-point discrete Routh "
   "equations, red:project / red:reconstruct go between full and reduced.  A Lagrangian that is not "
   "quadratic in the velocities is reduced numerically: J = mu is solved for thetadot and the "
   "reduced system is the classical Routhian L - mu.thetadot, state (x, p_x)."},
  {NULL, NULL, NULL, NULL}
};

static const struct { const char *name, *doc; } field_docs[] = {
  {"routh.A", "The mechanical connection A = I^-1 M_theta,x as a 1-form (list of expressions; a list of 1-forms when r > 1)."},
  {"routh.beta", "The magnetic 2-form beta_mu = d(mu^T A): matrix B_ij (list of lists), printed as a sum of dx_i^dx_j terms."},
  {"routh.amended", "The amended potential V_mu = V + 1/2 mu^T I^-1 mu (an expression)."},
  {"routh.potential", "The potential V = -L(q, 0) (an expression)."},
  {"routh.routhian", "The Routhian R^mu = 1/2 xdot^T Mtilde xdot - V_mu (an expression)."},
  {"routh.classical", "The classical Routhian Rc = R^mu + mu^T A xdot (an expression)."},
  {"routh.I", "The locked inertia I (an expression for r = 1, else an r x r matrix)."},
  {"routh.Iinv", "The inverse locked inertia (adjugate / determinant)."},
  {"routh.Mtilde", "The reduced kinetic matrix M_xx - M_x,theta I^-1 M_theta,x."},
  {"routh.M", "The full mass matrix d2L/dv2."},
  {"routh.Iinv_mu", "I^-1 mu, the group velocity of the locked motion."},
  {"routh.muA", "The 1-form mu^T A (the momentum shift)."},
  {"routh.thetadot", "The reconstruction thetadot = I^-1 mu - A xdot."},
  {"routh.force", "The reduced force (thetadot substituted on J = mu), or nil."},
  {"routh.constraints", "The constraints on the preshape space, or nil."},
  {"routh.mu", "The momentum value (a number for r = 1, else a vec); set with red:set{mu = ...}."},
  {"routh.params", "The parameters of the reduction: the original ones and mu_<theta> (read and assign like sys.params)."},
  {"routh.cyclic", "The names of the cyclic coordinates."},
  {"routh.shape", "The names of the shape (or preshape) coordinates."},
  {"routh.system", "The reduced system (params: the original ones and mu_<theta>) integrated by dm.integrator(red, ...)."},
  {"routh.full", "The original system."},
  {NULL, NULL}
};

void dm_open_reduce(lua_State *L)
{
  static const luaL_Reg meta[] = {{"__tostring", r_tostring}, {"__system", r_system},
                                  {"__close", r_close}, {NULL, NULL}};
  size_t i;
  dm_err e;
  if (dm_routh_register_integrators(&e) != DM_OK)
    luaL_error(L, "dm.routh: %s", e.msg);
  dm_lrouth_open_discrete(L);
  dm_newclass(L, DM_ROUTH_MT, "routh", dm_lrouth_methods, meta);
  lua_getfield(L, -1, "__methods");
  lua_pushcclosure(L, r_index, 1);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
  dm_register(L, "dm.", routh_funcs);
  dm_doc_options(L, "dm.routh", routh_keys);
  for (i = 0; field_docs[i].name; i++)
    dm_doc_add(L, field_docs[i].name, field_docs[i].name, field_docs[i].doc, 0);
}
