/* l_conn_mesh.c -- the discrete Levi-Civita connection of a triangle mesh
 * in Lua (src/conn/conn.h):
 *   LC = dm.discrete_connection{mesh = dm.mesh.sphere{level = 2}}
 *   LC:holonomy(v) ; LC:holonomies() ; LC:transition(t0, t1) ; LC:transport(ts, angle)
 * Triangles and vertices are numbered from 1.  The mesh is kept alive
 * through the user value. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_conn.h"
#include "lua/l_dec.h"

typedef struct dm_lmeshconn {
  const dm_dec_geom *G;         /* owned by the mesh (user value 1) */
} dm_lmeshconn;

static dm_lmeshconn *checkmc(lua_State *L, int idx)
{
  return luaL_checkudata(L, idx, DM_MESHCONN_MT);
}

int dm_lua_meshconn_new(lua_State *L, int midx)
{
  dm_lmesh *m = dm_checkmesh(L, midx);
  dm_lmeshconn *c;
  midx = lua_absindex(L, midx);
  if (m->K->n != 2)
    luaL_error(L, "dm.discrete_connection: the Levi-Civita connection needs a triangle mesh, "
               "got a mesh of dimension %d", m->K->n);
  if (!m->K->oriented)
    luaL_error(L, "dm.discrete_connection: the mesh is not consistently oriented");
  c = lua_newuserdatauv(L, sizeof *c, 1);
  c->G = m->G;
  luaL_setmetatable(L, DM_MESHCONN_MT);
  lua_pushvalue(L, midx);
  lua_setiuservalue(L, -2, 1);
  return 1;
}

static int tri_arg(lua_State *L, int idx, const dm_dec_geom *G)
{
  lua_Integer t = luaL_checkinteger(L, idx);
  if (t < 1 || t > G->K->nsimp[2])
    luaL_error(L, "triangle %d does not exist (1..%d)", (int)t, G->K->nsimp[2]);
  return (int)t - 1;
}

static int m_transition(lua_State *L)
{
  dm_lmeshconn *c = checkmc(L, 1);
  int t0 = tri_arg(L, 2, c->G), t1 = tri_arg(L, 3, c->G);
  double a;
  dm_err e;
  if (dm_conn_mesh_transition(c->G, t0, t1, &a, &e) != DM_OK)
    return dm_lua_fail(L, "transition", e.status, &e);
  lua_pushnumber(L, a);
  return 1;
}

static int m_transport(lua_State *L)
{
  dm_lmeshconn *c = checkmc(L, 1);
  double a = luaL_optnumber(L, 3, 0.0);
  size_t n, k;
  gsl_vector *buf;
  int *ts;
  dm_err e;
  luaL_checktype(L, 2, LUA_TTABLE);
  n = (size_t)luaL_len(L, 2);
  if (n < 1)
    luaL_error(L, "transport: a chain of at least one triangle expected");
  buf = dm_pushvec(L, n);                     /* scratch owned by Lua */
  ts = (int *)buf->data;
  for (k = 0; k < n; k++) {
    lua_geti(L, 2, (lua_Integer)k + 1);
    ts[k] = tri_arg(L, -1, c->G);
    lua_pop(L, 1);
  }
  if (dm_conn_mesh_transport(c->G, ts, n, &a, &e) != DM_OK)
    return dm_lua_fail(L, "transport", e.status, &e);
  lua_pushnumber(L, a);
  return 1;
}

static int m_holonomy(lua_State *L)
{
  dm_lmeshconn *c = checkmc(L, 1);
  lua_Integer v = luaL_checkinteger(L, 2);
  double a;
  dm_err e;
  if (v < 1 || v > c->G->K->nsimp[0])
    luaL_error(L, "holonomy: vertex %d does not exist (1..%d)", (int)v, c->G->K->nsimp[0]);
  if (dm_conn_mesh_vertex_holonomy(c->G, (int)v - 1, &a, &e) != DM_OK)
    return dm_lua_fail(L, "holonomy", e.status, &e);
  lua_pushnumber(L, a);
  return 1;
}

static int m_holonomies(lua_State *L)
{
  dm_lmeshconn *c = checkmc(L, 1);
  int nv = c->G->K->nsimp[0], v;
  gsl_vector *out = dm_pushvec(L, (size_t)nv);
  for (v = 0; v < nv; v++) {
    double a;
    if (dm_conn_mesh_vertex_holonomy(c->G, v, &a, NULL) != DM_OK)
      a = NAN;
    gsl_vector_set(out, (size_t)v, a);
  }
  return 1;
}

static int m_defects(lua_State *L)
{
  dm_lmeshconn *c = checkmc(L, 1);
  int nv = c->G->K->nsimp[0], v;
  gsl_vector *out = dm_pushvec(L, (size_t)nv);
  for (v = 0; v < nv; v++)
    gsl_vector_set(out, (size_t)v, dm_conn_mesh_defect(c->G, v));
  return 1;
}

static int mc_tostring(lua_State *L)
{
  dm_lmeshconn *c = checkmc(L, 1);
  lua_pushfstring(L, "<Levi-Civita connection of a triangle mesh: %d triangles, %d vertices>",
                  c->G->K->nsimp[2], c->G->K->nsimp[0]);
  return 1;
}

static const dm_reg mc_methods[] = {
  {"transition", m_transition, "LC:transition(t0, t1) -> angle",
   "The rotation angle carrying the frame of triangle t0 to that of the adjacent triangle t1 (the shared edge keeps its direction)."},
  {"transport", m_transport, "LC:transport({t1, t2, ...}[, angle = 0]) -> angle",
   "Parallel transport of a vector's angle along a chain of adjacent triangles."},
  {"holonomy", m_holonomy, "LC:holonomy(v) -> angle",
   "The holonomy around the interior vertex v, counter-clockwise: its angle defect mod 2 pi, in (-pi, pi]."},
  {"holonomies", m_holonomies, "LC:holonomies() -> vec",
   "The holonomy around every vertex (NaN on the boundary); on a closed surface they sum to 2 pi chi."},
  {"defects", m_defects, "LC:defects() -> vec",
   "The angle defects 2 pi - sum of angles (boundary vertices: pi - sum) from the edge lengths."},
  {NULL, NULL, NULL, NULL}
};

void dm_lua_open_conn_mesh(lua_State *L)
{
  static const luaL_Reg meta[] = {{"__tostring", mc_tostring}, {NULL, NULL}};
  dm_newclass(L, DM_MESHCONN_MT, "mesh_connection", mc_methods, meta);
  lua_pop(L, 1);
}
