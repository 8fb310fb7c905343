/* The tick during a hold (qs_hold.h), inlined into the timer interrupt
 * like qs_engine_tick.h, which calls it while a hold is under way. It
 * counts neither ticks nor steps: the main loop works them out from the
 * hold's state (qs_hold_axis_made). */
#ifndef QS_HOLD_TICK_H
#define QS_HOLD_TICK_H

#include "qs_engine.h"

/* One axis, one decision (h >= 0: step), then stop the axis if the
 * increment after it would not be positive. */
static QS_ALWAYS_INLINE uint8_t qs_hold_axis_tick(qs_hold *hd, uint8_t axis, uint8_t *moving)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    qs_i24 h, inc;
    uint8_t stepped = 0;

    if (!(*moving & bit))
        return 0;
    h = hd->h[axis];
    if (h >= 0) {
        stepped = bit;
        h -= hd->two_c2;
    }
    inc = hd->inc[axis];
    hd->h[axis] = h + inc;
    if (inc <= 0)
        *moving &= (uint8_t)~bit;
    else
        hd->inc[axis] = inc + hd->db[axis];
    return stepped;
}

/* A target may replace the decision above by its own of the same effect
 * (firmware/avr/axis_tick.h): it returns steps with the axis's bit added
 * and clears the axis's bit in moving when it stops. */
#ifndef QS_HOLD_AXIS_TICK
#define QS_HOLD_AXIS_TICK(hd, axis, moving, steps) ((uint8_t)((steps) | qs_hold_axis_tick(hd, axis, &(moving))))
#endif

/* Decelerate every moving axis; when none is left, give the held slot back
 * so that the main loop folds the hold into the positions. */
static QS_ALWAYS_INLINE uint8_t qs_engine_hold_tick(qs_engine *e)
{
    qs_hold *hd = &e->hold;
    uint8_t moving = hd->moving;
    uint8_t steps = QS_HOLD_AXIS_TICK(hd, 0, moving, 0);

#if QS_AXIS_COUNT > 1
    steps = QS_HOLD_AXIS_TICK(hd, 1, moving, steps);
#endif
#if QS_AXIS_COUNT > 2
    steps = QS_HOLD_AXIS_TICK(hd, 2, moving, steps);
#endif
#if QS_AXIS_COUNT > 3
    steps = QS_HOLD_AXIS_TICK(hd, 3, moving, steps);
#endif
    hd->tick_byte++;
    hd->moving = moving;
    if (!moving) {
        e->left = 0;
        qs_queue_release(&e->queue);
    }
    return steps;
}

#endif
