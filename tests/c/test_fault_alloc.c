/* test_fault_alloc.c -- every allocation may fail: with the k-th
 * allocation of a scenario refused (an interposed allocator, as in
 * test_step_nomalloc.c), dmech must end the scenario with a clear error
 * (a message about memory) or complete it, never crash, and leave a usable
 * session that leaks nothing: after the failure the same state runs the
 * scenario again successfully, and when it is closed every byte is back.
 *
 * Each scenario is a Lua chunk run in a fresh state (created before the
 * allocator is armed).  A first run counts its allocations N; then k runs
 * over a sample of 1..N (every k up to 40, then evenly spaced), or over
 * every k when $DMECH_FAULT_ALL is set (CI's fault stage: tens of thousands
 * of runs); $DMECH_FAULT_ONLY="<scenario>:<k>" reproduces one run (under a
 * debugger).  Numbers are printed as TAP diagnostics. */
#include <config.h>
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include "lua/dmlua.h"
#include "interpose.h"
#include "tap.h"

static const struct scenario {
  const char *name, *chunk;
} scenarios[] = {
  {"system, integrator, run, save and load",
   "local dm = require 'dmech'\n"
   "local s = dm.system{coords = {'x', 'y'}, params = {k = 2.385}, native = 'never',\n"
   "  L = function(q, v, p) return 0.5 * (v.x^2 + v.y^2) - p.k * (q.x^2 + q.y^4) end}\n"
   "local g = dm.integrator(s, {method = 'gauss', stages = 2, h = 0.05})\n"
   "local tr = assert(g:run({q = {1, 0.5}, v = {0, 0.2}}, {steps = 20, every = 2}))\n"
   "assert(#tr == 11 and tr:energy()[11] == tr:energy()[11])\n"
   "assert(tr:save(os.getenv('FAULT_FILE')))\n"
   "local back = assert(dm.load_trajectory(os.getenv('FAULT_FILE')))\n"
   "return #back\n"},
  {"expressions: derivatives, a compiled function",
   "local dm = require 'dmech'\n"
   "local x, y = dm.sym 'x', dm.sym 'y'\n"
   "local f = dm.exp(-x^2) * dm.sin(2.385 * y) + x * y\n"
   "local h = f:hessian{x, y}\n"
   "local fn = dm.fn{inputs = {x, y}, outputs = {f, f:diff(x)}, native = 'never'}\n"
   "local r = fn(0.5, 0.25)\n"
   "return tostring(h[1][2]) ~= '' and r[1] + r[2]\n"},
  {"Routh reduction: reduced run and reconstruction",
   "local dm = require 'dmech'\n"
   "local s = dm.system{coords = {'r', 'th'}, params = {mu = 2.385}, native = 'never',\n"
   "  L = function(q, v, p) return 0.5 * (v.r^2 + q.r^2 * v.th^2) + p.mu / q.r end}\n"
   "local red = dm.routh(s, {cyclic = {'th'}, mu = 1.1, native = 'never'})\n"
   "local rt = assert(dm.integrator(red, {method = 'gauss', h = 0.05})\n"
   "  :run({q = {1.3}, v = {0.1}}, {steps = 8}))\n"
   "return #red:reconstruct(rt)\n"},
  {"vectors, matrices, a trajectory from data",
   "local dm = require 'dmech'\n"
   "local m = dm.mat{{4, 1, 0}, {1, 3, 1}, {0, 1, 2.385}}\n"
   "local v = m:solve(dm.vec{1, 2, 3})\n"
   "local tr = dm.trajectory{t = {0, 1, 2}, coords = {'a'}, q = {a = {1, 2, 3}},\n"
   "  columns = {e = {v[1], v[2], v[3]}}, meta = {note = 'x'}}\n"
   "return tr:slice(2, 3):column('e')[1] + m:det()\n"},
};

/* The chunk in state L; 1 on success, else the message in msg. */
static int run_chunk(lua_State *L, const char *chunk, char *msg, size_t size)
{
  int ok = luaL_dostring(L, chunk) == LUA_OK;
  const char *m = lua_tostring(L, -1);
  snprintf(msg, size, "%s", ok ? "" : m != NULL ? m : "(error object is not a string)");
  lua_settop(L, 0);
  return ok;
}

static lua_State *new_state(void)
{
  lua_State *L = luaL_newstate();
  if (L == NULL)
    return NULL;
  luaL_openlibs(L);
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
  lua_pushcfunction(L, luaopen_dmech);
  lua_setfield(L, -2, "dmech");
  lua_pop(L, 1);
  return L;
}

static int about_memory(const char *msg)
{
  char low[600];
  size_t i;
  for (i = 0; msg[i] != '\0' && i + 1 < sizeof low; i++)
    low[i] = (char)tolower((unsigned char)msg[i]);
  low[i] = '\0';
  return strstr(low, "memory") != NULL;
}

/* "trajectory: trajectory: out of memory": a prefix said twice */
static int stutters(const char *msg)
{
  for (const char *w = msg; *w != '\0'; w++) {
    if (w != msg && w[-1] != ' ')
      continue;
    size_t n = strcspn(w, ": ");
    if (n > 0 && w[n] == ':' && w[n + 1] == ' ' && strncmp(w + n + 2, w, n + 1) == 0)
      return 1;
  }
  return 0;
}

/* Scenario s with its k-th allocation refused; 0 when something is wrong
 * (diagnosed: an unclear message, an unusable session, memory not given
 * back when the state is closed), else 1.  *errors counts the runs that
 * ended in an error. */
static int one(const struct scenario *s, long k, long *errors, char *first_msg)
{
  char msg[600];
  long long live0;
  lua_State *L;
  int ok, again;
  live0 = ip_live;
  L = new_state();
  if (L == NULL || !run_chunk(L, "require 'dmech'", msg, sizeof msg)) {
    tap_diag("cannot set up a state: %s", msg);
    return 0;
  }
  ip_fail_at(k);
  ok = run_chunk(L, s->chunk, msg, sizeof msg);
  ip_fail_at(0);
  if (!ok) {
    (*errors)++;
    if (!about_memory(msg) || stutters(msg)) {
      tap_diag("%s, allocation %ld refused: unclear error: %s", s->name, k, msg);
      lua_close(L);
      return 0;
    }
    if (first_msg[0] == '\0')
      snprintf(first_msg, 600, "%s", msg);
  }
  again = run_chunk(L, s->chunk, msg, sizeof msg);
  if (!again)
    tap_diag("%s, allocation %ld refused: the session is not usable after it: %s",
             s->name, k, msg);
  lua_close(L);
  if (ip_live != live0) {
    tap_diag("%s, allocation %ld refused: %lld bytes not freed", s->name, k,
             ip_live - live0);
    return 0;
  }
  return again;
}

int main(void)
{
  char path[4200];
  const char *tt = getenv("DMECH_TESTTMP");
  int all = getenv("DMECH_FAULT_ALL") != NULL && getenv("DMECH_FAULT_ALL")[0] != '\0';
  size_t i;
  if (!IP_ACTIVE) {
    printf("1..0 # SKIP no interposed allocator in this build (sanitizer)\n");
    return 0;
  }
  /* stdout's buffer is allocated at the first printf: before any count */
  tap_diag("scenarios with the k-th allocation refused (%s)", all ? "every k" : "a sample of k");
  snprintf(path, sizeof path, "%s/fault_alloc.csv", tt != NULL && *tt ? tt : "/tmp");
  setenv("FAULT_FILE", path, 1);
  if (getenv("DMECH_FAULT_ONLY") != NULL) {
    long si = 0, k = 0, errors = 0;
    char first[600] = "";
    if (sscanf(getenv("DMECH_FAULT_ONLY"), "%ld:%ld", &si, &k) != 2 || si < 0
        || (size_t)si >= sizeof scenarios / sizeof scenarios[0])
      return 2;
    tap_ok(one(&scenarios[si], k, &errors, first), "%s, allocation %ld refused: %s",
           scenarios[si].name, k, first[0] ? first : "completed");
    return tap_done();
  }
  for (i = 0; i < sizeof scenarios / sizeof scenarios[0]; i++) {
    const struct scenario *s = &scenarios[i];
    char msg[600], first[600] = "";
    long n, k, step, runs = 0, errors = 0, bad = 0;
    long long live0;
    lua_State *L;
    /* warm-up (caches created once per process), then count: a clean run */
    L = new_state();
    run_chunk(L, s->chunk, msg, sizeof msg);
    lua_close(L);
    live0 = ip_live;
    L = new_state();
    run_chunk(L, "require 'dmech'", msg, sizeof msg);
    n = ip_count;
    if (!run_chunk(L, s->chunk, msg, sizeof msg)) {
      tap_ok(0, "%s: runs without faults (%s)", s->name, msg);
      lua_close(L);
      continue;
    }
    n = ip_count - n;
    lua_close(L);
    step = all || n <= 40 ? 1 : (n - 40) / 60 + 1;
    for (k = 1; k <= n; k += k < 40 ? 1 : step) {
      runs++;
      bad += !one(s, k, &errors, first);
      if (bad > 5)
        break;
    }
    tap_ok(bad == 0, "%s: %ld allocations; refused one at a time in %ld runs, %ld ended "
           "in an error about memory, the others completed; the session worked after "
           "each", s->name, n, runs, errors);
    if (first[0] != '\0')
      tap_diag("first message: %s", first);
    tap_ok(ip_live == live0, "%s: every byte back after the %ld closed states (%lld -> %lld)",
           s->name, runs + 1, live0, ip_live);
  }
  unlink(path);
  return tap_done();
}
