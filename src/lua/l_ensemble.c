/* l_ensemble.c -- dm.ensemble{...}: the Lua face of core/ensemble.h
 * (dm.rng: l_rng.c; dm.mpi: l_mpi.c).
 *
 * dm.ensemble reads its options, then hands everything to the core driver
 * (dm_ensemble_run), which runs the members on its worker threads (and MPI
 * ranks).  Lua runs only in this thread, inside two trampolines the driver
 * calls between batches: `start` (the states and params generators) and
 * `user` (a Lua reduce function over each member's trajectory).  Both run
 * their Lua code under lua_pcall and return DM_ECALLBACK on an error, which
 * is re-raised after the driver has unwound (no longjmp over its memory).
 * The result is a Trajectory object with one row per member (columns t,
 * the reducers', status; doc/ensembles.md); under MPI every rank gets the
 * whole table and marks it a replica, so that only rank 0 writes it on
 * save.  The progress line goes to stderr between the driver's calls. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <gsl/gsl_rng.h>

#include "lua/l_ensemble.h"
#include "lua/l_integ.h"
#include "lua/l_lie_sys.h"
#include "core/ensemble.h"
#include "core/interrupt.h"
#include "core/mpi.h"
#include "core/trajectory_h5.h"

/* {======================================================================
 * the call's state and the trampolines
 * ======================================================================= */

/* Stack slots of dm.ensemble (after the argument at 1). */
enum { A_OPTS = 1, A_INTEG, A_STATES, A_PARAMS, A_REDUCE, A_RNG, A_NAMES, A_ERR, A_TOP = A_ERR };

typedef struct call {
  lua_State *L;
  dm_linteg *li;             /* an integrator of a Lagrangian system, or NULL */
  dm_lsystem *ls;            /* its system */
  dm_integrator *I;          /* the integrator */
  const dm_lie_system *lie;  /* or the system on a group of a Lie integrator */
  long members;
  int states_fn, params_fn, have_params;
  unsigned long seed;
  size_t nuser;
  int show;
  double shown_at;
  int shown;
  double *buf;               /* 4n: dm_lua_readstate's scratch */
  double *saved_par;         /* npar: the system's parameters */
  /* the member being handled, for the protected functions */
  long k;
  double *q, *p, *par, *out;
  dm_traj *tr;
} call;

/* Inside a protected body the frame is (c, the A_* slots): slot x is at
 * S(x). */
#define S(x) ((x) + 1)

/* The value for member k of the list or function at slot: pushed. */
static void member_value(lua_State *L, call *c, int slot, int is_fn, const char *what)
{
  if (is_fn) {
    lua_pushvalue(L, S(slot));
    lua_pushinteger(L, c->k + 1);
    lua_pushvalue(L, S(A_RNG));
    lua_call(L, 2, 1);
  } else if (lua_rawgeti(L, S(slot), c->k + 1) == LUA_TNIL) {
    luaL_error(L, "dm.ensemble: %s[%d] is missing", what, (int)(c->k + 1));
  }
}

/* Protected: params (into c->par and the system for reading the state),
 * then the state of member c->k. */
static int start_body(lua_State *L)
{
  call *c = lua_touserdata(L, 1);
  dm_lsystem *ls = c->ls;
  dm_lstate s;
  char fname[64];
  size_t i;
  /* the same generator stream for every rank count: re-seeded per member */
  if (lua_type(L, S(A_RNG)) == LUA_TUSERDATA)
    gsl_rng_set(dm_lua_checkrng(L, S(A_RNG)), dm_ens_seed(c->seed, c->k));
  if (c->have_params) {
    member_value(L, c, A_PARAMS, c->params_fn, "params");
    if (lua_type(L, -1) != LUA_TTABLE)
      luaL_error(L, "dm.ensemble: params of member %d: a table {name = value} expected, got %s",
                 (int)(c->k + 1), luaL_typename(L, -1));
    lua_pushnil(L);
    while (lua_next(L, -2) != 0) {
      long j = -1;
      if (lua_type(L, -2) != LUA_TSTRING || (j = dm_lua_system_param(ls, lua_tostring(L, -2))) < 0) {
        const char *bad = dm_tolstring(L, -2, NULL);
        luaL_error(L, "dm.ensemble: params of member %d: no parameter %s in system '%s' "
                   "(parameters: %s)", (int)(c->k + 1), bad, ls->sys.name,
                   dm_lsystem_names(L, ls->sys.params, ls->sys.npar));
      }
      if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(lua_tonumber(L, -1)))
        luaL_error(L, "dm.ensemble: params of member %d: %s must be a finite number",
                   (int)(c->k + 1), lua_tostring(L, -2));
      c->par[j] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
    /* the state is read on the member's system (p = dL/dv depends on it) */
    for (i = 0; i < ls->npar; i++)
      if (ls->sys.par[i] != c->par[i])
        dm_lua_system_setparam(L, ls, i, c->par[i]);
  }
  member_value(L, c, A_STATES, c->states_fn, "states");
  snprintf(fname, sizeof fname, "dm.ensemble: state of member %ld", c->k + 1);
  if (c->lie != NULL) {
    dm_lstate_lie g;
    dm_lua_lie_readstate(L, c->I, c->lie, -1, fname, &g);
    memcpy(c->q, g.g, c->I->nq * sizeof *c->q);
    memcpy(c->p, g.mu, c->I->n * sizeof *c->p);
    return 0;
  }
  /* the system's own converter: the Legendre map needs no method, and the
   * integrator is left alone (a parameter change would rebuild it) */
  dm_lua_readstate(L, ls, ls->conv, -1, fname, c->buf, &s);
  memcpy(c->q, s.q, ls->n * sizeof *c->q);
  memcpy(c->p, s.p, ls->n * sizeof *c->p);
  return 0;
}

/* Put the system's own parameters back (after a member's params). */
static void restore_params(call *c)
{
  size_t i;
  int changed = 0;
  if (c->ls == NULL)
    return;
  for (i = 0; i < c->ls->npar; i++)
    if (memcmp(&c->ls->sys.par[i], &c->saved_par[i], sizeof(double)) != 0) {
      c->ls->sys.par[i] = c->saved_par[i];
      changed = 1;
    }
  if (changed) {
    c->ls->gen++;
    if (c->ls->sys.refresh != NULL)
      c->ls->sys.refresh(&c->ls->sys, NULL);
  }
}

/* Protected: the reduce function of member c->k on its trajectory. */
static int user_body(lua_State *L)
{
  call *c = lua_touserdata(L, 1);
  dm_traj **slot;
  int base, nret, i;
  lua_pushvalue(L, S(A_REDUCE));
  slot = dm_newtraj(L);            /* the member's trajectory, lent to Lua */
  *slot = c->tr;
  c->tr = NULL;
  lua_pushinteger(L, c->k + 1);
  base = lua_gettop(L) - 3;
  lua_call(L, 2, LUA_MULTRET);
  nret = lua_gettop(L) - base;
  if (nret == 1 && lua_type(L, -1) == LUA_TTABLE) {
    /* a table: the columns by name, or a list */
    int t = lua_gettop(L);
    for (i = 0; i < (int)c->nuser; i++) {
      lua_rawgeti(L, S(A_NAMES), i + 1);
      if (lua_gettable(L, t) == LUA_TNIL) {
        lua_pop(L, 1);
        lua_rawgeti(L, t, i + 1);
      }
      if (lua_type(L, -1) != LUA_TNUMBER) {
        lua_rawgeti(L, S(A_NAMES), i + 1);
        luaL_error(L, "dm.ensemble: reduce of member %d: field '%s' must be a number, got %s",
                   (int)(c->k + 1), lua_tostring(L, -1), luaL_typename(L, -2));
      }
      c->out[i] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
    return 0;
  }
  if (nret != (int)c->nuser)
    luaL_error(L, "dm.ensemble: reduce of member %d returned %d value%s; columns names %d",
               (int)(c->k + 1), nret, nret == 1 ? "" : "s", (int)c->nuser);
  for (i = 0; i < nret; i++) {
    if (lua_type(L, base + 1 + i) != LUA_TNUMBER)
      luaL_error(L, "dm.ensemble: reduce of member %d: value %d must be a number, got %s",
                 (int)(c->k + 1), i + 1, luaL_typename(L, base + 1 + i));
    c->out[i] = lua_tonumber(L, base + 1 + i);
  }
  return 0;
}

/* Run body protected with the frame (c, slots); on an error the error value
 * goes to slot A_ERR and the status is DM_ECALLBACK. */
static int protect(call *c, lua_CFunction body, dm_err *e)
{
  lua_State *L = c->L;
  int top = lua_gettop(L), i;
  lua_pushcfunction(L, body);
  lua_pushlightuserdata(L, c);
  for (i = 1; i <= A_TOP; i++)
    lua_pushvalue(L, i);
  if (lua_pcall(L, 1 + A_TOP, 0, 0) != LUA_OK) {
    /* the text travels to the other MPI ranks; this rank re-raises the value */
    const char *msg = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
    dm_err_set(e, DM_ECALLBACK, "%s", msg != NULL ? msg : "a Lua function raised a non-string error");
    lua_replace(L, A_ERR);
    lua_settop(L, top);
    return DM_ECALLBACK;
  }
  lua_settop(L, top);
  return DM_OK;
}

static int start_cb(void *ctx, long k, double *q, double *p, double *par, dm_err *e)
{
  call *c = ctx;
  int st;
  c->k = k;
  c->q = q;
  c->p = p;
  c->par = par;
  st = protect(c, start_body, e);
  if (c->have_params)
    restore_params(c);
  return st;
}

static int user_cb(void *ctx, long k, dm_traj *tr, double *out, dm_err *e)
{
  call *c = ctx;
  int st;
  c->k = k;
  c->out = out;
  c->tr = dm_traj_slice(tr, 0, dm_traj_len(tr), 1, e);   /* Lua may keep it */
  if (c->tr == NULL)
    return e->status;
  st = protect(c, user_body, e);
  dm_traj_free(c->tr);       /* when the body did not take it */
  c->tr = NULL;
  return st;
}

/* Progress on stderr: shown after half a second, 4 times a second. */
static int progress_cb(void *ctx, const dm_ens_progress *pr)
{
  call *c = ctx;
  double rate;
  if (pr->elapsed < 0.5 || (c->shown && pr->elapsed - c->shown_at < 0.25))
    return 0;
  c->shown_at = pr->elapsed;
  rate = pr->elapsed > 0 ? (double)pr->done / pr->elapsed : 0;
  dm_num_fprintf(stderr, "\r  ensemble: %ld/%ld members (%4.1f%%), %ld failed  %9.3g members/s  "
                 "ETA %.0f s  ", pr->done, pr->total,
                 pr->total ? 100.0 * (double)pr->done / (double)pr->total : 100.0, pr->failed,
                 rate, rate > 0 ? (double)(pr->total - pr->done) / rate : 0.0);
  fflush(stderr);
  c->shown = 1;
  return 0;
}

/* }====================================================================== */

/* {======================================================================
 * dm.ensemble{...}
 * ======================================================================= */

static const char *const ens_keys[] = {"integrator", "members", "states", "params", "run",
  "reduce", "columns", "distance", "threads", "seed", "progress", "output", NULL};
static const char *const run_keys[] = {"t", "steps", "every", "h", "max_energy_error", NULL};

/* Raise on a key of the table at t not in keys. */
static void check_keys(lua_State *L, int t, const char *const *keys, const char *what)
{
  lua_pushnil(L);
  while (lua_next(L, t) != 0) {
    const char *const *k = keys;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key && *k && strcmp(*k, key) != 0)
      k++;
    if (key == NULL || *k == NULL) {
      const char *bad = dm_tolstring(L, -2, NULL);
      luaL_Buffer b;
      luaL_buffinit(L, &b);
      for (k = keys; *k; k++) {
        luaL_addstring(&b, *k);
        if (k[1])
          luaL_addstring(&b, ", ");
      }
      luaL_pushresult(&b);
      luaL_error(L, "dm.ensemble: unknown %s %s (known: %s)", what, bad, lua_tostring(L, -1));
    }
    lua_pop(L, 1);
  }
}

/* A list or a function in field key of the options, into slot; 0 when the
 * field is absent, 1 for a list, 2 for a function. */
static int list_or_function(lua_State *L, const char *key, int slot)
{
  int t = lua_getfield(L, A_OPTS, key);
  lua_replace(L, slot);
  if (t == LUA_TNIL)
    return 0;
  if (t == LUA_TFUNCTION || (t == LUA_TTABLE && luaL_getmetafield(L, slot, "__call") != LUA_TNIL
                             && (lua_pop(L, 1), 1)))
    return 2;
  if (t != LUA_TTABLE)
    luaL_error(L, "dm.ensemble: %s must be a list or a function(k, rng), got %s", key,
               luaL_typename(L, slot));
  return 1;
}

/* run = {t = | steps =, every =, h =, max_energy_error =} */
static void read_run(lua_State *L, double h, dm_run_opts *r)
{
  int has_t, has_steps, o;
  lua_Integer k;
  if (lua_getfield(L, A_OPTS, "run") != LUA_TTABLE)
    luaL_error(L, "dm.ensemble: run = {t = (final time) | steps = (count), every = ...} "
               "expected, got %s", luaL_typename(L, -1));
  o = lua_gettop(L);
  check_keys(L, o, run_keys, "run option");
  r->h = h;
  if (lua_getfield(L, o, "h") != LUA_TNIL) {
    r->h = lua_tonumber(L, -1);
    if (lua_type(L, -1) != LUA_TNUMBER || r->h == 0.0 || !isfinite(r->h))
      luaL_error(L, "dm.ensemble: run.h must be a finite non-zero number");
  }
  lua_pop(L, 1);
  if (isnan(r->h))
    luaL_error(L, "dm.ensemble: no step size: give h in dm.integrator(sys, {h = ...}) or run.h");
  has_t = lua_getfield(L, o, "t") != LUA_TNIL;
  has_steps = lua_getfield(L, o, "steps") != LUA_TNIL;
  lua_pop(L, 2);
  if (has_t == has_steps)
    luaL_error(L, "dm.ensemble: run needs exactly one of t = (the final time) or steps = (a count)");
  if (has_steps) {
    k = dm_optintegerfield(L, o, "steps", 0);
    if (k < 0)
      luaL_error(L, "dm.ensemble: run.steps must be >= 0, got %d", (int)k);
    r->nsteps = (long)k;
  } else {
    dm_err e;
    if (dm_run_steps_to(0.0, dm_optnumberfield(L, o, "t", 0), r->h, &r->nsteps, &e) != DM_OK)
      luaL_error(L, "dm.ensemble: run: %s", e.msg);
  }
  k = dm_optintegerfield(L, o, "every", 1);
  if (k < 1)
    luaL_error(L, "dm.ensemble: run.every must be >= 1, got %d", (int)k);
  r->every = (long)k;
  r->max_energy_error = dm_optnumberfield(L, o, "max_energy_error", 0);
  if (!(r->max_energy_error >= 0) || isinf(r->max_energy_error))
    luaL_error(L, "dm.ensemble: run.max_energy_error must be a finite number >= 0 (0: off)");
  lua_pop(L, 1);
}

/* reduce = {"final", "megno", ...} (default {"final"}) or a function;
 * columns names a function's values (default {"value"}). */
static unsigned read_reduce(lua_State *L, int *user, size_t *nuser)
{
  unsigned bits = 0;
  int t = lua_getfield(L, A_OPTS, "reduce");
  lua_replace(L, A_REDUCE);
  *user = 0;
  *nuser = 0;
  if (t == LUA_TNIL) {
    bits = DM_ENS_BIT(DM_ENS_FINAL);
  } else if (t == LUA_TFUNCTION) {
    *user = 1;
  } else if (t == LUA_TTABLE) {
    lua_Integer i, len = (lua_Integer)lua_rawlen(L, A_REDUCE);
    if (len == 0)
      luaL_error(L, "dm.ensemble: reduce lists no reducer (built-in: final, energy_error, "
                 "min_distance, megno, fli, lyapunov)");
    for (i = 1; i <= len; i++) {
      int r = -1;
      if (lua_rawgeti(L, A_REDUCE, i) == LUA_TFUNCTION)
        luaL_error(L, "dm.ensemble: reduce is either a list of built-in reducers or one "
                   "function of the member's trajectory, not both");
      if (lua_type(L, -1) != LUA_TSTRING || (r = dm_ens_reducer_find(lua_tostring(L, -1))) < 0)
        luaL_error(L, "dm.ensemble: reduce[%d]: unknown reducer %s (built-in: final, "
                   "energy_error, min_distance, megno, fli, lyapunov)", (int)i,
                   dm_tolstring(L, -1, NULL));
      bits |= DM_ENS_BIT(r);
      lua_pop(L, 1);
    }
  } else {
    luaL_error(L, "dm.ensemble: reduce must be a list of reducer names or a function(traj, k), "
               "got %s", luaL_typename(L, A_REDUCE));
  }
  t = lua_getfield(L, A_OPTS, "columns");
  if (t != LUA_TNIL && !*user)
    luaL_error(L, "dm.ensemble: columns names the values of a reduce function; the built-in "
               "reducers name their own");
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    lua_createtable(L, 1, 0);
    lua_pushliteral(L, "value");
    lua_rawseti(L, -2, 1);
  } else if (t != LUA_TTABLE || lua_rawlen(L, -1) == 0) {
    luaL_error(L, "dm.ensemble: columns must be a non-empty list of names");
  }
  lua_replace(L, A_NAMES);
  if (*user) {
    size_t i;
    *nuser = lua_rawlen(L, A_NAMES);
    for (i = 1; i <= *nuser; i++) {
      if (lua_rawgeti(L, A_NAMES, (lua_Integer)i) != LUA_TSTRING)
        luaL_error(L, "dm.ensemble: columns[%d] must be a string", (int)i);
      lua_pop(L, 1);
    }
  }
  return bits;
}

static void push_names_array(lua_State *L, size_t n, const char **names)
{
  size_t i;
  for (i = 0; i < n; i++) {
    lua_rawgeti(L, A_NAMES, (lua_Integer)(i + 1));
    names[i] = lua_tostring(L, -1);      /* anchored in the names table */
    lua_pop(L, 1);
  }
}

/* The coordinate called name (nq of them), or -1. */
static long coord_index(const dm_integrator *I, const dm_lsystem *ls, const char *name)
{
  size_t i;
  if (ls != NULL)
    return dm_lua_system_coord(ls, name);
  for (i = 0; I->sys->coords != NULL && i < I->nq; i++)
    if (strcmp(I->sys->coords[i], name) == 0)
      return (long)i;
  return -1;
}

static int l_ensemble(lua_State *L)
{
  dm_linteg *li = NULL;
  dm_lsystem *ls = NULL;
  dm_integrator *I;
  const dm_lie_system *lie = NULL;
  double h;
  call *c;
  dm_ens_opts o;
  dm_ens_summary sum;
  dm_traj **slot;
  unsigned char *dist = NULL;
  const char **names;
  const char *output;
  dm_err e;
  int st, user, nstates, show;
  lua_Integer members, threads, seed;
  size_t nuser;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  lua_settop(L, A_TOP);
  dm_lua_mpi_check(L, "dm.ensemble");
  check_keys(L, A_OPTS, ens_keys, "option");
  if (lua_getfield(L, A_OPTS, "integrator") == LUA_TNIL)
    return luaL_error(L, "dm.ensemble: integrator = (a dm.integrator) is required");
  lua_replace(L, A_INTEG);
  if ((I = dm_lua_lie_tointeg(L, A_INTEG, &lie, &h)) == NULL) {
    if (luaL_testudata(L, A_INTEG, DM_INTEG_MT) == NULL) {
      const char *got = luaL_getmetafield(L, A_INTEG, "__name") == LUA_TSTRING
                        ? lua_tostring(L, -1) : luaL_typename(L, A_INTEG);
      return luaL_error(L, "dm.ensemble: integrator must be a dm.integrator, got %s", got);
    }
    li = dm_linteg_check(L, A_INTEG);
    ls = li->ls;
    I = li->I;
    h = li->h;
  }
  nstates = list_or_function(L, "states", A_STATES);
  if (nstates == 0)
    return luaL_error(L, "dm.ensemble: states = (a list of states, or a function(k, rng) "
                      "returning member k's) is required");
  members = dm_optintegerfield(L, A_OPTS, "members", nstates == 1
                               ? (lua_Integer)lua_rawlen(L, A_STATES) : -1);
  if (members < 1)
    return luaL_error(L, members == -1 ? "dm.ensemble: members = (a count) is required with a "
                      "states function" : "dm.ensemble: members must be >= 1, got %d", (int)members);
  if (nstates == 1 && (lua_Integer)lua_rawlen(L, A_STATES) < members)
    return luaL_error(L, "dm.ensemble: states lists %d states for %d members",
                      (int)lua_rawlen(L, A_STATES), (int)members);
  st = list_or_function(L, "params", A_PARAMS);
  if (st != 0 && lie != NULL)
    return luaL_error(L, "dm.ensemble: params are not supported for a system on a group (its "
                      "integrators read the system's own parameters: set them with sys:param)");
  if (st == 1 && (lua_Integer)lua_rawlen(L, A_PARAMS) < members)
    return luaL_error(L, "dm.ensemble: params lists %d tables for %d members",
                      (int)lua_rawlen(L, A_PARAMS), (int)members);
  threads = dm_optintegerfield(L, A_OPTS, "threads", 0);
  if (threads < 0 || threads > 4096)
    return luaL_error(L, "dm.ensemble: threads must be in 1 .. 4096 (or 0: all cores), got %d",
                      (int)threads);
  seed = dm_optintegerfield(L, A_OPTS, "seed", 0);
  if (seed < 0 || seed > 0xffffffffLL)
    return luaL_error(L, "dm.ensemble: seed must be in 0 .. 2^32-1");
  output = dm_optstringfield(L, A_OPTS, "output", NULL);
  show = isatty(STDOUT_FILENO) && isatty(STDERR_FILENO);
  if (lua_getfield(L, A_OPTS, "progress") != LUA_TNIL)
    show = lua_toboolean(L, -1);
  lua_pop(L, 1);
  dm_ens_opts_init(&o);
  read_run(L, h, &o.run);
  o.reduce = read_reduce(L, &user, &nuser);
  /* distance = {"x", "y"}: the coordinates of min_distance */
  if (lua_getfield(L, A_OPTS, "distance") != LUA_TNIL) {
    size_t i, len;
    if (!(o.reduce & DM_ENS_BIT(DM_ENS_MIN_DISTANCE)))
      return luaL_error(L, "dm.ensemble: distance applies to the min_distance reducer");
    if (lua_type(L, -1) != LUA_TTABLE || (len = lua_rawlen(L, -1)) == 0)
      return luaL_error(L, "dm.ensemble: distance must be a list of coordinate names");
    dist = lua_newuserdatauv(L, I->nq, 0);
    memset(dist, 0, I->nq);
    for (i = 1; i <= len; i++) {
      long j = -1;
      lua_rawgeti(L, -2, (lua_Integer)i);
      if (lua_type(L, -1) != LUA_TSTRING || (j = coord_index(I, ls, lua_tostring(L, -1))) < 0) {
        const char *bad = dm_tolstring(L, -1, NULL);
        return luaL_error(L, "dm.ensemble: distance[%d]: no coordinate %s in system '%s' "
                          "(coordinates: %s)", (int)i, bad, I->sys->name,
                          dm_lsystem_names(L, I->sys->coords, I->nq));
      }
      dist[j] = 1;
      lua_pop(L, 1);
    }
    lua_replace(L, -2);     /* keep the flags (anchored) in place of the list */
  }
  /* everything the call needs lives in Lua userdata: an error frees it */
  c = lua_newuserdatauv(L, sizeof *c, 0);
  memset(c, 0, sizeof *c);
  c->buf = lua_newuserdatauv(L, (4 * I->nq + I->sys->npar + 1) * sizeof(double), 0);
  c->saved_par = c->buf + 4 * I->nq;
  memcpy(c->saved_par, I->sys->par, I->sys->npar * sizeof(double));
  names = lua_newuserdatauv(L, (nuser + 1) * sizeof *names, 0);
  push_names_array(L, nuser, names);
  c->L = L;
  c->li = li;
  c->ls = ls;
  c->I = I;
  c->lie = lie;
  c->members = (long)members;
  c->states_fn = nstates == 2;
  c->params_fn = st == 2;
  c->have_params = st != 0;
  c->seed = (unsigned long)seed;
  c->nuser = nuser;
  if (c->states_fn || c->params_fn)
    dm_lua_pushrng(L, c->seed);
  else
    lua_pushnil(L);
  lua_replace(L, A_RNG);
  o.members = (long)members;
  o.threads = (int)threads;
  o.dist = dist;
  o.start = start_cb;
  o.start_ctx = c;
  o.params = c->have_params;
  if (user) {
    o.user = user_cb;
    o.user_ctx = c;
    o.nuser = nuser;
    o.user_names = names;
  }
  if (show) {
    o.progress = progress_cb;
    o.progress_ctx = c;
  }
  o.index_base = 1;
  o.distributed = 1;
  o.output = output;
  slot = dm_newtraj(L);                 /* the result's home, before anything is allocated */
  st = dm_ensemble_run(I, &o, slot, &sum, &e);
  if (c->shown) {
    fprintf(stderr, "\r%90s\r", "");
    fflush(stderr);
  }
  if (st == DM_EINTR)
    dm_interrupt_clear();
  if (st == DM_ECALLBACK && !lua_isnil(L, A_ERR)) {
    lua_pushvalue(L, A_ERR);      /* the Lua function's own error */
    return lua_error(L);
  }
  if (*slot == NULL)
    return dm_lua_fail(L, "dm.ensemble", st, &e);
  if (dm_mpi_size() > 1)
    dm_traj_mark_replica(L, -1);
  if (sum.note[0] != '\0' && dm_mpi_rank() == 0) {
    lua_pushfstring(L, "dm.ensemble: %s", sum.note);
    dm_lua_warning(L, lua_tostring(L, -1));
    lua_pop(L, 1);
  }
  if (st == DM_OK && sum.failed == 0)
    return 1;
  if (st == DM_OK || st == DM_EINTR) {
    const char *first = NULL;
    size_t i;
    for (i = 0; first == NULL && i < dm_traj_meta_count(*slot); i++) {
      const char *k, *v;
      dm_traj_meta_at(*slot, i, &k, &v);
      if (strncmp(k, "failure.", 8) == 0)
        first = v;
    }
    if (st == DM_EINTR)
      lua_pushfstring(L, "dm.ensemble: %s", e.msg);
    else
      lua_pushfstring(L, "dm.ensemble: %d of %d members failed (the first: %s); their status and "
                      "time reached are in the table", (int)sum.failed, (int)sum.members,
                      first ? first : "?");
    dm_lua_warning(L, lua_tostring(L, -1));       /* nothing fails silently */
    return 2;
  }
  lua_pushfstring(L, "dm.ensemble: %s", e.msg);   /* the output file: table kept */
  return 2;
}

/* }====================================================================== */

static const dm_reg ens_funcs[] = {
  {"ensemble", l_ensemble,
   "dm.ensemble{integrator=, members=, states=, params=, run={t=|steps=, every=}, reduce=, threads=, seed=, output=} -> table[, message]",
   "Run many members (states = a list or function(k, rng), params likewise) on all cores and MPI ranks; reduce = built-in reducers {\"final\", \"energy_error\", \"min_distance\", \"megno\", \"fli\", \"lyapunov\"} or function(traj, k) with columns = {names}; returns a table with one row per member (t, the reduced columns, status) that saves to .csv or .h5 (output = \"f.h5\" writes it collectively)."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_ensemble(lua_State *L)
{
  dm_gsl_init();
  dm_open_mpi(L);
  dm_open_rng(L);
  dm_register(L, "dm.", ens_funcs);
}
