/* dec_impl.h -- private to src/dec (and white-box tests). */
#ifndef DM_DEC_IMPL_H
#define DM_DEC_IMPL_H

#include "dec/dec.h"

/* The metric of one top n-simplex from its squared edge lengths D
 * ((n+1) x (n+1), row-major): volumes and signed dual pieces |*s cap top|
 * of every face, indexed by local vertex mask (2^(n+1) entries).  generic
 * forces the flag recursion for triangles too (the cotangent closed form is
 * used otherwise).  Returns 0, or the mask of a degenerate face. */
int dm_dec__top_pieces(int n, const double *D, int generic, double *vol, double *piece);

#endif
