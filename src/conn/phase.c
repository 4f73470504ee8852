/* phase.c -- the geometric phase of a shape path sampled by a trajectory
 * (a reduced run, or any run whose first columns are shape coordinates):
 * the body transport of its horizontal lift, by a discrete connection
 * (sample to sample) or a continuous one (straight segments between
 * samples); for a closed path the holonomy
 * (doc/bundles-connections-holonomy.md §8). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conn/conn_impl.h"
#include "core/interrupt.h"
#include "core/trajectory.h"

/* the samples as a shape path (malloc'ed into *xs), the gap of its ends */
static int gather(const dm_conn_bundle *B, const dm_traj *T, const size_t *cols,
                  const double *q0, double **xs, size_t *n, double *gap, dm_err *e)
{
  size_t len = dm_traj_len(T), nx = B->nx, i, k, jc[DM_CONN_NX_MAX];
  double g = 0.0, *x;
  if (!dm_conn_bundle_is_trivial(B))
    return dm_err_set(e, DM_EUNSUP, "phase: needs a trivial bundle S x G, got the %s bundle",
                      B->type->name);
  if (len < 2)
    return dm_err_set(e, DM_EINVAL, "phase: the path needs at least 2 samples, got %zu", len);
  for (i = 0; i < nx; i++) {
    jc[i] = cols ? cols[i] : (i < dm_traj_ncoords(T) ? dm_traj_qcol(T, i) : (size_t)-1);
    if (jc[i] >= dm_traj_ncols(T))
      return dm_err_set(e, DM_EINVAL, "phase: the trajectory has no column for shape "
                        "coordinate %zu (it has %zu coordinates)", i + 1, dm_traj_ncoords(T));
  }
  if ((x = malloc(len * nx * sizeof *x + 1)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "phase: out of memory");
  for (i = 0; i < nx; i++) {
    const double *c = dm_traj_col(T, jc[i]);
    for (k = 0; k < len; k++)
      x[k * nx + i] = c[k];
    g = fmax(g, fabs(c[len - 1] - c[0]));
    if (!(fabs(q0[i] - c[0]) <= 1e-9 * fmax(1.0, fabs(c[0])))) {
      free(x);
      return dm_err_set(e, DM_EINVAL, "phase: q0 is not over the first sample (coordinate %zu: "
                        "%.17g against %.17g)", i + 1, q0[i], c[0]);
    }
  }
  *xs = x;
  *n = len;
  if (gap)
    *gap = g;
  return DM_OK;
}

static void outputs(const dm_lie_group *G, const double *g0, const double *P, double *spatial,
                    double *body)
{
  double gi[DM_LIE_NQ_MAX], t[DM_LIE_NQ_MAX];
  if (spatial) {
    dm_lie_inverse(G, g0, gi);
    dm_lie_compose(G, g0, P, t);
    dm_lie_compose(G, t, gi, spatial);
  }
  if (body)
    memcpy(body, P, G->nq * sizeof *P);
}

int dm_conn_dc_phase(dm_conn_dc *D, const dm_traj *T, const size_t *cols, const double *q0,
                     double *spatial, double *body, double *gap, dm_err *e)
{
  const dm_conn_bundle *B = D->B;
  const dm_lie_group *G = B->G;
  double *xs, A[DM_LIE_NQ_MAX], Ai[DM_LIE_NQ_MAX], P[DM_LIE_NQ_MAX];
  size_t n, k;
  int st;
  if ((st = gather(B, T, cols, q0, &xs, &n, gap, e)) != DM_OK)
    return st;
  dm_lie_identity(G, P);
  for (k = 0; k + 1 < n && st == DM_OK; k++) {
    if ((k & 4095) == 4095 && dm_interrupted()) {
      st = dm_err_set(e, DM_EINTR, "phase: interrupted at sample %zu of %zu", k + 1, n);
      break;
    }
    if ((st = dm_conn_dc_local(D, xs + k * B->nx, xs + (k + 1) * B->nx, A, e)) == DM_OK) {
      dm_lie_inverse(G, A, Ai);
      dm_lie_compose(G, P, Ai, P);
    }
  }
  free(xs);
  if (st == DM_OK)
    outputs(G, q0 + B->nx, P, spatial, body);
  return st;
}

int dm_conn_phase(dm_conn *C, const dm_traj *T, const size_t *cols, const double *q0,
                  const dm_conn_topts *o, double *spatial, double *body, double *gap, dm_err *e)
{
  const dm_conn_bundle *B = C->B;
  double *xs, P[DM_LIE_NQ_MAX];
  size_t n;
  int st;
  if ((st = gather(B, T, cols, q0, &xs, &n, gap, e)) != DM_OK)
    return st;
  st = dm_conn_transport_polygon(C, xs, n, o, P, e);
  free(xs);
  if (st == DM_OK)
    outputs(B->G, q0 + B->nx, P, spatial, body);
  return st;
}
