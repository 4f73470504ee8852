/* test_conn_mesh.c -- Levi-Civita connections (src/conn): on the frame
 * bundle of the sphere (geodesic polygons: area mod 2 pi, the Foucault
 * pendulum) and on triangle meshes (vertex holonomy = angle defect on the
 * octahedron, a triangulated cube, a flat fan, an icosphere with
 * Gauss-Bonnet; transitions against the reflection formula built from the
 * edge normals; intrinsic geometries; error paths).  Reference values:
 * tests/data/conn/reference.py. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "conn/conn.h"

/* {==== the sphere frames ================================================== */

static double holo_sphere(dm_conn_dc *D, const double *pts, size_t n, const double *R0, dm_err *e)
{
  double ang;
  if (dm_conn_dc_holonomy(D, pts, n, R0, NULL, NULL, &ang, e) != DM_OK)
    return NAN;
  return ang;
}

/* the polygon through the corners, each great-circle edge cut into m pieces */
static size_t subdivide(const double *corners, size_t nc, int m, double *out)
{
  size_t k, n = 0;
  int j, i;
  for (k = 0; k + 1 < nc; k++)
    for (j = 0; j < m; j++) {
      double v[3], s = 0.0;
      for (i = 0; i < 3; i++)
        v[i] = corners[3 * k + i] * (m - j) + corners[3 * (k + 1) + i] * j;
      for (i = 0; i < 3; i++)
        s += v[i] * v[i];
      for (i = 0; i < 3; i++)
        out[3 * n + i] = v[i] / sqrt(s);
      n++;
    }
  memcpy(out + 3 * n, corners + 3 * (nc - 1), 3 * sizeof *out);
  return n + 1;
}

static void test_sphere(void)
{
  dm_conn_bundle *S = dm_conn_bundle_sphere_frames(NULL);
  dm_conn_dc *D = dm_conn_dc_alloc(dm_conn_rule_find("levi-civita"), S, NULL, NULL, NULL, NULL);
  double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, oct[12] = {0, 0, 1, 1, 0, 0, 0, 1, 0, 0, 0, 1},
         tri[12] = {0, 0, 1, 1, 0, 0, cos(1.0), sin(1.0), 0, 0, 0, 1}, pts[3 * 1100], R0[9],
         p0[3], e1[3] = {0, 1, 0}, e2[3], err[3], a, back[9] = {0, 0, 1, 0, 0, -1, 0, 0, 1};
  const double want[3] = {3.111019, 3.139699, 3.141474};
  size_t n;
  int m, k, N, okm = 1;
  dm_err e;
  for (m = 1; m <= 7; m += 3) {
    n = subdivide(oct, 4, m, pts);
    a = holo_sphere(D, pts, n, I, NULL);
    okm = okm && fabs(a - M_PI / 2) < 1e-14;
  }
  tap_ok(okm, "sphere: octant triangle e3 -> e1 -> e2 -> pi/2 for 1, 4 and 7 pieces per edge");
  n = subdivide(tri, 4, 5, pts);
  tap_near(holo_sphere(D, pts, n, I, NULL), 1.0, 1e-14,
           "sphere: triangle e3 -> e1 -> (cos 1, sin 1, 0): its area 1.0");
  /* Foucault: latitude 30 degrees, eastward, N geodesic edges */
  for (k = 0; k < 3; k++) {
    N = 16 << (2 * k);
    for (m = 0; m <= N; m++) {
      double t = 2 * M_PI * m / N;
      pts[3 * m] = cos(M_PI / 6) * cos(t);
      pts[3 * m + 1] = cos(M_PI / 6) * sin(t);
      pts[3 * m + 2] = sin(M_PI / 6);
    }
    memcpy(pts + 3 * N, pts, 3 * sizeof *pts);
    memcpy(p0, pts, sizeof p0);
    e2[0] = p0[1] * e1[2] - p0[2] * e1[1];
    e2[1] = p0[2] * e1[0] - p0[0] * e1[2];
    e2[2] = p0[0] * e1[1] - p0[1] * e1[0];
    for (m = 0; m < 3; m++) {
      R0[3 * m] = e1[m];
      R0[3 * m + 1] = e2[m];
      R0[3 * m + 2] = p0[m];
    }
    a = fmod(holo_sphere(D, pts, (size_t)N + 1, R0, NULL) + 2 * M_PI, 2 * M_PI);
    err[k] = fabs(a - want[k]);
    tap_ok(err[k] < 1e-6, "Foucault, latitude 30, N = %d: holonomy %.6f (2 pi sin 30 = pi mod "
           "2 pi)", N, a);
  }
  /* errors: an antipodal edge, a shape off the sphere */
  tap_ok(isnan(holo_sphere(D, back, 3, I, &e)) && strstr(e.msg, "antipodal"),
         "sphere: an antipodal edge has no unique geodesic: %s", e.msg);
  p0[0] = 0.0; p0[1] = 0.0; p0[2] = 2.0;
  tap_ok(dm_conn_dc_hlift(D, I, p0, R0, &e) == DM_EDOM && strstr(e.msg, "unit sphere"),
         "sphere: a point off the sphere: %s", e.msg);
  dm_conn_dc_free(D);
  dm_conn_bundle_free(S);
}

/* }==== */

/* {==== meshes ============================================================== */

typedef struct mesh {
  dm_dec_complex *K;
  dm_dec_geom *G;
} mesh;

static mesh make_mesh(int N, int nv, int nt, const double *X, const int *T)
{
  mesh m;
  m.K = dm_dec_complex_alloc(2, nv, nt, T, NULL);
  m.G = dm_dec_geom_alloc(m.K, N, X, NULL);
  return m;
}

static void mesh_free(mesh *m)
{
  dm_dec_geom_free(m->G);
  dm_dec_complex_free(m->K);
}

static mesh octahedron(void)
{
  static const double X[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  int T[24], t = 0, sx, sy, sz;
  for (sx = 0; sx < 2; sx++)
    for (sy = 0; sy < 2; sy++)
      for (sz = 0; sz < 2; sz++) {
        int a = sx, b = 2 + sy, c = 4 + sz, odd = (sx + sy + sz) & 1;
        T[3 * t] = a;
        T[3 * t + 1] = odd ? c : b;
        T[3 * t + 2] = odd ? b : c;
        t++;
      }
  return make_mesh(3, 6, 8, X, T);
}

static mesh cube(void)
{
  static const double X[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                               0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  /* outward quads (counter-clockwise from outside), split along a diagonal */
  static const int Q[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3};
  int T[36], f;
  for (f = 0; f < 6; f++) {
    const int *q = Q + 4 * f;
    T[6 * f] = q[0]; T[6 * f + 1] = q[1]; T[6 * f + 2] = q[2];
    T[6 * f + 3] = q[0]; T[6 * f + 4] = q[2]; T[6 * f + 5] = q[3];
  }
  return make_mesh(3, 8, 12, X, T);
}

/* a planar fan: centre 0 and 7 irregular rim vertices */
static mesh fan(void)
{
  double X[16];
  int T[21], k;
  X[0] = 0.05;
  X[1] = -0.02;
  for (k = 0; k < 7; k++) {
    double t = 2 * M_PI * k / 7 + 0.2 * sin(3.0 * k);
    X[2 + 2 * k] = (1 + 0.3 * cos(2.0 * k)) * cos(t);
    X[3 + 2 * k] = (1 + 0.3 * cos(2.0 * k)) * sin(t);
    T[3 * k] = 0;
    T[3 * k + 1] = 1 + k;
    T[3 * k + 2] = 1 + (k + 1) % 7;
  }
  return make_mesh(2, 8, 7, X, T);
}

static void test_polyhedra(void)
{
  mesh o = octahedron(), c = cube(), f = fan();
  double a, sum = 0.0, worst = 0.0;
  int v, okc = 1;
  dm_err e;
  tap_ok(o.G && c.G && f.G, "octahedron, cube and fan built");
  for (v = 0; v < 6; v++) {
    dm_conn_mesh_vertex_holonomy(o.G, v, &a, NULL);
    worst = fmax(worst, fabs(a - 2 * M_PI / 3));
    sum += a;
  }
  tap_ok(worst < 1e-14, "octahedron: holonomy around every vertex = 2 pi - 4 pi/3 = 2 pi/3 (%.1e)",
         worst);
  tap_near(sum, 4 * M_PI, 1e-13, "octahedron: the sum is 4 pi (Gauss-Bonnet)");
  for (v = 0; v < 8; v++) {
    dm_conn_mesh_vertex_holonomy(c.G, v, &a, NULL);
    okc = okc && fabs(a - M_PI / 2) < 1e-14 && fabs(dm_conn_mesh_defect(c.G, v) - M_PI / 2) < 1e-14;
  }
  tap_ok(okc, "triangulated cube: every corner pi/2 (= its angle defect)");
  dm_conn_mesh_vertex_holonomy(f.G, 0, &a, NULL);
  tap_ok(fabs(a) < 1e-13, "flat fan: holonomy 0 (%.1e)", a);
  tap_ok(dm_conn_mesh_vertex_holonomy(f.G, 3, &a, &e) == DM_EINVAL && strstr(e.msg, "boundary"),
         "fan: a rim vertex is on the boundary: %s", e.msg);
  tap_ok(dm_conn_mesh_transition(o.G, 0, 7, &a, &e) == DM_EINVAL && strstr(e.msg, "share no edge"),
         "opposite octahedron faces share no edge: %s", e.msg);
  tap_ok(dm_conn_mesh_transition(o.G, 0, 8, &a, &e) == DM_EINVAL && strstr(e.msg, "does not exist"),
         "triangle out of range: %s", e.msg);
  tap_ok(dm_conn_mesh_vertex_holonomy(o.G, 6, &a, &e) == DM_EINVAL, "vertex out of range: %s",
         e.msg);
  mesh_free(&o);
  mesh_free(&c);
  mesh_free(&f);
}

/* the frame of a triangle as mesh_lc.c defines it, recomputed here from the
 * embedded coordinates: e1 along the first edge, e2 = n x e1 */
static void frame3(const double *X, const int *t, double *e1, double *e2)
{
  double a[3], b[3], n[3], s;
  int i;
  for (i = 0; i < 3; i++) {
    a[i] = X[3 * t[1] + i] - X[3 * t[0] + i];
    b[i] = X[3 * t[2] + i] - X[3 * t[0] + i];
  }
  n[0] = a[1] * b[2] - a[2] * b[1];
  n[1] = a[2] * b[0] - a[0] * b[2];
  n[2] = a[0] * b[1] - a[1] * b[0];
  s = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  for (i = 0; i < 3; i++)
    e1[i] = a[i] / s;
  e2[0] = n[1] * e1[2] - n[2] * e1[1];
  e2[1] = n[2] * e1[0] - n[0] * e1[2];
  e2[2] = n[0] * e1[1] - n[1] * e1[0];
  s = sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
  for (i = 0; i < 3; i++)
    e2[i] /= s;
}

/* the unit normal of edge (u, w) in the plane of triangle t, pointing out
 * of t, in t's frame */
static void edge_normal(const double *X, const int *t, int u, int w, int out, double *nn)
{
  double e1[3], e2[3], d[3], m[3], c[3], in[2], s;
  int i, o = t[0] + t[1] + t[2] - u - w;
  frame3(X, t, e1, e2);
  for (i = 0; i < 3; i++) {
    d[i] = X[3 * w + i] - X[3 * u + i];
    c[i] = X[3 * o + i] - X[3 * u + i];
  }
  /* component of c orthogonal to d, negated: points out of t */
  s = (c[0] * d[0] + c[1] * d[1] + c[2] * d[2]) / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (i = 0; i < 3; i++)
    m[i] = (out ? -1.0 : 1.0) * (c[i] - s * d[i]);
  in[0] = m[0] * e1[0] + m[1] * e1[1] + m[2] * e1[2];
  in[1] = m[0] * e2[0] + m[1] * e2[1] + m[2] * e2[2];
  s = sqrt(in[0] * in[0] + in[1] * in[1]);
  nn[0] = in[0] / s;
  nn[1] = in[1] / s;
}

static void test_reflections(void)
{
  dm_dec_meshdata *md = dm_dec_gen_sphere(1.0, 1, NULL);
  mesh m = make_mesh(3, md->nv, md->ntop, md->X, md->T);
  double worst = 0.0, a, sum = 0.0, gb;
  int t0, t1, k, checked = 0, v;
  for (t0 = 0; t0 < md->ntop; t0++)
    for (t1 = t0 + 1; t1 < md->ntop; t1++) {
      const int *A = md->T + 3 * t0, *B = md->T + 3 * t1;
      int sh[2], ns = 0, i, j;
      double n0[2], n1[2], b[2], bn, R[4], ang;
      for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
          if (A[i] == B[j] && ns < 2)
            sh[ns++] = A[i];
      if (ns != 2)
        continue;
      dm_conn_mesh_transition(m.G, t0, t1, &a, NULL);
      edge_normal(md->X, A, sh[0], sh[1], 1, n0);
      edge_normal(md->X, B, sh[0], sh[1], 0, n1);
      /* A = (I - 2 b b^T)(I - 2 n0 n0^T), b = (n0 + n1)/|n0 + n1| */
      b[0] = n0[0] + n1[0];
      b[1] = n0[1] + n1[1];
      bn = sqrt(b[0] * b[0] + b[1] * b[1]);
      b[0] /= bn;
      b[1] /= bn;
      {
        double P[4] = {1 - 2 * b[0] * b[0], -2 * b[0] * b[1], -2 * b[0] * b[1], 1 - 2 * b[1] * b[1]};
        double Q[4] = {1 - 2 * n0[0] * n0[0], -2 * n0[0] * n0[1], -2 * n0[0] * n0[1],
                       1 - 2 * n0[1] * n0[1]};
        R[0] = P[0] * Q[0] + P[1] * Q[2];
        R[1] = P[0] * Q[1] + P[1] * Q[3];
        R[2] = P[2] * Q[0] + P[3] * Q[2];
        R[3] = P[2] * Q[1] + P[3] * Q[3];
      }
      ang = atan2(R[2], R[0]);
      worst = fmax(worst, fabs(remainder(ang - a, 2 * M_PI)));
      checked++;
    }
  tap_ok(checked == 3 * md->ntop / 2 && worst < 1e-13,
         "icosphere: %d transitions = the rotation (I - 2bb^T)(I - 2 n0 n0^T) of the edge "
         "normals (%.1e)", checked, worst);
  for (v = 0; v < md->nv; v++) {
    dm_conn_mesh_vertex_holonomy(m.G, v, &a, NULL);
    gb = dm_conn_mesh_defect(m.G, v);
    worst = fmax(worst, fabs(a - gb));
    sum += a;
  }
  tap_ok(worst < 1e-13, "icosphere: vertex holonomy = angle defect at all %d vertices", md->nv);
  tap_near(sum, 4 * M_PI, 1e-12, "icosphere: Gauss-Bonnet, sum = 4 pi");
  /* transport along a chain = the sum of its transitions */
  {
    int chain[3], nc = 0, ok;
    double s = 0.3, d1, d2;
    chain[nc++] = 0;
    for (k = 1; k < md->ntop && nc < 3; k++)
      if (dm_conn_mesh_transition(m.G, chain[nc - 1], k, &a, NULL) == DM_OK)
        chain[nc++] = k;
    dm_conn_mesh_transition(m.G, chain[0], chain[1], &d1, NULL);
    dm_conn_mesh_transition(m.G, chain[1], chain[2], &d2, NULL);
    ok = dm_conn_mesh_transport(m.G, chain, 3, &s, NULL) == DM_OK;
    tap_ok(ok && fabs(s - (0.3 + d1 + d2)) < 1e-15, "transport along a chain of triangles");
  }
  mesh_free(&m);
  dm_dec_meshdata_free(md);
}

/* an intrinsic geometry (edge lengths only) gives the same holonomies */
static void test_intrinsic(void)
{
  mesh o = octahedron();
  dm_dec_geom *Gi = dm_dec_geom_alloc_intrinsic(o.K, o.G->len2, NULL);
  double a, b, worst = 0.0;
  int v;
  for (v = 0; v < 6; v++) {
    dm_conn_mesh_vertex_holonomy(o.G, v, &a, NULL);
    dm_conn_mesh_vertex_holonomy(Gi, v, &b, NULL);
    worst = fmax(worst, fabs(a - b));
  }
  tap_ok(Gi && worst < 1e-15, "intrinsic octahedron: same holonomies from edge lengths");
  dm_dec_geom_free(Gi);
  mesh_free(&o);
}

/* }==== */

int main(void)
{
  dm_gsl_init();
  test_sphere();
  test_polyhedra();
  test_reflections();
  test_intrinsic();
  return tap_done();
}
