/* Cubic segments against exact arithmetic (docs/CUBIC.md):
 * - the decision at a small width, exhaustively: every segment at
 *   Sigma = 2^7 with 8-bit wrapping arithmetic, every tick within half a
 *   step of the ideal and equal to the closed form, every continuation equal
 *   to a fresh start from the exact end state;
 * - the firmware's own code at full width: 10^6 random chained segments on
 *   four axes through qs_cubic_prepare and the engine's tick, every tick
 *   against a reference that adds up the ideal exactly, with no drift;
 * - validation, positions read mid-segment, a hold from a cubic state, and a
 *   quadratic segment in a slot a cubic one used before. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "qs_engine_tick.h"
#include "qs_test_support.h"
#include "unity.h"

#define SIGMA ((int64_t)1 << 31)

static qs_engine engine;

void setUp(void)
{
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    tp_seed(0xC0B1C5EEDull);
}

void tearDown(void)
{
}

/* ---- the small width ---------------------------------------------------- */

/* Every start (e0, I1, d) and every r with |q| within 8 bits, run until the
 * advance per tick leaves [0, 128], q leaves 8 bits or the tick count 8
 * bits: each prefix is a segment, each end a continuation. */
static void test_every_segment_at_sigma_2_7_with_8_bit_arithmetic(void)
{
    const int s = 128, half = 64;
    uint64_t segments = 0, ticks = 0, ties = 0, bad = 0;
    int e0, i1, d1, r;

    for (e0 = -half; e0 <= half; e0++)
        for (i1 = 0; i1 <= s; i1++) {
            if (e0 == half && i1 == s)
                continue; /* the one start that would trail by half a step */
            for (d1 = -i1; d1 <= s - i1; d1++) {
                if (d1 < -127 || d1 > 127)
                    continue;
                for (r = -127; r <= 127; r++) {
                    int8_t h = (int8_t)(uint8_t)(e0 + i1 - half);
                    int8_t b = (int8_t)(uint8_t)(i1 + d1 - s);
                    int8_t q = (int8_t)d1;
                    int32_t inc = i1, acc = d1, x = 0, p = 0;
                    int k;
                    for (k = 1; k <= 255; k++) {
                        const int stepped = h >= 0;
                        int32_t err;
                        h = (int8_t)(uint8_t)(h + b + (stepped ? 0 : s));
                        q = (int8_t)(q + r);
                        b = (int8_t)(uint8_t)(b + q);
                        x += inc;
                        p += stepped;
                        ticks++;
                        err = e0 + x - s * p;
                        if (err < -half || err >= half || p != tp_floor_div(e0 + x + half, s))
                            bad++;
                        ties += err == -half;
                        /* the exact state after tick k */
                        inc += acc;
                        acc += r;
                        if (acc < -127 || acc > 127)
                            break; /* q would leave 8 bits: no segment this long */
                        segments++;
                        if (h != (int8_t)(uint8_t)(err + inc - half) || b != (int8_t)(uint8_t)(inc + acc - s)
                            || q != acc)
                            bad++;
                        if (inc < 0 || inc > s)
                            break; /* the next tick would leave [0, 1] step */
                    }
                }
            }
        }
    printf("Sigma = 2^7: %llu segments, %llu ticks, %llu ties at half a step, %llu failures\n",
           (unsigned long long)segments, (unsigned long long)ticks, (unsigned long long)ties,
           (unsigned long long)bad);
    TEST_ASSERT_EQUAL_INT64(0, (int64_t)bad);
    TEST_ASSERT_TRUE(ties > 0);
    TEST_ASSERT_TRUE(segments > 100000000ull);
}

/* ---- full width, the firmware's code ------------------------------------ */

typedef struct {
    int64_t e, i, d; /* exact: error, next advance, its change (in the axis's direction) */
    int64_t position; /* steps, signed */
    int negative;
} ref_axis;

static ref_axis ref[QS_AXIS_COUNT];

static int64_t mag(int64_t x)
{
    return x < 0 ? -x : x;
}

/* Whether n ticks from (i, d) with r keep 0 <= I <= Sigma and |q| < 2^23. */
static int runnable(int64_t i, int64_t d, int64_t r, int64_t n)
{
    int64_t k;
    if (mag(d) >= QS_CUBIC_ACCEL_LIMIT || mag(d + n * r) >= QS_CUBIC_ACCEL_LIMIT)
        return 0;
    if (r == 0) /* linear: the ends decide */
        return i >= 0 && i <= SIGMA && i + (n - 1) * d >= 0 && i + (n - 1) * d <= SIGMA;
    for (k = 0; k < n; k++) {
        if (i < 0 || i > SIGMA)
            return 0;
        i += d;
        d += r;
    }
    return 1;
}

/* A random segment that heads each axis for a random speed, sometimes with a
 * state set (a corner: new speed, acceleration, perhaps a new direction). */
static void random_cubic(qs_cubic_msg *m)
{
    static const uint16_t long_n[] = {1, 2, 3, 1000, 20000, 65535};
    uint8_t axis;
    int64_t n;

    n = tp_rand(500) ? 1 + tp_rand(120) : long_n[tp_rand(6)];
    m->n = (uint16_t)n;
    m->jerk = m->set = m->negative = 0;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        const uint8_t bit = (uint8_t)(1u << axis);
        int64_t i = ref[axis].i, d = ref[axis].d, r = 0, target;
        m->speed[axis] = 0;
        m->accel[axis] = 0;
        m->r[axis] = 0;
        if (tp_rand(10) == 0 || i < 0 || i > SIGMA) {
            /* a set: a speed, often an extreme, and a small acceleration */
            static const uint32_t speeds[] = {0, 1, 0x7FFFFFFFu, 0x40000000u};
            i = tp_rand(3) ? (int64_t)tp_rand(0x7FFFFFFF) : speeds[tp_rand(4)];
            d = tp_rand(2) ? 0 : (int64_t)tp_rand(2001) - 1000;
            m->set |= bit;
            m->speed[axis] = (uint32_t)i;
            m->accel[axis] = (int32_t)d;
            if (tp_rand(3) == 0)
                m->negative |= bit;
            else
                m->negative |= (uint8_t)(ref[axis].negative ? bit : 0);
        }
        if (n <= 120 && tp_rand(3)) {
            target = (int64_t)tp_rand(0x7FFFFFFF);
            if (n > 1)
                r = (target - i - n * d) / ((n * (n - 1)) / 2);
            if (r > 32767)
                r = 32767;
            if (r < -32768)
                r = -32768;
            while (r && !runnable(i, d, r, n))
                r /= 2;
        }
        if (!runnable(i, d, r, n)) {
            /* stop where it is: a set to rest, and no jerk */
            m->set |= bit;
            m->speed[axis] = 0;
            m->accel[axis] = 0;
            r = 0;
        }
        if (r) {
            m->jerk |= bit;
            m->r[axis] = (int16_t)r;
        }
    }
}

/* The reference's start state for an axis of m. */
static void ref_start(const qs_cubic_msg *m, uint8_t axis)
{
    const uint8_t bit = (uint8_t)(1u << axis);
    if (m->set & bit) {
        const int negative = (m->negative & bit) != 0;
        if (negative != ref[axis].negative)
            ref[axis].e = -ref[axis].e;
        ref[axis].negative = negative;
        ref[axis].i = m->speed[axis];
        ref[axis].d = m->accel[axis];
    }
}

static uint64_t chain_ticks;

/* Queue m, run it to its end, and check every tick against the reference. */
static void run_checked(const qs_cubic_msg *m)
{
    qs_fault f;
    uint8_t axis;
    uint16_t t;

    TEST_ASSERT_TRUE(qs_queue_free(&engine.queue) > 0);
    TEST_ASSERT_EQUAL_INT_MESSAGE(QS_ERR_NONE,
                                  qs_cubic_prepare(&engine.chain, qs_queue_back(&engine.queue), m, QS_AXIS_COUNT, &f),
                                  "a runnable segment was refused");
    qs_queue_publish(&engine.queue);
    qs_engine_wake(&engine);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        ref_start(m, axis);
    for (t = 0; t < m->n; t++) {
        /* the decisions of this call step at the next tick: apply at once */
        uint8_t steps = qs_engine_tick(&engine);
        chain_ticks++;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            ref_axis *a = &ref[axis];
            const int stepped = (steps >> axis) & 1;
            if (stepped) {
                TEST_ASSERT_EQUAL_INT_MESSAGE(a->negative, (engine.dir_bits >> axis) & 1, "wrong direction");
                a->position += a->negative ? -1 : 1;
            }
            a->e += a->i - (stepped ? SIGMA : 0);
            if (a->e < -SIGMA / 2 || a->e >= SIGMA / 2) {
                char text[120];
                snprintf(text, sizeof text, "axis %u tick %u of %u: %lld past the ideal", axis, t + 1, m->n,
                         (long long)a->e);
                TEST_FAIL_MESSAGE(text);
            }
            a->i += a->d;
            a->d += m->r[axis];
        }
    }
    TEST_ASSERT_EQUAL_UINT16(0, engine.left);
    qs_engine_retire(&engine);
}

static void test_a_million_random_chained_segments_do_not_drift(void)
{
    uint32_t k;
    uint8_t axis;
    qs_cubic_msg m;
    qs_engine_view v;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        ref[axis] = (ref_axis){0, 0, 0, 0, 0};
    chain_ticks = 0;
    for (k = 0; k < 1000000u; k++) {
        random_cubic(&m);
        run_checked(&m);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            /* the firmware's chain is the exact state, and positions agree */
            TEST_ASSERT_EQUAL_INT64(ref[axis].e, engine.chain.e[axis]);
            TEST_ASSERT_EQUAL_UINT32((uint32_t)ref[axis].i, engine.chain.i[axis]);
            TEST_ASSERT_EQUAL_INT64(ref[axis].d, engine.chain.d[axis]);
        }
        /* the last segment's slot may be kept (it ends moving): read positions whole */
        qs_engine_read(&engine, &v);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            TEST_ASSERT_EQUAL_INT64(ref[axis].position, v.position[axis]);
    }
    printf("10^6 chained segments, %llu ticks on %d axes: no drift\n", (unsigned long long)chain_ticks,
           QS_AXIS_COUNT);
}

/* ---- validation ---------------------------------------------------------- */

static qs_cubic_msg rest_msg(uint16_t n)
{
    qs_cubic_msg m = {0};
    m.n = n;
    return m;
}

static void expect_refused(const qs_cubic_msg *m, uint8_t field, uint8_t axis)
{
    qs_cubic_chain before = engine.chain;
    qs_fault f = {0};
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, qs_cubic_prepare(&engine.chain, qs_queue_back(&engine.queue), m, 3, &f));
    TEST_ASSERT_EQUAL_INT(field, f.field);
    TEST_ASSERT_EQUAL_INT(axis, f.axis);
    /* the state the chain carries (its work area aside) */
    TEST_ASSERT_TRUE(memcmp(before.e, engine.chain.e, sizeof before.e) == 0);
    TEST_ASSERT_TRUE(memcmp(before.i, engine.chain.i, sizeof before.i) == 0);
    TEST_ASSERT_TRUE(memcmp(before.d, engine.chain.d, sizeof before.d) == 0);
    TEST_ASSERT_EQUAL_HEX8(before.negative, engine.chain.negative);
}

static void test_validation_names_the_field_and_changes_nothing(void)
{
    qs_cubic_msg m = rest_msg(0);
    qs_fault f;

    expect_refused(&m, QS_FIELD_N, QS_AXIS_NONE);
    m = rest_msg(10);
    m.jerk = 0x08; /* axis 3 on a 3-axis machine */
    expect_refused(&m, QS_FIELD_AXES, QS_AXIS_NONE);
    /* from rest, a negative jerk would move backwards */
    m = rest_msg(10);
    m.jerk = 0x02;
    m.r[1] = -5;
    expect_refused(&m, QS_FIELD_SPEED, 1);
    /* a set near full speed that accelerates past one step per tick */
    m = rest_msg(100);
    m.set = 0x01;
    m.speed[0] = 0x7FFF0000u;
    m.accel[0] = 100000;
    expect_refused(&m, QS_FIELD_SPEED, 0);
    /* an acceleration that leaves 24 bits by the end */
    m = rest_msg(100);
    m.set = 0x04;
    m.speed[2] = 0x10000000u;
    m.accel[2] = 8388000;
    m.jerk = 0x04;
    m.r[2] = 100;
    expect_refused(&m, QS_FIELD_ACCEL, 2);
    /* a speed that dips below zero inside the segment, though both ends are fine */
    m = rest_msg(1001);
    m.set = 0x01;
    m.speed[0] = 1000000;
    m.accel[0] = -4000;
    m.jerk = 0x01;
    m.r[0] = 8;
    expect_refused(&m, QS_FIELD_SPEED, 0);
    m.r[0] = 9; /* its least advance is then just above zero */
    TEST_ASSERT_EQUAL_INT(QS_ERR_NONE, qs_cubic_prepare(&engine.chain, qs_queue_back(&engine.queue), &m, 3, &f));
}

/* ---- positions mid-segment, a hold ------------------------------------- */

static void test_positions_read_mid_segment_match_the_steps_made(void)
{
    qs_cubic_msg m = rest_msg(3000);
    int32_t made = 0;
    uint16_t t;
    qs_fault f;

    m.set = 0x01;
    m.speed[0] = 0x20000000u; /* 1/4 step per tick, accelerating, jerking back */
    m.accel[0] = 300000;
    m.jerk = 0x01;
    m.r[0] = -150;
    TEST_ASSERT_EQUAL_INT(QS_ERR_NONE, qs_cubic_prepare(&engine.chain, qs_queue_back(&engine.queue), &m, 4, &f));
    qs_queue_publish(&engine.queue);
    qs_engine_wake(&engine);
    for (t = 0; t < m.n; t++) {
        qs_engine_view v;
        made += qs_engine_tick(&engine) & 1;
        if (t % 7 == 0) {
            qs_engine_read(&engine, &v);
            TEST_ASSERT_EQUAL_INT32(made, v.position[0]);
        }
    }
}

/* A hold from the middle of a jerk phase: every tick equals the hold's closed
 * form (PROTOCOL.md section 8.1) in the scale 2^22, from the exact state. */
static void test_a_hold_from_a_cubic_state_follows_its_closed_form(void)
{
    const uint16_t decel = 700;
    uint16_t held_at;

    for (held_at = 1; held_at < 2000; held_at += 97) {
        qs_cubic_msg m = rest_msg(2000);
        uint16_t decels[QS_AXIS_COUNT] = {decel, decel, decel, decel};
        int64_t e, i, d, before = 0, e_h, i1, w = (int64_t)1 << 22, dd, j, made = 0, stop;
        uint16_t t;
        qs_fault f;

        qs_engine_init(&engine, QS_QUEUE_CAPACITY);
        m.set = 0x01;
        m.speed[0] = 0x30000000u;
        m.accel[0] = 20000;
        m.jerk = 0x01;
        m.r[0] = -23;
        TEST_ASSERT_EQUAL_INT(QS_ERR_NONE, qs_cubic_prepare(&engine.chain, qs_queue_back(&engine.queue), &m, 4, &f));
        qs_queue_publish(&engine.queue);
        qs_engine_wake(&engine);
        e = 0;
        i = m.speed[0];
        d = m.accel[0];
        for (t = 0; t < held_at; t++) {
            uint8_t s = qs_engine_tick(&engine) & 1;
            before += s;
            e += i - (s ? SIGMA : 0);
            i += d;
            d += m.r[0];
        }
        TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decels, 0));
        /* The motion runs on through the hold's window, then the hold begins. */
        for (t = 0; t < QS_TRIGGER_TICKS; t++) {
            uint8_t s = qs_engine_tick(&engine) & 1;
            before += s;
            e += i - (s ? SIGMA : 0);
            i += d;
            d += m.r[0];
        }
        TEST_ASSERT_EQUAL_INT(0, engine.trigger_window);
        e_h = tp_floor_div(e, 512);
        i1 = i / 512;
        dd = -(decel >> 2);
        stop = (i1 + (-dd) - 1) / (-dd);
        for (j = 1; j <= stop; j++) {
            int64_t expect = tp_floor_div(e_h + j * i1 + dd * (j * (j - 1) / 2) + w / 2, w);
            made += qs_engine_tick(&engine) & 1;
            TEST_ASSERT_EQUAL_INT64(expect, made);
            if (j % 61 == 0) {
                /* a STATUS mid-hold: the steps worked out from the hold's state */
                qs_engine_view v;
                qs_engine_read(&engine, &v);
                TEST_ASSERT_EQUAL_INT32(before + made, v.position[0]);
                TEST_ASSERT_EQUAL_UINT32(held_at + QS_TRIGGER_TICKS + j, v.motion_ticks);
            }
        }
        TEST_ASSERT_EQUAL_UINT8(0, engine.hold.moving);
        qs_engine_retire(&engine);
        TEST_ASSERT_EQUAL_INT32(before + made, engine.base[0]);
        TEST_ASSERT_EQUAL_UINT8(QS_STATE_IDLE, engine.state);
        /* the chain starts again at rest */
        TEST_ASSERT_EQUAL_UINT32(0, engine.chain.i[0]);
    }
}

/* Slots are reused round the ring: a quadratic segment prepared into the slot
 * a cubic one ran in runs as a quadratic segment (its closed form), not on
 * the cubic path with what that slot held. */
static void test_a_quadratic_segment_after_a_cubic_one_in_the_same_slot(void)
{
    qs_cubic_msg m = rest_msg(200);
    qs_segment_msg q = {0};
    uint32_t made = 0;
    uint16_t t;
    qs_fault f;

    qs_engine_init(&engine, 2); /* two slots: the third segment reuses the cubic one's */
    m.set = 0x01;
    m.speed[0] = 0x10000000u; /* 1/8 step per tick: 25 steps */
    TEST_ASSERT_EQUAL_INT(QS_ERR_NONE, qs_cubic_prepare(&engine.chain, qs_queue_back(&engine.queue), &m, 4, &f));
    qs_queue_publish(&engine.queue);
    q.n = 100;
    q.active = 0x01;
    q.v0[0] = 2048; /* then half a step per tick: 50 steps */
    q.vn[0] = 2048;
    qs_segment_prepare(qs_queue_back(&engine.queue), &q);
    qs_cubic_follow_quadratic(&engine.chain, qs_queue_back(&engine.queue), &q);
    qs_queue_publish(&engine.queue);
    qs_engine_wake(&engine);
    for (t = 0; t < 201; t++)
        made += qs_engine_tick(&engine) & 1;
    qs_engine_retire(&engine);
    TEST_ASSERT_EQUAL_UINT32(1, qs_queue_free(&engine.queue));
    q.vn[0] = 0; /* and to rest: 25 steps, in the slot the cubic segment ran in */
    qs_segment_prepare(qs_queue_back(&engine.queue), &q);
    qs_cubic_follow_quadratic(&engine.chain, qs_queue_back(&engine.queue), &q);
    qs_queue_publish(&engine.queue);
    for (t = 0; t < 200; t++)
        made += qs_engine_tick(&engine) & 1;
    qs_engine_retire(&engine);
    TEST_ASSERT_EQUAL_UINT8(QS_STATE_IDLE, engine.state);
    TEST_ASSERT_EQUAL_UINT32(100, made);
    TEST_ASSERT_EQUAL_INT32(100, engine.base[0]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_a_quadratic_segment_after_a_cubic_one_in_the_same_slot);
    RUN_TEST(test_validation_names_the_field_and_changes_nothing);
    RUN_TEST(test_positions_read_mid_segment_match_the_steps_made);
    RUN_TEST(test_a_hold_from_a_cubic_state_follows_its_closed_form);
    RUN_TEST(test_every_segment_at_sigma_2_7_with_8_bit_arithmetic);
    RUN_TEST(test_a_million_random_chained_segments_do_not_drift);
    return UNITY_END();
}
