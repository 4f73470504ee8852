/* l_ensemble.h -- private glue of the ensemble bindings: l_ensemble.c
 * (dm.ensemble), l_rng.c (dm.rng), l_mpi.c (dm.mpi).  Not for other
 * bindings. */
#ifndef DM_L_ENSEMBLE_H
#define DM_L_ENSEMBLE_H

#include <gsl/gsl_rng.h>

#include "lua/dmlua.h"

/* random generators (l_rng.c) */
/* The generator of the rng userdata at idx; raises when it is closed. */
gsl_rng *dm_lua_checkrng(lua_State *L, int idx);
/* Push a new rng userdata seeded with seed; raises when out of memory. */
void dm_lua_pushrng(lua_State *L, unsigned long seed);
/* The rng class and dm.rng into the table at the top of the stack. */
void dm_open_rng(lua_State *L);

/* MPI (l_mpi.c) */
/* Raise "<what>: <why>" when MPI could not start at load time; else 0. */
int dm_lua_mpi_check(lua_State *L, const char *what);
/* Start MPI (recording a failure) and put dm.mpi into the table at the
 * top of the stack. */
void dm_open_mpi(lua_State *L);

#endif
