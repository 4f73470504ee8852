/* prk_impl.h -- the implicit PRK engine's private state, shared by
 * prk_engine.c (Newton, predictor, Jacobian, discrete Legendre transforms),
 * prk_constrained.c (multipliers) and verlet.c (explicit paths). */
#ifndef DM_PRK_IMPL_H
#define DM_PRK_IMPL_H

#include "integrators/integ_impl.h"
#include "integrators/galerkin.h"

enum dm_prk_mode {
  DM_PRK_STEP,      /* unknowns: stage velocities V (s n) */
  DM_PRK_CSTEP      /* V, stage multipliers (nK m), initial multiplier mu0 (m) */
};

/* The sparse Newton matrix (prk_sparse.c). */
typedef struct dm_prk_sparse dm_prk_sparse;

/* Structure of a constant mass matrix (explicit Stormer-Verlet). */
enum dm_prk_mass { DM_MASS_FULL, DM_MASS_DIAG, DM_MASS_UNIT };

struct dm_prk {
  const dm_system *sys;
  dm_tableau *tab;             /* owned copy */
  size_t n, s, m, sn, nn;
  int forced;
  int sep;                     /* separable and unforced: Lvv = M, Lvq = Bm = 0 */
  int explicit_sv;             /* explicit Stormer-Verlet / RATTLE */
  int distinct_nodes;          /* predictor may interpolate */
  double tol;
  int maxiter;
  int simplified;              /* reuse the factored Jacobian while converging fast */
  /* fixed-point iteration V_i <- M^{-1} (p0 + h sum_j at_ij W_j) before
   * Newton (separable, unforced, unconstrained systems): iteration mode,
   * whether it applies, steps left before it is tried again */
  int iteration;               /* enum dm_iteration_mode */
  int fixed_ok;
  long fixed_backoff;
  int njac;                    /* Jacobian factorisations in the last solve */
  double lvv_norm;             /* max |Lvv| over the stages, set with the Jacobian */
  /* constraints: multipliers at the stages K (interior stages of a Lobatto
   * type tableau), plus mu0 on p0 and g(q1) = 0 (see prk_constrained.c) */
  size_t nK, K[DM_TABLEAU_SMAX];
  size_t Nmax;
  double *block;               /* the one allocation the arrays below share */
  int sparse;                  /* the Newton matrix is sparse (sp), not Jm */
  int large;                   /* sparse, and no n x n stage arrays at all */
  dm_prk_sparse *sp;
  double *Jm;                  /* Nmax x Nmax Newton matrix, then its LU (dense) */
  size_t *perm;
  double *R;                   /* Nmax residual / update */
  double *X;                   /* Nmax unknowns; V = X[0 .. sn) */
  double *Q, *Lq, *Lv, *W, *F; /* s n each; W = Lq + F */
  double *Lvv, *Lvq, *Lqq, *Fq, *Fv, *D, *Bm;  /* s n n each; D = Lqq + Fq, Bm = Lvq^T + Fv */
  double *Lval;                /* s values of L */
  double *g, *G, *Hc;          /* constraint values at s + 2 points: stages, q0 (s), q1 (s+1) */
  double *q1w, *p1w, *v1w, *dq, *dp, *tmp;   /* n each */
  double *rhs;                 /* Nmax x 2n, Jacobian right-hand sides */
  /* history: predictor and compensated summation */
  int hist;
  double hist_h, E_ratio;
  double *hV, *hx, *hq1, *hp1; /* sn, Nmax - sn, n, n */
  double *E;                   /* s x s extrapolation matrix */
  double *cq, *cp;             /* Kahan carries */
  /* separable systems */
  int mass_ready;              /* dm_prk_mass_setup has filled what follows */
  double mass_norm;            /* max |M_ij| */
  double *Mdiag;               /* n: the diagonal of M^{-1} */
  double *Minv;                /* n x n, a full mass only (malloc'ed) */
  int mass_kind;               /* DM_MASS_UNIT / _DIAG / _FULL: how M^{-1} applies */
  double *svf;                 /* Lq at hq1 (first same as last) */
  int svf_valid;
  dm_legendre_ws *leg;
  dm_galerkin *gal;            /* discrete Legendre transforms (m == 0; else NULL) */
  void *work;
};

/* prk_engine.c */
int dm_prk_eval_stage(dm_prk *P, size_t i, int jac, int want_L, dm_err *e);
int dm_prk_singular(dm_prk *P, const char *what, double h, dm_err *e);
/* DM_OK, or the error of a discrete Legendre transform that cannot be
 * taken (constrained system, h = 0). */
int dm_prk_dleg_check(const dm_prk *P, double h, dm_err *e);

/* prk_sparse.c */
/* The sparse matrix for the engine (its stage values from the dense
 * arrays, or, large, from values on the system's pattern). */
int dm_prk_sparse_setup(dm_prk *P, int large, dm_err *e);
void dm_prk_sparse_free(dm_prk_sparse *S);
/* Stage i's second derivatives from the dense stage arrays (after
 * dm_prk_eval_stage). */
void dm_prk_sparse_gather(dm_prk *P, size_t i);
/* dm_prk_eval_stage of the large engine. */
int dm_prk_sparse_eval_stage(dm_prk *P, size_t i, int jac, int want_L, dm_err *e);
double dm_prk_sparse_lvv_norm(const dm_prk *P);
/* The matrix's values for step h (after every stage and, with
 * constraints, dm_prk_constr_assemble). */
void dm_prk_sparse_matrix(dm_prk *P, double h);
int dm_prk_sparse_factor(dm_prk *P, dm_err *e);
void dm_prk_sparse_solve(dm_prk *P, double *b);
/* *f += row a of (D_j xq + Bm_j xv); entry (a, c) of Lvq_j and D_j. */
void dm_prk_sparse_rowdot(const dm_prk *P, size_t j, size_t a, const double *xq,
                          const double *xv, double *f);
void dm_prk_sparse_entries(const dm_prk *P, size_t j, size_t a, size_t c, double *lvq,
                           double *d);
size_t dm_prk_sparse_nnz(const dm_prk *P);

/* prk_constrained.c */
int dm_prk_constr_layout(dm_prk *P, dm_err *e);
int dm_prk_constr_begin(dm_prk *P, const double *q0, dm_err *e);
int dm_prk_constr_assemble(dm_prk *P, double h, const double *q0, int jac, dm_err *e);
int dm_prk_constr_finish(dm_prk *P, double h, const double *q0, const double *p0,
                         double *q1, double *p1, dm_err *e);
int dm_prk_project_momentum(dm_prk *P, const double *q1, const double *G1,
                            double *p1, const double *vguess, dm_err *e);

/* composition.c: the coefficients g[0 .. *s) (at most 17) of a composition
 * scheme by name, or for "" the default scheme of the order (4, 6, 8);
 * *order_out its order.  DM_ENOTFOUND / DM_EINVAL with a message. */
int dm_composition_coeffs(const char *scheme, int order, double *g, size_t *s,
                          int *order_out, dm_err *e);

/* verlet.c */
int dm_prk_mass_setup(dm_prk *P, dm_err *e);
int dm_prk_verlet_setup(dm_prk *P, dm_err *e);
int dm_prk_verlet_step(dm_prk *P, double h, const double *q0, const double *p0,
                       int cont, double *q1, double *p1, dm_integ_stats *st, dm_err *e);
/* nsteps steps of ns substeps g[j] h each (g = NULL: plain Stormer-Verlet) */
int dm_prk_verlet_advance(dm_prk *P, double h, const double *g, size_t ns, long nsteps,
                          double *q, double *p, long *done, dm_integ_stats *st, dm_err *e);

#endif
