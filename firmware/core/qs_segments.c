#include "qs_segments.h"
#include "qs_protocol.h"
#include "qs_varint.h"

uint8_t qs_segments_next(qs_segments_msg *run, qs_cubic_chain *chain, uint8_t axis_count, qs_segment_msg *s,
                         qs_fault *f)
{
    const uint8_t *p = run->next;
    const uint8_t head = *p++;
    uint8_t axis, bit;

    if (head != QS_RECORD_REPEAT) {
        s->n = (uint16_t)((uint16_t)(head & QS_RECORD_N_HIGH) << 8 | *p++);
        if (head & QS_RECORD_AXES) {
            s->active = *p & 0x0Fu;
            s->negative = (uint8_t)(*p >> 4);
            p++;
        }
    }
    /* the chain has no state for an axis the firmware lacks */
    if (s->active >> axis_count)
        return qs_msg_bad_field(f, QS_FIELD_AXES, QS_AXIS_NONE);
    if (s->negative & (uint8_t)~s->active)
        return qs_msg_bad_field(f, QS_FIELD_DIRECTION, QS_AXIS_NONE);
    for (axis = 0, bit = 1; axis < QS_PROTOCOL_AXES; axis++, bit = (uint8_t)(bit << 1)) {
        uint16_t speed = 0;
        int16_t residual = 0, v0, vn;
        uint8_t known;

        if (!(s->active & bit)) {
            s->v0[axis] = s->vn[axis] = 0;
            s->r[axis] = 0;
            continue;
        }
        known = qs_cubic_quadratic_start(chain, axis, (s->negative & bit) ? 1 : 0, &speed, &residual);
        if (head != QS_RECORD_REPEAT) {
            if (!(known & QS_CHAIN_SPEED))
                return qs_msg_bad_field(f, QS_FIELD_V0, axis);
            v0 = (int16_t)speed;
            if (head & QS_RECORD_START)
                v0 = (int16_t)(v0 + qs_varint_read_signed16(&p));
            if (head & QS_RECORD_RESIDUAL) {
                residual = qs_varint_read_signed16(&p);
                known |= QS_CHAIN_RESIDUAL;
            }
            vn = v0;
            if (!(head & QS_RECORD_CRUISE))
                vn = (int16_t)(vn + qs_varint_read_signed16(&p));
            if (head & QS_RECORD_MIRROR)
                vn = (int16_t)(vn - run->last[axis]);
            if (v0 < 0 || v0 > QS_V_MAX)
                return qs_msg_bad_field(f, QS_FIELD_V0, axis);
            if (vn < 0 || vn > QS_V_MAX)
                return qs_msg_bad_field(f, QS_FIELD_VN, axis);
            s->v0[axis] = (uint16_t)v0;
            s->vn[axis] = (uint16_t)vn;
            if (vn != v0)
                run->last[axis] = (int16_t)(vn - v0);
        }
        if (!(known & QS_CHAIN_RESIDUAL))
            return qs_msg_bad_field(f, QS_FIELD_RESIDUAL, axis);
        s->r[axis] = residual;
    }
    run->next = p;
    return QS_ERR_NONE;
}
