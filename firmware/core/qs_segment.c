#include "qs_segment.h"
#include "qs_protocol.h"

void qs_segment_prepare(qs_segment *slot, const qs_segment_msg *m)
{
    int32_t n = m->n;
    int32_t c2 = n * QS_D;
    uint8_t axis;

    slot->n = m->n;
    slot->active = m->active;
    slot->negative = m->negative;
    slot->ends_moving = 0;
    slot->two_c2 = (qs_i24)(2 * c2);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        int32_t v0 = m->v0[axis];
        int32_t vn = m->vn[axis];
        int32_t c1 = vn - v0;
        int32_t c3 = c1 + 2 * n * v0 - c2;

        slot->h[axis] = (qs_i24)(n * m->r[axis] + c3);
        slot->b[axis] = (qs_i24)(c3 + 2 * c1 - c2);
        slot->db[axis] = (qs_i24)(2 * c1);
        slot->r[axis] = m->r[axis];
        /* s(n) = floor((r + n*(v0 + vn) + D) / 2D); the numerator is >= 0. */
        slot->total[axis] = (uint16_t)((m->r[axis] + n * (v0 + vn) + QS_D) >> (QS_SPEED_SHIFT + 1));
        if ((m->active & (1u << axis)) && vn > 0)
            slot->ends_moving = 1;
    }
}

/* s(t) = floor((n*r + n*D + t*q) / 2nD) with q = 2n*v0 + C1*t >= 0, the
 * distance covered times 2n/t, read back from b (see qs_segment.h) as
 * q = b + 2nD - C1*(t + 3). t*q needs 34 bits; splitting q at 2^13 keeps
 * every term within 32: floor(x / 2nD) = floor(floor(x / 8192) / n). */
uint16_t qs_segment_steps(const qs_segment *s, uint8_t axis, uint16_t t)
{
    return qs_segment_steps_from(s, axis, t, s->b[axis]);
}

uint16_t qs_segment_steps_from(const qs_segment *s, uint8_t axis, uint16_t t, qs_i24 b)
{
    int32_t n = s->n;
    int32_t c1 = (int32_t)s->db[axis] / 2;
    uint32_t q;
    uint32_t low;

    if (t == 0)
        return 0; /* even at r = 4096, where the formula would say 1 */
    if (t == s->n)
        return s->total[axis];
    q = (uint32_t)((int32_t)b + (int32_t)s->two_c2 - c1 * ((int32_t)t + 3));
    low = (uint32_t)(n * s->r[axis] + n * QS_D) + t * (q & 0x1FFFu);
    return (uint16_t)(((uint32_t)t * (q >> 13) + (low >> 13)) / (uint32_t)n);
}

int32_t qs_segment_speed_2n(const qs_segment *s, uint8_t axis)
{
    int32_t c1 = (int32_t)s->db[axis] / 2;
    return (int32_t)s->b[axis] + (int32_t)s->two_c2 - 3 * c1;
}
