/* adapt.c -- time-transformed integrators "adapt:<method>": the Poincare
 * transformation as a Lagrangian system of (q, t) that any registered
 * method integrates, and the explicit path for separable systems with the
 * potential's monitor.  See adapt.h and doc/beyond-fixed-steps.md §3. */
#include <config.h>
#include "integrators/adapt_impl.h"
#include "core/interrupt.h"
#include "core/numfmt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* {==== the monitor ===================================================== */

/* U = L(q, 0) = -V and its derivatives (potential's monitor). */
int dm_adapt_potential_eval(const tt_data *d, const double *q, const double *par, unsigned what,
                            double *U, double *Uq, double *Uqq, tt_scratch *s, void *bwork)
{
  dm_lag_out o = {0, Uq, s->Lv, s->Lvv, s->Lvq, Uqq};
  unsigned lw = DM_LAG_L | ((what & DM_MON_GRAD) ? DM_LAG_Q : 0)
                | ((what & DM_MON_HESS) ? DM_LAG_ALL : 0);
  int rc;
  memset(s->z, 0, d->n * sizeof *s->z);
  if ((rc = d->base->lagrangian(d->base->data, q, s->z, par, lw, &o, bwork)) != 0)
    return rc;
  *U = o.L;
  return 0;
}

/* g, gq, gqq of the monitor at q (what: DM_MON_* bits); > 0 outside the
 * domain (g not finite and positive; U <= 0). */
static int monitor_eval(const tt_data *d, const double *q, const double *par, unsigned what,
                        double *g, double *gq, double *gqq, void *work)
{
  tt_scratch s;
  size_t n = d->n, i, j;
  int rc;
  tt_layout(d, work, &s);
  if (d->mon != NULL) {
    rc = d->mon->eval(d->mon->data, q, par, what, g, gq, gqq, (char *)work + d->mwork_off);
    if (rc != 0)
      return rc;
    return isfinite(*g) && *g > 0.0 ? 0 : 1;
  }
  /* g = (U0/U)^a: gq = -a g Uq/U, gqq = a(a+1) g Uq Uq^T/U^2 - a g Uqq/U */
  double U, a = d->power;
  if ((rc = dm_adapt_potential_eval(d, q, par, what, &U, s.uq, s.uqq, &s, tt_bwork(d, work))) != 0)
    return rc;
  if (!(U > 0.0) || !isfinite(U))
    return 1;
  *g = a == 1.5 ? d->U0 / U * sqrt(d->U0 / U) : a == 1.0 ? d->U0 / U : pow(d->U0 / U, a);
  if (!isfinite(*g) || !(*g > 0.0))
    return 1;
  if (what & DM_MON_GRAD)
    for (i = 0; i < n; i++)
      gq[i] = -a * *g * s.uq[i] / U;
  if (what & DM_MON_HESS)
    for (i = 0; i < n; i++)
      for (j = 0; j < n; j++)
        gqq[i * n + j] = a * (a + 1.0) * *g * s.uq[i] * s.uq[j] / (U * U)
                         - a * *g * s.uqq[i * n + j] / U;
  return 0;
}

/* }====================================================================== */

/* {==== the transformed Lagrangian ======================================= */

/* L~(q, t, w, s) = g (L(q, u) + E0) + pi^2/2, u = w/g, pi = s - g, where the
 * derivatives follow from the chain rule with E = Lv.u - L (doc/beyond-fixed-steps.md
 * §3.2):
 *   L~_q  = g Lq - gq (E - E0) - pi gq,     L~_w = Lv,   L~_s = pi,
 *   L~_ww = Lvv/g,  L~_ss = 1,  L~_wq = Lvq - (Lvv u) gq^T/g,  L~_sq = -gq,
 *   L~_qq = g Lqq + gq (Lq - a)^T + (Lq - a) gq^T + c gq gq^T/g
 *           - gqq (E - E0 + pi) + gq gq^T,   a = Lvq^T u, c = u.Lvv u. */
static int tt_lagrangian(void *data, const double *qa, const double *va, const double *par,
                         unsigned what, dm_lag_out *out, void *work)
{
  const tt_data *d = data;
  size_t n = d->n, N = n + 1, i, j;
  tt_scratch s;
  double g, pi, E, c = 0.0;
  unsigned mw = DM_MON_G, bw = 0;
  int rc;
  tt_layout(d, work, &s);
  if (what & (DM_LAG_Q | DM_LAG_VQ | DM_LAG_QQ))
    mw |= DM_MON_GRAD;
  if (what & DM_LAG_QQ)
    mw |= DM_MON_HESS;
  if ((rc = monitor_eval(d, qa, par, mw, &g, s.gq, s.gqq, work)) != 0)
    return rc;
  for (i = 0; i < n; i++)
    s.u[i] = va[i] / g;
  pi = va[n] - g;
  if (what & DM_LAG_L)
    bw |= DM_LAG_L;
  if (what & DM_LAG_Q)
    bw |= DM_LAG_L | DM_LAG_Q | DM_LAG_V;
  if (what & DM_LAG_V)
    bw |= DM_LAG_V;
  if (what & DM_LAG_VV)
    bw |= DM_LAG_VV;
  if (what & DM_LAG_VQ)
    bw |= DM_LAG_VQ | DM_LAG_VV;
  if (what & DM_LAG_QQ)
    bw |= DM_LAG_ALL;
  dm_lag_out o = {0, s.Lq, s.Lv, s.Lvv, s.Lvq, s.Lqq};
  if ((rc = d->base->lagrangian(d->base->data, qa, s.u, par, bw, &o, tt_bwork(d, work))) != 0)
    return rc;
  E = -o.L;
  if (bw & DM_LAG_V)
    for (i = 0; i < n; i++)
      E += s.Lv[i] * s.u[i];
  if (what & DM_LAG_L)
    out->L = g * (o.L + d->E0) + 0.5 * pi * pi;
  if (what & DM_LAG_Q) {
    for (i = 0; i < n; i++)
      out->Lq[i] = g * s.Lq[i] - s.gq[i] * (E - d->E0 + pi);
    out->Lq[n] = 0.0;
  }
  if (what & DM_LAG_V) {
    for (i = 0; i < n; i++)
      out->Lv[i] = s.Lv[i];
    out->Lv[n] = pi;
  }
  if (what & DM_LAG_VV) {
    for (i = 0; i < n; i++) {
      for (j = 0; j < n; j++)
        out->Lvv[i * N + j] = s.Lvv[i * n + j] / g;
      out->Lvv[i * N + n] = out->Lvv[n * N + i] = 0.0;
    }
    out->Lvv[n * N + n] = 1.0;
  }
  if (what & (DM_LAG_VQ | DM_LAG_QQ))       /* Lvv u */
    for (i = 0; i < n; i++) {
      double acc = 0.0;
      for (j = 0; j < n; j++)
        acc += s.Lvv[i * n + j] * s.u[j];
      s.a[i] = acc;
    }
  if (what & DM_LAG_VQ) {
    for (i = 0; i < n; i++) {
      for (j = 0; j < n; j++)
        out->Lvq[i * N + j] = s.Lvq[i * n + j] - s.a[i] * s.gq[j] / g;
      out->Lvq[i * N + n] = 0.0;
    }
    for (j = 0; j < n; j++)
      out->Lvq[n * N + j] = -s.gq[j];
    out->Lvq[n * N + n] = 0.0;
  }
  if (what & DM_LAG_QQ) {
    for (i = 0; i < n; i++)
      c += s.u[i] * s.a[i];
    for (j = 0; j < n; j++) {             /* a := Lq - Lvq^T u */
      double acc = 0.0;
      for (i = 0; i < n; i++)
        acc += s.Lvq[i * n + j] * s.u[i];
      s.z[j] = s.Lq[j] - acc;
    }
    for (i = 0; i < n; i++) {
      for (j = 0; j < n; j++)
        out->Lqq[i * N + j] = g * s.Lqq[i * n + j] + s.gq[i] * s.z[j] + s.z[i] * s.gq[j]
                              + (c / g + 1.0) * s.gq[i] * s.gq[j]
                              - s.gqq[i * n + j] * (E - d->E0 + pi);
      out->Lqq[i * N + n] = out->Lqq[n * N + i] = 0.0;
    }
    out->Lqq[n * N + n] = 0.0;
  }
  return 0;
}

/* The base's constraints, with a zero column for t. */
static int tt_constraints(void *data, const double *qa, const double *par, unsigned what,
                          double *gc, double *G, double *H, void *work)
{
  const tt_data *d = data;
  size_t n = d->n, N = n + 1, m = d->m, a, i, j;
  tt_scratch s;
  int rc;
  tt_layout(d, work, &s);
  rc = d->base->constraints(d->base->data, qa, par, what, gc, s.Gs, s.Hs, tt_bwork(d, work));
  if (rc != 0)
    return rc;
  if (what & DM_CONSTR_DG)
    for (a = 0; a < m; a++) {
      for (j = 0; j < n; j++)
        G[a * N + j] = s.Gs[a * n + j];
      G[a * N + n] = 0.0;
    }
  if (what & DM_CONSTR_D2G)
    for (a = 0; a < m; a++)
      for (i = 0; i < N; i++)
        for (j = 0; j < N; j++)
          H[(a * N + i) * N + j] = i < n && j < n ? s.Hs[(a * n + i) * n + j] : 0.0;
  return 0;
}

static int tt_update(const dm_system *sys)
{
  const tt_data *d = sys->data;
  return d->base->update != NULL ? d->base->update(d->base) : 0;
}

/* }====================================================================== */

/* {==== the family ======================================================= */


static const char *const adapt_options[] = {"stages", "h", "tol", "maxiter", "simplified",
                                            "order", "scheme", "base", "explicit", "tableau",
                                            NULL};

static void adapt_free(dm_integrator *I)
{
  adapt_state *A = I->state;
  if (A == NULL)
    return;
  dm_integrator_free(A->inner);
  free(A->names);
  free(A->qa);
  free(A->F);
  free(A->work);
  free(A);
  I->state = NULL;
}

static int adapt_alloc(dm_integrator *I, dm_err *e)
{
  const dm_system *sys = I->sys;
  size_t n = I->n, N = n + 1, i, bytes;
  adapt_state *A;
  dm_integ_opts o = I->opt;
  int st;
  if (!I->variant[0])
    return dm_err_set(e, DM_EINVAL, "adapt: name the method to transform, adapt:<method> "
                      "(e.g. adapt:gauss)");
  if (strncmp(I->variant, "adapt", 5) == 0)
    return dm_err_set(e, DM_EINVAL, "adapt: a time transformation of a time transformation "
                      "('%s') is not a method", I->name);
  if (sys->force != NULL)
    return dm_err_set(e, DM_EUNSUP, "adapt: the time transformation keeps the energy level of "
                      "the start, which a generalized force changes: '%s' has a force",
                      sys->name ? sys->name : "system");
  if ((A = calloc(1, sizeof *A)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "adapt: out of memory");
  I->state = A;
  A->N = N;
  A->td.base = sys;
  A->td.n = n;
  A->td.m = sys->m;
  A->td.mon = I->opt.monitor;
  A->td.power = I->opt.power;
  A->td.E0 = NAN;
  A->td.U0 = NAN;
  A->td.nd = tt_ndoubles(n, sys->m);
  A->td.bwork_off = A->td.nd * sizeof(double);
  A->td.mwork_off = A->td.bwork_off + ((sys->work_size + 15) & ~(size_t)15);
  bytes = A->td.mwork_off + (A->td.mon ? A->td.mon->work_size : 0);
  A->names = calloc(N, sizeof *A->names);
  A->qa = calloc(4 * N + 2 * n + 4 * N * N, sizeof(double));
  A->work = calloc(1, bytes);
  if (A->names == NULL || A->qa == NULL || A->work == NULL) {
    adapt_free(I);
    return dm_err_set(e, DM_ENOMEM, "adapt: out of memory");
  }
  A->pa = A->qa + N;
  A->qa1 = A->pa + N;
  A->pa1 = A->qa1 + N;
  A->sq = A->pa1 + N;
  A->sp = A->sq + n;
  A->DA = A->sp + n;
  for (i = 0; i < n; i++)
    A->names[i] = sys->coords ? sys->coords[i] : "q";
  A->names[n] = "time";
  /* the transformed system */
  A->aug = *sys;
  A->aug.n = N;
  A->aug.coords = A->names;
  A->aug.flags = sys->flags & DM_SYS_MECHANICAL;
  A->aug.mass = NULL;
  A->aug.pattern = NULL;
  A->aug.lagrangian = tt_lagrangian;
  A->aug.force = NULL;
  A->aug.constraints = sys->m > 0 ? tt_constraints : NULL;
  A->aug.data = &A->td;
  A->aug.work_size = bytes;
  A->aug.free_data = NULL;
  A->aug.update = sys->update != NULL ? tt_update : NULL;
  A->aug.refresh = NULL;
  if ((strcmp(I->variant, "trapezoid") == 0
       || (strncmp(I->variant, "composition", 11) == 0
           && (I->variant[11] == '\0' || I->variant[11] == ':')
           && strcmp(I->opt.base, "trapezoid") == 0))
      && I->opt.monitor == NULL && I->opt.explicit_sv && (sys->flags & DM_SYS_SEPARABLE)
      && sys->mass != NULL && sys->m == 0) {
    if ((st = dm_adapt_explicit_setup(I, A, e)) != DM_OK) {
      adapt_free(I);
      return st;
    }
    return DM_OK;
  }
  o.monitor = NULL;
  if ((st = dm_integrator_new(&A->aug, I->variant, &o, &A->inner, e)) != DM_OK) {
    adapt_free(I);
    return st;
  }
  if (dm_integrator_varstep(A->inner)) {
    adapt_free(I);
    return dm_err_set(e, DM_EINVAL, "adapt: method '%s' has variable steps of its own",
                      I->variant);
  }
  I->order = A->inner->order;
  I->stages = A->inner->stages;
  I->flags = (A->inner->flags & (DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_EXPLICIT
                                 | DM_INTEG_EXACT_JAC | DM_INTEG_CONSTRAINTS))
             | DM_INTEG_VARSTEP;
  return DM_OK;
}

int dm_adapt_monitor_fail(adapt_state *A, int rc, const double *q, size_t n, dm_err *e)
{
  char bq[160];
  dm_num_format_vec(bq, sizeof bq, q, n);
  if (rc < 0)
    return dm_err_set(e, DM_ECALLBACK, "adapt: the monitor failed at q = %s", bq);
  if (A->td.mon == NULL)
    return dm_err_set(e, DM_EDOM, "adapt: the potential's monitor needs U = -V = L(q, 0) > 0 "
                      "(an attractive potential); not so at q = %s: give adapt.monitor", bq);
  return dm_err_set(e, DM_EDOM, "adapt: the monitor must be finite and > 0; not so at q = %s",
                    bq);
}

int dm_adapt_monitor_value(dm_integrator *I, const double *q, double *g, dm_err *e)
{
  adapt_state *A = I->state;
  int rc;
  if (!dm_adapt_is(I))
    return dm_err_set(e, DM_EINVAL, "not a time-transformed integrator");
  rc = monitor_eval(&A->td, q, I->sys->par, DM_MON_G, g, NULL, NULL, A->work);
  return rc == 0 ? DM_OK : dm_adapt_monitor_fail(A, rc, q, I->n, e);
}

static int adapt_begin(dm_integrator *I, double h, double t0, const double *q0,
                       const double *p0, dm_err *e)
{
  adapt_state *A = I->state;
  size_t n = I->n;
  double *v = I->scratch + 4 * n, E, g;
  tt_scratch s;
  int st, rc;
  (void)h;
  if ((st = dm_integrator_velocity(I, q0, p0, v, 0, e)) != DM_OK
      || (st = dm_integrator_energy(I, q0, v, &E, e)) != DM_OK)
    return st;
  if (A->td.mon == NULL) {
    double U;
    tt_layout(&A->td, A->work, &s);
    rc = dm_adapt_potential_eval(&A->td, q0, I->sys->par, DM_MON_G, &U, s.uq, s.uqq, &s,
                        tt_bwork(&A->td, A->work));
    if (rc != 0 || !(U > 0.0) || !isfinite(U))
      return dm_adapt_monitor_fail(A, rc < 0 ? rc : 1, q0, n, e);
    A->td.U0 = U;
  }
  A->td.E0 = E;
  if ((st = dm_adapt_monitor_value(I, q0, &g, e)) != DM_OK)
    return st;
  I->t = t0;
  I->dt = g * h;
  A->ct = 0.0;
  A->fsal = 0;
  if (A->inner != NULL)
    dm_integrator_reset(A->inner);
  if (A->expl)
    memset(A->cq, 0, 2 * n * sizeof *A->cq);
  return DM_OK;
}


/* One step of fictitious size h from (q0, p0, I->t) into q1, p1 (may
 * alias), advancing I->t and setting I->dt. */
static int adapt_step(dm_integrator *I, double h, const double *q0, const double *p0,
                      double *q1, double *p1, dm_err *e)
{
  adapt_state *A = I->state;
  size_t n = I->n;
  double t0 = I->t;
  int st;
  if (!I->begun) {
    if ((st = dm_integrator_begin(I, h, I->t, q0, p0, e)) != DM_OK)
      return st;
    t0 = I->t;
  }
  if (A->expl) {
    double t = t0;
    memmove(A->qa1, q0, n * sizeof *q0);
    memmove(A->pa1, p0, n * sizeof *p0);
    if ((st = dm_adapt_explicit_step(I, A, h, A->qa1, &t, A->pa1, NULL, e)) != DM_OK)
      return st;
    memcpy(q1, A->qa1, n * sizeof *q1);
    memcpy(p1, A->pa1, n * sizeof *p1);
    I->dt = t - t0;
    I->t = t;
    return DM_OK;
  }
  memcpy(A->qa, q0, n * sizeof *q0);
  memcpy(A->pa, p0, n * sizeof *p0);
  A->qa[n] = t0;
  A->pa[n] = 0.0;
  st = dm_integrator_step(A->inner, h, A->qa, A->pa, A->qa1, A->pa1, e);
  I->stats = A->inner->stats;
  if (st != DM_OK)
    return st;
  memcpy(q1, A->qa1, n * sizeof *q1);
  memcpy(p1, A->pa1, n * sizeof *p1);
  I->dt = A->qa1[n] - t0;
  I->t = A->qa1[n];
  return DM_OK;
}

/* The nominal step, or when it passes t_end a step ending there: the
 * fictitious step solving dt(sigma) = t_end - t by the secant method. */
static int adapt_step_until(dm_integrator *I, double h, double t_end, const double *q0,
                            const double *p0, double *q1, double *p1, int *reached, dm_err *e)
{
  adapt_state *A = I->state;
  size_t n = I->n;
  double t0 = I->t, target = t_end - t0, sa, da, sb, db, tol;
  int st, it;
  *reached = 0;
  memcpy(A->sq, q0, n * sizeof *q0);
  memcpy(A->sp, p0, n * sizeof *p0);
  tol = 4.0 * DBL_EPSILON * fmax(fabs(t_end), fabs(t0));
  if (fabs(target) <= tol) {          /* there already */
    memmove(q1, q0, n * sizeof *q1);
    memmove(p1, p0, n * sizeof *p1);
    I->t = t_end;
    I->dt = 0.0;
    *reached = 1;
    return DM_OK;
  }
  if ((st = adapt_step(I, h, A->sq, A->sp, q1, p1, e)) != DM_OK)
    return st;
  if ((I->t - t_end) * (h > 0 ? 1.0 : -1.0) < -tol)
    return DM_OK;                     /* not there yet */
  sa = h;
  da = I->t - t0;
  if (fabs(I->t - t_end) > tol) {
    sb = h * target / da;
    for (it = 0; it < 40; it++) {
      I->t = t0;
      if ((st = adapt_step(I, sb, A->sq, A->sp, q1, p1, e)) != DM_OK) {
        I->t = t0;
        return st;
      }
      db = I->t - t0;
      if (fabs(db - target) <= tol)
        break;
      if (db == da) {
        it = 40;
        break;
      }
      double sn = sb + (target - db) * (sb - sa) / (db - da);
      sa = sb;
      da = db;
      sb = sn;
    }
    if (it >= 40) {
      I->t = t0;
      return dm_err_set(e, DM_ENOCONV, "adapt: no fictitious step ends at t = %.17g "
                        "(secant iteration)", t_end);
    }
  }
  I->dt = t_end - t0;
  I->t = t_end;
  *reached = 1;
  return DM_OK;
}

int dm_adapt_extended_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                               double *D, dm_err *e)
{
  adapt_state *A;
  size_t n, N, M, i;
  int st;
  if (!dm_adapt_is(I))
    return dm_err_set(e, DM_EINVAL, "extended Jacobian: not a time-transformed integrator");
  A = I->state;
  n = I->n;
  N = A->N;
  M = 2 * N;
  if (!I->begun && (st = dm_integrator_begin(I, h, I->t, q0, p0, e)) != DM_OK)
    return st;
  if (A->expl) {
    double t = I->t;
    for (i = 0; i < M * M; i++)
      D[i] = i / M == i % M ? 1.0 : 0.0;
    memcpy(A->qa1, q0, n * sizeof *q0);
    memcpy(A->pa1, p0, n * sizeof *p0);
    A->fsal = 0;
    return dm_adapt_explicit_step(I, A, h, A->qa1, &t, A->pa1, D, e);
  }
  if (A->inner->type->jacobian == NULL && !(A->inner->flags & DM_INTEG_EXACT_JAC))
    return dm_integrator_jacobian(A->inner, h, A->qa, A->pa, D, e);
  memcpy(A->qa, q0, n * sizeof *q0);
  memcpy(A->pa, p0, n * sizeof *p0);
  A->qa[n] = I->t;
  A->pa[n] = 0.0;
  return dm_integrator_jacobian(A->inner, h, A->qa, A->pa, D, e);
}

/* The (q, p) block at the latched energy level. */
static int adapt_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                          double *DPhi, dm_err *e)
{
  adapt_state *A = I->state;
  size_t n = I->n, N = A->N, M = 2 * N, i, j;
  int st;
  if ((st = dm_adapt_extended_jacobian(I, h, q0, p0, A->DA, e)) != DM_OK)
    return st;
  for (i = 0; i < 2 * n; i++)
    for (j = 0; j < 2 * n; j++) {
      size_t r = i < n ? i : N + i - n, c = j < n ? j : N + j - n;
      DPhi[i * 2 * n + j] = A->DA[r * M + c];
    }
  return DM_OK;
}

static void adapt_reset(dm_integrator *I)
{
  adapt_state *A = I->state;
  if (A->inner != NULL)
    dm_integrator_reset(A->inner);
  A->fsal = 0;
}

static int adapt_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                         long *done, dm_err *e);

const dm_integrator_type dm_integ_adapt = {
  .name = "adapt",
  .summary = "time transformation dt/ds = g(q) of a method, fixed steps in the fictitious "
    "time s (adapt:<method>, Lua: adapt = {monitor =, power =})",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_CONSTRAINTS | DM_INTEG_VARSTEP,
  .options = adapt_options,
  .alloc = adapt_alloc,
  .step = adapt_step,
  .jacobian = adapt_jacobian,
  .dlegendre = NULL,
  .advance = adapt_advance,
  .reset = adapt_reset,
  .free = adapt_free,
  .begin = adapt_begin,
  .step_until = adapt_step_until,
};

/* The run loop's path: steps in place (a step writes only on success). */
static int adapt_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                         long *done, dm_err *e)
{
  long k;
  int st = DM_OK;
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = DM_EINTR;
      break;
    }
    if ((st = adapt_step(I, h, q, p, q, p, e)) != DM_OK)
      break;
  }
  *done = k;
  return st;
}

int dm_adapt_is(const dm_integrator *I)
{
  return I != NULL && I->type == &dm_integ_adapt;
}

double dm_adapt_energy_level(const dm_integrator *I)
{
  return dm_adapt_is(I) && I->begun ? ((const adapt_state *)I->state)->td.E0 : NAN;
}

/* }====================================================================== */

/* {==== a monitor from a compiled scalar field ========================== */

static int field_eval(void *data, const double *q, const double *par, unsigned what, double *g,
                      double *gq, double *gqq, void *work)
{
  const dm_system *f = data;
  size_t n = f->n, nn = n * n;
  double *w = work, *z = w, *Lv = z + n, *Lvv = Lv + n, *Lvq = Lvv + nn, *Lq = Lvq + nn,
         *Lqq = Lq + n;
  dm_lag_out o = {0, gq ? gq : Lq, Lv, Lvv, Lvq, gqq ? gqq : Lqq};
  unsigned lw = DM_LAG_L | ((what & DM_MON_GRAD) ? DM_LAG_Q : 0)
                | ((what & DM_MON_HESS) ? DM_LAG_ALL : 0);
  int rc;
  memset(z, 0, n * sizeof *z);
  rc = f->lagrangian(f->data, q, z, par, lw, &o,
                     (char *)work + (((3 * n + 3 * nn) * sizeof *w + 15) & ~(size_t)15));
  *g = o.L;
  return rc;
}

size_t dm_adapt_monitor_work(const dm_system *field)
{
  size_t n = field->n;
  return (((3 * n + 3 * n * n) * sizeof(double) + 15) & ~(size_t)15) + field->work_size;
}

void dm_adapt_monitor_from_system(dm_monitor *mon, const dm_system *field)
{
  mon->eval = field_eval;
  mon->data = (void *)field;
  mon->work_size = dm_adapt_monitor_work(field);
}

/* }====================================================================== */
