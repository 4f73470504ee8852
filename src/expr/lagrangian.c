/* lagrangian.c -- derive and compile a Lagrangian system (the dm_system
 * callbacks that run its tapes, or their native versions, are in
 * lagrangian_eval.c).  See lagrangian.h. */
#include <config.h>
#include "expr/lagrangian_impl.h"
#include "expr/tape.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

typedef lag_builder builder;

static void lag_free_data(lag_data *d)
{
  if (d == NULL)
    return;
  for (size_t i = 0; d->coords && i < d->n; i++)
    free(d->coords[i]);
  for (size_t i = 0; d->params && i < d->npar; i++)
    free(d->params[i]);
  free(d->coords);
  free(d->params);
  free(d->name);
  free(d->par);
  free(d->mass);
  free(d->pmass);
  dm_csr *pp[] = { &d->pat.vv, &d->pat.vq, &d->pat.qq, &d->pat.fq, &d->pat.fv };
  for (size_t i = 0; i < sizeof pp / sizeof pp[0]; i++)
    dm_csr_free(pp[i]);
  dm_bundle *ps[] = { &d->grad, &d->all, &d->lq, &d->qvqq, &d->force, &d->force_all,
                      &d->constr, &d->constr_all, &d->massp };
  for (size_t i = 0; i < sizeof ps / sizeof ps[0]; i++)
    dm_bundle_free(ps[i]);
  free(d);
}

static void lag_free(dm_system *s)
{
  lag_free_data(s->data);
  s->data = NULL;
}

/* 1 if any of x[0..k) is NaN or infinite (independent tests, no serial
 * chain: this runs after every evaluation). */
static int nonfinite(const double *x, size_t k)
{
  int bad = 0;
  for (size_t i = 0; i < k; i++)
    bad |= !(fabs(x[i]) <= DBL_MAX);
  return bad;
}

/* {==================================================================
 * building
 * =================================================================== */

int dm_lag__ctx_fail(lag_builder *b, const char *what)
{
  const dm_err *e = dm_expr_ctx_err(b->ctx);
  return dm_err_set(b->err, e->status ? e->status : DM_EFAILED, "%s: %s",
                    what, e->msg[0] ? e->msg : "cannot build the derivatives");
}

/* Compile a bundle on (q, v) or q alone: the tape, and native code (with
 * its scattering function for the blocks) when the mode asks for it.
 * exact: out was rewritten by dm_tape_optimize already (so that bundles
 * sharing outputs compute them identically). */
int dm_lag__compile_bundle(lag_builder *b, dm_bundle *p, size_t nout, const dm_expr *out,
                           size_t nin, const dm_block *blk, size_t nblk, int exact)
{
  const dm_lagrangian_spec *sp = b->sp;
  dm_bundle_src src = { b->ctx, b->in, sp->n, sp->npar, sp->par, b->in0, sp->par_values,
                        sp->native == DM_NATIVE_AUTO ? DM_NATIVE_AUTO | DM_BUNDLE_BACKGROUND
                                                     : sp->native };
  return dm_bundle_compile(p, &src, nout, out, nin, blk, nblk, exact, b->err);
}

static char *dupstr(const char *s)
{
  return s ? strdup(s) : NULL;
}

static int copy_names(lag_data *d, const dm_lagrangian_spec *sp,
                      dm_expr_ctx *ctx)
{
  d->coords = calloc(sp->n, sizeof *d->coords);
  d->params = calloc(sp->npar ? sp->npar : 1, sizeof *d->params);
  d->par = calloc(sp->npar ? sp->npar : 1, sizeof *d->par);
  if (!d->coords || !d->params || !d->par)
    return -1;
  for (size_t i = 0; i < sp->n; i++)
    if (!(d->coords[i] = dupstr(sp->coord_names ? sp->coord_names[i]
                                : dm_expr_name(ctx, sp->q[i]))))
      return -1;
  for (size_t i = 0; i < sp->npar; i++) {
    if (!(d->params[i] = dupstr(sp->param_names ? sp->param_names[i]
                                : dm_expr_name(ctx, sp->par[i]))))
      return -1;
    d->par[i] = sp->par_values ? sp->par_values[i] : 0.0;
  }
  if (sp->name && !(d->name = strdup(sp->name)))
    return -1;
  return 0;
}

/* Evaluate the mass matrix at the current parameters into pmass (values
 * on pat.vv) and, for n <= DM_LAG_MASS_DENSE_MAX, mass (dense), and test
 * positive definiteness: a diagonal mass by its entries, another one by a
 * dense Cholesky factorisation when it has a dense copy.  Returns 1 when M
 * is SPD. */
static int eval_mass(lag_data *d)
{
  size_t n = d->n, nw = d->massp.nregs, nnz = d->pat.vv.nnz;
  double *buf = calloc(nw + d->massp.nout + (d->mass ? n * n : 0) + 1, sizeof *buf);
  if (buf == NULL)
    return 0;
  const double *M0 = dm_bundle_run_plain(&d->massp, buf, d->par);  /* q = v = 0 */
  if (d->sparse) {
    memcpy(d->pmass, M0, nnz * sizeof *buf);
    if (d->mass)
      dm_csr_to_dense(&d->pat.vv, d->pmass, d->mass);
  } else {
    memcpy(d->mass, M0, n * n * sizeof *buf);
    dm_csr_from_dense(&d->pat.vv, d->mass, d->pmass);
  }
  int diag = 1, spd;
  for (size_t i = 0; i < n && diag; i++)
    diag = d->pat.vv.rowptr[i + 1] == d->pat.vv.rowptr[i] + 1 &&
           d->pat.vv.col[d->pat.vv.rowptr[i]] == i;
  if (diag) {
    spd = !nonfinite(d->pmass, nnz);
    for (size_t i = 0; i < n && spd; i++)
      spd = d->pmass[i] > 0.0;
  } else if (d->mass != NULL) {
    double *A = buf + nw + d->massp.nout;
    memcpy(A, d->mass, n * n * sizeof *buf);
    gsl_matrix_view M = gsl_matrix_view_array(A, n, n);
    spd = !nonfinite(d->mass, n * n) &&   /* needs dm_gsl_init() */
          gsl_linalg_cholesky_decomp1(&M.matrix) == GSL_SUCCESS;
  } else {
    spd = 0;
  }
  free(buf);
  return spd;
}

/* Structure flags from the derived expressions (nvv entries of Lvv, each
 * once); may compile the mass bundle, whose outputs mout are the mass in
 * the layout's order (dense n*n, or on pat.vv). */
int dm_lag__detect_structure(lag_builder *b, lag_data *d, const dm_expr *Lv,
                             size_t nvv, const dm_expr *Lvv, int lvq_zero,
                             size_t nmout, const dm_expr *mout, unsigned *flags)
{
  const dm_lagrangian_spec *sp = b->sp;
  size_t n = sp->n;
  int mech = 1, constant = 1;
  for (size_t i = 0; i < nvv; i++) {
    mech &= !dm_expr_depends(b->ctx, Lvv[i], n, sp->v);
    constant &= !dm_expr_depends(b->ctx, Lvv[i], n, sp->q);
  }
  *flags = mech ? DM_SYS_MECHANICAL : 0;
  if (!mech || !constant || !lvq_zero)
    return DM_OK;
  /* Lv(q, 0) == 0: no term linear in v */
  dm_expr *zero = malloc(n * sizeof *zero), *Lv0 = malloc(n * sizeof *Lv0);
  int s = DM_ENOMEM, ok = 0;
  double c;
  if (zero && Lv0) {
    for (size_t i = 0; i < n; i++)
      zero[i] = dm_expr_const(b->ctx, 0.0);
    s = dm_expr_subs(b->ctx, n, Lv, Lv0, n, sp->v, zero, b->err);
    ok = s == DM_OK;
    for (size_t i = 0; ok && i < n; i++)
      ok = dm_expr_is_const(b->ctx, Lv0[i], &c) && c == 0;
  }
  free(zero);
  free(Lv0);
  if (s != DM_OK)
    return s;
  if (!ok)
    return DM_OK;
  if (n <= DM_LAG_MASS_DENSE_MAX && (d->mass = malloc(n * n * sizeof *d->mass)) == NULL)
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  if ((d->pmass = malloc((d->pat.vv.nnz + 1) * sizeof *d->pmass)) == NULL)
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  builder nb = *b;
  dm_lagrangian_spec tsp = *sp;
  tsp.native = DM_NATIVE_NEVER;       /* evaluated rarely: the tape will do */
  nb.sp = &tsp;
  s = dm_lag__compile_bundle(&nb, &d->massp, nmout, mout, 2 * n, NULL, 0, 0);
  if (s != DM_OK)
    return s;
  d->mass_possible = 1;
  if (eval_mass(d))
    *flags |= DM_SYS_SEPARABLE;
  return DM_OK;
}

/* For every request mask, the bundle that covers it at the least cost:
 * tape instructions, plus the outputs copied when it has more arrays than
 * asked for, four times that when the bundle runs on the tape (native
 * code, where it compiled, always wins over a tape; with auto a bundle
 * whose compilation failed falls back to its tape alone). */
void dm_lag__select(lag_data *d)
{
  const dm_bundle *ps[] = { &d->lq, &d->qvqq, &d->grad, &d->all };
  for (unsigned w = 0; w <= DM_LAG_ALL; w++) {
    const dm_bundle *best = &d->all;
    size_t bc = SIZE_MAX;
    for (size_t i = 0; i < sizeof ps / sizeof ps[0]; i++) {
      const dm_bundle *p = ps[i];
      if (p->tape == NULL || (w & ~p->have) != 0)
        continue;
      size_t c = dm_tape_ninstr(p->tape) + ((p->have & ~(w | DM_LAG_L)) ? p->nout : 0);
      if (p->scatter == NULL)
        c = 4 * c + 4;
      if (c < bc) {
        bc = c;
        best = p;
      }
    }
    d->sel[w] = best;
  }
}

int dm_lagrangian_outputs(dm_expr_ctx *ctx, dm_expr L, size_t n, const dm_expr *in,
                          dm_expr *out, dm_expr *ow, dm_err *err)
{
  size_t m = 2 * n, tri = n * (n + 1) / 2;
  dm_expr *H = malloc(m * m * sizeof *H), *o = out + 1 + 2 * n;
  if (H == NULL)
    return dm_err_set(err, DM_ENOMEM, "out of memory");
  out[0] = L;
  /* gradient and Hessian in (q, v) at once: the Hessian routine shares the
   * chain rule through common subexpressions between all the blocks */
  dm_err ge;                     /* their own message (out of memory) */
  dm_err_clear(&ge);
  if (dm_expr_grad(ctx, L, m, in, out + 1, &ge) != DM_OK ||
      dm_expr_hessian(ctx, L, m, in, H, &ge) != DM_OK) {
    const dm_err *ce = ge.msg[0] ? &ge : dm_expr_ctx_err(ctx);
    free(H);
    return dm_err_set(err, ce->status ? ce->status : DM_EFAILED, "L: %s",
                      ce->msg[0] ? ce->msg : "cannot build the derivatives");
  }
  for (size_t i = 0; i < n; i++)            /* Lvv, upper triangle */
    for (size_t j = i; j < n; j++)
      *o++ = H[(n + i) * m + n + j];
  for (size_t i = 0; i < n; i++)            /* Lvq, full */
    for (size_t j = 0; j < n; j++)
      *o++ = H[(n + i) * m + j];
  for (size_t i = 0; i < n; i++)            /* Lqq, upper triangle */
    for (size_t j = i; j < n; j++)
      *o++ = H[i * m + j];
  free(H);
  return dm_tape_optimize(ctx, 1 + 2 * n + 2 * tri + n * n, out, ow, err);
}

/* Patterns of the dense layout from its outputs: Lvv and Lqq upper
 * triangles (tri entries each), Lvq full; an entry is in the pattern
 * unless it is the constant 0. */
static int dense_patterns(dm_expr_ctx *ctx, lag_data *d, const dm_expr *o)
{
  size_t n = d->n, tri = n * (n + 1) / 2, ne;
  uint32_t *r = malloc((n * n + 1) * sizeof *r), *c = malloc((n * n + 1) * sizeof *c);
  uint32_t *pos = malloc((2 * n * n + 1) * sizeof *pos);
  dm_csr *pat[3] = { &d->pat.vv, &d->pat.vq, &d->pat.qq };
  const dm_expr *blk[3] = { o, o + tri, o + tri + n * n };
  int s = r && c && pos ? DM_OK : DM_ENOMEM;
  double z;
  for (int k = 0; k < 3 && s == DM_OK; k++) {
    size_t e = 0;
    ne = 0;
    for (size_t i = 0; i < n; i++)
      for (size_t j = k == 1 ? 0 : i; j < n; j++, e++)
        if (!dm_expr_is_const(ctx, blk[k][e], &z) || z != 0) {
          r[ne] = (uint32_t)i;
          c[ne++] = (uint32_t)j;
        }
    s = dm_lag__pattern(pat[k], n, ne, r, c, k != 1, pos);
  }
  free(r);
  free(c);
  free(pos);
  return s;
}

/* L and its derivatives, dense layout: tapes grad and all, the structure
 * flags, the patterns. */
static int build_lagrangian(builder *b, lag_data *d, unsigned *flags)
{
  const dm_lagrangian_spec *sp = b->sp;
  size_t n = sp->n, tri = n * (n + 1) / 2;
  size_t nall = 1 + 2 * n + 2 * tri + n * n;
  dm_expr *out = malloc(nall * sizeof *out), *ow = malloc(nall * sizeof *ow);
  dm_expr *Lvv = malloc(n * n * sizeof *Lvv);
  int s = DM_ENOMEM;
  if (!out || !ow || !Lvv) {
    dm_err_set(b->err, s, "out of memory");
    goto done;
  }
  /* rewritten once for both bundles: the gradient alone and with the
   * Hessian are computed the same way, bit for bit */
  if ((s = dm_lagrangian_outputs(b->ctx, sp->L, n, b->in, out, ow, b->err)) != DM_OK)
    goto done;
  if ((s = dense_patterns(b->ctx, d, out + 1 + 2 * n)) != DM_OK) {
    dm_err_set(b->err, s, "out of memory");
    goto done;
  }
  const dm_expr *Lv = out + 1 + n;
  for (size_t i = 0, k = 1 + 2 * n; i < n; i++)
    for (size_t j = i; j < n; j++, k++)
      Lvv[i * n + j] = Lvv[j * n + i] = out[k];
  const dm_block blk[] = { { 0, DM_BLK_VEC, 1, 1, 0, NULL }, { 1, DM_BLK_VEC, n, 1, 0, NULL },
                           { 2, DM_BLK_VEC, n, 1, 0, NULL }, { 3, DM_BLK_SYM, n, 1, 0, NULL },
                           { 4, DM_BLK_FULL, n, 1, 0, NULL }, { 5, DM_BLK_SYM, n, 1, 0, NULL } };
  /* the bundles in the order their native code is wanted (background
   * compilation takes them in this order): Stormer-Verlet's force first */
  if ((s = dm_lag__detect_structure(b, d, Lv, n * n, Lvv, d->pat.vq.nnz == 0, n * n, Lvv,
                                    flags)) != DM_OK)
    goto done;
  if (d->mass_possible) {
    /* separable (Lvq = 0, Lvv constant): Lq depends on q alone, and the
     * integrators ask for Lq alone (Stormer-Verlet) or for Lq, Lv, Lqq
     * (the Newton matrix, Lvv being the mass); both bundles from the same
     * rewritten outputs, so their values are those of grad and all */
    const dm_block bq[] = { { 1, DM_BLK_VEC, n, 1, 0, NULL } };
    const dm_block bqv[] = { { 1, DM_BLK_VEC, n, 1, 0, NULL }, { 2, DM_BLK_VEC, n, 1, 0, NULL },
                             { 5, DM_BLK_SYM, n, 1, 0, NULL } };
    dm_expr *sep = malloc((2 * n + tri) * sizeof *sep);
    if (sep == NULL) {
      s = dm_err_set(b->err, DM_ENOMEM, "out of memory");
      goto done;
    }
    memcpy(sep, ow + 1, 2 * n * sizeof *sep);
    memcpy(sep + 2 * n, ow + 1 + 2 * n + tri + n * n, tri * sizeof *sep);
    if ((s = dm_lag__compile_bundle(b, &d->lq, n, ow + 1, n, bq, 1, 1)) == DM_OK)
      s = dm_lag__compile_bundle(b, &d->qvqq, 2 * n + tri, sep, 2 * n, bqv, 3, 1);
    free(sep);
    if (s != DM_OK)
      goto done;
  }
  if ((s = dm_lag__compile_bundle(b, &d->grad, 1 + 2 * n, ow, 2 * n, blk, 6, 1)) != DM_OK ||
      (s = dm_lag__compile_bundle(b, &d->all, nall, ow, 2 * n, blk, 6, 1)) != DM_OK)
    goto done;
  dm_lag__select(d);
done:
  free(out);
  free(ow);
  free(Lvv);
  return s;
}

int dm_lagrangian_force_outputs(dm_expr_ctx *ctx, size_t n, const dm_expr *F,
                                const dm_expr *in, dm_expr *out, dm_err *err)
{
  memcpy(out, F, n * sizeof *out);
  if (dm_expr_jacobian(ctx, n, F, n, in, out + n, NULL) != DM_OK ||
      dm_expr_jacobian(ctx, n, F, n, in + n, out + n + n * n, NULL) != DM_OK) {
    const dm_err *ce = dm_expr_ctx_err(ctx);
    return dm_err_set(err, ce->status ? ce->status : DM_EFAILED, "force: %s",
                      ce->msg[0] ? ce->msg : "cannot build the derivatives");
  }
  return dm_tape_optimize(ctx, n + 2 * n * n, out, out, err);
}

static int build_force(builder *b, lag_data *d)
{
  const dm_lagrangian_spec *sp = b->sp;
  size_t n = sp->n, nall = n + 2 * n * n;
  dm_expr *out = malloc(nall * sizeof *out);
  uint32_t *r = malloc((n * n + 1) * sizeof *r), *c = malloc((n * n + 1) * sizeof *c);
  uint32_t *pos = malloc((2 * n * n + 1) * sizeof *pos);
  if (out == NULL || r == NULL || c == NULL || pos == NULL) {
    free(out);
    free(r);
    free(c);
    free(pos);
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  }
  const dm_block blk[] = { { 0, DM_BLK_VEC, n, 1, 0, NULL }, { 1, DM_BLK_FULL, n, 1, 0, NULL },
                           { 2, DM_BLK_FULL, n, 1, 0, NULL } };
  int s = dm_lagrangian_force_outputs(b->ctx, n, sp->force, b->in, out, b->err);
  /* the patterns from the Jacobians before rewriting */
  dm_expr *J = malloc((2 * n * n + 1) * sizeof *J);
  if (s == DM_OK && J != NULL &&
      dm_expr_jacobian(b->ctx, n, sp->force, n, b->in, J, NULL) == DM_OK &&
      dm_expr_jacobian(b->ctx, n, sp->force, n, b->in + n, J + n * n, NULL) == DM_OK) {
    dm_csr *pat[2] = { &d->pat.fq, &d->pat.fv };
    double z;
    for (int k = 0; k < 2 && s == DM_OK; k++) {
      size_t ne = 0;
      for (size_t i = 0; i < n * n; i++)
        if (!dm_expr_is_const(b->ctx, J[k * n * n + i], &z) || z != 0) {
          r[ne] = (uint32_t)(i / n);
          c[ne++] = (uint32_t)(i % n);
        }
      if (dm_lag__pattern(pat[k], n, ne, r, c, 0, pos) != DM_OK)
        s = dm_err_set(b->err, DM_ENOMEM, "out of memory");
    }
  } else if (s == DM_OK) {
    s = dm_lag__ctx_fail(b, "force");
  }
  free(J);
  if (s == DM_OK)
    s = dm_lag__compile_bundle(b, &d->force, n, out, 2 * n, blk, 3, 1);
  if (s == DM_OK)
    s = dm_lag__compile_bundle(b, &d->force_all, nall, out, 2 * n, blk, 3, 1);
  free(out);
  free(r);
  free(c);
  free(pos);
  return s;
}

static int build_constraints(builder *b, lag_data *d)
{
  const dm_lagrangian_spec *sp = b->sp;
  size_t n = sp->n, m = sp->m, tri = n * (n + 1) / 2;
  size_t nall = m + m * n + m * tri;
  dm_expr *out = malloc(nall * sizeof *out);
  if (out == NULL)
    return dm_err_set(b->err, DM_ENOMEM, "out of memory");
  memcpy(out, sp->constraints, m * sizeof *out);
  const dm_block blk[] = { { 0, DM_BLK_VEC, m, 1, 0, NULL },
                           { 1, DM_BLK_VEC, m * n, 1, 0, NULL },
                           { 2, DM_BLK_SYM, n, m, n * n, NULL } };
  dm_expr *G = out + m, *o = out + m + m * n;
  int s = DM_OK;
  if (dm_expr_jacobian(b->ctx, m, sp->constraints, n, sp->q, G, NULL) != DM_OK)
    s = dm_lag__ctx_fail(b, "constraints");
  for (size_t a = 0; s == DM_OK && a < m; a++)
    for (size_t i = 0; i < n; i++)
      for (size_t j = i; j < n; j++)
        *o++ = dm_expr_diff(b->ctx, G[a * n + i], sp->q[j]);
  if (s == DM_OK && dm_expr_ctx_err(b->ctx)->status != DM_OK)
    s = dm_lag__ctx_fail(b, "constraints");
  if (s == DM_OK)
    s = dm_tape_optimize(b->ctx, nall, out, out, b->err);
  if (s == DM_OK)
    s = dm_lag__compile_bundle(b, &d->constr, m + m * n, out, n, blk, 3, 1);
  if (s == DM_OK)
    s = dm_lag__compile_bundle(b, &d->constr_all, nall, out, n, blk, 3, 1);
  free(out);
  return s;
}

static size_t bundle_need(const dm_bundle *p)
{
  return p->tape ? p->nregs + p->nout : 0;
}

int dm_lagrangian_compile(dm_expr_ctx *ctx, const dm_lagrangian_spec *sp,
                          dm_system *sys, dm_err *err)
{
  memset(sys, 0, sizeof *sys);
  size_t n = sp->n;
  builder b = { ctx, sp, NULL, NULL, err };
  lag_data *d = calloc(1, sizeof *d);
  b.in = malloc((2 * n + 1) * sizeof *b.in);
  if (sp->q0 && sp->v0)
    b.in0 = malloc((2 * n + 1) * sizeof *b.in0);
  int s = DM_ENOMEM;
  if (d == NULL || b.in == NULL || (sp->q0 && sp->v0 && b.in0 == NULL)) {
    dm_err_set(err, s, "out of memory");
    goto fail;
  }
  if (n) {
    memcpy(b.in, sp->q, n * sizeof *b.in);
    memcpy(b.in + n, sp->v, n * sizeof *b.in);
  }
  if (b.in0) {
    memcpy(b.in0, sp->q0, n * sizeof *b.in0);
    memcpy(b.in0 + n, sp->v0, n * sizeof *b.in0);
  }
  d->n = n;
  d->m = sp->m;
  d->npar = sp->npar;
  if ((s = dm_lag__check_spec(&b)) != DM_OK)
    goto fail;
  if (copy_names(d, sp, ctx) != 0) {
    s = dm_err_set(err, DM_ENOMEM, "out of memory");
    goto fail;
  }
  unsigned flags = 0;
  d->sparse = sp->layout == DM_LAG_LAYOUT_SPARSE ||
              (sp->layout != DM_LAG_LAYOUT_DENSE && n > DM_LAG_DENSE_MAX);
  if ((s = (d->sparse ? dm_lag__build_sparse : build_lagrangian)(&b, d, &flags)) != DM_OK ||
      (sp->force && (s = (d->sparse ? dm_lag__build_force_sparse : build_force)(&b, d))
       != DM_OK) ||
      (sp->m && (s = build_constraints(&b, d)) != DM_OK))
    goto fail;

  size_t need = 0;
  const dm_bundle *ps[] = { &d->grad, &d->all, &d->lq, &d->qvqq, &d->force,
                            &d->force_all, &d->constr, &d->constr_all };
  for (size_t i = 0; i < sizeof ps / sizeof ps[0]; i++)
    if (bundle_need(ps[i]) > need)
      need = bundle_need(ps[i]);
  d->need = need;
  /* scratch for second derivatives asked for in the other layout */
  size_t conv = d->sparse ? d->pat.vv.nnz + d->pat.vq.nnz + d->pat.qq.nnz : 3 * n * n;
  size_t fconv = !sp->force ? 0 : d->sparse ? d->pat.fq.nnz + d->pat.fv.nnz : 2 * n * n;
  need += conv > fconv ? conv : fconv;
  sys->name = d->name;
  sys->n = n;
  sys->npar = sp->npar;
  sys->m = sp->m;
  sys->coords = (const char *const *)d->coords;
  sys->params = (const char *const *)d->params;
  sys->par = d->par;
  sys->flags = flags;
  sys->mass = (flags & DM_SYS_SEPARABLE) ? d->mass : NULL;
  d->pat.mass = (flags & DM_SYS_SEPARABLE) ? d->pmass : NULL;
  sys->pattern = &d->pat;
  sys->lagrangian = dm_lag__eval;
  sys->force = sp->force ? dm_lag__force_eval : NULL;
  sys->constraints = sp->m ? dm_lag__constr_eval : NULL;
  sys->data = d;
  sys->work_size = need * sizeof(double);
  sys->free_data = lag_free;
  sys->update = dm_lagrangian_update;
  free(b.in);
  free(b.in0);
  return DM_OK;
fail:
  lag_free_data(d);
  free(b.in);
  free(b.in0);
  memset(sys, 0, sizeof *sys);
  return s;
}

int dm_lagrangian_refresh(dm_system *sys, dm_err *err)
{
  if (sys == NULL || sys->free_data != lag_free || sys->data == NULL)
    return dm_err_set(err, DM_EINVAL, "not a system compiled from a Lagrangian");
  lag_data *d = sys->data;
  if (!d->mass_possible)
    return DM_OK;
  if (eval_mass(d)) {
    sys->flags |= DM_SYS_SEPARABLE;
    sys->mass = d->mass;
    d->pat.mass = d->pmass;
  } else {
    sys->flags &= ~(unsigned)DM_SYS_SEPARABLE;
    sys->mass = NULL;
    d->pat.mass = NULL;
  }
  return DM_OK;
}

/* Every bundle with native code. */
static int bundles(lag_data *d, dm_bundle **ps)
{
  dm_bundle *all[] = { &d->lq, &d->qvqq, &d->grad, &d->all, &d->force, &d->force_all,
                       &d->constr, &d->constr_all };
  int k = 0;
  for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
    if (all[i]->tape != NULL)
      ps[k++] = all[i];
  return k;
}

int dm_lagrangian_update(const dm_system *sys)
{
  if (sys == NULL || sys->free_data != lag_free || sys->data == NULL)
    return 0;
  lag_data *d = sys->data;
  dm_bundle *ps[8];
  int k = bundles(d, ps), installed = 0, pending = 0;
  for (int i = 0; i < k; i++) {
    installed |= dm_bundle_update(ps[i]);
    pending |= dm_bundle_pending(ps[i]);
  }
  if (installed)
    dm_lag__select(d);       /* native code is preferred where it is */
  return pending;
}

int dm_lagrangian_wait_native(const dm_system *sys, int interruptible, dm_err *err)
{
  if (sys == NULL || sys->free_data != lag_free || sys->data == NULL)
    return dm_err_set(err, DM_EINVAL, "not a system compiled from a Lagrangian");
  lag_data *d = sys->data;
  dm_bundle *ps[8];
  int k = bundles(d, ps), s = DM_OK;
  for (int i = 0; i < k; i++) {
    dm_err e;
    int si = s == DM_EINTR ? dm_bundle_cancel(ps[i], &e) : dm_bundle_wait(ps[i], interruptible, &e);
    if (si != DM_OK && s == DM_OK) {
      s = si;
      if (err != NULL)
        *err = e;
    }
  }
  for (int i = 0; i < k && s == DM_OK; i++)
    if (ps[i]->native_failed) {
      s = ps[i]->native_err.status ? ps[i]->native_err.status : DM_EFAILED;
      if (err != NULL)
        *err = ps[i]->native_err;
    }
  dm_lagrangian_update(sys);
  return s;
}

int dm_lagrangian_native_state(const dm_system *sys, dm_lagrangian_native *ns, dm_err *err)
{
  memset(ns, 0, sizeof *ns);
  if (sys == NULL || sys->free_data != lag_free || sys->data == NULL)
    return dm_err_set(err, DM_EINVAL, "not a system compiled from a Lagrangian");
  lag_data *d = sys->data;
  dm_bundle *ps[8];
  int k = bundles(d, ps), told = 0;
  for (int i = 0; i < k; i++) {
    ns->native += ps[i]->nat != NULL;
    ns->pending += ps[i]->job != NULL;
    ns->failed += ps[i]->native_failed;
    if (ps[i]->native_failed && !told && err != NULL) {
      *err = ps[i]->native_err;
      told = 1;
    }
  }
  return DM_OK;
}

int dm_lagrangian_stats_get(const dm_system *sys, dm_lagrangian_stats *st)
{
  memset(st, 0, sizeof *st);
  if (sys == NULL || sys->free_data != lag_free || sys->data == NULL)
    return DM_EINVAL;
  const lag_data *d = sys->data;
  st->ninstr_grad = dm_tape_ninstr(d->grad.tape);
  st->ninstr_all = dm_tape_ninstr(d->all.tape);
  st->nregs_all = dm_tape_nregs(d->all.tape);
  st->native_grad = d->grad.nat != NULL;
  st->native_all = d->all.nat != NULL;
  st->ninstr_force = d->force_all.tape ? dm_tape_ninstr(d->force_all.tape) : 0;
  st->ninstr_constr = d->constr_all.tape ? dm_tape_ninstr(d->constr_all.tape) : 0;
  st->ninstr_q = d->lq.tape ? dm_tape_ninstr(d->lq.tape) : 0;
  st->ninstr_sep = d->qvqq.tape ? dm_tape_ninstr(d->qvqq.tape) : 0;
  st->native_q = d->lq.nat != NULL;
  st->native_sep = d->qvqq.nat != NULL;
  st->sparse = d->sparse;
  return DM_OK;
}
