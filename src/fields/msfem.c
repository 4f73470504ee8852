/* msfem.c -- the 1-D multiscale finite element method exact at the nodes
 * (doc/beyond-fixed-steps.md §4.1; thesis appendix C) and the standard linear
 * elements it is compared with.  Quadrature: GSL QAG (adaptive
 * Gauss-Kronrod 61); the tridiagonal system: gsl_linalg_solve_symm_tridiag.
 * See fields.h. */
#include <config.h>
#include "fields/fields.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_linalg.h>

#define LIMIT 2000

typedef struct ctx {
  const dm_msfem_problem *P;
  gsl_integration_workspace *outer, *inner;
  double tol;
  int rc;                    /* first callback failure */
  const char *who;           /* which function failed */
  char arg;                  /* its argument: 'x' or 'y' */
  double where;
  /* the element: its ends, Phi at its left end, D, the side (+1: rising) */
  double xa, xb, D;
  int side;
} ctx;

static double call(ctx *c, dm_fn1 f, void *data, double x, const char *who, char arg)
{
  double y;
  int rc = f(data, x, &y);
  if (rc != 0 || !isfinite(y)) {
    if (c->rc == 0) {
      c->rc = rc != 0 ? rc : 1;
      c->who = rc != 0 ? who : "a non-finite value of the function";
      c->arg = arg;
      c->where = x;
    }
    return 0.0;
  }
  return y;
}

static double inv_a(double x, void *p)
{
  ctx *c = p;
  double a = call(c, c->P->a, c->P->adata, x / c->P->eps, "a", 'y');
  if (c->rc == 0 && !(a > 0)) {
    c->rc = 1;
    c->who = "a <= 0 (a must be positive)";
    c->arg = 'y';
    c->where = x / c->P->eps;
  }
  return c->rc == 0 ? 1.0 / a : 0.0;
}

static double a_of(double x, void *p)
{
  ctx *c = p;
  return call(c, c->P->a, c->P->adata, x / c->P->eps, "a", 'y');
}

static int qag(ctx *c, gsl_integration_workspace *w, double (*fn)(double, void *), double lo,
               double hi, double *out)
{
  gsl_function F = {fn, c};
  double err;
  int st = gsl_integration_qag(&F, lo, hi, 0.0, c->tol, LIMIT, GSL_INTEG_GAUSS61, w, out, &err);
  if (c->rc != 0)
    return DM_ECALLBACK;
  /* a tolerance below what the integrand allows is not a failure: keep QAG's best */
  return st == GSL_SUCCESS || st == GSL_EROUND || st == GSL_ETOL ? DM_OK : DM_ENOCONV;
}

/* Phi(x) - Phi(xa) */
static double phi_rel(ctx *c, double x)
{
  double v;
  if (c->P->Phi != NULL)
    return call(c, c->P->Phi, c->P->phidata, x, "Phi", 'x')
           - call(c, c->P->Phi, c->P->phidata, c->xa, "Phi", 'x');
  if (qag(c, c->inner, inv_a, c->xa, x, &v) != DM_OK && c->rc == 0) {
    c->rc = 1;
    c->who = "the quadrature of 1/a";
    c->arg = 'x';
    c->where = x;
  }
  return v;
}

/* f(x) times the multiscale shape function on the element */
static double load_ms(double x, void *p)
{
  ctx *c = p;
  double fx = call(c, c->P->f, c->P->fdata, x, "f", 'x'), r = phi_rel(c, x) / c->D;
  return fx * (c->side > 0 ? r : 1.0 - r);
}

/* f(x) times the hat function on the element */
static double load_lin(double x, void *p)
{
  ctx *c = p;
  double fx = call(c, c->P->f, c->P->fdata, x, "f", 'x'), r = (x - c->xa) / (c->xb - c->xa);
  return fx * (c->side > 0 ? r : 1.0 - r);
}

int dm_msfem1d(const dm_msfem_problem *P, size_t N, int method, double *x, double *U,
               dm_err *e)
{
  ctx c;
  double *D = NULL, *diag, *off, *rhs, *sol;
  size_t i;
  int st = DM_OK;
  if (N < 3 || N > 1000000)
    return dm_err_set(e, DM_EINVAL, "msfem: need 3 <= N <= 1e6 elements, got %zu", N);
  if (!(P->eps > 0) || !isfinite(P->eps))
    return dm_err_set(e, DM_EINVAL, "msfem: eps must be finite and > 0");
  if (P->a == NULL || P->f == NULL)
    return dm_err_set(e, DM_EINVAL, "msfem: the coefficient a and the load f are required");
  if (method != DM_MSFEM_MULTISCALE && method != DM_MSFEM_LINEAR)
    return dm_err_set(e, DM_EINVAL, "msfem: unknown method %d", method);
  memset(&c, 0, sizeof c);
  c.P = P;
  c.tol = P->tol > 0 ? P->tol : 1e-13;
  c.outer = gsl_integration_workspace_alloc(LIMIT);
  c.inner = gsl_integration_workspace_alloc(LIMIT);
  D = malloc((5 * N + 1) * sizeof *D);
  if (c.outer == NULL || c.inner == NULL || D == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "msfem: out of memory");
    goto done;
  }
  diag = D + N;
  off = diag + N;
  rhs = off + N;
  sol = rhs + N;
  for (i = 0; i <= N; i++)
    x[i] = (double)i / (double)N;
  /* element "conductances": 1/D_i (multiscale), the mean of a over h / h^2 (linear) */
  for (i = 1; i <= N && st == DM_OK; i++) {
    c.xa = x[i - 1];
    c.xb = x[i];
    if (method == DM_MSFEM_MULTISCALE) {
      if (P->Phi != NULL)
        D[i - 1] = phi_rel(&c, x[i]);
      else
        st = qag(&c, c.outer, inv_a, x[i - 1], x[i], &D[i - 1]);
      D[i - 1] = 1.0 / D[i - 1];
    } else {
      st = qag(&c, c.outer, a_of, x[i - 1], x[i], &D[i - 1]);
      D[i - 1] /= (x[i] - x[i - 1]) * (x[i] - x[i - 1]);
    }
  }
  /* A_ij = -int a phi_i' phi_j' on the interior nodes 1..N-1; F_i = int f phi_i */
  for (i = 1; i < N && st == DM_OK; i++) {
    double left, right;
    diag[i - 1] = -(D[i - 1] + D[i]);
    off[i - 1] = D[i];
    c.xa = x[i - 1];
    c.xb = x[i];
    c.side = 1;
    c.D = 1.0 / D[i - 1];
    if ((st = qag(&c, c.outer, method == DM_MSFEM_MULTISCALE ? load_ms : load_lin, x[i - 1], x[i],
                  &left)) != DM_OK)
      break;
    c.xa = x[i];
    c.xb = x[i + 1];
    c.side = -1;
    c.D = 1.0 / D[i];
    if ((st = qag(&c, c.outer, method == DM_MSFEM_MULTISCALE ? load_ms : load_lin, x[i], x[i + 1],
                  &right)) != DM_OK)
      break;
    rhs[i - 1] = left + right;
  }
  if (st == DM_ECALLBACK || c.rc != 0) {
    st = dm_err_set(e, c.rc < 0 ? DM_ECALLBACK : DM_EDOM, "msfem: %s at %c = %.17g", c.who,
                    c.arg, c.where);
    goto done;
  }
  if (st != DM_OK) {
    st = dm_err_set(e, st, "msfem: the adaptive quadrature did not converge");
    goto done;
  }
  {
    gsl_vector_view dv = gsl_vector_view_array(diag, N - 1), ov = gsl_vector_view_array(off, N - 2),
                    rv = gsl_vector_view_array(rhs, N - 1), sv = gsl_vector_view_array(sol, N - 1);
    if (gsl_linalg_solve_symm_tridiag(&dv.vector, &ov.vector, &rv.vector, &sv.vector) != GSL_SUCCESS) {
      st = dm_err_set(e, DM_ESINGULAR, "msfem: the stiffness matrix is singular");
      goto done;
    }
  }
  U[0] = U[N] = 0.0;
  for (i = 1; i < N; i++)
    U[i] = sol[i - 1];
done:
  gsl_integration_workspace_free(c.outer);
  gsl_integration_workspace_free(c.inner);
  free(D);
  return st;
}
