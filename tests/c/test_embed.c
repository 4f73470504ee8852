/* test_embed.c -- dmech embedded in a C host: a host that opens Lua states,
 * loads dmech, uses it and closes the states again must get every byte
 * back.  The expression context lives in the Lua registry and is freed by
 * a __gc metamethod at lua_close: a failing __gc is reported by Lua as a
 * warning ("error in __gc"), which this host captures, and the bytes in
 * use (counted by an interposed allocator) must be back where they were
 * once the states are closed (a leaked context is about a megabyte per
 * state; valgrind cannot see it when the state is never closed). */
#include <config.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include "lua/dmlua.h"
#include "interpose.h"
#include "tap.h"

static char warnings[4096];

static void warnf(void *ud, const char *msg, int tocont)
{
  size_t n = strlen(warnings);
  (void)ud;
  (void)tocont;
  if (msg[0] == '@')           /* control message (@on, @off) */
    return;
  snprintf(warnings + n, sizeof warnings - n, "%s", msg);
}

/* One state's life: load dmech, trace and differentiate, close. */
static int one_state(void)
{
  static const char chunk[] =
    "local dm = require 'dmech'\n"
    "local x, y = dm.sym('x'), dm.sym('y')\n"
    "local f = dm.sin(x) * y^2 + 2.385 * x\n"
    "assert(tostring(f:diff(y)) ~= '')\n"
    "local s = dm.system{coords = {'q'}, params = {k = 2.385}, native = 'never',\n"
    "  L = function(q, v, p) return 0.5 * v.q^2 - 0.5 * p.k * q.q^2 end}\n"
    "return tostring(s)\n";
  lua_State *L = luaL_newstate();
  int ok;
  if (L == NULL)
    return 0;
  lua_setwarnf(L, warnf, NULL);
  luaL_openlibs(L);
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
  lua_pushcfunction(L, luaopen_dmech);
  lua_setfield(L, -2, "dmech");
  lua_pop(L, 1);
  ok = luaL_dostring(L, chunk) == LUA_OK;
  if (!ok)
    printf("# %s\n", lua_tostring(L, -1));
  lua_close(L);
  return ok;
}

int main(void)
{
  long long before, after;
  int ok = 1, i;
  ok &= one_state();                 /* warm-up: libc, GSL, dlopen caches */
  before = ip_live;
  for (i = 0; i < 10; i++)
    ok &= one_state();
  after = ip_live;
  tap_ok(ok, "11 states load dmech, trace a Lagrangian and close");
  tap_ok(warnings[0] == '\0', "no warning at lua_close (got: '%s')", warnings);
  if (IP_ACTIVE)
    tap_ok(after == before, "bytes in use after 10 more states and lua_close: "
           "%lld -> %lld", before, after);
  else
    tap_skip("no interposed allocator in this build (sanitizer)");
  return tap_done();
}
