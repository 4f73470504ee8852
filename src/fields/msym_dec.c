/* msym_dec.c -- the multisymplectic integrator of the nonlinear wave
 * equation with DEC in space: u a primal 0-cochain, the stiffness
 * S = *0 Delta_0 = d0^T *1 d0 and the mass *0 of src/dec, the midpoint rule
 * in time over each space-time prism (doc/beyond-fixed-steps.md §5.3).  The constant
 * SPD part of the Newton matrix is factored once by CHOLMOD.  See fields.h. */
#include <config.h>
#include "fields/fields.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct dm_msym_dec {
  size_t n;
  double c, dt;
  dm_potential V;
  dm_sparse *S;
  dm_sparse_chol *A;         /* *0/dt + (dt/4) c^2 S */
  double *m, *ub, *r, *d, *w, *z, *cu, *cp;
};

void dm_msym_dec_free(dm_msym_dec *M)
{
  if (M == NULL)
    return;
  dm_sparse_free(M->S);
  dm_sparse_chol_free(M->A);
  free(M->m);
  free(M);
}

int dm_msym_dec_alloc(const dm_dec_geom *G, double c, double dt, const dm_potential *V,
                      dm_msym_dec **out, dm_err *e)
{
  dm_msym_dec *M;
  dm_sparse *D = NULL, *A = NULL;
  size_t i;
  int st;
  *out = NULL;
  if (!isfinite(c) || !isfinite(dt) || dt == 0.0)
    return dm_err_set(e, DM_EINVAL, "multisymplectic: finite c and dt != 0 needed");
  if ((M = calloc(1, sizeof *M)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "multisymplectic: out of memory");
  if ((st = dm_dec_laplacian(G, 0, NULL, &M->S, e)) != DM_OK) {
    dm_msym_dec_free(M);
    return st;
  }
  M->n = (size_t)M->S->nrows;
  M->c = c;
  M->dt = dt;
  if (V != NULL)
    M->V = *V;
  if ((M->m = calloc(8 * M->n, sizeof *M->m)) == NULL) {
    dm_msym_dec_free(M);
    return dm_err_set(e, DM_ENOMEM, "multisymplectic: out of memory");
  }
  M->ub = M->m + M->n;
  M->r = M->ub + M->n;
  M->d = M->r + M->n;
  M->w = M->d + M->n;
  M->z = M->w + M->n;
  M->cu = M->z + M->n;
  M->cp = M->cu + M->n;
  if ((st = dm_dec_star(G, 0, 0, M->m, e)) != DM_OK) {
    dm_msym_dec_free(M);
    return st;
  }
  for (i = 0; i < M->n; i++)
    if (!(M->m[i] > 0)) {
      dm_msym_dec_free(M);
      return dm_err_set(e, DM_EINVAL, "multisymplectic: the dual cell of vertex %zu has no "
                        "positive volume (*0 = %g)", i + 1, M->m[i]);
    }
  for (i = 0; i < M->n; i++)
    M->w[i] = M->m[i] / dt;
  D = dm_sparse_diag((int)M->n, M->w, e);
  A = D ? dm_sparse_add(1.0, D, 0.25 * dt * c * c, M->S, e) : NULL;
  M->A = A ? dm_sparse_chol_alloc(A, e) : NULL;
  dm_sparse_free(D);
  dm_sparse_free(A);
  if (M->A == NULL) {
    dm_msym_dec_free(M);
    return e && e->status ? e->status : DM_ESINGULAR;
  }
  *out = M;
  return DM_OK;
}

size_t dm_msym_dec_nodes(const dm_msym_dec *M) { return M->n; }

void dm_msym_dec_momentum(const dm_msym_dec *M, const double *v, double *p)
{
  for (size_t i = 0; i < M->n; i++)
    p[i] = M->m[i] * v[i];
}

static int pot(const dm_msym_dec *M, double u, double *V, double *dV, double *d2V)
{
  if (M->V.eval == NULL) {
    if (V) *V = 0;
    if (dV) *dV = 0;
    if (d2V) *d2V = 0;
    return 0;
  }
  int rc = M->V.eval(M->V.data, u, V, dV, d2V);
  return rc != 0 ? rc : (dV && !isfinite(*dV)) || (d2V && !isfinite(*d2V)) ? 1 : 0;
}

/* f = c^2 S ubar + *0 V'(ubar) */
static int force(dm_msym_dec *M, const double *ubar, double *f)
{
  size_t i;
  dm_sparse_gemv(M->S, ubar, f);
  for (i = 0; i < M->n; i++) {
    double dV;
    if (pot(M, ubar[i], NULL, &dV, NULL) != 0)
      return DM_EDOM;
    f[i] = M->c * M->c * f[i] + M->m[i] * dV;
  }
  return DM_OK;
}

int dm_msym_dec_step(dm_msym_dec *M, const double *u0_in, const double *p0_in, double *u1,
                     double *p1, dm_err *e)
{
  size_t n = M->n, i;
  double dt = M->dt, d = HUGE_VAL, *u0 = M->cu, *p0 = M->cp;   /* outputs may alias inputs */
  int it, st;
  memmove(u0, u0_in, n * sizeof *u0);
  memmove(p0, p0_in, n * sizeof *p0);
  for (i = 0; i < n; i++)
    u1[i] = u0[i] + dt * p0[i] / M->m[i];
  for (it = 0; it < 200; it++) {
    double xs = 1.0;
    for (i = 0; i < n; i++)
      M->ub[i] = 0.5 * (u0[i] + u1[i]);
    if (force(M, M->ub, M->r) != DM_OK)
      return dm_err_set(e, DM_EDOM, "multisymplectic: V fails in the step");
    for (i = 0; i < n; i++)
      M->r[i] = M->m[i] * (u1[i] - u0[i]) / dt + 0.5 * dt * M->r[i] - p0[i];
    if ((st = dm_sparse_chol_solve(M->A, 1, M->r, M->d, e)) != DM_OK)
      return st;
    d = 0;
    for (i = 0; i < n; i++) {
      u1[i] -= M->d[i];
      d = fmax(d, fabs(M->d[i]));
      xs = fmax(xs, fabs(u1[i]));
    }
    if (!isfinite(d))
      return dm_err_set(e, DM_EDIVERGED, "multisymplectic: the update is not finite");
    if (d <= 4 * DBL_EPSILON * xs)
      break;
  }
  if (it >= 200)
    return dm_err_set(e, DM_ENOCONV, "multisymplectic: the simplified Newton iteration did not "
                      "converge (update %.3g): dt^2 max|V''| is too large", d);
  for (i = 0; i < n; i++)
    M->ub[i] = 0.5 * (u0[i] + u1[i]);
  force(M, M->ub, M->r);
  for (i = 0; i < n; i++)
    p1[i] = M->m[i] * (u1[i] - u0[i]) / dt - 0.5 * dt * M->r[i];
  return DM_OK;
}

double dm_msym_dec_energy(const dm_msym_dec *M, const double *u, const double *p)
{
  size_t i;
  double E = 0, V;
  dm_sparse_gemv(M->S, u, M->z);
  for (i = 0; i < M->n; i++) {
    E += 0.5 * p[i] * p[i] / M->m[i] + 0.5 * M->c * M->c * u[i] * M->z[i];
    if (pot(M, u[i], &V, NULL, NULL) == 0)
      E += M->m[i] * V;
  }
  return E;
}

/* K x = c^2 S x + diag(*0 V''(ubar)) x */
static void apply_K(dm_msym_dec *M, const double *x, double *y)
{
  dm_sparse_gemv(M->S, x, y);
  for (size_t i = 0; i < M->n; i++) {
    double d2V = 0;
    pot(M, M->ub[i], NULL, NULL, &d2V);
    y[i] = M->c * M->c * y[i] + M->m[i] * d2V * x[i];
  }
}

int dm_msym_dec_tangent(dm_msym_dec *M, const double *u0, const double *u1, const double *du0,
                        const double *dp0, double *du1, double *dp1, dm_err *e)
{
  size_t n = M->n, i;
  double dt = M->dt;
  int it, st;
  for (i = 0; i < n; i++)
    M->ub[i] = 0.5 * (u0[i] + u1[i]);
  /* (*0/dt + dt/4 K) du1 = dp0 + *0 du0/dt - dt/4 K du0, by iterating on the
   * factored *0/dt + dt/4 c^2 S (the V'' part moves to the right) */
  apply_K(M, du0, M->w);
  for (i = 0; i < n; i++) {
    M->r[i] = dp0[i] + M->m[i] * du0[i] / dt - 0.25 * dt * M->w[i];
    du1[i] = du0[i];
  }
  for (it = 0; it < 200; it++) {
    double d = 0, xs = 1e-300;
    apply_K(M, du1, M->w);
    dm_sparse_gemv(M->S, du1, M->z);
    for (i = 0; i < n; i++)          /* the V'' part of K du1 */
      M->d[i] = M->r[i] - 0.25 * dt * (M->w[i] - M->c * M->c * M->z[i]);
    if ((st = dm_sparse_chol_solve(M->A, 1, M->d, M->z, e)) != DM_OK)
      return st;
    for (i = 0; i < n; i++) {
      d = fmax(d, fabs(M->z[i] - du1[i]));
      xs = fmax(xs, fabs(M->z[i]));
      du1[i] = M->z[i];
    }
    if (d <= 4 * DBL_EPSILON * xs)
      break;
  }
  for (i = 0; i < n; i++)
    M->z[i] = du0[i] + du1[i];
  apply_K(M, M->z, M->w);
  for (i = 0; i < n; i++)
    dp1[i] = M->m[i] * (du1[i] - du0[i]) / dt - 0.25 * dt * M->w[i];
  return DM_OK;
}
