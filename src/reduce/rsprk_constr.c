/* rsprk_constr.c -- holonomic constraints ghat(y) = 0 on the preshape space
 * in the RSPRK step (thesis §2.8, Theorems 2.14 / 2.17; doc/reduce.md §11),
 * with the multiplier layout of src/integrators/prk_constrained.c and
 * its kernels (prk_kernels.h: stages, residual/Jacobian terms, impulses):
 * unknowns (Xd_i, Lt_k for the interior stages k of a Lobatto-type tableau,
 * mu0 on the initial momentum); equations
 *   r_i + G(x0)^T mu0 + sum_k at_ik G(X_k)^T Lt_k = 0,
 *   ghat(X_k) / h = 0,   ghat(x1) / h = 0;
 * then s1 gets - G(x0)^T mu0 - sum_k b_k G(X_k)^T Lt_k and the momentum
 * projection s1 <- s1 - G(x1)^T mu1 with the velocity tangent to the
 * constraint manifold.  Every stage point lies on ghat = 0.  The projection
 * in s equals the projection of the full p_x on J = mu (the connection
 * term muA(x1) is fixed), so the reduction commutes with RATTLE. */
#include <config.h>
#include "reduce/rsprk_impl.h"
#include "integrators/prk_kernels.h"

#include <math.h>
#include <string.h>

int dm_rsprk_constr_layout(dm_rsprk *P, dm_err *e)
{
  const dm_tableau *t = P->tab;
  if (dm_prk_constr_stages(t, &P->nK, P->K))
    return DM_OK;
  return dm_err_set(e, DM_EUNSUP, "constraints on the preshape space are not supported with the "
                    "%s tableau (s = %zu): use 'lobatto' (multipliers at every stage), 'trapezoid' "
                    "or 'midpoint'", t->name, t->s);
}

static int constr(dm_rsprk *P, const double *y, unsigned what, size_t slot, dm_err *e)
{
  size_t m = P->m, d = P->d;
  int st = P->sys->constraints(P->sys->data, y, P->red->par, what, P->g + slot * m,
                               P->G + slot * m * d, P->Hc + slot * m * d * d, P->work);
  if (st != 0)
    return dm_err_set(e, st > 0 ? DM_EDOM : DM_ECALLBACK, "the constraints failed (status %d)", st);
  return DM_OK;
}

int dm_rsprk_constr_begin(dm_rsprk *P, const double *x0, dm_err *e)
{
  size_t S = P->S, m = P->m;
  double gn;
  int st = constr(P, x0, DM_CONSTR_G | DM_CONSTR_DG, S, e);
  if (st != DM_OK)
    return st;
  gn = dm_rnorm_inf(P->g + S * m, m);
  if (!(gn <= 1e-8 * fmax(1.0, dm_rnorm_inf(x0, P->d))))
    return dm_err_set(e, DM_EINVAL, "the initial point violates the constraints: |g(x0)| = %.3g "
                      "(start on g = 0)", gn);
  return DM_OK;
}

/* The constraints at the constrained stages (with second derivatives when
 * jac) and at x1 = x0 + h sum b_j Xd_j, then their terms in the residual and
 * the Newton matrix (the core's dm_prk_constr_terms). */
int dm_rsprk_constr_assemble(dm_rsprk *P, double h, const double *x0, int jac, dm_err *e)
{
  size_t d = P->d, S = P->S;
  const double *b = P->tab->b;
  double *x1 = P->tmp;
  size_t kk, l, a;
  int st;
  for (kk = 0; kk < P->nK; kk++)
    if ((st = constr(P, P->Xs + P->K[kk] * d,
                     DM_CONSTR_G | DM_CONSTR_DG | (jac ? DM_CONSTR_D2G : 0u), P->K[kk], e)) != DM_OK)
      return st;
  for (a = 0; a < d; a++) {
    double acc = 0.0;
    for (l = 0; l < S; l++)
      acc += b[l] * P->X[l * d + a];
    x1[a] = x0[a] + h * acc;
  }
  if ((st = constr(P, x1, DM_CONSTR_G | DM_CONSTR_DG, S + 1, e)) != DM_OK)
    return st;
  dm_prk_constr_terms(P->tab, d, P->m, P->nK, P->K, h, P->X, P->g, P->G, P->Hc, P->R,
                      jac ? P->Jm : NULL);
  return DM_OK;
}

int dm_rsprk_project(dm_rsprk *P, const double *x1, const double *G1, double *s, dm_err *e)
{
  size_t d = P->d, m = P->m, N = d + m, i, a, c;
  double *M = P->small, *y = P->small + N * N;
  dm_lag_out o = {0, P->Lq, P->Lv, P->Lvv, P->Lvq, P->Lqq};   /* stage-0 slots as scratch */
  int st;
  memset(P->v1w, 0, d * sizeof(double));
  st = P->sys->lagrangian(P->sys->data, x1, P->v1w, P->red->par, DM_LAG_V | DM_LAG_VV, &o, P->work);
  if (st != 0)
    return dm_err_set(e, DM_EDOM, "the Routhian is outside its domain at the end point");
  memset(M, 0, N * N * sizeof(double));
  for (c = 0; c < d; c++) {
    for (i = 0; i < d; i++)
      M[c * N + i] = P->Lvv[c * d + i];
    for (a = 0; a < m; a++) {
      M[c * N + d + a] = G1[a * d + c];
      M[(d + a) * N + c] = G1[a * d + c];
    }
    y[c] = s[c] - P->Lv[c];
  }
  for (a = 0; a < m; a++)
    y[d + a] = 0.0;
  if (dm_rlu_factor(&P->lu_small, M, N) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "momentum projection onto the constraint manifold: singular "
                      "system (dependent constraint gradients or singular Mtilde)");
  dm_rlu_solve(&P->lu_small, M, N, y);
  for (c = 0; c < d; c++)
    for (a = 0; a < m; a++)
      s[c] -= G1[a * d + c] * y[d + a];
  return DM_OK;
}

int dm_rsprk_constr_finish(dm_rsprk *P, double h, const double *x0, const double *s0, double *x1,
                           double *s1, dm_err *e)
{
  const dm_routh *red = P->red;
  size_t d = P->d, S = P->S, m = P->m;
  double *G1 = P->G + (S + 1) * m * d, *pp = s1;   /* s1 is written last */
  size_t c;
  int st;
  (void)h;
  dm_prk_constr_momentum(P->tab, d, m, P->nK, P->K, P->X, P->G, P->dp);
  dm_prk_kahan(d, x0, P->dq, P->cq, x1);
  if (P->gyro) {
    /* muA(x1), reused as muA(x0) by the next step (not finite: s1 is, and
     * the step fails on it) */
    (void)dm_routh_muA(red, x1, P->a1, P->tin, P->tout, P->twork);
    for (c = 0; c < d; c++)
      P->dp[c] -= P->a1[c] - P->a0[c];
  }
  if ((st = constr(P, x1, DM_CONSTR_G | DM_CONSTR_DG, S + 1, e)) != DM_OK)
    return st;
  for (c = 0; c < d; c++)
    pp[c] = s0[c] + P->dp[c];
  memcpy(P->tmp, pp, d * sizeof(double));
  if ((st = dm_rsprk_project(P, x1, G1, P->tmp, e)) != DM_OK)
    return st;
  for (c = 0; c < d; c++)
    P->dp[c] += P->tmp[c] - pp[c];
  dm_prk_kahan(d, s0, P->dp, P->cp, s1);
  return DM_OK;
}
