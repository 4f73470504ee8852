/* trajectory_meta.c -- the metadata of a trajectory: an ordered list of
 * key=value items whose values are strings or numbers.  See trajectory.h. */
#include <config.h>
#include "core/trajectory_impl.h"

#include <stdlib.h>
#include <string.h>

#include "core/numfmt.h"

/* {==== metadata ============================================================== */

static size_t meta_find(const dm_traj *tr, const char *key)
{
  size_t i;
  for (i = 0; i < tr->nmeta; i++)
    if (strcmp(tr->m[i].key, key) == 0)
      return i;
  return DM_TRAJ_NONE;
}

static int valid_key(const char *key)
{
  const unsigned char *s = (const unsigned char *)key;
  if (s == NULL || *s == '\0')
    return 0;
  for (; *s != '\0'; s++)
    if (*s < 0x20 || *s == 0x7f || *s == '=')
      return 0;
  return 1;
}

/* Set key to the string value (isnum 0) or the number x (value: its text). */
static int meta_put(dm_traj *tr, const char *key, const char *value, int isnum, double x,
                    dm_err *e)
{
  size_t i;
  char *dk, *dv;
  if (!valid_key(key))
    return dm_err_set(e, DM_EINVAL, "invalid metadata key '%.100s' (non-empty,"
                      " no '=' and no control characters)",
                      key != NULL ? key : "(null)");
  i = meta_find(tr, key);
  if (value == NULL) {                       /* remove */
    if (i == DM_TRAJ_NONE)
      return DM_OK;
    free(tr->m[i].key);
    free(tr->m[i].val);
    memmove(tr->m + i, tr->m + i + 1, (tr->nmeta - i - 1) * sizeof *tr->m);
    tr->nmeta--;
    return DM_OK;
  }
  if ((dv = dm_traj__dupstr(value)) == NULL)
    return dm_err_set(e, DM_ENOMEM, "metadata: out of memory");
  if (i == DM_TRAJ_NONE) {
    if (tr->nmeta == tr->metacap) {
      size_t nc = tr->metacap ? 2 * tr->metacap : 8;
      meta *m2 = realloc(tr->m, nc * sizeof *m2);
      if (m2 == NULL) {
        free(dv);
        return dm_err_set(e, DM_ENOMEM, "metadata: out of memory");
      }
      tr->m = m2;
      tr->metacap = nc;
    }
    if ((dk = dm_traj__dupstr(key)) == NULL) {
      free(dv);
      return dm_err_set(e, DM_ENOMEM, "metadata: out of memory");
    }
    i = tr->nmeta++;
    tr->m[i].key = dk;
  } else {
    free(tr->m[i].val);
  }
  tr->m[i].val = dv;
  tr->m[i].isnum = isnum;
  tr->m[i].x = x;
  return DM_OK;
}

int dm_traj_meta_set(dm_traj *tr, const char *key, const char *value,
                     dm_err *e)
{
  return meta_put(tr, key, value, 0, 0.0, e);
}

int dm_traj_meta_set_number(dm_traj *tr, const char *key, double x, dm_err *e)
{
  char buf[DM_NUM_BUFSIZE];
  dm_num_format(buf, sizeof buf, x);
  return meta_put(tr, key, buf, 1, x, e);
}

const char *dm_traj_meta_get(const dm_traj *tr, const char *key)
{
  size_t i = key != NULL ? meta_find(tr, key) : DM_TRAJ_NONE;
  return i != DM_TRAJ_NONE ? tr->m[i].val : NULL;
}

int dm_traj_meta_number(const dm_traj *tr, const char *key, double *x)
{
  size_t i = key != NULL ? meta_find(tr, key) : DM_TRAJ_NONE;
  if (i == DM_TRAJ_NONE || !tr->m[i].isnum)
    return 0;
  if (x != NULL)
    *x = tr->m[i].x;
  return 1;
}

size_t dm_traj_meta_count(const dm_traj *tr) { return tr->nmeta; }

int dm_traj_meta_at(const dm_traj *tr, size_t i, const char **key,
                    const char **value)
{
  if (i >= tr->nmeta)
    return DM_EINVAL;
  if (key != NULL)
    *key = tr->m[i].key;
  if (value != NULL)
    *value = tr->m[i].val;
  return DM_OK;
}

int dm_traj_meta_number_at(const dm_traj *tr, size_t i, double *x)
{
  if (i >= tr->nmeta || !tr->m[i].isnum)
    return 0;
  if (x != NULL)
    *x = tr->m[i].x;
  return 1;
}

/* }==== */
