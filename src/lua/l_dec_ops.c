/* l_dec_ops.c -- the Mesh methods beyond d, star and Laplacians: files,
 * wedge, flat and sharp, contraction and Lie derivative, the homotopy
 * operator, moved meshes and push-forward, nested refinement and
 * multigrid (src/dec does the work). */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_dec.h"

/* {==== helpers ==================================================================== */

/* A dual vector field (one R^N vector per top simplex) from a function of
 * the circumcentre, a constant vector {a, b[, c]}, a table of vectors or a
 * mat; Lua-owned buffer pushed. */
static double *vector_field(lua_State *L, dm_lmesh *M, int arg, const char *fname)
{
  const dm_dec_complex *K = M->K;
  int N = M->G->N, nt = K->nsimp[K->n], t, c;
  double *X;
  gsl_matrix *m;
  arg = lua_absindex(L, arg);
  if (M->G->X == NULL)
    luaL_error(L, "%s: vector fields need a mesh with coordinates", fname);
  X = lua_newuserdatauv(L, (size_t)nt * N * sizeof *X + 1, 0);
  if (lua_type(L, arg) == LUA_TFUNCTION) {
    for (t = 0; t < nt; t++) {
      lua_pushvalue(L, arg);
      for (c = 0; c < N; c++)
        lua_pushnumber(L, M->G->cc[K->n][(size_t)t * N + c]);
      lua_call(L, N, N);
      for (c = 0; c < N; c++) {
        int isnum;
        X[(size_t)t * N + c] = lua_tonumberx(L, c - N, &isnum);
        if (!isnum)
          luaL_error(L, "%s: the field function must return %d numbers", fname, N);
      }
      lua_pop(L, N);
    }
  } else if ((m = dm_tomat(L, arg)) != NULL) {
    if ((int)m->size1 != nt || (int)m->size2 != N)
      luaL_error(L, "%s: %d x %d matrix expected (one row per top simplex), got %d x %d", fname, nt, N,
                 (int)m->size1, (int)m->size2);
    for (t = 0; t < nt; t++)
      for (c = 0; c < N; c++)
        X[(size_t)t * N + c] = gsl_matrix_get(m, (size_t)t, (size_t)c);
  } else if (lua_type(L, arg) == LUA_TTABLE && lua_rawgeti(L, arg, 1) == LUA_TNUMBER) {
    lua_pop(L, 1);
    if ((int)lua_rawlen(L, arg) != N)
      luaL_error(L, "%s: constant vector of %d components expected", fname, N);
    for (c = 0; c < N; c++) {
      lua_rawgeti(L, arg, c + 1);
      for (t = 0; t < nt; t++)
        X[(size_t)t * N + c] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
  } else if (lua_type(L, arg) == LUA_TTABLE) {
    lua_pop(L, 1);
    if ((int)lua_rawlen(L, arg) != nt)
      luaL_error(L, "%s: %d vectors expected (one per top simplex), got %d", fname, nt, (int)lua_rawlen(L, arg));
    for (t = 0; t < nt; t++) {
      lua_rawgeti(L, arg, t + 1);
      for (c = 0; c < N; c++) {
        lua_rawgeti(L, -1, c + 1);
        X[(size_t)t * N + c] = luaL_checknumber(L, -1);
        lua_pop(L, 1);
      }
      lua_pop(L, 1);
    }
  } else {
    dm_argexpected(L, arg, "function, vector, table of vectors or mat", luaL_typename(L, arg));
  }
  return X;
}

static dm_lcochain *cochain_of(lua_State *L, int arg, dm_lmesh *M, int dual, const char *fname)
{
  dm_lcochain *c = dm_checkcochain(L, arg);
  if (c->K != M->K)
    luaL_error(L, "%s: the cochain lives on another mesh", fname);
  if (c->t.dual != dual)
    luaL_error(L, "%s: %s cochain expected, got a %s", fname, dual ? "dual" : "primal",
               dm_dec_typename(L, c->t));
  return c;
}

static int weights_opt(lua_State *L, int arg, const char *fname)
{
  const char *w;
  if (lua_isnoneornil(L, arg))
    return DM_DEC_WEDGE_BARYCENTRIC;
  luaL_checktype(L, arg, LUA_TTABLE);
  w = dm_optstringfield(L, arg, "weights", "barycentric");
  if (strcmp(w, "barycentric") == 0)
    return DM_DEC_WEDGE_BARYCENTRIC;
  if (strcmp(w, "circumcentric") == 0)
    return DM_DEC_WEDGE_CIRCUMCENTRIC;
  return luaL_error(L, "%s: weights must be \"barycentric\" or \"circumcentric\", got \"%s\"", fname, w);
}

/* }==== */

static int l_load(lua_State *L)
{
  const char *path = dm_checkcstring(L, 1);
  dm_dec_complex *K;
  dm_dec_geom *G;
  dm_err e;
  dm_dec_load(path, &K, &G, &e);
  dm_pushmesh(L, K, G, "dm.mesh.load", &e);
  return 1;
}

static int m_save(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  const char *path = dm_checkcstring(L, 2);
  dm_err e;
  if (dm_dec_write(path, M->K, M->G, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:save", e.status, &e);
  lua_pushboolean(L, 1);
  return 1;
}

/* Both dual: the thesis's dual-dual wedge, only with {dual_dual = true}. */
static int wedge_dual(lua_State *L, dm_lmesh *M, dm_lcochain *a, dm_lcochain *b)
{
  dm_lcochain *r;
  dm_err e;
  int ok = 0;
  if (lua_istable(L, 4)) {
    lua_getfield(L, 4, "dual_dual");
    ok = lua_toboolean(L, -1);
    lua_pop(L, 1);
  }
  if (!ok)
    return luaL_error(L, "mesh:wedge: the dual-dual wedge is a sketch in the thesis (no property proved "
                      "but anti-commutativity); pass {dual_dual = true} to use it");
  if (a->t.deg + b->t.deg > M->K->n)
    return luaL_error(L, "mesh:wedge: degrees %d + %d exceed the dimension %d", a->t.deg, b->t.deg, M->K->n);
  r = dm_newcochain(L, 1, (dm_ltype){a->t.deg + b->t.deg, 1});
  if (dm_dec_wedge_dual(M->K, a->t.deg, a->v, b->t.deg, b->v, r->v, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:wedge", e.status, &e);
  return 1;
}

static int m_wedge(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  dm_lcochain *a, *b, *r;
  int w;
  dm_err e;
  lua_settop(L, 4);
  a = dm_checkcochain(L, 2);
  b = dm_checkcochain(L, 3);
  if (a->t.dual && b->t.dual && a->K == M->K && b->K == M->K)
    return wedge_dual(L, M, a, b);
  a = cochain_of(L, 2, M, 0, "mesh:wedge");
  b = cochain_of(L, 3, M, 0, "mesh:wedge");
  w = weights_opt(L, 4, "mesh:wedge");
  if (a->t.deg + b->t.deg > M->K->n)
    return luaL_error(L, "mesh:wedge: degrees %d + %d exceed the dimension %d", a->t.deg, b->t.deg, M->K->n);
  r = dm_newcochain(L, 1, (dm_ltype){a->t.deg + b->t.deg, 0});
  if (dm_dec_wedge(M->G, a->t.deg, a->v, b->t.deg, b->v, w, r->v, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:wedge", e.status, &e);
  return 1;
}

static int m_flat(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  double *X = vector_field(L, M, 2, "mesh:flat");
  dm_lcochain *r = dm_newcochain(L, 1, (dm_ltype){1, 0});
  dm_err e;
  if (dm_dec_flat(M->G, X, r->v, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:flat", e.status, &e);
  return 1;
}

static int m_sharp(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  dm_lcochain *a = cochain_of(L, 2, M, 0, "mesh:sharp");
  gsl_matrix *V;
  dm_err e;
  if (a->t.deg != 1)
    return luaL_error(L, "mesh:sharp: primal 1-cochain expected, got a %s", dm_dec_typename(L, a->t));
  if (M->G->X == NULL)
    return luaL_error(L, "mesh:sharp: vector fields need a mesh with coordinates");
  V = dm_pushmat(L, (size_t)M->K->nsimp[0], (size_t)M->G->N);
  if (dm_dec_sharp(M->G, a->v, V->data, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:sharp", e.status, &e);
  return 1;
}

static int contract_or_lie(lua_State *L, int lie)
{
  const char *fname = lie ? "mesh:lie" : "mesh:contract";
  dm_lmesh *M = dm_checkmesh(L, 1);
  double *X;
  dm_lcochain *b, *r;
  int w, k;
  dm_err e;
  lua_settop(L, 4);
  b = cochain_of(L, 3, M, 1, fname);
  w = weights_opt(L, 4, fname);
  X = vector_field(L, M, 2, fname);
  k = b->t.deg;
  if (!lie && k < 1)
    return luaL_error(L, "%s: the contraction of a dual 0-cochain is zero; dual degree >= 1 expected", fname);
  r = dm_newcochain(L, 1, (dm_ltype){lie ? k : k - 1, 1});
  if ((lie ? dm_dec_lie(M->G, k, b->v, X, w, r->v, &e) : dm_dec_contract(M->G, k, b->v, X, w, r->v, &e)) != DM_OK)
    return dm_lua_fail(L, fname, e.status, &e);
  return 1;
}

static int m_contract(lua_State *L) { return contract_or_lie(L, 0); }
static int m_lie(lua_State *L) { return contract_or_lie(L, 1); }

static int m_homotopy(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  lua_Integer k = luaL_checkinteger(L, 2);
  dm_sparse *p[DM_DEC_MAXDIM];
  dm_lsparse *s;
  int apex, i;
  dm_err e;
  if (k < 1 || k > M->K->n)
    return luaL_argerror(L, 2, lua_pushfstring(L, "degree in 1..%d expected, got %I", M->K->n, k));
  s = dm_newsparse(L, 1);
  if (dm_dec_homotopy(M->K, p, &apex, &e) != DM_OK)
    return dm_lua_fail(L, "mesh:homotopy", e.status, &e);
  for (i = 0; i < M->K->n; i++)
    if (i != k - 1)
      dm_sparse_free(p[i]);
  s->A = p[k - 1];
  s->K = M->K;
  s->dom = (dm_ltype){(int)k, 0};
  s->rng = (dm_ltype){(int)k - 1, 0};
  snprintf(s->label, sizeof s->label, "homotopy%d", (int)k);
  lua_pushinteger(L, apex + 1);
  return 2;
}

/* A mesh with the same simplices and new vertex positions. */
static int m_moved(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1);
  int nv = M->K->nsimp[0], N, i, c;
  double *X;
  dm_dec_complex *K;
  dm_dec_geom *G;
  dm_err e;
  if (M->G->X == NULL)
    return luaL_error(L, "mesh:moved: the mesh has no coordinates");
  if (lua_type(L, 2) == LUA_TFUNCTION) {
    N = M->G->N;
    X = lua_newuserdatauv(L, (size_t)nv * N * sizeof *X, 0);
    for (i = 0; i < nv; i++) {
      lua_pushvalue(L, 2);
      for (c = 0; c < N; c++)
        lua_pushnumber(L, M->G->X[(size_t)i * N + c]);
      lua_call(L, N, N);
      for (c = 0; c < N; c++) {
        int isnum;
        X[(size_t)i * N + c] = lua_tonumberx(L, c - N, &isnum);
        if (!isnum)
          return luaL_error(L, "mesh:moved: the function must return %d numbers", N);
      }
      lua_pop(L, N);
    }
  } else {
    gsl_matrix *m = dm_checkmatrix(L, 2, (size_t)nv, 0);
    N = (int)m->size2;
    X = lua_newuserdatauv(L, (size_t)nv * N * sizeof *X, 0);
    for (i = 0; i < nv; i++)
      for (c = 0; c < N; c++)
        X[(size_t)i * N + c] = gsl_matrix_get(m, (size_t)i, (size_t)c);
  }
  K = dm_dec_complex_alloc(M->K->n, nv, M->K->nsimp[M->K->n], M->K->top, &e);
  G = K != NULL ? dm_dec_geom_alloc(K, N, X, &e) : NULL;
  dm_pushmesh(L, K, G, "mesh:moved", &e);
  return 1;
}

static int m_push(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1), *M2;
  double *X;
  gsl_matrix *out;
  dm_err e;
  lua_settop(L, 3);
  M2 = dm_checkmesh(L, 3);
  X = vector_field(L, M, 2, "mesh:push");
  if (M2->K->n != M->K->n || M2->K->nsimp[M->K->n] != M->K->nsimp[M->K->n] ||
      memcmp(M2->K->top, M->K->top, (size_t)M->K->nsimp[M->K->n] * (M->K->n + 1) * sizeof(int)) != 0)
    return luaL_error(L, "mesh:push: the target mesh must have the same simplices (made by mesh:moved)");
  out = dm_pushmat(L, (size_t)M->K->nsimp[M->K->n], (size_t)M2->G->N);
  {
    /* the same complex is needed for the C call: use the target's geometry
     * on this mesh's complex through a shallow view */
    dm_dec_geom view = *M2->G;
    view.K = M->K;
    if (dm_dec_pushforward(M->G, &view, X, out->data, &e) != DM_OK)
      return dm_lua_fail(L, "mesh:push", e.status, &e);
  }
  return 1;
}

/* {==== nested refinement and multigrid ============================================= */

static int m_refine(lua_State *L)
{
  dm_lmesh *M = dm_checkmesh(L, 1), *F;
  dm_dec_meshdata *m, *f;
  int n = M->K->n, N = M->G->N, *parent = NULL;
  dm_dec_complex *K;
  dm_dec_geom *G;
  dm_err e;
  if (M->G->X == NULL || (n != 1 && n != 2))
    return luaL_error(L, "mesh:refine: meshes of dimension 1 or 2 with coordinates only");
  if ((m = dm_dec_meshdata_alloc(n, N, M->K->nsimp[0], M->K->nsimp[n], &e)) == NULL)
    return dm_lua_fail(L, "mesh:refine", e.status, &e);
  memcpy(m->X, M->G->X, (size_t)M->K->nsimp[0] * N * sizeof(double));
  memcpy(m->T, M->K->top, (size_t)M->K->nsimp[n] * (n + 1) * sizeof(int));
  f = dm_dec_refine(m, &parent, &e);
  dm_dec_meshdata_free(m);
  if (f == NULL)
    return dm_lua_fail(L, "mesh:refine", e.status, &e);
  K = dm_dec_complex_alloc(n, f->nv, f->ntop, f->T, &e);
  G = K != NULL ? dm_dec_geom_alloc(K, N, f->X, &e) : NULL;
  dm_dec_meshdata_free(f);
  if (G == NULL)
    free(parent);
  F = dm_pushmesh(L, K, G, "mesh:refine", &e);
  F->parent = parent;
  lua_pushvalue(L, 1);
  lua_setiuservalue(L, -2, 1);          /* the coarse mesh stays alive */
  return 1;
}

static dm_lmesh *coarse_of(lua_State *L, int idx, dm_lmesh *F, const char *fname)
{
  dm_lmesh *C;
  if (F->parent == NULL)
    luaL_error(L, "%s: the mesh was not made by mesh:refine", fname);
  lua_getiuservalue(L, idx, 1);
  C = dm_checkmesh(L, -1);
  return C;
}

static int m_restrict(lua_State *L)
{
  dm_lmesh *F = dm_checkmesh(L, 1), *C;
  dm_lcochain *c = cochain_of(L, 2, F, 0, "mesh:restrict"), *r;
  dm_sparse *R;
  dm_err e;
  lua_settop(L, 2);
  C = coarse_of(L, 1, F, "mesh:restrict");                 /* 3 */
  if (c->t.deg != 0 && c->t.deg != 1 && c->t.deg != F->K->n)
    return luaL_error(L, "mesh:restrict: degree 0, 1 or %d expected", F->K->n);
  r = dm_newcochain(L, 3, c->t);                           /* 4 */
  if ((R = dm_dec_restriction(C->K, F->K, F->parent, c->t.deg, &e)) == NULL)
    return dm_lua_fail(L, "mesh:restrict", e.status, &e);
  dm_sparse_gemv(R, c->v, r->v);
  dm_sparse_free(R);
  return 1;
}

/* Dirichlet Poisson Delta0 u = f (u = 0 on the boundary) by V-cycles over
 * the chain of meshes made by refine. */
static int m_mg_solve(lua_State *L)
{
  static const int maxlev = 32;
  dm_lmesh *F = dm_checkmesh(L, 1), *lv[32];
  dm_lcochain *f = cochain_of(L, 2, F, 0, "mesh:mg_solve"), *u;
  dm_sparse *P[32], *S = NULL;
  dm_dec_mg *mg = NULL;
  double tol, *w, *b;
  int nlev = 1, l, i, st, iters = 0, maxit;
  dm_err e;
  lua_settop(L, 3);
  tol = lua_isnil(L, 3) ? 1e-10 : dm_optnumberfield(L, 3, "tol", 1e-10);
  maxit = lua_isnil(L, 3) ? 100 : (int)dm_optintegerfield(L, 3, "maxit", 100);
  if (f->t.deg != 0)
    return luaL_error(L, "mesh:mg_solve: primal 0-cochain expected");
  lv[0] = F;
  lua_pushvalue(L, 1);
  while (lv[nlev - 1]->parent != NULL && nlev < maxlev) {
    lua_getiuservalue(L, -1, 1);
    lv[nlev++] = dm_checkmesh(L, -1);
  }
  if (nlev < 2)
    return luaL_error(L, "mesh:mg_solve: the mesh was not made by mesh:refine");
  u = dm_newcochain(L, 1, (dm_ltype){0, 0});
  w = lua_newuserdatauv(L, (size_t)f->n * sizeof *w, 0);
  b = lua_newuserdatauv(L, (size_t)f->n * sizeof *b, 0);
  for (l = 0; l < nlev - 1; l++)
    P[l] = NULL;
  /* P[j] links level j (coarse, lv[nlev-1-j]) to level j+1 */
  for (l = 0; l < nlev - 1; l++) {
    dm_lmesh *fine = lv[nlev - 2 - l], *coarse = lv[nlev - 1 - l];
    if ((P[l] = dm_dec_prolongation(coarse->K->nsimp[0], fine->K->nsimp[0], fine->parent, &e)) == NULL)
      goto fail;
  }
  if (dm_dec_laplacian(F->G, 0, NULL, &S, &e) != DM_OK)
    goto fail;
  if ((mg = dm_dec_mg_alloc(nlev, P, S, F->K->boundary[0], 2, &e)) == NULL)
    goto fail;
  dm_dec_star(F->G, 0, 0, w, NULL);
  for (i = 0; i < f->n; i++)
    b[i] = w[i] * f->v[i];
  st = dm_dec_mg_solve(mg, b, u->v, tol, maxit, &iters, &e);
  dm_dec_mg_free(mg);
  dm_sparse_free(S);
  for (l = 0; l < nlev - 1; l++)
    dm_sparse_free(P[l]);
  if (st != DM_OK)
    return dm_lua_fail(L, "mesh:mg_solve", st, &e);
  lua_pushvalue(L, -3);
  lua_pushinteger(L, iters);
  return 2;
fail:
  dm_sparse_free(S);
  for (l = 0; l < nlev - 1; l++)
    dm_sparse_free(P[l]);
  return dm_lua_fail(L, "mesh:mg_solve", e.status, &e);
}

/* }==== */

static const dm_reg ops_methods[] = {
  {"save", m_save, "M:save(\"file.off|obj|msh\") -> true",
   "Write the mesh as OFF or OBJ (triangle meshes) or Gmsh .msh 2.2, through a temporary file."},
  {"wedge", m_wedge, "M:wedge(a, b[, {weights = \"barycentric\" | \"circumcentric\", dual_dual = true}]) -> cochain",
   "The wedge product of two primal cochains (barycentric weights: Leibniz rule exact; circumcentric: the thesis's), or of two dual ones with dual_dual = true (an unproven sketch)."},
  {"flat", m_flat, "M:flat(X) -> cochain",
   "The primal 1-cochain of a dual vector field X (function of the circumcentre, constant vector, one vector per top simplex, or mat)."},
  {"sharp", m_sharp, "M:sharp(alpha) -> mat",
   "The vector field of a primal 1-cochain at the vertices (one row per vertex; constant fields come back exactly)."},
  {"contract", m_contract, "M:contract(X, beta[, {weights =}]) -> cochain",
   "The contraction of a dual k-cochain with a dual vector field, a dual (k-1)-cochain."},
  {"lie", m_lie, "M:lie(X, beta[, {weights =}]) -> cochain",
   "The Lie derivative of a dual cochain along a dual vector field (Cartan's formula)."},
  {"homotopy", m_homotopy, "M:homotopy(k) -> sparse, apex",
   "The homotopy operator from primal k- to (k-1)-cochains of a collapsible mesh: H d + d H = I, H d f = f - f(apex)."},
  {"moved", m_moved, "M:moved(f | mat) -> mesh",
   "The same simplices at new vertex positions (f(x, y[, z]) returns the new position): a discrete map."},
  {"push", m_push, "M:push(X, M2) -> mat",
   "The push-forward of a dual vector field of M to the moved mesh M2 (Jacobian of each simplex's affine map)."},
  {"refine", m_refine, "M:refine() -> mesh",
   "Split every triangle 1 -> 4 (segment 1 -> 2) at edge midpoints; the fine mesh remembers this one."},
  {"restrict", m_restrict, "F:restrict(c) -> cochain",
   "Coarsen a cochain of a refined mesh F (degrees 0, 1, n) by summing over the pieces: commutes with d."},
  {"mg_solve", m_mg_solve, "F:mg_solve(f[, {tol = 1e-10, maxit = 100}]) -> u, cycles",
   "Solve the Dirichlet Poisson problem Laplacian(0) u = f, u = 0 on the boundary, by multigrid V-cycles over the refinement chain."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg ops_funcs[] = {
  {"load", l_load, "dm.mesh.load(\"file.off|obj|msh\") -> mesh",
   "Read a mesh (OFF, OBJ, Gmsh .msh 2.2 or 4.1); defects are errors naming the line."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_dec_ops(lua_State *L)
{
  luaL_getmetatable(L, DM_MESH_MT);
  lua_getfield(L, -1, "__methods");
  dm_register(L, "mesh:", ops_methods);
  lua_pop(L, 2);
  lua_getfield(L, -1, "mesh");
  dm_register(L, "dm.mesh.", ops_funcs);
  lua_pop(L, 1);
}
