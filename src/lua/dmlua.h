/* dmlua.h -- what every dmech Lua binding shares.
 *
 * Bindings (src/lua/l*.c) turn C objects into userdata, check arguments and
 * turn dm statuses into Lua errors.  They never compute.  Patterns:
 *
 *  - Every exposed function or method is registered through a dm_reg table
 *    carrying a one-line signature and one sentence of documentation; the
 *    registry behind help()/apropos() is filled as a side effect, and a test
 *    fails when something reachable from `dm` has no entry.
 *  - Userdata are created empty with their metatable set before anything is
 *    allocated (liolib style); __gc and __close share one idempotent cleanup.
 *  - Numeric arguments accept a dm.vec or a Lua table of numbers:
 *    dm_checkvector() converts a table in place (the argument slot then holds a
 *    new vec), so memory is always owned by Lua and an error can never leak.
 */
#ifndef DM_LUA_H
#define DM_LUA_H

#include <lua.h>
#include <lauxlib.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "core/status.h"
#include "core/numfmt.h"   /* dm_num_format: numbers as the bindings print them */

#define DM_VEC_MT "dmech.vec"
#define DM_MAT_MT "dmech.mat"

/* ---- documented registration -------------------------------------------- */

typedef struct dm_reg {
  const char *name;
  lua_CFunction func;
  const char *sig;   /* "dm.vec(n | {x1,...} | x1, x2, ...) -> vec" */
  const char *doc;   /* one sentence */
} dm_reg;

/* Put the functions of `regs` (terminated by a NULL name) into the table at
 * the top of the stack and record their documentation under
 * "<prefix><name>" (prefix "dm." for module functions, "vec:" for methods). */
void dm_register(lua_State *L, const char *prefix, const dm_reg *regs);

/* Record documentation for `name`; if the value at `idx` is a function (or
 * any non-nil value) it is also indexed by identity so help(value) finds it.
 * idx 0 means no value. */
void dm_doc_add(lua_State *L, const char *name, const char *sig,
                const char *doc, int idx);

/* Create the metatable `tname` for a class whose methods are documented as
 * "<kind>:<method>"; `methods` becomes __index (unless `meta` sets __index),
 * `meta` supplies metamethods (undocumented).  Leaves the metatable on the
 * stack. */
void dm_newclass(lua_State *L, const char *tname, const char *kind,
                 const dm_reg *methods, const luaL_Reg *meta);
/* The end of an __index metamethod of such a class (when `meta` sets one):
 * push the method of the object at 1 named by the key at 2, nil when there
 * is none; returns 1. */
int dm_index_methods(lua_State *L);

/* A documented field of a class, registered as "<kind>.<name>"; sig NULL
 * means "<kind>.<name>". */
typedef struct dm_field {
  const char *name;
  const char *sig;   /* "sys.coords -> {name, ...}" */
  const char *doc;   /* one sentence */
} dm_field;

/* Document the fields of class `kind` (list terminated by a NULL name). */
void dm_doc_fields(lua_State *L, const char *kind, const dm_field *fields);

/* The option keys of the documented function `name` (NULL-terminated):
 * help lists them, the prompt completes them inside the options table, a
 * misspelt key gets a did-you-mean.  No-op when `name` is not documented. */
void dm_doc_options(lua_State *L, const char *name, const char *const *keys);

/* Push the docs registry table (name -> {sig=, doc=}). */
void dm_pushdocs(lua_State *L);

/* ---- errors ------------------------------------------------------------------ */

/* Raise a Lua error "<what>: <message>" for a failed dm status; `e` may be
 * NULL or have an empty message, then the status name is used. */
int dm_lua_fail(lua_State *L, const char *what, int status, const dm_err *e);

/* The registry key of the dm table (set when the expression binding opens;
 * dm.config lives in it). */
#define DM_LUA_DMTABLE "dmech.expr.dm"

/* A run (integ:run) that ended early with status and msg (the partial
 * trajectory is on the stack): with the run option strict = true (or
 * dm.config.strict) raise "run: <msg>"; else, unless warn = false (or
 * dm.config.warn = false), write "warning: run ended early (<status>):
 * <msg>" to io.stderr; push "run: <msg>" (the second result) and return 1.
 * dm_lua_run_check_flags checks both options of the table at opts (0: none)
 * up front. */
int dm_lua_run_ended(lua_State *L, int opts, int status, const char *msg);
/* "warning: <text>" on a line of its own, through io.stderr, unless
 * dm.config.warn = false (rank 0 only under MPI). */
void dm_lua_warning(lua_State *L, const char *text);
void dm_lua_run_check_flags(lua_State *L, int opts);

/* luaL_typeerror-style message with a free-form expectation:
 * "bad argument #arg to 'f' (<expected> expected, got <actual>)". */
int dm_argexpected(lua_State *L, int arg, const char *expected,
                   const char *actual);

/* Give numbers a __tostring that prints NaN as "nan" (print, tostring,
 * string.format "%s" and every message built with them; Lua's own
 * conversion says "-nan" for 0/0 on x86-64).  A process-wide setting of
 * the state: the dmech program and dmech-fuzz call it, a host loading the
 * module keeps Lua's behaviour unless it calls it too. */
void dm_lua_number_tostring(lua_State *L);

/* luaL_checkoption that does not turn a number into a name ("-nan"). */
int dm_checkoption(lua_State *L, int arg, const char *def, const char *const lst[]);

/* luaL_tolstring for messages: NaN and infinities print as "nan", "inf",
 * "-inf" (Lua's own conversion says "-nan" for the NaN of 0/0 on x86). */
const char *dm_tolstring(lua_State *L, int idx, size_t *len);

/* luaL_checkstring for strings that go to C as C strings (file names,
 * names, metadata): a string, not a number turned into one, and one
 * holding a NUL byte is refused, never truncated. */
const char *dm_checkcstring(lua_State *L, int arg);
/* lua_tostring with the same check on a value that is not an argument;
 * `what` starts the message "<what>: NUL byte at position k of "...""). */
const char *dm_tocstring(lua_State *L, int idx, const char *what);

/* 1 when the table at index t has a key that is not among keys (a
 * NULL-terminated list of strings), that key (the first one lua_next
 * gives) pushed; else 0, nothing pushed. */
int dm_unknownkey(lua_State *L, int t, const char *const *keys);
/* Raise "<what>: unknown <noun> 'k' (<noun>s: <list>)" ([k] for a key that
 * is not a string) for such a key of the table at t; return if none. */
void dm_checkkeys(lua_State *L, int t, const char *const *keys, const char *what,
                  const char *noun, const char *list);

/* Option value from the table at index t: number field `key` or default;
 * raises "bad argument #t to 'f' (field 'key': number expected, got X)". */
double dm_optnumberfield(lua_State *L, int t, const char *key, double def);
lua_Integer dm_optintegerfield(lua_State *L, int t, const char *key,
                               lua_Integer def);
const char *dm_optstringfield(lua_State *L, int t, const char *key,
                              const char *def);

/* ---- vectors and matrices -------------------------------------------------- */

/* A vec userdata: a gsl_vector whose data live in the userdata itself or, for
 * a view (row of a matrix), in the object held by user value 1. */
typedef struct dm_lvec {
  gsl_vector v;
} dm_lvec;

typedef struct dm_lmat {
  gsl_matrix m;
} dm_lmat;

/* New zero vector / matrix userdata pushed on the stack. */
gsl_vector *dm_pushvec(lua_State *L, size_t n);
gsl_matrix *dm_pushmat(lua_State *L, size_t rows, size_t cols);
/* Push a copy of a C array / GSL object as a new vec / mat. */
gsl_vector *dm_pushvec_copy(lua_State *L, const double *x, size_t n);
gsl_matrix *dm_pushmat_copy(lua_State *L, const gsl_matrix *src);

/* The vec / mat at arg, or NULL when it is something else. */
gsl_vector *dm_tovec(lua_State *L, int arg);
gsl_matrix *dm_tomat(lua_State *L, int arg);
/* The vec / mat at arg or raise an argument error. */
gsl_vector *dm_checkvec(lua_State *L, int arg);
gsl_matrix *dm_checkmat(lua_State *L, int arg);

/* Accept a vec or a sequence table of numbers at arg (a table is converted in
 * place to a new vec).  n == 0 accepts any non-empty length; otherwise the
 * length must equal n.  The result always has stride 1. */
gsl_vector *dm_checkvector(lua_State *L, int arg, size_t n);
/* Same for matrices: a mat or a table of equal-length row tables. */
gsl_matrix *dm_checkmatrix(lua_State *L, int arg, size_t rows, size_t cols);

/* Open the vec/mat classes and put dm.vec, dm.mat, ... into the table at the
 * top of the stack. */
void dm_open_doc(lua_State *L);      /* dm.docs, dm.doc */
void dm_open_linalg(lua_State *L);
void dm_open_mat(lua_State *L);   /* part of dm_open_linalg */
void dm_open_plot(lua_State *L);  /* dm.plot, dm.figure, dm.gnuplot (l_plot.c) */
/* Trajectories (l_traj.c): the Trajectory class, dm.trajectory, dm.load_trajectory.
 * Bindings producing one (integrator runs): `dm_traj **slot = dm_newtraj(L);` pushes
 * an empty Trajectory that owns whatever *slot holds (set *slot = dm_traj_alloc(...)),
 * or dm_pushtraj() allocates too (raises on failure).  Fill with dm_traj_sink; add
 * diagnostics with dm_traj_add_column(tr, DM_TRAJ_ENERGY or "momentum_<q>",
 * DM_TRAJ_DIAG, values, DM_TRAJ_REPLACE, &e); tostring shows the metadata keys
 * system, method, stages, h.  dm_totraj: NULL unless an open Trajectory. */
#define DM_TRAJ_MT "dmech.trajectory"
struct dm_traj **dm_newtraj(lua_State *L);
struct dm_traj *dm_pushtraj(lua_State *L, size_t n, const char *const *coords, unsigned flags);
struct dm_traj *dm_totraj(lua_State *L, int arg);
struct dm_traj *dm_checktraj(lua_State *L, int arg);
void dm_open_traj(lua_State *L);
/* Mark the Trajectory at arg as a table every MPI rank holds (an ensemble's
 * result): its save writes on rank 0 only. */
void dm_traj_mark_replica(lua_State *L, int arg);
void dm_open_expr(lua_State *L);  /* dm.sym, dm.fn, dm.trace, ... (l_expr.c, l_expr.h) */
void dm_open_system(lua_State *L);      /* dm.system (l_system.c, l_system.h) */
void dm_open_builtin(lua_State *L);     /* dm.systems catalog, with its C implementations (l_builtin.c) */
void dm_open_integrator(lua_State *L);  /* dm.integrator, dm.tableau, dm.methods */
void dm_open_reduce(lua_State *L);      /* dm.routh (l_reduce.c) */
void dm_open_lie(lua_State *L);         /* dm.lie: Lie groups, systems on groups (l_lie*.c) */
/* dm.system{space = G, ...}: a system on a Lie group (l_lie_system.c) */
int dm_lua_lie_system(lua_State *L);
/* Systems on spheres (l_lie_sphere.c): the n of the dm.lie.sphere(n) at idx
 * (0: not a sphere); the table at 1 made an ordinary system's fields
 * (default coords x1 .. x(n+1)); the traced system made one on S^n. */
size_t dm_lua_tosphere(lua_State *L, int idx);
void dm_lua_sphere_fields(lua_State *L, size_t n);
struct dm_system;
void dm_lua_sphere_system(lua_State *L, struct dm_system *sys, size_t n);
/* dm.integrator(sys | obj, opts) as a C function (l_integrator.c), for
 * bindings whose objects make integrators (red:integrator). */
int dm_lua_integrator(lua_State *L);
/* The C integrator of the Integrator userdata at idx (rebuilt first after
 * a parameter change); raises when it is not an open Integrator.  The
 * userdata owns it: keep the userdata on the stack while using it. */
struct dm_integrator *dm_lua_tointegrator(lua_State *L, int idx);
void dm_open_dec(lua_State *L);         /* dm.mesh.*, dm.sparse (l_dec*.c) */
void dm_open_conn(lua_State *L);        /* dm.bundle, dm.connection, ... (l_conn*.c) */
void dm_open_ensemble(lua_State *L);    /* dm.ensemble, dm.mpi, dm.rng (l_ensemble.c) */
void dm_open_fields(lua_State *L);      /* dm.schrodinger, field integrators (l_fields.c) */
void dm_open_wave(lua_State *L);        /* dm.wave: multisymplectic integrators (l_wave.c) */

/* ---- module opener ------------------------------------------------------------ */

/* Fill the `dm` table at the top of the stack with every binding module. */
void dm_open_all(lua_State *L);

/* luaopen_dmech: the C part of `require "dmech"`; loads the Lua-side library
 * (dmech.init) on top of it. */
int luaopen_dmech(lua_State *L);

#endif
