/* A RASTER line's pixels from the step tick (qs_raster.h), run by the
 * target right after qs_engine_tick with the axes it decided to step, in
 * a build with RASTER (QS_RASTER_BYTES).
 *
 * The first tick of a line of pixels a PWM period or longer is marked
 * (slow_path QS_PATH_RASTER, qs_engine_begin), and while a line is lit so
 * is the first tick of any segment; those ticks, and a hold's, an alarm's
 * or a cubic segment's while a line is lit, look further (qs_raster_watch,
 * once a segment). Every other tick costs two flag tests and, while a
 * line's pixel axis steps, a count down to the next boundary: the power
 * changes at the decision that reaches it. */
#ifndef QS_RASTER_TICK_H
#define QS_RASTER_TICK_H

#include "qs_raster.h"

#if QS_RASTER_BYTES

/* The rare call, made a target's own way (firmware/avr/rare_call.h). */
#ifndef QS_RASTER_WATCH
#define QS_RASTER_WATCH(r, o, e) qs_raster_watch(r, o, e)
#endif

/* The laser's power, set at once: a target may write its PWM in place
 * (firmware/avr/outputs.h). */
#ifndef QS_LASER_POWER
#define QS_LASER_POWER(power) qs_port_laser_power(power)
#endif

/* The decision crossed the next boundary: the next pixel's power, and the
 * steps to the boundary after it, floor((phase + k*pitch) / 256) less
 * floor((phase + (k-1)*pitch) / 256): pitch's whole steps, and one more
 * where the fractions carry. In line, in byte steps: at a pixel a step,
 * every tick of a line crosses one. */
static QS_ALWAYS_INLINE void qs_raster_cross(qs_raster *r)
{
    const qs_raster_index at = (qs_raster_index)((r->at + 1u) & (QS_RASTER_BYTES - 1u));

    r->at = at;
    if (--r->boundaries) {
        const uint8_t part = (uint8_t)r->pitch;
        const uint8_t frac = (uint8_t)(r->frac + part);
        r->frac = frac;
        r->togo = (uint16_t)((uint8_t)(r->pitch >> 8) + (uint16_t)(frac < part));
    } else {
        r->bit = 0; /* the last pixel: nothing more to count */
    }
    QS_LASER_POWER(r->power[at]);
}

static QS_ALWAYS_INLINE void qs_raster_tick(qs_raster *r, const qs_outputs *o, qs_engine *e, uint8_t steps)
{
    const uint8_t path = e->slow_path;

    (void)o; /* a target's own call may take it from elsewhere */
    if (e->line_lit && (steps & r->bit) && --r->togo == 0)
        qs_raster_cross(r);
    if (QS_UNLIKELY(path)
        && (path == QS_PATH_RASTER || (e->line_lit && (e->state != QS_STATE_RUNNING || path == QS_PATH_CUBIC)))) {
        r->stepped = steps;
        QS_RASTER_WATCH(r, o, e);
    }
}
#endif

#endif
