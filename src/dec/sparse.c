/* sparse.c -- the CSR type: construction, CHOLMOD MatrixOps on zero-copy
 * views, row/column scaling, products with vectors, norms. */
#include <config.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/cholmod.h>

#include "dec/sparse.h"
#include "dec/sparse_impl.h"

dm_sparse *dm_sparse_alloc(int nrows, int ncols, int nnz, dm_err *e)
{
  dm_sparse *A;
  if (nrows < 0 || ncols < 0 || nnz < 0) {
    dm_err_set(e, DM_EINVAL, "sparse matrix: negative size %d x %d (%d entries)",
               nrows, ncols, nnz);
    return NULL;
  }
  A = calloc(1, sizeof *A);
  if (A == NULL)
    goto nomem;
  A->nrows = nrows;
  A->ncols = ncols;
  A->rowptr = calloc((size_t)nrows + 1, sizeof *A->rowptr);
  A->col = malloc(((size_t)nnz + 1) * sizeof *A->col);
  A->val = malloc(((size_t)nnz + 1) * sizeof *A->val);
  if (A->rowptr == NULL || A->col == NULL || A->val == NULL)
    goto nomem;
  return A;
nomem:
  dm_sparse_free(A);
  dm_err_set(e, DM_ENOMEM, "sparse matrix %d x %d with %d entries: out of memory",
             nrows, ncols, nnz);
  return NULL;
}

void dm_sparse_free(dm_sparse *A)
{
  if (A == NULL)
    return;
  free(A->rowptr);
  free(A->col);
  free(A->val);
  free(A);
}

int dm_sparse_nnz(const dm_sparse *A)
{
  return A->rowptr[A->nrows];
}

dm_sparse *dm_sparse_copy(const dm_sparse *A, dm_err *e)
{
  int nnz = dm_sparse_nnz(A);
  dm_sparse *B = dm_sparse_alloc(A->nrows, A->ncols, nnz, e);
  if (B == NULL)
    return NULL;
  memcpy(B->rowptr, A->rowptr, ((size_t)A->nrows + 1) * sizeof *B->rowptr);
  memcpy(B->col, A->col, (size_t)nnz * sizeof *B->col);
  memcpy(B->val, A->val, (size_t)nnz * sizeof *B->val);
  return B;
}

/* Two stable counting sorts (by column, then by row) leave every row's
 * columns increasing; duplicates are then adjacent and summed. */
dm_sparse *dm_sparse_from_triplets(int nrows, int ncols, int nnz, const int *ri,
                                   const int *ci, const double *v, dm_err *e)
{
  int *cptr = NULL, *perm = NULL, *cnt = NULL, k, i, out;
  dm_sparse *A = NULL;
  for (k = 0; k < nnz; k++)
    if (ri[k] < 0 || ri[k] >= nrows || ci[k] < 0 || ci[k] >= ncols) {
      dm_err_set(e, DM_EINVAL, "sparse triplet %d: index (%d, %d) outside %d x %d",
                 k + 1, ri[k] + 1, ci[k] + 1, nrows, ncols);
      return NULL;
    }
  A = dm_sparse_alloc(nrows, ncols, nnz, e);
  cptr = calloc((size_t)ncols + 1, sizeof *cptr);
  perm = malloc(((size_t)nnz + 1) * sizeof *perm);
  cnt = calloc((size_t)nrows + 1, sizeof *cnt);
  if (A == NULL || cptr == NULL || perm == NULL || cnt == NULL) {
    dm_sparse_free(A);
    A = NULL;
    dm_err_set(e, DM_ENOMEM, "sparse matrix from %d triplets: out of memory", nnz);
    goto done;
  }
  for (k = 0; k < nnz; k++)
    cptr[ci[k] + 1]++;
  for (k = 0; k < ncols; k++)
    cptr[k + 1] += cptr[k];
  for (k = 0; k < nnz; k++)
    perm[cptr[ci[k]]++] = k;                   /* by column, stable */
  for (k = 0; k < nnz; k++)
    A->rowptr[ri[k] + 1]++;
  for (i = 0; i < nrows; i++)
    A->rowptr[i + 1] += A->rowptr[i];
  for (k = 0; k < nnz; k++) {                  /* by row, stable */
    int t = perm[k], r = ri[t], p = A->rowptr[r] + cnt[r]++;
    A->col[p] = ci[t];
    A->val[p] = v[t];
  }
  out = 0;                                     /* sum duplicates */
  for (i = 0; i < nrows; i++) {
    int p = A->rowptr[i], end = A->rowptr[i + 1];
    A->rowptr[i] = out;
    while (p < end) {
      int c = A->col[p];
      double s = A->val[p++];
      while (p < end && A->col[p] == c)
        s += A->val[p++];
      A->col[out] = c;
      A->val[out++] = s;
    }
  }
  A->rowptr[nrows] = out;
done:
  free(cptr);
  free(perm);
  free(cnt);
  return A;
}

dm_sparse *dm_sparse_diag(int n, const double *d, dm_err *e)
{
  int i;
  dm_sparse *A = dm_sparse_alloc(n, n, n, e);
  if (A == NULL)
    return NULL;
  for (i = 0; i < n; i++) {
    A->rowptr[i + 1] = i + 1;
    A->col[i] = i;
    A->val[i] = d != NULL ? d[i] : 1.0;
  }
  return A;
}

/* {==== CHOLMOD views ======================================================== */

void dm_sparse__start(cholmod_common *c)
{
  cholmod_start(c);
  c->print = 0;            /* numerics never print */
  c->error_handler = NULL;
}

/* The CSR arrays of A read as the CSC matrix A^T (nothing copied). */
cholmod_sparse dm_sparse__view_t(const dm_sparse *A, int stype)
{
  cholmod_sparse v;
  memset(&v, 0, sizeof v);
  v.nrow = (size_t)A->ncols;
  v.ncol = (size_t)A->nrows;
  v.nzmax = (size_t)dm_sparse_nnz(A);
  v.p = A->rowptr;
  v.i = A->col;
  v.x = A->val;
  v.stype = stype;
  v.itype = CHOLMOD_INT;
  v.xtype = CHOLMOD_REAL;
  v.dtype = CHOLMOD_DOUBLE;
  v.sorted = 1;
  v.packed = 1;
  return v;
}

/* A CHOLMOD CSC result C read back as the CSR matrix C^T (copied; C freed). */
static dm_sparse *from_cholmod_t(cholmod_sparse *C, cholmod_common *c,
                                 const char *what, dm_err *e)
{
  dm_sparse *A;
  size_t nnz;
  if (C == NULL) {
    dm_err_set(e, c->status == CHOLMOD_OUT_OF_MEMORY ? DM_ENOMEM : DM_EFAILED,
               "%s: CHOLMOD status %d", what, c->status);
    return NULL;
  }
  nnz = (size_t)((int *)C->p)[C->ncol];
  if (C->nrow > INT_MAX || C->ncol > INT_MAX || nnz > INT_MAX) {
    cholmod_free_sparse(&C, c);
    dm_err_set(e, DM_EINVAL, "%s: result too large for 32-bit indices", what);
    return NULL;
  }
  A = dm_sparse_alloc((int)C->ncol, (int)C->nrow, (int)nnz, e);
  if (A != NULL) {
    memcpy(A->rowptr, C->p, (C->ncol + 1) * sizeof *A->rowptr);
    memcpy(A->col, C->i, nnz * sizeof *A->col);
    memcpy(A->val, C->x, nnz * sizeof *A->val);
  }
  cholmod_free_sparse(&C, c);
  return A;
}

dm_sparse *dm_sparse_transpose(const dm_sparse *A, dm_err *e)
{
  cholmod_common c;
  cholmod_sparse va = dm_sparse__view_t(A, 0);
  dm_sparse *T;
  dm_sparse__start(&c);
  T = from_cholmod_t(cholmod_transpose(&va, 1, &c), &c, "sparse transpose", e);
  cholmod_finish(&c);
  return T;
}

/* CSR(A B) = CSC((A B)^T) = CSC(B^T) CSC(A^T): ssmult of the two views. */
dm_sparse *dm_sparse_mul(const dm_sparse *A, const dm_sparse *B, dm_err *e)
{
  cholmod_common c;
  cholmod_sparse va, vb;
  dm_sparse *C;
  if (A->ncols != B->nrows) {
    dm_err_set(e, DM_EINVAL, "sparse product: %d x %d times %d x %d", A->nrows,
               A->ncols, B->nrows, B->ncols);
    return NULL;
  }
  va = dm_sparse__view_t(A, 0);
  vb = dm_sparse__view_t(B, 0);
  dm_sparse__start(&c);
  C = from_cholmod_t(cholmod_ssmult(&vb, &va, 0, 1, 1, &c), &c, "sparse product", e);
  cholmod_finish(&c);
  return C;
}

dm_sparse *dm_sparse_add(double alpha, const dm_sparse *A, double beta,
                         const dm_sparse *B, dm_err *e)
{
  cholmod_common c;
  cholmod_sparse va, vb;
  double al[2] = {alpha, 0}, be[2] = {beta, 0};
  dm_sparse *C;
  if (A->nrows != B->nrows || A->ncols != B->ncols) {
    dm_err_set(e, DM_EINVAL, "sparse sum: %d x %d plus %d x %d", A->nrows,
               A->ncols, B->nrows, B->ncols);
    return NULL;
  }
  va = dm_sparse__view_t(A, 0);
  vb = dm_sparse__view_t(B, 0);
  dm_sparse__start(&c);
  C = from_cholmod_t(cholmod_add(&va, &vb, al, be, 1, 1, &c), &c, "sparse sum", e);
  cholmod_finish(&c);
  return C;
}

/* }==== */

dm_sparse *dm_sparse_drop(const dm_sparse *A, double tol, dm_err *e)
{
  int i, p, out = 0;
  dm_sparse *B = dm_sparse_alloc(A->nrows, A->ncols, dm_sparse_nnz(A), e);
  if (B == NULL)
    return NULL;
  for (i = 0; i < A->nrows; i++) {
    for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
      if (tol > 0 ? fabs(A->val[p]) >= tol : A->val[p] != 0.0) {
        B->col[out] = A->col[p];
        B->val[out++] = A->val[p];
      }
    B->rowptr[i + 1] = out;
  }
  return B;
}

dm_sparse *dm_sparse_select(const dm_sparse *A, const unsigned char *keeprow,
                            const unsigned char *keepcol, dm_err *e)
{
  int *newcol = malloc(((size_t)A->ncols + 1) * sizeof *newcol);
  int i, p, nr = 0, nc = 0, out = 0;
  dm_sparse *B = NULL;
  if (newcol == NULL) {
    dm_err_set(e, DM_ENOMEM, "sparse selection: out of memory");
    return NULL;
  }
  for (i = 0; i < A->ncols; i++)
    newcol[i] = (keepcol == NULL || keepcol[i]) ? nc++ : -1;
  for (i = 0; i < A->nrows; i++)
    nr += (keeprow == NULL || keeprow[i]) ? 1 : 0;
  B = dm_sparse_alloc(nr, nc, dm_sparse_nnz(A), e);
  if (B != NULL) {
    nr = 0;
    for (i = 0; i < A->nrows; i++) {
      if (keeprow != NULL && !keeprow[i])
        continue;
      for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
        if (newcol[A->col[p]] >= 0) {
          B->col[out] = newcol[A->col[p]];
          B->val[out++] = A->val[p];
        }
      B->rowptr[++nr] = out;
    }
  }
  free(newcol);
  return B;
}

dm_sparse *dm_sparse_fix_rows(const dm_sparse *A, const unsigned char *fixed, dm_err *e)
{
  int i, p, out = 0;
  dm_sparse *B = dm_sparse_alloc(A->nrows, A->ncols, dm_sparse_nnz(A) + A->nrows, e);
  if (B == NULL)
    return NULL;
  for (i = 0; i < A->nrows; i++) {
    if (fixed[i]) {
      B->col[out] = i;
      B->val[out++] = 1.0;
    } else {
      for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) {
        B->col[out] = A->col[p];
        B->val[out++] = A->val[p];
      }
    }
    B->rowptr[i + 1] = out;
  }
  return B;
}

void dm_sparse_scale(dm_sparse *A, const double *r, const double *c)
{
  int i, p;
  for (i = 0; i < A->nrows; i++)
    for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
      A->val[p] *= (r != NULL ? r[i] : 1.0) * (c != NULL ? c[A->col[p]] : 1.0);
}

void dm_sparse_gemv(const dm_sparse *A, const double *x, double *y)
{
  int i, p;
  for (i = 0; i < A->nrows; i++) {
    double s = 0.0;
    for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
      s += A->val[p] * x[A->col[p]];
    y[i] = s;
  }
}

void dm_sparse_gemv_t(const dm_sparse *A, const double *x, double *y)
{
  int i, p;
  memset(y, 0, (size_t)A->ncols * sizeof *y);
  for (i = 0; i < A->nrows; i++)
    for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
      y[A->col[p]] += A->val[p] * x[i];
}

double dm_sparse_norm(const dm_sparse *A)
{
  int p, nnz = dm_sparse_nnz(A);
  double scale = dm_sparse_maxabs(A), s = 0.0;
  if (scale == 0.0 || scale != scale)
    return scale;
  for (p = 0; p < nnz; p++)
    s += (A->val[p] / scale) * (A->val[p] / scale);
  return scale * sqrt(s);
}

double dm_sparse_maxabs(const dm_sparse *A)
{
  int p, nnz = dm_sparse_nnz(A);
  double m = 0.0;
  for (p = 0; p < nnz; p++) {
    double a = fabs(A->val[p]);
    if (a > m || a != a)
      m = a;
  }
  return m;
}

double dm_sparse_get(const dm_sparse *A, int i, int j)
{
  int lo = A->rowptr[i], hi = A->rowptr[i + 1] - 1;
  while (lo <= hi) {
    int mid = lo + (hi - lo) / 2;
    if (A->col[mid] == j)
      return A->val[mid];
    if (A->col[mid] < j)
      lo = mid + 1;
    else
      hi = mid - 1;
  }
  return 0.0;
}

double dm_sparse_asymmetry(const dm_sparse *A)
{
  int i, p;
  double m = 0.0;
  if (A->nrows != A->ncols)
    return HUGE_VAL;
  for (i = 0; i < A->nrows; i++)
    for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) {
      double d = fabs(A->val[p] - dm_sparse_get(A, A->col[p], i));
      if (d > m)
        m = d;
    }
  return m;
}
