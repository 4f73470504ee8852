/* l_lie.h -- private glue of the Lie group bindings: l_lie.c (dm.lie: the
 * group objects, their functions G.exp{...} ..., spheres), l_lie_elem.c
 * (group elements: composition, action, matrices, printing) and the
 * systems and integrators on groups (l_lie_system.c, l_lie_integ.c).
 *
 * A group is a userdata "dmech.liegroup" owning a dm_lie_group; its user
 * value 1 caches the functions bound to it (G.exp is a closure that passes
 * G; G:exp(x) works too).  An element is a userdata "dmech.lieelement"
 * holding nq numbers or nq expression nodes (a symbolic element, as a
 * traced Lagrangian sees it); its user value 1 is its group userdata,
 * which keeps the descriptor alive.
 */
#ifndef DM_L_LIE_H
#define DM_L_LIE_H

#include "lua/dmlua.h"
#include "lie/lie.h"

#define DM_LIEGROUP_MT "dmech.liegroup"
#define DM_LIEELEM_MT "dmech.lieelement"
#define DM_LIESPHERE_MT "dmech.liesphere"

typedef struct dm_lgroup {
  dm_lie_group *G;              /* NULL until built */
} dm_lgroup;

typedef union dm_lslot {
  double x;
  dm_expr e;
} dm_lslot;

typedef struct dm_lelem {
  const dm_lie_group *G;        /* owned by the group userdata (user value 1) */
  int sym;                      /* 1: v[i].e are nodes; 0: v[i].x numbers */
  dm_lslot v[];
} dm_lelem;

/* Push a group userdata owning G (built by the caller right after the push:
 * the userdata is pushed empty, then *slot = G).  Usage:
 *   dm_lie_group **slot = dm_lua_newgroup(L); *slot = dm_lie_so3(&e);
 * and raise if *slot is NULL. */
dm_lie_group **dm_lua_newgroup(lua_State *L);
/* The group at idx or raise (argument error naming what was expected). */
const dm_lie_group *dm_lua_checkgroup(lua_State *L, int idx);
const dm_lie_group *dm_lua_togroup(lua_State *L, int idx);

/* Push a new element of the group whose userdata is at gidx (numeric or
 * symbolic; values unset). */
dm_lelem *dm_lua_newelem(lua_State *L, int gidx, int sym);
/* The element at idx (NULL if it is not one); checked: raises. */
dm_lelem *dm_lua_toelem(lua_State *L, int idx);
dm_lelem *dm_lua_checkelem(lua_State *L, int idx, const char *fname);
/* Push the group userdata of the element at idx. */
void dm_lua_elemgroup(lua_State *L, int idx);
/* The element's values as numbers (raises if symbolic, naming fname) or as
 * nodes (numbers become constants) into out (nq). */
void dm_lua_elem_numbers(lua_State *L, const dm_lelem *el, const char *fname, double *out);
void dm_lua_elem_nodes(lua_State *L, const dm_lelem *el, dm_expr *out);

/* Read n values (a vec, a list of numbers or expressions, a symbolic
 * vector, or a number when n == 1) into x (numbers) and ex (nodes; numbers
 * become constants); returns 1 when some entry is an expression.  Raises
 * naming fname and `what`. */
int dm_lua_readvals(lua_State *L, int idx, size_t n, const char *fname, const char *what,
                    double *x, dm_expr *ex);
/* Push n numbers as a vec, or n nodes as a list of expressions. */
void dm_lua_pushvals(lua_State *L, size_t n, int sym, const double *x, const dm_expr *ex);
/* Push an r x c matrix: a mat (numbers) or a list of rows of expressions. */
void dm_lua_pushmatvals(lua_State *L, size_t r, size_t c, int sym, const double *x,
                        const dm_expr *ex);

/* Raise the expression context's error after a failed symbolic call. */
int dm_lua_lie_symfail(lua_State *L, const char *fname, const dm_err *e);

/* Objects whose functions are bound to them (G.exp, S.log): a metatable
 * with __methods = funcs registered under "<prefix><name>"; __index from
 * meta should call dm_lua_bound_index, which returns (and caches in user
 * value 1) a closure passing the object first, else calls fields(L). */
void dm_lua_newclass_bound(lua_State *L, const char *tname, const char *name,
                           const char *prefix, const dm_reg *funcs, const luaL_Reg *meta);
int dm_lua_bound_index(lua_State *L, const char *prefix, int (*fields)(lua_State *));

int dm_lua_lie_sphere(lua_State *L);      /* dm.lie.sphere (l_lie_sphere.c) */
void dm_lua_open_liesphere(lua_State *L);
void dm_lua_open_lieelem(lua_State *L);   /* the element class (l_lie_elem.c) */
void dm_open_lie(lua_State *L);           /* dm.lie (l_lie.c) */

#endif
