/* sparse_impl.h -- private to src/dec/sparse*.c: CHOLMOD glue. */
#ifndef DM_DEC_SPARSE_IMPL_H
#define DM_DEC_SPARSE_IMPL_H

#include <suitesparse/cholmod.h>

#include "dec/sparse.h"

/* cholmod_start with printing and the error handler off. */
void dm_sparse__start(cholmod_common *c);
/* The CSR arrays of A read as the CSC matrix A^T, zero copy; stype as in
 * cholmod_sparse (a symmetric A is its own transpose). */
cholmod_sparse dm_sparse__view_t(const dm_sparse *A, int stype);

#endif
