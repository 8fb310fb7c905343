#include "qs_messages.h"
#include "qs_config.h"
#include "qs_varint.h"

static inline uint16_t get16(const uint8_t *p)
{
    return (uint16_t)(p[0] | ((uint16_t)p[1] << 8));
}

static inline uint32_t get32(const uint8_t *p)
{
    return (uint32_t)get16(p) | ((uint32_t)get16(p + 2) << 16);
}

static uint8_t put16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    return 2;
}

static uint8_t put32(uint8_t *p, uint32_t v)
{
    put16(p, (uint16_t)v);
    put16(p + 2, (uint16_t)(v >> 16));
    return 4;
}

static uint8_t bit_count(uint8_t bits)
{
    uint8_t n = 0;
    for (; bits; bits &= (uint8_t)(bits - 1))
        n++;
    return n;
}

uint8_t qs_msg_parse_empty(uint8_t len)
{
    return len == 0 ? QS_ERR_NONE : QS_ERR_BAD_LENGTH;
}

uint8_t qs_msg_parse_segment(const uint8_t *p, uint8_t len, qs_segment_msg *s)
{
    uint8_t axis, bit;

    if (len < QS_LEN_SEGMENT_HEAD)
        return QS_ERR_BAD_LENGTH;
    s->n = get16(p);
    s->active = p[2] & 0x0F;
    s->negative = (uint8_t)(p[2] >> 4);
    if (len != QS_LEN_SEGMENT_HEAD + QS_LEN_SEGMENT_AXIS * bit_count(s->active))
        return QS_ERR_BAD_LENGTH;
    p += QS_LEN_SEGMENT_HEAD;
    /* A walking bit rather than 1 << axis: the AVR shifts by a variable
     * count in a loop. */
    for (axis = 0, bit = 1; axis < QS_PROTOCOL_AXES; axis++, bit = (uint8_t)(bit << 1)) {
        if (s->active & bit) {
            s->v0[axis] = get16(p);
            s->vn[axis] = get16(p + 2);
            s->r[axis] = (int16_t)get16(p + 4);
            p += QS_LEN_SEGMENT_AXIS;
        } else {
            s->v0[axis] = 0;
            s->vn[axis] = 0;
            s->r[axis] = 0;
        }
    }
    return QS_ERR_NONE;
}

/* Every record whole: a head (not MIRROR with CRUISE; REPEAT alone, never first), n's
 * low byte, the axes byte where flagged (the first record must have one),
 * then per active axis one varint for each of START, RESIDUAL and, unless
 * CRUISE, vn; a varint is one byte below 0x80 or two with the second below
 * 0x80. */
QS_NOINLINE uint8_t qs_msg_parse_segments(const uint8_t *p, uint8_t len, qs_segments_msg *s)
{
    const uint8_t *const end = p + len;
    uint8_t axes = 0, count = 0;

    s->next = p;
    s->last[0] = s->last[1] = s->last[2] = s->last[3] = 0;
    while (p != end) {
        const uint8_t head = *p++;
        uint8_t fields;

        if (count == QS_SEGMENTS_MAX || (head & (QS_RECORD_MIRROR | QS_RECORD_CRUISE)) == (QS_RECORD_MIRROR | QS_RECORD_CRUISE))
            return QS_ERR_BAD_LENGTH;
        count++;
        if (head & QS_RECORD_REPEAT) {
            if (head != QS_RECORD_REPEAT || count == 1)
                return QS_ERR_BAD_LENGTH;
            continue;
        }
        if (p == end)
            return QS_ERR_BAD_LENGTH;
        p++; /* n's low byte */
        if (head & QS_RECORD_AXES) {
            if (p == end)
                return QS_ERR_BAD_LENGTH;
            axes = *p++;
        } else if (count == 1) {
            return QS_ERR_BAD_LENGTH;
        }
        fields = (uint8_t)(((head & QS_RECORD_START) ? 1 : 0) + ((head & QS_RECORD_RESIDUAL) ? 1 : 0)
                           + ((head & QS_RECORD_CRUISE) ? 0 : 1));
        fields = (uint8_t)(fields * bit_count(axes & 0x0Fu));
        while (fields--)
            if (!(p = qs_varint_skip(p, end, 2)))
                return QS_ERR_BAD_LENGTH;
    }
    if (count == 0)
        return QS_ERR_BAD_LENGTH;
    s->count = count;
    return QS_ERR_NONE;
}

/* Every cubic record whole: its jerks byte, n*4 + flags in at most 3 bytes,
 * the sets byte where flagged, per set axis a speed (at most 5 bytes, the
 * fifth below 0x10: under 2^32 in all) and, with ACCEL, an acceleration
 * (at most 4), then per axis whose jerk is given a varint (at most 3). */
QS_NOINLINE uint8_t qs_msg_parse_cubic_segments(const uint8_t *p, uint8_t len, qs_segments_msg *s)
{
    const uint8_t *const end = p + len;
    uint8_t count = 0;

    s->next = p;
    s->last[0] = s->last[1] = s->last[2] = s->last[3] = 0;
    while (p != end) {
        uint8_t jerks = *p++, flags, fields;

        if (count == QS_SEGMENTS_MAX)
            return QS_ERR_BAD_LENGTH;
        count++;
        if (p == end)
            return QS_ERR_BAD_LENGTH;
        flags = *p;
        p = qs_varint_skip(p, end, 3);
        if (!p)
            return QS_ERR_BAD_LENGTH;
        if (flags & QS_CUBIC_RECORD_SETS) {
            if (p == end)
                return QS_ERR_BAD_LENGTH;
            fields = bit_count(*p++ & 0x0Fu);
            while (fields--) {
                const uint8_t *speed = p;

                p = qs_varint_skip(p, end, 5);
                if (!p || (p - speed == 5 && p[-1] > 0x0Fu))
                    return QS_ERR_BAD_LENGTH;
                if ((flags & QS_CUBIC_RECORD_ACCEL) && !(p = qs_varint_skip(p, end, 4)))
                    return QS_ERR_BAD_LENGTH;
            }
        }
        for (fields = 0; fields < QS_PROTOCOL_AXES; fields++, jerks >>= 2)
            if ((jerks & 3u) == QS_CUBIC_JERK_GIVEN && !(p = qs_varint_skip(p, end, 3)))
                return QS_ERR_BAD_LENGTH;
    }
    if (count == 0)
        return QS_ERR_BAD_LENGTH;
    s->count = count;
    return QS_ERR_NONE;
}

uint8_t qs_msg_parse_cubic(const uint8_t *p, uint8_t len, qs_cubic_msg *c)
{
    uint8_t axis, bit, need;

    if (len < QS_LEN_CUBIC_SEGMENT_HEAD)
        return QS_ERR_BAD_LENGTH;
    c->n = get16(p);
    c->jerk = p[2] & 0x0F;
    c->set = (uint8_t)(p[2] >> 4);
    need = (uint8_t)(QS_LEN_CUBIC_SEGMENT_HEAD + QS_LEN_CUBIC_SEGMENT_SET * bit_count(c->set)
                     + QS_LEN_CUBIC_SEGMENT_JERK * bit_count(c->jerk));
    if (len != need)
        return QS_ERR_BAD_LENGTH;
    p += QS_LEN_CUBIC_SEGMENT_HEAD;
    c->negative = 0;
    for (axis = 0, bit = 1; axis < QS_PROTOCOL_AXES; axis++, bit = (uint8_t)(bit << 1)) {
        c->speed[axis] = 0;
        c->accel[axis] = 0;
        c->r[axis] = 0;
        if (c->set & bit) {
            uint32_t v = get32(p);
            /* bit 31: the direction; accel: 24 bits, sign-extended */
            c->speed[axis] = v & 0x7FFFFFFFUL;
            if (v & 0x80000000UL)
                c->negative |= bit;
            c->accel[axis] = (int32_t)((uint32_t)get16(p + 4) | ((uint32_t)p[6] << 16) | (p[6] & 0x80 ? 0xFF000000UL : 0));
            p += QS_LEN_CUBIC_SEGMENT_SET;
        }
        if (c->jerk & bit) {
            c->r[axis] = (int16_t)get16(p);
            p += QS_LEN_CUBIC_SEGMENT_JERK;
        }
    }
    return QS_ERR_NONE;
}

uint8_t qs_msg_parse_set_position(const uint8_t *p, uint8_t len, qs_set_position_msg *sp)
{
    uint8_t axis;

    if (len < QS_LEN_SET_POSITION_HEAD
        || len != QS_LEN_SET_POSITION_HEAD + QS_LEN_SET_POSITION_AXIS * bit_count(p[0]))
        return QS_ERR_BAD_LENGTH;
    sp->mask = p[0];
    p += QS_LEN_SET_POSITION_HEAD;
    for (axis = 0; axis < 8; axis++) {
        if (!(sp->mask & (1u << axis)))
            continue;
        /* Bits above the wire's axes are refused by the content check. */
        if (axis < QS_PROTOCOL_AXES)
            sp->position[axis] = (int32_t)get32(p);
        p += QS_LEN_SET_POSITION_AXIS;
    }
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
        if (!(sp->mask & (1u << axis)))
            sp->position[axis] = 0;
    return QS_ERR_NONE;
}

uint8_t qs_msg_parse_hold(const uint8_t *p, uint8_t len, qs_hold_msg *h)
{
    uint8_t axis;

    if (len != QS_LEN_HOLD)
        return QS_ERR_BAD_LENGTH;
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
        h->decel[axis] = get16(p + 2 * axis);
    return QS_ERR_NONE;
}

uint8_t qs_msg_parse_hold_along(const uint8_t *p, uint8_t len, qs_hold_along_msg *h)
{
    if (len != QS_LEN_HOLD_ALONG)
        return QS_ERR_BAD_LENGTH;
    qs_msg_parse_hold(p, QS_LEN_HOLD, &h->hold);
    qs_msg_parse_hold(p + QS_LEN_HOLD, QS_LEN_HOLD, &h->path.hold);
    h->path.first = get16(p + 2 * QS_LEN_HOLD);
    h->path.last = get16(p + 2 * QS_LEN_HOLD + 2);
    return QS_ERR_NONE;
}

uint8_t qs_msg_parse_probe(const uint8_t *p, uint8_t len, qs_probe_msg *pr)
{
    if (len != QS_LEN_PROBE)
        return QS_ERR_BAD_LENGTH;
    pr->input = p[0];
    pr->level = p[1];
    return qs_msg_parse_hold(p + 2, QS_LEN_HOLD, &pr->hold);
}

uint8_t qs_msg_parse_config(const uint8_t *p, uint8_t len, qs_config_msg *cf)
{
    uint8_t i;

    if (len != QS_LEN_CONFIG)
        return QS_ERR_BAD_LENGTH;
    cf->invert = get16(p);
    cf->enabled = get16(p + 2);
    cf->hard_limits = p[4];
    for (i = 0; i < QS_WIRE_INPUTS; i++)
        cf->debounce[i] = p[5 + i];
    return qs_msg_parse_hold(p + 5 + QS_WIRE_INPUTS, QS_LEN_HOLD, &cf->hold);
}

uint8_t qs_msg_parse_outputs(const uint8_t *p, uint8_t len, qs_outputs_msg *o)
{
    if (len != QS_LEN_OUTPUTS)
        return QS_ERR_BAD_LENGTH;
    o->outputs = p[0];
    o->power = get16(p + 1);
    o->axis = p[3];
    o->speed = get16(p + 4);
    return QS_ERR_NONE;
}

uint8_t qs_msg_bad_field(qs_fault *f, uint8_t field, uint8_t axis)
{
    f->code = QS_ERR_BAD_FIELD;
    f->field = field;
    f->axis = axis;
    return QS_ERR_BAD_FIELD;
}

static uint8_t axes_beyond(uint8_t axis_count)
{
    return (uint8_t)(0xFFu << axis_count);
}

/* Whether one active axis's fields are all within their ranges. At
 * r = 4096 with both speeds 4096 the stepper would need two steps in the
 * first tick. */
static uint8_t axis_fields_valid(uint16_t v0, uint16_t vn, int16_t r)
{
    return v0 <= QS_V_MAX && vn <= QS_V_MAX && r >= -QS_R_MAX && r <= QS_R_MAX
           && !(r == QS_R_MAX && v0 == QS_V_MAX && vn == QS_V_MAX);
}

/* Which field to name when some axis is out of range: field by field as
 * in the table, each in axis order. */
static uint8_t name_bad_field(const qs_segment_msg *s, qs_fault *f)
{
    uint8_t axis;

    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
        if ((s->active & (1u << axis)) && s->v0[axis] > QS_V_MAX)
            return qs_msg_bad_field(f, QS_FIELD_V0, axis);
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
        if ((s->active & (1u << axis)) && s->vn[axis] > QS_V_MAX)
            return qs_msg_bad_field(f, QS_FIELD_VN, axis);
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
        if ((s->active & (1u << axis)) && !axis_fields_valid(s->v0[axis], s->vn[axis], s->r[axis]))
            return qs_msg_bad_field(f, QS_FIELD_RESIDUAL, axis);
    return QS_ERR_NONE; /* not reached: some axis was invalid */
}

QS_NOINLINE uint8_t qs_msg_check_segment(const qs_segment_msg *s, uint8_t axis_count, qs_fault *f)
{
    uint8_t axis, bit;

    if (s->n < 1 || s->n > QS_N_MAX)
        return qs_msg_bad_field(f, QS_FIELD_N, QS_AXIS_NONE);
    if (s->active & axes_beyond(axis_count))
        return qs_msg_bad_field(f, QS_FIELD_AXES, QS_AXIS_NONE);
    if (s->negative & (uint8_t)~s->active)
        return qs_msg_bad_field(f, QS_FIELD_DIRECTION, QS_AXIS_NONE);
    /* One pass for the usual case, a valid segment (a walking bit, as in
     * parse_segment). */
    for (axis = 0, bit = 1; axis < QS_PROTOCOL_AXES; axis++, bit = (uint8_t)(bit << 1))
        if ((s->active & bit) && !axis_fields_valid(s->v0[axis], s->vn[axis], s->r[axis]))
            return name_bad_field(s, f);
    f->code = QS_ERR_NONE;
    return QS_ERR_NONE;
}

uint8_t qs_msg_check_set_position(const qs_set_position_msg *p, uint8_t axis_count, qs_fault *f)
{
    uint8_t axis;

    if (p->mask & axes_beyond(axis_count))
        return qs_msg_bad_field(f, QS_FIELD_AXES, QS_AXIS_NONE);
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
        if ((p->mask & (1u << axis)) && (p->position[axis] > QS_POSITION_MAX || p->position[axis] < -QS_POSITION_MAX))
            return qs_msg_bad_field(f, QS_FIELD_POSITION, axis);
    f->code = QS_ERR_NONE;
    return QS_ERR_NONE;
}

uint8_t qs_msg_parse_watchdog(const uint8_t *p, uint8_t len, qs_watchdog_msg *w)
{
    if (len != QS_LEN_WATCHDOG)
        return QS_ERR_BAD_LENGTH;
    w->timeout_ms = get16(p);
    return QS_ERR_NONE;
}

uint8_t qs_msg_check_watchdog(const qs_watchdog_msg *w, qs_fault *f)
{
    if (w->timeout_ms > QS_WATCHDOG_MAX_MS)
        return qs_msg_bad_field(f, QS_FIELD_TIMEOUT, QS_AXIS_NONE);
    f->code = QS_ERR_NONE;
    return QS_ERR_NONE;
}

/* Axes the firmware has need a deceleration it can apply; the others must
 * say 0, so that a HOLD meant for another machine is not half obeyed. */
uint8_t qs_msg_check_hold(const qs_hold_msg *h, uint8_t axis_count, qs_fault *f)
{
    uint8_t axis;

    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
        uint16_t d = h->decel[axis];
        if (axis < axis_count ? (d < 1 || d > QS_DECEL_MAX) : d != 0)
            return qs_msg_bad_field(f, QS_FIELD_DECEL, axis);
    }
    f->code = QS_ERR_NONE;
    return QS_ERR_NONE;
}

/* Only an input that can end a motion (a limit or the probe) the firmware
 * has; then the level and the hold's decelerations. */
uint8_t qs_msg_check_probe(const qs_probe_msg *pr, uint8_t axis_count, uint16_t present, qs_fault *f)
{
    if (pr->input > QS_INPUT_PROBE || !((present >> pr->input) & 1u))
        return qs_msg_bad_field(f, QS_FIELD_INPUT, QS_AXIS_NONE);
    if (pr->level > 1)
        return qs_msg_bad_field(f, QS_FIELD_LEVEL, QS_AXIS_NONE);
    return qs_msg_check_hold(&pr->hold, axis_count, f);
}

/* Bits for inputs the wire names (absent ones are ignored), hard limits
 * on or off, and the feed hold's decelerations as HOLD's. */
uint8_t qs_msg_check_config(const qs_config_msg *cf, uint8_t axis_count, qs_fault *f)
{
    const uint16_t beyond = (uint16_t)~((1u << QS_WIRE_INPUTS) - 1u);

    if ((cf->invert | cf->enabled) & beyond)
        return qs_msg_bad_field(f, QS_FIELD_INPUTS, QS_AXIS_NONE);
    if (cf->hard_limits > 1)
        return qs_msg_bad_field(f, QS_FIELD_HARD_LIMITS, QS_AXIS_NONE);
    return qs_msg_check_hold(&cf->hold, axis_count, f);
}

/* A power that follows a speed names an axis the firmware has and a speed
 * it can reach; any other names none. */
uint8_t qs_msg_check_outputs(const qs_outputs_msg *o, uint8_t axis_count, qs_fault *f)
{
    if (o->outputs & (uint8_t)~QS_OUT_BITS)
        return qs_msg_bad_field(f, QS_FIELD_OUTPUTS, QS_AXIS_NONE);
    if (o->outputs & QS_OUT_DYNAMIC) {
        if (o->axis >= axis_count)
            return qs_msg_bad_field(f, QS_FIELD_REFERENCE, o->axis);
        if (o->speed == 0 || o->speed > QS_D)
            return qs_msg_bad_field(f, QS_FIELD_REFERENCE, o->axis);
    } else if (o->axis != 0 || o->speed != 0) {
        return qs_msg_bad_field(f, QS_FIELD_REFERENCE, QS_AXIS_NONE);
    }
    return QS_ERR_NONE;
}

static uint8_t head(uint8_t *body, uint8_t type, uint8_t seq)
{
    body[0] = type;
    body[1] = seq;
    return 2;
}

uint8_t qs_msg_encode_ack(uint8_t *body, uint8_t seq, const qs_ack *a)
{
    uint8_t n = head(body, QS_TYPE_ACK, seq);
    body[n++] = a->next_seq;
    body[n++] = a->free;
    body[n++] = a->reason;
    n += put16(body + n, a->done);
    return n;
}

uint8_t qs_msg_encode_identify_reply(uint8_t *body, uint8_t seq, const qs_identity *id)
{
    uint8_t n = head(body, QS_TYPE_IDENTIFY_REPLY, seq);
    body[n++] = id->protocol_version;
    body[n++] = id->fw_major;
    body[n++] = id->fw_minor;
    body[n++] = id->fw_patch;
    body[n++] = id->board;
    body[n++] = id->axis_count;
    body[n++] = id->queue_capacity;
    body[n++] = id->speed_shift;
    n += put16(body + n, id->n_max);
    n += put32(body + n, id->tick_hz);
    n += put16(body + n, id->capabilities);
    body[n++] = id->next_seq;
    n += put16(body + n, id->boot_id);
    n += put16(body + n, id->raster_ring);
    return n;
}

uint8_t qs_msg_encode_status_report(uint8_t *body, uint8_t seq, const qs_status *st)
{
    uint8_t n = head(body, QS_TYPE_STATUS_REPORT, seq);
    uint8_t axis;

    body[n++] = st->state;
    body[n++] = st->alarm;
    body[n++] = st->queue_fill;
    body[n++] = st->next_seq;
    n += put32(body + n, st->segments_done);
    n += put32(body + n, st->motion_ticks);
    n += put16(body + n, st->counters.rx_overrun);
    n += put16(body + n, st->counters.bad_frame);
    n += put16(body + n, st->counters.bad_crc);
    n += put16(body + n, st->counters.seq_gap);
    n += put16(body + n, st->counters.seq_dup);
    n += put16(body + n, st->counters.rejected);
    for (axis = 0; axis < st->axis_count; axis++)
        n += put32(body + n, (uint32_t)st->position[axis]);
    return n;
}

uint8_t qs_msg_encode_error(uint8_t *body, uint8_t seq, const qs_error_report *e)
{
    uint8_t n = head(body, QS_TYPE_ERROR, seq);
    body[n++] = e->code;
    body[n++] = e->type;
    body[n++] = e->seq;
    body[n++] = e->field;
    body[n++] = e->axis;
    return n;
}

uint8_t qs_msg_encode_alarm(uint8_t *body, uint8_t seq, const qs_alarm_report *a)
{
    uint8_t n = head(body, QS_TYPE_ALARM, seq);
    uint8_t axis;

    body[n++] = a->code;
    n += put32(body + n, a->motion_ticks);
    for (axis = 0; axis < a->axis_count; axis++)
        n += put32(body + n, (uint32_t)a->position[axis]);
    return n;
}

uint8_t qs_msg_encode_hold_done(uint8_t *body, uint8_t seq, uint8_t kind, uint32_t hold_tick,
                                uint32_t motion_ticks, uint8_t axis_count, const int32_t *position)
{
    uint8_t n = head(body, QS_TYPE_EVENT, seq);
    uint8_t axis;

    body[n++] = kind;
    n += put32(body + n, hold_tick);
    n += put32(body + n, motion_ticks);
    for (axis = 0; axis < axis_count; axis++)
        n += put32(body + n, (uint32_t)position[axis]);
    return n;
}

uint8_t qs_msg_encode_input_status(uint8_t *body, uint8_t seq, const qs_input_status *st)
{
    uint8_t n = head(body, QS_TYPE_INPUT_STATUS, seq);

    n += put16(body + n, st->present);
    n += put16(body + n, st->active);
    n += put16(body + n, st->raw);
    n += put16(body + n, st->invert);
    n += put16(body + n, st->enabled);
    body[n++] = st->hard_limits;
    body[n++] = st->armed;
    body[n++] = st->level;
    n += put16(body + n, st->latches_lost);
    return n;
}

uint8_t qs_msg_encode_input_event(uint8_t *body, uint8_t seq, uint32_t motion_ticks, uint16_t active,
                                  uint16_t changed, uint8_t cause, uint8_t axis_count, const int32_t *position)
{
    uint8_t n = head(body, QS_TYPE_EVENT, seq);
    uint8_t axis;

    body[n++] = QS_EVENT_INPUT;
    n += put32(body + n, motion_ticks);
    n += put16(body + n, active);
    n += put16(body + n, changed);
    body[n++] = cause;
    for (axis = 0; axis < axis_count; axis++)
        n += put32(body + n, (uint32_t)position[axis]);
    return n;
}

uint8_t qs_msg_encode_probe_missed(uint8_t *body, uint8_t seq, uint32_t motion_ticks, uint8_t axis_count,
                                   const int32_t *position)
{
    uint8_t n = head(body, QS_TYPE_EVENT, seq);
    uint8_t axis;

    body[n++] = QS_EVENT_PROBE_MISSED;
    n += put32(body + n, motion_ticks);
    for (axis = 0; axis < axis_count; axis++)
        n += put32(body + n, (uint32_t)position[axis]);
    return n;
}
