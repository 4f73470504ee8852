/* testrun.h -- `dmech test`: the command that runs users' *_test.lua files.
 *
 * The runner's logic (finding the files, reading their TAP, the report) is
 * the Lua module dmech.testrun; testrun.c gives it what Lua lacks -- child
 * processes run several at a time with their output captured, directory
 * listings, a monotonic clock, the number of usable cores -- in a Lua state
 * of its own.  Each test file runs in a fresh dmech process.
 *
 * dm_testrun takes the whole command line (argv[1] is "test") and returns
 * the process exit status: 0 when every test passed, 1 when one failed or a
 * file errored, 2 for bad usage, 130 when interrupted.  It prints to stdout
 * and stderr, never exits, and frees everything it made.  Not thread-safe
 * (it changes the SIGINT disposition while the children run).
 */
#ifndef DM_APP_TESTRUN_H
#define DM_APP_TESTRUN_H

int dm_testrun(int argc, char **argv);

#endif
