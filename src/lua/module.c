/* module.c -- luaopen_dmech: the C side of `require "dmech"`.
 *
 * Used twice: linked into the dmech program (where it is preloaded) and built
 * as the Lua C module dmech.so for stock lua5.4.  It builds the table of C
 * functions, makes the Lua-side library findable and hands the table to
 * dmech.init, whose result is the module.
 *
 * Where the Lua-side library is: the directories of DMECH_PATH first; then,
 * for a program or module still in its build tree, the source tree's lua/
 * named by the file UNINSTALLED_MARK that the build writes next to src/dmech
 * (looked for beside the running executable or module and one directory up,
 * for src/.libs/dmech.so) and that is never installed; otherwise the
 * installed data directory DMECH_LUADIR only.  No source path is compiled
 * into the binaries.
 */
#include <config.h>
#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lua/dmlua.h"

#define UNINSTALLED_MARK "dmech-uninstalled.path"

/* The file this code runs from: the module for dmech.so, else the program. */
static int own_path(char *buf, size_t size)
{
  Dl_info info;
  ssize_t k;
  if (dladdr((void *)luaopen_dmech, &info) != 0 && info.dli_fname != NULL
      && strstr(info.dli_fname, ".so") != NULL && realpath(info.dli_fname, buf) != NULL)
    return 1;
  k = readlink("/proc/self/exe", buf, size - 1);
  if (k <= 0)
    return 0;
  buf[k] = '\0';
  return 1;
}

/* The Lua directory of the build tree this binary belongs to, into dir
 * (size PATH_MAX); 0 when it is not in a build tree (installed). */
static int uninstalled_dir(char *dir)
{
  char self[PATH_MAX], mark[PATH_MAX + 64];
  int up;
  if (!own_path(self, sizeof self))
    return 0;
  for (up = 0; up < 2; up++) {
    char *slash = strrchr(self, '/');
    FILE *f;
    if (slash == NULL)
      return 0;
    *slash = '\0';
    snprintf(mark, sizeof mark, "%s/" UNINSTALLED_MARK, self);
    if ((f = fopen(mark, "re")) == NULL)
      continue;
    if (fgets(dir, PATH_MAX, f) == NULL)
      dir[0] = '\0';
    fclose(f);
    dir[strcspn(dir, "\n")] = '\0';
    return dir[0] != '\0';
  }
  return 0;
}

/* Prepend "<dir>/?.lua" for every directory we search to package.path, once. */
static void setpath(lua_State *L)
{
  luaL_Buffer b;
  const char *env = getenv("DMECH_PATH");
  lua_getglobal(L, "package");
  if (!lua_istable(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  if (lua_getfield(L, -1, "dmech_path_set") != LUA_TNIL) {
    lua_pop(L, 2);
    return;
  }
  lua_pop(L, 1);
  luaL_buffinit(L, &b);
  if (env != NULL && *env != '\0') {
    const char *p = env, *q;
    for (;;) {
      q = strchr(p, ':');
      size_t len = q != NULL ? (size_t)(q - p) : strlen(p);
      if (len > 0) {
        luaL_addlstring(&b, p, len);
        luaL_addstring(&b, "/?.lua;");
      }
      if (q == NULL)
        break;
      p = q + 1;
    }
  }
  {
    char dir[PATH_MAX];
    if (uninstalled_dir(dir)) {
      luaL_addstring(&b, dir);
      luaL_addstring(&b, "/?.lua;");
    } else {
      luaL_addstring(&b, DMECH_LUADIR "/?.lua;");
    }
  }
  lua_getfield(L, -2, "path");
  luaL_addvalue(&b);
  luaL_pushresult(&b);
  lua_setfield(L, -2, "path");
  lua_pushboolean(L, 1);
  lua_setfield(L, -2, "dmech_path_set");
  lua_pop(L, 1);
}

static int return_upvalue(lua_State *L)
{
  lua_pushvalue(L, lua_upvalueindex(1));
  return 1;
}

/* Lua names a function called without a name (pcall(dm.mesh.grid, 5)) by
 * searching package.loaded two levels deep: "dmech.vec" is found, but
 * dm.mesh.grid is a level deeper and was reported as '?'.  Put every
 * sub-table of functions (dm.mesh, dm.lie, ...) there as "dmech.<name>"
 * unless that name is taken. */
static void name_subtables(lua_State *L, int dm)
{
  int loaded;
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "loaded");
  loaded = lua_gettop(L);
  lua_pushnil(L);
  while (lua_next(L, dm) != 0) {            /* key, value */
    int plain = lua_type(L, -2) == LUA_TSTRING && lua_type(L, -1) == LUA_TTABLE;
    if (plain && lua_getmetatable(L, -1)) {  /* a class or proxy: not a module */
      lua_pop(L, 1);
      plain = 0;
    }
    if (plain) {
      const char *name = lua_pushfstring(L, "dmech.%s", lua_tostring(L, -2));
      if (lua_getfield(L, loaded, name) == LUA_TNIL) {
        lua_pushvalue(L, -3);
        lua_setfield(L, loaded, name);
      }
      lua_pop(L, 2);
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 2);
}

int luaopen_dmech(lua_State *L)
{
  dm_gsl_init();
  setpath(L);
  lua_newtable(L);
  dm_open_all(L);
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "loaded");
  lua_pushvalue(L, -3);
  lua_setfield(L, -2, "dmech.core");       /* package.loaded["dmech.core"] = C table */
  lua_pop(L, 2);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.init");
  lua_call(L, 1, 1);
  /* From now on the module is known under one name only ("dmech", set by
   * require), so tracebacks name functions dmech.vec, not dmech.init.vec;
   * later requires of "dmech.core" get the same table through preload. */
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "loaded");
  lua_pushnil(L);
  lua_setfield(L, -2, "dmech.core");
  lua_pushnil(L);
  lua_setfield(L, -2, "dmech.init");
  lua_pop(L, 1);
  lua_getfield(L, -1, "preload");
  lua_pushvalue(L, -3);
  lua_pushcclosure(L, return_upvalue, 1);
  lua_setfield(L, -2, "dmech.core");
  lua_pop(L, 2);
  name_subtables(L, lua_gettop(L));
  return 1;
}
