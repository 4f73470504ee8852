/* test_lagrangian_sparse.c -- the sparse layout of compiled Lagrangian
 * systems: patterns of the second derivatives, values on the patterns
 * against the dense layout (a nonlinear chain with a velocity-dependent
 * coupling, a force and parameters), dense requests served by a sparse
 * system and sparse requests by a dense one (bit for bit the same numbers
 * as the system's own layout), the mass of a separable system on its
 * pattern, the automatic choice by size, native code against the tape. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "expr/expr.h"
#include "expr/lagrangian.h"
#include "core/status.h"
#include "core/system.h"
#include "tap.h"

static dm_expr_ctx *C;

#define NMAX 48

typedef struct chain {
  size_t n;
  dm_expr q[NMAX], v[NMAX], par[2];
  double pv[2];
  dm_expr L, F[NMAX];
} chain;

/* An FPU-like chain with fixed ends, a gyroscopic coupling v_i q_{i+1}
 * (so Lvq is not zero), and a damping force on every other mass. */
static void make_chain(chain *c, size_t n, int separable)
{
  char nm[32];
  c->n = n;
  for (size_t i = 0; i < n; i++) {
    snprintf(nm, sizeof nm, "x%zu_%zu_%d", i, n, separable);
    c->q[i] = dm_expr_sym(C, nm);
    snprintf(nm, sizeof nm, "vx%zu_%zu_%d", i, n, separable);
    c->v[i] = dm_expr_sym(C, nm);
  }
  c->par[0] = dm_expr_param(C, "beta");
  c->par[1] = dm_expr_param(C, "gam");
  c->pv[0] = 0.7;
  c->pv[1] = 0.35;
  dm_expr L = dm_expr_const(C, 0), prev = dm_expr_const(C, 0), half = dm_expr_const(C, 0.5);
  for (size_t i = 0; i <= n; i++) {
    dm_expr d = i < n ? dm_expr_sub(C, c->q[i], prev) : dm_expr_neg(C, prev);
    dm_expr V = dm_expr_add(C, dm_expr_mul(C, half, dm_expr_powi(C, d, 2)),
                            dm_expr_mul(C, c->par[0], dm_expr_unary(C, DM_EXPR_COSH, d)));
    L = dm_expr_sub(C, L, V);
    if (i < n) {
      dm_expr m = dm_expr_const(C, 1.0 + 0.1 * (double)(i % 3));
      L = dm_expr_add(C, L, dm_expr_mul(C, dm_expr_mul(C, half, m),
                                        dm_expr_powi(C, c->v[i], 2)));
      if (!separable && i + 1 < n)
        L = dm_expr_add(C, L, dm_expr_mul(C, c->par[1],
                                          dm_expr_mul(C, c->v[i], dm_expr_unary(C, DM_EXPR_SIN,
                                                                                c->q[i + 1]))));
      prev = c->q[i];
    }
  }
  c->L = L;
  for (size_t i = 0; i < n; i++)
    c->F[i] = i % 2 ? dm_expr_mul(C, dm_expr_neg(C, c->par[1]),
                                  dm_expr_mul(C, c->v[i], dm_expr_powi(C, c->q[i], 2)))
                    : dm_expr_const(C, 0.0);
}

static int compile_chain(const chain *c, int layout, int native, int forced, dm_system *s)
{
  dm_lagrangian_spec sp = { .n = c->n, .q = c->q, .v = c->v, .npar = 2, .par = c->par,
    .par_values = c->pv, .L = c->L, .force = forced ? c->F : NULL, .native = native,
    .layout = layout };
  dm_err e;
  int st = dm_lagrangian_compile(C, &sp, s, &e);
  if (st != DM_OK)
    tap_diag("compile: %s", e.msg);
  return st;
}

typedef struct evals {
  double L, Lq[NMAX], Lv[NMAX], Lvv[NMAX * NMAX], Lvq[NMAX * NMAX], Lqq[NMAX * NMAX];
  double F[NMAX], Fq[NMAX * NMAX], Fv[NMAX * NMAX];
} evals;

static void point(size_t n, double *q, double *v)
{
  for (size_t i = 0; i < n; i++) {
    q[i] = 0.3 * sin(2.385 * (double)(i + 1));
    v[i] = 0.2 * cos(1.7 * (double)(i + 1));
  }
}

static int eval_all(dm_system *s, unsigned extra, unsigned fextra, evals *o)
{
  size_t n = s->n;
  double q[NMAX], v[NMAX];
  point(n, q, v);
  void *w = malloc(s->work_size);
  dm_lag_out lo = { 0, o->Lq, o->Lv, o->Lvv, o->Lvq, o->Lqq };
  int r = s->lagrangian(s->data, q, v, s->par, DM_LAG_ALL | extra, &lo, w);
  o->L = lo.L;
  if (r == 0 && s->force)
    r = s->force(s->data, q, v, s->par, DM_FORCE_F | DM_FORCE_Q | DM_FORCE_V | fextra,
                 o->F, o->Fq, o->Fv, w);
  free(w);
  return r;
}

static double maxrel(const double *a, const double *b, size_t k)
{
  double d = 0, m = 0;
  for (size_t i = 0; i < k; i++) {
    d = fmax(d, fabs(a[i] - b[i]));
    m = fmax(m, fabs(b[i]));
  }
  return m > 0 ? d / m : d;
}

/* The pattern p holds exactly the nonzeros of the dense M (structural
 * zeros may not appear; every nonzero must). */
static int covers(const dm_csr *p, const double *M, size_t n)
{
  for (size_t i = 0; i < n; i++)
    for (size_t j = 0; j < n; j++)
      if (M[i * n + j] != 0 && dm_csr_find(p, i, j) < 0)
        return 0;
  return 1;
}

static void test_layouts(size_t n, int forced)
{
  chain c;
  dm_system sd, ss;
  make_chain(&c, n, 0);
  int st = compile_chain(&c, DM_LAG_LAYOUT_DENSE, DM_NATIVE_NEVER, forced, &sd);
  st |= compile_chain(&c, DM_LAG_LAYOUT_SPARSE, DM_NATIVE_NEVER, forced, &ss);
  tap_ok(st == DM_OK && sd.pattern && ss.pattern, "n = %zu%s: both layouts compile", n,
         forced ? ", forced" : "");
  if (st != DM_OK)
    return;
  static evals d1, s1, d2, s2;
  const dm_sys_pattern *P = ss.pattern;
  eval_all(&sd, 0, 0, &d1);
  eval_all(&ss, 0, 0, &s1);                       /* sparse system, dense request */
  eval_all(&ss, DM_LAG_SPARSE, DM_FORCE_SPARSE, &s2);   /* its own layout */
  eval_all(&sd, DM_LAG_SPARSE, DM_FORCE_SPARSE, &d2);   /* dense system, values */
  double e = fmax(fabs(s1.L - d1.L) / fabs(d1.L), maxrel(s1.Lq, d1.Lq, n));
  e = fmax(e, maxrel(s1.Lv, d1.Lv, n));
  e = fmax(e, maxrel(s1.Lvv, d1.Lvv, n * n));
  e = fmax(e, maxrel(s1.Lvq, d1.Lvq, n * n));
  e = fmax(e, maxrel(s1.Lqq, d1.Lqq, n * n));
  if (forced) {
    e = fmax(e, maxrel(s1.F, d1.F, n));
    e = fmax(e, maxrel(s1.Fq, d1.Fq, n * n));
    e = fmax(e, maxrel(s1.Fv, d1.Fv, n * n));
  }
  tap_ok(e < 1e-14, "n = %zu: sparse layout = dense layout to round-off (%.2g)", n, e);
  tap_ok(covers(&P->vv, d1.Lvv, n) && covers(&P->vq, d1.Lvq, n) && covers(&P->qq, d1.Lqq, n) &&
         (!forced || (covers(&P->fq, d1.Fq, n) && covers(&P->fv, d1.Fv, n))),
         "n = %zu: the patterns hold every nonzero", n);
  tap_ok(P->vv.nnz == n && P->qq.nnz == 3 * n - 2 && P->vq.nnz == n - 1 &&
         (!forced || (P->fq.nnz == n / 2 && P->fv.nnz == n / 2)),
         "n = %zu: pattern sizes vv %zu (n), qq %zu (3n-2), vq %zu (n-1)%s", n, P->vv.nnz,
         P->qq.nnz, P->vq.nnz, forced ? ", fq = fv = n/2" : "");
  /* values on the pattern: the sparse system's own against its dense
   * request, bit for bit; the dense system's gathered values likewise */
  double *g = malloc(n * n * sizeof *g);
  int same = 1;
  const dm_sys_pattern *D = sd.pattern;
  const dm_csr *pp[5] = { &P->vv, &P->vq, &P->qq, &P->fq, &P->fv };
  const dm_csr *pd[5] = { &D->vv, &D->vq, &D->qq, &D->fq, &D->fv };
  const double *sv[5] = { s2.Lvv, s2.Lvq, s2.Lqq, s2.Fq, s2.Fv };
  const double *sd1[5] = { s1.Lvv, s1.Lvq, s1.Lqq, s1.Fq, s1.Fv };
  const double *dv[5] = { d2.Lvv, d2.Lvq, d2.Lqq, d2.Fq, d2.Fv };
  const double *dd[5] = { d1.Lvv, d1.Lvq, d1.Lqq, d1.Fq, d1.Fv };
  for (int k = 0; k < (forced ? 5 : 3); k++) {
    dm_csr_to_dense(pp[k], sv[k], g);
    same &= memcmp(g, sd1[k], n * n * sizeof *g) == 0;
    dm_csr_to_dense(pd[k], dv[k], g);
    same &= memcmp(g, dd[k], n * n * sizeof *g) == 0;
  }
  tap_ok(same, "n = %zu: values <-> dense requests agree bit for bit in both layouts", n);
  free(g);
  dm_system_release(&sd);
  dm_system_release(&ss);
}

static void test_separable(void)
{
  chain c;
  dm_system s;
  make_chain(&c, 40, 1);
  int st = compile_chain(&c, DM_LAG_LAYOUT_AUTO, DM_NATIVE_NEVER, 0, &s);
  dm_lagrangian_stats ls;
  dm_lagrangian_stats_get(&s, &ls);
  tap_ok(st == DM_OK && ls.sparse, "40 coordinates: the sparse layout is chosen");
  tap_ok((s.flags & DM_SYS_SEPARABLE) && s.mass != NULL && s.pattern->mass != NULL &&
         s.pattern->vv.nnz == 40, "separable chain: mass dense and on the diagonal pattern");
  int ok = 1;
  for (size_t i = 0; i < 40; i++)
    ok &= s.pattern->mass[i] == 1.0 + 0.1 * (double)(i % 3) && s.mass[i * 40 + i] == s.pattern->mass[i];
  tap_ok(ok, "mass values m_i = 1 + 0.1 (i mod 3)");
  dm_system_release(&s);
  chain c2;
  make_chain(&c2, 12, 1);
  st = compile_chain(&c2, DM_LAG_LAYOUT_AUTO, DM_NATIVE_NEVER, 0, &s);
  dm_lagrangian_stats_get(&s, &ls);
  tap_ok(st == DM_OK && !ls.sparse && s.pattern != NULL && s.pattern->qq.nnz == 34,
         "12 coordinates: the dense layout, with its pattern (qq %zu entries)",
         s.pattern ? s.pattern->qq.nnz : 0);
  dm_system_release(&s);
}

static void test_native(void)
{
  chain c;
  dm_system st_, sn;
  make_chain(&c, 36, 0);
  int s1 = compile_chain(&c, DM_LAG_LAYOUT_AUTO, DM_NATIVE_NEVER, 1, &st_);
  int s2 = compile_chain(&c, DM_LAG_LAYOUT_AUTO, DM_NATIVE_AUTO, 1, &sn);
  dm_lagrangian_wait_native(&sn, 0, NULL);
  dm_lagrangian_stats ls;
  dm_lagrangian_stats_get(&sn, &ls);
  if (s1 == DM_OK && s2 == DM_OK && ls.native_all) {
    static evals a, b;
    eval_all(&st_, DM_LAG_SPARSE, DM_FORCE_SPARSE, &a);
    eval_all(&sn, DM_LAG_SPARSE, DM_FORCE_SPARSE, &b);
    tap_ok(memcmp(&a, &b, sizeof a) == 0, "sparse layout: native code = tape, bit for bit");
    eval_all(&st_, 0, 0, &a);
    eval_all(&sn, 0, 0, &b);
    tap_ok(memcmp(&a, &b, sizeof a) == 0, "dense requests: native code = tape, bit for bit");
  } else {
    tap_ok(s1 == DM_OK && s2 == DM_OK, "# SKIP no C compiler");
    tap_ok(s1 == DM_OK && s2 == DM_OK, "# SKIP no C compiler");
  }
  dm_system_release(&st_);
  dm_system_release(&sn);
}

int main(void)
{
  dm_gsl_init();
  const char *tt = getenv("DMECH_TESTTMP");
  if (tt && *tt) {               /* native objects only under the build tree */
    static char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s/native-tmp-lagrangian-sparse", tt);
    mkdir(tmp, 0700);
    setenv("TMPDIR", tmp, 1);
  } else {
    setenv("XDG_CACHE_HOME", "/nonexistent-dmech-cache", 1);
  }
  C = dm_expr_ctx_alloc();
  test_layouts(6, 0);
  test_layouts(9, 1);
  test_layouts(40, 1);
  test_separable();
  test_native();
  dm_expr_ctx_free(C);
  return tap_done();
}
