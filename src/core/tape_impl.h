/* tape_impl.h -- the tape structure, shared by tape.c (compiling) and
 * tape_eval.c (running).  Not a public header. */
#ifndef DM_TAPE_IMPL_H
#define DM_TAPE_IMPL_H

#include "tape.h"

#define DM_TAPE_BATCH 32      /* points per block in batch evaluation */

struct dm_tape {
  size_t nin, npar, nconst, nout, ninstr, nregs;
  dm_tape_ins *code;
  double *consts;
  uint32_t *outreg;
};

/* Rewrite the outputs out[nout] for compiling (factored sums, shared
 * powers and reciprocals; tape_opt.c) into nw[nout], with nodes built
 * without simplification.  Uses the context's traversal scratch. */
int dm_tape__optimize(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                      dm_expr *nw, dm_err *err);

#endif
