/* The one core instance of the board firmware, shared by the main loop and
 * the step interrupt. */
#ifndef QS_FIRMWARE_H
#define QS_FIRMWARE_H

#include "qs_core.h"

extern qs_core core;

/* Start the port clock (port.c): Timer0, free-running. */
void port_clock_init(void);

#endif
