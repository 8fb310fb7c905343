#include "qs_outputs.h"

#include "qs_port.h"

void qs_outputs_off(qs_outputs *o)
{
    uint8_t i;

    for (i = 0; i < QS_OUTPUT_SETTINGS; i++) {
        o->setting[i].bits = 0;
        o->setting[i].power = 0;
        o->setting[i].speed = 0;
    }
    o->latest = 0;
}

uint8_t qs_outputs_take(qs_outputs *o, qs_engine *e, const qs_outputs_msg *m)
{
    const uint8_t next = (uint8_t)(o->latest + 1 == QS_OUTPUT_SETTINGS ? 0 : o->latest + 1);
    const qs_output_setting *latest = &o->setting[o->latest];
    const uint8_t bits = (uint8_t)(m->outputs | (uint8_t)(m->axis << QS_OUT_AXIS_SHIFT));
    uint8_t i;

    if (latest->bits == bits && latest->power == m->power && latest->speed == m->speed)
        return 1;
    /* The segments from the running one on carry indices in order: the
     * next entry is free unless one of them still carries it. */
    for (i = e->queue.tail; i != e->queue.head; i = qs_queue_next(&e->queue, i))
        if (qs_outputs_carried(qs_queue_at(&e->queue, i)) == next)
            return 0;
    o->setting[next].bits = bits;
    o->setting[next].power = m->power;
    o->setting[next].speed = m->speed;
    o->latest = next;
    return 1;
}

uint32_t qs_outputs_ratio(uint32_t num, uint32_t den)
{
    while (den > 0xFFFFu) {
        den >>= 1;
        num >>= 1;
    }
    if (num >= den)
        return 0x10000UL;
    return (num << 16) / den;
}

/* The segment whose setting is in effect: the one running, or held, or
 * about to begin; 0 at rest. */
static const qs_segment *in_effect(qs_engine *e)
{
    if (e->state == QS_STATE_HOLDING)
        return e->held;
    if (e->state != QS_STATE_RUNNING)
        return 0;
    if (e->left)
        return e->seg;
    return qs_queue_empty(&e->queue) ? 0 : qs_queue_front(&e->queue);
}

/* The reference axis's speed now as num/den of the reference speed, read
 * with the tick locked out: a hold's increment (scale 2knD), a quadratic
 * segment's 2n*v(t), a cubic one's advance over the next tick (2^-31 step). */
static void reference_speed(const qs_engine *e, const qs_segment *s, uint8_t axis, uint16_t speed, uint32_t *num,
                            uint32_t *den)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    int32_t v;

    *num = 0;
    *den = 1;
    if (e->state == QS_STATE_HOLDING) {
        if (!(e->hold.moving & bit))
            return;
        v = (int32_t)e->hold.inc[axis];
        *den = ((uint32_t)e->hold.two_c2 >> 12) * speed;
    } else if (!(s->active & bit)) {
        return; /* a segment about to begin reads as at its start */
    } else if (QS_IS_CUBIC(s)) {
        *num = s->c.b[axis] + QS_SIGMA - (uint32_t)(int32_t)s->c.q[axis];
        *den = (uint32_t)speed << 19;
        return;
    } else {
        v = qs_segment_speed_2n(s, axis);
        *den = ((uint32_t)s->two_c2 >> 12) * speed;
    }
    *num = v > 0 ? (uint32_t)v : 0;
}

void qs_outputs_level(const qs_engine *engine, const qs_outputs *outputs, qs_output_level *out)
{
    qs_engine *e = (qs_engine *)engine; /* only read; the queue's accessors are not const */
    qs_output_setting setting;
    uint32_t num = 0, den = 1;
    uint8_t saved = qs_port_lock();
    const qs_segment *s = in_effect(e);

    if (e->state == QS_STATE_ALARM) {
        qs_port_unlock(saved);
        out->pins = 0;
        out->duty = 0;
        return;
    }
    setting = outputs->setting[s ? qs_outputs_carried(s) : outputs->latest];
    if (s && (setting.bits & QS_OUT_DYNAMIC))
        reference_speed(e, s, (uint8_t)(setting.bits >> QS_OUT_AXIS_SHIFT), setting.speed, &num, &den);
    qs_port_unlock(saved);
    out->pins = (uint8_t)(setting.bits & (QS_OUT_ON | QS_OUT_REVERSE | QS_OUT_MIST | QS_OUT_FLOOD));
    if (!(setting.bits & QS_OUT_ON))
        out->duty = 0;
    else if (!(setting.bits & QS_OUT_DYNAMIC))
        out->duty = setting.power;
    else
        out->duty = (uint16_t)(((uint32_t)setting.power * qs_outputs_ratio(num, den)) >> 16);
}
