/* native.c -- emit C for a tape, compile it with the system compiler, load
 * it, check it against the tape, cache the object.  See native.h. */
#include <config.h>
#include "native.h"
#include "interrupt.h"

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

#define CC_FLAGS "-O2 -fPIC -shared -ffp-contract=off"
#define CC_TIMEOUT 300.0      /* seconds */
#define ID_SYMBOL "dm_native_id"

struct dm_native {
  void *dl;
  dm_native_fn fn;
  int cached;
  char key[65];
};

void dm_native_free(dm_native *nat)
{
  if (nat == NULL)
    return;
  if (nat->dl != NULL)
    dlclose(nat->dl);
  free(nat);
}

dm_native_fn dm_native_function(const dm_native *nat) { return nat->fn; }
int dm_native_cached(const dm_native *nat) { return nat->cached; }
const char *dm_native_key(const dm_native *nat) { return nat->key; }

const char *dm_native_mode_name(int mode)
{
  switch (mode) {
  case DM_NATIVE_NEVER: return "never";
  case DM_NATIVE_AUTO: return "auto";
  case DM_NATIVE_ALWAYS: return "always";
  default: return "?";
  }
}

int dm_native_mode_parse(const char *name)
{
  for (int m = DM_NATIVE_NEVER; m <= DM_NATIVE_ALWAYS; m++)
    if (name != NULL && strcmp(name, dm_native_mode_name(m)) == 0)
      return m;
  return -1;
}

/* {==================================================================
 * SHA-256 (FIPS 180-4), for cache keys
 * =================================================================== */

typedef struct sha256 {
  uint32_t h[8];
  uint64_t len;
  unsigned char buf[64];
  size_t nbuf;
} sha256;

static const uint32_t K256[64] = {
  0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1,
  0x923f82a4, 0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3,
  0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
  0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
  0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147,
  0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
  0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
  0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
  0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
  0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208,
  0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2
};

#define ROR(x, n) (((x) >> (n)) | ((x) << (32 - (n))))

static void sha_block(sha256 *s, const unsigned char *p)
{
  uint32_t w[64], v[8];
  for (int i = 0; i < 16; i++)
    w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 |
           (uint32_t)p[4 * i + 2] << 8 | p[4 * i + 3];
  for (int i = 16; i < 64; i++) {
    uint32_t s0 = ROR(w[i - 15], 7) ^ ROR(w[i - 15], 18) ^ (w[i - 15] >> 3);
    uint32_t s1 = ROR(w[i - 2], 17) ^ ROR(w[i - 2], 19) ^ (w[i - 2] >> 10);
    w[i] = w[i - 16] + s0 + w[i - 7] + s1;
  }
  memcpy(v, s->h, sizeof v);
  for (int i = 0; i < 64; i++) {
    uint32_t S1 = ROR(v[4], 6) ^ ROR(v[4], 11) ^ ROR(v[4], 25);
    uint32_t ch = (v[4] & v[5]) ^ (~v[4] & v[6]);
    uint32_t t1 = v[7] + S1 + ch + K256[i] + w[i];
    uint32_t S0 = ROR(v[0], 2) ^ ROR(v[0], 13) ^ ROR(v[0], 22);
    uint32_t mj = (v[0] & v[1]) ^ (v[0] & v[2]) ^ (v[1] & v[2]);
    memmove(v + 1, v, 7 * sizeof *v);
    v[4] += t1;
    v[0] = t1 + S0 + mj;
  }
  for (int i = 0; i < 8; i++)
    s->h[i] += v[i];
}

static void sha_init(sha256 *s)
{
  static const uint32_t h0[8] = { 0x6a09e667, 0xbb67ae85, 0x3c6ef372,
    0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19 };
  memcpy(s->h, h0, sizeof h0);
  s->len = 0;
  s->nbuf = 0;
}

static void sha_update(sha256 *s, const void *data, size_t n)
{
  const unsigned char *p = data;
  s->len += n;
  while (n > 0) {
    size_t k = 64 - s->nbuf < n ? 64 - s->nbuf : n;
    memcpy(s->buf + s->nbuf, p, k);
    s->nbuf += k;
    p += k;
    n -= k;
    if (s->nbuf == 64) {
      sha_block(s, s->buf);
      s->nbuf = 0;
    }
  }
}

static void sha_hex(sha256 *s, char hex[65])
{
  uint64_t bits = s->len * 8;
  unsigned char pad = 0x80, zero = 0, lenb[8];
  sha_update(s, &pad, 1);
  while (s->nbuf != 56)
    sha_update(s, &zero, 1);
  for (int i = 0; i < 8; i++)
    lenb[i] = (unsigned char)(bits >> (56 - 8 * i));
  sha_update(s, lenb, 8);
  for (int i = 0; i < 8; i++)
    snprintf(hex + 8 * i, 9, "%08x", (unsigned)s->h[i]);
}

/* {==================================================================
 * emitting C
 * =================================================================== */

typedef struct sbuf {
  char *s;
  size_t len, cap;
  int nomem;
} sbuf;

static void sb_printf(sbuf *b, const char *fmt, ...)
{
  va_list ap;
  if (b->nomem)
    return;
  for (;;) {
    va_start(ap, fmt);
    int k = vsnprintf(b->s ? b->s + b->len : NULL, b->s ? b->cap - b->len : 0, fmt, ap);
    va_end(ap);
    if (k < 0) {
      b->nomem = 1;
      return;
    }
    if (b->s && b->len + (size_t)k < b->cap) {
      b->len += (size_t)k;
      return;
    }
    size_t cap = b->cap ? b->cap : 4096;
    while (cap <= b->len + (size_t)k)
      cap *= 2;
    char *p = realloc(b->s, cap);
    if (p == NULL) {
      b->nomem = 1;
      return;
    }
    b->s = p;
    b->cap = cap;
  }
}

/* The C expression for register r; writer[r] = instruction that last
 * wrote the temporary r. */
static void operand(char *buf, size_t size, const dm_tape *t, uint32_t r,
                    const size_t *writer)
{
  size_t nin = dm_tape_nin(t), npar = dm_tape_npar(t);
  size_t base = nin + npar + dm_tape_nconst(t);
  if (r < nin)
    snprintf(buf, size, "in[%u]", r);
  else if (r < nin + npar)
    snprintf(buf, size, "par[%zu]", r - nin);
  else if (r < base) {
    double c = dm_tape_consts(t)[r - nin - npar];
    if (isnan(c))
      snprintf(buf, size, "NAN");
    else if (isinf(c))
      snprintf(buf, size, c > 0 ? "HUGE_VAL" : "(-HUGE_VAL)");
    else
      snprintf(buf, size, "(%a)", c);
  } else {
    snprintf(buf, size, "t%zu", writer[r]);
  }
}

static const char *const c_func[DM_T_NOPS] = {
  [DM_T_POW] = "pow", [DM_T_ATAN2] = "atan2", [DM_T_SQRT] = "sqrt",
  [DM_T_EXP] = "exp", [DM_T_LOG] = "log", [DM_T_SIN] = "sin",
  [DM_T_COS] = "cos", [DM_T_TAN] = "tan", [DM_T_ASIN] = "asin",
  [DM_T_ACOS] = "acos", [DM_T_ATAN] = "atan", [DM_T_SINH] = "sinh",
  [DM_T_COSH] = "cosh", [DM_T_TANH] = "tanh", [DM_T_ABS] = "fabs",
  [DM_T_SIGN] = "dm_sign"
};

static const char *const c_infix[DM_T_NOPS] = {
  [DM_T_ADD] = "+", [DM_T_SUB] = "-", [DM_T_MUL] = "*", [DM_T_DIV] = "/",
  [DM_T_LT] = "<", [DM_T_LE] = "<=", [DM_T_GT] = ">", [DM_T_GE] = ">=",
  [DM_T_EQ] = "==", [DM_T_NE] = "!="
};

static const char prelude[] =
  "/* generated by dmech from a tape: do not edit */\n"
  "#include <math.h>\n#include <stddef.h>\n"
  "static inline double dm_powi(double x, int n)\n{\n"
  "  unsigned long u = n < 0 ? (unsigned long)(-(long)n) : (unsigned long)n;\n"
  "  double r = 1.0, p = x;\n"
  "  while (u) {\n    if (u & 1)\n      r *= p;\n    u >>= 1;\n"
  "    if (u)\n      p *= p;\n  }\n  return n < 0 ? 1.0 / r : r;\n}\n"
  "static inline double dm_sign(double x)\n"
  "{\n  return x > 0 ? 1.0 : x < 0 ? -1.0 : x == 0 ? 0.0 : x;\n}\n";

char *dm_native_source(const dm_tape *t)
{
  sbuf b = { NULL, 0, 0, 0 };
  size_t n = dm_tape_ninstr(t), nregs = dm_tape_nregs(t);
  size_t *writer = calloc(nregs ? nregs : 1, sizeof *writer);
  if (writer == NULL)
    return NULL;
  sb_printf(&b, "%s\nvoid dm_native_eval(const double *restrict in, "
            "const double *restrict par, double *restrict out)\n{\n"
            "  (void)in; (void)par;\n", prelude);
  const dm_tape_ins *code = dm_tape_code(t);
  char x[64], y[64], c[64];
  for (size_t i = 0; i < n && !b.nomem; i++) {
    const dm_tape_ins *ip = &code[i];
    int op = (int)(ip->code & 0xff);
    operand(x, sizeof x, t, ip->a, writer);
    int fused = op >= DM_T_MULADD && op <= DM_T_MUL3;
    if (op != DM_T_POWI && op != DM_T_SELECT && c_infix[op] == NULL &&
        op != DM_T_POW && op != DM_T_ATAN2 && !fused)
      y[0] = '\0';
    else if (op != DM_T_POWI)
      operand(y, sizeof y, t, ip->b, writer);
    if (fused)
      operand(c, sizeof c, t, ip->code >> 8, writer);
    sb_printf(&b, "  const double t%zu = ", i);
    switch (op) {
    case DM_T_NEG: sb_printf(&b, "-%s;\n", x); break;
    case DM_T_SQR: sb_printf(&b, "%s * %s;\n", x, x); break;
    case DM_T_CUBE: sb_printf(&b, "%s * (%s * %s);\n", x, x, x); break;
    case DM_T_RECIP: sb_printf(&b, "1.0 / %s;\n", x); break;
    case DM_T_POWI: sb_printf(&b, "dm_powi(%s, %d);\n", x, (int32_t)ip->b); break;
    case DM_T_POW: case DM_T_ATAN2:
      sb_printf(&b, "%s(%s, %s);\n", c_func[op], x, y);
      break;
    case DM_T_SELECT:
      operand(c, sizeof c, t, ip->code >> 8, writer);
      sb_printf(&b, "%s != 0 ? %s : %s;\n", c, x, y);
      break;
    case DM_T_MULADD: sb_printf(&b, "%s * %s + %s;\n", x, y, c); break;
    case DM_T_MULSUB: sb_printf(&b, "%s * %s - %s;\n", x, y, c); break;
    case DM_T_SUBMUL: sb_printf(&b, "%s - %s * %s;\n", c, x, y); break;
    case DM_T_MUL3: sb_printf(&b, "%s * %s * %s;\n", x, y, c); break;
    default:
      if (c_infix[op] != NULL && op >= DM_T_LT)
        sb_printf(&b, "(%s %s %s) ? 1.0 : 0.0;\n", x, c_infix[op], y);
      else if (c_infix[op] != NULL)
        sb_printf(&b, "%s %s %s;\n", x, c_infix[op], y);
      else
        sb_printf(&b, "%s(%s);\n", c_func[op], x);
      break;
    }
    writer[ip->d] = i;
  }
  const uint32_t *outreg = dm_tape_outregs(t);
  for (size_t k = 0; k < dm_tape_nout(t); k++) {
    operand(x, sizeof x, t, outreg[k], writer);
    sb_printf(&b, "  out[%zu] = %s;\n", k, x);
  }
  sb_printf(&b, "}\n");
  free(writer);
  if (b.nomem) {
    free(b.s);
    return NULL;
  }
  return b.s;
}

/* {==================================================================
 * running the compiler
 * =================================================================== */

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Split $CC (else "cc") at blanks into argv[0..k), return k (0: none). */
static int cc_words(char *copy, char **argv, int max)
{
  int k = 0;
  char *save = NULL;
  for (char *p = strtok_r(copy, " \t", &save); p != NULL && k < max;
       p = strtok_r(NULL, " \t", &save))
    argv[k++] = p;
  return k;
}

/* Run argv with stdin from /dev/null and stdout + stderr captured into out
 * (at most size-1 bytes kept, NUL-terminated).  *status is the exit code
 * (128 + signal when killed).  Returns a dm status. */
static int run(char *const argv[], char *out, size_t size, int *status,
               dm_err *err)
{
  int fd[2];
  if (pipe(fd) != 0)
    return dm_err_set(err, DM_EIO, "native: pipe: %s", strerror(errno));
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 1);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 2);
  posix_spawn_file_actions_addclose(&fa, fd[0]);
  posix_spawn_file_actions_addclose(&fa, fd[1]);
  pid_t pid;
  int rc = posix_spawnp(&pid, argv[0], &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fd[1]);
  if (rc != 0) {
    close(fd[0]);
    return dm_err_set(err, rc == ENOENT ? DM_ENOTFOUND : DM_EIO,
                      "native: cannot run C compiler '%s': %s", argv[0],
                      strerror(rc));
  }
  size_t len = 0;
  int result = DM_OK;
  double t0 = now();
  for (;;) {
    struct pollfd p = { fd[0], POLLIN, 0 };
    int k = poll(&p, 1, 50);
    if (k > 0) {
      char tmp[4096];
      ssize_t r = read(fd[0], tmp, sizeof tmp);
      if (r == 0)
        break;
      if (r > 0 && len + 1 < size) {
        size_t m = (size_t)r < size - 1 - len ? (size_t)r : size - 1 - len;
        memcpy(out + len, tmp, m);
        len += m;
      }
      if (r < 0 && errno != EINTR)
        break;
    }
    if (dm_interrupted() || now() - t0 > CC_TIMEOUT) {
      result = dm_interrupted() ? DM_EINTR : DM_ETIMEOUT;
      kill(pid, SIGKILL);
      break;
    }
  }
  out[len] = '\0';
  close(fd[0]);
  int ws;
  while (waitpid(pid, &ws, 0) < 0 && errno == EINTR)
    ;
  *status = WIFEXITED(ws) ? WEXITSTATUS(ws) : 128 + WTERMSIG(ws);
  if (result == DM_EINTR)
    return dm_err_set(err, DM_EINTR, "native: compilation interrupted");
  if (result == DM_ETIMEOUT)
    return dm_err_set(err, DM_ETIMEOUT, "native: %s ran longer than %.0f s",
                      argv[0], CC_TIMEOUT);
  /* glibc reports a failed exec as exit status 127 */
  if (*status == 127 && len == 0)
    return dm_err_set(err, DM_ENOTFOUND, "native: cannot run C compiler '%s'",
                      argv[0]);
  return DM_OK;
}

/* {==================================================================
 * files and the cache
 * =================================================================== */

static int write_file(const char *path, const void *data, size_t n)
{
  int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    return -1;
  const char *p = data;
  while (n > 0) {
    ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR)
      continue;
    if (w <= 0) {
      close(fd);
      return -1;
    }
    p += w;
    n -= (size_t)w;
  }
  return close(fd);
}

/* Whole file into a malloc'ed buffer, or NULL. */
static char *read_file(const char *path, size_t *n)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return NULL;
  char *buf = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len == cap) {
      cap = cap ? 2 * cap : 65536;
      char *p = realloc(buf, cap);
      if (p == NULL)
        break;
      buf = p;
    }
    size_t r = fread(buf + len, 1, cap - len, f);
    len += r;
    if (r == 0)
      break;
  }
  int bad = ferror(f);
  fclose(f);
  if (bad || buf == NULL) {
    free(buf);
    return NULL;
  }
  *n = len;
  return buf;
}

/* A directory we own, not accessible to others (created 0700 if missing). */
static int private_dir(const char *path)
{
  struct stat st;
  if (mkdir(path, 0700) != 0 && errno != EEXIST)
    return -1;
  if (lstat(path, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid()
      || (st.st_mode & 077) != 0)
    return -1;
  return 0;
}

/* $XDG_CACHE_HOME/dmech or $HOME/.cache/dmech into dir; -1 when there is
 * no usable cache directory. */
static int cache_dir(char *dir, size_t size)
{
  const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
  char base[4096];
  if (x != NULL && x[0] == '/')
    snprintf(base, sizeof base, "%s", x);
  else if (home != NULL && home[0] == '/')
    snprintf(base, sizeof base, "%s/.cache", home);
  else
    return -1;
  /* the base may be missing: create it (and only it) privately */
  if (mkdir(base, 0700) != 0 && errno != EEXIST)
    return -1;
  if ((size_t)snprintf(dir, size, "%s/dmech", base) >= size)
    return -1;
  return private_dir(dir);
}

/* A cached object is used only if it is a regular file of ours that
 * nobody else can write. */
static int trusted_file(const char *path)
{
  int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0)
    return 0;
  struct stat st;
  int ok = fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
           st.st_uid == getuid() && (st.st_mode & 022) == 0;
  close(fd);
  return ok;
}

/* Copy the object into the cache: temporary name, 0600, rename. */
static int cache_store(const char *dir, const char *final, const char *obj)
{
  size_t n;
  char *data = read_file(obj, &n), tmp[4200];
  if (data == NULL)
    return -1;
  snprintf(tmp, sizeof tmp, "%s/.tmp-XXXXXX", dir);
  int fd = mkstemp(tmp);
  int bad = fd < 0;
  for (size_t off = 0; !bad && off < n;) {
    ssize_t w = write(fd, data + off, n - off);
    if (w < 0 && errno == EINTR)
      continue;
    bad = w <= 0;
    off += bad ? 0 : (size_t)w;
  }
  free(data);
  if (fd >= 0) {
    bad |= fchmod(fd, 0600) != 0;
    bad |= close(fd) != 0;
    if (bad || rename(tmp, final) != 0) {
      unlink(tmp);
      return -1;
    }
  }
  return bad ? -1 : 0;
}

/* {==================================================================
 * loading and checking
 * =================================================================== */

static double urand(uint64_t *s)
{
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 9007199254740992.0;
}

static int agree(double a, double b)
{
  if (a == b || (isnan(a) && isnan(b)))
    return 1;
  return fabs(a - b) <= 1e-15 * fmax(fabs(a), fabs(b));
}

/* The native function against the tape at 16 points: near (in0, par0)
 * when given, and uniformly random in [-2, 2]. */
static int verify(const dm_tape *t, dm_native_fn fn, const double *in0,
                  const double *par0, dm_err *err)
{
  size_t nin = dm_tape_nin(t), npar = dm_tape_npar(t), nout = dm_tape_nout(t);
  size_t nw = dm_tape_work_size(t);
  double *buf = malloc((nin + npar + 2 * nout + nw + 1) * sizeof *buf);
  if (buf == NULL)
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  double *in = buf, *par = in + nin, *o1 = par + npar, *o2 = o1 + nout;
  double *w = o2 + nout;
  uint64_t seed = 0x9e3779b97f4a7c15ULL;
  int status = DM_OK;
  for (int rep = 0; rep < 16 && status == DM_OK; rep++) {
    int near = rep % 2 == 0;
    for (size_t i = 0; i < nin; i++)
      in[i] = near && in0 ? in0[i] * (1 + 0.05 * (urand(&seed) - 0.5)) +
                            1e-3 * (urand(&seed) - 0.5)
                          : 4 * urand(&seed) - 2;
    for (size_t i = 0; i < npar; i++)
      par[i] = par0 ? par0[i] * (rep < 2 ? 1 : 1 + 0.05 * (urand(&seed) - 0.5))
                    : 4 * urand(&seed) - 2;
    dm_tape_eval(t, in, par, o1, w);
    fn(in, par, o2);
    for (size_t k = 0; k < nout; k++)
      if (!agree(o1[k], o2[k])) {
        status = dm_err_set(err, DM_EFAILED, "native: compiled code gives "
                            "%.17g for output %zu where the tape gives %.17g",
                            o2[k], k + 1, o1[k]);
        break;
      }
  }
  free(buf);
  return status;
}

/* dlopen path and check that it is the object with this key. */
static int load(const char *path, const char *key, dm_native *nat, dm_err *err)
{
  void *dl = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (dl == NULL)
    return dm_err_set(err, DM_EIO, "native: dlopen: %s", dlerror());
  const char *id = dlsym(dl, ID_SYMBOL);
  void *fn = dlsym(dl, "dm_native_eval");
  if (id == NULL || fn == NULL || strcmp(id, key) != 0) {
    dlclose(dl);
    return dm_err_set(err, DM_EIO, "native: %s is not the expected object", path);
  }
  nat->dl = dl;
  memcpy(&nat->fn, &fn, sizeof fn);     /* object to function pointer */
  return DM_OK;
}

/* Compile src into dir/f.so (files in dir, which the caller removes). */
static int build(char **ccargv, int ncc, const char *dir, const char *src,
                 char *obj, size_t objsize, dm_err *err)
{
  char cpath[4200], flags[] = CC_FLAGS, *argv[64], msg[2048];
  int k = 0, status;
  snprintf(cpath, sizeof cpath, "%s/f.c", dir);
  snprintf(obj, objsize, "%s/f.so", dir);
  if (write_file(cpath, src, strlen(src)) != 0)
    return dm_err_set(err, DM_EIO, "native: cannot write %s: %s", cpath,
                      strerror(errno));
  for (int i = 0; i < ncc; i++)
    argv[k++] = ccargv[i];
  k += cc_words(flags, argv + k, 16);
  argv[k++] = "-o";
  argv[k++] = obj;
  argv[k++] = cpath;
  argv[k++] = "-lm";
  argv[k] = NULL;
  int s = run(argv, msg, sizeof msg, &status, err);
  if (s != DM_OK)
    return s;
  if (status != 0)
    return dm_err_set(err, DM_EFAILED, "native: %s failed (exit %d): %s",
                      ccargv[0], status, msg);
  return DM_OK;
}

static void remove_tree(const char *dir)
{
  char p[4200];
  static const char *const files[] = { "f.c", "f.so" };
  for (size_t i = 0; i < 2; i++) {
    snprintf(p, sizeof p, "%s/%s", dir, files[i]);
    unlink(p);
  }
  rmdir(dir);
}

/* The key: SHA-256 of the source, the compiler command, its --version
 * output and the flags. */
static int make_key(char **ccargv, int ncc, const char *src, char key[65],
                    dm_err *err)
{
  char *argv[40], ver[4096];
  int status;
  for (int i = 0; i < ncc; i++)
    argv[i] = ccargv[i];
  argv[ncc] = "--version";
  argv[ncc + 1] = NULL;
  int s = run(argv, ver, sizeof ver, &status, err);
  if (s != DM_OK)
    return s;
  if (status != 0)
    return dm_err_set(err, DM_ENOTFOUND, "native: '%s --version' failed "
                      "(exit %d)", ccargv[0], status);
  sha256 h;
  sha_init(&h);
  for (int i = 0; i < ncc; i++)
    sha_update(&h, ccargv[i], strlen(ccargv[i]) + 1);
  sha_update(&h, ver, strlen(ver) + 1);
  sha_update(&h, CC_FLAGS, sizeof CC_FLAGS);
  sha_update(&h, src, strlen(src));
  sha_hex(&h, key);
  return DM_OK;
}

static int compile_native(const dm_tape *t, const double *in0,
                          const double *par0, dm_native *nat, char *src,
                          dm_err *err)
{
  const char *cc = getenv("CC");
  char cccopy[1024], *ccargv[32];
  snprintf(cccopy, sizeof cccopy, "%s", cc && *cc ? cc : "cc");
  int ncc = cc_words(cccopy, ccargv, 30);
  if (ncc == 0)
    return dm_err_set(err, DM_ENOTFOUND, "native: $CC is blank");
  int s = make_key(ccargv, ncc, src, nat->key, err);
  if (s != DM_OK)
    return s;

  char cdir[4096], cached[4200];
  int have_cache = cache_dir(cdir, sizeof cdir) == 0;
  if (have_cache) {
    snprintf(cached, sizeof cached, "%s/%s.so", cdir, nat->key);
    if (trusted_file(cached) && load(cached, nat->key, nat, NULL) == DM_OK) {
      if (verify(t, nat->fn, in0, par0, NULL) == DM_OK) {
        nat->cached = 1;
        return DM_OK;
      }
      dlclose(nat->dl);                /* stale or damaged: rebuild */
      nat->dl = NULL;
      unlink(cached);
    }
  }

  /* the object embeds its key so that a loaded file can be recognised */
  size_t len = strlen(src);
  char idline[128];
  snprintf(idline, sizeof idline, "const char %s[] = \"%s\";\n", ID_SYMBOL, nat->key);
  char *full = malloc(len + strlen(idline) + 1);
  if (full == NULL)
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  memcpy(full, src, len);
  strcpy(full + len, idline);

  const char *tmpd = getenv("TMPDIR");
  char dir[4096], obj[4200];
  snprintf(dir, sizeof dir, "%s/dmech-XXXXXX", tmpd && *tmpd ? tmpd : "/tmp");
  if (mkdtemp(dir) == NULL) {
    free(full);
    return dm_err_set(err, DM_EIO, "native: mkdtemp in %s: %s",
                      tmpd && *tmpd ? tmpd : "/tmp", strerror(errno));
  }
  s = build(ccargv, ncc, dir, full, obj, sizeof obj, err);
  free(full);
  if (s == DM_OK) {
    if (have_cache && cache_store(cdir, cached, obj) == 0 &&
        load(cached, nat->key, nat, NULL) == DM_OK)
      ;
    else
      s = load(obj, nat->key, nat, err);
  }
  remove_tree(dir);
  if (s != DM_OK)
    return s;
  return verify(t, nat->fn, in0, par0, err);
}

int dm_native_compile(const dm_tape *t, const double *in0, const double *par0,
                      dm_native **natp, dm_err *err)
{
  *natp = NULL;
  dm_native *nat = calloc(1, sizeof *nat);
  char *src = dm_native_source(t);
  if (nat == NULL || src == NULL) {
    free(nat);
    free(src);
    return dm_err_set(err, DM_ENOMEM, "native: out of memory");
  }
  int s = compile_native(t, in0, par0, nat, src, err);
  free(src);
  if (s != DM_OK) {
    dm_native_free(nat);
    return s;
  }
  *natp = nat;
  return DM_OK;
}
