/* lie.h -- Lie groups, their Lie algebras, and the spheres S^n as
 * homogeneous spaces: the configuration manifolds of mechanics on groups.
 *
 * Groups.  R^n, SO(2), T^n, SO(3), SE(2), SE(3) and finite products of
 * them.  A group is a dm_lie_group: an immutable descriptor (sizes, name,
 * factors) pointing to a constant type object, a table of functions (GSL
 * style: one table per family, see dm_lie_type).  Elements are plain
 * arrays of G->nq doubles, algebra elements arrays of G->dim doubles in the
 * coordinates below.  The theory, conventions and the formulas with their
 * numerical treatment are in doc/lie.md.
 *
 *   group   storage (nq)                       algebra (dim)
 *   R^n     x (n)                              v (n)
 *   SO(2)   angle theta, unwrapped (1)         omega (1)
 *   T^n     n unwrapped angles                 n
 *   SO(3)   R row-major (9)                    omega (3), hat = cross product
 *   SE(2)   (theta, x, y): theta unwrapped     (omega, vx, vy)
 *   SE(3)   R row-major, then p (12)           (omega, v), rotation first
 *   product concatenation of the factors       concatenation
 *
 * Angles are stored unwrapped: composition adds without reduction, log
 * returns the principal value in (-pi, pi].  SE(2) composes as
 * (t1, p1)(t2, p2) = (t1 + t2, p1 + R(t1) p2), SE(3) as
 * (R1, p1)(R2, p2) = (R1 R2, p1 + R1 p2).
 *
 * Trivializations.  The derivative of a chart chi (exp or the Cayley map)
 * is given right-trivialized, d/de chi(xi + e v) chi(xi)^-1 = dchi_xi v
 * (for SO(3) exp: the "left Jacobian" V(xi) of the robotics literature),
 * or left-trivialized, chi(xi)^-1 d/de chi(xi + e v) = dchi_{-xi} v.
 * Body velocity is xi = g^-1 gdot; the left-trivialized derivative of a
 * function f on G is (d/de) f(g exp(e e_k)), k = 1..dim.
 *
 * Matrices are row-major with a leading dimension ld >= their column count
 * (so a product writes its factors' blocks in place).  Ad is dim x dim;
 * ad_xi eta = [xi, eta]; the coadjoint actions are the transposes.
 * The matrix representation (dm_lie_matrix, hat) is msize x msize:
 * SO(3) 3, SE(3) 4 (homogeneous), SE(2) 3, SO(2) 2, R^n n+1
 * (homogeneous translations), T^n 2n (block diagonal), products block
 * diagonal.  dm_lie_act is the action on R^kdim (SO(3), SE(3): R^3; SO(2),
 * SE(2): R^2; R^n: translation of R^n; T^n: R^2n; products: concatenation).
 *
 * Numerics.  Every coefficient with a removable singularity (sin t/t,
 * (1 - cos t)/t^2, (t - sin t)/t^3, (1 - (t/2)cot(t/2))/t^2, ...) is
 * evaluated by its Taylor series in t^2 below a threshold where the direct
 * formula would cancel, so every function is accurate and smooth at 0.
 * SO(3) log is computed from atan2(|sin|, cos) and, for rotation angles
 * beyond pi/2, from the symmetric part of R, so it is accurate at and near
 * pi; at exactly pi it returns one of the two opposite axes (the one with
 * a positive largest component).  Products of rotations lose orthogonality
 * only by round-off (a random walk, ~1e-13 after 1e7 compositions);
 * dm_lie_normalize projects back (polar factor by SVD).
 *
 * Symbolic elements.  Every operation except normalization and checks
 * also exists on expression nodes (dm_lie_sym_*, below), so that a
 * Lagrangian written with group elements is traced into the expression
 * engine and differentiated exactly, including at the identity.
 *
 * Spheres.  S^n is the unit sphere in R^(n+1) (points: n+1 doubles);
 * dm_lie_sphere_* give its exponential, logarithm, distance and tangent
 * projection, and for S^2 the SO(3) action and the rotation carrying one
 * point to another.
 *
 * Errors.  Total operations return void.  Partial ones return DM_OK or
 * DM_EDOM and fill the dm_err (may be NULL) with a message naming the
 * operation and the input: the inverse Cayley map at rotation angle pi,
 * the sphere logarithm at the antipode, an element that is not in the
 * group (dm_lie_check).  NaN inputs propagate; they are not checked on the
 * hot paths.  Outputs may alias inputs unless stated otherwise.
 *
 * Ownership.  Constructors (dm_lie_rn ... dm_lie_product, dm_lie_group_copy)
 * return a group the caller releases with dm_lie_group_free (NULL is a
 * no-op); a product copies its factors.  Nothing else allocates: the
 * element functions write caller memory only.
 *
 * Thread safety.  A group is immutable after construction and may be used
 * from any number of threads at once; every function is reentrant.
 */
#ifndef DM_LIE_H
#define DM_LIE_H

#include <stddef.h>

#include "core/status.h"
#include "expr/expr.h"

typedef struct dm_lie_group dm_lie_group;
typedef struct dm_lie_sym_type dm_lie_sym_type;

enum dm_lie_kind {
  DM_LIE_RN = 0, DM_LIE_SO2, DM_LIE_TN, DM_LIE_SO3, DM_LIE_SE2, DM_LIE_SE3,
  DM_LIE_PRODUCT
};

/* Which trivialization of a chart derivative. */
enum dm_lie_side { DM_LIE_RIGHT = 0, DM_LIE_LEFT = 1 };

/* Largest algebra dimension, element size and matrix size of a group
 * (products included): bounds for callers' stack buffers. */
#define DM_LIE_DIM_MAX 64
#define DM_LIE_NQ_MAX 256
#define DM_LIE_FAC_MAX 16

/* The type object of a family: functions on elements of one group G of the
 * family (the descriptor carries the sizes).  Every family fills every
 * entry.  Matrix outputs take a leading dimension.  The chart derivatives
 * are right-trivialized; `inv` selects the inverse matrix. */
typedef struct dm_lie_type {
  const char *name;     /* "Rn", "SO2", "Tn", "SO3", "SE2", "SE3", "product" */
  int kind;             /* enum dm_lie_kind */
  void (*identity)(const dm_lie_group *G, double *g);
  void (*compose)(const dm_lie_group *G, const double *a, const double *b, double *ab);
  void (*inverse)(const dm_lie_group *G, const double *a, double *ai);
  void (*exp)(const dm_lie_group *G, const double *xi, double *g);
  void (*log)(const dm_lie_group *G, const double *g, double *xi);
  void (*Ad)(const dm_lie_group *G, const double *g, double *M, size_t ld);
  void (*ad)(const dm_lie_group *G, const double *xi, double *M, size_t ld);
  void (*bracket)(const dm_lie_group *G, const double *a, const double *b, double *c);
  void (*dexp)(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld);
  void (*cay)(const dm_lie_group *G, const double *xi, double *g);
  /* DM_EDOM (no message) where the inverse Cayley map is undefined */
  int (*icay)(const dm_lie_group *G, const double *g, double *xi);
  void (*dcay)(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld);
  void (*hat)(const dm_lie_group *G, const double *xi, double *A, size_t ld);
  void (*vee)(const dm_lie_group *G, const double *A, size_t ld, double *xi);
  void (*matrix)(const dm_lie_group *G, const double *g, double *M, size_t ld);
  /* DM_EDOM (no message) when the fixed entries of M are wrong */
  int (*from_matrix)(const dm_lie_group *G, const double *M, size_t ld, double *g);
  void (*act)(const dm_lie_group *G, const double *g, const double *x, double *y);
  void (*normalize)(const dm_lie_group *G, double *g);
  /* max |R^T R - I| entry over the rotation blocks (0 for vector storage);
   * *det_ok = 0 when a rotation block has det <= 0 */
  double (*defect)(const dm_lie_group *G, const double *g, int *det_ok);
  /* dg = d/de (g exp(e e_k)) (side LEFT) or d/de (exp(e e_k) g) (RIGHT),
   * in storage coordinates (nq) */
  void (*generator)(const dm_lie_group *G, const double *g, size_t k, int side, double *dg);
  const dm_lie_sym_type *sym;   /* the same operations on expressions */
} dm_lie_type;

/* The descriptor.  Read the fields; never write them. */
struct dm_lie_group {
  const dm_lie_type *type;
  int kind;             /* = type->kind */
  char name[64];        /* "SO3", "R2", "T3", "SE3xT3" */
  size_t nq;            /* doubles per element */
  size_t dim;           /* dimension of the algebra */
  size_t n;             /* R^n, T^n: n; else 0 */
  size_t msize;         /* size of the matrix representation */
  size_t kdim;          /* dimension of the space dm_lie_act acts on */
  int abelian;
  /* products: the factors (never products themselves: nested products are
   * flattened) and the offsets of factor i in elements, algebra vectors,
   * the matrix representation and the acted-on space; i = 0 .. nfac,
   * the last entry being the total */
  size_t nfac;
  dm_lie_group **fac;
  size_t *qoff, *xoff, *moff, *koff;
};

/* {==== construction ===================================================== */

/* Each returns a new group or NULL with DM_EINVAL (n out of 1..DM_LIE_DIM_MAX)
 * or DM_ENOMEM in e. */
dm_lie_group *dm_lie_rn(size_t n, dm_err *e);
dm_lie_group *dm_lie_so2(dm_err *e);
dm_lie_group *dm_lie_torus(size_t n, dm_err *e);
dm_lie_group *dm_lie_so3(dm_err *e);
dm_lie_group *dm_lie_se2(dm_err *e);
dm_lie_group *dm_lie_se3(dm_err *e);
/* The product of k >= 1 groups (copied; products among them are
 * flattened into their factors).  DM_EINVAL when k == 0, more than
 * DM_LIE_FAC_MAX factors or sizes beyond the DM_LIE_*_MAX bounds. */
dm_lie_group *dm_lie_product(size_t k, const dm_lie_group *const *fac, dm_err *e);
dm_lie_group *dm_lie_group_copy(const dm_lie_group *G, dm_err *e);
void dm_lie_group_free(dm_lie_group *G);
/* 1 when G and H are the same group (same family, sizes and factors). */
int dm_lie_group_equal(const dm_lie_group *G, const dm_lie_group *H);
/* The group named by a name as in G->name ("SO3", "R2", "T3", "SE3xT3"):
 * the inverse of the naming, for files that record a group by name.
 * NULL and DM_EINVAL naming the part not understood. */
dm_lie_group *dm_lie_group_parse(const char *name, dm_err *e);
/* A one-line description of g into buf (truncated like snprintf; returns
 * the full length): "rotation 1.5708 about (0, 0, 1) [0 -1 0; 1 0 0; 0 0 1]"
 * (SO(3): angle, axis and matrix), "rotation ... , translation (1, 2, 3)"
 * (SE(3)), "angle 0.5" (SO(2)), "angle 0.5, translation (1, 2)" (SE(2)),
 * "(1, 2, 3)" (R^n), "angles (0.5, 1)" (T^n), factors joined by " | ".
 * Numbers with 6 significant digits, C locale. */
int dm_lie_describe(const dm_lie_group *G, const double *g, char *buf, size_t size);

/* {==== elements (dispatch through G->type; see dm_lie_type) ============== */

void dm_lie_identity(const dm_lie_group *G, double *g);
void dm_lie_compose(const dm_lie_group *G, const double *a, const double *b, double *ab);
void dm_lie_inverse(const dm_lie_group *G, const double *a, double *ai);
/* a^-1 b (the relative element of the discrete mechanics, F_k = g_k^-1 g_k+1) */
void dm_lie_between(const dm_lie_group *G, const double *a, const double *b, double *d);
void dm_lie_exp(const dm_lie_group *G, const double *xi, double *g);
/* Principal logarithm: rotation angles in [0, pi], SO(2)/T^n angles in
 * (-pi, pi]. */
void dm_lie_log(const dm_lie_group *G, const double *g, double *xi);
/* dist(a, b) = |log(a^-1 b)| (Euclidean norm of the algebra coordinates);
 * conjugation invariant on SO(n) and the tori. */
double dm_lie_dist(const dm_lie_group *G, const double *a, const double *b);
void dm_lie_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld);
void dm_lie_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld);
void dm_lie_bracket(const dm_lie_group *G, const double *a, const double *b, double *c);
/* y = Ad_g x, y = Ad*_g mu := Ad_g^T mu (vectors of dim; y may alias). */
void dm_lie_Ad_apply(const dm_lie_group *G, const double *g, const double *x, double *y);
void dm_lie_Adstar_apply(const dm_lie_group *G, const double *g, const double *mu, double *y);
/* dexp / dexp^-1 of the exponential chart (dim x dim), trivialized on `side`. */
void dm_lie_dexp(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld);
void dm_lie_dexpinv(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld);
/* The Cayley map cay(A) = (I - A/2)^-1 (I + A/2) of the matrix
 * representation (defined on every algebra here), its inverse and
 * derivatives.  dm_lie_icay: DM_EDOM at the cut locus (a rotation by pi). */
void dm_lie_cay(const dm_lie_group *G, const double *xi, double *g);
int dm_lie_icay(const dm_lie_group *G, const double *g, double *xi, dm_err *e);
void dm_lie_dcay(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld);
void dm_lie_dcayinv(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld);
/* The algebra as matrices (msize x msize) and back (vee takes the part of A
 * in the algebra: for a rotation block its skew-symmetric part). */
void dm_lie_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld);
void dm_lie_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi);
/* g as a matrix (msize x msize) and back: from_matrix reads the group
 * coordinates (angles by atan2) and checks the fixed entries (homogeneous
 * last row, the 2x2 rotation pattern); DM_EDOM with a message otherwise.
 * Use dm_lie_check for the rotation blocks. */
void dm_lie_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld);
int dm_lie_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g,
                       dm_err *e);
/* y = g . x on R^kdim (y may alias x). */
void dm_lie_act(const dm_lie_group *G, const double *g, const double *x, double *y);
/* Project onto the group: every rotation block to the nearest rotation
 * (polar factor by SVD; det fixed to +1). */
void dm_lie_normalize(const dm_lie_group *G, double *g);
/* DM_OK when every value is finite and every rotation block R has
 * max |R^T R - I| <= tol and det R > 0; else DM_EDOM with a message
 * ("SO3 element: R^T R - I = 3.2e-05 (> tol 1e-10): not a rotation"). */
int dm_lie_check(const dm_lie_group *G, const double *g, double tol, dm_err *e);
/* The k-th generator at g in storage coordinates (see dm_lie_type). */
void dm_lie_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                      double *dg);
/* Trivialized gradient of a function f on G from its gradient in storage
 * coordinates: out_k = sum_a df/dg_a dg_a(k), dg from dm_lie_generator. */
void dm_lie_trivialize(const dm_lie_group *G, const double *g, const double *grad,
                       int side, double *out);

/* {==== symbolic elements ================================================
 * The same operations on expression nodes (expr.h): an element is an array
 * of G->nq nodes, an algebra element G->dim nodes, matrices row-major with
 * no leading dimension (dim x dim, msize x msize).  The results are the
 * numeric formulas as expressions, with the series branches as
 * select(t < threshold, series, closed form) so that their values and
 * every derivative are those of the numeric code; the logarithm takes the
 * branches of the numeric one (atan2, the symmetric part beyond pi/2) with
 * selects.  Normalization, checks and the matrix-to-element conversion
 * are numeric only.  Inputs may be constants (numbers fold).
 *
 * Each function returns DM_OK, or the context's error (DM_ENOMEM, ...) with
 * its message copied into e; the outputs are then unspecified.  Nodes
 * belong to the context (expr.h); the functions allocate nothing else.
 * Like the context, not thread safe. */

struct dm_lie_sym_type {
  void (*identity)(dm_expr_ctx *c, const dm_lie_group *G, dm_expr *g);
  void (*compose)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *a,
                  const dm_expr *b, dm_expr *ab);
  void (*inverse)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *a, dm_expr *ai);
  void (*exp)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *g);
  void (*log)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *xi);
  void (*Ad)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *M, size_t ld);
  void (*ad)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *M, size_t ld);
  void (*dexp)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, int inv,
               dm_expr *M, size_t ld);
  void (*cay)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *g);
  void (*icay)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *xi);
  void (*dcay)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, int inv,
               dm_expr *M, size_t ld);
  void (*hat)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *A, size_t ld);
  void (*vee)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *A, size_t ld, dm_expr *xi);
  void (*matrix)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *M,
                 size_t ld);
  void (*act)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, const dm_expr *x,
              dm_expr *y);
  void (*generator)(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, size_t k,
                    int side, dm_expr *dg);
};

int dm_lie_sym_identity(dm_expr_ctx *c, const dm_lie_group *G, dm_expr *g, dm_err *e);
int dm_lie_sym_compose(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *a,
                       const dm_expr *b, dm_expr *ab, dm_err *e);
int dm_lie_sym_inverse(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *a, dm_expr *ai,
                       dm_err *e);
int dm_lie_sym_exp(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *g,
                   dm_err *e);
int dm_lie_sym_log(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *xi,
                   dm_err *e);
int dm_lie_sym_Ad(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *M,
                  dm_err *e);
int dm_lie_sym_ad(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *M,
                  dm_err *e);
int dm_lie_sym_bracket(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *a,
                       const dm_expr *b, dm_expr *ab, dm_err *e);
/* y = M x for a dim x dim M (trans: M^T x) */
int dm_lie_sym_matvec(dm_expr_ctx *c, size_t n, const dm_expr *M, int trans,
                      const dm_expr *x, dm_expr *y, dm_err *e);
int dm_lie_sym_dexp(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, int side,
                    dm_expr *M, dm_err *e);
int dm_lie_sym_dexpinv(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, int side,
                       dm_expr *M, dm_err *e);
int dm_lie_sym_cay(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *g,
                   dm_err *e);
/* the closed form (infinite or NaN on the cut locus) */
int dm_lie_sym_icay(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *xi,
                    dm_err *e);
int dm_lie_sym_dcay(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, int side,
                    dm_expr *M, dm_err *e);
int dm_lie_sym_dcayinv(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, int side,
                       dm_expr *M, dm_err *e);
int dm_lie_sym_hat(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *xi, dm_expr *A,
                   dm_err *e);
int dm_lie_sym_vee(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *A, dm_expr *xi,
                   dm_err *e);
int dm_lie_sym_matrix(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, dm_expr *M,
                      dm_err *e);
int dm_lie_sym_act(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, const dm_expr *x,
                   dm_expr *y, dm_err *e);
int dm_lie_sym_generator(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g, size_t k,
                         int side, dm_expr *dg, dm_err *e);
/* out_k = sum_a grad_a dg_a(k): the trivialized gradient of a function
 * from its gradient in storage coordinates */
int dm_lie_sym_trivialize(dm_expr_ctx *c, const dm_lie_group *G, const dm_expr *g,
                          const dm_expr *grad, int side, dm_expr *out, dm_err *e);

/* }====================================================================== */

/* {==== the sphere S^n in R^(n+1) ========================================= */

/* p, q points (n+1 doubles, unit norm), v tangent vectors at p (v.p = 0).
 * exp_p(v) = cos|v| p + sin|v| v/|v|; log_p(q) the tangent vector of length
 * dist(p, q) pointing to q (DM_EDOM at q = -p, where it is undefined);
 * dist = atan2(|p x q|, p.q) computed without cancellation at any angle. */
void dm_lie_sphere_exp(size_t n, const double *p, const double *v, double *q);
int dm_lie_sphere_log(size_t n, const double *p, const double *q, double *v, dm_err *e);
double dm_lie_sphere_dist(size_t n, const double *p, const double *q);
/* v - (v.p) p */
void dm_lie_sphere_tangent(size_t n, const double *p, const double *v, double *w);
/* p / |p|; DM_EDOM for p = 0 or non-finite */
int dm_lie_sphere_normalize(size_t n, double *p, dm_err *e);
/* S^2 as SO(3)/SO(2): the projection p = R e3, and the rotation about
 * p0 x p1 carrying p0 to p1 (R = I for p1 = p0; DM_EDOM at p1 = -p0, where
 * the axis is undefined).  The action is dm_lie_act of SO(3). */
void dm_lie_sphere_project(const double *R, double *p);
int dm_lie_sphere_rotation(const double *p0, const double *p1, double *R, dm_err *e);

#endif
