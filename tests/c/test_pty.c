/* test_pty.c -- drive the interactive dmech through a pseudo-terminal:
 * tab completion (dm.v<TAB>, v:<TAB>), Ctrl-C at the prompt, Ctrl-C inside
 * `while true do end` keeping variables, a second Ctrl-C quitting, and
 * history (one entry per multi-line chunk) persisted across two sessions;
 * completion of fields, of names and files inside strings and of option
 * keys, help wrapped to the terminal's width, a bracketed paste run
 * statement by statement, the bare words help and quit; the warning of a
 * run that ended early; a script stopped by Ctrl-C exits with 130. */
#include <config.h>

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "tap.h"

#define BUFSZ 65536

typedef struct session {
  pid_t pid;
  int fd;
  char buf[BUFSZ];
  size_t len;
} session;

static const char *dmech, *tmp;

static const char *script_arg = NULL;    /* start_term: run this script, not the prompt */

/* dmech on a new pty of `cols` columns with TERM=term. */
static int start_term(session *s, const char *statedir, const char *term, unsigned short cols)
{
  struct winsize ws = {24, 100, 0, 0};
  ws.ws_col = cols;
  s->len = 0;
  s->buf[0] = '\0';
  s->pid = forkpty(&s->fd, NULL, NULL, &ws);
  if (s->pid < 0)
    return -1;
  if (s->pid == 0) {
    setenv("TERM", term, 1);
    setenv("INPUTRC", "/dev/null", 1);
    setenv("HOME", tmp, 1);
    setenv("XDG_STATE_HOME", statedir, 1);
    unsetenv("COLUMNS");
    if (chdir(tmp) != 0)
      _exit(126);
    if (script_arg != NULL)
      execl(dmech, dmech, script_arg, (char *)NULL);
    else
      execl(dmech, dmech, (char *)NULL);
    _exit(127);
  }
  return 0;
}

static int start(session *s, const char *statedir)
{
  return start_term(s, statedir, "dumb", 100);
}

/* The longest line (in bytes, escapes excluded) of buf[from, to). */
static size_t longest_line(const char *buf, size_t from, size_t to)
{
  size_t best = 0, cur = 0, i;
  for (i = from; i < to; i++) {
    unsigned char c = (unsigned char)buf[i];
    if (c == '\n' || c == '\r') {
      cur = 0;
    } else if (c == 0x1b) {                   /* skip an escape sequence */
      while (i + 1 < to && !((buf[i + 1] >= 'A' && buf[i + 1] <= 'Z') || (buf[i + 1] >= 'a' && buf[i + 1] <= 'z')))
        i++;
      i++;
    } else if ((c & 0xc0) != 0x80) {          /* count characters, not bytes */
      if (++cur > best)
        best = cur;
    }
  }
  return best;
}

/* Read until `want` appears after position `from` (or timeout); 1 if seen. */
static int expect_from(session *s, size_t from, const char *want, double timeout)
{
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  for (;;) {
    struct pollfd p = {s->fd, POLLIN, 0};
    double el;
    if (s->len > from && strstr(s->buf + from, want) != NULL)
      return 1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    el = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (el > timeout)
      return 0;
    if (poll(&p, 1, 50) > 0) {
      ssize_t r = read(s->fd, s->buf + s->len, BUFSZ - 1 - s->len);
      if (r <= 0)
        return strstr(s->buf + from, want) != NULL;
      s->len += (size_t)r;
      s->buf[s->len] = '\0';
      /* NULs from the terminal would cut strstr short */
      for (size_t i = s->len - (size_t)r; i < s->len; i++)
        if (s->buf[i] == '\0')
          s->buf[i] = ' ';
    }
  }
}

static void send(session *s, const char *text)
{
  size_t n = strlen(text);
  if (write(s->fd, text, n) != (ssize_t)n)
    perror("write");
}

static int finish(session *s, int *status)
{
  int i;
  for (i = 0; i < 100; i++) {
    pid_t r = waitpid(s->pid, status, WNOHANG);
    if (r == s->pid) {
      close(s->fd);
      tap_diag("child %d ended: %s %d", (int)s->pid,
               WIFEXITED(*status) ? "exit status" : "signal",
               WIFEXITED(*status) ? WEXITSTATUS(*status) : WTERMSIG(*status));
      return 1;
    }
    expect_from(s, s->len, "\x01\x02never", 0.05);   /* drain */
    usleep(50000);
  }
  kill(s->pid, SIGKILL);
  waitpid(s->pid, status, 0);
  close(s->fd);
  return 0;
}

static void show_tail(const session *s)
{
  size_t from = s->len > 300 ? s->len - 300 : 0;
  const char *p;
  printf("#   terminal tail: ");
  for (p = s->buf + from; *p; p++)
    putchar(*p == '\n' ? '|' : (*p == '\r' ? ' ' : *p));
  printf("\n");
}

#define EXPECT(s, from, want, name)                                      \
  do {                                                                   \
    if (!tap_ok(expect_from(s, from, want, 10.0), "%s", name))           \
      show_tail(s);                                                      \
  } while (0)

int main(void)
{
  session s;
  char state[1024], hist[1100], line[4096];
  size_t mark;
  int status;
  FILE *f;

  dmech = getenv("DMECH");
  tmp = getenv("DMECH_TESTTMP");
  if (dmech == NULL || tmp == NULL) {
    printf("1..0 # SKIP DMECH and DMECH_TESTTMP must be set (run through make check)\n");
    return 0;
  }
  snprintf(state, sizeof state, "%s/pty-state", tmp);
  snprintf(hist, sizeof hist, "%s/dmech/history", state);
  unlink(hist);

  /* ---- session 1 ---- */
  if (start(&s, state) != 0) {
    printf("1..0 # SKIP forkpty failed: %s\n", strerror(errno));
    return 0;
  }
  EXPECT(&s, 0, "dm> ", "prompt appears");

  mark = s.len;
  send(&s, "dm.v\t");
  EXPECT(&s, mark, "dm.vec", "dm.v<TAB> completes to dm.vec");
  mark = s.len;
  send(&s, "\x03");                           /* Ctrl-C clears the line */
  EXPECT(&s, mark, "dm> ", "Ctrl-C at the prompt gives a fresh prompt");
  mark = s.len;
  send(&s, "6 * 7\r");
  EXPECT(&s, mark, "42", "the cleared line is gone (6 * 7 -> 42)");
  tap_ok(strstr(s.buf + mark, "dm.vec6") == NULL && strstr(s.buf + mark, "error") == NULL,
         "no leftover text from the cleared line");

  mark = s.len;
  send(&s, "v = dm.vec{3, 4}\r");
  EXPECT(&s, mark, "dm> ", "assignment accepted");
  mark = s.len;
  send(&s, "v\r");
  EXPECT(&s, mark, "\nvec{3, 4}", "the value prints itself");
  mark = s.len;
  send(&s, "v:no\t");
  EXPECT(&s, mark, "v:norm", "v:no<TAB> completes a method of a userdata");
  send(&s, "()\r");
  EXPECT(&s, mark, "5.0", "completed method runs");
  mark = s.len;
  send(&s, "v:\t\t");
  EXPECT(&s, mark, "v:totable", "v:<TAB><TAB> lists the methods");
  mark = (size_t)(strstr(s.buf + mark, "v:totable") - s.buf);
  EXPECT(&s, mark, "dm> v:", "the line is redrawn after the list");
  mark = s.len;
  send(&s, "\x03");
  EXPECT(&s, mark, "dm> ", "Ctrl-C after a completion list clears the line");
  mark = s.len;
  send(&s, "string.for\t");
  EXPECT(&s, mark, "string.format", "completion through nested tables");
  tap_ok(strstr(s.buf + mark, "v:string") == NULL, "nothing left of the cleared line");
  mark = s.len;
  send(&s, "\x03");
  EXPECT(&s, mark, "dm> ", "Ctrl-C again");

  mark = s.len;
  /* Ctrl-C only once the loop runs: one sent while the line is still
   * unread would discard it (the terminal flushes its input on SIGINT) */
  send(&s, "x = 2.385; print('loop' .. 'ing'); while true do end\r");
  EXPECT(&s, mark, "looping", "the loop started");
  send(&s, "\x03");
  EXPECT(&s, mark, "interrupted!", "Ctrl-C stops a running loop");
  mark = s.len;
  send(&s, "x * 2\r");
  EXPECT(&s, mark, "4.77", "variables intact after the interrupt");

  mark = s.len;
  send(&s, "for i = 1, 2 do\r");
  send(&s, "io.write('k', i, ' ')\r");
  send(&s, "end\r");
  EXPECT(&s, mark, "k1 k2", "multi-line chunk runs");
  mark = s.len;
  send(&s, "print('again' .. 6 * 7)\r");
  EXPECT(&s, mark, "again42", "last entry runs");
  mark = (size_t)(strstr(s.buf + mark, "again42") - s.buf);
  EXPECT(&s, mark, "dm> ", "prompt back");   /* ^D only counts at a prompt */
  send(&s, "\x04");                            /* Ctrl-D: end of input */
  tap_ok(finish(&s, &status) && WIFEXITED(status) && WEXITSTATUS(status) == 0,
         "Ctrl-D leaves with status 0");

  /* the history file: one entry per chunk */
  f = fopen(hist, "r");
  tap_ok(f != NULL, "history file written at %s", hist);
  if (f != NULL) {
    int entries = 0, saw_multi = 0;
    struct stat st;
    char prev[4096] = "";
    while (fgets(line, sizeof line, f) != NULL) {
      if (line[0] == '#' && line[1] >= '0' && line[1] <= '9')
        entries++;
      if (strstr(prev, "for i = 1, 2 do") && strstr(line, "io.write"))
        saw_multi = 1;
      snprintf(prev, sizeof prev, "%s", line);
    }
    fclose(f);
    tap_ok(saw_multi, "multi-line chunk stored as consecutive lines of one entry");
    tap_ok(entries >= 6, "timestamps delimit %d entries", entries);
    tap_ok(stat(hist, &st) == 0 && (st.st_mode & 077) == 0, "history file is private (0600)");
  } else {
    tap_ok(0, "multi-line chunk stored");
    tap_ok(0, "entries");
    tap_ok(0, "history file private");
  }

  /* ---- session 2: history comes back ---- */
  if (start(&s, state) != 0)
    return tap_done();
  EXPECT(&s, 0, "dm> ", "second session prompt");
  mark = s.len;
  send(&s, "\x10\r");                          /* Ctrl-P: previous entry */
  EXPECT(&s, mark, "again42", "previous session's last entry recalled");
  mark = s.len;
  send(&s, "\x10\x10\x10\r");                   /* back over the multi-line chunk */
  EXPECT(&s, mark, "k1 k2", "a multi-line chunk is recalled as one entry");
  send(&s, "\x04");
  finish(&s, &status);

  /* ---- completion of fields, strings and options; help; paste ---- */
  if (start_term(&s, state, "dumb", 60) != 0)
    return tap_done();
  EXPECT(&s, 0, "dm> ", "fourth session prompt (60 columns)");
  {
    char cmd[2048];
    FILE *tf;
    mark = s.len;
    send(&s, "sys = dm.systems.kepler(); I = dm.integrator(sys, {h = 0.05})\r");
    EXPECT(&s, mark, "dm> ", "a system and an integrator");
    mark = s.len;
    send(&s, "sys.coo\t");
    EXPECT(&s, mark, "sys.coords", "sys.coo<TAB> completes a data field");
    send(&s, "\r");
    EXPECT(&s, mark, "{\"x\", \"y\"}", "the completed field runs");
    mark = s.len;
    send(&s, "I.fam\t");
    EXPECT(&s, mark, "I.family", "I.fam<TAB> completes an integrator field");
    mark = s.len;
    send(&s, "\x03");
    EXPECT(&s, mark, "dm> ", "Ctrl-C clears the completed line");
    mark = s.len;
    send(&s, "tr = I:run({q = {0.4, 0}, p = {0, 2}}, {steps = 20, ev\t");
    EXPECT(&s, mark, "ev" "ery = ", "an option key of integ:run completes with ' = '");
    send(&s, "2})\r");
    EXPECT(&s, mark, "dm> ", "the run with the completed option");
    mark = s.len;
    send(&s, "tr:column(\"ene\t");
    EXPECT(&s, mark, "\"energy\"", "a column name inside a string, the string closed");
    send(&s, "):max() > -1e300\r");
    EXPECT(&s, mark, "true", "the completed column reads");
    mark = s.len;
    send(&s, "dm.plot{ {tr, \"x\", \"p_\t\t");
    EXPECT(&s, mark, "p_y", "column names of a plot series listed");
    /* the line is drawn again after the list: wait for it, or its prompt
     * passes for the one Ctrl-C brings and the next line is typed into
     * this one before the Ctrl-C has cleared it */
    if (strstr(s.buf + mark, "p_y") != NULL)
      mark = (size_t)(strstr(s.buf + mark, "p_y") - s.buf);
    EXPECT(&s, mark, "dm> dm.plot{ {tr, \"x\", \"p_", "the plot line after the list");
    mark = s.len;
    send(&s, "\x03");
    EXPECT(&s, mark, "dm> ", "Ctrl-C clears the plot line");
    mark = s.len;
    send(&s, "dm.integrator(sys, {met\t");
    EXPECT(&s, mark, "method = ", "an option key inside the options table of dm.integrator");
    mark = s.len;
    send(&s, "\x03");
    EXPECT(&s, mark, "dm> ", "Ctrl-C clears the option line");
    mark = s.len;
    send(&s, "dm.\t\t");
    EXPECT(&s, mark, "dm.vec", "dm.<TAB><TAB> lists dm");
    mark = (size_t)(strstr(s.buf + mark, "dm.vec") - s.buf);
    EXPECT(&s, mark, "dm> dm.", "the line after the list");
    tap_ok(strstr(s.buf + mark - 2000 > s.buf ? s.buf + mark - 2000 : s.buf, "dm._gp") == NULL,
           "internal names (dm._gp) hidden");
    mark = s.len;
    send(&s, "\x03");
    EXPECT(&s, mark, "dm> ", "Ctrl-C clears the dm. line");
    snprintf(cmd, sizeof cmd, "%s/pty-completion-target.lua", tmp);
    tf = fopen(cmd, "w");
    if (tf != NULL) {
      fputs("return 6 * 7\n", tf);
      fclose(tf);
    }
    mark = s.len;
    send(&s, "dofile(\"pty-completion-ta\t");   /* the session runs in tmp */
    EXPECT(&s, mark, "pty-completion-target.lua\"", "a file name inside a string");
    send(&s, ")\r");
    EXPECT(&s, mark, "42", "the completed file runs");

    mark = s.len;
    send(&s, "help \"dm.integrator\"\r");
    EXPECT(&s, mark, "Options: method", "help shows the options");
    EXPECT(&s, (size_t)(strstr(s.buf + mark, "Options: method") - s.buf), "dm> ", "prompt after help");
    tap_ok(longest_line(s.buf, mark, s.len) <= 60, "help wrapped to the 60-column terminal (longest %d)",
           (int)longest_line(s.buf, mark, s.len));
    mark = s.len;
    send(&s, "help\r");
    EXPECT(&s, mark, " entries", "bare help at the prompt");
    send(&s, "\x04");
    finish(&s, &status);
  }
  /* bracketed paste needs a terminal that has it */
  if (start_term(&s, state, "xterm", 80) != 0)
    return tap_done();
  EXPECT(&s, 0, "dm> ", "fifth session prompt (xterm)");
  {
    mark = s.len;
    send(&s, "\x1b[200~local a = 2.5\nlocal b = 4\nprint(\"pasted\")\na * b\n\x1b[201~");
    EXPECT(&s, mark, "pasted", "a bracketed paste runs at once, statement by statement");
    EXPECT(&s, mark, "10.0", "and shows the value of its last expression");
    mark = s.len;
    send(&s, "b + 0.385\r");
    EXPECT(&s, mark, "4.385", "the paste's locals stay defined");
    mark = s.len;
    send(&s, "c = 1; c + 1\r");
    EXPECT(&s, mark, "\r2\r\n", "a = 1; a + 1 prints 2");
    send(&s, "quit\r");
    tap_ok(finish(&s, &status) && WIFEXITED(status) && WEXITSTATUS(status) == 0,
           "bare quit leaves with status 0");
  }

  /* ---- a run that ends early warns on the terminal; Ctrl-C stops a script ---- */
  if (start(&s, state) != 0)
    return tap_done();
  EXPECT(&s, 0, "dm> ", "sixth session prompt");
  mark = s.len;
  send(&s, "tr = dm.integrator(dm.systems.kepler(), {h = 0.05}):run({q = {0.4, 0}, p = {0, 2}}, "
           "{steps = 100, max_energy_error = 1e-14})\r");
  EXPECT(&s, mark, "warning: run ended early (diverged): the energy error",
         "a run that ends early warns on stderr");
  mark = s.len;
  send(&s, "tr.status\r");
  EXPECT(&s, mark, "\"diverged\"", "tr.status at the prompt");
  send(&s, "\x04");
  finish(&s, &status);
  {
    char path[1100];
    FILE *sf;
    snprintf(path, sizeof path, "%s/pty-interrupted.lua", tmp);
    sf = fopen(path, "w");
    if (sf != NULL) {
      fputs("local I = dm.integrator(dm.systems.kepler{impl = \"c\"}, {method = \"trapezoid\", h = 0.001})\n"
            "print(\"running\")\n"
            "local tr = I:run({q = {0.4, 0}, p = {0, 2}}, {steps = 4000000000, every = 1000000})\n"
            "print(\"after the run\")\n", sf);
      fclose(sf);
    }
    script_arg = path;
    if (start(&s, state) != 0)
      return tap_done();
    script_arg = NULL;
    EXPECT(&s, 0, "running", "a script runs on the terminal");
    usleep(300000);
    mark = s.len;
    send(&s, "\x03");
    EXPECT(&s, mark, "interrupted (Ctrl-C): the script stops here", "Ctrl-C stops the script");
    tap_ok(finish(&s, &status) && WIFEXITED(status) && WEXITSTATUS(status) == 130,
           "an interrupted script exits with status 130");
    tap_ok(strstr(s.buf, "after the run") == NULL, "nothing after the run ran");
  }

  /* ---- a second Ctrl-C during the same run quits ---- */
  if (start(&s, state) != 0)
    return tap_done();
  EXPECT(&s, 0, "dm> ", "third session prompt");
  mark = s.len;
  /* "spinning" comes from inside the pcall: a Ctrl-C that lands before it
   * would stop the whole line */
  send(&s, "while true do local ok, e = pcall(function() io.write('spin' .. 'ning\\n') io.flush() "
           "while true do end end); io.write('ca' .. 'ught: ', tostring(e), '\\n') end\r");
  EXPECT(&s, mark, "spinning", "the loop started");
  mark = s.len;
  send(&s, "\x03");
  /* the second Ctrl-C only after dmech has handled the first: two SIGINTs
   * pending at once are one signal */
  EXPECT(&s, mark, "caught: ", "the first Ctrl-C stopped the inner loop only");
  EXPECT(&s, mark, "interrupted!", "... with the interrupt's message");
  send(&s, "\x03");
  tap_ok(finish(&s, &status) && WIFSIGNALED(status) && WTERMSIG(status) == SIGINT,
         "a second Ctrl-C during the same run quits");
  return tap_done();
}
