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
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        hd->db[axis] = qs_hold_db(kn, decel[axis]);
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
static QS_ALWAYS_INLINE uint8_t begin_axis(const qs_hold *hd, qs_i24 *h, qs_i24 *inc, const qs_segment *s,
                                          uint8_t axis, uint8_t bytes, uint8_t k, uint8_t at_end)
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
    h[axis] = scaled(s->h[axis] - past, bytes, k);
    inc[axis] = scaled(next, bytes, k) + hd->db[axis];
    return (uint8_t)(1u << axis);
}

/* A cubic axis (qs_cubic.h): the increment over the next tick is
 * I(t+1) = b - q + Sigma and the ideal is e = h - I(t+1) + Sigma/2 ahead;
 * both, floored to the hold's scale 2^22, start it. */
static QS_ALWAYS_INLINE uint8_t begin_cubic_axis(const qs_hold *hd, qs_i24 *h, qs_i24 *inc, const qs_segment *s,
                                                uint8_t axis, uint8_t at_end)
{
    const uint32_t next = s->c.b[axis] - (uint32_t)(int32_t)s->c.q[axis] + QS_SIGMA;
    const int32_t e = (int32_t)(s->c.h[axis] - next + QS_HALF_SIGMA);
    /* After the end, I(n+1) was never checked against one step a tick: the
     * last tick's advance I(n) = I(n+1) - (q - r) starts the hold instead. */
    const uint32_t first = at_end ? next - (uint32_t)(int32_t)(s->c.q[axis] - s->c.r[axis]) : next;
    const qs_i24 i1 = (qs_i24)(first >> QS_HOLD_CUBIC_SHIFT);

    if (!(s->active & (1u << axis)) || i1 <= 0)
        return 0;
    h[axis] = (qs_i24)(e >> QS_HOLD_CUBIC_SHIFT) + i1 - ((qs_i24)QS_HOLD_CUBIC_N * QS_D);
    inc[axis] = i1 + hd->db[axis];
    return (uint8_t)(1u << axis);
}

/* The state a hold begins with, into h and inc (the hold's own, or
 * qs_hold_origin_of's); out of line, so the usual hold's code stays as
 * short. */
static QS_NOINLINE uint8_t begin_cubic(const qs_hold *hd, qs_i24 *h, qs_i24 *inc, const qs_segment *s,
                                       uint8_t at_end)
{
    uint8_t moving = begin_cubic_axis(hd, h, inc, s, 0, at_end);

#if QS_AXIS_COUNT > 1
    moving |= begin_cubic_axis(hd, h, inc, s, 1, at_end);
#endif
#if QS_AXIS_COUNT > 2
    moving |= begin_cubic_axis(hd, h, inc, s, 2, at_end);
#endif
#if QS_AXIS_COUNT > 3
    moving |= begin_cubic_axis(hd, h, inc, s, 3, at_end);
#endif
    return moving;
}

/* A quadratic segment's; after all n ticks of it (at_end) the increment is
 * the end speed's. */
static QS_NOINLINE uint8_t begin_quadratic(const qs_hold *hd, qs_i24 *h, qs_i24 *inc, const qs_segment *s,
                                           uint8_t at_end)
{
    const uint8_t bytes = hd->shift & 8, k = hd->bits_k;
    uint8_t moving = begin_axis(hd, h, inc, s, 0, bytes, k, at_end);

#if QS_AXIS_COUNT > 1
    moving |= begin_axis(hd, h, inc, s, 1, bytes, k, at_end);
#endif
#if QS_AXIS_COUNT > 2
    moving |= begin_axis(hd, h, inc, s, 2, bytes, k, at_end);
#endif
#if QS_AXIS_COUNT > 3
    moving |= begin_axis(hd, h, inc, s, 3, bytes, k, at_end);
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
    if (QS_IS_CUBIC(s))
        return begin_cubic(hd, hd->h, hd->inc, s, at_end);
    if (at_end)
        return begin_quadratic(hd, hd->h, hd->inc, s, 1);
    /* Mid-segment: the hold predicted for this very decision. */
    qs_hold_predict(hd, s, 0, 0);
    return qs_hold_begin_predicted(hd, s);
}

/* An axis that moves has added inc0, inc0 + db, ...: T increments, with
 * inc now inc0 + T db. One that has stopped added one more, inc itself,
 * and kept it. */
static QS_ALWAYS_INLINE uint32_t axis_ticks(int32_t inc0, int32_t inc, uint32_t slowing, uint8_t stopped)
{
    return (uint32_t)(inc0 - inc) / slowing + stopped;
}

/* v / d and v % d for d = 2 * 2knD = kn * 2^14 and v < 2^30: a 16-bit
 * division (kn < 2^10), a third of a 32-bit one's cycles on the AVR. */
static QS_ALWAYS_INLINE uint16_t over_d(uint32_t v, uint16_t kn, uint32_t *rest)
{
    const uint16_t high = (uint16_t)(v >> 14);

    *rest = ((uint32_t)(high % kn) << 14) | (v & 0x3FFFu);
    return high / kn;
}

/* h = h0 + (the increments added) - 2knD steps. The T increments add up to
 * T (inc0 + the last) / 2 = T m / 2, m = 2 inc0 - |db| (T - 1): with
 * d = 2 * 2knD = kn * 2^14, steps = (T m + 2 (h0 - h)) / d, exactly. m <= d
 * < 2^24 (an axis moves until its increment would not be positive, and no
 * faster than a step a tick; m < 0 only when T <= 2). A hold of fewer than
 * 2^16 ticks (2 s at 32 kHz) splits m at bit 14, so that every product
 * fits 32 bits; a longer one divides T m, up to 48 bits, a nibble of T at
 * a time (the AVR's 64-bit arithmetic would not fit the Uno's flash). */
static QS_ALWAYS_INLINE uint32_t axis_steps(uint32_t ticks, int32_t m, int32_t twice_h_lost, uint16_t kn)
{
    uint32_t b, steps = 0, r = 0, t = ticks << 8, whole;
    uint8_t i;

    if (ticks < 0x10000u) {
        /* T m + 2 (h0 - h) = 2^14 T (m >> 14) + low, both multiples of 2^14 */
        const int32_t low = (int32_t)(ticks * (uint32_t)(m & 0x3FFF)) + twice_h_lost;
        return (uint32_t)((int32_t)ticks * (m >> 14) + (low >> 14)) / kn;
    }
    whole = over_d((uint32_t)m, kn, &b); /* 0 or 1 */
    for (i = 0; i < 6; i++) {
        const uint32_t v = (r << 4) + (t >> 28) * b; /* < 2^29 */
        steps = (steps << 4) + over_d(v, kn, &r);
        t <<= 4;
    }
    steps += ticks * whole;
    /* r and 2 (h0 - h) add up to a multiple of d */
    if (twice_h_lost >= -(int32_t)r)
        return steps + over_d(r + (uint32_t)twice_h_lost, kn, &r);
    return steps - over_d((uint32_t)-twice_h_lost - r, kn, &r);
}

void qs_hold_origin_of(const qs_hold *hd, const qs_segment *s, uint8_t at_end, qs_hold_origin *o)
{
    o->axes = QS_IS_CUBIC(s) ? begin_cubic(hd, o->h, o->inc, s, at_end) : begin_quadratic(hd, o->h, o->inc, s, at_end);
}

/* Out of line, with the arithmetic inlined: the shallowest stack found for
 * a STATUS during a hold. */
QS_NOINLINE uint32_t qs_hold_axis_made(const qs_hold *hd, const qs_hold_origin *o, uint8_t axis, qs_i24 h,
                                       qs_i24 inc, uint8_t moving, uint32_t *ticks)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    const int32_t inc0 = o->inc[axis];
    const uint32_t slowing = (uint32_t)-(int32_t)hd->db[axis];
    uint32_t t;

    if (!(o->axes & bit))
        return 0;
    t = axis_ticks(inc0, inc, slowing, !(moving & bit));
    if (t > *ticks)
        *ticks = t; /* a moving axis has run them all */
    return axis_steps(t, (int32_t)(2u * (uint32_t)inc0 - slowing * (t ? t - 1u : 0u)),
                      2 * ((int32_t)o->h[axis] - (int32_t)h), (uint16_t)(hd->two_c2 >> 13));
}
