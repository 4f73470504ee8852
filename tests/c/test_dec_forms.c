/* test_dec_forms.c -- flat, sharp, wedge products, contraction and Lie
 * derivative. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "dec/dec.h"

typedef struct {
  dm_dec_meshdata *m;
  dm_dec_complex *K;
  dm_dec_geom *G;
} mesh;

static mesh make(dm_dec_meshdata *m)
{
  mesh r;
  r.m = m;
  r.K = dm_dec_complex_alloc(m->n, m->nv, m->ntop, m->T, NULL);
  r.G = dm_dec_geom_alloc(r.K, m->N, m->X, NULL);
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

/* The 1-cochain of the closed form dx_c (exact values on edges). */
static double *dcoord(const mesh *r, int c)
{
  int i, N = r->m->N;
  double *a = malloc(r->K->nsimp[1] * sizeof *a);
  for (i = 0; i < r->K->nsimp[1]; i++)
    a[i] = r->m->X[r->K->simp[1][2 * i + 1] * N + c] - r->m->X[r->K->simp[1][2 * i] * N + c];
  return a;
}

int main(void)
{
  int i, wmode;
  dm_err e;
  /* flat and sharp of a constant field on the disc */
  {
    mesh r = make(dm_dec_gen_disc(1.0, 6, NULL));
    int nt = r.K->nsimp[2], ne = r.K->nsimp[1], nv = r.K->nsimp[0];
    double *X = malloc(nt * 2 * sizeof *X), *a = malloc(ne * sizeof *a), *V = malloc(nv * 2 * sizeof *V);
    double *da = malloc(nt * sizeof *da), err = 0, errd = 0, errs = 0;
    for (i = 0; i < nt; i++) {
      X[2 * i] = 2.385;
      X[2 * i + 1] = -0.75;
    }
    dm_dec_flat(r.G, X, a, NULL);
    for (i = 0; i < ne; i++) {
      const double *p = r.m->X + 2 * r.K->simp[1][2 * i], *q = r.m->X + 2 * r.K->simp[1][2 * i + 1];
      err = fmax(err, fabs(a[i] - (2.385 * (q[0] - p[0]) - 0.75 * (q[1] - p[1]))));
    }
    dm_sparse_gemv(r.K->d[1], a, da);
    for (i = 0; i < nt; i++)
      errd = fmax(errd, fabs(da[i]));
    tap_ok(err < 1e-14 && errd < 1e-14, "flat of a constant field is X.e on every edge (%.2g), closed (%.2g)", err, errd);
    dm_dec_sharp(r.G, a, V, NULL);
    for (i = 0; i < nv; i++)
      errs = fmax(errs, fabs(V[2 * i] - 2.385) + fabs(V[2 * i + 1] + 0.75));
    tap_ok(errs < 1e-13, "sharp of that flat returns the field at every vertex (%.2g)", errs);
    /* contraction of the area form with a constant field */
    {
      double *mu = malloc(nv * sizeof *mu), *ix = malloc(ne * sizeof *ix), *lie = malloc(nv * sizeof *lie);
      double ec = 0, el = 0;
      for (i = 0; i < nv; i++)
        mu[i] = r.G->dual[0][i];
      for (wmode = 0; wmode < 2; wmode++) {
        dm_dec_contract(r.G, 2, mu, X, wmode, ix, NULL);
        for (i = 0; i < ne; i++) {
          const double *p = r.m->X + 2 * r.K->simp[1][2 * i], *q = r.m->X + 2 * r.K->simp[1][2 * i + 1];
          double len = sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]));
          ec = fmax(ec, fabs(ix[i] - r.G->dual[1][i] * (2.385 * (q[0] - p[0]) - 0.75 * (q[1] - p[1])) / len));
        }
        dm_dec_lie(r.G, 2, mu, X, wmode, lie, NULL);
        for (i = 0; i < nv; i++)
          if (!r.K->boundary[0][i])
            el = fmax(el, fabs(lie[i]));
      }
      tap_ok(ec < 1e-14, "i_X of the area form = |*e| X.e/|e| on every dual edge (%.2g)", ec);
      tap_ok(el < 1e-14, "L_X of the area form vanishes at interior vertices for constant X (%.2g)", el);
      free(mu);
      free(ix);
      free(lie);
    }
    /* dx ^ dy = area, both weights */
    {
      double *dx = dcoord(&r, 0), *dy = dcoord(&r, 1), *w = malloc(nt * sizeof *w), ew = 0;
      for (wmode = 0; wmode < 2; wmode++) {
        dm_dec_wedge(r.G, 1, dx, 1, dy, wmode, w, NULL);
        for (i = 0; i < nt; i++)
          ew = fmax(ew, fabs(w[i] - r.G->vol[2][i]));
      }
      tap_ok(ew < 1e-15, "dx ^ dy = area of every triangle, both weights (%.2g)", ew);
      free(dx);
      free(dy);
      free(w);
    }
    free(X); free(a); free(V); free(da);
    drop(&r);
  }
  /* flat is not injective: Hirani's hexagon */
  {
    double X[14], F[12];
    int T[18];
    mesh r;
    double a[12], m = 0;
    X[0] = X[1] = 0;
    for (i = 0; i < 6; i++) {
      double th = (30 + 60 * i) * M_PI / 180;
      X[2 * (i + 1)] = cos(th);
      X[2 * (i + 1) + 1] = sin(th);
      T[3 * i] = 0;
      T[3 * i + 1] = i + 1;
      T[3 * i + 2] = (i + 1) % 6 + 1;
      F[2 * i] = cos((240 - 120 * (i % 3)) * M_PI / 180);
      F[2 * i + 1] = sin((240 - 120 * (i % 3)) * M_PI / 180);
    }
    r = make_raw(2, 2, 7, X, 6, T);
    dm_dec_flat(r.G, F, a, NULL);
    for (i = 0; i < 12; i++)
      m = fmax(m, fabs(a[i]));
    tap_ok(m < 1e-15, "flat of the hexagon field is zero on all 12 edges (%.2g)", m);
    drop(&r);
  }
  /* path graph: 0 ^ 1 and 0 ^ 0 */
  {
    double X[] = {1, 0, 0, 0, 0, 2}, f[] = {1, 1, 0}, b[] = {2.5, 5.0}, o[3];
    double g[] = {1, 2, 3}, h[] = {3, 4, 7};
    int T[] = {0, 1, 1, 2};
    mesh r = make_raw(1, 2, 3, X, 2, T);
    dm_dec_wedge(r.G, 0, f, 1, b, DM_DEC_WEDGE_CIRCUMCENTRIC, o, NULL);
    tap_ok(o[0] == 2.5 && o[1] == 2.5, "path: f ^ beta = (2.5, 2.5)");
    dm_dec_wedge(r.G, 0, g, 0, h, DM_DEC_WEDGE_BARYCENTRIC, o, NULL);
    tap_ok(o[0] == 3 && o[1] == 8 && o[2] == 21, "0 ^ 0 is the pointwise product");
    tap_ok(dm_dec_wedge(r.G, 1, b, 1, b, 0, o, &e) == DM_EINVAL &&
           strcmp(e.msg, "wedge: degrees 1 + 1 exceed the dimension 1") == 0, "%s", e.msg);
    drop(&r);
  }
  /* right isosceles triangle: weights matter */
  {
    double X[] = {0, 0, 1, 0, 0, 1}, a[] = {1, 0, 0}, b[] = {0, 1, 0}, o[1];
    int T[] = {0, 1, 2};
    mesh r = make_raw(2, 2, 3, X, 1, T);
    dm_dec_wedge(r.G, 1, a, 1, b, DM_DEC_WEDGE_CIRCUMCENTRIC, o, NULL);
    tap_near(o[0], 0.25, 1e-15, "right triangle: circumcentric alpha ^ beta = 1/4");
    dm_dec_wedge(r.G, 1, a, 1, b, DM_DEC_WEDGE_BARYCENTRIC, o, NULL);
    tap_near(o[0], 1.0 / 6, 1e-15, "right triangle: barycentric alpha ^ beta = 1/6");
    drop(&r);
  }
  /* a scalene tetrahedron: associativity on closed forms, Leibniz */
  {
    double X[] = {0.1, 0.05, -0.02, 1.3, 0.2, 0.1, 0.3, 1.1, 0.15, 0.25, 0.35, 0.9};
    int T[] = {0, 1, 2, 3};
    mesh r = make_raw(3, 3, 4, X, 1, T);
    double *dx = dcoord(&r, 0), *dy = dcoord(&r, 1), *dz = dcoord(&r, 2);
    double xy[4], yz[4], v1[1], v2[1], defect[2];
    for (wmode = 0; wmode < 2; wmode++) {
      dm_dec_wedge(r.G, 1, dx, 1, dy, wmode, xy, NULL);
      dm_dec_wedge(r.G, 1, dy, 1, dz, wmode, yz, NULL);
      dm_dec_wedge(r.G, 2, xy, 1, dz, wmode, v1, NULL);
      dm_dec_wedge(r.G, 1, dx, 2, yz, wmode, v2, NULL);
      tap_ok(fabs(v1[0] - r.G->vol[3][0]) < 1e-13 && fabs(v2[0] - r.G->vol[3][0]) < 1e-13,
             "%s: (dX^dY)^dZ = dX^(dY^dZ) = volume %.6f (%.6f, %.6f)",
             wmode ? "circumcentric" : "barycentric", r.G->vol[3][0], v1[0], v2[0]);
    }
    /* Leibniz d(a ^ b) = da ^ b - a ^ db for random 1-forms */
    for (wmode = 0; wmode < 2; wmode++) {
      double a[6], b[6], ab[4], dab[1], da[4], db[4], t1[1], t2[1], ba[4], anti = 0;
      for (i = 0; i < 6; i++) {
        a[i] = sin(2.385 * (i + 1));
        b[i] = cos(1.7 * (i + 2)) + 0.3;
      }
      dm_dec_wedge(r.G, 1, a, 1, b, wmode, ab, NULL);
      dm_dec_wedge(r.G, 1, b, 1, a, wmode, ba, NULL);
      for (i = 0; i < 4; i++)
        anti = fmax(anti, fabs(ab[i] + ba[i]));
      tap_ok(anti < 1e-15, "%s: a ^ b = -b ^ a for 1-forms", wmode ? "circumcentric" : "barycentric");
      dm_sparse_gemv(r.K->d[2], ab, dab);
      dm_sparse_gemv(r.K->d[1], a, da);
      dm_sparse_gemv(r.K->d[1], b, db);
      dm_dec_wedge(r.G, 2, da, 1, b, wmode, t1, NULL);
      dm_dec_wedge(r.G, 1, a, 2, db, wmode, t2, NULL);
      defect[wmode] = fabs(dab[0] - (t1[0] - t2[0]));
    }
    tap_ok(defect[0] < 1e-14, "barycentric wedge: Leibniz rule exact (defect %.2g)", defect[0]);
    tap_ok(defect[1] > 1e-3, "circumcentric wedge: Leibniz fails on a scalene tet (defect %.3g)", defect[1]);
    free(dx); free(dy); free(dz);
    drop(&r);
  }
  /* the dual-dual wedge: anti-commutative (the only property claimed) */
  {
    mesh r = make(dm_dec_gen_disc(1.0, 4, NULL)), q = make(dm_dec_gen_box(2, 2, 2, 1, 1, 1, NULL));
    mesh *ms[2] = {&r, &q};
    int j, k, l;
    double worst = 0, size = 0;
    for (j = 0; j < 2; j++) {
      const dm_dec_complex *K = ms[j]->K;
      int n = K->n;
      for (k = 0; k <= n; k++)
        for (l = 0; k + l <= n; l++) {
          double *a = malloc(K->nsimp[n - k] * sizeof *a), *b = malloc(K->nsimp[n - l] * sizeof *b);
          double *ab = malloc(K->nsimp[n - k - l] * sizeof *ab), *ba = malloc(K->nsimp[n - k - l] * sizeof *ba);
          double sg = (k * l) % 2 ? -1.0 : 1.0;
          for (i = 0; i < K->nsimp[n - k]; i++)
            a[i] = sin(2.385 * i + k);
          for (i = 0; i < K->nsimp[n - l]; i++)
            b[i] = cos(1.3 * i - l) + 0.25;
          dm_dec_wedge_dual(K, k, a, l, b, ab, NULL);
          dm_dec_wedge_dual(K, l, b, k, a, ba, NULL);
          for (i = 0; i < K->nsimp[n - k - l]; i++) {
            worst = fmax(worst, fabs(ab[i] - sg * ba[i]));
            size = fmax(size, fabs(ab[i]));
          }
          free(a); free(b); free(ab); free(ba);
        }
    }
    tap_ok(worst < 1e-13 && size > 0.1, "dual-dual wedge: a ^ b = (-1)^(kl) b ^ a in 2-D and 3-D, all degrees (%.2g)", worst);
    drop(&r);
    drop(&q);
  }
  return tap_done();
}
