/* linit.c -- the list of binding modules that make up the `dm` table.
 * A new binding module adds one line to `openers`. */
#include <config.h>

#include "lua/dmlua.h"

typedef void (*dm_opener)(lua_State *L);

static const dm_opener openers[] = {
  dm_open_doc,
  dm_open_linalg,
  dm_open_plot,
  dm_open_traj,
  dm_open_expr,
  dm_open_system,
  dm_open_builtin,
  dm_open_integrator,
  dm_open_reduce,
  dm_open_dec,
  dm_open_lie,
  dm_open_conn,
  dm_open_ensemble,
  dm_open_fields,
  dm_open_wave,
  NULL
};

void dm_open_all(lua_State *L)
{
  const dm_opener *o;
  for (o = openers; *o != NULL; o++)
    (*o)(L);
}
