/* system.c -- helpers common to every dm_system. */
#include <config.h>
#include "core/system.h"

#include <string.h>

void dm_system_release(dm_system *s)
{
  if (s == NULL)
    return;
  if (s->free_data != NULL)
    s->free_data(s);
  memset(s, 0, sizeof *s);
}
