/* lie_system.c -- systems on Lie groups: the derivatives of L(g, xi) and of
 * the force in the trivialized form (lie_system.h), their compiled
 * programs, the dm_system view of kind "lie", the structure the lgvi
 * family needs (constant kinetic matrix, potential moments), and the
 * invariance check of the reduced (Euler-Poincare) form. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_integ_impl.h"

/* {==== names ============================================================ */

static char *dupstr(const char *s)
{
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d)
    memcpy(d, s, n);
  return d;
}

/* names of the stored numbers of one factor, before making them unique */
static void factor_names(const dm_lie_group *F, char (*out)[24])
{
  size_t i, j;
  switch (F->kind) {
  case DM_LIE_SO3:
  case DM_LIE_SE3:
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++)
        snprintf(out[3 * i + j], 24, "R%zu%zu", i + 1, j + 1);
    if (F->kind == DM_LIE_SE3)
      for (i = 0; i < 3; i++)
        snprintf(out[9 + i], 24, "p%zu", i + 1);
    break;
  case DM_LIE_SO2:
    snprintf(out[0], 24, "theta");
    break;
  case DM_LIE_SE2:
    snprintf(out[0], 24, "theta");
    snprintf(out[1], 24, "x");
    snprintf(out[2], 24, "y");
    break;
  case DM_LIE_TN:
    for (i = 0; i < F->nq; i++)
      snprintf(out[i], 24, "theta%zu", i + 1);
    break;
  default:
    for (i = 0; i < F->nq; i++)
      snprintf(out[i], 24, "x%zu", i + 1);
    break;
  }
}

/* every stored number named; a name seen before in an earlier factor gets
 * the suffix _<factor> */
void dm_lie_coord_names(const dm_lie_group *G, char (*names)[DM_LIE_NAME_MAX])
{
  size_t f, nf = G->kind == DM_LIE_PRODUCT ? G->nfac : 1, i, k = 0;
  for (f = 0; f < nf; f++) {
    const dm_lie_group *F = G->kind == DM_LIE_PRODUCT ? G->fac[f] : G;
    char nb[DM_LIE_NQ_MAX][24];
    factor_names(F, nb);
    for (i = 0; i < F->nq; i++, k++) {
      size_t j;
      int dup = 0;
      for (j = 0; j < k; j++)
        dup = dup || strcmp(names[j], nb[i]) == 0;
      if (dup)
        snprintf(names[k], DM_LIE_NAME_MAX, "%.12s_%u", nb[i], (unsigned)(f + 1) % 100u);
      else
        snprintf(names[k], DM_LIE_NAME_MAX, "%s", nb[i]);
    }
  }
}

static char **make_gnames(const dm_lie_group *G)
{
  char (*buf)[DM_LIE_NAME_MAX] = malloc(G->nq * sizeof *buf);
  char **names = calloc(G->nq + 1, sizeof *names);
  size_t k;
  if (names == NULL || buf == NULL) {
    free(buf);
    free(names);
    return NULL;
  }
  dm_lie_coord_names(G, buf);
  for (k = 0; k < G->nq; k++)
    if ((names[k] = dupstr(buf[k])) == NULL)
      break;
  free(buf);
  return names;
}

static char **make_numbered(const char *prefix, size_t n)
{
  char **names = calloc(n + 1, sizeof *names), b[32];
  size_t i;
  if (names == NULL)
    return NULL;
  for (i = 0; i < n; i++) {
    snprintf(b, sizeof b, "%s%zu", prefix, i + 1);
    if ((names[i] = dupstr(b)) == NULL)
      return names;
  }
  return names;
}

static void free_names(char **names, size_t n)
{
  size_t i;
  for (i = 0; names && i < n; i++)
    free(names[i]);
  free(names);
}

static int names_ok(char **names, size_t n)
{
  size_t i;
  if (names == NULL)
    return 0;
  for (i = 0; i < n; i++)
    if (names[i] == NULL)
      return 0;
  return 1;
}

/* }====================================================================== */

/* {==== the dm_system callbacks ========================================== */

/* (g, xi) into w, run p, test the outputs; 1 when one is NaN or Inf */
static int run2(const dm_lie_system *S, const dm_bundle *p, const double *g, const double *xi,
                const double *par, double *w, double **out)
{
  double *o, bad = 0.0;
  size_t i;
  memcpy(w, g, S->nq * sizeof *w);
  if (xi)
    memcpy(w + S->nq, xi, S->dim * sizeof *w);
  o = dm_bundle_run_plain(p, w, par);
  for (i = 0; i < p->nout; i++)
    bad += 0.0 * o[i];
  *out = o;
  return bad != 0.0 || bad != bad;
}

static int lie_lag(void *data, const double *q, const double *v, const double *par,
                   unsigned what, dm_lag_out *out, void *work)
{
  const dm_lie_system *S = data;
  const size_t n = S->dim;
  int full = (what & (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ)) != 0;
  double *o;
  if (what & DM_LAG_SPARSE)
    return -1;
  if (run2(S, full ? &S->all : &S->grad, q, v, par, work, &o))
    return 1;
  if (what & DM_LAG_L)
    out->L = o[0];
  if (what & DM_LAG_Q)
    memcpy(out->Lq, o + 1, n * sizeof *o);
  if (what & DM_LAG_V)
    memcpy(out->Lv, o + 1 + n, n * sizeof *o);
  if (what & DM_LAG_VV)
    memcpy(out->Lvv, o + 1 + 2 * n, n * n * sizeof *o);
  if (what & DM_LAG_VQ)
    memcpy(out->Lvq, o + 1 + 2 * n + n * n, n * n * sizeof *o);
  if (what & DM_LAG_QQ)
    memcpy(out->Lqq, o + 1 + 2 * n + 2 * n * n, n * n * sizeof *o);
  return 0;
}

/* F only: the Jacobians are not derived for systems on groups */
static int lie_force(void *data, const double *q, const double *v, const double *par,
                     unsigned what, double *F, double *Fq, double *Fv, void *work)
{
  const dm_lie_system *S = data;
  double *o;
  if (what & (DM_FORCE_Q | DM_FORCE_V | DM_FORCE_SPARSE))
    return -1;
  if (run2(S, &S->fprog, q, v, par, work, &o))
    return 1;
  memcpy(F, o, S->dim * sizeof *o);
  return 0;
}

int dm_lie_eval_moment(const dm_lie_system *S, const double *g, double *M, double *work)
{
  double *o;
  if (S->moment_zero) {
    memset(M, 0, S->dim * sizeof *M);
    return 0;
  }
  if (run2(S, &S->moment, g, NULL, S->parv, work, &o))
    return 1;
  memcpy(M, o, S->dim * sizeof *o);
  return 0;
}

int dm_lie_eval_force(const dm_lie_system *S, const double *g, const double *xi, double *F,
                      double *work)
{
  double *o;
  if (S->force == NULL) {
    memset(F, 0, S->dim * sizeof *F);
    return 0;
  }
  if (run2(S, &S->fprog, g, xi, S->parv, work, &o))
    return 1;
  memcpy(F, o, S->dim * sizeof *o);
  return 0;
}

/* }====================================================================== */

/* {==== compiling ======================================================== */

static int ctxfail(dm_expr_ctx *ctx, const char *what, dm_err *e)
{
  const dm_err *ce = dm_expr_ctx_err(ctx);
  int st = ce->status ? ce->status : DM_EFAILED;
  dm_err_set(e, st, "%s: %s", what, ce->msg[0] ? ce->msg : "cannot build the derivatives");
  dm_expr_ctx_clear_err(ctx);
  return st;
}

static int is_zero(dm_expr_ctx *ctx, dm_expr x)
{
  double v;
  return dm_expr_is_const(ctx, x, &v) && v == 0.0;
}

int dm_lie_compile_bundle(const dm_lie_system *S, dm_bundle *p, size_t nout, const dm_expr *out,
                          size_t nin, const dm_expr *in, dm_err *e)
{
  dm_bundle_src src;
  memset(&src, 0, sizeof src);
  src.ctx = S->ctx;
  src.in = in;
  src.inlen = nin;
  src.npar = S->npar;
  src.par = S->par;
  src.par0 = S->parv;
  src.native = S->native;
  return dm_bundle_compile(p, &src, nout, out, nin, NULL, 0, 0, e);
}

void dm_lie_system_grow_work(dm_lie_system *S, const dm_bundle *p)
{
  size_t need = p->nregs + p->nout + 8;
  if (need > S->work)
    S->work = need;
  S->sys.work_size = S->work * sizeof(double);
}

/* L, Lq, Lv, Lvv, Lvq, Lqq in the trivialized form; the grad and all
 * bundles; the moment and force programs; the lgvi structure */
static int build(dm_lie_system *S, dm_err *e)
{
  dm_expr_ctx *ctx = S->ctx;
  const size_t nq = S->nq, n = S->dim;
  size_t nout = 1 + 2 * n + 3 * n * n, i, j;
  dm_expr *out = calloc(nout, sizeof *out), *gg = calloc(nq, sizeof *gg), *in;
  dm_expr *Lq = out + 1, *Lv = out + 1 + n, *Lvv = Lv + n, *Lvq = Lvv + n * n, *Lqq = Lvq + n * n;
  dm_expr zero = dm_expr_const(ctx, 0.0), M[DM_LIE_DIM_MAX], Lv0[DM_LIE_DIM_MAX];
  dm_expr zs[DM_LIE_DIM_MAX];
  int st = DM_OK;
  if (out == NULL || gg == NULL) {
    free(out);
    free(gg);
    return dm_err_set(e, DM_ENOMEM, "system on a group: out of memory");
  }
  in = calloc(nq + n, sizeof *in);
  if (in == NULL) {
    free(out);
    free(gg);
    return dm_err_set(e, DM_ENOMEM, "system on a group: out of memory");
  }
  memcpy(in, S->g, nq * sizeof *in);
  memcpy(in + nq, S->xi, n * sizeof *in);
  out[0] = S->L;
#define CK(what) do { if (st != DM_OK || dm_expr_ctx_err(ctx)->status != DM_OK) { \
    st = ctxfail(ctx, what, e); goto done; } } while (0)
  st = dm_expr_grad(ctx, S->L, nq, S->g, gg, NULL);
  CK("L (derivative in g)");
  st = dm_lie_sym_trivialize(ctx, S->G, S->g, gg, DM_LIE_LEFT, Lq, NULL);
  CK("L (trivialized derivative in g)");
  st = dm_expr_grad(ctx, S->L, n, S->xi, Lv, NULL);
  CK("L (momentum)");
  st = dm_expr_jacobian(ctx, n, Lv, n, S->xi, Lvv, NULL);
  CK("L (d2L/dxi2)");
  for (i = 0; i < n && st == DM_OK; i++) {
    st = dm_expr_grad(ctx, Lv[i], nq, S->g, gg, NULL);
    if (st == DM_OK)
      st = dm_lie_sym_trivialize(ctx, S->G, S->g, gg, DM_LIE_LEFT, Lvq + i * n, NULL);
    if (st == DM_OK)
      st = dm_expr_grad(ctx, Lq[i], nq, S->g, gg, NULL);
    if (st == DM_OK)
      st = dm_lie_sym_trivialize(ctx, S->G, S->g, gg, DM_LIE_LEFT, Lqq + i * n, NULL);
  }
  CK("L (second derivatives)");
  if ((st = dm_lie_compile_bundle(S, &S->grad, 1 + 2 * n, out, nq + n, in, e)) != DM_OK)
    goto done;
  dm_lie_system_grow_work(S, &S->grad);
  if ((st = dm_lie_compile_bundle(S, &S->all, nout, out, nq + n, in, e)) != DM_OK)
    goto done;
  dm_lie_system_grow_work(S, &S->all);
  /* moments M(g) = Lq(g, 0) */
  for (i = 0; i < n; i++)
    zs[i] = zero;
  st = dm_expr_subs(ctx, n, Lq, M, n, S->xi, zs, NULL);
  CK("L (moments)");
  S->moment_zero = 1;
  for (i = 0; i < n; i++)
    S->moment_zero = S->moment_zero && is_zero(ctx, M[i]);
  if (!S->moment_zero) {
    if ((st = dm_lie_compile_bundle(S, &S->moment, n, M, nq, S->g, e)) != DM_OK)
      goto done;
    dm_lie_system_grow_work(S, &S->moment);
  }
  if (S->force != NULL) {
    if ((st = dm_lie_compile_bundle(S, &S->fprog, n, S->force, nq + n, in, e)) != DM_OK)
      goto done;
    dm_lie_system_grow_work(S, &S->fprog);
  }
  /* lgvi: L = 1/2 xi^T J xi - U(g), J free of g and xi */
  st = dm_expr_subs(ctx, n, Lv, Lv0, n, S->xi, zs, NULL);
  CK("L (momentum at rest)");
  S->quadratic = 1;
  for (i = 0; i < n && S->quadratic; i++) {
    S->quadratic = is_zero(ctx, Lv0[i]);
    for (j = 0; j < n && S->quadratic; j++)
      S->quadratic = is_zero(ctx, Lvq[i * n + j]) &&
                     !dm_expr_depends(ctx, Lvv[i * n + j], nq, S->g) &&
                     !dm_expr_depends(ctx, Lvv[i * n + j], n, S->xi);
  }
  if (S->quadratic) {
    if ((S->Jexpr = malloc(n * n * sizeof *S->Jexpr)) == NULL ||
        (S->J = malloc(n * n * sizeof *S->J)) == NULL) {
      st = dm_err_set(e, DM_ENOMEM, "system on a group: out of memory");
      goto done;
    }
    memcpy(S->Jexpr, Lvv, n * n * sizeof *Lvv);
    if ((st = dm_lie_update_J(S, e)) != DM_OK)
      goto done;
  }
#undef CK
done:
  free(out);
  free(gg);
  free(in);
  return st;
}

int dm_lie_update_J(dm_lie_system *S, dm_err *e)
{
  if (!S->quadratic)
    return DM_OK;
  return dm_expr_eval(S->ctx, S->dim * S->dim, S->Jexpr, S->J, S->npar, S->par, S->parv, e);
}

/* the substitution g -> identity (the reduced Lagrangian and force) */
static int reduce_exprs(dm_lie_system *S, dm_err *e)
{
  dm_expr id[DM_LIE_NQ_MAX], r[DM_LIE_DIM_MAX];
  if (dm_lie_sym_identity(S->ctx, S->G, id, e) != DM_OK)
    return e->status;
  if (dm_expr_subs(S->ctx, 1, &S->L, &S->L, S->nq, S->g, id, e) != DM_OK)
    return e->status;
  if (S->force != NULL) {
    if (dm_expr_subs(S->ctx, S->dim, S->force, r, S->nq, S->g, id, e) != DM_OK)
      return e->status;
    memcpy(S->force, r, S->dim * sizeof *r);
  }
  return DM_OK;
}

void dm_lie_system_free(dm_lie_system *S)
{
  size_t i;
  if (S == NULL)
    return;
  dm_bundle_free(&S->grad);
  dm_bundle_free(&S->all);
  dm_bundle_free(&S->moment);
  dm_bundle_free(&S->fprog);
  for (i = 0; i < S->ngauss; i++) {
    dm_bundle_free(&S->gauss[i].res);
    dm_bundle_free(&S->gauss[i].jac);
  }
  free(S->gauss);
  dm_lie_group_free(S->G);
  free(S->name);
  free(S->g);
  free(S->xi);
  free(S->par);
  free(S->force);
  free(S->force0);
  free(S->parv);
  free(S->Jexpr);
  free(S->J);
  free_names(S->pnames, S->npar);
  free_names(S->gnames, S->nq);
  free_names(S->munames, S->dim);
  free_names(S->xinames, S->dim);
  free(S);
}

static int alloc_from(dm_expr_ctx *ctx, const dm_lie_spec *sp, dm_lie_system **out, dm_err *e)
{
  dm_lie_system *S = calloc(1, sizeof *S);
  size_t i, nq, n;
  *out = NULL;
  if (S == NULL)
    return dm_err_set(e, DM_ENOMEM, "system on a group: out of memory");
  S->ctx = ctx;
  if ((S->G = dm_lie_group_copy(sp->G, e)) == NULL) {
    dm_lie_system_free(S);
    return e ? e->status : DM_ENOMEM;
  }
  nq = S->nq = S->G->nq;
  n = S->dim = S->G->dim;
  S->npar = sp->npar;
  S->native = sp->native;
  S->reduced = sp->reduced;
  S->name = dupstr(sp->name ? sp->name : "system on a group");
  S->g = malloc(nq * sizeof *S->g);
  S->xi = malloc(n * sizeof *S->xi);
  S->par = malloc((sp->npar + 1) * sizeof *S->par);
  S->parv = calloc(sp->npar + 1, sizeof *S->parv);
  S->pnames = calloc(sp->npar + 1, sizeof *S->pnames);
  S->gnames = make_gnames(S->G);
  S->munames = make_numbered("mu", n);
  S->xinames = make_numbered("xi", n);
  if (sp->force) {
    S->force = malloc(n * sizeof *S->force);
    S->force0 = malloc(n * sizeof *S->force0);
  }
  if (!S->name || !S->g || !S->xi || !S->par || !S->parv || !S->pnames ||
      !names_ok(S->gnames, nq) || !names_ok(S->munames, n) || !names_ok(S->xinames, n) ||
      (sp->force && (!S->force || !S->force0))) {
    dm_lie_system_free(S);
    return dm_err_set(e, DM_ENOMEM, "system on a group: out of memory");
  }
  memcpy(S->g, sp->g, nq * sizeof *S->g);
  memcpy(S->xi, sp->xi, n * sizeof *S->xi);
  if (sp->npar)
    memcpy(S->par, sp->par, sp->npar * sizeof *S->par);
  for (i = 0; i < sp->npar; i++) {
    const char *pn = sp->param_names ? sp->param_names[i] : dm_expr_name(ctx, sp->par[i]);
    S->parv[i] = sp->par_values ? sp->par_values[i] : 0.0;
    if ((S->pnames[i] = dupstr(pn ? pn : "?")) == NULL) {
      dm_lie_system_free(S);
      return dm_err_set(e, DM_ENOMEM, "system on a group: out of memory");
    }
  }
  S->L = S->L0 = sp->L;
  if (sp->force) {
    memcpy(S->force, sp->force, n * sizeof *S->force);
    memcpy(S->force0, sp->force, n * sizeof *S->force0);
  }
  *out = S;
  return DM_OK;
}

/* the momentum map of left translations, for the run driver's momentum
 * columns */
static void spatial_momentum(const dm_system *sys, const double *g, const double *mu, double *J)
{
  dm_lie_spatial_momentum(((const dm_lie_system *)sys->data)->G, g, mu, J);
}

static void fill_base(dm_lie_system *S)
{
  dm_system *sys = &S->sys;
  memset(sys, 0, sizeof *sys);
  sys->name = S->name;
  sys->kind = DM_SYSTEM_LIE;
  sys->n = S->dim;
  sys->nq = S->nq;
  sys->npar = S->npar;
  sys->coords = (const char *const *)S->gnames;
  sys->pnames = (const char *const *)S->munames;
  sys->vnames = (const char *const *)S->xinames;
  sys->space = S->G->name;
  sys->momentum_map = spatial_momentum;
  sys->params = (const char *const *)S->pnames;
  sys->par = S->parv;
  sys->flags = S->quadratic ? DM_SYS_MECHANICAL : 0;
  sys->lagrangian = lie_lag;
  sys->force = S->force ? lie_force : NULL;
  sys->data = S;
  sys->work_size = S->work * sizeof(double);
}

static int check_spec(const dm_lie_spec *sp, dm_err *e)
{
  if (sp == NULL || sp->G == NULL || sp->g == NULL || sp->xi == NULL || sp->L == DM_EXPR_NONE ||
      (sp->npar > 0 && sp->par == NULL))
    return dm_err_set(e, DM_EINVAL, "system on a group: the spec needs a group, the symbols of "
                      "g and xi and a Lagrangian");
  return DM_OK;
}

int dm_lie_system_compile(dm_expr_ctx *ctx, const dm_lie_spec *sp, dm_lie_system **out,
                          dm_err *e)
{
  dm_lie_system *S;
  int st;
  *out = NULL;
  if ((st = check_spec(sp, e)) != DM_OK)
    return st;
  if ((st = alloc_from(ctx, sp, &S, e)) != DM_OK)
    return st;
  if (S->reduced && (st = reduce_exprs(S, e)) != DM_OK) {
    dm_lie_system_free(S);
    return st;
  }
  if ((st = build(S, e)) != DM_OK) {
    dm_lie_system_free(S);
    return st;
  }
  fill_base(S);
  *out = S;
  return DM_OK;
}

/* }====================================================================== */

/* {==== reduction: the invariance check ================================== */

/* deterministic pseudo-random numbers in [-1, 1) */
static double lcg(unsigned long long *s)
{
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 4503599627370496.0 - 1.0;
}

/* the right-trivialized derivatives in g of the nf expressions f, checked
 * to vanish: symbolically, else at 5 random points */
static int check_invariant(const dm_lie_system *S, size_t nf, const dm_expr *f,
                           const char *what, dm_err *e)
{
  dm_expr_ctx *ctx = S->ctx;
  const size_t nq = S->nq, n = S->dim;
  dm_expr gg[DM_LIE_NQ_MAX], d[DM_LIE_DIM_MAX];
  unsigned long long seed = 2385;
  size_t k, i, a;
  for (k = 0; k < nf; k++) {
    int zero = 1;
    if (dm_expr_grad(ctx, f[k], nq, S->g, gg, NULL) != DM_OK ||
        dm_lie_sym_trivialize(ctx, S->G, S->g, gg, DM_LIE_RIGHT, d, e) != DM_OK)
      return ctxfail(ctx, "euler_poincare", e);
    for (i = 0; i < n; i++)
      zero = zero && is_zero(ctx, d[i]);
    if (zero)
      continue;
    for (a = 0; a < 5; a++) {
      double xr[DM_LIE_DIM_MAX], gv[DM_LIE_NQ_MAX], xv[DM_LIE_DIM_MAX], vals[DM_LIE_DIM_MAX + 1];
      double gradv[DM_LIE_NQ_MAX], scale = 1.0;
      dm_expr vars[DM_LIE_NQ_MAX + DM_LIE_DIM_MAX + 64], ev[DM_LIE_DIM_MAX + 1 + DM_LIE_NQ_MAX];
      double vv[DM_LIE_NQ_MAX + DM_LIE_DIM_MAX + 64];
      size_t nv = 0;
      for (i = 0; i < n; i++)
        xr[i] = 2.0 * lcg(&seed), xv[i] = lcg(&seed);
      dm_lie_exp(S->G, xr, gv);
      for (i = 0; i < nq; i++)
        vars[nv] = S->g[i], vv[nv++] = gv[i];
      for (i = 0; i < n; i++)
        vars[nv] = S->xi[i], vv[nv++] = xv[i];
      for (i = 0; i < S->npar && nv < sizeof vars / sizeof vars[0]; i++)
        vars[nv] = S->par[i], vv[nv++] = S->parv[i];
      memcpy(ev, d, n * sizeof *d);
      ev[n] = f[k];
      if (dm_expr_eval(ctx, n + 1, ev, vals, nv, vars, vv, e) != DM_OK)
        return e ? e->status : DM_EINVAL;
      if (dm_expr_eval(ctx, nq, gg, gradv, nv, vars, vv, e) != DM_OK)
        return e ? e->status : DM_EINVAL;
      scale = fmax(scale, fabs(vals[n]));
      for (i = 0; i < nq; i++)
        scale = fmax(scale, fabs(gradv[i]));
      for (i = 0; i < n; i++)
        if (!(fabs(vals[i]) <= 1e-10 * scale)) {
          char gd[256], xd[160];
          size_t m, len = 0;
          dm_lie_describe(S->G, gv, gd, sizeof gd);
          xd[0] = '\0';
          for (m = 0; m < n && len < sizeof xd; m++)
            len += (size_t)snprintf(xd + len, sizeof xd - len, "%s%.6g", m ? ", " : "", xv[m]);
          return dm_err_set(e, DM_EINVAL, "euler_poincare: %s is not invariant under left "
                            "translations in %s: d/de %s(exp(e e_%zu) g, xi) = %.6g at g = %s, "
                            "xi = (%s) (a potential or another dependence on g; the reduced "
                            "form needs a G-invariant Lagrangian)", what, S->G->name,
                            nf > 1 ? "F" : "L", i + 1, vals[i], gd, xd);
        }
    }
  }
  return DM_OK;
}

int dm_lie_system_reduce(const dm_lie_system *S, dm_lie_system **out, dm_err *e)
{
  dm_lie_spec sp;
  int st;
  *out = NULL;
  if (S->reduced)
    return dm_err_set(e, DM_EINVAL, "euler_poincare: '%s' is reduced already", S->name);
  if ((st = check_invariant(S, 1, &S->L0, "the Lagrangian", e)) != DM_OK)
    return st;
  if (S->force0 && (st = check_invariant(S, S->dim, S->force0, "the force", e)) != DM_OK)
    return st;
  memset(&sp, 0, sizeof sp);
  sp.name = S->name;
  sp.G = S->G;
  sp.g = S->g;
  sp.xi = S->xi;
  sp.npar = S->npar;
  sp.par = S->par;
  sp.par_values = S->parv;
  sp.param_names = (const char *const *)S->pnames;
  sp.L = S->L0;
  sp.force = S->force0;
  sp.native = S->native;
  sp.reduced = 1;
  return dm_lie_system_compile(S->ctx, &sp, out, e);
}

/* }====================================================================== */

/* {==== accessors ======================================================== */

const dm_system *dm_lie_system_base(const dm_lie_system *S)
{
  return &S->sys;
}

const dm_lie_system *dm_lie_system_of(const dm_system *sys)
{
  if (sys == NULL || sys->kind == NULL || strcmp(sys->kind, DM_SYSTEM_LIE) != 0)
    return NULL;
  return sys->data;
}

const dm_lie_group *dm_lie_system_group(const dm_lie_system *S)
{
  return S->G;
}

int dm_lie_system_is_reduced(const dm_lie_system *S)
{
  return S->reduced;
}

const char *const *dm_lie_system_gnames(const dm_lie_system *S)
{
  return (const char *const *)S->gnames;
}

const char *const *dm_lie_system_munames(const dm_lie_system *S)
{
  return (const char *const *)S->munames;
}

const char *const *dm_lie_system_xinames(const dm_lie_system *S)
{
  return (const char *const *)S->xinames;
}

double *dm_lie_system_par(dm_lie_system *S)
{
  return S->parv;
}

void dm_lie_system_params_changed(dm_lie_system *S)
{
  S->gen++;
  dm_lie_update_J(S, NULL);
}

/* }====================================================================== */
