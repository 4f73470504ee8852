/* registry.c -- the integrator families, looked up by system kind and
 * method name.  The families of this directory are listed here (a new one
 * is one file plus one line); other modules register theirs at run time
 * with dm_integrator_register.
 *
 * The table only grows: an entry is written, then published by a release
 * store of the count, so lookups read it without a lock (acquire load);
 * registrations are serialised by a mutex. */
#include <config.h>
#include "integrators/integrator.h"

#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

extern const dm_integrator_type dm_integ_midpoint, dm_integ_gauss, dm_integ_trapezoid,
  dm_integ_lobatto, dm_integ_prk, dm_integ_composition, dm_integ_rk4, dm_integ_gsl,
  dm_integ_adapt, dm_integ_sem, dm_integ_multiscale;

static const dm_integrator_type *const builtin[] = {
  &dm_integ_midpoint,
  &dm_integ_gauss,
  &dm_integ_trapezoid,
  &dm_integ_lobatto,
  &dm_integ_prk,
  &dm_integ_composition,
  &dm_integ_rk4,
  &dm_integ_gsl,
  &dm_integ_adapt,
  &dm_integ_sem,
  &dm_integ_multiscale
};
#define NBUILTIN (sizeof builtin / sizeof builtin[0])

static const dm_integrator_type *_Atomic added[DM_INTEG_REGISTRY_MAX];
static atomic_size_t nadded;
static pthread_mutex_t reg_lock = PTHREAD_MUTEX_INITIALIZER;

size_t dm_integrator_count(void)
{
  return NBUILTIN + atomic_load_explicit(&nadded, memory_order_acquire);
}

const dm_integrator_type *dm_integrator_type_at(size_t i)
{
  if (i < NBUILTIN)
    return builtin[i];
  i -= NBUILTIN;
  if (i >= atomic_load_explicit(&nadded, memory_order_acquire))
    return NULL;
  return atomic_load_explicit(&added[i], memory_order_relaxed);
}

static int same_kind(const char *a, const char *b)
{
  if (a == NULL)
    a = DM_SYSTEM_LAGRANGIAN;
  if (b == NULL)
    b = DM_SYSTEM_LAGRANGIAN;
  return strcmp(a, b) == 0;
}

int dm_integrator_has_option(const dm_integrator_type *type, const char *name)
{
  const char *const *o;
  for (o = type->options; o != NULL && *o != NULL; o++)
    if (strcmp(*o, name) == 0)
      return 1;
  return 0;
}

int dm_integrator_stages_chosen(const dm_integrator *I)
{
  return I->stages > 0 && (dm_integrator_has_option(I->type, "stages")
                           || dm_integrator_has_option(I->type, "tableau"));
}

int dm_integrator_accepts(const dm_integrator_type *type, const char *kind)
{
  const char *const *k;
  if (type->kinds == NULL)
    return same_kind(kind, NULL);
  for (k = type->kinds; *k != NULL; k++)
    if (same_kind(*k, kind))
      return 1;
  return 0;
}

/* Does `type` answer to the whole method name s? */
static int answers(const dm_integrator_type *type, const char *s)
{
  const char *const *a;
  if (strcmp(type->name, s) == 0)
    return 1;
  for (a = type->names; a != NULL && *a != NULL; a++)
    if (strcmp(*a, s) == 0)
      return 1;
  return 0;
}

/* "family" or "family:variant" (the variant is the family's business) */
const dm_integrator_type *dm_integrator_find(const char *kind, const char *name,
                                             const char **variant_out)
{
  const char *colon;
  size_t len, i, count = dm_integrator_count();
  if (variant_out)
    *variant_out = NULL;
  if (name == NULL)
    return NULL;
  colon = strchr(name, ':');
  len = colon ? (size_t)(colon - name) : strlen(name);
  for (i = 0; i < count; i++) {
    const dm_integrator_type *t = dm_integrator_type_at(i);
    if (!dm_integrator_accepts(t, kind))
      continue;
    if (answers(t, name))
      return t;
    if (colon && strlen(t->name) == len && strncmp(t->name, name, len) == 0) {
      if (variant_out)
        *variant_out = colon + 1;
      return t;
    }
  }
  return NULL;
}

const dm_integrator_type *dm_integrator_lookup(const char *name, const char **variant_out)
{
  return dm_integrator_find(NULL, name, variant_out);
}

/* Would t and u both answer to some name for some kind? */
static int clash(const dm_integrator_type *t, const dm_integrator_type *u, const char **which)
{
  const char *const lag[] = {DM_SYSTEM_LAGRANGIAN, NULL};
  const char *const *k;
  for (k = t->kinds ? t->kinds : lag; *k != NULL; k++) {
    const char *const *a;
    if (!dm_integrator_accepts(u, *k))
      continue;
    if (answers(u, t->name)) {
      *which = t->name;
      return 1;
    }
    for (a = t->names; a != NULL && *a != NULL; a++)
      if (answers(u, *a)) {
        *which = *a;
        return 1;
      }
  }
  return 0;
}

int dm_integrator_register(const dm_integrator_type *type, dm_err *e)
{
  size_t i, n;
  const char *which = NULL;
  int st = DM_OK;
  if (type == NULL || type->name == NULL || type->name[0] == '\0' || type->alloc == NULL
      || type->step == NULL)
    return dm_err_set(e, DM_EINVAL, "integrator registration: a family needs a name, "
                      "alloc and step");
  pthread_mutex_lock(&reg_lock);
  n = dm_integrator_count();
  for (i = 0; i < n; i++) {
    const dm_integrator_type *u = dm_integrator_type_at(i);
    if (u == type)
      goto out;                                   /* already registered */
    if (clash(type, u, &which)) {
      st = dm_err_set(e, DM_EINVAL, "integrator registration: family '%s' answers to '%s', "
                      "which family '%s' already has for the same kind of system",
                      type->name, which, u->name);
      goto out;
    }
  }
  i = atomic_load_explicit(&nadded, memory_order_relaxed);
  if (i >= DM_INTEG_REGISTRY_MAX) {
    st = dm_err_set(e, DM_ENOMEM, "integrator registration: the registry is full (%d families)",
                    DM_INTEG_REGISTRY_MAX);
    goto out;
  }
  atomic_store_explicit(&added[i], type, memory_order_relaxed);
  atomic_store_explicit(&nadded, i + 1, memory_order_release);
out:
  pthread_mutex_unlock(&reg_lock);
  return st;
}
