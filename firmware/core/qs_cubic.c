#include <stddef.h>

#include "qs_cubic.h"
#include "qs_cubic_sums.h"
#include "qs_protocol.h"

/* The sums are 48-bit (qs_wide.h, qs_cubic_sums.h): the steps are their
 * bits 31 and up. */
_Static_assert(QS_CUBIC_SHIFT == 31, "a step is 2^31");

/* C(n, 2) = n(n-1)/2 < 2^31 for n <= 65535. */
static uint32_t choose2(uint16_t n)
{
    return n < 2 ? 0 : qs_umul16(n, (uint16_t)(n - 1)) >> 1;
}

/* x / 3 for any 16-bit x, by a multiply (exact: 3 * 43691 = 2^17 + 1). */
static QS_ALWAYS_INLINE uint16_t third(uint16_t x)
{
    return (uint16_t)((uint16_t)(qs_umul16(x, 43691u) >> 16) >> 1);
}

/* C(n, 3) = n(n-1)(n-2)/6 < 2^46: the factor 2 and the factor 3 divided
 * out of n, n-1, n-2 first, then two products. */
static QS_NOINLINE qs_w48 choose3(uint16_t n)
{
    uint16_t a = n, b = (uint16_t)(n - 1), c = (uint16_t)(n - 2);
    const uint16_t n3 = third(n);
    const uint8_t rest = (uint8_t)((uint8_t)n - (uint8_t)(3 * (uint8_t)n3)); /* n mod 3: 0 ... 2 */
    qs_w48 out = qs_w48_of(0);

    if (n < 3)
        return out;
    if (a & 1)
        b >>= 1;
    else
        a >>= 1;
    /* the one of n, n-1, n-2 that 3 divides (n-1 perhaps halved) */
    if (rest == 0)
        a = (a == n) ? n3 : (uint16_t)(n3 >> 1);
    else if (rest == 1)
        b = third(b);
    else
        c = third(c);
    qs_w48_mac(&out, qs_umul16(a, b), c);
    return out;
}

/* The segment's counts for every axis's sums: n - 1, C(n-1, 2) and
 * C(n, 3). Of n, n-1, n-2 the one that 3 divides is 3 * (n/3 rounded
 * down), so 2 * C(n, 3) is n/3 times the other two (one multiply for
 * C(n-1, 2) serves when 3 divides n). n = 1 and 2 give 0 throughout. */
static QS_NOINLINE void segment_counts(qs_cubic_terms *t, uint16_t n)
{
    const uint16_t less = (uint16_t)(n - 1), less2 = (uint16_t)(n - 2);
    const uint32_t both = qs_umul16(less, less2); /* (n-1)(n-2): 0 for n < 3 */
    const uint16_t n3 = third(n);
    const uint8_t rest = (uint8_t)((uint8_t)n - (uint8_t)(3 * (uint8_t)n3)); /* n mod 3 */
    qs_w48 twice_c3 = qs_w48_of(0);

    t->n = n;
    t->n_less = less;
    t->c2_less = both >> 1;
    qs_w48_mac(&twice_c3, rest == 0 ? both : qs_umul16(n, rest == 1 ? less2 : less), n3);
    t->c3.lo = (twice_c3.lo >> 1) | ((uint32_t)twice_c3.hi << 31);
    t->c3.hi = (uint16_t)(twice_c3.hi >> 1);
}

/* -2^23 < q < 2^23 */
static uint8_t accel_fits(int32_t q)
{
    return q > -QS_CUBIC_ACCEL_LIMIT && q < QS_CUBIC_ACCEL_LIMIT;
}


/* Whether that extreme is in [0, Sigma] too. Found by a division. */
static QS_NOINLINE uint8_t extreme_in_range(const qs_cubic_terms *t)
{
    const int32_t d = t->d, r = t->r;
    qs_cubic_terms at = *t;
    uint16_t k;

    if (r > 0)
        k = (uint16_t)(1 + (uint32_t)(-d + r - 1) / (uint16_t)r); /* the first k whose difference is >= 0: the least I */
    else
        k = (uint16_t)(1 + (uint32_t)(d - r - 1) / (uint16_t)-r); /* the first k whose difference is <= 0: the largest I */
    /* I(k) = i + (k-1)*d + C(k-1, 2)*r: last's sum with k in place of n */
    at.n_less = (uint16_t)(k - 1);
    at.c2_less = choose2((uint16_t)(k - 1));
    return qs_cubic_last(&at);
}

void qs_cubic_reset(qs_cubic_chain *c)
{
    uint8_t axis;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        c->e[axis] = 0;
        c->i[axis] = 0;
        c->d[axis] = 0;
    }
    c->negative = 0;
    c->after = 0;
}

/* The end state of the quadratic segment the chain was left after. */
static QS_NOINLINE void settle_quadratic(qs_cubic_chain *c)
{
    const qs_segment *slot = c->after;
    uint8_t axis, bit;

    for (axis = 0, bit = 1; axis < QS_AXIS_COUNT; axis++, bit = (uint8_t)(bit << 1)) {
        c->d[axis] = 0;
        if (!(c->after_active & bit)) {
            c->i[axis] = 0;
            continue;
        }
        /* The residual after it, r + n(v0 + vn) - 8192*steps in 1/8192
         * step (v0 + vn = 2vn - db/2: the slot keeps r and db), lies in
         * [-4096, 4096): its low 13 bits are exact in 16-bit arithmetic.
         * In this scale it is 2^18 times that; the end speed vn/4096 step
         * per tick is 2^19 times vn. */
        const uint16_t vn = c->after_vn[axis];
        const uint16_t sum = (uint16_t)(2 * vn - (uint16_t)((int32_t)slot->db[axis] / 2));
        const uint16_t rest = (uint16_t)((uint16_t)slot->r[axis] + (uint16_t)(slot->n * sum) + QS_D) & (2 * QS_D - 1);
        c->e[axis] = (int32_t)((uint32_t)(int32_t)((int16_t)rest - QS_D) << 18);
        c->i[axis] = (uint32_t)vn << 19;
    }
    c->negative = (uint8_t)((c->negative & ~c->after_active) | (c->after_negative & c->after_active));
    c->after = 0;
}

static QS_ALWAYS_INLINE void settle(qs_cubic_chain *c)
{
    if (c->after)
        settle_quadratic(c);
}

uint32_t qs_cubic_speed(qs_cubic_chain *c, uint8_t axis, uint8_t *negative)
{
    settle(c);
    *negative = (uint8_t)((c->negative >> axis) & 1u);
    return c->i[axis];
}

void qs_cubic_rest_on_ideal(qs_cubic_chain *c, uint8_t mask)
{
    uint8_t axis;

    settle(c);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        if (mask & (1u << axis))
            c->e[axis] = 0;
}

uint8_t qs_cubic_quadratic_start(qs_cubic_chain *c, uint8_t axis, uint8_t negative, uint16_t *speed, int16_t *r)
{
    uint8_t on = 0;
    int32_t e;
    uint32_t i;

    settle(c);
    i = c->i[axis];
    if (c->d[axis] == 0 && (i & 0x7FFFFUL) == 0 && i <= (uint32_t)QS_V_MAX << 19) {
        *speed = (uint16_t)(i >> 19);
        on |= QS_CHAIN_SPEED;
    }
    /* e is measured along the axis's last direction: the other way round
     * for a segment in the other direction. */
    e = c->e[axis];
    if (((c->negative >> axis) & 1u) != negative)
        e = -e;
    if ((e & 0x3FFFFL) == 0) {
        *r = (int16_t)(e >> 18);
        on |= QS_CHAIN_RESIDUAL;
    }
    return on;
}

void qs_cubic_follow_quadratic(qs_cubic_chain *c, const qs_segment *slot, const qs_segment_msg *m)
{
    uint8_t axis;

    /* An axis the last quadratic segment moved and this one does not keeps
     * that segment's end state: settle it before it is lost (its slot is
     * still intact, this one went to the next). */
    if (c->after && (c->after_active & (uint8_t)~m->active))
        settle_quadratic(c);
    c->after = slot;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        c->after_vn[axis] = m->vn[axis];
    c->after_active = m->active;
    c->after_negative = m->negative;
}

_Static_assert(offsetof(qs_cubic_chain, e) == 0 && offsetof(qs_cubic_chain, i) == offsetof(qs_cubic_ends, i)
                   && offsetof(qs_cubic_chain, d) == offsetof(qs_cubic_ends, d),
               "the chain begins as qs_cubic_ends");

/* One axis of a segment, exactly: its start state and steps into the slot,
 * its end state into end; returns 0 if its acceleration is too wide at
 * either end (|d| < 2^23) or some advance leaves [0, Sigma]. The advances
 * I(k) are quadratic in k: the ends, I(1) = i and last = I(n), and an
 * extreme between them decide. */
static QS_ALWAYS_INLINE uint8_t plan_axis(qs_cubic_terms *t, const qs_cubic_chain *c, const qs_cubic_msg *m,
                                     qs_segment *slot, uint8_t axis, qs_cubic_ends *end)
{
    uint8_t kind;

    qs_cubic_load(t, c, m, axis);
    kind = qs_cubic_check(t);
    if (!kind)
        return 0;
    if (!(kind & QS_CUBIC_MOVING)) {
        /* at rest, and stays there */
        end->e[axis] = (int32_t)(t->ahead - QS_HALF_SIGMA);
        end->i[axis] = 0;
        end->d[axis] = 0;
        slot->total[axis] = 0;
        return 1;
    }
    if (kind & QS_CUBIC_CURVED) {
        if (!qs_cubic_last(t))
            return 0;
    } else {
        t->last = qs_w48_of(t->i); /* a steady speed */
    }
    if ((kind & QS_CUBIC_EXTREME) && !extreme_in_range(t))
        return 0;
    qs_cubic_finish(t, slot, axis, end);
    return 1;
}

/* The ACCEL check of axis of m: |d| < 2^23 at the start and at the end. */
static uint8_t accel_ok(const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis)
{
    const int32_t d = (m->set & (1u << axis)) ? m->accel[axis] : c->d[axis];
    const int32_t nr = qs_usmul16(m->n, m->r[axis]);

    /* |n*r| < 2^31; below 2^24 unless the end is out of range anyway */
    return accel_fits(d) && nr < (1L << 24) && nr > -(1L << 24) && accel_fits(d + nr);
}

/* A segment an axis of which failed (failed, the first in axis order): the
 * field to report, field by field as the protocol lists them, each in axis
 * order: the acceleration's width of every axis first, then the advance
 * per tick. */
static QS_NOINLINE uint8_t refuse(const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis_count, uint8_t failed,
                                  qs_fault *f)
{
    uint8_t axis;

    for (axis = 0; axis < axis_count; axis++)
        if (!accel_ok(c, m, axis))
            return qs_msg_bad_field(f, QS_FIELD_ACCEL, axis);
    return qs_msg_bad_field(f, QS_FIELD_SPEED, failed);
}

QS_NOINLINE uint8_t qs_cubic_prepare(qs_cubic_chain *c, qs_segment *slot, const qs_cubic_msg *m, uint8_t axis_count,
                                     qs_fault *f)
{
    qs_cubic_terms terms, *t = &terms;
    const uint16_t n = m->n;
    const uint8_t named = (uint8_t)(m->jerk | m->set);
    qs_cubic_ends end;
    uint8_t axis;

    settle(c);
    if (n < 1)
        return qs_msg_bad_field(f, QS_FIELD_N, QS_AXIS_NONE);
    if (named & (uint8_t)(0xFFu << axis_count))
        return qs_msg_bad_field(f, QS_FIELD_AXES, QS_AXIS_NONE);
    segment_counts(t, n);
    slot->n = n;
    slot->active = 0;
    slot->tick_axes = 0;
    slot->cubic = QS_CUBIC_KIND;
    slot->ends_moving = 0;
    for (axis = 0; axis < axis_count; axis++)
        if (!plan_axis(t, c, m, slot, axis, &end))
            return refuse(c, m, axis_count, axis, f);

    /* Valid: the chain moves on. */
    if (axis_count == QS_AXIS_COUNT) {
        /* word by word: the AVR's memcpy moves a byte per loop */
        uint32_t *to = (uint32_t *)(void *)c;
        const uint32_t *from = (const uint32_t *)(const void *)&end;
        for (axis = 0; axis < 3 * QS_AXIS_COUNT; axis++)
            to[axis] = from[axis];
    } else {
        for (axis = 0; axis < axis_count; axis++) {
            c->e[axis] = end.e[axis];
            c->i[axis] = end.i[axis];
            c->d[axis] = end.d[axis];
        }
    }
    c->negative = (uint8_t)((c->negative & ~m->set) | (m->negative & m->set));
    slot->negative = (uint8_t)(c->negative & slot->active);
    return QS_ERR_NONE;
}

uint16_t qs_cubic_steps(const qs_segment *s, uint8_t axis, uint16_t t, uint32_t h, uint32_t b, qs_i24 q)
{
    /* I(t+1) and e(t) from the running state, the advance so far backwards
     * from I(t+1): t*I(t+1) - C(t+1, 2)*q + C(t+2, 3)*r. The steps made
     * are (e(0) + advance - e(t)) / Sigma exactly, so e(0)'s top byte is
     * enough. */
    uint32_t next, c2;
    int32_t e, mq;
    qs_w48 sum, c3, high;

    if (t == 0)
        return 0; /* even when e(0) is half a step, which would round up */
    if (t == s->n)
        return s->total[axis];
    next = b - (uint32_t)(int32_t)q + QS_SIGMA;
    e = (int32_t)(h - next + QS_HALF_SIGMA);
    sum = qs_w48_of(QS_HALF_SIGMA);
    qs_w48_add(&sum, (int32_t)((uint32_t)(int32_t)s->c.e_top[axis] << 24));
    qs_w48_add(&sum, -e);
    qs_w48_mac(&sum, next, t);
    /* - C(t+1, 2)*q, with -q split at bit 16 */
    c2 = choose2((uint16_t)(t + 1));
    mq = -(int32_t)q;
    qs_w48_mac(&sum, c2, (uint16_t)mq);
    high = qs_w48_of(0);
    qs_w48_mac_sy(&high, c2, (int16_t)(mq >> 16));
    qs_w48_add_16(&sum, high.lo);
    /* + C(t+2, 3)*r = (C(t+1, 3) + C(t+1, 2))*r, as t + 2 may need 17 bits */
    c3 = choose3((uint16_t)(t + 1));
    qs_w48_mac(&c3, c2, 1);
    qs_w48_mac_48(&sum, c3, (int16_t)s->c.r[axis]);
    return (uint16_t)((sum.hi << 1) | (sum.lo >> 31)); /* bits 31-46 */
}
