/* test_expr_util.c -- helpers shared by the expression-engine tests: a
 * small infix parser (Lua precedence) building dm_expr nodes, and a
 * complex-step evaluator over the DAG for exact-to-round-off reference
 * derivatives.  Names starting with 'p' or 'k' are parameters, other names
 * symbols. */
#include <config.h>
#include <complex.h>
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "expr/expr.h"

dm_expr tx_parse(dm_expr_ctx *ctx, const char *s);
int tx_cstep(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
             const double *vals, size_t k, double *deriv);

/* Expressions in x, y, z (symbols) and p, k (parameters) whose derivatives
 * the tests check; valid at x=0.3817, y=0.5293, z=1.2385, p=1.385, k=0.7125
 * and nearby. */
const char *const tx_exprs[] = {
  "x^2*y + sin(x*y)", "exp(-x^2)*cos(3*y)", "log(1 + x^2 + y^2)",
  "sqrt(x^2 + y^2 + z^2)",
  "-1/sqrt(x^2 + z^2) + p/(x^2 + z^2)^1.5*(1.5*z^2/(x^2 + z^2) - 0.5)",
  "tan(x)*y", "asin(x*y)", "acos(x/2)", "atan(x/y)", "atan2(y, x)",
  "atan2(-y, -x)", "sinh(x)*cosh(y)", "tanh(x - y)", "abs(x - y)",
  "abs(sin(3*x))", "x^y", "p^x", "x^2.5", "x^-3", "(x + y)^7",
  "1/(1 + exp(-p*x))", "select(x < y, x^2, y^3)",
  "select(x > 0.1, sin(x), cos(x))", "x*y*z*p", "(x - y)/(x + y)", "x/y/z",
  "exp(sin(x))*log(y)", "sqrt(1 - x^2)", "cos(x)^2 + sin(x)^2",
  "0.5*(x^2 + y^2*z^2)", "x^3 - 3*x*y^2", "exp(x)*exp(-x)", "log(exp(x*y))",
  "sin(x)/x", "1/(x^2 + y^2)^2", "(x^2 + y^2)^-0.5", "sqrt(sqrt(x + y))",
  "x*exp(-p*y)*cos(k*z)", "atan(tan(x))", "cosh(x)^2 - sinh(x)^2",
  "-x*(y - z)", "x - (y - (z - p))", "p*x^2/2 - k*cos(y)",
  "sin(x + y + z)^3", "log(abs(x - 2))", "exp(x^2*y)/(1 + z)",
  "y*atan2(z, x + y)", "sqrt(x)*sqrt(y)*sqrt(z)", "(1 + x)^(1 + y)",
  "tanh(p*x)^2", "asin(sin(x))", "acos(cos(y))",
  "x^4 - 2*x^2*y^2 + y^4", "1 - x^2/2 + x^4/24 - x^6/720",
  "select(x*y >= 0.15, x*y, 0.15)", "-(x^2 + 2*x*y + y^2)",
  "sin(2*pi*x)*cos(2*pi*y)", "exp(-(x - p)^2/(2*k^2))",
  "x/(1 + x/(1 + x/(1 + y)))", "sinh(x)^2/cosh(x)", "log(x)*log(y)*log(z)",
  "z^(x*y)", "select(x ~= y, (x^2 - y^2)/(x - y), 2*x)",
  "x*y/(x*y + z)", "(x*y)^3/(x*y)^2", "p^2*k*x - k*p^2*x + y",
};
const size_t tx_nexprs = sizeof tx_exprs / sizeof tx_exprs[0];

/* The double spherical pendulum (doc/reduce.md §14) in cylindrical
 * coordinates q = (r1, th1, r2, th2), velocities (vr1, vth1, vr2, vth2),
 * parameters (pm1, pm2, pl1, pl2, pg): Cartesian velocities of the bobs
 * written out, z_i = -sqrt(l_i^2 - r_i^2). */
const char tx_dsp_lagrangian[] =
  "0.5*pm1*((vr1*cos(th1) - r1*sin(th1)*vth1)^2"
  " + (vr1*sin(th1) + r1*cos(th1)*vth1)^2"
  " + (r1*vr1/sqrt(pl1^2 - r1^2))^2)"
  " + 0.5*pm2*((vr1*cos(th1) - r1*sin(th1)*vth1 + vr2*cos(th2) - r2*sin(th2)*vth2)^2"
  " + (vr1*sin(th1) + r1*cos(th1)*vth1 + vr2*sin(th2) + r2*cos(th2)*vth2)^2"
  " + (r1*vr1/sqrt(pl1^2 - r1^2) + r2*vr2/sqrt(pl2^2 - r2^2))^2)"
  " + pm1*pg*sqrt(pl1^2 - r1^2) + pm2*pg*(sqrt(pl1^2 - r1^2) + sqrt(pl2^2 - r2^2))";
const char *const tx_dsp_q[4] = { "r1", "th1", "r2", "th2" };
const char *const tx_dsp_v[4] = { "vr1", "vth1", "vr2", "vth2" };
const char *const tx_dsp_par[5] = { "pm1", "pm2", "pl1", "pl2", "pg" };

/* The J2 satellite (doc/reduce.md §13), Cartesian: q = (x, y, z),
 * v = (vx, vy, vz), parameter pJ2; L = |v|^2/2 - V with
 * V = -1/R + J2/R^3 (1.5 z^2/R^2 - 0.5). */
const char tx_j2_lagrangian[] =
  "0.5*(vx^2 + vy^2 + vz^2) + 1/sqrt(x^2 + y^2 + z^2)"
  " - pJ2/sqrt(x^2 + y^2 + z^2)^3*(1.5*z^2/(x^2 + y^2 + z^2) - 0.5)";

typedef struct P {
  dm_expr_ctx *ctx;
  const char *s;
  int bad;
} P;

static void ws(P *p) { while (isspace((unsigned char)*p->s)) p->s++; }
static int eat(P *p, const char *t)
{
  ws(p);
  size_t k = strlen(t);
  if (strncmp(p->s, t, k) != 0)
    return 0;
  /* do not take "<" from "<=" */
  if (k == 1 && (t[0] == '<' || t[0] == '>') && p->s[1] == '=')
    return 0;
  p->s += k;
  return 1;
}

static dm_expr parse_expr(P *p);
static dm_expr parse_unary(P *p);

static dm_expr parse_atom(P *p)
{
  ws(p);
  if (eat(p, "(")) {
    dm_expr e = parse_expr(p);
    if (!eat(p, ")")) p->bad = 1;
    return e;
  }
  if (isdigit((unsigned char)*p->s) || *p->s == '.') {
    char *end;
    double v = strtod(p->s, &end);
    p->s = end;
    return dm_expr_const(p->ctx, v);
  }
  if (isalpha((unsigned char)*p->s) || *p->s == '_') {
    char name[64];
    size_t k = 0;
    while ((isalnum((unsigned char)*p->s) || *p->s == '_') && k < 63)
      name[k++] = *p->s++;
    name[k] = '\0';
    if (eat(p, "(")) {
      dm_expr args[4];
      int n = 0;
      if (!eat(p, ")")) {
        do {
          if (n < 4) args[n++] = parse_expr(p);
        } while (eat(p, ","));
        if (!eat(p, ")")) p->bad = 1;
      }
      return dm_expr_call(p->ctx, name, n, args);
    }
    if (strcmp(name, "pi") == 0)
      return dm_expr_const(p->ctx, M_PI);
    if (name[0] == 'p' || name[0] == 'k')
      return dm_expr_param(p->ctx, name);
    return dm_expr_sym(p->ctx, name);
  }
  p->bad = 1;
  return DM_EXPR_NONE;
}

static dm_expr parse_pow(P *p)
{
  dm_expr a = parse_atom(p);
  if (eat(p, "^"))
    return dm_expr_pow(p->ctx, a, parse_unary(p));   /* right assoc */
  return a;
}

static dm_expr parse_unary(P *p)
{
  if (eat(p, "-"))
    return dm_expr_neg(p->ctx, parse_unary(p));
  return parse_pow(p);
}

static dm_expr parse_mul(P *p)
{
  dm_expr a = parse_unary(p);
  for (;;) {
    if (eat(p, "*")) a = dm_expr_mul(p->ctx, a, parse_unary(p));
    else if (eat(p, "/")) a = dm_expr_div(p->ctx, a, parse_unary(p));
    else return a;
  }
}

static dm_expr parse_add(P *p)
{
  dm_expr a = parse_mul(p);
  for (;;) {
    if (eat(p, "+")) a = dm_expr_add(p->ctx, a, parse_mul(p));
    else if (eat(p, "-")) a = dm_expr_sub(p->ctx, a, parse_mul(p));
    else return a;
  }
}

static dm_expr parse_expr(P *p)
{
  static const struct { const char *tok; int op; } cmp[] = {
    { "<=", DM_EXPR_LE }, { ">=", DM_EXPR_GE }, { "==", DM_EXPR_EQ },
    { "~=", DM_EXPR_NE }, { "<", DM_EXPR_LT }, { ">", DM_EXPR_GT }
  };
  dm_expr a = parse_add(p);
  for (size_t i = 0; i < sizeof cmp / sizeof cmp[0]; i++)
    if (eat(p, cmp[i].tok))
      return dm_expr_binary(p->ctx, cmp[i].op, a, parse_add(p));
  return a;
}

/* The expression of s, or DM_EXPR_NONE on a syntax error. */
dm_expr tx_parse(dm_expr_ctx *ctx, const char *s)
{
  P p = { ctx, s, 0 };
  dm_expr e = parse_expr(&p);
  ws(&p);
  if (p.bad || *p.s != '\0')
    return DM_EXPR_NONE;
  return e;
}

/* {==================================================================
 * complex step
 * =================================================================== */

typedef double complex cplx;

static cplx csign_abs(cplx z) { return creal(z) < 0 ? -z : z; }

static cplx cval(dm_expr_ctx *ctx, dm_expr e, cplx *memo, char *done,
                 size_t n, const dm_expr *vars, const cplx *x, int *bad)
{
  if (done[e])
    return memo[e];
  int op = dm_expr_kind(ctx, e), na = dm_expr_nargs(ctx, e);
  cplx a = 0, b = 0, c = 0, r = 0;
  if (na >= 1) a = cval(ctx, dm_expr_arg(ctx, e, 0), memo, done, n, vars, x, bad);
  if (na >= 2) b = cval(ctx, dm_expr_arg(ctx, e, 1), memo, done, n, vars, x, bad);
  if (na >= 3) c = cval(ctx, dm_expr_arg(ctx, e, 2), memo, done, n, vars, x, bad);
  double v;
  switch (op) {
  case DM_EXPR_CONST: dm_expr_is_const(ctx, e, &v); r = v; break;
  case DM_EXPR_SYM: case DM_EXPR_PARAM:
    *bad = 1;
    for (size_t k = 0; k < n; k++)
      if (vars[k] == e) { r = x[k]; *bad = 0; }
    break;
  case DM_EXPR_ADD: r = a + b; break;
  case DM_EXPR_SUB: r = a - b; break;
  case DM_EXPR_MUL: r = a * b; break;
  case DM_EXPR_DIV: r = a / b; break;
  case DM_EXPR_POW: r = cpow(a, b); break;
  case DM_EXPR_POWI: {
    int m = dm_expr_powi_exponent(ctx, e);
    r = 1;
    for (int i = 0; i < abs(m); i++) r *= a;
    if (m < 0) r = 1 / r;
    break;
  }
  case DM_EXPR_ATAN2: {
    r = catan(a / b);
    if (creal(b) < 0) r += creal(a) >= 0 ? M_PI : -M_PI;
    break;
  }
  case DM_EXPR_LT: r = creal(a) < creal(b); break;
  case DM_EXPR_LE: r = creal(a) <= creal(b); break;
  case DM_EXPR_GT: r = creal(a) > creal(b); break;
  case DM_EXPR_GE: r = creal(a) >= creal(b); break;
  case DM_EXPR_EQ: r = creal(a) == creal(b); break;
  case DM_EXPR_NE: r = creal(a) != creal(b); break;
  case DM_EXPR_NEG: r = -a; break;
  case DM_EXPR_SQRT: r = csqrt(a); break;
  case DM_EXPR_EXP: r = cexp(a); break;
  case DM_EXPR_LOG: r = clog(a); break;
  case DM_EXPR_SIN: r = csin(a); break;
  case DM_EXPR_COS: r = ccos(a); break;
  case DM_EXPR_TAN: r = ctan(a); break;
  case DM_EXPR_ASIN: r = casin(a); break;
  case DM_EXPR_ACOS: r = cacos(a); break;
  case DM_EXPR_ATAN: r = catan(a); break;
  case DM_EXPR_SINH: r = csinh(a); break;
  case DM_EXPR_COSH: r = ccosh(a); break;
  case DM_EXPR_TANH: r = ctanh(a); break;
  case DM_EXPR_ABS: r = csign_abs(a); break;
  case DM_EXPR_SIGN: r = creal(a) > 0 ? 1 : creal(a) < 0 ? -1 : 0; break;
  case DM_EXPR_SELECT: r = creal(a) != 0 ? b : c; break;
  default: *bad = 1;
  }
  done[e] = 1;
  memo[e] = r;
  return r;
}

/* d e / d vars[k] at vals by the complex step (h = 1e-30): exact to
 * round-off for analytic expressions.  Returns 0 on success. */
int tx_cstep(dm_expr_ctx *ctx, dm_expr e, size_t n, const dm_expr *vars,
             const double *vals, size_t k, double *deriv)
{
  size_t sz = dm_expr_ctx_size(ctx);
  cplx *memo = malloc(sz * sizeof *memo), *x = malloc(n * sizeof *x);
  char *done = calloc(sz, 1);
  int bad = 0;
  const double h = 1e-30;
  for (size_t i = 0; i < n; i++)
    x[i] = vals[i] + (i == k ? h * I : 0);
  cplx r = cval(ctx, e, memo, done, n, vars, x, &bad);
  *deriv = cimag(r) / h;
  free(memo);
  free(x);
  free(done);
  return bad;
}
