/* RASTER: a laser line at a constant speed with a power for every pixel
 * (PROTOCOL.md section 5.2). The motion is the chain's cruise, as a
 * SEGMENTS record with CRUISE would run it; the pixels' powers wait in a
 * ring until their segment has run. The power is looked up from the steps
 * the pixel axis has made in the running segment, so the duty changes at
 * the step that crosses each boundary: the tick does nothing more. */
#ifndef QS_RASTER_H
#define QS_RASTER_H

#include <stdint.h>
#include "qs_engine.h"
#include "qs_messages.h"
#include "qs_outputs.h"

/* Pixel powers the ring holds (IDENTIFY_REPLY's raster_ring); 0 builds no
 * RASTER (the capability bit is then clear and the type unknown). At most
 * 1024 (a slot's 10-bit index). The Uno's laser build keeps 128. */
#ifndef QS_RASTER_BYTES
#define QS_RASTER_BYTES (QS_QUEUE_CAPACITY < 16 ? 0 : 1024)
#endif
_Static_assert(QS_RASTER_BYTES <= 1024, "a slot keeps a power's index in 10 bits");

#define QS_LEN_RASTER_HEAD QS_LEN_RASTER
#define QS_RASTER_PIXELS_MAX (QS_MAX_FRAME - 4 - QS_LEN_RASTER_HEAD)
#define QS_RASTER_WHERE_COUNT_SHIFT 10

typedef struct {
#if QS_RASTER_BYTES
    uint8_t power[QS_RASTER_BYTES];
#endif
    uint16_t write; /* where the next line's powers go */
} qs_raster;

/* The payload's length and fields; QS_ERR_NONE or QS_ERR_BAD_LENGTH. */
uint8_t qs_raster_parse(const uint8_t *p, uint8_t len, qs_raster_msg *m);

/* The line's own fields against its motion s (read from the chain, checked
 * as a SEGMENT): RASTER_AXIS, then PIXELS. */
uint8_t qs_raster_check(const qs_raster_msg *m, const qs_segment_msg *s, qs_fault *f);

/* Whether the ring has room for count more powers beside those of the
 * slots still queued (q's slots from retired to head). */
uint8_t qs_raster_room(const qs_raster *r, qs_queue *q, uint8_t count);

/* The line's powers into the ring, its pixels into the prepared slot. */
void qs_raster_store(qs_raster *r, qs_segment *slot, const qs_raster_msg *m);

/* The running RASTER's pixel power replaces the duty, while the setting it
 * carries is on (out as qs_outputs_level left it): the pixel under the axis
 * `ahead` ticks from now, in the line running then if it is the next one;
 * past the end of the RASTER lines queued, the setting's own duty (dark
 * around a row). */
void qs_raster_level(const qs_raster *r, qs_engine *e, qs_output_level *out, uint16_t ahead);

#endif
