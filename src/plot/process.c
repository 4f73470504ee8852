/* process.c -- the gnuplot child: spawn, pipes, poll loop, death, kill.
 *
 * All three pipe ends we keep are non-blocking and close-on-exec.  Writing
 * and reading are interleaved in one poll loop (gp_pump), so gnuplot can
 * never block on a full stdout/stderr pipe while we block on a full stdin
 * pipe.  SIGPIPE is blocked around each write (and a SIGPIPE it raised is
 * consumed), so a dead gnuplot shows up as EPIPE, never kills dmech, and the
 * process-wide SIGPIPE disposition stays the application's business.
 */
#include <config.h>

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "plot/gp_private.h"

extern char **environ;

#define GP_SLICE_MS 100      /* poll slice: how often interrupts are seen */
#define GP_READ_CHUNK 65536

double gp_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char *gp_program(const dm_gp_session *s)
{
  const char *env;
  if (s->program != NULL)
    return s->program;
  env = getenv("DMECH_GNUPLOT");
  return (env != NULL && *env != '\0') ? env : "gnuplot";
}

/* {==== spawning ========================================================= */

/* A pipe whose ends are both >= 3 (so dup2 onto 0..2 in the child never
 * hits the same descriptor and clears close-on-exec as it must). */
static int pipe_hi(int fds[2])
{
  int i;
  if (pipe2(fds, O_CLOEXEC) != 0)
    return -1;
  for (i = 0; i < 2; i++) {
    if (fds[i] < 3) {
      int hi = fcntl(fds[i], F_DUPFD_CLOEXEC, 3);
      if (hi < 0)
        return -1;
      close(fds[i]);
      fds[i] = hi;
    }
  }
  return 0;
}

static void close_fd(int *fd)
{
  if (*fd >= 0) {
    close(*fd);
    *fd = -1;
  }
}

static int set_nonblock(int fd)
{
  int fl = fcntl(fd, F_GETFL);
  return fl < 0 ? -1 : fcntl(fd, F_SETFL, fl | O_NONBLOCK);
}

static int spawn_fail(dm_err *e, const char *prog, int err)
{
  if (err == ENOENT)
    return dm_err_set(e, DM_ENOTFOUND,
                      "gnuplot program '%s' not found; install gnuplot or set "
                      "DMECH_GNUPLOT to its path", prog);
  return dm_err_set(e, DM_EIO, "cannot start gnuplot program '%s': %s", prog,
                    strerror(err));
}

/* Resolve prog like execvp would (a name with '/' as is, else through
 * $PATH) into out; 0 or an errno.  Done before spawning so a missing
 * program is reported the same way whatever posix_spawn does (glibc reports
 * exec failures, other implementations and valgrind exit with 127). */
static int find_program(const char *prog, char *out, size_t size)
{
  struct stat st;
  const char *path, *p;
  int err = ENOENT;
  if (prog[0] == '\0')
    return ENOENT;
  if (strchr(prog, '/') != NULL) {
    if (stat(prog, &st) != 0)
      return errno;
    if (!S_ISREG(st.st_mode) || access(prog, X_OK) != 0)
      return EACCES;
    snprintf(out, size, "%s", prog);
    return 0;
  }
  path = getenv("PATH");
  if (path == NULL)
    path = "/usr/local/bin:/usr/bin:/bin";
  for (p = path;; p++) {
    const char *q = strchr(p, ':');
    size_t n = q != NULL ? (size_t)(q - p) : strlen(p);
    if ((size_t)snprintf(out, size, "%.*s%s%s", (int)n, p, n > 0 ? "/" : "",
                         prog) < size
        && stat(out, &st) == 0) {
      if (S_ISREG(st.st_mode) && access(out, X_OK) == 0)
        return 0;
      err = EACCES;
    }
    if (q == NULL)
      break;
    p = q;
  }
  return err;
}

/* Start the program with piped stdio in a new process group (pgid = pid),
 * signals at their defaults and none blocked. */
int gp_spawn(dm_gp_session *s, dm_err *e)
{
  int in[2] = {-1, -1}, out[2] = {-1, -1}, err[2] = {-1, -1};
  const char *prog = gp_program(s);
  char exe[4096], *argv[2];
  posix_spawn_file_actions_t fa;
  posix_spawnattr_t at;
  sigset_t def, none;
  pid_t pid;
  int rc;

  if ((rc = find_program(prog, exe, sizeof exe)) != 0)
    return spawn_fail(e, prog, rc);
  if (pipe_hi(in) != 0 || pipe_hi(out) != 0 || pipe_hi(err) != 0) {
    rc = errno;
    close_fd(&in[0]); close_fd(&in[1]); close_fd(&out[0]);
    close_fd(&out[1]); close_fd(&err[0]); close_fd(&err[1]);
    return dm_err_set(e, DM_EIO, "cannot create pipes for gnuplot: %s",
                      strerror(rc));
  }
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, in[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&fa, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&fa, err[1], STDERR_FILENO);
#if HAVE_POSIX_SPAWN_FILE_ACTIONS_ADDCLOSEFROM_NP
  /* nothing but stdio: a file another thread has open without
   * close-on-exec (HDF5 files, with their flock) must not stay open, and
   * locked, as long as gnuplot runs */
  posix_spawn_file_actions_addclosefrom_np(&fa, 3);
#endif
  posix_spawnattr_init(&at);
  posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF
                                | POSIX_SPAWN_SETSIGMASK);
  posix_spawnattr_setpgroup(&at, 0);
  sigemptyset(&def);
  sigaddset(&def, SIGINT);  sigaddset(&def, SIGQUIT); sigaddset(&def, SIGPIPE);
  sigaddset(&def, SIGTERM); sigaddset(&def, SIGHUP);  sigaddset(&def, SIGCHLD);
  sigaddset(&def, SIGTSTP); sigaddset(&def, SIGTTIN); sigaddset(&def, SIGTTOU);
  posix_spawnattr_setsigdefault(&at, &def);
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&at, &none);
  argv[0] = (char *)prog;
  argv[1] = NULL;
  rc = posix_spawn(&pid, exe, &fa, &at, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&at);
  close_fd(&in[0]);
  close_fd(&out[1]);
  close_fd(&err[1]);
  if (rc != 0) {
    close_fd(&in[1]); close_fd(&out[0]); close_fd(&err[0]);
    return spawn_fail(e, prog, rc);
  }
  set_nonblock(in[1]);
  set_nonblock(out[0]);
  set_nonblock(err[0]);
  s->pid = pid;
  s->fd_in = in[1];
  s->fd_out = out[0];
  s->fd_err = err[0];
  s->generation++;
  gp_buf_clear(&s->wbuf);
  gp_buf_clear(&s->ebuf);
  gp_buf_clear(&s->last_err);
  s->woff = 0;
  return DM_OK;
}

/* }==== */

/* {==== death =============================================================== */

static void reap(dm_gp_session *s, int *status)
{
  pid_t r;
  do
    r = waitpid(s->pid, status, 0);
  while (r < 0 && errno == EINTR);
}

/* 1 when pid has exited (left as a zombie, not reaped: its pid, which is
 * also the process group id, cannot be reused while we kill the group),
 * 0 while it runs, -1 when it is not our child any more. */
static int exited(pid_t pid)
{
  siginfo_t si;
  memset(&si, 0, sizeof si);
  if (waitid(P_PID, (id_t)pid, &si, WEXITED | WNOHANG | WNOWAIT) != 0)
    return errno == EINTR ? 0 : -1;
  return si.si_pid == pid ? 1 : 0;
}

static void forget_process(dm_gp_session *s)
{
  close_fd(&s->fd_in);
  close_fd(&s->fd_out);
  close_fd(&s->fd_err);
  s->pid = -1;
  s->woff = 0;
  s->dirty = 0;
  s->to_stdout = 0;
  gp_buf_clear(&s->wbuf);
  gp_buf_clear(&s->ebuf);
  gp_output_discard(s);
  gp_data_cleanup(s, 0);
}

/* Kill the whole process group (gnuplot and helpers such as gnuplot_qt)
 * and reap gnuplot. */
void gp_kill(dm_gp_session *s)
{
  int status;
  if (s->pid > 0) {
    kill(-s->pid, SIGKILL);
    kill(s->pid, SIGKILL);
    reap(s, &status);
    gp_log(s, "# dmech: gnuplot (pid %ld) stopped\n", (long)s->pid);
  }
  forget_process(s);
}

void dm_gp_stop(dm_gp_session *s)
{
  if (s != NULL)
    gp_kill(s);
}

/* Is gnuplot still there?  Reaps (and forgets) a process that exited or
 * whose stdin is gone. */
int gp_alive(dm_gp_session *s)
{
  struct pollfd p;
  int status;
  pid_t r;
  if (s->pid <= 0)
    return 0;
  if ((r = exited(s->pid)) != 0) {
    if (r > 0) {
      kill(-s->pid, SIGKILL);             /* leftover helpers */
      reap(s, &status);
    }
    gp_log(s, "# dmech: gnuplot (pid %ld) had exited\n", (long)s->pid);
    forget_process(s);
    return 0;
  }
  p.fd = s->fd_in;
  p.events = POLLOUT;
  p.revents = 0;
  if (poll(&p, 1, 0) > 0 && (p.revents & (POLLERR | POLLHUP | POLLNVAL))) {
    gp_kill(s);
    return 0;
  }
  return 1;
}

static void describe_status(char *buf, size_t n, int status)
{
  if (WIFEXITED(status))
    snprintf(buf, n, "exit status %d", WEXITSTATUS(status));
  else if (WIFSIGNALED(status))
    snprintf(buf, n, "killed by signal %d", WTERMSIG(status));
  else
    snprintf(buf, n, "status %d", status);
}

/* gnuplot closed a pipe: give it a moment to exit, reap it, report what it
 * last said. */
static int gp_died(dm_gp_session *s, dm_err *e)
{
  char how[64], tail[200];
  int status = 0, i;
  pid_t r = 0, pid = s->pid;
  size_t n;
  for (i = 0; i < 50; i++) {                 /* up to 0.5 s */
    struct timespec ts = {0, 10000000L};
    if ((r = exited(pid)) != 0)
      break;
    nanosleep(&ts, NULL);
  }
  if (r >= 0) {
    kill(-pid, SIGKILL);                     /* helpers; gnuplot if still up */
    kill(pid, SIGKILL);
    reap(s, &status);
  }
  if (r < 0)
    snprintf(how, sizeof how, "status unknown");
  else
    describe_status(how, sizeof how, status);
  if (r >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 127
      && s->starting) {
    gp_log(s, "# dmech: gnuplot (pid %ld) could not run (%s)\n", (long)pid, how);
    forget_process(s);
    return dm_err_set(e, DM_ENOTFOUND, "gnuplot program '%s' could not be "
                      "run (%s); install gnuplot or set DMECH_GNUPLOT to its "
                      "path", gp_program(s), how);
  }
  gp_buf_append(&s->last_err, s->ebuf.p != NULL ? s->ebuf.p : "", s->ebuf.len);
  n = s->last_err.len;
  tail[0] = '\0';
  if (n > 0) {
    const char *p = s->last_err.p + (n > sizeof tail - 1 ? n - (sizeof tail - 1) : 0);
    snprintf(tail, sizeof tail, "%s", p);
    for (i = 0; tail[i] != '\0'; i++)
      if (tail[i] == '\n' || tail[i] == '\r')
        tail[i] = ' ';
  }
  gp_log(s, "# dmech: gnuplot (pid %ld) exited (%s)\n", (long)pid, how);
  forget_process(s);
  return dm_err_set(e, DM_EIO, "gnuplot (pid %ld) exited unexpectedly (%s)%s%s",
                    (long)pid, how, tail[0] ? ": " : "", tail);
}

static int gp_hung(dm_gp_session *s, const char *doing, dm_err *e)
{
  pid_t pid = s->pid;
  gp_kill(s);
  return dm_err_set(e, DM_ETIMEOUT,
                    "gnuplot (pid %ld) did not answer within %g s while %s; "
                    "it was stopped and will be restarted", (long)pid,
                    s->timeout, doing);
}

static int gp_stopped_by_user(dm_gp_session *s, dm_err *e)
{
  gp_kill(s);
  return dm_err_set(e, DM_EINTR, "interrupted while waiting for gnuplot; "
                    "it was stopped and will be restarted");
}

/* }==== */

/* {==== the poll loop ======================================================= */

/* Read everything available on fd into b; *eof set when the pipe closed. */
static int drain(int fd, gp_buf *b, size_t *got, int *eof)
{
  for (;;) {
    ssize_t r;
    if (gp_buf_reserve(b, GP_READ_CHUNK) != 0)
      return DM_ENOMEM;
    r = read(fd, b->p + b->len, GP_READ_CHUNK);
    if (r > 0) {
      b->len += (size_t)r;
      b->p[b->len] = '\0';
      *got += (size_t)r;
      continue;
    }
    if (r == 0)
      *eof = 1;
    else if (errno == EINTR)
      continue;
    else if (errno != EAGAIN && errno != EWOULDBLOCK)
      *eof = 1;
    return DM_OK;
  }
}

/* write() with SIGPIPE blocked; a SIGPIPE raised by this write is consumed
 * unless one was already pending before. */
static ssize_t write_nopipe(int fd, const void *buf, size_t n)
{
  sigset_t pipeset, old, pending;
  int was_pending, saved;
  ssize_t r;
  sigemptyset(&pipeset);
  sigaddset(&pipeset, SIGPIPE);
  sigpending(&pending);
  was_pending = sigismember(&pending, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipeset, &old);
  r = write(fd, buf, n);
  saved = errno;
  if (r < 0 && saved == EPIPE && !was_pending) {
    struct timespec zero = {0, 0};
    while (sigtimedwait(&pipeset, NULL, &zero) < 0 && errno == EINTR)
      ;
  }
  pthread_sigmask(SIG_SETMASK, &old, NULL);
  errno = saved;
  return r;
}

/* One poll round: write what we can of wbuf (when want_write), read what
 * gnuplot wrote.  *progress counts the bytes moved. */
static int gp_pump(dm_gp_session *s, int want_write, int wait_ms,
                   size_t *progress, dm_err *e)
{
  struct pollfd p[3];
  int n = 0, iw = -1, eof = 0, rc, i;
  *progress = 0;
  if (want_write && s->woff < s->wbuf.len) {
    iw = n;
    p[n].fd = s->fd_in;
    p[n++].events = POLLOUT;
  }
  p[n].fd = s->fd_out;
  p[n++].events = POLLIN;
  p[n].fd = s->fd_err;
  p[n++].events = POLLIN;
  for (i = 0; i < n; i++)
    p[i].revents = 0;
  if (poll(p, (nfds_t)n, wait_ms) < 0) {
    if (errno == EINTR)
      return DM_OK;
    return dm_err_set(e, DM_EIO, "poll on gnuplot's pipes failed: %s",
                      strerror(errno));
  }
  for (i = (iw == 0 ? 1 : 0); i < n; i++) {
    if (p[i].revents == 0)
      continue;
    rc = drain(p[i].fd, p[i].fd == s->fd_out ? &s->obuf : &s->ebuf, progress,
               &eof);
    if (rc != DM_OK)
      return dm_err_set(e, rc, "out of memory reading gnuplot's output");
  }
  if (iw == 0 && p[0].revents != 0) {
    if (p[0].revents & (POLLERR | POLLHUP | POLLNVAL)) {
      eof = 1;
    } else {
      size_t len = s->wbuf.len - s->woff;
      ssize_t w = write_nopipe(s->fd_in, s->wbuf.p + s->woff,
                               len > GP_READ_CHUNK ? GP_READ_CHUNK : len);
      if (w > 0) {
        s->woff += (size_t)w;
        *progress += (size_t)w;
      } else if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK
                 && errno != EINTR) {
        eof = 1;
      }
    }
  }
  if (eof)
    return gp_died(s, e);
  return DM_OK;
}

/* Common wait: no progress for s->timeout seconds means hung; an interrupt
 * stops gnuplot. */
static int check_stall(dm_gp_session *s, size_t progress, double *last,
                       const char *doing, dm_err *e)
{
  double t = gp_now();
  if (progress > 0) {
    *last = t;
    return DM_OK;
  }
  if (dm_interrupted())
    return gp_stopped_by_user(s, e);
  if (t - *last > s->timeout)
    return gp_hung(s, doing, e);
  return DM_OK;
}

/* Write all of wbuf. */
int gp_flush(dm_gp_session *s, dm_err *e)
{
  double last = gp_now();
  size_t progress;
  int rc;
  if (s->pid <= 0)
    return dm_err_set(e, DM_EIO, "gnuplot is not running");
  while (s->woff < s->wbuf.len) {
    rc = gp_pump(s, 1, GP_SLICE_MS, &progress, e);
    if (rc == DM_OK)
      rc = check_stall(s, progress, &last, "receiving commands", e);
    if (rc != DM_OK)
      return rc;
  }
  gp_buf_clear(&s->wbuf);
  s->woff = 0;
  return DM_OK;
}

/* Flush, then read stderr until a line starting with `marker` arrived;
 * *pos = its offset in ebuf.  Finally collect whatever gnuplot already wrote
 * to stdout (it flushes a text plot before it reaches the marker). */
int gp_wait_marker(dm_gp_session *s, const char *marker, size_t *pos,
                   dm_err *e)
{
  size_t mlen = strlen(marker), progress, line = 0;
  double last;
  int rc = gp_flush(s, e);
  if (rc != DM_OK)
    return rc;
  last = gp_now();
  for (;;) {
    char *nl;
    /* scan complete lines from `line` on */
    while (line < s->ebuf.len
           && (nl = memchr(s->ebuf.p + line, '\n', s->ebuf.len - line)) != NULL) {
      size_t end = (size_t)(nl - s->ebuf.p);
      if (end - line >= mlen && memcmp(s->ebuf.p + line, marker, mlen) == 0) {
        *pos = line;
        do
          rc = gp_pump(s, 0, 0, &progress, e);
        while (rc == DM_OK && progress > 0);
        return rc;
      }
      line = end + 1;
    }
    rc = gp_pump(s, 0, GP_SLICE_MS, &progress, e);
    if (rc == DM_OK)
      rc = check_stall(s, progress, &last, "working on a command", e);
    if (rc != DM_OK)
      return rc;
  }
}

/* }==== */
