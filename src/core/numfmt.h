/* numfmt.h -- numbers to text and back, always in the "C" locale.
 *
 * Every number dmech writes or reads as text goes through here: printed
 * values (vec, mat, formulas, messages), metadata, trajectory files, gnuplot
 * data and commands, and the C source of native code.  The functions use a
 * private "C" locale object (newlocale, created once) selected with
 * uselocale() for the calling thread only for the duration of the call, so a
 * host program that sets LC_NUMERIC (a decimal comma) -- dmech.so loaded
 * into it -- never changes what dmech writes or how it reads it back.
 *
 * Formats: dm_num_format writes the shortest of "%.15g", "%.16g", "%.17g"
 * that reads back to the same double ("0.1", not "0.10000000000000001"), and
 * "nan", "inf", "-inf"; every other function takes a printf format.
 *
 * Ownership: nothing to free; buffers belong to the caller.  The locale
 * object lives until the process exits.
 *
 * Errors: formatting truncates like snprintf and returns the length the
 * full text would have; dm_num_parse behaves like strtod (end pointer,
 * ERANGE), nothing else can fail.  If the C locale object cannot be created
 * (out of memory at the first call) the functions fall back to the calling
 * thread's locale.
 *
 * Thread safety: every function may be called from any thread at any time;
 * uselocale() changes only the calling thread's locale and restores it
 * before returning.
 */
#ifndef DM_NUMFMT_H
#define DM_NUMFMT_H

#include <locale.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

/* Bytes enough for any dm_num_format output, NUL included. */
#define DM_NUM_BUFSIZE 32

/* Shortest round-trip text of x into buf (see above); returns its length. */
int dm_num_format(char *buf, size_t size, double x);

/* "(x1, x2, ...)" with %.6g (at most 6 entries, then ", ...") into buf, for
 * messages; returns buf. */
const char *dm_num_format_vec(char *buf, size_t size, const double *x, size_t n);

/* snprintf / vsnprintf / fprintf in the "C" locale. */
int dm_num_snprintf(char *buf, size_t size, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;
int dm_num_vsnprintf(char *buf, size_t size, const char *fmt, va_list ap);
int dm_num_fprintf(FILE *f, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;

/* strtod in the "C" locale. */
double dm_num_parse(const char *s, char **end);

/* For loops that format many numbers (files, data blocks): select the "C"
 * locale for the calling thread and return the previous one, which the
 * caller hands back to dm_num_leave.  Plain printf family calls in between
 * use '.' as the decimal point. */
locale_t dm_num_enter(void);
void dm_num_leave(locale_t previous);

#endif
