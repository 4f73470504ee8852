/* trajectory_csv.c -- trajectories to and from CSV files (format in
 * trajectory.h).  Numbers are written with "%.17g" and read with strtod,
 * both in the "C" locale of numfmt.h selected for this thread only, so the
 * user's LC_NUMERIC (a decimal comma) never matters. */
#include <config.h>
#include "core/trajectory.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "core/numfmt.h"
#include "core/outfile.h"

#define MAGIC "# dmech trajectory "
#define FORMAT_VERSION 2     /* 2: numeric metadata ("# number"); 1 without */
#define POLL_EVERY 4096

/* {==== writing ============================================================ */

/* Metadata values may hold anything but NUL: escape what would break a line. */
static void put_escaped(FILE *f, const char *s)
{
  for (; *s != '\0'; s++) {
    unsigned char c = (unsigned char)*s;
    switch (c) {
    case '\\': fputs("\\\\", f); break;
    case '\n': fputs("\\n", f); break;
    case '\r': fputs("\\r", f); break;
    case '\t': fputs("\\t", f); break;
    default:
      if (c < 0x20 || c == 0x7f)
        fprintf(f, "\\x%02x", c);
      else
        fputc(c, f);
    }
  }
}

static void write_head(const dm_traj *tr, FILE *f)
{
  size_t i, nc = dm_traj_ncols(tr);
  int version = 1;
  for (i = 0; i < dm_traj_meta_count(tr); i++)
    if (dm_traj_meta_number_at(tr, i, NULL))
      version = FORMAT_VERSION;
  fprintf(f, MAGIC "%d\n", version);
  for (i = 0; i < dm_traj_meta_count(tr); i++) {
    const char *k, *v;
    dm_traj_meta_at(tr, i, &k, &v);
    fprintf(f, dm_traj_meta_number_at(tr, i, NULL) ? "# number %s=" : "# meta %s=", k);
    put_escaped(f, v);
    fputc('\n', f);
  }
  fputs("# kinds ", f);
  for (i = 0; i < nc; i++)
    fprintf(f, "%s%s", i ? "," : "", dm_traj_kindname(dm_traj_colkind(tr, i)));
  fputc('\n', f);
  for (i = 0; i < nc; i++)
    fprintf(f, "%s%s", i ? "," : "", dm_traj_colname(tr, i));
  fputc('\n', f);
}

static int write_body(const dm_traj *tr, FILE *f, const char *name, dm_err *e)
{
  size_t k, j, nc = dm_traj_ncols(tr), len = dm_traj_len(tr);
  for (k = 0; k < len; k++) {
    if ((k % POLL_EVERY == 0 || nc > 256) && dm_interrupted())
      return dm_err_set(e, DM_EINTR, "saving '%.200s': interrupted at sample "
                        "%zu of %zu", name, k, len);
    for (j = 0; j < nc; j++)
      fprintf(f, j ? ",%.17g" : "%.17g", dm_traj_col(tr, j)[k]);
    if (fputc('\n', f) == EOF)
      return dm_err_set(e, DM_EIO, "writing '%.200s': %s", name,
                        strerror(errno));
  }
  return DM_OK;
}

int dm_traj_write(const dm_traj *tr, FILE *f, const char *name, dm_err *e)
{
  locale_t old;
  int st;
  if (name == NULL)
    name = "(stream)";
  old = dm_num_enter();
  errno = 0;
  write_head(tr, f);
  st = write_body(tr, f, name, e);
  dm_num_leave(old);
  if (st == DM_OK && (fflush(f) != 0 || ferror(f)))
    st = dm_err_set(e, DM_EIO, "writing '%.200s': %s", name,
                    strerror(errno ? errno : EIO));
  return st;
}

int dm_traj_write_rows(const dm_traj *tr, FILE *f, const char *name, dm_err *e)
{
  locale_t old = dm_num_enter();
  int st;
  errno = 0;
  st = write_body(tr, f, name ? name : "(stream)", e);
  dm_num_leave(old);
  return st;
}

int dm_traj_save(const dm_traj *tr, const char *path, dm_err *e)
{
  dm_outfile o;
  int st;
  if (path == NULL || path[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "save: empty file name");
  if ((st = dm_outfile_open(&o, path, "saving", 0, NULL, e)) != DM_OK)
    return st;
  st = dm_traj_write(tr, o.f, path, e);
  if (st != DM_OK) {
    dm_outfile_abandon(&o);
    return st;
  }
  return dm_outfile_commit(&o, e);
}

/* }==== */

/* {==== reading ============================================================ */

typedef struct reader {
  const char *path;
  FILE *f;
  char *line;           /* current line, newline stripped */
  size_t cap;
  size_t lineno;
  dm_err *e;
} reader;

/* Next line into r->line: 1, 0 at end of file, -1 on error (e set). */
static int next_line(reader *r)
{
  ssize_t k;
  errno = 0;
  k = getline(&r->line, &r->cap, r->f);
  if (k < 0) {
    if (errno == ENOMEM) {          /* not the end of the file */
      dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory at line %zu", r->path,
                 r->lineno + 1);
      return -1;
    }
    if (ferror(r->f)) {
      dm_err_set(r->e, DM_EIO, "reading '%.200s': %s", r->path,
                 strerror(errno ? errno : EIO));
      return -1;
    }
    return 0;
  }
  r->lineno++;
  if ((size_t)k != strlen(r->line)) {
    dm_err_set(r->e, DM_EINVAL, "%.200s:%zu: line contains a NUL byte",
               r->path, r->lineno);
    return -1;
  }
  if (k > 0 && r->line[k - 1] == '\n')
    r->line[--k] = '\0';
  if (k > 0 && r->line[k - 1] == '\r')
    r->line[--k] = '\0';
  return 1;
}

static int fail_at(reader *r, const char *fmt, const char *a, const char *b)
{
  char msg[DM_ERRMSG_MAX];
  snprintf(msg, sizeof msg, fmt, a, b);
  return dm_err_set(r->e, DM_EINVAL, "%.200s:%zu: %s", r->path, r->lineno, msg);
}

/* Prefix a message some trajectory call left in e with "path:line: ". */
static int relocate(reader *r, int st)
{
  char msg[DM_ERRMSG_MAX];
  if (r->e == NULL)
    return st;
  snprintf(msg, sizeof msg, "%s", r->e->msg);
  return dm_err_set(r->e, st, "%.200s:%zu: %s", r->path, r->lineno, msg);
}

/* Number of comma-separated fields in s. */
static size_t count_fields(const char *s)
{
  size_t count = 1;
  for (; *s != '\0'; s++)
    count += *s == ',';
  return count;
}

/* Split s in place at commas into fields[count_fields(s)]. */
static void split(char *s, char **fields)
{
  size_t count = 0;
  for (;;) {
    char *c = strchr(s, ',');
    fields[count++] = s;
    if (c == NULL)
      return;
    *c = '\0';
    s = c + 1;
  }
}

static int unescape(reader *r, char *s)
{
  char *w = s;
  for (; *s != '\0'; s++) {
    if (*s != '\\') {
      *w++ = *s;
      continue;
    }
    s++;
    switch (*s) {
    case '\\': *w++ = '\\'; break;
    case 'n': *w++ = '\n'; break;
    case 'r': *w++ = '\r'; break;
    case 't': *w++ = '\t'; break;
    case 'x': {
      char hex[3] = {0, 0, 0}, *end;
      long c;
      if (s[1] != '\0')
        memcpy(hex, s + 1, 2);
      c = strtol(hex, &end, 16);
      if (end != hex + 2 || c == 0)
        return fail_at(r, "bad escape '\\x%.2s' in metadata value%s", hex, "");
      *w++ = (char)c;
      s += 2;
      break;
    }
    default:
      return fail_at(r, "bad escape '\\%.1s' in metadata value (expected "
                     "\\\\, \\n, \\r, \\t or \\xHH)%s", s, "");
    }
  }
  *w = '\0';
  return DM_OK;
}

static int kind_of(const char *s)
{
  int k;
  for (k = DM_TRAJ_T; k <= DM_TRAJ_DATA; k++)
    if (strcmp(s, dm_traj_kindname(k)) == 0)
      return k;
  return -1;
}

/* Everything seen before the header line. */
typedef struct preamble {
  int magic;               /* "# dmech trajectory 1" seen */
  char *kinds;             /* copy of the kinds list, or NULL */
  size_t kinds_line;
  char **mkey, **mval;     /* metadata in file order */
  double *mx;              /* numeric values (NaN for strings) */
  unsigned char *misnum;
  size_t nmeta;
} preamble;

static void preamble_free(preamble *pr)
{
  size_t i;
  for (i = 0; i < pr->nmeta; i++) {
    free(pr->mkey[i]);
    free(pr->mval[i]);
  }
  free(pr->mkey);
  free(pr->mval);
  free(pr->mx);
  free(pr->misnum);
  free(pr->kinds);
}

/* "# meta key=value" (isnum 0) or "# number key=value" (isnum 1) */
static int read_meta(reader *r, preamble *pr, const char *text, int isnum)
{
  const char *eq = strchr(text, '='), *what = isnum ? "number" : "meta";
  char *k, *v, **nk, **nv, *end;
  double *nx, x = NAN;
  unsigned char *nn;
  size_t i;
  int st;
  if (eq == NULL || eq == text)
    return fail_at(r, "expected '# %s key=value', got '%.200s'", what, r->line);
  if (isnum) {
    x = dm_num_parse(eq + 1, &end);
    if (end == eq + 1 || *end != '\0')
      return fail_at(r, "'# number' value '%.60s' is not a number%s", eq + 1, "");
  }
  k = strndup(text, (size_t)(eq - text));
  v = strdup(eq + 1);
  nk = realloc(pr->mkey, (pr->nmeta + 1) * sizeof *nk);
  if (nk != NULL)
    pr->mkey = nk;
  nv = nk != NULL ? realloc(pr->mval, (pr->nmeta + 1) * sizeof *nv) : NULL;
  if (nv != NULL)
    pr->mval = nv;
  nx = nv != NULL ? realloc(pr->mx, (pr->nmeta + 1) * sizeof *nx) : NULL;
  if (nx != NULL)
    pr->mx = nx;
  nn = nx != NULL ? realloc(pr->misnum, pr->nmeta + 1) : NULL;
  if (nn != NULL)
    pr->misnum = nn;
  if (k == NULL || v == NULL || nn == NULL) {
    free(k);
    free(v);
    return dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
  }
  for (i = 0; i < pr->nmeta; i++)
    if (strcmp(pr->mkey[i], k) == 0) {
      st = fail_at(r, "duplicate metadata key '%.200s'%s", k, "");
      free(k);
      free(v);
      return st;
    }
  pr->mkey[pr->nmeta] = k;
  pr->mval[pr->nmeta] = v;
  pr->mx[pr->nmeta] = x;
  pr->misnum[pr->nmeta] = (unsigned char)isnum;
  pr->nmeta++;
  return isnum ? DM_OK : unescape(r, v);
}

/* One '#' line before the header. */
static int read_comment(reader *r, preamble *pr)
{
  const char *s = r->line;
  if (strncmp(s, MAGIC, strlen(MAGIC)) == 0) {
    const char *ver = s + strlen(MAGIC);
    if (strcmp(ver, "1") != 0 && strcmp(ver, "2") != 0)
      return fail_at(r, "unsupported trajectory format version '%.50s' (this "
                     "dmech reads versions 1 and 2)%s", ver, "");
    pr->magic = ver[0] - '0';
    return DM_OK;
  }
  if (strncmp(s, "# meta ", 7) == 0)
    return read_meta(r, pr, s + 7, 0);
  if (strncmp(s, "# number ", 9) == 0 && pr->magic >= 2)
    return read_meta(r, pr, s + 9, 1);
  if (strncmp(s, "# kinds ", 8) == 0) {
    if (pr->kinds != NULL) {
      char a[32];
      snprintf(a, sizeof a, "%zu", pr->kinds_line);
      return fail_at(r, "second '# kinds' line (the first is on line %s)%s",
                     a, "");
    }
    pr->kinds = strdup(s + 8);
    pr->kinds_line = r->lineno;
    if (pr->kinds == NULL)
      return dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory",
                        r->path);
  }
  return DM_OK;                  /* any other comment is ignored */
}

static int cmp_name(const void *a, const void *b)
{
  return strcmp(*(char *const *)a, *(char *const *)b);
}

/* A name used twice in the header, found by sorting a copy of the list
 * (O(n log n): a header of 10^5 names took 30 s with the pairwise test). */
static int twice(reader *r, char **names, size_t nc)
{
  char **sorted = malloc(nc * sizeof *sorted);
  size_t i;
  int st = DM_OK;
  if (sorted == NULL)
    return dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory",
                      r->path);
  memcpy(sorted, names, nc * sizeof *sorted);
  qsort(sorted, nc, sizeof *sorted, cmp_name);
  for (i = 1; i < nc && st == DM_OK; i++)
    if (strcmp(sorted[i], sorted[i - 1]) == 0)
      st = fail_at(r, "column '%.100s' appears twice in the header%s",
                   sorted[i], "");
  free(sorted);
  return st;
}

/* The p (pass 1) or v (pass 2) columns from column *j on: "p_<coord>" for
 * each of the n coordinates, or -- named momenta -- a run of columns of
 * the kind with their own names (*np of them; a v run must match the p
 * run).  *named: -1 not known yet, 0 standard, 1 named. */
static int state_block(reader *r, char **names, const int *kind, size_t nc, size_t q0,
                       size_t n, int pass, size_t *j, size_t *np, int *named)
{
  const char *pre = pass == 1 ? "p_" : "v_";
  int k = pass == 1 ? DM_TRAJ_P : DM_TRAJ_V;
  char want[DM_TRAJ_NAME_MAX + 8];
  size_t i, start = *j;
  if (*named < 0)
    *named = strncmp(names[*j], pre, 2) != 0;
  if (!*named) {
    for (i = 0; i < n; i++, (*j)++) {
      snprintf(want, sizeof want, "%s%s", pre, names[q0 + i]);
      if (*j >= nc || kind[*j] != k || strcmp(names[*j], want) != 0)
        return fail_at(r, pass == 1 ? "expected momentum column '%.140s' of kind p after "
                       "the q columns%s" : "expected velocity column '%.140s' of kind v "
                       "after the q and p columns%s", want, "");
    }
    *np = n;
    return DM_OK;
  }
  while (*j < nc && kind[*j] == k)
    (*j)++;
  if (pass == 2 && *np != SIZE_MAX && *j - start != *np) {
    char a[32], b[32];
    snprintf(a, sizeof a, "%zu", *j - start);
    snprintf(b, sizeof b, "%zu", *np);
    return fail_at(r, "%s velocity columns of kind v for %s momentum columns of kind p", a, b);
  }
  *np = *j - start;
  return DM_OK;
}

/* Check the kinds against the header names: t, n q, [np p], [np v],
 * extras. */
static int layout(reader *r, char **names, char **kinds, size_t nc,
                  size_t *n, size_t *np, int *named, unsigned *flags, int *kind)
{
  size_t j, i, q0;
  for (i = 0; i < nc; i++) {
    kind[i] = kinds != NULL ? kind_of(kinds[i]) : (i == 0 ? DM_TRAJ_T : DM_TRAJ_DATA);
    if (kind[i] < 0)
      return fail_at(r, "unknown column kind '%.50s' in '# kinds' (expected t, "
                     "q, p, v, diag, derived or data)%s", kinds[i], "");
  }
  {
    int st = twice(r, names, nc);
    if (st != DM_OK)
      return st;
  }
  j = 1;
  if (kind[0] != DM_TRAJ_T || strcmp(names[0], "t") != 0)
    return fail_at(r, "the first column must be 't' of kind t (got '%.100s' "
                   "of kind %s)", names[0], dm_traj_kindname(kind[0]));
  for (q0 = j; j < nc && kind[j] == DM_TRAJ_Q; j++)
    ;
  *n = j - q0;
  *np = SIZE_MAX;
  *named = -1;
  *flags = 0;
  if (j < nc && kind[j] == DM_TRAJ_P) {
    int st = state_block(r, names, kind, nc, q0, *n, 1, &j, np, named);
    if (st != DM_OK)
      return st;
    *flags |= DM_TRAJ_WITH_P;
  }
  if (j < nc && kind[j] == DM_TRAJ_V) {
    int st = state_block(r, names, kind, nc, q0, *n, 2, &j, np, named);
    if (st != DM_OK)
      return st;
    *flags |= DM_TRAJ_WITH_V;
  }
  if (*np == SIZE_MAX)
    *np = *n;
  if (*named < 0)
    *named = 0;
  for (; j < nc; j++)
    if (kind[j] < DM_TRAJ_DIAG)
      return fail_at(r, "column '%.100s' of kind %s is out of place (order: "
                     "t, q..., p..., v..., then diag/derived/data)",
                     names[j], dm_traj_kindname(kind[j]));
  return DM_OK;
}

/* Build the empty trajectory described by the header line and preamble. */
static dm_traj *make_traj(reader *r, preamble *pr, size_t *ncols)
{
  size_t nc = count_fields(r->line), nk = 0, n = 0, np = 0, i;
  char **names = malloc(nc * sizeof *names), **kinds = NULL;
  int *kind = malloc(nc * sizeof *kind), named = 0;
  unsigned flags = 0;
  dm_traj *tr = NULL;
  int st;
  if (names == NULL || kind == NULL) {
    dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
    goto done;
  }
  split(r->line, names);
  if (pr->kinds != NULL) {
    nk = count_fields(pr->kinds);
    if ((kinds = malloc(nk * sizeof *kinds)) == NULL) {
      dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
      goto done;
    }
    split(pr->kinds, kinds);
    if (nk != nc) {
      char a[32], b[32];
      snprintf(a, sizeof a, "%zu", nc);
      snprintf(b, sizeof b, "%zu", nk);
      fail_at(r, "the header names %s columns but '# kinds' lists %s", a, b);
      goto done;
    }
  } else if (pr->magic) {
    fail_at(r, "expected a '# kinds' line before the header%s%s", "", "");
    goto done;
  }
  if (layout(r, names, kinds, nc, &n, &np, &named, &flags, kind) != DM_OK)
    goto done;
  {
    const char *const *cn = (const char *const *)names;
    size_t jp = 1 + n, jv = jp + ((flags & DM_TRAJ_WITH_P) ? np : 0);
    tr = named ? dm_traj_alloc_state(n, cn + 1, np, (flags & DM_TRAJ_WITH_P) ? cn + jp : NULL,
                                     (flags & DM_TRAJ_WITH_V) ? cn + jv : NULL, flags, r->e)
               : dm_traj_alloc(n, cn + 1, flags, r->e);
  }
  for (i = 1 + n + np * (!!(flags & DM_TRAJ_WITH_P) + !!(flags & DM_TRAJ_WITH_V));
       tr != NULL && i < nc; i++)
    if ((st = dm_traj_add_column(tr, names[i], kind[i], NULL, 0, r->e)) != DM_OK) {
      dm_traj_free(tr);
      tr = NULL;
    }
  for (i = 0; tr != NULL && i < pr->nmeta; i++)
    if ((st = pr->misnum[i] ? dm_traj_meta_set_number(tr, pr->mkey[i], pr->mx[i], r->e)
                            : dm_traj_meta_set(tr, pr->mkey[i], pr->mval[i], r->e)) != DM_OK) {
      dm_traj_free(tr);
      tr = NULL;
    }
  if (tr == NULL && (r->e == NULL || r->e->status != DM_ENOMEM))
    relocate(r, DM_EINVAL);
  *ncols = nc;
done:
  free(names);
  free(kinds);
  free(kind);
  return tr;
}

/* Parse one data line into row[nc]. */
static int parse_row(reader *r, const dm_traj *tr, size_t nc, double *row)
{
  char *s = r->line, *end;
  size_t j;
  if (*s == '\0') {
    char a[32];
    snprintf(a, sizeof a, "%zu", nc);
    return fail_at(r, "empty line (expected %s comma-separated numbers)%s", a, "");
  }
  for (j = 0; j < nc; j++) {
    char *field = s;
    row[j] = strtod(s, &end);
    while (*end == ' ' || *end == '\t')
      end++;
    if (end == s || (*end != ',' && *end != '\0')) {
      char *c = strchr(field, ',');
      char msg[DM_ERRMSG_MAX];
      if (c != NULL)
        *c = '\0';
      snprintf(msg, sizeof msg, "field %zu (column '%s'): '%.60s' is not a number",
               j + 1, dm_traj_colname(tr, j), field);
      return fail_at(r, "%s%s", msg, "");
    }
    if (*end == '\0' && j + 1 < nc) {
      char a[64], b[32];
      snprintf(a, sizeof a, "%zu", nc);
      snprintf(b, sizeof b, "%zu", j + 1);
      return fail_at(r, "expected %s comma-separated numbers, got %s", a, b);
    }
    s = end + 1;
    if (*end == '\0')
      break;
  }
  if (*end == ',') {
    char a[64], b[32];
    snprintf(a, sizeof a, "%zu", nc);
    snprintf(b, sizeof b, "%zu", nc + count_fields(s));
    return fail_at(r, "expected %s comma-separated numbers, got %s", a, b);
  }
  return DM_OK;
}

static int read_rows(reader *r, dm_traj *tr, size_t nc)
{
  double *row = malloc(nc * sizeof *row);
  size_t n = dm_traj_ncoords(tr), np = dm_traj_nmomenta(tr), j;
  const double *q = row + 1, *p = NULL, *v = NULL;
  int got, st = DM_OK;
  if (row == NULL)
    return dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
  j = 1 + n;
  if (dm_traj_flags(tr) & DM_TRAJ_WITH_P) {
    p = row + j;
    j += np;
  }
  if (dm_traj_flags(tr) & DM_TRAJ_WITH_V) {
    v = row + j;
    j += np;
  }
  while (st == DM_OK && (got = next_line(r)) > 0) {
    if ((r->lineno % POLL_EVERY == 0 || nc > 256) && dm_interrupted())
      st = dm_err_set(r->e, DM_EINTR, "reading '%.200s': interrupted at line "
                      "%zu", r->path, r->lineno);
    else if ((st = parse_row(r, tr, nc, row)) == DM_OK)
      st = dm_traj_append(tr, row[0], q, p, v, row + j, r->e);
  }
  if (st == DM_OK && got < 0)
    st = r->e != NULL ? r->e->status : DM_EIO;
  free(row);
  return st;
}

dm_traj *dm_traj_load(const char *path, dm_err *e)
{
  reader r = {0};
  preamble pr = {0};
  dm_traj *tr = NULL;
  size_t nc = 0;
  int got, st = DM_OK;
  r.path = path != NULL ? path : "";
  r.e = e;
  r.f = fopen(r.path, "re");
  if (r.f == NULL) {
    dm_err_set(e, DM_EIO, "cannot open '%.200s': %s", r.path, strerror(errno));
    return NULL;
  }
  {
    /* a device never ends (/dev/zero, /dev/full: one endless line of NUL
     * bytes); a FIFO (a pipe from another program) is fine */
    struct stat sb;
    if (fstat(fileno(r.f), &sb) == 0 && !S_ISREG(sb.st_mode) && !S_ISFIFO(sb.st_mode)) {
      dm_err_set(e, DM_EINVAL, "cannot read '%.200s': it is %s, not a file", r.path,
                 S_ISDIR(sb.st_mode) ? "a directory" : S_ISCHR(sb.st_mode)
                 ? "a character device" : "a special file");
      fclose(r.f);
      return NULL;
    }
  }
  while ((got = next_line(&r)) > 0 && r.line[0] == '#')
    if ((st = read_comment(&r, &pr)) != DM_OK)
      break;
  if (st == DM_OK && got == 0)
    dm_err_set(e, DM_EINVAL, "%.200s:%zu: no header line (expected 't,...' "
               "naming the columns)", r.path, r.lineno);
  else if (st == DM_OK && got > 0 && r.line[0] == '\0')
    fail_at(&r, "empty line where the header was expected ('t,...')%s%s", "", "");
  else if (st == DM_OK && got > 0)
    tr = make_traj(&r, &pr, &nc);
  if (tr != NULL) {
    locale_t old = dm_num_enter();
    st = read_rows(&r, tr, nc);
    dm_num_leave(old);
  }
  if (st != DM_OK) {
    dm_traj_free(tr);
    tr = NULL;
  }
  preamble_free(&pr);
  free(r.line);
  fclose(r.f);
  return tr;
}

/* }==== */
