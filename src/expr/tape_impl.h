/* tape_impl.h -- the tape structure, shared by tape.c (compiling) and
 * tape_eval.c (running).  Not a public header. */
#ifndef DM_TAPE_IMPL_H
#define DM_TAPE_IMPL_H

#include "expr/tape.h"

#define DM_TAPE_BATCH 32      /* points per block in batch evaluation */

/* An instruction as the evaluation loop runs it (direct threading): the
 * address of its handler (GNU C; else the op), the result register and up
 * to three operand registers (b: the exponent for POWI). */
typedef struct dm_tape_xins {
  const void *op;
  uint32_t d, a, b, c;
} dm_tape_xins;

struct dm_tape {
  size_t nin, npar, nconst, nout, ninstr, nregs;
  size_t nslot, slot0;      /* output slots: registers slot0 .. +nslot */
  size_t ncopy;             /* at the end of a run, register copy[j][1] */
  uint32_t (*copy)[2];      /* into register copy[j][0] (slots) */
  double *preset;           /* the constants and the slots: what the
                               registers from nin + npar hold before a run
                               (constant outputs are there already) */
  dm_tape_ins *code;
  dm_tape_xins *xcode;      /* ninstr + 1: the last one stops */
  double *consts;
  uint32_t *outreg;
};

/* Fill t->xcode from t->code (allocated here; DM_ENOMEM). */
int dm_tape__thread(dm_tape *t);

/* Rewrite the outputs out[nout] for compiling (factored sums, shared
 * powers and reciprocals; tape_opt.c) into nw[nout], with nodes built
 * without simplification.  Uses the context's traversal scratch. */
int dm_tape__optimize(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                      dm_expr *nw, dm_err *err);

#endif
