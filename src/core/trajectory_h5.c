/* trajectory_h5.c -- trajectories to and from HDF5 files: one dataset per
 * column, metadata as root attributes, atomic replacement, and the
 * collective write of a table every MPI rank holds.  See trajectory_h5.h. */
#include <config.h>
#include "core/trajectory_h5.h"
#include "core/trajectory_h5_impl.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <hdf5.h>

#include "core/interrupt.h"
#include "core/outfile.h"
#include "core/mpi.h"

#if defined(H5_HAVE_PARALLEL) && defined(DM_HAVE_MPI)
#define DM_H5_PARALLEL 1
#include <mpi.h>
#endif

#define FORMAT_KEY "dmech.format"
#define FORMAT "trajectory 1"

static pthread_mutex_t h5_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_once_t h5_once = PTHREAD_ONCE_INIT;
static char h5_version[32];

static void h5_init(void)
{
  unsigned maj = 0, min = 0, rel = 0;
  H5open();
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  H5get_libversion(&maj, &min, &rel);
  snprintf(h5_version, sizeof h5_version, "%u.%u.%u", maj, min, rel);
}

static void lock(void)
{
  pthread_once(&h5_once, h5_init);
  pthread_mutex_lock(&h5_lock);
}

static void unlock(void)
{
  pthread_mutex_unlock(&h5_lock);
}

const char *dm_h5_version(void)
{
  pthread_once(&h5_once, h5_init);
  return h5_version;
}

const char *dm_h5_mode(void)
{
#ifdef DM_H5_PARALLEL
  return "parallel (MPI-IO)";
#else
  return "serial (gathered to rank 0)";
#endif
}

int dm_h5_is_hdf5(const char *path)
{
  static const unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
  unsigned char buf[8];
  int fd = open(path, O_RDONLY | O_CLOEXEC), ok;
  if (fd < 0)
    return 0;
  ok = read(fd, buf, 8) == 8 && memcmp(buf, sig, 8) == 0;
  close(fd);
  return ok;
}

int dm_h5_wanted(const char *path)
{
  static const char *const ext[] = {".h5", ".hdf5", ".he5", NULL};
  size_t lp = strlen(path);
  const char *const *x;
  for (x = ext; *x != NULL; x++) {
    size_t lx = strlen(*x);
    if (lp > lx && strcmp(path + lp - lx, *x) == 0)
      return 1;
  }
  return 0;
}

/* {==== errors =========================================================== */

typedef struct h5msg {
  char text[256];
  int got;
} h5msg;

static herr_t take_innermost(unsigned n, const H5E_error2_t *err, void *data)
{
  h5msg *m = data;
  (void)n;
  if (!m->got && err->desc != NULL) {
    snprintf(m->text, sizeof m->text, "%s", err->desc);
    m->got = 1;
  }
  return 0;
}

/* "saving|reading '<path>': <what> (HDF5: <its innermost message>)" into
 * e; clears HDF5's stack.  what starting with "cannot create|write|close"
 * is about saving. */
static int h5_fail(dm_err *e, int st, const char *path, const char *what)
{
  const char *verb = strstr(what, "read") || strstr(what, "open") || strstr(what, "list")
                     || strstr(what, "not an") ? "reading" : "saving";
  h5msg m;
  memset(&m, 0, sizeof m);
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, take_innermost, &m);
  H5Eclear2(H5E_DEFAULT);
  if (m.got)
    return dm_err_set(e, st, "%s '%.200s': %s (HDF5: %.200s)", verb, path, what, m.text);
  return dm_err_set(e, st, "%s '%.200s': %s", verb, path, what);
}

/* }====================================================================== */

/* {==== writing ========================================================== */

static hid_t string_type(void)
{
  hid_t t = H5Tcopy(H5T_C_S1);
  if (t >= 0 && (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0)) {
    H5Tclose(t);
    return -1;
  }
  return t;
}

/* A fixed-length (not variable-length) UTF-8 string: variable-length
 * strings live in the file's global heap, whose reader in libhdf5 1.10
 * crashes on damaged files (found by fuzzing dm.load_trajectory); h5py
 * reads these as bytes (.decode() gives the str). */
static int put_string(hid_t obj, const char *name, const char *value)
{
  hid_t t = H5Tcopy(H5T_C_S1), sp = H5Screate(H5S_SCALAR), a = -1;
  int ok = 0;
  if (t >= 0 && (H5Tset_size(t, strlen(value) + 1) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0
                 || H5Tset_strpad(t, H5T_STR_NULLTERM) < 0)) {
    H5Tclose(t);
    t = -1;
  }
  if (t >= 0 && sp >= 0)
    a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
  if (a >= 0)
    ok = H5Awrite(a, t, value) >= 0;
  if (a >= 0)
    H5Aclose(a);
  if (sp >= 0)
    H5Sclose(sp);
  if (t >= 0)
    H5Tclose(t);
  return ok;
}

static int put_number(hid_t obj, const char *name, double x)
{
  hid_t sp = H5Screate(H5S_SCALAR), a = -1;
  int ok = 0;
  if (sp >= 0)
    a = H5Acreate2(obj, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
  if (a >= 0)
    ok = H5Awrite(a, H5T_NATIVE_DOUBLE, &x) >= 0;
  if (a >= 0)
    H5Aclose(a);
  if (sp >= 0)
    H5Sclose(sp);
  return ok;
}

static int check_names(const dm_traj *tr, const char *path, dm_err *e)
{
  size_t j, i;
  for (j = 0; j < dm_traj_ncols(tr); j++)
    if (strchr(dm_traj_colname(tr, j), '/') != NULL)
      return dm_err_set(e, DM_EINVAL, "saving '%.200s': column '%.100s' cannot name an HDF5 "
                        "dataset (it contains '/')", path, dm_traj_colname(tr, j));
  for (i = 0; i < dm_traj_meta_count(tr); i++) {
    const char *k, *v;
    dm_traj_meta_at(tr, i, &k, &v);
    if (strcmp(k, FORMAT_KEY) == 0)
      return dm_err_set(e, DM_EINVAL, "saving '%.200s': the metadata key '%s' is reserved for "
                        "the file format", path, FORMAT_KEY);
  }
  return DM_OK;
}

/* The root attributes: the format, then tr's metadata in order. */
static int write_attrs(hid_t f, const dm_traj *tr, const char *path, dm_err *e)
{
  if (!put_string(f, FORMAT_KEY, FORMAT))
    return h5_fail(e, DM_EIO, path, "cannot write the attribute " FORMAT_KEY);
  for (size_t i = 0; i < dm_traj_meta_count(tr); i++) {
    const char *k, *v;
    double x;
    int ok;
    dm_traj_meta_at(tr, i, &k, &v);
    ok = dm_traj_meta_number_at(tr, i, &x) ? put_number(f, k, x) : put_string(f, k, v);
    if (!ok)
      return h5_fail(e, DM_EIO, path, "cannot write a metadata attribute");
  }
  return DM_OK;
}

/* Root attributes and one dataset per column, of which this process
 * writes rows first, first + stride, ... (0, 1: all); the same selection in
 * memory (tr holds every row) and in the file.  dxpl: the transfer
 * property list (collective under MPI-IO). */
static int write_columns(hid_t f, const dm_traj *tr, size_t first, size_t stride, hid_t dxpl,
                         hid_t dcpl, const char *path, dm_err *e);

static int write_file(hid_t f, const dm_traj *tr, size_t first, size_t stride, hid_t dxpl,
                      const char *path, dm_err *e)
{
  int st = DM_OK;
  /* every value is written: no fill values first (they would double the
   * bytes written) */
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (dcpl < 0 || H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER) < 0) {
    if (dcpl >= 0)
      H5Pclose(dcpl);
    return h5_fail(e, DM_EIO, path, "cannot set up a dataset");
  }
  st = write_columns(f, tr, first, stride, dxpl, dcpl, path, e);
  H5Pclose(dcpl);
  return st;
}

static int write_columns(hid_t f, const dm_traj *tr, size_t first, size_t stride, hid_t dxpl,
                         hid_t dcpl, const char *path, dm_err *e)
{
  size_t i, j, len = dm_traj_len(tr);
  hsize_t dims[1] = {len}, start[1] = {first}, step[1] = {stride};
  hsize_t count[1] = {len > first ? (len - first + stride - 1) / stride : 0};
  int st = write_attrs(f, tr, path, e);
  if (st != DM_OK)
    return st;
  (void)i;
  for (j = 0; j < dm_traj_ncols(tr); j++) {
    hid_t fs = H5Screate_simple(1, dims, NULL), ms = -1, d = -1;
    int ok = 0;
    if (dm_interrupted()) {
      if (fs >= 0)
        H5Sclose(fs);
      return dm_err_set(e, DM_EINTR, "saving '%.200s': interrupted", path);
    }
    if (fs >= 0)
      d = H5Dcreate2(f, dm_traj_colname(tr, j), H5T_IEEE_F64LE, fs, H5P_DEFAULT, dcpl,
                     H5P_DEFAULT);
    if (d >= 0 && put_string(d, "kind", dm_traj_kindname(dm_traj_colkind(tr, j)))) {
      ok = 1;
      if (len > 0) {
        ms = H5Screate_simple(1, dims, NULL);
        if (count[0] > 0)
          ok = ms >= 0 && H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, step, count, NULL) >= 0
               && H5Sselect_hyperslab(ms, H5S_SELECT_SET, start, step, count, NULL) >= 0;
        else
          ok = ms >= 0 && H5Sselect_none(fs) >= 0 && H5Sselect_none(ms) >= 0;
        if (ok)
          ok = H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, dxpl, dm_traj_col(tr, j)) >= 0;
      }
    }
    if (ms >= 0)
      H5Sclose(ms);
    if (d >= 0)
      H5Dclose(d);
    if (fs >= 0)
      H5Sclose(fs);
    if (!ok)
      return h5_fail(e, DM_EIO, path, "cannot write a column");
  }
  return DM_OK;
}

/* A new temporary name next to path: "<path>.tmp-<random>", created empty
 * and exclusively (so a guessed name is harmless). */
static char *temp_name(const char *path, dm_err *e)
{
  static unsigned counter;
  size_t lp = strlen(path);
  char *tmp = malloc(lp + 32);
  int attempt;
  if (tmp == NULL) {
    dm_err_set(e, DM_ENOMEM, "saving '%.200s': out of memory", path);
    return NULL;
  }
  for (attempt = 0; attempt < 100; attempt++) {
    struct timespec ts;
    uint64_t r;
    int fd;
    clock_gettime(CLOCK_REALTIME, &ts);
    r = ((uint64_t)ts.tv_nsec << 20) ^ (uint64_t)ts.tv_sec ^ ((uint64_t)getpid() << 40)
        ^ (uint64_t)(++counter) * 0x9e3779b97f4a7c15ULL;
    snprintf(tmp, lp + 32, "%s.tmp-%016llx", path, (unsigned long long)r);
    fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      close(fd);
      return tmp;
    }
    if (errno != EEXIST)
      break;
  }
  dm_err_set(e, DM_EIO, "saving '%.200s': cannot create a temporary file next to it: %s", path,
             strerror(errno));
  free(tmp);
  return NULL;
}

/* fsync the finished temporary file, rename it over path, fsync the
 * directory. */
static int publish(const char *tmp, const char *path, dm_err *e)
{
  int fd = open(tmp, O_RDONLY | O_CLOEXEC), ok;
  const char *slash;
  char dir[4096];
  if (fd < 0)
    return dm_err_set(e, DM_EIO, "saving '%.200s': %s", path, strerror(errno));
  ok = fsync(fd) == 0;
  close(fd);
  if (!ok)
    return dm_err_set(e, DM_EIO, "saving '%.200s': fsync: %s", path, strerror(errno));
  if (rename(tmp, path) != 0)
    return dm_err_set(e, DM_EIO, "saving '%.200s': cannot rename the temporary file: %s", path,
                      strerror(errno));
  slash = strrchr(path, '/');
  snprintf(dir, sizeof dir, "%.*s", slash == NULL ? 1 : slash == path ? 1 : (int)(slash - path),
           slash == NULL ? "." : path);
  if ((fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) >= 0) {
    fsync(fd);
    close(fd);
  }
  return DM_OK;
}

/* The file creation list: link and attribute creation order tracked on the
 * root group, so columns and metadata come back in their order. */
/* File access for the temporary file being written: without HDF5's file
 * lock.  Nobody else knows the file's name before it is renamed into
 * place, so the lock protects nothing; but flock locks belong to the open
 * file, so a child forked by another thread while the file is open (a
 * compiler started in the background) keeps a copy of the descriptor and
 * with it the exclusive lock after H5Fclose, and reading the published
 * file then fails ("unable to lock file, errno = 11") until the child has
 * closed it.  Readers keep their shared lock: it only conflicts with an
 * exclusive one. */
static hid_t unlocked_fapl(void)
{
  hid_t p = H5Pcreate(H5P_FILE_ACCESS);
#if (H5_VERS_MAJOR == 1 && H5_VERS_MINOR == 10 && H5_VERS_RELEASE >= 7) \
    || H5_VERSION_GE(1, 12, 1)
  if (p >= 0)
    H5Pset_file_locking(p, 0, 1);
#endif
  return p;
}

static hid_t ordered_fcpl(void)
{
  hid_t p = H5Pcreate(H5P_FILE_CREATE);
  if (p >= 0) {
    H5Pset_link_creation_order(p, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
    H5Pset_attr_creation_order(p, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  }
  return p;
}

int dm_traj_save_h5(const dm_traj *tr, const char *path, dm_err *e)
{
  dm_outfile o;                 /* core/outfile.h: what may be replaced */
  hid_t fcpl, fapl, f;
  int st;
  if (path == NULL || path[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "save: empty file name");
  if ((st = check_names(tr, path, e)) != DM_OK)
    return st;
  if ((st = dm_outfile_open(&o, path, "saving", DM_OUTFILE_NAMED, NULL, e)) != DM_OK)
    return st;
  lock();
  fcpl = ordered_fcpl();
  fapl = unlocked_fapl();
  f = H5Fcreate(o.tmp, H5F_ACC_TRUNC, fcpl, fapl >= 0 ? fapl : H5P_DEFAULT);
  if (f < 0)
    st = h5_fail(e, DM_EIO, path, "cannot create the HDF5 file");
  else
    st = write_file(f, tr, 0, 1, H5P_DEFAULT, path, e);
  if (f >= 0 && H5Fclose(f) < 0 && st == DM_OK)
    st = h5_fail(e, DM_EIO, path, "cannot close the HDF5 file");
  if (fapl >= 0)
    H5Pclose(fapl);
  if (fcpl >= 0)
    H5Pclose(fcpl);
  unlock();
  if (st != DM_OK) {
    dm_outfile_abandon(&o);
    return st;
  }
  return dm_outfile_commit(&o, e);
}

/* }====================================================================== */

/* {==== reading ========================================================== */

typedef struct col {
  char *name;
  int kind;               /* enum dm_traj_kind; -1: not given */
  double *x;
} col;

typedef struct meta {
  char *key, *text;       /* text NULL: a number */
  double x;
} meta;

typedef struct reader {
  const char *path;
  dm_err *e;
  int st;
  col *cols;
  size_t ncols, cap, len;
  meta *meta;
  size_t nmeta, mcap;
} reader;

/* A string attribute (fixed or variable length) as a malloc'ed string, or
 * NULL when it is not a scalar string. */
static char *get_string(hid_t a)
{
  hid_t t = H5Aget_type(a), sp = H5Aget_space(a), mt = -1;
  char *out = NULL;
  if (t < 0 || sp < 0 || H5Tget_class(t) != H5T_STRING || H5Sget_simple_extent_npoints(sp) != 1)
    goto done;
  if (H5Tis_variable_str(t) > 0) {
    char *s = NULL;
    mt = string_type();
    if (mt >= 0 && H5Aread(a, mt, &s) >= 0 && s != NULL) {
      out = strdup(s);
      H5free_memory(s);
    }
  } else {
    size_t n = H5Tget_size(t);
    H5T_cset_t cs = H5Tget_cset(t);
    mt = H5Tcopy(H5T_C_S1);
    if (mt >= 0 && H5Tset_size(mt, n + 1) >= 0 && (cs < 0 || H5Tset_cset(mt, cs) >= 0)
        && (out = calloc(n + 2, 1)) != NULL
        && H5Aread(a, mt, out) < 0) {
      free(out);
      out = NULL;
    }
  }
done:
  if (mt >= 0)
    H5Tclose(mt);
  if (sp >= 0)
    H5Sclose(sp);
  if (t >= 0)
    H5Tclose(t);
  return out;
}

static int kind_of(const char *s)
{
  int k;
  for (k = DM_TRAJ_T; k <= DM_TRAJ_DATA; k++)
    if (strcmp(s, dm_traj_kindname(k)) == 0)
      return k;
  return -1;
}

static herr_t on_attr(hid_t loc, const char *name, const H5A_info_t *info, void *data)
{
  reader *r = data;
  hid_t a, t, sp;
  meta *m;
  (void)info;
  if (strcmp(name, FORMAT_KEY) == 0)
    return 0;
  if (r->nmeta == r->mcap) {
    size_t cap = r->mcap ? 2 * r->mcap : 16;
    meta *nm = realloc(r->meta, cap * sizeof *nm);
    if (nm == NULL) {
      r->st = dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
      return -1;
    }
    r->meta = nm;
    r->mcap = cap;
  }
  if ((a = H5Aopen(loc, name, H5P_DEFAULT)) < 0)
    return 0;
  t = H5Aget_type(a);
  sp = H5Aget_space(a);
  m = &r->meta[r->nmeta];
  memset(m, 0, sizeof *m);
  if (t >= 0 && sp >= 0 && H5Sget_simple_extent_npoints(sp) == 1
      && (H5Tget_class(t) == H5T_FLOAT || H5Tget_class(t) == H5T_INTEGER)) {
    if (H5Aread(a, H5T_NATIVE_DOUBLE, &m->x) >= 0 && (m->key = strdup(name)) != NULL)
      r->nmeta++;
  } else if ((m->text = get_string(a)) != NULL) {     /* other types: skipped */
    if ((m->key = strdup(name)) != NULL)
      r->nmeta++;
    else
      free(m->text);
  }
  if (sp >= 0)
    H5Sclose(sp);
  if (t >= 0)
    H5Tclose(t);
  H5Aclose(a);
  return 0;
}

static herr_t on_link(hid_t g, const char *name, const H5L_info_t *info, void *data)
{
  reader *r = data;
  hid_t o, sp = -1, t = -1;
  hssize_t npts;
  col *c;
  (void)info;
  if ((o = H5Oopen(g, name, H5P_DEFAULT)) < 0)
    return 0;
  if (H5Iget_type(o) != H5I_DATASET) {
    H5Oclose(o);
    return 0;                      /* groups and named types: not columns */
  }
  sp = H5Dget_space(o);
  t = H5Dget_type(o);
  if (sp < 0 || t < 0 || H5Sget_simple_extent_ndims(sp) != 1
      || (H5Tget_class(t) != H5T_FLOAT && H5Tget_class(t) != H5T_INTEGER)) {
    r->st = dm_err_set(r->e, DM_EINVAL, "reading '%.200s': dataset '%.100s' is not a column "
                       "(expected a 1-D array of numbers)", r->path, name);
    goto fail;
  }
  npts = H5Sget_simple_extent_npoints(sp);
  if (r->ncols > 0 && (size_t)npts != r->len) {
    r->st = dm_err_set(r->e, DM_EINVAL, "reading '%.200s': dataset '%.100s' has %lld values, "
                       "'%.100s' has %zu: the columns must have one length", r->path, name,
                       (long long)npts, r->cols[0].name, r->len);
    goto fail;
  }
  /* a damaged type may announce numbers of gigabytes, and HDF5 fills a
   * buffer of that size before it fails: refused before any allocation */
  if (H5Tget_size(t) == 0 || H5Tget_size(t) > 16) {
    r->st = dm_err_set(r->e, DM_EINVAL, "reading '%.200s': dataset '%.100s' has numbers of "
                       "%zu bytes (a damaged file?)", r->path, name, H5Tget_size(t));
    goto fail;
  }
  r->len = (size_t)npts;
  if (r->ncols == r->cap) {
    size_t cap = r->cap ? 2 * r->cap : 16;
    col *nc = realloc(r->cols, cap * sizeof *nc);
    if (nc == NULL)
      goto nomem;
    r->cols = nc;
    r->cap = cap;
  }
  c = &r->cols[r->ncols];
  c->kind = -1;
  c->name = strdup(name);
  c->x = malloc((r->len ? r->len : 1) * sizeof *c->x);
  if (c->name == NULL || c->x == NULL) {
    free(c->name);
    free(c->x);
    goto nomem;
  }
  r->ncols++;
  if (r->len > 0 && H5Dread(o, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, c->x) < 0) {
    r->st = h5_fail(r->e, DM_EIO, r->path, "cannot read a column");
    goto fail;
  }
  if (H5Aexists(o, "kind") > 0) {
    hid_t a = H5Aopen(o, "kind", H5P_DEFAULT);
    char *k = a >= 0 ? get_string(a) : NULL;
    if (a >= 0)
      H5Aclose(a);
    if (k != NULL && (c->kind = kind_of(k)) < 0) {
      r->st = dm_err_set(r->e, DM_EINVAL, "reading '%.200s': column '%.100s' has the unknown "
                         "kind '%.40s' (expected t, q, p, v, diag, derived or data)", r->path,
                         name, k);
      free(k);
      goto fail;
    }
    free(k);
  }
  H5Tclose(t);
  H5Sclose(sp);
  H5Oclose(o);
  return dm_interrupted() ? (r->st = dm_err_set(r->e, DM_EINTR, "reading '%.200s': "
                                                "interrupted", r->path), -1) : 0;
nomem:
  r->st = dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
fail:
  if (t >= 0)
    H5Tclose(t);
  if (sp >= 0)
    H5Sclose(sp);
  H5Oclose(o);
  return -1;
}

static long find_col(const reader *r, const char *name, int kind)
{
  size_t j;
  for (j = 0; j < r->ncols; j++)
    if (strcmp(r->cols[j].name, name) == 0 && (kind < 0 || r->cols[j].kind == kind))
      return (long)j;
  return -1;
}

/* The trajectory from the columns read: t, q, [p], [v], the rest extra. */
static dm_traj *build(reader *r)
{
  size_t n = 0, np = 0, nv = 0, m, j, i, k, ne = 0;
  long jt = find_col(r, "t", -1), *jq = NULL, *jp = NULL, *jv = NULL, *je = NULL;
  unsigned flags = 0;
  const char **coords = NULL, **pnames, **vnames;
  int named = 0;
  double *buf = NULL;
  dm_traj *tr = NULL;
  char want[DM_TRAJ_NAME_MAX + 8];
  int st = DM_OK;
  if (jt < 0 || (r->cols[jt].kind >= 0 && r->cols[jt].kind != DM_TRAJ_T)) {
    dm_err_set(r->e, DM_EINVAL, "reading '%.200s': no time column (a dataset 't'%s)", r->path,
               jt >= 0 ? " of kind t" : "");
    return NULL;
  }
  for (j = 0; j < r->ncols; j++) {
    n += r->cols[j].kind == DM_TRAJ_Q;
    np += r->cols[j].kind == DM_TRAJ_P;
    nv += r->cols[j].kind == DM_TRAJ_V;
  }
  m = n > np ? n : np;
  m = m > nv ? m : nv;
  jq = calloc(n + 1, sizeof *jq);
  jp = calloc(m + 1, sizeof *jp);
  jv = calloc(m + 1, sizeof *jv);
  je = calloc(r->ncols + 1, sizeof *je);
  coords = calloc(n + 2 * m + 1, sizeof *coords);
  buf = calloc(n + 2 * m + r->ncols + 1, sizeof *buf);
  if (jq == NULL || jp == NULL || jv == NULL || je == NULL || coords == NULL || buf == NULL) {
    dm_err_set(r->e, DM_ENOMEM, "reading '%.200s': out of memory", r->path);
    goto done;
  }
  pnames = coords + n;
  vnames = pnames + m;
  for (j = 0, i = 0; j < r->ncols; j++)
    if (r->cols[j].kind == DM_TRAJ_Q) {
      jq[i] = (long)j;
      coords[i++] = r->cols[j].name;
    }
  /* named momenta: the p (v) columns do not start with "p_" ("v_") */
  for (j = 0; j < r->ncols && !named; j++)
    named = (r->cols[j].kind == DM_TRAJ_P && strncmp(r->cols[j].name, "p_", 2) != 0)
            || (r->cols[j].kind == DM_TRAJ_V && strncmp(r->cols[j].name, "v_", 2) != 0);
  if (named) {
    size_t a = 0, b = 0;
    if (np > 0 && nv > 0 && np != nv) {
      dm_err_set(r->e, DM_EINVAL, "reading '%.200s': %zu velocity columns for %zu momentum "
                 "columns", r->path, nv, np);
      goto done;
    }
    for (j = 0; j < r->ncols; j++)
      if (r->cols[j].kind == DM_TRAJ_P) {
        jp[a] = (long)j;
        pnames[a++] = r->cols[j].name;
      } else if (r->cols[j].kind == DM_TRAJ_V) {
        jv[b] = (long)j;
        vnames[b++] = r->cols[j].name;
      }
    np = np > 0 ? np : nv;
    flags = (a > 0 ? DM_TRAJ_WITH_P : 0u) | (b > 0 ? DM_TRAJ_WITH_V : 0u);
  } else {
    for (i = 0; i < n; i++) {
      snprintf(want, sizeof want, "p_%s", coords[i]);
      jp[i] = find_col(r, want, DM_TRAJ_P);
      snprintf(want, sizeof want, "v_%s", coords[i]);
      jv[i] = find_col(r, want, DM_TRAJ_V);
    }
    for (k = 0; k < 2; k++) {
      long *jj = k == 0 ? jp : jv;
      size_t have = 0, total = k == 0 ? np : nv;
      for (i = 0; i < n; i++)
        have += jj[i] >= 0;
      if (total > 0 && (have != n || total != n)) {
        dm_err_set(r->e, DM_EINVAL, "reading '%.200s': the %s columns do not match the "
                   "coordinates (expected %s_<coordinate> for each of the %zu)", r->path,
                   k == 0 ? "momentum" : "velocity", k == 0 ? "p" : "v", n);
        goto done;
      }
      if (total > 0)
        flags |= k == 0 ? DM_TRAJ_WITH_P : DM_TRAJ_WITH_V;
    }
    np = n;
  }
  tr = named ? dm_traj_alloc_state(n, coords, np, (flags & DM_TRAJ_WITH_P) ? pnames : NULL,
                                   (flags & DM_TRAJ_WITH_V) ? vnames : NULL, flags, r->e)
             : dm_traj_alloc(n, coords, flags, r->e);
  if (tr == NULL)
    goto done;
  for (j = 0; j < r->ncols && st == DM_OK; j++) {
    int kd = r->cols[j].kind;
    if ((long)j == jt || kd == DM_TRAJ_Q || kd == DM_TRAJ_P || kd == DM_TRAJ_V)
      continue;
    if (kd == DM_TRAJ_T) {
      st = dm_err_set(r->e, DM_EINVAL, "reading '%.200s': a second time column '%.100s'",
                      r->path, r->cols[j].name);
      break;
    }
    je[ne++] = (long)j;
    st = dm_traj_add_column(tr, r->cols[j].name, kd < 0 ? DM_TRAJ_DATA : kd, NULL, 0, r->e);
  }
  for (i = 0; i < r->nmeta && st == DM_OK; i++)
    st = r->meta[i].text != NULL ? dm_traj_meta_set(tr, r->meta[i].key, r->meta[i].text, r->e)
                                 : dm_traj_meta_set_number(tr, r->meta[i].key, r->meta[i].x,
                                                           r->e);
  if (st == DM_OK)
    st = dm_traj_reserve(tr, r->len, r->e);
  for (k = 0; k < r->len && st == DM_OK; k++) {
    double *q = buf, *p = q + n, *v = p + np, *x = v + np;
    for (i = 0; i < n; i++)
      q[i] = r->cols[jq[i]].x[k];
    for (i = 0; i < np; i++) {
      p[i] = flags & DM_TRAJ_WITH_P ? r->cols[jp[i]].x[k] : NAN;
      v[i] = flags & DM_TRAJ_WITH_V ? r->cols[jv[i]].x[k] : NAN;
    }
    for (i = 0; i < ne; i++)
      x[i] = r->cols[je[i]].x[k];
    st = dm_traj_append(tr, r->cols[jt].x[k], q, p, v, x, r->e);
  }
  if (st != DM_OK) {
    dm_traj_free(tr);
    tr = NULL;
  }
done:
  free(jq), free(jp), free(jv), free(je), free(coords), free(buf);
  return tr;
}

dm_traj *dm_traj_load_h5(const char *path, dm_err *e)
{
  reader r;
  hid_t f;
  hsize_t idx = 0;
  dm_traj *tr = NULL;
  size_t j;
  memset(&r, 0, sizeof r);
  r.path = path;
  r.e = e;
  if (access(path, R_OK) != 0) {
    dm_err_set(e, DM_EIO, "reading '%.200s': %s", path, strerror(errno));
    return NULL;
  }
  lock();
  if ((f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT)) < 0) {
    h5_fail(e, DM_EIO, path, dm_h5_is_hdf5(path) ? "cannot open the HDF5 file"
                                                 : "not an HDF5 file");
    unlock();
    return NULL;
  }
  if (H5Literate(f, H5_INDEX_CRT_ORDER, H5_ITER_INC, &idx, on_link, &r) < 0 && r.st == DM_OK) {
    H5Eclear2(H5E_DEFAULT);
    for (j = 0; j < r.ncols; j++)
      free(r.cols[j].name), free(r.cols[j].x);
    r.ncols = 0;
    idx = 0;
    if (H5Literate(f, H5_INDEX_NAME, H5_ITER_INC, &idx, on_link, &r) < 0 && r.st == DM_OK)
      r.st = h5_fail(e, DM_EIO, path, "cannot list the datasets");
  }
  idx = 0;
  if (r.st == DM_OK
      && H5Aiterate2(f, H5_INDEX_CRT_ORDER, H5_ITER_INC, &idx, on_attr, &r) < 0 && r.st == DM_OK) {
    H5Eclear2(H5E_DEFAULT);
    for (j = 0; j < r.nmeta; j++)
      free(r.meta[j].key), free(r.meta[j].text);
    r.nmeta = 0;
    idx = 0;
    if (H5Aiterate2(f, H5_INDEX_NAME, H5_ITER_INC, &idx, on_attr, &r) < 0 && r.st == DM_OK)
      r.st = h5_fail(e, DM_EIO, path, "cannot list the attributes");
  }
  H5Fclose(f);
  unlock();
  if (r.st == DM_OK)
    tr = build(&r);
  for (j = 0; j < r.ncols; j++)
    free(r.cols[j].name), free(r.cols[j].x);
  for (j = 0; j < r.nmeta; j++)
    free(r.meta[j].key), free(r.meta[j].text);
  free(r.cols);
  free(r.meta);
  return tr;
}

/* }====================================================================== */

/* {==== by name or content; the collective save ======================= */

int dm_traj_save_any(const dm_traj *tr, const char *path, dm_err *e)
{
  if (path != NULL && dm_h5_wanted(path))
    return dm_traj_save_h5(tr, path, e);
  return dm_traj_save(tr, path, e);
}

dm_traj *dm_traj_load_any(const char *path, dm_err *e)
{
  if (path != NULL && (dm_h5_is_hdf5(path) || (dm_h5_wanted(path) && access(path, F_OK) != 0)))
    return dm_traj_load_h5(path, e);
  return dm_traj_load(path, e);
}

#ifdef DM_H5_PARALLEL
/* Every rank writes its rows into the one file through MPI-IO: the file and
 * its datasets are created collectively, the rows of each column written in
 * one collective transfer. */
static int save_parallel(const dm_traj *tr, const char *path, dm_err *e)
{
  char *tmp = NULL, *name = NULL;
  size_t nlen = 0;
  hid_t fcpl = -1, fapl = -1, dxpl = -1, f = -1;
  int st = check_names(tr, path, e);
  /* rank 0 picks the temporary name; every rank learns it */
  if (st == DM_OK && dm_mpi_rank() == 0 && (tmp = temp_name(path, e)) == NULL)
    st = e != NULL ? e->status : DM_EIO;
  st = dm_mpi_agree(st, e);
  if (st == DM_OK)
    st = dm_mpi_allgather_bytes(tmp != NULL ? tmp : "", tmp != NULL ? strlen(tmp) + 1 : 0,
                                (void **)&name, &nlen, NULL, e);
  if (st != DM_OK) {
    if (tmp != NULL)
      unlink(tmp);
    free(tmp);
    return st;
  }
  lock();
  fcpl = ordered_fcpl();
  fapl = unlocked_fapl();
  dxpl = H5Pcreate(H5P_DATASET_XFER);
  if (fapl < 0 || dxpl < 0 || H5Pset_fapl_mpio(fapl, MPI_COMM_WORLD, MPI_INFO_NULL) < 0
      || H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0)
    st = h5_fail(e, DM_EIO, path, "cannot set up MPI-IO");
  if (st == DM_OK && (f = H5Fcreate(name, H5F_ACC_TRUNC, fcpl, fapl)) < 0)
    st = h5_fail(e, DM_EIO, path, "cannot create the HDF5 file (MPI-IO)");
  if (st == DM_OK)
    st = write_file(f, tr, (size_t)dm_mpi_rank(), (size_t)dm_mpi_size(), dxpl, path, e);
  if (f >= 0 && H5Fclose(f) < 0 && st == DM_OK)
    st = h5_fail(e, DM_EIO, path, "cannot close the HDF5 file");
  if (dxpl >= 0)
    H5Pclose(dxpl);
  if (fapl >= 0)
    H5Pclose(fapl);
  if (fcpl >= 0)
    H5Pclose(fcpl);
  unlock();
  st = dm_mpi_agree(st, e);
  if (dm_mpi_rank() == 0) {
    if (st == DM_OK)
      st = publish(name, path, e);
    if (st != DM_OK)
      unlink(name);
  }
  st = dm_mpi_agree(st, e);
  free(name);
  free(tmp);
  return st;
}
#endif

int dm_traj_save_h5_shared(const dm_traj *tr, const char *path, dm_err *e)
{
  int st = DM_OK;
  if (path == NULL || path[0] == '\0')
    st = dm_err_set(e, DM_EINVAL, "save: empty file name");
  if (!dm_mpi_active() || dm_mpi_size() == 1)
    return st == DM_OK ? dm_traj_save_h5(tr, path, e) : st;
#ifdef DM_H5_PARALLEL
  st = dm_mpi_agree(st, e);
  return st == DM_OK ? save_parallel(tr, path, e) : st;
#else
  if (st == DM_OK && dm_mpi_rank() == 0)
    st = dm_traj_save_h5(tr, path, e);
  return dm_mpi_agree(st, e);
#endif
}

/* }====================================================================== */

/* {==== for trajectory_h5_stream.c (trajectory_h5_impl.h) ============== */

void dm_h5__lock(void)
{
  lock();
}

void dm_h5__unlock(void)
{
  unlock();
}

int dm_h5__fail(dm_err *e, int st, const char *path, const char *what)
{
  return h5_fail(e, st, path, what);
}

int dm_h5__put_string(hid_t obj, const char *name, const char *value)
{
  return put_string(obj, name, value);
}

int dm_h5__check_names(const dm_traj *tr, const char *path, dm_err *e)
{
  return check_names(tr, path, e);
}

int dm_h5__write_attrs(hid_t f, const dm_traj *tr, const char *path, dm_err *e)
{
  return write_attrs(f, tr, path, e);
}

hid_t dm_h5__ordered_fcpl(void)
{
  return ordered_fcpl();
}

hid_t dm_h5__unlocked_fapl(void)
{
  return unlocked_fapl();
}

/* }====================================================================== */
