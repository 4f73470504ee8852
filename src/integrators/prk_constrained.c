/* prk_constrained.c -- holonomic constraints g(q) = 0 (m of them) in the
 * implicit PRK step: Lagrange multipliers at the stages (doc/integrators.md §10,
 * thesis §2.8; Jay's Lobatto IIIA-IIIB SPARK form for index-3 mechanics).
 *
 * Formulation.  With the augmented Lagrangian L - lambda^T g, the stage
 * forces become W_j - G(Q_j)^T lambda_j.  Write Lt_k = h lambda_k (momentum
 * units).  Unknowns:
 *   V_i (s n)          stage velocities,
 *   Lt_k (m each)      multipliers at the constrained interior stages k in K,
 *   mu0 (m)            the multiplier acting on the initial momentum
 *                      (the node multiplier of the constrained DEL at q0).
 * Equations:
 *   Lv(Q_i, V_i) = p0 - G(q0)^T mu0 + h sum_j at_ij W_j - sum_{k in K} at_ik G(Q_k)^T Lt_k
 *   g(Q_k) / h = 0   (k in K),        g(q1) / h = 0,   q1 = q0 + h sum b_j V_j.
 * Then p1' = p0 - G(q0)^T mu0 + h sum_j b_j W_j - sum_{k in K} b_k G(Q_k)^T Lt_k and
 * the momentum projection p1 = p1' - G(q1)^T mu1 with mu1 such that the
 * velocity v1 (Lv(q1, v1) = p1) is tangent: G(q1) v1 = 0.
 *
 * Which stages carry multipliers:
 *  - Lobatto-type tableaus (c_1 = 0, c_s = 1, first row of a zero, last row
 *    of a = b, last column of at zero, first column of at = b_1): Q_1 = q0
 *    and Q_s = q1, so K = the interior stages 2..s-1; mu0 is h b_1 lambda_1
 *    and mu1 is h b_s lambda_s.  Every stage point lies on g = 0.  This is
 *    the Lobatto IIIA-IIIB constrained method (order 2s-2, symplectic on
 *    T*N); s = 2 is RATTLE (SHAKE for the positions, projection for p).
 *  - one-stage tableaus (midpoint): K is empty; the constrained discrete
 *    Euler-Lagrange equations with multipliers at the nodes (Marsden-West
 *    constrained DEL in position-momentum form), order 2.
 *  - Gauss with s >= 2 (and other tableaus): not supported.  A polynomial
 *    of degree s cannot put all s Gauss stage points and both end points on
 *    a curved constraint manifold consistently (on a circle the polynomial
 *    would be forced to nearly constant speed; the stage equations become
 *    inconsistent), and constraining only the nodes drops the order to 2.
 * The Newton matrix, in the unknown order (V, Lt_K, mu0):
 *   [ J_il + sum_k at_ik h a_kl (Lt_k . d2g(Q_k))   at_ik G_k^T   G0^T ]
 *   [ a_kl G_k                                         0            0   ]
 *   [ b_l G(q1)                                        0            0   ]
 * with J_il the unconstrained block of prk_engine.c; constraint rows are
 * divided by h so all blocks are O(1).
 */
#include <config.h>
#include "integrators/prk_impl.h"
#include "integrators/prk_kernels.h"

#include <float.h>
#include <math.h>
#include <string.h>

static int lobatto_type(const dm_tableau *t)
{
  size_t s = t->s, i;
  if (s < 2 || t->c[0] != 0.0 || t->c[s - 1] != 1.0)
    return 0;
  for (i = 0; i < s; i++)
    if (t->a[i] != 0.0 || fabs(t->a[(s - 1) * s + i] - t->b[i]) > 1e-14
        || t->at[i * s + s - 1] != 0.0 || fabs(t->at[i * s] - t->b[0]) > 1e-14)
      return 0;
  return 1;
}

int dm_prk_constr_stages(const dm_tableau *t, size_t *nK, size_t *K)
{
  size_t k;
  if (t->s == 1) {
    *nK = 0;
    return 1;
  }
  if (!lobatto_type(t))
    return 0;
  *nK = t->s - 2;
  for (k = 0; k < *nK; k++)
    K[k] = k + 1;
  return 1;
}

int dm_prk_constr_layout(dm_prk *P, dm_err *e)
{
  const dm_tableau *t = P->tab;
  if (P->sys->constraints == NULL)
    return dm_err_set(e, DM_EINVAL, "system '%s' declares m = %zu constraints but no constraint function",
                      P->sys->name ? P->sys->name : "?", P->m);
  if (dm_prk_constr_stages(t, &P->nK, P->K))
    return DM_OK;
  return dm_err_set(e, DM_EUNSUP,
                    "holonomic constraints are not supported with the %s tableau (s = %zu): "
                    "a degree-s curve cannot keep all Gauss stage points and both end points on "
                    "the constraint manifold; use 'lobatto' (multipliers at every stage), "
                    "'trapezoid' (RATTLE) or 'midpoint'", t->name, t->s);
}

int dm_prk_constr_begin(dm_prk *P, const double *q0, dm_err *e)
{
  size_t s = P->s, m = P->m, n = P->n;
  double gn;
  int st = dm_eval_constr(P->sys, q0, DM_CONSTR_G | DM_CONSTR_DG, P->g + s * m,
                          P->G + s * m * n, NULL, P->work, e);
  if (st != DM_OK)
    return st;
  gn = dm_norm_inf(P->g + s * m, m);
  if (!(gn <= 1e-8 * fmax(1.0, dm_norm_inf(q0, n))))
    return dm_err_set(e, DM_EINVAL,
                      "the initial position violates the constraints: |g(q0)| = %.3g "
                      "(start on g(q) = 0)", gn);
  return DM_OK;
}

void dm_prk_constr_terms(const dm_tableau *t, size_t n, size_t m, size_t nK, const size_t *K,
                         double h, const double *X, const double *g, const double *G,
                         const double *Hc, double *R, double *Jm)
{
  const size_t s = t->s, nn = n * n, sn = s * n;
  const size_t N = sn + nK * m + m, offL = sn, offM = sn + nK * m;
  const double *A = t->a, *At = t->at, *b = t->b;
  const double *G0 = G + s * m * n, *mu0 = X + offM;
  const double *g1 = g + (s + 1) * m, *G1 = G + (s + 1) * m * n;
  size_t i, kk, l, a, c, x;
  /* residual: multiplier terms in the stage equations, constraint rows */
  for (i = 0; i < s; i++)
    for (c = 0; c < n; c++) {
      double acc = 0.0;
      for (a = 0; a < m; a++)
        acc += G0[a * n + c] * mu0[a];
      for (kk = 0; kk < nK; kk++) {
        size_t k = K[kk];
        const double *Gk = G + k * m * n, *Lk = X + offL + kk * m;
        for (a = 0; a < m; a++)
          acc += At[i * s + k] * Gk[a * n + c] * Lk[a];
      }
      R[i * n + c] += acc;
    }
  for (kk = 0; kk < nK; kk++)
    for (a = 0; a < m; a++)
      R[offL + kk * m + a] = g[K[kk] * m + a] / h;
  for (a = 0; a < m; a++)
    R[offM + a] = g1[a] / h;
  if (Jm == NULL)
    return;
  for (kk = 0; kk < nK; kk++) {
    size_t k = K[kk];
    const double *Gk = G + k * m * n, *Hk = Hc + k * m * nn, *Lk = X + offL + kk * m;
    /* curvature term: sum_a Lt_a d2g_a(Q_k) into blocks (i, l) */
    for (c = 0; c < n; c++)
      for (x = 0; x < n; x++) {
        double hs = 0.0;
        for (a = 0; a < m; a++)
          hs += Lk[a] * Hk[(a * n + c) * n + x];
        for (i = 0; i < s; i++)
          for (l = 0; l < s; l++)
            Jm[(i * n + c) * N + l * n + x] += At[i * s + k] * h * A[k * s + l] * hs;
      }
    for (i = 0; i < s; i++)
      for (c = 0; c < n; c++)
        for (a = 0; a < m; a++)
          Jm[(i * n + c) * N + offL + kk * m + a] = At[i * s + k] * Gk[a * n + c];
    for (a = 0; a < m; a++)
      for (l = 0; l < s; l++)
        for (x = 0; x < n; x++)
          Jm[(offL + kk * m + a) * N + l * n + x] = A[k * s + l] * Gk[a * n + x];
  }
  for (i = 0; i < s; i++)
    for (c = 0; c < n; c++)
      for (a = 0; a < m; a++)
        Jm[(i * n + c) * N + offM + a] = G0[a * n + c];
  for (a = 0; a < m; a++)
    for (l = 0; l < s; l++)
      for (x = 0; x < n; x++)
        Jm[(offM + a) * N + l * n + x] = b[l] * G1[a * n + x];
}

void dm_prk_constr_momentum(const dm_tableau *t, size_t n, size_t m, size_t nK, const size_t *K,
                            const double *X, const double *G, double *dp)
{
  const size_t s = t->s, offL = s * n, offM = s * n + nK * m;
  const double *b = t->b, *G0 = G + s * m * n;
  size_t kk, a, c;
  for (c = 0; c < n; c++) {
    double sp = dp[c];
    for (a = 0; a < m; a++)
      sp -= G0[a * n + c] * X[offM + a];
    for (kk = 0; kk < nK; kk++) {
      const double *Gk = G + K[kk] * m * n;
      for (a = 0; a < m; a++)
        sp -= b[K[kk]] * Gk[a * n + c] * X[offL + kk * m + a];
    }
    dp[c] = sp;
  }
}

/* The constraints at the constrained stages (with second derivatives when
 * jac) and at q1 = q0 + h sum b_j V_j, then their terms (above). */
int dm_prk_constr_assemble(dm_prk *P, double h, const double *q0, int jac, dm_err *e)
{
  size_t n = P->n, s = P->s, m = P->m, nn = P->nn;
  const double *b = P->tab->b;
  double *q1 = P->tmp, *g1 = P->g + (s + 1) * m, *G1 = P->G + (s + 1) * m * n;
  size_t kk, l, a;
  int st;
  for (kk = 0; kk < P->nK; kk++) {
    size_t k = P->K[kk];
    st = dm_eval_constr(P->sys, P->Q + k * n, DM_CONSTR_G | DM_CONSTR_DG | (jac ? DM_CONSTR_D2G : 0u),
                        P->g + k * m, P->G + k * m * n, P->Hc + k * m * nn, P->work, e);
    if (st != DM_OK)
      return st;
  }
  for (a = 0; a < n; a++) {
    double acc = 0.0;
    for (l = 0; l < s; l++)
      acc += b[l] * P->X[l * n + a];
    q1[a] = q0[a] + h * acc;
  }
  if ((st = dm_eval_constr(P->sys, q1, DM_CONSTR_G | DM_CONSTR_DG, g1, G1, NULL, P->work, e)) != DM_OK)
    return st;
  dm_prk_constr_terms(P->tab, n, m, P->nK, P->K, h, P->X, P->g, P->G, P->Hc, P->R,
                      jac && !P->sparse ? P->Jm : NULL);
  return DM_OK;
}

/* Solve Lv(q1, v) + G1^T mu = p, G1 v = 0 for (v, mu) by Newton (one
 * iteration for a mechanical L) and replace p by p - G1^T mu. */
int dm_prk_project_momentum(dm_prk *P, const double *q1, const double *G1,
                            double *p, const double *vguess, dm_err *e)
{
  size_t n = P->n, m = P->m, N = n + m, i, a, c;
  double *y = P->rhs, *v = P->rhs, *mu = P->rhs + n;
  dm_lag_out o = {0, P->Lq, P->Lv, P->Lvv, P->Lvq, P->Lqq};   /* stage-1 buffers as scratch */
  int mech = (P->sys->flags & (DM_SYS_MECHANICAL | DM_SYS_SEPARABLE)) != 0;
  double d = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st;
  memcpy(v, vguess, n * sizeof(double));
  memset(mu, 0, m * sizeof(double));
  for (it = 0; it < P->maxiter; it++) {
    double ps, vs, ls;
    if ((st = dm_eval_lag(P->sys, q1, v, DM_LAG_V | DM_LAG_VV, &o, P->work, e)) != DM_OK)
      return st;
    memset(P->Jm, 0, N * N * sizeof(double));
    for (c = 0; c < n; c++) {
      double acc = P->Lv[c] - p[c];
      for (a = 0; a < m; a++) {
        acc += G1[a * n + c] * mu[a];
        P->Jm[c * N + n + a] = G1[a * n + c];
        P->Jm[(n + a) * N + c] = G1[a * n + c];
      }
      for (i = 0; i < n; i++)
        P->Jm[c * N + i] = P->Lvv[c * n + i];
      P->R[c] = acc;
    }
    for (a = 0; a < m; a++) {
      double acc = 0.0;
      for (c = 0; c < n; c++)
        acc += G1[a * n + c] * v[c];
      P->R[n + a] = acc;
    }
    st = dm_smalllu_factor(P->Jm, N, P->perm);
    if (st != DM_OK)
      return dm_err_set(e, st == DM_ESINGULAR ? DM_ESINGULAR : DM_EDOM,
                        "momentum projection onto the constraint manifold: singular system "
                        "(dependent constraint gradients or singular d2L/dv2)");
    dm_smalllu_solve(P->Jm, N, P->perm, P->R);
    for (i = 0; i < N; i++)
      y[i] -= P->R[i];
    ps = dm_norm_inf(p, n);
    ls = dm_norm_inf(P->Lvv, n * n);
    vs = fmax(fmax(dm_norm_inf(v, n), ls > 0 ? ps / ls : 0.0), DBL_MIN);
    d = fmax(dm_norm_inf(P->R, n) / vs,
             dm_norm_inf(P->R + n, m) / fmax(fmax(dm_norm_inf(mu, m), ps), DBL_MIN));
    if (mech || dm_newton_done(&stop, d, P->tol))
      break;
  }
  if (it == P->maxiter)
    return dm_err_set(e, DM_ENOCONV, "momentum projection did not converge (update %.3g)", d);
  for (c = 0; c < n; c++)
    for (a = 0; a < m; a++)
      p[c] -= G1[a * n + c] * mu[a];
  return DM_OK;
}

int dm_prk_constr_finish(dm_prk *P, double h, const double *q0, const double *p0,
                         double *q1, double *p1, dm_err *e)
{
  size_t n = P->n, s = P->s, m = P->m;
  const double *b = P->tab->b;
  double *G1 = P->G + (s + 1) * m * n, *pp = P->p1w == p1 ? P->v1w : P->p1w;
  size_t i, c;
  int st;
  for (c = 0; c < n; c++) {
    double sq = 0.0, sp = 0.0;
    for (i = 0; i < s; i++) {
      sq += b[i] * P->X[i * n + c];
      sp += b[i] * P->W[i * n + c];
    }
    P->dq[c] = h * sq;
    P->dp[c] = sp * h;
  }
  dm_prk_constr_momentum(P->tab, n, m, P->nK, P->K, P->X, P->G, P->dp);
  dm_prk_kahan(n, q0, P->dq, P->cq, q1);
  if ((st = dm_eval_constr(P->sys, q1, DM_CONSTR_G | DM_CONSTR_DG, P->g + (s + 1) * m, G1, NULL,
                           P->work, e)) != DM_OK)
    return st;
  for (c = 0; c < n; c++)
    pp[c] = p0[c] + P->dp[c];
  memcpy(P->tmp, pp, n * sizeof(double));
  st = dm_prk_project_momentum(P, q1, G1, pp, P->X + (s - 1) * n, e);
  if (st != DM_OK)
    return st;
  for (c = 0; c < n; c++)
    P->dp[c] += pp[c] - P->tmp[c];
  dm_prk_kahan(n, p0, P->dp, P->cp, p1);
  return DM_OK;
}
