/* lie_run.c -- runs of integrators on systems on groups into trajectories,
 * and their structure diagnostics: Legendre maps, energy, spatial momentum,
 * Casimirs, the symplecticity defect on T*G, time reversal, the empirical
 * order (lie_system.h).  The run loop is that of core/run.c for a state
 * (g, mu) whose two parts have different sizes (nq stored numbers, dim
 * momenta), which the vector-space run driver does not describe. */
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

/* {==== runs ============================================================= */

typedef struct lrun {
  dm_integrator *I;
  const dm_lie_system *S;
  dm_traj *tr;
  double *xi, *extra;
  int have_xi;
} lrun;

static int record(lrun *r, double t, const double *g, const double *mu, dm_err *e)
{
  const size_t n = r->S->dim;
  double *x = r->extra;
  int st;
  if ((st = dm_integrator_velocity(r->I, g, mu, r->xi, r->have_xi, e)) != DM_OK)
    return st;
  r->have_xi = 1;
  memcpy(x, mu, n * sizeof *x);
  memcpy(x + n, r->xi, n * sizeof *x);
  if ((st = dm_integrator_energy(r->I, g, r->xi, x + 2 * n, e)) != DM_OK)
    return st;
  dm_lie_spatial_momentum(r->S->G, g, mu, x + 2 * n + 1);
  return dm_traj_append(r->tr, t, g, NULL, NULL, x, e);
}

static int all_finite(const double *x, size_t n)
{
  double s = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    s += 0.0 * x[i];
  return s == 0.0;
}

static dm_traj *new_traj(const dm_integrator *I, const dm_lie_system *S, double h, dm_err *e)
{
  dm_traj *tr = dm_traj_alloc(S->nq, dm_lie_system_gnames(S), 0, e);
  char name[32];
  size_t i;
  int st = DM_OK;
  if (tr == NULL)
    return NULL;
  for (i = 0; i < S->dim && st == DM_OK; i++)
    st = dm_traj_add_column(tr, S->munames[i], DM_TRAJ_DATA, NULL, 0, e);
  for (i = 0; i < S->dim && st == DM_OK; i++)
    st = dm_traj_add_column(tr, S->xinames[i], DM_TRAJ_DATA, NULL, 0, e);
  if (st == DM_OK)
    st = dm_traj_add_column(tr, DM_TRAJ_ENERGY, DM_TRAJ_DIAG, NULL, 0, e);
  for (i = 0; i < S->dim && st == DM_OK; i++) {
    snprintf(name, sizeof name, "%s%zu", DM_TRAJ_MOMENTUM, i + 1);
    st = dm_traj_add_column(tr, name, DM_TRAJ_DIAG, NULL, 0, e);
  }
  if (st == DM_OK)
    st = dm_traj_meta_set(tr, "system", S->name, e);
  if (st == DM_OK)
    st = dm_traj_meta_set(tr, "method", I->name, e);
  if (st == DM_OK && dm_integrator_stages_chosen(I))
    st = dm_traj_meta_set_number(tr, "stages", I->stages, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "h", h, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "order", I->order, e);
  if (st == DM_OK)
    st = dm_traj_meta_set(tr, "space", S->G->name, e);
  if (st == DM_OK)
    st = dm_traj_meta_set_number(tr, "reduced", S->reduced, e);
  for (i = 0; i < S->npar && st == DM_OK; i++) {
    char key[160];
    snprintf(key, sizeof key, "param.%s", S->pnames[i]);
    st = dm_traj_meta_set_number(tr, key, S->parv[i], e);
  }
  if (st != DM_OK) {
    dm_traj_free(tr);
    return NULL;
  }
  return tr;
}

int dm_lie_run(dm_integrator *I, double *g, double *mu, const dm_lie_run_opts *o, dm_traj **out,
               dm_err *e)
{
  const dm_lie_system *S = dm_lie_system_of(I->sys);
  double g1[DM_LIE_NQ_MAX], mu1[DM_LIE_DIM_MAX], xi[DM_LIE_DIM_MAX];
  double extra[3 * DM_LIE_DIM_MAX + 1], h = o->h;
  long nsteps = o->nsteps, k = 0, last = -1;
  lrun r;
  dm_err le;
  int st = DM_OK;
  char tb[DM_NUM_BUFSIZE];
  *out = NULL;
  if (S == NULL)
    return dm_err_set(e, DM_EINVAL, "run: not a system on a Lie group");
  if (!isfinite(h) || h == 0.0 || !isfinite(o->t0) || o->every < 1)
    return dm_err_set(e, DM_EINVAL, "run: need a finite h != 0, a finite t0 and every >= 1");
  if (nsteps < 0) {
    double x = (o->t_end - o->t0) / h;
    if (!isfinite(x) || x < -0.5 || x > 9e15)
      return dm_err_set(e, DM_EINVAL, "run: the final time cannot be reached from t0 with h");
    nsteps = lround(x);
  }
  if (!all_finite(g, S->nq) || !all_finite(mu, S->dim))
    return dm_err_set(e, DM_EINVAL, "run: the initial state contains NaN or Inf");
  if ((r.tr = new_traj(I, S, h, e)) == NULL)
    return e ? e->status : DM_ENOMEM;
  r.I = I;
  r.S = S;
  r.xi = xi;
  r.extra = extra;
  r.have_xi = 0;
  dm_err_clear(&le);
  if (dm_traj_reserve(r.tr, (size_t)(nsteps / o->every + 2), &le) != DM_OK)
    dm_err_clear(&le);                   /* grows while appending instead */
  if ((st = record(&r, o->t0, g, mu, e)) != DM_OK) {
    dm_traj_free(r.tr);
    return st;
  }
  last = 0;
  for (k = 0; k < nsteps; k++) {
    if (dm_interrupted()) {
      st = DM_EINTR;
      dm_num_format(tb, sizeof tb, o->t0 + (double)k * h);
      dm_err_set(e, st, "interrupted after step %ld of %ld (t = %s); the trajectory up to there "
                 "is kept", k, nsteps, tb);
      break;
    }
    if ((st = dm_integrator_step(I, h, g, mu, g1, mu1, &le)) == DM_OK &&
        (!all_finite(g1, S->nq) || !all_finite(mu1, S->dim)))
      st = dm_err_set(&le, DM_EDOM, "the state became non-finite");
    if (st != DM_OK) {
      dm_num_format(tb, sizeof tb, o->t0 + (double)k * h);
      dm_err_set(e, st, "step %ld of %ld from t = %s failed: %s; the trajectory up to there is "
                 "kept", k + 1, nsteps, tb, le.msg);
      break;
    }
    memcpy(g, g1, S->nq * sizeof *g);
    memcpy(mu, mu1, S->dim * sizeof *mu);
    if ((k + 1) % o->every == 0 || k + 1 == nsteps) {
      if ((st = record(&r, o->t0 + (double)(k + 1) * h, g, mu, &le)) != DM_OK) {
        dm_err_set(e, st, "after step %ld: %s; the trajectory up to there is kept", k + 1,
                   le.msg);
        k++;
        last = k;
        break;
      }
      last = k + 1;
    }
  }
  if (st != DM_OK && last != k) {
    dm_err ign;
    if (record(&r, o->t0 + (double)k * h, g, mu, &ign) == DM_OK)
      last = k;
  }
  dm_traj_meta_set_number(r.tr, "steps", (double)k, NULL);
  dm_traj_meta_set_number(r.tr, "status", st, NULL);
  if (st != DM_OK)
    dm_traj_meta_set(r.tr, "message", e ? e->msg : dm_strstatus(st), NULL);
  *out = r.tr;
  return st;
}

int dm_lie_traj_group(const dm_traj *tr, dm_lie_group **G, dm_err *e)
{
  const char *name = dm_traj_meta_get(tr, "space");
  *G = NULL;
  if (name == NULL)
    return dm_err_set(e, DM_EINVAL, "the trajectory is not of a system on a Lie group (no "
                      "'space' in its metadata)");
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
