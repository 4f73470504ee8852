/* legendre.c -- the Legendre map p = dL/dv(q, v), its inverse by Newton,
 * the energy, and the Hamiltonian vector field (q, p) -> (v, Lq + F) with
 * its exact Jacobian (for the non-symplectic reference methods).
 * See integ_impl.h; workspaces are allocated once by dm_legendre_alloc. */
#include <config.h>
#include "core/numfmt.h"
#include "integrators/integ_impl.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* More coordinates than this (and a pattern): no n x n arrays. */
#define DM_LEG_DENSE_MAX 256

dm_legendre_ws *dm_legendre_alloc(const dm_system *sys)
{
  size_t n = sys->n;
  dm_legendre_ws *w = calloc(1, sizeof *w);
  double *d;
  if (w == NULL)
    return NULL;
  w->large = n > DM_LEG_DENSE_MAX && sys->pattern != NULL;
  /* Lq Lv F r vguess: 5n; Lvv Lvq Lqq Fq Fv A: 6 n*n; T: 2 n*n; Mcopy Mlu:
   * 2 n*n -- or, large, the values of Lvv on its pattern */
  d = calloc(5 * n + (w->large ? sys->pattern->vv.nnz + 1 : 10 * n * n), sizeof(double));
  w->perm = calloc(2 * n, sizeof(size_t));
  w->work = sys->work_size ? malloc(sys->work_size) : NULL;
  if (d == NULL || w->perm == NULL || (sys->work_size && w->work == NULL)) {
    free(d);
    free(w->perm);
    free(w->work);
    free(w);
    return NULL;
  }
  w->mperm = w->perm + n;
  w->sys = sys;
  w->n = n;
  w->tol = 4.0 * DBL_EPSILON;
  w->maxiter = 50;
  w->Lq = d;
  w->Lv = d + n;
  w->F = d + 2 * n;
  w->r = d + 3 * n;
  w->vguess = d + 4 * n;
  if (w->large) {
    w->sLvv = d + 5 * n;
    return w;
  }
  w->Lvv = d + 5 * n;
  w->Lvq = w->Lvv + n * n;
  w->Lqq = w->Lvq + n * n;
  w->Fq = w->Lqq + n * n;
  w->Fv = w->Fq + n * n;
  w->A = w->Fv + n * n;
  w->T = w->A + n * n;
  w->Mcopy = w->T + 2 * n * n;
  w->Mlu = w->Mcopy + n * n;
  return w;
}

void dm_legendre_free(dm_legendre_ws *w)
{
  if (w == NULL)
    return;
  free(w->Lq);
  free(w->perm);
  free(w->work);
  dm_splu_free(w->lu);
  free(w);
}

int dm_legendre_momentum(dm_legendre_ws *w, const double *q, const double *v,
                         double *p, dm_err *e)
{
  dm_lag_out o = {0, w->Lq, w->Lv, w->Lvv, w->Lvq, w->Lqq};
  int st = dm_eval_lag(w->sys, q, v, DM_LAG_V, &o, w->work, e);
  if (st == DM_OK)
    memcpy(p, w->Lv, w->n * sizeof(double));
  return st;
}

int dm_legendre_energy(dm_legendre_ws *w, const double *q, const double *v,
                       double *E, dm_err *e)
{
  dm_lag_out o = {0, w->Lq, w->Lv, w->Lvv, w->Lvq, w->Lqq};
  size_t i;
  int st = dm_eval_lag(w->sys, q, v, DM_LAG_L | DM_LAG_V, &o, w->work, e);
  if (st != DM_OK)
    return st;
  *E = -o.L;
  for (i = 0; i < w->n; i++)
    *E += w->Lv[i] * v[i];
  return DM_OK;
}

static int singular_lvv(const dm_system *sys, const double *q, const double *v, dm_err *e)
{
  char bq[160], bv[160];
  return dm_err_set(e, DM_ESINGULAR,
                    "d2L/dv2 is singular at q = %s, v = %s: the Lagrangian of '%s' is not "
                    "regular (its Hessian in the velocities must be invertible)",
                    dm_num_format_vec(bq, sizeof bq, q, sys->n), dm_num_format_vec(bv, sizeof bv, v, sys->n),
                    sys->name ? sys->name : "system");
}

/* v = M^{-1} p for a separable system (Lv = M v): the LU of the current
 * mass matrix, refactored when it changed; for unit mass v = p.  The
 * numbers are those of one Newton step from v = 0, which is what the
 * general path computes from a zero guess. */
static int separable_velocity(dm_legendre_ws *w, const double *p, double *v, dm_err *e)
{
  const double *M = w->sys->mass;
  size_t n = w->n, nn = n * n, i;
  if (M == NULL) {                /* large: the diagonal mass on the pattern */
    const double *m = w->sys->pattern->mass;
    for (i = 0; i < n; i++)
      v[i] = p[i] / m[i];
    for (i = 0; i < n; i++)
      if (!isfinite(v[i]))
        return dm_err_set(e, DM_EDOM, "velocity solve produced a non-finite value");
    return DM_OK;
  }
  if (w->mass_state == 0 || !dm_same(M, w->Mcopy, nn)) {
    int unit = 1;
    dm_vcopy(w->Mcopy, M, nn);
    for (i = 0; i < nn; i++)
      unit &= M[i] == (i % (n + 1) == 0 ? 1.0 : 0.0);
    w->mass_state = unit ? 1 : 2;
    if (!unit) {
      dm_vcopy(w->Mlu, M, nn);
      if (dm_smalllu_factor(w->Mlu, n, w->mperm) != DM_OK) {
        w->mass_state = 0;
        return dm_err_set(e, DM_ESINGULAR, "the mass matrix of '%s' is singular or not finite",
                          w->sys->name ? w->sys->name : "system");
      }
    }
  }
  for (i = 0; i < n; i++)
    v[i] = p[i];
  if (w->mass_state == 2)
    dm_smalllu_solve(w->Mlu, n, w->mperm, v);
  for (i = 0; i < n; i++)
    if (!isfinite(v[i]))
      return dm_err_set(e, DM_EDOM, "velocity solve produced a non-finite value");
  return DM_OK;
}

/* A separable system whose mass is known: dense, or diagonal on the
 * pattern of a large one. */
static int separable(const dm_legendre_ws *w)
{
  const dm_system *s = w->sys;
  return (s->flags & DM_SYS_SEPARABLE) &&
         (s->mass != NULL ||
          (w->large && s->pattern->mass != NULL && s->pattern->vv.nnz == s->n));
}

/* Newton on Lv(q, v) = p for a large system: d2L/dv2 on its pattern,
 * sparse LU (analysed at the first call). */
static int large_velocity(dm_legendre_ws *w, const double *q, const double *p, double *v,
                          int guess, dm_err *e)
{
  size_t n = w->n, i;
  const dm_csr *vv = &w->sys->pattern->vv;
  dm_lag_out o = {0, w->Lq, w->Lv, w->sLvv, NULL, NULL};
  int mech = (w->sys->flags & (DM_SYS_MECHANICAL | DM_SYS_SEPARABLE)) != 0;
  double d = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st;
  if (w->lu == NULL && (st = dm_splu_alloc(vv, &w->lu, e)) != DM_OK)
    return st;
  if (!guess)
    memset(v, 0, n * sizeof(double));
  for (it = 0; it < w->maxiter; it++) {
    double vs, ls;
    st = dm_eval_lag(w->sys, q, v, DM_LAG_V | DM_LAG_VV | DM_LAG_SPARSE, &o, w->work, e);
    if (st != DM_OK)
      return st;
    for (i = 0; i < n; i++)
      w->r[i] = w->Lv[i] - p[i];
    st = dm_splu_factor(w->lu, w->sLvv, NULL);
    if (st == DM_ESINGULAR)
      return singular_lvv(w->sys, q, v, e);
    if (st != DM_OK)
      return dm_err_set(e, st == DM_ENOMEM ? DM_ENOMEM : DM_EDOM,
                        st == DM_ENOMEM ? "out of memory" : "non-finite d2L/dv2 in the velocity solve");
    dm_splu_solve(w->lu, w->r, 1, NULL);
    for (i = 0; i < n; i++)
      v[i] -= w->r[i];
    ls = dm_norm_inf(w->sLvv, vv->nnz);
    vs = fmax(dm_norm_inf(v, n), dm_norm_inf(p, n) / (ls > 0 ? ls : 1.0));
    d = dm_norm_inf(w->r, n) / (vs > 0 ? vs : 1.0);
    if (!isfinite(d))
      return dm_err_set(e, DM_EDOM, "velocity solve produced a non-finite value");
    if (mech || dm_newton_done(&stop, d, w->tol))
      return DM_OK;
  }
  return dm_err_set(e, DM_ENOCONV,
                    "velocity from momentum (Newton on dL/dv = p) did not converge: "
                    "relative update %.3g after %d iterations", d, it);
}

/* Newton on Lv(q, v) = p.  A mechanical L (linear Legendre map) needs one
 * iteration from any guess; a separable one none (v = M^{-1} p). */
int dm_legendre_velocity(dm_legendre_ws *w, const double *q, const double *p,
                         double *v, int guess, dm_err *e)
{
  size_t n = w->n, i;
  dm_lag_out o = {0, w->Lq, w->Lv, w->Lvv, w->Lvq, w->Lqq};
  int mech = (w->sys->flags & (DM_SYS_MECHANICAL | DM_SYS_SEPARABLE)) != 0;
  double d = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st;
  if (separable(w))
    return separable_velocity(w, p, v, e);
  if (w->large)
    return large_velocity(w, q, p, v, guess, e);
  if (!guess)
    memset(v, 0, n * sizeof(double));
  for (it = 0; it < w->maxiter; it++) {
    double vs, ls;
    if ((st = dm_eval_lag(w->sys, q, v, DM_LAG_V | DM_LAG_VV, &o, w->work, e)) != DM_OK)
      return st;
    for (i = 0; i < n; i++)
      w->r[i] = w->Lv[i] - p[i];
    memcpy(w->A, w->Lvv, n * n * sizeof(double));
    st = dm_smalllu_factor(w->A, n, w->perm);
    if (st == DM_ESINGULAR)
      return singular_lvv(w->sys, q, v, e);
    if (st != DM_OK)
      return dm_err_set(e, DM_EDOM, "non-finite d2L/dv2 in the velocity solve");
    dm_smalllu_solve(w->A, n, w->perm, w->r);
    for (i = 0; i < n; i++)
      v[i] -= w->r[i];
    ls = dm_norm_inf(w->Lvv, n * n);
    vs = fmax(dm_norm_inf(v, n), dm_norm_inf(p, n) / (ls > 0 ? ls : 1.0));
    d = dm_norm_inf(w->r, n) / (vs > 0 ? vs : 1.0);
    if (!isfinite(d))
      return dm_err_set(e, DM_EDOM, "velocity solve produced a non-finite value");
    if (mech || dm_newton_done(&stop, d, w->tol))
      return DM_OK;
  }
  return dm_err_set(e, DM_ENOCONV,
                    "velocity from momentum (Newton on dL/dv = p) did not converge: "
                    "relative update %.3g after %d iterations", d, it);
}

int dm_legendre_field(dm_legendre_ws *w, const double *q, const double *p,
                      double *qdot, double *pdot, dm_err *e)
{
  size_t n = w->n, i;
  dm_lag_out o = {0, w->Lq, w->Lv, w->Lvv, w->Lvq, w->Lqq};
  int st;
  if (separable(w) && qdot != p && pdot != q) {
    /* qdot = M^{-1} p, pdot = Lq(q) (+ F) straight into the outputs */
    if ((st = separable_velocity(w, p, qdot, e)) != DM_OK)
      return st;
    o.Lq = pdot;
    if ((st = dm_eval_lag(w->sys, q, qdot, DM_LAG_Q, &o, w->work, e)) != DM_OK)
      return st;
    if (w->sys->force) {
      if ((st = dm_eval_force(w->sys, q, qdot, DM_FORCE_F, w->F, NULL, NULL, w->work, e)) != DM_OK)
        return st;
      for (i = 0; i < n; i++)
        pdot[i] += w->F[i];
    }
    return DM_OK;
  }
  st = dm_legendre_velocity(w, q, p, w->vguess, w->have_guess, e);
  if (st != DM_OK)
    return st;
  w->have_guess = 1;
  memcpy(qdot, w->vguess, n * sizeof(double));
  if ((st = dm_eval_lag(w->sys, q, w->vguess, DM_LAG_Q, &o, w->work, e)) != DM_OK)
    return st;
  memcpy(pdot, w->Lq, n * sizeof(double));
  if (w->sys->force) {
    if ((st = dm_eval_force(w->sys, q, w->vguess, DM_FORCE_F, w->F, NULL, NULL, w->work, e)) != DM_OK)
      return st;
    for (i = 0; i < n; i++)
      pdot[i] += w->F[i];
  }
  return DM_OK;
}

/* dv/dq = -Lvv^{-1} Lvq, dv/dp = Lvv^{-1};
 * d pdot/dq = Lqq + Fq + (Lvq^T + Fv) dv/dq, d pdot/dp = (Lvq^T + Fv) dv/dp. */
int dm_legendre_field_jac(dm_legendre_ws *w, const double *q, const double *p,
                          double *Jm, dm_err *e)
{
  size_t n = w->n, N2 = 2 * n, i, j, k;
  dm_lag_out o = {0, w->Lq, w->Lv, w->Lvv, w->Lvq, w->Lqq};
  const double *v = w->vguess;
  double *X = w->T;     /* n x 2n: Lvv^{-1} [-Lvq | I] */
  int st;
  if (w->large)
    return dm_err_set(e, DM_EUNSUP, "the Jacobian of the Hamiltonian vector field is not "
                      "available for systems of more than %d coordinates", DM_LEG_DENSE_MAX);
  if ((st = dm_legendre_velocity(w, q, p, w->vguess, w->have_guess, e)) != DM_OK)
    return st;
  w->have_guess = 1;
  if ((st = dm_eval_lag(w->sys, q, v, DM_LAG_ALL, &o, w->work, e)) != DM_OK)
    return st;
  if (w->sys->force) {
    if ((st = dm_eval_force(w->sys, q, v, DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V,
                            w->F, w->Fq, w->Fv, w->work, e)) != DM_OK)
      return st;
  } else {
    memset(w->Fq, 0, n * n * sizeof(double));
    memset(w->Fv, 0, n * n * sizeof(double));
  }
  memcpy(w->A, w->Lvv, n * n * sizeof(double));
  if (dm_smalllu_factor(w->A, n, w->perm) != DM_OK)
    return singular_lvv(w->sys, q, v, e);
  for (j = 0; j < N2; j++) {
    for (i = 0; i < n; i++)
      w->r[i] = j < n ? -w->Lvq[i * n + j] : (i == j - n);
    dm_smalllu_solve(w->A, n, w->perm, w->r);
    for (i = 0; i < n; i++)
      X[i * N2 + j] = w->r[i];
  }
  for (i = 0; i < n; i++)
    for (j = 0; j < N2; j++) {
      double s = j < n ? w->Lqq[i * n + j] + w->Fq[i * n + j] : 0.0;
      for (k = 0; k < n; k++)
        s += (w->Lvq[k * n + i] + w->Fv[i * n + k]) * X[k * N2 + j];
      Jm[i * N2 + j] = X[i * N2 + j];
      Jm[(n + i) * N2 + j] = s;
    }
  return DM_OK;
}
