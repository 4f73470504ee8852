/* trajectory_h5_stream.c -- a trajectory's HDF5 file written in pieces
 * while a run goes on (dm_h5_stream_*, see trajectory_h5.h): the layout of
 * dm_traj_save_h5 with chunked datasets extended by every block, the root
 * attributes rewritten from the run's final metadata, published through
 * core/outfile.h. */
#include <config.h>
#include "core/trajectory_h5.h"
#include "core/trajectory_h5_impl.h"

#include <stdlib.h>
#include <string.h>

#include "core/outfile.h"

/* {==== a file written in pieces ========================================= */

/* Samples per chunk of a streamed dataset: the first block's length within
 * [STREAM_CHUNK_MIN, STREAM_CHUNK_MAX] (1 to 512 KB of doubles). */
#define STREAM_CHUNK_MIN 128
#define STREAM_CHUNK_MAX 65536

struct dm_h5_stream {
  dm_outfile o;
  char *path;
  hid_t f;
  hid_t *d;                 /* ncols datasets */
  size_t ncols, len;
  int started, failed;
  dm_err err;
};

int dm_h5_stream_open(const char *path, dm_h5_stream **out, dm_err *e)
{
  *out = NULL;
  if (path == NULL || path[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "stream: empty file name");
  dm_h5_stream *s = calloc(1, sizeof *s);
  if (s == NULL || (s->path = strdup(path)) == NULL) {
    free(s);
    return dm_err_set(e, DM_ENOMEM, "stream: out of memory");
  }
  s->f = -1;
  int st = dm_outfile_open(&s->o, path, "saving", DM_OUTFILE_NAMED, NULL, e);
  if (st != DM_OK) {
    free(s->path);
    free(s);
    return st;
  }
  *out = s;
  return DM_OK;
}

/* The file and its empty extendible datasets, from the first block. */
static int stream_create(dm_h5_stream *s, const dm_traj *tr, dm_err *e)
{
  size_t n = dm_traj_len(tr), j;
  hsize_t dims[1] = {0}, maxd[1] = {H5S_UNLIMITED};
  hsize_t chunk[1] = {n < STREAM_CHUNK_MIN ? STREAM_CHUNK_MIN
                      : n > STREAM_CHUNK_MAX ? STREAM_CHUNK_MAX : n};
  hid_t fcpl = dm_h5__ordered_fcpl(), fapl = dm_h5__unlocked_fapl();
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  int st = dm_h5__check_names(tr, s->path, e);
  if (st == DM_OK && (s->d = malloc((dm_traj_ncols(tr) + 1) * sizeof *s->d)) == NULL)
    st = dm_err_set(e, DM_ENOMEM, "saving '%.200s': out of memory", s->path);
  if (st == DM_OK && (dcpl < 0 || H5Pset_chunk(dcpl, 1, chunk) < 0
                      || H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER) < 0))
    st = dm_h5__fail(e, DM_EIO, s->path, "cannot set up a dataset");
  if (st == DM_OK && (s->f = H5Fcreate(s->o.tmp, H5F_ACC_TRUNC, fcpl,
                                       fapl >= 0 ? fapl : H5P_DEFAULT)) < 0)
    st = dm_h5__fail(e, DM_EIO, s->path, "cannot create the HDF5 file");
  if (st == DM_OK)
    st = dm_h5__write_attrs(s->f, tr, s->path, e);
  for (j = 0; st == DM_OK && j < dm_traj_ncols(tr); j++) {
    hid_t fs = H5Screate_simple(1, dims, maxd), d = -1;
    if (fs >= 0)
      d = H5Dcreate2(s->f, dm_traj_colname(tr, j), H5T_IEEE_F64LE, fs, H5P_DEFAULT, dcpl,
                     H5P_DEFAULT);
    if (fs >= 0)
      H5Sclose(fs);
    if (d >= 0)
      s->d[s->ncols++] = d;
    if (d < 0 || !dm_h5__put_string(d, "kind", dm_traj_kindname(dm_traj_colkind(tr, j))))
      st = dm_h5__fail(e, DM_EIO, s->path, "cannot write a column");
  }
  if (dcpl >= 0)
    H5Pclose(dcpl);
  if (fapl >= 0)
    H5Pclose(fapl);
  if (fcpl >= 0)
    H5Pclose(fcpl);
  return st;
}

/* Append the block's rows to every dataset. */
static int stream_append(dm_h5_stream *s, const dm_traj *tr, dm_err *e)
{
  size_t n = dm_traj_len(tr), j;
  hsize_t start[1] = {s->len}, count[1] = {n}, total[1] = {s->len + n};
  if (dm_traj_ncols(tr) != s->ncols)
    return dm_err_set(e, DM_EINVAL, "saving '%.200s': a block with %zu columns after %zu",
                      s->path, dm_traj_ncols(tr), s->ncols);
  for (j = 0; j < s->ncols; j++) {
    hid_t fs = -1, ms = H5Screate_simple(1, count, NULL);
    int ok = ms >= 0 && H5Dset_extent(s->d[j], total) >= 0 && (fs = H5Dget_space(s->d[j])) >= 0
             && H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0
             && H5Dwrite(s->d[j], H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, dm_traj_col(tr, j)) >= 0;
    if (fs >= 0)
      H5Sclose(fs);
    if (ms >= 0)
      H5Sclose(ms);
    if (!ok)
      return dm_h5__fail(e, DM_EIO, s->path, "cannot write a column");
  }
  s->len += n;
  return DM_OK;
}

/* Keep a stream's first error; report it (again) in e. */
static int stream_failed(dm_h5_stream *s, int st, dm_err *e)
{
  if (st != DM_OK && !s->failed) {
    s->failed = 1;
    if (e != NULL)
      s->err = *e;
    else
      dm_err_set(&s->err, st, "saving '%.200s': %s", s->path, dm_strstatus(st));
  }
  return st;
}

int dm_h5_stream_put(dm_h5_stream *s, const dm_traj *tr, dm_err *e)
{
  int st;
  if (s->failed) {
    if (e != NULL)
      *e = s->err;
    return s->err.status;
  }
  if (dm_traj_len(tr) == 0 && s->started)
    return DM_OK;
  dm_h5__lock();
  st = s->started ? DM_OK : stream_create(s, tr, &s->err);
  s->started = 1;
  if (st == DM_OK && dm_traj_len(tr) > 0)
    st = stream_append(s, tr, &s->err);
  dm_h5__unlock();
  if (st != DM_OK) {
    s->failed = 1;
    if (e != NULL)
      *e = s->err;
  }
  return st;
}

int dm_h5_stream_meta(dm_h5_stream *s, const dm_traj *tr, dm_err *e)
{
  int st;
  if (!s->started || s->failed)
    return DM_OK;
  dm_h5__lock();
  /* every root attribute goes (creation order: always index 0), then the
   * new ones in order */
  while (H5Adelete_by_idx(s->f, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC, 0, H5P_DEFAULT) >= 0)
    ;
  H5Eclear2(H5E_DEFAULT);
  st = dm_h5__check_names(tr, s->path, e);
  if (st == DM_OK)
    st = dm_h5__write_attrs(s->f, tr, s->path, e);
  dm_h5__unlock();
  return stream_failed(s, st, e);
}

/* Close the HDF5 objects; DM_OK when they closed cleanly. */
static int stream_close_h5(dm_h5_stream *s, dm_err *e)
{
  int st = DM_OK;
  dm_h5__lock();
  for (size_t j = 0; j < s->ncols; j++)
    H5Dclose(s->d[j]);
  s->ncols = 0;
  if (s->f >= 0 && H5Fclose(s->f) < 0)
    st = dm_h5__fail(e, DM_EIO, s->path, "cannot close the HDF5 file");
  s->f = -1;
  dm_h5__unlock();
  return st;
}

static void stream_free(dm_h5_stream *s)
{
  free(s->d);
  free(s->path);
  free(s);
}

int dm_h5_stream_close(dm_h5_stream *s, dm_err *e)
{
  int st = DM_OK;
  if (s == NULL)
    return DM_OK;
  if (!s->started) {                   /* nothing recorded: no file */
    dm_outfile_abandon(&s->o);
  } else if (s->failed && s->err.status != DM_EINTR) {
    stream_close_h5(s, NULL);
    dm_outfile_abandon(&s->o);
    st = s->err.status;
    if (e != NULL)
      *e = s->err;
  } else if ((st = stream_close_h5(s, e)) != DM_OK) {
    dm_outfile_abandon(&s->o);
  } else {
    st = dm_outfile_commit(&s->o, e);
  }
  stream_free(s);
  return st;
}

void dm_h5_stream_abandon(dm_h5_stream *s)
{
  if (s == NULL)
    return;
  stream_close_h5(s, NULL);
  dm_outfile_abandon(&s->o);
  stream_free(s);
}

/* }====================================================================== */
