/* dec_poisson.c -- end-to-end cost of a DEC Poisson solve: build the complex,
 * the circumcentric duals, assemble Delta0 (symmetric form), factor with
 * CHOLMOD on the interior unknowns and solve.  bench/dec_bench.sh runs it
 * against the same pipeline written with NumPy/SciPy (bench/dec_poisson.py)
 * on the same mesh, one process per size, and prints the ratios.
 *
 *   dec_poisson gen disc NRINGS FILE   write a Delaunay disc (X: float64
 *                                      nv x 2, T: int32 ntop x 3, after a
 *                                      header "n N nv ntop" of 4 int32)
 *   dec_poisson gen box N FILE         a tetrahedral box (N^3 cubes)
 *   dec_poisson run FILE               time the pipeline on FILE
 *
 * Output of run: one line "phase seconds" per phase, then the peak resident
 * set (kB), the number of unknowns and a check value (u at the middle).
 */
#include <config.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>

#include "dec/dec.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int gen(const char *kind, int size, const char *path)
{
  dm_err e;
  dm_dec_meshdata *m = strcmp(kind, "box") == 0 ? dm_dec_gen_box(size, size, size, 1, 1, 1, &e)
                                                : dm_dec_gen_disc(1.0, size, &e);
  FILE *f;
  int hdr[4];
  if (m == NULL) {
    fprintf(stderr, "gen: %s\n", e.msg);
    return 1;
  }
  if (strcmp(kind, "box") == 0) {           /* break the Kuhn symmetry a little */
    int i, c;
    for (i = 0; i < m->nv; i++)
      for (c = 0; c < 3; c++) {
        double x = m->X[3 * i + c];
        if (x > 0 && x < 1)
          m->X[3 * i + c] += 0.1 / size * sin(2.385 * (3 * i + c));
      }
  }
  hdr[0] = m->n;
  hdr[1] = m->N;
  hdr[2] = m->nv;
  hdr[3] = m->ntop;
  f = fopen(path, "wb");
  if (f == NULL || fwrite(hdr, sizeof hdr, 1, f) != 1 ||
      fwrite(m->X, sizeof(double), (size_t)m->nv * m->N, f) != (size_t)m->nv * m->N ||
      fwrite(m->T, sizeof(int), (size_t)m->ntop * (m->n + 1), f) != (size_t)m->ntop * (m->n + 1) ||
      fclose(f) != 0) {
    perror(path);
    return 1;
  }
  printf("%d-simplices %d vertices %d\n", m->n, m->ntop, m->nv);
  dm_dec_meshdata_free(m);
  return 0;
}

static int run(const char *path)
{
  FILE *f = fopen(path, "rb");
  int hdr[4], i, n, N, nv, nt, nfree = 0, mid = 0;
  double *X, *w, *rhs, *u, t0, t[6], best = 1e300;
  int *T;
  dm_dec_complex *K;
  dm_dec_geom *G;
  dm_sparse *S = NULL;
  dm_dec_solver *F;
  dm_err e;
  struct rusage ru;
  if (f == NULL || fread(hdr, sizeof hdr, 1, f) != 1) {
    perror(path);
    return 1;
  }
  n = hdr[0];
  N = hdr[1];
  nv = hdr[2];
  nt = hdr[3];
  X = malloc((size_t)nv * N * sizeof *X);
  T = malloc((size_t)nt * (n + 1) * sizeof *T);
  if (fread(X, sizeof *X, (size_t)nv * N, f) != (size_t)nv * N ||
      fread(T, sizeof *T, (size_t)nt * (n + 1), f) != (size_t)nt * (n + 1)) {
    fprintf(stderr, "%s: short file\n", path);
    return 1;
  }
  fclose(f);
  t0 = now();
  K = dm_dec_complex_alloc(n, nv, nt, T, &e);
  t[0] = now();
  G = K ? dm_dec_geom_alloc(K, N, X, &e) : NULL;
  t[1] = now();
  if (G == NULL || dm_dec_laplacian(G, 0, NULL, &S, &e) != DM_OK) {
    fprintf(stderr, "%s\n", e.msg);
    return 1;
  }
  t[2] = now();
  F = dm_dec_solver_alloc(S, K->boundary[0], &e);
  t[3] = now();
  if (F == NULL) {
    fprintf(stderr, "%s\n", e.msg);
    return 1;
  }
  w = malloc((size_t)nv * sizeof *w);
  rhs = malloc((size_t)nv * sizeof *rhs);
  u = malloc((size_t)nv * sizeof *u);
  /* triangles: Delta0 u = 1 (mass *0); tetrahedra: S u = 1 (the SciPy twin
   * does not build the signed 3-D *0, so both skip the mass there) */
  dm_dec_star(G, 0, 0, w, NULL);
  for (i = 0; i < nv; i++)
    rhs[i] = 1.0;
  dm_dec_solver_solve(F, n == 3 ? NULL : w, rhs, NULL, u, &e);
  t[4] = now();
  for (i = 0; i < nv; i++) {
    double d = 0;
    int c;
    nfree += !K->boundary[0][i];
    for (c = 0; c < N; c++)
      d += (X[(size_t)i * N + c] - (n == 3 ? 0.5 : 0.0)) * (X[(size_t)i * N + c] - (n == 3 ? 0.5 : 0.0));
    if (d < best) {
      best = d;
      mid = i;
    }
  }
  getrusage(RUSAGE_SELF, &ru);
  printf("complex %.4f\ngeometry %.4f\nassembly %.4f\nfactor %.4f\nsolve %.4f\ntotal %.4f\n",
         t[0] - t0, t[1] - t[0], t[2] - t[1], t[3] - t[2], t[4] - t[3], t[4] - t0);
  printf("maxrss_kb %ld\nunknowns %d\nsimplices %d\ncheck %.10g\n", ru.ru_maxrss, nfree, nt, u[mid]);
  dm_dec_solver_free(F);
  dm_sparse_free(S);
  dm_dec_geom_free(G);
  dm_dec_complex_free(K);
  free(X);
  free(T);
  free(w);
  free(rhs);
  free(u);
  return 0;
}

int main(int argc, char **argv)
{
  dm_gsl_init();
  if (argc == 5 && strcmp(argv[1], "gen") == 0)
    return gen(argv[2], atoi(argv[3]), argv[4]);
  if (argc == 3 && strcmp(argv[1], "run") == 0)
    return run(argv[2]);
  fprintf(stderr, "usage: %s gen disc|box SIZE FILE | run FILE\n", argv[0]);
  return 2;
}
