/* bench_scale.c -- how dmech's costs grow with the number of degrees of
 * freedom: the host of bench/scale.lua (the measurements and the tables),
 * with the hand-written C references it compares against:
 *
 *   bench.fpu_sv(q, p, h, n, beta)    FPU-beta chain with fixed ends
 *   bench.nbody_sv(q, p, h, n)        planar N-body, unit masses, G = 1,
 *                                     the O(N^2) pair loop (third law)
 *
 * both Stormer-Verlet (leapfrog, one force per step) with compensated q
 * and p updates -- the algorithm of the integrators' explicit path --
 * returning the thread CPU seconds, the final q and p; bench.now() (thread
 * CPU seconds), bench.wall() (monotonic seconds), bench.children() (CPU
 * seconds of the children waited for: the C compilers), bench.setenv(name, value),
 * bench.mkdtemp(), bench.machine().
 *
 * The same file builds against an older tree of dmech (its libdmlua) to
 * measure the "before" columns: the script uses only the API both have.
 *
 * usage: bench_scale script.lua [quick]   (DMECH_PATH: the Lua library) */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <lua.h>
#include <lauxlib.h>
#include <lualib.h>

int luaopen_dmech(lua_State *L);

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int b_now(lua_State *L)
{
  lua_pushnumber(L, now());
  return 1;
}

static int b_wall(lua_State *L)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  lua_pushnumber(L, (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec);
  return 1;
}

/* CPU seconds of the children waited for (the C compilers) */
static int b_children(lua_State *L)
{
  struct rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  lua_pushnumber(L, (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                    (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec);
  return 1;
}

static int b_setenv(lua_State *L)
{
  const char *k = luaL_checkstring(L, 1), *v = luaL_optstring(L, 2, NULL);
  if (v != NULL)
    setenv(k, v, 1);
  else
    unsetenv(k);
  return 0;
}

static int b_mkdtemp(lua_State *L)
{
  char t[] = "/tmp/dmech_scaleXXXXXX";
  if (mkdtemp(t) == NULL)
    return luaL_error(L, "mkdtemp failed");
  lua_pushstring(L, t);
  return 1;
}

static double *readvec(lua_State *L, int idx, int n)
{
  luaL_checktype(L, idx, LUA_TTABLE);
  double *x = malloc((size_t)n * sizeof *x);
  for (int i = 0; i < n; i++) {
    lua_rawgeti(L, idx, i + 1);
    x[i] = luaL_checknumber(L, -1);
    lua_pop(L, 1);
  }
  return x;
}

static void pushvec(lua_State *L, const double *x, int n)
{
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; i++) {
    lua_pushnumber(L, x[i]);
    lua_rawseti(L, -2, i + 1);
  }
}

/* {==================================================================
 * the forces
 * =================================================================== */

/* F = -dV/dq, V = sum over the N + 1 springs d = q_i - q_{i-1} (q_0 =
 * q_{N+1} = 0) of d^2/2 + beta d^4/4 */
static void fpu_force(const double *q, int n, double beta, double *f, void *work)
{
  (void)work;
  double prev = 0.0, fprev = 0.0;       /* V'(d) of the spring left of i */
  for (int i = 0; i < n; i++) {
    double d = q[i] - prev, g = d + beta * d * d * d;
    if (i > 0)
      f[i - 1] = fprev - g;
    fprev = g;
    prev = q[i];
  }
  double d = -prev, g = d + beta * d * d * d;
  f[n - 1] = fprev - g;
}

/* planar, bodies a = 0..nb-1 at (q[2a], q[2a+1]), unit masses: V = -sum 1/r */
static void nbody_force(const double *q, int n, double unused, double *f, void *work)
{
  (void)unused;
  (void)work;
  int nb = n / 2;
  memset(f, 0, (size_t)n * sizeof *f);
  for (int a = 0; a < nb; a++) {
    double xa = q[2 * a], ya = q[2 * a + 1], fx = 0.0, fy = 0.0;
    for (int b = a + 1; b < nb; b++) {
      double dx = q[2 * b] - xa, dy = q[2 * b + 1] - ya;
      double r2 = dx * dx + dy * dy, ir3 = 1.0 / (r2 * sqrt(r2));
      fx += dx * ir3;
      fy += dy * ir3;
      f[2 * b] -= dx * ir3;
      f[2 * b + 1] -= dy * ir3;
    }
    f[2 * a] += fx;
    f[2 * a + 1] += fy;
  }
}

typedef void (*force_fn)(const double *q, int n, double par, double *f, void *work);

/* leapfrog (kick-drift-kick with the force kept from the last step),
 * compensated sums in q and p; unit masses */
static double leapfrog(force_fn force, double par, double *q, double *p, int n, double h,
                       long nsteps)
{
  double *f0 = malloc((size_t)n * sizeof *f0), *f1 = malloc((size_t)n * sizeof *f1);
  double *cq = calloc((size_t)n, sizeof *cq), *cp = calloc((size_t)n, sizeof *cp);
  double t0 = now();
  force(q, n, par, f0, NULL);
  for (long k = 0; k < nsteps; k++) {
    for (int i = 0; i < n; i++) {
      double y = h * (p[i] + 0.5 * h * f0[i]) - cq[i], t = q[i] + y;
      cq[i] = (t - q[i]) - y;
      q[i] = t;
    }
    force(q, n, par, f1, NULL);
    for (int i = 0; i < n; i++) {
      double y = 0.5 * h * (f0[i] + f1[i]) - cp[i], t = p[i] + y;
      cp[i] = (t - p[i]) - y;
      p[i] = t;
    }
    double *s = f0;
    f0 = f1;
    f1 = s;
  }
  double t = now() - t0;
  free(f0);
  free(f1);
  free(cq);
  free(cp);
  return t;
}

static int run_hand(lua_State *L, force_fn force, double par)
{
  int n = (int)luaL_len(L, 1);
  double *q = readvec(L, 1, n), *p = readvec(L, 2, n);
  double h = luaL_checknumber(L, 3);
  long nsteps = (long)luaL_checkinteger(L, 4);
  double t = leapfrog(force, par, q, p, n, h, nsteps);
  lua_pushnumber(L, t);
  pushvec(L, q, n);
  pushvec(L, p, n);
  free(q);
  free(p);
  return 3;
}

static int b_fpu_sv(lua_State *L)
{
  return run_hand(L, fpu_force, luaL_checknumber(L, 5));
}

static int b_nbody_sv(lua_State *L)
{
  return run_hand(L, nbody_force, 0.0);
}

/* }================================================================== */

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
  lua_pushfstring(L, "%s, %d CPUs online, %s %s", model, (int)sysconf(_SC_NPROCESSORS_ONLN),
                  u.sysname, u.release);
  return 1;
}

int main(int argc, char **argv)
{
  if (argc < 2) {
    fprintf(stderr, "usage: bench_scale script.lua [args]\n");
    return 2;
  }
  lua_State *L = luaL_newstate();
  if (L == NULL)
    return 1;
  luaL_openlibs(L);
  luaL_requiref(L, "dmech", luaopen_dmech, 0);
  lua_setglobal(L, "dm");
  static const luaL_Reg fns[] = {
    {"now", b_now}, {"wall", b_wall}, {"children", b_children}, {"setenv", b_setenv},
    {"mkdtemp", b_mkdtemp},
    {"fpu_sv", b_fpu_sv}, {"nbody_sv", b_nbody_sv}, {"machine", b_machine}, {NULL, NULL}
  };
  luaL_newlib(L, fns);
  lua_setglobal(L, "bench");
  lua_createtable(L, argc, 0);
  for (int i = 2; i < argc; i++) {
    lua_pushstring(L, argv[i]);
    lua_rawseti(L, -2, i - 1);
  }
  lua_setglobal(L, "arg");
  int st = luaL_dofile(L, argv[1]);
  if (st != LUA_OK)
    fprintf(stderr, "bench_scale: %s\n", lua_tostring(L, -1));
  lua_close(L);
  return st == LUA_OK ? 0 : 1;
}
