/* curve.c -- shape paths s -> x(s) given as expressions, compiled with
 * their exact derivative, for transport and holonomy along curves. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conn/conn_impl.h"

struct dm_conn_curve {
  dm_tape *t;                   /* in: s; out: x (nx), dx/ds (nx) */
  size_t nx;
  double *work, *out;
};

dm_conn_curve *dm_conn_curve_alloc(dm_expr_ctx *ctx, dm_expr s, size_t nx, const dm_expr *x,
                                   dm_err *e)
{
  dm_conn_curve *c = calloc(1, sizeof *c);
  dm_expr *out = malloc((2 * nx + 1) * sizeof *out);
  size_t i;
  if (c == NULL || out == NULL) {
    free(c);
    free(out);
    dm_err_set(e, DM_ENOMEM, "curve: out of memory");
    return NULL;
  }
  c->nx = nx;
  for (i = 0; i < nx; i++) {
    out[i] = x[i];
    out[nx + i] = dm_expr_diff(ctx, x[i], s);
  }
  if (dm_tape_compile(ctx, 2 * nx, out, 1, &s, 0, NULL, &c->t, e) != DM_OK) {
    free(out);
    free(c);
    return NULL;
  }
  free(out);
  if ((c->work = malloc((dm_tape_work_size(c->t) + 2 * nx + 1) * sizeof *c->work)) == NULL) {
    dm_conn_curve_free(c);
    dm_err_set(e, DM_ENOMEM, "curve: out of memory");
    return NULL;
  }
  c->out = c->work + dm_tape_work_size(c->t);
  return c;
}

void dm_conn_curve_free(dm_conn_curve *c)
{
  if (c == NULL)
    return;
  dm_tape_free(c->t);
  free(c->work);
  free(c);
}

int dm_conn_curve_eval(void *ud, double s, double *x, double *dx, dm_err *e)
{
  dm_conn_curve *c = ud;
  size_t i;
  dm_tape_eval(c->t, &s, NULL, c->out, c->work);
  for (i = 0; i < 2 * c->nx; i++)
    if (!isfinite(c->out[i]))
      return dm_err_set(e, DM_EDOM, "curve: x(s) or x'(s) is not finite at s = %g", s);
  memcpy(x, c->out, c->nx * sizeof *x);
  memcpy(dx, c->out + c->nx, c->nx * sizeof *dx);
  return DM_OK;
}
