/* testrun.c -- `dmech test`: child processes, directories and clocks for the
 * Lua runner (lua/dmech/testrun.lua), in a Lua state of its own.
 *
 * sys.run(jobs, parallel, on_done) starts every job (an argv list) as a child
 * with stdin from /dev/null and stdout, stderr and descriptor 3 piped (3
 * carries the TAP, so what a test prints cannot be taken for a test line),
 * at most `parallel` at once, in the order given; as each one ends it calls
 * on_done(i, how, code, stdout, stderr, tap, seconds), how = "exit" |
 * "signal" | "spawn" (could not start: stderr says why).  Children stay in our process
 * group, so Ctrl-C at the terminal reaches them; a SIGINT also stops new
 * starts, is passed on to the running children, and makes run() return true
 * once they ended.  A second one ends the runner.
 *
 * Everything a run holds (slots, buffers, descriptors, children) lives in a
 * userdata whose __gc kills and reaps what is left, so an error raised
 * anywhere (a failing on_done, memory) leaks nothing; on_done errors are
 * re-raised after the children were killed and reaped.
 */
#include <config.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include "lua/dmlua.h"
#include "app/testrun.h"

extern char **environ;

#define POOL_MT "dmech.testrun.pool"
#define DIR_MT "dmech.testrun.dir"
#define READ_CHUNK 65536
#define SLICE_MS 100         /* poll slice: exits behind held pipes, SIGINT */
#define NSTREAM 3            /* stdout, stderr, TAP (descriptor 3 in the child) */

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* {==== SIGINT while children run ======================================= */

static volatile sig_atomic_t sigints = 0;

static void on_sigint(int sig)
{
  if (++sigints > 1) {
    signal(sig, SIG_DFL);
    raise(sig);
  }
}

/* }==== */

/* {==== the pool of running children ==================================== */

typedef struct outbuf {
  char *p;
  size_t len, cap;
} outbuf;

typedef struct slot {
  int job;             /* 1-based job index; 0 = free */
  pid_t pid;           /* > 0 until reaped */
  int fd[NSTREAM];     /* read ends of stdout, stderr, TAP; -1 once closed */
  outbuf out[NSTREAM];
  double t0;
} slot;

typedef struct pool {
  int n;
  int sigset;                 /* SIGINT handler installed: old is valid */
  struct sigaction old;
  struct pollfd *pfd;         /* NSTREAM n entries, after the slots */
  int *owner;                 /* slot of each pfd entry */
  slot s[];
} pool;

static void close_fd(int *fd)
{
  if (*fd >= 0) {
    close(*fd);
    *fd = -1;
  }
}

static void reap(pid_t pid, int *status)
{
  while (waitpid(pid, status, 0) < 0 && errno == EINTR)
    ;
}

/* Free a slot: kill (when asked) and reap its child, close, free. */
static void slot_clear(slot *s, int kill_child)
{
  int i, st;
  if (s->pid > 0) {
    if (kill_child)
      kill(s->pid, SIGKILL);
    reap(s->pid, &st);
  }
  for (i = 0; i < NSTREAM; i++) {
    close_fd(&s->fd[i]);
    free(s->out[i].p);
  }
  memset(s, 0, sizeof *s);
  for (i = 0; i < NSTREAM; i++)
    s->fd[i] = -1;
}

static void pool_release(pool *p)
{
  int i;
  for (i = 0; i < p->n; i++)
    if (p->s[i].job != 0)
      slot_clear(&p->s[i], 1);
  if (p->sigset) {
    sigaction(SIGINT, &p->old, NULL);
    p->sigset = 0;
  }
}

static int pool_gc(lua_State *L)
{
  pool_release(luaL_checkudata(L, 1, POOL_MT));
  return 0;
}

/* Read what is there now; 1 at end of file (fd closed), 0 when it would
 * block, -1 out of memory. */
static int drain(slot *s, int i)
{
  for (;;) {
    outbuf *b = &s->out[i];
    ssize_t r;
    if (b->cap - b->len < READ_CHUNK) {
      size_t cap = b->cap * 2 + READ_CHUNK;
      char *q = realloc(b->p, cap);
      if (q == NULL)
        return -1;
      b->p = q;
      b->cap = cap;
    }
    r = read(s->fd[i], b->p + b->len, b->cap - b->len);
    if (r > 0) {
      b->len += (size_t)r;
      continue;
    }
    if (r < 0 && errno == EINTR)
      continue;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
      return 0;
    close_fd(&s->fd[i]);      /* end of file, or an error reading: done */
    return 1;
  }
}

/* A pipe whose ends are >= 4 and close-on-exec (dup2 onto 1, 2 and 3 in
 * the child never meets the same descriptor and clears the flag as it
 * must). */
static int pipe_hi(int fds[2])
{
  int i;
  if (pipe2(fds, O_CLOEXEC) != 0)
    return -1;
  for (i = 0; i < 2; i++) {
    if (fds[i] < 4) {
      int hi = fcntl(fds[i], F_DUPFD_CLOEXEC, 4);
      if (hi < 0) {
        close(fds[0]);
        close(fds[1]);
        return -1;
      }
      close(fds[i]);
      fds[i] = hi;
    }
  }
  return 0;
}

/* Start argv in slot s; 0 or an errno. */
static int slot_start(slot *s, char **argv)
{
  int fds[NSTREAM][2], rc = 0, i, k;
  posix_spawn_file_actions_t fa;
  posix_spawnattr_t at;
  sigset_t def, none;
  pid_t pid;
  for (i = 0; i < NSTREAM; i++) {
    if (pipe_hi(fds[i]) != 0) {
      rc = errno;
      for (k = 0; k < i; k++) {
        close(fds[k][0]);
        close(fds[k][1]);
      }
      return rc;
    }
  }
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  for (i = 0; i < NSTREAM; i++)
    posix_spawn_file_actions_adddup2(&fa, fds[i][1], STDOUT_FILENO + i);
  posix_spawnattr_init(&at);
  posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  sigemptyset(&def);
  sigaddset(&def, SIGINT);
  sigaddset(&def, SIGPIPE);
  sigaddset(&def, SIGTERM);
  posix_spawnattr_setsigdefault(&at, &def);
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&at, &none);
  if (strchr(argv[0], '/') != NULL)
    rc = posix_spawn(&pid, argv[0], &fa, &at, argv, environ);
  else
    rc = posix_spawnp(&pid, argv[0], &fa, &at, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&at);
  for (i = 0; i < NSTREAM; i++) {
    close(fds[i][1]);
    if (rc != 0)
      close(fds[i][0]);
  }
  if (rc != 0)
    return rc;
  s->pid = pid;
  for (i = 0; i < NSTREAM; i++) {
    s->fd[i] = fds[i][0];
    fcntl(s->fd[i], F_SETFL, fcntl(s->fd[i], F_GETFL) | O_NONBLOCK);
  }
  s->t0 = now();
  return 0;
}

/* Stack: jobs, parallel, on_done, pool, argv buffer. */
#define JOBS 1
#define ON_DONE 3
#define POOL 4

/* Raise after freeing the pool (children killed and reaped). */
static int pool_error(lua_State *L, pool *p, const char *what)
{
  pool_release(p);
  return luaL_error(L, "%s", what);
}

/* Call on_done for the job that ended in slot s, then free the slot. */
static void finish(lua_State *L, pool *p, slot *s, const char *how, int code,
                   double secs)
{
  int i;
  lua_pushvalue(L, ON_DONE);
  lua_pushinteger(L, s->job);
  lua_pushstring(L, how);
  lua_pushinteger(L, code);
  for (i = 0; i < NSTREAM; i++)
    lua_pushlstring(L, s->out[i].p != NULL ? s->out[i].p : "", s->out[i].len);
  lua_pushnumber(L, secs);
  slot_clear(s, 0);
  if (lua_pcall(L, 4 + NSTREAM, 0, 0) != LUA_OK) {
    pool_release(p);
    lua_error(L);
  }
}

/* The child of slot s ended (status st): read what is left, report. */
static void ended(lua_State *L, pool *p, slot *s, int st)
{
  double secs = now() - s->t0;
  int i;
  s->pid = 0;
  for (i = 0; i < NSTREAM; i++) {
    if (s->fd[i] >= 0 && drain(s, i) < 0)
      pool_error(L, p, "not enough memory for a test's output");
    close_fd(&s->fd[i]);  /* a grandchild may still hold it: not waited for */
  }
  if (WIFSIGNALED(st))
    finish(L, p, s, "signal", WTERMSIG(st), secs);
  else
    finish(L, p, s, "exit", WEXITSTATUS(st), secs);
}

static void start_job(lua_State *L, pool *p, slot *s, int job, char **argv)
{
  int k, n, rc;
  lua_geti(L, JOBS, job);
  n = (int)luaL_len(L, -1);
  for (k = 0; k < n; k++) {
    lua_geti(L, -1, k + 1);
    argv[k] = (char *)lua_tostring(L, -1);  /* kept alive by the jobs table */
    lua_pop(L, 1);
  }
  argv[n] = NULL;
  lua_pop(L, 1);
  memset(s, 0, sizeof *s);
  for (k = 0; k < NSTREAM; k++)
    s->fd[k] = -1;
  s->job = job;
  rc = slot_start(s, argv);
  if (rc != 0) {
    char msg[300];
    snprintf(msg, sizeof msg, "cannot start '%s': %s\n", argv[0], strerror(rc));
    s->out[1].p = strdup(msg);
    s->out[1].len = s->out[1].p != NULL ? strlen(msg) : 0;
    finish(L, p, s, "spawn", rc, 0.0);
  }
}

/* The poll set of the open pipes; returns its size. */
static int poll_set(pool *p)
{
  int i, j, m = 0;
  for (i = 0; i < p->n; i++)
    for (j = 0; j < NSTREAM; j++)
      if (p->s[i].job != 0 && p->s[i].fd[j] >= 0) {
        p->pfd[m].fd = p->s[i].fd[j];
        p->pfd[m].events = POLLIN;
        p->pfd[m].revents = 0;
        p->owner[m++] = i * NSTREAM + j;
      }
  return m;
}

/* 1 when a child closed all its pipes but was not reaped yet: it is
 * exiting, look again soon. */
static int exiting(const pool *p)
{
  int i, j;
  for (i = 0; i < p->n; i++) {
    const slot *s = &p->s[i];
    if (s->job == 0 || s->pid <= 0)
      continue;
    for (j = 0; j < NSTREAM && s->fd[j] < 0; j++)
      ;
    if (j == NSTREAM)
      return 1;
  }
  return 0;
}

static int l_run(lua_State *L)
{
  lua_Integer njobs, parallel, next = 1;
  int i, j, maxargs = 1, running = 0, forwarded = 0;
  size_t size;
  pool *p;
  char **argv;
  struct sigaction sa;

  luaL_checktype(L, JOBS, LUA_TTABLE);
  parallel = luaL_checkinteger(L, 2);
  luaL_argcheck(L, parallel >= 1 && parallel <= 1024, 2, "between 1 and 1024 expected");
  luaL_checktype(L, ON_DONE, LUA_TFUNCTION);
  lua_settop(L, ON_DONE);
  njobs = luaL_len(L, JOBS);
  for (i = 1; i <= njobs; i++) {
    int k, n;
    if (lua_geti(L, JOBS, i) != LUA_TTABLE)
      return luaL_error(L, "job %d is not a list of strings", i);
    n = (int)luaL_len(L, -1);
    if (n < 1)
      return luaL_error(L, "job %d is empty", i);
    for (k = 1; k <= n; k++) {
      if (lua_geti(L, -1, k) != LUA_TSTRING)
        return luaL_error(L, "argument %d of job %d is not a string", k, i);
      lua_pop(L, 1);
    }
    if (n + 1 > maxargs)
      maxargs = n + 1;
    lua_pop(L, 1);
  }
  if (parallel > njobs)
    parallel = njobs > 0 ? njobs : 1;

  size = sizeof(pool) + (size_t)parallel * sizeof(slot)
         + NSTREAM * (size_t)parallel * (sizeof(struct pollfd) + sizeof(int));
  p = lua_newuserdatauv(L, size, 0);
  memset(p, 0, size);
  p->n = (int)parallel;
  p->pfd = (struct pollfd *)(void *)&p->s[parallel];
  p->owner = (int *)(void *)&p->pfd[NSTREAM * parallel];
  for (i = 0; i < p->n; i++)
    for (j = 0; j < NSTREAM; j++)
      p->s[i].fd[j] = -1;
  if (luaL_newmetatable(L, POOL_MT)) {
    lua_pushcfunction(L, pool_gc);
    lua_setfield(L, -2, "__gc");
  }
  lua_setmetatable(L, POOL);
  argv = lua_newuserdatauv(L, (size_t)maxargs * sizeof(char *), 0);

  sigints = 0;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &p->old);
  p->sigset = 1;

  for (;;) {
    int m, rc;
    while (sigints == 0 && running < p->n && next <= njobs) {
      for (i = 0; p->s[i].job != 0; i++)
        ;
      start_job(L, p, &p->s[i], (int)next++, argv);
      if (p->s[i].job != 0)
        running++;
    }
    if (sigints > 0 && !forwarded) {
      for (i = 0; i < p->n; i++)
        if (p->s[i].pid > 0)
          kill(p->s[i].pid, SIGINT);
      forwarded = 1;
    }
    if (running == 0)
      break;
    m = poll_set(p);
    rc = poll(p->pfd, (nfds_t)m, exiting(p) ? 1 : SLICE_MS);
    if (rc < 0 && errno != EINTR)
      return pool_error(L, p, strerror(errno));
    for (i = 0; rc > 0 && i < m; i++)
      if (p->pfd[i].revents != 0) {
        slot *s = &p->s[p->owner[i] / NSTREAM];
        j = p->owner[i] % NSTREAM;
        if (s->fd[j] >= 0 && drain(s, j) < 0)
          return pool_error(L, p, "not enough memory for a test's output");
      }
    for (i = 0; i < p->n; i++) {
      slot *s = &p->s[i];
      int st;
      pid_t r;
      if (s->job == 0 || s->pid <= 0)
        continue;
      r = waitpid(s->pid, &st, WNOHANG);
      if (r == s->pid) {
        ended(L, p, s, st);
        running--;
      }
    }
  }
  pool_release(p);
  lua_pushboolean(L, sigints > 0);
  return 1;
}

/* }==== */

/* {==== files, cores, clock ============================================= */

static int dir_gc(lua_State *L)
{
  DIR **d = luaL_checkudata(L, 1, DIR_MT);
  if (*d != NULL) {
    closedir(*d);
    *d = NULL;
  }
  return 0;
}

static const char *kind_of(const struct stat *st)
{
  return S_ISDIR(st->st_mode) ? "dir" : S_ISREG(st->st_mode) ? "file" : "other";
}

/* sys.kind(path) -> "file" | "dir" | "other" | nil, message */
static int l_kind(lua_State *L)
{
  const char *path = luaL_checkstring(L, 1);
  struct stat st;
  if (stat(path, &st) != 0) {
    luaL_pushfail(L);
    lua_pushfstring(L, "%s: %s", path, strerror(errno));
    return 2;
  }
  lua_pushstring(L, kind_of(&st));
  return 1;
}

/* sys.list(dir) -> names, kinds (unsorted; symbolic links followed) | nil, message */
static int l_list(lua_State *L)
{
  const char *path = luaL_checkstring(L, 1);
  DIR **d;
  struct dirent *e;
  lua_Integer n = 0;
  d = lua_newuserdatauv(L, sizeof *d, 0);
  *d = NULL;
  if (luaL_newmetatable(L, DIR_MT)) {
    lua_pushcfunction(L, dir_gc);
    lua_setfield(L, -2, "__gc");
  }
  lua_setmetatable(L, -2);
  *d = opendir(path);
  if (*d == NULL) {
    luaL_pushfail(L);
    lua_pushfstring(L, "%s: %s", path, strerror(errno));
    return 2;
  }
  lua_newtable(L);
  lua_newtable(L);
  while ((errno = 0, e = readdir(*d)) != NULL) {
    const char *kind;
    struct stat st;
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
      continue;
    if (e->d_type == DT_DIR)
      kind = "dir";
    else if (e->d_type == DT_REG)
      kind = "file";
    else if (fstatat(dirfd(*d), e->d_name, &st, 0) == 0)
      kind = kind_of(&st);
    else
      kind = "other";
    n++;
    lua_pushstring(L, e->d_name);
    lua_rawseti(L, -3, n);
    lua_pushstring(L, kind);
    lua_rawseti(L, -2, n);
  }
  closedir(*d);
  *d = NULL;
  return 2;
}

/* sys.ncpu() -> the cores this process may run on */
static int l_ncpu(lua_State *L)
{
  cpu_set_t set;
  long n = 0;
  if (sched_getaffinity(0, sizeof set, &set) == 0)
    n = CPU_COUNT(&set);
  if (n < 1)
    n = sysconf(_SC_NPROCESSORS_ONLN);
  lua_pushinteger(L, n >= 1 ? n : 1);
  return 1;
}

static int l_clock(lua_State *L)
{
  lua_pushnumber(L, now());
  return 1;
}

/* sys.exe() -> the path of this program, or nil */
static int l_exe(lua_State *L)
{
  char buf[4096];
  ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0 || (size_t)n >= sizeof buf - 1) {
    luaL_pushfail(L);
    return 1;
  }
  lua_pushlstring(L, buf, (size_t)n);
  return 1;
}

/* }==== */

static const luaL_Reg sys_funcs[] = {
  {"run", l_run}, {"kind", l_kind}, {"list", l_list}, {"ncpu", l_ncpu},
  {"clock", l_clock}, {"exe", l_exe}, {NULL, NULL}
};

/* Under lua_pcall: the libraries, dmech (for its search path), then
 * require("dmech.testrun").main(args, sys) -> exit status. */
static int tmain(lua_State *L)
{
  int argc = (int)lua_tointeger(L, 1), i;
  char **argv = lua_touserdata(L, 2);
  luaL_openlibs(L);
  luaL_requiref(L, "dmech", luaopen_dmech, 0);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.testrun");
  lua_call(L, 1, 1);
  lua_getfield(L, -1, "main");
  lua_createtable(L, argc, 0);
  for (i = 2; i < argc; i++) {
    lua_pushstring(L, argv[i]);
    lua_rawseti(L, -2, i - 1);
  }
  luaL_newlib(L, sys_funcs);
  lua_pushstring(L, argv[0]);
  lua_setfield(L, -2, "argv0");
  lua_call(L, 2, 1);
  return 1;
}

int dm_testrun(int argc, char **argv)
{
  lua_State *L = luaL_newstate();
  int status, code;
  if (L == NULL) {
    fprintf(stderr, "%s test: not enough memory\n", argv[0]);
    return 2;
  }
  lua_pushcfunction(L, tmain);
  lua_pushinteger(L, argc);
  lua_pushlightuserdata(L, argv);
  status = lua_pcall(L, 2, 1, 0);
  if (status != LUA_OK) {
    const char *msg = lua_tostring(L, -1);
    fflush(stdout);
    fprintf(stderr, "%s test: %s\n", argv[0], msg != NULL ? msg : "(error object is not a string)");
    code = 2;
  } else {
    code = lua_isinteger(L, -1) ? (int)lua_tointeger(L, -1) : 2;
  }
  lua_close(L);
  if (fflush(stdout) != 0 && code == 0)
    code = 2;
  return code;
}
