/* RASTER: a laser line at a constant speed with a power for every pixel
 * (PROTOCOL.md section 5.2). The motion is the chain's cruise, as a
 * SEGMENTS record with CRUISE would run it; the pixels' powers wait in a
 * ring until their segment has run. Where each pixel lasts at least the
 * target's PWM period, the tick switches the power at the decision that
 * crosses each boundary (qs_raster_tick.h): it counts the pixel axis's
 * steps down to the next one. Shorter pixels the target's main loop looks
 * up (qs_raster_level), from the steps the axis has made. */
#ifndef QS_RASTER_H
#define QS_RASTER_H

#include <stdint.h>
#include "qs_engine.h"
#include "qs_messages.h"
#include "qs_outputs.h"

_Static_assert(QS_RASTER_BYTES <= 1024, "a slot keeps a power's index in 10 bits");
_Static_assert((QS_RASTER_BYTES & (QS_RASTER_BYTES - 1)) == 0, "the ring wraps by a mask");

#define QS_LEN_RASTER_HEAD QS_LEN_RASTER
#define QS_RASTER_PIXELS_MAX (QS_MAX_FRAME - 4 - QS_LEN_RASTER_HEAD)
#define QS_RASTER_WHERE_COUNT_SHIFT 10

/* An index into the ring: a byte where the ring is no longer (the Uno's). */
#if QS_RASTER_BYTES <= 256
typedef uint8_t qs_raster_index;
#else
typedef uint16_t qs_raster_index;
#endif

typedef struct {
#if QS_RASTER_BYTES
    uint8_t power[QS_RASTER_BYTES];
    /* Tick side: the line whose pixels the tick switches (0: none, and the
     * duty is the main loop's), the pixel under its axis, and the count
     * down to the next boundary. */
    const qs_segment *line;
    uint16_t togo;      /* the pixel axis's steps to the next boundary */
    uint16_t pitch;     /* the line's, 1/256 step between boundaries */
    qs_raster_index at; /* the ring index of the pixel's power */
    uint8_t frac;       /* the last boundary crossed, phase + (k-1)*pitch, mod 256 */
    uint8_t boundaries; /* still to cross */
    uint8_t bit;        /* the pixel axis while boundaries remain, else 0 */
    uint8_t stepped;    /* the axes the tick that calls qs_raster_watch stepped */
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

/* The tick's work where a segment began with its first tick marked, or a
 * hold, an alarm or a cubic segment came while a line is lit: a RASTER line
 * of pixels a PWM period or longer (QS_SLOT_RASTER_TICK) whose setting is
 * on is the tick's from its first decision, its first pixel's power set at
 * once (qs_port_laser_power), until the first decision of what follows;
 * anything else gives the duty back to the main loop, dark until it looks.
 * Out of line: once a segment. */
void qs_raster_watch(qs_raster *r, const qs_outputs *o, qs_engine *e);

/* Whether the tick switches a line's pixels now (a line is lit). */
static inline uint8_t qs_raster_lit(const qs_raster *r)
{
#if QS_RASTER_BYTES
    return r->line != 0;
#else
    (void)r;
    return 0;
#endif
}

/* While a RASTER line runs and the setting it carries is on (out as
 * qs_outputs_level left it), its pixel's power replaces the duty: the
 * tick's, where it switches the line's pixels (while one is lit the target
 * leaves the duty to it: qs_raster_lit); for a line of pixels shorter
 * than the PWM's period, the pixel under the axis `ahead` ticks from now,
 * in the line running then if it is the next one (a target whose duty
 * takes effect a period later looks half a period ahead); past the end of
 * the RASTER lines queued, the setting's own duty (dark around a row). */
void qs_raster_level(const qs_raster *r, qs_engine *e, qs_output_level *out, uint16_t ahead);

#endif
