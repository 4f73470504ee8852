/* tape.h -- compiled expressions: a flat register program and its
 * evaluation loop.
 *
 * dm_tape_compile turns (outputs, inputs, parameters) of an expression
 * context into a tape: the outputs are first rewritten for evaluation
 * (tape_opt.c: sums factored greedily, powers by products, shared
 * reciprocals), then the nodes reachable from them are laid out in
 * topological order, one instruction each (shared subexpressions are
 * computed once, constants live in a pool; a product used once is fused
 * into its user), on registers reused by liveness.  Register
 * layout: [0, nin) inputs, [nin, nin+npar) parameters, then the constant
 * pool, then temporaries.
 *
 * A tape is immutable and independent of the context that produced it, so
 * it may be used from several threads at once: evaluation writes only the
 * caller's `out` and `work` (dm_tape_work_size doubles, one buffer per
 * thread) and never allocates.
 *
 * Ownership: dm_tape_compile allocates, dm_tape_free releases (NULL ok).
 * Errors: compile returns a dm status (DM_EINVAL for an unbound symbol,
 * duplicate input or invalid handle, DM_ENOMEM) and fills err.  Evaluation
 * cannot fail; NaN and Inf propagate as IEEE arithmetic says.
 */
#ifndef DM_TAPE_H
#define DM_TAPE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "expr/expr.h"
#include "core/status.h"

typedef struct dm_tape dm_tape;

/* Instruction set (read by emitters such as native.c). */
enum dm_tape_op {
  DM_T_ADD, DM_T_SUB, DM_T_MUL, DM_T_DIV, DM_T_NEG,
  DM_T_SQR,     /* a*a                     */
  DM_T_CUBE,    /* a*(a*a)                 */
  DM_T_RECIP,   /* 1/a                     */
  DM_T_POWI,    /* a^n, n = (int32_t)b, by binary powering (dm_tape_powi) */
  DM_T_POW, DM_T_ATAN2,
  DM_T_SQRT, DM_T_EXP, DM_T_LOG, DM_T_SIN, DM_T_COS, DM_T_TAN,
  DM_T_ASIN, DM_T_ACOS, DM_T_ATAN, DM_T_SINH, DM_T_COSH, DM_T_TANH,
  DM_T_ABS, DM_T_SIGN,
  DM_T_LT, DM_T_LE, DM_T_GT, DM_T_GE, DM_T_EQ, DM_T_NE,   /* 1.0 / 0.0 */
  DM_T_SELECT,  /* r[d] = r[c] != 0 ? r[a] : r[b], c = code >> 8 */
  /* fused (a product used once, folded into its user; rounded as the two
   * separate operations, never as an FMA): c = code >> 8 */
  DM_T_MULADD,  /* r[a]*r[b] + r[c]          */
  DM_T_MULSUB,  /* r[a]*r[b] - r[c]          */
  DM_T_SUBMUL,  /* r[c] - r[a]*r[b]          */
  DM_T_MUL3,    /* (r[a]*r[b])*r[c]          */
  /* sin and cos of one argument, one call: r[d] = sin(r[a]), r[c] =
   * cos(r[a]) (c = code >> 8; the same values as sin and cos) */
  DM_T_SINCOS,
  DM_T_NOPS
};

/* One instruction: op = code & 0xff; d, a, b registers (b is the exponent
 * for POWI); SELECT and the fused ops keep a third register c in
 * code >> 8, SINCOS its second result register. */
typedef struct dm_tape_ins {
  uint32_t code;
  uint32_t d, a, b;
} dm_tape_ins;

/* Compile.  `in` and `par` are symbols or parameters (each at most once
 * over both lists); every symbol or parameter the outputs depend on must be
 * among them.  npar / nin may be 0. */
int dm_tape_compile(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                    size_t nin, const dm_expr *in, size_t npar,
                    const dm_expr *par, dm_tape **tape, dm_err *err);
void dm_tape_free(dm_tape *t);

/* The outputs rewritten the way dm_tape_compile rewrites them before
 * compiling (sums factored, powers and reciprocals shared; values equal up
 * to rounding), as new nodes of the context that are never simplified:
 * nw[nout].  Compiling any of them with dm_tape_compile_exact computes
 * them with exactly the same operations, whatever else is compiled along,
 * so bundles that share outputs (L and its gradient alone, and with the
 * Hessian) give bit-identical values. */
int dm_tape_optimize(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                     dm_expr *nw, dm_err *err);
/* dm_tape_compile without the rewriting: every node as it is. */
int dm_tape_compile_exact(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                          size_t nin, const dm_expr *in, size_t npar,
                          const dm_expr *par, dm_tape **tape, dm_err *err);
/* dm_tape_compile_exact with the outputs also laid out in nslot
 * consecutive registers from dm_tape_slot_base(t): after a run, register
 * base + s holds output slot_out[s] (an output may fill several slots;
 * DM_EINVAL for slot_out[s] >= nout).  An output is computed straight into
 * its first slot; the other slots are copied at the end of a run (a short
 * loop, not instructions).  Callers that store outputs in arrays
 * (mirrored matrices, say) then copy whole blocks. */
int dm_tape_compile_slots(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                          size_t nin, const dm_expr *in, size_t npar,
                          const dm_expr *par, size_t nslot,
                          const uint32_t *slot_out, dm_tape **tape,
                          dm_err *err);
size_t dm_tape_slot_base(const dm_tape *t);

/* out[nout] = outputs at (in[nin], par[npar]); work has dm_tape_work_size
 * doubles.  in / par may be NULL when nin / npar is 0.  in may be work
 * itself (the inputs are its first nin registers: no copy).  out must not
 * overlap work. */
void dm_tape_eval(const dm_tape *t, const double *in, const double *par,
                  double *out, double *work);
size_t dm_tape_work_size(const dm_tape *t);
/* The same without collecting the outputs: output k stays in
 * work[dm_tape_outregs(t)[k]] (for callers that scatter them). */
void dm_tape_run(const dm_tape *t, const double *in, const double *par,
                 double *work);

/* Evaluate at npts points: point k reads in + k*in_stride and writes
 * out + k*out_stride (strides in doubles); par is shared.  Vectorised over
 * blocks of points; work has dm_tape_batch_work_size doubles. */
void dm_tape_eval_batch(const dm_tape *t, size_t npts, const double *in,
                        size_t in_stride, const double *par, double *out,
                        size_t out_stride, double *work);
size_t dm_tape_batch_work_size(const dm_tape *t);

/* Sizes and contents. */
size_t dm_tape_ninstr(const dm_tape *t);
size_t dm_tape_nregs(const dm_tape *t);
size_t dm_tape_nin(const dm_tape *t);
size_t dm_tape_npar(const dm_tape *t);
size_t dm_tape_nout(const dm_tape *t);
size_t dm_tape_nconst(const dm_tape *t);
const dm_tape_ins *dm_tape_code(const dm_tape *t);
const double *dm_tape_consts(const dm_tape *t);       /* nconst values */
const uint32_t *dm_tape_outregs(const dm_tape *t);    /* nout registers */
/* Number of instructions with each op (counts[DM_T_NOPS]). */
void dm_tape_op_counts(const dm_tape *t, size_t *counts);
const char *dm_tape_op_name(int op);

/* dst[0..n) = src[0..n) (not overlapping): short ones inline, two
 * doubles at a time, long ones by memcpy (for callers that copy a few
 * outputs per evaluation). */
static inline void dm_copy_doubles(double *dst, const double *src, size_t n)
{
  if (n > 32) {
    memcpy(dst, src, n * sizeof *dst);
    return;
  }
  size_t i = 0;
  for (; i + 2 <= n; i += 2)
    memcpy(dst + i, src + i, 2 * sizeof *dst);
  if (i < n)
    dst[i] = src[i];
}

/* x^n exactly as DM_T_POWI computes it (binary powering). */
static inline double dm_tape_powi(double x, int n)
{
  unsigned long u = n < 0 ? (unsigned long)(-(long)n) : (unsigned long)n;
  double r = 1.0, p = x;
  while (u) {
    if (u & 1)
      r *= p;
    u >>= 1;
    if (u)
      p *= p;
  }
  return n < 0 ? 1.0 / r : r;
}

#endif
