/* dconn.c -- discrete connections: A_d, hor / ver, horizontal lifts,
 * holonomy, the extended pair-groupoid composition, reduction of pairs,
 * the order test and the continuous limit, for any rule (rules.c) on any
 * bundle (doc/bundles-connections-holonomy.md §4-§6). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conn/conn_impl.h"
#include "core/interrupt.h"
#include "integrators/integrator.h"

dm_conn_dc *dm_conn_dc_alloc(const dm_conn_rule *R, const dm_conn_bundle *B, dm_conn *parent,
                             dm_conn_pair_fn local, void *ud, dm_err *e)
{
  dm_conn_dc *D;
  if (R == NULL || B == NULL) {
    dm_err_set(e, DM_EINVAL, "discrete connection: a rule and a bundle expected");
    return NULL;
  }
  if ((R->needs & DM_CONN_NEEDS_TRIVIAL) && !dm_conn_bundle_is_trivial(B)) {
    dm_err_set(e, DM_EINVAL, "discrete connection: rule '%s' needs a trivial bundle S x G, "
               "got the %s bundle", R->name, B->type->name);
    return NULL;
  }
  if ((R->needs & DM_CONN_NEEDS_SPHERE) && strcmp(B->type->name, "sphere_frames") != 0) {
    dm_err_set(e, DM_EINVAL, "discrete connection: rule '%s' is defined on the sphere-frame "
               "bundle, got the %s bundle", R->name, B->type->name);
    return NULL;
  }
  if ((R->needs & DM_CONN_NEEDS_PARENT) && parent == NULL) {
    dm_err_set(e, DM_EINVAL, "discrete connection: rule '%s' is built from a continuous "
               "connection (none given)", R->name);
    return NULL;
  }
  if (parent != NULL && parent->B != B &&
      (parent->B->nx != B->nx || !dm_lie_group_equal(parent->B->G, B->G))) {
    dm_err_set(e, DM_EINVAL, "discrete connection: the continuous connection lives on another "
               "bundle (%s, not %s)", parent->B->name, B->name);
    return NULL;
  }
  if ((R->needs & DM_CONN_NEEDS_LOCAL) && local == NULL) {
    dm_err_set(e, DM_EINVAL, "discrete connection: rule 'local' needs a function A(x0, x1)");
    return NULL;
  }
  if (R->needs & DM_CONN_NEEDS_LD) {
    dm_err_set(e, DM_EINVAL, "discrete connection: rule '%s' is made by "
               "dm_conn_dc_mechanical from a discrete Lagrangian", R->name);
    return NULL;
  }
  if ((D = calloc(1, sizeof *D)) == NULL) {
    dm_err_set(e, DM_ENOMEM, "discrete connection: out of memory");
    return NULL;
  }
  D->R = R;
  D->B = B;
  D->parent = parent;
  D->local = local;
  D->local_ud = ud;
  D->topts.substeps = 8;
  D->topts.tol = 0.0;
  return D;
}

void dm_conn_dc_free(dm_conn_dc *D)
{
  if (D == NULL)
    return;
  dm_conn__mech_free(D->mech);
  free(D);
}

const dm_conn_rule *dm_conn_dc_rule(const dm_conn_dc *D)
{
  return D->R;
}

const dm_conn_bundle *dm_conn_dc_bundle(const dm_conn_dc *D)
{
  return D->B;
}

void dm_conn_dc_set_topts(dm_conn_dc *D, const dm_conn_topts *o)
{
  D->topts = *o;
}

int dm_conn_dc_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e)
{
  if (!dm_conn_bundle_is_trivial(D->B) || D->R->local == NULL)
    return dm_err_set(e, DM_EUNSUP, "local representation: rule '%s' on the %s bundle has none "
                      "(it needs a trivial bundle S x G)", D->R->name, D->B->type->name);
  return D->R->local(D, x0, x1, A, e);
}

int dm_conn_dc_hlift(dm_conn_dc *D, const double *q0, const double *x1, double *q1, dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  const dm_lie_group *G = B->G;
  double A[DM_LIE_NQ_MAX], Ai[DM_LIE_NQ_MAX], x0[DM_CONN_NX_MAX], qt[DM_CONN_NQ_MAX];
  int st;
  if ((st = dm_conn_shape_check(B, x1, "lift: x1", e)) != DM_OK)
    return st;
  if (D->R->hlift)
    return D->R->hlift(D, q0, x1, q1, e);
  if (dm_conn_bundle_is_trivial(B)) {
    dm_conn_proj(B, q0, x0);
    if ((st = D->R->local(D, x0, x1, A, e)) != DM_OK)
      return st;
    memcpy(q1, x1, B->nx * sizeof *x1);
    dm_lie_inverse(G, A, Ai);
    dm_lie_compose(G, q0 + B->nx, Ai, q1 + B->nx);
    return DM_OK;
  }
  /* any point over x1, moved by A_d^-1 */
  if ((st = dm_conn_section(B, x1, qt, e)) != DM_OK || D->R->eval == NULL)
    return st != DM_OK ? st : dm_err_set(e, DM_EUNSUP, "lift: rule '%s' cannot lift on the %s "
                                         "bundle", D->R->name, B->type->name);
  if ((st = D->R->eval(D, q0, qt, A, e)) != DM_OK)
    return st;
  dm_lie_inverse(G, A, Ai);
  dm_conn_act(B, Ai, qt, q1);
  return DM_OK;
}

int dm_conn_dc_eval(dm_conn_dc *D, const double *q0, const double *q1, double *g, dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  double x1[DM_CONN_NX_MAX], qb[DM_CONN_NQ_MAX], A[DM_LIE_NQ_MAX], gi[DM_LIE_NQ_MAX],
         t[DM_LIE_NQ_MAX];
  int st;
  if (D->R->eval)
    return D->R->eval(D, q0, q1, g, e);
  dm_conn_proj(B, q1, x1);
  if (dm_conn_bundle_is_trivial(B)) {
    /* g1 A(x0, x1) g0^-1 */
    if ((st = dm_conn_shape_check(B, x1, "A_d: q1", e)) != DM_OK ||
        (st = D->R->local(D, q0, x1, A, e)) != DM_OK)
      return st;
    dm_lie_inverse(B->G, q0 + B->nx, gi);
    dm_lie_compose(B->G, q1 + B->nx, A, t);
    dm_lie_compose(B->G, t, gi, g);
    return DM_OK;
  }
  if ((st = dm_conn_dc_hlift(D, q0, x1, qb, e)) != DM_OK)
    return st;
  return dm_conn_fiber_diff(B, qb, q1, g, e);
}

int dm_conn_dc_hor(dm_conn_dc *D, const double *q0, const double *q1, double *h1, dm_err *e)
{
  double g[DM_LIE_NQ_MAX], gi[DM_LIE_NQ_MAX];
  int st = dm_conn_dc_eval(D, q0, q1, g, e);
  if (st != DM_OK)
    return st;
  dm_lie_inverse(D->B->G, g, gi);
  dm_conn_act(D->B, gi, q1, h1);
  return DM_OK;
}

int dm_conn_dc_ver(dm_conn_dc *D, const double *q0, const double *q1, double *v1, dm_err *e)
{
  double g[DM_LIE_NQ_MAX];
  int st = dm_conn_dc_eval(D, q0, q1, g, e);
  if (st != DM_OK)
    return st;
  dm_conn_act(D->B, g, q0, v1);
  return DM_OK;
}

/* prefix the message of a failed edge with the edge (copied first: the
 * message is the source and the destination) */
static int edge_err(dm_err *e, int st, const char *what, size_t k)
{
  char m[DM_ERRMSG_MAX];
  if (e == NULL)
    return st;
  memcpy(m, e->msg, sizeof m);
  return dm_err_set(e, st, "%s: edge %zu -> %zu: %s", what, k, k + 1, m);
}

static int over_check(const dm_conn_bundle *B, const double *q0, const double *x, const char *what,
                      dm_err *e)
{
  double x0[DM_CONN_NX_MAX];
  size_t i;
  dm_conn_proj(B, q0, x0);
  for (i = 0; i < B->nx; i++)
    if (!(fabs(x0[i] - x[i]) <= 1e-9 * fmax(1.0, fabs(x[i]))))
      return dm_err_set(e, DM_EINVAL, "%s: q0 is not over the first shape point (coordinate %zu: "
                        "%.17g against %.17g)", what, i + 1, x0[i], x[i]);
  return DM_OK;
}

int dm_conn_dc_lift(dm_conn_dc *D, const double *xs, size_t n, const double *q0, double *qs,
                    dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  size_t k;
  int st;
  if (n < 1)
    return dm_err_set(e, DM_EINVAL, "lift: at least one shape point expected");
  if ((st = dm_conn_shape_check(B, xs, "lift: point 1", e)) != DM_OK ||
      (st = over_check(B, q0, xs, "lift", e)) != DM_OK)
    return st;
  memcpy(qs, q0, B->nq * sizeof *q0);
  for (k = 1; k < n; k++) {
    if ((k & 4095) == 0 && dm_interrupted())
      return dm_err_set(e, DM_EINTR, "lift: interrupted at point %zu of %zu", k + 1, n);
    if ((st = dm_conn_dc_hlift(D, qs + (k - 1) * B->nq, xs + k * B->nx, qs + k * B->nq, e)) != DM_OK)
      return edge_err(e, st, "lift", k);
  }
  return DM_OK;
}

int dm_conn_dc_holonomy(dm_conn_dc *D, const double *xs, size_t n, const double *q0,
                        double *spatial, double *body, double *lifted, dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  const dm_lie_group *G = B->G;
  double qa[DM_CONN_NQ_MAX], qb[DM_CONN_NQ_MAX], S[DM_LIE_NQ_MAX], g0[DM_LIE_NQ_MAX],
         gi[DM_LIE_NQ_MAX], t[DM_LIE_NQ_MAX], x0[DM_CONN_NX_MAX];
  size_t k, i;
  int st;
  if (n < 2)
    return dm_err_set(e, DM_EINVAL, "holonomy: a loop needs at least 2 points, got %zu", n);
  for (i = 0; i < B->nx; i++)
    if (!(fabs(xs[i] - xs[(n - 1) * B->nx + i]) <= 1e-9 * fmax(1.0, fabs(xs[i]))))
      return dm_err_set(e, DM_EINVAL, "holonomy: the loop is not closed (coordinate %zu starts "
                        "at %.17g and ends at %.17g)", i + 1, xs[i], xs[(n - 1) * B->nx + i]);
  if ((st = dm_conn_shape_check(B, xs, "holonomy: point 1", e)) != DM_OK ||
      (st = over_check(B, q0, xs, "holonomy", e)) != DM_OK)
    return st;
  if (dm_conn_bundle_is_trivial(B) && D->R->hlift == NULL) {
    /* g_N = g0 P, P = A(x0, x1)^-1 A(x1, x2)^-1 ... (unwrapped angles
     * compose without reduction): the product directly, no points */
    for (k = 1; k < n; k++)
      if ((st = dm_conn_shape_check(B, xs + k * B->nx, "holonomy: a point", e)) != DM_OK)
        return edge_err(e, st, "holonomy", k);
    dm_lie_identity(G, t);
    for (k = 1; k < n; k++) {
      if ((k & 4095) == 0 && dm_interrupted())
        return dm_err_set(e, DM_EINTR, "holonomy: interrupted at point %zu of %zu", k + 1, n);
      if ((st = D->R->local(D, xs + (k - 1) * B->nx, xs + k * B->nx, S, e)) != DM_OK)
        return edge_err(e, st, "holonomy", k);
      dm_lie_inverse(G, S, gi);
      dm_lie_compose(G, t, gi, t);
    }
    if (lifted)
      *lifted = (G->abelian && G->dim == 1) ? t[0] : NAN;
    if (body)
      memcpy(body, t, G->nq * sizeof *t);
    if (spatial) {
      dm_lie_inverse(G, q0 + B->nx, gi);
      dm_lie_compose(G, q0 + B->nx, t, S);
      dm_lie_compose(G, S, gi, spatial);
    }
    return DM_OK;
  }
  memcpy(qa, q0, B->nq * sizeof *q0);
  for (k = 1; k < n; k++) {
    if ((k & 4095) == 0 && dm_interrupted())
      return dm_err_set(e, DM_EINTR, "holonomy: interrupted at point %zu of %zu", k + 1, n);
    if ((st = dm_conn_dc_hlift(D, qa, xs + k * B->nx, qb, e)) != DM_OK)
      return edge_err(e, st, "holonomy", k);
    memcpy(qa, qb, B->nq * sizeof *qb);
  }
  if ((st = dm_conn_fiber_diff(B, q0, qa, S, e)) != DM_OK)
    return st;
  if (spatial)
    memcpy(spatial, S, G->nq * sizeof *S);
  if (lifted)
    *lifted = (G->abelian && G->dim == 1) ? S[0] : NAN;
  if (body) {
    if (G->abelian) {
      memcpy(body, S, G->nq * sizeof *S);
    } else {
      if ((st = dm_conn_trivialize(B, q0, x0, g0, e)) != DM_OK)
        return st;
      dm_lie_inverse(G, g0, gi);
      dm_lie_compose(G, gi, S, t);
      dm_lie_compose(G, t, g0, body);
    }
  }
  return DM_OK;
}

int dm_conn_dc_compose(dm_conn_dc *D, const double *a0, const double *a1, const double *b0,
                       const double *b1, double *c1, dm_err *e)
{
  double g[DM_LIE_NQ_MAX], gap;
  int st;
  (void)a0;
  gap = dm_conn_shape_gap(D->B, a1, b0);
  if (!(gap <= 1e-9))
    return dm_err_set(e, DM_EINVAL, "compose: the pairs do not meet: the second point of the "
                      "first pair and the first point of the second have different shapes "
                      "(difference %g)", gap);
  if ((st = dm_conn_dc_eval(D, b0, a1, g, e)) != DM_OK)
    return st;
  dm_conn_act(D->B, g, b1, c1);
  return DM_OK;
}

/* g0 of a point (trivialization), for the body representatives */
static int base_g(dm_conn_dc *D, const double *q0, double *x0, double *g0, dm_err *e)
{
  return dm_conn_trivialize(D->B, q0, x0, g0, e);
}

int dm_conn_dc_reduce(dm_conn_dc *D, const double *q0, const double *q1, double *x0, double *x1,
                      double *zeta, dm_err *e)
{
  const dm_lie_group *G = D->B->G;
  double g0[DM_LIE_NQ_MAX], gi[DM_LIE_NQ_MAX], A[DM_LIE_NQ_MAX], t[DM_LIE_NQ_MAX];
  int st;
  if ((st = base_g(D, q0, x0, g0, e)) != DM_OK || (st = dm_conn_dc_eval(D, q0, q1, A, e)) != DM_OK)
    return st;
  dm_conn_proj(D->B, q1, x1);
  dm_lie_inverse(G, g0, gi);
  dm_lie_compose(G, gi, A, t);
  dm_lie_compose(G, t, g0, zeta);
  return DM_OK;
}

int dm_conn_dc_unreduce(dm_conn_dc *D, const double *x0, const double *x1, const double *zeta,
                        const double *q0, double *q1, dm_err *e)
{
  const dm_lie_group *G = D->B->G;
  double g0[DM_LIE_NQ_MAX], gi[DM_LIE_NQ_MAX], t[DM_LIE_NQ_MAX], h[DM_LIE_NQ_MAX],
         xq[DM_CONN_NX_MAX], qb[DM_CONN_NQ_MAX];
  int st;
  if ((st = over_check(D->B, q0, x0, "unreduce", e)) != DM_OK ||
      (st = base_g(D, q0, xq, g0, e)) != DM_OK || (st = dm_conn_dc_hlift(D, q0, x1, qb, e)) != DM_OK)
    return st;
  /* A_d(q0, h qb) = h A_d(q0, qb) = h, h = g0 zeta g0^-1 */
  dm_lie_inverse(G, g0, gi);
  dm_lie_compose(G, g0, zeta, t);
  dm_lie_compose(G, t, gi, h);
  dm_conn_act(D->B, h, qb, q1);
  return DM_OK;
}

int dm_conn_dc_order(dm_conn_dc *D, dm_conn_dc *ref, const double *q, const double *v,
                     const double *h, size_t nh, double *defects, double *slope, dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  const dm_lie_group *G = B->G;
  double q1[DM_CONN_NQ_MAX], a[DM_LIE_NQ_MAX], b[DM_LIE_NQ_MAX];
  size_t k, i;
  int st;
  if (!dm_conn_bundle_is_trivial(B) || ref->B->nq != B->nq || !dm_lie_group_equal(ref->B->G, G))
    return dm_err_set(e, DM_EUNSUP, "order test: needs two discrete connections on one trivial "
                      "bundle S x G");
  if (nh < 2)
    return dm_err_set(e, DM_EINVAL, "order test: at least two step sizes expected, got %zu", nh);
  for (k = 0; k < nh; k++) {
    if (!(h[k] > 0.0))
      return dm_err_set(e, DM_EINVAL, "order test: step sizes must be > 0, got %g", h[k]);
    memcpy(q1, q, B->nq * sizeof *q);
    for (i = 0; i < B->nx; i++)
      q1[i] = q[i] + h[k] * v[i];
    if ((st = dm_conn_dc_eval(ref, q, q1, a, e)) != DM_OK ||
        (st = dm_conn_dc_eval(D, q, q1, b, e)) != DM_OK)
      return st;
    defects[k] = dm_lie_dist(G, b, a);
  }
  if (slope)
    *slope = dm_integrator_order_fit(h, defects, nh);
  return DM_OK;
}

int dm_conn_dc_limit(dm_conn_dc *D, const double *q, const double *xdot, const double *xi,
                     double eps, double *out, dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  const dm_lie_group *G = B->G;
  double qp[DM_CONN_NQ_MAX], gp[DM_LIE_NQ_MAX], w[DM_LIE_DIM_MAX], E[DM_LIE_NQ_MAX],
         lp[DM_LIE_DIM_MAX], lm[DM_LIE_DIM_MAX];
  size_t i, a;
  int st, sgn;
  if (!dm_conn_bundle_is_trivial(B))
    return dm_err_set(e, DM_EUNSUP, "continuous limit: needs a trivial bundle S x G");
  if (!(eps > 0.0))
    return dm_err_set(e, DM_EINVAL, "continuous limit: eps must be > 0, got %g", eps);
  for (sgn = 1; sgn >= -1; sgn -= 2) {
    memcpy(qp, q, B->nq * sizeof *q);
    for (i = 0; i < B->nx; i++)
      qp[i] = q[i] + sgn * eps * xdot[i];
    for (a = 0; a < G->dim; a++)
      w[a] = sgn * eps * xi[a];
    dm_lie_exp(G, w, E);
    dm_lie_compose(G, q + B->nx, E, qp + B->nx);
    if ((st = dm_conn_dc_eval(D, q, qp, gp, e)) != DM_OK)
      return st;
    dm_lie_log(G, gp, sgn > 0 ? lp : lm);
    if (dm_conn__near_cut(G, sgn > 0 ? lp : lm))
      return dm_err_set(e, DM_EDOM, "continuous limit: A_d at the cut locus (a rotation by pi); "
                        "take a smaller eps");
  }
  for (a = 0; a < G->dim; a++)
    out[a] = (lp[a] - lm[a]) / (2.0 * eps);
  return DM_OK;
}
