/* CUBIC_SEGMENTS: chained cubic segments, several to a frame (PROTOCOL.md
 * section 5.2). A record carries n, per axis a jerk as a code (none, given,
 * the axis's last jerk in the frame or its negation) and, where an axis is
 * set, its new speed as a change from the chain's: a jerk-limited move's
 * phases take a few bytes each. */
#ifndef QS_CUBIC_RECORDS_H
#define QS_CUBIC_RECORDS_H

#include <stdint.h>
#include "qs_cubic.h"
#include "qs_messages.h"

/* The next record of run as a CUBIC_SEGMENT, into m, its sets made whole
 * from the chain (which must have followed the records before). Returns
 * QS_ERR_NONE, or QS_ERR_BAD_FIELD with f filled in: N, AXES, DIRECTION,
 * then per axis SPEED (a set outside 0 ... 1 step, or from a chain speed
 * outside it) and JERK. The record was parsed whole already
 * (qs_msg_parse_cubic_segments). */
uint8_t qs_cubic_records_next(qs_segments_msg *run, qs_cubic_chain *chain, uint8_t axis_count, qs_cubic_msg *m,
                              qs_fault *f);

#endif
