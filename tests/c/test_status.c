/* test_status.c -- status names, error records, GSL mapping, interrupt flag. */
#include <config.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include "core/status.h"
#include "core/interrupt.h"
#include "tap.h"

int main(void)
{
  dm_err e;
  gsl_matrix *m;
  gsl_permutation *p;
  int sign, st;

  dm_gsl_init();
  tap_ok(strcmp(dm_strstatus(DM_OK), "success") == 0, "DM_OK is named success");
  tap_ok(strcmp(dm_strstatus(DM_ESINGULAR), "singular matrix") == 0, "singular named");
  tap_ok(strcmp(dm_strstatus(9999), "unknown status") == 0, "out-of-range status");
  tap_ok(strcmp(dm_strstatus(-3), "unknown status") == 0, "negative status");

  tap_is_int(dm_err_set(&e, DM_ENOCONV, "Newton: residual %.4g after %d iterations", 2.385e-3, 50),
             DM_ENOCONV, "dm_err_set returns its status");
  tap_ok(strcmp(e.msg, "Newton: residual 0.002385 after 50 iterations") == 0, "message formatted: %s", e.msg);
  tap_is_int(dm_err_set(NULL, DM_EDOM, "ignored"), DM_EDOM, "NULL record allowed");
  dm_err_clear(&e);
  tap_ok(e.status == DM_OK && e.msg[0] == '\0', "clear resets the record");

  tap_is_int(dm_from_gsl(GSL_SUCCESS), DM_OK, "GSL success");
  tap_is_int(dm_from_gsl(GSL_ESING), DM_ESINGULAR, "GSL_ESING");
  tap_is_int(dm_from_gsl(GSL_EMAXITER), DM_ENOCONV, "GSL_EMAXITER");
  tap_is_int(dm_from_gsl(GSL_EDOM), DM_EDOM, "GSL_EDOM");
  tap_is_int(dm_from_gsl(GSL_EBADLEN), DM_EINVAL, "GSL_EBADLEN");

  /* With the handler off a GSL failure returns instead of aborting. */
  m = gsl_matrix_calloc(2, 2);
  p = gsl_permutation_alloc(3);      /* wrong length: GSL_EBADLEN */
  st = gsl_linalg_LU_decomp(m, p, &sign);
  tap_ok(st != GSL_SUCCESS, "GSL error returned, not aborted (status %d)", st);
  gsl_permutation_free(p);
  gsl_matrix_free(m);

  dm_interrupt_clear();
  tap_ok(!dm_interrupted(), "flag clear");
  dm_interrupt_raise();
  tap_ok(dm_interrupted(), "flag raised");
  dm_interrupt_clear();
  tap_ok(!dm_interrupted(), "flag cleared again");
  return tap_done();
}
