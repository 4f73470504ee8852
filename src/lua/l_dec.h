/* l_dec.h -- shared by the DEC bindings (l_dec.c meshes, l_dec_mesh.c their
 * constructors, l_dec_sparse.c sparse matrices, l_dec_cochain.c cochains).
 *
 * A Mesh owns its complex and geometry.  Cochains and operators built from a
 * mesh keep it alive through user value 1 and remember its complex, so that
 * operands from two meshes are refused.  Types: a cochain knows its degree
 * and side (primal or dual); an operator knows the type it takes and the
 * type it gives (deg < 0: untyped, any vector of the right length).
 */
#ifndef DM_L_DEC_H
#define DM_L_DEC_H

#include "lua/dmlua.h"
#include "dec/dec.h"

#define DM_MESH_MT "dmech.mesh"
#define DM_SPARSE_MT "dmech.sparse"
#define DM_COCHAIN_MT "dmech.cochain"

typedef struct dm_lmesh {
  dm_dec_complex *K;
  dm_dec_geom *G;
  unsigned warned;             /* bit k: nonpositive *_k reported */
  int *parent;                 /* made by M:refine(): 2 coarse vertices per
                                  vertex; the coarse mesh is user value 1 */
} dm_lmesh;

typedef struct dm_ltype {
  int deg, dual;               /* deg < 0: untyped */
} dm_ltype;

typedef struct dm_lsparse {
  dm_sparse *A;
  const dm_dec_complex *K;     /* NULL for untyped matrices */
  dm_ltype dom, rng;
  char label[32];
  /* A = diag(w)^-1 S on the free unknowns, identity rows on fixed ones with
   * values g (all NULL for a plain matrix) */
  dm_sparse *S;
  double *w, *g;
  unsigned char *fixed;
  int kernel;                  /* a Laplacian without boundary condition */
  dm_dec_solver *chol;         /* factors, made on the first solve */
  dm_sparse_lu *lu;
} dm_lsparse;

typedef struct dm_lcochain {
  const dm_dec_complex *K;
  dm_ltype t;
  int n;
  double *v;                   /* points into the userdata block */
} dm_lcochain;

/* meshes (l_dec.c) */
dm_lmesh *dm_checkmesh(lua_State *L, int arg);
/* "primal 1-cochain", "dual 0-cochain" */
const char *dm_dec_typename(lua_State *L, dm_ltype t);
/* Number of values of a cochain of type t. */
int dm_dec_typesize(const dm_dec_complex *K, dm_ltype t);

/* Push a new Mesh owning K and G (NULL: raise e's message). */
dm_lmesh *dm_pushmesh(lua_State *L, dm_dec_complex *K, dm_dec_geom *G, const char *what, dm_err *e);
/* Push a Mesh built from m (consumed; NULL: raise e's message). */
dm_lmesh *dm_pushmesh_data(lua_State *L, dm_dec_meshdata *m, const char *what, dm_err *e);
/* Unknown option keys of the table at t raise "<fname>: unknown option 'k'
 * (options: a, b)" (a misspelt option is never silently ignored). */
void dm_dec_checkopts(lua_State *L, int t, const char *fname, const char *const *known);
/* dm.mesh with its constructors (l_dec_mesh.c) into the table at the top. */
void dm_open_dec_mesh(lua_State *L);
/* The methods of l_dec_ops.c into the Mesh class, dm.mesh.load. */
void dm_open_dec_ops(lua_State *L);

/* sparse matrices (l_dec_sparse.c): an empty Sparse pushed, user value =
 * the value at mesh_idx (0: none). */
dm_lsparse *dm_newsparse(lua_State *L, int mesh_idx);
dm_lsparse *dm_checksparse(lua_State *L, int arg);
void dm_open_sparse(lua_State *L);

/* cochains (l_dec_cochain.c): a zero cochain of type t on the mesh at
 * mesh_idx, pushed. */
dm_lcochain *dm_newcochain(lua_State *L, int mesh_idx, dm_ltype t);
dm_lcochain *dm_tocochain(lua_State *L, int arg);
dm_lcochain *dm_checkcochain(lua_State *L, int arg);
void dm_open_cochain(lua_State *L);

#endif
