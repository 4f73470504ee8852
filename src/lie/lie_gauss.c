/* lie_gauss.c -- the natural-chart Galerkin Lie group variational
 * integrator (lie:gauss, lie:gauss:cayley).
 *
 * On [t_k, t_k + h] the curve is g(tau) = g_k chi(xi(tau)), xi(tau) =
 * sum_nu X^nu l_nu(tau), a polynomial of degree s through X^0 = 0 at the
 * control times d_nu = nu/s (chi = exp or the Cayley map); its body
 * velocity is eta = dchi^L_xi (xi'), dchi^L the left-trivialized chart
 * derivative (not xi' itself, a slip of the thesis for s >= 2).  The
 * action S = h sum_i b_i L(g(c_i), eta(c_i)) with the s Gauss nodes.  With
 * forces F_i at the nodes (Lagrange-d'Alembert) the step equations in the
 * unknowns X = (X^1..X^s) are (doc/lie.md):
 *   dS/dX^nu + sum_i h b_i l_nu(c_i) dchi^L_(xi_i)^T F_i = 0   (nu < s)
 *   A - dchi^R_f^T (mu_k + Q) = 0,   A = dS/dX^s + (the same force term)
 *   Q = (d/de) S(g_k exp(e e_k)) + sum_i h b_i Ad_(chi_i^-1)^T F_i
 * and then g_k+1 = g_k chi(f), f = X^s, mu_k+1 = Ad*_chi(f) (mu_k + Q).
 * The residual, its Jacobian in X and mu_k+1 are one compiled program of
 * (g_k, X, mu_k, h), derived exactly by the expression engine from L (and
 * F) traced with symbolic group elements.  On a reduced system g_k is the
 * identity (L is invariant) and Q holds the forces only.  Newton with the
 * exact Jacobian and the small dense LU; the previous step's X as the
 * predictor.  A step never allocates. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "lie/lie_integ_impl.h"
#include "core/newton.h"
#include "core/smalllu.h"
#include "core/tableau.h"
#include "core/vecmath.h"

/* {==== the step program ================================================= */

/* Lagrange basis of the nodes nu/s (nu = 0..s) and its derivative at t */
static void lagrange(size_t s, double t, double *l, double *dl)
{
  size_t nu, m, j;
  for (nu = 0; nu <= s; nu++) {
    double dn = (double)nu / (double)s, p = 1.0, dp = 0.0;
    for (m = 0; m <= s; m++) {
      double dm = (double)m / (double)s;
      if (m == nu)
        continue;
      /* d/dt of the product by the product rule */
      {
        double q = 1.0 / (dn - dm), term = q;
        for (j = 0; j <= s; j++) {
          double dj = (double)j / (double)s;
          if (j != nu && j != m)
            term *= (t - dj) / (dn - dj);
        }
        dp += term;
      }
      p *= (t - dm) / (dn - dm);
    }
    l[nu] = p;
    dl[nu] = dp;
  }
}

typedef struct pb {
  dm_lie_system *S;
  dm_expr_ctx *c;
  size_t s, n, nq, nx;
  int cayley;
  dm_expr *X, *mu, h;           /* symbols */
  dm_expr *R, *Jm, *mu1;        /* outputs */
} pb;

#define K(x) dm_expr_const(b->c, (x))
#define ADD(x, y) dm_expr_add(b->c, (x), (y))
#define MUL(x, y) dm_expr_mul(b->c, (x), (y))
#define SUB(x, y) dm_expr_sub(b->c, (x), (y))

/* dchi (inv 0) of the chart at x, trivialized on side, into M (n x n) */
static int dchart(pb *b, const dm_expr *x, int side, dm_expr *M, dm_err *e)
{
  if (b->cayley)
    return dm_lie_sym_dcay(b->c, b->S->G, x, side, M, e);
  return dm_lie_sym_dexp(b->c, b->S->G, x, side, M, e);
}

static int chart(pb *b, const dm_expr *x, dm_expr *g, dm_err *e)
{
  if (b->cayley)
    return dm_lie_sym_cay(b->c, b->S->G, x, g, e);
  return dm_lie_sym_exp(b->c, b->S->G, x, g, e);
}

static int build_step(pb *b, dm_err *e)
{
  dm_lie_system *S = b->S;
  const dm_lie_group *G = S->G;
  const size_t s = b->s, n = b->n, nq = b->nq, nx = b->nx;
  dm_tableau *tab = NULL;
  dm_expr gk[DM_LIE_NQ_MAX], xi_i[DM_LIE_DIM_MAX], dxi[DM_LIE_DIM_MAX], chi[DM_LIE_NQ_MAX];
  dm_expr gi[DM_LIE_NQ_MAX], eta[DM_LIE_DIM_MAX], Mi[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];
  dm_expr from[DM_LIE_NQ_MAX + DM_LIE_DIM_MAX], to[DM_LIE_NQ_MAX + DM_LIE_DIM_MAX];
  dm_expr Fi[DM_LIE_DIM_MAX], tmp[DM_LIE_DIM_MAX], Q[DM_LIE_DIM_MAX], Li, Sx, invc[DM_LIE_NQ_MAX];
  dm_expr *fterm = calloc(nx + 1, sizeof *fterm), *gradX = calloc(nx + 1, sizeof *gradX);
  dm_expr gradg[DM_LIE_NQ_MAX], Fq[DM_LIE_DIM_MAX];
  double l[DM_TABLEAU_SMAX + 2], dl[DM_TABLEAU_SMAX + 2];
  size_t i, nu, a;
  int st = DM_OK;
  if (fterm == NULL || gradX == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "lie:gauss: out of memory");
    goto done;
  }
  if ((st = dm_tableau_gauss(s, &tab, e)) != DM_OK)
    goto done;
  if (S->reduced)
    st = dm_lie_sym_identity(b->c, G, gk, e);
  else
    memcpy(gk, S->g, nq * sizeof *gk);
  for (a = 0; a <= nx; a++)
    fterm[a] = K(0.0);
  for (a = 0; a < n; a++)
    Fq[a] = K(0.0);
  memcpy(from, S->g, nq * sizeof *from);
  memcpy(from + nq, S->xi, n * sizeof *from);
  Sx = K(0.0);
  for (i = 0; i < s && st == DM_OK; i++) {
    dm_expr hb = MUL(b->h, K(tab->b[i]));
    lagrange(s, tab->c[i], l, dl);
    for (a = 0; a < n; a++) {
      dm_expr x = K(0.0), v = K(0.0);
      for (nu = 1; nu <= s; nu++) {
        x = ADD(x, MUL(K(l[nu]), b->X[(nu - 1) * n + a]));
        v = ADD(v, MUL(K(dl[nu]), b->X[(nu - 1) * n + a]));
      }
      xi_i[a] = x;
      dxi[a] = dm_expr_div(b->c, v, b->h);
    }
    if ((st = chart(b, xi_i, chi, e)) != DM_OK ||
        (st = dm_lie_sym_compose(b->c, G, gk, chi, gi, e)) != DM_OK ||
        (st = dchart(b, xi_i, DM_LIE_LEFT, Mi, e)) != DM_OK ||
        (st = dm_lie_sym_matvec(b->c, n, Mi, 0, dxi, eta, e)) != DM_OK)
      break;
    memcpy(to, gi, nq * sizeof *to);
    memcpy(to + nq, eta, n * sizeof *to);
    if ((st = dm_expr_subs(b->c, 1, &S->L, &Li, nq + n, from, to, e)) != DM_OK)
      break;
    Sx = ADD(Sx, MUL(hb, Li));
    if (S->force != NULL) {
      if ((st = dm_expr_subs(b->c, n, S->force, Fi, nq + n, from, to, e)) != DM_OK)
        break;
      /* sum_i h b_i l_nu(c_i) dchi^L(xi_i)^T F_i, and Ad_(chi^-1)^T F_i */
      if ((st = dm_lie_sym_matvec(b->c, n, Mi, 1, Fi, tmp, e)) != DM_OK)
        break;
      for (nu = 1; nu <= s; nu++)
        for (a = 0; a < n; a++)
          fterm[(nu - 1) * n + a] = ADD(fterm[(nu - 1) * n + a], MUL(MUL(hb, K(l[nu])), tmp[a]));
      if ((st = dm_lie_sym_inverse(b->c, G, chi, invc, e)) != DM_OK ||
          (st = dm_lie_sym_Ad(b->c, G, invc, Mi, e)) != DM_OK ||
          (st = dm_lie_sym_matvec(b->c, n, Mi, 1, Fi, tmp, e)) != DM_OK)
        break;
      for (a = 0; a < n; a++)
        Fq[a] = ADD(Fq[a], MUL(hb, tmp[a]));
    }
  }
  if (st != DM_OK)
    goto done;
  if ((st = dm_expr_grad(b->c, Sx, nx, b->X, gradX, e)) != DM_OK)
    goto done;
  /* Q = the trivialized derivative of S in g_k, plus the forces' part */
  if (!S->reduced) {
    if ((st = dm_expr_grad(b->c, Sx, nq, S->g, gradg, e)) != DM_OK ||
        (st = dm_lie_sym_trivialize(b->c, G, S->g, gradg, DM_LIE_LEFT, Q, e)) != DM_OK)
      goto done;
  } else {
    for (a = 0; a < n; a++)
      Q[a] = K(0.0);
  }
  for (a = 0; a < n; a++)
    Q[a] = ADD(ADD(Q[a], Fq[a]), b->mu[a]);          /* mu_k + Q */
  for (a = 0; a < nx; a++)
    b->R[a] = ADD(gradX[a], fterm[a]);
  /* the last block: A - dchi^R_f^T (mu + Q) */
  {
    const dm_expr *f = b->X + (s - 1) * n;
    if ((st = dchart(b, f, DM_LIE_RIGHT, Mi, e)) != DM_OK ||
        (st = dm_lie_sym_matvec(b->c, n, Mi, 1, Q, tmp, e)) != DM_OK)
      goto done;
    for (a = 0; a < n; a++)
      b->R[(s - 1) * n + a] = SUB(b->R[(s - 1) * n + a], tmp[a]);
    if ((st = chart(b, f, chi, e)) != DM_OK || (st = dm_lie_sym_Ad(b->c, G, chi, Mi, e)) != DM_OK ||
        (st = dm_lie_sym_matvec(b->c, n, Mi, 1, Q, b->mu1, e)) != DM_OK)
      goto done;
  }
  /* J = the Hessian of S (the engine picks forward or reverse, whichever
   * is smaller) + the Jacobian of the rest of R */
  {
    dm_expr *T = calloc(nx + 1, sizeof *T), *JT = calloc(nx * nx + 1, sizeof *JT);
    if (T == NULL || JT == NULL) {
      free(T);
      free(JT);
      st = dm_err_set(e, DM_ENOMEM, "lie:gauss: out of memory");
      goto done;
    }
    for (a = 0; a < nx; a++)
      T[a] = SUB(b->R[a], gradX[a]);
    st = dm_expr_hessian(b->c, Sx, nx, b->X, b->Jm, e);
    if (st == DM_OK)
      st = dm_expr_jacobian(b->c, nx, T, nx, b->X, JT, e);
    for (a = 0; st == DM_OK && a < nx * nx; a++)
      b->Jm[a] = ADD(b->Jm[a], JT[a]);
    free(T);
    free(JT);
  }
done:
  dm_tableau_free(tab);
  free(fterm);
  free(gradX);
  if (st == DM_OK && dm_expr_ctx_err(b->c)->status != DM_OK) {
    st = dm_err_set(e, dm_expr_ctx_err(b->c)->status, "lie:gauss: %s",
                    dm_expr_ctx_err(b->c)->msg);
    dm_expr_ctx_clear_err(b->c);
  }
  return st;
}

#undef K
#undef ADD
#undef MUL
#undef SUB

int dm_lie_gauss_program(dm_lie_system *S, size_t s, int cayley, const dm_lie_gauss_prog **out,
                         dm_err *e)
{
  pb b;
  dm_lie_gauss_prog *gp;
  dm_expr *buf, *in;
  size_t i, n = S->dim, nq = S->nq, nx = s * n, nout, nin;
  char name[64];
  int st;
  for (i = 0; i < S->ngauss; i++)
    if (S->gauss[i].s == s && S->gauss[i].cayley == cayley) {
      *out = &S->gauss[i];
      return DM_OK;
    }
  nout = nx + nx * nx + n;
  nin = nq + nx + n + 1;
  memset(&b, 0, sizeof b);
  b.S = S;
  b.c = S->ctx;
  b.s = s;
  b.n = n;
  b.nq = nq;
  b.nx = nx;
  b.cayley = cayley;
  buf = calloc(nout + nin, sizeof *buf);
  gp = realloc(S->gauss, (S->ngauss + 1) * sizeof *S->gauss);
  if (buf == NULL || gp == NULL) {
    free(buf);
    if (gp)
      S->gauss = gp;
    return dm_err_set(e, DM_ENOMEM, "lie:gauss: out of memory");
  }
  S->gauss = gp;
  in = buf + nout;
  memcpy(in, S->g, nq * sizeof *in);
  b.X = in + nq;
  b.mu = b.X + nx;
  for (i = 0; i < nx; i++) {
    snprintf(name, sizeof name, "lie:gauss:X%zu", i + 1);
    b.X[i] = dm_expr_sym(S->ctx, name);
  }
  for (i = 0; i < n; i++) {
    snprintf(name, sizeof name, "lie:gauss:mu%zu", i + 1);
    b.mu[i] = dm_expr_sym(S->ctx, name);
  }
  b.h = in[nin - 1] = dm_expr_sym(S->ctx, "lie:gauss:h");
  b.R = buf;                    /* the residual program: R, mu1 */
  b.mu1 = buf + nx;
  b.Jm = buf + nx + n;          /* the Jacobian program */
  if ((st = build_step(&b, e)) == DM_OK) {
    gp = &S->gauss[S->ngauss];
    memset(gp, 0, sizeof *gp);
    gp->s = s;
    gp->cayley = cayley;
    st = dm_lie_compile_bundle(S, &gp->res, nx + n, buf, nin, in, e);
    if (st == DM_OK)
      st = dm_lie_compile_bundle(S, &gp->jac, nx * nx, b.Jm, nin, in, e);
    if (st == DM_OK) {
      dm_lie_system_grow_work(S, &gp->res);
      dm_lie_system_grow_work(S, &gp->jac);
      S->ngauss++;
      *out = gp;
    } else {
      dm_bundle_free(&gp->res);
      dm_bundle_free(&gp->jac);
    }
  }
  free(buf);
  return st;
}

/* }====================================================================== */

/* {==== the integrator =================================================== */

typedef struct lgs {
  dm_lie_system *S;
  const dm_lie_gauss_prog *P;
  size_t s, n, nq, nx, nin;
  int cayley, warm, have_jac;
  double hprev, hjac;
  double *X, *Xprev, *R, *A, *work, *xi0;
  size_t *perm;
} lgs;

static const char *const gauss_options[] = {"stages", "h", "tol", "maxiter", "simplified", NULL};
static const char *const gauss_names[] = {"lie:gauss:cayley", NULL};

static void gauss_free(dm_integrator *I)
{
  lgs *W = I->state;
  if (W) {
    free(W->X);
    free(W->work);
    free(W->perm);
    free(W);
  }
  I->state = NULL;
}

static int gauss_alloc(dm_integrator *I, dm_err *e)
{
  dm_lie_system *S = (dm_lie_system *)dm_lie_system_of(I->sys);
  lgs *W;
  int st;
  size_t s, nw;
  if (S == NULL)
    return dm_err_set(e, DM_EINVAL, "lie:gauss: needs a system on a Lie group");
  if (I->opt.stages < 0 || I->opt.stages > 8)
    return dm_err_set(e, DM_EINVAL, "lie:gauss: stages = %d out of range 1..8", I->opt.stages);
  s = I->opt.stages ? (size_t)I->opt.stages : 2;
  if ((W = calloc(1, sizeof *W)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "lie:gauss: out of memory");
  I->state = W;
  W->S = S;
  W->s = s;
  W->n = S->dim;
  W->nq = S->nq;
  W->nx = s * S->dim;
  W->cayley = strcmp(I->name, "lie:gauss:cayley") == 0;
  if ((st = dm_lie_gauss_program(S, s, W->cayley, &W->P, e)) != DM_OK) {
    gauss_free(I);
    return st;
  }
  W->nin = W->nq + W->nx + W->n + 1;
  nw = W->P->res.nregs + W->P->res.nout;
  if (W->P->jac.nregs + W->P->jac.nout > nw)
    nw = W->P->jac.nregs + W->P->jac.nout;
  W->X = calloc(3 * W->nx + W->nx * W->nx + W->n + 2, sizeof *W->X);
  W->work = calloc(nw + W->nin + 8, sizeof *W->work);
  W->perm = calloc(W->nx + 1, sizeof *W->perm);
  if (W->X == NULL || W->work == NULL || W->perm == NULL) {
    gauss_free(I);
    return dm_err_set(e, DM_ENOMEM, "lie:gauss: out of memory");
  }
  W->Xprev = W->X + W->nx;
  W->R = W->Xprev + W->nx;
  W->A = W->R + W->nx;
  W->xi0 = W->A + W->nx * W->nx;
  I->order = (int)(2 * s);
  I->stages = (int)s;
  /* symmetric only for s = 1 in the exp chart (the curve g_k exp(tau f) is
   * the one-parameter subgroup through both ends) */
  if (s != 1 || W->cayley)
    I->flags &= ~(unsigned)DM_INTEG_SYMMETRIC;
  return DM_OK;
}

static void gauss_reset(dm_integrator *I)
{
  lgs *W = I->state;
  W->warm = 0;
  W->have_jac = 0;
}

/* the predictor: the previous step's X for the same h, else xi(tau) =
 * tau h xi_k with xi_k from the Legendre map */
static int predict(dm_integrator *I, lgs *W, double h, const double *g0, const double *mu0,
                   dm_err *e)
{
  size_t nu, a;
  int st;
  if (W->warm && h == W->hprev) {
    memcpy(W->X, W->Xprev, W->nx * sizeof *W->X);
    return DM_OK;
  }
  if ((st = dm_integrator_velocity(I, g0, mu0, W->xi0, 0, e)) != DM_OK)
    return st;
  for (nu = 1; nu <= W->s; nu++)
    for (a = 0; a < W->n; a++)
      W->X[(nu - 1) * W->n + a] = h * (double)nu / (double)W->s * W->xi0[a];
  return DM_OK;
}

/* run program p at (g0, X, mu0, h); 1 when an output is NaN or Inf */
static int run_prog(lgs *W, const dm_bundle *p, double h, const double *g0, const double *mu0,
                    double **o)
{
  double *w = W->work, bad = 0.0;
  size_t i;
  memcpy(w, g0, W->nq * sizeof *w);
  memcpy(w + W->nq, W->X, W->nx * sizeof *w);
  memcpy(w + W->nq + W->nx, mu0, W->n * sizeof *w);
  w[W->nq + W->nx + W->n] = h;
  *o = dm_bundle_run_plain(p, w, W->S->parv);
  for (i = 0; i < p->nout; i++)
    bad += 0.0 * (*o)[i];
  return bad != 0.0 || bad != bad;
}

/* Newton with the exact Jacobian; with `simplified` the factored Jacobian
 * is kept across iterations and steps (same h) while the updates contract
 * tenfold, and recomputed at the current X when they do not */
static int gauss_step(dm_integrator *I, double h, const double *q0, const double *p0,
                      double *q1, double *p1, dm_err *e)
{
  lgs *W = I->state;
  const dm_lie_group *G = W->S->G;
  const size_t nx = W->nx, n = W->n;
  double *o = NULL, d = HUGE_VAL, dprev = HUGE_VAL, chi[DM_LIE_NQ_MAX];
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  size_t i;
  int st, it, fresh = 0, jacs = 0, conv = 0;
  if ((st = predict(I, W, h, q0, p0, e)) != DM_OK)
    return st;
  if (!I->opt.simplified || W->hjac != h)
    W->have_jac = 0;
  for (it = 0; it < I->opt.maxiter; it++) {
    double xs;
    if (!W->have_jac) {
      if (run_prog(W, &W->P->jac, h, q0, p0, &o))
        return dm_err_set(e, DM_EDOM, "lie:gauss: the Jacobian of the step equations is not "
                          "finite (NaN or Inf; h = %.6g)", h);
      memcpy(W->A, o, nx * nx * sizeof *W->A);
      if (dm_smalllu_factor(W->A, nx, W->perm) != DM_OK)
        return dm_err_set(e, DM_ESINGULAR, "lie:gauss: singular Jacobian of the step equations "
                          "(a singular kinetic energy, or a step past the chart's range)");
      W->have_jac = 1;
      W->hjac = h;
      fresh = 1;
      jacs++;
    }
    if (run_prog(W, &W->P->res, h, q0, p0, &o))
      return dm_err_set(e, DM_EDOM, "lie:gauss: the step equations are not finite (NaN or Inf) "
                        "at Newton iteration %d (h = %.6g)", it + 1, h);
    memcpy(W->R, o, nx * sizeof *W->R);
    dm_smalllu_solve(W->A, nx, W->perm, W->R);
    for (i = 0; i < nx; i++)
      W->X[i] -= W->R[i];
    xs = dm_norm_inf(W->X, nx);
    d = dm_norm_inf(W->R, nx) / (xs > 0.0 ? xs : 1.0);
    if (!(d == d))
      break;
    if (dm_newton_done(&stop, d, I->opt.tol)) {
      conv = 1;
      break;
    }
    if (!I->opt.simplified || (!fresh && d > 0.1 * dprev) || (fresh && it > 0 && d > 0.5 * dprev))
      W->have_jac = 0;
    fresh = 0;
    dprev = d;
  }
  I->stats.iters = it + 1;
  I->stats.jacs = jacs;
  I->stats.residual = d;
  I->stats.tol = I->opt.tol;
  if (!conv)
    return dm_err_set(e, DM_ENOCONV, "lie:gauss: Newton did not converge in %d iterations "
                      "(relative update %.3g, tol %.3g)", it, d, I->opt.tol);
  /* mu_k+1 at the converged X */
  if (run_prog(W, &W->P->res, h, q0, p0, &o))
    return dm_err_set(e, DM_EDOM, "lie:gauss: mu_k+1 is not finite (h = %.6g)", h);
  memcpy(p1, o + nx, n * sizeof *p1);
  if (W->cayley)
    dm_lie_cay(G, W->X + nx - n, chi);
  else
    dm_lie_exp(G, W->X + nx - n, chi);
  dm_lie_compose(G, q0, chi, q1);
  memcpy(W->Xprev, W->X, nx * sizeof *W->X);
  W->warm = 1;
  W->hprev = h;
  I->stats.steps++;
  I->stats.iters_total += it + 1;
  return DM_OK;
}

/* }====================================================================== */

static const char *const lie_kinds[] = {DM_SYSTEM_LIE, NULL};

const dm_integrator_type dm_lie_integ_gauss = {
  .name = "lie:gauss",
  .summary = "natural-chart Galerkin Lie group variational integrator (exp chart; "
             "lie:gauss:cayley the Cayley chart), s Gauss stages, order 2s",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_VARIATIONAL | DM_INTEG_FORCES,
  .options = gauss_options,
  .alloc = gauss_alloc,
  .step = gauss_step,
  .reset = gauss_reset,
  .free = gauss_free,
  .kinds = lie_kinds,
  .names = gauss_names,
};

int dm_lie_register_integrators(dm_err *e)
{
  int st = dm_integrator_register(&dm_lie_integ_lgvi, e);
  if (st == DM_OK)
    st = dm_integrator_register(&dm_lie_integ_gauss, e);
  if (st == DM_OK)
    st = dm_integrator_register(&dm_lie_integ_gsl, e);
  if (st == DM_OK)
    st = dm_integrator_register(&dm_sphere_integ_lgvi, e);
  return st;
}
