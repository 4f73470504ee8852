/* l_integ_run.c -- integ:run(state, {...}) -> Trajectory[, message].
 *
 * The loop is C: dm_integrator_run, called on pieces of the run so that a
 * progress line can be updated between pieces (when enabled; otherwise the
 * run is one piece).  Piece boundaries fall on multiples of `every` or, for
 * sparse sampling, inside an interval between samples; a sink in front of
 * the trajectory keeps exactly the samples one uninterrupted run would
 * record (steps 0, every, 2 every, ..., the last step) with the times
 * t0 + k h.  Ctrl-C (DM_EINTR) and numerical failures keep the trajectory
 * computed so far: it is returned with a message saying where the run
 * stopped; the interrupt flag is cleared so the REPL does not raise.
 * Energy and momentum diagnostics are added as columns after the run. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "lua/l_integ.h"
#include "core/interrupt.h"
#include "core/trajectory.h"

/* {======================================================================
 * the sink: exactly the samples of one uninterrupted run
 * ======================================================================= */

typedef struct runctx {
  dm_traj *tr;
  size_t n;
  long every, nsteps;       /* of the whole run */
  long kstart;              /* global index of the current piece's first step */
  long last_k;              /* global index of the last recorded sample (-1: none) */
  long pend_k;              /* global index of the pending (not recorded) emission */
  double t0, h, tpiece;     /* start time, step, current piece's start time */
  double *pq, *pp, *pv;     /* the pending emission (n each) */
} runctx;

static int run_sink(void *ctx, double t, const double *q, const double *p, const double *v)
{
  runctx *c = ctx;
  long k = c->kstart + lround((t - c->tpiece) / c->h);
  int st;
  if (k == c->last_k)
    return 0;
  if (k % c->every != 0 && k != c->nsteps) {
    /* not a sample point; kept in case the run stops here */
    memcpy(c->pq, q, c->n * sizeof *q);
    memcpy(c->pp, p, c->n * sizeof *p);
    memcpy(c->pv, v, c->n * sizeof *v);
    c->pend_k = k;
    return 0;
  }
  if ((st = dm_traj_append(c->tr, c->t0 + (double)k * c->h, q, p, v, NULL, NULL)) != DM_OK)
    return st;
  c->last_k = k;
  return 0;
}

/* }====================================================================== */

/* {======================================================================
 * progress on stderr (between pieces; numerics never print)
 * ======================================================================= */

typedef struct progress {
  int on, shown;
  double start, last;
} progress;

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Shown only for runs longer than half a second, at most 4 times a second. */
static void progress_update(progress *pg, long k, long nsteps, double t)
{
  double tn = now(), el = tn - pg->start, rate;
  if (!pg->on || el < 0.5 || tn - pg->last < 0.25)
    return;
  pg->last = tn;
  rate = el > 0 ? (double)k / el : 0;
  fprintf(stderr, "\r  run: step %ld/%ld (%4.1f%%)  t = %-12.6g %9.3g steps/s  ETA %.0f s  ",
          k, nsteps, nsteps ? 100.0 * (double)k / (double)nsteps : 100.0, t, rate,
          rate > 0 ? (double)(nsteps - k) / rate : 0.0);
  fflush(stderr);
  pg->shown = 1;
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

typedef struct runopts {
  long nsteps, every, chunk;
  double h;
  int progress, energy;
  unsigned char *mom;       /* n flags: momentum columns */
} runopts;

static const char *const run_keys[] = {"steps", "t", "every", "progress", "energy", "momentum",
                                       "h", "chunk", NULL};

static void read_momentum(lua_State *L, int o, const dm_lsystem *ls, unsigned char *mom)
{
  int type = lua_getfield(L, o, "momentum");
  if (type == LUA_TNIL) {
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
                   ls->sys.name, luaL_tolstring(L, -1, NULL));
      mom[c] = 1;
      lua_pop(L, 1);
    }
  } else {
    luaL_error(L, "run: option 'momentum' must be a list of coordinate names or a boolean, got %s",
               luaL_typename(L, -1));
  }
  lua_pop(L, 1);
}

static void read_runopts(lua_State *L, int o, dm_linteg *li, double t0, runopts *r)
{
  lua_Integer steps;
  int has_steps, has_t;
  lua_pushnil(L);
  while (lua_next(L, o) != 0) {
    const char *const *k = run_keys;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key && *k && strcmp(*k, key) != 0)
      k++;
    if (key == NULL || *k == NULL)
      luaL_error(L, "run: unknown option %s (options: steps, t, every, progress, energy, "
                 "momentum, h, chunk)", luaL_tolstring(L, -2, NULL));
    lua_pop(L, 1);
  }
  r->h = li->h;
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
  if (has_steps == has_t)
    luaL_error(L, "run: give exactly one of steps = (a number of steps) or t = (the final time)");
  if (has_steps) {
    steps = dm_optintegerfield(L, o, "steps", 0);
    if (steps < 0)
      luaL_error(L, "run: steps must be >= 0, got %d", (int)steps);
    r->nsteps = (long)steps;
  } else {
    double T = dm_optnumberfield(L, o, "t", 0), x = (T - t0) / r->h;
    if (!isfinite(x) || x < -0.5 || x > 9e15) {
      char a[32], b[32], c[32];
      dm_fmtnum(a, sizeof a, T);
      dm_fmtnum(b, sizeof b, t0);
      dm_fmtnum(c, sizeof c, r->h);
      luaL_error(L, "run: the final time t = %s cannot be reached from t0 = %s with h = %s", a, b, c);
    }
    r->nsteps = lround(x);
  }
  lua_pop(L, 2);
  steps = dm_optintegerfield(L, o, "every", 1);
  if (steps < 1)
    luaL_error(L, "run: every must be >= 1, got %d", (int)steps);
  r->every = (long)steps;
  steps = dm_optintegerfield(L, o, "chunk", 0);
  if (steps < 0)
    luaL_error(L, "run: chunk must be >= 1 (0: adaptive), got %d", (int)steps);
  r->chunk = (long)steps;
  r->progress = isatty(STDOUT_FILENO) && isatty(STDERR_FILENO);
  if (lua_getfield(L, o, "progress") != LUA_TNIL)
    r->progress = lua_toboolean(L, -1);
  r->energy = lua_getfield(L, o, "energy") == LUA_TNIL || lua_toboolean(L, -1);
  lua_pop(L, 2);
  read_momentum(L, o, li->ls, r->mom);
}

/* }====================================================================== */

/* {======================================================================
 * the trajectory: metadata and diagnostic columns
 * ======================================================================= */

static void set_meta(lua_State *L, dm_traj *tr, const char *key, const char *val)
{
  dm_err e;
  if (dm_traj_meta_set(tr, key, val, &e) != DM_OK)
    dm_lua_fail(L, "run", e.status, &e);
}

static void set_meta_num(lua_State *L, dm_traj *tr, const char *key, double x)
{
  char buf[32];
  dm_fmtnum(buf, sizeof buf, x);
  set_meta(L, tr, key, buf);
}

static void add_metadata(lua_State *L, dm_linteg *li, dm_traj *tr, double h)
{
  const dm_system *s = &li->ls->sys;
  char key[300];
  lua_Integer st;
  set_meta(L, tr, "system", s->name);
  set_meta(L, tr, "method", li->method);
  lua_getfield(L, 1, "stages");         /* the integrator's field */
  st = lua_tointeger(L, -1);
  lua_pop(L, 1);
  if (st > 0 && strcmp(li->method, "midpoint") != 0 && strcmp(li->method, "trapezoid") != 0)
    set_meta_num(L, tr, "stages", (double)st);
  set_meta_num(L, tr, "h", h);
  set_meta_num(L, tr, "order", li->I->order);
  for (size_t i = 0; i < s->npar; i++) {
    snprintf(key, sizeof key, "param.%s", s->params[i]);
    set_meta_num(L, tr, key, s->par[i]);
  }
}

/* energy and momentum_<coord> columns over every sample */
static void add_diagnostics(lua_State *L, dm_linteg *li, dm_traj *tr, const runopts *r)
{
  size_t n = li->ls->n, len = dm_traj_len(tr), i, k;
  double *col, *q = li->buf + 6 * n, *v = li->buf + 7 * n;
  dm_err e;
  if (len == 0)
    return;
  col = lua_newuserdatauv(L, len * sizeof *col, 0);
  if (r->energy) {
    for (k = 0; k < len; k++) {
      for (i = 0; i < n; i++) {
        q[i] = dm_traj_col(tr, dm_traj_qcol(tr, i))[k];
        v[i] = dm_traj_col(tr, dm_traj_vcol(tr, i))[k];
      }
      if (dm_integrator_energy(li->I, q, v, &col[k], NULL) != DM_OK)
        col[k] = NAN;
    }
    if (dm_traj_add_column(tr, DM_TRAJ_ENERGY, DM_TRAJ_DIAG, col, DM_TRAJ_REPLACE, &e) != DM_OK)
      dm_lua_fail(L, "run", e.status, &e);
  }
  for (i = 0; i < n; i++)
    if (r->mom[i]) {
      char name[DM_TRAJ_NAME_MAX + 1];
      memcpy(col, dm_traj_col(tr, dm_traj_pcol(tr, i)), len * sizeof *col);
      snprintf(name, sizeof name, "%s%s", DM_TRAJ_MOMENTUM, li->ls->sys.coords[i]);
      if (dm_traj_add_column(tr, name, DM_TRAJ_DIAG, col, DM_TRAJ_REPLACE, &e) != DM_OK)
        dm_lua_fail(L, "run", e.status, &e);
    }
  lua_pop(L, 1);
}

/* }====================================================================== */

/* {======================================================================
 * the driver
 * ======================================================================= */

/* End of the piece starting at step k, about P steps: whole intervals
 * between samples when k is a sample step, else no further than the next
 * sample step (so no sample is skipped); never past nsteps. */
static long piece_end(long k, long P, long every, long nsteps)
{
  long next = (k / every + 1) * every, end;
  if (k % every == 0 && P >= every)
    end = P >= nsteps - k ? nsteps : (k + P) / every * every;
  else
    end = k + P < next ? k + P : next;
  return end < nsteps ? end : nsteps;
}

/* The failure text without dm_integrator_run's "step i of m ...: " prefix,
 * which counts steps of the piece, not of the run. */
static const char *inner_message(const dm_err *e)
{
  const char *s = strstr(e->msg, " failed: ");
  if (s != NULL)
    return s + 9;
  s = strstr(e->msg, "): ");
  return s != NULL ? s + 3 : e->msg;
}

int dm_linteg_run(lua_State *L)
{
  dm_linteg *li = dm_linteg_check(L, 1);
  size_t n = li->ls->n;
  dm_lstate s;
  runopts r;
  runctx c;
  progress pg;
  dm_run_info info;
  dm_err e;
  long k = 0, P;
  int st = DM_OK;
  if (lua_isnoneornil(L, 3)) {
    lua_settop(L, 2);
    lua_newtable(L);
  }
  luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  dm_linteg_readstate(L, li, 2, "run", &s);
  r.mom = lua_newuserdatauv(L, n, 0);                            /* 4 */
  memset(r.mom, 0, n);
  read_runopts(L, 3, li, s.t, &r);

  dm_traj *tr = dm_pushtraj(L, n, li->ls->sys.coords, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V); /* 5 */
  add_metadata(L, li, tr, r.h);
  /* best effort; beyond 2^20 samples the storage grows by doubling */
  dm_traj_reserve(tr, (size_t)(r.nsteps / r.every < (1L << 20) ? r.nsteps / r.every + 2 : 1L << 20),
                  NULL);

  memset(&c, 0, sizeof c);
  c.tr = tr;
  c.n = n;
  c.every = r.every;
  c.nsteps = r.nsteps;
  c.last_k = c.pend_k = -1;
  c.t0 = s.t;
  c.h = r.h;
  c.pq = li->buf + 6 * n;
  c.pp = li->buf + 7 * n;
  c.pv = li->buf + 8 * n;
  memset(&pg, 0, sizeof pg);
  pg.on = r.progress;
  pg.start = pg.last = now();
  P = r.chunk > 0 ? r.chunk : pg.on ? (r.every < 64 ? 64 : r.every) : r.nsteps;
  dm_err_clear(&e);
  do {
    long end = piece_end(k, P, r.every, r.nsteps);
    double tp = now();
    c.kstart = k;
    c.tpiece = s.t + (double)k * r.h;
    st = dm_integrator_run(li->I, c.tpiece, s.q, s.p, r.h, end - k,
                           k % r.every == 0 || end == k ? r.every : end - k, run_sink, &c,
                           &info, &e);
    k += info.steps;
    if (pg.on && r.chunk == 0) {
      double dt = now() - tp;
      P = dt > 1e-3 ? (long)((double)P * fmin(16.0, fmax(0.5, 0.1 / dt))) : 16 * P;
      if (P < 1)
        P = 1;
    }
    if (pg.on)
      progress_update(&pg, k, r.nsteps, s.t + (double)k * r.h);
  } while (st == DM_OK && k < r.nsteps);
  progress_end(&pg);

  /* the last good state when the run stopped between sample points */
  if (st != DM_OK && c.last_k != k && c.pend_k == k &&
      dm_traj_append(tr, s.t + (double)k * r.h, c.pq, c.pp, c.pv, NULL, NULL) == DM_OK)
    c.last_k = k;
  if (st != DM_OK && dm_traj_len(tr) == 0)
    return dm_lua_fail(L, "run", st, &e);
  add_diagnostics(L, li, tr, &r);
  lua_settop(L, 5);
  if (st == DM_OK)
    return 1;
  char tk[32];
  dm_fmtnum(tk, sizeof tk, s.t + (double)k * r.h);
  if (st == DM_EINTR) {
    dm_interrupt_clear();
    lua_pushfstring(L, "run: interrupted after step %I of %I (t = %s); the trajectory up to "
                    "there is returned", (lua_Integer)k, (lua_Integer)r.nsteps, tk);
  } else {
    lua_pushfstring(L, "run: step %I of %I from t = %s failed: %s; the trajectory up to there "
                    "is returned", (lua_Integer)k + 1, (lua_Integer)r.nsteps, tk,
                    inner_message(&e));
  }
  return 2;
}
