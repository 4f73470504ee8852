/* maps.c -- discrete maps between two geometries of one complex: the
 * push-forward of dual vector fields by the Jacobians of the affine maps
 * of the top simplices (doc/exterior-calculus.md §11); nested refinement
 * transfer operators (§12). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/smalllu.h"
#include "dec/dec.h"

/* J = E2 (E1^T E1)^-1 E1^T with E the edge vectors x_i - x_0 of the top
 * simplex in each geometry; out(s) = J X(s). */
int dm_dec_pushforward(const dm_dec_geom *G1, const dm_dec_geom *G2, const double *X, double *out,
                       dm_err *e)
{
  const dm_dec_complex *K = G1->K;
  int n = K->n, N1 = G1->N, N2 = G2->N, t, i, j, c;
  if (G2->K != K)
    return dm_err_set(e, DM_EINVAL, "push-forward: the geometries belong to different complexes");
  if (G1->X == NULL || G2->X == NULL || N1 > 8 || N2 > 8)
    return dm_err_set(e, DM_EUNSUP, "push-forward: embedded meshes (at most 8 coordinates) expected");
  for (t = 0; t < K->nsimp[n]; t++) {
    const int *v = K->simp[n] + (size_t)t * (n + 1);
    double E1[DM_DEC_MAXDIM][8], E2[DM_DEC_MAXDIM][8], G[DM_DEC_MAXDIM * DM_DEC_MAXDIM];
    double a[DM_DEC_MAXDIM];
    size_t perm[DM_DEC_MAXDIM];
    for (i = 0; i < n; i++) {
      for (c = 0; c < N1; c++)
        E1[i][c] = G1->X[(size_t)v[i + 1] * N1 + c] - G1->X[(size_t)v[0] * N1 + c];
      for (c = 0; c < N2; c++)
        E2[i][c] = G2->X[(size_t)v[i + 1] * N2 + c] - G2->X[(size_t)v[0] * N2 + c];
    }
    for (i = 0; i < n; i++) {
      double s = 0.0;
      for (j = 0; j < n; j++) {
        double g = 0.0;
        for (c = 0; c < N1; c++)
          g += E1[i][c] * E1[j][c];
        G[i * n + j] = g;
      }
      for (c = 0; c < N1; c++)
        s += E1[i][c] * X[(size_t)t * N1 + c];
      a[i] = s;                                   /* E1^T X */
    }
    if (dm_smalllu_factor(G, (size_t)n, perm) != DM_OK)
      return dm_err_set(e, DM_EDOM, "push-forward: degenerate simplex %d", t + 1);
    dm_smalllu_solve(G, (size_t)n, perm, a);
    for (c = 0; c < N2; c++) {
      double s = 0.0;
      for (i = 0; i < n; i++)
        s += E2[i][c] * a[i];
      out[(size_t)t * N2 + c] = s;
    }
  }
  return DM_OK;
}

/* Restriction R_k: fine k-cochains -> coarse k-cochains by summing over the
 * pieces (k = 0: the values at the old vertices; k = 1: the two halves of
 * every coarse edge, signed by direction; k = n: the children of every top
 * simplex, which keep its orientation). */
dm_sparse *dm_dec_restriction(const dm_dec_complex *Kc, const dm_dec_complex *Kf, const int *parent,
                              int k, dm_err *e)
{
  int n = Kc->n, s, cnt = 0, *ri = NULL, *ci = NULL, nch = n == 1 ? 2 : 4;
  double *v = NULL;
  dm_sparse *R = NULL;
  if (k < 0 || k > n || (k != 0 && k != 1 && k != n)) {
    dm_err_set(e, DM_EINVAL, "restriction: degree %d (0, 1 or %d expected)", k, n);
    return NULL;
  }
  ri = malloc(((size_t)Kc->nsimp[k] * nch + 1) * sizeof *ri);
  ci = malloc(((size_t)Kc->nsimp[k] * nch + 1) * sizeof *ci);
  v = malloc(((size_t)Kc->nsimp[k] * nch + 1) * sizeof *v);
  if (ri == NULL || ci == NULL || v == NULL) {
    dm_err_set(e, DM_ENOMEM, "restriction: out of memory");
    goto done;
  }
  for (s = 0; s < Kc->nsimp[k]; s++) {
    if (k == 0) {
      ri[cnt] = s; ci[cnt] = s; v[cnt++] = 1.0;
    } else if (k == n) {
      int c;
      for (c = 0; c < nch; c++) {
        ri[cnt] = s; ci[cnt] = nch * s + c; v[cnt++] = 1.0;
      }
    } else {                                         /* k = 1 < n: halves of an edge */
      int a = Kc->simp[1][2 * s], b = Kc->simp[1][2 * s + 1], m = -1, i, h;
      for (i = Kc->nsimp[0]; i < Kf->nsimp[0] && m < 0; i++)
        if ((parent[2 * i] == a && parent[2 * i + 1] == b) || (parent[2 * i] == b && parent[2 * i + 1] == a))
          m = i;
      if (m < 0) {
        dm_err_set(e, DM_EINVAL, "restriction: the fine mesh does not refine edge %d", s + 1);
        goto done;
      }
      for (h = 0; h < 2; h++) {
        int ed[2] = {h == 0 ? a : m, h == 0 ? m : b}, id = dm_dec_find(Kf, 1, ed);
        ri[cnt] = s; ci[cnt] = id; v[cnt++] = ed[0] < ed[1] ? 1.0 : -1.0;
      }
    }
  }
  R = dm_sparse_from_triplets(Kc->nsimp[k], Kf->nsimp[k], cnt, ri, ci, v, e);
done:
  free(ri);
  free(ci);
  free(v);
  return R;
}

/* Linear interpolation of 0-cochains: fine = coarse at old vertices, the
 * mean of the two ends at midpoints. */
dm_sparse *dm_dec_prolongation(int nc, int nf, const int *parent, dm_err *e)
{
  int i, cnt = 0, *ri = malloc(2 * ((size_t)nf + 1) * sizeof *ri), *ci = malloc(2 * ((size_t)nf + 1) * sizeof *ci);
  double *v = malloc(2 * ((size_t)nf + 1) * sizeof *v);
  dm_sparse *P = NULL;
  if (ri != NULL && ci != NULL && v != NULL) {
    for (i = 0; i < nf; i++) {
      if (i < nc) {
        ri[cnt] = i; ci[cnt] = i; v[cnt++] = 1.0;
      } else {
        ri[cnt] = i; ci[cnt] = parent[2 * i]; v[cnt++] = 0.5;
        ri[cnt] = i; ci[cnt] = parent[2 * i + 1]; v[cnt++] = 0.5;
      }
    }
    P = dm_sparse_from_triplets(nf, nc, cnt, ri, ci, v, e);
  } else {
    dm_err_set(e, DM_ENOMEM, "prolongation: out of memory");
  }
  free(ri);
  free(ci);
  free(v);
  return P;
}
