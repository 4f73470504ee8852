/* l_plot.c -- Lua binding of the gnuplot session (src/plot).
 *
 * One dm_gp_session per Lua state, created on first use and kept in the
 * registry as a userdata whose __gc frees it (which kills and reaps
 * gnuplot when the state closes).  Exposed:
 *
 *   dm.gnuplot(cmd)          the raw escape hatch (errors surface too)
 *   dm.plot{...}, dm.figure{...}
 *                            C entry points that load lua/dmech/plot.lua on
 *                            first use and call its recipes (so start-up
 *                            pays nothing for plotting)
 *   dm._gp.*                 the primitives plot.lua composes with: begin,
 *                            send, quote, data, terminal, checkpoint, ...
 *
 * Only trusted text (composed by plot.lua) goes through _gp.send; every user
 * string goes through _gp.quote, every user style through _gp.style_ok.
 */
#include <config.h>

#include <stdio.h>
#include <string.h>

#include "lua/dmlua.h"
#include "plot/gnuplot.h"

#define GP_MT "dmech.gnuplot"
#define GP_KEY "dmech.gnuplot.session"

typedef struct lgp {
  dm_gp_session *s;
} lgp;

static int gp_gc(lua_State *L)
{
  lgp *g = luaL_checkudata(L, 1, GP_MT);
  dm_gp_session_free(g->s);
  g->s = NULL;
  return 0;
}

/* The state's session, created (empty userdata first, then the session)
 * on first use. */
static dm_gp_session *session(lua_State *L)
{
  lgp *g;
  if (lua_getfield(L, LUA_REGISTRYINDEX, GP_KEY) == LUA_TUSERDATA) {
    g = lua_touserdata(L, -1);
    lua_pop(L, 1);
    if (g->s == NULL)
      luaL_error(L, "gnuplot session already closed");
    return g->s;
  }
  lua_pop(L, 1);
  g = lua_newuserdatauv(L, sizeof *g, 0);
  g->s = NULL;
  luaL_setmetatable(L, GP_MT);
  lua_setfield(L, LUA_REGISTRYINDEX, GP_KEY);
  g->s = dm_gp_session_alloc();
  if (g->s == NULL)
    luaL_error(L, "out of memory creating the gnuplot session");
  return g->s;
}

/* io.stdout:write(text) when the io library is there, else stdout. */
static void write_stdout(lua_State *L, const char *text, size_t len)
{
  int top = lua_gettop(L);
  if (len == 0)
    return;
  if (lua_getglobal(L, "io") == LUA_TTABLE
      && lua_getfield(L, -1, "stdout") != LUA_TNIL
      && lua_getfield(L, -1, "write") == LUA_TFUNCTION) {
    lua_insert(L, -2);                       /* io, write, stdout */
    lua_pushlstring(L, text, len);
    lua_call(L, 2, 0);
    lua_getfield(L, -1, "stdout");
    if (lua_getfield(L, -1, "flush") == LUA_TFUNCTION) {
      lua_insert(L, -2);
      lua_call(L, 1, 0);
    }
  } else {
    fwrite(text, 1, len, stdout);
    fflush(stdout);
  }
  lua_settop(L, top);
}

/* {==== public functions ===================================================== */

static int l_gnuplot(lua_State *L)
{
  size_t len, olen, mlen;
  const char *cmd = luaL_checklstring(L, 1, &len);
  dm_gp_session *s = session(L);
  const char *out, *msgs;
  dm_err e;
  int rc, top;
  if (strlen(cmd) != len)
    return luaL_argerror(L, 1, "command contains a NUL byte");
  rc = dm_gp_command(s, cmd, NULL, &e);
  if (rc != DM_OK)
    return dm_lua_fail(L, "dm.gnuplot", rc, &e);
  out = dm_gp_output(s, &olen);
  top = lua_gettop(L);
  write_stdout(L, out, olen);
  lua_settop(L, top);
  msgs = dm_gp_messages(s, &mlen);
  while (mlen > 0 && (msgs[mlen - 1] == '\n' || msgs[mlen - 1] == '\r'))
    mlen--;
  lua_pushlstring(L, msgs, mlen);
  return 1;
}

/* dm.plot / dm.figure: require "dmech.plot" and call its function of the
 * same name with our arguments. */
static int forward(lua_State *L, const char *name)
{
  int n = lua_gettop(L);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "dmech.plot");
  lua_call(L, 1, 1);
  lua_getfield(L, -1, name);
  lua_remove(L, -2);
  lua_insert(L, 1);
  lua_call(L, n, LUA_MULTRET);
  return lua_gettop(L);
}

static int l_plot(lua_State *L) { return forward(L, "plot"); }
static int l_figure(lua_State *L) { return forward(L, "figure"); }

static const dm_reg plot_funcs[] = {
  {"plot", l_plot,
   "dm.plot{series..., options...}",
   "Plot series with gnuplot: {x, y[, z]} (tables or vecs), {obj, \"colx\", \"coly\"[, \"colz\"]} "
   "for any obj with :column(name) (trajectories), {f, range = {a, b}, samples = 500} for "
   "f(t) -> y | x, y | x, y, z; series options with = \"lines\" (a gnuplot style), legend = "
   "\"text\" (the key entry; title is the same), range, samples.  Three columns make a 3-D "
   "plot; layout = \"rows,cols\" makes every element a panel (a series, or a table of series "
   "with its own panel options; a single-series panel's title is the panel's title).  By "
   "default axes are labelled with the column names, the key goes to a corner free of data "
   "(or outside), configuration-space orbits (coordinate columns on every axis) get equal "
   "aspect, and values <= 0 on a log axis are left out; output writes the file."},
  {"figure", l_figure, "dm.figure{options..., series...} -> figure",
   "A figure that keeps its series for live updates (:add, :append, "
   ":refresh), saving (:save) and closing (:close, or a <close> variable); it takes "
   "dm.plot's series and options."},
  {"gnuplot", l_gnuplot, "dm.gnuplot(\"command\") -> string",
   "Send a raw command to the session's gnuplot and return what it printed; "
   "its complaints become errors."},
  {NULL, NULL, NULL, NULL}
};

/* The options of dm.plot and dm.figure (plot.lua reads this list: the
 * first five are plot-wide, the others also panel options). */
static const char *const plot_keys[] = {
  "layout", "output", "size", "terminal", "enhanced",
  "title", "xlabel", "ylabel", "zlabel", "xrange", "yrange", "zrange", "logscale", "grid",
  "key", "aspect", "view", "with", "commands", NULL
};

/* Documented here so help() knows them before plot.lua is loaded;
 * plot.lua attaches its functions to these entries. */
static const dm_reg figure_docs[] = {
  {"plot", NULL, "fig:plot{series..., options...}",
   "Replace the figure's series and options and draw it."},
  {"splot", NULL, "fig:splot{series..., options...}",
   "Like fig:plot, but every series must have three columns (a 3-D plot)."},
  {"add", NULL, "fig:add(series[, panel]) -> id",
   "Add a series to the figure (to a panel of a layout) and redraw; returns the series id."},
  {"append", NULL, "fig:append(id, x, y[, z])",
   "Append points (numbers, tables or vecs) to a data series without redrawing."},
  {"refresh", NULL, "fig:refresh()",
   "Redraw the figure with all the data it holds now."},
  {"save", NULL, "fig:save(\"file.png|svg|pdf\"[, {size={w,h}}])",
   "Draw the figure into a file, complete when the call returns."},
  {"close", NULL, "fig:close()",
   "Forget the figure's data in gnuplot and close its window; idempotent."},
  {"series", NULL, "fig:series(id) -> table",
   "The series record (columns, style, title) behind a series id."},
  {NULL, NULL, NULL, NULL}
};

/* }==== */

/* {==== primitives for plot.lua ============================================== */

#define WHAT_KEY "dmech.gnuplot.what"

/* Raise "<what>: <message>" without a source position: the primitives are
 * called from plot.lua, whose line numbers mean nothing to the user. */
static int raise(lua_State *L, const char *what, int status, const dm_err *e)
{
  const char *msg = (e != NULL && e->msg[0] != '\0') ? e->msg : dm_strstatus(status);
  if (what != NULL)
    lua_pushfstring(L, "%s: %s", what, msg);
  else
    lua_pushstring(L, msg);
  return lua_error(L);
}

/* The user-level name of the transaction in progress, for error messages. */
static const char *current_what(lua_State *L)
{
  const char *w;
  lua_getfield(L, LUA_REGISTRYINDEX, WHAT_KEY);
  w = lua_isstring(L, -1) ? lua_tostring(L, -1) : "plot";
  lua_pop(L, 1);                 /* the string stays anchored in the registry */
  return w;
}

static int gp_begin(lua_State *L)
{
  dm_gp_session *s;
  dm_err e;
  int rc;
  luaL_optstring(L, 1, "plot");
  lua_settop(L, 1);
  if (lua_isnil(L, 1))
    lua_pushliteral(L, "plot");
  lua_setfield(L, LUA_REGISTRYINDEX, WHAT_KEY);
  s = session(L);
  rc = dm_gp_begin(s, &e);
  if (rc != DM_OK)
    return raise(L, current_what(L), rc, &e);
  return 0;
}

static int gp_send(lua_State *L)
{
  size_t len;
  const char *text = luaL_checklstring(L, 1, &len);
  dm_gp_session *s = session(L);
  dm_err e;
  int rc;
  if (strlen(text) != len)
    return luaL_argerror(L, 1, "text contains a NUL byte");
  rc = dm_gp_send(s, &e, "%s", text);
  if (rc != DM_OK)
    return raise(L, current_what(L), rc, &e);
  return 0;
}

static int gp_quote(lua_State *L)
{
  size_t len, n;
  const char *str = luaL_checklstring(L, 1, &len);
  int flags = lua_toboolean(L, 2) ? DM_GP_QUOTE_ONELINE : 0;
  luaL_Buffer b;
  char *p;
  n = dm_gp_quote(NULL, 0, str, len, flags);
  p = luaL_buffinitsize(L, &b, n + 1);
  dm_gp_quote(p, n + 1, str, len, flags);
  luaL_pushresultsize(&b, n);
  return 1;
}

static int gp_fmt(lua_State *L)
{
  char buf[64];
  double x = luaL_checknumber(L, 1);
  dm_num_format(buf, sizeof buf, x);
  lua_pushstring(L, buf);
  return 1;
}

static int gp_style_ok(lua_State *L)
{
  lua_pushboolean(L, dm_gp_valid_style(dm_checkcstring(L, 1)));
  return 1;
}

/* _gp.data(name, col1, col2[, ...]): columns are vecs or tables of numbers
 * of one length (tables are converted in place, so Lua owns all memory). */
static int gp_data(lua_State *L)
{
  const char *name = dm_checkcstring(L, 1);
  int k = lua_gettop(L) - 1, i;
  const double *cols[8];
  size_t n = 0;
  dm_gp_session *s;
  dm_err e;
  int rc;
  if (k < 1 || k > 8)
    return luaL_error(L, "datablock '%s': 1 to 8 columns expected, got %d",
                      name, k);
  for (i = 0; i < k; i++) {
    gsl_vector *v = dm_checkvector(L, i + 2, n);
    n = v->size;
    cols[i] = v->data;
  }
  s = session(L);
  rc = dm_gp_datablock(s, name, n, (size_t)k, cols, NULL, &e);
  if (rc != DM_OK)
    return raise(L, current_what(L), rc, &e);
  return 0;
}

/* _gp.terminal{terminal=, file=, size={w,h}, window=, enhanced=} -> the
 * `set terminal` line used. */
static int gp_terminal(lua_State *L)
{
  dm_gp_termreq req;
  dm_gp_termenv env;
  dm_gp_session *s;
  char cmd[512];
  dm_err e;
  int rc;
  luaL_checktype(L, 1, LUA_TTABLE);
  memset(&req, 0, sizeof req);
  req.terminal = dm_optstringfield(L, 1, "terminal", NULL);
  req.file = dm_optstringfield(L, 1, "file", NULL);
  req.window = (int)dm_optintegerfield(L, 1, "window", 0);
  if (lua_getfield(L, 1, "enhanced") != LUA_TNIL)
    req.enhanced = lua_toboolean(L, -1);
  lua_pop(L, 1);
  if (lua_getfield(L, 1, "size") != LUA_TNIL) {
    int t = lua_gettop(L);
    if (!lua_istable(L, t) || lua_geti(L, t, 1) != LUA_TNUMBER
        || lua_geti(L, t, 2) != LUA_TNUMBER)
      return luaL_error(L, "size: {width, height} expected");
    req.width = lua_tonumber(L, -2);
    req.height = lua_tonumber(L, -1);
    if (!(req.width > 0 && req.height > 0)) {
      char a[DM_NUM_BUFSIZE], b[DM_NUM_BUFSIZE];
      dm_num_format(a, sizeof a, req.width);
      dm_num_format(b, sizeof b, req.height);
      return luaL_error(L, "size: two positive numbers expected, got %s,%s", a, b);
    }
  }
  s = session(L);
  rc = dm_gp_set_terminal(s, &req, &e);
  if (rc != DM_OK)
    return raise(L, current_what(L), rc, &e);
  dm_gp_termenv_get(&env);
  if (dm_gp_terminal_command(s, &req, &env, cmd, sizeof cmd, &e) != DM_OK)
    cmd[0] = '\0';
  lua_pushstring(L, cmd);
  return 1;
}

/* _gp.checkpoint(what) -> messages, output */
static int gp_checkpoint(lua_State *L)
{
  const char *what = luaL_optstring(L, 1, "plot");
  dm_gp_session *s = session(L);
  size_t mlen, olen;
  const char *m, *o;
  dm_err e;
  int rc = dm_gp_checkpoint(s, what, &e);
  if (rc != DM_OK)   /* a gnuplot complaint names `what` already */
    return raise(L, rc == DM_EFAILED ? NULL : what, rc, &e);
  m = dm_gp_messages(s, &mlen);
  o = dm_gp_output(s, &olen);
  lua_pushlstring(L, m, mlen);
  lua_pushlstring(L, o, olen);
  return 2;
}

static int gp_pid(lua_State *L)
{
  pid_t pid = dm_gp_pid(session(L));
  if (pid > 0)
    lua_pushinteger(L, (lua_Integer)pid);
  else
    lua_pushnil(L);
  return 1;
}

static int gp_generation(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)dm_gp_generation(session(L)));
  return 1;
}

/* Terminals of the running gnuplot (starting it if needed). */
static int gp_terminals(lua_State *L)
{
  dm_gp_session *s = session(L);
  dm_err e;
  int rc = dm_gp_start(s, &e);
  if (rc != DM_OK)
    return raise(L, current_what(L), rc, &e);
  lua_pushstring(L, dm_gp_terminals(s));
  lua_pushnumber(L, dm_gp_version(s));
  return 2;
}

static int gp_stop(lua_State *L)
{
  dm_gp_stop(session(L));
  return 0;
}

static int gp_timeout(lua_State *L)
{
  dm_gp_session *s = session(L);
  if (!lua_isnoneornil(L, 1)) {
    double t = luaL_checknumber(L, 1);
    luaL_argcheck(L, t > 0, 1, "positive number of seconds expected");
    dm_gp_set_timeout(s, t);
  }
  lua_pushnumber(L, dm_gp_timeout(s));
  return 1;
}

static int gp_program(lua_State *L)
{
  const char *p = lua_toboolean(L, 1) ? dm_checkcstring(L, 1) : NULL;
  dm_err e;
  if (dm_gp_set_program(session(L), p, &e) != DM_OK)
    return raise(L, current_what(L), e.status, &e);
  return 0;
}

static int gp_log_to(lua_State *L)
{
  const char *p = lua_toboolean(L, 1) ? dm_checkcstring(L, 1) : NULL;
  dm_err e;
  if (dm_gp_set_log(session(L), p, &e) != DM_OK)
    return raise(L, "dm._gp.log", e.status, &e);
  return 0;
}

static const dm_reg gp_funcs[] = {
  {"begin", gp_begin, "dm._gp.begin([what])",
   "Start a plot transaction, (re)starting gnuplot when needed."},
  {"send", gp_send, "dm._gp.send(text)",
   "Queue trusted command text (never user strings) for gnuplot."},
  {"quote", gp_quote, "dm._gp.quote(s[, oneline]) -> string",
   "A user string as a gnuplot string expression that renders literally."},
  {"fmt", gp_fmt, "dm._gp.fmt(x) -> string",
   "A number as gnuplot reads it back exactly, whatever the locale."},
  {"style_ok", gp_style_ok, "dm._gp.style_ok(s) -> boolean",
   "Whether a `with` style is plain words, numbers and quoted colours."},
  {"data", gp_data, "dm._gp.data(name, col1, col2[, ...])",
   "Send columns (vecs or tables of equal length) as the datablock $name."},
  {"terminal", gp_terminal,
   "dm._gp.terminal{terminal=, file=, size={w,h}, window=, enhanced=} -> string",
   "Choose and set the terminal (and a file output closed by the checkpoint)."},
  {"checkpoint", gp_checkpoint, "dm._gp.checkpoint([what]) -> messages, output",
   "End the transaction; gnuplot's complaints become an error naming `what`."},
  {"pid", gp_pid, "dm._gp.pid() -> integer | nil",
   "Process id of the running gnuplot, if any."},
  {"generation", gp_generation, "dm._gp.generation() -> integer",
   "How many times gnuplot was started in this session."},
  {"terminals", gp_terminals, "dm._gp.terminals() -> string, version",
   "The terminals (GPVAL_TERMINALS) and version of the session's gnuplot."},
  {"stop", gp_stop, "dm._gp.stop()",
   "Kill the session's gnuplot now; the next plot starts a new one."},
  {"timeout", gp_timeout, "dm._gp.timeout([seconds]) -> seconds",
   "Get or set how long gnuplot may stay silent before it is declared hung."},
  {"program", gp_program, "dm._gp.program(path | false)",
   "Use this gnuplot program from the next start (false: $DMECH_GNUPLOT or gnuplot)."},
  {"log", gp_log_to, "dm._gp.log(file | false)",
   "Record every command sent to gnuplot in a file (as $DMECH_GNUPLOT_LOG does); false stops."},
  {NULL, NULL, NULL, NULL}
};

/* }==== */

void dm_open_plot(lua_State *L)
{
  const dm_reg *r;
  luaL_newmetatable(L, GP_MT);
  lua_pushcfunction(L, gp_gc);
  lua_setfield(L, -2, "__gc");
  lua_pop(L, 1);
  dm_register(L, "dm.", plot_funcs);
  dm_doc_options(L, "dm.plot", plot_keys);
  dm_doc_options(L, "dm.figure", plot_keys);
  lua_newtable(L);
  dm_register(L, "dm._gp.", gp_funcs);
  lua_setfield(L, -2, "_gp");
  for (r = figure_docs; r->name != NULL; r++) {
    char name[64];
    snprintf(name, sizeof name, "figure:%s", r->name);
    dm_doc_add(L, name, r->sig, r->doc, 0);
  }
}
