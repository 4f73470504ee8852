/* l_dec.c -- dm.mesh.*: simplicial meshes (src/dec) as Mesh userdata, with
 * their operators (typed Sparse matrices) and cochains.  Numerics live in
 * src/dec; this file checks arguments, allocates through userdata and turns
 * statuses into errors. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_dec.h"

/* {==== helpers ==================================================================== */

static const char *const simplex_names[] = {"vertex", "edge", "triangle", "tetrahedron", "4-simplex"};
static const char *const simplex_plurals[] = {"vertices", "edges", "triangles", "tetrahedra", "4-simplices"};

const char *dm_dec_typename(lua_State *L, dm_ltype t)
{
  if (t.deg < 0)
    return lua_pushliteral(L, "vector");
  return lua_pushfstring(L, "%s %d-cochain", t.dual ? "dual" : "primal", t.deg);
}

int dm_dec_typesize(const dm_dec_complex *K, dm_ltype t)
{
  return K->nsimp[t.dual ? K->n - t.deg : t.deg];
}

dm_lmesh *dm_checkmesh(lua_State *L, int arg)
{
  dm_lmesh *M = luaL_checkudata(L, arg, DM_MESH_MT);
  if (M->K == NULL || M->G == NULL)
    luaL_error(L, "mesh is empty (freed)");
  return M;
}

static void mesh_clear(dm_lmesh *M)
{
  dm_dec_geom_free(M->G);
  dm_dec_complex_free(M->K);
  free(M->parent);
  M->G = NULL;
  M->K = NULL;
  M->parent = NULL;
}

dm_lmesh *dm_pushmesh(lua_State *L, dm_dec_complex *K, dm_dec_geom *G, const char *what, dm_err *e)
{
  dm_lmesh *M;
  if (K == NULL || G == NULL) {
    dm_dec_geom_free(G);
    dm_dec_complex_free(K);
    dm_lua_fail(L, what, e->status, e);
  }
  M = lua_newuserdatauv(L, sizeof *M, 1);
  memset(M, 0, sizeof *M);
  M->K = K;
  M->G = G;
  luaL_setmetatable(L, DM_MESH_MT);
  return M;
}

static int m_gc(lua_State *L)
{
  mesh_clear(luaL_checkudata(L, 1, DM_MESH_MT));
  return 0;
}

/* Unknown option keys raise (a misspelt option is never silently ignored). */
static void check_opts(lua_State *L, int t, const char *fname, const char *const *known)
{
  lua_pushnil(L);
  while (lua_next(L, t) != 0) {
    const char *const *k = known;
    const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : NULL;
    while (key != NULL && *k != NULL && strcmp(*k, key) != 0)
      k++;
    if (key == NULL || *k == NULL) {
      luaL_Buffer b;
      luaL_buffinit(L, &b);
      for (k = known; *k != NULL; k++) {
        luaL_addstring(&b, *k);
        if (k[1] != NULL)
          luaL_addstring(&b, ", ");
      }
      luaL_pushresult(&b);
      {
        const char *list = lua_tostring(L, -1);      /* order matters: */
        const char *bad = dm_tolstring(L, -3, NULL);  /* this one pushes */
        luaL_error(L, "%s: unknown option '%s' (options: %s)", fname, bad, list);
      }
    }
    lua_pop(L, 1);
  }
}

/* Options table at argument 1 (absent: empty). */
static void opts_arg(lua_State *L, const char *fname, const char *const *known)
{
  if (lua_isnoneornil(L, 1)) {
    lua_settop(L, 0);
    lua_newtable(L);
  }
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  check_opts(L, 1, fname, known);
}

static int checkdeg(lua_State *L, int arg, const dm_lmesh *M, int lo, int hi)
{
  lua_Integer k = luaL_checkinteger(L, arg);
  if (k < lo || k > hi) {
    const char *msg = lua_pushfstring(L, "degree in %d..%d expected, got %I (mesh of dimension %d)",
                                      lo, hi, k, M->K->n);
    luaL_argerror(L, arg, msg);
  }
  return (int)k;
}

/* Once per mesh and degree: non-positive dual volumes make *_k indefinite. */
static void warn_star(dm_lmesh *M, int k)
{
  if (M->G->nonpos[k] > 0 && !(M->warned & (1u << k))) {
    M->warned |= 1u << k;
    fprintf(stderr,
            "dmech: warning: %d %s of this mesh %s non-positive dual volume (not Delaunay there): "
            "*%d is indefinite\n",
            M->G->nonpos[k], M->G->nonpos[k] > 1 ? simplex_plurals[k] : simplex_names[k],
            M->G->nonpos[k] > 1 ? "have" : "has", k);
  }
}

/* }==== */

/* {==== construction ============================================================== */

/* Push a Mesh built from m (consumed; NULL: raise e's message). */
static dm_lmesh *push_mesh(lua_State *L, dm_dec_meshdata *m, const char *what, dm_err *e)
{
  dm_lmesh *M;
  if (m == NULL)
    dm_lua_fail(L, what, e->status, e);
  M = lua_newuserdatauv(L, sizeof *M, 1);
  memset(M, 0, sizeof *M);
  luaL_setmetatable(L, DM_MESH_MT);
  M->K = dm_dec_complex_alloc(m->n, m->nv, m->ntop, m->T, e);
  if (M->K != NULL)
    M->G = dm_dec_geom_alloc(M->K, m->N, m->X, e);
  dm_dec_meshdata_free(m);
  if (M->G == NULL) {
    mesh_clear(M);
    dm_lua_fail(L, what, e->status, e);
  }
  return M;
}

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
  push_mesh(L, dm_dec_gen_grid((int)nx, (int)ny, x[0], x[1], y[0], y[1], &e), "dm.mesh.grid", &e);
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
  push_mesh(L, dm_dec_gen_disc(r, (int)n, &e), "dm.mesh.disc", &e);
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
  push_mesh(L, dm_dec_gen_annulus(dm_optnumberfield(L, 1, "r0", 0.5), dm_optnumberfield(L, 1, "r1", 1.0),
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
  push_mesh(L, dm_dec_gen_sphere(dm_optnumberfield(L, 1, "radius", 1.0), (int)lev, &e),
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
  push_mesh(L, dm_dec_gen_torus(dm_optnumberfield(L, 1, "R", 2.0), dm_optnumberfield(L, 1, "r", 1.0),
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
  push_mesh(L, dm_dec_gen_box((int)nx, (int)ny, (int)nz, sz[0], sz[1], sz[2], &e), "dm.mesh.box", &e);
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
    push_mesh(L, dm_dec_gen_path((int)x->size - 1, x->data, &e), "dm.mesh.path", &e);
  } else {
    lua_Integer n = dm_optintegerfield(L, 1, "n", 4);
    if (n < 1 || n > 100000000)
      return luaL_error(L, "dm.mesh.path: n >= 1 segments expected, got %I", n);
    push_mesh(L, dm_dec_gen_path((int)n, NULL, &e), "dm.mesh.path", &e);
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

/* {==== methods ==================================================================== */

static int m_tostring(lua_State *L)
{
  dm_lmesh *M = luaL_checkudata(L, 1, DM_MESH_MT);
  luaL_Buffer b;
  int k;
  if (M->K == NULL) {
    lua_pushliteral(L, "mesh (freed)");
    return 1;
  }
  luaL_buffinit(L, &b);
  if (M->G->X != NULL)
    lua_pushfstring(L, "mesh of dimension %d in R^%d:", M->K->n, M->G->N);
  else
    lua_pushfstring(L, "mesh of dimension %d (intrinsic):", M->K->n);
  luaL_addvalue(&b);
  for (k = 0; k <= M->K->n; k++) {
    lua_pushfstring(L, "%s %d %s", k ? "," : "", M->K->nsimp[k],
                    M->K->nsimp[k] == 1 ? simplex_names[k] : simplex_plurals[k]);
    luaL_addvalue(&b);
  }
  luaL_pushresult(&b);
  return 1;
}

static int m_betti(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int b[DM_DEC_MAXDIM + 1], k;
  dm_err e;
  if (dm_dec_betti(M->K, b, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:betti", e.status, &e);
  for (k = 0; k <= M->K->n; k++)
    lua_pushinteger(L, b[k]);
  return M->K->n + 1;
}

static int m_count(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  lua_pushinteger(L, M->K->nsimp[checkdeg(L, 2, M, 0, M->K->n)]);
  return 1;
}

static int m_dim(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  lua_pushinteger(L, M->K->n);
  lua_pushinteger(L, M->G->N);
  return 2;
}

static dm_lsparse *typed_result(lua_State *L, dm_lmesh *M, dm_sparse *A, const char *what,
                                dm_err *e, dm_ltype dom, dm_ltype rng)
{
  dm_lsparse *s;
  if (A == NULL)
    dm_lua_fail(L, what, e->status, e);
  s = dm_newsparse(L, 1);
  s->A = A;
  s->K = M->K;
  s->dom = dom;
  s->rng = rng;
  return s;
}

static int m_d(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n - 1);
  dm_err e;
  dm_lsparse *s = typed_result(L, M, dm_dec_d(M->K, k, &e), "mesh:d", &e, (dm_ltype){k, 0},
                               (dm_ltype){k + 1, 0});
  snprintf(s->label, sizeof s->label, "d%d", k);
  return 1;
}

static int m_dual_d(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int j = checkdeg(L, 2, M, 0, M->K->n - 1);
  dm_err e;
  dm_lsparse *s = typed_result(L, M, dm_dec_dual_d(M->K, j, &e), "mesh:dual_d", &e,
                               (dm_ltype){j, 1}, (dm_ltype){j + 1, 1});
  snprintf(s->label, sizeof s->label, "dual d%d", j);
  return 1;
}

static int dual_flag(lua_State *L, int arg, const char *fname)
{
  static const char *const known[] = {"dual", NULL};
  int d;
  if (lua_isnoneornil(L, arg))
    return 0;
  luaL_checktype(L, arg, LUA_TTABLE);
  check_opts(L, arg, fname, known);
  lua_getfield(L, arg, "dual");
  d = lua_toboolean(L, -1);
  lua_pop(L, 1);
  return d;
}

/* star(k): primal k -> dual n-k; star(j, {dual = true}): dual j -> primal n-j. */
static int m_star(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n), n = M->K->n, dual = dual_flag(L, 3, "mesh:star");
  int pk = dual ? n - k : k, st;
  dm_lsparse *s;
  dm_err e;
  double *w;
  warn_star(M, pk);
  w = lua_newuserdatauv(L, ((size_t)M->K->nsimp[pk] + 1) * sizeof *w, 0);
  if ((st = dm_dec_star(M->G, pk, dual, w, &e)) != DM_OK)
    return dm_lua_fail(L, "mesh:star", st, &e);
  s = typed_result(L, M, dm_sparse_diag(M->K->nsimp[pk], w, &e), "mesh:star", &e,
                   (dm_ltype){k, dual}, (dm_ltype){n - k, !dual});
  snprintf(s->label, sizeof s->label, "%sstar%d", dual ? "dual " : "", k);
  return 1;
}

static int m_codiff(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 1, M->K->n);
  dm_err e;
  dm_lsparse *s;
  warn_star(M, k - 1);
  s = typed_result(L, M, dm_dec_codiff(M->G, k, &e), "mesh:codiff", &e, (dm_ltype){k, 0},
                   (dm_ltype){k - 1, 0});
  snprintf(s->label, sizeof s->label, "codiff%d", k);
  return 1;
}

/* Fill a cochain's values from a number, table, vec, cochain or function. */
typedef struct {
  lua_State *L;
  int fidx, nret, N, failed;
} fn_ctx;

static int call_fn(const double *x, double *vals, void *ud)
{
  fn_ctx *c = ud;
  lua_State *L = c->L;
  int i;
  lua_pushvalue(L, c->fidx);
  for (i = 0; i < c->N; i++)
    lua_pushnumber(L, x[i]);
  if (lua_pcall(L, c->N, c->nret, 0) != LUA_OK) {
    c->failed = 1;
    return 1;                       /* the error object stays on the stack */
  }
  for (i = 0; i < c->nret; i++) {
    int isnum;
    vals[i] = lua_tonumberx(L, i - c->nret, &isnum);
    if (!isnum) {
      lua_pushfstring(L, "function must return %d number%s, value %d is %s", c->nret,
                      c->nret > 1 ? "s" : "", i + 1, luaL_typename(L, i - c->nret));
      c->failed = 1;
      return 1;
    }
  }
  lua_pop(L, c->nret);
  return 0;
}

static void fill_values(lua_State *L, dm_lmesh *M, int arg, dm_lcochain *c, const char *fname)
{
  int i;
  if (lua_type(L, arg) == LUA_TNUMBER) {
    double x = lua_tonumber(L, arg);
    for (i = 0; i < c->n; i++)
      c->v[i] = x;
  } else if (lua_type(L, arg) == LUA_TFUNCTION) {
    fn_ctx ctx = {L, lua_absindex(L, arg), 1, M->G->N, 0};
    dm_err e;
    int st;
    if (c->t.dual)
      luaL_error(L, "%s: dual cochains cannot be sampled from a function", fname);
    if (c->t.deg == 1)
      ctx.nret = M->G->N;
    st = dm_dec_derham(M->G, c->t.deg, call_fn, &ctx, c->v, &e);
    if (ctx.failed) {
      const char *msg = lua_tostring(L, -1);
      luaL_error(L, "%s: %s", fname, msg != NULL ? msg : "error in the function");
    }
    if (st != DM_OK)
      dm_lua_fail(L, fname, st, &e);
  } else {
    dm_lcochain *src = dm_tocochain(L, arg);
    const double *x;
    if (src != NULL) {
      x = src->v;
      if (src->n != c->n)
        luaL_error(L, "%s: %d values expected, got %d", fname, c->n, src->n);
    } else {
      gsl_vector *v;
      if (lua_type(L, arg) != LUA_TTABLE && dm_tovec(L, arg) == NULL)
        dm_argexpected(L, arg, "number, function, table, vec or cochain", luaL_typename(L, arg));
      v = dm_checkvector(L, arg, 0);
      if ((int)v->size != c->n)
        luaL_error(L, "%s: %d values expected (one per %s), got %d", fname, c->n,
                   c->t.dual ? "dual cell" : simplex_names[c->t.deg], (int)v->size);
      x = v->data;
    }
    memcpy(c->v, x, (size_t)c->n * sizeof(double));
  }
}

static int m_cochain(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n), dual;
  dm_lcochain *c;
  lua_settop(L, 4);
  dual = dual_flag(L, 4, "mesh:cochain");
  c = dm_newcochain(L, 1, (dm_ltype){k, dual});
  if (!lua_isnil(L, 3))
    fill_values(L, M, 3, c, "mesh:cochain");
  lua_settop(L, 5);
  return 1;
}

static int m_laplacian(lua_State *L)
{
  static const char *const known[] = {"boundary", "value", "pin", NULL};
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n), n = M->K->n, i, dirichlet = 0, st;
  lua_Integer pin = 0;
  dm_sparse *Delta = NULL, *S = NULL;
  dm_lsparse *s;
  dm_err e;
  lua_settop(L, 3);
  if (!lua_isnil(L, 3)) {
    const char *bc;
    luaL_checktype(L, 3, LUA_TTABLE);
    check_opts(L, 3, "mesh:laplacian", known);
    bc = dm_optstringfield(L, 3, "boundary", "none");
    if (strcmp(bc, "dirichlet") == 0)
      dirichlet = 1;
    else if (strcmp(bc, "none") != 0)
      return luaL_error(L, "mesh:laplacian: boundary must be \"dirichlet\" or \"none\", got \"%s\"", bc);
    pin = dm_optintegerfield(L, 3, "pin", 0);
    if (pin != 0 && (dirichlet || pin < 1 || pin > M->K->nsimp[k]))
      return luaL_error(L, "mesh:laplacian: pin must be a %d-simplex index in 1..%d (without boundary = \"dirichlet\")",
                        k, M->K->nsimp[k]);
  }
  warn_star(M, k);
  if (k > 0)
    warn_star(M, k - 1);
  if (k < n)
    warn_star(M, k + 1);
  s = dm_newsparse(L, 1);                                  /* 4 */
  s->K = M->K;
  s->dom = s->rng = (dm_ltype){k, 0};
  snprintf(s->label, sizeof s->label, "laplacian%d", k);
  if ((st = dm_dec_laplacian(M->G, k, &Delta, &S, &e)) != DM_OK)
    return dm_lua_fail(L, "mesh:laplacian", st, &e);
  s->S = S;
  s->A = Delta;
  s->w = malloc(((size_t)M->K->nsimp[k] + 1) * sizeof *s->w);
  if (s->w == NULL)
    return luaL_error(L, "mesh:laplacian: out of memory");
  dm_dec_star(M->G, k, 0, s->w, NULL);
  s->kernel = !dirichlet && pin == 0;
  if (pin != 0) {            /* one unknown held at 0: fixes the constants of a closed mesh */
    s->fixed = calloc((size_t)M->K->nsimp[k] + 1, 1);
    s->g = calloc((size_t)M->K->nsimp[k] + 1, sizeof *s->g);
    if (s->fixed == NULL || s->g == NULL)
      return luaL_error(L, "mesh:laplacian: out of memory");
    s->fixed[pin - 1] = 1;
    if ((Delta = dm_sparse_fix_rows(s->A, s->fixed, &e)) == NULL)
      return dm_lua_fail(L, "mesh:laplacian", e.status, &e);
    dm_sparse_free(s->A);
    s->A = Delta;
  }
  if (dirichlet) {
    int nb = 0;
    s->fixed = malloc((size_t)M->K->nsimp[k] + 1);
    s->g = calloc((size_t)M->K->nsimp[k] + 1, sizeof *s->g);
    if (s->fixed == NULL || s->g == NULL)
      return luaL_error(L, "mesh:laplacian: out of memory");
    memcpy(s->fixed, M->K->boundary[k], (size_t)M->K->nsimp[k]);
    for (i = 0; i < M->K->nsimp[k]; i++)
      nb += s->fixed[i];
    if (nb == 0)
      return luaL_error(L, "mesh:laplacian: boundary = \"dirichlet\" on a mesh without boundary");
    if (lua_getfield(L, 3, "value") != LUA_TNIL) {         /* 5 */
      dm_lcochain *g = dm_newcochain(L, 1, (dm_ltype){k, 0});   /* 6 */
      fill_values(L, M, 5, g, "mesh:laplacian (value)");
      for (i = 0; i < M->K->nsimp[k]; i++)
        if (s->fixed[i])
          s->g[i] = g->v[i];
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
    if ((Delta = dm_sparse_fix_rows(s->A, s->fixed, &e)) == NULL)
      return dm_lua_fail(L, "mesh:laplacian", e.status, &e);
    dm_sparse_free(s->A);
    s->A = Delta;
  }
  return 1;
}

static int m_vertices(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int i, c;
  if (M->G->X == NULL)
    return luaL_error(L, "mesh:vertices: an intrinsic mesh has no coordinates");
  lua_createtable(L, M->K->nsimp[0], 0);
  for (i = 0; i < M->K->nsimp[0]; i++) {
    lua_createtable(L, M->G->N, 0);
    for (c = 0; c < M->G->N; c++) {
      lua_pushnumber(L, M->G->X[(size_t)i * M->G->N + c]);
      lua_rawseti(L, -2, c + 1);
    }
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

static int m_simplices(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n), i, c;
  const int *S = k == M->K->n ? M->K->top : M->K->simp[k];
  lua_createtable(L, M->K->nsimp[k], 0);
  for (i = 0; i < M->K->nsimp[k]; i++) {
    lua_createtable(L, k + 1, 0);
    for (c = 0; c <= k; c++) {
      lua_pushinteger(L, S[(size_t)i * (k + 1) + c] + 1);
      lua_rawseti(L, -2, c + 1);
    }
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

static int m_boundary(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n), i;
  dm_lcochain *c = dm_newcochain(L, 1, (dm_ltype){k, 0});
  for (i = 0; i < c->n; i++)
    c->v[i] = M->K->boundary[k][i];
  return 1;
}

static int volumes(lua_State *L, int dual)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n);
  dm_lcochain *c = dm_newcochain(L, 1, (dm_ltype){k, 0});
  memcpy(c->v, dual ? M->G->dual[k] : M->G->vol[k], (size_t)c->n * sizeof(double));
  return 1;
}

static int m_volumes(lua_State *L) { return volumes(L, 0); }
static int m_dual_volumes(lua_State *L) { return volumes(L, 1); }

static int m_well_centered(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  lua_pushboolean(L, M->G->not_well_centered == 0);
  lua_pushinteger(L, M->G->not_well_centered);
  return 2;
}

static int m_check(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  dm_err e;
  if (dm_dec_complex_check(M->K, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:check", e.status, &e);
  lua_pushboolean(L, 1);
  return 1;
}

static int m_eigen(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int k = checkdeg(L, 2, M, 0, M->K->n), i, j, nk = M->K->nsimp[k], st;
  lua_Integer nev = luaL_optinteger(L, 3, 6);
  dm_sparse *S = NULL;
  double *m, *lam, *vec, sigma = 0;
  dm_err e;
  if (nev < 1 || nev >= nk)
    return luaL_error(L, "mesh:eigen: number of eigenpairs in 1..%d expected, got %I", nk - 1, nev);
  for (i = k > 0 ? k - 1 : 0; i <= k + 1 && i <= M->K->n; i++)
    if (M->G->nonpos[i] > 0)
      return luaL_error(L, "mesh:eigen: %d %s non-positive dual volume: the problem is not definite",
                        M->G->nonpos[i], M->G->nonpos[i] > 1 ? simplex_plurals[i] : simplex_names[i]);
  m = lua_newuserdatauv(L, (size_t)nk * sizeof *m, 0);
  lam = lua_newuserdatauv(L, (size_t)nev * sizeof *lam, 0);
  vec = lua_newuserdatauv(L, (size_t)nk * (size_t)nev * sizeof *vec, 0);
  dm_dec_star(M->G, k, 0, m, NULL);
  if ((st = dm_dec_laplacian(M->G, k, NULL, &S, &e)) != DM_OK)
    return dm_lua_fail(L, "mesh:eigen", st, &e);
  for (i = 0; i < nk; i++)
    sigma += dm_sparse_get(S, i, i) / m[i];
  sigma = -1e-3 * sigma / nk;
  st = dm_sparse_eigsh(S, m, (int)nev, sigma, 0, lam, vec, &e);
  dm_sparse_free(S);
  if (st != DM_OK)
    return dm_lua_fail(L, "mesh:eigen", st, &e);
  dm_pushvec_copy(L, lam, (size_t)nev);
  lua_createtable(L, (int)nev, 0);
  for (j = 0; j < nev; j++) {
    dm_lcochain *c = dm_newcochain(L, 1, (dm_ltype){k, 0});
    memcpy(c->v, vec + (size_t)j * nk, (size_t)nk * sizeof(double));
    lua_rawseti(L, -2, j + 1);
  }
  return 2;
}

/* }==== */

static const dm_reg mesh_methods[] = {
  {"betti", m_betti, "M:betti() -> b0, b1, ..., bn",
   "The Betti numbers, exactly (ranks of the boundary matrices modulo a large prime)."},
  {"count", m_count, "M:count(k) -> integer", "The number of k-simplices."},
  {"dim", m_dim, "M:dim() -> n, N", "The dimension of the mesh and of the space it lies in (0 when intrinsic)."},
  {"d", m_d, "M:d(k) -> sparse", "The exterior derivative on primal k-cochains (entries +-1, d(k+1) * d(k) = 0 exactly)."},
  {"dual_d", m_dual_d, "M:dual_d(j) -> sparse",
   "The exterior derivative on dual j-cochains, (-1)^(n-j) times the boundary operator."},
  {"star", m_star, "M:star(k[, {dual = true}]) -> sparse",
   "The Hodge star from primal k-cochains to dual (n-k)-cochains (with dual = true: from dual k- to primal (n-k)-cochains)."},
  {"codiff", m_codiff, "M:codiff(k) -> sparse", "The codifferential from primal k- to (k-1)-cochains, the adjoint of d(k-1)."},
  {"laplacian", m_laplacian, "M:laplacian(k[, {boundary = \"dirichlet\", value = g} | {pin = i}]) -> sparse",
   "The Laplace-de Rham operator d delta + delta d on primal k-cochains (positive semidefinite); Dirichlet rows fix the boundary values to g (default 0), pin = i holds simplex i at 0 (closed meshes)."},
  {"cochain", m_cochain, "M:cochain(k, f | values | number[, {dual = true}]) -> cochain",
   "A k-cochain: integrals of a form given by f(x, y[, z]) over the k-simplices (values for k = 0, 1-form components for k = 1, a density for k = n), or given values."},
  {"vertices", m_vertices, "M:vertices() -> {{x, y, ...}, ...}", "The vertex coordinates."},
  {"simplices", m_simplices, "M:simplices(k) -> {{i, j, ...}, ...}",
   "The k-simplices as 1-based vertex lists (top simplices in input order and orientation)."},
  {"boundary", m_boundary, "M:boundary(k) -> cochain",
   "A primal k-cochain that is 1 on the boundary k-simplices and 0 elsewhere."},
  {"volumes", m_volumes, "M:volumes(k) -> cochain", "The volumes of the k-simplices (1 for vertices)."},
  {"dual_volumes", m_dual_volumes, "M:dual_volumes(k) -> cochain",
   "The signed volumes of the circumcentric dual cells of the k-simplices."},
  {"well_centered", m_well_centered, "M:well_centered() -> boolean, count",
   "Whether every circumcentre lies strictly inside its simplex, and the number of simplices where it does not."},
  {"check", m_check, "M:check() -> true",
   "Raise an error naming the first non-manifold face or inconsistently oriented pair of simplices."},
  {"eigen", m_eigen, "M:eigen(k[, n]) -> values, {cochains}",
   "The n (default 6) smallest eigenvalues of the Laplacian on k-cochains and their eigencochains (ARPACK on a CHOLMOD factor)."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg mesh_meta[] = {
  {"__tostring", m_tostring}, {"__gc", m_gc}, {"__close", m_gc}, {NULL, NULL}
};

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

void dm_open_dec(lua_State *L)
{
  dm_newclass(L, DM_MESH_MT, "mesh", mesh_methods, mesh_meta);
  lua_pop(L, 1);
  dm_open_sparse(L);
  dm_open_cochain(L);
  lua_newtable(L);
  dm_register(L, "dm.mesh.", mesh_funcs);
  lua_setfield(L, -2, "mesh");
  dm_open_dec_ops(L);
}
