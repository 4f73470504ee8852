/* l_traj.h -- private glue between l_traj.c (the Trajectory class) and
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

/* Put dm.trajectory into the table at the top of the stack. */
void dm_ltraj_open_build(lua_State *L);

#endif
