/* tape_eval.c -- running a tape: the hot loop of every integrator.
 *
 * One pass over a compact instruction array on a register file in the
 * caller's work buffer; no allocation, no calls through pointers.  With GNU
 * C the dispatch is threaded (a jump table of labels, one indirect jump per
 * instruction, which branch predictors follow far better than the single
 * jump of a switch; cross-jumping is off so that GCC does not merge the
 * dispatch tails back into one jump); otherwise it is a switch.
 * Floating-point contraction is off so that a*b + c rounds twice, exactly
 * as the DAG evaluator and the native code (-ffp-contract=off) do. */
#include <config.h>
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off", "no-crossjumping")
#endif
#include "tape_impl.h"

#include <math.h>
#include <string.h>

static inline double sign_of(double x)
{
  return x > 0 ? 1.0 : x < 0 ? -1.0 : x == 0 ? 0.0 : x;
}

/* The operation of every instruction, on scalars a, b, c (B: the second
 * register, C: the third, E: the POWI exponent). */
#define DM_TAPE_OPS(X)                                  \
  X(DM_T_ADD, a + B)                                    \
  X(DM_T_SUB, a - B)                                    \
  X(DM_T_MUL, a * B)                                    \
  X(DM_T_DIV, a / B)                                    \
  X(DM_T_NEG, -a)                                       \
  X(DM_T_SQR, a * a)                                    \
  X(DM_T_CUBE, a * (a * a))                             \
  X(DM_T_RECIP, 1.0 / a)                                \
  X(DM_T_POWI, dm_tape_powi(a, E))                      \
  X(DM_T_POW, pow(a, B))                                \
  X(DM_T_ATAN2, atan2(a, B))                            \
  X(DM_T_SQRT, sqrt(a))                                 \
  X(DM_T_EXP, exp(a))                                   \
  X(DM_T_LOG, log(a))                                   \
  X(DM_T_SIN, sin(a))                                   \
  X(DM_T_COS, cos(a))                                   \
  X(DM_T_TAN, tan(a))                                   \
  X(DM_T_ASIN, asin(a))                                 \
  X(DM_T_ACOS, acos(a))                                 \
  X(DM_T_ATAN, atan(a))                                 \
  X(DM_T_SINH, sinh(a))                                 \
  X(DM_T_COSH, cosh(a))                                 \
  X(DM_T_TANH, tanh(a))                                 \
  X(DM_T_ABS, fabs(a))                                  \
  X(DM_T_SIGN, sign_of(a))                              \
  X(DM_T_LT, a < B)                                     \
  X(DM_T_LE, a <= B)                                    \
  X(DM_T_GT, a > B)                                     \
  X(DM_T_GE, a >= B)                                    \
  X(DM_T_EQ, a == B)                                    \
  X(DM_T_NE, a != B)                                    \
  X(DM_T_SELECT, C != 0 ? a : B)                        \
  X(DM_T_MULADD, a * B + C)                             \
  X(DM_T_MULSUB, a * B - C)                             \
  X(DM_T_SUBMUL, C - a * B)                             \
  X(DM_T_MUL3, a * B * C)

static void load(const dm_tape *t, const double *in, const double *par,
                 double *w)
{
  if (t->nin && in != w)              /* in == w: inputs already in place */
    memcpy(w, in, t->nin * sizeof *w);
  if (t->npar)
    memcpy(w + t->nin, par, t->npar * sizeof *w);
  if (t->nconst)
    memcpy(w + t->nin + t->npar, t->consts, t->nconst * sizeof *w);
}

#define B (w[ip->b])
#define C (w[ip->code >> 8])
#define E ((int32_t)ip->b)

void dm_tape_eval(const dm_tape *t, const double *in, const double *par,
                  double *out, double *w)
{
  dm_tape_run(t, in, par, w);
  for (size_t k = 0; k < t->nout; k++)
    out[k] = w[t->outreg[k]];
}

void dm_tape_run(const dm_tape *t, const double *in, const double *par,
                 double *w)
{
  load(t, in, par, w);
  const dm_tape_ins *ip = t->code, *end = ip + t->ninstr;
  if (ip < end) {
#if defined(__GNUC__)
#define LABEL(op, expr) [op] = &&L_##op,
    static const void *const jump[DM_T_NOPS] = { DM_TAPE_OPS(LABEL) };
#undef LABEL
    double a = w[ip->a];
    goto *jump[ip->code & 0xff];
#define CASE(op, expr)                                  \
  L_##op:                                               \
    w[ip->d] = (expr);                                  \
    if (++ip == end)                                    \
      goto done;                                        \
    a = w[ip->a];                                       \
    goto *jump[ip->code & 0xff];
    DM_TAPE_OPS(CASE)
#undef CASE
done:;
#else
    for (; ip < end; ip++) {
      const double a = w[ip->a];
      switch (ip->code & 0xff) {
#define CASE(op, expr) case op: w[ip->d] = (expr); break;
        DM_TAPE_OPS(CASE)
#undef CASE
      default: break;
      }
    }
#endif
  }
}

#undef B
#undef C
#undef E

/* {==================================================================
 * batches: registers are rows of DM_TAPE_BATCH points, each instruction a
 * loop the compiler vectorises
 * =================================================================== */

#define B (b[j])
#define C (c[j])
#define E ((int32_t)ip->b)

static void run_block(const dm_tape *t, double *W, size_t m)
{
  const size_t R = DM_TAPE_BATCH;
  for (size_t i = 0; i < t->ninstr; i++) {
    const dm_tape_ins *ip = &t->code[i];
    double *d = W + (size_t)ip->d * R;
    const double *pa = W + (size_t)ip->a * R;
    const double *b = W + (size_t)(ip->b % t->nregs) * R;
    const double *c = W + (size_t)(ip->code >> 8) * R;
    switch (ip->code & 0xff) {
#define CASE(op, expr)                                  \
    case op:                                            \
      for (size_t j = 0; j < m; j++) {                  \
        const double a = pa[j];                         \
        d[j] = (expr);                                  \
      }                                                 \
      break;
      DM_TAPE_OPS(CASE)
#undef CASE
    default:
      break;
    }
  }
}

#undef B
#undef C
#undef E

void dm_tape_eval_batch(const dm_tape *t, size_t npts, const double *in,
                        size_t in_stride, const double *par, double *out,
                        size_t out_stride, double *W)
{
  const size_t R = DM_TAPE_BATCH;
  /* parameters and constants are never overwritten: fill them once */
  for (size_t k = 0; k < t->npar + t->nconst; k++) {
    double v = k < t->npar ? par[k] : t->consts[k - t->npar];
    double *r = W + (t->nin + k) * R;
    for (size_t j = 0; j < R; j++)
      r[j] = v;
  }
  for (size_t s = 0; s < npts; s += R) {
    size_t m = npts - s < R ? npts - s : R;
    for (size_t j = 0; j < m; j++)
      for (size_t i = 0; i < t->nin; i++)
        W[i * R + j] = in[(s + j) * in_stride + i];
    run_block(t, W, m);
    for (size_t j = 0; j < m; j++)
      for (size_t k = 0; k < t->nout; k++)
        out[(s + j) * out_stride + k] = W[(size_t)t->outreg[k] * R + j];
  }
}
