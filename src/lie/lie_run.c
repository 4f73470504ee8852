/* lie_run.c -- states and structure diagnostics of systems on groups
 * (lie_system.h): Legendre maps, energy, spatial momentum, Casimirs, the
 * group element of a trajectory's sample, the symplecticity defect on
 * T*G, time reversal, the empirical order.  Runs go through the core run
 * driver (core/run.h): the system declares its nq stored numbers, its
 * momentum and velocity names and its spatial momentum (system.h). */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_integ_impl.h"
#include "core/interrupt.h"
#include "core/numfmt.h"
#include "core/vecmath.h"

/* {==== states =========================================================== */

int dm_lie_momentum(dm_integrator *I, const double *g, const double *xi, double *mu, dm_err *e)
{
  return dm_integrator_momentum(I, g, xi, mu, e);
}

int dm_lie_velocity(dm_integrator *I, const double *g, const double *mu, double *xi, dm_err *e)
{
  return dm_integrator_velocity(I, g, mu, xi, 0, e);
}

int dm_lie_energy(dm_integrator *I, const double *g, const double *mu, double *E, dm_err *e)
{
  double xi[DM_LIE_DIM_MAX];
  int st = dm_integrator_velocity(I, g, mu, xi, 0, e);
  if (st != DM_OK)
    return st;
  return dm_integrator_energy(I, g, xi, E, e);
}

void dm_lie_spatial_momentum(const dm_lie_group *G, const double *g, const double *mu, double *J)
{
  double gi[DM_LIE_NQ_MAX];
  dm_lie_inverse(G, g, gi);
  dm_lie_Adstar_apply(G, gi, mu, J);
}

static size_t casimirs1(const dm_lie_group *F, const double *mu, double *c)
{
  size_t i;
  switch (F->kind) {
  case DM_LIE_SO3:
    c[0] = dm_v3_dot(mu, mu);
    return 1;
  case DM_LIE_SE3:
    c[0] = dm_v3_dot(mu + 3, mu + 3);
    c[1] = dm_v3_dot(mu, mu + 3);
    return 2;
  case DM_LIE_SE2:
    c[0] = mu[1] * mu[1] + mu[2] * mu[2];
    return 1;
  default:
    for (i = 0; i < F->dim; i++)
      c[i] = mu[i];
    return F->dim;
  }
}

size_t dm_lie_casimirs(const dm_lie_group *G, const double *mu, double *c)
{
  size_t i, k = 0;
  if (G->kind != DM_LIE_PRODUCT)
    return casimirs1(G, mu, c);
  for (i = 0; i < G->nfac; i++)
    k += casimirs1(G->fac[i], mu + G->xoff[i], c + k);
  return k;
}

/* }====================================================================== */

/* {==== trajectories ===================================================== */

int dm_lie_traj_group(const dm_traj *tr, dm_lie_group **G, dm_err *e)
{
  const char *name = dm_traj_meta_get(tr, "space");
  *G = NULL;
  if (name == NULL)
    return dm_err_set(e, DM_EINVAL, "the trajectory is not of a system on a Lie group (no "
                      "'space' in its metadata)");
  if (strncmp(name, "S^", 2) == 0)
    return dm_err_set(e, DM_EINVAL, "the trajectory is of a system on the sphere %s, not on a "
                      "Lie group: its points are the coordinates (traj[k].q)", name);
  if ((*G = dm_lie_group_parse(name, e)) == NULL)
    return e ? e->status : DM_EINVAL;
  if ((*G)->nq != dm_traj_ncoords(tr)) {
    size_t n = dm_traj_ncoords(tr), nq = (*G)->nq;
    dm_lie_group_free(*G);
    *G = NULL;
    return dm_err_set(e, DM_EINVAL, "the trajectory's space is %s (%zu numbers per element) but "
                      "it has %zu coordinates", name, nq, n);
  }
  return DM_OK;
}

int dm_lie_traj_element(const dm_traj *tr, const dm_lie_group *G, size_t k, double *g, dm_err *e)
{
  if (dm_traj_ncoords(tr) != G->nq)
    return dm_err_set(e, DM_EINVAL, "the trajectory has %zu coordinates, %s elements %zu",
                      dm_traj_ncoords(tr), G->name, G->nq);
  return dm_traj_get(tr, k, NULL, g, NULL, NULL, e);
}

/* }====================================================================== */

/* {==== structure diagnostics ============================================ */

/* one step from a copy (the integrator's warm start forgotten first) */
static int step1(dm_integrator *I, double h, const double *g, const double *mu, double *g1,
                 double *mu1, dm_err *e)
{
  dm_integrator_reset(I);
  return dm_integrator_step(I, h, g, mu, g1, mu1, e);
}

int dm_lie_symplecticity_defect(dm_integrator *I, double h, const double *g0, const double *mu0,
                                double *defect, dm_err *e)
{
  const dm_lie_system *S = dm_lie_system_of(I->sys);
  const dm_lie_group *G;
  double g1[DM_LIE_NQ_MAX], mu1[DM_LIE_DIM_MAX], gp[DM_LIE_NQ_MAX], gm[DM_LIE_NQ_MAX];
  double mp[DM_LIE_DIM_MAX], mm[DM_LIE_DIM_MAX], ex[DM_LIE_NQ_MAX], d[DM_LIE_NQ_MAX];
  double lp[DM_LIE_DIM_MAX], lm[DM_LIE_DIM_MAX], g1i[DM_LIE_NQ_MAX];
  double *D, *O0, *O1, worst = 0.0;
  size_t n, m, i, j, k;
  int st;
  if (S == NULL)
    return dm_err_set(e, DM_EINVAL, "symplecticity_defect: not a system on a Lie group");
  G = S->G;
  n = S->dim;
  m = 2 * n;
  D = calloc(3 * m * m, sizeof *D);
  if (D == NULL)
    return dm_err_set(e, DM_ENOMEM, "symplecticity_defect: out of memory");
  O0 = D + m * m;
  O1 = O0 + m * m;
  if ((st = step1(I, h, g0, mu0, g1, mu1, e)) != DM_OK)
    goto done;
  dm_lie_inverse(G, g1, g1i);
  for (j = 0; j < m && st == DM_OK; j++) {
    double eps = 1e-6, sc = j < n ? 1.0 : fmax(1.0, dm_norm_inf(mu0, n));
    double v[DM_LIE_DIM_MAX] = {0};
    int sgn;
    for (sgn = 0; sgn < 2 && st == DM_OK; sgn++) {
      double s = sgn ? -eps * sc : eps * sc, *go = sgn ? gm : gp, *mo = sgn ? mm : mp;
      memcpy(mo, mu0, n * sizeof *mo);
      if (j < n) {
        v[j] = s;
        dm_lie_exp(G, v, ex);
        dm_lie_compose(G, g0, ex, d);
        v[j] = 0.0;
        st = step1(I, h, d, mo, go, mo, e);
      } else {
        mo[j - n] += s;
        st = step1(I, h, g0, mo, go, mo, e);
      }
    }
    if (st != DM_OK)
      break;
    dm_lie_compose(G, g1i, gp, d);
    dm_lie_log(G, d, lp);
    dm_lie_compose(G, g1i, gm, d);
    dm_lie_log(G, d, lm);
    for (i = 0; i < n; i++) {
      D[i * m + j] = (lp[i] - lm[i]) / (2 * eps * sc);
      D[(n + i) * m + j] = (mp[i] - mm[i]) / (2 * eps * sc);
    }
  }
  if (st != DM_OK)
    goto done;
  /* Omega(mu) = [[B(mu), I], [-I, 0]], B_ij = mu . [e_i, e_j] */
  for (k = 0; k < 2; k++) {
    const double *mu = k ? mu1 : mu0;
    double *O = k ? O1 : O0;
    for (i = 0; i < n; i++)
      for (j = 0; j < n; j++) {
        double ei[DM_LIE_DIM_MAX] = {0}, ej[DM_LIE_DIM_MAX] = {0}, b[DM_LIE_DIM_MAX], s = 0.0;
        size_t a;
        ei[i] = 1.0;
        ej[j] = 1.0;
        dm_lie_bracket(G, ei, ej, b);
        for (a = 0; a < n; a++)
          s += mu[a] * b[a];
        O[i * m + j] = s;
        O[i * m + n + j] = i == j ? 1.0 : 0.0;
        O[(n + i) * m + j] = i == j ? -1.0 : 0.0;
        O[(n + i) * m + n + j] = 0.0;
      }
  }
  /* D^T O1 D - O0 */
  for (i = 0; i < m; i++)
    for (j = 0; j < m; j++) {
      double s = 0.0;
      size_t a, b2;
      for (a = 0; a < m; a++)
        for (b2 = 0; b2 < m; b2++)
          s += D[a * m + i] * O1[a * m + b2] * D[b2 * m + j];
      worst = fmax(worst, fabs(s - O0[i * m + j]));
    }
  *defect = worst;
done:
  free(D);
  dm_integrator_reset(I);
  return st;
}

int dm_lie_reversal(dm_integrator *I, double h, long n, const double *g0, const double *mu0,
                    double *dev, dm_err *e)
{
  const dm_lie_system *S = dm_lie_system_of(I->sys);
  double g[DM_LIE_NQ_MAX], mu[DM_LIE_DIM_MAX], d = 0.0;
  long k;
  size_t i;
  int st = DM_OK;
  if (S == NULL)
    return dm_err_set(e, DM_EINVAL, "reversal: not a system on a Lie group");
  memcpy(g, g0, S->nq * sizeof *g);
  memcpy(mu, mu0, S->dim * sizeof *mu);
  dm_integrator_reset(I);
  for (k = 0; k < 2 * n && st == DM_OK; k++)
    st = dm_integrator_step(I, k < n ? h : -h, g, mu, g, mu, e);
  dm_integrator_reset(I);
  if (st != DM_OK)
    return st;
  for (i = 0; i < S->dim; i++)
    d = fmax(d, fabs(mu[i] - mu0[i]));
  *dev = dm_lie_dist(S->G, g, g0) + d;
  return DM_OK;
}

static int run_to(const dm_lie_system *S, const char *method, const dm_integ_opts *opts,
                  const double *g0, const double *mu0, double T, double h, double *g, double *mu,
                  dm_err *e)
{
  dm_integrator *I;
  long k, n = lround(T / h);
  int st;
  if (n < 1)
    n = 1;
  h = T / (double)n;
  if ((st = dm_integrator_new(&S->sys, method, opts, &I, e)) != DM_OK)
    return st;
  memcpy(g, g0, S->nq * sizeof *g);
  memcpy(mu, mu0, S->dim * sizeof *mu);
  for (k = 0; k < n && st == DM_OK; k++) {
    if (dm_interrupted())
      st = dm_err_set(e, DM_EINTR, "order estimate: interrupted");
    else
      st = dm_integrator_step(I, h, g, mu, g, mu, e);
  }
  dm_integrator_free(I);
  return st;
}

int dm_lie_order_estimate(const dm_lie_system *S, const char *method, const dm_integ_opts *opts,
                          const double *g0, const double *mu0, double T, const double *h,
                          size_t k, double *err, double *order, dm_err *e)
{
  double gr[DM_LIE_NQ_MAX], mr[DM_LIE_DIM_MAX], g[DM_LIE_NQ_MAX], mu[DM_LIE_DIM_MAX];
  double errs[64], hmin = HUGE_VAL;
  dm_integ_opts ro;
  size_t i, a;
  int st;
  if (k < 2 || k > 64 || !(T > 0.0))
    return dm_err_set(e, DM_EINVAL, "order estimate: needs 2..64 step sizes and T > 0");
  for (i = 0; i < k; i++) {
    if (!(h[i] > 0.0) || !isfinite(h[i]))
      return dm_err_set(e, DM_EINVAL, "order estimate: step size %zu is not > 0", i + 1);
    hmin = fmin(hmin, h[i]);
  }
  dm_integ_opts_init(&ro);
  ro.stages = 6;
  if ((st = run_to(S, "lie:gauss", &ro, g0, mu0, T, hmin / 8.0, gr, mr, e)) != DM_OK)
    return st;
  for (i = 0; i < k; i++) {
    double d = 0.0;
    if ((st = run_to(S, method, opts, g0, mu0, T, h[i], g, mu, e)) != DM_OK)
      return st;
    for (a = 0; a < S->dim; a++)
      d = fmax(d, fabs(mu[a] - mr[a]));
    errs[i] = dm_lie_dist(S->G, g, gr) + d;
    if (err)
      err[i] = errs[i];
  }
  *order = dm_integrator_order_fit(h, errs, k);
  return DM_OK;
}

/* }====================================================================== */
