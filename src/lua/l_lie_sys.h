/* l_lie_sys.h -- private glue of the bindings of systems on Lie groups
 * (l_lie_system.c) and their integrators (l_lie_integ.c).  Not for other
 * bindings: dm.system and dm.integrator reach them through
 * dm_lua_lie_system and the system's __integrator metamethod; dm.ensemble
 * (l_ensemble.c) takes the integrator through dm_lua_lie_tointeg and reads
 * its members' states with dm_lua_lie_readstate.
 *
 * A system is a userdata "dmech.liesystem" owning a dm_lie_system (user
 * value 1: the group userdata of its space); an integrator a userdata
 * "dmech.lieinteg" owning a dm_integrator (user value 1: the system).
 */
#ifndef DM_L_LIE_SYS_H
#define DM_L_LIE_SYS_H

#include "lua/l_lie.h"
#include "lie/lie_system.h"

#define DM_LIESYS_MT "dmech.liesystem"
#define DM_LIEINTEG_MT "dmech.lieinteg"

typedef struct dm_llsys {
  dm_lie_system *S;             /* NULL until built */
} dm_llsys;

/* A state read from {g =, mu = | xi = [, t =]}. */
typedef struct dm_lstate_lie {
  double t;
  double g[DM_LIE_NQ_MAX], mu[DM_LIE_DIM_MAX], xi[DM_LIE_DIM_MAX];
} dm_lstate_lie;

dm_llsys *dm_lua_tolsys(lua_State *L, int idx);
dm_llsys *dm_lua_checklsys(lua_State *L, int idx);

/* Read the state at idx: g an element of the system's space (numeric,
 * checked to be in the group to 1e-10), mu, or xi turned into mu by the
 * Legendre map of I; xi filled from mu.  Raises naming fname. */
void dm_lua_lie_readstate(lua_State *L, dm_integrator *I, const dm_lie_system *S, int idx,
                          const char *fname, dm_lstate_lie *st);
/* Push {t =, g = element (of the group userdata at gidx), mu = vec, xi = vec}. */
void dm_lua_lie_pushstate(lua_State *L, int gidx, const dm_lie_system *S, double t,
                          const double *g, const double *mu, const double *xi);

/* The open integrator at idx when it is one of a system on a group (*S
 * its system, *h its step, NAN when not set), else NULL. */
dm_integrator *dm_lua_lie_tointeg(lua_State *L, int idx, const dm_lie_system **S, double *h);

/* dm.integrator(sys, opts) for a system on a group (the __integrator
 * metamethod of the system). */
int dm_lua_lie_integrator(lua_State *L);

void dm_lua_open_liesys(lua_State *L);     /* l_lie_system.c */
void dm_lua_open_lieinteg(lua_State *L);   /* l_lie_integ.c */

#endif
