/* builtin_systems.c -- hand-written C systems; see builtin_systems.h.
 * Callbacks follow system.h: fill the requested outputs, return 0, or 1
 * (recoverable) at a singular point (|q| = 0). */
#include <config.h>
#include "core/builtin_systems.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct bdata {
  double par[4];
  double mass[9];
  size_t n;
  int form;
  double (*mscale)(const double *par);   /* mass = mscale(par) Id; NULL: unit */
} bdata;

static void bfree(dm_system *s)
{
  free(s->data);
}

/* The constant mass matrix from the current parameters. */
static int brefresh(dm_system *s, dm_err *e)
{
  bdata *d = s->data;
  size_t i;
  double m;
  (void)e;
  if (d == NULL || d->mscale == NULL)
    return DM_OK;
  m = d->mscale(d->par);
  for (i = 0; i < d->n; i++)
    d->mass[i * d->n + i] = m;
  return DM_OK;
}

/* scalar masses of the systems with a mass parameter */
static double mass_m0(const double *par) { return par[0]; }              /* m first */
static double mass_m2(const double *par) { return par[2]; }              /* g, l, m */
static double mass_ml2(const double *par) { return par[2] * par[1] * par[1]; }

/* Common set-up: n coordinates, unit mass, parameter values. */
static int setup(dm_system *s, const char *name, size_t n, size_t m, const char *const *coords,
                 const char *const *params, size_t npar, const double *par, unsigned flags,
                 dm_lag_fn lag, dm_err *e)
{
  bdata *d = calloc(1, sizeof *d);
  size_t i;
  memset(s, 0, sizeof *s);
  if (d == NULL)
    return dm_err_set(e, DM_ENOMEM, "%s: out of memory", name);
  for (i = 0; i < npar; i++)
    d->par[i] = par[i];
  for (i = 0; i < n; i++)
    d->mass[i * n + i] = 1.0;
  s->name = name;
  s->n = n;
  s->m = m;
  s->npar = npar;
  s->coords = coords;
  s->params = params;
  s->par = d->par;
  s->flags = flags;
  s->mass = (flags & DM_SYS_SEPARABLE) ? d->mass : NULL;
  s->lagrangian = lag;
  s->data = d;
  s->free_data = bfree;
  s->refresh = brefresh;
  d->n = n;
  return DM_OK;
}

/* setup, then a mass that follows a parameter */
static int setup_m(dm_system *s, const char *name, size_t n, size_t m, const char *const *coords,
                   const char *const *params, size_t npar, const double *par, unsigned flags,
                   dm_lag_fn lag, double (*mscale)(const double *), dm_err *e)
{
  int st = setup(s, name, n, m, coords, params, npar, par, flags, lag, e);
  if (st == DM_OK) {
    ((bdata *)s->data)->mscale = mscale;
    brefresh(s, NULL);
  }
  return st;
}

/* T = |v|^2 / 2 (only when L is asked for), Lv = v, Lvv = I, Lvq = 0. */
static inline void kinetic(size_t n, const double *v, unsigned what, dm_lag_out *o, double *T)
{
  size_t i;
  if (what & DM_LAG_L) {
    double s = 0.0;
    for (i = 0; i < n; i++)
      s += v[i] * v[i];
    *T = 0.5 * s;               /* = the sum of v_i^2 / 2: halving is exact */
  }
  if (what & DM_LAG_V)
    for (i = 0; i < n; i++)
      o->Lv[i] = v[i];
  if (what & DM_LAG_VV) {
    for (i = 0; i < n * n; i++)
      o->Lvv[i] = 0.0;
    for (i = 0; i < n; i++)
      o->Lvv[i * n + i] = 1.0;
  }
  if (what & DM_LAG_VQ)
    for (i = 0; i < n * n; i++)
      o->Lvq[i] = 0.0;
}

/* The same with the mass M Id: T = M |v|^2 / 2, Lv = M v, Lvv = M Id. */
static inline void kinetic_m(size_t n, double M, const double *v, unsigned what, dm_lag_out *o,
                             double *T)
{
  size_t i;
  kinetic(n, v, what, o, T);
  if (what & DM_LAG_L)
    *T *= M;
  if (what & DM_LAG_V)
    for (i = 0; i < n; i++)
      o->Lv[i] *= M;
  if (what & DM_LAG_VV)
    for (i = 0; i < n; i++)
      o->Lvv[i * n + i] = M;
}

/* {==== harmonic oscillator, pendulum, damped oscillator ================= */

/* par: m, omega */
static int harmonic_lag(void *data, const double *q, const double *v, const double *par,
                        unsigned what, dm_lag_out *o, void *work)
{
  double m = par[0], k = m * par[1] * par[1], T = 0.0;
  (void)data;
  (void)work;
  kinetic_m(1, m, v, what, o, &T);
  if (what & DM_LAG_L)
    o->L = T - 0.5 * k * q[0] * q[0];
  if (what & DM_LAG_Q)
    o->Lq[0] = -k * q[0];
  if (what & DM_LAG_QQ)
    o->Lqq[0] = -k;
  return 0;
}

/* par: g, l, m */
static int pendulum_lag(void *data, const double *q, const double *v, const double *par,
                        unsigned what, dm_lag_out *o, void *work)
{
  double g = par[0], l = par[1], m = par[2], mgl = m * g * l, T = 0.0;
  (void)data;
  (void)work;
  kinetic_m(1, m * l * l, v, what, o, &T);
  if (what & DM_LAG_L)
    o->L = T + mgl * cos(q[0]);
  if (what & DM_LAG_Q)
    o->Lq[0] = -mgl * sin(q[0]);
  if (what & DM_LAG_QQ)
    o->Lqq[0] = -mgl * cos(q[0]);
  return 0;
}

static int damping_force(void *data, const double *q, const double *v, const double *par,
                         unsigned what, double *F, double *Fq, double *Fv, void *work)
{
  (void)data;
  (void)q;
  (void)work;
  if (what & DM_FORCE_F)            /* par: m, omega, c */
    F[0] = -par[2] * v[0];
  if (what & DM_FORCE_Q)
    Fq[0] = 0.0;
  if (what & DM_FORCE_V)
    Fv[0] = -par[2];
  return 0;
}

static const char *const xname[] = {"x"};

int dm_builtin_harmonic(dm_system *s, double m, double omega, dm_err *e)
{
  static const char *const pn[] = {"m", "omega"};
  double par[2] = {m, omega};
  return setup_m(s, "harmonic oscillator", 1, 0, xname, pn, 2, par,
                 DM_SYS_SEPARABLE | DM_SYS_MECHANICAL, harmonic_lag, mass_m0, e);
}

int dm_builtin_pendulum(dm_system *s, double g, double l, double m, dm_err *e)
{
  static const char *const cn[] = {"theta"};
  static const char *const pn[] = {"g", "l", "m"};
  double par[3] = {g, l, m};
  return setup_m(s, "pendulum", 1, 0, cn, pn, 3, par, DM_SYS_SEPARABLE | DM_SYS_MECHANICAL,
                 pendulum_lag, mass_ml2, e);
}

int dm_builtin_damped_oscillator(dm_system *s, double m, double omega, double c, dm_err *e)
{
  static const char *const pn[] = {"m", "omega", "c"};
  double par[3] = {m, omega, c};
  int st = setup_m(s, "damped oscillator", 1, 0, xname, pn, 3, par,
                   DM_SYS_SEPARABLE | DM_SYS_MECHANICAL, harmonic_lag, mass_m0, e);
  if (st == DM_OK)
    s->force = damping_force;
  return st;
}

/* {==== Kepler and J2 ==================================================== */

static inline int kepler_lag_n(size_t n, const double *q, const double *v, const double *par,
                               unsigned what, dm_lag_out *o)
{
  double r2 = 0.0, r, ir3, k, T = 0.0, mu = par[0];
  size_t i, j;
  for (i = 0; i < n; i++)
    r2 += q[i] * q[i];
  if (!(r2 > 0.0))
    return 1;
  r = sqrt(r2);
  kinetic(n, v, what, o, &T);
  if (what & DM_LAG_L)
    o->L = T + mu / r;
  /* -mu q / r^3 with one division: k = -mu / r^3 */
  ir3 = 1.0 / (r2 * r);
  k = -mu * ir3;
  if (what & DM_LAG_Q)
    for (i = 0; i < n; i++)
      o->Lq[i] = k * q[i];
  if (what & DM_LAG_QQ) {
    double c = 3.0 * mu * ir3 / r2;       /* Lqq = k I + 3 mu q q^T / r^5 */
    for (i = 0; i < n; i++)
      for (j = 0; j < n; j++)
        o->Lqq[i * n + j] = c * (q[i] * q[j]) + (i == j ? k : 0.0);
  }
  return 0;
}

static int kepler2_lag(void *data, const double *q, const double *v, const double *par,
                       unsigned what, dm_lag_out *o, void *work)
{
  (void)data;
  (void)work;
  return kepler_lag_n(2, q, v, par, what, o);
}

static int kepler3_lag(void *data, const double *q, const double *v, const double *par,
                       unsigned what, dm_lag_out *o, void *work)
{
  (void)data;
  (void)work;
  return kepler_lag_n(3, q, v, par, what, o);
}

static const char *const xyz[] = {"x", "y", "z"};

int dm_builtin_kepler(dm_system *s, int dim, double mu, dm_err *e)
{
  static const char *const pn[] = {"mu"};
  if (dim != 2 && dim != 3) {
    memset(s, 0, sizeof *s);
    return dm_err_set(e, DM_EINVAL, "kepler: dimension must be 2 or 3 (got %d)", dim);
  }
  return setup(s, "Kepler (Cartesian)", (size_t)dim, 0,
               xyz, pn, 1, &mu, DM_SYS_SEPARABLE | DM_SYS_MECHANICAL,
               dim == 2 ? kepler2_lag : kepler3_lag, e);
}

/* V = -1/r + J2 (3/2 z^2 r^-5 - 1/2 r^-3):
 *   dV/dq_i = A q_i + 3 J2 z r^-5 d_i3,  A = r^-3 + 3/2 J2 r^-5 - 15/2 J2 z^2 r^-7,
 *   d2V/dq_i dq_j = A d_ij + B q_i q_j - 15 J2 z r^-7 (q_i d_j3 + d_i3 q_j) + 3 J2 r^-5 d_i3 d_j3,
 *   B = -3 r^-5 - 15/2 J2 r^-7 + 105/2 J2 z^2 r^-9. */
static int j2_lag(void *data, const double *q, const double *v, const double *par,
                  unsigned what, dm_lag_out *o, void *work)
{
  double J2 = par[0], z = q[2], r2 = q[0] * q[0] + q[1] * q[1] + z * z, r, ir, ir2, ir3, ir5, ir7;
  double T = 0.0, A, B;
  size_t i, j;
  (void)data;
  (void)work;
  if (!(r2 > 0.0))
    return 1;
  r = sqrt(r2);
  ir = 1.0 / r;
  ir2 = ir * ir;
  ir3 = ir2 * ir;
  ir5 = ir3 * ir2;
  ir7 = ir5 * ir2;
  kinetic(3, v, what, o, &T);
  if (what & DM_LAG_L)
    o->L = T + ir - J2 * (1.5 * z * z * ir5 - 0.5 * ir3);
  A = ir3 + 1.5 * J2 * ir5 - 7.5 * J2 * z * z * ir7;
  if (what & DM_LAG_Q) {
    for (i = 0; i < 3; i++)
      o->Lq[i] = -A * q[i];
    o->Lq[2] -= 3.0 * J2 * z * ir5;
  }
  if (what & DM_LAG_QQ) {
    B = -3.0 * ir5 - 7.5 * J2 * ir7 + 52.5 * J2 * z * z * ir7 * ir2;
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++) {
        double hij = (i == j ? A : 0.0) + B * q[i] * q[j];
        if (j == 2)
          hij -= 15.0 * J2 * z * ir7 * q[i];
        if (i == 2)
          hij -= 15.0 * J2 * z * ir7 * q[j];
        if (i == 2 && j == 2)
          hij += 3.0 * J2 * ir5;
        o->Lqq[i * 3 + j] = -hij;
      }
  }
  return 0;
}

int dm_builtin_j2(dm_system *s, double J2, dm_err *e)
{
  static const char *const pn[] = {"J2"};
  return setup(s, "J2 satellite (Cartesian)", 3, 0, xyz, pn, 1, &J2,
               DM_SYS_SEPARABLE | DM_SYS_MECHANICAL, j2_lag, e);
}

/* {==== spherical pendulum =============================================== */

static int sph_r3_lag(void *data, const double *q, const double *v, const double *par,
                      unsigned what, dm_lag_out *o, void *work)
{
  double T = 0.0, mg = par[2] * par[0];          /* par: g, l, m */
  (void)data;
  (void)work;
  kinetic_m(3, par[2], v, what, o, &T);
  if (what & DM_LAG_L)
    o->L = T - mg * q[2];
  if (what & DM_LAG_Q) {
    o->Lq[0] = o->Lq[1] = 0.0;
    o->Lq[2] = -mg;
  }
  if (what & DM_LAG_QQ)
    memset(o->Lqq, 0, 9 * sizeof(double));
  return 0;
}

static int sph_r3_constr(void *data, const double *q, const double *par, unsigned what,
                         double *g, double *G, double *H, void *work)
{
  const bdata *d = data;
  double l = par[1], r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2], r = sqrt(r2);
  size_t i, j;
  (void)work;
  if (d->form == 0) {
    if (what & DM_CONSTR_G)
      g[0] = r2 - l * l;
    if (what & DM_CONSTR_DG)
      for (i = 0; i < 3; i++)
        G[i] = 2.0 * q[i];
    if (what & DM_CONSTR_D2G)
      for (i = 0; i < 9; i++)
        H[i] = (i / 3 == i % 3) ? 2.0 : 0.0;
    return 0;
  }
  if (!(r > 0.0))
    return 1;
  if (what & DM_CONSTR_G)
    g[0] = r - l;
  if (what & DM_CONSTR_DG)
    for (i = 0; i < 3; i++)
      G[i] = q[i] / r;
  if (what & DM_CONSTR_D2G)
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++)
        H[i * 3 + j] = ((i == j) - q[i] * q[j] / r2) / r;
  return 0;
}

int dm_builtin_spherical_pendulum_r3(dm_system *s, double g, double l, double m, int form,
                                     dm_err *e)
{
  static const char *const pn[] = {"g", "l", "m"};
  double par[3] = {g, l, m};
  int st;
  if (form != 0 && form != 1) {
    memset(s, 0, sizeof *s);
    return dm_err_set(e, DM_EINVAL, "spherical pendulum: constraint form must be 0 or 1");
  }
  st = setup_m(s, "spherical pendulum (R3)", 3, 1, xyz, pn, 3, par,
               DM_SYS_SEPARABLE | DM_SYS_MECHANICAL, sph_r3_lag, mass_m2, e);
  if (st == DM_OK) {
    ((bdata *)s->data)->form = form;
    s->constraints = sph_r3_constr;
  }
  return st;
}

static int sph_lag(void *data, const double *q, const double *v, const double *par,
                   unsigned what, dm_lag_out *o, void *work)
{
  double g = par[0] * par[2], l = par[1], l2 = par[2] * l * l, st = sin(q[0]), ct = cos(q[0]);
  (void)data;
  (void)work;
  if (what & DM_LAG_L)
    o->L = 0.5 * l2 * (v[0] * v[0] + st * st * v[1] * v[1]) + g * l * ct;
  if (what & DM_LAG_Q) {
    o->Lq[0] = l2 * st * ct * v[1] * v[1] - g * l * st;
    o->Lq[1] = 0.0;
  }
  if (what & DM_LAG_V) {
    o->Lv[0] = l2 * v[0];
    o->Lv[1] = l2 * st * st * v[1];
  }
  if (what & DM_LAG_VV) {
    o->Lvv[0] = l2;
    o->Lvv[1] = o->Lvv[2] = 0.0;
    o->Lvv[3] = l2 * st * st;
  }
  if (what & DM_LAG_VQ) {
    o->Lvq[0] = o->Lvq[1] = o->Lvq[3] = 0.0;
    o->Lvq[2] = 2.0 * l2 * st * ct * v[1];
  }
  if (what & DM_LAG_QQ) {
    o->Lqq[0] = l2 * (ct * ct - st * st) * v[1] * v[1] - g * l * ct;
    o->Lqq[1] = o->Lqq[2] = o->Lqq[3] = 0.0;
  }
  return 0;
}

int dm_builtin_spherical_pendulum(dm_system *s, double g, double l, double m, dm_err *e)
{
  static const char *const cn[] = {"theta", "phi"};
  static const char *const pn[] = {"g", "l", "m"};
  double par[3] = {g, l, m};
  return setup(s, "spherical pendulum", 2, 0, cn, pn, 3, par,
               DM_SYS_MECHANICAL, sph_lag, e);
}
