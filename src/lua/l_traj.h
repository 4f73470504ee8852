/* l_traj.h -- private glue between l_traj.c (the Trajectory class),
 * l_traj_cols.c (its columns, samples and column proxies) and
 * l_traj_build.c (dm.trajectory{...}).  Not for other bindings: they use the
 * API in dmlua.h. */
#ifndef DM_L_TRAJ_H
#define DM_L_TRAJ_H

#include "lua/dmlua.h"
#include "core/trajectory.h"

/* Set metadata key of tr to the value at arg: numbers as numbers, strings
 * and booleans as strings (tostring), nil removes; anything else raises
 * "string or number expected".  Returns the trajectory's status. */
int dm_ltraj_setmeta(lua_State *L, dm_traj *tr, const char *key, int arg, dm_err *e);
/* Push the value of metadata item i: a number or a string. */
void dm_ltraj_pushmeta(lua_State *L, const dm_traj *tr, size_t i);

/* The trajectory of the Trajectory at idx inside a metamethod: a plain
 * error (not an argument error naming the metamethod) when it was closed. */
dm_traj *dm_ltraj_checkopen(lua_State *L, int idx);

/* columns and samples (l_traj_cols.c) */
/* Push column j as a new vec; raises when there are no samples. */
void dm_ltraj_pushcolumn(lua_State *L, const dm_traj *tr, size_t j);
/* Raise "no column 'x' (available: ...)" against argument arg. */
int dm_ltraj_nocolumn(lua_State *L, int arg, const dm_traj *tr, const char *name);
/* 1-based sample index (negative: from the end) -> 0-based, or (size_t)-1. */
size_t dm_ltraj_sampleindex(lua_Integer k, size_t len);
/* Push sample k (0-based) as {t=, q=vec, p=vec, v=vec, <column>=number...}. */
void dm_ltraj_pushsample(lua_State *L, const dm_traj *tr, size_t k);
/* Push traj.q / traj.p / traj.v (kind 'q', 'p' or 'v') of the Trajectory
 * at tidx; raises when it stores no such columns. */
void dm_ltraj_pushcolumns(lua_State *L, int tidx, const dm_traj *tr, char kind);
/* The metatables of the column proxies (called by dm_open_traj). */
void dm_ltraj_open_cols(lua_State *L);

/* Put dm.trajectory into the table at the top of the stack. */
void dm_ltraj_open_build(lua_State *L);

#endif
