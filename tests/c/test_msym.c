/* test_msym.c -- multisymplectic integrators of the nonlinear wave equation
 * (doc/beyond-fixed-steps.md §5): the dispersion relation of plane waves on the grid
 * and on a DEC ring, order 2 of a standing wave, the discrete
 * multisymplectic form formula checked cell by cell, node by node and
 * level by level (sine-Gordon), the sine-Gordon kink against the exact
 * one, the DEC integrator on a triangle mesh (exact energy of the linear
 * wave, symplectic step), errors. */
#include <config.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/status.h"
#include "fields/fields.h"
#include "tap.h"

static int sine_gordon(void *d, double u, double *V, double *dV, double *d2V)
{
  (void)d;
  if (V)
    *V = 1 - cos(u);
  if (dV)
    *dV = sin(u);
  if (d2V)
    *d2V = cos(u);
  return 0;
}

static const dm_potential SG = {sine_gordon, NULL};

/* omega of mode k measured from three levels: A^{j+1} + A^{j-1} = 2 cos(w dt) A^j */
static double measured_omega(const double *a, long n, double dt)
{
  double worst = 0, w0 = NAN;
  for (long j = 1; j + 1 < n; j++) {
    double w = acos((a[j + 1] + a[j - 1]) / (2 * a[j])) / dt;
    if (fabs(a[j]) < 1e-3)
      continue;
    if (isnan(w0))
      w0 = w;
    worst = fmax(worst, fabs(w - w0));
  }
  return worst < 1e-11 ? w0 : NAN;
}

static void dispersion(void)
{
  size_t N = 64;
  double L = 10.0, c = 1.3, dt = 0.1, k = 2 * M_PI * 5 / L, u[64], p[64], v[64], a[40];
  dm_msym *M;
  dm_msym_alloc(N, L, 1, c, dt, NULL, &M, NULL);
  for (size_t i = 0; i < N; i++) {
    u[i] = cos(k * L * (double)i / (double)N);
    v[i] = 0.4 * sin(k * L * (double)i / (double)N);
  }
  dm_msym_momentum(M, v, p);
  for (long j = 0; j < 40; j++) {
    /* the amplitude of cos(kx) */
    a[j] = 0;
    for (size_t i = 0; i < N; i++)
      a[j] += u[i] * cos(k * L * (double)i / (double)N) * 2 / (double)N;
    dm_msym_step(M, u, p, u, p, NULL);
  }
  double w = measured_omega(a, 40, dt), want = dm_msym_dispersion(M, k);
  double dx = L / N, lhs = tan(w * dt / 2) / dt, rhs = c * tan(k * dx / 2) / dx;
  tap_ok(fabs(w - want) < 1e-12 && fabs(lhs - rhs) < 1e-12, "grid, V = 0: a plane wave's "
         "omega = %.15f, tan(w dt/2)/dt - c tan(k dx/2)/dx = %.2g (exact omega c k = %.6f)", w,
         lhs - rhs, c * k);
  dm_msym_free(M);

  /* a ring of N vertices (a regular polygon): *0 = dx (the chord), the
   * semi-discrete spectrum 4 sin^2(pi m/N)/dx^2 and the midpoint rule in time:
   * tan(w dt/2)/dt = c sin(pi m/N)/dx */
  enum { NR = 48 };
  dm_dec_meshdata *md = dm_dec_meshdata_alloc(1, 2, NR, NR, NULL);
  for (int i = 0; i < NR; i++) {
    md->X[2 * i] = cos(2 * M_PI * i / NR);
    md->X[2 * i + 1] = sin(2 * M_PI * i / NR);
    md->T[2 * i] = i;
    md->T[2 * i + 1] = (i + 1) % NR;
  }
  dm_dec_complex *K = dm_dec_complex_alloc(1, NR, NR, md->T, NULL);
  dm_dec_geom *G = dm_dec_geom_alloc(K, 2, md->X, NULL);
  dm_msym_dec *D;
  int st = dm_msym_dec_alloc(G, c, dt, NULL, &D, NULL);
  double ur[NR], pr[NR], vr[NR], ar[40], dxr = 2 * sin(M_PI / NR);
  int m = 3;
  for (int i = 0; i < NR; i++) {
    ur[i] = cos(2 * M_PI * m * i / NR);
    vr[i] = 0.7 * sin(2 * M_PI * m * i / NR);
  }
  dm_msym_dec_momentum(D, vr, pr);
  for (long j = 0; j < 40; j++) {
    ar[j] = 0;
    for (int i = 0; i < NR; i++)
      ar[j] += ur[i] * cos(2 * M_PI * m * i / NR) * 2.0 / NR;
    dm_msym_dec_step(D, ur, pr, ur, pr, NULL);
  }
  w = measured_omega(ar, 40, dt);
  double gap = tan(w * dt / 2) / dt - c * sin(M_PI * m / NR) / dxr;
  tap_ok(st == DM_OK && fabs(gap) < 1e-12, "DEC ring of %d vertices, V = 0: omega = %.15f, "
         "tan(w dt/2)/dt - c sin(pi m/N)/dx = %.2g", NR, w, gap);
  dm_msym_dec_free(D);
  dm_dec_geom_free(G);
  dm_dec_complex_free(K);
  dm_dec_meshdata_free(md);
}

/* u = sin(3x) cos(3ct) on [0, pi], ends held: order 2 in (dx, dt) jointly */
static void standing(void)
{
  double c = 1.1, err[3];
  for (int r = 0; r < 3; r++) {
    size_t N = 30u << r;
    double dx = M_PI / N, dt = 0.5 * dx, T = 1.0;
    long n = lround(T / dt);
    dt = T / (double)n;
    dm_msym *M;
    double *u = calloc(2 * (N + 1), sizeof *u), *p = u + N + 1;
    dm_msym_alloc(N, M_PI, 0, c, dt, NULL, &M, NULL);
    for (size_t i = 0; i <= N; i++)
      u[i] = sin(3 * dx * (double)i);
    /* p from the exact initial velocity 0 */
    for (long j = 0; j < n; j++)
      dm_msym_step(M, u, p, u, p, NULL);
    err[r] = 0;
    for (size_t i = 0; i <= N; i++)
      err[r] = fmax(err[r], fabs(u[i] - sin(3 * dx * (double)i) * cos(3 * c * T)));
    dm_msym_free(M);
    free(u);
  }
  double o1 = log2(err[0] / err[1]), o2 = log2(err[1] / err[2]);
  tap_ok(fabs(o1 - 2) < 0.1 && fabs(o2 - 2) < 0.1, "standing wave sin(3x) cos(3ct), ends held, "
         "dt = dx/2: errors %.3g %.3g %.3g, order %.3f %.3f (2)", err[0], err[1], err[2], o1, o2);
}

/* sine-Gordon: the form formula and the kink */
static void sine_gordon_checks(void)
{
  size_t N = 128;
  double L = 20.0, dt = 0.05, res[3];
  double *b = calloc(6 * N, sizeof *b), *u = b, *p = u + N, *du = p + N, *dp = du + N,
         *dv = dp + N, *dq = dv + N;
  dm_msym *M;
  dm_msym_alloc(N, L, 1, 1.0, dt, &SG, &M, NULL);
  for (size_t i = 0; i < N; i++) {
    double x = L * (double)i / (double)N;
    u[i] = 2.0 * sin(2 * M_PI * x / L) + 0.5 * cos(6 * M_PI * x / L);
  }
  for (size_t i = 0; i < N; i++) {
    double x = L * (double)i / (double)N;
    p[i] = dm_msym_dx(M) * 0.8 * cos(4 * M_PI * x / L);
    du[i] = exp(-(x - 7) * (x - 7));
    dp[i] = 0.3 * sin(2 * M_PI * x / L);
    dv[i] = cos(4 * M_PI * x / L);
    dq[i] = exp(-(x - 12) * (x - 12)) * 0.7;
  }
  int st = dm_msym_form_check(M, u, p, du, dp, dv, dq, 200, res, NULL);
  tap_ok(st == DM_OK && res[0] < 1e-14, "sine-Gordon, 200 steps: on every cell the corner forms "
         "sum to %.2g (relative)", res[0]);
  tap_ok(st == DM_OK && res[1] < 1e-12, "at every node of every level the corner forms of its "
         "four cells sum to %.2g: the discrete multisymplectic conservation law", res[1]);
  tap_ok(st == DM_OK && res[2] < 1e-12, "the symplectic form of every level equals the first's "
         "to %.2g", res[2]);
  dm_msym_free(M);
  free(b);

  /* the kink u = 4 atan(exp(g (x - vt))), g = 1/sqrt(1 - v^2), ends held at 0 and 2 pi */
  double v = 0.5, g = 1 / sqrt(1 - v * v), errs[2];
  for (int r = 0; r < 2; r++) {
    size_t NN = 400u << r;
    double len = 40, dx = len / NN, h = 0.5 * dx, T = 10;
    long n = lround(T / h);
    h = T / n;
    double *uu = calloc(3 * (NN + 1), sizeof *uu), *pp = uu + NN + 1, *vv = pp + NN + 1;
    dm_msym *K;
    dm_msym_alloc(NN, len, 0, 1.0, h, &SG, &K, NULL);
    for (size_t i = 0; i <= NN; i++) {
      double x = -20 + dx * (double)i, ex = exp(g * x);
      uu[i] = 4 * atan(ex);
      vv[i] = -4 * g * v * ex / (1 + ex * ex);
    }
    /* the momentum of the first slab from the exact velocity at t = h/2 */
    dm_msym_momentum(K, vv, pp);
    for (long j = 0; j < n; j++)
      dm_msym_step(K, uu, pp, uu, pp, NULL);
    errs[r] = 0;
    for (size_t i = 1; i < NN; i++) {
      double x = -20 + dx * (double)i;
      errs[r] = fmax(errs[r], fabs(uu[i] - 4 * atan(exp(g * (x - v * T)))));
    }
    dm_msym_free(K);
    free(uu);
  }
  tap_ok(errs[1] < 0.3 * errs[0] && errs[0] < 0.05, "sine-Gordon kink, v = 0.5, to t = 10: max "
         "error %.3g (dx = 0.1), %.3g (dx = 0.05)", errs[0], errs[1]);
}

/* DEC on a disc of triangles: energy of the linear wave exact, sine-Gordon bounded,
 * the step symplectic */
static void dec_disc(void)
{
  dm_dec_meshdata *md = dm_dec_gen_disc(1.0, 4, NULL);
  dm_dec_complex *K = dm_dec_complex_alloc(2, md->nv, md->ntop, md->T, NULL);
  dm_dec_geom *G = dm_dec_geom_alloc(K, 2, md->X, NULL);
  size_t n = (size_t)md->nv, i, j;
  double *u = calloc(8 * n + 4 * n * n, sizeof *u), *p = u + n, *u1 = p + n, *p1 = u1 + n;
  double *e = p1 + n, *z = e + 2 * n, *D = z + 2 * n;
  for (int pass = 0; pass < 2; pass++) {
    dm_msym_dec *M;
    int st = dm_msym_dec_alloc(G, 1.0, 0.05, pass ? &SG : NULL, &M, NULL);
    for (i = 0; i < n; i++) {
      u[i] = exp(-8 * (md->X[2 * i] * md->X[2 * i] + md->X[2 * i + 1] * md->X[2 * i + 1]));
      p[i] = 0;
    }
    double E0 = dm_msym_dec_energy(M, u, p), dE = 0;
    for (int k = 0; k < 400 && st == DM_OK; k++) {
      st = dm_msym_dec_step(M, u, p, u, p, NULL);
      dE = fmax(dE, fabs(dm_msym_dec_energy(M, u, p) - E0));
    }
    if (!pass)
      tap_ok(st == DM_OK && dE <= 1e-13 * E0, "DEC disc (%zu vertices), wave equation, 400 "
             "steps: energy %.6g constant to %.2g (midpoint rule: a quadratic invariant)", n, E0,
             dE);
    else
      tap_ok(st == DM_OK && dE < 1e-3 * E0, "DEC disc, sine-Gordon: energy error %.2g of %.4g "
             "(bounded)", dE, E0);
    if (pass) {
      /* the step's Jacobian (columns by the tangent map) is symplectic */
      dm_msym_dec_step(M, u, p, u1, p1, NULL);
      for (j = 0; j < 2 * n; j++) {
        memset(z, 0, 2 * n * sizeof *z);
        z[j] = 1;
        dm_msym_dec_tangent(M, u, u1, z, z + n, e, e + n, NULL);
        for (i = 0; i < 2 * n; i++)
          D[i * 2 * n + j] = e[i];
      }
      double worst = 0, big = 0;
      for (i = 0; i < 4 * n * n; i++)
        big = fmax(big, fabs(D[i]));
      for (i = 0; i < 2 * n; i++)
        for (j = 0; j < 2 * n; j++) {
          double acc = 0;
          for (size_t l = 0; l < n; l++)
            acc += D[l * 2 * n + i] * D[(n + l) * 2 * n + j] - D[(n + l) * 2 * n + i] * D[l * 2 * n + j];
          double want = (i < n && j == i + n) ? 1 : (i >= n && j + n == i) ? -1 : 0;
          worst = fmax(worst, fabs(acc - want));
        }
      tap_ok(worst < 1e-12 * big * big, "DEC disc, sine-Gordon: the step is symplectic, defect "
             "%.2g (max |D| = %.3g)", worst, big);
    }
    dm_msym_dec_free(M);
  }
  free(u);
  dm_dec_geom_free(G);
  dm_dec_complex_free(K);
  dm_dec_meshdata_free(md);
}

static void errors(void)
{
  dm_msym *M = NULL;
  dm_err e;
  tap_ok(dm_msym_alloc(2, 1, 1, 1, 0.1, NULL, &M, &e) == DM_EINVAL && M == NULL
         && strcmp(e.msg, "multisymplectic: need 3 <= N cells, got 2") == 0, "N = 2: %s", e.msg);
  tap_ok(dm_msym_alloc(10, 1, 1, 1, 0.0, NULL, &M, &e) == DM_EINVAL, "dt = 0: %s", e.msg);
}

int main(void)
{
  dispersion();
  standing();
  sine_gordon_checks();
  dec_disc();
  errors();
  return tap_done();
}
