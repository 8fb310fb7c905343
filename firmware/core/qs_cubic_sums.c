/* qs_cubic_sums.h in C: the host build's (the emulator's, the tests'), and
 * the reference for the AVR's (firmware/avr/cubic_sums.c), which the
 * simavr tests check against this, built for the AVR under other names
 * with QS_CUBIC_SUMS_IN_C (tests/simavr/avr/forms_check.c). */
#include "qs_cubic_sums.h"
#include "qs_protocol.h"

#if !defined(__AVR__) || defined(QS_CUBIC_SUMS_IN_C)

/* -2^23 < q < 2^23 */
static uint8_t accel_fits(int32_t q)
{
    return q > -QS_CUBIC_ACCEL_LIMIT && q < QS_CUBIC_ACCEL_LIMIT;
}

static uint64_t w48_value(qs_w48 a)
{
    return (uint64_t)a.lo | (uint64_t)a.hi << 32;
}

static qs_w48 w48_from(uint64_t v)
{
    qs_w48 a;
    a.lo = (uint32_t)v;
    a.hi = (uint16_t)(v >> 32);
    return a;
}

uint8_t qs_cubic_last(qs_cubic_terms *t)
{
    const int64_t last = (int64_t)t->i + (int64_t)t->n_less * t->d + (int64_t)t->c2_less * t->r;
    t->last = w48_from((uint64_t)last);
    return last >= 0 && last <= (int64_t)QS_SIGMA;
}

uint8_t qs_cubic_check(qs_cubic_terms *t)
{
    const int32_t d = t->d, r = t->r;
    int32_t last_difference;
    uint8_t kind = QS_CUBIC_VALID;

    t->nr = (int32_t)t->n * r;
    /* |n*r| < 2^31; below 2^24 unless the end is out of range anyway */
    if (!(accel_fits(d) && t->nr < (1L << 24) && t->nr > -(1L << 24) && accel_fits(d + t->nr)))
        return 0;
    if (!(t->i || d || r))
        return kind; /* at rest, and stays there */
    if (t->i > QS_SIGMA)
        return 0;
    kind |= QS_CUBIC_MOVING;
    if (!(d || r))
        return kind;
    kind |= QS_CUBIC_CURVED;
    /* Whether I's differences d + (k-1)*r change sign before k = n, so that
     * I(k) has an extreme inside the segment (the ends are checked apart):
     * d + (n-2)*r lies between I(n-1) and I(n). */
    last_difference = d + t->nr - 2 * r;
    if ((r > 0 && d < 0 && last_difference > 0) || (r < 0 && d > 0 && last_difference < 0))
        kind |= QS_CUBIC_EXTREME;
    return kind;
}

void qs_cubic_load(qs_cubic_terms *t, const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    int32_t e = c->e[axis];

    if (m->set & bit) {
        if ((c->negative ^ m->negative) & bit)
            e = -e;
        t->i = m->speed[axis];
        t->d = m->accel[axis];
    } else {
        t->i = c->i[axis];
        t->d = c->d[axis];
    }
    t->ahead = (uint32_t)e + QS_HALF_SIGMA;
    t->r = m->r[axis];
}

void qs_cubic_finish(qs_cubic_terms *t, qs_segment *slot, uint8_t axis, qs_cubic_ends *end)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    const uint64_t sum = (uint64_t)t->i + t->last.lo;
    const uint64_t twice = 2 * (uint64_t)t->ahead + t->n * sum - w48_value(t->c3) * (uint64_t)(int64_t)t->r;

    t->twice = w48_from(twice);
    /* I(n+1) = I(n) + d + (n-1)*r, within 32 bits now that I(n) is */
    end->d[axis] = t->d + t->nr;
    end->i[axis] = t->last.lo + (uint32_t)(end->d[axis] - t->r);
    /* twice is 2*(e + Sigma/2 + X(n)): the steps are its bits 32 and up,
     * the new e (plus Sigma/2) its bits 1 to 31 */
    end->e[axis] = (int32_t)((t->twice.lo >> 1) & (QS_SIGMA - 1u)) - (int32_t)QS_HALF_SIGMA;
    slot->total[axis] = t->twice.hi;
    slot->c.h[axis] = t->ahead + t->i - QS_SIGMA;
    slot->c.b[axis] = t->i + (uint32_t)t->d - QS_SIGMA;
    slot->c.q[axis] = t->d;
    slot->c.r[axis] = t->r;
    slot->c.e_top[axis] = (int8_t)((t->ahead - QS_HALF_SIGMA) >> 24);
    slot->active |= bit;
    slot->tick_axes |= bit;
    if (!t->r) {
        slot->tick_axes |= (uint8_t)(bit << 4);
        if (!t->d)
            slot->cubic |= bit;
    }
    if (end->i[axis] || end->d[axis])
        slot->ends_moving = 1;
}

#else
typedef int qs_cubic_sums_on_the_avr; /* firmware/avr/cubic_sums.c */
#endif
