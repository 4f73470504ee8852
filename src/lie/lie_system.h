/* lie_system.h -- mechanical systems whose configuration space is a Lie
 * group (or a product with R^n, tori, ...), their Lie group variational
 * integrators, runs into trajectories and structure diagnostics.
 * Theory, conventions and the discrete equations: doc/lie.md.
 *
 * A system on G is a Lagrangian L(g, xi; par) of the element g (its nq
 * stored numbers) and the body velocity xi = g^-1 gdot (dim numbers), with
 * an optional generalized force F(g, xi; par) (dim components paired with
 * the body velocity: body torques for SO(3), wrench (torque, force) in the
 * body frame for SE(3)).  dm_lie_system_compile derives, exactly, from the
 * expressions of L and F: the body momentum mu = dL/dxi and the
 * left-trivialized derivatives in g, compiles them (tape, or native code),
 * and exposes the result as a dm_system of kind DM_SYSTEM_LIE (n = dim,
 * nq = the group's stored numbers: q holds the nq numbers of g, v = xi,
 * p = mu; Lq is the left-trivialized
 * derivative (d/de) L(g exp(e e_k), xi), Lvq and Lqq the left-trivialized
 * derivatives of Lv and Lq) so that the integrator layer's Legendre maps,
 * energy and registry serve it unchanged.
 *
 * Integrator families (registered by dm_lie_register_integrators for the
 * kind DM_SYSTEM_LIE, created with dm_integrator_new; the state is
 * q = g (nq numbers), p = mu (dim), steps g_k -> g_k+1 = g_k chi(f_k)):
 *   lgvi         Lee-Leok-McClamroch / Moser-Veselov: the discrete kinetic
 *                energy of each factor in trace form (SO(3)), with the
 *                potential's moments at both ends; needs L = 1/2 xi^T J xi
 *                - U(g) with J constant and block diagonal over the factors
 *                (and over rotation and translation in SE(2), SE(3)).
 *                Order 2, explicit but for a 3x3 Newton solve per rotation.
 *   lie:gauss    natural-chart Galerkin Lie group variational integrator:
 *                xi(t) a polynomial of degree s in the exp chart at g_k,
 *                s-point Gauss quadrature (stages = s, default 2), order 2s;
 *                "lie:gauss:cayley" uses the Cayley chart.
 *   gsl:<stepper> GSL odeiv2 fixed-step Runge-Kutta (rk2, rk4, rkf45, rkck,
 *                rk8pd) on the Euler-Poincare equations, quaternions for the
 *                rotations: not structure preserving, a reference.
 * On a reduced system (spec->reduced: the discrete Euler-Poincare
 * equations) the same families step mu from the reduced Lagrangian
 * l(xi) = L(e, xi) alone and reconstruct g.
 *
 * Ownership.  dm_lie_system_compile copies the group, names and parameter
 * values and allocates the compiled programs; dm_lie_system_free releases
 * them (NULL is a no-op).  The expression context is borrowed: the
 * lie:gauss family compiles its step program when an integrator is created,
 * so the context must outlive the system.  Integrators borrow the system.
 *
 * Errors.  DM_EINVAL (bad spec; a Lagrangian that is not invariant handed
 * to the reduced form, naming the derivative that is not zero and where;
 * lgvi on a Lagrangian it cannot take, naming why), DM_ENOMEM, the
 * expression engine's statuses; runs and steps as integrator.h and run.h.
 *
 * Thread safety.  Compiling (dm_lie_system_compile, creating a lie:gauss
 * integrator) uses the expression context: one thread at a time.  Once
 * built, a system and its programs are read-only; integrators on it may
 * run in parallel threads, one integrator per thread.
 */
#ifndef DM_LIE_SYSTEM_H
#define DM_LIE_SYSTEM_H

#include <stddef.h>

#include "core/status.h"
#include "core/system.h"
#include "core/trajectory.h"
#include "expr/expr.h"
#include "integrators/integrator.h"
#include "lie/lie.h"

#define DM_SYSTEM_LIE "lie"
/* A Lagrangian system on the unit sphere S^n in R^(n+1) (coordinates: the
 * n + 1 entries of the point x, velocities and momenta in R^(n+1) tangent
 * at x): registered family "lgvi" (sphere_lgvi.c, Lee-Leok-McClamroch for
 * L = (m/2)|v|^2 - U(x), explicit, order 2), with the symplecticity
 * defect on T*S^n (integrator.h: manifold_defect).  Such a system is an
 * ordinary Lagrangian dm_system of this kind (L traced on R^(n+1)). */
#define DM_SYSTEM_SPHERE "sphere"

typedef struct dm_lie_system dm_lie_system;

typedef struct dm_lie_spec {
  const char *name;              /* may be NULL */
  const dm_lie_group *G;         /* copied */
  const dm_expr *g;              /* nq distinct symbols: the stored numbers of g */
  const dm_expr *xi;             /* dim distinct symbols: the body velocity */
  size_t npar;
  const dm_expr *par;            /* npar parameters */
  const double *par_values;      /* npar values; NULL: zeros */
  const char *const *param_names;  /* NULL: the names of par */
  dm_expr L;
  const dm_expr *force;          /* dim components, or NULL */
  int native;                    /* enum dm_native_mode */
  int reduced;                   /* 1: the Euler-Poincare (reduced) system */
} dm_lie_spec;

int dm_lie_system_compile(dm_expr_ctx *ctx, const dm_lie_spec *spec, dm_lie_system **out,
                          dm_err *e);
void dm_lie_system_free(dm_lie_system *S);

/* The reduced (Euler-Poincare) system of S: the same expressions with
 * reduced = 1, after checking that L and the force are invariant under
 * left translation (their right-trivialized derivatives in g vanish
 * identically, or numerically at random points to 1e-10 relative).  On a
 * failure DM_EINVAL names the first derivative found not to vanish, its
 * value and the point. */
int dm_lie_system_reduce(const dm_lie_system *S, dm_lie_system **out, dm_err *e);

/* The dm_system view (kind DM_SYSTEM_LIE); its data points back to S. */
const dm_system *dm_lie_system_base(const dm_lie_system *S);
/* S from a dm_system of kind DM_SYSTEM_LIE, else NULL. */
const dm_lie_system *dm_lie_system_of(const dm_system *sys);
const dm_lie_group *dm_lie_system_group(const dm_lie_system *S);
int dm_lie_system_is_reduced(const dm_lie_system *S);
/* Names of the stored numbers of g ("R11".."R33", "p1".."p3", "theta",
 * "x1".., factor names made unique), of mu ("mu1"..) and xi ("xi1"..). */
#define DM_LIE_NAME_MAX 24
void dm_lie_coord_names(const dm_lie_group *G, char (*names)[DM_LIE_NAME_MAX]);
const char *const *dm_lie_system_gnames(const dm_lie_system *S);
const char *const *dm_lie_system_munames(const dm_lie_system *S);
const char *const *dm_lie_system_xinames(const dm_lie_system *S);
/* Parameters: the live values (change them in place, then call
 * dm_lie_system_params_changed) and their names. */
double *dm_lie_system_par(dm_lie_system *S);
void dm_lie_system_params_changed(dm_lie_system *S);

/* Register the families above, and lgvi on spheres, with the integrator
 * registry (idempotent). */
int dm_lie_register_integrators(dm_err *e);

/* {==== states and diagnostics =========================================== */

/* mu = dL/dxi at (g, xi); xi from mu by Newton on the Legendre map (the
 * integrator's workspace); E = mu . xi - L. */
int dm_lie_momentum(dm_integrator *I, const double *g, const double *xi, double *mu,
                    dm_err *e);
int dm_lie_velocity(dm_integrator *I, const double *g, const double *mu, double *xi,
                    dm_err *e);
int dm_lie_energy(dm_integrator *I, const double *g, const double *mu, double *E, dm_err *e);
/* The momentum map of left translations (spatial momentum, the Noether
 * quantity of a left-invariant L): J = Ad*_(g^-1) mu (dim numbers). */
void dm_lie_spatial_momentum(const dm_lie_group *G, const double *g, const double *mu,
                             double *J);
/* Casimirs of the Lie-Poisson bracket of g*, factor by factor: SO(3) |mu|^2;
 * SE(3) |p|^2 and w.p (mu = (w, p)); SE(2) |p|^2; abelian factors their
 * components.  Writes them into c (at most dim + 1) and returns how many. */
size_t dm_lie_casimirs(const dm_lie_group *G, const double *mu, double *c);

/* The step map's derivative in trivialized coordinates (perturbations
 * g exp(eta), mu + nu; central differences of step step) and its defect
 * from preserving the canonical form of T*G in the left trivialization,
 * omega((eta1, nu1), (eta2, nu2)) = nu2.eta1 - nu1.eta2 + mu.[eta1, eta2]:
 * max |DPhi^T Omega(mu1) DPhi - Omega(mu0)|. */
int dm_lie_symplecticity_defect(dm_integrator *I, double h, const double *g0,
                                const double *mu0, double *defect, dm_err *e);
/* n steps with h, then n with -h: the distance dist(g, g0) + |mu - mu0|. */
int dm_lie_reversal(dm_integrator *I, double h, long n, const double *g0, const double *mu0,
                    double *dev, dm_err *e);

/* {==== runs ============================================================= */

/* Runs are the core run driver's (core/run.h: dm_run_traj_alloc, dm_run)
 * on the integrator: the system's dm_system declares nq stored numbers per
 * configuration, so a trajectory has the columns t, the stored numbers of
 * g (coordinates, named by dm_lie_system_gnames), mu1.. (p), xi1.. (v),
 * energy and, when the momentum columns are asked for, momentum_1.. =
 * the spatial momentum (the system's momentum map); the metadata "space"
 * names the group. */

/* The group element of sample k of a trajectory of a run (or
 * loaded from its file): G from the "space" metadata (caller frees), the
 * stored numbers from the coordinate columns.  DM_EINVAL when the
 * trajectory has no "space" or its coordinates do not fit. */
int dm_lie_traj_group(const dm_traj *tr, dm_lie_group **G, dm_err *e);
int dm_lie_traj_element(const dm_traj *tr, const dm_lie_group *G, size_t k, double *g,
                        dm_err *e);

/* Empirical order: from (g0, mu0) to time T with each step h[i] (rounded to
 * whole steps), errors dist(g, gref) + |mu - muref| against a reference
 * computed with lie:gauss, 6 stages and h[k-1]/8, slope into *order. */
int dm_lie_order_estimate(const dm_lie_system *S, const char *method,
                          const dm_integ_opts *opts, const double *g0, const double *mu0,
                          double T, const double *h, size_t k, double *err, double *order,
                          dm_err *e);

#endif
