/* l_integ.h -- private glue of the integrator binding: l_integrator.c
 * (dm.integrator, states, one-step methods and diagnostics), l_integ_opts.c
 * (options and user tableaus),
 * l_integ_run.c (integ:run: the chunked C run loop, progress, trajectory
 * and diagnostic columns) and l_integ_diag.c (dm.tableau,
 * integ:order_estimate, dm.methods); l_ensemble.c (dm.ensemble) reads
 * integrators and states through it too, and the integrators of systems on
 * groups (l_lie_integ.c) run through dm_lua_integ_run.  Not for other
 * bindings.
 *
 * An Integrator is a userdata "dmech.integrator" holding a dm_linteg; its
 * user value 1 is the System userdata it integrates (kept alive by it),
 * user value 2 the userdata owning a prk tableau (or nil).
 */
#ifndef DM_L_INTEG_H
#define DM_L_INTEG_H

#include "lua/l_system.h"
#include "core/tableau.h"

#define DM_INTEG_MT "dmech.integrator"

typedef struct dm_linteg {
  dm_integrator *I;          /* NULL once closed */
  dm_lsystem *ls;            /* borrowed; anchored in user value 1 */
  unsigned long gen;         /* ls->gen when I was built */
  char method[2 * DM_INTEG_STRMAX];
  dm_integ_opts opt;         /* as given; opt.tableau (prk) lives in user value 2 */
  double h;                  /* step of step()/run(); NAN: not set */
  double *buf;               /* 10 n doubles */
} dm_linteg;

/* A state read from a Lua table {q=, p=} | {q=, v=} [t=]. */
typedef struct dm_lstate {
  double t;
  double *q, *p, *v;         /* n each (into dm_linteg.buf or caller memory) */
} dm_lstate;

/* The System at idx, or the one an object at idx stands for: its
 * metatable's __system (a function of the object) returns it, e.g. a
 * Routh reduction's reduced system; replaced at idx.  Raises "system
 * expected". */
dm_lsystem *dm_linteg_checksystem(lua_State *L, int idx);
/* The open Integrator at idx, rebuilt first if its system's parameters
 * changed since it was built; raises otherwise. */
dm_linteg *dm_linteg_check(lua_State *L, int idx);
/* The step size: the value at idx when it is a number, else integ.h;
 * raises when neither is a finite non-zero number. */
double dm_linteg_h(lua_State *L, dm_linteg *li, int idx);
/* Read the state table at idx, {q=, p=} | {q=, v=} [t=] (p wins when both
 * are given), into s, whose q, p, v point into buf (4 n doubles; the last n
 * are scratch): p from v through the Legendre map of I, v from p by Newton,
 * which also proves d2L/dv2 regular at the state.  Raises naming `fname`
 * on a missing field, a wrong size, NaN or Inf, or a singular Hessian. */
void dm_lua_readstate(lua_State *L, dm_lsystem *ls, dm_integrator *I, int idx,
                      const char *fname, double *buf, dm_lstate *s);
/* The same with the integrator's own buffer (buf[0 .. 4n)). */
void dm_linteg_readstate(lua_State *L, dm_linteg *li, int idx, const char *fname,
                         dm_lstate *s);
/* Push {t=, q=vec, p=vec, v=vec}. */
void dm_linteg_pushstate(lua_State *L, const dm_linteg *li, double t, const double *q,
                         const double *p, const double *v);
/* Parse integrator options from the table at idx (skipping the keys in
 * `skip`, a NULL-ended list) into opt, *method (anchored in the table), *h
 * (NAN when absent) and, for method "prk", the user tableau, and with the
 * option adapt the monitor of a time transformation (*method becomes
 * "adapt:<method>"): pushes one value, a table owning them, so nothing
 * leaks when a later check raises; opt->tableau, opt->monitor point into
 * it.  Options are mapped by
 * name through dm_integ_options; each must apply to the method, which must
 * apply to sys (its kind picks the family).  Raises naming `fname`. */
void dm_linteg_parse(lua_State *L, int idx, const char *fname, const char *const *skip,
                     const dm_system *sys, dm_integ_opts *opt, const char **method, double *h);
/* "a, b, gsl:<stepper>": the methods for systems of this kind (pushed). */
void dm_linteg_push_methods(lua_State *L, const char *kind);

/* The tableau box class (l_integ_opts.c). */
void dm_linteg_open_opts(lua_State *L);
/* The option adapt of the table at idx (l_integ_adapt.c): 0 when absent or
 * false; else sets opt->monitor (its owner stored as own.monitor, own a
 * table index) or opt->power and returns 1.  Raises naming fname. */
int dm_linteg_parse_adapt(lua_State *L, int idx, const char *fname, const dm_system *sys,
                          dm_integ_opts *opt, int own);
void dm_linteg_open_adapt(lua_State *L);

/* Lua functions defined in l_integ_run.c / l_integ_diag.c. */
int dm_linteg_run(lua_State *L);
/* integ:run after the state: the options table at o (keys as integ:run's;
 * h the integrator's step, NAN: none; ls the Lagrangian system whose
 * coordinates `momentum` names, NULL for a system on a group: momentum =
 * true | false selects the columns of its momentum map), then dm_run of I
 * from (t0, q, p) into a new Trajectory (progress line, sink, memory
 * warning); returns the Lua results: the trajectory[, message]. */
int dm_lua_integ_run(lua_State *L, dm_integrator *I, const dm_lsystem *ls, int o, double h,
                     double t0, double *q, double *p);
int dm_linteg_order_estimate(lua_State *L);   /* l_integ_diag.c */

/* Record the option keys of dm.integrator and integ:run in the docs. */
void dm_linteg_doc_options(lua_State *L);
void dm_linteg_doc_run(lua_State *L);
extern const dm_reg dm_linteg_diag_funcs[];

#endif
