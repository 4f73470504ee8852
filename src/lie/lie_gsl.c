/* lie_gsl.c -- non-structure-preserving references for systems on groups:
 * "gsl:<stepper>" (rk2, rk4, rkf45, rkck, rk8pd) integrates the
 * Euler-Poincare equations with the reconstruction in embedding
 * coordinates with a fixed step of GSL odeiv2:
 *   mu' = ad_xi^T mu + Lq(g, xi) + F(g, xi),   xi from mu (Legendre map),
 *   q' = q (0, w)/2 for an SO(3) or SE(3) rotation (a quaternion, never
 *   normalized), p' = R v (SE(3)), theta' = w, x' = v (abelian factors),
 *   SE(2): theta' = w, (x, y)' = R(theta) v.
 * It conserves neither |mu|, nor the spatial momentum, nor the energy:
 * the comparison the Lie group variational integrators are measured
 * against.  The quaternion is kept between steps while the state passed in
 * is the one returned by the previous step (else it is taken from g). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "lie/lie_integ_impl.h"

typedef struct lgsl {
  const dm_lie_system *S;
  gsl_odeiv2_step *st;
  gsl_odeiv2_system sys;
  dm_integrator *I;
  size_t ny, nf;
  size_t yoff[DM_LIE_FAC_MAX + 1];
  double *y, *yerr, *g, *xi, *Lq, *F, *last_g, *work;
  int have_last, fail;
  dm_err err;
} lgsl;

static const char *const gsl_options[] = {"h", "tol", "maxiter", NULL};

static const dm_lie_group *factor(const dm_lie_group *G, size_t k)
{
  return G->kind == DM_LIE_PRODUCT ? G->fac[k] : G;
}

static size_t ode_size(const dm_lie_group *F)
{
  return F->kind == DM_LIE_SO3 ? 4 : F->kind == DM_LIE_SE3 ? 7 : F->nq;
}

/* rotation matrix of a quaternion (w, x, y, z), normalized by |q|^2 */
static void quat_to_R(const double *q, double *R)
{
  double w = q[0], x = q[1], y = q[2], z = q[3], s = 2.0 / (w * w + x * x + y * y + z * z);
  R[0] = 1 - s * (y * y + z * z), R[1] = s * (x * y - w * z), R[2] = s * (x * z + w * y);
  R[3] = s * (x * y + w * z), R[4] = 1 - s * (x * x + z * z), R[5] = s * (y * z - w * x);
  R[6] = s * (x * z - w * y), R[7] = s * (y * z + w * x), R[8] = 1 - s * (x * x + y * y);
}

/* Shepperd's method: the largest of w, x, y, z first */
static void R_to_quat(const double *R, double *q)
{
  double tr = R[0] + R[4] + R[8], t[4] = {1 + tr, 1 + R[0] - R[4] - R[8],
                                          1 - R[0] + R[4] - R[8], 1 - R[0] - R[4] + R[8]};
  int m = 0, i;
  for (i = 1; i < 4; i++)
    if (t[i] > t[m])
      m = i;
  {
    double s = 0.5 / sqrt(t[m]);
    switch (m) {
    case 0:
      q[0] = 0.25 / s, q[1] = (R[7] - R[5]) * s, q[2] = (R[2] - R[6]) * s, q[3] = (R[3] - R[1]) * s;
      break;
    case 1:
      q[0] = (R[7] - R[5]) * s, q[1] = 0.25 / s, q[2] = (R[1] + R[3]) * s, q[3] = (R[2] + R[6]) * s;
      break;
    case 2:
      q[0] = (R[2] - R[6]) * s, q[1] = (R[1] + R[3]) * s, q[2] = 0.25 / s, q[3] = (R[5] + R[7]) * s;
      break;
    default:
      q[0] = (R[3] - R[1]) * s, q[1] = (R[2] + R[6]) * s, q[2] = (R[5] + R[7]) * s, q[3] = 0.25 / s;
      break;
    }
  }
}

/* y (ODE coordinates of g) -> g */
static void y_to_g(const lgsl *W, const double *y, double *g)
{
  const dm_lie_group *G = W->S->G;
  size_t k;
  for (k = 0; k < W->nf; k++) {
    const dm_lie_group *F = factor(G, k);
    double *gk = g + (G->kind == DM_LIE_PRODUCT ? G->qoff[k] : 0);
    const double *yk = y + W->yoff[k];
    if (F->kind == DM_LIE_SO3 || F->kind == DM_LIE_SE3) {
      quat_to_R(yk, gk);
      if (F->kind == DM_LIE_SE3)
        memcpy(gk + 9, yk + 4, 3 * sizeof *gk);
    } else {
      memcpy(gk, yk, F->nq * sizeof *gk);
    }
  }
}

static void g_to_y(const lgsl *W, const double *g, double *y)
{
  const dm_lie_group *G = W->S->G;
  size_t k;
  for (k = 0; k < W->nf; k++) {
    const dm_lie_group *F = factor(G, k);
    const double *gk = g + (G->kind == DM_LIE_PRODUCT ? G->qoff[k] : 0);
    double *yk = y + W->yoff[k];
    if (F->kind == DM_LIE_SO3 || F->kind == DM_LIE_SE3) {
      R_to_quat(gk, yk);
      if (F->kind == DM_LIE_SE3)
        memcpy(yk + 4, gk + 9, 3 * sizeof *yk);
    } else {
      memcpy(yk, gk, F->nq * sizeof *yk);
    }
  }
}

static int rhs(double t, const double *y, double *dy, void *params)
{
  lgsl *W = params;
  const dm_lie_system *S = W->S;
  const dm_lie_group *G = S->G;
  const size_t n = S->dim, ng = W->yoff[W->nf];
  const double *mu = y + ng;
  double ad[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];
  dm_lag_out o;
  size_t k, i, j;
  (void)t;
  y_to_g(W, y, W->g);
  if (dm_integrator_velocity(W->I, W->g, mu, W->xi, 1, &W->err) != DM_OK) {
    W->fail = 1;
    return GSL_EBADFUNC;
  }
  memset(&o, 0, sizeof o);
  o.Lq = W->Lq;
  if (S->sys.lagrangian(S->sys.data, W->g, W->xi, S->parv, DM_LAG_Q, &o, W->work) != 0 ||
      dm_lie_eval_force(S, W->g, W->xi, W->F, W->work) != 0) {
    dm_err_set(&W->err, DM_EDOM, "gsl: the Lagrangian or the force is not finite");
    W->fail = 1;
    return GSL_EBADFUNC;
  }
  /* mu' = ad_xi^T mu + Lq + F */
  dm_lie_ad(G, W->xi, ad, n);
  for (i = 0; i < n; i++) {
    double s = W->Lq[i] + W->F[i];
    for (j = 0; j < n; j++)
      s += ad[j * n + i] * mu[j];
    dy[ng + i] = s;
  }
  for (k = 0; k < W->nf; k++) {
    const dm_lie_group *F = factor(G, k);
    const double *xk = W->xi + (G->kind == DM_LIE_PRODUCT ? G->xoff[k] : 0);
    const double *yk = y + W->yoff[k];
    double *dk = dy + W->yoff[k];
    if (F->kind == DM_LIE_SO3 || F->kind == DM_LIE_SE3) {
      /* q' = q (0, w) / 2 */
      double qw = yk[0], qx = yk[1], qy = yk[2], qz = yk[3];
      dk[0] = 0.5 * (-qx * xk[0] - qy * xk[1] - qz * xk[2]);
      dk[1] = 0.5 * (qw * xk[0] + qy * xk[2] - qz * xk[1]);
      dk[2] = 0.5 * (qw * xk[1] + qz * xk[0] - qx * xk[2]);
      dk[3] = 0.5 * (qw * xk[2] + qx * xk[1] - qy * xk[0]);
      if (F->kind == DM_LIE_SE3) {
        double R[9];
        quat_to_R(yk, R);
        dm_m3_apply(R, xk + 3, dk + 4);
      }
    } else if (F->kind == DM_LIE_SE2) {
      double c = cos(yk[0]), s = sin(yk[0]);
      dk[0] = xk[0];
      dk[1] = c * xk[1] - s * xk[2];
      dk[2] = s * xk[1] + c * xk[2];
    } else {
      memcpy(dk, xk, F->nq * sizeof *dk);
    }
  }
  return GSL_SUCCESS;
}

static void gsl_free_(dm_integrator *I)
{
  lgsl *W = I->state;
  if (W) {
    if (W->st)
      gsl_odeiv2_step_free(W->st);
    free(W->y);
    free(W->work);
    free(W);
  }
  I->state = NULL;
}

static const gsl_odeiv2_step_type *stepper(const char *name)
{
  if (strcmp(name, "rk2") == 0)
    return gsl_odeiv2_step_rk2;
  if (strcmp(name, "rk4") == 0)
    return gsl_odeiv2_step_rk4;
  if (strcmp(name, "rkf45") == 0)
    return gsl_odeiv2_step_rkf45;
  if (strcmp(name, "rkck") == 0)
    return gsl_odeiv2_step_rkck;
  if (strcmp(name, "rk8pd") == 0)
    return gsl_odeiv2_step_rk8pd;
  return NULL;
}

static int gsl_alloc(dm_integrator *I, dm_err *e)
{
  const dm_lie_system *S = dm_lie_system_of(I->sys);
  const gsl_odeiv2_step_type *T;
  lgsl *W;
  size_t k, n;
  if (S == NULL)
    return dm_err_set(e, DM_EINVAL, "gsl: needs a system on a Lie group");
  if ((T = stepper(I->variant)) == NULL)
    return dm_err_set(e, DM_ENOTFOUND, "gsl: unknown stepper '%s' for a system on a group "
                      "(rk2, rk4, rkf45, rkck, rk8pd)", I->variant);
  if ((W = calloc(1, sizeof *W)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "gsl: out of memory");
  I->state = W;
  W->S = S;
  W->I = I;
  n = S->dim;
  W->nf = S->G->kind == DM_LIE_PRODUCT ? S->G->nfac : 1;
  for (k = 0; k < W->nf; k++)
    W->yoff[k + 1] = W->yoff[k] + ode_size(factor(S->G, k));
  W->ny = W->yoff[W->nf] + n;
  W->y = calloc(2 * W->ny + 2 * S->nq + 3 * n + 4, sizeof *W->y);
  W->work = calloc(S->work + 8, sizeof *W->work);
  W->st = gsl_odeiv2_step_alloc(T, W->ny);
  if (W->y == NULL || W->work == NULL || W->st == NULL) {
    gsl_free_(I);
    return dm_err_set(e, DM_ENOMEM, "gsl: out of memory");
  }
  W->yerr = W->y + W->ny;
  W->g = W->yerr + W->ny;
  W->last_g = W->g + S->nq;
  W->xi = W->last_g + S->nq;
  W->Lq = W->xi + n;
  W->F = W->Lq + n;
  W->sys.function = rhs;
  W->sys.jacobian = NULL;
  W->sys.dimension = W->ny;
  W->sys.params = W;
  I->order = (int)gsl_odeiv2_step_order(W->st);
  I->flags = 0;
  return DM_OK;
}

static void gsl_reset_(dm_integrator *I)
{
  lgsl *W = I->state;
  W->have_last = 0;
  gsl_odeiv2_step_reset(W->st);
}

static int gsl_step_(dm_integrator *I, double h, const double *q0, const double *p0, double *q1,
                     double *p1, dm_err *e)
{
  lgsl *W = I->state;
  const dm_lie_system *S = W->S;
  const size_t ng = W->yoff[W->nf];
  int st;
  if (!(W->have_last && memcmp(q0, W->last_g, S->nq * sizeof *q0) == 0))
    g_to_y(W, q0, W->y);
  memcpy(W->y + ng, p0, S->dim * sizeof *p0);
  W->fail = 0;
  st = gsl_odeiv2_step_apply(W->st, 0.0, h, W->y, W->yerr, NULL, NULL, &W->sys);
  if (W->fail)
    return dm_err_set(e, W->err.status ? W->err.status : DM_EDOM, "%s", W->err.msg);
  if (st != GSL_SUCCESS)
    return dm_err_set(e, dm_from_gsl(st), "gsl:%s: the step failed (%s)", I->variant,
                      gsl_strerror(st));
  y_to_g(W, W->y, q1);
  memcpy(p1, W->y + ng, S->dim * sizeof *p1);
  memcpy(W->last_g, q1, S->nq * sizeof *q1);
  W->have_last = 1;
  I->stats.steps++;
  return DM_OK;
}

static const char *const lie_kinds[] = {DM_SYSTEM_LIE, NULL};

const dm_integrator_type dm_lie_integ_gsl = {
  .name = "gsl",
  .summary = "GSL odeiv2 fixed-step Runge-Kutta on the Euler-Poincare equations with "
             "quaternions for rotations (not structure preserving; a reference)",
  .order = 0,
  .flags = 0,
  .options = gsl_options,
  .alloc = gsl_alloc,
  .step = gsl_step_,
  .reset = gsl_reset_,
  .free = gsl_free_,
  .kinds = lie_kinds,
};
