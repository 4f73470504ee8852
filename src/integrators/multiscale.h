/* multiscale.h -- multiscale variational integrators (method "multiscale",
 * doc/beyond-fixed-steps.md §4) and the Filon-Lobatto phase-sampled quadrature they
 * integrate with.
 *
 * The step is the nodal Galerkin step of a discrete action S over a space
 * of curves in which the "fast" coordinates carry, besides the polynomial
 * 1 - tau, tau, tau (1 - tau), the oscillatory bubbles sin wt - tau sin wh
 * and cos wt - (1 - tau) - tau cos wh (tau = t/h) of a fixed fast frequency
 * w, the other coordinates cubic Lagrange polynomials (nodes 0, 1/3, 2/3,
 * 1).  S = sum_ij C_ij L(q(c_i h, phi_j), v(c_i h, phi_j)): the integrand
 * is sampled at nu Lobatto nodes in time and K phases phi_j = 2 pi j/K of
 * the oscillation, with weights exact for trigonometric polynomials of
 * degree < K/2 in the phase and Filon (exact) in the oscillation
 * (dm_filon_phase_weights).  A step from (q0, p0) solves p0 + dS/dq0 = 0,
 * dS/d(internal) = 0 for q1 and the internal degrees of freedom by Newton
 * with the exact Hessian of S; p1 = dS/dq1.  Options: omega (0: estimated
 * at the first step, dm_multiscale_frequency), fast (coordinate names,
 * comma-separated; "": the coordinate the estimate names), nodes (nu >= 3,
 * default 4), phases (K >= 4, default 8).  Unforced, unconstrained
 * Lagrangian systems (DM_EUNSUP).  Ownership and errors as integrator.h.
 */
#ifndef DM_MULTISCALE_H
#define DM_MULTISCALE_H

#include <stddef.h>
#include "integrators/integrator.h"

/* b_i(theta) = int_0^1 l_i(x) e^{i theta x} dx for the Lagrange basis l_i
 * of nu distinct nodes c in [0, 1] (1 <= nu <= 12), into b as nu complex
 * numbers (re, im interleaved: 2 nu doubles; no <complex.h> here, whose
 * macro I would clash with the integrators' parameter names): by the moments
 * mu_r = int x^r e^{i theta x} (mu_0 = (e^{i theta} - 1)/(i theta),
 * mu_r = (e^{i theta} - r mu_{r-1})/(i theta)) for |theta| >= nu + 1, by a
 * 20-point Gauss rule below (where the recursion loses digits). */
int dm_filon_weights(size_t nu, const double *c, double theta, double *b, dm_err *e);

/* The phase-sampled weights C (nu x K, row-major) with
 * int_0^h G(t, w t) dt ~ sum_ij C_ij G(c_i h, 2 pi j/K), exact when G is a
 * polynomial of degree < nu in t times a trigonometric polynomial of degree
 * < K/2 in the phase:  C_ij = (h/K) Re sum_{|n|<K/2} b_i(n w h) e^{-i n phi_j}. */
int dm_filon_phase_weights(size_t nu, const double *c, size_t K, double h, double omega,
                           double *C, dm_err *e);

/* The fast frequency of sys at (q0, p0): the largest w with
 * (-Lqq) x = w^2 Lvv x at (q0, v(q0, p0)) (the linearisation; gensymm
 * eigenproblem), refined by the peak of the Hann-windowed FFT of the
 * coordinate with the largest share in that mode over a resolved run
 * (Gauss s = 2, 32 steps per fast period, 64 periods).  *coord (may be
 * NULL) = that coordinate.  DM_EDOM when the linearisation has no
 * oscillatory mode. */
int dm_multiscale_frequency(const dm_system *sys, const double *q0, const double *p0,
                            double *omega, size_t *coord, dm_err *e);

/* The fast frequency a multiscale integrator uses (NaN before it is known). */
double dm_multiscale_omega(const dm_integrator *I);

#endif
