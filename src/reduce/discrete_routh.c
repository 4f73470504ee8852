/* discrete_routh.c -- discrete Routh reduction (thesis §2.3.2-2.3.4,
 * doc/reduce.md §6-8) for the midpoint and the Galerkin discrete Lagrangians of
 * the full system, in the additive coordinates q = (theta, x):
 *   psi_mu(x0, x1): J_d((0, x0), (psi, x1)) = mu, J_d = D2 L_d along theta;
 *     midpoint: psi = h I(xbar)^{-1} mu - A(xbar)(x1 - x0) (linear, no
 *     iteration); Galerkin: Newton on p1_theta = mu with the exact
 *     d p1_theta / d theta1 from the boundary problem (integrators/galerkin.h);
 *   Lhat(x0, x1) = L_d((0, x0), (psi, x1));
 *   D1 Lhat = dL_d/dx0 + mu . D1 psi,   D2 Lhat = dL_d/dx1 + mu . D2 psi,
 *   Ahat_1 = mu . D1 psi - muA(x0),     Ahat_2 = mu . D2 psi + muA(x1);
 *   DR: D2 Lhat(x_{k-1}, x_k) + D1 Lhat(x_k, x_{k+1}) = Ahat_2(x_{k-1}, x_k) + Ahat_1(x_k, x_{k+1}).
 * The general form is computed term by term (the mu.Dpsi and muA terms
 * cancel only in exact arithmetic; dm_routh_dr_residual returns it beside
 * the shape components of DEL).  The position-momentum form uses the
 * reduced discrete Legendre transforms F- = -D1 Lhat + Ahat_1 and
 * F+ = D2 Lhat - Ahat_2; Newton on x1 with the exact Jacobian
 * -dF-/dx1 = -(dp0_x/dx1 + dp0_x/dtheta1 D2 psi). */
#include <config.h>
#include "reduce/routh_impl.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct dm_routh_dr {
  dm_routh *red;
  const dm_system *fsys;
  dm_galerkin *g;                  /* NULL: midpoint closed form */
  size_t n, r, d;
  double tol;
  int maxiter, iters;
  double sing_ref;
  double *q0, *q1, *qb, *v, *p0, *p1, *Lq, *Lv, *Lvv, *Lvq, *Lqq;
  double *d00, *d01, *d10, *d11;
  double *psi, *Dpsi, *w, *A, *muA, *Dw, *DA, *a0, *a1;
  double *J, *res, *x1, *dx, *tin, *tout, *twork, *Ld;
  int have_prev;
  double *dxprev, *sc;             /* d, 6 d scratch */
  dm_rlu lu_d, lu_r;
  void *work, *rwork;              /* full / reduced system callbacks */
};

void dm_routh_dr_free(dm_routh_dr *dr)
{
  if (dr == NULL)
    return;
  dm_galerkin_free(dr->g);
  dm_rlu_free(&dr->lu_d);
  dm_rlu_free(&dr->lu_r);
  free(dr->q0);
  free(dr->work);
  free(dr->rwork);
  free(dr);
}

int dm_routh_dr_iters(const dm_routh_dr *dr)
{
  return dr->iters;
}

int dm_routh_dr_alloc(dm_routh *red, const dm_tableau *t, double tol, int maxiter,
                      dm_routh_dr **out, dm_err *e)
{
  dm_routh_dr *dr;
  size_t n = red->n, r = red->r, d = red->s, nn = n * n, tot, nout;
  double *p;
  int st;
  *out = NULL;
  if (red->m > 0 || red->has_force)
    return dm_err_set(e, DM_EUNSUP, "the discrete Routh equations are implemented for unforced, "
                      "unconstrained systems; use an RSPRK method (gauss, lobatto, midpoint) for "
                      "forces and constraints");
  if ((dr = calloc(1, sizeof *dr)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  dr->red = red;
  dr->fsys = &red->fsys;
  dr->n = n;
  dr->r = r;
  dr->d = d;
  dr->tol = tol > 0 ? tol : 10 * DBL_EPSILON;
  dr->maxiter = maxiter > 0 ? maxiter : 50;
  nout = red->connd.nout > red->conn.nout ? red->connd.nout : red->conn.nout;
  if (red->gyro_r.nout > nout)
    nout = red->gyro_r.nout;
  tot = 7 * n + 2 * n + 3 * nn + 4 * nn + r + 2 * r * d + r + r * d + d + r * d + r * d * d + 2 * d
        + d * d + 3 * d + 2 * d + nout + red->nwork + r * r + 8 + 1 + d + 6 * d;
  dr->q0 = calloc(tot, sizeof(double));
  dr->work = red->fsys.work_size ? malloc(red->fsys.work_size) : NULL;
  dr->rwork = malloc(red->rsys.work_size + 8);
  if (dr->q0 == NULL || (red->fsys.work_size && dr->work == NULL) || dr->rwork == NULL
      || dm_rlu_init(&dr->lu_d, d)
      || dm_rlu_init(&dr->lu_r, r)) {
    dm_routh_dr_free(dr);
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  p = dr->q0 + n;
#define TAKE(ptr, k) do { dr->ptr = p; p += (k); } while (0)
  TAKE(q1, n); TAKE(qb, n); TAKE(v, n); TAKE(p0, n); TAKE(p1, n); TAKE(Lq, n); TAKE(Lv, n);
  TAKE(Lvv, nn); TAKE(Lvq, nn); TAKE(Lqq, nn);
  TAKE(d00, nn); TAKE(d01, nn); TAKE(d10, nn); TAKE(d11, nn);
  TAKE(psi, r); TAKE(Dpsi, 2 * r * d); TAKE(w, r); TAKE(A, r * d); TAKE(muA, d);
  TAKE(Dw, r * d); TAKE(DA, r * d * d); TAKE(a0, d); TAKE(a1, d);
  TAKE(J, d * d); TAKE(res, d); TAKE(x1, d); TAKE(dx, d); TAKE(tin, 2 * d); TAKE(tout, nout);
  TAKE(twork, red->nwork + r * r + 8); TAKE(Ld, 1); TAKE(dxprev, d); TAKE(sc, 6 * d);
#undef TAKE
  if (t == NULL && red->general) {   /* no closed-form psi: midpoint = Galerkin-Gauss 1 */
    dm_tableau *g1 = NULL;
    if ((st = dm_tableau_gauss(1, &g1, e)) == DM_OK)
      st = dm_galerkin_alloc(&red->fsys, g1, dr->tol, dr->maxiter, &dr->g, e);
    dm_tableau_free(g1);
    if (st != DM_OK) {
      dm_routh_dr_free(dr);
      return st;
    }
  }
  if (t != NULL && (st = dm_galerkin_alloc(&red->fsys, t, dr->tol, dr->maxiter, &dr->g, e)) != DM_OK) {
    dm_routh_dr_free(dr);
    return st;
  }
  *out = dr;
  return DM_OK;
}

/* I^{-1} mu, A, muA (and Dw, DA when deriv) at x */
static int conn_at(dm_routh_dr *dr, const double *x, int deriv, dm_err *e)
{
  const dm_routh *red = dr->red;
  size_t r = dr->r, d = dr->d, k;
  dm_rprog_run(&red->conn, x, red->par, dr->tout, dr->twork);
  for (k = 0; k < red->conn.nout; k++)
    if (!isfinite(dr->tout[k]))
      return dm_err_set(e, DM_ESINGULAR, "the mechanical connection is not finite (singular "
                        "locked inertia)");
  memcpy(dr->w, dr->tout, r * sizeof(double));
  memcpy(dr->A, dr->tout + r, r * d * sizeof(double));
  memcpy(dr->muA, dr->tout + r + r * d, d * sizeof(double));
  if (!deriv)
    return DM_OK;
  dm_rprog_run(&red->connd, x, red->par, dr->tout, dr->twork);
  memcpy(dr->Dw, dr->tout, r * d * sizeof(double));
  memcpy(dr->DA, dr->tout + r * d, r * d * d * sizeof(double));
  return DM_OK;
}

static int muA_at(dm_routh_dr *dr, const double *x, double *a, dm_err *e)
{
  if (dm_routh_muA(dr->red, x, a, dr->tin, dr->tout, dr->twork))
    return dm_err_set(e, DM_ESINGULAR, "mu^T A is not finite (singular locked inertia)");
  return DM_OK;
}

/* The midpoint formula psi = h I(xbar)^{-1} mu - A(xbar)(x1 - x0), with
 * the connection data at xbar (and its derivatives when deriv). */
static int psi_midpoint(dm_routh_dr *dr, double h, const double *x0, const double *x1, int deriv,
                        dm_err *e)
{
  size_t r = dr->r, d = dr->d, a, i;
  double xb[64], *xbar = d <= 64 ? xb : dr->dx;
  int st;
  for (i = 0; i < d; i++)
    xbar[i] = 0.5 * (x0[i] + x1[i]);
  if ((st = conn_at(dr, xbar, deriv, e)) != DM_OK)
    return st;
  for (a = 0; a < r; a++) {
    double acc = h * dr->w[a];
    for (i = 0; i < d; i++)
      acc -= dr->A[a * d + i] * (x1[i] - x0[i]);
    dr->psi[a] = acc;
  }
  return DM_OK;
}

/* Midpoint: psi (+ Dpsi), full two-point data p0, p1, Ld (+ d.. blocks). */
static int lift_midpoint(dm_routh_dr *dr, double h, const double *x0, const double *x1, int deriv,
                         dm_err *e)
{
  const dm_routh *red = dr->red;
  size_t n = dr->n, r = dr->r, d = dr->d, a, i, k, c;
  dm_lag_out o = {0, dr->Lq, dr->Lv, dr->Lvv, dr->Lvq, dr->Lqq};
  int st;
  if ((st = psi_midpoint(dr, h, x0, x1, deriv, e)) != DM_OK)
    return st;
  if (deriv)      /* D1 psi = (h/2) Dw - 1/2 DA.dx + A, D2 psi = (h/2) Dw - 1/2 DA.dx - A */
    for (a = 0; a < r; a++)
      for (k = 0; k < d; k++) {
        double t = 0.5 * h * dr->Dw[a * d + k];
        for (i = 0; i < d; i++)
          t -= 0.5 * dr->DA[(a * d + i) * d + k] * (x1[i] - x0[i]);
        dr->Dpsi[a * 2 * d + k] = t + dr->A[a * d + k];
        dr->Dpsi[a * 2 * d + d + k] = t - dr->A[a * d + k];
      }
  dm_routh_join(red, NULL, x0, dr->q0);
  dm_routh_join(red, dr->psi, x1, dr->q1);
  for (c = 0; c < n; c++) {
    dr->qb[c] = 0.5 * (dr->q0[c] + dr->q1[c]);
    dr->v[c] = (dr->q1[c] - dr->q0[c]) / h;
  }
  st = dr->fsys->lagrangian(dr->fsys->data, dr->qb, dr->v, dr->fsys->par,
                            DM_LAG_GRAD | (deriv ? (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ) : 0u), &o,
                            dr->work);
  if (st != 0)
    return dm_err_set(e, st > 0 ? DM_EDOM : DM_ECALLBACK, "L is outside its domain at the midpoint");
  *dr->Ld = h * o.L;
  for (c = 0; c < n; c++) {
    dr->p0[c] = dr->Lv[c] - 0.5 * h * dr->Lq[c];
    dr->p1[c] = dr->Lv[c] + 0.5 * h * dr->Lq[c];
  }
  if (deriv)
    for (c = 0; c < n; c++)
      for (k = 0; k < n; k++) {
        double vq = 0.5 * dr->Lvq[c * n + k], vv = dr->Lvv[c * n + k] / h;
        double qq = 0.25 * h * dr->Lqq[c * n + k], qv = 0.5 * dr->Lvq[k * n + c];
        dr->d01[c * n + k] = vq + vv - qq - qv;
        dr->d11[c * n + k] = vq + vv + qq + qv;
        dr->d00[c * n + k] = vq - vv - qq + qv;
        dr->d10[c * n + k] = vq - vv + qq - qv;
      }
  return DM_OK;
}

/* Galerkin: psi by Newton on p1_theta = mu (start: the midpoint formula). */
static int lift_galerkin(dm_routh_dr *dr, double h, const double *x0, const double *x1, int deriv,
                         dm_err *e)
{
  const dm_routh *red = dr->red;
  const double *mu = red->par + red->npar;
  size_t n = dr->n, r = dr->r, d = dr->d, a, b, i, it;
  double Jr[DM_ROUTH_RMAX * DM_ROUTH_RMAX], f[DM_ROUTH_RMAX], dn = HUGE_VAL;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int st, ok = 0;
  if (red->general) {         /* start: h thetadot at the midpoint with the secant velocity */
    for (i = 0; i < d; i++) {             /* Lq, Lv: free in the Galerkin path */
      dr->Lq[i] = 0.5 * (x0[i] + x1[i]);
      dr->Lv[i] = (x1[i] - x0[i]) / h;
    }
    if (dm_routh_general_thetadot(red, dr->Lq, dr->Lv, red->par, dr->psi, dr->rwork))
      return dm_err_set(e, DM_EDOM, "psi_mu: J = mu has no solution thetadot between x0 and x1");
    for (a = 0; a < r; a++)
      dr->psi[a] *= h;
  } else if ((st = psi_midpoint(dr, h, x0, x1, 0, e)) != DM_OK)
    return st;
  dm_routh_join(red, NULL, x0, dr->q0);
  for (it = 0; it < (size_t)dr->maxiter; it++) {
    dm_routh_join(red, dr->psi, x1, dr->q1);
    st = dm_galerkin_solve(dr->g, h, dr->q0, dr->q1, dr->Ld, dr->p0, dr->p1, dr->d00, dr->d01,
                           dr->d10, dr->d11, 1, e);
    if (st != DM_OK)
      return st;
    for (a = 0; a < r; a++) {
      f[a] = dr->p1[red->cyc[a]] - mu[a];
      for (b = 0; b < r; b++)
        Jr[a * r + b] = dr->d11[red->cyc[a] * n + red->cyc[b]];
    }
    if (dm_rlu_factor(&dr->lu_r, Jr, r) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "psi_mu: d J_d / d theta1 is singular (the discrete "
                        "Lagrangian is not group-regular here)");
    dm_rlu_solve(&dr->lu_r, Jr, r, f);
    for (a = 0; a < r; a++)
      dr->psi[a] -= f[a];
    dn = dm_rnorm_inf(f, r) / fmax(dm_rnorm_inf(dr->psi, r), fabs(h) * DBL_MIN + 1e-300);
    if (dm_rnorm_inf(f, r) == 0.0 || dm_newton_done(&stop, dn, dr->tol)) {
      ok = 1;
      break;
    }
  }
  if (!ok)
    return dm_err_set(e, DM_ENOCONV, "psi_mu: Newton on J_d = mu did not converge (update %.3g)", dn);
  dm_routh_join(red, dr->psi, x1, dr->q1);
  st = dm_galerkin_solve(dr->g, h, dr->q0, dr->q1, dr->Ld, dr->p0, dr->p1,
                         deriv ? dr->d00 : NULL, dr->d01, dr->d10, dr->d11, 1, e);
  if (st != DM_OK || !deriv)
    return st;
  /* Dpsi: d11_tt D2psi = -d11_tx, d11_tt D1psi = -d10_tx (q0 = (0, x0)) */
  for (a = 0; a < r; a++)
    for (b = 0; b < r; b++)
      Jr[a * r + b] = dr->d11[red->cyc[a] * n + red->cyc[b]];
  if (dm_rlu_factor(&dr->lu_r, Jr, r) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "psi_mu: d J_d / d theta1 is singular");
  for (i = 0; i < 2 * d; i++) {
    const double *M = i < d ? dr->d10 : dr->d11;
    size_t col = red->shape[i % d];
    for (a = 0; a < r; a++)
      f[a] = -M[red->cyc[a] * n + col];
    dm_rlu_solve(&dr->lu_r, Jr, r, f);
    for (a = 0; a < r; a++)
      dr->Dpsi[a * 2 * d + i] = f[a];
  }
  return DM_OK;
}

static int lift(dm_routh_dr *dr, double h, const double *x0, const double *x1, int deriv, dm_err *e)
{
  if (h == 0.0)
    return dm_err_set(e, DM_EINVAL, "discrete Routh equations need h != 0");
  return dr->g ? lift_galerkin(dr, h, x0, x1, deriv, e) : lift_midpoint(dr, h, x0, x1, deriv, e);
}

int dm_routh_dr_psi(dm_routh_dr *dr, double h, const double *x0, const double *x1, double *psi,
                    double *Dpsi, dm_err *e)
{
  int st = lift(dr, h, x0, x1, Dpsi != NULL, e);
  if (st != DM_OK)
    return st;
  memcpy(psi, dr->psi, dr->r * sizeof(double));
  if (Dpsi)
    memcpy(Dpsi, dr->Dpsi, 2 * dr->r * dr->d * sizeof(double));
  return DM_OK;
}

/* Lhat and the one-forms from the lifted data (after lift with deriv). */
static int oneforms(dm_routh_dr *dr, const double *x0, const double *x1, double *D1, double *D2,
                    double *A1, double *A2, dm_err *e)
{
  const dm_routh *red = dr->red;
  const double *mu = red->par + red->npar;
  size_t r = dr->r, d = dr->d, i, a;
  int st;
  if ((st = muA_at(dr, x0, dr->a0, e)) != DM_OK || (st = muA_at(dr, x1, dr->a1, e)) != DM_OK)
    return st;
  for (i = 0; i < d; i++) {
    double m1 = 0.0, m2 = 0.0;
    for (a = 0; a < r; a++) {
      m1 += mu[a] * dr->Dpsi[a * 2 * d + i];
      m2 += mu[a] * dr->Dpsi[a * 2 * d + d + i];
    }
    if (D1)
      D1[i] = -dr->p0[red->shape[i]] + m1;
    if (D2)
      D2[i] = dr->p1[red->shape[i]] + m2;
    if (A1)
      A1[i] = m1 - dr->a0[i];
    if (A2)
      A2[i] = m2 + dr->a1[i];
  }
  return DM_OK;
}

int dm_routh_dr_lhat(dm_routh_dr *dr, double h, const double *x0, const double *x1, double *Lhat,
                     double *D1, double *D2, double *A1, double *A2, dm_err *e)
{
  int st = lift(dr, h, x0, x1, 1, e);
  if (st != DM_OK)
    return st;
  if (Lhat)
    *Lhat = *dr->Ld;
  return oneforms(dr, x0, x1, D1, D2, A1, A2, e);
}

int dm_routh_dr_residual(dm_routh_dr *dr, double h, const double *xp, const double *xc,
                         const double *xn, double *res_dr, double *res_del, dm_err *e)
{
  const dm_routh *red = dr->red;
  size_t d = dr->d, i;
  double *D2p = dr->sc, *A2p = D2p + d, *D1n = A2p + d, *A1n = D1n + d, *p1x = A1n + d;
  int st;
  if ((st = dm_routh_dr_lhat(dr, h, xp, xc, NULL, NULL, D2p, NULL, A2p, e)) != DM_OK)
    return st;
  for (i = 0; i < d; i++)
    p1x[i] = dr->p1[red->shape[i]];
  if ((st = dm_routh_dr_lhat(dr, h, xc, xn, NULL, D1n, NULL, A1n, NULL, e)) != DM_OK)
    return st;
  for (i = 0; i < d; i++) {
    if (res_dr)
      res_dr[i] = D2p[i] + D1n[i] - A2p[i] - A1n[i];
    if (res_del)
      res_del[i] = p1x[i] - dr->p0[red->shape[i]];
  }
  return DM_OK;
}

int dm_routh_dr_step(dm_routh_dr *dr, double h, const double *x0, const double *s0, double *x1,
                     double *s1, double *psi, dm_err *e)
{
  const dm_routh *red = dr->red;
  size_t n = dr->n, r = dr->r, d = dr->d, i, k, a, it;
  double dn = HUGE_VAL, *D1 = dr->res, *A1 = dr->dx;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int st, ok = 0;
  st = dm_routh_check_inertia(red, x0, &dr->sing_ref, dr->twork, "the initial point", e);
  if (st != DM_OK)
    return st;
  /* predictor: the previous increment, or the velocity from Mtilde(x0) v = s0 */
  if (dr->have_prev) {
    for (i = 0; i < d; i++)
      dr->x1[i] = x0[i] + dr->dxprev[i];
  } else {
    dm_lag_out o = {0, dr->Lq, dr->Lv, dr->Lvv, dr->Lvq, dr->Lqq};
    memset(dr->v, 0, d * sizeof(double));
    st = red->rsys.lagrangian(red->rsys.data, x0, dr->v, red->par, DM_LAG_VV, &o, dr->rwork);
    if (st != 0)
      return dm_err_set(e, DM_EDOM, "the Routhian is outside its domain at x0");
    memcpy(dr->J, dr->Lvv, d * d * sizeof(double));
    if (dm_rlu_factor(&dr->lu_d, dr->J, d) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "the reduced kinetic matrix is singular at x0");
    memcpy(dr->v, s0, d * sizeof(double));
    dm_rlu_solve(&dr->lu_d, dr->J, d, dr->v);
    for (i = 0; i < d; i++)
      dr->x1[i] = x0[i] + h * dr->v[i];
  }
  for (it = 1; it <= (size_t)dr->maxiter; it++) {
    double xs;
    if ((st = lift(dr, h, x0, dr->x1, 1, e)) != DM_OK ||
        (st = oneforms(dr, x0, dr->x1, D1, NULL, A1, NULL, e)) != DM_OK)
      break;
    /* residual s0 + D1 Lhat - Ahat_1 (general form), Jacobian -dF-/dx1 */
    for (i = 0; i < d; i++)
      dr->v[i] = s0[i] + D1[i] - A1[i];
    for (i = 0; i < d; i++)
      for (k = 0; k < d; k++) {
        double acc = dr->d01[red->shape[i] * n + red->shape[k]];
        for (a = 0; a < r; a++)
          acc += dr->d01[red->shape[i] * n + red->cyc[a]] * dr->Dpsi[a * 2 * d + d + k];
        dr->J[i * d + k] = -acc;
      }
    if (dm_rlu_factor(&dr->lu_d, dr->J, d) != DM_OK) {
      st = dm_err_set(e, DM_ESINGULAR, "discrete Routh equations: singular Newton matrix (h = %g)", h);
      break;
    }
    dm_rlu_solve(&dr->lu_d, dr->J, d, dr->v);
    for (i = 0; i < d; i++)
      dr->x1[i] -= dr->v[i];
    xs = fmax(dm_rnorm_inf(dr->x1, d) - dm_rnorm_inf(x0, d), 0.0);
    dn = dm_rnorm_inf(dr->v, d) / fmax(fmax(dm_rnorm_inf(dr->x1, d), xs), DBL_MIN);
    if (!isfinite(dn)) {
      st = dm_err_set(e, DM_EDOM, "discrete Routh equations: non-finite Newton update (h = %g)", h);
      break;
    }
    if (dm_newton_done(&stop, dn, dr->tol)) {
      ok = 1;
      break;
    }
  }
  dr->iters = (int)(it > (size_t)dr->maxiter ? (size_t)dr->maxiter : it);
  if (st != DM_OK) {
    dr->have_prev = 0;
    return st;
  }
  if (!ok) {
    dr->have_prev = 0;
    return dm_err_set(e, DM_ENOCONV, "discrete Routh equations: Newton did not converge in %d "
                      "iterations (update %.3g, h = %g)", dr->iters, dn, h);
  }
  if ((st = dm_routh_check_inertia(red, dr->x1, &dr->sing_ref, dr->twork, "the end point", e))
      != DM_OK || (st = lift(dr, h, x0, dr->x1, 1, e)) != DM_OK) {
    dr->have_prev = 0;
    return st;
  }
  /* s1 = D2 Lhat - Ahat_2 (general form) */
  if ((st = oneforms(dr, x0, dr->x1, NULL, dr->res, NULL, dr->dx, e)) != DM_OK)
    return st;
  if (psi)
    memcpy(psi, dr->psi, r * sizeof(double));
  for (i = 0; i < d; i++) {
    dr->dxprev[i] = dr->x1[i] - x0[i];
    s1[i] = dr->res[i] - dr->dx[i];
    x1[i] = dr->x1[i];
  }
  dr->have_prev = 1;
  return DM_OK;
}

int dm_routh_dr_solve(dm_routh_dr *dr, double h, const double *xp, const double *xc, double *xn,
                      int guess, dm_err *e)
{
  size_t d = dr->d, i;
  double *sc = dr->sc;
  int st;
  /* s_c = F+(xp, xc) = D2 Lhat - Ahat_2 */
  st = dm_routh_dr_lhat(dr, h, xp, xc, NULL, NULL, sc, NULL, sc + d, e);
  if (st == DM_OK) {
    for (i = 0; i < d; i++)
      sc[i] -= sc[d + i];
    if (guess) {
      for (i = 0; i < d; i++)
        dr->dxprev[i] = xn[i] - xc[i];
    } else {
      for (i = 0; i < d; i++)
        dr->dxprev[i] = xc[i] - xp[i];
    }
    dr->have_prev = 1;
    st = dm_routh_dr_step(dr, h, xc, sc, xn, sc + d, NULL, e);
  }
  return st;
}

/* The step Jacobian by implicit differentiation of the reduced discrete
 * Legendre transforms at the converged step.  In additive coordinates
 * F-(x0, x1) = p0_x(q0, q1) - muA(x0) and F+(x0, x1) = p1_x(q0, q1) -
 * muA(x1) with q0 = (0, x0), q1 = (psi_mu(x0, x1), x1) (the mu.Dpsi terms
 * of D Lhat and Ahat cancel), so with the blocks dp/dq of the full
 * discrete Lagrangian, Dpsi and K = d muA/dx:
 *   P = dF-/dx0 = d00_xx + d01_xt D1psi - K(x0),  Q = dF-/dx1 = d01_xx + d01_xt D2psi,
 *   R = dF+/dx0 = d10_xx + d11_xt D1psi,          S = dF+/dx1 = d11_xx + d11_xt D2psi - K(x1);
 * s0 = F-(x0, x1) gives dx1 = Q^{-1} (ds0 - P dx0), and s1 = F+(x0, x1)
 * ds1 = R dx0 + S dx1. */
int dm_routh_dr_jacobian(dm_routh_dr *dr, double h, const double *x0, const double *s0,
                         double *DPhi, dm_err *e)
{
  const dm_routh *red = dr->red;
  size_t n = dr->n, r = dr->r, d = dr->d, N = 2 * d, i, k, a, j;
  double *P, *Q, *R, *S, *K0, *K1, *Y, *x1, *s1, *mu_a;
  int st;
  if ((P = malloc((6 * d * d + N * d + 3 * d) * sizeof(double))) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  Q = P + d * d;
  R = Q + d * d;
  S = R + d * d;
  K0 = S + d * d;
  K1 = K0 + d * d;
  Y = K1 + d * d;              /* d x 2d: Q^{-1} [-P | Id] */
  x1 = Y + N * d;
  s1 = x1 + d;
  mu_a = s1 + d;
  st = dm_routh_dr_step(dr, h, x0, s0, x1, s1, NULL, e);
  if (st == DM_OK && (dm_routh_muA_K(red, x0, mu_a, K0, dr->tin, dr->twork)
                      || dm_routh_muA_K(red, x1, mu_a, K1, dr->tin, dr->twork)))
    st = dm_err_set(e, DM_EDOM, "mu^T A or its derivative is not finite at this point");
  /* the step ended with lift(x0, x1) and derivatives: d.., Dpsi are current */
  for (i = 0; st == DM_OK && i < d; i++)
    for (k = 0; k < d; k++) {
      size_t xi = red->shape[i], xk = red->shape[k];
      double p = dr->d00[xi * n + xk], q = dr->d01[xi * n + xk];
      double rr = dr->d10[xi * n + xk], ss = dr->d11[xi * n + xk];
      for (a = 0; a < r; a++) {
        double D1 = dr->Dpsi[a * 2 * d + k], D2 = dr->Dpsi[a * 2 * d + d + k];
        size_t ta = red->cyc[a];
        p += dr->d01[xi * n + ta] * D1;
        q += dr->d01[xi * n + ta] * D2;
        rr += dr->d11[xi * n + ta] * D1;
        ss += dr->d11[xi * n + ta] * D2;
      }
      P[i * d + k] = p - K0[i * d + k];
      Q[i * d + k] = q;
      R[i * d + k] = rr;
      S[i * d + k] = ss - K1[i * d + k];
    }
  if (st == DM_OK && dm_rlu_factor(&dr->lu_d, Q, d) != DM_OK)
    st = dm_err_set(e, DM_ESINGULAR, "discrete Routh step Jacobian: dF-/dx1 is singular (h = %g)", h);
  for (j = 0; st == DM_OK && j < N; j++) {
    double *col = dr->sc;      /* 6 d scratch */
    for (i = 0; i < d; i++)
      col[i] = j < d ? -P[i * d + j] : (double)(i == j - d);
    dm_rlu_solve(&dr->lu_d, Q, d, col);
    for (i = 0; i < d; i++)
      Y[i * N + j] = col[i];
  }
  for (i = 0; st == DM_OK && i < d; i++)
    for (j = 0; j < N; j++) {
      double acc = j < d ? R[i * d + j] : 0.0;
      for (k = 0; k < d; k++)
        acc += S[i * d + k] * Y[k * N + j];
      DPhi[i * N + j] = Y[i * N + j];
      DPhi[(d + i) * N + j] = acc;
    }
  free(P);
  return st;
}
