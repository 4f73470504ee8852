/* cleanup.h -- temporary files, temporary directories and child process
 * groups that must not outlive the process.
 *
 * Code that creates a temporary file or directory, or starts a child in
 * its own process group, registers it here and drops the registration when
 * it has removed or reaped it itself.  Whatever is still registered when
 * the process ends is removed (files unlinked, directories emptied one
 * level deep and removed) and killed (SIGKILL to the whole group):
 *   - at normal process exit -- also `os.exit` from Lua without closing
 *     the state -- through an atexit handler installed at the first
 *     registration (in a shared object it runs at dlclose as well);
 *   - on SIGTERM, SIGHUP and SIGQUIT when the program called
 *     dm_cleanup_catch_signals() (the dmech program does; a host embedding
 *     the library keeps its own signal dispositions and may call
 *     dm_cleanup_run() from its own handler).
 *
 * Limits: DM_CLEANUP_SLOTS registrations at a time, paths shorter than
 * DM_CLEANUP_PATH_MAX; beyond them registration returns -1 and the caller
 * goes on without the guarantee.
 *
 * A child or file exists before it can be registered.  So that SIGTERM in
 * between does not leak it, create and register between dm_cleanup_hold
 * and dm_cleanup_release: the signals above are blocked in the calling
 * thread (give the child the mask `old` back), and dm_cleanup_run in any
 * other thread first waits (up to 2 s) until no thread is held.
 *
 * Thread safety: registration and dropping may happen from any thread
 * (slots are claimed atomically); dm_cleanup_run is async-signal-safe.
 */
#ifndef DM_CLEANUP_H
#define DM_CLEANUP_H

#include <signal.h>
#include <sys/types.h>

#define DM_CLEANUP_SLOTS 32
#define DM_CLEANUP_PATH_MAX 1024

/* Register; returns a slot number for dm_cleanup_drop, or -1. */
int dm_cleanup_add_file(const char *path);
int dm_cleanup_add_dir(const char *path);
int dm_cleanup_add_pgroup(pid_t pgid);

/* Around creating something and registering it (see above); *old
 * receives the thread's previous signal mask, to be passed back. */
void dm_cleanup_hold(sigset_t *old);
void dm_cleanup_release(const sigset_t *old);

/* Forget a registration (slot < 0 is a no-op). */
void dm_cleanup_drop(int slot);

/* Kill every registered process group, remove every registered file and
 * directory, forget them all; first wait (at most 2 s) while another
 * thread is between hold and release.  Async-signal-safe. */
void dm_cleanup_run(void);

/* Install handlers for SIGTERM, SIGHUP and SIGQUIT (those not ignored)
 * that run dm_cleanup_run and then die of the same signal. */
void dm_cleanup_catch_signals(void);

/* Number of registrations in force (for tests). */
int dm_cleanup_count(void);

#endif
