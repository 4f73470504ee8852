/* lagrangian_impl.h -- internals shared by lagrangian.c (building),
 * lagrangian_check.c (the checks of the description), lagrangian_eval.c
 * (the callbacks) and lagrangian_sparse.c (patterns, the outputs of the
 * sparse layout).  Not a public header. */
#ifndef DM_LAGRANGIAN_IMPL_H
#define DM_LAGRANGIAN_IMPL_H

#include "expr/lagrangian.h"
#include "expr/bundle.h"

/* Up to this many coordinates the second derivatives are compiled as
 * dense n x n arrays (what the small systems always had); above, as values
 * on their pattern. */
#define DM_LAG_DENSE_MAX 32
/* A dense mass matrix (sys->mass) up to this many coordinates; above, a
 * separable system needs a diagonal mass (held on the pattern). */
#define DM_LAG_MASS_DENSE_MAX 256

typedef struct lag_data {
  size_t n, m, npar;
  char *name;
  char **coords, **params;
  double *par, *mass;
  /* compiled bundles of outputs (bundle.h) */
  dm_bundle grad, all;        /* L, Lq, Lv | + Lvv, Lvq, Lqq */
  dm_bundle lq, qvqq;         /* separable L: Lq (of q alone) | Lq, Lv, Lqq */
  const dm_bundle *sel[DM_LAG_ALL + 1];  /* the cheapest bundle for each request */
  dm_bundle force, force_all; /* F | + Fq, Fv */
  dm_bundle constr, constr_all;  /* g, G | + H */
  dm_bundle massp;            /* Lvv (dense n*n, or on pat.vv) when constant in q and v */
  int mass_possible;
  /* the patterns of the second derivatives; the bundles hold them as
   * dense arrays (sparse == 0) or as values on the patterns */
  int sparse;
  dm_sys_pattern pat;
  double *pmass;              /* separable: the mass on pat.vv */
  size_t need;                /* doubles of work for the tapes; conversion
                                 scratch follows */
} lag_data;

typedef struct lag_builder {
  dm_expr_ctx *ctx;
  const dm_lagrangian_spec *sp;
  dm_expr *in;              /* q then v */
  double *in0;              /* typical inputs, or NULL */
  dm_err *err;
} lag_builder;

/* A pattern from ne entries (row r[k], column c[k]) arriving so that each
 * row's columns ascend; pos[2k] is the place of entry k, pos[2k+1] that of
 * its mirror (c, r) when sym and r != c, else DM_BLK_NOPOS.  DM_ENOMEM. */
int dm_lag__pattern(dm_csr *p, size_t n, size_t ne, const uint32_t *r, const uint32_t *c,
                    int sym, uint32_t *pos);
/* The sparse layout: L, Lq, Lv and the Hessian blocks on their patterns
 * (sparse Hessian of L in (q, v)), bundles grad, all, and for a separable
 * L lq, qvqq; structure flags.  Filled into d. */
int dm_lag__build_sparse(lag_builder *b, lag_data *d, unsigned *flags);
/* The force F and its Jacobians on their patterns (sparse layout). */
int dm_lag__build_force_sparse(lag_builder *b, lag_data *d);
/* Compile a bundle on (q, v) or q alone (lagrangian.c). */
int dm_lag__compile_bundle(lag_builder *b, dm_bundle *p, size_t nout, const dm_expr *out,
                           size_t nin, const dm_block *blk, size_t nblk, int exact);
/* The structure flags from Lvv (nvv entries, listed with their full
 * pattern positions in lagrangian.c's conventions), Lv; may compile the
 * mass bundle (outputs mout: the mass in the layout's order). */
int dm_lag__detect_structure(lag_builder *b, lag_data *d, const dm_expr *Lv,
                             size_t nvv, const dm_expr *Lvv, int lvq_zero,
                             size_t nmout, const dm_expr *mout, unsigned *flags);
/* The context's error (out of memory, or why a derivative failed) as
 * "what: message" in b->err; returns its status (lagrangian.c). */
int dm_lag__ctx_fail(lag_builder *b, const char *what);
/* The description checked before anything is derived (lagrangian_check.c). */
int dm_lag__check_spec(lag_builder *b);
/* The bundle for each request (lagrangian.c). */
void dm_lag__select(lag_data *d);
/* The dm_system callbacks (lagrangian_eval.c); data is the lag_data. */
int dm_lag__eval(void *data, const double *q, const double *v,
                 const double *par, unsigned what, dm_lag_out *out, void *work);
int dm_lag__force_eval(void *data, const double *q, const double *v,
                       const double *par, unsigned what, double *F, double *Fq,
                       double *Fv, void *work);
int dm_lag__constr_eval(void *data, const double *q, const double *par,
                        unsigned what, double *g, double *G, double *H,
                        void *work);

#endif
