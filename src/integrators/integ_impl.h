/* integ_impl.h -- private helpers shared by the integrator families
 * (not part of the public API; include only from src/integrators).
 *
 *  - checked callback evaluation (SUNDIALS statuses -> DM_* with messages),
 *  - the helpers of the Newton tests (infinity norm: src/core/vecmath.h,
 *    stopping rule: src/core/newton.h, LU: src/core/smalllu.h),
 *  - the Legendre-map workspace (velocity Newton, Hamiltonian vector field
 *    and its Jacobian, used by rk4 and gsl:*),
 *  - the implicit PRK engine used by midpoint/gauss/trapezoid/lobatto/prk
 *    (prk_engine.c, prk_constrained.c, verlet.c).
 * Workspaces are allocated by *_alloc and never reallocated by a step.
 */
#ifndef DM_INTEG_IMPL_H
#define DM_INTEG_IMPL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include "integrators/integrator.h"
#include "core/newton.h"
#include "integrators/prk_kernels.h"
#include "core/smalllu.h"

/* {==== checked evaluation ============================================== */

/* The callbacks, with a failing status turned into DM_EDOM / DM_ECALLBACK
 * and a message naming q.  Inline: they run several times per Newton
 * iteration; the message is formatted out of line (dm_eval_fail). */
int dm_eval_fail(int rc, const char *what, const double *q, size_t n, dm_err *e);

static inline int dm_eval_lag(const dm_system *sys, const double *q, const double *v,
                              unsigned what, dm_lag_out *out, void *work, dm_err *e)
{
  int rc = sys->lagrangian(sys->data, q, v, sys->par, what, out, work);
  return rc == 0 ? DM_OK : dm_eval_fail(rc, "Lagrangian evaluation", q, sys->n, e);
}

static inline int dm_eval_force(const dm_system *sys, const double *q, const double *v,
                                unsigned what, double *F, double *Fq, double *Fv, void *work,
                                dm_err *e)
{
  int rc = sys->force(sys->data, q, v, sys->par, what, F, Fq, Fv, work);
  return rc == 0 ? DM_OK : dm_eval_fail(rc, "force evaluation", q, sys->n, e);
}

static inline int dm_eval_constr(const dm_system *sys, const double *q, unsigned what,
                                 double *g, double *G, double *H, void *work, dm_err *e)
{
  int rc = sys->constraints(sys->data, q, sys->par, what, g, G, H, work);
  return rc == 0 ? DM_OK : dm_eval_fail(rc, "constraint evaluation", q, sys->n, e);
}



/* {==== Legendre map ===================================================== */

typedef struct dm_legendre_ws {
  const dm_system *sys;
  size_t n;
  double tol;
  int maxiter;
  double *Lq, *Lv, *Lvv, *Lvq, *Lqq;  /* n, n, n*n, n*n, n*n */
  double *F, *Fq, *Fv;                /* n, n*n, n*n */
  double *r, *A, *T;                  /* n, n*n, 2*n*n */
  size_t *perm;
  double *vguess;                     /* last velocity (warm start) */
  int have_guess;
  /* separable systems: v = M^{-1} p with the LU of sys->mass, refactored
   * whenever sys->mass differs from the copy it was made from (parameters
   * changed); unit mass: v = p */
  double *Mcopy, *Mlu;                /* n*n each */
  size_t *mperm;
  int mass_state;                     /* 0: not factored, 1: unit, 2: LU */
  void *work;
  /* large systems (more than 256 coordinates, with a pattern): no n x n
   * array; d2L/dv2 on its pattern, solved by sparse LU */
  int large;
  double *sLvv;                       /* vv.nnz */
  dm_splu *lu;                        /* made at the first velocity solve */
} dm_legendre_ws;

dm_legendre_ws *dm_legendre_alloc(const dm_system *sys);
void dm_legendre_free(dm_legendre_ws *w);
int dm_legendre_momentum(dm_legendre_ws *w, const double *q, const double *v,
                         double *p, dm_err *e);
int dm_legendre_velocity(dm_legendre_ws *w, const double *q, const double *p,
                         double *v, int guess, dm_err *e);
int dm_legendre_energy(dm_legendre_ws *w, const double *q, const double *v,
                       double *E, dm_err *e);
/* Hamiltonian vector field qdot = v(q, p), pdot = Lq + F (warm-started). */
int dm_legendre_field(dm_legendre_ws *w, const double *q, const double *p,
                      double *qdot, double *pdot, dm_err *e);
/* Its Jacobian d(qdot, pdot)/d(q, p), 2n x 2n row-major (DM_EUNSUP for a
 * large system). */
int dm_legendre_field_jac(dm_legendre_ws *w, const double *q, const double *p,
                          double *Jm, dm_err *e);

/* {==== implicit PRK engine ============================================== */

typedef struct dm_prk dm_prk;

/* Engine for tableau t (copied) on sys; explicit != 0 allows the explicit
 * Stormer-Verlet/RATTLE path for Lobatto s=2 on separable unforced systems.
 * Gauss with s >= 2 on a constrained system is DM_EUNSUP (see
 * prk_constrained.c).  On error *out is NULL. */
int dm_prk_alloc(const dm_system *sys, const dm_tableau *t, double tol,
                 int maxiter, int explicit_sv, int linear, dm_prk **out, dm_err *e);
void dm_prk_free(dm_prk *P);
void dm_prk_reset(dm_prk *P);
int dm_prk_is_explicit(const dm_prk *P);
int dm_prk_step(dm_prk *P, double h, const double *q0, const double *p0,
                double *q1, double *p1, dm_integ_stats *st, dm_err *e);
int dm_prk_jacobian(dm_prk *P, double h, const double *q0, const double *p0,
                    double *DPhi, dm_integ_stats *st, dm_err *e);
int dm_prk_dlegendre(dm_prk *P, double h, const double *q0, const double *q1,
                     double *p0, double *p1, double *Ld, dm_integ_stats *st,
                     dm_err *e);

/* Type-object glue for families whose I->state is a dm_prk. */
int dm_prk_type_step(dm_integrator *I, double h, const double *q0, const double *p0,
                     double *q1, double *p1, dm_err *e);
int dm_prk_type_jacobian(dm_integrator *I, double h, const double *q0,
                         const double *p0, double *DPhi, dm_err *e);
int dm_prk_type_dlegendre(dm_integrator *I, double h, const double *q0,
                          const double *q1, double *p0, double *p1, double *Ld,
                          dm_err *e);
int dm_prk_type_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                        long *done, dm_err *e);
void dm_prk_type_reset(dm_integrator *I);
void dm_prk_type_free(dm_integrator *I);
/* Common alloc tail: engine for tableau t, flags/order from the tableau. */
int dm_prk_type_setup(dm_integrator *I, const dm_tableau *t, dm_err *e);

#endif
