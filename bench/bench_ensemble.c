/* bench_ensemble.c -- the ensemble driver and its HDF5 output against their
 * references, ratios printed in one run (doc/ensembles.md §8):
 *
 *  1. threads: a MEGNO ensemble (the built-in C J2 satellite, Gauss s = 2,
 *     the exact step Jacobian every step) on 1 and on 2 threads; the ratio
 *     of the wall times is the speed-up (goal: >= 1.8 on 2 cores);
 *  2. per-member overhead: many short members (reduce "final", 1 thread)
 *     against the bare loop a C programmer writes -- one integrator,
 *     dm_integrator_reset and dm_integrator_advance per start -- over the
 *     same starts; (ensemble - bare) / members (goal: <= 5 us);
 *  3. HDF5: an ensemble-shaped table of 10 columns x 10^7 rows (10^8
 *     doubles, 800 MB) saved with dm_traj_save_h5 (fsync included) against
 *     `dd if=/dev/zero bs=8000000 count=100 conv=fsync` into the same
 *     directory; MB/s of each and the ratio (goal: >= 0.5).
 *
 *   bench/bench_ensemble [directory for the 800 MB files (default .)] [reps (3)]
 *                        [parts: threads,overhead,hdf5 (default all)]
 *
 * Each timing is the minimum over reps runs (wall clock, CLOCK_MONOTONIC):
 * on a shared machine the minimum is the run least disturbed.
 */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "core/builtin_systems.h"
#include "core/ensemble.h"
#include "core/trajectory_h5.h"
#include "integrators/integrator.h"

/* CPU seconds of every thread of the process */
static double cpu(void)
{
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec
         + (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* J2 orbits: a = 1.5 + 0.02 k, inclined 40 degrees */
static int j2_start(void *ctx, long k, double *q, double *p, double *par, dm_err *e)
{
  double a = 1.5 + 0.02 * (double)(k % 100), v = sqrt(1.0 / a), c = cos(0.7), s = sin(0.7);
  (void)ctx, (void)par, (void)e;
  q[0] = a, q[1] = 0, q[2] = 0;
  p[0] = 0, p[1] = v * c, p[2] = v * s;
  return DM_OK;
}

static double ensemble_time(dm_integrator *I, long members, long nsteps, unsigned reduce,
                            int threads, dm_traj **keep)
{
  dm_ens_opts o;
  dm_traj *t = NULL;
  dm_err e;
  double t0;
  dm_ens_opts_init(&o);
  o.members = members;
  o.threads = threads;
  o.run.h = 0.02;
  o.run.nsteps = nsteps;
  o.run.every = nsteps > 0 ? nsteps : 1;
  o.reduce = reduce;
  o.start = j2_start;
  t0 = now();
  if (dm_ensemble_run(I, &o, &t, NULL, &e) != DM_OK) {
    fprintf(stderr, "bench_ensemble: %s\n", e.msg);
    exit(1);
  }
  t0 = now() - t0;
  if (keep != NULL)
    *keep = t;
  else
    dm_traj_free(t);
  return t0;
}

static void threads(dm_integrator *I, int reps)
{
  double t1 = INFINITY, t2 = INFINITY, c1 = INFINITY, c2 = INFINITY;
  dm_traj *a = NULL, *b = NULL;
  int r;
  for (r = 0; r < reps; r++) {
    double c0 = cpu();
    double x = ensemble_time(I, 64, 4000, DM_ENS_BIT(DM_ENS_MEGNO), 1, r == 0 ? &a : NULL);
    double c = cpu(), y;
    c1 = fmin(c1, c - c0);
    y = ensemble_time(I, 64, 4000, DM_ENS_BIT(DM_ENS_MEGNO), 2, r == 0 ? &b : NULL);
    c2 = fmin(c2, cpu() - c);
    t1 = fmin(t1, x);
    t2 = fmin(t2, y);
  }
  printf("threads   64 MEGNO members x 4000 steps (J2, Gauss s=2): 1 thread %.3f s, 2 threads "
         "%.3f s: speed-up %.2f (goal >= 1.8); CPU seconds %.3f and %.3f (2 x their ratio, %.2f, is the "
         "speed-up 2 idle cores would give); tables equal: %s\n", t1, t2, t1 / t2, c1, c2, c1 / c2 * 2,
         memcmp(dm_traj_col(a, 1), dm_traj_col(b, 1), 64 * sizeof(double)) == 0 ? "yes" : "NO");
  dm_traj_free(a);
  dm_traj_free(b);
}

static void overhead(dm_integrator *I, int reps)
{
  enum { M = 20000, STEPS = 10 };
  double te = INFINITY, tb = INFINITY, sink = 0;
  int r;
  for (r = 0; r < reps; r++) {
    double t0;
    long k;
    te = fmin(te, ensemble_time(I, M, STEPS, DM_ENS_BIT(DM_ENS_FINAL), 1, NULL));
    t0 = now();
    for (k = 0; k < M; k++) {
      double q[3], p[3];
      long done;
      j2_start(NULL, k, q, p, NULL, NULL);
      dm_integrator_reset(I);
      dm_integrator_advance(I, 0.02, STEPS, q, p, &done, NULL);
      sink += q[0];
    }
    tb = fmin(tb, now() - t0);
  }
  printf("overhead  %d members x %d steps, 1 thread: ensemble %.3f s, bare loop %.3f s: "
         "%.2f us per member over the bare run (goal <= 5; %.2f us per member in all)%s\n",
         M, STEPS, te, tb, 1e6 * (te - tb) / M, 1e6 * te / M, sink == 0 ? " " : "");
}

static void hdf5(const char *dir, int reps)
{
  enum { COLS = 10 };
  const long rows = 10000000L;
  char path[4096], cmd[8300];
  dm_traj *t = dm_traj_alloc(0, NULL, 0, NULL);
  double row[COLS], th = INFINITY, td = INFINITY, mb = (double)rows * COLS * 8 / 1e6;
  dm_err e;
  long k;
  int j, r;
  for (j = 1; j < COLS; j++) {
    char name[16];
    snprintf(name, sizeof name, "c%d", j);
    dm_traj_add_column(t, name, DM_TRAJ_DATA, NULL, 0, NULL);
  }
  dm_traj_meta_set_number(t, "members", (double)rows, NULL);
  if (dm_traj_reserve(t, (size_t)rows, &e) != DM_OK) {
    printf("hdf5      skipped: %s\n", e.msg);
    dm_traj_free(t);
    return;
  }
  for (k = 0; k < rows; k++) {
    for (j = 0; j < COLS; j++)
      row[j] = sin(0.001 * (double)k + j);
    dm_traj_append(t, row[0], NULL, NULL, NULL, row + 1, NULL);
  }
  snprintf(path, sizeof path, "%s/bench_ensemble.h5", dir);
  for (r = 0; r < reps; r++) {
    double t0 = now();
    if (dm_traj_save_h5(t, path, &e) != DM_OK) {
      printf("hdf5      failed: %s\n", e.msg);
      break;
    }
    th = fmin(th, now() - t0);
    unlink(path);
    snprintf(cmd, sizeof cmd, "dd if=/dev/zero of='%s/bench_ensemble.dd' bs=8000000 count=%ld "
             "conv=fsync status=none", dir, rows * COLS * 8 / 8000000);
    t0 = now();
    if (system(cmd) != 0) {
      printf("hdf5      dd failed\n");
      break;
    }
    td = fmin(td, now() - t0);
    snprintf(cmd, sizeof cmd, "%s/bench_ensemble.dd", dir);
    unlink(cmd);
  }
  printf("hdf5      %.0f MB (10^8 doubles, %d columns) in %s: dm_traj_save_h5 %.0f MB/s, dd %.0f "
         "MB/s: ratio %.2f (goal >= 0.5)\n", mb, COLS, dir, mb / th, mb / td, td / th);
  dm_traj_free(t);
}

int main(int argc, char **argv)
{
  const char *dir = argc > 1 ? argv[1] : ".";
  int reps = argc > 2 ? atoi(argv[2]) : 3;
  const char *parts = argc > 3 ? argv[3] : "threads,overhead,hdf5";
  dm_system s;
  dm_integrator *I;
  dm_gsl_init();
  if (reps < 1)
    reps = 1;
  dm_builtin_j2(&s, 0.05, NULL);
  dm_integrator_new(&s, "gauss", NULL, &I, NULL);
  printf("bench_ensemble: %ld online processors, HDF5 %s\n", sysconf(_SC_NPROCESSORS_ONLN),
         dm_h5_version());
  if (strstr(parts, "threads"))
    threads(I, reps);
  if (strstr(parts, "overhead"))
    overhead(I, reps);
  if (strstr(parts, "hdf5"))
    hdf5(dir, reps);
  dm_integrator_free(I);
  dm_system_release(&s);
  return 0;
}
