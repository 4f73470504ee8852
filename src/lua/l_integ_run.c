/* l_integ_run.c -- integ:run(state, {...}) -> Trajectory[, message].
 *
 * The run is core's dm_run (core/run.h): pieces, sampling, diagnostic
 * columns, metadata, runaway detection and the last good state on an early
 * end.  This file reads the options, draws the progress line on stderr
 * (between pieces, through dm_run's progress callback) and turns the
 * outcome into Lua values: the trajectory, and for an early end a second
 * value, core's message prefixed with "run: " (and a warning on stderr, or
 * an error with strict = true: dm_lua_run_ended).  Ctrl-C (DM_EINTR) clears
 * the interrupt flag so that the REPL does not raise as well. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "lua/l_integ.h"
#include "core/interrupt.h"
#include "core/run.h"
#include "core/trajectory.h"

/* {======================================================================
 * progress on stderr (numerics never print)
 * ======================================================================= */

typedef struct progress {
  int shown;
  double last;
} progress;

/* Shown only for runs longer than half a second, at most 4 times a second. */
static int progress_draw(void *ctx, const dm_run_progress *pr)
{
  progress *pg = ctx;
  double rate;
  if (pr->elapsed < 0.5 || (pg->shown && pr->elapsed - pg->last < 0.25))
    return 0;
  pg->last = pr->elapsed;
  rate = pr->elapsed > 0 ? (double)pr->step / pr->elapsed : 0;
  dm_num_fprintf(stderr, "\r  run: step %ld/%ld (%4.1f%%)  t = %-12.6g %9.3g steps/s  ETA %.0f s  ",
                 pr->step, pr->nsteps,
                 pr->nsteps ? 100.0 * (double)pr->step / (double)pr->nsteps : 100.0, pr->t, rate,
                 rate > 0 ? (double)(pr->nsteps - pr->step) / rate : 0.0);
  fflush(stderr);
  pg->shown = 1;
  return 0;
}

static void progress_end(progress *pg)
{
  if (pg->shown) {
    fprintf(stderr, "\r%80s\r", "");
    fflush(stderr);
  }
  pg->shown = 0;
}

/* }====================================================================== */

/* {======================================================================
 * options
 * ======================================================================= */

static const char *const run_keys[] = {"steps", "t", "every", "progress", "energy", "momentum",
                                       "h", "chunk", "max_energy_error", "strict", "warn", "sink",
                                       "sink_every", NULL};

/* momentum = nil | boolean | {coordinate names}: the flags of the
 * momentum columns.  Without a Lagrangian system (ls NULL: a system on a
 * group), or for one with a momentum map (on S^2), the columns are those
 * of the system's momentum map, all or none. */
static void read_momentum(lua_State *L, int o, const dm_lsystem *ls, const dm_system *sys,
                          unsigned char *mom)
{
  int type = lua_getfield(L, o, "momentum");
  if (ls == NULL || sys->momentum_map != NULL) {
    if (type != LUA_TNIL && type != LUA_TBOOLEAN)
      luaL_error(L, "run: option 'momentum' must be a boolean for a system on %s (the "
                 "%s momentum columns momentum_1..), got %s", ls == NULL ? "a group" :
                 sys->space, ls == NULL ? "spatial" : "angular", luaL_typename(L, -1));
    memset(mom, sys->momentum_map != NULL && (type == LUA_TNIL || lua_toboolean(L, -1)),
           sys->n);
  } else if (type == LUA_TNIL) {
    memcpy(mom, ls->cyclic, ls->n);
  } else if (type == LUA_TBOOLEAN) {
    if (lua_toboolean(L, -1))
      memcpy(mom, ls->cyclic, ls->n);
  } else if (type == LUA_TTABLE) {
    size_t k = lua_rawlen(L, -1);
    for (size_t i = 1; i <= k; i++) {
      long c = -1;
      if (lua_rawgeti(L, -1, (lua_Integer)i) != LUA_TSTRING ||
          (c = dm_lua_system_coord(ls, lua_tostring(L, -1))) < 0)
        luaL_error(L, "run: momentum[%d] must name a coordinate of '%s', got %s", (int)i,
                   ls->sys.name, dm_tolstring(L, -1, NULL));
      mom[c] = 1;
      lua_pop(L, 1);
    }
  } else {
    luaL_error(L, "run: option 'momentum' must be a list of coordinate names or a boolean, got %s",
               luaL_typename(L, -1));
  }
  lua_pop(L, 1);
}

static void check_keys(lua_State *L, int o)
{
  lua_pushnil(L);
  while (lua_next(L, o) != 0) {
    const char *const *k = run_keys;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key && *k && strcmp(*k, key) != 0)
      k++;
    if (key == NULL || *k == NULL)
      luaL_error(L, "run: unknown option %s (options: steps, t, every, progress, energy, "
                 "momentum, h, chunk, max_energy_error, strict, warn, sink, sink_every)",
                 dm_tolstring(L, -2, NULL));
    lua_pop(L, 1);
  }
}

void dm_linteg_doc_run(lua_State *L)
{
  dm_doc_options(L, "integrator:run", run_keys);
}

/* The options table at o into r (momentum flags into mom, n bytes); h:
 * the integrator's step (NAN: none). */
static void read_runopts(lua_State *L, int o, const dm_integrator *I, const dm_lsystem *ls,
                         double h, dm_run_opts *r, int *show, unsigned char *mom)
{
  lua_Integer steps;
  int has_steps, has_t;
  dm_err e;
  check_keys(L, o);
  r->h = h;
  if (lua_getfield(L, o, "h") != LUA_TNIL) {
    r->h = lua_tonumber(L, -1);
    if (lua_type(L, -1) != LUA_TNUMBER || r->h == 0.0 || !isfinite(r->h))
      luaL_error(L, "run: option 'h' must be a finite non-zero number");
  }
  lua_pop(L, 1);
  if (isnan(r->h))
    luaL_error(L, "run: no step size: give h in dm.integrator(sys, {h = ...}) or in the run options");
  has_steps = lua_getfield(L, o, "steps") != LUA_TNIL;
  has_t = lua_getfield(L, o, "t") != LUA_TNIL;
  lua_pop(L, 2);
  if (has_steps == has_t)
    luaL_error(L, "run: give exactly one of steps = (a number of steps) or t = (the final time)");
  if (has_steps) {
    steps = dm_optintegerfield(L, o, "steps", 0);
    if (steps < 0)
      luaL_error(L, "run: steps must be >= 0, got %d", (int)steps);
    r->nsteps = (long)steps;
  } else if (dm_integrator_varstep(I)) {
    /* the integrator keeps the physical time: the run steps until t */
    r->t_end = dm_optnumberfield(L, o, "t", 0);
    if (dm_run_steps_to(r->t0, r->t_end, r->h, &r->nsteps, &e) != DM_OK)
      luaL_error(L, "run: %s", e.msg);
    r->nsteps = -1;
  } else if (dm_run_steps_to(r->t0, dm_optnumberfield(L, o, "t", 0), r->h, &r->nsteps, &e)
             != DM_OK) {
    luaL_error(L, "run: %s", e.msg);
  }
  steps = dm_optintegerfield(L, o, "every", 1);
  if (steps < 1)
    luaL_error(L, "run: every must be >= 1, got %d", (int)steps);
  r->every = (long)steps;
  steps = dm_optintegerfield(L, o, "chunk", 0);
  if (steps < 0)
    luaL_error(L, "run: chunk must be >= 1 (0: adaptive), got %d", (int)steps);
  r->piece = (long)steps;
  r->max_energy_error = dm_optnumberfield(L, o, "max_energy_error", 0);
  if (!(r->max_energy_error >= 0) || isinf(r->max_energy_error))
    luaL_error(L, "run: max_energy_error must be a finite number >= 0 (0: off)");
  *show = isatty(STDOUT_FILENO) && isatty(STDERR_FILENO);
  if (lua_getfield(L, o, "progress") != LUA_TNIL)
    *show = lua_toboolean(L, -1);
  r->energy = lua_getfield(L, o, "energy") == LUA_TNIL || lua_toboolean(L, -1);
  lua_pop(L, 2);
  read_momentum(L, o, ls, I->sys, mom);
  r->momentum = mom;
  dm_lua_run_check_flags(L, o);
}

/* }====================================================================== */

/* {======================================================================
 * streaming (sink) and the memory warning
 * ======================================================================= */

/* What the sink sends samples to: a Lua function (called under pcall
 * from inside the run: its error stops the run and is reported after
 * it), or a CSV or HDF5 file written in pieces. */
typedef struct sinkctx {
  lua_State *L;
  int fn, traj;             /* stack slots of the function and the trajectory */
  dm_traj_stream *file;
} sinkctx;

static int sink_call(void *ctx, const dm_traj *tr, dm_err *e)
{
  sinkctx *sc = ctx;
  if (sc->file != NULL)
    return dm_traj_stream_put(sc->file, tr, e);
  lua_State *L = sc->L;
  lua_pushvalue(L, sc->fn);
  lua_pushvalue(L, sc->traj);
  if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
    dm_err_set(e, DM_EFAILED, "%s", dm_tolstring(L, -1, NULL));
    lua_pop(L, 2);
    return DM_EFAILED;
  }
  return DM_OK;
}

/* sink = function(traj) | "file.csv" | "file.h5", sink_every = k into r / sc (the
 * file opened). */
static void read_sink(lua_State *L, int o, dm_run_opts *r, sinkctx *sc)
{
  int type = lua_getfield(L, o, "sink");
  if (type == LUA_TNIL) {
    lua_pop(L, 1);
    return;
  }
  lua_Integer k = dm_optintegerfield(L, o, "sink_every", 4096);
  if (k < 1)
    luaL_error(L, "run: sink_every must be >= 1, got %d", (int)k);
  r->sink_every = (long)k;
  if (type == LUA_TFUNCTION) {
    sc->fn = lua_gettop(L);
  } else if (type == LUA_TSTRING) {
    dm_err e;
    if (dm_traj_stream_open(lua_tostring(L, -1), &sc->file, &e) != DM_OK)
      luaL_error(L, "run: sink: %s", e.msg);
    lua_pop(L, 1);
  } else {
    luaL_error(L, "run: option 'sink' must be a function(traj) or a file name (.csv, .h5), "
               "got %s",
               luaL_typename(L, -1));
  }
  r->sink = sink_call;
  r->sink_ctx = sc;
}

/* dm.config.memory_limit (bytes), else half of the physical memory; the
 * warn flag: options, else dm.config.warn, else on. */
static double memory_limit(lua_State *L, int opts, int *warn)
{
  double lim = 0;
  int top = lua_gettop(L);
  *warn = 1;
  if (lua_getfield(L, LUA_REGISTRYINDEX, DM_LUA_DMTABLE) == LUA_TTABLE &&
      lua_getfield(L, -1, "config") == LUA_TTABLE) {
    if (lua_getfield(L, -1, "memory_limit") == LUA_TNUMBER)
      lim = lua_tonumber(L, -1);
    if (lua_getfield(L, -2, "warn") == LUA_TBOOLEAN)
      *warn = lua_toboolean(L, -1);
  }
  if (lua_istable(L, opts) && lua_getfield(L, opts, "warn") == LUA_TBOOLEAN)
    *warn = lua_toboolean(L, -1);
  lua_settop(L, top);
  if (lim > 0)
    return lim;
  long pages = sysconf(_SC_PHYS_PAGES), psize = sysconf(_SC_PAGESIZE);
  return pages > 0 && psize > 0 ? 0.5 * (double)pages * (double)psize : 0;
}

/* A warning (through io.stderr, like the run's other warnings) before a
 * run whose trajectory would take more than the limit. */
static void warn_memory(lua_State *L, int opts, const dm_integrator *I, const dm_run_opts *r)
{
  int warn, top = lua_gettop(L);
  double bytes = (double)dm_run_bytes(I, r), lim = memory_limit(L, opts, &warn);
  if (!warn || !(lim > 0 && bytes > lim))
    return;
  char msg[512];
  dm_num_snprintf(msg, sizeof msg, "warning: run: the trajectory will take %.3g MB (%ld steps, "
                  "every %ld, %zu coordinates), above dm.config.memory_limit = %.3g MB; record "
                  "less often (every = ...) or stream the samples (sink = \"file.csv\" or a "
                  "function, sink_every = ...)\n", bytes / 1048576.0, r->nsteps, r->every,
                  I->nq, lim / 1048576.0);
  if (lua_getglobal(L, "io") == LUA_TTABLE && lua_getfield(L, -1, "stderr") != LUA_TNIL &&
      lua_getfield(L, -1, "write") == LUA_TFUNCTION) {
    lua_insert(L, -2);
    lua_pushstring(L, msg);
    lua_call(L, 2, 0);
  } else {
    fputs(msg, stderr);
    fflush(stderr);
  }
  lua_settop(L, top);
}

/* }====================================================================== */

int dm_lua_integ_run(lua_State *L, dm_integrator *I, const dm_lsystem *ls, int o, double h,
                     double t0, double *q, double *p)
{
  size_t n = I->n;
  unsigned char *mom;
  dm_run_opts r;
  dm_run_result res;
  progress pg = {0, 0.0};
  dm_err e;
  int st, show;
  o = lua_absindex(L, o);
  mom = lua_newuserdatauv(L, n, 0);
  memset(mom, 0, n);
  dm_run_opts_init(&r);
  r.t0 = t0;
  read_runopts(L, o, I, ls, h, &r, &show, mom);
  if (show) {
    r.progress = progress_draw;
    r.progress_ctx = &pg;
  }
  sinkctx sc = { L, 0, 0, NULL };
  read_sink(L, o, &r, &sc);                      /* the function stays on the stack */
  warn_memory(L, o, I, &r);
  dm_traj **slot = dm_newtraj(L);                /* its home before it exists */
  int tslot = lua_gettop(L);
  if ((*slot = dm_run_traj_alloc(I, &e)) == NULL) {
    if (sc.file != NULL)
      dm_traj_stream_abandon(sc.file);
    return dm_lua_fail(L, "run", e.status, &e);
  }
  sc.traj = tslot;
  st = dm_run(I, q, p, &r, *slot, &res, &e);
  progress_end(&pg);
  if (sc.file != NULL) {                         /* the file appears, also after an early end */
    dm_err ce;
    /* the run's final metadata (steps, status, message) into the file */
    int cs = dm_traj_stream_meta(sc.file, *slot, &ce);
    if (cs != DM_OK)
      dm_traj_stream_abandon(sc.file);
    else
      cs = dm_traj_stream_close(sc.file, &ce);
    if (cs != DM_OK && st == DM_OK) {
      st = cs;
      e = ce;
    }
  }
  if (st == DM_EINTR)
    dm_interrupt_clear();
  if (st != DM_OK && res.samples == 0)
    return dm_lua_fail(L, "run", st, &e);
  lua_settop(L, tslot);
  if (st == DM_OK)
    return 1;
  return 1 + dm_lua_run_ended(L, o, st, e.msg);
}

int dm_linteg_run(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  dm_lstate s;
  if (lua_isnoneornil(L, 3)) {
    lua_settop(L, 2);
    lua_newtable(L);
  }
  luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  dm_linteg_readstate(L, li, 2, "run", &s);
  return dm_lua_integ_run(L, li->I, li->ls, 3, li->h, s.t, s.q, s.p);
}
