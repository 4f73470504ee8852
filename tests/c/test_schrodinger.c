/* test_schrodinger.c -- the pseudospectral variational integrator for the
 * Schrodinger equation (doc/beyond-fixed-steps.md §6): one mode (Milne-Simpson error
 * against T E^5 dt^4/180 and order 4, Crank-Nicolson order 2 and its norm,
 * the stability bound dt E/hbar <= sqrt 3 from both sides), the free
 * particle mode by mode, the harmonic oscillator's eigenvalues w(n + 1/2)
 * and a coherent state whose <x> oscillates with frequency w, FFT round
 * trips, errors. */
#include <config.h>
#include <complex.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "fields/fields.h"
#include "tap.h"

/* one mode, V = E: H = [E] */
static dm_schrod *one_mode(double E)
{
  static double V[8];
  dm_schrod *S;
  for (int i = 0; i < 8; i++)
    V[i] = E;
  dm_schrod_alloc(0, 1.0, 1.0, V, 8, &S, NULL);
  return S;
}

/* |c(T) - e^{-iET}| after T/dt steps of the method (E = 1 unless set) */
static double energy_level = 1.0;
static double one_mode_error(int method, double dt, double T, double *maxabs, double *normdev)
{
  dm_schrod *S = one_mode(energy_level);
  dm_schrod_stepper *P;
  dm_traj *tr = dm_schrod_traj_alloc(NULL);
  double complex c = 1.0;
  long n = lround(T / dt), done;
  dm_schrod_stepper_alloc(S, method, dt, &P, NULL);
  dm_schrod_run(P, DM_SCHROD_EXACT, 0.0, &c, n, 1, tr, &done, NULL);
  if (maxabs != NULL || normdev != NULL) {
    const double *nm = dm_traj_col(tr, dm_traj_find(tr, "norm"));
    double m = 0, d = 0;
    for (size_t k = 0; k < dm_traj_len(tr); k++) {
      m = fmax(m, sqrt(nm[k] / (2 * M_PI)));
      d = fmax(d, fabs(nm[k] / (2 * M_PI) - 1.0));
    }
    if (maxabs)
      *maxabs = m;
    if (normdev)
      *normdev = d;
  }
  dm_traj_free(tr);
  dm_schrod_stepper_free(P);
  dm_schrod_free(S);
  return cabs(c - cexp(-I * energy_level * (double)n * dt));
}

/* max |c| over steps [0, n) and [n, 2n) of Milne-Simpson at z = dt E */
static void halves(double z, long n, double *first, double *second)
{
  dm_schrod *S = one_mode(z / 0.1);
  dm_schrod_stepper *P;
  dm_traj *tr = dm_schrod_traj_alloc(NULL);
  double complex c = 1.0;
  long done;
  dm_schrod_stepper_alloc(S, DM_SCHROD_MILNE, 0.1, &P, NULL);
  dm_schrod_run(P, DM_SCHROD_EXACT, 0.0, &c, 2 * n, 1, tr, &done, NULL);
  const double *nm = dm_traj_col(tr, dm_traj_find(tr, "norm"));
  *first = *second = 0;
  for (long k = 0; k <= 2 * n; k++) {
    double a = sqrt(nm[k] / (2 * M_PI));
    if (k < n)
      *first = fmax(*first, a);
    else
      *second = fmax(*second, a);
  }
  dm_traj_free(tr);
  dm_schrod_stepper_free(P);
  dm_schrod_free(S);
}

static void single_mode(void)
{
  double e1 = one_mode_error(DM_SCHROD_MILNE, 0.1, 10, NULL, NULL);
  double e2 = one_mode_error(DM_SCHROD_MILNE, 0.05, 10, NULL, NULL);
  double e3 = one_mode_error(DM_SCHROD_MILNE, 0.025, 10, NULL, NULL);
  tap_ok(fabs(e1 / (10 * 1e-4 / 180) - 1) < 0.01, "Milne-Simpson, one mode E = 1, dt = 0.1, "
         "T = 10: error %.5g (T E^5 dt^4/180 = %.5g)", e1, 10 * 1e-4 / 180);
  tap_ok(fabs(log2(e1 / e2) - 4) < 0.02 && fabs(log2(e2 / e3) - 4) < 0.02,
         "Milne-Simpson: errors %.3g %.3g %.3g, order %.3f %.3f (4; the thesis says 2)", e1, e2, e3,
         log2(e1 / e2), log2(e2 / e3));
  double nd, c1 = one_mode_error(DM_SCHROD_CN, 0.1, 10, NULL, &nd);
  double c2 = one_mode_error(DM_SCHROD_CN, 0.05, 10, NULL, NULL);
  tap_ok(fabs(c1 / 8.32e-3 - 1) < 0.01 && fabs(c2 / 2.08e-3 - 1) < 0.01
         && fabs(log2(c1 / c2) - 2) < 0.01, "Crank-Nicolson: errors %.4g %.4g, order %.3f (2)",
         c1, c2, log2(c1 / c2));
  tap_ok(nd <= 2e-14, "Crank-Nicolson: | |c| - 1 | <= %.2g over 100 steps (a quadratic invariant)",
         nd);
  /* the stability bound dt E/hbar <= sqrt 3: dt = 0.1, E = z/dt */
  double f1, s1, f2, s2, f3, s3, f4, s4;
  halves(1.70, 500, &f1, &s1);
  halves(1.74, 500, &f2, &s2);
  tap_ok(s1 <= f1 * 1.01 && s2 > 1e36, "Milne-Simpson z = 1.70: max |c| %.4g over 500 "
         "steps, %.4g over the next 500 (bounded); z = 1.74: %.3g by t = 100", f1, s1, s2);
  halves(sqrt(3.0) * (1 - 1e-4), 2000, &f3, &s3);
  halves(sqrt(3.0) * (1 + 1e-4), 2000, &f4, &s4);
  tap_ok(s3 <= f3 * 1.01 && s4 > 1e3 * f4, "the bound is sqrt 3: z = sqrt 3 (1 - 1e-4): max "
         "|c| %.4g over 2000 steps, %.4g over the next 2000; z = sqrt 3 (1 + 1e-4): %.3g, then %.3g",
         f3, s3, f4, s4);
}

/* V = 0: c_k(t) = c_k(0) e^{-i hbar k^2 t/2m} */
static void free_particle(void)
{
  dm_schrod *S;
  dm_schrod_stepper *P;
  size_t K = 8, N = 2 * K + 1;
  double complex c[17], c0[17];
  double hbar = 1.3, m = 0.7, dt = 0.002, worst = 0;
  long n = 500, done;
  dm_schrod_alloc(K, hbar, m, NULL, 0, &S, NULL);
  for (size_t j = 0; j < N; j++)
    c0[j] = c[j] = (0.3 + 0.1 * (double)j) * cexp(I * 0.7 * (double)j) / sqrt(2 * M_PI * N);
  dm_schrod_stepper_alloc(S, DM_SCHROD_MILNE, dt, &P, NULL);
  dm_traj *tr = dm_schrod_traj_alloc(NULL);
  int st = dm_schrod_run(P, DM_SCHROD_EXACT, 0, c, n, 50, tr, &done, NULL);
  /* each mode: the phase error n z^5/180, z = dt hbar k^2/2m (dt max E = 0.12) */
  for (size_t j = 0; j < N; j++) {
    double k = (double)j - (double)K, z = dt * hbar * k * k / (2 * m);
    double err = cabs(c[j] - c0[j] * cexp(-I * hbar * k * k * (double)n * dt / (2 * m)));
    double want = (double)n * pow(z, 5) / 180 * cabs(c0[j]);
    worst = fmax(worst, fabs(err - want) / (want + 1e-12));
  }
  tap_ok(st == DM_OK && done == n && worst < 0.01 && dm_traj_len(tr) == 11,
         "free particle, K = 8, Milne-Simpson: every mode's error is n z^5/180 |c_k| (to %.2g "
         "relative)", worst);
  dm_traj_free(tr);
  dm_schrod_stepper_free(P);
  dm_schrod_free(S);
}

/* V = w^2 (x - pi)^2/2, w = 16, K = 32 */
static void oscillator(void)
{
  enum { M = 65536, MS = 512 };
  static double V[M];
  static double complex psi[MS];
  double w = 16, worst = 0, a = 0.25;
  size_t K = 32, N = 65;
  dm_schrod *S;
  for (int j = 0; j < M; j++) {
    double x = 2 * M_PI * j / M - M_PI;
    V[j] = 0.5 * w * w * x * x;
  }
  int st = dm_schrod_alloc(K, 1.0, 1.0, V, M, &S, NULL);
  gsl_vector *ev = gsl_vector_alloc(N);
  st |= dm_schrod_eigen(S, ev, NULL, NULL);
  for (int n = 0; n < 6; n++)
    worst = fmax(worst, fabs(gsl_vector_get(ev, n) - w * (n + 0.5)));
  tap_ok(st == DM_OK && worst <= 1e-10, "harmonic oscillator w = 16, K = 32: the six lowest "
         "eigenvalues of the Galerkin Hamiltonian are w (n + 1/2) to %.2g", worst);
  /* a coherent state: the ground state displaced by a */
  for (int j = 0; j < MS; j++) {
    double x = 2 * M_PI * j / MS;
    psi[j] = pow(w / M_PI, 0.25) * exp(-0.5 * w * (x - M_PI - a) * (x - M_PI - a));
  }
  double complex c[65];
  st = dm_schrod_analyse(S, psi, MS, c, NULL);
  dm_schrod_diag d0;
  dm_schrod_diagnose(S, c, &d0);
  tap_ok(st == DM_OK && fabs(d0.norm - 1) < 1e-12 && fabs(d0.x - M_PI - a) < 1e-12
         && fabs(d0.energy - w * (0.5 + 0.5 * w * a * a)) < 1e-9,
         "coherent state from samples (FFT): norm %.15f, <x> - pi = %.15f, energy %.10g", d0.norm,
         d0.x - M_PI, d0.energy);
  double zmax = gsl_vector_get(ev, N - 1), dt = 0.5 * sqrt(3.0) / zmax;
  dm_schrod_stepper *P;
  dm_traj *tr = dm_schrod_traj_alloc(NULL);
  long n = lround(2 * M_PI / w * 2 / dt), done;   /* two periods */
  dm_schrod_stepper_alloc(S, DM_SCHROD_MILNE, dt, &P, NULL);
  st = dm_schrod_run(P, DM_SCHROD_EXACT, 0, c, n, 1, tr, &done, NULL);
  const double *t = dm_traj_col(tr, 0), *x = dm_traj_col(tr, dm_traj_find(tr, "x")),
               *E = dm_traj_col(tr, dm_traj_find(tr, "energy")),
               *nm = dm_traj_col(tr, dm_traj_find(tr, "norm"));
  double dx = 0, dE = 0, dn = 0;
  for (size_t k = 0; k < dm_traj_len(tr); k++) {
    dx = fmax(dx, fabs(x[k] - M_PI - a * cos(w * t[k])));
    dE = fmax(dE, fabs(E[k] - E[0]));
    dn = fmax(dn, fabs(nm[k] - nm[0]));
  }
  tap_ok(st == DM_OK && dx < 1e-6 && dE < 1e-8 && dn < 1e-8, "coherent state, Milne-Simpson "
         "dt = sqrt3/(2 max E) = %.3g, two periods: <x> = pi + a cos(w t) to %.2g, energy to "
         "%.2g, norm to %.2g", dt, dx, dE, dn);
  dm_schrod_stepper_free(P);
  dm_traj_free(tr);
  /* Crank-Nicolson on 65 modes: the norm to round-off over 1000 steps */
  dm_schrod_analyse(S, psi, MS, c, NULL);
  tr = dm_schrod_traj_alloc(NULL);
  dm_schrod_stepper_alloc(S, DM_SCHROD_CN, 0.01, &P, NULL);
  st = dm_schrod_run(P, DM_SCHROD_CN, 0, c, 1000, 10, tr, &done, NULL);
  nm = dm_traj_col(tr, dm_traj_find(tr, "norm"));
  dn = 0;
  for (size_t k = 0; k < dm_traj_len(tr); k++)
    dn = fmax(dn, fabs(nm[k] - nm[0]));
  tap_ok(st == DM_OK && dn <= 2e-13, "Crank-Nicolson, 65 modes, dt = 0.01 (dt max E = %.3g): "
         "norm conserved to %.2g over 1000 steps", 0.01 * zmax, dn);
  /* analysis and synthesis are inverse */
  double complex back[65];
  dm_schrod_synthesise(S, c, MS, psi, NULL);
  dm_schrod_analyse(S, psi, MS, back, NULL);
  double rt = 0;
  for (size_t j = 0; j < N; j++)
    rt = fmax(rt, cabs(back[j] - c[j]));
  tap_ok(rt < 1e-15, "synthesis then analysis returns the coefficients to %.2g", rt);
  dm_traj_free(tr);
  dm_schrod_stepper_free(P);
  gsl_vector_free(ev);
  dm_schrod_free(S);
}

static void errors(void)
{
  dm_schrod *S = NULL;
  dm_schrod_stepper *P = NULL;
  dm_err e;
  double V[10] = {0};
  tap_ok(dm_schrod_alloc(4, 1, 1, V, 10, &S, &e) == DM_EINVAL && S == NULL
         && strcmp(e.msg, "schrodinger: the potential needs M > 4K = 16 samples (and at most "
                   "2^24), got 10") == 0, "too few samples of V: %s", e.msg);
  tap_ok(dm_schrod_alloc(4, 0, 1, NULL, 0, &S, &e) == DM_EINVAL
         && strcmp(e.msg, "schrodinger: hbar and m must be finite and > 0") == 0, "hbar = 0: %s",
         e.msg);
  V[3] = NAN;
  tap_ok(dm_schrod_alloc(1, 1, 1, V, 10, &S, &e) == DM_EINVAL
         && strstr(e.msg, "V is not finite at x = 2 pi 3/10") != NULL, "NaN in V: %s", e.msg);
  dm_schrod_alloc(2, 1, 1, NULL, 0, &S, NULL);
  tap_ok(dm_schrod_stepper_alloc(S, DM_SCHROD_CN, 0.0, &P, &e) == DM_EINVAL && P == NULL,
         "dt = 0: %s", e.msg);
  double complex c[5] = {0}, psi[4];
  tap_ok(dm_schrod_analyse(S, psi, 4, c, &e) == DM_EINVAL
         && strstr(e.msg, "4 samples cannot resolve 5 modes") != NULL, "too few samples: %s",
         e.msg);
  dm_schrod_stepper_alloc(S, DM_SCHROD_MILNE, 0.1, &P, NULL);
  tap_ok(dm_schrod_step(P, NULL, c, c, &e) == DM_EINVAL
         && strstr(e.msg, "two-step method") != NULL, "Milne-Simpson without c_prev: %s", e.msg);
  dm_schrod_stepper_free(P);
  dm_schrod_free(S);
}

int main(void)
{
  single_mode();
  free_particle();
  oscillator();
  errors();
  return tap_done();
}
