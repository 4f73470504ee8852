/* multigrid.c -- geometric multigrid V-cycles on nested meshes
 * (doc/exterior-calculus.md §12): Galerkin coarse operators P^T A P, symmetric
 * Gauss-Seidel smoothing, CHOLMOD on the coarsest level.  Every work array
 * is allocated once by dm_dec_mg_alloc. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/interrupt.h"
#include "dec/dec.h"

struct dm_dec_mg {
  int nlev, nu, n, nfree;
  int *freeidx;
  dm_sparse **A, **P, **Pt;      /* A[l]; P[l]: level l+1 from level l */
  int **diag;                    /* position of the diagonal in each row of A[l] */
  double **x, **b, **r;          /* per level */
  dm_sparse_chol *coarse;
};

void dm_dec_mg_free(dm_dec_mg *M)
{
  int l;
  if (M == NULL)
    return;
  for (l = 0; l < M->nlev; l++) {
    if (M->A)
      dm_sparse_free(M->A[l]);
    if (M->P && l < M->nlev - 1) {
      dm_sparse_free(M->P[l]);
      dm_sparse_free(M->Pt[l]);
    }
    if (M->diag)
      free(M->diag[l]);
    if (M->x) {
      free(M->x[l]);
      free(M->b[l]);
      free(M->r[l]);
    }
  }
  free(M->A);
  free(M->P);
  free(M->Pt);
  free(M->diag);
  free(M->x);
  free(M->b);
  free(M->r);
  free(M->freeidx);
  dm_sparse_chol_free(M->coarse);
  free(M);
}

dm_dec_mg *dm_dec_mg_alloc(int nlev, dm_sparse *const *P, const dm_sparse *S,
                           const unsigned char *fixed, int nu, dm_err *e)
{
  dm_dec_mg *M;
  unsigned char *keep = NULL;
  int l, i;
  if (nlev < 1 || S->nrows != S->ncols || nu < 1) {
    dm_err_set(e, DM_EINVAL, "multigrid: %d levels, %d x %d matrix, %d sweeps", nlev, S->nrows,
               S->ncols, nu);
    return NULL;
  }
  M = calloc(1, sizeof *M);
  if (M == NULL)
    goto nomem;
  M->nlev = nlev;
  M->nu = nu;
  M->n = S->nrows;
  M->A = calloc((size_t)nlev, sizeof *M->A);
  M->P = calloc((size_t)nlev, sizeof *M->P);
  M->Pt = calloc((size_t)nlev, sizeof *M->Pt);
  M->diag = calloc((size_t)nlev, sizeof *M->diag);
  M->x = calloc((size_t)nlev, sizeof *M->x);
  M->b = calloc((size_t)nlev, sizeof *M->b);
  M->r = calloc((size_t)nlev, sizeof *M->r);
  M->freeidx = malloc(((size_t)M->n + 1) * sizeof *M->freeidx);
  keep = malloc((size_t)M->n + 1);
  if (!M->A || !M->P || !M->Pt || !M->diag || !M->x || !M->b || !M->r || !M->freeidx || !keep)
    goto nomem;
  for (i = 0; i < M->n; i++) {
    keep[i] = !(fixed != NULL && fixed[i]);
    if (keep[i])
      M->freeidx[M->nfree++] = i;
  }
  if ((M->A[nlev - 1] = dm_sparse_select(S, keep, keep, e)) == NULL)
    goto fail;
  for (l = nlev - 2; l >= 0; l--) {
    dm_sparse *AP;
    if (P[l]->nrows != (l == nlev - 2 ? M->n : M->A[l + 1]->nrows)) {
      dm_err_set(e, DM_EINVAL, "multigrid: prolongation %d has %d rows, level %d has %d unknowns", l + 1,
                 P[l]->nrows, l + 2, l == nlev - 2 ? M->n : M->A[l + 1]->nrows);
      goto fail;
    }
    M->P[l] = dm_sparse_select(P[l], l == nlev - 2 ? keep : NULL, NULL, e);
    if (M->P[l] == NULL || (M->Pt[l] = dm_sparse_transpose(M->P[l], e)) == NULL)
      goto fail;
    if ((AP = dm_sparse_mul(M->A[l + 1], M->P[l], e)) == NULL)
      goto fail;
    M->A[l] = dm_sparse_mul(M->Pt[l], AP, e);
    dm_sparse_free(AP);
    if (M->A[l] == NULL)
      goto fail;
  }
  for (l = 0; l < nlev; l++) {
    int nr = M->A[l]->nrows, p;
    M->diag[l] = malloc(((size_t)nr + 1) * sizeof *M->diag[l]);
    M->x[l] = calloc((size_t)nr + 1, sizeof(double));
    M->b[l] = calloc((size_t)nr + 1, sizeof(double));
    M->r[l] = calloc((size_t)nr + 1, sizeof(double));
    if (!M->diag[l] || !M->x[l] || !M->b[l] || !M->r[l])
      goto nomem;
    for (i = 0; i < nr; i++) {
      M->diag[l][i] = -1;
      for (p = M->A[l]->rowptr[i]; p < M->A[l]->rowptr[i + 1]; p++)
        if (M->A[l]->col[p] == i && M->A[l]->val[p] > 0)
          M->diag[l][i] = p;
      if (M->diag[l][i] < 0) {
        dm_err_set(e, DM_ESINGULAR, "multigrid: level %d, row %d has no positive diagonal", l + 1, i + 1);
        goto fail;
      }
    }
  }
  if ((M->coarse = dm_sparse_chol_alloc(M->A[0], e)) == NULL)
    goto fail;
  free(keep);
  return M;
nomem:
  dm_err_set(e, DM_ENOMEM, "multigrid: out of memory");
fail:
  free(keep);
  dm_dec_mg_free(M);
  return NULL;
}

static void gauss_seidel(const dm_sparse *A, const int *diag, const double *b, double *x, int backward)
{
  int n = A->nrows, i, p, s;
  for (s = 0; s < n; s++) {
    double acc;
    i = backward ? n - 1 - s : s;
    acc = b[i];
    for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
      if (p != diag[i])
        acc -= A->val[p] * x[A->col[p]];
    x[i] = acc / A->val[diag[i]];
  }
}

static int vcycle(dm_dec_mg *M, int l, dm_err *e)
{
  const dm_sparse *A = M->A[l];
  int s, i;
  if (l == 0)
    return dm_sparse_chol_solve(M->coarse, 1, M->b[0], M->x[0], e);
  for (s = 0; s < M->nu; s++) {
    gauss_seidel(A, M->diag[l], M->b[l], M->x[l], 0);
    gauss_seidel(A, M->diag[l], M->b[l], M->x[l], 1);
  }
  dm_sparse_gemv(A, M->x[l], M->r[l]);
  for (i = 0; i < A->nrows; i++)
    M->r[l][i] = M->b[l][i] - M->r[l][i];
  dm_sparse_gemv(M->Pt[l - 1], M->r[l], M->b[l - 1]);
  memset(M->x[l - 1], 0, (size_t)M->A[l - 1]->nrows * sizeof(double));
  if (vcycle(M, l - 1, e) != DM_OK)
    return e != NULL ? e->status : DM_EFAILED;
  dm_sparse_gemv(M->P[l - 1], M->x[l - 1], M->r[l]);
  for (i = 0; i < A->nrows; i++)
    M->x[l][i] += M->r[l][i];
  for (s = 0; s < M->nu; s++) {
    gauss_seidel(A, M->diag[l], M->b[l], M->x[l], 0);
    gauss_seidel(A, M->diag[l], M->b[l], M->x[l], 1);
  }
  return DM_OK;
}

int dm_dec_mg_vcycle(dm_dec_mg *M, const double *b, double *u, dm_err *e)
{
  int L = M->nlev - 1, a, st;
  for (a = 0; a < M->nfree; a++) {
    M->b[L][a] = b[M->freeidx[a]];
    M->x[L][a] = u[M->freeidx[a]];
  }
  if ((st = vcycle(M, L, e)) != DM_OK)
    return st;
  memset(u, 0, (size_t)M->n * sizeof *u);
  for (a = 0; a < M->nfree; a++)
    u[M->freeidx[a]] = M->x[L][a];
  return DM_OK;
}

int dm_dec_mg_solve(dm_dec_mg *M, const double *b, double *u, double tol, int maxit, int *iters,
                    dm_err *e)
{
  int L = M->nlev - 1, it, a, st;
  double bn = 0.0;
  for (a = 0; a < M->nfree; a++)
    bn += b[M->freeidx[a]] * b[M->freeidx[a]];
  bn = sqrt(bn);
  for (it = 0; it < maxit; it++) {
    double rn = 0.0;
    if ((st = dm_dec_mg_vcycle(M, b, u, e)) != DM_OK)
      return st;
    dm_sparse_gemv(M->A[L], M->x[L], M->r[L]);
    for (a = 0; a < M->nfree; a++) {
      double d = M->b[L][a] - M->r[L][a];
      rn += d * d;
    }
    if (sqrt(rn) <= tol * bn) {
      *iters = it + 1;
      return DM_OK;
    }
    if (dm_interrupted())
      return dm_err_set(e, DM_EINTR, "multigrid: interrupted after %d cycles", it + 1);
  }
  *iters = maxit;
  return dm_err_set(e, DM_ENOCONV, "multigrid: residual above %g after %d V-cycles", tol, maxit);
}
