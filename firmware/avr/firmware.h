/* The one core instance of the board firmware, shared by the main loop and
 * the step interrupt. */
#ifndef QS_FIRMWARE_H
#define QS_FIRMWARE_H

#include "qs_core.h"

extern qs_core core;

#endif
