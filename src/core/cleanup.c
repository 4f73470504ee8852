/* cleanup.c -- what must not outlive the process (see cleanup.h).
 *
 * The registry is a fixed array of slots so that a signal handler can walk
 * it without taking locks or allocating: a slot is claimed with a
 * compare-and-swap (FREE -> BUSY), filled, then published (READY); the
 * handler only touches READY slots and uses only async-signal-safe calls
 * (kill, unlink, rmdir, open, close, nanosleep and the getdents64 system
 * call).
 */
#include <config.h>
#include "core/cleanup.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

enum { FREE = 0, BUSY, READY };
enum { KIND_FILE = 1, KIND_DIR, KIND_PGROUP };

typedef struct slot {
  int state;                     /* FREE, BUSY, READY (atomic) */
  int kind;
  pid_t pgid;
  char path[DM_CLEANUP_PATH_MAX];
} slot;

static slot slots[DM_CLEANUP_SLOTS];
static int holding;              /* threads between hold and release (atomic) */
static const int fatal_sigs[] = { SIGTERM, SIGHUP, SIGQUIT };
static pthread_once_t atexit_once = PTHREAD_ONCE_INIT;

static void run_at_exit(void)
{
  dm_cleanup_run();
}

static void install_atexit(void)
{
  atexit(run_at_exit);
}

static int add(int kind, const char *path, pid_t pgid)
{
  size_t n = path != NULL ? strlen(path) : 0;
  int i;
  if (n >= DM_CLEANUP_PATH_MAX)
    return -1;
  pthread_once(&atexit_once, install_atexit);
  for (i = 0; i < DM_CLEANUP_SLOTS; i++) {
    int expect = FREE;
    if (!__atomic_compare_exchange_n(&slots[i].state, &expect, BUSY, 0,
                                     __ATOMIC_ACQ_REL, __ATOMIC_RELAXED))
      continue;
    slots[i].kind = kind;
    slots[i].pgid = pgid;
    if (path != NULL)
      memcpy(slots[i].path, path, n + 1);
    __atomic_store_n(&slots[i].state, READY, __ATOMIC_RELEASE);
    return i;
  }
  return -1;
}

int dm_cleanup_add_file(const char *path)
{
  return path != NULL ? add(KIND_FILE, path, 0) : -1;
}

int dm_cleanup_add_dir(const char *path)
{
  return path != NULL ? add(KIND_DIR, path, 0) : -1;
}

int dm_cleanup_add_pgroup(pid_t pgid)
{
  return pgid > 1 ? add(KIND_PGROUP, NULL, pgid) : -1;
}

void dm_cleanup_hold(sigset_t *old)
{
  sigset_t set;
  size_t i;
  sigemptyset(&set);
  for (i = 0; i < sizeof fatal_sigs / sizeof fatal_sigs[0]; i++)
    sigaddset(&set, fatal_sigs[i]);
  pthread_sigmask(SIG_BLOCK, &set, old);
  __atomic_add_fetch(&holding, 1, __ATOMIC_ACQ_REL);
}

void dm_cleanup_release(const sigset_t *old)
{
  __atomic_sub_fetch(&holding, 1, __ATOMIC_ACQ_REL);
  pthread_sigmask(SIG_SETMASK, old, NULL);
}

void dm_cleanup_drop(int i)
{
  if (i >= 0 && i < DM_CLEANUP_SLOTS)
    __atomic_store_n(&slots[i].state, FREE, __ATOMIC_RELEASE);
}

int dm_cleanup_count(void)
{
  int i, n = 0;
  for (i = 0; i < DM_CLEANUP_SLOTS; i++)
    n += __atomic_load_n(&slots[i].state, __ATOMIC_ACQUIRE) == READY;
  return n;
}

/* Unlink the entries of dir (one level), with no allocation. */
static void empty_dir(const char *dir)
{
  char buf[4096];
  int fd = open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  long n;
  if (fd < 0)
    return;
  while ((n = syscall(SYS_getdents64, fd, buf, sizeof buf)) > 0) {
    long off = 0;
    while (off < n) {
      /* struct linux_dirent64: u64 ino, s64 off, u16 reclen, u8 type, name */
      unsigned short reclen;
      const char *name = buf + off + 19;
      memcpy(&reclen, buf + off + 16, sizeof reclen);
      if (strcmp(name, ".") != 0 && strcmp(name, "..") != 0)
        unlinkat(fd, name, 0);
      off += reclen;
    }
  }
  close(fd);
}

void dm_cleanup_run(void)
{
  int i, errsave = errno;
  /* a child started by another thread but not registered yet would be
   * missed: let that thread finish registering (it runs with our signals
   * blocked, so this never waits for the thread it interrupted) */
  for (i = 0; i < 2000 && __atomic_load_n(&holding, __ATOMIC_ACQUIRE) > 0; i++) {
    struct timespec ts = { 0, 1000000L };
    nanosleep(&ts, NULL);
  }
  /* processes first: a compiler must not write into a directory being
   * removed */
  for (i = 0; i < DM_CLEANUP_SLOTS; i++)
    if (__atomic_load_n(&slots[i].state, __ATOMIC_ACQUIRE) == READY
        && slots[i].kind == KIND_PGROUP)
      kill(-slots[i].pgid, SIGKILL);
  for (i = 0; i < DM_CLEANUP_SLOTS; i++) {
    int expect = READY;
    if (!__atomic_compare_exchange_n(&slots[i].state, &expect, BUSY, 0,
                                     __ATOMIC_ACQ_REL, __ATOMIC_RELAXED))
      continue;
    if (slots[i].kind == KIND_FILE)
      unlink(slots[i].path);
    else if (slots[i].kind == KIND_DIR) {
      empty_dir(slots[i].path);
      rmdir(slots[i].path);
    }
    __atomic_store_n(&slots[i].state, FREE, __ATOMIC_RELEASE);
  }
  errno = errsave;
}

static void on_fatal_signal(int sig)
{
  dm_cleanup_run();
  signal(sig, SIG_DFL);
  raise(sig);
}

void dm_cleanup_catch_signals(void)
{
  size_t i;
  for (i = 0; i < sizeof fatal_sigs / sizeof fatal_sigs[0]; i++) {
    struct sigaction sa, old;
    if (sigaction(fatal_sigs[i], NULL, &old) != 0 || old.sa_handler == SIG_IGN)
      continue;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    sigaction(fatal_sigs[i], &sa, NULL);
  }
}
