/* reduce_systems.h -- test systems of the Routh reduction tests, built as
 * expressions (doc/reduce.md §13-14):
 *   J2 satellite in cylindrical coordinates (r, theta, z), param J2;
 *   double spherical pendulum in cylindrical coordinates with the bobs
 *   hanging below (r1, theta1, r2, phi), phi = theta2 - theta1, params
 *   m1, m2, l1, l2, g, optional damping force on the shape (param c);
 *   the same in R^3 x R^3 (r1, theta1, z1, r2, phi, z2) with the two length
 *   constraints r_i^2 + z_i^2 = l_i^2. */
#ifndef DM_REDUCE_SYSTEMS_H
#define DM_REDUCE_SYSTEMS_H

#include <string.h>
#include "expr/expr.h"
#include "reduce/routh.h"

typedef struct rsys {
  dm_expr_ctx *c;
  size_t n, npar, m;
  dm_expr q[6], v[6], par[8], L, F[6], g[2];
  double pv[8];
  int forced;
} rsys;

#define RC(x) dm_expr_const(S->c, (x))
#define RADD(a, b) dm_expr_add(S->c, (a), (b))
#define RSUB(a, b) dm_expr_sub(S->c, (a), (b))
#define RMUL(a, b) dm_expr_mul(S->c, (a), (b))
#define RDIV(a, b) dm_expr_div(S->c, (a), (b))
#define RSQ(a) dm_expr_powi(S->c, (a), 2)
#define RF(name, a) rs_call1(S->c, name, (a))

static inline dm_expr rs_call1(dm_expr_ctx *c, const char *f, dm_expr a)
{
  return dm_expr_call(c, f, 1, &a);
}

static inline void rs_syms(rsys *S, size_t n, const char *const *qn, const char *const *vn, size_t npar,
                    const char *const *pn, const double *pv)
{
  size_t i;
  memset(S, 0, sizeof *S);
  S->c = dm_expr_ctx_alloc();
  S->n = n;
  S->npar = npar;
  for (i = 0; i < n; i++) {
    S->q[i] = dm_expr_sym(S->c, qn[i]);
    S->v[i] = dm_expr_sym(S->c, vn[i]);
  }
  for (i = 0; i < npar; i++) {
    S->par[i] = dm_expr_param(S->c, pn[i]);
    S->pv[i] = pv[i];
  }
}

/* J2: V = -1/R + J2/R^3 (3 z^2/(2 R^2) - 1/2), R = sqrt(r^2 + z^2) */
static inline dm_expr rs_j2_potential(rsys *S, dm_expr r, dm_expr z)
{
  dm_expr R = RF("sqrt", RADD(RSQ(r), RSQ(z)));
  return RADD(RDIV(RC(-1.0), R),
              RMUL(RDIV(S->par[0], dm_expr_powi(S->c, R, 3)),
                   RSUB(RDIV(RMUL(RC(1.5), RSQ(z)), RSQ(R)), RC(0.5))));
}

static inline void rs_j2(rsys *S, double J2)
{
  static const char *qn[] = {"r", "theta", "z"}, *vn[] = {"rd", "thetad", "zd"}, *pn[] = {"J2"};
  dm_expr T;
  rs_syms(S, 3, qn, vn, 1, pn, &J2);
  T = RMUL(RC(0.5), RADD(RADD(RSQ(S->v[0]), RMUL(RSQ(S->q[0]), RSQ(S->v[1]))), RSQ(S->v[2])));
  S->L = RSUB(T, rs_j2_potential(S, S->q[0], S->q[2]));
}

/* kinetic energy of the double spherical pendulum from cylindrical data of
 * both bobs: (r, rdot, thetadot, z, zdot) per bob, phi, phidot implicit */
static inline dm_expr rs_dsp_T(rsys *S, dm_expr r1, dm_expr rd1, dm_expr thd1, dm_expr zd1, dm_expr r2,
                        dm_expr rd2, dm_expr thd2, dm_expr zd2, dm_expr phi)
{
  dm_expr m1 = S->par[0], m2 = S->par[1];
  dm_expr v1 = RADD(RADD(RSQ(rd1), RMUL(RSQ(r1), RSQ(thd1))), RSQ(zd1));
  dm_expr v2 = RADD(RADD(RSQ(rd2), RMUL(RSQ(r2), RSQ(thd2))), RSQ(zd2));
  dm_expr cp = RF("cos", phi), sp = RF("sin", phi);
  dm_expr d12 = RADD(RADD(RMUL(RADD(RMUL(rd1, rd2), RMUL(RMUL(r1, r2), RMUL(thd1, thd2))), cp),
                          RMUL(RSUB(RMUL(RMUL(r1, thd1), rd2), RMUL(RMUL(rd1, r2), thd2)), sp)),
                     RMUL(zd1, zd2));
  return RADD(RMUL(RMUL(RC(0.5), m1), v1),
              RMUL(RMUL(RC(0.5), m2), RADD(RADD(v1, v2), RMUL(RC(2.0), d12))));
}

/* params m1, m2, l1, l2, g (and c when forced) */
static inline void rs_dsp(rsys *S, const double *pv, int forced)
{
  static const char *qn[] = {"r1", "theta1", "r2", "phi"}, *vn[] = {"r1d", "theta1d", "r2d", "phid"};
  static const char *pn[] = {"m1", "m2", "l1", "l2", "g", "c"};
  dm_expr r1, r2, S1, S2, zd1, zd2, T, V;
  rs_syms(S, 4, qn, vn, forced ? 6 : 5, pn, pv);
  r1 = S->q[0];
  r2 = S->q[2];
  S1 = RF("sqrt", RSUB(RSQ(S->par[2]), RSQ(r1)));
  S2 = RF("sqrt", RSUB(RSQ(S->par[3]), RSQ(r2)));
  zd1 = RDIV(RMUL(r1, S->v[0]), S1);
  zd2 = RDIV(RMUL(r2, S->v[2]), S2);
  T = rs_dsp_T(S, r1, S->v[0], S->v[1], zd1, r2, S->v[2], RADD(S->v[1], S->v[3]), zd2, S->q[3]);
  V = RMUL(RMUL(RC(-1.0), S->par[4]), RADD(RMUL(S->par[0], S1), RMUL(S->par[1], RADD(S1, S2))));
  S->L = RSUB(T, V);
  if (forced) {
    /* damping of the shape velocities, plus a theta1dot-dependent drag on
     * r1 (the reduced force must substitute thetadot on J = mu) */
    S->forced = 1;
    S->F[0] = RMUL(RMUL(RC(-1.0), S->par[5]), RADD(S->v[0], RMUL(RMUL(RC(0.3), r1), S->v[1])));
    S->F[1] = RC(0.0);
    S->F[2] = RMUL(RMUL(RC(-1.0), S->par[5]), S->v[2]);
    S->F[3] = RMUL(RMUL(RC(-0.5), S->par[5]), S->v[3]);
  }
}

/* R^3 x R^3 in cylindrical coordinates of each bob with the length
 * constraints; params m1, m2, l1, l2, g */
static inline void rs_dsp_constrained(rsys *S, const double *pv)
{
  static const char *qn[] = {"r1", "theta1", "z1", "r2", "phi", "z2"};
  static const char *vn[] = {"r1d", "theta1d", "z1d", "r2d", "phid", "z2d"};
  static const char *pn[] = {"m1", "m2", "l1", "l2", "g"};
  dm_expr T, V;
  rs_syms(S, 6, qn, vn, 5, pn, pv);
  T = rs_dsp_T(S, S->q[0], S->v[0], S->v[1], S->v[2], S->q[3], S->v[3], RADD(S->v[1], S->v[4]),
               S->v[5], S->q[4]);
  V = RMUL(S->par[4], RADD(RMUL(S->par[0], S->q[2]), RMUL(S->par[1], RADD(S->q[2], S->q[5]))));
  S->L = RSUB(T, V);
  S->m = 2;
  S->g[0] = RSUB(RADD(RSQ(S->q[0]), RSQ(S->q[2])), RSQ(S->par[2]));
  S->g[1] = RSUB(RADD(RSQ(S->q[3]), RSQ(S->q[5])), RSQ(S->par[3]));
}

static inline int rs_reduce_native(rsys *S, size_t r, const size_t *cyc, const double *mu,
                                   int native, dm_routh **red, dm_err *e)
{
  dm_routh_spec sp;
  memset(&sp, 0, sizeof sp);
  sp.name = "test";
  sp.n = S->n;
  sp.q = S->q;
  sp.v = S->v;
  sp.npar = S->npar;
  sp.par = S->par;
  sp.par_values = S->pv;
  sp.L = S->L;
  sp.force = S->forced ? S->F : NULL;
  sp.m = S->m;
  sp.constraints = S->m ? S->g : NULL;
  sp.r = r;
  sp.cyclic = cyc;
  sp.mu = mu;
  sp.native = native;
  return dm_routh_derive(S->c, &sp, red, e);
}

static inline int rs_reduce(rsys *S, size_t r, const size_t *cyc, const double *mu, dm_routh **red,
                            dm_err *e)
{
  return rs_reduce_native(S, r, cyc, mu, DM_NATIVE_NEVER, red, e);
}

#endif
