/* test_radapt.c -- the r-adaptive multisymplectic integrator of the
 * nonlinear wave equation on moving nodes (doc/beyond-fixed-steps.md §7):
 * with alpha = 0 the centre rule is the still-grid integrator of msym.c to
 * round-off and the edge rule has the lumped-mass dispersion relation; a
 * steep sine-Gordon kink keeps the nodes ordered and the equidistribution
 * at solver tolerance every step; order 2 in dx and dt by halving; at a
 * fixed number of nodes the adaptive run beats the uniform one on a
 * travelling kink; the energy error of a long breather run is bounded;
 * errors. */
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

/* the kink 4 atan(exp(g (x - xs - v t))) */
typedef struct kink {
  double v, xs;
} kink;

static double kink_u(const kink *K, double x, double t)
{
  double g = 1 / sqrt(1 - K->v * K->v);
  return 4 * atan(exp(g * (x - K->xs - K->v * t)));
}

static double kink_ut(const kink *K, double x, double t)
{
  double g = 1 / sqrt(1 - K->v * K->v), e = exp(g * (x - K->xs - K->v * t));
  return -4 * g * K->v * e / (1 + e * e);
}

static int kink0(void *d, double x, double *y)
{
  *y = kink_u(d, x, 0);
  return 0;
}

/* the largest error of the piecewise-linear field on 20001 points */
static double interp_error(const kink *K, size_t N, const double *X, const double *u, double t)
{
  double worst = 0;
  size_t k = 0;
  for (int s = 0; s <= 20000; s++) {
    double x = X[0] + (X[N] - X[0]) * s / 20000.0, th;
    while (k + 1 < N && X[k + 1] < x)
      k++;
    th = (x - X[k]) / (X[k + 1] - X[k]);
    worst = fmax(worst, fabs(u[k] * (1 - th) + u[k + 1] * th - kink_u(K, x, t)));
  }
  return worst;
}

typedef struct runstat {
  double err, res, hmin, dE;
  int ordered, st;
  char msg[512];
} runstat;

/* a kink run on [-L/2, L/2]; keeps the final state in X, u (N + 1 each, may be NULL) */
static runstat kink_run(size_t N, double L, double dt, double alpha, int rule, const kink *K,
                        double T, double *Xo, double *uo)
{
  runstat r = {0, 0, HUGE_VAL, 0, 1, DM_OK, ""};
  dm_radapt *R;
  dm_err e;
  double *X = malloc(4 * (N + 1) * sizeof *X), *u = X + N + 1, *p = u + N + 1, *v = p + N + 1;
  long ns = lround(T / dt), j;
  if (dm_radapt_alloc(N, -L / 2, L, 1.0, dt, alpha, rule, &SG, &R, &e) != DM_OK
      || dm_radapt_init(R, kink0, (void *)K, X, u, &e) != DM_OK) {
    r.st = e.status;
    free(X);
    return r;
  }
  for (size_t i = 0; i <= N; i++)
    v[i] = kink_ut(K, X[i], 0);
  dm_radapt_momentum(R, X, v, p);
  double E0 = dm_radapt_energy(R, X, u, p);
  r.res = dm_radapt_residual(R, X, u);
  for (j = 0; j < ns; j++) {
    if ((r.st = dm_radapt_step(R, X, u, p, X, u, p, &e)) != DM_OK) {
      snprintf(r.msg, sizeof r.msg, "%s", e.msg);
      break;
    }
    r.res = fmax(r.res, dm_radapt_residual(R, X, u));
    r.dE = fmax(r.dE, fabs(dm_radapt_energy(R, X, u, p) - E0));
    for (size_t k = 0; k < N; k++) {
      r.hmin = fmin(r.hmin, X[k + 1] - X[k]);
      r.ordered &= X[k + 1] > X[k];
    }
  }
  r.err = interp_error(K, N, X, u, (double)ns * dt);
  if (Xo)
    memcpy(Xo, X, (N + 1) * sizeof *X);
  if (uo)
    memcpy(uo, u, (N + 1) * sizeof *X);
  dm_radapt_free(R);
  free(X);
  return r;
}

/* the still-grid integrator (msym.c) on the same kink: interpolation error */
static double uniform_run(size_t N, double L, double dt, const kink *K, double T)
{
  dm_msym *M;
  double *X = malloc(4 * (N + 1) * sizeof *X), *u = X + N + 1, *p = u + N + 1, *v = p + N + 1;
  long ns = lround(T / dt);
  dm_msym_alloc(N, L, 0, 1.0, dt, &SG, &M, NULL);
  for (size_t i = 0; i <= N; i++) {
    X[i] = -L / 2 + L * (double)i / (double)N;
    u[i] = kink_u(K, X[i], 0);
    v[i] = kink_ut(K, X[i], 0);
  }
  dm_msym_momentum(M, v, p);
  for (long j = 0; j < ns; j++)
    dm_msym_step(M, u, p, u, p, NULL);
  double err = interp_error(K, N, X, u, (double)ns * dt);
  dm_msym_free(M);
  free(X);
  return err;
}

/* alpha = 0, centre rule: msym.c's integrator to round-off */
static void still_centre(void)
{
  size_t N = 60, n = N + 1;
  double L = 30, dt = 0.2385, X[61], u[61], p[61], v[61], w[61], q[61], dmax = 0, xmax = 0;
  kink K = {0.385, -4};
  dm_radapt *R;
  dm_msym *M;
  dm_radapt_alloc(N, -L / 2, L, 1.0, dt, 0.0, DM_RADAPT_CENTRE, &SG, &R, NULL);
  dm_msym_alloc(N, L, 0, 1.0, dt, &SG, &M, NULL);
  tap_ok(dm_radapt_init(R, kink0, &K, X, u, NULL) == DM_OK, "alpha = 0: initial mesh");
  for (size_t i = 0; i < n; i++) {
    v[i] = kink_ut(&K, X[i], 0);
    w[i] = u[i];
    xmax = fmax(xmax, fabs(X[i] - (-L / 2 + L * (double)i / (double)N)));
  }
  tap_ok(xmax < 1e-14, "alpha = 0: the initial mesh is uniform (%.2e)", xmax);
  dm_radapt_momentum(R, X, v, p);
  dm_msym_momentum(M, v, q);
  for (int j = 0; j < 100; j++) {
    dm_radapt_step(R, X, u, p, X, u, p, NULL);
    dm_msym_step(M, w, q, w, q, NULL);
    for (size_t i = 0; i < n; i++) {
      dmax = fmax(dmax, fmax(fabs(u[i] - w[i]), fabs(p[i] - q[i])));
      xmax = fmax(xmax, fabs(X[i] - (-L / 2 + L * (double)i / (double)N)));
    }
  }
  tap_ok(dmax < 1e-12, "alpha = 0, centre rule: 100 steps = the still grid (u, p to %.2e)", dmax);
  tap_ok(xmax < 1e-13, "alpha = 0: the nodes stay put (%.2e)", xmax);
  dm_radapt_free(R);
  dm_msym_free(M);
}

static int zero_field(void *d, double x, double *y)
{
  (void)d;
  (void)x;
  *y = 0;
  return 0;
}

/* alpha = 0, edge rule: the lumped-mass dispersion relation
 * tan(w dt/2)/dt = c sin(k dx/2)/dx on the sine modes of held ends */
static void still_edges(void)
{
  size_t N = 48, n = N + 1;
  double L = 7.5, c = 1.3, dt = 0.2385, dx = L / (double)N, k = 5 * M_PI / L;
  double X[49], u[49], p[49], v[49], a[30], w0 = NAN, worst = 0;
  dm_radapt *R;
  dm_potential none = {NULL, NULL};
  dm_radapt_alloc(N, 0, L, c, dt, 0.0, DM_RADAPT_EDGES, &none, &R, NULL);
  dm_radapt_init(R, zero_field, NULL, X, u, NULL);
  for (size_t i = 0; i < n; i++) {
    u[i] = sin(k * X[i]);
    v[i] = 0.3 * sin(k * X[i]);
  }
  dm_radapt_momentum(R, X, v, p);
  for (int j = 0; j < 30; j++) {
    a[j] = u[12] / sin(k * X[12]);
    dm_radapt_step(R, X, u, p, X, u, p, NULL);
  }
  for (int j = 1; j + 1 < 30; j++) {
    if (fabs(a[j]) < 1e-2)
      continue;
    double w = acos((a[j + 1] + a[j - 1]) / (2 * a[j])) / dt;
    if (isnan(w0))
      w0 = w;
    worst = fmax(worst, fabs(w - w0));
  }
  double want = 2 / dt * atan(c * dt * sin(k * dx / 2) / dx);
  tap_near(w0, want, 1e-12, "alpha = 0, edge rule: omega %.15g = 2/dt atan(c dt sin(k dx/2)/dx)",
           w0);
  tap_ok(worst < 1e-12, "the mode is a single frequency (spread %.2e)", worst);
  dm_radapt_free(R);
}

/* a steep kink (v = 0.95, width 0.31 against dx = 0.5) */
static void steep(void)
{
  kink K = {0.95, -5};
  double X[81], u[81];
  runstat r = kink_run(80, 40, 0.0625, 4.0, DM_RADAPT_EDGES, &K, 10, X, u);
  double eu = uniform_run(80, 40, 0.0625, &K, 10), dense = HUGE_VAL;
  tap_ok(r.st == DM_OK, "steep kink: 160 steps%s%s", r.st ? ": " : "", r.msg);
  tap_ok(r.ordered && r.hmin > 0, "the nodes never cross (smallest cell %.4f)", r.hmin);
  tap_ok(r.res < 1e-13, "equidistribution at solver tolerance at the start and every step (%.2e)", r.res);
  /* the nodes crowd at the kink, now at x = 4.5 */
  for (int i = 0; i < 80; i++)
    if (X[i] <= 4.5 && X[i + 1] >= 4.5)
      dense = X[i + 1] - X[i];
  tap_ok(dense < 0.1 * 0.5, "the cell at the kink is %.4f (uniform: 0.5)", dense);
  tap_ok(r.err < 0.2 && eu / r.err > 10, "steep kink, 80 cells: error %.3g adaptive, %.3g uniform",
         r.err, eu);
  r = kink_run(80, 40, 0.25, 4.0, DM_RADAPT_EDGES, &K, 1, NULL, NULL);
  tap_ok(r.st == DM_EDIVERGED && strncmp(r.msg, "r-adaptive: the mesh tangled in cell ", 37) == 0,
         "dt = 0.25 moves the kink past its cells: %s", r.msg);
}

/* order 2 in dx and dt together, and in dt alone */
static void orders(void)
{
  kink K = {0.5, -3};
  double e[3], f[4];
  for (int m = 0; m < 3; m++) {
    size_t N = 80u << m;
    runstat r = kink_run(N, 40, 20.0 / (double)N, 2.385, DM_RADAPT_EDGES, &K, 5, NULL, NULL);
    e[m] = r.err;
  }
  double o1 = log2(e[0] / e[1]), o2 = log2(e[1] / e[2]);
  tap_ok(fabs(o1 - 2) < 0.15 && fabs(o2 - 2) < 0.15,
         "halving dx and dt: errors %.3g %.3g %.3g, orders %.3f %.3f", e[0], e[1], e[2], o1, o2);
  /* dt alone at 160 cells: differences of the final fields */
  double Xr[161], ur[161], X[161], u[161];
  kink_run(160, 40, 0.2 / 16, 2.385, DM_RADAPT_EDGES, &K, 5, Xr, ur);
  for (int m = 0; m < 3; m++) {
    kink_run(160, 40, 0.2 / (1 << m), 2.385, DM_RADAPT_EDGES, &K, 5, X, u);
    f[m] = 0;
    for (int i = 0; i <= 160; i++)
      f[m] = fmax(f[m], fmax(fabs(u[i] - ur[i]), fabs(X[i] - Xr[i])));
  }
  o1 = log2(f[0] / f[1]);
  o2 = log2(f[1] / f[2]);
  tap_ok(fabs(o1 - 2) < 0.2 && fabs(o2 - 2) < 0.2,
         "halving dt at 160 cells: changes %.3g %.3g %.3g, orders %.3f %.3f", f[0], f[1], f[2], o1,
         o2);
}

/* a travelling kink at a fixed number of nodes */
static void versus_uniform(void)
{
  kink K = {0.9, -6};
  runstat r = kink_run(100, 40, 0.1, 4.0, DM_RADAPT_EDGES, &K, 12, NULL, NULL);
  double eu = uniform_run(100, 40, 0.1, &K, 12);
  tap_ok(r.st == DM_OK && eu / r.err > 6,
         "kink v = 0.9, 100 cells, t = 12: error %.3g adaptive, %.3g uniform (ratio %.1f)", r.err, eu,
         eu / r.err);
}

/* the breather 4 atan(sqrt(1 - w^2)/w sin(w t)/cosh(sqrt(1 - w^2) x)) */
static double W_ = 0.385;

static int breather0(void *d, double x, double *y)
{
  (void)d;
  (void)x;
  *y = 0;
  return 0;
}

static void energy(void)
{
  size_t N = 100;
  double L = 40, dt = 0.1, X[101], u[101], p[101], v[101], a = sqrt(1 - W_ * W_);
  double E0, m1 = 0, m2 = 0;
  dm_radapt *R;
  dm_radapt_alloc(N, -L / 2, L, 1.0, dt, 0.5, DM_RADAPT_EDGES, &SG, &R, NULL);
  dm_radapt_init(R, breather0, NULL, X, u, NULL);
  for (size_t i = 0; i <= N; i++)               /* u_t at t = 0: 4 a/cosh(a x) */
    v[i] = 4 * a / cosh(a * X[i]);
  dm_radapt_momentum(R, X, v, p);
  E0 = dm_radapt_energy(R, X, u, p);
  int st = DM_OK;
  for (long j = 1; j <= 4000 && st == DM_OK; j++) {
    st = dm_radapt_step(R, X, u, p, X, u, p, NULL);
    double d = fabs(dm_radapt_energy(R, X, u, p) - E0);
    if (j <= 2000)
      m1 = fmax(m1, d);
    else
      m2 = fmax(m2, d);
  }
  tap_ok(st == DM_OK, "breather w = 0.385, alpha = 0.5: 4000 steps (t = 400)");
  tap_ok(m2 < 1.3 * m1 && m1 < 0.02 * E0,
         "energy error bounded: max %.3g over t <= 200, %.3g over 200..400 (E = %.4g)", m1, m2, E0);
  dm_radapt_free(R);
}

static int bad_field(void *d, double x, double *y)
{
  (void)d;
  *y = x > 1 ? NAN : 0;
  return 0;
}

static void errors(void)
{
  dm_radapt *R = (dm_radapt *)1;
  dm_err e;
  double X[11], u[11];
  tap_ok(dm_radapt_alloc(2, 0, 1, 1, 0.1, 1, DM_RADAPT_EDGES, NULL, &R, &e) == DM_EINVAL
         && R == NULL && strcmp(e.msg, "r-adaptive: need 3 <= N cells, got 2") == 0, "%s", e.msg);
  tap_ok(dm_radapt_alloc(10, 0, 1, 1, 0.1, -2.385, DM_RADAPT_EDGES, NULL, &R, &e) == DM_EINVAL
         && strcmp(e.msg, "r-adaptive: alpha must be a finite number >= 0, got -2.385") == 0, "%s",
         e.msg);
  tap_ok(dm_radapt_alloc(10, 0, 1, 1, 0.1, 1, 7, NULL, &R, &e) == DM_EINVAL
         && strcmp(e.msg, "r-adaptive: unknown kinetic rule 7") == 0, "%s", e.msg);
  tap_ok(dm_radapt_alloc(10, 0, -1, 1, 0.1, 1, 0, NULL, &R, &e) == DM_EINVAL, "%s", e.msg);
  dm_radapt_alloc(10, 0, 2, 1, 0.1, 1, DM_RADAPT_EDGES, NULL, &R, &e);
  tap_ok(dm_radapt_init(R, bad_field, NULL, X, u, &e) == DM_EDOM
         && strcmp(e.msg, "r-adaptive: the initial field fails at x = 1.2") == 0, "%s", e.msg);
  dm_radapt_free(R);
  dm_radapt_free(NULL);
}

int main(void)
{
  still_centre();
  still_edges();
  steep();
  orders();
  versus_uniform();
  energy();
  errors();
  return tap_done();
}
