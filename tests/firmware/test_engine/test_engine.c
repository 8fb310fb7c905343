/* The step engine against exact integer arithmetic: every tick of every
 * segment is compared with the ideal curve and with the closed form of
 * PROTOCOL.md section 8; the per-tick values are checked against the
 * 24-bit budget; validation is checked to refuse everything outside it. */
#include <stdint.h>
#include <stdio.h>

#include "qs_engine_tick.h"
#include "qs_messages.h"
#include "qs_test_support.h"
#include "unity.h"

#define D 4096
#define BOUND (2L * QS_N_MAX * D + 3L * D) /* 8,384,512 */

static qs_engine engine;

void setUp(void)
{
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    tp_seed(0x9E3779B97F4A7C15ull);
}

void tearDown(void)
{
}

/* A speed that is often an extreme. */
static uint16_t rnd_speed(void)
{
    static const uint16_t extremes[] = {0, 1, 4095, 4096};
    return tp_rand(3) ? (uint16_t)tp_rand(4097) : extremes[tp_rand(4)];
}

static uint16_t rnd_n(void)
{
    static const uint16_t extremes[] = {1, 2, 1021, 1022};
    return tp_rand(4) ? (uint16_t)(1 + tp_rand(QS_N_MAX)) : extremes[tp_rand(4)];
}

static int16_t rnd_residual(uint16_t v0, uint16_t vn)
{
    static const int16_t extremes[] = {-4096, -4095, 0, 4095, 4096};
    int16_t r = tp_rand(3) ? (int16_t)((int32_t)tp_rand(8193) - 4096) : extremes[tp_rand(5)];
    if (r == 4096 && v0 == 4096 && vn == 4096)
        r = 4095; /* the one excluded input */
    return r;
}

static void enqueue(const qs_segment_msg *m)
{
    qs_fault f;
    TEST_ASSERT_EQUAL_INT_MESSAGE(QS_ERR_NONE, qs_msg_check_segment(m, QS_AXIS_COUNT, &f),
                                  "test generated an invalid segment");
    TEST_ASSERT_TRUE(qs_queue_free(&engine.queue) > 0);
    qs_segment_prepare(qs_queue_back(&engine.queue), m);
    qs_queue_publish(&engine.queue);
    qs_engine_wake(&engine);
}

static void random_segment(qs_segment_msg *m, uint8_t active)
{
    uint8_t axis;
    m->n = rnd_n();
    m->active = active;
    m->negative = (uint8_t)(tp_rand(16) & active);
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
        m->v0[axis] = m->vn[axis] = 0;
        m->r[axis] = 0;
        if (!(active & (1u << axis)))
            continue;
        m->v0[axis] = rnd_speed();
        m->vn[axis] = rnd_speed();
        m->r[axis] = rnd_residual(m->v0[axis], m->vn[axis]);
    }
}

/* Run one queued segment to its end, checking every tick of every active
 * axis; with check_reads, also the positions the main loop reads mid-way.
 * steps[] accumulates the steps made (signed). */
static void run_checked(const qs_segment_msg *m, int check_reads, int32_t *position)
{
    int32_t start[QS_AXIS_COUNT];
    int64_t made[QS_AXIS_COUNT] = {0};
    uint8_t axis;
    uint16_t t;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        start[axis] = position[axis];
    for (t = 1; t <= m->n; t++) {
        uint8_t bits = qs_engine_tick(&engine);
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(0, bits & ~m->active, "an inactive axis stepped");
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            int64_t n2d = 2LL * m->n * D;
            int64_t err;
            if (!(m->active & (1u << axis)))
                continue;
            if (bits & (1u << axis)) {
                int negative = (engine.dir_bits >> axis) & 1;
                TEST_ASSERT_EQUAL_INT_MESSAGE((m->negative >> axis) & 1, negative,
                                              "step with the wrong direction");
                made[axis]++;
                position[axis] += negative ? -1 : 1;
            }
            /* Within half a step of the ideal curve, and what the host predicts. */
            err = made[axis] * n2d - tp_ideal_2nd(m, axis, t);
            TEST_ASSERT_LESS_OR_EQUAL_INT64(m->n * (int64_t)D, err);
            TEST_ASSERT_GREATER_OR_EQUAL_INT64(-m->n * (int64_t)D, err);
            TEST_ASSERT_EQUAL_INT64(tp_closed_form(m, axis, t), made[axis]);
        }
        if (check_reads) {
            qs_engine_view v;
            qs_engine_read(&engine, &v);
            for (axis = 0; axis < QS_AXIS_COUNT; axis++)
                TEST_ASSERT_EQUAL_INT32(position[axis], v.position[axis]);
        }
    }
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        int32_t expect = (int32_t)tp_closed_form(m, axis, m->n);
        if (!(m->active & (1u << axis)))
            expect = 0;
        if ((m->negative >> axis) & 1)
            expect = -expect;
        TEST_ASSERT_EQUAL_INT32(start[axis] + expect, position[axis]);
    }
}

static void test_random_segments_follow_the_ideal_curve_and_the_closed_form(void)
{
    int32_t position[QS_AXIS_COUNT] = {0};
    qs_engine_view v;
    uint8_t axis;
    int i;
    uint32_t held = 0;

    for (i = 0; i < 4000; i++) {
        qs_segment_msg m;
        random_segment(&m, (uint8_t)(1 + tp_rand((1u << QS_AXIS_COUNT) - 1)));
        enqueue(&m);
        run_checked(&m, i % 8 == 0, position);
        /* A segment that ends moving keeps its slot for a hold from its end. */
        TEST_ASSERT_EQUAL_INT(engine.kept, qs_queue_count(&engine.queue));
        TEST_ASSERT_EQUAL_INT(engine.kept, engine.state == QS_STATE_RUNNING);
        /* The segment ended at rest or not: the next tick settles, or holds. */
        if (engine.state == QS_STATE_RUNNING) {
            const uint8_t bits = qs_engine_tick(&engine);
            held += engine.state == QS_STATE_HOLDING; /* a STOP during it: the held one is not done */
            TEST_ASSERT_TRUE(engine.state == QS_STATE_HOLDING || engine.state == QS_STATE_ALARM);
            for (axis = 0; axis < QS_AXIS_COUNT; axis++)
                if ((bits >> axis) & 1)
                    position[axis] += ((engine.dir_bits >> axis) & 1) ? -1 : 1;
        }
        qs_engine_halt(&engine, QS_STATE_IDLE, QS_ALARM_NONE);
    }
    qs_engine_read(&engine, &v);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        TEST_ASSERT_EQUAL_INT32(position[axis], v.position[axis]);
    TEST_ASSERT_EQUAL_UINT32(4000 - held, v.segments_done);
    TEST_ASSERT_TRUE(held > 1000);
}

/* The host side of a chain: the ideal position in 1/8192 step, carried
 * exactly, gives each segment's residual. */
static void test_long_chains_carry_the_residual_without_drift(void)
{
    int64_t ideal[QS_AXIS_COUNT] = {0}; /* 1/8192 step */
    int32_t position[QS_AXIS_COUNT] = {0};
    uint32_t ticks = 0;
    qs_engine_view v;
    uint8_t axis;
    int i;

    for (i = 0; i < 3000; i++) {
        qs_segment_msg m;
        random_segment(&m, (1u << QS_AXIS_COUNT) - 1);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            int sigma = ((m.negative >> axis) & 1) ? -1 : 1;
            int64_t r = sigma * (ideal[axis] - 8192LL * position[axis]);
            TEST_ASSERT_LESS_OR_EQUAL_INT64(4096, r);
            TEST_ASSERT_GREATER_OR_EQUAL_INT64(-4096, r);
            m.r[axis] = (int16_t)r;
            if (r == 4096 && m.v0[axis] == 4096 && m.vn[axis] == 4096)
                m.vn[axis] = 4095; /* what a host does with the excluded input */
            ideal[axis] += sigma * (int64_t)m.n * (m.v0[axis] + m.vn[axis]);
        }
        /* Keep the queue busy so segments run back to back. */
        enqueue(&m);
        run_checked(&m, i % 16 == 0, position);
        ticks += m.n;
        TEST_ASSERT_TRUE(engine.state != QS_STATE_ALARM);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            int64_t off = ideal[axis] - 8192LL * position[axis];
            TEST_ASSERT_LESS_OR_EQUAL_INT64(4096, off);
            TEST_ASSERT_GREATER_OR_EQUAL_INT64(-4096, off);
        }
    }
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
    /* The last one counts once the next begins, or its hold ends. */
    TEST_ASSERT_EQUAL_UINT32(3000 - engine.kept, v.segments_done);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        TEST_ASSERT_EQUAL_INT32(position[axis], v.position[axis]);
}

/* Queued segments run back to back: the first decision of each happens on
 * the tick after the last of the one before, and the direction changes
 * only with that first decision. */
static void test_queued_segments_run_back_to_back_with_their_own_direction(void)
{
    qs_segment_msg a = {0}, b = {0};
    uint32_t calls = 0;
    uint8_t bits;

    a.n = 3; a.active = 1; a.v0[0] = 4096; a.vn[0] = 4096;            /* +3 steps */
    b.n = 2; b.active = 1; b.negative = 1; b.v0[0] = 4096; b.vn[0] = 4096; /* -2 steps */
    enqueue(&a);
    enqueue(&b);
    while (calls < 3) {
        bits = qs_engine_tick(&engine);
        calls++;
        TEST_ASSERT_EQUAL_HEX8(1, bits);
        TEST_ASSERT_EQUAL_HEX8(0, engine.dir_bits & 1);
    }
    bits = qs_engine_tick(&engine);
    TEST_ASSERT_EQUAL_HEX8(1, bits);
    TEST_ASSERT_EQUAL_HEX8(1, engine.dir_bits & 1);
    bits = qs_engine_tick(&engine);
    TEST_ASSERT_EQUAL_HEX8(1, bits);
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, engine.state); /* b ended moving */
    TEST_ASSERT_TRUE(engine.kept);
    bits = qs_engine_tick(&engine); /* an underrun: the hold's first tick, at b's end speed */
    TEST_ASSERT_EQUAL_HEX8(1, bits);
    TEST_ASSERT_EQUAL_HEX8(1, engine.dir_bits & 1);
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, engine.state);
    while (engine.state == QS_STATE_HOLDING) {
        qs_engine_tick(&engine);
        qs_engine_retire(&engine);
    }
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, engine.state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, engine.alarm);
}

/* Every n, and every extreme of speed and residual: no per-tick value, not
 * even the intermediate of the no-step branch, leaves +-(2nD + 3D), and for
 * n = 1022 the bound is reached. */
static void test_per_tick_values_stay_within_24_bits(void)
{
    static const uint16_t speeds[] = {0, 1, 2048, 4095, 4096};
    static const int16_t residuals[] = {-4096, -4095, -1, 0, 1, 4095, 4096};
    int64_t worst_1022 = 0;
    uint16_t n;
    unsigned i, j, k;

    for (n = 1; n <= QS_N_MAX; n++) {
        int64_t bound = 2L * n * D + 3L * D;
        for (i = 0; i < 5; i++)
            for (j = 0; j < 5; j++)
                for (k = 0; k < 7; k++) {
                    qs_segment_msg m = {0};
                    qs_segment *s;
                    uint16_t t;
                    m.n = n;
                    m.active = 1;
                    m.v0[0] = speeds[i];
                    m.vn[0] = speeds[j];
                    m.r[0] = residuals[k];
                    if (m.r[0] == 4096 && m.v0[0] == 4096 && m.vn[0] == 4096)
                        continue;
                    enqueue(&m);
                    s = qs_queue_front(&engine.queue);
                    for (t = 0; t < n; t++) {
                        int64_t h = s->h[0], b = s->b[0];
                        int64_t worst = h < 0 ? -h : h;
                        if (h < 0 && h + s->two_c2 > worst)
                            worst = h + s->two_c2;
                        if ((b < 0 ? -b : b) > worst)
                            worst = b < 0 ? -b : b;
                        TEST_ASSERT_LESS_OR_EQUAL_INT64(bound, worst);
                        if (n == QS_N_MAX && worst > worst_1022)
                            worst_1022 = worst;
                        qs_engine_tick(&engine);
                    }
                    /* The state after the last tick is never used again but
                     * was computed: it too stays in range (b reaches the
                     * bound here, when v0 = 4096 and vn = 0). */
                    {
                        int64_t h = s->h[0], b = s->b[0];
                        int64_t worst = h < 0 ? -h : h;
                        if ((b < 0 ? -b : b) > worst)
                            worst = b < 0 ? -b : b;
                        TEST_ASSERT_LESS_OR_EQUAL_INT64(bound, worst);
                        if (n == QS_N_MAX && worst > worst_1022)
                            worst_1022 = worst;
                    }
                    if (engine.state != QS_STATE_IDLE)
                        qs_engine_halt(&engine, QS_STATE_IDLE, QS_ALARM_NONE);
                    qs_engine_retire(&engine);
                }
    }
    TEST_ASSERT_EQUAL_INT64(BOUND, worst_1022);
    TEST_ASSERT_TRUE(BOUND < (1L << 23));
}

/* Validation is the other half of the range argument: it refuses every
 * value outside the ranges the bound assumes, field by field. */
static void test_validation_refuses_everything_outside_the_ranges(void)
{
    qs_segment_msg m = {0};
    qs_fault f;
    int32_t x;

    m.n = 1;
    m.active = 1;
    for (x = 0; x <= 0xFFFF; x++) {
        m.n = (uint16_t)x;
        TEST_ASSERT_EQUAL_INT(x >= 1 && x <= QS_N_MAX ? QS_ERR_NONE : QS_ERR_BAD_FIELD,
                              qs_msg_check_segment(&m, 4, &f));
        if (f.code == QS_ERR_BAD_FIELD)
            TEST_ASSERT_EQUAL_INT(QS_FIELD_N, f.field);
    }
    m.n = QS_N_MAX;
    for (x = 0; x <= 0xFFFF; x++) {
        m.v0[0] = (uint16_t)x;
        TEST_ASSERT_EQUAL_INT(x <= 4096 ? QS_ERR_NONE : QS_ERR_BAD_FIELD, qs_msg_check_segment(&m, 4, &f));
        if (x > 4096) {
            TEST_ASSERT_EQUAL_INT(QS_FIELD_V0, f.field);
            TEST_ASSERT_EQUAL_INT(0, f.axis);
        }
    }
    m.v0[0] = 0;
    for (x = 0; x <= 0xFFFF; x++) {
        m.vn[0] = (uint16_t)x;
        TEST_ASSERT_EQUAL_INT(x <= 4096 ? QS_ERR_NONE : QS_ERR_BAD_FIELD, qs_msg_check_segment(&m, 4, &f));
        if (x > 4096)
            TEST_ASSERT_EQUAL_INT(QS_FIELD_VN, f.field);
    }
    for (x = -32768; x <= 32767; x++) {
        m.r[0] = (int16_t)x;
        m.v0[0] = m.vn[0] = 4096;
        TEST_ASSERT_EQUAL_INT(x >= -4096 && x < 4096 ? QS_ERR_NONE : QS_ERR_BAD_FIELD,
                              qs_msg_check_segment(&m, 4, &f));
        m.vn[0] = 4095;
        TEST_ASSERT_EQUAL_INT(x >= -4096 && x <= 4096 ? QS_ERR_NONE : QS_ERR_BAD_FIELD,
                              qs_msg_check_segment(&m, 4, &f));
        if (f.code == QS_ERR_BAD_FIELD)
            TEST_ASSERT_EQUAL_INT(QS_FIELD_RESIDUAL, f.field);
    }
    /* Axes and directions. */
    m.r[0] = 0;
    m.active = 0x08;
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, qs_msg_check_segment(&m, 3, &f));
    TEST_ASSERT_EQUAL_INT(QS_FIELD_AXES, f.field);
    TEST_ASSERT_EQUAL_INT(QS_AXIS_NONE, f.axis);
    TEST_ASSERT_EQUAL_INT(QS_ERR_NONE, qs_msg_check_segment(&m, 4, &f));
    m.active = 0x01;
    m.negative = 0x02;
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, qs_msg_check_segment(&m, 4, &f));
    TEST_ASSERT_EQUAL_INT(QS_FIELD_DIRECTION, f.field);
}

/* The main loop recovers the steps made and the current speed from the
 * running state; both agree with counting and with v(t) at every tick. */
static void test_steps_and_speed_are_recovered_from_the_running_state(void)
{
    int i;
    for (i = 0; i < 300; i++) {
        qs_segment_msg m;
        qs_segment *s;
        uint16_t made[QS_AXIS_COUNT] = {0};
        uint16_t t;
        uint8_t axis;

        random_segment(&m, (1u << QS_AXIS_COUNT) - 1);
        enqueue(&m);
        s = qs_queue_front(&engine.queue);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            TEST_ASSERT_EQUAL_UINT16(0, qs_segment_steps(s, axis, 0));
        for (t = 1; t <= m.n; t++) {
            uint8_t bits = qs_engine_tick(&engine);
            for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
                if (bits & (1u << axis))
                    made[axis]++;
                TEST_ASSERT_EQUAL_UINT16(made[axis], qs_segment_steps(s, axis, t));
                if (t < m.n)
                    TEST_ASSERT_EQUAL_INT32(2L * m.n * m.v0[axis] + 2L * t * ((int32_t)m.vn[axis] - m.v0[axis]),
                                            qs_engine_speed_2n_locked(&engine, axis));
            }
        }
        qs_engine_halt(&engine, QS_STATE_IDLE, QS_ALARM_NONE);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_random_segments_follow_the_ideal_curve_and_the_closed_form);
    RUN_TEST(test_long_chains_carry_the_residual_without_drift);
    RUN_TEST(test_queued_segments_run_back_to_back_with_their_own_direction);
    RUN_TEST(test_per_tick_values_stay_within_24_bits);
    RUN_TEST(test_validation_refuses_everything_outside_the_ranges);
    RUN_TEST(test_steps_and_speed_are_recovered_from_the_running_state);
    return UNITY_END();
}
