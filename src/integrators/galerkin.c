/* galerkin.c -- the Galerkin discrete Lagrangian as a two-point function:
 * Newton on the boundary problem for (V, p0), then Ld, p0, p1 and the
 * second derivatives by the implicit function theorem (see galerkin.h).
 *
 * Unknowns Z = (V_1 .. V_s, p0), N = s n + n.  Residual
 *   R_i = Lv_i - p0 - h sum_j at_ij W_j,   R_s = sum_j b_j V_j - (q1 - q0)/h,
 * Jacobian (D = Lqq + Fq, Bm = Lvq^T + Fv)
 *   dR_i/dV_k = d_ik Lvv_i + h a_ik Lvq_i - h at_ik Bm_k - h^2 sum_j at_ij a_jk D_j,
 *   dR_i/dp0 = -I,  dR_s/dV_k = b_k I.
 * Full Newton (the Jacobian is factored at every iterate, and at the
 * solution again for the derivatives); stopping rule of src/core/newton.h
 * on the update scaled by max|V| (velocities) and |p0| + |h| max|W|
 * (momentum).  Derivatives: dZ/dq0 and dZ/dq1 from J dZ = -dR/dq with
 *   dR_i/dq0 = Lvq_i - h sum_j at_ij D_j,  dR_i/dq1 = 0,
 *   dR_s/dq0 = -I/h,  dR_s/dq1 = I/h,
 * then dQ_j = dq0 + h sum_k a_jk dV_k and dp1 = dp0 + h sum_j b_j (D_j dQ_j
 * + Bm_j dV_j). */
#include <config.h>
#include "integrators/galerkin.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/newton.h"
#include "core/smalllu.h"

struct dm_galerkin {
  const dm_system *sys;
  dm_tableau *tab;
  size_t n, S, Sn, nn, N;
  int forced;
  double tol;
  int maxiter, iters, warm_ok;
  double *Jm, *R, *Z, *Q, *Lq, *Lv, *W, *F, *Lvv, *Lvq, *Lqq, *D, *Bm, *Fq, *Fv, *Lval, *rhs,
    *dQ;
  size_t *perm;
  void *work;
};

void dm_galerkin_free(dm_galerkin *g)
{
  if (g == NULL)
    return;
  free(g->Jm);
  free(g->perm);
  free(g->work);
  dm_tableau_free(g->tab);
  free(g);
}

int dm_galerkin_iters(const dm_galerkin *g)
{
  return g->iters;
}

int dm_galerkin_alloc(const dm_system *sys, const dm_tableau *t, double tol, int maxiter,
                      dm_galerkin **out, dm_err *e)
{
  dm_galerkin *g;
  size_t n = sys->n, S = t->s, nn = n * n, Sn = S * n, N = Sn + n;
  double *p;
  *out = NULL;
  if (sys->m > 0)
    return dm_err_set(e, DM_EINVAL, "the Galerkin discrete Lagrangian is for unconstrained systems");
  if ((g = calloc(1, sizeof *g)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  g->sys = sys;
  g->n = n;
  g->S = S;
  g->Sn = Sn;
  g->nn = nn;
  g->N = N;
  g->forced = sys->force != NULL;
  g->tol = tol;
  g->maxiter = maxiter;
  g->tab = dm_tableau_copy(t);
  g->Jm = calloc(N * N + 2 * N + 7 * Sn + 7 * S * nn + S + N * 2 * n, sizeof(double));
  g->perm = calloc(N, sizeof *g->perm);
  g->work = sys->work_size ? malloc(sys->work_size) : NULL;
  if (g->tab == NULL || g->Jm == NULL || g->perm == NULL || (sys->work_size && g->work == NULL)) {
    dm_galerkin_free(g);
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  p = g->Jm + N * N;
  g->R = p; p += N;
  g->Z = p; p += N;
  g->Q = p; p += Sn;
  g->Lq = p; p += Sn;
  g->Lv = p; p += Sn;
  g->W = p; p += Sn;
  g->F = p; p += Sn;
  g->dQ = p; p += Sn;
  p += Sn;
  g->Lvv = p; p += S * nn;
  g->Lvq = p; p += S * nn;
  g->Lqq = p; p += S * nn;
  g->D = p; p += S * nn;
  g->Bm = p; p += S * nn;
  g->Fq = p; p += S * nn;
  g->Fv = p; p += S * nn;
  g->Lval = p; p += S;
  g->rhs = p;
  *out = g;
  return DM_OK;
}

/* max |x_i|; NaN when some x_i is NaN or infinite */
static double norm_inf(const double *x, size_t n)
{
  double m = 0.0, z = 0.0;
  size_t i;
  for (i = 0; i < n; i++) {
    double a = fabs(x[i]);
    m = a > m ? a : m;
    z += x[i] * 0.0;
  }
  return z == z ? m : NAN;
}

/* L (and F) at stage i: W = Lq + F; with jac also D = Lqq + Fq and
 * Bm = Lvq^T + Fv. */
static int eval_stage(dm_galerkin *g, size_t i, int jac, dm_err *e)
{
  const dm_system *sys = g->sys;
  size_t n = g->n, nn = g->nn, a, c, k = i * n, kk = i * nn;
  const double *Qi = g->Q + k, *Vi = g->Z + k;
  dm_lag_out o = {0, g->Lq + k, g->Lv + k, g->Lvv + kk, g->Lvq + kk, g->Lqq + kk};
  unsigned what = DM_LAG_GRAD | (jac ? (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ) : 0u);
  int st = sys->lagrangian(sys->data, Qi, Vi, sys->par, what, &o, g->work);
  if (st != 0)
    return dm_err_set(e, st > 0 ? DM_EDOM : DM_ECALLBACK, "discrete Lagrangian: L is outside its "
                      "domain at a stage point");
  g->Lval[i] = o.L;
  if (g->forced) {
    st = sys->force(sys->data, Qi, Vi, sys->par, DM_FORCE_F | (jac ? DM_FORCE_Q | DM_FORCE_V : 0u),
                    g->F + k, g->Fq + kk, g->Fv + kk, g->work);
    if (st != 0)
      return dm_err_set(e, st > 0 ? DM_EDOM : DM_ECALLBACK, "discrete Lagrangian: the force is "
                        "outside its domain at a stage point");
  }
  for (a = 0; a < n; a++)
    g->W[k + a] = g->forced ? g->Lq[k + a] + g->F[k + a] : g->Lq[k + a];
  if (jac)
    for (a = 0; a < n; a++)
      for (c = 0; c < n; c++) {
        g->D[kk + a * n + c] = g->forced ? g->Lqq[kk + a * n + c] + g->Fq[kk + a * n + c]
                                         : g->Lqq[kk + a * n + c];
        g->Bm[kk + a * n + c] = g->forced ? g->Lvq[kk + c * n + a] + g->Fv[kk + a * n + c]
                                          : g->Lvq[kk + c * n + a];
      }
  return DM_OK;
}

/* Residual at Z (and the Jacobian when jac). */
static int assemble(dm_galerkin *g, double h, const double *q0, const double *q1, int jac,
                    dm_err *e)
{
  size_t n = g->n, S = g->S, nn = g->nn, Sn = g->Sn, N = g->N, i, j, k, a, c;
  const double *A = g->tab->a, *At = g->tab->at, *b = g->tab->b, *V = g->Z, *p0 = g->Z + Sn;
  int st;
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < S; j++)
        acc += A[i * S + j] * V[j * n + a];
      g->Q[i * n + a] = q0[a] + h * acc;
    }
  for (i = 0; i < S; i++)
    if ((st = eval_stage(g, i, jac, e)) != DM_OK)
      return st;
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < S; j++)
        acc += At[i * S + j] * g->W[j * n + a];
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
                     - h * At[i * S + k] * g->Bm[k * nn + a * n + c];
          if (i == k)
            v += g->Lvv[i * nn + a * n + c];
          for (j = 0; j < S; j++)
            v -= h * h * At[i * S + j] * A[j * S + k] * g->D[j * nn + a * n + c];
          g->Jm[(i * n + a) * N + k * n + c] = v;
        }
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      g->Jm[(i * n + a) * N + Sn + a] = -1.0;
      g->Jm[(Sn + a) * N + i * n + a] = b[i];
    }
  return DM_OK;
}

static int newton(dm_galerkin *g, double h, const double *q0, const double *q1, dm_err *e)
{
  size_t n = g->n, Sn = g->Sn, N = g->N, i;
  double dn = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st;
  for (it = 1; it <= g->maxiter; it++) {
    double vs, ps;
    if ((st = assemble(g, h, q0, q1, 1, e)) != DM_OK)
      return st;
    if (dm_smalllu_factor(g->Jm, N, g->perm) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "discrete Lagrangian: singular boundary problem (h = %g)",
                        h);
    dm_smalllu_solve(g->Jm, N, g->perm, g->R);
    for (i = 0; i < N; i++)
      g->Z[i] -= g->R[i];
    vs = fmax(norm_inf(g->Z, Sn), DBL_MIN);
    ps = fmax(norm_inf(g->Z + Sn, n) + fabs(h) * norm_inf(g->W, Sn), DBL_MIN);
    dn = fmax(norm_inf(g->R, Sn) / vs, norm_inf(g->R + Sn, n) / ps);
    if (!isfinite(dn))
      break;
    if (dm_newton_done(&stop, dn, g->tol)) {
      g->iters = it;
      return DM_OK;
    }
  }
  g->iters = it > g->maxiter ? g->maxiter : it;
  return dm_err_set(e, DM_ENOCONV, "discrete Lagrangian: Newton on the boundary problem did not "
                    "converge in %d iterations (update %.3g > tol %.3g, h = %g)", g->iters, dn,
                    g->tol, h);
}

/* Column c of [dZ/dq0 | dZ/dq1] into dZ (N values), J factored at the
 * solution. */
static void dZ_column(dm_galerkin *g, double h, size_t c, double *dZ)
{
  size_t n = g->n, S = g->S, Sn = g->Sn, nn = g->nn, i, j, a;
  const double *At = g->tab->at;
  for (i = 0; i < S; i++)
    for (a = 0; a < n; a++) {
      double v = 0.0;
      if (c < n) {
        v = g->Lvq[i * nn + a * n + c];
        for (j = 0; j < S; j++)
          v -= h * At[i * S + j] * g->D[j * nn + a * n + c];
      }
      dZ[i * n + a] = -v;
    }
  for (a = 0; a < n; a++)
    dZ[Sn + a] = c < n ? (a == c ? -1.0 / h : 0.0) : (a == c - n ? 1.0 / h : 0.0);
  dm_smalllu_solve(g->Jm, g->N, g->perm, dZ);
}

static int derivatives(dm_galerkin *g, double h, double *d00, double *d01, double *d10,
                       double *d11, dm_err *e)
{
  size_t n = g->n, S = g->S, Sn = g->Sn, nn = g->nn, j, k, a, c, x;
  const double *A = g->tab->a, *b = g->tab->b;
  if (dm_smalllu_factor(g->Jm, g->N, g->perm) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "discrete Lagrangian: singular boundary problem (h = %g)", h);
  for (c = 0; c < 2 * n; c++) {
    double *dZ = g->rhs + c * g->N;
    dZ_column(g, h, c, dZ);
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
          f += g->D[j * nn + a * n + x] * g->dQ[j * n + x] + g->Bm[j * nn + a * n + x] * dZ[j * n + x];
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

int dm_galerkin_solve(dm_galerkin *g, double h, const double *q0, const double *q1, double *Ld,
                      double *p0, double *p1, double *d00, double *d01, double *d10,
                      double *d11, int warm, dm_err *e)
{
  size_t n = g->n, S = g->S, Sn = g->Sn, i, a;
  const double *b = g->tab->b;
  int st, deriv = d00 != NULL;
  if (h == 0.0)
    return dm_err_set(e, DM_EINVAL, "discrete Lagrangian needs h != 0");
  if (!(warm && g->warm_ok))
    for (i = 0; i < S; i++)
      for (a = 0; a < n; a++)
        g->Z[i * n + a] = (q1[a] - q0[a]) / h;
  memset(g->Z + Sn, 0, n * sizeof(double));
  g->warm_ok = 0;
  if ((st = newton(g, h, q0, q1, e)) != DM_OK)
    return st;
  g->warm_ok = 1;
  /* values at the solution (and the Jacobian there for the derivatives) */
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
      acc += b[i] * g->W[i * n + a];
    if (p0)
      p0[a] = g->Z[Sn + a];
    if (p1)
      p1[a] = g->Z[Sn + a] + h * acc;
  }
  return deriv ? derivatives(g, h, d00, d01, d10, d11, e) : DM_OK;
}
