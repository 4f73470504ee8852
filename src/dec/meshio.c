/* meshio.c -- reading and writing meshes: OFF, Wavefront OBJ, Gmsh .msh
 * (ASCII versions 2.2 and 4.1).  Every defect found while reading names the
 * file, the line and what is wrong (doc/exterior-calculus.md §13). */
#include <config.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/numfmt.h"
#include "dec/dec.h"

/* {==== a growing mesh ============================================================ */

typedef struct {
  const char *path;
  FILE *f;
  char *line;
  size_t cap;
  int lineno;
  dm_err *e;
  /* collected */
  double *X;
  int nv, capv, N;
  int *T, nt, capt, n, *tline;
} reader;

static int rerr(reader *r, const char *fmt, const char *detail)
{
  char buf[DM_ERRMSG_MAX / 2];
  snprintf(buf, sizeof buf, fmt, detail);
  return dm_err_set(r->e, DM_EINVAL, "%s:%d: %s", r->path, r->lineno, buf);
}

/* Next line (without the newline); 0 at end of file. */
static int next_line(reader *r)
{
  size_t len = 0;
  if (r->cap == 0) {
    r->cap = 256;
    if ((r->line = malloc(r->cap)) == NULL)
      return -1;
  }
  r->line[0] = '\0';
  for (;;) {
    if (fgets(r->line + len, (int)(r->cap - len), r->f) == NULL)
      return len > 0 ? 1 : 0;
    len += strlen(r->line + len);
    if (len > 0 && r->line[len - 1] == '\n')
      break;
    if (len + 1 >= r->cap) {
      char *l = realloc(r->line, 2 * r->cap);
      if (l == NULL)
        return -1;
      r->line = l;
      r->cap *= 2;
    }
  }
  while (len > 0 && (r->line[len - 1] == '\n' || r->line[len - 1] == '\r'))
    r->line[--len] = '\0';
  r->lineno++;
  return 1;
}

/* Next line that is not blank and not a comment (c = comment character). */
static int next_content(reader *r, char c)
{
  int st;
  while ((st = next_line(r)) == 1) {
    const char *p = r->line + strspn(r->line, " \t");
    if (*p != '\0' && *p != c)
      return 1;
  }
  return st;
}

static int add_vertex(reader *r, const double *x, int N)
{
  int c;
  if (r->nv == r->capv) {
    int cap = r->capv ? 2 * r->capv : 1024;
    double *X = realloc(r->X, (size_t)cap * 3 * sizeof *X);
    if (X == NULL)
      return dm_err_set(r->e, DM_ENOMEM, "%s: out of memory", r->path);
    r->X = X;
    r->capv = cap;
  }
  for (c = 0; c < 3; c++)
    r->X[(size_t)r->nv * 3 + c] = c < N ? x[c] : 0.0;
  r->nv++;
  return DM_OK;
}

static int add_simplex(reader *r, const int *v, int n)
{
  int i;
  if (r->nt == r->capt) {
    int cap = r->capt ? 2 * r->capt : 1024;
    int *T = realloc(r->T, (size_t)cap * (DM_DEC_MAXDIM + 1) * sizeof *T);
    int *L = realloc(r->tline, (size_t)cap * sizeof *L);
    if (T != NULL)
      r->T = T;
    if (L != NULL)
      r->tline = L;
    if (T == NULL || L == NULL)
      return dm_err_set(r->e, DM_ENOMEM, "%s: out of memory", r->path);
    r->capt = cap;
  }
  for (i = 0; i <= n; i++)
    r->T[(size_t)r->nt * (n + 1) + i] = v[i];
  r->tline[r->nt++] = r->lineno;
  return DM_OK;
}

/* Parse up to max numbers from s; returns the count, -1 on a bad token. */
static int parse_numbers(const char *s, double *x, int max, const char **bad)
{
  int k = 0;
  for (;;) {
    char *end;
    s += strspn(s, " \t");
    if (*s == '\0' || *s == '#')
      return k;
    if (k == max)
      return k + 1;
    x[k] = dm_num_parse(s, &end);
    if (end == s || (*end != '\0' && *end != ' ' && *end != '\t' && *end != '#')) {
      *bad = s;
      return -1;
    }
    k++;
    s = end;
  }
}

static int check_coords(reader *r, const double *x, int k)
{
  int c;
  for (c = 0; c < k; c++)
    if (!isfinite(x[c]))
      return rerr(r, "coordinate %s is not a finite number", c == 0 ? "x" : c == 1 ? "y" : "z");
  return DM_OK;
}

/* }==== */

/* {==== formats ====================================================================== */

static int read_off(reader *r)
{
  double x[16];
  const char *bad = NULL;
  int nv, nf, i, k;
  if (next_content(r, '#') != 1 || strncmp(r->line + strspn(r->line, " \t"), "OFF", 3) != 0)
    return rerr(r, "%s", "OFF header expected");
  k = parse_numbers(r->line + strspn(r->line, " \t") + 3, x, 3, &bad);
  if (k == 0) {
    if (next_content(r, '#') != 1)
      return rerr(r, "%s", "vertex and face counts expected");
    k = parse_numbers(r->line, x, 3, &bad);
  }
  if (k < 2 || x[0] < 1 || x[1] < 1 || x[0] != floor(x[0]) || x[1] != floor(x[1]) || x[0] > INT_MAX
      || x[1] > INT_MAX)
    return rerr(r, "%s", "counts 'vertices faces edges' expected");
  nv = (int)x[0];
  nf = (int)x[1];
  for (i = 0; i < nv; i++) {
    if (next_content(r, '#') != 1)
      return rerr(r, "end of file after %s vertices", "too few");
    k = parse_numbers(r->line, x, 3, &bad);
    if (k < 0)
      return rerr(r, "not a number: '%.40s'", bad);
    if (k != 3)
      return rerr(r, "%s", "3 coordinates expected");
    if (check_coords(r, x, 3) != DM_OK || add_vertex(r, x, 3) != DM_OK)
      return DM_EINVAL;
  }
  r->n = 2;
  for (i = 0; i < nf; i++) {
    int v[3], c;
    if (next_content(r, '#') != 1)
      return rerr(r, "end of file: %s faces than announced", "fewer");
    k = parse_numbers(r->line, x, 16, &bad);
    if (k < 0)
      return rerr(r, "not a number: '%.40s'", bad);
    if (k < 1 || x[0] != 3)
      return rerr(r, "%s", "face with 3 vertices expected (only triangles are supported)");
    if (k != 4)
      return rerr(r, "%s", "face '3 i j k' expected");
    for (c = 0; c < 3; c++) {
      if (x[c + 1] < 0 || x[c + 1] >= nv || x[c + 1] != floor(x[c + 1])) {
        char d[64];
        snprintf(d, sizeof d, "%.17g", x[c + 1]);
        return rerr(r, "vertex %s does not exist (vertices are numbered from 0)", d);
      }
      v[c] = (int)x[c + 1];
    }
    if (add_simplex(r, v, 2) != DM_OK)
      return DM_ENOMEM;
  }
  return DM_OK;
}

static int read_obj(reader *r)
{
  int st;
  r->n = 2;
  while ((st = next_content(r, '#')) == 1) {
    const char *p = r->line + strspn(r->line, " \t");
    if (p[0] == 'v' && (p[1] == ' ' || p[1] == '\t')) {
      double x[4];
      const char *bad = NULL;
      int k = parse_numbers(p + 1, x, 4, &bad);
      if (k < 0)
        return rerr(r, "not a number: '%.40s'", bad);
      if (k < 3)
        return rerr(r, "%s", "vertex 'v x y z' expected");
      if (check_coords(r, x, 3) != DM_OK || add_vertex(r, x, 3) != DM_OK)
        return DM_EINVAL;
    } else if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
      int v[3], c = 0;
      p++;
      for (;;) {
        char *end;
        long idx;
        p += strspn(p, " \t");
        if (*p == '\0' || *p == '#')
          break;
        if (c == 3)
          return rerr(r, "%s", "face with more than 3 vertices (only triangles are supported)");
        errno = 0;
        idx = strtol(p, &end, 10);
        if (end == p || errno != 0)
          return rerr(r, "bad vertex index '%.20s'", p);
        if (idx < 0)
          idx = r->nv + idx + 1;                /* relative index */
        if (idx < 1 || idx > r->nv) {
          char d[64];
          snprintf(d, sizeof d, "%ld", idx);
          return rerr(r, "vertex %s does not exist (not defined before this line)", d);
        }
        v[c++] = (int)idx - 1;
        p = end + strcspn(end, " \t");          /* skip /vt/vn */
      }
      if (c != 3)
        return rerr(r, "%s", "face with 3 vertices expected");
      if (add_simplex(r, v, 2) != DM_OK)
        return DM_ENOMEM;
    }
  }
  return st < 0 ? dm_err_set(r->e, DM_ENOMEM, "%s: out of memory", r->path) : DM_OK;
}

/* A count or a tag read as a double: the int it is, or -1 (a count) /
 * INT_MIN (a tag) when it is not a whole number in range -- a cast of
 * 3.4e10 or NaN to int is undefined. */
static int msh_count(double v)
{
  return v >= 0 && v < INT_MAX && v == floor(v) ? (int)v : -1;
}

static int msh_tag(double v)
{
  return v > INT_MIN && v <= INT_MAX && v == floor(v) ? (int)v : INT_MIN;
}

/* Gmsh: element type -> dimension of the simplex (or -1: ignored). */
static int gmsh_dim(int type)
{
  switch (type) {
  case 15: return 0;
  case 1: return 1;
  case 2: return 2;
  case 4: return 3;
  default: return -1;
  }
}

typedef struct {
  int tag, idx;
} tagmap;

static int cmp_tag(const void *a, const void *b)
{
  int x = ((const tagmap *)a)->tag, y = ((const tagmap *)b)->tag;
  return (x > y) - (x < y);
}

static int find_tag(const tagmap *m, int n, int tag)
{
  int lo = 0, hi = n - 1;
  while (lo <= hi) {
    int mid = lo + (hi - lo) / 2;
    if (m[mid].tag == tag)
      return m[mid].idx;
    if (m[mid].tag < tag)
      lo = mid + 1;
    else
      hi = mid - 1;
  }
  return -1;
}

static int expect(reader *r, const char *what)
{
  if (next_content(r, '\0') != 1 || strcmp(r->line + strspn(r->line, " \t"), what) != 0)
    return rerr(r, "'%s' expected", what);
  return DM_OK;
}

/* Elements of the highest dimension present become the top simplices;
 * lower-dimensional ones (boundary lines, points) are dropped. */
static int read_msh(reader *r)
{
  double x[16], version;
  const char *bad = NULL;
  tagmap *tags = NULL;
  int st = DM_OK, k, i, maxdim = -1, *etype = NULL, *enodes = NULL, *eline = NULL, ne = 0, cape = 0;
  if (expect(r, "$MeshFormat") != DM_OK)
    return DM_EINVAL;
  if (next_content(r, '\0') != 1 || (k = parse_numbers(r->line, x, 3, &bad)) < 2)
    return rerr(r, "%s", "'version file-type data-size' expected");
  version = x[0];
  if (x[1] != 0)
    return rerr(r, "%s", "binary .msh files are not supported (save as ASCII)");
  if (!(version >= 2 && version < 3) && !(version >= 4 && version < 5))
    return rerr(r, "%s", "format version 2.x or 4.x expected");
  if (expect(r, "$EndMeshFormat") != DM_OK)
    return DM_EINVAL;
  /* skip sections until $Nodes */
  for (;;) {
    if (next_content(r, '\0') != 1)
      return rerr(r, "%s", "end of file before $Nodes");
    if (strcmp(r->line, "$Nodes") == 0)
      break;
  }
  if (next_content(r, '\0') != 1 || (k = parse_numbers(r->line, x, 4, &bad)) < (version < 3 ? 1 : 2)
      || msh_count(x[0]) < 0 || (version >= 3 && msh_count(x[1]) < 0))
    return rerr(r, "%s", "node count expected");
  if (version < 3) {
    int nn = msh_count(x[0]);
    tags = malloc(((size_t)nn + 1) * sizeof *tags);
    if (tags == NULL)
      return dm_err_set(r->e, DM_ENOMEM, "%s: out of memory", r->path);
    for (i = 0; i < nn; i++) {
      if (next_content(r, '\0') != 1)
        goto eof;
      k = parse_numbers(r->line, x, 4, &bad);
      if (k < 0) {
        st = rerr(r, "not a number: '%.40s'", bad);
        goto done;
      }
      if (k != 4) {
        st = rerr(r, "%s", "node 'tag x y z' expected");
        goto done;
      }
      if ((st = check_coords(r, x + 1, 3)) != DM_OK || (st = add_vertex(r, x + 1, 3)) != DM_OK)
        goto done;
      if ((tags[i].tag = msh_tag(x[0])) == INT_MIN) {
        st = rerr(r, "%s", "node 'tag x y z' expected");
        goto done;
      }
      tags[i].idx = i;
    }
  } else {
    int nblocks = msh_count(x[0]), nn = msh_count(x[1]), b, got = 0;
    tags = malloc(((size_t)nn + 1) * sizeof *tags);
    if (tags == NULL)
      return dm_err_set(r->e, DM_ENOMEM, "%s: out of memory", r->path);
    for (b = 0; b < nblocks; b++) {
      int cnt, j, first = got;
      if (next_content(r, '\0') != 1)
        goto eof;
      if (parse_numbers(r->line, x, 4, &bad) != 4) {
        st = rerr(r, "%s", "node block 'entityDim entityTag parametric numNodes' expected");
        goto done;
      }
      if ((cnt = msh_count(x[3])) < 0) {
        st = rerr(r, "%s", "node block 'entityDim entityTag parametric numNodes' expected");
        goto done;
      }
      if (x[2] != 0) {
        st = rerr(r, "%s", "parametric nodes are not supported");
        goto done;
      }
      if (got + cnt > nn) {
        st = rerr(r, "%s", "more nodes than announced");
        goto done;
      }
      for (j = 0; j < cnt; j++) {
        if (next_content(r, '\0') != 1)
          goto eof;
        if (parse_numbers(r->line, x, 2, &bad) != 1) {
          st = rerr(r, "%s", "node tag expected");
          goto done;
        }
        if ((tags[got + j].tag = msh_tag(x[0])) == INT_MIN) {
          st = rerr(r, "%s", "node tag expected");
          goto done;
        }
        tags[got + j].idx = got + j;
      }
      for (j = 0; j < cnt; j++) {
        if (next_content(r, '\0') != 1)
          goto eof;
        k = parse_numbers(r->line, x, 4, &bad);
        if (k < 0) {
          st = rerr(r, "not a number: '%.40s'", bad);
          goto done;
        }
        if (k != 3) {
          st = rerr(r, "%s", "node coordinates 'x y z' expected");
          goto done;
        }
        if ((st = check_coords(r, x, 3)) != DM_OK || (st = add_vertex(r, x, 3)) != DM_OK)
          goto done;
      }
      got = first + cnt;
    }
  }
  if ((st = expect(r, "$EndNodes")) != DM_OK)
    goto done;
  qsort(tags, (size_t)r->nv, sizeof *tags, cmp_tag);
  for (i = 1; i < r->nv; i++)
    if (tags[i].tag == tags[i - 1].tag) {
      char d[32];
      snprintf(d, sizeof d, "%d", tags[i].tag);
      st = rerr(r, "node tag %s defined twice", d);
      goto done;
    }
  for (;;) {
    if (next_content(r, '\0') != 1) {
      st = rerr(r, "%s", "end of file before $Elements");
      goto done;
    }
    if (strcmp(r->line, "$Elements") == 0)
      break;
  }
  if (next_content(r, '\0') != 1 || (k = parse_numbers(r->line, x, 4, &bad)) < (version < 3 ? 1 : 2)
      || msh_count(x[0]) < 0 || (version >= 3 && msh_count(x[1]) < 0)) {
    st = rerr(r, "%s", "element count expected");
    goto done;
  }
  {
    int nblocks = version < 3 ? 1 : msh_count(x[0]), b, total = msh_count(version < 3 ? x[0] : x[1]);
    cape = total + 1;
    etype = malloc((size_t)cape * sizeof *etype);
    enodes = malloc((size_t)cape * 4 * sizeof *enodes);
    eline = malloc((size_t)cape * sizeof *eline);
    if (!etype || !enodes || !eline) {
      st = dm_err_set(r->e, DM_ENOMEM, "%s: out of memory", r->path);
      goto done;
    }
    for (b = 0; b < nblocks; b++) {
      int cnt = total, type = 0, j;
      if (version >= 4) {
        if (next_content(r, '\0') != 1)
          goto eof;
        if (parse_numbers(r->line, x, 4, &bad) != 4) {
          st = rerr(r, "%s", "element block 'entityDim entityTag elementType numElements' expected");
          goto done;
        }
        type = msh_tag(x[2]);
        if ((cnt = msh_count(x[3])) < 0) {
          st = rerr(r, "%s", "element block 'entityDim entityTag elementType numElements' expected");
          goto done;
        }
      }
      for (j = 0; j < cnt; j++) {
        int off, dim, c, nnode;
        if (next_content(r, '\0') != 1)
          goto eof;
        k = parse_numbers(r->line, x, 16, &bad);
        if (k < 0) {
          st = rerr(r, "not a number: '%.40s'", bad);
          goto done;
        }
        if (version < 3) {
          if (k < 3 || msh_count(x[2]) < 0 || x[2] > 16) {
            st = rerr(r, "%s", "element 'tag type ntags tags... nodes...' expected");
            goto done;
          }
          type = msh_tag(x[1]);
          off = 3 + msh_count(x[2]);
        } else {
          off = 1;
        }
        dim = gmsh_dim(type);
        if (dim < 0) {
          char d[32];
          snprintf(d, sizeof d, "%d", type);
          st = rerr(r, "element type %s is not a simplex of order 1 (supported: 15 point, 1 line, 2 triangle, 4 tetrahedron)", d);
          goto done;
        }
        nnode = dim + 1;
        if (k != off + nnode) {
          st = rerr(r, "%s", "wrong number of nodes for the element type");
          goto done;
        }
        if (ne >= cape) {
          st = rerr(r, "%s", "more elements than announced");
          goto done;
        }
        for (c = 0; c < nnode; c++) {
          int tag = msh_tag(x[off + c]);
          int idx = tag == INT_MIN ? -1 : find_tag(tags, r->nv, tag);
          if (idx < 0) {
            char d[64];
            snprintf(d, sizeof d, "%.17g", x[off + c]);
            st = rerr(r, "node %s does not exist", d);
            goto done;
          }
          enodes[(size_t)ne * 4 + c] = idx;
        }
        etype[ne] = dim;
        eline[ne++] = r->lineno;
        if (dim > maxdim)
          maxdim = dim;
      }
    }
  }
  if ((st = expect(r, "$EndElements")) != DM_OK)
    goto done;
  if (maxdim < 1) {
    st = dm_err_set(r->e, DM_EINVAL, "%s: no lines, triangles or tetrahedra", r->path);
    goto done;
  }
  r->n = maxdim;
  for (i = 0; i < ne; i++)
    if (etype[i] == maxdim) {
      int save = r->lineno;
      r->lineno = eline[i];
      st = add_simplex(r, enodes + (size_t)i * 4, maxdim);
      r->tline[r->nt - 1] = eline[i];
      r->lineno = save;
      if (st != DM_OK)
        goto done;
    }
  goto done;
eof:
  st = rerr(r, "%s", "unexpected end of file");
done:
  free(tags);
  free(etype);
  free(enodes);
  free(eline);
  return st;
}

/* }==== */

static const char *extension(const char *path)
{
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  return (dot != NULL && (slash == NULL || dot > slash)) ? dot + 1 : "";
}

int dm_dec_read(const char *path, dm_dec_meshdata **out, int **lines, dm_err *e)
{
  reader r;
  const char *ext = extension(path);
  int st, i, c, flat = 1;
  memset(&r, 0, sizeof r);
  r.path = path;
  r.e = e;
  *out = NULL;
  if (lines != NULL)
    *lines = NULL;
  if (strcmp(ext, "off") != 0 && strcmp(ext, "obj") != 0 && strcmp(ext, "msh") != 0)
    return dm_err_set(e, DM_EINVAL, "%s: unknown mesh format '.%s' (.off, .obj or .msh expected)", path, ext);
  if ((r.f = fopen(path, "r")) == NULL)
    return dm_err_set(e, DM_EIO, "%s: %s", path, strerror(errno));
  if (strcmp(ext, "off") == 0)
    st = read_off(&r);
  else if (strcmp(ext, "obj") == 0)
    st = read_obj(&r);
  else
    st = read_msh(&r);
  if (st == DM_OK && ferror(r.f))
    st = dm_err_set(e, DM_EIO, "%s: read error", path);
  fclose(r.f);
  free(r.line);
  if (st == DM_OK && (r.nt == 0 || r.nv == 0))
    st = dm_err_set(e, DM_EINVAL, "%s: no %s found", path, r.nv == 0 ? "vertices" : "simplices");
  if (st == DM_OK) {
    /* planar when every z is 0 (and the mesh is not made of tetrahedra) */
    for (i = 0; i < r.nv && flat; i++)
      flat = r.X[3 * (size_t)i + 2] == 0.0;
    r.N = (flat && r.n <= 2) ? 2 : 3;
    *out = dm_dec_meshdata_alloc(r.n, r.N, r.nv, r.nt, e);
    if (*out == NULL)
      st = DM_ENOMEM;
  }
  if (st == DM_OK) {
    for (i = 0; i < r.nv; i++)
      for (c = 0; c < r.N; c++)
        (*out)->X[(size_t)i * r.N + c] = r.X[(size_t)i * 3 + c];
    memcpy((*out)->T, r.T, (size_t)r.nt * (r.n + 1) * sizeof *r.T);
    if (lines != NULL) {
      *lines = r.tline;
      r.tline = NULL;
    }
  }
  free(r.X);
  free(r.T);
  free(r.tline);
  return st;
}

int dm_dec_write(const char *path, const dm_dec_complex *K, const dm_dec_geom *G, dm_err *e)
{
  const char *ext = extension(path);
  int n = K->n, N = G->N, i, c, fmt, fd;
  size_t plen = strlen(path);
  char *tmp;
  FILE *f;
  locale_t old;
  if (strcmp(ext, "off") == 0)
    fmt = 0;
  else if (strcmp(ext, "obj") == 0)
    fmt = 1;
  else if (strcmp(ext, "msh") == 0)
    fmt = 2;
  else
    return dm_err_set(e, DM_EINVAL, "%s: unknown mesh format '.%s' (.off, .obj or .msh expected)", path, ext);
  if (G->X == NULL || N > 3)
    return dm_err_set(e, DM_EUNSUP, "%s: only meshes with coordinates in R^1..R^3 can be written", path);
  if (fmt < 2 && n != 2)
    return dm_err_set(e, DM_EUNSUP, "%s: OFF and OBJ hold triangle meshes; use .msh for dimension %d", path, n);
  if ((tmp = malloc(plen + 16)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "%s: out of memory", path);
  snprintf(tmp, plen + 16, "%s.XXXXXX", path);
  if ((fd = mkstemp(tmp)) < 0 || (f = fdopen(fd, "w")) == NULL) {
    int err = errno;
    if (fd >= 0) {
      close(fd);
      unlink(tmp);
    }
    free(tmp);
    return dm_err_set(e, DM_EIO, "%s: %s", path, strerror(err));
  }
  old = dm_num_enter();
  if (fmt == 0)
    fprintf(f, "OFF\n%d %d 0\n", K->nsimp[0], K->nsimp[n]);
  else if (fmt == 1)
    fprintf(f, "# dmech mesh: %d vertices, %d triangles\n", K->nsimp[0], K->nsimp[n]);
  else
    fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n", K->nsimp[0]);
  for (i = 0; i < K->nsimp[0]; i++) {
    if (fmt == 1)
      fputs("v", f);
    else if (fmt == 2)
      fprintf(f, "%d", i + 1);
    for (c = 0; c < 3; c++)
      fprintf(f, "%s%.17g", (c == 0 && fmt == 0) ? "" : " ", c < N ? G->X[(size_t)i * N + c] : 0.0);
    fputs("\n", f);
  }
  if (fmt == 2)
    fprintf(f, "$EndNodes\n$Elements\n%d\n", K->nsimp[n]);
  for (i = 0; i < K->nsimp[n]; i++) {
    const int *v = K->top + (size_t)i * (n + 1);
    static const int type[] = {15, 1, 2, 4};
    if (fmt == 0)
      fprintf(f, "3 %d %d %d\n", v[0], v[1], v[2]);
    else if (fmt == 1)
      fprintf(f, "f %d %d %d\n", v[0] + 1, v[1] + 1, v[2] + 1);
    else {
      fprintf(f, "%d %d 2 0 1", i + 1, type[n]);
      for (c = 0; c <= n; c++)
        fprintf(f, " %d", v[c] + 1);
      fputs("\n", f);
    }
  }
  if (fmt == 2)
    fputs("$EndElements\n", f);
  dm_num_leave(old);
  if (ferror(f) | (fclose(f) != 0) || rename(tmp, path) != 0) {
    int err = errno;
    unlink(tmp);
    free(tmp);
    return dm_err_set(e, DM_EIO, "%s: %s", path, strerror(err));
  }
  free(tmp);
  return DM_OK;
}

int dm_dec_load(const char *path, dm_dec_complex **Kout, dm_dec_geom **Gout, dm_err *e)
{
  dm_dec_meshdata *m = NULL;
  dm_dec_complex *K = NULL;
  int *lines = NULL, st, a, b, f, kind, t, i, j;
  static const char *const facename[] = {"vertex", "vertex", "edge", "triangle"};
  *Kout = NULL;
  *Gout = NULL;
  if ((st = dm_dec_read(path, &m, &lines, e)) != DM_OK)
    return st;
  for (t = 0; t < m->ntop; t++)                /* defects the complex would report by number */
    for (i = 0; i <= m->n; i++)
      for (j = 0; j < i; j++)
        if (m->T[t * (m->n + 1) + i] == m->T[t * (m->n + 1) + j]) {
          st = dm_err_set(e, DM_EINVAL, "%s:%d: simplex repeats vertex %d", path, lines[t],
                          m->T[t * (m->n + 1) + i] + 1);
          goto done;
        }
  if ((K = dm_dec_complex_alloc(m->n, m->nv, m->ntop, m->T, e)) == NULL) {
    char msg[DM_ERRMSG_MAX];
    snprintf(msg, sizeof msg, "%s", e != NULL ? e->msg : "");
    st = dm_err_set(e, DM_EINVAL, "%s: %s", path, msg);
    goto done;
  }
  kind = dm_dec_complex_defect(K, &a, &b, &f);
  if (kind != 0) {
    const int *v = K->simp[K->n - 1] + (size_t)f * K->n;
    char face[64];
    int len = 0;
    for (i = 0; i < K->n; i++)
      len += snprintf(face + len, sizeof face - (size_t)len, "%s%d", i ? "," : "(", v[i] + 1);
    snprintf(face + len, sizeof face - (size_t)len, ")");
    if (kind == 1)
      st = dm_err_set(e, DM_EINVAL, "%s:%d: non-manifold %s %s: more than two simplices share it (also line %d)",
                      path, lines[b], facename[K->n], face, lines[a]);
    else
      st = dm_err_set(e, DM_EINVAL,
                      "%s:%d: inconsistent orientation: shares %s %s with the simplex on line %d in the same direction",
                      path, lines[b], facename[K->n], face, lines[a]);
    goto done;
  }
  if ((*Gout = dm_dec_geom_alloc(K, m->N, m->X, e)) == NULL) {
    char msg[DM_ERRMSG_MAX];
    snprintf(msg, sizeof msg, "%s", e != NULL ? e->msg : "");
    st = dm_err_set(e, e != NULL ? e->status : DM_EDOM, "%s: %s", path, msg);
    goto done;
  }
  *Kout = K;
  K = NULL;
done:
  dm_dec_complex_free(K);
  dm_dec_meshdata_free(m);
  free(lines);
  return st;
}
