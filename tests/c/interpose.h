/* interpose.h -- an allocator interposed on the whole process, for tests
 * (include it in exactly one source file of a test program).
 *
 * The program defines malloc, calloc, realloc and free itself and forwards
 * to the C library's through dlsym(RTLD_NEXT), so every allocation --
 * dmech's, Lua's, GSL's, libc's -- passes here.  It can
 *   - count allocations (ip_count),
 *   - keep the number of bytes in use (ip_live, from malloc_usable_size),
 *     so a test sees memory that a closed Lua state did not give back
 *     even when it is freed later at exit (valgrind would not report it),
 *   - fail the k-th allocation from now on (ip_fail_at(k)): that call
 *     returns NULL, the calls before and after it succeed.
 *
 * Needs glibc >= 2.34 (dlsym in libc) and no other allocator in the
 * process (AddressSanitizer and valgrind bring theirs): IP_ACTIVE is 0
 * there and the test should skip what depends on it. */
#ifndef DM_INTERPOSE_H
#define DM_INTERPOSE_H

#include <stddef.h>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define IP_NO_INTERPOSE 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define IP_NO_INTERPOSE 1
#endif

#if !defined(IP_NO_INTERPOSE) && defined(__linux__) && defined(__GLIBC__) \
    && defined(__GLIBC_PREREQ)
#if __GLIBC_PREREQ(2, 34)
#define IP_ACTIVE 1
#endif
#endif
#ifndef IP_ACTIVE
#define IP_ACTIVE 0
#endif

static long ip_count;          /* allocations so far (malloc, calloc, realloc) */
static long long ip_live;      /* bytes in use */
static long ip_fail_k;         /* fail when ip_count reaches this (0: never) */
static long ip_failures;       /* allocations refused so far */

/* Fail the k-th allocation from now (k >= 1); 0 disarms. */
static inline void ip_fail_at(long k)
{
  ip_fail_k = k > 0 ? ip_count + k : 0;
}

#if IP_ACTIVE
#include <dlfcn.h>
#include <errno.h>
#include <malloc.h>
#include <string.h>

static void *(*ip_next_malloc)(size_t);
static void *(*ip_next_calloc)(size_t, size_t);
static void *(*ip_next_realloc)(void *, size_t);
static void (*ip_next_free)(void *);
static int (*ip_next_memalign)(void **, size_t, size_t);
static int ip_resolving;
/* dlsym may calloc before the real calloc is known: serve it from here */
static _Alignas(16) char ip_boot[4096];
static size_t ip_boot_used;

static void *ip_boot_alloc(size_t n)
{
  void *p;
  n = (n + 15) & ~(size_t)15;
  if (ip_boot_used + n > sizeof ip_boot)
    return NULL;
  p = ip_boot + ip_boot_used;
  ip_boot_used += n;
  return p;                       /* static storage: already zero */
}

static int ip_in_boot(const void *p)
{
  return (const char *)p >= ip_boot && (const char *)p < ip_boot + sizeof ip_boot;
}

static void ip_resolve(void)
{
  ip_resolving = 1;
  *(void **)&ip_next_malloc = dlsym(RTLD_NEXT, "malloc");
  *(void **)&ip_next_calloc = dlsym(RTLD_NEXT, "calloc");
  *(void **)&ip_next_realloc = dlsym(RTLD_NEXT, "realloc");
  *(void **)&ip_next_free = dlsym(RTLD_NEXT, "free");
  *(void **)&ip_next_memalign = dlsym(RTLD_NEXT, "posix_memalign");
  ip_resolving = 0;
}

/* Count one allocation; 1 when it must fail (errno ENOMEM, as malloc). */
static int ip_refuse(void)
{
  ip_count++;
  if (ip_fail_k != 0 && ip_count == ip_fail_k) {
    ip_failures++;
    errno = ENOMEM;
    return 1;
  }
  return 0;
}

void *malloc(size_t n)
{
  void *p;
  if (ip_next_malloc == NULL) {
    if (ip_resolving)
      return ip_boot_alloc(n);
    ip_resolve();
  }
  if (ip_refuse())
    return NULL;
  p = ip_next_malloc(n);
  if (p != NULL)
    ip_live += (long long)malloc_usable_size(p);
  return p;
}

void *calloc(size_t a, size_t b)
{
  void *p;
  if (ip_next_calloc == NULL) {
    if (ip_resolving)
      return b && a > (size_t)-1 / b ? NULL : ip_boot_alloc(a * b);
    ip_resolve();
  }
  if (ip_refuse())
    return NULL;
  p = ip_next_calloc(a, b);
  if (p != NULL)
    ip_live += (long long)malloc_usable_size(p);
  return p;
}

void *realloc(void *p, size_t n)
{
  size_t old;
  void *q;
  if (ip_next_realloc == NULL)
    ip_resolve();
  if (ip_in_boot(p)) {             /* never happens in practice */
    q = malloc(n);
    if (q != NULL)
      memcpy(q, p, n);
    return q;
  }
  if (ip_refuse())
    return NULL;
  old = p != NULL ? malloc_usable_size(p) : 0;
  q = ip_next_realloc(p, n);
  if (q != NULL || n == 0)
    ip_live += (long long)(q != NULL ? malloc_usable_size(q) : 0) - (long long)old;
  return q;
}

int posix_memalign(void **pp, size_t align, size_t n)
{
  int rc;
  if (ip_next_memalign == NULL)
    ip_resolve();
  if (ip_refuse())
    return 12;                      /* ENOMEM */
  rc = ip_next_memalign(pp, align, n);
  if (rc == 0)
    ip_live += (long long)malloc_usable_size(*pp);
  return rc;
}

void *aligned_alloc(size_t align, size_t n)
{
  void *p = NULL;
  return posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, n) == 0
         ? p : NULL;
}

void free(void *p)
{
  if (p == NULL || ip_in_boot(p))
    return;
  if (ip_next_free == NULL)
    ip_resolve();
  ip_live -= (long long)malloc_usable_size(p);
  ip_next_free(p);
}
#endif

#endif
