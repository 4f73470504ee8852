/* test_tableau.c -- PRK coefficient generator against the exact tables of
 * doc/integrators.md §5,
 * symplecticity and row sums for s up to 8, user tableaus, error paths. */
#include <config.h>
#include <math.h>
#include <string.h>
#include "core/status.h"
#include "core/tableau.h"
#include "tap.h"

static double maxdiff(const double *x, const double *y, size_t n)
{
  double d = 0.0;
  size_t i;
  for (i = 0; i < n; i++)
    d = fmax(d, fabs(x[i] - y[i]));
  return d;
}

static void check(const char *what, const double *got, const double *want, size_t n)
{
  double d = maxdiff(got, want, n);
  tap_ok(d <= 1e-15, "%s to 1e-15 (max diff %.2g)", what, d);
}

static void t21_gauss(void)
{
  dm_tableau *t;
  const double r3 = sqrt(3.0), r15 = sqrt(15.0);
  const double c1[] = {0.5}, b1[] = {1.0}, a1[] = {0.5};
  const double c2[] = {0.21132486540518712, 0.78867513459481288}, b2[] = {0.5, 0.5};
  const double a2[] = {0.25, -0.038675134594812866, 0.53867513459481287, 0.25};
  const double c3[] = {0.11270166537925831, 0.5, 0.88729833462074169};
  const double b3[] = {5.0 / 18, 4.0 / 9, 5.0 / 18};
  const double a3[] = {0.13888888888888889, -0.035976667524938903, 0.0097894440153083260,
                       0.30026319498086457, 0.22222222222222222, -0.022485417203086815,
                       0.26798833376246944, 0.48042111196938336, 0.13888888888888889};
  const double a3x[] = {5.0 / 36, 2.0 / 9 - r15 / 15, 5.0 / 36 - r15 / 30,
                        5.0 / 36 + r15 / 24, 2.0 / 9, 5.0 / 36 - r15 / 24,
                        5.0 / 36 + r15 / 30, 2.0 / 9 + r15 / 15, 5.0 / 36};
  const double a2x[] = {0.25, 0.25 - r3 / 6, 0.25 + r3 / 6, 0.25};

  tap_is_int(dm_tableau_gauss(1, &t, NULL), DM_OK, "gauss s=1");
  check("G1 c", t->c, c1, 1);
  check("G1 b", t->b, b1, 1);
  check("G1 a", t->a, a1, 1);
  check("G1 at = a", t->at, a1, 1);
  tap_is_int(t->order, 2, "G1 order 2");
  dm_tableau_free(t);

  tap_is_int(dm_tableau_gauss(2, &t, NULL), DM_OK, "gauss s=2");
  check("G2 c", t->c, c2, 2);
  check("G2 b", t->b, b2, 2);
  check("G2 a (decimals)", t->a, a2, 4);
  check("G2 a (closed form)", t->a, a2x, 4);
  check("G2 at = a", t->at, a2x, 4);
  tap_ok((t->flags & DM_TAB_SYMPLECTIC) && (t->flags & DM_TAB_SYMMETRIC), "G2 symplectic and symmetric");
  dm_tableau_free(t);

  tap_is_int(dm_tableau_gauss(3, &t, NULL), DM_OK, "gauss s=3");
  check("G3 c", t->c, c3, 3);
  check("G3 b", t->b, b3, 3);
  check("G3 a (decimals)", t->a, a3, 9);
  check("G3 a (closed form)", t->a, a3x, 9);
  check("G3 at = a", t->at, a3x, 9);
  dm_tableau_free(t);
}

static void t21_lobatto(void)
{
  dm_tableau *t;
  const double r5 = sqrt(5.0);
  const double c2[] = {0, 1}, b2[] = {0.5, 0.5}, a2[] = {0, 0, 0.5, 0.5}, at2[] = {0.5, 0, 0.5, 0};
  const double c3[] = {0, 0.5, 1}, b3[] = {1.0 / 6, 2.0 / 3, 1.0 / 6};
  const double a3[] = {0, 0, 0, 5.0 / 24, 1.0 / 3, -1.0 / 24, 1.0 / 6, 2.0 / 3, 1.0 / 6};
  const double at3[] = {1.0 / 6, -1.0 / 6, 0, 1.0 / 6, 1.0 / 3, 0, 1.0 / 6, 5.0 / 6, 0};
  const double c4[] = {0, 0.5 - r5 / 10, 0.5 + r5 / 10, 1};
  const double b4[] = {1.0 / 12, 5.0 / 12, 5.0 / 12, 1.0 / 12};
  const double a4r2[] = {11.0 / 120 + r5 / 120, 5.0 / 24 - r5 / 120, 5.0 / 24 - 13 * r5 / 120,
                         -1.0 / 120 + r5 / 120};
  const double at4r1[] = {1.0 / 12, -(1 + r5) / 24, (r5 - 1) / 24, 0};

  tap_is_int(dm_tableau_lobatto(2, &t, NULL), DM_OK, "lobatto s=2");
  check("L2 c", t->c, c2, 2);
  check("L2 b", t->b, b2, 2);
  check("L2 a (IIIA)", t->a, a2, 4);
  check("L2 at (IIIB)", t->at, at2, 4);
  tap_is_int(t->order, 2, "L2 order 2");
  dm_tableau_free(t);

  tap_is_int(dm_tableau_lobatto(3, &t, NULL), DM_OK, "lobatto s=3");
  check("L3 c", t->c, c3, 3);
  check("L3 b", t->b, b3, 3);
  check("L3 a (IIIA)", t->a, a3, 9);
  check("L3 at (IIIB)", t->at, at3, 9);
  tap_ok((t->flags & DM_TAB_SYMPLECTIC) && (t->flags & DM_TAB_SYMMETRIC), "L3 symplectic and symmetric");
  dm_tableau_free(t);

  tap_is_int(dm_tableau_lobatto(4, &t, NULL), DM_OK, "lobatto s=4");
  check("L4 c", t->c, c4, 4);
  check("L4 b", t->b, b4, 4);
  check("L4 a row 2", t->a + 4, a4r2, 4);
  check("L4 at row 1", t->at, at4r1, 4);
  tap_is_int(t->order, 6, "L4 order 6");
  dm_tableau_free(t);
}

/* Every generated table up to s = 8: row sums of a and at equal c, sum b = 1,
 * symplecticity defect at round-off, b_i integrates polynomials up to the
 * quadrature order exactly. */
static void generator_s8(void)
{
  size_t s, i, j, k;
  for (k = 0; k < 2; k++)
    for (s = k ? 2 : 1; s <= 8; s++) {
      dm_tableau *t;
      double rs = 0.0, sb = 0.0, mom = 0.0, def;
      int st = k ? dm_tableau_lobatto(s, &t, NULL) : dm_tableau_gauss(s, &t, NULL);
      int deg = k ? (int)(2 * s - 3) : (int)(2 * s - 1);
      if (st != DM_OK) {
        tap_ok(0, "%s s=%zu generated", k ? "lobatto" : "gauss", s);
        continue;
      }
      for (i = 0; i < s; i++) {
        double ra = 0.0, rat = 0.0;
        for (j = 0; j < s; j++) {
          ra += t->a[i * s + j];
          rat += t->at[i * s + j];
        }
        /* Lobatto IIIB s=2 ([[1/2,0],[1/2,0]]) is the classical exception
         * to sum_j at_ij = c_i; every other table satisfies both. */
        rs = fmax(rs, fabs(ra - t->c[i]));
        if (!(k == 1 && s == 2))
          rs = fmax(rs, fabs(rat - t->c[i]));
        sb += t->b[i];
      }
      /* int_0^1 tau^deg = 1/(deg+1) */
      for (i = 0; i < s; i++)
        mom += t->b[i] * pow(t->c[i], deg);
      def = dm_tableau_symplectic_defect(t, NULL, NULL);
      tap_ok(rs <= 4e-15 && fabs(sb - 1.0) <= 4e-15 && def <= 4e-16
             && fabs(mom - 1.0 / (deg + 1)) <= 4e-15
             && (t->flags & DM_TAB_SYMPLECTIC) && (t->flags & DM_TAB_SYMMETRIC),
             "%s s=%zu: row sums %.1g, sum b - 1 = %.1g, symplectic defect %.1g, degree-%d moment %.1g",
             k ? "lobatto" : "gauss", s, rs, sb - 1.0, def, deg, mom - 1.0 / (deg + 1));
      dm_tableau_free(t);
    }
}

static void user_prk(void)
{
  dm_tableau *t;
  dm_err e;
  /* Lobatto IIIA-IIIB s=2 typed in by hand is accepted and symmetric. */
  const double a[] = {0, 0, 0.5, 0.5}, b[] = {0.5, 0.5}, at[] = {0.5, 0, 0.5, 0};
  /* A perturbed at violates b_i at_ij + b_j a_ji = b_i b_j at (1, 2). */
  const double atbad[] = {0.5, 0.001, 0.5, 0};
  /* Explicit RK4 (not symplectic with at = a) */
  const double rk4a[] = {0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1, 0};
  const double rk4b[] = {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6};
  const double bt[] = {0.5, 0.5 + 2.385e-3};
  const double cbad[] = {0.3, 0.3};

  tap_is_int(dm_tableau_prk(2, a, b, at, NULL, NULL, 0, &t, &e), DM_OK, "user L2 tableau accepted");
  tap_ok(t && (t->flags & DM_TAB_SYMMETRIC) && fabs(t->c[1] - 1.0) < 1e-16, "user L2: symmetric, c from row sums");
  dm_tableau_free(t);

  tap_is_int(dm_tableau_prk(2, a, b, atbad, NULL, NULL, 0, &t, &e), DM_EINVAL, "perturbed at rejected");
  tap_ok(t == NULL && strstr(e.msg, "(i, j) = (1, 2)") && strstr(e.msg, "not symplectic"),
         "message names the pair: %s", e.msg);
  tap_is_int(dm_tableau_prk(2, a, b, at, bt, NULL, 0, &t, &e), DM_EINVAL, "b != bt rejected");
  tap_ok(strstr(e.msg, "bt_2") != NULL, "message names bt_2: %s", e.msg);
  tap_is_int(dm_tableau_prk(4, rk4a, rk4b, rk4a, NULL, NULL, 0, &t, &e), DM_EINVAL,
             "RK4 with at = a rejected");
  tap_ok(strstr(e.msg, "defect") || strstr(e.msg, "= "), "RK4 message: %s", e.msg);
  /* at omitted: the symplectic partner of RK4 is derived and accepted */
  tap_is_int(dm_tableau_prk(4, rk4a, rk4b, NULL, NULL, NULL, 0, &t, &e), DM_OK,
             "RK4 with derived partner at accepted");
  tap_ok(t && dm_tableau_symplectic_defect(t, NULL, NULL) < 1e-16, "derived partner is symplectic");
  dm_tableau_free(t);

  tap_is_int(dm_tableau_gauss(0, &t, &e), DM_EINVAL, "gauss s=0 rejected");
  tap_ok(strstr(e.msg, "out of range") != NULL, "message: %s", e.msg);
  tap_is_int(dm_tableau_lobatto(1, &t, &e), DM_EINVAL, "lobatto s=1 rejected");
  tap_is_int(dm_tableau_gauss(DM_TABLEAU_SMAX + 1, &t, &e), DM_EINVAL, "gauss s=21 rejected");
  tap_is_int(dm_tableau_galerkin(2, cbad, &t, &e), DM_EINVAL, "coinciding nodes rejected");
  tap_ok(strstr(e.msg, "coincide") != NULL, "message: %s", e.msg);
}

static void galerkin_nodes(void)
{
  /* Galerkin from the Gauss nodes reproduces the Gauss table; from the
   * Lobatto nodes the Lobatto table. */
  dm_tableau *g, *h;
  double x[6];
  tap_is_int(dm_tableau_gauss(4, &g, NULL), DM_OK, "gauss s=4");
  tap_is_int(dm_tableau_galerkin(4, g->c, &h, NULL), DM_OK, "galerkin on gauss-4 nodes");
  tap_ok(maxdiff(g->a, h->a, 16) < 1e-15 && maxdiff(g->at, h->at, 16) < 1e-15,
         "galerkin(gauss nodes) == gauss");
  dm_tableau_free(g);
  dm_tableau_free(h);
  tap_is_int(dm_tableau_lobatto_nodes(6, x, NULL), DM_OK, "lobatto nodes s=6");
  /* interior nodes of s=6 are (1 -+ sqrt(1/3 -+ 2 sqrt(7)/21))/2 */
  tap_near(x[1], (1 - sqrt(1.0 / 3 + 2 * sqrt(7.0) / 21)) / 2, 1e-16, "L6 node 2");
  tap_near(x[2], (1 - sqrt(1.0 / 3 - 2 * sqrt(7.0) / 21)) / 2, 1e-16, "L6 node 3");
}

int main(void)
{
  dm_gsl_init();
  t21_gauss();
  t21_lobatto();
  generator_s8();
  user_prk();
  galerkin_nodes();
  return tap_done();
}
