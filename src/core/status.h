/* status.h -- status codes and error records shared by all dmech numerics.
 *
 * Every numerical routine returns an int status: DM_OK (0) on success, one of
 * the positive DM_E* codes otherwise.  Routines that can fail for reasons worth
 * explaining also take a `dm_err *` (may be NULL) and fill its message; the
 * caller (a Lua binding, a test) decides what to do with it.  Nothing under
 * src/core prints, exits or knows about Lua.
 *
 * Ownership: dm_err is a plain value; it owns no heap memory.
 */
#ifndef DM_STATUS_H
#define DM_STATUS_H

#include <stddef.h>

enum dm_status {
  DM_OK = 0,
  DM_EINVAL,     /* invalid argument (size, range, option) */
  DM_ENOMEM,     /* allocation failed */
  DM_ENOCONV,    /* iteration (Newton, fixed point) did not converge */
  DM_ESINGULAR,  /* singular matrix / non-regular Lagrangian */
  DM_EDOM,       /* value outside the domain of a function, NaN produced */
  DM_EINTR,      /* interrupted by the user (dm_interrupted()) */
  DM_EIO,        /* file or process I/O failed */
  DM_ENOTFOUND,  /* named thing (method, column, program) does not exist */
  DM_EUNSUP,     /* combination not supported */
  DM_ECALLBACK,  /* a user callback reported failure */
  DM_ETIMEOUT,   /* an external process did not answer in time */
  DM_EFAILED,    /* generic failure; see message */
  DM_EDIVERGED,  /* a run left its bounds (non-finite energy, energy error) */
  DM_NSTATUS     /* number of status codes (not a status) */
};

#define DM_ERRMSG_MAX 512

typedef struct dm_err {
  int status;
  char msg[DM_ERRMSG_MAX];
} dm_err;

/* Short fixed name of a status ("singular matrix", ...). Never NULL. */
const char *dm_strstatus(int status);

/* Record status and a printf-style message in e (if e is not NULL) and return
 * status, so callers can write `return dm_err_set(e, DM_EINVAL, "...")`. */
int dm_err_set(dm_err *e, int status, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;

/* Reset e to DM_OK with an empty message. */
void dm_err_clear(dm_err *e);

/* Map a GSL status code to a dm status code. */
int dm_from_gsl(int gsl_status);

/* Turn GSL's abort-on-error handler off.  Called once by every entry point
 * (luaopen_dmech, test programs); idempotent. */
void dm_gsl_init(void);

#endif
