/* numfmt.c -- numbers to text and back in the "C" locale (see numfmt.h). */
#include <config.h>
#include "core/numfmt.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

static locale_t c_locale = (locale_t)0;
static pthread_once_t c_once = PTHREAD_ONCE_INIT;

static void c_locale_make(void)
{
  c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
}

static locale_t c_loc(void)
{
  pthread_once(&c_once, c_locale_make);
  return c_locale;
}

locale_t dm_num_enter(void)
{
  locale_t c = c_loc();
  return c != (locale_t)0 ? uselocale(c) : (locale_t)0;
}

void dm_num_leave(locale_t previous)
{
  if (previous != (locale_t)0)
    uselocale(previous);
}

int dm_num_vsnprintf(char *buf, size_t size, const char *fmt, va_list ap)
{
  locale_t old = dm_num_enter();
  int n = vsnprintf(buf, size, fmt, ap);
  dm_num_leave(old);
  return n;
}

int dm_num_snprintf(char *buf, size_t size, const char *fmt, ...)
{
  va_list ap;
  int n;
  va_start(ap, fmt);
  n = dm_num_vsnprintf(buf, size, fmt, ap);
  va_end(ap);
  return n;
}

int dm_num_fprintf(FILE *f, const char *fmt, ...)
{
  va_list ap;
  locale_t old = dm_num_enter();
  int n;
  va_start(ap, fmt);
  n = vfprintf(f, fmt, ap);
  va_end(ap);
  dm_num_leave(old);
  return n;
}

double dm_num_parse(const char *s, char **end)
{
  locale_t c = c_loc();
  return c != (locale_t)0 ? strtod_l(s, end, c) : strtod(s, end);
}

int dm_num_format(char *buf, size_t size, double x)
{
  char tmp[DM_NUM_BUFSIZE];
  locale_t old;
  int prec;
  if (isnan(x))
    return snprintf(buf, size, "nan");
  if (isinf(x))
    return snprintf(buf, size, x > 0 ? "inf" : "-inf");
  old = dm_num_enter();
  for (prec = 15; prec < 17; prec++) {
    snprintf(tmp, sizeof tmp, "%.*g", prec, x);
    if (strtod(tmp, NULL) == x)
      break;
  }
  if (prec == 17)
    snprintf(tmp, sizeof tmp, "%.17g", x);
  dm_num_leave(old);
  return snprintf(buf, size, "%s", tmp);
}

const char *dm_num_format_vec(char *buf, size_t size, const double *x, size_t n)
{
  size_t i, k = 0;
  locale_t old;
  if (size == 0)
    return buf;
  old = dm_num_enter();
  k += (size_t)snprintf(buf, size, "(");
  for (i = 0; i < n && i < 6 && k < size; i++)
    k += (size_t)snprintf(buf + k, size - k, "%s%.6g", i ? ", " : "", x[i]);
  if (k < size)
    snprintf(buf + k, size - k, "%s)", n > 6 ? ", ..." : "");
  dm_num_leave(old);
  return buf;
}
