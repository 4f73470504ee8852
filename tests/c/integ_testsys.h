/* integ_testsys.h -- small hand-written systems used only by the integrator
 * tests: a non-regular Lagrangian, a non-mechanical one and a stiff quartic
 * well that runs away at large steps. */
#ifndef DM_INTEG_TESTSYS_H
#define DM_INTEG_TESTSYS_H

#include <math.h>
#include <string.h>
#include "core/system.h"

/* L = 1/2 (v1 + v2)^2 - 1/2 (q1^2 + q2^2): d2L/dv2 = [[1,1],[1,1]] singular. */
static inline int ts_singular_lag(void *data, const double *q, const double *v, const double *par,
                           unsigned what, dm_lag_out *o, void *work)
{
  double s = v[0] + v[1];
  (void)data; (void)par; (void)work;
  if (what & DM_LAG_L) o->L = 0.5 * s * s - 0.5 * (q[0] * q[0] + q[1] * q[1]);
  if (what & DM_LAG_Q) { o->Lq[0] = -q[0]; o->Lq[1] = -q[1]; }
  if (what & DM_LAG_V) { o->Lv[0] = s; o->Lv[1] = s; }
  if (what & DM_LAG_VV) { o->Lvv[0] = o->Lvv[1] = o->Lvv[2] = o->Lvv[3] = 1.0; }
  if (what & DM_LAG_VQ) memset(o->Lvq, 0, 4 * sizeof(double));
  if (what & DM_LAG_QQ) { o->Lqq[0] = o->Lqq[3] = -1.0; o->Lqq[1] = o->Lqq[2] = 0.0; }
  return 0;
}

static inline void ts_singular(dm_system *s)
{
  memset(s, 0, sizeof *s);
  s->name = "degenerate";
  s->n = 2;
  s->lagrangian = ts_singular_lag;
}

/* Relativistic oscillator L = -sqrt(1 - v^2) - 1/2 w^2 q^2 (c = m = 1):
 * not mechanical (p = v / sqrt(1 - v^2)), par[0] = w.  |v| >= 1 is outside
 * the domain (status 1). */
static inline int ts_rel_lag(void *data, const double *q, const double *v, const double *par,
                      unsigned what, dm_lag_out *o, void *work)
{
  double w2 = par[0] * par[0], u = 1.0 - v[0] * v[0], r;
  (void)data; (void)work;
  if (!(u > 0.0))
    return 1;
  r = sqrt(u);
  if (what & DM_LAG_L) o->L = -r - 0.5 * w2 * q[0] * q[0];
  if (what & DM_LAG_Q) o->Lq[0] = -w2 * q[0];
  if (what & DM_LAG_V) o->Lv[0] = v[0] / r;
  if (what & DM_LAG_VV) o->Lvv[0] = 1.0 / (u * r);
  if (what & DM_LAG_VQ) o->Lvq[0] = 0.0;
  if (what & DM_LAG_QQ) o->Lqq[0] = -w2;
  return 0;
}

static inline void ts_relativistic(dm_system *s)
{
  static double ts_rel_par[1] = {2.385};
  memset(s, 0, sizeof *s);
  s->name = "relativistic oscillator";
  s->n = 1;
  s->npar = 1;
  s->par = ts_rel_par;
  s->lagrangian = ts_rel_lag;
}

/* Quartic well L = 1/2 v^2 - k q^4 / 4, par[0] = k: at k = 1e12 and a step
 * of 100 every method runs away (the energy overflows). */
static inline int ts_quartic_lag(void *data, const double *q, const double *v, const double *par,
                                 unsigned what, dm_lag_out *o, void *work)
{
  double k = par[0], q2 = q[0] * q[0];
  (void)data; (void)work;
  if (what & DM_LAG_L) o->L = 0.5 * v[0] * v[0] - 0.25 * k * q2 * q2;
  if (what & DM_LAG_Q) o->Lq[0] = -k * q2 * q[0];
  if (what & DM_LAG_V) o->Lv[0] = v[0];
  if (what & DM_LAG_VV) o->Lvv[0] = 1.0;
  if (what & DM_LAG_VQ) o->Lvq[0] = 0.0;
  if (what & DM_LAG_QQ) o->Lqq[0] = -3.0 * k * q2;
  return 0;
}

static inline void ts_quartic(dm_system *s, double *k)
{
  static const char *const names[] = {"q"}, *const pnames[] = {"k"};
  memset(s, 0, sizeof *s);
  s->name = "quartic well";
  s->n = 1;
  s->npar = 1;
  s->coords = names;
  s->params = pnames;
  s->par = k;
  s->flags = DM_SYS_MECHANICAL;
  s->lagrangian = ts_quartic_lag;
}

#endif
