/* escape.c -- user strings as gnuplot string expressions.
 *
 * Inside gnuplot single quotes nothing is special except the quote itself:
 * no backslash escapes, no `@macro` expansion, no backtick command
 * substitution.  gnuplot documents '' as a quote inside single quotes, but
 * its scanner (5.4) mis-reads a string that starts with '' or has two ''
 * in a row, so a quote is written as the concatenation '."'".' instead, and
 * a newline (which a single-quoted string cannot hold) as '."\n".' --
 * every place that takes a string (titles, labels, key entries, file
 * names) takes a string expression.  Other control characters (including
 * NUL) become spaces, so nothing a user writes can end the command line.
 */
#include <config.h>

#include <string.h>

#include "plot/gnuplot.h"

/* Append c to dst if it fits (keeping room for the NUL); count it anyway. */
static void put(char *dst, size_t size, size_t *k, const char *s, size_t n)
{
  size_t i;
  for (i = 0; i < n; i++, (*k)++)
    if (*k + 1 < size)
      dst[*k] = s[i];
}

size_t dm_gp_quote(char *dst, size_t size, const char *src, size_t len,
                   int flags)
{
  static const char nl[] = "'.\"\\n\".'", quote[] = "'.\"'\".'";
  size_t i, k = 0;
  put(dst, size, &k, "'", 1);
  for (i = 0; i < len; i++) {
    unsigned char c = (unsigned char)src[i];
    if (c == '\r' || c == '\n') {
      if (c == '\r' && i + 1 < len && src[i + 1] == '\n')
        i++;
      if (flags & DM_GP_QUOTE_ONELINE)
        put(dst, size, &k, " ", 1);
      else
        put(dst, size, &k, nl, sizeof nl - 1);
    } else if (c == '\'') {
      put(dst, size, &k, quote, sizeof quote - 1);
    } else if ((c < 0x20 && c != '\t') || c == 0x7f) {
      put(dst, size, &k, " ", 1);
    } else {
      put(dst, size, &k, (const char *)&src[i], 1);
    }
  }
  put(dst, size, &k, "'", 1);
  if (size > 0)
    dst[k < size ? k : size - 1] = '\0';
  return k;
}

int dm_gp_valid_name(const char *name)
{
  size_t i;
  if (name == NULL || name[0] == '\0' || strlen(name) > 64)
    return 0;
  for (i = 0; name[i] != '\0'; i++) {
    char c = name[i];
    int alpha = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    if (!alpha && !(i > 0 && c >= '0' && c <= '9'))
      return 0;
  }
  return 1;
}

/* A `with` style a user wrote: words, numbers, spaces, . , : # + - and
 * quoted colour names ('#ff8800', "dark-red"); nothing that could end the
 * command or call a function (; @ ` $ ( ) { } \ newline). */
int dm_gp_valid_style(const char *style)
{
  const char *p;
  if (style == NULL || style[0] == '\0' || strlen(style) > 200)
    return 0;
  for (p = style; *p != '\0'; p++) {
    char c = *p;
    if (c == '\'' || c == '"') {
      const char *q = p + 1;
      while (*q != '\0' && *q != c) {
        char d = *q++;
        if (!((d >= 'a' && d <= 'z') || (d >= 'A' && d <= 'Z')
              || (d >= '0' && d <= '9') || d == '#' || d == '_' || d == ' '
              || d == '-' || d == '.'))
          return 0;
      }
      if (*q != c)
        return 0;
      p = q;
      continue;
    }
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')
          || (c >= '0' && c <= '9') || c == ' ' || c == '.' || c == ','
          || c == ':' || c == '#' || c == '+' || c == '-' || c == '_'))
      return 0;
  }
  return 1;
}
