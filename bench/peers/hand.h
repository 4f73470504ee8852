/* hand.h -- the benchmark algorithms written by hand, as a person would for
 * one problem: the force is inlined (static inline from problems.h), no
 * function pointers, no compensated summation unless the name says so.
 *
 *   hand_sv_<prob>(h, N, q, p)        plain leapfrog (velocity Verlet, one force
 *                                     evaluation per step, first same as last)
 *   hand_sv_kahan_<prob>(h, N, q, p)  the same with Kahan-compensated q, p
 *                                     updates (what dmech's Stormer-Verlet does)
 *   hand_gauss2_<prob>(h, N, q, p)    2-stage Gauss (order 4) for q'' = f(q):
 *                                     stage displacements Z_i = Q_i - q0 solve
 *                                     Z_i = h c_i p0 + h^2 sum_k (A^2)_ik f(q0 + Z_k)
 *                                     by simplified Newton (Jacobian
 *                                     I - h^2 A^2 (x) Df(q0), LU with partial
 *                                     pivoting once per step), Taylor predictor,
 *                                     iterated to round-off (update <= 4 eps |q0|
 *                                     or no further decrease, at most 30 iterations).
 *                                     Returns the total number of iterations.
 * State (q, p) is updated in place. */
#ifndef BENCH_HAND_H
#define BENCH_HAND_H

#include <float.h>
#include <math.h>
#include <string.h>
#include "problems.h"

#define HAND_SV(NAME, N, FORCE)                                                  \
  static inline void NAME(double h, long steps, double *q, double *p)           \
  {                                                                              \
    double f[N];                                                                 \
    long k;                                                                      \
    int i;                                                                       \
    FORCE(q, f);                                                                 \
    for (k = 0; k < steps; k++) {                                                \
      for (i = 0; i < N; i++) {                                                  \
        p[i] += 0.5 * h * f[i];                                                  \
        q[i] += h * p[i];                                                        \
      }                                                                          \
      FORCE(q, f);                                                               \
      for (i = 0; i < N; i++)                                                    \
        p[i] += 0.5 * h * f[i];                                                  \
    }                                                                            \
  }

#define HAND_SV_KAHAN(NAME, N, FORCE)                                            \
  static inline void NAME(double h, long steps, double *q, double *p)           \
  {                                                                              \
    double f0[N], f1[N], cq[N] = {0}, cp[N] = {0}, ph[N];                        \
    long k;                                                                      \
    int i;                                                                       \
    FORCE(q, f0);                                                                \
    for (k = 0; k < steps; k++) {                                                \
      for (i = 0; i < N; i++) {                                                  \
        double y, t;                                                             \
        ph[i] = p[i] + 0.5 * h * f0[i];                                          \
        y = h * ph[i] - cq[i];                                                   \
        t = q[i] + y;                                                            \
        cq[i] = (t - q[i]) - y;                                                  \
        q[i] = t;                                                                \
      }                                                                          \
      FORCE(q, f1);                                                              \
      for (i = 0; i < N; i++) {                                                  \
        double y = 0.5 * h * (f0[i] + f1[i]) - cp[i], t = p[i] + y;              \
        cp[i] = (t - p[i]) - y;                                                  \
        p[i] = t;                                                                \
        f0[i] = f1[i];                                                           \
      }                                                                          \
    }                                                                            \
  }

/* dense LU with partial pivoting of an m x m matrix (m <= 8), in place */
static inline int hand_lu(double *J, int m, int *perm)
{
  int i, j, k;
  for (k = 0; k < m; k++) {
    int piv = k;
    double best = fabs(J[k * m + k]);
    for (i = k + 1; i < m; i++)
      if (fabs(J[i * m + k]) > best) {
        best = fabs(J[i * m + k]);
        piv = i;
      }
    perm[k] = piv;
    if (best == 0.0)
      return -1;
    if (piv != k)
      for (j = 0; j < m; j++) {
        double t = J[k * m + j];
        J[k * m + j] = J[piv * m + j];
        J[piv * m + j] = t;
      }
    for (i = k + 1; i < m; i++) {
      double l = J[i * m + k] /= J[k * m + k];
      for (j = k + 1; j < m; j++)
        J[i * m + j] -= l * J[k * m + j];
    }
  }
  return 0;
}

static inline void hand_lu_solve(const double *J, int m, const int *perm, double *x)
{
  int i, j;
  for (i = 0; i < m; i++) {
    double t = x[perm[i]];
    x[perm[i]] = x[i];
    x[i] = t;
    for (j = 0; j < i; j++)
      x[i] -= J[i * m + j] * x[j];
  }
  for (i = m - 1; i >= 0; i--) {
    for (j = i + 1; j < m; j++)
      x[i] -= J[i * m + j] * x[j];
    x[i] /= J[i * m + i];
  }
}

#define HAND_GAUSS2(NAME, N, FORCE, DFORCE)                                      \
  static inline long NAME(double h, long steps, double *q, double *p)           \
  {                                                                              \
    const double s3 = sqrt(3.0), c[2] = {0.5 - s3 / 6, 0.5 + s3 / 6};            \
    const double A[2][2] = {{0.25, 0.25 - s3 / 6}, {0.25 + s3 / 6, 0.25}};       \
    double A2[2][2], bA[2], Z[2][N], F[2][N], Qs[N], D[N * N], J[4 * N * N];     \
    double r[2 * N], f0[N];                                                      \
    int perm[2 * N], i, j, k, l, m = 2 * N;                                      \
    long st, iters = 0;                                                          \
    for (i = 0; i < 2; i++) {                                                    \
      for (j = 0; j < 2; j++)                                                    \
        A2[i][j] = A[i][0] * A[0][j] + A[i][1] * A[1][j];                        \
      bA[i] = 0.5 * (A[0][i] + A[1][i]);                                         \
    }                                                                            \
    for (st = 0; st < steps; st++) {                                             \
      double scale = 0.0, prev = HUGE_VAL;                                       \
      int it;                                                                    \
      FORCE(q, f0);                                                              \
      DFORCE(q, D);                                                              \
      for (i = 0; i < N; i++)                                                    \
        scale = fmax(scale, fabs(q[i]));                                         \
      for (i = 0; i < 2; i++)                                                    \
        for (k = 0; k < 2; k++)                                                  \
          for (j = 0; j < N; j++)                                                \
            for (l = 0; l < N; l++)                                              \
              J[(i * N + j) * m + k * N + l] =                                   \
                (i == k && j == l ? 1.0 : 0.0) - h * h * A2[i][k] * D[j * N + l];\
      hand_lu(J, m, perm);                                                       \
      for (i = 0; i < 2; i++)                                                    \
        for (j = 0; j < N; j++)                                                  \
          Z[i][j] = h * c[i] * p[j] + 0.5 * h * h * c[i] * c[i] * f0[j];         \
      for (it = 1; it <= 30; it++) {                                             \
        double d = 0.0;                                                          \
        for (i = 0; i < 2; i++) {                                                \
          for (j = 0; j < N; j++)                                                \
            Qs[j] = q[j] + Z[i][j];                                              \
          FORCE(Qs, F[i]);                                                       \
        }                                                                        \
        for (i = 0; i < 2; i++)                                                  \
          for (j = 0; j < N; j++)                                                \
            r[i * N + j] = -(Z[i][j] - h * c[i] * p[j]                           \
                             - h * h * (A2[i][0] * F[0][j] + A2[i][1] * F[1][j]));\
        hand_lu_solve(J, m, perm, r);                                            \
        for (i = 0; i < 2; i++)                                                  \
          for (j = 0; j < N; j++) {                                              \
            Z[i][j] += r[i * N + j];                                             \
            d = fmax(d, fabs(r[i * N + j]));                                     \
          }                                                                      \
        iters++;                                                                 \
        if (d <= 4 * DBL_EPSILON * scale || d >= prev)                           \
          break;                                                                 \
        prev = d;                                                                \
      }                                                                          \
      for (j = 0; j < N; j++) {                                                  \
        q[j] += h * p[j] + h * h * (bA[0] * F[0][j] + bA[1] * F[1][j]);          \
        p[j] += 0.5 * h * (F[0][j] + F[1][j]);                                   \
      }                                                                          \
    }                                                                            \
    return iters;                                                                \
  }

HAND_SV(hand_sv_kepler, KEP_N, kep_force)
HAND_SV(hand_sv_j2, J2_N, j2_force)
HAND_SV_KAHAN(hand_sv_kahan_kepler, KEP_N, kep_force)
HAND_GAUSS2(hand_gauss2_j2, J2_N, j2_force, j2_dforce)
HAND_GAUSS2(hand_gauss2_kepler, KEP_N, kep_force, kep_dforce)

#endif
