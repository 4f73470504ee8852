/* registry.c -- the list of integrator families, looked up by name.
 * A new method is one file defining a `const dm_integrator_type` plus one
 * line here. */
#include <config.h>
#include "integrators/integrator.h"

#include <string.h>

extern const dm_integrator_type dm_integ_midpoint, dm_integ_gauss, dm_integ_trapezoid,
  dm_integ_lobatto, dm_integ_prk, dm_integ_composition, dm_integ_rk4, dm_integ_gsl;
extern const dm_integrator_type dm_integ_routh;   /* src/reduce/routh_integ.c */

static const dm_integrator_type *const registry[] = {
  &dm_integ_midpoint,
  &dm_integ_gauss,
  &dm_integ_trapezoid,
  &dm_integ_lobatto,
  &dm_integ_prk,
  &dm_integ_composition,
  &dm_integ_rk4,
  &dm_integ_gsl,
  &dm_integ_routh,
  NULL
};

const dm_integrator_type *const *dm_integrator_types(void)
{
  return registry;
}

/* "family" or "family:variant" */
const dm_integrator_type *dm_integrator_lookup(const char *name, const char **variant_out)
{
  const char *colon;
  size_t len, i;
  if (variant_out)
    *variant_out = NULL;
  if (name == NULL)
    return NULL;
  colon = strchr(name, ':');
  len = colon ? (size_t)(colon - name) : strlen(name);
  for (i = 0; registry[i] != NULL; i++)
    if (strlen(registry[i]->name) == len && strncmp(registry[i]->name, name, len) == 0) {
      if (variant_out)
        *variant_out = colon ? colon + 1 : NULL;
      return registry[i];
    }
  return NULL;
}
