/* l_reduce.h -- private glue of the Routh reduction binding: l_reduce.c
 * (dm.routh, fields, formulas) and
 * l_reduce_ops.c (methods: set_mu, project, lift, reconstruct, phase, eval,
 * defect, integrator) and l_reduce_dr.c (red:discrete: the two-point
 * discrete Routh equations).  Not for other bindings.
 *
 * A Routh reduction is a userdata "dmech.routh" (dm_lrouth) whose user
 * value 1 is the reduced System userdata -- it owns the dm_routh (its
 * free_data frees it) -- and user value 2 the original System. */
#ifndef DM_L_REDUCE_H
#define DM_L_REDUCE_H

#include "lua/dmlua.h"
#include "lua/l_expr.h"
#include "lua/l_system.h"
#include "reduce/routh.h"
#include "core/trajectory.h"

#define DM_ROUTH_MT "dmech.routh"

typedef struct dm_lrouth {
  dm_routh *red;          /* owned by the reduced System (user value 1) */
} dm_lrouth;

dm_lrouth *dm_lrouth_check(lua_State *L, int idx);
/* 1 when the value at idx is a reduction whose systems are open */
int dm_lrouth_isopen(lua_State *L, int idx);
/* a list of names; numbers as a number (n = 1) or a vec */
void dm_lrouth_push_names(lua_State *L, const char *const *names, size_t n);
void dm_lrouth_push_numbers(lua_State *L, const double *x, size_t n);
/* mu (or theta): a number (r = 1), a list / vec of r numbers, or nil
 * (zeros), from the value at idx; raises naming fname */
void dm_lrouth_read_mu(lua_State *L, int idx, size_t r, double *mu, const char *fname);
/* dm.integrator on the reduced System of the reduction at idx with the
 * options table at opts (may be 0: none); pushes the Integrator */
void dm_lrouth_integrator(lua_State *L, int idx, int opts);

extern const dm_reg dm_lrouth_methods[];
/* red:discrete{...} and the class of its result (l_reduce_dr.c) */
int dm_lrouth_discrete(lua_State *L);
void dm_lrouth_open_discrete(lua_State *L);

#endif
