/* lmat.c -- dm.mat: GSL matrices as Lua userdata.
 *
 * Storage lives inside the userdata (row-major, tda = cols).  m[i] is a row
 * view (a vec sharing the matrix's memory, so m[i][j] = x writes through).
 * Products go through BLAS, factorizations through GSL; every temporary is a
 * Lua userdata, so an error at any point frees everything.
 */
#include <config.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_permutation.h>

#include "core/smalllu.h"
#include "lua/dmlua.h"

/* {======================================================================
 * construction and checking
 * ======================================================================= */

gsl_matrix *dm_pushmat(lua_State *L, size_t rows, size_t cols)
{
  dm_lmat *u;
  if (rows == 0 || cols == 0 || rows > ((size_t)-1 / sizeof(double)) / cols)
    luaL_error(L, "matrix size %dx%d out of range", (int)rows, (int)cols);
  u = lua_newuserdatauv(L, sizeof *u + rows * cols * sizeof(double), 0);
  u->m.size1 = rows;
  u->m.size2 = cols;
  u->m.tda = cols;
  u->m.data = (double *)(u + 1);
  u->m.block = NULL;
  u->m.owner = 0;
  memset(u->m.data, 0, rows * cols * sizeof(double));
  luaL_setmetatable(L, DM_MAT_MT);
  return &u->m;
}

gsl_matrix *dm_pushmat_copy(lua_State *L, const gsl_matrix *src)
{
  gsl_matrix *m = dm_pushmat(L, src->size1, src->size2);
  gsl_matrix_memcpy(m, src);
  return m;
}

gsl_matrix *dm_tomat(lua_State *L, int arg)
{
  dm_lmat *u = luaL_testudata(L, arg, DM_MAT_MT);
  return u != NULL ? &u->m : NULL;
}

gsl_matrix *dm_checkmat(lua_State *L, int arg)
{
  return &((dm_lmat *)luaL_checkudata(L, arg, DM_MAT_MT))->m;
}

/* A table of equal-length row tables (or row vecs) at arg -> new mat (pushed). */
static gsl_matrix *mat_fromtable(lua_State *L, int arg)
{
  size_t i, j, rows = lua_rawlen(L, arg), cols;
  gsl_matrix *m;
  if (rows == 0)
    dm_argexpected(L, arg, "non-empty table of rows", "empty table");
  lua_rawgeti(L, arg, 1);
  if (dm_tovec(L, -1) != NULL)
    cols = dm_tovec(L, -1)->size;
  else if (lua_type(L, -1) == LUA_TTABLE)
    cols = lua_rawlen(L, -1);
  else
    cols = 0;
  lua_pop(L, 1);
  if (cols == 0)
    dm_argexpected(L, arg, "table of non-empty rows", "something else at row 1");
  m = dm_pushmat(L, rows, cols);
  for (i = 0; i < rows; i++) {
    gsl_vector *row;
    lua_rawgeti(L, arg, (lua_Integer)i + 1);
    if (lua_type(L, -1) != LUA_TTABLE && dm_tovec(L, -1) == NULL) {
      const char *msg = lua_pushfstring(L, "table of rows expected, got %s at row %d",
                                        luaL_typename(L, -1), (int)i + 1);
      luaL_argerror(L, arg, msg);
    }
    row = dm_tovec(L, -1);
    if (row == NULL)
      row = dm_checkvector(L, -1, 0);
    if (row->size != cols) {
      const char *msg = lua_pushfstring(L, "rows of equal length expected, row %d has %d, row 1 has %d",
                                        (int)i + 1, (int)row->size, (int)cols);
      luaL_argerror(L, arg, msg);
    }
    for (j = 0; j < cols; j++)
      gsl_matrix_set(m, i, j, gsl_vector_get(row, j));
    lua_pop(L, 1);
  }
  return m;
}

gsl_matrix *dm_checkmatrix(lua_State *L, int arg, size_t rows, size_t cols)
{
  gsl_matrix *m;
  arg = lua_absindex(L, arg);
  m = dm_tomat(L, arg);
  if (m == NULL) {
    if (lua_type(L, arg) != LUA_TTABLE)
      dm_argexpected(L, arg, "mat or table of rows", luaL_typename(L, arg));
    m = mat_fromtable(L, arg);
    lua_replace(L, arg);
  }
  if ((rows != 0 && m->size1 != rows) || (cols != 0 && m->size2 != cols)) {
    const char *want = lua_pushfstring(L, "%dx%d matrix", (int)rows, (int)cols);
    const char *got = lua_pushfstring(L, "%dx%d", (int)m->size1, (int)m->size2);
    dm_argexpected(L, arg, want, got);
  }
  return m;
}

static gsl_matrix *checksquare(lua_State *L, int arg, const char *what)
{
  gsl_matrix *m = dm_checkmat(L, arg);
  if (m->size1 != m->size2)
    luaL_error(L, "%s: square matrix expected, got %dx%d", what, (int)m->size1, (int)m->size2);
  return m;
}

/* }====================================================================== */

/* {======================================================================
 * functions of dm
 * ======================================================================= */

static int l_mat(lua_State *L)
{
  if (lua_isinteger(L, 1)) {
    lua_Integer r = lua_tointeger(L, 1), c = luaL_optinteger(L, 2, r);
    luaL_argcheck(L, r > 0, 1, "positive number of rows expected");
    luaL_argcheck(L, c > 0, 2, "positive number of columns expected");
    dm_pushmat(L, (size_t)r, (size_t)c);
  } else if (dm_tomat(L, 1) != NULL) {
    dm_pushmat_copy(L, dm_tomat(L, 1));
  } else if (lua_type(L, 1) == LUA_TTABLE) {
    mat_fromtable(L, 1);
  } else {
    return dm_argexpected(L, 1, "size, table of rows or mat",
                          lua_isnone(L, 1) ? "no value" : luaL_typename(L, 1));
  }
  return 1;
}

static int l_eye(lua_State *L)
{
  lua_Integer n = luaL_checkinteger(L, 1);
  luaL_argcheck(L, n > 0, 1, "positive size expected");
  gsl_matrix_set_identity(dm_pushmat(L, (size_t)n, (size_t)n));
  return 1;
}

static int l_diag(lua_State *L)
{
  gsl_vector *d = dm_checkvector(L, 1, 0);
  gsl_matrix *m = dm_pushmat(L, d->size, d->size);
  size_t i;
  for (i = 0; i < d->size; i++)
    gsl_matrix_set(m, i, i, gsl_vector_get(d, i));
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * methods
 * ======================================================================= */

static int mt_rows(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)dm_checkmat(L, 1)->size1);
  return 1;
}

static int mt_cols(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)dm_checkmat(L, 1)->size2);
  return 1;
}

static void checkij(lua_State *L, const gsl_matrix *m, size_t *i, size_t *j)
{
  lua_Integer a = luaL_checkinteger(L, 2), b = luaL_checkinteger(L, 3);
  if (a < 1 || (size_t)a > m->size1 || b < 1 || (size_t)b > m->size2)
    luaL_error(L, "mat index (%I, %I) out of range (%dx%d)", a, b,
               (int)m->size1, (int)m->size2);
  *i = (size_t)a - 1;
  *j = (size_t)b - 1;
}

static int mt_get(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  size_t i, j;
  checkij(L, m, &i, &j);
  lua_pushnumber(L, gsl_matrix_get(m, i, j));
  return 1;
}

static int mt_set(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  size_t i, j;
  checkij(L, m, &i, &j);
  gsl_matrix_set(m, i, j, luaL_checknumber(L, 4));
  return 0;
}

static int mt_t(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  gsl_matrix_transpose_memcpy(dm_pushmat(L, m->size2, m->size1), m);
  return 1;
}

static int mt_copy(lua_State *L)
{
  dm_pushmat_copy(L, dm_checkmat(L, 1));
  return 1;
}

static int mt_trace(lua_State *L)
{
  gsl_matrix *m = checksquare(L, 1, "trace");
  double s = 0.0;
  size_t i;
  for (i = 0; i < m->size1; i++)
    s += gsl_matrix_get(m, i, i);
  lua_pushnumber(L, s);
  return 1;
}

static int mt_norm(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  gsl_vector_view all = gsl_vector_view_array(m->data, m->size1 * m->size2);
  lua_pushnumber(L, gsl_blas_dnrm2(&all.vector));
  return 1;
}

/* LU factorization of a copy of the square matrix at 1.  The copy (a mat)
 * and the permutation storage are pushed, so nothing can leak.  Up to
 * DM_SMALLLU_NMAX the allocation-free kernel of core/smalllu.h factors
 * (GSL 2.7's LU allocates a pivot vector inside and crashes when that
 * allocation fails -- found by tests/c/test_fault_alloc.c); larger
 * matrices go to GSL through dm_gsl_lu_decomp. */
typedef struct lu {
  gsl_matrix *a;
  gsl_permutation p;
  int sign;
  int singular;
  int small;          /* factored by dm_smalllu_factor (its layout) */
} lu;

static void lu_factor(lua_State *L, const char *what, lu *f)
{
  gsl_matrix *m = checksquare(L, 1, what);
  size_t i, n = m->size1;
  f->a = dm_pushmat_copy(L, m);
  f->p.size = n;
  f->p.data = lua_newuserdatauv(L, (n > 0 ? n : 1) * sizeof(size_t), 0);
  f->small = n <= DM_SMALLLU_NMAX && f->a->tda == n;
  f->singular = 0;
  f->sign = 1;
  if (f->small) {
    int st = dm_smalllu_factor(f->a->data, n, f->p.data);
    f->singular = st != DM_OK;
    for (i = 0; !f->singular && i < n; i++)
      if (f->p.data[i] != i)
        f->sign = -f->sign;
    return;
  }
  if (dm_gsl_lu_decomp(f->a, &f->p, &f->sign) == DM_ENOMEM)
    luaL_error(L, "%s: out of memory", what);
  for (i = 0; i < n; i++)
    if (gsl_matrix_get(f->a, i, i) == 0.0 || !isfinite(gsl_matrix_get(f->a, i, i)))
      f->singular = 1;
}

/* x = A^-1 b with the factors (b and x may be the same vector). */
static void lu_solve(const lu *f, const gsl_vector *b, gsl_vector *x)
{
  size_t n = f->a->size1;
  if (f->small) {
    gsl_vector_memcpy(x, b);
    dm_smalllu_solve(f->a->data, n, f->p.data, x->data);
  } else {
    gsl_linalg_LU_solve(f->a, &f->p, b, x);
  }
}

static int mt_det(lua_State *L)
{
  lu f;
  double d = 1.0;
  size_t i, n;
  lu_factor(L, "det", &f);
  n = f.a->size1;
  if (f.singular)
    d = 0.0;
  else if (f.small)
    for (i = 0; i < n; i++)
      d /= gsl_matrix_get(f.a, i, i);        /* the kernel keeps 1/U_kk */
  else
    d = gsl_linalg_LU_det(f.a, f.sign);
  lua_pushnumber(L, f.small && !f.singular ? f.sign * d : d);
  return 1;
}

static int mt_inv(lua_State *L)
{
  lu f;
  gsl_matrix *r;
  size_t j, n;
  lu_factor(L, "inv", &f);
  if (f.singular)
    return luaL_error(L, "inv: matrix is singular");
  n = f.a->size1;
  r = dm_pushmat(L, n, n);
  if (!f.small) {
    if (gsl_linalg_LU_invert(f.a, &f.p, r) != GSL_SUCCESS)
      return luaL_error(L, "inv: matrix is singular");
    return 1;
  }
  {
    gsl_vector *e = dm_pushvec(L, n);          /* contiguous column buffer */
    for (j = 0; j < n; j++) {                  /* column j: A x = e_j */
      gsl_vector_view c = gsl_matrix_column(r, j);
      gsl_vector_set_basis(e, j);
      dm_smalllu_solve(f.a->data, n, f.p.data, e->data);
      gsl_vector_memcpy(&c.vector, e);
    }
    lua_pop(L, 1);
  }
  return 1;
}

static int mt_solve(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  gsl_vector *b = dm_checkvector(L, 2, m->size1), *x;
  lu f;
  lu_factor(L, "solve", &f);
  if (f.singular)
    return luaL_error(L, "solve: matrix is singular");
  x = dm_pushvec(L, m->size1);
  lu_solve(&f, b, x);
  return 1;
}

/* Eigen-decomposition of a symmetric matrix: values ascending, and the
 * matrix whose columns are the corresponding orthonormal eigenvectors. */
static int mt_eig(lua_State *L)
{
  gsl_matrix *m = checksquare(L, 1, "eig"), *a, *vecs;
  gsl_vector *vals;
  gsl_eigen_symmv_workspace *w;
  size_t i, j, n = m->size1;
  double scale = 0.0;
  int st;
  for (i = 0; i < n; i++)
    for (j = 0; j < n; j++)
      scale = fmax(scale, fabs(gsl_matrix_get(m, i, j)));
  for (i = 0; i < n; i++)
    for (j = i + 1; j < n; j++)
      if (fabs(gsl_matrix_get(m, i, j) - gsl_matrix_get(m, j, i)) > 1e-12 * scale)
        return luaL_error(L, "eig: symmetric matrix expected (entries (%d,%d) and (%d,%d) differ)",
                          (int)i + 1, (int)j + 1, (int)j + 1, (int)i + 1);
  a = dm_pushmat_copy(L, m);
  vals = dm_pushvec(L, n);
  vecs = dm_pushmat(L, n, n);
  w = gsl_eigen_symmv_alloc(n);
  if (w == NULL)
    return luaL_error(L, "eig: out of memory");
  st = gsl_eigen_symmv(a, vals, vecs, w);
  gsl_eigen_symmv_free(w);
  if (st != GSL_SUCCESS)
    return luaL_error(L, "eig: %s", gsl_strerror(st));
  gsl_eigen_symmv_sort(vals, vecs, GSL_EIGEN_SORT_VAL_ASC);
  return 2;
}

static int mt_totable(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  size_t i, j;
  lua_createtable(L, (int)m->size1, 0);
  for (i = 0; i < m->size1; i++) {
    lua_createtable(L, (int)m->size2, 0);
    for (j = 0; j < m->size2; j++) {
      lua_pushnumber(L, gsl_matrix_get(m, i, j));
      lua_rawseti(L, -2, (lua_Integer)j + 1);
    }
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  return 1;
}

static int mt_col(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  lua_Integer j = luaL_checkinteger(L, 2);
  if (j < 1 || (size_t)j > m->size2)
    return luaL_error(L, "mat column %I out of range 1..%d", j, (int)m->size2);
  {
    gsl_vector_const_view c = gsl_matrix_const_column(m, (size_t)j - 1);
    gsl_vector_memcpy(dm_pushvec(L, m->size1), &c.vector);
  }
  return 1;
}

/* }====================================================================== */

/* {======================================================================
 * metamethods
 * ======================================================================= */

/* m[i]: a vec viewing row i (writes go to the matrix). */
static int pushrow(lua_State *L, int marg, size_t i)
{
  gsl_matrix *m = dm_checkmat(L, marg);
  dm_lvec *u = lua_newuserdatauv(L, sizeof *u, 1);
  u->v.size = m->size2;
  u->v.stride = 1;
  u->v.data = m->data + i * m->tda;
  u->v.block = NULL;
  u->v.owner = 0;
  luaL_setmetatable(L, DM_VEC_MT);
  lua_pushvalue(L, marg);
  lua_setiuservalue(L, -2, 1);      /* keep the matrix alive */
  return 1;
}

static int mm_index(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  if (lua_type(L, 2) == LUA_TNUMBER) {
    lua_Integer i = luaL_checkinteger(L, 2);
    if (i < 1 || (size_t)i > m->size1)
      return luaL_error(L, "mat row %I out of range 1..%d", i, (int)m->size1);
    return pushrow(L, 1, (size_t)i - 1);
  }
  return dm_index_methods(L);
}

static int mm_newindex(lua_State *L)
{
  return luaL_error(L, "mat: assign elements with m[i][j] = x or m:set(i, j, x)");
}

static int mm_len(lua_State *L)
{
  lua_pushinteger(L, (lua_Integer)dm_checkmat(L, 1)->size1);
  return 1;
}

static int elementwise(lua_State *L, char op)
{
  gsl_matrix *a = dm_tomat(L, 1), *b = dm_tomat(L, 2), *r;
  size_t k, n;
  if (a == NULL || b == NULL)
    return luaL_error(L, "mat %c: mat operands expected, got %s and %s", op,
                      luaL_typename(L, 1), luaL_typename(L, 2));
  if (a->size1 != b->size1 || a->size2 != b->size2)
    return luaL_error(L, "mat %c mat: shapes differ (%dx%d and %dx%d)", op,
                      (int)a->size1, (int)a->size2, (int)b->size1, (int)b->size2);
  r = dm_pushmat(L, a->size1, a->size2);
  n = a->size1 * a->size2;
  for (k = 0; k < n; k++)
    r->data[k] = op == '+' ? a->data[k] + b->data[k] : a->data[k] - b->data[k];
  return 1;
}

static int mm_add(lua_State *L) { return elementwise(L, '+'); }
static int mm_sub(lua_State *L) { return elementwise(L, '-'); }

static int scale(lua_State *L, const gsl_matrix *m, double s, int divide)
{
  gsl_matrix *r = dm_pushmat(L, m->size1, m->size2);
  size_t k, n = m->size1 * m->size2;
  for (k = 0; k < n; k++)
    r->data[k] = divide ? m->data[k] / s : m->data[k] * s;
  return 1;
}

static int mm_mul(lua_State *L)
{
  gsl_matrix *a = dm_tomat(L, 1), *b = dm_tomat(L, 2);
  gsl_vector *v;
  if (a != NULL && b != NULL) {
    if (a->size2 != b->size1)
      return luaL_error(L, "mat * mat: inner dimensions differ (%dx%d times %dx%d)",
                        (int)a->size1, (int)a->size2, (int)b->size1, (int)b->size2);
    gsl_blas_dgemm(CblasNoTrans, CblasNoTrans, 1.0, a, b, 0.0,
                   dm_pushmat(L, a->size1, b->size2));
    return 1;
  }
  if (a != NULL && (v = dm_tovec(L, 2)) != NULL) {
    if (v->size != a->size2)
      return luaL_error(L, "mat * vec: %dx%d matrix times vector of length %d",
                        (int)a->size1, (int)a->size2, (int)v->size);
    gsl_blas_dgemv(CblasNoTrans, 1.0, a, v, 0.0, dm_pushvec(L, a->size1));
    return 1;
  }
  if (a != NULL && lua_type(L, 2) == LUA_TNUMBER)
    return scale(L, a, lua_tonumber(L, 2), 0);
  if (b != NULL && lua_type(L, 1) == LUA_TNUMBER)
    return scale(L, b, lua_tonumber(L, 1), 0);
  return luaL_error(L, "mat *: mat, vec or number operands expected, got %s and %s",
                    luaL_typename(L, 1), luaL_typename(L, 2));
}

/* v * m (registered for lvec.c): the row vector v^T m. */
static int vecmat(lua_State *L)
{
  gsl_vector *v = dm_checkvec(L, 1);
  gsl_matrix *m = dm_checkmat(L, 2);
  if (v->size != m->size1)
    return luaL_error(L, "vec * mat: vector of length %d times %dx%d matrix",
                      (int)v->size, (int)m->size1, (int)m->size2);
  gsl_blas_dgemv(CblasTrans, 1.0, m, v, 0.0, dm_pushvec(L, m->size2));
  return 1;
}

static int mm_div(lua_State *L)
{
  gsl_matrix *a = dm_tomat(L, 1);
  if (a == NULL || lua_type(L, 2) != LUA_TNUMBER)
    return luaL_error(L, "mat /: only division by a number is defined");
  return scale(L, a, lua_tonumber(L, 2), 1);
}

static int mm_unm(lua_State *L)
{
  return scale(L, dm_checkmat(L, 1), -1.0, 0);
}

static int mm_eq(lua_State *L)
{
  gsl_matrix *a = dm_tomat(L, 1), *b = dm_tomat(L, 2);
  lua_pushboolean(L, a != NULL && b != NULL && gsl_matrix_equal(a, b));
  return 1;
}

/* Rows on separate lines, columns right-aligned to a common width. */
static int mm_tostring(lua_State *L)
{
  gsl_matrix *m = dm_checkmat(L, 1);
  luaL_Buffer b;
  char num[32];
  size_t i, j;
  int w = 1;
  for (i = 0; i < m->size1; i++)
    for (j = 0; j < m->size2; j++) {
      int len = dm_num_format(num, sizeof num, gsl_matrix_get(m, i, j));
      if (len > w)
        w = len;
    }
  luaL_buffinit(L, &b);
  luaL_addstring(&b, "mat{");
  for (i = 0; i < m->size1; i++) {
    luaL_addstring(&b, i == 0 ? "{" : ",\n    {");
    for (j = 0; j < m->size2; j++) {
      char cell[48];
      dm_num_format(num, sizeof num, gsl_matrix_get(m, i, j));
      snprintf(cell, sizeof cell, "%s%*s", j > 0 ? ", " : "", w, num);
      luaL_addstring(&b, cell);
    }
    luaL_addstring(&b, "}");
  }
  luaL_addstring(&b, "}");
  luaL_pushresult(&b);
  return 1;
}

/* }====================================================================== */

static const dm_reg mat_methods[] = {
  {"rows", mt_rows, "m:rows() -> integer", "Number of rows."},
  {"cols", mt_cols, "m:cols() -> integer", "Number of columns."},
  {"get", mt_get, "m:get(i, j) -> number", "Element (i, j), 1-based."},
  {"set", mt_set, "m:set(i, j, x)", "Set element (i, j) to x."},
  {"col", mt_col, "m:col(j) -> vec", "A copy of column j."},
  {"t", mt_t, "m:t() -> mat", "The transpose."},
  {"copy", mt_copy, "m:copy() -> mat", "An independent copy."},
  {"trace", mt_trace, "m:trace() -> number", "Sum of the diagonal of a square matrix."},
  {"norm", mt_norm, "m:norm() -> number", "Frobenius norm."},
  {"det", mt_det, "m:det() -> number", "Determinant (LU factorization, GSL)."},
  {"inv", mt_inv, "m:inv() -> mat", "Inverse (LU, GSL); raises an error for a singular matrix."},
  {"solve", mt_solve, "m:solve(b) -> vec", "Solution x of m x = b (LU, GSL)."},
  {"eig", mt_eig, "m:eig() -> values, vectors",
   "Eigenvalues (ascending vec) and eigenvectors (columns of a mat) of a symmetric matrix."},
  {"totable", mt_totable, "m:totable() -> table", "The rows as a new table of tables."},
  {NULL, NULL, NULL, NULL}
};

static const luaL_Reg mat_meta[] = {
  {"__index", mm_index},
  {"__newindex", mm_newindex},
  {"__len", mm_len},
  {"__add", mm_add},
  {"__sub", mm_sub},
  {"__mul", mm_mul},
  {"__div", mm_div},
  {"__unm", mm_unm},
  {"__eq", mm_eq},
  {"__tostring", mm_tostring},
  {NULL, NULL}
};

static const dm_reg mat_funcs[] = {
  {"mat", l_mat, "dm.mat(rows[, cols] | {{...}, ...} | m) -> mat",
   "A zero matrix of the given size, or one built from a table of rows (a copy when given a mat)."},
  {"eye", l_eye, "dm.eye(n) -> mat", "The n x n identity matrix."},
  {"diag", l_diag, "dm.diag(v) -> mat", "Square matrix with v on the diagonal."},
  {NULL, NULL, NULL, NULL}
};


void dm_open_mat(lua_State *L)
{
  dm_newclass(L, DM_MAT_MT, "mat", mat_methods, mat_meta);
  lua_pop(L, 1);
  lua_pushcfunction(L, vecmat);
  lua_setfield(L, LUA_REGISTRYINDEX, "dmech.vecmat");
  dm_register(L, "dm.", mat_funcs);
}
