/* The inputs (qs_inputs.h) and their latches (qs_latch.h), driven tick by
 * tick as the emulator drives them: each input's polarity and debounce,
 * latched positions equal to the steps counted here at any moment (in a
 * segment, between segments, in a hold, at rest), a hard limit leaving no
 * step after its tick, and an armed trigger beginning, QS_TRIGGER_TICKS
 * decisions after its latch, exactly the hold a HOLD at that tick would. */
#include <stdint.h>
#include <string.h>

#include "qs_engine_tick.h"
#include "qs_inputs_tick.h"
#include "qs_messages.h"
#include "qs_test_support.h"
#include "unity.h"

#define D 4096
#define IDLE_RAW 0x0FFFu /* every pin high: nothing active (active low) */
#define BIT(i) ((uint16_t)(1u << (i)))

typedef struct {
    qs_engine e;
    qs_inputs in;
    uint16_t seen;                 /* the last sample */
    uint32_t ticks;                /* motion ticks, by the emulator's rule */
    int32_t position[QS_AXIS_COUNT]; /* steps counted from the tick's output */
} rig;

static rig a, b;
static const uint16_t decel4[4] = {300, 700, 1500, 4000};

void setUp(void)
{
    tp_seed(0x9E3779B97F4A7C15ull);
}

void tearDown(void)
{
    tp_check_unlocked();
}

static void rig_init(rig *r)
{
    memset(r, 0, sizeof *r);
    qs_engine_init(&r->e, QS_QUEUE_CAPACITY);
    qs_inputs_init(&r->in, QS_INPUTS_ALL);
    r->seen = QS_INPUTS_RESAMPLE;
}

static void enqueue(rig *r, const qs_segment_msg *m)
{
    qs_fault f;
    TEST_ASSERT_EQUAL_INT(QS_ERR_NONE, qs_msg_check_segment(m, QS_AXIS_COUNT, &f));
    qs_engine_retire(&r->e);
    TEST_ASSERT_TRUE(qs_queue_free(&r->e.queue) > 0);
    qs_segment_prepare(qs_queue_back(&r->e.queue), m);
    qs_queue_publish(&r->e.queue);
    qs_engine_wake(&r->e);
}

static void steady(qs_segment_msg *m, uint16_t n, uint16_t v0, uint16_t vn, uint8_t negative)
{
    uint8_t axis;
    memset(m, 0, sizeof *m);
    m->n = n;
    m->active = (uint8_t)((1u << QS_AXIS_COUNT) - 1);
    m->negative = negative;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        m->v0[axis] = (uint16_t)(v0 >> axis);
        m->vn[axis] = (uint16_t)(vn >> axis);
    }
}

/* One tick as the emulator runs it: sample, decide, count. Returns the
 * step bits. */
static uint8_t tick(rig *r, uint16_t raw)
{
    const uint16_t left = r->e.left;
    const uint8_t tail = r->e.queue.tail;
    uint8_t bits, axis;

    qs_inputs_tick(&r->in, &r->e, &r->seen, raw);
    bits = qs_engine_tick(&r->e);
    if (left != 0 || r->e.left != 0 || r->e.queue.tail != tail)
        r->ticks++;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        if (bits & (1u << axis))
            r->position[axis] += ((r->e.dir_bits >> axis) & 1) ? -1 : 1;
    qs_engine_retire(&r->e);
    return bits;
}

static void run(rig *r, uint32_t n, uint16_t raw)
{
    while (n--)
        tick(r, raw);
}

static void assert_latch(rig *r, uint32_t tick_at, const int32_t *position, uint16_t changed, uint8_t cause)
{
    const qs_latch *l = qs_engine_oldest_latch(&r->e);
    uint8_t axis;
    TEST_ASSERT_TRUE_MESSAGE(l != 0, "no latch");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(tick_at, l->u.at.tick, "latched tick");
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        TEST_ASSERT_EQUAL_INT32_MESSAGE(position[axis], l->u.at.position[axis], "latched position");
    TEST_ASSERT_EQUAL_HEX16(changed, l->changed);
    TEST_ASSERT_EQUAL_INT(cause, l->cause);
    qs_engine_free_latch(&r->e);
}

static void assert_positions(const int32_t *expected, const int32_t *actual, uint8_t count)
{
    uint8_t axis;
    for (axis = 0; axis < count; axis++)
        TEST_ASSERT_EQUAL_INT32(expected[axis], actual[axis]);
}

static void assert_no_latch(rig *r)
{
    TEST_ASSERT_TRUE_MESSAGE(qs_engine_oldest_latch(&r->e) == 0, "unexpected latch");
}

/* ---- tests ---- */

static void test_each_input_is_active_low_unless_inverted(void)
{
    uint8_t input, invert;
    for (input = 0; input < QS_INPUT_COUNT; input++) {
        for (invert = 0; invert < 2; invert++) {
            const uint8_t zero[QS_INPUT_COUNT] = {0};
            const uint16_t idle = invert ? (uint16_t)(IDLE_RAW & ~BIT(input)) : IDLE_RAW;
            const int32_t here[QS_AXIS_COUNT] = {0};
            rig_init(&a);
            qs_inputs_configure(&a.in, &a.e, invert ? BIT(input) : 0, QS_INPUTS_ALL, 0, zero, decel4);
            run(&a, 3, idle);
            TEST_ASSERT_FALSE(qs_inputs_is_active(&a.in, input));
            run(&a, 1, (uint16_t)(idle ^ BIT(input)));
            TEST_ASSERT_TRUE(qs_inputs_is_active(&a.in, input));
            TEST_ASSERT_EQUAL_HEX16(BIT(input), a.in.active);
            assert_latch(&a, 0, here, BIT(input),
                         input == QS_INPUT_ABORT        ? QS_CAUSE_E_STOP
                         : input == QS_INPUT_FEED_HOLD  ? QS_CAUSE_FEED_HOLD
                         : input == QS_INPUT_CYCLE_START ? QS_CAUSE_CYCLE_START
                                                         : QS_CAUSE_REPORT);
            run(&a, 1, idle);
            TEST_ASSERT_FALSE(qs_inputs_is_active(&a.in, input));
        }
    }
}

static void test_an_input_closed_at_power_up_is_a_state_not_an_edge(void)
{
    rig_init(&a);
    run(&a, 5, (uint16_t)(IDLE_RAW & ~BIT(QS_INPUT_LIMIT)));
    TEST_ASSERT_TRUE(qs_inputs_is_active(&a.in, QS_INPUT_LIMIT));
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, a.e.state);
    assert_no_latch(&a);
}

/* A glitch shorter than the debounce is dropped; an edge that bounces
 * inside it is accepted when the window closes, latched at its first edge. */
static void test_debounce_drops_glitches_and_latches_the_first_edge(void)
{
    static const uint8_t windows[] = {1, 3, 10, 255};
    uint8_t w;
    for (w = 0; w < sizeof windows; w++) {
        uint8_t debounce[QS_INPUT_COUNT] = {0};
        const uint16_t probe = BIT(QS_INPUT_PROBE);
        const uint8_t d = windows[w];
        int32_t at_edge[QS_AXIS_COUNT];
        uint32_t edge_tick;
        qs_segment_msg m;
        uint32_t k;

        rig_init(&a);
        debounce[QS_INPUT_PROBE] = d;
        qs_inputs_configure(&a.in, &a.e, 0, QS_INPUTS_ALL, 1, debounce, decel4);
        steady(&m, 1000, 1500, 1500, 0x2);
        enqueue(&a, &m);
        enqueue(&a, &m);
        run(&a, 100, IDLE_RAW);
        /* A glitch of d - 1 ticks. */
        if (d > 1) {
            run(&a, (uint32_t)(d - 1), IDLE_RAW & ~probe);
            run(&a, 50, IDLE_RAW);
            TEST_ASSERT_FALSE(qs_inputs_is_active(&a.in, QS_INPUT_PROBE));
            assert_no_latch(&a);
        }
        /* A real edge, bouncing through the window. */
        memcpy(at_edge, a.position, sizeof at_edge);
        edge_tick = a.ticks;
        for (k = 0; k < d; k++) {
            TEST_ASSERT_FALSE(qs_inputs_is_active(&a.in, QS_INPUT_PROBE));
            tick(&a, (k % 3 == 1 && k + 1 < d) ? IDLE_RAW : (uint16_t)(IDLE_RAW & ~probe));
        }
        run(&a, 1, IDLE_RAW & ~probe);
        TEST_ASSERT_TRUE(qs_inputs_is_active(&a.in, QS_INPUT_PROBE));
        assert_latch(&a, edge_tick, at_edge, probe, QS_CAUSE_REPORT);
        assert_no_latch(&a);
    }
}

/* Latches at random ticks of random chains, in holds and between
 * segments, equal the steps counted at that tick. */
static void test_latched_positions_are_exact_at_any_tick(void)
{
    uint16_t round;
    for (round = 0; round < 300; round++) {
        qs_segment_msg m;
        uint16_t edges = 0, toggle = IDLE_RAW;
        uint8_t i, held = 0;
        rig_init(&a);
        tick(&a, toggle); /* the power-up sample */
        for (i = 0; i < 6; i++) {
            steady(&m, (uint16_t)(1 + tp_rand(QS_N_MAX)), (uint16_t)tp_rand(D + 1), (uint16_t)tp_rand(D + 1),
                   (uint8_t)tp_rand(16) & 0xF);
            if (i == 5)
                for (uint8_t axis = 0; axis < QS_PROTOCOL_AXES; axis++)
                    m.vn[axis] = 0;
            enqueue(&a, &m);
        }
        while (a.e.state == QS_STATE_RUNNING || a.e.state == QS_STATE_HOLDING) {
            if (tp_rand(97) == 0) {
                int32_t at[QS_AXIS_COUNT];
                const uint32_t t = a.ticks;
                memcpy(at, a.position, sizeof at);
                toggle ^= BIT(QS_INPUT_PROBE);
                tick(&a, toggle);
                assert_latch(&a, t, at, BIT(QS_INPUT_PROBE), QS_CAUSE_REPORT);
                edges++;
            } else {
                tick(&a, toggle);
            }
            if (!held && tp_rand(3000) == 0) {
                qs_engine_hold(&a.e, decel4, 0);
                held = 1;
            }
        }
        TEST_ASSERT_TRUE(edges < 1000);
    }
}

static void test_a_hard_limit_leaves_no_step_after_its_tick(void)
{
    uint8_t axis;
    for (axis = 0; axis < QS_AXIS_COUNT * 2; axis++) {
        const uint16_t limit = BIT(QS_INPUT_LIMIT + axis);
        qs_segment_msg m;
        int32_t at[QS_AXIS_COUNT];
        uint32_t t;
        qs_engine_view v;
        rig_init(&a);
        steady(&m, 1000, D, D, 0x5);
        enqueue(&a, &m);
        enqueue(&a, &m);
        run(&a, 300 + 37 * axis, IDLE_RAW);
        memcpy(at, a.position, sizeof at);
        t = a.ticks;
        TEST_ASSERT_EQUAL_INT(0, tick(&a, IDLE_RAW & ~limit));
        TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, a.e.state);
        TEST_ASSERT_EQUAL_INT(QS_ALARM_HARD_LIMIT, a.e.alarm);
        run(&a, 2000, IDLE_RAW & ~limit);
        assert_positions(at, a.position, QS_AXIS_COUNT);
        qs_engine_finish_freeze(&a.e);
        qs_engine_read(&a.e, &v);
        assert_positions(at, v.position, QS_AXIS_COUNT);
        TEST_ASSERT_EQUAL_UINT32(t, v.motion_ticks);
        TEST_ASSERT_EQUAL_INT(0, v.queue_fill);
        assert_latch(&a, t, at, limit, QS_CAUSE_HARD_LIMIT);
    }
}

static void test_hard_limits_can_be_disabled(void)
{
    const uint8_t zero[QS_INPUT_COUNT] = {0};
    qs_segment_msg m;
    rig_init(&a);
    qs_inputs_configure(&a.in, &a.e, 0, QS_INPUTS_ALL, 0, zero, decel4);
    steady(&m, 500, D, 0, 0);
    enqueue(&a, &m);
    run(&a, 100, IDLE_RAW);
    run(&a, 100, IDLE_RAW & ~BIT(QS_INPUT_LIMIT + 1));
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, a.e.state);
}

static void test_abort_freezes_even_during_a_hold(void)
{
    qs_segment_msg m;
    int32_t at[QS_AXIS_COUNT];
    uint32_t t;
    rig_init(&a);
    steady(&m, 1000, D, D, 0);
    enqueue(&a, &m);
    enqueue(&a, &m);
    run(&a, 200, IDLE_RAW);
    qs_engine_hold(&a.e, decel4, 0);
    run(&a, 100, IDLE_RAW);
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, a.e.state);
    memcpy(at, a.position, sizeof at);
    t = a.ticks;
    TEST_ASSERT_EQUAL_INT(0, tick(&a, IDLE_RAW & ~BIT(QS_INPUT_ABORT)));
    run(&a, 500, IDLE_RAW & ~BIT(QS_INPUT_ABORT));
    assert_positions(at, a.position, QS_AXIS_COUNT);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_E_STOP, a.e.alarm);
    assert_latch(&a, t, at, BIT(QS_INPUT_ABORT), QS_CAUSE_E_STOP);
}

/* The trigger's hold begins QS_TRIGGER_TICKS decisions after its latch
 * (the motion runs on meanwhile, across segment ends too) and is the hold a
 * HOLD at that tick boundary begins: the same steps, the queue behind it
 * dropped, and hold_tick that boundary's. */
static void test_an_armed_edge_begins_the_hold_a_hold_at_that_tick_would(void)
{
    uint16_t round;
    for (round = 0; round < 200; round++) {
        const uint8_t input = (uint8_t)(round % 2 ? QS_INPUT_PROBE : QS_INPUT_LIMIT + tp_rand(QS_AXIS_COUNT));
        const uint32_t at_tick = 1 + tp_rand(2500);
        qs_segment_msg m;
        uint32_t hold_tick = 0;
        uint8_t i;
        rig_init(&a);
        rig_init(&b);
        qs_engine_arm_trigger(&a.e, input, 1, decel4);
        for (i = 0; i < 4; i++) {
            steady(&m, (uint16_t)(200 + tp_rand(800)), (uint16_t)tp_rand(D + 1), (uint16_t)tp_rand(D + 1),
                   (uint8_t)tp_rand(16));
            enqueue(&a, &m);
            enqueue(&b, &m);
        }
        while (a.ticks < at_tick && a.e.state == QS_STATE_RUNNING) {
            TEST_ASSERT_EQUAL_HEX8(tick(&b, IDLE_RAW), tick(&a, IDLE_RAW));
        }
        if (a.e.state != QS_STATE_RUNNING)
            continue;
        {
            int32_t at[QS_AXIS_COUNT];
            const uint32_t t = a.ticks;
            uint8_t k;
            memcpy(at, a.position, sizeof at);
            /* A HOLD at that tick takes the same window. */
            qs_engine_hold(&b.e, decel4, 0);
            for (k = 0; k < QS_TRIGGER_TICKS && b.e.state == QS_STATE_RUNNING; k++) {
                TEST_ASSERT_EQUAL_HEX8(tick(&b, IDLE_RAW), tick(&a, IDLE_RAW & ~BIT(input)));
            }
            if (a.e.state != QS_STATE_HOLDING)
                continue; /* the motion ended inside the window */
            TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, b.e.state);
            while (b.e.state == QS_STATE_HOLDING) {
                TEST_ASSERT_EQUAL_HEX8(tick(&b, IDLE_RAW), tick(&a, IDLE_RAW & ~BIT(input)));
            }
            run(&a, 3, IDLE_RAW & ~BIT(input));
            TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, a.e.state);
            assert_positions(b.position, a.position, QS_AXIS_COUNT);
            TEST_ASSERT_EQUAL_INT(0, qs_queue_count(&a.e.queue));
            assert_latch(&a, t, at, BIT(input), QS_CAUSE_TRIGGER);
            TEST_ASSERT_TRUE(qs_engine_take_hold_done(&a.e, &hold_tick));
            TEST_ASSERT_EQUAL_UINT32(t + QS_TRIGGER_TICKS, hold_tick);
            TEST_ASSERT_FALSE(a.e.trigger);
        }
    }
}

/* While armed on one limit, that limit ends the motion and the others
 * still alarm; release (level 0) works the same way. */
static void test_the_armed_limit_is_no_alarm_but_the_others_are(void)
{
    qs_segment_msg m;
    rig_init(&a);
    run(&a, 1, IDLE_RAW & ~BIT(QS_INPUT_LIMIT + 2)); /* axis 2's switch closed already */
    qs_engine_arm_trigger(&a.e, QS_INPUT_LIMIT + 2, 0, decel4);
    steady(&m, 800, 2000, 2000, 0);
    enqueue(&a, &m);
    enqueue(&a, &m);
    run(&a, 100, IDLE_RAW & ~BIT(QS_INPUT_LIMIT + 2));
    run(&a, QS_TRIGGER_TICKS, IDLE_RAW); /* released: the hold begins, and runs to rest */
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, a.e.state);
    while (a.e.state == QS_STATE_HOLDING)
        tick(&a, IDLE_RAW);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, a.e.state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, a.e.alarm);

    rig_init(&a);
    qs_engine_arm_trigger(&a.e, QS_INPUT_LIMIT, 1, decel4);
    steady(&m, 800, 2000, 2000, 0);
    enqueue(&a, &m);
    run(&a, 100, IDLE_RAW);
    run(&a, 1, IDLE_RAW & ~BIT(QS_INPUT_LIMIT + 1));
    TEST_ASSERT_EQUAL_INT(QS_ALARM_HARD_LIMIT, a.e.alarm);
}

static void test_a_trigger_with_nothing_moving_asks_the_main_loop(void)
{
    rig_init(&a);
    run(&a, 2, IDLE_RAW);
    qs_engine_arm_trigger(&a.e, QS_INPUT_PROBE, 1, decel4);
    run(&a, 1, IDLE_RAW & ~BIT(QS_INPUT_PROBE));
    TEST_ASSERT_EQUAL_INT(QS_INPUTS_HOLD_TRIGGER, a.in.hold_request);
    TEST_ASSERT_FALSE(a.e.trigger);
}

static void test_a_full_ring_loses_the_latch_but_not_the_action(void)
{
    uint8_t i;
    rig_init(&a);
    run(&a, 1, IDLE_RAW);
    for (i = 0; i < QS_LATCH_RING; i++)
        run(&a, 1, (uint16_t)(IDLE_RAW ^ (i % 2 ? 0 : BIT(QS_INPUT_CYCLE_START))));
    TEST_ASSERT_EQUAL_UINT16(0, a.e.latches.lost);
    run(&a, 1, IDLE_RAW & ~BIT(QS_INPUT_ABORT));
    TEST_ASSERT_EQUAL_UINT16(1, a.e.latches.lost);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_E_STOP, a.e.alarm);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_each_input_is_active_low_unless_inverted);
    RUN_TEST(test_an_input_closed_at_power_up_is_a_state_not_an_edge);
    RUN_TEST(test_debounce_drops_glitches_and_latches_the_first_edge);
    RUN_TEST(test_latched_positions_are_exact_at_any_tick);
    RUN_TEST(test_a_hard_limit_leaves_no_step_after_its_tick);
    RUN_TEST(test_hard_limits_can_be_disabled);
    RUN_TEST(test_abort_freezes_even_during_a_hold);
    RUN_TEST(test_an_armed_edge_begins_the_hold_a_hold_at_that_tick_would);
    RUN_TEST(test_the_armed_limit_is_no_alarm_but_the_others_are);
    RUN_TEST(test_a_trigger_with_nothing_moving_asks_the_main_loop);
    RUN_TEST(test_a_full_ring_loses_the_latch_but_not_the_action);
    return UNITY_END();
}
