/* The per-tick step decision, inlined into the timer interrupt.
 *
 * qs_engine_tick() returns the axes that step at the NEXT tick (bit i =
 * axis i); e->dir_bits holds their directions. A new segment is loaded
 * lazily at the start of the call that makes its first decision, so the
 * last step of the previous segment still goes out with its own direction.
 * A segment starting at motion tick S makes the step decided by its call
 * t-1 (counting from 0) at tick S+t. While a hold is under way the tick
 * runs qs_hold_tick.h instead, at the cost of one flag test here. */
#ifndef QS_ENGINE_TICK_H
#define QS_ENGINE_TICK_H

#include "qs_engine.h"
#include "qs_hold_tick.h"

/* One axis, one decision: h >= 0 means the stepper would be half a step or
 * more behind the ideal position after the next tick. Without a step, 2*C2
 * is added before b so that no intermediate leaves +-(2nD + 3D). Steps are
 * not counted here: the main loop recovers them from the closed form. */
static QS_ALWAYS_INLINE uint8_t qs_engine_axis_tick(qs_segment *s, uint8_t axis)
{
    qs_i24 h = s->h[axis];
    qs_i24 b = s->b[axis];
    uint8_t stepped = 0;

    if (!(s->active & (1u << axis)))
        return 0;
    if (h >= 0)
        stepped = (uint8_t)(1u << axis);
    else
        h += s->two_c2;
    s->h[axis] = h + b;
    s->b[axis] = b + s->db[axis];
    return stepped;
}

/* Between segments: take the next one, or settle. */
static QS_ALWAYS_INLINE uint8_t qs_engine_begin(qs_engine *e)
{
    qs_segment *s;

    if (e->state != QS_STATE_RUNNING)
        return 0;
    if (qs_queue_empty(&e->queue)) {
        /* The previous segment ended moving and nothing followed it. */
        if (e->ends_moving) {
            e->alarm = QS_ALARM_UNDERRUN;
            e->state = QS_STATE_ALARM;
        } else {
            e->state = QS_STATE_IDLE;
        }
        return 0;
    }
    s = qs_queue_front(&e->queue);
    e->seg = s;
    e->left = s->n;
    /* Inactive axes keep their direction pins as they were. */
    e->dir_bits = (uint8_t)((e->dir_bits & (uint8_t)~s->active) | s->negative);
    return 1;
}

/* The segment's last decision is made: hand its slot back. */
static QS_ALWAYS_INLINE void qs_engine_finish(qs_engine *e, qs_segment *s)
{
    e->ends_moving = s->ends_moving;
    qs_queue_release(&e->queue);
    /* At rest with nothing queued: idle at once, so SET_POSITION is allowed
     * as soon as the host learns the segment is done. An underrun waits for
     * the next tick, giving the host that much more time. */
    if (!e->ends_moving && qs_queue_empty(&e->queue))
        e->state = QS_STATE_IDLE;
}

static QS_ALWAYS_INLINE uint8_t qs_engine_tick(qs_engine *e)
{
    qs_segment *s;
    uint8_t steps;

    if (QS_UNLIKELY(e->hold.moving))
        return qs_engine_hold_tick(e);
    if (e->left == 0 && !qs_engine_begin(e))
        return 0;
    s = e->seg;
    steps = qs_engine_axis_tick(s, 0);
#if QS_AXIS_COUNT > 1
    steps |= qs_engine_axis_tick(s, 1);
#endif
#if QS_AXIS_COUNT > 2
    steps |= qs_engine_axis_tick(s, 2);
#endif
#if QS_AXIS_COUNT > 3
    steps |= qs_engine_axis_tick(s, 3);
#endif
    if (--e->left == 0)
        qs_engine_finish(e, s);
    return steps;
}

#endif
