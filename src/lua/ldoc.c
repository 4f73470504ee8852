/* ldoc.c -- the documentation registry behind help() and apropos().
 *
 * Two tables live in the Lua registry: "dmech.docs" maps a qualified name
 * ("dm.vec", "vec:dot") to {name=, sig=, doc=}; "dmech.docvals" (weak keys)
 * maps a documented value (a C function) to the same record, so help(v.dot)
 * works without knowing names.  A record may carry opts = {"key", ...}, the
 * option keys of a function taking an options table (help lists them, the
 * prompt completes them, misspelt ones get a did-you-mean).  Fields of a
 * class are documented as "<kind>.<field>" beside its "<kind>:<method>"s;
 * "dmech.classes" maps every class metatable to its kind, so the prompt
 * can tell dmech's objects from others without calling anything.
 */
#include <config.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "lua/dmlua.h"

static void pushregtable(lua_State *L, const char *key, const char *mode)
{
  if (lua_getfield(L, LUA_REGISTRYINDEX, key) == LUA_TTABLE)
    return;
  lua_pop(L, 1);
  lua_newtable(L);
  if (mode != NULL) {
    lua_newtable(L);
    lua_pushstring(L, mode);
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
  }
  lua_pushvalue(L, -1);
  lua_setfield(L, LUA_REGISTRYINDEX, key);
}

void dm_pushdocs(lua_State *L)
{
  pushregtable(L, "dmech.docs", NULL);
}

void dm_doc_add(lua_State *L, const char *name, const char *sig,
                const char *doc, int idx)
{
  if (idx != 0)
    idx = lua_absindex(L, idx);
  dm_pushdocs(L);
  lua_createtable(L, 0, 3);
  lua_pushstring(L, name);
  lua_setfield(L, -2, "name");
  lua_pushstring(L, sig != NULL ? sig : name);
  lua_setfield(L, -2, "sig");
  lua_pushstring(L, doc != NULL ? doc : "");
  lua_setfield(L, -2, "doc");
  lua_pushvalue(L, -1);
  lua_setfield(L, -3, name);                 /* docs[name] = rec */
  if (idx != 0 && !lua_isnil(L, idx)) {
    pushregtable(L, "dmech.docvals", "k");
    lua_pushvalue(L, idx);
    lua_pushvalue(L, -3);
    lua_rawset(L, -3);                        /* docvals[value] = rec */
    lua_pop(L, 1);
  }
  lua_pop(L, 2);
}

/* Lua names a C function that was called without a name (pcall(f, ...), a
 * tail call) by searching package.loaded, as it finds string.rep.  Each
 * method ("<kind>:" prefix) is put there under its documented name, so
 * that errors say "bad argument #2 to 'trajectory:meta'", not "to '?'"
 * (a key with a colon is never a module name that require would ask for).
 * Functions of dm and its sub-tables are found through package.loaded
 * ["dmech"] and ["dmech.<sub>"] (module.c). */
static void name_methods(lua_State *L, const char *prefix, const dm_reg *regs)
{
  size_t n = strlen(prefix);
  if (n == 0 || prefix[n - 1] != ':')
    return;
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  for (; regs->name != NULL; regs++) {
    lua_pushfstring(L, "%s%s", prefix, regs->name);
    lua_pushcfunction(L, regs->func);
    lua_settable(L, -3);
  }
  lua_pop(L, 1);
}

void dm_register(lua_State *L, const char *prefix, const dm_reg *regs)
{
  luaL_Buffer b;
  name_methods(L, prefix, regs);
  for (; regs->name != NULL; regs++) {
    lua_pushcfunction(L, regs->func);
    luaL_buffinit(L, &b);
    luaL_addstring(&b, prefix);
    luaL_addstring(&b, regs->name);
    luaL_pushresult(&b);
    dm_doc_add(L, lua_tostring(L, -1), regs->sig, regs->doc, -2);
    lua_pop(L, 1);
    lua_setfield(L, -2, regs->name);
  }
}

void dm_newclass(lua_State *L, const char *tname, const char *kind,
                 const dm_reg *methods, const luaL_Reg *meta)
{
  char prefix[64];
  luaL_newmetatable(L, tname);
  snprintf(prefix, sizeof prefix, "%s:", kind);
  if (meta != NULL) {
    const luaL_Reg *m;
    luaL_setfuncs(L, meta, 0);
    /* a callable object called from C (traj:derive calling an fn) is
     * named "<kind>()" in errors, as methods are named above */
    for (m = meta; m->name != NULL; m++)
      if (strcmp(m->name, "__call") == 0) {
        luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
        lua_pushfstring(L, "%s()", kind);
        lua_pushcfunction(L, m->func);
        lua_settable(L, -3);
        lua_pop(L, 1);
      }
  }
  lua_pushstring(L, kind);
  lua_setfield(L, -2, "__name");
  pushregtable(L, "dmech.classes", "k");
  lua_pushvalue(L, -2);
  lua_pushstring(L, kind);
  lua_rawset(L, -3);
  lua_pop(L, 1);
  if (methods != NULL) {
    lua_newtable(L);
    dm_register(L, prefix, methods);
    if (lua_getfield(L, -2, "__index") == LUA_TNIL) {
      lua_pop(L, 1);
      lua_pushvalue(L, -1);
      lua_setfield(L, -3, "__index");
    } else {
      lua_pop(L, 1);
    }
    lua_setfield(L, -2, "__methods");   /* for completion and the doc test */
  }
}

int dm_index_methods(lua_State *L)
{
  lua_getmetatable(L, 1);
  lua_getfield(L, -1, "__methods");
  lua_pushvalue(L, 2);
  lua_rawget(L, -2);
  return 1;
}

void dm_doc_fields(lua_State *L, const char *kind, const dm_field *fields)
{
  char name[128];
  for (; fields->name != NULL; fields++) {
    snprintf(name, sizeof name, "%s.%s", kind, fields->name);
    dm_doc_add(L, name, fields->sig != NULL ? fields->sig : name, fields->doc, 0);
  }
}

void dm_doc_options(lua_State *L, const char *name, const char *const *keys)
{
  lua_Integer i = 0;
  dm_pushdocs(L);
  if (lua_getfield(L, -1, name) != LUA_TTABLE) {
    lua_pop(L, 2);
    return;
  }
  lua_newtable(L);
  for (; *keys != NULL; keys++) {
    lua_pushstring(L, *keys);
    lua_rawseti(L, -2, ++i);
  }
  lua_setfield(L, -2, "opts");
  lua_pop(L, 2);
}

/* {======================================================================
 * Lua access to the registry (used by lua/dmech/help.lua and the doc test)
 * ======================================================================= */

static int l_docs(lua_State *L)
{
  dm_pushdocs(L);
  pushregtable(L, "dmech.docvals", "k");
  return 2;
}

static int l_doc(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  const char *sig = dm_checkcstring(L, 2);
  const char *doc = dm_checkcstring(L, 3);
  dm_doc_add(L, name, sig, doc, lua_isnoneornil(L, 4) ? 0 : 4);
  return 0;
}

static const dm_reg doc_funcs[] = {
  {"docs", l_docs, "dm.docs() -> by_name, by_value",
   "The documentation registry: name -> {name, sig, doc}, and documented value -> the same record."},
  {"doc", l_doc, "dm.doc(name, signature, sentence[, value])",
   "Add an entry to the documentation registry (for Lua-side functions and user libraries)."},
  {NULL, NULL, NULL, NULL}
};

/* dm._termwidth(): $COLUMNS, else the width of the terminal on stdout,
 * else nil (help wraps its text to this). */
static int l_termwidth(lua_State *L)
{
  const char *env = getenv("COLUMNS");
  struct winsize ws;
  long w = 0;
  if (env != NULL && *env != '\0')
    w = strtol(env, NULL, 10);
  if (w <= 0 && isatty(STDOUT_FILENO) && ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0)
    w = ws.ws_col;
  if (w <= 0 || w > 100000)
    return 0;
  lua_pushinteger(L, w);
  return 1;
}

void dm_open_doc(lua_State *L)
{
  dm_register(L, "dm.", doc_funcs);
  lua_pushcfunction(L, l_termwidth);
  lua_setfield(L, -2, "_termwidth");
}
