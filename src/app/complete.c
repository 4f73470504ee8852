/* complete.c -- tab completion at the prompt.
 *
 * What the text before the cursor asks for:
 *   a.b.c<TAB>, obj:m<TAB>   keys of tables (raw, along __index tables),
 *                            methods of objects and, for dmech's objects,
 *                            their documented fields ("system.coords");
 *                            names starting with '_' only when the partial
 *                            name does (dm._gp stays hidden);
 *   "...<TAB>                inside a string: the names its context asks
 *                            for -- columns of a trajectory (tr:column("th,
 *                            {tr, "x", "), coordinates of a system
 *                            (sys:momentum(q, v, "th), keys of a table
 *                            (t["k) -- else file names;
 *   {key<TAB>                inside the options table of a call: the option
 *                            keys documented for the function
 *                            (dm.integrator(sys, {met, I:run(s, {st,
 *                            dm.plot{ti), beside the usual names.
 * The line is read by a small Lua lexer (strings, comments, brackets).
 * Completion never runs user code: tables are read raw; only dmech's own
 * classes (their metatable is in the "dmech.classes" registry table) are
 * asked, through their C functions, for a field (__index) or for names
 * (the method `names`, the field `coords`, the field `system`).
 */
#include <config.h>

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include <lauxlib.h>
#include <lua.h>

#include "app/complete_lex.h"
#include "app/repl.h"

#ifdef HAVE_READLINE
#include <readline/readline.h>

#define MAX_CHAIN 8

static lua_State *complL = NULL;
static const char *const break_chars = " \t\n\"\\'`@$><=;|&{(,+-*/^%[]#~)";

/* {======================================================================
 * values, read without running user code
 * ======================================================================= */

/* The kind of a dmech object (pushes nothing), or NULL. */
static const char *dmech_kind(lua_State *L, int idx)
{
  const char *kind = NULL;
  idx = lua_absindex(L, idx);
  if (!lua_getmetatable(L, idx))
    return NULL;
  if (lua_getfield(L, LUA_REGISTRYINDEX, "dmech.classes") == LUA_TTABLE) {
    lua_pushvalue(L, -2);
    if (lua_rawget(L, -2) == LUA_TSTRING)
      kind = lua_tostring(L, -1);      /* anchored in the classes table */
    lua_pop(L, 1);
  }
  lua_pop(L, 2);
  return kind;
}

/* Push the method table of the value at idx (its metatable's __index when a
 * table, else __methods), or nil. */
static void push_index_table(lua_State *L, int idx)
{
  idx = lua_absindex(L, idx);
  if (!lua_getmetatable(L, idx)) {
    lua_pushnil(L);
    return;
  }
  lua_pushliteral(L, "__index");
  lua_rawget(L, -2);
  if (!lua_istable(L, -1)) {
    lua_pop(L, 1);
    lua_pushliteral(L, "__methods");
    lua_rawget(L, -2);
    if (!lua_istable(L, -1)) {
      lua_pop(L, 1);
      lua_pushnil(L);
    }
  }
  lua_remove(L, -2);
}

/* Push the documentation registry (name -> {name=, sig=, doc=[, opts=]}). */
static void push_docs(lua_State *L)
{
  if (lua_getfield(L, LUA_REGISTRYINDEX, "dmech.docs") != LUA_TTABLE) {
    lua_pop(L, 1);
    lua_newtable(L);
  }
}

/* Is `kind.key` a documented field? */
static int documented_field(lua_State *L, const char *kind, const char *key, size_t len)
{
  int found;
  push_docs(L);
  lua_pushfstring(L, "%s.%s", kind, key);
  (void)len;
  found = lua_rawget(L, -2) == LUA_TTABLE;
  lua_pop(L, 2);
  return found;
}

static int call_index(lua_State *L)
{
  lua_gettable(L, 1);
  return 1;
}

/* Push field `key` of a dmech object through its own C __index (guarded). */
static void dmech_field(lua_State *L, int idx, const char *key)
{
  idx = lua_absindex(L, idx);
  lua_pushcfunction(L, call_index);
  lua_pushvalue(L, idx);
  lua_pushstring(L, key);
  if (lua_pcall(L, 2, 1, 0) != LUA_OK) {
    lua_pop(L, 1);
    lua_pushnil(L);
  }
}

/* Raw lookup of key in the value at idx, following __index tables; dmech
 * objects also answer their documented fields. */
static void raw_lookup(lua_State *L, int idx, const char *key, size_t len)
{
  int depth;
  const char *kind;
  idx = lua_absindex(L, idx);
  if ((kind = dmech_kind(L, idx)) != NULL) {
    char k[128];
    if (len < sizeof k) {
      memcpy(k, key, len);
      k[len] = '\0';
      if (documented_field(L, kind, k, len)) {
        dmech_field(L, idx, k);
        return;
      }
    }
  }
  lua_pushvalue(L, idx);
  for (depth = 0; depth < MAX_CHAIN; depth++) {
    if (lua_istable(L, -1)) {
      lua_pushlstring(L, key, len);
      lua_rawget(L, -2);
      if (!lua_isnil(L, -1)) {
        lua_remove(L, -2);
        return;
      }
      lua_pop(L, 1);
    }
    push_index_table(L, -1);
    lua_remove(L, -2);
    if (lua_isnil(L, -1))
      return;
  }
  lua_pop(L, 1);
  lua_pushnil(L);
}

/* Push the value of the path in s[a, b) ("tr", "red.system"); nil when any
 * step is missing.  A ':' in the path resolves to its receiver. */
static void push_path(lua_State *L, const char *s, size_t a, size_t b)
{
  size_t p = a;
  lua_pushglobaltable(L);
  while (p < b) {
    size_t q = p;
    while (q < b && s[q] != '.' && s[q] != ':')
      q++;
    raw_lookup(L, -1, s + p, q - p);
    lua_remove(L, -2);
    if (lua_isnil(L, -1) || q >= b || s[q] == ':')
      return;
    p = q + 1;
  }
}

/* }====================================================================== */

/* {======================================================================
 * candidates
 * ======================================================================= */

/* cands[name] = true when name starts with part (and '_' names only when
 * part starts with '_'; identifiers only unless any). */
static void add_cand(lua_State *L, int cands, const char *name, const char *part, int any)
{
  size_t plen = strlen(part);
  if (strncmp(name, part, plen) != 0)
    return;
  if (name[0] == '_' && part[0] != '_')
    return;
  if (!any) {
    const char *c = name;
    if (!(isalpha((unsigned char)*c) || *c == '_'))
      return;
    for (c++; *c; c++)
      if (!(isalnum((unsigned char)*c) || *c == '_'))
        return;
  }
  lua_pushstring(L, name);
  lua_pushboolean(L, 1);
  lua_rawset(L, cands);
}

/* The string keys of the table at the top (popped: no) starting with part. */
static void collect_keys(lua_State *L, const char *part, int cands, int any)
{
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    if (lua_type(L, -2) == LUA_TSTRING)
      add_cand(L, cands, lua_tostring(L, -2), part, any);
    lua_pop(L, 1);
  }
}

/* Strings of the list at the top (popped) starting with part. */
static void collect_list(lua_State *L, const char *part, int cands)
{
  lua_Integer i, n;
  if (lua_istable(L, -1)) {
    n = (lua_Integer)lua_rawlen(L, -1);
    for (i = 1; i <= n; i++) {
      if (lua_rawgeti(L, -1, i) == LUA_TSTRING)
        add_cand(L, cands, lua_tostring(L, -1), part, 1);
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
}

/* The documented fields "<kind>.<field>" starting with part. */
static void collect_fields(lua_State *L, const char *kind, const char *part, int cands)
{
  size_t klen = strlen(kind);
  push_docs(L);
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    if (lua_type(L, -2) == LUA_TSTRING) {
      const char *n = lua_tostring(L, -2);
      if (strncmp(n, kind, klen) == 0 && n[klen] == '.')
        add_cand(L, cands, n + klen + 1, part, 0);
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

/* Members of the value at the top (popped) after '.' (fields and methods)
 * or ':' (methods only). */
static void collect_members(lua_State *L, const char *part, int cands, int methods_only)
{
  const char *kind = dmech_kind(L, -1);
  int depth;
  if (kind != NULL && !methods_only)
    collect_fields(L, kind, part, cands);
  if (methods_only) {
    push_index_table(L, -1);
    lua_remove(L, -2);
  }
  for (depth = 0; depth < MAX_CHAIN && !lua_isnil(L, -1); depth++) {
    if (lua_istable(L, -1))
      collect_keys(L, part, cands, 0);
    push_index_table(L, -1);
    lua_remove(L, -2);
  }
  lua_pop(L, 1);
}

static int call_names(lua_State *L)
{
  lua_getfield(L, 2, "names");          /* methods table, upvalue-free C function */
  lua_pushvalue(L, 1);
  lua_call(L, 1, 1);
  return 1;
}

/* The names the value at the top (popped) offers for strings: keys of a
 * table; for dmech objects their method `names`, field `coords`, or the
 * names of their field `system`. */
static void collect_names(lua_State *L, const char *part, int cands, int depth)
{
  const char *kind = dmech_kind(L, -1);
  if (kind == NULL) {
    if (lua_istable(L, -1))
      collect_keys(L, part, cands, 1);
    lua_pop(L, 1);
    return;
  }
  {
    char name[80];
    int has_names;
    snprintf(name, sizeof name, "%s:names", kind);
    push_docs(L);
    has_names = lua_getfield(L, -1, name) == LUA_TTABLE;
    lua_pop(L, 2);
    if (has_names) {
      push_index_table(L, -1);
      lua_getfield(L, -1, "names");
      if (lua_iscfunction(L, -1)) {
        lua_pop(L, 1);
        lua_pushcfunction(L, call_names);
        lua_pushvalue(L, -3);
        lua_pushvalue(L, -3);
        if (lua_pcall(L, 2, 1, 0) == LUA_OK)
          collect_list(L, part, cands);
        else
          lua_pop(L, 1);
        lua_pop(L, 2);
        return;
      }
      lua_pop(L, 2);
    }
  }
  if (documented_field(L, kind, "coords", 6)) {
    dmech_field(L, -1, "coords");
    collect_list(L, part, cands);
  } else if (depth < 2 && documented_field(L, kind, "system", 6)) {
    dmech_field(L, -1, "system");
    collect_names(L, part, cands, depth + 1);
  }
  lua_pop(L, 1);
}

/* Push the value of the path whose tokens end at token k, or nil. */
static void push_path_tokens(lua_State *L, const lexed *x, const char *s, int k)
{
  int a = dm_lex_path_start(x, s, k);
  if (a < 0)
    lua_pushnil(L);
  else
    push_path(L, s, x->tok[a].start, x->tok[k].end);
}

/* The token that ends the first element after the bracket at token b (a
 * path followed by ',' or ';'), or -1. */
static int first_element(const lexed *x, const char *s, int b)
{
  int k = b + 1;
  while (k + 2 < x->ntok && x->tok[k].type == T_NAME && (dm_lex_is_op(x, s, k + 1, '.')))
    k += 2;
  if (k < x->ntok && x->tok[k].type == T_NAME && k + 1 < x->ntok
      && (dm_lex_is_op(x, s, k + 1, ',') || dm_lex_is_op(x, s, k + 1, ';')))
    return k;
  return -1;
}

/* Names for the open string at the end of the line: from the innermost
 * bracket outwards, the first context that offers any. */
static void string_names(lua_State *L, const lexed *x, const char *s, const char *part, int cands)
{
  int d;
  for (d = x->nopen - 1; d >= 0; d--) {
    int b = x->open[d];
    char c = s[x->tok[b].start];
    int before = b - 1;
    if (c == '[') {                                     /* t["k */
      push_path_tokens(L, x, s, before);
      collect_names(L, part, cands, 0);
    } else if (c == '(' && before >= 2 && dm_lex_is_op(x, s, before - 1, ':')) {  /* obj:m("x */
      push_path_tokens(L, x, s, before - 2);
      collect_names(L, part, cands, 0);
    } else if (c == '(') {                              /* f(obj, "x */
      int e = first_element(x, s, b);
      if (e >= 0) {
        push_path_tokens(L, x, s, e);
        collect_names(L, part, cands, 0);
      }
    } else if (c == '{') {                              /* {obj, "x", "y */
      int e = first_element(x, s, b);
      if (e >= 0) {
        push_path_tokens(L, x, s, e);
        collect_names(L, part, cands, 0);
      }
    }
    lua_pushnil(L);
    if (lua_next(L, cands) != 0) {
      lua_pop(L, 2);
      return;
    }
  }
}

/* Option keys when the cursor is at a key position of a table that is the
 * options argument of a call: f{, f(a, {, obj:m(a, {. */
static void option_keys(lua_State *L, const lexed *x, const char *s, int last, const char *part,
                        int cands)
{
  int b, k, callee;
  if (x->nopen == 0)
    return;
  b = x->open[x->nopen - 1];
  if (s[x->tok[b].start] != '{')
    return;
  /* a key position: right after '{', ',' or ';' */
  k = last;
  if (!(k == b || dm_lex_is_op(x, s, k, ',') || dm_lex_is_op(x, s, k, ';')))
    return;
  if (b >= 1 && x->tok[b - 1].type == T_NAME) {
    callee = b - 1;                                     /* f{ */
  } else if (x->nopen >= 2 && (dm_lex_is_op(x, s, b - 1, '(') || dm_lex_is_op(x, s, b - 1, ','))) {
    int p = x->open[x->nopen - 2];
    if (s[x->tok[p].start] != '(')
      return;
    callee = p - 1;                                     /* f(..., { */
  } else {
    return;
  }
  if (callee < 0 || x->tok[callee].type != T_NAME)
    return;
  {
    int a = dm_lex_path_start(x, s, callee);
    if (a < 0)
      return;
    push_docs(L);
    if (callee >= 2 && dm_lex_is_op(x, s, callee - 1, ':')) {    /* obj:m(..., { */
      const char *kind;
      push_path(L, s, x->tok[a].start, x->tok[callee - 2].end);
      kind = dmech_kind(L, -1);
      lua_pop(L, 1);
      if (kind == NULL) {
        lua_pop(L, 1);
        return;
      }
      lua_pushfstring(L, "%s:", kind);
      lua_pushlstring(L, s + x->tok[callee].start, x->tok[callee].end - x->tok[callee].start);
      lua_concat(L, 2);
      lua_rawget(L, -2);
    } else {                                            /* by value: docvals */
      lua_pop(L, 1);
      lua_getfield(L, LUA_REGISTRYINDEX, "dmech.docvals");
      push_path(L, s, x->tok[a].start, x->tok[callee].end);
      if (!lua_istable(L, -2) || lua_isnil(L, -1)) {
        lua_pop(L, 2);
        return;
      }
      lua_rawget(L, -2);
    }
    if (lua_istable(L, -1) && lua_getfield(L, -1, "opts") == LUA_TTABLE) {
      collect_list(L, part, cands);
    } else {
      lua_pop(L, 1);
    }
    lua_pop(L, 2);
  }
}

/* }====================================================================== */

/* {======================================================================
 * Readline glue
 * ======================================================================= */

static char quote_char = '\0';   /* the open string's quote, for a unique match */

/* The word to complete: inside a string the whole string so far (file
 * names have '/'), else the usual Lua word. */
static char *word_break_hook(void)
{
  static lexed x;
  quote_char = '\0';
  if (dm_lex(rl_line_buffer, (size_t)rl_point, &x) && x.ntok > 0 && !x.in_comment
      && x.tok[x.ntok - 1].type == T_OPENSTR) {
    quote_char = rl_line_buffer[x.tok[x.ntok - 1].start];
    return quote_char == '"' ? "\"" : "'";
  }
  return (char *)break_chars;
}

/* Sorted "<prefix><name>" array for Readline from the candidate set. */
static char **make_matches(lua_State *L, int cands, const char *text, size_t prefixlen, int top)
{
  char **matches;
  int n = 0, i;
  lua_newtable(L);
  lua_pushnil(L);
  while (lua_next(L, cands) != 0) {
    lua_pop(L, 1);
    lua_pushvalue(L, -1);
    lua_rawseti(L, -3, ++n);
  }
  if (n == 0) {
    lua_settop(L, top);
    return NULL;
  }
  lua_getglobal(L, "table");
  if (lua_istable(L, -1) && lua_getfield(L, -1, "sort") == LUA_TFUNCTION) {
    lua_remove(L, -2);
    lua_pushvalue(L, -2);
    if (lua_pcall(L, 1, 0, 0) != LUA_OK)
      lua_pop(L, 1);
  } else {
    lua_pop(L, 2);
  }
  matches = malloc(((size_t)n + 2) * sizeof *matches);
  if (matches == NULL) {
    lua_settop(L, top);
    return NULL;
  }
  for (i = 1; i <= n; i++) {
    size_t klen;
    const char *k;
    lua_rawgeti(L, -1, i);
    k = lua_tolstring(L, -1, &klen);
    matches[i] = malloc(prefixlen + klen + 1);
    if (matches[i] != NULL) {
      memcpy(matches[i], text, prefixlen);
      memcpy(matches[i] + prefixlen, k, klen + 1);
    }
    lua_pop(L, 1);
  }
  matches[n + 1] = NULL;
  /* matches[0]: the longest common prefix of all candidates */
  {
    size_t lcp = matches[1] ? strlen(matches[1]) : 0;
    for (i = 2; i <= n; i++) {
      size_t j = 0;
      while (matches[i] && j < lcp && matches[i][j] == matches[1][j])
        j++;
      lcp = j;
    }
    matches[0] = malloc(lcp + 1);
    if (matches[0] != NULL && matches[1] != NULL) {
      memcpy(matches[0], matches[1], lcp);
      matches[0][lcp] = '\0';
    }
  }
  if (n == 1) {                            /* single match: no list */
    free(matches[0]);
    matches[0] = matches[1];
    matches[1] = NULL;
  }
  lua_settop(L, top);
  return matches;
}

static char **file_matches(const char *text)
{
  char **m;
  rl_filename_completion_desired = 1;
  rl_filename_quoting_desired = 0;
  m = rl_completion_matches(text, rl_filename_completion_function);
  if (m != NULL && m[1] == NULL)          /* a unique file: close the string */
    rl_completion_append_character = quote_char;
  return m;
}

static char **complete_string(lua_State *L, const lexed *x, const char *text, int top)
{
  int cands;
  char **m;
  lua_newtable(L);
  cands = lua_gettop(L);
  string_names(L, x, rl_line_buffer, text, cands);
  lua_pushnil(L);
  if (lua_next(L, cands) == 0) {
    lua_settop(L, top);
    return file_matches(text);
  }
  lua_pop(L, 2);
  m = make_matches(L, cands, text, 0, top);
  if (m != NULL && m[1] == NULL)
    rl_completion_append_character = quote_char;
  return m;
}

static void keywords(lua_State *L, const char *p, int cands)
{
  static const char *const kw[] = {"and", "break", "do", "else", "elseif",
    "end", "false", "for", "function", "goto", "if", "in", "local", "nil",
    "not", "or", "repeat", "return", "then", "true", "until", "while", NULL};
  int i;
  for (i = 0; kw[i] != NULL; i++)
    add_cand(L, cands, kw[i], p, 0);
}

static char **dm_completion(const char *text, int start, int end)
{
  lua_State *L = complL;
  static lexed x;
  const char *sep, *p, *last = NULL;
  int top, cands, opts;
  char **matches;
  (void)end;
  rl_attempted_completion_over = 1;        /* never fall back to file names */
  rl_completion_append_character = '\0';   /* reset by Readline each time */
  if (L == NULL || !dm_lex(rl_line_buffer, (size_t)rl_point, &x) || x.in_comment)
    return NULL;
  top = lua_gettop(L);
  if (!lua_checkstack(L, 40))
    return NULL;
  if (x.ntok > 0 && x.tok[x.ntok - 1].type == T_OPENSTR)
    return complete_string(L, &x, text, top);
  lua_newtable(L);
  opts = lua_gettop(L);
  lua_newtable(L);
  cands = lua_gettop(L);
  /* the tokens before the word being completed */
  {
    int k = x.ntok - 1;
    while (k >= 0 && x.tok[k].start >= (size_t)start)
      k--;
    if (strpbrk(text, ".:") == NULL) {
      option_keys(L, &x, rl_line_buffer, k, text, opts);
      lua_pushnil(L);
      while (lua_next(L, opts) != 0) {
        lua_pushvalue(L, -2);
        lua_insert(L, -2);
        lua_rawset(L, cands);
      }
    }
    if (k >= 0 && (dm_lex_is_op(&x, rl_line_buffer, k, '.') || dm_lex_is_op(&x, rl_line_buffer, k, ':'))) {
      lua_settop(L, top);                  /* after an expression we cannot read */
      return NULL;
    }
  }
  lua_pushglobaltable(L);
  p = text;
  /* walk the path: every segment followed by '.' or ':' */
  while ((sep = strpbrk(p, ".:")) != NULL) {
    raw_lookup(L, -1, p, (size_t)(sep - p));
    lua_remove(L, -2);
    last = sep;
    p = sep + 1;
    if (lua_isnil(L, -1) || *sep == ':')
      break;
  }
  if (last != NULL && *last == ':' && strpbrk(p, ".:") != NULL) {
    lua_settop(L, top);
    return NULL;
  }
  if (!lua_isnil(L, -1))
    collect_members(L, p, cands, last != NULL && *last == ':');
  else
    lua_pop(L, 1);
  if (last == NULL)
    keywords(L, p, cands);
  {
    /* a unique option key completes with " = ": "met" -> "method = " */
    int unique_opt = 0, n = 0;
    lua_pushnil(L);
    while (lua_next(L, cands) != 0) {
      lua_pop(L, 1);
      if (++n == 1) {
        lua_pushvalue(L, -1);
        unique_opt = lua_rawget(L, opts) != LUA_TNIL;
        lua_pop(L, 1);
      }
    }
    matches = make_matches(L, cands, text, (size_t)(p - text), top);
    if (matches != NULL && matches[1] == NULL && n == 1 && unique_opt) {
      size_t len = strlen(matches[0]);
      char *withe = realloc(matches[0], len + 4);
      if (withe != NULL) {
        memcpy(withe + len, " = ", 4);
        matches[0] = withe;
      }
    }
  }
  return matches;
}

void dm_complete_init(lua_State *L)
{
  complL = L;
  rl_attempted_completion_function = dm_completion;
  rl_completion_word_break_hook = word_break_hook;
  rl_completer_word_break_characters = (char *)break_chars;
  rl_completion_append_character = '\0';
  rl_basic_quote_characters = "\"'";
}

/* }====================================================================== */

#else

void dm_complete_init(lua_State *L)
{
  (void)L;
}

#endif
