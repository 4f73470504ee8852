/* outfile.c -- write a file without destroying what is at its path (see
 * outfile.h). */
#include <config.h>
#include "core/outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/cleanup.h"
#include "core/interrupt.h"

#define SUFFIX_LEN 22     /* "." + ".<16 hex>" + ".tmp" */

const char *dm_outfile_kind(const char *path)
{
  struct stat st;
  if (lstat(path, &st) != 0)
    return "nothing";
  if (S_ISREG(st.st_mode)) return "a regular file";
  if (S_ISDIR(st.st_mode)) return "a directory";
  if (S_ISLNK(st.st_mode)) return "a symbolic link";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "a special file";
}

static uint64_t random64(void)
{
  static unsigned counter;
  uint64_t r = 0;
  struct timespec ts;
  if (getrandom(&r, sizeof r, GRND_NONBLOCK) == (ssize_t)sizeof r)
    return r;
  clock_gettime(CLOCK_REALTIME, &ts);
  return ((uint64_t)ts.tv_nsec << 20) ^ (uint64_t)ts.tv_sec
         ^ ((uint64_t)getpid() << 40)
         ^ (uint64_t)(++counter) * 0x9e3779b97f4a7c15ULL;
}

/* "<dir>/.<base>.<hex>.tmp" beside target, created O_EXCL; base shortened
 * (at a UTF-8 character boundary) so the name fits in NAME_MAX. */
static int make_temp(dm_outfile *o, dm_err *e)
{
  const char *t = o->target, *slash = strrchr(t, '/');
  size_t dirlen = slash != NULL ? (size_t)(slash - t + 1) : 0;
  const char *base = t + dirlen;
  size_t blen = strlen(base), n = strlen(t) + SUFFIX_LEN + 2;
  long name_max = 255;
  int attempt, fd = -1;
  if (dirlen > 0) {
    char *dir = strndup(t, dirlen);
    if (dir != NULL) {
      long m = pathconf(dir, _PC_NAME_MAX);
      if (m > SUFFIX_LEN + 8)
        name_max = m;
      free(dir);
    }
  } else {
    long m = pathconf(".", _PC_NAME_MAX);
    if (m > SUFFIX_LEN + 8)
      name_max = m;
  }
  if (blen > (size_t)name_max - SUFFIX_LEN) {
    blen = (size_t)name_max - SUFFIX_LEN;
    while (blen > 0 && ((unsigned char)base[blen] & 0xC0) == 0x80)
      blen--;
  }
  if ((o->tmp = malloc(n)) == NULL) {
    dm_err_set(e, DM_ENOMEM, "%s '%.200s': out of memory", o->what, o->path);
    return -1;
  }
  for (attempt = 0; attempt < 100; attempt++) {
    snprintf(o->tmp, n, "%.*s.%.*s.%016llx.tmp", (int)dirlen, t, (int)blen,
             base, (unsigned long long)random64());
    fd = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST)
      break;
  }
  if (fd < 0) {
    int err = errno;
    free(o->tmp);
    o->tmp = NULL;
    dm_err_set(e, DM_EIO, "%s '%.200s': cannot create a temporary file next "
               "to it: %s", o->what, o->path, strerror(err));
    return -1;
  }
  o->slot = dm_cleanup_add_file(o->tmp);
  return fd;
}

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Seconds to wait for a FIFO reader: $DMECH_FIFO_TIMEOUT or the default. */
static double fifo_wait(void)
{
  const char *env = getenv("DMECH_FIFO_TIMEOUT");
  char *end;
  double t = env != NULL ? strtod(env, &end) : -1;
  return env != NULL && end != env && t >= 0 && t < 1e6 ? t
         : DM_OUTFILE_FIFO_WAIT;
}

/* Open a FIFO or device for writing in place; a FIFO without a reader is
 * waited for. */
static int open_through(const dm_outfile *o, dm_err *e)
{
  double t0 = now(), wait = fifo_wait();
  for (;;) {
    int fd = open(o->target, O_WRONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd >= 0) {
      int fl = fcntl(fd, F_GETFL);
      if (fl >= 0)
        fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
      return fd;
    }
    if (errno != ENXIO)
      return dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                        strerror(errno)), -1;
    if (dm_interrupted())
      return dm_err_set(e, DM_EINTR, "%s '%.200s': interrupted while waiting "
                        "for a reader of the FIFO", o->what, o->path), -1;
    if (now() - t0 > wait)
      return dm_err_set(e, DM_EIO, "%s '%.200s': nobody reads this FIFO "
                        "(waited %g s)", o->what, o->path, wait), -1;
    usleep(20000);
  }
}

/* What is at the path: sets o->target and o->through, or refuses. */
static int classify(dm_outfile *o, dm_err *e)
{
  struct stat st;
  if (lstat(o->path, &st) != 0) {
    if (errno != ENOENT)
      return dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                        strerror(errno));
    o->target = strdup(o->path);
    return o->target != NULL ? DM_OK
           : dm_err_set(e, DM_ENOMEM, "%s: out of memory", o->what);
  }
  if (S_ISLNK(st.st_mode)) {
    o->target = realpath(o->path, NULL);
    if (o->target == NULL)
      return dm_err_set(e, DM_EINVAL, "%s '%.200s': the symbolic link %s",
                        o->what, o->path, errno == ENOENT
                        ? "points to nothing (a dangling link is not followed)"
                        : strerror(errno));
    if (stat(o->target, &st) != 0)
      return dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                        strerror(errno));
  } else if ((o->target = strdup(o->path)) == NULL) {
    return dm_err_set(e, DM_ENOMEM, "%s: out of memory", o->what);
  }
  if (S_ISREG(st.st_mode))
    return DM_OK;
  if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) {
    o->through = 1;
    return DM_OK;
  }
  return dm_err_set(e, DM_EINVAL, "%s '%.200s': is %s, not a file (only "
                    "regular files are replaced; FIFOs and character devices "
                    "are written through)", o->what, o->path,
                    S_ISDIR(st.st_mode) ? "a directory"
                    : S_ISBLK(st.st_mode) ? "a block device"
                    : S_ISSOCK(st.st_mode) ? "a socket" : "a special file");
}

static void release(dm_outfile *o)
{
  if (o->tmp != NULL)
    unlink(o->tmp);
  dm_cleanup_drop(o->slot);
  free(o->path);
  free(o->target);
  free(o->tmp);
  o->path = o->target = o->tmp = NULL;
  o->slot = -1;
}

int dm_outfile_open(dm_outfile *o, const char *path, const char *what,
                    int flags, const char *privdir, dm_err *e)
{
  int st, fd = -1;
  memset(o, 0, sizeof *o);
  o->slot = -1;
  o->what = what != NULL ? what : "writing";
  if (path == NULL || path[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "%s: empty file name", o->what);
  if (path[strlen(path) - 1] == '/')
    return dm_err_set(e, DM_EINVAL, "%s '%.200s': is a directory name",
                      o->what, path);
  if ((o->path = strdup(path)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "%s: out of memory", o->what);
  if ((st = classify(o, e)) != DM_OK)
    goto fail;
  if (o->through && (flags & DM_OUTFILE_NAMED)) {
    size_t n;
    if (privdir == NULL) {
      st = dm_err_set(e, DM_EINVAL, "%s '%.200s': is %s; this format needs a "
                      "regular file", o->what, path, dm_outfile_kind(o->target));
      goto fail;
    }
    n = strlen(privdir) + 16;
    if ((o->tmp = malloc(n)) == NULL) {
      st = dm_err_set(e, DM_ENOMEM, "%s: out of memory", o->what);
      goto fail;
    }
    snprintf(o->tmp, n, "%s/.out-XXXXXX", privdir);
    if ((fd = mkstemp(o->tmp)) < 0) {
      st = dm_err_set(e, DM_EIO, "%s '%.200s': cannot create a temporary "
                      "file in %.200s: %s", o->what, path, privdir,
                      strerror(errno));
      free(o->tmp);
      o->tmp = NULL;
      goto fail;
    }
    o->slot = dm_cleanup_add_file(o->tmp);
  } else if (o->through) {
    fd = open_through(o, e);
  } else {
    fd = make_temp(o, e);
  }
  if (fd < 0) {
    st = e != NULL ? e->status : DM_EIO;
    goto fail;
  }
  if (flags & DM_OUTFILE_NAMED) {
    close(fd);
    return DM_OK;
  }
  if ((o->f = fdopen(fd, "w")) == NULL) {
    st = dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, path,
                    strerror(errno));
    close(fd);
    goto fail;
  }
  return DM_OK;
fail:
  release(o);
  return st;
}

/* Copy the named temporary into the device or FIFO. */
static int copy_through(dm_outfile *o, dm_err *e)
{
  char buf[65536];
  int in = open(o->tmp, O_RDONLY | O_CLOEXEC), out, st = DM_OK;
  ssize_t r;
  if (in < 0)
    return dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                      strerror(errno));
  if ((out = open_through(o, e)) < 0) {
    close(in);
    return e != NULL ? e->status : DM_EIO;
  }
  while (st == DM_OK && (r = read(in, buf, sizeof buf)) != 0) {
    size_t off = 0;
    if (r < 0 && errno == EINTR)
      continue;
    if (r < 0) {
      st = dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                      strerror(errno));
      break;
    }
    while (off < (size_t)r) {
      ssize_t w = write(out, buf + off, (size_t)r - off);
      if (w < 0 && errno == EINTR)
        continue;
      if (w <= 0) {
        st = dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                        strerror(w < 0 ? errno : EIO));
        break;
      }
      off += (size_t)w;
    }
  }
  close(in);
  if (close(out) != 0 && st == DM_OK)
    st = dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                    strerror(errno));
  return st;
}

/* Flush and close o->f; fsync first when it is a temporary file. */
static int close_stream(dm_outfile *o, dm_err *e)
{
  int st = DM_OK, bad;
  FILE *f = o->f;
  o->f = NULL;
  errno = 0;
  bad = fflush(f) != 0 || ferror(f);
  if (bad)
    st = dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                    strerror(errno ? errno : EIO));
  if (st == DM_OK && !o->through && fsync(fileno(f)) != 0)
    st = dm_err_set(e, DM_EIO, "%s '%.200s': fsync: %s", o->what, o->path,
                    strerror(errno));
  if (fclose(f) != 0 && st == DM_OK)
    st = dm_err_set(e, DM_EIO, "%s '%.200s': %s", o->what, o->path,
                    strerror(errno));
  return st;
}

/* fsync the directory holding path so that the rename is durable; a
 * failure is not reported (the data are safe, only the name may lag). */
static void sync_dir(const char *path)
{
  const char *slash = strrchr(path, '/');
  char *dir = slash == NULL ? strdup(".")
              : strndup(path, slash == path ? 1 : (size_t)(slash - path));
  int fd;
  if (dir == NULL)
    return;
  fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    fsync(fd);
    close(fd);
  }
  free(dir);
}

int dm_outfile_commit(dm_outfile *o, dm_err *e)
{
  struct stat st;
  int rc = DM_OK;
  if (o->path == NULL)
    return DM_OK;
  if (o->f != NULL)
    rc = close_stream(o, e);
  if (rc == DM_OK && o->through && o->tmp != NULL)
    rc = copy_through(o, e);
  if (rc == DM_OK && !o->through && o->f == NULL) {
    int fd = open(o->tmp, O_RDONLY | O_CLOEXEC);    /* written by another */
    if (fd >= 0) {                                  /* process: make it */
      fsync(fd);                                    /* durable too */
      close(fd);
    }
  }
  if (rc == DM_OK && !o->through) {
    if (lstat(o->target, &st) == 0 && !S_ISREG(st.st_mode))
      rc = dm_err_set(e, DM_EINVAL, "%s '%.200s': %s appeared there while "
                      "writing; not replaced", o->what, o->path,
                      dm_outfile_kind(o->target));
    else if (rename(o->tmp, o->target) != 0)
      rc = dm_err_set(e, DM_EIO, "%s '%.200s': cannot rename the temporary "
                      "file: %s", o->what, o->path, strerror(errno));
    else {
      free(o->tmp);            /* renamed: nothing to remove any more */
      o->tmp = NULL;
      sync_dir(o->target);
    }
  }
  release(o);
  return rc;
}

void dm_outfile_abandon(dm_outfile *o)
{
  if (o->f != NULL) {
    fclose(o->f);
    o->f = NULL;
  }
  if (o->path != NULL)
    release(o);
}
