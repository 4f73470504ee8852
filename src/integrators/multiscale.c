/* multiscale.c -- the multiscale variational integrator: a Galerkin
 * discrete action over curves with oscillatory bubbles in the fast
 * coordinates, integrated by the Filon-Lobatto phase-sampled rule, solved
 * in nodal form by Newton with the exact Hessian (doc/beyond-fixed-steps.md §4.3);
 * the estimate of the fast frequency.  See multiscale.h. */
#include <config.h>
#include "integrators/multiscale.h"
#include "integrators/integ_impl.h"
#include "core/interrupt.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_fft_complex.h>

#define NF 5            /* local functions of a fast coordinate: q0, q1, A, B, C */
#define NS 4            /* of a slow one: q0, q1, Q(1/3), Q(2/3) */

typedef struct ms_state {
  size_t n, nu, K, P, nint, ndof, nx;
  int ready;                   /* layout and omega fixed */
  unsigned char *fast;         /* n flags */
  size_t *ioff;                /* n: first internal DOF of each coordinate */
  double omega, h;             /* the weights below are for this (omega, h) */
  double *c, *W;               /* nu Lobatto nodes; P weights */
  double *valF, *derF;         /* P x NF */
  double *valS, *derS;         /* nu x NS */
  double *q, *v, *Lq, *Lv, *Lvv, *Lvq, *Lqq;   /* at one point */
  double *g, *H, *J, *R, *X, *Xp;   /* ndof, ndof^2, nx^2, nx, ndof, ndof */
  double *v0;
  size_t *perm;
  int have_prev;
  void *work;
} ms_state;

static const char *const ms_options[] = {"h", "tol", "maxiter", "omega", "fast", "nodes",
                                         "phases", NULL};

static void ms_free(dm_integrator *I)
{
  ms_state *S = I->state;
  if (S == NULL)
    return;
  free(S->fast);
  free(S->ioff);
  free(S->c);
  free(S->perm);
  free(S->work);
  free(S);
  I->state = NULL;
}

/* the slow basis: cubic Lagrange on 0, 1/3, 2/3, 1, ordered q0, q1, Q1, Q2 */
static const double snode[NS] = {0.0, 1.0, 1.0 / 3.0, 2.0 / 3.0};

static void slow_basis(double tau, double *val, double *der)
{
  for (int a = 0; a < NS; a++) {
    double v = 1.0, d = 0.0;
    for (int b = 0; b < NS; b++) {
      if (b == a)
        continue;
      double f = 1.0 / (snode[a] - snode[b]), p = 1.0;
      for (int k = 0; k < NS; k++)            /* derivative: sum of products */
        if (k != a && k != b)
          p *= (tau - snode[k]) / (snode[a] - snode[k]);
      d += f * p;
      v *= (tau - snode[b]) * f;
    }
    val[a] = v;
    der[a] = d;
  }
}

/* the fast basis at (tau, phi) for w h = wh (derivatives in t: / h) */
static void fast_basis(double tau, double phi, double wh, double h, double *val, double *der)
{
  double s = sin(phi), co = cos(phi), sw = sin(wh), cw = cos(wh), w = wh / h;
  val[0] = 1.0 - tau;          der[0] = -1.0 / h;
  val[1] = tau;                der[1] = 1.0 / h;
  val[2] = tau * (1.0 - tau);  der[2] = (1.0 - 2.0 * tau) / h;
  val[3] = s - tau * sw;       der[3] = w * co - sw / h;
  val[4] = co - (1.0 - tau) - tau * cw;
  der[4] = -w * s + (1.0 - cw) / h;
}

/* weights and basis tables for (omega, h) */
static int ms_tables(ms_state *S, double h, dm_err *e)
{
  size_t i, j;
  int st;
  if (S->h == h)
    return DM_OK;
  if ((st = dm_filon_phase_weights(S->nu, S->c, S->K, h, S->omega, S->W, e)) != DM_OK)
    return st;
  for (i = 0; i < S->nu; i++) {
    slow_basis(S->c[i], S->valS + i * NS, S->derS + i * NS);
    for (j = 0; j < S->K; j++)
      fast_basis(S->c[i], 2.0 * M_PI * (double)j / (double)S->K, S->omega * h, h,
                 S->valF + (i * S->K + j) * NF, S->derF + (i * S->K + j) * NF);
    for (size_t a = 0; a < NS; a++)
      S->derS[i * NS + a] /= h;
  }
  S->h = h;
  return DM_OK;
}

/* global index of local function f of coordinate c */
static inline size_t dof(const ms_state *S, size_t c, size_t f)
{
  return f == 0 ? c : f == 1 ? S->n + c : S->ioff[c] + f - 2;
}

/* The layout of the internal DOFs (fast flags set). */
static void ms_layout(ms_state *S)
{
  size_t c, k = 2 * S->n;
  for (c = 0; c < S->n; c++) {
    S->ioff[c] = k;
    k += S->fast[c] ? NF - 2 : NS - 2;
  }
  S->ndof = k;
  S->nint = k - 2 * S->n;
  S->nx = S->n + S->nint;
}

/* S, its gradient g and Hessian H in all DOFs at X (h fixed). */
static int ms_eval(dm_integrator *I, ms_state *S, dm_err *e)
{
  size_t n = S->n, nn = n * n, nd = S->ndof, i, j, c, d, f, ff;
  int st;
  memset(S->g, 0, nd * sizeof *S->g);
  memset(S->H, 0, nd * nd * sizeof *S->H);
  for (i = 0; i < S->nu; i++)
    for (j = 0; j < S->K; j++) {
      size_t p = i * S->K + j;
      const double *vf = S->valF + p * NF, *df = S->derF + p * NF;
      const double *vs = S->valS + i * NS, *ds = S->derS + i * NS;
      double w = S->W[p];
      for (c = 0; c < n; c++) {
        const double *va = S->fast[c] ? vf : vs, *da = S->fast[c] ? df : ds;
        size_t nf = S->fast[c] ? NF : NS;
        double qv = 0.0, vv = 0.0;
        for (f = 0; f < nf; f++) {
          double x = S->X[dof(S, c, f)];
          qv += x * va[f];
          vv += x * da[f];
        }
        S->q[c] = qv;
        S->v[c] = vv;
      }
      dm_lag_out o = {0, S->Lq, S->Lv, S->Lvv, S->Lvq, S->Lqq};
      if ((st = dm_eval_lag(I->sys, S->q, S->v, DM_LAG_ALL, &o, S->work, e)) != DM_OK)
        return st;
      for (c = 0; c < n; c++) {
        const double *va = S->fast[c] ? vf : vs, *da = S->fast[c] ? df : ds;
        size_t nf = S->fast[c] ? NF : NS;
        for (f = 0; f < nf; f++) {
          size_t r = dof(S, c, f);
          S->g[r] += w * (S->Lq[c] * va[f] + S->Lv[c] * da[f]);
          for (d = 0; d < n; d++) {
            const double *vb = S->fast[d] ? vf : vs, *db = S->fast[d] ? df : ds;
            size_t mf = S->fast[d] ? NF : NS;
            /* Lqq[c][d], Lqv[c][d] = Lvq[d][c], Lvq[c][d], Lvv[c][d] */
            double qq = S->Lqq[c * n + d], qv = S->Lvq[d * n + c], vq = S->Lvq[c * n + d],
                   vv = S->Lvv[c * n + d];
            for (ff = 0; ff < mf; ff++)
              S->H[r * nd + dof(S, d, ff)] += w * (va[f] * (vb[ff] * qq + db[ff] * qv)
                                                   + da[f] * (vb[ff] * vq + db[ff] * vv));
          }
        }
      }
      (void)nn;
    }
  return DM_OK;
}

/* rows q0 and internals, columns q1 and internals */
static inline size_t row_of(const ms_state *S, size_t r)
{
  return r < S->n ? r : S->n + r;
}

/* Newton on X[n .. ndof) for p0 + dS/dq0 = 0, dS/d(internal) = 0. */
static int ms_newton(dm_integrator *I, ms_state *S, const double *p0, dm_err *e)
{
  size_t n = S->n, nx = S->nx, nd = S->ndof, r, u;
  dm_newton_test stop = DM_NEWTON_TEST_INIT;
  double d = HUGE_VAL, tol = I->opt.tol;
  int it, st;
  for (it = 0; it < I->opt.maxiter; it++) {
    double xs;
    if ((st = ms_eval(I, S, e)) != DM_OK)
      return st;
    for (r = 0; r < nx; r++) {
      size_t rr = row_of(S, r);
      S->R[r] = S->g[rr] + (r < n ? p0[r] : 0.0);
      for (u = 0; u < nx; u++)
        S->J[r * nx + u] = S->H[rr * nd + n + u];
    }
    if ((st = dm_smalllu_factor(S->J, nx, S->perm)) != DM_OK)
      return dm_err_set(e, st == DM_ESINGULAR ? DM_ESINGULAR : DM_EDOM,
                        "multiscale: %s Newton matrix (h = %g, omega = %g)",
                        st == DM_ESINGULAR ? "singular" : "non-finite", S->h, S->omega);
    dm_smalllu_solve(S->J, nx, S->perm, S->R);
    for (u = 0; u < nx; u++)
      S->X[n + u] -= S->R[u];
    xs = dm_norm_inf(S->X, nd);
    d = dm_norm_inf(S->R, nx) / (xs > 0 ? xs : 1.0);
    if (!isfinite(d))
      return dm_err_set(e, DM_EDOM, "multiscale: the Newton update is not finite");
    I->stats.iters = it + 1;
    if (dm_newton_done(&stop, d, tol))
      break;
  }
  I->stats.residual = d;
  I->stats.tol = tol;
  I->stats.iters_total += I->stats.iters;
  if (it >= I->opt.maxiter)
    return dm_err_set(e, DM_ENOCONV, "multiscale: Newton did not converge in %d iterations "
                      "(update %.3g, tol %.3g)", it, d, tol);
  return ms_eval(I, S, e);          /* g at the solution: p1 */
}

/* The guess: the previous step's curve continued (its span is invariant
 * under time shifts), else the straight line through v(q0, p0). */
static int ms_guess(dm_integrator *I, ms_state *S, const double *q0, const double *p0, double h,
                    dm_err *e)
{
  size_t n = S->n, c;
  int cont = S->have_prev && dm_same(q0, S->Xp + n, n);
  if (cont) {
    double wh = S->omega * h, cw = cos(wh), sw = sin(wh);
    for (c = 0; c < n; c++) {
      double *o = S->Xp, x0 = o[c], x1 = o[n + c];
      if (S->fast[c]) {
        double A = o[S->ioff[c]], B = o[S->ioff[c] + 1], C = o[S->ioff[c] + 2], val[NF], der[NF];
        fast_basis(2.0, 2.0 * wh, wh, h, val, der);
        S->X[n + c] = x0 * val[0] + x1 * val[1] + A * val[2] + B * val[3] + C * val[4];
        S->X[S->ioff[c]] = A;
        S->X[S->ioff[c] + 1] = B * cw - C * sw;
        S->X[S->ioff[c] + 2] = B * sw + C * cw;
      } else {
        double val[NS], der[NS], x[NS] = {x0, x1, o[S->ioff[c]], o[S->ioff[c] + 1]};
        double t3[3] = {2.0, 4.0 / 3.0, 5.0 / 3.0}, y[3];
        for (int k = 0; k < 3; k++) {
          slow_basis(t3[k], val, der);
          y[k] = x[0] * val[0] + x[1] * val[1] + x[2] * val[2] + x[3] * val[3];
        }
        S->X[n + c] = y[0];
        S->X[S->ioff[c]] = y[1];
        S->X[S->ioff[c] + 1] = y[2];
      }
    }
  } else {
    int st = dm_integrator_velocity(I, q0, p0, S->v0, 0, e);
    if (st != DM_OK)
      return st;
    for (c = 0; c < n; c++) {
      S->X[n + c] = q0[c] + h * S->v0[c];
      if (S->fast[c]) {
        S->X[S->ioff[c]] = S->X[S->ioff[c] + 1] = S->X[S->ioff[c] + 2] = 0.0;
      } else {
        S->X[S->ioff[c]] = q0[c] + h * S->v0[c] / 3.0;
        S->X[S->ioff[c] + 1] = q0[c] + 2.0 * h * S->v0[c] / 3.0;
      }
    }
  }
  memcpy(S->X, q0, n * sizeof *q0);
  return DM_OK;
}

/* Fix omega and the fast coordinates from the start (q0, p0). */
static int ms_prepare(dm_integrator *I, ms_state *S, const double *q0, const double *p0,
                      dm_err *e)
{
  size_t n = S->n, c, guess = 0;
  int st;
  S->omega = I->opt.omega;
  if (S->omega == 0.0 || I->opt.fast[0] == '\0') {
    double w;
    if ((st = dm_multiscale_frequency(I->sys, q0, p0, &w, &guess, e)) != DM_OK)
      return st;
    if (S->omega == 0.0)
      S->omega = w;
  }
  memset(S->fast, 0, n);
  if (I->opt.fast[0] == '\0') {
    S->fast[guess] = 1;
  } else {
    const char *s = I->opt.fast;
    while (*s) {
      size_t len = strcspn(s, ", ");
      int found = 0;
      for (c = 0; c < n; c++)
        if (I->sys->coords && strlen(I->sys->coords[c]) == len
            && strncmp(I->sys->coords[c], s, len) == 0)
          found = S->fast[c] = 1;
      if (!found && len > 0)
        return dm_err_set(e, DM_EINVAL, "multiscale: fast = '%s' names no coordinate of '%s'",
                          I->opt.fast, I->sys->name ? I->sys->name : "system");
      s += len;
      s += strspn(s, ", ");
    }
  }
  ms_layout(S);
  S->h = NAN;
  S->have_prev = 0;
  S->ready = 1;
  return DM_OK;
}

static int ms_alloc(dm_integrator *I, dm_err *e)
{
  const dm_system *sys = I->sys;
  size_t n = I->n, nu = (size_t)I->opt.nodes, K = (size_t)I->opt.phases, nmax = 5 * n, nn = n * n;
  ms_state *S;
  int st;
  if (sys->force != NULL || sys->m > 0)
    return dm_err_set(e, DM_EUNSUP, "multiscale: a conservative, unconstrained system is needed "
                      "('%s' has %s)", sys->name ? sys->name : "system",
                      sys->force ? "a force" : "constraints");
  if (nu < 3 || nu > 12 || K < 4 || K > 64)
    return dm_err_set(e, DM_EINVAL, "multiscale: nodes must be in 3..12 and phases in 4..64");
  if (!(I->opt.omega >= 0) || !isfinite(I->opt.omega))
    return dm_err_set(e, DM_EINVAL, "multiscale: omega must be finite and >= 0 (0: estimated)");
  if ((S = calloc(1, sizeof *S)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "multiscale: out of memory");
  I->state = S;
  S->n = n;
  S->nu = nu;
  S->K = K;
  S->P = nu * K;
  S->fast = calloc(n, 1);
  S->c = calloc(nu + S->P * (1 + 2 * NF) + 2 * nu * NS + 4 * n + 3 * nn + nmax + nmax * nmax
                + nmax * nmax + 3 * nmax + n + n, sizeof(double));
  S->perm = calloc(nmax + n, sizeof *S->perm);
  S->work = sys->work_size ? malloc(sys->work_size) : NULL;
  if (S->fast == NULL || S->c == NULL || S->perm == NULL || (sys->work_size && !S->work)) {
    ms_free(I);
    return dm_err_set(e, DM_ENOMEM, "multiscale: out of memory");
  }
  S->W = S->c + nu;
  S->valF = S->W + S->P;
  S->derF = S->valF + S->P * NF;
  S->valS = S->derF + S->P * NF;
  S->derS = S->valS + nu * NS;
  S->q = S->derS + nu * NS;
  S->v = S->q + n;
  S->Lq = S->v + n;
  S->Lv = S->Lq + n;
  S->Lvv = S->Lv + n;
  S->Lvq = S->Lvv + nn;
  S->Lqq = S->Lvq + nn;
  S->g = S->Lqq + nn;
  S->H = S->g + nmax;
  S->J = S->H + nmax * nmax;
  S->R = S->J + nmax * nmax;
  S->X = S->R + nmax;
  S->Xp = S->X + nmax;
  S->v0 = S->Xp + nmax;
  S->ioff = malloc(n * sizeof *S->ioff);
  if (S->ioff == NULL) {
    ms_free(I);
    return dm_err_set(e, DM_ENOMEM, "multiscale: out of memory");
  }
  if ((st = dm_tableau_lobatto_nodes(nu, S->c, e)) != DM_OK) {
    ms_free(I);
    return st;
  }
  I->order = 0;
  I->stages = 0;
  I->flags = DM_INTEG_SYMPLECTIC | DM_INTEG_EXACT_JAC;
  return DM_OK;
}

static int ms_step(dm_integrator *I, double h, const double *q0, const double *p0, double *q1,
                   double *p1, dm_err *e)
{
  ms_state *S = I->state;
  size_t n = S->n;
  int st;
  if (!S->ready && (st = ms_prepare(I, S, q0, p0, e)) != DM_OK)
    return st;
  if (h != S->h) {
    S->have_prev = 0;
    if ((st = ms_tables(S, h, e)) != DM_OK)
      return st;
  }
  if ((st = ms_guess(I, S, q0, p0, h, e)) != DM_OK || (st = ms_newton(I, S, p0, e)) != DM_OK) {
    S->have_prev = 0;
    return st;
  }
  memcpy(q1, S->X + n, n * sizeof *q1);
  memcpy(p1, S->g + n, n * sizeof *p1);
  memcpy(S->Xp, S->X, S->ndof * sizeof *S->X);
  S->have_prev = 1;
  I->stats.steps++;
  return DM_OK;
}

/* A run starts: omega and the fast coordinates follow its start. */
static int ms_begin(dm_integrator *I, double h, double t0, const double *q0, const double *p0,
                    dm_err *e)
{
  ms_state *S = I->state;
  (void)h;
  (void)t0;
  S->ready = 0;
  return ms_prepare(I, S, q0, p0, e);
}

static void ms_reset(dm_integrator *I)
{
  ms_state *S = I->state;
  S->have_prev = 0;
  S->ready = 0;
}

const dm_integrator_type dm_integ_multiscale = {
  .name = "multiscale",
  .summary = "multiscale Galerkin: oscillatory bubbles of a fast frequency omega (given or "
    "estimated) in the fast coordinates, Filon-Lobatto phase-sampled quadrature",
  .order = 0,
  .flags = DM_INTEG_SYMPLECTIC | DM_INTEG_EXACT_JAC,
  .options = ms_options,
  .alloc = ms_alloc,
  .step = ms_step,
  .jacobian = NULL,
  .dlegendre = NULL,
  .advance = NULL,
  .reset = ms_reset,
  .free = ms_free,
  .begin = ms_begin,
};

double dm_multiscale_omega(const dm_integrator *I)
{
  if (I == NULL || I->type != &dm_integ_multiscale)
    return NAN;
  const ms_state *S = I->state;
  return S->ready ? S->omega : NAN;
}

/* {==== the estimate of the fast frequency =============================== */

int dm_multiscale_frequency(const dm_system *sys, const double *q0, const double *p0,
                            double *omega, size_t *coord, dm_err *e)
{
  size_t n = sys->n, nn = n * n, i, j = 0, best = 0, Np = 64 * 32, Nf = 4 * 2048;
  dm_integrator *G = NULL;
  dm_integ_opts o;
  double *buf = NULL, wl, big = -1, h;
  gsl_eigen_gensymmv_workspace *ws = NULL;
  double *z = NULL;             /* Nf complex, interleaved (GSL radix-2 FFT) */
  int st;
  dm_integ_opts_init(&o);
  o.stages = 2;
  if ((st = dm_integrator_new(sys, "gauss", &o, &G, e)) != DM_OK)
    return st;
  buf = calloc(4 * n + 4 * nn + Np + 1, sizeof *buf);
  ws = gsl_eigen_gensymmv_alloc(n);
  if (buf == NULL || ws == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "multiscale: out of memory");
    goto done;
  }
  double *v = buf, *Lq = v + n, *Lv = Lq + n, *ev = Lv + n, *A = ev + n, *B = A + nn,
         *Z = B + nn, *Lvq = Z + nn, *trace = Lvq + nn;
  if ((st = dm_integrator_velocity(G, q0, p0, v, 0, e)) != DM_OK)
    goto done;
  dm_lag_out lo = {0, Lq, Lv, B, Lvq, A};
  void *work = sys->work_size ? malloc(sys->work_size) : NULL;
  st = sys->lagrangian(sys->data, q0, v, sys->par, DM_LAG_ALL, &lo, work);
  free(work);
  if (st != 0) {
    st = dm_err_set(e, DM_EDOM, "multiscale: the Lagrangian fails at the start");
    goto done;
  }
  for (i = 0; i < nn; i++)
    A[i] = -A[i];                    /* -Lqq x = w^2 Lvv x */
  {
    gsl_matrix_view Am = gsl_matrix_view_array(A, n, n), Bm = gsl_matrix_view_array(B, n, n),
                    Zm = gsl_matrix_view_array(Z, n, n);
    gsl_vector_view evv = gsl_vector_view_array(ev, n);
    if (gsl_eigen_gensymmv(&Am.matrix, &Bm.matrix, &evv.vector, &Zm.matrix, ws) != GSL_SUCCESS) {
      st = dm_err_set(e, DM_ESINGULAR, "multiscale: the linearisation at the start has no "
                      "eigenpairs (is d2L/dv2 positive definite?)");
      goto done;
    }
    for (i = 0; i < n; i++)
      if (ev[i] > big) {
        big = ev[i];
        j = i;
      }
    if (!(big > 0)) {
      st = dm_err_set(e, DM_EDOM, "multiscale: no oscillatory mode at the start (the largest "
                      "eigenvalue of -Lqq against Lvv is %g <= 0): give omega", big);
      goto done;
    }
    wl = sqrt(big);
    big = -1;
    for (i = 0; i < n; i++)          /* the coordinate with the largest share of that mode */
      if (fabs(gsl_matrix_get(&Zm.matrix, i, j)) > big) {
        big = fabs(gsl_matrix_get(&Zm.matrix, i, j));
        best = i;
      }
  }
  /* a resolved run: 32 steps per period of the linearisation, 64 periods */
  h = 2.0 * M_PI / wl / 32.0;
  {
    double *q = Lq, *p = Lv;
    long done_steps;
    memcpy(q, q0, n * sizeof *q);
    memcpy(p, p0, n * sizeof *p);
    for (size_t k = 0; k < Np; k++) {
      trace[k] = q[best];
      if ((st = dm_integrator_advance(G, h, 1, q, p, &done_steps, e)) != DM_OK)
        goto done;
    }
  }
  if ((z = calloc(2 * Nf, sizeof *z)) == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "multiscale: out of memory");
    goto done;
  }
  {
    /* remove the mean and the trend, Hann window, zero padding x4 */
    double sx = 0, sy = 0, sxx = 0, sxy = 0, a, b;
    for (i = 0; i < Np; i++) {
      sx += (double)i;
      sy += trace[i];
      sxx += (double)i * (double)i;
      sxy += (double)i * trace[i];
    }
    b = ((double)Np * sxy - sx * sy) / ((double)Np * sxx - sx * sx);
    a = (sy - b * sx) / (double)Np;
    for (i = 0; i < Np; i++)
      z[2 * i] = (trace[i] - a - b * (double)i)
                 * (0.5 - 0.5 * cos(2.0 * M_PI * (double)i / (double)(Np - 1)));
  }
  if (gsl_fft_complex_radix2_forward(z, 1, Nf) != GSL_SUCCESS) {
    st = dm_err_set(e, DM_EDOM, "multiscale: the FFT of the resolved run failed");
    goto done;
  }
  {
    /* the peak near the linearisation's frequency (bin wl h Nf/2pi = Nf/32) */
    size_t lo_bin = Nf / 64, hi = Nf / 16, pk = lo_bin;
    double m = -1;
    for (i = lo_bin; i <= hi; i++) {
      double a2 = z[2 * i] * z[2 * i] + z[2 * i + 1] * z[2 * i + 1];
      if (a2 > m) {
        m = a2;
        pk = i;
      }
    }
    double ym = log(z[2 * pk - 2] * z[2 * pk - 2] + z[2 * pk - 1] * z[2 * pk - 1]), y0 = log(m),
           yp = log(z[2 * pk + 2] * z[2 * pk + 2] + z[2 * pk + 3] * z[2 * pk + 3]);
    double delta = 0.5 * (ym - yp) / (ym - 2.0 * y0 + yp);
    if (!isfinite(delta) || fabs(delta) > 1)
      delta = 0;
    *omega = 2.0 * M_PI * ((double)pk + delta) / ((double)Nf * h);
  }
  if (coord != NULL)
    *coord = best;
  st = DM_OK;
done:
  free(z);
  gsl_eigen_gensymmv_free(ws);
  free(buf);
  dm_integrator_free(G);
  return st;
}

/* }====================================================================== */
