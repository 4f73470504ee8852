/* conn_impl.h -- private to src/conn: the structs behind the opaque
 * connection types and small helpers shared by its files.  Not API. */
#ifndef DM_CONN_IMPL_H
#define DM_CONN_IMPL_H

#include <math.h>

#include "conn/conn.h"
#include "expr/tape.h"

struct dm_conn {
  const dm_conn_bundle *B;
  dm_conn_fn fn;
  void *ud;
  int has_dA;
  void (*free_ud)(void *);
  int expr;                     /* ud is a conn_expr (dm_conn_set_params) */
  size_t dim, nx;
  double *A, *A2, *dA;          /* scratch: dim*nx, dim*nx, nx*dim*nx */
};

/* the tapes of an expression connection (conn_expr.c) */
typedef struct conn_expr {
  dm_tape *tA, *tdA;            /* A; A then dA */
  struct dm_native *nat;        /* native code of tA, or NULL */
  void (*fA)(const double *in, const double *par, double *out);
  size_t nA, npar;
  double *par, *work, *out;     /* out: nA (1 + nx) inside work's block */
} conn_expr;
int dm_conn__expr_eval(void *ud, const double *x, double *A, double *dA, dm_err *e);
void dm_conn__expr_free(void *ud);

/* the discrete mechanical connection (mechanical.c) */
typedef struct conn_mech conn_mech;
void dm_conn__mech_free(conn_mech *m);
int dm_conn__mech_solve(dm_conn_dc *D, const double *q0, const double *q1, double *k,
                        dm_err *e);

struct dm_conn_dc {
  const dm_conn_rule *R;
  const dm_conn_bundle *B;
  dm_conn *parent;
  dm_conn_pair_fn local;
  void *local_ud;
  dm_conn_topts topts;
  conn_mech *mech;
  dm_conn_dc *guess;            /* mechanical: the initial guess (not owned) */
};

/* 1 when the algebra element xi (a principal logarithm) is within 1e-9 of
 * the cut locus: a rotation angle of pi (SO(2), T^n, SE(2) angles; the
 * rotation vector of SO(3), SE(3)), where log is not unique. */
static inline int dm_conn__near_cut(const dm_lie_group *G, const double *xi)
{
  const double lim = M_PI - 1e-9;
  size_t f, i;
  switch (G->kind) {
  case DM_LIE_SO2: case DM_LIE_SE2:
    return fabs(xi[0]) > lim;
  case DM_LIE_TN:
    for (i = 0; i < G->n; i++)
      if (fabs(xi[i]) > lim)
        return 1;
    return 0;
  case DM_LIE_SO3: case DM_LIE_SE3:
    return sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]) > lim;
  case DM_LIE_PRODUCT:
    for (f = 0; f < G->nfac; f++)
      if (dm_conn__near_cut(G->fac[f], xi + G->xoff[f]))
        return 1;
    return 0;
  default:
    return 0;
  }
}

/* |v| (Euclidean) */
static inline double dm_conn__norm(const double *v, size_t n)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    s += v[i] * v[i];
  return sqrt(s);
}

#endif
