/* sphere_lgvi.c -- the variational integrator of Lee, Leok and McClamroch
 * on the unit sphere S^n in R^(n+1), for systems of kind "sphere"
 * (lie_system.h): L = (m/2)|v|^2 - U(x) with a constant m > 0, x a unit
 * vector and v, p = m v tangent to the sphere at x.
 *
 * Discrete Lagrangian (doc/lie.md §10)
 *   L_d(x0, x1) = (m/2h)|x1 - x0|^2 - (h/2)(U(x0) + U(x1)),
 * with the discrete Legendre transforms (P_x w = w - (x.w) x projects on
 * the tangent space at x; Lq(x, 0) = -grad U(x))
 *   p0 = -D1 L_d = (m/h) P_x0 x1 - (h/2) P_x0 Lq(x0, 0),
 *   p1 =  D2 L_d = -(m/h) P_x1 x0 + (h/2) P_x1 Lq(x1, 0).
 * The step solves the first for x1 on the sphere explicitly:
 *   a = (h/m) P_x0 (p0 + (h/2) Lq(x0, 0)),   s = sqrt(1 - |a|^2),
 *   x1 = s x0 + a,    p1 = (m/h)(s a - |a|^2 x0) + (h/2) P_x1 Lq(x1, 0)
 * (P_x1 x0 = |a|^2 x0 - s a without cancellation).  |a| < 1 is the step
 * size limit (the chord of one step is shorter than the diameter).
 * Symplectic on T*S^n, symmetric, order 2; |x| stays 1 to round-off with
 * no projection.  A step never allocates. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_integ_impl.h"

typedef struct slgvi {
  size_t d;                      /* ambient dimension n + 1 */
  double m;                      /* the constant mass */
  double *work;                  /* the system's scratch */
  double *Lq, *Lv, *Lvv, *Lvq, *v0, *a;   /* d, d, d^2, d^2, d, d */
} slgvi;

static const char *const sphere_options[] = {"h", NULL};

static double dot(size_t d, const double *a, const double *b)
{
  double s = 0.0;
  for (size_t i = 0; i < d; i++)
    s += a[i] * b[i];
  return s;
}

/* w <- P_x w */
static void project(size_t d, const double *x, double *w)
{
  double c = dot(d, x, w);
  for (size_t i = 0; i < d; i++)
    w[i] -= c * x[i];
}

static int eval(dm_integrator *I, slgvi *W, const double *x, const double *v, unsigned what,
                dm_err *e)
{
  const dm_system *s = I->sys;
  dm_lag_out o = {0.0, W->Lq, W->Lv, W->Lvv, W->Lvq, NULL};
  int rc = s->lagrangian(s->data, x, v, s->par, what, &o, W->work);
  if (rc != 0)
    return dm_err_set(e, rc > 0 ? DM_EDOM : DM_ECALLBACK, "lgvi on S%zu: the Lagrangian "
                      "cannot be evaluated at x = (%g, %g, ...) (callback status %d)", W->d - 1,
                      x[0], W->d > 1 ? x[1] : 0.0, rc);
  return DM_OK;
}

/* {==== set-up: L must be (m/2)|v|^2 - U(x) ============================== */

/* deterministic points on the sphere and tangent vectors */
static double lcg(unsigned long long *s)
{
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 4503599627370496.0 - 1.0;
}

static void random_state(size_t d, unsigned long long *seed, double *x, double *v)
{
  double r;
  for (size_t i = 0; i < d; i++) {
    x[i] = lcg(seed);
    v[i] = 2.385 * lcg(seed);
  }
  r = sqrt(dot(d, x, x));
  for (size_t i = 0; i < d; i++)
    x[i] /= r;
  project(d, x, v);
}

/* d^2L/dv^2 = m I, d^2L/dv dq = 0 and dL/dv = m v at five points on TS^n */
static int check_form(dm_integrator *I, slgvi *W, dm_err *e)
{
  size_t d = W->d, i, j, k;
  unsigned long long seed = 2385;
  double x[DM_LIE_DIM_MAX + 1], v[DM_LIE_DIM_MAX + 1];
  int st;
  for (k = 0; k < 5; k++) {
    random_state(d, &seed, x, v);
    if ((st = eval(I, W, x, v, DM_LAG_V | DM_LAG_VV | DM_LAG_VQ, e)) != DM_OK)
      return st;
    if (k == 0) {
      W->m = W->Lvv[0];
      if (!(W->m > 0.0) || !isfinite(W->m))
        return dm_err_set(e, DM_EINVAL, "lgvi on S%zu: the mass d2L/dv1^2 = %g is not > 0",
                          d - 1, W->m);
    }
    for (i = 0; i < d; i++) {
      if (fabs(W->Lv[i] - W->m * v[i]) > 1e-10 * W->m * (1.0 + fabs(v[i])))
        return dm_err_set(e, DM_EINVAL, "lgvi on S%zu takes L = (m/2)|v|^2 - U(x) with a "
                          "constant m: dL/dv_%zu = %.17g is not m v_%zu = %.17g at a point of "
                          "the sphere (a term linear in v, or m depending on x)", d - 1, i + 1,
                          W->Lv[i], i + 1, W->m * v[i]);
      for (j = 0; j < d; j++) {
        double want = i == j ? W->m : 0.0;
        if (fabs(W->Lvv[i * d + j] - want) > 1e-10 * W->m ||
            fabs(W->Lvq[i * d + j]) > 1e-10 * W->m)
          return dm_err_set(e, DM_EINVAL, "lgvi on S%zu takes L = (m/2)|v|^2 - U(x) with a "
                            "constant m: d2L/dv%zu dv%zu = %.17g, d2L/dv%zu dq%zu = %.17g "
                            "(want %g and 0)", d - 1, i + 1, j + 1, W->Lvv[i * d + j], i + 1,
                            j + 1, W->Lvq[i * d + j], want);
      }
    }
  }
  return DM_OK;
}

static void sphere_free(dm_integrator *I)
{
  slgvi *W = I->state;
  if (W != NULL)
    free(W->work);
  free(W);
  I->state = NULL;
}

static int sphere_alloc(dm_integrator *I, dm_err *e)
{
  const dm_system *s = I->sys;
  size_t d = s->n;
  slgvi *W;
  int st;
  if (d < 2 || d > DM_LIE_DIM_MAX + 1)
    return dm_err_set(e, DM_EINVAL, "lgvi on a sphere: %zu coordinates (need 2 .. %d)", d,
                      DM_LIE_DIM_MAX + 1);
  if (s->force != NULL)
    return dm_err_set(e, DM_EUNSUP, "lgvi on S%zu: generalized forces are not supported",
                      d - 1);
  if ((W = calloc(1, sizeof *W + (4 * d + 2 * d * d) * sizeof(double))) == NULL ||
      (W->work = malloc(s->work_size + 8)) == NULL) {
    free(W);
    return dm_err_set(e, DM_ENOMEM, "lgvi on S%zu: out of memory", d - 1);
  }
  I->state = W;
  W->d = d;
  W->Lq = (double *)(W + 1);
  W->Lv = W->Lq + d;
  W->Lvv = W->Lv + d;
  W->Lvq = W->Lvv + d * d;
  W->v0 = W->Lvq + d * d;
  W->a = W->v0 + d;
  if ((st = check_form(I, W, e)) != DM_OK)
    return st;
  I->stages = 1;
  return DM_OK;
}

/* }====================================================================== */

/* {==== the step ========================================================= */

/* x a unit vector and p tangent to the sphere at x (to 1e-10) */
static int on_sphere(const slgvi *W, const double *x, const double *p, dm_err *e)
{
  size_t d = W->d;
  double r2 = dot(d, x, x), xp = dot(d, x, p), pn = sqrt(dot(d, p, p));
  if (!(fabs(r2 - 1.0) <= 1e-10))
    return dm_err_set(e, DM_EDOM, "lgvi on S%zu: the point is not on the sphere: |x|^2 - 1 = "
                      "%.3g (start from a unit vector)", d - 1, r2 - 1.0);
  if (!(fabs(xp) <= 1e-10 * (1.0 + pn)))
    return dm_err_set(e, DM_EDOM, "lgvi on S%zu: the momentum is not tangent to the sphere: "
                      "x.p = %.3g (start from a velocity with x.v = 0)", d - 1, xp);
  return DM_OK;
}

static int sphere_step(dm_integrator *I, double h, const double *x0, const double *p0,
                       double *x1, double *p1, dm_err *e)
{
  slgvi *W = I->state;
  size_t d = W->d, i;
  double *a = W->a, a2, s, c;
  int st;
  if ((st = on_sphere(W, x0, p0, e)) != DM_OK)
    return st;
  memset(W->v0, 0, d * sizeof *W->v0);
  if ((st = eval(I, W, x0, W->v0, DM_LAG_Q, e)) != DM_OK)
    return st;
  for (i = 0; i < d; i++)
    a[i] = p0[i] + 0.5 * h * W->Lq[i];
  project(d, x0, a);
  c = h / W->m;
  for (i = 0; i < d; i++)
    a[i] *= c;
  a2 = dot(d, a, a);
  if (!(a2 < 1.0))
    return dm_err_set(e, DM_EDOM, "lgvi on S%zu: the step h = %g is too large for the speed: "
                      "the chord h|p|/m = %.3g must be < 1 (reduce h)", d - 1, h, sqrt(a2));
  s = sqrt((1.0 - sqrt(a2)) * (1.0 + sqrt(a2)));
  /* x0[i] is read before x1[i] is written: x1 may alias x0 */
  for (i = 0; i < d; i++) {
    double xi = s * x0[i] + a[i];
    p1[i] = (s * a[i] - a2 * x0[i]) / c;
    x1[i] = xi;
  }
  if ((st = eval(I, W, x1, W->v0, DM_LAG_Q, e)) != DM_OK)
    return st;
  project(d, x1, W->Lq);
  for (i = 0; i < d; i++)
    p1[i] += 0.5 * h * W->Lq[i];
  I->stats.steps++;
  return DM_OK;
}

/* a run's start: on the sphere, with a tangent momentum */
static int sphere_begin(dm_integrator *I, double h, double t0, const double *x0,
                        const double *p0, dm_err *e)
{
  (void)h;
  (void)t0;
  return on_sphere(I->state, x0, p0, e);
}

static int sphere_dlegendre(dm_integrator *I, double h, const double *x0, const double *x1,
                            double *p0, double *p1, double *Ld, dm_err *e)
{
  slgvi *W = I->state;
  size_t d = W->d, i;
  double U0, U1, k = 0.0, c01 = dot(d, x0, x1);
  dm_lag_out o = {0.0, W->Lq, NULL, NULL, NULL, NULL};
  const dm_system *s = I->sys;
  memset(W->v0, 0, d * sizeof *W->v0);
  if (s->lagrangian(s->data, x0, W->v0, s->par, DM_LAG_L | DM_LAG_Q, &o, W->work) != 0)
    return dm_err_set(e, DM_EDOM, "lgvi on S%zu: the Lagrangian cannot be evaluated", d - 1);
  U0 = -o.L;
  if (p0 != NULL) {
    for (i = 0; i < d; i++)
      p0[i] = W->m / h * (x1[i] - c01 * x0[i]) - 0.5 * h * (W->Lq[i] - dot(d, x0, W->Lq) * x0[i]);
  }
  if (s->lagrangian(s->data, x1, W->v0, s->par, DM_LAG_L | DM_LAG_Q, &o, W->work) != 0)
    return dm_err_set(e, DM_EDOM, "lgvi on S%zu: the Lagrangian cannot be evaluated", d - 1);
  U1 = -o.L;
  if (p1 != NULL) {
    double c = dot(d, x1, W->Lq);
    for (i = 0; i < d; i++)
      p1[i] = -W->m / h * (x0[i] - c01 * x1[i]) + 0.5 * h * (W->Lq[i] - c * x1[i]);
  }
  for (i = 0; i < d; i++)
    k += (x1[i] - x0[i]) * (x1[i] - x0[i]);
  if (Ld != NULL)
    *Ld = 0.5 * W->m / h * k - 0.5 * h * (U0 + U1);
  return DM_OK;
}

/* }====================================================================== */

/* {==== the symplecticity defect on T*S^n ================================ */

/* An orthonormal basis t_1 .. t_n of the tangent space at x (Gram-Schmidt
 * of the coordinate axes, the one most parallel to x left out). */
static void tangent_basis(size_t d, const double *x, double *t)
{
  size_t skip = 0, i, j, k = 0;
  for (i = 1; i < d; i++)
    if (fabs(x[i]) > fabs(x[skip]))
      skip = i;
  for (j = 0; j < d; j++) {
    double *u = t + k * d;
    if (j == skip)
      continue;
    memset(u, 0, d * sizeof *u);
    u[j] = 1.0;
    for (int pass = 0; pass < 2; pass++) {   /* twice is enough (Kahan) */
      project(d, x, u);
      for (i = 0; i < k; i++) {
        double c = dot(d, t + i * d, u);
        for (size_t l = 0; l < d; l++)
          u[l] -= c * t[i * d + l];
      }
    }
    double r = sqrt(dot(d, u, u));
    for (i = 0; i < d; i++)
      u[i] /= r;
    k++;
  }
}

/* The step map's derivative along T*S^n = {|x| = 1, x.p = 0} (central
 * differences along curves in it: x turned towards t_a with p kept
 * tangent, or p + e t_a), and the defect of the restriction of the
 * canonical form dx ^ dp: max |w(DPhi e_a, DPhi e_b) - w(e_a, e_b)|. */
static int sphere_defect(dm_integrator *I, double h, const double *x0, const double *p0,
                         double *defect, dm_err *e)
{
  slgvi *W = I->state;
  size_t d = W->d, n = d - 1, N = 2 * n, a, b, i;
  double *buf = malloc((d * n + 4 * N * d + 4 * d) * sizeof *buf), worst = 0.0;
  double *t, *Dx, *Dp, *xs, *ps, *x1, *p1, *E0x, *E0p;
  int st = DM_OK;
  if (buf == NULL)
    return dm_err_set(e, DM_ENOMEM, "symplecticity_defect: out of memory");
  t = buf;
  Dx = t + d * n;                /* N columns of d: the images */
  Dp = Dx + N * d;
  E0x = Dp + N * d;              /* N columns of d: the basis itself */
  E0p = E0x + N * d;
  xs = E0p + N * d;
  ps = xs + d;
  x1 = ps + d;
  p1 = x1 + d;
  if ((st = on_sphere(W, x0, p0, e)) != DM_OK)
    goto done;
  tangent_basis(d, x0, t);
  for (a = 0; a < N && st == DM_OK; a++) {
    const double *ta = t + (a % n) * d;
    double eps = a < n ? 1e-6 : 1e-6 * fmax(1.0, sqrt(dot(d, p0, p0)));
    for (i = 0; i < d; i++) {     /* the basis vector in ambient coordinates */
      E0x[a * d + i] = a < n ? ta[i] : 0.0;
      E0p[a * d + i] = a < n ? -dot(d, ta, p0) * x0[i] : ta[i];
    }
    for (int sg = 0; sg < 2 && st == DM_OK; sg++) {
      double ep = sg ? -eps : eps, c = cos(ep), s = sin(ep);
      for (i = 0; i < d; i++) {
        xs[i] = a < n ? c * x0[i] + s * ta[i] : x0[i];
        ps[i] = a < n ? p0[i] : p0[i] + ep * ta[i];
      }
      project(d, xs, ps);
      dm_integrator_reset(I);
      if ((st = I->type->step(I, h, xs, ps, x1, p1, e)) != DM_OK)   /* the step in use */
        break;
      for (i = 0; i < d; i++) {
        double sgn = sg ? -1.0 : 1.0;
        if (sg == 0) {
          Dx[a * d + i] = 0.0;
          Dp[a * d + i] = 0.0;
        }
        Dx[a * d + i] += sgn * x1[i] / (2.0 * eps);
        Dp[a * d + i] += sgn * p1[i] / (2.0 * eps);
      }
    }
  }
  if (st != DM_OK)
    goto done;
  for (a = 0; a < N; a++)
    for (b = 0; b < N; b++) {
      double w1 = dot(d, Dx + a * d, Dp + b * d) - dot(d, Dp + a * d, Dx + b * d);
      double w0 = dot(d, E0x + a * d, E0p + b * d) - dot(d, E0p + a * d, E0x + b * d);
      worst = fmax(worst, fabs(w1 - w0));
    }
  *defect = worst;
done:
  free(buf);
  dm_integrator_reset(I);
  return st;
}

/* }====================================================================== */

static const char *const sphere_kinds[] = {DM_SYSTEM_SPHERE, NULL};

const dm_integrator_type dm_sphere_integ_lgvi = {
  .name = "lgvi",
  .summary = "variational integrator on the sphere (Lee-Leok-McClamroch) for "
             "L = (m/2)|v|^2 - U(x); explicit, order 2, symplectic, |x| = 1 to round-off",
  .order = 2,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_EXPLICIT | DM_INTEG_VARIATIONAL,
  .options = sphere_options,
  .alloc = sphere_alloc,
  .step = sphere_step,
  .dlegendre = sphere_dlegendre,
  .free = sphere_free,
  .kinds = sphere_kinds,
  .begin = sphere_begin,
  .manifold_defect = sphere_defect,
};
