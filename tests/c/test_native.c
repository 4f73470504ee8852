/* test_native.c -- tapes compiled to machine code: agreement with the tape
 * to 1e-15 on random points, the object cache (hit, permissions, tampered
 * and foreign files), temporary files cleaned up, and the failure paths (no
 * compiler, compilation errors).  Writes only under $DMECH_TESTTMP (the
 * harness points XDG_CACHE_HOME there too). */
#include <config.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "expr/expr.h"
#include "expr/native.h"
#include "expr/tape.h"
#include "tap.h"

dm_expr tx_parse(dm_expr_ctx *ctx, const char *s);
extern const char *const tx_exprs[];
extern const size_t tx_nexprs;
extern const char tx_dsp_lagrangian[];
extern const char *const tx_dsp_q[4], *const tx_dsp_v[4], *const tx_dsp_par[5];

#define NV 5
static dm_expr_ctx *C;
static dm_expr V[NV];
static const double base[NV] = { 0.3817, 0.5293, 1.2385, 1.385, 0.7125 };
static char tmpdir[4096], cachedir[4400];

static double urand(unsigned *s)
{
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffffff) / 16777216.0;
}

static int agree(double a, double b)
{
  return a == b || (isnan(a) && isnan(b)) ||
         fabs(a - b) <= 1e-15 * fmax(fabs(a), fabs(b));
}

/* Native vs tape at npts random points near `mid` (inputs then params). */
static long mismatches(const dm_tape *t, dm_native_fn fn, const double *mid,
                       int npts, double spread)
{
  size_t nin = dm_tape_nin(t), npar = dm_tape_npar(t), nout = dm_tape_nout(t);
  double *x = malloc((nin + npar) * sizeof *x), *w = malloc(dm_tape_work_size(t) * sizeof *w);
  double *o1 = malloc(nout * sizeof *o1), *o2 = malloc(nout * sizeof *o2);
  unsigned seed = 7;
  long bad = 0;
  for (int p = 0; p < npts; p++) {
    for (size_t i = 0; i < nin + npar; i++)
      x[i] = mid[i] * (1 + spread * (urand(&seed) - 0.5));
    dm_tape_eval(t, x, x + nin, o1, w);
    fn(x, x + nin, o2);
    for (size_t k = 0; k < nout; k++)
      bad += !agree(o1[k], o2[k]);
  }
  free(x); free(w); free(o1); free(o2);
  return bad;
}

static int count_tmp_dirs(void)
{
  DIR *d = opendir(tmpdir);
  int n = 0;
  struct dirent *e;
  while (d && (e = readdir(d)) != NULL)
    n += strncmp(e->d_name, "dmech-", 6) == 0;
  if (d)
    closedir(d);
  return n;
}

static void test_agreement(void)
{
  size_t per = 1 + NV + NV * NV, nout = tx_nexprs * per;
  dm_expr *out = malloc(nout * sizeof *out);
  for (size_t i = 0; i < tx_nexprs; i++) {
    dm_expr e = tx_parse(C, tx_exprs[i]), *o = out + i * per;
    o[0] = e;
    dm_expr_grad(C, e, NV, V, o + 1, NULL);
    dm_expr_hessian(C, e, NV, V, o + 1 + NV, NULL);
  }
  dm_tape *t;
  dm_tape_compile(C, nout, out, 3, V, 2, V + 3, &t, NULL);
  free(out);
  dm_native *nat;
  dm_err err;
  int tmp0 = count_tmp_dirs();
  int st = dm_native_compile(t, base, base + 3, &nat, &err);
  tap_ok(st == DM_OK, "native compile of %zu instructions (%s)",
         dm_tape_ninstr(t), st == DM_OK ? "ok" : err.msg);
  if (st != DM_OK) {
    dm_tape_free(t);
    return;
  }
  long bad = mismatches(t, dm_native_function(nat), base, 300, 0.2);
  tap_is_int(bad, 0, "native = tape to 1e-15 relative on 300 random points "
             "x %zu outputs", nout);
  tap_is_int(count_tmp_dirs(), tmp0, "the private build directory is removed");

  dm_native_free(nat);
  dm_tape_free(t);
}

/* A tape long enough to be cut into chunks and units: a recurrence whose
 * values cross chunks (s_k needs s_{k-1}, sincos pairs, a square root that
 * is NaN for y > 1.2), its outputs scattered into three arrays; flat and
 * scattered code against the tape, a partial mask, the NaN report. */
static void test_chunks(void)
{
  enum { K = 600 };
  dm_expr out[2 * K], s = dm_expr_const(C, 0.0), x = V[0], y = V[1];
  dm_expr r = dm_expr_unary(C, DM_EXPR_SQRT, dm_expr_sub(C, dm_expr_const(C, 1.2), y));
  for (int k = 0; k < K; k++) {
    dm_expr a = dm_expr_mul(C, x, dm_expr_const(C, 0.01 * (k + 1)));
    dm_expr u = dm_expr_mul(C, dm_expr_unary(C, DM_EXPR_SIN, a), dm_expr_unary(C, DM_EXPR_COS, a));
    s = dm_expr_add(C, dm_expr_mul(C, s, dm_expr_const(C, 0.999)),
                    dm_expr_mul(C, u, k % 7 ? y : r));
    out[k] = s;
    out[K + k] = dm_expr_div(C, dm_expr_mul(C, s, V[3]), dm_expr_add(C, dm_expr_powi(C, a, 2),
                                                                     dm_expr_const(C, 1.0)));
  }
  dm_tape *t;
  int st = dm_tape_compile_exact(C, 2 * K, out, 3, V, 2, V + 3, &t, NULL);
  size_t ni = st == DM_OK ? dm_tape_ninstr(t) : 0;
  char *src = st == DM_OK ? dm_native_source(t) : NULL;
  tap_ok(src && ni > 4000 && strstr(src, "/* unit 2 */") && strstr(src, "dm_k8(") &&
         strstr(src, "r[") != NULL, "a tape of %zu instructions: several units, chunks and "
         "values passed between them", ni);
  free(src);
  if (st != DM_OK)
    return;
  dm_native *nat;
  dm_err err;
  st = dm_native_compile(t, base, base + 3, &nat, &err);
  tap_ok(st == DM_OK && mismatches(t, dm_native_function(nat), base, 50, 0.2) == 0,
         "chunked flat code = tape on 50 points%s%s", st ? ": " : "", st ? err.msg : "");
  dm_native_free(nat);
  /* mapped: s_k to a[k] and b[K-1-k], the quotients to c[k] */
  dm_native_map im[3] = { { 0, 0, 0 }, { 1, 0, 1 }, { 2, 0, 2 } }, om[3 * K];
  for (uint32_t k = 0; k < K; k++) {
    om[3 * k] = (dm_native_map){ k, 0, k };
    om[3 * k + 1] = (dm_native_map){ k, 1, K - 1 - k };
    om[3 * k + 2] = (dm_native_map){ K + k, 2, k };
  }
  st = dm_native_compile_mapped(t, base, base + 3, im, 3 * K, om, &nat, &err);
  tap_ok(st == DM_OK && dm_native_function(nat) == NULL && dm_native_scatter(nat) != NULL,
         "chunked scatter code compiled (no flat function)%s%s", st ? ": " : "",
         st ? err.msg : "");
  if (st != DM_OK) {
    dm_tape_free(t);
    return;
  }
  static double a[K], b[K], c[K], o[2 * K], work[8 * K];
  double *w = malloc(dm_tape_work_size(t) * sizeof *w);
  double in[3] = { 0.7, 0.9, 1.1 }, par[2] = { 1.385, 0.7125 };
  const double *ins[1] = { in };
  double *outs[3] = { a, b, c };
  dm_tape_eval(t, in, par, o, w);
  int rc = dm_native_scatter(nat)(ins, par, outs, 7u, work), same = rc == 0;
  for (int k = 0; k < K; k++)
    same &= agree(a[k], o[k]) && b[K - 1 - k] == a[k] && agree(c[k], o[K + k]);
  tap_ok(same, "scatter: every destination = tape");
  for (int k = 0; k < K; k++)
    b[k] = -1.0;
  rc = dm_native_scatter(nat)(ins, par, outs, 5u, work);
  same = rc == 0;
  for (int k = 0; k < K; k++)
    same &= b[k] == -1.0 && agree(a[k], o[k]) && agree(c[k], o[K + k]);
  tap_ok(same, "scatter with array 1 left out of the mask: untouched, the others written");
  in[1] = 1.5;                          /* sqrt(1.2 - y): NaN */
  rc = dm_native_scatter(nat)(ins, par, outs, 7u, work);
  tap_is_int(rc, 1, "an output NaN: the scatter reports 1");
  dm_native_free(nat);
  /* every output once, in order, into one array (a gradient): the NaN
   * test is a plain loop over it, not index tables */
  static double g[2 * K];
  dm_native_map gm[2 * K];
  for (uint32_t k = 0; k < 2 * K; k++)
    gm[k] = (dm_native_map){ k, 0, k };
  double *gouts[1] = { g };
  st = dm_native_compile_mapped(t, base, base + 3, im, 2 * K, gm, &nat, &err);
  in[1] = 0.9;
  rc = st == DM_OK ? dm_native_scatter(nat)(ins, par, gouts, 1u, work) : -1;
  same = rc == 0;
  for (int k = 0; k < 2 * K; k++)
    same &= agree(g[k], o[k]);
  tap_ok(same, "scatter into one array, every output in order: = tape");
  in[1] = 1.5;
  rc = st == DM_OK ? dm_native_scatter(nat)(ins, par, gouts, 1u, work) : -1;
  int nans = 0;
  for (int k = 0; k < 2 * K; k++)
    nans += isnan(g[k]);
  tap_ok(rc == 1 && nans > 0, "... and an output NaN: reported (%d NaN outputs)", nans);
  in[1] = 0.9;
  par[0] = HUGE_VAL;                    /* the quotients become infinite, not NaN */
  rc = st == DM_OK ? dm_native_scatter(nat)(ins, par, gouts, 1u, work) : -1;
  nans = 0;
  for (int k = 0; k < 2 * K; k++)
    nans += isinf(g[k]) ? 1 : 0;
  tap_ok(rc == 1 && nans > 0, "... and an infinite one: reported (%d infinite outputs)", nans);
  free(w);
  dm_native_free(nat);
  dm_tape_free(t);
}

/* The object cache, on a small tape (quick to compile). */
static void test_cache(void)
{
  dm_expr e[2] = { tx_parse(C, "sin(x)*exp(p*y) - z^3/k"), DM_EXPR_NONE };
  e[1] = dm_expr_diff(C, e[0], V[3]);
  dm_tape *t;
  dm_native *nat;
  dm_err err;
  dm_tape_compile(C, 2, e, 3, V, 2, V + 3, &t, NULL);
  int st = dm_native_compile(t, base, base + 3, &nat, &err);
  if (st != DM_OK) {
    tap_ok(0, "compile for the cache tests: %s", err.msg);
    dm_tape_free(t);
    return;
  }
  char path[4600];
  struct stat st1, st2;
  snprintf(path, sizeof path, "%s/%s.so", cachedir, dm_native_key(nat));
  /* start from a miss whatever earlier runs left in the cache */
  dm_native_free(nat);
  unlink(path);
  st = dm_native_compile(t, base, base + 3, &nat, &err);
  tap_ok(st == DM_OK && !dm_native_cached(nat), "compiled afresh after the "
         "cached object was removed");
  tap_ok(stat(cachedir, &st1) == 0 && (st1.st_mode & 0777) == 0700 &&
         st1.st_uid == getuid(), "cache directory is ours, mode 0700");
  tap_ok(stat(path, &st2) == 0 && (st2.st_mode & 0777) == 0600 &&
         st2.st_uid == getuid(), "cached object is ours, mode 0600");

  dm_native *again;
  st = dm_native_compile(t, base, base + 3, &again, &err);
  tap_ok(st == DM_OK && dm_native_cached(again) && !dm_native_cached(nat) &&
         strcmp(dm_native_key(again), dm_native_key(nat)) == 0,
         "second compile of the same tape is a cache hit");
  dm_native_free(again);

  /* a cached file writable by others is not trusted: rebuilt, 0600 again */
  chmod(path, 0666);
  st = dm_native_compile(t, base, base + 3, &again, &err);
  tap_ok(st == DM_OK && !dm_native_cached(again) && stat(path, &st2) == 0 &&
         (st2.st_mode & 0777) == 0600, "a group/other-writable cached object "
         "is rebuilt, not loaded");
  dm_native_free(again);
  dm_native_free(nat);

  /* a foreign object under the key's name is refused and replaced */
  unlink(path);
  FILE *f = fopen(path, "w");
  fputs("not an object", f);
  fclose(f);
  chmod(path, 0600);
  st = dm_native_compile(t, base, base + 3, &again, &err);
  tap_ok(st == DM_OK && !dm_native_cached(again), "a damaged cached object "
         "is replaced (%s)", st == DM_OK ? "ok" : err.msg);
  dm_native_free(again);
  /* two cached objects loaded at once, each for the first time in this
   * process: both hits, each its own code (the dynamic loader must not
   * take the second for the first) */
  dm_expr e2[1] = { tx_parse(C, "cos(x)*y + z*k") };
  dm_tape *t2;
  dm_native *o1 = NULL, *o2 = NULL;
  dm_tape_compile(C, 1, e2, 3, V, 2, V + 3, &t2, NULL);
  st = dm_native_compile(t, base, base + 3, &o1, &err);     /* both stored */
  int sb = dm_native_compile(t2, base, base + 3, &o2, &err);
  dm_native_free(o1);
  dm_native_free(o2);
  o1 = o2 = NULL;
  if (st == DM_OK && sb == DM_OK) {
    st = dm_native_compile(t, base, base + 3, &o1, &err);
    sb = dm_native_compile(t2, base, base + 3, &o2, &err);
  }
  double x3[3] = {0.3, -1.2, 2.0}, p2[2] = {0.7, 1.5}, out2[1] = {0}, want2[1] = {0};
  double *w2 = malloc((dm_tape_work_size(t2) + 1) * sizeof *w2);
  dm_tape_eval(t2, x3, p2, want2, w2);
  if (st == DM_OK && sb == DM_OK)
    dm_native_function(o2)(x3, p2, out2);
  tap_ok(st == DM_OK && sb == DM_OK && dm_native_cached(o1) && dm_native_cached(o2) &&
         out2[0] == want2[0], "two cached objects loaded at once: both cache hits, "
         "each computing its own tape");
  free(w2);
  dm_native_free(o1);
  dm_native_free(o2);
  dm_tape_free(t2);
  dm_tape_free(t);
}

static void test_dsp(void)
{
  dm_expr L = tx_parse(C, tx_dsp_lagrangian), vars[8], par[5], out[73];
  for (int i = 0; i < 4; i++) {
    vars[i] = dm_expr_sym(C, tx_dsp_q[i]);
    vars[4 + i] = dm_expr_sym(C, tx_dsp_v[i]);
  }
  for (int i = 0; i < 5; i++)
    par[i] = dm_expr_param(C, tx_dsp_par[i]);
  out[0] = L;
  dm_expr_grad(C, L, 8, vars, out + 1, NULL);
  dm_expr_hessian(C, L, 8, vars, out + 9, NULL);
  dm_tape *t;
  dm_tape_compile(C, 73, out, 8, vars, 5, par, &t, NULL);
  double mid[13] = { 0.6, 0.3, 0.5, 1.1, 0.2, -0.4, 0.3, 0.7,
                     1.0, 1.5, 1.0, 1.0, 9.81 };
  dm_native *nat;
  dm_err err;
  int st = dm_native_compile(t, mid, mid + 8, &nat, &err);
  tap_ok(st == DM_OK, "double spherical pendulum L + gradient + Hessian "
         "compiled natively");
  if (st == DM_OK) {
    tap_is_int(mismatches(t, dm_native_function(nat), mid, 500, 0.3), 0,
               "double spherical pendulum: native = tape on 500 points, "
               "parameters varied too");
    double o1[73], o2[73], w[512];
    mid[2] = 2.385;                  /* r2 > l2: sqrt of a negative number */
    dm_native_function(nat)(mid, mid + 8, o1);
    dm_tape_eval(t, mid, mid + 8, o2, w);
    int nan = 0, same = 1;
    for (int k = 0; k < 73; k++) {
      nan += isnan(o1[k]);
      same &= agree(o1[k], o2[k]);
    }
    tap_ok(nan > 0 && same, "outside the domain both give NaN in the same "
           "%d outputs", nan);
  }
  dm_native_free(nat);
  char *src = dm_native_source(t);
  tap_ok(src && strstr(src, "void dm_native_eval(") && strstr(src, "sqrt(") &&
         !strstr(src, "system("), "emitted source is straight-line C");
  free(src);
  dm_tape_free(t);
}

static void test_failures(void)
{
  dm_expr e = tx_parse(C, "x*sin(y) + exp(p)");
  dm_tape *t;
  dm_tape_compile(C, 1, &e, 2, V, 1, V + 3, &t, NULL);
  dm_native *nat = (dm_native *)&e;
  dm_err err;
  const char *old = getenv("CC");
  char *saved = old ? strdup(old) : NULL;
  setenv("CC", "/nonexistent/cc", 1);
  int st = dm_native_compile(t, NULL, NULL, &nat, &err);
  tap_ok(st == DM_ENOTFOUND && nat == NULL && strstr(err.msg, "/nonexistent/cc"),
         "no compiler: DM_ENOTFOUND (%s)", err.msg);
  setenv("CC", "cc -include /nonexistent/dmech-missing.h", 1);
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  tap_ok(st == DM_EFAILED && nat == NULL && strstr(err.msg, "dmech-missing.h"),
         "compiler error: DM_EFAILED with the compiler's message");
  for (char *c = err.msg; *c; c++)
    if (*c == '\n')
      *c = ' ';
  tap_diag("%.200s", err.msg);
  setenv("CC", "   ", 1);
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  tap_ok(st == DM_ENOTFOUND, "blank $CC: DM_ENOTFOUND");
  if (saved) {
    setenv("CC", saved, 1);
    free(saved);
  } else {
    unsetenv("CC");
  }
  tap_ok(dm_native_mode_parse("auto") == DM_NATIVE_AUTO &&
         dm_native_mode_parse("never") == DM_NATIVE_NEVER &&
         dm_native_mode_parse("always") == DM_NATIVE_ALWAYS &&
         dm_native_mode_parse("sometimes") == -1, "mode names");
  dm_tape_free(t);
}

int main(void)
{
  const char *tt = getenv("DMECH_TESTTMP");
  if (tt == NULL || *tt == '\0') {          /* run by hand: private scratch */
    static char d[] = "/tmp/dmech-test-native-XXXXXX";
    tt = mkdtemp(d);
  }
  /* a directory of its own: test programs run in parallel */
  snprintf(tmpdir, sizeof tmpdir, "%s/native-tmp-native", tt);
  mkdir(tmpdir, 0700);
  setenv("TMPDIR", tmpdir, 1);
  const char *xc = getenv("XDG_CACHE_HOME");
  if (xc == NULL || xc[0] != '/') {
    static char cdir[4200];
    snprintf(cdir, sizeof cdir, "%s/cache", tt);
    setenv("XDG_CACHE_HOME", cdir, 1);
    xc = cdir;
  }
  snprintf(cachedir, sizeof cachedir, "%s/dmech", xc);

  C = dm_expr_ctx_alloc();
  const char *names[NV] = { "x", "y", "z", "p", "k" };
  for (int i = 0; i < NV; i++)
    V[i] = i >= 3 ? dm_expr_param(C, names[i]) : dm_expr_sym(C, names[i]);

  /* no working cc at all: the feature is absent, say so and skip */
  dm_expr one = V[0];
  dm_tape *t;
  dm_native *nat;
  dm_tape_compile(C, 1, &one, 1, V, 0, NULL, &t, NULL);
  int st = dm_native_compile(t, NULL, NULL, &nat, NULL);
  dm_native_free(nat);
  dm_tape_free(t);
  if (st == DM_ENOTFOUND) {
    printf("1..0 # SKIP no C compiler\n");
    dm_expr_ctx_free(C);
    return 0;
  }
  test_agreement();
  test_chunks();
  test_cache();
  test_dsp();
  test_failures();
  dm_expr_ctx_free(C);
  return tap_done();
}
