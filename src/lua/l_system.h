/* l_system.h -- the System userdata (dm.system, dm.builtin.*) for other
 * bindings: integrators (l_integrator.c) and reduction read the compiled
 * dm_system and, for traced systems, the expression nodes it came from.
 *
 * A System is a full userdata "dmech.system" holding a dm_lsystem.  Traced
 * systems (dm.system{...}) keep the nodes of L, the coordinate and velocity
 * symbols, the parameters, the force and constraint expressions in the Lua
 * state's expression context (dm_lua_exprctx); built-in C systems
 * (dm.builtin.*) have traced == 0 and no nodes: code that needs
 * expressions (reduction) must refuse them with dm_lua_checktraced().
 *
 * Ownership: the userdata owns everything in the struct (released by its
 * __gc).  Pointers taken from it (&ls->sys, names, node arrays) stay valid
 * while the userdata is reachable: a binding that keeps one (an integrator)
 * must anchor the System userdata, e.g. in its user value.  __close (and
 * __gc) release everything at once, idempotently: a closed System has
 * sys.lagrangian == NULL (dm_lua_tosystem returns NULL, checks raise
 * "attempt to use a closed system"), and objects built on it must test
 * that before using the pointers they kept.
 *
 * Parameters: ls->sys.par holds the current values (the compiled callbacks
 * read them at every call).  Change them through dm_lua_system_setparam(),
 * which refreshes derived data and bumps ls->gen; objects that cache
 * anything computed from the parameters (integrators: the inverse mass
 * matrix) compare gen and rebuild.
 */
#ifndef DM_L_SYSTEM_H
#define DM_L_SYSTEM_H

#include "lua/dmlua.h"
#include "expr/expr.h"
#include "core/system.h"
#include "integrators/integrator.h"

#define DM_SYSTEM_MT "dmech.system"

typedef struct dm_lsystem {
  dm_system sys;        /* the compiled system; sys.coords, sys.params are the names */
  size_t n, npar, m;    /* = sys.n, sys.npar, sys.m */
  int traced;           /* 1: dm.system (nodes below valid); 0: built-in C */
  int native;           /* 1 when native code runs the Lagrangian */
  unsigned long gen;    /* bumped by every parameter change */
  /* expression nodes (traced systems only; else DM_EXPR_NONE / NULL) */
  dm_expr L;
  dm_expr *q, *v;       /* n coordinate and velocity symbols */
  dm_expr *par;         /* npar parameter nodes, in sys.params order */
  dm_expr *force;       /* n generalized-force components, or NULL */
  dm_expr *constr;      /* m constraint expressions g(q) (0 = satisfied), or NULL */
  unsigned char *cyclic;  /* n flags: L, force, constraints free of q_i */
  /* coordinate arrays (dm.coords): coordinates first .. first+count-1 are
   * name[1] .. name[count] */
  size_t ngroups;
  struct dm_lcoordarray {
    char *name;
    size_t first, count;
  } *groups;
  /* private to l_system.c: conversions (Legendre maps) and scratch */
  dm_integrator *conv;
  double *buf;          /* 6n doubles */
} dm_lsystem;

/* The System at idx, or NULL. */
dm_lsystem *dm_lua_tosystem(lua_State *L, int idx);
/* The System at idx, or raise "bad argument #idx to 'f' (system expected,
 * got X)". */
dm_lsystem *dm_lua_checksystem(lua_State *L, int idx);
/* Same, and raise "<what> needs a system defined by a Lagrangian
 * (dm.system{...}); '<name>' is a built-in C system without expressions"
 * for built-ins. */
dm_lsystem *dm_lua_checktraced(lua_State *L, int idx, const char *what);

/* Index of coordinate / parameter `name`, or -1. */
long dm_lua_system_coord(const dm_lsystem *ls, const char *name);
long dm_lua_system_param(const dm_lsystem *ls, const char *name);
/* Set parameter i to x: refreshes the mass of traced systems, bumps gen. */
void dm_lua_system_setparam(lua_State *L, dm_lsystem *ls, size_t i, double x);
/* params = {name = value, ...} (sorted by name) or {{name, value}, ...}
 * (this order) from field "params" of the table at t: pushes the params
 * value and two userdata arrays (names, values; names anchored in the
 * params table), returns their length.  Raises "dm.system: ..." on a
 * params value of another shape, a name that is not an identifier, a name
 * listed twice or a value that is not finite. */
size_t dm_lsystem_read_params(lua_State *L, int t, const char ***pn, double **pv);
/* Raise "<what>: parameter '<name>' must be a finite number, got nan". */
void dm_lsystem_checkfinite(lua_State *L, const char *what, const char *name, double x);

/* Read n numbers for the system's coordinates from the value at idx: a vec,
 * a list of numbers, or a table keyed by coordinate names ({r = 2, z = 0.3};
 * an array of coordinates by its name and a list, {x = {...}, theta = 1};
 * missing names raise).  `what` names the value in messages ("state.q").
 * Raises on a wrong type or length; writes out[0..n). */
void dm_lua_system_readvec(lua_State *L, const dm_lsystem *ls, int idx,
                           const char *what, double *out);

/* Push a new System userdata in the empty state (metatable set, nothing
 * allocated): for constructors of built-in systems, which then fill
 * ls->sys and call dm_lua_system_finish(). */
dm_lsystem *dm_lua_system_new(lua_State *L);
/* Complete a System whose ls->sys is filled (allocate buffers, the
 * conversion helper); raises on failure (the userdata then owns and frees
 * whatever was filled).  cyclic: names of cyclic coordinates (NULL-ended
 * list, may be NULL) for systems without expressions. */
void dm_lua_system_finish(lua_State *L, dm_lsystem *ls, const char *const *cyclic);

/* Push "a, b, c" (n names; "none" when n == 0) and return it, for
 * messages listing coordinates or parameters. */
const char *dm_lsystem_names(lua_State *L, const char *const *names, size_t n);
/* Index of the coordinate / parameter named by the string at arg, or raise
 * "no coordinate 'x' in system 's' (coordinates: ...)". */
long dm_lsystem_checkcoord(lua_State *L, const dm_lsystem *ls, int arg);
long dm_lsystem_checkparam(lua_State *L, const dm_lsystem *ls, int arg);

/* Native code of a traced system compiled in the background: installs
 * what is ready and says where it stands (native: in use; pending: still
 * compiling; the first failure's message pushed when want_error, else
 * nothing pushed).  Systems without a Lagrangian compiled here: their
 * creation-time flag, nothing pending. */
void dm_lsystem_native(lua_State *L, dm_lsystem *ls, int *native, int *pending,
                       int want_error);

/* ---- shared by l_system.c and l_system_obj.c only ---- */
int dm_lsystem_gc(lua_State *L);
void dm_lsystem_open_class(lua_State *L);           /* metatables */
void dm_lsystem_push_params(lua_State *L, int sys); /* sets the params proxy */

#endif
