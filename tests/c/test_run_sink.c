/* test_run_sink.c -- a run's memory (core/run.h, core/trajectory.h): the
 * storage reserved for exactly the samples recorded and 8 bytes per
 * stored number after the run; streaming to a sink in blocks of
 * sink_every samples, the blocks together bitwise the samples of the run
 * without a sink; a sink that fails stops the run with its message; the
 * CSV stream written in pieces loading back as the one saved at once, and
 * kept after an early end; dm_run_bytes. */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "core/status.h"
#include "core/builtin_systems.h"
#include "core/run.h"
#include "integrators/integrator.h"
#include "tap.h"

typedef struct collect {
  dm_traj *all;             /* the samples received, appended */
  long calls, max_block;
  long fail_at;             /* call number that fails (0: none) */
  dm_traj_stream *file;
} collect;

static int on_sink(void *ctx, const dm_traj *tr, dm_err *e)
{
  collect *c = ctx;
  size_t k, j, n = dm_traj_len(tr), nc = dm_traj_ncols(tr);
  c->calls++;
  if ((long)n > c->max_block)
    c->max_block = (long)n;
  if (c->fail_at && c->calls == c->fail_at)
    return dm_err_set(e, DM_EFAILED, "the disk is full (pretend)");
  if (c->file != NULL)
    return dm_traj_stream_put(c->file, tr, e);
  for (k = 0; k < n; k++) {
    double row[64];             /* t, q, p, v, extra columns in order */
    size_t m = dm_traj_ncoords(tr);
    if (dm_traj_row(tr, k, row, NULL) != DM_OK || nc > 64)
      return DM_EFAILED;
    for (j = dm_traj_ncols(c->all); j < nc; j++)    /* the run's extra columns */
      dm_traj_add_column(c->all, dm_traj_colname(tr, j), dm_traj_colkind(tr, j), NULL, 0, NULL);
    if (dm_traj_append(c->all, row[0], row + 1, row + 1 + m, row + 1 + 2 * m,
                       row + 1 + 3 * m, NULL) != DM_OK)
      return DM_ENOMEM;
  }
  return DM_OK;
}

static int same_rows(const dm_traj *a, const dm_traj *b, size_t from, size_t n)
{
  size_t j, k;
  if (dm_traj_ncols(a) != dm_traj_ncols(b) || dm_traj_len(b) < from + n)
    return 0;
  for (j = 0; j < dm_traj_ncols(a); j++)
    for (k = 0; k < n; k++)
      if (memcmp(&dm_traj_col(a, j)[k], &dm_traj_col(b, j)[from + k], sizeof(double)) != 0)
        return 0;
  return 1;
}

int main(void)
{
  dm_system s;
  dm_integrator *I = NULL;
  dm_run_opts o;
  dm_run_result res;
  dm_err e;
  double q0[2] = {0.5, 0.0}, p0[2] = {0.0, 1.3}, q[2], p[2];
  int st;
  dm_builtin_kepler(&s, 2, 1.0, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);

  /* without a sink: every sample, 8 bytes per number after the run */
  dm_traj *full = dm_run_traj_alloc(I, NULL);
  dm_run_opts_init(&o);
  o.h = 0.01;
  o.nsteps = 10000;
  o.every = 7;
  memcpy(q, q0, sizeof q);
  memcpy(p, p0, sizeof p);
  st = dm_run(I, q, p, &o, full, &res, &e);
  size_t len = dm_traj_len(full), nc = dm_traj_ncols(full);
  tap_ok(st == DM_OK && len == 10000 / 7 + 2, "10000 steps every 7: %zu samples", len);
  tap_is_int((long)dm_traj_bytes(full), (long)(len * nc * 8),
             "after the run the trajectory holds 8 bytes per stored number (%zu columns)", nc);
  tap_is_int((long)dm_run_bytes(I, &o), (long)((10000 / 7 + 2) * nc * 8),
             "dm_run_bytes: what the run reserves, known before it");

  /* a sink every 100 samples: the blocks are the samples, bitwise */
  collect c = {dm_run_traj_alloc(I, NULL), 0, 0, 0, NULL};
  dm_traj *tr = dm_run_traj_alloc(I, NULL);
  o.sink = on_sink;
  o.sink_ctx = &c;
  o.sink_every = 100;
  memcpy(q, q0, sizeof q);
  memcpy(p, p0, sizeof p);
  st = dm_run(I, q, p, &o, tr, &res, &e);
  tap_ok(st == DM_OK && c.calls == (long)(len + 99) / 100 && c.max_block == 100,
         "sink_every = 100: %ld calls of at most 100 samples", c.calls);
  tap_ok(same_rows(c.all, full, 0, len) && dm_traj_len(c.all) == len,
         "the samples streamed are bitwise those of the run without a sink");
  tap_ok(dm_traj_len(tr) == 1 && same_rows(tr, full, len - 1, 1) && (size_t)res.samples == len,
         "the trajectory returned holds the last sample; the result counts them all");
  tap_ok(dm_traj_bytes(tr) <= nc * 8 && dm_run_bytes(I, &o) == 100 * nc * 8,
         "with a sink the run holds sink_every samples at most (%zu bytes reserved)",
         dm_run_bytes(I, &o));
  dm_traj_free(tr);
  dm_traj_free(c.all);

  /* a sink that fails: the run stops with its message */
  collect f = {dm_run_traj_alloc(I, NULL), 0, 0, 3, NULL};
  o.sink_ctx = &f;
  tr = dm_run_traj_alloc(I, NULL);
  memcpy(q, q0, sizeof q);
  memcpy(p, p0, sizeof p);
  st = dm_run(I, q, p, &o, tr, &res, &e);
  tap_ok(st == DM_EFAILED && strstr(e.msg, "the sink failed: the disk is full (pretend)") != NULL
         && res.steps < 10000 && f.calls == 3, "a failing sink stops the run: %s", e.msg);
  dm_traj_free(tr);
  dm_traj_free(f.all);

  /* the CSV stream: the same file as dm_traj_save's of the whole run */
  char dir[] = "/tmp/dmech_sinkXXXXXX";
  if (mkdtemp(dir) == NULL) {
    tap_skip("no temporary directory");
    return tap_done();
  }
  char a[256], b[256];
  snprintf(a, sizeof a, "%s/streamed.csv", dir);
  snprintf(b, sizeof b, "%s/saved.csv", dir);
  collect w = {NULL, 0, 0, 0, NULL};
  st = dm_traj_stream_open(a, &w.file, &e);
  o.sink_ctx = &w;
  o.sink_every = 33;
  tr = dm_run_traj_alloc(I, NULL);
  memcpy(q, q0, sizeof q);
  memcpy(p, p0, sizeof p);
  st = st == DM_OK ? dm_run(I, q, p, &o, tr, &res, &e) : st;
  tap_ok(st == DM_OK && access(a, F_OK) != 0, "while streaming, the file is not at its path");
  st = dm_traj_stream_close(w.file, &e);
  dm_traj *back = dm_traj_load(a, &e);
  tap_ok(st == DM_OK && back != NULL && dm_traj_len(back) == len && same_rows(back, full, 0, len),
         "the CSV written in blocks of 33 loads back as the samples, bitwise");
  dm_traj_free(back);
  dm_traj_free(tr);
  /* an early end: what was streamed stays */
  w.file = NULL;
  w.calls = 0;
  w.fail_at = 0;
  dm_traj_stream_open(b, &w.file, NULL);
  o.max_energy_error = 1e-300;   /* stops after a few steps */
  o.energy = 1;
  tr = dm_run_traj_alloc(I, NULL);
  memcpy(q, q0, sizeof q);
  memcpy(p, p0, sizeof p);
  st = dm_run(I, q, p, &o, tr, &res, &e);
  int cs = dm_traj_stream_close(w.file, NULL);
  back = dm_traj_load(b, NULL);
  tap_ok(st == DM_EDIVERGED && cs == DM_OK && back != NULL && dm_traj_len(back) == (size_t)res.samples,
         "an early end (energy runaway) keeps the %ld samples streamed", res.samples);
  dm_traj_free(back);
  dm_traj_free(tr);
  /* nothing recorded: no file */
  char c2[256];
  snprintf(c2, sizeof c2, "%s/none.csv", dir);
  dm_traj_stream *none = NULL;
  dm_traj_stream_open(c2, &none, NULL);
  tap_ok(dm_traj_stream_close(none, NULL) == DM_OK && access(c2, F_OK) != 0,
         "a stream that got nothing leaves no file");
  remove(a);
  remove(b);
  rmdir(dir);

  dm_traj_free(full);
  dm_integrator_free(I);
  dm_system_release(&s);
  return tap_done();
}
