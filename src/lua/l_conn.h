/* l_conn.h -- private glue of the connection bindings: l_conn.c (dm.bundle,
 * bundles), l_conn_point.c (their points), l_conn_args.c (readers of
 * shapes, group elements, options), l_conn_cont.c (dm.connection,
 * dm.mechanical_connection), l_conn_disc.c (dm.discrete_connection,
 * dm.order_test), l_conn_dmech.c (dm.discrete_mechanical_connection),
 * l_conn_mesh.c (the Levi-Civita connection of a triangle mesh).
 *
 * A bundle is a userdata "dmech.bundle" owning a dm_conn_bundle; user value
 * 1 is a table {group = <dm.lie group userdata>, L = <reduced Lagrangian
 * l(x, xdot, xi, p) or nil>, params = {{name, value}, ...} or nil,
 * system = <System or nil>, name = <catalog name or nil>}.  A point is a
 * userdata "dmech.bpoint" holding nq numbers; user value 1 is its bundle.
 * Connections keep their bundle (and parent, guess, Lua callbacks) in
 * their user values, so C pointers into them stay valid.
 */
#ifndef DM_L_CONN_H
#define DM_L_CONN_H

#include "lua/dmlua.h"
#include "lua/l_lie.h"
#include "conn/conn.h"

#define DM_BUNDLE_MT "dmech.bundle"
#define DM_BPOINT_MT "dmech.bpoint"
#define DM_CONN_MT "dmech.connection"
#define DM_DCONN_MT "dmech.dconnection"
#define DM_MESHCONN_MT "dmech.meshconnection"

typedef struct dm_lbundle {
  dm_conn_bundle *B;            /* NULL until built */
} dm_lbundle;

typedef struct dm_lbpoint {
  const dm_conn_bundle *B;      /* owned by the bundle (user value 1) */
  double q[];
} dm_lbpoint;

/* bundles (l_conn.c) */
dm_lbundle *dm_lua_checkbundle(lua_State *L, int idx);
/* Push the field `key` of the bundle's user value table. */
void dm_lua_bundle_field(lua_State *L, int bidx, const char *key);
/* The reduced Lagrangian of the bundle at bidx traced into nodes: pushes
 * nothing, fills xs, xd (nx), xi (dim), par (npar) and *l; 0 when the
 * bundle has no Lagrangian.  npar <= 32. */
int dm_lua_bundle_lagrangian(lua_State *L, int bidx, dm_expr *xs, dm_expr *xd, dm_expr *xi,
                             dm_expr *par, double *parval, size_t *npar, dm_expr *l);
/* Trace l(x, xdot, xi, p) (the function at fidx, parameters {{name,
 * value}, ...} at pidx) for the bundle B: fills the nodes as above. */
void dm_lua_trace_lagrangian(lua_State *L, const dm_conn_bundle *B, int fidx, int pidx,
                             dm_expr *xs, dm_expr *xd, dm_expr *xi, dm_expr *par, double *parval,
                             size_t *npar, dm_expr *l);
/* The columns of a trajectory (at tidx) that sample the shape of the
 * bundle at bidx: NULL when its coordinates are the shape coordinates,
 * else the columns of the shape coordinates by name (bundles from a
 * system) written into buf (nx); raises otherwise.  Then reads q0 from
 * q0idx (0 or nil: the first sample with the identity) into q0. */
const size_t *dm_lua_phase_cols(lua_State *L, int bidx, int tidx, int q0idx, size_t *buf,
                                double *q0);

/* points (l_conn_point.c) */
/* A new point of the bundle at bidx holding q (nq numbers). */
dm_lbpoint *dm_lua_pushpoint(lua_State *L, int bidx, const double *q);
/* Read a point of the bundle at bidx from idx: a point of that bundle, or
 * a table as B:point{...} takes, or nq coordinates.  Raises naming what. */
void dm_lua_readpoint(lua_State *L, int bidx, int idx, const char *what, double *q);
/* The contents of B:point{...} (the table at idx) into q: {x =, g =} on
 * trivial bundles, {R =} on the sphere frames, {q =} otherwise. */
void dm_lua_point_from_table(lua_State *L, int bidx, int idx, const char *what, double *q);
/* The point class "dmech.bpoint" (called by dm_open_conn). */
void dm_lua_open_conn_point(lua_State *L);

/* readers shared by the connection bindings (l_conn_args.c) */
/* n numbers at idx: a vec, a list, or (n = 1) a number; raises naming what. */
size_t dm_lua_conn_readnums(lua_State *L, int idx, const char *what, double *x, size_t n);
/* An element of the Lie algebra (dim numbers: a vec, or a number when
 * dim = 1) at idx; raises as dm_checkvector does. */
void dm_lua_conn_readalgebra(lua_State *L, int idx, size_t dim, double *xi);
/* Options of a transport: {substeps = n, tol = t} at idx (0: none). */
void dm_lua_readtopts(lua_State *L, int idx, const char *fname, dm_conn_topts *o);
/* Raise "<fname>: unknown option 'k' (options: a, b)" for keys not in known. */
void dm_lua_conn_checkkeys(lua_State *L, int idx, const char *fname, const char *const *known);
/* A shape point (nx numbers: a vec or a list), checked by the bundle. */
void dm_lua_readshape(lua_State *L, const dm_conn_bundle *B, int idx, const char *what,
                      double *x);
/* A list of shape points (a list of vecs / lists, or a mat with one point
 * per row) into a scratch vec pushed on the stack; returns the data and
 * the count in *n. */
double *dm_lua_readshapes(lua_State *L, const dm_conn_bundle *B, int idx, const char *what,
                          size_t *n);
/* A group element of G (the group userdata at gidx) from idx: an element,
 * a number (one-coordinate groups) or the coordinates. */
void dm_lua_readgroupelem(lua_State *L, int gidx, int idx, const char *what, double *g);
/* Push a numeric element of the group userdata at gidx. */
void dm_lua_pushgroupelem(lua_State *L, int gidx, const double *g);
/* Push a holonomy result table {spatial, body, angle[, axis]} with a
 * __tostring; gidx the group userdata; body may be NULL. */
void dm_lua_pushholonomy(lua_State *L, int gidx, const double *spatial, const double *body,
                         double lifted);

/* continuous connections (l_conn_cont.c) */
/* Push a connection on a new trivial bundle S x G (G the group userdata
 * at gidx) from the expressions A (dim x nx) in the symbols x, with
 * parameters par (names pnames, values pv): red:connection(). */
void dm_lua_push_conn_exprs(lua_State *L, int gidx, const char *name, size_t nx,
                            const dm_expr *x, const dm_expr *A, size_t npar, const dm_expr *par,
                            const char *const *pnames, const double *pv);
dm_conn *dm_lua_checkconn(lua_State *L, int idx);
dm_conn *dm_lua_toconn(lua_State *L, int idx);
void dm_lua_open_conn_cont(lua_State *L);
/* discrete (l_conn_disc.c) and mesh (l_conn_mesh.c) connections */
dm_conn_dc *dm_lua_todconn(lua_State *L, int idx);
/* Push an empty discrete connection on the bundle at bidx (user value
 * {bundle = B}); returns its slot for the dm_conn_dc, NULL until set. */
dm_conn_dc **dm_lua_newdconn(lua_State *L, int bidx);
/* Set field key of the user value table of the discrete connection at idx
 * to the value at vidx (keeps it alive: guess, parent). */
void dm_lua_dconn_setfield(lua_State *L, int idx, const char *key, int vidx);
void dm_lua_open_conn_disc(lua_State *L);
/* dm.discrete_mechanical_connection (l_conn_dmech.c) */
void dm_lua_open_conn_dmech(lua_State *L);
void dm_lua_open_conn_mesh(lua_State *L);
/* the mesh connection constructor (dm.discrete_connection{mesh = M}) */
int dm_lua_meshconn_new(lua_State *L, int midx);

#endif
