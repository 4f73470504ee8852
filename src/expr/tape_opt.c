/* tape_opt.c -- the outputs of a tape rewritten for fewer and cheaper
 * instructions before they are compiled (see dm_tape__optimize in
 * tape_impl.h).
 *
 * Printing wants sums and products in the flat normal form expr_norm.c
 * builds; evaluating wants them factored.  Every maximal sum (sums whose
 * sub-sums are used nowhere else) becomes a list of terms c * monomial,
 * where a monomial is a product of powers of atoms (nodes used more than
 * once, or that are not products: functions, sums inside products, ...),
 * and is rewritten by greedy factoring: the atom power common to the most
 * terms goes out (a*x + a*y + z -> a*(x + y) + z), recursively.  Nodes
 * used more than once are never taken apart, so sharing is kept.
 * Monomials are products of shared powers (x^5 = (x^2)^2 * x, no powi
 * loops), in an order that puts frequent atoms first so that partial
 * products are shared; an atom that appears in several denominators is
 * divided once (a shared reciprocal, then products), any other
 * denominator is one division.  The rewritten nodes are built without
 * simplification (dm_expr__cons), so they are hash-consed among
 * themselves but never change the user's expressions.
 *
 * Results differ from the DAG evaluation by reassociation only (a few
 * ulps); native code is emitted from the same tape and agrees bit for
 * bit. */
#include <config.h>
#include "expr/tape_impl.h"
#include "expr/expr_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { K_OTHER = 0, K_SUM = 1, K_PROD = 2 };
enum { ADD = DM_EXPR_ADD, SUB = DM_EXPR_SUB, MUL = DM_EXPR_MUL,
       DIV = DM_EXPR_DIV, NEG = DM_EXPR_NEG, POWI = DM_EXPR_POWI };

#define EXP_MAX (1 << 20)

typedef struct fac {
  int32_t atom;         /* position of the atom in the collected list */
  int32_t e;            /* exponent, nonzero */
} fac;

typedef struct term {
  double c;
  size_t off, n;        /* factors facs[off .. off+n) */
} term;

/* A term while factoring: its own copy of the factors. */
typedef struct mterm {
  double c;
  fac *f;
  size_t n;
} mterm;

/* A value or its negation. */
typedef struct sv {
  dm_expr n;
  int neg;
} sv;

typedef struct opt {
  dm_expr_ctx *ctx;
  size_t nold;          /* nodes before rewriting */
  long nl;
  int32_t *L;           /* collected nodes, ascending */
  int32_t *uses, *parent;
  uint8_t *kind, *isout, *absorbed;
  dm_expr *img;         /* the rewritten node of each root */
  size_t *first, *nterm;  /* IR of each root: terms[first .. first+nterm) */
  term *terms;
  size_t nterms, capterms;
  fac *facs;
  size_t nfacs, capfacs;
  int32_t *dcount;      /* per atom: monomials with it in the denominator */
  int32_t *freq;        /* per atom: monomials with it */
  struct { int32_t node; int64_t e; } *stk;
  size_t capstk;
  /* the sums emitted so far by their terms (canonical factor order):
   * sums[j] is the value of terms rterm[sums[j].off .. +n) */
  struct sument { uint64_t h; size_t off, n; dm_expr node; int neg; } *sums;
  size_t nsums, capsums;
  int32_t *stab;        /* hash table of indices into sums, -1 empty */
  size_t stabcap;
  struct rterm { double c; size_t foff, n; } *rterm;
  size_t nrterm, caprterm;
  fac *rfac;
  size_t nrfac, caprfac;
  dm_expr one;
  int nomem;
} opt;

static long pos(const opt *o, dm_expr x)
{
  return o->ctx->aux[x];
}

static int node_kind(const dm_expr_ctx *ctx, dm_expr x)
{
  switch (ctx->node[x].op) {
  case ADD:
  case SUB:
    return K_SUM;
  case MUL:
  case DIV:
  case POWI:
    return K_PROD;
  case NEG: {
    dm_expr a = ctx->node[x].a;
    while (ctx->node[a].op == NEG)
      a = ctx->node[a].a;
    return (ctx->node[a].op == ADD || ctx->node[a].op == SUB) ? K_SUM : K_PROD;
  }
  default:
    return K_OTHER;
  }
}

/* {==================================================================
 * the IR: terms of sums, factors of monomials
 * =================================================================== */

static int push(opt *o, size_t *ns, dm_expr x, int64_t e)
{
  if (dm_expr__grow(&o->stk, &o->capstk, *ns + 1, sizeof *o->stk))
    return -1;
  o->stk[*ns].node = x;
  o->stk[*ns].e = e;
  ++*ns;
  return 0;
}

static int add_fac(opt *o, size_t off, dm_expr x, int64_t e)
{
  int32_t p = (int32_t)pos(o, x);
  for (size_t i = off; i < o->nfacs; i++)
    if (o->facs[i].atom == p) {
      o->facs[i].e += (int32_t)e;
      return 0;
    }
  if (dm_expr__grow(&o->facs, &o->capfacs, o->nfacs + 1, sizeof *o->facs))
    return -1;
  o->facs[o->nfacs].atom = p;
  o->facs[o->nfacs++].e = (int32_t)e;
  return 0;
}

static int descend(const opt *o, dm_expr x, dm_expr root, int kind)
{
  long p = pos(o, x);
  return o->kind[p] == kind && (x == root || o->absorbed[p]);
}

/* The monomial of y (taken apart when apart, else y is one atom)
 * appended as a term with sign s; uses the stack above base. */
static int add_monomial(opt *o, dm_expr y, double s, int apart, size_t base)
{
  const dm_expr_ctx *ctx = o->ctx;
  size_t off = o->nfacs, ns = base;
  double c = s;
  if (push(o, &ns, y, 1))
    return -1;
  while (ns > base) {
    dm_expr x = o->stk[--ns].node;
    int64_t e = o->stk[ns].e;
    const dm_node nd = ctx->node[x];
    if (nd.op == DM_EXPR_CONST) {
      double v = ctx->cval[nd.a];
      c *= e > 0 ? dm_tape_powi(v, (int)e) : 1.0 / dm_tape_powi(v, (int)-e);
      continue;
    }
    /* a product in a denominator is always taken apart: its bases get
     * shared reciprocals instead of a division each */
    if (((x != y || apart) && descend(o, x, y, K_PROD)) ||
        (e < 0 && o->kind[pos(o, x)] == K_PROD)) {
      int64_t e2 = nd.op == POWI ? e * nd.b : e;
      if (e2 <= EXP_MAX && e2 >= -EXP_MAX) {
        int r = 0;
        switch (nd.op) {
        case NEG:
          if (e & 1)
            c = -c;
          r = push(o, &ns, nd.a, e);
          break;
        case MUL:
        case DIV:
          r = push(o, &ns, nd.b, nd.op == MUL ? e : -e) || push(o, &ns, nd.a, e);
          break;
        default:                              /* POWI */
          r = push(o, &ns, nd.a, e2);
          break;
        }
        if (r)
          return -1;
        continue;
      }
    }
    if (add_fac(o, off, x, e))
      return -1;
  }
  size_t n = off;
  for (size_t i = off; i < o->nfacs; i++)     /* drop x^0 */
    if (o->facs[i].e != 0)
      o->facs[n++] = o->facs[i];
  o->nfacs = n;
  if (dm_expr__grow(&o->terms, &o->capterms, o->nterms + 1, sizeof *o->terms))
    return -1;
  o->terms[o->nterms++] = (term){ c, off, n - off };
  return 0;
}

/* The terms of the root at position p. */
static int build_ir(opt *o, long p)
{
  const dm_expr_ctx *ctx = o->ctx;
  dm_expr z = o->L[p];
  o->first[p] = o->nterms;
  if (o->kind[p] == K_PROD) {
    if (add_monomial(o, z, 1.0, 1, 0))
      return -1;
  } else {
    size_t ns = 0;
    double cst = 0;
    if (push(o, &ns, z, 1))
      return -1;
    while (ns > 0) {
      dm_expr x = o->stk[--ns].node;
      int s = (int)o->stk[ns].e, r = 0;
      const dm_node nd = ctx->node[x];
      long q = pos(o, x);
      if (nd.op == DM_EXPR_CONST) {
        cst += s * ctx->cval[nd.a];
        continue;
      }
      if (descend(o, x, z, K_SUM)) {
        if (nd.op == NEG)
          r = push(o, &ns, nd.a, -s);
        else
          r = push(o, &ns, nd.b, nd.op == ADD ? s : -s) || push(o, &ns, nd.a, s);
        if (r)
          return -1;
        continue;
      }
      /* a term: a monomial taken apart when it is used only here, else
       * one atom */
      if (add_monomial(o, x, s, o->kind[q] == K_PROD && o->absorbed[q], ns))
        return -1;
    }
    if (cst != 0) {
      if (dm_expr__grow(&o->terms, &o->capterms, o->nterms + 1, sizeof *o->terms))
        return -1;
      o->terms[o->nterms++] = (term){ cst, o->nfacs, 0 };
    }
  }
  o->nterm[p] = o->nterms - o->first[p];
  for (size_t t = o->first[p]; t < o->nterms; t++)
    for (size_t i = 0; i < o->terms[t].n; i++) {
      const fac *f = &o->facs[o->terms[t].off + i];
      o->freq[f->atom]++;
      if (f->e < 0)
        o->dcount[f->atom]++;
    }
  return 0;
}

/* {==================================================================
 * emitting
 * =================================================================== */

static dm_expr C2(opt *o, int op, dm_expr a, dm_expr b)
{
  if (a == DM_EXPR_NONE || b == DM_EXPR_NONE)
    return DM_EXPR_NONE;
  dm_expr r = dm_expr__cons(o->ctx, op, a, b, -1);
  if (r == DM_EXPR_NONE)
    o->nomem = 1;
  return r;
}

static dm_expr konst(opt *o, double c)
{
  dm_expr r = dm_expr_const(o->ctx, c);
  if (r == DM_EXPR_NONE)
    o->nomem = 1;
  return r;
}

/* a^e, e >= 1, by squarings and products (no powi loop). */
static dm_expr power(opt *o, dm_expr a, int e)
{
  if (e == 1 || a == DM_EXPR_NONE)
    return a;
  if (e == 2 || e == 3)
    return C2(o, POWI, a, e);
  if (e % 2 == 0)
    return C2(o, POWI, power(o, a, e / 2), 2);
  return C2(o, MUL, power(o, a, e - 1), a);
}

/* An atom's factor a^e for a product (e > 0, or e < 0 through the shared
 * reciprocal); DM_EXPR_NONE when it belongs in a denominator. */
static dm_expr num_factor(opt *o, const fac *f)
{
  dm_expr a = o->img[f->atom];
  if (f->e > 0)
    return power(o, a, f->e);
  if (o->dcount[f->atom] < 2)
    return DM_EXPR_NONE;
  return power(o, C2(o, DIV, o->one, a), -f->e);
}

static const opt *sort_opt;

/* Frequent atoms first, then by position. */
static int cmp_fac(const void *p, const void *q)
{
  const fac *x = p, *y = q;
  int32_t fx = sort_opt->freq[x->atom], fy = sort_opt->freq[y->atom];
  if (fx != fy)
    return fx > fy ? -1 : 1;
  if (x->atom != y->atom)
    return x->atom < y->atom ? -1 : 1;
  return (x->e > y->e) - (x->e < y->e);
}

static sv monomial(opt *o, fac *F, size_t n, double c)
{
  sort_opt = o;
  qsort(F, n, sizeof *F, cmp_fac);
  dm_expr num = DM_EXPR_NONE, den = DM_EXPR_NONE;
  for (size_t i = 0; i < n; i++) {
    dm_expr t = num_factor(o, &F[i]);
    if (t != DM_EXPR_NONE) {
      num = num == DM_EXPR_NONE ? t : C2(o, MUL, num, t);
    } else {
      t = power(o, o->img[F[i].atom], -F[i].e);
      den = den == DM_EXPR_NONE ? t : C2(o, MUL, den, t);
    }
  }
  if (den != DM_EXPR_NONE)
    num = C2(o, DIV, num == DM_EXPR_NONE ? o->one : num, den);
  double a = fabs(c);
  if (num == DM_EXPR_NONE)
    return (sv){ konst(o, a), c < 0 };
  if (a != 1)
    num = C2(o, MUL, konst(o, a), num);
  return (sv){ num, c < 0 };
}

static sv sv_add(opt *o, sv x, sv y)
{
  if (x.neg == y.neg)
    return (sv){ C2(o, ADD, x.n, y.n), x.neg };
  return x.neg ? (sv){ C2(o, SUB, y.n, x.n), 0 } : (sv){ C2(o, SUB, x.n, y.n), 0 };
}

typedef struct occ {
  int32_t atom, sgn;
  size_t t;
  int32_t e;
} occ;

static int cmp_occ(const void *p, const void *q)
{
  const occ *x = p, *y = q;
  if (x->atom != y->atom)
    return x->atom < y->atom ? -1 : 1;
  return (x->sgn > y->sgn) - (x->sgn < y->sgn);
}

/* {==================================================================
 * sums already emitted, found again by their terms
 * =================================================================== */

static uint64_t mix(uint64_t h)
{
  return dm_expr__mix64(h);
}

/* Hash of a term (factors in any order). */
static uint64_t term_hash(const mterm *t)
{
  uint64_t s = 0;
  for (size_t i = 0; i < t->n; i++)
    s += mix((uint64_t)(uint32_t)t->f[i].atom * 0x9e3779b97f4a7c15ULL ^
             (uint64_t)(uint32_t)t->f[i].e);
  return mix(s ^ mix(dm_expr__dbits(t->c)) ^ t->n);
}

static int same_term(const opt *o, const struct rterm *x, const mterm *y)
{
  if (x->n != y->n || dm_expr__dbits(x->c) != dm_expr__dbits(y->c))
    return 0;
  const fac *f = o->rfac + x->foff;
  for (size_t i = 0; i < x->n; i++)   /* both in canonical factor order */
    if (f[i].atom != y->f[i].atom || f[i].e != y->f[i].e)
      return 0;
  return 1;
}

/* The registered sum with hash h whose terms are T[0..nt) but T[skip]. */
static const struct sument *sum_find(const opt *o, uint64_t h, const mterm *T,
                                     size_t nt, size_t skip)
{
  size_t n = nt - (skip < nt);
  if (o->stabcap == 0 || n < 2)
    return NULL;
  size_t mask = o->stabcap - 1;
  for (size_t j = h & mask; o->stab[j] >= 0; j = (j + 1) & mask) {
    const struct sument *e = &o->sums[o->stab[j]];
    if (e->h != h || e->n != n || e->node < 0)
      continue;
    size_t hit = 0;
    for (size_t a = 0; a < n; a++)       /* small sums: every pair */
      for (size_t b = 0; b < nt; b++)
        if (b != skip && same_term(o, &o->rterm[e->off + a], &T[b])) {
          hit++;
          break;
        }
    if (hit == n)
      return e;
  }
  return NULL;
}

/* Remember T[0..nt) (hash h) as the sum with value val (DM_EXPR_NONE:
 * set later through the index returned; -1 when not remembered). */
static long sum_put(opt *o, uint64_t h, const mterm *T, size_t nt, sv val)
{
  size_t nf = 0;
  for (size_t i = 0; i < nt; i++)
    nf += T[i].n;
  if (dm_expr__grow(&o->sums, &o->capsums, o->nsums + 1, sizeof *o->sums) ||
      dm_expr__grow(&o->rterm, &o->caprterm, o->nrterm + nt, sizeof *o->rterm) ||
      dm_expr__grow(&o->rfac, &o->caprfac, o->nrfac + nf, sizeof *o->rfac))
    return -1;                         /* (only a missed reuse) */
  if (2 * (o->nsums + 1) > o->stabcap) {
    size_t cap = o->stabcap ? 2 * o->stabcap : 256;
    int32_t *t = malloc(cap * sizeof *t);
    if (t == NULL)
      return -1;
    for (size_t j = 0; j < cap; j++)
      t[j] = -1;
    for (size_t k = 0; k < o->nsums; k++) {
      size_t j = o->sums[k].h & (cap - 1);
      while (t[j] >= 0)
        j = (j + 1) & (cap - 1);
      t[j] = (int32_t)k;
    }
    free(o->stab);
    o->stab = t;
    o->stabcap = cap;
  }
  struct sument *e = &o->sums[o->nsums];
  *e = (struct sument){ h, o->nrterm, nt, val.n, val.neg };
  for (size_t i = 0; i < nt; i++) {
    o->rterm[o->nrterm++] = (struct rterm){ T[i].c, o->nrfac, T[i].n };
    memcpy(o->rfac + o->nrfac, T[i].f, T[i].n * sizeof *T[i].f);
    o->nrfac += T[i].n;
  }
  size_t j = h & (o->stabcap - 1);
  while (o->stab[j] >= 0)
    j = (j + 1) & (o->stabcap - 1);
  o->stab[j] = (int32_t)o->nsums;
  return (long)o->nsums++;
}

/* Terms in a canonical order (by their sorted factors, then |c|), so that
 * equal sums give equal nodes and -S gives the negation of S exactly. */
static int cmp_term(const void *p, const void *q)
{
  const mterm *x = p, *y = q;
  for (size_t i = 0; i < x->n && i < y->n; i++) {
    int r = cmp_fac(&x->f[i], &y->f[i]);
    if (r != 0)
      return r;
  }
  if (x->n != y->n)
    return x->n < y->n ? -1 : 1;
  double a = fabs(x->c), b = fabs(y->c);
  return (a > b) - (a < b);
}

static void canon_terms(opt *o, mterm *T, size_t nt)
{
  sort_opt = o;
  for (size_t i = 0; i < nt; i++)
    qsort(T[i].f, T[i].n, sizeof *T[i].f, cmp_fac);
  qsort(T, nt, sizeof *T, cmp_term);
}

static sv factor_new(opt *o, mterm *T, size_t nt);

/* The sum of T[0..nt), greedily factored, or found among the sums emitted
 * before (also when it is one of them plus a term); T's factor arrays
 * may be reordered. */
static sv factor(opt *o, mterm *T, size_t nt)
{
  sv bad = { DM_EXPR_NONE, 0 };
  if (o->nomem)
    return bad;
  if (nt == 0)
    return (sv){ konst(o, 0.0), 0 };
  if (nt == 1)
    return monomial(o, T[0].f, T[0].n, T[0].c);
  /* this sum, or it but one term, emitted before? */
  sort_opt = o;
  uint64_t H = 0, *ht = malloc(nt * sizeof *ht);
  if (ht == NULL) {
    o->nomem = 1;
    return bad;
  }
  for (size_t i = 0; i < nt; i++) {
    qsort(T[i].f, T[i].n, sizeof *T[i].f, cmp_fac);
    H += ht[i] = term_hash(&T[i]);
  }
  const struct sument *e = sum_find(o, H, T, nt, nt);
  for (size_t i = 0; e == NULL && i < nt; i++)
    if ((e = sum_find(o, H - ht[i], T, nt, i)) != NULL) {
      sv r = sv_add(o, (sv){ e->node, e->neg },
                    monomial(o, T[i].f, T[i].n, T[i].c));
      sum_put(o, H, T, nt, r);
      free(ht);
      return r;
    }
  free(ht);
  if (e != NULL)
    return (sv){ e->node, e->neg };
  long k = sum_put(o, H, T, nt, bad);  /* before factor_new changes T */
  sv res = factor_new(o, T, nt);
  if (k >= 0) {
    o->sums[k].node = res.n;
    o->sums[k].neg = res.neg;
  }
  return res;
}

/* factor() of a sum not seen before. */
static sv factor_new(opt *o, mterm *T, size_t nt)
{
  sv bad = { DM_EXPR_NONE, 0 };
  size_t nocc = 0;
  for (size_t i = 0; i < nt; i++)
    nocc += T[i].n;
  occ *O = malloc((nocc + 1) * sizeof *O);
  if (O == NULL) {
    o->nomem = 1;
    return bad;
  }
  nocc = 0;
  for (size_t i = 0; i < nt; i++)
    for (size_t j = 0; j < T[i].n; j++)
      O[nocc++] = (occ){ T[i].f[j].atom, T[i].f[j].e > 0 ? 1 : -1, i,
                         abs(T[i].f[j].e) };
  qsort(O, nocc, sizeof *O, cmp_occ);
  /* the atom (with the sign of its exponent) in the most terms */
  size_t best = 0, bestn = 1, i = 0;
  while (i < nocc) {
    size_t j = i;
    while (j < nocc && cmp_occ(&O[i], &O[j]) == 0)
      j++;
    if (j - i > bestn || (j - i == bestn && bestn > 1 &&
        o->freq[O[i].atom] > o->freq[O[best].atom])) {
      best = i;
      bestn = j - i;
    }
    i = j;
  }
  sv r;
  if (bestn < 2) {                       /* nothing common: a plain sum */
    free(O);
    canon_terms(o, T, nt);
    r = monomial(o, T[0].f, T[0].n, T[0].c);
    for (size_t k = 1; k < nt; k++)
      r = sv_add(o, r, monomial(o, T[k].f, T[k].n, T[k].c));
    return r;
  }
  int32_t atom = O[best].atom, sgn = O[best].sgn, m = INT32_MAX;
  for (size_t k = best; k < best + bestn; k++)
    if (O[k].e < m)
      m = O[k].e;
  free(O);
  /* inner: the terms with atom^(sgn m) divided out; rest: the others */
  mterm *in = malloc(nt * sizeof *in), *rest = malloc(nt * sizeof *rest);
  size_t nin = 0, nrest = 0;
  if (in == NULL || rest == NULL) {
    free(in);
    free(rest);
    o->nomem = 1;
    return bad;
  }
  for (size_t k = 0; k < nt; k++) {
    size_t j = 0;
    while (j < T[k].n && !(T[k].f[j].atom == atom &&
                           (T[k].f[j].e > 0 ? 1 : -1) == sgn))
      j++;
    if (j == T[k].n) {
      rest[nrest++] = T[k];
      continue;
    }
    T[k].f[j].e -= sgn * m;
    if (T[k].f[j].e == 0) {
      T[k].f[j] = T[k].f[T[k].n - 1];
      T[k].n--;
    }
    in[nin++] = T[k];
  }
  sv x = factor(o, in, nin);
  free(in);
  fac f = { atom, sgn * m };
  dm_expr t = num_factor(o, &f);
  if (t != DM_EXPR_NONE)
    r = (sv){ C2(o, MUL, t, x.n), x.neg };
  else
    r = (sv){ C2(o, DIV, x.n, power(o, o->img[atom], m)), x.neg };
  if (nrest > 0)
    r = sv_add(o, r, factor(o, rest, nrest));
  free(rest);
  return r;
}

/* The rewritten node of the root at position p. */
static dm_expr emit_root(opt *o, long p)
{
  dm_expr_ctx *ctx = o->ctx;
  dm_expr x = o->L[p];
  const dm_node nd = ctx->node[x];
  if (o->kind[p] == K_OTHER) {
    int k = dm_expr__arity(nd.op);
    if (k == 0)
      return x;
    dm_expr a = o->img[pos(o, nd.a)];
    dm_expr b = k >= 2 ? o->img[pos(o, nd.b)] : (nd.op == POWI ? nd.b : -1);
    dm_expr c = k >= 3 ? o->img[pos(o, nd.c)] : -1;
    if (a == nd.a && (k < 2 || b == nd.b) && (k < 3 || c == nd.c))
      return x;
    dm_expr r = dm_expr__cons(ctx, nd.op, a, b, c);
    if (r == DM_EXPR_NONE)
      o->nomem = 1;
    return r;
  }
  /* -y of a y computed already: a negation (exact, so that expressions
   * built as each other's negatives, like the two halves of an
   * antisymmetric matrix, stay exact negatives) */
  dm_expr y = dm_expr_neg(ctx, x);
  if (y >= 0 && (size_t)y < o->nold && ctx->stamp[y] == ctx->epoch) {
    long q = pos(o, y);
    if (q < p && !o->absorbed[q]) {
      dm_expr r = dm_expr__cons(ctx, NEG, o->img[q], -1, -1);
      if (r == DM_EXPR_NONE)
        o->nomem = 1;
      return r;
    }
  }
  size_t nt = o->nterm[p], nf = 0;
  for (size_t t = 0; t < nt; t++)
    nf += o->terms[o->first[p] + t].n;
  mterm *T = malloc((nt + 1) * sizeof *T);
  fac *F = malloc((nf + 1) * sizeof *F);
  if (T == NULL || F == NULL) {
    free(T);
    free(F);
    o->nomem = 1;
    return DM_EXPR_NONE;
  }
  nf = 0;
  for (size_t t = 0; t < nt; t++) {
    const term *tm = &o->terms[o->first[p] + t];
    memcpy(F + nf, o->facs + tm->off, tm->n * sizeof *F);
    T[t] = (mterm){ tm->c, F + nf, tm->n };
    nf += tm->n;
  }
  sv r = factor(o, T, nt);
  free(T);
  free(F);
  if (r.neg && r.n != DM_EXPR_NONE) {
    r.n = dm_expr__cons(ctx, NEG, r.n, -1, -1);
    if (r.n == DM_EXPR_NONE)
      o->nomem = 1;
  }
  return r.n;
}

/* {==================================================================
 * driver
 * =================================================================== */

static void opt_free(opt *o)
{
  free(o->L);
  free(o->uses);
  free(o->parent);
  free(o->kind);
  free(o->isout);
  free(o->absorbed);
  free(o->img);
  free(o->first);
  free(o->nterm);
  free(o->terms);
  free(o->facs);
  free(o->dcount);
  free(o->freq);
  free(o->stk);
  free(o->sums);
  free(o->stab);
  free(o->rterm);
  free(o->rfac);
}

int dm_tape__optimize(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                      dm_expr *nw, dm_err *err)
{
  opt o;
  memset(&o, 0, sizeof o);
  o.ctx = ctx;
  o.one = dm_expr_const(ctx, 1.0);
  o.nold = ctx->n;
  long nl = dm_expr__collect(ctx, nout, out);
  if (nl < 0 || o.one == DM_EXPR_NONE)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  size_t sz = (size_t)(nl ? nl : 1);
  o.nl = nl;
  o.L = malloc(sz * sizeof *o.L);
  o.uses = calloc(sz, sizeof *o.uses);
  o.parent = malloc(sz * sizeof *o.parent);
  o.kind = malloc(sz);
  o.isout = calloc(sz, 1);
  o.absorbed = calloc(sz, 1);
  o.img = malloc(sz * sizeof *o.img);
  o.first = calloc(sz, sizeof *o.first);
  o.nterm = calloc(sz, sizeof *o.nterm);
  o.dcount = calloc(sz, sizeof *o.dcount);
  o.freq = calloc(sz, sizeof *o.freq);
  if (!o.L || !o.uses || !o.parent || !o.kind || !o.isout || !o.absorbed ||
      !o.img || !o.first || !o.nterm || !o.dcount || !o.freq) {
    opt_free(&o);
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  }
  memcpy(o.L, ctx->list, sz * sizeof *o.L);
  for (long p = 0; p < nl; p++) {
    ctx->aux[o.L[p]] = (int32_t)p;    /* positions (aux is ours now) */
    o.kind[p] = (uint8_t)node_kind(ctx, o.L[p]);
    o.parent[p] = -1;
  }
  for (long p = 0; p < nl; p++) {
    const dm_node nd = ctx->node[o.L[p]];
    int k = dm_expr__arity(nd.op);
    int32_t ops[3] = { nd.a, nd.b, nd.c };
    for (int j = 0; j < k; j++) {
      long q = pos(&o, ops[j]);
      o.uses[q]++;
      o.parent[q] = (int32_t)p;
    }
  }
  for (size_t k = 0; k < nout; k++)
    o.isout[pos(&o, out[k])] = 1;
  /* a sum inside a sum, or a product inside a sum or product, used only
   * there, is taken apart by its user */
  for (long p = 0; p < nl; p++) {
    if (o.uses[p] != 1 || o.isout[p] || o.kind[p] == K_OTHER)
      continue;
    int pk = o.kind[o.parent[p]];
    o.absorbed[p] = o.kind[p] == K_SUM ? pk == K_SUM : pk != K_OTHER;
  }
  int s = DM_OK;
  for (long p = 0; p < nl && s == DM_OK; p++)
    if (o.kind[p] != K_OTHER && !o.absorbed[p] && build_ir(&o, p))
      s = DM_ENOMEM;
  for (long p = 0; p < nl && s == DM_OK; p++) {
    if (o.absorbed[p])
      continue;
    o.img[p] = emit_root(&o, p);
    if (o.nomem || o.img[p] == DM_EXPR_NONE)
      s = DM_ENOMEM;
  }
  if (s == DM_OK)
    for (size_t k = 0; k < nout; k++)
      nw[k] = o.img[pos(&o, out[k])];
  opt_free(&o);
  if (s != DM_OK)
    return dm_err_set(err, DM_ENOMEM, "tape: out of memory");
  return DM_OK;
}
