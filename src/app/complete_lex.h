/* complete_lex.h -- the small Lua lexer of tab completion (complete.c):
 * the tokens of the line before the cursor and its open brackets.  Private
 * to src/app. */
#ifndef DM_COMPLETE_LEX_H
#define DM_COMPLETE_LEX_H

#include <stddef.h>

#define MAX_TOKENS 2048
#define MAX_DEPTH 64

enum { T_NAME, T_STRING, T_OPENSTR, T_NUMBER, T_OP };

typedef struct token {
  int type;
  size_t start, end;     /* [start, end) in the line; for strings the quotes included */
} token;

typedef struct lexed {
  token tok[MAX_TOKENS];
  int ntok;
  int open[MAX_DEPTH];   /* token indices of the open brackets, innermost last */
  int nopen;
  int in_comment;        /* the cursor is in a comment */
} lexed;

/* Tokens of line[0, end).  Returns 0 when the line is too long to read (or
 * the cursor is inside a long string). */
int dm_lex(const char *s, size_t end, lexed *x);
/* 1 when token k is the operator c. */
int dm_lex_is_op(const lexed *x, const char *s, int k, char c);
/* The path ending at token k (NAME ('.' NAME)* [':' NAME]): returns the
 * index of its first token, or -1 when token k does not end a path. */
int dm_lex_path_start(const lexed *x, const char *s, int k);

#endif
