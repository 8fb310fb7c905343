#include "qs_cubic_records.h"
#include "qs_protocol.h"
#include "qs_varint.h"

uint8_t qs_cubic_records_next(qs_segments_msg *run, qs_cubic_chain *chain, uint8_t axis_count, qs_cubic_msg *m,
                              qs_fault *f)
{
    const uint8_t *p = run->next;
    const uint8_t jerks = *p++;
    const uint32_t head = qs_varint_read(&p);
    uint8_t sets = 0, named = 0, axis, bit, code;

    if (head < 4 || head >> 2 > QS_CUBIC_N_MAX)
        return qs_msg_bad_field(f, QS_FIELD_N, QS_AXIS_NONE);
    m->n = (uint16_t)(head >> 2);
    if (head & QS_CUBIC_RECORD_SETS)
        sets = *p++;
    for (axis = 0, code = jerks; axis < QS_PROTOCOL_AXES; axis++, code >>= 2)
        if (code & 3u)
            named |= (uint8_t)(1u << axis);
    m->jerk = named;
    m->set = sets & 0x0Fu;
    m->negative = (uint8_t)(sets >> 4);
    /* the chain has no state for an axis the firmware lacks */
    if ((named | m->set) >> axis_count)
        return qs_msg_bad_field(f, QS_FIELD_AXES, QS_AXIS_NONE);
    if (m->negative & (uint8_t)~m->set)
        return qs_msg_bad_field(f, QS_FIELD_DIRECTION, QS_AXIS_NONE);
    for (axis = 0, bit = 1; axis < QS_PROTOCOL_AXES; axis++, bit = (uint8_t)(bit << 1)) {
        m->speed[axis] = 0;
        m->accel[axis] = 0;
        if (m->set & bit) {
            /* the chain's speed, taken in the set's direction, plus the change */
            uint32_t base;
            uint8_t negative;
            const int32_t change = qs_varint_read_signed(&p);

            base = qs_cubic_speed(chain, axis, &negative);
            if (base > QS_SIGMA)
                return qs_msg_bad_field(f, QS_FIELD_SPEED, axis);
            if (negative != ((m->negative & bit) ? 1u : 0u)) {
                /* reversed: change - base */
                if (change < 0 || (uint32_t)change < base)
                    return qs_msg_bad_field(f, QS_FIELD_SPEED, axis);
                base = (uint32_t)change - base;
            } else if (change < 0) {
                const uint32_t less = 0u - (uint32_t)change;

                if (base < less)
                    return qs_msg_bad_field(f, QS_FIELD_SPEED, axis);
                base -= less;
            } else {
                base += (uint32_t)change;
            }
            if (base >= QS_SIGMA)
                return qs_msg_bad_field(f, QS_FIELD_SPEED, axis);
            m->speed[axis] = base;
            if (head & QS_CUBIC_RECORD_ACCEL)
                m->accel[axis] = qs_varint_read_signed(&p);
        }
    }
    for (axis = 0, code = jerks; axis < QS_PROTOCOL_AXES; axis++, code >>= 2) {
        int32_t r = 0;

        switch (code & 3u) {
        case QS_CUBIC_JERK_GIVEN:
            r = qs_varint_read_signed(&p);
            break;
        case QS_CUBIC_JERK_NEGATE:
            r = -(int32_t)run->last[axis];
            break;
        case QS_CUBIC_JERK_SAME:
            r = run->last[axis];
            break;
        default:
            break;
        }
        if (r < -32768L || r > 32767L)
            return qs_msg_bad_field(f, QS_FIELD_JERK, axis);
        if (code & 3u)
            run->last[axis] = (int16_t)r;
        m->r[axis] = (int16_t)r;
    }
    run->next = p;
    return QS_ERR_NONE;
}
