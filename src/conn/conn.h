/* conn.h -- principal bundles, continuous and discrete connections,
 * horizontal lifts, curvature and holonomy, the discrete mechanical
 * connection and the discrete Levi-Civita connection of a triangle mesh
 * (thesis ch. 4; theory, conventions and the corrected formulas in
 * doc/bundles-connections-holonomy.md).
 *
 * Conventions (doc/bundles-connections-holonomy.md §1).  Groups act on the
 * left, g.q.  A trivial bundle Q = S x G stores a point q = (x, g) as the nx
 * shape coordinates followed by the G->nq group coordinates, and h.(x, g) =
 * (x, hg).  Body velocity xi = g^-1 gdot.  The local connection form
 * A_loc(x) is a dim x nx matrix (row-major): horizontal motion is
 * g^-1 gdot = -A_loc(x) xdot.  The curvature is
 * B_ij = d_i A_j - d_j A_i - [A_i, A_j] (A_i the i-th column), so that a
 * small counter-clockwise loop of area e^2 in the (x_i, x_j) plane has body
 * holonomy exp(-e^2 B_ij) + O(e^3).  A discrete connection is given by its
 * local representation A(x0, x1) in G, with A_d(x0, g0, x1, g1) =
 * g1 A(x0, x1) g0^-1 (horizontal pairs: g1 = g0 A(x0, x1)^-1), or, on
 * bundles without a global section (the sphere frames), by an intrinsic
 * horizontal lift q0, x1 -> q1bar with A_d(q0, q1) = fiber_diff(q1bar, q1).
 * Holonomy of a closed shape path from q0 = (x0, g0): the lift ends at
 * g0 P (P the body holonomy); the spatial holonomy is g0 P g0^-1.
 *
 * Objects.
 *   dm_conn_bundle  a principal bundle: group, sizes and a type object of
 *                   functions (action, projection, fibre difference,
 *                   optional section, trivialization, symbolic action).
 *                   Built-in: trivial S x G, the sphere frames SO(3) ->
 *                   S^2 with G = SO(2), and n particles in R^3 under the
 *                   diagonal rotation.
 *   dm_conn         a continuous connection on a trivial bundle: a
 *                   callback giving A_loc(x) and, when it can, its
 *                   derivatives (exact curvature); from expressions
 *                   (dm_conn_expr_alloc) the callback runs compiled tapes.
 *   dm_conn_dc      a discrete connection: a rule (a type object found by
 *                   name: "euler", "midpoint", "cayley", "transport",
 *                   "exact", "trivial", "local", "mechanical",
 *                   "levi-civita") with its inputs.
 *
 * Ownership.  _alloc / _free pairs; _free(NULL) is a no-op.  A bundle owns
 * a copy of its group.  A connection keeps a pointer to its bundle, a
 * discrete connection to its bundle and parent connection: they must
 * outlive it.  Nothing else allocates; outputs are caller memory.
 *
 * Errors.  Functions return DM_OK or a DM_E* status and fill the dm_err
 * (may be NULL) with a message naming the operation and the input:
 * DM_EINVAL (sizes, a pair whose shapes do not match in a composition, an
 * unknown rule), DM_EUNSUP (an operation the bundle or rule cannot do:
 * reduce on a bundle without trivialization, a continuous connection on a
 * non-trivial bundle), DM_EDOM (log at the cut locus, antipodal points on
 * the sphere, a degenerate triangle or particle configuration),
 * DM_ENOCONV / DM_ESINGULAR (the Newton solve of the discrete mechanical
 * connection: never a silent value), DM_ECALLBACK (a user callback
 * failed), DM_EINTR (long loops poll dm_interrupted()).
 *
 * Threads.  Bundles are immutable.  Connections hold scratch buffers and
 * counters: one thread at a time per object (make one per thread).
 */
#ifndef DM_CONN_H
#define DM_CONN_H

#include <stddef.h>

#include "core/status.h"
#include "expr/expr.h"
#include "lie/lie.h"
#include "dec/dec.h"

/* Bounds for callers' stack buffers. */
#define DM_CONN_NX_MAX 64       /* shape coordinates */
#define DM_CONN_NQ_MAX 320      /* coordinates of a bundle point */

typedef struct dm_conn_bundle dm_conn_bundle;
typedef struct dm_conn dm_conn;
typedef struct dm_conn_dc dm_conn_dc;
typedef struct dm_conn_rule dm_conn_rule;

/* {==== bundles ============================================================ */

typedef struct dm_conn_bundle_type {
  const char *name;             /* "trivial", "sphere_frames", "particles" */
  /* gq = g.q (gq may alias q) */
  void (*act)(const dm_conn_bundle *B, const double *g, const double *q, double *gq);
  /* the shape point (nx chart coordinates) of q */
  void (*proj)(const dm_conn_bundle *B, const double *q, double *x);
  /* g with q2 = g.q (q, q2 on one fibre; the caller checks that) */
  int (*fiber_diff)(const dm_conn_bundle *B, const double *q, const double *q2, double *g,
                    dm_err *e);
  /* a point over x (NULL when none is known); DM_EDOM outside the chart */
  int (*section)(const dm_conn_bundle *B, const double *x, double *q, dm_err *e);
  /* (x, g) with q = g.section(x) (NULL: no global trivialization) */
  int (*trivialize)(const dm_conn_bundle *B, const double *q, double *x, double *g);
  /* the action on expression nodes (NULL: none; the discrete mechanical
   * connection needs it) */
  int (*act_sym)(dm_expr_ctx *c, const dm_conn_bundle *B, const dm_expr *g, const dm_expr *q,
                 dm_expr *gq, dm_err *e);
  /* DM_EDOM with a message when x is not a shape point (sphere: |p| != 1) */
  int (*shape_check)(const dm_conn_bundle *B, const double *x, const char *what, dm_err *e);
  /* the point at s in [0, 1] of the shape path from x0 to x1 used by the
   * transport rule, and its s-derivative (a straight line in the chart,
   * a great-circle arc on the sphere) */
  void (*shape_interp)(const dm_conn_bundle *B, const double *x0, const double *x1, double s,
                       double *xs, double *dxs);
} dm_conn_bundle_type;

struct dm_conn_bundle {
  const dm_conn_bundle_type *type;
  dm_lie_group *G;              /* owned */
  size_t nq;                    /* doubles per bundle point */
  size_t nx;                    /* shape chart coordinates */
  size_t dimS;                  /* dimension of the shape space */
  size_t npart;                 /* particles bundle: number of particles */
  char name[80];
};

/* S x G with S = R^m (a chart; m = 0 gives Q = G). */
dm_conn_bundle *dm_conn_bundle_trivial(size_t m, const dm_lie_group *G, dm_err *e);
/* Q = SO(3) (9 numbers, row-major), S = S^2 (p = R e3, 3 numbers),
 * G = SO(2) acting by theta.R = R Rz(theta). */
dm_conn_bundle *dm_conn_bundle_sphere_frames(dm_err *e);
/* Q = (R^3)^n (n >= 2), G = SO(3) acting on every particle; the shape of
 * q is q turned into the frame of its first two particles (first along
 * e1, second in the (e1, e2) half plane y > 0), defined when they are
 * linearly independent (DM_EDOM otherwise). */
dm_conn_bundle *dm_conn_bundle_particles(size_t n, dm_err *e);
void dm_conn_bundle_free(dm_conn_bundle *B);

/* 1 when B is a trivial bundle (points (x, g), continuous connections). */
int dm_conn_bundle_is_trivial(const dm_conn_bundle *B);
/* Dispatch (see dm_conn_bundle_type); unsupported operations give
 * DM_EUNSUP naming the bundle. */
void dm_conn_act(const dm_conn_bundle *B, const double *g, const double *q, double *gq);
void dm_conn_proj(const dm_conn_bundle *B, const double *q, double *x);
int dm_conn_fiber_diff(const dm_conn_bundle *B, const double *q, const double *q2, double *g,
                       dm_err *e);
int dm_conn_section(const dm_conn_bundle *B, const double *x, double *q, dm_err *e);
int dm_conn_trivialize(const dm_conn_bundle *B, const double *q, double *x, double *g,
                       dm_err *e);
int dm_conn_shape_check(const dm_conn_bundle *B, const double *x, const char *what, dm_err *e);
/* Largest coordinate difference of the shapes of q0 and q1 (for checks). */
double dm_conn_shape_gap(const dm_conn_bundle *B, const double *q0, const double *q1);
/* Discrete generator i_q(g) = (q, g.q): writes the second point. */
void dm_conn_generator(const dm_conn_bundle *B, const double *q, const double *g, double *gq);

/* }==== */

/* {==== continuous connections ============================================== */

/* A_loc(x) into A (dim x nx, row-major) and, when dA is not NULL, its
 * derivatives dA[(k*dim + a)*nx + i] = d A_ai / d x_k.  Returns 0, or a
 * DM_E* status (with a message in e) when x is outside the domain.
 * Called with dA != NULL only when the connection was made with
 * has_dA = 1. */
typedef int (*dm_conn_fn)(void *ud, const double *x, double *A, double *dA, dm_err *e);

/* A connection on the trivial bundle B (DM_EUNSUP otherwise).  has_dA: the
 * callback gives derivatives (curvature exact); else central differences.
 * ud is not owned; free_ud (may be NULL) is called on it by dm_conn_free. */
dm_conn *dm_conn_alloc(const dm_conn_bundle *B, dm_conn_fn fn, void *ud, int has_dA,
                       void (*free_ud)(void *), dm_err *e);
void dm_conn_free(dm_conn *C);
const dm_conn_bundle *dm_conn_bundle_of(const dm_conn *C);

/* A connection from expressions of the caller's context: A (dim x nx
 * nodes, row-major) in the nx symbols x and the npar parameters par
 * (values copied; change them with dm_conn_set_params).  Compiles A and
 * its exact derivatives to tapes. */
dm_conn *dm_conn_expr_alloc(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *x,
                            const dm_expr *A, size_t npar, const dm_expr *par,
                            const double *parval, dm_err *e);
/* The mechanical connection A_loc = I(x)^-1 C(x) of a G-invariant kinetic
 * energy 1/2 xdot^T M xdot + xdot^T C^T xi + 1/2 xi^T I xi (I the locked
 * inertia, dim x dim, symmetric positive definite; C dim x nx): A is built
 * symbolically (elimination without pivoting, valid for SPD I) and then
 * handled as dm_conn_expr_alloc.  Aout (may be NULL; dim*nx nodes)
 * receives the nodes of A. */
dm_conn *dm_conn_mech_alloc(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *x,
                            const dm_expr *I, const dm_expr *Cm, size_t npar,
                            const dm_expr *par, const double *parval, dm_expr *Aout,
                            dm_err *e);
/* The same from a reduced Lagrangian l(x, xdot, xi): I = d2l/dxi2,
 * C = d2l/dxi dxdot (DM_EINVAL when l is not quadratic in (xdot, xi):
 * then I or C depends on the velocities). */
dm_conn *dm_conn_lagrangian_alloc(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *x,
                                  const dm_expr *xdot, const dm_expr *xi, dm_expr l,
                                  size_t npar, const dm_expr *par, const double *parval,
                                  dm_expr *Aout, dm_err *e);
/* Compile A_loc of an expression connection to native code (expr/native.h;
 * x0 a typical shape point for the check against the tape, may be NULL);
 * later evaluations of A_loc run it.  On failure (DM_ENOTFOUND no
 * compiler, DM_EFAILED, ...) the tape stays in use. */
int dm_conn_native(dm_conn *C, const double *x0, dm_err *e);
/* Parameters of an expression connection (DM_EINVAL for others). */
int dm_conn_set_params(dm_conn *C, const double *parval, dm_err *e);

/* A_loc(x) (dim x nx). */
int dm_conn_local(dm_conn *C, const double *x, double *A, dm_err *e);
/* The connection form A(q)(xdot, xi) = Ad_g (xi + A_loc(x) xdot), xi the
 * body velocity (dim). */
int dm_conn_form(dm_conn *C, const double *q, const double *xdot, const double *xi,
                 double *out, dm_err *e);
/* The horizontal lift of xdot at q as a body velocity: xi = -A_loc(x) xdot. */
int dm_conn_hlift_vec(dm_conn *C, const double *x, const double *xdot, double *xi, dm_err *e);
/* Curvature B_ij (dim values; i, j 0-based shape directions). */
int dm_conn_curvature(dm_conn *C, const double *x, size_t i, size_t j, double *b, dm_err *e);

/* A shape path s in [0, 1] -> x(s), x'(s). */
typedef int (*dm_conn_curve_fn)(void *ud, double s, double *x, double *dx, dm_err *e);

/* A shape path from expressions: x(s) (nx nodes of the caller's context in
 * the symbol s), compiled with its exact derivative; evaluate it through
 * dm_conn_curve_eval as a dm_conn_curve_fn with ud = the curve. */
typedef struct dm_conn_curve dm_conn_curve;
dm_conn_curve *dm_conn_curve_alloc(dm_expr_ctx *ctx, dm_expr s, size_t nx, const dm_expr *x,
                                   dm_err *e);
void dm_conn_curve_free(dm_conn_curve *c);
int dm_conn_curve_eval(void *ud, double s, double *x, double *dx, dm_err *e);

/* Transport options: Magnus 4 on `substeps` equal pieces (>= 1), or, when
 * tol > 0, adaptive Runge-Kutta-Prince-Dormand 8 (GSL rk8pd) with
 * absolute and relative tolerance tol. */
typedef struct dm_conn_topts {
  size_t substeps;
  double tol;
} dm_conn_topts;

/* Body transport H along a path: g(1) = g(0) H for the horizontal lift,
 * g' = g M(s), M = -A_loc(x(s)) x'(s). */
int dm_conn_transport(dm_conn *C, dm_conn_curve_fn curve, void *ud, const dm_conn_topts *o,
                      double *H, dm_err *e);
/* Along the straight segment x0 -> x1 of the chart. */
int dm_conn_transport_segment(dm_conn *C, const double *x0, const double *x1,
                              const dm_conn_topts *o, double *H, dm_err *e);
/* Along the polygon xs (n >= 2 points of nx) with straight edges. */
int dm_conn_transport_polygon(dm_conn *C, const double *xs, size_t n, const dm_conn_topts *o,
                              double *H, dm_err *e);
/* Holonomy of a closed path (the end point must equal the start: DM_EINVAL
 * otherwise, tolerance 1e-9 relative) from q0 = (x0, g0): spatial, body
 * (either may be NULL).  npieces paths are followed one after the other
 * (curves[k], uds[k]). */
int dm_conn_holonomy(dm_conn *C, size_t npieces, const dm_conn_curve_fn *curves,
                     void *const *uds, const double *q0, const dm_conn_topts *o,
                     double *spatial, double *body, dm_err *e);
/* The same along the closed polygon xs (n >= 2 points of nx, last = first)
 * with straight edges. */
int dm_conn_holonomy_polygon(dm_conn *C, const double *xs, size_t n, const double *q0,
                             const dm_conn_topts *o, double *spatial, double *body, dm_err *e);

/* }==== */

/* {==== discrete connections ================================================ */

/* User local representation A(x0, x1) (a group element, G->nq). */
typedef int (*dm_conn_pair_fn)(void *ud, const double *x0, const double *x1, double *A,
                               dm_err *e);

/* What a rule needs (dm_conn_rule.needs). */
enum {
  DM_CONN_NEEDS_PARENT = 1,     /* a continuous connection */
  DM_CONN_NEEDS_LOCAL = 2,      /* a dm_conn_pair_fn */
  DM_CONN_NEEDS_LD = 4,         /* a discrete Lagrangian (dm_conn_dc_mechanical) */
  DM_CONN_NEEDS_TRIVIAL = 8,    /* a trivial bundle */
  DM_CONN_NEEDS_SPHERE = 16     /* the sphere-frame bundle */
};

/* A rule is a type object (GSL style): a family of discrete connections. */
struct dm_conn_rule {
  const char *name;
  int order;                    /* order k (local error h^(k+1)); 0: exact, -1: depends */
  unsigned needs;
  /* the local representation A(x0, x1) (trivial bundles) */
  int (*local)(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e);
  /* the intrinsic horizontal lift (NULL: from local) */
  int (*hlift)(dm_conn_dc *D, const double *q0, const double *x1, double *q1, dm_err *e);
  /* A_d(q0, q1) directly (NULL: fiber_diff(hlift(q0, pi q1), q1)) */
  int (*eval)(dm_conn_dc *D, const double *q0, const double *q1, double *g, dm_err *e);
};

/* The rule named `name`, or NULL. */
const dm_conn_rule *dm_conn_rule_find(const char *name);
/* The registered rules, NULL-terminated. */
const dm_conn_rule *const *dm_conn_rules(void);

/* A discrete connection of rule R on B.  parent: the continuous connection
 * for euler, midpoint, cayley, transport, exact (NULL otherwise); local, ud:
 * the user local representation for "local".  Checks what the rule needs
 * (DM_EINVAL naming the missing input or the wrong bundle). */
dm_conn_dc *dm_conn_dc_alloc(const dm_conn_rule *R, const dm_conn_bundle *B, dm_conn *parent,
                             dm_conn_pair_fn local, void *ud, dm_err *e);
void dm_conn_dc_free(dm_conn_dc *D);
const dm_conn_rule *dm_conn_dc_rule(const dm_conn_dc *D);
const dm_conn_bundle *dm_conn_dc_bundle(const dm_conn_dc *D);
/* Transport rule: the options of its continuous transports. */
void dm_conn_dc_set_topts(dm_conn_dc *D, const dm_conn_topts *o);

/* The discrete mechanical connection of a G-invariant discrete Lagrangian
 * Ld(q0, q1) (an expression of the caller's context in the nq symbols q0,
 * the nq symbols q1 and the npar parameters): horizontal pairs have zero
 * discrete momentum J_d(q0, q1) = D2 Ld(q0, q1) . xi_Q(q1).  A_d(q0, q1) =
 * k^-1 where J_d(q0, k.q1) = mu (mu = 0 unless set, abelian G only), found
 * by Newton on the group, k <- k exp(eta), from the guess connection's
 * value (NULL: the identity) with the exact Jacobian (derivatives of Ld
 * compiled to tapes).  Needs a bundle with a symbolic action.  tol: update
 * size to stop (default 1e-14 when <= 0), maxit (default 50 when 0). */
dm_conn_dc *dm_conn_dc_mechanical(const dm_conn_bundle *B, dm_expr_ctx *ctx,
                                  const dm_expr *q0, const dm_expr *q1, dm_expr Ld,
                                  size_t npar, const dm_expr *par, const double *parval,
                                  dm_conn_dc *guess, double tol, int maxit, dm_err *e);
/* The midpoint discrete Lagrangian of a reduced Lagrangian l(x, xdot, xi)
 * on a trivial bundle: Ld = h l((x0 + x1)/2, (x1 - x0)/h, log(g0^-1 g1)/h)
 * as nodes in the symbols q0 = (x0, g0), q1 = (x1, g1) (nq each);
 * G-invariant for any group.  xs, xd (nx) and xi (dim) are the symbols l
 * is written in. */
int dm_conn_midpoint_ld(dm_expr_ctx *ctx, const dm_conn_bundle *B, const dm_expr *q0,
                        const dm_expr *q1, const dm_expr *xs, const dm_expr *xd,
                        const dm_expr *xi, dm_expr l, double h, dm_expr *Ld, dm_err *e);
/* The discrete momentum J_d(q0, q1) (dim) of a mechanical connection. */
int dm_conn_dc_momentum(dm_conn_dc *D, const double *q0, const double *q1, double *J, dm_err *e);
/* Target momentum mu (dim; NULL: zero).  DM_EUNSUP for non-abelian G
 * unless mu = 0. */
int dm_conn_dc_set_mu(dm_conn_dc *D, const double *mu, dm_err *e);
int dm_conn_dc_set_params(dm_conn_dc *D, const double *parval, dm_err *e);
/* Newton statistics since creation: solves, iterations. */
void dm_conn_dc_newton_stats(const dm_conn_dc *D, unsigned long *solves, unsigned long *iters);

/* A(x0, x1) (trivial bundles; DM_EUNSUP otherwise). */
int dm_conn_dc_local(dm_conn_dc *D, const double *x0, const double *x1, double *A, dm_err *e);
/* A_d(q0, q1) in G. */
int dm_conn_dc_eval(dm_conn_dc *D, const double *q0, const double *q1, double *g, dm_err *e);
/* hor(q0, q1) = (q0, A_d^-1 q1), ver(q0, q1) = (q0, A_d q0): the second
 * points (the first is q0). */
int dm_conn_dc_hor(dm_conn_dc *D, const double *q0, const double *q1, double *h1, dm_err *e);
int dm_conn_dc_ver(dm_conn_dc *D, const double *q0, const double *q1, double *v1, dm_err *e);
/* The horizontal lift of the shape point x1 at q0. */
int dm_conn_dc_hlift(dm_conn_dc *D, const double *q0, const double *x1, double *q1, dm_err *e);
/* Lift the shape polygon xs (n points of nx) from q0 (over xs[0]; checked)
 * into qs (n points of nq; qs[0] = q0). */
int dm_conn_dc_lift(dm_conn_dc *D, const double *xs, size_t n, const double *q0, double *qs,
                    dm_err *e);
/* Holonomy of the closed polygon xs (last point = first, checked) from q0:
 * spatial g0 P g0^-1 and body P (body needs a trivialization or an
 * abelian G; either pointer may be NULL); *lifted (may be NULL): for
 * one-dimensional abelian groups (R, SO(2)) the accumulated unwrapped
 * value of P, which counts the turns a mod-2pi angle forgets. */
int dm_conn_dc_holonomy(dm_conn_dc *D, const double *xs, size_t n, const double *q0,
                        double *spatial, double *body, double *lifted, dm_err *e);
/* Extended pair-groupoid composition (a0, a1).(b0, b1) = (a0, A_d(b0, a1) b1),
 * defined when a1 and b0 have the same shape (DM_EINVAL otherwise): the
 * second point c1 (the first is a0). */
int dm_conn_dc_compose(dm_conn_dc *D, const double *a0, const double *a1, const double *b0,
                       const double *b1, double *c1, dm_err *e);
/* The reduced pair (x0, x1, zeta), zeta = g0^-1 A_d(q0, q1) g0 the body
 * representative of [q0, A_d(q0, q1)], and back: q1 with reduce(q0, q1) =
 * (x0, x1, zeta) for the given q0 over x0.  Need a trivialization. */
int dm_conn_dc_reduce(dm_conn_dc *D, const double *q0, const double *q1, double *x0, double *x1,
                      double *zeta, dm_err *e);
int dm_conn_dc_unreduce(dm_conn_dc *D, const double *x0, const double *x1, const double *zeta,
                        const double *q0, double *q1, dm_err *e);
/* Order test: defects d(h_k) = |log(A_ref(q, q1) A_d(q, q1)^-1)|,
 * q1 = (x0 + h_k v, g0) (the sphere: exp_p(h_k v)), and the least-squares
 * slope of log d against log h (order = slope - 1). */
int dm_conn_dc_order(dm_conn_dc *D, dm_conn_dc *ref, const double *q, const double *v,
                     const double *h, size_t nh, double *defects, double *slope, dm_err *e);
/* The continuous limit d/de A_d(q, q(e)) at e = 0 by central differences,
 * q(e) = (x + e xdot, g exp(e xi)) (trivial bundles): an algebra element. */
int dm_conn_dc_limit(dm_conn_dc *D, const double *q, const double *xdot, const double *xi,
                     double eps, double *out, dm_err *e);

/* {==== phases of sampled shape paths ====================================== */

/* The geometric phase of the shape path sampled by a trajectory T: its
 * columns cols[0..nx) (NULL: the first nx coordinates), followed from
 * q0 = (x(0), g0) (trivial bundles; q0's shape must be the first sample).
 * body: P with g_N = g0 P (the body transport; for a closed path the body
 * holonomy), spatial: g0 P g0^-1, *gap: the largest coordinate difference
 * between the first and last samples (0 for a closed loop).  The discrete
 * version lifts sample to sample with D; the continuous one transports
 * along the straight segments between samples with options o.  Either
 * output pointer may be NULL.  DM_EINVAL for fewer than 2 samples or a
 * column out of range. */
struct dm_traj;
int dm_conn_dc_phase(dm_conn_dc *D, const struct dm_traj *T, const size_t *cols,
                     const double *q0, double *spatial, double *body, double *gap, dm_err *e);
int dm_conn_phase(dm_conn *C, const struct dm_traj *T, const size_t *cols, const double *q0,
                  const dm_conn_topts *o, double *spatial, double *body, double *gap, dm_err *e);

/* }==== */

/* {==== the discrete Levi-Civita connection of a triangle mesh ============== */

/* Every triangle carries an orthonormal frame of its plane: e1 along its
 * first edge (top[t][0] -> top[t][1]), e2 turned by +90 degrees in the
 * triangle's orientation.  The transition across a shared edge is the
 * rotation angle (SO(2)) carrying vectors expressed in the frame of t0 to
 * the frame of t1 such that the edge keeps its physical direction: the
 * rotation fixing the complement of span(n0, n1) and taking the edge
 * normal n0 to n1.  Needs only the edge lengths (embedded and intrinsic
 * geometries alike).  DM_EINVAL when t0, t1 share no edge. */
int dm_conn_mesh_transition(const dm_dec_geom *G, int t0, int t1, double *angle, dm_err *e);
/* Holonomy around the interior vertex v: the product of the transitions
 * around its star, counter-clockwise, as an angle in (-pi, pi] (equal to
 * the angle defect 2 pi - sum of the angles at v, mod 2 pi).  DM_EINVAL
 * for a boundary vertex or a non-manifold star. */
int dm_conn_mesh_vertex_holonomy(const dm_dec_geom *G, int v, double *angle, dm_err *e);
/* Transport of the angle of a vector along a chain of adjacent triangles
 * ts[0..n): *angle (in the frame of ts[0]) becomes the angle in the frame
 * of ts[n-1]. */
int dm_conn_mesh_transport(const dm_dec_geom *G, const int *ts, size_t n, double *angle,
                           dm_err *e);
/* The angle defect 2 pi - sum of the triangle angles at v (boundary
 * vertices: pi - sum). */
double dm_conn_mesh_defect(const dm_dec_geom *G, int v);

/* }==== */

#endif
