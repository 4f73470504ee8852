/* errors.c -- running Lua code for the application: Ctrl-C, the message
 * handler, the report of an error.
 *
 * dm_docall runs a function with SIGINT armed: the first Ctrl-C stops Lua
 * code (a hook) and C loops (the polled interrupt flag), a second one during
 * the same call quits.  The message handler adds to the error message
 *   - a hint when dmech.help.hint has one (did-you-mean for misspelt names,
 *     methods and options; dm.cos for math.cos on a symbolic value; ':' for
 *     a method called with '.'),
 *   - a traceback: the whole one for scripts; at the prompt only the user's
 *     frames (not C functions, not dmech's own Lua library), and none at all
 *     for an error in the line itself.  The whole traceback of the last error
 *     is kept for dm.traceback().
 * With dm_keep_locals, the top-level locals of a script become globals when
 * it ends, normally or by an error (`dmech -i script.lua`).
 */
#include <config.h>

#include <signal.h>
#include <stdio.h>
#include <string.h>

#include <lauxlib.h>
#include <lua.h>

#include "core/interrupt.h"
#include "app/repl.h"

#define TRACEBACK_KEY "dmech.traceback"
#define CHUNK_KEY "dmech.chunk"

static lua_State *globalL = NULL;
static volatile sig_atomic_t sigint_count = 0;
static volatile sig_atomic_t script_sigint = 0;   /* Ctrl-C while a script ran */
static int interactive = 0;
static int script_interrupted = 0;                /* ... and it stopped the script */
static const void *keep_target = NULL;   /* the script whose locals are kept */
static char libdir[4096];                /* "@<dir>/" of dmech's Lua library */

/* {======================================================================
 * Ctrl-C: first press stops the running code, a second one quits
 * ======================================================================= */

/* Does a Ctrl-C stop the script (the default), or only the run it
 * interrupts (dm.config.interrupt = "run", as at the prompt)? */
static int interrupt_stops_script(lua_State *L)
{
  int top = lua_gettop(L), stops = 1;
  if (lua_getglobal(L, "dm") == LUA_TTABLE && lua_getfield(L, -1, "config") == LUA_TTABLE
      && lua_getfield(L, -1, "interrupt") == LUA_TSTRING)
    stops = strcmp(lua_tostring(L, -1), "run") != 0;
  lua_settop(L, top);
  return stops;
}

/* Hook set by the signal handler: fires at the next Lua instruction.  At
 * the prompt: if a C loop already consumed the interrupt (it returned its
 * partial result and cleared the flag) there is nothing left to stop.  In a
 * script (no prompt) the script stops, also after a run that kept its
 * partial result, unless dm.config.interrupt = "run"; the program then
 * exits with status 130. */
static void lstop(lua_State *L, lua_Debug *ar)
{
  (void)ar;
  lua_sethook(L, NULL, 0, 0);
  if (!interactive && script_sigint && (script_interrupted || interrupt_stops_script(L))) {
    dm_interrupt_clear();
    script_interrupted = 1;
    /* armed again: a pcall in the script that catches this does not keep it
     * going (a second Ctrl-C still quits at once) */
    lua_sethook(L, lstop, LUA_MASKCOUNT, 1);
    luaL_error(L, "interrupted (Ctrl-C): the script stops here; with dm.config.interrupt = "
               "\"run\" a Ctrl-C ends only the run, which keeps what it computed");
  }
  if (dm_interrupted()) {
    dm_interrupt_clear();
    luaL_error(L, "interrupted!");
  }
}

static void laction(int sig)
{
  int flag = LUA_MASKCALL | LUA_MASKRET | LUA_MASKLINE | LUA_MASKCOUNT;
  if (++sigint_count > 1) {          /* second Ctrl-C in the same run: quit */
    signal(sig, SIG_DFL);
    raise(sig);
    return;
  }
  script_sigint = 1;
  dm_interrupt_raise();
  lua_sethook(globalL, lstop, flag, 1);
}

int dm_script_interrupted(void)
{
  return script_interrupted;
}

/* }====================================================================== */

/* {======================================================================
 * keeping a script's locals
 * ======================================================================= */

/* The active locals of the function at `ar` become globals ("(temporary)"
 * slots excepted; a later local of the same name wins, as in the code). */
static void locals_to_globals(lua_State *L, lua_Debug *ar)
{
  const char *name;
  int i;
  if (!lua_checkstack(L, 4))
    return;
  for (i = 1; (name = lua_getlocal(L, ar, i)) != NULL; i++) {
    if (name[0] != '(' && strcmp(name, "__dmech_keep") != 0)
      lua_setglobal(L, name);
    else
      lua_pop(L, 1);
  }
}

static int is_target(lua_State *L, lua_Debug *ar)
{
  const void *f;
  if (keep_target == NULL || !lua_getinfo(L, "f", ar))
    return 0;
  f = lua_topointer(L, -1);
  lua_pop(L, 1);
  return f == keep_target;
}

static void keep_hook(lua_State *L, lua_Debug *ar)
{
  if (ar->event == LUA_HOOKRET && is_target(L, ar)) {
    locals_to_globals(L, ar);
    keep_target = NULL;
    lua_sethook(L, NULL, 0, 0);
  }
}

/* Find the target's frame on the stack (an error inside the script). */
static void keep_on_error(lua_State *L)
{
  lua_Debug ar;
  int level;
  for (level = 0; keep_target != NULL && lua_getstack(L, level, &ar); level++)
    if (is_target(L, &ar)) {
      locals_to_globals(L, &ar);
      keep_target = NULL;
    }
}

int dm_keep_caller_locals(lua_State *L)
{
  lua_Debug ar;
  int n = lua_gettop(L);
  if (lua_getstack(L, 1, &ar))
    locals_to_globals(L, &ar);
  lua_settop(L, n);
  return n;
}

void dm_keep_locals(lua_State *L, int idx)
{
  keep_target = lua_topointer(L, idx);
  lua_sethook(L, keep_hook, LUA_MASKRET, 0);
}

/* }====================================================================== */

/* {======================================================================
 * the message handler
 * ======================================================================= */

void dm_set_interactive(lua_State *L, int on)
{
  (void)L;
  interactive = on;
}

void dm_set_chunk(lua_State *L, const char *text, size_t len)
{
  lua_pushlstring(L, text, len);
  lua_setfield(L, LUA_REGISTRYINDEX, CHUNK_KEY);
}

/* "@<dir>/" of dmech's own Lua files, found from where dm.help was loaded. */
static const char *library_dir(lua_State *L)
{
  lua_Debug ar;
  char *slash;
  if (libdir[0] != '\0')
    return libdir;
  if (lua_getglobal(L, "dm") != LUA_TTABLE || lua_getfield(L, -1, "help") != LUA_TFUNCTION) {
    lua_pop(L, 2);
    return NULL;
  }
  lua_remove(L, -2);
  if (!lua_getinfo(L, ">S", &ar) || ar.source[0] != '@')
    return NULL;
  snprintf(libdir, sizeof libdir, "%s", ar.source);
  slash = strrchr(libdir, '/');
  if (slash == NULL) {
    libdir[0] = '\0';
    return NULL;
  }
  slash[1] = '\0';
  return libdir;
}

static int user_frame(lua_State *L, const lua_Debug *ar)
{
  const char *lib = library_dir(L);
  if (ar->what[0] == 'C')
    return 0;
  return lib == NULL || strncmp(ar->source, lib, strlen(lib)) != 0;
}

/* The user's frames from `level` up, in luaL_traceback's format; pushes the
 * text and returns how many frames it has (0: push "") and in *hidden how
 * many Lua frames of the library were left out. */
static int short_traceback(lua_State *L, int level, int *hidden)
{
  lua_Debug ar;
  luaL_Buffer b;
  int n = 0, firstmain = 0;
  *hidden = 0;
  luaL_buffinit(L, &b);
  for (; lua_getstack(L, level, &ar); level++) {
    lua_getinfo(L, "Slnt", &ar);
    if (!user_frame(L, &ar)) {
      *hidden += ar.what[0] != 'C';
      continue;
    }
    if (*ar.namewhat != '\0')
      lua_pushfstring(L, "\n\t%s:%d: in %s '%s'", ar.short_src, ar.currentline, ar.namewhat,
                      ar.name);
    else if (*ar.what == 'm')
      lua_pushfstring(L, "\n\t%s:%d: in main chunk", ar.short_src, ar.currentline);
    else
      lua_pushfstring(L, "\n\t%s:%d: in function <%s:%d>", ar.short_src, ar.currentline,
                      ar.short_src, ar.linedefined);
    if (n == 0)
      firstmain = *ar.what == 'm';
    luaL_addvalue(&b);
    n++;
  }
  luaL_pushresult(&b);
  if (n == 1 && firstmain) {     /* the typed line itself: nothing to show */
    lua_pop(L, 1);
    lua_pushliteral(L, "");
    n = 0;
  }
  return n;
}

/* Ask dmech.help.hint(msg, info) for a hint; pushes it or "". */
static void push_hint(lua_State *L, int msg, int traceback)
{
  lua_Debug ar;
  int top = lua_gettop(L);
  if (!lua_checkstack(L, 10))
    goto none;
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.help");
  if (lua_pcall(L, 1, 1, 0) != LUA_OK || lua_getfield(L, -1, "hint") != LUA_TFUNCTION)
    goto none;
  lua_pushvalue(L, msg);
  lua_createtable(L, 0, 6);
  if (lua_getstack(L, 1, &ar) && lua_getinfo(L, "Sn", &ar)) {
    lua_pushstring(L, ar.what);
    lua_setfield(L, -2, "what");
    if (ar.name != NULL) {
      lua_pushstring(L, ar.name);
      lua_setfield(L, -2, "name");
    }
    lua_pushstring(L, ar.namewhat);
    lua_setfield(L, -2, "namewhat");
  }
  for (int level = 1; lua_getstack(L, level, &ar); level++) {
    lua_getinfo(L, "Sl", &ar);
    if (ar.what[0] != 'C' && ar.currentline > 0) {
      lua_pushstring(L, ar.source);
      lua_setfield(L, -2, "source");
      lua_pushinteger(L, ar.currentline);
      lua_setfield(L, -2, "line");
      break;
    }
  }
  lua_pushvalue(L, traceback);
  lua_setfield(L, -2, "traceback");
  lua_getfield(L, LUA_REGISTRYINDEX, CHUNK_KEY);
  lua_setfield(L, -2, "chunk");
  if (lua_pcall(L, 2, 1, 0) != LUA_OK || lua_type(L, -1) != LUA_TSTRING)
    goto none;
  lua_replace(L, top + 1);
  lua_settop(L, top + 1);
  return;
none:
  lua_settop(L, top);
  lua_pushliteral(L, "");
}

static int msghandler(lua_State *L)
{
  const char *msg = lua_tostring(L, 1);
  int hidden, n;
  if (msg == NULL) {
    if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING)
      return 1;
    msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    lua_replace(L, 1);
  }
  lua_settop(L, 1);
  keep_on_error(L);
  luaL_traceback(L, L, NULL, 1);                                       /* 2 */
  push_hint(L, 1, 2);                                                  /* 3 */
  lua_pushvalue(L, 1);
  lua_pushvalue(L, 3);
  lua_pushliteral(L, "\n");
  lua_pushvalue(L, 2);
  lua_concat(L, 4);                                    /* 4: the whole report */
  lua_pushvalue(L, 4);
  lua_setfield(L, LUA_REGISTRYINDEX, TRACEBACK_KEY);
  if (!interactive)
    return 1;
  n = short_traceback(L, 1, &hidden);                                  /* 5 */
  lua_pushvalue(L, 1);
  lua_pushvalue(L, 3);
  if (n > 0) {
    lua_pushliteral(L, "\nstack traceback:");
    lua_pushvalue(L, 5);
    lua_pushstring(L, hidden > 0 ? "\n\t(dm.traceback() shows every frame)" : "");
    lua_concat(L, 5);
  } else {
    lua_concat(L, 2);
  }
  return 1;
}

/* dm.traceback(): the message and whole traceback of the last error. */
static int l_traceback(lua_State *L)
{
  if (lua_getfield(L, LUA_REGISTRYINDEX, TRACEBACK_KEY) != LUA_TSTRING) {
    lua_pushliteral(L, "no error yet\n");
  } else {
    lua_pushliteral(L, "\n");
    lua_concat(L, 2);
  }
  lua_getglobal(L, "io");
  if (lua_getfield(L, -1, "write") == LUA_TFUNCTION) {
    lua_pushvalue(L, -3);
    lua_call(L, 1, 0);
  }
  return 0;
}

void dm_open_errors(lua_State *L)
{
  if (lua_getglobal(L, "dm") != LUA_TTABLE) {
    lua_pop(L, 1);
    return;
  }
  lua_pushcfunction(L, l_traceback);
  lua_setfield(L, -2, "traceback");
  if (lua_getfield(L, -1, "doc") == LUA_TFUNCTION) {
    lua_pushliteral(L, "dm.traceback");
    lua_pushliteral(L, "dm.traceback()");
    lua_pushliteral(L, "Print the message and the whole stack traceback of the last error "
                       "(the prompt shows only the user's frames).");
    lua_getfield(L, -5, "traceback");
    lua_call(L, 4, 0);
  } else {
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

/* }====================================================================== */

int dm_docall(lua_State *L, int narg, int nres)
{
  int status, base = lua_gettop(L) - narg;
  struct sigaction sa, old;
  lua_pushcfunction(L, msghandler);
  lua_insert(L, base);
  globalL = L;
  sigint_count = 0;
  script_sigint = 0;
  dm_interrupt_clear();
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = laction;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old);
  status = lua_pcall(L, narg, nres, base);
  sigaction(SIGINT, &old, NULL);
  lua_sethook(L, NULL, 0, 0);
  keep_target = NULL;
  dm_interrupt_clear();
  lua_remove(L, base);
  return status;
}

void dm_message(const char *pname, const char *msg)
{
  fflush(stdout);           /* keep stdout and stderr in order in pipes */
  if (pname)
    fprintf(stderr, "%s: ", pname);
  fprintf(stderr, "%s\n", msg);
  fflush(stderr);
}

int dm_report(lua_State *L, int status)
{
  if (status != LUA_OK) {
    const char *msg = lua_tostring(L, -1);
    dm_message(dm_progname, msg != NULL ? msg : "(error object is not a string)");
    lua_pop(L, 1);
  }
  return status;
}
