#include "qs_segment.h"
#include "qs_protocol.h"
#include "qs_wide.h"

/* n * v for n <= N_MAX and 0 <= v <= 2 * V_MAX: below 2^23, so 24 bits
 * hold it (the AVR's 8 x 8-bit products, qs_wide.h, not a library call). */
static QS_ALWAYS_INLINE qs_i24 product(uint16_t n, uint16_t v)
{
    return (qs_i24)qs_umul16(n, v);
}

/* One active axis. Every value here stays within +-(2nD + 3D) < 2^23
 * (docs/FIXED_POINT.md), so the AVR computes in 24 bits. */
static QS_ALWAYS_INLINE void prepare_axis(qs_segment *slot, uint8_t axis, uint16_t n, qs_i24 c2, uint16_t v0, uint16_t vn,
                         int16_t r)
{
    const qs_i24 c1 = (int16_t)(vn - v0);
    const qs_i24 nv0 = product(n, v0);
    const qs_i24 c3 = c1 + nv0 + nv0 - c2;
    /* n*r as n*|r| with r's sign: a product of two unsigned values. */
    const qs_i24 nr = r < 0 ? -product(n, (uint16_t)-r) : product(n, (uint16_t)r);
    /* s(n) = floor((r + n*(v0 + vn) + D) / 2D); the numerator is >= 0 and
     * shifted by a whole byte first: a byte move, not a bit loop. */
    const qs_i24 twice_travel = r + nv0 + product(n, vn) + QS_D;

    slot->h[axis] = nr + c3;
    slot->b[axis] = c3 + c1 + c1 - c2;
    slot->db[axis] = c1 + c1;
    slot->r[axis] = r;
    slot->total[axis] = (uint16_t)((uint16_t)(twice_travel >> 8) >> (QS_SPEED_SHIFT + 1 - 8));
    slot->ends_moving |= vn != 0;
    if (vn == v0)
        slot->tick_axes |= (uint8_t)(0x10u << axis);
}

/* The axes one by one with constant indices: fixed offsets into slot and
 * m instead of pointers stepped through a loop. Axes not in active are
 * left as they are: nothing reads them. */
#define PREPARE_AXIS(axis)                                                                    \
    do {                                                                                      \
        if (m->active & (1u << (axis)))                                                       \
            prepare_axis(slot, axis, n, c2, m->v0[axis], m->vn[axis], m->r[axis]);            \
    } while (0)

QS_NOINLINE void qs_segment_prepare(qs_segment *slot, const qs_segment_msg *m)
{
    const uint16_t n = m->n;
    /* n * D, as a byte move after a short shift (n < 2^10) */
    const qs_i24 c2 = (qs_i24)(uint16_t)(n << (QS_SPEED_SHIFT - 8)) << 8;

    slot->n = n;
    slot->active = m->active;
    slot->tick_axes = m->active;
    slot->negative = m->negative;
    slot->ends_moving = 0;
    slot->cubic = 0; /* the slot may have held a cubic segment, or a parked frame */
    slot->two_c2 = c2 + c2;
    PREPARE_AXIS(0);
#if QS_AXIS_COUNT > 1
    PREPARE_AXIS(1);
#endif
#if QS_AXIS_COUNT > 2
    PREPARE_AXIS(2);
#endif
#if QS_AXIS_COUNT > 3
    PREPARE_AXIS(3);
#endif
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
