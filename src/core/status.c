/* status.c -- status names, error records, GSL status mapping. */
#include <config.h>
#include "core/status.h"
#include "core/numfmt.h"

#include <stdarg.h>
#include <stdio.h>
#include <gsl/gsl_errno.h>

const char *dm_strstatus(int status)
{
  static const char *const names[] = {
    "success", "invalid argument", "out of memory", "no convergence",
    "singular matrix", "domain error", "interrupted", "input/output error",
    "not found", "not supported", "callback failed", "timeout", "failed",
    "diverged"
  };
  if (status < 0 || status >= (int)(sizeof names / sizeof names[0]))
    return "unknown status";
  return names[status];
}

int dm_err_set(dm_err *e, int status, const char *fmt, ...)
{
  if (e != NULL) {
    va_list ap;
    e->status = status;
    va_start(ap, fmt);
    dm_num_vsnprintf(e->msg, sizeof e->msg, fmt, ap);
    va_end(ap);
  }
  return status;
}

void dm_err_clear(dm_err *e)
{
  if (e != NULL) {
    e->status = DM_OK;
    e->msg[0] = '\0';
  }
}

int dm_from_gsl(int s)
{
  switch (s) {
  case GSL_SUCCESS: return DM_OK;
  case GSL_EDOM: case GSL_ERANGE: case GSL_EOVRFLW: case GSL_EUNDRFLW:
    return DM_EDOM;
  case GSL_ENOMEM: return DM_ENOMEM;
  case GSL_EMAXITER: case GSL_ENOPROG: case GSL_ENOPROGJ: case GSL_ETOL:
  case GSL_ETOLF: case GSL_ETOLX: case GSL_ETOLG: case GSL_ERUNAWAY:
    return DM_ENOCONV;
  case GSL_ESING: case GSL_EZERODIV: return DM_ESINGULAR;
  case GSL_EINVAL: case GSL_EBADLEN: case GSL_ENOTSQR: case GSL_EBADTOL:
    return DM_EINVAL;
  case GSL_EUNIMPL: case GSL_EUNSUP: return DM_EUNSUP;
  case GSL_EBADFUNC: return DM_ECALLBACK;
  default: return DM_EFAILED;
  }
}

void dm_gsl_init(void)
{
  gsl_set_error_handler_off();
}
