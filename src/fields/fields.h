/* fields.h -- variational integrators for fields (doc/beyond-fixed-steps.md §4-7):
 * the pseudospectral Schrodinger integrator (schrodinger.c), the 1-D
 * multiscale finite element method exact at the nodes (msfem.c), and the
 * multisymplectic integrators of the nonlinear wave equation on space-time
 * grids (msym.c), on moving r-adaptive nodes (radapt.c) and on DEC meshes in
 * space (msym_dec.c).
 *
 * Ownership.  Every _alloc returns a new object in *out that the caller
 * releases with the matching _free (NULL is a no-op); all workspaces are
 * allocated there, steps never allocate.  Arrays passed in are copied or
 * only read during the call unless said otherwise.
 * Errors.  DM_OK or a DM_E* status with a message in the dm_err (may be
 * NULL): DM_EINVAL for bad sizes and values (the message names them),
 * DM_ENOMEM, DM_ESINGULAR (a singular step matrix), DM_ENOCONV (Newton),
 * DM_EINTR (Ctrl-C: runs stop and keep what they computed), DM_EDIVERGED.
 * Thread safety.  Objects are used by one thread at a time; distinct
 * objects may run in parallel (FFT plans are made under a lock).
 * Complex arrays are `double _Complex` (the C99 keyword): this header does
 * not include <complex.h>, whose macro I would clash with the integrators'
 * parameter names.
 */
#ifndef DM_FIELDS_H
#define DM_FIELDS_H

#include <stddef.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "core/status.h"
#include "core/system.h"
#include "core/trajectory.h"
#include "dec/dec.h"

/* {==== the pseudospectral Schrodinger integrator ======================== */

/* i hbar psi_t = -(hbar^2/2m) psi_xx + V(x) psi on the periodic domain
 * [0, 2 pi), psi = sum_{k=-K..K} c_k e^{ikx} (N = 2K + 1 modes).  The
 * Galerkin Hamiltonian H_kk' = (hbar^2 k^2/2m) delta_kk' + Vhat_{k-k'},
 * Vhat_m = (1/2pi) int V e^{-imx} dx from M samples of V on x_j = 2 pi j/M
 * by FFTW (M > 4K).  Coefficient vectors are arrays of N double _Complex,
 * index j <-> wavenumber k = j - K. */
typedef struct dm_schrod dm_schrod;

/* V: M samples (NULL: V = 0, M ignored). */
int dm_schrod_alloc(size_t K, double hbar, double mass, const double *V, size_t M,
                    dm_schrod **out, dm_err *e);
void dm_schrod_free(dm_schrod *S);
size_t dm_schrod_modes(const dm_schrod *S);              /* N */
size_t dm_schrod_K(const dm_schrod *S);
double dm_schrod_hbar(const dm_schrod *S);
double dm_schrod_mass(const dm_schrod *S);
/* The Galerkin Hamiltonian (N x N, Hermitian; borrowed). */
const gsl_matrix_complex *dm_schrod_hamiltonian(const dm_schrod *S);
/* Its eigenvalues (N, ascending) and, when evec != NULL, the eigenvectors
 * as its columns (N x N), by gsl_eigen_hermv. */
int dm_schrod_eigen(const dm_schrod *S, gsl_vector *eval, gsl_matrix_complex *evec, dm_err *e);

/* Coefficients of the samples psi(x_j), x_j = 2 pi j/M (M > 2K), by FFT:
 * c_k = (1/M) sum_j psi_j e^{-ikx_j}; and back: psi_j = sum_k c_k e^{ikx_j}. */
int dm_schrod_analyse(const dm_schrod *S, const double _Complex *psi, size_t M,
                      double _Complex *c, dm_err *e);
int dm_schrod_synthesise(const dm_schrod *S, const double _Complex *c, size_t M,
                         double _Complex *psi, dm_err *e);

/* Diagnostics of a coefficient vector: the norm int |psi|^2 dx = 2 pi
 * sum |c_k|^2, the energy <H> = c^H H c / c^H c, and the expectations
 * <x> over [0, 2 pi) and <p> = hbar <k> (exact in the coefficients). */
typedef struct dm_schrod_diag {
  double norm, energy, x, p;
} dm_schrod_diag;
void dm_schrod_diagnose(const dm_schrod *S, const double _Complex *c, dm_schrod_diag *d);

/* Time steppers.  Milne-Simpson (the pseudospectral variational integrator
 * with piecewise-linear c(t) and exact integration in time):
 *   i hbar (c^{l+1} - c^{l-1})/(2 dt) = H (c^{l-1} + 4 c^l + c^{l+1})/6,
 * two-step, order 4, stable iff dt max|E|/hbar <= sqrt 3; Crank-Nicolson
 * (the midpoint rule in time): (I + i dt H/2hbar) c^{l+1} = (I - i dt
 * H/2hbar) c^l, order 2, unconditionally stable, conserves sum |c_k|^2;
 * exact: e^{-iH dt/hbar} from the eigenpairs.  The step matrix is factored
 * once (gsl_linalg_complex_LU_decomp). */
enum dm_schrod_method { DM_SCHROD_MILNE, DM_SCHROD_CN, DM_SCHROD_EXACT };
typedef struct dm_schrod_stepper dm_schrod_stepper;

int dm_schrod_stepper_alloc(const dm_schrod *S, int method, double dt,
                            dm_schrod_stepper **out, dm_err *e);
void dm_schrod_stepper_free(dm_schrod_stepper *P);
/* One step: Milne-Simpson c_next from (c_prev, c_cur); the one-step
 * methods ignore c_prev (may be NULL).  Outputs may not alias inputs. */
int dm_schrod_step(dm_schrod_stepper *P, const double _Complex *c_prev,
                   const double _Complex *c_cur, double _Complex *c_next, dm_err *e);

/* A run of nsteps steps from c (in: c^0; out: the last state) recording t,
 * norm, energy, x, p every `every` steps and at the end into tr (from
 * dm_schrod_traj_alloc, empty).  Milne-Simpson starts with c^1 from one
 * step of `start` (DM_SCHROD_EXACT or DM_SCHROD_CN).  Stops on Ctrl-C
 * (DM_EINTR) or a non-finite state (DM_EDIVERGED), keeping the samples. */
dm_traj *dm_schrod_traj_alloc(dm_err *e);
int dm_schrod_run(dm_schrod_stepper *P, int start, double t0, double _Complex *c, long nsteps,
                  long every, dm_traj *tr, long *done, dm_err *e);

/* }====================================================================== */

/* {==== the 1-D multiscale finite element method ======================== */

/* A real function of one variable for the solvers: 0 on success, > 0
 * outside its domain, < 0 on failure (the caller's message then says
 * which function failed and where). */
typedef int (*dm_fn1)(void *data, double x, double *y);

/* (a(x/eps) u')' = f(x) on (0, 1), u(0) = u(1) = 0, on N equal elements.
 * Multiscale (DM_MSFEM_MULTISCALE): the shape functions solve the
 * homogeneous cell problem, (Phi(x) - Phi(x_{i-1}))/D_i with
 * Phi(x) = int_0^x ds/a(s/eps) (from Phi when given, else by adaptive
 * quadrature of 1/a), D_i = Phi(x_i) - Phi(x_{i-1}); the tridiagonal
 * stiffness is exact and the nodal values are u(x_i) up to the quadrature
 * of the load (GSL QAG, relative tolerance tol).  Linear
 * (DM_MSFEM_LINEAR): hat functions, a integrated exactly on each element.
 * N >= 3. */
enum { DM_MSFEM_MULTISCALE, DM_MSFEM_LINEAR };
typedef struct dm_msfem_problem {
  dm_fn1 a, f, Phi;          /* a(y) > 0, f(x); Phi(x) (may be NULL) */
  void *adata, *fdata, *phidata;
  double eps;                /* > 0 */
  double tol;                /* quadrature tolerance (0: 1e-13) */
} dm_msfem_problem;

/* x, U: N + 1 values (the nodes, the nodal values, U[0] = U[N] = 0). */
int dm_msfem1d(const dm_msfem_problem *P, size_t N, int method, double *x, double *U,
               dm_err *e);

/* }====================================================================== */

/* {==== multisymplectic integrators of the nonlinear wave equation ======= */

/* The Lagrangian density l = u_t^2/2 - c^2 u_x^2/2 - V(u) (sine-Gordon:
 * V = 1 - cos u; V = 0: the wave equation).  eval fills V, V', V'' at u
 * (any pointer may be NULL); returns 0, > 0 outside its domain, < 0 on
 * failure.  A potential with eval == NULL is V = 0. */
typedef struct dm_potential {
  int (*eval)(void *data, double u, double *V, double *dV, double *d2V);
  void *data;
} dm_potential;

/* A potential whose V(u) is the Lagrangian of a one-coordinate system at
 * (u, 0): V' = Lq, V'' = Lqq (an expression compiled by src/expr).  ps
 * holds the system (borrowed) and a work buffer of its work_size bytes,
 * both the caller's; pot->data points to ps.  Not for two threads at once. */
typedef struct dm_potential_system {
  const struct dm_system *field;
  void *work;
} dm_potential_system;
void dm_potential_from_system(dm_potential *pot, dm_potential_system *ps);

/* {---- space-time grids: bilinear elements, one-point rule (msym.c) ----
 * Nodes x_i = x0 + i dx, dx = length/N: periodic (N nodes) or with both
 * ends held at their initial values (N + 1 nodes).  Per cell
 * L_d = dx dt l(u_t, u_x, ubar) with the cell-centre differences and mean
 * of the four corners; the step is the one-step map (u^j, p^j) ->
 * (u^{j+1}, p^{j+1}) of the slab's discrete Lagrangian, p^j_i the sum of
 * the slot derivatives of the two cells of a slab at node i (discrete
 * Legendre transforms): Newton with the (cyclic) symmetric tridiagonal
 * Jacobian. */
typedef struct dm_msym dm_msym;

int dm_msym_alloc(size_t N, double length, int periodic, double c, double dt,
                  const dm_potential *V, dm_msym **out, dm_err *e);
void dm_msym_free(dm_msym *M);
size_t dm_msym_nodes(const dm_msym *M);
double dm_msym_dx(const dm_msym *M);
double dm_msym_dt(const dm_msym *M);
/* The momentum of a velocity field at the start: p = dx v (held nodes 0). */
void dm_msym_momentum(const dm_msym *M, const double *v, double *p);
/* One step (outputs may alias inputs). */
int dm_msym_step(dm_msym *M, const double *u0, const double *p0, double *u1, double *p1,
                 dm_err *e);
/* The derivative of the step at (u0, p0) -> (u1, p1) (the step's solution)
 * applied to (du0, dp0). */
int dm_msym_tangent(dm_msym *M, const double *u0, const double *u1, const double *du0,
                    const double *dp0, double *du1, double *dp1, dm_err *e);
/* The energy sum_i [p_i^2/(2 dx) + dx c^2 ((u_{i+1} - u_i)/dx)^2/2 + dx V(u_i)]. */
double dm_msym_energy(const dm_msym *M, const double *u, const double *p);
/* The discrete multisymplectic form formula over n steps from (u, p) with
 * the first variations (du, dp), (dv, dq): for each cell, the sum over its
 * four corners of the 2-forms d(D_corner L_d du_corner)(V, W) (an identity:
 * the Hessian of L_d is symmetric); for each interior node of each level,
 * the sum of its corner forms over the four cells around it (zero exactly
 * when V and W solve the linearised scheme); the symplectic form
 * sum_i (du_i dq_i - dv_i dp_i) of every level against the first.  Maxima
 * relative to the largest corner form into res[0..3) (cell, node, level). */
int dm_msym_form_check(dm_msym *M, const double *u, const double *p, const double *du,
                       const double *dp, const double *dv, const double *dq, long nsteps,
                       double *res, dm_err *e);
/* The plane-wave dispersion relation of the scheme (V = 0): the omega with
 * tan(omega dt/2)/dt = c tan(k dx/2)/dx. */
double dm_msym_dispersion(const dm_msym *M, double k);

/* {---- moving nodes, r-adaptive (radapt.c) ----
 * Ends held at x0 and x0 + length, N cells, the interior nodes X_i move.
 * A space-time cell with corners (X_k^j, X_{k+1}^j, X_k^{j+1}, X_{k+1}^{j+1})
 * has L_d = hb dt l(u_t, u_x, ubar), hb its mean width, u_x = u_xi/hb,
 * u_t the time derivative at fixed x, (u_T - u_B - (X_T - X_B) u_x)/dt
 * along a vertical edge: its square sampled at the cell centre
 * (DM_RADAPT_CENTRE: the mean of the two edges; on a still uniform mesh
 * msym.c's cell) or averaged over the two edges (DM_RADAPT_EDGES: lumped
 * mass; immune to the odd-even node oscillation the centre rule shows on
 * steep fronts at small dt).  The field's discrete
 * Euler-Lagrange equations treat the mesh as a given (time-dependent)
 * control; the mesh of each new level solves the arc-length
 * equidistribution sqrt(h_k^2 + alpha du_k^2) equal for all cells, i.e.
 * h_k rho_k = const with rho = sqrt(1 + alpha u_x^2).  Both by Newton on the
 * interleaved unknowns (u_i, X_i), banded LU of GSL (3 + 3 diagonals). */
typedef struct dm_radapt dm_radapt;
enum { DM_RADAPT_CENTRE, DM_RADAPT_EDGES };

/* alpha >= 0 (0: the mesh stays uniform to round-off); rule one of the
 * two above. */
int dm_radapt_alloc(size_t N, double x0, double length, double c, double dt, double alpha,
                    int rule, const dm_potential *V, dm_radapt **out, dm_err *e);
void dm_radapt_free(dm_radapt *R);
size_t dm_radapt_nodes(const dm_radapt *R);            /* N + 1 */
double dm_radapt_dt(const dm_radapt *R);
double dm_radapt_alpha(const dm_radapt *R);
/* The initial mesh X (N + 1) equidistributed for the field u0 (de Boor's
 * iteration on the piecewise-linear interpolant), u = u0(X). */
int dm_radapt_init(dm_radapt *R, dm_fn1 u0, void *data, double *X, double *u, dm_err *e);
/* p_i = (X_{i+1} - X_{i-1})/2 v_i at the interior nodes, 0 at the ends. */
void dm_radapt_momentum(const dm_radapt *R, const double *X, const double *v, double *p);
/* One step (X, u, p) -> (X1, u1, p1) (outputs may alias inputs);
 * DM_EDIVERGED if nodes crossed. */
int dm_radapt_step(dm_radapt *R, const double *X0, const double *u0, const double *p0,
                   double *X1, double *u1, double *p1, dm_err *e);
/* max_i |l_i - l_{i-1}| / mean l, l_k the arc length of cell k. */
double dm_radapt_residual(const dm_radapt *R, const double *X, const double *u);
/* sum p_i^2/(2 m_i) + m_i V(u_i) + sum_k h_k c^2 ((u_{k+1} - u_k)/h_k)^2/2,
 * m_i = (X_{i+1} - X_{i-1})/2 (msym.c's energy on a uniform mesh). */
double dm_radapt_energy(const dm_radapt *R, const double *X, const double *u, const double *p);

/* {---- DEC meshes in space (msym_dec.c) ----
 * u a primal 0-cochain on a mesh of any dimension (1-D paths, triangle
 * meshes, ...), the semi-discrete Lagrangian
 * l(u, v) = v^T *0 v/2 - c^2 u^T S u/2 - sum_v *0_v V(u_v), S = d0^T *1 d0,
 * integrated by the midpoint rule in time over each space-time prism:
 * the step (u^j, p^j) -> (u^{j+1}, p^{j+1}) solves
 * *0 (u1 - u0)/dt + (dt/2)(c^2 S ubar + *0 V'(ubar)) = p0 by simplified
 * Newton with the constant SPD matrix *0/dt + (dt/4) c^2 S (CHOLMOD),
 * p1 = *0 (u1 - u0)/dt - (dt/2)(c^2 S ubar + *0 V'(ubar)).  The mesh is
 * borrowed; its boundary (if any) carries the natural (Neumann) condition. */
typedef struct dm_msym_dec dm_msym_dec;

int dm_msym_dec_alloc(const dm_dec_geom *G, double c, double dt, const dm_potential *V,
                      dm_msym_dec **out, dm_err *e);
void dm_msym_dec_free(dm_msym_dec *M);
size_t dm_msym_dec_nodes(const dm_msym_dec *M);
void dm_msym_dec_momentum(const dm_msym_dec *M, const double *v, double *p);
/* One step (outputs may alias inputs). */
int dm_msym_dec_step(dm_msym_dec *M, const double *u0, const double *p0, double *u1,
                     double *p1, dm_err *e);
/* The energy p^T *0^{-1} p/2 + c^2 u^T S u/2 + sum *0 V(u). */
double dm_msym_dec_energy(const dm_msym_dec *M, const double *u, const double *p);
/* The step's Jacobian applied to (du0, dp0) at (u0 -> u1). */
int dm_msym_dec_tangent(dm_msym_dec *M, const double *u0, const double *u1, const double *du0,
                        const double *dp0, double *du1, double *dp1, dm_err *e);

/* }====================================================================== */

#endif
