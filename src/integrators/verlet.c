/* verlet.c -- explicit paths of the Lobatto IIIA-IIIB s=2 (trapezoid) step
 * for separable unforced systems L = 1/2 v^T M v - V(q):
 *   Stormer-Verlet (velocity Verlet)
 *     p_half = p0 + h/2 Lq(q0),  q1 = q0 + h M^{-1} p_half,  p1 = p_half + h/2 Lq(q1)
 *   and, with constraints g(q) = 0, RATTLE:
 *     p_half = p0 + h/2 Lq(q0) - G(q0)^T mu0, with mu0 (m unknowns, Newton
 *     on g(q1(mu0)) = 0: SHAKE), then p1 = p_half + h/2 Lq(q1) - G(q1)^T mu1
 *     with mu1 making M^{-1} p1 tangent (momentum projection).
 * These are exactly the engine's Lobatto-2 step equations (stage velocities
 * V_1 = V_2 = M^{-1} p_half), so the implicit-function Jacobian of
 * prk_engine.c applies unchanged.  Lq at q1 is kept for the next step
 * (first same as last): one force evaluation per step. */
#include <config.h>
#include "integrators/prk_impl.h"

#include <float.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include "core/interrupt.h"

static int is_lobatto2(const dm_tableau *t)
{
  return t->s == 2 && t->c[0] == 0.0 && t->c[1] == 1.0 && t->a[0] == 0.0 && t->a[1] == 0.0
         && t->a[2] == 0.5 && t->a[3] == 0.5 && t->at[0] == 0.5 && t->at[1] == 0.0
         && t->at[2] == 0.5 && t->at[3] == 0.0 && t->b[0] == 0.5 && t->b[1] == 0.5;
}

/* The mass's structure (unit, diagonal, full: from the dense matrix, or
 * from the pattern of a large system, whose mass is diagonal), its
 * inverse's diagonal exactly (reciprocals), and for a full mass the
 * inverse by Cholesky; the largest entry of M.  DM_EUNSUP when the system
 * is not separable and unforced with a known mass (nothing set), DM_EINVAL
 * when the mass is not symmetric positive definite. */
int dm_prk_mass_setup(dm_prk *P, dm_err *e)
{
  const dm_system *sys = P->sys;
  const dm_sys_pattern *pat = sys->pattern;
  const double *M = sys->mass;
  size_t n = P->n, i;
  if (P->mass_ready)
    return DM_OK;
  if (!(sys->flags & DM_SYS_SEPARABLE) || P->forced ||
      (M == NULL && (pat == NULL || pat->mass == NULL || pat->vv.nnz != n)))
    return dm_err_set(e, DM_EUNSUP, "system '%s' has no constant mass matrix (L is not "
                      "1/2 v^T M v - V(q) without forces)", sys->name ? sys->name : "?");
  P->mass_kind = DM_MASS_UNIT;
  P->mass_norm = 0.0;
  int spd = 1;
  if (M != NULL) {
    for (i = 0; i < n * n; i++) {
      if (i / n != i % n && M[i] != 0.0)
        P->mass_kind = DM_MASS_FULL;
      else if (i / n == i % n && M[i] != 1.0 && P->mass_kind == DM_MASS_UNIT)
        P->mass_kind = DM_MASS_DIAG;
      P->mass_norm = fmax(P->mass_norm, fabs(M[i]));
    }
    for (i = 0; i < n; i++) {
      spd &= M[i * n + i] > 0.0 && isfinite(M[i * n + i]);
      P->Mdiag[i] = 1.0 / M[i * n + i];
    }
  } else {                                  /* n diagonal entries on vv */
    for (i = 0; i < n; i++) {
      double mi = pat->mass[i];
      spd &= pat->vv.col[pat->vv.rowptr[i]] == i && mi > 0.0 && isfinite(mi);
      if (mi != 1.0)
        P->mass_kind = DM_MASS_DIAG;
      P->Mdiag[i] = 1.0 / mi;
      P->mass_norm = fmax(P->mass_norm, fabs(mi));
    }
  }
  if (P->mass_kind == DM_MASS_FULL) {
    gsl_matrix_view Mi;
    if ((P->Minv = malloc(n * n * sizeof *P->Minv)) == NULL)
      return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
    memcpy(P->Minv, M, n * n * sizeof(double));
    Mi = gsl_matrix_view_array(P->Minv, n, n);
    spd = gsl_linalg_cholesky_decomp1(&Mi.matrix) == 0 &&
          gsl_linalg_cholesky_invert(&Mi.matrix) == 0;
  }
  if (!spd) {
    free(P->Minv);
    P->Minv = NULL;
    return dm_err_set(e, DM_EINVAL, "system '%s' is flagged separable but its mass matrix is not "
                      "symmetric positive definite", sys->name ? sys->name : "?");
  }
  P->mass_ready = 1;
  return DM_OK;
}

int dm_prk_verlet_setup(dm_prk *P, dm_err *e)
{
  P->explicit_sv = 0;
  if (!is_lobatto2(P->tab))
    return DM_OK;
  int st = dm_prk_mass_setup(P, e);
  if (st == DM_EUNSUP)
    return DM_OK;
  if (st != DM_OK)
    return st;
  P->explicit_sv = 1;
  return DM_OK;
}

static int force_at(dm_prk *P, const double *q, double *f, dm_err *e)
{
  dm_lag_out o = {0, f, P->Lv + P->n, NULL, NULL, NULL};
  for (size_t i = 0; i < P->n; i++)
    P->v1w[i] = 0.0;                         /* Lq of a separable L ignores v */
  return dm_eval_lag(P->sys, q, P->v1w, DM_LAG_Q, &o, P->work, e);
}

static inline void minv_mul(const dm_prk *P, const double *x, double *y)
{
  size_t n = P->n, i, j;
  const double *Mi = P->Minv;
  switch (P->mass_kind) {
  case DM_MASS_UNIT:
    for (i = 0; i < n; i++)
      y[i] = x[i];
    break;
  case DM_MASS_DIAG:
    for (i = 0; i < n; i++)
      y[i] = P->Mdiag[i] * x[i];
    break;
  default:
    for (i = 0; i < n; i++) {
      double acc = 0.0;
      for (j = 0; j < n; j++)
        acc += Mi[i * n + j] * x[j];
      y[i] = acc;
    }
  }
}

/* u = M^{-1} ph with the half-step momentum ph = base - G0^T mu0 */
static void shake_velocity(const dm_prk *P, const double *base, const double *G0,
                           const double *mu, double *ph, double *u)
{
  size_t n = P->n, m = P->m, a, c;
  for (c = 0; c < n; c++) {
    double acc = base[c];
    for (a = 0; a < m; a++)
      acc -= G0[a * n + c] * mu[a];
    ph[c] = acc;
  }
  minv_mul(P, ph, u);
}

/* SHAKE: mu0 with g(q0 + h M^{-1}(base - G0^T mu0)) = 0; leaves u = M^{-1} p_half
 * in X[0..n) and mu0 in X[2n..2n+m). */
static int shake(dm_prk *P, double h, const double *q0, const double *base, const double *G0,
                 double ms, dm_integ_stats *stt, dm_err *e)
{
  size_t n = P->n, m = P->m, a, b, c;
  double *u = P->X, *mu = P->X + 2 * n, *qq = P->tmp, *gq = P->g, *Gq = P->G, *ph = P->dp;
  double d = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st;
  for (it = 1; it <= P->maxiter; it++) {
    shake_velocity(P, base, G0, mu, ph, u);
    for (c = 0; c < n; c++)
      qq[c] = q0[c] + h * u[c];
    if ((st = dm_eval_constr(P->sys, qq, DM_CONSTR_G | DM_CONSTR_DG, gq, Gq, NULL, P->work, e)) != DM_OK)
      return st;
    /* d(g/h)/dmu0_b = -G(qq) M^{-1} G0_b^T */
    for (b = 0; b < m; b++) {
      minv_mul(P, G0 + b * n, P->q1w);
      for (a = 0; a < m; a++) {
        double acc = 0.0;
        for (c = 0; c < n; c++)
          acc += Gq[a * n + c] * P->q1w[c];
        P->Jm[a * m + b] = -acc;
      }
    }
    for (a = 0; a < m; a++)
      P->R[a] = gq[a] / h;
    if (!isfinite(dm_norm_inf(P->R, m)))
      return dm_err_set(e, DM_EDOM, "SHAKE: non-finite constraint residual (h = %g)", h);
    if ((st = dm_smalllu_factor(P->Jm, m, P->perm)) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "SHAKE: singular constraint matrix G(q1) M^-1 G(q0)^T "
                        "(h = %g too large, or dependent constraints)", h);
    dm_smalllu_solve(P->Jm, m, P->perm, P->R);
    for (a = 0; a < m; a++)
      mu[a] -= P->R[a];
    d = dm_norm_inf(P->R, m) / fmax(fmax(dm_norm_inf(mu, m), ms), DBL_MIN);
    if (dm_newton_done(&stop, d, P->tol))
      break;
  }
  if (stt) {
    stt->iters = it > P->maxiter ? P->maxiter : it;
    stt->residual = d;
    stt->tol = P->tol;
    stt->iters_total += stt->iters;
  }
  if (it > P->maxiter)
    return dm_err_set(e, DM_ENOCONV, "SHAKE iteration for the position constraints did not converge: "
                      "relative update %.3g > tol %.3g (h = %g)", d, P->tol, h);
  shake_velocity(P, base, G0, mu, ph, u);
  return DM_OK;
}

int dm_prk_verlet_step(dm_prk *P, double h, const double *q0, const double *p0,
                       int cont, double *q1, double *p1, dm_integ_stats *stt, dm_err *e)
{
  size_t n = P->n, m = P->m, a, c;
  double *f0 = P->Lq, *f1 = P->Lq + n, *u = P->X, *ph = P->dp;
  const double hh = 0.5 * h;
  int st;
  if (cont && P->svf_valid)
    dm_vcopy(f0, P->svf, n);
  else if ((st = force_at(P, q0, f0, e)) != DM_OK)
    return st;
  P->svf_valid = 0;
  if (m == 0) {
    /* drift, force, kick: the arithmetic of the run loop (and of the
     * constrained path below with mu = 0), inline */
    double *cq = P->cq, *cp = P->cp;
    if (stt) {
      stt->iters = 0;
      stt->residual = 0.0;
      stt->tol = P->tol;
    }
    for (c = 0; c < n; c++)
      ph[c] = p0[c] + hh * f0[c];
    minv_mul(P, ph, u);
    for (c = 0; c < n; c++) {
      double y = h * u[c] - cq[c], t = q0[c] + y;
      cq[c] = (t - q0[c]) - y;
      q1[c] = t;
      P->X[n + c] = u[c];
    }
    if ((st = force_at(P, q1, f1, e)) != DM_OK)
      return st;
    for (c = 0; c < n; c++) {
      double y = hh * (f0[c] + f1[c]) - cp[c], t = p0[c] + y;
      cp[c] = (t - p0[c]) - y;
      p1[c] = t;
      P->svf[c] = f1[c];
    }
    P->svf_valid = 1;
    return DM_OK;
  }
  {
    double *base = P->W, *G0 = P->G + P->s * m * n;
    if ((st = dm_prk_constr_begin(P, q0, e)) != DM_OK)
      return st;
    for (c = 0; c < n; c++)
      base[c] = p0[c] + 0.5 * h * f0[c];
    if (!cont)
      memset(P->X + 2 * n, 0, m * sizeof(double));
    else
      memcpy(P->X + 2 * n, P->hx, m * sizeof(double));
    if ((st = shake(P, h, q0, base, G0, dm_norm_inf(base, n), stt, e)) != DM_OK)
      return st;
  }
  for (c = 0; c < n; c++)
    P->dq[c] = h * u[c];
  memcpy(P->X + n, u, n * sizeof(double));
  dm_prk_kahan(n, q0, P->dq, P->cq, q1);
  if ((st = force_at(P, q1, f1, e)) != DM_OK)
    return st;
  memcpy(P->svf, f1, n * sizeof(double));
  /* dp accumulated in W + n.. as the increment p1 - p0 */
  {
    double *dp = P->W + n, *pp = P->Q, *pp0 = P->Q + n;
    double *G0 = P->G + P->s * m * n, *G1 = P->G + (P->s + 1) * m * n, *mu0 = P->X + 2 * n;
    for (c = 0; c < n; c++)
      dp[c] = 0.5 * h * (f0[c] + f1[c]);
    for (c = 0; c < n; c++)
      for (a = 0; a < m; a++)
        dp[c] -= G0[a * n + c] * mu0[a];
    if ((st = dm_eval_constr(P->sys, q1, DM_CONSTR_G | DM_CONSTR_DG, P->g + (P->s + 1) * m, G1,
                             NULL, P->work, e)) != DM_OK)
      return st;
    for (c = 0; c < n; c++)
      pp[c] = pp0[c] = p0[c] + dp[c];
    if ((st = dm_prk_project_momentum(P, q1, G1, pp, u, e)) != DM_OK)
      return st;
    for (c = 0; c < n; c++)
      dp[c] += pp[c] - pp0[c];
    dm_prk_kahan(n, p0, dp, P->cp, p1);
  }
  P->svf_valid = 1;
  return DM_OK;
}

/* The drift of one component: u = M^{-1} ph (unit or diagonal mass),
 * q1 = q + h u with Kahan compensation (carry c in, *cn out). */
static inline double drift1(int kind, double mii, double h, double ph, double q, double c,
                            double *cn, double *u)
{
  double uu = kind == DM_MASS_UNIT ? ph : mii * ph, y = h * uu - c, t = q + y;
  *cn = (t - q) - y;
  *u = uu;
  return t;
}

/* The drift of a whole step into q1, cn, u from (q, p + h/2 f, carries c). */
static void drift(const dm_prk *P, double h, const double *q, const double *p, const double *f,
                  const double *c, double *q1, double *cn, double *u, double *ph)
{
  size_t n = P->n, i;
  const double hh = 0.5 * h;
  if (P->mass_kind == DM_MASS_FULL) {
    for (i = 0; i < n; i++)
      ph[i] = p[i] + hh * f[i];
    minv_mul(P, ph, u);
    for (i = 0; i < n; i++) {
      double y = h * u[i] - c[i], t = q[i] + y;
      cn[i] = (t - q[i]) - y;
      q1[i] = t;
    }
    return;
  }
  for (i = 0; i < n; i++)
    q1[i] = drift1(P->mass_kind, P->Mdiag[i], h, p[i] + hh * f[i], q[i], c[i], cn + i,
                   u + i);
}

/* The run loop's fast path for unconstrained Stormer-Verlet, and for
 * compositions of it: nsteps steps in place, each of ns substeps of
 * g[j] h (g = NULL: one substep of h), one force evaluation per substep
 * (first same as last), Kahan compensated updates whose carries run on
 * across substeps and steps.  The kick of one substep and the drift of
 * the next run in one pass (the drift's position goes to a buffer and
 * becomes the state when the substep succeeds), so the new momenta flow to
 * the next positions in registers: the dependency chain of a substep holds
 * the force and a few additions, not loads of values just stored.  Same
 * arithmetic as dm_prk_verlet_step called substep by substep, so results
 * are bitwise identical to stepping (and to a composition's step()).
 * q, p serve as scratch during the loop (one substep a step) or are
 * written at step boundaries: on return (also after a failure or Ctrl-C)
 * they hold the state after *done steps. */
int dm_prk_verlet_advance(dm_prk *P, double h, const double *g, size_t ns, long nsteps,
                          double *q, double *p, long *done, dm_integ_stats *stt, dm_err *e)
{
  static const double one = 1.0;
  const dm_system *sys = P->sys;
  const size_t n = P->n;
  const int kind = P->mass_kind;
  const double *Md = P->Mdiag;
  double *f0 = P->Lq, *f1 = P->Lq + n, *tmp;
  /* speculative positions of the next substep, and the position carries
   * and drift velocities of the state (c), of the next substep (s) and of
   * the one after (t), rotated as substeps complete; qw, pw: the state
   * between substeps (the caller's arrays when there is one substep) */
  double *qs = P->q1w, *qt = P->tmp, *pn = P->dp, *ph = P->Q + n;
  double *cqc = P->cq, *cqs = P->dq, *cqt = P->p1w;
  double *uc = P->W, *us = P->W + n, *ut = P->Q;
  double *cp = P->cp, *qw, *pw;
  double hk, hh;
  dm_lag_out o = {0, NULL, P->Lv + n, NULL, NULL, NULL};
  long k = 0;
  size_t i, j = 0;
  int st = DM_OK, rc;
  int cont = P->hist && dm_same(q, P->hq1, n) && dm_same(p, P->hp1, n);
  if (g == NULL || ns == 0) {
    g = &one;
    ns = 1;
  }
  qw = ns == 1 ? q : P->R;
  pw = ns == 1 ? p : P->R + n;
  *done = 0;
  if (!cont) {
    memset(P->cq, 0, n * sizeof(double));
    memset(cp, 0, n * sizeof(double));
    P->svf_valid = 0;
  }
  if (cont && P->svf_valid)
    dm_vcopy(f0, P->svf, n);
  else if ((st = force_at(P, q, f0, e)) != DM_OK)
    return st;
  P->hist = 0;
  P->svf_valid = 0;
  memset(P->v1w, 0, n * sizeof(double));
  dm_vcopy(uc, P->X, n);           /* the last substep's velocity, if any */
  if (qw != q) {
    dm_vcopy(qw, q, n);
    dm_vcopy(pw, p, n);
  }
  hk = g[0] * h;
  hh = 0.5 * hk;
  if (nsteps > 0)
    drift(P, hk, qw, pw, f0, cqc, qs, cqs, us, ph);
  while (k < nsteps) {
    const size_t jn = j + 1 == ns ? 0 : j + 1;
    const int more = jn != 0 || k + 1 < nsteps;
    const double hk1 = g[jn] * h, hh1 = 0.5 * hk1;
    int bad = 0;
    if (j == 0 && dm_interrupted()) {
      st = DM_EINTR;
      break;
    }
    o.Lq = f1;
    if ((rc = sys->lagrangian(sys->data, qs, P->v1w, sys->par, DM_LAG_Q, &o, P->work)) != 0) {
      st = dm_eval_lag(sys, qs, P->v1w, DM_LAG_Q, &o, P->work, e);   /* formats the message */
      if (st == DM_OK)
        st = dm_err_set(e, rc > 0 ? DM_EDOM : DM_ECALLBACK, "force evaluation failed");
      break;
    }
    /* kick: p1 = p + h/2 (f0 + f1), compensated, one finiteness test per
     * substep; then (unless this is the last) the next drift from p1 */
    if (kind != DM_MASS_FULL && more) {
      for (i = 0; i < n; i++) {
        double f = f1[i], y = hh * (f0[i] + f) - cp[i], t = pw[i] + y, qi = qs[i];
        bad |= !isfinite(t) | !isfinite(qi);
        cp[i] = (t - pw[i]) - y;
        pn[i] = t;
        qt[i] = drift1(kind, Md[i], hk1, t + hh1 * f, qi, cqs[i], cqt + i, ut + i);
      }
    } else {
      for (i = 0; i < n; i++) {
        double y = hh * (f0[i] + f1[i]) - cp[i], t = pw[i] + y;
        bad |= !isfinite(t) | !isfinite(qs[i]);
        cp[i] = (t - pw[i]) - y;
        pn[i] = t;
      }
      if (more)
        drift(P, hk1, qs, pn, f1, cqs, qt, cqt, ut, ph);
    }
    if (bad) {
      st = dm_err_set(e, DM_EDOM, "the step produced a non-finite state (NaN or Inf; h = %g)", h);
      break;
    }
    if (ns == 1) {
      /* the new state by renaming, not copying (two fewer passes over
       * four arrays a step: what the loop costs above a few hundred
       * coordinates is memory traffic); copied out at the end */
      tmp = qw, qw = qs, qs = qt, qt = tmp;
      tmp = pw, pw = pn, pn = tmp;
    } else {
      for (i = 0; i < n; i++) {
        qw[i] = qs[i];
        pw[i] = pn[i];
      }
      tmp = qs, qs = qt, qt = tmp;
    }
    tmp = f0, f0 = f1, f1 = tmp;
    tmp = cqc, cqc = cqs, cqs = cqt, cqt = tmp;
    tmp = uc, uc = us, us = ut, ut = tmp;
    hk = hk1;
    hh = hh1;
    j = jn;
    if (j == 0) {
      k++;
      if (ns > 1) {
        dm_vcopy(q, qw, n);
        dm_vcopy(p, pw, n);
      }
    }
  }
  if (ns == 1) {                 /* the state after k steps, where it is */
    if (qw != q)
      dm_vcopy(q, qw, n);
    if (pw != p)
      dm_vcopy(p, pw, n);
  }
  *done = k;
  if (stt) {
    stt->steps += k;
    stt->iters = 0;
    stt->residual = 0.0;
  }
  if (st == DM_OK || st == DM_EINTR) {
    /* history for the next call: continuation, carries, FSAL force, the
     * last substep's stage velocities */
    if (cqc != P->cq)
      dm_vcopy(P->cq, cqc, n);
    dm_vcopy(P->hq1, q, n);
    dm_vcopy(P->hp1, p, n);
    dm_vcopy(P->svf, f0, n);
    dm_vcopy(P->X, uc, n);
    dm_vcopy(P->X + n, uc, n);
    dm_vcopy(P->hV, P->X, 2 * n);
    P->hist = 1;
    P->svf_valid = 1;
  }
  return st;
}
