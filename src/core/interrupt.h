/* interrupt.h -- the user's "stop" request, polled by every long loop.
 *
 * The application's SIGINT handler calls dm_interrupt_raise(); numerical loops
 * call dm_interrupted() once per step (it is a single volatile load) and, when
 * it returns non-zero, stop cleanly with DM_EINTR, keeping what they computed.
 * The application clears the flag before each new run.  The flag is process
 * wide on purpose: it models the one user at the keyboard.
 */
#ifndef DM_INTERRUPT_H
#define DM_INTERRUPT_H

#include <signal.h>

extern volatile sig_atomic_t dm_interrupt_flag;

/* Non-zero when the user asked to stop the current run. */
static inline int dm_interrupted(void) { return dm_interrupt_flag != 0; }

/* Async-signal-safe: request a stop. */
static inline void dm_interrupt_raise(void) { dm_interrupt_flag = 1; }

/* Forget a pending request (start of a new run). */
static inline void dm_interrupt_clear(void) { dm_interrupt_flag = 0; }

#endif
