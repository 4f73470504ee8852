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

#endif
