/* composition.c -- symmetric compositions of a symmetric second-order step
 * Phi_h = B_{g_s h} o ... o B_{g_1 h} with published coefficient tables
 * (g symmetric, sum g = 1).  The base step B is the trapezoid rule
 * (explicit Stormer-Verlet for separable L, implicit Lobatto IIIA-IIIB 2
 * otherwise, RATTLE with constraints) or the implicit midpoint rule
 * (option base).  The composition is symplectic and symmetric and raises
 * the order to 4, 6 or 8.
 *
 * Tables (first half up to and including the middle coefficient):
 *  yoshida4   s=3,  order 4: H. Yoshida, Construction of higher order
 *             symplectic integrators, Phys. Lett. A 150 (1990) 262-268
 *             (the "triple jump", g1 = 1/(2 - 2^(1/3))).
 *  yoshida6   s=7,  order 6: ibid., solution A.
 *  kahanli6   s=9,  order 6: W. Kahan, R.-C. Li, Composition constants for
 *             raising the orders of unconventional schemes for ordinary
 *             differential equations, Math. Comp. 66 (1997) 1089-1099, s9odr6a.
 *  mclachlan8 s=15, order 8: R. I. McLachlan, On the numerical integration of
 *             ordinary differential equations by symmetric composition methods,
 *             SIAM J. Sci. Comput. 16 (1995) 151-168 (also M. Suzuki, K. Umeno 1993).
 *  kahanli8   s=17, order 8: Kahan & Li (1997), s17odr8a.
 */
#include <config.h>
#include "integrators/prk_impl.h"
#include "core/interrupt.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double yoshida4[] = {1.351207191959657634047687808971460827,
                                  -1.702414383919315268095375617942921654};
static const double yoshida6[] = {0.78451361047755726381949763, 0.23557321335935813368479318,
                                  -1.17767998417887100694641568, 1.31518632068391121888424973};
static const double kahanli6[] = {0.39216144400731413927925056, 0.33259913678935943859974864,
                                  -0.70624617255763935980996482, 0.08221359629355080023149045,
                                  0.79854399093482996339895035};
static const double mclachlan8[] = {0.74167036435061295344822780, -0.40910082580003159399730010,
                                    0.19075471029623837995387626, -0.57386247111608226665638773,
                                    0.29906418130365592384446354, 0.33462491824529818378495798,
                                    0.31529309239676659663205666, -0.79688793935291635401978884};
static const double kahanli8[] = {0.13020248308889008087881763, 0.56116298177510838456196441,
                                  -0.38947496264484728640807860, 0.15884190655515560089621075,
                                  -0.39590389413323757733623154, 0.18453964097831570709183254,
                                  0.25837438768632204729397911, 0.29501172360931029887096624,
                                  -0.60550853383003451169892108};

typedef struct comp_scheme {
  const char *name;
  int order;
  size_t s;               /* number of base steps (odd) */
  const double *half;     /* (s + 1) / 2 coefficients */
} comp_scheme;

static const comp_scheme schemes[] = {
  {"yoshida4", 4, 3, yoshida4},
  {"yoshida6", 6, 7, yoshida6},
  {"kahanli6", 6, 9, kahanli6},
  {"mclachlan8", 8, 15, mclachlan8},
  {"kahanli8", 8, 17, kahanli8},
};

typedef struct comp_state {
  dm_integrator *inner;
  const comp_scheme *sc;
  double g[17];
  double *zq, *zp, *D, *Dk, *T;   /* n, n, 4n^2 x 3 */
} comp_state;

static const char *const comp_options[] = {"order", "scheme", "base", "h", "tol", "maxiter",
                                           "simplified", "explicit", NULL};

static void comp_free(dm_integrator *I)
{
  comp_state *C = I->state;
  if (C == NULL)
    return;
  dm_integrator_free(C->inner);
  free(C->zq);
  free(C);
  I->state = NULL;
}

/* The scheme named `want`, or for "" the default of the order. */
static const comp_scheme *find_scheme(const char *want, int order, dm_err *e)
{
  size_t i;
  if (!want[0]) {
    want = order == 4 ? "yoshida4" : order == 6 ? "kahanli6" : order == 8 ? "kahanli8" : NULL;
    if (want == NULL) {
      dm_err_set(e, DM_EINVAL, "composition: order = %d not available (4, 6 or 8)", order);
      return NULL;
    }
  }
  for (i = 0; i < sizeof schemes / sizeof schemes[0]; i++)
    if (strcmp(want, schemes[i].name) == 0)
      return &schemes[i];
  dm_err_set(e, DM_ENOTFOUND, "composition: unknown scheme '%s' (known: yoshida4, "
             "yoshida6, kahanli6, mclachlan8, kahanli8)", want);
  return NULL;
}

int dm_composition_coeffs(const char *scheme, int order, double *g, size_t *s,
                          int *order_out, dm_err *e)
{
  dm_err le;
  const comp_scheme *sc = find_scheme(scheme, order, &le);
  size_t i;
  if (sc == NULL)
    return dm_err_set(e, le.status, "%s", le.msg);
  for (i = 0; i < sc->s; i++)
    g[i] = sc->half[i < (sc->s + 1) / 2 ? i : sc->s - 1 - i];
  *s = sc->s;
  *order_out = sc->order;
  return DM_OK;
}

static int comp_alloc(dm_integrator *I, dm_err *e)
{
  const char *want = I->variant[0] ? I->variant : I->opt.scheme;
  const comp_scheme *sc = NULL;
  comp_state *C;
  dm_integ_opts o = I->opt;
  size_t i, n = I->n, s;
  int st;
  dm_err le;
  if ((sc = find_scheme(want, I->opt.order, &le)) == NULL)
    return dm_err_set(e, le.status, "%s", le.msg);
  if (strcmp(I->opt.base, "trapezoid") != 0 && strcmp(I->opt.base, "midpoint") != 0)
    return dm_err_set(e, DM_EINVAL, "composition: base must be 'trapezoid' or 'midpoint' (got '%s')",
                      I->opt.base);
  if ((C = calloc(1, sizeof *C)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "composition: out of memory");
  I->state = C;
  C->sc = sc;
  s = sc->s;
  for (i = 0; i < s; i++)
    C->g[i] = sc->half[i < (s + 1) / 2 ? i : s - 1 - i];
  C->zq = calloc(2 * n + 12 * n * n, sizeof(double));
  if (C->zq == NULL) {
    comp_free(I);
    return dm_err_set(e, DM_ENOMEM, "composition: out of memory");
  }
  C->zp = C->zq + n;
  C->D = C->zp + n;
  C->Dk = C->D + 4 * n * n;
  C->T = C->Dk + 4 * n * n;
  o.stages = 0;
  o.tableau = NULL;
  if ((st = dm_integrator_new(I->sys, I->opt.base, &o, &C->inner, e)) != DM_OK) {
    comp_free(I);
    return st;
  }
  I->order = sc->order;
  I->flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS
             | (C->inner->flags & (DM_INTEG_EXPLICIT | DM_INTEG_EXACT_JAC));
  return DM_OK;
}

static int comp_step(dm_integrator *I, double h, const double *q0, const double *p0,
                     double *q1, double *p1, dm_err *e)
{
  comp_state *C = I->state;
  size_t n = I->n, k;
  int it = 0, st;
  memcpy(C->zq, q0, n * sizeof(double));
  memcpy(C->zp, p0, n * sizeof(double));
  for (k = 0; k < C->sc->s; k++) {
    if ((st = C->inner->type->step(C->inner, C->g[k] * h, C->zq, C->zp, C->zq, C->zp, e)) != DM_OK) {
      I->stats = C->inner->stats;
      return st;
    }
    it += C->inner->stats.iters;
  }
  memcpy(q1, C->zq, n * sizeof(double));
  memcpy(p1, C->zp, n * sizeof(double));
  I->stats.iters = it;
  I->stats.residual = C->inner->stats.residual;
  I->stats.tol = C->inner->stats.tol;
  I->stats.iters_total += it;
  I->stats.steps++;
  return DM_OK;
}

/* The run loop's fast path: with the explicit Stormer-Verlet base, the
 * substeps run in the base engine's fused loop (one force per substep,
 * the same arithmetic as stepping); otherwise step() in place (it writes
 * its outputs only on success). */
static int comp_advance(dm_integrator *I, double h, long nsteps, double *q, double *p,
                        long *done, dm_err *e)
{
  comp_state *C = I->state;
  dm_integrator *B = C->inner;
  long k;
  int st = DM_OK;
  if (B->type->step == dm_prk_type_step && B->m == 0 && dm_prk_is_explicit(B->state)) {
    long before = I->stats.steps;
    st = dm_prk_verlet_advance(B->state, h, C->g, C->sc->s, nsteps, q, p, done, &I->stats, e);
    B->stats.steps += (I->stats.steps - before) * (long)C->sc->s;
    return st;
  }
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = DM_EINTR;
      break;
    }
    if ((st = comp_step(I, h, q, p, q, p, e)) != DM_OK)
      break;
  }
  *done = k;
  return st;
}

/* Chain rule: DPhi = D_s ... D_1 with each base Jacobian at its substep. */
static int comp_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                         double *DPhi, dm_err *e)
{
  comp_state *C = I->state;
  size_t n = I->n, N = 2 * n, k, i, j, l;
  int st;
  if (C->inner->type->jacobian == NULL)
    return dm_err_set(e, DM_EUNSUP, "composition: the base step has no Jacobian");
  memcpy(C->zq, q0, n * sizeof(double));
  memcpy(C->zp, p0, n * sizeof(double));
  for (i = 0; i < N * N; i++)
    C->D[i] = (i / N == i % N) ? 1.0 : 0.0;
  for (k = 0; k < C->sc->s; k++) {
    double hk = C->g[k] * h;
    if ((st = C->inner->type->jacobian(C->inner, hk, C->zq, C->zp, C->Dk, e)) != DM_OK)
      return st;
    for (i = 0; i < N; i++)
      for (j = 0; j < N; j++) {
        double acc = 0.0;
        for (l = 0; l < N; l++)
          acc += C->Dk[i * N + l] * C->D[l * N + j];
        C->T[i * N + j] = acc;
      }
    memcpy(C->D, C->T, N * N * sizeof(double));
    if ((st = C->inner->type->step(C->inner, hk, C->zq, C->zp, C->zq, C->zp, e)) != DM_OK)
      return st;
  }
  memcpy(DPhi, C->D, N * N * sizeof(double));
  return DM_OK;
}

static void comp_reset(dm_integrator *I)
{
  comp_state *C = I->state;
  dm_integrator_reset(C->inner);
}

const dm_integrator_type dm_integ_composition = {
  .name = "composition",
  .summary = "symmetric composition of the trapezoid (Stormer-Verlet) or midpoint step: order 4, 6, 8 "
    "(yoshida4, yoshida6, kahanli6, mclachlan8, kahanli8)",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_SYMMETRIC | DM_INTEG_FORCES | DM_INTEG_CONSTRAINTS,
  .options = comp_options,
  .alloc = comp_alloc,
  .step = comp_step,
  .jacobian = comp_jacobian,
  .dlegendre = NULL,
  .advance = comp_advance,
  .reset = comp_reset,
  .free = comp_free,
};
