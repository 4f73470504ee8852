/* native_sys.c -- the system side of native compilation: SHA-256 cache
 * keys, running the compiler (posix_spawn, never a shell), private files
 * and the object cache.  See native.h. */
#include <config.h>
#include "expr/native_impl.h"
#include "core/cleanup.h"
#include "core/interrupt.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <spawn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

#define CC_TIMEOUT 300.0      /* seconds, unless $DMECH_CC_TIMEOUT says */

/* What stops this thread's compilations: the interrupt flag (foreground)
 * or a job's cancel flag (background threads must not die of a Ctrl-C
 * meant for the computation in the foreground). */
static _Thread_local const atomic_int *tl_cancel, *tl_stop;

void dm_native__set_cancel(const atomic_int *flag)
{
  tl_cancel = flag;
}

/* tl_stop: a failure in a sibling compilation (dm_native__build_units) */
static int cancelled(void)
{
  return (tl_cancel != NULL ? atomic_load(tl_cancel) != 0 : dm_interrupted()) ||
         (tl_stop != NULL && atomic_load(tl_stop) != 0);
}


/* {==================================================================
 * SHA-256 (FIPS 180-4), for cache keys
 * =================================================================== */

typedef struct sha256 {
  uint32_t h[8];
  uint64_t len;
  unsigned char buf[64];
  size_t nbuf;
} sha256;

static const uint32_t K256[64] = {
  0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1,
  0x923f82a4, 0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3,
  0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
  0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
  0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147,
  0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
  0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
  0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
  0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
  0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208,
  0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2
};

#define ROR(x, n) (((x) >> (n)) | ((x) << (32 - (n))))

static void sha_block(sha256 *s, const unsigned char *p)
{
  uint32_t w[64], v[8];
  for (int i = 0; i < 16; i++)
    w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 |
           (uint32_t)p[4 * i + 2] << 8 | p[4 * i + 3];
  for (int i = 16; i < 64; i++) {
    uint32_t s0 = ROR(w[i - 15], 7) ^ ROR(w[i - 15], 18) ^ (w[i - 15] >> 3);
    uint32_t s1 = ROR(w[i - 2], 17) ^ ROR(w[i - 2], 19) ^ (w[i - 2] >> 10);
    w[i] = w[i - 16] + s0 + w[i - 7] + s1;
  }
  memcpy(v, s->h, sizeof v);
  for (int i = 0; i < 64; i++) {
    uint32_t S1 = ROR(v[4], 6) ^ ROR(v[4], 11) ^ ROR(v[4], 25);
    uint32_t ch = (v[4] & v[5]) ^ (~v[4] & v[6]);
    uint32_t t1 = v[7] + S1 + ch + K256[i] + w[i];
    uint32_t S0 = ROR(v[0], 2) ^ ROR(v[0], 13) ^ ROR(v[0], 22);
    uint32_t mj = (v[0] & v[1]) ^ (v[0] & v[2]) ^ (v[1] & v[2]);
    memmove(v + 1, v, 7 * sizeof *v);
    v[4] += t1;
    v[0] = t1 + S0 + mj;
  }
  for (int i = 0; i < 8; i++)
    s->h[i] += v[i];
}

static void sha_init(sha256 *s)
{
  static const uint32_t h0[8] = { 0x6a09e667, 0xbb67ae85, 0x3c6ef372,
    0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19 };
  memcpy(s->h, h0, sizeof h0);
  s->len = 0;
  s->nbuf = 0;
}

static void sha_update(sha256 *s, const void *data, size_t n)
{
  const unsigned char *p = data;
  s->len += n;
  while (n > 0) {
    size_t k = 64 - s->nbuf < n ? 64 - s->nbuf : n;
    memcpy(s->buf + s->nbuf, p, k);
    s->nbuf += k;
    p += k;
    n -= k;
    if (s->nbuf == 64) {
      sha_block(s, s->buf);
      s->nbuf = 0;
    }
  }
}

static void sha_hex(sha256 *s, char hex[65])
{
  uint64_t bits = s->len * 8;
  unsigned char pad = 0x80, zero = 0, lenb[8];
  sha_update(s, &pad, 1);
  while (s->nbuf != 56)
    sha_update(s, &zero, 1);
  for (int i = 0; i < 8; i++)
    lenb[i] = (unsigned char)(bits >> (56 - 8 * i));
  sha_update(s, lenb, 8);
  for (int i = 0; i < 8; i++)
    snprintf(hex + 8 * i, 9, "%08x", (unsigned)s->h[i]);
}

/* {==================================================================
 * running the compiler
 * =================================================================== */

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Split $CC (else "cc") at blanks into argv[0..k), return k (0: none). */
int dm_native__cc_words(char *copy, char **argv, int max)
{
  int k = 0;
  char *save = NULL;
  for (char *p = strtok_r(copy, " \t", &save); p != NULL && k < max;
       p = strtok_r(NULL, " \t", &save))
    argv[k++] = p;
  return k;
}

/* Seconds the compiler may run: $DMECH_CC_TIMEOUT, else CC_TIMEOUT. */
static double cc_timeout(void)
{
  const char *env = getenv("DMECH_CC_TIMEOUT");
  char *end;
  double t = env != NULL ? strtod(env, &end) : 0;
  return env != NULL && end != env && t > 0 && t < 1e6 ? t : CC_TIMEOUT;
}

/* Run argv with stdin from /dev/null and stdout + stderr captured into out
 * (at most size-1 bytes kept, NUL-terminated).  *status is the exit code,
 * or minus the signal that killed it.  Returns a dm status.
 *
 * The compiler runs in a process group of its own: the driver `cc` starts
 * cc1, as, ld; on an interrupt or the timeout the whole group is killed
 * (killing only the driver left cc1 running at full CPU), and the group is
 * registered with core/cleanup.h so that SIGTERM or the process's exit
 * kill it too.
 * Being in its own group, the compiler does not see the terminal's Ctrl-C;
 * dmech's interrupt flag stops it instead. */
static int run(char *const argv[], char *out, size_t size, int *status,
               dm_err *err)
{
  int fd[2];
  if (pipe2(fd, O_CLOEXEC) != 0)
    return dm_err_set(err, DM_EIO, "native: pipe: %s", strerror(errno));
  posix_spawn_file_actions_t fa;
  posix_spawnattr_t attr;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 1);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 2);
  /* the compiler gets stdio and nothing else: a descriptor another thread
   * has open without close-on-exec (HDF5 opens its files so, with an
   * exclusive flock) must not stay open, and locked, until cc exits */
#if HAVE_POSIX_SPAWN_FILE_ACTIONS_ADDCLOSEFROM_NP
  posix_spawn_file_actions_addclosefrom_np(&fa, 3);
#else
  posix_spawn_file_actions_addclose(&fa, fd[0]);
  posix_spawn_file_actions_addclose(&fa, fd[1]);
#endif
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK);
  posix_spawnattr_setpgroup(&attr, 0);
  /* a SIGTERM between the spawn and the registration would leave the
   * group running: hold it back until the group is registered */
  sigset_t held;
  dm_cleanup_hold(&held);
  posix_spawnattr_setsigmask(&attr, &held);
  pid_t pid;
  int rc = posix_spawnp(&pid, argv[0], &fa, &attr, argv, environ);
  int slot = rc == 0 ? dm_cleanup_add_pgroup(pid) : -1;
  dm_cleanup_release(&held);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  close(fd[1]);
  if (rc != 0) {
    close(fd[0]);
    return dm_err_set(err, rc == ENOENT ? DM_ENOTFOUND : DM_EIO,
                      "native: cannot run C compiler '%s': %s", argv[0],
                      strerror(rc));
  }
  size_t len = 0;
  int result = DM_OK, ws = 0, open = 1;
  double t0 = now(), limit = cc_timeout();
  for (;;) {
    if (open) {
      struct pollfd p = { fd[0], POLLIN, 0 };
      if (poll(&p, 1, 50) > 0) {
        char tmp[4096];
        ssize_t r = read(fd[0], tmp, sizeof tmp);
        if (r > 0 && len + 1 < size) {
          size_t m = (size_t)r < size - 1 - len ? (size_t)r : size - 1 - len;
          memcpy(out + len, tmp, m);
          len += m;
        }
        open = r > 0 || (r < 0 && errno == EINTR);
      }
    } else {
      struct timespec ts = { 0, 10000000L };
      nanosleep(&ts, NULL);
    }
    /* the driver may exit while a child still holds the pipe, or close
     * the pipe and go on running: watch both */
    pid_t w = waitpid(pid, &ws, WNOHANG);
    if (w == pid)
      break;
    if (cancelled() || now() - t0 > limit) {
      result = cancelled() ? DM_EINTR : DM_ETIMEOUT;
      kill(-pid, SIGKILL);
      while (waitpid(pid, &ws, 0) < 0 && errno == EINTR)
        ;
      break;
    }
  }
  /* whatever the driver left in its group (nothing, normally) goes too;
   * the group id stays reserved while any member lives */
  kill(-pid, SIGKILL);
  dm_cleanup_drop(slot);
  while (open) {                 /* the rest of the output, if any */
    char tmp[4096];
    struct pollfd p = { fd[0], POLLIN, 0 };
    ssize_t r = poll(&p, 1, 0) > 0 ? read(fd[0], tmp, sizeof tmp) : 0;
    if (r > 0 && len + 1 < size) {
      size_t m = (size_t)r < size - 1 - len ? (size_t)r : size - 1 - len;
      memcpy(out + len, tmp, m);
      len += m;
    }
    open = r > 0;
  }
  while (len > 0 && (out[len - 1] == '\n' || out[len - 1] == ' '))
    len--;                       /* messages end without a newline */
  out[len] = '\0';
  close(fd[0]);
  *status = WIFEXITED(ws) ? WEXITSTATUS(ws) : -WTERMSIG(ws);
  if (result == DM_EINTR)
    return dm_err_set(err, DM_EINTR, "native: compilation interrupted");
  if (result == DM_ETIMEOUT)
    return dm_err_set(err, DM_ETIMEOUT, "native: %s ran longer than %g s",
                      argv[0], limit);
  /* glibc reports a failed exec as exit status 127 */
  if (*status == 127 && len == 0)
    return dm_err_set(err, DM_ENOTFOUND, "native: cannot run C compiler '%s'",
                      argv[0]);
  return DM_OK;
}

/* {==================================================================
 * files and the cache
 * =================================================================== */

static int write_file(const char *path, const void *data, size_t n)
{
  int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    return -1;
  const char *p = data;
  while (n > 0) {
    ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR)
      continue;
    if (w <= 0) {
      close(fd);
      return -1;
    }
    p += w;
    n -= (size_t)w;
  }
  return close(fd);
}

/* Whole file into a malloc'ed buffer, or NULL. */
static char *read_file(const char *path, size_t *n)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return NULL;
  char *buf = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len == cap) {
      cap = cap ? 2 * cap : 65536;
      char *p = realloc(buf, cap);
      if (p == NULL)
        break;
      buf = p;
    }
    size_t r = fread(buf + len, 1, cap - len, f);
    len += r;
    if (r == 0)
      break;
  }
  int bad = ferror(f);
  fclose(f);
  if (bad || buf == NULL) {
    free(buf);
    return NULL;
  }
  *n = len;
  return buf;
}

/* A directory we own, not accessible to others (created 0700 if missing). */
static int private_dir(const char *path)
{
  struct stat st;
  if (mkdir(path, 0700) != 0 && errno != EEXIST)
    return -1;
  if (lstat(path, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid()
      || (st.st_mode & 077) != 0)
    return -1;
  return 0;
}

/* $XDG_CACHE_HOME/dmech or $HOME/.cache/dmech into dir; -1 when there is
 * no usable cache directory. */
int dm_native__cache_dir(char *dir, size_t size)
{
  const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
  char base[4096];
  if (x != NULL && x[0] == '/')
    snprintf(base, sizeof base, "%s", x);
  else if (home != NULL && home[0] == '/')
    snprintf(base, sizeof base, "%s/.cache", home);
  else
    return -1;
  /* the base may be missing: create it (and only it) privately */
  if (mkdir(base, 0700) != 0 && errno != EEXIST)
    return -1;
  if ((size_t)snprintf(dir, size, "%s/dmech", base) >= size)
    return -1;
  return private_dir(dir);
}

/* The digest of an object is kept beside it as "<object>.sha256" (64 hex
 * digits), written when the object is stored: a cached object whose
 * content no longer matches (a damaged disk block, a truncated copy, an
 * edit) is never handed to dlopen -- running it could raise SIGILL on
 * every later start until the cache was deleted by hand. */
static void digest_hex(const void *data, size_t n, char hex[65])
{
  sha256 h;
  sha_init(&h);
  sha_update(&h, data, n);
  sha_hex(&h, hex);
}

/* Write n bytes to a new private temporary in dir and rename it to final. */
static int store_file(const char *dir, const char *final, const void *data,
                      size_t n)
{
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s/.tmp-XXXXXX", dir);
  int fd = mkstemp(tmp);
  if (fd < 0)
    return -1;
  int bad = 0;
  for (size_t off = 0; !bad && off < n;) {
    ssize_t w = write(fd, (const char *)data + off, n - off);
    if (w < 0 && errno == EINTR)
      continue;
    bad = w <= 0;
    off += bad ? 0 : (size_t)w;
  }
  bad |= fchmod(fd, 0600) != 0;
  bad |= close(fd) != 0;
  if (bad || rename(tmp, final) != 0) {
    unlink(tmp);
    return -1;
  }
  return 0;
}

/* Copy the object into the cache with its digest: temporary names, 0600,
 * rename (the digest first: an object never appears without one). */
int dm_native__cache_store(const char *dir, const char *final, const char *obj)
{
  size_t n;
  char *data = read_file(obj, &n), sumpath[4300], hex[65];
  if (data == NULL)
    return -1;
  digest_hex(data, n, hex);
  snprintf(sumpath, sizeof sumpath, "%s.sha256", final);
  int rc = store_file(dir, sumpath, hex, 64) == 0
           && store_file(dir, final, data, n) == 0 ? 0 : -1;
  free(data);
  return rc;
}

/* Whole content of an open descriptor (malloc'ed), or NULL. */
static char *read_fd(int fd, size_t *n)
{
  char *buf = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len == cap) {
      char *p = realloc(buf, cap = cap ? 2 * cap : 65536);
      if (p == NULL) {
        free(buf);
        return NULL;
      }
      buf = p;
    }
    ssize_t r = read(fd, buf + len, cap - len);
    if (r < 0 && errno == EINTR)
      continue;
    if (r < 0) {
      free(buf);
      return NULL;
    }
    if (r == 0)
      break;
    len += (size_t)r;
  }
  *n = len;
  return buf;
}

/* Open a cached object for loading: a regular file of ours that others
 * cannot write, whose SHA-256 equals the recorded one.  Returns the open
 * descriptor (close it after dlopen) and in lpath the name to give dlopen:
 * /proc/self/fd/N when there is /proc, so the checked content is the
 * loaded content; else the path.  -1 when the object must be rebuilt. */
int dm_native__cache_open(const char *path, char *lpath, size_t size)
{
  char sumpath[4300], want[65], hex[65];
  snprintf(sumpath, sizeof sumpath, "%s.sha256", path);
  int sfd = open(sumpath, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (sfd < 0)
    return -1;
  struct stat st;
  ssize_t k = -1;
  if (fstat(sfd, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == getuid()
      && (st.st_mode & 022) == 0)
    k = read(sfd, want, 64);
  close(sfd);
  if (k != 64)
    return -1;
  want[64] = '\0';
  int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0)
    return -1;
  size_t n;
  char *data = NULL;
  if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == getuid()
      && (st.st_mode & 022) == 0)
    data = read_fd(fd, &n);
  if (data == NULL) {
    close(fd);
    return -1;
  }
  digest_hex(data, n, hex);
  free(data);
  if (strcmp(hex, want) != 0) {
    close(fd);
    return -1;
  }
  snprintf(lpath, size, "/proc/self/fd/%d", fd);
  if (access(lpath, R_OK) != 0)
    snprintf(lpath, size, "%s", path);
  return fd;
}

/* Compile src into dir/f.so (files in dir, which the caller removes). */
/* The message of a compiler run that ended with status != 0 (see run):
 * "native: <cc> failed (exit 1): <its output>" or "... failed (killed by
 * signal 11, Segmentation fault)" -- no dangling ": " without output. */
static const char *how_ended(int status, char *how, size_t n)
{
  if (status < 0)
    snprintf(how, n, "killed by signal %d, %s", -status, strsignal(-status));
  else
    snprintf(how, n, "exit %d", status);
  return how;
}

static int cc_failed(dm_err *err, const char *doing, const char *cc, int status,
                     const char *msg)
{
  char how[96];
  how_ended(status, how, sizeof how);
  return dm_err_set(err, DM_EFAILED, "native: %s%s failed (%s)%s%s", doing, cc, how,
                    msg[0] != '\0' ? ": " : "", msg);
}

int dm_native__build(char **ccargv, int ncc, const char *dir, const char *src,
                 char *obj, size_t objsize, dm_err *err)
{
  char cpath[4200], flags[] = CC_FLAGS, *argv[64], msg[2048];
  int k = 0, status;
  snprintf(cpath, sizeof cpath, "%s/f.c", dir);
  snprintf(obj, objsize, "%s/f.so", dir);
  if (write_file(cpath, src, strlen(src)) != 0)
    return dm_err_set(err, DM_EIO, "native: cannot write %s: %s", cpath,
                      strerror(errno));
  for (int i = 0; i < ncc; i++)
    argv[k++] = ccargv[i];
  k += dm_native__cc_words(flags, argv + k, 16);
  argv[k++] = "-o";
  argv[k++] = obj;
  argv[k++] = cpath;
  argv[k++] = "-lm";
  argv[k] = NULL;
  int s = run(argv, msg, sizeof msg, &status, err);
  if (s != DM_OK)
    return s;
  if (status != 0)
    return cc_failed(err, "", ccargv[0], status, msg);
  return DM_OK;
}

void dm_native__remove_tree(const char *dir)
{
  char p[4200];
  static const char *const files[] = { "f.c", "f.so" };
  for (size_t i = 0; i < 2; i++) {
    snprintf(p, sizeof p, "%s/%s", dir, files[i]);
    unlink(p);
  }
  rmdir(dir);
}

/* {==================================================================
 * units compiled in parallel
 * =================================================================== */

typedef struct unit_job {
  char **ccargv;
  int ncc;
  const char *dir, *opt;
  char *const *src;
  size_t n, next;           /* units; the next one to take */
  pthread_mutex_t mu;
  const atomic_int *cancel;     /* the starting thread's */
  atomic_int stop;          /* set by the first failure (under mu), polled */
  int status;
  dm_err err;
} unit_job;

/* Compile unit k: write it, run the compiler. */
static int compile_unit(unit_job *J, size_t k, dm_err *err)
{
  char cpath[4200], opath[4200], flags[] = CC_UNIT_FLAGS, opt[64], *argv[64], msg[2048];
  int a = 0, status;
  snprintf(cpath, sizeof cpath, "%s/u%zu.c", J->dir, k);
  snprintf(opath, sizeof opath, "%s/u%zu.o", J->dir, k);
  if (write_file(cpath, J->src[k], strlen(J->src[k])) != 0)
    return dm_err_set(err, DM_EIO, "native: cannot write %s: %s", cpath, strerror(errno));
  for (int i = 0; i < J->ncc && a < 40; i++)
    argv[a++] = J->ccargv[i];
  a += dm_native__cc_words(flags, argv + a, 16);
  snprintf(opt, sizeof opt, "%s", J->opt);
  a += dm_native__cc_words(opt, argv + a, 4);
  argv[a++] = "-o";
  argv[a++] = opath;
  argv[a++] = cpath;
  argv[a] = NULL;
  int s = run(argv, msg, sizeof msg, &status, err);
  if (s != DM_OK)
    return s;
  if (status != 0)
    return cc_failed(err, "", J->ccargv[0], status, msg);
  return DM_OK;
}

/* A worker: units until none is left or one failed; it stops with the
 * caller's stop condition too. */
static void *unit_worker(void *arg)
{
  unit_job *J = arg;
  const atomic_int *save = tl_cancel, *save2 = tl_stop;
  tl_cancel = J->cancel;
  tl_stop = &J->stop;
  for (;;) {
    pthread_mutex_lock(&J->mu);
    size_t k = J->next < J->n && !atomic_load(&J->stop) ? J->next++ : J->n;
    pthread_mutex_unlock(&J->mu);
    if (k >= J->n)
      break;
    dm_err e;
    int s = compile_unit(J, k, &e);
    pthread_mutex_lock(&J->mu);
    if (s != DM_OK && J->status == DM_OK) {
      J->status = s;
      J->err = e;
      atomic_store(&J->stop, 1);
    }
    pthread_mutex_unlock(&J->mu);
  }
  tl_cancel = save;
  tl_stop = save2;
  return NULL;
}

/* One unit: compiled and linked by one compiler run. */
static int build_one(char **ccargv, int ncc, const char *dir, const char *src,
                     const char *opt, char *obj, size_t objsize, dm_err *err)
{
  char cpath[4200], flags[] = CC_ONE_FLAGS, optc[64], *argv[64], msg[2048];
  int a = 0, status;
  snprintf(cpath, sizeof cpath, "%s/u0.c", dir);
  snprintf(obj, objsize, "%s/f.so", dir);
  if (write_file(cpath, src, strlen(src)) != 0)
    return dm_err_set(err, DM_EIO, "native: cannot write %s: %s", cpath, strerror(errno));
  for (int i = 0; i < ncc && a < 40; i++)
    argv[a++] = ccargv[i];
  a += dm_native__cc_words(flags, argv + a, 16);
  snprintf(optc, sizeof optc, "%s", opt);
  a += dm_native__cc_words(optc, argv + a, 4);
  argv[a++] = "-o";
  argv[a++] = obj;
  argv[a++] = cpath;
  argv[a++] = "-lm";
  argv[a] = NULL;
  int s = run(argv, msg, sizeof msg, &status, err);
  if (s != DM_OK)
    return s;
  if (status != 0)
    return cc_failed(err, "", ccargv[0], status, msg);
  return DM_OK;
}

int dm_native__build_units(char **ccargv, int ncc, const char *dir, char *const *src,
                           size_t n, const char *opt, int par, char *obj,
                           size_t objsize, dm_err *err)
{
  if (n == 1)
    return build_one(ccargv, ncc, dir, src[0], opt, obj, objsize, err);
  unit_job J;
  memset(&J, 0, sizeof J);
  J.ccargv = ccargv;
  J.ncc = ncc;
  J.dir = dir;
  J.opt = opt;
  J.src = src;
  J.n = n;
  J.cancel = tl_cancel;
  atomic_init(&J.stop, 0);
  pthread_mutex_init(&J.mu, NULL);
  enum { MAXPAR = 8 };
  pthread_t th[MAXPAR];
  int nth = par < 1 ? 1 : par > MAXPAR ? MAXPAR : par, started = 0;
  if ((size_t)nth > n)
    nth = (int)n;
  for (int i = 1; i < nth; i++)           /* this thread is worker 0 */
    if (pthread_create(&th[i], NULL, unit_worker, &J) == 0)
      started |= 1 << i;
  unit_worker(&J);
  for (int i = 1; i < nth; i++)
    if (started & (1 << i))
      pthread_join(th[i], NULL);
  pthread_mutex_destroy(&J.mu);
  if (J.status != DM_OK) {
    if (err != NULL)
      *err = J.err;
    return J.status;
  }
  if (cancelled())
    return dm_err_set(err, DM_EINTR, "native: compilation interrupted");
  /* link */
  char flags[] = CC_LINK_FLAGS, msg[2048];
  char (*opath)[4200] = malloc(n * sizeof *opath);
  char **largv = malloc((n + 64) * sizeof *largv);
  if (opath == NULL || largv == NULL) {
    free(opath);
    free(largv);
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  }
  int a = 0, status;
  for (int i = 0; i < ncc && a < 40; i++)
    largv[a++] = ccargv[i];
  a += dm_native__cc_words(flags, largv + a, 8);
  snprintf(obj, objsize, "%s/f.so", dir);
  largv[a++] = "-o";
  largv[a++] = obj;
  for (size_t k = 0; k < n; k++) {
    snprintf(opath[k], sizeof opath[k], "%s/u%zu.o", dir, k);
    largv[a++] = opath[k];
  }
  largv[a++] = "-lm";
  largv[a] = NULL;
  int s = run(largv, msg, sizeof msg, &status, err);
  free(opath);
  free(largv);
  if (s != DM_OK)
    return s;
  if (status != 0)
    return cc_failed(err, "linking with ", ccargv[0], status, msg);
  return DM_OK;
}

void dm_native__remove_units(const char *dir, size_t n)
{
  char p[4200];
  for (size_t k = 0; k < n; k++) {
    snprintf(p, sizeof p, "%s/u%zu.c", dir, k);
    unlink(p);
    snprintf(p, sizeof p, "%s/u%zu.o", dir, k);
    unlink(p);
  }
  snprintf(p, sizeof p, "%s/f.so", dir);
  unlink(p);
  rmdir(dir);
}

/* The key: SHA-256 of the source, the compiler command, its --version
 * output and the flags. */
int dm_native__make_key(char **ccargv, int ncc, const char *src, char key[65],
                    dm_err *err)
{
  char *argv[40], ver[4096];
  int status;
  for (int i = 0; i < ncc; i++)
    argv[i] = ccargv[i];
  argv[ncc] = "--version";
  argv[ncc + 1] = NULL;
  int s = run(argv, ver, sizeof ver, &status, err);
  if (s != DM_OK)
    return s;
  if (status != 0) {
    char how[96];
    return dm_err_set(err, DM_ENOTFOUND, "native: '%s --version' failed "
                      "(%s)", ccargv[0], how_ended(status, how, sizeof how));
  }
  sha256 h;
  sha_init(&h);
  for (int i = 0; i < ncc; i++)
    sha_update(&h, ccargv[i], strlen(ccargv[i]) + 1);
  sha_update(&h, ver, strlen(ver) + 1);
  sha_update(&h, CC_FLAGS, sizeof CC_FLAGS);
  sha_update(&h, src, strlen(src));
  sha_hex(&h, key);
  return DM_OK;
}

