/* SEGMENTS: chained quadratic segments, several to a frame (PROTOCOL.md
 * section 5.2). The segment before leaves every axis at a speed and a
 * residual, which the chain (qs_cubic.h) keeps exactly: they are the next
 * segment's v0 and r unless its record says otherwise, so a record carries
 * little more than n and each axis's change of speed. */
#ifndef QS_SEGMENTS_H
#define QS_SEGMENTS_H

#include <stdint.h>
#include "qs_cubic.h"
#include "qs_messages.h"

/* The next record of run as a SEGMENT, into s, which holds the record
 * before (what REPEAT and a record without an axes byte take from it); the
 * chain gives the defaults, so it must have followed that record.
 * Returns QS_ERR_NONE, or QS_ERR_BAD_FIELD with f filled in (AXES,
 * DIRECTION, V0, VN or RESIDUAL, as SEGMENT names them). The record was
 * parsed whole already (qs_msg_parse_segments). */
uint8_t qs_segments_next(qs_segments_msg *run, qs_cubic_chain *chain, uint8_t axis_count, qs_segment_msg *s,
                         qs_fault *f);

#endif
