/* l_wave.c -- dm.wave: the multisymplectic integrators of the nonlinear
 * wave equation u_tt = c^2 u_xx - V'(u) (src/fields/fields.h) from Lua.
 *
 *   dm.wave{N =, length =, x0 = 0, periodic = true, c = 1, dt =, V = function(u) ... end}
 *   dm.wave{mesh = M, c = 1, dt =, V = ...}          (DEC in space, any mesh)
 *   dm.wave{N =, length =, ..., adapt = {monitor = "arclength", alpha =, rule = "edges"}}
 *                                                     (moving nodes, ends held)
 *
 * V is traced once with a symbolic u and compiled with V' and V'' (like a
 * Lagrangian of one coordinate); the compiled system and its work buffer
 * live in the userdata.  A Wave userdata ("dmech.waveeq") owns the C
 * integrator; a mesh it integrates on is kept alive in user value 1.
 * Runs return a trajectory (t, energy) and a matrix of the field at the
 * samples (rows), both made in C; this file converts.  Adaptive runs add
 * the equidistribution residual as a trajectory column and return the
 * node positions at the samples as a third matrix.  Its methods are
 * documented as "waveeq:<name>" ("wave:" is the Schrodinger state's). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "expr/lagrangian.h"
#include "fields/fields.h"
#include "lua/l_dec.h"
#include "lua/l_expr.h"

#define WAVE_MT "dmech.waveeq"

typedef struct lwaveeq {
  dm_msym *G;                /* grid, or */
  dm_msym_dec *D;            /* DEC mesh, or */
  dm_radapt *A;              /* moving nodes */
  const dm_dec_geom *geom;   /* the mesh's geometry (borrowed, user value 1) */
  double x0, dx, dt;
  size_t n;                  /* nodes */
  dm_system field;           /* compiled V (zeroed when V = 0) */
  dm_potential_system ps;
  dm_potential pot;
  void *work;
} lwaveeq;

static int wave_gc(lua_State *L)
{
  lwaveeq *w = luaL_checkudata(L, 1, WAVE_MT);
  dm_msym_free(w->G);
  dm_msym_dec_free(w->D);
  dm_radapt_free(w->A);
  dm_system_release(&w->field);
  free(w->work);
  w->G = NULL;
  w->D = NULL;
  w->A = NULL;
  w->work = NULL;
  return 0;
}

static lwaveeq *checkwave(lua_State *L, int idx)
{
  lwaveeq *w = luaL_checkudata(L, idx, WAVE_MT);
  if (w->G == NULL && w->D == NULL && w->A == NULL)
    luaL_error(L, "attempt to use a closed wave integrator");
  return w;
}

/* Trace V (the function at fi) and compile it into w->field. */
static void compile_V(lua_State *L, int fi, lwaveeq *w)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  static const char *const uname[] = {"u"};
  dm_lagrangian_spec sp;
  dm_expr sym[2], V;
  size_t rows, cols;
  dm_err e;
  int st;
  dm_lua_pushsymvec(L, "u", 1, uname, NULL, DM_EXPR_SYM);
  int qv = lua_gettop(L);
  dm_lua_pushsymvec(L, "v", 1, uname, "v_%s", DM_EXPR_SYM);
  int vv = lua_gettop(L);
  lua_geti(L, qv, 1);
  sym[0] = dm_lua_toexpr(L, -1);
  lua_geti(L, vv, 1);
  sym[1] = dm_lua_toexpr(L, -1);
  lua_pushvalue(L, fi);
  lua_pushvalue(L, -3);
  dm_lua_trace(L, "the potential V of dm.wave", 1);
  if (lua_isnil(L, -1))
    luaL_error(L, "dm.wave: V returned nothing (return an expression of u)");
  dm_lua_toexprs(L, -1, "the potential V of dm.wave", &V, 1, &rows, &cols);
  if (rows != 1 || cols != 0)
    luaL_error(L, "dm.wave: V must return one expression of u, got a list");
  memset(&sp, 0, sizeof sp);
  sp.name = "potential";
  sp.n = 1;
  sp.q = sym;
  sp.v = sym + 1;
  sp.coord_names = uname;
  sp.L = V;
  sp.native = DM_NATIVE_NEVER;
  if ((st = dm_lagrangian_compile(ctx, &sp, &w->field, &e)) != DM_OK)
    dm_lua_fail(L, "dm.wave", st, &e);
  if (w->field.work_size > 0 && (w->work = malloc(w->field.work_size)) == NULL)
    luaL_error(L, "dm.wave: out of memory");
  w->ps.field = &w->field;
  w->ps.work = w->work;
  dm_potential_from_system(&w->pot, &w->ps);
  lua_settop(L, fi);
}

static const char *const wave_keys[] = {"N", "length", "x0", "periodic", "c", "dt", "V", "mesh",
                                        "adapt", NULL};
static const char *const adapt_keys[] = {"monitor", "alpha", "rule", NULL};

/* Check the table adapt = {...} at index t: alpha into *alpha, the rule. */
static int check_adapt(lua_State *L, int t, double *alpha)
{
  static const char *const rules[] = {"centre", "edges", NULL};
  if (!lua_istable(L, t))
    luaL_error(L, "dm.wave: adapt must be a table {monitor = \"arclength\", alpha = ...}, got %s",
               luaL_typename(L, t));
  if (dm_unknownkey(L, t, adapt_keys)) {
    int str = lua_type(L, -1) == LUA_TSTRING;
    luaL_error(L, "dm.wave: unknown field %s%s%s of adapt (fields: monitor, alpha, rule)",
               str ? "'" : "[", luaL_tolstring(L, -1, NULL), str ? "'" : "]");
  }
  if (lua_getfield(L, t, "monitor") != LUA_TNIL
      && (lua_type(L, -1) != LUA_TSTRING || strcmp(lua_tostring(L, -1), "arclength") != 0))
    luaL_error(L, "dm.wave: adapt.monitor must be \"arclength\" (rho = sqrt(1 + alpha u_x^2)), "
               "got %s", luaL_tolstring(L, -1, NULL));
  lua_pop(L, 1);
  if (lua_getfield(L, t, "alpha") == LUA_TNIL)
    luaL_error(L, "dm.wave: adapt.alpha is required (a number >= 0: the weight of u_x in the "
               "monitor)");
  int ok;
  *alpha = lua_tonumberx(L, -1, &ok);
  if (!ok || !(*alpha >= 0) || !isfinite(*alpha))
    luaL_error(L, "dm.wave: adapt.alpha must be a finite number >= 0, got %s",
               luaL_tolstring(L, -1, NULL));
  lua_pop(L, 1);
  int rule = DM_RADAPT_EDGES;
  if (lua_getfield(L, t, "rule") != LUA_TNIL) {
    const char *r = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
    for (rule = 0; rules[rule] && strcmp(rules[rule], r) != 0; rule++)
      ;
    if (rules[rule] == NULL)
      luaL_error(L, "dm.wave: adapt.rule must be \"edges\" or \"centre\", got %s",
                 luaL_tolstring(L, -1, NULL));
    rule = rule == 0 ? DM_RADAPT_CENTRE : DM_RADAPT_EDGES;
  }
  lua_pop(L, 1);
  return rule;
}

/* dm.wave{...} */
static int l_wave(lua_State *L)
{
  dm_err e;
  int st;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_checkkeys(L, 1, wave_keys, "dm.wave", "field",
               "N, length, x0, periodic, c, dt, V, mesh, adapt");
  double c = dm_optnumberfield(L, 1, "c", 1.0), dt = dm_optnumberfield(L, 1, "dt", NAN);
  if (!isfinite(dt) || dt == 0.0)
    luaL_error(L, "dm.wave: dt must be a finite non-zero number (the time step)");
  lwaveeq *w = lua_newuserdatauv(L, sizeof *w, 1);             /* 2 */
  memset(w, 0, sizeof *w);
  luaL_setmetatable(L, WAVE_MT);
  w->dt = dt;
  if (lua_getfield(L, 1, "V") != LUA_TNIL) {                    /* 3 */
    if (!lua_isfunction(L, 3))
      luaL_error(L, "dm.wave: V must be a function of u, got %s", luaL_typename(L, 3));
    compile_V(L, 3, w);
  }
  lua_settop(L, 2);
  if (lua_getfield(L, 1, "mesh") != LUA_TNIL) {                 /* 3 */
    dm_lmesh *m = dm_checkmesh(L, 3);
    if (lua_getfield(L, 1, "N") != LUA_TNIL || lua_getfield(L, 1, "length") != LUA_TNIL)
      luaL_error(L, "dm.wave: give mesh or N and length, not both");
    if (lua_getfield(L, 1, "adapt") != LUA_TNIL)
      luaL_error(L, "dm.wave: adapt moves the nodes of a grid (N, length), not of a mesh");
    lua_pop(L, 1);
    lua_pushvalue(L, 3);
    lua_setiuservalue(L, 2, 1);
    w->geom = m->G;
    if ((st = dm_msym_dec_alloc(m->G, c, dt, &w->pot, &w->D, &e)) != DM_OK)
      return dm_lua_fail(L, "dm.wave", st, &e);
    w->n = dm_msym_dec_nodes(w->D);
  } else {
    lua_Integer N = dm_optintegerfield(L, 1, "N", 0);
    double len = dm_optnumberfield(L, 1, "length", NAN), alpha = 0;
    int has_p = lua_getfield(L, 1, "periodic") != LUA_TNIL, periodic = !has_p || lua_toboolean(L, -1);
    lua_pop(L, 1);
    if (N < 3)
      luaL_error(L, "dm.wave: N (the cells, >= 3) and length, or mesh, are required");
    w->x0 = dm_optnumberfield(L, 1, "x0", 0.0);
    if (lua_getfield(L, 1, "adapt") != LUA_TNIL) {              /* 4 */
      int rule = check_adapt(L, lua_gettop(L), &alpha);
      if (has_p && periodic)
        luaL_error(L, "dm.wave: adapt needs periodic = false (the end nodes are held)");
      if ((st = dm_radapt_alloc((size_t)N, w->x0, len, c, dt, alpha, rule, &w->pot, &w->A, &e))
          != DM_OK)
        return dm_lua_fail(L, "dm.wave", st, &e);
      w->n = dm_radapt_nodes(w->A);
      w->dx = len / (double)N;
    } else {
      if ((st = dm_msym_alloc((size_t)N, len, periodic, c, dt, &w->pot, &w->G, &e)) != DM_OK)
        return dm_lua_fail(L, "dm.wave", st, &e);
      w->n = dm_msym_nodes(w->G);
      w->dx = dm_msym_dx(w->G);
    }
  }
  lua_settop(L, 2);
  return 1;
}

/* The coordinates of node i into x (1 value on a grid, N on a mesh). */
static int node_coords(const lwaveeq *w, size_t i, double *x)
{
  if (w->G != NULL || w->A != NULL) {
    x[0] = w->x0 + w->dx * (double)i;
    return 1;
  }
  for (int k = 0; k < w->geom->N; k++)
    x[k] = w->geom->X[i * (size_t)w->geom->N + (size_t)k];
  return w->geom->N;
}

/* The field at idx: a function of the node coordinates, a vec or a list. */
static void read_field(lua_State *L, lwaveeq *w, int idx, const char *what, double *out)
{
  size_t i;
  if (lua_isfunction(L, idx)) {
    for (i = 0; i < w->n; i++) {
      double x[4];
      int k, nx = node_coords(w, i, x), ok;
      lua_pushvalue(L, idx);
      for (k = 0; k < nx; k++)
        lua_pushnumber(L, x[k]);
      lua_call(L, nx, 1);
      out[i] = lua_tonumberx(L, -1, &ok);
      if (!ok || !isfinite(out[i]))
        luaL_error(L, "run: %s must return finite numbers, got %s at node %d", what,
                   luaL_tolstring(L, -1, NULL), (int)i + 1);
      lua_pop(L, 1);
    }
    return;
  }
  lua_pushvalue(L, idx);
  gsl_vector *v = dm_checkvector(L, lua_gettop(L), w->n);
  for (i = 0; i < w->n; i++)
    out[i] = gsl_vector_get(v, i);
  lua_pop(L, 1);
}

static const char *const run_keys[] = {"steps", "t", "every", NULL};

/* the initial field of an adaptive run: the Lua function at index idx */
typedef struct lfield {
  lua_State *L;
  int idx;
} lfield;

static int call_field(void *data, double x, double *y)
{
  lfield *f = data;
  int ok;
  lua_pushvalue(f->L, f->idx);
  lua_pushnumber(f->L, x);
  lua_call(f->L, 1, 1);
  *y = lua_tonumberx(f->L, -1, &ok);
  lua_pop(f->L, 1);
  return ok && isfinite(*y) ? 0 : 1;
}

/* An adaptive run (the checks of w_run done, state at 2): traj, U, X */
static int run_adapt(lua_State *L, lwaveeq *w, long nsteps, long every)
{
  size_t n = w->n, i;
  dm_err e;
  int st;
  double *b = lua_newuserdatauv(L, 4 * n * sizeof *b, 0);       /* 4 */
  double *X = b, *u = X + n, *p = u + n, *v = p + n;
  if (lua_getfield(L, 2, "u") != LUA_TFUNCTION)                 /* 5 */
    luaL_error(L, "run: with adapt, state.u must be a function of x (the nodes are placed by "
               "it), got %s", luaL_typename(L, 5));
  lfield f = {L, 5};
  if ((st = dm_radapt_init(w->A, call_field, &f, X, u, &e)) != DM_OK)
    return dm_lua_fail(L, "run: state.u", st, &e);
  int tv = lua_getfield(L, 2, "v");                              /* 6 */
  if (tv != LUA_TNIL && tv != LUA_TFUNCTION)
    luaL_error(L, "run: with adapt, state.v must be a function of x, got %s", luaL_typename(L, 6));
  for (i = 0; i < n; i++) {
    if (tv == LUA_TNIL) {
      v[i] = 0;
      continue;
    }
    int ok;
    lua_pushvalue(L, 6);
    lua_pushnumber(L, X[i]);
    lua_call(L, 1, 1);
    v[i] = lua_tonumberx(L, -1, &ok);
    if (!ok || !isfinite(v[i]))
      luaL_error(L, "run: state.v must return finite numbers, got %s at x = %f",
                 luaL_tolstring(L, -1, NULL), X[i]);
    lua_pop(L, 1);
  }
  dm_radapt_momentum(w->A, X, v, p);
  long ns = nsteps / every + 1 + (nsteps % every != 0), row = 0, k;
  struct dm_traj **slot = dm_newtraj(L);                        /* 7 */
  if ((*slot = dm_traj_alloc(0, NULL, 0, &e)) == NULL
      || dm_traj_add_column(*slot, "energy", DM_TRAJ_DIAG, NULL, 0, &e) != DM_OK
      || dm_traj_add_column(*slot, "equidist", DM_TRAJ_DIAG, NULL, 0, &e) != DM_OK)
    return dm_lua_fail(L, "run", e.status, &e);
  gsl_matrix *U = dm_pushmat(L, (size_t)ns, n);                 /* 8 */
  gsl_matrix *XX = dm_pushmat(L, (size_t)ns, n);                /* 9 */
  st = DM_OK;
  for (k = 0; k <= nsteps; k++) {
    if (k > 0 && (st = dm_radapt_step(w->A, X, u, p, X, u, p, &e)) != DM_OK)
      break;
    if (k % every == 0 || k == nsteps) {
      double d[2] = {dm_radapt_energy(w->A, X, u, p), dm_radapt_residual(w->A, X, u)};
      dm_traj_append(*slot, (double)k * w->dt, NULL, NULL, NULL, d, NULL);
      for (i = 0; i < n; i++) {
        gsl_matrix_set(U, (size_t)row, i, u[i]);
        gsl_matrix_set(XX, (size_t)row, i, X[i]);
      }
      row++;
    }
  }
  dm_traj_meta_set(*slot, "system", "wave equation", NULL);
  dm_traj_meta_set(*slot, "method", "multisymplectic (r-adaptive)", NULL);
  dm_traj_meta_set_number(*slot, "h", w->dt, NULL);
  if (st != DM_OK) {                /* the samples so far, and why it stopped */
    gsl_matrix_view part = gsl_matrix_submatrix(U, 0, 0, (size_t)(row > 0 ? row : 1), n);
    dm_pushmat_copy(L, &part.matrix);
    lua_replace(L, 8);
    part = gsl_matrix_submatrix(XX, 0, 0, (size_t)(row > 0 ? row : 1), n);
    dm_pushmat_copy(L, &part.matrix);
    lua_replace(L, 9);
    lua_pushfstring(L, "run: step %d failed: %s", (int)k, e.msg);
    return 4;
  }
  return 3;
}

/* W:run({u = f | vec, v = f | vec}, {t = | steps =, every = 1}) -> traj, U */
static int w_run(lua_State *L)
{
  lwaveeq *w = checkwave(L, 1);
  size_t n = w->n, i;
  long nsteps, every;
  dm_err e;
  luaL_checktype(L, 2, LUA_TTABLE);
  luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  dm_checkkeys(L, 3, run_keys, "run", "option", "steps, t, every");
  int has_t = lua_getfield(L, 3, "t") != LUA_TNIL, has_n = lua_getfield(L, 3, "steps") != LUA_TNIL;
  lua_pop(L, 2);
  if (has_t == has_n)
    luaL_error(L, "run: give exactly one of steps = (a number of steps) or t = (the final time)");
  if (has_n) {
    nsteps = (long)dm_optintegerfield(L, 3, "steps", 0);
  } else {
    double x = dm_optnumberfield(L, 3, "t", 0) / w->dt;
    if (!isfinite(x) || x < -0.5 || x > 1e9)
      luaL_error(L, "run: the final time cannot be reached with dt = %f", w->dt);
    nsteps = lround(x);
  }
  every = (long)dm_optintegerfield(L, 3, "every", 1);
  if (nsteps < 0 || every < 1)
    luaL_error(L, "run: need steps >= 0 and every >= 1");
  if (w->A != NULL)
    return run_adapt(L, w, nsteps, every);
  double *b = lua_newuserdatauv(L, 3 * n * sizeof *b, 0);       /* 4 */
  double *u = b, *p = u + n, *v = p + n;
  if (lua_getfield(L, 2, "u") == LUA_TNIL)                      /* 5 */
    luaL_error(L, "run: the state needs u (a function of the node coordinates, or values)");
  read_field(L, w, 5, "state.u", u);
  if (lua_getfield(L, 2, "v") != LUA_TNIL)                      /* 6 */
    read_field(L, w, 6, "state.v", v);
  else
    memset(v, 0, n * sizeof *v);
  if (w->G != NULL)
    dm_msym_momentum(w->G, v, p);
  else
    dm_msym_dec_momentum(w->D, v, p);
  long ns = nsteps / every + 1 + (nsteps % every != 0);
  struct dm_traj **slot = dm_newtraj(L);                        /* 7 */
  if ((*slot = dm_traj_alloc(0, NULL, 0, &e)) == NULL
      || dm_traj_add_column(*slot, "energy", DM_TRAJ_DIAG, NULL, 0, &e) != DM_OK)
    return dm_lua_fail(L, "run", e.status, &e);
  gsl_matrix *U = dm_pushmat(L, (size_t)ns, n);                 /* 8 */
  long row = 0, k;
  int st = DM_OK;
  for (k = 0; k <= nsteps; k++) {
    if (k > 0) {
      st = w->G ? dm_msym_step(w->G, u, p, u, p, &e) : dm_msym_dec_step(w->D, u, p, u, p, &e);
      if (st != DM_OK)
        break;
    }
    if (k % every == 0 || k == nsteps) {
      double E = w->G ? dm_msym_energy(w->G, u, p) : dm_msym_dec_energy(w->D, u, p);
      dm_traj_append(*slot, (double)k * w->dt, NULL, NULL, NULL, &E, NULL);
      for (i = 0; i < n; i++)
        gsl_matrix_set(U, (size_t)row, i, u[i]);
      row++;
    }
  }
  dm_traj_meta_set(*slot, "system", "wave equation", NULL);
  dm_traj_meta_set(*slot, "method", w->G ? "multisymplectic (grid)" : "multisymplectic (DEC)", NULL);
  dm_traj_meta_set_number(*slot, "h", w->dt, NULL);
  if (st != DM_OK) {                /* the samples so far, and why it stopped */
    gsl_matrix_view part = gsl_matrix_submatrix(U, 0, 0, (size_t)(row > 0 ? row : 1), n);
    dm_pushmat_copy(L, &part.matrix);
    lua_replace(L, 8);
    lua_pushfstring(L, "run: step %d failed: %s", (int)k, e.msg);
    return 3;
  }
  return 2;
}

/* W:form_check(state, {du =, dp =, dv =, dq =, steps =}) -> {cell, node, level} */
static int w_form_check(lua_State *L)
{
  lwaveeq *w = checkwave(L, 1);
  size_t n = w->n;
  double res[3];
  dm_err e;
  if (w->G == NULL)
    return luaL_error(L, "form_check: the multisymplectic form formula is checked on still "
                      "grids (not a mesh, not adapt)");
  luaL_checktype(L, 2, LUA_TTABLE);
  luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  double *b = lua_newuserdatauv(L, 7 * n * sizeof *b, 0);       /* 4 */
  static const char *const f[] = {"du", "dp", "dv", "dq"};
  if (lua_getfield(L, 2, "u") == LUA_TNIL)
    luaL_error(L, "form_check: the state needs u");
  read_field(L, w, lua_gettop(L), "state.u", b);
  if (lua_getfield(L, 2, "v") != LUA_TNIL)
    read_field(L, w, lua_gettop(L), "state.v", b + 6 * n);
  else
    memset(b + 6 * n, 0, n * sizeof *b);
  dm_msym_momentum(w->G, b + 6 * n, b + n);
  for (int k = 0; k < 4; k++) {
    if (lua_getfield(L, 3, f[k]) == LUA_TNIL)
      luaL_error(L, "form_check: the variations du, dp, dv, dq are required");
    read_field(L, w, lua_gettop(L), f[k], b + (size_t)(2 + k) * n);
  }
  long steps = (long)dm_optintegerfield(L, 3, "steps", 10);
  int st = dm_msym_form_check(w->G, b, b + n, b + 2 * n, b + 3 * n, b + 4 * n, b + 5 * n, steps,
                              res, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, "form_check", st, &e);
  lua_createtable(L, 0, 3);
  lua_pushnumber(L, res[0]);
  lua_setfield(L, -2, "cell");
  lua_pushnumber(L, res[1]);
  lua_setfield(L, -2, "node");
  lua_pushnumber(L, res[2]);
  lua_setfield(L, -2, "level");
  return 1;
}

static int w_dispersion(lua_State *L)
{
  lwaveeq *w = checkwave(L, 1);
  if (w->G == NULL)
    return luaL_error(L, "dispersion: the relation is the still grid's (not a mesh, not adapt)");
  lua_pushnumber(L, dm_msym_dispersion(w->G, luaL_checknumber(L, 2)));
  return 1;
}

static int w_nodes(lua_State *L)
{
  lwaveeq *w = checkwave(L, 1);
  if (w->A != NULL)
    return luaL_error(L, "x: adaptive nodes move (run returns them as its third value)");
  gsl_vector *x = dm_pushvec(L, w->n);
  if (w->G == NULL)
    return luaL_error(L, "x: a mesh's vertices are the mesh's");
  for (size_t i = 0; i < w->n; i++)
    gsl_vector_set(x, i, w->x0 + w->dx * (double)i);
  return 1;
}

static int w_tostring(lua_State *L)
{
  lwaveeq *w = luaL_checkudata(L, 1, WAVE_MT);
  if (w->G == NULL && w->D == NULL && w->A == NULL)
    lua_pushliteral(L, "<wave (closed)>");
  else if (w->A != NULL)
    lua_pushfstring(L, "<wave grid r-adaptive alpha=%f, %d nodes, dt=%f%s>",
                    dm_radapt_alpha(w->A), (int)w->n, w->dt, w->field.lagrangian ? ", V(u)" : "");
  else
    lua_pushfstring(L, "<wave %s, %d nodes, dt=%f%s>", w->G ? "grid" : "DEC mesh", (int)w->n, w->dt,
                    w->field.lagrangian ? ", V(u)" : "");
  return 1;
}

static const dm_reg wave_methods[] = {
  {"run", w_run, "W:run({u = f | vec, v = f | vec}, {t = | steps =, every = 1}) -> traj, U",
   "Integrate from u and u_t (functions of the node coordinates or values): a trajectory of t "
   "and the energy, and the field at the samples as the rows of a matrix.  With adapt: u and v "
   "are functions of x, the trajectory adds the equidistribution residual (column equidist) and "
   "a third matrix holds the node positions X_i(t) at the samples."},
  {"form_check", w_form_check, "W:form_check(state, {du =, dp =, dv =, dq =, steps = 10}) -> {cell, node, level}",
   "The discrete multisymplectic form formula along a run (grids): the largest corner-form sum of "
   "a cell, of the four cells around a node, and the change of the symplectic form of a level, "
   "relative."},
  {"dispersion", w_dispersion, "W:dispersion(k) -> omega",
   "The grid scheme's plane-wave frequency: tan(omega dt/2)/dt = c tan(k dx/2)/dx."},
  {"x", w_nodes, "W:x() -> vec", "The grid's node coordinates."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg wave_meta[] = {
  {"__gc", wave_gc}, {"__close", wave_gc}, {"__tostring", w_tostring}, {NULL, NULL}
};

static const dm_reg wave_funcs[] = {
  {"wave", l_wave,
   "dm.wave{N =, length =, x0 = 0, periodic = true | mesh = M, c = 1, dt =, V = function(u) ... end, adapt = {monitor = \"arclength\", alpha =, rule = \"edges\"}} -> W",
   "The multisymplectic variational integrator of u_tt = c^2 u_xx - V'(u): bilinear elements on a "
   "space-time grid (periodic, or ends held), or DEC in space on a mesh with the midpoint rule in "
   "time.  adapt (ends held) moves the nodes: each level equidistributes the arc length "
   "sqrt(h^2 + alpha du^2) of its cells (rule: u_t^2 sampled on the cells' edges, or at their "
   "centre as on the still grid)."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_wave(lua_State *L)
{
  dm_newclass(L, WAVE_MT, "waveeq", wave_methods, wave_meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", wave_funcs);
  dm_doc_options(L, "dm.wave", wave_keys);
  dm_doc_options(L, "wave:run", run_keys);
}
