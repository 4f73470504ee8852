/* prk_sparse.c -- the Newton matrix of the implicit PRK step as a sparse
 * matrix, factored by KLU (core/sparse.h).
 *
 * The stage block (i, l) of the Newton matrix (prk_engine.c)
 *   J_il = d_il Lvv_i + h a_il Lvq_i - h at_il Bm_l - sum_j h^2 at_ij a_jl D_j
 * has the pattern U = vv + vq + vq^T + qq (+ fq + fv with a force; every
 * entry with constraints, whose curvature terms are dense), the union of
 * the system's patterns (system.h; every entry without one).  The matrix
 * is stored row by row: row (i, a) holds block (0, i) .. (s-1, i) of row a
 * of U, then the multiplier columns; a constraint row holds every
 * velocity column.  The pattern is analysed once (KLU) and every Jacobian
 * is a numerical refactorisation with the same pivots while they stay
 * good (sparse.h).
 *
 * Stage values live on U (VV, VQ, BM, DD: s x nnz(U) each) and the block
 * entries are computed with the dense code's arithmetic in the same order,
 * so the matrices are the same numbers; the two solvers differ by
 * rounding only.  Two ways to fill them: from the dense stage arrays of
 * the engine (gathered; small systems and constrained ones, whose
 * multiplier code works on dense arrays), or -- without any n x n array --
 * from values on the system's patterns (DM_LAG_SPARSE), for large
 * unconstrained systems. */
#include <config.h>
#include "integrators/prk_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct dm_prk_sparse {
  int large;                /* stage values from the patterns, no dense arrays */
  dm_csr U;
  size_t nnzU;
  size_t *udense;           /* nnzU: row * n + col (gathering) */
  /* large: places in U of the entries of the system's patterns, and one
   * stage's values on them */
  uint32_t *pvv, *pvq, *pvqT, *pqq, *pfq, *pfv;
  double *sLvv, *sLvq, *sLqq, *sFq, *sFv;
  double *VV, *VQ, *BM, *DD;    /* s x nnzU */
  dm_csr J;
  uint32_t *jblk;           /* s s nnzU: place in J of block (i, l) entry p */
  double *Jv;               /* values of J */
  dm_splu *lu;
};

void dm_prk_sparse_free(dm_prk_sparse *S)
{
  if (S == NULL)
    return;
  dm_csr_free(&S->U);
  dm_csr_free(&S->J);
  free(S->udense);
  free(S->pvv);
  free(S->pvq);
  free(S->pvqT);
  free(S->pqq);
  free(S->pfq);
  free(S->pfv);
  free(S->sLvv);
  free(S->VV);
  free(S->jblk);
  free(S->Jv);
  dm_splu_free(S->lu);
  free(S);
}

/* {==================================================================
 * patterns
 * =================================================================== */

/* Column lists of the transpose of p (n x n): rowptr/col of p^T. */
static int transpose(const dm_csr *p, dm_csr *t)
{
  size_t n = p->nrow;
  if (dm_csr_alloc(t, p->ncol, n, p->nnz) != DM_OK)
    return -1;
  memset(t->rowptr, 0, (p->ncol + 1) * sizeof *t->rowptr);
  for (size_t k = 0; k < p->nnz; k++)
    t->rowptr[p->col[k] + 1]++;
  for (size_t j = 0; j < p->ncol; j++)
    t->rowptr[j + 1] += t->rowptr[j];
  size_t *fill = malloc((p->ncol + 1) * sizeof *fill);
  if (fill == NULL) {
    dm_csr_free(t);
    return -1;
  }
  memcpy(fill, t->rowptr, (p->ncol + 1) * sizeof *fill);
  for (size_t i = 0; i < n; i++)          /* rows in order: columns ascend */
    for (size_t k = p->rowptr[i]; k < p->rowptr[i + 1]; k++)
      t->col[fill[p->col[k]]++] = (uint32_t)i;
  free(fill);
  return 0;
}

static int grow_u32(uint32_t **p, size_t *cap, size_t need)
{
  if (need <= *cap)
    return 0;
  size_t c = *cap ? *cap : 1024;
  while (c < need)
    c *= 2;
  uint32_t *q = realloc(*p, c * sizeof *q);
  if (q == NULL)
    return -1;
  *p = q;
  *cap = c;
  return 0;
}

/* U: the union of the patterns (NULL entries skipped), every entry when
 * full. */
static int union_pattern(size_t n, const dm_csr *const *ps, int np, int full, dm_csr *U)
{
  if (full)
    return dm_csr_full(U, n, n) == DM_OK ? 0 : -1;
  uint32_t *mark = calloc(n, sizeof *mark), *row = malloc((n + 1) * sizeof *row);
  size_t nnz = 0, cap = 0;
  uint32_t *cols = NULL;
  int s = -1;
  if (mark == NULL || row == NULL || dm_csr_alloc(U, n, n, 0) != DM_OK)
    goto done;
  for (size_t i = 0; i < n; i++) {
    size_t k = 0;
    U->rowptr[i] = nnz;
    for (int q = 0; q < np; q++)
      if (ps[q] != NULL)
        for (size_t e = ps[q]->rowptr[i]; e < ps[q]->rowptr[i + 1]; e++)
          if (mark[ps[q]->col[e]] != i + 1) {
            mark[ps[q]->col[e]] = (uint32_t)(i + 1);
            row[k++] = ps[q]->col[e];
          }
    /* ascending (the rows merged are each ascending: insertion sort of a
     * few entries) */
    for (size_t a = 1; a < k; a++) {
      uint32_t x = row[a];
      size_t b = a;
      while (b > 0 && row[b - 1] > x) {
        row[b] = row[b - 1];
        b--;
      }
      row[b] = x;
    }
    if (grow_u32(&cols, &cap, nnz + k) != 0)
      goto done;
    memcpy(cols + nnz, row, k * sizeof *row);
    nnz += k;
  }
  U->rowptr[n] = nnz;
  free(U->col);
  U->col = cols ? cols : malloc(sizeof *U->col);
  cols = NULL;
  U->nnz = nnz;
  s = U->col ? 0 : -1;
done:
  free(mark);
  free(row);
  free(cols);
  return s;
}

/* The place in U of every entry of p (transposed: of (j, i) for p's
 * (i, j)). */
static uint32_t *places(const dm_csr *U, const dm_csr *p, int transposed)
{
  uint32_t *pl = malloc((p->nnz + 1) * sizeof *pl);
  if (pl == NULL)
    return NULL;
  for (size_t i = 0; i < p->nrow; i++)
    for (size_t k = p->rowptr[i]; k < p->rowptr[i + 1]; k++) {
      long q = transposed ? dm_csr_find(U, p->col[k], i) : dm_csr_find(U, i, p->col[k]);
      pl[k] = (uint32_t)q;               /* U holds every entry of p */
    }
  return pl;
}

/* J's pattern (see the top) and the places of the blocks' entries. */
static int newton_pattern(dm_prk *P, dm_prk_sparse *S)
{
  const size_t n = P->n, s = P->s, m = P->m, sn = P->sn, nK = P->nK;
  const size_t N = sn + (m ? nK * m + m : 0), nc = m ? nK * m + m : 0;
  const dm_csr *U = &S->U;
  size_t nnz = s * s * S->nnzU + (m ? 2 * s * n * nc : 0);
  if (dm_csr_alloc(&S->J, N, N, nnz) != DM_OK ||
      (S->jblk = malloc((s * s * S->nnzU + 1) * sizeof *S->jblk)) == NULL ||
      (S->Jv = calloc(nnz + 1, sizeof *S->Jv)) == NULL)
    return -1;
  size_t k = 0;
  for (size_t i = 0; i < s; i++)
    for (size_t a = 0; a < n; a++) {
      size_t r0 = U->rowptr[a], ra = U->rowptr[a + 1] - r0;
      S->J.rowptr[i * n + a] = k;
      for (size_t l = 0; l < s; l++)
        for (size_t p = r0; p < r0 + ra; p++) {
          S->jblk[(i * s + l) * S->nnzU + p] = (uint32_t)k;
          S->J.col[k++] = (uint32_t)(l * n + U->col[p]);
        }
      for (size_t c = 0; c < nc; c++)
        S->J.col[k++] = (uint32_t)(sn + c);
    }
  for (size_t r = sn; r < N; r++) {
    S->J.rowptr[r] = k;
    for (size_t c = 0; c < sn; c++)
      S->J.col[k++] = (uint32_t)c;
  }
  S->J.rowptr[N] = k;
  return 0;
}

int dm_prk_sparse_setup(dm_prk *P, int large, dm_err *e)
{
  const dm_system *sys = P->sys;
  const dm_sys_pattern *sp = sys->pattern;
  const size_t n = P->n, s = P->s;
  dm_prk_sparse *S = calloc(1, sizeof *S);
  dm_csr vqT = { 0 };
  if (S == NULL)
    goto oom;
  P->sp = S;
  S->large = large;
  {
    const dm_csr *ps[6] = { sp ? &sp->vv : NULL, sp ? &sp->vq : NULL, NULL,
                            sp ? &sp->qq : NULL, sp && P->forced ? &sp->fq : NULL,
                            sp && P->forced ? &sp->fv : NULL };
    if (sp != NULL && transpose(&sp->vq, &vqT) != 0)
      goto oom;
    ps[2] = sp ? &vqT : NULL;
    if (union_pattern(n, ps, 6, sp == NULL || P->m > 0, &S->U) != 0)
      goto oom;
  }
  S->nnzU = S->U.nnz;
  if ((S->udense = malloc((S->nnzU + 1) * sizeof *S->udense)) == NULL)
    goto oom;
  for (size_t i = 0; i < n; i++)
    for (size_t p = S->U.rowptr[i]; p < S->U.rowptr[i + 1]; p++)
      S->udense[p] = i * n + S->U.col[p];
  if (large) {
    size_t tot = sp->vv.nnz + sp->vq.nnz + sp->qq.nnz + sp->fq.nnz + sp->fv.nnz;
    if ((S->pvv = places(&S->U, &sp->vv, 0)) == NULL ||
        (S->pvq = places(&S->U, &sp->vq, 0)) == NULL ||
        (S->pvqT = places(&S->U, &sp->vq, 1)) == NULL ||
        (S->pqq = places(&S->U, &sp->qq, 0)) == NULL ||
        (S->pfq = places(&S->U, &sp->fq, 0)) == NULL ||
        (S->pfv = places(&S->U, &sp->fv, 0)) == NULL ||
        (S->sLvv = malloc((tot + 1) * sizeof *S->sLvv)) == NULL)
      goto oom;
    S->sLvq = S->sLvv + sp->vv.nnz;
    S->sLqq = S->sLvq + sp->vq.nnz;
    S->sFq = S->sLqq + sp->qq.nnz;
    S->sFv = S->sFq + sp->fq.nnz;
  }
  if ((S->VV = calloc(4 * s * S->nnzU + 1, sizeof *S->VV)) == NULL)
    goto oom;
  S->VQ = S->VV + s * S->nnzU;
  S->BM = S->VQ + s * S->nnzU;
  S->DD = S->BM + s * S->nnzU;
  if (newton_pattern(P, S) != 0)
    goto oom;
  dm_csr_free(&vqT);
  return dm_splu_alloc(&S->J, &S->lu, e);
oom:
  dm_csr_free(&vqT);
  return dm_err_set(e, DM_ENOMEM, "integrator: out of memory");
}

/* {==================================================================
 * stages and the matrix
 * =================================================================== */

void dm_prk_sparse_gather(dm_prk *P, size_t i)
{
  dm_prk_sparse *S = P->sp;
  const size_t nnzU = S->nnzU, nn = P->nn;
  const size_t *ud = S->udense;
  const double *Lvv = P->Lvv + i * nn, *Lvq = P->Lvq + i * nn, *Bm = P->Bm + i * nn;
  const double *D = P->D + i * nn;
  double *VV = S->VV + i * nnzU, *VQ = S->VQ + i * nnzU, *BM = S->BM + i * nnzU;
  double *DD = S->DD + i * nnzU;
  for (size_t p = 0; p < nnzU; p++) {
    VV[p] = Lvv[ud[p]];
    VQ[p] = Lvq[ud[p]];
    BM[p] = Bm[ud[p]];
    DD[p] = D[ud[p]];
  }
}

int dm_prk_sparse_eval_stage(dm_prk *P, size_t i, int jac, int want_L, dm_err *e)
{
  dm_prk_sparse *S = P->sp;
  const dm_sys_pattern *sp = P->sys->pattern;
  const size_t n = P->n, nnzU = S->nnzU;
  double *Qi = P->Q + i * n, *Vi = P->X + i * n;
  dm_lag_out o = {0, P->Lq + i * n, P->Lv + i * n, S->sLvv, S->sLvq, S->sLqq};
  unsigned what = DM_LAG_Q | DM_LAG_V | (want_L ? DM_LAG_L : 0u) |
                  (jac ? DM_LAG_SPARSE | (P->sep ? DM_LAG_QQ : (DM_LAG_VV | DM_LAG_VQ | DM_LAG_QQ))
                       : 0u);
  int st = dm_eval_lag(P->sys, Qi, Vi, what, &o, P->work, e);
  if (st != DM_OK)
    return st;
  P->Lval[i] = o.L;
  if (P->forced) {
    unsigned fw = DM_FORCE_F | (jac ? (DM_FORCE_Q | DM_FORCE_V | DM_FORCE_SPARSE) : 0u);
    if ((st = dm_eval_force(P->sys, Qi, Vi, fw, P->F + i * n, S->sFq, S->sFv, P->work, e))
        != DM_OK)
      return st;
    for (size_t a = 0; a < n; a++)
      P->W[i * n + a] = P->Lq[i * n + a] + P->F[i * n + a];
  } else {
    dm_vcopy(P->W + i * n, P->Lq + i * n, n);
  }
  if (!jac)
    return DM_OK;
  double *VV = S->VV + i * nnzU, *VQ = S->VQ + i * nnzU, *BM = S->BM + i * nnzU;
  double *DD = S->DD + i * nnzU;
  memset(VV, 0, nnzU * sizeof *VV);
  memset(VQ, 0, nnzU * sizeof *VQ);
  memset(BM, 0, nnzU * sizeof *BM);
  memset(DD, 0, nnzU * sizeof *DD);
  const double *mv = P->sep ? sp->mass : S->sLvv;
  for (size_t k = 0; k < sp->vv.nnz; k++)
    VV[S->pvv[k]] = mv[k];
  for (size_t k = 0; k < sp->qq.nnz; k++)
    DD[S->pqq[k]] = S->sLqq[k];
  if (!P->sep)
    for (size_t k = 0; k < sp->vq.nnz; k++) {
      VQ[S->pvq[k]] = S->sLvq[k];
      BM[S->pvqT[k]] = S->sLvq[k];
    }
  if (P->forced) {                        /* D = Lqq + Fq, Bm = Lvq^T + Fv */
    for (size_t k = 0; k < sp->fq.nnz; k++)
      DD[S->pfq[k]] = DD[S->pfq[k]] + S->sFq[k];
    for (size_t k = 0; k < sp->fv.nnz; k++)
      BM[S->pfv[k]] = BM[S->pfv[k]] + S->sFv[k];
  }
  return DM_OK;
}

double dm_prk_sparse_lvv_norm(const dm_prk *P)
{
  return dm_norm_inf(P->sp->VV, P->s * P->sp->nnzU);
}

/* The values of J: the stage blocks (prk_engine.c's newton_matrix, the
 * same arithmetic in the same order), and with constraints the multiplier
 * terms of prk_constrained.c (dm_prk_constr_terms). */
void dm_prk_sparse_matrix(dm_prk *P, double h)
{
  dm_prk_sparse *S = P->sp;
  const size_t s = P->s, nnzU = S->nnzU;
  const double *restrict A = P->tab->a, *restrict At = P->tab->at;
  const double *restrict VV = S->VV, *restrict VQ = S->VQ, *restrict BM = S->BM;
  const double *restrict DD = S->DD;
  double *restrict Jv = S->Jv, cj[DM_TABLEAU_SMAX];
  const int sep = P->sep;
  for (size_t i = 0; i < s; i++)
    for (size_t l = 0; l < s; l++) {
      const double hal = h * A[i * s + l], hatl = h * At[i * s + l];
      const double *VQi = VQ + i * nnzU, *BMl = BM + l * nnzU, *VVi = VV + i * nnzU;
      const uint32_t *pos = S->jblk + (i * s + l) * nnzU;
      for (size_t j = 0; j < s; j++)
        cj[j] = h * h * At[i * s + j] * A[j * s + l];
      for (size_t p = 0; p < nnzU; p++) {
        double v = sep ? 0.0 : hal * VQi[p] - hatl * BMl[p];
        if (i == l)
          v += VVi[p];
        for (size_t j = 0; j < s; j++)
          v -= cj[j] * DD[j * nnzU + p];
        Jv[pos[p]] = v;
      }
    }
  if (P->m == 0)
    return;
  const size_t n = P->n, m = P->m, nn = P->nn, nK = P->nK, sn = P->sn;
  const size_t nc = nK * m + m;
  const double *b = P->tab->b, *G0 = P->G + s * m * n, *G1 = P->G + (s + 1) * m * n;
  const double *X = P->X;
  /* curvature: sum_a Lt_a d2g_a(Q_k) into every block (U is full here) */
  for (size_t kk = 0; kk < nK; kk++) {
    size_t k = P->K[kk];
    const double *Hk = P->Hc + k * m * nn, *Lk = X + sn + kk * m;
    for (size_t c = 0; c < n; c++)
      for (size_t x = 0; x < n; x++) {
        double hs = 0.0;
        for (size_t a = 0; a < m; a++)
          hs += Lk[a] * Hk[(a * n + c) * n + x];
        size_t p = S->U.rowptr[c] + x;          /* full rows */
        for (size_t i = 0; i < s; i++)
          for (size_t l = 0; l < s; l++)
            Jv[S->jblk[(i * s + l) * nnzU + p]] += At[i * s + k] * h * A[k * s + l] * hs;
      }
  }
  /* multiplier columns of the stage rows, then the constraint rows */
  for (size_t i = 0; i < s; i++)
    for (size_t c = 0; c < n; c++) {
      double *row = Jv + S->J.rowptr[i * n + c] + s * (S->U.rowptr[c + 1] - S->U.rowptr[c]);
      for (size_t kk = 0; kk < nK; kk++) {
        size_t k = P->K[kk];
        const double *Gk = P->G + k * m * n;
        for (size_t a = 0; a < m; a++)
          row[kk * m + a] = At[i * s + k] * Gk[a * n + c];
      }
      for (size_t a = 0; a < m; a++)
        row[nK * m + a] = G0[a * n + c];
    }
  for (size_t r = 0; r < nc; r++) {
    double *row = Jv + S->J.rowptr[sn + r];
    size_t kk = r / m, a = r % m;
    for (size_t l = 0; l < s; l++)
      for (size_t x = 0; x < n; x++)
        row[l * n + x] = kk < nK ? A[P->K[kk] * s + l] * P->G[(P->K[kk] * m + a) * n + x]
                                 : b[l] * G1[a * n + x];
  }
}

int dm_prk_sparse_factor(dm_prk *P, dm_err *e)
{
  return dm_splu_factor(P->sp->lu, P->sp->Jv, e);
}

void dm_prk_sparse_solve(dm_prk *P, double *b)
{
  dm_splu_solve(P->sp->lu, b, 1, NULL);
}

/* Row a of D_j and Bm_j (j a stage) times x, for the step Jacobian. */
void dm_prk_sparse_rowdot(const dm_prk *P, size_t j, size_t a, const double *xq,
                          const double *xv, double *f)
{
  const dm_prk_sparse *S = P->sp;
  const double *DD = S->DD + j * S->nnzU, *BM = S->BM + j * S->nnzU;
  double acc = *f;
  for (size_t p = S->U.rowptr[a]; p < S->U.rowptr[a + 1]; p++)
    acc += DD[p] * xq[S->U.col[p]] + BM[p] * xv[S->U.col[p]];
  *f = acc;
}

/* Entry (a, c) of stage j's Lvq and D (0 outside U). */
void dm_prk_sparse_entries(const dm_prk *P, size_t j, size_t a, size_t c, double *lvq,
                           double *d)
{
  const dm_prk_sparse *S = P->sp;
  long p = dm_csr_find(&S->U, a, c);
  *lvq = p < 0 ? 0.0 : S->VQ[j * S->nnzU + (size_t)p];
  *d = p < 0 ? 0.0 : S->DD[j * S->nnzU + (size_t)p];
}

size_t dm_prk_sparse_nnz(const dm_prk *P)
{
  return P->sp->J.nnz;
}
