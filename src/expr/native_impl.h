/* native_impl.h -- internals shared by native.c and native_sys.c.  Not a
 * public header. */
#ifndef DM_NATIVE_IMPL_H
#define DM_NATIVE_IMPL_H

#include <stdatomic.h>
#include "expr/native.h"

#define CC_FLAGS "-O1 -fPIC -shared -ffp-contract=off -fno-math-errno"
/* Units compiled separately (with an optimisation level chosen by size),
 * then linked. */
#define CC_UNIT_FLAGS "-c -fPIC -ffp-contract=off -fno-math-errno"
#define CC_LINK_FLAGS "-shared"
/* One unit: compiled and linked by one run. */
#define CC_ONE_FLAGS "-fPIC -shared -ffp-contract=off -fno-math-errno"

/* The source of a tape as translation units (native_emit.c); the last one
 * holds the entry point.  nslot: doubles the entry point keeps on its
 * stack for values passed between chunks. */
typedef struct dm_native_srcs {
  size_t n;
  char **src;
  size_t nslot;
} dm_native_srcs;
/* Chunks of at most `chunk` instructions, `per_unit` chunks per unit;
 * inmap / outmap NULL: the flat dm_native_eval, else dm_native_scatter. */
int dm_native__emit(const dm_tape *t, const dm_native_map *inmap, size_t nmap,
                    const dm_native_map *outmap, size_t chunk, size_t per_unit,
                    dm_native_srcs *out);
void dm_native__srcs_free(dm_native_srcs *s);
/* $CC and $TMPDIR as they were when a background job was started (the
 * worker thread does not read the environment, which the starting thread
 * may change); NULL fields: unset. */
typedef struct dm_native_env {
  const char *cc, *tmpdir;
} dm_native_env;
/* dm_native_compile (inmap NULL) or dm_native_compile_mapped; env NULL:
 * the environment now. */
int dm_native__compile_with(const dm_tape *t, const double *in0, const double *par0,
                            const dm_native_map *inmap, size_t nmap,
                            const dm_native_map *outmap, const dm_native_env *env,
                            dm_native **natp, dm_err *err);

/* Split a compiler command at blanks into argv[0..k) (copy is modified). */
int dm_native__cc_words(char *copy, char **argv, int max);
/* key = SHA-256 (hex) of the source, the compiler command, its --version
 * text and the flags; DM_ENOTFOUND when the compiler does not run. */
int dm_native__make_key(char **ccargv, int ncc, const char *src, char key[65],
                        dm_err *err);
/* The private cache directory (created 0700), or -1 when there is none. */
int dm_native__cache_dir(char *dir, size_t size);
/* Open a cached object whose content matches its recorded SHA-256 (and
 * that is a regular file of ours others cannot write): descriptor (close
 * after dlopen) and the name to dlopen in lpath; -1 when it must be
 * rebuilt. */
int dm_native__cache_open(const char *path, char *lpath, size_t size);
/* Copy obj into the cache as final with its digest final.sha256
 * (temporary names, 0600, rename). */
int dm_native__cache_store(const char *dir, const char *final, const char *obj);
/* Write src to dir/f.c and compile it to dir/f.so (path into obj). */
int dm_native__build(char **ccargv, int ncc, const char *dir, const char *src,
                     char *obj, size_t objsize, dm_err *err);
/* Remove dir/f.c, dir/f.so and dir. */
void dm_native__remove_tree(const char *dir);
/* Write src[k] to dir/u<k>.c, compile each to u<k>.o with CC_UNIT_FLAGS
 * and opt (at most par compilers at once), link them into dir/f.so (path
 * into obj).  The first failure wins; compilers still running are
 * stopped. */
int dm_native__build_units(char **ccargv, int ncc, const char *dir, char *const *src,
                           size_t n, const char *opt, int par, char *obj,
                           size_t objsize, dm_err *err);
/* Remove the files of dm_native__build_units and dir. */
void dm_native__remove_units(const char *dir, size_t n);
/* The compilations started by this thread stop when *flag becomes
 * non-zero (background jobs) instead of at dm_interrupted() (NULL, the
 * default: the foreground).  The flag is atomic: another thread sets it
 * while this one polls it. */
void dm_native__set_cancel(const atomic_int *flag);

#endif
