/* test_lie_nomalloc.c -- steps of the integrators of systems on groups
 * never allocate: lgvi, lie:gauss (s = 1, 2, simplified Newton and full
 * Newton), lie:gauss:cayley and gsl:rk4 on the heavy top and on SE(3), 200
 * steps each under an interposed allocator that counts every malloc,
 * calloc and realloc of the process; and the integrators keep stepping
 * correctly when every allocation fails (they allocate nothing). */
#include <config.h>
#include <stdlib.h>
#include <string.h>

#include "lie/lie_system.h"
#include "expr/native.h"
#include "interpose.h"
#include "lie_testsys.h"
#include "tap.h"

static void check(const dm_lie_system *S, const char *method, int stages, int simplified,
                  const double *g0, const double *mu0)
{
  dm_integ_opts o;
  dm_integrator *I;
  dm_err e;
  double g[12], mu[6];
  const dm_lie_group *G = dm_lie_system_group(S);
  long before, k;
  int st = DM_OK;
  dm_integ_opts_init(&o);
  o.stages = stages;
  o.simplified = simplified;
  if (dm_integrator_new(dm_lie_system_base(S), method, &o, &I, &e) != DM_OK) {
    tap_ok(0, "%s: %s", method, e.msg);
    return;
  }
  memcpy(g, g0, G->nq * sizeof *g);
  memcpy(mu, mu0, G->dim * sizeof *mu);
  st = dm_integrator_step(I, 0.01, g, mu, g, mu, &e);          /* warm up */
  before = ip_count;
  ip_fail_at(1);
  for (k = 0; k < 200 && st == DM_OK; k++)
    st = dm_integrator_step(I, 0.01, g, mu, g, mu, &e);
  ip_fail_at(0);
  tap_ok(st == DM_OK && ip_count == before, "%s on %s (s=%d, simplified=%d): 200 steps, %ld "
         "allocations, every one refused", method, G->name, stages, simplified,
         ip_count - before);
  dm_integrator_free(I);
}

int main(void)
{
  dm_expr_ctx *ctx;
  dm_lie_group *SO3, *SE3;
  dm_lie_system *top, *body;
  dm_err e;
  static const double par[6] = {1, 2, 3, 9.81, 0.3, 0};
  double g0[12], w[6] = {0.5, 0.2, -0.1, 1, 0.5, 0.2}, mu[6] = {0.5, 0.2, 1, 0.4, 1, -0.3};
  if (!IP_ACTIVE) {
    tap_plan(0);
    printf("# skip: no interposable allocator here\n");
    return 0;
  }
  dm_gsl_init();
  ctx = dm_expr_ctx_alloc();
  SO3 = dm_lie_so3(NULL);
  SE3 = dm_lie_se3(NULL);
  dm_lie_register_integrators(&e);
  if (lt_top(ctx, SO3, par, 1, 0, DM_NATIVE_NEVER, &top, &e) != DM_OK ||
      lt_se3(ctx, SE3, DM_NATIVE_NEVER, &body, &e) != DM_OK) {
    tap_ok(0, "systems: %s", e.msg);
    return tap_done();
  }
  dm_lie_exp(SO3, w, g0);
  check(top, "lgvi", 0, 1, g0, mu);
  check(top, "lie:gauss", 1, 1, g0, mu);
  check(top, "lie:gauss", 2, 1, g0, mu);
  check(top, "lie:gauss", 2, 0, g0, mu);
  check(top, "lie:gauss:cayley", 2, 1, g0, mu);
  check(top, "gsl:rk4", 0, 1, g0, mu);
  dm_lie_exp(SE3, w, g0);
  check(body, "lgvi", 0, 1, g0, mu);
  check(body, "lie:gauss", 2, 1, g0, mu);
  dm_lie_system_free(top);
  dm_lie_system_free(body);
  dm_lie_group_free(SO3);
  dm_lie_group_free(SE3);
  dm_expr_ctx_free(ctx);
  return tap_done();
}
