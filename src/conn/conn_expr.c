/* conn_expr.c -- continuous connections from expressions: A_loc(x) given,
 * or the mechanical connection A = I^-1 C of a locked inertia I and a
 * coupling C (or of a reduced Lagrangian l(x, xdot, xi)), built
 * symbolically; A and its exact derivatives are compiled to tapes
 * (doc/bundles-connections-holonomy.md §3). */
#include <config.h>
#include <stdlib.h>
#include <string.h>

#include "conn/conn_impl.h"
#include "expr/native.h"

void dm_conn__expr_free(void *ud)
{
  conn_expr *c = ud;
  if (c == NULL)
    return;
  dm_native_free(c->nat);
  dm_tape_free(c->tA);
  dm_tape_free(c->tdA);
  free(c->par);
  free(c->work);
  free(c);
}

int dm_conn__expr_eval(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  conn_expr *c = ud;
  (void)e;
  if (dA == NULL) {
    if (c->fA)
      c->fA(x, c->par, A);
    else
      dm_tape_eval(c->tA, x, c->par, A, c->work);
    return DM_OK;
  }
  /* the second tape computes A then dA */
  dm_tape_eval(c->tdA, x, c->par, c->out, c->work);
  memcpy(A, c->out, c->nA * sizeof *A);
  memcpy(dA, c->out + c->nA, (dm_tape_nout(c->tdA) - c->nA) * sizeof *dA);
  return DM_OK;
}

/* {==== A given ============================================================= */

dm_conn *dm_conn_expr_alloc(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *x,
                            const dm_expr *A, size_t npar, const dm_expr *par,
                            const double *parval, dm_err *e)
{
  conn_expr *c;
  dm_conn *C;
  dm_expr *out = NULL, *J;
  size_t dim, nx, nA, k, i, a, ws;
  int st;
  if (B == NULL || !dm_conn_bundle_is_trivial(B)) {
    dm_err_set(e, DM_EUNSUP, "connection: a local connection form needs a trivial bundle S x G");
    return NULL;
  }
  dim = B->G->dim;
  nx = B->nx;
  nA = dim * nx;
  if ((c = calloc(1, sizeof *c)) == NULL ||
      (out = malloc((nA + nx * nA + 1) * sizeof *out)) == NULL ||
      (c->par = calloc(npar + 1, sizeof *c->par)) == NULL) {
    dm_conn__expr_free(c);
    dm_err_set(e, DM_ENOMEM, "connection: out of memory");
    free(out);
    return NULL;
  }
  c->nA = nA;
  c->npar = npar;
  if (npar)
    memcpy(c->par, parval, npar * sizeof *parval);
  memcpy(out, A, nA * sizeof *A);
  /* out[nA + (k dim + a) nx + i] = d A_ai / d x_k: the Jacobian J[(a nx + i) nx + k] */
  J = out + nA;
  if (nx > 0) {
    dm_expr *Jt = malloc(nA * nx * sizeof *Jt);
    if (Jt == NULL) {
      st = dm_err_set(e, DM_ENOMEM, "connection: out of memory");
      goto fail;
    }
    if ((st = dm_expr_jacobian(ctx, nA, A, nx, x, Jt, e)) != DM_OK) {
      free(Jt);
      goto fail;
    }
    for (k = 0; k < nx; k++)
      for (a = 0; a < dim; a++)
        for (i = 0; i < nx; i++)
          J[(k * dim + a) * nx + i] = Jt[(a * nx + i) * nx + k];
    free(Jt);
  }
  if ((st = dm_tape_compile(ctx, nA, out, nx, x, npar, par, &c->tA, e)) != DM_OK ||
      (st = dm_tape_compile(ctx, nA + nx * nA, out, nx, x, npar, par, &c->tdA, e)) != DM_OK)
    goto fail;
  ws = dm_tape_work_size(c->tA);
  if (dm_tape_work_size(c->tdA) > ws)
    ws = dm_tape_work_size(c->tdA);
  if ((c->work = malloc((ws + nA + nx * nA + 1) * sizeof *c->work)) == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "connection: out of memory");
    goto fail;
  }
  c->out = c->work + ws;
  free(out);
  if ((C = dm_conn_alloc(B, dm_conn__expr_eval, c, 1, dm_conn__expr_free, e)) == NULL) {
    dm_conn__expr_free(c);
    return NULL;
  }
  C->expr = 1;
  return C;
fail:
  (void)st;
  free(out);
  dm_conn__expr_free(c);
  return NULL;
}

int dm_conn_native(dm_conn *C, const double *x0, dm_err *e)
{
  conn_expr *c;
  int st;
  if (!C->expr)
    return dm_err_set(e, DM_EINVAL, "connection: not made from expressions (nothing to compile)");
  c = C->ud;
  if (c->fA != NULL)
    return DM_OK;
  if ((st = dm_native_compile(c->tA, x0, c->par, &c->nat, e)) != DM_OK)
    return st;
  c->fA = dm_native_function(c->nat);
  return DM_OK;
}

int dm_conn_set_params(dm_conn *C, const double *parval, dm_err *e)
{
  conn_expr *c;
  if (!C->expr)
    return dm_err_set(e, DM_EINVAL, "connection: no parameters (not made from expressions)");
  c = C->ud;
  if (c->npar)
    memcpy(c->par, parval, c->npar * sizeof *parval);
  return DM_OK;
}

/* }==== */

/* {==== mechanical: A = I^-1 C ============================================= */

/* Solve I X = Cm for X (n x n, n x m nodes) by Gaussian elimination
 * without pivoting (I symmetric positive definite: every pivot is a
 * positive Schur complement). */
static int sym_solve(dm_expr_ctx *ctx, size_t n, const dm_expr *I, size_t m, const dm_expr *Cm,
                     dm_expr *X, dm_err *e)
{
  dm_expr *a = malloc((n * n + n * m + 1) * sizeof *a), *b;
  size_t i, j, k;
  const dm_err *ce;
  if (a == NULL)
    return dm_err_set(e, DM_ENOMEM, "mechanical connection: out of memory");
  b = a + n * n;
  memcpy(a, I, n * n * sizeof *I);
  memcpy(b, Cm, n * m * sizeof *Cm);
  for (k = 0; k < n; k++)
    for (i = k + 1; i < n; i++) {
      dm_expr f = dm_expr_div(ctx, a[i * n + k], a[k * n + k]);
      for (j = k + 1; j < n; j++)
        a[i * n + j] = dm_expr_sub(ctx, a[i * n + j], dm_expr_mul(ctx, f, a[k * n + j]));
      for (j = 0; j < m; j++)
        b[i * m + j] = dm_expr_sub(ctx, b[i * m + j], dm_expr_mul(ctx, f, b[k * m + j]));
    }
  for (k = n; k-- > 0;)
    for (j = 0; j < m; j++) {
      dm_expr s = b[k * m + j];
      for (i = k + 1; i < n; i++)
        s = dm_expr_sub(ctx, s, dm_expr_mul(ctx, a[k * n + i], X[i * m + j]));
      X[k * m + j] = dm_expr_div(ctx, s, a[k * n + k]);
    }
  free(a);
  ce = dm_expr_ctx_err(ctx);
  if (ce->status != DM_OK)
    return dm_err_set(e, ce->status, "mechanical connection: %s", ce->msg);
  return DM_OK;
}

dm_conn *dm_conn_mech_alloc(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *x,
                            const dm_expr *I, const dm_expr *Cm, size_t npar,
                            const dm_expr *par, const double *parval, dm_expr *Aout,
                            dm_err *e)
{
  dm_expr *A;
  dm_conn *C;
  size_t dim, nx;
  if (B == NULL || !dm_conn_bundle_is_trivial(B)) {
    dm_err_set(e, DM_EUNSUP, "mechanical connection: needs a trivial bundle S x G");
    return NULL;
  }
  dim = B->G->dim;
  nx = B->nx;
  if ((A = malloc((dim * nx + 1) * sizeof *A)) == NULL) {
    dm_err_set(e, DM_ENOMEM, "mechanical connection: out of memory");
    return NULL;
  }
  if (sym_solve(ctx, dim, I, nx, Cm, A, e) != DM_OK) {
    free(A);
    return NULL;
  }
  C = dm_conn_expr_alloc(ctx, B, x, A, npar, par, parval, e);
  if (C != NULL && Aout != NULL)
    memcpy(Aout, A, dim * nx * sizeof *A);
  free(A);
  return C;
}

dm_conn *dm_conn_lagrangian_alloc(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *x,
                                  const dm_expr *xdot, const dm_expr *xi, dm_expr l,
                                  size_t npar, const dm_expr *par, const double *parval,
                                  dm_expr *Aout, dm_err *e)
{
  size_t dim, nx, a, b, i;
  dm_expr *I = NULL, *Cm, *g = NULL, *vel = NULL;
  dm_conn *C = NULL;
  int st;
  if (B == NULL || !dm_conn_bundle_is_trivial(B)) {
    dm_err_set(e, DM_EUNSUP, "mechanical connection: needs a trivial bundle S x G");
    return NULL;
  }
  dim = B->G->dim;
  nx = B->nx;
  if ((I = malloc((dim * dim + dim * nx + dim + 2 * (dim + nx) + 1) * sizeof *I)) == NULL) {
    dm_err_set(e, DM_ENOMEM, "mechanical connection: out of memory");
    return NULL;
  }
  Cm = I + dim * dim;
  g = Cm + dim * nx;
  vel = g + dim;
  /* dl/dxi, then its derivatives in xi (I) and xdot (C) */
  if ((st = dm_expr_grad(ctx, l, dim, xi, g, e)) != DM_OK)
    goto done;
  for (a = 0; a < dim; a++) {
    for (b = 0; b < dim; b++)
      I[a * dim + b] = dm_expr_diff(ctx, g[a], xi[b]);
    for (i = 0; i < nx; i++)
      Cm[a * nx + i] = dm_expr_diff(ctx, g[a], xdot[i]);
  }
  memcpy(vel, xdot, nx * sizeof *vel);
  memcpy(vel + nx, xi, dim * sizeof *vel);
  for (a = 0; a < dim * dim + dim * nx; a++)
    if (dm_expr_depends(ctx, I[a], nx + dim, vel)) {
      dm_err_set(e, DM_EINVAL, "mechanical connection: the Lagrangian is not quadratic in the "
                 "velocities (its %s depends on them), so it has no locked inertia",
                 a < dim * dim ? "d2l/dxi2" : "d2l/dxi dxdot");
      goto done;
    }
  C = dm_conn_mech_alloc(ctx, B, x, I, Cm, npar, par, parval, Aout, e);
done:
  free(I);
  return C;
}

/* }==== */
