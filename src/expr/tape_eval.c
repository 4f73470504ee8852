/* tape_eval.c -- running a tape: the hot loop of every integrator.
 *
 * One pass over a compact instruction array on a register file in the
 * caller's work buffer; no allocation, no calls through pointers.  With GNU
 * C the dispatch is direct threaded (each instruction holds the address of
 * its handler: one indirect jump per instruction, which branch predictors
 * follow far better than the single jump of a switch; cross-jumping is off
 * so that GCC does not merge the dispatch tails back into one jump; the
 * code ends in a stop instruction, so there is no counter); otherwise it is
 * a switch.
 * Floating-point contraction is off so that a*b + c rounds twice, exactly
 * as the DAG evaluator and the native code (-ffp-contract=off) do. */
#include <config.h>
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off", "no-crossjumping")
#endif
#include "expr/tape_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static inline double sign_of(double x)
{
  return x > 0 ? 1.0 : x < 0 ? -1.0 : x == 0 ? 0.0 : x;
}

/* sin(x), storing cos(x) in *c: one call where the C library has one
 * (glibc's sincos gives exactly sin(x) and cos(x)). */
static inline double sin_cos(double x, double *c)
{
#if defined(__GLIBC__) && defined(_GNU_SOURCE)
  double s;
  sincos(x, &s, c);
  return s;
#else
  *c = cos(x);
  return sin(x);
#endif
}

/* The operation of every instruction on its operands A, B, C (E: the
 * POWI exponent; CW: where SINCOS stores the cosine), by arity. */
#define DM_TAPE_UNARY(X)                                \
  X(DM_T_NEG, -A)                                       \
  X(DM_T_SQR, A * A)                                    \
  X(DM_T_CUBE, A * (A * A))                             \
  X(DM_T_RECIP, 1.0 / A)                                \
  X(DM_T_POWI, dm_tape_powi(A, E))                      \
  X(DM_T_SQRT, sqrt(A))                                 \
  X(DM_T_EXP, exp(A))                                   \
  X(DM_T_LOG, log(A))                                   \
  X(DM_T_SIN, sin(A))                                   \
  X(DM_T_COS, cos(A))                                   \
  X(DM_T_TAN, tan(A))                                   \
  X(DM_T_ASIN, asin(A))                                 \
  X(DM_T_ACOS, acos(A))                                 \
  X(DM_T_ATAN, atan(A))                                 \
  X(DM_T_SINH, sinh(A))                                 \
  X(DM_T_COSH, cosh(A))                                 \
  X(DM_T_TANH, tanh(A))                                 \
  X(DM_T_ABS, fabs(A))                                  \
  X(DM_T_SIGN, sign_of(A))                              \
  X(DM_T_SINCOS, sin_cos(A, CW))
#define DM_TAPE_BINARY(X)                               \
  X(DM_T_ADD, A + B)                                    \
  X(DM_T_SUB, A - B)                                    \
  X(DM_T_MUL, A * B)                                    \
  X(DM_T_DIV, A / B)                                    \
  X(DM_T_POW, pow(A, B))                                \
  X(DM_T_ATAN2, atan2(A, B))                            \
  X(DM_T_LT, A < B)                                     \
  X(DM_T_LE, A <= B)                                    \
  X(DM_T_GT, A > B)                                     \
  X(DM_T_GE, A >= B)                                    \
  X(DM_T_EQ, A == B)                                    \
  X(DM_T_NE, A != B)
#define DM_TAPE_TERNARY(X)                              \
  X(DM_T_SELECT, C != 0 ? A : B)                        \
  X(DM_T_MULADD, A * B + C)                             \
  X(DM_T_MULSUB, A * B - C)                             \
  X(DM_T_SUBMUL, C - A * B)                             \
  X(DM_T_MUL3, A * B * C)
#define DM_TAPE_OPS(X) DM_TAPE_UNARY(X) DM_TAPE_BINARY(X) DM_TAPE_TERNARY(X)

/* Parameters, constants and constant outputs into their registers;
 * inputs too unless they are there already. */
static inline void load(const dm_tape *t, const double *in, const double *par,
                        double *w)
{
  if (in != w)
    for (size_t i = 0; i < t->nin; i++)
      w[i] = in[i];
  double *p = w + t->nin;
  for (size_t i = 0; i < t->npar; i++)
    p[i] = par[i];
  p += t->npar;
  dm_copy_doubles(p, t->preset, t->nconst + t->nslot);
}

#define E ((int32_t)ip->b)

void dm_tape_eval(const dm_tape *t, const double *in, const double *par,
                  double *out, double *w)
{
  dm_tape_run(t, in, par, w);
  for (size_t k = 0; k < t->nout; k++)
    out[k] = w[t->outreg[k]];
}

/* Handlers come in variants by where the previous instruction's result
 * is read: V0 all operands from registers; VA, VB, VC operand A, B or C
 * straight from r (the value just computed), without the round trip
 * through memory -- the store-to-load latency would otherwise sit on
 * every dependency chain. */
enum { V0, VA, VB, VC, NVAR };

/* Pairs: two consecutive instructions of these ops, the second not reading
 * the first's result, run by one handler (one dispatch for two; the second
 * takes its operands from registers, A2, B2, C2).  The first one's
 * variant as above. */
#define DM_TAPE_PAIR2(M, v, x, ex)                                    \
  M(v, x, ex, MUL, A2 * B2) M(v, x, ex, MULADD, A2 * B2 + C2)         \
  M(v, x, ex, MULSUB, A2 * B2 - C2) M(v, x, ex, MUL3, A2 * B2 * C2)   \
  M(v, x, ex, ADD, A2 + B2) M(v, x, ex, SUB, A2 - B2)                 \
  M(v, x, ex, SQR, A2 * A2)
#define DM_TAPE_PAIRS(M, v)                                           \
  DM_TAPE_PAIR2(M, v, MUL, A * B) DM_TAPE_PAIR2(M, v, MULADD, A * B + C) \
  DM_TAPE_PAIR2(M, v, MULSUB, A * B - C)                              \
  DM_TAPE_PAIR2(M, v, MUL3, A * B * C) DM_TAPE_PAIR2(M, v, ADD, A + B) \
  DM_TAPE_PAIR2(M, v, SUB, A - B) DM_TAPE_PAIR2(M, v, SQR, A * A)
enum { P_MUL, P_MULADD, P_MULSUB, P_MUL3, P_ADD, P_SUB, P_SQR, NPAIR };
/* 1 + the pair index of an op, 0 when it does not pair */
static const signed char pair_index[DM_T_NOPS] = {
  [DM_T_MUL] = 1 + P_MUL, [DM_T_MULADD] = 1 + P_MULADD,
  [DM_T_MULSUB] = 1 + P_MULSUB, [DM_T_MUL3] = 1 + P_MUL3,
  [DM_T_ADD] = 1 + P_ADD, [DM_T_SUB] = 1 + P_SUB, [DM_T_SQR] = 1 + P_SQR
};
#define PAIR_BASE (NVAR * DM_T_NOPS + 1)
#define NLABELS (PAIR_BASE + NVAR * NPAIR * NPAIR)
#define PAIR_AT(v, x, y) (PAIR_BASE + ((v) * NPAIR + (x)) * NPAIR + (y))

/* The loop over t->xcode, or (t == NULL) the handler addresses into
 * labels[NLABELS]: op + variant * DM_T_NOPS (NULL where a variant does
 * not exist), then the stop, then the pairs at PAIR_AT (GNU C only). */
static void run(const dm_tape *t, double *w, const void **labels)
{
#if defined(__GNUC__)
#define LABEL0(o_, expr) [o_] = &&L0_##o_,
#define LABELA(o_, expr) [VA * DM_T_NOPS + o_] = &&LA_##o_,
#define LABELB(o_, expr) [VB * DM_T_NOPS + o_] = &&LB_##o_,
#define LABELC(o_, expr) [VC * DM_T_NOPS + o_] = &&LC_##o_,
#define LABELP(v, x, ex, y, ey) [PAIR_AT(v, P_##x, P_##y)] = &&LP##v##_##x##_##y,
  static const void *const jump[NLABELS] = {
    DM_TAPE_OPS(LABEL0) DM_TAPE_OPS(LABELA)
    DM_TAPE_BINARY(LABELB) DM_TAPE_TERNARY(LABELB) DM_TAPE_TERNARY(LABELC)
    [NVAR * DM_T_NOPS] = &&L_halt,
    DM_TAPE_PAIRS(LABELP, V0) DM_TAPE_PAIRS(LABELP, VA)
    DM_TAPE_PAIRS(LABELP, VB) DM_TAPE_PAIRS(LABELP, VC)
  };
#undef LABEL0
#undef LABELA
#undef LABELB
#undef LABELC
#undef LABELP
  if (t == NULL) {
    memcpy(labels, jump, sizeof jump);
    return;
  }
  /* each handler stores its result, loads the next instruction's first
   * operand and jumps to its handler: one indirect jump per instruction,
   * no counter (the last instruction stops) */
  const dm_tape_xins *ip = t->xcode;
  double a = w[ip->a], r = 0;
  goto *ip->op;
#define HANDLER(L, o_, expr)                            \
  L##o_:                                                \
    r = (expr);                                         \
    w[ip->d] = r;                                       \
    ip++;                                               \
    a = w[ip->a];                                       \
    goto *ip->op;
#define CW (&w[ip->c])
#define H0(o_, expr) HANDLER(L0_, o_, expr)
#define HA(o_, expr) HANDLER(LA_, o_, expr)
#define HB(o_, expr) HANDLER(LB_, o_, expr)
#define HC(o_, expr) HANDLER(LC_, o_, expr)
#define PAIR(v, x, ex, y, ey)                           \
  LP##v##_##x##_##y:                                    \
    w[ip->d] = (ex);                                    \
    r = (ey);                                           \
    w[ip[1].d] = r;                                     \
    ip += 2;                                            \
    a = w[ip->a];                                       \
    goto *ip->op;
#define A2 (w[ip[1].a])
#define B2 (w[ip[1].b])
#define C2 (w[ip[1].c])
#define A a
#define B (w[ip->b])
#define C (w[ip->c])
  DM_TAPE_OPS(H0)
  DM_TAPE_PAIRS(PAIR, V0)
#undef A
#define A r
  DM_TAPE_OPS(HA)
  DM_TAPE_PAIRS(PAIR, VA)
#undef A
#undef B
#define A a
#define B r
  DM_TAPE_BINARY(HB)
  DM_TAPE_TERNARY(HB)
  DM_TAPE_PAIRS(PAIR, VB)
#undef B
#undef C
#define B (w[ip->b])
#define C r
  DM_TAPE_TERNARY(HC)
  DM_TAPE_PAIRS(PAIR, VC)
#undef A
#undef B
#undef C
#undef A2
#undef B2
#undef C2
#undef PAIR
#undef H0
#undef HA
#undef HB
#undef HC
#undef HANDLER
#undef CW
L_halt:
  return;
#else
  if (t == NULL) {                  /* every variant is its plain op */
    for (int i = 0; i < NVAR * DM_T_NOPS; i++)
      labels[i] = (const void *)(uintptr_t)(i % DM_T_NOPS);
    labels[NVAR * DM_T_NOPS] = (const void *)(uintptr_t)DM_T_NOPS;
    for (int i = PAIR_BASE; i < NLABELS; i++)
      labels[i] = NULL;                 /* no pairs */
    return;
  }
  for (const dm_tape_xins *ip = t->xcode; ; ip++) {
    const double a = w[ip->a];
    switch ((int)(uintptr_t)ip->op) {
#define A a
#define B (w[ip->b])
#define C (w[ip->c])
#define CW (&w[ip->c])
#define CASE(o_, expr) case o_: w[ip->d] = (expr); break;
      DM_TAPE_OPS(CASE)
#undef CASE
#undef A
#undef B
#undef C
#undef CW
    default:
      return;
    }
  }
#endif
}

/* The variant of instruction c given the register the previous one
 * wrote (-1: none). */
static int variant(const dm_tape_ins *c, int64_t prev)
{
  int op = (int)(c->code & 0xff);
  if (prev < 0)
    return V0;
  if (c->a == prev)
    return VA;
  int binary = (op >= DM_T_ADD && op <= DM_T_DIV) || op == DM_T_POW ||
               op == DM_T_ATAN2 || (op >= DM_T_LT && op <= DM_T_NE);
  int ternary = op == DM_T_SELECT || (op >= DM_T_MULADD && op <= DM_T_MUL3);
  if ((binary || ternary) && c->b == prev)
    return VB;
  if (ternary && (c->code >> 8) == prev)
    return VC;
  return V0;
}

/* 1 if instruction c reads register reg. */
static int reads(const dm_tape_ins *c, uint32_t reg)
{
  int op = (int)(c->code & 0xff);
  int binary = (op >= DM_T_ADD && op <= DM_T_DIV) || op == DM_T_POW ||
               op == DM_T_ATAN2 || (op >= DM_T_LT && op <= DM_T_NE);
  int ternary = op == DM_T_SELECT || (op >= DM_T_MULADD && op <= DM_T_MUL3);
  return c->a == reg || ((binary || ternary) && c->b == reg) ||
         (ternary && (c->code >> 8) == reg);
}

int dm_tape__thread(dm_tape *t)
{
  const void *labels[NLABELS];
  run(NULL, NULL, labels);
  t->xcode = malloc((t->ninstr + 1) * sizeof *t->xcode);
  if (t->xcode == NULL)
    return DM_ENOMEM;
  int64_t prev = -1;
  for (size_t i = 0; i < t->ninstr; i++) {
    const dm_tape_ins *c = &t->code[i];
    int op = (int)(c->code & 0xff), v = variant(c, prev);
    const void *h = labels[v * DM_T_NOPS + op];
    if (h == NULL)
      h = labels[op];
    t->xcode[i] = (dm_tape_xins){ h, c->d, c->a, c->b, c->code >> 8 };
    prev = c->d;
    if (i + 1 < t->ninstr) {          /* and the next one, as a pair? */
      const dm_tape_ins *n = &t->code[i + 1];
      int px = pair_index[op], py = pair_index[n->code & 0xff];
      h = px && py ? labels[PAIR_AT(v, px - 1, py - 1)] : NULL;
      if (h != NULL && !reads(n, c->d) && n->d != c->d) {
        t->xcode[i].op = h;
        t->xcode[i + 1] = (dm_tape_xins){ NULL, n->d, n->a, n->b, n->code >> 8 };
        prev = n->d;
        i++;
      }
    }
  }
  t->xcode[t->ninstr] = (dm_tape_xins){ labels[NVAR * DM_T_NOPS], 0, 0, 0, 0 };
  return DM_OK;
}

void dm_tape_run(const dm_tape *t, const double *in, const double *par,
                 double *w)
{
  load(t, in, par, w);
  if (t->ninstr > 0)
    run(t, w, NULL);
  const uint32_t (*c)[2] = (const uint32_t (*)[2])t->copy;
  for (size_t j = 0; j < t->ncopy; j++)
    w[c[j][0]] = w[c[j][1]];
}

#undef B
#undef C
#undef E

/* {==================================================================
 * batches: registers are rows of DM_TAPE_BATCH points, each instruction a
 * loop the compiler vectorises
 * =================================================================== */

#define A a
#define B (b[j])
#define C (c[j])
#define CW (&c[j])
#define E ((int32_t)ip->b)

static void run_block(const dm_tape *t, double *W, size_t m)
{
  const size_t R = DM_TAPE_BATCH;
  for (size_t i = 0; i < t->ninstr; i++) {
    const dm_tape_ins *ip = &t->code[i];
    double *d = W + (size_t)ip->d * R;
    const double *pa = W + (size_t)ip->a * R;
    const double *b = W + (size_t)(ip->b % t->nregs) * R;
    double *c = W + (size_t)(ip->code >> 8) * R;
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

#undef CW
#undef A
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
