/* prk_kernels.h -- pieces of the implicit PRK step shared by the core
 * engine (prk_engine.c, prk_constrained.c) and the reduced RSPRK engine of
 * src/reduce (rsprk.c, rsprk_constr.c), which solve the same stage
 * equations on different state.  Everything works on arrays owned by the
 * caller (row-major, stage-major: stage i of an s x n array is row i);
 * nothing allocates and nothing fails.
 */
#ifndef DM_PRK_KERNELS_H
#define DM_PRK_KERNELS_H

#include <stddef.h>

/* The stage predictor: the previous step's stage values hV (s x n, at the
 * nodes c of its step) extrapolated to the stage times of the next step,
 * X_i = sum_j l_j(1 + r c_i) hV_j, with l_j the Lagrange basis on c and
 * r = h / h_prev (nodes distinct).  E (s x s) caches the basis values for
 * the ratio *E_ratio: recomputed (and *E_ratio set) when r differs, so a
 * caller invalidates it with *E_ratio = NAN.  X must not overlap hV. */
void dm_prk_extrapolate(size_t s, size_t n, const double *c, double r, double *E,
                        double *E_ratio, const double *hV, double *X);

#endif
