/* main.c -- the dmech program: a lua-compatible command line around the dmech
 * library.  Modelled on lua.c (Lua 5.4): options -e -l -i -v -E -W - --,
 * LUA_INIT / DMECH_INIT, the `arg` table, tracebacks on errors, exit status 1
 * on failure.  `dm` (and `help`, `apropos`) are globals; `require "dmech"`
 * returns the same table.
 */
#include <config.h>

#include <errno.h>
#include <locale.h>
#include <stdio_ext.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include "core/cleanup.h"
#include "core/interrupt.h"
#include "core/mpi.h"
#include "lua/dmlua.h"
#include "app/repl.h"
#include "app/testrun.h"

const char *dm_progname = DM_PROGNAME;

static void print_usage(const char *badoption)
{
  FILE *f = badoption != NULL ? stderr : stdout;
  if (badoption != NULL) {
    if (badoption[1] == 'e' || badoption[1] == 'l')
      fprintf(f, "%s: '%s' needs argument\n", dm_progname, badoption);
    else
      fprintf(f, "%s: unrecognized option '%s'\n", dm_progname, badoption);
  }
  fprintf(f,
    "usage: %s [options] [script [args]]\n"
    "       %s test [options] [files or directories]  (run *_test.lua files)\n"
    "Computational geometric mechanics at a Lua 5.4 prompt.\n"
    "Available options are:\n"
    "  -e stat   execute string 'stat'\n"
    "  -i        enter interactive mode after executing 'script'\n"
    "  -l mod    require library 'mod' into global 'mod'\n"
    "  -l g=mod  require library 'mod' into global 'g'\n"
    "  -v        show version information\n"
    "  -E        ignore environment variables (DMECH_INIT, LUA_INIT, DMECH_PATH)\n"
    "  -W        turn warnings on\n"
    "  --help    show this help and exit\n"
    "  --        stop handling options\n"
    "  -         stop handling options and execute stdin\n"
    "Environment: DMECH_INIT (else LUA_INIT_5_4, LUA_INIT) runs first;\n"
    "DMECH_PATH adds directories searched for dmech's Lua library;\n"
    "DMECH_GNUPLOT names the gnuplot program.\n"
    "In the interactive prompt: help(x), help \"name\", apropos \"word\".\n",
    dm_progname, dm_progname);
  fflush(f);
}

static void print_version(void)
{
  printf("%s %s (%s, GSL)\n", PACKAGE_NAME, PACKAGE_VERSION, LUA_RELEASE);
  fflush(stdout);
}

/* {======================================================================
 * argument handling (as in lua.c)
 * ======================================================================= */

#define has_error 1
#define has_i 2
#define has_v 4
#define has_e 8
#define has_E 16
#define has_help 32

static int collectargs(char **argv, int *first)
{
  int args = 0, i;
  if (argv[0] != NULL) {
    if (argv[0][0])
      dm_progname = argv[0];
  } else {
    *first = -1;
    return 0;
  }
  for (i = 1; argv[i] != NULL; i++) {
    *first = i;
    if (argv[i][0] != '-')
      return args;
    switch (argv[i][1]) {
    case '-':
      if (strcmp(argv[i], "--help") == 0)
        return args | has_help;
      if (argv[i][2] != '\0')
        return has_error;
      *first = i + 1;
      return args;
    case '\0':
      return args;
    case 'E':
      if (argv[i][2] != '\0')
        return has_error;
      args |= has_E;
      break;
    case 'W':
      if (argv[i][2] != '\0')
        return has_error;
      break;
    case 'i':
      args |= has_i;  /* fall through: -i implies -v */
      /* FALLTHROUGH */
    case 'v':
      if (argv[i][2] != '\0')
        return has_error;
      args |= has_v;
      break;
    case 'e':
      args |= has_e;
      /* FALLTHROUGH */
    case 'l':
      if (argv[i][2] == '\0') {
        i++;
        if (argv[i] == NULL || argv[i][0] == '-')
          return has_error;
      }
      break;
    default:
      return has_error;
    }
  }
  *first = 0;
  return args;
}

static void createargtable(lua_State *L, char **argv, int argc, int script)
{
  int i, narg;
  if (script == argc)
    script = 0;
  narg = argc - (script + 1);
  lua_createtable(L, narg, script + 1);
  for (i = 0; i < argc; i++) {
    lua_pushstring(L, argv[i]);
    lua_rawseti(L, -2, i - script);
  }
  lua_setglobal(L, "arg");
}

static int dochunk(lua_State *L, int status)
{
  if (status == LUA_OK)
    status = dm_docall(L, 0, 0);
  return dm_report(L, status);
}

static int dostring(lua_State *L, const char *s, const char *name)
{
  return dochunk(L, luaL_loadbuffer(L, s, strlen(s), name));
}

static int dolibrary(lua_State *L, char *globname)
{
  int status;
  char *modname = strchr(globname, '=');
  if (modname == NULL)
    modname = globname;
  else {
    *modname = '\0';
    modname++;
  }
  lua_getglobal(L, "require");
  lua_pushstring(L, modname);
  status = dm_docall(L, 1, 1);
  if (status == LUA_OK)
    lua_setglobal(L, globname);
  return dm_report(L, status);
}

static int pushargs(lua_State *L)
{
  int i, n;
  if (lua_getglobal(L, "arg") != LUA_TTABLE)
    luaL_error(L, "'arg' is not a table");
  n = (int)luaL_len(L, -1);
  luaL_checkstack(L, n + 3, "too many arguments to script");
  for (i = 1; i <= n; i++)
    lua_rawgeti(L, -i, i);
  lua_remove(L, -i);
  return n;
}

/* Run the script; with -i (keep) its top-level locals become globals when
 * it ends, normally or by an error, for the prompt that follows. */
static int handle_script(lua_State *L, char **argv, int keep)
{
  int status;
  const char *fname = argv[0];
  if (strcmp(fname, "-") == 0 && strcmp(argv[-1], "--") != 0)
    fname = NULL;   /* stdin */
  status = luaL_loadfile(L, fname);
  if (status == LUA_OK) {
    int n = pushargs(L);
    if (keep)
      dm_keep_locals(L, -n - 1);
    status = dm_docall(L, n, LUA_MULTRET);
  }
  return dm_report(L, status);
}

static int runargs(lua_State *L, char **argv, int n)
{
  int i;
  for (i = 1; i < n; i++) {
    int option = argv[i][1];
    switch (option) {
    case 'e':
    case 'l': {
      int status;
      char *extra = argv[i] + 2;
      if (*extra == '\0')
        extra = argv[++i];
      status = (option == 'e') ? dostring(L, extra, "=(command line)")
                               : dolibrary(L, extra);
      if (status != LUA_OK)
        return 0;
      break;
    }
    case 'W':
      lua_warning(L, "@on", 0);
      break;
    }
  }
  return 1;
}

static int handle_init(lua_State *L)
{
  const char *name = "=DMECH_INIT";
  const char *init = getenv("DMECH_INIT");
  if (init == NULL || *init == '\0') {
    name = "=LUA_INIT_5_4";
    init = getenv("LUA_INIT_5_4");
  }
  if (init == NULL || *init == '\0') {
    name = "=LUA_INIT";
    init = getenv("LUA_INIT");
  }
  if (init == NULL || *init == '\0')
    return LUA_OK;
  if (init[0] == '@')
    return dochunk(L, luaL_loadfile(L, init + 1));
  return dostring(L, init, name);
}

/* }====================================================================== */

/* Make `require "dmech"` find the built-in module and set the globals. */
static int open_dmech(lua_State *L)
{
  int status;
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
  lua_pushcfunction(L, luaopen_dmech);
  lua_setfield(L, -2, "dmech");
  lua_pop(L, 1);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech");
  status = dm_docall(L, 1, 1);
  if (status != LUA_OK)
    return dm_report(L, status);
  lua_getfield(L, -1, "help");
  lua_setglobal(L, "help");
  lua_getfield(L, -1, "apropos");
  lua_setglobal(L, "apropos");
  lua_setglobal(L, "dm");
  dm_open_errors(L);
  return LUA_OK;
}

static int pmain(lua_State *L)
{
  int argc = (int)lua_tointeger(L, 1);
  char **argv = (char **)lua_touserdata(L, 2);
  int script, failed = 0;
  int args = collectargs(argv, &script);
  luaL_checkversion(L);
  if (args == has_error) {
    print_usage(argv[script]);
    return 0;
  }
  if (args & has_help) {
    print_usage(NULL);
    lua_pushboolean(L, 1);
    return 1;
  }
  if (args & has_v)
    print_version();
  if (args & has_E) {
    lua_pushboolean(L, 1);
    lua_setfield(L, LUA_REGISTRYINDEX, "LUA_NOENV");
    unsetenv("DMECH_PATH");
  }
  luaL_openlibs(L);
  dm_lua_number_tostring(L);           /* NaN prints "nan", never "-nan" */
  createargtable(L, argv, argc, script);
  lua_gc(L, LUA_GCGEN, 0, 0);
  if (open_dmech(L) != LUA_OK)
    return 0;
  if (!(args & has_E)) {
    if (handle_init(L) != LUA_OK)
      return 0;
  }
  if (!runargs(L, argv, script > 0 ? script : argc))
    return 0;
  if (script > 0) {
    /* with -i an error in the script leaves us at the prompt */
    failed = handle_script(L, argv + script, args & has_i) != LUA_OK;
    if (failed && !(args & has_i))
      return 0;
  }
  if (args & has_i) {
    dm_repl(L);
    if (failed)            /* as python -i: the script's failure is the status */
      return 0;
  } else if (script < 1 && !(args & (has_e | has_v))) {
    if (isatty(0)) {
      print_version();
      dm_repl(L);
    } else {
      dochunk(L, luaL_loadfile(L, NULL));
    }
  }
  lua_pushboolean(L, 1);
  return 1;
}

/* {======================================================================
 * exit checks: output lost must not look like success
 * ======================================================================= */

/* At exit (also os.exit): if what was printed could not all be written
 * (stdout closed, a full disk, `> /dev/full`), say so and exit 1, as
 * coreutils' close_stdout does.  A closed stdout nobody wrote to is fine. */
static void close_stdout(void)
{
  int pending = __fpending(stdout) != 0, failed = ferror(stdout) != 0;
  int closefail = fclose(stdout) != 0, err = errno;
  if (failed || (closefail && (pending || err != EBADF))) {
    fprintf(stderr, "%s: write error on standard output%s%s\n", dm_progname,
            closefail ? ": " : "", closefail ? strerror(err) : "");
    fflush(stderr);
    _exit(EXIT_FAILURE);
  }
}

/* }====================================================================== */

int main(int argc, char **argv)
{
  int status, result;
  lua_State *L;
  setlocale(LC_CTYPE, "");        /* Readline and UTF-8; numbers stay "C" */
  atexit(close_stdout);
  /* temporary directories and compiler process groups go with us */
  dm_cleanup_catch_signals();
  /* past RLIMIT_FSIZE a write fails with EFBIG (reported) instead of
   * killing the process with SIGXFSZ (a half-written temporary left) */
  signal(SIGXFSZ, SIG_IGN);
  if (argc > 1 && strcmp(argv[1], "test") == 0)
    return dm_testrun(argc, argv);  /* `dmech test`: the test runner */
  L = luaL_newstate();
  if (L == NULL) {
    dm_message(argv[0], "cannot create state: not enough memory");
    return EXIT_FAILURE;
  }
  lua_pushcfunction(L, pmain);
  lua_pushinteger(L, argc);
  lua_pushlightuserdata(L, argv);
  status = lua_pcall(L, 2, 1, 0);
  result = lua_toboolean(L, -1);
  dm_report(L, status);
  if (!(result && status == LUA_OK))
    dm_mpi_fail(dm_script_interrupted() ? 130 : EXIT_FAILURE);  /* under mpirun: end every rank */
  lua_close(L);
  if (result && status == LUA_OK)
    return EXIT_SUCCESS;
  /* a script stopped by Ctrl-C ends as shells expect of one: 128 + SIGINT */
  return dm_script_interrupted() ? 130 : EXIT_FAILURE;
}
