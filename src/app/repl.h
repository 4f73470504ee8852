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

/* Print the error message at the top of the stack (if any) to stderr,
 * prefixed with the program name. */
int dm_report(lua_State *L, int status);
void dm_message(const char *pname, const char *msg);

/* The program name used in reports (argv[0] or "dmech"). */
extern const char *dm_progname;

/* At the prompt tracebacks show only the user's frames (errors.c). */
void dm_set_interactive(lua_State *L, int on);

/* The text of the chunk about to run (for hints that quote the user's code). */
void dm_set_chunk(lua_State *L, const char *text, size_t len);

/* Make the top-level locals of the function at idx globals when it returns
 * or fails during the next dm_docall (dmech -i script.lua). */
void dm_keep_locals(lua_State *L, int idx);

/* Lua function: the active locals of its caller become globals (the
 * prompt passes it to every chunk, which calls it at its end). */
int dm_keep_caller_locals(lua_State *L);

/* True when a Ctrl-C stopped a script (not at the prompt): exit 130. */
int dm_script_interrupted(void);

/* Add dm.traceback() to the `dm` global. */
void dm_open_errors(lua_State *L);

/* The interactive loop: Readline when stdin is a terminal (and Readline was
 * built in), plain stdio otherwise. */
void dm_repl(lua_State *L);

/* Tab completion over the state's globals (complete.c). */
void dm_complete_init(lua_State *L);

#endif
