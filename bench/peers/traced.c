/* traced.c -- see traced.h.  The expressions are written the way the Lua
 * examples write them (integer powers, sqrt, parameters by name). */
#include <config.h>
#include <stdio.h>
#include <string.h>
#include "traced.h"
#include "expr/expr.h"

const char *const bt_names[BT_NSYS] = {
  "Kepler (2-D)", "J2 Cartesian", "J2 cylindrical", "spherical pendulum",
  "double sph. pendulum R3xR3 + 2 constraints", "double sph. pendulum cylindrical"
};

#define C(x) dm_expr_const(X, (x))
#define ADD(a, b) dm_expr_add(X, (a), (b))
#define SUB(a, b) dm_expr_sub(X, (a), (b))
#define MUL(a, b) dm_expr_mul(X, (a), (b))
#define DIV(a, b) dm_expr_div(X, (a), (b))
#define SQ(a) dm_expr_powi(X, (a), 2)
#define POWI(a, k) dm_expr_powi(X, (a), (k))

static dm_expr fn1(dm_expr_ctx *X, const char *f, dm_expr a)
{
  return dm_expr_call(X, f, 1, &a);
}
#define SQRT(a) fn1(X, "sqrt", (a))
#define COS(a) fn1(X, "cos", (a))
#define SIN(a) fn1(X, "sin", (a))

int bt_build(int which, int native, dm_system *sys, dm_lagrangian_stats *st, dm_err *e)
{
  static const char *qn[6][6] = {
    {"x", "y"}, {"x", "y", "z"}, {"r", "th", "z"}, {"th", "ph"},
    {"x1", "y1", "z1", "x2", "y2", "z2"}, {"r1", "th1", "r2", "th2"}};
  static const size_t nn[6] = {2, 3, 3, 2, 6, 4};
  static const char *pn[6][5] = {
    {"mu"}, {"J2"}, {"J2"}, {"g", "l"}, {"m1", "m2", "g", "l1", "l2"}, {"m1", "m2", "g", "l1", "l2"}};
  static const double pv[6][5] = {
    {1.0}, {0.05}, {0.05}, {9.81, 1.3}, {1.0, 1.3, 9.81, 1.1, 0.8}, {1.0, 1.3, 9.81, 1.1, 0.8}};
  static const size_t np[6] = {1, 1, 1, 2, 5, 5};
  dm_expr_ctx *X;
  dm_expr q[6], v[6], par[5], L, g[2];
  dm_lagrangian_spec sp;
  char vb[8];
  size_t n, i, m = 0;
  int rc;
  if (which < 0 || which >= BT_NSYS)
    return dm_err_set(e, DM_EINVAL, "bt_build: unknown system %d", which);
  if ((X = dm_expr_ctx_alloc()) == NULL)
    return dm_err_set(e, DM_ENOMEM, "bt_build: out of memory");
  n = nn[which];
  for (i = 0; i < n; i++) {
    q[i] = dm_expr_sym(X, qn[which][i]);
    snprintf(vb, sizeof vb, "v%s", qn[which][i]);
    v[i] = dm_expr_sym(X, vb);
  }
  for (i = 0; i < np[which]; i++)
    par[i] = dm_expr_param(X, pn[which][i]);
  switch (which) {
  case BT_KEPLER:
    L = ADD(MUL(C(0.5), ADD(SQ(v[0]), SQ(v[1]))), DIV(par[0], SQRT(ADD(SQ(q[0]), SQ(q[1])))));
    break;
  case BT_J2: {
    dm_expr R = SQRT(ADD(ADD(SQ(q[0]), SQ(q[1])), SQ(q[2])));
    dm_expr V = ADD(DIV(C(-1.0), R), MUL(DIV(par[0], POWI(R, 3)),
                                         SUB(DIV(MUL(C(1.5), SQ(q[2])), SQ(R)), C(0.5))));
    L = SUB(MUL(C(0.5), ADD(ADD(SQ(v[0]), SQ(v[1])), SQ(v[2]))), V);
    break;
  }
  case BT_J2_CYL: {
    dm_expr r = q[0], z = q[2], R = SQRT(ADD(SQ(r), SQ(z)));
    dm_expr V = ADD(DIV(C(-1.0), R), MUL(DIV(par[0], POWI(R, 3)),
                                         SUB(DIV(MUL(C(1.5), SQ(z)), SQ(R)), C(0.5))));
    L = SUB(MUL(C(0.5), ADD(ADD(SQ(v[0]), MUL(SQ(r), SQ(v[1]))), SQ(v[2]))), V);
    break;
  }
  case BT_SPH_PEND: {
    dm_expr l2 = SQ(par[1]);
    L = ADD(MUL(MUL(C(0.5), l2), ADD(SQ(v[0]), MUL(SQ(SIN(q[0])), SQ(v[1])))),
            MUL(MUL(par[0], par[1]), COS(q[0])));
    break;
  }
  case BT_DSP_CART: {
    dm_expr m1 = par[0], m2 = par[1], gg = par[2], l1 = par[3], l2 = par[4];
    dm_expr T1 = ADD(ADD(SQ(v[0]), SQ(v[1])), SQ(v[2]));
    dm_expr T2 = ADD(ADD(SQ(ADD(v[0], v[3])), SQ(ADD(v[1], v[4]))), SQ(ADD(v[2], v[5])));
    dm_expr T = MUL(C(0.5), ADD(MUL(m1, T1), MUL(m2, T2)));
    dm_expr V = MUL(gg, ADD(MUL(m1, q[2]), MUL(m2, ADD(q[2], q[5]))));
    L = SUB(T, V);
    g[0] = SUB(SQRT(ADD(ADD(SQ(q[0]), SQ(q[1])), SQ(q[2]))), l1);
    g[1] = SUB(SQRT(ADD(ADD(SQ(q[3]), SQ(q[4])), SQ(q[5]))), l2);
    m = 2;
    break;
  }
  default: { /* BT_DSP_CYL: q_i = (r_i cos th_i, r_i sin th_i, -sqrt(l_i^2 - r_i^2)) */
    dm_expr m1 = par[0], m2 = par[1], gg = par[2], l1 = par[3], l2 = par[4];
    dm_expr r1 = q[0], t1 = q[1], r2 = q[2], t2 = q[3];
    dm_expr z1 = dm_expr_neg(X, SQRT(SUB(SQ(l1), SQ(r1))));
    dm_expr z2 = dm_expr_neg(X, SQRT(SUB(SQ(l2), SQ(r2))));
    /* velocities of the relative positions in Cartesian components */
    dm_expr x1d = SUB(MUL(v[0], COS(t1)), MUL(MUL(r1, SIN(t1)), v[1]));
    dm_expr y1d = ADD(MUL(v[0], SIN(t1)), MUL(MUL(r1, COS(t1)), v[1]));
    dm_expr z1d = DIV(MUL(r1, v[0]), dm_expr_neg(X, z1));
    dm_expr x2d = SUB(MUL(v[2], COS(t2)), MUL(MUL(r2, SIN(t2)), v[3]));
    dm_expr y2d = ADD(MUL(v[2], SIN(t2)), MUL(MUL(r2, COS(t2)), v[3]));
    dm_expr z2d = DIV(MUL(r2, v[2]), dm_expr_neg(X, z2));
    dm_expr T1 = ADD(ADD(SQ(x1d), SQ(y1d)), SQ(z1d));
    dm_expr T2 = ADD(ADD(SQ(ADD(x1d, x2d)), SQ(ADD(y1d, y2d))), SQ(ADD(z1d, z2d)));
    dm_expr T = MUL(C(0.5), ADD(MUL(m1, T1), MUL(m2, T2)));
    dm_expr V = MUL(gg, ADD(MUL(m1, z1), MUL(m2, ADD(z1, z2))));
    L = SUB(T, V);
    break;
  }
  }
  if (dm_expr_ctx_err(X)->status != DM_OK) {
    rc = dm_err_set(e, dm_expr_ctx_err(X)->status, "%s", dm_expr_ctx_err(X)->msg);
    dm_expr_ctx_free(X);
    return rc;
  }
  memset(&sp, 0, sizeof sp);
  sp.name = bt_names[which];
  sp.n = n;
  sp.q = q;
  sp.v = v;
  sp.npar = np[which];
  sp.par = par;
  sp.par_values = pv[which];
  sp.L = L;
  sp.m = m;
  sp.constraints = m ? g : NULL;
  sp.native = native;
  rc = dm_lagrangian_compile(X, &sp, sys, e);
  if (rc == DM_OK && st)
    rc = dm_lagrangian_stats_get(sys, st);
  dm_expr_ctx_free(X);
  return rc;
}
