/* test_trajectory.c -- columnar trajectories: appending, columns, derived
 * columns, slicing, metadata, CSV round trips and every error path. */
#include <config.h>
#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <locale.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/interrupt.h"
#include "core/trajectory.h"
#include "tap.h"

#define NBIG 100000

static char dir[512];

static const char *path_in(const char *name)
{
  static char buf[4][700];
  static int k;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
  return buf[k];
}

static int has(const char *hay, const char *needle)
{
  int ok = strstr(hay, needle) != NULL;
  if (!ok)
    tap_diag("message '%s' lacks '%s'", hay, needle);
  return ok;
}

static int same_bits(double a, double b)
{
  return memcmp(&a, &b, sizeof a) == 0;
}

/* Files whose name starts with prefix in dir (leftover temporaries). */
static int count_prefixed(const char *prefix)
{
  DIR *d = opendir(dir);
  struct dirent *de;
  int count = 0;
  if (d == NULL)
    return -1;
  while ((de = readdir(d)) != NULL)
    if (strncmp(de->d_name, prefix, strlen(prefix)) == 0)
      count++;
  closedir(d);
  return count;
}

static void write_file(const char *name, const char *text)
{
  FILE *f = fopen(path_in(name), "w");
  fputs(text, f);
  fclose(f);
}

/* A J2-like state at sample k. */
static void state(size_t k, double *t, double q[3], double p[3], double v[3])
{
  double s = 0.05 * (double)k;
  *t = s;
  q[0] = 2.385 + 0.1 * sin(s);
  q[1] = 0.6 * s;
  q[2] = 0.3 * cos(1.1 * s);
  v[0] = 0.1 * cos(s);
  v[1] = 0.6;
  v[2] = -0.33 * sin(1.1 * s);
  p[0] = v[0];
  p[1] = q[0] * q[0] * v[1];
  p[2] = v[2];
}

static dm_traj *big_traj(void)
{
  static const char *const coords[] = {"r", "theta", "z"};
  dm_traj *tr = dm_traj_alloc(3, coords, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL);
  int (*sink)(void *, double, const double *, const double *, const double *) =
    dm_traj_sink;
  size_t k;
  for (k = 0; k < NBIG; k++) {
    double t, q[3], p[3], v[3];
    state(k, &t, q, p, v);
    if (sink(tr, t, q, p, v) != DM_OK)
      break;
  }
  return tr;
}

static void test_columns(dm_traj *tr)
{
  double t, q[3], p[3], v[3], gq[3], gp[3], gv[3], gt, row[10];
  size_t k, j = 0, bad = 0;
  dm_err e;
  char names[64];

  tap_is_int((long)dm_traj_len(tr), NBIG, "10^5 samples appended through the sink");
  tap_is_int((long)dm_traj_ncols(tr), 10, "t + 3 q + 3 p + 3 v columns");
  tap_ok(strcmp(dm_traj_colname(tr, 1), "r") == 0
         && strcmp(dm_traj_colname(tr, 5), "p_theta") == 0
         && strcmp(dm_traj_colname(tr, 9), "v_z") == 0,
         "names: q 'r', momentum 'p_theta', velocity 'v_z'");
  tap_ok(dm_traj_find(tr, "v_theta") == 8 && dm_traj_qcol(tr, 2) == 3
         && dm_traj_pcol(tr, 0) == 4 && dm_traj_vcol(tr, 1) == 8
         && dm_traj_vcol(tr, 3) == DM_TRAJ_NONE, "column indices by name and coordinate");
  tap_ok(dm_traj_colkind(tr, 0) == DM_TRAJ_T && dm_traj_colkind(tr, 6) == DM_TRAJ_P
         && dm_traj_colkind(tr, 7) == DM_TRAJ_V && dm_traj_colkind(tr, 10) == -1,
         "column kinds");
  for (k = 0; k < NBIG; k += 997) {
    state(k, &t, q, p, v);
    dm_traj_get(tr, k, &gt, gq, gp, gv, NULL);
    if (gt != t || memcmp(q, gq, sizeof q) || memcmp(p, gp, sizeof p)
        || memcmp(v, gv, sizeof v) || dm_traj_col(tr, 5)[k] != p[1])
      bad++;
  }
  tap_is_int((long)bad, 0, "every 997th sample reads back exactly (columns and samples)");
  state(NBIG - 1, &t, q, p, v);
  dm_traj_row(tr, NBIG - 1, row, NULL);
  tap_ok(row[0] == t && row[3] == q[2] && row[6] == p[2] && row[8] == v[1],
         "last row t=%.17g r=%.17g", row[0], row[1]);
  tap_is_int(dm_traj_get(tr, NBIG, &gt, NULL, NULL, NULL, &e), DM_EINVAL,
             "sample past the end rejected");
  tap_ok(has(e.msg, "sample 100000 out of range (100000 samples)"), "message: %s", e.msg);
  tap_is_int(dm_traj_lookup(tr, "rho", &j, &e), DM_ENOTFOUND, "unknown column 'rho'");
  tap_ok(has(e.msg, "no column 'rho' (available: t, r, theta, z, p_r, p_theta, p_z, "
             "v_r, v_theta, v_z)"), "the message lists the columns: %s", e.msg);
  dm_traj_names(tr, names, 24);
  tap_ok(strcmp(names, "t, r, theta, z, ...") == 0, "names truncated with ...: '%s'", names);
}

static void test_alloc_errors(void)
{
  static const char *const dup[] = {"x", "x"}, *const tt[] = {"t"},
    *const comma[] = {"a,b"}, *const clash[] = {"x", "p_x"};
  dm_err e;
  dm_traj *tr;
  double q = 2.385;

  tap_ok(dm_traj_alloc(2, dup, 0, &e) == NULL && e.status == DM_EINVAL
         && has(e.msg, "column name 'x' is used twice"), "duplicate coordinates: %s", e.msg);
  tap_ok(dm_traj_alloc(1, tt, 0, &e) == NULL && has(e.msg, "'t' is used twice"),
         "a coordinate cannot be called t: %s", e.msg);
  tap_ok(dm_traj_alloc(1, comma, 0, &e) == NULL && has(e.msg, "invalid coordinate name 'a,b'"),
         "comma in a name: %s", e.msg);
  tap_ok(dm_traj_alloc(2, clash, DM_TRAJ_WITH_P, &e) == NULL
         && has(e.msg, "'p_x' is used twice"), "q name clashing with a momentum name: %s", e.msg);
  tap_ok(dm_traj_alloc(1, NULL, 8, &e) == NULL && e.status == DM_EINVAL, "unknown flags");

  tr = dm_traj_alloc(2, NULL, DM_TRAJ_WITH_V, &e);
  tap_ok(tr != NULL && strcmp(dm_traj_colname(tr, 2), "q2") == 0
         && strcmp(dm_traj_colname(tr, 3), "v_q1") == 0 && dm_traj_pcol(tr, 0) == DM_TRAJ_NONE,
         "default names q1, q2, v_q1 and no p columns");
  tap_is_int(dm_traj_append(tr, 0.5, NULL, NULL, NULL, NULL, &e), DM_EINVAL, "q is required");
  dm_traj_free(tr);

  tr = dm_traj_alloc(1, NULL, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL);
  dm_traj_append(tr, 0.25, &q, NULL, NULL, NULL, NULL);
  tap_ok(dm_traj_col(tr, 1)[0] == 2.385 && isnan(dm_traj_col(tr, 2)[0])
         && isnan(dm_traj_col(tr, 3)[0]), "p, v NULL store NaN (not available)");
  dm_traj_free(tr);
  dm_traj_free(NULL);
}

/* Derive callbacks: cylindrical -> Cartesian; a failing one; an interrupting one. */
static int cart(void *ctx, const dm_traj_sample *s, double *out)
{
  (void)ctx;
  out[0] = s->q[0] * cos(s->q[1]);
  out[1] = s->q[0] * sin(s->q[1]);
  out[2] = 0.5 * (s->v[0] * s->v[0] + s->q[0] * s->q[0] * s->v[1] * s->v[1]
                  + s->v[2] * s->v[2]);
  return 0;
}

static int fail_at(void *ctx, const dm_traj_sample *s, double *out)
{
  out[0] = 1.0;
  return s->k == *(size_t *)ctx ? 7 : 0;
}

static int interrupt_at(void *ctx, const dm_traj_sample *s, double *out)
{
  out[0] = 2.385;
  if (s->k == *(size_t *)ctx)
    dm_interrupt_raise();
  return 0;
}

static int uses_extra(void *ctx, const dm_traj_sample *s, double *out)
{
  (void)ctx;
  out[0] = s->extra[0] * 2.0;   /* x doubled */
  return 0;
}

static void test_derive(dm_traj *tr)
{
  static const char *const xyz[] = {"x", "y", "kinetic"}, *const one[] = {"bad"},
    *const r[] = {"r"}, *const x2[] = {"x2"}, *const x[] = {"x"};
  size_t k, bad = 0, at = 777, nc = dm_traj_ncols(tr);
  dm_err e;
  double t, q[3], p[3], v[3];

  tap_is_int(dm_traj_derive(tr, 3, xyz, DM_TRAJ_DERIVED, cart, NULL, 0, &e), DM_OK,
             "derive x, y, kinetic in one pass");
  for (k = 0; k < NBIG; k += 101) {
    state(k, &t, q, p, v);
    if (dm_traj_col(tr, 10)[k] != q[0] * cos(q[1]) || dm_traj_col(tr, 11)[k] != q[0] * sin(q[1])
        || dm_traj_col(tr, 12)[k] != 0.5 * (v[0] * v[0] + q[0] * q[0] * v[1] * v[1] + v[2] * v[2]))
      bad++;
  }
  tap_is_int((long)bad, 0, "derived values equal the direct formula bit for bit");
  tap_ok(dm_traj_colkind(tr, 11) == DM_TRAJ_DERIVED, "kind derived");

  tap_is_int(dm_traj_derive(tr, 1, one, DM_TRAJ_DERIVED, fail_at, &at, 0, &e), DM_ECALLBACK,
             "failing callback");
  tap_ok(has(e.msg, "callback failed at sample 777 (t = 38.850000000000001) with status 7"),
         "message names the sample: %s", e.msg);
  tap_is_int((long)dm_traj_ncols(tr), (long)nc + 3, "nothing added on failure");

  at = 10;
  dm_interrupt_clear();
  tap_is_int(dm_traj_derive(tr, 1, one, DM_TRAJ_DERIVED, interrupt_at, &at, 0, &e), DM_EINTR,
             "interrupted derive");
  dm_interrupt_clear();
  tap_ok(has(e.msg, "interrupted at sample 11 of 100000") && dm_traj_ncols(tr) == nc + 3,
         "stops at the next sample and adds nothing: %s", e.msg);

  tap_is_int(dm_traj_derive(tr, 1, x, DM_TRAJ_DERIVED, cart, NULL, 0, &e), DM_EINVAL,
             "deriving an existing name without REPLACE");
  tap_ok(has(e.msg, "column 'x' exists"), "message: %s", e.msg);
  tap_is_int(dm_traj_derive(tr, 1, r, DM_TRAJ_DERIVED, cart, NULL, DM_TRAJ_REPLACE, &e),
             DM_EINVAL, "a q column cannot be replaced");
  tap_ok(has(e.msg, "column 'r' is a q column and cannot be replaced"), "message: %s", e.msg);
  tap_is_int(dm_traj_derive(tr, 1, x2, DM_TRAJ_DERIVED, uses_extra, NULL, 0, &e), DM_OK,
             "a derived column may read earlier extra columns");
  tap_ok(dm_traj_col(tr, 13)[4321] == 2.0 * dm_traj_col(tr, 10)[4321], "x2 = 2 x");
  tap_is_int(dm_traj_derive(tr, 1, x2, DM_TRAJ_DERIVED, interrupt_at, &at, DM_TRAJ_REPLACE,
                            &e), DM_EINTR, "interrupted replace");
  dm_interrupt_clear();
  tap_ok(dm_traj_col(tr, 13)[4321] == 2.0 * dm_traj_col(tr, 10)[4321],
         "an interrupted replace keeps the old values");
  at = NBIG + 1;
  tap_is_int(dm_traj_derive(tr, 1, x2, DM_TRAJ_DIAG, interrupt_at, &at, DM_TRAJ_REPLACE, &e),
             DM_OK, "replace with REPLACE");
  tap_ok(dm_traj_col(tr, 13)[4321] == 2.385 && dm_traj_colkind(tr, 13) == DM_TRAJ_DIAG,
         "replaced values and kind");
  tap_is_int(dm_traj_remove_column(tr, "x2", &e), DM_OK, "remove an extra column");
  tap_is_int(dm_traj_remove_column(tr, "p_z", &e), DM_EINVAL, "p columns cannot be removed");
  tap_is_int(dm_traj_remove_column(tr, "nope", &e), DM_ENOTFOUND, "remove unknown column");
  tap_is_int(dm_traj_derive(tr, 0, NULL, DM_TRAJ_DERIVED, cart, NULL, 0, &e), DM_EINVAL,
             "no names");
  tap_is_int(dm_traj_derive(tr, 1, one, DM_TRAJ_Q, cart, NULL, 0, &e), DM_EINVAL,
             "kind q is not an extra kind");
}

static void test_extra_columns(void)
{
  static const char *const c[] = {"x"};
  dm_traj *tr = dm_traj_alloc(1, c, 0, NULL);
  double E[3] = {-0.5, -0.49999999999999994, -0.50000000000000011}, q = 2.385, ex = 7.5;
  double two[2] = {-0.50000000000000011, -0.5};
  dm_err e;
  size_t k;
  for (k = 0; k < 3; k++)
    dm_traj_append(tr, (double)k, &q, NULL, NULL, NULL, NULL);
  tap_is_int(dm_traj_add_column(tr, DM_TRAJ_ENERGY, DM_TRAJ_DIAG, E, 0, &e), DM_OK,
             "add the energy diagnostic");
  tap_is_int(dm_traj_add_column(tr, "momentum_x", DM_TRAJ_DIAG, NULL, 0, &e), DM_OK,
             "add an empty momentum diagnostic");
  tap_ok(dm_traj_col(tr, 2)[1] == E[1] && isnan(dm_traj_col(tr, 3)[2]), "values and NaN fill");
  dm_traj_append(tr, 3.0, &q, NULL, NULL, two, NULL);
  tap_ok(dm_traj_col(tr, 2)[3] == E[2] && dm_traj_col(tr, 3)[3] == E[0],
         "append with extra values");
  dm_traj_append(tr, 4.0, &q, NULL, NULL, NULL, NULL);
  tap_ok(isnan(dm_traj_col(tr, 2)[4]), "append without extras stores NaN");
  tap_is_int(dm_traj_add_column(tr, "bad name", DM_TRAJ_DATA, NULL, 0, &e), DM_EINVAL,
             "space in a column name");
  tap_is_int(dm_traj_add_column(tr, "w", DM_TRAJ_T, NULL, 0, &e), DM_EINVAL, "bad kind");
  tap_is_int(dm_traj_add_column(tr, "energy", DM_TRAJ_DIAG, &ex, 0, &e), DM_EINVAL,
             "duplicate extra column");
  dm_traj_clear(tr);
  tap_ok(dm_traj_len(tr) == 0 && dm_traj_ncols(tr) == 4, "clear keeps the columns");
  dm_traj_free(tr);
}

static void test_slice_meta(dm_traj *tr)
{
  dm_traj *s;
  dm_err e;
  size_t k, bad = 0, nc = dm_traj_ncols(tr);
  const char *key, *val;

  dm_traj_meta_set(tr, "system", "J2 satellite (cylindrical)", NULL);
  dm_traj_meta_set(tr, "method", "gauss", NULL);
  dm_traj_meta_set(tr, "h", "0.05", NULL);
  dm_traj_meta_set(tr, "method", "lobatto", NULL);
  tap_ok(dm_traj_meta_count(tr) == 3 && strcmp(dm_traj_meta_get(tr, "method"), "lobatto") == 0
         && dm_traj_meta_at(tr, 1, &key, &val) == DM_OK && strcmp(key, "method") == 0,
         "metadata: replace keeps the insertion order");
  dm_traj_meta_set(tr, "method", NULL, NULL);
  tap_ok(dm_traj_meta_get(tr, "method") == NULL && dm_traj_meta_count(tr) == 2
         && dm_traj_meta_at(tr, 1, &key, &val) == DM_OK && strcmp(key, "h") == 0,
         "metadata: remove");
  dm_traj_meta_set(tr, "method", "gauss s=2", NULL);
  tap_is_int(dm_traj_meta_set(tr, "a=b", "x", &e), DM_EINVAL, "'=' in a key");
  tap_is_int(dm_traj_meta_set(tr, "", "x", &e), DM_EINVAL, "empty key");
  tap_is_int(dm_traj_meta_at(tr, 3, &key, &val), DM_EINVAL, "meta_at out of range");

  s = dm_traj_slice(tr, 10, 1000, 7, &e);
  tap_ok(s != NULL && dm_traj_len(s) == 142 && dm_traj_ncols(s) == nc,
         "slice [10,1000) stride 7: 142 samples, every column");
  for (k = 0; s != NULL && k < dm_traj_len(s); k++) {
    size_t j;
    for (j = 0; j < nc; j++)
      if (!same_bits(dm_traj_col(s, j)[k], dm_traj_col(tr, j)[10 + 7 * k]))
        bad++;
  }
  tap_is_int((long)bad, 0, "slice values are the strided originals");
  tap_ok(s != NULL && strcmp(dm_traj_meta_get(s, "system"), "J2 satellite (cylindrical)") == 0
         && dm_traj_colkind(s, 12) == DM_TRAJ_DERIVED, "slice keeps metadata and kinds");
  dm_traj_free(s);
  s = dm_traj_slice(tr, 99999, 100000, 1, NULL);
  tap_ok(s != NULL && dm_traj_len(s) == 1 && dm_traj_col(s, 0)[0] == dm_traj_col(tr, 0)[99999],
         "last-sample slice");
  dm_traj_free(s);
  s = dm_traj_slice(tr, 5, 5, 3, NULL);
  tap_ok(s != NULL && dm_traj_len(s) == 0, "empty slice");
  dm_traj_free(s);
  tap_ok(dm_traj_slice(tr, 6, 5, 1, &e) == NULL && e.status == DM_EINVAL
         && has(e.msg, "need i <= j <= 100000"), "reversed slice: %s", e.msg);
  tap_ok(dm_traj_slice(tr, 0, 100001, 1, &e) == NULL, "slice past the end");
  tap_ok(dm_traj_slice(tr, 0, 10, 0, &e) == NULL, "stride 0");
}

static int roundtrip_same(const dm_traj *a, const dm_traj *b)
{
  size_t j, k, i;
  if (dm_traj_len(a) != dm_traj_len(b) || dm_traj_ncols(a) != dm_traj_ncols(b)
      || dm_traj_ncoords(a) != dm_traj_ncoords(b) || dm_traj_flags(a) != dm_traj_flags(b)
      || dm_traj_meta_count(a) != dm_traj_meta_count(b))
    return 0;
  for (j = 0; j < dm_traj_ncols(a); j++) {
    if (strcmp(dm_traj_colname(a, j), dm_traj_colname(b, j)) != 0
        || dm_traj_colkind(a, j) != dm_traj_colkind(b, j))
      return 0;
    for (k = 0; k < dm_traj_len(a); k++) {
      double x = dm_traj_col(a, j)[k], y = dm_traj_col(b, j)[k];
      if (!same_bits(x, y) && !(isnan(x) && isnan(y)))
        return 0;
    }
  }
  for (i = 0; i < dm_traj_meta_count(a); i++) {
    const char *ka, *va, *kb, *vb;
    double xa = 0, xb = 0;
    int na, nb;
    dm_traj_meta_at(a, i, &ka, &va);
    dm_traj_meta_at(b, i, &kb, &vb);
    na = dm_traj_meta_number_at(a, i, &xa);
    nb = dm_traj_meta_number_at(b, i, &xb);
    if (strcmp(ka, kb) != 0 || strcmp(va, vb) != 0 || na != nb
        || (na && !same_bits(xa, xb) && !(isnan(xa) && isnan(xb))))
      return 0;
  }
  return 1;
}

static dm_traj *special_traj(void)
{
  static const double vals[] = {
    2.385, 1.0 / 3.0, 1e-300, -0.0, 1.7976931348623157e308, 4.9406564584124654e-324,
    DBL_MIN, -123456789.12345679, 3.141592653589793, 0.1 + 0.2, 1e22, -2.2250738585072009e-308,
    INFINITY, -INFINITY, NAN, 6.02214076e23
  };
  static const char *const c[] = {"r", "theta"};
  size_t nv = sizeof vals / sizeof vals[0], k;
  dm_traj *tr = dm_traj_alloc(2, c, DM_TRAJ_WITH_P, NULL);
  for (k = 0; k < nv; k++) {
    double q[2] = {vals[k], vals[(k + 3) % nv]}, p[2] = {vals[(k + 7) % nv], -vals[k]};
    double ex = vals[(k + 11) % nv];
    if (k == 0)
      dm_traj_add_column(tr, "energy", DM_TRAJ_DIAG, NULL, 0, NULL);
    dm_traj_append(tr, vals[(k + 5) % nv], q, p, NULL, &ex, NULL);
  }
  dm_traj_add_column(tr, "note", DM_TRAJ_DATA, NULL, 0, NULL);
  dm_traj_meta_set(tr, "system", "Kepler e=0.6, \"polar\"", NULL);
  dm_traj_meta_set(tr, "weird key # \\", "line1\nline2\r\tTab\\n\001 é", NULL);
  dm_traj_meta_set(tr, "h", "0.01", NULL);
  return tr;
}

static void test_roundtrip(dm_traj *big)
{
  dm_traj *tr = special_traj(), *back;
  dm_err e;
  char buf[256];
  FILE *f;

  tap_is_int(dm_traj_save(tr, path_in("special.csv"), &e), DM_OK, "save special values");
  back = dm_traj_load(path_in("special.csv"), &e);
  tap_ok(back != NULL, "load special values%s%s", back ? "" : ": ", back ? "" : e.msg);
  tap_ok(back != NULL && roundtrip_same(tr, back),
         "round trip bit-exact: 2.385, 1/3, 1e-300, -0.0, DBL_MAX, denormals, inf, nan, "
         "names, kinds, metadata with newline/backslash/control bytes");
  tap_ok(back != NULL && signbit(dm_traj_col(back, 1)[3]) && dm_traj_col(back, 1)[3] == 0.0,
         "-0.0 keeps its sign");
  dm_traj_free(back);
  f = fopen(path_in("special.csv"), "r");
  tap_ok(f != NULL && fgets(buf, sizeof buf, f) && strcmp(buf, "# dmech trajectory 1\n") == 0,
         "first line is the format magic");
  while (f != NULL && fgets(buf, sizeof buf, f) && buf[0] == '#')
    ;
  tap_ok(strcmp(buf, "t,r,theta,p_r,p_theta,energy,note\n") == 0, "header: %.*s",
         (int)strcspn(buf, "\n"), buf);
  if (fgets(buf, sizeof buf, f) == NULL)
    buf[0] = '\0';
  tap_ok(strcmp(buf, "4.9406564584124654e-324,2.3849999999999998,-0,-123456789.12345679,"
                    "-2.3849999999999998,"
                    "-2.2250738585072009e-308,nan\n") == 0, "first data line is %%.17g: %.*s",
         (int)strcspn(buf, "\n"), buf);
  if (f != NULL)
    fclose(f);
  dm_traj_free(tr);

  tap_is_int(dm_traj_save(big, path_in("big.csv"), &e), DM_OK, "save 10^5 x 13 columns");
  back = dm_traj_load(path_in("big.csv"), &e);
  tap_ok(back != NULL && roundtrip_same(big, back), "10^5-sample round trip bit-exact");
  dm_traj_free(back);
  tap_is_int(count_prefixed("big.csv.tmp"), 0, "no temporary file left behind");
}

/* Save with a decimal-comma LC_NUMERIC: the file must not change. */
static void test_locale(void)
{
  static const char *const names[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8",
                                      "de_DE", NULL};
  const char *got = NULL;
  dm_traj *tr = special_traj(), *back;
  int i;
  char cmd[800];
  for (i = 0; names[i] != NULL && got == NULL; i++)
    got = setlocale(LC_NUMERIC, names[i]);
  if (got == NULL) {               /* build one for this test run */
    snprintf(cmd, sizeof cmd, "localedef -i de_DE -f UTF-8 '%s/loc/de_DE.UTF-8' "
             ">/dev/null 2>&1", dir);
    mkdir(path_in("loc"), 0700);
    if (system(cmd) == 0 || access(path_in("loc/de_DE.UTF-8/LC_NUMERIC"), R_OK) == 0) {
      setenv("LOCPATH", path_in("loc"), 1);
      got = setlocale(LC_NUMERIC, "de_DE.UTF-8");
    }
  }
  if (got == NULL || strcmp(localeconv()->decimal_point, ",") != 0) {
    tap_ok(1, "decimal-comma locale # SKIP no such locale and localedef failed");
    tap_ok(1, "decimal-comma load # SKIP");
  } else {
    char s[32];
    snprintf(s, sizeof s, "%.3f", 2.385);
    tap_diag("LC_NUMERIC=%s prints 2.385 as %s", got, s);
    dm_traj_save(tr, path_in("comma.csv"), NULL);
    back = dm_traj_load(path_in("comma.csv"), NULL);
    setlocale(LC_NUMERIC, "C");
    tap_ok(back != NULL && roundtrip_same(tr, back),
           "save+load under a decimal-comma LC_NUMERIC round-trips");
    dm_traj_free(back);
    back = dm_traj_load(path_in("special.csv"), NULL);
    tap_ok(back != NULL && roundtrip_same(tr, back), "file is identical to the C-locale one");
    dm_traj_free(back);
  }
  setlocale(LC_NUMERIC, "C");
  dm_traj_free(tr);
}

static void expect_load_error(const char *name, const char *text, int status,
                              const char *needle);

/* Numbers as numbers: kept as doubles, formatted shortest, saved as
 * "# number" lines of a version 2 file and loaded back bit for bit. */
static void test_numeric_meta(void)
{
  static const char *const c[] = {"x"};
  dm_traj *tr = dm_traj_alloc(1, c, 0, NULL), *back, *s;
  double q = 2.385, x = 0;
  char buf[128];
  FILE *f;
  dm_err e;
  int v2 = 0, line = 0;
  dm_traj_append(tr, 0.0, &q, NULL, NULL, NULL, NULL);
  tap_is_int(dm_traj_meta_set_number(tr, "h", 0.05, &e), DM_OK, "set a number");
  tap_ok(dm_traj_meta_number(tr, "h", &x) && x == 0.05 && strcmp(dm_traj_meta_get(tr, "h"), "0.05") == 0,
         "it reads back as the double 0.05 and the text \"0.05\"");
  dm_traj_meta_set_number(tr, "third", 1.0 / 3.0, NULL);
  dm_traj_meta_set_number(tr, "stages", 3, NULL);
  dm_traj_meta_set_number(tr, "neg0", -0.0, NULL);
  dm_traj_meta_set_number(tr, "big", -INFINITY, NULL);
  dm_traj_meta_set(tr, "label", "0.05", NULL);
  tap_ok(!dm_traj_meta_number(tr, "label", &x) && !dm_traj_meta_number(tr, "none", &x)
         && strcmp(dm_traj_meta_get(tr, "third"), "0.3333333333333333") == 0
         && strcmp(dm_traj_meta_get(tr, "big"), "-inf") == 0,
         "strings are not numbers; 1/3 and -inf as text: %s, %s", dm_traj_meta_get(tr, "third"),
         dm_traj_meta_get(tr, "big"));
  dm_traj_meta_set(tr, "stages", "three", NULL);
  tap_ok(!dm_traj_meta_number(tr, "stages", NULL) && dm_traj_meta_number_at(tr, 0, NULL)
         && !dm_traj_meta_number_at(tr, 2, NULL) && !dm_traj_meta_number_at(tr, 99, NULL),
         "a string replaces a number in place");
  dm_traj_meta_set_number(tr, "stages", 3, NULL);
  s = dm_traj_slice(tr, 0, 1, 1, NULL);
  tap_ok(s != NULL && dm_traj_meta_number(s, "third", &x) && x == 1.0 / 3.0, "slices keep numbers");
  dm_traj_free(s);
  tap_is_int(dm_traj_save(tr, path_in("nummeta.csv"), &e), DM_OK, "save");
  back = dm_traj_load(path_in("nummeta.csv"), &e);
  tap_ok(back != NULL && roundtrip_same(tr, back) && dm_traj_meta_number(back, "neg0", &x)
         && signbit(x), "numeric metadata round-trips bit for bit (1/3, -0.0, -inf), strings stay strings");
  dm_traj_free(back);
  f = fopen(path_in("nummeta.csv"), "r");
  while (f != NULL && fgets(buf, sizeof buf, f) && buf[0] == '#') {
    v2 |= line++ == 0 && strcmp(buf, "# dmech trajectory 2\n") == 0;
    v2 |= (strcmp(buf, "# number h=0.05\n") == 0) << 1;
    v2 |= (strcmp(buf, "# meta label=0.05\n") == 0) << 2;
  }
  if (f != NULL)
    fclose(f);
  tap_is_int(v2, 7, "version 2 file with '# number h=0.05' and '# meta label=0.05' lines");
  write_file("v1.csv", "# dmech trajectory 1\n# meta h=0.05\n# kinds t\nt\n0\n");
  back = dm_traj_load(path_in("v1.csv"), &e);
  tap_ok(back != NULL && !dm_traj_meta_number(back, "h", NULL)
         && strcmp(dm_traj_meta_get(back, "h"), "0.05") == 0, "a version 1 file loads with strings");
  dm_traj_free(back);
  expect_load_error("badnum.csv", "# dmech trajectory 2\n# number h=0.05x\n# kinds t\nt\n",
                    DM_EINVAL, "badnum.csv:2: '# number' value '0.05x' is not a number");
  dm_traj_free(tr);
}

static void expect_load_error(const char *name, const char *text, int status,
                              const char *needle)
{
  dm_err e;
  dm_traj *tr;
  dm_err_clear(&e);
  write_file(name, text);
  tr = dm_traj_load(path_in(name), &e);
  tap_ok(tr == NULL && e.status == status && has(e.msg, needle), "%s: %s", name, e.msg);
  dm_traj_free(tr);
}

static void test_malformed(void)
{
  dm_err e;
  dm_traj *tr;

  tr = dm_traj_load(path_in("missing.csv"), &e);
  tap_ok(tr == NULL && e.status == DM_EIO && has(e.msg, "missing.csv': No such file"),
         "missing file: %s", e.msg);
  expect_load_error("short.csv", "t,x\n1,2\n3\n", DM_EINVAL,
                    "short.csv:3: expected 2 comma-separated numbers, got 1");
  expect_load_error("long.csv", "t,x\n1,2\n3,4,5,6\n", DM_EINVAL,
                    "long.csv:3: expected 2 comma-separated numbers, got 4");
  expect_load_error("nan.csv", "t,x\n1,2\n3,abc\n", DM_EINVAL,
                    "nan.csv:3: field 2 (column 'x'): 'abc' is not a number");
  expect_load_error("trail.csv", "t,x\n1,2.5e\n", DM_EINVAL,
                    "trail.csv:2: field 2 (column 'x'): '2.5e' is not a number");
  expect_load_error("emptyf.csv", "t,x\n1,\n", DM_EINVAL, "emptyf.csv:2: field 2");
  expect_load_error("blank.csv", "t,x\n1,2\n\n3,4\n", DM_EINVAL,
                    "blank.csv:3: empty line (expected 2 comma-separated numbers)");
  expect_load_error("first.csv", "x,t\n1,2\n", DM_EINVAL,
                    "first.csv:1: the first column must be 't'");
  expect_load_error("empty.csv", "", DM_EINVAL, "empty.csv:0: no header line");
  expect_load_error("onlycomments.csv", "# hello\n# world\n", DM_EINVAL,
                    "onlycomments.csv:2: no header line");
  expect_load_error("nokinds.csv", "# dmech trajectory 1\nt,x\n", DM_EINVAL,
                    "nokinds.csv:2: expected a '# kinds' line before the header");
  expect_load_error("version.csv", "# dmech trajectory 3\n# kinds t\nt\n", DM_EINVAL,
                    "version.csv:1: unsupported trajectory format version '3' (this dmech reads versions 1 and 2)");
  expect_load_error("count.csv", "# dmech trajectory 1\n# kinds t,q\nt,x,y\n", DM_EINVAL,
                    "count.csv:3: the header names 3 columns but '# kinds' lists 2");
  expect_load_error("kind.csv", "# dmech trajectory 1\n# kinds t,q,w\nt,x,y\n", DM_EINVAL,
                    "kind.csv:3: unknown column kind 'w'");
  expect_load_error("pname.csv", "# dmech trajectory 1\n# kinds t,q,p\nt,r,p_x\n", DM_EINVAL,
                    "pname.csv:3: expected momentum column 'p_r'");
  expect_load_error("order.csv", "# dmech trajectory 1\n# kinds t,q,diag,q\nt,r,E,z\n",
                    DM_EINVAL, "order.csv:3: column 'z' of kind q is out of place");
  expect_load_error("twokinds.csv", "# kinds t\n# kinds t\nt\n", DM_EINVAL,
                    "twokinds.csv:2: second '# kinds' line (the first is on line 1)");
  expect_load_error("meta.csv", "# dmech trajectory 1\n# meta h 0.05\n# kinds t\nt\n",
                    DM_EINVAL, "meta.csv:2: expected '# meta key=value'");
  expect_load_error("esc.csv", "# dmech trajectory 1\n# meta a=x\\q\n# kinds t\nt\n",
                    DM_EINVAL, "esc.csv:2: bad escape '\\q'");
  expect_load_error("dupmeta.csv", "# meta a=1\n# meta a=2\nt\n", DM_EINVAL,
                    "dupmeta.csv:2: duplicate metadata key 'a'");
  expect_load_error("dupcol.csv", "t,x,x\n", DM_EINVAL,
                    "dupcol.csv:1: column 'x' appears twice in the header");
  expect_load_error("headblank.csv", "# c\n\nt\n", DM_EINVAL,
                    "headblank.csv:2: empty line where the header was expected");

  /* A plain CSV (no dmech lines, CRLF line ends, blanks around numbers). */
  write_file("plain.csv", "# from elsewhere\r\nt,a,b\r\n0.5, 2.385 ,-1e-300\r\n1.5,3,4\r\n");
  tr = dm_traj_load(path_in("plain.csv"), &e);
  tap_ok(tr != NULL && dm_traj_ncoords(tr) == 0 && dm_traj_ncols(tr) == 3
         && dm_traj_colkind(tr, 1) == DM_TRAJ_DATA && dm_traj_len(tr) == 2
         && dm_traj_col(tr, 1)[0] == 2.385 && dm_traj_col(tr, 2)[0] == -1e-300,
         "plain CSV with CRLF loads as data columns");
  dm_traj_free(tr);
}

static void test_write_failures(dm_traj *big)
{
  dm_traj *tr = special_traj(), *back;
  struct rlimit old, lim;
  dm_err e;
  int st;

  /* A directory nobody may write (root ignores mode bits: use /proc). */
  if (geteuid() != 0) {
    mkdir(path_in("ro"), 0555);
    chmod(path_in("ro"), 0555);
    st = dm_traj_save(tr, path_in("ro/x.csv"), &e);
    tap_ok(st == DM_EIO && has(e.msg, "cannot create a temporary file next to it: "
                               "Permission denied"), "read-only directory: %s", e.msg);
    tap_ok(access(path_in("ro/x.csv"), F_OK) != 0, "no file in the read-only directory");
  } else {
    st = dm_traj_save(tr, "/proc/dmech-traj-test.csv", &e);
    tap_ok(st == DM_EIO && has(e.msg, "cannot create a temporary file next to it"),
           "non-writable directory (/proc, running as root): %s", e.msg);
    tap_ok(access("/proc/dmech-traj-test.csv", F_OK) != 0, "no file in /proc");
  }
  st = dm_traj_save(tr, path_in("nodir/x.csv"), &e);
  tap_ok(st == DM_EIO && has(e.msg, "No such file or directory"), "missing directory: %s", e.msg);

  /* The disk "fills up" half way (RLIMIT_FSIZE): the old file stays. */
  dm_traj_save(tr, path_in("keep.csv"), NULL);
  signal(SIGXFSZ, SIG_IGN);
  getrlimit(RLIMIT_FSIZE, &old);
  lim = old;
  lim.rlim_cur = 65536;
  setrlimit(RLIMIT_FSIZE, &lim);
  st = dm_traj_save(big, path_in("keep.csv"), &e);
  setrlimit(RLIMIT_FSIZE, &old);
  signal(SIGXFSZ, SIG_DFL);
  tap_ok(st == DM_EIO && has(e.msg, "File too large"), "write failure mid-file: %s", e.msg);
  back = dm_traj_load(path_in("keep.csv"), &e);
  tap_ok(back != NULL && roundtrip_same(tr, back), "the previous file is untouched");
  dm_traj_free(back);
  tap_is_int(count_prefixed("keep.csv.tmp"), 0, "the partial temporary file was removed");

  dm_interrupt_raise();
  st = dm_traj_save(big, path_in("intr.csv"), &e);
  dm_interrupt_clear();
  tap_ok(st == DM_EINTR && access(path_in("intr.csv"), F_OK) != 0
         && count_prefixed("intr.csv") == 0, "interrupted save leaves nothing: %s", e.msg);
  tap_is_int(dm_traj_save(tr, "", &e), DM_EINVAL, "empty file name");
  dm_traj_free(tr);
}

/* Appending under an address-space limit: DM_ENOMEM, every stored sample
 * intact, appending resumes when memory is back.  Runs in a child process. */
static int enomem_child(void)
{
  static const char *const c[] = {"a", "b", "c"};
  dm_traj *tr = dm_traj_alloc(3, c, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, NULL);
  struct rlimit old, lim;
  unsigned long pages = 0;
  size_t k, n;
  dm_err e;
  int st = DM_OK;
  FILE *f = fopen("/proc/self/statm", "r");
  if (f == NULL || fscanf(f, "%lu", &pages) != 1)
    return 10;
  fclose(f);
  getrlimit(RLIMIT_AS, &old);
  lim = old;
  lim.rlim_cur = pages * (unsigned long)sysconf(_SC_PAGESIZE) + (128ul << 20);
  if (setrlimit(RLIMIT_AS, &lim) != 0)
    return 11;
  for (k = 0; st == DM_OK && k < (1ul << 26); k++) {
    double q[3] = {k * 2.385, -(double)k, 1.0 / (k + 1)};
    st = dm_traj_append(tr, (double)k, q, q, q, NULL, &e);
  }
  setrlimit(RLIMIT_AS, &old);
  if (st != DM_ENOMEM)
    return 12;
  if (strstr(e.msg, "kept") == NULL)
    return 13;
  n = dm_traj_len(tr);
  if (n != k - 1 || n < 1000)
    return 14;
  for (k = 0; k < n; k++)
    if (dm_traj_col(tr, 0)[k] != (double)k || dm_traj_col(tr, 1)[k] != k * 2.385
        || dm_traj_col(tr, 9)[k] != 1.0 / (k + 1))
      return 15;
  {
    double q[3] = {1, 2, 3};
    if (dm_traj_append(tr, -1.0, q, q, q, NULL, &e) != DM_OK || dm_traj_len(tr) != n + 1)
      return 16;
  }
  printf("# ENOMEM after %zu samples\n", n);
  fflush(stdout);
  dm_traj_free(tr);
  return 0;
}

static void test_enomem(dm_traj *inherited)
{
  int status = -1;
  pid_t pid;
  fflush(stdout);
  pid = fork();
  if (pid == 0) {
    dm_traj_free(inherited);       /* the child's copy: keep valgrind quiet */
    _exit(enomem_child());
  }
  waitpid(pid, &status, 0);
  tap_ok(WIFEXITED(status) && WEXITSTATUS(status) == 0,
         "allocation failure while appending: DM_ENOMEM, samples intact, appending "
         "resumes (child status %d)", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}

/* A configuration stored in more numbers than it has momenta (a rotation:
 * 9 entries, 3 momenta): named p and v columns through append, get,
 * derive, slice, the CSV round trip and the loader's checks. */
static int np_sum(void *ctx, const dm_traj_sample *s, double *out)
{
  (void)ctx;
  out[0] = (double)s->np + s->p[2] + 10.0 * s->v[0] + 100.0 * s->q[8];
  return 0;
}

static void test_named_momenta(void)
{
  static const char *const g[] = {"R11", "R12", "R13", "R21", "R22", "R23", "R31", "R32", "R33"};
  static const char *const mu[] = {"mu1", "mu2", "mu3"}, *const xi[] = {"xi1", "xi2", "xi3"};
  static const char *const dname[] = {"d"};
  double q[9], p[3], v[3], t, q2[9], p2[3], v2[3];
  dm_traj *tr, *s, *l;
  dm_err e;
  size_t k, i;
  int ok = 1;
  tr = dm_traj_alloc_state(9, g, 3, NULL, NULL, DM_TRAJ_WITH_P, &e);
  tap_ok(tr == NULL && e.status == DM_EINVAL && has(e.msg, "3 momenta for 9 coordinates need "
         "the names of their p and v columns"), "alloc_state without names: %s", e.msg);
  tr = dm_traj_alloc_state(9, g, 3, mu, NULL, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, &e);
  tap_ok(tr == NULL && e.status == DM_EINVAL, "alloc_state: v asked for, no v names: %s", e.msg);
  tr = dm_traj_alloc_state(9, g, 3, mu, xi, DM_TRAJ_WITH_P | DM_TRAJ_WITH_V, &e);
  tap_ok(tr != NULL && dm_traj_ncoords(tr) == 9 && dm_traj_nmomenta(tr) == 3
         && dm_traj_named_momenta(tr) && dm_traj_ncols(tr) == 16, "9 coordinates, 3 momenta");
  if (tr == NULL)
    return;
  tap_ok(dm_traj_pcol(tr, 2) == 12 && dm_traj_vcol(tr, 0) == 13 && dm_traj_vcol(tr, 3) == DM_TRAJ_NONE
         && strcmp(dm_traj_colname(tr, dm_traj_pcol(tr, 1)), "mu2") == 0
         && dm_traj_colkind(tr, 15) == DM_TRAJ_V, "p and v columns by their own names and kinds");
  dm_traj_add_column(tr, "energy", DM_TRAJ_DIAG, NULL, 0, NULL);
  for (k = 0; k < 5; k++) {
    double x = 2.385 * (double)k + 0.125;
    for (i = 0; i < 9; i++)
      q[i] = sin(x + (double)i);
    for (i = 0; i < 3; i++) {
      p[i] = cos(x * (double)(i + 1));
      v[i] = -p[i] / (double)(i + 2);
    }
    dm_traj_append(tr, 0.1 * (double)k, q, p, v, &x, NULL);
  }
  dm_traj_get(tr, 3, &t, q2, p2, v2, NULL);
  tap_ok(t == 0.30000000000000004 && q2[8] == sin(2.385 * 3 + 0.125 + 8.0)
         && p2[2] == cos((2.385 * 3 + 0.125) * 3.0) && v2[1] == -cos((2.385 * 3 + 0.125) * 2.0) / 3.0
         && dm_traj_col(tr, 16)[3] == 2.385 * 3 + 0.125, "get: q (9), p and v (3), extra");
  tap_ok(dm_traj_derive(tr, 1, dname, DM_TRAJ_DERIVED, np_sum, NULL, 0, &e) == DM_OK
         && dm_traj_col(tr, 17)[3] == 3.0 + p2[2] + 10.0 * v2[0] + 100.0 * q2[8],
         "derive sees np = 3 and the named p, v");
  s = dm_traj_slice(tr, 1, 5, 2, &e);
  tap_ok(s != NULL && dm_traj_len(s) == 2 && dm_traj_nmomenta(s) == 3 && dm_traj_named_momenta(s)
         && strcmp(dm_traj_colname(s, 14), "xi2") == 0 && dm_traj_col(s, 12)[1] == dm_traj_col(tr, 12)[3],
         "slice keeps the named momenta");
  dm_traj_free(s);
  dm_traj_meta_set(tr, "space", "SO3", NULL);
  tap_ok(dm_traj_save(tr, path_in("named.csv"), &e) == DM_OK, "save: %s", e.msg);
  l = dm_traj_load(path_in("named.csv"), &e);
  tap_ok(l != NULL && dm_traj_named_momenta(l) && dm_traj_nmomenta(l) == 3 && roundtrip_same(tr, l),
         "CSV round trip, bit for bit: %s", l ? "" : e.msg);
  dm_traj_free(l);
  dm_traj_free(tr);
  /* the first p column not "p_...": named; p and v runs must match */
  write_file("onlyv.csv", "# dmech trajectory 2\n# kinds t,q,q,v\nt,a,b,w\n1,2,3,4\n");
  l = dm_traj_load(path_in("onlyv.csv"), &e);
  ok = l != NULL && dm_traj_ncoords(l) == 2 && dm_traj_nmomenta(l) == 1
       && dm_traj_vcol(l, 0) == 3 && dm_traj_pcol(l, 0) == DM_TRAJ_NONE;
  tap_ok(ok, "v columns alone, named: one velocity for two coordinates");
  dm_traj_free(l);
  expect_load_error("vcount.csv", "# dmech trajectory 2\n# kinds t,q,q,p,v,v\nt,a,b,mu1,xi1,xi2\n",
                    DM_EINVAL, "vcount.csv:3: 2 velocity columns of kind v for 1 momentum "
                    "columns of kind p");
  expect_load_error("vname.csv", "# dmech trajectory 2\n# kinds t,q,p,v\nt,a,p_a,w\n",
                    DM_EINVAL, "vname.csv:3: expected velocity column 'v_a' of kind v after the "
                    "q and p columns");
}

static void cleanup(void)
{
  static const char *const files[] = {
    "special.csv", "big.csv", "comma.csv", "short.csv", "long.csv", "nan.csv", "trail.csv",
    "emptyf.csv", "blank.csv", "first.csv", "empty.csv", "onlycomments.csv", "nokinds.csv",
    "version.csv", "count.csv", "kind.csv", "pname.csv", "order.csv", "twokinds.csv",
    "meta.csv", "esc.csv", "dupmeta.csv", "dupcol.csv", "headblank.csv", "plain.csv",
    "keep.csv", "nummeta.csv", "v1.csv", "badnum.csv", "named.csv", "onlyv.csv", "vcount.csv",
    "vname.csv", NULL
  };
  int i;
  char cmd[700];
  for (i = 0; files[i] != NULL; i++)
    unlink(path_in(files[i]));
  rmdir(path_in("ro"));
  snprintf(cmd, sizeof cmd, "rm -rf '%s/loc'", dir);
  if (access(path_in("loc"), F_OK) == 0 && system(cmd) != 0)
    tap_diag("could not remove %s/loc", dir);
  rmdir(dir);
}

int main(void)
{
  const char *base = getenv("DMECH_TESTTMP");
  dm_traj *big;

  dm_gsl_init();
  setlocale(LC_ALL, "C");
  if (base == NULL || mkdir(base, 0700) != 0) {
    if (base == NULL || errno != EEXIST)
      base = "/tmp";
  }
  snprintf(dir, sizeof dir, "%s/traj-XXXXXX", base);
  if (mkdtemp(dir) == NULL) {
    printf("Bail out! cannot create a temporary directory under %s\n", base);
    return 1;
  }
  test_alloc_errors();
  big = big_traj();
  test_columns(big);
  test_derive(big);
  test_extra_columns();
  test_slice_meta(big);
  test_roundtrip(big);
  test_locale();
  test_numeric_meta();
  test_malformed();
  test_named_momenta();
  test_write_failures(big);
  test_enomem(big);
  dm_traj_free(big);
  cleanup();
  return tap_done();
}
