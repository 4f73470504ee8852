/* terminal.c -- which gnuplot terminal, in what size, and file outputs.
 *
 * A file output goes to a temporary file (core/outfile.h in named mode:
 * O_EXCL, unpredictable name, beside the target); the checkpoint that ends
 * the transaction sends `unset output` and renames it onto the target only
 * when gnuplot reported no error, so a failed plot never clobbers an older
 * good file and a successful one is complete when the call returns.  A
 * symbolic link is followed; a FIFO or character device gets the finished
 * plot copied into it; a directory or block device is refused.
 */
#include <config.h>

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/numfmt.h"
#include "plot/gp_private.h"

/* {==== the choice ========================================================== */

static int in_list(const char *list, const char *word)
{
  size_t n = strlen(word);
  const char *p = list;
  if (n == 0 || list == NULL)
    return 0;
  while ((p = strstr(p, word)) != NULL) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
      return 1;
    p += n;
  }
  return 0;
}

int dm_gp_has_terminal(const dm_gp_session *s, const char *name)
{
  return in_list(s->terminals, name);
}

void dm_gp_termenv_get(dm_gp_termenv *env)
{
  const char *d = getenv("DISPLAY"), *w = getenv("WAYLAND_DISPLAY");
  struct winsize ws;
  memset(env, 0, sizeof *env);
  env->gnuterm = getenv("GNUTERM");
  if (env->gnuterm != NULL && env->gnuterm[0] == '\0')
    env->gnuterm = NULL;
  env->has_x11 = d != NULL && d[0] != '\0';
  env->has_display = env->has_x11 || (w != NULL && w[0] != '\0');
  env->tty = isatty(STDOUT_FILENO);
  env->cols = 80;
  env->rows = 25;
  if (env->tty && ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0
      && ws.ws_row > 0) {
    env->cols = ws.ws_col;
    env->rows = ws.ws_row;
  } else {
    const char *c = getenv("COLUMNS"), *l = getenv("LINES");
    if (c != NULL && atoi(c) > 0)
      env->cols = atoi(c);
    if (l != NULL && atoi(l) > 0)
      env->rows = atoi(l);
  }
}

/* A terminal request the user typed: "name [plain options]". */
static int check_user_terminal(const char *t, dm_err *e)
{
  const char *p;
  for (p = t; *p != '\0'; p++) {
    char c = *p;
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')
          || (c >= '0' && c <= '9') || c == '_' || c == ' ' || c == ','
          || c == '.' || c == '-'))
      return dm_err_set(e, DM_EINVAL, "terminal '%.60s': only plain words and "
                        "numbers are accepted (use dm.gnuplot for anything "
                        "else)", t);
  }
  if (t[0] == '\0' || t[0] == ' ')
    return dm_err_set(e, DM_EINVAL, "empty terminal name");
  return DM_OK;
}

/* Copy the first word of t into name, mapping the friendly aliases. */
static int terminal_name(const char *t, const char *available, char *name,
                         size_t size, dm_err *e)
{
  size_t n = strcspn(t, " ");
  char word[64];
  int rc = check_user_terminal(t, e);
  if (rc != DM_OK)
    return rc;
  snprintf(word, sizeof word, "%.*s", (int)(n < 63 ? n : 63), t);
  if (strcmp(word, "sixel") == 0)
    snprintf(word, sizeof word, "sixelgd");
  if (available != NULL && available[0] != '\0' && !in_list(available, word))
    return dm_err_set(e, DM_ENOTFOUND, "this gnuplot has no terminal '%s' "
                      "(it has:%s%.300s)", word,
                      available[0] == ' ' ? "" : " ", available);
  if (strlen(word) + 1 > size)
    return dm_err_set(e, DM_EINVAL, "terminal name too long");
  strcpy(name, word);
  return DM_OK;
}

int dm_gp_pick_terminal(const dm_gp_termenv *env, const char *user,
                        const char *available, char *name, size_t size,
                        dm_err *e)
{
  static const char *const windows[] = {"qt", "wxt", "x11"};
  size_t i;
  if (user != NULL && user[0] != '\0')
    return terminal_name(user, available, name, size, e);
  if (env->gnuterm != NULL)
    return terminal_name(env->gnuterm, available, name, size, e);
  if (env->has_display)
    for (i = 0; i < sizeof windows / sizeof windows[0]; i++) {
      if (strcmp(windows[i], "x11") == 0 && !env->has_x11)
        continue;
      if (in_list(available, windows[i]) && strlen(windows[i]) < size) {
        strcpy(name, windows[i]);
        return DM_OK;
      }
    }
  if (env->tty && size > 4) {
    strcpy(name, "dumb");
    return DM_OK;
  }
  return dm_err_set(e, DM_EUNSUP, "nowhere to show the plot: no display "
                    "($DISPLAY/$WAYLAND_DISPLAY) with a window terminal and "
                    "standard output is not a terminal; give output = "
                    "\"file.png|svg|pdf\" (or terminal = \"dumb\")");
}

int dm_gp_terminal_for_file(const char *file, const char *available,
                            char *name, size_t size, dm_err *e)
{
  static const struct { const char *ext, *first, *second; } map[] = {
    {"png", "pngcairo", "png"},   {"svg", "svg", NULL},
    {"pdf", "pdfcairo", "pdf"},   {"eps", "epscairo", "postscript"},
    {"ps", "postscript", NULL},   {"gif", "gif", NULL},
    {"jpg", "jpeg", NULL},        {"jpeg", "jpeg", NULL},
    {"txt", "dumb", NULL},        {"tex", "epslatex", NULL},
    {"sixel", "sixelgd", NULL},   {"html", "canvas", NULL},
  };
  const char *dot = strrchr(file, '.'), *slash = strrchr(file, '/');
  size_t i;
  if (dot == NULL || (slash != NULL && dot < slash) || dot[1] == '\0')
    return dm_err_set(e, DM_EINVAL, "cannot tell the format of '%.200s' from "
                      "its extension (.png .svg .pdf .eps .txt ...); give "
                      "terminal=", file);
  for (i = 0; i < sizeof map / sizeof map[0]; i++) {
    const char *t = NULL;
    if (strcasecmp(dot + 1, map[i].ext) != 0)
      continue;
    if (available == NULL || available[0] == '\0' || in_list(available, map[i].first))
      t = map[i].first;
    else if (map[i].second != NULL && in_list(available, map[i].second))
      t = map[i].second;
    if (t == NULL)
      return dm_err_set(e, DM_EUNSUP, "this gnuplot cannot write .%s files "
                        "(no terminal '%s')", map[i].ext, map[i].first);
    snprintf(name, size, "%s", t);
    return DM_OK;
  }
  return dm_err_set(e, DM_EINVAL, "unknown plot file extension '%.20s' in "
                    "'%.200s' (known: .png .svg .pdf .eps .ps .gif .jpg .txt "
                    ".tex .sixel .html); give terminal=", dot, file);
}

/* }==== */

/* {==== the `set terminal` line ============================================= */

static int is_one_of(const char *t, const char *const *list)
{
  for (; *list != NULL; list++)
    if (strcmp(t, *list) == 0)
      return 1;
  return 0;
}

int dm_gp_terminal_command(const dm_gp_session *s, const dm_gp_termreq *req,
                           const dm_gp_termenv *env, char *out, size_t size,
                           dm_err *e)
{
  static const char *const windows[] = {"qt", "wxt", "x11", NULL};
  static const char *const paper[] = {"pdfcairo", "epscairo", "postscript",
                                      "pdf", "epslatex", NULL};
  static const char *const pixels[] = {"pngcairo", "png", "svg", "gif", "jpeg",
                                       "sixelgd", "canvas", "qt", "wxt", "x11",
                                       NULL};
  static const char *const textmode[] = {
    "pngcairo", "png", "svg", "gif", "jpeg", "sixelgd", "qt", "wxt", "x11",
    "pdfcairo", "epscairo", "postscript", "dumb", "canvas", NULL};
  const char *avail = s != NULL ? s->terminals : "", *opts = "";
  char name[64];
  double w = req->width, h = req->height;
  size_t k;
  int rc;
  if (req->file != NULL && (req->terminal == NULL || req->terminal[0] == '\0'))
    rc = dm_gp_terminal_for_file(req->file, avail, name, sizeof name, e);
  else if (req->file != NULL)
    rc = terminal_name(req->terminal, avail, name, sizeof name, e);
  else
    rc = dm_gp_pick_terminal(env, req->terminal, avail, name, sizeof name, e);
  if (rc != DM_OK)
    return rc;
  if (req->terminal != NULL && req->terminal[0] != '\0')
    opts = req->terminal + strcspn(req->terminal, " ");
  else if (req->file == NULL && env->gnuterm != NULL)
    opts = env->gnuterm + strcspn(env->gnuterm, " ");
  if ((w < 0 || h < 0) || (w > 0) != (h > 0) || w > 1e5 || h > 1e5)
    return dm_err_set(e, DM_EINVAL, "size must be two positive numbers, got "
                      "%g,%g", w, h);
  k = (size_t)snprintf(out, size, "set terminal %s", name);
  if (is_one_of(name, windows) && k < size)
    k += (size_t)snprintf(out + k, size - k, " %d", req->window);
  /* gnuplot remembers a terminal's last size: always say which one */
  if (w == 0 && strcmp(name, "dumb") == 0) {
    int screen = req->file == NULL && env->tty;
    w = screen ? (env->cols > 20 ? env->cols : 20) : 79;
    h = screen ? (env->rows > 11 ? env->rows - 1 : 10) : 24;
  } else if (w == 0 && is_one_of(name, paper)) {
    w = 360;                                   /* 5in x 3.5in */
    h = 252;
  } else if (w == 0 && is_one_of(name, pixels) && !is_one_of(name, windows)) {
    w = 640;
    h = 480;
  }
  if (w > 0 && k < size) {
    if (is_one_of(name, paper))
      k += (size_t)dm_num_snprintf(out + k, size - k, " size %.6gin,%.6gin", w / 72.0,
                                   h / 72.0);
    else if (is_one_of(name, pixels) || strcmp(name, "dumb") == 0)
      k += (size_t)snprintf(out + k, size - k, " size %d,%d", (int)(w + 0.5),
                            (int)(h + 0.5));
  }
  if (is_one_of(name, textmode) && k < size)
    k += (size_t)snprintf(out + k, size - k, "%s",
                          req->enhanced ? " enhanced" : " noenhanced");
  if (opts[0] != '\0' && k < size)
    k += (size_t)snprintf(out + k, size - k, "%s", opts);
  if (k >= size)
    return dm_err_set(e, DM_EINVAL, "terminal command too long");
  return DM_OK;
}

/* }==== */

/* {==== file outputs ======================================================== */

static int check_filename(const char *file, dm_err *e)
{
  const unsigned char *p;
  if (file[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "empty output file name");
  for (p = (const unsigned char *)file; *p != '\0'; p++)
    if (*p < 0x20 || *p == 0x7f)
      return dm_err_set(e, DM_EINVAL, "output file name contains a control "
                        "character");
  if (file[strlen(file) - 1] == '/')
    return dm_err_set(e, DM_EINVAL, "output file name '%.200s' is a directory",
                      file);
  return DM_OK;
}

int dm_gp_set_terminal(dm_gp_session *s, const dm_gp_termreq *req, dm_err *e)
{
  struct stat st;
  dm_gp_termenv env;
  char cmd[512];
  int rc;
  dm_gp_termenv_get(&env);
  if (req->file != NULL && (rc = check_filename(req->file, e)) != DM_OK)
    return rc;
  rc = dm_gp_terminal_command(s, req, &env, cmd, sizeof cmd, e);
  if (rc != DM_OK)
    return rc;
  if (req->file == NULL) {
    s->to_stdout = strncmp(cmd, "set terminal dumb", 17) == 0
                   || strncmp(cmd, "set terminal sixel", 18) == 0;
    return dm_gp_send(s, e, "%s\nset output\n", cmd);
  }
  gp_output_discard(s);
  /* a device or FIFO gets the finished plot copied from a private file */
  if (stat(req->file, &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode))
      && (rc = gp_ensure_datadir(s, e)) != DM_OK)
    return rc;
  rc = dm_outfile_open(&s->out, req->file, "plot output", DM_OUTFILE_NAMED,
                       s->datadir, e);
  if (rc != DM_OK)
    return rc;
  s->to_stdout = 0;
  rc = dm_gp_send(s, e, "set terminal push\n%s\nset output ", cmd);
  if (rc == DM_OK)
    rc = dm_gp_sendq(s, s->out.tmp, strlen(s->out.tmp), DM_GP_QUOTE_ONELINE, e);
  if (rc == DM_OK)
    rc = dm_gp_send(s, e, "\n");
  s->out_open = 1;
  return rc;
}

int gp_output_close(dm_gp_session *s, dm_err *e)
{
  static const char cmd[] = "\nunset output\nset terminal pop\n";
  if (s->out.tmp == NULL || !s->out_open)
    return DM_OK;
  s->out_open = 0;
  return gp_append(s, cmd, sizeof cmd - 1, e);
}

/* Does the file gnuplot wrote end as its format must?  gnuplot does not
 * report a failed write (a full disk, RLIMIT_FSIZE, being killed): a
 * truncated PNG was renamed over the older good file.  The format is told
 * by the first bytes, the end checked by the last ones (PNG: IEND chunk,
 * PDF/PostScript: %%EOF, SVG: </svg>, GIF: 0x3B, JPEG: FFD9); an empty
 * file is incomplete; other formats (text) pass. */
static int output_complete(const char *path)
{
  unsigned char head[8], tail[64];
  size_t nh, nt;
  long size;
  FILE *f = fopen(path, "rb");
  int ok = 1;
  if (f == NULL)
    return 0;
  nh = fread(head, 1, sizeof head, f);
  if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) <= 0) {
    fclose(f);
    return 0;
  }
  fseek(f, size > (long)sizeof tail ? size - (long)sizeof tail : 0, SEEK_SET);
  nt = fread(tail, 1, sizeof tail, f);
  fclose(f);
#define ENDS(lit) (nt >= sizeof(lit) - 1 \
                   && memcmp(tail + nt - (sizeof(lit) - 1), lit, sizeof(lit) - 1) == 0)
#define HAS(lit) (memmem(tail, nt, lit, sizeof(lit) - 1) != NULL)
  if (nh >= 8 && memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0)
    ok = ENDS("IEND\xae\x42\x60\x82");
  else if (nh >= 4 && (memcmp(head, "%PDF", 4) == 0 || memcmp(head, "%!PS", 4) == 0))
    ok = HAS("%%EOF");
  else if (nh >= 5 && (memcmp(head, "<?xml", 5) == 0 || memcmp(head, "<svg", 4) == 0))
    ok = HAS("</svg>");
  else if (nh >= 4 && memcmp(head, "GIF8", 4) == 0)
    ok = tail[nt - 1] == 0x3b;
  else if (nh >= 2 && head[0] == 0xff && head[1] == 0xd8)
    ok = ENDS("\xff\xd9");
#undef ENDS
#undef HAS
  return ok;
}

int gp_output_commit(dm_gp_session *s, dm_err *e)
{
  s->out_open = 0;
  if (s->out.tmp != NULL && !output_complete(s->out.tmp)) {
    int rc = dm_err_set(e, DM_EIO, "plot output '%.200s': the file gnuplot wrote is "
                        "incomplete (disk full or a file size limit?); nothing was "
                        "replaced", s->out.path);
    dm_outfile_abandon(&s->out);
    return rc;
  }
  return dm_outfile_commit(&s->out, e);
}

void gp_output_discard(dm_gp_session *s)
{
  dm_outfile_abandon(&s->out);
  s->out_open = 0;
}

/* }==== */
