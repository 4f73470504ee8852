/* lie_integ_impl.h -- private to src/lie: the layout of a system on a group
 * and the helpers its integrator families share (lie_system.c, lie_lgvi.c,
 * lie_gauss.c, lie_run.c).  Not part of the API. */
#ifndef DM_LIE_INTEG_IMPL_H
#define DM_LIE_INTEG_IMPL_H

#include <stddef.h>

#include "lie/lie_system.h"
#include "lie/lie_impl.h"
#include "expr/bundle.h"

/* the compiled Galerkin step programs, both on the inputs (g, X =
 * xi^1..xi^s, mu, h): res gives the residual (s dim) and mu_k+1 (dim), jac
 * the residual's Jacobian in X ((s dim)^2) */
typedef struct dm_lie_gauss_prog {
  size_t s;
  int cayley;
  dm_bundle res, jac;
} dm_lie_gauss_prog;

struct dm_lie_system {
  dm_system sys;                /* the view of kind "lie"; sys.data = this */
  dm_lie_group *G;
  char *name;
  dm_expr_ctx *ctx;             /* borrowed */
  size_t nq, dim, npar;
  dm_expr *g, *xi, *par;        /* symbols */
  dm_expr L0, L;                /* as given; as used (reduced: g = e) */
  dm_expr *force0, *force;      /* dim each, or NULL */
  double *parv;                 /* current parameter values */
  char **pnames, **gnames, **munames, **xinames;
  int reduced, native;
  dm_bundle grad, all;          /* (g, xi) -> L, Lq, Lv [, Lvv, Lvq, Lqq] */
  dm_bundle moment;             /* g -> M = Lq(g, 0) (unless moment_zero) */
  int moment_zero;
  dm_bundle fprog;              /* (g, xi) -> F */
  int quadratic;                /* L = 1/2 xi^T J xi - U(g), J constant */
  dm_expr *Jexpr;               /* dim^2 */
  double *J;                    /* at the current parameters */
  unsigned long gen;            /* bumped by parameter changes */
  size_t work;                  /* doubles of scratch a program run needs */
  dm_lie_gauss_prog *gauss;     /* compiled step programs, by (s, chart) */
  size_t ngauss;
};

/* M = Lq(g, 0) (the potential's moment, zeros when there is none) and
 * F(g, xi) (zeros when unforced); work: S->work doubles.  1 when an
 * output is NaN or Inf. */
int dm_lie_eval_moment(const dm_lie_system *S, const double *g, double *M, double *work);
int dm_lie_eval_force(const dm_lie_system *S, const double *g, const double *xi, double *F,
                      double *work);
/* Compile nout outputs on nin inputs (one array) with the system's
 * parameters and native mode. */
int dm_lie_compile_bundle(const dm_lie_system *S, dm_bundle *p, size_t nout, const dm_expr *out,
                          size_t nin, const dm_expr *in, dm_err *e);
void dm_lie_system_grow_work(dm_lie_system *S, const dm_bundle *p);
/* J from its expressions at the current parameters. */
int dm_lie_update_J(dm_lie_system *S, dm_err *e);
/* The Galerkin step program for (s, cayley), compiled on first use. */
int dm_lie_gauss_program(dm_lie_system *S, size_t s, int cayley, const dm_lie_gauss_prog **out,
                         dm_err *e);

extern const dm_integrator_type dm_lie_integ_lgvi, dm_lie_integ_gauss, dm_lie_integ_gsl;
extern const dm_integrator_type dm_sphere_integ_lgvi;     /* sphere_lgvi.c */

#endif
