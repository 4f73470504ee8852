/* gsl_peer.h -- GSL odeiv2 driven directly on the hand-written problems
 * (the way a GSL user writes it: y = (q, p), y' = (p, f(q)), exact Jacobian).
 *
 *   gp_system(prob)          the gsl_odeiv2_system of GP_KEPLER / GP_J2
 *   gp_fixed(T, prob, h, N, y, eps)
 *                            N fixed steps of h with gsl_odeiv2_step_apply
 *                            (stepper attached to a driver with epsabs = eps,
 *                            which the implicit steppers use for their Newton);
 *                            returns the GSL status
 *   gp_adaptive(T, prob, t1, tol, y, &maxdH, &nsteps)
 *                            gsl_odeiv2_evolve_apply with the standard y-control
 *                            (epsabs = epsrel = tol) from 0 to t1; when maxdH is
 *                            not NULL the energy error is sampled at every
 *                            accepted step.
 * y has 2n doubles and is updated in place. */
#ifndef BENCH_GSL_PEER_H
#define BENCH_GSL_PEER_H

#include <gsl/gsl_odeiv2.h>

enum { GP_KEPLER, GP_J2 };

gsl_odeiv2_system gp_system(int prob);
double gp_energy(int prob, const double *y);
int gp_fixed(const gsl_odeiv2_step_type *T, int prob, double h, long N, double *y, double eps);
int gp_adaptive(const gsl_odeiv2_step_type *T, int prob, double t1, double tol, double *y,
                double *maxdH, long *nsteps);

#endif
