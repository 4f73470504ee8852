/* l_traj.h -- private glue between l_traj.c (the Trajectory class) and
 * l_traj_build.c (dm.trajectory{...}).  Not for other bindings: they use the
 * API in dmlua.h. */
#ifndef DM_L_TRAJ_H
#define DM_L_TRAJ_H

#include "lua/dmlua.h"

/* The metadata value at arg as a string pushed on the stack: strings as they
 * are, floats in shortest round-trip form, integers and booleans by
 * tostring; anything else raises "string or number expected". */
const char *dm_ltraj_metavalue(lua_State *L, int arg);

/* Put dm.trajectory into the table at the top of the stack. */
void dm_ltraj_open_build(lua_State *L);

#endif
