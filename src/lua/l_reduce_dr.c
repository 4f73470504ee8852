/* l_reduce_dr.c -- the discrete Routh equations in their two-point form
 * (the form of the reduction theorem: a DEL trajectory projected to shape
 * space solves them, and conversely):
 *
 *   local D = red:discrete{method = "gauss", stages = 2, h = 0.05}
 *   D:psi(x0, x1)               -> psi_mu, D1psi, D2psi
 *   D:lhat(x0, x1)              -> Lhat, {D1 =, D2 =, A1 =, A2 =}
 *   D:dlegendre(x0, x1)         -> s0, s1      (reduced discrete Legendre transforms)
 *   D:residual(xp, xc, xn)      -> DR residual, shape part of DEL
 *   D:solve(xp, xc)             -> xn          (DR equations solved for x_{k+1})
 *   D:dtheta(x0, x1, dth0, dx0, dx1) -> dth1   (reconstruction of tangent vectors)
 *
 * A userdata "dmech.routh.discrete" owns the dm_routh_dr; user value 1 is
 * the reduction (kept alive).  Scratch lives in userdata (no leak on an
 * argument error).  No numerics here. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "lua/l_reduce.h"

#define DR_MT "dmech.routh.discrete"

typedef struct ldr {
  dm_routh_dr *dr;             /* NULL once closed */
  dm_routh *red;               /* borrowed; anchored in user value 1 */
  double h;
  int stages;
  char method[16];
} ldr;

static int ldr_gc(lua_State *L)
{
  ldr *D = luaL_checkudata(L, 1, DR_MT);
  dm_routh_dr_free(D->dr);
  D->dr = NULL;
  return 0;
}

static ldr *check_ldr(lua_State *L)
{
  ldr *D = luaL_checkudata(L, 1, DR_MT);
  if (D->dr == NULL)
    luaL_error(L, "attempt to use a closed discrete Routh object");
  lua_getiuservalue(L, 1, 1);
  dm_lrouth_check(L, -1);          /* raises when the reduction was closed */
  lua_pop(L, 1);
  return D;
}

/* scratch doubles owned by a new userdata pushed above the first `top`
 * arguments (absent ones become nil) */
static double *scratch(lua_State *L, int top, size_t n)
{
  double *p;
  lua_settop(L, top);
  p = lua_newuserdatauv(L, (n ? n : 1) * sizeof(double), 0);
  memset(p, 0, (n ? n : 1) * sizeof(double));
  return p;
}

/* shape point at arg into x (s numbers: vec, list or {name = value}) */
static void read_x(lua_State *L, int self, int arg, const char *what, double *x)
{
  dm_lsystem *rs;
  lua_getiuservalue(L, self, 1);               /* the reduction */
  lua_getiuservalue(L, -1, 1);                 /* its reduced System */
  rs = lua_touserdata(L, -1);
  lua_pop(L, 2);
  dm_lua_system_readvec(L, rs, arg, what, x);
}

/* r group numbers at arg (a number for r = 1, else r numbers) */
static void read_r(lua_State *L, int arg, size_t r, double *g, const char *what)
{
  dm_lrouth_read_mu(L, arg, r, g, what);
}

/* r x s matrix (row-major, row stride `ld`): a vec for r = 1, else a mat */
static void push_rs(lua_State *L, const double *a, size_t r, size_t s, size_t ld)
{
  size_t i, j;
  if (r == 1) {
    dm_pushvec_copy(L, a, s);
    return;
  }
  gsl_matrix *M = dm_pushmat(L, r, s);
  for (i = 0; i < r; i++)
    for (j = 0; j < s; j++)
      gsl_matrix_set(M, i, j, a[i * ld + j]);
}

static int d_psi(lua_State *L)
{
  ldr *D = check_ldr(L);
  const dm_routh_exprs *x = dm_routh_exprs_get(D->red);
  size_t s = x->s, r = x->r;
  double *buf = scratch(L, 3, 2 * s + 2 * r * s + r);
  double *x0 = buf, *x1 = x0 + s, *Dp = x1 + s, *psi = Dp + 2 * r * s;
  dm_err e;
  int st;
  read_x(L, 1, 2, "psi: x0", x0);
  read_x(L, 1, 3, "psi: x1", x1);
  if ((st = dm_routh_dr_psi(D->dr, D->h, x0, x1, psi, Dp, &e)) != DM_OK)
    return dm_lua_fail(L, "psi", st, &e);
  dm_lrouth_push_numbers(L, psi, r);
  push_rs(L, Dp, r, s, 2 * s);
  push_rs(L, Dp + s, r, s, 2 * s);
  return 3;
}

static int d_lhat(lua_State *L)
{
  ldr *D = check_ldr(L);
  size_t s = dm_routh_exprs_get(D->red)->s;
  double *buf = scratch(L, 3, 6 * s + 1), *x0 = buf, *x1 = x0 + s, *D1 = x1 + s, *D2 = D1 + s;
  double *A1 = D2 + s, *A2 = A1 + s, *Lh = A2 + s;
  dm_err e;
  int st;
  read_x(L, 1, 2, "lhat: x0", x0);
  read_x(L, 1, 3, "lhat: x1", x1);
  if ((st = dm_routh_dr_lhat(D->dr, D->h, x0, x1, Lh, D1, D2, A1, A2, &e)) != DM_OK)
    return dm_lua_fail(L, "lhat", st, &e);
  lua_pushnumber(L, *Lh);
  lua_createtable(L, 0, 4);
  dm_pushvec_copy(L, D1, s);
  lua_setfield(L, -2, "D1");
  dm_pushvec_copy(L, D2, s);
  lua_setfield(L, -2, "D2");
  dm_pushvec_copy(L, A1, s);
  lua_setfield(L, -2, "A1");
  dm_pushvec_copy(L, A2, s);
  lua_setfield(L, -2, "A2");
  return 2;
}

static int d_legendre(lua_State *L)
{
  ldr *D = check_ldr(L);
  size_t s = dm_routh_exprs_get(D->red)->s, i;
  double *buf = scratch(L, 3, 6 * s), *x0 = buf, *x1 = x0 + s, *D1 = x1 + s, *D2 = D1 + s;
  double *A1 = D2 + s, *A2 = A1 + s;
  dm_err e;
  int st;
  read_x(L, 1, 2, "dlegendre: x0", x0);
  read_x(L, 1, 3, "dlegendre: x1", x1);
  if ((st = dm_routh_dr_lhat(D->dr, D->h, x0, x1, NULL, D1, D2, A1, A2, &e)) != DM_OK)
    return dm_lua_fail(L, "dlegendre", st, &e);
  for (i = 0; i < s; i++) {      /* F- = -D1 Lhat + Ahat_1, F+ = D2 Lhat - Ahat_2 */
    D1[i] = A1[i] - D1[i];
    D2[i] -= A2[i];
  }
  dm_pushvec_copy(L, D1, s);
  dm_pushvec_copy(L, D2, s);
  return 2;
}

static int d_residual(lua_State *L)
{
  ldr *D = check_ldr(L);
  size_t s = dm_routh_exprs_get(D->red)->s;
  double *buf = scratch(L, 4, 5 * s), *xp = buf, *xc = xp + s, *xn = xc + s, *rd = xn + s;
  double *rl = rd + s;
  dm_err e;
  int st;
  read_x(L, 1, 2, "residual: x_prev", xp);
  read_x(L, 1, 3, "residual: x_cur", xc);
  read_x(L, 1, 4, "residual: x_next", xn);
  if ((st = dm_routh_dr_residual(D->dr, D->h, xp, xc, xn, rd, rl, &e)) != DM_OK)
    return dm_lua_fail(L, "residual", st, &e);
  dm_pushvec_copy(L, rd, s);
  dm_pushvec_copy(L, rl, s);
  return 2;
}

static int d_solve(lua_State *L)
{
  ldr *D = check_ldr(L);
  size_t s = dm_routh_exprs_get(D->red)->s;
  double *buf = scratch(L, 4, 3 * s), *xp = buf, *xc = xp + s, *xn = xc + s;
  dm_err e;
  int st, guess = !lua_isnil(L, 4);
  read_x(L, 1, 2, "solve: x_prev", xp);
  read_x(L, 1, 3, "solve: x_cur", xc);
  if (guess)
    read_x(L, 1, 4, "solve: guess", xn);
  if ((st = dm_routh_dr_solve(D->dr, D->h, xp, xc, xn, guess, &e)) != DM_OK)
    return dm_lua_fail(L, "solve", st, &e);
  dm_pushvec_copy(L, xn, s);
  return 1;
}

/* dtheta1 = dtheta0 + D1 psi dx0 + D2 psi dx1 (additive coordinates) */
static int d_dtheta(lua_State *L)
{
  ldr *D = check_ldr(L);
  const dm_routh_exprs *x = dm_routh_exprs_get(D->red);
  size_t s = x->s, r = x->r, a, i;
  double *buf = scratch(L, 6, 4 * s + 2 * r * s), *x0 = buf, *x1 = x0 + s, *dx0 = x1 + s;
  double *dx1 = dx0 + s, *Dp = dx1 + s, psi[DM_ROUTH_RMAX], dth[DM_ROUTH_RMAX];
  dm_err e;
  int st;
  read_x(L, 1, 2, "dtheta: x0", x0);
  read_x(L, 1, 3, "dtheta: x1", x1);
  read_r(L, 4, r, dth, "dtheta (dtheta0)");
  read_x(L, 1, 5, "dtheta: dx0", dx0);
  read_x(L, 1, 6, "dtheta: dx1", dx1);
  if ((st = dm_routh_dr_psi(D->dr, D->h, x0, x1, psi, Dp, &e)) != DM_OK)
    return dm_lua_fail(L, "dtheta", st, &e);
  for (a = 0; a < r; a++)
    for (i = 0; i < s; i++)
      dth[a] += Dp[a * 2 * s + i] * dx0[i] + Dp[a * 2 * s + s + i] * dx1[i];
  dm_lrouth_push_numbers(L, dth, r);
  return 1;
}

static int ldr_index(lua_State *L)
{
  ldr *D = luaL_checkudata(L, 1, DR_MT);
  const char *k = dm_checkcstring(L, 2);
  if (lua_getfield(L, lua_upvalueindex(1), k) != LUA_TNIL)
    return 1;
  if (strcmp(k, "h") == 0)
    lua_pushnumber(L, D->h);
  else if (strcmp(k, "method") == 0)
    lua_pushstring(L, D->method);
  else if (strcmp(k, "stages") == 0)
    lua_pushinteger(L, D->stages);
  else if (strcmp(k, "reduction") == 0)
    lua_getiuservalue(L, 1, 1);
  else
    return luaL_error(L, "discrete Routh object has no field or method '%s' (fields: h, method, "
                      "stages, reduction; methods: psi, lhat, dlegendre, residual, solve, dtheta)", k);
  return 1;
}

static int ldr_tostring(lua_State *L)
{
  ldr *D = luaL_checkudata(L, 1, DR_MT);
  char num[32];
  int open;
  lua_getiuservalue(L, 1, 1);
  open = dm_lrouth_isopen(L, -1);
  lua_pop(L, 1);
  if (D->dr == NULL || !open) {
    lua_pushliteral(L, "<discrete Routh (closed)>");
    return 1;
  }
  dm_num_format(num, sizeof num, D->h);
  lua_pushfstring(L, "<discrete Routh '%s': %s", dm_routh_system(D->red)->name, D->method);
  if (strcmp(D->method, "midpoint") != 0)
    lua_pushfstring(L, " s=%d", D->stages);
  else
    lua_pushliteral(L, "");
  lua_pushfstring(L, " h=%s>", num);
  lua_concat(L, 3);
  return 1;
}

/* red:discrete{method = "midpoint" | "gauss" | "lobatto", stages =, h =} */
int dm_lrouth_discrete(lua_State *L)
{
  dm_lrouth *u = dm_lrouth_check(L, 1);
  static const char *const keys[] = {"method", "stages", "h", NULL};
  const char *method;
  int stages, st;
  double h;
  dm_tableau *t = NULL;
  ldr *D;
  dm_err e;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  lua_pushnil(L);
  while (lua_next(L, 2) != 0) {
    const char *const *k = keys;
    while (*k && !(lua_type(L, -2) == LUA_TSTRING && strcmp(*k, lua_tostring(L, -2)) == 0))
      k++;
    if (*k == NULL)
      return luaL_error(L, "discrete: unknown option %s (options: method, stages, h)",
                        dm_tolstring(L, -2, NULL));
    lua_pop(L, 1);
  }
  method = dm_optstringfield(L, 2, "method", "midpoint");
  h = dm_optnumberfield(L, 2, "h", NAN);
  if (!isfinite(h) || h == 0.0)
    return luaL_error(L, "discrete: option 'h' (a finite non-zero step) is required");
  if (strcmp(method, "gauss") == 0 || strcmp(method, "lobatto") == 0) {
    stages = (int)dm_optintegerfield(L, 2, "stages", strcmp(method, "gauss") == 0 ? 2 : 3);
    if (stages < (method[0] == 'g' ? 1 : 2) || stages > DM_TABLEAU_SMAX)
      return luaL_error(L, "discrete: %s needs %d <= stages <= %d, got %d", method,
                        method[0] == 'g' ? 1 : 2, DM_TABLEAU_SMAX, stages);
  } else if (strcmp(method, "midpoint") == 0) {
    stages = 1;
    if (dm_optintegerfield(L, 2, "stages", 1) != 1)
      return luaL_error(L, "discrete: midpoint has exactly 1 stage");
  } else {
    return luaL_error(L, "discrete: method must be \"midpoint\", \"gauss\" or \"lobatto\" (Galerkin "
                      "discrete Lagrangians), got \"%s\"", method);
  }
  D = lua_newuserdatauv(L, sizeof *D, 1);                      /* 3 */
  memset(D, 0, sizeof *D);
  luaL_setmetatable(L, DR_MT);
  lua_pushvalue(L, 1);
  lua_setiuservalue(L, 3, 1);
  D->red = u->red;
  D->h = h;
  D->stages = stages;
  snprintf(D->method, sizeof D->method, "%s", method);
  if (method[0] == 'g')
    st = dm_tableau_gauss((size_t)stages, &t, &e);
  else if (method[0] == 'l')
    st = dm_tableau_lobatto((size_t)stages, &t, &e);
  else
    st = DM_OK;
  if (st == DM_OK)
    st = dm_routh_dr_alloc(u->red, t, 0, 0, &D->dr, &e);
  dm_tableau_free(t);
  if (st != DM_OK)
    return dm_lua_fail(L, "discrete", st, &e);
  return 1;
}

static const dm_reg dr_methods[] = {
  {"psi", d_psi, "D:psi(x0, x1) -> psi, D1psi, D2psi",
   "The group step psi_mu(x0, x1) with J_d((0, x0), (psi, x1)) = mu (discrete reconstruction) and "
   "its derivatives (a vec of s for one cyclic coordinate, else r x s matrices)."},
  {"lhat", d_lhat, "D:lhat(x0, x1) -> Lhat, {D1 =, D2 =, A1 =, A2 =}",
   "The reduced discrete Lagrangian Lhat(x0, x1) = L_d((0, x0), (psi_mu, x1)), its derivatives "
   "D1 Lhat, D2 Lhat and the one-forms Ahat_1, Ahat_2 of the discrete Routh equations."},
  {"dlegendre", d_legendre, "D:dlegendre(x0, x1) -> s0, s1",
   "The reduced discrete Legendre transforms s0 = -D1 Lhat + Ahat_1 and s1 = D2 Lhat - Ahat_2 "
   "(the reduced momenta p_x - mu^T A at both ends)."},
  {"residual", d_residual, "D:residual(x_prev, x_cur, x_next) -> dr, del",
   "The discrete Routh equations D2 Lhat(x_prev, x_cur) + D1 Lhat(x_cur, x_next) - Ahat_2 - "
   "Ahat_1 term by term, and the shape components of DEL with the group steps psi_mu (both 0 on a "
   "solution)."},
  {"solve", d_solve, "D:solve(x_prev, x_cur[, guess]) -> x_next",
   "Solve the two-point discrete Routh equations for x_next (Newton, exact Jacobian)."},
  {"dtheta", d_dtheta, "D:dtheta(x0, x1, dtheta0, dx0, dx1) -> dtheta1",
   "Reconstruction of tangent vectors: dtheta1 = dtheta0 + D1psi dx0 + D2psi dx1 makes "
   "((dtheta0, dx0), (dtheta1, dx1)) tangent to J_d = mu."},
  {NULL, NULL, NULL, NULL}
};

void dm_lrouth_open_discrete(lua_State *L)
{
  static const luaL_Reg meta[] = {{"__gc", ldr_gc}, {"__close", ldr_gc},
                                  {"__tostring", ldr_tostring}, {NULL, NULL}};
  dm_newclass(L, DR_MT, "discrete", dr_methods, meta);
  lua_getfield(L, -1, "__methods");
  lua_pushcclosure(L, ldr_index, 1);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
}
