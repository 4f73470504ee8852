/* escape.c -- user strings as gnuplot string expressions.
 *
 * gnuplot reads a command line with several scanners that each track
 * quotes their own way: the lexer, the `@macro` expander and the backtick
 * command substitution.  They agree only on simple single-quoted text.
 * Measured with 5.4: '' (the documented quote-in-quotes) breaks the lexer
 * when two come in a row or at the start, and a quote inside a double-quoted
 * piece ('a'."'".'b @m') flips the macro expander's idea of "inside quotes",
 * so a later @m is expanded.  Hence the encoding: runs of ordinary
 * characters go in single quotes; every character that any scanner treats
 * specially -- ' " \ ` @ -- and newlines go as octal escapes in a
 * double-quoted piece ("\047"), so the text sent contains no quote, backtick,
 * at-sign or backslash-before-quote that a scanner could misread:
 *
 *     it's @home  ->  'it'."\047".'s '."\100".'home'
 *
 * Other control characters (including NUL) become spaces, so nothing a
 * user writes can end the command line.  Every place that takes a string
 * (titles, labels, key entries, file names) takes a string expression.
 */
#include <config.h>

#include <stdio.h>
#include <string.h>

#include "plot/gnuplot.h"

/* Append s[0..n) to dst if it fits (keeping room for the NUL); count it
 * anyway. */
static void put(char *dst, size_t size, size_t *k, const char *s, size_t n)
{
  size_t i;
  for (i = 0; i < n; i++, (*k)++)
    if (*k + 1 < size)
      dst[*k] = s[i];
}

/* 0: ordinary, 1: octal escape, 2: becomes a space; newline handled apart */
static int klass(unsigned char c)
{
  if (c == '\'' || c == '"' || c == '\\' || c == '`' || c == '@')
    return 1;
  if ((c < 0x20 && c != '\t') || c == 0x7f)
    return 2;
  return 0;
}

size_t dm_gp_quote(char *dst, size_t size, const char *src, size_t len,
                   int flags)
{
  size_t i, k = 0;
  int state = 0;   /* 0: nothing yet, 1: inside '...', 2: inside "..." */
  for (i = 0; i < len; i++) {
    unsigned char c = (unsigned char)src[i];
    int nl = c == '\n' || c == '\r', cls = nl ? 1 : klass(c);
    if (nl && (flags & DM_GP_QUOTE_ONELINE)) {
      cls = 0;
      c = ' ';
    } else if (cls == 2) {
      cls = 0;
      c = ' ';
    }
    if (nl && c == '\r' && i + 1 < len && src[i + 1] == '\n')
      i++;                                      /* \r\n is one newline */
    if (cls == 0 && state != 1) {
      put(dst, size, &k, state == 2 ? "\".'" : "'", state == 2 ? 3 : 1);
      state = 1;
    } else if (cls == 1 && state != 2) {
      put(dst, size, &k, state == 1 ? "'.\"" : "\"", state == 1 ? 3 : 1);
      state = 2;
    }
    if (cls == 0) {
      put(dst, size, &k, (const char *)&c, 1);
    } else {
      char oct[8];
      snprintf(oct, sizeof oct, "\\%03o", nl ? '\n' : c);
      put(dst, size, &k, oct, 4);
    }
  }
  if (state == 0)
    put(dst, size, &k, "''", 2);
  else
    put(dst, size, &k, state == 1 ? "'" : "\"", 1);
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
