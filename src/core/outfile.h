/* outfile.h -- writing a file without ever destroying what is at its path.
 *
 * What is at the path decides how it is written:
 *   - nothing, or a regular file: the data go to a new temporary file in the
 *     same directory (created with O_EXCL under an unpredictable name,
 *     mode 0666 minus the umask) that dm_outfile_commit fsyncs and renames
 *     over the path, so the path holds either the old file or the complete
 *     new one; dm_outfile_abandon (and any failure) removes the temporary
 *     and leaves the old file untouched;
 *   - a symbolic link: followed.  The link stays a link and the file it
 *     points to is replaced as above (the temporary goes beside that file).
 *     A dangling link or a loop is refused;
 *   - a FIFO or a character device (/dev/null, /dev/stdout, a terminal):
 *     written through, in place -- opened for writing without creating or
 *     truncating anything, never renamed or removed.  A FIFO nobody reads
 *     is waited for (interruptible) up to $DMECH_FIFO_TIMEOUT seconds
 *     (default DM_OUTFILE_FIFO_WAIT);
 *   - a directory, a block device or a socket: refused.
 * Temporary names are "<dir>/.<name>.<16 hex digits>.tmp", with <name>
 * shortened so that the temporary name fits where the final name fits.
 * The temporary file is registered with core/cleanup.h until it is renamed
 * or removed, so a signal or the process's exit does not leave it behind.
 *
 * Named mode (DM_OUTFILE_NAMED): the data are written by another process
 * that opens o->tmp by name (gnuplot's `set output`).  For a regular target
 * the temporary is the one beside the path; for a FIFO or a device it is a
 * private file in `privdir` (the caller's mkdtemp directory) whose content
 * commit copies to the device.  No descriptor is kept open before commit.
 *
 * Errors (DM_EINVAL for what is refused, DM_EIO for system failures,
 * DM_ENOMEM, DM_EINTR while waiting for a FIFO reader) carry a message
 * naming the path: "<what> '<path>': <reason>".
 *
 * Ownership: a dm_outfile is a caller-owned value; after a successful
 * dm_outfile_open exactly one of commit / abandon must be called; both
 * release everything and are no-ops on a zeroed or finished value.  Not
 * thread-safe per value; different values are independent.
 */
#ifndef DM_OUTFILE_H
#define DM_OUTFILE_H

#include <stdio.h>

#include "core/status.h"

#define DM_OUTFILE_NAMED 1
#define DM_OUTFILE_FIFO_WAIT 10.0

typedef struct dm_outfile {
  char *path;     /* the path as given (copy) */
  char *target;   /* the file replaced: path, or where its symlink points */
  char *tmp;      /* temporary file, or NULL when writing straight through */
  FILE *f;        /* write here (NULL in named mode) */
  int through;    /* 1: FIFO or device, written in place */
  int slot;       /* cleanup registration of tmp, or -1 */
  const char *what; /* "saving" / "plot output": prefix of messages */
} dm_outfile;

/* Prepare to write `path`; `what` prefixes error messages and must stay
 * valid until commit/abandon.  In normal mode o->f is ready for writing.
 * privdir is used (and required) only in named mode for devices/FIFOs. */
int dm_outfile_open(dm_outfile *o, const char *path, const char *what,
                    int flags, const char *privdir, dm_err *e);

/* Finish: flush o->f, fsync and rename over the target (written through:
 * flush and close; named mode with a device: copy the temporary into it).
 * A write error on o->f at any time before (ENOSPC, EFBIG, EIO) is reported
 * here.  Before renaming, the target is checked again: if something other
 * than a regular file appeared there meanwhile, nothing is replaced.  On
 * failure the old file is untouched and the temporary removed. */
int dm_outfile_commit(dm_outfile *o, dm_err *e);

/* Give up: close, remove the temporary, release. */
void dm_outfile_abandon(dm_outfile *o);

/* Describe what is at path for messages ("a FIFO", "a directory", ...);
 * "nothing" when it does not exist. */
const char *dm_outfile_kind(const char *path);

#endif
