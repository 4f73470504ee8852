/* betti.c -- exact Betti numbers b_k = N_k - rank d_{k-1} - rank d_k.
 *
 * Ranks over the field Z/p, p = 2^31 - 1, by the column reduction used in
 * persistent homology: columns reduced left to right until their lowest
 * nonzero row is unique.  Top dimension first, with "clearing": a k-simplex
 * that is the pivot row of a reduced column of the boundary of dimension
 * k+1 has a column that reduces to zero in dimension k, so it is skipped.
 * Integer arithmetic throughout; floating-point rank is not reliable on
 * meshes of realistic size. */
#include <config.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/interrupt.h"
#include "dec/dec.h"

#define PRIME 2147483647u

typedef struct {
  int len, cap;
  int *row;
  uint32_t *val;
} column;

static uint32_t mulmod(uint32_t a, uint32_t b)
{
  return (uint32_t)(((uint64_t)a * b) % PRIME);
}

static uint32_t invmod(uint32_t a)
{
  uint32_t r = 1, e = PRIME - 2;
  while (e != 0) {
    if (e & 1)
      r = mulmod(r, a);
    a = mulmod(a, a);
    e >>= 1;
  }
  return r;
}

static int col_reserve(column *c, int cap)
{
  if (cap <= c->cap)
    return 0;
  cap = cap < 2 * c->cap ? 2 * c->cap : cap;
  {
    int *r = realloc(c->row, (size_t)cap * sizeof *r);
    uint32_t *v;
    if (r == NULL)
      return -1;
    c->row = r;
    v = realloc(c->val, (size_t)cap * sizeof *v);
    if (v == NULL)
      return -1;
    c->val = v;
  }
  c->cap = cap;
  return 0;
}

/* out = a - f b (rows sorted ascending, zero entries dropped). */
static int col_axpy(const column *a, uint32_t f, const column *b, column *out)
{
  int i = 0, j = 0;
  out->len = 0;
  if (col_reserve(out, a->len + b->len) != 0)
    return -1;
  while (i < a->len || j < b->len) {
    int r;
    uint32_t v;
    if (j >= b->len || (i < a->len && a->row[i] < b->row[j])) {
      r = a->row[i];
      v = a->val[i++];
    } else {
      uint32_t fb = mulmod(f, b->val[j]);
      r = b->row[j];
      if (i < a->len && a->row[i] == r)
        v = (a->val[i++] + PRIME - fb) % PRIME;
      else
        v = (PRIME - fb) % PRIME;
      j++;
    }
    if (v != 0) {
      out->row[out->len] = r;
      out->val[out->len++] = v;
    }
  }
  return 0;
}

/* Rank of boundary_{k+1} = d_k^T: column s is row s of d_k.  skip[s]
 * marks columns known to reduce to zero; pivot rows are flagged in
 * cleared[] for the next dimension down. */
static int reduce(const dm_sparse *D, const unsigned char *skip,
                  unsigned char *cleared, int *rank, dm_err *e)
{
  int ncols = D->nrows, nrows = D->ncols, s, p, st = DM_OK;
  int *pivot = malloc(((size_t)nrows + 1) * sizeof *pivot);
  column *red = calloc((size_t)ncols + 1, sizeof *red);
  column cur = {0, 0, NULL, NULL}, tmp = {0, 0, NULL, NULL};
  *rank = 0;
  if (pivot == NULL || red == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "Betti numbers: out of memory");
    goto done;
  }
  for (s = 0; s < nrows; s++)
    pivot[s] = -1;
  for (s = 0; s < ncols; s++) {
    if (skip != NULL && skip[s])
      continue;
    if ((s & 1023) == 0 && dm_interrupted()) {
      st = dm_err_set(e, DM_EINTR, "Betti numbers: interrupted");
      goto done;
    }
    if (col_reserve(&cur, D->rowptr[s + 1] - D->rowptr[s]) != 0)
      goto nomem;
    cur.len = 0;
    for (p = D->rowptr[s]; p < D->rowptr[s + 1]; p++) {
      cur.row[cur.len] = D->col[p];
      cur.val[cur.len++] = D->val[p] > 0 ? 1u : PRIME - 1u;
    }
    while (cur.len > 0 && pivot[cur.row[cur.len - 1]] >= 0) {
      const column *b = &red[pivot[cur.row[cur.len - 1]]];
      uint32_t f = mulmod(cur.val[cur.len - 1], invmod(b->val[b->len - 1]));
      column t;
      if (col_axpy(&cur, f, b, &tmp) != 0)
        goto nomem;
      t = cur;
      cur = tmp;
      tmp = t;
    }
    if (cur.len > 0) {
      int low = cur.row[cur.len - 1];
      pivot[low] = s;
      if (cleared != NULL)
        cleared[low] = 1;
      red[s] = cur;                         /* keep it; start a fresh one */
      cur.len = cur.cap = 0;
      cur.row = NULL;
      cur.val = NULL;
      (*rank)++;
    }
  }
  goto done;
nomem:
  st = dm_err_set(e, DM_ENOMEM, "Betti numbers: out of memory");
done:
  if (red != NULL)
    for (s = 0; s < ncols; s++) {
      free(red[s].row);
      free(red[s].val);
    }
  free(red);
  free(pivot);
  free(cur.row);
  free(cur.val);
  free(tmp.row);
  free(tmp.val);
  return st;
}

int dm_dec_betti(const dm_dec_complex *K, int *betti, dm_err *e)
{
  int n = K->n, k, rank[DM_DEC_MAXDIM + 2] = {0}, st = DM_OK;
  unsigned char *cleared[DM_DEC_MAXDIM + 1] = {NULL};
  for (k = 0; k <= n; k++)
    if ((cleared[k] = calloc((size_t)K->nsimp[k] + 1, 1)) == NULL) {
      st = dm_err_set(e, DM_ENOMEM, "Betti numbers: out of memory");
      goto done;
    }
  /* rank[k] = rank of boundary_k = rank d_{k-1}; rank[0] = rank[n+1] = 0 */
  for (k = n; k >= 1; k--)
    if ((st = reduce(K->d[k - 1], cleared[k], cleared[k - 1], &rank[k], e)) != DM_OK)
      goto done;
  for (k = 0; k <= n; k++)
    betti[k] = K->nsimp[k] - rank[k] - rank[k + 1];
done:
  for (k = 0; k <= n; k++)
    free(cleared[k]);
  return st;
}
