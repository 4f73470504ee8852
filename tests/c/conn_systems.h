/* conn_systems.h -- connections written by hand in C for the connection
 * tests (and the holonomy benchmark): their local forms A_loc(x) with
 * exact derivatives, from the closed forms of
 * doc/bundles-connections-holonomy.md.
 *   platform   point mass m at body position (u, v) on a platform of
 *              inertia I: A = m (-v, u)/(I + m rho^2)
 *   cat        the planar three-link cat (three uniform rods of mass 1,
 *              length 1): A = [sum r_i x dr_i/dx + (1, 1)/12] /
 *              [sum |r_i|^2 + 3/12]
 *   rotor      SO(3) with rotors: constant columns (k_i/I_i) e_i
 *   twist      a non-constant so(3)-valued form on R^2 (random tests)
 *   orbiter    heading = polar angle: A = (p_y, -p_x)/|p|^2
 * Header only; static functions of the dm_conn_fn type. */
#ifndef CONN_SYSTEMS_H
#define CONN_SYSTEMS_H

#include <math.h>
#include <string.h>

#include "conn/conn.h"

typedef struct plat_par {
  double I, m;
} plat_par;

static inline int plat_A(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  const plat_par *p = ud;
  double u = x[0], v = x[1], D = p->I + p->m * (u * u + v * v), D2 = D * D;
  (void)e;
  A[0] = -p->m * v / D;
  A[1] = p->m * u / D;
  if (dA) {
    /* d/du, then d/dv */
    dA[0] = 2.0 * p->m * p->m * v * u / D2;
    dA[1] = p->m / D - 2.0 * p->m * p->m * u * u / D2;
    dA[2] = -p->m / D + 2.0 * p->m * p->m * v * v / D2;
    dA[3] = -2.0 * p->m * p->m * u * v / D2;
  }
  return DM_OK;
}

/* the cat: centres of the rods relative to the centre of mass and their
 * derivatives in x1, x2 */
static inline void cat_geometry(const double *x, double r[3][2], double dr[2][3][2])
{
  double c[3][2], dc[2][3][2], cm[2], dcm[2][2];
  int i, k, a;
  memset(dc, 0, sizeof dc);
  c[0][0] = 0.0;
  c[0][1] = 0.0;
  c[1][0] = -0.5 - 0.5 * cos(x[0]);
  c[1][1] = -0.5 * sin(x[0]);
  c[2][0] = 0.5 + 0.5 * cos(x[1]);
  c[2][1] = 0.5 * sin(x[1]);
  dc[0][1][0] = 0.5 * sin(x[0]);
  dc[0][1][1] = -0.5 * cos(x[0]);
  dc[1][2][0] = -0.5 * sin(x[1]);
  dc[1][2][1] = 0.5 * cos(x[1]);
  for (a = 0; a < 2; a++) {
    cm[a] = (c[0][a] + c[1][a] + c[2][a]) / 3.0;
    for (k = 0; k < 2; k++)
      dcm[k][a] = (dc[k][0][a] + dc[k][1][a] + dc[k][2][a]) / 3.0;
  }
  for (i = 0; i < 3; i++)
    for (a = 0; a < 2; a++) {
      r[i][a] = c[i][a] - cm[a];
      for (k = 0; k < 2; k++)
        dr[k][i][a] = dc[k][i][a] - dcm[k][a];
    }
}

static inline int cat_A(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  double r[3][2], dr[2][3][2], num[2] = {1.0 / 12, 1.0 / 12}, den = 0.25;
  int i, k;
  (void)ud;
  (void)e;
  cat_geometry(x, r, dr);
  for (i = 0; i < 3; i++) {
    den += r[i][0] * r[i][0] + r[i][1] * r[i][1];
    for (k = 0; k < 2; k++)
      num[k] += r[i][0] * dr[k][i][1] - r[i][1] * dr[k][i][0];
  }
  A[0] = num[0] / den;
  A[1] = num[1] / den;
  if (dA) {
    /* central differences of the closed form are not exact: the tests
     * that need dA use has_dA = 0 for the cat */
    return dm_err_set(e, DM_EINVAL, "cat: no derivatives");
  }
  return DM_OK;
}

typedef struct rotor_par {
  double c[3];          /* k_i / I_i */
} rotor_par;

static inline int rotor_A(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  const rotor_par *p = ud;
  int a, i;
  (void)x;
  (void)e;
  for (a = 0; a < 3; a++)
    for (i = 0; i < 3; i++)
      A[a * 3 + i] = a == i ? p->c[a] : 0.0;
  if (dA)
    memset(dA, 0, 27 * sizeof *dA);
  return DM_OK;
}

/* A(x) (3 x 2): columns depending on x, with exact derivatives */
static inline int twist_A(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  double u = x[0], v = x[1];
  (void)ud;
  (void)e;
  A[0] = 0.3 + 0.2 * sin(v);  A[1] = 0.1 * u;
  A[2] = 0.2 * cos(u);        A[3] = -0.4 + 0.1 * v * v;
  A[4] = 0.15 * u * v;        A[5] = 0.25 + 0.05 * u;
  if (dA) {
    /* d/du */
    dA[0] = 0.0;              dA[1] = 0.1;
    dA[2] = -0.2 * sin(u);    dA[3] = 0.0;
    dA[4] = 0.15 * v;         dA[5] = 0.05;
    /* d/dv */
    dA[6] = 0.2 * cos(v);     dA[7] = 0.0;
    dA[8] = 0.0;              dA[9] = 0.2 * v;
    dA[10] = 0.15 * u;        dA[11] = 0.0;
  }
  return DM_OK;
}

static inline int orbiter_A(void *ud, const double *x, double *A, double *dA, dm_err *e)
{
  double r2 = x[0] * x[0] + x[1] * x[1];
  (void)ud;
  if (!(r2 > 0.0))
    return dm_err_set(e, DM_EDOM, "orbiter: the origin is not in the shape space");
  A[0] = x[1] / r2;
  A[1] = -x[0] / r2;
  if (dA) {
    double r4 = r2 * r2;
    dA[0] = -2.0 * x[0] * x[1] / r4;
    dA[1] = -1.0 / r2 + 2.0 * x[0] * x[0] / r4;
    dA[2] = 1.0 / r2 - 2.0 * x[1] * x[1] / r4;
    dA[3] = 2.0 * x[0] * x[1] / r4;
  }
  return DM_OK;
}

#endif
