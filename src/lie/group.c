/* group.c -- group descriptors (construction, products, copies) and the
 * dispatching entry points of lie.h, with the messages of the partial
 * operations. */
#include <config.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_impl.h"
#include "core/numfmt.h"

/* {==== construction ===================================================== */

static dm_lie_group *new_group(const dm_lie_type *type, size_t n, size_t nq, size_t dim,
                               size_t msize, size_t kdim, int abelian, dm_err *e)
{
  dm_lie_group *G = calloc(1, sizeof *G);
  if (G == NULL) {
    dm_err_set(e, DM_ENOMEM, "Lie group: out of memory");
    return NULL;
  }
  G->type = type;
  G->kind = type->kind;
  G->n = n;
  G->nq = nq;
  G->dim = dim;
  G->msize = msize;
  G->kdim = kdim;
  G->abelian = abelian;
  return G;
}

static int check_n(const char *what, size_t n, dm_err *e)
{
  if (n < 1 || n > DM_LIE_DIM_MAX)
    return dm_err_set(e, DM_EINVAL, "%s: dimension n = %zu out of range 1..%d", what, n,
                      DM_LIE_DIM_MAX);
  return DM_OK;
}

dm_lie_group *dm_lie_rn(size_t n, dm_err *e)
{
  dm_lie_group *G;
  if (check_n("R^n", n, e) != DM_OK)
    return NULL;
  if ((G = new_group(&dm_lie_type_rn, n, n, n, n + 1, n, 1, e)) != NULL)
    snprintf(G->name, sizeof G->name, "R%zu", n);
  return G;
}

dm_lie_group *dm_lie_so2(dm_err *e)
{
  dm_lie_group *G = new_group(&dm_lie_type_so2, 1, 1, 1, 2, 2, 1, e);
  if (G)
    strcpy(G->name, "SO2");
  return G;
}

dm_lie_group *dm_lie_torus(size_t n, dm_err *e)
{
  dm_lie_group *G;
  if (check_n("T^n", n, e) != DM_OK)
    return NULL;
  if ((G = new_group(&dm_lie_type_tn, n, n, n, 2 * n, 2 * n, 1, e)) != NULL)
    snprintf(G->name, sizeof G->name, "T%zu", n);
  return G;
}

dm_lie_group *dm_lie_so3(dm_err *e)
{
  dm_lie_group *G = new_group(&dm_lie_type_so3, 0, 9, 3, 3, 3, 0, e);
  if (G)
    strcpy(G->name, "SO3");
  return G;
}

dm_lie_group *dm_lie_se2(dm_err *e)
{
  dm_lie_group *G = new_group(&dm_lie_type_se2, 0, 3, 3, 3, 2, 0, e);
  if (G)
    strcpy(G->name, "SE2");
  return G;
}

dm_lie_group *dm_lie_se3(dm_err *e)
{
  dm_lie_group *G = new_group(&dm_lie_type_se3, 0, 12, 6, 4, 3, 0, e);
  if (G)
    strcpy(G->name, "SE3");
  return G;
}

static dm_lie_group *copy_simple(const dm_lie_group *F, dm_err *e)
{
  dm_lie_group *G = new_group(F->type, F->n, F->nq, F->dim, F->msize, F->kdim, F->abelian, e);
  if (G)
    memcpy(G->name, F->name, sizeof G->name);
  return G;
}

dm_lie_group *dm_lie_product(size_t k, const dm_lie_group *const *fac, dm_err *e)
{
  const dm_lie_group *flat[DM_LIE_FAC_MAX];
  size_t nf = 0, i, j, nq = 0, dim = 0, ms = 0, kd = 0, len = 0;
  dm_lie_group *G;
  int ab = 1;
  if (k == 0 || fac == NULL) {
    dm_err_set(e, DM_EINVAL, "product: needs at least one factor");
    return NULL;
  }
  for (i = 0; i < k; i++) {
    const dm_lie_group *F = fac[i];
    size_t m = F->kind == DM_LIE_PRODUCT ? F->nfac : 1;
    for (j = 0; j < m; j++) {
      if (nf == DM_LIE_FAC_MAX) {
        dm_err_set(e, DM_EINVAL, "product: more than %d factors", DM_LIE_FAC_MAX);
        return NULL;
      }
      flat[nf++] = F->kind == DM_LIE_PRODUCT ? F->fac[j] : F;
    }
  }
  for (i = 0; i < nf; i++) {
    nq += flat[i]->nq;
    dim += flat[i]->dim;
    ms += flat[i]->msize;
    kd += flat[i]->kdim;
    ab = ab && flat[i]->abelian;
    len += strlen(flat[i]->name) + 1;
  }
  if (nq > DM_LIE_NQ_MAX || dim > DM_LIE_DIM_MAX || len > sizeof G->name) {
    dm_err_set(e, DM_EINVAL, "product: too large (%zu doubles per element, dimension %zu; "
               "limits %d and %d)", nq, dim, DM_LIE_NQ_MAX, DM_LIE_DIM_MAX);
    return NULL;
  }
  if ((G = new_group(&dm_lie_type_product, 0, nq, dim, ms, kd, ab, e)) == NULL)
    return NULL;
  G->fac = calloc(nf, sizeof *G->fac);
  G->qoff = calloc(4 * (nf + 1), sizeof *G->qoff);
  if (G->fac == NULL || G->qoff == NULL) {
    dm_lie_group_free(G);
    dm_err_set(e, DM_ENOMEM, "product: out of memory");
    return NULL;
  }
  G->nfac = nf;
  G->xoff = G->qoff + (nf + 1);
  G->moff = G->xoff + (nf + 1);
  G->koff = G->moff + (nf + 1);
  for (i = 0; i < nf; i++) {
    if ((G->fac[i] = copy_simple(flat[i], e)) == NULL) {
      dm_lie_group_free(G);
      return NULL;
    }
    G->qoff[i + 1] = G->qoff[i] + flat[i]->nq;
    G->xoff[i + 1] = G->xoff[i] + flat[i]->dim;
    G->moff[i + 1] = G->moff[i] + flat[i]->msize;
    G->koff[i + 1] = G->koff[i] + flat[i]->kdim;
    if (i)
      strcat(G->name, "x");
    strcat(G->name, flat[i]->name);
  }
  return G;
}

dm_lie_group *dm_lie_group_copy(const dm_lie_group *G, dm_err *e)
{
  if (G->kind == DM_LIE_PRODUCT)
    return dm_lie_product(1, &G, e);
  return copy_simple(G, e);
}

void dm_lie_group_free(dm_lie_group *G)
{
  size_t i;
  if (G == NULL)
    return;
  for (i = 0; G->fac && i < G->nfac; i++)
    dm_lie_group_free(G->fac[i]);
  free(G->fac);
  free(G->qoff);
  free(G);
}

int dm_lie_group_equal(const dm_lie_group *G, const dm_lie_group *H)
{
  size_t i;
  if (G->kind != H->kind || G->nq != H->nq || G->dim != H->dim || G->n != H->n ||
      G->nfac != H->nfac)
    return 0;
  for (i = 0; i < G->nfac; i++)
    if (!dm_lie_group_equal(G->fac[i], H->fac[i]))
      return 0;
  return 1;
}

/* "SO3" | "SE3" | "SO2" | "SE2" | "R<n>" | "T<n>" */
static dm_lie_group *parse_one(const char *s, size_t len, dm_err *e)
{
  char buf[16];
  if (len == 0 || len >= sizeof buf) {
    dm_err_set(e, DM_EINVAL, "Lie group name: cannot read '%.*s' (expected SO2, SO3, SE2, SE3, "
               "R<n> or T<n>)", (int)len, s);
    return NULL;
  }
  memcpy(buf, s, len);
  buf[len] = '\0';
  if (strcmp(buf, "SO3") == 0)
    return dm_lie_so3(e);
  if (strcmp(buf, "SE3") == 0)
    return dm_lie_se3(e);
  if (strcmp(buf, "SO2") == 0)
    return dm_lie_so2(e);
  if (strcmp(buf, "SE2") == 0)
    return dm_lie_se2(e);
  if ((buf[0] == 'R' || buf[0] == 'T') && buf[1] >= '1' && buf[1] <= '9') {
    char *end;
    unsigned long n = strtoul(buf + 1, &end, 10);
    if (*end == '\0')
      return buf[0] == 'R' ? dm_lie_rn(n, e) : dm_lie_torus(n, e);
  }
  dm_err_set(e, DM_EINVAL, "Lie group name: cannot read '%s' (expected SO2, SO3, SE2, SE3, "
             "R<n> or T<n>)", buf);
  return NULL;
}

dm_lie_group *dm_lie_group_parse(const char *name, dm_err *e)
{
  dm_lie_group *fac[DM_LIE_FAC_MAX], *G = NULL;
  size_t k = 0, i;
  const char *s = name;
  if (name == NULL) {
    dm_err_set(e, DM_EINVAL, "Lie group name: none given");
    return NULL;
  }
  for (;;) {
    const char *x = strchr(s, 'x');
    size_t len = x ? (size_t)(x - s) : strlen(s);
    if (k == DM_LIE_FAC_MAX) {
      dm_err_set(e, DM_EINVAL, "Lie group name '%s': more than %d factors", name, DM_LIE_FAC_MAX);
      goto out;
    }
    if ((fac[k] = parse_one(s, len, e)) == NULL)
      goto out;
    k++;
    if (x == NULL)
      break;
    s = x + 1;
  }
  G = k == 1 ? fac[--k] : dm_lie_product(k, (const dm_lie_group *const *)fac, e);
out:
  for (i = 0; i < k; i++)
    dm_lie_group_free(fac[i]);
  return G;
}

/* }====================================================================== */

/* {==== description ====================================================== */

typedef struct sbuf {
  char *p;
  size_t size, len;
} sbuf;

static void put(sbuf *b, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;
static void put(sbuf *b, const char *fmt, ...)
{
  va_list ap;
  int n;
  va_start(ap, fmt);
  n = dm_num_vsnprintf(b->p ? b->p + (b->len < b->size ? b->len : b->size) : NULL,
                       b->len < b->size ? b->size - b->len : 0, fmt, ap);
  va_end(ap);
  if (n > 0)
    b->len += (size_t)n;
}

static void put_vec(sbuf *b, const double *x, size_t n)
{
  size_t i;
  put(b, "(");
  for (i = 0; i < n; i++)
    put(b, "%s%.6g", i ? ", " : "", x[i] == 0.0 ? 0.0 : x[i]);
  put(b, ")");
}

static void put_rotation(sbuf *b, const double *R)
{
  double w[3], th;
  dm_so3_log(R, w);
  th = sqrt(dm_v3_dot(w, w));
  if (th == 0.0) {
    put(b, "rotation 0");
    return;
  }
  w[0] /= th, w[1] /= th, w[2] /= th;
  put(b, "rotation %.6g about ", th);
  put_vec(b, w, 3);
}

static void describe1(const dm_lie_group *G, const double *g, sbuf *b)
{
  size_t i;
  switch (G->kind) {
  case DM_LIE_SO3:
    put_rotation(b, g);
    put(b, " [");
    for (i = 0; i < 9; i++)   /* entries below 1e-14 (rounded zeros) print as 0 */
      put(b, "%s%.4g", i == 0 ? "" : i % 3 == 0 ? "; " : " ", fabs(g[i]) < 1e-14 ? 0.0 : g[i]);
    put(b, "]");
    break;
  case DM_LIE_SE3:
    put_rotation(b, g);
    put(b, ", translation ");
    put_vec(b, g + 9, 3);
    break;
  case DM_LIE_SO2:
    put(b, "angle %.6g", g[0]);
    break;
  case DM_LIE_SE2:
    put(b, "angle %.6g, translation ", g[0]);
    put_vec(b, g + 1, 2);
    break;
  case DM_LIE_TN:
    put(b, "angles ");
    put_vec(b, g, G->n);
    break;
  default:
    put_vec(b, g, G->nq);
    break;
  }
}

int dm_lie_describe(const dm_lie_group *G, const double *g, char *buf, size_t size)
{
  sbuf b = {buf, size, 0};
  size_t i;
  if (buf != NULL && size > 0)
    buf[0] = '\0';
  if (G->kind != DM_LIE_PRODUCT)
    describe1(G, g, &b);
  for (i = 0; i < G->nfac; i++) {
    if (i)
      put(&b, " | ");
    describe1(G->fac[i], g + G->qoff[i], &b);
  }
  return (int)b.len;
}

/* }====================================================================== */

/* {==== dispatch ========================================================= */

void dm_lie_identity(const dm_lie_group *G, double *g)
{
  G->type->identity(G, g);
}

void dm_lie_compose(const dm_lie_group *G, const double *a, const double *b, double *ab)
{
  if (G->kind == DM_LIE_SO3)            /* the common case without the indirect call */
    dm_m3_mul(a, b, ab);
  else
    G->type->compose(G, a, b, ab);
}

void dm_lie_inverse(const dm_lie_group *G, const double *a, double *ai)
{
  G->type->inverse(G, a, ai);
}

void dm_lie_between(const dm_lie_group *G, const double *a, const double *b, double *d)
{
  double ai[DM_LIE_NQ_MAX];
  G->type->inverse(G, a, ai);
  G->type->compose(G, ai, b, d);
}

void dm_lie_exp(const dm_lie_group *G, const double *xi, double *g)
{
  G->type->exp(G, xi, g);
}

void dm_lie_log(const dm_lie_group *G, const double *g, double *xi)
{
  G->type->log(G, g, xi);
}

double dm_lie_dist(const dm_lie_group *G, const double *a, const double *b)
{
  double d[DM_LIE_NQ_MAX], xi[DM_LIE_DIM_MAX], s = 0.0;
  size_t i;
  dm_lie_between(G, a, b, d);
  G->type->log(G, d, xi);
  for (i = 0; i < G->dim; i++)
    s += xi[i] * xi[i];
  return sqrt(s);
}

void dm_lie_Ad(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  G->type->Ad(G, g, M, ld);
}

void dm_lie_ad(const dm_lie_group *G, const double *xi, double *M, size_t ld)
{
  G->type->ad(G, xi, M, ld);
}

void dm_lie_bracket(const dm_lie_group *G, const double *a, const double *b, double *c)
{
  G->type->bracket(G, a, b, c);
}

static void apply(const double *M, size_t n, int trans, const double *x, double *y)
{
  double t[DM_LIE_DIM_MAX];
  size_t i, j;
  for (i = 0; i < n; i++) {
    double s = 0.0;
    for (j = 0; j < n; j++)
      s += (trans ? M[j * n + i] : M[i * n + j]) * x[j];
    t[i] = s;
  }
  memcpy(y, t, n * sizeof *y);
}

void dm_lie_Ad_apply(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  double M[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];
  if (G->kind == DM_LIE_SO3) {
    dm_m3_apply(g, x, y);
    return;
  }
  G->type->Ad(G, g, M, G->dim);
  apply(M, G->dim, 0, x, y);
}

void dm_lie_Adstar_apply(const dm_lie_group *G, const double *g, const double *mu, double *y)
{
  double M[DM_LIE_DIM_MAX * DM_LIE_DIM_MAX];
  if (G->kind == DM_LIE_SO3) {
    dm_m3_tapply(g, mu, y);
    return;
  }
  G->type->Ad(G, g, M, G->dim);
  apply(M, G->dim, 1, mu, y);
}

/* The left-trivialized derivative of a chart with chi(-xi) = chi(xi)^-1
 * is the right-trivialized one at -xi. */
static const double *side_arg(const dm_lie_group *G, const double *xi, int side, double *buf)
{
  size_t i;
  if (side != DM_LIE_LEFT)
    return xi;
  for (i = 0; i < G->dim; i++)
    buf[i] = -xi[i];
  return buf;
}

void dm_lie_dexp(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld)
{
  double b[DM_LIE_DIM_MAX];
  G->type->dexp(G, side_arg(G, xi, side, b), 0, M, ld);
}

void dm_lie_dexpinv(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld)
{
  double b[DM_LIE_DIM_MAX];
  G->type->dexp(G, side_arg(G, xi, side, b), 1, M, ld);
}

void dm_lie_cay(const dm_lie_group *G, const double *xi, double *g)
{
  G->type->cay(G, xi, g);
}

int dm_lie_icay(const dm_lie_group *G, const double *g, double *xi, dm_err *e)
{
  if (G->type->icay(G, g, xi) != DM_OK)
    return dm_err_set(e, DM_EDOM, "the %s element is a rotation by pi: the inverse Cayley map "
                      "is undefined there (its cut locus)", G->name);
  return DM_OK;
}

void dm_lie_dcay(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld)
{
  double b[DM_LIE_DIM_MAX];
  G->type->dcay(G, side_arg(G, xi, side, b), 0, M, ld);
}

void dm_lie_dcayinv(const dm_lie_group *G, const double *xi, int side, double *M, size_t ld)
{
  double b[DM_LIE_DIM_MAX];
  G->type->dcay(G, side_arg(G, xi, side, b), 1, M, ld);
}

void dm_lie_hat(const dm_lie_group *G, const double *xi, double *A, size_t ld)
{
  G->type->hat(G, xi, A, ld);
}

void dm_lie_vee(const dm_lie_group *G, const double *A, size_t ld, double *xi)
{
  G->type->vee(G, A, ld, xi);
}

void dm_lie_matrix(const dm_lie_group *G, const double *g, double *M, size_t ld)
{
  G->type->matrix(G, g, M, ld);
}

int dm_lie_from_matrix(const dm_lie_group *G, const double *M, size_t ld, double *g,
                       dm_err *e)
{
  size_t i, j;
  for (i = 0; i < G->msize; i++)
    for (j = 0; j < G->msize; j++)
      if (!isfinite(M[i * ld + j]))
        return dm_err_set(e, DM_EDOM, "%s matrix: entry [%zu][%zu] is not finite", G->name,
                          i + 1, j + 1);
  if (G->type->from_matrix(G, M, ld, g) != DM_OK)
    return dm_err_set(e, DM_EDOM, "%s matrix: the fixed entries are not those of the group "
                      "(homogeneous last row, [[c, -s], [s, c]] rotation blocks, zeros "
                      "outside the blocks)", G->name);
  return DM_OK;
}

void dm_lie_act(const dm_lie_group *G, const double *g, const double *x, double *y)
{
  G->type->act(G, g, x, y);
}

void dm_lie_normalize(const dm_lie_group *G, double *g)
{
  G->type->normalize(G, g);
}

int dm_lie_check(const dm_lie_group *G, const double *g, double tol, dm_err *e)
{
  double d;
  size_t i;
  int det_ok;
  for (i = 0; i < G->nq; i++)
    if (!isfinite(g[i]))
      return dm_err_set(e, DM_EDOM, "%s element: entry %zu is not finite", G->name, i + 1);
  d = G->type->defect(G, g, &det_ok);
  if (!(d <= tol))
    return dm_err_set(e, DM_EDOM, "%s element: max |R^T R - I| = %.3g (> tol %.3g): not a "
                      "rotation", G->name, d, tol);
  if (!det_ok)
    return dm_err_set(e, DM_EDOM, "%s element: det R < 0: a reflection, not a rotation",
                      G->name);
  return DM_OK;
}

void dm_lie_generator(const dm_lie_group *G, const double *g, size_t k, int side,
                      double *dg)
{
  G->type->generator(G, g, k, side, dg);
}

void dm_lie_trivialize(const dm_lie_group *G, const double *g, const double *grad,
                       int side, double *out)
{
  double dg[DM_LIE_NQ_MAX];
  size_t k, a;
  for (k = 0; k < G->dim; k++) {
    double s = 0.0;
    G->type->generator(G, g, k, side, dg);
    for (a = 0; a < G->nq; a++)
      s += grad[a] * dg[a];
    out[k] = s;
  }
}

/* }====================================================================== */
