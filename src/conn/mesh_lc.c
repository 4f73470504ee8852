/* mesh_lc.c -- the discrete Levi-Civita connection of a triangle mesh
 * (doc/bundles-connections-holonomy.md §7): every triangle carries an
 * orthonormal frame of its own plane, built from its edge lengths alone (first
 * vertex at the origin, first edge along e1, the triangle on the side e2 > 0 of
 * it), and crossing a shared edge rotates frames so that the edge keeps its
 * direction.  The product of the transitions around an interior vertex is
 * the rotation by its angle defect (mod 2 pi). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conn/conn_impl.h"

static double wrap(double a)
{
  a = remainder(a, 2.0 * M_PI);
  if (a <= -M_PI)
    a += 2.0 * M_PI;
  return a;
}

static double len2_of(const dm_dec_geom *G, int u, int w)
{
  int v2[2] = {u, w};
  int k = dm_dec_find(G->K, 1, v2);
  return k < 0 ? NAN : G->len2[k];
}

/* positions P (3 x 2) of the vertices of triangle t (in its vertex order)
 * in its frame; DM_EDOM for a degenerate triangle */
static int tri_coords(const dm_dec_geom *G, int t, double *P, dm_err *e)
{
  const int *v = G->K->top + 3 * (size_t)t;
  double ab2 = len2_of(G, v[0], v[1]), ac2 = len2_of(G, v[0], v[2]),
         bc2 = len2_of(G, v[1], v[2]);
  double ab = sqrt(ab2), ac = sqrt(ac2), c, s;
  c = (ab2 + ac2 - bc2) / (2.0 * ab * ac);
  if (!(ab > 0.0 && ac > 0.0) || !(fabs(c) < 1.0))
    return dm_err_set(e, DM_EDOM, "levi-civita: triangle %d (vertices %d, %d, %d) is degenerate",
                      t + 1, v[0] + 1, v[1] + 1, v[2] + 1);
  s = sqrt(1.0 - c * c);
  P[0] = P[1] = 0.0;
  P[2] = ab;
  P[3] = 0.0;
  P[4] = ac * c;
  P[5] = ac * s;
  return DM_OK;
}

static int local_index(const dm_dec_complex *K, int t, int v)
{
  int i;
  for (i = 0; i < 3; i++)
    if (K->top[3 * (size_t)t + i] == v)
      return i;
  return -1;
}

static int check_tri(const dm_dec_geom *G, int t, const char *what, dm_err *e)
{
  if (G == NULL || G->K->n != 2)
    return dm_err_set(e, DM_EINVAL, "%s: a triangle mesh expected", what);
  if (t < 0 || t >= G->K->nsimp[2])
    return dm_err_set(e, DM_EINVAL, "%s: triangle %d does not exist (1..%d)", what, t + 1,
                      G->K->nsimp[2]);
  return DM_OK;
}

int dm_conn_mesh_transition(const dm_dec_geom *G, int t0, int t1, double *angle, dm_err *e)
{
  const dm_dec_complex *K;
  double P0[6], P1[6], f0, f1;
  int sh[2], ns = 0, i, i0u, i0w, i1u, i1w, st;
  if ((st = check_tri(G, t0, "transition", e)) != DM_OK ||
      (st = check_tri(G, t1, "transition", e)) != DM_OK)
    return st;
  K = G->K;
  for (i = 0; i < 3; i++)
    if (local_index(K, t1, K->top[3 * (size_t)t0 + i]) >= 0 && ns < 2)
      sh[ns++] = K->top[3 * (size_t)t0 + i];
  if (t0 == t1 || ns != 2)
    return dm_err_set(e, DM_EINVAL, "transition: triangles %d and %d share no edge", t0 + 1,
                      t1 + 1);
  i0u = local_index(K, t0, sh[0]);
  i0w = local_index(K, t0, sh[1]);
  i1u = local_index(K, t1, sh[0]);
  i1w = local_index(K, t1, sh[1]);
  /* consistent orientations run the shared edge in opposite directions */
  if (((i0w - i0u + 3) % 3) == ((i1w - i1u + 3) % 3))
    return dm_err_set(e, DM_EINVAL, "transition: triangles %d and %d are oriented "
                      "inconsistently (both run edge %d-%d the same way)", t0 + 1, t1 + 1,
                      sh[0] + 1, sh[1] + 1);
  if ((st = tri_coords(G, t0, P0, e)) != DM_OK || (st = tri_coords(G, t1, P1, e)) != DM_OK)
    return st;
  f0 = atan2(P0[2 * i0w + 1] - P0[2 * i0u + 1], P0[2 * i0w] - P0[2 * i0u]);
  f1 = atan2(P1[2 * i1w + 1] - P1[2 * i1u + 1], P1[2 * i1w] - P1[2 * i1u]);
  *angle = wrap(f1 - f0);
  return DM_OK;
}

int dm_conn_mesh_transport(const dm_dec_geom *G, const int *ts, size_t n, double *angle,
                           dm_err *e)
{
  double a = *angle, d;
  size_t k;
  int st;
  if (n < 1)
    return dm_err_set(e, DM_EINVAL, "transport: at least one triangle expected");
  if ((st = check_tri(G, ts[0], "transport", e)) != DM_OK)
    return st;
  for (k = 0; k + 1 < n; k++) {
    if ((st = dm_conn_mesh_transition(G, ts[k], ts[k + 1], &d, e)) != DM_OK)
      return st;
    a += d;
  }
  *angle = a;
  return DM_OK;
}

/* the triangle other than t containing the edge {v, w}, or -1 */
static int across(const dm_dec_complex *K, int t, int v, int w, int *count)
{
  int s, r = -1;
  *count = 0;
  for (s = 0; s < K->nsimp[2]; s++)
    if (local_index(K, s, v) >= 0 && local_index(K, s, w) >= 0) {
      ++*count;
      if (s != t)
        r = s;
    }
  return r;
}

int dm_conn_mesh_vertex_holonomy(const dm_dec_geom *G, int v, double *angle, dm_err *e)
{
  const dm_dec_complex *K;
  double sum = 0.0, d;
  int t0 = -1, t, s, guard, cnt, st;
  if (G == NULL || G->K->n != 2)
    return dm_err_set(e, DM_EINVAL, "vertex holonomy: a triangle mesh expected");
  K = G->K;
  if (v < 0 || v >= K->nsimp[0])
    return dm_err_set(e, DM_EINVAL, "vertex holonomy: vertex %d does not exist (1..%d)", v + 1,
                      K->nsimp[0]);
  for (s = 0; s < K->nsimp[2] && t0 < 0; s++)
    if (local_index(K, s, v) >= 0)
      t0 = s;
  t = t0;
  /* counter-clockwise about v: from (v, a, b) to the triangle across {v, b} */
  for (guard = 0; guard <= K->nsimp[2]; guard++) {
    int i = local_index(K, t, v), b = K->top[3 * (size_t)t + (i + 2) % 3];
    int nt = across(K, t, v, b, &cnt);
    if (cnt > 2)
      return dm_err_set(e, DM_EINVAL, "vertex holonomy: the star of vertex %d is not a "
                        "manifold (edge %d-%d has %d triangles)", v + 1, v + 1, b + 1, cnt);
    if (nt < 0)
      return dm_err_set(e, DM_EINVAL, "vertex holonomy: vertex %d is on the boundary (edge "
                        "%d-%d has one triangle): its dual cell is not a closed loop", v + 1,
                        v + 1, b + 1);
    if ((st = dm_conn_mesh_transition(G, t, nt, &d, e)) != DM_OK)
      return st;
    sum += d;
    t = nt;
    if (t == t0)
      break;
  }
  if (t != t0)
    return dm_err_set(e, DM_EINVAL, "vertex holonomy: the triangles around vertex %d do not "
                      "close up", v + 1);
  *angle = wrap(sum);
  return DM_OK;
}

double dm_conn_mesh_defect(const dm_dec_geom *G, int v)
{
  const dm_dec_complex *K = G->K;
  double sum = 0.0, P[6];
  int s, boundary = K->boundary[0] ? K->boundary[0][v] : 0;
  for (s = 0; s < K->nsimp[2]; s++) {
    int i = local_index(K, s, v);
    double ax, ay, bx, by;
    if (i < 0 || tri_coords(G, s, P, NULL) != DM_OK)
      continue;
    ax = P[2 * ((i + 1) % 3)] - P[2 * i];
    ay = P[2 * ((i + 1) % 3) + 1] - P[2 * i + 1];
    bx = P[2 * ((i + 2) % 3)] - P[2 * i];
    by = P[2 * ((i + 2) % 3) + 1] - P[2 * i + 1];
    sum += atan2(fabs(ax * by - ay * bx), ax * bx + ay * by);
  }
  return (boundary ? M_PI : 2.0 * M_PI) - sum;
}
