/* sweep_impl.h -- the reverse sweeps that expr_grad.c (gradients, sparse
 * Jacobians) and expr_hessian.c (Hessians) share.  Private to src/expr:
 * never included from another directory.  The functions set the context's
 * error (and return -1) or a dm_err (and return its status) as their
 * comments in expr_grad.c say; none is thread-safe across one context. */
#ifndef DM_EXPR_SWEEP_IMPL_H
#define DM_EXPR_SWEEP_IMPL_H

#include "expr/expr_impl.h"

#include <stddef.h>
#include <stdint.h>

/* Sparse rows of derivatives: (variable index, expression) entries,
 * ascending by index within a row, rows one after the other. */
typedef struct rows {
  size_t n, cap;
  uint32_t *idx;
  dm_expr *val;
} rows;

/* One entry of a row being gathered. */
typedef struct ent {
  uint32_t j;
  dm_expr x;
} ent;

/* What the sweeps of one derivative computation share: the variables (a
 * hash table from node to index), and the nodes whose gradients are
 * already known (sorted handles, a sparse row each): a sweep does not
 * descend below them but applies the chain rule with their rows. */
/* Contributions to an adjoint waiting to be summed, in arrival order:
 * chain h holds entries first .. last (linked by next), count of them. */
typedef struct contrib {
  dm_expr w;
  int32_t next;
} contrib;
typedef struct chain {
  int32_t first, last, count;
} chain;

typedef struct swp {
  size_t n;
  const dm_expr *vars;
  int32_t *vtab;            /* open addressing: variable indices, -1 empty */
  size_t vmask;
  size_t nk;                /* the first nk known nodes are in force */
  const int32_t *knode;
  const size_t *koff;       /* row k: kr->idx/val[koff[k] .. koff[k + 1]) */
  const rows *kr;
  dm_expr root, zero, one;
  uint32_t *touch;          /* n: variables reached through known rows */
  ent *tmp;                 /* n: the row being gathered */
  contrib *cb;              /* pending contributions of this sweep */
  size_t ncb, capcb;
  chain *ch;
  size_t nch, capch;
  dm_expr *terms;           /* a chain's terms being summed */
  size_t capterms;
} swp;

int dm_expr__rows_push(rows *r, uint32_t j, dm_expr x);
void dm_expr__rows_free(rows *r);
int dm_expr__cmp_ent(const void *a, const void *b);      /* qsort by index */

int dm_expr__swp_init(dm_expr_ctx *ctx, swp *S, size_t n, const dm_expr *vars);
void dm_expr__swp_free(swp *S);
long dm_expr__var_index(const swp *S, int32_t x);
long dm_expr__known_find(const swp *S, dm_expr x);
int dm_expr__is_leafvar(const dm_expr_ctx *ctx, const swp *S, int32_t x, long *j);
int dm_expr__sweep(dm_expr_ctx *ctx, swp *S, dm_expr root, rows *out);

int dm_expr__check_vars(dm_expr_ctx *ctx, dm_expr e, size_t n,
                        const dm_expr *vars, const char *who, dm_err *err);
int dm_expr__oom_err(dm_err *err, const char *who);
/* The sweep state on vars (dm_expr__swp_init) and nrow + 1 row offsets
 * (malloc'ed), or NULL with nothing left allocated (out of memory). */
size_t *dm_expr__rows_start(dm_expr_ctx *ctx, swp *S, size_t n, const dm_expr *vars,
                            size_t nrow);
int dm_expr__to_sparse(rows *r, const size_t *off, size_t nrow, size_t ncol,
                       dm_expr_sparse *out);
int dm_expr__keep(dm_expr_ctx *ctx, int s, const dm_err *local);

#endif
