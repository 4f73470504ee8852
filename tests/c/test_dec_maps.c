/* test_dec_maps.c -- nested refinement (restriction commutes with d,
 * areas coarsen to areas), multigrid V-cycles against CHOLMOD, push-forward
 * Jacobians, naturality of the wedge products, mesh files. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "dec/dec.h"

static dm_dec_geom *geom(dm_dec_meshdata *m, dm_dec_complex **K)
{
  *K = dm_dec_complex_alloc(m->n, m->nv, m->ntop, m->T, NULL);
  return dm_dec_geom_alloc(*K, m->N, m->X, NULL);
}

int main(void)
{
  dm_err e;
  int i;
  /* restriction on a 1 -> 4 refinement of a jiggled disc */
  {
    dm_dec_meshdata *c = dm_dec_gen_disc(1.0, 3, NULL), *f;
    dm_dec_complex *Kc, *Kf;
    dm_dec_geom *Gc, *Gf;
    int *parent;
    dm_sparse *R0, *R1, *R2, *A, *B;
    double *af, *ac, m = 0;
    for (i = 7; i < c->nv; i++)
      c->X[2 * i] += 0.05 * sin(3.7 * i);
    f = dm_dec_refine(c, &parent, NULL);
    Gc = geom(c, &Kc);
    Gf = geom(f, &Kf);
    R0 = dm_dec_restriction(Kc, Kf, parent, 0, NULL);
    R1 = dm_dec_restriction(Kc, Kf, parent, 1, NULL);
    R2 = dm_dec_restriction(Kc, Kf, parent, 2, NULL);
    A = dm_sparse_mul(R1, Kf->d[0], NULL);
    B = dm_sparse_mul(Kc->d[0], R0, NULL);
    {
      dm_sparse *D = dm_sparse_add(1, A, -1, B, NULL);
      tap_ok(dm_sparse_maxabs(D) == 0, "R1 d0 = d0 R0 exactly");
      dm_sparse_free(D);
    }
    dm_sparse_free(A);
    dm_sparse_free(B);
    A = dm_sparse_mul(R2, Kf->d[1], NULL);
    B = dm_sparse_mul(Kc->d[1], R1, NULL);
    {
      dm_sparse *D = dm_sparse_add(1, A, -1, B, NULL);
      tap_ok(dm_sparse_maxabs(D) == 0, "R2 d1 = d1 R1 exactly");
      dm_sparse_free(D);
    }
    af = Gf->vol[2];
    ac = malloc(Kc->nsimp[2] * sizeof *ac);
    dm_sparse_gemv(R2, af, ac);
    for (i = 0; i < Kc->nsimp[2]; i++)
      m = fmax(m, fabs(ac[i] - Gc->vol[2][i]) / Gc->vol[2][i]);
    tap_ok(m < 1e-14, "fine areas coarsen to the coarse areas (%.2g)", m);
    tap_ok(dm_dec_restriction(Kc, Kf, parent, 3, &e) == NULL && e.status == DM_EINVAL, "%s", e.msg);
    free(ac);
    dm_sparse_free(A); dm_sparse_free(B);
    dm_sparse_free(R0); dm_sparse_free(R1); dm_sparse_free(R2);
    free(parent);
    dm_dec_geom_free(Gc); dm_dec_geom_free(Gf);
    dm_dec_complex_free(Kc); dm_dec_complex_free(Kf);
    dm_dec_meshdata_free(c); dm_dec_meshdata_free(f);
  }
  /* multigrid: 5 levels from a 3-ring disc, against CHOLMOD */
  {
    dm_dec_meshdata *lev[5];
    int *par[5], L = 5, iters = 0;
    dm_sparse *P[4], *S;
    dm_dec_complex *K;
    dm_dec_geom *G;
    dm_dec_mg *mg;
    dm_dec_solver *F;
    double *b, *u, *ref, *w, m = 0, r0 = 0;
    lev[0] = dm_dec_gen_disc(1.0, 3, NULL);
    for (i = 1; i < L; i++)
      lev[i] = dm_dec_refine(lev[i - 1], &par[i], NULL);
    for (i = 0; i + 1 < L; i++)
      P[i] = dm_dec_prolongation(lev[i]->nv, lev[i + 1]->nv, par[i + 1], NULL);
    G = geom(lev[L - 1], &K);
    dm_dec_laplacian(G, 0, NULL, &S, NULL);
    mg = dm_dec_mg_alloc(L, P, S, K->boundary[0], 2, &e);
    b = malloc(K->nsimp[0] * sizeof *b);
    u = calloc(K->nsimp[0], sizeof *u);
    ref = malloc(K->nsimp[0] * sizeof *ref);
    w = malloc(K->nsimp[0] * sizeof *w);
    dm_dec_star(G, 0, 0, w, NULL);
    for (i = 0; i < K->nsimp[0]; i++)
      b[i] = w[i] * (1.0 + lev[L - 1]->X[2 * i]);
    tap_ok(mg != NULL, "multigrid hierarchy of %d levels, %d unknowns on the finest", L, K->nsimp[0]);
    /* convergence factor of one V(2,2) cycle */
    dm_dec_mg_vcycle(mg, b, u, NULL);
    {
      double r1 = 0, *Su = malloc(K->nsimp[0] * sizeof *Su);
      dm_sparse_gemv(S, u, Su);
      for (i = 0; i < K->nsimp[0]; i++)
        if (!K->boundary[0][i]) {
          r0 += b[i] * b[i];
          r1 += (b[i] - Su[i]) * (b[i] - Su[i]);
        }
      tap_ok(sqrt(r1 / r0) < 0.1, "one V-cycle reduces the residual by %.3g", sqrt(r1 / r0));
      free(Su);
    }
    memset(u, 0, K->nsimp[0] * sizeof *u);
    {
      int st = dm_dec_mg_solve(mg, b, u, 1e-10, 50, &iters, &e);
      tap_ok(st == DM_OK && iters <= 12, "multigrid converges to 1e-10 in %d cycles", iters);
    }
    F = dm_dec_solver_alloc(S, K->boundary[0], NULL);
    for (i = 0; i < K->nsimp[0]; i++)
      b[i] /= w[i];
    dm_dec_solver_solve(F, w, b, NULL, ref, NULL);
    for (i = 0; i < K->nsimp[0]; i++)
      m = fmax(m, fabs(u[i] - ref[i]));
    tap_ok(m < 1e-9, "multigrid solution = CHOLMOD solution (%.2g)", m);
    dm_dec_solver_free(F);
    dm_dec_mg_free(mg);
    free(b); free(u); free(ref); free(w);
    dm_sparse_free(S);
    dm_dec_geom_free(G);
    dm_dec_complex_free(K);
    for (i = 0; i < L; i++) {
      dm_dec_meshdata_free(lev[i]);
      if (i > 0)
        free(par[i]);
      if (i + 1 < L)
        dm_sparse_free(P[i]);
    }
  }
  /* push-forward: an affine map has Jacobian A on every simplex */
  {
    dm_dec_meshdata *m = dm_dec_gen_box(2, 1, 1, 1, 1, 1, NULL), *m2 = dm_dec_gen_box(2, 1, 1, 1, 1, 1, NULL);
    const double A[9] = {1.2, 0.3, -0.1, 0.2, 0.9, 0.4, -0.3, 0.1, 1.1}, bb[3] = {2.385, -1, 0.5};
    dm_dec_complex *K, *K2;
    dm_dec_geom *G, *G2, view;
    double *X, *out, err = 0;
    int nt, c, j;
    for (i = 0; i < m->nv; i++)
      for (c = 0; c < 3; c++) {
        double s = bb[c];
        for (j = 0; j < 3; j++)
          s += A[3 * c + j] * m->X[3 * i + j];
        m2->X[3 * i + c] = s;
      }
    G = geom(m, &K);
    G2 = geom(m2, &K2);
    view = *G2;
    view.K = K;
    nt = K->nsimp[3];
    X = malloc(nt * 3 * sizeof *X);
    out = malloc(nt * 3 * sizeof *out);
    for (i = 0; i < 3 * nt; i++)
      X[i] = sin(1.3 * i + 0.2);
    dm_dec_pushforward(G, &view, X, out, NULL);
    for (i = 0; i < nt; i++)
      for (c = 0; c < 3; c++) {
        double s = 0;
        for (j = 0; j < 3; j++)
          s += A[3 * c + j] * X[3 * i + j];
        err = fmax(err, fabs(out[3 * i + c] - s));
      }
    tap_ok(err < 1e-14, "push-forward by an affine map is A X on every tetrahedron (%.2g)", err);
    tap_ok(dm_dec_pushforward(G, G2, X, out, &e) == DM_EINVAL, "geometries of two complexes refused");
    free(X); free(out);
    dm_dec_geom_free(G); dm_dec_geom_free(G2);
    dm_dec_complex_free(K); dm_dec_complex_free(K2);
    dm_dec_meshdata_free(m); dm_dec_meshdata_free(m2);
  }
  /* naturality: right triangle -> equilateral triangle */
  {
    double X1[] = {0, 0, 1, 0, 0, 1}, X2[] = {0, 0, 1, 0, 0.5, 0.8660254037844386};
    double a[] = {1, 0, 0}, b[] = {0, 1, 0}, o1[1], o2[1], o3[1], o4[1];
    int T[] = {0, 1, 2};
    dm_dec_complex *K = dm_dec_complex_alloc(2, 3, 1, T, NULL);
    dm_dec_geom *G1 = dm_dec_geom_alloc(K, 2, X1, NULL), *G2 = dm_dec_geom_alloc(K, 2, X2, NULL);
    dm_dec_wedge(G1, 1, a, 1, b, DM_DEC_WEDGE_CIRCUMCENTRIC, o1, NULL);
    dm_dec_wedge(G2, 1, a, 1, b, DM_DEC_WEDGE_CIRCUMCENTRIC, o2, NULL);
    dm_dec_wedge(G1, 1, a, 1, b, DM_DEC_WEDGE_BARYCENTRIC, o3, NULL);
    dm_dec_wedge(G2, 1, a, 1, b, DM_DEC_WEDGE_BARYCENTRIC, o4, NULL);
    tap_ok(fabs(o1[0] - 0.25) < 1e-15 && fabs(o2[0] - 1.0 / 6) < 1e-15,
           "circumcentric wedge is not natural: 1/4 before the map, 1/6 after");
    tap_ok(o3[0] == o4[0] && fabs(o3[0] - 1.0 / 6) < 1e-15, "barycentric wedge is natural: 1/6 on both");
    dm_dec_geom_free(G1); dm_dec_geom_free(G2);
    dm_dec_complex_free(K);
  }
  /* files: write, read back */
  {
    const char *dir = getenv("DMECH_TESTTMP");
    char path[512];
    dm_dec_meshdata *m = dm_dec_gen_sphere(1.0, 1, NULL), *back = NULL;
    dm_dec_complex *K, *K2 = NULL;
    dm_dec_geom *G, *G2 = NULL;
    const char *ext[] = {"off", "obj", "msh"};
    int j;
    G = geom(m, &K);
    for (j = 0; j < 3; j++) {
      double d = 0;
      snprintf(path, sizeof path, "%s/dec_sphere.%s", dir != NULL ? dir : "/tmp", ext[j]);
      tap_ok(dm_dec_write(path, K, G, &e) == DM_OK, "write %s", ext[j]);
      tap_ok(dm_dec_load(path, &K2, &G2, &e) == DM_OK, "load %s back", ext[j]);
      for (i = 0; K2 && i < K->nsimp[0] * 3; i++)
        d = fmax(d, fabs(G2->X[i] - G->X[i]));
      tap_ok(K2 && d == 0 && memcmp(K2->top, K->top, K->nsimp[2] * 3 * sizeof(int)) == 0,
             "%s round trip is exact", ext[j]);
      dm_dec_geom_free(G2);
      dm_dec_complex_free(K2);
    }
    tap_ok(dm_dec_write("/nonexistent-dir/x.off", K, G, &e) == DM_EIO, "%s", e.msg);
    (void)back;
    dm_dec_geom_free(G);
    dm_dec_complex_free(K);
    dm_dec_meshdata_free(m);
  }
  return tap_done();
}
