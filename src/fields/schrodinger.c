/* schrodinger.c -- the pseudospectral variational integrator for the
 * Schrodinger equation (doc/beyond-fixed-steps.md §6): the Galerkin Hamiltonian from
 * an FFT of V (FFTW), its eigenpairs (GSL), Milne-Simpson, Crank-Nicolson
 * and exact steps with one LU factorisation (GSL), runs with norm, energy,
 * <x>, <p>.  See fields.h. */
#include <config.h>
#include "fields/fields.h"
#include "core/interrupt.h"
#include "core/numfmt.h"

#include <complex.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <fftw3.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_permutation.h>

/* FFTW's planner is not thread-safe: plans are made under this lock. */
static pthread_mutex_t plan_lock = PTHREAD_MUTEX_INITIALIZER;

struct dm_schrod {
  size_t K, N;
  double hbar, mass;
  gsl_matrix_complex *H;
};

/* H entry (i, j) as a double complex (gsl_complex has the same layout). */
static inline double complex *hat(const gsl_matrix_complex *A, size_t i, size_t j)
{
  return (double complex *)(A->data + 2 * (i * A->tda + j));
}

/* out = FFT of the n values in (sign: FFTW_FORWARD / FFTW_BACKWARD). */
static int fft(const double complex *in, double complex *out, size_t n, int sign, dm_err *e)
{
  fftw_complex *a = fftw_malloc(n * sizeof *a), *b = fftw_malloc(n * sizeof *b);
  fftw_plan p = NULL;
  if (a != NULL && b != NULL) {
    pthread_mutex_lock(&plan_lock);
    p = fftw_plan_dft_1d((int)n, a, b, sign, FFTW_ESTIMATE);
    pthread_mutex_unlock(&plan_lock);
  }
  if (p == NULL) {
    fftw_free(a);
    fftw_free(b);
    return dm_err_set(e, DM_ENOMEM, "FFT of %zu points: out of memory", n);
  }
  memcpy(a, in, n * sizeof *a);
  fftw_execute(p);
  memcpy(out, b, n * sizeof *b);
  pthread_mutex_lock(&plan_lock);
  fftw_destroy_plan(p);
  pthread_mutex_unlock(&plan_lock);
  fftw_free(a);
  fftw_free(b);
  return DM_OK;
}

int dm_schrod_alloc(size_t K, double hbar, double mass, const double *V, size_t M,
                    dm_schrod **out, dm_err *e)
{
  dm_schrod *S;
  double complex *vs = NULL, *vh = NULL;
  size_t N = 2 * K + 1, i, j;
  int st;
  *out = NULL;
  if (K > 4096)
    return dm_err_set(e, DM_EINVAL, "schrodinger: K = %zu modes each way is more than 4096", K);
  if (!(hbar > 0) || !isfinite(hbar) || !(mass > 0) || !isfinite(mass))
    return dm_err_set(e, DM_EINVAL, "schrodinger: hbar and m must be finite and > 0");
  if (V != NULL) {
    if (M <= 4 * K || M > (1u << 24))
      return dm_err_set(e, DM_EINVAL, "schrodinger: the potential needs M > 4K = %zu samples "
                        "(and at most 2^24), got %zu", 4 * K, M);
    for (i = 0; i < M; i++)
      if (!isfinite(V[i]))
        return dm_err_set(e, DM_EINVAL, "schrodinger: V is not finite at x = 2 pi %zu/%zu", i, M);
  }
  if ((S = calloc(1, sizeof *S)) == NULL || (S->H = gsl_matrix_complex_calloc(N, N)) == NULL) {
    free(S);
    return dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
  }
  S->K = K;
  S->N = N;
  S->hbar = hbar;
  S->mass = mass;
  if (V != NULL) {
    vs = malloc(M * sizeof *vs);
    vh = malloc(M * sizeof *vh);
    if (vs == NULL || vh == NULL) {
      st = dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
      goto fail;
    }
    for (i = 0; i < M; i++)
      vs[i] = V[i];
    if ((st = fft(vs, vh, M, FFTW_FORWARD, e)) != DM_OK)
      goto fail;
    /* H_jl += Vhat_{k_j - k_l}, Vhat_m = vh[m mod M]/M */
    for (i = 0; i < N; i++)
      for (j = 0; j < N; j++) {
        long m = (long)i - (long)j;
        *hat(S->H, i, j) = vh[m >= 0 ? (size_t)m : M - (size_t)(-m)] / (double)M;
      }
    /* exactly Hermitian (V real) */
    for (i = 0; i < N; i++) {
      *hat(S->H, i, i) = creal(*hat(S->H, i, i));
      for (j = 0; j < i; j++)
        *hat(S->H, i, j) = conj(*hat(S->H, j, i));
    }
  }
  for (i = 0; i < N; i++) {
    double k = (double)i - (double)K;
    *hat(S->H, i, i) += hbar * hbar * k * k / (2.0 * mass);
  }
  free(vs);
  free(vh);
  *out = S;
  return DM_OK;
fail:
  free(vs);
  free(vh);
  dm_schrod_free(S);
  return st;
}

void dm_schrod_free(dm_schrod *S)
{
  if (S == NULL)
    return;
  gsl_matrix_complex_free(S->H);
  free(S);
}

size_t dm_schrod_modes(const dm_schrod *S) { return S->N; }
size_t dm_schrod_K(const dm_schrod *S) { return S->K; }
double dm_schrod_hbar(const dm_schrod *S) { return S->hbar; }
double dm_schrod_mass(const dm_schrod *S) { return S->mass; }
const gsl_matrix_complex *dm_schrod_hamiltonian(const dm_schrod *S) { return S->H; }

int dm_schrod_eigen(const dm_schrod *S, gsl_vector *eval, gsl_matrix_complex *evec, dm_err *e)
{
  size_t N = S->N;
  gsl_matrix_complex *A = gsl_matrix_complex_alloc(N, N), *Z = NULL;
  gsl_eigen_hermv_workspace *w = NULL;
  int st = DM_OK;
  if (eval->size != N || (evec != NULL && (evec->size1 != N || evec->size2 != N))) {
    gsl_matrix_complex_free(A);
    return dm_err_set(e, DM_EINVAL, "schrodinger: eigenpairs need room for %zu modes", N);
  }
  if (A == NULL || (Z = gsl_matrix_complex_alloc(N, N)) == NULL
      || (w = gsl_eigen_hermv_alloc(N)) == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
    goto done;
  }
  gsl_matrix_complex_memcpy(A, S->H);
  if (gsl_eigen_hermv(A, eval, Z, w) != GSL_SUCCESS) {
    st = dm_err_set(e, DM_ENOCONV, "schrodinger: the Hermitian eigensolver failed");
    goto done;
  }
  gsl_eigen_hermv_sort(eval, Z, GSL_EIGEN_SORT_VAL_ASC);
  if (evec != NULL)
    gsl_matrix_complex_memcpy(evec, Z);
done:
  gsl_eigen_hermv_free(w);
  gsl_matrix_complex_free(Z);
  gsl_matrix_complex_free(A);
  return st;
}

int dm_schrod_analyse(const dm_schrod *S, const double complex *psi, size_t M,
                      double complex *c, dm_err *e)
{
  double complex *f;
  size_t j;
  long K = (long)S->K;
  int st;
  if (M <= 2 * S->K)
    return dm_err_set(e, DM_EINVAL, "schrodinger: %zu samples cannot resolve %zu modes (need "
                      "more than 2K = %zu)", M, S->N, 2 * S->K);
  if ((f = malloc(M * sizeof *f)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
  if ((st = fft(psi, f, M, FFTW_FORWARD, e)) == DM_OK)
    for (j = 0; j < S->N; j++) {
      long k = (long)j - K;
      c[j] = f[k >= 0 ? (size_t)k : M - (size_t)(-k)] / (double)M;
    }
  free(f);
  return st;
}

int dm_schrod_synthesise(const dm_schrod *S, const double complex *c, size_t M,
                         double complex *psi, dm_err *e)
{
  double complex *f;
  size_t j;
  long K = (long)S->K;
  int st;
  if (M <= 2 * S->K)
    return dm_err_set(e, DM_EINVAL, "schrodinger: %zu points cannot hold %zu modes (need more "
                      "than 2K = %zu)", M, S->N, 2 * S->K);
  if ((f = calloc(M, sizeof *f)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
  for (j = 0; j < S->N; j++) {
    long k = (long)j - K;
    f[k >= 0 ? (size_t)k : M - (size_t)(-k)] = c[j];
  }
  st = fft(f, psi, M, FFTW_BACKWARD, e);
  free(f);
  return st;
}

void dm_schrod_diagnose(const dm_schrod *S, const double complex *c, dm_schrod_diag *d)
{
  size_t N = S->N, i, j;
  double s = 0.0, E = 0.0, p = 0.0, x = 0.0;
  for (i = 0; i < N; i++) {
    double complex hc = 0.0;
    double a2 = creal(c[i]) * creal(c[i]) + cimag(c[i]) * cimag(c[i]);
    s += a2;
    p += ((double)i - (double)S->K) * a2;
    for (j = 0; j < N; j++) {
      hc += *hat(S->H, i, j) * c[j];
      if (j != i)              /* int_0^2pi x e^{inx} dx = -2 pi i/n */
        x += creal(conj(c[i]) * c[j] * (-I / ((double)j - (double)i)));
    }
    E += creal(conj(c[i]) * hc);
  }
  d->norm = 2.0 * M_PI * s;
  d->energy = s > 0 ? E / s : NAN;
  d->p = s > 0 ? S->hbar * p / s : NAN;
  d->x = s > 0 ? M_PI + x / s : NAN;
}

/* {==== steppers ========================================================= */

struct dm_schrod_stepper {
  const dm_schrod *S;
  int method;
  double dt;
  gsl_matrix_complex *LU;       /* the step matrix, factored (milne, cn) */
  gsl_permutation *perm;
  gsl_vector_complex *b, *x;    /* right-hand side, solution */
  gsl_matrix_complex *U;        /* exact: eigenvectors */
  double *E;                    /* exact: eigenvalues */
  double complex *w, *a, *bufs; /* N each; bufs: 3 N for runs */
};

void dm_schrod_stepper_free(dm_schrod_stepper *P)
{
  if (P == NULL)
    return;
  gsl_matrix_complex_free(P->LU);
  gsl_permutation_free(P->perm);
  gsl_vector_complex_free(P->b);
  gsl_vector_complex_free(P->x);
  gsl_matrix_complex_free(P->U);
  free(P->E);
  free(P->w);
  free(P);
}

int dm_schrod_stepper_alloc(const dm_schrod *S, int method, double dt, dm_schrod_stepper **out,
                            dm_err *e)
{
  size_t N = S->N, i, j;
  dm_schrod_stepper *P;
  int signum, st = DM_OK;
  *out = NULL;
  if (!isfinite(dt) || dt == 0.0)
    return dm_err_set(e, DM_EINVAL, "schrodinger: the step dt must be finite and non-zero");
  if (method != DM_SCHROD_MILNE && method != DM_SCHROD_CN && method != DM_SCHROD_EXACT)
    return dm_err_set(e, DM_EINVAL, "schrodinger: unknown method %d", method);
  if ((P = calloc(1, sizeof *P)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
  P->S = S;
  P->method = method;
  P->dt = dt;
  P->w = malloc(5 * N * sizeof *P->w);
  P->b = gsl_vector_complex_alloc(N);
  P->x = gsl_vector_complex_alloc(N);
  if (P->w == NULL || P->b == NULL || P->x == NULL)
    goto nomem;
  P->a = P->w + N;
  P->bufs = P->a + N;
  if (method == DM_SCHROD_EXACT) {
    gsl_vector *ev = gsl_vector_alloc(N);
    P->U = gsl_matrix_complex_alloc(N, N);
    P->E = malloc(N * sizeof *P->E);
    if (ev == NULL || P->U == NULL || P->E == NULL) {
      gsl_vector_free(ev);
      goto nomem;
    }
    st = dm_schrod_eigen(S, ev, P->U, e);
    for (i = 0; i < N && st == DM_OK; i++)
      P->E[i] = gsl_vector_get(ev, i);
    gsl_vector_free(ev);
    if (st != DM_OK) {
      dm_schrod_stepper_free(P);
      return st;
    }
    *out = P;
    return DM_OK;
  }
  P->LU = gsl_matrix_complex_alloc(N, N);
  P->perm = gsl_permutation_alloc(N);
  if (P->LU == NULL || P->perm == NULL)
    goto nomem;
  /* milne: i hbar/(2 dt) I - H/6;  cn: I + i dt H/(2 hbar) */
  for (i = 0; i < N; i++)
    for (j = 0; j < N; j++) {
      double complex h = *hat(S->H, i, j), v;
      if (method == DM_SCHROD_MILNE)
        v = (i == j ? I * S->hbar / (2.0 * dt) : 0.0) - h / 6.0;
      else
        v = (i == j ? 1.0 : 0.0) + I * dt * h / (2.0 * S->hbar);
      *hat(P->LU, i, j) = v;
    }
  if (gsl_linalg_complex_LU_decomp(P->LU, P->perm, &signum) != GSL_SUCCESS) {
    dm_schrod_stepper_free(P);
    return dm_err_set(e, DM_ESINGULAR, "schrodinger: the step matrix is singular");
  }
  *out = P;
  return DM_OK;
nomem:
  dm_schrod_stepper_free(P);
  return dm_err_set(e, DM_ENOMEM, "schrodinger: out of memory");
}

/* w = H c */
static void apply_H(const dm_schrod *S, const double complex *c, double complex *w)
{
  size_t N = S->N, i, j;
  for (i = 0; i < N; i++) {
    double complex acc = 0.0;
    const double complex *row = hat(S->H, i, 0);
    for (j = 0; j < N; j++)
      acc += row[j] * c[j];
    w[i] = acc;
  }
}

int dm_schrod_step(dm_schrod_stepper *P, const double complex *c_prev,
                   const double complex *c_cur, double complex *c_next, dm_err *e)
{
  const dm_schrod *S = P->S;
  size_t N = S->N, i, j;
  double complex *b = (double complex *)P->b->data, *x = (double complex *)P->x->data;
  switch (P->method) {
  case DM_SCHROD_EXACT:            /* U diag(e^{-iE dt/hbar}) U^H c */
    for (i = 0; i < N; i++) {
      double complex acc = 0.0;
      for (j = 0; j < N; j++)
        acc += conj(*hat(P->U, j, i)) * c_cur[j];
      P->a[i] = acc * cexp(-I * P->E[i] * P->dt / S->hbar);
    }
    for (i = 0; i < N; i++) {
      double complex acc = 0.0;
      for (j = 0; j < N; j++)
        acc += *hat(P->U, i, j) * P->a[j];
      c_next[i] = acc;
    }
    return DM_OK;
  case DM_SCHROD_CN:               /* b = c - i dt/(2 hbar) H c */
    apply_H(S, c_cur, P->w);
    for (i = 0; i < N; i++)
      b[i] = c_cur[i] - I * P->dt / (2.0 * S->hbar) * P->w[i];
    break;
  default:                         /* b = i hbar/(2dt) c_prev + H (c_prev/6 + 2 c_cur/3) */
    if (c_prev == NULL)
      return dm_err_set(e, DM_EINVAL, "schrodinger: Milne-Simpson is a two-step method (give "
                        "the previous state)");
    for (i = 0; i < N; i++)
      P->a[i] = c_prev[i] / 6.0 + 2.0 * c_cur[i] / 3.0;
    apply_H(S, P->a, P->w);
    for (i = 0; i < N; i++)
      b[i] = I * S->hbar / (2.0 * P->dt) * c_prev[i] + P->w[i];
    break;
  }
  gsl_linalg_complex_LU_solve(P->LU, P->perm, P->b, P->x);
  memcpy(c_next, x, N * sizeof *c_next);
  return DM_OK;
}

/* }====================================================================== */

/* {==== runs ============================================================= */

static const char *const diag_cols[] = {"norm", "energy", "x", "p"};

dm_traj *dm_schrod_traj_alloc(dm_err *e)
{
  dm_traj *tr = dm_traj_alloc(0, NULL, 0, e);
  for (size_t i = 0; tr != NULL && i < 4; i++)
    if (dm_traj_add_column(tr, diag_cols[i], DM_TRAJ_DIAG, NULL, 0, e) != DM_OK) {
      dm_traj_free(tr);
      return NULL;
    }
  return tr;
}

static int record(dm_schrod_stepper *P, dm_traj *tr, double t, const double complex *c,
                  long k, dm_err *e)
{
  dm_schrod_diag d;
  double x[4];
  size_t i;
  for (i = 0; i < P->S->N; i++)
    if (!isfinite(creal(c[i])) || !isfinite(cimag(c[i])))
      return dm_err_set(e, DM_EDIVERGED, "schrodinger: the state became non-finite by step %ld "
                        "(t = %.17g)", k, t);
  dm_schrod_diagnose(P->S, c, &d);
  x[0] = d.norm;
  x[1] = d.energy;
  x[2] = d.x;
  x[3] = d.p;
  return dm_traj_append(tr, t, NULL, NULL, NULL, x, e);
}

int dm_schrod_run(dm_schrod_stepper *P, int start, double t0, double complex *c, long nsteps,
                  long every, dm_traj *tr, long *done, dm_err *e)
{
  const dm_schrod *S = P->S;
  size_t N = S->N;
  double complex *prev = P->bufs, *cur = prev + N, *next = cur + N;
  dm_schrod_stepper *Q = NULL;
  long k = 0, last = 0;
  int st = DM_OK;
  *done = 0;
  if (nsteps < 0 || every < 1)
    return dm_err_set(e, DM_EINVAL, "schrodinger: need steps >= 0 and every >= 1");
  if (tr == NULL || dm_traj_len(tr) != 0 || dm_traj_find(tr, "norm") == DM_TRAJ_NONE)
    return dm_err_set(e, DM_EINVAL, "schrodinger: the trajectory must be empty, from "
                      "dm_schrod_traj_alloc");
  if (P->method == DM_SCHROD_MILNE && nsteps > 0
      && (st = dm_schrod_stepper_alloc(S, start == DM_SCHROD_CN ? DM_SCHROD_CN : DM_SCHROD_EXACT,
                                       P->dt, &Q, e)) != DM_OK)
    return st;
  memcpy(cur, c, N * sizeof *cur);
  if ((st = record(P, tr, t0, cur, 0, e)) != DM_OK)
    goto out;
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = dm_err_set(e, DM_EINTR, "schrodinger: interrupted after step %ld of %ld", k, nsteps);
      break;
    }
    if (k == 0 && Q != NULL)
      st = dm_schrod_step(Q, NULL, cur, next, e);
    else
      st = dm_schrod_step(P, prev, cur, next, e);
    if (st != DM_OK)
      break;
    memcpy(prev, cur, N * sizeof *cur);
    memcpy(cur, next, N * sizeof *cur);
    if ((k + 1) % every == 0 || k + 1 == nsteps) {
      if ((st = record(P, tr, t0 + (double)(k + 1) * P->dt, cur, k + 1, e)) != DM_OK) {
        k++;
        break;
      }
      last = k + 1;
    }
  }
  if (st == DM_EINTR && last != k)     /* the last state, kept */
    record(P, tr, t0 + (double)k * P->dt, cur, k, NULL);
out:
  /* the last finite state */
  memcpy(c, st == DM_EDIVERGED ? prev : cur, N * sizeof *c);
  *done = k;
  dm_schrod_stepper_free(Q);
  return st;
}

/* }====================================================================== */
