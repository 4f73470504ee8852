/* complete.c -- tab completion of Lua names at the prompt.
 *
 * The word before the cursor is split at its last '.' or ':' into a path
 * ("dm", "v:..." ) and a partial name.  The path is resolved from the globals
 * with raw access only, and candidates are the string keys of the table
 * reached, of the tables its metatable's __index chain leads to, and -- for
 * userdata and after ':' -- of the method table (__index when it is a table,
 * else dmech's __methods).  Completion never calls a metamethod or any other
 * user code.
 */
#include <config.h>

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include <lauxlib.h>
#include <lua.h>

#include "app/repl.h"

#ifdef HAVE_READLINE
#include <readline/readline.h>

#define MAX_CHAIN 8

static lua_State *complL = NULL;

static int is_ident(const char *s)
{
  if (!(isalpha((unsigned char)*s) || *s == '_'))
    return 0;
  for (s++; *s; s++)
    if (!(isalnum((unsigned char)*s) || *s == '_'))
      return 0;
  return 1;
}

/* Push the method/field table to search for the value at idx when reached
 * with ':' (methods) or '.' (fields); pushes nil when there is none. */
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

/* Raw lookup of key in the value at idx, following __index tables. */
static void raw_lookup(lua_State *L, int idx, const char *key, size_t len)
{
  int depth;
  idx = lua_absindex(L, idx);
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

/* Add the identifier keys of the table at the top starting with `part`. */
static void collect(lua_State *L, const char *part, int cands)
{
  size_t plen = strlen(part);
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    if (lua_type(L, -2) == LUA_TSTRING) {
      const char *k = lua_tostring(L, -2);
      if (strncmp(k, part, plen) == 0 && is_ident(k)) {
        lua_pushvalue(L, -2);
        lua_pushboolean(L, 1);
        lua_rawset(L, cands);
      }
    }
    lua_pop(L, 1);
  }
}

static char **dm_completion(const char *text, int start, int end)
{
  lua_State *L = complL;
  const char *sep;
  int top, cands, depth, n, i;
  char **matches;
  size_t prefixlen;
  (void)start;
  (void)end;
  rl_attempted_completion_over = 1;        /* never fall back to file names */
  rl_completion_append_character = '\0';   /* reset by Readline each time */
  if (L == NULL)
    return NULL;
  top = lua_gettop(L);
  if (!lua_checkstack(L, 20))
    return NULL;
  lua_newtable(L);
  cands = lua_gettop(L);
  sep = strpbrk(text, ".:");
  lua_pushglobaltable(L);
  {
    const char *p = text, *last = NULL;
    /* walk the path: every segment followed by '.' or ':' */
    while ((sep = strpbrk(p, ".:")) != NULL) {
      raw_lookup(L, -1, p, (size_t)(sep - p));
      lua_remove(L, -2);
      last = sep;
      p = sep + 1;
      if (lua_isnil(L, -1) || *sep == ':')
        break;
    }
    if (last != NULL && *last == ':') {
      if (strpbrk(p, ".:") != NULL) {
        lua_settop(L, top);
        return NULL;
      }
      push_index_table(L, -1);            /* methods only */
      lua_remove(L, -2);
    }
    prefixlen = (size_t)(p - text);
    if (!lua_isnil(L, -1)) {
      /* fields of the table and along its __index chain */
      for (depth = 0; depth < MAX_CHAIN && !lua_isnil(L, -1); depth++) {
        if (lua_istable(L, -1))
          collect(L, p, cands);
        push_index_table(L, -1);
        lua_remove(L, -2);
      }
    }
    lua_pop(L, 1);
    if (last == NULL) {                     /* keywords at the top level */
      static const char *const kw[] = {"and", "break", "do", "else", "elseif",
        "end", "false", "for", "function", "goto", "if", "in", "local", "nil",
        "not", "or", "repeat", "return", "then", "true", "until", "while", NULL};
      size_t plen = strlen(p);
      for (i = 0; kw[i] != NULL; i++)
        if (strncmp(kw[i], p, plen) == 0) {
          lua_pushstring(L, kw[i]);
          lua_pushboolean(L, 1);
          lua_rawset(L, cands);
        }
    }
  }
  /* candidates -> sorted array of "<prefix><name>" */
  lua_newtable(L);
  n = 0;
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
  lua_getfield(L, -1, "sort");
  lua_remove(L, -2);
  lua_pushvalue(L, -2);
  if (lua_pcall(L, 1, 0, 0) != LUA_OK)
    lua_pop(L, 1);
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
    size_t lcp = strlen(matches[1]);
    for (i = 2; i <= n; i++) {
      size_t j = 0;
      while (j < lcp && matches[i][j] == matches[1][j])
        j++;
      lcp = j;
    }
    matches[0] = malloc(lcp + 1);
    if (matches[0] != NULL) {
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

void dm_complete_init(lua_State *L)
{
  complL = L;
  rl_attempted_completion_function = dm_completion;
  rl_completer_word_break_characters = " \t\n\"\\'`@$><=;|&{(,+-*/^%[]#~)";
  rl_completion_append_character = '\0';
  rl_basic_quote_characters = "\"'";
}

#else

void dm_complete_init(lua_State *L)
{
  (void)L;
}

#endif
