/* test_smalllu.c -- the small dense LU (src/core/smalllu.c) against GSL's LU:
 * random well-conditioned matrices on both sides of DM_SMALLLU_NMAX (factors,
 * pivots and solutions), ill-conditioned ones (Hilbert, graded rows:
 * backward error at round-off, forward error within cond * eps of GSL),
 * pivoting cases that fail without row interchanges, singular detection
 * (exact rank deficiency, relative threshold independent of the scale),
 * non-finite entries, and reuse of one factorisation for several
 * right-hand sides. */
#include <config.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_rng.h>

#include "core/smalllu.h"
#include "core/status.h"
#include "tap.h"

#define NM (DM_SMALLLU_NMAX + 8)

static gsl_rng *rng;

static double norm_inf(const double *x, size_t n)
{
  double m = 0.0;
  for (size_t i = 0; i < n; i++)
    m = fmax(m, fabs(x[i]));
  return m;
}

/* ||A x - b||_inf / (||A||_max n ||x||_inf): backward error in units of eps */
static double backward(const double *A, const double *x, const double *b, size_t n)
{
  double r = 0.0;
  for (size_t i = 0; i < n; i++) {
    long double acc = b[i];
    for (size_t j = 0; j < n; j++)
      acc -= (long double)A[i * n + j] * x[j];
    r = fmax(r, fabs((double)acc));
  }
  return r / (norm_inf(A, n * n) * (double)n * norm_inf(x, n)) / DBL_EPSILON;
}

/* GSL's solution of A x = b (A copied) */
static int gsl_solve(const double *A, const double *b, size_t n, double *x, double *lu,
                     size_t *p)
{
  gsl_matrix_view M;
  gsl_permutation P = {n, p};
  gsl_vector_const_view B = gsl_vector_const_view_array(b, n);
  gsl_vector_view X = gsl_vector_view_array(x, n);
  int sg;
  memcpy(lu, A, n * n * sizeof(double));
  M = gsl_matrix_view_array(lu, n, n);
  gsl_linalg_LU_decomp(&M.matrix, &P, &sg);
  return gsl_linalg_LU_solve(&M.matrix, &P, &B.vector, &X.vector);
}

static int small_solve(const double *A, const double *b, size_t n, double *x, double *lu,
                       size_t *perm)
{
  int st;
  memcpy(lu, A, n * n * sizeof(double));
  memcpy(x, b, n * sizeof(double));
  if ((st = dm_smalllu_factor(lu, n, perm)) == DM_OK)
    dm_smalllu_solve(lu, n, perm, x);
  return st;
}

/* random entries in [-2.385, 2.385] plus 2.385 n on the diagonal when dominant */
static void random_matrix(double *A, size_t n, int dominant)
{
  for (size_t i = 0; i < n * n; i++)
    A[i] = 2.385 * (2.0 * gsl_rng_uniform(rng) - 1.0);
  if (dominant)
    for (size_t i = 0; i < n; i++)
      A[i * n + i] += (A[i * n + i] < 0 ? -2.385 : 2.385) * (double)n;
}

static void random_vector(double *b, size_t n)
{
  for (size_t i = 0; i < n; i++)
    b[i] = 2.385 * (2.0 * gsl_rng_uniform(rng) - 1.0) + 0.5;
}

static double rel_diff(const double *x, const double *y, size_t n)
{
  double d = 0.0;
  for (size_t i = 0; i < n; i++)
    d = fmax(d, fabs(x[i] - y[i]));
  return d / norm_inf(y, n);
}

/* row order of the interchange sequence perm (LAPACK ipiv), as a gsl_permutation */
static void ipiv_to_rows(const size_t *perm, size_t n, size_t *rows)
{
  for (size_t i = 0; i < n; i++)
    rows[i] = i;
  for (size_t k = 0; k < n; k++) {
    size_t t = rows[k];
    rows[k] = rows[perm[k]];
    rows[perm[k]] = t;
  }
}

static void test_random(void)
{
  static double A[NM * NM], lu[NM * NM], lug[NM * NM], b[NM], x[NM], xg[NM];
  static size_t perm[NM], pg[NM], rows[NM];
  double worst_x = 0.0, worst_bw = 0.0, worst_lu = 0.0;
  int bad_perm = 0, bad_status = 0;
  /* 1 .. 40, then sizes around DM_SMALLLU_NMAX (both kernels) */
  static const size_t big[] = {64, 100, DM_SMALLLU_NMAX - 1, DM_SMALLLU_NMAX,
                               DM_SMALLLU_NMAX + 1, DM_SMALLLU_NMAX + 8};
  for (size_t t = 0; t < 40 + sizeof big / sizeof big[0]; t++)
    for (int rep = 0; rep < (t < 40 ? 8 : 2); rep++) {
      size_t n = t < 40 ? t + 1 : big[t - 40];
      random_matrix(A, n, rep % 2);
      random_vector(b, n);
      if (small_solve(A, b, n, x, lu, perm) != DM_OK || gsl_solve(A, b, n, xg, lug, pg) != 0) {
        bad_status++;
        continue;
      }
      worst_x = fmax(worst_x, rel_diff(x, xg, n));
      worst_bw = fmax(worst_bw, backward(A, x, b, n));
      if (n <= DM_SMALLLU_NMAX) {
        /* same pivots (no ties in random data) and the same factors */
        ipiv_to_rows(perm, n, rows);
        for (size_t i = 0; i < n; i++)
          bad_perm += rows[i] != pg[i];
        for (size_t i = 0; i < n; i++)       /* the kernel keeps 1/U_ii */
          lu[i * n + i] = 1.0 / lu[i * n + i];
        worst_lu = fmax(worst_lu, rel_diff(lu, lug, n * n));
      }
    }
  tap_is_int(bad_status, 0, "random 1x1 .. 40x40 and 64 .. %d: every factorisation succeeds", DM_SMALLLU_NMAX + 8);
  tap_ok(worst_x <= 1e-13, "random: solution = GSL's to %.2g (<= 1e-13)", worst_x);
  tap_ok(worst_bw <= 1.0, "random: backward error %.2g n eps (<= 1)", worst_bw);
  tap_is_int(bad_perm, 0, "random n <= %d: the same row interchanges as GSL", DM_SMALLLU_NMAX);
  tap_ok(worst_lu <= 1e-13, "random n <= %d: L and U = GSL's to %.2g (<= 1e-13)",
         DM_SMALLLU_NMAX, worst_lu);
}

/* Hilbert matrices (condition up to ~1e13) and rows graded over 16 decades:
 * backward stable, and as close to GSL as the conditioning allows. */
static void test_ill_conditioned(void)
{
  static double A[NM * NM], lu[NM * NM], lug[NM * NM], b[NM], x[NM], xg[NM];
  static size_t perm[NM], pg[NM];
  double worst_bw = 0.0, worst_fw = 0.0, xone = 0.0;
  for (size_t n = 4; n <= 10; n++) {
    for (size_t i = 0; i < n; i++)
      for (size_t j = 0; j < n; j++)
        A[i * n + j] = 2.385 / (double)(i + j + 1);
    for (size_t i = 0; i < n; i++) {      /* b = A (1, ..., 1) */
      b[i] = 0.0;
      for (size_t j = 0; j < n; j++)
        b[i] += A[i * n + j];
    }
    tap_is_int(small_solve(A, b, n, x, lu, perm), DM_OK, "Hilbert %zu x %zu factors", n, n);
    gsl_solve(A, b, n, xg, lug, pg);
    worst_bw = fmax(worst_bw, backward(A, x, b, n));
    /* cond_inf(H_n) < 10^(1.5 n) for n <= 10 */
    worst_fw = fmax(worst_fw, rel_diff(x, xg, n) / (pow(10.0, 1.5 * (double)n) * DBL_EPSILON));
    if (n == 6)
      for (size_t i = 0; i < n; i++)
        xone = fmax(xone, fabs(x[i] - 1.0));
  }
  tap_ok(worst_bw <= 1.0, "Hilbert 4..10: backward error %.2g n eps (<= 1)", worst_bw);
  tap_ok(worst_fw <= 1.0, "Hilbert 4..10: |x - x_gsl| / |x| = %.2g cond eps (<= 1)", worst_fw);
  tap_ok(xone <= 1e-8 && xone > 0.0, "Hilbert 6: x = (1, ..., 1) to %.2g (cond ~ 1e7)", xone);

  /* graded rows: 10^(4 - 8 i / (n - 1)) is fine; over 16 decades the smallest
   * pivot falls below the relative threshold 16 n eps max|a| (by design) */
  for (int wide = 0; wide <= 1; wide++) {
    size_t n = 9;
    double dec = wide ? 16.0 : 8.0;
    random_matrix(A, n, 1);
    for (size_t i = 0; i < n; i++)
      for (size_t j = 0; j < n; j++)
        A[i * n + j] *= pow(10.0, dec / 2 - dec * (double)i / (double)(n - 1));
    random_vector(b, n);
    if (wide) {
      tap_is_int(small_solve(A, b, n, x, lu, perm), DM_ESINGULAR,
                 "rows graded over 16 decades: DM_ESINGULAR (relative pivot test)");
      continue;
    }
    tap_is_int(small_solve(A, b, n, x, lu, perm), DM_OK, "rows graded 1e4 .. 1e-4 factor");
    gsl_solve(A, b, n, xg, lug, pg);
    tap_ok(rel_diff(x, xg, n) <= 1e-12, "graded rows: solution = GSL's to %.2g",
           rel_diff(x, xg, n));
    tap_ok(backward(A, x, b, n) <= 1.0, "graded rows: backward error %.2g n eps",
           backward(A, x, b, n));
  }
}

/* Matrices that elimination without interchanges gets wrong or cannot do. */
static void test_pivoting(void)
{
  static double lu[NM * NM], x[NM];
  static size_t perm[NM];
  {
    const double A[4] = {0.0, 2.385, 1.5, 0.0}, b[2] = {4.77, 3.0};
    tap_is_int(small_solve(A, b, 2, x, lu, perm), DM_OK, "zero leading entry: factors");
    tap_ok(perm[0] == 1 && perm[1] == 1, "zero leading entry: rows 1 and 2 interchanged");
    tap_ok(x[0] == 2.0 && x[1] == 2.0, "zero leading entry: x = (2, 2) exactly (%.17g, %.17g)",
           x[0], x[1]);
  }
  {
    /* without pivoting x1 = (1 - x2) / 1e-20 loses everything */
    const double A[4] = {1e-20, 2.385, 2.385, 2.385}, b[2] = {2.385, 4.77};
    small_solve(A, b, 2, x, lu, perm);
    tap_near(x[0], 1.0, 1e-15, "tiny leading pivot: x1 = 1");
    tap_near(x[1], 1.0, 1e-15, "tiny leading pivot: x2 = 1");
  }
  {
    /* cyclic permutation times 2.385: exact solution, every row moved */
    double A[25] = {0}, b[5], xs[5];
    for (size_t i = 0; i < 5; i++) {
      A[i * 5 + (i + 1) % 5] = 2.385;
      b[i] = 2.385 * (double)(i + 2);
    }
    tap_is_int(small_solve(A, b, 5, xs, lu, perm), DM_OK, "5x5 cyclic permutation factors");
    int exact = 1;
    for (size_t i = 0; i < 5; i++)
      exact &= xs[(i + 1) % 5] == (double)(i + 2);
    tap_ok(exact, "5x5 cyclic permutation: exact solution");
  }
  {
    /* one factorisation, several right-hand sides: the columns of A^-1 A = I */
    double A[16], inv[16], e[4];
    size_t n = 4;
    random_matrix(A, n, 0);
    memcpy(lu, A, sizeof A);
    tap_is_int(dm_smalllu_factor(lu, n, perm), DM_OK, "4x4 random factors");
    for (size_t c = 0; c < n; c++) {
      for (size_t i = 0; i < n; i++)
        e[i] = i == c ? 1.0 : 0.0;
      dm_smalllu_solve(lu, n, perm, e);
      for (size_t i = 0; i < n; i++)
        inv[i * n + c] = e[i];
    }
    double dev = 0.0;
    for (size_t i = 0; i < n; i++)
      for (size_t j = 0; j < n; j++) {
        double acc = 0.0;
        for (size_t k = 0; k < n; k++)
          acc += A[i * n + k] * inv[k * n + j];
        dev = fmax(dev, fabs(acc - (i == j)));
      }
    tap_ok(dev <= 1e-13, "four solves with one factorisation: |A A^-1 - I| = %.2g", dev);
  }
}

static void test_singular(void)
{
  static double A[NM * NM], lu[NM * NM], x[NM], b[NM];
  static size_t perm[NM];
  size_t sizes[] = {3, 7, DM_SMALLLU_NMAX, DM_SMALLLU_NMAX + 5};
  for (size_t t = 0; t < sizeof sizes / sizeof *sizes; t++) {
    size_t n = sizes[t];
    random_matrix(A, n, 0);
    for (size_t j = 0; j < n; j++)          /* last row = 2.385 row 0 - row 1 */
      A[(n - 1) * n + j] = 2.385 * A[j] - A[n + j];
    random_vector(b, n);
    tap_is_int(small_solve(A, b, n, x, lu, perm), DM_ESINGULAR,
               "%zu x %zu with a dependent row: DM_ESINGULAR", n, n);
    for (size_t i = 0; i < n * n; i++)      /* the same, scaled by 1e-300: still singular */
      A[i] *= 1e-300;
    tap_is_int(small_solve(A, b, n, x, lu, perm), DM_ESINGULAR,
               "%zu x %zu dependent, scaled by 1e-300: DM_ESINGULAR", n, n);
  }
  memset(A, 0, sizeof A);
  tap_is_int(small_solve(A, b, 4, x, lu, perm), DM_ESINGULAR, "zero 4x4: DM_ESINGULAR");
  A[0] = 0.0;
  tap_is_int(small_solve(A, b, 1, x, lu, perm), DM_ESINGULAR, "zero 1x1: DM_ESINGULAR");
  /* the threshold is relative: a regular matrix at 1e-300 or 1e300 is fine */
  {
    double B[9] = {2.385, 1, 0, 1, 2.385, 1, 0, 1, 2.385}, y[3] = {1, 2, 3}, ys[3];
    for (int s = -1; s <= 1; s += 2) {
      double sc = s < 0 ? 1e-300 : 1e300, C[9], c3[3];
      for (size_t i = 0; i < 9; i++)
        C[i] = B[i] * sc;
      for (size_t i = 0; i < 3; i++)
        c3[i] = y[i] * sc;
      tap_is_int(small_solve(C, c3, 3, ys, lu, perm), DM_OK, "regular 3x3 scaled by %g factors",
                 sc);
      small_solve(B, y, 3, x, lu, perm);
      tap_ok(rel_diff(ys, x, 3) <= 4 * DBL_EPSILON, "scaled by %g: the same solution", sc);
    }
  }
  /* nearly singular: a pivot below 16 n eps max|a| is refused */
  {
    double C[4] = {2.385, 2.385, 2.385, 2.385 * (1.0 + 8 * DBL_EPSILON)};
    double D[4] = {2.385, 2.385, 2.385, 2.385 * (1.0 + 1e-10)};
    tap_is_int(dm_smalllu_factor(C, 2, perm), DM_ESINGULAR,
               "pivot 8 eps |a| (< 32 eps |a|): DM_ESINGULAR");
    tap_is_int(dm_smalllu_factor(D, 2, perm), DM_OK, "pivot 1e-10 |a|: accepted");
  }
}

static void test_nonfinite(void)
{
  static double A[NM * NM], lu[NM * NM];
  static size_t perm[NM];
  size_t sizes[] = {1, 5, DM_SMALLLU_NMAX + 1};
  for (size_t t = 0; t < sizeof sizes / sizeof *sizes; t++) {
    size_t n = sizes[t];
    for (int kind = 0; kind < 3; kind++) {
      random_matrix(A, n, 1);
      A[(n * n) / 2] = kind == 0 ? NAN : kind == 1 ? HUGE_VAL : -HUGE_VAL;
      memcpy(lu, A, n * n * sizeof(double));
      int st = dm_smalllu_factor(lu, n, perm);
      tap_is_int(st, DM_EDOM, "%zu x %zu with %s: DM_EDOM", n, n,
                 kind == 0 ? "NaN" : kind == 1 ? "Inf" : "-Inf");
      tap_ok(memcmp(lu, A, n * n * sizeof(double)) == 0, "%zu x %zu with %s: a unchanged", n, n,
             kind == 0 ? "NaN" : kind == 1 ? "Inf" : "-Inf");
    }
  }
}

int main(void)
{
  gsl_set_error_handler_off();
  rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, 2385);
  test_random();
  test_ill_conditioned();
  test_pivoting();
  test_singular();
  test_nonfinite();
  gsl_rng_free(rng);
  return tap_done();
}
