/* bench_mech.c -- per-step cost of dmech's discrete mechanics, as a user
 * runs it (dm.system traced from Lua, dm.integrator, integ:run), against
 * hand-written C loops of the same algorithms, side by side in one process:
 *
 *  1. J2 satellite, Cartesian, Gauss s=2, h = 0.05: traced L on the tape,
 *     traced L as native code, the built-in C J2 system with the same
 *     integrator, and a hand-written Gauss-2 loop (below) with its own
 *     Newton: stage velocities as unknowns, exact Jacobian, simplified
 *     Newton (refresh when the update contracts less than tenfold), the
 *     predictor extrapolating the previous step's stage polynomial, the
 *     round-off stopping rule, Kahan-compensated q and p updates.
 *  2. Kepler e = 0.6, Stormer-Verlet h = 0.01: traced (native and tape), the
 *     built-in C Kepler, and a hand-written leapfrog (one force per step,
 *     compensated sums) -- the same algorithm as the integrator's explicit
 *     path.
 *
 * Each variant runs `reps` times, the repetitions interleaved across the
 * variants (after one warm-up round), timed in thread CPU time; the median
 * ns/step is printed with steps/s and the ratio to the hand-written loop,
 * plus the distance between final states (the loops compute the same
 * numbers up to round-off).  Targets:
 * traced native <= 1.3x hand-written, tape <= 4x.
 *
 * usage: bench_mech [reps]   (DMECH_PATH must point at the Lua library) */
#include <config.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <lua.h>
#include <lauxlib.h>
#include <lualib.h>

#include "lua/dmlua.h"
#include "core/builtin_systems.h"
#include "integrators/integrator.h"

/* CPU time of this thread: the machine may be shared, and time spent
 * descheduled is not the code's cost. */
static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* {==================================================================
 * hand-written J2: F = dL/dq = -grad V and H = dF/dq, with
 * V = -1/R + J2 (1.5 z^2 / R^5 - 0.5 / R^3)
 * =================================================================== */

static void j2_force(const double *q, double J2, double *F, double *H)
{
  const double x = q[0], y = q[1], z = q[2];
  const double r2 = x * x + y * y + z * z, iR = 1.0 / sqrt(r2);
  const double a = iR / r2, b = a / r2, c = b / r2, d = c / r2;   /* R^-3, -5, -7, -9 */
  const double z2 = z * z;
  const double g = a + J2 * (1.5 * b - 7.5 * z2 * c);
  F[0] = -x * g;
  F[1] = -y * g;
  F[2] = -z * g - 3.0 * J2 * z * b;
  if (H == NULL)
    return;
  const double hh = -3.0 * b - 7.5 * J2 * c + 52.5 * J2 * z2 * d;
  const double t = -15.0 * J2 * z * c;
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      double v = (i == j ? g : 0.0) + q[i] * q[j] * hh;
      if (j == 2)
        v += t * q[i] + (i == 2 ? t * q[j] + 3.0 * J2 * b : 0.0);
      H[i * 3 + j] = H[j * 3 + i] = -v;
    }
}

/* 6x6 LU with partial pivoting in place; 0 when singular. */
static int lu6(double *A, int *perm)
{
  for (int k = 0; k < 6; k++) {
    int p = k;
    for (int i = k + 1; i < 6; i++)
      if (fabs(A[i * 6 + k]) > fabs(A[p * 6 + k]))
        p = i;
    if (A[p * 6 + k] == 0.0)
      return 0;
    perm[k] = p;
    if (p != k)
      for (int j = 0; j < 6; j++) {
        double t = A[k * 6 + j];
        A[k * 6 + j] = A[p * 6 + j];
        A[p * 6 + j] = t;
      }
    for (int i = k + 1; i < 6; i++) {
      double l = A[i * 6 + k] /= A[k * 6 + k];
      for (int j = k + 1; j < 6; j++)
        A[i * 6 + j] -= l * A[k * 6 + j];
    }
  }
  return 1;
}

static void lu6_solve(const double *A, const int *perm, double *b)
{
  for (int k = 0; k < 6; k++) {
    double t = b[perm[k]];
    b[perm[k]] = b[k];
    b[k] = t;
  }
  for (int i = 1; i < 6; i++)
    for (int j = 0; j < i; j++)
      b[i] -= A[i * 6 + j] * b[j];
  for (int i = 5; i >= 0; i--) {
    for (int j = i + 1; j < 6; j++)
      b[i] -= A[i * 6 + j] * b[j];
    b[i] /= A[i * 6 + i];
  }
}

static double maxabs(const double *x, int n)
{
  double m = 0.0;
  for (int i = 0; i < n; i++)
    m = fmax(m, fabs(x[i]));
  return m;
}

/* n Gauss-2 steps of h on (q, p) in place; returns Newton iterations. */
static long hand_gauss2(double *q, double *p, double h, long nsteps, double J2)
{
  const double s3 = sqrt(3.0);
  const double A[2][2] = {{0.25, 0.25 - s3 / 6}, {0.25 + s3 / 6, 0.25}}, b[2] = {0.5, 0.5};
  const double c[2] = {0.5 - s3 / 6, 0.5 + s3 / 6};
  double E[2][2], X[6], Vp[6], Q[6], F[6], H[18], R[6], J[36], cq[3] = {0}, cp[3] = {0};
  int perm[6], hist = 0;
  long iters = 0;
  /* predictor: the previous stage polynomial at the new stage times */
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++)
      E[i][j] = (1.0 + c[i] - c[1 - j]) / (c[j] - c[1 - j]);
  for (long k = 0; k < nsteps; k++) {
    double d = HUGE_VAL, dlast = HUGE_VAL, dbest = HUGE_VAL;
    int jac = 1, stall = 0;
    for (int i = 0; i < 2; i++)
      for (int a = 0; a < 3; a++)
        X[i * 3 + a] = hist ? E[i][0] * Vp[a] + E[i][1] * Vp[3 + a] : p[a];
    for (int it = 1; it <= 50; it++) {
      iters++;
      for (int i = 0; i < 2; i++)
        for (int a = 0; a < 3; a++)
          Q[i * 3 + a] = q[a] + h * (A[i][0] * X[a] + A[i][1] * X[3 + a]);
      j2_force(Q, J2, F, jac ? H : NULL);
      j2_force(Q + 3, J2, F + 3, jac ? H + 9 : NULL);
      for (int i = 0; i < 2; i++)
        for (int a = 0; a < 3; a++)
          R[i * 3 + a] = X[i * 3 + a] - p[a] - h * (A[i][0] * F[a] + A[i][1] * F[3 + a]);
      if (jac) {
        for (int i = 0; i < 2; i++)
          for (int kk = 0; kk < 2; kk++)
            for (int a = 0; a < 3; a++)
              for (int e = 0; e < 3; e++)
                J[(i * 3 + a) * 6 + kk * 3 + e] = (i == kk && a == e ? 1.0 : 0.0)
                  - h * h * (A[i][0] * A[0][kk] * H[a * 3 + e] + A[i][1] * A[1][kk] * H[9 + a * 3 + e]);
        if (!lu6(J, perm))
          return -1;
      }
      lu6_solve(J, perm, R);
      for (int i = 0; i < 6; i++)
        X[i] -= R[i];
      d = maxabs(R, 6) / fmax(maxabs(X, 6), maxabs(p, 3) + fabs(h) * maxabs(F, 6));
      if (d <= 10 * DBL_EPSILON)
        break;
      if (d <= 1e-10 && d > 0.5 * dbest && ++stall >= 2)
        break;
      dbest = fmin(dbest, d);
      jac = d > 0.1 * dlast;
      dlast = d;
    }
    if (d > 1e-12) {
      for (int i = 0; i < 2; i++)
        for (int a = 0; a < 3; a++)
          Q[i * 3 + a] = q[a] + h * (A[i][0] * X[a] + A[i][1] * X[3 + a]);
      j2_force(Q, J2, F, NULL);
      j2_force(Q + 3, J2, F + 3, NULL);
    }
    for (int a = 0; a < 3; a++) {
      double y = h * (b[0] * X[a] + b[1] * X[3 + a]) - cq[a], t = q[a] + y;
      cq[a] = (t - q[a]) - y;
      q[a] = t;
      y = h * (b[0] * F[a] + b[1] * F[3 + a]) - cp[a];
      t = p[a] + y;
      cp[a] = (t - p[a]) - y;
      p[a] = t;
    }
    memcpy(Vp, X, sizeof Vp);
    hist = 1;
  }
  return iters;
}

/* }================================================================== */

/* {==================================================================
 * hand-written Stormer-Verlet for Kepler, L = |v|^2/2 + 1/|q|
 * =================================================================== */

static inline void kepler_force(const double *q, double *f)
{
  double r2 = q[0] * q[0] + q[1] * q[1], ir3 = 1.0 / (r2 * sqrt(r2));
  f[0] = -q[0] * ir3;
  f[1] = -q[1] * ir3;
}

static void hand_leapfrog(double *q, double *p, double h, long nsteps)
{
  double f0[2], f1[2], cq[2] = {0, 0}, cp[2] = {0, 0};
  kepler_force(q, f0);
  for (long k = 0; k < nsteps; k++) {
    double q1[2];
    for (int i = 0; i < 2; i++) {
      double y = h * (p[i] + 0.5 * h * f0[i]) - cq[i], t = q[i] + y;
      cq[i] = (t - q[i]) - y;
      q1[i] = t;
    }
    kepler_force(q1, f1);
    for (int i = 0; i < 2; i++) {
      double y = 0.5 * h * (f0[i] + f1[i]) - cp[i], t = p[i] + y;
      cp[i] = (t - p[i]) - y;
      p[i] = t;
      q[i] = q1[i];
      f0[i] = f1[i];
    }
  }
}

/* }================================================================== */

/* {==================================================================
 * Lua glue: bench.now(), bench.gauss2_j2(q, p, h, n, J2), bench.leapfrog(q, p, h, n)
 * (both return seconds, final q, final p as tables)
 * =================================================================== */

static void read3(lua_State *L, int idx, double *x, int n)
{
  luaL_checktype(L, idx, LUA_TTABLE);
  for (int i = 0; i < n; i++) {
    lua_rawgeti(L, idx, i + 1);
    x[i] = luaL_checknumber(L, -1);
    lua_pop(L, 1);
  }
}

static void push3(lua_State *L, const double *x, int n)
{
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; i++) {
    lua_pushnumber(L, x[i]);
    lua_rawseti(L, -2, i + 1);
  }
}

static int b_now(lua_State *L)
{
  lua_pushnumber(L, now());
  return 1;
}

static int b_gauss2(lua_State *L)
{
  double q[3], p[3], h = luaL_checknumber(L, 3), J2 = luaL_checknumber(L, 5), t0;
  long n = (long)luaL_checkinteger(L, 4), it;
  read3(L, 1, q, 3);
  read3(L, 2, p, 3);
  t0 = now();
  it = hand_gauss2(q, p, h, n, J2);
  lua_pushnumber(L, now() - t0);
  push3(L, q, 3);
  push3(L, p, 3);
  lua_pushinteger(L, it);
  return 4;
}

static int b_leapfrog(lua_State *L)
{
  double q[2], p[2], h = luaL_checknumber(L, 3), t0;
  long n = (long)luaL_checkinteger(L, 4);
  read3(L, 1, q, 2);
  read3(L, 2, p, 2);
  t0 = now();
  hand_leapfrog(q, p, h, n);
  lua_pushnumber(L, now() - t0);
  push3(L, q, 2);
  push3(L, p, 2);
  return 3;
}

/* bench.capi(system, method, stages, h, q, p, n): the built-in C system
 * through dm_integrator_run directly (no Lua, no trajectory): what the
 * integrator itself costs.  system: "j2" or "kepler". */
static int b_capi(lua_State *L)
{
  const char *which = luaL_checkstring(L, 1), *method = luaL_checkstring(L, 2);
  int stages = (int)luaL_checkinteger(L, 3), n = strcmp(which, "j2") == 0 ? 3 : 2;
  double h = luaL_checknumber(L, 4), q[3], p[3], t0, t;
  long nsteps = (long)luaL_checkinteger(L, 7);
  dm_system sys;
  dm_integ_opts o;
  dm_integrator *I = NULL;
  int st;
  read3(L, 5, q, n);
  read3(L, 6, p, n);
  st = n == 3 ? dm_builtin_j2(&sys, 0.05, NULL) : dm_builtin_kepler(&sys, 2, 1.0, NULL);
  if (st != DM_OK)
    return luaL_error(L, "cannot build the system");
  dm_integ_opts_init(&o);
  o.stages = stages;
  if (dm_integrator_new(&sys, method, &o, &I, NULL) != DM_OK) {
    dm_system_release(&sys);
    return luaL_error(L, "cannot build the integrator");
  }
  t0 = now();
  st = dm_integrator_run(I, 0.0, q, p, h, nsteps, nsteps, NULL, NULL, NULL, NULL);
  t = now() - t0;
  dm_integrator_free(I);
  dm_system_release(&sys);
  if (st != DM_OK)
    return luaL_error(L, "run failed");
  lua_pushnumber(L, t);
  push3(L, q, n);
  push3(L, p, n);
  return 3;
}

static int b_machine(lua_State *L)
{
  char model[512] = "unknown CPU", line[512];
  FILE *f = fopen("/proc/cpuinfo", "r");
  struct utsname u;
  while (f && fgets(line, sizeof line, f))
    if (strncmp(line, "model name", 10) == 0) {
      char *c = strchr(line, ':');
      snprintf(model, sizeof model, "%s", c ? c + 2 : line);
      model[strcspn(model, "\n")] = '\0';
      break;
    }
  if (f)
    fclose(f);
  uname(&u);
  lua_pushfstring(L, "%s, %d CPUs online, %s %s, compiler %s", model,
                  (int)sysconf(_SC_NPROCESSORS_ONLN), u.sysname, u.release,
#ifdef __VERSION__
                  __VERSION__
#else
                  "?"
#endif
  );
  return 1;
}

/* }================================================================== */

static const char script[] =
  "local dm, B, reps = require 'dmech', bench, bench.reps\n"
  "local function median(t) table.sort(t); return t[(#t + 1) // 2] end\n"
  "local function dist(a, b) local d = 0; for i = 1, #a do d = math.max(d, math.abs(a[i] - b[i])) end; return d end\n"
  "local function final(tr, sys) local q, p = {}, {}\n"
  "  for i, c in ipairs(sys.coords) do q[i], p[i] = tr:column(c)[#tr], tr:column('p_' .. c)[#tr] end\n"
  "  return q, p end\n"
  "-- a variant is a function running n steps and returning seconds, final q, final p\n"
  "local function user(sys, opts, s, n)   -- the user's path: integ:run, one sample at the end\n"
  "  local I = dm.integrator(sys, opts)\n"
  "  local o = {steps = n, every = n, energy = false, momentum = false, progress = false}\n"
  "  return function()\n"
  "    local t0 = B.now(); local tr = I:run(s, o); local t = B.now() - t0\n"
  "    local q, p = final(tr, sys); return t, q, p\n"
  "  end, I\n"
  "end\n"
  "-- repetitions interleaved across the variants, so that a busy machine\n"
  "-- disturbs them alike; the first round is a warm-up\n"
  "local function measure(variants, n)\n"
  "  local ts = {}\n"
  "  for r = 0, reps do\n"
  "    for i, v in ipairs(variants) do\n"
  "      local t, q, p = v.f()\n"
  "      v.q, v.p = q, p\n"
  "      if r > 0 then ts[i] = ts[i] or {}; ts[i][r] = t / n * 1e9 end\n"
  "    end\n"
  "  end\n"
  "  local ref = median(ts[1])\n"
  "  for i, v in ipairs(variants) do\n"
  "    local ns = median(ts[i]); local ratio = ns / ref\n"
  "    local d = i > 1 and ('|final state - hand| = %.1e'):format(math.max(dist(v.q, variants[1].q), dist(v.p, variants[1].p))) or ''\n"
  "    print(('  %-42s %9.1f %12.4g %8.2f%s   %s'):format(v.name, ns, 1e9 / ns, ratio,\n"
  "      v.target and ((ratio <= v.target and ' ok  ' or ' MISS') .. (' (<= %g)'):format(v.target)) or '            ', d))\n"
  "  end\n"
  "end\n"
  "local function header(title)\n"
  "  print(title)\n"
  "  print(('  %-42s %9s %12s %8s'):format('variant', 'ns/step', 'steps/s', 'ratio'))\n"
  "end\n"
  "print('machine: ' .. B.machine())\n"
  "print(('thread CPU time, median of %d interleaved runs each; the ratio is to the hand-written C loop'):format(reps))\n"
  "print()\n"
  "local function j2sys(native)\n"
  "  return dm.system{name = 'J2', coords = {'x', 'y', 'z'}, params = {J2 = 0.05}, native = native,\n"
  "    L = function(q, v, p)\n"
  "      local R = dm.sqrt(q.x^2 + q.y^2 + q.z^2)\n"
  "      local V = -1 / R + p.J2 / R^3 * (1.5 * q.z^2 / R^2 - 0.5)\n"
  "      return 0.5 * (v.x^2 + v.y^2 + v.z^2) - V\n"
  "    end}\n"
  "end\n"
  "local N = 100000\n"
  "local s = {q = {2, 0, 0.3}, p = {0, 0.6, 0.1}}\n"
  "local g2 = {method = 'gauss', stages = 2, h = 0.05}\n"
  "header(('J2 satellite (Cartesian), Gauss s=2, h = 0.05, %d steps'):format(N))\n"
  "local fb, bI = user(dm.systems.j2{J2 = 0.05, impl = 'c'}, g2, s, N)\n"
  "measure({\n"
  "  {name = 'hand-written C Gauss-2 loop', f = function() return B.gauss2_j2(s.q, s.p, 0.05, N, 0.05) end},\n"
  "  {name = 'C API: built-in J2, dm_integrator_run', f = function() return B.capi('j2', 'gauss', 2, 0.05, s.q, s.p, N) end},\n"
  "  {name = 'dmech, built-in C J2 system', f = fb},\n"
  "  {name = 'dmech, traced L, native code', f = user(j2sys('always'), g2, s, N), target = 1.3},\n"
  "  {name = 'dmech, traced L, tape', f = user(j2sys(false), g2, s, N), target = 4},\n"
  "}, N)\n"
  "print(('  Newton iterations per step: hand %.2f, dmech %.2f'):format(select(4, B.gauss2_j2(s.q, s.p, 0.05, N, 0.05)) / N,\n"
  "  bI.stats.iters_total / bI.stats.steps))\n"
  "print()\n"
  "local M = 10000000\n"
  "local k = {q = {0.4, 0}, p = {0, 2}}\n"
  "local sv = {method = 'trapezoid', h = 0.01}\n"
  "local function kep(native)\n"
  "  return dm.system{name = 'Kepler', coords = {'x', 'y'}, native = native,\n"
  "    L = function(q, v) return 0.5 * (v.x^2 + v.y^2) + 1 / dm.sqrt(q.x^2 + q.y^2) end}\n"
  "end\n"
  "header(('Kepler e = 0.6, Stormer-Verlet, h = 0.01, %d steps'):format(M))\n"
  "measure({\n"
  "  {name = 'hand-written C leapfrog', f = function() return B.leapfrog(k.q, k.p, 0.01, M) end},\n"
  "  {name = 'C API: built-in Kepler, dm_integrator_run', f = function() return B.capi('kepler', 'trapezoid', 0, 0.01, k.q, k.p, M) end},\n"
  "  {name = 'dmech, built-in C Kepler system', f = user(dm.systems.kepler{impl = 'c'}, sv, k, M)},\n"
  "  {name = 'dmech, traced L, native code', f = user(kep('always'), sv, k, M), target = 1.3},\n"
  "  {name = 'dmech, traced L, tape', f = user(kep(false), sv, k, M), target = 4},\n"
  "}, M)\n";

int main(int argc, char **argv)
{
  lua_State *L = luaL_newstate();
  int reps = argc > 1 ? atoi(argv[1]) : 7, st;
  if (L == NULL)
    return 1;
  luaL_openlibs(L);
  luaL_requiref(L, "dmech", luaopen_dmech, 0);
  lua_pop(L, 1);
  lua_newtable(L);
  lua_pushcfunction(L, b_now);
  lua_setfield(L, -2, "now");
  lua_pushcfunction(L, b_gauss2);
  lua_setfield(L, -2, "gauss2_j2");
  lua_pushcfunction(L, b_leapfrog);
  lua_setfield(L, -2, "leapfrog");
  lua_pushcfunction(L, b_capi);
  lua_setfield(L, -2, "capi");
  lua_pushcfunction(L, b_machine);
  lua_setfield(L, -2, "machine");
  lua_pushinteger(L, reps > 0 ? reps : 7);
  lua_setfield(L, -2, "reps");
  lua_setglobal(L, "bench");
  st = luaL_loadbuffer(L, script, sizeof script - 1, "=bench_mech") || lua_pcall(L, 0, 0, 0);
  if (st != LUA_OK)
    fprintf(stderr, "bench_mech: %s\n", lua_tostring(L, -1));
  lua_close(L);
  return st == LUA_OK ? 0 : 1;
}
