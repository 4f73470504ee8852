/* trajectory.h -- the columnar record of a run.
 *
 * A trajectory is a table of samples stored column by column: the time t,
 * the coordinates q, optionally the momenta p and the velocities v, then any
 * number of extra columns (diagnostics filled by the integrator binding,
 * derived columns computed by a callback, plain data).  It also carries
 * metadata: an ordered list of key=value pairs whose values are strings or
 * numbers (system name, method, h, parameters, how the run ended, ...).
 *
 * Column layout and names (fixed order):
 *   0                 "t"
 *   1 .. n            q columns, named after the coordinates ("r", "theta")
 *   then np           p columns "p_<coord>" ("p_r")       if DM_TRAJ_WITH_P
 *   then np           v columns "v_<coord>" ("v_r")       if DM_TRAJ_WITH_V
 *   then              extra columns in the order they were added
 * Without coordinate names the coordinates are called "q1", ..., "qn".
 * Usually np = n.  A configuration stored in more numbers than it has
 * velocities (a rotation: 9 entries, 3 angular velocities) has np < n
 * momenta whose p and v columns carry their own names ("mu1", "xi1";
 * dm_traj_alloc_state): a trajectory with "named momenta".
 * Diagnostic columns written by integrators are named DM_TRAJ_ENERGY
 * ("energy") and DM_TRAJ_MOMENTUM "<coord or name>" ("momentum_theta").
 * A column name is non-empty, at most DM_TRAJ_NAME_MAX bytes, contains no
 * control character, space, comma or quote, and is unique in the trajectory.
 *
 * Samples are indexed 0 .. len-1 in C (the Lua binding is 1-based).
 *
 * Metadata keys producers should use (the Lua __tostring shows the first
 * four): "system" (name, a string), "method" (a string), "stages", "h" (numbers),
 * and "param.<name>" (a number) for each system parameter; the run driver
 * (run.h) adds "order", "steps", "status" (numbers) and "message" (a string).
 * A number keeps its double value; its text (dm_traj_meta_get) is the
 * shortest round-trip form in the C locale.
 *
 * Ownership: dm_traj_alloc / dm_traj_load / dm_traj_slice return a new
 * trajectory the caller releases with dm_traj_free (NULL is a no-op).  The
 * trajectory copies every name, key, value and number it is given.  Pointers
 * returned by accessors (column data, names, metadata) belong to the
 * trajectory: column data stay valid until the next append / column change,
 * names and metadata until the next change of that item or dm_traj_free.
 *
 * Errors: functions return DM_OK or a DM_E* status and fill `e` (may be NULL)
 * with a message; constructors return NULL and fill `e`.  A failed call
 * changes nothing: in particular an allocation failure while appending
 * (DM_ENOMEM) keeps every sample already stored.  Long loops (derive, save,
 * load) poll dm_interrupted() and stop with DM_EINTR, changing nothing.
 * Files are written to a temporary name in the same directory, fsync'ed and
 * renamed, so the final name never holds a partial file; numbers use "%.17g"
 * in the C locale whatever LC_NUMERIC says, so a save/load round trip is
 * bit-exact (NaN payloads excepted).
 *
 * Thread safety: a trajectory is a plain object; concurrent readers are fine,
 * a writer needs exclusive access.
 */
#ifndef DM_TRAJECTORY_H
#define DM_TRAJECTORY_H

#include <stddef.h>
#include <stdio.h>

#include "core/status.h"

typedef struct dm_traj dm_traj;

/* What a column holds. */
enum dm_traj_kind {
  DM_TRAJ_T = 0,       /* the time column (always column 0) */
  DM_TRAJ_Q,           /* a coordinate */
  DM_TRAJ_P,           /* a conjugate momentum p_i */
  DM_TRAJ_V,           /* a velocity v_i */
  DM_TRAJ_DIAG,        /* a diagnostic written by an integrator (energy, ...) */
  DM_TRAJ_DERIVED,     /* computed from the samples by a callback */
  DM_TRAJ_DATA         /* anything else (user data, a column loaded from CSV) */
};

/* dm_traj_alloc flags: which state columns are stored besides t and q. */
enum { DM_TRAJ_WITH_P = 1u << 0, DM_TRAJ_WITH_V = 1u << 1 };

/* dm_traj_derive / dm_traj_add_column option: replace an existing extra
 * column of the same name (t, q, p, v columns can never be replaced). */
enum { DM_TRAJ_REPLACE = 1u << 0 };

#define DM_TRAJ_NONE ((size_t)-1)     /* "no such column" index */
#define DM_TRAJ_NAME_MAX 128          /* bytes in a column name, without NUL */
#define DM_TRAJ_ENERGY "energy"       /* the energy diagnostic column */
#define DM_TRAJ_MOMENTUM "momentum_"  /* prefix of momentum diagnostic columns */

/* ---- life cycle ---------------------------------------------------------- */

/* New empty trajectory for n coordinates (n may be 0: a plain table of t and
 * extra columns).  coords: n names or NULL for "q1".."qn".  flags:
 * DM_TRAJ_WITH_P | DM_TRAJ_WITH_V.  NULL + DM_EINVAL on a bad or duplicate
 * name, DM_ENOMEM. */
dm_traj *dm_traj_alloc(size_t n, const char *const *coords, unsigned flags,
                       dm_err *e);
/* The same with np momenta: pnames, vnames (np names each) name the p and v
 * columns the flags ask for; both NULL: "p_<coord>", "v_<coord>" as
 * dm_traj_alloc, which needs np == n. */
dm_traj *dm_traj_alloc_state(size_t n, const char *const *coords, size_t np,
                             const char *const *pnames, const char *const *vnames,
                             unsigned flags, dm_err *e);
void dm_traj_free(dm_traj *tr);

/* Make room for `nsamples` samples in total (appends then never allocate
 * until that many are stored).  DM_ENOMEM leaves the trajectory as it was. */
int dm_traj_reserve(dm_traj *tr, size_t nsamples, dm_err *e);

/* Remove every sample (columns, names and metadata stay). */
void dm_traj_clear(dm_traj *tr);
/* Give back the storage beyond the samples held (at least one sample's
 * room stays): 8 bytes per stored number.  Never fails (a shrink the
 * allocator refuses leaves the storage as it is). */
void dm_traj_shrink(dm_traj *tr);
/* Bytes of the sample storage held (the columns' room: 8 per number). */
size_t dm_traj_bytes(const dm_traj *tr);

/* ---- appending ------------------------------------------------------------- */

/* Append one sample.  q: n values (required when n > 0).  p, v: np values or
 * NULL; stored only when the trajectory has those columns, NULL then stores
 * NaN ("not available").  extra: one value per extra column in column order,
 * or NULL for NaN.  Storage grows by doubling; DM_ENOMEM keeps every sample
 * already stored. */
int dm_traj_append(dm_traj *tr, double t, const double *q, const double *p,
                   const double *v, const double *extra, dm_err *e);

/* The sink an integrator run loop calls for each recorded state: ctx is the
 * dm_traj *.  Same as dm_traj_append(ctx, t, q, p, v, NULL, NULL).  Returns
 * DM_OK or DM_ENOMEM (the run should stop; the samples so far are kept). */
int dm_traj_sink(void *ctx, double t, const double *q, const double *p,
                 const double *v);

/* ---- shape and columns --------------------------------------------------- */

size_t dm_traj_len(const dm_traj *tr);        /* samples */
size_t dm_traj_ncoords(const dm_traj *tr);    /* n */
size_t dm_traj_nmomenta(const dm_traj *tr);   /* np */
int dm_traj_named_momenta(const dm_traj *tr); /* 1: p, v columns named apart */
size_t dm_traj_ncols(const dm_traj *tr);      /* all columns, t included */
unsigned dm_traj_flags(const dm_traj *tr);    /* DM_TRAJ_WITH_* */
/* Name of coordinate i (< n); NULL when out of range. */
const char *dm_traj_coord(const dm_traj *tr, size_t i);

/* Column j (< ncols): name, kind (enum dm_traj_kind; -1 out of range) and
 * data (len values; NULL out of range or while the trajectory is empty). */
const char *dm_traj_colname(const dm_traj *tr, size_t j);
int dm_traj_colkind(const dm_traj *tr, size_t j);
const double *dm_traj_col(const dm_traj *tr, size_t j);
/* Short name of a kind: "t", "q", "p", "v", "diag", "derived", "data". */
const char *dm_traj_kindname(int kind);

/* Index of the column called `name`, or DM_TRAJ_NONE. */
size_t dm_traj_find(const dm_traj *tr, const char *name);
/* Index of the q column of coordinate i (< n), of the p / v column of
 * momentum i (< np), or DM_TRAJ_NONE when i is out of range or the
 * trajectory does not store that kind. */
size_t dm_traj_qcol(const dm_traj *tr, size_t i);
size_t dm_traj_pcol(const dm_traj *tr, size_t i);
size_t dm_traj_vcol(const dm_traj *tr, size_t i);

/* Index of column `name`; DM_ENOTFOUND with the message
 * "no column 'x' (available: t, r, p_r, ...)" when absent. */
int dm_traj_lookup(const dm_traj *tr, const char *name, size_t *j, dm_err *e);

/* Write "t, r, p_r, ..." (all column names, comma+space separated) into buf
 * (truncated with "..." when it does not fit); returns buf. */
char *dm_traj_names(const dm_traj *tr, char *buf, size_t size);

/* Copy sample k into the caller's arrays (each may be NULL; q gets n
 * values, p and v np, NaN when not stored).  DM_EINVAL when k >= len. */
int dm_traj_get(const dm_traj *tr, size_t k, double *t, double *q, double *p,
                double *v, dm_err *e);
/* Copy all ncols values of sample k into row.  DM_EINVAL when k >= len. */
int dm_traj_row(const dm_traj *tr, size_t k, double *row, dm_err *e);

/* ---- extra columns ----------------------------------------------------------- */

/* Add an extra column of the given kind (DM_TRAJ_DIAG, _DERIVED or _DATA)
 * filled with values[0..len-1] (NULL: NaN).  With DM_TRAJ_REPLACE in opts an
 * existing extra column of that name is overwritten (kind updated), else
 * DM_EINVAL.  This is how an integrator binding adds diagnostics computed
 * after a run: dm_traj_add_column(tr, DM_TRAJ_ENERGY, DM_TRAJ_DIAG, E, 0, e). */
int dm_traj_add_column(dm_traj *tr, const char *name, int kind,
                       const double *values, unsigned opts, dm_err *e);

/* Remove extra column `name` (t, q, p, v cannot be removed): DM_ENOTFOUND,
 * DM_EINVAL. */
int dm_traj_remove_column(dm_traj *tr, const char *name, dm_err *e);

/* One sample as a derive callback sees it.  row holds all ncols values of
 * the sample (column order); q, p, v, extra point into it (p, v NULL when
 * not stored). */
typedef struct dm_traj_sample {
  size_t k;                 /* sample index, 0-based */
  double t;
  size_t n;                 /* coordinates */
  const double *q, *p, *v;  /* n, np, np values */
  const double *extra;      /* the extra columns that existed before the call */
  const double *row;        /* all columns */
  const dm_traj *traj;      /* for names (read only; do not modify) */
  size_t np;                /* momenta */
} dm_traj_sample;

/* A derive callback writes m values to out (SUNDIALS convention: 0 success,
 * non-zero failure). */
typedef int (*dm_traj_fn)(void *ctx, const dm_traj_sample *s, double *out);

/* Add m extra columns `names` of the given kind whose values are fn(ctx,
 * sample, out) for every stored sample (one call per sample fills all m
 * columns, e.g. x, y, z from cylindrical coordinates).  Nothing changes on
 * failure: DM_ECALLBACK (the message names the sample and the callback's
 * status; a caller that knows more can overwrite it), DM_EINTR, DM_ENOMEM,
 * DM_EINVAL (bad/duplicate name, m == 0).  DM_TRAJ_REPLACE as in
 * dm_traj_add_column.  Samples appended later get NaN in these columns. */
int dm_traj_derive(dm_traj *tr, size_t m, const char *const *names, int kind,
                   dm_traj_fn fn, void *ctx, unsigned opts, dm_err *e);

/* ---- slicing ------------------------------------------------------------------ */

/* New trajectory with samples i, i+stride, ... < j (0-based, half-open;
 * i <= j <= len, stride >= 1; i == j gives an empty trajectory), every column
 * and all metadata.  NULL + DM_EINVAL / DM_ENOMEM. */
dm_traj *dm_traj_slice(const dm_traj *tr, size_t i, size_t j, size_t stride,
                       dm_err *e);

/* ---- metadata --------------------------------------------------------------- */

/* Set key=value (value NULL removes the key; removing an absent key is OK).
 * A key is non-empty, has no '=' and no control character; a value is any
 * C string (newlines and control characters are escaped in files).  Order of
 * first insertion is kept. */
int dm_traj_meta_set(dm_traj *tr, const char *key, const char *value,
                     dm_err *e);
/* Set key to the number x (its text: shortest round-trip form). */
int dm_traj_meta_set_number(dm_traj *tr, const char *key, double x, dm_err *e);
/* Value of key as text (numbers formatted) or NULL. */
const char *dm_traj_meta_get(const dm_traj *tr, const char *key);
/* 1 and *x (may be NULL) = the value when key holds a number, else 0 (absent
 * or a string). */
int dm_traj_meta_number(const dm_traj *tr, const char *key, double *x);
size_t dm_traj_meta_count(const dm_traj *tr);
/* The i-th pair (i < count): DM_OK, else DM_EINVAL. */
int dm_traj_meta_at(const dm_traj *tr, size_t i, const char **key,
                    const char **value);
/* 1 and *x when the i-th value is a number, else 0. */
int dm_traj_meta_number_at(const dm_traj *tr, size_t i, double *x);

/* ---- files ---------------------------------------------------------------------- */

/* CSV format (comment lines start with '#'):
 *   # dmech trajectory 2
 *   # meta <key>=<value, with \\ \n \r \t \xHH escapes>      (string values)
 *   # number <key>=<shortest round-trip number>              (numeric values)
 *   # kinds t,q,q,p,p,v,v,diag,derived                      (one per column)
 *   t,r,theta,p_r,p_theta,v_r,v_theta,energy,x
 *   0,2,0,...                                               (%.17g)
 * The p columns follow the q columns.  When the first is called "p_..."
 * they must be "p_<coord>" for every coordinate (and the v columns
 * "v_<coord>"); otherwise the file has named momenta (above): as many p
 * columns as there are, each keeping its name, and as many v columns.
 * Version 1 files (no "# number" lines) load with every value a string.
 * dm_traj_load also reads a plain CSV whose first line is a header starting
 * with "t" (other '#' lines are skipped): every other column becomes a
 * DM_TRAJ_DATA column.  Errors name the file, the line and what was expected.
 */

/* Save to path as core/outfile.h writes: a regular file (or nothing) is
 * replaced atomically (temp file in the same directory, fsync, rename), a
 * symbolic link is followed, a FIFO or character device is written
 * through, anything else refused.  DM_EIO (message with path and
 * strerror), DM_EINVAL (refused), DM_EINTR; on failure no temporary file
 * is left and an existing file at path is untouched. */
int dm_traj_save(const dm_traj *tr, const char *path, dm_err *e);

/* Write the CSV text to a stream (no atomicity; `name` is used in messages). */
int dm_traj_write(const dm_traj *tr, FILE *f, const char *name, dm_err *e);
/* Only the rows of the samples (after a dm_traj_write of the same columns:
 * a file written in pieces). */
int dm_traj_write_rows(const dm_traj *tr, FILE *f, const char *name, dm_err *e);

/* A CSV or HDF5 file written in pieces as a long run goes (the run
 * driver's sink, run.h), HDF5 when the name ends in .h5, .hdf5 or .he5
 * (dm_h5_wanted, core/trajectory_h5.h), else CSV.  CSV: the first put
 * writes the header (the metadata known then) and the samples, later ones
 * the samples.  HDF5: the layout of dm_traj_save_h5 with chunked,
 * extendible datasets grown by each put, and stream_meta replaces the
 * root attributes by a trajectory's metadata (the run's final ones: steps,
 * status, message), so the file says how the run ended; for CSV
 * stream_meta does nothing.  Close makes the file appear at path, as
 * dm_traj_save would (temporary file, rename), also after an early end of
 * the run -- what was put is kept; abandon removes it; a stream that got
 * nothing leaves no file.  Errors as dm_traj_save's; a stream that failed
 * keeps failing. */
typedef struct dm_traj_stream dm_traj_stream;
int dm_traj_stream_open(const char *path, dm_traj_stream **s, dm_err *e);
int dm_traj_stream_put(dm_traj_stream *s, const dm_traj *tr, dm_err *e);
int dm_traj_stream_meta(dm_traj_stream *s, const dm_traj *tr, dm_err *e);
int dm_traj_stream_close(dm_traj_stream *s, dm_err *e);      /* NULL: DM_OK */
void dm_traj_stream_abandon(dm_traj_stream *s);              /* NULL: no-op */

/* Load a trajectory saved by dm_traj_save (or a plain CSV, see above).
 * NULL + DM_EIO (cannot open/read), DM_EINVAL (malformed: "f.csv:7: expected
 * 9 comma-separated numbers, got 8"), DM_ENOMEM, DM_EINTR. */
dm_traj *dm_traj_load(const char *path, dm_err *e);

#endif
