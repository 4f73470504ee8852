/* repl.h -- what main.c and repl.c share. */
#ifndef DM_REPL_H
#define DM_REPL_H

#include <lua.h>

#define DM_PROGNAME "dmech"

/* Run the function below the narg arguments on the stack under a traceback
 * message handler with Ctrl-C armed: the first Ctrl-C stops Lua code (hook)
 * and C loops (dm_interrupted()), a second one during the same call quits.
 * Returns the lua_pcall status. */
int dm_docall(lua_State *L, int narg, int nres);

/* Print the error message at the top of the stack (if any) to stderr. */
int dm_report(lua_State *L, int status);

/* The interactive loop: Readline when stdin is a terminal (and Readline was
 * built in), plain stdio otherwise. */
void dm_repl(lua_State *L);

/* Tab completion over the state's globals (complete.c). */
void dm_complete_init(lua_State *L);

#endif
