/* l_mpi.c -- dm.mpi.rank, size, barrier, wtime, info: the Lua face of
 * core/mpi.h.  MPI starts when the binding opens; a build without MPI
 * started by mpirun with several processes records why it cannot run, and
 * dm.mpi.* and dm.ensemble raise that message (l_ensemble.h). */
#include <config.h>
#include <stdio.h>
#include <time.h>

#include "lua/l_ensemble.h"
#include "core/mpi.h"
#include "core/trajectory_h5.h"

/* The status of dm_mpi_start() at load time (a build without MPI started by
 * mpirun with several processes refuses to run ensembles). */
static int mpi_status = DM_OK;
static char mpi_message[DM_ERRMSG_MAX];

int dm_lua_mpi_check(lua_State *L, const char *what)
{
  if (mpi_status != DM_OK)
    return luaL_error(L, "%s: %s", what, mpi_message);
  return 0;
}

static int l_mpi_rank(lua_State *L)
{
  dm_lua_mpi_check(L, "dm.mpi.rank");
  lua_pushinteger(L, dm_mpi_rank());
  return 1;
}

static int l_mpi_size(lua_State *L)
{
  dm_lua_mpi_check(L, "dm.mpi.size");
  lua_pushinteger(L, dm_mpi_size());
  return 1;
}

static int l_mpi_barrier(lua_State *L)
{
  dm_err e;
  int st;
  dm_lua_mpi_check(L, "dm.mpi.barrier");
  if ((st = dm_mpi_barrier(&e)) != DM_OK)
    return dm_lua_fail(L, "dm.mpi.barrier", st, &e);
  return 0;
}

/* Monotonic wall-clock seconds (MPI_Wtime's meaning, with or without MPI):
 * os.clock counts the CPU time of every thread. */
static int l_mpi_wtime(lua_State *L)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  lua_pushnumber(L, (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec);
  return 1;
}

static int l_mpi_info(lua_State *L)
{
  lua_createtable(L, 0, 6);
  lua_pushboolean(L, dm_mpi_built());
  lua_setfield(L, -2, "built");
  lua_pushboolean(L, dm_mpi_active());
  lua_setfield(L, -2, "active");
  lua_pushstring(L, dm_mpi_library());
  lua_setfield(L, -2, "library");
  lua_pushstring(L, dm_h5_mode());
  lua_setfield(L, -2, "hdf5");
  lua_pushstring(L, dm_h5_version());
  lua_setfield(L, -2, "hdf5_version");
  lua_pushinteger(L, dm_mpi_local_size());
  lua_setfield(L, -2, "local_size");
  return 1;
}

/* }====================================================================== */

static const dm_reg mpi_funcs[] = {
  {"rank", l_mpi_rank, "dm.mpi.rank() -> integer",
   "This process's MPI rank (0 without mpirun)."},
  {"size", l_mpi_size, "dm.mpi.size() -> integer",
   "The number of MPI ranks running the script (1 without mpirun)."},
  {"barrier", l_mpi_barrier, "dm.mpi.barrier()",
   "Wait until every rank has reached this call (no-op without mpirun)."},
  {"wtime", l_mpi_wtime, "dm.mpi.wtime() -> seconds",
   "Wall-clock seconds from an arbitrary origin (monotonic), for timing runs; os.clock counts the CPU time of all threads."},
  {"info", l_mpi_info, "dm.mpi.info() -> {built=, active=, library=, hdf5=, ...}",
   "How this dmech was built and started: MPI support and library, the HDF5 version and whether it writes in parallel."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_mpi(lua_State *L)
{
  dm_err e;
  if ((mpi_status = dm_mpi_start(&e)) != DM_OK)
    snprintf(mpi_message, sizeof mpi_message, "%s", e.msg);
  lua_newtable(L);
  dm_register(L, "dm.mpi.", mpi_funcs);
  lua_setfield(L, -2, "mpi");
}
