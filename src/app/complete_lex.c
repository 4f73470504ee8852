/* complete_lex.c -- the small Lua lexer of tab completion (complete_lex.h):
 * names, numbers, strings (open or closed, long ones skipped), comments and
 * operators, with the brackets still open at the cursor. */
#include <config.h>

#include <ctype.h>

#include "app/complete_lex.h"

/* Tokens of line[0, end).  Returns 0 when the line is too long to read. */
int dm_lex(const char *s, size_t end, lexed *x)
{
  size_t i = 0;
  x->ntok = x->nopen = x->in_comment = 0;
  while (i < end) {
    unsigned char c = (unsigned char)s[i];
    token *t;
    if (isspace(c)) {
      i++;
      continue;
    }
    if (x->ntok == MAX_TOKENS)
      return 0;
    t = &x->tok[x->ntok];
    t->start = i;
    if (c == '-' && i + 1 < end && s[i + 1] == '-') {
      x->in_comment = 1;                      /* a comment runs to the cursor */
      return 1;
    }
    if (isalpha(c) || c == '_') {
      while (i < end && (isalnum((unsigned char)s[i]) || s[i] == '_'))
        i++;
      t->type = T_NAME;
    } else if (isdigit(c) || (c == '.' && i + 1 < end && isdigit((unsigned char)s[i + 1]))) {
      while (i < end && (isalnum((unsigned char)s[i]) || s[i] == '.'))
        i++;
      t->type = T_NUMBER;
    } else if (c == '"' || c == '\'') {
      i++;
      t->type = T_OPENSTR;
      while (i < end) {
        if (s[i] == '\\') {
          i += 2;
          continue;
        }
        if ((unsigned char)s[i++] == c) {
          t->type = T_STRING;
          break;
        }
      }
      if (i > end)
        i = end;
    } else if (c == '[' && i + 1 < end && (s[i + 1] == '[' || s[i + 1] == '=')) {
      /* a long string: skip to its closing bracket (or the cursor) */
      size_t level = 0, j = i + 1;
      while (j < end && s[j] == '=')
        level++, j++;
      t->type = T_OPENSTR;
      for (j = j + 1; j < end; j++)
        if (s[j] == ']') {
          size_t k = j + 1, l = 0;
          while (k < end && s[k] == '=')
            l++, k++;
          if (l == level && k < end && s[k] == ']') {
            t->type = T_STRING;
            j = k;
            break;
          }
        }
      i = j + 1 < end ? j + 1 : end;
      if (t->type == T_OPENSTR)
        return 0;                              /* no completion inside a long string */
    } else {
      i++;
      t->type = T_OP;
      if (c == '(' || c == '{' || c == '[') {
        if (x->nopen < MAX_DEPTH)
          x->open[x->nopen++] = x->ntok;
      } else if ((c == ')' || c == '}' || c == ']') && x->nopen > 0) {
        x->nopen--;
      }
    }
    t->end = i;
    x->ntok++;
  }
  return 1;
}

int dm_lex_is_op(const lexed *x, const char *s, int k, char c)
{
  return k >= 0 && k < x->ntok && x->tok[k].type == T_OP && s[x->tok[k].start] == c;
}

/* The path ending at token k (NAME ('.' NAME)* [':' NAME]): returns the
 * index of its first token, or -1 when token k does not end a path. */
int dm_lex_path_start(const lexed *x, const char *s, int k)
{
  if (k < 0 || x->tok[k].type != T_NAME)
    return -1;
  while (k >= 2 && x->tok[k - 2].type == T_NAME && (dm_lex_is_op(x, s, k - 1, '.') || dm_lex_is_op(x, s, k - 1, ':')))
    k -= 2;
  /* a path preceded by '.' or ':' belongs to an expression we cannot read */
  if (k >= 1 && (dm_lex_is_op(x, s, k - 1, '.') || dm_lex_is_op(x, s, k - 1, ':') || dm_lex_is_op(x, s, k - 1, ']')
                 || dm_lex_is_op(x, s, k - 1, ')')))
    return -1;
  return k;
}
