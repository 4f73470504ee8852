/* l_conn_point.c -- points of a bundle in Lua (l_conn.h): a userdata
 * "dmech.bpoint" holding the nq coordinates, its bundle in user value 1;
 *   q = B:point{x = {0.5, 0}, g = 0} ; q.x ; q.g ; q.R ; q:coords()
 * and the reader every connection method uses for a point argument. */
#include <config.h>
#include <stdio.h>
#include <string.h>

#include "lua/l_conn.h"

/* {==== points ============================================================== */

static dm_lbpoint *topoint(lua_State *L, int idx)
{
  return luaL_testudata(L, idx, DM_BPOINT_MT);
}

dm_lbpoint *dm_lua_pushpoint(lua_State *L, int bidx, const double *q)
{
  dm_lbundle *b = dm_lua_checkbundle(L, bidx);
  dm_lbpoint *p;
  bidx = lua_absindex(L, bidx);
  p = lua_newuserdatauv(L, sizeof *p + b->B->nq * sizeof(double), 1);
  p->B = b->B;
  memcpy(p->q, q, b->B->nq * sizeof *q);
  luaL_setmetatable(L, DM_BPOINT_MT);
  lua_pushvalue(L, bidx);
  lua_setiuservalue(L, -2, 1);
  return p;
}

void dm_lua_point_from_table(lua_State *L, int bidx, int idx, const char *what, double *q)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, bidx)->B;
  char w[160];
  dm_err e;
  idx = lua_absindex(L, idx);
  if (dm_conn_bundle_is_trivial(B)) {
    lua_getfield(L, idx, "x");
    lua_getfield(L, idx, "g");
    if ((B->nx > 0 && lua_isnil(L, -2)) || lua_isnil(L, -1))
      luaL_error(L, "%s: a point {x = {...}, g = ...} of %s expected", what, B->name);
    snprintf(w, sizeof w, "%s.x", what);
    dm_lua_readshape(L, B, -2, w, q);
    snprintf(w, sizeof w, "%s.g", what);
    dm_lua_bundle_field(L, bidx, "group");
    dm_lua_readgroupelem(L, -1, -2, w, q + B->nx);
    lua_pop(L, 3);
    return;
  }
  if (strcmp(B->type->name, "sphere_frames") == 0) {
    dm_lelem *el;
    double R[9];
    lua_getfield(L, idx, "R");
    el = dm_lua_toelem(L, -1);
    if (el != NULL && el->G->kind == DM_LIE_SO3) {
      dm_lua_elem_numbers(L, el, what, R);
    } else if (dm_tomat(L, -1) != NULL) {
      gsl_matrix *M = dm_tomat(L, -1);
      size_t i;
      if (M->size1 != 3 || M->size2 != 3)
        luaL_error(L, "%s.R: a 3x3 matrix expected", what);
      for (i = 0; i < 9; i++)
        R[i] = gsl_matrix_get(M, i / 3, i % 3);
    } else {
      luaL_error(L, "%s: a frame {R = <SO3 element>} expected, got R = %s", what,
                 luaL_typename(L, -1));
    }
    {
      dm_lie_group *G3 = dm_lie_so3(NULL);
      int st = G3 ? dm_lie_check(G3, R, 1e-10, &e) : DM_ENOMEM;
      dm_lie_group_free(G3);
      if (st != DM_OK)
        luaL_error(L, "%s.R: %s", what, e.msg);
    }
    memcpy(q, R, sizeof R);
    lua_pop(L, 1);
    return;
  }
  lua_getfield(L, idx, "q");
  if (lua_isnil(L, -1))
    luaL_error(L, "%s: a point {q = {...}} (%d coordinates) expected", what, (int)B->nq);
  snprintf(w, sizeof w, "%s.q", what);
  dm_lua_conn_readnums(L, -1, w, q, B->nq);
  if (dm_conn_shape_check(B, q, w, &e) != DM_OK)
    luaL_error(L, "%s", e.msg);
  lua_pop(L, 1);
}

void dm_lua_readpoint(lua_State *L, int bidx, int idx, const char *what, double *q)
{
  const dm_conn_bundle *B = dm_lua_checkbundle(L, bidx)->B;
  dm_lbpoint *p = topoint(L, idx);
  if (p != NULL) {
    if (p->B != B && (p->B->nq != B->nq || p->B->type != B->type ||
                      !dm_lie_group_equal(p->B->G, B->G)))
      luaL_error(L, "%s: a point of %s expected, got a point of %s", what, B->name, p->B->name);
    memcpy(q, p->q, B->nq * sizeof *q);
    return;
  }
  if (lua_istable(L, idx) && luaL_len(L, idx) == 0) {
    dm_lua_point_from_table(L, bidx, idx, what, q);
    return;
  }
  if (lua_istable(L, idx) || dm_tovec(L, idx) != NULL) {
    dm_lua_conn_readnums(L, idx, what, q, B->nq);
    return;
  }
  luaL_error(L, "%s: a point of %s (B:point{...}) expected, got %s", what, B->name,
             luaL_typename(L, idx));
}

/* }==== */

/* {==== point class ========================================================= */

static int p_coords(lua_State *L)
{
  dm_lbpoint *p = luaL_checkudata(L, 1, DM_BPOINT_MT);
  dm_pushvec_copy(L, p->q, p->B->nq);
  return 1;
}

static int p_bundle(lua_State *L)
{
  luaL_checkudata(L, 1, DM_BPOINT_MT);
  lua_getiuservalue(L, 1, 1);
  return 1;
}

static int point_index(lua_State *L)
{
  dm_lbpoint *p = luaL_checkudata(L, 1, DM_BPOINT_MT);
  const char *k = lua_tostring(L, 2);
  const dm_conn_bundle *B = p->B;
  if (k != NULL) {
    int triv = dm_conn_bundle_is_trivial(B), sph = strcmp(B->type->name, "sphere_frames") == 0;
    if (strcmp(k, "x") == 0 || (sph && strcmp(k, "p") == 0)) {
      double x[DM_CONN_NX_MAX];
      dm_conn_proj(B, p->q, x);
      dm_pushvec_copy(L, x, B->nx);
      return 1;
    }
    if (strcmp(k, "g") == 0 && triv) {
      lua_getiuservalue(L, 1, 1);
      dm_lua_bundle_field(L, -1, "group");
      dm_lua_pushgroupelem(L, -1, p->q + B->nx);
      return 1;
    }
    if (strcmp(k, "R") == 0 && sph) {
      dm_lie_group **slot = dm_lua_newgroup(L);
      dm_err e;
      if ((*slot = dm_lie_so3(&e)) == NULL)
        return dm_lua_fail(L, "point.R", e.status, &e);
      dm_lua_pushgroupelem(L, -1, p->q);
      return 1;
    }
    if (strcmp(k, "q") == 0)
      return p_coords(L);
  }
  return dm_index_methods(L);
}

static int point_tostring(lua_State *L)
{
  dm_lbpoint *p = luaL_checkudata(L, 1, DM_BPOINT_MT);
  const dm_conn_bundle *B = p->B;
  char buf[640], v[200], g[160];
  if (dm_conn_bundle_is_trivial(B)) {
    dm_num_format_vec(v, sizeof v, p->q, B->nx);
    dm_lie_describe(B->G, p->q + B->nx, g, sizeof g);
    snprintf(buf, sizeof buf, "<point of %s: x = %s, g = %s>", B->name, v, g);
  } else if (strcmp(B->type->name, "sphere_frames") == 0) {
    double x[3];
    dm_conn_proj(B, p->q, x);
    dm_num_format_vec(v, sizeof v, x, 3);
    dm_num_format_vec(g, sizeof g, p->q, 9);
    snprintf(buf, sizeof buf, "<frame over p = %s: R = %s>", v, g);
  } else {
    dm_num_format_vec(v, sizeof v, p->q, B->nq);
    snprintf(buf, sizeof buf, "<point of %s: q = %s>", B->name, v);
  }
  lua_pushstring(L, buf);
  return 1;
}

static const dm_reg point_methods[] = {
  {"coords", p_coords, "q:coords() -> vec", "The stored coordinates of the point (shape chart, then group)."},
  {"bundle", p_bundle, "q:bundle() -> B", "The bundle of the point."},
  {NULL, NULL, NULL, NULL}
};

/* }==== */

void dm_lua_open_conn_point(lua_State *L)
{
  static const luaL_Reg pmeta[] = {{"__index", point_index}, {"__tostring", point_tostring},
                                   {NULL, NULL}};
  dm_newclass(L, DM_BPOINT_MT, "q", point_methods, pmeta);
  lua_pop(L, 1);
}
