/* radapt.c -- the r-adaptive multisymplectic integrator of
 * l = u_t^2/2 - c^2 u_x^2/2 - V(u) on moving nodes X_i(t) with held ends
 * (doc/beyond-fixed-steps.md §7): the space-time cells of msym.c become
 * quadrilaterals with straight sides, the field's discrete Euler-Lagrange
 * equations are those of the time-dependent discrete Lagrangian with the
 * mesh as a given control, and the mesh of each new level is fixed by the
 * discrete arc-length equidistribution of that level.  Both are solved
 * together by Newton with the banded LU of GSL.  See fields.h. */
#include <config.h>
#include "fields/fields.h"
#include "core/newton.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#define LB 3               /* sub- and super-diagonals of the step Jacobian */
#define UB 3

struct dm_radapt {
  size_t N, nn, n;           /* cells, nodes (N + 1), unknowns 2 (N - 1) */
  double x0, length, dt, c, alpha;
  dm_potential V;
  gsl_matrix *AB;            /* n x (2 LB + UB + 1), GSL's band storage */
  gsl_vector_uint *piv;
  double *rhs, *sol, *cu, *cp, *cX, *ell, *S, *Xn;
  double *lastX, *lastu, *dX, *du; /* the last step's output and change (predictor) */
  int have_last;
  int kin;                   /* DM_RADAPT_CENTRE or DM_RADAPT_EDGES */
};

static const double GX[4] = {-1, 1, -1, 1};   /* BL BR TL TR */

static int pot(const dm_radapt *R, double u, double *V, double *dV, double *d2V)
{
  if (R->V.eval == NULL) {
    if (V) *V = 0;
    if (dV) *dV = 0;
    if (d2V) *d2V = 0;
    return 0;
  }
  return R->V.eval(R->V.data, u, V, dV, d2V);
}

/* A cell with corner values u[4] at corner positions X[4] (BL BR TL TR):
 * with hb = mean width, u_x = u_xi/hb the slope at the centre, and the
 * time derivatives at fixed x sampled at points E with weights omega_E,
 * u_t(E) = (sum_a T_Ea u_a - (sum_a T_Ea X_a) u_x)/dt,
 * L_d = hb dt [sum_E omega_E u_t(E)^2/2 - c^2 u_x^2/2 - V(mean u)].
 * The one-point rule samples the centre (T = GT/2, msym.c's cell on a
 * still mesh); DM_RADAPT_EDGES samples the two vertical edges (weights 1/2).
 * D[a] = dL_d/du_a, Hu[4a+b] = d2L_d/du_a du_b, HX[4a+b] = d2L_d/du_a dX_b
 * (each may be NULL). */
static int mcell(const dm_radapt *R, const double *u, const double *X, double *D, double *Hu,
                 double *HX)
{
  static const double TC[1][4] = {{-0.5, -0.5, 0.5, 0.5}};
  static const double TE[2][4] = {{-1, 0, 1, 0}, {0, -1, 0, 1}};
  const double (*T)[4] = R->kin == DM_RADAPT_CENTRE ? TC : TE;
  int nE = R->kin == DM_RADAPT_CENTRE ? 1 : 2;
  double om = 1.0 / nE, dt = R->dt, c2 = R->c * R->c;
  double hb = 0.5 * (X[1] - X[0] + X[3] - X[2]);
  double z = 0.5 * (u[1] + u[3] - u[0] - u[2]) / hb;
  double ub = 0.25 * (u[0] + u[1] + u[2] + u[3]), A = hb * dt, dV = 0, d2V = 0;
  double za[4], B[4], w[2], xE[2], wa[2][4];
  int rc = pot(R, ub, NULL, &dV, Hu ? &d2V : NULL);
  if (rc != 0 || !isfinite(dV) || !isfinite(d2V))
    return rc != 0 ? rc : 1;
  for (int a = 0; a < 4; a++)
    za[a] = GX[a] / (2 * hb);
  for (int E = 0; E < nE; E++) {
    double ut = 0;
    xE[E] = 0;
    for (int a = 0; a < 4; a++) {
      ut += T[E][a] * u[a];
      xE[E] += T[E][a] * X[a];
    }
    w[E] = (ut - xE[E] * z) / dt;
    for (int a = 0; a < 4; a++)
      wa[E][a] = (T[E][a] - xE[E] * za[a]) / dt;
  }
  for (int a = 0; a < 4; a++) {
    B[a] = -c2 * z * za[a] - 0.25 * dV;
    for (int E = 0; E < nE; E++)
      B[a] += om * w[E] * wa[E][a];
    if (D)
      D[a] = A * B[a];
  }
  for (int a = 0; a < 4; a++)
    for (int b = 0; b < 4; b++) {
      if (Hu) {
        double k = 0;
        for (int E = 0; E < nE; E++)
          k += om * wa[E][b] * wa[E][a];
        Hu[4 * a + b] = A * (k - c2 * za[b] * za[a] - d2V / 16);
      }
      if (HX) {
        double dA = 0.5 * dt * GX[b], dz = -z * GX[b] / (2 * hb);
        double dza = -za[a] * GX[b] / (2 * hb), k = 0;
        for (int E = 0; E < nE; E++) {
          double dw = (-T[E][b] * z - xE[E] * dz) / dt, dwa = (-T[E][b] * za[a] - xE[E] * dza) / dt;
          k += om * (dw * wa[E][a] + w[E] * dwa);
        }
        HX[4 * a + b] = dA * B[a] + A * (k - c2 * (dz * za[a] + z * dza));
      }
    }
  return 0;
}

/* the corner values of cell k of the slab (level 0 below, 1 above) */
static void corners(const double *a0, const double *a1, size_t k, double *c)
{
  c[0] = a0[k];
  c[1] = a0[k + 1];
  c[2] = a1[k];
  c[3] = a1[k + 1];
}

/* arc length of cell k: sqrt(h^2 + alpha du^2) */
static inline double arc(const dm_radapt *R, const double *X, const double *u, size_t k)
{
  double h = X[k + 1] - X[k], d = u[k + 1] - u[k];
  return sqrt(h * h + R->alpha * d * d);
}

int dm_radapt_alloc(size_t N, double x0, double length, double c, double dt, double alpha,
                    int rule, const dm_potential *V, dm_radapt **out, dm_err *e)
{
  dm_radapt *R;
  *out = NULL;
  if (N < 3 || N > 10000000)
    return dm_err_set(e, DM_EINVAL, "r-adaptive: need 3 <= N cells, got %zu", N);
  if (!(length > 0) || !isfinite(length) || !isfinite(x0) || !isfinite(c) || !isfinite(dt)
      || dt == 0.0)
    return dm_err_set(e, DM_EINVAL, "r-adaptive: finite x0, length > 0, finite c and dt != 0 "
                      "needed");
  if (!(alpha >= 0) || !isfinite(alpha))
    return dm_err_set(e, DM_EINVAL, "r-adaptive: alpha must be a finite number >= 0, got %g",
                      alpha);
  if (rule != DM_RADAPT_CENTRE && rule != DM_RADAPT_EDGES)
    return dm_err_set(e, DM_EINVAL, "r-adaptive: unknown kinetic rule %d", rule);
  if ((R = calloc(1, sizeof *R)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "r-adaptive: out of memory");
  R->N = N;
  R->nn = N + 1;
  R->n = 2 * (N - 1);
  R->x0 = x0;
  R->length = length;
  R->dt = dt;
  R->c = c;
  R->alpha = alpha;
  R->kin = rule;
  if (V != NULL)
    R->V = *V;
  R->AB = gsl_matrix_alloc(R->n, 2 * LB + UB + 1);
  R->piv = gsl_vector_uint_alloc(R->n);
  R->rhs = malloc((2 * R->n + 10 * R->nn) * sizeof(double));
  if (R->AB == NULL || R->piv == NULL || R->rhs == NULL) {
    dm_radapt_free(R);
    return dm_err_set(e, DM_ENOMEM, "r-adaptive: out of memory");
  }
  R->sol = R->rhs + R->n;
  R->cu = R->sol + R->n;
  R->cp = R->cu + R->nn;
  R->cX = R->cp + R->nn;
  R->ell = R->cX + R->nn;
  R->S = R->ell + R->nn;
  R->Xn = R->S + R->nn;
  R->lastX = R->Xn + R->nn;
  R->lastu = R->lastX + R->nn;
  R->dX = R->lastu + R->nn;
  R->du = R->dX + R->nn;
  *out = R;
  return DM_OK;
}

void dm_radapt_free(dm_radapt *R)
{
  if (R == NULL)
    return;
  gsl_matrix_free(R->AB);
  gsl_vector_uint_free(R->piv);
  free(R->rhs);
  free(R);
}

size_t dm_radapt_nodes(const dm_radapt *R) { return R->nn; }
double dm_radapt_dt(const dm_radapt *R) { return R->dt; }
double dm_radapt_alpha(const dm_radapt *R) { return R->alpha; }

double dm_radapt_residual(const dm_radapt *R, const double *X, const double *u)
{
  double tot = 0, worst = 0;
  for (size_t k = 0; k < R->N; k++)
    tot += arc(R, X, u, k);
  for (size_t i = 1; i < R->N; i++)
    worst = fmax(worst, fabs(arc(R, X, u, i) - arc(R, X, u, i - 1)));
  return worst / (tot / (double)R->N);
}

/* The last digits of an initial mesh: Newton on the equidistribution for X
 * with the nodal values held (they move by the mesh's change times u_x,
 * at round-off), tridiagonal (GSL). */
static int polish(dm_radapt *R, double *X, const double *u, dm_err *e)
{
  size_t N = R->N, m = N - 1, i;
  double *dg = R->Xn, *lo = R->S, *up = R->dX, *rhs = R->rhs, *sol = R->sol;
  for (int it = 0; it < 4; it++) {
    for (size_t k = 0; k < N; k++)
      R->ell[k] = arc(R, X, u, k);
    for (i = 1; i < N; i++) {
      double gl = (X[i] - X[i - 1]) / R->ell[i - 1], gr = (X[i + 1] - X[i]) / R->ell[i];
      rhs[i - 1] = R->ell[i] - R->ell[i - 1];
      dg[i - 1] = -gr - gl;
      if (i > 1)
        lo[i - 2] = gl;
      if (i + 1 < N)
        up[i - 1] = gr;
    }
    gsl_vector_view d = gsl_vector_view_array(dg, m), a = gsl_vector_view_array(up, m - 1),
                    b = gsl_vector_view_array(lo, m - 1), r = gsl_vector_view_array(rhs, m),
                    x = gsl_vector_view_array(sol, m);
    if (gsl_linalg_solve_tridiag(&d.vector, &a.vector, &b.vector, &r.vector, &x.vector)
        != GSL_SUCCESS)
      return dm_err_set(e, DM_ESINGULAR, "r-adaptive: singular mesh equations");
    for (i = 1; i < N; i++)
      X[i] -= sol[i - 1];
  }
  return DM_OK;
}

int dm_radapt_init(dm_radapt *R, dm_fn1 u0, void *data, double *X, double *u, dm_err *e)
{
  size_t N = R->N, i, k;
  double d = HUGE_VAL, dprev = HUGE_VAL;
  int it;
  R->have_last = 0;
  for (i = 0; i <= N; i++)
    X[i] = R->x0 + R->length * (double)i / (double)N;
  /* de Boor's iteration: place the nodes at equal arc length of the
   * piecewise-linear interpolant on the current nodes */
  for (it = 0; it < 2000; it++) {
    for (i = 0; i <= N; i++) {
      int rc = u0(data, X[i], &u[i]);
      if (rc != 0 || !isfinite(u[i]))
        return dm_err_set(e, DM_EDOM, "r-adaptive: the initial field fails at x = %g", X[i]);
    }
    if (d <= 4 * DBL_EPSILON * R->length || (it > 50 && d >= dprev && d <= 1e-12 * R->length))
      return polish(R, X, u, e);
    dprev = d;
    R->S[0] = 0;
    for (k = 0; k < N; k++)
      R->S[k + 1] = R->S[k] + arc(R, X, u, k);
    R->Xn[0] = X[0];
    R->Xn[N] = X[N];
    for (i = 1, k = 0; i < N; i++) {
      double T = R->S[N] * (double)i / (double)N;
      while (k + 1 < N && R->S[k + 1] < T)
        k++;
      R->Xn[i] = X[k] + (T - R->S[k]) / (R->S[k + 1] - R->S[k]) * (X[k + 1] - X[k]);
    }
    d = 0;
    for (i = 1; i < N; i++) {
      double x = 0.5 * (X[i] + R->Xn[i]);        /* damped: the plain iteration can oscillate */
      d = fmax(d, fabs(x - X[i]));
      X[i] = x;
    }
  }
  return dm_err_set(e, DM_ENOCONV, "r-adaptive: the initial mesh did not equidistribute "
                    "(last change %.3g)", d);
}

void dm_radapt_momentum(const dm_radapt *R, const double *X, const double *v, double *p)
{
  p[0] = p[R->N] = 0.0;
  for (size_t i = 1; i < R->N; i++)
    p[i] = 0.5 * (X[i + 1] - X[i - 1]) * v[i];
}

/* A(row, col) += v in GSL's band storage: AB(col, LB + UB + row - col) */
static inline void band_add(gsl_matrix *AB, size_t row, size_t col, double v)
{
  double *p = gsl_matrix_ptr(AB, col, LB + UB + row - col);
  *p += v;
}

int dm_radapt_step(dm_radapt *R, const double *X0_in, const double *u0_in, const double *p0_in,
                   double *X1, double *u1, double *p1, dm_err *e)
{
  size_t N = R->N, nn = R->nn, n = R->n, i, k;
  double d = HUGE_VAL, *u0 = R->cu, *p0 = R->cp, *X0 = R->cX;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  int it;
  memmove(u0, u0_in, nn * sizeof *u0);
  memmove(p0, p0_in, nn * sizeof *p0);
  memmove(X0, X0_in, nn * sizeof *X0);
  /* the first guess: continue the last step's node motion when this step
   * starts where it ended, else still nodes moving with the momentum */
  int cont = R->have_last && memcmp(X0, R->lastX, nn * sizeof *X0) == 0
             && memcmp(u0, R->lastu, nn * sizeof *u0) == 0;
  for (i = 0; i < nn; i++) {
    if (cont) {
      X1[i] = X0[i] + R->dX[i];
      u1[i] = u0[i] + R->du[i];
    } else {
      X1[i] = X0[i];
      u1[i] = (i > 0 && i < N) ? u0[i] + R->dt * p0[i] / (0.5 * (X0[i + 1] - X0[i - 1])) : u0[i];
    }
  }
  for (it = 0; it < 60; it++) {
    double xs = 1, cu[4], cX[4], D[4], Hu[16], HX[16];
    gsl_matrix_set_zero(R->AB);
    for (i = 0; i < n; i++)
      R->rhs[i] = 0;
    for (i = 1; i < N; i++)
      R->rhs[2 * (i - 1)] = p0[i];
    /* the field equations: rows 2 (i - 1), unknowns u1_i at 2 (i - 1), X1_i at 2 (i - 1) + 1 */
    for (k = 0; k < N; k++) {
      corners(u0, u1, k, cu);
      corners(X0, X1, k, cX);
      if (mcell(R, cu, cX, D, Hu, HX) != 0)
        return dm_err_set(e, DM_EDOM, "r-adaptive: V fails in cell %zu", k);
      for (int a = 0; a < 2; a++) {                      /* bottom corners carry equations */
        size_t node = k + (size_t)a;
        if (node == 0 || node == N)
          continue;
        size_t row = 2 * (node - 1);
        R->rhs[row] += D[a];
        for (int b = 2; b < 4; b++) {                    /* top corners are unknowns */
          size_t m = k + (size_t)(b - 2);
          if (m == 0 || m == N)
            continue;
          band_add(R->AB, row, 2 * (m - 1), Hu[4 * a + b]);
          band_add(R->AB, row, 2 * (m - 1) + 1, HX[4 * a + b]);
        }
      }
    }
    /* the equidistribution of level j + 1: rows 2 (i - 1) + 1 */
    for (k = 0; k < N; k++)
      R->ell[k] = arc(R, X1, u1, k);
    for (i = 1; i < N; i++) {
      size_t row = 2 * (i - 1) + 1;
      R->rhs[row] = R->ell[i] - R->ell[i - 1];
      for (int s = 0; s < 2; s++) {                      /* cells i (+) and i - 1 (-) */
        size_t c = i - (size_t)s;
        double sg = s == 0 ? 1.0 : -1.0, l = R->ell[c];
        double gh = (X1[c + 1] - X1[c]) / l, gu = R->alpha * (u1[c + 1] - u1[c]) / l;
        if (c + 1 < N) {
          band_add(R->AB, row, 2 * c, sg * gu);
          band_add(R->AB, row, 2 * c + 1, sg * gh);
        }
        if (c > 0) {
          band_add(R->AB, row, 2 * (c - 1), -sg * gu);
          band_add(R->AB, row, 2 * (c - 1) + 1, -sg * gh);
        }
      }
    }
    gsl_vector_view r = gsl_vector_view_array(R->rhs, n), s = gsl_vector_view_array(R->sol, n);
    if (gsl_linalg_LU_band_decomp(n, LB, UB, R->AB, R->piv) != GSL_SUCCESS
        || gsl_linalg_LU_band_solve(LB, UB, R->AB, R->piv, &r.vector, &s.vector) != GSL_SUCCESS)
      return dm_err_set(e, DM_ESINGULAR, "r-adaptive: singular step Jacobian");
    d = 0;
    for (i = 1; i < N; i++) {
      u1[i] -= R->sol[2 * (i - 1)];
      X1[i] -= R->sol[2 * (i - 1) + 1];
      xs = fmax(xs, fmax(fabs(u1[i]), fabs(X1[i])));
      d = fmax(d, fmax(fabs(R->sol[2 * (i - 1)]), fabs(R->sol[2 * (i - 1) + 1])));
    }
    d /= xs;
    if (!isfinite(d))
      return dm_err_set(e, DM_EDIVERGED, "r-adaptive: the Newton update is not finite");
    if (dm_newton_done(&stop, d, 4 * DBL_EPSILON))
      break;
  }
  if (it >= 60)
    return dm_err_set(e, DM_ENOCONV, "r-adaptive: Newton did not converge (update %.3g)", d);
  for (k = 0; k < N; k++)
    if (!(X1[k + 1] > X1[k]))
      return dm_err_set(e, DM_EDIVERGED, "r-adaptive: the mesh tangled in cell %zu (nodes "
                        "crossed)", k);
  for (i = 0; i < nn; i++) {
    R->dX[i] = X1[i] - X0[i];
    R->du[i] = u1[i] - u0[i];
    R->lastX[i] = X1[i];
    R->lastu[i] = u1[i];
    p1[i] = 0.0;
  }
  R->have_last = 1;
  for (k = 0; k < N; k++) {
    double cu[4], cX[4], D[4];
    corners(u0, u1, k, cu);
    corners(X0, X1, k, cX);
    mcell(R, cu, cX, D, NULL, NULL);
    if (k > 0)
      p1[k] += D[2];                                     /* TL */
    if (k + 1 < N)
      p1[k + 1] += D[3];                                 /* TR */
  }
  return DM_OK;
}

double dm_radapt_energy(const dm_radapt *R, const double *X, const double *u, const double *p)
{
  double E = 0, c2 = R->c * R->c, V;
  for (size_t i = 1; i < R->N; i++) {
    double m = 0.5 * (X[i + 1] - X[i - 1]);
    E += p[i] * p[i] / (2 * m);
    if (pot(R, u[i], &V, NULL, NULL) == 0)
      E += m * V;
  }
  for (size_t k = 0; k < R->N; k++) {
    double h = X[k + 1] - X[k], g = (u[k + 1] - u[k]) / h;
    E += 0.5 * h * c2 * g * g;
  }
  return E;
}
