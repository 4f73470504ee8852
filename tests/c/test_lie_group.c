/* test_lie_group.c -- the group layer (src/lie): every operation of every
 * family (R^3, SO(2), T^3, SO(3), SE(2), SE(3), SE(3) x T^3, SO(3) x R^2)
 * on random elements generic, near the identity and near rotation angle
 * pi, against independent references: the matrix exponential and the
 * Cayley map of the matrix representation (Taylor series with scaling and
 * squaring, GSL LU), finite differences for dexp, dcay and the generators,
 * the group laws; the closed-form values of doc/lie.md (Rz(90) from
 * exp and cay, the screw motion, the near-pi logarithms, a rotation of
 * (1,1,1)); continuity of the series coefficients at their thresholds;
 * 1e7 compositions without loss of orthogonality; normalization; the
 * error paths and their messages; group names and descriptions.  The
 * sphere S^n: test_lie_sphere.c. */
#include <config.h>
#include <math.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_rng.h>

#include "lie/lie.h"
#include "lie/lie_impl.h"
#include "tap.h"

#define NQ DM_LIE_NQ_MAX
#define DIM 24
#define MS 24

static gsl_rng *rng;

static double urand(double a, double b)
{
  return a + (b - a) * gsl_rng_uniform(rng);
}

static void rand_unit3(double *n)
{
  double r;
  do {
    n[0] = urand(-1, 1), n[1] = urand(-1, 1), n[2] = urand(-1, 1);
    r = dm_v3_dot(n, n);
  } while (r > 1.0 || r < 1e-2);
  r = sqrt(r);
  n[0] /= r, n[1] /= r, n[2] /= r;
}

enum { GENERIC, NEAR0, NEARPI };

/* a random algebra element of a simple group: rotation angle in (0, 3) for
 * GENERIC, ~1e-7 for NEAR0, pi - ~1e-7 for NEARPI (translations of size 1,
 * or 1e-7 near 0) */
static void rand_simple(const dm_lie_group *G, int mode, double *xi)
{
  double ang = mode == NEAR0 ? urand(1e-8, 1e-6) : mode == NEARPI ? M_PI - urand(1e-9, 1e-7)
                                                                   : urand(0.05, 3.0);
  double tr = mode == NEAR0 ? 1e-7 : 1.0;
  size_t i;
  for (i = 0; i < G->dim; i++)
    xi[i] = urand(-tr, tr);
  switch (G->kind) {
  case DM_LIE_SO3:
  case DM_LIE_SE3:
    rand_unit3(xi);
    xi[0] *= ang, xi[1] *= ang, xi[2] *= ang;
    break;
  case DM_LIE_SO2:
  case DM_LIE_TN:
    for (i = 0; i < G->dim; i++)
      xi[i] = (gsl_rng_uniform(rng) < 0.5 ? -1 : 1) * (mode == NEARPI ? ang : ang / 3);
    break;
  case DM_LIE_SE2:
    xi[0] = (gsl_rng_uniform(rng) < 0.5 ? -1 : 1) * ang;
    break;
  default:
    break;
  }
}

static void rand_xi(const dm_lie_group *G, int mode, double *xi)
{
  size_t i;
  if (G->kind != DM_LIE_PRODUCT) {
    rand_simple(G, mode, xi);
    return;
  }
  for (i = 0; i < G->nfac; i++)
    rand_simple(G->fac[i], mode, xi + G->xoff[i]);
}

static void rand_g(const dm_lie_group *G, int mode, double *g)
{
  double xi[DIM];
  rand_xi(G, mode, xi);
  dm_lie_exp(G, xi, g);
}

static double maxdiff(const double *a, const double *b, size_t n)
{
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return isnan(m) ? INFINITY : m;
}

static double vnorm(const double *a, size_t n)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    s += a[i] * a[i];
  return sqrt(s);
}

/* {==== dense helpers for the references =================================== */

static void mmul(const double *A, const double *B, double *C, size_t n)
{
  double T[MS * MS];
  size_t i, j, k;
  for (i = 0; i < n; i++)
    for (j = 0; j < n; j++) {
      double s = 0.0;
      for (k = 0; k < n; k++)
        s += A[i * n + k] * B[k * n + j];
      T[i * n + j] = s;
    }
  memcpy(C, T, n * n * sizeof *C);
}

/* exp of a matrix: Taylor series of A / 2^s, then s squarings */
static void mexp(const double *A, double *E, size_t n)
{
  double B[MS * MS], T[MS * MS], nrm = 0.0;
  size_t i, k;
  int s = 0;
  for (i = 0; i < n * n; i++)
    nrm = fmax(nrm, fabs(A[i]));
  while (nrm * n > 0.05)
    nrm /= 2, s++;
  for (i = 0; i < n * n; i++)
    B[i] = A[i] / ldexp(1.0, s);
  memset(E, 0, n * n * sizeof *E);
  memset(T, 0, n * n * sizeof *T);
  for (i = 0; i < n; i++)
    E[i * n + i] = T[i * n + i] = 1.0;
  for (k = 1; k < 20; k++) {
    mmul(T, B, T, n);
    for (i = 0; i < n * n; i++) {
      T[i] /= (double)k;
      E[i] += T[i];
    }
  }
  while (s-- > 0)
    mmul(E, E, E, n);
}

/* (I - A/2)^-1 (I + A/2) by GSL LU */
static void mcay(const double *A, double *C, size_t n)
{
  double L[MS * MS], R[MS * MS];
  size_t i, j;
  int sg;
  gsl_permutation *p = gsl_permutation_alloc(n);
  gsl_matrix_view Lv = gsl_matrix_view_array(L, n, n);
  for (i = 0; i < n; i++)
    for (j = 0; j < n; j++) {
      L[i * n + j] = (i == j) - 0.5 * A[i * n + j];
      R[i * n + j] = (i == j) + 0.5 * A[i * n + j];
    }
  gsl_linalg_LU_decomp(&Lv.matrix, p, &sg);
  for (j = 0; j < n; j++) {
    double col[MS];
    gsl_vector_view cv = gsl_vector_view_array(col, n);
    for (i = 0; i < n; i++)
      col[i] = R[i * n + j];
    gsl_linalg_LU_svx(&Lv.matrix, p, &cv.vector);
    for (i = 0; i < n; i++)
      C[i * n + j] = col[i];
  }
  gsl_permutation_free(p);
}

/* }====================================================================== */

/* {==== identities for one group ========================================= */

typedef struct worst_t {
  double v[32];
} worst_t;

enum {
  W_EXPLOG, W_LOGEXP, W_INV, W_ASSOC, W_MEXP, W_MCAY, W_ICAY, W_AD, W_ADHOM, W_ADEXP,
  W_BRACKET, W_ADMAT, W_DEXP_R, W_DEXP_L, W_DEXPINV, W_DCAY_R, W_DCAY_L, W_DCAYINV,
  W_HATVEE, W_MATMUL, W_FROMMAT, W_ACT, W_GEN_L, W_GEN_R, W_ADEXPAD, W_NW
};

static const char *const wname[W_NW] = {
  "exp(log g) = g", "log(exp xi) = xi", "g g^-1 = e", "associativity",
  "exp = matrix exponential of hat", "cay = (I - A/2)^-1 (I + A/2)", "icay(cay xi) = xi",
  "Ad_g xi = vee(g hat(xi) g^-1)", "Ad_gh = Ad_g Ad_h", "exp(Ad_g xi) = g exp(xi) g^-1",
  "bracket = vee([hat a, hat b])", "ad_a b = [a, b]", "dexp (right) = finite differences",
  "dexp (left) = finite differences", "dexpinv dexp = I (both sides)",
  "dcay (right) = finite differences", "dcay (left) = finite differences",
  "dcayinv dcay = I (both sides)", "vee(hat xi) = xi", "matrix(g h) = matrix(g) matrix(h)",
  "from_matrix(matrix g) = g", "act = matrix representation", "left generators = FD",
  "right generators = FD", "Ad_exp(xi) = exp(ad_xi)"
};

static void upd(worst_t *w, int k, double v)
{
  if (isnan(v))
    v = INFINITY;
  if (v > w->v[k])
    w->v[k] = v;
}

/* right (side 0) or left (1) trivialized FD derivative of a chart */
static void chart_fd(const dm_lie_group *G, void (*chart)(const dm_lie_group *, const double *,
                                                          double *),
                     const double *xi, int side, double *M)
{
  double eps = 1e-5, xp[DIM], g0[NQ], gp[NQ], gm[NQ], d[NQ], a[DIM], b[DIM], ig[NQ];
  size_t i, j, n = G->dim;
  chart(G, xi, g0);
  dm_lie_inverse(G, g0, ig);
  for (j = 0; j < n; j++) {
    memcpy(xp, xi, n * sizeof *xp);
    xp[j] += eps;
    chart(G, xp, gp);
    xp[j] -= 2 * eps;
    chart(G, xp, gm);
    if (side == 0)
      dm_lie_compose(G, gp, ig, d);
    else
      dm_lie_compose(G, ig, gp, d);
    dm_lie_log(G, d, a);
    if (side == 0)
      dm_lie_compose(G, gm, ig, d);
    else
      dm_lie_compose(G, ig, gm, d);
    dm_lie_log(G, d, b);
    for (i = 0; i < n; i++)
      M[i * n + j] = (a[i] - b[i]) / (2 * eps);
  }
}

static void matvec(const double *M, const double *x, double *y, size_t n)
{
  size_t i, j;
  for (i = 0; i < n; i++) {
    y[i] = 0.0;
    for (j = 0; j < n; j++)
      y[i] += M[i * n + j] * x[j];
  }
}

static void one_sample(const dm_lie_group *G, int mode, worst_t *w)
{
  size_t n = G->dim, nq = G->nq, ms = G->msize, i, j, k;
  double xi[DIM], eta[DIM], zeta[DIM], g[NQ], h[NQ], f[NQ], gh[NQ], t1[NQ], t2[NQ];
  double A[MS * MS], B[MS * MS], C[MS * MS], M1[DIM * DIM], M2[DIM * DIM], M3[DIM * DIM];
  double v1[DIM], v2[DIM];
  rand_xi(G, mode, xi);
  rand_xi(G, GENERIC, eta);
  rand_xi(G, mode, zeta);
  dm_lie_exp(G, xi, g);
  rand_g(G, GENERIC, h);
  rand_g(G, GENERIC, f);

  /* exp / log */
  dm_lie_log(G, g, v1);
  dm_lie_exp(G, v1, t1);
  upd(w, W_EXPLOG, dm_lie_dist(G, g, t1));
  upd(w, W_LOGEXP, maxdiff(v1, xi, n) / fmax(1e-300, fmin(1.0, vnorm(xi, n))) *
                     (mode == NEAR0 ? 1.0 : 1e-0));
  /* inverse, associativity */
  dm_lie_inverse(G, g, t1);
  dm_lie_compose(G, g, t1, t2);
  dm_lie_log(G, t2, v1);
  upd(w, W_INV, vnorm(v1, n));
  dm_lie_compose(G, g, h, gh);
  dm_lie_compose(G, gh, f, t1);
  dm_lie_compose(G, h, f, t2);
  dm_lie_compose(G, g, t2, t2);
  upd(w, W_ASSOC, dm_lie_dist(G, t1, t2));
  /* exp and cay against the matrix representation */
  dm_lie_hat(G, xi, A, ms);
  mexp(A, B, ms);
  dm_lie_matrix(G, g, C, ms);
  upd(w, W_MEXP, maxdiff(B, C, ms * ms));
  dm_lie_hat(G, zeta, A, ms);
  mcay(A, B, ms);
  dm_lie_cay(G, zeta, t1);
  dm_lie_matrix(G, t1, C, ms);
  upd(w, W_MCAY, maxdiff(B, C, ms * ms));
  if (dm_lie_icay(G, t1, v1, NULL) == DM_OK)
    upd(w, W_ICAY, maxdiff(v1, zeta, n) / fmax(1.0, vnorm(zeta, n)));
  else
    upd(w, W_ICAY, INFINITY);
  /* Ad */
  dm_lie_Ad(G, h, M1, n);
  matvec(M1, eta, v1, n);
  dm_lie_hat(G, eta, A, ms);
  dm_lie_matrix(G, h, B, ms);
  mmul(B, A, C, ms);
  dm_lie_inverse(G, h, t1);
  dm_lie_matrix(G, t1, B, ms);
  mmul(C, B, C, ms);
  dm_lie_vee(G, C, ms, v2);
  upd(w, W_AD, maxdiff(v1, v2, n) / fmax(1.0, vnorm(v1, n)));
  dm_lie_compose(G, g, h, gh);
  dm_lie_Ad(G, gh, M1, n);
  dm_lie_Ad(G, g, M2, n);
  dm_lie_Ad(G, h, M3, n);
  mmul(M2, M3, M2, n);
  upd(w, W_ADHOM, maxdiff(M1, M2, n * n) / 10);
  dm_lie_Ad_apply(G, h, eta, v1);
  dm_lie_exp(G, v1, t1);
  dm_lie_exp(G, eta, t2);
  dm_lie_compose(G, h, t2, t2);
  dm_lie_inverse(G, h, gh);
  dm_lie_compose(G, t2, gh, t2);
  upd(w, W_ADEXP, dm_lie_dist(G, t1, t2));
  /* bracket and ad */
  dm_lie_bracket(G, xi, eta, v1);
  dm_lie_hat(G, xi, A, ms);
  dm_lie_hat(G, eta, B, ms);
  mmul(A, B, C, ms);
  mmul(B, A, B, ms);
  for (i = 0; i < ms * ms; i++)
    C[i] -= B[i];
  dm_lie_vee(G, C, ms, v2);
  upd(w, W_BRACKET, maxdiff(v1, v2, n) / fmax(1.0, vnorm(v1, n)));
  dm_lie_ad(G, xi, M1, n);
  matvec(M1, eta, v2, n);
  upd(w, W_ADMAT, maxdiff(v1, v2, n) / fmax(1.0, vnorm(v1, n)));
  /* Ad_exp(xi) = exp(ad_xi) */
  mexp(M1, M2, n);
  dm_lie_Ad(G, g, M3, n);
  upd(w, W_ADEXPAD, maxdiff(M2, M3, n * n) / 10);
  /* chart derivatives */
  dm_lie_dexp(G, xi, DM_LIE_RIGHT, M1, n);
  chart_fd(G, dm_lie_exp, xi, 0, M2);
  upd(w, W_DEXP_R, maxdiff(M1, M2, n * n));
  dm_lie_dexp(G, xi, DM_LIE_LEFT, M1, n);
  chart_fd(G, dm_lie_exp, xi, 1, M2);
  upd(w, W_DEXP_L, maxdiff(M1, M2, n * n));
  for (k = 0; k < 2; k++) {
    dm_lie_dexp(G, xi, (int)k, M1, n);
    dm_lie_dexpinv(G, xi, (int)k, M2, n);
    mmul(M1, M2, M3, n);
    for (i = 0; i < n; i++)
      M3[i * n + i] -= 1.0;
    upd(w, W_DEXPINV, maxdiff(M3, M3, n * n) + vnorm(M3, n * n));
  }
  dm_lie_dcay(G, zeta, DM_LIE_RIGHT, M1, n);
  chart_fd(G, dm_lie_cay, zeta, 0, M2);
  upd(w, W_DCAY_R, maxdiff(M1, M2, n * n));
  dm_lie_dcay(G, zeta, DM_LIE_LEFT, M1, n);
  chart_fd(G, dm_lie_cay, zeta, 1, M2);
  upd(w, W_DCAY_L, maxdiff(M1, M2, n * n));
  for (k = 0; k < 2; k++) {
    dm_lie_dcay(G, zeta, (int)k, M1, n);
    dm_lie_dcayinv(G, zeta, (int)k, M2, n);
    mmul(M1, M2, M3, n);
    for (i = 0; i < n; i++)
      M3[i * n + i] -= 1.0;
    upd(w, W_DCAYINV, vnorm(M3, n * n));
  }
  /* hat / vee, matrix, from_matrix, act */
  dm_lie_hat(G, xi, A, ms);
  dm_lie_vee(G, A, ms, v1);
  upd(w, W_HATVEE, maxdiff(v1, xi, n));
  dm_lie_compose(G, g, h, gh);
  dm_lie_matrix(G, gh, A, ms);
  dm_lie_matrix(G, g, B, ms);
  dm_lie_matrix(G, h, C, ms);
  mmul(B, C, B, ms);
  upd(w, W_MATMUL, maxdiff(A, B, ms * ms));
  if (dm_lie_from_matrix(G, A, ms, t1, NULL) == DM_OK)
    upd(w, W_FROMMAT, dm_lie_dist(G, t1, gh));
  else
    upd(w, W_FROMMAT, INFINITY);
  {
    double x[MS], y[MS], z[MS];
    size_t kd = G->kdim;
    for (i = 0; i < kd; i++)
      x[i] = urand(-2, 2);
    dm_lie_act(G, g, x, y);
    /* the acted-on space sits in the representation block by block: a
     * homogeneous block (R^n, SE(n)) maps x to M [x; 1], a rotation block
     * to M x */
    {
      const dm_lie_group *const *fac = G->kind == DM_LIE_PRODUCT
                                           ? (const dm_lie_group *const *)G->fac : &G;
      size_t nf = G->kind == DM_LIE_PRODUCT ? G->nfac : 1, fi, ko = 0, mo = 0;
      dm_lie_matrix(G, g, A, ms);
      for (fi = 0; fi < nf; fi++) {
        const dm_lie_group *F = fac[fi];
        int homog = F->kind == DM_LIE_RN || F->kind == DM_LIE_SE2 || F->kind == DM_LIE_SE3;
        for (i = 0; i < F->kdim; i++) {
          double s = homog ? A[(mo + i) * ms + mo + F->msize - 1] : 0.0;
          for (j = 0; j < F->kdim; j++)
            s += A[(mo + i) * ms + mo + j] * x[ko + j];
          z[ko + i] = s;
        }
        ko += F->kdim;
        mo += F->msize;
      }
    }
    upd(w, W_ACT, maxdiff(y, z, kd));
  }
  /* generators against FD of g exp(e e_k) and exp(e e_k) g (through the
   * matrix representation, where the storage derivative is linear) */
  for (k = 0; k < n; k++) {
    double e1[DIM] = {0}, gp[NQ], gm[NQ], dg[NQ], fd[NQ], eps = 1e-6;
    int side;
    for (side = 0; side < 2; side++) {
      e1[k] = eps;
      dm_lie_exp(G, e1, t1);
      if (side == DM_LIE_LEFT)
        dm_lie_compose(G, g, t1, gp);
      else
        dm_lie_compose(G, t1, g, gp);
      e1[k] = -eps;
      dm_lie_exp(G, e1, t1);
      if (side == DM_LIE_LEFT)
        dm_lie_compose(G, g, t1, gm);
      else
        dm_lie_compose(G, t1, g, gm);
      e1[k] = 0.0;
      for (i = 0; i < nq; i++)
        fd[i] = (gp[i] - gm[i]) / (2 * eps);
      dm_lie_generator(G, g, k, side, dg);
      upd(w, side == DM_LIE_LEFT ? W_GEN_L : W_GEN_R, maxdiff(fd, dg, nq));
    }
  }
}

static void test_group(const dm_lie_group *G, int nsamples)
{
  static const char *const mname[] = {"generic", "near 0", "near pi"};
  /* tolerances: identities 1e-12 relative (1e-11 where a near-pi log of a
   * product amplifies round-off), finite differences 1e-8 */
  static const double tol[W_NW] = {
    1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-11, 1e-12, 1e-12,
    1e-8, 1e-8, 1e-12, 1e-8, 1e-8, 1e-12, 1e-15, 1e-12, 1e-12, 1e-12, 1e-8, 1e-8, 1e-12};
  int mode, s, k;
  for (mode = 0; mode < 3; mode++) {
    worst_t w;
    memset(&w, 0, sizeof w);
    for (s = 0; s < nsamples; s++)
      one_sample(G, mode, &w);
    for (k = 0; k < W_NW; k++) {
      double t = tol[k];
      tap_ok(w.v[k] <= t, "%s %s: %s (worst %.2g <= %.0e)", G->name, mname[mode], wname[k],
             w.v[k], t);
    }
  }
}

/* }====================================================================== */

static void rot_z(double a, double *R)
{
  double w[3] = {0, 0, a};
  dm_so3_exp(w, R);
}

static void test_closed_forms(dm_lie_group *SO3, dm_lie_group *SE3)
{
  static const double Rz90[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
  double w[3] = {0, 0, M_PI / 2}, R[12], v[6], x[6], n[3];
  dm_err e;
  int i, k;
  /* exp(0,0,pi/2) = Rz(90), log back */
  dm_lie_exp(SO3, w, R);
  tap_ok(maxdiff(R, Rz90, 9) <= 1e-15, "SO3 exp(0,0,pi/2) = Rz(90) (%.2g)",
         maxdiff(R, Rz90, 9));
  dm_lie_log(SO3, Rz90, v);
  tap_ok(maxdiff(v, w, 3) <= 1e-15, "SO3 log(Rz(90)) = (0,0,pi/2)");
  /* near-pi logarithms */
  {
    static const double D[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
    static const double P[9] = {0, -1, 0, -1, 0, 0, 0, 0, -1};
    double r = M_SQRT1_2;
    dm_lie_log(SO3, D, v);
    tap_ok(fabs(vnorm(v, 3) - M_PI) <= 1e-15 && fabs(fabs(v[0]) - M_PI) <= 1e-15,
           "SO3 log diag(1,-1,-1): |w| = pi along e1 (%g %g %g)", v[0], v[1], v[2]);
    dm_lie_exp(SO3, v, R);
    tap_ok(maxdiff(R, D, 9) <= 1e-15, "SO3 exp(log diag(1,-1,-1)) = diag(1,-1,-1)");
    dm_lie_log(SO3, P, v);
    tap_ok(fabs(vnorm(v, 3) - M_PI) <= 1e-15 &&
               fabs(fabs(v[0] / M_PI) - r) <= 1e-15 && fabs(v[0] + v[1]) <= 1e-15 &&
               v[2] == 0.0,
           "SO3 log [[0,-1,0],[-1,0,0],[0,0,-1]]: |w| = pi along (1,-1,0)/sqrt2");
    dm_lie_exp(SO3, v, R);
    tap_ok(maxdiff(R, P, 9) <= 1e-15, "SO3 exp(log) of the Pinocchio case");
  }
  {
    double worst = 0.0, worstn = 0.0, a;
    for (i = 0; i < 200; i++) {
      double u[3], Q[9], C[9], Ct[9];
      rand_unit3(n);
      /* (pi - 1e-9) n and exact pi rotations conjugated by random rotations */
      for (k = 0; k < 3; k++)
        u[k] = (M_PI - 1e-9) * n[k];
      dm_so3_exp(u, R);
      dm_lie_log(SO3, R, v);
      worstn = fmax(worstn, maxdiff(v, u, 3));
      dm_lie_exp(SO3, v, Q);
      worst = fmax(worst, maxdiff(Q, R, 9));
      rand_g(SO3, GENERIC, C);
      dm_lie_inverse(SO3, C, Ct);
      {
        static const double X[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
        dm_m3_mul(C, X, Q);
        dm_m3_mul(Q, Ct, Q);
      }
      dm_lie_log(SO3, Q, v);
      a = vnorm(v, 3);
      worstn = fmax(worstn, fabs(a - M_PI));
      dm_lie_exp(SO3, v, R);
      worst = fmax(worst, maxdiff(Q, R, 9));
    }
    tap_ok(worst <= 4e-15, "SO3 exp(log R) = R at pi - 1e-9 and at pi (conjugated): %.2g",
           worst);
    tap_ok(worstn <= 1e-14, "SO3 log at pi - 1e-9: the vector itself (%.2g)", worstn);
    w[0] = 0, w[1] = 0, w[2] = 1e-5;
    dm_lie_exp(SO3, w, R);
    dm_lie_log(SO3, R, v);
    tap_ok(maxdiff(v, w, 3) <= 1e-21, "SO3 log(exp(0,0,1e-5)) (%.2g)", maxdiff(v, w, 3));
  }
  /* tr R = 1 + 2 cos(phi) */
  {
    double worst = 0.0;
    for (i = 0; i < 100; i++) {
      rand_g(SO3, GENERIC, R);
      dm_lie_log(SO3, R, v);
      worst = fmax(worst, fabs(R[0] + R[4] + R[8] - 1.0 - 2.0 * cos(vnorm(v, 3))));
    }
    tap_ok(worst <= 1e-14, "SO3 tr R = 1 + 2 cos|log R| (%.2g)", worst);
  }
  /* SE(3) screw motion */
  {
    double xi[6] = {0, 0, M_PI / 2, 1, 0, 0}, g[12], want[3] = {2 / M_PI, 2 / M_PI, 0};
    dm_lie_exp(SE3, xi, g);
    tap_ok(maxdiff(g, Rz90, 9) <= 1e-15 && maxdiff(g + 9, want, 3) <= 1e-15,
           "SE3 exp((0,0,pi/2),(1,0,0)): Rz(90), p = (2/pi, 2/pi, 0)");
    dm_lie_log(SE3, g, x);
    tap_ok(maxdiff(x, xi, 6) <= 1e-15, "SE3 log of the screw motion");
  }
  /* V^-1 V = I at theta in {1e-8, 0.3, pi - 1e-6, pi} */
  {
    static const double th[4] = {1e-8, 0.3, M_PI - 1e-6, M_PI};
    double V[9], Vi[9], P[9], worst = 0.0;
    for (i = 0; i < 4; i++) {
      rand_unit3(n);
      for (k = 0; k < 3; k++)
        w[k] = th[i] * n[k];
      dm_lie_dexp(SO3, w, DM_LIE_RIGHT, V, 3);
      dm_lie_dexpinv(SO3, w, DM_LIE_RIGHT, Vi, 3);
      dm_m3_mul(Vi, V, P);
      P[0] -= 1, P[4] -= 1, P[8] -= 1;
      worst = fmax(worst, vnorm(P, 9));
    }
    tap_ok(worst <= 1e-14, "SO3 V^-1 V = I at 1e-8, 0.3, pi - 1e-6, pi (%.2g)", worst);
  }
  /* Cayley */
  {
    double c[3] = {0, 0, 2}, ci[3];
    dm_lie_cay(SO3, c, R);
    tap_ok(maxdiff(R, Rz90, 9) <= 1e-16, "SO3 cay(0,0,2) = Rz(90)");
    tap_ok(dm_lie_icay(SO3, R, ci, NULL) == DM_OK && maxdiff(ci, c, 3) <= 1e-15,
           "SO3 icay(cay(0,0,2)) = (0,0,2)");
  }
  /* SE(3): t = (1,1,1), R = Rz(pi/4) Ry(pi/2) Rx(pi) maps (1,1,1) to
   * (1, 1 - sqrt2, 0) */
  {
    double g[12], Ry[9], Rx[9], y[3], one[3] = {1, 1, 1};
    double wy[3] = {0, M_PI / 2, 0}, wx[3] = {M_PI, 0, 0};
    rot_z(M_PI / 4, g);
    dm_so3_exp(wy, Ry);
    dm_so3_exp(wx, Rx);
    dm_m3_mul(g, Ry, g);
    dm_m3_mul(g, Rx, g);
    g[9] = g[10] = g[11] = 1.0;
    dm_lie_act(SE3, g, one, y);
    tap_ok(fabs(y[0] - 1) <= 1e-15 && fabs(y[1] - (1 - M_SQRT2)) <= 1e-15 &&
               fabs(y[2]) <= 1e-15,
           "SE3 (Rz(pi/4)Ry(pi/2)Rx(pi), (1,1,1)) . (1,1,1) = (1, 1 - sqrt2, 0): (%.17g, %.17g, "
           "%.3g)", y[0], y[1], y[2]);
  }
  (void)e;
}

/* the series coefficients agree with the closed forms at their thresholds */
static void test_series_thresholds(void)
{
  struct { const char *name; double (*f)(double); double t; } c[] = {
    {"sinc", dm_lie_sinc, 1e-2}, {"cosc", dm_lie_cosc, 1e-2},
    {"sinc3", dm_lie_sinc3, 4.0}, {"dexpinv_coef", dm_lie_dexpinv_coef, 4.0},
    {"coefE", dm_lie_coefE, 4.0}, {"coefG", dm_lie_coefG, 4.0},
    {"invsinc", dm_lie_invsinc, 1e-2}};
  size_t i;
  for (i = 0; i < sizeof c / sizeof c[0]; i++) {
    double lo = c[i].f(nextafter(c[i].t, 0)), hi = c[i].f(c[i].t);
    tap_ok(fabs(lo - hi) <= 4e-16 * fabs(hi), "%s continuous at its series threshold t = %g "
           "(jump %.2g relative)", c[i].name, c[i].t, fabs(lo - hi) / fabs(hi));
  }
  tap_ok(dm_lie_sinc(0) == 1.0 && dm_lie_cosc(0) == 0.5 && dm_lie_sinc3(0) == 1.0 / 6 &&
             dm_lie_dexpinv_coef(0) == 1.0 / 12 && fabs(dm_lie_dexpinv_coef(M_PI * M_PI) -
                                                        1 / (M_PI * M_PI)) <= 1e-16,
         "coefficients at 0 and (1 - (t/2)cot(t/2))/t^2 = 1/pi^2 at pi");
}

/* 1e7 compositions of rotations: plain products drift from orthogonality
 * by ~1e-17 per product (1e-10 after 1e7 with a cycle of 64 factors);
 * normalizing every 100 products (one Bjorck step, ~2 products' cost)
 * bounds it by 100 such drifts, for ever. */
static void test_long_products(dm_lie_group *SO3)
{
  double Rs[64][9], R[9], Q[9], worst = 0.0, worstn = 0.0;
  long k;
  int i, ok, okn;
  for (i = 0; i < 64; i++)
    rand_g(SO3, GENERIC, Rs[i]);
  dm_lie_identity(SO3, R);
  dm_lie_identity(SO3, Q);
  for (k = 0; k < 10000000; k++) {
    dm_lie_compose(SO3, R, Rs[k & 63], R);
    dm_lie_compose(SO3, Q, Rs[k & 63], Q);
    if (k % 100 == 99) {
      worst = fmax(worst, dm_lie_orth_defect3(R, NULL));
      worstn = fmax(worstn, dm_lie_orth_defect3(Q, NULL));
      dm_lie_normalize(SO3, Q);
    }
  }
  worst = fmax(worst, dm_lie_orth_defect3(R, &ok));
  worstn = fmax(worstn, dm_lie_orth_defect3(Q, &okn));
  tap_ok(worstn <= 1e-14 && okn, "SO3: 1e7 compositions normalized every 100: max |R^T R - I| "
         "= %.2g", worstn);
  tap_ok(worst <= 1e-9 && ok, "SO3: 1e7 plain compositions drift to %.2g (<= 1e-9)", worst);
  tap_ok(dm_lie_dist(SO3, R, Q) <= 1e-8, "the two products agree to %.2g",
         dm_lie_dist(SO3, R, Q));
  dm_lie_normalize(SO3, R);
  tap_ok(dm_lie_orth_defect3(R, NULL) <= 4e-16, "SO3 normalize after them: %.2g",
         dm_lie_orth_defect3(R, NULL));
}

static void test_normalize(dm_lie_group *SO3, dm_lie_group *SE3)
{
  double R[12], Q[9], S[9], wo = 0.0, sym = 0.0;
  int i, k, ok;
  for (i = 0; i < 50; i++) {
    rand_g(SE3, GENERIC, R);
    for (k = 0; k < 9; k++)
      R[k] += urand(-1e-3, 1e-3);
    memcpy(Q, R, sizeof Q);
    dm_lie_normalize(SE3, R);
    wo = fmax(wo, dm_lie_orth_defect3(R, &ok));
    /* the polar factor: R^T Q symmetric */
    dm_m3_tmul(R, Q, S);
    sym = fmax(sym, fmax(fabs(S[1] - S[3]), fmax(fabs(S[2] - S[6]), fabs(S[5] - S[7]))));
  }
  tap_ok(wo <= 5e-16 && sym <= 1e-15, "SE3 normalize: orthogonal (%.2g), polar factor "
         "(R^T A symmetric: %.2g)", wo, sym);
  {
    double X[9] = {1, 0, 0, 0, 1, 0, 0, 0, -1};
    dm_lie_normalize(SO3, X);
    dm_lie_orth_defect3(X, &ok);
    tap_ok(ok, "SO3 normalize of a reflection gives a rotation");
  }
}

static void test_errors(dm_lie_group *SO3, dm_lie_group *SE2, dm_lie_group *SE3)
{
  double R[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1}, v[6], M[16], g[12];
  dm_err e;
  dm_err_clear(&e);
  tap_ok(dm_lie_icay(SO3, R, v, &e) == DM_EDOM &&
             strcmp(e.msg, "the SO3 element is a rotation by pi: the inverse Cayley map is "
                    "undefined there (its cut locus)") == 0,
         "icay at pi: DM_EDOM, message '%s'", e.msg);
  {
    double s[3] = {M_PI, 1, 2};
    tap_ok(dm_lie_icay(SE2, s, v, &e) == DM_EDOM, "SE2 icay at angle pi: DM_EDOM");
  }
  R[4] = 1.0001;
  tap_ok(dm_lie_check(SO3, R, 1e-10, &e) == DM_EDOM &&
             strcmp(e.msg, "SO3 element: max |R^T R - I| = 0.0002 (> tol 1e-10): not a "
                    "rotation") == 0,
         "check: not a rotation, '%s'", e.msg);
  R[4] = 1.0;
  tap_ok(dm_lie_check(SO3, R, 1e-10, &e) == DM_EDOM &&
             strcmp(e.msg, "SO3 element: det R < 0: a reflection, not a rotation") == 0,
         "check: reflection, '%s'", e.msg);
  R[4] = NAN;
  tap_ok(dm_lie_check(SO3, R, 1e-10, &e) == DM_EDOM &&
             strcmp(e.msg, "SO3 element: entry 5 is not finite") == 0,
         "check: NaN, '%s'", e.msg);
  dm_lie_identity(SE3, g);
  tap_ok(dm_lie_check(SE3, g, 1e-14, &e) == DM_OK, "check: identity of SE3 passes");
  dm_lie_matrix(SE3, g, M, 4);
  M[13] = 0.5;
  tap_ok(dm_lie_from_matrix(SE3, M, 4, g, &e) == DM_EDOM &&
             strstr(e.msg, "SE3 matrix: the fixed entries") == e.msg,
         "from_matrix: bad homogeneous row, '%s'", e.msg);
  {
    const dm_lie_group *none[1];
    tap_ok(dm_lie_product(0, none, &e) == NULL && e.status == DM_EINVAL &&
               strcmp(e.msg, "product: needs at least one factor") == 0,
           "product of nothing: '%s'", e.msg);
    tap_ok(dm_lie_rn(0, &e) == NULL && strcmp(e.msg, "R^n: dimension n = 0 out of range "
                                              "1..64") == 0, "R^0: '%s'", e.msg);
  }
}

static void test_product(dm_lie_group *SE3, dm_lie_group *T3)
{
  const dm_lie_group *f[2] = {SE3, T3};
  dm_lie_group *P = dm_lie_product(2, f, NULL), *PP;
  double xi[9], g[15], h[15], gh[15], a[12], b[12], v[9], M[81], A6[36], A3[9];
  size_t i, j;
  int ok = 1;
  tap_ok(P && P->nq == 15 && P->dim == 9 && P->msize == 10 && strcmp(P->name, "SE3xT3") == 0,
         "SE3 x T3: sizes and name");
  rand_xi(P, GENERIC, xi);
  dm_lie_exp(P, xi, g);
  dm_lie_exp(SE3, xi, a);
  dm_lie_exp(T3, xi + 6, b);
  tap_ok(maxdiff(g, a, 12) == 0 && maxdiff(g + 12, b, 3) == 0, "product exp factor-wise");
  rand_g(P, GENERIC, h);
  dm_lie_compose(P, g, h, gh);
  dm_lie_compose(SE3, g, h, a);
  dm_lie_compose(T3, g + 12, h + 12, b);
  tap_ok(maxdiff(gh, a, 12) == 0 && maxdiff(gh + 12, b, 3) == 0, "product compose factor-wise");
  dm_lie_log(P, gh, v);
  dm_lie_log(SE3, a, xi);
  dm_lie_log(T3, b, xi + 6);
  tap_ok(maxdiff(v, xi, 9) == 0, "product log factor-wise");
  dm_lie_Ad(P, g, M, 9);
  dm_lie_Ad(SE3, g, A6, 6);
  dm_lie_Ad(T3, g + 12, A3, 3);
  for (i = 0; i < 9; i++)
    for (j = 0; j < 9; j++) {
      double want = i < 6 && j < 6 ? A6[i * 6 + j] : i >= 6 && j >= 6 ? A3[(i - 6) * 3 + j - 6]
                                                                      : 0.0;
      ok = ok && M[i * 9 + j] == want;
    }
  tap_ok(ok, "product Ad block diagonal");
  {
    const dm_lie_group *f2[2] = {P, SE3};
    PP = dm_lie_product(2, f2, NULL);
    tap_ok(PP && PP->nfac == 3 && strcmp(PP->name, "SE3xT3xSE3") == 0,
           "nested products are flattened");
    dm_lie_group_free(PP);
  }
  dm_lie_group_free(P);
}

static void test_angles(dm_lie_group *SO2, dm_lie_group *SE2)
{
  double a = 3.0, b = 2.5, c, v, g[3] = {3.5, 1, 2}, x[3];
  dm_lie_compose(SO2, &a, &b, &c);
  tap_ok(c == 5.5, "SO2 composition adds unwrapped angles");
  dm_lie_log(SO2, &c, &v);
  tap_ok(fabs(v - (5.5 - 2 * M_PI)) <= 1e-15, "SO2 log: principal value");
  c = M_PI;
  dm_lie_log(SO2, &c, &v);
  tap_ok(v == M_PI, "SO2 log(pi) = pi (interval (-pi, pi])");
  c = -M_PI;
  dm_lie_log(SO2, &c, &v);
  tap_ok(v == M_PI, "SO2 log(-pi) = pi");
  dm_lie_log(SE2, g, x);
  dm_lie_exp(SE2, x, x);
  tap_ok(fabs(x[0] - (3.5 - 2 * M_PI)) <= 1e-15 && dm_lie_dist(SE2, x, g) <= 1e-15,
         "SE2 exp(log g) = g mod 2 pi");
}

static void test_names(void)
{
  static const char *const names[] = {"SO3", "SE3", "SO2", "SE2", "R4", "T2", "SE3xT3xR1"};
  char buf[256];
  size_t i;
  dm_err e;
  for (i = 0; i < sizeof names / sizeof names[0]; i++) {
    dm_lie_group *G = dm_lie_group_parse(names[i], &e);
    tap_ok(G != NULL && strcmp(G->name, names[i]) == 0, "parse '%s'", names[i]);
    dm_lie_group_free(G);
  }
  tap_ok(dm_lie_group_parse("SO3xSO4", &e) == NULL &&
             strcmp(e.msg, "Lie group name: cannot read 'SO4' (expected SO2, SO3, SE2, SE3, R<n> "
                    "or T<n>)") == 0, "parse error: '%s'", e.msg);
  tap_ok(dm_lie_group_parse("R0", &e) == NULL, "parse R0 fails");
  {
    dm_lie_group *G = dm_lie_group_parse("SO3xR2", NULL);
    double g[11] = {0, -1, 0, 1, 0, 0, 0, 0, 1, 2.385, -1};
    dm_lie_describe(G, g, buf, sizeof buf);
    tap_ok(strcmp(buf, "rotation 1.5708 about (0, 0, 1) [0 -1 0; 1 0 0; 0 0 1] | (2.385, -1)") == 0,
           "describe: '%s'", buf);
    tap_ok(dm_lie_describe(G, g, buf, 10) > 10 && strlen(buf) == 9, "describe truncates");
    dm_lie_group_free(G);
  }
}

int main(void)
{
  dm_lie_group *R3, *SO2, *T3, *SO3, *SE2, *SE3, *P1, *P2, *R2;
  const dm_lie_group *f1[2], *f2[2];
  dm_gsl_init();
  rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, 2385);
  R3 = dm_lie_rn(3, NULL);
  R2 = dm_lie_rn(2, NULL);
  SO2 = dm_lie_so2(NULL);
  T3 = dm_lie_torus(3, NULL);
  SO3 = dm_lie_so3(NULL);
  SE2 = dm_lie_se2(NULL);
  SE3 = dm_lie_se3(NULL);
  f1[0] = SE3, f1[1] = T3;
  f2[0] = SO3, f2[1] = R2;
  P1 = dm_lie_product(2, f1, NULL);
  P2 = dm_lie_product(2, f2, NULL);

  test_group(R3, 20);
  test_group(SO2, 20);
  test_group(T3, 20);
  test_group(SO3, 100);
  test_group(SE2, 100);
  test_group(SE3, 100);
  test_group(P1, 30);
  test_group(P2, 30);
  test_closed_forms(SO3, SE3);
  test_series_thresholds();
  test_long_products(SO3);
  test_normalize(SO3, SE3);
  test_errors(SO3, SE2, SE3);
  test_product(SE3, T3);
  test_angles(SO2, SE2);
  test_names();

  dm_lie_group_free(R3);
  dm_lie_group_free(R2);
  dm_lie_group_free(SO2);
  dm_lie_group_free(T3);
  dm_lie_group_free(SO3);
  dm_lie_group_free(SE2);
  dm_lie_group_free(SE3);
  dm_lie_group_free(P1);
  dm_lie_group_free(P2);
  dm_lie_group_free(NULL);
  gsl_rng_free(rng);
  return tap_done();
}
