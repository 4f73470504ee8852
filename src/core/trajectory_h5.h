/* trajectory_h5.h -- trajectories (and ensemble tables) as HDF5 files.
 *
 * Layout, readable without dmech (h5py, HDF5.jl, h5dump):
 *   /                      root group; attributes:
 *     "dmech.format"       "trajectory 1" (string)
 *     <key>                every metadata item, in order: a 64-bit float
 *                          scalar for numbers, a fixed-length UTF-8 string
 *                          otherwise ("method", "h", "param.mu", ...)
 *   /<column name>         one dataset per column, in column order (link
 *                          creation order is tracked): 1-D, little-endian
 *                          64-bit floats, one value per sample; attribute
 *                          "kind" = "t", "q", "p", "v", "diag", "derived" or
 *                          "data"
 * A column name containing '/' cannot name a dataset (DM_EINVAL); the
 * metadata key "dmech.format" is reserved.
 *
 * Strings are written fixed-length: variable-length ones live in the
 * file's global heap, which libhdf5 1.10 reads past its bounds when the
 * file is damaged (a crash the fuzzer found); files from elsewhere may
 * still hold variable-length strings, which are read (and expose that
 * library bug).
 *
 * Loading accepts files written here and plain HDF5 files whose root holds
 * 1-D numeric datasets of one length, one of them called "t" (the others
 * become data columns; attributes that are numeric or string scalars
 * become metadata, others are skipped).  Errors name the file and what was
 * expected; HDF5's own message (its innermost error) is appended.
 *
 * Saving is atomic as for CSV (trajectory.h): a temporary file in the same
 * directory, fsync, rename.  Numbers are stored as doubles: a round trip is
 * bit-exact.
 *
 * Collective saving under MPI: dm_traj_save_h5_shared writes a table that
 * every rank holds (the ensemble driver's gathered result) once: with
 * parallel HDF5 (the build's HDF5 has H5_HAVE_PARALLEL and dmech has MPI)
 * all ranks create the file together and rank r writes rows r, r + size,
 * ... of every column in one collective MPI-IO transfer; otherwise rank 0
 * writes the file alone.  Every rank must call it; all return the same
 * status.  Without MPI it is dm_traj_save_h5.
 *
 * Thread safety: HDF5 (as Debian builds it) is not thread-safe; these
 * functions serialize on one process-wide lock.  HDF5's automatic error
 * printing is turned off on first use.
 */
#ifndef DM_TRAJECTORY_H5_H
#define DM_TRAJECTORY_H5_H

#include "core/status.h"
#include "core/trajectory.h"

/* 1 when the file at path starts with the HDF5 signature. */
int dm_h5_is_hdf5(const char *path);
/* 1 when the name asks for HDF5: it ends in .h5, .hdf5 or .he5. */
int dm_h5_wanted(const char *path);
/* "parallel (MPI-IO)" or "serial": how this build writes collectively. */
const char *dm_h5_mode(void);
/* The HDF5 library version, "1.10.8". */
const char *dm_h5_version(void);

int dm_traj_save_h5(const dm_traj *tr, const char *path, dm_err *e);
dm_traj *dm_traj_load_h5(const char *path, dm_err *e);

/* CSV or HDF5 by the name (dm_h5_wanted) / by the content (dm_h5_is_hdf5). */
int dm_traj_save_any(const dm_traj *tr, const char *path, dm_err *e);
dm_traj *dm_traj_load_any(const char *path, dm_err *e);

/* The collective save described above. */
int dm_traj_save_h5_shared(const dm_traj *tr, const char *path, dm_err *e);

/* A file written in pieces (the HDF5 side of dm_traj_stream,
 * core/trajectory.h): the layout above, every column a chunked dataset
 * extended by each put (the columns of every put must be those of the
 * first); meta rewrites the root attributes from tr's metadata; close
 * publishes the file (core/outfile.h rules, as dm_traj_save_h5: a
 * temporary beside the target, fsync, rename; devices and FIFOs are
 * refused), or leaves none when nothing was put; abandon removes it. */
typedef struct dm_h5_stream dm_h5_stream;
int dm_h5_stream_open(const char *path, dm_h5_stream **s, dm_err *e);
int dm_h5_stream_put(dm_h5_stream *s, const dm_traj *tr, dm_err *e);
int dm_h5_stream_meta(dm_h5_stream *s, const dm_traj *tr, dm_err *e);
int dm_h5_stream_close(dm_h5_stream *s, dm_err *e);
void dm_h5_stream_abandon(dm_h5_stream *s);

#endif
