/* integrator.c -- options table, life cycle, state conversions and the run
 * loop shared by every integrator family.  See integrator.h. */
#include <config.h>
#include "integrators/integ_impl.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "core/interrupt.h"
#include "core/numfmt.h"

/* {==== options ========================================================== */

#define OPT(f) offsetof(dm_integ_opts, f), sizeof(((dm_integ_opts *)0)->f)
const dm_option_desc dm_integ_options[] = {
  {"stages", DM_OPT_INT, OPT(stages), 1, DM_TABLEAU_SMAX,
   "number of stages: gauss >= 1 (default 2), lobatto >= 2 (default 3)"},
  {"h", DM_OPT_DOUBLE, OPT(h), -HUGE_VAL, HUGE_VAL, "step size (negative: backwards in time)"},
  {"tol", DM_OPT_DOUBLE, OPT(tol), DBL_EPSILON, 1e-2,
   "Newton stops when the relative update is <= tol (default 10 eps: round-off)"},
  {"maxiter", DM_OPT_INT, OPT(maxiter), 1, 1000, "Newton iteration cap (default 50)"},
  {"simplified", DM_OPT_BOOL, OPT(simplified), 0, 1,
   "Newton: reuse the factored exact Jacobian while the updates contract tenfold (default true)"},
  {"order", DM_OPT_INT, OPT(order), 4, 8, "composition: order 4, 6 or 8"},
  {"scheme", DM_OPT_STRING, OPT(scheme), 0, 0,
   "composition coefficients: yoshida4, yoshida6, kahanli6, mclachlan8, kahanli8 (default by order)"},
  {"base", DM_OPT_STRING, OPT(base), 0, 0, "composition base step: trapezoid (default) or midpoint"},
  {"explicit", DM_OPT_BOOL, OPT(explicit_sv), 0, 1,
   "use explicit Stormer-Verlet / RATTLE for separable L (default true)"},
  {"adaptive", DM_OPT_BOOL, OPT(adaptive), 0, 1, "gsl:*: adaptive steps inside each h"},
  {"epsabs", DM_OPT_DOUBLE, OPT(epsabs), 0, 1, "gsl:*: absolute tolerance (default 1e-10)"},
  {"epsrel", DM_OPT_DOUBLE, OPT(epsrel), 0, 1, "gsl:*: relative tolerance (default 1e-10)"},
  {"omega", DM_OPT_DOUBLE, OPT(omega), 0, HUGE_VAL,
   "multiscale: the fast frequency (default 0: estimated from the start)"},
  {"fast", DM_OPT_STRING, OPT(fast), 0, 0,
   "multiscale: the fast coordinates, comma-separated (default: the estimate's)"},
  {"nodes", DM_OPT_INT, OPT(nodes), 3, 12, "multiscale: Lobatto nodes in time (default 4)"},
  {"phases", DM_OPT_INT, OPT(phases), 4, 64, "multiscale: phases of the oscillation sampled (default 8)"},
  {"linear", DM_OPT_STRING, OPT(linear), 0, 0,
   "Newton matrices: dense LU, sparse LU (KLU) or auto (default: sparse for large sparse systems)"},
  {"iteration", DM_OPT_STRING, OPT(iteration), 0, 0,
   "stage equations: newton, or fixed (a fixed-point iteration on a separable L, Newton "
   "when it contracts slowly; an error on other systems), auto (default: fixed where it "
   "applies)"},
  {NULL, 0, 0, 0, 0, 0, NULL}
};
#undef OPT

void dm_integ_opts_init(dm_integ_opts *o)
{
  memset(o, 0, sizeof *o);
  o->tol = 10.0 * DBL_EPSILON;
  o->maxiter = 50;
  o->simplified = 1;
  o->order = 4;
  strcpy(o->base, "trapezoid");
  o->explicit_sv = 1;
  o->epsabs = 1e-10;
  o->epsrel = 1e-10;
  strcpy(o->linear, "auto");
  o->power = 1.0;
  o->nodes = 4;
  o->phases = 8;
  strcpy(o->iteration, "auto");
}

const dm_option_desc *dm_integ_option_find(const char *name)
{
  const dm_option_desc *d;
  for (d = dm_integ_options; name && d->name; d++)
    if (strcmp(d->name, name) == 0)
      return d;
  return NULL;
}

int dm_integ_opts_set_number(dm_integ_opts *o, const char *name, double v, dm_err *e)
{
  const dm_option_desc *d = dm_integ_option_find(name);
  char *f = (char *)o;
  if (d == NULL)
    return dm_err_set(e, DM_ENOTFOUND, "unknown integrator option '%s'", name ? name : "(null)");
  if (d->kind == DM_OPT_STRING)
    return dm_err_set(e, DM_EINVAL, "option '%s' expects a string", d->name);
  if (!(v >= d->min && v <= d->max) || (d->kind != DM_OPT_DOUBLE && v != floor(v))) {
    char got[DM_NUM_BUFSIZE], lo[DM_NUM_BUFSIZE], hi[DM_NUM_BUFSIZE];
    dm_num_format(got, sizeof got, v);
    dm_num_format(lo, sizeof lo, d->min);
    dm_num_format(hi, sizeof hi, d->max);
    if (v != v)
      return dm_err_set(e, DM_EINVAL, "option '%s' must be a number, got nan", d->name);
    if (d->kind == DM_OPT_DOUBLE && d->min == -HUGE_VAL && d->max == HUGE_VAL)
      return dm_err_set(e, DM_EINVAL, "option '%s' must be finite, got %s", d->name, got);
    return dm_err_set(e, DM_EINVAL, "option '%s' = %s out of range (%s %s..%s)", d->name, got,
                      d->kind == DM_OPT_DOUBLE ? "number" : d->kind == DM_OPT_BOOL ? "boolean"
                                                                               : "integer",
                      lo, hi);
  }
  if (d->kind == DM_OPT_DOUBLE)
    *(double *)(f + d->offset) = v;
  else
    *(int *)(f + d->offset) = (int)v;
  return DM_OK;
}

int dm_integ_opts_set_string(dm_integ_opts *o, const char *name, const char *v, dm_err *e)
{
  const dm_option_desc *d = dm_integ_option_find(name);
  if (d == NULL)
    return dm_err_set(e, DM_ENOTFOUND, "unknown integrator option '%s'", name ? name : "(null)");
  if (d->kind != DM_OPT_STRING)
    return dm_err_set(e, DM_EINVAL, "option '%s' expects a number", d->name);
  if (v == NULL || strlen(v) >= d->size)
    return dm_err_set(e, DM_EINVAL, "option '%s': string missing or too long", d->name);
  strcpy((char *)o + d->offset, v);
  return DM_OK;
}

int dm_integ_opts_get(const dm_integ_opts *o, const char *name, double *num,
                      const char **str, dm_err *e)
{
  const dm_option_desc *d = dm_integ_option_find(name);
  const char *f = (const char *)o;
  if (d == NULL)
    return dm_err_set(e, DM_ENOTFOUND, "unknown integrator option '%s'", name ? name : "(null)");
  if (d->kind == DM_OPT_STRING) {
    if (str)
      *str = f + d->offset;
  } else if (num) {
    *num = d->kind == DM_OPT_DOUBLE ? *(const double *)(f + d->offset)
                                    : (double)*(const int *)(f + d->offset);
  }
  return DM_OK;
}

/* {==== life cycle ======================================================= */

/* "a, b, gsl:<stepper>" -- the methods for a kind -- into buf */
static void known_methods(const char *kind, char *buf, size_t len)
{
  size_t i, k = 0, count = dm_integrator_count();
  buf[0] = '\0';
  for (i = 0; i < count && k < len; i++) {
    const dm_integrator_type *t = dm_integrator_type_at(i);
    const char *const *a;
    if (!dm_integrator_accepts(t, kind))
      continue;
    k += (size_t)snprintf(buf + k, len - k, "%s%s%s", k ? ", " : "", t->name,
                          strcmp(t->name, "gsl") == 0 ? ":<stepper>"
                          : strcmp(t->name, "adapt") == 0 ? ":<method>" : "");
    for (a = t->names; a != NULL && *a != NULL && k < len; a++)
      k += (size_t)snprintf(buf + k, len - k, ", %s", *a);
  }
}

/* DM_ENOTFOUND for a method no family of sys's kind answers to: say which
 * kinds it does apply to, if any */
static const dm_integrator_type *not_found(const dm_system *sys, const char *method, dm_err *e)
{
  const char *kind = sys->kind ? sys->kind : DM_SYSTEM_LAGRANGIAN;
  char buf[400], kinds[160];
  size_t i, k = 0, count = dm_integrator_count();
  kinds[0] = '\0';
  for (i = 0; i < count && k < sizeof kinds; i++) {
    const dm_integrator_type *t = dm_integrator_type_at(i);
    const char *const lag[] = {DM_SYSTEM_LAGRANGIAN, NULL}, *const *kk;
    if (dm_integrator_find(t->kinds ? t->kinds[0] : NULL, method, NULL) != t)
      continue;
    for (kk = t->kinds ? t->kinds : lag; *kk != NULL && k < sizeof kinds; kk++)
      if (strstr(kinds, *kk) == NULL)
        k += (size_t)snprintf(kinds + k, sizeof kinds - k, "%s%s", k ? ", " : "", *kk);
  }
  known_methods(kind, buf, sizeof buf);
  if (kinds[0] != '\0')
    dm_err_set(e, DM_ENOTFOUND, "method '%s' does not apply to system '%s' (a %s system); it "
               "integrates %s systems (methods here: %s)", method, sys->name ? sys->name : "?",
               kind, kinds, buf);
  else
    dm_err_set(e, DM_ENOTFOUND, "unknown integration method '%s' (known: %s)",
               method ? method : "(null)", buf);
  return NULL;
}

const dm_integrator_type *dm_integrator_select(const dm_system *sys, const char *method,
                                               const char **variant_out, dm_err *e)
{
  const dm_integrator_type *t = dm_integrator_find(sys->kind, method, variant_out);
  return t != NULL ? t : not_found(sys, method, e);
}

int dm_integrator_new(const dm_system *sys, const char *method,
                      const dm_integ_opts *opts, dm_integrator **out, dm_err *e)
{
  const dm_integrator_type *type;
  const char *variant;
  dm_integrator *I;
  size_t n;
  int st;
  *out = NULL;
  if (sys == NULL || sys->lagrangian == NULL || sys->n == 0)
    return dm_err_set(e, DM_EINVAL, "integrator: the system has no Lagrangian or no coordinates");
  if (sys->m > 0 && sys->constraints == NULL)
    return dm_err_set(e, DM_EINVAL, "system '%s' declares %zu constraints but no constraint function",
                      sys->name ? sys->name : "?", sys->m);
  if ((type = dm_integrator_select(sys, method, &variant, e)) == NULL)
    return DM_ENOTFOUND;
  if (sys->m > 0 && !(type->flags & DM_INTEG_CONSTRAINTS))
    return dm_err_set(e, DM_EUNSUP, "method '%s' does not support holonomic constraints "
                      "(use lobatto, trapezoid or midpoint)", method);
  if (opts && (!(opts->tol > 0.0) || opts->maxiter < 1))
    return dm_err_set(e, DM_EINVAL, "integrator: tol must be > 0 and maxiter >= 1");
  n = sys->n;
  if ((I = calloc(1, sizeof *I)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
  I->type = type;
  I->sys = sys;
  I->n = n;
  I->nq = dm_system_nq(sys);
  I->m = sys->m;
  if (opts)
    I->opt = *opts;
  else
    dm_integ_opts_init(&I->opt);
  snprintf(I->name, sizeof I->name, "%s", method);
  if (variant && strlen(variant) >= sizeof I->variant) {
    free(I);
    return dm_err_set(e, DM_EINVAL, "method variant '%s' too long", variant);
  }
  if (variant)
    strcpy(I->variant, variant);
  I->scratch = calloc(9 * n + I->nq, sizeof(double));
  I->leg = dm_legendre_alloc(sys);
  if (I->scratch == NULL || I->leg == NULL) {
    dm_integrator_free(I);
    return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
  }
  I->order = type->order;
  I->flags = type->flags;
  if ((st = type->alloc(I, e)) != DM_OK) {
    dm_integrator_free(I);
    return st;
  }
  I->opt.tableau = NULL;      /* borrowed; families keep their own copy */
  *out = I;
  return DM_OK;
}

void dm_integrator_free(dm_integrator *I)
{
  if (I == NULL)
    return;
  if (I->state && I->type->free)
    I->type->free(I);
  dm_legendre_free(I->leg);
  free(I->scratch);
  free(I);
}

void dm_integrator_reset(dm_integrator *I)
{
  int linear = I->stats.linear;          /* facts of the setup, not counters */
  size_t nnz = I->stats.nnz;
  if (I->type->reset)
    I->type->reset(I);
  memset(&I->stats, 0, sizeof I->stats);
  I->stats.linear = linear;
  I->stats.nnz = nnz;
  I->begun = 0;
}

static int finite_vec(const double *x, size_t n)
{
  size_t i;
  for (i = 0; i < n; i++)
    if (!isfinite(x[i]))
      return 0;
  return 1;
}

int dm_integrator_step(dm_integrator *I, double h, const double *q0, const double *p0,
                       double *q1, double *p1, dm_err *e)
{
  int st;
  if (!isfinite(h))
    return dm_err_set(e, DM_EINVAL, "step size h = %g is not finite", h);
  if (I->sys->update != NULL)          /* a step boundary: background code */
    I->sys->update(I->sys);
  if (dm_integrator_varstep(I) && !I->begun
      && (st = dm_integrator_begin(I, h, 0.0, q0, p0, e)) != DM_OK)
    return st;
  if ((st = I->type->step(I, h, q0, p0, q1, p1, e)) != DM_OK)
    return st;
  if (!finite_vec(q1, I->nq) || !finite_vec(p1, I->n))
    return dm_err_set(e, DM_EDOM, "the step produced a non-finite state (NaN or Inf; h = %g)", h);
  if (!dm_integrator_varstep(I)) {
    I->t += h;
    I->dt = h;
  }
  return DM_OK;
}

int dm_integrator_begin(dm_integrator *I, double h, double t0, const double *q0,
                        const double *p0, dm_err *e)
{
  int st;
  if (!isfinite(h) || h == 0.0 || !isfinite(t0))
    return dm_err_set(e, DM_EINVAL, "begin: need a finite step h != 0 and a finite start time");
  I->begun = 0;
  if (I->type->begin != NULL && (st = I->type->begin(I, h, t0, q0, p0, e)) != DM_OK)
    return st;
  if (!dm_integrator_varstep(I) || I->type->begin == NULL) {
    I->t = t0;
    I->dt = h;
  }
  I->begun = 1;
  return DM_OK;
}

int dm_integrator_step_until(dm_integrator *I, double h, double t_end, const double *q0,
                             const double *p0, double *q1, double *p1, int *reached,
                             dm_err *e)
{
  int st;
  *reached = 0;
  if (!isfinite(h) || h == 0.0 || !isfinite(t_end))
    return dm_err_set(e, DM_EINVAL, "step_until: need a finite step h != 0 and a finite end");
  if (!dm_integrator_varstep(I) || I->type->step_until == NULL) {
    double rest = t_end - I->t, hh = h;
    if (rest * h <= 0.0 || fabs(rest) <= fabs(h)) {
      hh = rest;
      *reached = 1;
    }
    if (hh == 0.0) {
      memmove(q1, q0, I->nq * sizeof *q1);
      memmove(p1, p0, I->n * sizeof *p1);
      return DM_OK;
    }
    if ((st = dm_integrator_step(I, hh, q0, p0, q1, p1, e)) != DM_OK) {
      *reached = 0;
      return st;
    }
    if (*reached)
      I->t = t_end;
    return DM_OK;
  }
  if (I->sys->update != NULL)
    I->sys->update(I->sys);
  if (!I->begun && (st = dm_integrator_begin(I, h, 0.0, q0, p0, e)) != DM_OK)
    return st;
  if ((st = I->type->step_until(I, h, t_end, q0, p0, q1, p1, reached, e)) != DM_OK)
    return st;
  if (!finite_vec(q1, I->nq) || !finite_vec(p1, I->n))
    return dm_err_set(e, DM_EDOM, "the step produced a non-finite state (NaN or Inf; h = %g)", h);
  return DM_OK;
}

/* {==== conversions ====================================================== */

int dm_integrator_momentum(dm_integrator *I, const double *q, const double *v,
                           double *p, dm_err *e)
{
  return dm_legendre_momentum(I->leg, q, v, p, e);
}

int dm_integrator_velocity(dm_integrator *I, const double *q, const double *p,
                           double *v, int guess, dm_err *e)
{
  return dm_legendre_velocity(I->leg, q, p, v, guess, e);
}

int dm_integrator_energy(dm_integrator *I, const double *q, const double *v,
                         double *E, dm_err *e)
{
  return dm_legendre_energy(I->leg, q, v, E, e);
}

int dm_integrator_dlegendre(dm_integrator *I, double h, const double *q0,
                            const double *q1, double *p0, double *p1, double *Ld,
                            dm_err *e)
{
  if (I->type->dlegendre == NULL || !(I->flags & DM_INTEG_VARIATIONAL))
    return dm_err_set(e, DM_EUNSUP, "method '%s' has no discrete Lagrangian (not variational)",
                      I->name);
  return I->type->dlegendre(I, h, q0, q1, p0, p1, Ld, e);
}

int dm_integrator_del_step(dm_integrator *I, double h, const double *q_prev,
                           const double *q_cur, double *q_next, dm_err *e)
{
  double *p = I->scratch + 6 * I->n, *pn = I->scratch + 7 * I->n;
  int st = dm_integrator_dlegendre(I, h, q_prev, q_cur, NULL, p, NULL, e);
  if (st != DM_OK)
    return st;
  return dm_integrator_step(I, h, q_cur, p, q_next, pn, e);
}

int dm_integrator_discrete_momentum(dm_integrator *I, double h, const double *q0,
                                    const double *q1, const double *xi, double *J,
                                    dm_err *e)
{
  double *p = I->scratch + 6 * I->n;
  size_t i;
  int st = dm_integrator_dlegendre(I, h, q0, q1, NULL, p, NULL, e);
  if (st != DM_OK)
    return st;
  *J = 0.0;
  for (i = 0; i < I->n; i++)
    *J += xi[i] * p[i];
  return DM_OK;
}

/* {==== run loop ========================================================= */

static int emit(dm_integrator *I, dm_sink_fn sink, void *ctx, double t, const double *q,
                const double *p, double *v, long *nsamples, dm_err *e)
{
  int st;
  if (sink == NULL)
    return DM_OK;
  if ((st = dm_legendre_velocity(I->leg, q, p, v, *nsamples > 0, e)) != DM_OK)
    return st;
  if ((st = sink(ctx, t, q, p, v)) != 0)
    return dm_err_set(e, st > 0 && st < DM_NSTATUS ? st : DM_ECALLBACK,
                      "the sample sink stopped the run at t = %.17g (%s)", t,
                      dm_strstatus(st > 0 ? st : DM_ECALLBACK));
  (*nsamples)++;
  return DM_OK;
}

/* Up to nsteps steps in place without the type's fast path: each step goes
 * to scratch and is copied back only when it succeeded. */
static int advance_steps(dm_integrator *I, double h, long nsteps, double *q, double *p,
                         long *done, dm_err *e)
{
  size_t n = I->n, nq = I->nq;
  double *q1 = I->scratch + 8 * n, *p1 = q1 + nq;   /* beyond the 8n of the others */
  long k;
  int st = DM_OK;
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = DM_EINTR;
      break;
    }
    if ((st = dm_integrator_step(I, h, q, p, q1, p1, e)) != DM_OK)
      break;
    memcpy(q, q1, nq * sizeof(double));
    memcpy(p, p1, n * sizeof(double));
  }
  *done = k;
  return st;
}

int dm_integrator_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                          long *done, dm_err *e)
{
  return I->type->advance ? I->type->advance(I, h, nsteps, q, p, done, e)
                          : advance_steps(I, h, nsteps, q, p, done, e);
}

int dm_integrator_run(dm_integrator *I, double t0, double *q, double *p, double h,
                      long nsteps, long every, dm_sink_fn sink, void *ctx,
                      dm_run_info *info, dm_err *e)
{
  size_t n = I->n;
  double *v = I->scratch + 2 * n;
  long k = 0, last_emit = -1, nsamples = 0;
  int st = DM_OK, sink_failed = 0;
  dm_err le;
  dm_err_clear(&le);
  if (!isfinite(h) || h == 0.0 || nsteps < 0 || every < 1) {
    st = dm_err_set(e, DM_EINVAL, "run: need a finite h != 0 (got %g), steps >= 0 (got %ld), "
                    "every >= 1 (got %ld)", h, nsteps, every);
    goto done;
  }
  if (!finite_vec(q, I->nq) || !finite_vec(p, n)) {
    st = dm_err_set(e, DM_EDOM, "run: the initial state contains NaN or Inf");
    goto done;
  }
  if ((st = emit(I, sink, ctx, t0, q, p, v, &nsamples, &le)) != DM_OK) {
    dm_err_set(e, st, "%s", le.msg);
    goto done;
  }
  last_emit = 0;
  while (k < nsteps) {
    long chunk = every - k % every, got = 0;
    if (chunk > nsteps - k)
      chunk = nsteps - k;
    st = dm_integrator_advance(I, h, chunk, q, p, &got, &le);
    k += got;
    if (st == DM_EINTR) {
      dm_err_set(e, DM_EINTR, "interrupted after step %ld of %ld (t = %.17g); the trajectory "
                 "up to there is kept", k, nsteps, t0 + (double)k * h);
      break;
    }
    if (st != DM_OK) {
      dm_err_set(e, st, "step %ld of %ld from t = %.17g failed: %s", k + 1, nsteps,
                 t0 + (double)k * h, le.msg);
      break;
    }
    if (k % every == 0 || k == nsteps) {
      if ((st = emit(I, sink, ctx, t0 + (double)k * h, q, p, v, &nsamples, &le)) != DM_OK) {
        dm_err_set(e, st, "after step %ld (t = %.17g): %s", k, t0 + (double)k * h, le.msg);
        sink_failed = 1;
        break;
      }
      last_emit = k;
    }
  }
  if (st != DM_OK && !sink_failed && last_emit != k) {
    dm_err ign;
    if (emit(I, sink, ctx, t0 + (double)k * h, q, p, v, &nsamples, &ign) == DM_OK)
      last_emit = k;
  }
done:
  if (info) {
    info->steps = k;
    info->t = t0 + (double)k * h;
    info->samples = nsamples;
    info->status = st;
    info->residual = I->stats.residual;
    info->tol = I->stats.tol;
  }
  return st;
}
