/* test_native_faults.c -- native compilation when things go wrong: a
 * damaged object in the cache, a compiler that is interrupted, times out,
 * is stopped by SIGTERM to dmech, or fails.  Each must end in a clear
 * status with no compiler process left running, no build directory left in
 * $TMPDIR, and a cache that works afterwards.
 *
 * The fake compiler is a shell script that, like `cc` starting `cc1`,
 * starts a child (`sleep`) and waits for it; it writes the child's pid to
 * a file so the test can check that it is gone. */
#include <config.h>
#include <dirent.h>
#include <elf.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/cleanup.h"
#include "core/interrupt.h"
#include "expr/expr.h"
#include "expr/native.h"
#include "expr/tape.h"
#include "tap.h"

static char tmpdir[4096], cachedir[4400], fakecc[4400], pidfile[4400];
static dm_expr_ctx *C;

/* dmech-* build directories in $TMPDIR */
static int count_build_dirs(void)
{
  DIR *d = opendir(tmpdir);
  struct dirent *de;
  int n = 0;
  if (d == NULL)
    return -1;
  while ((de = readdir(d)) != NULL)
    n += strncmp(de->d_name, "dmech-", 6) == 0;
  closedir(d);
  return n;
}

/* A process that exists and is not a zombie (in a container nobody may
 * reap orphans, so a killed one can stay a zombie). */
static int alive(pid_t pid)
{
  char path[64], buf[512], *p;
  FILE *f;
  snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
  if ((f = fopen(path, "r")) == NULL)
    return 0;
  p = fgets(buf, sizeof buf, f);
  fclose(f);
  if (p == NULL || (p = strrchr(buf, ')')) == NULL)
    return 0;
  return p[2] != 'Z' && p[2] != 'X';
}

static void sleep_ms(long ms)
{
  struct timespec ts = { ms / 1000, (ms % 1000) * 1000000L };
  nanosleep(&ts, NULL);
}

/* The pid the fake compiler's child wrote, waiting up to 10 s for it. */
static pid_t wait_pidfile(void)
{
  for (int i = 0; i < 1000; i++) {
    FILE *f = fopen(pidfile, "r");
    int pid = 0;
    if (f != NULL) {
      int k = fscanf(f, "%d", &pid);
      fclose(f);
      if (k == 1 && pid > 0)
        return pid;
    }
    sleep_ms(10);
  }
  return -1;
}

/* Gone within 2 s? */
static int gone(pid_t pid)
{
  for (int i = 0; i < 200 && alive(pid); i++)
    sleep_ms(10);
  return !alive(pid);
}

static dm_tape *small_tape(const char *tag)
{
  dm_expr x = dm_expr_sym(C, "x"), y = dm_expr_sym(C, tag);
  dm_expr e = dm_expr_binary(C, DM_EXPR_MUL, dm_expr_unary(C, DM_EXPR_SIN, x),
                             dm_expr_binary(C, DM_EXPR_ADD, y,
                                            dm_expr_const(C, 2.385)));
  dm_expr in[2] = { x, y };
  dm_tape *t = NULL;
  dm_tape_compile(C, 1, &e, 2, in, 0, NULL, &t, NULL);
  return t;
}

/* {==== a damaged object in the cache ====================================== */

/* File offset of symbol `name` in the ELF shared object image, or -1. */
static long symbol_offset(const unsigned char *img, size_t n, const char *name)
{
  const Elf64_Ehdr *eh = (const void *)img;
  if (n < sizeof *eh || memcmp(eh->e_ident, ELFMAG, SELFMAG) != 0
      || eh->e_ident[EI_CLASS] != ELFCLASS64)
    return -1;
  const Elf64_Shdr *sh = (const void *)(img + eh->e_shoff);
  for (int i = 0; i < eh->e_shnum; i++) {
    if (sh[i].sh_type != SHT_DYNSYM && sh[i].sh_type != SHT_SYMTAB)
      continue;
    const Elf64_Sym *sym = (const void *)(img + sh[i].sh_offset);
    const char *str = (const char *)img + sh[sh[i].sh_link].sh_offset;
    for (size_t k = 0; k < sh[i].sh_size / sizeof *sym; k++) {
      if (strcmp(str + sym[k].st_name, name) != 0 || sym[k].st_value == 0)
        continue;
      const Elf64_Phdr *ph = (const void *)(img + eh->e_phoff);
      for (int j = 0; j < eh->e_phnum; j++)
        if (ph[j].p_type == PT_LOAD && sym[k].st_value >= ph[j].p_vaddr
            && sym[k].st_value < ph[j].p_vaddr + ph[j].p_filesz)
          return (long)(sym[k].st_value - ph[j].p_vaddr + ph[j].p_offset);
    }
  }
  return -1;
}

/* Overwrite the start of dm_native_eval in the cached object with ud2
 * (an illegal instruction): what a damaged block did in the audit. */
static int corrupt_object(const char *path)
{
  FILE *f = fopen(path, "r+b");
  unsigned char *img;
  long size, off;
  int ok = 0;
  if (f == NULL)
    return 0;
  fseek(f, 0, SEEK_END);
  size = ftell(f);
  rewind(f);
  img = malloc((size_t)size);
  if (img != NULL && fread(img, 1, (size_t)size, f) == (size_t)size
      && (off = symbol_offset(img, (size_t)size, "dm_native_eval")) > 0) {
    static const unsigned char ud2[16] = { 0x0f, 0x0b, 0x0f, 0x0b, 0x0f, 0x0b,
      0x0f, 0x0b, 0x0f, 0x0b, 0x0f, 0x0b, 0x0f, 0x0b, 0x0f, 0x0b };
    ok = fseek(f, off, SEEK_SET) == 0 && fwrite(ud2, 1, 16, f) == 16;
  }
  free(img);
  return fclose(f) == 0 && ok;
}

/* Compile in a child process: 0 = compiled afresh, 1 = cache hit, 2 =
 * error, 128 + signal = crashed. */
static int compile_in_child(const dm_tape *t)
{
  pid_t pid = fork();
  int ws;
  if (pid == 0) {
    dm_native *nat;
    int st = dm_native_compile(t, NULL, NULL, &nat, NULL);
    _exit(st != DM_OK ? 2 : dm_native_cached(nat));
  }
  waitpid(pid, &ws, 0);
  return WIFEXITED(ws) ? WEXITSTATUS(ws) : 128 + WTERMSIG(ws);
}

static void test_damaged_cache(void)
{
#if defined(__x86_64__)
  dm_tape *t = small_tape("damaged");
  dm_native *nat;
  char path[4600], sum[4700];
  int st = dm_native_compile(t, NULL, NULL, &nat, NULL);
  if (st != DM_OK) {
    tap_ok(0, "compile for the damaged-cache test");
    dm_tape_free(t);
    return;
  }
  snprintf(path, sizeof path, "%s/%s.so", cachedir, dm_native_key(nat));
  snprintf(sum, sizeof sum, "%s.sha256", path);
  dm_native_free(nat);
  tap_is_int(compile_in_child(t), 1, "second compile is a cache hit");
  tap_ok(access(sum, R_OK) == 0, "the object's digest is stored beside it");
  tap_ok(corrupt_object(path), "cached object damaged: ud2 at dm_native_eval");
  tap_is_int(compile_in_child(t), 0, "the damaged object is not run (no "
             "SIGILL = 132) but rebuilt");
  tap_is_int(compile_in_child(t), 1, "... and replaced: the next compile is a "
             "cache hit again");
  unlink(sum);
  tap_is_int(compile_in_child(t), 0, "an object without a digest is rebuilt");
  tap_is_int(compile_in_child(t), 1, "... with one");
  FILE *f = fopen(sum, "w");
  fputs("0000000000000000000000000000000000000000000000000000000000000000", f);
  fclose(f);
  tap_is_int(compile_in_child(t), 0, "a wrong digest: rebuilt");
  dm_tape_free(t);
#else
  for (int i = 0; i < 8; i++)
    tap_skip("the damaged-object test writes x86-64 code");
#endif
}

/* }==== */

/* {==== a compiler that has to be stopped ================================== */

static int probe_fd = -1;       /* the descriptor the "fds" compiler looks for */

static void write_fakecc(const char *mode)
{
  FILE *f = fopen(fakecc, "w");
  fprintf(f, "#!/bin/sh\n"
             "case \"$*\" in *--version*) echo 'fakecc %s 1.0'; exit 0;; esac\n", mode);
  if (strcmp(mode, "fail") == 0)
    fprintf(f, "echo 'f.c:1:1: error: the fake compiler refuses' >&2; exit 1\n");
  else if (strcmp(mode, "crash") == 0)
    fprintf(f, "kill -SEGV $$\n");
  else if (strcmp(mode, "fds") == 0)
    fprintf(f, "[ -e /proc/$$/fd/1 ] || { echo 'no /proc' >&2; exit 1; }\n"
               "if [ -e /proc/$$/fd/%d ]; then echo 'descriptor %d: inherited' >&2;\n"
               "else echo 'descriptor %d: closed' >&2; fi; exit 1\n",
            probe_fd, probe_fd, probe_fd);
  else
    fprintf(f, "sleep 300 &\necho $! > '%s'\nwait\n", pidfile);
  fclose(f);
  chmod(fakecc, 0700);
  unlink(pidfile);
  setenv("CC", fakecc, 1);
}

static void *interrupt_later(void *arg)
{
  (void)arg;
  if (wait_pidfile() > 0)
    dm_interrupt_raise();
  return NULL;
}

static void test_stopped_compiler(void)
{
  dm_tape *t = small_tape("stopped");
  dm_native *nat = NULL;
  dm_err err;
  pthread_t th;
  int dirs0 = count_build_dirs(), st;
  pid_t child;

  /* Ctrl-C (the interrupt flag) while the compiler runs */
  write_fakecc("hang");
  pthread_create(&th, NULL, interrupt_later, NULL);
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  pthread_join(th, NULL);
  dm_interrupt_clear();
  child = wait_pidfile();
  tap_ok(st == DM_EINTR && nat == NULL && strstr(err.msg, "interrupted"),
         "interrupted compile: DM_EINTR (%s)", err.msg);
  tap_ok(child > 0 && gone(child), "the compiler's child (cc1's place) is "
         "killed too (pid %d)", (int)child);
  tap_is_int(count_build_dirs(), dirs0, "no build directory left");
  tap_is_int(dm_cleanup_count(), 0, "nothing left registered for cleanup");

  /* the timeout */
  write_fakecc("hang2");
  setenv("DMECH_CC_TIMEOUT", "0.5", 1);
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  unsetenv("DMECH_CC_TIMEOUT");
  child = wait_pidfile();
  tap_ok(st == DM_ETIMEOUT && strstr(err.msg, "ran longer than 0.5 s"),
         "compiler past $DMECH_CC_TIMEOUT: DM_ETIMEOUT (%s)", err.msg);
  tap_ok(child > 0 && gone(child), "its child is killed too");
  tap_is_int(count_build_dirs(), dirs0, "no build directory left");

  /* SIGTERM to the process while it compiles */
  write_fakecc("hang3");
  child = fork();
  if (child == 0) {
    dm_cleanup_catch_signals();
    dm_native_compile(t, NULL, NULL, &nat, NULL);
    _exit(0);
  }
  pid_t grandchild = wait_pidfile();
  int ws = 0;
  kill(child, SIGTERM);
  waitpid(child, &ws, 0);
  tap_ok(WIFSIGNALED(ws) && WTERMSIG(ws) == SIGTERM, "SIGTERM during a "
         "compile: the process dies of SIGTERM");
  tap_ok(grandchild > 0 && gone(grandchild), "... and takes the compiler's "
         "child with it");
  tap_is_int(count_build_dirs(), dirs0, "... and removes its build directory");

  /* SIGTERM after the compiler exists but before its group is registered:
   * the window forced wide open, with a plain child in its own group */
  int sync[2];
  if (pipe(sync) != 0)
    sync[0] = sync[1] = -1;
  child = fork();
  if (child == 0) {
    sigset_t held, pend;
    dm_cleanup_catch_signals();
    dm_cleanup_hold(&held);
    pid_t g = fork();
    if (g == 0) {
      setpgid(0, 0);
      sigprocmask(SIG_SETMASK, &held, NULL);
      execlp("sleep", "sleep", "300", (char *)NULL);
      _exit(127);
    }
    setpgid(g, g);
    if (write(sync[1], &g, sizeof g) != (ssize_t)sizeof g)
      _exit(2);
    for (int i = 0; i < 30000; i++) {      /* until SIGTERM is pending */
      sigpending(&pend);
      if (sigismember(&pend, SIGTERM))
        break;
      sleep_ms(1);
    }
    dm_cleanup_add_pgroup(g);
    dm_cleanup_release(&held);               /* SIGTERM is delivered here */
    _exit(0);
  }
  grandchild = -1;
  if (read(sync[0], &grandchild, sizeof grandchild) != (ssize_t)sizeof grandchild)
    grandchild = -1;
  close(sync[0]);
  close(sync[1]);
  kill(child, SIGTERM);
  waitpid(child, &ws, 0);
  tap_ok(WIFSIGNALED(ws) && WTERMSIG(ws) == SIGTERM, "SIGTERM between starting "
         "a child and registering it: held back, then the process dies of it");
  tap_ok(grandchild > 0 && gone(grandchild), "... and the child's group is killed");

  /* compilers that fail or crash */
  write_fakecc("fail");
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  tap_ok(st == DM_EFAILED && strstr(err.msg, "exit 1")
         && strstr(err.msg, "the fake compiler refuses"),
         "failing compiler: DM_EFAILED with its message (%s)", err.msg);
  write_fakecc("crash");
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  tap_ok(st == DM_EFAILED && strstr(err.msg, "failed (killed by signal 11, Segmentation fault)")
         && err.msg[strlen(err.msg) - 1] == ')',
         "crashing compiler: DM_EFAILED, killed by SIGSEGV, no empty output quoted (%s)",
         err.msg);
  tap_is_int(count_build_dirs(), dirs0, "no build directory left");

  /* a descriptor another thread has open without close-on-exec (HDF5
   * opens its files so, with a flock) is not passed to the compiler */
  probe_fd = open("/dev/null", O_RDONLY);
  write_fakecc("fds");
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  close(probe_fd);
  char want[64];
  snprintf(want, sizeof want, "descriptor %d: closed", probe_fd);
  tap_ok(st == DM_EFAILED && strstr(err.msg, want) != NULL,
         "the compiler gets stdio, no other descriptor (%s)", err.msg);

  /* and the real compiler still works afterwards */
  unsetenv("CC");
  st = dm_native_compile(t, NULL, NULL, &nat, &err);
  tap_ok(st == DM_OK, "the system compiler works after all that");
  dm_native_free(nat);
  dm_tape_free(t);
}

/* }==== */

int main(void)
{
  const char *tt = getenv("DMECH_TESTTMP");
  if (tt == NULL || *tt == '\0') {
    static char d[] = "/tmp/dmech-test-nfault-XXXXXX";
    tt = mkdtemp(d);
  }
  snprintf(tmpdir, sizeof tmpdir, "%s/native-tmp-faults", tt);
  mkdir(tmpdir, 0700);
  setenv("TMPDIR", tmpdir, 1);
  const char *xc = getenv("XDG_CACHE_HOME");
  if (xc == NULL || xc[0] != '/') {
    static char cdir[4200];
    snprintf(cdir, sizeof cdir, "%s/cache", tt);
    setenv("XDG_CACHE_HOME", cdir, 1);
    xc = cdir;
  }
  snprintf(cachedir, sizeof cachedir, "%s/dmech", xc);
  snprintf(fakecc, sizeof fakecc, "%s/fakecc.sh", tt);
  snprintf(pidfile, sizeof pidfile, "%s/fakecc.pid", tt);
  unsetenv("CC");

  C = dm_expr_ctx_alloc();
  dm_tape *t = small_tape("probe");
  dm_native *nat;
  int st = dm_native_compile(t, NULL, NULL, &nat, NULL);
  dm_native_free(nat);
  dm_tape_free(t);
  if (st == DM_ENOTFOUND) {
    printf("1..0 # SKIP no C compiler\n");
    dm_expr_ctx_free(C);
    return 0;
  }
  test_damaged_cache();
  test_stopped_compiler();
  dm_expr_ctx_free(C);
  return tap_done();
}
