/* native.h -- tapes compiled to machine code by the system C compiler.
 *
 * dm_native_compile emits straight-line C for a tape (one local double per
 * instruction, the same operations in the same order, so results agree with
 * the tape to the last bit in practice; each output stored as soon as it
 * is computed).  A tape of up to 2000 instructions is one function; a
 * longer one is cut into functions of 500 instructions, in an order that
 * keeps each output's subexpressions together (values passed on in a
 * stack array), eight per translation unit, so that the compiler's time
 * grows linearly with the tape (native_emit.c).  The units are
 * compiled with $CC (else "cc") `-c -O1 -fPIC -ffp-contract=off
 * -fno-math-errno`, as many at once as there are processors (at most 4),
 * and linked with `-shared` (-O1: straight-line code of a few hundred
 * temporaries runs faster than at -O2 or -O3 -- less register pressure --
 * and compiles sooner; -fno-math-errno lets sqrt be one instruction and
 * pairs sin/cos of one argument into sincos; no -ffast-math: results equal
 * the tape's bit for bit) in a private mkdtemp directory
 * (mode 0700) under $TMPDIR (else /tmp), loaded with dlopen and checked
 * against the tape on random points (relative agreement 1e-15, NaN equal to
 * NaN).  Objects are cached under $XDG_CACHE_HOME/dmech (else
 * ~/.cache/dmech; directory 0700, files 0600, written to a temporary name
 * and renamed) keyed by the SHA-256 of the emitted source, the compiler
 * command, its --version text and the flags, with the SHA-256 of the
 * object itself beside it (<key>.so.sha256); a cached object is loaded
 * only when it is a regular file owned by the user, not writable by
 * others, and its content has that digest (else it is rebuilt and
 * replaced).  The compilers run through posix_spawn (never a shell), each
 * in a process group of its own, which is killed whole on an interrupt,
 * on the timeout and (through core/cleanup.h) on exit or SIGTERM; the
 * build directory is removed on every path.  The stderr of a failing one
 * becomes the error message.  A compilation in the foreground stops at
 * Ctrl-C (dm_interrupted); one in a background job (native_job.h) at its
 * own cancel flag.
 *
 * Errors (the caller then uses the tape): DM_ENOTFOUND no compiler,
 * DM_EFAILED compilation failed or the code disagrees with the tape,
 * DM_EIO file or dlopen trouble, DM_EINTR interrupted, DM_ETIMEOUT the
 * compiler ran longer than $DMECH_CC_TIMEOUT seconds (default 300).  Nothing is printed.
 *
 * Ownership: dm_native_compile allocates, dm_native_free releases (NULL
 * ok); the loaded code stays valid until then and does not refer to the
 * tape.  The compiled functions are re-entrant (the scatter function
 * writes only its outputs and the caller's work).
 */
#ifndef DM_NATIVE_H
#define DM_NATIVE_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "expr/tape.h"

/* What the caller wants (dm.config.native).  What "auto" means is the
 * caller's: compiled Lagrangians run the tape at once and compile in the
 * background (native_job.h); other users of bundles compile at once. */
enum dm_native_mode {
  DM_NATIVE_NEVER = 0,  /* always the tape */
  DM_NATIVE_AUTO,       /* native when a compiler works, else the tape, silently */
  DM_NATIVE_ALWAYS,     /* native or an error, compiled before anything runs */
  DM_NATIVE_WAIT        /* compiled before anything runs; failing that the
                           tape, silently (Ctrl-C stops waiting) */
};

typedef struct dm_native dm_native;

/* out[nout] = outputs at (in, par), same contract as dm_tape_eval. */
typedef void (*dm_native_fn)(const double *in, const double *par, double *out);

/* Compile tape t.  in0 / par0 (may be NULL) are a typical point: the check
 * against the tape uses points near it as well as random ones. */
int dm_native_compile(const dm_tape *t, const double *in0, const double *par0,
                      dm_native **nat, dm_err *err);
void dm_native_free(dm_native *nat);

dm_native_fn dm_native_function(const dm_native *nat);

/* Element `elem` of array `arr` (arr < 32), for output `k` or input k. */
typedef struct dm_native_map {
  uint32_t k, arr, elem;
} dm_native_map;

/* Gathers its inputs and scatters its outputs itself: input i is
 * in[inmap[i].arr][inmap[i].elem]; output k goes to out[arr][elem] for
 * every outmap entry with that k whose bit (1 << arr) is set in mask (the
 * arrays whose bit is clear are not touched and may be NULL; their values
 * go to work, which needs room for every output array, at most the tape's
 * dm_tape_work_size doubles).  Returns 1 when any output is NaN or
 * infinite (the requested arrays are then written all the same), else 0.
 * This is what a system callback needs without copying through buffers:
 * each output goes straight to its places as soon as it is computed. */
typedef int (*dm_native_scatter_fn)(const double *const *in, const double *par,
                                    double *const *out, unsigned mask, double *work);

/* Compile the scatter function for these maps (inmap has dm_tape_nin(t)
 * entries; the maps are only read during the call); it is checked against
 * the tape.  A native compiled this way has no flat function
 * (dm_native_function gives NULL). */
int dm_native_compile_mapped(const dm_tape *t, const double *in0,
                             const double *par0, const dm_native_map *inmap,
                             size_t nmap, const dm_native_map *outmap,
                             dm_native **nat, dm_err *err);
/* The scatter function, or NULL when compiled without maps (then the flat
 * function, dm_native_function, is there). */
dm_native_scatter_fn dm_native_scatter(const dm_native *nat);
/* 1 if the object came from the cache, 0 if it was compiled now. */
int dm_native_cached(const dm_native *nat);
/* The cache key (64 hex digits). */
const char *dm_native_key(const dm_native *nat);

/* The C source emitted for t (malloc'ed, caller frees; NULL when out of
 * memory). */
char *dm_native_source(const dm_tape *t);

/* "never" / "auto" / "always" / "wait" and back (-1 for an unknown
 * name). */
const char *dm_native_mode_name(int mode);
int dm_native_mode_parse(const char *name);

#endif
