/* product.c -- finite direct products G1 x ... x Gk: every operation factor
 * by factor, matrices block diagonal (offsets in the descriptor). */
#include <config.h>
#include <string.h>

#include "lie/lie_impl.h"

#define FOR_FAC(G, i) for ((i) = 0; (i) < (G)->nfac; (i)++)
#define FAC(G, i) ((const dm_lie_group *)(G)->fac[i])

static void pr_identity(const dm_lie_group *G, double *g)
{
  size_t i;
  FOR_FAC(G, i) FAC(G, i)->type->identity(FAC(G, i), g + G->qoff[i]);
}

static void pr_compose(const dm_lie_group *G, const double *a, const double *b, double *ab)
{
  size_t i, o;
  FOR_FAC(G, i) {
    o = G->qoff[i];
    FAC(G, i)->type->compose(FAC(G, i), a + o, b + o, ab + o);
  }
}

static void pr_inverse(const dm_lie_group *G, const double *a, double *ai)
{
  size_t i, o;
  FOR_FAC(G, i) {
    o = G->qoff[i];
    FAC(G, i)->type->inverse(FAC(G, i), a + o, ai + o);
  }
}

static void pr_exp(const dm_lie_group *G, const double *xi, double *g)
{
  size_t i;
  FOR_FAC(G, i) FAC(G, i)->type->exp(FAC(G, i), xi + G->xoff[i], g + G->qoff[i]);
}

static void pr_log(const dm_lie_group *G, const double *g, double *xi)
{
  size_t i;
  FOR_FAC(G, i) FAC(G, i)->type->log(FAC(G, i), g + G->qoff[i], xi + G->xoff[i]);
}

static void pr_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  size_t i, o;
  dm_lie_zero(M, G->dim, G->dim, ld);
  FOR_FAC(G, i) {
    o = G->xoff[i];
    FAC(G, i)->type->Ad(FAC(G, i), g + G->qoff[i], M + o * ld + o, ld);
  }
}

static void pr_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld)
{
  size_t i, o;
  dm_lie_zero(M, G->dim, G->dim, ld);
  FOR_FAC(G, i) {
    o = G->xoff[i];
    FAC(G, i)->type->ad(FAC(G, i), xi + o, M + o * ld + o, ld);
  }
}

static void pr_bracket(const dm_lie_group *G, const double *a, const double *b, double *c)
{
  size_t i, o;
  FOR_FAC(G, i) {
    o = G->xoff[i];
    FAC(G, i)->type->bracket(FAC(G, i), a + o, b + o, c + o);
  }
}

static void pr_dexp(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  size_t i, o;
  dm_lie_zero(M, G->dim, G->dim, ld);
  FOR_FAC(G, i) {
    o = G->xoff[i];
    FAC(G, i)->type->dexp(FAC(G, i), xi + o, inv, M + o * ld + o, ld);
  }
}

static void pr_cay(const dm_lie_group *G, const double *xi, double *g)
{
  size_t i;
  FOR_FAC(G, i) FAC(G, i)->type->cay(FAC(G, i), xi + G->xoff[i], g + G->qoff[i]);
}

static int pr_icay(const dm_lie_group *G, const double *g, double *xi)
{
  size_t i;
  FOR_FAC(G, i)
    if (FAC(G, i)->type->icay(FAC(G, i), g + G->qoff[i], xi + G->xoff[i]) != DM_OK)
      return DM_EDOM;
  return DM_OK;
}

static void pr_dcay(const dm_lie_group *G, const double *xi, int inv, double *M, size_t ld)
{
  size_t i, o;
  dm_lie_zero(M, G->dim, G->dim, ld);
  FOR_FAC(G, i) {
    o = G->xoff[i];
    FAC(G, i)->type->dcay(FAC(G, i), xi + o, inv, M + o * ld + o, ld);
  }
}

static void pr_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  size_t i, o;
  dm_lie_zero(A, G->msize, G->msize, ld);
  FOR_FAC(G, i) {
    o = G->moff[i];
    FAC(G, i)->type->hat(FAC(G, i), xi + G->xoff[i], A + o * ld + o, ld);
  }
}

static void pr_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  size_t i, o;
  FOR_FAC(G, i) {
    o = G->moff[i];
    FAC(G, i)->type->vee(FAC(G, i), A + o * ld + o, ld, xi + G->xoff[i]);
  }
}

static void pr_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  size_t i, o;
  dm_lie_zero(M, G->msize, G->msize, ld);
  FOR_FAC(G, i) {
    o = G->moff[i];
    FAC(G, i)->type->matrix(FAC(G, i), g + G->qoff[i], M + o * ld + o, ld);
  }
}

/* the blocks, and zeros outside them */
static int pr_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g)
{
  size_t i, r, c, f = 0;
  for (r = 0; r < G->msize; r++) {
    while (r >= G->moff[f + 1])
      f++;
    for (c = 0; c < G->msize; c++)
      if ((c < G->moff[f] || c >= G->moff[f + 1]) && fabs(M[r * ld + c]) > 1e-12)
        return DM_EDOM;
  }
  FOR_FAC(G, i) {
    size_t o = G->moff[i];
    if (FAC(G, i)->type->from_matrix(FAC(G, i), M + o * ld + o, ld, g + G->qoff[i]) != DM_OK)
      return DM_EDOM;
  }
  return DM_OK;
}

static void pr_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  size_t i, o;
  FOR_FAC(G, i) {
    o = G->koff[i];
    FAC(G, i)->type->act(FAC(G, i), g + G->qoff[i], x + o, y + o);
  }
}

static void pr_normalize(const dm_lie_group *G, double *g)
{
  size_t i;
  FOR_FAC(G, i) FAC(G, i)->type->normalize(FAC(G, i), g + G->qoff[i]);
}

static double pr_defect(const dm_lie_group *G, const double *g, int *det_ok)
{
  double m = 0.0, d;
  size_t i;
  int ok = 1, k;
  FOR_FAC(G, i) {
    d = FAC(G, i)->type->defect(FAC(G, i), g + G->qoff[i], &k);
    m = d > m || d != d ? d : m;
    ok = ok && k;
  }
  if (det_ok)
    *det_ok = ok;
  return m;
}

static void pr_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                         double *dg)
{
  size_t i = 0;
  memset(dg, 0, G->nq * sizeof *dg);
  while (k >= G->xoff[i + 1])
    i++;
  FAC(G, i)->type->generator(FAC(G, i), g + G->qoff[i], k - G->xoff[i], side,
                             dg + G->qoff[i]);
}

const dm_lie_type dm_lie_type_product = {
  "product", DM_LIE_PRODUCT, pr_identity, pr_compose, pr_inverse, pr_exp, pr_log,
  pr_Ad, pr_ad, pr_bracket, pr_dexp, pr_cay, pr_icay, pr_dcay, pr_hat, pr_vee,
  pr_matrix, pr_from_matrix, pr_act, pr_normalize, pr_defect, pr_generator, &dm_lie_sym_product
};
