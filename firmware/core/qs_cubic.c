#include "qs_cubic.h"
#include "qs_protocol.h"

/* Sums over a segment need more than 32 bits (an advance of up to n steps
 * in 2^-31 step, terms up to C(n, 3)*r < 2^61); the main loop does them
 * once per segment, each product of two 32-bit factors (a widening
 * multiply: far cheaper on the AVR than a 64 x 64 one). */
typedef int64_t wide;

static wide times(int32_t a, int32_t b)
{
    return (wide)a * (wide)b;
}

/* C(n, 2) = n(n-1)/2 < 2^31 for n <= 65535. */
static uint32_t choose2(uint32_t n)
{
    return n < 2 ? 0 : (n * (n - 1)) >> 1;
}

/* C(n, 3) = n(n-1)(n-2)/6 < 2^46, as two factors: ab < 2^31 and c < 2^16
 * (the factor 2 and the factor 3 divided out of n, n-1, n-2 first), so
 * that C(n, 3)*r is ab * (c*r), two 32-bit factors. */
typedef struct {
    int32_t ab;
    uint16_t c;
} choose3_t;

static choose3_t choose3(uint32_t n)
{
    uint16_t a = (uint16_t)n, b = (uint16_t)(n - 1), c = (uint16_t)(n - 2);
    choose3_t out = {0, 0};

    if (n < 3)
        return out;
    if (a & 1)
        b >>= 1;
    else
        a >>= 1;
    switch ((uint16_t)n % 3) { /* the one of n, n-1, n-2 that 3 divides */
    case 0:
        a /= 3;
        break;
    case 1:
        b /= 3; /* n-1, halved or not */
        break;
    default:
        c /= 3;
        break;
    }
    out.ab = (int32_t)((uint32_t)a * b);
    out.c = c;
    return out;
}

static wide choose3_times(choose3_t c3, int16_t r)
{
    return times(c3.ab, (int32_t)c3.c * r);
}

/* I(k) = i + (k-1)*d + C(k-1, 2)*r, exactly. */
static wide advance_at(wide i, int32_t d, int16_t r, uint32_t k)
{
    return i + times((int32_t)(k - 1), d) + times((int32_t)choose2(k - 1), r);
}

static uint8_t in_range(wide x)
{
    return x >= 0 && x <= (wide)QS_SIGMA;
}

static uint8_t accel_fits(wide q)
{
    return q > -QS_CUBIC_ACCEL_LIMIT && q < QS_CUBIC_ACCEL_LIMIT;
}

/* Whether 0 <= I(k) <= Sigma for k = 1..n, given I(1) = i and I(n) = last:
 * I is quadratic in k, so the ends and, where its differences d + (k-1)*r
 * change sign inside, the extreme between them (found by a division, only
 * then). */
static uint8_t advances_in_range(wide i, wide last, int32_t d, int16_t r, uint16_t n)
{
    uint32_t k;

    if (!in_range(i) || !in_range(last))
        return 0;
    if (r > 0 && d < 0)
        k = 1 + (uint32_t)((-(int32_t)d + r - 1) / r); /* the first k whose difference is >= 0: the least I */
    else if (r < 0 && d > 0)
        k = 1 + (uint32_t)((d - r - 1) / -(int32_t)r); /* the first k whose difference is <= 0: the largest I */
    else
        return 1;
    return k >= n || in_range(advance_at(i, d, r, k));
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
        /* The residual after it, rest - 4096 in 1/8192 step, is 2^18 times
         * that in this scale; the end speed vn/4096 step per tick is 2^19
         * times vn. */
        c->e[axis] = (int32_t)((uint32_t)(int32_t)((int16_t)slot->rest[axis] - QS_D) << 18);
        c->i[axis] = (uint32_t)c->after_vn[axis] << 19;
    }
    c->negative = (uint8_t)((c->negative & ~c->after_active) | (c->after_negative & c->after_active));
    c->after = 0;
}

static QS_ALWAYS_INLINE void settle(qs_cubic_chain *c)
{
    if (c->after)
        settle_quadratic(c);
}

void qs_cubic_rest_on_ideal(qs_cubic_chain *c, uint8_t mask)
{
    uint8_t axis;

    settle(c);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        if (mask & (1u << axis))
            c->e[axis] = 0;
}

void qs_cubic_follow_quadratic(qs_cubic_chain *c, const qs_segment *slot, const qs_segment_msg *m)
{
    uint8_t axis;

    c->after = slot;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        c->after_vn[axis] = m->vn[axis];
    c->after_active = m->active;
    c->after_negative = m->negative;
}

static uint8_t bad_field(qs_fault *f, uint8_t field, uint8_t axis)
{
    f->code = QS_ERR_BAD_FIELD;
    f->field = field;
    f->axis = axis;
    return QS_ERR_BAD_FIELD;
}

/* One axis's start state: the chain's, or the set's; a set that turns the
 * axis round measures the error the other way. */
typedef struct {
    int32_t e;
    uint32_t i;
    int32_t d;
} start_state;

static start_state axis_start(const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    start_state s;

    s.e = c->e[axis];
    s.i = c->i[axis];
    s.d = c->d[axis];
    if (m->set & bit) {
        if ((c->negative ^ m->negative) & bit)
            s.e = -s.e;
        s.i = m->speed[axis];
        s.d = m->accel[axis];
    }
    return s;
}

/* One axis over a segment: where it starts, what the segment does to it. */
typedef struct {
    start_state s;
    int32_t end_e;
    uint32_t end_i;
    int32_t end_d;
    uint16_t steps;
    uint8_t moves;
} axis_plan;

/* The sums of a segment of n ticks for one axis, exactly: its end state,
 * the steps it makes; returns 0 if some advance leaves [0, Sigma]. */
static uint8_t plan_axis(axis_plan *p, uint16_t n, uint32_t c2, choose3_t c3, int16_t r)
{
    const start_state *s = &p->s;
    wide travel, total, end_i;

    p->end_e = s->e;
    p->end_i = 0;
    p->end_d = 0;
    p->steps = 0;
    p->moves = s->i || s->d || r;
    if (!p->moves)
        return 1; /* at rest, and stays there */
    p->end_d = s->d + (int32_t)((int32_t)n * r);
    end_i = (wide)s->i + times(n, s->d) + times((int32_t)c2, r);
    /* I(n) = I(n+1) - (d + (n-1)*r) */
    if (!advances_in_range(s->i, end_i - (p->end_d - r), s->d, r, n))
        return 0;
    travel = (wide)((uint64_t)n * s->i) + times((int32_t)c2, s->d) + choose3_times(c3, r);
    total = (wide)s->e + travel + (wide)QS_HALF_SIGMA;
    p->steps = (uint16_t)((uint32_t)(total >> 16) >> (QS_CUBIC_SHIFT - 16));
    p->end_e = (int32_t)((uint32_t)total & (QS_SIGMA - 1u)) - (int32_t)QS_HALF_SIGMA;
    p->end_i = (uint32_t)end_i;
    return 1;
}

QS_NOINLINE uint8_t qs_cubic_prepare(qs_cubic_chain *c, qs_segment *slot, const qs_cubic_msg *m, uint8_t axis_count,
                                     qs_fault *f)
{
    const uint16_t n = m->n;
    const uint8_t named = (uint8_t)(m->jerk | m->set);
    axis_plan plan[QS_AXIS_COUNT];
    uint32_t c2;
    choose3_t c3;
    uint8_t axis, bit;

    settle(c);
    if (n < 1)
        return bad_field(f, QS_FIELD_N, QS_AXIS_NONE);
    if (named & (uint8_t)(0xFFu << axis_count))
        return bad_field(f, QS_FIELD_AXES, QS_AXIS_NONE);
    /* Field by field, each in axis order: the acceleration's width, then
     * the advance per tick. */
    for (axis = 0; axis < axis_count; axis++) {
        plan[axis].s = axis_start(c, m, axis);
        if (!accel_fits(plan[axis].s.d) || !accel_fits((wide)plan[axis].s.d + (int32_t)n * m->r[axis]))
            return bad_field(f, QS_FIELD_ACCEL, axis);
    }
    c2 = choose2(n);
    c3 = choose3(n);
    for (axis = 0; axis < axis_count; axis++)
        if (!plan_axis(&plan[axis], n, c2, c3, m->r[axis]))
            return bad_field(f, QS_FIELD_SPEED, axis);

    /* Valid: fill the slot, and the chain moves on. */
    slot->n = n;
    slot->active = 0;
    slot->tick_axes = 0;
    slot->cubic = QS_CUBIC_KIND;
    slot->ends_moving = 0;
    for (axis = 0, bit = 1; axis < axis_count; axis++, bit = (uint8_t)(bit << 1)) {
        const axis_plan *p = &plan[axis];
        const int16_t r = m->r[axis];
        slot->total[axis] = p->steps;
        c->e[axis] = p->end_e;
        c->i[axis] = p->end_i;
        c->d[axis] = p->end_d;
        if (!p->moves)
            continue;
        slot->active |= bit;
        slot->tick_axes |= bit;
        if (!r) {
            slot->tick_axes |= (uint8_t)(bit << 4);
            if (!p->s.d)
                slot->cubic |= bit;
        }
        if (p->end_i || p->end_d)
            slot->ends_moving = 1;
        slot->c.h[axis] = (uint32_t)p->s.e + p->s.i - QS_HALF_SIGMA;
        slot->c.b[axis] = p->s.i + (uint32_t)p->s.d - QS_SIGMA;
        slot->c.q[axis] = p->s.d;
        slot->c.r[axis] = r;
        slot->c.e_top[axis] = (int8_t)(p->s.e >> 24);
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
    uint32_t next, sum_low;
    int32_t e;
    wide sum;

    if (t == 0)
        return 0; /* even when e(0) is half a step, which would round up */
    if (t == s->n)
        return s->total[axis];
    next = b - (uint32_t)(int32_t)q + QS_SIGMA;
    e = (int32_t)(h - next + QS_HALF_SIGMA);
    sum = (wide)((uint64_t)t * next) - times((int32_t)choose2((uint32_t)t + 1), q)
          + choose3_times(choose3((uint32_t)t + 2), (int16_t)s->c.r[axis]);
    sum += (wide)s->c.e_top[axis] * 16777216 - e + (wide)QS_HALF_SIGMA; /* a multiply: the top byte may be negative */
    sum_low = (uint32_t)(sum >> 16) >> (QS_CUBIC_SHIFT - 16);
    return (uint16_t)sum_low;
}
