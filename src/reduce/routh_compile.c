/* routh_compile.c -- the compiled side of a Routh reduction: the full,
 * reduced and classical systems (dm_lagrangian_compile), the programs the
 * reduced integrators evaluate, the public reduced system (forwarding to
 * the compiled R^mu with `data` = the dm_routh, so the "routh" integrator
 * family can find the connection data), accessors, mu and parameter
 * updates, evaluation, and small numerical helpers. */
#include <config.h>
#include "reduce/routh_impl.h"
#include "expr/lagrangian.h"
#include "core/smalllu.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* {==== programs ========================================================= */

/* par: the parameter nodes of every program (original, then mu) */
static int prog_compile(dm_expr_ctx *ctx, dm_routh *red, const dm_routh_spec *sp, dm_rprog *p,
                        size_t nout, const dm_expr *out, size_t nin, const dm_expr *in,
                        const dm_expr *par, dm_err *e)
{
  int st = dm_tape_compile(ctx, nout, out, nin, in, red->np, par, &p->tape, e);
  if (st != DM_OK)
    return st;
  p->nin = nin;
  p->nout = nout;
  p->nwork = dm_tape_work_size(p->tape);
  if (p->nwork > red->nwork)
    red->nwork = p->nwork;
  if (sp->native != DM_NATIVE_NEVER) {
    dm_err ne;
    st = dm_native_compile(p->tape, NULL, red->par, &p->nat, &ne);
    if (st == DM_OK)
      p->fn = dm_native_function(p->nat);
    else if (sp->native == DM_NATIVE_ALWAYS || st == DM_EINTR) {
      if (e)
        *e = ne;
      return st;
    }
  }
  return DM_OK;
}

static void prog_free(dm_rprog *p)
{
  dm_native_free(p->nat);
  dm_tape_free(p->tape);
  memset(p, 0, sizeof *p);
}

void dm_routh_release_progs(dm_routh *red)
{
  dm_rprog *ps[] = {&red->inertia, &red->conn, &red->connd, &red->gyro_r, &red->thd, &red->info};
  size_t i;
  for (i = 0; i < sizeof ps / sizeof ps[0]; i++)
    prog_free(ps[i]);
  dm_bundle_free(&red->stage_r);
  dm_bundle_free(&red->stage_j);
  dm_csr_free(&red->upat);
}

/* {==== RSPRK stage programs ============================================= */

/* How each array of a stage is stored (dm_rstage_arr order). */
static const unsigned stage_kind[DM_RS_NARR] = {
  DM_BLK_VEC, DM_BLK_VEC, DM_BLK_SYM, DM_BLK_FULL, DM_BLK_SYM,      /* Lq Lv Lvv Lvq Lqq */
  DM_BLK_VEC, DM_BLK_FULL, DM_BLK_FULL,                             /* F Fq Fv */
  DM_BLK_VEC, DM_BLK_FULL, DM_BLK_FULL, DM_BLK_VEC, DM_BLK_VEC,     /* muA K B kv ib */
  DM_BLK_FULL, DM_BLK_FULL                                          /* dkv dib */
};

/* One stage program: the arrays k with from[k] != NULL, whose rewritten
 * outputs start at from[k] (symmetric ones as upper triangles), in
 * dm_rstage_arr order; out: room for all the outputs. */
static int compile_stage(dm_bundle *p, const dm_bundle_src *src, const dm_expr *const *from,
                         size_t s, dm_expr *out, dm_err *e)
{
  dm_block blk[DM_RS_NARR];
  dm_expr *o = out;
  size_t nb = 0, k;
  for (k = 0; k < DM_RS_NARR; k++) {
    unsigned kind = stage_kind[k];
    size_t len = kind == DM_BLK_VEC ? s : kind == DM_BLK_FULL ? s * s : s * (s + 1) / 2;
    if (from[k] == NULL)
      continue;
    blk[nb++] = (dm_block){(unsigned)k, kind, s, 1, 0, NULL};
    memcpy(o, from[k], len * sizeof *o);
    o += len;
  }
  return dm_bundle_compile(p, src, (size_t)(o - out), out, 2 * s, blk, nb, 1, e);
}

/* The pattern of a stage block of the RSPRK Newton matrix (rsprk.c:
 * d_ik Rvv + h a_ik (Rvx + K) - h at_ik E - h^2 sum at a D, E = Rxv - B^T
 * + Fv + K, D = Rxx - dib + Fx + dkv): entry (a, c) unless every term
 * that lands there is the constant 0 -- indexed as rsprk.c reads the
 * stage arrays.  R: the rewritten Lagrangian outputs (L, Lq, Lv, Lvv and
 * Lqq upper triangles, Lvq full), F: F, Fq, Fv (or NULL), G: muA, K, B,
 * kv, ib, dkv, dib (or NULL). */
static int stage_pattern(dm_expr_ctx *ctx, dm_routh *red, const dm_expr *R, const dm_expr *F,
                         const dm_expr *G)
{
  size_t s = red->s, ss = s * s, tri = s * (s + 1) / 2, a, c, nnz = 0;
  const dm_expr *vv = R + 1 + 2 * s, *vq = vv + tri, *qq = vq + ss;
  double z;
  dm_csr *U = &red->upat;
  dm_csr_free(U);
  uint32_t *cols = malloc((ss + 1) * sizeof *cols);
  if (cols == NULL || dm_csr_alloc(U, s, s, 0) != DM_OK) {
    free(cols);
    return DM_ENOMEM;
  }
#define NZ(x) (!dm_expr_is_const(ctx, (x), &z) || z != 0)
  for (a = 0; a < s; a++) {
    U->rowptr[a] = nnz;
    for (c = 0; c < s; c++) {
      size_t lo = a < c ? a : c, hi = a < c ? c : a;
      size_t t = lo * (2 * s - lo + 1) / 2 + (hi - lo), ac = a * s + c, ca = c * s + a;
      int on = NZ(vv[t]) || NZ(qq[t]) || NZ(vq[ac]) || NZ(vq[ca]);
      if (!on && F != NULL)
        on = NZ(F[s + ac]) || NZ(F[s + ss + ac]);
      if (!on && G != NULL)
        on = NZ(G[s + ac]) || NZ(G[s + ss + ca]) || NZ(G[3 * s + 2 * ss + ac])
             || NZ(G[3 * s + 3 * ss + ac]);
      if (on)
        cols[nnz++] = (uint32_t)c;
    }
  }
#undef NZ
  U->rowptr[s] = nnz;
  free(U->col);
  U->col = cols;
  U->nnz = nnz;
  return DM_OK;
}

/* The programs of an RSPRK stage, one per request kind (gradient: stage_r;
 * with second derivatives: stage_j), each one tape, and native code, for
 * every array of a stage (dm_rstage_arr).  Each group of outputs is
 * rewritten as its own program rewrites it -- R^mu's derivatives as the
 * compiled reduced system (dm_lagrangian_outputs), the force as its force
 * (dm_lagrangian_force_outputs), the connection terms as gyro_r would for
 * the gradient kind and as a program of all of them for the full kind --
 * and the union compiled without rewriting: every value is bit for bit the
 * one of the separate programs, the nodes the groups share (I, I^{-1}, A
 * and their derivatives) are computed once, and one call fills a stage. */
static int compile_stages(dm_expr_ctx *ctx, dm_routh *red, const dm_routh_spec *sp,
                          const dm_expr *in, const dm_expr *par, const dm_expr *K,
                          const dm_expr *kv, const dm_expr *ib, const dm_expr *dkv,
                          const dm_expr *dib, dm_err *e)
{
  const dm_routh_exprs *x = &red->ex;
  size_t s = red->s, ss = s * s, tri = s * (s + 1) / 2, nR = 1 + 2 * s + 2 * tri + ss;
  size_t nF = red->has_force ? s + 2 * ss : 0, nG = red->has_gyro ? 3 * s + 4 * ss : 0;
  dm_expr *R = malloc((2 * nR + nF + 3 * s + nG + nR + nF + nG) * sizeof *R);
  dm_expr *Rw = R + nR, *F = Rw + nR, *Gr = F + nF, *Gj = Gr + 3 * s, *out = Gj + nG;
  dm_bundle_src src = {ctx, in, s, red->np, par, NULL, red->par, sp->native};
  int st;
  if (R == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  st = dm_lagrangian_outputs(ctx, x->R, s, in, R, Rw, e);
  if (st == DM_OK && nF)
    st = dm_lagrangian_force_outputs(ctx, s, x->force, in, F, e);
  if (st == DM_OK && nG) {
    memcpy(Gr, x->muA, s * sizeof *Gr);
    memcpy(Gr + s, kv, s * sizeof *Gr);
    memcpy(Gr + 2 * s, ib, s * sizeof *Gr);
    memcpy(Gj, x->muA, s * sizeof *Gj);
    memcpy(Gj + s, K, ss * sizeof *Gj);
    memcpy(Gj + s + ss, x->B, ss * sizeof *Gj);
    memcpy(Gj + s + 2 * ss, kv, s * sizeof *Gj);
    memcpy(Gj + 2 * s + 2 * ss, ib, s * sizeof *Gj);
    memcpy(Gj + 3 * s + 2 * ss, dkv, ss * sizeof *Gj);
    memcpy(Gj + 3 * s + 3 * ss, dib, ss * sizeof *Gj);
    if ((st = dm_tape_optimize(ctx, 3 * s, Gr, Gr, e)) == DM_OK)
      st = dm_tape_optimize(ctx, nG, Gj, Gj, e);
  }
  if (st == DM_OK) {         /* gradient: Lq, Lv, F, muA, kv, ib */
    const dm_expr *from[DM_RS_NARR] = {Rw + 1, Rw + 1 + s};
    if (nF)
      from[DM_RS_F] = F;
    if (nG) {
      from[DM_RS_MUA] = Gr;
      from[DM_RS_KV] = Gr + s;
      from[DM_RS_IB] = Gr + 2 * s;
    }
    st = compile_stage(&red->stage_r, &src, from, s, out, e);
  }
  if (st == DM_OK && stage_pattern(ctx, red, Rw, nF ? F : NULL, nG ? Gj : NULL) != DM_OK)
    st = dm_err_set(e, DM_ENOMEM, "out of memory");
  if (st == DM_OK) {         /* everything */
    const dm_expr *from[DM_RS_NARR] = {Rw + 1, Rw + 1 + s, Rw + 1 + 2 * s, Rw + 1 + 2 * s + tri,
                                       Rw + 1 + 2 * s + tri + ss};
    if (nF) {
      from[DM_RS_F] = F;
      from[DM_RS_FQ] = F + s;
      from[DM_RS_FV] = F + s + ss;
    }
    if (nG) {
      from[DM_RS_MUA] = Gj;
      from[DM_RS_K] = Gj + s;
      from[DM_RS_B] = Gj + s + ss;
      from[DM_RS_KV] = Gj + s + 2 * ss;
      from[DM_RS_IB] = Gj + 2 * s + 2 * ss;
      from[DM_RS_DKV] = Gj + 3 * s + 2 * ss;
      from[DM_RS_DIB] = Gj + 3 * s + 3 * ss;
    }
    st = compile_stage(&red->stage_j, &src, from, s, out, e);
  }
  free(R);
  if (st == DM_OK) {
    if (red->stage_r.nregs > red->nwork)
      red->nwork = red->stage_r.nregs;
    if (red->stage_j.nregs > red->nwork)
      red->nwork = red->stage_j.nregs;
  }
  return st;
}

/* {==== forwarding callbacks of the public reduced system ================ */

int dm_routh_lag_forward(void *data, const double *q, const double *v, const double *par,
                         unsigned what, dm_lag_out *out, void *work)
{
  const dm_routh *red = data;
  return red->rsys.lagrangian(red->rsys.data, q, v, par, what, out, work);
}

static int force_forward(void *data, const double *q, const double *v, const double *par,
                         unsigned what, double *F, double *Fq, double *Fv, void *work)
{
  const dm_routh *red = data;
  return red->rsys.force(red->rsys.data, q, v, par, what, F, Fq, Fv, work);
}

static int constr_forward(void *data, const double *q, const double *par, unsigned what,
                          double *g, double *G, double *H, void *work)
{
  const dm_routh *red = data;
  return red->rsys.constraints(red->rsys.data, q, par, what, g, G, H, work);
}

/* {==== building ========================================================= */

static int compile_system(dm_expr_ctx *ctx, dm_routh *red, const dm_routh_spec *sp, dm_expr L,
                          const dm_expr *par, const char *suffix, dm_system *sys, dm_err *e)
{
  dm_lagrangian_spec ls;
  char name[512];
  snprintf(name, sizeof name, "%s%s", red->name, suffix);
  memset(&ls, 0, sizeof ls);
  ls.name = name;
  ls.n = red->s;
  ls.q = red->ex.x;
  ls.v = red->ex.xdot;
  ls.npar = red->np;
  ls.par = par;
  ls.par_values = red->par;
  ls.coord_names = (const char *const *)red->names;
  ls.param_names = (const char *const *)red->names + red->s;
  ls.L = L;
  ls.force = red->ex.force;
  ls.m = red->m;
  ls.constraints = red->ex.constraints;
  ls.native = sp->native;
  return dm_lagrangian_compile(ctx, &ls, sys, e);
}

int dm_routh_compile_full(dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_system *sys, dm_err *e)
{
  dm_lagrangian_spec ls;
  memset(&ls, 0, sizeof ls);
  ls.name = sp->name ? sp->name : "system";
  ls.n = sp->n;
  ls.q = sp->q;
  ls.v = sp->v;
  ls.npar = sp->npar;
  ls.par = sp->par;
  ls.par_values = sp->par_values;
  ls.coord_names = sp->coord_names;
  ls.param_names = sp->param_names;
  ls.L = sp->L;
  ls.force = sp->force;
  ls.m = sp->m;
  ls.constraints = sp->constraints;
  ls.native = sp->native;
  return dm_lagrangian_compile(ctx, &ls, sys, e);
}

int dm_routh_compile_nodes(dm_routh *red, dm_expr_ctx *ctx, const dm_routh_spec *sp,
                           const dm_expr *K, const dm_expr *kv, const dm_expr *ib,
                           const dm_expr *dkv, const dm_expr *dib, const dm_expr *Dw,
                           const dm_expr *DA, dm_err *e)
{
  const dm_routh_exprs *x = &red->ex;
  size_t r = red->r, s = red->s, ss = s * s, nmax;
  size_t ninfo = 2 * r * r + r * s + r + s + 2 * ss + r + 5, i;
  dm_expr *in = NULL, *out = NULL, *par = NULL;
  int st;
  nmax = ninfo > 3 * s ? ninfo : 3 * s;
  if (r + r * s + s > nmax)
    nmax = r + r * s + s;
  if (r * s + r * ss > nmax)
    nmax = r * s + r * ss;
  in = malloc(2 * s * sizeof *in);
  out = malloc(nmax * sizeof *out);
  par = malloc(red->np * sizeof *par);
  if (in == NULL || out == NULL || par == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "out of memory");
    goto done;
  }
  memcpy(in, x->x, s * sizeof *in);
  memcpy(in + s, x->xdot, s * sizeof *in);
  for (i = 0; i < red->npar; i++)
    par[i] = sp->par[i];
  for (i = 0; i < red->r; i++)
    par[red->npar + i] = red->ex.mu[i];
  if ((st = dm_routh_compile_full(ctx, sp, &red->fsys, e)) != DM_OK ||
      (st = compile_system(ctx, red, sp, x->R, par, "", &red->rsys, e)) != DM_OK ||
      (st = compile_system(ctx, red, sp, x->Rc, par, " (classical Routhian)", &red->csys, e)) != DM_OK)
    goto done;
  if ((st = prog_compile(ctx, red, sp, &red->inertia, r * r, x->I, s, in, par, e)) != DM_OK)
    goto done;
  memcpy(out, x->Iinv_mu, r * sizeof *out);
  memcpy(out + r, x->A, r * s * sizeof *out);
  memcpy(out + r + r * s, x->muA, s * sizeof *out);
  if ((st = prog_compile(ctx, red, sp, &red->conn, r + r * s + s, out, s, in, par, e)) != DM_OK)
    goto done;
  memcpy(out, Dw, r * s * sizeof *out);
  memcpy(out + r * s, DA, r * ss * sizeof *out);
  if ((st = prog_compile(ctx, red, sp, &red->connd, r * s + r * ss, out, s, in, par, e)) != DM_OK)
    goto done;
  memcpy(out, x->muA, s * sizeof *out);
  memcpy(out + s, kv, s * sizeof *out);
  memcpy(out + 2 * s, ib, s * sizeof *out);
  if ((st = prog_compile(ctx, red, sp, &red->gyro_r, 3 * s, out, 2 * s, in, par, e)) != DM_OK)
    goto done;
  if ((st = compile_stages(ctx, red, sp, in, par, K, kv, ib, dkv, dib, e)) != DM_OK)
    goto done;
  if ((st = prog_compile(ctx, red, sp, &red->thd, r, x->thetadot, 2 * s, in, par, e)) != DM_OK)
    goto done;
  /* info: I, Iinv, A, Iinv_mu, muA, Mt, B, thetadot, detI, V, Vmu, R, Rc */
  {
    dm_expr *o = out;
    memcpy(o, x->I, r * r * sizeof *o); o += r * r;
    memcpy(o, x->Iinv, r * r * sizeof *o); o += r * r;
    memcpy(o, x->A, r * s * sizeof *o); o += r * s;
    memcpy(o, x->Iinv_mu, r * sizeof *o); o += r;
    memcpy(o, x->muA, s * sizeof *o); o += s;
    memcpy(o, x->Mtilde, ss * sizeof *o); o += ss;
    memcpy(o, x->B, ss * sizeof *o); o += ss;
    memcpy(o, x->thetadot, r * sizeof *o); o += r;
    *o++ = x->detI; *o++ = x->V; *o++ = x->Vmu; *o++ = x->R; *o++ = x->Rc;
  }
  if ((st = prog_compile(ctx, red, sp, &red->info, ninfo, out, 2 * s, in, par, e)) != DM_OK)
    goto done;
  /* one parameter array for every system: a change through any of them
   * (e.g. a Lua params proxy on the public system) is seen by all */
  red->fpar_own = red->fsys.par;
  red->rpar_own = red->rsys.par;
  red->cpar_own = red->csys.par;
  red->fsys.par = red->rsys.par = red->csys.par = red->par;
  /* the public reduced system; never flagged separable, so nothing caches
   * a mass matrix that a parameter change could make stale */
  red->sys = red->rsys;
  red->sys.name = red->name;
  red->sys.flags &= ~(unsigned)DM_SYS_SEPARABLE;
  red->sys.mass = NULL;
  red->sys.lagrangian = dm_routh_lag_forward;
  red->sys.force = red->rsys.force ? force_forward : NULL;
  red->sys.constraints = red->rsys.constraints ? constr_forward : NULL;
  red->sys.data = red;
  red->sys.free_data = NULL;
  red->sys.refresh = dm_routh_sys_refresh;
  red->nscratch = 8 * red->n + 4 * red->n * red->n + ninfo + red->nwork + 2 * red->np
                  + red->fsys.work_size / sizeof(double) + 1;
  red->scratch = calloc(red->nscratch, sizeof(double));
  red->lscratch = calloc(3 * s + ss + red->rsys.work_size / sizeof(double) + 1, sizeof(double));
  if (red->scratch == NULL || red->lscratch == NULL || dm_rlu_init(&red->lu_s, s) != DM_OK)
    st = dm_err_set(e, DM_ENOMEM, "out of memory");
done:
  free(in);
  free(out);
  free(par);
  return st;
}

void dm_routh_free(dm_routh *red)
{
  size_t i;
  if (red == NULL)
    return;
  dm_routh_release_progs(red);
  if (red->fpar_own) {             /* give the systems their own arrays back */
    red->fsys.par = red->fpar_own;
    red->rsys.par = red->rpar_own;
    red->csys.par = red->cpar_own;
  }
  dm_system_release(&red->fsys);
  dm_system_release(&red->rsys);
  dm_system_release(&red->csys);
  for (i = 0; red->names && i < red->s + red->np; i++)
    free(red->names[i]);
  free(red->names);
  free(red->name);
  free(red->cname);
  free(red->shape);
  free(red->par);
  free(red->exbuf);
  free(red->scratch);
  free(red->lscratch);
  dm_rlu_free(&red->lu_s);
  free(red);
}

/* {==== accessors ======================================================== */

const dm_routh_exprs *dm_routh_exprs_get(const dm_routh *red) { return &red->ex; }
const dm_system *dm_routh_system(const dm_routh *red) { return &red->sys; }
const dm_system *dm_routh_classical(const dm_routh *red) { return &red->csys; }
const dm_system *dm_routh_full(const dm_routh *red) { return &red->fsys; }
const double *dm_routh_mu(const dm_routh *red) { return red->par + red->npar; }
int dm_routh_is_mechanical(const dm_routh *red) { return !red->general; }

int dm_routh_of_system(const dm_system *sys, dm_routh **red)
{
  if (sys == NULL || sys->lagrangian != dm_routh_lag_forward || sys->data == NULL)
    return 0;
  if (red)
    *red = sys->data;
  return 1;
}

/* Bring the private parameter copies of the compiled systems up to date
 * and re-evaluate their constant mass matrices (separable structure). */
static void refresh(dm_routh *red)
{
  dm_system *ss[3] = {&red->fsys, &red->rsys, &red->csys};
  double *own[3] = {red->fpar_own, red->rpar_own, red->cpar_own};
  size_t k;
  if (red->general) {            /* csys = rsys read red->par directly */
    memcpy(own[0], red->par, red->npar * sizeof(double));
    red->fsys.par = own[0];
    dm_lagrangian_refresh(&red->fsys, NULL);
    red->fsys.par = red->par;
    return;
  }
  memcpy(own[0], red->par, red->npar * sizeof(double));
  memcpy(own[1], red->par, red->np * sizeof(double));
  memcpy(own[2], red->par, red->np * sizeof(double));
  for (k = 0; k < 3; k++) {
    ss[k]->par = own[k];
    dm_lagrangian_refresh(ss[k], NULL);
    ss[k]->par = red->par;
  }
}

int dm_routh_set_mu(dm_routh *red, const double *mu, dm_err *e)
{
  size_t a;
  for (a = 0; a < red->r; a++)
    if (!isfinite(mu[a]))
      return dm_err_set(e, DM_EINVAL, "momentum mu[%zu] = %g is not finite", a + 1, mu[a]);
  for (a = 0; a < red->r; a++)
    red->par[red->npar + a] = mu[a];
  refresh(red);
  return DM_OK;
}

/* The public reduced system's refresh hook: a parameter (or mu) changed
 * through its par (shared by every system of the reduction). */
int dm_routh_sys_refresh(dm_system *sys, dm_err *e)
{
  dm_routh *red;
  (void)e;
  if (dm_routh_of_system(sys, &red))
    refresh(red);
  return DM_OK;
}

int dm_routh_set_param(dm_routh *red, size_t i, double v, dm_err *e)
{
  if (i >= red->npar)
    return dm_err_set(e, DM_EINVAL, "parameter index %zu out of range 1..%zu", i + 1, red->npar);
  red->par[i] = v;
  refresh(red);
  return DM_OK;
}

int dm_routh_set_sing_tol(dm_routh *red, double tol, dm_err *e)
{
  if (!(tol > 0.0 && tol < 1.0))
    return dm_err_set(e, DM_EINVAL, "sing_tol = %g must be in (0, 1)", tol);
  red->sing_tol = tol;
  return DM_OK;
}

static int finite_all(const double *x, size_t n)
{
  size_t i;
  for (i = 0; i < n; i++)
    if (!isfinite(x[i]))
      return 0;
  return 1;
}

/* A non-mechanical L has only the classical Routhian and thetadot. */
static int general_eval(dm_routh *red, const double *x, const double *xdot, dm_routh_vals *v,
                        dm_err *e)
{
  size_t s = red->s;
  double *xd = red->scratch, *w = xd + s;
  dm_lag_out o;
  if (v->I || v->Iinv || v->A || v->Iinv_mu || v->muA || v->Mtilde || v->B)
    return dm_err_set(e, DM_EUNSUP, "L is not mechanical: there is no locked inertia, connection "
                      "or magnetic term, only the classical Routhian and thetadot");
  if (xdot)
    memcpy(xd, xdot, s * sizeof *xd);
  else
    memset(xd, 0, s * sizeof *xd);
  memset(&o, 0, sizeof o);
  if (dm_routh_general_thetadot(red, x, xd, red->par, v->thetadot ? v->thetadot : w, w + red->r)
      || red->csys.lagrangian(red, x, xd, red->par, DM_LAG_L, &o, w + red->r) != 0)
    return dm_err_set(e, DM_EDOM, "J(x, thetadot, xdot) = mu has no solution thetadot here (or L "
                      "is outside its domain)");
  v->detI = v->V = v->Vmu = NAN;
  v->R = v->Rc = o.L;
  return DM_OK;
}

int dm_routh_eval(dm_routh *red, const double *x, const double *xdot, dm_routh_vals *v,
                  dm_err *e)
{
  size_t r = red->r, s = red->s, ss = s * s;
  double *in = red->scratch, *o = in + 2 * s, *w = o + red->info.nout;
  if (red->general)
    return general_eval(red, x, xdot, v, e);
  memcpy(in, x, s * sizeof *in);
  if (xdot)
    memcpy(in + s, xdot, s * sizeof *in);
  else
    memset(in + s, 0, s * sizeof *in);
  dm_rprog_run(&red->info, in, red->par, o, w);
  if (!finite_all(o, red->info.nout))
    return dm_err_set(e, DM_EDOM, "the reduced objects are not finite at this point (singular "
                      "locked inertia or outside the domain)");
#define PUT(f, k) do { if (v->f) memcpy(v->f, o, (k) * sizeof *o); o += (k); } while (0)
  PUT(I, r * r); PUT(Iinv, r * r); PUT(A, r * s); PUT(Iinv_mu, r); PUT(muA, s);
  PUT(Mtilde, ss); PUT(B, ss); PUT(thetadot, r);
#undef PUT
  v->detI = o[0];
  v->V = o[1];
  v->Vmu = o[2];
  v->R = o[3];
  v->Rc = o[4];
  return DM_OK;
}

int dm_routh_vanishes(dm_routh *red, dm_expr_ctx *ctx, dm_expr e)
{
  const dm_routh_exprs *x = &red->ex;
  size_t nv = 2 * x->s + red->np, i, k;
  dm_expr *vars, parts[3];
  double *vals, v[3];
  unsigned long seed = 12345;
  int op = dm_expr_kind(ctx, e), ok = 1;
  if (dm_expr_is_const(ctx, e, &v[0]))
    return v[0] == 0.0;
  if (op != DM_EXPR_SUB && op != DM_EXPR_ADD)
    return 0;
  vars = malloc(nv * sizeof *vars);
  vals = malloc(nv * sizeof *vals);
  if (vars == NULL || vals == NULL) {
    free(vars);
    free(vals);
    return 0;
  }
  memcpy(vars, x->x, x->s * sizeof *vars);
  memcpy(vars + x->s, x->xdot, x->s * sizeof *vars);
  for (i = 0; i < red->npar; i++)
    vars[2 * x->s + i] = dm_expr_param(ctx, red->names[red->s + i]);
  memcpy(vars + 2 * x->s + red->npar, x->mu, x->r * sizeof *vars);
  parts[0] = e;
  parts[1] = dm_expr_arg(ctx, e, 0);
  parts[2] = dm_expr_arg(ctx, e, 1);
  for (k = 0; k < 4 && ok; k++) {
    for (i = 0; i < nv; i++) {
      double u;
      seed = seed * 6364136223846793005UL + 1442695040888963407UL;
      u = (double)(seed >> 11) / 9007199254740992.0;
      if (i < x->s)
        vals[i] = 0.15 + 0.4 * u;                      /* positions */
      else if (i < 2 * x->s)
        vals[i] = 2.0 * u - 1.0;                       /* velocities */
      else
        vals[i] = red->par[i - 2 * x->s] != 0.0 ? red->par[i - 2 * x->s] * (0.9 + 0.2 * u)
                                                 : 0.5 + u;
    }
    if (dm_expr_eval(ctx, 3, parts, v, nv, vars, vals, NULL) != DM_OK || !isfinite(v[0])
        || !isfinite(v[1]) || !isfinite(v[2]) || fabs(v[1]) + fabs(v[2]) == 0.0)
      ok = 0;
    else
      ok = fabs(v[0]) <= 1e-12 * (fabs(v[1]) + fabs(v[2]));
  }
  free(vars);
  free(vals);
  return ok;
}

int dm_routh_muA(const dm_routh *red, const double *x, double *muA, double *tin, double *tout,
                 double *work)
{
  size_t s = red->s, i;
  int bad = 0;
  if (!red->has_gyro) {
    memset(muA, 0, s * sizeof *muA);
    return 0;
  }
  for (i = 0; i < s; i++) {
    tin[i] = x[i];
    tin[s + i] = 0.0;
  }
  dm_rprog_run(&red->gyro_r, tin, red->par, tout, work);
  for (i = 0; i < s; i++) {
    bad |= !isfinite(tout[i]);
    muA[i] = tout[i];
  }
  return bad;
}

int dm_routh_muA_K(const dm_routh *red, const double *x, double *muA, double *K, double *tin,
                   double *work)
{
  size_t s = red->s, i;
  const double *in[2] = {x, tin + s};
  double *o[DM_RS_NARR] = {NULL};
  if (!red->has_gyro) {
    memset(muA, 0, s * sizeof *muA);
    memset(K, 0, s * s * sizeof *K);
    return 0;
  }
  for (i = 0; i < s; i++)
    tin[s + i] = 0.0;
  o[DM_RS_MUA] = muA;
  o[DM_RS_K] = K;
  return dm_bundle_run(&red->stage_j, in, s, red->par, o, (1u << DM_RS_MUA) | (1u << DM_RS_K),
                       work);
}

/* {==== small numerical helpers ========================================== */

void dm_routh_sym_eig(const double *I, size_t r, double *lmin, double *lmax)
{
  double a[9], lo, hi;
  size_t i, j, p, q, sweep;
  if (r == 1) {
    *lmin = *lmax = I[0];
    return;
  }
  if (r == 2) {
    double m = 0.5 * (I[0] + I[3]), d = 0.5 * (I[0] - I[3]);
    double rad = hypot(d, 0.5 * (I[1] + I[2]));
    *lmin = m - rad;
    *lmax = m + rad;
    return;
  }
  /* 3 x 3: cyclic Jacobi rotations (quadratic convergence) */
  for (i = 0; i < 9; i++)
    a[i] = I[i];
  for (i = 0; i < 3; i++)
    for (j = 0; j < i; j++)
      a[i * 3 + j] = a[j * 3 + i] = 0.5 * (a[i * 3 + j] + a[j * 3 + i]);
  for (sweep = 0; sweep < 30; sweep++) {
    double off = fabs(a[1]) + fabs(a[2]) + fabs(a[5]);
    if (off <= 1e-300 || off <= DBL_EPSILON * 1e-3 * (fabs(a[0]) + fabs(a[4]) + fabs(a[8])))
      break;
    for (p = 0; p < 2; p++)
      for (q = p + 1; q < 3; q++) {
        double apq = a[p * 3 + q], th, t, c, sn;
        size_t k;
        if (apq == 0.0)
          continue;
        th = (a[q * 3 + q] - a[p * 3 + p]) / (2.0 * apq);
        t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
        c = 1.0 / sqrt(t * t + 1.0);
        sn = t * c;
        for (k = 0; k < 3; k++) {     /* columns p, q */
          double akp = a[k * 3 + p], akq = a[k * 3 + q];
          a[k * 3 + p] = c * akp - sn * akq;
          a[k * 3 + q] = sn * akp + c * akq;
        }
        for (k = 0; k < 3; k++) {     /* rows p, q */
          double apk = a[p * 3 + k], aqk = a[q * 3 + k];
          a[p * 3 + k] = c * apk - sn * aqk;
          a[q * 3 + k] = sn * apk + c * aqk;
        }
      }
  }
  lo = fmin(a[0], fmin(a[4], a[8]));
  hi = fmax(a[0], fmax(a[4], a[8]));
  *lmin = lo;
  *lmax = hi;
}

/* The small dense Newton systems of the reduced integrators use the core's
 * LU kernel (src/core/smalllu.h: partial pivoting, in place, row-major,
 * no allocation); dm_rlu only owns the pivot array. */
int dm_rlu_init(dm_rlu *lu, size_t N)
{
  lu->N = N;
  lu->perm = calloc(N ? N : 1, sizeof(size_t));
  return lu->perm != NULL ? DM_OK : DM_ENOMEM;
}

void dm_rlu_free(dm_rlu *lu)
{
  free(lu->perm);
  lu->perm = NULL;
}

int dm_rlu_factor(dm_rlu *lu, double *a, size_t N)
{
  if (N != lu->N)
    return DM_EINVAL;
  return dm_smalllu_factor(a, N, lu->perm);
}

void dm_rlu_solve(const dm_rlu *lu, const double *a, size_t N, double *b)
{
  dm_smalllu_solve(a, N, lu->perm, b);
}

/* max |x_i|; NaN when some x_i is NaN or infinite */
double dm_rnorm_inf(const double *x, size_t n)
{
  double m = 0.0, z = 0.0;
  size_t i;
  for (i = 0; i < n; i++) {
    double a = fabs(x[i]);
    m = a > m ? a : m;
    z += x[i] * 0.0;           /* NaN iff some x_i is NaN or infinite */
  }
  return z == z ? m : NAN;
}
