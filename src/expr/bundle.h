/* bundle.h -- a compiled bundle: several outputs of an expression context
 * in one tape (tape.h), and in native code (native.h) when asked for and
 * a compiler works, evaluated straight into the caller's arrays.
 *
 * The outputs are described by blocks, one array each, in output order:
 * vectors, full matrices, symmetric matrices (packed upper triangles,
 * written to both halves), each `rep` times at a stride (the blocks must
 * fill their arrays densely).  The inputs are consecutive arrays of inlen
 * values each (input i is element i % inlen of array i / inlen).  A run
 * writes the outputs of the arrays whose bit (1 << arr) is in its mask:
 * native code through its scatter function (each output stored as soon as
 * it is computed), the tape into consecutive slots copied array by array.
 * Both test every output for NaN/Inf, requested or not, and report it.
 * Used by the systems compiled from a Lagrangian (lagrangian.c) and by the
 * stage programs of the Routh reduction (src/reduce/routh_compile.c).
 *
 * Ownership: dm_bundle_compile fills a caller-provided dm_bundle (zeroed
 * before) and allocates its tape, native code and tables; dm_bundle_free
 * releases them and zeroes the struct (a zeroed bundle may be freed).  The
 * expressions are only read during the compilation.  Running needs a work
 * array of nregs doubles (dm_bundle_run_plain: nregs + nout), one per
 * thread; it never allocates.
 * Errors (compile): the tape compiler's statuses, DM_ENOMEM, DM_EFAILED for
 * blocks that leave gaps; native code that does not compile is skipped
 * silently with modes auto and wait (the tape runs), an error with always
 * (or DM_EINTR when interrupted).  With auto | DM_BUNDLE_BACKGROUND the
 * bundle compiles its tape and queues the native code (native_job.h); the
 * bundle runs the tape until dm_bundle_update installs it.
 */
#ifndef DM_BUNDLE_H
#define DM_BUNDLE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "expr/expr.h"
#include "expr/native.h"
#include "expr/native_job.h"
#include "core/status.h"
#include "expr/tape.h"

/* Where outputs go.  DM_BLK_PAIRS: len outputs, output i stored at
 * elements pos[2i] and pos[2i+1] of the array (the second DM_BLK_NOPOS for
 * one place only): values on a sparse pattern, the upper triangle of a
 * symmetric one written to both halves. */
enum { DM_BLK_VEC, DM_BLK_FULL, DM_BLK_SYM, DM_BLK_PAIRS };
#define DM_BLK_NOPOS UINT32_MAX
typedef struct dm_block {
  unsigned arr, kind;       /* array index (< 32), DM_BLK_* */
  size_t len;               /* vector length or matrix order */
  size_t rep, stride;       /* repetitions, at this stride (constraint Hessians) */
  const uint32_t *pos;      /* DM_BLK_PAIRS: 2 len places */
} dm_block;

/* What the bundles of one owner are compiled from. */
typedef struct dm_bundle_src {
  dm_expr_ctx *ctx;
  const dm_expr *in;        /* inputs (symbols); a bundle uses the first nin */
  size_t inlen;             /* length of each input array */
  size_t npar;
  const dm_expr *par;
  const double *in0;        /* a typical input point, or NULL */
  const double *par0;       /* parameter values, or NULL */
  int native;               /* enum dm_native_mode, | DM_BUNDLE_BACKGROUND */
} dm_bundle_src;

/* With DM_NATIVE_AUTO: compile in the background (install with
 * dm_bundle_update). */
#define DM_BUNDLE_BACKGROUND 0x100

typedef struct dm_bundle {
  dm_tape *tape;
  dm_native *nat;
  dm_native_fn fn;
  dm_native_scatter_fn scatter;   /* native, writing the caller's arrays */
  size_t nout, nregs;
  /* tape path: the outputs are laid out in the tape's slots (registers
   * from slot0) exactly as in the arrays: array a is slots aoff[a] ..
   * aoff[a+1] */
  size_t slot0;
  uint32_t narr, aoff[33];
  uint32_t nchk, *chk;            /* the registers to test for NaN/Inf */
  size_t nin;                     /* inputs */
  unsigned have;                  /* bits of the arrays it fills */
  unsigned fill;                  /* bits below narr of the arrays it lacks */
  dm_native_job *job;             /* native code on its way (background) */
  int native_failed;              /* the background compilation failed */
  dm_err native_err;              /* and why */
} dm_bundle;

/* Compile nout outputs out on the first nin inputs of src, stored by the
 * nblk blocks blk (nblk = 0: no arrays, for dm_bundle_run_plain only).
 * exact: out was rewritten by dm_tape_optimize already (with blocks the
 * outputs are always compiled as they are). */
int dm_bundle_compile(dm_bundle *p, const dm_bundle_src *src, size_t nout, const dm_expr *out,
                      size_t nin, const dm_block *blk, size_t nblk, int exact, dm_err *err);
void dm_bundle_free(dm_bundle *p);
/* Background compilation: install native code that has become ready (1),
 * nothing yet (0: the tape runs on); a failure ends the job, the tape
 * stays (native_failed, native_err).  Call it between runs or steps,
 * never while the bundle is being run. */
int dm_bundle_update(dm_bundle *p);
/* 1 while a background compilation is queued or running. */
static inline int dm_bundle_pending(const dm_bundle *p)
{
  return p->job != NULL;
}
/* Wait for the background compilation and install it; Ctrl-C stops
 * waiting (interruptible).  DM_OK also when there was none. */
int dm_bundle_wait(dm_bundle *p, int interruptible, dm_err *err);
/* Cancel a background compilation (the tape stays); DM_EINTR when there
 * was one, else DM_OK. */
int dm_bundle_cancel(dm_bundle *p, dm_err *err);

/* Outputs in order into w + nregs, the inputs being already in w (the
 * tape's first registers).  Returns w + nregs. */
static inline double *dm_bundle_run_plain(const dm_bundle *p, double *w, const double *par)
{
  double *o = w + p->nregs;
  if (p->fn != NULL)
    p->fn(w, par, o);
  else
    dm_tape_eval(p->tape, w, par, o, w);
  return o;
}

/* Bit 63 set when x is NaN or infinite (its exponent is all ones): ORed
 * over many values without floating-point compares. */
static inline uint64_t dm_bundle_nonfinite_bit(double x)
{
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  return (u & 0x7ff0000000000000ULL) + 0x0010000000000000ULL;
}

/* The tape path of a run: run on the inputs already in w (its slots then
 * hold the arrays' contents), test every output for NaN/Inf, requested or
 * not, as native code does, copy the arrays whose bit is in mask.  Returns
 * 1 (nothing written) when an output is NaN or Inf. */
static inline int dm_bundle_tape_scatter(const dm_bundle *p, double *w, const double *par,
                                         double *const *out, unsigned mask)
{
  dm_tape_run(p->tape, w, par, w);
  const uint32_t *chk = p->chk, nchk = p->nchk;
  uint64_t bad = 0;
  for (uint32_t j = 0; j < nchk; j++)
    bad |= dm_bundle_nonfinite_bit(w[chk[j]]);
  if (bad >> 63)
    return 1;
  const double *v = w + p->slot0;
  for (uint32_t a = 0; a < p->narr; a++)
    if (mask & (1u << a))
      dm_copy_doubles(out[a], v + p->aoff[a], p->aoff[a + 1] - p->aoff[a]);
  return 0;
}

/* A whole run: the inputs from the arrays in[0 .. nin/inlen), the outputs
 * into the arrays of mask; 1 when an output is NaN or Inf (the arrays are
 * then untouched on the tape path, partly written by native code), else 0.
 * work: nregs doubles. */
static inline int dm_bundle_run(const dm_bundle *p, const double *const *in, size_t inlen,
                                const double *par, double *const *out, unsigned mask,
                                double *work)
{
  if (p->scatter != NULL)
    return p->scatter(in, par, out, mask, work);
  for (size_t k = 0, a = 0; k < p->nin; k += inlen, a++)
    for (size_t i = 0; i < inlen; i++)
      work[k + i] = in[a][i];
  return dm_bundle_tape_scatter(p, work, par, out, mask);
}

#endif
