/* builtin_systems.h -- hand-written C systems (the speed references for the
 * benchmarks and the test systems of the integrators).
 *
 * Each constructor fills a caller-provided dm_system (its previous contents
 * are ignored) and allocates the parameter vector, the mass matrix and the
 * names; release them with dm_system_release().  On error (DM_ENOMEM,
 * DM_EINVAL) *s is zeroed and nothing is leaked.  Parameters live in s->par
 * under the names in s->params and may be changed between steps.
 * All Lagrangians have unit mass unless stated; all derivatives are exact.
 */
#ifndef DM_BUILTIN_SYSTEMS_H
#define DM_BUILTIN_SYSTEMS_H

#include "core/status.h"
#include "core/system.h"

/* The systems of the catalogue (dm.systems, lua/dmech/systems.lua) written
 * in C: the same Lagrangians, coordinate names, parameter names and order,
 * so that dm.systems.<name>{impl = "c"} is the same system.  A mass that
 * depends on a parameter is refreshed by s->refresh after a change. */

/* L = m v^2/2 - m omega^2 x^2/2 (coordinate x; par: m, omega). Separable. */
int dm_builtin_harmonic(dm_system *s, double m, double omega, dm_err *e);

/* L = m l^2 v^2/2 + m g l cos(theta) (coordinate theta; par: g, l, m;
 * g = l = m = 1 in doc/integrators.md §12). Separable. */
int dm_builtin_pendulum(dm_system *s, double g, double l, double m, dm_err *e);

/* Kepler problem in dim = 2 or 3 Cartesian coordinates:
 * L = 1/2 |v|^2 + mu / |q| (par: mu). Separable. */
int dm_builtin_kepler(dm_system *s, int dim, double mu, dm_err *e);

/* J2 satellite, Cartesian (x, y, z), non-dimensional (doc/reduce.md §13, the
 * corrected potential):
 *   V = -1/|q| + (J2/|q|^3) (3 z^2 / (2 |q|^2) - 1/2),  L = 1/2 |v|^2 - V.
 * (par: J2). Separable. */
int dm_builtin_j2(dm_system *s, double J2, dm_err *e);

/* Damped oscillator: L = m v^2/2 - m omega^2 x^2/2 with the generalized
 * force F = -c v (par: m, omega, c). Energy decays like exp(-c t/m) for
 * light damping. */
int dm_builtin_damped_oscillator(dm_system *s, double m, double omega, double c, dm_err *e);

/* Spherical pendulum in R^3 with one holonomic constraint:
 *   L = m |v|^2/2 - m g z,   form 0: g(q) = |q|^2 - l^2,   form 1: g(q) = |q| - l
 * (par: g, l, m). Separable. */
int dm_builtin_spherical_pendulum_r3(dm_system *s, double g, double l, double m, int form,
                                     dm_err *e);

/* Spherical pendulum in spherical coordinates (theta from the downward
 * vertical, phi azimuth), q = l (sin th cos ph, sin th sin ph, -cos th):
 *   L = m l^2 (thdot^2 + sin^2 th phdot^2)/2 + m g l cos th   (par: g, l, m).
 * Mechanical (not separable); phi is cyclic. */
int dm_builtin_spherical_pendulum(dm_system *s, double g, double l, double m, dm_err *e);

#endif
