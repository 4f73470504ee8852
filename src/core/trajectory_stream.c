/* trajectory_stream.c -- a trajectory's CSV file written in pieces while a
 * run goes on (see trajectory.h): the same text dm_traj_save writes, the
 * header with the first piece, through core/outfile.h. */
#include <config.h>
#include "core/trajectory.h"
#include "core/outfile.h"

#include <stdlib.h>
#include <string.h>

struct dm_traj_stream {
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

int dm_traj_stream_close(dm_traj_stream *s, dm_err *e)
{
  if (s == NULL)
    return DM_OK;
  int st = DM_OK;
  if (!s->started) {                   /* nothing recorded: no file */
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
  dm_outfile_abandon(&s->o);
  free(s->path);
  free(s);
}
