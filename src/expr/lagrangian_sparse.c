/* lagrangian_sparse.c -- the sparse layout of a Lagrangian system (more
 * than DM_LAG_DENSE_MAX coordinates): the second derivatives are derived
 * on their structural pattern only (dm_expr_hessian_sparse: the cost of the
 * gradient's DAG, not n times it) and compiled as values on the patterns,
 * so a chain of n masses has O(n) outputs instead of 3 n^2.  The dense
 * layout is in lagrangian.c, the callbacks in lagrangian_eval.c. */
#include <config.h>
#include "expr/lagrangian_impl.h"
#include "expr/tape.h"

#include <stdlib.h>
#include <string.h>

int dm_lag__pattern(dm_csr *p, size_t n, size_t ne, const uint32_t *r, const uint32_t *c,
                    int sym, uint32_t *pos)
{
  size_t nnz = ne;
  for (size_t k = 0; sym && k < ne; k++)
    nnz += r[k] != c[k];
  if (dm_csr_alloc(p, n, n, nnz) != DM_OK)
    return DM_ENOMEM;
  size_t *fill = calloc(n + 1, sizeof *fill);
  if (fill == NULL) {
    dm_csr_free(p);
    return DM_ENOMEM;
  }
  for (size_t k = 0; k < ne; k++) {
    fill[r[k]]++;
    if (sym && r[k] != c[k])
      fill[c[k]]++;
  }
  size_t acc = 0;
  for (size_t i = 0; i < n; i++) {
    size_t t = fill[i];
    p->rowptr[i] = fill[i] = acc;
    acc += t;
  }
  p->rowptr[n] = acc;
  for (size_t k = 0; k < ne; k++) {
    pos[2 * k] = (uint32_t)fill[r[k]];
    p->col[fill[r[k]]++] = c[k];
    pos[2 * k + 1] = DM_BLK_NOPOS;
    if (sym && r[k] != c[k]) {
      pos[2 * k + 1] = (uint32_t)fill[c[k]];
      p->col[fill[c[k]]++] = r[k];
    }
  }
  free(fill);
  return DM_OK;
}

/* The entries of one block of the Hessian: (row, column) in the block's
 * own numbering, the expression, the places on the block's pattern. */
typedef struct hblock {
  size_t ne;
  uint32_t *r, *c, *pos;
  dm_expr *x;
} hblock;

static int hblock_alloc(hblock *h, size_t cap)
{
  memset(h, 0, sizeof *h);
  h->r = malloc((cap + 1) * sizeof *h->r);
  h->c = malloc((cap + 1) * sizeof *h->c);
  h->pos = malloc((2 * cap + 1) * sizeof *h->pos);
  h->x = malloc((cap + 1) * sizeof *h->x);
  return h->r && h->c && h->pos && h->x ? 0 : -1;
}

static void hblock_free(hblock *h)
{
  free(h->r);
  free(h->c);
  free(h->pos);
  free(h->x);
}

static void hblock_add(hblock *h, size_t r, size_t c, dm_expr x)
{
  h->r[h->ne] = (uint32_t)r;
  h->c[h->ne] = (uint32_t)c;
  h->x[h->ne++] = x;
}

static int oom(lag_builder *b)
{
  return dm_err_set(b->err, DM_ENOMEM, "out of memory");
}

/* Lvv (upper), Lvq (transposed from the (q_i, v_j) entries) and Lqq
 * (upper) from the upper triangle of the Hessian in (q, v), with their
 * patterns. */
static int split_hessian(lag_data *d, const dm_expr_sparse *H, hblock blk[3])
{
  size_t n = d->n;
  for (int k = 0; k < 3; k++)
    if (hblock_alloc(&blk[k], H->nnz) != 0)
      return DM_ENOMEM;
  for (size_t i = 0; i < 2 * n; i++)
    for (size_t k = H->rowptr[i]; k < H->rowptr[i + 1]; k++) {
      size_t j = H->col[k];
      if (i >= n)
        hblock_add(&blk[0], i - n, j - n, H->val[k]);
      else if (j >= n)
        hblock_add(&blk[1], j - n, i, H->val[k]);   /* Lvq[j][i] */
      else
        hblock_add(&blk[2], i, j, H->val[k]);
    }
  dm_csr *pat[3] = { &d->pat.vv, &d->pat.vq, &d->pat.qq };
  for (int k = 0; k < 3; k++)
    if (dm_lag__pattern(pat[k], n, blk[k].ne, blk[k].r, blk[k].c, k != 1, blk[k].pos) != DM_OK)
      return DM_ENOMEM;
  return DM_OK;
}

int dm_lag__build_sparse(lag_builder *b, lag_data *d, unsigned *flags)
{
  const dm_lagrangian_spec *sp = b->sp;
  const size_t n = sp->n;
  dm_expr_sparse H = { 0 };
  hblock blk[3] = { { 0 }, { 0 }, { 0 } };
  dm_expr *out = NULL, *ow = NULL, *mout = NULL, *sep = NULL;
  int s;
  if (dm_expr_hessian_sparse(b->ctx, sp->L, 2 * n, b->in, &H, b->err) != DM_OK) {
    s = dm_lag__ctx_fail(b, "L");
    goto done;
  }
  if ((s = split_hessian(d, &H, blk)) != DM_OK) {
    oom(b);
    goto done;
  }
  size_t nh = blk[0].ne + blk[1].ne + blk[2].ne, nall = 1 + 2 * n + nh;
  out = malloc(nall * sizeof *out);
  ow = malloc(nall * sizeof *ow);
  mout = malloc((d->pat.vv.nnz + 1) * sizeof *mout);
  sep = malloc((2 * n + blk[2].ne + 1) * sizeof *sep);
  if (!out || !ow || !mout || !sep) {
    s = oom(b);
    goto done;
  }
  out[0] = sp->L;
  if (dm_expr_grad(b->ctx, sp->L, 2 * n, b->in, out + 1, b->err) != DM_OK) {
    s = dm_lag__ctx_fail(b, "L");
    goto done;
  }
  dm_expr *o = out + 1 + 2 * n;
  for (int k = 0; k < 3; k++) {
    memcpy(o, blk[k].x, blk[k].ne * sizeof *o);
    o += blk[k].ne;
  }
  /* rewritten once for every bundle (bit-identical values between them) */
  if ((s = dm_tape_optimize(b->ctx, nall, out, ow, b->err)) != DM_OK)
    goto done;
  const dm_block bl[] = { { 0, DM_BLK_VEC, 1, 1, 0, NULL }, { 1, DM_BLK_VEC, n, 1, 0, NULL },
                          { 2, DM_BLK_VEC, n, 1, 0, NULL },
                          { 3, DM_BLK_PAIRS, blk[0].ne, 1, 0, blk[0].pos },
                          { 4, DM_BLK_PAIRS, blk[1].ne, 1, 0, blk[1].pos },
                          { 5, DM_BLK_PAIRS, blk[2].ne, 1, 0, blk[2].pos } };
  for (size_t k = 0; k < blk[0].ne; k++) {           /* the mass on pat.vv */
    mout[blk[0].pos[2 * k]] = blk[0].x[k];
    if (blk[0].pos[2 * k + 1] != DM_BLK_NOPOS)
      mout[blk[0].pos[2 * k + 1]] = blk[0].x[k];
  }
  /* in the order their native code is wanted (lagrangian.c) */
  if ((s = dm_lag__detect_structure(b, d, out + 1 + n, blk[0].ne, blk[0].x, blk[1].ne == 0,
                                    d->pat.vv.nnz, mout, flags)) != DM_OK)
    goto done;
  if (d->mass_possible) {
    /* separable: Lq of q alone, and Lq, Lv, Lqq (see lagrangian.c) */
    const dm_block bq[] = { { 1, DM_BLK_VEC, n, 1, 0, NULL } };
    const dm_block bqv[] = { { 1, DM_BLK_VEC, n, 1, 0, NULL }, { 2, DM_BLK_VEC, n, 1, 0, NULL },
                             { 5, DM_BLK_PAIRS, blk[2].ne, 1, 0, blk[2].pos } };
    memcpy(sep, ow + 1, 2 * n * sizeof *sep);
    memcpy(sep + 2 * n, ow + 1 + 2 * n + blk[0].ne + blk[1].ne, blk[2].ne * sizeof *sep);
    if ((s = dm_lag__compile_bundle(b, &d->lq, n, ow + 1, n, bq, 1, 1)) != DM_OK ||
        (s = dm_lag__compile_bundle(b, &d->qvqq, 2 * n + blk[2].ne, sep, 2 * n, bqv, 3, 1))
        != DM_OK)
      goto done;
  }
  if ((s = dm_lag__compile_bundle(b, &d->grad, 1 + 2 * n, ow, 2 * n, bl, 6, 1)) != DM_OK ||
      (s = dm_lag__compile_bundle(b, &d->all, nall, ow, 2 * n, bl, 6, 1)) != DM_OK)
    goto done;
  dm_lag__select(d);
done:
  dm_expr_sparse_free(&H);
  for (int k = 0; k < 3; k++)
    hblock_free(&blk[k]);
  free(out);
  free(ow);
  free(mout);
  free(sep);
  return s;
}

int dm_lag__build_force_sparse(lag_builder *b, lag_data *d)
{
  const dm_lagrangian_spec *sp = b->sp;
  const size_t n = sp->n;
  dm_expr_sparse J[2] = { { 0 }, { 0 } };
  dm_csr *pat[2] = { &d->pat.fq, &d->pat.fv };
  uint32_t *r = NULL, *pos[2] = { NULL, NULL };
  dm_expr *out = NULL;
  int s = DM_OK;
  for (int k = 0; k < 2 && s == DM_OK; k++)
    if (dm_expr_jacobian_sparse(b->ctx, n, sp->force, n, b->in + k * n, &J[k], b->err)
        != DM_OK)
      s = dm_lag__ctx_fail(b, "force");
  if (s != DM_OK)
    goto done;
  size_t nall = n + J[0].nnz + J[1].nnz, mx = J[0].nnz > J[1].nnz ? J[0].nnz : J[1].nnz;
  out = malloc(nall * sizeof *out);
  r = malloc((mx + 1) * sizeof *r);
  pos[0] = malloc((2 * J[0].nnz + 1) * sizeof *pos[0]);
  pos[1] = malloc((2 * J[1].nnz + 1) * sizeof *pos[1]);
  if (!out || !r || !pos[0] || !pos[1]) {
    s = oom(b);
    goto done;
  }
  memcpy(out, sp->force, n * sizeof *out);
  dm_expr *o = out + n;
  for (int k = 0; k < 2; k++) {
    for (size_t i = 0; i < n; i++)
      for (size_t e = J[k].rowptr[i]; e < J[k].rowptr[i + 1]; e++)
        r[e] = (uint32_t)i;
    if (dm_lag__pattern(pat[k], n, J[k].nnz, r, J[k].col, 0, pos[k]) != DM_OK) {
      s = oom(b);
      goto done;
    }
    memcpy(o, J[k].val, J[k].nnz * sizeof *o);
    o += J[k].nnz;
  }
  if ((s = dm_tape_optimize(b->ctx, nall, out, out, b->err)) != DM_OK)
    goto done;
  const dm_block blk[] = { { 0, DM_BLK_VEC, n, 1, 0, NULL },
                           { 1, DM_BLK_PAIRS, J[0].nnz, 1, 0, pos[0] },
                           { 2, DM_BLK_PAIRS, J[1].nnz, 1, 0, pos[1] } };
  if ((s = dm_lag__compile_bundle(b, &d->force, n, out, 2 * n, blk, 3, 1)) == DM_OK)
    s = dm_lag__compile_bundle(b, &d->force_all, nall, out, 2 * n, blk, 3, 1);
done:
  dm_expr_sparse_free(&J[0]);
  dm_expr_sparse_free(&J[1]);
  free(out);
  free(r);
  free(pos[0]);
  free(pos[1]);
  return s;
}
