/* test_dec_sparse.c -- the CSR type against dense arithmetic; CHOLMOD,
 * UMFPACK and ARPACK through it. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "dec/sparse.h"

#define NR 7
#define NC 5

static double rnd(unsigned *s)
{
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffff) / 65536.0 - 0.5;
}

static dm_sparse *random_sparse(int nr, int nc, double fill, unsigned *seed, double *dense)
{
  int ri[200], ci[200], k = 0, i, j;
  double v[200];
  memset(dense, 0, sizeof(double) * (size_t)(nr * nc));
  for (i = 0; i < nr; i++)
    for (j = 0; j < nc; j++)
      if (rnd(seed) + 0.5 < fill) {
        ri[k] = i;
        ci[k] = j;
        v[k] = 2.385 * rnd(seed);
        dense[i * nc + j] += v[k];
        k++;
      }
  return dm_sparse_from_triplets(nr, nc, k, ri, ci, v, NULL);
}

static double maxdiff_dense(const dm_sparse *A, const double *D)
{
  int i, j;
  double m = 0;
  for (i = 0; i < A->nrows; i++)
    for (j = 0; j < A->ncols; j++) {
      double d = fabs(dm_sparse_get(A, i, j) - D[i * A->ncols + j]);
      if (d > m)
        m = d;
    }
  return m;
}

static int sorted_rows(const dm_sparse *A)
{
  int i, p;
  for (i = 0; i < A->nrows; i++)
    for (p = A->rowptr[i] + 1; p < A->rowptr[i + 1]; p++)
      if (A->col[p] <= A->col[p - 1])
        return 0;
  return 1;
}

/* 1-D Dirichlet Laplacian tridiag(-1, 2, -1) of size n. */
static dm_sparse *lap1d(int n)
{
  int *ri = malloc(3 * (size_t)n * sizeof *ri), *ci = malloc(3 * (size_t)n * sizeof *ci), k = 0, i;
  double *v = malloc(3 * (size_t)n * sizeof *v);
  dm_sparse *A;
  for (i = 0; i < n; i++) {
    ri[k] = i; ci[k] = i; v[k++] = 2.0;
    if (i > 0) { ri[k] = i; ci[k] = i - 1; v[k++] = -1.0; }
    if (i + 1 < n) { ri[k] = i; ci[k] = i + 1; v[k++] = -1.0; }
  }
  A = dm_sparse_from_triplets(n, n, k, ri, ci, v, NULL);
  free(ri);
  free(ci);
  free(v);
  return A;
}

int main(void)
{
  unsigned seed = 2385;
  double Ad[NR * NC], Bd[NC * NR], Cd[NR * NR], Td[NC * NR];
  dm_sparse *A, *B, *C, *T, *S;
  dm_err e;
  int i, j, k;

  /* triplets: duplicates summed, rows sorted */
  {
    int ri[] = {2, 0, 2, 1, 2}, ci[] = {1, 3, 1, 0, 0};
    double v[] = {1.5, -2.0, 0.25, 4.0, 7.0};
    A = dm_sparse_from_triplets(3, 4, 5, ri, ci, v, NULL);
    tap_is_int(dm_sparse_nnz(A), 4, "duplicates merged");
    tap_ok(dm_sparse_get(A, 2, 1) == 1.75 && dm_sparse_get(A, 2, 0) == 7.0 &&
           dm_sparse_get(A, 0, 3) == -2.0 && dm_sparse_get(A, 1, 2) == 0.0,
           "entries of a matrix from triplets");
    tap_ok(sorted_rows(A), "columns increasing in each row");
    dm_sparse_free(A);
    ri[0] = 3;
    A = dm_sparse_from_triplets(3, 4, 5, ri, ci, v, &e);
    tap_ok(A == NULL && e.status == DM_EINVAL &&
           strcmp(e.msg, "sparse triplet 1: index (4, 2) outside 3 x 4") == 0,
           "out-of-range triplet named: %s", e.msg);
  }

  A = random_sparse(NR, NC, 0.4, &seed, Ad);
  B = random_sparse(NC, NR, 0.4, &seed, Bd);
  C = dm_sparse_mul(A, B, NULL);
  for (i = 0; i < NR; i++)
    for (j = 0; j < NR; j++) {
      double s = 0;
      for (k = 0; k < NC; k++)
        s += Ad[i * NC + k] * Bd[k * NR + j];
      Cd[i * NR + j] = s;
    }
  tap_ok(C != NULL && maxdiff_dense(C, Cd) < 1e-15 && sorted_rows(C), "product equals the dense product");
  T = dm_sparse_transpose(A, NULL);
  for (i = 0; i < NR; i++)
    for (j = 0; j < NC; j++)
      Td[j * NR + i] = Ad[i * NC + j];
  tap_ok(T->nrows == NC && maxdiff_dense(T, Td) == 0 && sorted_rows(T), "transpose");
  S = dm_sparse_add(2.0, T, -0.5, B, NULL);
  for (i = 0; i < NC * NR; i++)
    Td[i] = 2.0 * Td[i] - 0.5 * Bd[i];
  tap_ok(maxdiff_dense(S, Td) < 1e-15, "alpha A + beta B");
  {
    double x[NC], y[NR], yt[NC], z[NR];
    for (i = 0; i < NC; i++)
      x[i] = rnd(&seed);
    for (i = 0; i < NR; i++)
      z[i] = rnd(&seed);
    dm_sparse_gemv(A, x, y);
    dm_sparse_gemv_t(A, z, yt);
    double m1 = 0, m2 = 0;
    for (i = 0; i < NR; i++) {
      double s = 0;
      for (k = 0; k < NC; k++)
        s += Ad[i * NC + k] * x[k];
      m1 = fmax(m1, fabs(s - y[i]));
    }
    for (k = 0; k < NC; k++) {
      double s = 0;
      for (i = 0; i < NR; i++)
        s += Ad[i * NC + k] * z[i];
      m2 = fmax(m2, fabs(s - yt[k]));
    }
    tap_ok(m1 < 1e-15 && m2 < 1e-15, "A x and A^T x");
  }
  {
    dm_sparse *bad = dm_sparse_mul(A, A, &e);
    tap_ok(bad == NULL && strcmp(e.msg, "sparse product: 7 x 5 times 7 x 5") == 0,
           "product of incompatible sizes: %s", e.msg);
  }
  {
    unsigned char kr[NR] = {1, 0, 1, 1, 0, 1, 1}, kc[NC] = {0, 1, 1, 0, 1};
    dm_sparse *Sel = dm_sparse_select(A, kr, kc, NULL);
    int ok = Sel->nrows == 5 && Sel->ncols == 3, r = 0;
    for (i = 0; i < NR; i++) {
      int c = 0;
      if (!kr[i])
        continue;
      for (j = 0; j < NC; j++)
        if (kc[j]) {
          ok = ok && dm_sparse_get(Sel, r, c) == Ad[i * NC + j];
          c++;
        }
      r++;
    }
    tap_ok(ok, "row/column selection");
    dm_sparse_free(Sel);
  }
  dm_sparse_free(A);
  dm_sparse_free(B);
  dm_sparse_free(C);
  dm_sparse_free(T);
  dm_sparse_free(S);

  /* CHOLMOD on the 1-D Laplacian: exact solution of a quadratic */
  {
    int n = 50;
    dm_sparse *L = lap1d(n);
    dm_sparse_chol *F = dm_sparse_chol_alloc(L, &e);
    double b[100], x[100], h = 1.0 / (n + 1), m = 0;
    for (i = 0; i < n; i++)
      b[i] = b[n + i] = 2.0 * h * h;        /* -u'' = 2, u = t (1 - t) */
    tap_ok(F != NULL, "Cholesky of the 1-D Laplacian");
    dm_sparse_chol_solve(F, 2, b, x, NULL);
    for (i = 0; i < n; i++) {
      double t = (i + 1) * h;
      m = fmax(m, fabs(x[i] - t * (1 - t)));
      m = fmax(m, fabs(x[n + i] - t * (1 - t)));
    }
    tap_ok(m < 1e-13, "two right-hand sides solved exactly (max error %.2g)", m);
    tap_ok(dm_sparse_chol_rcond(F) > 1e-5, "rcond estimate positive");
    dm_sparse_chol_free(F);
    /* singular: the Neumann Laplacian */
    L->val[0] = 1.0;
    L->val[dm_sparse_nnz(L) - 1] = 1.0;
    F = dm_sparse_chol_alloc(L, &e);
    tap_ok(F == NULL && e.status == DM_ESINGULAR, "singular positive semidefinite matrix refused: %s", e.msg);
    L->val[0] = -1.0;
    F = dm_sparse_chol_alloc(L, &e);
    tap_ok(F == NULL && e.status == DM_ESINGULAR &&
           strstr(e.msg, "matrix not positive definite (at unknown ") == e.msg,
           "indefinite matrix refused, pivot named: %s", e.msg);
    /* UMFPACK on a nonsymmetric matrix */
    {
      dm_sparse *U = lap1d(n), *Ut;
      dm_sparse_lu *LU;
      double y[100], r = 0;
      for (i = 0; i < n; i++)
        if (i + 1 < n)
          U->val[U->rowptr[i + 1] - 1] = -0.25;   /* superdiagonal changed */
      LU = dm_sparse_lu_alloc(U, &e);
      for (i = 0; i < n; i++)
        x[i] = sin(2.385 * i);
      dm_sparse_gemv(U, x, b);
      dm_sparse_lu_solve(LU, b, y, NULL);
      for (i = 0; i < n; i++)
        r = fmax(r, fabs(y[i] - x[i]));
      tap_ok(LU != NULL && r < 1e-13, "UMFPACK solves a nonsymmetric system (error %.2g)", r);
      Ut = dm_sparse_transpose(U, NULL);
      tap_ok(dm_sparse_asymmetry(U) == 0.75, "asymmetry of a nonsymmetric matrix");
      dm_sparse_lu_free(LU);
      dm_sparse_free(Ut);
      for (i = U->rowptr[3]; i < U->rowptr[4]; i++)
        U->val[i] = 0.0;
      LU = dm_sparse_lu_alloc(U, &e);
      tap_ok(LU == NULL && e.status == DM_ESINGULAR, "singular matrix refused by LU: %s", e.msg);
      dm_sparse_free(U);
    }
    dm_sparse_free(L);
  }

  /* ARPACK: lowest eigenvalues of the 1-D Laplacian with a mass */
  {
    int n = 200, nev = 4;
    dm_sparse *L = lap1d(n);
    double *m = malloc((size_t)n * sizeof *m), lam[4], *vec = malloc((size_t)n * nev * sizeof *vec);
    double err = 0, orth = 0;
    for (i = 0; i < n; i++)
      m[i] = 2.385;
    tap_ok(dm_sparse_eigsh(L, m, nev, -1e-3, 0, lam, vec, &e) == DM_OK, "eigsh runs");
    for (k = 0; k < nev; k++) {
      double want = (2 - 2 * cos((k + 1) * M_PI / (n + 1))) / 2.385;
      err = fmax(err, fabs(lam[k] - want) / want);
    }
    for (j = 0; j < nev; j++)
      for (k = 0; k < nev; k++) {
        double s = 0;
        for (i = 0; i < n; i++)
          s += vec[j * n + i] * m[i] * vec[k * n + i];
        orth = fmax(orth, fabs(s - (j == k)));
      }
    tap_ok(err < 1e-12, "4 lowest eigenvalues to %.2g relative", err);
    tap_ok(orth < 1e-12, "eigenvectors mass-orthonormal (%.2g)", orth);
    tap_ok(dm_sparse_eigsh(L, m, n, 0, 0, lam, vec, &e) == DM_EINVAL, "too many eigenpairs: %s", e.msg);
    m[3] = -1;
    tap_ok(dm_sparse_eigsh(L, m, 2, 0, 0, lam, vec, &e) == DM_EINVAL &&
           strcmp(e.msg, "eigenpairs: mass entry 4 is -1 (positive expected)") == 0,
           "nonpositive mass refused: %s", e.msg);
    free(m);
    free(vec);
    dm_sparse_free(L);
  }
  dm_sparse_free(NULL);
  dm_sparse_chol_free(NULL);
  dm_sparse_lu_free(NULL);
  return tap_done();
}
