/* laux.c -- argument checking and error helpers shared by the bindings. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/mpi.h"
#include "core/numfmt.h"
#include "lua/dmlua.h"

int dm_lua_fail(lua_State *L, const char *what, int status, const dm_err *e)
{
  /* a record the failing call did not fill (its status differs) is not
   * trusted: its message may be stale or never written */
  const char *msg = (e != NULL && e->status == status && e->msg[0] != '\0'
                     && memchr(e->msg, '\0', sizeof e->msg) != NULL)
                    ? e->msg : dm_strstatus(status);
  size_t n = strlen(what);
  /* a message that already starts with "<what>: " is not prefixed twice */
  if (strncmp(msg, what, n) == 0 && msg[n] == ':' && msg[n + 1] == ' ')
    return luaL_error(L, "%s", msg);
  return luaL_error(L, "%s: %s", what, msg);
}

int dm_argexpected(lua_State *L, int arg, const char *expected,
                   const char *actual)
{
  const char *msg = lua_pushfstring(L, "%s expected, got %s", expected, actual);
  return luaL_argerror(L, arg, msg);
}

/* __tostring of numbers: Lua's own conversion, except "nan" for every NaN
 * (the NaN of 0/0 prints "-nan" on x86-64). */
static int number_tostring(lua_State *L)
{
  if (lua_type(L, 1) == LUA_TNUMBER && !lua_isinteger(L, 1) && isnan(lua_tonumber(L, 1))) {
    lua_pushliteral(L, "nan");
    return 1;
  }
  lua_pushvalue(L, 1);
  lua_tolstring(L, -1, NULL);      /* the raw conversion: no metamethod */
  return 1;
}

void dm_lua_number_tostring(lua_State *L)
{
  lua_pushinteger(L, 0);
  if (!lua_getmetatable(L, -1))
    lua_createtable(L, 0, 1);
  lua_pushcfunction(L, number_tostring);
  lua_setfield(L, -2, "__tostring");
  lua_setmetatable(L, -2);
  lua_pop(L, 1);
}

const char *dm_tolstring(lua_State *L, int idx, size_t *len)
{
  if (lua_type(L, idx) == LUA_TNUMBER && !lua_isinteger(L, idx)
      && !isfinite(lua_tonumber(L, idx))) {
    char buf[DM_NUM_BUFSIZE];
    dm_num_format(buf, sizeof buf, lua_tonumber(L, idx));
    return lua_pushlstring(L, buf, len != NULL ? (*len = strlen(buf)) : strlen(buf));
  }
  return luaL_tolstring(L, idx, len);
}

int dm_checkoption(lua_State *L, int arg, const char *def, const char *const lst[])
{
  if (lua_type(L, arg) == LUA_TNUMBER)
    luaL_checktype(L, arg, LUA_TSTRING);
  return luaL_checkoption(L, arg, def, lst);
}

const char *dm_checkcstring(lua_State *L, int arg)
{
  size_t len;
  const char *s;
  if (lua_type(L, arg) != LUA_TSTRING)     /* no number coerced to "-nan" */
    luaL_checktype(L, arg, LUA_TSTRING);
  s = lua_tolstring(L, arg, &len);
  if (strlen(s) != len)
    dm_argexpected(L, arg, "string without NUL bytes",
                   lua_pushfstring(L, "a string with a NUL byte at position %d",
                                   (int)strlen(s) + 1));
  return s;
}

const char *dm_tocstring(lua_State *L, int idx, const char *what)
{
  size_t len;
  const char *s = lua_tolstring(L, idx, &len);
  if (s != NULL && strlen(s) != len)
    luaL_error(L, "%s: NUL byte at position %d of \"%s\" (C strings end "
               "there)", what, (int)strlen(s) + 1, s);
  return s;
}

/* The field's value is on top of the stack. */
int dm_unknownkey(lua_State *L, int t, const char *const *keys)
{
  t = lua_absindex(L, t);
  lua_pushnil(L);
  while (lua_next(L, t) != 0) {
    const char *const *k = keys;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key && *k && strcmp(*k, key) != 0)
      k++;
    lua_pop(L, 1);
    if (key == NULL || *k == NULL)
      return 1;
  }
  return 0;
}

void dm_checkkeys(lua_State *L, int t, const char *const *keys, const char *what,
                  const char *noun, const char *list)
{
  if (dm_unknownkey(L, t, keys)) {
    int str = lua_type(L, -1) == LUA_TSTRING;
    const char *k = luaL_tolstring(L, -1, NULL);
    luaL_error(L, "%s: unknown %s %s%s%s (%ss: %s)", what, noun, str ? "'" : "[", k,
               str ? "'" : "]", noun, list);
  }
}

static int fielderror(lua_State *L, int t, const char *key, const char *want)
{
  const char *got;
  if (lua_type(L, -1) == LUA_TNUMBER) {
    char buf[32];
    dm_num_format(buf, sizeof buf, lua_tonumber(L, -1));
    got = lua_pushfstring(L, "%s", buf);
  } else {
    got = luaL_typename(L, -1);
  }
  return luaL_argerror(L, t, lua_pushfstring(L, "field '%s': %s expected, got %s",
                                             key, want, got));
}

double dm_optnumberfield(lua_State *L, int t, const char *key, double def)
{
  double x;
  int isnum;
  if (lua_getfield(L, t, key) == LUA_TNIL) {
    lua_pop(L, 1);
    return def;
  }
  x = lua_tonumberx(L, -1, &isnum);
  if (!isnum)
    return fielderror(L, t, key, "number");
  lua_pop(L, 1);
  return x;
}

lua_Integer dm_optintegerfield(lua_State *L, int t, const char *key,
                               lua_Integer def)
{
  lua_Integer k;
  int isnum;
  if (lua_getfield(L, t, key) == LUA_TNIL) {
    lua_pop(L, 1);
    return def;
  }
  k = lua_tointegerx(L, -1, &isnum);
  if (!isnum)
    return fielderror(L, t, key, "integer");
  lua_pop(L, 1);
  return k;
}

/* The returned string stays valid: it is anchored in the table at t. */
const char *dm_optstringfield(lua_State *L, int t, const char *key,
                              const char *def)
{
  const char *s;
  if (lua_getfield(L, t, key) == LUA_TNIL) {
    lua_pop(L, 1);
    return def;
  }
  if (lua_type(L, -1) != LUA_TSTRING) {
    fielderror(L, t, key, "string");
    return NULL;
  }
  s = lua_tostring(L, -1);
  if (strlen(s) != lua_rawlen(L, -1)) {
    luaL_argerror(L, t, lua_pushfstring(L, "field '%s': string without NUL "
                                        "bytes expected, got a NUL byte at "
                                        "position %d", key, (int)strlen(s) + 1));
    return NULL;
  }
  lua_pop(L, 1);
  return s;
}


/* {======================================================================
 * a run that ended early
 * ======================================================================= */

/* Boolean field `key` of the options table at opts, else of dm.config,
 * else def. */
static int run_flag(lua_State *L, int opts, const char *key, int def)
{
  int v = def, t, top = lua_gettop(L);
  if (opts != 0 && lua_istable(L, opts)) {
    t = lua_getfield(L, opts, key);
    if (t != LUA_TNIL && t != LUA_TBOOLEAN)
      luaL_error(L, "run: option '%s' must be a boolean, got %s", key, luaL_typename(L, -1));
    if (t == LUA_TBOOLEAN) {
      v = lua_toboolean(L, -1);
      lua_settop(L, top);
      return v;
    }
    lua_settop(L, top);
  }
  if (lua_getfield(L, LUA_REGISTRYINDEX, DM_LUA_DMTABLE) == LUA_TTABLE
      && lua_getfield(L, -1, "config") == LUA_TTABLE
      && lua_getfield(L, -1, key) == LUA_TBOOLEAN)
    v = lua_toboolean(L, -1);
  lua_settop(L, top);
  return v;
}

void dm_lua_run_check_flags(lua_State *L, int opts)
{
  opts = opts != 0 ? lua_absindex(L, opts) : 0;
  run_flag(L, opts, "strict", 0);
  run_flag(L, opts, "warn", 1);
}

/* The warning line itself (rank 0 only under MPI: one line, not one per
 * rank). */
static void write_warning(lua_State *L, const char *text)
{
  int top = lua_gettop(L);
  if (dm_mpi_rank() != 0)
    return;
  /* through io.stderr, so that a script that redirects it sees it (not
   * protected: a pending Ctrl-C that stops the script must get through) */
  if (lua_getglobal(L, "io") == LUA_TTABLE && lua_getfield(L, -1, "stderr") != LUA_TNIL
      && lua_getfield(L, -1, "write") == LUA_TFUNCTION) {
    lua_insert(L, -2);
    lua_pushfstring(L, "warning: %s\n", text);
    lua_call(L, 2, 0);
  } else {
    fprintf(stderr, "warning: %s\n", text);
    fflush(stderr);
  }
  lua_settop(L, top);
}

void dm_lua_warning(lua_State *L, const char *text)
{
  if (run_flag(L, 0, "warn", 1))
    write_warning(L, text);
}

int dm_lua_run_ended(lua_State *L, int opts, int status, const char *msg)
{
  int top = lua_gettop(L), strict, warn;
  opts = opts != 0 ? lua_absindex(L, opts) : 0;
  strict = run_flag(L, opts, "strict", 0);
  warn = run_flag(L, opts, "warn", 1);
  if (msg == NULL || *msg == '\0')
    msg = dm_strstatus(status);
  if (strict)
    return luaL_error(L, "run: %s", msg);
  if (warn) {
    lua_pushfstring(L, "run ended early (%s): %s", dm_strstatus(status), msg);
    write_warning(L, lua_tostring(L, -1));
    lua_settop(L, top);
  }
  lua_pushfstring(L, "run: %s", msg);
  return 1;
}

/* }====================================================================== */
