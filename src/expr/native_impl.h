/* native_impl.h -- internals shared by native.c and native_sys.c.  Not a
 * public header. */
#ifndef DM_NATIVE_IMPL_H
#define DM_NATIVE_IMPL_H

#include "expr/native.h"

#define CC_FLAGS "-O1 -fPIC -shared -ffp-contract=off -fno-math-errno"

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

#endif
