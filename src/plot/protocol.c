/* protocol.c -- sessions, transactions, datablocks and checkpoints.
 *
 * A checkpoint line is
 *     set print; print '<marker>', GPVAL_ERRNO; reset errors
 * preceded by an empty line (it ends a dangling `\` continuation).  `set
 * print` makes sure the marker goes to stderr even after a raw `set print
 * "file"`; GPVAL_ERRNO tells an error from mere output (warnings, `print`).
 */
#include <config.h>

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "core/numfmt.h"
#include "plot/gp_private.h"

#define GP_DEFAULT_TIMEOUT 30.0

/* {==== buffers ============================================================== */

int gp_buf_reserve(gp_buf *b, size_t extra)
{
  size_t need = b->len + extra + 1, cap;
  char *p;
  if (need <= b->cap)
    return 0;
  cap = b->cap ? b->cap : 256;
  while (cap < need)
    cap *= 2;
  p = realloc(b->p, cap);
  if (p == NULL)
    return -1;
  b->p = p;
  b->cap = cap;
  return 0;
}

int gp_buf_append(gp_buf *b, const char *data, size_t len)
{
  if (gp_buf_reserve(b, len) != 0)
    return -1;
  if (len > 0)
    memcpy(b->p + b->len, data, len);
  b->len += len;
  b->p[b->len] = '\0';
  return 0;
}

void gp_buf_consume(gp_buf *b, size_t n)
{
  if (n >= b->len) {
    gp_buf_clear(b);
    return;
  }
  memmove(b->p, b->p + n, b->len - n);
  b->len -= n;
  b->p[b->len] = '\0';
}

void gp_buf_clear(gp_buf *b)
{
  b->len = 0;
  if (b->p != NULL)
    b->p[0] = '\0';
}

void gp_buf_free(gp_buf *b)
{
  free(b->p);
  b->p = NULL;
  b->len = b->cap = 0;
}

/* }==== */

/* {==== lifetime ============================================================= */

dm_gp_session *dm_gp_session_alloc(void)
{
  dm_gp_session *s = calloc(1, sizeof *s);
  const char *env;
  if (s == NULL)
    return NULL;
  s->pid = -1;
  s->fd_in = s->fd_out = s->fd_err = -1;
  s->datadir_slot = s->out.slot = -1;
  s->timeout = GP_DEFAULT_TIMEOUT;
  env = getenv("DMECH_GNUPLOT_TIMEOUT");
  if (env != NULL && *env != '\0') {
    double t = dm_num_parse(env, NULL);
    if (t > 0 && isfinite(t))
      s->timeout = t;
  }
  env = getenv("DMECH_GNUPLOT_LOG");
  if (env != NULL && *env != '\0')
    dm_gp_set_log(s, env, NULL);           /* a bad path only loses the log */
  return s;
}

/* Let gnuplot finish on end-of-input for a moment, then kill its group. */
void dm_gp_session_free(dm_gp_session *s)
{
  if (s == NULL)
    return;
  if (s->pid > 0) {
    int i;
    close(s->fd_in);
    s->fd_in = -1;
    for (i = 0; i < 30 && gp_alive(s); i++) {
      struct timespec ts = {0, 10000000L};
      nanosleep(&ts, NULL);
    }
    gp_kill(s);
  }
  gp_output_discard(s);
  gp_data_cleanup(s, 1);
  if (s->log != NULL)
    fclose(s->log);
  free(s->program);
  gp_buf_free(&s->wbuf);
  gp_buf_free(&s->obuf);
  gp_buf_free(&s->ebuf);
  gp_buf_free(&s->msgs);
  gp_buf_free(&s->last_err);
  free(s);
}

int dm_gp_set_program(dm_gp_session *s, const char *program, dm_err *e)
{
  char *copy = NULL;
  if (program != NULL && (copy = strdup(program)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  free(s->program);
  s->program = copy;
  return DM_OK;
}

void dm_gp_set_timeout(dm_gp_session *s, double seconds)
{
  if (seconds > 0 && isfinite(seconds))
    s->timeout = seconds;
}

double dm_gp_timeout(const dm_gp_session *s) { return s->timeout; }
pid_t dm_gp_pid(const dm_gp_session *s) { return s->pid; }
unsigned long dm_gp_generation(const dm_gp_session *s) { return s->generation; }
const char *dm_gp_terminals(const dm_gp_session *s) { return s->terminals; }
double dm_gp_version(const dm_gp_session *s) { return s->version; }

int dm_gp_set_log(dm_gp_session *s, const char *path, dm_err *e)
{
  FILE *f = NULL;
  if (path != NULL && (f = fopen(path, "a")) == NULL)
    return dm_err_set(e, DM_EIO, "cannot open gnuplot log '%s': %s", path,
                      strerror(errno));
  if (s->log != NULL)
    fclose(s->log);
  s->log = f;
  return DM_OK;
}

void gp_log(dm_gp_session *s, const char *fmt, ...)
{
  va_list ap;
  if (s->log == NULL)
    return;
  va_start(ap, fmt);
  vfprintf(s->log, fmt, ap);
  va_end(ap);
  fflush(s->log);
}

/* }==== */

/* {==== sending =============================================================== */

/* Queue bytes (logged), streaming out once enough is queued. */
static int queue(dm_gp_session *s, const char *data, size_t len, int logit,
                 dm_err *e)
{
  if (s->pid <= 0)
    return dm_err_set(e, DM_EIO, "gnuplot is not running");
  if (gp_buf_append(&s->wbuf, data, len) != 0)
    return dm_err_set(e, DM_ENOMEM, "out of memory queueing gnuplot commands");
  if (logit && s->log != NULL)
    fwrite(data, 1, len, s->log);
  if (s->wbuf.len - s->woff > GP_FLUSH_AT)
    return gp_flush(s, e);
  return DM_OK;
}

int gp_append(dm_gp_session *s, const char *data, size_t len, dm_err *e)
{
  return queue(s, data, len, 1, e);
}

int gp_send_unlogged(dm_gp_session *s, const char *data, size_t len,
                     dm_err *e)
{
  return queue(s, data, len, 0, e);
}

int gp_sendq_unlogged(dm_gp_session *s, const char *str, dm_err *e)
{
  size_t n = dm_gp_quote(NULL, 0, str, strlen(str), DM_GP_QUOTE_ONELINE);
  char *q = malloc(n + 1);
  int rc;
  if (q == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory quoting a string");
  dm_gp_quote(q, n + 1, str, strlen(str), DM_GP_QUOTE_ONELINE);
  rc = queue(s, q, n, 0, e);
  free(q);
  return rc;
}

int dm_gp_send(dm_gp_session *s, dm_err *e, const char *fmt, ...)
{
  va_list ap;
  locale_t old;
  char small[512], *big = NULL;
  int n, rc;
  old = dm_num_enter();
  va_start(ap, fmt);
  n = vsnprintf(small, sizeof small, fmt, ap);
  va_end(ap);
  if (n >= (int)sizeof small) {
    big = malloc((size_t)n + 1);
    if (big != NULL) {
      va_start(ap, fmt);
      vsnprintf(big, (size_t)n + 1, fmt, ap);
      va_end(ap);
    }
  }
  dm_num_leave(old);
  if (n < 0 || (n >= (int)sizeof small && big == NULL))
    return dm_err_set(e, DM_ENOMEM, "cannot format gnuplot command");
  rc = gp_append(s, big != NULL ? big : small, (size_t)n, e);
  free(big);
  return rc;
}

int dm_gp_sendq(dm_gp_session *s, const char *str, size_t len, int flags,
                dm_err *e)
{
  char small[512], *big = NULL;
  size_t n = dm_gp_quote(small, sizeof small, str, len, flags);
  int rc;
  if (n >= sizeof small) {
    if ((big = malloc(n + 1)) == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory quoting a string");
    dm_gp_quote(big, n + 1, str, len, flags);
  }
  rc = gp_append(s, big != NULL ? big : small, n, e);
  free(big);
  return rc;
}

/* }==== */

/* {==== checkpoints ========================================================== */

/* Send the marker line and wait for it; msgs = stderr text before it;
 * *gp_errno = GPVAL_ERRNO as gnuplot printed it. */
int gp_roundtrip(dm_gp_session *s, const char *what, int *gp_errno, dm_err *e)
{
  char marker[96], cmd[160];
  size_t pos = 0, eol;
  const char *after;
  int rc, n;
  s->serial++;
  snprintf(marker, sizeof marker, "DMECH_CHECKPOINT_%ld_%lu", (long)getpid(),
           s->serial);
  n = snprintf(cmd, sizeof cmd,
               "\nset print; print '%s', GPVAL_ERRNO; reset errors\n", marker);
  gp_log(s, "# dmech: checkpoint (%s)\n", what != NULL ? what : "");
  rc = queue(s, cmd, (size_t)n, 0, e);
  if (rc == DM_OK)
    rc = gp_wait_marker(s, marker, &pos, e);
  gp_data_cleanup(s, 0);
  if (rc != DM_OK)
    return rc;
  gp_buf_clear(&s->msgs);
  gp_buf_append(&s->msgs, s->ebuf.p, pos);
  after = s->ebuf.p + pos + strlen(marker);
  *gp_errno = (int)strtol(after, NULL, 10);
  eol = (size_t)((const char *)memchr(after, '\n',
                                      s->ebuf.len - (size_t)(after - s->ebuf.p))
                 - s->ebuf.p);
  gp_buf_consume(&s->ebuf, eol + 1);
  gp_buf_clear(&s->last_err);
  gp_buf_append(&s->last_err, s->msgs.p, s->msgs.len);
  return DM_OK;
}

/* Skip blanks; return pointer to the first non-blank. */
static const char *skipws(const char *p, const char *end)
{
  while (p < end && (*p == ' ' || *p == '\t' || *p == '\r'))
    p++;
  return p;
}

/* Compose "<what>: gnuplot: <complaints> (at: <echoed command>)" from the
 * stderr text: echo lines "gnuplot> ..." give the command, caret lines are
 * dropped, "line N: " prefixes removed, warnings put after the errors. */
static int complaint(dm_gp_session *s, const char *what, dm_err *e)
{
  char text[2][DM_ERRMSG_MAX], at[160];
  size_t k[2] = {0, 0};
  const char *p = s->msgs.p != NULL ? s->msgs.p : "", *end = p + s->msgs.len;
  at[0] = text[0][0] = text[1][0] = '\0';
  while (p < end) {
    const char *nl = memchr(p, '\n', (size_t)(end - p)), *q, *le;
    le = nl != NULL ? nl : end;
    while (le > p && (le[-1] == ' ' || le[-1] == '\r'))
      le--;
    q = skipws(p, le);
    if (q < le && !(*q == '^' && skipws(q + 1, le) == le)) {
      if ((size_t)(le - q) > 9 && memcmp(q, "gnuplot> ", 9) == 0) {
        snprintf(at, sizeof at, "%.*s", (int)(le - q - 9), q + 9);
      } else {
        int w = (size_t)(le - q) > 8 && strncasecmp(q, "warning:", 8) == 0;
        if ((size_t)(le - q) > 5 && memcmp(q, "line ", 5) == 0) {
          const char *c = memchr(q, ':', (size_t)(le - q));
          if (c != NULL)
            q = skipws(c + 1, le);
        }
        if (k[w] + 3 < sizeof text[w])
          k[w] += (size_t)snprintf(text[w] + k[w], sizeof text[w] - k[w],
                                   "%s%.*s", k[w] > 0 ? "; " : "",
                                   (int)(le - q), q);
      }
    }
    p = nl != NULL ? nl + 1 : end;
  }
  if (k[0] == 0 && k[1] == 0)
    snprintf(text[0], sizeof text[0], "error (no message)");
  return dm_err_set(e, DM_EFAILED, "%s: gnuplot: %s%s%s%s%s%s",
                    what != NULL ? what : "command", text[0],
                    k[0] > 0 && k[1] > 0 ? "; " : "", text[1],
                    at[0] != '\0' ? " (at: " : "", at, at[0] != '\0' ? ")" : "");
}

int dm_gp_checkpoint(dm_gp_session *s, const char *what, dm_err *e)
{
  int rc, gp_errno = 0;
  if (s->pid <= 0) {
    gp_output_discard(s);
    return dm_err_set(e, DM_EIO, "%s: gnuplot is not running",
                      what != NULL ? what : "command");
  }
  rc = gp_output_close(s, e);
  if (rc == DM_OK)
    rc = gp_roundtrip(s, what, &gp_errno, e);
  if (rc != DM_OK) {
    gp_output_discard(s);
    return rc;
  }
  s->dirty = 0;
  if (gp_errno != 0) {
    gp_output_discard(s);
    return complaint(s, what, e);
  }
  return gp_output_commit(s, e);
}

/* }==== */

/* {==== starting and transactions ============================================ */

/* Version and terminals, on lines of their own (a warning such as iconv's
 * under LC_ALL=C may come first). */
static int probe(dm_gp_session *s, dm_err *e)
{
  static const char cmds[] = "set print\nset encoding utf8\n"
    "print 'DMECH_VERSION ', GPVAL_VERSION\n"
    "print 'DMECH_TERMINALS ', GPVAL_TERMINALS\n";
  const char *v, *t;
  char *end;
  int rc, gp_errno = 0;
  rc = gp_append(s, cmds, sizeof cmds - 1, e);
  if (rc == DM_OK)
    rc = gp_roundtrip(s, "start-up", &gp_errno, e);
  if (rc != DM_OK)
    return rc;
  v = strstr(s->msgs.p, "DMECH_VERSION ");
  t = strstr(s->msgs.p, "DMECH_TERMINALS ");
  s->version = v != NULL ? dm_num_parse(v + 14, &end) : 0;
  if (gp_errno != 0 || v == NULL || t == NULL) {
    const char *prog = gp_program(s);
    gp_kill(s);
    return dm_err_set(e, DM_EUNSUP, "program '%s' does not behave like gnuplot "
                      "5: %.200s", prog, s->msgs.p);
  }
  if (s->version < 5.0) {
    double ver = s->version;
    gp_kill(s);
    return dm_err_set(e, DM_EUNSUP, "gnuplot %g is too old (5.0 or later "
                      "needed)", ver);
  }
  t += 15;                                 /* keep the leading space */
  snprintf(s->terminals, sizeof s->terminals, "%.*s", (int)strcspn(t, "\n"), t);
  end = s->terminals + strlen(s->terminals);
  while (end > s->terminals && end[-1] == ' ')
    *--end = '\0';
  return DM_OK;
}

/* Give gnuplot a screen terminal right away so raw `plot` commands show. */
static void initial_terminal(dm_gp_session *s)
{
  dm_gp_termreq req;
  dm_gp_termenv env;
  char cmd[256];
  int gp_errno;
  memset(&req, 0, sizeof req);
  dm_gp_termenv_get(&env);
  if (dm_gp_terminal_command(s, &req, &env, cmd, sizeof cmd, NULL) != DM_OK)
    return;
  if (dm_gp_send(s, NULL, "%s\n", cmd) == DM_OK
      && gp_roundtrip(s, "initial terminal", &gp_errno, NULL) == DM_OK
      && gp_errno == 0)
    s->to_stdout = strncmp(cmd, "set terminal dumb", 17) == 0
                   || strncmp(cmd, "set terminal sixel", 18) == 0;
}

int dm_gp_start(dm_gp_session *s, dm_err *e)
{
  int rc;
  if (gp_alive(s))
    return DM_OK;
  rc = gp_spawn(s, e);
  if (rc != DM_OK)
    return rc;
  gp_log(s, "# dmech: gnuplot started (pid %ld, program %s)\n", (long)s->pid,
         gp_program(s));
  s->starting = 1;
  rc = probe(s, e);
  s->starting = 0;
  if (rc != DM_OK) {
    gp_kill(s);
    return rc;
  }
  initial_terminal(s);
  return s->pid > 0 ? DM_OK
                    : dm_err_set(e, DM_EIO, "gnuplot exited during start-up");
}

int dm_gp_begin(dm_gp_session *s, dm_err *e)
{
  int rc;
  if (s->dirty && gp_alive(s)) {
    int gp_errno;
    dm_err ignored;
    /* an abandoned transaction: close its output, find the marker again */
    if (gp_output_close(s, &ignored) != DM_OK
        || gp_roundtrip(s, "resynchronise", &gp_errno, &ignored) != DM_OK)
      gp_kill(s);
    gp_output_discard(s);
  }
  s->dirty = 0;
  rc = dm_gp_start(s, e);
  if (rc != DM_OK)
    return rc;
  gp_buf_clear(&s->obuf);
  gp_buf_clear(&s->msgs);
  s->dirty = 1;
  return DM_OK;
}

int dm_gp_command(dm_gp_session *s, const char *cmd, const char *what,
                  dm_err *e)
{
  char name[80];
  size_t len = strlen(cmd);
  int rc;
  if (what == NULL) {
    size_t i;
    snprintf(name, sizeof name, "'%.60s%s'", cmd, len > 60 ? "..." : "");
    for (i = 0; name[i] != '\0'; i++)
      if (name[i] == '\n' || name[i] == '\r')
        name[i] = ' ';
    what = name;
  }
  rc = dm_gp_begin(s, e);
  if (rc == DM_OK)
    rc = gp_append(s, cmd, len, e);
  /* blank lines are no-ops, but they leave the interactive `help` (which
   * reads "Subtopic of ...:" answers from stdin) instead of letting it eat
   * the checkpoint */
  if (rc == DM_OK)
    rc = gp_append(s, "\n\n\n\n\n", 5, e);
  if (rc == DM_OK)
    rc = dm_gp_checkpoint(s, what, e);
  return rc;
}

const char *dm_gp_messages(const dm_gp_session *s, size_t *len)
{
  if (len != NULL)
    *len = s->msgs.len;
  return s->msgs.p != NULL ? s->msgs.p : "";
}

const char *dm_gp_output(const dm_gp_session *s, size_t *len)
{
  if (len != NULL)
    *len = s->obuf.len;
  return s->obuf.p != NULL ? s->obuf.p : "";
}

/* }==== */
