/* rules.c -- the rules that build discrete connections, as type objects
 * (doc/bundles-connections-holonomy.md §6): from a continuous connection
 * (euler, midpoint, cayley, transport, exact), the trivial connection, a user
 * local representation, the discrete mechanical connection (mechanical.c) and
 * the Levi-Civita connection of the sphere frames.  A new rule is one
 * table here and one line in `rules`. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "conn/conn_impl.h"

/* w = A_loc(x) dx */
static int form_at(dm_conn_dc *D, const double *x, const double *x0, const double *x1,
                   double *w, dm_err *e)
{
  dm_conn *C = D->parent;
  size_t a, i;
  int st = dm_conn_local(C, x, C->A, e);
  if (st != DM_OK)
    return st;
  for (a = 0; a < C->dim; a++) {
    double s = 0.0;
    for (i = 0; i < C->nx; i++)
      s += C->A[a * C->nx + i] * (x1[i] - x0[i]);
    w[a] = s;
  }
  return DM_OK;
}

static void midpoint_of(size_t n, const double *x0, const double *x1, double *xb)
{
  size_t i;
  for (i = 0; i < n; i++)
    xb[i] = 0.5 * (x0[i] + x1[i]);
}

static int euler_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e)
{
  double w[DM_LIE_DIM_MAX];
  int st = form_at(D, x0, x0, x1, w, e);
  if (st == DM_OK)
    dm_lie_exp(D->B->G, w, A);
  return st;
}

static int midpoint_local(dm_conn_dc *D, const double *x0, const double *x1, double *A,
                          dm_err *e)
{
  double w[DM_LIE_DIM_MAX], xb[DM_CONN_NX_MAX];
  int st;
  midpoint_of(D->B->nx, x0, x1, xb);
  if ((st = form_at(D, xb, x0, x1, w, e)) == DM_OK)
    dm_lie_exp(D->B->G, w, A);
  return st;
}

static int cayley_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e)
{
  double w[DM_LIE_DIM_MAX], xb[DM_CONN_NX_MAX];
  int st;
  midpoint_of(D->B->nx, x0, x1, xb);
  if ((st = form_at(D, xb, x0, x1, w, e)) == DM_OK)
    dm_lie_cay(D->B->G, w, A);
  return st;
}

/* A = H^-1, H the continuous body transport along the shape path */
static int transport_local(dm_conn_dc *D, const double *x0, const double *x1, double *A,
                           dm_err *e)
{
  double H[DM_LIE_NQ_MAX];
  int st = dm_conn_transport_segment(D->parent, x0, x1, &D->topts, H, e);
  if (st == DM_OK)
    dm_lie_inverse(D->B->G, H, A);
  return st;
}

/* A_d = exp(log(g1 g0^-1) + Ad_g0 A_loc(x0) dx): the product exponential
 * on S x G; its lift is Euler's */
static int exact_eval(dm_conn_dc *D, const double *q0, const double *q1, double *g, dm_err *e)
{
  const dm_lie_group *G = D->B->G;
  size_t nx = D->B->nx, a;
  double w[DM_LIE_DIM_MAX], aw[DM_LIE_DIM_MAX], eta[DM_LIE_DIM_MAX], gi[DM_LIE_NQ_MAX],
         d[DM_LIE_NQ_MAX];
  int st = form_at(D, q0, q0, q1, w, e);
  if (st != DM_OK)
    return st;
  dm_lie_inverse(G, q0 + nx, gi);
  dm_lie_compose(G, q1 + nx, gi, d);
  dm_lie_log(G, d, eta);
  if (dm_conn__near_cut(G, eta))
    return dm_err_set(e, DM_EDOM, "exact rule: log(g1 g0^-1) at the cut locus (a rotation by "
                      "pi), where the group exponential is not invertible");
  dm_lie_Ad_apply(G, q0 + nx, w, aw);
  for (a = 0; a < G->dim; a++)
    eta[a] += aw[a];
  dm_lie_exp(G, eta, g);
  return DM_OK;
}

static int trivial_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e)
{
  (void)x0;
  (void)x1;
  (void)e;
  dm_lie_identity(D->B->G, A);
  return DM_OK;
}

static int user_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e)
{
  size_t a;
  int st = D->local(D->local_ud, x0, x1, A, e);
  if (st != DM_OK)
    return st;
  for (a = 0; a < D->B->G->nq; a++)
    if (!isfinite(A[a]))
      return dm_err_set(e, DM_EDOM, "local representation: A(x0, x1) is not finite");
  return DM_OK;
}

/* A(x0, x1) = A_d((x0, e), (x1, e)) */
static int mech_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e)
{
  double q0[DM_CONN_NQ_MAX], q1[DM_CONN_NQ_MAX], k[DM_LIE_NQ_MAX];
  int st;
  dm_conn_section(D->B, x0, q0, NULL);
  dm_conn_section(D->B, x1, q1, NULL);
  if ((st = dm_conn__mech_solve(D, q0, q1, k, e)) == DM_OK)
    dm_lie_inverse(D->B->G, k, A);
  return st;
}

/* trivial bundles go through the local representation (the three
 * properties of doc/bundles-connections-holonomy.md §4 then hold exactly);
 * others solve J_d(q0, k q1) = mu directly */
static int mech_eval(dm_conn_dc *D, const double *q0, const double *q1, double *g, dm_err *e)
{
  double k[DM_LIE_NQ_MAX], A[DM_LIE_NQ_MAX], gi[DM_LIE_NQ_MAX], t[DM_LIE_NQ_MAX];
  const dm_lie_group *G = D->B->G;
  size_t nx = D->B->nx;
  int st;
  if (dm_conn_bundle_is_trivial(D->B)) {
    if ((st = mech_local(D, q0, q1, A, e)) != DM_OK)
      return st;
    dm_lie_inverse(G, q0 + nx, gi);
    dm_lie_compose(G, q1 + nx, A, t);
    dm_lie_compose(G, t, gi, g);
    return DM_OK;
  }
  if ((st = dm_conn__mech_solve(D, q0, q1, k, e)) == DM_OK)
    dm_lie_inverse(G, k, g);
  return st;
}

/* the sphere frames: R1 = M(p0, p1) R0, M the rotation about p0 x p1
 * carrying p0 to p1 (parallel transport along the geodesic).  M is built
 * from p0 and p1 normalized: M depends on R0 e3, and without it a frame
 * off SO(3) by e gives an M off by e, so the defect doubles at every
 * edge (2^64 after 64 edges). */
static int lc_hlift(dm_conn_dc *D, const double *q0, const double *x1, double *q1, dm_err *e)
{
  double p0[3], p1[3], M[9];
  int i, j, k, st;
  dm_conn_proj(D->B, q0, p0);
  memcpy(p1, x1, sizeof p1);
  if ((st = dm_lie_sphere_normalize(2, p0, e)) != DM_OK ||
      (st = dm_lie_sphere_normalize(2, p1, e)) != DM_OK)
    return st;
  if ((st = dm_lie_sphere_rotation(p0, p1, M, e)) != DM_OK)
    return dm_err_set(e, st, "levi-civita lift: p1 = -p0 (antipodal points (%g, %g, %g) and "
                      "(%g, %g, %g)): the geodesic between them is not unique", p0[0], p0[1],
                      p0[2], x1[0], x1[1], x1[2]);
  for (i = 0; i < 3; i++)
    for (j = 0; j < 3; j++) {
      double s = 0.0;
      for (k = 0; k < 3; k++)
        s += M[3 * i + k] * q0[3 * k + j];
      q1[3 * i + j] = s;
    }
  return DM_OK;
}

static const dm_conn_rule rule_euler = {
  "euler", 1, DM_CONN_NEEDS_PARENT | DM_CONN_NEEDS_TRIVIAL, euler_local, NULL, NULL
};
static const dm_conn_rule rule_midpoint = {
  "midpoint", 2, DM_CONN_NEEDS_PARENT | DM_CONN_NEEDS_TRIVIAL, midpoint_local, NULL, NULL
};
static const dm_conn_rule rule_cayley = {
  "cayley", 2, DM_CONN_NEEDS_PARENT | DM_CONN_NEEDS_TRIVIAL, cayley_local, NULL, NULL
};
static const dm_conn_rule rule_transport = {
  "transport", 0, DM_CONN_NEEDS_PARENT | DM_CONN_NEEDS_TRIVIAL, transport_local, NULL, NULL
};
static const dm_conn_rule rule_exact = {
  "exact", 1, DM_CONN_NEEDS_PARENT | DM_CONN_NEEDS_TRIVIAL, euler_local, NULL, exact_eval
};
static const dm_conn_rule rule_trivial = {
  "trivial", -1, DM_CONN_NEEDS_TRIVIAL, trivial_local, NULL, NULL
};
static const dm_conn_rule rule_local = {
  "local", -1, DM_CONN_NEEDS_LOCAL | DM_CONN_NEEDS_TRIVIAL, user_local, NULL, NULL
};
static const dm_conn_rule rule_mechanical = {
  "mechanical", -1, DM_CONN_NEEDS_LD, mech_local, NULL, mech_eval
};
static const dm_conn_rule rule_lc = {
  "levi-civita", 0, DM_CONN_NEEDS_SPHERE, NULL, lc_hlift, NULL
};

static const dm_conn_rule *const rules[] = {
  &rule_euler, &rule_midpoint, &rule_cayley, &rule_transport, &rule_exact, &rule_trivial,
  &rule_local, &rule_mechanical, &rule_lc, NULL
};

const dm_conn_rule *dm_conn_rule_find(const char *name)
{
  size_t k;
  if (name == NULL)
    return NULL;
  for (k = 0; rules[k] != NULL; k++)
    if (strcmp(rules[k]->name, name) == 0)
      return rules[k];
  return NULL;
}

const dm_conn_rule *const *dm_conn_rules(void)
{
  return rules;
}
