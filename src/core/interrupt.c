/* interrupt.c -- storage of the interrupt flag (see interrupt.h). */
#include <config.h>
#include "core/interrupt.h"

volatile sig_atomic_t dm_interrupt_flag = 0;
