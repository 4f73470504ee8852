/* test_sparse.c -- compressed-row patterns and the KLU solver
 * (src/core/sparse.c): solutions against GSL's dense LU on random sparse
 * matrices (tridiagonal, block-banded, arrow, unsymmetric patterns that
 * need pivoting), numerical refactorisation on the same pattern with new
 * values (no new pivoted factorisation while the pivots stay good, a new
 * one when a pivot vanishes), several right-hand sides at once, the
 * pattern helpers, and the errors: singular, NaN entries, non-square
 * patterns, solve before factor. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_rng.h>

#include "core/sparse.h"
#include "core/status.h"
#include "tap.h"

static gsl_rng *rng;

/* A pattern from a dense 0/1 mask. */
static void pattern_of(dm_csr *p, const int *mask, size_t n)
{
  size_t nnz = 0;
  for (size_t k = 0; k < n * n; k++)
    nnz += mask[k] != 0;
  if (dm_csr_alloc(p, n, n, nnz) != DM_OK)
    abort();
  nnz = 0;
  for (size_t i = 0; i < n; i++) {
    p->rowptr[i] = nnz;
    for (size_t j = 0; j < n; j++)
      if (mask[i * n + j])
        p->col[nnz++] = (uint32_t)j;
  }
  p->rowptr[n] = nnz;
}

/* Random values on the pattern; the diagonal (when present) gets weight
 * dom (0: no diagonal dominance). */
static void random_values(const dm_csr *p, double *val, double dom)
{
  for (size_t i = 0; i < p->nrow; i++)
    for (size_t k = p->rowptr[i]; k < p->rowptr[i + 1]; k++)
      val[k] = gsl_rng_uniform(rng) * 2.0 - 1.0 + (p->col[k] == i ? dom : 0.0);
}

/* max |x_sparse - x_gsl| / max |x_gsl| for A x = b. */
static double compare_gsl(const dm_csr *p, const double *val, dm_splu *lu, int *st)
{
  size_t n = p->nrow;
  double *A = malloc(n * n * sizeof *A), *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x);
  for (size_t i = 0; i < n; i++)
    b[i] = 2.385 * sin(1.0 + (double)i);
  dm_csr_to_dense(p, val, A);
  memcpy(x, b, n * sizeof *x);
  *st = dm_splu_solve(lu, x, 1, NULL);
  gsl_matrix_view M = gsl_matrix_view_array(A, n, n);
  gsl_vector_view B = gsl_vector_view_array(b, n);
  gsl_permutation *perm = gsl_permutation_alloc(n);
  int sg;
  gsl_linalg_LU_decomp(&M.matrix, perm, &sg);
  gsl_linalg_LU_svx(&M.matrix, perm, &B.vector);
  double d = 0.0, m = 0.0;
  for (size_t i = 0; i < n; i++) {
    d = fmax(d, fabs(x[i] - b[i]));
    m = fmax(m, fabs(b[i]));
  }
  gsl_permutation_free(perm);
  free(A);
  free(b);
  free(x);
  return d / m;
}

static void check_pattern(const char *name, const int *mask, size_t n, double dom)
{
  dm_csr p;
  dm_splu *lu = NULL;
  pattern_of(&p, mask, n);
  double *val = malloc(p.nnz * sizeof *val);
  int st = dm_splu_alloc(&p, &lu, NULL);
  tap_is_int(st, DM_OK, "%s (n = %zu, nnz = %zu): analysis", name, n, p.nnz);
  for (int round = 0; round < 3; round++) {
    random_values(&p, val, dom);
    st = dm_splu_factor(lu, val, NULL);
    int ss;
    double err = compare_gsl(&p, val, lu, &ss);
    tap_ok(st == DM_OK && ss == DM_OK && err < 1e-11,
           "%s: factorisation %d agrees with GSL's dense LU (rel. diff %.2g)", name, round + 1,
           err);
  }
  dm_splu_stats st2;
  dm_splu_stats_get(lu, &st2);
  tap_diag("%s: %zu pivoted factorisations, %zu refactorisations, nnz(L+U) = %zu", name,
           st2.nfactor, st2.nrefactor, st2.lunz);
  dm_splu_free(lu);
  dm_csr_free(&p);
  free(val);
}

int main(void)
{
  rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, 2385);
  gsl_set_error_handler_off();
  enum { N = 60 };
  static int mask[N * N];

  /* tridiagonal */
  memset(mask, 0, sizeof mask);
  for (int i = 0; i < N; i++)
    for (int j = i - 1; j <= i + 1; j++)
      if (j >= 0 && j < N)
        mask[i * N + j] = 1;
  check_pattern("tridiagonal", mask, N, 4.0);
  /* 2 x 2 blocks of tridiagonals (a Gauss-2 Newton matrix of a chain) */
  memset(mask, 0, sizeof mask);
  for (int bi = 0; bi < 2; bi++)
    for (int bk = 0; bk < 2; bk++)
      for (int i = 0; i < N / 2; i++)
        for (int j = i - 1; j <= i + 1; j++)
          if (j >= 0 && j < N / 2)
            mask[(bi * N / 2 + i) * N + bk * N / 2 + j] = 1;
  check_pattern("2x2 blocks of tridiagonals", mask, N, 3.0);
  /* arrow: dense last row and column */
  memset(mask, 0, sizeof mask);
  for (int i = 0; i < N; i++)
    mask[i * N + i] = mask[i * N + N - 1] = mask[(N - 1) * N + i] = 1;
  check_pattern("arrow", mask, N, 2.0);
  /* unsymmetric, no diagonal dominance: a cyclic shift plus random entries
   * (needs pivoting off the diagonal) */
  memset(mask, 0, sizeof mask);
  for (int i = 0; i < N; i++) {
    mask[i * N + (i + 1) % N] = 1;
    for (int r = 0; r < 3; r++)
      mask[i * N + gsl_rng_uniform_int(rng, N)] = 1;
  }
  check_pattern("unsymmetric random", mask, N, 0.0);

  /* refactorisation: same pattern, values scaled and perturbed -> numeric
   * refactorisations only; then a vanishing pivot forces a new choice */
  {
    dm_csr p;
    dm_splu *lu = NULL;
    memset(mask, 0, sizeof mask);
    for (int i = 0; i < N; i++)
      for (int j = i - 1; j <= i + 1; j++)
        if (j >= 0 && j < N)
          mask[i * N + j] = 1;
    pattern_of(&p, mask, N);
    double *val = malloc(p.nnz * sizeof *val);
    dm_splu_alloc(&p, &lu, NULL);
    random_values(&p, val, 4.0);
    dm_splu_factor(lu, val, NULL);
    for (int k = 0; k < 5; k++) {
      for (size_t j = 0; j < p.nnz; j++)
        val[j] *= 1.0 + 0.01 * sin((double)(j + k));
      dm_splu_factor(lu, val, NULL);
    }
    dm_splu_stats st;
    dm_splu_stats_get(lu, &st);
    tap_ok(st.nfactor == 1 && st.nrefactor == 5,
           "slowly changing values: 1 pivoted factorisation, 5 refactorisations (got %zu, %zu)",
           st.nfactor, st.nrefactor);
    /* make the first row's diagonal vanish: swap in a pivot */
    long k00 = dm_csr_find(&p, 0, 0), k01 = dm_csr_find(&p, 0, 1);
    tap_ok(k00 == 0 && k01 == 1 && dm_csr_find(&p, 0, 5) == -1 && dm_csr_find(&p, 5, 6) == 16,
           "dm_csr_find: positions of (0,0), (0,1), (5,6) and an absent entry");
    val[k00] = 0.0;
    val[k01] = 3.0;
    int st2;
    int s = dm_splu_factor(lu, val, NULL);
    double err = compare_gsl(&p, val, lu, &st2);
    dm_splu_stats_get(lu, &st);
    tap_ok(s == DM_OK && err < 1e-11 && st.nfactor == 2,
           "a vanishing diagonal pivot: pivoted again (%zu), solution agrees (%.2g)",
           st.nfactor, err);
    /* several right-hand sides */
    double *B = malloc(3 * N * sizeof *B), *A = malloc(N * N * sizeof *A);
    for (int i = 0; i < 3 * N; i++)
      B[i] = cos(0.7 * i);
    dm_splu_solve(lu, B, 3, NULL);
    dm_csr_to_dense(&p, val, A);
    double res = 0.0;
    for (int r = 0; r < 3; r++)
      for (int i = 0; i < N; i++) {
        double acc = -cos(0.7 * (r * N + i));
        for (int j = 0; j < N; j++)
          acc += A[i * N + j] * B[r * N + j];
        res = fmax(res, fabs(acc));
      }
    tap_ok(res < 1e-12, "three right-hand sides at once: residual %.2g", res);
    /* dense <-> values */
    double *v2 = malloc(p.nnz * sizeof *v2);
    dm_csr_from_dense(&p, A, v2);
    tap_ok(memcmp(v2, val, p.nnz * sizeof *v2) == 0, "values -> dense -> values is the identity");
    /* errors */
    dm_err e;
    val[3] = NAN;
    tap_is_int(dm_splu_factor(lu, val, &e), DM_EDOM, "NaN entry: DM_EDOM (%s)", e.msg);
    for (size_t j = 0; j < p.nnz; j++)
      val[j] = p.col[j] < 2 ? 1.0 : (double)(j + 1);   /* columns 0 and 1 equal */
    for (int i = 2; i < N; i++) {                        /* rows >= 2: no 0/1 entries */
      long a = dm_csr_find(&p, i, 0), b = dm_csr_find(&p, i, 1);
      if (a >= 0) val[a] = 0.0;
      if (b >= 0) val[b] = 0.0;
    }
    val[dm_csr_find(&p, 2, 1)] = 0.0;
    tap_is_int(dm_splu_factor(lu, val, &e), DM_ESINGULAR, "singular matrix: DM_ESINGULAR (%s)",
               e.msg);
    free(v2);
    free(A);
    free(B);
    free(val);
    dm_splu_free(lu);
    dm_csr_free(&p);
  }
  {
    dm_csr p;
    dm_splu *lu = NULL;
    dm_err e;
    double b[3] = {1, 2, 3};
    dm_csr_alloc(&p, 2, 3, 0);
    tap_is_int(dm_splu_alloc(&p, &lu, &e), DM_EINVAL, "non-square pattern: DM_EINVAL (%s)",
               e.msg);
    dm_csr_free(&p);
    dm_csr_full(&p, 3, 3);
    tap_ok(p.nnz == 9 && p.rowptr[2] == 6 && p.col[7] == 1, "full pattern 3x3");
    dm_splu_alloc(&p, &lu, NULL);
    tap_is_int(dm_splu_solve(lu, b, 1, &e), DM_EINVAL, "solve before factor: DM_EINVAL (%s)",
               e.msg);
    dm_splu_free(lu);
    dm_splu_free(NULL);
    dm_csr_free(&p);
    dm_csr_free(&p);
  }
  gsl_rng_free(rng);
  return tap_done();
}
