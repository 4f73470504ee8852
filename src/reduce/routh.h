/* routh.h -- automatic Routh reduction by cyclic coordinates (thesis ch. 2,
 * doc/reduce.md): the reduced objects derived symbolically, the
 * reduced integrators (RSPRK, discrete Routh equations, classical Routhian
 * SPRK), projection, reconstruction and geometric phases.
 *
 * Setting.  A Lagrangian L(q, v; par) on n coordinates, r <= 3 of which
 * (theta, the "cyclic" ones, any positions in q) do not appear in L; the
 * others are the shape coordinates x (s = n - r, in the order of q).  The
 * group acts by theta -> theta + phi.  L must be mechanical without terms
 * linear in v: L = 1/2 v^T M(x) v - V(x) (detected symbolically).  The
 * derivation (dm_routh_derive) builds, as expression nodes of the caller's
 * context:
 *   I (r x r locked inertia), I^{-1} (adjugate / determinant, r <= 3),
 *   A = I^{-1} M_theta,x (r x s mechanical connection), I^{-1} mu,
 *   muA = mu^T A (s), Mt = M_xx - M_x,theta I^{-1} M_theta,x (s x s),
 *   V, V_mu = V + 1/2 mu^T I^{-1} mu (amended potential),
 *   R = 1/2 xdot^T Mt xdot - V_mu (Routhian), Rc = R + muA . xdot (classical),
 *   B_ij = d_i (muA)_j - d_j (muA)_i (magnetic 2-form), 
 *   thetadot = I^{-1} mu - A xdot (reconstruction),
 * with mu a vector of r parameter nodes "mu_<cyclic name>", so set_mu never
 * re-derives.  A generalized force F(q, v) is reduced when its cyclic
 * components vanish identically (Lemma 2.15): Fhat(x, xdot) = F_x with
 * thetadot substituted.  Holonomic constraints g(q) must not depend on theta
 * (G-invariant): the reduced system lives on the preshape space with
 * ghat = g (Theorems 2.14, 2.17).
 *
 * Systems.  dm_routh_system() is the reduced system on the shape (or
 * preshape) space: Lagrangian R^mu, params = original params then mu,
 * reduced force and constraints; its kind is DM_ROUTH_KIND, so integrators
 * made for it (dm_integrator_new, dm_routh_integrator_new) are the reduced
 * families below, never a core method, which would integrate R^mu WITHOUT
 * the magnetic term.
 * dm_routh_classical() is the plain system of the classical Routhian Rc
 * (canonical momentum y = s + muA); dm_routh_full() the unreduced system.
 *
 * Reduced state.  (x, s), s = dR/dxdot = p_x - muA(x) (the momentum shift of
 * thesis §2.5).  Every "routh" integrator maps (x0, s0) -> (x1, s1) through
 * the dm_integrator interface (q = x, p = s), so runs, energies
 * (E = s.xdot - R = reduced energy H_mu) and trajectories work unchanged.
 * Methods (dm_routh_integrator_new):
 *   "gauss", "midpoint", "lobatto", "trapezoid" (= Lobatto 2), "prk" (user
 *        tableau): RSPRK (eq. 2.5.14) with that tableau, Newton with the exact
 *        Jacobian; constraints need a Lobatto-type tableau or midpoint
 *        (multipliers at every stage, as prk_constrained.c);
 *   "dr" (= "dr:midpoint"), "dr:gauss" / "dr:lobatto" (Galerkin, `stages`):
 *        the discrete Routh equations (2.3.29) in position-momentum form
 *        through the reduced discrete Legendre transforms; no forces or
 *        constraints;
 *   "classical" (= "classical:gauss"), "classical:<core method>": the core
 *        PRK engine on Rc, wrapped by the momentum shift sigma(x, s) =
 *        (x, s + muA(x)) so its state is (x, s) too.
 * Each also accumulates the group coordinate increment of every step
 * (reconstruction): RSPRK h sum b_j Thetadot_j (Hamiltonian side), DR and
 * classical psi_mu(x0, x1) (Lagrangian side); see dm_routh_integrator_theta.
 *
 * Non-mechanical Lagrangians.  When d2L/dv2 depends on v or L has terms
 * linear in v, there is no locked inertia or mechanical connection; the
 * derivation publishes only the symbols and M = d2L/dv2 (the other nodes
 * of dm_routh_exprs are DM_EXPR_NONE / NULL) and the reduced system is
 * the classical Routhian Rc = L - mu . thetadot on J = mu, evaluated
 * numerically (thetadot by Newton, exact derivatives by implicit
 * differentiation; routh_general.c).  The reduced state is (x, p_x)
 * (no momentum shift); every method is the classical-Routhian one
 * ("gauss" etc. = "classical:gauss"), "dr" uses the Galerkin L_d (midpoint
 * = Gauss 1); dm_routh_eval gives thetadot and R = Rc only; phase is
 * DM_EUNSUP; forces and constraints are refused (DM_EUNSUP).
 *
 * Singular locked inertia.  Integrators check I at every stage point and at
 * x1: when its smallest eigenvalue drops below sing_tol (default 1e-10)
 * times the largest eigenvalue of I at the first step after creation/reset,
 * the step fails with DM_ESINGULAR ("the group action is not free there"),
 * so a run stops keeping the partial trajectory.
 *
 * Ownership.  dm_routh_derive allocates; dm_routh_free releases (NULL ok).
 * The systems returned by the accessors belong to the dm_routh (never
 * dm_system_release them) and live until dm_routh_free; integrators made on
 * them must be freed first.  The expression context is only read during
 * derive; the node handles in dm_routh_exprs belong to it (print them with
 * the same context).  Evaluation helpers (dm_routh_eval, project, lift,
 * phase, reconstruct) use scratch space of the dm_routh: one thread at a
 * time; integrators have their own buffers.
 *
 * Errors.  Functions return DM_OK or a DM_E* status and fill the dm_err
 * (may be NULL): DM_EINVAL (a cyclic coordinate that L depends on -- the
 * message prints dL/dtheta --, a force with a cyclic component, a
 * constraint depending on theta, bad sizes), DM_EUNSUP (non-mechanical L,
 * terms linear in v, r > 3, an unsupported method/feature combination),
 * DM_ESINGULAR (singular locked inertia), DM_ENOCONV, DM_EDOM, DM_ENOMEM,
 * DM_EINTR (long loops poll dm_interrupted()).
 */
#ifndef DM_ROUTH_H
#define DM_ROUTH_H

#include <stddef.h>

#include "expr/expr.h"
#include "expr/native.h"
#include "core/status.h"
#include "core/system.h"
#include "core/tableau.h"
#include "core/trajectory.h"
#include "integrators/integrator.h"

#define DM_ROUTH_RMAX 3

typedef struct dm_routh dm_routh;

typedef struct dm_routh_spec {
  const char *name;                /* may be NULL */
  size_t n;                        /* coordinates */
  const dm_expr *q, *v;            /* n symbols each */
  size_t npar;
  const dm_expr *par;              /* npar parameters */
  const double *par_values;        /* npar values (NULL: zeros) */
  const char *const *coord_names;  /* n (NULL: names of q) */
  const char *const *param_names;  /* npar (NULL: names of par) */
  dm_expr L;
  const dm_expr *force;            /* n or NULL */
  size_t m;
  const dm_expr *constraints;      /* m or NULL */
  size_t r;                        /* cyclic coordinates, 1..DM_ROUTH_RMAX */
  const size_t *cyclic;            /* r distinct indices into q (0-based) */
  const double *mu;                /* r momentum values (NULL: zeros) */
  int native;                      /* enum dm_native_mode */
} dm_routh_spec;

/* The derived objects as nodes of the context given to dm_routh_derive.
 * Matrices are row-major; sizes in the comments. */
typedef struct dm_routh_exprs {
  size_t n, r, s, m, npar;
  const size_t *cyclic, *shape;    /* r / s indices into the full q */
  const dm_expr *x, *xdot;         /* s shape symbols / their velocities */
  const dm_expr *theta, *thetadot_sym;  /* r cyclic symbols / velocities */
  const dm_expr *mu;               /* r parameters mu_<name> */
  const dm_expr *M;                /* n*n full mass matrix d2L/dv2 */
  const dm_expr *I, *Iinv;         /* r*r */
  dm_expr detI;
  const dm_expr *A;                /* r*s */
  const dm_expr *Iinv_mu;          /* r */
  const dm_expr *muA;              /* s: (mu^T A)_i */
  const dm_expr *Mtilde;           /* s*s */
  dm_expr V, Vmu, R, Rc;
  const dm_expr *B;                /* s*s, B_ij = d_i muA_j - d_j muA_i */
  const dm_expr *thetadot;         /* r: I^{-1} mu - A xdot */
  const dm_expr *force;            /* s reduced force, or NULL */
  const dm_expr *constraints;      /* m, or NULL */
} dm_routh_exprs;

/* Numerical values at a shape point (x, xdot); every pointer may be NULL. */
typedef struct dm_routh_vals {
  double *I, *Iinv, *A, *Iinv_mu, *muA, *Mtilde, *B, *thetadot;
  double detI, V, Vmu, R, Rc;
} dm_routh_vals;

/* {==== derivation and accessors ======================================= */

int dm_routh_derive(dm_expr_ctx *ctx, const dm_routh_spec *spec, dm_routh **out,
                    dm_err *e);
void dm_routh_free(dm_routh *red);

const dm_routh_exprs *dm_routh_exprs_get(const dm_routh *red);
const dm_system *dm_routh_system(const dm_routh *red);     /* reduced, R^mu */
const dm_system *dm_routh_classical(const dm_routh *red);  /* Rc, state (x, y) */
const dm_system *dm_routh_full(const dm_routh *red);       /* unreduced */
/* 0 when L is not mechanical (see "Non-mechanical Lagrangians" above). */
int dm_routh_is_mechanical(const dm_routh *red);
/* 1 if the system is the reduced system of a dm_routh (then *red is set). */
int dm_routh_of_system(const dm_system *sys, dm_routh **red);

/* Momentum value (r) used by the reduced systems; set without re-deriving. */
int dm_routh_set_mu(dm_routh *red, const double *mu, dm_err *e);
const double *dm_routh_mu(const dm_routh *red);
/* Original parameter i (< npar) in every system of the reduction. */
int dm_routh_set_param(dm_routh *red, size_t i, double value, dm_err *e);
/* Relative threshold of the singular-inertia test (> 0; default 1e-10). */
int dm_routh_set_sing_tol(dm_routh *red, double tol, dm_err *e);

/* 1 if expression e (of the shape coordinates, their velocities, the
 * parameters and mu) vanishes identically: a constant 0, or a sum /
 * difference whose value is below 1e-12 times the size of its two terms at
 * several pseudo-random points near the current parameters (e.g. the
 * r1 dr2 component of the double pendulum's beta, zero by Euler's theorem
 * for the homogeneous I; the simplifier does not see it).  Meant for
 * display; the derived expressions themselves are never changed. */
int dm_routh_vanishes(dm_routh *red, dm_expr_ctx *ctx, dm_expr e);

/* Values of the derived objects at (x, xdot) (xdot may be NULL: zeros) with
 * the current mu.  DM_EDOM when a value is not finite. */
int dm_routh_eval(dm_routh *red, const double *x, const double *xdot,
                  dm_routh_vals *out, dm_err *e);

/* {==== projection and lift ============================================= */

/* Full (q, p) -> shape x (s), shifted momentum s_ = p_x - mu^T A(x) (s), the
 * momentum mu = p_theta (r) and theta (r); any output may be NULL.  Uses the
 * state's own mu (not the one set in red).  DM_ESINGULAR when I(x) is
 * singular (not positive definite). */
int dm_routh_project(dm_routh *red, const double *q, const double *p, double *x,
                     double *s_, double *mu, double *theta, dm_err *e);
/* Same from (q, v): p = dL/dv first. */
int dm_routh_project_qv(dm_routh *red, const double *q, const double *v, double *x,
                        double *s_, double *mu, double *theta, dm_err *e);
/* (theta, x, s_) with red's mu -> full (q, p) (either may be NULL). */
int dm_routh_lift(dm_routh *red, const double *theta, const double *x,
                  const double *s_, double *q, double *p, dm_err *e);
/* The same with the full velocity v (may be NULL): xdot from the reduced
 * Legendre map, thetadot = I^{-1} mu - A xdot. */
int dm_routh_lift_state(dm_routh *red, const double *theta, const double *x,
                        const double *s_, double *q, double *p, double *v, dm_err *e);
/* Reduced Legendre map and its inverse: s_ = dR/dxdot (x, xdot) and
 * Mtilde(x) xdot = s_ (R is mechanical); DM_ESINGULAR for singular Mtilde. */
int dm_routh_momentum(dm_routh *red, const double *x, const double *xdot, double *s_,
                      dm_err *e);
int dm_routh_velocity(dm_routh *red, const double *x, const double *s_, double *xdot,
                      dm_err *e);

/* {==== integrators ====================================================== */

/* The system kind of reduced systems (dm_system.kind): the integrator
 * families below answer for it. */
#define DM_ROUTH_KIND "routh"

/* Register the reduced families (rsprk, dr, classical) with the integrator
 * registry; idempotent, called by dm_routh_derive and the Lua binding. */
int dm_routh_register_integrators(dm_err *e);

/* Integrator on red's reduced system (method names above; opts as for
 * dm_integrator_new: stages, tol, maxiter, simplified, tableau for "prk");
 * the same as dm_integrator_new(dm_routh_system(red), ...).  Free with
 * dm_integrator_free before red. */
int dm_routh_integrator_new(dm_routh *red, const char *method, const dm_integ_opts *opts,
                            dm_integrator **out, dm_err *e);
/* 1 if I belongs to one of the reduced families. */
int dm_routh_is_integrator(const dm_integrator *I);
/* Group coordinate accumulated over the steps taken (r values; starts at 0
 * or at the value set) -- the reconstruction theta_k. */
int dm_routh_integrator_theta(const dm_integrator *I, double *theta, dm_err *e);
int dm_routh_integrator_set_theta(dm_integrator *I, const double *theta, dm_err *e);
/* "rsprk", "dr" or "classical". */
const char *dm_routh_integrator_kind(const dm_integrator *I);

/* Non-canonical symplecticity defect of one step at (x0, s0):
 * max |DPhi^T W(x1) DPhi - W(x0)| / max(1, max |W(x0)|) with
 * W(x) = [[-B(x), Id], [-Id, 0]] (doc/reduce.md §10).  DPhi exact (implicit
 * differentiation of each method's step equations).  Not for constrained
 * systems. */
int dm_routh_symplecticity_defect(dm_integrator *I, double h, const double *x0,
                                  const double *s0, double *defect, dm_err *e);

/* {==== discrete Routh equations (doc/reduce.md §7) ========================= */

typedef struct dm_routh_dr dm_routh_dr;

/* Discrete Routh machinery for a discrete Lagrangian of the full system:
 * t == NULL: midpoint L_d = h L((q0+q1)/2, (q1-q0)/h) (psi_mu in closed form);
 * otherwise the Galerkin L_d of tableau t (psi_mu by Newton).  Unforced,
 * unconstrained systems only.  On error *out is NULL. */
int dm_routh_dr_alloc(dm_routh *red, const dm_tableau *t, double tol, int maxiter,
                      dm_routh_dr **out, dm_err *e);
void dm_routh_dr_free(dm_routh_dr *dr);
/* psi_mu(x0, x1) (r): the Delta theta with J_d((0, x0), (psi, x1)) = mu;
 * Dpsi (r x 2s: [D1 psi | D2 psi], row-major) may be NULL. */
int dm_routh_dr_psi(dm_routh_dr *dr, double h, const double *x0, const double *x1,
                    double *psi, double *Dpsi, dm_err *e);
/* Reduced discrete Lagrangian and its one-forms at (x0, x1): Lhat, D1 Lhat,
 * D2 Lhat, Ahat_1, Ahat_2 (s each; any pointer may be NULL). */
int dm_routh_dr_lhat(dm_routh_dr *dr, double h, const double *x0, const double *x1,
                     double *Lhat, double *D1, double *D2, double *A1, double *A2,
                     dm_err *e);
/* Residuals at (x_prev, x_cur, x_next): the general DR form
 * D2 Lhat(p, c) + D1 Lhat(c, n) - Ahat_2(p, c) - Ahat_1(c, n)  (res_dr) and
 * the shape components of DEL with Delta theta = psi_mu (res_del); s each,
 * either may be NULL. */
int dm_routh_dr_residual(dm_routh_dr *dr, double h, const double *xp, const double *xc,
                         const double *xn, double *res_dr, double *res_del, dm_err *e);
/* Solve the DR equations for x_next given (x_prev, x_cur) (Newton, exact
 * Jacobian; x_next holds the guess on entry when guess != 0). */
int dm_routh_dr_solve(dm_routh_dr *dr, double h, const double *xp, const double *xc,
                      double *xn, int guess, dm_err *e);
/* Position-momentum form: (x0, s0) -> (x1, s1) with
 * s0 = -D1 Lhat + Ahat_1 (x0, x1) and s1 = D2 Lhat - Ahat_2 (x0, x1);
 * *psi (may be NULL) receives psi_mu(x0, x1). */
int dm_routh_dr_step(dm_routh_dr *dr, double h, const double *x0, const double *s0,
                     double *x1, double *s1, double *psi, dm_err *e);
/* D(x1, s1)/D(x0, s0) (2s x 2s, row-major) of dm_routh_dr_step at
 * (x0, s0), exact: implicit differentiation of the reduced discrete
 * Legendre transforms with the second derivatives of L_d and D psi_mu. */
int dm_routh_dr_jacobian(dm_routh_dr *dr, double h, const double *x0, const double *s0,
                         double *DPhi, dm_err *e);
/* Newton iterations of the last solve. */
int dm_routh_dr_iters(const dm_routh_dr *dr);

/* {==== reconstruction and phases ======================================= */

/* Full trajectory (columns t, q, p, v of the full system) from a reduced
 * trajectory rt (columns t, x, and s = p columns; v optional) with mu = red's
 * mu and theta(t0) = theta0 (r; NULL: zeros): between consecutive samples
 * the reduced step is repeated with integrator I (a "routh" integrator of
 * red) and step h (h == 0: one step per sample interval), starting from the
 * stored sample, and theta advanced by the group increments the integrator
 * reports (Hamiltonian side for RSPRK, psi_mu for DR and classical).
 * *out is a new trajectory (caller frees). */
int dm_routh_reconstruct(dm_routh *red, dm_integrator *I, double h, const dm_traj *rt,
                         const double *theta0, dm_traj **out, dm_err *e);

/* Split the group advance over a (closed) shape loop sampled in `loop`
 * (columns t and x; consecutive samples joined by straight segments) into
 * dyn = sum_k dt I(xbar)^{-1} mu and geo = -sum_k A(xbar) (x_{k+1} - x_k),
 * xbar the segment midpoint (r each); dyn + geo is the midpoint
 * reconstruction of theta(T) - theta(0).  *gap (may be NULL) = |x_N - x_0|
 * (max norm), the closure defect of the loop. */
int dm_routh_phase(dm_routh *red, const dm_traj *loop, double *dyn, double *geo,
                   double *gap, dm_err *e);

#endif
