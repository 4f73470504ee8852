/* native.c -- emit C for a tape, compile it with the system compiler, load
 * it, check it against the tape, cache the object.  See native.h. */
#include <config.h>
#include "core/numfmt.h"
#include "core/cleanup.h"
#include "expr/native_impl.h"

#include <dlfcn.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define ID_SYMBOL "dm_native_id"

struct dm_native {
  void *dl;
  dm_native_fn fn;
  dm_native_scatter_fn scatter;         /* NULL unless compiled mapped */
  const dm_native_map *inmap, *outmap;  /* during compilation only */
  size_t nmap;
  int cached;
  int fd;                 /* open while dl was loaded through /proc/self/fd/<fd>, else -1 */
  char key[65];
};

void dm_native_free(dm_native *nat)
{
  if (nat == NULL)
    return;
  if (nat->dl != NULL)
    dlclose(nat->dl);
  if (nat->fd >= 0)
    close(nat->fd);
  free(nat);
}

dm_native_fn dm_native_function(const dm_native *nat) { return nat->fn; }
dm_native_scatter_fn dm_native_scatter(const dm_native *nat) { return nat->scatter; }
int dm_native_cached(const dm_native *nat) { return nat->cached; }
const char *dm_native_key(const dm_native *nat) { return nat->key; }

const char *dm_native_mode_name(int mode)
{
  switch (mode) {
  case DM_NATIVE_NEVER: return "never";
  case DM_NATIVE_AUTO: return "auto";
  case DM_NATIVE_ALWAYS: return "always";
  case DM_NATIVE_WAIT: return "wait";
  default: return "?";
  }
}

int dm_native_mode_parse(const char *name)
{
  for (int m = DM_NATIVE_NEVER; m <= DM_NATIVE_WAIT; m++)
    if (name != NULL && strcmp(name, dm_native_mode_name(m)) == 0)
      return m;
  return -1;
}

/* {==================================================================
 * emitting C (native_emit.c): sizes
 * =================================================================== */

/* Up to this many instructions a tape is one function (the compiler
 * allocates registers over all of it); above, chunks of CHUNK
 * instructions, CHUNKS_PER_UNIT per translation unit, compiled in
 * parallel.  Measured on the gradient and Hessian bundles of an FPU chain
 * of 1024 masses (52000 instructions in four bundles; gcc 12, CPU seconds
 * of the compilers, ns per coordinate of the compiled gradient): chunks of
 * 250 / 500 / 1500 instructions: 4.4 / 5.2 / 6.7 s, 1.4 / 1.3 / 1.3 ns;
 * one function per bundle: 35 s of cc1 for 7165 instructions of
 * (unordered) code alone.  -O0 compiles 1.2x faster but runs 4.6x slower,
 * as slow as the tape: never chosen. */
#define ONE_FUNCTION 2000
#define CHUNK 500
#define CHUNKS_PER_UNIT 8

static int emit_units(const dm_tape *t, const dm_native_map *inmap, size_t nmap,
                      const dm_native_map *outmap, dm_native_srcs *srcs)
{
  size_t ni = dm_tape_ninstr(t);
  if (ni <= ONE_FUNCTION)
    return dm_native__emit(t, inmap, nmap, outmap, ni ? ni : 1, 1, srcs);
  return dm_native__emit(t, inmap, nmap, outmap, CHUNK, CHUNKS_PER_UNIT, srcs);
}

/* The units one after the other (the cache key, dm_native_source). */
static char *joined(const dm_native_srcs *s)
{
  size_t len = 1;
  for (size_t u = 0; u < s->n; u++)
    len += strlen(s->src[u]) + 32;
  char *j = malloc(len), *p = j;
  if (j == NULL)
    return NULL;
  for (size_t u = 0; u < s->n; u++)
    p += sprintf(p, "/* unit %zu */\n%s", u, s->src[u]);
  *p = '\0';
  return j;
}

char *dm_native_source(const dm_tape *t)
{
  dm_native_srcs s;
  if (emit_units(t, NULL, 0, NULL, &s) != DM_OK)
    return NULL;
  char *j = joined(&s);
  dm_native__srcs_free(&s);
  return j;
}

/* {==================================================================
 * loading and checking
 * =================================================================== */

static double urand(uint64_t *s)
{
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 9007199254740992.0;
}

static int agree(double a, double b)
{
  if (a == b || (isnan(a) && isnan(b)))
    return 1;
  return fabs(a - b) <= 1e-15 * fmax(fabs(a), fabs(b));
}

/* The scatter function at (in, par) against the tape's outputs o: the
 * same NaN/Inf report, every destination holding its output (to the last
 * bit in practice, 1e-15 relative at most), and with one array left out
 * of the mask that array untouched and the others still written. */
static int check_scatter(const dm_tape *t, const dm_native *nat,
                         const double *in, const double *par, const double *o)
{
  size_t nin = dm_tape_nin(t), nout = dm_tape_nout(t), nmap = nat->nmap;
  enum { MAXARR = 32 };
  size_t isz[MAXARR] = { 0 }, osz[MAXARR] = { 0 }, total = 0, ototal = 0;
  for (size_t i = 0; i < nin; i++)
    if (nat->inmap[i].elem + 1 > isz[nat->inmap[i].arr])
      isz[nat->inmap[i].arr] = nat->inmap[i].elem + 1;
  for (size_t j = 0; j < nmap; j++)
    if (nat->outmap[j].elem + 1 > osz[nat->outmap[j].arr])
      osz[nat->outmap[j].arr] = nat->outmap[j].elem + 1;
  for (int a = 0; a < MAXARR; a++) {
    total += isz[a] + osz[a];
    ototal += osz[a];
  }
  double *buf = malloc((total + ototal + 1) * sizeof *buf), *p = buf;
  const double *ins[MAXARR];
  double *outs[MAXARR], *work = buf + total;
  if (buf == NULL)
    return -1;
  for (int a = 0; a < MAXARR; a++) {
    ins[a] = p;
    p += isz[a];
    outs[a] = p;
    p += osz[a];
  }
  for (size_t i = 0; i < nin; i++)
    ((double *)ins[nat->inmap[i].arr])[nat->inmap[i].elem] = in[i];
  int bad = 0, ok = 1;
  for (size_t k = 0; k < nout; k++)
    bad |= !(fabs(o[k]) <= DBL_MAX);
  int last = -1;
  for (int a = 0; a < MAXARR; a++)
    if (osz[a])
      last = a;
  for (int pass = 0; pass < 2 && ok; pass++) {
    unsigned mask = pass == 0 ? ~0u : ~(1u << (last < 0 ? 0 : last));
    for (int a = 0; a < MAXARR; a++)
      for (size_t e = 0; e < osz[a]; e++)
        outs[a][e] = -12345.678;            /* unwritten marker */
    int r = nat->scatter(ins, par, outs, mask, work);
    ok = (r != 0) == bad;
    for (size_t j = 0; ok && !bad && j < nmap; j++) {
      const dm_native_map *m = &nat->outmap[j];
      double got = outs[m->arr][m->elem];
      if (pass == 1 && (int)m->arr == last)
        ok = got == -12345.678;
      else
        ok = agree(got, o[m->k]);
    }
  }
  free(buf);
  return ok ? 0 : -1;
}

/* The native code against the tape at 16 points: near (in0, par0) when
 * given, and uniformly random in [-2, 2]. */
static int verify(const dm_tape *t, const dm_native *nat, const double *in0,
                  const double *par0, dm_err *err)
{
  size_t nin = dm_tape_nin(t), npar = dm_tape_npar(t), nout = dm_tape_nout(t);
  size_t nw = dm_tape_work_size(t);
  double *buf = malloc((nin + npar + 2 * nout + nw + 1) * sizeof *buf);
  if (buf == NULL)
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  double *in = buf, *par = in + nin, *o1 = par + npar, *o2 = o1 + nout;
  double *w = o2 + nout;
  uint64_t seed = 0x9e3779b97f4a7c15ULL;
  int status = DM_OK;
  for (int rep = 0; rep < 16 && status == DM_OK; rep++) {
    int near = rep % 2 == 0;
    for (size_t i = 0; i < nin; i++)
      in[i] = near && in0 ? in0[i] * (1 + 0.05 * (urand(&seed) - 0.5)) +
                            1e-3 * (urand(&seed) - 0.5)
                          : 4 * urand(&seed) - 2;
    for (size_t i = 0; i < npar; i++)
      par[i] = par0 ? par0[i] * (rep < 2 ? 1 : 1 + 0.05 * (urand(&seed) - 0.5))
                    : 4 * urand(&seed) - 2;
    dm_tape_eval(t, in, par, o1, w);
    if (nat->fn != NULL) {
      nat->fn(in, par, o2);
      for (size_t k = 0; k < nout; k++)
        if (!agree(o1[k], o2[k])) {
          status = dm_err_set(err, DM_EFAILED, "native: compiled code gives "
                              "%.17g for output %zu where the tape gives %.17g",
                              o2[k], k + 1, o1[k]);
          break;
        }
    }
    if (status == DM_OK && nat->scatter && check_scatter(t, nat, in, par, o1) != 0)
      status = dm_err_set(err, DM_EFAILED, "native: the compiled code disagrees "
                          "with the tape");
  }
  free(buf);
  return status;
}

/* dlopen path and check that it is the object with this key. */
static int load(const char *path, const char *key, dm_native *nat, dm_err *err)
{
  void *dl = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (dl == NULL)
    return dm_err_set(err, DM_EIO, "native: dlopen: %s", dlerror());
  const char *id = dlsym(dl, ID_SYMBOL);
  void *fn = dlsym(dl, nat->inmap ? "dm_native_scatter" : "dm_native_eval");
  if (id == NULL || fn == NULL || strcmp(id, key) != 0) {
    dlclose(dl);
    return dm_err_set(err, DM_EIO, "native: %s is not the expected object", path);
  }
  nat->dl = dl;
  if (nat->inmap)
    memcpy(&nat->scatter, &fn, sizeof fn);  /* object to function pointer */
  else
    memcpy(&nat->fn, &fn, sizeof fn);
  return DM_OK;
}

/* Parallel compilers: the processors online, at most 4. */
static int parallelism(void)
{
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n < 1 ? 1 : n > 4 ? 4 : (int)n;
}

static int compile_native(const dm_tape *t, const double *in0,
                          const double *par0, dm_native *nat, dm_native_srcs *srcs,
                          const dm_native_env *env, dm_err *err)
{
  const char *cc = env ? env->cc : getenv("CC");
  char cccopy[1024], *ccargv[32];
  snprintf(cccopy, sizeof cccopy, "%s", cc && *cc ? cc : "cc");
  int ncc = dm_native__cc_words(cccopy, ccargv, 30);
  if (ncc == 0)
    return dm_err_set(err, DM_ENOTFOUND, "native: $CC is blank");
  const char *opt = "-O1";
  char *all = joined(srcs);
  if (all == NULL)
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  size_t alen = strlen(all);
  char *keysrc = realloc(all, alen + 128);
  if (keysrc == NULL) {
    free(all);
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  }
  snprintf(keysrc + alen, 128, "/* " CC_UNIT_FLAGS " %s; " CC_LINK_FLAGS " */\n", opt);
  int s = dm_native__make_key(ccargv, ncc, keysrc, nat->key, err);
  free(keysrc);
  if (s != DM_OK)
    return s;

  char cdir[4096], cached[4200];
  int have_cache = dm_native__cache_dir(cdir, sizeof cdir) == 0;
  if (have_cache) {
    snprintf(cached, sizeof cached, "%s/%s.so", cdir, nat->key);
    /* loaded only when its content matches the digest recorded when it
     * was stored: a damaged object is never executed */
    char lpath[4200];
    int cfd = dm_native__cache_open(cached, lpath, sizeof lpath);
    /* the descriptor stays open while the object is loaded: the dynamic
     * loader knows an object by the name it was opened with, and a second
     * object opened as /proc/self/fd/<the same number> would be taken for
     * the first one */
    if (cfd >= 0 && load(lpath, nat->key, nat, NULL) == DM_OK) {
      nat->fd = cfd;
      if (verify(t, nat, in0, par0, NULL) == DM_OK) {
        nat->cached = 1;
        return DM_OK;
      }
      dlclose(nat->dl);                /* stale or damaged: rebuild */
      close(nat->fd);
      nat->fd = -1;
      nat->dl = NULL;
      nat->fn = NULL;
      nat->scatter = NULL;
      unlink(cached);
    } else if (cfd >= 0) {
      close(cfd);
    }
  }

  /* the object embeds its key so that a loaded file can be recognised */
  char *last = srcs->src[srcs->n - 1];
  size_t len = strlen(last);
  char idline[128];
  snprintf(idline, sizeof idline, "const char %s[] = \"%s\";\n", ID_SYMBOL, nat->key);
  char *full = realloc(last, len + strlen(idline) + 1);
  if (full == NULL)
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  strcpy(full + len, idline);
  srcs->src[srcs->n - 1] = full;

  const char *tmpd = env ? env->tmpdir : getenv("TMPDIR");
  char dir[4096], obj[4200];
  snprintf(dir, sizeof dir, "%s/dmech-XXXXXX", tmpd && *tmpd ? tmpd : "/tmp");
  sigset_t held;
  dm_cleanup_hold(&held);                  /* no SIGTERM before it is registered */
  if (mkdtemp(dir) == NULL) {
    int e = errno;
    dm_cleanup_release(&held);
    return dm_err_set(err, DM_EIO, "native: mkdtemp in %s: %s",
                      tmpd && *tmpd ? tmpd : "/tmp", strerror(e));
  }
  int dslot = dm_cleanup_add_dir(dir);     /* removed at exit or SIGTERM too */
  dm_cleanup_release(&held);
  s = dm_native__build_units(ccargv, ncc, dir, srcs->src, srcs->n, opt, parallelism(),
                             obj, sizeof obj, err);
  if (s == DM_OK) {
    if (have_cache && dm_native__cache_store(cdir, cached, obj) == 0 &&
        load(cached, nat->key, nat, NULL) == DM_OK)
      ;
    else
      s = load(obj, nat->key, nat, err);
  }
  dm_native__remove_units(dir, srcs->n);
  dm_cleanup_drop(dslot);
  if (s != DM_OK)
    return s;
  return verify(t, nat, in0, par0, err);
}

int dm_native__compile_with(const dm_tape *t, const double *in0,
                            const double *par0, const dm_native_map *inmap,
                            size_t nmap, const dm_native_map *outmap,
                            const dm_native_env *env, dm_native **natp, dm_err *err)
{
  *natp = NULL;
  for (size_t j = 0; j < nmap; j++)
    if (outmap[j].k >= dm_tape_nout(t) || outmap[j].arr >= 32)
      return dm_err_set(err, DM_EINVAL, "native: output map entry %zu out of "
                        "range", j + 1);
  for (size_t i = 0; inmap && i < dm_tape_nin(t); i++)
    if (inmap[i].arr >= 32)
      return dm_err_set(err, DM_EINVAL, "native: input map entry %zu out of "
                        "range", i + 1);
  dm_native *nat = calloc(1, sizeof *nat);
  dm_native_srcs srcs;
  if (nat == NULL || emit_units(t, inmap, nmap, outmap, &srcs) != DM_OK) {
    free(nat);
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  }
  nat->fd = -1;
  nat->inmap = inmap;
  nat->outmap = outmap;
  nat->nmap = nmap;
  int s = compile_native(t, in0, par0, nat, &srcs, env, err);
  dm_native__srcs_free(&srcs);
  nat->inmap = nat->outmap = NULL;      /* the caller's: not kept */
  if (s != DM_OK) {
    dm_native_free(nat);
    return s;
  }
  *natp = nat;
  return DM_OK;
}

int dm_native_compile(const dm_tape *t, const double *in0, const double *par0,
                      dm_native **natp, dm_err *err)
{
  return dm_native__compile_with(t, in0, par0, NULL, 0, NULL, NULL, natp, err);
}

int dm_native_compile_mapped(const dm_tape *t, const double *in0,
                             const double *par0, const dm_native_map *inmap,
                             size_t nmap, const dm_native_map *outmap,
                             dm_native **natp, dm_err *err)
{
  if (inmap == NULL || (nmap && outmap == NULL))
    return dm_err_set(err, DM_EINVAL, "native: maps missing");
  return dm_native__compile_with(t, in0, par0, inmap, nmap, outmap, NULL, natp, err);
}
