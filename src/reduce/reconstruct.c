/* reconstruct.c -- between the full and the reduced phase spaces:
 * projection (q, p) -> (x, s = p_x - mu^T A(x)), mu = p_theta (the momentum
 * shift pi_mu of thesis §2.2/§2.5), the lift back, reconstruction of a full
 * trajectory from a reduced one (theta advanced by the group increments the
 * reduced integrator reports: h sum b_j Thetadot_j on the Hamiltonian side,
 * psi_mu(x_k, x_{k+1}) on the Lagrangian side), and the split of the group
 * advance over a closed shape loop into dynamic and geometric phases. */
#include <config.h>
#include "core/numfmt.h"
#include "reduce/routh_impl.h"
#include "core/interrupt.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* scratch layout of red->scratch for this file */
typedef struct scr {
  double *par2, *tin, *tout, *twork, *pb, *fwork;
} scr;

static scr carve(dm_routh *red)
{
  scr S;
  S.par2 = red->scratch;
  S.tin = S.par2 + red->np;
  S.tout = S.tin + 2 * red->s;
  S.twork = S.tout + red->info.nout + 3 * red->s;
  S.pb = S.twork + red->nwork;
  S.fwork = S.pb + red->n;
  return S;
}

/* muA(x) and the inertia test with momentum mu (NULL: red's). */
static int shift_at(dm_routh *red, scr *S, const double *x, const double *mu, double *a, dm_err *e)
{
  size_t s = red->s, r = red->r, i;
  double lmin, lmax;
  char bx[200];
  if (red->general) {          /* no connection: no momentum shift */
    memset(a, 0, s * sizeof(double));
    return DM_OK;
  }
  memcpy(S->par2, red->par, red->np * sizeof(double));
  if (mu)
    memcpy(S->par2 + red->npar, mu, r * sizeof(double));
  dm_rprog_run(&red->inertia, x, S->par2, S->tout, S->twork);
  for (i = 0; i < r * r; i++)
    if (!isfinite(S->tout[i]))
      return dm_err_set(e, DM_ESINGULAR, "the locked inertia is not finite at x = %s",
                        dm_num_format_vec(bx, sizeof bx, x, s));
  dm_routh_sym_eig(S->tout, r, &lmin, &lmax);
  if (!(lmin > 1e-14 * fmax(lmax, 1e-300)) || !(lmax > 0.0))
    return dm_err_set(e, DM_ESINGULAR, "the locked inertia I(x) is singular at x = %s (smallest "
                      "eigenvalue %.3g): the symmetry group does not act freely there",
                      dm_num_format_vec(bx, sizeof bx, x, s), lmin);
  memcpy(S->tin, x, s * sizeof(double));
  memset(S->tin + s, 0, s * sizeof(double));
  dm_rprog_run(&red->gyro_r, S->tin, S->par2, S->tout, S->twork);
  for (i = 0; i < s; i++) {
    if (!isfinite(S->tout[i]))
      return dm_err_set(e, DM_EDOM, "mu^T A is not finite at x = %s", dm_num_format_vec(bx, sizeof bx, x, s));
    a[i] = S->tout[i];
  }
  return DM_OK;
}

int dm_routh_project(dm_routh *red, const double *q, const double *p, double *x, double *s_,
                     double *mu, double *theta, dm_err *e)
{
  scr S = carve(red);
  size_t s = red->s, r = red->r, i, a;
  double muv[DM_ROUTH_RMAX], *xx = S.pb, *aa = S.pb + s;
  int st;
  if (red->n < 2 * s) {       /* pb has n entries; need 2 s */
    aa = S.fwork;
  }
  for (a = 0; a < r; a++) {
    muv[a] = p[red->cyc[a]];
    if (!isfinite(muv[a]))
      return dm_err_set(e, DM_EINVAL, "the momentum p_%zu is not finite", red->cyc[a] + 1);
  }
  dm_routh_split(red, q, NULL, xx);
  if ((st = shift_at(red, &S, xx, muv, aa, e)) != DM_OK)
    return st;
  if (s_)
    for (i = 0; i < s; i++)
      s_[i] = p[red->shape[i]] - aa[i];
  if (mu)
    memcpy(mu, muv, r * sizeof(double));
  if (theta)
    dm_routh_split(red, q, theta, NULL);
  if (x)
    memcpy(x, xx, s * sizeof(double));
  return DM_OK;
}

int dm_routh_project_qv(dm_routh *red, const double *q, const double *v, double *x, double *s_,
                        double *mu, double *theta, dm_err *e)
{
  size_t n = red->n;
  double *p = malloc(3 * n * sizeof(double) + red->fsys.work_size);
  dm_lag_out o;
  int st;
  if (p == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  memset(&o, 0, sizeof o);
  o.Lv = p;
  st = red->fsys.lagrangian(red->fsys.data, q, v, red->fsys.par, DM_LAG_V, &o, p + n);
  if (st != 0)
    st = dm_err_set(e, DM_EDOM, "L is outside its domain at this state");
  else
    st = dm_routh_project(red, q, p, x, s_, mu, theta, e);
  free(p);
  return st;
}

int dm_routh_lift(dm_routh *red, const double *theta, const double *x, const double *s_,
                  double *q, double *p, dm_err *e)
{
  scr S = carve(red);
  size_t s = red->s, r = red->r, i, a;
  double *aa = S.fwork;
  int st;
  if (q)
    dm_routh_join(red, theta, x, q);
  if (p == NULL)
    return DM_OK;
  if ((st = shift_at(red, &S, x, NULL, aa, e)) != DM_OK)
    return st;
  for (a = 0; a < r; a++)
    p[red->cyc[a]] = red->par[red->npar + a];
  for (i = 0; i < s; i++)
    p[red->shape[i]] = s_[i] + aa[i];
  return DM_OK;
}

int dm_routh_momentum(dm_routh *red, const double *x, const double *xdot, double *s_, dm_err *e)
{
  size_t d = red->s;
  double *w = red->lscratch + 3 * d + d * d;
  dm_lag_out o;
  memset(&o, 0, sizeof o);
  o.Lv = s_;
  if (red->rsys.lagrangian(red->rsys.data, x, xdot, red->par, DM_LAG_V, &o, w) != 0)
    return dm_err_set(e, DM_EDOM, "the Routhian is outside its domain at this state");
  return DM_OK;
}

int dm_routh_velocity(dm_routh *red, const double *x, const double *s_, double *xdot, dm_err *e)
{
  size_t d = red->s, i;
  double *z = red->lscratch, *Lv = z + d, *M = z + 3 * d, *w = M + d * d;
  dm_lag_out o;
  if (red->general)
    return dm_routh_general_velocity(red, x, s_, xdot, e);
  memset(&o, 0, sizeof o);
  memset(z, 0, d * sizeof(double));
  o.Lv = Lv;
  o.Lvv = M;
  if (red->rsys.lagrangian(red->rsys.data, x, z, red->par, DM_LAG_V | DM_LAG_VV, &o, w) != 0)
    return dm_err_set(e, DM_EDOM, "the Routhian is outside its domain at this state");
  if (dm_rlu_factor(&red->lu_s, M, d) != DM_OK)
    return dm_err_set(e, DM_ESINGULAR, "the reduced kinetic matrix Mtilde is singular here");
  for (i = 0; i < d; i++)
    xdot[i] = s_[i] - Lv[i];
  dm_rlu_solve(&red->lu_s, M, d, xdot);
  return DM_OK;
}

/* {==== reconstruction ===================================================== */

/* full velocity from (x, s): xdot from the reduced Legendre map, thetadot =
 * I^{-1} mu - A xdot */
static int full_velocity(dm_routh *red, const double *x, const double *s_, double *xd, double *v,
                         dm_err *e)
{
  scr S = carve(red);
  size_t d = red->s, r = red->r;
  double thd[DM_ROUTH_RMAX];
  int st = dm_routh_velocity(red, x, s_, xd, e);
  if (st != DM_OK)
    return st;
  if (red->general) {
    if (dm_routh_general_thetadot(red, x, xd, red->par, thd, S.twork))
      return dm_err_set(e, DM_EDOM, "J = mu has no solution thetadot at this state");
    dm_routh_join(red, thd, xd, v);
    return DM_OK;
  }
  memcpy(S.tin, x, d * sizeof(double));
  memcpy(S.tin + d, xd, d * sizeof(double));
  dm_rprog_run(&red->thd, S.tin, red->par, S.tout, S.twork);
  memcpy(thd, S.tout, r * sizeof(double));
  dm_routh_join(red, thd, xd, v);
  return DM_OK;
}

int dm_routh_lift_state(dm_routh *red, const double *theta, const double *x, const double *s_,
                        double *q, double *p, double *v, dm_err *e)
{
  size_t d = red->s;
  double xd[64];
  int st = dm_routh_lift(red, theta, x, s_, q, p, e);
  if (st != DM_OK || v == NULL)
    return st;
  if (d > 64)
    return dm_err_set(e, DM_EUNSUP, "lift: more than 64 shape coordinates");
  return full_velocity(red, x, s_, xd, v, e);
}

/* A trajectory of another system with as many coordinates (Kepler's x, y
 * taken for r, z) was reconstructed without a word: the coordinate names
 * must be the shape coordinates', and a trajectory that says which system
 * it came from must come from this reduced system. */
static int check_origin(const dm_routh *red, const dm_traj *rt, dm_err *e)
{
  const char *from = dm_traj_meta_get(rt, "system");
  for (size_t i = 0; i < red->s; i++)
    if (strcmp(dm_traj_coord(rt, i), red->names[i]) != 0)
      return dm_err_set(e, DM_EINVAL, "the reduced trajectory's coordinate %zu is '%.60s' "
                        "where this reduction's shape coordinate is '%.60s' (a trajectory "
                        "of another system?)", i + 1, dm_traj_coord(rt, i), red->names[i]);
  if (from != NULL && red->sys.name != NULL && strcmp(from, red->sys.name) != 0)
    return dm_err_set(e, DM_EINVAL, "the trajectory comes from system '%.100s', not from "
                      "'%.100s'%s", from, red->sys.name,
                      red->fsys.name != NULL && strcmp(from, red->fsys.name) == 0
                      ? " (reconstruct takes a run of the reduced system)" : "");
  return DM_OK;
}

int dm_routh_reconstruct(dm_routh *red, dm_integrator *I, double h, const dm_traj *rt,
                         const double *theta0, dm_traj **out, dm_err *e)
{
  size_t d = red->s, r = red->r, n = red->n, len, k, i, jq[64], jp[64], jv[64];
  double *buf = NULL, *x, *s_, *xw, *sw, *q, *p, *v, *xd, th[DM_ROUTH_RMAX];
  dm_traj *T = NULL;
  int st = DM_OK, use_p = 1;
  char key[64];
  *out = NULL;
  dm_routh *owner = NULL;
  if (!dm_routh_is_integrator(I) || !dm_routh_of_system(I->sys, &owner) || owner != red)
    return dm_err_set(e, DM_EINVAL, "the integrator must be a reduced integrator of this "
                      "reduction");
  if (rt == NULL || dm_traj_ncoords(rt) != d || d > 64)
    return dm_err_set(e, DM_EINVAL, "the reduced trajectory must have the %zu shape "
                      "coordinates, got %zu", d, rt != NULL ? dm_traj_ncoords(rt) : 0);
  if ((st = check_origin(red, rt, e)) != DM_OK)
    return st;
  len = dm_traj_len(rt);
  for (i = 0; i < d; i++) {
    jq[i] = dm_traj_qcol(rt, i);
    jp[i] = dm_traj_pcol(rt, i);
    jv[i] = dm_traj_vcol(rt, i);
    if (jp[i] == DM_TRAJ_NONE)
      use_p = 0;
    if (!use_p && jv[i] == DM_TRAJ_NONE)
      return dm_err_set(e, DM_EINVAL, "the reduced trajectory needs momentum (p) or "
                        "velocity (v) columns");
  }
  if ((buf = malloc((6 * d + 3 * n) * sizeof(double))) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  x = buf; s_ = x + d; xw = s_ + d; sw = xw + d; xd = sw + d; q = xd + 2 * d; p = q + n; v = p + n;
  T = dm_traj_alloc(n, red->fsys.coords, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, e);
  if (T == NULL) {
    free(buf);
    return e ? e->status : DM_ENOMEM;
  }
  for (k = 0; k < dm_traj_meta_count(rt) && st == DM_OK; k++) {
    const char *kk, *vv;
    if (dm_traj_meta_at(rt, k, &kk, &vv) == DM_OK)
      st = dm_traj_meta_set(T, kk, vv, e);
  }
  if (st == DM_OK && red->fsys.name)
    st = dm_traj_meta_set(T, "system", red->fsys.name, e);
  if (st == DM_OK)
    st = dm_traj_meta_set(T, "reconstructed", dm_routh_integrator_kind(I), e);
  if (st == DM_OK)
    st = dm_traj_reserve(T, len, e);
  for (i = 0; i < r; i++)
    th[i] = theta0 ? theta0[i] : 0.0;
  for (k = 0; st == DM_OK && k < len; k++) {
    const double *tc = dm_traj_col(rt, 0);
    if (dm_interrupted()) {
      st = dm_err_set(e, DM_EINTR, "reconstruct: interrupted at sample %zu", k + 1);
      break;
    }
    for (i = 0; i < d; i++) {
      x[i] = dm_traj_col(rt, jq[i])[k];
      s_[i] = use_p ? dm_traj_col(rt, jp[i])[k] : dm_traj_col(rt, jv[i])[k];
    }
    if (!use_p) {                  /* s = dR/dxdot (x, v) */
      memcpy(xd, s_, d * sizeof(double));
      if ((st = dm_integrator_momentum(I, x, xd, s_, e)) != DM_OK)
        break;
    }
    if (k > 0) {
      double dt = tc[k] - tc[k - 1], hh;
      long nsub = h != 0.0 ? lround(fabs(dt / h)) : 1, j;
      if (nsub < 1)
        nsub = 1;
      hh = dt / (double)nsub;
      for (i = 0; i < d; i++) {
        xw[i] = dm_traj_col(rt, jq[i])[k - 1];
        sw[i] = use_p ? dm_traj_col(rt, jp[i])[k - 1] : 0.0;
      }
      if (!use_p) {
        for (i = 0; i < d; i++)
          xd[i] = dm_traj_col(rt, jv[i])[k - 1];
        if ((st = dm_integrator_momentum(I, xw, xd, sw, e)) != DM_OK)
          break;
      }
      if ((st = dm_routh_integrator_set_theta(I, th, e)) != DM_OK)
        break;
      for (j = 0; j < nsub && st == DM_OK; j++)
        st = dm_integrator_step(I, hh, xw, sw, xw, sw, e);
      if (st == DM_OK)
        st = dm_routh_integrator_theta(I, th, e);
      if (st != DM_OK)
        break;
    }
    if ((st = dm_routh_lift(red, th, x, s_, q, p, e)) != DM_OK ||
        (st = full_velocity(red, x, s_, xd, v, e)) != DM_OK)
      break;
    st = dm_traj_append(T, tc[k], q, p, v, NULL, e);
  }
  if (st == DM_OK) {
    snprintf(key, sizeof key, "%zu", r);
    st = dm_traj_meta_set(T, "group_dim", key, e);
  }
  free(buf);
  if (st != DM_OK && (st != DM_EINTR || dm_traj_len(T) == 0)) {
    dm_traj_free(T);
    return st;
  }
  *out = T;            /* DM_EINTR: the samples reconstructed so far */
  return st;
}

int dm_routh_phase(dm_routh *red, const dm_traj *loop, double *dyn, double *geo, double *gap,
                   dm_err *e)
{
  scr S = carve(red);
  size_t d = red->s, r = red->r, len, k, i, a, jq[64];
  const double *t;
  double xb[64], dx[64], g = 0.0;
  if (red->general)
    return dm_err_set(e, DM_EUNSUP, "phase: L is not mechanical, there is no mechanical "
                      "connection to split the phase with");
  if (loop == NULL || dm_traj_ncoords(loop) != d || d > 64)
    return dm_err_set(e, DM_EINVAL, "phase: the loop must be a trajectory of the %zu shape "
                      "coordinates", d);
  len = dm_traj_len(loop);
  if (len < 2)
    return dm_err_set(e, DM_EINVAL, "phase: the loop needs at least 2 samples");
  for (i = 0; i < d; i++)
    jq[i] = dm_traj_qcol(loop, i);
  for (a = 0; a < r; a++)
    dyn[a] = geo[a] = 0.0;
  t = dm_traj_col(loop, 0);
  for (k = 0; k + 1 < len; k++) {
    for (i = 0; i < d; i++) {
      double x0 = dm_traj_col(loop, jq[i])[k], x1 = dm_traj_col(loop, jq[i])[k + 1];
      xb[i] = 0.5 * (x0 + x1);
      dx[i] = x1 - x0;
    }
    dm_rprog_run(&red->conn, xb, red->par, S.tout, S.twork);
    for (a = 0; a < r; a++) {
      double acc = 0.0;
      if (!isfinite(S.tout[a]))
        return dm_err_set(e, DM_ESINGULAR, "phase: singular locked inertia on the loop (segment %zu)",
                          k + 1);
      for (i = 0; i < d; i++)
        acc += S.tout[r + a * d + i] * dx[i];
      dyn[a] += (t[k + 1] - t[k]) * S.tout[a];
      geo[a] -= acc;
    }
  }
  for (i = 0; i < d; i++)
    g = fmax(g, fabs(dm_traj_col(loop, jq[i])[len - 1] - dm_traj_col(loop, jq[i])[0]));
  if (gap)
    *gap = g;
  return DM_OK;
}
