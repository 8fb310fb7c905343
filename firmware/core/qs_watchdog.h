/* WATCHDOG (PROTOCOL.md section 5): motion stops when the host falls
 * silent. qs_core_host_silent (qs_core.h) tells when. Internal to the core. */
#ifndef QS_WATCHDOG_H
#define QS_WATCHDOG_H

#include "qs_core.h"

/* In force at once, counted from now; 0 turns it off. */
void qs_watchdog_start(qs_core *c, uint16_t timeout_ms);

/* The host went silent while moving (or left an underrun's stop with an
 * output on): a hold at stop_decel, ending in ALARM HOST_LOST (at once if
 * nothing moves). Out of line: rare. */
QS_NOINLINE void qs_watchdog_expire(qs_core *c);

#endif
