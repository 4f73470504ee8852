/* sem.c -- symplectic-energy-momentum integrators: the Gauss Galerkin
 * discrete Lagrangian with the step size as an unknown fixed by the
 * discrete energy (see sem.h, doc/beyond-fixed-steps.md §2).
 *
 * Unknowns: the stage velocities V (s n) and h.  Equations, with
 * Q_i = q0 + h sum_j a_ij V_j,
 *   F_i = Lv(Q_i, V_i) - p0 - h sum_j at_ij Lq(Q_j, V_j) = 0   (the PRK stages)
 *   G   = sum_i b_i E(Q_i, V_i) - E = 0                         (the energy)
 * Newton with the exact Jacobian; the fixed-h stages (begin, the
 * fallback's inner solves, the last step of a run) drop G and h. */
#include <config.h>
#include "integrators/sem.h"
#include "integrators/integ_impl.h"
#include "core/interrupt.h"
#include "core/numfmt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>
#include <gsl/gsl_roots.h>

typedef struct sem_state {
  dm_tableau *tab;
  size_t n, s, sn;
  double E, Elast, h0, hprev, sgn;
  double *X, *R, *J, *Q, *Lq, *Lv, *Lval, *Lvv, *Lvq, *Lqq, *Eq, *Ev, *AV;
  double *v0, *cq, *cp, *hq, *hp;
  double tc;                 /* Kahan carry of t */
  size_t *perm;
  int hist;                  /* cq, cp belong to the state hq, hp */
  void *work;
  /* the fallback: r(h) = Ed(h) - E with fixed-h solves */
  gsl_root_fsolver *root;
  gsl_min_fminimizer *min;
  const double *fq0, *fp0;
  dm_integrator *I;
  int fst;                   /* status of the last inner solve */
  dm_err ferr;
} sem_state;

static const char *const sem_options[] = {"stages", "h", "tol", "maxiter", NULL};

static void sem_free(dm_integrator *I)
{
  sem_state *S = I->state;
  if (S == NULL)
    return;
  dm_tableau_free(S->tab);
  free(S->X);
  free(S->perm);
  free(S->work);
  if (S->root)
    gsl_root_fsolver_free(S->root);
  if (S->min)
    gsl_min_fminimizer_free(S->min);
  free(S);
  I->state = NULL;
}

static int sem_alloc(dm_integrator *I, dm_err *e)
{
  const dm_system *sys = I->sys;
  size_t n = I->n, s, sn, N, nn = n * n;
  sem_state *S;
  int st;
  if (sys->force != NULL || sys->m > 0)
    return dm_err_set(e, DM_EUNSUP, "sem: energy-momentum steps need a conservative, "
                      "unconstrained system ('%s' has %s)", sys->name ? sys->name : "system",
                      sys->force != NULL ? "a force" : "constraints");
  if (I->opt.stages < 0 || I->opt.stages > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "sem: stages = %d out of range 1..%d", I->opt.stages,
                      DM_TABLEAU_SMAX);
  s = I->opt.stages ? (size_t)I->opt.stages : 1;
  if ((S = calloc(1, sizeof *S)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "sem: out of memory");
  I->state = S;
  if ((st = dm_tableau_gauss(s, &S->tab, e)) != DM_OK) {
    sem_free(I);
    return st;
  }
  sn = s * n;
  N = sn + 1;
  S->n = n;
  S->s = s;
  S->sn = sn;
  S->X = calloc(2 * N + N * N + 5 * sn + s + 3 * s * nn + 2 * sn + 5 * n, sizeof(double));
  S->perm = calloc(N, sizeof *S->perm);
  S->work = sys->work_size ? malloc(sys->work_size) : NULL;
  S->root = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
  S->min = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
  if (S->X == NULL || S->perm == NULL || (sys->work_size && S->work == NULL) || S->root == NULL
      || S->min == NULL) {
    sem_free(I);
    return dm_err_set(e, DM_ENOMEM, "sem: out of memory");
  }
  S->R = S->X + N;
  S->J = S->R + N;
  S->Q = S->J + N * N;
  S->Lq = S->Q + sn;
  S->Lv = S->Lq + sn;
  S->Eq = S->Lv + sn;
  S->Ev = S->Eq + sn;
  S->Lval = S->Ev + sn;
  S->Lvv = S->Lval + s;
  S->Lvq = S->Lvv + s * nn;
  S->Lqq = S->Lvq + s * nn;
  S->AV = S->Lqq + s * nn;
  S->v0 = S->AV + sn + sn;
  S->cq = S->v0 + n;
  S->cp = S->cq + n;
  S->hq = S->cp + n;
  S->hp = S->hq + n;
  S->E = S->Elast = NAN;
  S->I = I;
  I->order = (int)(2 * s);
  I->stages = (int)s;
  I->flags = DM_INTEG_SYMMETRIC | DM_INTEG_VARSTEP;
  return DM_OK;
}

/* Stage points and the Lagrangian there (jac: all second derivatives). */
static int eval_stages(dm_integrator *I, sem_state *S, double h, const double *q0, int jac,
                       dm_err *e)
{
  size_t n = S->n, s = S->s, nn = n * n, i, j, a;
  const double *A = S->tab->a;
  int st;
  for (i = 0; i < s; i++) {
    double *Qi = S->Q + i * n, *AVi = S->AV + i * n;
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < s; j++)
        acc += A[i * s + j] * S->X[j * n + a];
      AVi[a] = acc;
      Qi[a] = q0[a] + h * acc;
    }
    dm_lag_out o = {0, S->Lq + i * n, S->Lv + i * n, S->Lvv + i * nn, S->Lvq + i * nn,
                    S->Lqq + i * nn};
    if ((st = dm_eval_lag(I->sys, Qi, S->X + i * n, jac ? DM_LAG_ALL : DM_LAG_GRAD, &o, S->work,
                          e)) != DM_OK)
      return st;
    S->Lval[i] = o.L;
  }
  return DM_OK;
}

/* Ed = sum b_i (Lv_i . V_i - L_i) at the current stages. */
static double stage_energy(const sem_state *S)
{
  size_t n = S->n, i, a;
  double Ed = 0.0;
  for (i = 0; i < S->s; i++) {
    double Ei = -S->Lval[i];
    for (a = 0; a < n; a++)
      Ei += S->Lv[i * n + a] * S->X[i * n + a];
    Ed += S->tab->b[i] * Ei;
  }
  return Ed;
}

/* Residuals F (and G when free_h) at the current stages. */
static void residual(sem_state *S, double h, const double *p0, int free_h)
{
  size_t n = S->n, s = S->s, i, j, a;
  const double *At = S->tab->at;
  for (i = 0; i < s; i++)
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < s; j++)
        acc += At[i * s + j] * S->Lq[j * n + a];
      S->R[i * n + a] = S->Lv[i * n + a] - p0[a] - h * acc;
    }
  if (free_h)
    S->R[S->sn] = stage_energy(S) - S->E;
}

/* The Newton matrix (sn, or sn + 1 with the energy row and h column). */
static void jacobian(sem_state *S, double h, int free_h)
{
  size_t n = S->n, s = S->s, nn = n * n, sn = S->sn, N = free_h ? sn + 1 : sn;
  size_t i, k, j, a, b, l;
  const double *A = S->tab->a, *At = S->tab->at, *B = S->tab->b;
  double *Jm = S->J;
  for (i = 0; i < s; i++)
    for (k = 0; k < s; k++)
      for (a = 0; a < n; a++)
        for (b = 0; b < n; b++) {
          double v = h * A[i * s + k] * S->Lvq[i * nn + a * n + b]
                     - h * At[i * s + k] * S->Lvq[k * nn + b * n + a];
          for (j = 0; j < s; j++)
            v -= h * h * At[i * s + j] * A[j * s + k] * S->Lqq[j * nn + a * n + b];
          if (i == k)
            v += S->Lvv[i * nn + a * n + b];
          Jm[(i * n + a) * N + k * n + b] = v;
        }
  if (!free_h)
    return;
  /* E_q = Lvq^T V - Lq, E_v = Lvv V at each stage */
  for (i = 0; i < s; i++)
    for (b = 0; b < n; b++) {
      double eq = -S->Lq[i * n + b], ev = 0.0;
      for (a = 0; a < n; a++) {
        eq += S->X[i * n + a] * S->Lvq[i * nn + a * n + b];
        ev += S->Lvv[i * nn + b * n + a] * S->X[i * n + a];
      }
      S->Eq[i * n + b] = eq;
      S->Ev[i * n + b] = ev;
    }
  /* column h: dF_i/dh = Lvq_i AV_i - sum_j at_ij Lq_j - h sum_j at_ij Lqq_j AV_j */
  for (i = 0; i < s; i++)
    for (a = 0; a < n; a++) {
      double v = 0.0;
      for (b = 0; b < n; b++)
        v += S->Lvq[i * nn + a * n + b] * S->AV[i * n + b];
      for (j = 0; j < s; j++) {
        double w = 0.0;
        for (l = 0; l < n; l++)
          w += S->Lqq[j * nn + a * n + l] * S->AV[j * n + l];
        v -= At[i * s + j] * (S->Lq[j * n + a] + h * w);
      }
      Jm[(i * n + a) * N + sn] = v;
    }
  /* row G: dG/dV_k = b_k E_v(k) + h sum_i b_i a_ik E_q(i); dG/dh = sum_i b_i E_q(i).AV_i */
  for (k = 0; k < s; k++)
    for (b = 0; b < n; b++) {
      double v = B[k] * S->Ev[k * n + b];
      for (i = 0; i < s; i++)
        v += h * B[i] * A[i * s + k] * S->Eq[i * n + b];
      Jm[sn * N + k * n + b] = v;
    }
  {
    double v = 0.0;
    for (i = 0; i < s; i++)
      for (a = 0; a < n; a++)
        v += B[i] * S->Eq[i * n + a] * S->AV[i * n + a];
    Jm[sn * N + sn] = v;
  }
}

/* Newton on the stages (and h when free_h) from the guess in S->X, *h.
 * DM_EDOM when h leaves (0, 4 h0]; on success the stages hold L, Lq, Lv
 * at the solution. */
static int newton(dm_integrator *I, sem_state *S, double *h, const double *q0,
                  const double *p0, int free_h, dm_err *e)
{
  size_t sn = S->sn, N = free_h ? sn + 1 : sn, i;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  double d = HUGE_VAL, tol = I->opt.tol;
  int it, st;
  for (it = 0; it < I->opt.maxiter; it++) {
    double vs, ls = 0.0;
    if ((st = eval_stages(I, S, *h, q0, 1, e)) != DM_OK)
      return st;
    residual(S, *h, p0, free_h);
    jacobian(S, *h, free_h);
    if ((st = dm_smalllu_factor(S->J, N, S->perm)) != DM_OK)
      return st == DM_ESINGULAR ? dm_err_set(e, DM_ESINGULAR, "sem: singular Newton matrix "
                                             "(h = %.6g)", *h)
                                : dm_err_set(e, DM_EDOM, "sem: non-finite Newton matrix");
    dm_smalllu_solve(S->J, N, S->perm, S->R);
    for (i = 0; i < sn; i++)
      S->X[i] -= S->R[i];
    if (free_h)
      *h -= S->R[sn];
    for (i = 0; i < S->s * S->n * S->n; i++)
      ls = fmax(ls, fabs(S->Lvv[i]));
    vs = fmax(dm_norm_inf(S->X, sn), dm_norm_inf(p0, S->n) / (ls > 0 ? ls : 1.0));
    d = dm_norm_inf(S->R, sn) / (vs > 0 ? vs : 1.0);
    if (free_h)
      d = fmax(d, fabs(S->R[sn]) / fabs(*h));
    if (!isfinite(d) || !isfinite(*h))
      return dm_err_set(e, DM_EDOM, "sem: the Newton update is not finite");
    if (free_h && !(S->sgn * *h > 0.0 && S->sgn * *h <= 4.0 * fabs(S->h0)))
      return dm_err_set(e, DM_EDOM, "sem: the step h = %.6g left (0, 4 h0]", *h);
    I->stats.iters = it + 1;
    if (dm_newton_done(&stop, d, tol))
      break;
  }
  I->stats.residual = d;
  I->stats.tol = tol;
  I->stats.iters_total += I->stats.iters;
  if (it >= I->opt.maxiter)
    return dm_err_set(e, DM_ENOCONV, "sem: Newton did not converge in %d iterations (update "
                      "%.3g, tol %.3g, h = %.6g)", it, d, tol, *h);
  return eval_stages(I, S, *h, q0, 0, e);
}

/* The guess: every stage velocity v(q0, p0). */
static int guess(dm_integrator *I, sem_state *S, const double *q0, const double *p0, dm_err *e)
{
  size_t i;
  int st = dm_integrator_velocity(I, q0, p0, S->v0, 0, e);
  if (st != DM_OK)
    return st;
  for (i = 0; i < S->s; i++)
    memcpy(S->X + i * S->n, S->v0, S->n * sizeof *S->v0);
  return DM_OK;
}

/* A fixed-h solve from the guess; Ed into *Ed. */
static int fixed_solve(dm_integrator *I, sem_state *S, double h, const double *q0,
                       const double *p0, double *Ed, dm_err *e)
{
  int st;
  if ((st = guess(I, S, q0, p0, e)) != DM_OK || (st = newton(I, S, &h, q0, p0, 0, e)) != DM_OK)
    return st;
  *Ed = stage_energy(S);
  return DM_OK;
}

/* {==== the fallback ===================================================== */

static double energy_gap(double h, void *ctx)
{
  sem_state *S = ctx;
  double Ed;
  if (S->fst != DM_OK)
    return NAN;
  S->fst = fixed_solve(S->I, S, h, S->fq0, S->fp0, &Ed, &S->ferr);
  return S->fst == DM_OK ? Ed - S->E : NAN;
}

static double energy_gap2(double h, void *ctx)
{
  double r = energy_gap(h, ctx);
  return r * r;
}

/* Where Newton on (V, h) failed: keep the last step when it still meets
 * the energy; else a root of Ed(h) - E bracketed on a grid around the last
 * step (the sign change nearest to it), else the minimiser of
 * (Ed(h) - E)^2 (the step is then flagged).  The stages hold the solution
 * on success. */
static int fallback(dm_integrator *I, sem_state *S, const double *q0, const double *p0,
                    double *h_out, dm_err *e)
{
  static const double fac[] = {0.125, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0};
  enum { NG = sizeof fac / sizeof fac[0] };
  double hg[NG], rg[NG], H = fabs(S->h0), hl = fabs(S->hprev), hb = hl, lo, hi, r;
  double tolE = 100.0 * DBL_EPSILON * fmax(1.0, fabs(S->E));
  gsl_function F = {energy_gap, S};
  size_t k, best = 0, ng = 0, mid = 0;
  int it, bracket = -1;
  S->fq0 = q0;
  S->fp0 = p0;
  S->fst = DM_OK;
  r = energy_gap(hl, S);
  if (S->fst == DM_OK && fabs(r) <= tolE) {
    *h_out = S->sgn * hl;
    return DM_OK;
  }
  for (k = 0; k < NG; k++) {
    double h = fac[k] * hl;
    if (h > 4.0 * H)
      break;
    S->fst = DM_OK;
    r = energy_gap(h, S);
    if (S->fst != DM_OK)
      continue;
    hg[ng] = h;
    rg[ng] = r;
    if (fac[k] == 1.0)
      mid = ng;
    ng++;
  }
  if (ng == 0)
    return dm_err_set(e, S->ferr.status ? S->ferr.status : DM_ENOCONV, "sem: no step of "
                      "(0, 4 h0] solves the stage equations: %s", S->ferr.msg);
  /* the sign change and the smallest gap nearest to the last step */
  for (k = 0; k < ng; k++) {
    size_t d = k > mid ? k - mid : mid - k, db = best > mid ? best - mid : mid - best;
    if (fabs(rg[k]) < fabs(rg[best]) || (fabs(rg[k]) == fabs(rg[best]) && d < db))
      best = k;
    if (k + 1 < ng && rg[k] * rg[k + 1] <= 0.0) {
      size_t dk = k >= mid ? k - mid : mid - k - 1;
      size_t dbr = bracket < 0 ? NG : (size_t)bracket >= mid ? (size_t)bracket - mid
                                                             : mid - (size_t)bracket - 1;
      if (dk < dbr)
        bracket = (int)k;
    }
  }
  S->fst = DM_OK;
  if (bracket >= 0) {                              /* a root: the energy is matched */
    gsl_root_fsolver_set(S->root, &F, hg[bracket], hg[bracket + 1]);
    for (it = 0; it < 100; it++) {
      gsl_root_fsolver_iterate(S->root);
      lo = gsl_root_fsolver_x_lower(S->root);
      hi = gsl_root_fsolver_x_upper(S->root);
      if (S->fst != DM_OK || gsl_root_test_interval(lo, hi, 0.0, 4.0 * DBL_EPSILON) != GSL_CONTINUE)
        break;
    }
    hb = gsl_root_fsolver_root(S->root);
  } else {                                         /* the smallest gap: flagged */
    size_t a = best > 0 ? best - 1 : best, b = best + 1 < ng ? best + 1 : best;
    hb = hg[best];
    if (a < best && b > best && fabs(rg[a]) > fabs(rg[best]) && fabs(rg[b]) > fabs(rg[best])) {
      gsl_function F2 = {energy_gap2, S};
      if (gsl_min_fminimizer_set_with_values(S->min, &F2, hg[best], rg[best] * rg[best], hg[a],
                                             rg[a] * rg[a], hg[b], rg[b] * rg[b]) == GSL_SUCCESS) {
        for (it = 0; it < 100; it++) {
          gsl_min_fminimizer_iterate(S->min);
          lo = gsl_min_fminimizer_x_lower(S->min);
          hi = gsl_min_fminimizer_x_upper(S->min);
          if (S->fst != DM_OK || gsl_min_test_interval(lo, hi, 0.0, 1e-10) != GSL_CONTINUE)
            break;
        }
        hb = gsl_min_fminimizer_x_minimum(S->min);
      }
    }
  }
  S->fst = DM_OK;
  r = energy_gap(hb, S);                      /* the stages at the chosen h */
  if (S->fst != DM_OK)
    return dm_err_set(e, S->ferr.status, "sem: %s", S->ferr.msg);
  if (fabs(r) > tolE)
    I->stats.flagged++;
  *h_out = S->sgn * hb;
  return DM_OK;
}

/* }====================================================================== */

/* Outputs of a converged step of size h: q1, p1 (Kahan carries when the
 * step continues the last one), the clock. */
static void finish(dm_integrator *I, sem_state *S, double h, const double *q0, const double *p0,
                   double *q1, double *p1)
{
  size_t n = S->n, s = S->s, a, j;
  const double *B = S->tab->b;
  int cont = S->hist && dm_same(q0, S->hq, n) && dm_same(p0, S->hp, n);
  if (!cont) {
    memset(S->cq, 0, 2 * n * sizeof *S->cq);
    S->tc = 0.0;
  }
  for (a = 0; a < n; a++) {
    double sq = 0.0, sp = 0.0, y, t;
    for (j = 0; j < s; j++) {
      sq += B[j] * S->X[j * n + a];
      sp += B[j] * S->Lq[j * n + a];
    }
    y = h * sq - S->cq[a];
    t = q0[a] + y;
    S->cq[a] = (t - q0[a]) - y;
    q1[a] = t;
    y = h * sp - S->cp[a];
    t = p0[a] + y;
    S->cp[a] = (t - p0[a]) - y;
    p1[a] = t;
  }
  {
    double y = h - S->tc, t = I->t + y;
    S->tc = (t - I->t) - y;
    I->t = t;
  }
  memcpy(S->hq, q1, n * sizeof *q1);
  memcpy(S->hp, p1, n * sizeof *p1);
  S->hist = 1;
  S->Elast = stage_energy(S);
  I->dt = h;
  I->stats.steps++;
}

static int sem_begin(dm_integrator *I, double h, double t0, const double *q0, const double *p0,
                     dm_err *e)
{
  sem_state *S = I->state;
  double Ed;
  int st;
  S->h0 = h;
  S->sgn = h > 0 ? 1.0 : -1.0;
  if ((st = fixed_solve(I, S, h, q0, p0, &Ed, e)) != DM_OK)
    return st;
  S->E = Ed;
  S->hprev = h;
  S->hist = 0;
  I->t = t0;
  I->dt = h;
  return DM_OK;
}

static int sem_step(dm_integrator *I, double h, const double *q0, const double *p0, double *q1,
                    double *p1, dm_err *e)
{
  sem_state *S = I->state;
  double hk;
  dm_err le;
  int st;
  if (!I->begun && (st = dm_integrator_begin(I, h, I->t, q0, p0, e)) != DM_OK)
    return st;
  hk = S->hprev;
  if ((st = guess(I, S, q0, p0, e)) != DM_OK)
    return st;
  if ((st = newton(I, S, &hk, q0, p0, 1, &le)) != DM_OK) {
    if (st == DM_EINTR || st == DM_ECALLBACK)
      return dm_err_set(e, st, "%s", le.msg);
    if ((st = fallback(I, S, q0, p0, &hk, e)) != DM_OK)
      return st;
  }
  finish(I, S, hk, q0, p0, q1, p1);
  S->hprev = hk;
  return DM_OK;
}

/* The energy step, or when it passes t_end a fixed step ending there. */
static int sem_step_until(dm_integrator *I, double h, double t_end, const double *q0,
                          const double *p0, double *q1, double *p1, int *reached, dm_err *e)
{
  sem_state *S = I->state;
  double t0 = I->t, tc = S->tc, tol = 4.0 * DBL_EPSILON * fmax(fabs(t0), fabs(t_end)), rest, Ed;
  double hp = S->hprev;
  int st;
  *reached = 0;
  if ((st = sem_step(I, h, q0, p0, q1, p1, e)) != DM_OK)
    return st;
  if (S->sgn * (I->t - t_end) < -tol)
    return DM_OK;
  *reached = 1;
  if (fabs(I->t - t_end) <= tol) {
    I->t = t_end;
    return DM_OK;
  }
  I->t = t0;
  S->tc = tc;
  S->hprev = hp;
  I->stats.steps--;
  rest = t_end - t0;
  if ((st = fixed_solve(I, S, rest, q0, p0, &Ed, e)) != DM_OK)
    return st;
  finish(I, S, rest, q0, p0, q1, p1);
  I->t = t_end;
  return DM_OK;
}

static void sem_reset(dm_integrator *I)
{
  sem_state *S = I->state;
  S->hist = 0;
}

static int sem_advance(dm_integrator *I, double h, long nsteps, double *q, double *p, long *done,
                       dm_err *e)
{
  long k;
  int st = DM_OK;
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = DM_EINTR;
      break;
    }
    if ((st = sem_step(I, h, q, p, q, p, e)) != DM_OK)
      break;
  }
  *done = k;
  return st;
}

const dm_integrator_type dm_integ_sem = {
  .name = "sem",
  .summary = "symplectic-energy-momentum: Gauss Galerkin steps whose size keeps the discrete "
    "energy (stages >= 1, default 1 = midpoint), variable h",
  .order = 0,
  .flags = DM_INTEG_SYMMETRIC | DM_INTEG_VARSTEP,
  .options = sem_options,
  .alloc = sem_alloc,
  .step = sem_step,
  .jacobian = NULL,
  .dlegendre = NULL,
  .advance = sem_advance,
  .reset = sem_reset,
  .free = sem_free,
  .begin = sem_begin,
  .step_until = sem_step_until,
};

int dm_sem_is(const dm_integrator *I)
{
  return I != NULL && I->type == &dm_integ_sem;
}

double dm_sem_energy_level(const dm_integrator *I)
{
  return dm_sem_is(I) && I->begun ? ((const sem_state *)I->state)->E : NAN;
}

double dm_sem_last_energy(const dm_integrator *I)
{
  return dm_sem_is(I) ? ((const sem_state *)I->state)->Elast : NAN;
}

int dm_sem_set_energy_level(dm_integrator *I, double E, dm_err *e)
{
  if (!dm_sem_is(I))
    return dm_err_set(e, DM_EINVAL, "not an energy-momentum integrator (method 'sem')");
  if (!I->begun)
    return dm_err_set(e, DM_EINVAL, "sem: begin the run first (the level is set by begin)");
  if (!isfinite(E))
    return dm_err_set(e, DM_EINVAL, "sem: the energy level must be finite");
  ((sem_state *)I->state)->E = E;
  return DM_OK;
}
