/* smalllu.h -- dense LU with partial pivoting for the small Newton systems
 * of the integrators and the reduction (stage equations, SHAKE, momentum
 * projections, Legendre maps: n from 1 to about a hundred).
 *
 * Why not GSL here.  The project uses GSL's linear algebra; small kernels
 * are the exception when measured.  GSL 2.7's gsl_linalg_LU_decomp is the
 * blocked (level-3) algorithm: for a 6 x 6 system it goes through views,
 * cblas_dtrsv/dger/idamax calls and mallocs and frees a pivot vector on
 * every call.  In the J2 Gauss-2 benchmark (6 x 6 Newton matrix; perf) the
 * GSL LU and solve were ~35% of a step and malloc/free ~2%.  Factor + solve
 * of a random diagonally dominant matrix (copy included), this kernel
 * against GSL with gslcblas (thread CPU time, median of 9, same machine,
 * one run): n = 6: 0.21 vs 0.64 us, 9: 0.61 vs 1.29, 16: 2.6 vs 3.2,
 * 24: 8.0 vs 7.8, 32: 17 vs 17, 48: 49 vs 47, 64: 101 vs 99, 96: 307 vs
 * 275, 128: 744 vs 695 us (within 12% up to n = 128); from n = 160 GSL's
 * blocked code is ~1.6x faster (160: 2.26 vs 1.41 ms, 256: 9.1 vs 5.6 ms)
 * -- the kernel's rank-1 updates stream the whole trailing matrix through
 * the cache at every elimination step.  Hence DM_SMALLLU_NMAX = 128: no
 * Newton system of a realistic step (Gauss 8 on 16 coordinates) allocates,
 * and where GSL's malloc comes back the factorisation costs milliseconds.
 * Same pivots as GSL, and L and U equal to GSL's to round-off
 * (tests/c/test_smalllu.c).  Above DM_SMALLLU_NMAX the calls go to
 * gsl_linalg_LU_decomp / gsl_linalg_LU_svx unchanged.
 *
 * Storage.  a is row-major n x n, factored in place: the unit lower factor
 * below the diagonal, U above it; on the diagonal 1/U_kk for n <=
 * DM_SMALLLU_NMAX (the solve then multiplies), U_kk above (GSL's layout).
 * Treat the factors as opaque.  For n <= DM_SMALLLU_NMAX, perm[k] is
 * the row interchanged with row k at elimination step k (LAPACK's ipiv, 0
 * based); above, perm is the data of a gsl_permutation.  Only
 * dm_smalllu_solve reads perm, with the same n, so callers never see the
 * difference.
 *
 * Ownership.  Nothing is allocated for n <= DM_SMALLLU_NMAX: the caller
 * owns a, perm (room for n) and b.  Above it, GSL >= 2.7 allocates a pivot
 * vector inside gsl_linalg_LU_decomp (a malloc/free per factorisation).
 *
 * Errors.  dm_smalllu_factor returns DM_OK; DM_ENOMEM (above
 * DM_SMALLLU_NMAX only: GSL's pivot vector); DM_EDOM (a is left unchanged)
 * when an entry is NaN or infinite; DM_ESINGULAR when a pivot |U_kk| is not
 * above 16 n eps max|a_ij| (a relative test, independent of the scale of a;
 * a is then partly factored and must not be passed to the solve).  No
 * message is set: callers know what the matrix means.
 */
#ifndef DM_SMALLLU_H
#define DM_SMALLLU_H

#include <stddef.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>

/* gsl_linalg_LU_decomp, safe when memory runs out: GSL 2.7 allocates a
 * pivot vector inside and dereferences it even when that allocation
 * failed (a crash found by refusing allocations one at a time,
 * tests/c/test_fault_alloc.c).  The same allocation is tried first, and
 * DM_ENOMEM returned when it fails; else DM_OK (or DM_EFAILED for GSL's
 * own errors). */
int dm_gsl_lu_decomp(gsl_matrix *A, gsl_permutation *p, int *signum);

/* Sizes up to this use the kernel in smalllu.c, larger ones GSL. */
#define DM_SMALLLU_NMAX 128

int dm_smalllu_factor(double *a, size_t n, size_t *perm);

/* Solve A x = b with the factors from dm_smalllu_factor (DM_OK); b is
 * overwritten by x. */
void dm_smalllu_solve(const double *lu, size_t n, const size_t *perm, double *b);

#endif
