/* The reports the firmware sends (PROTOCOL.md section 6) and the
 * STATUS_REPORT counters. Each report is built in c->tx and sent at once,
 * before the next is built. Internal to the core. */
#ifndef QS_REPORTS_H
#define QS_REPORTS_H

#include "qs_core.h"

void qs_report_ack(qs_core *c, uint8_t seq, uint8_t reason);
void qs_report_error(qs_core *c, uint8_t seq, uint8_t type, const qs_fault *f);
void qs_report_identify(qs_core *c, uint8_t seq);

/* The answer to seq. With hold_first, a hold that ended while the status
 * was read is reported first. */
void qs_report_status(qs_core *c, uint8_t seq, uint8_t hold_first);
void qs_report_input_status(qs_core *c, uint8_t seq);

/* EVENT INPUT for every latched input change, oldest first, before
 * anything else is reported (a trigger's latch precedes its HOLD_DONE). */
void qs_report_pending_inputs(qs_core *c);

/* The EVENT HOLD_DONE of a finished hold, once (after the inputs' events).
 * Sent before anything else is handled and before any status that shows
 * the hold over, so a host learns where the axes rest before it sees them
 * idle. */
void qs_report_pending_hold(qs_core *c);

/* ALARM for the engine's alarm; every output goes off with it. */
void qs_report_alarm(qs_core *c);

/* The armed motion came to rest without its edge. Out of line: its
 * snapshot stays off the main loop's deepest paths. */
QS_NOINLINE void qs_report_probe_missed(qs_core *c);

/* f: an ERROR code alone, naming no field. */
static inline void qs_fault_code(qs_fault *f, uint8_t code)
{
    f->code = code;
    f->field = QS_FIELD_NONE;
    f->axis = QS_AXIS_NONE;
}

/* A counter one up, saturating at 65535. */
void qs_count(uint16_t *counter);

/* The counter an ERROR code belongs to, one up. */
void qs_count_error(qs_core *c, uint8_t code);

#endif
