/* test_gnuplot.c -- the gnuplot session: quoting, round trips, files,
 * errors, dead and hung gnuplot, big data, terminal choice.
 *
 * Needs gnuplot 5 on PATH (or $DMECH_GNUPLOT); every test that talks to it
 * is skipped (TAP "# SKIP") only when no gnuplot can be started at all.
 * Files go under $DMECH_TESTTMP (the harness sets it) or a fresh /tmp dir.
 */
#include <config.h>

#include <errno.h>
#include <fcntl.h>
#include <locale.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "core/status.h"
#include "plot/gnuplot.h"
#include "tap.h"

static char tmpdir[512];

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void path(char *out, size_t n, const char *name)
{
  snprintf(out, n, "%s/%s", tmpdir, name);
}

static int exists(const char *p)
{
  struct stat st;
  return stat(p, &st) == 0;
}

/* Count files in tmpdir whose name contains `part`. */
static int count_files(const char *part)
{
  char cmd[1200], line[64];
  FILE *f;
  int n = -1;
  snprintf(cmd, sizeof cmd, "ls -a '%s' | grep -c -- '%s'", tmpdir, part);
  if ((f = popen(cmd, "r")) != NULL) {
    if (fgets(line, sizeof line, f) != NULL)
      n = atoi(line);
    pclose(f);
  }
  return n;
}

/* Width and height from a PNG's IHDR, or -1 when it is not a PNG. */
static int png_size(const char *file, long *w, long *h)
{
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  unsigned char b[24];
  FILE *f = fopen(file, "rb");
  size_t n;
  if (f == NULL)
    return -1;
  n = fread(b, 1, sizeof b, f);
  fclose(f);
  if (n != sizeof b || memcmp(b, sig, 8) != 0 || memcmp(b + 12, "IHDR", 4) != 0)
    return -1;
  *w = ((long)b[16] << 24) | ((long)b[17] << 16) | ((long)b[18] << 8) | b[19];
  *h = ((long)b[20] << 24) | ((long)b[21] << 16) | ((long)b[22] << 8) | b[23];
  return 0;
}

/* {==== quoting (no gnuplot needed) ======================================= */

struct qcase {
  const char *in;
  size_t len;          /* 0: strlen */
  int flags;
  const char *quoted;  /* dm_gp_quote result */
  const char *printed; /* what gnuplot's print shows */
};

static const struct qcase qcases[] = {
  {"abc", 0, 0, "'abc'", "abc"},
  {"", 0, 0, "''", ""},
  {"it's", 0, 0, "'it'.\"\\047\".'s'", "it's"},
  {"''", 0, 0, "\"\\047\\047\"", "''"},
  {"'", 0, 0, "\"\\047\"", "'"},
  {"a'''b", 0, 0, "'a'.\"\\047\\047\\047\".'b'", "a'''b"},
  {"back\\slash\\", 0, 0, "'back'.\"\\134\".'slash'.\"\\134\"", "back\\slash\\"},
  {"two\nlines", 0, 0, "'two'.\"\\012\".'lines'", "two\nlines"},
  {"crlf\r\nend\r", 0, 0, "'crlf'.\"\\012\".'end'.\"\\012\"", "crlf\nend\n"},
  {"a;b @m `touch x` $x \"q\"", 0, 0,
   "'a;b '.\"\\100\".'m '.\"\\140\".'touch x'.\"\\140\".' $x '.\"\\042\".'q'.\"\\042\"",
   "a;b @m `touch x` $x \"q\""},
  {"system(\"touch y\")", 0, 0, "'system('.\"\\042\".'touch y'.\"\\042\".')'",
   "system(\"touch y\")"},
  {"x'y @m", 0, 0, "'x'.\"\\047\".'y '.\"\\100\".'m'", "x'y @m"},
  {"ctl\001\033x\177", 0, 0, "'ctl  x '", "ctl  x "},
  {"nul\0in", 6, 0, "'nul in'", "nul in"},
  {"tab\there", 0, 0, "'tab\there'", "tab\there"},
  {"one\nline", 0, DM_GP_QUOTE_ONELINE, "'one line'", "one line"},
  {"\xce\xb8 = 2.385", 0, 0, "'\xce\xb8 = 2.385'", "\xce\xb8 = 2.385"},
};
#define NQ (sizeof qcases / sizeof qcases[0])

static void test_quote_table(void)
{
  size_t i;
  char buf[256];
  for (i = 0; i < NQ; i++) {
    const struct qcase *c = &qcases[i];
    size_t len = c->len ? c->len : strlen(c->in);
    size_t n = dm_gp_quote(buf, sizeof buf, c->in, len, c->flags);
    tap_ok(n == strlen(c->quoted) && strcmp(buf, c->quoted) == 0,
           "quote case %zu -> %s (got %s)", i, c->quoted, buf);
  }
  /* truncation behaves like snprintf */
  {
    size_t n = dm_gp_quote(buf, 5, "abcdef", 6, 0);
    tap_ok(n == 8 && strcmp(buf, "'abc") == 0,
           "quote truncates like snprintf (needs 8, wrote '%s')", buf);
    n = dm_gp_quote(NULL, 0, "it's", 4, 0);
    tap_is_int((long)n, 15, "quote with size 0 only measures");
  }
  tap_ok(dm_gp_valid_name("dm_1") && dm_gp_valid_name("_x")
         && !dm_gp_valid_name("1a") && !dm_gp_valid_name("a b")
         && !dm_gp_valid_name("a;b") && !dm_gp_valid_name(""),
         "datablock names: identifiers only");
  tap_ok(dm_gp_valid_style("lines") && dm_gp_valid_style("linespoints pt 7 ps 0.5")
         && dm_gp_valid_style("lines lc rgb '#ff8800' lw 2.385")
         && dm_gp_valid_style("points lc rgb \"dark-red\""),
         "plain styles accepted");
  tap_ok(!dm_gp_valid_style("lines; system('touch x')")
         && !dm_gp_valid_style("lines lc rgb 'a;b'") && !dm_gp_valid_style("lines @m")
         && !dm_gp_valid_style("lines `x`") && !dm_gp_valid_style("lines\nplot")
         && !dm_gp_valid_style("lines lc rgb 'open") && !dm_gp_valid_style("")
         && !dm_gp_valid_style("l $dm1") && !dm_gp_valid_style("lines \\"),
         "styles that could inject refused");
}

/* }==== */

/* {==== terminal choice (no gnuplot needed) ================================ */

static void test_pick_terminal(void)
{
  const char *all = " dumb png pngcairo qt svg sixelgd wxt x11 pdfcairo";
  dm_gp_termenv env = {NULL, 0, 0, 0, 100, 40};
  char name[64];
  dm_err e;
  int rc;

  rc = dm_gp_pick_terminal(&env, "sixel", all, name, sizeof name, &e);
  tap_ok(rc == DM_OK && strcmp(name, "sixelgd") == 0, "sixel maps to sixelgd");
  rc = dm_gp_pick_terminal(&env, "sixel", " dumb png", name, sizeof name, &e);
  tap_ok(rc == DM_ENOTFOUND && strstr(e.msg, "sixelgd") != NULL,
         "sixel without sixelgd: %s", e.msg);
  rc = dm_gp_pick_terminal(&env, "png; system('touch x')", all, name,
                           sizeof name, &e);
  tap_ok(rc == DM_EINVAL, "terminal with ; and quotes refused: %s", e.msg);
  env.gnuterm = "wxt";
  env.has_display = env.has_x11 = 1;
  rc = dm_gp_pick_terminal(&env, NULL, all, name, sizeof name, &e);
  tap_ok(rc == DM_OK && strcmp(name, "wxt") == 0, "$GNUTERM beats the display");
  env.gnuterm = NULL;
  rc = dm_gp_pick_terminal(&env, NULL, all, name, sizeof name, &e);
  tap_ok(rc == DM_OK && strcmp(name, "qt") == 0, "display: qt first");
  env.has_x11 = 0;                          /* Wayland only: x11 unusable */
  env.tty = 1;
  rc = dm_gp_pick_terminal(&env, NULL, " dumb png x11", name, sizeof name, &e);
  tap_ok(rc == DM_OK && strcmp(name, "dumb") == 0,
         "Wayland without qt/wxt, on a tty: dumb (got %s)", name);
  env.has_display = 0;
  env.tty = 0;
  rc = dm_gp_pick_terminal(&env, NULL, all, name, sizeof name, &e);
  tap_ok(rc == DM_EUNSUP && strstr(e.msg, "output") != NULL,
         "no display, no tty: error asks for output= (%s)", e.msg);

  rc = dm_gp_terminal_for_file("dir/f.PNG", all, name, sizeof name, &e);
  tap_ok(rc == DM_OK && strcmp(name, "pngcairo") == 0, ".PNG -> pngcairo");
  rc = dm_gp_terminal_for_file("f.png", " dumb png", name, sizeof name, &e);
  tap_ok(rc == DM_OK && strcmp(name, "png") == 0, ".png without cairo -> png");
  rc = dm_gp_terminal_for_file("f.xyz", all, name, sizeof name, &e);
  tap_ok(rc == DM_EINVAL && strstr(e.msg, ".xyz") != NULL, "unknown extension: %s",
         e.msg);
  rc = dm_gp_terminal_for_file("a.d/noext", all, name, sizeof name, &e);
  tap_ok(rc == DM_EINVAL, "no extension refused");
}

static void test_terminal_command(dm_gp_session *s)
{
  dm_gp_termenv env = {NULL, 0, 0, 1, 100, 40};
  dm_gp_termreq req;
  char cmd[256];
  dm_err e;
  int rc;
  memset(&req, 0, sizeof req);
  req.file = "x.pdf";
  req.width = 720;
  req.height = 360;
  rc = dm_gp_terminal_command(s, &req, &env, cmd, sizeof cmd, &e);
  tap_ok(rc == DM_OK && strcmp(cmd, "set terminal pdfcairo size 10in,5in noenhanced") == 0,
         "pdf size in points: %s", cmd);
  req.file = NULL;
  req.width = req.height = 0;
  rc = dm_gp_terminal_command(s, &req, &env, cmd, sizeof cmd, &e);
  tap_ok(rc == DM_OK && strcmp(cmd, "set terminal dumb size 100,39 noenhanced") == 0,
         "tty: dumb sized to the terminal: %s", cmd);
  req.file = "x.svg";
  rc = dm_gp_terminal_command(s, &req, &env, cmd, sizeof cmd, &e);
  tap_ok(rc == DM_OK && strcmp(cmd, "set terminal svg size 640,480 noenhanced") == 0,
         "default size is explicit (gnuplot would reuse the last): %s", cmd);
  req.file = NULL;
  req.width = 3;
  rc = dm_gp_terminal_command(s, &req, &env, cmd, sizeof cmd, &e);
  tap_ok(rc == DM_EINVAL, "size with one zero refused: %s", e.msg);
}

/* }==== */

/* {==== talking to gnuplot ================================================== */

/* Run a raw command, return messages (static copy). */
static const char *ask(dm_gp_session *s, const char *cmd, int *rc, dm_err *e)
{
  static char out[4096];
  *rc = dm_gp_command(s, cmd, NULL, e);
  snprintf(out, sizeof out, "%s", dm_gp_messages(s, NULL));
  return out;
}

static void test_roundtrip_strings(dm_gp_session *s)
{
  size_t i;
  dm_err e;
  /* if any scanner expanded @m, the printed text would show EXPANDED */
  tap_ok(dm_gp_command(s, "m = 'EXPANDED'", NULL, &e) == DM_OK, "macro m defined");
  for (i = 0; i < NQ; i++) {
    const struct qcase *c = &qcases[i];
    size_t len = c->len ? c->len : strlen(c->in);
    char want[256];
    int rc = dm_gp_begin(s, &e);
    if (rc == DM_OK) rc = dm_gp_send(s, &e, "print ");
    if (rc == DM_OK) rc = dm_gp_sendq(s, c->in, len, c->flags, &e);
    if (rc == DM_OK) rc = dm_gp_send(s, &e, "\n");
    if (rc == DM_OK) rc = dm_gp_checkpoint(s, "print", &e);
    snprintf(want, sizeof want, "%s\n", c->printed);
    tap_ok(rc == DM_OK && strcmp(dm_gp_messages(s, NULL), want) == 0,
           "gnuplot prints case %zu literally", i);
    if (rc != DM_OK || strcmp(dm_gp_messages(s, NULL), want) != 0)
      tap_diag("rc %d (%s), got [%s]", rc, e.msg, dm_gp_messages(s, NULL));
  }
}

static void test_injection(dm_gp_session *s)
{
  static const char nasty[] =
    "T' ; system(\"touch %s\") ; print '\n`touch %s` @m \\' \" ; @m";
  char flag[600], title[1400], png[600];
  dm_err e;
  long w, h;
  int rc;
  path(flag, sizeof flag, "injected_c");
  path(png, sizeof png, "inject.png");
  unlink(flag);
  snprintf(title, sizeof title, nasty, flag, flag);
  rc = dm_gp_begin(s, &e);
  /* a macro that would run a command if @m were expanded */
  if (rc == DM_OK)
    rc = dm_gp_send(s, &e, "m = \"system('touch %s')\"\n", flag);
  if (rc == DM_OK) {
    dm_gp_termreq req = {"png", png, 320, 200, 0, 0};
    rc = dm_gp_set_terminal(s, &req, &e);
  }
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "set title ");
  if (rc == DM_OK) rc = dm_gp_sendq(s, title, strlen(title), 0, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "\nset xlabel ");
  if (rc == DM_OK) rc = dm_gp_sendq(s, title, strlen(title), 0, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "\nplot x title ");
  if (rc == DM_OK) rc = dm_gp_sendq(s, title, strlen(title), 0, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "inject", &e);
  tap_ok(rc == DM_OK, "plot with a nasty title/label/key succeeds (%s)",
         rc ? e.msg : "ok");
  tap_ok(png_size(png, &w, &h) == 0 && w == 320 && h == 200,
         "it wrote a 320x200 PNG");
  tap_ok(!exists(flag), "no command was injected (%s absent)", flag);
  rc = dm_gp_command(s, "print GPVAL_TERM", NULL, &e);
  tap_ok(rc == DM_OK && strncmp(dm_gp_messages(s, NULL), "dumb", 4) != 0
         && strncmp(dm_gp_messages(s, NULL), "png", 3) != 0,
         "terminal popped after the file (now %.*s)",
         (int)strcspn(dm_gp_messages(s, NULL), "\n"), dm_gp_messages(s, NULL));
}

static void test_png(dm_gp_session *s)
{
  static const double x[] = {0.0, 1.0, 2.385, 3.5, 5.0};
  static const double y[] = {1.0, -0.5, 2.385, 0.25, -1.75};
  const double *cols[2] = {x, y};
  char png[600];
  dm_gp_termreq req = {NULL, NULL, 413, 227, 0, 0};
  dm_err e;
  long w = 0, h = 0;
  int rc;
  path(png, sizeof png, "curve.png");
  unlink(png);
  req.file = png;
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_datablock(s, "dm1", 5, 2, cols, NULL, &e);
  if (rc == DM_OK) rc = dm_gp_set_terminal(s, &req, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "plot $dm1 using 1:2 with linespoints\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "png", &e);
  tap_ok(rc == DM_OK, "PNG plot (%s)", rc ? e.msg : "ok");
  tap_ok(png_size(png, &w, &h) == 0, "PNG signature and IHDR");
  tap_ok(w == 413 && h == 227, "PNG is 413x227 as asked (got %ldx%ld)", w, h);
  tap_is_int(count_files(".tmp"), 0, "no temporary file left behind");
  path(png, sizeof png, "it's a \\ file;.png");
  unlink(png);
  req.file = png;
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_set_terminal(s, &req, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "plot $dm1 using 1:2 with lines\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "png", &e);
  tap_ok(rc == DM_OK && png_size(png, &w, &h) == 0 && w == 413,
         "file name with quote, backslash and ; (%s)", rc ? e.msg : "ok");
}

/* Numbers arrive exactly (%.17g) and whatever the locale says. */
static void test_numbers(dm_gp_session *s)
{
  static const char *const locales[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8",
                                        "ru_RU.UTF-8", NULL};
  const char *const *l;
  double v[4] = {2.385, 1.0 / 3.0, -7.0e-300, 12345678.901234567};
  const double *cols[1] = {v};
  char want[256];
  const char *used = NULL;
  dm_err e;
  int rc;
  for (l = locales; *l != NULL && used == NULL; l++)
    used = setlocale(LC_NUMERIC, *l) != NULL ? *l : NULL;
  tap_diag("numeric locale for this test: %s", used ? used : "C (no decimal-comma locale installed)");
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_datablock(s, "num", 4, 1, cols, NULL, &e);
  if (rc == DM_OK)
    rc = dm_gp_send(s, &e, "print $num[1].'|'.$num[2].'|'.$num[3].'|'.$num[4]\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "numbers", &e);
  setlocale(LC_NUMERIC, "C");
  snprintf(want, sizeof want, "%.17g|%.17g|%.17g|%.17g\n", v[0], v[1], v[2], v[3]);
  tap_ok(rc == DM_OK && strcmp(dm_gp_messages(s, NULL), want) == 0,
         "datablock rows are %%.17g with '.' (got %.*s)",
         (int)strcspn(dm_gp_messages(s, NULL), "\n"), dm_gp_messages(s, NULL));
  {
    double nan_inf[3] = {2.385, 0.0 / 0.0, 1.0 / 0.0};
    const double *c2[1] = {nan_inf};
    rc = dm_gp_begin(s, &e);
    if (rc == DM_OK) rc = dm_gp_datablock(s, "ni", 3, 1, c2, NULL, &e);
    if (rc == DM_OK) rc = dm_gp_send(s, &e, "print $ni[2].' '.$ni[3]\n");
    if (rc == DM_OK) rc = dm_gp_checkpoint(s, "nan", &e);
    tap_ok(rc == DM_OK && strcmp(dm_gp_messages(s, NULL), "NaN NaN\n") == 0,
           "non-finite values go as NaN");
  }
  {
    double m[6] = {1, 10, 2, 20, 3, 30};   /* row-major 3x2: strides */
    const double *c3[2] = {m, m + 1};
    size_t st[2] = {2, 2};
    rc = dm_gp_begin(s, &e);
    if (rc == DM_OK) rc = dm_gp_datablock(s, "st", 3, 2, c3, st, &e);
    if (rc == DM_OK) rc = dm_gp_send(s, &e, "print $st[3]\n");
    if (rc == DM_OK) rc = dm_gp_checkpoint(s, "strides", &e);
    tap_ok(rc == DM_OK && strcmp(dm_gp_messages(s, NULL), "3 30\n") == 0,
           "strided columns");
  }
  rc = dm_gp_datablock(s, "bad name", 1, 1, cols, NULL, &e);
  tap_ok(rc == DM_EINVAL, "bad datablock name refused");
}

static void test_errors(dm_gp_session *s)
{
  char txt[600];
  dm_gp_termreq req = {"dumb", NULL, 60, 15, 0, 0};
  dm_err e;
  int rc;
  const char *m;

  rc = dm_gp_command(s, "plot sin(x) with foo", "dm.plot", &e);
  tap_ok(rc == DM_EFAILED && strstr(e.msg, "unrecognized plot type") != NULL
         && strncmp(e.msg, "dm.plot: gnuplot: ", 18) == 0
         && strstr(e.msg, "with foo") != NULL,
         "bad `with` style -> error with gnuplot's text: %s", e.msg);
  m = ask(s, "print 2.385*2", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "4.77\n") == 0, "session fine afterwards");

  /* a bad range while writing a file: error, target untouched, no temp */
  path(txt, sizeof txt, "badrange.txt");
  unlink(txt);
  req.file = txt;
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_set_terminal(s, &req, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "set xrange [2.385:2.385]\nplot sin(x)\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "bad range", &e);
  tap_ok(rc == DM_EFAILED && strstr(e.msg, "x_min should not equal x_max") != NULL,
         "bad range -> error: %s", e.msg);
  tap_ok(!exists(txt) && count_files(".tmp") == 0,
         "failed plot leaves neither the file nor a temporary");

  /* raw command with an error among good ones */
  rc = dm_gp_command(s, "set xrange [1:2:3:]\nprint 'after'", NULL, &e);
  tap_ok(rc == DM_EFAILED && strstr(e.msg, "'set xrange [1:2:3:]") != NULL,
         "raw error names the command: %s", e.msg);
  /* a dangling continuation does not swallow the checkpoint */
  m = ask(s, "print 6*7 \\", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "42\n") == 0, "trailing backslash handled");
  /* the interactive help reads answers from stdin: it must not eat the
   * checkpoint */
  m = ask(s, "help set xrange", &rc, &e);
  tap_ok(rc == DM_OK && strstr(m, "xrange") != NULL,
         "help returns (%s)", rc ? e.msg : "ok");
  /* messages that are not errors */
  m = ask(s, "print 'note: fine'", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "note: fine\n") == 0, "print output is a message");
  /* the user's `set print` cannot hide our marker */
  m = ask(s, "set print '/dev/null'", &rc, &e);
  m = ask(s, "print 5", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "5\n") == 0, "set print cannot hide checkpoints");

  /* output to a directory that does not exist */
  path(txt, sizeof txt, "no/such/dir/x.png");
  req.terminal = NULL;
  req.file = txt;
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_set_terminal(s, &req, &e);
  tap_ok(rc == DM_EIO && strstr(e.msg, "no/such/dir") != NULL,
         "missing output directory: %s", e.msg);
  m = ask(s, "print 1", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "1\n") == 0, "abandoned transaction resynchronised");
}

static void test_dumb_stdout(dm_gp_session *s)
{
  dm_gp_termreq req = {"dumb", NULL, 50, 12, 0, 0};
  const char *out, *p;
  dm_err e;
  int rc, lines = 0;
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_set_terminal(s, &req, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "plot [0:3] x*x notitle\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "dumb", &e);
  out = dm_gp_output(s, NULL);
  for (p = out; *p; p++)
    lines += *p == '\n';
  tap_ok(rc == DM_OK && strstr(out, "+---") != NULL && lines >= 12,
         "dumb plot collected from stdout (%d lines)", lines);
}

static void test_big_output(dm_gp_session *s)
{
  dm_err e;
  size_t len = 0;
  int rc = dm_gp_command(s, "do for [i=1:40000] { print i }", NULL, &e);
  dm_gp_messages(s, &len);
  tap_ok(rc == DM_OK && len > 200000, "200 kB on stderr drained (%zu bytes)", len);
}

static void test_big_data(dm_gp_session *s, size_t n)
{
  double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
  const double *cols[2] = {x, y};
  char png[600];
  dm_gp_termreq req = {NULL, NULL, 300, 200, 0, 0};
  dm_err e;
  double t0 = now();
  long w, h;
  size_t i;
  int rc;
  for (i = 0; i < n; i++) {
    x[i] = 2.385 * (double)i / (double)n;
    y[i] = x[i] * x[i];
  }
  path(png, sizeof png, "big.png");
  req.file = png;
  rc = dm_gp_begin(s, &e);
  if (rc == DM_OK) rc = dm_gp_datablock(s, "big", n, 2, cols, NULL, &e);
  if (rc == DM_OK) rc = dm_gp_set_terminal(s, &req, &e);
  if (rc == DM_OK) rc = dm_gp_send(s, &e, "stats $big using 2 nooutput\n"
                                   "print STATS_records\nplot $big with lines\n");
  if (rc == DM_OK) rc = dm_gp_checkpoint(s, "big", &e);
  tap_ok(rc == DM_OK && atol(dm_gp_messages(s, NULL)) == (long)n,
         "%zu points streamed, gnuplot counted %ld (%.2f s)", n,
         atol(dm_gp_messages(s, NULL)), now() - t0);
  tap_ok(png_size(png, &w, &h) == 0 && w == 300, "big PNG written");
  {
    char cmd[700], line[64];
    FILE *f;
    int left = -1;
    snprintf(cmd, sizeof cmd, "ls %s/dmech-gnuplot-*/ 2>/dev/null | grep -c dat",
             tmpdir);
    if ((f = popen(cmd, "r")) != NULL) {
      if (fgets(line, sizeof line, f) != NULL)
        left = atoi(line);
      pclose(f);
    }
    tap_is_int(left, 0, "large-datablock file removed after the checkpoint");
  }
  free(x);
  free(y);
}

static void test_interrupt(dm_gp_session *s)
{
  size_t n = 100000, i;
  double *x = malloc(n * sizeof *x);
  const double *cols[1] = {x};
  const char *m;
  dm_err e;
  int rc;
  for (i = 0; i < n; i++)
    x[i] = (double)i;
  rc = dm_gp_begin(s, &e);
  dm_interrupt_raise();
  if (rc == DM_OK) rc = dm_gp_datablock(s, "intr", n, 1, cols, NULL, &e);
  dm_interrupt_clear();
  tap_ok(rc == DM_EINTR && strstr(e.msg, "4095 of 100000") != NULL,
         "interrupt stops a datablock: %s", e.msg);
  m = ask(s, "print |$intr|", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "4095\n") == 0,
         "session continues, partial block closed (%.*s rows)",
         (int)strcspn(m, "\n"), m);
  free(x);
}

static void wait_dead(pid_t pid)
{
  siginfo_t si;
  while (waitid(P_PID, (id_t)pid, &si, WEXITED | WNOWAIT) < 0 && errno == EINTR)
    ;
}

static void test_kill(dm_gp_session *s)
{
  dm_err e;
  const char *m;
  pid_t pid = dm_gp_pid(s);
  unsigned long gen = dm_gp_generation(s);
  int rc;
  kill(pid, SIGKILL);
  wait_dead(pid);
  m = ask(s, "print 6*7", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "42\n") == 0, "killed gnuplot restarted (%s)",
         rc ? e.msg : "ok");
  tap_ok(dm_gp_generation(s) == gen + 1 && dm_gp_pid(s) != pid,
         "new process (generation %lu)", dm_gp_generation(s));

  /* killed in the middle of a transaction, then more than a pipe-full */
  rc = dm_gp_begin(s, &e);
  pid = dm_gp_pid(s);
  kill(pid, SIGKILL);
  wait_dead(pid);
  {
    size_t n = 50000, i;
    double *x = malloc(n * sizeof *x);
    const double *cols[1] = {x};
    for (i = 0; i < n; i++)
      x[i] = 2.385 * (double)i;
    if (rc == DM_OK) rc = dm_gp_datablock(s, "late", n, 1, cols, NULL, &e);
    if (rc == DM_OK) rc = dm_gp_checkpoint(s, "late", &e);
    free(x);
  }
  tap_ok(rc == DM_EIO && strstr(e.msg, "exited unexpectedly") != NULL,
         "death mid-transaction reported, no SIGPIPE: %s", e.msg);
  m = ask(s, "print 2.385", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "2.385\n") == 0, "and the next command works");
}

static void test_hung(dm_gp_session *s)
{
  char script[600];
  FILE *f;
  dm_err e;
  double t0, dt;
  pid_t pid;
  int rc;
  const char *m;

  /* a real gnuplot that stops answering */
  dm_gp_set_timeout(s, 0.5);
  t0 = now();
  pid = dm_gp_pid(s);
  rc = dm_gp_command(s, "pause 30", NULL, &e);
  dt = now() - t0;
  tap_ok(rc == DM_ETIMEOUT && strstr(e.msg, "did not answer") != NULL,
         "busy gnuplot times out: %s", e.msg);
  tap_ok(dt < 5.0 && kill(pid, 0) != 0, "killed and reaped after %.2f s", dt);

  /* a stand-in that never answers at all */
  path(script, sizeof script, "hung-gnuplot.sh");
  f = fopen(script, "w");
  if (f != NULL) {
    fputs("#!/bin/sh\nexec sleep 100\n", f);
    fclose(f);
    chmod(script, 0755);
  }
  setenv("DMECH_GNUPLOT", script, 1);
  t0 = now();
  rc = dm_gp_command(s, "print 1", NULL, &e);
  dt = now() - t0;
  tap_ok(rc == DM_ETIMEOUT && dt < 5.0, "silent stand-in: timeout in %.2f s: %s",
         dt, e.msg);
  tap_is_int(dm_gp_pid(s), -1, "stand-in gone");
  unsetenv("DMECH_GNUPLOT");
  dm_gp_set_timeout(s, 30);
  m = ask(s, "print 2.385+1", &rc, &e);
  tap_ok(rc == DM_OK && strcmp(m, "3.385\n") == 0, "recovered with the real gnuplot");
}

static void test_missing(void)
{
  dm_gp_session *s;
  dm_err e;
  int rc;
  setenv("DMECH_GNUPLOT", "/nonexistent", 1);
  s = dm_gp_session_alloc();
  rc = dm_gp_command(s, "print 1", NULL, &e);
  tap_ok(rc == DM_ENOTFOUND && strstr(e.msg, "'/nonexistent' not found") != NULL
         && strstr(e.msg, "DMECH_GNUPLOT") != NULL,
         "DMECH_GNUPLOT=/nonexistent: %s", e.msg);
  unsetenv("DMECH_GNUPLOT");
  dm_gp_set_program(s, "dmech-no-such-gnuplot-here", &e);
  rc = dm_gp_command(s, "print 1", NULL, &e);
  tap_ok(rc == DM_ENOTFOUND, "program not on PATH: %s", e.msg);
  dm_gp_set_program(s, "/bin/true", &e);
  rc = dm_gp_command(s, "print 1", NULL, &e);
  tap_ok(rc == DM_EIO && strstr(e.msg, "exited") != NULL,
         "a program that exits at once: %s", e.msg);
  dm_gp_session_free(s);
}

static void test_log(void)
{
  char log[600], line[256];
  dm_gp_session *s;
  dm_err e;
  FILE *f;
  int title = 0, block = 0, ckpt = 0;
  double v[2] = {2.385, 4.5};
  const double *cols[1] = {v};
  path(log, sizeof log, "gnuplot.log");
  unlink(log);
  setenv("DMECH_GNUPLOT_LOG", log, 1);
  s = dm_gp_session_alloc();
  unsetenv("DMECH_GNUPLOT_LOG");
  if (dm_gp_begin(s, &e) == DM_OK) {
    dm_gp_send(s, &e, "set title ");
    dm_gp_sendq(s, "it's", 4, 0, &e);
    dm_gp_send(s, &e, "\n");
    dm_gp_datablock(s, "lg", 2, 1, cols, NULL, &e);
    dm_gp_checkpoint(s, "logged", &e);
  }
  dm_gp_session_free(s);
  f = fopen(log, "r");
  while (f != NULL && fgets(line, sizeof line, f) != NULL) {
    title += strcmp(line, "set title 'it'.\"\\047\".'s'\n") == 0;
    block += strcmp(line, "$lg << EOD\n") == 0 || strcmp(line, "2.3849999999999998\n") == 0;
    ckpt += strstr(line, "checkpoint (logged)") != NULL;
  }
  if (f != NULL)
    fclose(f);
  tap_ok(title == 1 && block == 2 && ckpt == 1,
         "DMECH_GNUPLOT_LOG records commands, data and checkpoints");
}

static void test_free_reaps(void)
{
  dm_gp_session *s = dm_gp_session_alloc();
  dm_err e;
  pid_t pid;
  dm_gp_start(s, &e);
  pid = dm_gp_pid(s);
  dm_gp_session_free(s);
  tap_ok(pid > 0 && kill(pid, 0) != 0 && errno == ESRCH,
         "session free reaps gnuplot (pid %ld)", (long)pid);
  dm_gp_session_free(NULL);
}

/* A descriptor open without close-on-exec (as HDF5 opens its files, with
 * a flock) is not passed on to gnuplot. */
static void test_no_inherited_fds(void)
{
  dm_gp_session *s = dm_gp_session_alloc();
  dm_err e;
  char link[64], target[256];
  int fd = open("/dev/null", O_RDONLY), rc;
  ssize_t n0 = -1, n = -1;
  int err = 0;
  rc = dm_gp_start(s, &e);
  if (rc == DM_OK) {
    snprintf(link, sizeof link, "/proc/%ld/fd/0", (long)dm_gp_pid(s));
    n0 = readlink(link, target, sizeof target - 1);     /* /proc works */
    snprintf(link, sizeof link, "/proc/%ld/fd/%d", (long)dm_gp_pid(s), fd);
    n = readlink(link, target, sizeof target - 1);
    err = errno;
  }
  tap_ok(rc == DM_OK && fd > 2 && n0 > 0 && n < 0 && err == ENOENT,
         "gnuplot gets stdio, not descriptor %d of ours", fd);
  dm_gp_session_free(s);
  close(fd);
}

/* }==== */

int main(void)
{
  dm_gp_session *s;
  dm_err e;
  const char *t = getenv("DMECH_TESTTMP");
  int rc;

  dm_gsl_init();
  if (t != NULL && *t != '\0') {
    snprintf(tmpdir, sizeof tmpdir, "%s/gnuplot-c", t);
    mkdir(t, 0777);
    mkdir(tmpdir, 0777);
  } else {
    snprintf(tmpdir, sizeof tmpdir, "/tmp/dmech-gp-XXXXXX");
    if (mkdtemp(tmpdir) == NULL)
      return 1;
  }
  unsetenv("DMECH_GNUPLOT_LOG");
  setenv("TMPDIR", tmpdir, 1);      /* the private data directories go here */
  test_quote_table();
  test_pick_terminal();

  s = dm_gp_session_alloc();
  rc = dm_gp_start(s, &e);
  if (rc != DM_OK) {
    /* only a truly missing gnuplot is a reason to skip */
    tap_ok(rc == DM_ENOTFOUND, "gnuplot missing (%s)", e.msg);
    printf("ok %d # SKIP gnuplot not available\n", ++tap_n);
    dm_gp_session_free(s);
    return tap_done();
  }
  tap_ok(dm_gp_version(s) >= 5.0 && dm_gp_has_terminal(s, "dumb"),
         "gnuplot %g with terminals%.60s...", dm_gp_version(s), dm_gp_terminals(s));
  test_terminal_command(s);
  test_roundtrip_strings(s);
  test_injection(s);
  test_png(s);
  test_numbers(s);
  test_errors(s);
  test_dumb_stdout(s);
  test_big_output(s);
  test_big_data(s, 200000);
  test_interrupt(s);
  test_kill(s);
  test_hung(s);
  dm_gp_session_free(s);
  test_missing();
  test_log();
  test_free_reaps();
  test_no_inherited_fds();
  return tap_done();
}
