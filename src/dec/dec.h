/* dec.h -- discrete exterior calculus on simplicial complexes
 * (doc/exterior-calculus.md).
 *
 * Three objects, each immutable once built:
 *
 *   dm_dec_complex  the topology: pure oriented simplicial complex of
 *                   dimension n <= DM_DEC_MAXDIM, its simplices of every
 *                   dimension, face tables and the exact integer exterior
 *                   derivatives d_k = boundary_{k+1}^T.
 *   dm_dec_geom     one metric on a complex: squared edge lengths (from
 *                   vertex coordinates in R^N, or given: the intrinsic
 *                   "local metric" mode), primal volumes, circumcentres,
 *                   signed circumcentric dual volumes and their pieces in
 *                   every top simplex.  Several geometries may share one
 *                   complex (a discrete map is two of them).
 *   dm_dec_meshdata a plain vertex/simplex table (generators, files).
 *
 * Conventions (doc/exterior-calculus.md §1): k-simplices for k < n are stored
 * with increasing vertex indices and numbered in lexicographic order; top
 * simplices keep the caller's order and the caller's vertex order, which is
 * their orientation (top_sign = parity relative to the sorted row).  Dual
 * cells are oriented so that orientation(s) ^ orientation(*s) is the
 * orientation of the top simplices; then the dual derivative on dual
 * j-cochains is (-1)^(n-j) boundary_{n-j} (= (-1)^(n-j) d_{n-j-1}^T),
 * *_k = diag(|*s|/|s|), ** = (-1)^(k(n-k)), delta_k = *_{k-1}^-1 d_{k-1}^T *_k
 * and Delta_k = d delta + delta d is positive semidefinite.
 *
 * Ownership: _alloc / _free pairs; _free(NULL) is a no-op.  A geometry keeps a
 * pointer to its complex, which must outlive it.  Matrices and vectors
 * returned through pointer arguments are new and owned by the caller
 * (dm_sparse_free / free).
 *
 * Errors: functions return DM_OK or a DM_E* status (or NULL) and fill the
 * dm_err (may be NULL) with a message naming the simplex (1-based vertex
 * lists) or the argument at fault.  Nothing prints; warnings are data
 * (dm_dec_geom fields nonpos, not_well_centered) for the caller to report.
 *
 * Threads: complexes and geometries are read-only after _alloc and may be
 * shared by any number of threads; every function here is reentrant.
 *
 * Using a triangle mesh (n = 2) from other modules: vertices are 0..nsimp[0]-1
 * with coordinates G->X (N per vertex); edge e is simp[1][2e] < simp[1][2e+1];
 * triangle t is top[3t..3t+2] in its oriented order.  The edges of t are
 * face[1][3t + j] for the local masks dm_dec_face_mask(2, 1, j) = {0,1},
 * {0,2}, {1,2} over the sorted row simp[2][3t..]; row t of d[1] lists them
 * with the induced signs (+1: the edge runs along t's orientation).  The
 * triangles of an edge are the column of d[1] (dm_sparse_transpose); an
 * edge with one triangle is a boundary edge (boundary[1][e]).  Lengths
 * squared: G->len2[e]; areas G->vol[2][t]; angles follow from len2 (the
 * cotangents are how geom.c gets the duals).  dm_dec_find(K, k, v) looks a
 * simplex up by its vertices.
 */
#ifndef DM_DEC_H
#define DM_DEC_H

#include "core/status.h"
#include "dec/sparse.h"

#define DM_DEC_MAXDIM 4

/* {==== raw meshes ========================================================== */

typedef struct dm_dec_meshdata {
  int n;          /* dimension of the top simplices */
  int N;          /* embedding dimension (coordinates per vertex) */
  int nv, ntop;
  double *X;      /* nv x N */
  int *T;         /* ntop x (n + 1), 0-based, orientation = vertex order */
} dm_dec_meshdata;

/* Allocate arrays for nv vertices and ntop simplices (X, T uninitialised). */
dm_dec_meshdata *dm_dec_meshdata_alloc(int n, int N, int nv, int ntop, dm_err *e);
void dm_dec_meshdata_free(dm_dec_meshdata *m);

/* Generators.  All produce consistently oriented meshes (counterclockwise in
 * the plane, outward normals on closed surfaces, positive volume for tets).
 *   grid:    [x0,x1] x [y0,y1], nx x ny squares, each square [a,b,d,c] split
 *            along its diagonal a-d (right triangles).
 *   disc:    radius r, nr rings of 6i vertices (1 + 3 nr (nr+1) vertices,
 *            6 nr^2 nearly equilateral triangles), made Delaunay by flips.
 *   annulus: radii r0 < r1, nr rings of m vertices, odd rings turned by half
 *            a step (m >= 3, nr >= 1).
 *   sphere:  radius r, icosahedron subdivided `level` times 1 -> 4 (10 4^L + 2
 *            vertices).
 *   torus:   radii R > r, m vertices around the big circle, n (even) around
 *            the tube, odd rows staggered by half a step; vertex (i, j) at
 *            u = 2 pi (i + (j mod 2)/2)/m, v = 2 pi j / n.
 *   box:     [0,a] x [0,b] x [0,c], nx x ny x nz cubes of 6 tetrahedra each
 *            (Kuhn split along the cube diagonal).
 *   path:    vertices x_0..x_np on the real line (np segments; x given). */
dm_dec_meshdata *dm_dec_gen_grid(int nx, int ny, double x0, double x1, double y0,
                                 double y1, dm_err *e);
dm_dec_meshdata *dm_dec_gen_disc(double r, int nr, dm_err *e);
dm_dec_meshdata *dm_dec_gen_annulus(double r0, double r1, int nr, int m, dm_err *e);
dm_dec_meshdata *dm_dec_gen_sphere(double r, int level, dm_err *e);
dm_dec_meshdata *dm_dec_gen_torus(double R, double r, int m, int n, dm_err *e);
dm_dec_meshdata *dm_dec_gen_box(int nx, int ny, int nz, double a, double b,
                                double c, dm_err *e);
dm_dec_meshdata *dm_dec_gen_path(int np, const double *x, dm_err *e);

/* Lawson edge flips until every interior edge of a planar triangle mesh is
 * locally Delaunay (opposite angles summing to at most pi, i.e. *_1 >= 0);
 * returns the number of flips (>= 0) or minus a status. */
int dm_dec_delaunay_flips(dm_dec_meshdata *m, dm_err *e);

/* One level of nested refinement: every triangle split 1 -> 4 at edge
 * midpoints (n = 2), every segment 1 -> 2 (n = 1).  When parent is not NULL
 * it receives, for every new vertex, the two vertices of its coarse edge
 * (old vertices: both entries equal the vertex itself), 2 ints per vertex. */
dm_dec_meshdata *dm_dec_refine(const dm_dec_meshdata *m, int **parent, dm_err *e);


/* }==== */

/* {==== the complex ========================================================== */

typedef struct dm_dec_complex {
  int n;                            /* dimension */
  int nsimp[DM_DEC_MAXDIM + 1];     /* number of k-simplices */
  int *simp[DM_DEC_MAXDIM + 1];     /* nsimp[k] x (k+1) vertex indices, rows
                                       increasing; simp[n]: rows sorted, table
                                       in input order */
  int *top;                         /* nsimp[n] x (n+1) in input vertex order */
  signed char *top_sign;            /* +1/-1: parity of top[] against simp[n] */
  int nface[DM_DEC_MAXDIM + 1];     /* C(n+1, k+1): k-faces of a top simplex */
  int *face[DM_DEC_MAXDIM + 1];     /* nsimp[n] x nface[k]: global index of the
                                       k-face of top t with local mask
                                       dm_dec_face_mask(n, k, j) (bits over the
                                       sorted row simp[n][t]) */
  dm_sparse *d[DM_DEC_MAXDIM];      /* d[k]: N_{k+1} x N_k, entries +-1 */
  unsigned char *boundary[DM_DEC_MAXDIM + 1]; /* 1 when the k-simplex lies in
                                       the boundary subcomplex */
  int manifold;                     /* every (n-1)-face has 1 or 2 cofaces */
  int oriented;                     /* the two cofaces of every interior
                                       (n-1)-face induce opposite signs */
} dm_dec_complex;

/* The complex of ntop top simplices T (ntop x (n+1), 0-based, vertex order =
 * orientation) on nv vertices.  Errors (DM_EINVAL, naming the simplex): an
 * index outside 0..nv-1, a repeated vertex, two top simplices with the same
 * vertex set, a vertex in no simplex (only pure complexes are supported),
 * n outside 1..DM_DEC_MAXDIM. */
dm_dec_complex *dm_dec_complex_alloc(int n, int nv, int ntop, const int *T,
                                     dm_err *e);
void dm_dec_complex_free(dm_dec_complex *K);

/* Local k-faces of an n-simplex: bit masks over its n+1 sorted vertices, in
 * lexicographic order of the faces; dm_dec_face_index inverts it. */
unsigned dm_dec_face_mask(int n, int k, int j);
int dm_dec_face_index(int n, unsigned mask);

/* Index of the k-simplex with the given (k+1) vertices (any order), or -1. */
int dm_dec_find(const dm_dec_complex *K, int k, const int *v);

/* The first defect among: an (n-1)-face with more than two cofaces
 * ("non-manifold"), two cofaces inducing the same orientation on a shared
 * face ("inconsistent orientation").  DM_OK when neither. */
int dm_dec_complex_check(const dm_dec_complex *K, dm_err *e);
/* The same as data: 0 (none), 1 (non-manifold: face f of the top simplices
 * a, b, ...), 2 (orientation: top simplices a and b share face f). */
int dm_dec_complex_defect(const dm_dec_complex *K, int *a, int *b, int *f);

/* Betti numbers b_0..b_n, exactly: ranks of the boundary matrices by
 * elimination modulo the prime 2^31 - 1 (equal to the rational ranks unless
 * that prime divides a torsion coefficient of the integral homology). */
int dm_dec_betti(const dm_dec_complex *K, int *betti, dm_err *e);

/* }==== */

/* {==== geometry ============================================================= */

typedef struct dm_dec_geom {
  const dm_dec_complex *K;          /* not owned */
  int N;                            /* coordinates per vertex (0: intrinsic) */
  double *X;                        /* nv x N copy, NULL when intrinsic */
  double *len2;                     /* squared edge lengths, nsimp[1] */
  double *vol[DM_DEC_MAXDIM + 1];   /* primal volumes, vol[0] = 1 */
  double *dual[DM_DEC_MAXDIM + 1];  /* signed dual volumes |*s| (|*top| = 1) */
  double *piece[DM_DEC_MAXDIM + 1]; /* nsimp[n] x nface[k]: signed |*s cap t| */
  double *cc[DM_DEC_MAXDIM + 1];    /* circumcentres nsimp[k] x N (NULL when
                                       intrinsic) */
  int nonpos[DM_DEC_MAXDIM + 1];    /* simplices with dual volume <= 0 */
  int not_well_centered;            /* simplices (k >= 1) whose circumcentre is
                                       not strictly inside */
} dm_dec_geom;

/* Geometry from vertex coordinates X (nv x N, N >= n). */
dm_dec_geom *dm_dec_geom_alloc(const dm_dec_complex *K, int N, const double *X,
                               dm_err *e);
/* Intrinsic geometry from squared edge lengths (indexed like simp[1]).
 * Checked: lengths positive, and every simplex of dimension >= 2 has a
 * positive squared volume (Cayley-Menger; triangle inequalities alone do
 * not guarantee a tetrahedron): DM_EDOM naming the simplex otherwise. */
dm_dec_geom *dm_dec_geom_alloc_intrinsic(const dm_dec_complex *K,
                                         const double *len2, dm_err *e);
void dm_dec_geom_free(dm_dec_geom *G);

/* Barycentric coordinates of the circumcentre of the k-simplex s (k+1
 * values, summing to 1). */
int dm_dec_circumcenter_bary(const dm_dec_geom *G, int k, int s, double *b,
                             dm_err *e);

/* }==== */

/* {==== operators ============================================================ */

/* Hodge star *_k as a vector (primal k -> dual n-k): |*s|/|s|.  With
 * inverse != 0: the star from dual (n-k) to primal k, (-1)^(k(n-k)) |s|/|*s|;
 * DM_ESINGULAR naming the first simplex with |*s| = 0. */
int dm_dec_star(const dm_dec_geom *G, int k, int inverse, double *out, dm_err *e);

/* d_k (N_{k+1} x N_k) and the dual derivative on dual j-cochains,
 * (-1)^(n-j) d_{n-j-1}^T (N_{n-j-1} x N_{n-j}). */
dm_sparse *dm_dec_d(const dm_dec_complex *K, int k, dm_err *e);
dm_sparse *dm_dec_dual_d(const dm_dec_complex *K, int j, dm_err *e);

/* The codifferential delta_k = *_{k-1}^-1 d_{k-1}^T *_k (N_{k-1} x N_k),
 * k >= 1. */
dm_sparse *dm_dec_codiff(const dm_dec_geom *G, int k, dm_err *e);

/* Laplace-de Rham Delta_k = d delta + delta d (N_k x N_k), and its symmetric
 * form S = *_k Delta_k (either pointer may be NULL). */
int dm_dec_laplacian(const dm_dec_geom *G, int k, dm_sparse **delta,
                     dm_sparse **sym, dm_err *e);

/* A user function of a point x (N coordinates) writing its values into
 * vals; returns 0, or nonzero to stop the caller with DM_ECALLBACK. */
typedef int (*dm_dec_fn)(const double *x, double *vals, void *ud);

/* The de Rham map: the k-cochain of integrals of a form over the primal
 * k-simplices (embedded geometries only).
 *   k = 0: f(x) at the vertices (1 value);
 *   k = 1: f returns the N components of a 1-form; integral along every
 *          edge (tail = lower vertex) by 3-point Gauss-Legendre, exact for
 *          polynomial coefficients of degree <= 5;
 *   k = n = N (2 or 3): f returns the density of f dx^1...dx^n; integral
 *          over every top simplex with its orientation, exact for
 *          polynomials of degree <= 5 (triangles) or 3 (tetrahedra).
 * Other degrees: DM_EUNSUP. */
int dm_dec_derham(const dm_dec_geom *G, int k, dm_dec_fn f, void *ud, double *out,
                  dm_err *e);

/* }==== */

/* {==== vector fields, wedge, contraction (doc/exterior-calculus.md §7-§9) == */

/* Flat of a dual vector field X (one R^N vector per top simplex, N_n x N)
 * to a primal 1-cochain: <X^flat, e> = sum_s (|*e cap s|/|*e|) X(s).e_vec
 * (edges with |*e| = 0: plain average over their top simplices). */
int dm_dec_flat(const dm_dec_geom *G, const double *X, double *alpha, dm_err *e);
/* Renormalised primal-primal sharp of a 1-cochain: a vector per vertex,
 * V(v) = sum_s (|*v cap s|/|*v|) sum_{w in s} alpha([v,w]) grad lambda_w^s
 * (N_0 x N).  Reproduces constant fields exactly. */
int dm_dec_sharp(const dm_dec_geom *G, const double *alpha, double *V, dm_err *e);

enum { DM_DEC_WEDGE_BARYCENTRIC = 0, DM_DEC_WEDGE_CIRCUMCENTRIC = 1 };
/* Primal-primal wedge of a k-cochain a and an l-cochain b into a
 * (k+l)-cochain out.  Barycentric weights 1/(p+1) (Leibniz rule exact,
 * natural under maps) or circumcentric ones |s cap *v|/|s| (the thesis's
 * Def 3.24; Leibniz only for closed factors). */
int dm_dec_wedge(const dm_dec_geom *G, int k, const double *a, int l, const double *b,
                 int weights, double *out, dm_err *e);

/* The thesis's dual-dual wedge (Def 3.25; a sketch there, no property
 * proved): dual k-cochain a (N_{n-k} values) ^ dual l-cochain b -> dual
 * (k+l)-cochain (N_{n-k-l} values), combinatorial (no metric).  Only
 * anti-commutativity is tested; the Lua surface hides it behind a flag. */
int dm_dec_wedge_dual(const dm_dec_complex *K, int k, const double *a, int l, const double *b,
                      double *out, dm_err *e);

/* Algebraic contraction of a dual k-cochain beta (N_{n-k} values, k >= 1)
 * with a dual vector field X: (-1)^(k(n-k)) *((*beta) ^ X^flat), a dual
 * (k-1)-cochain (N_{n-k+1} values); Lie derivative by Cartan's formula
 * L_X = i_X D + D i_X (dual k-cochain to dual k-cochain). */
int dm_dec_contract(const dm_dec_geom *G, int k, const double *beta, const double *X,
                    int weights, double *out, dm_err *e);
int dm_dec_lie(const dm_dec_geom *G, int k, const double *beta, const double *X, int weights,
               double *out, dm_err *e);

/* The cone operators of a collapsible complex: p[k] (N_k x N_{k+1}, k =
 * 0..n-1, integer entries), row tau holding the chain p(tau), with
 * p d + d p = I on k-chains (k >= 1) and d p(v) = v - apex.  Read as a
 * matrix on cochains, p[k] is the homotopy H: C^{k+1} -> C^k, and
 * p[k] d[k] + d[k-1] p[k-1] = I (k >= 1), p[0] d[0] f = f - f(apex),
 * d[n-1] p[n-1] = I.  DM_EFAILED
 * naming what is left when greedy collapses do not reach a point (not
 * contractible, or a non-collapsible order such as the dunce hat). */
int dm_dec_homotopy(const dm_dec_complex *K, dm_sparse **p, int *apex, dm_err *e);

/* }==== */

/* {==== maps and nested meshes (doc/exterior-calculus.md §11, §12) ========= */

/* Push-forward of a dual vector field X (N_n x N1) from geometry G1 to G2
 * of the same complex: J_s X(s), J_s = E2 (E1^T E1)^-1 E1^T the Jacobian of
 * the affine map of top simplex s.  Pull-back: swap G1 and G2.  Cochains
 * need no transfer (same simplices: f^* d = d f^*). */
int dm_dec_pushforward(const dm_dec_geom *G1, const dm_dec_geom *G2, const double *X, double *out,
                       dm_err *e);

/* For Kf from dm_dec_refine of Kc's mesh (parent as returned there):
 * restriction of fine k-cochains to coarse ones (k = 0, 1 or n), sums over
 * pieces, commuting with d; linear prolongation of 0-cochains (nf x nc). */
dm_sparse *dm_dec_restriction(const dm_dec_complex *Kc, const dm_dec_complex *Kf, const int *parent,
                              int k, dm_err *e);
dm_sparse *dm_dec_prolongation(int nc, int nf, const int *parent, dm_err *e);

/* Geometric multigrid for S u = b, S symmetric positive definite on the
 * finest level, levels linked by prolongations P[l] (level l+1 from level
 * l, l = 0..nlev-2), coarse operators P^T S P, fixed (Dirichlet) unknowns
 * of the finest level held at zero (the rows of b there are ignored).
 * V(nu, nu) cycles with symmetric Gauss-Seidel, CHOLMOD on level 0. */
typedef struct dm_dec_mg dm_dec_mg;
dm_dec_mg *dm_dec_mg_alloc(int nlev, dm_sparse *const *P, const dm_sparse *S,
                           const unsigned char *fixed, int nu, dm_err *e);
/* One V-cycle: u <- u + V(b - S u) on the free unknowns. */
int dm_dec_mg_vcycle(dm_dec_mg *M, const double *b, double *u, dm_err *e);
/* Cycles until the residual's 2-norm is below tol times that of b (at
 * most maxit); *iters receives the count.  DM_ENOCONV otherwise. */
int dm_dec_mg_solve(dm_dec_mg *M, const double *b, double *u, double tol, int maxit, int *iters,
                    dm_err *e);
void dm_dec_mg_free(dm_dec_mg *M);

/* }==== */

/* {==== solving operators of the form diag(w)^-1 S ============================ */

/* A factored Dirichlet problem: S symmetric (n x n), `fixed` flags (may be
 * NULL) the unknowns prescribed by boundary values.  CHOLMOD factors S on the
 * free unknowns once; DM_ESINGULAR (naming the pivot) when that block is not
 * positive definite. */
typedef struct dm_dec_solver dm_dec_solver;
dm_dec_solver *dm_dec_solver_alloc(const dm_sparse *S, const unsigned char *fixed,
                                   dm_err *e);
/* Find u with u = g on fixed unknowns and (diag(w)^-1 S u) = f on the free
 * ones (w == NULL: w = 1; g == NULL: g = 0). */
int dm_dec_solver_solve(dm_dec_solver *F, const double *w, const double *f,
                        const double *g, double *u, dm_err *e);
void dm_dec_solver_free(dm_dec_solver *F);

/* }==== */

/* {==== mesh files (doc/exterior-calculus.md §13) ========================== */

/* Read a mesh file: OFF (triangles), Wavefront OBJ (v and triangular f
 * lines), Gmsh .msh ASCII 2.2 or 4.1 (points, lines, triangles, tetrahedra;
 * the highest dimension present gives the top simplices).  Coordinates
 * with every z = 0 make a planar mesh (N = 2).  lines (may be NULL)
 * receives the line number of every top simplex (free()).  Errors name
 * the file, the line and the defect ("mesh.off:12: vertex 57 does not
 * exist (vertices are numbered from 0)"). */
int dm_dec_read(const char *path, dm_dec_meshdata **out, int **lines, dm_err *e);
/* Write OFF, OBJ (triangle meshes) or .msh 2.2 by the extension of path,
 * through a temporary file renamed over path. */
int dm_dec_write(const char *path, const dm_dec_complex *K, const dm_dec_geom *G, dm_err *e);
/* Read, build the complex and its geometry; a non-manifold face or an
 * inconsistently oriented pair is an error naming the lines of the
 * simplices. */
int dm_dec_load(const char *path, dm_dec_complex **K, dm_dec_geom **G, dm_err *e);

/* }==== */

#endif
