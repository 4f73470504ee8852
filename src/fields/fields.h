/* fields.h -- variational integrators for fields (doc/galerkin.md §4-6):
 * the pseudospectral Schrodinger integrator (schrodinger.c) and the 1-D
 * multiscale finite element method exact at the nodes (msfem.c).
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
#include "core/trajectory.h"

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

#endif
