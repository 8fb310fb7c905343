#include "qs_engine.h"
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
    e->ends_moving = 0;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        e->base[axis] = 0;
    e->completed_ticks = 0;
    e->segments_done = 0;
    e->hold.moving = 0;
    e->hold.planned_n = 0;
    e->held = 0;
    e->held_t0 = 0;
    e->hold_tick = 0;
    e->hold_end_tick = 0;
    e->hold_report = 0;
}

static int32_t signed_steps(const qs_segment *s, uint8_t axis, int32_t steps, int32_t position)
{
    return ((s->negative >> axis) & 1u) ? position - steps : position + steps;
}

/* What the running or held slot has done, taken with the tick locked out:
 * a few bytes, so that the closed forms (a division each) run unlocked.
 * The slot itself stays put meanwhile: only the main loop refills slots,
 * and a held slot's own state is frozen. */
typedef struct {
    const qs_segment *seg; /* 0: nothing running */
    uint16_t t;            /* ticks of it run (before the hold, if held) */
    qs_u24 ticks;          /* a hold's ticks since */
    uint8_t held;
    union {
        qs_i24 b[QS_AXIS_COUNT];     /* running: its b after t ticks */
        qs_u24 steps[QS_AXIS_COUNT]; /* held: the hold's steps */
    } at;
} progress;

_Static_assert(sizeof(qs_i24) == sizeof(qs_u24), "b and steps are copied alike");

/* Kept short: it runs with the tick locked out. */
static void take_progress(const qs_engine *e, progress *p)
{
    const uint8_t *from;
    uint8_t *to = (uint8_t *)&p->at;
    uint8_t i;

    if (e->held) {
        p->held = 1;
        p->seg = e->held;
        p->t = e->held_t0;
        p->ticks = e->hold.ticks;
        from = (const uint8_t *)e->hold.steps;
    } else if (e->left) {
        p->held = 0;
        p->seg = e->seg;
        p->t = (uint16_t)(e->seg->n - e->left);
        p->ticks = 0;
        from = (const uint8_t *)e->seg->b;
    } else {
        p->seg = 0;
        return;
    }
    for (i = 0; i < sizeof p->at; i++)
        to[i] = from[i];
}

static void add_progress(const progress *p, int32_t *position, uint32_t *ticks)
{
    const qs_segment *s = p->seg;
    uint8_t axis;

    if (!s)
        return;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        int32_t steps;
        if (!(s->active & (1u << axis)))
            continue;
        if (p->held)
            steps = qs_segment_steps(s, axis, p->t) + (int32_t)p->at.steps[axis];
        else
            steps = qs_segment_steps_from(s, axis, p->t, p->at.b[axis]);
        position[axis] = signed_steps(s, axis, steps, position[axis]);
    }
    *ticks += p->t + (uint32_t)p->ticks;
}

/* The hold is over: fold it into the totals (the tick no longer touches
 * it, so no snapshot is needed). */
static QS_NOINLINE void fold_held(qs_engine *e)
{
    const qs_segment *s = e->held;
    uint8_t axis;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        if (s->active & (1u << axis))
            e->base[axis] = signed_steps(s, axis,
                                         qs_segment_steps(s, axis, e->held_t0) + (int32_t)e->hold.steps[axis],
                                         e->base[axis]);
    e->completed_ticks += e->held_t0 + (uint32_t)e->hold.ticks;
    e->held = 0;
}

static void note_hold_done(qs_engine *e)
{
    e->hold_report = 1;
    e->hold_end_tick = e->completed_ticks;
}

void qs_engine_retire_slots(qs_engine *e)
{
    qs_queue *q = &e->queue;
    uint8_t tail = q->tail; /* slots before it are the tick's no more */

    QS_COMPILER_BARRIER(); /* what the tick wrote before releasing them */
    while (q->retired != tail) {
        const qs_segment *s = qs_queue_at(q, q->retired);
        uint8_t axis;
        if (s == e->held) {
            /* A hold ended: its slot is released only then. */
            fold_held(e);
            e->state = QS_STATE_IDLE;
            note_hold_done(e);
        } else {
            /* A whole segment: its step totals, no closed form needed (a
             * walking bit: the AVR shifts by a variable count in a loop). */
            uint8_t bit = 1;
            for (axis = 0; axis < QS_AXIS_COUNT; axis++, bit = (uint8_t)(bit << 1)) {
                if (!(s->active & bit))
                    continue;
                if (s->negative & bit)
                    e->base[axis] -= s->total[axis];
                else
                    e->base[axis] += s->total[axis];
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
     * under us here. */
    if (e->state == QS_STATE_IDLE)
        e->state = QS_STATE_RUNNING;
}

/* Drop the running slot and everything queued, unretired (with the tick
 * locked out and its steps already folded). */
static void flush(qs_engine *e)
{
    e->left = 0;
    e->slow_path = 1;
    e->queue.tail = e->queue.head;
    e->queue.retired = e->queue.head;
    e->ends_moving = 0;
}

void qs_engine_halt(qs_engine *e, uint8_t state, uint8_t alarm)
{
    uint8_t saved = lock_retired(e);
    progress p;

    /* Steps already made stay made: counted once the tick is let go. */
    take_progress(e, &p);
    e->hold.moving = 0;
    e->held = 0;
    flush(e);
    e->alarm = alarm;
    e->state = state;
    qs_port_unlock(saved);
    add_progress(&p, e->base, &e->completed_ticks);
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
    return ok;
}

void qs_engine_read(qs_engine *e, qs_engine_view *v)
{
    uint8_t saved = lock_retired(e);
    const uint8_t tail = e->queue.tail;
    uint8_t axis;
    progress p;

    v->state = e->state;
    v->alarm = e->alarm;
    take_progress(e, &p);
    qs_port_unlock(saved);
    v->queue_fill = qs_queue_distance(&e->queue, tail, e->queue.head);
    v->segments_done = e->segments_done;
    v->motion_ticks = e->completed_ticks;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        v->position[axis] = e->base[axis];
    add_progress(&p, v->position, &v->motion_ticks);
}

/* The length of the segment a hold would begin in if it began now (0:
 * none), so that the plan is usually made before the lock that begins it. */
static uint16_t likely_held_n(qs_engine *e)
{
    uint8_t saved = qs_port_lock();
    uint16_t n = 0;

    if (e->state == QS_STATE_RUNNING) {
        if (e->left != 0)
            n = e->seg->n;
        else if (!qs_queue_empty(&e->queue))
            n = qs_queue_front(&e->queue)->n;
    }
    qs_port_unlock(saved);
    return n;
}

QS_NOINLINE uint8_t qs_engine_hold(qs_engine *e, const uint16_t *decel)
{
    qs_queue *q = &e->queue;
    uint16_t guess = likely_held_n(e);
    qs_segment *s;
    uint16_t left;
    uint8_t saved, moving, tail;

    e->hold.planned_n = 0;
    for (;;) {
        if (guess && e->hold.planned_n != guess)
            qs_hold_plan(&e->hold, guess, decel);
        saved = lock_retired(e);
        if (e->state != QS_STATE_RUNNING) {
            /* A hold running, or just ended and not yet reported, answers
             * for this one too. */
            uint8_t outcome = e->state == QS_STATE_ALARM                     ? QS_HOLD_IN_ALARM
                              : e->state == QS_STATE_HOLDING || e->hold_report ? QS_HOLD_UNDER_WAY
                                                                                : QS_HOLD_AT_REST;
            if (outcome == QS_HOLD_AT_REST) {
                /* Nothing ran since the last hold ended: repeat its report,
                 * so that a host that lost HOLD_DONE can simply ask again. */
                if (e->completed_ticks != e->hold_end_tick)
                    e->hold_tick = e->completed_ticks;
                note_hold_done(e);
            }
            qs_port_unlock(saved);
            return outcome;
        }
        if (e->left != 0) {
            s = e->seg;
        } else if (!qs_queue_empty(q)) {
            s = qs_queue_front(q); /* between segments: hold from the start of the next */
        } else {
            qs_port_unlock(saved);
            return QS_HOLD_NO_SEGMENT;
        }
        if (e->hold.planned_n == s->n)
            break;
        /* The segment ended meanwhile: plan for the one now running, out of
         * the lock, and look again. */
        guess = s->n;
        qs_port_unlock(saved);
    }
    if (e->left == 0) {
        /* Begin it as the tick would have. */
        e->seg = s;
        e->left = s->n;
        e->dir_bits = (uint8_t)((e->dir_bits & (uint8_t)~s->active) | s->negative);
    }
    moving = qs_hold_begin(&e->hold, s);
    if (!moving) {
        progress p;
        e->held = s;
        e->held_t0 = (uint16_t)(s->n - e->left);
        take_progress(e, &p);
        e->held = 0;
        flush(e);
        e->state = QS_STATE_IDLE;
        qs_port_unlock(saved);
        e->hold_tick = e->completed_ticks + p.t;
        add_progress(&p, e->base, &e->completed_ticks);
        note_hold_done(e);
        return QS_HOLD_AT_REST;
    }
    left = e->left;
    tail = q->tail; /* the held slot's: the tick releases it when the hold ends */
    e->state = QS_STATE_HOLDING;
    e->hold.moving = moving; /* the next tick decelerates */
    e->slow_path = 1;
    qs_port_unlock(saved);
    /* What only the main loop reads, after the lock: it delays a tick that
     * falls due meanwhile, so it holds the least. The tick no longer
     * begins segments (HOLDING), so the queued ones can go now. */
    q->head = qs_queue_next(q, tail);
    e->held = s;
    e->held_t0 = (uint16_t)(s->n - left);
    e->hold_tick = e->completed_ticks + e->held_t0;
    return QS_HOLD_STARTED;
}

int32_t qs_engine_speed_2n_locked(const qs_engine *e, uint8_t axis)
{
    if (e->left == 0 || e->held || !(e->seg->active & (1u << axis)))
        return 0;
    return qs_segment_speed_2n(e->seg, axis);
}
