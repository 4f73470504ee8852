/* test_tape.c -- compiled tapes: agreement with the DAG evaluator, batch
 * evaluation, parameters changed after compiling, register reuse, CSE on
 * the double spherical pendulum, error paths, NaN propagation. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "expr/expr.h"
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

static double urand(unsigned *s)
{
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffffff) / 16777216.0;
}

static double relerr(double got, double want)
{
  if (got == want || (isnan(got) && isnan(want)))
    return 0;
  return fabs(got - want) / fmax(1.0, fabs(want));
}

/* One tape for value + gradient + Hessian of every test expression. */
static void test_against_eval(void)
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
  dm_err err;
  int st = dm_tape_compile(C, nout, out, 3, V, 2, V + 3, &t, &err);
  tap_ok(st == DM_OK, "compile %zu outputs (value, gradient, Hessian of %zu "
         "expressions)", nout, tx_nexprs);
  tap_diag("%zu instructions, %zu registers, %zu constants", dm_tape_ninstr(t),
           dm_tape_nregs(t), dm_tape_nconst(t));
  double *w = malloc(dm_tape_work_size(t) * sizeof *w);
  double *y = malloc(nout * sizeof *y), *ref = malloc(nout * sizeof *ref);
  double worst = 0;
  unsigned seed = 42;
  for (int rep = 0; rep < 20; rep++) {
    double x[NV];
    for (int k = 0; k < NV; k++)
      x[k] = base[k] * (0.9 + 0.2 * urand(&seed));
    dm_tape_eval(t, x, x + 3, y, w);
    dm_expr_eval(C, nout, out, ref, NV, V, x, NULL);
    for (size_t k = 0; k < nout; k++)
      worst = fmax(worst, relerr(y[k], ref[k]));
  }
  tap_ok(worst < 1e-12, "tape = DAG evaluation to round-off at 20 random "
         "points (max rel diff %.2g: the tape computes factored sums, shared "
         "reciprocals; d2/dx2 of (x^2 - y^2)/(x - y) cancels terms ~300)", worst);

  /* batch over 77 points (not a multiple of the block) = single evals */
  enum { NP = 77 };
  double *pin = malloc(NP * 3 * sizeof *pin), *pout = malloc(NP * nout * sizeof *pout);
  double *bw = malloc(dm_tape_batch_work_size(t) * sizeof *bw);
  double par[2] = { base[3], base[4] };
  for (int j = 0; j < NP * 3; j++)
    pin[j] = base[j % 3] * (0.9 + 0.2 * urand(&seed));
  dm_tape_eval_batch(t, NP, pin, 3, par, pout, nout, bw);
  double bworst = 0;
  for (int j = 0; j < NP; j++) {
    dm_tape_eval(t, pin + 3 * j, par, y, w);
    for (size_t k = 0; k < nout; k++)
      bworst = fmax(bworst, relerr(pout[j * nout + k], y[k]));
  }
  tap_ok(bworst == 0, "batch evaluation of 77 points = single evaluations");
  free(pin); free(pout); free(bw);
  free(w); free(y); free(ref); free(out);
  dm_tape_free(t);
}

static void test_params_and_sharing(void)
{
  dm_expr e = tx_parse(C, "p*sin(x)^2 + k*cos(x)^2 + sin(x)*cos(x)*p*k");
  dm_expr d = dm_expr_diff(C, e, V[0]);
  dm_expr outs[2] = { e, d };
  dm_tape *t;
  dm_tape_compile(C, 2, outs, 1, V, 2, V + 3, &t, NULL);
  double w[64], y[2], x = 0.7, par[2] = { 2.385, -0.75 };
  dm_tape_eval(t, &x, par, y, w);
  double s = sin(x), c = cos(x);
  tap_near(y[0], 2.385 * s * s - 0.75 * c * c + s * c * 2.385 * -0.75, 1e-15,
           "value with p = 2.385, k = -0.75");
  par[0] = 1.5;
  par[1] = 4.25;
  dm_tape_eval(t, &x, par, y, w);
  tap_near(y[0], 1.5 * s * s + 4.25 * c * c + s * c * 1.5 * 4.25, 1e-15,
           "parameters changed after compiling (p = 1.5, k = 4.25)");
  tap_near(y[1], 2 * 1.5 * s * c - 2 * 4.25 * c * s + (c * c - s * s) * 1.5 * 4.25,
           1e-14, "derivative follows the new parameters");
  size_t cnt[DM_T_NOPS];
  dm_tape_op_counts(t, cnt);
  tap_ok(cnt[DM_T_SINCOS] == 1 && cnt[DM_T_SIN] + cnt[DM_T_COS] == 0,
         "sin(x) and cos(x) computed once, together (sincos)");
  tap_ok(dm_tape_nregs(t) <= 64, "fits the work buffer");
  dm_tape_free(t);

  /* a long chain reuses registers: sum of x^i/i for i = 1..200 (factored
   * into Horner's rule: one fused multiply-add per term) */
  dm_expr sum = dm_expr_const(C, 0);
  for (int i = 1; i <= 200; i++)
    sum = dm_expr_add(C, sum, dm_expr_div(C, dm_expr_powi(C, V[0], i), dm_expr_const(C, i)));
  dm_tape_compile(C, 1, &sum, 1, V, 0, NULL, &t, NULL);
  size_t tmp = dm_tape_nregs(t) - 1 - dm_tape_nconst(t);
  tap_ok(dm_tape_ninstr(t) >= 200 && tmp <= 6, "liveness: %zu instructions use "
         "%zu temporaries", dm_tape_ninstr(t), tmp);
  double val, ws[1024], want = 0;
  x = 0.5;
  dm_tape_eval(t, &x, NULL, &val, ws);
  for (int i = 1; i <= 200; i++)
    want += pow(0.5, i) / i;
  tap_near(val, want, 1e-15, "sum x^i/i at 0.5 = log 2");
  dm_tape_free(t);
}

/* Double spherical pendulum: L, its gradient and full Hessian in (q, v). */
static void test_dsp_size(void)
{
  dm_expr L = tx_parse(C, tx_dsp_lagrangian), vars[8], par[5];
  for (int i = 0; i < 4; i++) {
    vars[i] = dm_expr_sym(C, tx_dsp_q[i]);
    vars[4 + i] = dm_expr_sym(C, tx_dsp_v[i]);
  }
  for (int i = 0; i < 5; i++)
    par[i] = dm_expr_param(C, tx_dsp_par[i]);
  dm_expr out[1 + 8 + 64];
  out[0] = L;
  dm_expr_grad(C, L, 8, vars, out + 1, NULL);
  dm_expr_hessian(C, L, 8, vars, out + 9, NULL);
  dm_tape *t;
  int st = dm_tape_compile(C, 73, out, 8, vars, 5, par, &t, NULL);
  tap_ok(st == DM_OK, "double spherical pendulum: L + gradient + Hessian compiled");
  size_t cnt[DM_T_NOPS];
  dm_tape_op_counts(t, cnt);
  tap_diag("double spherical pendulum L+grad+Hessian: %zu instructions "
           "(%zu sincos, %zu sqrt, %zu div, %zu recip), %zu registers, %zu constants",
           dm_tape_ninstr(t), cnt[DM_T_SINCOS], cnt[DM_T_SQRT], cnt[DM_T_DIV],
           cnt[DM_T_RECIP], dm_tape_nregs(t), dm_tape_nconst(t));
  tap_ok(cnt[DM_T_SINCOS] == 2 && cnt[DM_T_SIN] + cnt[DM_T_COS] == 0 &&
         cnt[DM_T_SQRT] == 2 && cnt[DM_T_DIV] == 0 && cnt[DM_T_RECIP] <= 2,
         "CSE: each sin/cos pair and sqrt computed once; divisions share reciprocals");
  size_t separate = 0;
  for (int k = 0; k < 73; k++) {
    dm_tape *t1;
    dm_tape_compile(C, 1, out + k, 8, vars, 5, par, &t1, NULL);
    separate += dm_tape_ninstr(t1);
    dm_tape_free(t1);
  }
  tap_diag("the 73 outputs compiled one by one: %zu instructions in all", separate);
  tap_ok(dm_tape_ninstr(t) <= 306 && 3 * dm_tape_ninstr(t) < separate,
         "CSE keeps the tape small (%zu <= 306 instructions, < 1/3 of the "
         "outputs compiled separately)", dm_tape_ninstr(t));
  dm_tape_free(t);
}

/* Output slots: outputs laid out as a caller's arrays, an output in two
 * slots, a constant and an input among them; the same values as eval. */
static void test_slots(void)
{
  dm_expr outs[4] = { tx_parse(C, "x*y + sin(x)"), dm_expr_const(C, 2.5), V[1],
                      tx_parse(C, "x^2*p") };
  const uint32_t slot_out[6] = { 3, 0, 1, 0, 2, 3 };
  dm_tape *t;
  dm_err err;
  int st = dm_tape_compile_slots(C, 4, outs, 2, V, 1, V + 3, 6, slot_out, &t, &err);
  double in[2] = { 0.6831, -1.2385 }, par = 0.7125, y[4], w[64];
  dm_tape_eval(t, in, &par, y, w);
  const double *v = w + dm_tape_slot_base(t);
  int ok = st == DM_OK && dm_tape_work_size(t) <= 64;
  for (int sl = 0; ok && sl < 6; sl++)
    ok = v[sl] == y[slot_out[sl]];
  tap_ok(ok && y[0] == in[0] * in[1] + sin(in[0]) && y[1] == 2.5 && y[2] == in[1],
         "slots: each holds its output after a run (%zu instructions)",
         dm_tape_ninstr(t));
  dm_tape_free(t);
  const uint32_t bad_slot[1] = { 4 };
  st = dm_tape_compile_slots(C, 4, outs, 2, V, 1, V + 3, 1, bad_slot, &t, &err);
  tap_ok(st == DM_EINVAL && t == NULL && strstr(err.msg, "slot 1"),
         "a slot naming no output is refused: %s", err.msg);
}

static void test_errors(void)
{
  dm_err err;
  dm_tape *t = (dm_tape *)&err;
  dm_expr e = tx_parse(C, "x*y + p");
  int st = dm_tape_compile(C, 1, &e, 1, V, 1, V + 3, &t, &err);
  tap_ok(st == DM_EINVAL && t == NULL && strstr(err.msg, "symbol 'y'"),
         "unbound symbol: %s", err.msg);
  dm_expr dup[2] = { V[0], V[0] };
  st = dm_tape_compile(C, 1, &e, 2, dup, 0, NULL, &t, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "'x' is listed twice"), "duplicate input: %s", err.msg);
  dm_expr notsym = tx_parse(C, "x + 1");
  st = dm_tape_compile(C, 1, &e, 1, &notsym, 0, NULL, &t, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "input 1 is not a symbol"), "input not a symbol: %s", err.msg);
  dm_expr badout = 99999999;
  st = dm_tape_compile(C, 1, &badout, 1, V, 0, NULL, &t, &err);
  tap_ok(st == DM_EINVAL && strstr(err.msg, "output 1"), "invalid output: %s", err.msg);

  /* NaN propagation: only the outputs that depend on sqrt(-x) are NaN */
  dm_expr outs[3] = { tx_parse(C, "sqrt(x) + y"), tx_parse(C, "x*y"),
                      tx_parse(C, "select(x < 0, 0, log(x))") };
  st = dm_tape_compile(C, 3, outs, 2, V, 0, NULL, &t, &err);
  double w[32], y[3], in[2] = { -2.385, 0.5 };
  dm_tape_eval(t, in, NULL, y, w);
  tap_ok(st == DM_OK && isnan(y[0]) && y[1] == -2.385 * 0.5 && y[2] == 0,
         "NaN propagates to the dependent output only; select guards log");
  dm_tape_free(t);
  dm_expr k7 = dm_expr_const(C, 7.25);
  st = dm_tape_compile(C, 1, &k7, 0, NULL, 0, NULL, &t, &err);
  dm_tape_eval(t, NULL, NULL, y, w);
  tap_ok(st == DM_OK && dm_tape_ninstr(t) == 0 && y[0] == 7.25, "constant output, no inputs");
  dm_tape_free(t);
}

int main(void)
{
  C = dm_expr_ctx_alloc();
  const char *names[NV] = { "x", "y", "z", "p", "k" };
  for (int i = 0; i < NV; i++)
    V[i] = i >= 3 ? dm_expr_param(C, names[i]) : dm_expr_sym(C, names[i]);
  test_against_eval();
  test_params_and_sharing();
  test_dsp_size();
  test_slots();
  test_errors();
  dm_expr_ctx_free(C);
  return tap_done();
}
