/* test_dec_cone.c -- the discrete Poincare lemma: cone operators from
 * greedy collapses, exact integer homotopy identities. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "dec/dec.h"

/* max |p[k] d[k] + d[k-1] p[k-1] - I| over k = 0..n (with the k = 0 and
 * k = n ends as documented). */
static double homotopy_defect(const dm_dec_complex *K, dm_sparse **p, int apex)
{
  int n = K->n, k, i;
  double m = 0;
  for (k = 0; k <= n; k++) {
    dm_sparse *A = NULL, *B = NULL, *S, *I;
    int N = K->nsimp[k];
    if (k < n)
      A = dm_sparse_mul(p[k], K->d[k], NULL);
    if (k > 0)
      B = dm_sparse_mul(K->d[k - 1], p[k - 1], NULL);
    S = A && B ? dm_sparse_add(1, A, 1, B, NULL) : dm_sparse_copy(A ? A : B, NULL);
    I = dm_sparse_diag(N, NULL, NULL);
    {
      dm_sparse *R = dm_sparse_add(1, S, -1, I, NULL);
      if (k == 0) {                       /* p d f = f - f(apex): R = -1 in column apex */
        for (i = 0; i < N; i++)
          m = fmax(m, fabs(dm_sparse_get(R, i, apex) + 1));
        for (i = 0; i < dm_sparse_nnz(R); i++)
          if (R->col[i] != apex)
            m = fmax(m, fabs(R->val[i]));
      } else {
        m = fmax(m, dm_sparse_maxabs(R));
      }
      dm_sparse_free(R);
    }
    dm_sparse_free(A);
    dm_sparse_free(B);
    dm_sparse_free(S);
    dm_sparse_free(I);
  }
  return m;
}

int main(void)
{
  dm_err e;
  int k, apex = -1, i;
  dm_sparse *p[DM_DEC_MAXDIM];
  /* hexagon fan */
  {
    int T[18];
    dm_dec_complex *K;
    for (i = 0; i < 6; i++) {
      T[3 * i] = 0;
      T[3 * i + 1] = i + 1;
      T[3 * i + 2] = (i + 1) % 6 + 1;
    }
    K = dm_dec_complex_alloc(2, 7, 6, T, NULL);
    tap_ok(dm_dec_homotopy(K, p, &apex, &e) == DM_OK, "hexagon fan collapses");
    tap_ok(homotopy_defect(K, p, apex) == 0, "fan: H d + d H = I exactly (H d f = f - f(w) on 0-forms)");
    /* closed => exact: alpha = d f, H alpha = f - f(w), d H alpha = alpha */
    {
      double f[7], a[12], h[7], dh[12], m = 0;
      for (i = 0; i < 7; i++)
        f[i] = (i * 37 % 11) - 5;
      dm_sparse_gemv(K->d[0], f, a);
      dm_sparse_gemv(p[0], a, h);
      dm_sparse_gemv(K->d[0], h, dh);
      for (i = 0; i < 7; i++)
        m = fmax(m, fabs(h[i] - (f[i] - f[apex])));
      for (i = 0; i < 12; i++)
        m = fmax(m, fabs(dh[i] - a[i]));
      tap_ok(m == 0, "Poincare lemma on the fan: H(df) = f - f(w), d(H df) = df");
    }
    for (k = 0; k < 2; k++)
      dm_sparse_free(p[k]);
    dm_dec_complex_free(K);
  }
  /* 3 x 3 grid (not star-shaped): still collapsible */
  {
    dm_dec_meshdata *m = dm_dec_gen_grid(3, 3, 0, 1, 0, 1, NULL);
    dm_dec_complex *K = dm_dec_complex_alloc(2, m->nv, m->ntop, m->T, NULL);
    double mx;
    tap_ok(dm_dec_homotopy(K, p, &apex, &e) == DM_OK, "3 x 3 grid collapses to vertex %d", apex + 1);
    tap_ok(homotopy_defect(K, p, apex) == 0, "grid: homotopy identities exact");
    mx = fmax(dm_sparse_maxabs(p[0]), dm_sparse_maxabs(p[1]));
    tap_ok(mx == 1, "grid: entries of p in {-1, 0, 1}");
    for (k = 0; k < 2; k++)
      dm_sparse_free(p[k]);
    dm_dec_complex_free(K);
    dm_dec_meshdata_free(m);
  }
  /* a tetrahedral box, and a disc */
  {
    dm_dec_meshdata *m = dm_dec_gen_box(2, 2, 2, 1, 1, 1, NULL);
    dm_dec_complex *K = dm_dec_complex_alloc(3, m->nv, m->ntop, m->T, NULL);
    tap_ok(dm_dec_homotopy(K, p, &apex, &e) == DM_OK && homotopy_defect(K, p, apex) == 0,
           "tetrahedral box: homotopy identities exact in degrees 0..3");
    for (k = 0; k < 3; k++)
      dm_sparse_free(p[k]);
    dm_dec_complex_free(K);
    dm_dec_meshdata_free(m);
    m = dm_dec_gen_disc(1.0, 8, NULL);
    K = dm_dec_complex_alloc(2, m->nv, m->ntop, m->T, NULL);
    tap_ok(dm_dec_homotopy(K, p, &apex, &e) == DM_OK && homotopy_defect(K, p, apex) == 0,
           "disc of 8 rings: homotopy identities exact");
    for (k = 0; k < 2; k++)
      dm_sparse_free(p[k]);
    dm_dec_complex_free(K);
    dm_dec_meshdata_free(m);
  }
  /* an annulus is not contractible */
  {
    dm_dec_meshdata *m = dm_dec_gen_annulus(1, 2, 1, 6, NULL);
    dm_dec_complex *K = dm_dec_complex_alloc(2, m->nv, m->ntop, m->T, NULL);
    tap_ok(dm_dec_homotopy(K, p, &apex, &e) == DM_EFAILED && strstr(e.msg, "no collapse to a point") &&
           strstr(e.msg, "0 2-simplices") != NULL, "annulus: %s", e.msg);
    dm_dec_complex_free(K);
    dm_dec_meshdata_free(m);
  }
  return tap_done();
}
