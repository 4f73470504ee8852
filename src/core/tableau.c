/* tableau.c -- Gauss, Lobatto IIIA-IIIB and user PRK coefficient tables.
 * See tableau.h for the formulas and the ownership rules. */
#include <config.h>
#include "core/tableau.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_integration.h>

dm_tableau *dm_tableau_alloc(size_t s)
{
  dm_tableau *t;
  double *d;
  if (s == 0 || s > 4096)
    return NULL;
  t = calloc(1, sizeof *t + (3 * s + 2 * s * s) * sizeof(double));
  if (t == NULL)
    return NULL;
  d = (double *)(t + 1);
  t->s = s;
  t->c = d;
  t->b = d + s;
  t->bt = d + 2 * s;
  t->a = d + 3 * s;
  t->at = d + 3 * s + s * s;
  strcpy(t->name, "prk");
  return t;
}

void dm_tableau_free(dm_tableau *t)
{
  free(t);
}

dm_tableau *dm_tableau_copy(const dm_tableau *t)
{
  dm_tableau *u;
  if (t == NULL || (u = dm_tableau_alloc(t->s)) == NULL)
    return NULL;
  memcpy(u->name, t->name, sizeof u->name);
  u->order = t->order;
  u->flags = t->flags;
  memcpy(u->c, t->c, (3 * t->s + 2 * t->s * t->s) * sizeof(double));
  return u;
}

/* Lagrange basis polynomial l_j of the nodes c at x, in long double (the
 * tables must be right to the last bit for s up to 8 and beyond). */
static long double lagrange(size_t s, const double *c, size_t j, long double x)
{
  long double v = 1.0L;
  size_t k;
  for (k = 0; k < s; k++)
    if (k != j)
      v *= (x - (long double)c[k]) / ((long double)c[j] - (long double)c[k]);
  return v;
}

/* b_i = int_0^1 l_i, a_ij = int_0^{c_i} l_j with the s-point Gauss rule
 * (exact for the degree s-1 integrands), at from the symplectic condition. */
static int galerkin_fill(dm_tableau *t, dm_err *e)
{
  size_t s = t->s, i, j, k;
  gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc(s);
  if (gl == NULL)
    return dm_err_set(e, DM_ENOMEM, "tableau: out of memory for the %zu-point Gauss rule", s);
  for (i = 0; i < s; i++) {
    long double bi = 0.0L;
    for (k = 0; k < s; k++) {
      double x, w;
      gsl_integration_glfixed_point(0.0, 1.0, k, &x, &w, gl);
      bi += (long double)w * lagrange(s, t->c, i, x);
    }
    t->b[i] = (double)bi;
    t->bt[i] = t->b[i];
  }
  for (i = 0; i < s; i++)
    for (j = 0; j < s; j++) {
      long double aij = 0.0L;
      if (t->c[i] != 0.0)
        for (k = 0; k < s; k++) {
          double x, w;
          gsl_integration_glfixed_point(0.0, t->c[i], k, &x, &w, gl);
          aij += (long double)w * lagrange(s, t->c, j, x);
        }
      t->a[i * s + j] = (double)aij;
    }
  gsl_integration_glfixed_table_free(gl);
  for (i = 0; i < s; i++) {
    if (t->b[i] == 0.0)
      return dm_err_set(e, DM_EINVAL,
                        "tableau: quadrature weight b_%zu is zero (nodes give a degenerate rule)", i + 1);
  }
  for (i = 0; i < s; i++)
    for (j = 0; j < s; j++)
      t->at[i * s + j] = t->b[j] * (1.0 - t->a[j * s + i] / t->b[i]);
  t->flags |= DM_TAB_GALERKIN;
  return DM_OK;
}

static int check_nodes(size_t s, const double *c, dm_err *e)
{
  size_t i, j;
  for (i = 0; i < s; i++) {
    if (!(c[i] >= 0.0 && c[i] <= 1.0))
      return dm_err_set(e, DM_EINVAL, "tableau: node c_%zu = %g is outside [0, 1]", i + 1, c[i]);
    for (j = 0; j < i; j++)
      if (fabs(c[i] - c[j]) < 1e-12)
        return dm_err_set(e, DM_EINVAL, "tableau: nodes c_%zu and c_%zu coincide (%g)", j + 1, i + 1, c[i]);
  }
  return DM_OK;
}

int dm_tableau_galerkin(size_t s, const double *c, dm_tableau **out, dm_err *e)
{
  dm_tableau *t;
  int st;
  *out = NULL;
  if (s < 1 || s > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "tableau: stages = %zu out of range 1..%d", s, DM_TABLEAU_SMAX);
  if ((st = check_nodes(s, c, e)) != DM_OK)
    return st;
  if ((t = dm_tableau_alloc(s)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "tableau: out of memory");
  memcpy(t->c, c, s * sizeof(double));
  strcpy(t->name, "galerkin");
  if ((st = galerkin_fill(t, e)) != DM_OK) {
    dm_tableau_free(t);
    return st;
  }
  dm_tableau_classify(t, 1e-13);
  *out = t;
  return DM_OK;
}

static int cmp_double(const void *x, const void *y)
{
  double a = *(const double *)x, b = *(const double *)y;
  return (a > b) - (a < b);
}

int dm_tableau_gauss(size_t s, dm_tableau **out, dm_err *e)
{
  dm_tableau *t;
  gsl_integration_glfixed_table *gl;
  size_t i;
  int st;
  *out = NULL;
  if (s < 1 || s > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "gauss: stages = %zu out of range 1..%d", s, DM_TABLEAU_SMAX);
  if ((t = dm_tableau_alloc(s)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "gauss: out of memory");
  if ((gl = gsl_integration_glfixed_table_alloc(s)) == NULL) {
    dm_tableau_free(t);
    return dm_err_set(e, DM_ENOMEM, "gauss: out of memory for the Gauss rule");
  }
  for (i = 0; i < s; i++) {
    double w;
    gsl_integration_glfixed_point(0.0, 1.0, i, &t->c[i], &w, gl);
  }
  gsl_integration_glfixed_table_free(gl);
  qsort(t->c, s, sizeof(double), cmp_double);
  /* exact symmetry c_i + c_{s+1-i} = 1 */
  for (i = 0; i < s / 2; i++)
    t->c[s - 1 - i] = 1.0 - t->c[i];
  if (s % 2)
    t->c[s / 2] = 0.5;
  if ((st = galerkin_fill(t, e)) != DM_OK) {
    dm_tableau_free(t);
    return st;
  }
  strcpy(t->name, "gauss");
  t->order = (int)(2 * s);
  dm_tableau_classify(t, 1e-13);
  *out = t;
  return DM_OK;
}

/* P_N(x) and P'_N(x) by the three-term recurrence. */
static void legendre_pd(int N, long double x, long double *p, long double *dp)
{
  long double p0 = 1.0L, p1 = x, p2;
  int k;
  if (N == 0) {
    *p = 1.0L;
    *dp = 0.0L;
    return;
  }
  for (k = 2; k <= N; k++) {
    p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  *p = p1;
  *dp = N * (x * p1 - p0) / (x * x - 1.0L);   /* |x| < 1 here */
}

int dm_tableau_lobatto_nodes(size_t s, double *x, dm_err *e)
{
  int N = (int)s - 1;     /* interior nodes: roots of P'_N */
  size_t k;
  if (s < 2 || s > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "lobatto: stages = %zu out of range 2..%d", s, DM_TABLEAU_SMAX);
  x[0] = 0.0;
  x[s - 1] = 1.0;
  for (k = 1; k <= (s - 2 + 1) / 2; k++) {
    /* Chebyshev-Lobatto guess, then Newton on P'_N using
     * (1 - x^2) P''_N = 2 x P'_N - N (N+1) P_N. */
    long double z = -cosl(3.14159265358979323846264338327950288L * (long double)k / N);
    long double dzprev = HUGE_VALL;
    int it;
    for (it = 0; it < 100; it++) {
      long double p, dp, d2p, dz;
      legendre_pd(N, z, &p, &dp);
      d2p = (2.0L * z * dp - (long double)N * (N + 1) * p) / (1.0L - z * z);
      dz = dp / d2p;
      z -= dz;
      /* converged, or at the precision floor (long double may be double) */
      if (fabsl(dz) <= 4.0L * LDBL_EPSILON || (fabsl(dz) < 1e-14L && fabsl(dz) >= dzprev))
        break;
      dzprev = fabsl(dz);
    }
    if (it == 100 || !(fabsl(z) < 1.0L))
      return dm_err_set(e, DM_ENOCONV, "lobatto: Newton for node %zu of %zu did not converge", k + 1, s);
    x[k] = (double)((1.0L + z) / 2.0L);
    x[s - 1 - k] = (double)((1.0L - z) / 2.0L);
  }
  if (s % 2)
    x[s / 2] = 0.5;
  return DM_OK;
}

int dm_tableau_lobatto(size_t s, dm_tableau **out, dm_err *e)
{
  dm_tableau *t;
  int st;
  size_t i;
  *out = NULL;
  if (s < 2 || s > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "lobatto: stages = %zu out of range 2..%d", s, DM_TABLEAU_SMAX);
  if ((t = dm_tableau_alloc(s)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "lobatto: out of memory");
  if ((st = dm_tableau_lobatto_nodes(s, t->c, e)) != DM_OK
      || (st = galerkin_fill(t, e)) != DM_OK) {
    dm_tableau_free(t);
    return st;
  }
  /* Exact structural zeros and ones of the IIIA-IIIB pair: a_1j = 0,
   * a_sj = b_j, at_is = 0, at_i1 = b_1. */
  for (i = 0; i < s; i++) {
    t->a[i] = 0.0;
    t->a[(s - 1) * s + i] = t->b[i];
    t->at[i * s + s - 1] = 0.0;
    t->at[i * s] = t->b[0];
  }
  strcpy(t->name, "lobatto");
  t->order = (int)(2 * s - 2);
  dm_tableau_classify(t, 1e-13);
  *out = t;
  return DM_OK;
}

double dm_tableau_symplectic_defect(const dm_tableau *t, size_t *wi, size_t *wj)
{
  size_t s = t->s, i, j, bi = 0, bj = 0;
  double worst = 0.0;
  for (i = 0; i < s; i++)
    for (j = 0; j < s; j++) {
      double d = fabs(t->b[i] * t->at[i * s + j] + t->b[j] * t->a[j * s + i]
                      - t->b[i] * t->b[j]);
      if (!(d <= worst)) {      /* also catches NaN */
        worst = d;
        bi = i;
        bj = j;
      }
    }
  for (i = 0; i < s; i++) {
    double d = fabs(t->b[i] - t->bt[i]);
    if (!(d <= worst)) {
      worst = d;
      bi = i;
      bj = (size_t)-1;
    }
  }
  if (wi)
    *wi = bi;
  if (wj)
    *wj = bj;
  return worst;
}

void dm_tableau_classify(dm_tableau *t, double tol)
{
  size_t s = t->s, i, j;
  double bmax = 1.0;
  int sym = 1;
  for (i = 0; i < s; i++)
    bmax = fmax(bmax, fabs(t->b[i]));
  t->flags &= ~(unsigned)(DM_TAB_SYMPLECTIC | DM_TAB_SYMMETRIC);
  if (dm_tableau_symplectic_defect(t, NULL, NULL) <= tol * bmax * bmax)
    t->flags |= DM_TAB_SYMPLECTIC;
  /* symmetric (self-adjoint): c_i + c_{s+1-i} = 1,
   * a_ij + a_{s+1-i,s+1-j} = b_j, likewise for at, bt */
  for (i = 0; i < s && sym; i++) {
    size_t ir = s - 1 - i;
    if (fabs(t->c[i] + t->c[ir] - 1.0) > tol || fabs(t->b[i] - t->b[ir]) > tol
        || fabs(t->bt[i] - t->bt[ir]) > tol)
      sym = 0;
    for (j = 0; j < s && sym; j++) {
      size_t jr = s - 1 - j;
      if (fabs(t->a[i * s + j] + t->a[ir * s + jr] - t->b[j]) > tol * bmax
          || fabs(t->at[i * s + j] + t->at[ir * s + jr] - t->bt[j]) > tol * bmax)
        sym = 0;
    }
  }
  if (sym)
    t->flags |= DM_TAB_SYMMETRIC;
}

int dm_tableau_prk(size_t s, const double *a, const double *b,
                   const double *at, const double *bt, const double *c,
                   double tol, dm_tableau **out, dm_err *e)
{
  dm_tableau *t;
  size_t i, j, wi, wj;
  double bmax = 1.0, d;
  *out = NULL;
  if (s < 1 || s > DM_TABLEAU_SMAX)
    return dm_err_set(e, DM_EINVAL, "prk: stages = %zu out of range 1..%d", s, DM_TABLEAU_SMAX);
  if (a == NULL || b == NULL)
    return dm_err_set(e, DM_EINVAL, "prk: the coefficients a and b are required");
  for (i = 0; i < s * s; i++)
    if (!isfinite(a[i]) || (at != NULL && !isfinite(at[i])))
      return dm_err_set(e, DM_EINVAL, "prk: coefficient %s[%zu][%zu] is not finite",
                        isfinite(a[i]) ? "at" : "a", i / s + 1, i % s + 1);
  for (i = 0; i < s; i++) {
    if (!isfinite(b[i]) || (bt && !isfinite(bt[i])) || (c && !isfinite(c[i])))
      return dm_err_set(e, DM_EINVAL, "prk: weight or node %zu is not finite", i + 1);
    if (at == NULL && b[i] == 0.0)
      return dm_err_set(e, DM_EINVAL, "prk: b_%zu = 0, cannot derive the symplectic partner at", i + 1);
  }
  if ((t = dm_tableau_alloc(s)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "prk: out of memory");
  memcpy(t->a, a, s * s * sizeof(double));
  memcpy(t->b, b, s * sizeof(double));
  memcpy(t->bt, bt ? bt : b, s * sizeof(double));
  for (i = 0; i < s; i++) {
    double ci = 0.0;
    for (j = 0; j < s; j++)
      ci += a[i * s + j];
    t->c[i] = c ? c[i] : ci;
    bmax = fmax(bmax, fabs(b[i]));
    for (j = 0; j < s; j++)
      t->at[i * s + j] = at ? at[i * s + j] : b[j] * (1.0 - a[j * s + i] / b[i]);
  }
  if (tol <= 0.0)
    tol = 1e-13;
  d = dm_tableau_symplectic_defect(t, &wi, &wj);
  if (!(d <= tol * bmax * bmax)) {
    if (wj == (size_t)-1)
      dm_err_set(e, DM_EINVAL,
                 "prk: not symplectic: b_%zu = %.17g differs from bt_%zu = %.17g (defect %.3g > tol %.3g)",
                 wi + 1, t->b[wi], wi + 1, t->bt[wi], d, tol * bmax * bmax);
    else
      dm_err_set(e, DM_EINVAL,
                 "prk: not symplectic: b_i at_ij + b_j a_ji - b_i b_j = %.3g at (i, j) = (%zu, %zu) (tol %.3g)",
                 t->b[wi] * t->at[wi * s + wj] + t->b[wj] * t->a[wj * s + wi] - t->b[wi] * t->b[wj],
                 wi + 1, wj + 1, tol * bmax * bmax);
    dm_tableau_free(t);
    return DM_EINVAL;
  }
  strcpy(t->name, "prk");
  dm_tableau_classify(t, fmax(tol, 1e-13));
  *out = t;
  return DM_OK;
}
