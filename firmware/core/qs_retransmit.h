/* Selective repeat (PROTOCOL.md 5.4): the sequence check of sequenced
 * frames, segments parked after a lost frame, the stream ended by a hold
 * the firmware began. Internal to the core. */
#ifndef QS_RETRANSMIT_H
#define QS_RETRANSMIT_H

#include "qs_core.h"

/* Whether a sequenced frame is the one expected next. A later frame means
 * some were lost: a segment is parked to run after them if it can be, else
 * dropped; an earlier one is a resend of a frame already consumed. The
 * answer (an ACK) says which. */
uint8_t qs_in_sequence(qs_core *c, const qs_host_msg *m);

/* The frames parked behind the one just taken, now in order. One message
 * buffer, outside the frame's own call, keeps the stack as it was. */
QS_NOINLINE void qs_run_parked(qs_core *c);

/* A hold the firmware began itself (a trigger, the feed hold button) ends
 * the stream: frames the host sent before it learns of it must not run once
 * the hold is over. Moving next_seq on by half the sequence space makes
 * every one of them a duplicate (PROTOCOL.md 5.4); the host adopts next_seq
 * from a status at rest. */
void qs_end_stream(qs_core *c);

#endif
