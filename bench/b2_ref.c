/* b2_ref.c -- high-accuracy references for B2 (writes bench/data/reference.txt).
 *
 * Kepler e = 0.6: exact, from Kepler's equation solved in __float128
 * (a = 1, n = 1, start at pericentre) at t = 1000 periods as a double
 * (the value the harnesses use).  J2: no closed form; integrated in
 * __float128 (113-bit significand, libquadmath) with Stormer-Verlet composed
 * to order 10 by the recursive triple jump (Yoshida 1990: 3^4 = 81 substeps,
 * coefficients computed in __float128), at step h = 0.025, h/2 the difference
 * and h/4; the differences give the observed order and the error estimate of
 * the stored (finest) value.
 * Also prints the vector field at the end so a harness can correct for an
 * end time that differs by round-off (ref(t) = ref(T) + (t - T) f).
 * Usage: b2_ref [out-file]   (default: stdout).  Takes ~15 minutes (run once; the result is committed).
 */
#include <config.h>
#include <quadmath.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <math.h>

typedef __float128 R;

#define J2 0.05Q

static void force(int prob, const R *q, R *f)
{
  if (prob == 0) {
    R r2 = q[0] * q[0] + q[1] * q[1], r = sqrtq(r2), a = 1 / (r2 * r);
    f[0] = -q[0] * a;
    f[1] = -q[1] * a;
  } else {
    R x = q[0], y = q[1], z = q[2], r2 = x * x + y * y + z * z, Rr = sqrtq(r2);
    R a = 1 / (r2 * Rr), b = a / r2, c = b / r2;
    R g = a + J2 * (1.5Q * b - 7.5Q * z * z * c);
    f[0] = -x * g;
    f[1] = -y * g;
    f[2] = -z * g - 3 * J2 * z * b;
  }
}

static R energy(int prob, const R *q, const R *p)
{
  if (prob == 0)
    return 0.5Q * (p[0] * p[0] + p[1] * p[1]) - 1 / sqrtq(q[0] * q[0] + q[1] * q[1]);
  {
    R z = q[2], r2 = q[0] * q[0] + q[1] * q[1] + z * z, Rr = sqrtq(r2);
    return 0.5Q * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1 / Rr
           + J2 / (r2 * Rr) * (1.5Q * z * z / r2 - 0.5Q);
  }
}

static R gam[81];
static int ng;

/* recursive triple jump: order 2 -> 4 -> 6 -> 8 -> 10 */
static void triple_jump(void)
{
  R g[81], t[81];
  int n = 1, k, i, j;
  g[0] = 1;
  for (k = 2; k <= 8; k += 2) {
    R e = 1.0Q / (k + 1), s = powq(2.0Q, e), g1 = 1 / (2 - s), g0 = -s / (2 - s);
    const R w[3] = {g1, g0, g1};
    int m = 0;
    for (j = 0; j < 3; j++)
      for (i = 0; i < n; i++)
        t[m++] = w[j] * g[i];
    n = m;
    for (i = 0; i < n; i++)
      g[i] = t[i];
  }
  for (i = 0; i < n; i++)
    gam[i] = g[i];
  ng = n;
}

/* N composed steps of h; q, p in place; returns max |H - H0| */
static R integrate(int prob, R h, long N, R *q, R *p)
{
  int n = prob == 0 ? 2 : 3, i, s;
  R f[3], H0 = energy(prob, q, p), m = 0;
  long k;
  force(prob, q, f);
  for (k = 0; k < N; k++) {
    for (s = 0; s < ng; s++) {
      R hs = gam[s] * h;
      for (i = 0; i < n; i++) {
        p[i] += 0.5Q * hs * f[i];
        q[i] += hs * p[i];
      }
      force(prob, q, f);
      for (i = 0; i < n; i++)
        p[i] += 0.5Q * hs * f[i];
    }
    if (k % 64 == 0) {
      R d = fabsq(energy(prob, q, p) - H0);
      if (d > m)
        m = d;
    }
  }
  return m;
}

static void kepler_exact(R t, R *q, R *p)
{
  const R e = 0.6Q, pi2 = 2 * M_PIq;
  R M = fmodq(t, pi2), E = M + e * sinq(M);
  int it;
  for (it = 0; it < 100; it++) {
    R d = (E - e * sinq(E) - M) / (1 - e * cosq(E));
    E -= d;
    if (fabsq(d) < 1e-33Q)
      break;
  }
  q[0] = cosq(E) - e;
  q[1] = sqrtq(1 - e * e) * sinq(E);
  p[0] = -sinq(E) / (1 - e * cosq(E));
  p[1] = sqrtq(1 - e * e) * cosq(E) / (1 - e * cosq(E));
}

static void pr(FILE *o, const char *tag, int n, const R *q, const R *p)
{
  char b[64];
  int i;
  fprintf(o, "%s", tag);
  for (i = 0; i < n; i++) {
    quadmath_snprintf(b, sizeof b, "%.25Qe", q[i]);
    fprintf(o, " %s", b);
  }
  for (i = 0; i < n; i++) {
    quadmath_snprintf(b, sizeof b, "%.25Qe", p[i]);
    fprintf(o, " %s", b);
  }
  fprintf(o, "\n");
}

static double dist(int n, const R *q, const R *p, const R *q2, const R *p2)
{
  R s = 0;
  int i;
  for (i = 0; i < n; i++)
    s += (q[i] - q2[i]) * (q[i] - q2[i]) + (p[i] - p2[i]) * (p[i] - p2[i]);
  return (double)sqrtq(s);
}

int main(int argc, char **argv)
{
  FILE *o = argc > 1 ? fopen(argv[1], "w") : stdout;
  const double TK = 2000.0 * 3.14159265358979323846, TJ = 12750.0;
  R qe[3], pe[3], f[3];
  long NJ = 510000;   /* h = 0.025 */
  clock_t c0 = clock();
  if (o == NULL) {
    perror(argv[1]);
    return 1;
  }
  triple_jump();
  fprintf(o, "# bench/data/reference.txt -- written by bench/b2_ref.c (make bench-ref); do not edit.\n");
  fprintf(o, "# Kepler e=0.6: exact (Kepler's equation in __float128) at t = 2000*pi rounded to double.\n");
  fprintf(o, "# J2 (J2 = 0.05, q0 = (2, 0, 0.3), p0 = (0, 0.6, 0.1)) at t = 12750: Stormer-Verlet composed to\n");
  fprintf(o, "# order 10 (recursive triple jump, 81 substeps) in __float128, h = 0.00625 (0.025 and 0.0125 for the estimate).\n");
  fprintf(o, "# Lines: <name>_t T;  <name> q... p... at T;  <name>_v dq/dt... dp/dt... at T (to correct for round-off in the end time).\n");
  /* Kepler: exact value, and a validation of the integrator */
  kepler_exact((R)TK, qe, pe);
  {
    char b[64];
    quadmath_snprintf(b, sizeof b, "%.25Qe", (R)TK);
    fprintf(o, "kepler_t %s\n", b);
  }
  pr(o, "kepler", 2, qe, pe);
  force(0, qe, f);
  pr(o, "kepler_v", 2, pe, f);
  /* J2: three step sizes, the finest is stored */
  {
    R qs[3][3], ps[3][3];
    double dHs[3];
    int lev, i;
    char b[64];
    for (lev = 0; lev < 3; lev++) {
      long N = NJ << lev;
      qs[lev][0] = 2; qs[lev][1] = 0; qs[lev][2] = 0.3Q;
      ps[lev][0] = 0; ps[lev][1] = 0.6Q; ps[lev][2] = 0.1Q;
      dHs[lev] = (double)integrate(1, (R)TJ / N, N, qs[lev], ps[lev]);
    }
    quadmath_snprintf(b, sizeof b, "%.25Qe", (R)TJ);
    fprintf(o, "j2_t %s\n", b);
    pr(o, "j2", 3, qs[2], ps[2]);
    force(1, qs[2], f);
    pr(o, "j2_v", 3, ps[2], f);
    for (i = 0; i < 3; i++)
      fprintf(o, "# J2 h = %g: max|dH| = %.3e\n", TJ / (double)(NJ << i), dHs[i]);
    {
      double d1 = dist(3, qs[0], ps[0], qs[1], ps[1]), d2 = dist(3, qs[1], ps[1], qs[2], ps[2]);
      fprintf(o, "# |ref(0.025) - ref(0.0125)| = %.3e, |ref(0.0125) - ref(0.00625)| = %.3e, observed "
              "order %.1f; error of the stored value ~ %.1e; CPU %.0f s\n", d1, d2, log2(d1 / d2),
              d2 * d2 / d1, (double)(clock() - c0) / CLOCKS_PER_SEC);
    }
  }
  if (o != stdout)
    fclose(o);
  return 0;
}
