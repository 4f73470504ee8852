/* adapt_explicit.c -- the explicit path of the time-transformed methods:
 * Stormer-Verlet (drift-kick-drift) and its compositions on the separable
 * extended Hamiltonian f(T(p) + p_t) - f(U(q)) with f' = g(U) = (U0/U)^a,
 * which on the energy surface p_t = -E0 is the flow of the Poincare
 * transformation with the potential's monitor (doc/beyond-fixed-steps.md §3.3).
 * See adapt.h. */
#include <config.h>
#include "integrators/adapt_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The explicit path: trapezoid or composition (trapezoid base) with the
 * potential's monitor on a separable, unforced, unconstrained system. */
int dm_adapt_explicit_setup(dm_integrator *I, adapt_state *A, dm_err *e)
{
  const char *v = I->variant, *scheme = I->opt.scheme;
  size_t n = I->n, nn = n * n, N = n + 1;
  int order = 2, st;
  if (strcmp(v, "trapezoid") == 0) {
    A->ns = 1;
    A->gam[0] = 1.0;
  } else {
    if (strncmp(v, "composition:", 12) == 0)
      scheme = v + 12;
    if ((st = dm_composition_coeffs(scheme, I->opt.order, A->gam, &A->ns, &order, e)) != DM_OK)
      return st;
  }
  A->F = calloc(6 * n + 2 * nn + 4 * N * N, sizeof(double));
  if (A->F == NULL)
    return dm_err_set(e, DM_ENOMEM, "adapt: out of memory");
  A->v = A->F + n;
  A->cq = A->v + n;
  A->cp = A->cq + n;
  A->hq = A->cp + n;
  A->hp = A->hq + n;
  A->Minv = A->hp + n;
  A->K = A->Minv + nn;
  A->T2 = A->K + nn;
  /* M^{-1} for the Jacobian: columns of M^{-1} through the Legendre map */
  for (size_t j = 0; j < n; j++) {
    double *ej = A->cq, *col = A->cp;
    memset(ej, 0, n * sizeof *ej);
    ej[j] = 1.0;
    if ((st = dm_legendre_velocity(I->leg, A->hq, ej, col, 0, e)) != DM_OK)
      return st;
    for (size_t i = 0; i < n; i++)
      A->Minv[i * n + j] = col[i];
  }
  memset(A->cq, 0, 2 * n * sizeof *A->cq);
  A->expl = 1;
  I->order = order;
  I->stages = 0;
  I->flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_EXPLICIT | DM_INTEG_EXACT_JAC
             | DM_INTEG_VARSTEP;
  return DM_OK;
}


static inline void kahan(double *x, double *c, double dx)
{
  double y = dx - *c, t = *x + y;
  *c = (t - *x) - y;
  *x = t;
}

/* The kick of f(U(q)): F = g(U) grad U, with g = (U0/U)^a as a function of
 * U; K = dF/dq when asked. */
static int expl_force(dm_integrator *I, adapt_state *A, const double *q, int jac, dm_err *e)
{
  size_t n = I->n, i, j;
  double U, g, a = A->td.power;
  tt_scratch s;
  int rc;
  tt_layout(&A->td, A->work, &s);
  rc = dm_adapt_potential_eval(&A->td, q, I->sys->par, DM_MON_GRAD | (jac ? DM_MON_HESS : 0), &U,
                               A->F, s.uqq, &s, tt_bwork(&A->td, A->work));
  if (rc != 0 || !(U > 0.0) || !isfinite(U))
    return dm_adapt_monitor_fail(A, rc < 0 ? rc : 1, q, n, e);
  g = a == 1.5 ? A->td.U0 / U * sqrt(A->td.U0 / U) : a == 1.0 ? A->td.U0 / U
                                                              : pow(A->td.U0 / U, a);
  if (jac)                           /* K = g'(U) Uq Uq^T + g Uqq, g' = -a g/U */
    for (i = 0; i < n; i++)
      for (j = 0; j < n; j++)
        A->K[i * n + j] = -a * g / U * A->F[i] * A->F[j] + g * s.uqq[i * n + j];
  for (i = 0; i < n; i++)
    A->F[i] *= g;
  return DM_OK;
}

/* x = T(p) - E0 > 0 and g(x) for the drift; v = M^{-1} p. */
static int expl_drift_rate(dm_integrator *I, adapt_state *A, const double *p, double *phi,
                           double *x_out, dm_err *e)
{
  size_t n = I->n, i;
  double x = -A->td.E0, a = A->td.power;
  int st;
  if ((st = dm_legendre_velocity(I->leg, NULL, p, A->v, 0, e)) != DM_OK)
    return st;
  for (i = 0; i < n; i++)
    x += 0.5 * p[i] * A->v[i];
  if (!(x > 0.0))
    return dm_err_set(e, DM_EDOM, "adapt: the extended Hamiltonian needs T(p) - E0 > 0 "
                      "(a bound state with U > 0); T - E0 = %g", x);
  *phi = a == 1.5 ? A->td.U0 / x * sqrt(A->td.U0 / x) : a == 1.0 ? A->td.U0 / x
                                                               : pow(A->td.U0 / x, a);
  *x_out = x;
  return DM_OK;
}

/* p += c F(q) (D: rows p += c K rows q) */
static int expl_kick(dm_integrator *I, adapt_state *A, double c, const double *q, double *p,
                     double *D, dm_err *e)
{
  size_t n = I->n, N = A->N, M = 2 * N, i, j, l;
  int st;
  if ((st = expl_force(I, A, q, D != NULL, e)) != DM_OK)
    return st;
  for (i = 0; i < n; i++)
    kahan(&p[i], &A->cp[i], c * A->F[i]);
  if (D != NULL)
    for (i = 0; i < n; i++)
      for (j = 0; j < M; j++) {
        double acc = 0.0;
        for (l = 0; l < n; l++)
          acc += A->K[i * n + l] * D[l * M + j];
        D[(N + i) * M + j] += c * acc;
      }
  return DM_OK;
}

/* q += c g(x) M^{-1} p, t += c g(x), x = T(p) + p_t (D: the chain rule,
 * q += c [g M^-1 + g' v v^T] dp + c g' v dp_t, t += c g' (v.dp + dp_t)) */
static int expl_drift(dm_integrator *I, adapt_state *A, double c, double *q, double *t,
                      const double *p, double *D, dm_err *e)
{
  size_t n = I->n, N = A->N, M = 2 * N, i, j, l;
  double phi = 0.0, x = 1.0;
  int st;
  if ((st = expl_drift_rate(I, A, p, &phi, &x, e)) != DM_OK)
    return st;
  for (i = 0; i < n; i++)
    kahan(&q[i], &A->cq[i], c * phi * A->v[i]);
  kahan(t, &A->ct, c * phi);
  if (D != NULL) {
    double dphi = -A->td.power * phi / x, *vp = A->T2;     /* v^T (D rows p) + D row p_t */
    for (j = 0; j < M; j++) {
      double acc = D[(N + n) * M + j];
      for (l = 0; l < n; l++)
        acc += A->v[l] * D[(N + l) * M + j];
      vp[j] = acc;
    }
    for (i = 0; i < n; i++)
      for (j = 0; j < M; j++) {
        double acc = 0.0;
        for (l = 0; l < n; l++)
          acc += A->Minv[i * n + l] * D[(N + l) * M + j];
        D[i * M + j] += c * (phi * acc + dphi * A->v[i] * vp[j]);
      }
    for (j = 0; j < M; j++)
      D[n * M + j] += c * dphi * vp[j];
  }
  return DM_OK;
}

/* One step of fictitious size h in place on (q, t, p): the composition of
 * drift-kick-drift Stormer-Verlet substeps (adjacent drifts merged), Kahan
 * carries kept while steps continue; D (2N x 2N, or NULL) accumulates the
 * extended Jacobian.  Drift-kick-drift: with a = 1 (the logarithmic
 * Hamiltonian) every substep keeps a Kepler orbit's energy exactly. */
int dm_adapt_explicit_step(dm_integrator *I, adapt_state *A, double h, double *q, double *t, double *p,
                     double *D, dm_err *e)
{
  size_t n = I->n, k;
  int st, cont = A->fsal && dm_same(q, A->hq, n) && dm_same(p, A->hp, n);
  if (!cont) {
    memset(A->cq, 0, 2 * n * sizeof *A->cq);
    A->ct = 0.0;
  }
  if ((st = expl_drift(I, A, 0.5 * A->gam[0] * h, q, t, p, D, e)) != DM_OK)
    return st;
  for (k = 0; k < A->ns; k++) {
    double c = 0.5 * (A->gam[k] + (k + 1 < A->ns ? A->gam[k + 1] : 0.0)) * h;
    if ((st = expl_kick(I, A, A->gam[k] * h, q, p, D, e)) != DM_OK
        || (st = expl_drift(I, A, c, q, t, p, D, e)) != DM_OK)
      return st;
  }
  memcpy(A->hq, q, n * sizeof *q);
  memcpy(A->hp, p, n * sizeof *p);
  A->fsal = D == NULL;
  I->stats.iters = 0;
  I->stats.steps++;
  return DM_OK;
}
