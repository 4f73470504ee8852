/* prk_engine.c -- implicit symplectic PRK step for a Lagrangian system.
 *
 * Unknowns are the s stage velocities V_i = Qdot_i (doc/integrators.md §6):
 *   Q_i = q0 + h sum_j a_ij V_j,
 *   R_i = Lv(Q_i, V_i) - p0 - h sum_j at_ij W_j = 0,   W_j = Lq(Q_j, V_j) + F(Q_j, V_j)
 *   q1 = q0 + h sum_j b_j V_j,   p1 = p0 + h sum_j b_j W_j
 * (W includes the generalized force: discrete Lagrange-d'Alembert, doc/integrators.md §9).
 * Newton uses the exact Jacobian
 *   dR_i/dV_k = d_ik Lvv_i + h a_ik Lvq_i - h at_ik (Lvq_k^T + Fv_k)
 *               - h^2 sum_j at_ij a_jk (Lqq_j + Fq_j),
 * factored with GSL LU (by default as a simplified Newton: the Jacobian
 * factored at the first iterate is reused while the updates contract at
 * least tenfold, and refreshed otherwise; option simplified = false
 * refactors every iteration), and iterates to round-off with the stopping
 * rule of src/core/newton.h (scaled update <= tol, default 10 eps, or a
 * round-off stall below DM_NEWTON_ACCEPT = 1e-10); at most maxiter
 * iterations (failure: DM_ENOCONV with the update, residual and tolerance).
 * A separable, unforced, unconstrained system L = 1/2 v^T M v - V(q)
 * first iterates without any matrix (option iteration, default auto):
 *   V_i <- V_i - M^{-1} R_i = M^{-1} (p0 + h sum_j at_ij W_j),
 * with the same stopping rule; when the updates contract less than
 * DM_PRK_FIXED_RATE per iteration Newton takes over from the predictor
 * (and is used alone for the next DM_PRK_FIXED_BACKOFF steps).
 * Both converge to the same stages, so they agree to round-off.
 * The predictor extrapolates the previous step's stage-velocity polynomial
 * (nodes c, values V) to the new stage times; without history (or with
 * repeated nodes) it starts from the previous stages or from v(q0, p0).
 * q and p increments are added with Kahan compensation; the carries persist
 * while steps continue from the previous output.
 *
 * The discrete Legendre transforms (p0, p1, Ld for given q0, q1) are the
 * Galerkin discrete Lagrangian of the same tableau: galerkin.h, the one
 * solver of that boundary problem (the discrete Routh equations use it too).
 *
 * The Jacobian of the step map comes from the implicit function theorem on
 * R(V; q0, p0) = 0 at the converged stages:
 *   dV = -J^{-1} [dR/dq0 | dR/dp0],  dR_i/dq0 = Lvq_i - h sum_j at_ij D_j,
 *   dR_i/dp0 = -I, then dq1 = dq0 + h sum b_j dV_j,
 *   dp1 = dp0 + h sum_j b_j (D_j dQ_j + Bm_j dV_j).
 */
#include <config.h>
#include "core/numfmt.h"
#include "integrators/prk_impl.h"
#include "integrators/prk_kernels.h"
#include "core/interrupt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static size_t nunk(const dm_prk *P, int mode)
{
  return mode == DM_PRK_CSTEP ? P->sn + P->nK * P->m + P->m : P->sn;
}

/* Dense or sparse Newton matrices (linear = DM_LINEAR_AUTO): dense up to
 * DM_PRK_SPARSE_MIN unknowns and whenever the system has no pattern or a
 * stage block would be more than a quarter full; sparse above (or when
 * the dense matrix would not fit comfortably: DM_PRK_DENSE_MAX unknowns).
 * See doc/scale.md for the measurements behind the numbers. */
#define DM_PRK_SPARSE_MIN 48
#define DM_PRK_DENSE_MAX 2048
/* The fixed-point iteration (see the top): abandoned for Newton when an
 * update is more than DM_PRK_FIXED_RATE times the one before (or after
 * DM_PRK_FIXED_MAXITER iterations), then not tried for
 * DM_PRK_FIXED_BACKOFF steps.  One iteration costs the stage forces only,
 * a Newton iteration also a linear solve with the s n x s n matrix (and
 * its factorisation, the second derivatives): see doc/scale.md for the
 * measurements (Gauss 2: 2 to 9 times faster from 2 to 1024 coordinates). */
#define DM_PRK_FIXED_RATE 0.25
#define DM_PRK_FIXED_MAXITER 30
#define DM_PRK_FIXED_BACKOFF 64

static int want_sparse(const dm_system *sys, size_t s, size_t N, int linear)
{
  if (linear != DM_LINEAR_AUTO)
    return linear == DM_LINEAR_SPARSE;
  const dm_sys_pattern *p = sys->pattern;
  size_t n = sys->n;
  if (N <= DM_PRK_SPARSE_MIN)
    return 0;
  if (p == NULL)
    return N > DM_PRK_DENSE_MAX;
  double nnz = (double)(p->vv.nnz + 2 * p->vq.nnz + p->qq.nnz + p->fq.nnz + p->fv.nnz);
  if (sys->m > 0)
    nnz = (double)n * (double)n;       /* curvature terms fill the blocks */
  (void)s;
  return N > DM_PRK_DENSE_MAX || nnz <= 0.25 * (double)n * (double)n;
}

int dm_prk_alloc(const dm_system *sys, const dm_tableau *t, double tol,
                 int maxiter, int explicit_sv, int linear, dm_prk **out, dm_err *e)
{
  dm_prk *P = calloc(1, sizeof *P);
  size_t n = sys->n, s = t->s, m = sys->m, nn = n * n, sn = s * n, i, j, tot;
  size_t extra, mat, stg, rhs;
  double *d;
  int st;
  *out = NULL;
  if (P == NULL)
    return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
  P->sys = sys;
  P->n = n;
  P->s = s;
  P->m = m;
  P->sn = sn;
  P->nn = nn;
  P->forced = sys->force != NULL;
  P->sep = (sys->flags & DM_SYS_SEPARABLE) && !P->forced &&
           (sys->mass != NULL || (sys->pattern != NULL && sys->pattern->mass != NULL));
  P->tol = tol;
  P->maxiter = maxiter;
  P->simplified = 1;
  P->E_ratio = NAN;
  if ((P->tab = dm_tableau_copy(t)) == NULL) {
    free(P);
    return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
  }
  if (m > 0 && (st = dm_prk_constr_layout(P, e)) != DM_OK) {
    dm_tableau_free(P->tab);
    free(P);
    return st;
  }
  extra = P->nK * m + m;
  P->Nmax = sn + extra;
  P->sparse = want_sparse(sys, s, P->Nmax, linear);
  P->large = P->sparse && m == 0 && sys->pattern != NULL;
  /* the dense Newton matrix, the n x n stage arrays, the step Jacobian's
   * right-hand sides: only what the mode needs (a large system has none) */
  mat = !P->sparse ? P->Nmax * P->Nmax
        : m > 0 ? (n + m) * (n + m)      /* the momentum projection's matrix */
        : 0;
  stg = P->large ? 0 : 7 * s * nn;
  rhs = P->large ? P->Nmax : P->Nmax * 2 * n;
  tot = mat + 3 * P->Nmax + 5 * sn + stg + s
        + (s + 2) * (m + m * n + m * nn) + 6 * n + rhs
        + sn + P->Nmax + 2 * n + s * s + 2 * n + n + n;
  d = calloc(tot, sizeof(double));
  P->perm = calloc(P->Nmax, sizeof(size_t));
  P->work = sys->work_size ? malloc(sys->work_size) : NULL;
  P->leg = dm_legendre_alloc(sys);
  if (m == 0 && (st = dm_galerkin_alloc(sys, t, tol, maxiter, &P->gal, e)) != DM_OK) {
    free(d);
    P->Jm = NULL;
    dm_prk_free(P);
    return st;
  }
  if (d == NULL || P->perm == NULL || (sys->work_size && P->work == NULL) || P->leg == NULL) {
    free(d);
    P->Jm = NULL;
    dm_prk_free(P);
    return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
  }
  P->block = d;
#define TAKE(ptr, cnt) do { (ptr) = (cnt) > 0 ? d : NULL; d += (cnt); } while (0)
  TAKE(P->Jm, mat);
  TAKE(P->R, P->Nmax);
  TAKE(P->X, P->Nmax);
  TAKE(P->hx, P->Nmax);
  TAKE(P->Q, sn); TAKE(P->Lq, sn); TAKE(P->Lv, sn); TAKE(P->W, sn); TAKE(P->F, sn);
  TAKE(P->Lvv, stg / 7); TAKE(P->Lvq, stg / 7); TAKE(P->Lqq, stg / 7);
  TAKE(P->Fq, stg / 7); TAKE(P->Fv, stg / 7); TAKE(P->D, stg / 7); TAKE(P->Bm, stg / 7);
  TAKE(P->Lval, s);
  TAKE(P->g, (s + 2) * m); TAKE(P->G, (s + 2) * m * n); TAKE(P->Hc, (s + 2) * m * nn);
  TAKE(P->q1w, n); TAKE(P->p1w, n); TAKE(P->v1w, n); TAKE(P->dq, n); TAKE(P->dp, n);
  TAKE(P->tmp, n);
  TAKE(P->rhs, rhs);
  TAKE(P->hV, sn); TAKE(P->hq1, n); TAKE(P->hp1, n); TAKE(P->E, s * s);
  TAKE(P->cq, n); TAKE(P->cp, n); TAKE(P->Mdiag, n); TAKE(P->svf, n);
#undef TAKE
  P->distinct_nodes = 1;
  for (i = 0; i < s; i++)
    for (j = 0; j < i; j++)
      if (fabs(t->c[i] - t->c[j]) < 1e-8)
        P->distinct_nodes = 0;
  if (P->sparse && (st = dm_prk_sparse_setup(P, P->large, e)) != DM_OK) {
    dm_prk_free(P);
    return st;
  }
  if (explicit_sv && (st = dm_prk_verlet_setup(P, e)) != DM_OK) {
    dm_prk_free(P);
    return st;
  }
  *out = P;
  return DM_OK;
}

void dm_prk_free(dm_prk *P)
{
  if (P == NULL)
    return;
  free(P->block);
  free(P->Minv);
  dm_prk_sparse_free(P->sp);
  free(P->perm);
  free(P->work);
  dm_legendre_free(P->leg);
  dm_galerkin_free(P->gal);
  dm_tableau_free(P->tab);
  free(P);
}

void dm_prk_reset(dm_prk *P)
{
  P->hist = 0;
  P->fixed_backoff = 0;
  P->svf_valid = 0;
  P->E_ratio = NAN;
  memset(P->cq, 0, P->n * sizeof(double));
  memset(P->cp, 0, P->n * sizeof(double));
}

int dm_prk_is_explicit(const dm_prk *P)
{
  return P->explicit_sv;
}

static int eval_dense(dm_prk *P, size_t i, int jac, int want_L, dm_err *e);

/* Evaluate L (and the force) at stage i: gradients always, the value when
 * want_L, second derivatives when jac; W, D, Bm derived. */
int dm_prk_eval_stage(dm_prk *P, size_t i, int jac, int want_L, dm_err *e)
{
  if (P->large)
    return dm_prk_sparse_eval_stage(P, i, jac, want_L, e);
  int st = eval_dense(P, i, jac, want_L, e);
  if (st == DM_OK && jac && P->sparse)
    dm_prk_sparse_gather(P, i);
  return st;
}

/* dm_prk_eval_stage into the dense stage arrays. */
static int eval_dense(dm_prk *P, size_t i, int jac, int want_L, dm_err *e)
{
  size_t n = P->n, nn = P->nn, a, b;
  double *Qi = P->Q + i * n, *Vi = P->X + i * n;
  dm_lag_out o = {0, P->Lq + i * n, P->Lv + i * n, P->Lvv + i * nn, P->Lvq + i * nn,
                  P->Lqq + i * nn};
  /* a separable L has Lvv = M (sys->mass, current parameters) and Lvq = 0:
   * only Lqq is asked for with the Jacobian, and Lvq, Bm stay zero */
  unsigned what = DM_LAG_Q | DM_LAG_V | (want_L ? DM_LAG_L : 0u)
                  | (jac ? (P->sep ? DM_LAG_QQ : (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ)) : 0u);
  int st = dm_eval_lag(P->sys, Qi, Vi, what, &o, P->work, e);
  if (st != DM_OK)
    return st;
  P->Lval[i] = o.L;
  if (!P->forced) {
    /* F, Fq, Fv stay zero: W = Lq, D = Lqq, Bm = Lvq^T without the additions */
    dm_vcopy(P->W + i * n, P->Lq + i * n, n);
    if (jac) {
      const double *Lvq = P->Lvq + i * nn;
      double *Bm = P->Bm + i * nn;
      dm_vcopy(P->D + i * nn, P->Lqq + i * nn, nn);
      if (P->sep) {
        if (P->sys->mass != NULL)
          dm_vcopy(P->Lvv + i * nn, P->sys->mass, nn);
        else
          dm_csr_to_dense(&P->sys->pattern->vv, P->sys->pattern->mass, P->Lvv + i * nn);
        return DM_OK;
      }
      for (a = 0; a < n; a++)
        for (b = 0; b < n; b++)
          Bm[a * n + b] = Lvq[b * n + a];
    }
    return DM_OK;
  }
  {
    unsigned fw = DM_FORCE_F | (jac ? (DM_FORCE_Q | DM_FORCE_V) : 0u);
    st = dm_eval_force(P->sys, Qi, Vi, fw, P->F + i * n, P->Fq + i * nn, P->Fv + i * nn,
                       P->work, e);
    if (st != DM_OK)
      return st;
  }
  for (a = 0; a < n; a++)
    P->W[i * n + a] = P->Lq[i * n + a] + P->F[i * n + a];
  if (jac)
    for (a = 0; a < n; a++)
      for (b = 0; b < n; b++) {
        P->D[i * nn + a * n + b] = P->Lqq[i * nn + a * n + b] + P->Fq[i * nn + a * n + b];
        P->Bm[i * nn + a * n + b] = P->Lvq[i * nn + b * n + a] + P->Fv[i * nn + a * n + b];
      }
  return DM_OK;
}

/* The stage-velocity block of the Newton matrix (row stride N):
 *   J_ik = d_ik Lvv_i + h a_ik Lvq_i - h at_ik Bm_k - sum_j (h^2 at_ij a_jk) D_j,
 * each entry accumulated in a register (restrict: the arrays never alias). */
static void newton_matrix(dm_prk *P, double h, size_t N)
{
  const size_t n = P->n, s = P->s, nn = P->nn;
  const double *restrict A = P->tab->a, *restrict At = P->tab->at;
  const double *restrict Lvv = P->Lvv, *restrict Lvq = P->Lvq, *restrict Bm = P->Bm;
  const double *restrict D = P->D;
  double *restrict Jm = P->Jm, cj[DM_TABLEAU_SMAX];
  const int sep = P->sep;       /* Lvq = Bm = 0 */
  size_t i, j, k, a, c;
  for (i = 0; i < s; i++)
    for (k = 0; k < s; k++) {
      const double hak = h * A[i * s + k], hatk = h * At[i * s + k];
      const double *Lvqi = Lvq + i * nn, *Bmk = Bm + k * nn, *Lvvi = Lvv + i * nn;
      for (j = 0; j < s; j++)
        cj[j] = h * h * At[i * s + j] * A[j * s + k];
      for (a = 0; a < n; a++) {
        double *Jr = Jm + (i * n + a) * N + k * n;
        for (c = 0; c < n; c++) {
          double v = sep ? 0.0 : hak * Lvqi[a * n + c] - hatk * Bmk[a * n + c];
          if (i == k)
            v += Lvvi[a * n + c];
          for (j = 0; j < s; j++)
            v -= cj[j] * D[j * nn + a * n + c];
          Jr[c] = v;
        }
      }
    }
}

/* Residual (and Newton matrix when jac) of the stage equations at X. */
static int assemble(dm_prk *P, int mode, double h, const double *q0, const double *p0, int jac,
                    dm_err *e)
{
  const size_t n = P->n, s = P->s, sn = P->sn, N = nunk(P, mode);
  const double *A = P->tab->a, *At = P->tab->at;
  const double *V = P->X, *pp = p0;
  size_t i, j, a;
  int st;
  {
    double *restrict Q = P->Q;   /* restrict in these blocks only: the */
    for (i = 0; i < s; i++)      /* stage evaluation reads and writes P */
      for (a = 0; a < n; a++) {
        double acc = 0.0;
        for (j = 0; j < s; j++)
          acc += A[i * s + j] * V[j * n + a];
        Q[i * n + a] = q0[a] + h * acc;
      }
  }
  for (i = 0; i < s; i++)
    if ((st = dm_prk_eval_stage(P, i, jac, 0, e)) != DM_OK)
      return st;
  {
    const double *restrict W = P->W, *restrict Lv = P->Lv;
    double *restrict R = P->R;
    for (i = 0; i < s; i++)
      for (a = 0; a < n; a++) {
        double acc = 0.0;
        for (j = 0; j < s; j++)
          acc += At[i * s + j] * W[j * n + a];
        R[i * n + a] = Lv[i * n + a] - pp[a] - h * acc;
      }
  }
  if (jac && !P->sparse) {
    if (N > sn)
      memset(P->Jm, 0, N * N * sizeof(double));
    newton_matrix(P, h, N);
    P->lvv_norm = dm_norm_inf(P->Lvv, s * P->nn);
  }
  if (mode == DM_PRK_CSTEP && (st = dm_prk_constr_assemble(P, h, q0, jac, e)) != DM_OK)
    return st;
  if (jac && P->sparse) {
    dm_prk_sparse_matrix(P, h);
    P->lvv_norm = dm_prk_sparse_lvv_norm(P);
  }
  return DM_OK;
}

/* Scaled size of the Newton update held in R: velocities relative to
 * max(|V|, momentum scale / |Lvv|), multipliers and p0 relative to
 * max(|x|, momentum scale) with momentum scale |p| + |h| |W|.  rv and xv
 * are max |R| and max |X| over the velocity block (computed by the caller
 * while it applied the update). */
static double update_norm(const dm_prk *P, int mode, double h, const double *p0, double rv,
                          double xv)
{
  size_t sn = P->sn, N = nunk(P, mode);
  double ms = dm_norm_inf(p0, P->n) + fabs(h) * dm_norm_inf(P->W, sn);
  double lv = P->lvv_norm;      /* Lvv changes only with the Jacobian */
  double vs = dm_max3(xv, lv > 0 ? ms / lv : 0.0, DBL_MIN);
  double d = rv / vs;
  if (N > sn) {
    double xs = dm_max3(dm_norm_inf(P->X + sn, N - sn), ms, DBL_MIN);
    d = dm_max2(d, dm_norm_inf(P->R + sn, N - sn) / xs);
  }
  return d;
}

int dm_prk_singular(dm_prk *P, const char *what, double h, dm_err *e)
{
  size_t n = P->n, i;
  char bq[160], bv[160];
  /* which stage's d2L/dv2 is singular, when there are dense ones to look
   * at (scratch: an error path may allocate) */
  double *A = P->Lvv != NULL ? malloc(P->nn * sizeof *A) : NULL;
  size_t *perm = A != NULL ? malloc(n * sizeof *perm) : NULL;
  for (i = 0; perm != NULL && i < P->s; i++) {
    memcpy(A, P->Lvv + i * P->nn, P->nn * sizeof(double));
    if (dm_smalllu_factor(A, n, perm) != DM_OK) {
      free(A);
      free(perm);
      return dm_err_set(e, DM_ESINGULAR,
                        "d2L/dv2 is singular at stage %zu (q = %s, v = %s): the Lagrangian of "
                        "'%s' is not regular (its Hessian in the velocities must be invertible)",
                        i + 1, dm_num_format_vec(bq, sizeof bq, P->Q + i * n, n),
                        dm_num_format_vec(bv, sizeof bv, P->X + i * n, n),
                        P->sys->name ? P->sys->name : "system");
    }
  }
  free(A);
  free(perm);
  return dm_err_set(e, DM_ESINGULAR, "singular Newton matrix of the %s (h = %g)%s", what, h,
                    P->m ? "; the constraint gradients may be linearly dependent"
                         : "; try a smaller step");
}

/* One fixed-point iteration at X: the stage points Q, the forces W = Lq
 * there (the only derivative it needs: Lv = M V is the mass's), and
 *   X_i <- M^{-1} (p0 + h sum_j at_ij W_j);
 * returns the scaled update (update_norm's, NaN when something is not
 * finite) or an evaluation error in *st. */
/* update_norm's scaling (velocities against max(|V|, momentum scale /
 * |M|)), |p0| computed once per step; NaN when nan is not 0 */
static double fixed_norm(const dm_prk *P, double h, double p0norm, double wn, double rv,
                         double xv, double nan)
{
  if (nan != 0.0 || nan != nan)
    return NAN;
  double ms = p0norm + fabs(h) * wn, lv = P->mass_norm;
  return rv / dm_max3(xv, lv > 0 ? ms / lv : 0.0, DBL_MIN);
}

/* fixed_iterate for two stages and a diagonal mass: each loop one pass,
 * the same arithmetic as the general one (sums from 0.0, j ascending). */
static double fixed_iterate2(dm_prk *P, double h, const double *restrict q0,
                             const double *restrict p0, double p0norm, int *st, dm_err *e)
{
  const size_t n = P->n;
  const double *A = P->tab->a, *At = P->tab->at;
  const double a00 = A[0], a01 = A[1], a10 = A[2], a11 = A[3];
  const double b00 = At[0], b01 = At[1], b10 = At[2], b11 = At[3];
  const double *restrict Md = P->Mdiag;
  const int diag = P->mass_kind == DM_MASS_DIAG;
  double *restrict X0 = P->X, *restrict X1 = P->X + n;
  double *restrict Q0 = P->Q, *restrict Q1 = P->Q + n;
  double *restrict W0 = P->W, *restrict W1 = P->W + n;
  double rv = 0.0, xv = 0.0, wn = 0.0, nan = 0.0;
  for (size_t a = 0; a < n; a++) {
    const double x0 = X0[a], x1 = X1[a];
    double c0 = 0.0, c1 = 0.0;
    c0 += a00 * x0;
    c0 += a01 * x1;
    c1 += a10 * x0;
    c1 += a11 * x1;
    Q0[a] = q0[a] + h * c0;
    Q1[a] = q0[a] + h * c1;
  }
  for (size_t i = 0; i < 2; i++) {
    dm_lag_out o = {0, P->W + i * n, P->Lv + i * n, NULL, NULL, NULL};
    if ((*st = dm_eval_lag(P->sys, P->Q + i * n, P->X + i * n, DM_LAG_Q, &o, P->work, e))
        != DM_OK)
      return NAN;
  }
  for (size_t a = 0; a < n; a++) {
    const double w0 = W0[a], w1 = W1[a];
    double c0 = 0.0, c1 = 0.0;
    c0 += b00 * w0;
    c0 += b01 * w1;
    c1 += b10 * w0;
    c1 += b11 * w1;
    double t0 = p0[a] + h * c0, t1 = p0[a] + h * c1;
    if (diag) {
      t0 *= Md[a];
      t1 *= Md[a];
    }
    const double r0 = fabs(X0[a] - t0), r1 = fabs(X1[a] - t1);
    const double y0 = fabs(t0), y1 = fabs(t1), v0 = fabs(w0), v1 = fabs(w1);
    X0[a] = t0;
    X1[a] = t1;
    rv = r0 > rv ? r0 : rv;
    rv = r1 > rv ? r1 : rv;
    xv = y0 > xv ? y0 : xv;
    xv = y1 > xv ? y1 : xv;
    wn = v0 > wn ? v0 : wn;
    wn = v1 > wn ? v1 : wn;
    nan += (r0 + r1) * 0.0;
  }
  *st = DM_OK;
  return fixed_norm(P, h, p0norm, wn, rv, xv, nan);
}

static double fixed_iterate(dm_prk *P, double h, const double *q0, const double *p0,
                            double p0norm, int *st, dm_err *e)
{
  const size_t n = P->n, s = P->s;
  const double *restrict A = P->tab->a, *restrict At = P->tab->at;
  const double *restrict Md = P->Mdiag;
  double *restrict X = P->X, *restrict Q = P->Q, *restrict W = P->W;
  double *restrict t = P->tmp, rv = 0.0, xv = 0.0, nan = 0.0;
  if (s == 2 && P->mass_kind != DM_MASS_FULL)
    return fixed_iterate2(P, h, q0, p0, p0norm, st, e);
  /* the sums over j in the order of assemble's (bitwise the same), as
   * loops over a that vectorise */
  for (size_t i = 0; i < s; i++) {
    double *restrict Qi = Q + i * n;
    memset(t, 0, n * sizeof *t);
    for (size_t j = 0; j < s; j++) {
      const double c = A[i * s + j], *restrict Xj = X + j * n;
      for (size_t a = 0; a < n; a++)
        t[a] += c * Xj[a];
    }
    for (size_t a = 0; a < n; a++)
      Qi[a] = q0[a] + h * t[a];
  }
  for (size_t i = 0; i < s; i++) {
    dm_lag_out o = {0, W + i * n, P->Lv + i * n, NULL, NULL, NULL};
    if ((*st = dm_eval_lag(P->sys, Q + i * n, X + i * n, DM_LAG_Q, &o, P->work, e)) != DM_OK)
      return NAN;
  }
  double wn = 0.0;
  for (size_t a = 0; a < s * n; a++) {
    double w = fabs(W[a]);
    wn = w > wn ? w : wn;
  }
  for (size_t i = 0; i < s; i++) {
    double *restrict Xi = X + i * n;
    t = P->tmp;
    memset(t, 0, n * sizeof *t);
    for (size_t j = 0; j < s; j++) {
      const double c = At[i * s + j], *restrict Wj = W + j * n;
      for (size_t a = 0; a < n; a++)
        t[a] += c * Wj[a];
    }
    for (size_t a = 0; a < n; a++)
      t[a] = p0[a] + h * t[a];
    if (P->mass_kind == DM_MASS_FULL) {
      const double *Mi = P->Minv;
      for (size_t a = 0; a < n; a++) {
        double u = 0.0;
        for (size_t c = 0; c < n; c++)
          u += Mi[a * n + c] * t[c];
        P->v1w[a] = u;
      }
      t = P->v1w;
    } else if (P->mass_kind == DM_MASS_DIAG) {
      for (size_t a = 0; a < n; a++)
        t[a] *= Md[a];
    }
    for (size_t a = 0; a < n; a++) {
      double r = fabs(Xi[a] - t[a]), x = fabs(t[a]);
      Xi[a] = t[a];
      rv = r > rv ? r : rv;
      xv = x > xv ? x : xv;
      nan += r * 0.0;                   /* NaN iff r is (x NaN makes r NaN) */
    }
  }
  *st = DM_OK;
  return fixed_norm(P, h, p0norm, wn, rv, xv, nan);
}

/* The fixed-point iteration from the predicted stages: DM_OK with *done
 * set when it converged (stages, W and stats as newton leaves them), DM_OK
 * with *done clear when Newton should take over (from the predictor again
 * when an iterate went bad), or an error that Newton could not avoid
 * either (out of memory, interrupted). */
static int fixed_point(dm_prk *P, int mode, double h, const double *q0, const double *p0,
                       int *its, int *done, double *dout, dm_err *e)
{
  const size_t sn = P->sn;
  double d = HUGE_VAL, dlast = HUGE_VAL;
  double *saved = P->rhs;              /* the predictor (rhs: scratch between steps) */
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st = DM_OK;
  const double p0norm = dm_norm_inf(p0, P->n);
  *done = 0;
  *its = 0;
  memcpy(saved, P->X, sn * sizeof(double));
  P->lvv_norm = P->mass_norm;
  for (it = 1; it <= DM_PRK_FIXED_MAXITER; it++) {
    dm_err le;
    d = fixed_iterate(P, h, q0, p0, p0norm, &st, &le);
    if (st == DM_ENOMEM || st == DM_EINTR) {
      if (e != NULL)
        *e = le;
      return st;
    }
    *its = it;
    if (st != DM_OK || !isfinite(d))
      break;                            /* a bad iterate: Newton from the predictor */
    /* at the tolerance (stopping earlier on the rate, d rate / (1 - rate)
     * <= tol, leaves an error of about tol per step where Newton leaves
     * far less: Kepler's reversal over 2 x 200 steps went from 4e-14 to
     * 3e-12) */
    if (dm_newton_done(&stop, d, P->tol)) {
      *done = 1;
      break;
    }
    if (it >= 2 && d > DM_PRK_FIXED_RATE * dlast)
      break;                            /* slow or diverging: Newton from the predictor */
    dlast = d;
  }
  if (!*done) {
    /* not from the iterate reached: the scaled update stays near 1 while
     * the iterates grow without bound (h too large), and Newton from
     * there would start from garbage where alone it finds the stages or
     * reports the divergence as it always did */
    memcpy(P->X, saved, sn * sizeof(double));
    P->fixed_backoff = P->iteration == DM_ITER_AUTO ? DM_PRK_FIXED_BACKOFF : 0;
    return DM_OK;
  }
  *dout = d;
  /* the forces were evaluated before the last update, as in newton */
  if (d <= 1e-12)
    return DM_OK;
  return assemble(P, mode, h, q0, p0, 0, e);   /* W at the final stages */
}

static int use_fixed(dm_prk *P, int mode)
{
  if (mode != DM_PRK_STEP || !P->fixed_ok || P->iteration == DM_ITER_NEWTON)
    return 0;
  if (P->fixed_backoff > 0) {
    P->fixed_backoff--;
    return 0;
  }
  return 1;
}

static int newton(dm_prk *P, int mode, double h, const double *q0, const double *p0,
                  dm_integ_stats *stt, dm_err *e)
{
  size_t N = nunk(P, mode), i;
  double d = HUGE_VAL, dlast = HUGE_VAL, rn = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st, ok = 0, jac = 1, njac = 0, fits = 0;
  if (use_fixed(P, mode)) {
    int done;
    double fd = 0.0;
    if ((st = fixed_point(P, mode, h, q0, p0, &fits, &done, &fd, e)) != DM_OK)
      return st;
    if (done) {
      if (stt) {
        stt->iters = fits;
        stt->jacs = 0;
        stt->residual = fd;
        stt->tol = P->tol;
        stt->iters_total += fits;
        stt->fixed_total++;
      }
      P->njac = 0;
      return DM_OK;
    }
  }
  for (it = 1; it <= P->maxiter; it++) {
    if ((st = assemble(P, mode, h, q0, p0, jac, e)) != DM_OK)
      return st;
    rn = dm_norm_inf(P->R, N);
    if (!isfinite(rn))
      return dm_err_set(e, DM_EDOM, "non-finite residual in the stage equations (h = %g, iteration %d)",
                        h, it);
    if (jac) {
      njac++;
      st = P->sparse ? dm_prk_sparse_factor(P, NULL) : dm_smalllu_factor(P->Jm, N, P->perm);
      if (st == DM_ESINGULAR)
        return dm_prk_singular(P, "stage equations", h, e);
      if (st == DM_ENOMEM)
        return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
      if (st != DM_OK)
        return dm_err_set(e, DM_EDOM, "non-finite Newton matrix (h = %g)", h);
    }
    if (P->sparse)
      dm_prk_sparse_solve(P, P->R);
    else
      dm_smalllu_solve(P->Jm, N, P->perm, P->R);
    {
      /* X -= R; max |R| and max |X| of the velocities on the way (a NaN
       * in either makes d NaN: the test below catches it) */
      double *X = P->X, rv = 0.0, xv = 0.0;
      const double *R = P->R;
      int nan = 0;
      for (i = 0; i < P->sn; i++) {
        double r = fabs(R[i]), x;
        X[i] -= R[i];
        x = fabs(X[i]);
        rv = r > rv ? r : rv;
        xv = x > xv ? x : xv;
        nan |= (r != r) | (x != x);
      }
      for (; i < N; i++)
        X[i] -= R[i];
      d = update_norm(P, mode, h, p0, nan ? NAN : rv, xv);
    }
    if (!isfinite(d))
      return dm_err_set(e, DM_EDOM, "non-finite Newton update (h = %g)", h);
    /* at the tolerance, or in the round-off regime once the updates stop
     * contracting (newton.h) */
    if (dm_newton_done(&stop, d, P->tol)) {
      ok = 1;
      break;
    }
    /* simplified Newton: keep the factored exact Jacobian while the updates
     * contract at least tenfold, otherwise refresh it */
    jac = !P->simplified || d > 0.1 * dlast;
    dlast = d;
  }
  if (it > P->maxiter)
    it = P->maxiter;
  if (stt) {
    stt->iters = it + fits;
    stt->jacs = njac;
    stt->residual = d;
    stt->tol = P->tol;
    stt->iters_total += it + fits;
  }
  P->njac = njac;
  if (!ok)
    return dm_err_set(e, DM_ENOCONV,
                      "Newton on the stage equations did not converge in %d iterations: "
                      "relative update %.3g > tol %.3g (residual %.3g, h = %g)",
                      it, d, P->tol, rn, h);
  /* The stage forces were evaluated before the last update; when that update
   * is at round-off they are the converged ones, otherwise evaluate again. */
  if (d <= 1e-12)
    return DM_OK;
  return assemble(P, mode, h, q0, p0, 0, e);
}

static int predict(dm_prk *P, double h, const double *q0, const double *p0, int cont,
                   dm_err *e)
{
  size_t n = P->n, s = P->s, sn = P->sn, i, N = nunk(P, P->m ? DM_PRK_CSTEP : DM_PRK_STEP);
  if (cont && P->distinct_nodes) {
    dm_prk_extrapolate(s, n, P->tab->c, h / P->hist_h, P->E, &P->E_ratio, P->hV, P->X);
  } else if (cont) {
    memcpy(P->X, P->hV, sn * sizeof(double));
  } else {
    int st;
    if (P->hist)
      memcpy(P->v1w, P->hV + (s - 1) * n, n * sizeof(double));
    st = dm_legendre_velocity(P->leg, q0, p0, P->v1w, P->hist, e);
    if (st != DM_OK)
      return st;
    for (i = 0; i < s; i++)
      memcpy(P->X + i * n, P->v1w, n * sizeof(double));
  }
  if (N > sn) {
    if (cont)
      memcpy(P->X + sn, P->hx, (N - sn) * sizeof(double));
    else
      memset(P->X + sn, 0, (N - sn) * sizeof(double));
  }
  return DM_OK;
}

int dm_prk_step(dm_prk *P, double h, const double *q0, const double *p0,
                double *q1, double *p1, dm_integ_stats *stt, dm_err *e)
{
  size_t n = P->n, s = P->s, sn = P->sn, i, a;
  const double *b = P->tab->b;
  int mode = P->m ? DM_PRK_CSTEP : DM_PRK_STEP, st, bad = 0;
  int cont = P->hist && dm_same(q0, P->hq1, n) && dm_same(p0, P->hp1, n);
  if (!cont) {
    memset(P->cq, 0, n * sizeof(double));
    memset(P->cp, 0, n * sizeof(double));
    P->svf_valid = 0;
  }
  if (h == 0.0) {
    memmove(q1, q0, n * sizeof(double));
    memmove(p1, p0, n * sizeof(double));
    return DM_OK;
  }
  if (P->explicit_sv) {
    st = dm_prk_verlet_step(P, h, q0, p0, cont, P->q1w, P->p1w, stt, e);
  } else {
    st = predict(P, h, q0, p0, cont, e);
    if (st == DM_OK && P->m)
      st = dm_prk_constr_begin(P, q0, e);
    if (st == DM_OK)
      st = newton(P, mode, h, q0, p0, stt, e);
    if (st == DM_OK && P->m) {
      st = dm_prk_constr_finish(P, h, q0, p0, P->q1w, P->p1w, e);
    } else if (st == DM_OK) {
      /* q1 = q0 + h sum b_i V_i, p1 = p0 + h sum b_i W_i, Kahan-compensated
       * (the arithmetic of dm_prk_kahan, in one pass) */
      const double *X = P->X, *W = P->W;
      double *cq = P->cq, *cp = P->cp, *q1w = P->q1w, *p1w = P->p1w;
      for (a = 0; a < n; a++) {
        double sq = 0.0, sp = 0.0, y, t;
        for (i = 0; i < s; i++) {
          sq += b[i] * X[i * n + a];
          sp += b[i] * W[i * n + a];
        }
        y = h * sq - cq[a];
        t = q0[a] + y;
        cq[a] = (t - q0[a]) - y;
        q1w[a] = t;
        y = h * sp - cp[a];
        t = p0[a] + y;
        cp[a] = (t - p0[a]) - y;
        p1w[a] = t;
      }
    }
  }
  for (a = 0; a < n; a++)
    bad |= !isfinite(P->q1w[a]) | !isfinite(P->p1w[a]);
  if (st == DM_OK && bad)
    st = dm_err_set(e, DM_EDOM, "the step produced a non-finite state (NaN or Inf; h = %g)", h);
  if (st != DM_OK) {
    P->hist = 0;
    P->svf_valid = 0;
    return st;
  }
  /* history: the predictor's stages (and multipliers), continuation test */
  dm_vcopy(P->hV, P->X, sn);
  if (P->m)
    dm_vcopy(P->hx, P->X + sn, nunk(P, DM_PRK_CSTEP) - sn);
  dm_vcopy(P->hq1, P->q1w, n);
  dm_vcopy(P->hp1, P->p1w, n);
  P->hist_h = h;
  P->hist = 1;
  dm_vcopy(q1, P->q1w, n);
  dm_vcopy(p1, P->p1w, n);
  if (stt)
    stt->steps++;
  return DM_OK;
}

int dm_prk_jacobian(dm_prk *P, double h, const double *q0, const double *p0,
                    double *DPhi, dm_integ_stats *stt, dm_err *e)
{
  size_t n = P->n, s = P->s, sn = P->sn, nn = P->nn, N2 = 2 * n, i, j, k, a, c, x;
  const double *A = P->tab->a, *At = P->tab->at, *b = P->tab->b;
  int st;
  if (P->m)
    return dm_err_set(e, DM_EUNSUP, "the step Jacobian is not available for constrained systems");
  if ((st = dm_prk_step(P, h, q0, p0, DPhi, DPhi + n, stt, e)) != DM_OK)
    return st;
  if ((st = assemble(P, DM_PRK_STEP, h, q0, p0, 1, e)) != DM_OK)
    return st;
  if ((P->sparse ? dm_prk_sparse_factor(P, NULL) : dm_smalllu_factor(P->Jm, sn, P->perm))
      != DM_OK)
    return dm_prk_singular(P, "stage equations", h, e);
  for (c = 0; c < N2; c++) {
    double *dV = P->rhs + (P->large ? 0 : c * sn);
    for (i = 0; i < s; i++)
      for (a = 0; a < n; a++) {
        double v;
        if (c < n && P->large) {
          double lvq, dd;
          dm_prk_sparse_entries(P, i, a, c, &lvq, &dd);
          v = lvq;
          for (j = 0; j < s; j++) {
            dm_prk_sparse_entries(P, j, a, c, &lvq, &dd);
            v -= h * At[i * s + j] * dd;
          }
        } else if (c < n) {
          v = P->Lvq[i * nn + a * n + c];
          for (j = 0; j < s; j++)
            v -= h * At[i * s + j] * P->D[j * nn + a * n + c];
        } else {
          v = (a == c - n) ? -1.0 : 0.0;
        }
        dV[i * n + a] = -v;
      }
    if (P->sparse)
      dm_prk_sparse_solve(P, dV);
    else
      dm_smalllu_solve(P->Jm, sn, P->perm, dV);
    /* dQ_j = e_c (q part) + h sum_k a_jk dV_k, stored in Q as scratch */
    for (j = 0; j < s; j++)
      for (a = 0; a < n; a++) {
        double acc = 0.0;
        for (k = 0; k < s; k++)
          acc += A[j * s + k] * dV[k * n + a];
        P->Q[j * n + a] = (c < n && a == c ? 1.0 : 0.0) + h * acc;
      }
    for (a = 0; a < n; a++) {
      double dq1 = 0.0, dp1 = 0.0;
      for (j = 0; j < s; j++) {
        double f = 0.0;
        dq1 += b[j] * dV[j * n + a];
        if (P->large)
          dm_prk_sparse_rowdot(P, j, a, P->Q + j * n, dV + j * n, &f);
        else
          for (x = 0; x < n; x++)
            f += P->D[j * nn + a * n + x] * P->Q[j * n + x] + P->Bm[j * nn + a * n + x] * dV[j * n + x];
        dp1 += b[j] * f;
      }
      DPhi[a * N2 + c] = (c == a ? 1.0 : 0.0) + h * dq1;
      DPhi[(n + a) * N2 + c] = (c == n + a ? 1.0 : 0.0) + h * dp1;
    }
  }
  return DM_OK;
}

int dm_prk_dleg_check(const dm_prk *P, double h, dm_err *e)
{
  if (P->m)
    return dm_err_set(e, DM_EUNSUP,
                      "discrete Legendre transforms are not available for constrained systems");
  if (h == 0.0)
    return dm_err_set(e, DM_EINVAL, "discrete Legendre transform needs h != 0");
  return DM_OK;
}

int dm_prk_dlegendre(dm_prk *P, double h, const double *q0, const double *q1,
                     double *p0, double *p1, double *Ld, dm_integ_stats *stt, dm_err *e)
{
  int st = dm_prk_dleg_check(P, h, e);
  if (st != DM_OK)
    return st;
  st = dm_galerkin_solve(P->gal, h, q0, q1, Ld, p0, p1, NULL, NULL, NULL, NULL, 0, e);
  if (stt) {
    stt->iters = dm_galerkin_iters(P->gal);
    stt->jacs = stt->iters;
    stt->iters_total += stt->iters;
  }
  return st;
}

/* {==== type-object glue for the PRK families ============================ */

/* The iteration option: whether the fixed-point iteration applies (auto:
 * quietly not when the system does not allow it; fixed: an error then). */
static int fixed_setup(dm_prk *P, const char *name, dm_err *e)
{
  if (name == NULL || name[0] == '\0' || strcmp(name, "auto") == 0)
    P->iteration = DM_ITER_AUTO;
  else if (strcmp(name, "newton") == 0)
    P->iteration = DM_ITER_NEWTON;
  else if (strcmp(name, "fixed") == 0)
    P->iteration = DM_ITER_FIXED;
  else
    return dm_err_set(e, DM_EINVAL, "option 'iteration' must be \"auto\", \"newton\" or "
                      "\"fixed\", got \"%s\"", name);
  P->fixed_ok = 0;
  if (P->iteration == DM_ITER_NEWTON || P->explicit_sv)
    return DM_OK;
  dm_err le;
  int st = P->m == 0 ? dm_prk_mass_setup(P, &le)
                     : dm_err_set(&le, DM_EUNSUP, "the system has constraints");
  if (st == DM_ENOMEM) {
    if (e != NULL)
      *e = le;
    return st;
  }
  if (st != DM_OK && P->iteration == DM_ITER_FIXED)
    return dm_err_set(e, DM_EINVAL, "iteration = \"fixed\" needs a separable Lagrangian "
                      "1/2 v^T M v - V(q) without forces or constraints: %s", le.msg);
  P->fixed_ok = st == DM_OK;
  return DM_OK;
}

int dm_prk_type_setup(dm_integrator *I, const dm_tableau *t, dm_err *e)
{
  dm_prk *P;
  int linear = dm_linear_mode_parse(I->opt.linear);
  if (linear < 0)
    return dm_err_set(e, DM_EINVAL, "option 'linear' must be \"auto\", \"dense\" or "
                      "\"sparse\", got \"%s\"", I->opt.linear);
  int st = dm_prk_alloc(I->sys, t, I->opt.tol, I->opt.maxiter, I->opt.explicit_sv, linear,
                        &P, e);
  if (st != DM_OK)
    return st;
  I->state = P;
  P->simplified = I->opt.simplified;
  if ((st = fixed_setup(P, I->opt.iteration, e)) != DM_OK) {
    dm_prk_free(P);
    I->state = NULL;
    return st;
  }
  I->stats.linear = P->sparse ? DM_LINEAR_SPARSE : DM_LINEAR_DENSE;
  I->stats.nnz = P->sparse ? dm_prk_sparse_nnz(P) : 0;
  I->order = t->order;
  I->stages = (int)t->s;
  I->flags = DM_INTEG_VARIATIONAL | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS;
  if (I->m == 0)
    I->flags |= DM_INTEG_EXACT_JAC;
  if (t->flags & DM_TAB_SYMPLECTIC)
    I->flags |= DM_INTEG_SYMPLECTIC;
  if (t->flags & DM_TAB_SYMMETRIC)
    I->flags |= DM_INTEG_SYMMETRIC;
  if (P->explicit_sv)
    I->flags |= DM_INTEG_EXPLICIT;
  return DM_OK;
}

int dm_prk_type_step(dm_integrator *I, double h, const double *q0, const double *p0,
                     double *q1, double *p1, dm_err *e)
{
  return dm_prk_step(I->state, h, q0, p0, q1, p1, &I->stats, e);
}

int dm_prk_type_jacobian(dm_integrator *I, double h, const double *q0,
                         const double *p0, double *DPhi, dm_err *e)
{
  return dm_prk_jacobian(I->state, h, q0, p0, DPhi, &I->stats, e);
}

int dm_prk_type_dlegendre(dm_integrator *I, double h, const double *q0,
                          const double *q1, double *p0, double *p1, double *Ld,
                          dm_err *e)
{
  return dm_prk_dlegendre(I->state, h, q0, q1, p0, p1, Ld, &I->stats, e);
}

int dm_prk_type_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                        long *done, dm_err *e)
{
  dm_prk *P = I->state;
  long k;
  int st = DM_OK;
  if (P->explicit_sv && P->m == 0)
    return dm_prk_verlet_advance(P, h, NULL, 1, nsteps, q, p, done, &I->stats, e);
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = DM_EINTR;
      break;
    }
    if ((st = dm_prk_step(P, h, q, p, q, p, &I->stats, e)) != DM_OK)
      break;      /* outputs are written only on success */
  }
  *done = k;
  return st;
}

void dm_prk_type_reset(dm_integrator *I)
{
  dm_prk_reset(I->state);
}

void dm_prk_type_free(dm_integrator *I)
{
  dm_prk_free(I->state);
  I->state = NULL;
}
