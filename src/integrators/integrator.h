/* integrator.h -- one-step integrators for a dm_system, selected by name.
 *
 * Every method family is a `const dm_integrator_type` (GSL ode-initval2
 * style) in its own file.  The families of this directory are listed in
 * registry.c; other modules add theirs with dm_integrator_register (the
 * Routh reduction registers RSPRK, the discrete Routh equations and the
 * classical Routhian for its reduced systems).  A family declares which
 * system kinds it integrates (dm_system.kind): the method name is looked up
 * among the families for the system's kind, so "gauss" is the Gauss PRK on
 * a Lagrangian system and RSPRK on the reduced system of a Routh reduction.
 * Method names of the Lagrangian kind:
 *   midpoint, gauss (stages >= 1), trapezoid, lobatto (IIIA-IIIB, stages >= 2),
 *   prk (user tableau), composition (symmetric compositions of order 4/6/8),
 *   rk4 (classical, non-symplectic), gsl:<stepper> (GSL odeiv2).
 *
 * State.  The primary state is (q, p), p = dL/dv.  step() maps (q0, p0) to
 * (q1, p1) over a step h of either sign.  Conversions to (q, v) and to the
 * two-point (q0, q1) form are below (discrete Legendre transforms).  Runs
 * into a trajectory are core/run.h.
 *
 * Ownership.  dm_integrator_new() allocates the integrator and every
 * workspace any later step needs (a step never calls malloc); the system is
 * borrowed and must outlive the integrator; dm_integrator_free() releases
 * everything (NULL is a no-op).  Registered types are borrowed for the life
 * of the process.
 *
 * Thread safety.  One integrator must not be used by two threads at once;
 * two integrators on one system may (systems keep no state between calls).
 * Registration may run concurrently with lookups and dm_integrator_new:
 * entries are published atomically and never removed.
 *
 * Errors.  Functions return DM_OK or a DM_E* status and fill the dm_err (may
 * be NULL): DM_ENOCONV (Newton did not converge; residual and tolerance in
 * the message and in I->stats), DM_ESINGULAR (singular Jacobian, e.g. a
 * Lagrangian whose d2L/dv2 is singular), DM_EDOM (a callback reported a
 * point outside its domain, or a NaN appeared), DM_ECALLBACK, DM_EINVAL,
 * DM_ENOTFOUND (unknown method), DM_EUNSUP, DM_EINTR (run interrupted).
 * After a failed step the outputs are unspecified and the state is unchanged.
 */
#ifndef DM_INTEGRATOR_H
#define DM_INTEGRATOR_H

#include <stddef.h>
#include "core/status.h"
#include "core/system.h"
#include "core/tableau.h"

typedef struct dm_integrator dm_integrator;

/* {==== options: one struct, described by a table so bindings can get and
 * set fields by name (REBOUND style) ===================================== */

#define DM_INTEG_STRMAX 32

/* A monitor function of a time transformation (methods "adapt:<method>",
 * src/integrators/adapt.c): the physical time runs as dt/ds = g(q) > 0 in
 * the fictitious time s of the steps.  eval fills g and, when the bits of
 * `what` ask, the gradient gq (n) and the Hessian gqq (n x n, row-major)
 * at q with the system's parameters par; it returns 0, > 0 outside its
 * domain, < 0 on failure (system.h).  Re-entrant with its own work
 * (work_size bytes).  Borrowed by the integrators: it must outlive them. */
enum { DM_MON_G = 1u, DM_MON_GRAD = 2u, DM_MON_HESS = 4u };
typedef struct dm_monitor {
  int (*eval)(void *data, const double *q, const double *par, unsigned what, double *g,
              double *gq, double *gqq, void *work);
  void *data;
  size_t work_size;
} dm_monitor;

typedef struct dm_integ_opts {
  int stages;          /* gauss >= 1, lobatto >= 2 (0: family default) */
  double h;            /* default step size of run() (informational here) */
  double tol;          /* Newton: stop when |update| <= tol * scale */
  int maxiter;         /* Newton iteration cap */
  int simplified;      /* Newton: reuse the factored Jacobian while it converges fast */
  int order;           /* composition: 4, 6 or 8 */
  char scheme[DM_INTEG_STRMAX];  /* composition table ("" = default for order) */
  char base[DM_INTEG_STRMAX];    /* composition base step: trapezoid|midpoint */
  int explicit_sv;     /* use explicit Stormer-Verlet/RATTLE when L is separable */
  int adaptive;        /* gsl: adaptive steps inside each h */
  double epsabs, epsrel;         /* gsl adaptive tolerances */
  const dm_tableau *tableau;     /* prk: user tableau (copied by new()) */
  char linear[DM_INTEG_STRMAX];  /* Newton matrices: auto (default), dense, sparse */
  const dm_monitor *monitor;     /* adapt: the monitor (borrowed); NULL: the
                                  * potential's, (U(q0)/U(q))^power, U = -V */
  double power;        /* adapt: exponent of the potential's monitor (1:
                        * Sundman's dt = r ds for a 1/r potential) */
  double omega;        /* multiscale: the fast frequency (0: estimated) */
  char fast[DM_INTEG_STRMAX];    /* multiscale: fast coordinates, comma-separated */
  int nodes;           /* multiscale: Lobatto nodes of the Filon rule (4) */
  int phases;          /* multiscale: phases sampled per step (8) */
  char iteration[DM_INTEG_STRMAX];  /* stage equations: auto (default), newton, fixed */
} dm_integ_opts;

/* How the stage equations of an implicit method are solved (option
 * "iteration"): Newton, or first the fixed-point iteration
 * V_i <- M^{-1} (p0 + h sum_j at_ij W_j) of a separable system (Newton
 * takes over when it contracts slowly), or chosen by size. */
enum dm_iteration_mode { DM_ITER_AUTO = 0, DM_ITER_NEWTON, DM_ITER_FIXED };

enum dm_opt_kind { DM_OPT_INT, DM_OPT_DOUBLE, DM_OPT_BOOL, DM_OPT_STRING };

typedef struct dm_option_desc {
  const char *name;
  int kind;            /* dm_opt_kind */
  size_t offset;       /* offsetof(dm_integ_opts, field) */
  size_t size;         /* bytes (strings: buffer size) */
  double min, max;     /* accepted range for numbers */
  const char *doc;
} dm_option_desc;

/* The option table, terminated by an entry with name == NULL. */
extern const dm_option_desc dm_integ_options[];

void dm_integ_opts_init(dm_integ_opts *o);
const dm_option_desc *dm_integ_option_find(const char *name);
/* Set a number (int, double or bool option) or a string option by name;
 * DM_ENOTFOUND for an unknown name, DM_EINVAL for a wrong kind or range. */
int dm_integ_opts_set_number(dm_integ_opts *o, const char *name, double v, dm_err *e);
int dm_integ_opts_set_string(dm_integ_opts *o, const char *name, const char *v, dm_err *e);
/* Read an option: numbers into *num, strings into *str (either may be NULL). */
int dm_integ_opts_get(const dm_integ_opts *o, const char *name, double *num,
                      const char **str, dm_err *e);

/* {==== the type object ================================================== */

enum dm_integ_flags {
  DM_INTEG_SYMPLECTIC  = 1u << 0,
  DM_INTEG_SYMMETRIC   = 1u << 1,
  DM_INTEG_EXPLICIT    = 1u << 2,  /* no nonlinear solve (this instance) */
  DM_INTEG_VARIATIONAL = 1u << 3,  /* has a discrete Lagrangian: dm_integrator_dlegendre */
  DM_INTEG_FORCES      = 1u << 4,  /* supports a generalized force */
  DM_INTEG_CONSTRAINTS = 1u << 5,  /* supports holonomic constraints */
  DM_INTEG_ADAPTIVE    = 1u << 6,  /* steps internally with error control */
  DM_INTEG_EXACT_JAC   = 1u << 7,  /* jacobian() is exact (else finite differences) */
  DM_INTEG_VARSTEP     = 1u << 8   /* the physical length of a step is the family's
                                    * (time transformations, energy-momentum
                                    * methods): see begin/step_until, I->t, I->dt */
};

typedef struct dm_integrator_type {
  const char *name;          /* registry name; "gsl" matches "gsl:<variant>" */
  const char *summary;       /* one line for help texts */
  int order;                 /* nominal order; 0 when it depends on options */
  unsigned flags;            /* nominal dm_integ_flags */
  const char *const *options;  /* names of the options it reads, NULL-terminated */
  /* Build I->state from I->sys, I->opt, I->variant; set I->order, I->flags. */
  int (*alloc)(dm_integrator *I, dm_err *e);
  /* (q0, p0) -> (q1, p1); outputs may alias inputs. */
  int (*step)(dm_integrator *I, double h, const double *q0, const double *p0,
              double *q1, double *p1, dm_err *e);
  /* D(q1,p1)/D(q0,p0) (2n x 2n, row-major) at (q0, p0); NULL: not available
   * (the generic code falls back to central differences). */
  int (*jacobian)(dm_integrator *I, double h, const double *q0, const double *p0,
                  double *DPhi, dm_err *e);
  /* Discrete Legendre transforms of the method's discrete Lagrangian:
   * p0 = -D1 Ld(q0, q1), p1 = D2 Ld(q0, q1), *Ld (any output may be NULL).
   * NULL: not variational. */
  int (*dlegendre)(dm_integrator *I, double h, const double *q0, const double *q1,
                   double *p0, double *p1, double *Ld, dm_err *e);
  /* Optional fast path of the run loop: up to nsteps steps of h in place
   * on (q, p), polling dm_interrupted() before each step (DM_EINTR, no
   * message).  *done = steps completed; on any failure q, p hold the state
   * after *done steps.  NULL: the run loop calls step() repeatedly. */
  int (*advance)(dm_integrator *I, double h, long nsteps, double *q, double *p,
                 long *done, dm_err *e);
  /* Forget step history (predictor, compensated-summation carries). */
  void (*reset)(dm_integrator *I);
  void (*free)(dm_integrator *I);
  /* The system kinds (dm_system.kind) this family integrates, NULL-ended;
   * NULL: Lagrangian systems (DM_SYSTEM_LAGRANGIAN) only. */
  const char *const *kinds;
  /* Further method names the family answers to besides `name` (the
   * instance sees the one requested in I->name), NULL-ended; may be NULL. */
  const char *const *names;
  /* begin (optional for every family): start a run from (q0, p0) -- a
   * family may fix what depends on the start (a fast frequency).  For
   * families with variable physical steps (DM_INTEG_VARSTEP) it is
   * required and more: begin: start a run at physical time t0 from (q0, p0) with
   * the nominal step h -- latch what the run keeps fixed (an energy
   * level), set I->t = t0 and I->dt to the length of the first step (or
   * its first-order estimate).  Every step then advances I->t by the step's
   * physical length and sets I->dt to it.  step_until: one step of nominal
   * size h that, when it would pass the physical time t_end, is replaced by
   * a shorter one ending there exactly (I->t = t_end, *reached = 1);
   * NULL for the others. */
  int (*begin)(dm_integrator *I, double h, double t0, const double *q0, const double *p0,
               dm_err *e);
  int (*step_until)(dm_integrator *I, double h, double t_end, const double *q0,
                    const double *p0, double *q1, double *p1, int *reached, dm_err *e);
  /* States on a submanifold of the coordinates (a sphere in R^(n+1)):
   * the symplecticity defect of the step map for the symplectic form
   * there, from perturbations along the manifold; the step Jacobian in
   * coordinates is then not defined.  NULL: the states are coordinates. */
  int (*manifold_defect)(dm_integrator *I, double h, const double *q0, const double *p0,
                         double *defect, dm_err *e);
} dm_integrator_type;

/* Statistics of the last step and running totals. */
typedef struct dm_integ_stats {
  int iters;            /* Newton iterations of the last step (0 if explicit) */
  int jacs;             /* Jacobian factorisations in the last step */
  double residual;      /* final max-norm residual / update of the last solve */
  double tol;           /* the tolerance it was compared with */
  long steps;           /* steps taken since new() or reset */
  long iters_total;
  int linear;           /* the Newton matrices: DM_LINEAR_DENSE or _SPARSE (core/sparse.h;
                           0 for explicit methods) */
  size_t nnz;           /* entries of a sparse Newton matrix */
  long flagged;         /* steps a family flagged since new() or reset (sem:
                         * "energy not matched", sem.h) */
  long fixed_total;     /* steps solved by the fixed-point iteration alone */
} dm_integ_stats;

struct dm_integrator {
  const dm_integrator_type *type;
  const dm_system *sys;            /* borrowed */
  size_t n, m;                     /* coordinates (velocities, momenta), constraints */
  size_t nq;                       /* numbers per configuration q (dm_system_nq) */
  dm_integ_opts opt;               /* private copy (tableau copied into state) */
  char variant[DM_INTEG_STRMAX];   /* text after "name:" (gsl stepper) */
  char name[2 * DM_INTEG_STRMAX];  /* full method name as requested */
  int order;                       /* actual order of this instance */
  int stages;                      /* stages of a Runge-Kutta / Galerkin method
                                    * (midpoint 1, trapezoid 2, gauss s, ...);
                                    * 0 when the notion does not apply */
  unsigned flags;                  /* actual dm_integ_flags */
  dm_integ_stats stats;
  double t, dt;                    /* the physical time reached and the length of
                                    * the last step: kept by the VARSTEP
                                    * families (see begin); dm_integrator_step
                                    * keeps them for the others */
  int begun;                       /* begin() ran since new() or reset */
  void *state;                     /* family private */
  struct dm_legendre_ws *leg;      /* Legendre-map workspace (velocity solves) */
  double *scratch;                 /* 8n + nq + n doubles for the generic layer */
};

/* {==== registry and life cycle ========================================== */

/* Add a family to the registry (idempotent for the same type object).
 * DM_EINVAL when the type lacks a name, step or alloc, or when another
 * registered family already answers to one of its names for one of its
 * kinds; DM_ENOMEM when the registry is full (DM_INTEG_REGISTRY_MAX). */
#define DM_INTEG_REGISTRY_MAX 64
int dm_integrator_register(const dm_integrator_type *type, dm_err *e);

/* The registered families, in registration order (the families of this
 * directory first): their count, and the i-th (NULL when i >= count). */
size_t dm_integrator_count(void);
const dm_integrator_type *dm_integrator_type_at(size_t i);

/* Does the family read option `name` (listed in type->options)? */
int dm_integrator_has_option(const dm_integrator_type *type, const char *name);
/* Is the stage count of I a choice (a "stages" or "tableau" option), so that
 * it belongs in a description of the run (midpoint and trapezoid: no)? */
int dm_integrator_stages_chosen(const dm_integrator *I);

/* Does the family integrate systems of this kind (NULL: Lagrangian)? */
int dm_integrator_accepts(const dm_integrator_type *type, const char *kind);

/* The family answering to a method name for a system kind (NULL:
 * Lagrangian): "gauss", "gsl:rk8pd" (the gsl family, variant "rk8pd"),
 * "dr:gauss" (kind "routh").  NULL if none.  *variant_out (may be NULL)
 * points into name after the family's name and ':' (NULL if none). */
const dm_integrator_type *dm_integrator_find(const char *kind, const char *name,
                                             const char **variant_out);
/* The family for sys->kind and method, or NULL and DM_ENOTFOUND in e with
 * the methods of that kind, or the kinds the method applies to. */
const dm_integrator_type *dm_integrator_select(const dm_system *sys, const char *method,
                                               const char **variant_out, dm_err *e);
/* dm_integrator_find for Lagrangian systems. */
const dm_integrator_type *dm_integrator_lookup(const char *name, const char **variant_out);

/* Create an integrator for sys with method name and options (NULL: defaults);
 * the family is the one answering to the name for sys->kind.  DM_ENOTFOUND
 * names the methods of that kind, or the kinds the method applies to.
 * On error *out is NULL and nothing is leaked. */
int dm_integrator_new(const dm_system *sys, const char *method,
                      const dm_integ_opts *opts, dm_integrator **out, dm_err *e);
void dm_integrator_free(dm_integrator *I);
void dm_integrator_reset(dm_integrator *I);

/* One step (q0, p0) -> (q1, p1); h may be negative.  Outputs may alias the
 * inputs.  Checks the result for NaN (DM_EDOM). */
int dm_integrator_step(dm_integrator *I, double h, const double *q0, const double *p0,
                       double *q1, double *p1, dm_err *e);

/* Start a run: the type's begin when it has one (a VARSTEP family that
 * steps before begin was called begins at t0 = 0 from the first step's
 * start); I->t = t0 and I->dt = h for fixed-step families.  step_until: the type's step_until for those; for the others
 * a step of h, or of t_end - I->t when that is shorter (same sign as h). */
int dm_integrator_begin(dm_integrator *I, double h, double t0, const double *q0,
                        const double *p0, dm_err *e);
int dm_integrator_step_until(dm_integrator *I, double h, double t_end, const double *q0,
                             const double *p0, double *q1, double *p1, int *reached,
                             dm_err *e);
static inline int dm_integrator_varstep(const dm_integrator *I)
{
  return (I->flags & DM_INTEG_VARSTEP) != 0;
}

/* {==== state conversions ================================================ */

/* p = dL/dv (q, v). */
int dm_integrator_momentum(dm_integrator *I, const double *q, const double *v,
                           double *p, dm_err *e);
/* v solving dL/dv (q, v) = p by Newton (v holds the initial guess on entry
 * when guess != 0, else the guess is 0).  DM_ESINGULAR when d2L/dv2 is
 * singular (the Lagrangian is not regular). */
int dm_integrator_velocity(dm_integrator *I, const double *q, const double *p,
                           double *v, int guess, dm_err *e);
/* E = p.v - L at (q, v). */
int dm_integrator_energy(dm_integrator *I, const double *q, const double *v,
                         double *E, dm_err *e);
/* Discrete Legendre transforms (variational methods only): p0 = -D1 Ld,
 * p1 = D2 Ld, Ld (outputs may be NULL). */
int dm_integrator_dlegendre(dm_integrator *I, double h, const double *q0,
                            const double *q1, double *p0, double *p1, double *Ld,
                            dm_err *e);
/* DEL step (q_prev, q_cur) -> q_next: p_cur = D2 Ld(q_prev, q_cur), then one
 * step from (q_cur, p_cur). */
int dm_integrator_del_step(dm_integrator *I, double h, const double *q_prev,
                           const double *q_cur, double *q_next, dm_err *e);
/* Discrete momentum along a cyclic direction xi (n): J_d = xi . D2 Ld(q0, q1). */
int dm_integrator_discrete_momentum(dm_integrator *I, double h, const double *q0,
                                    const double *q1, const double *xi, double *J,
                                    dm_err *e);

/* {==== runs ============================================================= */

/* Up to nsteps steps of h in place on (q, p) through the family's fast
 * path (or step() repeatedly), polling dm_interrupted() before each step
 * (DM_EINTR, no message).  *done = steps completed; on failure q, p hold
 * the state after *done steps and e the failing step's own message. */
int dm_integrator_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                          long *done, dm_err *e);

/* Sample sink supplied by the trajectory module: return 0 to continue,
 * non-zero to stop the run (DM_ECALLBACK). */
typedef int (*dm_sink_fn)(void *ctx, double t, const double *q, const double *p,
                          const double *v);

typedef struct dm_run_info {
  long steps;           /* steps completed */
  double t;             /* time reached */
  long samples;         /* samples emitted */
  int status;           /* final status */
  double residual, tol; /* of the last (failed) Newton solve */
} dm_run_info;

/* Take nsteps steps of size h from (t0, q, p), updating q, p in place.
 * Emits (t, q, p, v) through sink (may be NULL) at step 0 and every `every`
 * steps, and the final state if it was not emitted.  Polls dm_interrupted()
 * every step.  On DM_EINTR, Newton failure, NaN state or sink stop, it stops:
 * q, p hold the last good state, which is emitted if it had not been, and
 * the message says at which step and time it stopped.  info may be NULL. */
int dm_integrator_run(dm_integrator *I, double t0, double *q, double *p, double h,
                      long nsteps, long every, dm_sink_fn sink, void *ctx,
                      dm_run_info *info, dm_err *e);

/* {==== diagnostics ====================================================== */

/* DPhi (2n x 2n) of one step at (q0, p0): exact (implicit differentiation of
 * the converged step equations, or differentiation through explicit stages)
 * when I->flags has DM_INTEG_EXACT_JAC, else central differences.
 * Not available for constrained systems (DM_EUNSUP). */
int dm_integrator_jacobian(dm_integrator *I, double h, const double *q0,
                           const double *p0, double *DPhi, dm_err *e);
/* max_ij |(DPhi^T J DPhi - J)_ij| with J = [[0, I], [-I, 0]]; for a family
 * whose states live on a submanifold (type->manifold_defect), the defect
 * of the restriction of that form to it. */
int dm_integrator_symplecticity_defect(dm_integrator *I, double h, const double *q0,
                                       const double *p0, double *defect, dm_err *e);
/* n steps with h then n with -h from (q0, p0); *dev = max-norm distance
 * from (q0, p0). */
int dm_integrator_reversal(dm_integrator *I, double h, long n, const double *q0,
                           const double *p0, double *dev, dm_err *e);
/* Least-squares slope of log(err) against log(h) (k >= 2 points, all > 0);
 * NaN if the data are unusable. */
double dm_integrator_order_fit(const double *h, const double *err, size_t k);
/* Empirical order: integrate from (q0, p0) to time T with each step h[i]
 * (T/h[i] rounded to whole steps, h adjusted), compare with the reference
 * (qref, pref) at T (NULL: computed with a high-order method and a small
 * step), errors (2-norm over q and p) into err[i] (may be NULL), fitted
 * slope into *order. */
int dm_integrator_order_estimate(const dm_system *sys, const char *method,
                                 const dm_integ_opts *opts, const double *q0,
                                 const double *p0, double T, const double *h, size_t k,
                                 const double *qref, const double *pref, double *err,
                                 double *order, dm_err *e);

#endif
