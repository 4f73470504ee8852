/* lagrangian_check.c -- the checks of a Lagrangian system's description
 * before anything is derived: coordinates and velocities are distinct
 * symbols, and L, the force and the constraints depend only on what they
 * may (the constraints on coordinates and parameters).  See lagrangian.h. */
#include <config.h>
#include "expr/lagrangian_impl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_expr(const void *a, const void *b)
{
  dm_expr x = *(const dm_expr *)a, y = *(const dm_expr *)b;
  return (x > y) - (x < y);
}

static int cmp_pair(const void *a, const void *b)
{
  const dm_expr *x = a, *y = b;
  if (x[0] != y[0])
    return (x[0] > y[0]) - (x[0] < y[0]);
  return (x[1] > y[1]) - (x[1] < y[1]);
}

static int member(dm_expr x, size_t n, const dm_expr *sorted)
{
  return n > 0 && bsearch(&x, sorted, n, sizeof x, cmp_expr) != NULL;
}

/* Every symbol or parameter in e must be one of allowed[0..na) (sorted);
 * vel (sorted, nv, may be NULL) names the velocities for the message. */
static int check_vars(lag_builder *b, dm_expr e, const char *what, size_t na,
                      const dm_expr *allowed, size_t nv, const dm_expr *vel)
{
  dm_expr fv1[64], *fv = fv1;
  long k = dm_expr_free_vars(b->ctx, e, NULL, 0);
  if (k < 0 && dm_expr_ctx_err(b->ctx)->status == DM_ENOMEM)
    return dm_lag__ctx_fail(b, what);
  if (k < 0)
    return dm_err_set(b->err, DM_EINVAL, "%s is not a valid expression", what);
  if (k > 64 && (fv = malloc((size_t)k * sizeof *fv)) == NULL)
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  dm_expr_free_vars(b->ctx, e, fv, (size_t)k);
  int s = DM_OK;
  for (long i = 0; i < k && s == DM_OK; i++) {
    if (member(fv[i], na, allowed))
      continue;
    if (vel != NULL && member(fv[i], nv, vel))
      s = dm_err_set(b->err, DM_EINVAL, "%s depends on the velocity "
                     "'%s'", what, dm_expr_name(b->ctx, fv[i]));
    else
      s = dm_err_set(b->err, DM_EINVAL, "%s depends on %s '%s', which is "
                     "not a coordinate, velocity or parameter", what,
                     dm_expr_kind(b->ctx, fv[i]) == DM_EXPR_SYM ? "symbol"
                     : "parameter", dm_expr_name(b->ctx, fv[i]));
  }
  if (fv != fv1)
    free(fv);
  return s;
}

/* The smallest i such that x[i] is among x[0..i), -1 if none, -2 out of
 * memory. */
static long first_repeat(const dm_expr *x, size_t n)
{
  dm_expr (*t)[2] = malloc((n ? n : 1) * sizeof *t);
  if (t == NULL)
    return -2;
  for (size_t i = 0; i < n; i++) {
    t[i][0] = x[i];
    t[i][1] = (dm_expr)i;
  }
  qsort(t, n, sizeof *t, cmp_pair);
  long best = -1;
  for (size_t i = 1; i < n; i++)       /* within a group, indices ascend */
    if (t[i][0] == t[i - 1][0] && (i < 2 || t[i - 2][0] != t[i][0]) &&
        (best < 0 || t[i][1] < best))
      best = t[i][1];
  free(t);
  return best;
}

int dm_lag__check_spec(lag_builder *b)
{
  const dm_lagrangian_spec *sp = b->sp;
  size_t n = sp->n, na = 2 * n + sp->npar;
  char what[64];
  if (n == 0 || !sp->q || !sp->v || (sp->npar && !sp->par) ||
      (sp->m && !sp->constraints))
    return dm_err_set(b->err, DM_EINVAL, "a system needs n >= 1 coordinates, "
                      "their velocities and the listed parameters");
  for (size_t i = 0; i < 2 * n; i++)
    if (dm_expr_kind(b->ctx, b->in[i]) != DM_EXPR_SYM)
      return dm_err_set(b->err, DM_EINVAL, "%s %zu is not a symbol",
                        i < n ? "coordinate" : "velocity", i % n + 1);
  long dup = first_repeat(b->in, 2 * n);
  if (dup == -2)
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  if (dup >= 0)
    return dm_err_set(b->err, DM_EINVAL, "'%s' is listed twice among the "
                      "coordinates and velocities", dm_expr_name(b->ctx, b->in[dup]));
  dm_expr *allowed = malloc(na * sizeof *allowed), *vel = malloc(n * sizeof *vel);
  if (allowed == NULL || vel == NULL) {
    free(allowed);
    free(vel);
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  }
  memcpy(allowed, b->in, 2 * n * sizeof *allowed);
  if (sp->npar)
    memcpy(allowed + 2 * n, sp->par, sp->npar * sizeof *allowed);
  qsort(allowed, na, sizeof *allowed, cmp_expr);
  int s = check_vars(b, sp->L, "L", na, allowed, 0, NULL);
  for (size_t i = 0; s == DM_OK && sp->force && i < n; i++) {
    snprintf(what, sizeof what, "force component %zu", i + 1);
    s = check_vars(b, sp->force[i], what, na, allowed, 0, NULL);
  }
  /* constraints: coordinates and parameters only */
  memcpy(allowed, sp->q, n * sizeof *allowed);
  if (sp->npar)
    memcpy(allowed + n, sp->par, sp->npar * sizeof *allowed);
  qsort(allowed, n + sp->npar, sizeof *allowed, cmp_expr);
  memcpy(vel, sp->v, n * sizeof *vel);
  qsort(vel, n, sizeof *vel, cmp_expr);
  for (size_t a = 0; s == DM_OK && a < sp->m; a++) {
    snprintf(what, sizeof what, "constraint %zu", a + 1);
    s = check_vars(b, sp->constraints[a], what, n + sp->npar, allowed, n, vel);
  }
  free(allowed);
  free(vel);
  return s;
}
