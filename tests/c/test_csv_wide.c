/* test_csv_wide.c -- the CSV reader and writer on wide files: 10^5 columns
 * load and save with every value intact, a name used twice is found
 * however far apart, and Ctrl-C (the interrupt flag) stops reading and
 * writing a wide file at the next line, not after 4096 of them.
 *
 * The pairwise duplicate test and the column list grown by 8 made a
 * 10^5-column header take 30 s; this program runs under a 20 s CPU limit
 * (RLIMIT_CPU) as a guard against such a regression (it needs ~0.2 s). */
#include <config.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "core/trajectory.h"
#include "tap.h"

#define NC 100000

static char dir[4096];

static void write_wide(const char *path, size_t rows, const char *dup_last)
{
  FILE *f = fopen(path, "w");
  fputs("t", f);
  for (size_t j = 0; j < NC; j++)
    if (j + 1 == NC && dup_last != NULL)
      fprintf(f, ",%s", dup_last);
    else
      fprintf(f, ",c%zu", j);
  fputc('\n', f);
  for (size_t k = 0; k < rows; k++) {
    fprintf(f, "%.17g", 0.5 * (double)k);
    for (size_t j = 0; j < NC; j++)
      fprintf(f, ",%.17g", 2.385 * (double)j + (double)k);
    fputc('\n', f);
  }
  fclose(f);
}

static int count_temporaries(void)
{
  DIR *d = opendir(dir);
  struct dirent *de;
  int n = 0;
  while (d != NULL && (de = readdir(d)) != NULL)
    n += strstr(de->d_name, ".tmp") != NULL;
  if (d != NULL)
    closedir(d);
  return n;
}

int main(void)
{
  struct rlimit cpu = { 20, 20 };
  char path[4200], out[4200];
  dm_err e;
  const char *tt = getenv("DMECH_TESTTMP");
  setrlimit(RLIMIT_CPU, &cpu);
  snprintf(dir, sizeof dir, "%s/csv_wide", tt != NULL && *tt ? tt : "/tmp");
  mkdir(dir, 0700);
  snprintf(path, sizeof path, "%s/wide.csv", dir);
  snprintf(out, sizeof out, "%s/wide_out.csv", dir);

  write_wide(path, 3, NULL);
  dm_traj *tr = dm_traj_load(path, &e);
  tap_ok(tr != NULL, "a CSV file of 10^5 columns x 3 rows loads (%s)",
         tr != NULL ? "ok" : e.msg);
  if (tr != NULL) {
    size_t j = dm_traj_find(tr, "c99999");
    tap_ok(dm_traj_ncols(tr) == NC + 1 && dm_traj_len(tr) == 3,
           "%zu columns, %zu samples", dm_traj_ncols(tr), dm_traj_len(tr));
    tap_ok(j == NC && dm_traj_col(tr, j)[2] == 2.385 * 99999.0 + 2.0,
           "the last column is found by name with its values");
    tap_ok(dm_traj_find(tr, "c50000") == 50001 && dm_traj_find(tr, "c100000")
           == DM_TRAJ_NONE, "lookups in the middle and of a missing name");
    tap_ok(dm_traj_save(tr, out, &e) == DM_OK, "saved again");
    dm_traj *back = dm_traj_load(out, &e);
    int same = back != NULL && dm_traj_ncols(back) == NC + 1;
    for (size_t c = 0; same && c <= NC; c++)
      for (size_t k = 0; k < 3; k++)
        same &= dm_traj_col(back, c)[k] == dm_traj_col(tr, c)[k];
    tap_ok(same, "and read back: every value equal");
    dm_traj_free(back);

    dm_interrupt_raise();
    int st = dm_traj_save(tr, out, &e);
    dm_interrupt_clear();
    tap_ok(st == DM_EINTR && strstr(e.msg, "interrupted at sample 0"),
           "Ctrl-C while saving a wide trajectory stops at once (%s)", e.msg);
    tap_is_int(count_temporaries(), 0, "no temporary file left");
    back = dm_traj_load(out, &e);
    tap_ok(back != NULL && dm_traj_len(back) == 3, "the older file is intact");
    dm_traj_free(back);
    dm_traj_free(tr);
  }

  dm_interrupt_raise();
  tr = dm_traj_load(path, &e);
  dm_interrupt_clear();
  tap_ok(tr == NULL && e.status == DM_EINTR && strstr(e.msg, "interrupted at line 2"),
         "Ctrl-C while reading a wide file stops at the first data line (%s)",
         tr == NULL ? e.msg : "loaded");
  dm_traj_free(tr);

  write_wide(path, 1, "c0");
  tr = dm_traj_load(path, &e);
  tap_ok(tr == NULL && strstr(e.msg, "wide.csv:1: column 'c0' appears twice "
                              "in the header"),
         "columns 2 and 100001 with one name: %s", tr == NULL ? e.msg : "loaded");
  dm_traj_free(tr);
  unlink(path);
  unlink(out);
  return tap_done();
}
