/* l_dec_sparse.c -- Sparse: CSR matrices (src/dec/sparse.h) with products,
 * sums, transposes, A * x and solves.  Operators made by a mesh are typed
 * (the cochain type they take and give) and products check the types; a
 * Laplacian remembers its symmetric form so that :solve uses CHOLMOD. */
#include <config.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lua/l_dec.h"

static void sparse_clear(dm_lsparse *s)
{
  dm_sparse_free(s->A);
  dm_sparse_free(s->S);
  free(s->w);
  free(s->g);
  free(s->fixed);
  dm_dec_solver_free(s->chol);
  dm_sparse_lu_free(s->lu);
  s->A = s->S = NULL;
  s->w = s->g = NULL;
  s->fixed = NULL;
  s->chol = NULL;
  s->lu = NULL;
}

static int s_gc(lua_State *L)
{
  sparse_clear(luaL_checkudata(L, 1, DM_SPARSE_MT));
  return 0;
}

dm_lsparse *dm_newsparse(lua_State *L, int mesh_idx)
{
  dm_lsparse *s;
  if (mesh_idx != 0)
    mesh_idx = lua_absindex(L, mesh_idx);
  s = lua_newuserdatauv(L, sizeof *s, 1);
  memset(s, 0, sizeof *s);
  s->dom.deg = s->rng.deg = -1;
  luaL_setmetatable(L, DM_SPARSE_MT);
  if (mesh_idx != 0) {
    lua_pushvalue(L, mesh_idx);
    lua_setiuservalue(L, -2, 1);
  }
  return s;
}

dm_lsparse *dm_checksparse(lua_State *L, int arg)
{
  dm_lsparse *s = luaL_checkudata(L, arg, DM_SPARSE_MT);
  if (s->A == NULL)
    luaL_error(L, "sparse matrix is empty (freed)");
  return s;
}

static int typed(const dm_lsparse *s)
{
  return s->K != NULL && s->dom.deg >= 0;
}

static int same(dm_ltype a, dm_ltype b)
{
  return a.deg == b.deg && a.dual == b.dual;
}

/* A new Sparse holding A (pushed; raises with e's message when A is NULL:
 * nothing is held then). */
static dm_lsparse *push_result(lua_State *L, dm_sparse *A, int mesh_idx, const char *what,
                               const dm_err *e)
{
  dm_lsparse *s;
  if (A == NULL)
    dm_lua_fail(L, what, e->status, e);
  s = dm_newsparse(L, mesh_idx);
  s->A = A;
  return s;
}

/* {==== arithmetic ============================================================== */

static int scaled(lua_State *L, int si, double f)
{
  dm_lsparse *a = dm_checksparse(L, si), *r;
  dm_err e;
  int p;
  lua_getiuservalue(L, si, 1);
  r = push_result(L, dm_sparse_copy(a->A, &e), lua_isnil(L, -1) ? 0 : -1, "sparse * number", &e);
  for (p = 0; p < dm_sparse_nnz(r->A); p++)
    r->A->val[p] *= f;
  r->K = a->K;
  r->dom = a->dom;
  r->rng = a->rng;
  snprintf(r->label, sizeof r->label, "%s", "scaled matrix");
  return 1;
}

static int mul_vector(lua_State *L, dm_lsparse *a)
{
  gsl_vector *x = dm_checkvector(L, 2, (size_t)a->A->ncols);
  gsl_vector *y = dm_pushvec(L, (size_t)(a->A->nrows > 0 ? a->A->nrows : 1));
  dm_sparse_gemv(a->A, x->data, y->data);
  return 1;
}

static int mul_cochain(lua_State *L, dm_lsparse *a, dm_lcochain *c)
{
  dm_lcochain *r;
  if (typed(a)) {
    if (c->K != a->K)
      return luaL_error(L, "%s * cochain: the cochain lives on another mesh", a->label);
    if (!same(a->dom, c->t)) {
      const char *want = dm_dec_typename(L, a->dom), *got = dm_dec_typename(L, c->t);
      return luaL_error(L, "%s * cochain: the operator takes %ss, got a %s", a->label, want, got);
    }
    lua_getiuservalue(L, 1, 1);
    r = dm_newcochain(L, -1, a->rng);
    dm_sparse_gemv(a->A, c->v, r->v);
    return 1;
  }
  if (a->A->ncols != c->n)
    return luaL_error(L, "sparse * cochain: %d columns, cochain of %d values", a->A->ncols, c->n);
  if (a->A->nrows == 0)
    return luaL_error(L, "sparse * cochain: the matrix has no rows");
  dm_sparse_gemv(a->A, c->v, dm_pushvec(L, (size_t)a->A->nrows)->data);
  return 1;
}

static int s_mul(lua_State *L)
{
  dm_lsparse *a, *b, *r;
  dm_lcochain *c;
  dm_err e;
  if (lua_isnumber(L, 1))
    return scaled(L, 2, lua_tonumber(L, 1));
  if (lua_isnumber(L, 2))
    return scaled(L, 1, lua_tonumber(L, 2));
  a = dm_checksparse(L, 1);
  if ((c = dm_tocochain(L, 2)) != NULL)
    return mul_cochain(L, a, c);
  if (luaL_testudata(L, 2, DM_SPARSE_MT) == NULL)
    return mul_vector(L, a);
  b = dm_checksparse(L, 2);
  if (typed(a) && typed(b)) {
    if (a->K != b->K)
      return luaL_error(L, "sparse * sparse: the operators belong to different meshes");
    if (!same(a->dom, b->rng)) {
      const char *ta = dm_dec_typename(L, a->dom), *tb = dm_dec_typename(L, b->rng);
      return luaL_error(L, "%s * %s: the left operator takes %ss, the right one gives %ss",
                        a->label, b->label, ta, tb);
    }
  }
  lua_getiuservalue(L, typed(a) ? 1 : 2, 1);
  r = push_result(L, dm_sparse_mul(a->A, b->A, &e), lua_isnil(L, -1) ? 0 : -1, "sparse * sparse", &e);
  if (typed(a) && typed(b)) {
    r->K = a->K;
    r->dom = b->dom;
    r->rng = a->rng;
  }
  snprintf(r->label, sizeof r->label, "%s", "product");
  return 1;
}

static int addsub(lua_State *L, double sg, const char *op)
{
  dm_lsparse *a = dm_checksparse(L, 1), *b = dm_checksparse(L, 2), *r;
  dm_err e;
  if (typed(a) && typed(b) && (a->K != b->K || !same(a->dom, b->dom) || !same(a->rng, b->rng))) {
    const char *ta = dm_dec_typename(L, a->dom), *tb = dm_dec_typename(L, b->dom);
    return luaL_error(L, "%s %s %s: operators of different types (taking %ss and %ss)", a->label,
                      op, b->label, ta, tb);
  }
  lua_getiuservalue(L, 1, 1);
  r = push_result(L, dm_sparse_add(1.0, a->A, sg, b->A, &e), lua_isnil(L, -1) ? 0 : -1,
                  sg > 0 ? "sparse + sparse" : "sparse - sparse", &e);
  if (typed(a) && typed(b)) {
    r->K = a->K;
    r->dom = a->dom;
    r->rng = a->rng;
  }
  snprintf(r->label, sizeof r->label, "%s", sg > 0 ? "sum" : "difference");
  return 1;
}

static int s_add(lua_State *L) { return addsub(L, 1.0, "+"); }
static int s_sub(lua_State *L) { return addsub(L, -1.0, "-"); }
static int s_unm(lua_State *L) { return scaled(L, 1, -1.0); }

static int s_t(lua_State *L)
{
  dm_lsparse *a = dm_checksparse(L, 1), *r;
  dm_err e;
  lua_getiuservalue(L, 1, 1);
  r = push_result(L, dm_sparse_transpose(a->A, &e), lua_isnil(L, -1) ? 0 : -1, "sparse:t", &e);
  r->K = a->K;
  r->dom = a->rng;
  r->rng = a->dom;
  snprintf(r->label, sizeof r->label, "%.24s^T", a->label);
  return 1;
}

/* }==== */

static int s_tostring(lua_State *L)
{
  dm_lsparse *s = luaL_checkudata(L, 1, DM_SPARSE_MT);
  if (s->A == NULL) {
    lua_pushliteral(L, "sparse (freed)");
    return 1;
  }
  if (typed(s)) {
    const char *d = dm_dec_typename(L, s->dom), *r = dm_dec_typename(L, s->rng);
    lua_pushfstring(L, "sparse %dx%d, %d nonzeros (%s: %ss -> %ss%s)", s->A->nrows, s->A->ncols,
                    dm_sparse_nnz(s->A), s->label, d, r,
                    s->fixed != NULL ? ", Dirichlet rows" : "");
  } else {
    lua_pushfstring(L, "sparse %dx%d, %d nonzeros", s->A->nrows, s->A->ncols, dm_sparse_nnz(s->A));
  }
  return 1;
}

/* An exactly zero matrix (d(k+1) * d(k)) answers the integer 0. */
static int s_norm(lua_State *L)
{
  double x = dm_sparse_norm(dm_checksparse(L, 1)->A);
  if (x == 0.0)
    lua_pushinteger(L, 0);
  else
    lua_pushnumber(L, x);
  return 1;
}

static int s_nnz(lua_State *L)
{
  lua_pushinteger(L, dm_sparse_nnz(dm_checksparse(L, 1)->A));
  return 1;
}

static int s_size(lua_State *L)
{
  dm_lsparse *s = dm_checksparse(L, 1);
  lua_pushinteger(L, s->A->nrows);
  lua_pushinteger(L, s->A->ncols);
  return 2;
}

static int s_get(lua_State *L)
{
  dm_lsparse *s = dm_checksparse(L, 1);
  lua_Integer i = luaL_checkinteger(L, 2), j = luaL_checkinteger(L, 3);
  if (i < 1 || i > s->A->nrows || j < 1 || j > s->A->ncols)
    return luaL_error(L, "sparse:get: index (%I, %I) outside %d x %d", i, j, s->A->nrows, s->A->ncols);
  lua_pushnumber(L, dm_sparse_get(s->A, (int)i - 1, (int)j - 1));
  return 1;
}

static int s_triplets(lua_State *L)
{
  dm_lsparse *s = dm_checksparse(L, 1);
  int i, p, k = 0;
  lua_createtable(L, dm_sparse_nnz(s->A), 0);
  lua_createtable(L, dm_sparse_nnz(s->A), 0);
  lua_createtable(L, dm_sparse_nnz(s->A), 0);
  for (i = 0; i < s->A->nrows; i++)
    for (p = s->A->rowptr[i]; p < s->A->rowptr[i + 1]; p++) {
      k++;
      lua_pushinteger(L, i + 1);
      lua_rawseti(L, -4, k);
      lua_pushinteger(L, s->A->col[p] + 1);
      lua_rawseti(L, -3, k);
      lua_pushnumber(L, s->A->val[p]);
      lua_rawseti(L, -2, k);
    }
  return 3;
}

/* {==== solve ==================================================================== */

static int solve_fail(lua_State *L, dm_lsparse *s, const dm_err *e)
{
  if (e->status == DM_ESINGULAR && s->kernel)
    return luaL_error(L, "%s:solve: %s; without a boundary condition the kernel holds the "
                      "harmonic forms: pass {boundary = \"dirichlet\"}", s->label, e->msg);
  return luaL_error(L, "%s:solve: %s", s->label[0] ? s->label : "sparse", e->msg);
}

static int s_solve(lua_State *L)
{
  dm_lsparse *s = dm_checksparse(L, 1);
  dm_lcochain *c = dm_tocochain(L, 2);
  const double *b;
  double *x;
  dm_err e;
  int st;
  if (s->A->nrows != s->A->ncols)
    return luaL_error(L, "sparse:solve: square matrix expected, got %d x %d", s->A->nrows, s->A->ncols);
  if (c != NULL) {
    if (typed(s) && (c->K != s->K || !same(c->t, s->rng))) {
      const char *want = dm_dec_typename(L, s->rng), *got = dm_dec_typename(L, c->t);
      return luaL_error(L, "%s:solve: right-hand side must be a %s%s, got a %s", s->label, want,
                        c->K != s->K ? " of the same mesh" : "", got);
    }
    if (c->n != s->A->nrows)
      return luaL_error(L, "sparse:solve: %d rows, right-hand side of %d values", s->A->nrows, c->n);
    b = c->v;
  } else {
    b = dm_checkvector(L, 2, (size_t)s->A->nrows)->data;
  }
  if (typed(s)) {
    lua_getiuservalue(L, 1, 1);
    x = dm_newcochain(L, -1, s->dom)->v;
  } else {
    x = dm_pushvec(L, (size_t)s->A->nrows)->data;
  }
  if (s->S != NULL) {
    if (s->chol == NULL && (s->chol = dm_dec_solver_alloc(s->S, s->fixed, &e)) == NULL)
      return solve_fail(L, s, &e);
    st = dm_dec_solver_solve(s->chol, s->w, b, s->g, x, &e);
  } else {
    if (s->lu == NULL && (s->lu = dm_sparse_lu_alloc(s->A, &e)) == NULL)
      return solve_fail(L, s, &e);
    st = dm_sparse_lu_solve(s->lu, b, x, &e);
  }
  if (st != DM_OK)
    return solve_fail(L, s, &e);
  return 1;
}

/* }==== */

/* dm.sparse(rows, cols, {{i, j, v}, ...}) */
static int l_sparse(lua_State *L)
{
  lua_Integer nr = luaL_checkinteger(L, 1), nc = luaL_checkinteger(L, 2), k, n;
  dm_lsparse *s;
  int *ri, *ci;
  double *v;
  dm_err e;
  luaL_checktype(L, 3, LUA_TTABLE);
  if (nr < 1 || nc < 1 || nr > 0x7fffffff || nc > 0x7fffffff)
    return luaL_error(L, "dm.sparse: sizes %I x %I (positive expected)", nr, nc);
  n = (lua_Integer)lua_rawlen(L, 3);
  ri = lua_newuserdatauv(L, (size_t)(n + 1) * sizeof *ri, 0);
  ci = lua_newuserdatauv(L, (size_t)(n + 1) * sizeof *ci, 0);
  v = lua_newuserdatauv(L, (size_t)(n + 1) * sizeof *v, 0);
  for (k = 1; k <= n; k++) {
    int isnum[3], q;
    lua_Integer a, b;
    double x;
    if (lua_rawgeti(L, 3, k) != LUA_TTABLE)
      return luaL_error(L, "dm.sparse: entry %I: {i, j, value} expected, got %s", k, luaL_typename(L, -1));
    for (q = 1; q <= 3; q++)
      lua_rawgeti(L, -q, q);
    a = lua_tointegerx(L, -3, &isnum[0]);
    b = lua_tointegerx(L, -2, &isnum[1]);
    x = lua_tonumberx(L, -1, &isnum[2]);
    if (!isnum[0] || !isnum[1] || !isnum[2])
      return luaL_error(L, "dm.sparse: entry %I: {i, j, value} expected (integers i, j)", k);
    if (a < 1 || a > nr || b < 1 || b > nc)
      return luaL_error(L, "dm.sparse: entry %I: index (%I, %I) outside %I x %I", k, a, b, nr, nc);
    ri[k - 1] = (int)a - 1;
    ci[k - 1] = (int)b - 1;
    v[k - 1] = x;
    lua_pop(L, 4);
  }
  s = dm_newsparse(L, 0);
  s->A = dm_sparse_from_triplets((int)nr, (int)nc, (int)n, ri, ci, v, &e);
  if (s->A == NULL)
    return dm_lua_fail(L, "dm.sparse", e.status, &e);
  return 1;
}

static const dm_reg sparse_methods[] = {
  {"t", s_t, "A:t() -> sparse", "The transpose (an operator's types swap)."},
  {"norm", s_norm, "A:norm() -> number", "The Frobenius norm (the integer 0 when every entry is exactly zero)."},
  {"nnz", s_nnz, "A:nnz() -> integer", "The number of stored entries."},
  {"size", s_size, "A:size() -> rows, cols", "The numbers of rows and columns."},
  {"get", s_get, "A:get(i, j) -> number", "The entry in row i, column j (0 when not stored)."},
  {"triplets", s_triplets, "A:triplets() -> rows, cols, values",
   "The stored entries as three Lua tables (1-based indices), row by row."},
  {"solve", s_solve, "A:solve(b) -> x",
   "Solve A x = b: CHOLMOD for Laplacians (factored once, on the free unknowns of a Dirichlet problem), UMFPACK otherwise."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg sparse_meta[] = {
  {"__mul", s_mul}, {"__add", s_add}, {"__sub", s_sub}, {"__unm", s_unm},
  {"__tostring", s_tostring}, {"__gc", s_gc}, {"__close", s_gc}, {NULL, NULL}
};

static const dm_reg sparse_funcs[] = {
  {"sparse", l_sparse, "dm.sparse(rows, cols, {{i, j, v}, ...}) -> sparse",
   "A sparse matrix from (row, column, value) triplets; duplicates are summed."},
  {NULL, NULL, NULL, NULL}
};

void dm_open_sparse(lua_State *L)
{
  dm_newclass(L, DM_SPARSE_MT, "sparse", sparse_methods, sparse_meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", sparse_funcs);
}
