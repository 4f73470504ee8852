/* system.h -- a mechanical system as the integrators see it.
 *
 * A system is a set of C callbacks that evaluate the Lagrangian L(q, v; par)
 * and its first and second derivatives, and optionally a generalized force
 * F(q, v; par) and holonomic constraints g(q; par) = 0.  The callbacks are
 * implemented either by tapes compiled from a traced Lua function (the
 * expression engine, src/expr/lagrangian.c) or by hand-written C (built-in
 * systems, src/core/builtin_systems.c).  Integrators never know which.
 *
 * Conventions
 *  - n coordinates, m constraints, npar parameters.  Matrices are dense,
 *    row-major, n*n doubles: Lvv[i*n+j] = d2L/dv_i dv_j,
 *    Lvq[i*n+j] = d2L/dv_i dq_j, Lqq[i*n+j] = d2L/dq_i dq_j -- or, when
 *    the system has a pattern and the request says DM_LAG_SPARSE
 *    (DM_FORCE_SPARSE), the values on that pattern.
 *  - Callbacks follow SUNDIALS: return 0 on success, > 0 for a recoverable
 *    failure (the point is outside the domain, e.g. sqrt of a negative number;
 *    a caller may retry with a smaller step), < 0 for an unrecoverable one.
 *  - Callbacks are re-entrant: they read `data` and `par` and write only their
 *    outputs and `work` (work_size bytes supplied by the caller, one buffer per
 *    thread), so one system can be used from several threads at once.
 *  - `par` points to the system's current parameter values; changing them
 *    between calls changes the system without recompiling anything.
 *
 * Ownership: a dm_system is a plain description; whoever fills it (the
 * Lagrangian compiler, a built-in constructor) owns `data`, `par`, names and
 * releases them through `free_data` (may be NULL).
 */
#ifndef DM_SYSTEM_H
#define DM_SYSTEM_H

#include <stddef.h>

#include "core/sparse.h"
#include "core/status.h"

/* Which outputs a Lagrangian evaluation must fill (bit mask). */
enum dm_lag_what {
  DM_LAG_L   = 1u << 0,   /* out->L                     */
  DM_LAG_Q   = 1u << 1,   /* out->Lq[n]    = dL/dq      */
  DM_LAG_V   = 1u << 2,   /* out->Lv[n]    = dL/dv      */
  DM_LAG_VV  = 1u << 3,   /* out->Lvv[n*n]              */
  DM_LAG_VQ  = 1u << 4,   /* out->Lvq[n*n]              */
  DM_LAG_QQ  = 1u << 5,   /* out->Lqq[n*n]              */
  DM_LAG_GRAD = DM_LAG_L | DM_LAG_Q | DM_LAG_V,
  DM_LAG_ALL  = 0x3f,
  /* with VV, VQ, QQ: those arrays hold the values on the system's pattern
   * (sys->pattern->vv, vq, qq: vv.nnz, vq.nnz, qq.nnz doubles) instead of
   * n*n dense matrices; only for systems with a pattern */
  DM_LAG_SPARSE = 1u << 6
};

/* Output record; the caller points the arrays at storage it owns.  Only the
 * requested outputs are written; an evaluator may also fill others. */
typedef struct dm_lag_out {
  double L;
  double *Lq, *Lv;
  double *Lvv, *Lvq, *Lqq;
} dm_lag_out;

typedef int (*dm_lag_fn)(void *data, const double *q, const double *v,
                         const double *par, unsigned what, dm_lag_out *out,
                         void *work);

/* Generalized force F(q, v) (n) and its Jacobians Fq[i*n+j] = dF_i/dq_j,
 * Fv[i*n+j] = dF_i/dv_j; `what` uses DM_FORCE_* bits. */
enum { DM_FORCE_F = 1u, DM_FORCE_Q = 2u, DM_FORCE_V = 4u,
       DM_FORCE_SPARSE = 8u };     /* Fq, Fv as values on pattern->fq, fv */
typedef int (*dm_force_fn)(void *data, const double *q, const double *v,
                           const double *par, unsigned what, double *F,
                           double *Fq, double *Fv, void *work);

/* Holonomic constraints g(q) (m), G[a*n+j] = dg_a/dq_j, and second
 * derivatives H[(a*n+i)*n+j] = d2g_a/dq_i dq_j; `what` uses DM_CONSTR_* bits. */
enum { DM_CONSTR_G = 1u, DM_CONSTR_DG = 2u, DM_CONSTR_D2G = 4u };
typedef int (*dm_constr_fn)(void *data, const double *q, const double *par,
                            unsigned what, double *g, double *G, double *H,
                            void *work);

/* Structural facts integrators may exploit. */
enum dm_system_flags {
  /* L = 1/2 v^T M v - V(q) with a constant, symmetric positive definite M
   * given in `mass`: enables explicit Stormer-Verlet and compositions. */
  DM_SYS_SEPARABLE  = 1u << 0,
  /* L is quadratic in v (mechanical): the Legendre map is linear in v. */
  DM_SYS_MECHANICAL = 1u << 1
};

/* System kinds (dm_system.kind): which integrator families apply
 * (integrator.h).  NULL means DM_SYSTEM_LAGRANGIAN. */
#define DM_SYSTEM_LAGRANGIAN "lagrangian"   /* L(q, v) on R^n (coordinates) */

/* The structural nonzeros of the second derivatives, for solvers that
 * work on sparse matrices.  Full patterns (both triangles of the
 * symmetric Lvv and Lqq); vq is Lvq's ([i][j] = d2L/dv_i dq_j); fq, fv
 * are empty (nnz 0) for an unforced system.  mass: for a separable system
 * the mass matrix as values on vv at the current parameters, else NULL.
 * Owned by the system's filler. */
typedef struct dm_sys_pattern {
  dm_csr vv, vq, qq;
  dm_csr fq, fv;
  const double *mass;
} dm_sys_pattern;

typedef struct dm_system {
  const char *name;
  const char *kind;             /* static string; NULL: DM_SYSTEM_LAGRANGIAN */
  size_t n;                     /* coordinates */
  size_t npar;                  /* parameters */
  size_t m;                     /* constraints (0: none) */
  const char *const *coords;    /* n names, may be NULL */
  const char *const *params;    /* npar names, may be NULL */
  double *par;                  /* npar current values */
  unsigned flags;               /* dm_system_flags */
  const double *mass;           /* n*n, only with DM_SYS_SEPARABLE; may be
                                   NULL then for a large system whose
                                   pattern holds a diagonal mass */
  const dm_sys_pattern *pattern;  /* NULL: no pattern known (dense) */

  dm_lag_fn lagrangian;         /* required */
  dm_force_fn force;            /* NULL: unforced */
  dm_constr_fn constraints;     /* NULL iff m == 0 */
  void *data;                   /* passed to the callbacks */
  size_t work_size;             /* bytes of scratch per concurrent caller */

  void (*free_data)(struct dm_system *);  /* releases what the filler owns */
  /* Optional (NULL: nothing ever changes): install what has become ready
   * since the last call -- native code compiled in the background while
   * the tape ran; the results are the same to round-off either way.
   * Drivers call it between steps, never during one, from the thread that
   * uses the system.  Returns 1 while more is on its way, else 0. */
  int (*update)(const struct dm_system *);
  /* Bring what the filler derived from the parameters (a constant mass
   * matrix) up to date after par changed; NULL: nothing to do. */
  int (*refresh)(struct dm_system *, dm_err *);

  /* Configurations stored in other numbers than the n velocities (a
   * system on a Lie group: a rotation is 9 numbers, its body velocity 3).
   * nq: numbers per configuration q (0: n; coords then names nq); p and v
   * keep n.  pnames, vnames: n names of the momenta and velocities, the
   * p and v columns of trajectories (NULL: "p_<coord>", "v_<coord>",
   * only when nq is n).  space: the configuration space's name, recorded
   * by runs as the metadata "space" (NULL: none).  momentum_map (NULL:
   * none): a momentum map J(q, p) of n values (a group's spatial
   * momentum) that runs record as "momentum_<k>" in place of p_k. */
  size_t nq;
  const char *const *pnames, *const *vnames;
  const char *space;
  void (*momentum_map)(const struct dm_system *, const double *q, const double *p,
                       double *J);
} dm_system;

/* Numbers per configuration: sys->nq, or n when it is 0. */
static inline size_t dm_system_nq(const dm_system *s)
{
  return s->nq != 0 ? s->nq : s->n;
}

/* Release what the system's filler owns (calls free_data) and zero *s.
 * NULL is a no-op. */
void dm_system_release(dm_system *s);

#endif
