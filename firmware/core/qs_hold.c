#include "qs_hold.h"
#include "qs_cubic.h"
#include "qs_protocol.h"

/* floor(2*kn*D * decel * 2^-24) = (kn * decel) >> 11 */
#define DB_SHIFT (QS_DECEL_SHIFT - QS_SPEED_SHIFT - 1)

/* Shifts by constants only: the AVR shifts by a variable count in a loop,
 * and an armed PROBE plans in the tick. */
uint8_t qs_hold_shift(uint16_t n)
{
    uint8_t shift = 0;

    while ((uint16_t)(n << 1) <= QS_N_MAX) {
        n = (uint16_t)(n << 1);
        shift++;
    }
    return shift;
}

qs_i24 qs_hold_db(uint16_t kn, uint16_t decel)
{
    /* kn * decel < 2^24: the product's middle bytes, then the last 3 bits. */
    uint16_t quanta = (uint16_t)((uint16_t)(((uint32_t)kn * decel) >> 8) >> (DB_SHIFT - 8));

    /* A deceleration below one quantum would never stop the axis. */
    return quanta ? -(qs_i24)quanta : -1;
}

void qs_hold_plan(qs_hold *hd, uint16_t n, const uint16_t *decel)
{
    uint8_t shift = qs_hold_shift(n);
    uint16_t kn = (uint16_t)(n << shift);
    uint8_t axis;

    hd->shift = shift;
    hd->bits_k = (uint8_t)(1u << (shift & 7));
    hd->two_c2 = (qs_i24)(uint16_t)(kn << (QS_SPEED_SHIFT + 1 - 8)) << 8; /* 2knD: a short shift, a byte move */
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        hd->db[axis] = qs_hold_db(kn, decel[axis]);
        hd->steps[axis] = 0;
    }
    hd->ticks = 0;
    hd->planned_n = n;
    hd->predicted_slot = 0;
}

/* x * 2^shift, for a result known to fit, with x moved up a byte already
 * when shift >= 8 (a byte move) and k = 2^(shift mod 8): three 8 x 8 -> 16
 * bit products (one instruction each on the AVR), added byte by byte,
 * where a shift loop would take up to 7 rounds under the lock that begins
 * a hold, whose length delays a tick that falls due meanwhile. Worked on
 * the 24-bit pattern, unsigned (x may be negative): the result fits. */
static QS_ALWAYS_INLINE qs_i24 times_k(qs_u24 u, uint8_t k)
{
    const uint16_t lo = (uint16_t)((uint16_t)(uint8_t)u * k);
    const uint16_t mid = (uint16_t)((uint16_t)(uint8_t)(u >> 8) * k);
    const uint8_t hi = (uint8_t)((uint8_t)(u >> 16) * k); /* its low byte is all that counts */
    const uint16_t byte1 = (uint16_t)((lo >> 8) + (uint8_t)mid);
    const uint8_t byte2 = (uint8_t)((mid >> 8) + hi + (byte1 >> 8));

    return qs_i24_from_bits((qs_u24)(uint8_t)lo | ((qs_u24)(uint8_t)byte1 << 8) | ((qs_u24)byte2 << 16));
}

/* x * 2^shift, for a result known to fit: a byte move when shift >= 8,
 * then times k = 2^(shift mod 8). */
static QS_ALWAYS_INLINE qs_i24 scaled(qs_i24 x, uint8_t bytes, uint8_t k)
{
    qs_u24 u = (qs_u24)x;

    if (bytes)
        u <<= 8;
    /* n >= 512, or n = 2 or 3 (a byte move): no multiply */
    return k == 1 ? (qs_i24)u : times_k(u, k);
}

/* One axis; constant axis numbers keep this short, under the lock. */
static QS_ALWAYS_INLINE uint8_t begin_axis(qs_hold *hd, const qs_segment *s, uint8_t axis, uint8_t bytes,
                                          uint8_t k, uint8_t at_end)
{
    /* The increment over the tick of the next decision: b as it was before
     * the last decision, plus 2nD. After the segment's end the quadratic
     * would go on accelerating (past one step a tick, near the top speed):
     * the hold's first tick runs at the end speed instead, 2n*vn, which is
     * C1 = db/2 less, and h, which holds that increment already, too. */
    qs_i24 past, next;

    if (!(s->active & (1u << axis)))
        return 0; /* its fields are whatever the slot held before: never read */
    past = at_end ? s->db[axis] / 2 : 0;
    next = s->b[axis] - s->db[axis] + s->two_c2 - past;
    if (next <= 0)
        return 0;
    hd->h[axis] = scaled(s->h[axis] - past, bytes, k);
    hd->inc[axis] = scaled(next, bytes, k) + hd->db[axis];
    return (uint8_t)(1u << axis);
}

/* A cubic axis (qs_cubic.h): the increment over the next tick is
 * I(t+1) = b - q + Sigma and the ideal is e = h - I(t+1) + Sigma/2 ahead;
 * both, floored to the hold's scale 2^22, start it. */
static QS_ALWAYS_INLINE uint8_t begin_cubic_axis(qs_hold *hd, const qs_segment *s, uint8_t axis,
                                                uint8_t at_end)
{
    const uint32_t next = s->c.b[axis] - (uint32_t)(int32_t)s->c.q[axis] + QS_SIGMA;
    const int32_t e = (int32_t)(s->c.h[axis] - next + QS_HALF_SIGMA);
    /* After the end, I(n+1) was never checked against one step a tick: the
     * last tick's advance I(n) = I(n+1) - (q - r) starts the hold instead. */
    const uint32_t first = at_end ? next - (uint32_t)(int32_t)(s->c.q[axis] - s->c.r[axis]) : next;
    const qs_i24 i1 = (qs_i24)(first >> QS_HOLD_CUBIC_SHIFT);

    if (!(s->active & (1u << axis)) || i1 <= 0)
        return 0;
    hd->h[axis] = (qs_i24)(e >> QS_HOLD_CUBIC_SHIFT) + i1 - ((qs_i24)QS_HOLD_CUBIC_N * QS_D);
    hd->inc[axis] = i1 + hd->db[axis];
    return (uint8_t)(1u << axis);
}

static QS_NOINLINE uint8_t begin_cubic(qs_hold *hd, const qs_segment *s, uint8_t at_end)
{
    uint8_t moving = begin_cubic_axis(hd, s, 0, at_end);

#if QS_AXIS_COUNT > 1
    moving |= begin_cubic_axis(hd, s, 1, at_end);
#endif
#if QS_AXIS_COUNT > 2
    moving |= begin_cubic_axis(hd, s, 2, at_end);
#endif
#if QS_AXIS_COUNT > 3
    moving |= begin_cubic_axis(hd, s, 3, at_end);
#endif
    return moving;
}

/* After all n ticks of a segment (a hold at its end) the increment is the
 * end speed's; out of line, so the usual hold's code stays as short. */
static QS_NOINLINE uint8_t begin_at_end(qs_hold *hd, const qs_segment *s)
{
    const uint8_t bytes = hd->shift & 8, k = hd->bits_k;
    uint8_t moving = begin_axis(hd, s, 0, bytes, k, 1);

#if QS_AXIS_COUNT > 1
    moving |= begin_axis(hd, s, 1, bytes, k, 1);
#endif
#if QS_AXIS_COUNT > 2
    moving |= begin_axis(hd, s, 2, bytes, k, 1);
#endif
#if QS_AXIS_COUNT > 3
    moving |= begin_axis(hd, s, 3, bytes, k, 1);
#endif
    return moving;
}

/* One axis's increment `decisions` on: b then is b + decisions * db
 * (times_k: a small product that fits). */
static QS_ALWAYS_INLINE uint8_t predict_axis(qs_hold *hd, const qs_segment *s, uint8_t axis, uint8_t bytes,
                                            uint8_t k, uint8_t decisions)
{
    qs_i24 next;

    if (!(s->active & (1u << axis)))
        return 0;
    next = s->b[axis] - s->db[axis] + s->two_c2 + times_k((qs_u24)s->db[axis], decisions);
    if (next <= 0)
        return 0;
    hd->inc[axis] = scaled(next, bytes, k) + hd->db[axis];
    return (uint8_t)(1u << axis);
}

QS_NOINLINE void qs_hold_predict(qs_hold *hd, const qs_segment *s, uint8_t decisions, uint16_t left)
{
    const uint8_t bytes = hd->shift & 8, k = hd->bits_k;
    uint8_t moving = predict_axis(hd, s, 0, bytes, k, decisions);

#if QS_AXIS_COUNT > 1
    moving |= predict_axis(hd, s, 1, bytes, k, decisions);
#endif
#if QS_AXIS_COUNT > 2
    moving |= predict_axis(hd, s, 2, bytes, k, decisions);
#endif
#if QS_AXIS_COUNT > 3
    moving |= predict_axis(hd, s, 3, bytes, k, decisions);
#endif
    hd->predicted_moving = moving;
    hd->predicted_left = left;
    hd->predicted_slot = s;
}

uint8_t qs_hold_begin_predicted(qs_hold *hd, const qs_segment *s)
{
    const uint8_t bytes = hd->shift & 8, k = hd->bits_k, moving = hd->predicted_moving;

    if (moving & 1u)
        hd->h[0] = scaled(s->h[0], bytes, k);
#if QS_AXIS_COUNT > 1
    if (moving & 2u)
        hd->h[1] = scaled(s->h[1], bytes, k);
#endif
#if QS_AXIS_COUNT > 2
    if (moving & 4u)
        hd->h[2] = scaled(s->h[2], bytes, k);
#endif
#if QS_AXIS_COUNT > 3
    if (moving & 8u)
        hd->h[3] = scaled(s->h[3], bytes, k);
#endif
    hd->predicted_slot = 0;
    return moving;
}

uint8_t qs_hold_begin(qs_hold *hd, const qs_segment *s, uint8_t at_end)
{
    if (s->cubic)
        return begin_cubic(hd, s, at_end);
    if (at_end)
        return begin_at_end(hd, s);
    /* Mid-segment: the hold predicted for this very decision. */
    qs_hold_predict(hd, s, 0, 0);
    return qs_hold_begin_predicted(hd, s);
}
