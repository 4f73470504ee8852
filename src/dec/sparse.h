/* sparse.h -- compressed sparse row (CSR) matrices and the SuiteSparse solvers
 * behind them.
 *
 * dm_sparse is a plain CSR matrix: rowptr[nrows+1], col[nnz] (increasing in
 * each row, no duplicates) and val[nnz], 32-bit indices (nnz < 2^31).  It is
 * ours rather than cholmod_sparse so that operators live without a solver
 * context (no cholmod_common needed to hold or apply them), y = A x is a gather
 * loop, and integer matrices (boundary operators) stay plain data.  The CSR
 * arrays of A are, read column-wise, the CSC arrays of A^T: every SuiteSparse
 * call here works on such zero-copy views -- products, transposes and sums run
 * in CHOLMOD's MatrixOps, a symmetric matrix goes to CHOLMOD as it is, and
 * UMFPACK factors A^T and solves with its transpose option.
 *
 * Ownership: every dm_sparse * returned by a function here is new and freed
 * with dm_sparse_free (NULL is a no-op); the same for dm_sparse_chol and
 * dm_sparse_lu.  Inputs are never modified unless the name says so (_scale).
 *
 * Errors: functions returning a pointer return NULL on failure and fill the
 * dm_err (may be NULL) with DM_EINVAL (sizes), DM_ENOMEM, DM_ESINGULAR (a
 * factorization met a zero or negative pivot: the message names the column,
 * 1-based) or DM_EFAILED (a SuiteSparse status, named).  Nothing prints.
 *
 * Threads: a dm_sparse is read-only data after construction, usable from any
 * number of threads.  Each dm_sparse_chol / dm_sparse_lu carries its own
 * SuiteSparse workspace: one object per thread for concurrent solves.
 * dm_sparse_eigsh uses ARPACK, whose reverse-communication routines keep
 * static state: one call at a time per process.
 */
#ifndef DM_DEC_SPARSE_H
#define DM_DEC_SPARSE_H

#include "core/status.h"

typedef struct dm_sparse {
  int nrows, ncols;
  int *rowptr;      /* nrows + 1 */
  int *col;         /* rowptr[nrows] column indices, increasing in each row */
  double *val;      /* rowptr[nrows] values */
} dm_sparse;

/* A zero matrix with room for nnz entries (rowptr all 0, to be filled by the
 * caller in CSR order). */
dm_sparse *dm_sparse_alloc(int nrows, int ncols, int nnz, dm_err *e);
void dm_sparse_free(dm_sparse *A);
int dm_sparse_nnz(const dm_sparse *A);
dm_sparse *dm_sparse_copy(const dm_sparse *A, dm_err *e);

/* From nnz triplets (rows ri, columns ci, values v; 0-based); duplicates are
 * summed, explicit zeros kept.  Indices out of range give DM_EINVAL. */
dm_sparse *dm_sparse_from_triplets(int nrows, int ncols, int nnz, const int *ri,
                                   const int *ci, const double *v, dm_err *e);
/* diag(d) (n x n); d == NULL means the identity. */
dm_sparse *dm_sparse_diag(int n, const double *d, dm_err *e);

/* A^T, A B, alpha A + beta B (CHOLMOD MatrixOps on zero-copy views). */
dm_sparse *dm_sparse_transpose(const dm_sparse *A, dm_err *e);
dm_sparse *dm_sparse_mul(const dm_sparse *A, const dm_sparse *B, dm_err *e);
dm_sparse *dm_sparse_add(double alpha, const dm_sparse *A, double beta,
                         const dm_sparse *B, dm_err *e);
/* The same matrix without stored entries equal to zero (or below tol in
 * absolute value when tol > 0). */
dm_sparse *dm_sparse_drop(const dm_sparse *A, double tol, dm_err *e);
/* Rows (cols) whose keep flag is nonzero, renumbered in order; keep == NULL
 * keeps all. */
dm_sparse *dm_sparse_select(const dm_sparse *A, const unsigned char *keeprow,
                            const unsigned char *keepcol, dm_err *e);

/* A copy of the square matrix A whose flagged rows are identity rows. */
dm_sparse *dm_sparse_fix_rows(const dm_sparse *A, const unsigned char *fixed, dm_err *e);

/* In place: A <- diag(r) A diag(c) (either may be NULL). */
void dm_sparse_scale(dm_sparse *A, const double *r, const double *c);
/* y = A x (y has nrows entries, must not alias x); y = A^T x. */
void dm_sparse_gemv(const dm_sparse *A, const double *x, double *y);
void dm_sparse_gemv_t(const dm_sparse *A, const double *x, double *y);
/* Frobenius norm, largest |entry|, largest |A - A^T| (0 for symmetric). */
double dm_sparse_norm(const dm_sparse *A);
double dm_sparse_maxabs(const dm_sparse *A);
double dm_sparse_asymmetry(const dm_sparse *A);
/* Entry (i, j), 0 when not stored (binary search in row i). */
double dm_sparse_get(const dm_sparse *A, int i, int j);

/* {==== solvers ============================================================ */

/* Sparse Cholesky (CHOLMOD, supernodal where it pays, fill-reducing order):
 * S must be square and symmetric with both triangles stored (only the upper
 * one is read).  Factor once, solve many. */
typedef struct dm_sparse_chol dm_sparse_chol;
dm_sparse_chol *dm_sparse_chol_alloc(const dm_sparse *S, dm_err *e);
/* Solve S x = b for nrhs right-hand sides stored one after another (n each). */
int dm_sparse_chol_solve(dm_sparse_chol *F, int nrhs, const double *b, double *x,
                         dm_err *e);
/* Reciprocal condition estimate of the factor (CHOLMOD's (min/max diag)^2). */
double dm_sparse_chol_rcond(const dm_sparse_chol *F);
void dm_sparse_chol_free(dm_sparse_chol *F);

/* Sparse LU (UMFPACK) of a square matrix. */
typedef struct dm_sparse_lu dm_sparse_lu;
dm_sparse_lu *dm_sparse_lu_alloc(const dm_sparse *A, dm_err *e);
int dm_sparse_lu_solve(dm_sparse_lu *F, const double *b, double *x, dm_err *e);
void dm_sparse_lu_free(dm_sparse_lu *F);

/* The nev eigenpairs of K u = lambda diag(m) u with eigenvalues nearest to
 * sigma (K symmetric, m > 0): ARPACK in shift-invert mode (dsaupd mode 3) on a
 * CHOLMOD factor of K - sigma diag(m).  sigma must not be an eigenvalue; pick
 * it below the spectrum (e.g. -1e-3 times a typical diagonal entry of K
 * divided by m) to get the lowest ones.  Eigenvalues ascending into
 * lambda[nev], eigenvectors (m-orthonormal) column after column into
 * vec[n * nev] (may be NULL).  DM_ENOCONV when ARPACK does not converge in
 * maxit restarts (0: 300). */
int dm_sparse_eigsh(const dm_sparse *K, const double *m, int nev, double sigma,
                    int maxit, double *lambda, double *vec, dm_err *e);

/* }==== */

#endif
