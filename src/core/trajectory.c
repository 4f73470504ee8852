/* trajectory.c -- columnar storage of a run: columns and their names,
 * samples, slicing.  Extra (diagnostic, derived, data) columns are in
 * trajectory_columns.c, the metadata in trajectory_meta.c, the CSV files
 * in trajectory_csv.c. */
#include <config.h>
#include "core/trajectory_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

char *dm_traj__dupstr(const char *s)
{
  size_t k = strlen(s) + 1;
  char *d = malloc(k);
  if (d != NULL)
    memcpy(d, s, k);
  return d;
}

/* {==== names ============================================================ */

int dm_traj__valid_name(const char *s)
{
  size_t k;
  if (s == NULL || s[0] == '\0')
    return 0;
  for (k = 0; s[k] != '\0'; k++) {
    unsigned char c = (unsigned char)s[k];
    if (k >= DM_TRAJ_NAME_MAX || c < 0x20 || c == 0x7f || c == ' '
        || c == ',' || c == '"' || c == '\'')
      return 0;
  }
  return 1;
}

int dm_traj__bad_name(dm_err *e, const char *what, const char *s)
{
  if (s == NULL)
    return dm_err_set(e, DM_EINVAL, "%s name missing", what);
  return dm_err_set(e, DM_EINVAL, "invalid %s name '%.*s' (1 to %d bytes, "
                    "no spaces, commas, quotes or control characters)", what,
                    DM_TRAJ_NAME_MAX + 8, s, DM_TRAJ_NAME_MAX);
}

/* {==== the name index ===================================================
 * Wide trajectories (a CSV file of 10^5 columns) must not make every name
 * lookup, and so every column added, cost O(columns): past INDEX_FROM
 * columns names are found through an open-addressing hash table, kept up
 * to date by every change of the column list.  If its memory cannot be
 * had, lookups fall back to the linear search (same answers). */

#define INDEX_FROM 32

static size_t name_hash(const char *s)
{
  uint64_t h = 1469598103934665603ULL;            /* FNV-1a */
  for (; *s != '\0'; s++)
    h = (h ^ (unsigned char)*s) * 1099511628211ULL;
  return (size_t)(h ^ (h >> 32));
}

static void index_put(dm_traj *tr, size_t j)
{
  size_t k = name_hash(tr->cols[j].name) & (tr->hcap - 1);
  while (tr->hidx[k] != 0)
    k = (k + 1) & (tr->hcap - 1);
  tr->hidx[k] = j + 1;
}

/* Rebuild for the current columns (load <= 1/2), or drop it. */
void dm_traj__index_rebuild(dm_traj *tr)
{
  size_t cap = 64, j;
  free(tr->hidx);
  tr->hidx = NULL;
  tr->hcap = 0;
  if (tr->ncols < INDEX_FROM)
    return;
  while (cap < 2 * tr->ncols)
    cap *= 2;
  if ((tr->hidx = calloc(cap, sizeof *tr->hidx)) == NULL)
    return;
  tr->hcap = cap;
  for (j = 0; j < tr->ncols; j++)
    index_put(tr, j);
}

/* Column j (the last one) was just appended. */
void dm_traj__index_added(dm_traj *tr, size_t j)
{
  if (tr->hidx != NULL && 2 * tr->ncols <= tr->hcap)
    index_put(tr, j);
  else if (tr->ncols >= INDEX_FROM)
    dm_traj__index_rebuild(tr);
}

/* }==== */

size_t dm_traj_find(const dm_traj *tr, const char *name)
{
  size_t j;
  if (tr == NULL || name == NULL)
    return DM_TRAJ_NONE;
  if (tr->hidx != NULL) {
    size_t k = name_hash(name) & (tr->hcap - 1);
    for (; tr->hidx[k] != 0; k = (k + 1) & (tr->hcap - 1))
      if (strcmp(tr->cols[tr->hidx[k] - 1].name, name) == 0)
        return tr->hidx[k] - 1;
    return DM_TRAJ_NONE;
  }
  for (j = 0; j < tr->ncols; j++)
    if (strcmp(tr->cols[j].name, name) == 0)
      return j;
  return DM_TRAJ_NONE;
}

char *dm_traj_names(const dm_traj *tr, char *buf, size_t size)
{
  size_t j, used = 0;
  if (size == 0)
    return buf;
  buf[0] = '\0';
  for (j = 0; j < tr->ncols; j++) {
    const char *sep = j > 0 ? ", " : "";
    size_t need = strlen(sep) + strlen(tr->cols[j].name);
    /* the last name needs its own room; others also room for ", ..." */
    size_t room = need + 1 + (j + 1 < tr->ncols ? 5 : 0);
    if (used + room > size) {
      if (used + 6 <= size)
        strcpy(buf + used, j > 0 ? ", ..." : "...");
      break;
    }
    used += (size_t)snprintf(buf + used, size - used, "%s%s", sep,
                             tr->cols[j].name);
  }
  return buf;
}

int dm_traj_lookup(const dm_traj *tr, const char *name, size_t *j, dm_err *e)
{
  char list[DM_ERRMSG_MAX - 64];
  size_t k = dm_traj_find(tr, name);
  if (k == DM_TRAJ_NONE)
    return dm_err_set(e, DM_ENOTFOUND, "no column '%.100s' (available: %s)",
                      name != NULL ? name : "(null)",
                      dm_traj_names(tr, list, sizeof list));
  if (j != NULL)
    *j = k;
  return DM_OK;
}

/* }==== */

/* {==== life cycle ======================================================= */

/* Append a column named prefix+name (not yet allocated: x == NULL). */
static int push_col(dm_traj *tr, const char *prefix, const char *name,
                    int kind, dm_err *e)
{
  size_t lp = strlen(prefix), ln = strlen(name);
  char *s;
  if (tr->ncols == tr->colcap) {
    size_t nc = tr->colcap ? 2 * tr->colcap : 8;
    column *c = realloc(tr->cols, nc * sizeof *c);
    if (c == NULL)
      return dm_err_set(e, DM_ENOMEM, "trajectory: out of memory for columns");
    tr->cols = c;
    tr->colcap = nc;
  }
  s = malloc(lp + ln + 1);
  if (s == NULL)
    return dm_err_set(e, DM_ENOMEM, "trajectory: out of memory for names");
  memcpy(s, prefix, lp);
  memcpy(s + lp, name, ln + 1);
  if (!dm_traj__valid_name(s)) {
    int st = dm_traj__bad_name(e, "column", s);
    free(s);
    return st;
  }
  if (dm_traj_find(tr, s) != DM_TRAJ_NONE) {
    dm_err_set(e, DM_EINVAL, "column name '%s' is used twice", s);
    free(s);
    return DM_EINVAL;
  }
  tr->cols[tr->ncols].name = s;
  tr->cols[tr->ncols].kind = kind;
  tr->cols[tr->ncols].x = NULL;
  tr->ncols++;
  dm_traj__index_added(tr, tr->ncols - 1);
  return DM_OK;
}

/* The q, p or v columns (pass 0, 1, 2): names from `names`, or the
 * coordinates with the prefix, or "q1".. */
static int push_state_cols(dm_traj *tr, int pass, size_t count, const char *const *names,
                           const char *const *coords, dm_err *e)
{
  static const char *const pre[3] = {"", "p_", "v_"};
  static const int kinds[3] = {DM_TRAJ_Q, DM_TRAJ_P, DM_TRAJ_V};
  static const char *const what[3] = {"coordinate", "momentum", "velocity"};
  size_t i;
  int st = DM_OK;
  for (i = 0; i < count && st == DM_OK; i++) {
    char def[32];
    const char *name = def;
    const char *prefix = pre[pass];
    if (names != NULL) {
      name = names[i];
      prefix = "";
      if (!dm_traj__valid_name(name))
        return dm_traj__bad_name(e, what[pass], name);
    } else if (coords != NULL) {
      name = coords[i];
      if (!dm_traj__valid_name(name) || (pass == 0 && strlen(name) > DM_TRAJ_NAME_MAX - 2))
        return dm_traj__bad_name(e, "coordinate", name);
    } else {
      snprintf(def, sizeof def, "q%zu", i + 1);
    }
    st = push_col(tr, prefix, name, kinds[pass], e);
  }
  return st;
}

dm_traj *dm_traj_alloc_state(size_t n, const char *const *coords, size_t np,
                             const char *const *pnames, const char *const *vnames,
                             unsigned flags, dm_err *e)
{
  dm_traj *tr;
  int st = DM_OK, named = pnames != NULL || vnames != NULL;

  if (flags & ~(unsigned)(DM_TRAJ_WITH_P | DM_TRAJ_WITH_V)) {
    dm_err_set(e, DM_EINVAL, "trajectory: unknown flags 0x%x", flags);
    return NULL;
  }
  if (n > 1000000 || np > 1000000) {
    dm_err_set(e, DM_EINVAL, "trajectory: %zu coordinates is too many", n > np ? n : np);
    return NULL;
  }
  if ((!named && np != n) || (named && (((flags & DM_TRAJ_WITH_P) && pnames == NULL)
                                         || ((flags & DM_TRAJ_WITH_V) && vnames == NULL)))) {
    dm_err_set(e, DM_EINVAL, "trajectory: %zu momenta for %zu coordinates need the names of "
               "their p and v columns", np, n);
    return NULL;
  }
  tr = calloc(1, sizeof *tr);
  if (tr == NULL) {
    dm_err_set(e, DM_ENOMEM, "trajectory: out of memory");
    return NULL;
  }
  tr->n = n;
  tr->np = np;
  tr->named = named;
  tr->flags = flags;
  st = push_col(tr, "", "t", DM_TRAJ_T, e);
  if (st == DM_OK)
    st = push_state_cols(tr, 0, n, NULL, coords, e);
  if (st == DM_OK && (flags & DM_TRAJ_WITH_P))
    st = push_state_cols(tr, 1, np, pnames, coords, e);
  if (st == DM_OK && (flags & DM_TRAJ_WITH_V))
    st = push_state_cols(tr, 2, np, vnames, coords, e);
  if (st != DM_OK) {
    dm_traj_free(tr);
    return NULL;
  }
  tr->nstate = tr->ncols;
  return tr;
}

dm_traj *dm_traj_alloc(size_t n, const char *const *coords, unsigned flags,
                       dm_err *e)
{
  return dm_traj_alloc_state(n, coords, n, NULL, NULL, flags, e);
}

void dm_traj_free(dm_traj *tr)
{
  size_t j;
  if (tr == NULL)
    return;
  for (j = 0; j < tr->ncols; j++) {
    free(tr->cols[j].name);
    free(tr->cols[j].x);
  }
  free(tr->cols);
  free(tr->hidx);
  for (j = 0; j < tr->nmeta; j++) {
    free(tr->m[j].key);
    free(tr->m[j].val);
  }
  free(tr->m);
  free(tr);
}

/* Grow every column to hold at least `need` samples.  A failure part way
 * leaves some columns larger than tr->cap, which is harmless: the data are
 * intact and the next attempt reallocates to at least the same size. */
static int grow(dm_traj *tr, size_t need, dm_err *e)
{
  size_t j, nc;
  if (need <= tr->cap)
    return DM_OK;
  nc = tr->cap < 16 ? 16 : tr->cap;
  while (nc < need)
    nc = nc > SIZE_MAX / 2 ? need : 2 * nc;
  if (nc > SIZE_MAX / sizeof(double))
    return dm_err_set(e, DM_ENOMEM, "trajectory: %zu samples is too many", need);
  for (j = 0; j < tr->ncols; j++) {
    double *x = realloc(tr->cols[j].x, nc * sizeof *x);
    if (x == NULL)
      return dm_err_set(e, DM_ENOMEM, "trajectory: out of memory growing "
                        "to %zu samples (%zu kept)", nc, tr->len);
    tr->cols[j].x = x;
  }
  tr->cap = nc;
  return DM_OK;
}

int dm_traj_reserve(dm_traj *tr, size_t nsamples, dm_err *e)
{
  size_t j, nc = nsamples;
  if (nc <= tr->cap)
    return DM_OK;
  if (nc > SIZE_MAX / sizeof(double))
    return dm_err_set(e, DM_ENOMEM, "trajectory: %zu samples is too many", nc);
  for (j = 0; j < tr->ncols; j++) {
    double *x = realloc(tr->cols[j].x, nc * sizeof *x);
    if (x == NULL)
      return dm_err_set(e, DM_ENOMEM, "trajectory: out of memory reserving "
                        "%zu samples", nc);
    tr->cols[j].x = x;
  }
  tr->cap = nc;
  return DM_OK;
}

void dm_traj_shrink(dm_traj *tr)
{
  size_t j, nc = tr->len > 0 ? tr->len : 1;
  if (nc >= tr->cap)
    return;
  for (j = 0; j < tr->ncols; j++) {
    double *x = realloc(tr->cols[j].x, nc * sizeof *x);
    if (x != NULL)               /* refused: that column keeps its room */
      tr->cols[j].x = x;
  }
  tr->cap = nc;                  /* every column holds at least nc */
}

size_t dm_traj_bytes(const dm_traj *tr)
{
  return tr->cap * tr->ncols * sizeof(double);
}

void dm_traj_clear(dm_traj *tr)
{
  tr->len = 0;
}

/* }==== */

/* {==== appending and access ============================================ */

int dm_traj_append(dm_traj *tr, double t, const double *q, const double *p,
                   const double *v, const double *extra, dm_err *e)
{
  size_t i, j, k = tr->len, n = tr->n, np = tr->np;
  column *c;
  int st;
  if (n > 0 && q == NULL)
    return dm_err_set(e, DM_EINVAL, "trajectory append: q missing");
  if (k == tr->cap && (st = grow(tr, k + 1, e)) != DM_OK)
    return st;
  c = tr->cols;
  c[0].x[k] = t;
  for (i = 0; i < n; i++)
    c[1 + i].x[k] = q[i];
  j = 1 + n;
  if (tr->flags & DM_TRAJ_WITH_P) {
    for (i = 0; i < np; i++)
      c[j + i].x[k] = p != NULL ? p[i] : NAN;
    j += np;
  }
  if (tr->flags & DM_TRAJ_WITH_V) {
    for (i = 0; i < np; i++)
      c[j + i].x[k] = v != NULL ? v[i] : NAN;
    j += np;
  }
  for (i = 0; j + i < tr->ncols; i++)
    c[j + i].x[k] = extra != NULL ? extra[i] : NAN;
  tr->len = k + 1;
  return DM_OK;
}

int dm_traj_sink(void *ctx, double t, const double *q, const double *p,
                 const double *v)
{
  return dm_traj_append((dm_traj *)ctx, t, q, p, v, NULL, NULL);
}

size_t dm_traj_len(const dm_traj *tr) { return tr->len; }
size_t dm_traj_ncoords(const dm_traj *tr) { return tr->n; }
size_t dm_traj_nmomenta(const dm_traj *tr) { return tr->np; }
int dm_traj_named_momenta(const dm_traj *tr) { return tr->named; }
size_t dm_traj_ncols(const dm_traj *tr) { return tr->ncols; }
unsigned dm_traj_flags(const dm_traj *tr) { return tr->flags; }

const char *dm_traj_coord(const dm_traj *tr, size_t i)
{
  return i < tr->n ? tr->cols[1 + i].name : NULL;
}

const char *dm_traj_colname(const dm_traj *tr, size_t j)
{
  return j < tr->ncols ? tr->cols[j].name : NULL;
}

int dm_traj_colkind(const dm_traj *tr, size_t j)
{
  return j < tr->ncols ? tr->cols[j].kind : -1;
}

const double *dm_traj_col(const dm_traj *tr, size_t j)
{
  return j < tr->ncols ? tr->cols[j].x : NULL;
}

const char *dm_traj_kindname(int kind)
{
  static const char *const names[] = {"t", "q", "p", "v", "diag", "derived",
                                      "data"};
  if (kind < 0 || kind > DM_TRAJ_DATA)
    return "?";
  return names[kind];
}

size_t dm_traj_qcol(const dm_traj *tr, size_t i)
{
  return i < tr->n ? 1 + i : DM_TRAJ_NONE;
}

size_t dm_traj_pcol(const dm_traj *tr, size_t i)
{
  if (i >= tr->np || !(tr->flags & DM_TRAJ_WITH_P))
    return DM_TRAJ_NONE;
  return 1 + tr->n + i;
}

size_t dm_traj_vcol(const dm_traj *tr, size_t i)
{
  if (i >= tr->np || !(tr->flags & DM_TRAJ_WITH_V))
    return DM_TRAJ_NONE;
  return tr->nstate - tr->np + i;
}

int dm_traj_get(const dm_traj *tr, size_t k, double *t, double *q, double *p,
                double *v, dm_err *e)
{
  size_t i, n = tr->n;
  if (k >= tr->len)
    return dm_err_set(e, DM_EINVAL, "sample %zu out of range (%zu samples)",
                      k, tr->len);
  if (t != NULL)
    *t = tr->cols[0].x[k];
  for (i = 0; i < n && q != NULL; i++)
    q[i] = tr->cols[1 + i].x[k];
  for (i = 0; i < tr->np; i++) {
    size_t jp = dm_traj_pcol(tr, i), jv = dm_traj_vcol(tr, i);
    if (p != NULL)
      p[i] = jp != DM_TRAJ_NONE ? tr->cols[jp].x[k] : NAN;
    if (v != NULL)
      v[i] = jv != DM_TRAJ_NONE ? tr->cols[jv].x[k] : NAN;
  }
  return DM_OK;
}

int dm_traj_row(const dm_traj *tr, size_t k, double *row, dm_err *e)
{
  size_t j;
  if (k >= tr->len)
    return dm_err_set(e, DM_EINVAL, "sample %zu out of range (%zu samples)",
                      k, tr->len);
  for (j = 0; j < tr->ncols; j++)
    row[j] = tr->cols[j].x[k];
  return DM_OK;
}

/* }==== */

/* {==== slicing ================================================================ */

static int copy_meta(dm_traj *dst, const dm_traj *src, dm_err *e)
{
  size_t i;
  int st;
  for (i = 0; i < src->nmeta; i++) {
    const meta *m = &src->m[i];
    st = m->isnum ? dm_traj_meta_set_number(dst, m->key, m->x, e)
                  : dm_traj_meta_set(dst, m->key, m->val, e);
    if (st != DM_OK)
      return st;
  }
  return DM_OK;
}

dm_traj *dm_traj_slice(const dm_traj *tr, size_t i, size_t j, size_t stride,
                       dm_err *e)
{
  const char **coords = NULL, **pn, **vn;
  dm_traj *s = NULL;
  size_t a, c, k, count;
  int st = DM_OK;
  if (i > j || j > tr->len || stride == 0) {
    dm_err_set(e, DM_EINVAL, "slice [%zu, %zu) stride %zu of a trajectory "
               "with %zu samples: need i <= j <= %zu and stride >= 1",
               i, j, stride, tr->len, tr->len);
    return NULL;
  }
  count = (j - i + stride - 1) / stride;
  coords = malloc((tr->n + 2 * tr->np + 1) * sizeof *coords);
  if (coords == NULL) {
    dm_err_set(e, DM_ENOMEM, "slice: out of memory");
    return NULL;
  }
  pn = coords + tr->n;
  vn = pn + tr->np;
  for (a = 0; a < tr->n; a++)
    coords[a] = tr->cols[1 + a].name;
  for (a = 0; a < tr->np; a++) {
    size_t jp = dm_traj_pcol(tr, a), jv = dm_traj_vcol(tr, a);
    pn[a] = jp != DM_TRAJ_NONE ? tr->cols[jp].name : NULL;
    vn[a] = jv != DM_TRAJ_NONE ? tr->cols[jv].name : NULL;
  }
  s = tr->named ? dm_traj_alloc_state(tr->n, coords, tr->np,
                                      (tr->flags & DM_TRAJ_WITH_P) ? pn : NULL,
                                      (tr->flags & DM_TRAJ_WITH_V) ? vn : NULL, tr->flags, e)
                : dm_traj_alloc(tr->n, coords, tr->flags, e);
  free(coords);
  if (s == NULL)
    return NULL;
  for (c = tr->nstate; c < tr->ncols && st == DM_OK; c++)
    st = dm_traj_add_column(s, tr->cols[c].name, tr->cols[c].kind, NULL, 0, e);
  if (st == DM_OK)
    st = copy_meta(s, tr, e);
  if (st == DM_OK)
    st = dm_traj_reserve(s, count, e);
  if (st != DM_OK) {
    dm_traj_free(s);
    return NULL;
  }
  for (c = 0; c < tr->ncols; c++) {
    const double *src = tr->cols[c].x;
    double *dst = s->cols[c].x;
    for (k = 0; k < count; k++)
      dst[k] = src[i + k * stride];
  }
  s->len = count;
  return s;
}

/* }==== */
