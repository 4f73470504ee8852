/* trajectory_stream.c -- a trajectory's file written in pieces while a
 * run goes on (see trajectory.h): CSV, the same text dm_traj_save writes,
 * the header with the first piece, through core/outfile.h; or HDF5
 * (core/trajectory_h5.c) when the name asks for it. */
#include <config.h>
#include "core/trajectory.h"
#include "core/trajectory_h5.h"
#include "core/outfile.h"

#include <stdlib.h>
#include <string.h>

struct dm_traj_stream {
  dm_h5_stream *h5;         /* HDF5: everything is there */
  dm_outfile o;
  char *path;
  int started;              /* the header is written */
  int failed;
  dm_err err;
};

int dm_traj_stream_open(const char *path, dm_traj_stream **out, dm_err *e)
{
  *out = NULL;
  if (path == NULL || path[0] == '\0')
    return dm_err_set(e, DM_EINVAL, "stream: empty file name");
  dm_traj_stream *s = calloc(1, sizeof *s);
  if (s == NULL || (s->path = strdup(path)) == NULL) {
    free(s);
    return dm_err_set(e, DM_ENOMEM, "stream: out of memory");
  }
  if (dm_h5_wanted(path)) {
    int st = dm_h5_stream_open(path, &s->h5, e);
    if (st != DM_OK) {
      free(s->path);
      free(s);
      return st;
    }
    *out = s;
    return DM_OK;
  }
  int st = dm_outfile_open(&s->o, path, "saving", 0, NULL, e);
  if (st != DM_OK) {
    free(s->path);
    free(s);
    return st;
  }
  *out = s;
  return DM_OK;
}

int dm_traj_stream_put(dm_traj_stream *s, const dm_traj *tr, dm_err *e)
{
  if (s->h5 != NULL)
    return dm_h5_stream_put(s->h5, tr, e);
  if (s->failed) {
    if (e != NULL)
      *e = s->err;
    return s->err.status;
  }
  int st = s->started ? dm_traj_write_rows(tr, s->o.f, s->path, &s->err)
                      : dm_traj_write(tr, s->o.f, s->path, &s->err);
  s->started = 1;
  if (st != DM_OK) {
    s->failed = 1;
    if (e != NULL)
      *e = s->err;
  }
  return st;
}

int dm_traj_stream_meta(dm_traj_stream *s, const dm_traj *tr, dm_err *e)
{
  return s->h5 != NULL ? dm_h5_stream_meta(s->h5, tr, e) : DM_OK;
}

int dm_traj_stream_close(dm_traj_stream *s, dm_err *e)
{
  if (s == NULL)
    return DM_OK;
  int st = DM_OK;
  if (s->h5 != NULL) {
    st = dm_h5_stream_close(s->h5, e);
  } else if (!s->started) {                   /* nothing recorded: no file */
    dm_outfile_abandon(&s->o);
  } else if (s->failed && s->err.status != DM_EINTR) {
    dm_outfile_abandon(&s->o);
    st = s->err.status;
    if (e != NULL)
      *e = s->err;
  } else {
    st = dm_outfile_commit(&s->o, e);
  }
  free(s->path);
  free(s);
  return st;
}

void dm_traj_stream_abandon(dm_traj_stream *s)
{
  if (s == NULL)
    return;
  if (s->h5 != NULL)
    dm_h5_stream_abandon(s->h5);
  else
    dm_outfile_abandon(&s->o);
  free(s->path);
  free(s);
}
