/* tap.h -- a tiny TAP producer for the C unit tests (header only).
 *
 *   tap_plan(n) or tap_noplan() ... tap_ok(cond, fmt, ...), tap_near(x, y, tol,
 *   fmt, ...) (relative when |y| > 1, else absolute), tap_is_int(),
 *   tap_skip(reason), then
 *   return tap_done();  tap_done() prints the plan when none was given and
 *   returns the exit status (0 iff everything passed).
 */
#ifndef DM_TAP_H
#define DM_TAP_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

static int tap_n = 0, tap_failed = 0, tap_planned = -1;

static inline void tap_plan(int n) { tap_planned = n; printf("1..%d\n", n); }
static inline void tap_noplan(void) { tap_planned = -1; }

static inline void tap_vreport(int pass, const char *fmt, va_list ap)
{
  tap_n++;
  if (!pass) tap_failed++;
  printf("%s %d - ", pass ? "ok" : "not ok", tap_n);
  vprintf(fmt, ap);
  printf("\n");
  fflush(stdout);
}

#if defined(__GNUC__)
#define TAP_FMT(a, b) __attribute__((format(printf, a, b)))
#else
#define TAP_FMT(a, b)
#endif

static inline int tap_ok(int pass, const char *fmt, ...) TAP_FMT(2, 3);
static inline int tap_ok(int pass, const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  tap_vreport(pass, fmt, ap);
  va_end(ap);
  return pass;
}

/* |got - want| <= tol * max(1, |want|); NaN never passes. */
static inline int tap_near(double got, double want, double tol, const char *fmt, ...) TAP_FMT(4, 5);
static inline int tap_near(double got, double want, double tol, const char *fmt, ...)
{
  double scale = fabs(want) > 1.0 ? fabs(want) : 1.0;
  int pass = fabs(got - want) <= tol * scale;
  va_list ap;
  va_start(ap, fmt);
  tap_vreport(pass, fmt, ap);
  va_end(ap);
  if (!pass)
    printf("#   got %.17g, want %.17g, |diff| %.3g > %.3g\n", got, want,
           fabs(got - want), tol * scale);
  return pass;
}

static inline int tap_is_int(long got, long want, const char *fmt, ...) TAP_FMT(3, 4);
static inline int tap_is_int(long got, long want, const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  tap_vreport(got == want, fmt, ap);
  va_end(ap);
  if (got != want)
    printf("#   got %ld, want %ld\n", got, want);
  return got == want;
}

static inline void tap_diag(const char *fmt, ...) TAP_FMT(1, 2);
static inline void tap_diag(const char *fmt, ...)
{
  va_list ap;
  printf("# ");
  va_start(ap, fmt);
  vprintf(fmt, ap);
  va_end(ap);
  printf("\n");
}

/* A test point not run here: "ok n # SKIP reason". */
static inline void tap_skip(const char *reason)
{
  tap_n++;
  printf("ok %d # SKIP %s\n", tap_n, reason);
  fflush(stdout);
}

static inline int tap_done(void)
{
  if (tap_planned < 0)
    printf("1..%d\n", tap_n);
  else if (tap_planned != tap_n)
    printf("# planned %d tests but ran %d\n", tap_planned, tap_n);
  fflush(stdout);
  return (tap_failed == 0 && (tap_planned < 0 || tap_planned == tap_n)) ? 0 : 1;
}

#endif
