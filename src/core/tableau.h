/* tableau.h -- partitioned Runge-Kutta (PRK) coefficient tables.
 *
 * A tableau holds s stages: nodes c, weights b (q part) and bt (p part, b~),
 * and the s*s row-major matrices a (q part, e.g. Lobatto IIIA) and at
 * (p part, a~, e.g. Lobatto IIIB).  The PRK step built on it is
 *   Q_i = q0 + h sum_j a_ij Qdot_j,   P_i = p0 + h sum_j at_ij Pdot_j,
 *   q1  = q0 + h sum_j b_j Qdot_j,    p1  = p0 + h sum_j bt_j Pdot_j.
 *
 * Galerkin tableaus (doc/integrators.md §4, thesis eq. 2.4.3) come from s
 * quadrature nodes: b_i = int_0^1 l_i, a_ij = int_0^{c_i} l_j,
 * at_ij = b_j (1 - a_ji / b_i), bt = b.  Gauss nodes are taken from GSL
 * (gsl_integration_glfixed_table), Lobatto nodes are computed here
 * ({0, 1} and the roots of P'_{s-1}(2 tau - 1), Newton in long double).
 * The integrals are evaluated exactly by an s-point Gauss rule.
 *
 * Ownership: every constructor returns a new tableau in *out that the caller
 * releases with dm_tableau_free() (NULL is a no-op).  On error *out is set to
 * NULL, nothing is leaked, and the dm_err (may be NULL) says why.
 */
#ifndef DM_TABLEAU_H
#define DM_TABLEAU_H

#include <stddef.h>
#include "core/status.h"

/* Largest number of stages the generators accept. */
#define DM_TABLEAU_SMAX 20

enum dm_tableau_flags {
  DM_TAB_SYMPLECTIC = 1u << 0,  /* b_i at_ij + b_j a_ji = b_i b_j, b = bt */
  DM_TAB_SYMMETRIC  = 1u << 1,  /* c, a, at symmetric under i -> s+1-i */
  DM_TAB_GALERKIN   = 1u << 2   /* built from quadrature nodes */
};

typedef struct dm_tableau {
  size_t s;
  char name[32];       /* "gauss", "lobatto", "galerkin", "prk" */
  int order;           /* classical order if known, else 0 */
  unsigned flags;      /* dm_tableau_flags */
  double *c;           /* s nodes */
  double *b;           /* s weights, q part */
  double *bt;          /* s weights, p part */
  double *a;           /* s*s, q part, row-major */
  double *at;          /* s*s, p part, row-major */
} dm_tableau;

/* A zeroed tableau with s stages (one allocation); NULL if s == 0 or out of
 * memory. */
dm_tableau *dm_tableau_alloc(size_t s);
void dm_tableau_free(dm_tableau *t);
dm_tableau *dm_tableau_copy(const dm_tableau *t);

/* Gauss-Legendre Galerkin tableau (at = a up to round-off), order 2s,
 * 1 <= s <= DM_TABLEAU_SMAX. */
int dm_tableau_gauss(size_t s, dm_tableau **out, dm_err *e);

/* Lobatto IIIA-IIIB pair, order 2s-2, 2 <= s <= DM_TABLEAU_SMAX. */
int dm_tableau_lobatto(size_t s, dm_tableau **out, dm_err *e);

/* Galerkin tableau from s distinct nodes c in [0, 1] (any quadrature with
 * non-zero weights).  order is set to 0 (unknown). */
int dm_tableau_galerkin(size_t s, const double *c, dm_tableau **out, dm_err *e);

/* The s Gauss-Lobatto nodes on [0, 1] in increasing order (s >= 2),
 * x[0] = 0, x[s-1] = 1. */
int dm_tableau_lobatto_nodes(size_t s, double *x, dm_err *e);

/* A user-supplied PRK tableau.  at == NULL means at_ij = b_j(1 - a_ji/b_i)
 * (the symplectic partner of a); bt == NULL means bt = b; c == NULL means the
 * row sums of a.  The symplecticity conditions are checked with tolerance tol
 * (relative to max(1, max|b|^2); tol <= 0 selects 1e-13); a violation is
 * DM_EINVAL naming the (i, j) pair and the defect. */
int dm_tableau_prk(size_t s, const double *a, const double *b,
                   const double *at, const double *bt, const double *c,
                   double tol, dm_tableau **out, dm_err *e);

/* Largest symplecticity defect max_ij |b_i at_ij + b_j a_ji - b_i b_j| and
 * max_i |b_i - bt_i|; the worst (i, j) in *wi, *wj (may be NULL; for a b/bt
 * mismatch *wj == (size_t)-1). */
double dm_tableau_symplectic_defect(const dm_tableau *t, size_t *wi, size_t *wj);

/* Recompute t->flags (symplectic, symmetric) from the coefficients with
 * tolerance tol. */
void dm_tableau_classify(dm_tableau *t, double tol);

#endif
