/* bundle.c -- compile a bundle of outputs (see bundle.h). */
#include <config.h>
#include "expr/bundle.h"

#include <stdlib.h>

void dm_bundle_free(dm_bundle *p)
{
  dm_native_job_free(p->job);           /* first: it reads the tape */
  free(p->chk);
  dm_native_free(p->nat);
  dm_tape_free(p->tape);
  memset(p, 0, sizeof *p);
}

/* Output map for the blocks, cut at nout outputs; *nmap entries. */
static dm_native_map *make_outmap(const dm_block *blk, size_t nblk, size_t nout, size_t *nmap)
{
  size_t cap = 2 * nout + 1, j = 0, k = 0;
  dm_native_map *m = malloc(cap * sizeof *m);
  if (m == NULL)
    return NULL;
  for (size_t bi = 0; bi < nblk && k < nout; bi++) {
    const dm_block *B = &blk[bi];
    size_t n = B->len;
    for (size_t r = 0; r < B->rep && k < nout; r++) {
      uint32_t off = (uint32_t)(r * B->stride);
      if (B->kind == DM_BLK_VEC) {
        for (size_t i = 0; i < n && k < nout; i++, k++)
          m[j++] = (dm_native_map){ (uint32_t)k, B->arr, off + (uint32_t)i };
      } else if (B->kind == DM_BLK_FULL) {
        for (size_t i = 0; i < n * n && k < nout; i++, k++)
          m[j++] = (dm_native_map){ (uint32_t)k, B->arr, off + (uint32_t)i };
      } else if (B->kind == DM_BLK_PAIRS) {
        for (size_t i = 0; i < n && k < nout; i++, k++)
          for (int h = 0; h < 2; h++)
            if (B->pos[2 * i + h] != DM_BLK_NOPOS)
              m[j++] = (dm_native_map){ (uint32_t)k, B->arr, off + B->pos[2 * i + h] };
      } else {
        for (size_t i = 0; i < n; i++)
          for (size_t c = i; c < n && k < nout; c++, k++) {
            m[j++] = (dm_native_map){ (uint32_t)k, B->arr, off + (uint32_t)(i * n + c) };
            if (c != i)
              m[j++] = (dm_native_map){ (uint32_t)k, B->arr, off + (uint32_t)(c * n + i) };
          }
      }
    }
  }
  *nmap = j;
  return m;
}

int dm_bundle_compile(dm_bundle *p, const dm_bundle_src *src, size_t nout, const dm_expr *out,
                      size_t nin, const dm_block *blk, size_t nblk, int exact, dm_err *err)
{
  size_t nmap = 0, n = src->inlen;
  dm_native_map *inmap = malloc((nin + 1) * sizeof *inmap);
  dm_native_map *outmap = make_outmap(blk, nblk, nout, &nmap);
  uint32_t *slot_out = malloc((nmap + 1) * sizeof *slot_out);
  if (inmap == NULL || outmap == NULL || slot_out == NULL) {
    free(inmap);
    free(outmap);
    free(slot_out);
    return dm_err_set(err, DM_ENOMEM, "out of memory");
  }
  /* the arrays laid out one after the other in the tape's slots (the
   * blocks fill their arrays densely) */
  uint32_t size[32] = { 0 };
  p->narr = 0;
  for (size_t j = 0; j < nmap; j++) {
    uint32_t a = outmap[j].arr;
    if (a + 1 > p->narr)
      p->narr = a + 1;
    if (outmap[j].elem + 1 > size[a])
      size[a] = outmap[j].elem + 1;
  }
  p->aoff[0] = 0;
  p->have = 0;
  for (uint32_t a = 0; a < p->narr; a++) {
    p->aoff[a + 1] = p->aoff[a] + size[a];
    p->have |= size[a] ? 1u << a : 0u;
  }
  p->fill = (p->narr >= 32 ? ~0u : (1u << p->narr) - 1) & ~p->have;
  p->nin = nin;
  int s = p->aoff[p->narr] == nmap ? DM_OK
          : dm_err_set(err, DM_EFAILED, "internal: output blocks leave gaps");
  for (size_t j = 0; j < nmap; j++)
    slot_out[p->aoff[outmap[j].arr] + outmap[j].elem] = outmap[j].k;
  if (s == DM_OK && nmap > 0)
    s = dm_tape_compile_slots(src->ctx, nout, out, nin, src->in, src->npar,
                              src->par, nmap, slot_out, &p->tape, err);
  else if (s == DM_OK)
    s = (exact ? dm_tape_compile_exact : dm_tape_compile)(src->ctx, nout,
        out, nin, src->in, src->npar, src->par, &p->tape, err);
  free(slot_out);
  if (s != DM_OK) {
    free(inmap);
    free(outmap);
    return s;
  }
  p->nout = nout;
  p->nregs = dm_tape_work_size(p->tape);
  p->slot0 = dm_tape_slot_base(p->tape);
  /* the distinct output registers that are not constants */
  const uint32_t *oreg = dm_tape_outregs(p->tape);
  size_t c0 = dm_tape_nin(p->tape) + dm_tape_npar(p->tape);
  size_t c1 = c0 + dm_tape_nconst(p->tape);
  p->chk = malloc((nout + 1) * sizeof *p->chk);
  if (p->chk == NULL) {
    free(inmap);
    free(outmap);
    return dm_err_set(err, DM_ENOMEM, "out of memory");
  }
  p->nchk = 0;
  uint8_t *seen = calloc(p->nregs + 1, 1);
  if (seen == NULL) {
    free(inmap);
    free(outmap);
    return dm_err_set(err, DM_ENOMEM, "out of memory");
  }
  for (size_t k = 0; k < nout; k++)
    if (!(oreg[k] >= c0 && oreg[k] < c1) && !seen[oreg[k]]) {
      seen[oreg[k]] = 1;
      p->chk[p->nchk++] = oreg[k];
    }
  free(seen);
  const int mode = src->native & 0xff;
  if (mode == DM_NATIVE_NEVER) {
    free(inmap);
    free(outmap);
    return DM_OK;
  }
  for (size_t i = 0; i < nin; i++)           /* array by array */
    inmap[i] = (dm_native_map){ (uint32_t)i, (uint32_t)(i / n), (uint32_t)(i % n) };
  dm_err nerr;
  if (mode == DM_NATIVE_AUTO && (src->native & DM_BUNDLE_BACKGROUND)) {
    /* queued: the tape runs until dm_bundle_update installs the code; a
     * compiler that cannot be started leaves the tape */
    if (dm_native_job_start(p->tape, src->in0, src->par0, nmap ? inmap : NULL, nmap,
                            nmap ? outmap : NULL, &p->job, &nerr) != DM_OK) {
      p->native_failed = 1;
      p->native_err = nerr;
    }
    free(inmap);
    free(outmap);
    return DM_OK;
  }
  if (nmap > 0)
    s = dm_native_compile_mapped(p->tape, src->in0, src->par0, inmap, nmap,
                                 outmap, &p->nat, &nerr);
  else
    s = dm_native_compile(p->tape, src->in0, src->par0, &p->nat, &nerr);
  free(inmap);
  free(outmap);
  if (s == DM_OK) {
    p->fn = dm_native_function(p->nat);
    p->scatter = dm_native_scatter(p->nat);
  } else if (mode == DM_NATIVE_ALWAYS || (s == DM_EINTR && mode != DM_NATIVE_WAIT)) {
    if (err != NULL)
      *err = nerr;
    return s;
  } else {
    p->native_failed = 1;
    p->native_err = nerr;
  }
  return DM_OK;             /* auto, wait: the tape runs, silently */
}

int dm_bundle_update(dm_bundle *p)
{
  if (p->job == NULL)
    return 0;
  int st = dm_native_job_state(p->job);
  if (st == DM_NATIVE_JOB_QUEUED || st == DM_NATIVE_JOB_RUNNING)
    return 0;
  dm_native *nat = dm_native_job_take(p->job, &p->native_err);
  dm_native_job_free(p->job);
  p->job = NULL;
  if (nat == NULL) {
    p->native_failed = 1;
    return 0;
  }
  p->nat = nat;
  p->fn = dm_native_function(nat);
  p->scatter = dm_native_scatter(nat);
  return 1;
}

int dm_bundle_cancel(dm_bundle *p, dm_err *err)
{
  if (p->job == NULL)
    return DM_OK;
  dm_native_job_free(p->job);
  p->job = NULL;
  p->native_failed = 1;
  dm_err_set(&p->native_err, DM_EINTR, "native: compilation cancelled");
  if (err != NULL)
    *err = p->native_err;
  return DM_EINTR;
}

int dm_bundle_wait(dm_bundle *p, int interruptible, dm_err *err)
{
  if (p->job == NULL)
    return DM_OK;
  int s = dm_native_job_wait(p->job, interruptible, err);
  dm_bundle_update(p);
  return s;
}
