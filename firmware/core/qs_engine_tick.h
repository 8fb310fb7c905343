/* The per-tick step decision, inlined into the timer interrupt.
 *
 * qs_engine_tick() returns the axes that step at the NEXT tick (bit i =
 * axis i); e->dir_bits holds their directions. A new segment is loaded
 * lazily at the start of the call that makes its first decision, so the
 * last step of the previous segment still goes out with its own direction.
 * A segment starting at motion tick S makes the step decided by its call
 * t-1 (counting from 0) at tick S+t. While a hold is under way the tick
 * runs qs_hold_tick.h instead. Between segments and during a hold
 * e->slow_path is set, so that the middle of a segment, nearly every tick,
 * costs one flag test for both. */
#ifndef QS_ENGINE_TICK_H
#define QS_ENGINE_TICK_H

#include "qs_engine.h"
#include "qs_hold_tick.h"

/* One axis, one decision: h >= 0 means the stepper would be half a step or
 * more behind the ideal position after the next tick. Without a step, 2*C2
 * is added before b so that no intermediate leaves +-(2nD + 3D). Steps are
 * not counted here: the main loop recovers them from the closed form.
 * axes is the segment's tick_axes: bit i runs the axis, bit i + 4 says
 * its b stays as it is (db = 0). */
static QS_ALWAYS_INLINE uint8_t qs_engine_axis_tick(qs_segment *s, uint8_t axis, uint8_t axes)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    qs_i24 h, b;
    uint8_t stepped = 0;

    if (!(axes & bit))
        return 0;
    h = s->h[axis];
    if (h >= 0)
        stepped = bit;
    else
        h += s->two_c2;
    b = s->b[axis];
    s->h[axis] = h + b;
    if (!(axes & (bit << 4)))
        s->b[axis] = b + s->db[axis];
    return stepped;
}

/* A target may replace the decision above by its own of the same effect
 * (firmware/avr/axis_tick.h); it returns steps with the axis's bit added. */
#ifndef QS_ENGINE_AXIS_TICK
#define QS_ENGINE_AXIS_TICK(s, axis, axes, steps) ((uint8_t)((steps) | qs_engine_axis_tick(s, axis, axes)))
#endif

/* One axis of a cubic segment (qs_cubic.h): the same sign test, in 32 bits;
 * adding Sigma = 2^31 without a step flips the top bit. axes is the slot's
 * tick_axes (bit i + 4: r = 0, q stays), steady its cubic bits (bit i:
 * q = r = 0, b stays). */
static QS_ALWAYS_INLINE uint8_t qs_cubic_axis_tick(qs_segment *s, uint8_t axis, uint8_t axes, uint8_t steady)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    uint32_t h, b;
    uint8_t stepped = 0;

    if (!(axes & bit))
        return 0;
    h = s->c.h[axis];
    if ((int32_t)h >= 0)
        stepped = bit;
    else
        h += QS_SIGMA;
    b = s->c.b[axis];
    s->c.h[axis] = h + b;
    if (!(axes & (bit << 4)))
        s->c.q[axis] += s->c.r[axis];
    if (!(steady & bit))
        s->c.b[axis] = b + (uint32_t)(int32_t)s->c.q[axis];
    return stepped;
}

/* The underrun's hold, begun out of line (a target calls it its own way:
 * firmware/avr/rare_call.h). */
#ifndef QS_ENGINE_UNDERRUN
#define QS_ENGINE_UNDERRUN(e) qs_engine_underrun_in_tick(e)
#endif

#ifndef QS_CUBIC_AXES_TICK
#define QS_CUBIC_AXIS(s, axis, axes, steady) qs_cubic_axis_tick(s, axis, axes, steady)
#if QS_AXIS_COUNT == 1
#define QS_CUBIC_AXES_TICK(s, axes, steady) QS_CUBIC_AXIS(s, 0, axes, steady)
#elif QS_AXIS_COUNT == 2
#define QS_CUBIC_AXES_TICK(s, axes, steady) (QS_CUBIC_AXIS(s, 0, axes, steady) | QS_CUBIC_AXIS(s, 1, axes, steady))
#elif QS_AXIS_COUNT == 3
#define QS_CUBIC_AXES_TICK(s, axes, steady)                                                               \
    (QS_CUBIC_AXIS(s, 0, axes, steady) | QS_CUBIC_AXIS(s, 1, axes, steady) | QS_CUBIC_AXIS(s, 2, axes, steady))
#else
#define QS_CUBIC_AXES_TICK(s, axes, steady)                                                               \
    (QS_CUBIC_AXIS(s, 0, axes, steady) | QS_CUBIC_AXIS(s, 1, axes, steady) | QS_CUBIC_AXIS(s, 2, axes, steady) \
     | QS_CUBIC_AXIS(s, 3, axes, steady))
#endif
#endif

/* The trigger's rare work where its window cuts a segment or one begins
 * (qs_engine_trigger_split_in_tick), called out of line (a target calls it
 * its own way: firmware/avr/rare_call.h). */
#ifndef QS_ENGINE_TRIGGER_SPLIT
#define QS_ENGINE_TRIGGER_SPLIT(e) qs_engine_trigger_split_in_tick(e)
#endif

/* Between segments: take the next one (returns 1), or settle (0). A
 * segment that ended moving with nothing behind it keeps its slot
 * (e->kept) until this tick: if the queue is still dry, a hold begins where
 * it ended (an underrun: QS_ENGINE_UNDERRUN, out of line), else the slot
 * goes. Cheap otherwise, as it runs in the tick that makes the segment's
 * first decision: the slot is ready, found without arithmetic
 * (qs_queue_front). */
static QS_ALWAYS_INLINE uint8_t qs_engine_begin(qs_engine *e)
{
    qs_segment *s;

    if (e->state != QS_STATE_RUNNING)
        return 0;
    if (QS_UNLIKELY(e->kept)) {
        if (qs_queue_count(&e->queue) == 1) {
            QS_ENGINE_UNDERRUN(e);
            return 0;
        }
        e->kept = 0;
        qs_queue_release(&e->queue);
    }
    if (qs_queue_empty(&e->queue)) {
        e->state = QS_STATE_IDLE;
        return 0;
    }
    s = qs_queue_front(&e->queue);
    e->seg = s;
    e->left = s->n;
    e->slow_path = QS_IS_CUBIC(s) ? QS_PATH_CUBIC
                   : QS_RASTER_BYTES && ((s->ends_moving & QS_SLOT_RASTER_TICK) || QS_ENGINE_LINE_LIT(e))
                       ? QS_PATH_RASTER /* for qs_raster_tick.h */
                       : 0;
    /* Inactive axes keep their direction pins as they were. */
    e->dir_bits = (uint8_t)((e->dir_bits & (uint8_t)~s->active) | s->negative);
    if (QS_UNLIKELY(e->trigger_window))
        QS_ENGINE_TRIGGER_SPLIT(e); /* a trigger's window cuts it (or its hold begins here) */
    return 1;
}

/* The segment's last decision is made: hand its slot back, unless it ends
 * moving with nothing queued behind it: then the slot stays (e->kept), so
 * that a hold can begin from its end (an underrun, or a HOLD meanwhile).
 * At rest with nothing queued: idle at once, so SET_POSITION is allowed as
 * soon as the host learns the segment is done. An underrun waits for the
 * next tick, giving the host that much more time. */
static QS_ALWAYS_INLINE void qs_engine_end_segment(qs_engine *e, qs_segment *s)
{
    e->slow_path = 1;
    if (s->ends_moving & QS_ENDS_MOVING) {
        if (qs_queue_next(&e->queue, e->queue.tail) == e->queue.head) {
            e->kept = 1;
            return;
        }
        qs_queue_release(&e->queue);
        return;
    }
    qs_queue_release(&e->queue);
    if (qs_queue_empty(&e->queue))
        e->state = QS_STATE_IDLE;
}

/* The count has run out: the segment's end, or in a trigger's window
 * (qs_engine.h) maybe only where the window cut it: the rare path sorts
 * that out. */
static QS_ALWAYS_INLINE void qs_engine_finish(qs_engine *e, qs_segment *s)
{
    if (QS_UNLIKELY(e->trigger_window)) {
        QS_ENGINE_TRIGGER_SPLIT(e);
        return;
    }
    qs_engine_end_segment(e, s);
}

/* A tick of a cubic segment: every axis, then the count. */
static QS_ALWAYS_INLINE uint8_t qs_engine_cubic_tick(qs_engine *e)
{
    qs_segment *s = e->seg;
    uint8_t steps = QS_CUBIC_AXES_TICK(s, s->tick_axes, s->cubic);

    if (QS_UNLIKELY(--e->left == 0))
        qs_engine_finish(e, s);
    return steps;
}

/* A target may want to know which ticks ran no segment's decisions (and
 * so took little time): between segments, idle, and in a hold. The AVR
 * holds its step pulse to its shortest width only in those
 * (firmware/avr/step_timer.c). */
#ifndef QS_ENGINE_UNDECIDED
#define QS_ENGINE_UNDECIDED()
#endif

/* A target may let its tick rest while nothing moves: this runs in the
 * ticks that find the engine with nothing to do (not RUNNING, no hold
 * moving), and only in those; qs_port_tick_wake ends the rest. */
#ifndef QS_ENGINE_RESTING
#define QS_ENGINE_RESTING()
#endif

static QS_ALWAYS_INLINE uint8_t qs_engine_tick(qs_engine *e)
{
    qs_segment *s;
    uint8_t axes, steps;

    /* A quadratic segment's ticks pay one test; a cubic one's one more. */
    if (QS_UNLIKELY(e->slow_path)) {
        if (QS_RASTER_BYTES && e->slow_path == QS_PATH_RASTER) {
            e->slow_path = 0; /* a line's mark, where no qs_raster_tick took it */
            goto quadratic;
        }
        if (!QS_CUBIC || e->slow_path != QS_PATH_CUBIC) {
            /* An underrun begins a hold in place of the next segment. */
            if (!e->hold.moving && !qs_engine_begin(e) && !e->hold.moving) {
                QS_ENGINE_RESTING();
                QS_ENGINE_UNDECIDED();
                return 0;
            }
            if (e->hold.moving) {
                steps = qs_engine_hold_tick(e);
                QS_ENGINE_UNDECIDED();
                return steps;
            }
            if (!QS_CUBIC || (QS_RASTER_BYTES ? e->slow_path != QS_PATH_CUBIC : !e->slow_path))
                goto quadratic; /* a line's mark is a quadratic segment's */
        }
        return qs_engine_cubic_tick(e);
    }
quadratic:
    s = e->seg;
    axes = s->tick_axes;
    steps = QS_ENGINE_AXIS_TICK(s, 0, axes, 0);
#if QS_AXIS_COUNT > 1
    steps = QS_ENGINE_AXIS_TICK(s, 1, axes, steps);
#endif
#if QS_AXIS_COUNT > 2
    steps = QS_ENGINE_AXIS_TICK(s, 2, axes, steps);
#endif
#if QS_AXIS_COUNT > 3
    steps = QS_ENGINE_AXIS_TICK(s, 3, axes, steps);
#endif
    if (QS_UNLIKELY(--e->left == 0))
        qs_engine_finish(e, s);
    return steps;
}

#endif
