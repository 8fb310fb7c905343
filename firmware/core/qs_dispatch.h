/* Every host message (PROTOCOL.md section 5): its parser, then its
 * handler. Internal to the core. */
#ifndef QS_DISPATCH_H
#define QS_DISPATCH_H

#include "qs_core.h"

/* A checked frame's body (type, seq, payload): parsed, sequence-checked
 * where sequenced, and acted on; every outcome is answered. */
QS_NOINLINE void qs_dispatch_frame(qs_core *c, const uint8_t *body, uint8_t len);

/* A SEGMENT or CUBIC_SEGMENT, parsed and in sequence (a parked one too). */
void qs_on_segment(qs_core *c, const qs_host_msg *m);
void qs_on_cubic_segment(qs_core *c, const qs_host_msg *m);

#endif
