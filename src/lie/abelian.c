/* abelian.c -- the abelian groups: R^n (translations) and the tori SO(2),
 * T^n (angles stored unwrapped; log gives the principal value).  The
 * Cayley map of a rotation generator omega is the rotation by
 * 2 atan(omega/2). */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lie/lie_impl.h"

/* {==== shared: vector-like storage ====================================== */

static void ab_identity(const dm_lie_group *G, double *g)
{
  memset(g, 0, G->nq * sizeof *g);
}

static void ab_compose(const dm_lie_group *G, const double *a, const double *b, double *ab)
{
  size_t i;
  for (i = 0; i < G->nq; i++)
    ab[i] = a[i] + b[i];
}

static void ab_inverse(const dm_lie_group *G, const double *a, double *ai)
{
  size_t i;
  for (i = 0; i < G->nq; i++)
    ai[i] = -a[i];
}

static void ab_copy(const dm_lie_group *G, const double *x, double *y)
{
  memmove(y, x, G->nq * sizeof *y);
}

static void ab_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  size_t i;
  dm_lie_zero(M, G->dim, G->dim, ld);
  for (i = 0; i < G->dim; i++)
    M[i * ld + i] = 1.0;
}

static void ab_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld)
{
  dm_lie_zero(M, G->dim, G->dim, ld);
}

static void ab_bracket(const dm_lie_group *G, const double *a, const double *b, double *c)
{
  memset(c, 0, G->dim * sizeof *c);
}

static void ab_dexp(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  ab_Ad(G, NULL, M, ld);
}

static double ab_defect(const dm_lie_group *G, const double *g, int *det_ok)
{
  if (det_ok)
    *det_ok = 1;
  return 0.0;
}

static void ab_normalize(const dm_lie_group *G, double *g)
{
}

static void ab_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                         double *dg)
{
  memset(dg, 0, G->nq * sizeof *dg);
  dg[k] = 1.0;
}

/* }====================================================================== */

/* {==== R^n ============================================================== */

static int rn_icay(const dm_lie_group *G, const double *g, double *xi)
{
  ab_copy(G, g, xi);
  return DM_OK;
}

/* homogeneous (n+1) x (n+1): [[0, xi], [0, 0]] and [[I, x], [0, 1]] */
static void rn_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  size_t i, n = G->n;
  dm_lie_zero(A, n + 1, n + 1, ld);
  for (i = 0; i < n; i++)
    A[i * ld + n] = xi[i];
}

static void rn_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  size_t i, n = G->n;
  for (i = 0; i < n; i++)
    xi[i] = A[i * ld + n];
}

static void rn_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  size_t i, n = G->n;
  rn_hat(G, g, M, ld);
  for (i = 0; i <= n; i++)
    M[i * ld + i] = 1.0;
}

static int rn_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g)
{
  size_t i, j, n = G->n;
  for (i = 0; i <= n; i++)
    for (j = 0; j < n + (i == n); j++)
      if (fabs(M[i * ld + j] - (i == j ? 1.0 : 0.0)) > 1e-12)
        return DM_EDOM;
  for (i = 0; i < n; i++)
    g[i] = M[i * ld + n];
  return DM_OK;
}

static void rn_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  ab_compose(G, g, x, y);
}

const dm_lie_type dm_lie_type_rn = {
  "Rn", DM_LIE_RN, ab_identity, ab_compose, ab_inverse, ab_copy, ab_copy,
  ab_Ad, ab_ad, ab_bracket, ab_dexp, ab_copy, rn_icay, ab_dexp, rn_hat, rn_vee,
  rn_matrix, rn_from_matrix, rn_act, ab_normalize, ab_defect, ab_generator,
  &dm_lie_sym_rn
};

/* }====================================================================== */

/* {==== SO(2) and T^n ==================================================== */

static void tn_log(const dm_lie_group *G, const double *g, double *xi)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    xi[i] = dm_lie_wrap(g[i]);
}

static void tn_cay(const dm_lie_group *G, const double *xi, double *g)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    g[i] = 2.0 * atan(0.5 * xi[i]);
}

static int tn_icay(const dm_lie_group *G, const double *g, double *xi)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    if (!(fabs(dm_lie_wrap(g[i])) < M_PI))
      return DM_EDOM;
  for (i = 0; i < G->n; i++)
    xi[i] = 2.0 * tan(0.5 * dm_lie_wrap(g[i]));
  return DM_OK;
}

static void tn_dcay(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  size_t i;
  dm_lie_zero(M, G->n, G->n, ld);
  for (i = 0; i < G->n; i++) {
    double k = 4.0 / (4.0 + xi[i] * xi[i]);
    M[i * ld + i] = inv ? 1.0 / k : k;
  }
}

/* block diagonal 2n x 2n */
static void tn_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  size_t i, m = 2 * G->n;
  dm_lie_zero(A, m, m, ld);
  for (i = 0; i < G->n; i++) {
    A[2 * i * ld + 2 * i + 1] = -xi[i];
    A[(2 * i + 1) * ld + 2 * i] = xi[i];
  }
}

static void tn_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  size_t i;
  for (i = 0; i < G->n; i++)
    xi[i] = 0.5 * (A[(2 * i + 1) * ld + 2 * i] - A[2 * i * ld + 2 * i + 1]);
}

static void tn_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  size_t i, m = 2 * G->n;
  dm_lie_zero(M, m, m, ld);
  for (i = 0; i < G->n; i++) {
    double c = cos(g[i]), s = sin(g[i]);
    M[2 * i * ld + 2 * i] = c;
    M[2 * i * ld + 2 * i + 1] = -s;
    M[(2 * i + 1) * ld + 2 * i] = s;
    M[(2 * i + 1) * ld + 2 * i + 1] = c;
  }
}

/* each diagonal block [[c, -s], [s, c]] with c^2 + s^2 = 1, zeros
 * elsewhere (to 1e-12) */
static int tn_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g)
{
  size_t i, j, m = 2 * G->n;
  for (i = 0; i < m; i++)
    for (j = 0; j < m; j++)
      if (i / 2 != j / 2 && fabs(M[i * ld + j]) > 1e-12)
        return DM_EDOM;
  for (i = 0; i < G->n; i++) {
    const double *B = M + 2 * i * ld + 2 * i;
    double c = B[0], s = B[ld];
    if (fabs(B[ld + 1] - c) > 1e-12 || fabs(B[1] + s) > 1e-12 ||
        fabs(c * c + s * s - 1.0) > 1e-10)
      return DM_EDOM;
    g[i] = atan2(s, c);
  }
  return DM_OK;
}

static void tn_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  size_t i;
  for (i = 0; i < G->n; i++) {
    double c = cos(g[i]), s = sin(g[i]), a = x[2 * i], b = x[2 * i + 1];
    y[2 * i] = c * a - s * b;
    y[2 * i + 1] = s * a + c * b;
  }
}

const dm_lie_type dm_lie_type_so2 = {
  "SO2", DM_LIE_SO2, ab_identity, ab_compose, ab_inverse, ab_copy, tn_log,
  ab_Ad, ab_ad, ab_bracket, ab_dexp, tn_cay, tn_icay, tn_dcay, tn_hat, tn_vee,
  tn_matrix, tn_from_matrix, tn_act, ab_normalize, ab_defect, ab_generator,
  &dm_lie_sym_tn
};

const dm_lie_type dm_lie_type_tn = {
  "Tn", DM_LIE_TN, ab_identity, ab_compose, ab_inverse, ab_copy, tn_log,
  ab_Ad, ab_ad, ab_bracket, ab_dexp, tn_cay, tn_icay, tn_dcay, tn_hat, tn_vee,
  tn_matrix, tn_from_matrix, tn_act, ab_normalize, ab_defect, ab_generator,
  &dm_lie_sym_tn
};

/* }====================================================================== */
