/* routh_impl.h -- private state of the Routh reduction, shared by the files
 * of src/reduce (not part of the public API). */
#ifndef DM_ROUTH_IMPL_H
#define DM_ROUTH_IMPL_H

#include "reduce/routh.h"
#include "expr/bundle.h"
#include "core/newton.h"
#include "integrators/galerkin.h"
#include "expr/tape.h"
#include "core/sparse.h"

/* A compiled bundle of outputs: tape, and native code when available. */
typedef struct dm_rprog {
  dm_tape *tape;
  dm_native *nat;
  dm_native_fn fn;
  size_t nin, nout, nwork;   /* nwork: tape work doubles */
} dm_rprog;

static inline void dm_rprog_run(const dm_rprog *p, const double *in, const double *par,
                                double *out, double *work)
{
  if (p->fn)
    p->fn(in, par, out);
  else
    dm_tape_eval(p->tape, in, par, out, work);
}

/* The arrays an RSPRK stage program writes (bundle.h: output blocks, in
 * this order), at a stage point (x, xdot): the derivatives of R^mu (Lq =
 * dR/dx, Lv = dR/dxdot, Lvv, Lvq = d2R/dxdot dx, Lqq), the reduced force
 * and its Jacobians, the connection terms muA, K = d muA/dx, B, kv = K xdot,
 * ib = i_xdot B and their x-Jacobians dkv, dib.  The gradient program
 * (stage_r) writes LQ, LV, F, MUA, KV, IB; the full one (stage_j) all;
 * force and connection arrays only when the system has them. */
enum dm_rstage_arr {
  DM_RS_LQ, DM_RS_LV, DM_RS_LVV, DM_RS_LVQ, DM_RS_LQQ,
  DM_RS_F, DM_RS_FQ, DM_RS_FV,
  DM_RS_MUA, DM_RS_K, DM_RS_B, DM_RS_KV, DM_RS_IB, DM_RS_DKV, DM_RS_DIB,
  DM_RS_NARR
};

/* Small dense LU with partial pivoting on a row-major N x N matrix, in
 * place (dm_smalllu_factor of src/core/smalllu.h; this struct holds the
 * pivots); DM_ESINGULAR when a pivot is below 16 N eps max|a|, DM_EDOM for a
 * non-finite entry, DM_EINVAL when N differs from the size given to init. */
typedef struct dm_rlu {
  size_t N;
  size_t *perm;                    /* row interchanges */
} dm_rlu;

struct dm_routh {
  char *name;
  size_t n, r, s, m, npar, np;     /* np = npar + r */
  size_t cyc[DM_ROUTH_RMAX];
  size_t *shape;                   /* s */
  int has_gyro;                    /* mu^T A not identically zero */
  int general;                     /* L not mechanical: no connection, the
                                      classical Routhian is numerical
                                      (routh_general.c); rsys = csys */
  char *cname;                     /* general: name of csys */
  int has_force;
  double sing_tol;
  double *par;                     /* np: original params, then mu; shared by
                                      fsys, rsys, csys and sys (their .par) */
  double *fpar_own, *rpar_own, *cpar_own;  /* the compiled systems' private
                                      copies (read by dm_lagrangian_refresh) */
  char **names;                    /* s shape names + np param names */
  dm_system fsys, rsys, csys;      /* compiled full, reduced R, classical Rc */
  dm_system sys;                   /* the public reduced system (forwards to rsys) */
  dm_routh_exprs ex;
  dm_expr *exbuf;                  /* storage of the node arrays of ex */
  size_t *idxbuf;
  /* programs (inputs x, or (x, xdot); params par) */
  dm_rprog inertia;                /* x -> I (r*r) */
  dm_rprog conn;                   /* x -> Iinv_mu (r), A (r*s), muA (s) */
  dm_rprog connd;                  /* x -> D Iinv_mu (r*s), D A (r*s*s: [a][i][k] = dA_ai/dx_k) */
  dm_rprog gyro_r;                 /* (x, xd) -> muA, kv, ib */
  dm_bundle stage_r, stage_j;      /* (x, xd) -> the arrays of an RSPRK stage
                                      (dm_rstage_arr): gradient / all */
  dm_csr upat;                     /* s x s: the structural pattern of a stage
                                      block of the RSPRK Newton matrix */
  dm_rprog thd;                    /* (x, xd) -> thetadot (r) */
  dm_rprog info;                   /* (x, xd) -> everything of dm_routh_vals */
  size_t nwork;                    /* max tape work over the programs */
  double *scratch;                 /* for the evaluation helpers */
  size_t nscratch;
  double *lscratch;                /* reduced Legendre maps: 3 s + s*s + rsys work */
  dm_rlu lu_s;                     /* s x s */
};

/* routh_compile.c: compile the systems and programs from the derived nodes
 * (red->ex) and the internal ones: K = d muA/dx (s*s), kv = K xdot, ib =
 * i_xdot B (s each), their x-Jacobians dkv, dib (s*s), Dw = d(I^{-1} mu)/dx
 * (r*s), DA (r*s*s).  red->nwork covers the tapes of every program and
 * stage bundle. */
int dm_routh_compile_nodes(dm_routh *red, dm_expr_ctx *ctx, const dm_routh_spec *sp,
                           const dm_expr *K, const dm_expr *kv, const dm_expr *ib,
                           const dm_expr *dkv, const dm_expr *dib, const dm_expr *Dw,
                           const dm_expr *DA, dm_err *e);
void dm_routh_release_progs(dm_routh *red);
/* muA(x) (the connection term at zero velocity) from gyro_r; 1 when it is
 * not finite (muA then holds the values), else 0.  tin: 2 s, tout:
 * gyro_r.nout, work: red->nwork doubles. */
int dm_routh_muA(const dm_routh *red, const double *x, double *muA, double *tin, double *tout,
                 double *work);
/* muA(x) and K(x) = d muA/dx (s x s) from stage_j (zeros without a
 * connection term); 1 when an output of stage_j at (x, 0) is not finite
 * (muA, K then unspecified).  tin: 2 s, work: red->nwork doubles. */
int dm_routh_muA_K(const dm_routh *red, const double *x, double *muA, double *K, double *tin,
                   double *work);
/* The full system compiled from the spec (routh_compile.c). */
int dm_routh_compile_full(dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_system *sys, dm_err *e);
/* routh_general.c: the reduction of a non-mechanical L.  setup compiles
 * the full system and builds csys (= rsys) as the numerical classical
 * Routhian; thetadot solves J(x, u, xdot) = mu (par: the np parameters,
 * work: dm_routh_general_work bytes; 0, or 1 when there is no solution);
 * velocity inverts p_x = dRc/dxdot by Newton (red's scratch). */
int dm_routh_general_setup(dm_routh *red, dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_err *e);
size_t dm_routh_general_work(const dm_routh *red);
int dm_routh_general_thetadot(const dm_routh *red, const double *x, const double *xd,
                              const double *par, double *u, void *work);
int dm_routh_general_velocity(dm_routh *red, const double *x, const double *px, double *xd,
                              dm_err *e);
/* refresh hook of the public reduced system (par changed through it) */
int dm_routh_sys_refresh(dm_system *sys, dm_err *e);
int dm_routh_lag_forward(void *data, const double *q, const double *v, const double *par,
                         unsigned what, dm_lag_out *out, void *work);

/* Does d (an expression of the spec's q, v and parameters) vanish
 * identically?  Evaluated with its magnitude at pseudo-random points
 * (coordinate `angle` of q over [-pi, pi], the other positions in
 * [0.15, 0.55], velocities in [-1, 1], parameters near their values):
 * 1 when |d| <= 1e-10 times its magnitude at every finite point (at least
 * 8), 0 when not at some point, -1 when too few points are finite or out
 * of memory.  *worst (may be NULL): the largest |d| / magnitude seen
 * (routh_cyclic.c). */
int dm_routh_zero_by_eval(dm_expr_ctx *ctx, dm_expr d, const dm_routh_spec *sp, size_t angle,
                          double *worst);

/* Smallest and largest eigenvalue of the symmetric r x r matrix I (r <= 3;
 * closed form / Jacobi sweeps, no allocation). */
void dm_routh_sym_eig(const double *I, size_t r, double *lmin, double *lmax);

/* Gather / scatter between full coordinates and (theta, x). */
static inline void dm_routh_split(const dm_routh *red, const double *q, double *theta, double *x)
{
  size_t a, i;
  for (a = 0; theta && a < red->r; a++)
    theta[a] = q[red->cyc[a]];
  for (i = 0; x && i < red->s; i++)
    x[i] = q[red->shape[i]];
}

static inline void dm_routh_join(const dm_routh *red, const double *theta, const double *x,
                                 double *q)
{
  size_t a, i;
  for (a = 0; a < red->r; a++)
    q[red->cyc[a]] = theta ? theta[a] : 0.0;
  for (i = 0; i < red->s; i++)
    q[red->shape[i]] = x[i];
}

int dm_rlu_init(dm_rlu *lu, size_t N);
void dm_rlu_free(dm_rlu *lu);
int dm_rlu_factor(dm_rlu *lu, double *a, size_t N);
void dm_rlu_solve(const dm_rlu *lu, const double *a, size_t N, double *rhs);

double dm_rnorm_inf(const double *x, size_t n);

/* RSPRK engine (rsprk.c): the reduced symplectic PRK step of thesis eq.
 * 2.5.14 on T*S for any PRK tableau, constraints with Lobatto-type
 * tableaus (multipliers at every stage) or one stage. */
typedef struct dm_rsprk dm_rsprk;
/* linear: DM_LINEAR_AUTO, _DENSE or _SPARSE (core/sparse.h): how the
 * Newton matrices are factored (auto: by size and sparsity, rsprk.c) */
int dm_rsprk_alloc(dm_routh *red, const dm_tableau *t, double tol, int maxiter, int simplified,
                   int linear, dm_rsprk **out, dm_err *e);
/* DM_LINEAR_DENSE or DM_LINEAR_SPARSE as chosen; *nnz: entries of the
 * sparse Newton matrix (0 when dense) */
int dm_rsprk_linear(const dm_rsprk *P, size_t *nnz);
void dm_rsprk_free(dm_rsprk *P);
void dm_rsprk_reset(dm_rsprk *P);
/* (x0, s0) -> (x1, s1); dtheta (r, may be NULL) = h sum_j b_j Thetadot_j. */
int dm_rsprk_step(dm_rsprk *P, double h, const double *x0, const double *s0, double *x1,
                  double *s1, double *dtheta, dm_integ_stats *st, dm_err *e);
/* D(x1, s1)/D(x0, s0), 2s x 2s row-major (unconstrained only). */
int dm_rsprk_jacobian(dm_rsprk *P, double h, const double *x0, const double *s0, double *DPhi,
                      dm_integ_stats *st, dm_err *e);
const dm_tableau *dm_rsprk_tableau(const dm_rsprk *P);

/* The continuous Routh equations under a GSL explicit Runge-Kutta stepper
 * (routh_ode.c): y = (x, s, theta); step from (x0, s0) gives (x1, s1) and
 * the theta increment.  alloc sets *order; DM_EUNSUP for the implicit and
 * multistep steppers and for constrained reductions. */
typedef struct dm_rode dm_rode;
int dm_rode_alloc(dm_routh *red, const char *stepper, dm_rode **out, int *order, dm_err *e);
void dm_rode_free(dm_rode *O);
void dm_rode_reset(dm_rode *O);
int dm_rode_step(dm_rode *O, double h, const double *x0, const double *s0, double *x1, double *s1,
                 double *dtheta, dm_err *e);

/* Singular-inertia test shared by the reduced integrators: *ref is set from
 * x on the first call (ref <= 0); returns DM_ESINGULAR with a message when
 * lambda_min(I(x)) <= sing_tol * ref or I(x) is not finite.  work: at least
 * r*r + red->nwork doubles. */
int dm_routh_check_inertia(const dm_routh *red, const double *x, double *ref, double *work,
                           const char *where, dm_err *e);

#endif
