/* test_trajectory_h5.c -- trajectories through HDF5: bit-exact round trips
 * (awkward numbers, metadata of both kinds, empty tables), loading by
 * content, plain HDF5 files written by someone else, and the error paths
 * with their messages. */
#include <config.h>
#include <dlfcn.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <hdf5.h>

#include "core/trajectory.h"
#include "core/trajectory_h5.h"
#include "tap.h"

static char dir[256];

/* H5Fclose, interposed: when armed, a child is forked just before the
 * file is closed, as another thread's fork (a compiler started in the
 * background) may be; the child holds a copy of every descriptor until
 * it is released. */
static int fork_at_close;
static pid_t holder = -1;
static int holder_fd = -1;

herr_t H5Fclose(hid_t f)
{
  static herr_t (*next)(hid_t);
  if (next == NULL)
    *(void **)&next = dlsym(RTLD_NEXT, "H5Fclose");
  if (fork_at_close && holder < 0) {
    int fd[2];
    if (pipe(fd) == 0) {
      holder = fork();
      if (holder == 0) {
        char c;
        close(fd[1]);
        while (read(fd[0], &c, 1) < 0)
          ;
        _exit(0);
      }
      close(fd[0]);
      holder_fd = fd[1];
    }
  }
  return next != NULL ? next(f) : -1;
}

static void release_holder(void)
{
  if (holder > 0) {
    close(holder_fd);
    waitpid(holder, NULL, 0);
  }
  holder = -1;
  holder_fd = -1;
}

static const char *at(const char *name)
{
  static char buf[4][512];
  static int k;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
  return buf[k];
}

static dm_traj *sample_traj(size_t len)
{
  static const char *const coords[] = {"r", "theta"};
  dm_traj *tr = dm_traj_alloc(2, coords, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL);
  static const double odd[] = {-0.0, 5e-324, 1.7976931348623157e308, 0.1, -2.385};
  size_t k;
  dm_traj_add_column(tr, "energy", DM_TRAJ_DIAG, NULL, 0, NULL);
  dm_traj_add_column(tr, "x", DM_TRAJ_DERIVED, NULL, 0, NULL);
  for (k = 0; k < len; k++) {
    double q[2] = {sin(0.37 * (double)k), odd[k % 5]}, p[2] = {1.0 / (double)(k + 3), NAN};
    double v[2] = {INFINITY, -INFINITY}, x[2] = {(double)k * 2.385, cos((double)k)};
    dm_traj_append(tr, 0.01 * (double)k, q, p, v, x, NULL);
  }
  dm_traj_meta_set(tr, "system", "J2 satellite \xc3\xa9 (line 1\nline 2)", NULL);
  dm_traj_meta_set_number(tr, "h", 0.1, NULL);
  dm_traj_meta_set_number(tr, "param.J2", 1.08263e-3, NULL);
  dm_traj_meta_set(tr, "empty", "", NULL);
  return tr;
}

static int same(const dm_traj *a, const dm_traj *b)
{
  size_t j, i;
  if (dm_traj_len(a) != dm_traj_len(b) || dm_traj_ncols(a) != dm_traj_ncols(b)
      || dm_traj_ncoords(a) != dm_traj_ncoords(b) || dm_traj_flags(a) != dm_traj_flags(b)
      || dm_traj_meta_count(a) != dm_traj_meta_count(b))
    return 0;
  for (j = 0; j < dm_traj_ncols(a); j++)
    if (strcmp(dm_traj_colname(a, j), dm_traj_colname(b, j)) != 0
        || dm_traj_colkind(a, j) != dm_traj_colkind(b, j)
        || (dm_traj_len(a) > 0
            && memcmp(dm_traj_col(a, j), dm_traj_col(b, j), dm_traj_len(a) * sizeof(double))))
      return 0;
  for (i = 0; i < dm_traj_meta_count(a); i++) {
    const char *ka, *va, *kb, *vb;
    double x, y;
    int na, nb;
    dm_traj_meta_at(a, i, &ka, &va);
    dm_traj_meta_at(b, i, &kb, &vb);
    na = dm_traj_meta_number_at(a, i, &x);
    nb = dm_traj_meta_number_at(b, i, &y);
    if (strcmp(ka, kb) != 0 || strcmp(va, vb) != 0 || na != nb || (na && memcmp(&x, &y, sizeof x)))
      return 0;
  }
  return 1;
}

static void round_trips(void)
{
  dm_traj *a = sample_traj(1000), *b, *c;
  dm_err e;
  int st = dm_traj_save_h5(a, at("a.h5"), &e);
  tap_ok(st == DM_OK, "save 1000 samples as HDF5: %s", st ? e.msg : "ok");
  b = dm_traj_load_h5(at("a.h5"), &e);
  tap_ok(b != NULL && same(a, b), "load: columns, kinds, NaN/Inf/-0/denormals and metadata "
         "bit for bit%s%s", b ? "" : ": ", b ? "" : e.msg);
  tap_ok(dm_h5_is_hdf5(at("a.h5")) && !dm_h5_is_hdf5("/dev/null") && dm_h5_wanted("x.hdf5")
         && dm_h5_wanted("x.h5") && !dm_h5_wanted("x.csv") && !dm_h5_wanted("h5"),
         "HDF5 recognised by signature and by name");
  /* by name and by content */
  st = dm_traj_save_any(a, at("a.csv"), &e);
  tap_ok(st == DM_OK && !dm_h5_is_hdf5(at("a.csv")), "a .csv name saves CSV");
  rename(at("a.h5"), at("a.dat"));
  c = dm_traj_load_any(at("a.dat"), &e);
  tap_ok(c != NULL && same(a, c), "an HDF5 file named .dat loads by its content");
  dm_traj_free(c);
  c = dm_traj_load_any(at("a.csv"), &e);
  tap_ok(c != NULL && dm_traj_len(c) == 1000, "and a CSV one as CSV");
  dm_traj_free(c);
  dm_traj_free(b);
  dm_traj_free(a);
  /* no samples, no coordinates (an ensemble table's shape) */
  a = dm_traj_alloc(0, NULL, 0, NULL);
  dm_traj_add_column(a, "megno", DM_TRAJ_DATA, NULL, 0, NULL);
  dm_traj_meta_set_number(a, "members", 0, NULL);
  st = dm_traj_save_h5(a, at("empty.h5"), &e);
  b = dm_traj_load_h5(at("empty.h5"), &e);
  tap_ok(st == DM_OK && b != NULL && same(a, b), "an empty table round-trips");
  dm_traj_free(a);
  dm_traj_free(b);
}

/* A file written by another program: int and float datasets, a group, an
 * array attribute (skipped), fixed-length string attribute. */
static void foreign(void)
{
  hid_t f = H5Fcreate(at("foreign.h5"), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  hsize_t n = 4, two = 2;
  double t[4] = {0, 0.5, 1, 1.5};
  int sig[4] = {3, 1, 4, 1};
  hid_t sp = H5Screate_simple(1, &n, NULL), s2 = H5Screate_simple(1, &two, NULL), d, a, st;
  dm_traj *tr;
  dm_err e;
  d = H5Dcreate2(f, "signal", H5T_STD_I32LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, sig);
  H5Dclose(d);
  d = H5Dcreate2(f, "t", H5T_IEEE_F32LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, t);
  H5Dclose(d);
  H5Gclose(H5Gcreate2(f, "notes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  a = H5Acreate2(f, "pair", H5T_IEEE_F64LE, s2, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, t);
  H5Aclose(a);
  st = H5Tcopy(H5T_C_S1);
  H5Tset_size(st, 5);
  {
    hid_t sc = H5Screate(H5S_SCALAR);
    a = H5Acreate2(f, "author", st, sc, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, st, "ada!!");
    H5Aclose(a);
    H5Sclose(sc);
  }
  H5Tclose(st);
  {                                  /* a variable-length UTF-8 string, as h5py writes */
    hid_t vt = H5Tcopy(H5T_C_S1), sc = H5Screate(H5S_SCALAR);
    const char *note = "written by h5py \xc3\xa9";
    H5Tset_size(vt, H5T_VARIABLE);
    H5Tset_cset(vt, H5T_CSET_UTF8);
    a = H5Acreate2(f, "note", vt, sc, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, vt, &note);
    H5Aclose(a);
    H5Sclose(sc);
    H5Tclose(vt);
  }
  H5Sclose(sp);
  H5Sclose(s2);
  H5Fclose(f);
  tr = dm_traj_load_h5(at("foreign.h5"), &e);
  tap_ok(tr != NULL && dm_traj_len(tr) == 4 && dm_traj_ncols(tr) == 2
         && dm_traj_col(tr, 1)[2] == 4.0 && dm_traj_col(tr, 0)[3] == 1.5
         && strcmp(dm_traj_meta_get(tr, "author"), "ada!!") == 0
         && strcmp(dm_traj_meta_get(tr, "note"), "written by h5py \xc3\xa9") == 0
         && dm_traj_meta_get(tr, "pair") == NULL,
         "a plain HDF5 file: t and an integer column, fixed and variable-length strings%s%s", tr ? "" : ": ",
         tr ? "" : e.msg);
  dm_traj_free(tr);
}

static void errors(void)
{
  dm_traj *a = dm_traj_alloc(0, NULL, 0, NULL), *b;
  dm_err e;
  int st;
  FILE *f;
  dm_traj_add_column(a, "a/b", DM_TRAJ_DATA, NULL, 0, NULL);
  st = dm_traj_save_h5(a, at("slash.h5"), &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "column 'a/b' cannot name an HDF5 dataset") != NULL
         && access(at("slash.h5"), F_OK) != 0, "%s", e.msg);
  dm_traj_free(a);
  a = dm_traj_alloc(0, NULL, 0, NULL);
  dm_traj_meta_set(a, "dmech.format", "x", NULL);
  st = dm_traj_save_h5(a, at("r.h5"), &e);
  tap_ok(st == DM_EINVAL && strstr(e.msg, "metadata key 'dmech.format' is reserved") != NULL,
         "%s", e.msg);
  dm_traj_free(a);
  a = dm_traj_alloc(0, NULL, 0, NULL);
  st = dm_traj_save_h5(a, at("no/such/dir/x.h5"), &e);
  tap_ok(st == DM_EIO && strstr(e.msg, "cannot create a temporary file") != NULL, "%s", e.msg);
  dm_traj_free(a);
  b = dm_traj_load_h5(at("missing.h5"), &e);
  tap_ok(b == NULL && e.status == DM_EIO && strstr(e.msg, "reading '") != NULL
         && strstr(e.msg, "missing.h5': No such file or directory") != NULL, "%s", e.msg);
  f = fopen(at("text.h5"), "w");
  fputs("t,x\n0,1\n", f);
  fclose(f);
  b = dm_traj_load_h5(at("text.h5"), &e);
  tap_ok(b == NULL && strstr(e.msg, "text.h5': not an HDF5 file (HDF5: file signature not "
                             "found)") != NULL, "%s", e.msg);
  b = dm_traj_load_any(at("text.h5"), &e);
  tap_ok(b != NULL && dm_traj_len(b) == 1, "load_any reads a CSV named .h5 as CSV");
  dm_traj_free(b);
  /* a 2-D dataset is not a column; columns of two lengths */
  {
    hid_t h = H5Fcreate(at("bad.h5"), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), sp, d;
    hsize_t dims[2] = {2, 3}, n3 = 3;
    double z[6] = {0};
    sp = H5Screate_simple(2, dims, NULL);
    d = H5Dcreate2(h, "img", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, z);
    H5Dclose(d);
    H5Sclose(sp);
    H5Fclose(h);
    b = dm_traj_load_h5(at("bad.h5"), &e);
    tap_ok(b == NULL && e.status == DM_EINVAL
           && strstr(e.msg, "dataset 'img' is not a column (expected a 1-D array of numbers)"),
           "%s", e.msg);
    h = H5Fcreate(at("bad2.h5"), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    sp = H5Screate_simple(1, &n3, NULL);
    H5Dclose(H5Dcreate2(h, "a", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    H5Sclose(sp);
    sp = H5Screate_simple(1, dims, NULL);
    H5Dclose(H5Dcreate2(h, "t", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    H5Sclose(sp);
    H5Fclose(h);
    b = dm_traj_load_h5(at("bad2.h5"), &e);
    tap_ok(b == NULL && strstr(e.msg, "dataset 't' has 2 values, 'a' has 3: the columns must "
                               "have one length"), "%s", e.msg);
    h = H5Fcreate(at("bad3.h5"), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    sp = H5Screate_simple(1, &n3, NULL);
    H5Dclose(H5Dcreate2(h, "time", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    H5Sclose(sp);
    H5Fclose(h);
    b = dm_traj_load_h5(at("bad3.h5"), &e);
    tap_ok(b == NULL && strstr(e.msg, "no time column (a dataset 't')"), "%s", e.msg);
  }
}

/* Named momenta (9 stored numbers, 3 momenta): through HDF5 and back. */
static void named_momenta(void)
{
  static const char *const g[] = {"R11", "R12", "R13", "R21", "R22", "R23", "R31", "R32", "R33"};
  static const char *const mu[] = {"mu1", "mu2", "mu3"}, *const xi[] = {"xi1", "xi2", "xi3"};
  dm_traj *a = dm_traj_alloc_state(9, g, 3, mu, xi, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL), *b;
  dm_err e;
  size_t k, i;
  dm_traj_add_column(a, "energy", DM_TRAJ_DIAG, NULL, 0, NULL);
  for (k = 0; k < 7; k++) {
    double q[9], p[3], v[3], E = 2.385 * (double)k;
    for (i = 0; i < 9; i++)
      q[i] = cos(0.3 * (double)(k + i));
    for (i = 0; i < 3; i++) {
      p[i] = sin(1.7 * (double)(k + i));
      v[i] = p[i] / 1.3;
    }
    dm_traj_append(a, 0.05 * (double)k, q, p, v, &E, NULL);
  }
  dm_traj_meta_set(a, "space", "SO3", NULL);
  b = dm_traj_save_h5(a, at("named.h5"), &e) == DM_OK ? dm_traj_load_h5(at("named.h5"), &e) : NULL;
  tap_ok(b != NULL && same(a, b) && dm_traj_nmomenta(b) == 3 && dm_traj_named_momenta(b),
         "named momenta (mu1.., xi1..) through HDF5, bit for bit%s%s", b ? "" : ": ",
         b ? "" : e.msg);
  dm_traj_free(a);
  dm_traj_free(b);
}

/* A file just written reads back while a child forked during the write
 * still holds its descriptor (HDF5 would keep an exclusive flock on it). */
static void inherited_descriptor(void)
{
  dm_traj *a = sample_traj(7), *b;
  dm_err e;
  int st;
  fork_at_close = 1;
  st = dm_traj_save_h5(a, at("held.h5"), &e);
  fork_at_close = 0;
  b = st == DM_OK ? dm_traj_load_h5(at("held.h5"), &e) : NULL;
  tap_ok(holder > 0 && b != NULL && same(a, b),
         "read back while a forked child holds the writer's descriptor%s%s",
         b == NULL ? ": " : "", b == NULL ? e.msg : "");
  release_holder();
  dm_traj_free(a);
  dm_traj_free(b);
}

int main(void)
{
  const char *tmp = getenv("TMPDIR");
  snprintf(dir, sizeof dir, "%s/dmh5-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (mkdtemp(dir) == NULL)
    return 1;
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  round_trips();
  named_momenta();
  foreign();
  errors();
  inherited_descriptor();
  {
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
      tap_diag("could not remove %s", dir);
  }
  return tap_done();
}
