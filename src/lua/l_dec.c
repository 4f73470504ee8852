/* l_dec.c -- the Mesh class: simplicial meshes (src/dec) as Mesh userdata,
 * with their operators (typed Sparse matrices) and cochains.  Numerics live
 * in src/dec; this file checks arguments, allocates through userdata and
 * turns statuses into errors.  dm.mesh.grid ... dm.mesh.new: l_dec_mesh.c. */
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

dm_lmesh *dm_pushmesh_data(lua_State *L, dm_dec_meshdata *m, const char *what, dm_err *e)
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

static int m_gc(lua_State *L)
{
  mesh_clear(luaL_checkudata(L, 1, DM_MESH_MT));
  return 0;
}

void dm_dec_checkopts(lua_State *L, int t, const char *fname, const char *const *known)
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
  dm_dec_checkopts(L, arg, fname, known);
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
    dm_dec_checkopts(L, 3, "mesh:laplacian", known);
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

void dm_open_dec(lua_State *L)
{
  dm_newclass(L, DM_MESH_MT, "mesh", mesh_methods, mesh_meta);
  lua_pop(L, 1);
  dm_open_sparse(L);
  dm_open_cochain(L);
  dm_open_dec_mesh(L);
  dm_open_dec_ops(L);
}
