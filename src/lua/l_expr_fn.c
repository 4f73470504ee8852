/* l_expr_fn.c -- dm.fn: expressions compiled to a callable function (a
 * tape, or native code per dm.config.native), with parameters settable
 * after compiling.  Part of the expression binding (l_expr.c). */
#include <config.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_expr.h"
#include "expr/native.h"
#include "expr/tape.h"
#include "core/interrupt.h"

#define FN_MT "dmech.fn"
#define AUTO_MIN_INSTR 32   /* "auto" compiles natively from this size on */

typedef struct lfn {
  dm_tape *tape;
  dm_native *nat;
  dm_native_fn fn;
  size_t nin, npar, nout, rows, cols;
  int shape;                /* 0 number, 1 vec, 2 mat */
  double *par, *work, *in;
  char **pnames;
} lfn;

static void fn_release(lfn *f)
{
  dm_native_free(f->nat);
  dm_tape_free(f->tape);
  for (size_t i = 0; f->pnames && i < f->npar; i++)
    free(f->pnames[i]);
  free(f->pnames);
  free(f->par);
  free(f->work);
  free(f->in);
  memset(f, 0, sizeof *f);
}

static int fn_gc(lua_State *L)
{
  fn_release(luaL_checkudata(L, 1, FN_MT));
  return 0;
}

static lfn *checkfn(lua_State *L, int idx)
{
  lfn *f = luaL_checkudata(L, idx, FN_MT);
  if (f->tape == NULL)
    luaL_error(L, "the compiled function is closed");
  return f;
}

/* {======================================================================
 * building
 * ======================================================================= */

/* Resolve a name among the outputs' free variables (else a new symbol or,
 * for parameters, a new parameter). */
static dm_expr by_name(dm_expr_ctx *ctx, size_t nout, const dm_expr *out,
                       const char *name, int param)
{
  for (size_t k = 0; k < nout; k++) {
    dm_expr fv[256];
    long n = dm_expr_free_vars(ctx, out[k], fv, 256);
    for (long i = 0; i < n && i < 256; i++)
      if (strcmp(dm_expr_name(ctx, fv[i]), name) == 0)
        return fv[i];
  }
  return param ? dm_expr_param(ctx, name) : dm_expr_sym(ctx, name);
}

/* inputs: a symbol, a name, a symbolic vector or a list of those. */
static dm_expr *inputs_arg(lua_State *L, int t, size_t nout, const dm_expr *out,
                           size_t *n)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  int type = lua_getfield(L, t, "inputs");
  int idx = lua_gettop(L);
  if (type == LUA_TNIL)
    luaL_error(L, "dm.fn: field 'inputs' missing (a list of symbols)");
  int single = type != LUA_TTABLE;
  *n = single ? 1 : (size_t)luaL_len(L, idx);
  dm_expr *v = lua_newuserdatauv(L, (*n + 1) * sizeof *v, 0);
  for (size_t i = 0; i < *n; i++) {
    if (single)
      lua_pushvalue(L, idx);
    else
      lua_geti(L, idx, (lua_Integer)i + 1);
    dm_expr *u = luaL_testudata(L, -1, DM_EXPR_MT);
    if (lua_type(L, -1) == LUA_TSTRING) {
      v[i] = by_name(ctx, nout, out, lua_tostring(L, -1), 0);
      if (v[i] == DM_EXPR_NONE)               /* a bad name: raise now */
        dm_lua_ctx_raise(L, ctx);
    } else if (u && (dm_expr_kind(ctx, *u) == DM_EXPR_SYM ||
                   dm_expr_kind(ctx, *u) == DM_EXPR_PARAM))
      v[i] = *u;
    else
      luaL_error(L, "dm.fn: input %d is a %s, symbol or name expected",
                 (int)i + 1, u ? dm_expr_op_name(dm_expr_kind(ctx, *u))
                               : luaL_typename(L, -1));
    lua_pop(L, 1);
  }
  return v;
}

static int cmp_names(const void *a, const void *b)
{
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* params = {name = value, ...}: nodes, names (sorted), values into f. */
static dm_expr *params_arg(lua_State *L, int t, size_t nout, const dm_expr *out,
                           lfn *f)
{
  dm_expr_ctx *ctx = dm_lua_exprctx(L);
  int type = lua_getfield(L, t, "params");
  int idx = lua_gettop(L);
  size_t n = 0;
  if (type != LUA_TNIL && type != LUA_TTABLE)
    luaL_error(L, "dm.fn: field 'params' must be a table {name = value}, "
               "got %s", luaL_typename(L, idx));
  if (type == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, idx) != 0) {
      if (lua_type(L, -2) != LUA_TSTRING || lua_type(L, -1) != LUA_TNUMBER)
        luaL_error(L, "dm.fn: params must map names to numbers (got %s = %s)",
                   luaL_typename(L, -2), luaL_typename(L, -1));
      n++;
      lua_pop(L, 1);
    }
  }
  dm_expr *v = lua_newuserdatauv(L, (n + 1) * sizeof *v, 0);
  f->pnames = calloc(n + 1, sizeof *f->pnames);
  f->par = calloc(n + 1, sizeof *f->par);
  if (!f->pnames || !f->par)
    luaL_error(L, "out of memory");
  f->npar = 0;
  if (type == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, idx) != 0) {
      if (!(f->pnames[f->npar++] = strdup(lua_tostring(L, -2))))
        luaL_error(L, "out of memory");
      lua_pop(L, 1);
    }
  }
  qsort(f->pnames, f->npar, sizeof *f->pnames, cmp_names);
  for (size_t i = 0; i < f->npar; i++) {
    lua_getfield(L, idx, f->pnames[i]);
    f->par[i] = lua_tonumber(L, -1);
    lua_pop(L, 1);
    v[i] = by_name(ctx, nout, out, f->pnames[i], 1);
    if (v[i] == DM_EXPR_NONE)
      dm_lua_ctx_raise(L, ctx);
  }
  return v;
}

/* dm.fn{inputs = ..., outputs = ..., params = {...}, native = ...} */
static int l_fn(lua_State *L)
{
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  lfn *f = lua_newuserdatauv(L, sizeof *f, 0);      /* 2: empty, safe */
  memset(f, 0, sizeof *f);
  luaL_setmetatable(L, FN_MT);
  dm_expr_ctx *ctx = dm_lua_exprctx(L);

  if (lua_getfield(L, 1, "outputs") == LUA_TNIL)
    return luaL_error(L, "dm.fn: field 'outputs' missing (an expression or "
                      "a list of them)");
  int oidx = lua_gettop(L);
  size_t nout = dm_lua_toexprs(L, oidx, "dm.fn outputs", NULL, 0, &f->rows, &f->cols);
  dm_expr *out = lua_newuserdatauv(L, nout * sizeof *out, 0);
  dm_lua_toexprs(L, oidx, "dm.fn outputs", out, nout, NULL, NULL);
  f->shape = 0;
  if (lua_type(L, oidx) == LUA_TTABLE) {
    int t = lua_geti(L, oidx, 1);
    f->shape = t == LUA_TTABLE && !luaL_testudata(L, -1, DM_EXPR_MT) ? 2 : 1;
    lua_pop(L, 1);
  }

  size_t nin;
  dm_expr *in = inputs_arg(L, 1, nout, out, &nin);
  dm_expr *par = params_arg(L, 1, nout, out, f);
  int mode = dm_lua_native_mode(L);
  const char *m = dm_optstringfield(L, 1, "native", NULL);
  if (m != NULL && (mode = dm_native_mode_parse(m)) < 0)
    return luaL_error(L, "dm.fn: native must be \"auto\", \"wait\", \"always\" or "
                      "\"never\" (got \"%s\")", m);

  dm_err err;
  if (dm_tape_compile(ctx, nout, out, nin, in, f->npar, par, &f->tape, &err) != DM_OK)
    return luaL_error(L, "dm.fn: %s", err.msg);
  f->nin = nin;
  f->nout = nout;
  f->work = malloc((dm_tape_work_size(f->tape) + nout + 1) * sizeof *f->work);
  f->in = malloc((nin + 1) * sizeof *f->in);
  if (!f->work || !f->in)
    return luaL_error(L, "out of memory");
  if (mode == DM_NATIVE_ALWAYS ||
      ((mode == DM_NATIVE_AUTO || mode == DM_NATIVE_WAIT) &&
       dm_tape_ninstr(f->tape) >= AUTO_MIN_INSTR)) {
    int s = dm_native_compile(f->tape, NULL, f->par, &f->nat, &err);
    if (s == DM_OK)
      f->fn = dm_native_function(f->nat);
    else if (mode == DM_NATIVE_ALWAYS || s == DM_EINTR)
      return luaL_error(L, "dm.fn: %s", err.msg);
  }
  lua_settop(L, 2);
  return 1;
}

/* {======================================================================
 * calling
 * ======================================================================= */

/* Inputs from the arguments from index 2: nin numbers, or one table / vec. */
static void read_inputs(lua_State *L, lfn *f)
{
  int nargs = lua_gettop(L) - 1;
  if (nargs == 1 && (lua_type(L, 2) == LUA_TTABLE || dm_tovec(L, 2))) {
    gsl_vector *v = dm_checkvector(L, 2, 0);
    if (v->size != f->nin)
      luaL_error(L, "compiled function: %d inputs expected, got a vector of %d",
                 (int)f->nin, (int)v->size);
    memcpy(f->in, v->data, f->nin * sizeof *f->in);
    return;
  }
  if ((size_t)nargs != f->nin)
    luaL_error(L, "compiled function: %d inputs expected, got %d", (int)f->nin, nargs);
  for (size_t i = 0; i < f->nin; i++) {
    int isnum;
    f->in[i] = lua_tonumberx(L, (int)i + 2, &isnum);
    if (!isnum || lua_type(L, (int)i + 2) != LUA_TNUMBER)
      luaL_error(L, "compiled function: input %d is a %s, number expected",
                 (int)i + 1, luaL_typename(L, (int)i + 2));
  }
}

static void run(const lfn *f, const double *in, double *out)
{
  if (f->fn)
    f->fn(in, f->par, out);
  else
    dm_tape_eval(f->tape, in, f->par, out, f->work);
}

static int fn_call(lua_State *L)
{
  lfn *f = checkfn(L, 1);
  read_inputs(L, f);
  double *out = f->work + dm_tape_work_size(f->tape);
  run(f, f->in, out);
  if (f->shape == 0)
    lua_pushnumber(L, out[0]);
  else if (f->shape == 1)
    dm_pushvec_copy(L, out, f->nout);
  else
    memcpy(dm_pushmat(L, f->rows, f->cols)->data, out, f->nout * sizeof *out);
  return 1;
}

/* f:batch(points) -> mat, one row of outputs per row of points. */
static int fn_batch(lua_State *L)
{
  lfn *f = checkfn(L, 1);
  gsl_matrix *P = dm_checkmatrix(L, 2, 0, 0);
  if (P->size2 != f->nin)
    return luaL_error(L, "batch: points need %d columns, got %d", (int)f->nin,
                      (int)P->size2);
  gsl_matrix *R = dm_pushmat(L, P->size1, f->nout);
  if (f->fn) {
    for (size_t k = 0; k < P->size1; k++) {
      if ((k & 1023) == 0 && dm_interrupted())
        return luaL_error(L, "batch: interrupted");
      f->fn(P->data + k * P->tda, f->par, R->data + k * R->tda);
    }
    return 1;
  }
  double *w = malloc(dm_tape_batch_work_size(f->tape) * sizeof *w);
  if (w == NULL)
    return luaL_error(L, "out of memory");
  for (size_t k = 0; k < P->size1; k += 4096) {
    size_t m = P->size1 - k < 4096 ? P->size1 - k : 4096;
    if (dm_interrupted()) {
      free(w);
      return luaL_error(L, "batch: interrupted");
    }
    dm_tape_eval_batch(f->tape, m, P->data + k * P->tda, P->tda, f->par,
                       R->data + k * R->tda, R->tda, w);
  }
  free(w);
  return 1;
}

static long param_index(lua_State *L, lfn *f, int arg)
{
  const char *name = dm_checkcstring(L, arg);
  for (size_t i = 0; i < f->npar; i++)
    if (strcmp(f->pnames[i], name) == 0)
      return (long)i;
  return luaL_error(L, "no parameter '%s' in this function", name);
}

static int fn_set_param(lua_State *L)
{
  lfn *f = checkfn(L, 1);
  long i = param_index(L, f, 2);
  f->par[i] = luaL_checknumber(L, 3);
  return 0;
}

static int fn_param(lua_State *L)
{
  lfn *f = checkfn(L, 1);
  lua_pushnumber(L, f->par[param_index(L, f, 2)]);
  return 1;
}

static int fn_params(lua_State *L)
{
  lfn *f = checkfn(L, 1);
  lua_createtable(L, 0, (int)f->npar);
  for (size_t i = 0; i < f->npar; i++) {
    lua_pushnumber(L, f->par[i]);
    lua_setfield(L, -2, f->pnames[i]);
  }
  return 1;
}

static int fn_stats(lua_State *L)
{
  lfn *f = checkfn(L, 1);
  lua_createtable(L, 0, 6);
  lua_pushinteger(L, (lua_Integer)dm_tape_ninstr(f->tape));
  lua_setfield(L, -2, "instructions");
  lua_pushinteger(L, (lua_Integer)dm_tape_nregs(f->tape));
  lua_setfield(L, -2, "registers");
  lua_pushinteger(L, (lua_Integer)dm_tape_nconst(f->tape));
  lua_setfield(L, -2, "constants");
  lua_pushinteger(L, (lua_Integer)f->nin);
  lua_setfield(L, -2, "inputs");
  lua_pushinteger(L, (lua_Integer)f->nout);
  lua_setfield(L, -2, "outputs");
  lua_pushboolean(L, f->fn != NULL);
  lua_setfield(L, -2, "native");
  return 1;
}

static int fn_tostring(lua_State *L)
{
  lfn *f = luaL_checkudata(L, 1, FN_MT);
  if (f->tape == NULL)
    lua_pushstring(L, "<fn closed>");
  else
    lua_pushfstring(L, "<fn %d inputs -> %d outputs, %d instructions, %s>",
                    (int)f->nin, (int)f->nout, (int)dm_tape_ninstr(f->tape),
                    f->fn ? "native" : "tape");
  return 1;
}

static const luaL_Reg fn_meta[] = {
  {"__call", fn_call}, {"__gc", fn_gc}, {"__close", fn_gc},
  {"__tostring", fn_tostring}, {NULL, NULL}
};

static const dm_reg fn_methods[] = {
  {"set_param", fn_set_param, "f:set_param(name, value)",
   "Change a parameter of a compiled function; no recompilation."},
  {"param", fn_param, "f:param(name) -> number",
   "The current value of a parameter."},
  {"params", fn_params, "f:params() -> {name = value, ...}",
   "A copy of all parameter values."},
  {"batch", fn_batch, "f:batch(points) -> mat",
   "Evaluate at every row of a matrix (or table of rows) of inputs; one row of outputs per point."},
  {"stats", fn_stats, "f:stats() -> {instructions, registers, constants, inputs, outputs, native}",
   "The size of the compiled tape and whether native code runs."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg fn_funcs[] = {
  {"fn", l_fn, "dm.fn{inputs = {...}, outputs = e | {...} | {{...}}, params = {name = value}, native = mode} -> f",
   "Compile expressions into a fast function f(x1, ...) or f{...} returning a number, a vec or a mat; native per dm.config.native (\"auto\" compiles tapes of 32+ instructions when a C compiler works)."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_expr_fn(lua_State *L)
{
  dm_newclass(L, FN_MT, "fn", fn_methods, fn_meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", fn_funcs);
}
