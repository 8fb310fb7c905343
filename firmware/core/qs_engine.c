#include "qs_engine.h"
#include "qs_port.h"

void qs_engine_init(qs_engine *e, uint8_t queue_capacity)
{
    uint8_t axis;

    qs_queue_init(&e->queue, queue_capacity);
    e->seg = 0;
    e->left = 0;
    e->dir_bits = 0;
    e->state = QS_STATE_IDLE;
    e->alarm = QS_ALARM_NONE;
    e->ends_moving = 0;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        e->base[axis] = 0;
    e->completed_ticks = 0;
    e->segments_done = 0;
}

/* Add the steps an axis made in the first t ticks of s to position. */
static int32_t moved(const qs_segment *s, uint8_t axis, uint16_t t, int32_t position)
{
    int32_t steps;

    if (!(s->active & (1u << axis)))
        return position;
    steps = qs_segment_steps(s, axis, t);
    return ((s->negative >> axis) & 1u) ? position - steps : position + steps;
}

void qs_engine_retire(qs_engine *e)
{
    qs_queue *q = &e->queue;
    uint8_t tail = q->tail; /* slots before it are the tick's no more */

    while (q->retired != tail) {
        const qs_segment *s = qs_queue_at(q, q->retired);
        uint8_t axis;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            e->base[axis] = moved(s, axis, s->n, e->base[axis]);
        e->completed_ticks += s->n;
        e->segments_done++;
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

void qs_engine_halt(qs_engine *e, uint8_t state, uint8_t alarm)
{
    uint8_t saved = lock_retired(e);

    if (e->left != 0) {
        /* Steps already made stay made. */
        const qs_segment *s = e->seg;
        uint16_t t = (uint16_t)(s->n - e->left);
        uint8_t axis;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            e->base[axis] = moved(s, axis, t, e->base[axis]);
        e->completed_ticks += t;
        e->left = 0;
    }
    e->queue.tail = e->queue.head;
    e->queue.retired = e->queue.head;
    e->ends_moving = 0;
    e->alarm = alarm;
    e->state = state;
    qs_port_unlock(saved);
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
    uint8_t axis;

    v->state = e->state;
    v->alarm = e->alarm;
    v->queue_fill = qs_queue_count(&e->queue);
    v->segments_done = e->segments_done;
    v->motion_ticks = e->completed_ticks;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        v->position[axis] = e->base[axis];
    if (e->left != 0) {
        const qs_segment *s = e->seg;
        uint16_t t = (uint16_t)(s->n - e->left);
        v->motion_ticks += t;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            v->position[axis] = moved(s, axis, t, v->position[axis]);
    }
    qs_port_unlock(saved);
}

int32_t qs_engine_speed_2n_locked(const qs_engine *e, uint8_t axis)
{
    if (e->left == 0 || !(e->seg->active & (1u << axis)))
        return 0;
    return qs_segment_speed_2n(e->seg, axis);
}
