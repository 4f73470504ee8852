/* fuzz_host.c -- dmech-fuzz: a Lua host for tests/fuzz/fuzz.lua.
 *
 *   dmech-fuzz fuzz.lua <mode> [args...]
 *
 * Like `dmech script.lua`, with a `fuzz` table the driver uses:
 *   fuzz.call(seconds, f, ...) -> ok, results... | false, error
 *       pcall with a time limit: after `seconds` the interrupt flag is
 *       raised (C loops stop with DM_EINTR) and a hook stops Lua code with
 *       the error "fuzz: time limit"; a call still running 20 s later
 *       ($FUZZ_HARD_LIMIT) is a hang: "HANG" is written to stderr and the process exits with 3
 *       (the driver has written the reproducer of the call beforehand).
 *   fuzz.limit_memory(megabytes)  address-space limit (setrlimit), so an
 *       allocation bomb fails instead of swapping; a no-op under
 *       AddressSanitizer, whose allocator is limited by its own options.
 *   fuzz.report(text)  write to the real standard output: the process's
 *       stdout points at /dev/null (help() and friends print a lot).
 *   fuzz.now()       monotonic clock, seconds.
 *   fuzz.sanitized   true when built with AddressSanitizer.
 * The state is closed at the end, so leak checkers see what was not
 * freed.  Exit status: the script's (os.exit), 1 on an error. */
#include <config.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include "core/interrupt.h"
#include "lua/dmlua.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FUZZ_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define FUZZ_ASAN 1
#endif

#define HARD_LIMIT 20         /* seconds after the soft limit ($FUZZ_HARD_LIMIT) */
static long hard_limit = HARD_LIMIT;

static lua_State *hookL;
static volatile sig_atomic_t stage;    /* 0 idle, 1 armed, 2 soft limit hit */

static void stop_hook(lua_State *L, lua_Debug *ar)
{
  (void)ar;
  lua_sethook(L, NULL, 0, 0);
  luaL_error(L, "fuzz: time limit");
}

static void on_alarm(int sig)
{
  static const char msg[] = "HANG: a call ran past the hard time limit\n";
  struct itimerval it = {{0, 0}, {hard_limit, 0}};
  (void)sig;
  if (stage == 1) {
    stage = 2;
    dm_interrupt_raise();
    lua_sethook(hookL, stop_hook, LUA_MASKCALL | LUA_MASKRET | LUA_MASKCOUNT, 1);
    setitimer(ITIMER_REAL, &it, NULL);
    return;
  }
  if (write(2, msg, sizeof msg - 1) < 0) {
    /* nothing more to do */
  }
  _exit(3);
}

static void arm(double seconds)
{
  struct itimerval it;
  memset(&it, 0, sizeof it);
  it.it_value.tv_sec = (time_t)seconds;
  it.it_value.tv_usec = (suseconds_t)((seconds - (double)(time_t)seconds) * 1e6);
  if (it.it_value.tv_sec == 0 && it.it_value.tv_usec == 0)
    it.it_value.tv_usec = 1000;
  stage = 1;
  setitimer(ITIMER_REAL, &it, NULL);
}

static void disarm(lua_State *L)
{
  struct itimerval it;
  memset(&it, 0, sizeof it);
  setitimer(ITIMER_REAL, &it, NULL);
  stage = 0;
  lua_sethook(L, NULL, 0, 0);
  dm_interrupt_clear();
}

static int f_call(lua_State *L)
{
  double t = luaL_checknumber(L, 1);
  int n = lua_gettop(L) - 2, st, base;
  luaL_checkany(L, 2);
  lua_remove(L, 1);                        /* f, args */
  base = lua_gettop(L) - n - 1;
  hookL = L;
  arm(t);
  st = lua_pcall(L, n, LUA_MULTRET, 0);
  disarm(L);
  lua_pushboolean(L, st == LUA_OK);
  lua_insert(L, base + 1);
  return lua_gettop(L) - base;
}

static int f_limit_memory(lua_State *L)
{
  lua_Integer mb = luaL_checkinteger(L, 1);
#ifndef FUZZ_ASAN
  struct rlimit r;
  r.rlim_cur = r.rlim_max = (rlim_t)mb << 20;
  lua_pushboolean(L, setrlimit(RLIMIT_AS, &r) == 0);
#else
  (void)mb;
  lua_pushboolean(L, 0);
#endif
  return 1;
}

static FILE *report_file;

static int f_report(lua_State *L)
{
  size_t n;
  const char *s = luaL_checklstring(L, 1, &n);
  fwrite(s, 1, n, report_file);
  fflush(report_file);
  return 0;
}

static int f_now(lua_State *L)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  lua_pushnumber(L, (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec);
  return 1;
}

static int open_fuzz(lua_State *L)
{
  static const luaL_Reg f[] = {{"call", f_call}, {"limit_memory", f_limit_memory},
                               {"report", f_report}, {"now", f_now}, {NULL, NULL}};
  luaL_newlib(L, f);
#ifdef FUZZ_ASAN
  lua_pushboolean(L, 1);
#else
  lua_pushboolean(L, 0);
#endif
  lua_setfield(L, -2, "sanitized");
  return 1;
}

static int msghandler(lua_State *L)
{
  const char *msg = lua_tostring(L, 1);
  luaL_traceback(L, L, msg != NULL ? msg : "(error object is not a string)", 1);
  return 1;
}

int main(int argc, char **argv)
{
  lua_State *L;
  int i, st, code = 0;
  struct sigaction sa;
  if (getenv("FUZZ_HARD_LIMIT") != NULL && atol(getenv("FUZZ_HARD_LIMIT")) > 0)
    hard_limit = atol(getenv("FUZZ_HARD_LIMIT"));
  if (argc < 2) {
    fprintf(stderr, "usage: %s fuzz.lua mode [args...]\n", argv[0]);
    return 2;
  }
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_alarm;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGALRM, &sa, NULL);
  signal(SIGXFSZ, SIG_IGN);
  signal(SIGPIPE, SIG_IGN);
  report_file = fdopen(dup(1), "w");
  if (report_file == NULL || freopen("/dev/null", "w", stdout) == NULL)
    return 1;
  L = luaL_newstate();
  if (L == NULL)
    return 1;
  luaL_openlibs(L);
  dm_lua_number_tostring(L);                  /* as the dmech program */
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
  lua_pushcfunction(L, luaopen_dmech);
  lua_setfield(L, -2, "dmech");
  lua_pop(L, 1);
  luaL_requiref(L, "fuzz", open_fuzz, 1);
  lua_pop(L, 1);
  lua_createtable(L, argc, 0);
  for (i = 0; i < argc; i++) {
    lua_pushstring(L, argv[i]);
    lua_rawseti(L, -2, i - 1);
  }
  lua_setglobal(L, "arg");
  lua_pushcfunction(L, msghandler);
  st = luaL_loadfile(L, argv[1]);
  if (st == LUA_OK) {
    for (i = 2; i < argc; i++)
      lua_pushstring(L, argv[i]);
    st = lua_pcall(L, argc - 2, 1, 1);
  }
  if (st != LUA_OK) {
    fprintf(stderr, "%s: %s\n", argv[0], lua_tostring(L, -1));
    code = 1;
  } else if (lua_isinteger(L, -1)) {
    code = (int)lua_tointeger(L, -1);
  }
  lua_close(L);
  return code;
}
