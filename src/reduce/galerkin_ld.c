/* galerkin_ld.c -- the Galerkin discrete Lagrangian of a PRK tableau on a
 * (full, unforced, unconstrained) system as a two-point function with
 * derivatives (thesis §2.4, Theorem 2.12; Suris): given (q0, q1) solve for
 * the stage velocities V_i and p0
 *   Lv(Q_i, V_i) - p0 - h sum_j at_ij Lq(Q_j, V_j) = 0,  Q_i = q0 + h sum_j a_ij V_j,
 *   sum_j b_j V_j - (q1 - q0)/h = 0,
 * then p0 = -D1 Ld, p1 = p0 + h sum_j b_j Lq_j = D2 Ld, Ld = h sum_j b_j L_j.
 * Newton with the exact Jacobian; the second derivatives dp0/dq0, dp0/dq1,
 * dp1/dq0, dp1/dq1 by the implicit function theorem at the solution.  The
 * discrete Routh equations (discrete_routh.c) build psi_mu, the reduced
 * discrete Lagrangian and its one-forms on it. */
#include <config.h>
#include "reduce/routh_impl.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct dm_gld {
  const dm_system *sys;
  dm_tableau *tab;
  size_t n, S, Sn, nn, N;
  double tol;
  int maxiter, iters, warm_ok;
  double *Jm, *R, *Z, *Q, *Lq, *Lv, *Lvv, *Lvq, *Lqq, *Lval, *rhs, *dQ;
  dm_rlu lu;
  void *work;
};

void dm_gld_free(dm_gld *g)
{
  if (g == NULL)
    return;
  free(g->Jm);
  free(g->work);
  dm_rlu_free(&g->lu);
  dm_tableau_free(g->tab);
  free(g);
}

int dm_gld_iters(const dm_gld *g)
{
  return g->iters;
}

int dm_gld_alloc(const dm_system *sys, const dm_tableau *t, double tol, int maxiter, dm_gld **out,
                 dm_err *e)
{
  dm_gld *g = calloc(1, sizeof *g);
  size_t n = sys->n, S = t->s, nn = n * n, Sn = S * n, N = Sn + n;
  double *p;
  *out = NULL;
  if (g == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  g->sys = sys;
  g->n = n;
  g->S = S;
  g->Sn = Sn;
  g->nn = nn;
  g->N = N;
  g->tol = tol;
  g->maxiter = maxiter;
  g->tab = dm_tableau_copy(t);
  g->Jm = calloc(N * N + 2 * N + 4 * Sn + 3 * S * nn + S + N * 2 * n + Sn, sizeof(double));
  g->work = sys->work_size ? malloc(sys->work_size) : NULL;
  if (g->tab == NULL || g->Jm == NULL || (sys->work_size && g->work == NULL)
      || dm_rlu_init(&g->lu, N) != DM_OK) {
    dm_gld_free(g);
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  p = g->Jm + N * N;
  g->R = p; p += N;
  g->Z = p; p += N;
  g->Q = p; p += Sn;
  g->Lq = p; p += Sn;
  g->Lv = p; p += Sn;
  g->dQ = p; p += Sn;
  g->Lvv = p; p += S * nn;
  g->Lvq = p; p += S * nn;
  g->Lqq = p; p += S * nn;
  g->Lval = p; p += S;
  g->rhs = p;
  *out = g;
  return DM_OK;
}

static int assemble(dm_gld *g, double h, const double *q0, const double *q1, int jac, dm_err *e)
{
  size_t n = g->n, S = g->S, nn = g->nn, Sn = g->Sn, N = g->N, i, j, k, a, c;
  const double *A = g->tab->a, *At = g->tab->at, *b = g->tab->b, *V = g->Z, *p0 = g->Z + Sn;
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < S; j++)
        acc += A[i * S + j] * V[j * n + a];
      g->Q[i * n + a] = q0[a] + h * acc;
    }
  for (i = 0; i < S; i++) {
    dm_lag_out o = {0, g->Lq + i * n, g->Lv + i * n, g->Lvv + i * nn, g->Lvq + i * nn,
                    g->Lqq + i * nn};
    unsigned what = DM_LAG_GRAD | (jac ? (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ) : 0u);
    int st = g->sys->lagrangian(g->sys->data, g->Q + i * n, V + i * n, g->sys->par, what, &o,
                                g->work);
    if (st != 0)
      return dm_err_set(e, st > 0 ? DM_EDOM : DM_ECALLBACK, "discrete Lagrangian: L is outside its "
                        "domain at a stage point");
    g->Lval[i] = o.L;
  }
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < S; j++)
        acc += At[i * S + j] * g->Lq[j * n + a];
      g->R[i * n + a] = g->Lv[i * n + a] - p0[a] - h * acc;
    }
  for (a = 0; a < n; a++) {
    double acc = 0.0;
    for (j = 0; j < S; j++)
      acc += b[j] * V[j * n + a];
    g->R[Sn + a] = acc - (q1[a] - q0[a]) / h;
  }
  if (!jac)
    return DM_OK;
  memset(g->Jm, 0, N * N * sizeof(double));
  for (i = 0; i < S; i++)
    for (k = 0; k < S; k++)
      for (a = 0; a < n; a++)
        for (c = 0; c < n; c++) {
          double v = h * A[i * S + k] * g->Lvq[i * nn + a * n + c]
                     - h * At[i * S + k] * g->Lvq[k * nn + c * n + a];
          if (i == k)
            v += g->Lvv[i * nn + a * n + c];
          for (j = 0; j < S; j++)
            v -= h * h * At[i * S + j] * A[j * S + k] * g->Lqq[j * nn + a * n + c];
          g->Jm[(i * n + a) * N + k * n + c] = v;
        }
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      g->Jm[(i * n + a) * N + Sn + a] = -1.0;
      g->Jm[(Sn + a) * N + i * n + a] = b[i];
    }
  return DM_OK;
}

int dm_gld_solve(dm_gld *g, double h, const double *q0, const double *q1, double *p0, double *p1,
                 double *Ld, int deriv, double *d00, double *d01, double *d10, double *d11,
                 int warm, dm_err *e)
{
  size_t n = g->n, S = g->S, Sn = g->Sn, N = g->N, nn = g->nn, i, j, k, a, c, x;
  const double *A = g->tab->a, *At = g->tab->at, *b = g->tab->b;
  double dn = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st, ok = 0;
  if (h == 0.0)
    return dm_err_set(e, DM_EINVAL, "discrete Lagrangian needs h != 0");
  if (!(warm && g->warm_ok))
    for (i = 0; i < S; i++)
      for (a = 0; a < n; a++)
        g->Z[i * n + a] = (q1[a] - q0[a]) / h;
  memset(g->Z + Sn, 0, n * sizeof(double));
  for (it = 1; it <= g->maxiter; it++) {
    double vs, ps;
    if ((st = assemble(g, h, q0, q1, 1, e)) != DM_OK) {
      g->warm_ok = 0;
      return st;
    }
    if ((st = dm_rlu_factor(&g->lu, g->Jm, N)) != DM_OK) {
      g->warm_ok = 0;
      return dm_err_set(e, DM_ESINGULAR, "discrete Lagrangian: singular boundary problem (h = %g)", h);
    }
    dm_rlu_solve(&g->lu, g->Jm, N, g->R);
    for (i = 0; i < N; i++)
      g->Z[i] -= g->R[i];
    vs = fmax(dm_rnorm_inf(g->Z, Sn), DBL_MIN);
    ps = fmax(dm_rnorm_inf(g->Z + Sn, n) + fabs(h) * dm_rnorm_inf(g->Lq, Sn), DBL_MIN);
    dn = fmax(dm_rnorm_inf(g->R, Sn) / vs, dm_rnorm_inf(g->R + Sn, n) / ps);
    if (!isfinite(dn))
      break;
    if (dm_newton_done(&stop, dn, g->tol)) {
      ok = 1;
      break;
    }
  }
  g->iters = it > g->maxiter ? g->maxiter : it;
  if (!ok) {
    g->warm_ok = 0;
    return dm_err_set(e, DM_ENOCONV, "discrete Lagrangian: Newton on the boundary problem did not "
                      "converge (update %.3g, h = %g)", dn, h);
  }
  g->warm_ok = 1;
  /* converged values (and the Jacobian factor at them when derivatives are wanted) */
  if ((st = assemble(g, h, q0, q1, deriv, e)) != DM_OK)
    return st;
  if (Ld) {
    *Ld = 0.0;
    for (i = 0; i < S; i++)
      *Ld += h * b[i] * g->Lval[i];
  }
  for (a = 0; a < n; a++) {
    double acc = 0.0;
    for (i = 0; i < S; i++)
      acc += b[i] * g->Lq[i * n + a];
    if (p0)
      p0[a] = g->Z[Sn + a];
    if (p1)
      p1[a] = g->Z[Sn + a] + h * acc;
  }
  if (!deriv)
    return DM_OK;
  if (dm_rlu_factor(&g->lu, g->Jm, N) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "discrete Lagrangian: singular boundary problem (h = %g)", h);
  /* columns: q0 (0..n), q1 (n..2n) */
  for (c = 0; c < 2 * n; c++) {
    double *dZ = g->rhs + c * N;
    for (i = 0; i < S; i++)
      for (a = 0; a < n; a++) {
        double v = 0.0;
        if (c < n) {
          v = g->Lvq[i * nn + a * n + c];
          for (j = 0; j < S; j++)
            v -= h * At[i * S + j] * g->Lqq[j * nn + a * n + c];
        }
        dZ[i * n + a] = -v;
      }
    for (a = 0; a < n; a++)
      dZ[Sn + a] = c < n ? (a == c ? -1.0 / h : 0.0) : (a == c - n ? 1.0 / h : 0.0);
    dm_rlu_solve(&g->lu, g->Jm, N, dZ);
    for (j = 0; j < S; j++)
      for (a = 0; a < n; a++) {
        double acc = 0.0;
        for (k = 0; k < S; k++)
          acc += A[j * S + k] * dZ[k * n + a];
        g->dQ[j * n + a] = (c < n && a == c ? 1.0 : 0.0) + h * acc;
      }
    for (a = 0; a < n; a++) {
      double dp0 = dZ[Sn + a], dp1 = 0.0;
      for (j = 0; j < S; j++) {
        double f = 0.0;
        for (x = 0; x < n; x++)
          f += g->Lqq[j * nn + a * n + x] * g->dQ[j * n + x]
               + g->Lvq[j * nn + x * n + a] * dZ[j * n + x];
        dp1 += b[j] * f;
      }
      dp1 = dp0 + h * dp1;
      if (c < n) {
        d00[a * n + c] = dp0;
        d10[a * n + c] = dp1;
      } else {
        d01[a * n + c - n] = dp0;
        d11[a * n + c - n] = dp1;
      }
    }
  }
  return DM_OK;
}
