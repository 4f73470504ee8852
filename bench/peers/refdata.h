/* refdata.h -- read bench/data/reference.txt (written by bench/b2_ref.c) and
 * measure the error of a final state against it.
 *   ref_load(path, name, &r)  fills r (t, y = (q, p), v = (p, f) at t);
 *                             0 on success, -1 when the file or the entry is
 *                             missing (the caller reports the error as NaN)
 *   ref_error(&r, n, t, q, p) 2-norm of (q, p) - ref(t), ref(t) taken as
 *                             ref(T) + (t - T) v (t and T differ by round-off)
 * Header-only, C and C++. */
#ifndef BENCH_REFDATA_H
#define BENCH_REFDATA_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct ref_point {
  long double t;
  double y[6], v[6];
  int n;
} ref_point;

static inline int ref_line(FILE *f, const char *key, int cnt, long double *out)
{
  char line[1024];
  size_t kl = strlen(key);
  rewind(f);
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, key, kl) == 0 && line[kl] == ' ') {
      char *s = line + kl, *end;
      int i;
      for (i = 0; i < cnt; i++) {
        out[i] = strtold(s, &end);
        if (end == s)
          return -1;
        s = end;
      }
      return 0;
    }
  }
  return -1;
}

static inline int ref_load(const char *path, const char *name, ref_point *r)
{
  FILE *f = fopen(path, "r");
  char key[64];
  long double buf[6];
  int n = strcmp(name, "kepler") == 0 ? 2 : 3, i, rc = 0;
  if (f == NULL)
    return -1;
  r->n = n;
  snprintf(key, sizeof key, "%s_t", name);
  rc |= ref_line(f, key, 1, &r->t);
  rc |= ref_line(f, name, 2 * n, buf);
  for (i = 0; i < 2 * n; i++)
    r->y[i] = (double)buf[i];
  snprintf(key, sizeof key, "%s_v", name);
  rc |= ref_line(f, key, 2 * n, buf);
  for (i = 0; i < 2 * n; i++)
    r->v[i] = (double)buf[i];
  fclose(f);
  return rc;
}

static inline double ref_error(const ref_point *r, long double t, const double *q, const double *p)
{
  double s = 0.0, dt = (double)(t - r->t);
  int i;
  for (i = 0; i < 2 * r->n; i++) {
    double x = i < r->n ? q[i] : p[i - r->n], d = x - (r->y[i] + dt * r->v[i]);
    s += d * d;
  }
  return sqrt(s);
}

#endif
