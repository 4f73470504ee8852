/* lie_lgvi.c -- the Lie group variational integrator of Lee, Leok and
 * McClamroch (Moser-Veselov for the free rigid body), for L = 1/2 xi^T J xi
 * - U(g) on products of SO(3), SE(3), SE(2) and abelian factors.
 *
 * Discrete Lagrangian L_d = K_d(F_k) - (h/2)(U(g_k) + U(g_k+1)) with
 * F_k = g_k^-1 g_k+1 and K_d a sum over factors: (1/h) tr((I - F) J_d),
 * J_d = tr(J)/2 I - J, for a rotation; (1/2h) y^T M y for a translation or
 * an abelian block (y the body-frame displacement).  With the potential's
 * moments M(g) = -(d/de) U(g exp(e e_k)) and forces F (Lagrange-
 * d'Alembert, F_d^- = F_d^+ = (h/2) F) the step is (doc/lie.md):
 *   P = mu_k + (h/2)(M(g_k) + F_k);  solve D^R K_d(F_k) = P;
 *   g_k+1 = g_k F_k;  mu_k+1 = Ad*_(F_k) P + (h/2)(M(g_k+1) + F_k+1).
 * D^R K_d, the right-trivialized derivative, is solved factor by factor:
 * translations explicitly (y = h M^-1 P_v), then each rotation by Newton on
 * G(f) = a J f + b f x (J f) - h P_w = 0 (F = exp(f), a = sin th/th,
 * b = (1 - cos th)/th^2, analytic Jacobian) with the translation's moment
 * y x M y / h moved to the right side (SE(3)); SE(2)'s angle explicitly.
 * Velocity-dependent forces make the last equation a fixed point in
 * mu_k+1.  A step never allocates. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_integ_impl.h"
#include "core/newton.h"
#include "core/smalllu.h"
#include "core/vecmath.h"

enum { F_FLAT, F_SO3, F_SE3, F_SE2 };

typedef struct lgfac {
  int kind;
  size_t xo, qo, d;              /* offsets in algebra and storage, dimension */
  double J[9], Jd[9];            /* rotation inertia (3x3), J_d */
  double Jw;                     /* SE(2) rotational inertia */
  double Mlu[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];  /* translation / abelian mass, factored */
  size_t mperm[DM_LIE_DIM_MAX];
  double Mm[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];   /* the same, unfactored */
  size_t md;                     /* its order */
  double f[3];                   /* last rotation solution (warm start) */
} lgfac;

typedef struct lgvi {
  const dm_lie_system *S;
  unsigned long gen;
  size_t nf;
  lgfac fac[DM_LIE_FAC_MAX];
  double Jlu[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];
  size_t Jperm[DM_LIE_DIM_MAX];
  double P[DM_LIE_DIM_MAX], Phi[DM_LIE_NQ_MAX], M[DM_LIE_DIM_MAX], F[DM_LIE_DIM_MAX];
  double base[DM_LIE_DIM_MAX], xi[DM_LIE_DIM_MAX], mu[DM_LIE_DIM_MAX], g1[DM_LIE_NQ_MAX];
  double hprev;
  int warm;
  double *work;
} lgvi;

static const char *const lgvi_options[] = {"h", "tol", "maxiter", NULL};

/* {==== setup from the kinetic matrix ==================================== */

static int coupled(const double *J, size_t n, size_t r0, size_t r1, size_t c0, size_t c1,
                   double scale)
{
  size_t i, j;
  for (i = r0; i < r1; i++)
    for (j = c0; j < c1; j++)
      if (fabs(J[i * n + j]) > 1e-14 * scale || fabs(J[j * n + i]) > 1e-14 * scale)
        return 1;
  return 0;
}

static int factor_block(const double *J, size_t n, size_t o, size_t d, lgfac *f, dm_err *e,
                        const char *what)
{
  size_t i, j;
  f->md = d;
  for (i = 0; i < d; i++)
    for (j = 0; j < d; j++)
      f->Mm[i * d + j] = f->Mlu[i * d + j] = J[(o + i) * n + o + j];
  if (dm_smalllu_factor(f->Mlu, d, f->mperm) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "lgvi: the kinetic energy's %s block is singular", what);
  return DM_OK;
}

static int setup(dm_integrator *I, dm_err *e)
{
  lgvi *W = I->state;
  const dm_lie_system *S = W->S;
  const dm_lie_group *G = S->G;
  const size_t n = S->dim;
  double scale = dm_norm_inf(S->J, n * n);
  size_t k, i, j;
  int st;
  W->nf = G->kind == DM_LIE_PRODUCT ? G->nfac : 1;
  for (k = 0; k < W->nf; k++) {
    const dm_lie_group *F = G->kind == DM_LIE_PRODUCT ? G->fac[k] : G;
    lgfac *f = &W->fac[k];
    size_t xo = G->kind == DM_LIE_PRODUCT ? G->xoff[k] : 0;
    f->xo = xo;
    f->qo = G->kind == DM_LIE_PRODUCT ? G->qoff[k] : 0;
    f->d = F->dim;
    if (coupled(S->J, n, xo, xo + F->dim, 0, xo, scale) ||
        coupled(S->J, n, xo, xo + F->dim, xo + F->dim, n, scale))
      return dm_err_set(e, DM_EINVAL, "lgvi: the kinetic energy couples factor %zu (%s) of %s "
                        "with another factor; lgvi takes block-diagonal kinetic energies "
                        "(use method 'lie:gauss')", k + 1, F->name, G->name);
    switch (F->kind) {
    case DM_LIE_SO3:
    case DM_LIE_SE3:
      f->kind = F->kind == DM_LIE_SO3 ? F_SO3 : F_SE3;
      if (F->kind == DM_LIE_SE3 && coupled(S->J, n, xo, xo + 3, xo + 3, xo + 6, scale))
        return dm_err_set(e, DM_EINVAL, "lgvi: the kinetic energy couples the rotation and "
                          "the translation of SE3 (factor %zu); use method 'lie:gauss'", k + 1);
      for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
          f->J[3 * i + j] = S->J[(xo + i) * n + xo + j];
      for (i = 0; i < 9; i++)
        f->Jd[i] = -f->J[i] + (i % 4 == 0 ? 0.5 * (f->J[0] + f->J[4] + f->J[8]) : 0.0);
      if (F->kind == DM_LIE_SE3 && (st = factor_block(S->J, n, xo + 3, 3, f, e, "translation"))
                                       != DM_OK)
        return st;
      break;
    case DM_LIE_SE2:
      f->kind = F_SE2;
      if (coupled(S->J, n, xo, xo + 1, xo + 1, xo + 3, scale))
        return dm_err_set(e, DM_EINVAL, "lgvi: the kinetic energy couples the rotation and "
                          "the translation of SE2 (factor %zu); use method 'lie:gauss'", k + 1);
      f->Jw = S->J[xo * n + xo];
      if ((st = factor_block(S->J, n, xo + 1, 2, f, e, "translation")) != DM_OK)
        return st;
      break;
    default:
      f->kind = F_FLAT;
      if ((st = factor_block(S->J, n, xo, F->dim, f, e, F->name)) != DM_OK)
        return st;
      break;
    }
  }
  memcpy(W->Jlu, S->J, n * n * sizeof *S->J);
  if (dm_smalllu_factor(W->Jlu, n, W->Jperm) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "lgvi: the kinetic matrix d2L/dxi2 is singular");
  W->gen = S->gen;
  W->warm = 0;
  return DM_OK;
}

static void lgvi_free(dm_integrator *I)
{
  lgvi *W = I->state;
  if (W) {
    free(W->work);
    free(W);
  }
  I->state = NULL;
}

static int lgvi_alloc(dm_integrator *I, dm_err *e)
{
  const dm_lie_system *S = dm_lie_system_of(I->sys);
  lgvi *W;
  int st;
  if (S == NULL)
    return dm_err_set(e, DM_EINVAL, "lgvi: needs a system on a Lie group");
  if (!S->quadratic)
    return dm_err_set(e, DM_EINVAL, "lgvi: needs L = 1/2 xi^T J xi - U(g) with a constant "
                      "kinetic matrix J (free of g and xi) and no terms linear in xi; '%s' is "
                      "not of that form (use method 'lie:gauss')", S->name);
  if ((W = calloc(1, sizeof *W)) == NULL || (W->work = calloc(S->work + 8, sizeof(double))) == NULL) {
    free(W);
    return dm_err_set(e, DM_ENOMEM, "lgvi: out of memory");
  }
  W->S = S;
  I->state = W;
  if ((st = setup(I, e)) != DM_OK) {
    lgvi_free(I);
    return st;
  }
  I->order = 2;
  return DM_OK;
}

static void lgvi_reset(dm_integrator *I)
{
  ((lgvi *)I->state)->warm = 0;
}

/* }====================================================================== */

/* {==== the rotation equation ============================================ */

/* 2 d/dt of sin(th)/th and (1 - cos th)/th^2 (t = th^2): a'/th, b'/th */
static void dcoef(double t, double *da, double *db)
{
  if (t < 1e-2) {
    *da = 2.0 * (dm_lie_ser_sinc[1] + t * (2 * dm_lie_ser_sinc[2] + t * (3 * dm_lie_ser_sinc[3] +
                                                                      t * 4 * dm_lie_ser_sinc[4])));
    *db = 2.0 * (dm_lie_ser_cosc[1] + t * (2 * dm_lie_ser_cosc[2] + t * (3 * dm_lie_ser_cosc[3] +
                                                                      t * 4 * dm_lie_ser_cosc[4])));
  } else {
    double th = sqrt(t), s = sin(th), c = cos(th);
    *da = (th * c - s) / (t * th);
    *db = (th * s - 2.0 * (1.0 - c)) / (t * t);
  }
}

/* a J f + b f x (J f) = r for f (warm start in f), F = exp(f) */
static int solve_rotation(const lgfac *fc, const double *r, double *f, int maxiter, double tol,
                          dm_err *e)
{
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  double d = HUGE_VAL;
  int it;
  for (it = 0; it < maxiter; it++) {
    double t = dm_v3_dot(f, f), a = dm_lie_sinc(t), b = dm_lie_cosc(t), da, db;
    double Jf[3], fJf[3], G[3], A[9], Jh[9], fhJ[9], fn;
    int i, j;
    dm_m3_apply(fc->J, f, Jf);
    dm_v3_cross(f, Jf, fJf);
    for (i = 0; i < 3; i++)
      G[i] = a * Jf[i] + b * fJf[i] - r[i];
    dcoef(t, &da, &db);
    /* grad G = a J + b (hat(f) J - hat(J f)) + (J f) da f^T + (f x J f) db f^T */
    dm_so3_poly(f, 0.0, 1.0, 0.0, Jh, 3);
    dm_m3_mul(Jh, fc->J, fhJ);
    dm_so3_poly(Jf, 0.0, 1.0, 0.0, Jh, 3);
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++)
        A[3 * i + j] = a * fc->J[3 * i + j] + b * (fhJ[3 * i + j] - Jh[3 * i + j]) +
                       (Jf[i] * da + fJf[i] * db) * f[j];
    if (dm_m3_solve(A, G) != 0)
      return dm_err_set(e, DM_ESINGULAR, "lgvi: singular Jacobian of the rotation equation "
                        "(|f| = %.6g: the step turns the body by about pi)", sqrt(t));
    for (i = 0; i < 3; i++)
      f[i] -= G[i];
    fn = dm_norm_inf(f, 3);
    d = dm_norm_inf(G, 3) / (fn > 0.0 ? fn : 1.0);
    if (!(d == d))
      break;
    if (dm_newton_done(&stop, d, tol))
      return DM_OK;
  }
  return dm_err_set(e, DM_ENOCONV, "lgvi: the rotation equation did not converge in %d "
                    "iterations (relative update %.3g, tol %.3g)", it, d, tol);
}

/* }====================================================================== */

/* {==== the step ========================================================= */

/* D^R K_d(Phi) = P, factor by factor, into W->Phi */
static int solve_relative(dm_integrator *I, lgvi *W, double h, dm_err *e)
{
  const dm_lie_group *G = W->S->G;
  size_t k, i;
  int st;
  for (k = 0; k < W->nf; k++) {
    lgfac *fc = &W->fac[k];
    const double *P = W->P + fc->xo;
    double *Phi = W->Phi + fc->qo, y[DM_LIE_DIM_MAX], My[DM_LIE_DIM_MAX], r[3];
    switch (fc->kind) {
    case F_FLAT:
      for (i = 0; i < fc->d; i++)
        Phi[i] = h * P[i];
      dm_smalllu_solve(fc->Mlu, fc->d, fc->mperm, Phi);
      break;
    case F_SE2:
      y[0] = h * P[1], y[1] = h * P[2];
      dm_smalllu_solve(fc->Mlu, 2, fc->mperm, y);
      My[0] = fc->Mm[0] * y[0] + fc->Mm[1] * y[1];
      My[1] = fc->Mm[2] * y[0] + fc->Mm[3] * y[1];
      Phi[0] = (h * P[0] - (My[0] * (-y[1]) + My[1] * y[0])) / fc->Jw;
      Phi[1] = y[0];
      Phi[2] = y[1];
      break;
    default:                    /* SO3, SE3 */
      r[0] = h * P[0], r[1] = h * P[1], r[2] = h * P[2];
      if (fc->kind == F_SE3) {
        double c[3];
        for (i = 0; i < 3; i++)
          y[i] = h * P[3 + i];
        dm_smalllu_solve(fc->Mlu, 3, fc->mperm, y);
        dm_m3_apply(fc->Mm, y, My);
        dm_v3_cross(y, My, c);
        for (i = 0; i < 3; i++)
          r[i] -= c[i];
      }
      if (!W->warm || h != W->hprev) {
        memcpy(fc->f, r, sizeof fc->f);
        if (dm_m3_solve(fc->J, fc->f) != 0)
          fc->f[0] = fc->f[1] = fc->f[2] = 0.0;
      }
      if ((st = solve_rotation(fc, r, fc->f, I->opt.maxiter, I->opt.tol, e)) != DM_OK)
        return st;
      dm_so3_exp(fc->f, Phi);
      if (fc->kind == F_SE3)
        memcpy(Phi + 9, y, 3 * sizeof *y);
      break;
    }
  }
  (void)G;
  return DM_OK;
}

static int eval_fail(int rc, const char *what, dm_err *e)
{
  return dm_err_set(e, rc > 0 ? DM_EDOM : DM_ECALLBACK, "lgvi: %s is not finite (NaN or Inf)",
                    what);
}

static int lgvi_step(dm_integrator *I, double h, const double *q0, const double *p0,
                     double *q1, double *p1, dm_err *e)
{
  lgvi *W = I->state;
  const dm_lie_system *S = W->S;
  const dm_lie_group *G = S->G;
  const size_t n = S->dim, nq = S->nq;
  const double hh = 0.5 * h;
  size_t i;
  int st, it;
  if (W->gen != S->gen && (st = setup(I, e)) != DM_OK)
    return st;
  if ((st = dm_lie_eval_moment(S, q0, W->M, W->work)) != 0)
    return eval_fail(st, "the potential's moment at g_k", e);
  if (S->force) {
    memcpy(W->xi, p0, n * sizeof *p0);
    dm_smalllu_solve(W->Jlu, n, W->Jperm, W->xi);
    if ((st = dm_lie_eval_force(S, q0, W->xi, W->F, W->work)) != 0)
      return eval_fail(st, "the force at step start", e);
  }
  for (i = 0; i < n; i++)
    W->P[i] = p0[i] + hh * (W->M[i] + (S->force ? W->F[i] : 0.0));
  if ((st = solve_relative(I, W, h, e)) != DM_OK)
    return st;
  W->warm = 1;
  W->hprev = h;
  dm_lie_compose(G, q0, W->Phi, W->g1);
  dm_lie_Adstar_apply(G, W->Phi, W->P, W->base);
  if ((st = dm_lie_eval_moment(S, W->g1, W->M, W->work)) != 0)
    return eval_fail(st, "the potential's moment at g_k+1", e);
  for (i = 0; i < n; i++)
    W->mu[i] = W->base[i] + hh * (W->M[i] + (S->force ? W->F[i] : 0.0));
  /* mu_k+1 = base + (h/2)(M_k+1 + F(g_k+1, J^-1 mu_k+1)): a fixed point */
  for (it = 0; S->force && it < I->opt.maxiter; it++) {
    double d = 0.0, sc = dm_norm_inf(W->mu, n);
    memcpy(W->xi, W->mu, n * sizeof *W->mu);
    dm_smalllu_solve(W->Jlu, n, W->Jperm, W->xi);
    if ((st = dm_lie_eval_force(S, W->g1, W->xi, W->F, W->work)) != 0)
      return eval_fail(st, "the force at step end", e);
    for (i = 0; i < n; i++) {
      double m = W->base[i] + hh * (W->M[i] + W->F[i]);
      d = fmax(d, fabs(m - W->mu[i]));
      W->mu[i] = m;
    }
    if (d <= I->opt.tol * (sc > 1.0 ? sc : 1.0))
      break;
  }
  if (S->force && it == I->opt.maxiter)
    return dm_err_set(e, DM_ENOCONV, "lgvi: the velocity-dependent force's fixed point did not "
                      "converge in %d iterations (reduce h)", it);
  memcpy(q1, W->g1, nq * sizeof *q1);
  memcpy(p1, W->mu, n * sizeof *p1);
  I->stats.steps++;
  return DM_OK;
}

/* }====================================================================== */

static const char *const lie_kinds[] = {DM_SYSTEM_LIE, NULL};

const dm_integrator_type dm_lie_integ_lgvi = {
  .name = "lgvi",
  .summary = "Lie group variational integrator (Lee-Leok-McClamroch, Moser-Veselov trace form); "
             "order 2, symplectic, momentum preserving",
  .order = 2,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES,
  .options = lgvi_options,
  .alloc = lgvi_alloc,
  .step = lgvi_step,
  .reset = lgvi_reset,
  .free = lgvi_free,
  .kinds = lie_kinds,
};
