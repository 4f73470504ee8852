/* prk_kernels.h -- pieces of the implicit PRK step shared by the core
 * engine (prk_engine.c, prk_constrained.c) and the reduced RSPRK engine of
 * src/reduce (rsprk.c, rsprk_constr.c), which solve the same stage
 * equations on different state: the compensated update, the stage
 * predictor, the constraint multipliers (and, through vecmath.h, the
 * inline vector helpers of the hot path).
 * Everything works on arrays owned by the caller (row-major, stage-major:
 * stage i of an s x n array is row i); nothing allocates and nothing fails.
 */
#ifndef DM_PRK_KERNELS_H
#define DM_PRK_KERNELS_H

#include <stddef.h>
#include "core/tableau.h"
#include "core/vecmath.h"

/* {==== compensated update =============================================== */

/* out = x0 + dx with Kahan compensation: carry holds the rounding error of
 * the previous additions (zero at the start of a run) and is updated. */
static inline void dm_prk_kahan(size_t n, const double *x0, const double *dx, double *carry,
                                double *out)
{
  size_t i;
  for (i = 0; i < n; i++) {
    double y = dx[i] - carry[i];
    double t = x0[i] + y;
    carry[i] = (t - x0[i]) - y;
    out[i] = t;
  }
}

/* {==== stage predictor =================================================== */


/* The stage predictor: the previous step's stage values hV (s x n, at the
 * nodes c of its step) extrapolated to the stage times of the next step,
 * X_i = sum_j l_j(1 + r c_i) hV_j, with l_j the Lagrange basis on c and
 * r = h / h_prev (nodes distinct).  E (s x s) caches the basis values for
 * the ratio *E_ratio: recomputed (and *E_ratio set) when r differs, so a
 * caller invalidates it with *E_ratio = NAN.  X must not overlap hV. */
void dm_prk_extrapolate(size_t s, size_t n, const double *c, double r, double *E,
                        double *E_ratio, const double *hV, double *X);

/* {==== constraint multipliers (formulation: prk_constrained.c) ======== */

/* The stages that carry multipliers with tableau t: none for one stage,
 * the interior stages 1 .. s-2 of a Lobatto-type tableau (c_1 = 0, c_s = 1,
 * first row of a zero, last row of a = b, last column of at zero, first
 * column of at = b_1).  Sets *nK and K[0 .. *nK) (room for
 * DM_TABLEAU_SMAX) and returns 1; returns 0 (nothing set) for any other
 * tableau. */
int dm_prk_constr_stages(const dm_tableau *t, size_t *nK, size_t *K);

/* The multiplier terms of the constrained stage equations of tableau t on
 * n coordinates with m constraints, multipliers at the nK stages K.
 * Unknowns X = (V (s n), Lt_k (m each, k in K), mu0 (m)), N = s n + nK m + m
 * of them.  g (m), G (m x n) and Hc (m x n x n: [a][c][x] = d2g_a/dq_c dq_x)
 * hold the constraints at s + 2 points: slot k for stage k (Hc needed only
 * for k in K and only with Jm), slot s for q0, slot s + 1 for q1.
 *   R (N): adds G(q0)^T mu0 + sum_k at_ik G(Q_k)^T Lt_k to the stage rows,
 *          writes the constraint rows g(Q_k)/h and g(q1)/h;
 *   Jm (N x N, may be NULL): adds the curvature terms
 *          sum_k at_ik h a_kl (Lt_k . d2g(Q_k)) to the stage block, writes
 *          the multiplier columns and the constraint rows (their other
 *          entries must be zero on entry). */
void dm_prk_constr_terms(const dm_tableau *t, size_t n, size_t m, size_t nK, const size_t *K,
                         double h, const double *X, const double *g, const double *G,
                         const double *Hc, double *R, double *Jm);

/* The multiplier impulses on the momentum increment of the step, with the
 * layout above: dp -= G(q0)^T mu0 + sum_k b_k G(Q_k)^T Lt_k (n). */
void dm_prk_constr_momentum(const dm_tableau *t, size_t n, size_t m, size_t nK, const size_t *K,
                            const double *X, const double *G, double *dp);

#endif
