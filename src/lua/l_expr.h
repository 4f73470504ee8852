/* l_expr.h -- symbolic expressions in Lua, for other bindings (dm.system,
 * reduction, ...) that trace user functions and compile what they return.
 *
 * Every Lua state has one expression context (created on first use, freed
 * with the state).  An expression is a userdata "dmech.expr" holding a node
 * handle of that context; Lua numbers convert to constants wherever an
 * expression is expected.  A symbolic vector is a read-only proxy table
 * (t[k], t.name, #t, pairs work through metamethods; read it with
 * lua_geti / luaL_len or dm_lua_toexprs, not raw access) whose unknown
 * fields raise errors.
 */
#ifndef DM_L_EXPR_H
#define DM_L_EXPR_H

#include "lua/dmlua.h"
#include "expr/expr.h"

#define DM_EXPR_MT "dmech.expr"

/* The expression context of this Lua state. */
dm_expr_ctx *dm_lua_exprctx(lua_State *L);

/* The node of the expression or number at idx, or DM_EXPR_NONE. */
dm_expr dm_lua_toexpr(lua_State *L, int idx);
/* Same, raising "bad argument #idx to 'f' (expression or number expected,
 * got X)". */
dm_expr dm_lua_checkexpr(lua_State *L, int idx);
/* Push an expression userdata for e; raises the context's error (and
 * clears it) when e is DM_EXPR_NONE. */
void dm_lua_pushexpr(lua_State *L, dm_expr e);

/* Push a symbolic vector of n symbols (kind DM_EXPR_SYM) or parameters
 * (DM_EXPR_PARAM): element k is reachable as t[k] and t[elems[k]]; the
 * node names are string.format(fmt, elems[k]) (fmt NULL: "%s").  label
 * names the vector in error messages ("no element 'thta' in q"). */
void dm_lua_pushsymvec(lua_State *L, const char *label, size_t n,
                       const char *const *elems, const char *fmt, int kind);
/* Element `name` of the symbolic vector at idx becomes a symbolic vector of
 * its elements first .. first+count-1 (0-based; indexed 1..count), labelled
 * label: q.x[i] for an array of coordinates. */
void dm_lua_symvec_group(lua_State *L, int idx, const char *name, size_t first,
                         size_t count, const char *label);

/* 1 if the value at idx is a symbolic vector. */
int dm_lua_issymvec(lua_State *L, int idx);

/* Call the function below its nargs arguments on the stack (like
 * lua_call(L, nargs, 1)) while tracing: a comparison or branch on a
 * symbolic value inside raises "branch on a symbolic value in <what> at
 * file:line; use dm.select".  Leaves the result on the stack. */
void dm_lua_trace(lua_State *L, const char *what, int nargs);

/* Convert the value at idx (expression, number, or a list of them) into
 * at most max nodes stored in out; returns how many there are, or raises
 * naming `what`.  Nested lists are flattened row by row; *rows and *cols
 * (may be NULL) receive the shape: (1, 0) for a scalar, (1, k) for a list,
 * (r, c) for a list of r equal-length lists. */
size_t dm_lua_toexprs(lua_State *L, int idx, const char *what, dm_expr *out,
                      size_t max, size_t *rows, size_t *cols);

/* dm.config.native as an enum dm_native_mode (raises on a bad value). */
int dm_lua_native_mode(lua_State *L);

/* ---- shared by l_expr.c, l_expr_calc.c, l_expr_fn.c, l_expr_sym.c only ---- */
void dm_open_expr_fn(lua_State *L);                   /* dm.fn */
void dm_open_expr_sym(lua_State *L);                  /* dm.sym, dm.symvec, dm.trace */
int dm_lua_ctx_raise(lua_State *L, dm_expr_ctx *ctx);  /* raise + clear */
dm_expr dm_lua_checkexpr_only(lua_State *L, int idx);  /* no numbers */
extern const dm_reg dm_lexpr_methods[];               /* expr:... */
extern const dm_reg dm_lexpr_calc_funcs[];            /* dm.jacobian */

#endif
