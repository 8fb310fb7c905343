#include <string.h>

#include "qs_engine.h"
#include "qs_engine_tick.h"
#include "qs_port.h"

void qs_engine_init(qs_engine *e, uint8_t queue_capacity)
{
    uint8_t axis;

    qs_queue_init(&e->queue, queue_capacity);
    e->seg = 0;
    e->left = 0;
    e->slow_path = 1;
    e->dir_bits = 0;
    e->state = QS_STATE_IDLE;
    e->alarm = QS_ALARM_NONE;
    e->kept = 0;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        e->base[axis] = 0;
        e->pending[axis] = 0;
    }
    e->completed_ticks = 0;
    e->segments_done = 0;
    e->hold.moving = 0;
    e->hold.planned_n = 0;
    e->hold.predicted_slot = 0;
    e->held = 0;
    e->held_t0 = 0;
    e->hold_tick = 0;
    e->hold_end_tick = 0;
    e->hold_report = 0;
    e->hold_alarm = QS_ALARM_NONE;
    e->hold_starves = 0;
    e->holds_begun = 0;
#if QS_RASTER_BYTES
    e->line_lit = 0;
#endif
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        e->stop_decel[axis] = QS_DEFAULT_STOP_DECEL;
    e->hold_along = 0;
    for (axis = 0; axis < QS_LATCH_RING; axis++)
        e->latches.entry[axis].state = QS_LATCH_FREE;
    e->latches.next = 0;
    e->latches.taken = 0;
    e->latches.oldest = 0;
    e->latches.lost = 0;
    e->frozen = 0;
    e->trigger = 0;
    e->trigger_window = 0;
    e->trigger_rest = 0;
    e->held_by_tick = 0;
    e->resequence = 0;
    qs_cubic_reset(&e->chain);
}

/* A trigger's window closes early (a HOLD, STOP, an alarm): the segment's
 * count is whole again. With the tick locked out, or in it. */
static void close_trigger_window(qs_engine *e)
{
    if (!e->trigger_window)
        return; /* trigger_rest is trigger_since, for an armed trigger */
    e->left = (uint16_t)(e->left + e->trigger_rest);
    e->trigger_rest = 0;
    e->trigger_window = 0;
}

/* The segment length a hold's plan is for (qs_hold_plan): a quadratic
 * segment's own, and for a cubic one the scale its hold runs in. */
static uint16_t hold_key(const qs_segment *s)
{
    return QS_IS_CUBIC(s) ? QS_HOLD_CUBIC_N : s->n;
}

static int32_t signed_steps(const qs_segment *s, uint8_t axis, int32_t steps, int32_t position)
{
    return ((s->negative >> axis) & 1u) ? position - steps : position + steps;
}

/* What the running or held slot has done (qs_progress), taken with the
 * tick locked out or in the tick: a few bytes, so that the closed forms (a
 * division each) run unlocked. The slot itself stays put meanwhile: only
 * the main loop refills slots, after retiring them, and a held slot's own
 * state is frozen. */

/* Steps an axis of s made in its first t ticks, from its state frozen or
 * copied after them. */
static QS_NOINLINE int32_t steps_at(const qs_segment *s, uint8_t axis, uint16_t t)
{
    if (QS_IS_CUBIC(s))
        return qs_cubic_steps(s, axis, t, s->c.h[axis], s->c.b[axis], s->c.q[axis]);
    return qs_segment_steps(s, axis, t);
}

_Static_assert(sizeof(qs_i24) == sizeof(qs_u24), "b and steps are copied alike");

/* Kept short: it runs with the tick locked out, or in the tick at an
 * input's edge. */
static void take_progress(const qs_engine *e, qs_progress *p)
{
    const qs_segment *s = e->seg;

    if (!e->left && !e->kept) {
        /* Between segments, at rest, or a hold that has just ended (its
         * slot released, to be folded): nothing is part-way. (A kept slot
         * is read as a segment after all its ticks.) */
        p->seg = 0;
        return;
    }
    if (e->held) {
        p->held = 1;
        p->seg = e->held;
        p->t = e->held_t0;
        memcpy(p->at.hold.h, e->hold.h, sizeof p->at.hold.h);
        memcpy(p->at.hold.inc, e->hold.inc, sizeof p->at.hold.inc);
        p->at.hold.moving = e->frozen == QS_FROZEN_ALARM ? e->hold.moving_at_freeze : e->hold.moving;
        return;
    }
    p->held = 0;
    p->seg = s;
    p->t = (uint16_t)(s->n - e->left);
    if (e->trigger_window)
        p->t = (uint16_t)(p->t - e->trigger_rest); /* the window cut the count */
    if (QS_IS_CUBIC(s))
        memcpy(&p->at.c, &s->c, sizeof p->at.c);
    else
        memcpy(p->at.b, s->b, sizeof p->at.b);
}

/* A held slot: its t ticks before the hold, and the hold's, from its state
 * h, inc and moving (the hold's own, or a snapshot of it). Out of line:
 * the arithmetic stays off the stack of the usual snapshot. */
static QS_NOINLINE void add_held(const qs_engine *e, const qs_segment *s, uint16_t t, const qs_i24 *h,
                                 const qs_i24 *inc, uint8_t moving, int32_t *position, uint32_t *ticks)
{
    qs_hold_origin origin;
    uint32_t hold_ticks = 0;
    uint8_t axis;

    qs_hold_origin_of(&e->hold, s, t == s->n, &origin);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        if (s->active & (1u << axis)) {
            const uint32_t made =
                qs_hold_axis_made(&e->hold, &origin, axis, h[axis], inc[axis], moving, &hold_ticks);
            position[axis] = signed_steps(s, axis, steps_at(s, axis, t) + (int32_t)made, position[axis]);
        }
    *ticks += t + hold_ticks;
}

static void add_progress(const qs_engine *e, const qs_progress *p, int32_t *position, uint32_t *ticks)
{
    const qs_segment *s = p->seg;
    uint8_t axis;

    if (!s)
        return;
    if (p->held) {
        add_held(e, s, p->t, p->at.hold.h, p->at.hold.inc, p->at.hold.moving, position, ticks);
        return;
    }
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        int32_t steps;
        if (!(s->active & (1u << axis)))
            continue;
        if (QS_IS_CUBIC(s))
            steps = qs_cubic_steps(s, axis, p->t, p->at.c.h[axis], p->at.c.b[axis], p->at.c.q[axis]);
        else
            steps = qs_segment_steps_from(s, axis, p->t, p->at.b[axis]);
        position[axis] = signed_steps(s, axis, steps, position[axis]);
    }
    *ticks += p->t;
}

/* The hold is over: fold it into the totals (the tick no longer touches
 * it, so no snapshot is needed). */
static QS_NOINLINE void fold_held(qs_engine *e)
{
    const qs_segment *s = e->held;
    uint8_t axis;

    add_held(e, s, e->held_t0, e->hold.h, e->hold.inc, 0, e->base, &e->completed_ticks);
    if (e->held_t0 == s->n)
        e->segments_done++; /* held at its end (an underrun): it ran whole */
    e->held = 0;
    /* Nothing was queued while holding, and what was queued is gone. */
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        e->pending[axis] = 0;
}

static void note_hold_done(qs_engine *e)
{
    e->hold_report = 1;
    e->hold_end_tick = e->completed_ticks;
    qs_cubic_reset(&e->chain); /* whatever the queue was planned on is gone */
}

/* Latches whose snapshot is of the slot at queue index slot become
 * positions, with base and completed_ticks as they are at that slot's
 * start (it is not folded yet). Out of line, and called only when some
 * latch is kept: its frame stays off the main loop's deepest paths. */
static QS_NOINLINE void resolve_latches_now(qs_engine *e, uint8_t slot)
{
    uint8_t i, axis;

    for (i = 0; i < QS_LATCH_RING; i++) {
        qs_latch *l = &e->latches.entry[i];
        int32_t position[QS_AXIS_COUNT];
        uint32_t tick = e->completed_ticks;

        if (l->state == QS_LATCH_FREE || l->resolved || l->slot != slot)
            continue;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            position[axis] = e->base[axis];
        add_progress(e, &l->u.progress, position, &tick);
        l->u.at.tick = tick;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            l->u.at.position[axis] = position[axis];
        l->resolved = 1;
    }
}

static QS_ALWAYS_INLINE void resolve_latches(qs_engine *e, uint8_t slot)
{
    uint8_t i;

    for (i = 0; i < QS_LATCH_RING; i++)
        if (e->latches.entry[i].state != QS_LATCH_FREE) {
            resolve_latches_now(e, slot);
            return;
        }
}

void qs_engine_retire_slots(qs_engine *e)
{
    qs_queue *q = &e->queue;
    uint8_t tail = q->tail; /* slots before it are the tick's no more */

    QS_COMPILER_BARRIER(); /* what the tick wrote before releasing them */
    while (q->retired != tail) {
        const qs_segment *s = qs_queue_at(q, q->retired);
        uint8_t axis;
        resolve_latches(e, q->retired);
        if (s == e->held) {
            /* A hold ended: its slot is released only then. One the tick
             * began (at a trigger) leaves the queue behind it to drop. */
            if (e->held_by_tick) {
                e->hold_tick = e->completed_ticks + e->held_t0;
                q->head = qs_queue_next(q, q->retired);
                e->held_by_tick = 0;
            }
            fold_held(e);
            /* A hold the firmware began for a fault ends in its alarm; an
             * underrun's, paused (STARVED) until the host takes it up. */
            e->alarm = e->hold_alarm;
            e->state = e->hold_alarm    ? QS_STATE_ALARM
                       : e->hold_starves ? QS_STATE_STARVED
                                         : QS_STATE_IDLE;
            e->hold_alarm = QS_ALARM_NONE;
            e->hold_starves = 0;
            note_hold_done(e);
        } else {
            /* A whole segment: its step totals, no closed form needed (a
             * walking bit and walking pointers: the AVR shifts by a
             * variable count in a loop and indexes with a multiply). */
            uint8_t bit = 1;
            int32_t *base = e->base, *pending = e->pending;
            const uint16_t *total = s->total;
            for (axis = 0; axis < QS_AXIS_COUNT; axis++, bit = (uint8_t)(bit << 1), base++, pending++, total++) {
                int32_t steps;
                if (!(s->active & bit))
                    continue;
                steps = *total;
                if (s->negative & bit)
                    steps = -steps;
                *base += steps;
                *pending -= steps;
            }
            e->completed_ticks += s->n;
            e->segments_done++;
        }
        q->retired = qs_queue_next(q, q->retired);
    }
}

/* Retire everything and return with the tick locked out and nothing
 * finished but unretired. Each lock is short: folding happens unlocked. */
static uint8_t lock_retired(qs_engine *e)
{
    for (;;) {
        uint8_t saved;
        qs_engine_retire(e);
        saved = qs_port_lock();
        if (e->queue.retired == e->queue.tail)
            return saved;
        qs_port_unlock(saved);
    }
}

void qs_engine_wake(qs_engine *e)
{
    /* The tick changes state only while RUNNING, so IDLE cannot change
     * under us here; the lock keeps a resting tick from falling between
     * the two (the segment would begin a tick late). */
    if (e->state == QS_STATE_IDLE) {
        uint8_t saved = qs_port_lock();
        e->state = QS_STATE_RUNNING;
        qs_port_tick_wake();
        qs_port_unlock(saved);
    }
}

/* Drop the running slot and everything queued, unretired (with the tick
 * locked out and its steps already folded). */
static void flush(qs_engine *e)
{
    uint8_t axis;

    e->left = 0;
    e->slow_path = 1;
    qs_queue_drop(&e->queue);
    e->kept = 0;
    e->hold_alarm = QS_ALARM_NONE;
    e->hold_starves = 0;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        e->pending[axis] = 0;
}

void qs_engine_halt(qs_engine *e, uint8_t state, uint8_t alarm)
{
    uint8_t saved = lock_retired(e);
    const uint8_t halted = e->queue.tail;
    qs_progress p;

    /* Steps already made stay made: counted once the tick is let go. */
    close_trigger_window(e);
    take_progress(e, &p);
    e->hold.moving = 0;
    e->held = 0;
    e->held_by_tick = 0;
    e->trigger = 0;
    flush(e);
    qs_cubic_reset(&e->chain);
    e->alarm = alarm;
    e->state = state;
    e->frozen = 0;
    qs_port_unlock(saved);
    /* Latches taken in the halted slot, before its steps join the totals
     * (its contents stay until a new segment is queued). */
    resolve_latches(e, halted);
    add_progress(e, &p, e->base, &e->completed_ticks);
}

uint8_t qs_engine_set_positions(qs_engine *e, uint8_t mask, const int32_t *position)
{
    uint8_t saved = lock_retired(e);
    uint8_t ok = e->state == QS_STATE_IDLE && qs_queue_empty(&e->queue);
    uint8_t axis;

    for (axis = 0; ok && axis < QS_AXIS_COUNT; axis++)
        if (mask & (1u << axis))
            e->base[axis] = position[axis];
    qs_port_unlock(saved);
    if (ok)
        qs_cubic_rest_on_ideal(&e->chain, mask);
    return ok;
}

void qs_engine_read(qs_engine *e, qs_engine_view *v)
{
    uint8_t saved = lock_retired(e);
    const uint8_t tail = e->queue.tail;
    uint8_t axis;
    qs_progress p;

    /* A hold's window is open: the hold is under way, its deceleration due. */
    v->state = e->state == QS_STATE_RUNNING && e->trigger_window ? QS_STATE_HOLDING : e->state;
    v->alarm = e->alarm;
    take_progress(e, &p);
    qs_port_unlock(saved);
    v->queue_fill = qs_queue_distance(&e->queue, tail, e->queue.head);
    v->segments_done = e->segments_done;
    v->motion_ticks = e->completed_ticks;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        v->position[axis] = e->base[axis];
    add_progress(e, &p, v->position, &v->motion_ticks);
}

/* The slot a hold beginning now starts from, with the tick locked out (or
 * in it), while RUNNING: the running one; a kept one (the segment ended
 * moving, nothing behind it), from its end; between segments the next,
 * from its start (the kept one before it let go); 0 if none. */
static qs_segment *hold_slot(qs_engine *e)
{
    qs_queue *q = &e->queue;

    if (e->left != 0)
        return e->seg;
    if (e->kept) {
        if (qs_queue_count(q) == 1)
            return e->seg;
        e->kept = 0;
        qs_queue_release(q);
    }
    return qs_queue_empty(q) ? 0 : qs_queue_front(q);
}

/* A slot that hold_slot gave, and that has not begun: begin it as the tick
 * would have. A kept slot has run already: returns 1 (the hold begins at its
 * end), and it is now the held one, released when the hold ends. */
static uint8_t begin_slot(qs_engine *e, qs_segment *s)
{
    if (e->kept) {
        e->kept = 0;
        return 1;
    }
    if (e->left == 0) {
        e->seg = s;
        e->left = s->n;
        e->dir_bits = (uint8_t)((e->dir_bits & (uint8_t)~s->active) | s->negative);
    }
    return 0;
}

static QS_ALWAYS_INLINE uint8_t open_hold_window(qs_engine *e);

/* A hold begins through the window a trigger's hold takes (qs_engine.h):
 * the motion runs on for QS_TRIGGER_TICKS decisions while the tick plans
 * it, then the tick begins it, so that no tick runs twice its length.
 * The lock here only copies the decelerations and opens the window. */

/* Whether a HOLD_ALONG's decelerations are for the slot its hold will begin
 * in (QS_PATH_LEFT_MIN, qs_engine.h): one whose done count lies in first ...
 * last. With the tick locked out, while RUNNING. */
static uint8_t path_holds(qs_engine *e, const qs_path_hold *path)
{
    qs_queue *q = &e->queue;
    const uint8_t next = qs_queue_next(q, q->tail); /* the running slot keeps tail until it ends */
    const uint16_t span = (uint16_t)(path->last - path->first);
    const uint16_t done = (uint16_t)((uint16_t)e->segments_done - path->first);

    if (e->left >= QS_PATH_LEFT_MIN || (e->left && next == q->head))
        return done <= span;
    return e->left && done < span && qs_queue_at(q, next)->n >= QS_PATH_NEXT_MIN;
}

QS_NOINLINE uint8_t qs_engine_hold(qs_engine *e, const uint16_t *decel, const qs_path_hold *path)
{
    uint8_t saved = lock_retired(e);
    uint8_t outcome = QS_HOLD_STARTED, axis;

    e->trigger = 0; /* HOLD disarms */
    if (e->trigger_window) {
        outcome = QS_HOLD_UNDER_WAY; /* a hold's window is open: that hold answers for this one */
    } else if (e->state == QS_STATE_RUNNING) {
        /* The path's decelerations where the hold begins in a segment they
         * were given for. */
        e->hold_along = path && path_holds(e, path);
        if (e->hold_along)
            decel = path->hold.decel;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            e->trigger_decel[axis] = decel[axis];
        open_hold_window(e);
    } else {
        /* A hold running, or just ended and not yet reported, answers
         * for this one too. */
        outcome = e->state == QS_STATE_ALARM                               ? QS_HOLD_IN_ALARM
                  : e->state == QS_STATE_HOLDING || e->hold_report ? QS_HOLD_UNDER_WAY
                                                                    : QS_HOLD_AT_REST;
        if (outcome == QS_HOLD_AT_REST) {
            /* Nothing ran since the last hold ended: repeat its report,
             * so that a host that lost HOLD_DONE can simply ask again. */
            if (e->completed_ticks != e->hold_end_tick)
                e->hold_tick = e->completed_ticks;
            note_hold_done(e);
        }
    }
    qs_port_unlock(saved);
    return outcome;
}

int32_t qs_engine_speed_2n_locked(const qs_engine *e, uint8_t axis)
{
    if (e->left == 0 || e->held || QS_IS_CUBIC(e->seg) || !(e->seg->active & (1u << axis)))
        return 0;
    return qs_segment_speed_2n(e->seg, axis);
}

/* ---- inputs, from the tick ---- */

static uint8_t next_latch(uint8_t i)
{
    return (uint8_t)(i + 1 == QS_LATCH_RING ? 0 : i + 1);
}

qs_latch *qs_engine_latch_in_tick(qs_engine *e)
{
    qs_latch_ring *r = &e->latches;
    qs_latch *l = &r->entry[r->next];

    if (l->state != QS_LATCH_FREE) {
        if (r->lost != 0xFFFF)
            r->lost++;
        return 0;
    }
    take_progress(e, &l->u.progress);
    l->slot = e->queue.tail;
    l->resolved = 0;
    r->next = next_latch(r->next);
    r->taken++;
    return l;
}

void qs_engine_freeze_in_tick(qs_engine *e, uint8_t alarm)
{
    /* The tick's slow path then begins nothing (not RUNNING) and holds
     * nothing (no axis moving); the running or held slot keeps its state,
     * from which the main loop counts the steps made. */
    close_trigger_window(e);
    /* The hold's state counts its steps; its axes stopped here, not by
     * running out of increment (qs_hold_axis_made tells the two apart). */
    e->hold.moving_at_freeze = e->hold.moving;
    e->hold.moving = 0;
    e->slow_path = 1;
    e->trigger = 0;
    e->alarm = alarm;
    e->state = QS_STATE_ALARM;
    e->frozen = QS_FROZEN_ALARM;
}

void qs_engine_finish_freeze_slow(qs_engine *e)
{
    if (e->frozen == QS_FROZEN_ALARM) {
        qs_engine_halt(e, QS_STATE_ALARM, e->alarm);
        return;
    }
    /* A hold's window found every axis at rest: a hold at rest, at that
     * tick, ending as that hold would (a silent host's in its alarm). */
    const uint8_t alarm = e->hold_alarm;
    qs_engine_halt(e, alarm ? QS_STATE_ALARM : QS_STATE_IDLE, alarm);
    e->hold_tick = e->completed_ticks;
    note_hold_done(e);
}

/* The trigger's hold begins at this tick boundary: from the running slot,
 * a kept one's end or the next queued one's start, as HOLD would. Nothing
 * left to hold (the motion came to rest in the window): a hold found at
 * rest. Its plan is usually made already. */
static void begin_trigger_hold(qs_engine *e)
{
    const uint16_t left = e->left;
    qs_segment *s = e->state == QS_STATE_RUNNING ? hold_slot(e) : 0;
    uint8_t moving, at_end;

    e->trigger_window = 0;
    if (!s) {
        e->frozen = QS_FROZEN_AT_REST;
        return;
    }
    at_end = begin_slot(e, s);
    if (!at_end && qs_hold_is_predicted(&e->hold, s, e->left)) {
        moving = qs_hold_begin_predicted(&e->hold, s);
    } else {
        if (e->hold.planned_n != hold_key(s))
            qs_hold_plan(&e->hold, hold_key(s), e->trigger_decel);
        moving = qs_hold_begin(&e->hold, s, at_end);
    }
    e->holds_begun++;
    e->state = QS_STATE_HOLDING;
    e->slow_path = 1;
    if (!moving) {
        /* Every axis at rest already (a dwell): nothing more moves, and the
         * main loop ends it there as a hold found at rest. */
        e->left = left; /* a segment not begun stays so, and a kept one kept */
        e->kept = at_end;
        e->frozen = QS_FROZEN_AT_REST;
        return;
    }
    e->held = s;
    e->held_t0 = (uint16_t)(s->n - e->left);
    if (at_end)
        e->left = 1; /* nonzero while a slot is held: the hold releases it */
    e->held_by_tick = 1;
    e->hold.moving = moving;
}

/* Cut the running segment's count where the window's next work is due,
 * the window's count of decisions on, or let it run to its end if that comes first
 * (or one decision after: a cut never leaves a single tick, whose count
 * would not move across the cut's tick). */
static QS_ALWAYS_INLINE void cut_for_trigger(qs_engine *e)
{
    const uint8_t k = e->trigger_window & QS_TRIGGER_WAIT;
    const uint8_t work = e->trigger_window & (uint8_t)~QS_TRIGGER_WAIT;

    if (e->left > (uint16_t)k + 1u) {
        e->trigger_rest = (uint16_t)(e->left - k);
        e->left = k;
        e->trigger_window = work;
    } else {
        e->trigger_rest = 0;
        e->trigger_window = (uint8_t)(work | (e->left >= k ? 0 : (uint8_t)(k - e->left)));
    }
}

/* While RUNNING, with the tick locked out or in it: the window of a hold
 * at trigger_decel. */
static QS_ALWAYS_INLINE uint8_t open_hold_window(qs_engine *e)
{
    if (e->left == 0 && e->kept) {
        /* At a kept slot's end the next tick begins the hold there (an
         * underrun's path), with the window open: as a trigger's hold. */
        e->trigger_window = QS_TRIGGER_PLAN;
        return 1;
    }
    e->hold.planned_n = 0; /* and the plan, made again, drops a prediction */
    e->trigger_window = QS_TRIGGER_PLAN | QS_TRIGGER_PLAN_AT;
    if (e->left)
        cut_for_trigger(e); /* else the next segment, begun by the next tick, is cut as it begins */
    return 1;
}

uint8_t qs_engine_trigger_in_tick(qs_engine *e)
{
    e->trigger = 0;
    if (e->state != QS_STATE_RUNNING)
        return 0;
    e->resequence = 1; /* the stream ends here: frames in flight never run */
    if (e->left == 0 && e->kept) {
        begin_trigger_hold(e); /* at a kept slot's end: nothing to spread it over */
        return 1;
    }
    return open_hold_window(e);
}

/* A segment has just begun in the window. The tick that loads it (and
 * would make a hold's first decision) takes no other work, nor does the
 * next, which takes up the loading tick's lateness: what is due waits for
 * its third decision. A plan made for the segment before is made again,
 * for this one, before its hold begins; so are the increments (a
 * prediction is for one slot), in a tick of their own as far before the
 * beginning as in a window without a boundary (the beginning stays where
 * it was due, or follows that tick by as much) where the segment is long
 * enough for both, else in this tick. */
#define FIRST_WORK 3 /* the decision of a segment begun in the window at which work is done */
static void defer_past_begin(qs_engine *e)
{
    const uint8_t span = QS_TRIGGER_TICKS - QS_TRIGGER_PREDICT_AT; /* the increments to the beginning */
    const uint8_t planned = e->hold.planned_n == hold_key(e->seg);
    uint8_t wait = e->trigger_window & QS_TRIGGER_WAIT;
    uint8_t work = e->trigger_window & (uint8_t)~QS_TRIGGER_WAIT;

    if (work == QS_TRIGGER_PREDICT && (wait < FIRST_WORK || !planned)) {
        /* No prediction where it would be deferred or the plan is for
         * another length: the beginning is due when it would have been. */
        work = QS_TRIGGER_BEGIN;
        wait = (uint8_t)(wait + span);
    }
    if (work == QS_TRIGGER_BEGIN && !planned) {
        work = QS_TRIGGER_PLAN;
    } else if (work == QS_TRIGGER_BEGIN && !QS_IS_CUBIC(e->seg)) {
        const uint8_t at = wait >= FIRST_WORK + span ? (uint8_t)(wait - span) : FIRST_WORK;
        if (e->left > (uint16_t)(at + span + 1u)) {
            work = QS_TRIGGER_PREDICT;
            wait = at;
        }
    }
    if (wait < FIRST_WORK)
        wait = FIRST_WORK;
    e->trigger_window = (uint8_t)(work | wait);
}

/* Cut for the window's next work; where that is the hold's beginning and
 * the cut is in this slot, the hold begins where its count runs out, after
 * `left` more decisions: all but the rescale of h is done now, out of that
 * tick (b gains db with each decision; left counts this tick's too when it
 * is still to come, as in the tick that loads a segment). */
static QS_ALWAYS_INLINE void cut_and_predict(qs_engine *e)
{
    cut_for_trigger(e);
    if (e->trigger_window == QS_TRIGGER_BEGIN && e->trigger_rest && !QS_IS_CUBIC(e->seg)
        && e->hold.planned_n == e->seg->n)
        qs_hold_predict(&e->hold, e->seg, (uint8_t)e->left, e->trigger_rest);
}

void qs_engine_trigger_split_in_tick(qs_engine *e)
{
    if (!e->left) {
        /* The count ran out: where the window cut it, or at the segment's
         * end. The next segment is the next tick's to begin (the last
         * step goes out with its own direction), and it is cut then. */
        const uint16_t rest = e->trigger_rest;
        e->trigger_rest = 0;
        e->left = rest;
        if (!rest) {
            qs_engine_end_segment(e, e->seg);
            if (e->state != QS_STATE_RUNNING)
                begin_trigger_hold(e); /* the motion came to rest: a hold found at rest */
            return; /* a kept slot's end: the next tick begins the hold there (an underrun's path) */
        }
    }
    /* A segment runs on past a cut, or has just begun: the work due now,
     * then the next cut. */
    if (e->left == e->seg->n && e->left > FIRST_WORK + 1u) /* a cut there leaves more than a tick */
        defer_past_begin(e);
    if (!(e->trigger_window & QS_TRIGGER_WAIT)) {
        if (e->trigger_window == QS_TRIGGER_BEGIN) {
            begin_trigger_hold(e);
            return;
        }
        if (e->trigger_window == QS_TRIGGER_PLAN) {
            /* The plan, for the slot that runs now: usually the one held. */
            qs_hold_plan(&e->hold, hold_key(e->seg), e->trigger_decel);
            e->trigger_window = QS_TRIGGER_PREDICT | (QS_TRIGGER_PREDICT_AT - QS_TRIGGER_PLAN_AT);
            cut_for_trigger(e);
            return;
        }
        /* The increments, worked out as the cut for the beginning is made. */
        e->trigger_window = QS_TRIGGER_BEGIN | (QS_TRIGGER_TICKS - QS_TRIGGER_PREDICT_AT);
        cut_and_predict(e);
        return;
    }
    cut_and_predict(e); /* a beginning carried into a short segment begun in the window is predicted here */
}

/* ---- inputs, main loop ---- */

void qs_engine_arm_trigger(qs_engine *e, uint8_t input, uint8_t level, const uint16_t *decel)
{
    uint8_t saved = qs_port_lock();
    uint8_t axis;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        e->trigger_decel[axis] = decel[axis];
    e->hold_along = 0; /* a trigger's hold stops each axis at its own */
    e->trigger_input = input;
    e->trigger_level = level;
    e->trigger_since = (uint16_t)e->segments_done;
    e->trigger = 1;
    qs_port_unlock(saved);
}

void qs_engine_disarm_trigger(qs_engine *e)
{
    e->trigger = 0;
}

const qs_latch *qs_engine_oldest_latch(qs_engine *e)
{
    qs_latch_ring *r = &e->latches;

    qs_engine_retire(e);
    /* Every latch of a retired slot is resolved; those of the slot at the
     * retirement point resolve against its start. */
    resolve_latches(e, e->queue.retired);
    for (;;) {
        qs_latch *l = &r->entry[r->oldest];
        const uint8_t state = l->state;
        if (state == QS_LATCH_DISCARDED) {
            l->state = QS_LATCH_FREE;
            r->oldest = next_latch(r->oldest);
            continue;
        }
        return state == QS_LATCH_CONFIRMED && l->resolved ? l : 0;
    }
}

void qs_engine_free_latch(qs_engine *e)
{
    qs_latch_ring *r = &e->latches;

    r->entry[r->oldest].state = QS_LATCH_FREE;
    r->oldest = next_latch(r->oldest);
}

/* ---- faults, from the tick ---- */

void qs_engine_underrun_in_tick(qs_engine *e)
{
    qs_segment *s = e->seg; /* the kept slot, after all its ticks */
    uint8_t moving;

    if (e->trigger_window) {
        begin_trigger_hold(e); /* a trigger's window reached the end: its hold, from there */
        return;
    }
    qs_hold_plan(&e->hold, hold_key(s), e->stop_decel);
    moving = qs_hold_begin(&e->hold, s, 1);
    e->holds_begun++;
    e->trigger = 0;
    e->kept = 0;
    e->state = QS_STATE_HOLDING;
    e->held = s;
    e->held_t0 = s->n;
    e->held_by_tick = 1;
    e->hold_starves = 1; /* segments arriving meanwhile, and until a HOLD, are BUSY */
    if (!moving) {
        /* Nothing would move one tick on: a hold of no ticks at the
         * segment's end, its slot given back at once to be folded. */
        qs_queue_release(&e->queue);
        return;
    }
    e->left = 1; /* nonzero while a slot is held: the hold releases it */
    e->hold.moving = moving;
}

void qs_engine_end_starved(qs_engine *e)
{
    uint8_t saved = qs_port_lock(); /* an input's alarm from the tick wins */

    if (e->state == QS_STATE_STARVED)
        e->state = QS_STATE_IDLE;
    e->hold_starves = 0; /* an underrun's stop still under way ends IDLE, as the HOLD's own */
    qs_port_unlock(saved);
}

/* ---- positions ---- */

uint8_t qs_engine_room_for(const qs_engine *e, uint8_t active, uint16_t n, uint8_t *axis)
{
    uint8_t a, bit;
    const int32_t *base = e->base, *pending = e->pending;
    const int32_t most = QS_POSITION_MAX - (int32_t)n; /* a segment moves a position at most n */

    /* a walking bit and walking pointers (see qs_engine_retire_slots) */
    for (a = 0, bit = 1; a < QS_AXIS_COUNT; a++, bit = (uint8_t)(bit << 1), base++, pending++) {
        int32_t ahead;
        if (!(active & bit))
            continue;
        ahead = *base + *pending; /* where the queue leaves it */
        if (ahead > most || ahead < -most) {
            *axis = a;
            return 0;
        }
    }
    return 1;
}

void qs_engine_note_prepared(qs_engine *e, const qs_segment *s)
{
    uint8_t axis, bit;
    int32_t *pending = e->pending;
    const uint16_t *total = s->total;

    e->hold_along = 0; /* motion since the last hold: an underrun's stop would be its own */
    for (axis = 0, bit = 1; axis < QS_AXIS_COUNT; axis++, bit = (uint8_t)(bit << 1), pending++, total++) {
        int32_t steps;
        if (!(s->active & bit))
            continue;
        steps = *total;
        if (s->negative & bit)
            steps = -steps;
        *pending += steps;
    }
}
