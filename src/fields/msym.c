/* msym.c -- the multisymplectic variational integrator of
 * l = u_t^2/2 - c^2 u_x^2/2 - V(u) on a space-time grid: bilinear elements,
 * the one-point (cell-centre) rule, the step of a time slab in position-
 * momentum form, its derivative, and the discrete multisymplectic form
 * formula checked cell by cell and node by node (doc/beyond-fixed-steps.md §5).
 * See fields.h. */
#include <config.h>
#include "fields/fields.h"
#include "core/newton.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

struct dm_msym {
  size_t N, nn;              /* cells per slab; nodes (N periodic, N + 1 held ends) */
  int periodic;
  double dx, dt, c;
  dm_potential V;
  double *diag, *off, *rhs, *sol, *H, *prevtop, *rowu, *rowv, *roww, *rowp, *rowq, *cu, *cp;
};

static const double GT[4] = {-1, -1, 1, 1}, GX[4] = {-1, 1, -1, 1};   /* BL BR TL TR */

static int pot(const dm_msym *M, double u, double *V, double *dV, double *d2V)
{
  if (M->V.eval == NULL) {
    if (V) *V = 0;
    if (dV) *dV = 0;
    if (d2V) *d2V = 0;
    return 0;
  }
  return M->V.eval(M->V.data, u, V, dV, d2V);
}

/* Slot derivatives D[4] and Hessian H[16] (may be NULL) of a cell with
 * corners BL = b0, BR = b1, TL = t0, TR = t1. */
static int cell(const dm_msym *M, double b0, double b1, double t0, double t1, double *D, double *H)
{
  double dx = M->dx, dt = M->dt, c2 = M->c * M->c, vol = dx * dt;
  double ut = (t0 + t1 - b0 - b1) / (2 * dt), ux = (b1 + t1 - b0 - t0) / (2 * dx);
  double ub = 0.25 * (b0 + b1 + t0 + t1), dV = 0, d2V = 0;
  int rc = pot(M, ub, NULL, &dV, H ? &d2V : NULL);
  if (rc != 0 || !isfinite(dV) || !isfinite(d2V))
    return rc != 0 ? rc : 1;
  for (int a = 0; a < 4; a++) {
    double ga = GT[a] / (2 * dt), xa = GX[a] / (2 * dx);
    if (D)
      D[a] = vol * (ga * ut - c2 * xa * ux - 0.25 * dV);
    if (H)
      for (int b = 0; b < 4; b++)
        H[a * 4 + b] = vol * (ga * GT[b] / (2 * dt) - c2 * xa * GX[b] / (2 * dx) - d2V / 16);
  }
  return 0;
}

int dm_msym_alloc(size_t N, double length, int periodic, double c, double dt,
                  const dm_potential *V, dm_msym **out, dm_err *e)
{
  dm_msym *M;
  *out = NULL;
  if (N < 3 || N > 100000000)
    return dm_err_set(e, DM_EINVAL, "multisymplectic: need 3 <= N cells, got %zu", N);
  if (!(length > 0) || !isfinite(length) || !isfinite(c) || !isfinite(dt) || dt == 0.0)
    return dm_err_set(e, DM_EINVAL, "multisymplectic: length > 0, finite c and dt != 0 needed");
  if ((M = calloc(1, sizeof *M)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "multisymplectic: out of memory");
  M->N = N;
  M->nn = periodic ? N : N + 1;
  M->periodic = periodic != 0;
  M->dx = length / (double)N;
  M->dt = dt;
  M->c = c;
  if (V != NULL)
    M->V = *V;
  M->diag = calloc(13 * (M->nn + 1) + 16 * N, sizeof(double));
  if (M->diag == NULL) {
    free(M);
    return dm_err_set(e, DM_ENOMEM, "multisymplectic: out of memory");
  }
  M->off = M->diag + M->nn + 1;
  M->rhs = M->off + M->nn + 1;
  M->sol = M->rhs + M->nn + 1;
  M->prevtop = M->sol + M->nn + 1;
  M->rowu = M->prevtop + M->nn + 1;
  M->rowv = M->rowu + M->nn + 1;
  M->roww = M->rowv + M->nn + 1;
  M->rowp = M->roww + M->nn + 1;
  M->rowq = M->rowp + M->nn + 1;
  M->cu = M->rowq + M->nn + 1;
  M->cp = M->cu + M->nn + 1;
  M->H = M->cp + M->nn + 1;
  *out = M;
  return DM_OK;
}

void dm_msym_free(dm_msym *M)
{
  if (M == NULL)
    return;
  free(M->diag);
  free(M);
}

size_t dm_msym_nodes(const dm_msym *M) { return M->nn; }
double dm_msym_dx(const dm_msym *M) { return M->dx; }
double dm_msym_dt(const dm_msym *M) { return M->dt; }

void dm_msym_momentum(const dm_msym *M, const double *v, double *p)
{
  for (size_t i = 0; i < M->nn; i++)
    p[i] = M->periodic || (i > 0 && i < M->N) ? M->dx * v[i] : 0.0;
}

/* the right corner of cell k */
static inline size_t right(const dm_msym *M, size_t k)
{
  return M->periodic ? (k + 1) % M->N : k + 1;
}

/* the first and one-past-last node with an equation (interior when held) */
static inline size_t first_eq(const dm_msym *M) { return M->periodic ? 0 : 1; }
static inline size_t last_eq(const dm_msym *M) { return M->periodic ? M->N : M->N; }

/* cell k's Hessian into M->H + 16 k for the slab (u0 below, u1 above) */
static int slab_hessians(dm_msym *M, const double *u0, const double *u1, double *D)
{
  for (size_t k = 0; k < M->N; k++) {
    size_t r = right(M, k);
    int rc = cell(M, u0[k], u0[r], u1[k], u1[r], D ? D + 4 * k : NULL, M->H + 16 * k);
    if (rc != 0)
      return rc;
  }
  return 0;
}

/* Solve J x = b with the tridiagonal Jacobian of the slab (Hessians in
 * M->H): rows and columns are the nodes with equations. */
static int slab_solve(dm_msym *M, const double *b, double *x)
{
  size_t N = M->N, i, i0 = first_eq(M), i1 = last_eq(M), m = i1 - i0;
  for (i = i0; i < i1; i++) {
    size_t cl = M->periodic ? (i + N - 1) % N : i - 1, cr = i;   /* cells left, right of i */
    const double *Hl = M->H + 16 * cl, *Hr = M->H + 16 * cr;
    M->diag[i - i0] = Hl[1 * 4 + 3] + Hr[0 * 4 + 2];               /* BR,TR + BL,TL */
    M->off[i - i0] = Hr[0 * 4 + 3];                                /* BL,TR of the right cell */
    M->rhs[i - i0] = b[i];
  }
  gsl_vector_view d = gsl_vector_view_array(M->diag, m), r = gsl_vector_view_array(M->rhs, m),
                  s = gsl_vector_view_array(M->sol, m);
  int st;
  if (M->periodic) {
    gsl_vector_view o = gsl_vector_view_array(M->off, m);
    st = gsl_linalg_solve_symm_cyc_tridiag(&d.vector, &o.vector, &r.vector, &s.vector);
  } else {
    gsl_vector_view o = gsl_vector_view_array(M->off, m - 1);
    st = gsl_linalg_solve_symm_tridiag(&d.vector, &o.vector, &r.vector, &s.vector);
  }
  if (st != GSL_SUCCESS)
    return DM_ESINGULAR;
  for (i = 0; i < M->nn; i++)
    x[i] = i >= i0 && i < i1 ? M->sol[i - i0] : 0.0;
  return DM_OK;
}

int dm_msym_step(dm_msym *M, const double *u0_in, const double *p0_in, double *u1, double *p1,
                 dm_err *e)
{
  size_t N = M->N, nn = M->nn, i, i0 = first_eq(M), i1 = last_eq(M);
  double d = HUGE_VAL, *u0 = M->cu, *p0 = M->cp;     /* copies: outputs may alias inputs */
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it, rc;
  memmove(u0, u0_in, nn * sizeof *u0);
  memmove(p0, p0_in, nn * sizeof *p0);
  for (i = 0; i < nn; i++)
    u1[i] = (M->periodic || (i > 0 && i < N)) ? u0[i] + M->dt * p0[i] / M->dx : u0[i];
  for (it = 0; it < 60; it++) {
    double xs = 0;
    for (i = i0; i < i1; i++) {
      size_t cl = M->periodic ? (i + N - 1) % N : i - 1, cr = i;
      double Dl[4], Dr[4];
      if ((rc = cell(M, u0[cl], u0[i], u1[cl], u1[i], Dl, NULL)) != 0
          || (rc = cell(M, u0[i], u0[right(M, cr)], u1[i], u1[right(M, cr)], Dr, NULL)) != 0)
        return dm_err_set(e, DM_EDOM, "multisymplectic: V fails near node %zu", i);
      M->rowp[i] = p0[i] + Dl[1] + Dr[0];
    }
    if ((rc = slab_hessians(M, u0, u1, NULL)) != 0)
      return dm_err_set(e, DM_EDOM, "multisymplectic: V'' fails in the slab");
    if (slab_solve(M, M->rowp, M->rowq) != DM_OK)
      return dm_err_set(e, DM_ESINGULAR, "multisymplectic: singular slab Jacobian");
    for (i = i0; i < i1; i++) {
      u1[i] -= M->rowq[i];
      xs = fmax(xs, fabs(u1[i]));
    }
    d = 0;
    for (i = i0; i < i1; i++)
      d = fmax(d, fabs(M->rowq[i]));
    d /= xs > 1 ? xs : 1.0;
    if (!isfinite(d))
      return dm_err_set(e, DM_EDIVERGED, "multisymplectic: the Newton update is not finite");
    if (dm_newton_done(&stop, d, 4 * DBL_EPSILON))
      break;
  }
  if (it >= 60)
    return dm_err_set(e, DM_ENOCONV, "multisymplectic: Newton did not converge (update %.3g)", d);
  for (i = 0; i < nn; i++) {
    if (!M->periodic && (i == 0 || i == N)) {
      p1[i] = 0.0;
      continue;
    }
    size_t cl = M->periodic ? (i + N - 1) % N : i - 1, cr = i;
    double Dl[4], Dr[4];
    cell(M, u0[cl], u0[i], u1[cl], u1[i], Dl, NULL);
    cell(M, u0[i], u0[right(M, cr)], u1[i], u1[right(M, cr)], Dr, NULL);
    p1[i] = Dl[3] + Dr[2];                       /* TR of the left cell + TL of the right */
  }
  return DM_OK;
}

int dm_msym_tangent(dm_msym *M, const double *u0, const double *u1, const double *du0,
                    const double *dp0, double *du1, double *dp1, dm_err *e)
{
  size_t N = M->N, nn = M->nn, i, i0 = first_eq(M), i1 = last_eq(M);
  if (slab_hessians(M, u0, u1, NULL) != 0)
    return dm_err_set(e, DM_EDOM, "multisymplectic: V'' fails in the slab");
  /* J du1 = -(dp0 + dR/du0 du0) */
  for (i = i0; i < i1; i++) {
    size_t cl = M->periodic ? (i + N - 1) % N : i - 1, cr = i, rr = right(M, cr);
    const double *Hl = M->H + 16 * cl, *Hr = M->H + 16 * cr;
    M->rowp[i] = -(dp0[i] + Hl[1 * 4 + 0] * du0[cl] + Hl[1 * 4 + 1] * du0[i]
                   + Hr[0 * 4 + 0] * du0[i] + Hr[0 * 4 + 1] * du0[rr]);
  }
  if (slab_solve(M, M->rowp, du1) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "multisymplectic: singular slab Jacobian");
  for (i = 0; i < nn; i++) {
    if (!M->periodic && (i == 0 || i == N)) {
      du1[i] = 0.0;
      dp1[i] = 0.0;
      continue;
    }
    size_t cl = M->periodic ? (i + N - 1) % N : i - 1, cr = i, rr = right(M, cr);
    const double *Hl = M->H + 16 * cl, *Hr = M->H + 16 * cr;
    double zl[4] = {du0[cl], du0[i], du1[cl], du1[i]}, zr[4] = {du0[i], du0[rr], du1[i], du1[rr]};
    double acc = 0;
    for (int b = 0; b < 4; b++)
      acc += Hl[3 * 4 + b] * zl[b] + Hr[2 * 4 + b] * zr[b];
    dp1[i] = acc;
  }
  return DM_OK;
}

double dm_msym_energy(const dm_msym *M, const double *u, const double *p)
{
  double E = 0, c2 = M->c * M->c, V;
  for (size_t i = 0; i < M->nn; i++) {
    if (M->periodic || (i > 0 && i < M->N))
      E += p[i] * p[i] / (2 * M->dx);
    if (pot(M, u[i], &V, NULL, NULL) == 0 && (M->periodic || (i > 0 && i < M->N)))
      E += M->dx * V;
  }
  for (size_t k = 0; k < M->N; k++) {
    double g = (u[right(M, k)] - u[k]) / M->dx;
    E += 0.5 * M->dx * c2 * g * g;
  }
  return E;
}

double dm_msym_dispersion(const dm_msym *M, double k)
{
  return 2.0 / M->dt * atan(M->c * M->dt * tan(0.5 * k * M->dx) / M->dx);
}

/* corner form a of a cell: sum_b H_ab (V_b W_a - W_b V_a) */
static double corner_form(const double *H, int a, const double *V, const double *W)
{
  double s = 0;
  for (int b = 0; b < 4; b++)
    s += H[a * 4 + b] * (V[b] * W[a] - W[b] * V[a]);
  return s;
}

int dm_msym_form_check(dm_msym *M, const double *u, const double *p, const double *du,
                       const double *dp, const double *dv, const double *dq, long nsteps,
                       double *res, dm_err *e)
{
  size_t nn = M->nn, N = M->N, i, k;
  double *buf = malloc(12 * nn * sizeof *buf), w0 = 0, big = 0, cellmax = 0, nodemax = 0,
         levmax = 0;
  int st = DM_OK;
  if (buf == NULL)
    return dm_err_set(e, DM_ENOMEM, "multisymplectic: out of memory");
  double *u0 = buf, *p0 = u0 + nn, *V0 = p0 + nn, *P0 = V0 + nn, *W0 = P0 + nn, *Q0 = W0 + nn;
  double *u1 = Q0 + nn, *p1 = u1 + nn, *V1 = p1 + nn, *P1 = V1 + nn, *W1 = P1 + nn, *Q1 = W1 + nn;
  memcpy(u0, u, nn * sizeof *u);
  memcpy(p0, p, nn * sizeof *u);
  memcpy(V0, du, nn * sizeof *u);
  memcpy(P0, dp, nn * sizeof *u);
  memcpy(W0, dv, nn * sizeof *u);
  memcpy(Q0, dq, nn * sizeof *u);
  for (i = 0; i < nn; i++)
    w0 += V0[i] * Q0[i] - W0[i] * P0[i];
  memset(M->prevtop, 0, nn * sizeof *M->prevtop);
  for (long j = 0; j < nsteps && st == DM_OK; j++) {
    if ((st = dm_msym_step(M, u0, p0, u1, p1, e)) != DM_OK
        || (st = dm_msym_tangent(M, u0, u1, V0, P0, V1, P1, e)) != DM_OK
        || (st = dm_msym_tangent(M, u0, u1, W0, Q0, W1, Q1, e)) != DM_OK)
      break;
    /* this slab's corner forms; node sums at level j (bottom here + top of the slab below) */
    for (i = 0; i < nn; i++)
      M->rowv[i] = 0.0;
    for (k = 0; k < N; k++) {
      size_t r = right(M, k);
      const double *H = M->H + 16 * k;
      double Vc[4] = {V0[k], V0[r], V1[k], V1[r]}, Wc[4] = {W0[k], W0[r], W1[k], W1[r]}, s = 0;
      for (int a = 0; a < 4; a++) {
        double f = corner_form(H, a, Vc, Wc);
        big = fmax(big, fabs(f));
        s += f;
      }
      cellmax = fmax(cellmax, fabs(s));
      M->rowv[k] += corner_form(H, 0, Vc, Wc);                   /* bottom corners */
      M->rowv[r] += corner_form(H, 1, Vc, Wc);
      M->roww[k] = corner_form(H, 2, Vc, Wc);                    /* top corners, for level j+1 */
      M->rowu[k] = corner_form(H, 3, Vc, Wc);
    }
    if (j > 0)
      for (i = first_eq(M); i < last_eq(M); i++)
        nodemax = fmax(nodemax, fabs(M->rowv[i] + M->prevtop[i]));
    for (i = 0; i < nn; i++)
      M->prevtop[i] = 0.0;
    for (k = 0; k < N; k++) {
      M->prevtop[k] += M->roww[k];
      M->prevtop[right(M, k)] += M->rowu[k];
    }
    double w = 0;
    for (i = 0; i < nn; i++)
      w += V1[i] * Q1[i] - W1[i] * P1[i];
    levmax = fmax(levmax, fabs(w - w0));
    memcpy(u0, u1, 6 * nn * sizeof *u0);
  }
  big = big > 0 ? big : 1.0;
  res[0] = cellmax / big;
  res[1] = nodemax / big;
  res[2] = levmax / fmax(fabs(w0), big);
  free(buf);
  return st;
}

/* {==== a potential from a compiled one-coordinate system ================ */

static int sys_pot(void *data, double u, double *V, double *dV, double *d2V)
{
  dm_potential_system *ps = data;
  const dm_system *f = ps->field;
  double z = 0, Lq = 0, Lv = 0, Lvv = 0, Lvq = 0, Lqq = 0;
  dm_lag_out o = {0, &Lq, &Lv, &Lvv, &Lvq, &Lqq};
  unsigned what = DM_LAG_L | (dV ? DM_LAG_Q : 0) | (d2V ? DM_LAG_ALL : 0);
  int rc = f->lagrangian(f->data, &u, &z, f->par, what, &o, ps->work);
  if (rc != 0)
    return rc;
  if (V)
    *V = o.L;
  if (dV)
    *dV = Lq;
  if (d2V)
    *d2V = Lqq;
  return 0;
}

void dm_potential_from_system(dm_potential *pot, dm_potential_system *ps)
{
  pot->eval = sys_pot;
  pot->data = ps;
}

/* }====================================================================== */
