/* test_dec_complex.c -- simplicial complexes: orientation and boundary
 * operators, d o d = 0 exactly, simplex counts of the generators, Stokes,
 * exact Betti numbers, input errors. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "dec/dec.h"

static dm_dec_complex *from_mesh(const dm_dec_meshdata *m)
{
  return dm_dec_complex_alloc(m->n, m->nv, m->ntop, m->T, NULL);
}

/* max |d_{k+1} d_k| over k: products of +-1 matrices are exact. */
static double dd_max(const dm_dec_complex *K)
{
  int k;
  double m = 0;
  for (k = 0; k + 1 < K->n; k++) {
    dm_sparse *P = dm_sparse_mul(K->d[k + 1], K->d[k], NULL);
    m = fmax(m, dm_sparse_maxabs(P));
    dm_sparse_free(P);
  }
  return m;
}

static void check_betti(const dm_dec_complex *K, const int *want, const char *name)
{
  int b[DM_DEC_MAXDIM + 1], k, ok;
  dm_err e;
  ok = dm_dec_betti(K, b, &e) == DM_OK;
  for (k = 0; k <= K->n; k++)
    ok = ok && b[k] == want[k];
  tap_ok(ok, "Betti numbers of the %s: %d %d %d %d", name, b[0], b[1], K->n > 1 ? b[2] : -1,
         K->n > 2 ? b[3] : -1);
}

static unsigned seed = 2385;
static int irand(int lo, int hi)
{
  seed = seed * 1103515245u + 12345u;
  return lo + (int)((seed >> 8) % (unsigned)(hi - lo + 1));
}

int main(void)
{
  dm_err e;
  dm_dec_complex *K;
  dm_dec_meshdata *m;
  int k, i;

  /* one triangle: boundary over the sorted edges (01, 02, 12) */
  {
    int T[] = {0, 1, 2}, R[] = {0, 2, 1};
    K = dm_dec_complex_alloc(2, 3, 1, T, &e);
    tap_ok(K->nsimp[0] == 3 && K->nsimp[1] == 3 && K->nsimp[2] == 1, "triangle counts");
    tap_ok(K->d[1]->val[0] == 1 && K->d[1]->val[1] == -1 && K->d[1]->val[2] == 1 &&
           K->d[1]->col[0] == 0 && K->d[1]->col[2] == 2,
           "boundary of [0,1,2] = [1,2] - [0,2] + [0,1]");
    tap_ok(K->simp[1][2] == 0 && K->simp[1][3] == 2, "edges in lexicographic order");
    dm_dec_complex_free(K);
    K = dm_dec_complex_alloc(2, 3, 1, R, &e);
    tap_ok(K->d[1]->val[0] == -1 && K->d[1]->val[1] == 1 && K->d[1]->val[2] == -1 &&
           K->top_sign[0] == -1, "input order [0,2,1] flips the column");
    tap_ok(K->boundary[1][0] && K->boundary[0][2] && K->boundary[2][0] == 0, "boundary flags of a triangle");
    dm_dec_complex_free(K);
  }
  /* one tetrahedron: faces (012, 013, 023, 123) */
  {
    int A[] = {0, 1, 2, 3}, B[] = {3, 2, 1, 0}, C[] = {1, 0, 2, 3};
    const double want[] = {-1, 1, -1, 1};
    int ok = 1;
    K = dm_dec_complex_alloc(3, 4, 1, A, NULL);
    for (i = 0; i < 4; i++)
      ok = ok && K->d[2]->val[i] == want[i] && K->d[2]->col[i] == i;
    tap_ok(ok, "boundary of [0,1,2,3] over (012,013,023,123) = (-1,+1,-1,+1)");
    dm_dec_complex_free(K);
    K = dm_dec_complex_alloc(3, 4, 1, B, NULL);
    for (i = 0; i < 4; i++)
      ok = ok && K->d[2]->val[i] == want[i];
    tap_ok(ok, "[3,2,1,0] is an even permutation: same column");
    dm_dec_complex_free(K);
    K = dm_dec_complex_alloc(3, 4, 1, C, NULL);
    for (i = 0; i < 4; i++)
      ok = ok && K->d[2]->val[i] == -want[i];
    tap_ok(ok, "[1,0,2,3] negates it");
    tap_ok(dd_max(K) == 0, "d d = 0 on a tetrahedron");
    dm_dec_complex_free(K);
  }

  /* icospheres: counts, Euler characteristic, d d = 0 */
  for (k = 0; k <= 3; k++) {
    int p = 1 << (2 * k);
    m = dm_dec_gen_sphere(1.0, k, NULL);
    K = from_mesh(m);
    tap_ok(K->nsimp[0] == 10 * p + 2 && K->nsimp[1] == 30 * p && K->nsimp[2] == 20 * p &&
           K->manifold && K->oriented,
           "icosphere level %d: %d %d %d, oriented manifold", k, K->nsimp[0], K->nsimp[1], K->nsimp[2]);
    tap_ok(dd_max(K) == 0, "d d = 0 exactly on icosphere %d", k);
    if (k == 2)
      check_betti(K, (const int[]){1, 0, 1}, "icosphere");
    dm_dec_meshdata_free(m);
    dm_dec_complex_free(K);
  }
  /* staggered torus */
  m = dm_dec_gen_torus(2.0, 1.0, 24, 12, NULL);
  K = from_mesh(m);
  tap_ok(K->nsimp[0] == 288 && K->nsimp[1] == 3 * 288 && K->nsimp[2] == 2 * 288 &&
         K->manifold && K->oriented && dm_dec_complex_check(K, NULL) == DM_OK,
         "torus 24 x 12: counts, oriented closed manifold");
  tap_ok(dd_max(K) == 0, "d d = 0 on the torus");
  check_betti(K, (const int[]){1, 2, 1}, "torus");
  for (i = 0; i < K->nsimp[1]; i++)
    if (K->boundary[1][i])
      break;
  tap_ok(i == K->nsimp[1], "a closed surface has no boundary edges");
  dm_dec_meshdata_free(m);
  dm_dec_complex_free(K);

  /* Stokes: <d a, c> = <a, boundary c> for an integer chain c */
  m = dm_dec_gen_disc(1.0, 6, NULL);
  K = from_mesh(m);
  {
    int ne = K->nsimp[1], nt = K->nsimp[2];
    double *a = malloc(ne * sizeof *a), *c = malloc(nt * sizeof *c), *da = malloc(nt * sizeof *da);
    double *bc = malloc(ne * sizeof *bc), lhs = 0, rhs = 0;
    for (i = 0; i < ne; i++)
      a[i] = sin(2.385 * i) * 3.1;
    for (i = 0; i < nt; i++)
      c[i] = irand(-3, 3);
    dm_sparse_gemv(K->d[1], a, da);
    dm_sparse_gemv_t(K->d[1], c, bc);
    for (i = 0; i < nt; i++)
      lhs += da[i] * c[i];
    for (i = 0; i < ne; i++)
      rhs += a[i] * bc[i];
    tap_near(lhs, rhs, 1e-14, "Stokes on a random integer 2-chain");
    /* de Rham map of x dy; d of it = area of every (counterclockwise) triangle */
    {
      double err = 0;
      for (i = 0; i < ne; i++) {
        const double *pa = m->X + 2 * K->simp[1][2 * i], *pb = m->X + 2 * K->simp[1][2 * i + 1];
        a[i] = 0.5 * (pa[0] + pb[0]) * (pb[1] - pa[1]);
      }
      dm_sparse_gemv(K->d[1], a, da);
      for (i = 0; i < nt; i++) {
        const int *v = K->top + 3 * i;
        const double *p0 = m->X + 2 * v[0], *p1 = m->X + 2 * v[1], *p2 = m->X + 2 * v[2];
        double area = 0.5 * ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]));
        err = fmax(err, fabs(da[i] - area) / area);
      }
      tap_ok(err < 1e-13, "d R(x dy) = triangle area (relative error %.2g)", err);
    }
    free(a);
    free(c);
    free(da);
    free(bc);
  }
  check_betti(K, (const int[]){1, 0, 0}, "disc");
  {
    int nb = 0;
    for (i = 0; i < K->nsimp[0]; i++)
      nb += K->boundary[0][i];
    tap_is_int(nb, 36, "disc of 6 rings: 36 boundary vertices");
  }
  dm_dec_meshdata_free(m);
  dm_dec_complex_free(K);

  m = dm_dec_gen_annulus(1.0, 2.0, 4, 24, NULL);
  K = from_mesh(m);
  check_betti(K, (const int[]){1, 1, 0}, "annulus");
  tap_ok(dd_max(K) == 0 && K->oriented, "annulus: d d = 0, oriented");
  dm_dec_meshdata_free(m);
  dm_dec_complex_free(K);

  /* square grid 9 x 9 with 4 one-square holes: b = (1, 4, 0) */
  m = dm_dec_gen_grid(9, 9, 0, 1, 0, 1, NULL);
  {
    int *T = malloc(m->ntop * 3 * sizeof *T), nt = 0, t;
    for (t = 0; t < m->ntop; t++) {
      int sq = t / 2, sx = sq % 9, sy = sq / 9;
      if ((sx == 2 || sx == 6) && (sy == 2 || sy == 6))
        continue;
      memcpy(T + 3 * nt++, m->T + 3 * t, 3 * sizeof *T);
    }
    K = dm_dec_complex_alloc(2, m->nv, nt, T, NULL);
    check_betti(K, (const int[]){1, 4, 0}, "square with 4 holes");
    dm_dec_complex_free(K);
    free(T);
  }
  dm_dec_meshdata_free(m);

  /* tetrahedral box, and a solid torus (3 x 3 x 1 cubes without the centre) */
  m = dm_dec_gen_box(3, 3, 1, 3, 3, 1, NULL);
  K = from_mesh(m);
  tap_ok(K->nsimp[3] == 54 && K->nsimp[0] == 32 && dd_max(K) == 0 && K->manifold && K->oriented,
         "box 3x3x1: 54 tets, d d = 0, oriented manifold");
  check_betti(K, (const int[]){1, 0, 0, 0}, "box");
  dm_dec_complex_free(K);
  {
    int *T = malloc(m->ntop * 4 * sizeof *T), nt = 0, t;
    for (t = 0; t < m->ntop; t++)
      if (t / 6 != 4)
        memcpy(T + 4 * nt++, m->T + 4 * t, 4 * sizeof *T);
    K = dm_dec_complex_alloc(3, m->nv, nt, T, &e);
    check_betti(K, (const int[]){1, 1, 0, 0}, "solid torus");
    dm_dec_complex_free(K);
    free(T);
  }
  dm_dec_meshdata_free(m);

  /* lookup */
  m = dm_dec_gen_grid(3, 2, 0, 1, 0, 1, NULL);
  K = from_mesh(m);
  {
    int ed[] = {5, 1}, tri[] = {5, 0, 1}, no[] = {0, 7};
    int s = dm_dec_find(K, 1, ed);
    tap_ok(s >= 0 && K->simp[1][2 * s] == 1 && K->simp[1][2 * s + 1] == 5, "find an edge by its vertices");
    tap_ok(dm_dec_find(K, 2, tri) == 0 && dm_dec_find(K, 1, no) == -1, "find a triangle; a missing edge");
  }
  dm_dec_meshdata_free(m);
  dm_dec_complex_free(K);

  /* errors */
  {
    int T1[] = {0, 1, 5}, T2[] = {0, 1, 1}, T3[] = {0, 1, 2, 2, 1, 0}, T4[] = {0, 1, 2};
    int T5[] = {0, 1, 2, 0, 1, 3, 0, 1, 4}, T6[] = {0, 1, 2, 0, 1, 3};
    tap_ok(dm_dec_complex_alloc(2, 3, 1, T1, &e) == NULL &&
           strcmp(e.msg, "simplex 1: vertex 6 outside 1..3") == 0, "%s", e.msg);
    tap_ok(dm_dec_complex_alloc(2, 3, 1, T2, &e) == NULL &&
           strcmp(e.msg, "simplex 1 repeats vertex 2") == 0, "%s", e.msg);
    tap_ok(dm_dec_complex_alloc(2, 3, 2, T3, &e) == NULL &&
           strcmp(e.msg, "simplices 1 and 2 have the same vertices") == 0, "%s", e.msg);
    tap_ok(dm_dec_complex_alloc(2, 4, 1, T4, &e) == NULL &&
           strcmp(e.msg, "vertex 4 belongs to no simplex (only pure complexes are supported)") == 0,
           "%s", e.msg);
    tap_ok(dm_dec_complex_alloc(5, 4, 1, T4, &e) == NULL &&
           strcmp(e.msg, "complex: dimension 5 outside 1..4") == 0, "%s", e.msg);
    K = dm_dec_complex_alloc(2, 5, 3, T5, NULL);
    tap_ok(!K->manifold && dm_dec_complex_check(K, &e) == DM_EINVAL &&
           strcmp(e.msg, "non-manifold: edge (1,2) is a face of 3 simplices (1, 2, 3)") == 0, "%s", e.msg);
    dm_dec_complex_free(K);
    K = dm_dec_complex_alloc(2, 4, 2, T6, NULL);
    tap_ok(!K->oriented && dm_dec_complex_check(K, &e) == DM_EINVAL &&
           strcmp(e.msg, "inconsistent orientation: simplices 1 and 2 induce the same orientation on their shared edge (1,2)") == 0,
           "%s", e.msg);
    dm_dec_complex_free(K);
    tap_ok(dm_dec_gen_torus(2, 1, 10, 7, &e) == NULL &&
           strcmp(e.msg, "torus: R > r > 0, m >= 3 and an even n >= 4 expected") == 0, "%s", e.msg);
  }
  /* the constant local-face tables against a direct enumeration */
  {
    int n, ok = 1;
    for (n = 1; n <= DM_DEC_MAXDIM; n++) {
      int cnt[DM_DEC_MAXDIM + 1] = {0};
      unsigned mk, prev[DM_DEC_MAXDIM + 1] = {0};
      for (mk = 1; mk < (1u << (n + 1)); mk++) {
        int kk = __builtin_popcount(mk) - 1, j = dm_dec_face_index(n, mk);
        ok = ok && dm_dec_face_mask(n, kk, j) == mk;
        cnt[kk]++;
      }
      for (k = 0; k <= n; k++) {
        int j, c = 0;
        for (j = 0; dm_dec_face_mask(n, k, j) != 0 && j < 10; j++) {
          unsigned a = dm_dec_face_mask(n, k, j), b = prev[k];
          /* lexicographic order of the vertex tuples: compare lowest differing bit */
          if (j > 0) {
            unsigned d = a ^ b;
            ok = ok && (d & -d & b) != 0;
          }
          prev[k] = a;
          c++;
        }
        ok = ok && c == cnt[k];
      }
    }
    tap_ok(ok, "local face tables: masks and indices invert each other, lexicographic order");
  }
  dm_dec_complex_free(NULL);
  dm_dec_meshdata_free(NULL);
  return tap_done();
}
