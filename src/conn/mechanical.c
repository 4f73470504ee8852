/* mechanical.c -- the discrete mechanical connection of a G-invariant
 * discrete Lagrangian (doc/bundles-connections-holonomy.md §6.2): A_d(q0, q1) =
 * k^-1 where the discrete momentum J_d(q0, k.q1) = D2 Ld(q0, k.q1) . xi_Q(k.q1)
 * equals mu (0 for the mechanical connection proper).
 *
 * Symbolically: with fresh symbols k for a group element, L'(k) =
 * Ld(q0, k.q1) (the bundle's action on nodes); J_j = d/de L'(exp(e e_j) k),
 * the right-trivialized gradient of L' in k; its Jacobian in the update
 * k exp(eta) is the left-trivialized gradient of each J_j.  Both compile
 * into one tape with inputs k and parameters (q0, q1, user parameters).
 *
 * Newton on the group: k <- k exp(eta), Jac eta = mu - J, the small LU of
 * src/core and the project's stopping rule on |eta|.  GSL's multiroot
 * solvers update x + dx in R^n and cannot keep k on the group, hence this
 * loop. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "conn/conn_impl.h"
#include "core/newton.h"
#include "core/smalllu.h"
#include "core/numfmt.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

struct conn_mech {
  dm_tape *t;                   /* in: k (G->nq); par: q0, q1, user; out: J, Jac */
  size_t nq, npar, dim;
  double *par;                  /* 2 nq + npar */
  double *work, *out, *jac;
  size_t *perm;
  double mu[DM_LIE_DIM_MAX];
  double tol;
  int maxit, sgn;               /* sgn: the extremum's sign (0 until known) */
  unsigned long solves, iters;
};

void dm_conn__mech_free(conn_mech *m)
{
  if (m == NULL)
    return;
  dm_tape_free(m->t);
  free(m->par);
  free(m->work);
  free(m->perm);
  free(m);
}

/* Build the tape (nodes of ctx: k, k.q1, L', J, Jac). */
static int build(conn_mech *m, const dm_conn_bundle *B, dm_expr_ctx *ctx, const dm_expr *q0,
                 const dm_expr *q1, dm_expr Ld, size_t npar, const dm_expr *par, dm_err *e)
{
  const dm_lie_group *G = B->G;
  size_t nq = B->nq, gq = G->nq, dim = G->dim, j, a;
  dm_expr *k, *kq1, *gk, *out, *gj, *allpar;
  dm_expr L1;
  char name[48];
  int st;
  k = malloc((gq + nq + gq + dim + dim * dim + gq + 2 * nq + npar + 1) * sizeof *k);
  if (k == NULL)
    return dm_err_set(e, DM_ENOMEM, "discrete mechanical connection: out of memory");
  kq1 = k + gq;
  gk = kq1 + nq;
  out = gk + gq;
  gj = out + dim + dim * dim;
  allpar = gj + gq;
  for (a = 0; a < gq; a++) {
    snprintf(name, sizeof name, "conn.k%zu", a + 1);
    k[a] = dm_expr_sym(ctx, name);
  }
  if ((st = B->type->act_sym(ctx, B, k, q1, kq1, e)) != DM_OK ||
      (st = dm_expr_subs(ctx, 1, &Ld, &L1, nq, q1, kq1, e)) != DM_OK ||
      (st = dm_expr_grad(ctx, L1, gq, k, gk, e)) != DM_OK ||
      (st = dm_lie_sym_trivialize(ctx, G, k, gk, DM_LIE_RIGHT, out, e)) != DM_OK)
    goto done;
  for (j = 0; j < dim; j++) {
    if ((st = dm_expr_grad(ctx, out[j], gq, k, gj, e)) != DM_OK ||
        (st = dm_lie_sym_trivialize(ctx, G, k, gj, DM_LIE_LEFT, out + dim + j * dim, e)) != DM_OK)
      goto done;
  }
  memcpy(allpar, q0, nq * sizeof *q0);
  memcpy(allpar + nq, q1, nq * sizeof *q1);
  if (npar)
    memcpy(allpar + 2 * nq, par, npar * sizeof *par);
  st = dm_tape_compile(ctx, dim + dim * dim, out, gq, k, 2 * nq + npar, allpar, &m->t, e);
done:
  free(k);
  return st;
}

dm_conn_dc *dm_conn_dc_mechanical(const dm_conn_bundle *B, dm_expr_ctx *ctx,
                                  const dm_expr *q0, const dm_expr *q1, dm_expr Ld,
                                  size_t npar, const dm_expr *par, const double *parval,
                                  dm_conn_dc *guess, double tol, int maxit, dm_err *e)
{
  const dm_conn_rule *R = dm_conn_rule_find("mechanical");
  conn_mech *m;
  dm_conn_dc *D;
  size_t dim;
  if (B == NULL || ctx == NULL || q0 == NULL || q1 == NULL) {
    dm_err_set(e, DM_EINVAL, "discrete mechanical connection: bundle and Ld expected");
    return NULL;
  }
  if (B->type->act_sym == NULL) {
    dm_err_set(e, DM_EUNSUP, "discrete mechanical connection: the %s bundle has no symbolic "
               "action", B->type->name);
    return NULL;
  }
  if (guess != NULL && guess->B != B && (guess->B->nq != B->nq ||
                                         !dm_lie_group_equal(guess->B->G, B->G))) {
    dm_err_set(e, DM_EINVAL, "discrete mechanical connection: the guess lives on another bundle");
    return NULL;
  }
  if (maxit < 0 || isnan(tol)) {
    dm_err_set(e, DM_EINVAL, "discrete mechanical connection: tol and maxit must be numbers >= 0");
    return NULL;
  }
  dim = B->G->dim;
  if ((m = calloc(1, sizeof *m)) == NULL || (D = calloc(1, sizeof *D)) == NULL) {
    free(m);
    dm_err_set(e, DM_ENOMEM, "discrete mechanical connection: out of memory");
    return NULL;
  }
  D->R = R;
  D->B = B;
  D->mech = m;
  D->guess = guess;
  D->topts.substeps = 8;
  m->nq = B->nq;
  m->npar = npar;
  m->dim = dim;
  m->tol = tol > 0.0 ? tol : 1e-14;
  m->maxit = maxit > 0 ? maxit : 50;
  if (build(m, B, ctx, q0, q1, Ld, npar, par, e) != DM_OK)
    goto fail;
  if ((m->par = calloc(2 * m->nq + npar + 1, sizeof *m->par)) == NULL ||
      (m->work = malloc((dm_tape_work_size(m->t) + 2 * (dim + dim * dim) + 1) *
                        sizeof *m->work)) == NULL ||
      (m->perm = malloc((dim + 1) * sizeof *m->perm)) == NULL) {
    dm_err_set(e, DM_ENOMEM, "discrete mechanical connection: out of memory");
    goto fail;
  }
  m->out = m->work + dm_tape_work_size(m->t);
  m->jac = m->out + dim + dim * dim;
  if (npar)
    memcpy(m->par + 2 * m->nq, parval, npar * sizeof *parval);
  return D;
fail:
  dm_conn_dc_free(D);
  return NULL;
}

static conn_mech *mech_of(dm_conn_dc *D, const char *what, dm_err *e)
{
  if (D->mech == NULL)
    dm_err_set(e, DM_EINVAL, "%s: not a discrete mechanical connection (rule '%s')", what,
               D->R->name);
  return D->mech;
}

int dm_conn_dc_set_params(dm_conn_dc *D, const double *parval, dm_err *e)
{
  conn_mech *m = mech_of(D, "set_params", e);
  if (m == NULL)
    return DM_EINVAL;
  if (m->npar)
    memcpy(m->par + 2 * m->nq, parval, m->npar * sizeof *parval);
  return DM_OK;
}

int dm_conn_dc_set_mu(dm_conn_dc *D, const double *mu, dm_err *e)
{
  conn_mech *m = mech_of(D, "set_mu", e);
  size_t a;
  if (m == NULL)
    return DM_EINVAL;
  if (mu != NULL && !D->B->G->abelian)
    for (a = 0; a < m->dim; a++)
      if (mu[a] != 0.0)
        return dm_err_set(e, DM_EUNSUP, "set_mu: a nonzero momentum level needs an abelian "
                          "group (%s is not: its coadjoint orbit moves mu)", D->B->G->name);
  for (a = 0; a < m->dim; a++)
    m->mu[a] = mu ? mu[a] : 0.0;
  return DM_OK;
}

void dm_conn_dc_newton_stats(const dm_conn_dc *D, unsigned long *solves, unsigned long *iters)
{
  *solves = D->mech ? D->mech->solves : 0;
  *iters = D->mech ? D->mech->iters : 0;
}

/* J and Jac at k for the pair (q0, q1) */
static void eval_J(conn_mech *m, const double *k)
{
  dm_tape_eval(m->t, k, m->par, m->out, m->work);
}

int dm_conn_dc_momentum(dm_conn_dc *D, const double *q0, const double *q1, double *J, dm_err *e)
{
  conn_mech *m = mech_of(D, "momentum", e);
  double k[DM_LIE_NQ_MAX];
  if (m == NULL)
    return DM_EINVAL;
  memcpy(m->par, q0, m->nq * sizeof *q0);
  memcpy(m->par + m->nq, q1, m->nq * sizeof *q1);
  dm_lie_identity(D->B->G, k);
  eval_J(m, k);
  memcpy(J, m->out, m->dim * sizeof *J);
  return DM_OK;
}

/* 1 when the symmetric S (n x n, row-major) is positive definite; S is
 * overwritten by its Cholesky factor (GSL) */
static int posdef(double *S, size_t n)
{
  gsl_matrix_view v = gsl_matrix_view_array(S, n, n);
  return gsl_linalg_cholesky_decomp1(&v.matrix) == GSL_SUCCESS;
}

/* The kind of extremum horizontal pairs are: the sign of the Hessian of
 * k -> Ld(q0, k q1) on the diagonal q1 = q0 (a kinetic energy makes it
 * definite there: + for a minimum).  Computed once per connection. */
static int extremum_sign(conn_mech *m, const dm_lie_group *G, const double *q0)
{
  double k[DM_LIE_NQ_MAX], tr = 0.0;
  size_t a;
  if (m->sgn != 0)
    return m->sgn;
  memcpy(m->par, q0, m->nq * sizeof *q0);
  memcpy(m->par + m->nq, q0, m->nq * sizeof *q0);
  dm_lie_identity(G, k);
  eval_J(m, k);
  for (a = 0; a < m->dim; a++)
    tr += m->out[m->dim + a * m->dim + a];
  m->sgn = tr < 0.0 ? -1 : 1;
  return m->sgn;
}

/* Newton on the group for J_d(q0, k q1) = mu.  J is the right-trivialized
 * gradient of f(k) = Ld(q0, k q1) (minus mu), so its solutions are the
 * critical points of f, and horizontal pairs are the extremum that the
 * diagonal continues (a minimum for a kinetic energy).  Where the
 * symmetric part of the Hessian H = Ad_k^T Jac is not definite (of that
 * sign) the step is the regularized one (H + lambda I) eta = -g, at most
 * 1 long, which descends f; a limit that is a saddle is an error. */
int dm_conn__mech_solve(dm_conn_dc *D, const double *q0, const double *q1, double *k, dm_err *e)
{
  conn_mech *m = D->mech;
  const dm_lie_group *G = D->B->G;
  double eta[DM_LIE_DIM_MAX], E[DM_LIE_NQ_MAX], A[DM_LIE_NQ_MAX], res = HUGE_VAL;
  double Ad[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX], Hs[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX],
         S[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX], rhs[DM_LIE_DIM_MAX];
  dm_newton_test t = DM_NEWTON_TEST_INIT;
  size_t a, b, l, dim = m->dim;
  int it, st, sgn, pd = 1, saddle = 0;
  char p0[160], p1[160];
  sgn = extremum_sign(m, G, q0);
  /* the guess: k = A_guess(q0, q1)^-1 */
  if (D->guess != NULL) {
    if ((st = dm_conn_dc_eval(D->guess, q0, q1, A, e)) != DM_OK)
      return st;
    dm_lie_inverse(G, A, k);
  } else {
    dm_lie_identity(G, k);
  }
  memcpy(m->par, q0, m->nq * sizeof *q0);
  memcpy(m->par + m->nq, q1, m->nq * sizeof *q1);
  m->solves++;
  for (it = 1; it <= m->maxit; it++) {
    eval_J(m, k);
    res = 0.0;
    for (a = 0; a < dim; a++) {
      eta[a] = m->mu[a] - m->out[a];
      res = fmax(res, fabs(eta[a]));
    }
    memcpy(m->jac, m->out + dim, dim * dim * sizeof *m->jac);
    if (!isfinite(res))
      break;
    /* sgn sym(Ad_k^T Jac) (abelian: Ad = I) */
    if (G->abelian) {
      memset(Ad, 0, dim * dim * sizeof *Ad);
      for (a = 0; a < dim; a++)
        Ad[a * dim + a] = 1.0;
    } else {
      dm_lie_Ad(G, k, Ad, dim);
    }
    for (a = 0; a < dim; a++)
      for (b = 0; b < dim; b++) {
        double s1 = 0.0, s2 = 0.0;
        for (l = 0; l < dim; l++) {
          s1 += Ad[l * dim + a] * m->jac[l * dim + b];
          s2 += Ad[l * dim + b] * m->jac[l * dim + a];
        }
        Hs[a * dim + b] = 0.5 * sgn * (s1 + s2);
      }
    memcpy(S, Hs, dim * dim * sizeof *S);
    pd = posdef(S, dim);
    if (pd) {
      st = dm_smalllu_factor(m->jac, dim, m->perm);
      if (st != DM_OK) {
        dm_num_format_vec(p0, sizeof p0, q0, m->nq);
        dm_num_format_vec(p1, sizeof p1, q1, m->nq);
        return dm_err_set(e, DM_ESINGULAR, "discrete mechanical connection: singular momentum "
                          "Jacobian (the discrete Lagrangian is not group-regular there) at "
                          "q0 = %s, q1 = %s", p0, p1);
      }
      dm_smalllu_solve(m->jac, dim, m->perm, eta);
    } else {
      double lam = 1e-12, tr = 0.0, n;
      int tries;
      for (a = 0; a < dim; a++) {
        double s = 0.0;
        for (l = 0; l < dim; l++)
          s += Ad[l * dim + a] * eta[l];
        rhs[a] = sgn * s;
        tr += fabs(Hs[a * dim + a]);
      }
      lam = fmax(lam, tr / (double)dim);
      for (tries = 0; tries < 80; tries++, lam *= 2.0) {
        memcpy(S, Hs, dim * dim * sizeof *S);
        for (a = 0; a < dim; a++)
          S[a * dim + a] += lam;
        if (posdef(S, dim))
          break;
      }
      {
        gsl_matrix_view Sv = gsl_matrix_view_array(S, dim, dim);
        gsl_vector_view bv = gsl_vector_view_array(rhs, dim), xv = gsl_vector_view_array(eta, dim);
        gsl_linalg_cholesky_solve(&Sv.matrix, &bv.vector, &xv.vector);
      }
      n = dm_conn__norm(eta, dim);
      if (n > 1.0)
        for (a = 0; a < dim; a++)
          eta[a] /= n;
    }
    dm_lie_exp(G, eta, E);
    dm_lie_compose(G, k, E, k);
    m->iters++;
    if (dm_newton_done(&t, dm_conn__norm(eta, dim), m->tol)) {
      if (pd)
        return DM_OK;
      saddle = 1;
      break;
    }
  }
  dm_num_format_vec(p0, sizeof p0, q0, m->nq);
  dm_num_format_vec(p1, sizeof p1, q1, m->nq);
  if (saddle)
    return dm_err_set(e, DM_ENOCONV, "discrete mechanical connection: Newton ended on a saddle "
                      "of k -> Ld(q0, k q1), not the extremum the diagonal continues (the pair is "
                      "too far from the diagonal), at q0 = %s, q1 = %s", p0, p1);
  return dm_err_set(e, DM_ENOCONV, "discrete mechanical connection: Newton did not converge in "
                    "%d iterations (residual %.3g, tolerance %.3g) at q0 = %s, q1 = %s",
                    m->maxit, res, m->tol, p0, p1);
}

int dm_conn_midpoint_ld(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *q0,
                        const dm_expr *q1, const dm_expr *xs, const dm_expr *xd,
                        const dm_expr *xi, dm_expr l, double h, dm_expr *Ld, dm_err *e)
{
  const dm_lie_group *G;
  size_t nx, dim, i;
  dm_expr from[2 * DM_CONN_NX_MAX + DM_LIE_DIM_MAX], to[2 * DM_CONN_NX_MAX + DM_LIE_DIM_MAX],
          gi[DM_LIE_NQ_MAX], F[DM_LIE_NQ_MAX], w[DM_LIE_DIM_MAX], hh, half;
  int st;
  if (B == NULL || !dm_conn_bundle_is_trivial(B))
    return dm_err_set(e, DM_EUNSUP, "midpoint discrete Lagrangian: needs a trivial bundle S x G");
  if (!(h > 0.0))
    return dm_err_set(e, DM_EINVAL, "midpoint discrete Lagrangian: h must be > 0, got %g", h);
  G = B->G;
  nx = B->nx;
  dim = G->dim;
  if ((st = dm_lie_sym_inverse(ctx, G, q0 + nx, gi, e)) != DM_OK ||
      (st = dm_lie_sym_compose(ctx, G, gi, q1 + nx, F, e)) != DM_OK ||
      (st = dm_lie_sym_log(ctx, G, F, w, e)) != DM_OK)
    return st;
  hh = dm_expr_const(ctx, h);
  half = dm_expr_const(ctx, 0.5);
  for (i = 0; i < nx; i++) {
    from[i] = xs[i];
    to[i] = dm_expr_mul(ctx, half, dm_expr_add(ctx, q0[i], q1[i]));
    from[nx + i] = xd[i];
    to[nx + i] = dm_expr_div(ctx, dm_expr_sub(ctx, q1[i], q0[i]), hh);
  }
  for (i = 0; i < dim; i++) {
    from[2 * nx + i] = xi[i];
    to[2 * nx + i] = dm_expr_div(ctx, w[i], hh);
  }
  if ((st = dm_expr_subs(ctx, 1, &l, Ld, 2 * nx + dim, from, to, e)) != DM_OK)
    return st;
  *Ld = dm_expr_mul(ctx, hh, *Ld);
  if (*Ld == DM_EXPR_NONE)
    return dm_err_set(e, DM_ENOMEM, "midpoint discrete Lagrangian: %s", dm_expr_ctx_err(ctx)->msg);
  return DM_OK;
}
