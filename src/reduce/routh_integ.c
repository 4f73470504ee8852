/* routh_integ.c -- the integrator families of reduced systems (kind
 * DM_ROUTH_KIND, the reduced system of a dm_routh; routh.h), registered
 * with the integrator registry by dm_routh_register_integrators:
 *   rsprk      gauss | midpoint | lobatto | trapezoid | prk: RSPRK (rsprk.c)
 *   dr         dr[:midpoint | :gauss | :lobatto]: discrete Routh equations
 *   classical  classical[:gauss | midpoint | lobatto | trapezoid | prk]: the
 *              core PRK engine on the classical Routhian Rc, wrapped by the
 *              momentum shift sigma(x, s) = (x, s + muA(x)).
 * State (q, p) = (x, s) for all of them.  The group coordinate is
 * accumulated per step with compensated summation (reconstruction). */
#include <config.h>
#include "reduce/rsprk_impl.h"
#include "core/interrupt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { K_RSPRK, K_DR, K_CLASSICAL, K_ODE };
static const char *const kind_names[] = {"rsprk", "dr", "classical", "ode"};

typedef struct rinteg {
  int kind;
  dm_routh *red;
  dm_rsprk *P;
  dm_routh_dr *dr;               /* DR method, or psi for classical */
  dm_integrator *inner;          /* classical */
  dm_rode *ode;                  /* rk4, gsl:<stepper> */
  int have_theta;
  double theta[DM_ROUTH_RMAX], ctheta[DM_ROUTH_RMAX], dth[DM_ROUTH_RMAX];
  /* classical: last output in both momentum charts (exact continuation) */
  int last_valid;
  double *x0c, *y0, *y1, *xl, *sl, *yl, *a;
  double *tin, *tout, *twork;
  double sing_ref;
} rinteg;

static const dm_integrator_type rsprk_type, dr_type, classical_type, ode_type;

static const char *const routh_options[] = {"stages", "h", "tol", "maxiter", "simplified", NULL};
/* RSPRK and classical also take a user tableau (method prk) */
static const char *const tableau_options[] = {"stages", "h", "tol", "maxiter", "simplified",
                                              "tableau", "linear", "iteration", NULL};
static const char *const routh_kinds[] = {DM_ROUTH_KIND, NULL};
static const char *const rsprk_names[] = {"gauss", "midpoint", "lobatto", "trapezoid", "prk", NULL};
static const char *const ode_names[] = {"rk4", NULL};
static const char *const ode_options[] = {"h", NULL};

/* muA(x) with the tape of gyro_r at zero velocity */
static int muA_at(rinteg *R, const double *x, double *a, dm_err *e)
{
  if (dm_routh_muA(R->red, x, a, R->tin, R->tout, R->twork))
    return dm_err_set(e, DM_EDOM, "mu^T A is not finite at this point");
  return DM_OK;
}

static int make_tableau(const char *fam, const dm_integ_opts *o, dm_tableau **t, dm_err *e)
{
  *t = NULL;
  if (o->tableau != NULL && strcmp(fam, "prk") != 0)
    return dm_err_set(e, DM_EINVAL, "option 'tableau' is for method 'prk' (got method '%s')", fam);
  if (strcmp(fam, "gauss") == 0)
    return dm_tableau_gauss(o->stages ? (size_t)o->stages : 2, t, e);
  if (strcmp(fam, "midpoint") == 0) {
    if (o->stages > 1)
      return dm_err_set(e, DM_EINVAL, "midpoint has exactly 1 stage (got stages = %d)", o->stages);
    return dm_tableau_gauss(1, t, e);
  }
  if (strcmp(fam, "lobatto") == 0)
    return dm_tableau_lobatto(o->stages ? (size_t)o->stages : 3, t, e);
  if (strcmp(fam, "trapezoid") == 0)
    return dm_tableau_lobatto(2, t, e);
  if (strcmp(fam, "prk") == 0) {
    if (o->tableau == NULL)
      return dm_err_set(e, DM_EINVAL, "method 'prk' needs a tableau");
    if ((*t = dm_tableau_copy(o->tableau)) == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory");
    return DM_OK;
  }
  return dm_err_set(e, DM_ENOTFOUND, "unknown reduced method '%s' (known: gauss, midpoint, lobatto, "
                    "trapezoid, prk, dr, dr:gauss, dr:lobatto, classical, classical:<gauss|midpoint|"
                    "lobatto|trapezoid|prk>)", fam);
}

static void rinteg_free(dm_integrator *I)
{
  rinteg *R = I->state;
  if (R == NULL)
    return;
  dm_rsprk_free(R->P);
  dm_routh_dr_free(R->dr);
  dm_integrator_free(R->inner);
  dm_rode_free(R->ode);
  free(R->x0c);
  free(R);
  I->state = NULL;
}

static int alloc_buffers(rinteg *R)
{
  const dm_routh *red = R->red;
  size_t d = red->s, nout = red->gyro_r.nout;
  R->x0c = calloc(7 * d + 2 * d + nout + red->nwork + red->r * red->r + 8, sizeof(double));
  if (R->x0c == NULL)
    return DM_ENOMEM;
  R->y0 = R->x0c + d;
  R->y1 = R->y0 + d;
  R->xl = R->y1 + d;
  R->sl = R->xl + d;
  R->yl = R->sl + d;
  R->a = R->yl + d;
  R->tin = R->a + d;
  R->tout = R->tin + 2 * d;
  R->twork = R->tout + nout;
  return DM_OK;
}

static int alloc_classical(dm_integrator *I, rinteg *R, const char *sub, dm_err *e)
{
  dm_tableau *t = NULL;
  int st = make_tableau(sub, &I->opt, &t, e);
  dm_err e2;
  if (st != DM_OK)
    return st;
  st = dm_integrator_new(&R->red->csys, sub, &I->opt, &R->inner, e);
  if (st == DM_OK) {
    I->order = R->inner->order;
    I->flags = (R->inner->flags & (DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_EXACT_JAC))
               | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS;
    /* theta by psi_mu of the same Galerkin L_d (unforced, unconstrained) */
    R->have_theta = dm_routh_dr_alloc(R->red, strcmp(sub, "midpoint") == 0 ? NULL : t, I->opt.tol,
                                      I->opt.maxiter, &R->dr, &e2) == DM_OK;
  }
  dm_tableau_free(t);
  return st;
}

/* The state every reduced family starts from. */
static int rinteg_new(dm_integrator *I, int kind, rinteg **out, dm_err *e)
{
  rinteg *R;
  dm_routh *red;
  *out = NULL;
  if (!dm_routh_of_system(I->sys, &red))
    return dm_err_set(e, DM_EINVAL, "method '%s' needs the reduced system of a Routh reduction "
                      "(dm_routh_system)", I->name);
  if ((R = calloc(1, sizeof *R)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  I->state = R;
  R->kind = kind;
  R->red = red;
  if (alloc_buffers(R) != DM_OK)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  I->flags = DM_INTEG_SYMPLECTIC | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS;
  *out = R;
  return DM_OK;
}

/* "gauss", ... or "rsprk[:<tableau family>]" (default gauss) */
static int rsprk_alloc(dm_integrator *I, dm_err *e)
{
  int own = strcmp(I->name, "rsprk") == 0 || strncmp(I->name, "rsprk:", 6) == 0;
  const char *fam = !own ? I->name : I->variant[0] ? I->variant : "gauss";
  dm_tableau *t = NULL;
  rinteg *R;
  int st;
  int linear = dm_linear_mode_parse(I->opt.linear);
  const char *it = I->opt.iteration;
  if (linear < 0)
    return dm_err_set(e, DM_EINVAL, "option 'linear' must be \"auto\", \"dense\" or "
                      "\"sparse\", got \"%s\"", I->opt.linear);
  if (it[0] != '\0' && strcmp(it, "auto") != 0 && strcmp(it, "newton") != 0
      && strcmp(it, "fixed") != 0)
    return dm_err_set(e, DM_EINVAL, "option 'iteration' must be \"auto\", \"newton\" or "
                      "\"fixed\", got \"%s\"", it);
  if ((st = rinteg_new(I, K_RSPRK, &R, e)) != DM_OK)
    return st;
  if (!R->red->general && strcmp(it, "fixed") == 0)
    return dm_err_set(e, DM_EINVAL, "iteration = \"fixed\" needs a separable Lagrangian "
                      "1/2 v^T M v - V(q) without forces or constraints: the reduced stage "
                      "equations (RSPRK) carry the connection terms and are solved by Newton");
  if (R->red->general) {
    /* no connection, no RSPRK stage programs: with the momentum shift the
     * identity, RSPRK is the same method on the classical Routhian */
    R->kind = K_CLASSICAL;
    if ((st = alloc_classical(I, R, fam, e)) == DM_OK)
      I->stages = R->inner->stages;
    return st;
  }
  if ((st = make_tableau(fam, &I->opt, &t, e)) != DM_OK)
    return st;
  st = dm_rsprk_alloc(R->red, t, I->opt.tol, I->opt.maxiter, I->opt.simplified, linear, &R->P,
                      e);
  if (st == DM_OK) {
    I->stats.linear = dm_rsprk_linear(R->P, &I->stats.nnz);
    I->order = t->order;
    I->stages = (int)t->s;
    if (t->flags & DM_TAB_SYMMETRIC)
      I->flags |= DM_INTEG_SYMMETRIC;
    if (R->red->m == 0)
      I->flags |= DM_INTEG_EXACT_JAC;
    if (!(t->flags & DM_TAB_SYMPLECTIC))
      I->flags &= ~(unsigned)DM_INTEG_SYMPLECTIC;
    R->have_theta = 1;
  }
  dm_tableau_free(t);
  return st;
}

/* "dr" (= "dr:midpoint"), "dr:gauss", "dr:lobatto" */
static int dr_alloc(dm_integrator *I, dm_err *e)
{
  const char *sub = I->variant[0] ? I->variant : "midpoint";
  dm_tableau *t = NULL;
  rinteg *R;
  int st;
  if ((st = rinteg_new(I, K_DR, &R, e)) != DM_OK)
    return st;
  if (strcmp(sub, "midpoint") != 0 && (st = make_tableau(sub, &I->opt, &t, e)) != DM_OK)
    return st;
  if (strcmp(sub, "prk") == 0 || strcmp(sub, "trapezoid") == 0) {
    dm_tableau_free(t);
    return dm_err_set(e, DM_EUNSUP, "dr: discrete Lagrangians are midpoint, gauss or lobatto "
                      "(Galerkin), got '%s'", sub);
  }
  st = dm_routh_dr_alloc(R->red, t, I->opt.tol, I->opt.maxiter, &R->dr, e);
  I->order = t ? t->order : 2;
  I->stages = t ? (int)t->s : 1;
  dm_tableau_free(t);
  R->have_theta = 1;
  I->flags |= DM_INTEG_EXACT_JAC;
  if (st == DM_OK && t == NULL)
    I->flags |= DM_INTEG_SYMMETRIC;
  return st;
}

/* "classical" (= "classical:gauss"), "classical:<core method>" */
static int classical_alloc(dm_integrator *I, dm_err *e)
{
  rinteg *R;
  int st;
  if ((st = rinteg_new(I, K_CLASSICAL, &R, e)) != DM_OK)
    return st;
  if ((st = alloc_classical(I, R, I->variant[0] ? I->variant : "gauss", e)) == DM_OK)
    I->stages = R->inner->stages;
  return st;
}

/* "rk4" (= "gsl:rk4"), "gsl:<explicit stepper>": the continuous Routh
 * equations, theta integrated along (routh_ode.c) */
static int ode_alloc(dm_integrator *I, dm_err *e)
{
  const char *stepper = strcmp(I->name, "rk4") == 0 ? "rk4" : I->variant;
  rinteg *R;
  int st;
  if ((st = rinteg_new(I, K_ODE, &R, e)) != DM_OK)
    return st;
  if (stepper[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "name the stepper: gsl:rk4, gsl:rk8pd, ...");
  if ((st = dm_rode_alloc(R->red, stepper, &R->ode, &I->order, e)) != DM_OK)
    return st;
  /* mechanical: xdot = Mtilde^{-1} s, no nonlinear solve */
  I->flags = DM_INTEG_FORCES | (R->red->general ? 0u : (unsigned)DM_INTEG_EXPLICIT);
  R->have_theta = 1;
  return DM_OK;
}

static void add_theta(rinteg *R)
{
  size_t a;
  for (a = 0; a < R->red->r; a++) {
    double y = R->dth[a] - R->ctheta[a];
    double t = R->theta[a] + y;
    R->ctheta[a] = (t - R->theta[a]) - y;
    R->theta[a] = t;
  }
}

static int classical_step(dm_integrator *I, rinteg *R, double h, const double *x0,
                          const double *s0, double *x1, double *s1, dm_err *e)
{
  size_t d = R->red->s, i;
  int st;
  if (R->last_valid && memcmp(x0, R->xl, d * sizeof(double)) == 0
      && memcmp(s0, R->sl, d * sizeof(double)) == 0) {
    memcpy(R->y0, R->yl, d * sizeof(double));
  } else {
    if ((st = dm_routh_check_inertia(R->red, x0, &R->sing_ref, R->twork, "the initial point", e))
        != DM_OK || (st = muA_at(R, x0, R->a, e)) != DM_OK)
      return st;
    for (i = 0; i < d; i++)
      R->y0[i] = s0[i] + R->a[i];
  }
  memcpy(R->x0c, x0, d * sizeof(double));
  R->last_valid = 0;
  if ((st = dm_integrator_step(R->inner, h, R->x0c, R->y0, x1, R->y1, e)) != DM_OK)
    return st;
  I->stats = R->inner->stats;
  if ((st = dm_routh_check_inertia(R->red, x1, &R->sing_ref, R->twork, "the end point", e)) != DM_OK
      || (st = muA_at(R, x1, R->a, e)) != DM_OK)
    return st;
  for (i = 0; i < d; i++)
    s1[i] = R->y1[i] - R->a[i];
  if (R->have_theta && (st = dm_routh_dr_psi(R->dr, h, R->x0c, x1, R->dth, NULL, e)) != DM_OK)
    return st;
  memcpy(R->xl, x1, d * sizeof(double));
  memcpy(R->sl, s1, d * sizeof(double));
  memcpy(R->yl, R->y1, d * sizeof(double));
  R->last_valid = 1;
  return DM_OK;
}

static void zero_dtheta(rinteg *R)
{
  size_t a;
  for (a = 0; a < R->red->r; a++)
    R->dth[a] = 0.0;
}

static int ode_step(dm_integrator *I, double h, const double *q0, const double *p0, double *q1,
                    double *p1, dm_err *e)
{
  rinteg *R = I->state;
  int st;
  zero_dtheta(R);
  if ((st = dm_rode_step(R->ode, h, q0, p0, q1, p1, R->dth, e)) == DM_OK) {
    I->stats.steps++;
    add_theta(R);
  }
  return st;
}

static int classical_type_step(dm_integrator *I, double h, const double *q0, const double *p0,
                               double *q1, double *p1, dm_err *e);

static int rsprk_step(dm_integrator *I, double h, const double *q0, const double *p0, double *q1,
                      double *p1, dm_err *e)
{
  rinteg *R = I->state;
  int st;
  if (R->kind == K_CLASSICAL)          /* a general reduction (see rsprk_alloc) */
    return classical_type_step(I, h, q0, p0, q1, p1, e);
  zero_dtheta(R);
  if ((st = dm_rsprk_step(R->P, h, q0, p0, q1, p1, R->dth, &I->stats, e)) == DM_OK)
    add_theta(R);
  return st;
}

static int dr_step(dm_integrator *I, double h, const double *q0, const double *p0, double *q1,
                   double *p1, dm_err *e)
{
  rinteg *R = I->state;
  int st;
  zero_dtheta(R);
  if ((st = dm_routh_dr_step(R->dr, h, q0, p0, q1, p1, R->dth, e)) == DM_OK) {
    I->stats.iters = dm_routh_dr_iters(R->dr);
    I->stats.iters_total += I->stats.iters;
    I->stats.steps++;
    add_theta(R);
  }
  return st;
}

static int classical_type_step(dm_integrator *I, double h, const double *q0, const double *p0,
                               double *q1, double *p1, dm_err *e)
{
  rinteg *R = I->state;
  int st;
  zero_dtheta(R);
  if ((st = classical_step(I, R, h, q0, p0, q1, p1, e)) == DM_OK)
    add_theta(R);
  return st;
}

/* classical: D(x1, s1)/D(x0, s0) = Dsigma^{-1}(x1) DPhi_c Dsigma(x0),
 * Dsigma = [[Id, 0], [K, Id]], K = d muA/dx */
static int classical_jacobian(dm_integrator *I, rinteg *R, double h, const double *x0,
                              const double *s0, double *DPhi, dm_err *e)
{
  const dm_routh *red = R->red;
  size_t d = red->s, N = 2 * d, i, j, k;
  double *K0 = malloc((2 * d * d + N * N + 3 * d) * sizeof(double)), *K1, *Dc, *x1, *y0, *a;
  int st = DM_OK;
  if (K0 == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  K1 = K0 + d * d;
  Dc = K1 + d * d;
  x1 = Dc + N * N;
  y0 = x1 + d;
  a = y0 + d;
  (void)I;
  if (dm_routh_muA_K(red, x0, a, K0, R->tin, R->twork))
    st = dm_err_set(e, DM_EDOM, "mu^T A is not finite at this point");
  for (i = 0; i < d; i++)
    y0[i] = s0[i] + a[i];
  if (st == DM_OK && (st = dm_integrator_jacobian(R->inner, h, x0, y0, Dc, e)) == DM_OK) {
    double *yy = malloc(d * sizeof(double));
    if (yy == NULL)
      st = dm_err_set(e, DM_ENOMEM, "out of memory");
    if (st == DM_OK)
      st = dm_integrator_step(R->inner, h, x0, y0, x1, yy, e);
    free(yy);
  }
  if (st == DM_OK && dm_routh_muA_K(red, x1, a, K1, R->tin, R->twork))
    st = dm_err_set(e, DM_EDOM, "mu^T A is not finite at this point");
  if (st == DM_OK) {
    /* right: columns of the x0 block get + Dc[:, d + k] K0[k][j] */
    for (i = 0; i < N; i++)
      for (j = 0; j < d; j++) {
        double acc = Dc[i * N + j];
        for (k = 0; k < d; k++)
          acc += Dc[i * N + d + k] * K0[k * d + j];
        DPhi[i * N + j] = acc;
      }
    for (i = 0; i < N; i++)
      for (j = d; j < N; j++)
        DPhi[i * N + j] = Dc[i * N + j];
    /* left: s rows -= K1 x rows */
    for (i = 0; i < d; i++)
      for (j = 0; j < N; j++) {
        double acc = 0.0;
        for (k = 0; k < d; k++)
          acc += K1[i * d + k] * DPhi[k * N + j];
        Dc[i * N + j] = DPhi[(d + i) * N + j] - acc;
      }
    for (i = 0; i < d; i++)
      for (j = 0; j < N; j++)
        DPhi[(d + i) * N + j] = Dc[i * N + j];
  }
  R->last_valid = 0;
  free(K0);
  return st;
}

static int rsprk_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                          double *DPhi, dm_err *e)
{
  rinteg *R = I->state;
  if (R->kind == K_CLASSICAL)
    return classical_jacobian(I, R, h, q0, p0, DPhi, e);
  return dm_rsprk_jacobian(R->P, h, q0, p0, DPhi, &I->stats, e);
}

static int dr_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                       double *DPhi, dm_err *e)
{
  rinteg *R = I->state;
  return dm_routh_dr_jacobian(R->dr, h, q0, p0, DPhi, e);
}

static int classical_type_jacobian(dm_integrator *I, double h, const double *q0,
                                   const double *p0, double *DPhi, dm_err *e)
{
  return classical_jacobian(I, I->state, h, q0, p0, DPhi, e);
}

static void routh_reset(dm_integrator *I)
{
  rinteg *R = I->state;
  if (R->P)
    dm_rsprk_reset(R->P);
  if (R->inner)
    dm_integrator_reset(R->inner);
  R->last_valid = 0;
  R->sing_ref = 0.0;
  if (R->ode)
    dm_rode_reset(R->ode);
}

static const dm_integrator_type rsprk_type = {
  .name = "rsprk",
  .summary = "reduced symplectic PRK (RSPRK) on the shape space of a Routh reduction: gauss "
    "(stages, default 2), midpoint, lobatto (stages, default 3), trapezoid, prk (tableau); the "
    "magnetic term in the Newton matrix",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = tableau_options,
  .alloc = rsprk_alloc,
  .step = rsprk_step,
  .jacobian = rsprk_jacobian,
  .reset = routh_reset,
  .free = rinteg_free,
  .kinds = routh_kinds,
  .names = rsprk_names,
};

static const dm_integrator_type dr_type = {
  .name = "dr",
  .summary = "discrete Routh equations of a Routh reduction: dr (midpoint L_d), dr:gauss, "
    "dr:lobatto (Galerkin L_d, stages); no forces or constraints",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = routh_options,
  .alloc = dr_alloc,
  .step = dr_step,
  .jacobian = dr_jacobian,
  .reset = routh_reset,
  .free = rinteg_free,
  .kinds = routh_kinds,
};

static const dm_integrator_type classical_type = {
  .name = "classical",
  .summary = "SPRK of the classical Routhian of a Routh reduction with the momentum shift: "
    "classical (= classical:gauss), classical:<gauss|midpoint|lobatto|trapezoid|prk>",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS | DM_INTEG_EXACT_JAC,
  .options = tableau_options,
  .alloc = classical_alloc,
  .step = classical_type_step,
  .jacobian = classical_type_jacobian,
  .reset = routh_reset,
  .free = rinteg_free,
  .kinds = routh_kinds,
};

static const dm_integrator_type ode_type = {
  .name = "gsl",
  .summary = "the continuous Routh equations (non-symplectic references) of a Routh reduction: "
    "rk4 (= gsl:rk4), gsl:<rk2|rkf45|rkck|rk8pd>; theta integrated along",
  .order = 0,
  .flags = DM_INTEG_FORCES,
  .options = ode_options,
  .alloc = ode_alloc,
  .step = ode_step,
  .reset = routh_reset,
  .free = rinteg_free,
  .kinds = routh_kinds,
  .names = ode_names,
};

/* {==== public helpers =================================================== */

int dm_routh_register_integrators(dm_err *e)
{
  const dm_integrator_type *const types[] = {&rsprk_type, &dr_type, &classical_type, &ode_type};
  size_t i;
  int st = DM_OK;
  for (i = 0; i < 4 && st == DM_OK; i++)
    st = dm_integrator_register(types[i], e);
  return st;
}

int dm_routh_integrator_new(dm_routh *red, const char *method, const dm_integ_opts *opts,
                            dm_integrator **out, dm_err *e)
{
  int st;
  *out = NULL;
  if (red == NULL || method == NULL)
    return dm_err_set(e, DM_EINVAL, "reduced integrator: no reduction or method");
  if ((st = dm_routh_register_integrators(e)) != DM_OK)
    return st;
  return dm_integrator_new(&red->sys, method, opts, out, e);
}

int dm_routh_is_integrator(const dm_integrator *I)
{
  return I != NULL && I->state != NULL
         && (I->type == &rsprk_type || I->type == &dr_type || I->type == &classical_type
             || I->type == &ode_type);
}

int dm_routh_integrator_theta(const dm_integrator *I, double *theta, dm_err *e)
{
  const rinteg *R;
  if (!dm_routh_is_integrator(I))
    return dm_err_set(e, DM_EINVAL, "not a reduced (routh) integrator");
  R = I->state;
  if (!R->have_theta)
    return dm_err_set(e, DM_EUNSUP, "this reduced integrator cannot reconstruct the group "
                      "coordinate (classical Routhian with forces or constraints)");
  memcpy(theta, R->theta, R->red->r * sizeof(double));
  return DM_OK;
}

int dm_routh_integrator_set_theta(dm_integrator *I, const double *theta, dm_err *e)
{
  rinteg *R;
  if (!dm_routh_is_integrator(I))
    return dm_err_set(e, DM_EINVAL, "not a reduced (routh) integrator");
  R = I->state;
  memcpy(R->theta, theta, R->red->r * sizeof(double));
  memset(R->ctheta, 0, sizeof R->ctheta);
  return DM_OK;
}

const char *dm_routh_integrator_kind(const dm_integrator *I)
{
  if (!dm_routh_is_integrator(I))
    return NULL;
  return kind_names[((const rinteg *)I->state)->kind];
}

int dm_routh_symplecticity_defect(dm_integrator *I, double h, const double *x0, const double *s0,
                                  double *defect, dm_err *e)
{
  rinteg *R;
  dm_routh *red;
  size_t d, N, i, j, k;
  double *D, *W0, *W1, *T, *x1, *s1, th[DM_ROUTH_RMAX], ct[DM_ROUTH_RMAX], worst = 0.0, wmax = 1.0;
  dm_routh_vals v;
  int st;
  if (!dm_routh_is_integrator(I))
    return dm_err_set(e, DM_EINVAL, "not a reduced (routh) integrator");
  R = I->state;
  red = R->red;
  d = red->s;
  N = 2 * d;
  if ((D = malloc((4 * N * N + 2 * d) * sizeof(double))) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  W0 = D + N * N;
  W1 = W0 + N * N;
  T = W1 + N * N;
  x1 = T + N * N;
  s1 = x1 + d;
  memcpy(th, R->theta, sizeof th);
  memcpy(ct, R->ctheta, sizeof ct);
  st = dm_integrator_jacobian(I, h, x0, s0, D, e);
  if (st == DM_OK)
    st = dm_integrator_step(I, h, x0, s0, x1, s1, e);
  memcpy(R->theta, th, sizeof th);
  memcpy(R->ctheta, ct, sizeof ct);
  memset(&v, 0, sizeof v);
  memset(W0, 0, 2 * N * N * sizeof(double));
  for (k = 0; st == DM_OK && k < 2; k++) {
    double *W = k ? W1 : W0;
    v.B = T;
    if (red->general)            /* (x, p_x) canonical: no magnetic term */
      memset(T, 0, d * d * sizeof(double));
    else if ((st = dm_routh_eval(red, k ? x1 : x0, NULL, &v, e)) != DM_OK)
      break;
    for (i = 0; i < d; i++)
      for (j = 0; j < d; j++)
        W[i * N + j] = -T[i * d + j];
    for (i = 0; i < d; i++) {
      W[i * N + d + i] = 1.0;
      W[(d + i) * N + i] = -1.0;
    }
  }
  if (st == DM_OK) {
    /* T = W1 D, then D^T T - W0 */
    for (i = 0; i < N; i++)
      for (j = 0; j < N; j++) {
        double acc = 0.0;
        for (k = 0; k < N; k++)
          acc += W1[i * N + k] * D[k * N + j];
        T[i * N + j] = acc;
      }
    for (i = 0; i < N * N; i++)
      wmax = fmax(wmax, fabs(W0[i]));
    for (i = 0; i < N; i++)
      for (j = 0; j < N; j++) {
        double acc = 0.0;
        for (k = 0; k < N; k++)
          acc += D[k * N + i] * T[k * N + j];
        worst = fmax(worst, fabs(acc - W0[i * N + j]));
      }
    *defect = worst / wmax;
  }
  free(D);
  return st;
}
