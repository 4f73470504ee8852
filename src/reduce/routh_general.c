/* routh_general.c -- Routh reduction of a Lagrangian that is not mechanical
 * (not quadratic in the velocities, or with terms linear in them).  There
 * is no locked inertia or mechanical connection to write down; what
 * remains (thesis §2.2, the Routhian on J^{-1}(mu)) is computed
 * numerically:
 *   thetadot(x, xdot) = u solving J(x, u, xdot) = dL/dthetadot = mu
 *     (Newton with d2L/dthetadot2, the generalised locked inertia; steps
 *     halved while L is outside its domain),
 *   Rc(x, xdot) = L(x, u, xdot) - mu . u            (classical Routhian),
 *   dRc/dx = L_x,  dRc/dxdot = L_xdot                (envelope: L_u = mu),
 * and its second derivatives are Schur complements of the Hessian of L in
 * (x, u, xdot) eliminating u (du/dxdot = -L_uu^{-1} L_uxdot, du/dx =
 * -L_uu^{-1} L_ux):
 *   Rc_vv = L_vv - L_vu L_uu^{-1} L_uv,   Rc_vx = L_vx - L_vu L_uu^{-1} L_ux,
 *   Rc_xx = L_xx - L_xu L_uu^{-1} L_ux   (v = xdot).
 * So the classical Routhian is an ordinary dm_system with exact
 * derivatives, and the classical-Routhian methods, the discrete Routh
 * equations (Galerkin L_d of the full system, psi_mu by Newton) and the
 * reconstruction work unchanged; its Euler-Lagrange equations are the
 * Routh equations.  The reduced state is (x, p_x), p_x = dRc/dxdot: without
 * a connection there is no momentum shift. */
#include <config.h>
#include "reduce/routh_impl.h"
#include "core/smalllu.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* work layout (doubles) of the classical-Routhian callback, then the full
 * system's own work */
typedef struct gwork {
  double *q, *v, *Lq, *Lv, *Lvv, *Lvq, *Lqq, *J, *f, *u0, *Y;
  void *fwork;
} gwork;

static size_t gwork_doubles(const dm_routh *red)
{
  size_t n = red->n, r = red->r, s = red->s;
  return 4 * n + 3 * n * n + r * r + 2 * r + 2 * r * s + 8;
}

static gwork carve(const dm_routh *red, void *work)
{
  size_t n = red->n, r = red->r, s = red->s;
  gwork W;
  W.q = work;
  W.v = W.q + n;
  W.Lq = W.v + n;
  W.Lv = W.Lq + n;
  W.Lvv = W.Lv + n;
  W.Lvq = W.Lvv + n * n;
  W.Lqq = W.Lvq + n * n;
  W.J = W.Lqq + n * n;
  W.f = W.J + r * r;
  W.u0 = W.f + r;
  W.Y = W.u0 + r;
  W.fwork = (double *)work + gwork_doubles(red);
  (void)s;
  return W;
}

static int full_eval(const dm_routh *red, gwork *W, const double *par, unsigned what, double *L)
{
  dm_lag_out o = {0, W->Lq, W->Lv, W->Lvv, W->Lvq, W->Lqq};
  int st = red->fsys.lagrangian(red->fsys.data, W->q, W->v, par, what, &o, W->fwork);
  if (st == 0 && L)
    *L = o.L;
  return st;
}

/* f = J(x, u, xdot) - mu and the finite test of f and the Jacobian */
static int residual(const dm_routh *red, gwork *W, const double *mu)
{
  size_t n = red->n, r = red->r, a, b;
  int ok = 1;
  for (a = 0; a < r; a++) {
    W->f[a] = W->Lv[red->cyc[a]] - mu[a];
    ok &= isfinite(W->f[a]);
    for (b = 0; b < r; b++) {
      W->J[a * r + b] = W->Lvv[red->cyc[a] * n + red->cyc[b]];
      ok &= isfinite(W->J[a * r + b]);
    }
  }
  return ok;
}

/* Solve J(x, u, xdot) = mu for u, leaving W->q, W->v at the solution
 * (theta = 0) and Lv, Lvv evaluated there.  0 on success, 1 (recoverable:
 * outside the domain, singular, no convergence) otherwise. */
static int solve_u(const dm_routh *red, const double *x, const double *xd, const double *par,
                   gwork *W)
{
  const double *mu = par + red->npar;
  size_t r = red->r, a;
  size_t perm[DM_ROUTH_RMAX];
  double du[DM_ROUTH_RMAX], ucur[DM_ROUTH_RMAX] = {0};
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it;
  dm_routh_join(red, NULL, x, W->q);
  dm_routh_join(red, ucur, xd, W->v);
  if (full_eval(red, W, par, DM_LAG_V | DM_LAG_VV, NULL) != 0 || !residual(red, W, mu))
    return 1;
  for (it = 0; it < 100; it++) {
    double lam = 1.0, dn, un = 0.0;
    int k, ok = 0;
    if (dm_smalllu_factor(W->J, r, perm) != DM_OK)
      return 1;
    memcpy(du, W->f, r * sizeof(double));
    dm_smalllu_solve(W->J, r, perm, du);
    for (k = 0; k < 60 && !ok; k++, lam *= 0.5) {     /* halve while outside the domain */
      for (a = 0; a < r; a++)
        W->v[red->cyc[a]] = ucur[a] - lam * du[a];
      ok = full_eval(red, W, par, DM_LAG_V | DM_LAG_VV, NULL) == 0 && residual(red, W, mu);
    }
    if (!ok)
      return 1;
    lam *= 2.0;
    for (a = 0; a < r; a++) {
      ucur[a] = W->v[red->cyc[a]];
      un = fmax(un, fabs(ucur[a]));
    }
    dn = lam * dm_rnorm_inf(du, r) / fmax(un, DBL_MIN);
    if (dm_rnorm_inf(W->f, r) == 0.0 || (lam == 1.0 && dm_newton_done(&stop, dn, 10 * DBL_EPSILON)))
      return 0;
  }
  return 1;
}

/* The classical Routhian as a dm_system callback (data = the dm_routh). */
static int rc_lagrangian(void *data, const double *x, const double *xd, const double *par,
                         unsigned what, dm_lag_out *out, void *work)
{
  const dm_routh *red = data;
  const double *mu = par + red->npar;
  size_t n = red->n, r = red->r, s = red->s, a, i, j;
  size_t perm[DM_ROUTH_RMAX];
  gwork W = carve(red, work);
  unsigned need = DM_LAG_GRAD;
  int second = (what & (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ)) != 0;
  double L;
  if (solve_u(red, x, xd, par, &W) != 0)
    return 1;
  if (second)
    need |= DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ;
  if (full_eval(red, &W, par, need, &L) != 0)
    return 1;
  if (what & DM_LAG_L) {
    double acc = L;
    for (a = 0; a < r; a++)
      acc -= mu[a] * W.v[red->cyc[a]];
    out->L = acc;
  }
  for (i = 0; i < s; i++) {
    if (what & DM_LAG_Q)
      out->Lq[i] = W.Lq[red->shape[i]];
    if (what & DM_LAG_V)
      out->Lv[i] = W.Lv[red->shape[i]];
  }
  if (!second)
    return 0;
  /* Y = L_uu^{-1} [L_u xdot | L_u x]  (r x 2s) */
  for (a = 0; a < r; a++)
    for (i = 0; i < r; i++)
      W.J[a * r + i] = W.Lvv[red->cyc[a] * n + red->cyc[i]];
  if (dm_smalllu_factor(W.J, r, perm) != DM_OK)
    return 1;
  for (j = 0; j < 2 * s; j++) {
    for (a = 0; a < r; a++)
      W.f[a] = j < s ? W.Lvv[red->cyc[a] * n + red->shape[j]]
                     : W.Lvq[red->cyc[a] * n + red->shape[j - s]];
    dm_smalllu_solve(W.J, r, perm, W.f);
    for (a = 0; a < r; a++)
      W.Y[a * 2 * s + j] = W.f[a];
  }
  for (i = 0; i < s; i++)
    for (j = 0; j < s; j++) {
      size_t xi = red->shape[i], xj = red->shape[j];
      double vv = W.Lvv[xi * n + xj], vq = W.Lvq[xi * n + xj], qq = W.Lqq[xi * n + xj];
      for (a = 0; a < r; a++) {
        size_t c = red->cyc[a];
        vv -= W.Lvv[xi * n + c] * W.Y[a * 2 * s + j];
        vq -= W.Lvv[xi * n + c] * W.Y[a * 2 * s + s + j];
        qq -= W.Lvq[c * n + xi] * W.Y[a * 2 * s + s + j];
      }
      if (what & DM_LAG_VV)
        out->Lvv[i * s + j] = vv;
      if (what & DM_LAG_VQ)
        out->Lvq[i * s + j] = vq;
      if (what & DM_LAG_QQ)
        out->Lqq[i * s + j] = qq;
    }
  return 0;
}

size_t dm_routh_general_work(const dm_routh *red)
{
  return gwork_doubles(red) * sizeof(double) + red->fsys.work_size;
}

int dm_routh_general_thetadot(const dm_routh *red, const double *x, const double *xd,
                              const double *par, double *u, void *work)
{
  gwork W = carve(red, work);
  size_t a;
  if (solve_u(red, x, xd, par, &W) != 0)
    return 1;
  for (a = 0; a < red->r; a++)
    u[a] = W.v[red->cyc[a]];
  return 0;
}

int dm_routh_general_setup(dm_routh *red, dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_err *e)
{
  size_t s = red->s;
  int st = dm_routh_compile_full(ctx, sp, &red->fsys, e);
  char *cname;
  if (st != DM_OK)
    return st;
  red->fpar_own = red->fsys.par;
  red->fsys.par = red->par;
  cname = malloc(strlen(red->name) + 32);
  if (cname == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  sprintf(cname, "%s (classical Routhian)", red->name);
  red->cname = cname;
  memset(&red->csys, 0, sizeof red->csys);
  red->csys.name = cname;
  red->csys.n = s;
  red->csys.npar = red->np;
  red->csys.coords = (const char *const *)red->names;
  red->csys.params = (const char *const *)red->names + s;
  red->csys.par = red->par;
  red->csys.lagrangian = rc_lagrangian;
  red->csys.data = red;
  red->csys.work_size = dm_routh_general_work(red);
  red->rsys = red->csys;
  red->sys = red->csys;
  red->sys.name = red->name;
  red->sys.lagrangian = dm_routh_lag_forward;
  red->sys.refresh = dm_routh_sys_refresh;
  red->nscratch = 8 * red->n + 4 * red->n * red->n + red->np + 8 * s
                  + dm_routh_general_work(red) / sizeof(double) + 1;
  red->scratch = calloc(red->nscratch, sizeof(double));
  red->lscratch = calloc(4 * s + 2 * s * s + dm_routh_general_work(red) / sizeof(double) + 1,
                         sizeof(double));
  if (red->scratch == NULL || red->lscratch == NULL || dm_rlu_init(&red->lu_s, s) != DM_OK)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  return DM_OK;
}

/* xdot with dRc/dxdot (x, xdot) = p_x, by Newton with Rc_vv from the
 * previous velocity (0 first). */
int dm_routh_general_velocity(dm_routh *red, const double *x, const double *px, double *xd,
                              dm_err *e)
{
  size_t d = red->s, i;
  double *Lv = red->lscratch, *dx = Lv + d, *M = dx + 2 * d, *w = M + 2 * d * d;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it;
  memset(xd, 0, d * sizeof(double));
  for (it = 0; it < 100; it++) {
    dm_lag_out o = {0, NULL, Lv, M, NULL, NULL};
    double dn;
    if (rc_lagrangian(red, x, xd, red->par, DM_LAG_V | DM_LAG_VV, &o, w) != 0)
      return dm_err_set(e, DM_EDOM, "the classical Routhian is not defined at this state (J = mu "
                        "has no solution thetadot near it, or L is outside its domain)");
    for (i = 0; i < d; i++)
      dx[i] = Lv[i] - px[i];
    if (dm_rlu_factor(&red->lu_s, M, d) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "d2Rc/dxdot2 is singular at this state");
    dm_rlu_solve(&red->lu_s, M, d, dx);
    for (i = 0; i < d; i++)
      xd[i] -= dx[i];
    dn = dm_rnorm_inf(dx, d) / fmax(dm_rnorm_inf(xd, d), DBL_MIN);
    if (!isfinite(dn))
      return dm_err_set(e, DM_EDOM, "the inverse reduced Legendre map diverged");
    if (dm_rnorm_inf(dx, d) == 0.0 || dm_newton_done(&stop, dn, 10 * DBL_EPSILON))
      return DM_OK;
  }
  return dm_err_set(e, DM_ENOCONV, "the inverse reduced Legendre map (dRc/dxdot = p) did not "
                    "converge");
}
