/* generate.c -- mesh generators (grid, disc, annulus, icosphere, staggered
 * torus, tetrahedral box, path) and nested 1 -> 4 refinement. */
#include <config.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dec/dec.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

dm_dec_meshdata *dm_dec_meshdata_alloc(int n, int N, int nv, int ntop, dm_err *e)
{
  dm_dec_meshdata *m;
  if (n < 1 || N < 1 || nv < 1 || ntop < 1) {
    dm_err_set(e, DM_EINVAL, "mesh: sizes n=%d N=%d vertices=%d simplices=%d", n, N, nv, ntop);
    return NULL;
  }
  m = calloc(1, sizeof *m);
  if (m != NULL) {
    m->n = n;
    m->N = N;
    m->nv = nv;
    m->ntop = ntop;
    m->X = malloc((size_t)nv * N * sizeof *m->X);
    m->T = malloc((size_t)ntop * (n + 1) * sizeof *m->T);
  }
  if (m == NULL || m->X == NULL || m->T == NULL) {
    dm_dec_meshdata_free(m);
    dm_err_set(e, DM_ENOMEM, "mesh of %d vertices and %d simplices: out of memory", nv, ntop);
    return NULL;
  }
  return m;
}

void dm_dec_meshdata_free(dm_dec_meshdata *m)
{
  if (m == NULL)
    return;
  free(m->X);
  free(m->T);
  free(m);
}

typedef struct {
  size_t cap;
  int64_t *key;
  int *val;
} edgemap;
static int edgemap_init(edgemap *h, size_t nedges);
static void edgemap_free(edgemap *h);
static int midpoint(edgemap *h, int a, int b, int *next, int *parent);

static int bad(dm_err *e, const char *what, const char *cond)
{
  return dm_err_set(e, DM_EINVAL, "%s: %s", what, cond);
}

/* Planar triangles made counterclockwise. */
static void orient_ccw(dm_dec_meshdata *m)
{
  int t;
  for (t = 0; t < m->ntop; t++) {
    int *v = m->T + 3 * t;
    const double *a = m->X + 2 * v[0], *b = m->X + 2 * v[1], *c = m->X + 2 * v[2];
    if ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0) {
      int s = v[1];
      v[1] = v[2];
      v[2] = s;
    }
  }
}

dm_dec_meshdata *dm_dec_gen_grid(int nx, int ny, double x0, double x1, double y0,
                                 double y1, dm_err *e)
{
  dm_dec_meshdata *m;
  int i, j, t = 0;
  if (nx < 1 || ny < 1 || !(x1 > x0) || !(y1 > y0)) {
    bad(e, "grid", "nx, ny >= 1 and x1 > x0, y1 > y0 expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(2, 2, (nx + 1) * (ny + 1), 2 * nx * ny, e)) == NULL)
    return NULL;
  for (j = 0; j <= ny; j++)
    for (i = 0; i <= nx; i++) {
      m->X[2 * (j * (nx + 1) + i)] = i == nx ? x1 : x0 + (x1 - x0) * i / nx;
      m->X[2 * (j * (nx + 1) + i) + 1] = j == ny ? y1 : y0 + (y1 - y0) * j / ny;
    }
  for (j = 0; j < ny; j++)
    for (i = 0; i < nx; i++) {
      int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      int *T = m->T + 3 * t;
      T[0] = a; T[1] = b; T[2] = d;
      T[3] = a; T[4] = d; T[5] = c;
      t += 2;
    }
  return m;
}

/* Triangles between two closed rings (inner A of size a starting at index
 * ia, outer B of size b at ib), advancing by angle: exact integer test
 * (pb+1)/b <= (pa+1)/a.  Angle offsets are given as fractions of a step. */
static int zipper(int *T, int ia, int a, double offa, int ib, int b, double offb)
{
  int pa = 0, pb = 0, t = 0;
  while (pa < a || pb < b) {
    int advb;
    if (pa == a)
      advb = 1;
    else if (pb == b)
      advb = 0;
    else
      advb = (pb + 1 + offb) * a <= (pa + 1 + offa) * b;
    T[3 * t] = ia + pa % a;
    T[3 * t + 1] = ib + pb % b;
    T[3 * t + 2] = advb ? ib + (pb + 1) % b : ia + (pa + 1) % a;
    if (advb)
      pb++;
    else
      pa++;
    t++;
  }
  return t;
}

/* cot of the angle at c in triangle (a, b, c) of the plane. */
static double cot_at(const double *X, int a, int b, int c)
{
  double ux = X[2 * a] - X[2 * c], uy = X[2 * a + 1] - X[2 * c + 1];
  double vx = X[2 * b] - X[2 * c], vy = X[2 * b + 1] - X[2 * c + 1];
  return (ux * vx + uy * vy) / fabs(ux * vy - uy * vx);
}

int dm_dec_delaunay_flips(dm_dec_meshdata *m, dm_err *e)
{
  edgemap h = {0, NULL, NULL};
  int *owner = NULL, *parent = NULL, flips = 0, changed = 1, t, i, pass;
  unsigned char *touched = NULL;
  if (m->n != 2 || m->N != 2)
    return dm_err_set(e, DM_EUNSUP, "Delaunay flips: planar triangle meshes only");
  owner = malloc(3 * (size_t)m->ntop * 2 * sizeof *owner);
  parent = malloc(2 * ((size_t)m->nv + 3 * (size_t)m->ntop) * sizeof *parent);
  touched = malloc((size_t)m->ntop);
  if (owner == NULL || parent == NULL || touched == NULL)
    goto nomem;
  for (pass = 0; changed && pass < 1000; pass++) {
    int next = m->nv;
    changed = 0;
    edgemap_free(&h);
    if (edgemap_init(&h, 3 * (size_t)m->ntop) != 0)
      goto nomem;
    memset(touched, 0, (size_t)m->ntop);
    /* owner[2 id] = the triangle having the edge (lo, hi) in that order,
     * owner[2 id + 1] = the one having (hi, lo) */
    for (i = 0; i < 6 * m->ntop; i++)
      owner[i] = -1;
    for (t = 0; t < m->ntop; t++)
      for (i = 0; i < 3; i++) {
        int a = m->T[3 * t + i], b = m->T[3 * t + (i + 1) % 3];
        int id = midpoint(&h, a, b, &next, parent) - m->nv;
        owner[2 * id + (a < b ? 0 : 1)] = t;
      }
    for (t = 0; t < m->ntop; t++)
      for (i = 0; i < 3 && !touched[t]; i++) {
        int a = m->T[3 * t + i], b = m->T[3 * t + (i + 1) % 3], c = m->T[3 * t + (i + 2) % 3];
        int id = midpoint(&h, a, b, &next, parent) - m->nv, u = owner[2 * id + (a < b ? 1 : 0)], d = -1, j;
        if (u < 0 || touched[u])
          continue;
        for (j = 0; j < 3; j++)
          if (m->T[3 * u + j] != a && m->T[3 * u + j] != b)
            d = m->T[3 * u + j];
        if (cot_at(m->X, a, b, c) + cot_at(m->X, b, a, d) >= -1e-12)
          continue;
        m->T[3 * t] = a; m->T[3 * t + 1] = d; m->T[3 * t + 2] = c;
        m->T[3 * u] = d; m->T[3 * u + 1] = b; m->T[3 * u + 2] = c;
        touched[t] = touched[u] = 1;
        flips++;
        changed = 1;
      }
  }
  edgemap_free(&h);
  free(owner);
  free(parent);
  free(touched);
  return flips;
nomem:
  edgemap_free(&h);
  free(owner);
  free(parent);
  free(touched);
  return -dm_err_set(e, DM_ENOMEM, "Delaunay flips: out of memory");
}

dm_dec_meshdata *dm_dec_gen_disc(double r, int nr, dm_err *e)
{
  dm_dec_meshdata *m;
  int i, j, v = 1, t = 0;
  if (nr < 1 || !(r > 0)) {
    bad(e, "disc", "radius > 0 and n >= 1 expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(2, 2, 1 + 3 * nr * (nr + 1), 6 * nr * nr, e)) == NULL)
    return NULL;
  m->X[0] = m->X[1] = 0.0;
  for (i = 1; i <= nr; i++)
    for (j = 0; j < 6 * i; j++, v++) {
      double rho = i == nr ? r : r * i / nr, th = 2 * M_PI * (j + 0.5 * (i % 2)) / (6 * i);
      m->X[2 * v] = rho * cos(th);
      m->X[2 * v + 1] = rho * sin(th);
    }
  for (j = 0; j < 6; j++, t++) {
    m->T[3 * t] = 0;
    m->T[3 * t + 1] = 1 + j;
    m->T[3 * t + 2] = 1 + (j + 1) % 6;
  }
  for (i = 2, v = 1; i <= nr; i++) {
    int a = 6 * (i - 1);
    t += zipper(m->T + 3 * t, v, a, 0.5 * ((i - 1) % 2), v + a, 6 * i, 0.5 * (i % 2));
    v += a;
  }
  orient_ccw(m);
  if (dm_dec_delaunay_flips(m, e) < 0) {
    dm_dec_meshdata_free(m);
    return NULL;
  }
  return m;
}

dm_dec_meshdata *dm_dec_gen_annulus(double r0, double r1, int nr, int mm, dm_err *e)
{
  dm_dec_meshdata *m;
  int i, j, t = 0;
  if (nr < 1 || mm < 3 || !(r0 > 0) || !(r1 > r0)) {
    bad(e, "annulus", "0 < r0 < r1, n >= 1 rings and m >= 3 vertices per ring expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(2, 2, (nr + 1) * mm, 2 * nr * mm, e)) == NULL)
    return NULL;
  for (i = 0; i <= nr; i++)
    for (j = 0; j < mm; j++) {
      double rho = i == nr ? r1 : r0 + (r1 - r0) * i / nr;
      double th = 2 * M_PI * (j + 0.5 * (i % 2)) / mm;
      m->X[2 * (i * mm + j)] = rho * cos(th);
      m->X[2 * (i * mm + j) + 1] = rho * sin(th);
    }
  for (i = 0; i < nr; i++)
    t += zipper(m->T + 3 * t, i * mm, mm, 0.5 * (i % 2), (i + 1) * mm, mm,
                0.5 * ((i + 1) % 2));
  orient_ccw(m);
  if (dm_dec_delaunay_flips(m, e) < 0) {
    dm_dec_meshdata_free(m);
    return NULL;
  }
  return m;
}

dm_dec_meshdata *dm_dec_gen_torus(double R, double r, int mu, int nv, dm_err *e)
{
  dm_dec_meshdata *m;
  int i, j, t = 0;
  if (!(r > 0) || !(R > r) || mu < 3 || nv < 4 || nv % 2 != 0) {
    bad(e, "torus", "R > r > 0, m >= 3 and an even n >= 4 expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(2, 3, mu * nv, 2 * mu * nv, e)) == NULL)
    return NULL;
  for (j = 0; j < nv; j++)
    for (i = 0; i < mu; i++) {
      double u = 2 * M_PI * (i + 0.5 * (j % 2)) / mu, w = 2 * M_PI * j / nv;
      double *x = m->X + 3 * (j * mu + i);
      x[0] = (R + r * cos(w)) * cos(u);
      x[1] = (R + r * cos(w)) * sin(u);
      x[2] = r * sin(w);
    }
#define V(ii, jj) ((((jj) % nv) * mu) + ((ii) % mu))
  for (j = 0; j < nv; j++)
    for (i = 0; i < mu; i++) {
      int *T = m->T + 3 * t;
      if (j % 2 == 0) {
        T[0] = V(i, j); T[1] = V(i + 1, j); T[2] = V(i, j + 1);
        T[3] = V(i + 1, j); T[4] = V(i + 1, j + 1); T[5] = V(i, j + 1);
      } else {
        T[0] = V(i, j); T[1] = V(i + 1, j); T[2] = V(i + 1, j + 1);
        T[3] = V(i, j); T[4] = V(i + 1, j + 1); T[5] = V(i, j + 1);
      }
      t += 2;
    }
#undef V
  return m;
}

/* {==== edge midpoints (open addressing on the sorted pair) ===================== */

static int edgemap_init(edgemap *h, size_t nedges)
{
  size_t i;
  h->cap = 16;
  while (h->cap < 2 * nedges)
    h->cap *= 2;
  h->key = malloc(h->cap * sizeof *h->key);
  h->val = malloc(h->cap * sizeof *h->val);
  if (h->key == NULL || h->val == NULL)
    return -1;
  for (i = 0; i < h->cap; i++)
    h->key[i] = -1;
  return 0;
}

static void edgemap_free(edgemap *h)
{
  free(h->key);
  free(h->val);
}

/* The midpoint vertex of edge (a, b): found, or created as *next. */
static int midpoint(edgemap *h, int a, int b, int *next, int *parent)
{
  int64_t k = a < b ? (int64_t)a * 2147483648LL + b : (int64_t)b * 2147483648LL + a;
  size_t i = (size_t)((uint64_t)k * 0x9E3779B97F4A7C15ULL >> 20) & (h->cap - 1);
  while (h->key[i] >= 0) {
    if (h->key[i] == k)
      return h->val[i];
    i = (i + 1) & (h->cap - 1);
  }
  h->key[i] = k;
  h->val[i] = (*next)++;
  parent[2 * h->val[i]] = a < b ? a : b;
  parent[2 * h->val[i] + 1] = a < b ? b : a;
  return h->val[i];
}

/* }==== */

dm_dec_meshdata *dm_dec_refine(const dm_dec_meshdata *m, int **parent_out, dm_err *e)
{
  int n = m->n, N = m->N, nv, t, i, next = m->nv, nedges;
  dm_dec_meshdata *f;
  int *parent;
  edgemap h = {0, NULL, NULL};
  if (n != 1 && n != 2) {
    dm_err_set(e, DM_EUNSUP, "refine: %d-dimensional meshes are not supported (1 or 2)", n);
    return NULL;
  }
  nedges = n == 1 ? m->ntop : 3 * m->ntop;        /* upper bound on new vertices */
  parent = malloc(2 * ((size_t)m->nv + nedges) * sizeof *parent);
  if (parent == NULL || edgemap_init(&h, (size_t)nedges) != 0) {
    free(parent);
    edgemap_free(&h);
    dm_err_set(e, DM_ENOMEM, "refine: out of memory");
    return NULL;
  }
  for (i = 0; i < m->nv; i++)
    parent[2 * i] = parent[2 * i + 1] = i;
  for (t = 0; t < m->ntop; t++)
    for (i = 0; i <= n; i++)
      if (n == 2 || i == 0)
        midpoint(&h, m->T[(n + 1) * t + i], m->T[(n + 1) * t + (i + 1) % (n + 1)], &next,
                 parent);
  nv = next;
  f = dm_dec_meshdata_alloc(n, N, nv, m->ntop * (n == 1 ? 2 : 4), e);
  if (f != NULL) {
    memcpy(f->X, m->X, (size_t)m->nv * N * sizeof *f->X);
    for (i = m->nv; i < nv; i++) {
      int c;
      for (c = 0; c < N; c++)
        f->X[(size_t)i * N + c] = 0.5 * (m->X[(size_t)parent[2 * i] * N + c] +
                                        m->X[(size_t)parent[2 * i + 1] * N + c]);
    }
    next = m->nv;
    for (t = 0; t < m->ntop; t++) {
      const int *v = m->T + (n + 1) * t;
      if (n == 1) {
        int ab = midpoint(&h, v[0], v[1], &next, parent);
        int *T = f->T + 4 * t;
        T[0] = v[0]; T[1] = ab; T[2] = ab; T[3] = v[1];
      } else {
        int ab = midpoint(&h, v[0], v[1], &next, parent);
        int bc = midpoint(&h, v[1], v[2], &next, parent);
        int ca = midpoint(&h, v[2], v[0], &next, parent);
        int *T = f->T + 12 * t;
        T[0] = v[0]; T[1] = ab; T[2] = ca;
        T[3] = ab; T[4] = v[1]; T[5] = bc;
        T[6] = ca; T[7] = bc; T[8] = v[2];
        T[9] = ab; T[10] = bc; T[11] = ca;
      }
    }
  }
  edgemap_free(&h);
  if (f != NULL && parent_out != NULL)
    *parent_out = parent;
  else
    free(parent);
  return f;
}

dm_dec_meshdata *dm_dec_gen_sphere(double r, int level, dm_err *e)
{
  static const int F[20][3] = {
    {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
    {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
    {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
    {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  const double p = (1 + sqrt(5.0)) / 2;
  const double V[12][3] = {
    {-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
    {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  dm_dec_meshdata *m;
  int i, t, L;
  if (!(r > 0) || level < 0 || level > 10) {
    bad(e, "sphere", "radius > 0 and level in 0..10 expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(2, 3, 12, 20, e)) == NULL)
    return NULL;
  memcpy(m->X, V, sizeof V);
  memcpy(m->T, F, sizeof F);
  for (L = 0; L <= level; L++) {
    if (L > 0) {
      dm_dec_meshdata *f = dm_dec_refine(m, NULL, e);
      dm_dec_meshdata_free(m);
      if ((m = f) == NULL)
        return NULL;
    }
    for (i = 0; i < m->nv; i++) {
      double *x = m->X + 3 * i, s = r / sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
      x[0] *= s;
      x[1] *= s;
      x[2] *= s;
    }
  }
  for (t = 0; t < m->ntop; t++) {           /* outward normals */
    int *v = m->T + 3 * t;
    const double *a = m->X + 3 * v[0], *b = m->X + 3 * v[1], *c = m->X + 3 * v[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                     u[0] * w[1] - u[1] * w[0]};
    if (nrm[0] * a[0] + nrm[1] * a[1] + nrm[2] * a[2] < 0) {
      int s = v[1];
      v[1] = v[2];
      v[2] = s;
    }
  }
  return m;
}

dm_dec_meshdata *dm_dec_gen_box(int nx, int ny, int nz, double a, double b, double c,
                                dm_err *e)
{
  static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  dm_dec_meshdata *m;
  int i, j, k, p, t = 0;
  double h[3];
  if (nx < 1 || ny < 1 || nz < 1 || !(a > 0) || !(b > 0) || !(c > 0)) {
    bad(e, "box", "nx, ny, nz >= 1 and positive side lengths expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(3, 3, (nx + 1) * (ny + 1) * (nz + 1), 6 * nx * ny * nz, e)) == NULL)
    return NULL;
  h[0] = a / nx;
  h[1] = b / ny;
  h[2] = c / nz;
#define VID(ii, jj, kk) (((kk) * (ny + 1) + (jj)) * (nx + 1) + (ii))
  for (k = 0; k <= nz; k++)
    for (j = 0; j <= ny; j++)
      for (i = 0; i <= nx; i++) {
        double *x = m->X + 3 * VID(i, j, k);
        x[0] = i == nx ? a : i * h[0];
        x[1] = j == ny ? b : j * h[1];
        x[2] = k == nz ? c : k * h[2];
      }
  for (k = 0; k < nz; k++)
    for (j = 0; j < ny; j++)
      for (i = 0; i < nx; i++)
        for (p = 0; p < 6; p++, t++) {
          int q[3] = {i, j, k}, s, *T = m->T + 4 * t;
          T[0] = VID(i, j, k);
          for (s = 0; s < 3; s++) {
            q[perm[p][s]]++;
            T[s + 1] = VID(q[0], q[1], q[2]);
          }
          {                                     /* positive volume */
            const double *x0 = m->X + 3 * T[0], *x1 = m->X + 3 * T[1];
            const double *x2 = m->X + 3 * T[2], *x3 = m->X + 3 * T[3];
            double u[3], v[3], w[3], det;
            for (s = 0; s < 3; s++) {
              u[s] = x1[s] - x0[s];
              v[s] = x2[s] - x0[s];
              w[s] = x3[s] - x0[s];
            }
            det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                  u[2] * (v[0] * w[1] - v[1] * w[0]);
            if (det < 0) {
              int sw = T[2];
              T[2] = T[3];
              T[3] = sw;
            }
          }
        }
#undef VID
  return m;
}

dm_dec_meshdata *dm_dec_gen_path(int np, const double *x, dm_err *e)
{
  dm_dec_meshdata *m;
  int i;
  if (np < 1) {
    bad(e, "path", "at least one segment expected");
    return NULL;
  }
  if ((m = dm_dec_meshdata_alloc(1, 1, np + 1, np, e)) == NULL)
    return NULL;
  for (i = 0; i <= np; i++)
    m->X[i] = x != NULL ? x[i] : (double)i;
  for (i = 0; i < np; i++) {
    m->T[2 * i] = i;
    m->T[2 * i + 1] = i + 1;
  }
  return m;
}
