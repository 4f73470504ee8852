/* benchutil.h -- timing, medians and machine information for the C and C++
 * benchmark harnesses.  Header-only; prints to stdout (benchmarks are
 * programs, not numerics).
 *   bu_cpu()  process CPU time in seconds (CLOCK_PROCESS_CPUTIME_ID)
 *   bu_wall() monotonic wall time in seconds
 *   bu_median(x, n) sorts x in place and returns the median
 *   bu_machine(prog) prints one "# machine: ..." block */
#ifndef BENCH_BENCHUTIL_H
#define BENCH_BENCHUTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/utsname.h>
#include <unistd.h>

static inline double bu_cpu(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline double bu_wall(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline int bu_cmp(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static inline double bu_median(double *x, int n)
{
  qsort(x, (size_t)n, sizeof *x, bu_cmp);
  return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

static inline int bu_env_int(const char *name, int def)
{
  const char *s = getenv(name);
  return s && *s ? atoi(s) : def;
}

static inline void bu_machine(const char *prog)
{
  struct utsname u;
  char line[256], model[200] = "?";
  FILE *f = fopen("/proc/cpuinfo", "r");
  if (f) {
    while (fgets(line, sizeof line, f))
      if (strncmp(line, "model name", 10) == 0) {
        char *c = strchr(line, ':');
        if (c) {
          snprintf(model, sizeof model, "%s", c + 2);
          model[strcspn(model, "\n")] = 0;
        }
        break;
      }
    fclose(f);
  }
  uname(&u);
  printf("# %s\n# machine: %s %s, %ld cores online, %s\n", prog, u.sysname, u.machine,
         sysconf(_SC_NPROCESSORS_ONLN), model);
#ifdef __VERSION__
  printf("# compiler: %s\n", __VERSION__);
#endif
}

#endif
