/* tape.c -- compile expression outputs to a register program and run it.
 * The evaluation loop is the hot path of every integrator: a switch over a
 * compact instruction array, no calls through pointers, no allocation. */
#include <config.h>
#include "expr/tape_impl.h"
#include "expr/expr_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>



void dm_tape_free(dm_tape *t)
{
  if (t == NULL)
    return;
  free(t->code);
  free(t->xcode);
  free(t->copy);
  free(t->preset);
  free(t->consts);
  free(t->outreg);
  free(t);
}

size_t dm_tape_work_size(const dm_tape *t) { return t->nregs; }
size_t dm_tape_batch_work_size(const dm_tape *t) { return t->nregs * DM_TAPE_BATCH; }
size_t dm_tape_ninstr(const dm_tape *t) { return t->ninstr; }
size_t dm_tape_nregs(const dm_tape *t) { return t->nregs; }
size_t dm_tape_nin(const dm_tape *t) { return t->nin; }
size_t dm_tape_npar(const dm_tape *t) { return t->npar; }
size_t dm_tape_nout(const dm_tape *t) { return t->nout; }
size_t dm_tape_nconst(const dm_tape *t) { return t->nconst; }
size_t dm_tape_slot_base(const dm_tape *t) { return t->slot0; }
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
    "eq", "ne", "select", "muladd", "mulsub", "submul", "mul3", "sincos"
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

/* One planned instruction: its op and the list positions of its result
 * and operands (-1: none; for POWI the exponent is in imm). */
typedef struct plan {
  int op;
  int32_t pos, opnd[3], imm;
  int32_t pos2;         /* SINCOS: the position of the cosine, else -1 */
} plan;

typedef struct build {
  long nl;
  int32_t *list;        /* collected nodes (copy) */
  int32_t *reg;         /* per position: register, -1 for results */
  int32_t *last;        /* per position: last instruction reading it */
  int32_t *uses;        /* per position: readers (outputs count) */
  int32_t *planned;     /* per position: index into plans, -1 none */
  int32_t *slotreg;     /* per position: its output slot's register, or -1 */
  plan *plans;
  size_t nplans;
} build;

static void build_free(build *b)
{
  free(b->list);
  free(b->reg);
  free(b->last);
  free(b->uses);
  free(b->planned);
  free(b->slotreg);
  free(b->plans);
}

/* A plain product or square used by exactly one instruction and not an
 * output can be folded into that instruction. */
static int foldable(const build *b, int32_t q)
{
  int32_t k = b->planned[q];
  return k >= 0 && (b->plans[k].op == DM_T_MUL || b->plans[k].op == DM_T_SQR)
         && b->uses[q] == 1;
}

/* Plan the instruction of the node at position p (operand positions from
 * ctx->aux).  Products used once are folded into sums, differences and
 * products (their plans become DM_T_NOPS: deleted). */
static void plan_node(const dm_expr_ctx *ctx, build *b, long p)
{
  const dm_node nd = ctx->node[b->list[p]];
  plan *pl = &b->plans[b->nplans];
  int k = dm_expr__arity(nd.op);
  int32_t ops[3] = { nd.a, nd.b, nd.c };
  pl->pos = (int32_t)p;
  pl->pos2 = -1;
  pl->imm = nd.op == DM_EXPR_POWI ? nd.b : 0;
  pl->opnd[0] = pl->opnd[1] = pl->opnd[2] = -1;
  for (int j = 0; j < k; j++)
    pl->opnd[j] = ctx->aux[ops[j]];
  pl->op = lower(nd.op, nd.b);
  double c1;
  if (pl->op == DM_T_DIV && dm_expr_is_const(ctx, nd.a, &c1) && c1 == 1.0) {
    pl->op = DM_T_RECIP;                      /* 1/b */
    pl->opnd[0] = pl->opnd[1];
    pl->opnd[1] = -1;
  }
  if (pl->op == DM_T_ADD || pl->op == DM_T_SUB || pl->op == DM_T_MUL) {
    int32_t x = pl->opnd[0], y = pl->opnd[1], m = -1, other = -1;
    int left = 0;
    if (foldable(b, x) && x != y) {
      m = x, other = y, left = 1;
    } else if (foldable(b, y) && x != y) {
      m = y, other = x;
    }
    if (m >= 0) {
      plan *pm = &b->plans[b->planned[m]];
      int op = pl->op == DM_T_ADD ? DM_T_MULADD : pl->op == DM_T_MUL ? DM_T_MUL3
               : left ? DM_T_MULSUB : DM_T_SUBMUL;
      pl->op = op;
      pl->opnd[0] = pm->opnd[0];
      pl->opnd[1] = pm->op == DM_T_SQR ? pm->opnd[0] : pm->opnd[1];
      pl->opnd[2] = other;
      pm->op = DM_T_NOPS;                     /* folded away */
      b->planned[m] = -1;
    }
  }
  b->planned[p] = (int32_t)b->nplans++;
}

/* sin(x) and cos(x) both planned: one SINCOS where the first of them is
 * (the other deleted). */
static void pair_sincos(build *b)
{
  for (size_t k = 0; k < b->nplans; k++) {
    plan *pk = &b->plans[k];
    if (pk->op != DM_T_SIN && pk->op != DM_T_COS)
      continue;
    int want = pk->op == DM_T_SIN ? DM_T_COS : DM_T_SIN;
    for (size_t j = k + 1; j < b->nplans; j++) {
      plan *pj = &b->plans[j];
      if (pj->op != want || pj->opnd[0] != pk->opnd[0])
        continue;
      int32_t ps = pk->op == DM_T_SIN ? pk->pos : pj->pos;
      int32_t pc = pk->op == DM_T_SIN ? pj->pos : pk->pos;
      pk->op = DM_T_SINCOS;
      pk->pos = ps;
      pk->pos2 = pc;
      b->planned[ps] = (int32_t)k;
      b->planned[pc] = -1;
      pj->op = DM_T_NOPS;
      break;
    }
  }
}

/* Temporaries by liveness: an operand's register is free after its last
 * reading, so d may equal an operand (every op reads before writing).
 * Registers from base on are temporaries; a result with an output slot
 * goes to the slot's register (below base), never freed. */
static int assign_registers(dm_tape *t, build *b, size_t base, dm_err *err)
{
  int32_t *freel = malloc((2 * t->ninstr + 2) * sizeof *freel);
  if (freel == NULL)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  size_t nfree = 0, ntmp = 0, i = 0;
  for (size_t k = 0; k < b->nplans; k++) {
    const plan *pl = &b->plans[k];
    if (pl->op == DM_T_NOPS)
      continue;
    int32_t r[3] = { 0, 0, 0 };
    for (int j = 0; j < 3; j++) {
      int32_t q = pl->opnd[j];
      if (q < 0)
        continue;
      r[j] = b->reg[q];
      int dup = 0;
      for (int m = 0; m < j; m++)
        dup |= pl->opnd[m] == q;
      if (b->last[q] == (int32_t)i && (size_t)r[j] >= base && !dup)
        freel[nfree++] = r[j];
    }
    int32_t d = b->slotreg[pl->pos] >= 0 ? b->slotreg[pl->pos]
                : nfree > 0 ? freel[--nfree] : (int32_t)(base + ntmp++);
    b->reg[pl->pos] = d;
    dm_tape_ins *ins = &t->code[i++];
    ins->d = (uint32_t)d;
    if (pl->pos2 >= 0) {                      /* SINCOS: the cosine */
      r[2] = b->slotreg[pl->pos2] >= 0 ? b->slotreg[pl->pos2]
             : nfree > 0 ? freel[--nfree] : (int32_t)(base + ntmp++);
      b->reg[pl->pos2] = r[2];
    }
    switch (pl->op) {
    case DM_T_SELECT:                         /* select(c, a, b) */
      ins->a = (uint32_t)r[1];
      ins->b = (uint32_t)r[2];
      r[2] = r[0];
      break;
    case DM_T_POWI:
      ins->a = (uint32_t)r[0];
      ins->b = (uint32_t)pl->imm;
      break;
    default:
      ins->a = (uint32_t)r[0];
      ins->b = (uint32_t)r[1];
      break;
    }
    if ((uint32_t)r[2] >= (1u << 24)) {
      free(freel);
      return dm_err_set(err, DM_EUNSUP, "tape: too many registers");
    }
    ins->code = (uint32_t)pl->op | (uint32_t)r[2] << 8;
  }
  free(freel);
  t->nregs = base + ntmp;
  return DM_OK;
}

static int compile(dm_expr_ctx *ctx, dm_tape *t, build *b, size_t nout,
                   const dm_expr *out, size_t nin, const dm_expr *in,
                   size_t npar, const dm_expr *par, size_t nslot,
                   const uint32_t *slot_out, dm_err *err)
{
  long nl = dm_expr__collect(ctx, nout, out);
  if (nl < 0)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  size_t sz = (size_t)(nl ? nl : 1);
  b->nl = nl;
  b->list = malloc(sz * sizeof *b->list);
  b->reg = malloc(sz * sizeof *b->reg);
  b->last = malloc(sz * sizeof *b->last);
  b->uses = calloc(sz, sizeof *b->uses);
  b->planned = malloc(sz * sizeof *b->planned);
  b->slotreg = malloc(sz * sizeof *b->slotreg);
  b->plans = malloc(sz * sizeof *b->plans);
  t->consts = malloc(sz * sizeof *t->consts);
  t->outreg = malloc((nout ? nout : 1) * sizeof *t->outreg);
  if (!b->list || !b->reg || !b->last || !b->uses || !b->planned ||
      !b->slotreg || !b->plans || !t->consts || !t->outreg)
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
  /* pass 1: positions, fixed registers, constants, use counts */
  size_t ncon = 0;
  for (long p = 0; p < nl; p++) {
    int32_t x = b->list[p];
    const dm_node nd = ctx->node[x];
    b->last[p] = -1;
    b->reg[p] = -1;
    b->planned[p] = -1;
    b->slotreg[p] = -1;
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
        b->uses[ctx->aux[ops[j]]]++;
    }
    ctx->aux[x] = (int32_t)p;
  }
  for (size_t k = 0; k < nout; k++)
    b->uses[ctx->aux[out[k]]] += 2;            /* outputs are never folded */
  /* pass 2: plan (folding products), then liveness over the plan */
  b->nplans = 0;
  for (long p = 0; p < nl; p++)
    if (b->reg[p] == -1)
      plan_node(ctx, b, p);
  pair_sincos(b);
  size_t nins = 0;
  for (size_t k = 0; k < b->nplans; k++) {
    if (b->plans[k].op == DM_T_NOPS)
      continue;
    for (int j = 0; j < 3; j++)
      if (b->plans[k].opnd[j] >= 0)
        b->last[b->plans[k].opnd[j]] = (int32_t)nins;
    nins++;
  }
  size_t base = nin + npar + ncon;
  for (long p = 0; p < nl; p++)
    if (b->reg[p] <= -3)
      b->reg[p] = (int32_t)(nin + npar) + (-3 - b->reg[p]);
  for (size_t k = 0; k < nout; k++)
    b->last[ctx->aux[out[k]]] = INT32_MAX;      /* outputs live to the end */
  /* output slots: a computed output goes straight to its first slot; the
   * other slots (and outputs that are inputs, parameters or constants)
   * are copied at the end of a run */
  size_t ncopy = 0;
  for (size_t sl = 0; sl < nslot; sl++) {
    int32_t p = ctx->aux[out[slot_out[sl]]];
    if (b->reg[p] == -1 && b->slotreg[p] < 0)
      b->slotreg[p] = (int32_t)(base + sl);
    else
      ncopy++;
  }
  t->nin = nin;
  t->npar = npar;
  t->nconst = ncon;
  t->nout = nout;
  t->ninstr = nins;
  t->nslot = nslot;
  t->slot0 = base;
  t->code = malloc((nins ? nins : 1) * sizeof *t->code);
  t->copy = malloc((ncopy ? ncopy : 1) * sizeof *t->copy);
  t->preset = calloc(ncon + nslot + 1, sizeof *t->preset);
  if (t->code == NULL || t->copy == NULL || t->preset == NULL)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  memcpy(t->preset, t->consts, ncon * sizeof *t->preset);
  int s = assign_registers(t, b, base + nslot, err);
  if (s != DM_OK)
    return s;
  for (size_t sl = 0; sl < nslot; sl++) {  /* constants: preset, else copies */
    int32_t p = ctx->aux[out[slot_out[sl]]], r = b->reg[p];
    if (r == (int32_t)(base + sl))
      continue;
    if (r >= (int32_t)(nin + npar) && r < (int32_t)base) {
      t->preset[ncon + sl] = t->consts[r - (int32_t)(nin + npar)];
      continue;
    }
    t->copy[t->ncopy][0] = (uint32_t)(base + sl);
    t->copy[t->ncopy++][1] = (uint32_t)r;
  }
  for (size_t k = 0; k < nout; k++)
    t->outreg[k] = (uint32_t)b->reg[ctx->aux[out[k]]];
  return DM_OK;
}

static int compile_with(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                        size_t nin, const dm_expr *in, size_t npar,
                        const dm_expr *par, int rewrite, size_t nslot,
                        const uint32_t *slot_out, dm_tape **tape,
                        dm_err *err)
{
  *tape = NULL;
  for (size_t k = 0; k < nout; k++)
    if (!dm_expr__valid(ctx, out[k]))
      return dm_err_set(err, DM_EINVAL, "tape: output %zu is not a valid "
                        "expression", k + 1);
  int s = check_vars(ctx, nin, in, npar, par, err);
  if (s != DM_OK)
    return s;
  for (size_t sl = 0; sl < nslot; sl++)
    if (slot_out[sl] >= nout)
      return dm_err_set(err, DM_EINVAL, "tape: slot %zu names output %u of "
                        "%zu", sl + 1, slot_out[sl] + 1, nout);
  dm_tape *t = calloc(1, sizeof *t);
  dm_expr *nw = malloc((nout ? nout : 1) * sizeof *nw);
  build b = { 0, NULL, NULL, NULL, NULL, NULL, NULL, NULL, 0 };
  if (t == NULL || nw == NULL) {
    free(t);
    free(nw);
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  }
  if (rewrite)
    s = dm_tape__optimize(ctx, nout, out, nw, err);
  else
    memcpy(nw, out, nout * sizeof *nw);
  if (s == DM_OK)
    s = compile(ctx, t, &b, nout, nw, nin, in, npar, par, nslot, slot_out,
                err);
  if (s == DM_OK && dm_tape__thread(t) != DM_OK)
    s = dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  free(nw);
  build_free(&b);
  if (s != DM_OK) {
    dm_tape_free(t);
    return s;
  }
  *tape = t;
  return DM_OK;
}

int dm_tape_compile(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                    size_t nin, const dm_expr *in, size_t npar,
                    const dm_expr *par, dm_tape **tape, dm_err *err)
{
  return compile_with(ctx, nout, out, nin, in, npar, par, 1, 0, NULL, tape,
                      err);
}

int dm_tape_compile_exact(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                          size_t nin, const dm_expr *in, size_t npar,
                          const dm_expr *par, dm_tape **tape, dm_err *err)
{
  return compile_with(ctx, nout, out, nin, in, npar, par, 0, 0, NULL, tape,
                      err);
}

int dm_tape_compile_slots(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                          size_t nin, const dm_expr *in, size_t npar,
                          const dm_expr *par, size_t nslot,
                          const uint32_t *slot_out, dm_tape **tape,
                          dm_err *err)
{
  return compile_with(ctx, nout, out, nin, in, npar, par, 0, nslot, slot_out,
                      tape, err);
}

int dm_tape_optimize(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                     dm_expr *nw, dm_err *err)
{
  for (size_t k = 0; k < nout; k++)
    if (!dm_expr__valid(ctx, out[k]))
      return dm_err_set(err, DM_EINVAL, "tape: output %zu is not a valid "
                        "expression", k + 1);
  return dm_tape__optimize(ctx, nout, out, nw, err);
}
