/* trajectory_columns.c -- the extra columns of a trajectory (diagnostics,
 * derived columns, data): adding, replacing, removing, and deriving them
 * by a function of every sample.  See trajectory.h. */
#include <config.h>
#include "core/trajectory_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/interrupt.h"

/* {==== extra columns ===================================================== */

static int check_extra_kind(int kind, dm_err *e)
{
  if (kind != DM_TRAJ_DIAG && kind != DM_TRAJ_DERIVED && kind != DM_TRAJ_DATA)
    return dm_err_set(e, DM_EINVAL, "extra column kind must be diag, derived "
                      "or data (got %d)", kind);
  return DM_OK;
}

/* Check `m` new column names; slot[a] receives the index of the extra
 * column a replaces, or DM_TRAJ_NONE for a new one. */
static int check_new_names(const dm_traj *tr, size_t m, const char *const *names,
                           unsigned opts, size_t *slot, dm_err *e)
{
  size_t a, b;
  for (a = 0; a < m; a++) {
    size_t j;
    if (!dm_traj__valid_name(names[a]))
      return dm_traj__bad_name(e, "column", names[a]);
    for (b = 0; b < a; b++)
      if (strcmp(names[a], names[b]) == 0)
        return dm_err_set(e, DM_EINVAL, "column name '%s' is used twice",
                          names[a]);
    j = dm_traj_find(tr, names[a]);
    if (j != DM_TRAJ_NONE && j < tr->nstate)
      return dm_err_set(e, DM_EINVAL, "column '%s' is a %s column and cannot "
                        "be replaced", names[a],
                        dm_traj_kindname(tr->cols[j].kind));
    if (j != DM_TRAJ_NONE && !(opts & DM_TRAJ_REPLACE))
      return dm_err_set(e, DM_EINVAL, "column '%s' exists", names[a]);
    slot[a] = j;
  }
  return DM_OK;
}

/* Install m filled arrays (xs[a] has tr->cap values): replace or append.
 * Cannot fail: the column array has room (reserved by the caller). */
static void install(dm_traj *tr, size_t m, char **names, int kind,
                    double **xs, const size_t *slot)
{
  size_t a;
  for (a = 0; a < m; a++) {
    column *c;
    if (slot[a] != DM_TRAJ_NONE) {
      c = &tr->cols[slot[a]];
      free(c->name);
      free(c->x);
    } else {
      c = &tr->cols[tr->ncols++];
    }
    c->name = names[a];
    c->kind = kind;
    c->x = xs[a];
    names[a] = NULL;
    xs[a] = NULL;
    if (slot[a] == DM_TRAJ_NONE)
      dm_traj__index_added(tr, tr->ncols - 1);
  }
}

/* Allocate what m new columns need: column slots, names, arrays of cap. */
static int prepare(dm_traj *tr, size_t m, const char *const *names,
                   char **dn, double **xs, dm_err *e)
{
  size_t a;
  if (tr->ncols + m > tr->colcap) {
    size_t nc = tr->ncols + m + tr->ncols / 2 + 8;      /* geometric */
    column *c = realloc(tr->cols, nc * sizeof *c);
    if (c == NULL)
      return dm_err_set(e, DM_ENOMEM, "trajectory: out of memory for columns");
    tr->cols = c;
    tr->colcap = nc;
  }
  for (a = 0; a < m; a++) {
    dn[a] = dm_traj__dupstr(names[a]);
    xs[a] = tr->cap > 0 ? malloc(tr->cap * sizeof(double)) : NULL;
    if (dn[a] == NULL || (tr->cap > 0 && xs[a] == NULL))
      return dm_err_set(e, DM_ENOMEM, "trajectory: out of memory for column "
                        "'%s' (%zu samples)", names[a], tr->len);
  }
  return DM_OK;
}

static void release(size_t m, char **dn, double **xs)
{
  size_t a;
  for (a = 0; a < m; a++) {
    free(dn[a]);
    free(xs[a]);
  }
}

int dm_traj_add_column(dm_traj *tr, const char *name, int kind,
                       const double *values, unsigned opts, dm_err *e)
{
  size_t slot, k;
  char *dn = NULL;
  double *x = NULL;
  int st;
  if ((st = check_extra_kind(kind, e)) != DM_OK
      || (st = check_new_names(tr, 1, &name, opts, &slot, e)) != DM_OK)
    return st;
  if ((st = prepare(tr, 1, &name, &dn, &x, e)) != DM_OK) {
    release(1, &dn, &x);
    return st;
  }
  for (k = 0; k < tr->len; k++)
    x[k] = values != NULL ? values[k] : NAN;
  install(tr, 1, &dn, kind, &x, &slot);
  return DM_OK;
}

int dm_traj_remove_column(dm_traj *tr, const char *name, dm_err *e)
{
  size_t j = 0;
  int st = dm_traj_lookup(tr, name, &j, e);
  if (st != DM_OK)
    return st;
  if (j < tr->nstate)
    return dm_err_set(e, DM_EINVAL, "column '%s' is a %s column and cannot be "
                      "removed", name, dm_traj_kindname(tr->cols[j].kind));
  free(tr->cols[j].name);
  free(tr->cols[j].x);
  memmove(&tr->cols[j], &tr->cols[j + 1], (tr->ncols - j - 1) * sizeof *tr->cols);
  tr->ncols--;
  dm_traj__index_rebuild(tr);
  return DM_OK;
}

/* Evaluate fn over every sample into xs (m arrays). */
static int derive_fill(const dm_traj *tr, size_t m, dm_traj_fn fn, void *ctx,
                       double *row, double *out, double **xs, dm_err *e)
{
  dm_traj_sample s;
  size_t k, a, n = tr->n;
  s.n = n;
  s.np = tr->np;
  s.row = row;
  s.q = row + 1;
  s.p = (tr->flags & DM_TRAJ_WITH_P) ? row + 1 + n : NULL;
  s.v = (tr->flags & DM_TRAJ_WITH_V) ? row + tr->nstate - tr->np : NULL;
  s.extra = row + tr->nstate;
  s.traj = tr;
  for (k = 0; k < tr->len; k++) {
    int rc;
    if (dm_interrupted())
      return dm_err_set(e, DM_EINTR, "derive: interrupted at sample %zu of %zu",
                        k, tr->len);
    dm_traj_row(tr, k, row, NULL);
    s.k = k;
    s.t = row[0];
    rc = fn(ctx, &s, out);
    if (rc != 0)
      return dm_err_set(e, DM_ECALLBACK, "derive: callback failed at sample "
                        "%zu (t = %.17g) with status %d", k, s.t, rc);
    for (a = 0; a < m; a++)
      xs[a][k] = out[a];
  }
  return DM_OK;
}

int dm_traj_derive(dm_traj *tr, size_t m, const char *const *names, int kind,
                   dm_traj_fn fn, void *ctx, unsigned opts, dm_err *e)
{
  size_t *slot = NULL;
  char **dn = NULL;
  double **xs = NULL, *row = NULL;
  int st;
  if (m == 0 || names == NULL || fn == NULL)
    return dm_err_set(e, DM_EINVAL, "derive: need at least one column name "
                      "and a function");
  if ((st = check_extra_kind(kind, e)) != DM_OK)
    return st;
  slot = malloc(m * sizeof *slot);
  dn = calloc(m, sizeof *dn);
  xs = calloc(m, sizeof *xs);
  row = malloc((tr->ncols + m) * sizeof *row);
  if (slot == NULL || dn == NULL || xs == NULL || row == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "derive: out of memory");
    goto cleanup;
  }
  if ((st = check_new_names(tr, m, names, opts, slot, e)) != DM_OK
      || (st = prepare(tr, m, names, dn, xs, e)) != DM_OK
      || (st = derive_fill(tr, m, fn, ctx, row, row + tr->ncols, xs, e)) != DM_OK)
    goto cleanup;
  install(tr, m, dn, kind, xs, slot);
cleanup:
  if (dn != NULL && xs != NULL)
    release(m, dn, xs);
  free(slot);
  free(dn);
  free(xs);
  free(row);
  return st;
}

/* }==== */
