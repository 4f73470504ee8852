/* repl.c -- the interactive loop (modelled on lua.c's doREPL).
 *
 * Adds to lua.c: results auto-print through dmech.print's pretty printer; a
 * trailing ';' suppresses printing; `_` holds the last result; a multi-line
 * chunk is one history entry; history persists in
 * $XDG_STATE_HOME/dmech/history (else ~/.dmech_history), appended per entry;
 * Ctrl-C at the prompt clears the line (Readline's callback interface, so no
 * longjmp out of Readline); tab completion (complete.c).  Without a terminal
 * (or without Readline) lines come from stdio and prompts from
 * _PROMPT/_PROMPT2.
 */
#include <config.h>

#include <ctype.h>
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <fcntl.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lua.h>

#ifdef HAVE_READLINE
#include <readline/history.h>
#include <readline/readline.h>
#endif

#include "app/repl.h"

#define PROMPT1 "dm> "
#define PROMPT2 ".. "
#define MAXINPUT 512
#define HISTORY_KEEP 10000

static int use_readline = 0;
#ifdef HAVE_READLINE
static char *history_path = NULL;
#endif

/* {======================================================================
 * line input: Readline (callback interface) or stdio
 * ======================================================================= */

#ifdef HAVE_READLINE
/* Signals at the prompt reach the loop through a pipe (the self-pipe trick):
 * the handler only writes a byte, and poll() watches the pipe beside the
 * terminal, so a Ctrl-C arriving at any moment is seen at the next wake-up. */
static int sigpipe_fd[2] = {-1, -1};
static char *cb_line;
static int cb_done;

static void on_prompt_signal(int sig)
{
  int saved = errno;
  char c = sig == SIGINT ? 'i' : 'w';
  if (write(sigpipe_fd[1], &c, 1) < 0) {
    /* pipe full: a wake-up is already pending */
  }
  errno = saved;
}

static int open_sigpipe(void)
{
  int i;
  if (sigpipe_fd[0] >= 0)
    return 0;
  if (pipe(sigpipe_fd) != 0)
    return -1;
  for (i = 0; i < 2; i++) {
    fcntl(sigpipe_fd[i], F_SETFL, fcntl(sigpipe_fd[i], F_GETFL) | O_NONBLOCK);
    fcntl(sigpipe_fd[i], F_SETFD, FD_CLOEXEC);
  }
  return 0;
}

static void on_line(char *line)
{
  cb_line = line;
  cb_done = 1;
  rl_callback_handler_remove();
}

/* Read a line with Readline.  Returns 1 and sets *line (malloc'ed, NULL on
 * EOF); returns 0 when Ctrl-C cleared the line. */
static int rl_getline(const char *prompt, char **line)
{
  struct sigaction sa, oldint, oldwinch;
  int interrupted = 0;
  char c;
  while (read(sigpipe_fd[0], &c, 1) == 1)
    ;                                   /* forget stale wake-ups */
  memset(&sa, 0, sizeof sa);
  sigemptyset(&sa.sa_mask);
  sa.sa_handler = on_prompt_signal;
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, &oldint);
  sigaction(SIGWINCH, &sa, &oldwinch);
  cb_done = 0;
  cb_line = NULL;
  rl_callback_handler_install(prompt, on_line);
  while (!cb_done) {
    struct pollfd pfd[2] = {{fileno(rl_instream), POLLIN, 0}, {sigpipe_fd[0], POLLIN, 0}};
    int r = poll(pfd, 2, -1);
    if (r < 0) {
      if (errno == EINTR)
        continue;
      on_line(NULL);
      break;
    }
    if (pfd[1].revents & POLLIN) {
      int sigint = 0, winch = 0;
      while (read(sigpipe_fd[0], &c, 1) == 1) {
        sigint |= c == 'i';
        winch |= c == 'w';
      }
      if (winch)
        rl_resize_terminal();
      if (sigint) {
        rl_free_line_state();
        rl_callback_sigcleanup();
        rl_replace_line("", 0);
        rl_point = rl_end = 0;
        rl_crlf();
        rl_callback_handler_remove();
        interrupted = 1;
        break;
      }
    }
    if (pfd[0].revents & (POLLIN | POLLHUP | POLLERR))
      rl_callback_read_char();
  }
  sigaction(SIGINT, &oldint, NULL);
  sigaction(SIGWINCH, &oldwinch, NULL);
  *line = interrupted ? NULL : cb_line;
  return !interrupted;
}
#endif

static volatile sig_atomic_t stdio_sigint = 0;
static void on_stdio_sigint(int sig) { (void)sig; stdio_sigint = 1; }

static const char *get_prompt(lua_State *L, int firstline)
{
  if (lua_getglobal(L, firstline ? "_PROMPT" : "_PROMPT2") == LUA_TNIL)
    return firstline ? PROMPT1 : PROMPT2;
  return luaL_tolstring(L, -1, NULL);   /* leaves two values on the stack */
}

/* Push the next input line (without its newline).  Returns 0 at end of
 * input, -1 when Ctrl-C discarded the line, 1 otherwise. */
static int pushline(lua_State *L, int firstline)
{
  const char *prompt;
  size_t l;
  int top = lua_gettop(L);
  prompt = get_prompt(L, firstline);
#ifdef HAVE_READLINE
  if (use_readline) {
    char *b;
    int ok = rl_getline(prompt, &b);
    lua_settop(L, top);
    if (!ok)
      return -1;
    if (b == NULL)
      return 0;
    lua_pushstring(L, b);
    free(b);
    return 1;
  }
#endif
  {
    char buffer[MAXINPUT];
    luaL_Buffer lb;
    struct sigaction sa, old;
    int r = 1;
    fputs(prompt, stdout);
    fflush(stdout);
    lua_settop(L, top);
    /* On a terminal without Readline, Ctrl-C abandons the line: the read is
     * interrupted (no SA_RESTART) and reported as a cancelled line. */
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = on_stdio_sigint;
    stdio_sigint = 0;
    sigaction(SIGINT, &sa, &old);
    luaL_buffinit(L, &lb);
    for (;;) {
      if (fgets(buffer, sizeof buffer, stdin) == NULL) {
        if (stdio_sigint) {
          clearerr(stdin);
          fputs("\n", stdout);
          r = -1;
        } else if (luaL_bufflen(&lb) == 0) {
          r = 0;
        }
        break;
      }
      l = strlen(buffer);
      if (l > 0 && buffer[l - 1] == '\n') {
        luaL_addlstring(&lb, buffer, l - 1);
        break;
      }
      luaL_addlstring(&lb, buffer, l);
    }
    sigaction(SIGINT, &old, NULL);
    luaL_pushresult(&lb);
    if (r != 1)
      lua_pop(L, 1);
    return r;
  }
}

/* }====================================================================== */

/* {======================================================================
 * history
 * ======================================================================= */

#ifdef HAVE_READLINE
static int mkdirs(char *path)
{
  char *p;
  for (p = path + 1; *p; p++) {
    if (*p == '/') {
      *p = '\0';
      if (mkdir(path, 0700) != 0 && errno != EEXIST) {
        *p = '/';
        return -1;
      }
      *p = '/';
    }
  }
  return 0;
}

static void history_open(void)
{
  const char *state = getenv("XDG_STATE_HOME"), *home = getenv("HOME");
  size_t len;
  int fd;
  if (state != NULL && *state == '/') {
    len = strlen(state) + sizeof "/dmech/history";
    history_path = malloc(len);
    if (history_path == NULL)
      return;
    snprintf(history_path, len, "%s/dmech/history", state);
    if (mkdirs(history_path) != 0) {
      free(history_path);
      history_path = NULL;
      return;
    }
  } else if (home != NULL && *home != '\0') {
    len = strlen(home) + sizeof "/.dmech_history";
    history_path = malloc(len);
    if (history_path == NULL)
      return;
    snprintf(history_path, len, "%s/.dmech_history", home);
  } else {
    return;
  }
  /* Timestamps delimit entries, so a multi-line chunk reads back as one. */
  history_comment_char = '#';
  history_write_timestamps = 1;
  history_multiline_entries = 1;
  fd = open(history_path, O_WRONLY | O_CREAT | O_APPEND, 0600);
  if (fd >= 0)
    close(fd);
  read_history(history_path);
}

static void history_add(const char *entry)
{
  if (entry[0] == '\0')
    return;
  add_history(entry);
  if (history_path != NULL) {
    append_history(1, history_path);
    if (history_length > HISTORY_KEEP + HISTORY_KEEP / 10)
      history_truncate_file(history_path, HISTORY_KEEP);
  }
}
#endif

/* }====================================================================== */

/* {======================================================================
 * reading and running chunks
 * ======================================================================= */

#define EOFMARK "<eof>"
#define marklen (sizeof(EOFMARK) / sizeof(char) - 1)

static int incomplete(lua_State *L, int status)
{
  if (status == LUA_ERRSYNTAX) {
    size_t lmsg;
    const char *msg = lua_tolstring(L, -1, &lmsg);
    if (lmsg >= marklen && strcmp(msg + lmsg - marklen, EOFMARK) == 0) {
      lua_pop(L, 1);
      return 1;
    }
  }
  return 0;
}

/* Does the chunk end with ';' (ignoring trailing blanks)? */
static int ends_with_semicolon(const char *s, size_t l)
{
  while (l > 0 && (s[l - 1] == ' ' || s[l - 1] == '\t' || s[l - 1] == '\r' || s[l - 1] == '\n'))
    l--;
  return l > 0 && s[l - 1] == ';';
}

/* Compile text as a chunk named stdin: pushes the function and returns
 * LUA_OK, or returns the status with nothing pushed. */
static int try_load(lua_State *L, const char *text, size_t len)
{
  int status = luaL_loadbuffer(L, text, len, "=stdin");
  if (status != LUA_OK)
    lua_pop(L, 1);
  return status;
}

#define KEEP_NAME "__dmech_keep"

/* Compile the chunk in one of its forms (pushed on success, else nothing):
 * split < 0: the statements as they are; split = p >= 0: the statements
 * text[0, p) then "return select(1, <text[p, len)>)" -- text[0, p) ends
 * with ';' or a newline, so line numbers stay those of the text; select
 * keeps every value and makes the user's call an ordinary call, not a tail
 * call, so that tracebacks name it.  With keep, the chunk receives a
 * function as its vararg and calls it once its top-level statements have
 * run: their locals become globals (dm_keep_caller_locals). */
static int compile(lua_State *L, const char *text, size_t len, long split, int keep)
{
  int status, n = 0;
  if (keep) {
    lua_pushliteral(L, "local " KEEP_NAME " = ...; ");
    n++;
  }
  if (split < 0) {
    lua_pushlstring(L, text, len);
    n++;
    if (keep) {
      lua_pushliteral(L, "\n;" KEEP_NAME "()");
      n++;
    }
  } else {
    size_t p = (size_t)split;
    lua_pushlstring(L, text, p);
    lua_pushstring(L, keep ? ";" KEEP_NAME "() return select(1, " : "return select(1, ");
    lua_pushlstring(L, text + p, len - p);
    /* ")" on the same line (errors keep their line) unless a comment may end it */
    lua_pushstring(L, strstr(lua_tostring(L, -1), "--") != NULL ? "\n);" : ");");
    n += 4;
  }
  lua_concat(L, n);
  status = try_load(L, lua_tostring(L, -1), lua_rawlen(L, -1));
  if (status == LUA_OK)
    lua_remove(L, -2);
  else
    lua_pop(L, 1);
  return status;
}

/* Where to split the chunk so that the value of its last statement, when
 * that is an expression, is returned: 0 (the whole text is an expression),
 * the start of the last statement ("a = 1; a + 1", a pasted block), or -1.
 * `plain_ok` says the text also compiles as statements; then only splits
 * that cannot change its meaning are taken (after ';', or before a name:
 * "y = 1\n-x" is y = 1 - x). */
static long find_split(lua_State *L, const char *text, size_t len, int plain_ok)
{
  size_t p;
  if (compile(L, text, len, 0, 0) == LUA_OK) {
    lua_pop(L, 1);
    return 0;
  }
  for (p = len; p > 0; p--) {
    char c = text[p - 1], d;
    size_t q = p;
    if (c != '\n' && c != ';')
      continue;
    while (q < len && (text[q] == ' ' || text[q] == '\t' || text[q] == '\r' || text[q] == '\n'))
      q++;
    if (q == len)
      continue;
    d = text[q];
    if (plain_ok && c != ';' && !(isalpha((unsigned char)d) || d == '_'))
      continue;
    if (compile(L, text + p, len - p, 0, 0) != LUA_OK)
      continue;                                   /* the tail is not an expression */
    lua_pop(L, 1);
    if (try_load(L, text, p) != LUA_OK)
      continue;                                   /* the head is not whole statements */
    lua_pop(L, 1);
    if (compile(L, text, len, (long)p, 0) == LUA_OK) {
      lua_pop(L, 1);
      return (long)p;
    }
  }
  return -1;
}

/* Read a whole chunk; on success the stack is [chunk text, function]: the
 * function takes one argument, the keeper of its locals
 * (dm_keep_caller_locals), which it may ignore.  *expr tells whether it
 * returns the value of its last expression (printed unless *quiet: the
 * chunk ends with ';').  Returns the load status, -1 at end of input, -2
 * when Ctrl-C cancelled the input. */
static int loadchunk(lua_State *L, int *expr, int *quiet)
{
  int status, r;
  size_t len, l;
  long split;
  const char *text;
  for (;;) {
    text = lua_tolstring(L, 1, &len);
    *quiet = ends_with_semicolon(text, len);
    /* "x;" is not an expression: look at the text without its ';'s */
    l = len;
    while (*quiet && l > 0 && strchr(" \t\r\n;", text[l - 1]) != NULL)
      l--;
    status = try_load(L, text, len);
    if (status == LUA_OK)
      lua_pop(L, 1);
    split = find_split(L, text, l, status == LUA_OK);
    if (split >= 0 || status == LUA_OK) {
      *expr = split >= 0;
      if (compile(L, text, split >= 0 ? l : len, split, 1) == LUA_OK
          || compile(L, text, split >= 0 ? l : len, split, 0) == LUA_OK)
        return LUA_OK;
    }
    *expr = 0;
    status = luaL_loadbuffer(L, text, len, "=stdin");
    if (!incomplete(L, status))
      return status;
    r = pushline(L, 0);
    if (r <= 0) {
      if (r == 0)    /* end of input inside a chunk: report the syntax error */
        return luaL_loadbuffer(L, text, len, "=stdin");
      return -2;
    }
    lua_pushliteral(L, "\n");
    lua_insert(L, -2);
    lua_concat(L, 3);
  }
}

/* A bare word the prompt understands when it names no variable: help, exit,
 * quit (also as help(), exit(), quit()). */
static const char *command_word(lua_State *L, const char *line)
{
  static const char *const words[] = {"help", "exit", "quit", NULL};
  size_t n;
  int i;
  while (*line == ' ' || *line == '\t')
    line++;
  for (i = 0; words[i] != NULL; i++) {
    const char *rest;
    n = strlen(words[i]);
    if (strncmp(line, words[i], n) != 0)
      continue;
    rest = line + n;
    if (strncmp(rest, "()", 2) == 0 && i > 0)
      rest += 2;
    while (*rest == ' ' || *rest == '\t' || *rest == ';')
      rest++;
    if (*rest != '\0')
      continue;
    if (i > 0) {             /* exit/quit unless the user defined them */
      int defined = lua_getglobal(L, words[i]) != LUA_TNIL;
      lua_pop(L, 1);
      if (defined)
        return NULL;
    }
    return words[i];
  }
  return NULL;
}

/* Read a whole chunk; on success the stack is [line, function]; returns the
 * load status, -1 on end of input, -2 when Ctrl-C cancelled the input, -3
 * for the bare word `help`.  *expr tells whether the chunk is an expression
 * (its results are printed). */
static int loadline(lua_State *L, int *expr, int *quiet)
{
  int status, r;
  size_t len;
  const char *line, *word;
  lua_settop(L, 0);
  r = pushline(L, 1);
  if (r == 0)
    return -1;
  if (r < 0)
    return -2;
  line = lua_tolstring(L, 1, &len);
  if (len > 0 && line[0] == '=') {          /* "=expr" as in Lua 5.1 */
    lua_pushfstring(L, "%s", line + 1);
    lua_replace(L, 1);
  }
  line = lua_tolstring(L, 1, &len);
  if ((word = command_word(L, line)) != NULL) {
#ifdef HAVE_READLINE
    if (use_readline)
      history_add(line);
#endif
    return word[0] == 'h' ? -3 : -1;
  }
  status = loadchunk(L, expr, quiet);
  if (status == -2)
    return -2;
  line = lua_tolstring(L, 1, &len);
  dm_set_chunk(L, line, len);
#ifdef HAVE_READLINE
  if (use_readline)
    history_add(line);
#endif
  return status;
}

/* Print the results on the stack through dmech.print (pretty printer). */
static void print_results(lua_State *L)
{
  int n = lua_gettop(L);
  if (n == 0)
    return;
  luaL_checkstack(L, LUA_MINSTACK, "too many results to print");
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.print");
  if (lua_pcall(L, 1, 1, 0) != LUA_OK || lua_getfield(L, -1, "results") != LUA_TFUNCTION) {
    lua_settop(L, n);                      /* fall back to plain print */
    lua_getglobal(L, "print");
  } else {
    lua_remove(L, -2);
  }
  lua_insert(L, 1);
  if (dm_docall(L, n, 0) != LUA_OK)
    dm_report(L, LUA_ERRRUN);
}

#ifdef HAVE_READLINE
/* A bracketed paste that ends with a newline runs at once (as typed lines
 * would); without the newline it stays on the line for editing. */
static int paste_and_run(int count, int key)
{
  int r = rl_bracketed_paste_begin(count, key);
  if (rl_end > 0 && rl_line_buffer[rl_end - 1] == '\n') {
    rl_end--;
    rl_line_buffer[rl_end] = '\0';
    if (rl_point > rl_end)
      rl_point = rl_end;
    rl_newline(1, '\n');
  }
  return r;
}
#endif

/* help() through the global, as if typed. */
static void bare_help(lua_State *L)
{
  lua_settop(L, 0);
  if (lua_getglobal(L, "help") == LUA_TFUNCTION) {
    if (dm_docall(L, 0, 0) != LUA_OK)
      dm_report(L, LUA_ERRRUN);
  }
  lua_settop(L, 0);
}

/* dm.config.interactive = on: libraries that report what they did (dm.plot
 * writing a file) do it at the prompt only. */
static void set_config_interactive(lua_State *L, int on)
{
  int top = lua_gettop(L);
  if (lua_getglobal(L, "dm") == LUA_TTABLE && lua_getfield(L, -1, "config") == LUA_TTABLE) {
    lua_pushboolean(L, on);
    lua_setfield(L, -2, "interactive");
  }
  lua_settop(L, top);
}

void dm_repl(lua_State *L)
{
  int status, expr = 0, quiet = 0;
  dm_set_interactive(L, 1);
  set_config_interactive(L, 1);
#ifdef HAVE_READLINE
  use_readline = isatty(STDIN_FILENO) && open_sigpipe() == 0;
  if (use_readline) {
    rl_readline_name = DM_PROGNAME;
    rl_catch_signals = 0;
    rl_catch_sigwinch = 0;
    rl_initialize();
    rl_bind_keyseq_in_map("\033[200~", paste_and_run, emacs_standard_keymap);
    rl_bind_keyseq_in_map("\033[200~", paste_and_run, vi_insertion_keymap);
    dm_complete_init(L);
    history_open();
  }
#endif
  for (;;) {
    status = loadline(L, &expr, &quiet);
    if (status == -1)
      break;
    if (status == -2)
      continue;
    if (status == -3) {
      bare_help(L);
      continue;
    }
    lua_remove(L, 1);                        /* the line text */
    if (status == LUA_OK) {
      lua_pushcfunction(L, dm_keep_caller_locals);
      status = dm_docall(L, 1, LUA_MULTRET);
    }
    if (status == LUA_OK) {
      if (expr && lua_gettop(L) > 0) {
        lua_pushvalue(L, 1);
        lua_setglobal(L, "_");
      }
      if (!quiet)
        print_results(L);
    } else {
      dm_report(L, status);
    }
  }
  lua_settop(L, 0);
  dm_set_interactive(L, 0);
  set_config_interactive(L, 0);
  if (use_readline || isatty(STDIN_FILENO))
    fputs("\n", stdout);
  fflush(stdout);
#ifdef HAVE_READLINE
  free(history_path);
  history_path = NULL;
#endif
}

/* }====================================================================== */
