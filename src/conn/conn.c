/* conn.c -- continuous connections on a trivial bundle S x G: the local
 * form, the connection 1-form, horizontal lifts, curvature, and transport
 * and holonomy along shape paths by 4th-order Magnus or adaptive rk8pd
 * (doc/bundles-connections-holonomy.md §3). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "conn/conn_impl.h"
#include "core/interrupt.h"

dm_conn *dm_conn_alloc(const dm_conn_bundle *B, dm_conn_fn fn, void *ud, int has_dA,
                       void (*free_ud)(void *), dm_err *e)
{
  dm_conn *C;
  size_t dim, nx;
  if (B == NULL || fn == NULL) {
    dm_err_set(e, DM_EINVAL, "connection: bundle and local form expected");
    return NULL;
  }
  if (!dm_conn_bundle_is_trivial(B)) {
    dm_err_set(e, DM_EUNSUP, "connection: a local connection form needs a trivial bundle "
               "S x G (the %s bundle has no global trivialization for it)", B->type->name);
    return NULL;
  }
  dim = B->G->dim;
  nx = B->nx;
  if (nx == 0) {
    dm_err_set(e, DM_EINVAL, "connection: the shape space has dimension 0 (Q = G): a "
               "continuous connection has nothing to lift");
    return NULL;
  }
  if ((C = calloc(1, sizeof *C)) == NULL ||
      (C->A = calloc(2 * dim * nx + nx * dim * nx + 1, sizeof *C->A)) == NULL) {
    free(C);
    dm_err_set(e, DM_ENOMEM, "connection: out of memory");
    return NULL;
  }
  C->A2 = C->A + dim * nx;
  C->dA = C->A2 + dim * nx;
  C->B = B;
  C->fn = fn;
  C->ud = ud;
  C->has_dA = has_dA;
  C->free_ud = free_ud;
  C->dim = dim;
  C->nx = nx;
  return C;
}

void dm_conn_free(dm_conn *C)
{
  if (C == NULL)
    return;
  if (C->free_ud)
    C->free_ud(C->ud);
  free(C->A);
  free(C);
}

const dm_conn_bundle *dm_conn_bundle_of(const dm_conn *C)
{
  return C->B;
}

static int call_A(dm_conn *C, const double *x, double *A, double *dA, dm_err *e)
{
  size_t k;
  int st = C->fn(C->ud, x, A, dA, e);
  if (st != DM_OK)
    return st;
  for (k = 0; k < C->dim * C->nx; k++)
    if (!isfinite(A[k]))
      return dm_err_set(e, DM_EDOM, "connection: A_loc is not finite at x = (%g%s)", x[0],
                        C->nx > 1 ? ", ..." : "");
  return DM_OK;
}

int dm_conn_local(dm_conn *C, const double *x, double *A, dm_err *e)
{
  return call_A(C, x, A, NULL, e);
}

/* y = A v (dim x nx times nx) */
static void matvec(const double *A, size_t r, size_t c, const double *v, double *y)
{
  size_t i, j;
  for (i = 0; i < r; i++) {
    double s = 0.0;
    for (j = 0; j < c; j++)
      s += A[i * c + j] * v[j];
    y[i] = s;
  }
}

int dm_conn_form(dm_conn *C, const double *q, const double *xdot, const double *xi,
                 double *out, dm_err *e)
{
  double w[DM_LIE_DIM_MAX];
  size_t a;
  int st = call_A(C, q, C->A, NULL, e);
  if (st != DM_OK)
    return st;
  matvec(C->A, C->dim, C->nx, xdot, w);
  for (a = 0; a < C->dim; a++)
    w[a] += xi[a];
  dm_lie_Ad_apply(C->B->G, q + C->nx, w, out);
  return DM_OK;
}

int dm_conn_hlift_vec(dm_conn *C, const double *x, const double *xdot, double *xi, dm_err *e)
{
  size_t a;
  int st = call_A(C, x, C->A, NULL, e);
  if (st != DM_OK)
    return st;
  matvec(C->A, C->dim, C->nx, xdot, xi);
  for (a = 0; a < C->dim; a++)
    xi[a] = -xi[a];
  return DM_OK;
}

/* d A_ai / d x_k into col (dim values), exact or central differences */
static int dA_col(dm_conn *C, const double *x, size_t k, size_t i, double *col, dm_err *e)
{
  double xp[DM_CONN_NX_MAX], h;
  size_t a;
  int st;
  if (C->has_dA) {
    if ((st = C->fn(C->ud, x, C->A, C->dA, e)) != DM_OK)
      return st;
    for (a = 0; a < C->dim; a++)
      col[a] = C->dA[(k * C->dim + a) * C->nx + i];
    return DM_OK;
  }
  memcpy(xp, x, C->nx * sizeof *x);
  h = 1e-5 * fmax(1.0, fabs(x[k]));
  xp[k] = x[k] + h;
  if ((st = call_A(C, xp, C->A, NULL, e)) != DM_OK)
    return st;
  xp[k] = x[k] - h;
  if ((st = call_A(C, xp, C->A2, NULL, e)) != DM_OK)
    return st;
  for (a = 0; a < C->dim; a++)
    col[a] = (C->A[a * C->nx + i] - C->A2[a * C->nx + i]) / (2.0 * h);
  return DM_OK;
}

int dm_conn_curvature(dm_conn *C, const double *x, size_t i, size_t j, double *b, dm_err *e)
{
  double dij[DM_LIE_DIM_MAX], dji[DM_LIE_DIM_MAX], ai[DM_LIE_DIM_MAX], aj[DM_LIE_DIM_MAX],
         br[DM_LIE_DIM_MAX];
  size_t a;
  int st;
  if (i >= C->nx || j >= C->nx)
    return dm_err_set(e, DM_EINVAL, "curvature: directions must be 1..%zu, got %zu and %zu",
                      C->nx, i + 1, j + 1);
  if ((st = dA_col(C, x, i, j, dij, e)) != DM_OK || (st = dA_col(C, x, j, i, dji, e)) != DM_OK ||
      (st = call_A(C, x, C->A, NULL, e)) != DM_OK)
    return st;
  for (a = 0; a < C->dim; a++) {
    ai[a] = C->A[a * C->nx + i];
    aj[a] = C->A[a * C->nx + j];
  }
  dm_lie_bracket(C->B->G, ai, aj, br);
  for (a = 0; a < C->dim; a++)
    b[a] = dij[a] - dji[a] - br[a];
  return DM_OK;
}

/* {==== transport ============================================================ */

/* M(s) = -A_loc(x(s)) x'(s) */
static int eval_M(dm_conn *C, dm_conn_curve_fn curve, void *ud, double s, double *M, dm_err *e)
{
  double x[DM_CONN_NX_MAX], dx[DM_CONN_NX_MAX];
  size_t a;
  int st = curve(ud, s, x, dx, e);
  if (st != DM_OK)
    return st;
  if ((st = call_A(C, x, C->A, NULL, e)) != DM_OK)
    return st;
  matvec(C->A, C->dim, C->nx, dx, M);
  for (a = 0; a < C->dim; a++)
    M[a] = -M[a];
  return DM_OK;
}

/* H <- H exp(Omega) per piece, Omega = h/2 (M1 + M2) + (sqrt3/12) h^2 [M1, M2]
 * at the Gauss points s = 1/2 -+ sqrt3/6 of the piece */
static int magnus(dm_conn *C, dm_conn_curve_fn curve, void *ud, size_t n, double *H, dm_err *e)
{
  const dm_lie_group *G = C->B->G;
  const double c1 = 0.5 - sqrt(3.0) / 6.0, c2 = 0.5 + sqrt(3.0) / 6.0, kb = sqrt(3.0) / 12.0;
  double M1[DM_LIE_DIM_MAX], M2[DM_LIE_DIM_MAX], br[DM_LIE_DIM_MAX], Om[DM_LIE_DIM_MAX],
         E[DM_LIE_NQ_MAX];
  double h = 1.0 / (double)n;
  size_t k, a;
  int st;
  dm_lie_identity(G, H);
  for (k = 0; k < n; k++) {
    double s = (double)k * h;
    if ((st = eval_M(C, curve, ud, s + c1 * h, M1, e)) != DM_OK ||
        (st = eval_M(C, curve, ud, s + c2 * h, M2, e)) != DM_OK)
      return st;
    if (G->abelian) {
      for (a = 0; a < C->dim; a++)
        Om[a] = 0.5 * h * (M1[a] + M2[a]);
    } else {
      dm_lie_bracket(G, M1, M2, br);
      for (a = 0; a < C->dim; a++)
        Om[a] = 0.5 * h * (M1[a] + M2[a]) + kb * h * h * br[a];
    }
    dm_lie_exp(G, Om, E);
    dm_lie_compose(G, H, E, H);
  }
  return DM_OK;
}

typedef struct ode_ctx {
  dm_conn *C;
  dm_conn_curve_fn curve;
  void *ud;
  dm_err *e;
  int st;
} ode_ctx;

/* dg/ds = sum_k M_k(s) (d/de g exp(e e_k)) in storage coordinates */
static int ode_rhs(double s, const double y[], double f[], void *params)
{
  ode_ctx *o = params;
  const dm_lie_group *G = o->C->B->G;
  double M[DM_LIE_DIM_MAX], dg[DM_LIE_NQ_MAX];
  size_t k, a;
  if ((o->st = eval_M(o->C, o->curve, o->ud, s, M, o->e)) != DM_OK)
    return GSL_EBADFUNC;
  for (a = 0; a < G->nq; a++)
    f[a] = 0.0;
  for (k = 0; k < G->dim; k++) {
    dm_lie_generator(G, y, k, DM_LIE_LEFT, dg);
    for (a = 0; a < G->nq; a++)
      f[a] += M[k] * dg[a];
  }
  return GSL_SUCCESS;
}

static int adaptive(dm_conn *C, dm_conn_curve_fn curve, void *ud, double tol, double *H,
                    dm_err *e)
{
  const dm_lie_group *G = C->B->G;
  ode_ctx o = {C, curve, ud, e, DM_OK};
  gsl_odeiv2_system sys = {ode_rhs, NULL, G->nq, &o};
  gsl_odeiv2_driver *d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-2, tol,
                                                       tol);
  double s = 0.0;
  int gst;
  if (d == NULL)
    return dm_err_set(e, DM_ENOMEM, "transport: out of memory");
  dm_lie_identity(G, H);
  gst = gsl_odeiv2_driver_apply(d, &s, 1.0, H);
  gsl_odeiv2_driver_free(d);
  if (o.st != DM_OK)
    return o.st;
  if (gst != GSL_SUCCESS)
    return dm_err_set(e, dm_from_gsl(gst), "transport: adaptive integration failed (%s) at "
                      "s = %g", gsl_strerror(gst), s);
  dm_lie_normalize(G, H);
  return DM_OK;
}

int dm_conn_transport(dm_conn *C, dm_conn_curve_fn curve, void *ud, const dm_conn_topts *o,
                      double *H, dm_err *e)
{
  dm_conn_topts def = {8, 0.0};
  if (o == NULL)
    o = &def;
  if (o->tol > 0.0)
    return adaptive(C, curve, ud, o->tol, H, e);
  if (o->substeps < 1)
    return dm_err_set(e, DM_EINVAL, "transport: substeps must be >= 1");
  return magnus(C, curve, ud, o->substeps, H, e);
}

typedef struct seg {
  const dm_conn_bundle *B;
  const double *x0, *x1;
} seg;

static int seg_curve(void *ud, double s, double *x, double *dx, dm_err *e)
{
  seg *g = ud;
  (void)e;
  g->B->type->shape_interp(g->B, g->x0, g->x1, s, x, dx);
  return DM_OK;
}

int dm_conn_transport_segment(dm_conn *C, const double *x0, const double *x1,
                              const dm_conn_topts *o, double *H, dm_err *e)
{
  seg g = {C->B, x0, x1};
  return dm_conn_transport(C, seg_curve, &g, o, H, e);
}

/* spatial = g0 P g0^-1, body = P */
static void holo_out(const dm_lie_group *G, const double *g0, const double *P, double *spatial,
                     double *body)
{
  double t[DM_LIE_NQ_MAX], gi[DM_LIE_NQ_MAX];
  if (spatial) {
    dm_lie_inverse(G, g0, gi);
    dm_lie_compose(G, g0, P, t);
    dm_lie_compose(G, t, gi, spatial);
  }
  if (body)
    memcpy(body, P, G->nq * sizeof *P);
}

static int closed_check(size_t nx, const double *a, const double *b, const char *what, dm_err *e)
{
  size_t i;
  for (i = 0; i < nx; i++)
    if (!(fabs(a[i] - b[i]) <= 1e-9 * fmax(1.0, fabs(a[i]))))
      return dm_err_set(e, DM_EINVAL, "%s: the loop is not closed (coordinate %zu starts at "
                        "%.17g and ends at %.17g)", what, i + 1, a[i], b[i]);
  return DM_OK;
}

int dm_conn_holonomy(dm_conn *C, size_t npieces, const dm_conn_curve_fn *curves,
                     void *const *uds, const double *q0, const dm_conn_topts *o,
                     double *spatial, double *body, dm_err *e)
{
  const dm_lie_group *G = C->B->G;
  double P[DM_LIE_NQ_MAX], H[DM_LIE_NQ_MAX], xs[DM_CONN_NX_MAX], xe[DM_CONN_NX_MAX],
         d[DM_CONN_NX_MAX];
  size_t k;
  int st;
  if (npieces < 1)
    return dm_err_set(e, DM_EINVAL, "holonomy: at least one path expected");
  if ((st = curves[0](uds[0], 0.0, xs, d, e)) != DM_OK ||
      (st = curves[npieces - 1](uds[npieces - 1], 1.0, xe, d, e)) != DM_OK)
    return st;
  if ((st = closed_check(C->nx, xs, xe, "holonomy", e)) != DM_OK ||
      (st = closed_check(C->nx, q0, xs, "holonomy (q0 over the start)", e)) != DM_OK)
    return st;
  dm_lie_identity(G, P);
  for (k = 0; k < npieces; k++) {
    if (dm_interrupted())
      return dm_err_set(e, DM_EINTR, "holonomy: interrupted");
    if ((st = dm_conn_transport(C, curves[k], uds[k], o, H, e)) != DM_OK)
      return st;
    dm_lie_compose(G, P, H, P);
  }
  holo_out(G, q0 + C->nx, P, spatial, body);
  return DM_OK;
}

int dm_conn_transport_polygon(dm_conn *C, const double *xs, size_t n, const dm_conn_topts *o,
                              double *H, dm_err *e)
{
  const dm_lie_group *G = C->B->G;
  double P[DM_LIE_NQ_MAX];
  size_t k;
  int st;
  if (n < 2)
    return dm_err_set(e, DM_EINVAL, "transport: a polygon needs at least 2 points, got %zu", n);
  dm_lie_identity(G, H);
  for (k = 0; k + 1 < n; k++) {
    if ((k & 1023) == 1023 && dm_interrupted())
      return dm_err_set(e, DM_EINTR, "transport: interrupted at edge %zu of %zu", k + 1, n - 1);
    if ((st = dm_conn_transport_segment(C, xs + k * C->nx, xs + (k + 1) * C->nx, o, P, e)) != DM_OK)
      return st;
    dm_lie_compose(G, H, P, H);
  }
  return DM_OK;
}

int dm_conn_holonomy_polygon(dm_conn *C, const double *xs, size_t n, const double *q0,
                             const dm_conn_topts *o, double *spatial, double *body, dm_err *e)
{
  double P[DM_LIE_NQ_MAX];
  int st;
  if (n < 2)
    return dm_err_set(e, DM_EINVAL, "holonomy: a loop needs at least 2 points, got %zu", n);
  if ((st = closed_check(C->nx, xs, xs + (n - 1) * C->nx, "holonomy", e)) != DM_OK ||
      (st = closed_check(C->nx, q0, xs, "holonomy (q0 over the first point)", e)) != DM_OK ||
      (st = dm_conn_transport_polygon(C, xs, n, o, P, e)) != DM_OK)
    return st;
  holo_out(C->B->G, q0 + C->nx, P, spatial, body);
  return DM_OK;
}

/* }==== */
