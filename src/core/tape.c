/* tape.c -- compile expression outputs to a register program and run it.
 * The evaluation loop is the hot path of every integrator: a switch over a
 * compact instruction array, no calls through pointers, no allocation. */
#include <config.h>
#include "tape.h"
#include "expr_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct dm_tape {
  size_t nin, npar, nconst, nout, ninstr, nregs;
  dm_tape_ins *code;
  double *consts;
  uint32_t *outreg;
};

#define BATCH 32            /* points per block in batch evaluation */

void dm_tape_free(dm_tape *t)
{
  if (t == NULL)
    return;
  free(t->code);
  free(t->consts);
  free(t->outreg);
  free(t);
}

size_t dm_tape_work_size(const dm_tape *t) { return t->nregs; }
size_t dm_tape_batch_work_size(const dm_tape *t) { return t->nregs * BATCH; }
size_t dm_tape_ninstr(const dm_tape *t) { return t->ninstr; }
size_t dm_tape_nregs(const dm_tape *t) { return t->nregs; }
size_t dm_tape_nin(const dm_tape *t) { return t->nin; }
size_t dm_tape_npar(const dm_tape *t) { return t->npar; }
size_t dm_tape_nout(const dm_tape *t) { return t->nout; }
size_t dm_tape_nconst(const dm_tape *t) { return t->nconst; }
const dm_tape_ins *dm_tape_code(const dm_tape *t) { return t->code; }
const double *dm_tape_consts(const dm_tape *t) { return t->consts; }
const uint32_t *dm_tape_outregs(const dm_tape *t) { return t->outreg; }

void dm_tape_op_counts(const dm_tape *t, size_t *counts)
{
  memset(counts, 0, DM_T_NOPS * sizeof *counts);
  for (size_t i = 0; i < t->ninstr; i++)
    counts[t->code[i].code & 0xff]++;
}

const char *dm_tape_op_name(int op)
{
  static const char *const names[DM_T_NOPS] = {
    "add", "sub", "mul", "div", "neg", "sqr", "cube", "recip", "powi", "pow",
    "atan2", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos",
    "atan", "sinh", "cosh", "tanh", "abs", "sign", "lt", "le", "gt", "ge",
    "eq", "ne", "select"
  };
  return (op >= 0 && op < DM_T_NOPS) ? names[op] : "?";
}

/* {==================================================================
 * compiling
 * =================================================================== */

/* Tape op of an expression node (POWI lowered by exponent). */
static int lower(int op, int n)
{
  switch (op) {
  case DM_EXPR_ADD: return DM_T_ADD;
  case DM_EXPR_SUB: return DM_T_SUB;
  case DM_EXPR_MUL: return DM_T_MUL;
  case DM_EXPR_DIV: return DM_T_DIV;
  case DM_EXPR_POW: return DM_T_POW;
  case DM_EXPR_ATAN2: return DM_T_ATAN2;
  case DM_EXPR_LT: return DM_T_LT;
  case DM_EXPR_LE: return DM_T_LE;
  case DM_EXPR_GT: return DM_T_GT;
  case DM_EXPR_GE: return DM_T_GE;
  case DM_EXPR_EQ: return DM_T_EQ;
  case DM_EXPR_NE: return DM_T_NE;
  case DM_EXPR_POWI:
    return n == 2 ? DM_T_SQR : n == 3 ? DM_T_CUBE : n == -1 ? DM_T_RECIP
                                                            : DM_T_POWI;
  case DM_EXPR_NEG: return DM_T_NEG;
  case DM_EXPR_SQRT: return DM_T_SQRT;
  case DM_EXPR_EXP: return DM_T_EXP;
  case DM_EXPR_LOG: return DM_T_LOG;
  case DM_EXPR_SIN: return DM_T_SIN;
  case DM_EXPR_COS: return DM_T_COS;
  case DM_EXPR_TAN: return DM_T_TAN;
  case DM_EXPR_ASIN: return DM_T_ASIN;
  case DM_EXPR_ACOS: return DM_T_ACOS;
  case DM_EXPR_ATAN: return DM_T_ATAN;
  case DM_EXPR_SINH: return DM_T_SINH;
  case DM_EXPR_COSH: return DM_T_COSH;
  case DM_EXPR_TANH: return DM_T_TANH;
  case DM_EXPR_ABS: return DM_T_ABS;
  case DM_EXPR_SIGN: return DM_T_SIGN;
  case DM_EXPR_SELECT: return DM_T_SELECT;
  default: return -1;
  }
}

static int cmp_i32(const void *x, const void *y)
{
  int32_t a = *(const int32_t *)x, b = *(const int32_t *)y;
  return (a > b) - (a < b);
}

/* Inputs and parameters: valid symbols/parameters, none twice. */
static int check_vars(dm_expr_ctx *ctx, size_t nin, const dm_expr *in,
                      size_t npar, const dm_expr *par, dm_err *err)
{
  size_t n = nin + npar;
  int32_t *v = malloc((n ? n : 1) * sizeof *v);
  if (v == NULL)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  for (size_t k = 0; k < n; k++) {
    dm_expr e = k < nin ? in[k] : par[k - nin];
    int op = dm_expr_kind(ctx, e);
    if (op != DM_EXPR_SYM && op != DM_EXPR_PARAM) {
      free(v);
      return dm_err_set(err, DM_EINVAL, "tape: %s %zu is not a symbol or "
                        "parameter", k < nin ? "input" : "parameter",
                        (k < nin ? k : k - nin) + 1);
    }
    v[k] = e;
  }
  qsort(v, n, sizeof *v, cmp_i32);
  for (size_t k = 1; k < n; k++)
    if (v[k] == v[k - 1]) {
      const char *name = dm_expr_name(ctx, v[k]);
      free(v);
      return dm_err_set(err, DM_EINVAL, "tape: '%s' is listed twice among "
                        "the inputs and parameters", name);
    }
  free(v);
  return DM_OK;
}

typedef struct build {
  long nl;
  int32_t *list;        /* collected nodes (copy) */
  int32_t *reg;         /* per position: register, or -1 for instructions */
  int32_t *last;        /* per position: last instruction reading it */
  int32_t *ins_pos;     /* per instruction: position of its node */
} build;

static void build_free(build *b)
{
  free(b->list);
  free(b->reg);
  free(b->last);
  free(b->ins_pos);
}

/* Allocate temporaries in instruction order, freeing each operand after its
 * last reading (so d may equal an operand: every op reads before writing). */
static int assign_registers(dm_tape *t, const dm_expr_ctx *ctx, build *b,
                            size_t base, dm_err *err)
{
  int32_t *freel = malloc((t->ninstr + 1) * sizeof *freel);
  if (freel == NULL)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  size_t nfree = 0, ntmp = 0;
  for (size_t i = 0; i < t->ninstr; i++) {
    long p = b->ins_pos[i];
    const dm_node nd = ctx->node[b->list[p]];
    int k = dm_expr__arity(nd.op);
    int32_t ops[3] = { nd.a, nd.b, nd.c };
    int32_t r[3] = { 0, 0, 0 };
    for (int j = 0; j < k; j++) {
      long q = ctx->aux[ops[j]];
      r[j] = b->reg[q];
      if (b->last[q] == (int32_t)i && (size_t)r[j] >= base) {
        int dup = 0;
        for (int m = 0; m < j; m++)
          dup |= ops[m] == ops[j];
        if (!dup)
          freel[nfree++] = r[j];
      }
    }
    int32_t d = nfree > 0 ? freel[--nfree] : (int32_t)(base + ntmp++);
    b->reg[p] = d;
    dm_tape_ins *ins = &t->code[i];
    int op = lower(nd.op, nd.b);
    ins->d = (uint32_t)d;
    ins->a = (uint32_t)r[0];
    ins->b = op == DM_T_POWI ? (uint32_t)nd.b : (k >= 2 ? (uint32_t)r[1] : 0);
    if (op == DM_T_SELECT) {        /* select(c, a, b): cond in code */
      if ((uint32_t)r[0] >= (1u << 24)) {
        free(freel);
        return dm_err_set(err, DM_EUNSUP, "tape: too many registers");
      }
      ins->code = DM_T_SELECT | ((uint32_t)r[0] << 8);
      ins->a = (uint32_t)r[1];
      ins->b = (uint32_t)r[2];
    } else {
      ins->code = (uint32_t)op;
    }
  }
  free(freel);
  t->nregs = base + ntmp;
  return DM_OK;
}

static int compile(dm_expr_ctx *ctx, dm_tape *t, build *b, size_t nout,
                   const dm_expr *out, size_t nin, const dm_expr *in,
                   size_t npar, const dm_expr *par, dm_err *err)
{
  long nl = dm_expr__collect(ctx, nout, out);
  if (nl < 0)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  size_t sz = (size_t)(nl ? nl : 1);
  b->nl = nl;
  b->list = malloc(sz * sizeof *b->list);
  b->reg = malloc(sz * sizeof *b->reg);
  b->last = malloc(sz * sizeof *b->last);
  b->ins_pos = malloc(sz * sizeof *b->ins_pos);
  t->consts = malloc(sz * sizeof *t->consts);
  t->outreg = malloc((nout ? nout : 1) * sizeof *t->outreg);
  if (!b->list || !b->reg || !b->last || !b->ins_pos || !t->consts || !t->outreg)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  memcpy(b->list, ctx->list, sz * sizeof *b->list);
  const uint32_t ep = ctx->epoch;
  for (long p = 0; p < nl; p++)
    ctx->aux[b->list[p]] = -1;
  for (size_t k = 0; k < nin + npar; k++) {
    dm_expr v = k < nin ? in[k] : par[k - nin];
    if (ctx->stamp[v] == ep)
      ctx->aux[v] = -2 - (int32_t)k;
  }
  /* pass 1: positions, fixed registers, constants, instruction order */
  size_t ncon = 0, nins = 0;
  for (long p = 0; p < nl; p++) {
    int32_t x = b->list[p];
    const dm_node nd = ctx->node[x];
    b->last[p] = -1;
    b->reg[p] = -1;
    if (ctx->aux[x] <= -2) {
      b->reg[p] = -2 - ctx->aux[x];
    } else if (nd.op == DM_EXPR_CONST) {
      t->consts[ncon] = ctx->cval[nd.a];
      b->reg[p] = -3 - (int32_t)ncon++;      /* fixed up below */
    } else if (nd.op == DM_EXPR_SYM || nd.op == DM_EXPR_PARAM) {
      return dm_err_set(err, DM_EINVAL, "tape: %s '%s' is neither an input "
                        "nor a parameter", nd.op == DM_EXPR_SYM ? "symbol"
                        : "parameter", ctx->names[nd.a]);
    } else {
      int k = dm_expr__arity(nd.op);
      int32_t ops[3] = { nd.a, nd.b, nd.c };
      for (int j = 0; j < k; j++)
        b->last[ctx->aux[ops[j]]] = (int32_t)nins;
      b->ins_pos[nins++] = (int32_t)p;
    }
    ctx->aux[x] = (int32_t)p;
  }
  size_t base = nin + npar + ncon;
  for (long p = 0; p < nl; p++)
    if (b->reg[p] <= -3)
      b->reg[p] = (int32_t)(nin + npar) + (-3 - b->reg[p]);
  for (size_t k = 0; k < nout; k++)
    b->last[ctx->aux[out[k]]] = INT32_MAX;      /* outputs live to the end */
  t->nin = nin;
  t->npar = npar;
  t->nconst = ncon;
  t->nout = nout;
  t->ninstr = nins;
  t->code = malloc((nins ? nins : 1) * sizeof *t->code);
  if (t->code == NULL)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  int s = assign_registers(t, ctx, b, base, err);
  if (s != DM_OK)
    return s;
  for (size_t k = 0; k < nout; k++)
    t->outreg[k] = (uint32_t)b->reg[ctx->aux[out[k]]];
  return DM_OK;
}

int dm_tape_compile(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                    size_t nin, const dm_expr *in, size_t npar,
                    const dm_expr *par, dm_tape **tape, dm_err *err)
{
  *tape = NULL;
  for (size_t k = 0; k < nout; k++)
    if (!dm_expr__valid(ctx, out[k]))
      return dm_err_set(err, DM_EINVAL, "tape: output %zu is not a valid "
                        "expression", k + 1);
  int s = check_vars(ctx, nin, in, npar, par, err);
  if (s != DM_OK)
    return s;
  dm_tape *t = calloc(1, sizeof *t);
  build b = { 0, NULL, NULL, NULL, NULL };
  if (t == NULL)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  s = compile(ctx, t, &b, nout, out, nin, in, npar, par, err);
  build_free(&b);
  if (s != DM_OK) {
    dm_tape_free(t);
    return s;
  }
  *tape = t;
  return DM_OK;
}

/* {==================================================================
 * evaluation
 * =================================================================== */

static inline double sign_of(double x)
{
  return x > 0 ? 1.0 : x < 0 ? -1.0 : x == 0 ? 0.0 : x;
}

void dm_tape_eval(const dm_tape *t, const double *in, const double *par,
                  double *out, double *w)
{
  if (t->nin)
    memcpy(w, in, t->nin * sizeof *w);
  if (t->npar)
    memcpy(w + t->nin, par, t->npar * sizeof *w);
  if (t->nconst)
    memcpy(w + t->nin + t->npar, t->consts, t->nconst * sizeof *w);
  const dm_tape_ins *ip = t->code, *end = ip + t->ninstr;
  for (; ip < end; ip++) {
    const double a = w[ip->a];
    double *d = w + ip->d;
    switch (ip->code & 0xff) {
    case DM_T_ADD: *d = a + w[ip->b]; break;
    case DM_T_SUB: *d = a - w[ip->b]; break;
    case DM_T_MUL: *d = a * w[ip->b]; break;
    case DM_T_DIV: *d = a / w[ip->b]; break;
    case DM_T_NEG: *d = -a; break;
    case DM_T_SQR: *d = a * a; break;
    case DM_T_CUBE: *d = a * (a * a); break;
    case DM_T_RECIP: *d = 1.0 / a; break;
    case DM_T_POWI: *d = dm_tape_powi(a, (int32_t)ip->b); break;
    case DM_T_POW: *d = pow(a, w[ip->b]); break;
    case DM_T_ATAN2: *d = atan2(a, w[ip->b]); break;
    case DM_T_SQRT: *d = sqrt(a); break;
    case DM_T_EXP: *d = exp(a); break;
    case DM_T_LOG: *d = log(a); break;
    case DM_T_SIN: *d = sin(a); break;
    case DM_T_COS: *d = cos(a); break;
    case DM_T_TAN: *d = tan(a); break;
    case DM_T_ASIN: *d = asin(a); break;
    case DM_T_ACOS: *d = acos(a); break;
    case DM_T_ATAN: *d = atan(a); break;
    case DM_T_SINH: *d = sinh(a); break;
    case DM_T_COSH: *d = cosh(a); break;
    case DM_T_TANH: *d = tanh(a); break;
    case DM_T_ABS: *d = fabs(a); break;
    case DM_T_SIGN: *d = sign_of(a); break;
    case DM_T_LT: *d = a < w[ip->b]; break;
    case DM_T_LE: *d = a <= w[ip->b]; break;
    case DM_T_GT: *d = a > w[ip->b]; break;
    case DM_T_GE: *d = a >= w[ip->b]; break;
    case DM_T_EQ: *d = a == w[ip->b]; break;
    case DM_T_NE: *d = a != w[ip->b]; break;
    case DM_T_SELECT: *d = w[ip->code >> 8] != 0 ? a : w[ip->b]; break;
    default: break;
    }
  }
  for (size_t k = 0; k < t->nout; k++)
    out[k] = w[t->outreg[k]];
}

#define LOOP(expr) for (size_t j = 0; j < m; j++) d[j] = (expr); break

/* One block of m <= BATCH points; registers are rows of BATCH doubles. */
static void run_block(const dm_tape *t, double *W, size_t m)
{
  for (size_t i = 0; i < t->ninstr; i++) {
    const dm_tape_ins *ip = &t->code[i];
    double *d = W + (size_t)ip->d * BATCH;
    const double *a = W + (size_t)ip->a * BATCH;
    const double *b = W + (size_t)(ip->b % t->nregs) * BATCH;
    switch (ip->code & 0xff) {
    case DM_T_ADD: LOOP(a[j] + b[j]);
    case DM_T_SUB: LOOP(a[j] - b[j]);
    case DM_T_MUL: LOOP(a[j] * b[j]);
    case DM_T_DIV: LOOP(a[j] / b[j]);
    case DM_T_NEG: LOOP(-a[j]);
    case DM_T_SQR: LOOP(a[j] * a[j]);
    case DM_T_CUBE: LOOP(a[j] * (a[j] * a[j]));
    case DM_T_RECIP: LOOP(1.0 / a[j]);
    case DM_T_POWI: LOOP(dm_tape_powi(a[j], (int32_t)ip->b));
    case DM_T_POW: LOOP(pow(a[j], b[j]));
    case DM_T_ATAN2: LOOP(atan2(a[j], b[j]));
    case DM_T_SQRT: LOOP(sqrt(a[j]));
    case DM_T_EXP: LOOP(exp(a[j]));
    case DM_T_LOG: LOOP(log(a[j]));
    case DM_T_SIN: LOOP(sin(a[j]));
    case DM_T_COS: LOOP(cos(a[j]));
    case DM_T_TAN: LOOP(tan(a[j]));
    case DM_T_ASIN: LOOP(asin(a[j]));
    case DM_T_ACOS: LOOP(acos(a[j]));
    case DM_T_ATAN: LOOP(atan(a[j]));
    case DM_T_SINH: LOOP(sinh(a[j]));
    case DM_T_COSH: LOOP(cosh(a[j]));
    case DM_T_TANH: LOOP(tanh(a[j]));
    case DM_T_ABS: LOOP(fabs(a[j]));
    case DM_T_SIGN: LOOP(sign_of(a[j]));
    case DM_T_LT: LOOP(a[j] < b[j]);
    case DM_T_LE: LOOP(a[j] <= b[j]);
    case DM_T_GT: LOOP(a[j] > b[j]);
    case DM_T_GE: LOOP(a[j] >= b[j]);
    case DM_T_EQ: LOOP(a[j] == b[j]);
    case DM_T_NE: LOOP(a[j] != b[j]);
    case DM_T_SELECT: {
      const double *c = W + (size_t)(ip->code >> 8) * BATCH;
      LOOP(c[j] != 0 ? a[j] : b[j]);
    }
    default: break;
    }
  }
}

void dm_tape_eval_batch(const dm_tape *t, size_t npts, const double *in,
                        size_t in_stride, const double *par, double *out,
                        size_t out_stride, double *W)
{
  /* parameters and constants are never overwritten: fill them once */
  for (size_t k = 0; k < t->npar + t->nconst; k++) {
    double v = k < t->npar ? par[k] : t->consts[k - t->npar];
    double *r = W + (t->nin + k) * BATCH;
    for (size_t j = 0; j < BATCH; j++)
      r[j] = v;
  }
  for (size_t s = 0; s < npts; s += BATCH) {
    size_t m = npts - s < BATCH ? npts - s : BATCH;
    for (size_t j = 0; j < m; j++)
      for (size_t i = 0; i < t->nin; i++)
        W[i * BATCH + j] = in[(s + j) * in_stride + i];
    run_block(t, W, m);
    for (size_t j = 0; j < m; j++)
      for (size_t k = 0; k < t->nout; k++)
        out[(s + j) * out_stride + k] = W[(size_t)t->outreg[k] * BATCH + j];
  }
}
