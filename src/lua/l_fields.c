/* l_fields.c -- field integrators in Lua (src/fields/fields.h):
 * dm.schrodinger{K =, hbar =, m =, V =, samples =} (the pseudospectral
 * variational integrator) and its states, the Wave objects.
 *
 * A Schrodinger userdata owns a dm_schrod.  A Wave userdata holds the N
 * complex coefficients of a state; its user value 1 is the Schrodinger it
 * belongs to (kept alive).  The potential V is a Lua function of x sampled
 * once on the FFT grid (a number is a constant potential); an initial
 * state is a Lua function of x returning Re psi [, Im psi], sampled and
 * analysed by FFT.  Runs and eigenpairs are C; this file reads options
 * and converts. */
#include <config.h>
#include <math.h>
#include <string.h>

#include "fields/fields.h"
#include "integrators/multiscale.h"
#include "lua/dmlua.h"
#include "lua/l_system.h"
/* after the headers that name parameters I */
#include <complex.h>

#define SCHROD_MT "dmech.schrodinger"
#define WAVE_MT "dmech.wave"

typedef struct lschrod {
  dm_schrod *S;
} lschrod;

typedef struct lwave {
  size_t N;
  double complex c[];        /* N coefficients */
} lwave;

static lschrod *checkschrod(lua_State *L, int idx)
{
  lschrod *u = luaL_checkudata(L, idx, SCHROD_MT);
  if (u->S == NULL)
    luaL_error(L, "attempt to use a closed Schrodinger integrator");
  return u;
}

static lwave *checkwave(lua_State *L, int idx)
{
  return luaL_checkudata(L, idx, WAVE_MT);
}

/* A new Wave for the Schrodinger at sidx (pushed). */
static lwave *pushwave(lua_State *L, int sidx, size_t N)
{
  lwave *w;
  sidx = lua_absindex(L, sidx);
  w = lua_newuserdatauv(L, sizeof *w + N * sizeof w->c[0], 1);
  w->N = N;
  memset(w->c, 0, N * sizeof w->c[0]);
  luaL_setmetatable(L, WAVE_MT);
  lua_pushvalue(L, sidx);
  lua_setiuservalue(L, -2, 1);
  return w;
}

/* The Schrodinger of the wave at widx (pushed). */
static dm_schrod *wave_owner(lua_State *L, int widx)
{
  lua_getiuservalue(L, widx, 1);
  return checkschrod(L, -1)->S;
}

/* Raise "<what>: <message>" without the C message's own "schrodinger: "
 * or "msfem: ". */
static int fail(lua_State *L, const char *what, int st, const dm_err *e)
{
  const char *m = e->msg;
  if (strncmp(m, "schrodinger: ", 13) == 0)
    m += 13;
  else if (strncmp(m, "msfem: ", 7) == 0)
    m += 7;
  if (st == DM_ENOMEM)
    return luaL_error(L, "%s: out of memory", what);
  return luaL_error(L, "%s: %s", what, m[0] ? m : dm_strstatus(st));
}

static int schrod_gc(lua_State *L)
{
  lschrod *u = luaL_checkudata(L, 1, SCHROD_MT);
  dm_schrod_free(u->S);
  u->S = NULL;
  return 0;
}

/* f(x) at x_j = 2 pi j/M: numbers re[, im] into out (im may be NULL). */
static void sample(lua_State *L, int f, size_t M, const char *what, double *re, double *im)
{
  for (size_t j = 0; j < M; j++) {
    double x = 2.0 * M_PI * (double)j / (double)M;
    int ok1, ok2 = 1;
    lua_pushvalue(L, f);
    lua_pushnumber(L, x);
    lua_call(L, 1, 2);
    re[j] = lua_tonumberx(L, -2, &ok1);
    if (im != NULL)
      im[j] = lua_isnil(L, -1) ? 0.0 : lua_tonumberx(L, -1, &ok2);
    if (!ok1 || !ok2 || !isfinite(re[j]) || (im != NULL && !isfinite(im[j])))
      luaL_error(L, "%s must return finite numbers, got %s at x = %f", what,
                 luaL_tolstring(L, ok1 && isfinite(re[j]) ? -1 : -2, NULL), x);
    lua_pop(L, 2);
  }
}

static const char *const schrod_keys[] = {"K", "hbar", "m", "V", "samples", NULL};

/* dm.schrodinger{K = 32, hbar = 1, m = 1, V = function(x) ... end, samples = 65536} */
static int l_schrodinger(lua_State *L)
{
  lua_Integer K, M;
  double hbar, m, *V = NULL;
  dm_err e;
  int st;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_checkkeys(L, 1, schrod_keys, "dm.schrodinger", "field", "K, hbar, m, V, samples");
  K = dm_optintegerfield(L, 1, "K", 16);
  hbar = dm_optnumberfield(L, 1, "hbar", 1.0);
  m = dm_optnumberfield(L, 1, "m", 1.0);
  M = dm_optintegerfield(L, 1, "samples", 0);
  if (K < 0 || K > 4096)
    luaL_error(L, "dm.schrodinger: K must be in 0..4096 (the modes are k = -K..K), got %d", (int)K);
  lschrod *u = lua_newuserdatauv(L, sizeof *u, 0);            /* 2 */
  u->S = NULL;
  luaL_setmetatable(L, SCHROD_MT);
  int vt = lua_getfield(L, 1, "V");                             /* 3 */
  if (vt != LUA_TNIL) {
    if (vt != LUA_TFUNCTION && vt != LUA_TNUMBER)
      luaL_error(L, "dm.schrodinger: V must be a function of x or a number, got %s",
                 luaL_typename(L, 3));
    if (M == 0) {
      M = 1;
      while (M <= 4 * K || M < 4096)
        M *= 2;
    }
    if (M <= 4 * K || M > (1 << 24))
      luaL_error(L, "dm.schrodinger: samples must be more than 4K = %d (and at most 2^24), got %d",
                 (int)(4 * K), (int)M);
    V = lua_newuserdatauv(L, (size_t)M * sizeof *V, 0);       /* 4 */
    if (vt == LUA_TNUMBER)
      for (lua_Integer j = 0; j < M; j++)
        V[j] = lua_tonumber(L, 3);
    else
      sample(L, 3, (size_t)M, "dm.schrodinger: V", V, NULL);
  }
  if ((st = dm_schrod_alloc((size_t)K, hbar, m, V, (size_t)M, &u->S, &e)) != DM_OK)
    return fail(L, "dm.schrodinger", st, &e);
  lua_settop(L, 2);
  return 1;
}

/* S:energies() -> vec: the eigenvalues of the Galerkin Hamiltonian */
static int s_energies(lua_State *L)
{
  lschrod *u = checkschrod(L, 1);
  gsl_vector *ev = dm_pushvec(L, dm_schrod_modes(u->S));
  dm_err e;
  int st = dm_schrod_eigen(u->S, ev, NULL, &e);
  if (st != DM_OK)
    return fail(L, "energies", st, &e);
  return 1;
}

/* S:eigenstate(n) -> wave, E: the n-th eigenvector (n = 0: ground state),
 * normalised to int |psi|^2 = 1 */
static int s_eigenstate(lua_State *L)
{
  lschrod *u = checkschrod(L, 1);
  size_t N = dm_schrod_modes(u->S);
  lua_Integer n = luaL_checkinteger(L, 2);
  dm_err e;
  luaL_argcheck(L, n >= 0 && (size_t)n < N, 2, "state number 0 .. modes - 1 expected");
  gsl_vector *ev = dm_pushvec(L, N);                            /* 3 */
  double *zd = lua_newuserdatauv(L, 2 * N * N * sizeof *zd, 0);  /* 4: owned by Lua */
  gsl_matrix_complex_view Z = gsl_matrix_complex_view_array(zd, N, N);
  int st = dm_schrod_eigen(u->S, ev, &Z.matrix, &e);
  if (st != DM_OK)
    return fail(L, "eigenstate", st, &e);
  lwave *w = pushwave(L, 1, N);
  for (size_t j = 0; j < N; j++) {
    gsl_complex z = gsl_matrix_complex_get(&Z.matrix, j, (size_t)n);
    w->c[j] = (GSL_REAL(z) + I * GSL_IMAG(z)) / sqrt(2.0 * M_PI);
  }
  lua_pushnumber(L, gsl_vector_get(ev, (size_t)n));
  return 2;
}

/* S:wave(function(x) return re[, im] end[, samples]) -> wave */
static int s_wave(lua_State *L)
{
  lschrod *u = checkschrod(L, 1);
  size_t N = dm_schrod_modes(u->S), M;
  lua_Integer ms = luaL_optinteger(L, 3, 0);
  dm_err e;
  luaL_checktype(L, 2, LUA_TFUNCTION);
  M = ms > 0 ? (size_t)ms : 1;
  if (ms == 0)
    while (M <= 4 * dm_schrod_K(u->S) || M < 1024)
      M *= 2;
  luaL_argcheck(L, M > 2 * dm_schrod_K(u->S) && M <= (1u << 24), 3,
                "more samples than 2K (and at most 2^24) expected");
  double *re = lua_newuserdatauv(L, 2 * M * sizeof *re, 0);   /* 4 */
  double complex *psi = lua_newuserdatauv(L, M * sizeof *psi, 0);
  sample(L, 2, M, "wave: psi", re, re + M);
  for (size_t j = 0; j < M; j++)
    psi[j] = re[j] + I * re[M + j];
  lwave *w = pushwave(L, 1, N);
  int st = dm_schrod_analyse(u->S, psi, M, w->c, &e);
  if (st != DM_OK)
    return fail(L, "wave", st, &e);
  return 1;
}

/* The index of string option `key` of the table t in list (0: absent). */
static int pick(lua_State *L, int t, const char *key, const char *const *list, const char *says)
{
  int i = 0;
  if (lua_getfield(L, t, key) != LUA_TNIL) {
    const char *v = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
    for (; v && list[i] && strcmp(list[i], v) != 0; i++)
      ;
    if (v == NULL || list[i] == NULL)
      luaL_error(L, "run: %s must be %s, got %s%s%s", key, says, v ? "'" : "",
                 luaL_tolstring(L, -1, NULL), v ? "'" : "");
  }
  lua_pop(L, 1);
  return i;
}

static const char *const run_keys[] = {"method", "dt", "t", "steps", "every", "start", NULL};

/* S:run(wave, {method = "milne", dt =, t = | steps =, every = 1, start = "exact"})
 * -> traj, wave */
static int s_run(lua_State *L)
{
  lschrod *u = checkschrod(L, 1);
  lwave *w0 = checkwave(L, 2);
  size_t N = dm_schrod_modes(u->S);
  static const char *const methods[] = {"milne", "cn", "exact", NULL};
  static const char *const starts[] = {"exact", "cn", NULL};
  static const int mcode[] = {DM_SCHROD_MILNE, DM_SCHROD_CN, DM_SCHROD_EXACT};
  dm_schrod_stepper *P = NULL;
  dm_err e;
  long nsteps, done;
  int st;
  luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  if (w0->N != N || (wave_owner(L, 2), lua_rawequal(L, -1, 1)) == 0)
    return luaL_argerror(L, 2, "a wave of this Schrodinger integrator expected");
  lua_pop(L, 1);
  dm_checkkeys(L, 3, run_keys, "run", "option", "method, dt, t, steps, every, start");
  int mi = pick(L, 3, "method", methods, "milne, cn or exact");
  int si = pick(L, 3, "start", starts, "exact or cn");
  double dt = dm_optnumberfield(L, 3, "dt", NAN);
  if (!isfinite(dt) || dt == 0.0)
    luaL_error(L, "run: dt must be a finite non-zero number (the time step)");
  int has_t = lua_getfield(L, 3, "t") != LUA_TNIL, has_n = lua_getfield(L, 3, "steps") != LUA_TNIL;
  lua_pop(L, 2);
  if (has_t == has_n)
    luaL_error(L, "run: give exactly one of steps = (a number of steps) or t = (the final time)");
  if (has_n) {
    lua_Integer k = dm_optintegerfield(L, 3, "steps", 0);
    if (k < 0)
      luaL_error(L, "run: steps must be >= 0");
    nsteps = (long)k;
  } else {
    double T = dm_optnumberfield(L, 3, "t", 0), x = T / dt;
    if (!isfinite(x) || x < -0.5 || x > 1e12)
      luaL_error(L, "run: the final time t = %f cannot be reached with dt = %f", T, dt);
    nsteps = lround(x);
  }
  lua_Integer every = dm_optintegerfield(L, 3, "every", 1);
  if (every < 1)
    luaL_error(L, "run: every must be >= 1");
  struct dm_traj **slot = dm_newtraj(L);                        /* 4 */
  if ((*slot = dm_schrod_traj_alloc(&e)) == NULL)
    return fail(L, "run", DM_ENOMEM, &e);
  lwave *w = pushwave(L, 1, N);                                  /* 5 */
  memcpy(w->c, w0->c, N * sizeof w->c[0]);
  if ((st = dm_schrod_stepper_alloc(u->S, mcode[mi], dt, &P, &e)) != DM_OK)
    return fail(L, "run", st, &e);
  st = dm_schrod_run(P, mcode[si], 0.0, w->c, nsteps, (long)every, *slot, &done, &e);
  dm_schrod_stepper_free(P);
  dm_traj_meta_set(*slot, "system", "Schrodinger (pseudospectral)", NULL);
  dm_traj_meta_set(*slot, "method", methods[mi], NULL);
  dm_traj_meta_set_number(*slot, "h", dt, NULL);
  dm_traj_meta_set_number(*slot, "K", (double)dm_schrod_K(u->S), NULL);
  dm_traj_meta_set_number(*slot, "steps", (double)done, NULL);
  dm_traj_meta_set_number(*slot, "status", st, NULL);
  if (st != DM_OK) {
    if (dm_traj_len(*slot) == 0)
      return fail(L, "run", st, &e);
    dm_traj_meta_set(*slot, "message", e.msg, NULL);
    lua_pushfstring(L, "run: %s", e.msg);
    return 3;
  }
  return 2;
}

static int s_index(lua_State *L)
{
  lschrod *u = checkschrod(L, 1);
  const char *k = luaL_checkstring(L, 2);
  if (luaL_getmetafield(L, 1, "__methods") != LUA_TNIL && lua_getfield(L, -1, k) != LUA_TNIL)
    return 1;
  if (strcmp(k, "K") == 0)
    lua_pushinteger(L, (lua_Integer)dm_schrod_K(u->S));
  else if (strcmp(k, "modes") == 0)
    lua_pushinteger(L, (lua_Integer)dm_schrod_modes(u->S));
  else if (strcmp(k, "hbar") == 0)
    lua_pushnumber(L, dm_schrod_hbar(u->S));
  else if (strcmp(k, "m") == 0)
    lua_pushnumber(L, dm_schrod_mass(u->S));
  else
    return luaL_error(L, "Schrodinger integrator has no field or method '%s' (fields: K, modes, "
                      "hbar, m)", k);
  return 1;
}

static int s_tostring(lua_State *L)
{
  lschrod *u = luaL_checkudata(L, 1, SCHROD_MT);
  if (u->S == NULL)
    lua_pushliteral(L, "<schrodinger (closed)>");
  else
    lua_pushfstring(L, "<schrodinger K=%d (%d modes) hbar=%f m=%f>", (int)dm_schrod_K(u->S),
                    (int)dm_schrod_modes(u->S), dm_schrod_hbar(u->S), dm_schrod_mass(u->S));
  return 1;
}

/* {==== waves ============================================================ */

/* w:diagnostics() -> {norm =, energy =, x =, p =} */
static int w_diagnostics(lua_State *L)
{
  lwave *w = checkwave(L, 1);
  dm_schrod *S = wave_owner(L, 1);
  dm_schrod_diag d;
  dm_schrod_diagnose(S, w->c, &d);
  lua_createtable(L, 0, 4);
  lua_pushnumber(L, d.norm);
  lua_setfield(L, -2, "norm");
  lua_pushnumber(L, d.energy);
  lua_setfield(L, -2, "energy");
  lua_pushnumber(L, d.x);
  lua_setfield(L, -2, "x");
  lua_pushnumber(L, d.p);
  lua_setfield(L, -2, "p");
  return 1;
}

/* w:density([M]) -> x, |psi|^2 (vecs on M points) */
static int w_density(lua_State *L)
{
  lwave *w = checkwave(L, 1);
  lua_Integer M = luaL_optinteger(L, 2, 512);
  lua_settop(L, 2);
  dm_schrod *S = wave_owner(L, 1);
  dm_err e;
  luaL_argcheck(L, M > (lua_Integer)(2 * dm_schrod_K(S)) && M <= (1 << 24), 2,
                "more points than 2K (and at most 2^24) expected");
  double complex *psi = lua_newuserdatauv(L, (size_t)M * sizeof *psi, 0);
  int st = dm_schrod_synthesise(S, w->c, (size_t)M, psi, &e);
  if (st != DM_OK)
    return fail(L, "density", st, &e);
  gsl_vector *x = dm_pushvec(L, (size_t)M), *r = dm_pushvec(L, (size_t)M);
  for (lua_Integer j = 0; j < M; j++) {
    gsl_vector_set(x, (size_t)j, 2.0 * M_PI * (double)j / (double)M);
    gsl_vector_set(r, (size_t)j, creal(psi[j]) * creal(psi[j]) + cimag(psi[j]) * cimag(psi[j]));
  }
  return 2;
}

/* w:coefficients() -> re, im (vecs, k = -K .. K) */
static int w_coefficients(lua_State *L)
{
  lwave *w = checkwave(L, 1);
  gsl_vector *re = dm_pushvec(L, w->N), *im = dm_pushvec(L, w->N);
  for (size_t j = 0; j < w->N; j++) {
    gsl_vector_set(re, j, creal(w->c[j]));
    gsl_vector_set(im, j, cimag(w->c[j]));
  }
  return 2;
}

static int w_tostring(lua_State *L)
{
  lwave *w = checkwave(L, 1);
  dm_schrod_diag d;
  dm_schrod_diagnose(wave_owner(L, 1), w->c, &d);
  lua_pushfstring(L, "<wave %d modes norm=%f energy=%f <x>=%f>", (int)w->N, d.norm, d.energy, d.x);
  return 1;
}

/* }====================================================================== */

static const dm_reg schrod_methods[] = {
  {"energies", s_energies, "S:energies() -> vec",
   "The eigenvalues of the Galerkin Hamiltonian, ascending (the time-independent problem)."},
  {"eigenstate", s_eigenstate, "S:eigenstate(n) -> wave, E",
   "The n-th eigenstate (0: the ground state) as a wave normalised to int |psi|^2 dx = 1, and "
   "its energy."},
  {"wave", s_wave, "S:wave(function(x) return re[, im] end[, samples]) -> wave",
   "A state from psi(x) on [0, 2 pi), sampled on `samples` points and projected on the modes "
   "k = -K..K by FFT."},
  {"run", s_run, "S:run(wave, {method = \"milne\", dt =, t = | steps =, every = 1, start = \"exact\"}) -> traj, wave",
   "Integrate: Milne-Simpson (the variational integrator, order 4, stable iff dt max|E|/hbar "
   "<= sqrt 3), cn (Crank-Nicolson, order 2, norm to round-off) or exact; the trajectory holds "
   "t, norm, energy, x = <x>, p = <p>; the second result is the final wave."},
  {NULL, NULL, NULL, NULL}
};

static const dm_reg wave_methods[] = {
  {"diagnostics", w_diagnostics, "w:diagnostics() -> {norm, energy, x, p}",
   "The norm int |psi|^2, the energy <H>, and the expectations <x>, <p> of the state."},
  {"density", w_density, "w:density([M]) -> x, rho",
   "The density |psi|^2 on M points of [0, 2 pi) (default 512), by FFT."},
  {"coefficients", w_coefficients, "w:coefficients() -> re, im",
   "The real and imaginary parts of the coefficients c_k, k = -K..K."},
  {NULL, NULL, NULL, NULL}
};

static const dm_field schrod_fields[] = {
  {"K", "S.K -> integer", "The modes are k = -K..K."},
  {"modes", "S.modes -> integer", "The number of modes, 2K + 1."},
  {"hbar", "S.hbar -> number", "Planck's constant of the equation."},
  {"m", "S.m -> number", "The mass."},
  {NULL, NULL, NULL}
};

static const luaL_Reg schrod_meta[] = {
  {"__gc", schrod_gc}, {"__close", schrod_gc}, {"__tostring", s_tostring},
  {"__index", s_index}, {NULL, NULL}
};
static const luaL_Reg wave_meta[] = {{"__tostring", w_tostring}, {NULL, NULL}};

static int l_msfem(lua_State *L);
static int l_fast_frequency(lua_State *L);

static const dm_reg field_funcs[] = {
  {"msfem", l_msfem,
   "dm.msfem{a = function(y) ... end, f = function(x) ... end, eps =, N =[, Phi =, method = \"multiscale\", tol =]} -> x, U",
   "Solve (a(x/eps) u')' = f on (0, 1), u(0) = u(1) = 0, with N multiscale finite elements "
   "(exact at the nodes; Phi(x) = int_0^x ds/a(s/eps) when known) or linear ones."},
  {"fast_frequency", l_fast_frequency, "dm.fast_frequency(sys, {q =, p =}) -> omega, coord",
   "The fast frequency at a state (the linearisation, refined by the FFT of a short resolved "
   "run) and the coordinate that carries it, for method = \"multiscale\"."},
  {"schrodinger", l_schrodinger,
   "dm.schrodinger{K = 16, hbar = 1, m = 1, V = function(x) ... end | number, samples =} -> S",
   "The pseudospectral variational integrator of i hbar psi_t = -(hbar^2/2m) psi_xx + V psi on "
   "the periodic [0, 2 pi): modes k = -K..K, V sampled on `samples` points (default: a power of "
   "2 >= 4096 and > 4K) and Fourier-transformed by FFTW."},
  {NULL, NULL, NULL, NULL}
};


/* {==== multiscale: dm.msfem, dm.fast_frequency ========================== */

/* A Lua function of one number called from C under lua_pcall; the first
 * failure's message is kept in stack slot `err`. */
typedef struct lfn1 {
  lua_State *L;
  int fn, err;
  const char *what;
} lfn1;

static int call_fn1(void *data, double x, double *y)
{
  lfn1 *c = data;
  lua_State *L = c->L;
  int isnum;
  if (c->fn == 0)
    return -1;
  lua_pushvalue(L, c->fn);
  lua_pushnumber(L, x);
  if (lua_pcall(L, 1, 1, 0) != LUA_OK) {
    if (lua_isnil(L, c->err))
      lua_replace(L, c->err);
    else
      lua_pop(L, 1);
    return -1;
  }
  *y = lua_tonumberx(L, -1, &isnum);
  if (!isnum) {
    if (lua_isnil(L, c->err)) {
      lua_pushfstring(L, "%s must return a number, got %s at %f", c->what, luaL_typename(L, -1), x);
      lua_replace(L, c->err);
    }
    lua_pop(L, 1);
    return -1;
  }
  lua_pop(L, 1);
  return 0;
}

static const char *const msfem_keys[] = {"a", "f", "eps", "N", "Phi", "method", "tol", NULL};

/* dm.msfem{a = function(y), f = function(x), eps =, N =[, Phi =, method =, tol =]} -> x, U */
static int l_msfem(lua_State *L)
{
  static const char *const methods[] = {"multiscale", "linear", NULL};
  dm_msfem_problem P;
  lfn1 ca, cf, cp;
  dm_err e;
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_settop(L, 1);
  dm_checkkeys(L, 1, msfem_keys, "dm.msfem", "field", "a, f, eps, N, Phi, method, tol");
  lua_Integer N = dm_optintegerfield(L, 1, "N", 0);
  double eps = dm_optnumberfield(L, 1, "eps", NAN), tol = dm_optnumberfield(L, 1, "tol", 0);
  int mi = 0;
  if (lua_getfield(L, 1, "method") != LUA_TNIL) {
    const char *m = lua_tostring(L, -1);
    for (; m && methods[mi] && strcmp(methods[mi], m) != 0; mi++)
      ;
    if (m == NULL || methods[mi] == NULL)
      luaL_error(L, "dm.msfem: method must be multiscale or linear, got %s", luaL_tolstring(L, -1, NULL));
  }
  lua_pop(L, 1);
  if (N < 3 || N > 1000000)
    luaL_error(L, "dm.msfem: N must be an integer in 3..1e6 (the elements), got %d", (int)N);
  lua_getfield(L, 1, "a");                                      /* 2 */
  lua_getfield(L, 1, "f");                                      /* 3 */
  lua_getfield(L, 1, "Phi");                                    /* 4 */
  if (!lua_isfunction(L, 2) || !lua_isfunction(L, 3))
    luaL_error(L, "dm.msfem: a (a function of y = x/eps) and f (a function of x) are required");
  if (!lua_isnil(L, 4) && !lua_isfunction(L, 4))
    luaL_error(L, "dm.msfem: Phi must be a function of x, got %s", luaL_typename(L, 4));
  lua_pushnil(L);                                               /* 5: the first error */
  ca = (lfn1){L, 2, 5, "a"};
  cf = (lfn1){L, 3, 5, "f"};
  cp = (lfn1){L, lua_isnil(L, 4) ? 0 : 4, 5, "Phi"};
  gsl_vector *x = dm_pushvec(L, (size_t)N + 1), *U = dm_pushvec(L, (size_t)N + 1);  /* 6, 7 */
  memset(&P, 0, sizeof P);
  P.a = call_fn1;
  P.f = call_fn1;
  P.Phi = cp.fn ? call_fn1 : NULL;
  P.adata = &ca;
  P.fdata = &cf;
  P.phidata = &cp;
  P.eps = eps;
  P.tol = tol;
  int st = dm_msfem1d(&P, (size_t)N, mi == 0 ? DM_MSFEM_MULTISCALE : DM_MSFEM_LINEAR, x->data,
                      U->data, &e);
  if (!lua_isnil(L, 5))
    return luaL_error(L, "dm.msfem: %s", lua_tostring(L, 5));
  if (st != DM_OK)
    return fail(L, "dm.msfem", st, &e);
  return 2;
}

/* dm.fast_frequency(sys, {q =, p =}) -> omega, coordinate */
static int l_fast_frequency(lua_State *L)
{
  dm_lsystem *ls = dm_lua_checksystem(L, 1);
  double w, *q, *p;
  size_t co;
  dm_err e;
  luaL_checktype(L, 2, LUA_TTABLE);
  lua_settop(L, 2);
  q = lua_newuserdatauv(L, 2 * ls->n * sizeof *q, 0);           /* 3 */
  p = q + ls->n;
  if (lua_getfield(L, 2, "q") == LUA_TNIL || lua_getfield(L, 2, "p") == LUA_TNIL)
    return luaL_error(L, "fast_frequency: the state needs q and p (momenta)");
  dm_lua_system_readvec(L, ls, 4, "fast_frequency: state.q", q);
  dm_lua_system_readvec(L, ls, 5, "fast_frequency: state.p", p);
  int st = dm_multiscale_frequency(&ls->sys, q, p, &w, &co, &e);
  if (st != DM_OK)
    return dm_lua_fail(L, "fast_frequency", st, &e);
  lua_pushnumber(L, w);
  lua_pushstring(L, ls->sys.coords ? ls->sys.coords[co] : "?");
  return 2;
}

/* }====================================================================== */

void dm_open_fields(lua_State *L)
{
  dm_newclass(L, SCHROD_MT, "schrodinger", schrod_methods, schrod_meta);
  /* methods first, then the fields (s_index) */
  lua_newtable(L);
  for (const dm_reg *r = schrod_methods; r->name != NULL; r++) {
    lua_pushcfunction(L, r->func);
    lua_setfield(L, -2, r->name);
  }
  lua_setfield(L, -2, "__methods");
  lua_pop(L, 1);
  dm_doc_fields(L, "schrodinger", schrod_fields);
  dm_newclass(L, WAVE_MT, "wave", wave_methods, wave_meta);
  lua_pop(L, 1);
  dm_register(L, "dm.", field_funcs);
  dm_doc_options(L, "dm.schrodinger", schrod_keys);
  dm_doc_options(L, "schrodinger:run", run_keys);
  dm_doc_options(L, "dm.msfem", msfem_keys);
}
