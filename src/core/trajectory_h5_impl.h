/* trajectory_h5_impl.h -- helpers of trajectory_h5.c shared with
 * trajectory_h5_stream.c (private to src/core; includes <hdf5.h>).
 * Every HDF5 call is made between dm_h5__lock and dm_h5__unlock (the
 * library is not thread-safe); the others are trajectory_h5.c's: the
 * error message with HDF5's innermost one, a fixed-length string
 * attribute (1 when written), the column-name and reserved-key check, the
 * root attributes (format, then the metadata in order), the file creation
 * list tracking creation order, the access list without file locking. */
#ifndef DM_TRAJECTORY_H5_IMPL_H
#define DM_TRAJECTORY_H5_IMPL_H

#include <hdf5.h>

#include "core/status.h"
#include "core/trajectory.h"

void dm_h5__lock(void);
void dm_h5__unlock(void);
int dm_h5__fail(dm_err *e, int st, const char *path, const char *what);
int dm_h5__put_string(hid_t obj, const char *name, const char *value);
int dm_h5__check_names(const dm_traj *tr, const char *path, dm_err *e);
int dm_h5__write_attrs(hid_t f, const dm_traj *tr, const char *path, dm_err *e);
hid_t dm_h5__ordered_fcpl(void);
hid_t dm_h5__unlocked_fapl(void);

#endif
