/* sparse.c -- compressed-row patterns and the KLU solver.  See sparse.h. */
#include <config.h>
#include "core/sparse.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <suitesparse/klu.h>

int dm_linear_mode_parse(const char *name)
{
  if (name == NULL || name[0] == '\0' || strcmp(name, "auto") == 0)
    return DM_LINEAR_AUTO;
  if (strcmp(name, "dense") == 0)
    return DM_LINEAR_DENSE;
  if (strcmp(name, "sparse") == 0)
    return DM_LINEAR_SPARSE;
  return -1;
}

int dm_csr_alloc(dm_csr *p, size_t nrow, size_t ncol, size_t nnz)
{
  memset(p, 0, sizeof *p);
  p->rowptr = malloc((nrow + 1) * sizeof *p->rowptr);
  p->col = malloc((nnz ? nnz : 1) * sizeof *p->col);
  if (p->rowptr == NULL || p->col == NULL) {
    dm_csr_free(p);
    return DM_ENOMEM;
  }
  p->nrow = nrow;
  p->ncol = ncol;
  p->nnz = nnz;
  return DM_OK;
}

void dm_csr_free(dm_csr *p)
{
  if (p == NULL)
    return;
  free(p->rowptr);
  free(p->col);
  memset(p, 0, sizeof *p);
}

long dm_csr_find(const dm_csr *p, size_t i, size_t j)
{
  size_t lo = p->rowptr[i], hi = p->rowptr[i + 1];
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    if (p->col[mid] < j)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < p->rowptr[i + 1] && p->col[lo] == j ? (long)lo : -1;
}

void dm_csr_to_dense(const dm_csr *p, const double *val, double *dense)
{
  memset(dense, 0, p->nrow * p->ncol * sizeof *dense);
  for (size_t i = 0; i < p->nrow; i++)
    for (size_t k = p->rowptr[i]; k < p->rowptr[i + 1]; k++)
      dense[i * p->ncol + p->col[k]] = val[k];
}

void dm_csr_from_dense(const dm_csr *p, const double *dense, double *val)
{
  for (size_t i = 0; i < p->nrow; i++)
    for (size_t k = p->rowptr[i]; k < p->rowptr[i + 1]; k++)
      val[k] = dense[i * p->ncol + p->col[k]];
}

int dm_csr_full(dm_csr *p, size_t nrow, size_t ncol)
{
  if (dm_csr_alloc(p, nrow, ncol, nrow * ncol) != DM_OK)
    return DM_ENOMEM;
  for (size_t i = 0; i <= nrow; i++)
    p->rowptr[i] = i * ncol;
  for (size_t k = 0; k < nrow * ncol; k++)
    p->col[k] = (uint32_t)(k % ncol);
  return DM_OK;
}

/* {==================================================================
 * KLU
 * =================================================================== */

struct dm_splu {
  int n;
  int *Ap, *Ai;             /* the pattern as KLU's compressed columns */
  klu_common c;
  klu_symbolic *sym;
  klu_numeric *num;
  double rcond;             /* of the last factorisation with pivoting */
  size_t nfactor, nrefactor;
};

void dm_splu_free(dm_splu *lu)
{
  if (lu == NULL)
    return;
  if (lu->num != NULL)
    klu_free_numeric(&lu->num, &lu->c);
  if (lu->sym != NULL)
    klu_free_symbolic(&lu->sym, &lu->c);
  free(lu->Ap);
  free(lu->Ai);
  free(lu);
}

int dm_splu_alloc(const dm_csr *p, dm_splu **out, dm_err *e)
{
  *out = NULL;
  if (p->nrow != p->ncol || p->nrow == 0 || p->nnz > INT_MAX || p->nrow > INT_MAX)
    return dm_err_set(e, DM_EINVAL, "sparse LU: the pattern must be square, nonempty "
                      "and have at most %d entries", INT_MAX);
  dm_splu *lu = calloc(1, sizeof *lu);
  if (lu == NULL)
    return dm_err_set(e, DM_ENOMEM, "sparse LU: out of memory");
  lu->n = (int)p->nrow;
  lu->Ap = malloc((p->nrow + 1) * sizeof *lu->Ap);
  lu->Ai = malloc((p->nnz ? p->nnz : 1) * sizeof *lu->Ai);
  if (lu->Ap == NULL || lu->Ai == NULL) {
    dm_splu_free(lu);
    return dm_err_set(e, DM_ENOMEM, "sparse LU: out of memory");
  }
  for (size_t i = 0; i <= p->nrow; i++)
    lu->Ap[i] = (int)p->rowptr[i];
  for (size_t k = 0; k < p->nnz; k++)
    lu->Ai[k] = (int)p->col[k];
  klu_defaults(&lu->c);
  lu->sym = klu_analyze(lu->n, lu->Ap, lu->Ai, &lu->c);
  if (lu->sym == NULL) {
    int st = lu->c.status == KLU_OUT_OF_MEMORY ? DM_ENOMEM : DM_EINVAL;
    dm_splu_free(lu);
    return dm_err_set(e, st, "sparse LU: the analysis of the pattern failed (KLU status %d)",
                      st == DM_ENOMEM ? KLU_OUT_OF_MEMORY : lu->c.status);
  }
  *out = lu;
  return DM_OK;
}

static int finite_all(const double *v, size_t n)
{
  double s = 0.0;
  for (size_t k = 0; k < n; k++)
    s += v[k] * 0.0;          /* NaN iff some v[k] is NaN or infinite */
  return s == 0.0;
}

/* A full factorisation with pivoting (replacing any earlier one). */
static int factor_full(dm_splu *lu, double *val, dm_err *e)
{
  if (lu->num != NULL)
    klu_free_numeric(&lu->num, &lu->c);
  lu->num = klu_factor(lu->Ap, lu->Ai, val, lu->sym, &lu->c);
  if (lu->num == NULL) {
    if (lu->c.status == KLU_OUT_OF_MEMORY)
      return dm_err_set(e, DM_ENOMEM, "sparse LU: out of memory");
    return dm_err_set(e, DM_ESINGULAR, "sparse LU: the matrix is singular");
  }
  lu->nfactor++;
  if (lu->c.status == KLU_SINGULAR)
    return dm_err_set(e, DM_ESINGULAR, "sparse LU: the matrix is singular");
  lu->rcond = klu_rcond(lu->sym, lu->num, &lu->c) ? lu->c.rcond : 0.0;
  return DM_OK;
}

int dm_splu_factor(dm_splu *lu, const double *val, dm_err *e)
{
  size_t nnz = (size_t)lu->Ap[lu->n];
  if (!finite_all(val, nnz))
    return dm_err_set(e, DM_EDOM, "sparse LU: the matrix has an entry that is NaN or infinite");
  double *v = (double *)val;  /* KLU's prototypes are not const-correct; it only reads */
  if (lu->num == NULL)
    return factor_full(lu, v, e);
  /* the old pivot order is kept while the pivots stay within a factor
   * 1000 of the conditioning a fresh choice had */
  if (klu_refactor(lu->Ap, lu->Ai, v, lu->sym, lu->num, &lu->c) &&
      klu_rcond(lu->sym, lu->num, &lu->c) && lu->c.rcond >= 1e-3 * lu->rcond &&
      lu->c.rcond > 0.0) {
    lu->nrefactor++;
    return DM_OK;
  }
  return factor_full(lu, v, e);
}

int dm_splu_solve(dm_splu *lu, double *b, size_t nrhs, dm_err *e)
{
  if (lu->num == NULL)
    return dm_err_set(e, DM_EINVAL, "sparse LU: solve before a factorisation");
  if (!klu_tsolve(lu->sym, lu->num, lu->n, (int)nrhs, b, &lu->c))
    return dm_err_set(e, DM_ESINGULAR, "sparse LU: the solve failed (KLU status %d)",
                      lu->c.status);
  return DM_OK;
}

void dm_splu_stats_get(const dm_splu *lu, dm_splu_stats *st)
{
  st->nfactor = lu->nfactor;
  st->nrefactor = lu->nrefactor;
  st->lunz = lu->num ? (size_t)(lu->num->lnz + lu->num->unz + lu->n) : 0;
}
