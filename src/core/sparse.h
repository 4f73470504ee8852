/* sparse.h -- sparse matrices for the large systems: compressed-row
 * patterns (dm_csr) and a sparse direct LU solver (dm_splu) over
 * SuiteSparse KLU.
 *
 * A pattern lists the structurally nonzero entries of a matrix row by row:
 * row i holds the entries k in [rowptr[i], rowptr[i+1]), in column col[k],
 * columns ascending within a row.  Values live in separate arrays of nnz
 * doubles in the same order ("values on the pattern"), so one pattern
 * serves many matrices (every stage, every step).
 *
 * dm_splu factors a square matrix given as values on a fixed pattern:
 * the symbolic analysis (fill-reducing ordering, block triangular form) is
 * done once by dm_splu_alloc, the first dm_splu_factor factors with
 * partial pivoting, and later ones refactor numerically with the same
 * pivot order (no allocation); a refactorisation whose pivots have become
 * poor (KLU's reciprocal pivot ratio min |U_kk| / max |U_kk| a thousand
 * times below that of the last pivoted factorisation, or a zero pivot)
 * is redone with pivoting, which allocates.  Solves never allocate.
 * KLU reads compressed columns; the pattern's rows are handed to it as
 * the columns of the transpose, which is factored, and solves use the
 * transposed solve (so A x = b is what is solved).
 *
 * Ownership: dm_csr_alloc fills a caller-owned struct, dm_csr_free
 * releases it (a zeroed struct may be freed).  dm_splu_alloc /
 * dm_splu_free (NULL: no-op); the solver keeps no pointer to the pattern
 * it was analysed from.
 * Errors: DM_ENOMEM, DM_EINVAL (a pattern that is not square or has
 * more than INT_MAX entries), DM_ESINGULAR (a zero pivot, also after
 * re-pivoting), DM_EDOM (a value that is NaN or infinite); nothing is
 * printed.  Thread safety: a solver is used by one thread at a time;
 * patterns are read-only once built.
 */
#ifndef DM_SPARSE_H
#define DM_SPARSE_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

/* How the linear systems of a solver are solved (the integrators' option
 * "linear"): dense LU, sparse LU, or chosen by size and sparsity. */
enum dm_linear_mode { DM_LINEAR_AUTO = 0, DM_LINEAR_DENSE, DM_LINEAR_SPARSE };
/* "auto" (also NULL or ""), "dense", "sparse"; -1 for another name. */
int dm_linear_mode_parse(const char *name);

typedef struct dm_csr {
  size_t nrow, ncol, nnz;
  size_t *rowptr;           /* nrow + 1 */
  uint32_t *col;            /* nnz */
} dm_csr;

/* Room for a pattern with these sizes (rowptr and col uninitialised). */
int dm_csr_alloc(dm_csr *p, size_t nrow, size_t ncol, size_t nnz);
void dm_csr_free(dm_csr *p);
/* Position of entry (i, j) in the values, or -1 when it is not in the
 * pattern (binary search in row i). */
long dm_csr_find(const dm_csr *p, size_t i, size_t j);
/* dense[i*ncol + j] = values on the pattern, zero elsewhere. */
void dm_csr_to_dense(const dm_csr *p, const double *val, double *dense);
/* val[k] = dense[row(k)*ncol + col(k)] for every entry. */
void dm_csr_from_dense(const dm_csr *p, const double *dense, double *val);
/* The full pattern (every entry) of an nrow x ncol matrix. */
int dm_csr_full(dm_csr *p, size_t nrow, size_t ncol);

typedef struct dm_splu dm_splu;

/* Analyse the square pattern p. */
int dm_splu_alloc(const dm_csr *p, dm_splu **out, dm_err *e);
void dm_splu_free(dm_splu *lu);
/* Factor the matrix with these values (nnz of them, on the pattern). */
int dm_splu_factor(dm_splu *lu, const double *val, dm_err *e);
/* b := A^{-1} b for nrhs right-hand sides stored one after the other
 * (each n long); only after a successful factorisation. */
int dm_splu_solve(dm_splu *lu, double *b, size_t nrhs, dm_err *e);
/* Statistics: factorisations with pivoting, numerical refactorisations,
 * nonzeros of L + U of the last factorisation. */
typedef struct dm_splu_stats {
  size_t nfactor, nrefactor, lunz;
} dm_splu_stats;
void dm_splu_stats_get(const dm_splu *lu, dm_splu_stats *st);

#endif
