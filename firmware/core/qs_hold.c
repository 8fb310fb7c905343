#include "qs_hold.h"
#include "qs_protocol.h"

/* floor(2*kn*D * decel * 2^-24) = (kn * decel) >> 11 */
#define DB_SHIFT (QS_DECEL_SHIFT - QS_SPEED_SHIFT - 1)

uint8_t qs_hold_shift(uint16_t n)
{
    uint8_t shift = 0;

    while ((uint16_t)(n << (shift + 1)) <= QS_N_MAX)
        shift++;
    return shift;
}

qs_i24 qs_hold_db(uint16_t kn, uint16_t decel)
{
    uint16_t quanta = (uint16_t)(((uint32_t)kn * decel) >> DB_SHIFT);

    /* A deceleration below one quantum would never stop the axis. */
    return quanta ? -(qs_i24)quanta : -1;
}

void qs_hold_plan(qs_hold *hd, uint16_t n, const uint16_t *decel)
{
    uint8_t shift = qs_hold_shift(n);
    uint16_t kn = (uint16_t)(n << shift);
    uint8_t axis;

    hd->shift = shift;
    hd->two_c2 = (qs_i24)2 * kn * QS_D;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        hd->db[axis] = qs_hold_db(kn, decel[axis]);
        hd->steps[axis] = 0;
    }
    hd->ticks = 0;
    hd->planned_n = n;
}

/* x * 2^shift, for a result known to fit: shifted as unsigned, since x may
 * be negative; a shift by 8 is a byte move, the rest a short loop. */
static QS_ALWAYS_INLINE qs_i24 scaled(qs_i24 x, uint8_t shift)
{
    qs_u24 u = (qs_u24)x;

    if (shift & 8)
        u <<= 8;
    return (qs_i24)(u << (shift & 7));
}

/* One axis; constant axis numbers keep this short, under the lock. */
static QS_ALWAYS_INLINE uint8_t begin_axis(qs_hold *hd, const qs_segment *s, uint8_t axis)
{
    qs_i24 next;

    if (!(s->active & (1u << axis)))
        return 0;
    /* The increment over the tick of the next decision: b as it was before
     * the last decision, plus 2nD. */
    next = s->b[axis] - s->db[axis] + s->two_c2;
    if (next <= 0)
        return 0;
    hd->h[axis] = scaled(s->h[axis], hd->shift);
    hd->inc[axis] = scaled(next, hd->shift) + hd->db[axis];
    return (uint8_t)(1u << axis);
}

uint8_t qs_hold_begin(qs_hold *hd, const qs_segment *s)
{
    uint8_t moving = begin_axis(hd, s, 0);

#if QS_AXIS_COUNT > 1
    moving |= begin_axis(hd, s, 1);
#endif
#if QS_AXIS_COUNT > 2
    moving |= begin_axis(hd, s, 2);
#endif
#if QS_AXIS_COUNT > 3
    moving |= begin_axis(hd, s, 3);
#endif
    return moving;
}
