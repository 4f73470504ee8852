/* bundle.c -- principal bundles: the trivial bundle S x G, the frame
 * bundle SO(3) -> S^2 of the sphere, n particles in R^3 under the diagonal
 * rotation (doc/bundles-connections-holonomy.md §2).  Each is a type object;
 * the dispatch functions at the end check what a type does not provide. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>

#include "conn/conn_impl.h"

static dm_conn_bundle *bundle_new(const dm_conn_bundle_type *T, const dm_lie_group *G,
                                  dm_err *e)
{
  dm_conn_bundle *B = calloc(1, sizeof *B);
  if (B == NULL) {
    dm_err_set(e, DM_ENOMEM, "bundle: out of memory");
    return NULL;
  }
  B->type = T;
  if ((B->G = dm_lie_group_copy(G, e)) == NULL) {
    free(B);
    return NULL;
  }
  return B;
}

void dm_conn_bundle_free(dm_conn_bundle *B)
{
  if (B == NULL)
    return;
  dm_lie_group_free(B->G);
  free(B);
}

/* {==== trivial S x G ======================================================= */

static void triv_act(const dm_conn_bundle *B, const double *g, const double *q, double *gq)
{
  if (gq != q)
    memcpy(gq, q, B->nx * sizeof *q);
  dm_lie_compose(B->G, g, q + B->nx, gq + B->nx);
}

static void triv_proj(const dm_conn_bundle *B, const double *q, double *x)
{
  memcpy(x, q, B->nx * sizeof *x);
}

static int triv_fiber_diff(const dm_conn_bundle *B, const double *q, const double *q2, double *g,
                           dm_err *e)
{
  double gi[DM_LIE_NQ_MAX];
  (void)e;
  dm_lie_inverse(B->G, q + B->nx, gi);
  dm_lie_compose(B->G, q2 + B->nx, gi, g);
  return DM_OK;
}

static int triv_section(const dm_conn_bundle *B, const double *x, double *q, dm_err *e)
{
  (void)e;
  memcpy(q, x, B->nx * sizeof *x);
  dm_lie_identity(B->G, q + B->nx);
  return DM_OK;
}

static int triv_trivialize(const dm_conn_bundle *B, const double *q, double *x, double *g)
{
  memcpy(x, q, B->nx * sizeof *x);
  memcpy(g, q + B->nx, B->G->nq * sizeof *g);
  return DM_OK;
}

static int triv_act_sym(dm_expr_ctx *c, const dm_conn_bundle *B, const dm_expr *g,
                        const dm_expr *q, dm_expr *gq, dm_err *e)
{
  memcpy(gq, q, B->nx * sizeof *q);
  return dm_lie_sym_compose(c, B->G, g, q + B->nx, gq + B->nx, e);
}

static int finite_check(const dm_conn_bundle *B, const double *x, const char *what, dm_err *e)
{
  size_t i;
  for (i = 0; i < B->nx; i++)
    if (!isfinite(x[i]))
      return dm_err_set(e, DM_EDOM, "%s: shape coordinate %zu is %g", what, i + 1, x[i]);
  return DM_OK;
}

static void line_interp(const dm_conn_bundle *B, const double *x0, const double *x1, double s,
                        double *xs, double *dxs)
{
  size_t i;
  for (i = 0; i < B->nx; i++) {
    xs[i] = x0[i] + s * (x1[i] - x0[i]);
    dxs[i] = x1[i] - x0[i];
  }
}

static const dm_conn_bundle_type trivial_type = {
  "trivial", triv_act, triv_proj, triv_fiber_diff, triv_section, triv_trivialize,
  triv_act_sym, finite_check, line_interp
};

dm_conn_bundle *dm_conn_bundle_trivial(size_t m, const dm_lie_group *G, dm_err *e)
{
  dm_conn_bundle *B;
  if (G == NULL || m > DM_CONN_NX_MAX || m + G->nq > DM_CONN_NQ_MAX) {
    dm_err_set(e, DM_EINVAL, "bundle: shape dimension must be 0..%d and the group given",
               DM_CONN_NX_MAX);
    return NULL;
  }
  if ((B = bundle_new(&trivial_type, G, e)) == NULL)
    return NULL;
  B->nx = B->dimS = m;
  B->nq = m + G->nq;
  snprintf(B->name, sizeof B->name, "R%zu x %s", m, G->name);
  return B;
}

int dm_conn_bundle_is_trivial(const dm_conn_bundle *B)
{
  return B != NULL && B->type == &trivial_type;
}

/* }==== */

/* {==== the sphere frames SO(3) -> S^2, G = SO(2) =========================== */

/* R Rz(t): columns 1, 2 of R turned by t in their plane */
static void sf_act(const dm_conn_bundle *B, const double *g, const double *q, double *gq)
{
  double c = cos(g[0]), s = sin(g[0]);
  int i;
  (void)B;
  for (i = 0; i < 3; i++) {
    double a = q[3 * i], b = q[3 * i + 1];
    gq[3 * i] = c * a + s * b;
    gq[3 * i + 1] = -s * a + c * b;
    gq[3 * i + 2] = q[3 * i + 2];
  }
}

static void sf_proj(const dm_conn_bundle *B, const double *q, double *x)
{
  (void)B;
  x[0] = q[2];
  x[1] = q[5];
  x[2] = q[8];
}

/* R^T R2 = Rz(t): t = atan2(M10, M00) */
static int sf_fiber_diff(const dm_conn_bundle *B, const double *q, const double *q2, double *g,
                         dm_err *e)
{
  double m00 = 0.0, m10 = 0.0;
  int k;
  (void)B;
  (void)e;
  for (k = 0; k < 3; k++) {
    m00 += q[3 * k] * q2[3 * k];
    m10 += q[3 * k + 1] * q2[3 * k];
  }
  g[0] = atan2(m10, m00);
  return DM_OK;
}

static int sf_check(const dm_conn_bundle *B, const double *x, const char *what, dm_err *e)
{
  double r;
  int st = finite_check(B, x, what, e);
  if (st != DM_OK)
    return st;
  r = dm_conn__norm(x, 3);
  if (fabs(r - 1.0) > 1e-10)
    return dm_err_set(e, DM_EDOM, "%s: a point of the unit sphere expected, got (%g, %g, %g) "
                      "of norm %.17g", what, x[0], x[1], x[2], r);
  return DM_OK;
}

/* great-circle arc from x0 to x1 at constant speed: with v = log_x0(x1),
 * d = |v|, u = v/d: xs = cos(s d) x0 + sin(s d) u (antipodal points have
 * no arc: NaN) */
static void sf_interp(const dm_conn_bundle *B, const double *x0, const double *x1, double s,
                      double *xs, double *dxs)
{
  double v[3], d, c, sn;
  int i;
  (void)B;
  if (dm_lie_sphere_log(2, x0, x1, v, NULL) != DM_OK) {
    for (i = 0; i < 3; i++)
      xs[i] = dxs[i] = NAN;
    return;
  }
  d = dm_conn__norm(v, 3);
  c = cos(s * d);
  sn = sin(s * d);
  for (i = 0; i < 3; i++) {
    double u = d > 0.0 ? v[i] / d : 0.0;
    xs[i] = c * x0[i] + sn * u;
    dxs[i] = d * (-sn * x0[i] + c * u);
  }
}

static const dm_conn_bundle_type sphere_type = {
  "sphere_frames", sf_act, sf_proj, sf_fiber_diff, NULL, NULL, NULL, sf_check, sf_interp
};

dm_conn_bundle *dm_conn_bundle_sphere_frames(dm_err *e)
{
  dm_lie_group *G = dm_lie_so2(e);
  dm_conn_bundle *B;
  if (G == NULL)
    return NULL;
  B = bundle_new(&sphere_type, G, e);
  dm_lie_group_free(G);
  if (B == NULL)
    return NULL;
  B->nq = 9;
  B->nx = 3;
  B->dimS = 2;
  snprintf(B->name, sizeof B->name, "sphere frames SO3 -> S2");
  return B;
}

/* }==== */

/* {==== n particles in R^3, G = SO(3) diagonal ============================= */

/* The frame F (rows e1, e2, e3) of the first two particles; 0 when they
 * are (numerically) linearly dependent. */
static int part_frame(const double *q, double *F)
{
  double n1 = dm_conn__norm(q, 3), d, n2;
  int i;
  if (!(n1 > 0.0) || !isfinite(n1))
    return 0;
  for (i = 0; i < 3; i++)
    F[i] = q[i] / n1;
  d = F[0] * q[3] + F[1] * q[4] + F[2] * q[5];
  for (i = 0; i < 3; i++)
    F[3 + i] = q[3 + i] - d * F[i];
  n2 = dm_conn__norm(F + 3, 3);
  if (!(n2 > 1e-12 * dm_conn__norm(q + 3, 3)) || !isfinite(n2))
    return 0;
  for (i = 0; i < 3; i++)
    F[3 + i] /= n2;
  F[6] = F[1] * F[5] - F[2] * F[4];
  F[7] = F[2] * F[3] - F[0] * F[5];
  F[8] = F[0] * F[4] - F[1] * F[3];
  return 1;
}

static void part_act(const dm_conn_bundle *B, const double *g, const double *q, double *gq)
{
  size_t i;
  for (i = 0; i < B->npart; i++)
    dm_lie_act(B->G, g, q + 3 * i, gq + 3 * i);
}

static void part_proj(const dm_conn_bundle *B, const double *q, double *x)
{
  double F[9];
  size_t i;
  int a;
  if (!part_frame(q, F)) {
    for (i = 0; i < B->nx; i++)
      x[i] = NAN;
    return;
  }
  for (i = 0; i < B->npart; i++) {
    double y[3];
    for (a = 0; a < 3; a++)
      y[a] = F[3 * a] * q[3 * i] + F[3 * a + 1] * q[3 * i + 1] + F[3 * a + 2] * q[3 * i + 2];
    memcpy(x + 3 * i, y, sizeof y);
  }
}

/* q2 = R q: R = F(q2)^T F(q) */
static int part_fiber_diff(const dm_conn_bundle *B, const double *q, const double *q2, double *g,
                           dm_err *e)
{
  double F1[9], F2[9];
  int a, b, k;
  (void)B;
  if (!part_frame(q, F1) || !part_frame(q2, F2))
    return dm_err_set(e, DM_EDOM, "fiber difference: the first two particles are collinear "
                      "with the origin");
  for (a = 0; a < 3; a++)
    for (b = 0; b < 3; b++) {
      double s = 0.0;
      for (k = 0; k < 3; k++)
        s += F2[3 * k + a] * F1[3 * k + b];
      g[3 * a + b] = s;
    }
  return DM_OK;
}

static int part_section(const dm_conn_bundle *B, const double *x, double *q, dm_err *e)
{
  (void)e;
  memcpy(q, x, B->nq * sizeof *x);
  return DM_OK;
}

/* q = F^T . shape */
static int part_trivialize(const dm_conn_bundle *B, const double *q, double *x, double *g)
{
  double F[9];
  int a, b;
  if (!part_frame(q, F))
    return DM_EDOM;
  part_proj(B, q, x);
  for (a = 0; a < 3; a++)
    for (b = 0; b < 3; b++)
      g[3 * a + b] = F[3 * b + a];
  return DM_OK;
}

static int part_act_sym(dm_expr_ctx *c, const dm_conn_bundle *B, const dm_expr *g,
                        const dm_expr *q, dm_expr *gq, dm_err *e)
{
  size_t i;
  int st = DM_OK;
  for (i = 0; i < B->npart && st == DM_OK; i++)
    st = dm_lie_sym_act(c, B->G, g, q + 3 * i, gq + 3 * i, e);
  return st;
}

static int part_check(const dm_conn_bundle *B, const double *x, const char *what, dm_err *e)
{
  double F[9];
  int st = finite_check(B, x, what, e);
  if (st != DM_OK)
    return st;
  if (!part_frame(x, F))
    return dm_err_set(e, DM_EDOM, "%s: the first two particles are collinear with the origin",
                      what);
  return DM_OK;
}

static const dm_conn_bundle_type particles_type = {
  "particles", part_act, part_proj, part_fiber_diff, part_section, part_trivialize,
  part_act_sym, part_check, line_interp
};

dm_conn_bundle *dm_conn_bundle_particles(size_t n, dm_err *e)
{
  dm_lie_group *G;
  dm_conn_bundle *B;
  if (n < 2 || 3 * n > DM_CONN_NX_MAX) {
    dm_err_set(e, DM_EINVAL, "particles bundle: 2 to %d particles expected, got %zu",
               DM_CONN_NX_MAX / 3, n);
    return NULL;
  }
  if ((G = dm_lie_so3(e)) == NULL)
    return NULL;
  B = bundle_new(&particles_type, G, e);
  dm_lie_group_free(G);
  if (B == NULL)
    return NULL;
  B->npart = n;
  B->nq = B->nx = 3 * n;
  B->dimS = 3 * n - 3;
  snprintf(B->name, sizeof B->name, "%zu particles in R3 / SO3", n);
  return B;
}

/* }==== */

/* {==== dispatch ============================================================ */

void dm_conn_act(const dm_conn_bundle *B, const double *g, const double *q, double *gq)
{
  B->type->act(B, g, q, gq);
}

void dm_conn_proj(const dm_conn_bundle *B, const double *q, double *x)
{
  B->type->proj(B, q, x);
}

int dm_conn_fiber_diff(const dm_conn_bundle *B, const double *q, const double *q2, double *g,
                       dm_err *e)
{
  return B->type->fiber_diff(B, q, q2, g, e);
}

int dm_conn_section(const dm_conn_bundle *B, const double *x, double *q, dm_err *e)
{
  if (B->type->section == NULL)
    return dm_err_set(e, DM_EUNSUP, "the %s bundle has no global section", B->type->name);
  return B->type->section(B, x, q, e);
}

int dm_conn_trivialize(const dm_conn_bundle *B, const double *q, double *x, double *g,
                       dm_err *e)
{
  if (B->type->trivialize == NULL)
    return dm_err_set(e, DM_EUNSUP, "the %s bundle has no global trivialization",
                      B->type->name);
  if (B->type->trivialize(B, q, x, g) != DM_OK)
    return dm_err_set(e, DM_EDOM, "trivialize: the point is outside the chart of the %s bundle",
                      B->type->name);
  return DM_OK;
}

int dm_conn_shape_check(const dm_conn_bundle *B, const double *x, const char *what, dm_err *e)
{
  return B->type->shape_check(B, x, what, e);
}

double dm_conn_shape_gap(const dm_conn_bundle *B, const double *q0, const double *q1)
{
  double x0[DM_CONN_NX_MAX], x1[DM_CONN_NX_MAX], g = 0.0;
  size_t i;
  dm_conn_proj(B, q0, x0);
  dm_conn_proj(B, q1, x1);
  for (i = 0; i < B->nx; i++) {
    double d = fabs(x1[i] - x0[i]);
    if (!(d <= g))
      g = d;                  /* NaN propagates */
  }
  return g;
}

void dm_conn_generator(const dm_conn_bundle *B, const double *q, const double *g, double *gq)
{
  dm_conn_act(B, g, q, gq);
}

/* }==== */
