/* integ_common.c -- checked callback evaluation, formatting.
 * See integ_impl.h. */
#include <config.h>
#include "integ_impl.h"

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
                      what, dm_fmt_vec(buf, sizeof buf, q, n), rc);
  return dm_err_set(e, DM_ECALLBACK, "%s failed at q = %s (callback status %d)",
                    what, dm_fmt_vec(buf, sizeof buf, q, n), rc);
}

const char *dm_fmt_vec(char *buf, size_t len, const double *x, size_t n)
{
  size_t i, k = 0;
  if (len == 0)
    return buf;
  buf[0] = '\0';
  k += (size_t)snprintf(buf + k, k < len ? len - k : 0, "(");
  for (i = 0; i < n && i < 6 && k < len; i++)
    k += (size_t)snprintf(buf + k, len - k, "%s%.6g", i ? ", " : "", x[i]);
  if (k < len)
    snprintf(buf + k, len - k, "%s)", n > 6 ? ", ..." : "");
  return buf;
}
