/* integ_common.c -- checked callback evaluation, formatting, the stage
 * predictor shared with the RSPRK engine.  See integ_impl.h and
 * prk_kernels.h. */
#include <config.h>
#include "core/numfmt.h"
#include "integrators/integ_impl.h"
#include "integrators/prk_kernels.h"

#include <stdio.h>

/* A failed callback status (SUNDIALS convention) as a DM status with a
 * message; the evaluation wrappers in integ_impl.h call it only when rc != 0. */
int dm_eval_fail(int rc, const char *what, const double *q, size_t n, dm_err *e)
{
  char buf[160];
  if (rc == 0)
    return DM_OK;
  if (rc > 0)
    return dm_err_set(e, DM_EDOM, "%s: point outside the domain at q = %s (callback status %d)",
                      what, dm_num_format_vec(buf, sizeof buf, q, n), rc);
  return dm_err_set(e, DM_ECALLBACK, "%s failed at q = %s (callback status %d)",
                    what, dm_num_format_vec(buf, sizeof buf, q, n), rc);
}

/* l_j(x), the Lagrange basis polynomial of node j on the s nodes c */
static double lagrange_basis(size_t s, const double *c, size_t j, double x)
{
  double v = 1.0;
  size_t k;
  for (k = 0; k < s; k++)
    if (k != j)
      v *= (x - c[k]) / (c[j] - c[k]);
  return v;
}

void dm_prk_extrapolate(size_t s, size_t n, const double *c, double r, double *E,
                        double *E_ratio, const double *hV, double *X)
{
  size_t i, j, a;
  if (r != *E_ratio) {
    for (i = 0; i < s; i++)
      for (j = 0; j < s; j++)
        E[i * s + j] = lagrange_basis(s, c, j, 1.0 + r * c[i]);
    *E_ratio = r;
  }
  for (i = 0; i < s; i++)
    for (a = 0; a < n; a++) {
      double acc = 0.0;
      for (j = 0; j < s; j++)
        acc += E[i * s + j] * hV[j * n + a];
      X[i * n + a] = acc;
    }
}
