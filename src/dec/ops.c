/* ops.c -- Hodge stars, exterior and dual derivatives, codifferential,
 * Laplace-de Rham operators, and the Dirichlet solver for operators of the
 * form diag(w)^-1 S (doc/exterior-calculus.md §1, §4). */
#include <config.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dec/dec.h"

static int check_k(const dm_dec_complex *K, int k, int lo, int hi, const char *what,
                   dm_err *e)
{
  if (k < lo || k > hi)
    return dm_err_set(e, DM_EINVAL, "%s: degree %d outside %d..%d (complex of dimension %d)",
                      what, k, lo, hi, K->n);
  return DM_OK;
}

static void name_simplex(const dm_dec_complex *K, int k, int s, char *buf, size_t size)
{
  int i, len = 0;
  const int *v = k == K->n ? K->top + (size_t)s * (k + 1) : K->simp[k] + (size_t)s * (k + 1);
  for (i = 0; i <= k && len < (int)size; i++)
    len += snprintf(buf + len, size - (size_t)len, "%s%d", i ? "," : "(", v[i] + 1);
  if (len < (int)size)
    snprintf(buf + len, size - (size_t)len, ")");
}

int dm_dec_star(const dm_dec_geom *G, int k, int inverse, double *out, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int s, n = K->n;
  double sg = ((k * (n - k)) % 2 == 0) ? 1.0 : -1.0;
  if (check_k(K, k, 0, n, "Hodge star", e) != DM_OK)
    return DM_EINVAL;
  for (s = 0; s < K->nsimp[k]; s++) {
    if (!inverse) {
      out[s] = G->dual[k][s] / G->vol[k][s];
    } else if (G->dual[k][s] == 0.0) {
      char buf[96];
      name_simplex(K, k, s, buf, sizeof buf);
      return dm_err_set(e, DM_ESINGULAR,
                        "inverse Hodge star in degree %d: the dual cell of %d-simplex %d %s has zero volume",
                        k, k, s + 1, buf);
    } else {
      out[s] = sg * G->vol[k][s] / G->dual[k][s];
    }
  }
  return DM_OK;
}

dm_sparse *dm_dec_d(const dm_dec_complex *K, int k, dm_err *e)
{
  if (check_k(K, k, 0, K->n - 1, "exterior derivative", e) != DM_OK)
    return NULL;
  return dm_sparse_copy(K->d[k], e);
}

dm_sparse *dm_dec_dual_d(const dm_dec_complex *K, int j, dm_err *e)
{
  dm_sparse *D;
  int n = K->n;
  if (check_k(K, j, 0, n - 1, "dual derivative", e) != DM_OK)
    return NULL;
  D = dm_sparse_transpose(K->d[n - j - 1], e);
  if (D != NULL && (n - j) % 2 != 0) {
    int p;
    for (p = 0; p < dm_sparse_nnz(D); p++)
      D->val[p] = -D->val[p];
  }
  return D;
}

/* *_{k-1}^{-1} d_{k-1}^T *_k, with the primal inverse 1/star (no sign: the
 * sign of the dual-to-primal star is already in the definition of delta). */
dm_sparse *dm_dec_codiff(const dm_dec_geom *G, int k, dm_err *e)
{
  const dm_dec_complex *K = G->K;
  double *sl = NULL, *sr = NULL;
  dm_sparse *D = NULL;
  int s;
  if (check_k(K, k, 1, K->n, "codifferential", e) != DM_OK)
    return NULL;
  sl = malloc(((size_t)K->nsimp[k - 1] + 1) * sizeof *sl);
  sr = malloc(((size_t)K->nsimp[k] + 1) * sizeof *sr);
  if (sl == NULL || sr == NULL) {
    dm_err_set(e, DM_ENOMEM, "codifferential: out of memory");
    goto done;
  }
  dm_dec_star(G, k, 0, sr, NULL);
  for (s = 0; s < K->nsimp[k - 1]; s++) {
    if (G->dual[k - 1][s] == 0.0) {
      char buf[96];
      name_simplex(K, k - 1, s, buf, sizeof buf);
      dm_err_set(e, DM_ESINGULAR,
                 "codifferential in degree %d: the dual cell of %d-simplex %d %s has zero volume",
                 k, k - 1, s + 1, buf);
      goto done;
    }
    sl[s] = G->vol[k - 1][s] / G->dual[k - 1][s];
  }
  if ((D = dm_sparse_transpose(K->d[k - 1], e)) != NULL)
    dm_sparse_scale(D, sl, sr);
done:
  free(sl);
  free(sr);
  return D;
}

/* S = *_k d_{k-1} *_{k-1}^-1 d_{k-1}^T *_k + d_k^T *_{k+1} d_k, and
 * Delta = *_k^-1 S. */
int dm_dec_laplacian(const dm_dec_geom *G, int k, dm_sparse **delta, dm_sparse **sym,
                     dm_err *e)
{
  const dm_dec_complex *K = G->K;
  int n = K->n, st = DM_OK, s;
  dm_sparse *S = NULL, *up = NULL, *down = NULL, *t1 = NULL, *t2 = NULL;
  double *w = NULL;
  if (delta != NULL)
    *delta = NULL;
  if (sym != NULL)
    *sym = NULL;
  if (check_k(K, k, 0, n, "Laplacian", e) != DM_OK)
    return DM_EINVAL;
  w = malloc(((size_t)K->nsimp[k] + (k < n ? K->nsimp[k + 1] : 0) + 1) * sizeof *w);
  if (w == NULL)
    return dm_err_set(e, DM_ENOMEM, "Laplacian: out of memory");
  if (k < n) {                                      /* d_k^T *_{k+1} d_k */
    dm_dec_star(G, k + 1, 0, w, NULL);
    if ((t1 = dm_sparse_copy(K->d[k], e)) == NULL)
      goto fail;
    dm_sparse_scale(t1, w, NULL);
    if ((t2 = dm_sparse_transpose(K->d[k], e)) == NULL ||
        (up = dm_sparse_mul(t2, t1, e)) == NULL)
      goto fail;
    dm_sparse_free(t1);
    dm_sparse_free(t2);
    t1 = t2 = NULL;
  }
  if (k > 0) {                                      /* *_k d delta_k */
    if ((t1 = dm_dec_codiff(G, k, e)) == NULL)
      goto fail;
    dm_dec_star(G, k, 0, w, NULL);
    if ((t2 = dm_sparse_copy(K->d[k - 1], e)) == NULL)
      goto fail;
    dm_sparse_scale(t2, w, NULL);
    if ((down = dm_sparse_mul(t2, t1, e)) == NULL)
      goto fail;
  }
  if (up != NULL && down != NULL)
    S = dm_sparse_add(1.0, up, 1.0, down, e);
  else {
    S = up != NULL ? up : down;
    if (up != NULL)
      up = NULL;
    else
      down = NULL;
  }
  if (S == NULL)
    goto fail;
  if (delta != NULL) {
    dm_dec_star(G, k, 0, w, NULL);
    for (s = 0; s < K->nsimp[k]; s++) {
      if (w[s] == 0.0) {
        char buf[96];
        name_simplex(K, k, s, buf, sizeof buf);
        st = dm_err_set(e, DM_ESINGULAR,
                        "Laplacian in degree %d: the dual cell of %d-simplex %d %s has zero volume",
                        k, k, s + 1, buf);
        goto fail;
      }
      w[s] = 1.0 / w[s];
    }
    if ((*delta = dm_sparse_copy(S, e)) == NULL)
      goto fail;
    dm_sparse_scale(*delta, w, NULL);
  }
  if (sym != NULL) {
    *sym = S;
    S = NULL;
  }
  goto done;
fail:
  if (st == DM_OK)
    st = e != NULL && e->status != DM_OK ? e->status : DM_EFAILED;
  if (delta != NULL) {
    dm_sparse_free(*delta);
    *delta = NULL;
  }
done:
  dm_sparse_free(S);
  dm_sparse_free(up);
  dm_sparse_free(down);
  dm_sparse_free(t1);
  dm_sparse_free(t2);
  free(w);
  return st;
}

/* {==== Dirichlet solver ========================================================= */

struct dm_dec_solver {
  int n, nfree;
  unsigned char *fixed;      /* n flags */
  int *freeidx;              /* nfree original indices */
  dm_sparse *S;              /* copy of S (for the boundary columns) */
  dm_sparse_chol *F;         /* factor of S on the free unknowns */
  double *rhs, *sol;         /* nfree each */
};

void dm_dec_solver_free(dm_dec_solver *F)
{
  if (F == NULL)
    return;
  free(F->fixed);
  free(F->freeidx);
  dm_sparse_free(F->S);
  dm_sparse_chol_free(F->F);
  free(F->rhs);
  free(F->sol);
  free(F);
}

dm_dec_solver *dm_dec_solver_alloc(const dm_sparse *S, const unsigned char *fixed, dm_err *e)
{
  dm_dec_solver *F;
  dm_sparse *Sff = NULL;
  unsigned char *keep = NULL;
  int i;
  if (S->nrows != S->ncols) {
    dm_err_set(e, DM_EINVAL, "solver: square matrix expected, got %d x %d", S->nrows, S->ncols);
    return NULL;
  }
  F = calloc(1, sizeof *F);
  if (F == NULL)
    goto nomem;
  F->n = S->nrows;
  F->fixed = calloc((size_t)F->n + 1, 1);
  F->freeidx = malloc(((size_t)F->n + 1) * sizeof *F->freeidx);
  keep = malloc((size_t)F->n + 1);
  if (F->fixed == NULL || F->freeidx == NULL || keep == NULL)
    goto nomem;
  for (i = 0; i < F->n; i++) {
    F->fixed[i] = fixed != NULL && fixed[i];
    keep[i] = !F->fixed[i];
    if (keep[i])
      F->freeidx[F->nfree++] = i;
  }
  if (F->nfree == 0) {
    dm_err_set(e, DM_EINVAL, "solver: every unknown is fixed by the boundary condition");
    goto fail;
  }
  F->rhs = malloc((size_t)F->nfree * sizeof *F->rhs);
  F->sol = malloc((size_t)F->nfree * sizeof *F->sol);
  if (F->rhs == NULL || F->sol == NULL)
    goto nomem;
  if ((F->S = dm_sparse_copy(S, e)) == NULL || (Sff = dm_sparse_select(S, keep, keep, e)) == NULL)
    goto fail;
  if ((F->F = dm_sparse_chol_alloc(Sff, e)) == NULL)
    goto fail;
  dm_sparse_free(Sff);
  free(keep);
  return F;
nomem:
  dm_err_set(e, DM_ENOMEM, "solver: out of memory");
fail:
  dm_sparse_free(Sff);
  free(keep);
  dm_dec_solver_free(F);
  return NULL;
}

int dm_dec_solver_solve(dm_dec_solver *F, const double *w, const double *f, const double *g,
                        double *u, dm_err *e)
{
  int a, p, st;
  const dm_sparse *S = F->S;
  for (a = 0; a < F->nfree; a++) {
    int i = F->freeidx[a];
    double r = (w != NULL ? w[i] : 1.0) * f[i];
    if (g != NULL)
      for (p = S->rowptr[i]; p < S->rowptr[i + 1]; p++)
        if (F->fixed[S->col[p]])
          r -= S->val[p] * g[S->col[p]];
    F->rhs[a] = r;
  }
  if ((st = dm_sparse_chol_solve(F->F, 1, F->rhs, F->sol, e)) != DM_OK)
    return st;
  for (a = 0; a < F->n; a++)
    if (F->fixed[a])
      u[a] = g != NULL ? g[a] : 0.0;
  for (a = 0; a < F->nfree; a++)
    u[F->freeidx[a]] = F->sol[a];
  return DM_OK;
}

/* }==== */
