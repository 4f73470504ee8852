/* test_expr.c -- the expression DAG: derivatives of 60+ expressions against
 * the complex step, Hessians, printed forms, hash-consing and identities,
 * substitution + evaluation, error paths, deep expressions. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "expr/expr.h"
#include "tap.h"

dm_expr tx_parse(dm_expr_ctx *ctx, const char *s);
int tx_cstep(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
             const double *vals, size_t k, double *deriv);

extern const char *const tx_exprs[];
extern const size_t tx_nexprs;
#define exprs tx_exprs
#define NEXPR tx_nexprs
#define NV 5

static dm_expr_ctx *C;
static dm_expr V[NV];
static const double vals[NV] = { 0.3817, 0.5293, 1.2385, 1.385, 0.7125 };

static double ev(dm_expr e)
{
  double r = NAN;
  dm_expr_eval(C, 1, &e, &r, NV, V, vals, NULL);
  return r;
}

static double relerr(double got, double want)
{
  if (got == want)
    return 0;
  return fabs(got - want) / fmax(1.0, fabs(want));
}

static char *str(dm_expr e)
{
  static char buf[4096];
  char *s = dm_expr_to_string(C, e, sizeof buf - 8, NULL);
  snprintf(buf, sizeof buf, "%s", s ? s : "(null)");
  free(s);
  return buf;
}

/* First derivatives against the complex step, one test per expression. */
static void test_gradients(void)
{
  for (size_t i = 0; i < NEXPR; i++) {
    dm_expr e = tx_parse(C, exprs[i]);
    double worst = 0;
    int bad = e == DM_EXPR_NONE;
    for (int k = 0; k < NV && !bad; k++) {
      double ref, got = ev(dm_expr_diff(C, e, V[k]));
      bad |= tx_cstep(C, e, NV, V, vals, (size_t)k, &ref);
      worst = fmax(worst, relerr(got, ref));
      bad |= isnan(got);
    }
    tap_ok(!bad && worst < 1e-13, "gradient of %s (max rel err %.2g)",
           exprs[i], worst);
  }
}

/* Hessians: against the complex step of the gradient, and symmetric when
 * both orders are derived independently. */
static void test_hessians(void)
{
  double worst = 0, asym = 0;
  int bad = 0;
  for (size_t i = 0; i < NEXPR; i++) {
    dm_expr e = tx_parse(C, exprs[i]), H[NV * NV], g[NV];
    bad |= dm_expr_hessian(C, e, NV, V, H, NULL) != DM_OK;
    bad |= dm_expr_grad(C, e, NV, V, g, NULL) != DM_OK;
    for (int a = 0; a < NV; a++)
      for (int b = 0; b < NV; b++) {
        double ref, got = ev(H[a * NV + b]);
        bad |= tx_cstep(C, g[a], NV, V, vals, (size_t)b, &ref);
        double err = relerr(got, ref);
        if (err > worst) worst = err;
        double other = ev(dm_expr_diff(C, dm_expr_diff(C, e, V[b]), V[a]));
        asym = fmax(asym, relerr(got, other));
      }
  }
  tap_ok(!bad && worst < 1e-12, "Hessians of %zu expressions match the "
         "complex step (max rel err %.2g)", NEXPR, worst);
  tap_ok(asym < 1e-13, "d2/dxdy = d2/dydx evaluated independently "
         "(max rel diff %.2g)", asym);
}

/* Sparse Hessians: the same expressions as the dense ones, on exactly the
 * entries that are not the constant 0; sparse Jacobians: the dense ones'
 * values there (the dense rows may come from the derivative memo, built
 * another way); a variable listed twice is refused. */
static void test_sparse_derivs(void)
{
  int bad = 0, same = 1;
  dm_expr zero = dm_expr_const(C, 0.0);
  for (size_t i = 0; i < NEXPR; i++) {
    dm_expr e = tx_parse(C, exprs[i]), H[NV * NV], g[NV], J[NV * NV];
    dm_expr_sparse S, SJ;
    bad |= dm_expr_hessian(C, e, NV, V, H, NULL) != DM_OK;
    bad |= dm_expr_hessian_sparse(C, e, NV, V, &S, NULL) != DM_OK;
    bad |= dm_expr_grad(C, e, NV, V, g, NULL) != DM_OK;
    bad |= dm_expr_jacobian(C, NV, g, NV, V, J, NULL) != DM_OK;
    bad |= dm_expr_jacobian_sparse(C, NV, g, NV, V, &SJ, NULL) != DM_OK;
    if (bad)
      break;
    size_t k = 0, kj = 0;
    for (size_t a = 0; a < NV; a++)
      for (size_t b = 0; b < NV; b++) {
        if (b >= a && H[a * NV + b] != zero) {
          same &= k < S.rowptr[a + 1] && S.col[k] == b && S.val[k] == H[a * NV + b];
          k++;
        }
        if (J[a * NV + b] != zero) {
          same &= kj < SJ.rowptr[a + 1] && SJ.col[kj] == b &&
                  relerr(ev(SJ.val[kj]), ev(J[a * NV + b])) < 1e-14;
          kj++;
        }
      }
    same &= k == S.nnz && kj == SJ.nnz && S.nrow == NV && SJ.nrow == NV;
    dm_expr_sparse_free(&S);
    dm_expr_sparse_free(&SJ);
  }
  tap_ok(!bad && same, "sparse Hessians and Jacobians of %zu expressions: the dense ones' "
         "nonzero entries", NEXPR);
  dm_expr_sparse S;
  dm_err err;
  dm_expr dup[3] = { V[0], V[1], V[0] };
  tap_is_int(dm_expr_hessian_sparse(C, tx_parse(C, "x*y"), 3, dup, &S, &err), DM_EINVAL,
             "sparse Hessian: a variable listed twice (%s)", err.msg);
  dm_expr_sparse_free(&S);
  dm_expr_sparse_free(NULL);
  /* a chain of 300 variables: the Hessian of sum (x_i - x_{i-1})^4 is
   * tridiagonal, 2*300 - 1 entries in the upper triangle */
  enum { NC = 300 };
  dm_expr xs[NC], L = zero;
  char nm[16];
  for (int i = 0; i < NC; i++) {
    snprintf(nm, sizeof nm, "c%d", i);
    xs[i] = dm_expr_sym(C, nm);
    if (i > 0)
      L = dm_expr_add(C, L, dm_expr_powi(C, dm_expr_sub(C, xs[i], xs[i - 1]), 4));
  }
  int st = dm_expr_hessian_sparse(C, L, NC, xs, &S, NULL);
  tap_ok(st == DM_OK && S.nnz == 2 * NC - 1 && S.rowptr[NC] == S.nnz && S.col[1] == 1 &&
         S.col[2] == 1 && S.col[3] == 2, "chain of %d: tridiagonal pattern (%zu entries)",
         NC, S.nnz);
  dm_expr_sparse_free(&S);
}

/* Printing: a printed expression parses back to the same value. */
static void test_print_roundtrip(void)
{
  double worst = 0;
  int bad = 0;
  for (size_t i = 0; i < NEXPR; i++) {
    dm_expr e = tx_parse(C, exprs[i]);
    dm_expr es[3] = { e, dm_expr_diff(C, e, V[0]), dm_expr_diff(C, dm_expr_diff(C, e, V[0]), V[1]) };
    for (int j = 0; j < 3; j++) {
      char *s = dm_expr_to_string(C, es[j], 0, NULL);
      dm_expr back = s ? tx_parse(C, s) : DM_EXPR_NONE;
      if (back == DM_EXPR_NONE) {
        bad = 1;
        tap_diag("cannot reparse: %s", s ? s : "(null)");
      } else {
        worst = fmax(worst, relerr(ev(back), ev(es[j])));
      }
      free(s);
    }
  }
  tap_ok(!bad && worst < 1e-13, "printed expressions and derivatives parse "
         "back to the same value (max rel err %.2g)", worst);
}

static void is_str(const char *src, const char *want)
{
  const char *got = str(tx_parse(C, src));
  tap_ok(strcmp(got, want) == 0, "print(%s) = %s", src, want);
  if (strcmp(got, want) != 0)
    tap_diag("got %s", got);
}

static void is_dstr(const char *src, const char *var, const char *want)
{
  dm_expr d = dm_expr_diff(C, tx_parse(C, src), dm_expr_sym(C, var));
  const char *got = str(d);
  tap_ok(strcmp(got, want) == 0, "d(%s)/d%s = %s", src, var, want);
  if (strcmp(got, want) != 0)
    tap_diag("got %s", got);
}

/* In a fresh context, so that operands keep the order they were written
 * in (commutative operands are ordered by creation). */
static void test_printed_forms(void)
{
  dm_expr_ctx *saved = C;
  C = dm_expr_ctx_alloc();
  is_str("0.5*(r^2 + z^2)", "0.5*(r^2 + z^2)");
  is_str("-1/sqrt(r^2 + z^2)", "-1/sqrt(r^2 + z^2)");
  is_str("sin(theta)^2", "sin(theta)^2");
  is_str("x - (y - z)", "x - y + z");
  is_str("(x + y)*(x - y)", "(x + y)*(x - y)");
  is_str("a/(b*c)", "a/(b*c)");
  is_str("-x^2", "-x^2");
  is_str("(-x)^3", "-x^3");
  is_str("(-x)^2", "x^2");
  is_str("x*(-y)", "-x*y");
  is_str("x + -y", "x - y");
  is_str("x - -y", "x + y");
  is_str("2*x + 3*x", "5*x");
  is_str("x*y - y*x", "0");
  is_str("0.1 + 0.2", "0.30000000000000004");
  is_str("1/3", "0.3333333333333333");
  is_str("2.385*x", "2.385*x");
  is_str("1e-20*x", "1e-20*x");
  is_str("x^-1", "1/x");
  is_str("x^0.5", "sqrt(x)");
  is_str("(x^2)^3", "x^6");
  is_str("x*x*x", "x^3");
  is_str("select(x < 0, -x, x)", "select(x < 0, -x, x)");
  is_str("atan2(y, x)", "atan2(y, x)");
  is_str("(-x)^y", "(-x)^y");
  is_str("(x^y)^z", "(x^y)^z");
  is_str("x^y^z", "x^y^z");
  is_str("2^-3 + x", "x + 0.125");
  is_str("x - 3 + 3", "x");
  /* normal forms: flattened sums and products, like terms and factors */
  is_str("m2*cos(phi)*r1*r2 + (m2 + m1)*r1^2 + m2*cos(phi)*r1*r2 + m2*r2^2",
         "2*m2*cos(phi)*r1*r2 + (m2 + m1)*r1^2 + m2*r2^2");
  is_str("x + y + x", "2*x + y");
  is_str("x + 1 + y + 2", "x + y + 3");
  is_str("x*2*y*3", "6*x*y");
  is_str("x*y*x", "x^2*y");
  is_str("x^2*y/x", "x*y");
  is_str("x*y/(y*x)", "1");
  is_str("0.5*a + 0.5*b", "0.5*(a + b)");
  is_str("2*(a + b) - 2*a", "2*b");
  is_str("-(x - y)", "y - x");
  is_str("-x - y", "-(x + y)");
  is_str("3 - x - y", "3 - x - y");
  is_str("x/3/3", "x/9");
  is_str("6*x/3", "2*x");
  is_str("x/y/z^2*y", "x/z^2");
  is_str("(x*y)^2*x", "x^3*y^2");
  is_dstr("0.5*(r^2 + z^2)", "r", "r");
  is_dstr("sin(theta)^2", "theta", "2*sin(theta)*cos(theta)");
  is_dstr("x^3", "x", "3*x^2");
  is_dstr("exp(2*x)", "x", "2*exp(2*x)");
  is_dstr("log(x)", "x", "1/x");
  is_dstr("sqrt(x)", "x", "0.5/sqrt(x)");
  is_dstr("cos(x)", "x", "-sin(x)");
  is_dstr("cos(2*x)", "x", "-2*sin(2*x)");
  is_dstr("atan(x)", "x", "1/(x^2 + 1)");
  is_dstr("abs(x)", "x", "sign(x)");
  is_dstr("select(x < 1, x^2, 2*x)", "x", "select(x < 1, 2*x, 2)");
  is_dstr("x*y", "y", "x");
  is_dstr("1/x", "x", "-1/x^2");
  dm_expr_ctx_free(C);
  C = saved;
}

/* Hash-consing, canonical order and the safe identities. */
static void test_identities(void)
{
  dm_expr x = V[0], y = V[1];
#define SAME(a, b, what) tap_ok(tx_parse(C, a) == tx_parse(C, b), "%s: %s is %s", what, a, b)
  SAME("x*y + sin(x)", "x*y + sin(x)", "hash-consing");
  SAME("x*y", "y*x", "canonical product");
  SAME("x + y", "y + x", "canonical sum");
  SAME("x + 0", "x", "x+0");
  SAME("1*x", "x", "x*1");
  SAME("0*sin(x)", "0", "x*0");
  SAME("x - x", "0", "x-x");
  SAME("-(-x)", "x", "-(-x)");
  SAME("(x^2)^3", "x^6", "integer powers of powers");
  SAME("x^2*x^3", "x^5", "product of powers");
  SAME("2*(3*x)", "6*x", "constant factors merge");
  SAME("x + y + z", "z + (y + x)", "order and grouping of sums");
  SAME("(x*y)*z", "x*(z*y)", "order and grouping of products");
  SAME("x*y + y*z", "z*y + x*y", "sums of products in any order");
  SAME("x*x/x", "x", "x*x/x");
  SAME("(x + y)*(y + x)", "(x + y)^2", "equal sums are one base");
  SAME("x - x", "0", "t - t (NaN at x = Inf: the accepted policy)");
  SAME("sin(x)/sin(x)", "1", "t/t (NaN at sin(x) = 0: the same policy)");
#undef SAME
  tap_ok(tx_parse(C, "(x^0.5)^2") != x, "(x^0.5)^2 is not simplified to x (NaN for x<0)");
  dm_expr d1 = dm_expr_diff(C, tx_parse(C, "sin(x*y)*exp(x)"), x);
  size_t n1 = dm_expr_ctx_size(C);
  dm_expr d2 = dm_expr_diff(C, tx_parse(C, "sin(x*y)*exp(x)"), x);
  tap_ok(d1 == d2 && dm_expr_ctx_size(C) == n1, "derivatives are memoised (no new nodes)");
  dm_expr dir[2] = { dm_expr_const(C, 2.385), dm_expr_const(C, -0.75) };
  dm_expr e = tx_parse(C, "x^2*y + cos(y)");
  dm_expr dd = dm_expr_dirderiv(C, e, 2, V, dir);
  double want = 2.385 * ev(dm_expr_diff(C, e, x)) - 0.75 * ev(dm_expr_diff(C, e, y));
  tap_near(ev(dd), want, 1e-14, "directional derivative = grad . dir");
  double c;
  tap_ok(dm_expr_is_const(C, tx_parse(C, "cos(0)*3 + 2^2"), &c) && c == 7,
         "constant folding of cos(0)*3 + 2^2 = 7");
}

/* subs then eval equals eval at the substituted values. */
static void test_subs(void)
{
  double worst = 0;
  dm_expr from[2] = { V[0], V[2] };
  dm_expr to[2] = { tx_parse(C, "y^2 + 1.25"), tx_parse(C, "sin(p)") };
  double xv = vals[1] * vals[1] + 1.25, zv = sin(vals[3]);
  for (size_t i = 0; i < NEXPR; i++) {
    dm_expr e = tx_parse(C, exprs[i]), s;
    if (strstr(exprs[i], "asin") || strstr(exprs[i], "acos") || strstr(exprs[i], "sqrt(1 - x^2)"))
      continue;                                /* x > 1 is outside */
    dm_expr_subs(C, 1, &e, &s, 2, from, to, NULL);
    double v2[NV];
    memcpy(v2, vals, sizeof v2);
    v2[0] = xv;
    v2[2] = zv;
    double want = NAN, got = ev(s);
    dm_expr_eval(C, 1, &e, &want, NV, V, v2, NULL);
    worst = fmax(worst, relerr(got, want));
    if (!(relerr(got, want) < 1e-13))
      tap_diag("subs mismatch in %s: %.17g vs %.17g", exprs[i], got, want);
  }
  tap_ok(worst < 1e-13, "subs + eval = eval at substituted values (max rel err %.2g)", worst);
  dm_expr e = tx_parse(C, "x*y + x"), s;
  dm_expr f1 = V[0], t1 = dm_expr_const(C, 2);
  dm_expr_subs(C, 1, &e, &s, 1, &f1, &t1, NULL);
  tap_ok(strcmp(str(s), "2*y + 2") == 0, "subs x=2 in x*y + x gives 2*y + 2 (%s)", str(s));
}

static void test_errors(void)
{
  dm_expr x = V[0], args[3] = { x, x, x };
  dm_err err;
  dm_expr_ctx_clear_err(C);
  tap_ok(dm_expr_call(C, "foo", 1, args) == DM_EXPR_NONE &&
         dm_expr_ctx_err(C)->status == DM_ENOTFOUND &&
         strstr(dm_expr_ctx_err(C)->msg, "unknown function 'foo'"),
         "unknown function: %s", dm_expr_ctx_err(C)->msg);
  dm_expr_ctx_clear_err(C);
  tap_ok(dm_expr_call(C, "atan2", 1, args) == DM_EXPR_NONE &&
         dm_expr_ctx_err(C)->status == DM_EINVAL &&
         strstr(dm_expr_ctx_err(C)->msg, "atan2 expects 2 arguments, got 1"),
         "wrong arity: %s", dm_expr_ctx_err(C)->msg);
  dm_expr_ctx_clear_err(C);
  tap_ok(dm_expr_unary(C, DM_EXPR_ADD, x) == DM_EXPR_NONE &&
         dm_expr_ctx_err(C)->status == DM_EINVAL, "unary builder refuses add");
  dm_expr_ctx_clear_err(C);
  dm_expr chain = dm_expr_add(C, DM_EXPR_NONE, x);
  tap_ok(chain == DM_EXPR_NONE, "DM_EXPR_NONE propagates through builders");
  tap_ok(dm_expr_add(C, x, 123456789) == DM_EXPR_NONE &&
         dm_expr_ctx_err(C)->status == DM_EINVAL, "invalid handle refused");
  dm_expr_ctx_clear_err(C);
  tap_ok(dm_expr_diff(C, x, tx_parse(C, "x*y")) == DM_EXPR_NONE &&
         strstr(dm_expr_ctx_err(C)->msg, "symbol or parameter") != NULL,
         "diff with respect to a product is refused: %s", dm_expr_ctx_err(C)->msg);
  dm_expr_ctx_clear_err(C);
  tap_ok(dm_expr_sym(C, "") == DM_EXPR_NONE, "empty name refused");
  dm_expr_ctx_clear_err(C);
  dm_expr e = tx_parse(C, "x + w"), w = dm_expr_sym(C, "w");
  double r;
  int st = dm_expr_eval(C, 1, &e, &r, NV, V, vals, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "symbol 'w'"), "eval with an unbound symbol: %s", err.msg);
  st = dm_expr_eval(C, 1, &e, &r, 1, &w, vals, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "symbol 'x'"), "eval names the first unbound symbol: %s", err.msg);
  dm_expr sq = tx_parse(C, "sqrt(x) + log(y)");
  double neg[NV] = { -2.385, 0.5, 1, 1, 1 };
  st = dm_expr_eval(C, 1, &sq, &r, NV, V, neg, &err);
  tap_ok(st == DM_OK && isnan(r), "NaN propagates through eval (sqrt(-2.385))");
  dm_expr dsq = dm_expr_diff(C, sq, x);
  st = dm_expr_eval(C, 1, &dsq, &r, NV, V, neg, &err);
  tap_ok(st == DM_OK && isnan(r), "and through its derivative");
  int ar;
  tap_ok(dm_expr_func_lookup("select", &ar) == DM_EXPR_SELECT && ar == 3, "select has 3 arguments");
  tap_ok(dm_expr_func_lookup("powi", &ar) < 0, "powi is internal");
}

/* A sum of 200000 terms built one at a time: like terms collapse to 7;
 * distinct ones make a chain 200000 deep (collection stops at 256 terms,
 * so building stays linear), no recursion overflow. */
static void test_deep(void)
{
  dm_expr x = V[0], s = dm_expr_const(C, 0);
  const int N = 200000;
  double coef[8] = { 0 };
  for (int i = 1; i <= N; i++) {
    s = dm_expr_add(C, s, dm_expr_mul(C, dm_expr_const(C, (double)i), dm_expr_powi(C, x, i % 7 + 1)));
    coef[i % 7 + 1] += i;
  }
  char want_s[512], *p = want_s;
  for (int k = 2; k <= 8; k++)                  /* first seen: x^2 .. x^7, x */
    p += sprintf(p, "%s%.0f*x%s", k > 2 ? " + " : "", coef[k % 8 ? k : 1],
                 k == 8 ? "" : (char[]){ '^', (char)('0' + k), 0 });
  tap_ok(strcmp(str(s), want_s) == 0, "200000 like terms collected: %s", str(s));
  dm_expr d = dm_expr_diff(C, s, x);
  double xv = 0.5, got, want = 0;
  for (int i = 1; i <= N; i++) {
    int n = i % 7 + 1;
    want += (double)i * n * pow(xv, n - 1);
  }
  dm_expr_eval(C, 1, &d, &got, 1, &x, &xv, NULL);
  tap_near(got, want, 1e-12, "derivative of the collected sum");
  dm_expr s2 = dm_expr_const(C, 0);
  for (int i = 1; i <= N; i++)
    s2 = dm_expr_add(C, s2, dm_expr_unary(C, DM_EXPR_SIN,
                     dm_expr_add(C, x, dm_expr_const(C, 1e-3 * i))));
  dm_expr d2 = dm_expr_diff(C, s2, x);
  want = 0;
  for (int i = 1; i <= N; i++)
    want += cos(xv + 1e-3 * i);
  dm_expr_eval(C, 1, &d2, &got, 1, &x, &xv, NULL);
  tap_ok(fabs(got - want) <= 1e-10 * N, "derivative of a sum of 200000 distinct "
         "terms (%.17g vs %.17g)", got, want);
  char *str200 = dm_expr_to_string(C, s2, 200, NULL);
  tap_ok(str200 && strlen(str200) == 203 && strcmp(str200 + 200, "...") == 0,
         "printing is cut at max_len with ...");
  free(str200);
}

int main(void)
{
  C = dm_expr_ctx_alloc();
  const char *names[NV] = { "x", "y", "z", "p", "k" };
  for (int i = 0; i < NV; i++)
    V[i] = names[i][0] == 'p' || names[i][0] == 'k' ? dm_expr_param(C, names[i])
                                                    : dm_expr_sym(C, names[i]);
  test_gradients();
  test_hessians();
  test_sparse_derivs();
  test_print_roundtrip();
  test_printed_forms();
  test_identities();
  test_subs();
  test_errors();
  test_deep();
  tap_diag("context holds %zu nodes", dm_expr_ctx_size(C));
  dm_expr_ctx_free(C);
  return tap_done();
}
