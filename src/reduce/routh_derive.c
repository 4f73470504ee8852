/* routh_derive.c -- symbolic Routh reduction: from L(q, v) and the cyclic
 * coordinates to the locked inertia, mechanical connection, amended
 * potential, Routhians and magnetic 2-form as expression nodes (doc/reduce.md
 * §2-3).  See routh.h for what is derived and the error rules.
 *
 * Inverse of the locked inertia: symbolic, by the adjugate over the
 * determinant, for r <= 3 (r > 3 is DM_EUNSUP): it keeps every derived
 * object an expression that prints, differentiates and compiles, and r is
 * the dimension of an abelian symmetry group, in practice 1 or 2. */
#include <config.h>
#include "reduce/routh_impl.h"

#include <stdlib.h>
#include <string.h>

/* The node arrays of the derivation (all inside one buffer). */
typedef struct nodes {
  dm_expr *x, *xd, *th, *thd_sym, *mu, *M, *I, *Iinv, *A, *w, *muA, *Mt, *B, *thd;
  dm_expr *force, *g;
  dm_expr *K, *kv, *ib, *dkv, *dib, *Dw, *DA;
  dm_expr detI, V, Vmu, R, Rc;
} nodes;

static int ctx_fail(dm_expr_ctx *c, dm_err *e, const char *what)
{
  const dm_err *ce = dm_expr_ctx_err(c);
  return dm_err_set(e, ce->status ? ce->status : DM_EFAILED, "Routh reduction (%s): %s", what,
                    ce->msg[0] ? ce->msg : "cannot build the expressions");
}

static int is_zero(dm_expr_ctx *c, dm_expr x)
{
  double v;
  return dm_expr_is_const(c, x, &v) && v == 0.0;
}

/* "name" of coordinate i of the spec. */
static const char *coord_name(dm_expr_ctx *c, const dm_routh_spec *sp, size_t i)
{
  return sp->coord_names ? sp->coord_names[i] : dm_expr_name(c, sp->q[i]);
}

static int fail_expr(dm_expr_ctx *c, dm_err *e, int status, const char *pre, dm_expr x,
                     const char *post)
{
  char *str = dm_expr_to_string(c, x, 300, NULL);
  dm_err_set(e, status, "%s%s%s", pre, str ? str : "?", post);
  free(str);
  return status;
}

static int check_spec(dm_expr_ctx *c, const dm_routh_spec *sp, dm_err *e)
{
  size_t a, b;
  if (sp->n < 2 || sp->q == NULL || sp->v == NULL || sp->L == DM_EXPR_NONE)
    return dm_err_set(e, DM_EINVAL, "Routh reduction needs n >= 2 coordinates, their velocities "
                      "and L");
  if (sp->r < 1 || sp->cyclic == NULL || sp->r >= sp->n)
    return dm_err_set(e, DM_EINVAL, "Routh reduction needs 1 <= r < n cyclic coordinates (got r = "
                      "%zu, n = %zu)", sp->r, sp->n);
  if (sp->r > DM_ROUTH_RMAX)
    return dm_err_set(e, DM_EUNSUP, "Routh reduction by r = %zu cyclic coordinates: at most %d "
                      "(the locked inertia is inverted symbolically)", sp->r, DM_ROUTH_RMAX);
  if ((sp->npar && sp->par == NULL) || (sp->m && sp->constraints == NULL))
    return dm_err_set(e, DM_EINVAL, "Routh reduction: parameters or constraints missing");
  for (a = 0; a < sp->r; a++) {
    if (sp->cyclic[a] >= sp->n)
      return dm_err_set(e, DM_EINVAL, "cyclic coordinate index %zu out of range 1..%zu",
                        sp->cyclic[a] + 1, sp->n);
    for (b = 0; b < a; b++)
      if (sp->cyclic[a] == sp->cyclic[b])
        return dm_err_set(e, DM_EINVAL, "cyclic coordinate '%s' listed twice",
                          coord_name(c, sp, sp->cyclic[a]));
  }
  for (a = 0; a < sp->n; a++)
    if (dm_expr_kind(c, sp->q[a]) != DM_EXPR_SYM || dm_expr_kind(c, sp->v[a]) != DM_EXPR_SYM)
      return dm_err_set(e, DM_EINVAL, "coordinate %zu or its velocity is not a symbol", a + 1);
  return DM_OK;
}

/* Is expression x free of the cyclic coordinate a?  1: yes, *out is x with
 * theta_a fixed at 0 (x itself when theta_a does not appear); 0: no, *d is
 * dx/dtheta_a; -1: undecidable (dx/dtheta_a not finite at the sample
 * points); DM_E* < -1 never (context errors are read by the caller).
 * dx/dtheta_a that is not 0 as a formula is decided by evaluation
 * (routh_cyclic.c): theta appears, through sin and cos, in Lagrangians
 * written in Cartesian velocities of a rotating system. */
static int free_of(dm_expr_ctx *c, const dm_routh_spec *sp, dm_expr x, size_t a, dm_expr *out,
                   dm_expr *d)
{
  dm_expr th = sp->q[sp->cyclic[a]], zero = dm_expr_const(c, 0.0);
  int z;
  *out = x;
  *d = zero;
  if (!dm_expr_depends(c, x, 1, &th))
    return 1;
  *d = dm_expr_diff(c, x, th);
  if (*d == DM_EXPR_NONE)
    return -1;
  z = is_zero(c, *d) ? 1 : dm_routh_zero_by_eval(c, *d, sp, sp->cyclic[a], NULL);
  if (z == 1 && dm_expr_subs(c, 1, &x, out, 1, &th, &zero, NULL) != DM_OK)
    return -1;
  return z;
}

/* dL/dtheta must vanish: identically as a formula, or at every sample point
 * (then L is replaced by the equivalent L with theta = 0).  A force's
 * cyclic components and the theta-dependence of its shape components and
 * of the constraints are treated the same way (what does not vanish is
 * refused later with its own message).  sp2 is sp with the replaced
 * expressions in buf (n + m nodes). */
static int hidden_symmetry(dm_expr_ctx *c, const dm_routh_spec *sp, dm_routh_spec *sp2,
                           dm_expr *buf, dm_err *e)
{
  size_t a, i;
  *sp2 = *sp;
  for (a = 0; a < sp->r; a++) {
    dm_expr d, Lfix;
    char pre[300];
    int z = free_of(c, sp, sp2->L, a, &Lfix, &d);
    const char *nm = coord_name(c, sp, sp->cyclic[a]);
    if (dm_expr_ctx_err(c)->status != DM_OK)
      return ctx_fail(c, e, "dL/dtheta");
    if (z == 1) {
      sp2->L = Lfix;
      continue;
    }
    if (z == 0)
      snprintf(pre, sizeof pre, "'%s' is not a cyclic coordinate: L depends on it, dL/d%s = ", nm, nm);
    else
      snprintf(pre, sizeof pre, "cannot decide whether L depends on '%s': dL/d%s is not finite at "
               "the sample points; dL/d%s = ", nm, nm, nm);
    return fail_expr(c, e, DM_EINVAL, pre, d,
                     " (write L with the symmetry explicit, e.g. in terms of differences of angles)");
  }
  if (sp->force) {
    memcpy(buf, sp->force, sp->n * sizeof *buf);
    for (i = 0; i < sp->n; i++)
      for (a = 0; a < sp->r; a++) {
        dm_expr fix, d;
        int cyclic_comp = i == sp->cyclic[a];
        if (cyclic_comp && !is_zero(c, buf[i])
            && dm_routh_zero_by_eval(c, buf[i], sp, sp->cyclic[a], NULL) == 1)
          buf[i] = dm_expr_const(c, 0.0);
        else if (free_of(c, sp, buf[i], a, &fix, &d) == 1)
          buf[i] = fix;
      }
    sp2->force = buf;
  }
  if (sp->m) {
    memcpy(buf + sp->n, sp->constraints, sp->m * sizeof *buf);
    for (i = 0; i < sp->m; i++)
      for (a = 0; a < sp->r; a++) {
        dm_expr fix, d;
        if (free_of(c, sp, buf[sp->n + i], a, &fix, &d) == 1)
          buf[sp->n + i] = fix;
      }
    sp2->constraints = buf + sp->n;
  }
  if (dm_expr_ctx_err(c)->status != DM_OK)
    return ctx_fail(c, e, "the theta-dependence of the force or constraints");
  return DM_OK;
}

/* M = d2L/dv2 independent of v; no terms linear in v; V = -L(q, 0).
 * DM_EUNSUP otherwise: the caller then reduces numerically. */
static int mechanical(dm_expr_ctx *c, const dm_routh_spec *sp, nodes *N, dm_expr *tmp, dm_err *e)
{
  size_t n = sp->n, i;
  dm_expr *Lv = tmp, *zero = tmp + n, *Lv0 = tmp + 2 * n;
  if (dm_expr_hessian(c, sp->L, n, sp->v, N->M, NULL) != DM_OK)
    return ctx_fail(c, e, "d2L/dv2");
  for (i = 0; i < n * n; i++)
    if (dm_expr_depends(c, N->M[i], n, sp->v))
      return fail_expr(c, e, DM_EUNSUP, "L is not mechanical (quadratic in the velocities): "
                       "d2L/dv2 depends on v, e.g. ", N->M[i], "");
  if (dm_expr_grad(c, sp->L, n, sp->v, Lv, NULL) != DM_OK)
    return ctx_fail(c, e, "dL/dv");
  for (i = 0; i < n; i++)
    zero[i] = dm_expr_const(c, 0.0);
  if (dm_expr_subs(c, n, Lv, Lv0, n, sp->v, zero, e) != DM_OK)
    return DM_EFAILED;
  for (i = 0; i < n; i++)
    if (!is_zero(c, Lv0[i]))
      return fail_expr(c, e, DM_EUNSUP, "L has terms linear in the velocities (dL/dv at v = 0 is ",
                       Lv0[i], "): Routh reduction supports L = 1/2 v^T M(x) v - V(x)");
  if (dm_expr_subs(c, 1, &sp->L, &N->V, n, sp->v, zero, e) != DM_OK)
    return DM_EFAILED;
  N->V = dm_expr_neg(c, N->V);
  return DM_OK;
}

/* Iinv = adj(I) / det(I) for r <= 3. */
static void invert(dm_expr_ctx *c, size_t r, const dm_expr *I, dm_expr *Iinv, dm_expr *det)
{
#define E(i, j) I[(i) * r + (j)]
#define MUL(a, b) dm_expr_mul(c, a, b)
#define SUB(a, b) dm_expr_sub(c, a, b)
  size_t i, j;
  if (r == 1) {
    *det = I[0];
    Iinv[0] = dm_expr_div(c, dm_expr_const(c, 1.0), I[0]);
    return;
  }
  if (r == 2) {
    dm_expr adj[4];
    *det = SUB(MUL(E(0, 0), E(1, 1)), MUL(E(0, 1), E(1, 0)));
    adj[0] = E(1, 1);
    adj[1] = dm_expr_neg(c, E(0, 1));
    adj[2] = dm_expr_neg(c, E(1, 0));
    adj[3] = E(0, 0);
    for (i = 0; i < 4; i++)
      Iinv[i] = dm_expr_div(c, adj[i], *det);
    return;
  }
  {
    dm_expr cof[9];
    for (i = 0; i < 3; i++)
      for (j = 0; j < 3; j++) {
        size_t i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        cof[i * 3 + j] = SUB(MUL(E(i1, j1), E(i2, j2)), MUL(E(i1, j2), E(i2, j1)));
      }
    *det = dm_expr_add(c, dm_expr_add(c, MUL(E(0, 0), cof[0]), MUL(E(0, 1), cof[1])),
                       MUL(E(0, 2), cof[2]));
    for (i = 0; i < 3; i++)      /* inverse = cofactor^T / det */
      for (j = 0; j < 3; j++)
        Iinv[i * 3 + j] = dm_expr_div(c, cof[j * 3 + i], *det);
  }
#undef E
#undef MUL
#undef SUB
}

static dm_expr sum2(dm_expr_ctx *c, dm_expr acc, dm_expr a, dm_expr b)
{
  return dm_expr_add(c, acc, dm_expr_mul(c, a, b));
}

/* Everything from I to B, thetadot and the derivatives the integrators use. */
static int connection(dm_expr_ctx *c, const dm_routh *red, nodes *N, dm_err *e)
{
  size_t n = red->n, r = red->r, s = red->s, a, b, i, j, k;
  dm_expr half = dm_expr_const(c, 0.5), zero = dm_expr_const(c, 0.0), t;
  dm_expr *Mtx = N->Dw;            /* borrow: M_theta,x (r*s) until Dw is built */
  for (a = 0; a < r; a++)
    for (b = 0; b < r; b++)
      N->I[a * r + b] = N->M[red->cyc[a] * n + red->cyc[b]];
  for (a = 0; a < r; a++)
    for (i = 0; i < s; i++)
      Mtx[a * s + i] = N->M[red->cyc[a] * n + red->shape[i]];
  invert(c, r, N->I, N->Iinv, &N->detI);
  if (r == 1) {               /* the same objects, written as quotients (they print better) */
    N->w[0] = dm_expr_div(c, N->mu[0], N->I[0]);
    for (i = 0; i < s; i++)
      N->A[i] = dm_expr_div(c, Mtx[i], N->I[0]);
  }
  for (a = 0; a < r && r > 1; a++) {
    dm_expr acc = zero;
    for (b = 0; b < r; b++)
      acc = sum2(c, acc, N->Iinv[a * r + b], N->mu[b]);
    N->w[a] = acc;
    for (i = 0; i < s; i++) {
      acc = zero;
      for (b = 0; b < r; b++)
        acc = sum2(c, acc, N->Iinv[a * r + b], Mtx[b * s + i]);
      N->A[a * s + i] = acc;
    }
  }
  for (i = 0; i < s; i++) {
    dm_expr acc = zero;
    for (a = 0; a < r; a++)
      acc = sum2(c, acc, N->mu[a], N->A[a * s + i]);
    N->muA[i] = acc;
  }
  for (i = 0; i < s; i++)           /* Mt = Mxx - Mtx^T A, upper triangle mirrored */
    for (j = i; j < s; j++) {
      dm_expr acc = N->M[red->shape[i] * n + red->shape[j]];
      for (a = 0; a < r; a++)
        acc = dm_expr_sub(c, acc, dm_expr_mul(c, Mtx[a * s + i], N->A[a * s + j]));
      N->Mt[i * s + j] = N->Mt[j * s + i] = acc;
    }
  t = zero;
  for (a = 0; a < r; a++)
    t = sum2(c, t, N->mu[a], N->w[a]);
  if (r == 1)                 /* 1/2 mu^2 / I */
    t = dm_expr_div(c, dm_expr_powi(c, N->mu[0], 2), N->I[0]);
  N->Vmu = dm_expr_add(c, N->V, dm_expr_mul(c, half, t));
  t = zero;
  for (i = 0; i < s; i++) {
    t = sum2(c, t, dm_expr_mul(c, half, N->Mt[i * s + i]), dm_expr_powi(c, N->xd[i], 2));
    for (j = i + 1; j < s; j++)
      t = sum2(c, t, N->Mt[i * s + j], dm_expr_mul(c, N->xd[i], N->xd[j]));
  }
  N->R = dm_expr_sub(c, t, N->Vmu);
  t = N->R;
  for (i = 0; i < s; i++)
    t = sum2(c, t, N->muA[i], N->xd[i]);
  N->Rc = t;
  for (a = 0; a < r; a++) {
    dm_expr acc = N->w[a];
    for (i = 0; i < s; i++)
      acc = dm_expr_sub(c, acc, dm_expr_mul(c, N->A[a * s + i], N->xd[i]));
    N->thd[a] = acc;
  }
  /* magnetic term: K_ik = d muA_i / dx_k, B_ij = K_ji - K_ij */
  if (dm_expr_jacobian(c, s, N->muA, s, N->x, N->K, NULL) != DM_OK)
    return ctx_fail(c, e, "d(mu A)/dx");
  for (i = 0; i < s; i++)
    for (j = 0; j < s; j++)
      N->B[i * s + j] = i == j ? zero : dm_expr_sub(c, N->K[j * s + i], N->K[i * s + j]);
  for (i = 0; i < s; i++) {
    dm_expr kv = zero, ib = zero;
    for (k = 0; k < s; k++) {
      kv = sum2(c, kv, N->K[i * s + k], N->xd[k]);
      ib = sum2(c, ib, N->xd[k], N->B[k * s + i]);
    }
    N->kv[i] = kv;
    N->ib[i] = ib;
  }
  if (dm_expr_jacobian(c, s, N->kv, s, N->x, N->dkv, NULL) != DM_OK ||
      dm_expr_jacobian(c, s, N->ib, s, N->x, N->dib, NULL) != DM_OK ||
      dm_expr_jacobian(c, r * s, N->A, s, N->x, N->DA, NULL) != DM_OK ||
      dm_expr_jacobian(c, r, N->w, s, N->x, N->Dw, NULL) != DM_OK)
    return ctx_fail(c, e, "derivatives of the connection");
  return DM_OK;
}

/* Reduced force: cyclic components identically zero, shape components
 * independent of theta; thetadot substituted. */
static int reduce_force(dm_expr_ctx *c, const dm_routh_spec *sp, const dm_routh *red, nodes *N,
                        dm_err *e)
{
  size_t a, i;
  dm_expr th[DM_ROUTH_RMAX];
  char pre[300];
  for (a = 0; a < red->r; a++) {
    dm_expr Fa = sp->force[red->cyc[a]];
    th[a] = sp->q[red->cyc[a]];
    if (!is_zero(c, Fa)) {
      snprintf(pre, sizeof pre, "the force has a component along the cyclic coordinate '%s' "
               "(F_%s = ", coord_name(c, sp, red->cyc[a]), coord_name(c, sp, red->cyc[a]));
      return fail_expr(c, e, DM_EINVAL, pre, Fa, "): it would change the momentum (Lemma 2.15); "
                       "only forces whose cyclic components vanish can be reduced");
    }
  }
  for (i = 0; i < red->s; i++) {
    dm_expr Fi = sp->force[red->shape[i]];
    if (dm_expr_depends(c, Fi, red->r, th)) {
      snprintf(pre, sizeof pre, "force component '%s' depends on a cyclic coordinate (F = ",
               coord_name(c, sp, red->shape[i]));
      return fail_expr(c, e, DM_EINVAL, pre, Fi, "): the force must be invariant under the "
                       "symmetry");
    }
  }
  for (i = 0; i < red->s; i++)
    N->force[i] = sp->force[red->shape[i]];
  if (dm_expr_subs(c, red->s, N->force, N->force, red->r, N->thd_sym, N->thd, e) != DM_OK)
    return DM_EFAILED;
  return DM_OK;
}

static int reduce_constraints(dm_expr_ctx *c, const dm_routh_spec *sp, const dm_routh *red,
                              nodes *N, dm_err *e)
{
  size_t k, a;
  for (k = 0; k < sp->m; k++) {
    for (a = 0; a < red->r; a++) {
      dm_expr th = sp->q[red->cyc[a]], d;
      char pre[300];
      if (!dm_expr_depends(c, sp->constraints[k], 1, &th))
        continue;
      d = dm_expr_diff(c, sp->constraints[k], th);
      if (is_zero(c, d))
        continue;
      snprintf(pre, sizeof pre, "constraint %zu depends on the cyclic coordinate '%s' (dg/d%s = ",
               k + 1, coord_name(c, sp, red->cyc[a]), coord_name(c, sp, red->cyc[a]));
      return fail_expr(c, e, DM_EINVAL, pre, d, "): the constraint manifold must be invariant "
                       "under the symmetry");
    }
    N->g[k] = sp->constraints[k];
  }
  return DM_OK;
}

/* Names: shape coordinates, then parameters (original, then mu_<theta>). */
static int make_names(dm_expr_ctx *c, const dm_routh_spec *sp, dm_routh *red, dm_err *e)
{
  size_t i, a, j;
  red->names = calloc(red->s + red->np, sizeof *red->names);
  if (red->names == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  for (i = 0; i < red->s; i++)
    if ((red->names[i] = strdup(coord_name(c, sp, red->shape[i]))) == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory");
  for (i = 0; i < sp->npar; i++) {
    const char *pn = sp->param_names ? sp->param_names[i] : dm_expr_name(c, sp->par[i]);
    if ((red->names[red->s + i] = strdup(pn ? pn : "?")) == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  for (a = 0; a < red->r; a++) {
    char buf[300];
    snprintf(buf, sizeof buf, "mu_%s", coord_name(c, sp, red->cyc[a]));
    for (j = 0; j < sp->npar; j++)
      if (strcmp(buf, red->names[red->s + j]) == 0)
        return dm_err_set(e, DM_EINVAL, "the momentum parameter name '%s' is already a parameter "
                          "of the system", buf);
    if ((red->names[red->s + sp->npar + a] = strdup(buf)) == NULL)
      return dm_err_set(e, DM_ENOMEM, "out of memory");
  }
  return DM_OK;
}

static int alloc_nodes(dm_routh *red, nodes *N, dm_err *e)
{
  size_t n = red->n, r = red->r, s = red->s, m = red->m;
  size_t tot = 2 * s + 3 * r + n * n + 2 * r * r + r * s + r + s + 2 * s * s + r + s + m
               + s * s + 2 * s + 2 * s * s + r * s + r * s * s;
  dm_expr *d = malloc(tot * sizeof *d);
  if (d == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  red->exbuf = d;
#define TAKE(p, k) do { N->p = d; d += (k); } while (0)
  TAKE(x, s); TAKE(xd, s); TAKE(th, r); TAKE(thd_sym, r); TAKE(mu, r); TAKE(M, n * n);
  TAKE(I, r * r); TAKE(Iinv, r * r); TAKE(A, r * s); TAKE(w, r); TAKE(muA, s);
  TAKE(Mt, s * s); TAKE(B, s * s); TAKE(thd, r); TAKE(force, s); TAKE(g, m);
  TAKE(K, s * s); TAKE(kv, s); TAKE(ib, s); TAKE(dkv, s * s); TAKE(dib, s * s);
  TAKE(Dw, r * s); TAKE(DA, r * s * s);
#undef TAKE
  return DM_OK;
}

static void publish(dm_routh *red, const nodes *N)
{
  dm_routh_exprs *x = &red->ex;
  x->n = red->n; x->r = red->r; x->s = red->s; x->m = red->m; x->npar = red->npar;
  x->cyclic = red->cyc; x->shape = red->shape;
  x->x = N->x; x->xdot = N->xd; x->theta = N->th; x->thetadot_sym = N->thd_sym;
  x->mu = N->mu; x->M = N->M; x->I = N->I; x->Iinv = N->Iinv; x->detI = N->detI;
  x->A = N->A; x->Iinv_mu = N->w; x->muA = N->muA; x->Mtilde = N->Mt;
  x->V = N->V; x->Vmu = N->Vmu; x->R = N->R; x->Rc = N->Rc; x->B = N->B;
  x->thetadot = N->thd;
  x->force = red->has_force ? N->force : NULL;
  x->constraints = red->m ? N->g : NULL;
}

static int set_name(dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_routh *red, dm_err *e)
{
  const char *nm = sp->name ? sp->name : "system";
  char buf[400];
  size_t a, len = (size_t)snprintf(buf, sizeof buf, "%s reduced by", nm);
  for (a = 0; a < red->r && len < sizeof buf; a++)
    len += (size_t)snprintf(buf + len, sizeof buf - len, "%s %s", a ? "," : "",
                            coord_name(ctx, sp, red->cyc[a]));
  if ((red->name = strdup(buf)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  return DM_OK;
}

/* A Lagrangian that is not mechanical (mechanical() said why): only the
 * symbols and the mass matrix d2L/dv2 (v-dependent) are published; the
 * classical Routhian is evaluated numerically (routh_general.c).  Forces
 * and constraints are reduced only for mechanical Lagrangians. */
static int general(dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_routh *red, nodes *N, dm_err *e)
{
  dm_routh_exprs *x = &red->ex;
  int st;
  if (sp->force || sp->m)
    return dm_err_set(e, DM_EUNSUP, "L is not quadratic in the velocities: its Routh reduction is "
                      "numerical and does not take %s (only mechanical Lagrangians L = 1/2 v^T "
                      "M(x) v - V(x) are reduced with them)",
                      sp->force ? "a force" : "constraints");
  dm_expr_ctx_clear_err(ctx);
  red->general = 1;
  red->has_gyro = 0;
  red->has_force = 0;
  memset(x, 0, sizeof *x);
  x->n = red->n; x->r = red->r; x->s = red->s; x->m = 0; x->npar = red->npar;
  x->cyclic = red->cyc; x->shape = red->shape;
  x->x = N->x; x->xdot = N->xd; x->theta = N->th; x->thetadot_sym = N->thd_sym;
  x->mu = N->mu; x->M = N->M;
  x->detI = x->V = x->Vmu = x->R = x->Rc = DM_EXPR_NONE;
  if ((st = set_name(ctx, sp, red, e)) != DM_OK)
    return st;
  return dm_routh_general_setup(red, ctx, sp, e);
}

static int derive(dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_routh **out, dm_err *e)
{
  dm_routh *red;
  nodes N;
  dm_expr *tmp = NULL;
  size_t i, a, k;
  int st;
  if ((red = calloc(1, sizeof *red)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  red->n = sp->n;
  red->r = sp->r;
  red->s = sp->n - sp->r;
  red->m = sp->m;
  red->npar = sp->npar;
  red->np = sp->npar + sp->r;
  red->has_force = sp->force != NULL;
  red->sing_tol = 1e-10;
  red->shape = calloc(red->s, sizeof *red->shape);
  red->par = calloc(red->np, sizeof *red->par);
  tmp = calloc(3 * sp->n, sizeof *tmp);
  if (red->shape == NULL || red->par == NULL || tmp == NULL) {
    st = dm_err_set(e, DM_ENOMEM, "out of memory");
    goto fail;
  }
  for (a = 0; a < red->r; a++)
    red->cyc[a] = sp->cyclic[a];
  for (i = 0, k = 0; i < sp->n; i++) {
    int cyc = 0;
    for (a = 0; a < red->r; a++)
      cyc |= sp->cyclic[a] == i;
    if (!cyc)
      red->shape[k++] = i;
  }
  for (i = 0; i < sp->npar; i++)
    red->par[i] = sp->par_values ? sp->par_values[i] : 0.0;
  for (a = 0; a < red->r; a++)
    red->par[sp->npar + a] = sp->mu ? sp->mu[a] : 0.0;
  if ((st = make_names(ctx, sp, red, e)) != DM_OK || (st = alloc_nodes(red, &N, e)) != DM_OK)
    goto fail;
  for (i = 0; i < red->s; i++) {
    N.x[i] = sp->q[red->shape[i]];
    N.xd[i] = sp->v[red->shape[i]];
  }
  for (a = 0; a < red->r; a++) {
    N.th[a] = sp->q[red->cyc[a]];
    N.thd_sym[a] = sp->v[red->cyc[a]];
    N.mu[a] = dm_expr_param(ctx, red->names[red->s + sp->npar + a]);
    if (N.mu[a] == DM_EXPR_NONE) {          /* out of memory: say so here, */
      st = ctx_fail(ctx, e, "mu");           /* before the context is reset */
      goto fail;
    }
  }
  dm_expr_ctx_clear_err(ctx);
  st = mechanical(ctx, sp, &N, tmp, e);
  if (st == DM_EUNSUP) {         /* not quadratic in v: numerical classical Routhian */
    if ((st = general(ctx, sp, red, &N, e)) != DM_OK)
      goto fail;
    free(tmp);
    *out = red;
    return DM_OK;
  }
  if (st != DM_OK || (st = connection(ctx, red, &N, e)) != DM_OK)
    goto fail;
  if (sp->force && (st = reduce_force(ctx, sp, red, &N, e)) != DM_OK)
    goto fail;
  if (sp->m && (st = reduce_constraints(ctx, sp, red, &N, e)) != DM_OK)
    goto fail;
  if (dm_expr_ctx_err(ctx)->status != DM_OK) {
    st = ctx_fail(ctx, e, "derivation");
    goto fail;
  }
  for (i = 0; i < red->s; i++)
    red->has_gyro |= !is_zero(ctx, N.muA[i]);
  if ((st = set_name(ctx, sp, red, e)) != DM_OK)
    goto fail;
  publish(red, &N);
  st = dm_routh_compile_nodes(red, ctx, sp, N.K, N.kv, N.ib, N.dkv, N.dib, N.Dw, N.DA, e);
  if (st != DM_OK)
    goto fail;
  free(tmp);
  *out = red;
  return DM_OK;
fail:
  free(tmp);
  dm_routh_free(red);
  return st;
}

int dm_routh_derive(dm_expr_ctx *ctx, const dm_routh_spec *sp, dm_routh **out, dm_err *e)
{
  dm_routh_spec sp2;
  dm_expr *buf;
  int st;
  *out = NULL;
  if (ctx == NULL || sp == NULL)
    return dm_err_set(e, DM_EINVAL, "Routh reduction: no context or specification");
  if ((st = dm_routh_register_integrators(e)) != DM_OK)
    return st;
  if ((st = check_spec(ctx, sp, e)) != DM_OK)
    return st;
  if ((buf = malloc((sp->n + sp->m + 1) * sizeof *buf)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  dm_expr_ctx_clear_err(ctx);
  st = hidden_symmetry(ctx, sp, &sp2, buf, e);
  if (st == DM_OK)
    st = derive(ctx, &sp2, out, e);
  if (st == DM_OK)               /* its integrators are the reduced families */
    (*out)->sys.kind = DM_ROUTH_KIND;
  free(buf);
  return st;
}
