/* gnuplot.h -- one gnuplot process per session, spoken to through pipes.
 *
 * A dm_gp_session owns one gnuplot child process, started lazily (on the
 * first dm_gp_begin) in its own process group -- the user's Ctrl-C never
 * reaches it -- with stdin, stdout and stderr piped.  If gnuplot dies, the
 * next dm_gp_begin starts a new one.  Nothing here prints, exits or knows
 * about Lua.
 *
 * Protocol.  A user-level command is a transaction:
 *
 *     dm_gp_begin(s, e);                  -- (re)start gnuplot if needed
 *     dm_gp_send(s, e, "set title %s", q) -- text, buffered, streamed out
 *     dm_gp_datablock(s, "dm1", ...)      -- data as $dm1 << EOD ... EOD
 *     dm_gp_checkpoint(s, "dm.plot", e)   -- round trip: did gnuplot complain?
 *
 * The checkpoint sends `print "<unique marker>", GPVAL_ERRNO` and reads
 * gnuplot's stderr (poll with a timeout) until the marker comes back; when
 * gnuplot recorded an error, everything it wrote before the marker becomes
 * the message of the returned error.  A gnuplot that does not answer within
 * the timeout (counted from the last sign of life) is killed with its
 * process group and DM_ETIMEOUT returned; the next transaction restarts it.
 * Writes are non-blocking and interleaved with reading gnuplot's stdout and
 * stderr, so any amount of data streams without deadlock.  Numbers are
 * written with %.17g in the "C" locale whatever LC_NUMERIC says.
 *
 * Strings a user wrote (titles, labels, key entries, file names) must go
 * out through dm_gp_quote / dm_gp_sendq: a gnuplot single-quoted string
 * expression that gnuplot renders literally (no macro `@`, no backtick
 * substitution, no escapes, no way to end the command).
 *
 * Large datablocks (more than DM_GP_INLINE_ROWS rows) are written to a file
 * in a private temporary directory (mode 0700) and `load`ed: gnuplot reads
 * its stdin one byte per system call, which would make 10^6 points take
 * tens of seconds; through a file they take well under one.  The file is
 * removed after the checkpoint; the log records the data inline.
 *
 * Files.  dm_gp_set_terminal with a file name sends `set terminal` and
 * `set output` to a fresh temporary file beside the target; the next
 * checkpoint sends `unset output` (the file is complete when it returns)
 * and renames the temporary file to the target on success, removes it on
 * failure.
 *
 * Environment: $DMECH_GNUPLOT (program, default `gnuplot` on PATH),
 * $DMECH_GNUPLOT_TIMEOUT (seconds, default 30), $DMECH_GNUPLOT_LOG (append
 * every command sent to this file), $GNUTERM, $DISPLAY, $WAYLAND_DISPLAY.
 *
 * Errors: every int function returns DM_OK or a DM_E* status and fills the
 * dm_err (may be NULL): DM_ENOTFOUND (no gnuplot program), DM_EIO (pipe
 * failure, gnuplot exited), DM_ETIMEOUT (gnuplot hung; it was killed),
 * DM_EINTR (dm_interrupted() while waiting; gnuplot was killed), DM_EFAILED
 * (gnuplot reported an error; message = its text), DM_EINVAL (bad argument,
 * nothing sent), DM_EUNSUP (no usable terminal).  After any failure inside a
 * transaction the session resynchronises (or restarts gnuplot) at the next
 * dm_gp_begin, so one error never poisons the session.
 *
 * Ownership: dm_gp_session_alloc/dm_gp_session_free; free (NULL is a no-op)
 * closes the pipes, kills gnuplot's process group and reaps the child.
 * Strings returned by accessors belong to the session and stay valid until
 * the next call that talks to gnuplot.  Not thread-safe: one session per
 * thread.
 */
#ifndef DM_GNUPLOT_H
#define DM_GNUPLOT_H

#include <stddef.h>
#include <sys/types.h>

#include "core/status.h"

typedef struct dm_gp_session dm_gp_session;

/* ---- lifetime ------------------------------------------------------------ */

/* A session with no process yet (gnuplot starts on the first dm_gp_begin).
 * Reads $DMECH_GNUPLOT_TIMEOUT and $DMECH_GNUPLOT_LOG.  NULL when out of
 * memory. */
dm_gp_session *dm_gp_session_alloc(void);

/* Close the pipes, kill gnuplot's process group, reap it, free everything. */
void dm_gp_session_free(dm_gp_session *s);

/* Program to run (copied); NULL means $DMECH_GNUPLOT, else `gnuplot`.  Takes
 * effect at the next start. */
int dm_gp_set_program(dm_gp_session *s, const char *program, dm_err *e);

/* Seconds gnuplot may stay silent before it is declared hung (> 0). */
void dm_gp_set_timeout(dm_gp_session *s, double seconds);
double dm_gp_timeout(const dm_gp_session *s);

/* Append every command sent to `path` (NULL stops logging). */
int dm_gp_set_log(dm_gp_session *s, const char *path, dm_err *e);

/* Start gnuplot now if it is not running (restarting a dead one) and probe
 * its version and terminals.  dm_gp_begin calls this. */
int dm_gp_start(dm_gp_session *s, dm_err *e);

/* Kill gnuplot's process group and reap it now (no-op when not running). */
void dm_gp_stop(dm_gp_session *s);

/* Process id of the running gnuplot, or -1. */
pid_t dm_gp_pid(const dm_gp_session *s);

/* How many times gnuplot was started; a change means gnuplot's state
 * (datablocks, settings) was lost. */
unsigned long dm_gp_generation(const dm_gp_session *s);

/* GPVAL_TERMINALS of the running gnuplot (space separated), "" before the
 * first start. */
const char *dm_gp_terminals(const dm_gp_session *s);

/* gnuplot's version number (5.4 ...), 0 before the first start. */
double dm_gp_version(const dm_gp_session *s);

/* Non-zero when terminal `name` is in GPVAL_TERMINALS. */
int dm_gp_has_terminal(const dm_gp_session *s, const char *name);

/* ---- transactions ---------------------------------------------------------- */

/* Start a user-level command: ensure gnuplot runs (restart after a death,
 * resynchronise after an abandoned transaction) and forget the output and
 * messages of the previous one. */
int dm_gp_begin(dm_gp_session *s, dm_err *e);

/* Append printf-formatted command text (the "C" locale is in force for
 * numbers).  Add the newline yourself.  Text is streamed to gnuplot when
 * the buffer grows large; never put user strings in `fmt` -- use
 * dm_gp_sendq. */
int dm_gp_send(dm_gp_session *s, dm_err *e, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;

/* Append `len` bytes of a user string as a quoted gnuplot string expression
 * (see dm_gp_quote; flags as there). */
int dm_gp_sendq(dm_gp_session *s, const char *str, size_t len, int flags,
                dm_err *e);

/* Send a datablock $name with `nrows` rows of `ncols` columns: column j is
 * cols[j][i * strides[j]] (strides NULL means all 1).  Numbers are written
 * %.17g; NaN and infinities as NaN (an undefined point).  `name` is
 * [A-Za-z_][A-Za-z0-9_]* (without the `$`).  dm_interrupted() is polled:
 * an interrupted datablock is closed with the rows sent so far and DM_EINTR
 * returned. */
#define DM_GP_INLINE_ROWS 2000

int dm_gp_datablock(dm_gp_session *s, const char *name, size_t nrows,
                    size_t ncols, const double *const *cols,
                    const size_t *strides, dm_err *e);

/* Finish the transaction: flush, then round-trip a marker.  Returns DM_OK
 * when gnuplot reported no error (its messages, e.g. warnings or `print`
 * output, are in dm_gp_messages), DM_EFAILED with
 * "<what>: gnuplot: <its complaint> (at: <command>)" when it did.  A
 * pending file output is closed first and renamed into place on success. */
int dm_gp_checkpoint(dm_gp_session *s, const char *what, dm_err *e);

/* One raw command (may contain newlines) as its own transaction; `what`
 * names it in errors (NULL: the command itself).  Blank lines follow it, so
 * gnuplot's interactive `help` returns instead of reading the checkpoint. */
int dm_gp_command(dm_gp_session *s, const char *cmd, const char *what,
                  dm_err *e);

/* What gnuplot wrote on stderr before the last checkpoint's marker
 * (print output, warnings, error text), NUL terminated. */
const char *dm_gp_messages(const dm_gp_session *s, size_t *len);

/* What gnuplot wrote on stdout during the current / last transaction
 * (text plots of `dumb`, sixel images), NUL terminated. */
const char *dm_gp_output(const dm_gp_session *s, size_t *len);

/* ---- terminals and files ------------------------------------------------- */

typedef struct dm_gp_termreq {
  const char *terminal; /* the user's choice ("png", "qt", "dumb", "sixel"
                           with optional plain options), or NULL */
  const char *file;     /* output file, or NULL for the screen */
  double width, height; /* size; 0 = default (640x480 pixels, 79x24 or the
                           terminal's size for dumb, 360x252 points, window
                           terminals as they are).  Pixels for bitmap, svg
                           and window terminals, characters for dumb, points
                           (1/72 in) for pdf/eps */
  int window;           /* window number for window terminals (0, 1, ...) */
  int enhanced;         /* non-zero: enhanced text markup (default literal) */
} dm_gp_termreq;

/* Facts the choice of a screen terminal depends on (see
 * dm_gp_pick_terminal); dm_gp_termenv_get fills them from the process. */
typedef struct dm_gp_termenv {
  const char *gnuterm;  /* $GNUTERM or NULL */
  int has_display;      /* $DISPLAY or $WAYLAND_DISPLAY set */
  int has_x11;          /* $DISPLAY set */
  int tty;              /* standard output is a terminal */
  int cols, rows;       /* its size */
} dm_gp_termenv;

void dm_gp_termenv_get(dm_gp_termenv *env);

/* The terminal for showing a plot on screen: the user's choice, else
 * $GNUTERM, else qt/wxt/x11 when there is a display and `available` (a
 * GPVAL_TERMINALS list) has one, else `dumb` sized to the terminal when
 * standard output is one, else DM_EUNSUP asking for output=.  Writes the
 * terminal name into name[size]. */
int dm_gp_pick_terminal(const dm_gp_termenv *env, const char *user,
                        const char *available, char *name, size_t size,
                        dm_err *e);

/* The terminal a file name asks for, from its extension (.png .svg .pdf
 * .eps .ps .gif .jpg .jpeg .txt .tex .sixel), preferring cairo variants
 * present in `available`.  DM_EINVAL for an unknown extension. */
int dm_gp_terminal_for_file(const char *file, const char *available,
                            char *name, size_t size, dm_err *e);

/* Build the complete `set terminal ...` line (no newline) for `req` into
 * out[size]: terminal name, size (converted to the terminal's units),
 * window number, noenhanced.  User terminal options are checked to be
 * plain words and numbers. */
int dm_gp_terminal_command(const dm_gp_session *s, const dm_gp_termreq *req,
                           const dm_gp_termenv *env, char *out, size_t size,
                           dm_err *e);

/* Within a transaction: choose and set the terminal for `req`; with a file,
 * also `set output` to a temporary file that the next checkpoint closes and
 * renames onto req->file.  Remembers whether the output goes to gnuplot's
 * stdout (dm_gp_output then holds a text plot or sixel image). */
int dm_gp_set_terminal(dm_gp_session *s, const dm_gp_termreq *req,
                       dm_err *e);

/* ---- quoting --------------------------------------------------------------- */

#define DM_GP_QUOTE_ONELINE 1  /* newlines become spaces (not "\n") */

/* Write src[0..len) as a gnuplot string expression rendering exactly those
 * characters: ordinary runs in single quotes, each of ' " \ ` @ and newline
 * (\n, \r\n, \r) as an octal escape in a double-quoted piece ("\047"),
 * joined with '.': no gnuplot scanner (lexer, macros, backticks) can misread
 * it.  DM_GP_QUOTE_ONELINE turns newlines into spaces; other control
 * characters always become spaces.  Writes at most size bytes including the
 * NUL (dst may be NULL when size is 0) and returns the length the full
 * result needs, like snprintf. */
size_t dm_gp_quote(char *dst, size_t size, const char *src, size_t len,
                   int flags);

/* Non-zero when a user's plot style (the `with` clause) is safe to pass
 * through: words, numbers, spaces, . , : # + - _ and quoted colour names;
 * never ; @ ` $ ( ) { } \ or a newline. */
int dm_gp_valid_style(const char *style);

/* Non-zero when s is usable as a gnuplot identifier / datablock name. */
int dm_gp_valid_name(const char *name);

#endif
