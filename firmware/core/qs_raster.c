#include "qs_raster.h"

#include "qs_port.h"
#include "qs_raster_tick.h"

static uint16_t get16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (uint16_t)p[1] << 8);
}

uint8_t qs_raster_parse(const uint8_t *p, uint8_t len, qs_raster_msg *m)
{
    if (len <= QS_LEN_RASTER_HEAD)
        return QS_ERR_BAD_LENGTH; /* a line without a pixel (a frame caps the rest) */
    m->n = get16(p);
    m->axes = p[2];
    m->pixel = p[3];
    m->phase = get16(p + 4);
    m->pitch = get16(p + 6);
    m->count = (uint8_t)(len - QS_LEN_RASTER_HEAD);
    m->power = p + QS_LEN_RASTER_HEAD;
    return QS_ERR_NONE;
}

static uint8_t bad(qs_fault *f, uint8_t field)
{
    return qs_msg_bad_field(f, field, QS_AXIS_NONE);
}

uint8_t qs_raster_check(const qs_raster_msg *m, const qs_segment_msg *s, qs_fault *f)
{
    const uint8_t axis = m->pixel & 3u;
    const uint16_t v = s->v0[axis];
    uint32_t steps, last;
    uint8_t a;

    /* The pixel axis moves, and no axis steps more often: the boundaries
     * fall on the finest steps of the line. */
    if (m->pixel > 3u || !(s->active & (1u << axis)) || v == 0)
        return bad(f, QS_FIELD_RASTER_AXIS);
    for (a = 0; a < QS_PROTOCOL_AXES; a++)
        if ((s->active & (1u << a)) && s->v0[a] > v)
            return bad(f, QS_FIELD_RASTER_AXIS);
    /* At most a pixel a step; the first boundary a step on and within a
     * pixel; the last one no further than the axis goes: at a steady
     * speed s(n) = floor((r + 2*v*n + D) / 2D) (section 8). */
    if (m->pitch < 256u || m->phase < 256u || m->phase > m->pitch)
        return bad(f, QS_FIELD_PIXELS);
    steps = (uint32_t)((int32_t)s->r[axis] + 2 * (int32_t)v * (int32_t)s->n + QS_D) / (2u * QS_D);
    if (m->count > 1) {
        last = ((uint32_t)m->phase + (uint32_t)(m->count - 2u) * m->pitch) >> 8;
        if (last > steps)
            return bad(f, QS_FIELD_PIXELS);
    }
    return QS_ERR_NONE;
}

#if QS_RASTER_BYTES

uint8_t qs_raster_room(const qs_raster *r, qs_queue *q, uint8_t count)
{
    uint8_t i;

    /* The oldest line still queued holds the ring from its first power. */
    for (i = q->retired; i != q->head; i = qs_queue_next(q, i)) {
        const qs_segment *s = qs_queue_at(q, i);
        if (!QS_IS_CUBIC(s) && (s->ends_moving & QS_SLOT_RASTER)) {
            uint16_t start = s->px.where & 0x3FFu;
            uint16_t used = (uint16_t)((r->write + QS_RASTER_BYTES - start) % QS_RASTER_BYTES);
            return (uint16_t)(QS_RASTER_BYTES - used) >= count;
        }
    }
    return 1;
}

void qs_raster_store(qs_raster *r, qs_segment *slot, const qs_raster_msg *m)
{
    uint8_t k;

    slot->px.where = (uint16_t)(r->write | (uint16_t)m->count << QS_RASTER_WHERE_COUNT_SHIFT);
    slot->px.phase = m->phase;
    slot->px.pitch = m->pitch;
    /* ticks a pixel = n * pitch / (256 * steps), against the PWM's period */
    const uint8_t axis = m->pixel & 3u;
    const uint8_t by_tick = (uint32_t)slot->n * m->pitch
                            >= (uint32_t)qs_port_laser_period_ticks() * 256u * slot->total[axis];

    slot->ends_moving = (uint8_t)(slot->ends_moving | QS_SLOT_RASTER | (uint8_t)(axis << QS_SLOT_RASTER_AXIS_SHIFT)
                                  | (by_tick ? QS_SLOT_RASTER_TICK : 0u));
    for (k = 0; k < m->count; k++) {
        r->power[r->write] = m->power[k];
        r->write = (uint16_t)((r->write + 1u) % QS_RASTER_BYTES);
    }
}

static uint8_t is_raster(const qs_segment *s)
{
    return !QS_IS_CUBIC(s) && (s->ends_moving & QS_SLOT_RASTER);
}

/* A line whose pixels the tick switches. */
static uint8_t by_tick(const qs_segment *s)
{
    return is_raster(s) && (s->ends_moving & QS_SLOT_RASTER_TICK);
}

static void show(const qs_raster *r)
{
    qs_port_laser_power(r->line ? r->power[r->at] : 0);
}

void qs_raster_watch(qs_raster *r, const qs_outputs *o, qs_engine *e)
{
    const qs_segment *s = e->seg;

    if (e->slow_path == QS_PATH_RASTER) {
        e->slow_path = 0; /* the segment's other ticks are a quadratic one's */
        if (e->state == QS_STATE_RUNNING && by_tick(s) && (o->setting[qs_outputs_carried(s)].bits & QS_OUT_ON)) {
            const uint8_t count = (uint8_t)(s->px.where >> QS_RASTER_WHERE_COUNT_SHIFT);
            /* Boundary k (k >= 1) is crossed by the decision that makes
             * the pixel axis's steps reach floor((phase + (k-1)*pitch) /
             * 256); this decision is the line's first. */
            r->line = s;
            r->at = (qs_raster_index)(s->px.where & (QS_RASTER_BYTES - 1u));
            r->boundaries = (uint8_t)(count - 1u);
            r->frac = (uint8_t)s->px.phase;
            r->pitch = s->px.pitch;
            r->togo = (uint16_t)(s->px.phase >> 8);
            r->bit = count > 1 ? (uint8_t)(1u << ((s->ends_moving >> QS_SLOT_RASTER_AXIS_SHIFT) & 3u)) : 0;
            e->line_lit = 1;
            if ((r->stepped & r->bit) && --r->togo == 0)
                qs_raster_cross(r); /* this first decision stepped across it */
            else
                show(r);
            return;
        }
    }
    /* Past the lines (a segment that is none began), or a hold, an alarm
     * or a cubic segment stopped one. */
    if (r->line) {
        r->line = 0;
        r->bit = 0;
        e->line_lit = 0;
        show(r);
    }
}

/* The pixel under the axis after `steps` of its line: the number of
 * boundaries floor((phase + (k-1)*pitch) / 256), k >= 1, at or before it. */
static uint8_t pixel_at(const qs_raster_pixels *px, uint16_t steps)
{
    const uint8_t count = (uint8_t)(px->where >> QS_RASTER_WHERE_COUNT_SHIFT);
    const uint32_t reach = ((uint32_t)steps + 1u) << 8; /* boundary k is passed when phase + (k-1)*pitch < reach */
    uint32_t k;

    if (reach <= px->phase)
        return 0;
    k = (reach - px->phase + px->pitch - 1u) / px->pitch;
    return (uint8_t)(k < count ? k : count - 1u);
}

static uint8_t pixel_axis(const qs_segment *s)
{
    return (uint8_t)((s->ends_moving >> QS_SLOT_RASTER_AXIS_SHIFT) & 3u);
}

/* A line of short pixels: the one under the axis `ahead` ticks on. */
static void look_ahead(const qs_raster *r, qs_engine *e, qs_output_level *out, uint16_t ahead)
{
    const qs_segment *s, *next = 0;
    uint32_t t = 0;
    qs_i24 b;
    uint8_t i, saved;

    saved = qs_port_lock();
    /* the running line, or the next about to begin (at its start) */
    s = e->left ? e->seg : (qs_queue_empty(&e->queue) ? 0 : qs_queue_front(&e->queue));
    if (e->state != QS_STATE_RUNNING || e->trigger_window || !s || !is_raster(s) || by_tick(s)) {
        qs_port_unlock(saved);
        return;
    }
    if (e->left)
        t = (uint16_t)(s->n - e->left);
    else if (e->kept)
        t = s->n; /* it ended moving, nothing behind it yet: at its end */
    i = qs_queue_next(&e->queue, e->queue.tail);
    if (i != e->queue.head)
        next = qs_queue_at(&e->queue, i);
    qs_port_unlock(saved);
    /* only this loop reuses slots: s and next stay what they were */
    t += ahead;
    if (t >= s->n && next) { /* in the segment after the line */
        if (!is_raster(next) || by_tick(next))
            return; /* past the lines: the setting's duty (dark around a row) */
        t -= s->n;
        s = next;
        if (t > s->n)
            t = s->n;
    } else if (t > s->n) {
        return; /* past all that is queued */
    }
    /* a line is a cruise: b never changes, so the steps at any t follow from it */
    b = s->b[pixel_axis(s)];
    out->duty = (uint16_t)(r->power[((s->px.where & 0x3FFu)
                                     + pixel_at(&s->px, t ? qs_segment_steps_from(s, pixel_axis(s), (uint16_t)t, b) : 0))
                                    % QS_RASTER_BYTES]
                           * 257u);
}

void qs_raster_level(const qs_raster *r, qs_engine *e, qs_output_level *out, uint16_t ahead)
{
    uint8_t saved;

    if (!(out->pins & QS_OUT_ON))
        return;
    saved = qs_port_lock();
    if (r->line) {
        out->duty = (uint16_t)(r->power[r->at] * 257u); /* the tick's */
        qs_port_unlock(saved);
        return;
    }
    qs_port_unlock(saved);
    look_ahead(r, e, out, ahead);
}

#endif
