/* lagrangian_eval.c -- the dm_system callbacks of a compiled Lagrangian
 * system: run the bundle that covers a request (its native code, or its
 * tape), converting second derivatives asked for in the other layout.
 * See lagrangian.h; built by lagrangian.c. */
#include <config.h>
#include "expr/lagrangian_impl.h"

#include <stddef.h>

/* Inputs are written straight into the tape's register file (its first
 * registers are the inputs), so neither path copies them twice; the tape
 * path of a callback is dm_bundle_tape_scatter. */
static inline void copy(double *dst, const double *src, size_t k)
{
  for (size_t i = 0; i < k; i++)
    dst[i] = src[i];
}

/* The request mask is passed with L (whose storage is always there) and
 * the arrays the bundle lacks (p->fill) set, so that a request of all the
 * bundle has takes native code's direct path. */
static int lag_run(const lag_data *d, const double *q, const double *v,
                   const double *par, unsigned what, dm_lag_out *out, double *w)
{
  const size_t n = d->n;
  const dm_bundle *p = d->sel[what & DM_LAG_ALL];
  double *o[6] = { &out->L, out->Lq, out->Lv, out->Lvv, out->Lvq, out->Lqq };
  if (p->scatter != NULL) {
    const double *in[2] = { q, v };
    return p->scatter(in, par, o, (what & DM_LAG_ALL) | DM_LAG_L | p->fill, w);
  }
  copy(w, q, n);
  if (p->nin > n)
    copy(w + n, v, n);
  return dm_bundle_tape_scatter(p, w, par, o, (what & DM_LAG_ALL) | DM_LAG_L | p->fill);
}

/* Second derivatives asked for in the other layout than the bundles have:
 * computed into the scratch after the tapes' work, then spread (values ->
 * dense, zeros elsewhere) or gathered (dense -> values). */
static int lag_convert(const lag_data *d, const double *q, const double *v,
                       const double *par, unsigned what, dm_lag_out *out, double *w)
{
  const dm_csr *pat[3] = { &d->pat.vv, &d->pat.vq, &d->pat.qq };
  double **dst[3] = { &out->Lvv, &out->Lvq, &out->Lqq };
  const unsigned bit[3] = { DM_LAG_VV, DM_LAG_VQ, DM_LAG_QQ };
  dm_lag_out t = *out;
  double **tp[3] = { &t.Lvv, &t.Lvq, &t.Lqq };
  double *s = w + d->need;
  for (int b = 0; b < 3; b++) {
    *tp[b] = s;
    s += d->sparse ? pat[b]->nnz : d->n * d->n;
  }
  int st = lag_run(d, q, v, par, what, &t, w);
  out->L = t.L;
  if (st != 0)
    return st;
  for (int b = 0; b < 3; b++)
    if (what & bit[b]) {
      if (d->sparse)
        dm_csr_to_dense(pat[b], *tp[b], *dst[b]);
      else
        dm_csr_from_dense(pat[b], *tp[b], *dst[b]);
    }
  return 0;
}

int dm_lag__eval(void *data, const double *q, const double *v,
                 const double *par, unsigned what, dm_lag_out *out, void *work)
{
  const lag_data *d = data;
  int sp = (what & DM_LAG_SPARSE) != 0;
  if ((what & (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ)) && sp != d->sparse)
    return lag_convert(d, q, v, par, what, out, work);
  return lag_run(d, q, v, par, what, out, work);
}

static int force_run(const lag_data *d, const double *q, const double *v,
                     const double *par, unsigned what, double *F, double *Fq,
                     double *Fv, double *w)
{
  const size_t n = d->n;
  const dm_bundle *p = (what & (DM_FORCE_Q | DM_FORCE_V)) ? &d->force_all : &d->force;
  double *o[3] = { F, Fq, Fv };
  what &= DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V;
  if (p->scatter != NULL) {
    const double *in[2] = { q, v };
    return p->scatter(in, par, o, what, w);
  }
  copy(w, q, n);
  copy(w + n, v, n);
  return dm_bundle_tape_scatter(p, w, par, o, what);
}

int dm_lag__force_eval(void *data, const double *q, const double *v,
                       const double *par, unsigned what, double *F, double *Fq,
                       double *Fv, void *work)
{
  const lag_data *d = data;
  int sp = (what & DM_FORCE_SPARSE) != 0;
  if (!(what & (DM_FORCE_Q | DM_FORCE_V)) || sp == d->sparse)
    return force_run(d, q, v, par, what, F, Fq, Fv, work);
  const dm_csr *pat[2] = { &d->pat.fq, &d->pat.fv };
  double *dst[2] = { Fq, Fv }, *tp[2];
  double *s = (double *)work + d->need;
  for (int b = 0; b < 2; b++) {
    tp[b] = s;
    s += d->sparse ? pat[b]->nnz : d->n * d->n;
  }
  int st = force_run(d, q, v, par, what, F, tp[0], tp[1], work);
  if (st != 0)
    return st;
  for (int b = 0; b < 2; b++)
    if (what & (b == 0 ? DM_FORCE_Q : DM_FORCE_V)) {
      if (d->sparse)
        dm_csr_to_dense(pat[b], tp[b], dst[b]);
      else
        dm_csr_from_dense(pat[b], tp[b], dst[b]);
    }
  return 0;
}

int dm_lag__constr_eval(void *data, const double *q, const double *par,
                        unsigned what, double *g, double *G, double *H,
                        void *work)
{
  const lag_data *d = data;
  const dm_bundle *p = (what & DM_CONSTR_D2G) ? &d->constr_all : &d->constr;
  double *o[3] = { g, G, H };
  if (p->scatter != NULL) {
    const double *in[1] = { q };
    return p->scatter(in, par, o, what, work);
  }
  double *w = work;
  copy(w, q, d->n);
  return dm_bundle_tape_scatter(p, w, par, o, what);
}
