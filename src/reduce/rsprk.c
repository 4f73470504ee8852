/* rsprk.c -- the reduced symplectic partitioned Runge-Kutta method (thesis
 * §2.5, eq. 2.5.14; doc/reduce.md §9) on T*S with state (x, s),
 * s = dR/dxdot, implemented directly from its equations:
 *   X_i = x0 + h sum_j a_ij Xd_j
 *   S_i = s0 + h sum_j at_ij Sd_j + [h sum_j at_ij K_j Xd_j - (muA(X_i) - muA(x0))]
 *   S_i = dR/dxdot (X_i, Xd_i),   Sd_j = dR/dx (X_j, Xd_j) - i_{Xd_j} beta(X_j) + Fhat_j
 *   x1 = x0 + h sum_j b_j Xd_j
 *   s1 = s0 + h sum_j b_j Sd_j + [h sum_j b_j K_j Xd_j - (muA(x1) - muA(x0))]
 * with K = d(mu^T A)/dx, (K Xd)_i = (mu dA/dx Xd)_i and (i_v beta)_c =
 * sum_d v_d B_dc, each term derived and rewritten on its own (not through
 * the classical Routhian: the momentum-shift equivalence is a test), all of
 * a stage computed by one compiled program per request kind (gradient /
 * with second derivatives: routh_compile.c, red->stage_r / stage_j).
 * Unknowns are the stage velocities; residual r_i = dR/dxdot(X_i, Xd_i) - S_i.
 * Newton uses the exact Jacobian
 *   dr_i/dXd_k = d_ik Rvv_i + h a_ik (Rvx_i + K_i) - h at_ik E_k - h^2 sum_j at_ij a_jk D_j,
 *   E_k = Rxv_k - B_k^T + Fv_k + K_k,  D_j = Rxx_j - d(i beta)/dx_j + Fx_j + d(K Xd)/dx_j,
 * with the engine's stopping rule (src/core/newton.h: scaled update <= tol,
 * or round-off stall once below 1e-10) and, as prk_engine.c, simplified
 * Newton reusing the factored exact Jacobian while updates contract
 * tenfold.  The group increment of the step (Hamiltonian-side
 * reconstruction) is h sum_j b_j Thetadot_j, Thetadot_j = I(X_j)^{-1} mu -
 * A(X_j) Xd_j.  The step Jacobian comes from the implicit function theorem
 * on the converged stage equations. */
#include <config.h>
#include "core/numfmt.h"
#include "reduce/rsprk_impl.h"
#include "integrators/prk_kernels.h"
#include "core/interrupt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const dm_tableau *dm_rsprk_tableau(const dm_rsprk *P)
{
  return P->tab;
}

/* max |x_i|, NaN when some x_i is NaN or infinite (dm_rnorm_inf's
 * contract; the core's dm_norm_inf gives Inf for Inf), inline with two
 * independent max chains and no branch per entry: the vectors are a few
 * entries long and a call costs more than the work.  The other hot-path
 * helpers are the core engine's (prk_kernels.h). */
static inline double norm_inf(const double *x, size_t n)
{
  double m0 = 0.0, m1 = 0.0, z0 = 0.0, z1 = 0.0;
  size_t i;
  for (i = 0; i + 1 < n; i += 2) {
    double a = fabs(x[i]), b = fabs(x[i + 1]);
    m0 = a > m0 ? a : m0;
    m1 = b > m1 ? b : m1;
    z0 += x[i] * 0.0;           /* NaN iff x_i is NaN or infinite */
    z1 += x[i + 1] * 0.0;
  }
  if (i < n) {
    double a = fabs(x[i]);
    m0 = a > m0 ? a : m0;
    z0 += x[i] * 0.0;
  }
  return z0 + z1 == 0.0 ? (m0 > m1 ? m0 : m1) : NAN;
}

/* 1 when every x_i is finite: a sum of finite numbers is finite unless it
 * overflows, and only then are the entries looked at one by one */
static inline int all_finite(const double *x, size_t n)
{
  double s0 = 0.0, s1 = 0.0;
  size_t i;
  for (i = 0; i + 1 < n; i += 2) {
    s0 += x[i];
    s1 += x[i + 1];
  }
  if (i < n)
    s0 += x[i];
  if (fabs(s0 + s1) <= DBL_MAX)
    return 1;
  for (i = 0; i < n; i++)
    if (!(fabs(x[i]) <= DBL_MAX))
      return 0;
  return 1;
}

int dm_routh_check_inertia(const dm_routh *red, const double *x, double *ref, double *work,
                           const char *where, dm_err *e)
{
  size_t r = red->r, i;
  double lmin, lmax;
  char bx[200];
  if (red->general)     /* no locked inertia: the Routhian's own solve of J = mu fails instead */
    return DM_OK;
  dm_rprog_run(&red->inertia, x, red->par, work, work + r * r);
  for (i = 0; i < r * r; i++)
    if (!isfinite(work[i]))
      return dm_err_set(e, DM_ESINGULAR, "the locked inertia I(x) is not finite at %s x = %s",
                        where, dm_num_format_vec(bx, sizeof bx, x, red->s));
  dm_routh_sym_eig(work, r, &lmin, &lmax);
  if (!(*ref > 0.0)) {
    if (!(lmin > 0.0))
      return dm_err_set(e, DM_ESINGULAR, "the locked inertia I(x) is singular at %s x = %s "
                        "(smallest eigenvalue %.3g): the symmetry group does not act freely there",
                        where, dm_num_format_vec(bx, sizeof bx, x, red->s), lmin);
    *ref = lmax;
    return DM_OK;
  }
  if (!(lmin > red->sing_tol * *ref))
    return dm_err_set(e, DM_ESINGULAR, "the locked inertia I(x) became singular at %s x = %s "
                      "(smallest eigenvalue %.3g <= %.3g x its initial size %.3g): the symmetry "
                      "group does not act freely there (e.g. r -> 0) and the reduced equations "
                      "break down", where, dm_num_format_vec(bx, sizeof bx, x, red->s), lmin,
                      red->sing_tol, *ref);
  return DM_OK;
}

/* {==== allocation ======================================================= */

void dm_rsprk_free(dm_rsprk *P)
{
  if (P == NULL)
    return;
  free(P->Jm);
  free(P->work);
  dm_csr_free(&P->J);
  free(P->jblk);
  free(P->Jv);
  dm_splu_free(P->slu);
  dm_rlu_free(&P->lu);
  dm_rlu_free(&P->lu_small);
  dm_tableau_free(P->tab);
  free(P);
}

void dm_rsprk_reset(dm_rsprk *P)
{
  P->hist = 0;
  P->E_ratio = NAN;
  P->sing_ref = 0.0;
  memset(P->cq, 0, P->d * sizeof(double));
  memset(P->cp, 0, P->d * sizeof(double));
}

/* Dense or sparse Newton matrices (linear = DM_LINEAR_AUTO), the rule of
 * the unreduced engine (prk_engine.c, doc/scale.md §3): dense up to
 * RS_SPARSE_MIN unknowns and when a stage block would be more than a
 * quarter full (always with constraints, whose curvature terms fill the
 * blocks), sparse above or beyond RS_DENSE_MAX unknowns. */
#define RS_SPARSE_MIN 48
#define RS_DENSE_MAX 2048

static int want_sparse(const dm_rsprk *P, int linear)
{
  double d = (double)P->d;
  if (linear != DM_LINEAR_AUTO)
    return linear == DM_LINEAR_SPARSE;
  if (P->N <= RS_SPARSE_MIN)
    return 0;
  if (P->N > RS_DENSE_MAX)
    return 1;
  return P->m == 0 && (double)P->red->upat.nnz <= 0.25 * d * d;
}

/* J's pattern: row (i, a) holds stage blocks (i, 0) .. (i, S-1) of row a
 * of upat; with constraints every entry (the multiplier code fills the
 * dense matrix, whose values are gathered). */
static int sparse_setup(dm_rsprk *P, dm_err *e)
{
  const dm_csr *U = &P->red->upat;
  const size_t d = P->d, S = P->S, nU = U->nnz;
  size_t i, k, a, q, n = 0;
  int st;
  if (P->m > 0) {
    if (dm_csr_full(&P->J, P->N, P->N) != DM_OK)
      return dm_err_set(e, DM_ENOMEM, "RSPRK: out of memory");
  } else {
    if (U->nrow != d)
      return dm_err_set(e, DM_EINVAL, "RSPRK: the reduced system has no stage pattern");
    if (dm_csr_alloc(&P->J, P->N, P->N, S * S * nU) != DM_OK
        || (P->jblk = malloc((S * S * nU + 1) * sizeof *P->jblk)) == NULL)
      return dm_err_set(e, DM_ENOMEM, "RSPRK: out of memory");
    for (i = 0; i < S; i++)
      for (a = 0; a < d; a++) {
        P->J.rowptr[i * d + a] = n;
        for (k = 0; k < S; k++)
          for (q = U->rowptr[a]; q < U->rowptr[a + 1]; q++) {
            P->jblk[(i * S + k) * nU + q] = (uint32_t)n;
            P->J.col[n++] = (uint32_t)(k * d + U->col[q]);
          }
      }
    P->J.rowptr[P->N] = n;
  }
  if ((P->Jv = calloc(P->J.nnz + 1, sizeof *P->Jv)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "RSPRK: out of memory");
  if ((st = dm_splu_alloc(&P->J, &P->slu, e)) != DM_OK)
    return st;
  return DM_OK;
}

int dm_rsprk_linear(const dm_rsprk *P, size_t *nnz)
{
  *nnz = P->sparse ? P->J.nnz : 0;
  return P->sparse ? DM_LINEAR_SPARSE : DM_LINEAR_DENSE;
}

int dm_rsprk_alloc(dm_routh *red, const dm_tableau *t, double tol, int maxiter, int simplified,
                   int linear, dm_rsprk **out, dm_err *e)
{
  dm_rsprk *P = calloc(1, sizeof *P);
  size_t d = red->s, S = t->s, m = red->m, dd = d * d, Sd = S * d, tot, i, j, nsm, nout, mat;
  double *p;
  int st;
  *out = NULL;
  if (P == NULL)
    return dm_err_set(e, DM_ENOMEM, "RSPRK: out of memory");
  P->red = red;
  P->sys = &red->rsys;
  P->d = d;
  P->S = S;
  P->m = m;
  P->r = red->r;
  P->Sd = Sd;
  P->dd = dd;
  P->forced = red->rsys.force != NULL;
  P->gyro = red->has_gyro;
  P->tol = tol;
  P->maxiter = maxiter;
  P->simplified = simplified;
  P->E_ratio = NAN;
  if ((P->tab = dm_tableau_copy(t)) == NULL) {
    free(P);
    return dm_err_set(e, DM_ENOMEM, "RSPRK: out of memory");
  }
  if (m > 0 && (st = dm_rsprk_constr_layout(P, e)) != DM_OK) {
    dm_rsprk_free(P);
    return st;
  }
  P->N = Sd + (m ? P->nK * m + m : 0);
  P->sparse = want_sparse(P, linear);
  if (P->sparse && (st = sparse_setup(P, e)) != DM_OK) {
    dm_rsprk_free(P);
    return st;
  }
  nsm = d + m;
  nout = red->gyro_r.nout > red->info.nout ? red->gyro_r.nout : red->info.nout;
  mat = P->sparse && m == 0 ? 0 : P->N * P->N;   /* the dense Newton matrix */
  tot = mat + 2 * P->N + P->N * 2 * d + 8 * Sd + 11 * S * dd + S + 2 * d + 2 * dd
        + (S + 2) * (m + m * d + m * dd) + 6 * d + P->r + Sd + P->N + 2 * d + S * S + 2 * d
        + nsm * nsm + nsm + 2 * d + nout + red->nwork + red->r * red->r + 8;
  P->Jm = calloc(tot, sizeof(double));
  P->work = red->rsys.work_size ? malloc(red->rsys.work_size) : NULL;
  if (P->Jm == NULL || (red->rsys.work_size && P->work == NULL)
      || (!P->sparse && dm_rlu_init(&P->lu, P->N) != 0)
      || dm_rlu_init(&P->lu_small, d + m)) {
    dm_rsprk_free(P);
    return dm_err_set(e, DM_ENOMEM, "RSPRK: out of memory");
  }
  p = P->Jm + mat;
#define TAKE(ptr, cnt) do { (ptr) = p; p += (cnt); } while (0)
  TAKE(P->R, P->N); TAKE(P->X, P->N); TAKE(P->rhs, P->N * 2 * d);
  TAKE(P->Xs, Sd); TAKE(P->Lq, Sd); TAKE(P->Lv, Sd); TAKE(P->F, Sd); TAKE(P->Sdot, Sd);
  TAKE(P->ga, Sd); TAKE(P->gkv, Sd); TAKE(P->gib, Sd);
  TAKE(P->Lvv, S * dd); TAKE(P->Lvq, S * dd); TAKE(P->Lqq, S * dd); TAKE(P->Fq, S * dd);
  TAKE(P->Fv, S * dd); TAKE(P->gK, S * dd); TAKE(P->gB, S * dd); TAKE(P->gdkv, S * dd);
  TAKE(P->gdib, S * dd); TAKE(P->D, S * dd); TAKE(P->E, S * dd);
  TAKE(P->Lval, S);
  TAKE(P->a0, d); TAKE(P->a1, d); TAKE(P->K0, dd); TAKE(P->K1, dd);
  TAKE(P->g, (S + 2) * m); TAKE(P->G, (S + 2) * m * d); TAKE(P->Hc, (S + 2) * m * dd);
  TAKE(P->q1w, d); TAKE(P->p1w, d); TAKE(P->v1w, d); TAKE(P->dq, d); TAKE(P->dp, d);
  TAKE(P->tmp, d); TAKE(P->thd, P->r);
  TAKE(P->hV, Sd); TAKE(P->hx, P->N); TAKE(P->hq1, d); TAKE(P->hp1, d); TAKE(P->Ex, S * S);
  TAKE(P->cq, d); TAKE(P->cp, d);
  TAKE(P->small, nsm * nsm + nsm);
  TAKE(P->tin, 2 * d); TAKE(P->tout, nout); TAKE(P->twork, red->nwork + red->r * red->r + 8);
#undef TAKE
  for (i = 0; i < S; i++) {
    double **o = P->sout[i];
    o[DM_RS_LQ] = P->Lq + i * d;
    o[DM_RS_LV] = P->Lv + i * d;
    o[DM_RS_LVV] = P->Lvv + i * dd;
    o[DM_RS_LVQ] = P->Lvq + i * dd;
    o[DM_RS_LQQ] = P->Lqq + i * dd;
    o[DM_RS_F] = P->F + i * d;
    o[DM_RS_FQ] = P->Fq + i * dd;
    o[DM_RS_FV] = P->Fv + i * dd;
    o[DM_RS_MUA] = P->ga + i * d;
    o[DM_RS_K] = P->gK + i * dd;
    o[DM_RS_B] = P->gB + i * dd;
    o[DM_RS_KV] = P->gkv + i * d;
    o[DM_RS_IB] = P->gib + i * d;
    o[DM_RS_DKV] = P->gdkv + i * dd;
    o[DM_RS_DIB] = P->gdib + i * dd;
  }
  P->distinct_nodes = 1;
  for (i = 0; i < S; i++)
    for (j = 0; j < i; j++)
      if (fabs(t->c[i] - t->c[j]) < 1e-8)
        P->distinct_nodes = 0;
  *out = P;
  return DM_OK;
}

/* {==== stage evaluation ================================================= */

static int cb_fail(dm_rsprk *P, int st, const char *what, const double *x, dm_err *e)
{
  char bx[200];
  if (st > 0)
    return dm_err_set(e, DM_EDOM, "%s is not finite / outside its domain at x = %s", what,
                      dm_num_format_vec(bx, sizeof bx, x, P->d));
  return dm_err_set(e, DM_ECALLBACK, "%s callback failed (status %d) at x = %s", what, st,
                    dm_num_format_vec(bx, sizeof bx, x, P->d));
}

/* muA (and K = d muA/dx when K != NULL) at a node point x (velocity 0) */
static int eval_node(dm_rsprk *P, const double *x, double *a, double *K, dm_err *e)
{
  const dm_routh *red = P->red;
  int bad = K ? dm_routh_muA_K(red, x, a, K, P->tin, P->twork)
              : dm_routh_muA(red, x, a, P->tin, P->tout, P->twork);
  return bad ? cb_fail(P, 1, "the connection mu^T A", x, e) : DM_OK;
}

/* After a stage program met a NaN or Inf: the separate callbacks name the
 * culprit (the Routhian, the reduced force, else the connection terms). */
static int stage_fail(dm_rsprk *P, size_t i, int jac, dm_err *e)
{
  const dm_system *sys = P->sys;
  const double *par = P->red->par;
  const size_t d = P->d, dd = P->dd;
  const double *Xi = P->Xs + i * d, *Vi = P->X + i * d;
  dm_lag_out o = {0, P->Lq + i * d, P->Lv + i * d, P->Lvv + i * dd, P->Lvq + i * dd,
                  P->Lqq + i * dd};
  unsigned what = DM_LAG_Q | DM_LAG_V | (jac ? (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ) : 0u);
  int st = sys->lagrangian(sys->data, Xi, Vi, par, what, &o, P->work);
  if (st != 0)
    return cb_fail(P, st, "the Routhian", Xi, e);
  if (P->forced) {
    unsigned fw = DM_FORCE_F | (jac ? (DM_FORCE_Q | DM_FORCE_V) : 0u);
    st = sys->force(sys->data, Xi, Vi, par, fw, P->F + i * d, P->Fq + i * dd, P->Fv + i * dd, P->work);
    if (st != 0)
      return cb_fail(P, st, "the reduced force", Xi, e);
  }
  return cb_fail(P, 1, "the connection (mu^T A and its derivatives)", Xi, e);
}

/* The derivatives of R^mu (no value: the step never needs it), the reduced
 * force and the connection terms at stage i, by one call of a stage
 * program; then Sdot, and D, E when jac.  Terms that are identically zero
 * (no force, no gyroscopic part) are not added. */
static int eval_stage(dm_rsprk *P, size_t i, int jac, dm_err *e)
{
  const dm_routh *red = P->red;
  const size_t d = P->d, dd = P->dd;
  size_t a, b;
  const double *in[2] = {P->Xs + i * d, P->X + i * d};
  if (dm_bundle_run(jac ? &red->stage_j : &red->stage_r, in, d, red->par, P->sout[i], ~0u,
                    P->twork))
    return stage_fail(P, i, jac, e);
  {
    const double *restrict Lq = P->Lq + i * d, *restrict gib = P->gib + i * d;
    const double *restrict F = P->F + i * d;
    double *restrict Sd = P->Sdot + i * d;
    for (a = 0; a < d; a++) {
      double v = Lq[a];
      if (P->gyro)
        v -= gib[a];
      if (P->forced)
        v += F[a];
      Sd[a] = v;
    }
  }
  if (jac) {
    const size_t k0 = i * dd;
    const double *restrict Lqq = P->Lqq + k0, *restrict Lvq = P->Lvq + k0;
    const double *restrict gdib = P->gdib + k0, *restrict gdkv = P->gdkv + k0;
    const double *restrict gB = P->gB + k0, *restrict gK = P->gK + k0;
    const double *restrict Fq = P->Fq + k0, *restrict Fv = P->Fv + k0;
    double *restrict D = P->D + k0, *restrict E = P->E + k0;
    for (a = 0; a < d; a++)
      for (b = 0; b < d; b++) {
        size_t k = a * d + b, t = b * d + a;
        double x = Lqq[k], y = Lvq[t];
        if (P->gyro) {
          x -= gdib[k];
          y -= gB[t];
        }
        if (P->forced) {
          x += Fq[k];
          y += Fv[k];
        }
        if (P->gyro) {
          x += gdkv[k];
          y += gK[k];
        }
        D[k] = x;
        E[k] = y;
      }
  }
  return DM_OK;
}

/* Residual (and the Newton matrix when jac) of the stage equations. */
static int assemble(dm_rsprk *P, double h, const double *x0, const double *s0, int jac, dm_err *e)
{
  const size_t d = P->d, S = P->S, dd = P->dd, N = P->N;
  const double *A = P->tab->a, *At = P->tab->at;
  size_t i, j, k, a, c;
  int st;
  {
    const double *restrict X = P->X;     /* restrict in these blocks only: */
    double *restrict Xs = P->Xs;         /* the stage evaluation writes P */
    for (i = 0; i < S; i++)
      for (a = 0; a < d; a++) {
        double acc = 0.0;
        for (j = 0; j < S; j++)
          acc += A[i * S + j] * X[j * d + a];
        Xs[i * d + a] = x0[a] + h * acc;
      }
  }
  for (i = 0; i < S; i++)
    if ((st = eval_stage(P, i, jac, e)) != DM_OK)
      return st;
  {
    const double *restrict Sdot = P->Sdot, *restrict gkv = P->gkv, *restrict ga = P->ga;
    const double *restrict Lv = P->Lv, *restrict a0 = P->a0;
    double *restrict R = P->R;
    for (i = 0; i < S; i++)
      for (a = 0; a < d; a++) {
        double sd = 0.0, kv = 0.0;
        for (j = 0; j < S; j++) {
          sd += At[i * S + j] * Sdot[j * d + a];
          kv += At[i * S + j] * gkv[j * d + a];
        }
        /* S_i = s0 + h sum at Sd + [h sum at K V - (muA(X_i) - muA(x0))] */
        R[i * d + a] = Lv[i * d + a] - (s0[a] + h * sd + (h * kv - (ga[i * d + a] - a0[a])));
      }
  }
  if (jac) {
    /* each entry accumulated in a register, the h^2 at_ij a_jk hoisted;
     * the stage blocks fill the matrix unless there are multipliers */
    const double *restrict Lvq = P->Lvq, *restrict gK = P->gK, *restrict E = P->E;
    const double *restrict Lvv = P->Lvv, *restrict D = P->D;
    double *restrict Jm = P->Jm, cj[DM_TABLEAU_SMAX];
    if (P->sparse && P->m == 0) {
      /* the same entries with the same arithmetic, on the pattern */
      const dm_csr *U = &P->red->upat;
      const size_t nU = U->nnz;
      double *restrict Jv = P->Jv;
      for (i = 0; i < S; i++)
        for (k = 0; k < S; k++) {
          const double hak = h * A[i * S + k], hatk = h * At[i * S + k];
          const uint32_t *pl = P->jblk + (i * S + k) * nU;
          for (j = 0; j < S; j++)
            cj[j] = h * h * At[i * S + j] * A[j * S + k];
          for (a = 0; a < d; a++)
            for (size_t q = U->rowptr[a]; q < U->rowptr[a + 1]; q++) {
              const size_t ac = a * d + U->col[q];
              double v = hak * (Lvq[i * dd + ac] + gK[i * dd + ac]) - hatk * E[k * dd + ac];
              if (i == k)
                v += Lvv[i * dd + ac];
              for (j = 0; j < S; j++)
                v -= cj[j] * D[j * dd + ac];
              Jv[pl[q]] = v;
            }
        }
      P->lvv_norm = norm_inf(P->Lvv, S * dd);
      return DM_OK;
    }
    if (N > P->Sd)
      memset(Jm, 0, N * N * sizeof(double));
    for (i = 0; i < S; i++)
      for (k = 0; k < S; k++) {
        const double hak = h * A[i * S + k], hatk = h * At[i * S + k];
        double *Jb = Jm + (i * d) * N + k * d;
        for (j = 0; j < S; j++)
          cj[j] = h * h * At[i * S + j] * A[j * S + k];
        for (a = 0; a < d; a++)
          for (c = 0; c < d; c++) {
            const size_t ac = a * d + c;
            double v = hak * (Lvq[i * dd + ac] + gK[i * dd + ac]) - hatk * E[k * dd + ac];
            if (i == k)
              v += Lvv[i * dd + ac];
            for (j = 0; j < S; j++)
              v -= cj[j] * D[j * dd + ac];
            Jb[a * N + c] = v;
          }
      }
    P->lvv_norm = norm_inf(P->Lvv, S * dd);   /* Lvv changes only with the Jacobian */
  }
  if (P->m && (st = dm_rsprk_constr_assemble(P, h, x0, jac, e)) != DM_OK)
    return st;
  if (jac && P->sparse)            /* constrained: gathered from the dense matrix */
    dm_csr_from_dense(&P->J, P->Jm, P->Jv);
  return DM_OK;
}

/* Scaled size of the Newton update: rv and xv are max |R| and max |X| over
 * the velocities (from the update pass); the multipliers relative to
 * max(|x|, momentum scale). */
static double update_norm(const dm_rsprk *P, double h, const double *s0, double rv, double xv)
{
  size_t Sd = P->Sd, N = P->N;
  double ms = norm_inf(s0, P->d) + fabs(h) * norm_inf(P->Sdot, Sd);
  double lv = P->lvv_norm;
  double vs = dm_max3(xv, lv > 0 ? ms / lv : 0.0, DBL_MIN);
  double dn = rv / vs;
  if (N > Sd) {
    double xs = dm_max3(norm_inf(P->X + Sd, N - Sd), ms, DBL_MIN);
    dn = dm_max2(dn, norm_inf(P->R + Sd, N - Sd) / xs);
  }
  return dn;
}

/* After a failure: a singular locked inertia at a stage explains it best. */
static int explain(dm_rsprk *P, int st, dm_err *e)
{
  size_t i;
  dm_err e2;
  for (i = 0; i < P->S; i++)
    if (dm_routh_check_inertia(P->red, P->Xs + i * P->d, &P->sing_ref, P->twork, "a stage point",
                               &e2) == DM_ESINGULAR) {
      if (e)
        *e = e2;
      return DM_ESINGULAR;
    }
  return st;
}

static int newton(dm_rsprk *P, double h, const double *x0, const double *s0, dm_integ_stats *stt,
                  dm_err *e)
{
  size_t N = P->N, i;
  double dn = HUGE_VAL, dlast = HUGE_VAL, rn = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, st, ok = 0, jac = 1, njac = 0;
  for (it = 1; it <= P->maxiter; it++) {
    if ((st = assemble(P, h, x0, s0, jac, e)) != DM_OK)
      return explain(P, st, e);
    rn = norm_inf(P->R, N);
    if (!isfinite(rn))
      return explain(P, dm_err_set(e, DM_EDOM, "RSPRK: non-finite residual in the stage equations "
                                   "(h = %g, iteration %d)", h, it), e);
    if (jac) {
      njac++;
      st = P->sparse ? dm_splu_factor(P->slu, P->Jv, NULL) : dm_rlu_factor(&P->lu, P->Jm, N);
      if (st == DM_ENOMEM)
        return dm_err_set(e, st, "RSPRK: out of memory");
      if (st != DM_OK)
        return explain(P, dm_err_set(e, st == DM_EDOM ? DM_EDOM : DM_ESINGULAR,
                                     "RSPRK: singular Newton matrix of the stage equations (h = %g)%s",
                                     h, P->m ? "; the constraint gradients may be dependent"
                                     : "; try a smaller step"), e);
    }
    if (P->sparse)
      dm_splu_solve(P->slu, P->R, 1, NULL);
    else
      dm_rlu_solve(&P->lu, P->Jm, N, P->R);
    {
      /* X -= R; max |R| and max |X| of the velocities on the way (NaN or
       * Inf in either makes dn NaN: the test below catches it) */
      double *X = P->X, rv = 0.0, xv = 0.0, z = 0.0;
      const double *R = P->R;
      for (i = 0; i < P->Sd; i++) {
        double r = fabs(R[i]), x;
        X[i] -= R[i];
        x = fabs(X[i]);
        rv = r > rv ? r : rv;
        xv = x > xv ? x : xv;
        z += R[i] * 0.0 + X[i] * 0.0;
      }
      for (; i < N; i++)
        X[i] -= R[i];
      dn = update_norm(P, h, s0, z == 0.0 ? rv : NAN, xv);
    }
    if (!isfinite(dn))
      return explain(P, dm_err_set(e, DM_EDOM, "RSPRK: non-finite Newton update (h = %g)", h), e);
    if (dm_newton_done(&stop, dn, P->tol)) {
      ok = 1;
      break;
    }
    jac = !P->simplified || dn > 0.1 * dlast;
    dlast = dn;
  }
  if (it > P->maxiter)
    it = P->maxiter;
  if (stt) {
    stt->iters = it;
    stt->jacs = njac;
    stt->residual = dn;
    stt->tol = P->tol;
    stt->iters_total += it;
  }
  if (!ok)
    return explain(P, dm_err_set(e, DM_ENOCONV, "RSPRK: Newton on the stage equations did not "
                                 "converge in %d iterations: relative update %.3g > tol %.3g "
                                 "(residual %.3g, h = %g)", it, dn, P->tol, rn, h), e);
  if (dn <= 1e-12)
    return DM_OK;
  return assemble(P, h, x0, s0, 0, e);
}

/* {==== predictor ======================================================== */

int dm_rsprk_velocity(dm_rsprk *P, const double *x, const double *s, double *v, dm_err *e)
{
  size_t d = P->d, dd = P->dd;
  dm_lag_out o = {0, P->Lq, P->Lv, P->Lvv, P->Lvq, P->Lqq};   /* stage-0 slots as scratch */
  int st;
  memset(P->v1w, 0, d * sizeof(double));
  st = P->sys->lagrangian(P->sys->data, x, P->v1w, P->red->par, DM_LAG_V | DM_LAG_VV, &o, P->work);
  if (st != 0)
    return cb_fail(P, st, "the Routhian", x, e);
  if (P->m) {                                      /* lu_small is (d+m): pad with identity */
    size_t N = d + P->m, i, j;
    double *M = P->small;
    memset(M, 0, N * N * sizeof(double));
    for (i = 0; i < d; i++)
      for (j = 0; j < d; j++)
        M[i * N + j] = P->Lvv[i * d + j];
    for (i = d; i < N; i++)
      M[i * N + i] = 1.0;
    if (dm_rlu_factor(&P->lu_small, M, N) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "the reduced kinetic matrix Mtilde is singular");
    memset(P->small + N * N, 0, N * sizeof(double));
    for (i = 0; i < d; i++)
      P->small[N * N + i] = s[i] - P->Lv[i];
    dm_rlu_solve(&P->lu_small, M, N, P->small + N * N);
    memcpy(v, P->small + N * N, d * sizeof(double));
    return DM_OK;
  }
  memcpy(P->small, P->Lvv, dd * sizeof(double));
  if (dm_rlu_factor(&P->lu_small, P->small, d) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "the reduced kinetic matrix Mtilde is singular");
  {
    size_t i;
    for (i = 0; i < d; i++)
      v[i] = s[i] - P->Lv[i];
  }
  dm_rlu_solve(&P->lu_small, P->small, d, v);
  return DM_OK;
}

static int predict(dm_rsprk *P, double h, const double *x0, const double *s0, int cont, dm_err *e)
{
  size_t d = P->d, S = P->S, Sd = P->Sd, N = P->N, i;
  if (cont && P->distinct_nodes) {
    dm_prk_extrapolate(S, d, P->tab->c, h / P->hist_h, P->Ex, &P->E_ratio, P->hV, P->X);
  } else if (cont) {
    memcpy(P->X, P->hV, Sd * sizeof(double));
  } else {
    int st = dm_rsprk_velocity(P, x0, s0, P->dq, e);
    if (st != DM_OK)
      return st;
    for (i = 0; i < S; i++)
      memcpy(P->X + i * d, P->dq, d * sizeof(double));
  }
  if (N > Sd) {
    if (cont)
      memcpy(P->X + Sd, P->hx, (N - Sd) * sizeof(double));
    else
      memset(P->X + Sd, 0, (N - Sd) * sizeof(double));
  }
  return DM_OK;
}

/* {==== the step ========================================================= */

static int finish(dm_rsprk *P, double h, const double *x0, const double *s0, dm_err *e)
{
  size_t d = P->d, S = P->S, i, a;
  const double *b = P->tab->b;
  int st;
  for (a = 0; a < d; a++) {
    double sq = 0.0, sp = 0.0, kv = 0.0;
    for (i = 0; i < S; i++) {
      sq += b[i] * P->X[i * d + a];
      sp += b[i] * P->Sdot[i * d + a];
      kv += b[i] * P->gkv[i * d + a];
    }
    P->dq[a] = h * sq;
    P->dp[a] = h * sp + h * kv;       /* the -(muA(x1) - muA(x0)) part follows */
  }
  if (P->m)
    return dm_rsprk_constr_finish(P, h, x0, s0, P->q1w, P->p1w, e);
  dm_prk_kahan(d, x0, P->dq, P->cq, P->q1w);
  if (P->gyro) {
    if ((st = eval_node(P, P->q1w, P->a1, NULL, e)) != DM_OK)
      return st;
    for (a = 0; a < d; a++)
      P->dp[a] -= P->a1[a] - P->a0[a];
  }
  dm_prk_kahan(d, s0, P->dp, P->cp, P->p1w);
  return DM_OK;
}

/* h sum_j b_j Thetadot_j at the converged stages */
static void group_increment(dm_rsprk *P, double h, double *dtheta)
{
  const dm_routh *red = P->red;
  size_t d = P->d, r = P->r, j, a;
  for (a = 0; a < r; a++)
    dtheta[a] = 0.0;
  for (j = 0; j < P->S; j++) {
    dm_vcopy(P->tin, P->Xs + j * d, d);
    dm_vcopy(P->tin + d, P->X + j * d, d);
    dm_rprog_run(&red->thd, P->tin, red->par, P->thd, P->twork);
    for (a = 0; a < r; a++)
      dtheta[a] += h * P->tab->b[j] * P->thd[a];
  }
}

int dm_rsprk_step(dm_rsprk *P, double h, const double *x0, const double *s0, double *x1,
                  double *s1, double *dtheta, dm_integ_stats *stt, dm_err *e)
{
  size_t d = P->d, i;
  int cont = P->hist && dm_same(x0, P->hq1, d) && dm_same(s0, P->hp1, d);
  int st;
  if (!cont) {
    memset(P->cq, 0, d * sizeof(double));
    memset(P->cp, 0, d * sizeof(double));
  }
  if (h == 0.0) {
    memmove(x1, x0, d * sizeof(double));
    memmove(s1, s0, d * sizeof(double));
    for (i = 0; dtheta && i < P->r; i++)
      dtheta[i] = 0.0;
    return DM_OK;
  }
  /* continuing from the previous output: x0 was checked and muA(x0) is the
   * previous muA(x1) */
  st = cont ? DM_OK : dm_routh_check_inertia(P->red, x0, &P->sing_ref, P->twork, "the initial point", e);
  if (st == DM_OK && P->gyro) {
    if (cont)
      dm_vcopy(P->a0, P->a1, d);
    else
      st = eval_node(P, x0, P->a0, NULL, e);
  }
  if (st == DM_OK)
    st = predict(P, h, x0, s0, cont, e);
  if (st == DM_OK && P->m)
    st = dm_rsprk_constr_begin(P, x0, e);
  if (st == DM_OK)
    st = newton(P, h, x0, s0, stt, e);
  if (st == DM_OK)
    st = finish(P, h, x0, s0, e);
  for (i = 0; st == DM_OK && i < P->S; i++)
    st = dm_routh_check_inertia(P->red, P->Xs + i * d, &P->sing_ref, P->twork, "a stage point", e);
  if (st == DM_OK)
    st = dm_routh_check_inertia(P->red, P->q1w, &P->sing_ref, P->twork, "the end point", e);
  if (st == DM_OK && !(all_finite(P->q1w, d) && all_finite(P->p1w, d)))
    st = dm_err_set(e, DM_EDOM, "RSPRK: the step produced a non-finite state (h = %g)", h);
  if (st != DM_OK) {
    P->hist = 0;
    return st;
  }
  if (dtheta)
    group_increment(P, h, dtheta);
  dm_vcopy(P->hV, P->X, P->Sd);
  if (P->N > P->Sd)
    dm_vcopy(P->hx, P->X + P->Sd, P->N - P->Sd);
  dm_vcopy(P->hq1, P->q1w, d);
  dm_vcopy(P->hp1, P->p1w, d);
  P->hist_h = h;
  P->hist = 1;
  dm_vcopy(x1, P->q1w, d);
  dm_vcopy(s1, P->p1w, d);
  if (stt)
    stt->steps++;
  return DM_OK;
}

/* {==== step Jacobian ===================================================== */

int dm_rsprk_jacobian(dm_rsprk *P, double h, const double *x0, const double *s0, double *DPhi,
                      dm_integ_stats *stt, dm_err *e)
{
  size_t d = P->d, S = P->S, Sd = P->Sd, dd = P->dd, N2 = 2 * d, i, j, k, a, c, y;
  const double *A = P->tab->a, *At = P->tab->at, *b = P->tab->b;
  double *x1 = P->dq, *dX = P->Xs;   /* scratch after the solve: Xs reused for dX */
  int st;
  if (P->m)
    return dm_err_set(e, DM_EUNSUP, "the step Jacobian is not available for constrained systems");
  if ((st = dm_rsprk_step(P, h, x0, s0, DPhi, DPhi + d, NULL, stt, e)) != DM_OK)
    return st;
  memcpy(x1, DPhi, d * sizeof(double));
  memset(P->K0, 0, dd * sizeof(double));
  memset(P->K1, 0, dd * sizeof(double));
  if (P->gyro && ((st = eval_node(P, x0, P->a0, P->K0, e)) != DM_OK
                  || (st = eval_node(P, x1, P->a1, P->K1, e)) != DM_OK))
    return st;
  if ((st = assemble(P, h, x0, s0, 1, e)) != DM_OK)
    return st;
  if ((P->sparse ? dm_splu_factor(P->slu, P->Jv, NULL) : dm_rlu_factor(&P->lu, P->Jm, Sd))
      != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "RSPRK Jacobian: singular stage matrix (h = %g)", h);
  for (c = 0; c < N2; c++) {
    double *dV = P->rhs + c * Sd;
    for (i = 0; i < S; i++)
      for (a = 0; a < d; a++) {
        double v;
        if (c < d) {
          v = P->Lvq[i * dd + a * d + c] + P->gK[i * dd + a * d + c] - P->K0[a * d + c];
          for (j = 0; j < S; j++)
            v -= h * At[i * S + j] * P->D[j * dd + a * d + c];
        } else {
          v = (a == c - d) ? -1.0 : 0.0;
        }
        dV[i * d + a] = -v;
      }
    if (P->sparse)
      dm_splu_solve(P->slu, dV, 1, NULL);
    else
      dm_rlu_solve(&P->lu, P->Jm, Sd, dV);
    for (j = 0; j < S; j++)
      for (a = 0; a < d; a++) {
        double acc = 0.0;
        for (k = 0; k < S; k++)
          acc += A[j * S + k] * dV[k * d + a];
        dX[j * d + a] = (c < d && a == c ? 1.0 : 0.0) + h * acc;
      }
    for (a = 0; a < d; a++) {
      double dq1 = 0.0;
      for (j = 0; j < S; j++)
        dq1 += b[j] * dV[j * d + a];
      P->tmp[a] = (c == a ? 1.0 : 0.0) + h * dq1;     /* dx1 column c */
    }
    for (a = 0; a < d; a++) {
      double dp1 = 0.0, kk = 0.0;
      for (j = 0; j < S; j++) {
        double f = 0.0;
        for (y = 0; y < d; y++)
          f += P->D[j * dd + a * d + y] * dX[j * d + y] + P->E[j * dd + a * d + y] * dV[j * d + y];
        dp1 += b[j] * f;
      }
      for (y = 0; y < d; y++)
        kk += P->K1[a * d + y] * P->tmp[y];
      DPhi[a * N2 + c] = P->tmp[a];
      DPhi[(d + a) * N2 + c] = (c == d + a ? 1.0 : 0.0) + h * dp1 - kk
                               + (c < d ? P->K0[a * d + c] : 0.0);
    }
  }
  P->hist = 0;       /* stage buffers were reused */
  return DM_OK;
}
