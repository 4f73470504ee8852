/* expr_impl.h -- internals of the expression context shared by expr.c,
 * expr_diff.c, expr_print.c and tape.c.  Not a public header. */
#ifndef DM_EXPR_IMPL_H
#define DM_EXPR_IMPL_H

#include <string.h>

#include "expr/expr.h"

/* One node: 16 bytes.  Leaves: CONST (a = index into cval), SYM / PARAM
 * (a = name index).  POWI: a = base, b = exponent.  Others: operands a, b, c
 * (unused ones are -1).  len: for sums and products built by expr_norm.c,
 * the number of their terms / factors (saturating at 65535; 0 unknown). */
typedef struct dm_node {
  uint8_t op;
  uint8_t flags;            /* DM_NF_* */
  uint16_t len;
  int32_t a, b, c;
} dm_node;

/* One term of a sum (key: the term without its constant coefficient c;
 * k: DM_NE_PLAIN c*key, DM_NE_RECIP c/key, DM_NE_CONST the constant c) or
 * one factor of a product (key: the base, k: its integer exponent).  src:
 * which operand it came from. */
typedef struct dm_nel {
  int32_t key, k;
  double c;
  uint64_t h;               /* hash of the element */
  int32_t src, pad;
} dm_nel;
enum { DM_NE_PLAIN = 0, DM_NE_RECIP = 1, DM_NE_CONST = 2 };

/* A node pending in a flattening walk: node and sign / exponent. */
typedef struct dm_nwalk {
  int32_t node, pad;
  int64_t e;
} dm_nwalk;

/* The table of normal sums and products by the multiset of their
 * elements (hash h). */
typedef struct dm_nslot {
  uint64_t h;
  int32_t node, pad;
} dm_nslot;

enum { DM_NF_SYM = 1u, DM_NF_PARAM = 2u };

typedef struct dm_memo_ent {
  int32_t node, var, res;
} dm_memo_ent;

struct dm_expr_ctx {
  dm_node *node;
  size_t n, cap;
  double *cval;             /* constant values */
  size_t ncval, capcval;
  int32_t *htab;            /* cons table: node handles, -1 empty */
  uint32_t *htag;           /* the high half of each entry's hash */
  size_t hcap;              /* power of two */
  char **names;             /* symbol / parameter names */
  size_t nnames, capnames;
  int32_t *ntab;            /* name table: name indices, -1 empty */
  size_t ntcap;
  dm_memo_ent *memo;        /* derivative memo (node, var) -> result */
  size_t nmemo, memocap;
  /* per-node scratch for traversals: aux[i] valid iff stamp[i] == epoch */
  uint32_t *stamp;
  int32_t *aux;
  uint32_t epoch;
  size_t scap;
  int32_t *stack, *list;    /* traversal buffers */
  size_t stackcap, listcap;
  /* normal forms (expr_norm.c) */
  dm_nel *nel[2];           /* element lists: [0] being built, [1] compared */
  size_t nelcap[2];
  dm_nwalk *walk;           /* flattening stack */
  size_t walkcap;
  dm_nslot *ftab;           /* normal sums / products by element multiset */
  size_t ftabcap, nftab;
  dm_err err;
};

/* Record an error in the context (first one wins); returns DM_EXPR_NONE. */
dm_expr dm_expr__fail(dm_expr_ctx *ctx, int status, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;

static inline uint64_t dm_expr__mix64(uint64_t h)
{
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}

static inline uint64_t dm_expr__dbits(double x)
{
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  return u;
}

static inline int dm_expr__valid(const dm_expr_ctx *ctx, dm_expr e)
{
  return e >= 0 && (size_t)e < ctx->n;
}

static inline int dm_expr__arity(int op)
{
  if (op <= DM_EXPR_PARAM) return 0;
  if (op <= DM_EXPR_NE) return 2;
  if (op == DM_EXPR_SELECT) return 3;
  return 1;                 /* POWI counts as unary: exponent is data */
}

/* Collect the nodes reachable from roots[0..n-1] in ascending (topological)
 * order into ctx->list; returns their number or -1 (out of memory).  Starts
 * a new epoch: stamp[i] == epoch marks exactly the collected nodes, and
 * aux[] of those nodes is free for the caller. */
long dm_expr__collect(dm_expr_ctx *ctx, size_t n, const dm_expr *roots);

/* Same, not descending below nodes where stop() is true. */
typedef int (*dm_expr__stop_fn)(const dm_expr_ctx *ctx, dm_expr e,
                                const void *data);
long dm_expr__collect_stop(dm_expr_ctx *ctx, size_t n, const dm_expr *roots,
                           dm_expr__stop_fn stop, const void *data);

/* Same, not descending into subtrees without symbols or parameters. */
long dm_expr__collect_vars(dm_expr_ctx *ctx, size_t n, const dm_expr *roots);

/* Derivative memo: the result for (node, var) or -1; store one. */
int32_t dm_expr__memo_get(const dm_expr_ctx *ctx, int32_t node, int32_t var);
int dm_expr__memo_put(dm_expr_ctx *ctx, int32_t node, int32_t var, int32_t res);

/* The node (op, a, b, c) exactly, without simplification (not CONST;
 * unused operands -1). */
dm_expr dm_expr__cons(dm_expr_ctx *ctx, int op, dm_expr a, dm_expr b, dm_expr c);

/* The context's error status copied into err (DM_EFAILED if none). */
int dm_expr__status(dm_expr_ctx *ctx, dm_err *err);

/* Flattening into the element list ctx->nel[w] (expr_flat.c): sums (s a
 * sign) collect their constant in c (hasc: bit src when operand src had
 * one), products (exponent e) their coefficient in c and a constant
 * divisor (1/d not exact) in d.  With merge, like elements are collected.
 * Return -1 out of memory; products 1 when an exponent grows too large. */
typedef struct dm_flat {
  int w;
  size_t n;
  double c, d;
  int hasc;
} dm_flat;
int dm_expr__flatten_sum(dm_expr_ctx *ctx, dm_flat *f, dm_expr e, int s,
                         int src, int merge);
int dm_expr__flatten_prod(dm_expr_ctx *ctx, dm_flat *f, dm_expr e, int64_t ex,
                          int src, int merge);
dm_nel *dm_expr__new_el(dm_expr_ctx *ctx, dm_flat *f);
int dm_expr__grow(void *pp, size_t *cap, size_t need, size_t size);
/* 1 and *v = its value when e is a constant node. */
static inline int dm_expr__isc(const dm_expr_ctx *ctx, dm_expr e, double *v)
{
  if (ctx->node[e].op != DM_EXPR_CONST)
    return 0;
  *v = ctx->cval[ctx->node[e].a];
  return 1;
}
/* 1 when a and b are valid operands of a constructor; 0 for DM_EXPR_NONE
 * (an earlier failure, already recorded), or 0 after recording
 * DM_EINVAL for an invalid handle. */
static inline int dm_expr__check2(dm_expr_ctx *ctx, dm_expr a, dm_expr b)
{
  if (a == DM_EXPR_NONE || b == DM_EXPR_NONE)
    return 0;
  if (!dm_expr__valid(ctx, a) || !dm_expr__valid(ctx, b)) {
    dm_expr__fail(ctx, DM_EINVAL, "expression: invalid node handle");
    return 0;
  }
  return 1;
}
/* e is a sum (ADD, SUB, or negations of one). */
int dm_expr__sumlike(const dm_expr_ctx *ctx, dm_expr e);
/* Element hashes and the hash of a multiset from their sum; the normal
 * node with these n elements (or DM_EXPR_NONE); remember one (-1 out of
 * memory). */
uint64_t dm_expr__hel(const dm_nel *x, int prod);
uint64_t dm_expr__hfin(uint64_t s, size_t n, int prod);
dm_expr dm_expr__probe(dm_expr_ctx *ctx, uint64_t h, int prod,
                       const dm_nel *E, size_t n);
int dm_expr__reg(dm_expr_ctx *ctx, uint64_t h, dm_expr e);

/* Terms of a sum (prod 0; through a constant coefficient) or factors of a
 * product (prod 1) as far as the node records them; 1 for other nodes. */
size_t dm_expr__nlen(const dm_expr_ctx *ctx, dm_expr e, int prod);
/* The normal sum of t[0..k) at once (the node adding them one by one
 * gives, up to where a common coefficient is taken out), in time about
 * linear in the number of terms. */
dm_expr dm_expr__sum_n(dm_expr_ctx *ctx, size_t k, const dm_expr *t);
/* The constant node x (as dm_expr_const). */
dm_expr dm_expr__k(dm_expr_ctx *ctx, double x);
/* Release the normal-form buffers and table (expr_norm.c). */
void dm_expr__norm_free(dm_expr_ctx *ctx);


#endif
