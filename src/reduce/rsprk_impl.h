/* rsprk_impl.h -- private state of the RSPRK engine, shared by rsprk.c
 * (stages, Newton, step, Jacobian) and rsprk_constr.c (multipliers). */
#ifndef DM_RSPRK_IMPL_H
#define DM_RSPRK_IMPL_H

#include "reduce/routh_impl.h"

struct dm_rsprk {
  dm_routh *red;
  const dm_system *sys;          /* red->rsys: R^mu, reduced force, constraints */
  dm_tableau *tab;               /* owned copy */
  size_t d, S, m, r, Sd, dd;     /* shape dim, stages, constraints, group dim */
  int forced, gyro;
  double tol;
  int maxiter, simplified;
  size_t nK, K[DM_TABLEAU_SMAX]; /* constrained stages (Lobatto interior) */
  size_t N;                      /* Newton unknowns */
  int distinct_nodes;
  double *Jm, *R, *X, *rhs;      /* N*N, N, N, N*2d */
  double *Xs, *Lq, *Lv, *F, *Sdot, *ga, *gkv, *gib;                  /* S*d each */
  double *Lvv, *Lvq, *Lqq, *Fq, *Fv, *gK, *gB, *gdkv, *gdib, *D, *E;  /* S*d*d each */
  double *sout[DM_TABLEAU_SMAX][DM_RS_NARR];  /* stage i's arrays in the stage
                                                 programs' order (dm_rstage_arr) */
  double *Lval;                  /* S */
  double *a0, *a1, *K0, *K1;     /* d, d, d*d, d*d */
  double *g, *G, *Hc;            /* constraint values at S + 2 points: stages, x0 (S), x1 (S+1) */
  double *q1w, *p1w, *v1w, *dq, *dp, *tmp;   /* d each */
  double *thd;                   /* r */
  /* history: predictor and compensated summation */
  int hist;
  double hist_h, E_ratio;
  double *hV, *hx, *hq1, *hp1, *Ex, *cq, *cp;
  double sing_ref;
  double lvv_norm;               /* max |Lvv| over the stages, set with the Jacobian */
  /* sparse Newton matrices (linear = sparse): the pattern J (stage
   * blocks on red->upat, every entry with constraints), the place in J of
   * entry p of stage block (i, k) (unconstrained), the values, KLU */
  int sparse;
  dm_csr J;
  uint32_t *jblk;                /* S*S*nnz(upat) */
  double *Jv;                    /* nnz(J) */
  dm_splu *slu;
  dm_rlu lu, lu_small;           /* N; d + m (velocity / projection) */
  double *small;                 /* (d + m)^2 + (d + m) */
  double *tin, *tout, *twork;    /* program input (2d), outputs, tape work */
  void *work;                    /* system callback work */
};

int dm_rsprk_constr_layout(dm_rsprk *P, dm_err *e);
int dm_rsprk_constr_begin(dm_rsprk *P, const double *x0, dm_err *e);
int dm_rsprk_constr_assemble(dm_rsprk *P, double h, const double *x0, int jac, dm_err *e);
/* x1 and s1 (with the multiplier terms and the momentum projection) from the
 * converged stages; ds holds the unconstrained momentum increment on entry */
int dm_rsprk_constr_finish(dm_rsprk *P, double h, const double *x0, const double *s0,
                           double *x1, double *s1, dm_err *e);
/* s <- s - G1^T mu1 with the velocity v (Lvv v = s - G1^T mu1) tangent:
 * G1 v = 0 (R^mu is mechanical: one linear solve). */
int dm_rsprk_project(dm_rsprk *P, const double *x1, const double *G1, double *s, dm_err *e);
/* velocity v with dR/dxdot(x, v) = s (mechanical: Mtilde(x) v = s) */
int dm_rsprk_velocity(dm_rsprk *P, const double *x, const double *s, double *v, dm_err *e);

#endif
