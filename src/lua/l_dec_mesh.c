/* l_dec_mesh.c -- dm.mesh.grid, disc, annulus, sphere, torus, box, path
 * and new: Mesh userdata from the generators of src/dec or from vertex
 * coordinates (or edge lengths) and simplices given in Lua.  Part of the
 * DEC binding (l_dec.c); see l_dec.h. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_dec.h"

/* {==== options ==================================================================== */

/* Options table at argument 1 (absent: empty). */
static void opts_arg(lua_State *L, const char *fname, const char *const *known)
{
  if (lua_isnoneornil(L, 1)) {
    lua_settop(L, 0);
    lua_newtable(L);
  }
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_dec_checkopts(L, 1, fname, known);
}

/* }==== */

/* {==== construction ============================================================== */

static int l_grid(lua_State *L)
{
  static const char *const known[] = {"n", "nx", "ny", "x", "y", NULL};
  double x[2] = {0, 1}, y[2] = {0, 1};
  lua_Integer n, nx, ny;
  int i;
  dm_err e;
  opts_arg(L, "dm.mesh.grid", known);
  n = dm_optintegerfield(L, 1, "n", 8);
  nx = dm_optintegerfield(L, 1, "nx", n);
  ny = dm_optintegerfield(L, 1, "ny", n);
  for (i = 0; i < 2; i++) {
    const char *key = i == 0 ? "x" : "y";
    double *r = i == 0 ? x : y;
    if (lua_getfield(L, 1, key) != LUA_TNIL) {
      gsl_vector *v = dm_checkvector(L, -1, 2);
      r[0] = v->data[0];
      r[1] = v->data[1];
    }
    lua_pop(L, 1);
  }
  if (nx < 1 || ny < 1 || nx > 100000 || ny > 100000)
    return luaL_error(L, "dm.mesh.grid: nx, ny in 1..100000 expected, got %I, %I", nx, ny);
  dm_pushmesh_data(L, dm_dec_gen_grid((int)nx, (int)ny, x[0], x[1], y[0], y[1], &e), "dm.mesh.grid", &e);
  return 1;
}

static int l_disc(lua_State *L)
{
  static const char *const known[] = {"radius", "n", NULL};
  double r;
  lua_Integer n;
  dm_err e;
  opts_arg(L, "dm.mesh.disc", known);
  r = dm_optnumberfield(L, 1, "radius", 1.0);
  n = dm_optintegerfield(L, 1, "n", 8);
  if (n < 1 || n > 10000)
    return luaL_error(L, "dm.mesh.disc: n (rings) in 1..10000 expected, got %I", n);
  dm_pushmesh_data(L, dm_dec_gen_disc(r, (int)n, &e), "dm.mesh.disc", &e);
  return 1;
}

static int l_annulus(lua_State *L)
{
  static const char *const known[] = {"r0", "r1", "n", "m", NULL};
  lua_Integer n, m;
  dm_err e;
  opts_arg(L, "dm.mesh.annulus", known);
  n = dm_optintegerfield(L, 1, "n", 4);
  m = dm_optintegerfield(L, 1, "m", 24);
  if (n < 1 || n > 100000 || m < 3 || m > 1000000)
    return luaL_error(L, "dm.mesh.annulus: n >= 1 rings and m >= 3 vertices per ring expected, got %I, %I", n, m);
  dm_pushmesh_data(L, dm_dec_gen_annulus(dm_optnumberfield(L, 1, "r0", 0.5), dm_optnumberfield(L, 1, "r1", 1.0),
                                  (int)n, (int)m, &e), "dm.mesh.annulus", &e);
  return 1;
}

static int l_sphere(lua_State *L)
{
  static const char *const known[] = {"radius", "level", NULL};
  dm_err e;
  lua_Integer lev;
  opts_arg(L, "dm.mesh.sphere", known);
  lev = dm_optintegerfield(L, 1, "level", 2);
  if (lev < 0 || lev > 9)
    return luaL_error(L, "dm.mesh.sphere: level in 0..9 expected, got %I", lev);
  dm_pushmesh_data(L, dm_dec_gen_sphere(dm_optnumberfield(L, 1, "radius", 1.0), (int)lev, &e),
            "dm.mesh.sphere", &e);
  return 1;
}

/* n around the big circle, m (even) around the tube: the long way gets the
 * larger count, so that the default shapes stay Delaunay. */
static int l_torus(lua_State *L)
{
  static const char *const known[] = {"R", "r", "m", "n", NULL};
  dm_err e;
  lua_Integer m, n;
  opts_arg(L, "dm.mesh.torus", known);
  n = dm_optintegerfield(L, 1, "n", 24);
  m = dm_optintegerfield(L, 1, "m", 12);
  if (n < 3 || m < 4 || m > 1000000 || n > 1000000 || m % 2 != 0)
    return luaL_error(L, "dm.mesh.torus: n >= 3 around the big circle and an even m >= 4 around the tube expected, got n = %I, m = %I", n, m);
  dm_pushmesh_data(L, dm_dec_gen_torus(dm_optnumberfield(L, 1, "R", 2.0), dm_optnumberfield(L, 1, "r", 1.0),
                                (int)n, (int)m, &e), "dm.mesh.torus", &e);
  return 1;
}

static int l_box(lua_State *L)
{
  static const char *const known[] = {"n", "nx", "ny", "nz", "size", NULL};
  double sz[3] = {1, 1, 1};
  lua_Integer n, nx, ny, nz;
  dm_err e;
  opts_arg(L, "dm.mesh.box", known);
  n = dm_optintegerfield(L, 1, "n", 4);
  nx = dm_optintegerfield(L, 1, "nx", n);
  ny = dm_optintegerfield(L, 1, "ny", n);
  nz = dm_optintegerfield(L, 1, "nz", n);
  if (lua_getfield(L, 1, "size") != LUA_TNIL) {
    gsl_vector *v = dm_checkvector(L, -1, 3);
    memcpy(sz, v->data, sizeof sz);
  }
  lua_pop(L, 1);
  if (nx < 1 || ny < 1 || nz < 1 || nx > 1000 || ny > 1000 || nz > 1000)
    return luaL_error(L, "dm.mesh.box: nx, ny, nz in 1..1000 expected");
  dm_pushmesh_data(L, dm_dec_gen_box((int)nx, (int)ny, (int)nz, sz[0], sz[1], sz[2], &e), "dm.mesh.box", &e);
  return 1;
}

static int l_path(lua_State *L)
{
  static const char *const known[] = {"n", "x", NULL};
  dm_err e;
  opts_arg(L, "dm.mesh.path", known);
  if (lua_getfield(L, 1, "x") != LUA_TNIL) {
    gsl_vector *x = dm_checkvector(L, -1, 0);
    if (x->size < 2)
      return luaL_error(L, "dm.mesh.path: at least two points expected");
    dm_pushmesh_data(L, dm_dec_gen_path((int)x->size - 1, x->data, &e), "dm.mesh.path", &e);
  } else {
    lua_Integer n = dm_optintegerfield(L, 1, "n", 4);
    if (n < 1 || n > 100000000)
      return luaL_error(L, "dm.mesh.path: n >= 1 segments expected, got %I", n);
    dm_pushmesh_data(L, dm_dec_gen_path((int)n, NULL, &e), "dm.mesh.path", &e);
  }
  return 1;
}

/* Rows of a table of tables of numbers into a Lua-owned array (pushed). */
static double *rows_of(lua_State *L, int t, const char *fname, const char *field, int *nrow,
                       int *ncol, int integer)
{
  int n = (int)lua_rawlen(L, t), i, j, w = -1;
  double *a;
  if (n == 0)
    luaL_error(L, "%s: field '%s': non-empty table of rows expected", fname, field);
  for (i = 1; i <= n; i++) {
    if (lua_rawgeti(L, t, i) != LUA_TTABLE)
      luaL_error(L, "%s: %s %d: table expected, got %s", fname, field, i, luaL_typename(L, -1));
    if (w < 0)
      w = (int)lua_rawlen(L, -1);
    if ((int)lua_rawlen(L, -1) != w || w == 0)
      luaL_error(L, "%s: %s %d has %d entries, %s 1 has %d", fname, field, i, (int)lua_rawlen(L, -1),
                 field, w);
    lua_pop(L, 1);
  }
  a = lua_newuserdatauv(L, (size_t)n * (size_t)w * sizeof *a, 0);
  for (i = 1; i <= n; i++) {
    lua_rawgeti(L, t, i);
    for (j = 1; j <= w; j++) {
      int isnum;
      double x;
      lua_rawgeti(L, -1, j);
      x = lua_tonumberx(L, -1, &isnum);
      if (!isnum || (integer && x != floor(x)))
        luaL_error(L, "%s: %s %d, entry %d: %s expected, got %s", fname, field, i, j,
                   integer ? "integer" : "number", luaL_typename(L, -1));
      if (!integer && !isfinite(x))
        luaL_error(L, "%s: %s %d, coordinate %d is not finite", fname, field, i, j);
      a[(size_t)(i - 1) * w + (j - 1)] = x;
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  *nrow = n;
  *ncol = w;
  return a;
}

/* dm.mesh.new{vertices = {...}, simplices = {...}} or {simplices, lengths} */
static int l_new(lua_State *L)
{
  static const char *const known[] = {"vertices", "simplices", "lengths", NULL};
  int nt, w, nv = 0, N = 0, i, nl = 0, wl = 0, *T;
  double *S, *X = NULL, *Lw = NULL;
  dm_lmesh *M;
  dm_err e;
  opts_arg(L, "dm.mesh.new", known);
  if (lua_getfield(L, 1, "simplices") != LUA_TTABLE)
    return luaL_error(L, "dm.mesh.new: field 'simplices': table of vertex-index tables expected, got %s",
                      luaL_typename(L, -1));
  S = rows_of(L, 2, "dm.mesh.new", "simplex", &nt, &w, 1);           /* 3 */
  if (lua_getfield(L, 1, "vertices") == LUA_TTABLE)                   /* 4 */
    X = rows_of(L, 4, "dm.mesh.new", "vertex", &nv, &N, 0);           /* 5 */
  else if (lua_getfield(L, 1, "lengths") == LUA_TTABLE)               /* 5 */
    Lw = rows_of(L, 5, "dm.mesh.new", "length", &nl, &wl, 0);         /* 6 */
  else
    return luaL_error(L, "dm.mesh.new: field 'vertices' (coordinates) or 'lengths' ({i, j, length} per edge) expected");
  if (Lw != NULL) {
    if (wl != 3)
      return luaL_error(L, "dm.mesh.new: lengths: {i, j, length} expected per edge");
    for (i = 0; i < nt * w; i++)
      nv = (int)fmax(nv, S[i]);
  }
  T = lua_newuserdatauv(L, (size_t)nt * (size_t)w * sizeof *T, 0);
  for (i = 0; i < nt * w; i++)
    T[i] = (int)S[i] - 1;
  if (w < 2 || w > DM_DEC_MAXDIM + 1)
    return luaL_error(L, "dm.mesh.new: simplices of %d vertices (2..%d expected)", w, DM_DEC_MAXDIM + 1);
  M = lua_newuserdatauv(L, sizeof *M, 1);
  memset(M, 0, sizeof *M);
  luaL_setmetatable(L, DM_MESH_MT);
  if ((M->K = dm_dec_complex_alloc(w - 1, nv, nt, T, &e)) == NULL)
    return dm_lua_fail(L, "dm.mesh.new", e.status, &e);
  if (X != NULL) {
    M->G = dm_dec_geom_alloc(M->K, N, X, &e);
  } else {
    double *l2 = lua_newuserdatauv(L, ((size_t)M->K->nsimp[1] + 1) * sizeof *l2, 0);
    for (i = 0; i < M->K->nsimp[1]; i++)
      l2[i] = -1;
    for (i = 0; i < nl; i++) {
      int v[2] = {(int)Lw[3 * i] - 1, (int)Lw[3 * i + 1] - 1}, s = -1;
      if (v[0] >= 0 && v[1] >= 0 && v[0] < nv && v[1] < nv)
        s = dm_dec_find(M->K, 1, v);
      if (s < 0)
        return luaL_error(L, "dm.mesh.new: length %d: (%d, %d) is not an edge of the mesh", i + 1, v[0] + 1,
                          v[1] + 1);
      l2[s] = Lw[3 * i + 2] * Lw[3 * i + 2] * (Lw[3 * i + 2] > 0 ? 1 : -1);
    }
    for (i = 0; i < M->K->nsimp[1]; i++)
      if (l2[i] == -1)
        return luaL_error(L, "dm.mesh.new: no length for edge (%d, %d)", M->K->simp[1][2 * i] + 1,
                          M->K->simp[1][2 * i + 1] + 1);
    M->G = dm_dec_geom_alloc_intrinsic(M->K, l2, &e);
    lua_pop(L, 1);
  }
  if (M->G == NULL)
    return dm_lua_fail(L, "dm.mesh.new", e.status, &e);
  return 1;
}

/* }==== */

static const dm_reg mesh_funcs[] = {
  {"grid", l_grid, "dm.mesh.grid{n = 8 | nx =, ny =, x = {0, 1}, y = {0, 1}} -> mesh",
   "A rectangle cut into nx x ny squares, each split along one diagonal into right triangles."},
  {"disc", l_disc, "dm.mesh.disc{radius = 1, n = 8} -> mesh",
   "A disc of n rings of nearly equilateral triangles (1 + 3n(n+1) vertices)."},
  {"annulus", l_annulus, "dm.mesh.annulus{r0 = 0.5, r1 = 1, n = 4, m = 24} -> mesh",
   "An annulus of n rings of m vertices, alternate rings turned by half a step."},
  {"sphere", l_sphere, "dm.mesh.sphere{radius = 1, level = 2} -> mesh",
   "An icosahedron subdivided level times (10 * 4^level + 2 vertices on the sphere)."},
  {"torus", l_torus, "dm.mesh.torus{R = 2, r = 1, n = 24, m = 12} -> mesh",
   "A torus in R^3, n vertices around the big circle and m (even) around the tube, alternate rings staggered."},
  {"box", l_box, "dm.mesh.box{n = 4 | nx =, ny =, nz =, size = {1, 1, 1}} -> mesh",
   "A box of nx x ny x nz cubes, six tetrahedra each."},
  {"path", l_path, "dm.mesh.path{n = 4 | x = {x0, x1, ...}} -> mesh", "A 1-dimensional mesh: segments on the real line."},
  {"new", l_new, "dm.mesh.new{vertices = {{x, y, ...}, ...} | lengths = {{i, j, l}, ...}, simplices = {{i, j, k}, ...}} -> mesh",
   "A mesh from vertex coordinates or edge lengths (intrinsic) and oriented top simplices (1-based)."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_dec_mesh(lua_State *L)
{
  lua_newtable(L);
  dm_register(L, "dm.mesh.", mesh_funcs);
  lua_setfield(L, -2, "mesh");
}
