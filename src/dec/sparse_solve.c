/* sparse_solve.c -- sparse direct solvers and a few eigenpairs:
 * CHOLMOD (symmetric positive definite), UMFPACK (general square) and ARPACK
 * shift-invert on a CHOLMOD factor (symmetric generalized, diagonal mass). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/cholmod.h>
#include <suitesparse/umfpack.h>
#include <arpack/arpack.h>

#include "core/interrupt.h"
#include "dec/sparse.h"
#include "dec/sparse_impl.h"

/* {==== CHOLMOD ============================================================== */

struct dm_sparse_chol {
  cholmod_common c;
  cholmod_factor *L;
  int n;
  double rcond;
};

/* Below this (min/max diag of L)^2 the matrix is singular to working
 * precision: a positive semidefinite matrix with a kernel (a Laplacian
 * without boundary conditions) factors with a round-off pivot near 1e-16. */
#define CHOL_RCOND_MIN 1e-13

void dm_sparse_chol_free(dm_sparse_chol *F)
{
  if (F == NULL)
    return;
  if (F->L != NULL)
    cholmod_free_factor(&F->L, &F->c);
  cholmod_finish(&F->c);
  free(F);
}

dm_sparse_chol *dm_sparse_chol_alloc(const dm_sparse *S, dm_err *e)
{
  dm_sparse_chol *F;
  cholmod_sparse v;
  if (S->nrows != S->ncols || S->nrows == 0) {
    dm_err_set(e, DM_EINVAL, "Cholesky: square non-empty matrix expected, got %d x %d",
               S->nrows, S->ncols);
    return NULL;
  }
  F = calloc(1, sizeof *F);
  if (F == NULL) {
    dm_err_set(e, DM_ENOMEM, "Cholesky: out of memory");
    return NULL;
  }
  F->n = S->nrows;
  dm_sparse__start(&F->c);
  F->c.final_ll = 1;                      /* LL': a non-positive pivot fails */
  v = dm_sparse__view_t(S, 1);            /* symmetric: upper triangle read */
  F->L = cholmod_analyze(&v, &F->c);
  if (F->L == NULL) {
    dm_err_set(e, F->c.status == CHOLMOD_OUT_OF_MEMORY ? DM_ENOMEM : DM_EFAILED,
               "Cholesky analysis of a %d x %d matrix: CHOLMOD status %d", F->n,
               F->n, F->c.status);
    goto fail;
  }
  cholmod_factorize(&v, F->L, &F->c);
  if (F->c.status == CHOLMOD_NOT_POSDEF) {
    size_t mi = F->L->minor;
    int col = (mi < F->L->n && F->L->Perm != NULL) ? ((int *)F->L->Perm)[mi] : (int)mi;
    dm_err_set(e, DM_ESINGULAR, "matrix not positive definite (at unknown %d of %d)",
               col + 1, F->n);
    goto fail;
  }
  if (F->c.status < CHOLMOD_OK) {
    dm_err_set(e, F->c.status == CHOLMOD_OUT_OF_MEMORY ? DM_ENOMEM : DM_EFAILED,
               "Cholesky factorization: CHOLMOD status %d", F->c.status);
    goto fail;
  }
  F->rcond = cholmod_rcond(F->L, &F->c);
  if (!(F->rcond >= CHOL_RCOND_MIN)) {
    dm_err_set(e, DM_ESINGULAR,
               "matrix singular to working precision (Cholesky rcond %.3g)", F->rcond);
    goto fail;
  }
  return F;
fail:
  dm_sparse_chol_free(F);
  return NULL;
}

double dm_sparse_chol_rcond(const dm_sparse_chol *F)
{
  return F->rcond;
}

int dm_sparse_chol_solve(dm_sparse_chol *F, int nrhs, const double *b, double *x,
                         dm_err *e)
{
  cholmod_dense B, *X;
  memset(&B, 0, sizeof B);
  B.nrow = (size_t)F->n;
  B.ncol = (size_t)nrhs;
  B.nzmax = B.nrow * B.ncol;
  B.d = B.nrow;
  B.x = (void *)b;
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  X = cholmod_solve(CHOLMOD_A, F->L, &B, &F->c);
  if (X == NULL)
    return dm_err_set(e, F->c.status == CHOLMOD_OUT_OF_MEMORY ? DM_ENOMEM : DM_EFAILED,
                      "Cholesky solve: CHOLMOD status %d", F->c.status);
  memcpy(x, X->x, B.nzmax * sizeof *x);
  cholmod_free_dense(&X, &F->c);
  return DM_OK;
}

/* }==== */

/* {==== UMFPACK =============================================================== */

struct dm_sparse_lu {
  int n;
  dm_sparse *At;          /* our copy of A; its CSR arrays are the CSC of A^T */
  void *numeric;
  double control[UMFPACK_CONTROL];
};

void dm_sparse_lu_free(dm_sparse_lu *F)
{
  if (F == NULL)
    return;
  if (F->numeric != NULL)
    umfpack_di_free_numeric(&F->numeric);
  dm_sparse_free(F->At);
  free(F);
}

dm_sparse_lu *dm_sparse_lu_alloc(const dm_sparse *A, dm_err *e)
{
  dm_sparse_lu *F;
  void *symbolic = NULL;
  double info[UMFPACK_INFO];
  int st;
  if (A->nrows != A->ncols || A->nrows == 0) {
    dm_err_set(e, DM_EINVAL, "LU: square non-empty matrix expected, got %d x %d",
               A->nrows, A->ncols);
    return NULL;
  }
  F = calloc(1, sizeof *F);
  if (F == NULL || (F->At = dm_sparse_copy(A, e)) == NULL) {
    free(F);
    dm_err_set(e, DM_ENOMEM, "LU: out of memory");
    return NULL;
  }
  F->n = A->nrows;
  umfpack_di_defaults(F->control);
  st = umfpack_di_symbolic(F->n, F->n, F->At->rowptr, F->At->col, F->At->val,
                           &symbolic, F->control, info);
  if (st == UMFPACK_OK)
    st = umfpack_di_numeric(F->At->rowptr, F->At->col, F->At->val, symbolic,
                            &F->numeric, F->control, info);
  if (symbolic != NULL)
    umfpack_di_free_symbolic(&symbolic);
  if (st == UMFPACK_WARNING_singular_matrix) {
    dm_err_set(e, DM_ESINGULAR, "matrix singular (UMFPACK found a zero pivot)");
    goto fail;
  }
  if (st != UMFPACK_OK) {
    dm_err_set(e, st == UMFPACK_ERROR_out_of_memory ? DM_ENOMEM : DM_EFAILED,
               "LU factorization: UMFPACK status %d", st);
    goto fail;
  }
  return F;
fail:
  dm_sparse_lu_free(F);
  return NULL;
}

int dm_sparse_lu_solve(dm_sparse_lu *F, const double *b, double *x, dm_err *e)
{
  double info[UMFPACK_INFO];
  int st = umfpack_di_solve(UMFPACK_At, F->At->rowptr, F->At->col, F->At->val, x,
                            b, F->numeric, F->control, info);
  if (st != UMFPACK_OK)
    return dm_err_set(e, DM_EFAILED, "LU solve: UMFPACK status %d", st);
  return DM_OK;
}

/* }==== */

/* {==== ARPACK shift-invert ===================================================== */

/* Sort eigenvalues ascending, moving the vectors along (nev is small). */
static void sort_pairs(int n, int nev, double *lambda, double *vec)
{
  int i, j, k;
  for (i = 1; i < nev; i++)
    for (j = i; j > 0 && lambda[j] < lambda[j - 1]; j--) {
      double t = lambda[j];
      lambda[j] = lambda[j - 1];
      lambda[j - 1] = t;
      if (vec != NULL)
        for (k = 0; k < n; k++) {
          t = vec[(size_t)j * n + k];
          vec[(size_t)j * n + k] = vec[(size_t)(j - 1) * n + k];
          vec[(size_t)(j - 1) * n + k] = t;
        }
    }
}

int dm_sparse_eigsh(const dm_sparse *K, const double *m, int nev, double sigma,
                    int maxit, double *lambda, double *vec, dm_err *e)
{
  int n = K->nrows, ncv, lworkl, ido = 0, info = 0, iparam[11], ipntr[14], i;
  int status = DM_OK, *select = NULL;
  double *resid = NULL, *v = NULL, *workd = NULL, *workl = NULL, *z = NULL, *tmp = NULL;
  dm_sparse *mdiag = NULL, *shifted = NULL;
  dm_sparse_chol *F = NULL;
  if (K->nrows != K->ncols || nev < 1 || nev >= n) {
    return dm_err_set(e, DM_EINVAL,
                      "eigenpairs: %d requested of a %d x %d matrix (1 <= nev < n)",
                      nev, K->nrows, K->ncols);
  }
  for (i = 0; i < n; i++)
    if (!(m[i] > 0))
      return dm_err_set(e, DM_EINVAL,
                        "eigenpairs: mass entry %d is %g (positive expected)", i + 1, m[i]);
  ncv = 2 * nev + 1 < 20 ? 20 : 2 * nev + 1;
  if (ncv > n)
    ncv = n;
  lworkl = ncv * (ncv + 8);
  mdiag = dm_sparse_diag(n, m, e);
  shifted = mdiag != NULL ? dm_sparse_add(1.0, K, -sigma, mdiag, e) : NULL;
  F = shifted != NULL ? dm_sparse_chol_alloc(shifted, e) : NULL;
  if (F == NULL) {
    status = e != NULL && e->status != DM_OK ? e->status : DM_EFAILED;
    goto done;
  }
  resid = malloc((size_t)n * sizeof *resid);
  v = malloc((size_t)n * ncv * sizeof *v);
  workd = malloc(3 * (size_t)n * sizeof *workd);
  workl = malloc((size_t)lworkl * sizeof *workl);
  z = malloc((size_t)n * nev * sizeof *z);
  tmp = malloc((size_t)n * sizeof *tmp);
  select = calloc((size_t)ncv, sizeof *select);
  if (!resid || !v || !workd || !workl || !z || !tmp || !select) {
    status = dm_err_set(e, DM_ENOMEM, "eigenpairs: out of memory");
    goto done;
  }
  memset(iparam, 0, sizeof iparam);
  memset(ipntr, 0, sizeof ipntr);
  iparam[0] = 1;                               /* exact shifts */
  iparam[2] = maxit > 0 ? maxit : 300;
  iparam[6] = 3;                               /* shift-invert */
  for (i = 0; i < n; i++)                      /* reproducible start vector */
    resid[i] = 1.0 + 0.5 * sin(2.385 * (i + 1));
  info = 1;
  for (;;) {
    dsaupd_c(&ido, "G", n, "LM", nev, 0.0, resid, ncv, v, n, iparam, ipntr, workd,
             workl, lworkl, &info);
    if (ido == -1 || ido == 1 || ido == 2) {
      double *x = workd + ipntr[0] - 1, *y = workd + ipntr[1] - 1;
      if (ido == 2) {
        for (i = 0; i < n; i++)
          y[i] = m[i] * x[i];
        continue;
      }
      if (ido == 1)
        memcpy(tmp, workd + ipntr[2] - 1, (size_t)n * sizeof *tmp);
      else
        for (i = 0; i < n; i++)
          tmp[i] = m[i] * x[i];
      if ((status = dm_sparse_chol_solve(F, 1, tmp, y, e)) != DM_OK)
        goto done;
      if (dm_interrupted()) {
        status = dm_err_set(e, DM_EINTR, "eigenpairs: interrupted");
        goto done;
      }
      continue;
    }
    break;
  }
  if (info == 1) {
    status = dm_err_set(e, DM_ENOCONV,
                        "eigenpairs: ARPACK did not converge in %d restarts (%d of %d converged)",
                        iparam[2], iparam[4], nev);
    goto done;
  }
  if (info < 0) {
    status = dm_err_set(e, DM_EFAILED, "eigenpairs: ARPACK dsaupd error %d", info);
    goto done;
  }
  dseupd_c(1, "A", select, lambda, z, n, sigma, "G", n, "LM", nev, 0.0, resid, ncv,
           v, n, iparam, ipntr, workd, workl, lworkl, &info);
  if (info != 0) {
    status = dm_err_set(e, DM_EFAILED, "eigenpairs: ARPACK dseupd error %d", info);
    goto done;
  }
  sort_pairs(n, nev, lambda, z);
  if (vec != NULL)
    memcpy(vec, z, (size_t)n * nev * sizeof *vec);
done:
  dm_sparse_chol_free(F);
  dm_sparse_free(shifted);
  dm_sparse_free(mdiag);
  free(resid);
  free(v);
  free(workd);
  free(workl);
  free(z);
  free(tmp);
  free(select);
  return status;
}

/* }==== */
