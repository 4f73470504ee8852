/* trajectory_impl.h -- the representation of a trajectory, shared by the
 * files of src/core that implement trajectory.h (trajectory.c: columns,
 * samples, slicing; trajectory_columns.c: extra columns; trajectory_meta.c:
 * metadata).  Private to src/core. */
#ifndef DM_TRAJECTORY_IMPL_H
#define DM_TRAJECTORY_IMPL_H

#include "core/trajectory.h"

#include <stddef.h>

typedef struct column {
  char *name;
  int kind;
  double *x;          /* capacity >= tr->cap values (NULL while cap == 0) */
} column;

/* A metadata item: a string, or a number (with its text in val). */
typedef struct meta {
  char *key, *val;
  int isnum;
  double x;
} meta;

struct dm_traj {
  size_t n;           /* coordinates (q columns) */
  size_t np;          /* momenta: p and v columns each (n unless named apart) */
  int named;          /* the p and v columns have their own names */
  unsigned flags;     /* DM_TRAJ_WITH_* */
  size_t nstate;      /* 1 + n + np * (has p + has v): first extra column */
  column *cols;
  size_t ncols, colcap;
  size_t *hidx;       /* name hash index: slots hold column + 1, 0 empty; */
  size_t hcap;        /* NULL (linear search) while few columns or no memory */
  size_t len, cap;    /* samples stored, samples every column can hold */
  meta *m;            /* metadata in insertion order */
  size_t nmeta, metacap;
};

/* A malloc'ed copy of s (non-NULL), or NULL when out of memory. */
char *dm_traj__dupstr(const char *s);
/* 1 if s is a valid column name (see trajectory.h). */
int dm_traj__valid_name(const char *s);
/* The DM_EINVAL error for the invalid (or missing) `what` name s. */
int dm_traj__bad_name(dm_err *e, const char *what, const char *s);
/* Keep the name index up to date: column j (the last one) was just
 * appended; or the column list changed otherwise. */
void dm_traj__index_added(dm_traj *tr, size_t j);
void dm_traj__index_rebuild(dm_traj *tr);

#endif
