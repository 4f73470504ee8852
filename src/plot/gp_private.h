/* gp_private.h -- the gnuplot session's insides, shared by the files of src/plot.
 * Not installed, not for other modules. */
#ifndef DM_GP_PRIVATE_H
#define DM_GP_PRIVATE_H

#include <stdio.h>
#include <sys/types.h>

#include "core/outfile.h"
#include "plot/gnuplot.h"

/* A growable byte buffer, always NUL terminated when p != NULL. */
typedef struct gp_buf {
  char *p;
  size_t len, cap;
} gp_buf;

int gp_buf_reserve(gp_buf *b, size_t extra);
int gp_buf_append(gp_buf *b, const char *data, size_t len);
void gp_buf_consume(gp_buf *b, size_t n);   /* drop the first n bytes */
void gp_buf_clear(gp_buf *b);
void gp_buf_free(gp_buf *b);

/* Write buffer is streamed out when it holds more than this. */
#define GP_FLUSH_AT 65536

struct dm_gp_session {
  pid_t pid;              /* -1: not running */
  int fd_in, fd_out, fd_err;  /* our ends of gnuplot's stdin/stdout/stderr */
  unsigned long generation;   /* number of starts */
  unsigned long serial;       /* checkpoint counter */
  int dirty;              /* a transaction was left without checkpoint */
  int starting;           /* inside dm_gp_start (exit 127 = not found) */
  char *program;          /* NULL: $DMECH_GNUPLOT or "gnuplot" */
  double timeout;         /* seconds of silence before "hung" */
  FILE *log;

  gp_buf wbuf;            /* text waiting to be written */
  size_t woff;            /* bytes of wbuf already written */
  gp_buf obuf;            /* gnuplot's stdout since begin */
  gp_buf ebuf;            /* gnuplot's stderr not yet consumed */
  gp_buf msgs;            /* stderr text before the last marker */
  gp_buf last_err;        /* stderr tail kept for "gnuplot exited" */

  char *datadir;          /* private directory for large datablocks */
  int datadir_slot;       /* its core/cleanup.h registration */
  char terminals[2048];   /* GPVAL_TERMINALS */
  double version;

  /* pending file output (set_terminal with a file) */
  dm_outfile out;         /* gnuplot writes out.tmp (out.path: none) */
  int out_open;           /* `unset output` not yet sent */
  int to_stdout;          /* current terminal writes to gnuplot's stdout */
};

/* process.c */
int gp_spawn(dm_gp_session *s, dm_err *e);
void gp_kill(dm_gp_session *s);
int gp_alive(dm_gp_session *s);
int gp_flush(dm_gp_session *s, dm_err *e);
int gp_wait_marker(dm_gp_session *s, const char *marker, size_t *pos,
                   dm_err *e);
const char *gp_program(const dm_gp_session *s);

/* protocol.c */
int gp_append(dm_gp_session *s, const char *data, size_t len, dm_err *e);
void gp_log(dm_gp_session *s, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;
int gp_send_unlogged(dm_gp_session *s, const char *data, size_t len,
                     dm_err *e);
int gp_sendq_unlogged(dm_gp_session *s, const char *str, dm_err *e);
int gp_roundtrip(dm_gp_session *s, const char *what, int *gp_errno,
                 dm_err *e);

/* datablock.c */
int gp_ensure_datadir(dm_gp_session *s, dm_err *e);
void gp_data_cleanup(dm_gp_session *s, int remove_dir);

/* terminal.c */
void gp_output_discard(dm_gp_session *s);
int gp_output_close(dm_gp_session *s, dm_err *e);
int gp_output_commit(dm_gp_session *s, dm_err *e);

double gp_now(void);

#endif
