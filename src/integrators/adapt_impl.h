/* adapt_impl.h -- private to src/integrators/adapt*.c: the transformed
 * system's data and scratch, the family's state, and the explicit path
 * (adapt_explicit.c) shared with adapt.c.  See adapt.h. */
#ifndef DM_ADAPT_IMPL_H
#define DM_ADAPT_IMPL_H

#include "integrators/adapt.h"
#include "integrators/prk_impl.h"

/* What the transformed system reads: the base system, the monitor, the
 * latched energy level and, for the potential's monitor, U(q0) and a. */
typedef struct tt_data {
  const dm_system *base;
  size_t n, m;
  const dm_monitor *mon;     /* NULL: the potential's monitor */
  double E0;
  double U0, power;
  size_t nd;                 /* doubles of scratch at the start of work */
  size_t bwork_off;          /* byte offsets of the base's and the monitor's work */
  size_t mwork_off;
} tt_data;

/* Scratch layout (doubles) inside a transformed-system work buffer. */
typedef struct tt_scratch {
  double *u, *Lq, *Lv, *Lvv, *Lvq, *Lqq, *gq, *gqq, *a, *z, *uq, *uqq, *Gs, *Hs;
} tt_scratch;

typedef struct adapt_state {
  tt_data td;
  dm_system aug;
  const char **names;          /* n + 1 coordinate names */
  dm_integrator *inner;        /* NULL on the explicit path */
  size_t N;                    /* n + 1 */
  double *qa, *pa, *qa1, *pa1; /* N each */
  double *sq, *sp;             /* n each: the start of step_until */
  double *DA;                  /* (2N)^2 */
  void *work;                  /* the transformed system's work */
  /* explicit path */
  int expl;
  size_t ns;                   /* substeps */
  double gam[17];
  double *F, *v, *cq, *cp, *hq, *hp, *Minv, *K, *T2; /* n, n, n, n, n, n, nn, nn, 4N^2 */
  double ct;                   /* Kahan carry of t */
  int fsal;                    /* F holds the kick at hq */
} adapt_state;

/* Scratch layout (doubles) inside a transformed-system work buffer. */
static inline size_t tt_ndoubles(size_t n, size_t m)
{
  return 8 * n + 7 * n * n + m * n + m * n * n + 8;
}

static inline void tt_layout(const tt_data *d, void *work, tt_scratch *s)
{
  size_t n = d->n, nn = n * n;
  double *w = work;
  s->u = w; w += n;
  s->Lq = w; w += n;
  s->Lv = w; w += n;
  s->a = w; w += n;
  s->z = w; w += n;          /* zeros: v = 0 for the potential */
  s->uq = w; w += n;
  s->gq = w; w += n;
  s->Lvv = w; w += nn;
  s->Lvq = w; w += nn;
  s->Lqq = w; w += nn;
  s->gqq = w; w += nn;
  s->uqq = w; w += nn;
  s->Gs = w; w += d->m * n;
  s->Hs = w;
}

static inline void *tt_bwork(const tt_data *d, void *work)
{
  return (char *)work + d->bwork_off;
}

/* U = L(q, 0) = -V and, by the bits of what (DM_MON_*), its gradient and
 * Hessian; the callback's status. */
int dm_adapt_potential_eval(const tt_data *d, const double *q, const double *par, unsigned what,
                            double *U, double *Uq, double *Uqq, tt_scratch *s, void *bwork);
/* The error of a monitor outside its domain (rc > 0) or failing (rc < 0). */
int dm_adapt_monitor_fail(adapt_state *A, int rc, const double *q, size_t n, dm_err *e);

/* adapt_explicit.c: set up the explicit path (trapezoid or composition with
 * the potential's monitor on a separable system); one step of fictitious
 * size h in place on (q, t, p), D (2(n+1) square or NULL) accumulating the
 * extended Jacobian. */
int dm_adapt_explicit_setup(dm_integrator *I, adapt_state *A, dm_err *e);
int dm_adapt_explicit_step(dm_integrator *I, adapt_state *A, double h, double *q, double *t,
                           double *p, double *D, dm_err *e);

#endif
