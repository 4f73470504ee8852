/* datablock.c -- numbers to gnuplot as named datablocks.
 *
 * Rows are "%.17g %.17g ...\n" formatted in the "C" locale (numfmt.h), so a
 * decimal comma in LC_NUMERIC can never reach gnuplot; non-finite values
 * are written NaN (an undefined point: a gap in a line).
 *
 * Small blocks go inline through the command pipe.  Large ones are written
 * to "<private dir>/<name>.dat" (the directory is created by mkdtemp, mode
 * 0700, once per session) holding the same "$name << EOD ... EOD" text and
 * gnuplot is told to `load` it: gnuplot reads its stdin one byte per read(2),
 * a file through stdio.  The files are removed after every checkpoint.
 */
#include <config.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/cleanup.h"
#include "core/interrupt.h"
#include "core/numfmt.h"
#include "plot/gp_private.h"

static size_t fmt_number(char *p, double x)
{
  if (!isfinite(x)) {
    memcpy(p, "NaN", 3);
    return 3;
  }
  return (size_t)sprintf(p, "%.17g", x);
}

/* One row into line (>= ncols * 26 + 1 bytes); returns its length. */
static size_t fmt_row(char *line, size_t i, size_t ncols,
                      const double *const *cols, const size_t *strides)
{
  size_t j, k = 0;
  for (j = 0; j < ncols; j++) {
    size_t st = strides != NULL ? strides[j] : 1;
    if (j > 0)
      line[k++] = ' ';
    k += fmt_number(line + k, cols[j][i * st]);
  }
  line[k++] = '\n';
  return k;
}

/* The session's private directory (mkdtemp, 0700), created on first use
 * and registered for removal at exit or on a fatal signal. */
int gp_ensure_datadir(dm_gp_session *s, dm_err *e)
{
  const char *base = getenv("TMPDIR");
  char *dir;
  size_t n;
  if (s->datadir != NULL)
    return DM_OK;
  if (base == NULL || base[0] == '\0')
    base = "/tmp";
  n = strlen(base) + 32;
  if ((dir = malloc(n)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "out of memory");
  snprintf(dir, n, "%s/dmech-gnuplot-XXXXXX", base);
  if (mkdtemp(dir) == NULL) {
    int err = errno;
    free(dir);
    return dm_err_set(e, DM_EIO, "cannot create a private directory for plot "
                      "data in %s: %s", base, strerror(err));
  }
  s->datadir = dir;
  s->datadir_slot = dm_cleanup_add_dir(dir);
  return DM_OK;
}

void gp_data_cleanup(dm_gp_session *s, int remove_dir)
{
  DIR *d;
  struct dirent *de;
  if (s->datadir == NULL)
    return;
  if ((d = opendir(s->datadir)) != NULL) {
    while ((de = readdir(d)) != NULL) {
      char p[4096];
      if (de->d_name[0] == '.')
        continue;
      snprintf(p, sizeof p, "%s/%s", s->datadir, de->d_name);
      unlink(p);
    }
    closedir(d);
  }
  if (remove_dir) {
    rmdir(s->datadir);
    dm_cleanup_drop(s->datadir_slot);
    s->datadir_slot = -1;
    free(s->datadir);
    s->datadir = NULL;
  }
}

/* Inline: rows streamed through the pipe. */
static int block_inline(dm_gp_session *s, const char *name, size_t nrows,
                        size_t ncols, const double *const *cols,
                        const size_t *strides, size_t *done, dm_err *e)
{
  char line[8 * 26 + 2];
  size_t i;
  int rc = dm_gp_send(s, e, "$%s << EOD\n", name);
  for (i = 0; i < nrows && rc == DM_OK; i++) {
    if ((i & 4095) == 4095 && dm_interrupted())
      break;
    rc = gp_append(s, line, fmt_row(line, i, ncols, cols, strides), e);
  }
  *done = i;
  return rc != DM_OK ? rc : gp_append(s, "EOD\n", 4, e);
}

/* Through a file that gnuplot loads; the log still gets the data inline. */
static int block_file(dm_gp_session *s, const char *name, size_t nrows,
                      size_t ncols, const double *const *cols,
                      const size_t *strides, size_t *done, dm_err *e)
{
  char line[8 * 26 + 2], path[4096];
  FILE *f;
  size_t i, k;
  int rc = gp_ensure_datadir(s, e), bad;
  if (rc != DM_OK)
    return rc;
  snprintf(path, sizeof path, "%s/%s.dat", s->datadir, name);
  if ((f = fopen(path, "w")) == NULL)
    return dm_err_set(e, DM_EIO, "cannot write plot data '%s': %s", path,
                      strerror(errno));
  fprintf(f, "$%s << EOD\n", name);
  gp_log(s, "$%s << EOD\n", name);
  for (i = 0; i < nrows; i++) {
    if ((i & 4095) == 4095 && dm_interrupted())
      break;
    k = fmt_row(line, i, ncols, cols, strides);
    fwrite(line, 1, k, f);
    if (s->log != NULL)
      fwrite(line, 1, k, s->log);
  }
  *done = i;
  fputs("EOD\n", f);
  gp_log(s, "EOD\n");
  errno = 0;
  bad = fflush(f) != 0 || ferror(f);
  if (bad && errno == 0)
    errno = EIO;
  {
    int err = errno;
    if (fclose(f) != 0 && !bad) {
      bad = 1;
      err = errno;
    }
    if (bad) {
      unlink(path);
      return dm_err_set(e, DM_EIO, "cannot write plot data '%s': %s", path,
                        strerror(err));
    }
  }
  rc = gp_send_unlogged(s, "load ", 5, e);
  if (rc == DM_OK)
    rc = gp_sendq_unlogged(s, path, e);
  if (rc == DM_OK)
    rc = gp_send_unlogged(s, "\n", 1, e);
  return rc;
}

int dm_gp_datablock(dm_gp_session *s, const char *name, size_t nrows,
                    size_t ncols, const double *const *cols,
                    const size_t *strides, dm_err *e)
{
  size_t done = 0;
  locale_t old;
  int rc;
  if (!dm_gp_valid_name(name))
    return dm_err_set(e, DM_EINVAL, "invalid datablock name '%s'", name);
  if (ncols == 0 || ncols > 8 || cols == NULL)
    return dm_err_set(e, DM_EINVAL, "datablock needs 1 to 8 columns, got %zu",
                      ncols);
  if (s->pid <= 0)
    return dm_err_set(e, DM_EIO, "gnuplot is not running");
  old = dm_num_enter();
  if (nrows > DM_GP_INLINE_ROWS)
    rc = block_file(s, name, nrows, ncols, cols, strides, &done, e);
  else
    rc = block_inline(s, name, nrows, ncols, cols, strides, &done, e);
  dm_num_leave(old);
  if (rc == DM_OK && done < nrows)
    rc = dm_err_set(e, DM_EINTR, "interrupted while sending data to gnuplot "
                    "($%s has %zu of %zu rows)", name, done, nrows);
  return rc;
}
