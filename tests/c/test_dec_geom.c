/* test_dec_geom.c -- circumcentric duals, Hodge stars, codifferential and
 * Laplacians: exact values on small simplices, the cotangent formula against
 * the flag sums, intrinsic against embedded, support-volume tiling, star
 * signs, adjointness, stencils, exactness on quadratics, Dirichlet solves,
 * spectra of the sphere and the torus, convergence order. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "dec/dec.h"
#include "dec/dec_impl.h"

typedef struct {
  dm_dec_meshdata *m;
  dm_dec_complex *K;
  dm_dec_geom *G;
} mesh;

static mesh make(dm_dec_meshdata *m)
{
  mesh r;
  dm_err e;
  r.m = m;
  r.K = dm_dec_complex_alloc(m->n, m->nv, m->ntop, m->T, &e);
  r.G = r.K ? dm_dec_geom_alloc(r.K, m->N, m->X, &e) : NULL;
  if (r.G == NULL)
    tap_diag("mesh: %s", e.msg);
  return r;
}

static mesh make_raw(int n, int N, int nv, const double *X, int ntop, const int *T)
{
  dm_dec_meshdata *m = dm_dec_meshdata_alloc(n, N, nv, ntop, NULL);
  memcpy(m->X, X, sizeof(double) * (size_t)(nv * N));
  memcpy(m->T, T, sizeof(int) * (size_t)(ntop * (n + 1)));
  return make(m);
}

static void drop(mesh *r)
{
  dm_dec_geom_free(r->G);
  dm_dec_complex_free(r->K);
  dm_dec_meshdata_free(r->m);
}

static double *star(const mesh *r, int k)
{
  double *s = malloc(((size_t)r->K->nsimp[k] + 1) * sizeof *s);
  dm_dec_star(r->G, k, 0, s, NULL);
  return s;
}

static int near_all(const double *got, const double *want, int n, double tol)
{
  int i;
  for (i = 0; i < n; i++)
    if (!(fabs(got[i] - want[i]) <= tol * fmax(1.0, fabs(want[i])))) {
      tap_diag("entry %d: got %.17g want %.17g", i, got[i], want[i]);
      return 0;
    }
  return 1;
}

static int is_interior_vertex(const dm_dec_complex *K, int v)
{
  return !K->boundary[0][v];
}

/* Sigma_s |s| |*s| / |K| for every k. */
static void tiling(const mesh *r, double *out)
{
  int k, s, n = r->K->n;
  double total = 0;
  for (s = 0; s < r->K->nsimp[n]; s++)
    total += r->G->vol[n][s];
  for (k = 0; k <= n; k++) {
    double acc = 0;
    for (s = 0; s < r->K->nsimp[k]; s++)
      acc += r->G->vol[k][s] * r->G->dual[k][s];
    out[k] = acc / total;
  }
}

static double s3 = 1.7320508075688772;

int main(void)
{
  dm_err e;
  int i, k;
  /* equilateral triangle, side 1 */
  {
    double X[] = {0, 0, 1, 0, 0.5, 0.8660254037844386};
    int T[] = {0, 1, 2};
    mesh r = make_raw(2, 2, 3, X, 1, T);
    double *s0 = star(&r, 0), *s1 = star(&r, 1), *s2 = star(&r, 2);
    double w0[] = {s3 / 12, s3 / 12, s3 / 12}, w1[] = {s3 / 6, s3 / 6, s3 / 6}, w2[] = {4 / s3};
    tap_ok(near_all(s0, w0, 3, 1e-12) && near_all(s1, w1, 3, 1e-12) && near_all(s2, w2, 1, 1e-12),
           "equilateral triangle: stars sqrt3/12, sqrt3/6, 4/sqrt3");
    tap_ok(r.G->not_well_centered == 0 && r.G->nonpos[0] == 0, "equilateral triangle is well-centered");
    free(s0); free(s1); free(s2);
    drop(&r);
  }
  /* regular tetrahedron */
  {
    double X[] = {0, 0, 0, 0, 1, 1, 1, 0, 1, 1, 1, 0};
    int T[] = {0, 1, 2, 3};
    mesh r = make_raw(3, 3, 4, X, 1, T);
    double dv[] = {1.0 / 12, sqrt(2.0) / 12, s3 / 6, 1}, pv[] = {1, sqrt(2.0), s3 / 2, 1.0 / 3};
    double st[] = {1.0 / 12, 1.0 / 12, 1.0 / 3, 3}, t[4];
    int ok = 1;
    for (k = 0; k <= 3; k++) {
      double *s = star(&r, k);
      for (i = 0; i < r.K->nsimp[k]; i++)
        ok = ok && fabs(r.G->dual[k][i] - dv[k]) < 1e-12 && fabs(r.G->vol[k][i] - pv[k]) < 1e-12 &&
             fabs(s[i] - st[k]) < 1e-12;
      free(s);
    }
    tap_ok(ok, "regular tetrahedron: dual volumes, volumes and stars");
    tiling(&r, t);
    tap_ok(fabs(t[0] - 1) < 1e-12 && fabs(t[1] - 3) < 1e-12 && fabs(t[2] - 3) < 1e-12 &&
           fabs(t[3] - 1) < 1e-12, "tetrahedron: sum |s||*s| = C(3,k)|K|");
    drop(&r);
  }
  /* right triangle: circumcentre on the hypotenuse */
  {
    double X[] = {0, 0, 1, 0, 0, 1};
    int T[] = {0, 1, 2};
    mesh r = make_raw(2, 2, 3, X, 1, T);
    double *s0 = star(&r, 0), *s1 = star(&r, 1), *s2 = star(&r, 2), inv[3];
    double w0[] = {0.25, 0.125, 0.125}, w1[] = {0.5, 0.5, 0}, w2[] = {2};
    tap_ok(near_all(s0, w0, 3, 1e-12) && near_all(s1, w1, 3, 1e-12) && near_all(s2, w2, 1, 1e-12),
           "right triangle: *0 = (1/4,1/8,1/8), *1 = (1/2,1/2,0), *2 = 2");
    tap_ok(r.G->not_well_centered == 1, "right triangle: not well-centered");
    tap_ok(dm_dec_star(r.G, 1, 1, inv, &e) == DM_ESINGULAR &&
           strcmp(e.msg, "inverse Hodge star in degree 1: the dual cell of 1-simplex 3 (2,3) has zero volume") == 0,
           "%s", e.msg);
    free(s0); free(s1); free(s2);
    drop(&r);
  }
  /* obtuse triangle: signed duals */
  {
    double X[] = {0, 0, 2, 0, 1, 0.4};
    int T[] = {0, 1, 2};
    mesh r = make_raw(2, 2, 3, X, 1, T);
    double *s0 = star(&r, 0), *s1 = star(&r, 1), b[3];
    double w0[] = {-0.1625, -0.1625, 0.725}, w1[] = {-0.525, 1.25, 1.25};
    tap_ok(near_all(s0, w0, 3, 1e-12), "obtuse triangle: signed *0");
    tap_ok(near_all(s1, w1, 3, 1e-12), "obtuse triangle: *1 negative on the long edge");
    tap_ok(r.G->nonpos[0] == 2 && r.G->nonpos[1] == 1, "nonpositive duals counted");
    dm_dec_circumcenter_bary(r.G, 2, 0, b, NULL);
    tap_ok(fabs(r.G->cc[2][0] - 1) < 1e-12 && fabs(r.G->cc[2][1] + 1.05) < 1e-12 && b[2] < 0,
           "circumcentre (1, -1.05) outside, negative barycentric");
    free(s0); free(s1);
    drop(&r);
  }
  /* two equilateral triangles; the same in R^6 after a translation */
  {
    double X[] = {0, 0, 1, 0, 0.5, s3 / 2, 1.5, s3 / 2}, Y[24];
    int T[] = {0, 1, 2, 1, 3, 2};
    mesh r = make_raw(2, 2, 4, X, 2, T), q;
    double w0[] = {s3 / 12, s3 / 6, s3 / 6, s3 / 12}, w1[5];
    double *s0 = star(&r, 0), *s1 = star(&r, 1), *t0, *t1;
    int shared = dm_dec_find(r.K, 1, (const int[]){1, 2});
    for (i = 0; i < 5; i++)
      w1[i] = i == shared ? s3 / 3 : s3 / 6;
    tap_ok(near_all(s0, w0, 4, 1e-12) && near_all(s1, w1, 5, 1e-12), "two equilateral triangles");
    for (i = 0; i < 4; i++)
      for (k = 0; k < 6; k++)
        Y[6 * i + k] = (k < 2 ? X[2 * i + k] : 0) + 0.1 * (k + 1) + 2.385;
    q = make_raw(2, 6, 4, Y, 2, T);
    t0 = star(&q, 0);
    t1 = star(&q, 1);
    tap_ok(near_all(t0, s0, 4, 1e-12) && near_all(t1, s1, 5, 1e-12), "unchanged in R^6, translated");
    free(s0); free(s1); free(t0); free(t1);
    drop(&r);
    drop(&q);
  }
  /* perturbed regular 4-simplex in R^5: support volumes tile C(4,k) times */
  {
    double X[25], t[5];
    int T[] = {0, 1, 2, 3, 4}, ok;
    for (i = 0; i < 25; i++)
      X[i] = (i % 6 == 0 ? 1.0 : 0.0) + 0.01 * sin(2.385 * (i + 1));
    mesh r = make_raw(4, 5, 5, X, 1, T);
    tiling(&r, t);
    ok = r.G->not_well_centered == 0 && fabs(t[0] - 1) < 1e-12 && fabs(t[1] - 4) < 1e-12 &&
         fabs(t[2] - 6) < 1e-12 && fabs(t[3] - 4) < 1e-12 && fabs(t[4] - 1) < 1e-12;
    tap_ok(ok, "4-simplex: sum |s||*s|/|K| = %.14g %.14g %.14g %.14g %.14g", t[0], t[1], t[2], t[3], t[4]);
    drop(&r);
  }
  /* cotangent formula = flag sums, on an irregular mesh with obtuse triangles */
  {
    mesh r = make(dm_dec_gen_disc(1.0, 5, NULL));
    double dmax = 0;
    int t;
    for (i = 0; i < r.m->nv; i++)      /* jiggle interior vertices */
      if (is_interior_vertex(r.K, i)) {
        r.m->X[2 * i] += 0.06 * sin(7.1 * i);
        r.m->X[2 * i + 1] += 0.06 * cos(5.3 * i);
      }
    dm_dec_geom_free(r.G);
    r.G = dm_dec_geom_alloc(r.K, 2, r.m->X, NULL);
    for (t = 0; t < r.K->nsimp[2]; t++) {
      double D[9], v1[8], p1[8], v2[8], p2[8];
      const int *v = r.K->simp[2] + 3 * t;
      unsigned msk;
      for (i = 0; i < 9; i++) {
        const double *a = r.m->X + 2 * v[i / 3], *b = r.m->X + 2 * v[i % 3];
        D[i] = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]);
      }
      dm_dec__top_pieces(2, D, 0, v1, p1);
      dm_dec__top_pieces(2, D, 1, v2, p2);
      for (msk = 1; msk < 8; msk++)
        dmax = fmax(dmax, fabs(p1[msk] - p2[msk]) + fabs(v1[msk] - v2[msk]));
    }
    tap_ok(dmax < 1e-14, "cotangent formula equals the signed flag sums (max diff %.2g)", dmax);
    tap_ok(r.G->not_well_centered > 0, "the jiggled disc has %d non-well-centred simplices",
           r.G->not_well_centered);
    /* Laplacian of x^2 + y^2 is -4 at every interior vertex, even there */
    {
      dm_sparse *L;
      double *f = malloc(r.m->nv * sizeof *f), *g = malloc(r.m->nv * sizeof *g), err = 0;
      dm_dec_laplacian(r.G, 0, &L, NULL, NULL);
      for (i = 0; i < r.m->nv; i++)
        f[i] = r.m->X[2 * i] * r.m->X[2 * i] + r.m->X[2 * i + 1] * r.m->X[2 * i + 1];
      dm_sparse_gemv(L, f, g);
      for (i = 0; i < r.m->nv; i++)
        if (is_interior_vertex(r.K, i))
          err = fmax(err, fabs(g[i] + 4));
      tap_ok(err < 1e-11, "Delta0 (x^2+y^2) = -4 at interior vertices of an obtuse mesh (%.2g)", err);
      for (i = 0; i < r.m->nv; i++)
        f[i] = 2.385 * r.m->X[2 * i] - 1.5 * r.m->X[2 * i + 1] + 0.25;
      dm_sparse_gemv(L, f, g);
      err = 0;
      for (i = 0; i < r.m->nv; i++)
        if (is_interior_vertex(r.K, i))
          err = fmax(err, fabs(g[i]));
      tap_ok(err < 1e-12, "Delta0 of a linear function vanishes inside (%.2g)", err);
      free(f);
      free(g);
      dm_sparse_free(L);
    }
    drop(&r);
  }
  /* intrinsic = embedded; circumradius check */
  {
    mesh r = make(dm_dec_gen_box(2, 2, 2, 1.0, 1.3, 0.9, NULL));
    dm_dec_geom *I;
    double dmax = 0;
    for (i = 0; i < r.m->nv; i++) {
      r.m->X[3 * i] += 0.03 * sin(3.3 * i);
      r.m->X[3 * i + 2] += 0.03 * cos(1.7 * i);
    }
    dm_dec_geom_free(r.G);
    r.G = dm_dec_geom_alloc(r.K, 3, r.m->X, NULL);
    I = dm_dec_geom_alloc_intrinsic(r.K, r.G->len2, &e);
    for (k = 0; k <= 3; k++)
      for (i = 0; i < r.K->nsimp[k]; i++)
        dmax = fmax(dmax, fabs(I->dual[k][i] - r.G->dual[k][i]) + fabs(I->vol[k][i] - r.G->vol[k][i]));
    tap_ok(I != NULL && I->X == NULL && dmax < 1e-12, "intrinsic and embedded duals agree (%.2g)", dmax);
    /* the circumcentre is equidistant from the vertices of every tet */
    dmax = 0;
    for (i = 0; i < r.K->nsimp[3]; i++) {
      const double *c = r.G->cc[3] + 3 * i;
      double R0 = -1;
      for (k = 0; k < 4; k++) {
        const double *x = r.m->X + 3 * r.K->simp[3][4 * i + k];
        double d = sqrt((x[0] - c[0]) * (x[0] - c[0]) + (x[1] - c[1]) * (x[1] - c[1]) +
                        (x[2] - c[2]) * (x[2] - c[2]));
        if (R0 < 0)
          R0 = d;
        dmax = fmax(dmax, fabs(d - R0));
      }
    }
    tap_ok(dmax < 1e-12, "circumcentres equidistant from the vertices (%.2g)", dmax);
    {
      double *bad = malloc(r.K->nsimp[1] * sizeof *bad);
      memcpy(bad, r.G->len2, r.K->nsimp[1] * sizeof *bad);
      bad[0] = 40.0;
      tap_ok(dm_dec_geom_alloc_intrinsic(r.K, bad, &e) == NULL && e.status == DM_EDOM,
             "lengths violating the triangle inequality: %s", e.msg);
      bad[0] = -1;
      tap_ok(dm_dec_geom_alloc_intrinsic(r.K, bad, &e) == NULL &&
             strcmp(e.msg, "edge (1,2): squared length -1 (positive expected)") == 0, "%s", e.msg);
      free(bad);
    }
    dm_dec_geom_free(I);
    drop(&r);
  }
  /* a flat tetrahedron with valid triangles: Cayley-Menger */
  {
    int T[] = {0, 1, 2, 3};
    dm_dec_complex *K = dm_dec_complex_alloc(3, 4, 1, T, NULL);
    double l2[6];
    for (i = 0; i < 6; i++)
      l2[i] = 1.0;
    l2[5] = 3.9;          /* edge (3,4): triangles fine (sqrt 3.9 < 2), no tetrahedron */
    l2[0] = 1.0;
    tap_ok(dm_dec_geom_alloc_intrinsic(K, l2, &e) == NULL && e.status == DM_EDOM &&
           strstr(e.msg, "degenerate 3-simplex") != NULL, "Cayley-Menger: %s", e.msg);
    dm_dec_complex_free(K);
  }
  /* ** = (-1)^(k(n-k)) on well-centred meshes */
  {
    mesh r2 = make(dm_dec_gen_sphere(1.0, 1, NULL));
    double X[] = {0, 0, 0, 0, 1, 1, 1, 0, 1, 1, 1, 0};
    int T[] = {0, 1, 2, 3}, ok = 1;
    mesh r3 = make_raw(3, 3, 4, X, 1, T);
    mesh *rs[2] = {&r2, &r3};
    int j;
    for (j = 0; j < 2; j++) {
      int n = rs[j]->K->n;
      for (k = 0; k <= n; k++) {
        double *a = star(rs[j], k), *b = malloc(rs[j]->K->nsimp[k] * sizeof *b);
        dm_dec_star(rs[j]->G, k, 1, b, NULL);
        for (i = 0; i < rs[j]->K->nsimp[k]; i++)
          ok = ok && fabs(a[i] * b[i] - ((k * (n - k)) % 2 ? -1 : 1)) < 1e-13;
        free(a);
        free(b);
      }
    }
    tap_ok(ok, "** = (-1)^(k(n-k)) on a sphere and a tetrahedron");
    drop(&r2);
    drop(&r3);
  }
  /* right-triangle grid: stars and the 5-point stencil */
  {
    int N = 6;
    double h = 1.0 / N, err = 0;
    mesh r = make(dm_dec_gen_grid(N, N, 0, 1, 0, 1, NULL));
    double *s0 = star(&r, 0), *s1 = star(&r, 1), *s2 = star(&r, 2);
    int ok0 = 1, ok1 = 1, ok2 = 1;
    dm_sparse *L;
    for (i = 0; i < r.m->nv; i++) {
      int ix = i % (N + 1), iy = i / (N + 1), nb = (ix == 0 || ix == N) + (iy == 0 || iy == N);
      ok0 = ok0 && fabs(s0[i] - h * h / (1 << nb)) < 1e-14;
    }
    for (i = 0; i < r.K->nsimp[1]; i++) {
      int a = r.K->simp[1][2 * i], b = r.K->simp[1][2 * i + 1];
      int diag = (b - a) == N + 2, want2 = r.K->boundary[1][i] ? 1 : 2;
      ok1 = ok1 && fabs(s1[i] - (diag ? 0.0 : want2 * 0.5)) < 1e-12;
    }
    for (i = 0; i < r.K->nsimp[2]; i++)
      ok2 = ok2 && fabs(s2[i] - 2 / (h * h)) < 1e-9;
    tap_ok(ok0 && ok1 && ok2, "right-triangle grid: *0 = h^2 (1/2 sides, 1/4 corners), *1 = 1, 1/2, 0, *2 = 2/h^2");
    dm_dec_laplacian(r.G, 0, &L, NULL, NULL);
    for (i = 0; i < r.m->nv; i++) {
      int j, p;
      if (r.K->boundary[0][i])
        continue;
      for (p = L->rowptr[i]; p < L->rowptr[i + 1]; p++) {
        j = L->col[p];
        double want = j == i ? 4 : (abs(j - i) == 1 || abs(j - i) == N + 1) ? -1 : 0;
        err = fmax(err, fabs(h * h * L->val[p] - want));
      }
    }
    tap_ok(err < 1e-12, "interior rows of h^2 Delta0 are the 5-point stencil (%.2g)", err);
    free(s0); free(s1); free(s2);
    dm_sparse_free(L);
    drop(&r);
  }
  /* harmonic polynomials on the grid: Dirichlet solution exact */
  {
    int N = 8, j;
    mesh r = make(dm_dec_gen_grid(N, N, 0, 1, 0, 1, NULL));
    dm_sparse *S;
    dm_dec_solver *F;
    double *g = malloc(r.m->nv * sizeof *g), *u = malloc(r.m->nv * sizeof *u);
    double *f = calloc(r.m->nv, sizeof *f), *w = star(&r, 0);
    dm_dec_laplacian(r.G, 0, NULL, &S, NULL);
    F = dm_dec_solver_alloc(S, r.K->boundary[0], &e);
    for (j = 0; j < 3; j++) {
      double err = 0;
      for (i = 0; i < r.m->nv; i++) {
        double x = r.m->X[2 * i], y = r.m->X[2 * i + 1];
        g[i] = j == 0 ? x * x - y * y : j == 1 ? x * y : x * x * x - 3 * x * y * y;
      }
      dm_dec_solver_solve(F, w, f, g, u, NULL);
      for (i = 0; i < r.m->nv; i++)
        err = fmax(err, fabs(u[i] - g[i]));
      tap_ok(err < 1e-13, "harmonic polynomial %d reproduced by the Dirichlet solve (%.2g)", j + 1, err);
    }
    dm_dec_solver_free(F);
    free(g); free(u); free(f); free(w);
    dm_sparse_free(S);
    drop(&r);
  }
  /* 1-D path: Delta0 and Delta1 */
  {
    mesh r = make(dm_dec_gen_path(4, NULL, NULL));
    dm_sparse *L0, *L1;
    double W0[25] = {2, -2, 0, 0, 0, -1, 2, -1, 0, 0, 0, -1, 2, -1, 0, 0, 0, -1, 2, -1, 0, 0, 0, -2, 2};
    double W1[16] = {3, -1, 0, 0, -1, 2, -1, 0, 0, -1, 2, -1, 0, 0, -1, 3};
    int ok = 1, j;
    dm_dec_laplacian(r.G, 0, &L0, NULL, NULL);
    dm_dec_laplacian(r.G, 1, &L1, NULL, NULL);
    for (i = 0; i < 5; i++)
      for (j = 0; j < 5; j++)
        ok = ok && dm_sparse_get(L0, i, j) == W0[5 * i + j];
    for (i = 0; i < 4; i++)
      for (j = 0; j < 4; j++)
        ok = ok && dm_sparse_get(L1, i, j) == W1[4 * i + j];
    tap_ok(ok, "path of 5 vertices: Delta0 and Delta1 exactly");
    dm_sparse_free(L0);
    dm_sparse_free(L1);
    drop(&r);
  }
  /* disc: Dirichlet Poisson with a quadratic solution is exact */
  {
    mesh r = make(dm_dec_gen_disc(1.0, 12, NULL));
    dm_sparse *S;
    dm_dec_solver *F;
    double *f = malloc(r.m->nv * sizeof *f), *u = malloc(r.m->nv * sizeof *u), *w = star(&r, 0);
    double err = 0;
    for (i = 0; i < r.m->nv; i++)
      f[i] = 4.0;
    dm_dec_laplacian(r.G, 0, NULL, &S, NULL);
    tap_ok(dm_sparse_asymmetry(S) < 1e-13, "symmetric form of Delta0 is symmetric");
    F = dm_dec_solver_alloc(S, r.K->boundary[0], NULL);
    dm_dec_solver_solve(F, w, f, NULL, u, NULL);
    for (i = 0; i < r.m->nv; i++) {
      double x = r.m->X[2 * i], y = r.m->X[2 * i + 1];
      err = fmax(err, fabs(u[i] - (1 - x * x - y * y)));
    }
    tap_ok(err < 1e-12, "Delta0 u = 4, u = 0 on the circle: u = 1 - r^2 at the vertices (%.2g)", err);
    dm_dec_solver_free(F);
    F = dm_dec_solver_alloc(S, NULL, &e);
    tap_ok(F == NULL && e.status == DM_ESINGULAR, "no boundary condition: singular (%s)", e.msg);
    free(f); free(u); free(w);
    dm_sparse_free(S);
    drop(&r);
  }
  /* convergence: u = cos(pi r^2 / 2) on the unit disc, order 2 at vertices */
  {
    double err[3];
    int lev;
    for (lev = 0; lev < 3; lev++) {
      mesh r = make(dm_dec_gen_disc(1.0, 6 << lev, NULL));
      dm_sparse *S;
      dm_dec_solver *F;
      double *f = malloc(r.m->nv * sizeof *f), *u = malloc(r.m->nv * sizeof *u), *w = star(&r, 0);
      const double pi = M_PI;
      err[lev] = 0;
      for (i = 0; i < r.m->nv; i++) {
        double x = r.m->X[2 * i], y = r.m->X[2 * i + 1], q = x * x + y * y;
        /* -lap cos(pi q/2) = 2 pi sin(pi q/2) + pi^2 q cos(pi q/2) */
        f[i] = 2 * pi * sin(pi * q / 2) + pi * pi * q * cos(pi * q / 2);
      }
      dm_dec_laplacian(r.G, 0, NULL, &S, NULL);
      F = dm_dec_solver_alloc(S, r.K->boundary[0], NULL);
      dm_dec_solver_solve(F, w, f, NULL, u, NULL);
      for (i = 0; i < r.m->nv; i++) {
        double x = r.m->X[2 * i], y = r.m->X[2 * i + 1];
        err[lev] = fmax(err[lev], fabs(u[i] - cos(pi * (x * x + y * y) / 2)));
      }
      dm_dec_solver_free(F);
      free(f); free(u); free(w);
      dm_sparse_free(S);
      drop(&r);
    }
    tap_ok(log2(err[0] / err[1]) > 1.9 && log2(err[1] / err[2]) > 1.9,
           "Poisson on the disc: max errors %.3g %.3g %.3g, orders %.2f %.2f", err[0], err[1], err[2],
           log2(err[0] / err[1]), log2(err[1] / err[2]));
  }
  /* icosphere level 2: spectrum of Delta0 */
  {
    mesh r = make(dm_dec_gen_sphere(1.0, 2, NULL));
    dm_sparse *S;
    double *m = star(&r, 0), lam[16], area = 0;
    const double want[16] = {0, 1.9999905, 1.9999905, 1.9999905, 5.865269, 5.865269, 5.865269,
                             5.865269, 5.865269, 11.23404, 11.23404, 11.23404, 11.41460,
                             11.41460, 11.41460, 11.41460};
    int ok;
    dm_dec_laplacian(r.G, 0, NULL, &S, NULL);
    for (i = 0; i < r.m->nv; i++)
      area += m[i];
    ok = dm_sparse_eigsh(S, m, 16, -1e-3, 0, lam, NULL, &e) == DM_OK && fabs(lam[0]) < 1e-10;
    for (i = 1; i < 16; i++)
      ok = ok && fabs(lam[i] - want[i]) < 1e-5 * want[i];
    tap_ok(ok, "icosphere 162: eigenvalues %.7g %.7g %.7g %.7g %.7g", lam[0], lam[1], lam[4], lam[9], lam[15]);
    tap_near(area, 12.329849, 1e-7, "icosphere 162: total dual area");
    free(m);
    dm_sparse_free(S);
    drop(&r);
  }
  /* torus 24 x 12: harmonic 1-forms, shared spectra, adjointness of delta */
  {
    mesh r = make(dm_dec_gen_torus(2.0, 1.0, 24, 12, NULL));
    dm_sparse *S0, *S1, *S2, *del;
    double *m0 = star(&r, 0), *m1 = star(&r, 1), *m2 = star(&r, 2), l0[3], l1[6], l2[3], mn = 1e9;
    int ok;
    for (i = 0; i < r.K->nsimp[1]; i++)
      mn = fmin(mn, m1[i]);
    tap_near(mn, 0.26917, 1e-4, "torus: min *1 > 0");
    dm_dec_laplacian(r.G, 0, NULL, &S0, NULL);
    dm_dec_laplacian(r.G, 1, NULL, &S1, NULL);
    dm_dec_laplacian(r.G, 2, NULL, &S2, NULL);
    ok = dm_sparse_eigsh(S1, m1, 6, -1e-3, 0, l1, NULL, &e) == DM_OK;
    ok = ok && dm_sparse_eigsh(S0, m0, 3, -1e-3, 0, l0, NULL, &e) == DM_OK;
    ok = ok && dm_sparse_eigsh(S2, m2, 3, -1e-3, 0, l2, NULL, &e) == DM_OK;
    tap_ok(ok && fabs(l1[0]) < 1e-10 && fabs(l1[1]) < 1e-10 && l1[2] > 0.2,
           "torus: Delta1 has exactly 2 zero eigenvalues (b1 = 2): %.3g %.3g %.7g", l1[0], l1[1], l1[2]);
    tap_ok(fabs(l1[2] - 0.2501765) < 1e-6 && fabs(l1[3] - 0.2501765) < 1e-6 &&
           fabs(l1[4] - 0.2516426) < 1e-6 && fabs(l1[5] - 0.2516426) < 1e-6,
           "torus: next eigenvalues of Delta1 %.7g %.7g %.7g %.7g", l1[2], l1[3], l1[4], l1[5]);
    tap_ok(fabs(l0[0]) < 1e-10 && fabs(l0[1] - 0.2516426) < 1e-6 && fabs(l2[0]) < 1e-10 &&
           fabs(l2[1] - 0.2501765) < 1e-6,
           "torus: Delta0 and Delta2 have one zero eigenvalue and share the others with Delta1");
    /* <d a, b>_{k+1} = <a, delta b>_k */
    for (k = 0; k < 2; k++) {
      int na = r.K->nsimp[k], nb = r.K->nsimp[k + 1];
      double *a = malloc(na * sizeof *a), *b = malloc(nb * sizeof *b), *da = malloc(nb * sizeof *da);
      double *db = malloc(na * sizeof *db), *sa = star(&r, k), *sb = star(&r, k + 1), lhs = 0, rhs = 0;
      for (i = 0; i < na; i++)
        a[i] = sin(2.385 * i + k);
      for (i = 0; i < nb; i++)
        b[i] = cos(1.234 * i - k);
      del = dm_dec_codiff(r.G, k + 1, NULL);
      dm_sparse_gemv(r.K->d[k], a, da);
      dm_sparse_gemv(del, b, db);
      for (i = 0; i < nb; i++)
        lhs += da[i] * sb[i] * b[i];
      for (i = 0; i < na; i++)
        rhs += a[i] * sa[i] * db[i];
      tap_near(lhs, rhs, 1e-12, "delta_%d is the adjoint of d_%d in the star inner product", k + 1, k);
      free(a); free(b); free(da); free(db); free(sa); free(sb);
      dm_sparse_free(del);
    }
    free(m0); free(m1); free(m2);
    dm_sparse_free(S0); dm_sparse_free(S1); dm_sparse_free(S2);
    drop(&r);
  }
  /* dual derivative signs: 2D D0 = d1^T, D1 = -d0^T; 3D D0 = -d2^T */
  {
    mesh r = make(dm_dec_gen_grid(2, 2, 0, 1, 0, 1, NULL));
    mesh q = make(dm_dec_gen_box(1, 1, 1, 1, 1, 1, NULL));
    dm_sparse *D0 = dm_dec_dual_d(r.K, 0, NULL), *D1 = dm_dec_dual_d(r.K, 1, NULL);
    dm_sparse *E0 = dm_dec_dual_d(q.K, 0, NULL);
    int ok;
    {
      dm_sparse *T1 = dm_sparse_transpose(r.K->d[1], NULL), *T0 = dm_sparse_transpose(r.K->d[0], NULL);
      dm_sparse *T2 = dm_sparse_transpose(q.K->d[2], NULL);
      dm_sparse *a = dm_sparse_add(1, D0, -1, T1, NULL), *b = dm_sparse_add(1, D1, 1, T0, NULL);
      dm_sparse *c = dm_sparse_add(1, E0, 1, T2, NULL);
      ok = dm_sparse_maxabs(a) == 0 && dm_sparse_maxabs(b) == 0 && dm_sparse_maxabs(c) == 0;
      dm_sparse_free(T1); dm_sparse_free(T0); dm_sparse_free(T2);
      dm_sparse_free(a); dm_sparse_free(b); dm_sparse_free(c);
    }
    tap_ok(ok, "dual derivative: D0 = d1^T, D1 = -d0^T in 2D, D0 = -d2^T in 3D");
    tap_ok(dm_dec_dual_d(r.K, 2, &e) == NULL &&
           strcmp(e.msg, "dual derivative: degree 2 outside 0..1 (complex of dimension 2)") == 0, "%s", e.msg);
    dm_sparse_free(D0); dm_sparse_free(D1); dm_sparse_free(E0);
    drop(&r);
    drop(&q);
  }
  /* the disc generator is Delaunay after its flips */
  {
    mesh r = make(dm_dec_gen_disc(1.0, 32, NULL));
    dm_dec_meshdata *m = dm_dec_gen_disc(1.0, 32, NULL);
    tap_ok(r.G->nonpos[1] == 0 && r.G->nonpos[0] == 0, "disc of 32 rings: every *1 and *0 positive");
    tap_is_int(dm_dec_delaunay_flips(m, NULL), 0, "a second round of flips finds nothing");
    dm_dec_meshdata_free(m);
    drop(&r);
  }
  dm_dec_geom_free(NULL);
  return tap_done();
}
