/* The hold (qs_hold.h, docs/FIXED_POINT.md section 8) against exact 64-bit
 * arithmetic: the rescale, the deceleration quantum, every tick of the
 * deceleration against its closed form, where each axis stops, the 24-bit
 * budget over the extremes, and how the engine takes a hold at any moment
 * of a segment, between segments, at rest and at an underrun. */
#include <stdint.h>
#include <stdio.h>

#include "qs_engine_tick.h"
#include "qs_messages.h"
#include "qs_test_support.h"
#include "unity.h"

#define D 4096
#define BUDGET (1L << 23)

static qs_engine engine;

void setUp(void)
{
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    tp_seed(0x2545F4914F6CDD1Dull);
}

void tearDown(void)
{
    tp_check_unlocked();
}

/* ---- the reference: the hold in exact arithmetic ---- */

typedef struct {
    int64_t kn;   /* k*n */
    int64_t w;    /* 2knD: the hold's scale */
    int64_t e0;   /* k * e(t0): scaled error at the hold tick */
    int64_t i1;   /* k * X'(t0+1): increment over the first hold tick */
    int64_t d;    /* change of the increment per tick, < 0 */
    int64_t j;    /* decisions until the axis stops */
    int64_t s_t0; /* the segment's steps before the hold */
} ref_hold;

static ref_hold reference(const qs_segment_msg *m, uint8_t axis, uint16_t t0, uint16_t decel)
{
    ref_hold r;
    int64_t n = m->n, k = 1, c1 = (int64_t)m->vn[axis] - m->v0[axis];
    int64_t x_t0 = tp_ideal_2nd(m, axis, t0);
    int64_t quanta;

    while (2 * k * n <= QS_N_MAX)
        k *= 2;
    r.kn = k * n;
    r.w = 2 * r.kn * D;
    r.s_t0 = tp_closed_form(m, axis, t0);
    r.e0 = k * (x_t0 - 2 * n * D * r.s_t0);
    /* After the end (t0 = n) the first hold tick runs at the end speed. */
    r.i1 = t0 == n ? k * 2 * n * m->vn[axis] : k * (2 * n * m->v0[axis] + c1 * (2 * t0 + 1));
    /* a = decel / 2^24 step per tick^2 is 2knD*a = kn*decel / 2^11 quanta. */
    quanta = r.kn * decel / 2048;
    r.d = quanta > 0 ? -quanta : -1;
    r.j = r.i1 > 0 && (m->active & (1u << axis)) ? (r.i1 + (-r.d) - 1) / (-r.d) : 0;
    return r;
}

/* Ideal position (times w) after j hold ticks, relative to the stepper at
 * the hold tick. */
static int64_t ref_ideal(const ref_hold *r, int64_t j)
{
    int64_t t = j < r->j ? j : r->j;
    return r->e0 + t * r->i1 + r->d * t * (t - 1) / 2;
}

static int64_t ref_steps(const ref_hold *r, int64_t j)
{
    if (j == 0)
        return 0;
    return tp_floor_div(ref_ideal(r, j) + r->kn * D, r->w);
}

/* ---- driving the engine ---- */

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

/* HOLD, then the ticks of its window (qs_engine.h): the motion runs on for
 * QS_TRIGGER_TICKS decisions (more where a segment begins in it), then the
 * hold begins. Adds the window's ticks to *t. A window that finds every axis
 * at rest ends as a hold found at rest (QS_HOLD_AT_REST). */
static uint8_t hold_through_window(const uint16_t *decel, uint16_t *t)
{
    uint8_t outcome = qs_engine_hold(&engine, decel, 0);

    while (engine.trigger_window) {
        qs_engine_tick(&engine);
        (*t)++;
    }
    if (engine.frozen) {
        qs_engine_finish_freeze(&engine);
        outcome = QS_HOLD_AT_REST;
    }
    return outcome;
}

static uint16_t rnd_speed(void)
{
    static const uint16_t extremes[] = {0, 1, 4095, 4096};
    return tp_rand(3) ? (uint16_t)tp_rand(4097) : extremes[tp_rand(4)];
}

static uint16_t rnd_decel(void)
{
    static const uint16_t extremes[] = {1, 2, 3, 8190, 8191};
    return tp_rand(3) ? (uint16_t)(1 + tp_rand(QS_DECEL_MAX)) : extremes[tp_rand(5)];
}

static void random_segment(qs_segment_msg *m, uint16_t n)
{
    uint8_t axis;
    m->n = n;
    m->active = (uint8_t)(1 + tp_rand((1u << QS_AXIS_COUNT) - 1));
    m->negative = (uint8_t)(tp_rand(16) & m->active);
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
        m->v0[axis] = m->vn[axis] = 0;
        m->r[axis] = 0;
        if (!(m->active & (1u << axis)))
            continue;
        m->v0[axis] = rnd_speed();
        m->vn[axis] = rnd_speed();
        m->r[axis] = (int16_t)((int32_t)tp_rand(8193) - 4096);
        if (m->r[axis] == 4096 && m->v0[axis] == 4096 && m->vn[axis] == 4096)
            m->r[axis] = 4095;
    }
}

/* Run a hold begun after t0 ticks of m to its end, checking every tick of
 * every axis against the reference; returns the ticks it took. Positions
 * are relative to the start of m. */
static int64_t run_hold_from(const qs_segment_msg *m, uint16_t t0, const uint16_t *decel, int32_t *made,
                             int begun_by_tick);

static int64_t run_hold_checked(const qs_segment_msg *m, uint16_t t0, const uint16_t *decel,
                                int32_t *made)
{
    return run_hold_from(m, t0, decel, made, 0);
}

/* The same for a hold that the first tick begins (an underrun). */
static int64_t run_hold_from(const qs_segment_msg *m, uint16_t t0, const uint16_t *decel, int32_t *made,
                             int begun_by_tick)
{
    ref_hold ref[QS_AXIS_COUNT];
    int64_t steps[QS_AXIS_COUNT] = {0};
    int64_t longest = 0, j;
    uint8_t axis;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        ref[axis] = reference(m, axis, t0, decel[axis]);
        if (ref[axis].j > longest)
            longest = ref[axis].j;
    }
    for (j = 1; j <= longest; j++) {
        uint8_t bits;
        TEST_ASSERT_EQUAL_INT(j == 1 && begun_by_tick ? QS_STATE_RUNNING : QS_STATE_HOLDING, engine.state);
        bits = qs_engine_tick(&engine);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            const ref_hold *r = &ref[axis];
            int64_t err;
            if (bits & (1u << axis)) {
                TEST_ASSERT_TRUE_MESSAGE(j <= r->j, "a step after the axis stopped");
                TEST_ASSERT_EQUAL_INT_MESSAGE((m->negative >> axis) & 1, (engine.dir_bits >> axis) & 1,
                                              "a hold step in the wrong direction");
                steps[axis]++;
            }
            TEST_ASSERT_EQUAL_INT64_MESSAGE(ref_steps(r, j), steps[axis], "steps differ from the closed form");
            /* Within half a step of the ideal deceleration. */
            err = steps[axis] * r->w - ref_ideal(r, j);
            TEST_ASSERT_LESS_OR_EQUAL_INT64(r->kn * D, err);
            TEST_ASSERT_GREATER_OR_EQUAL_INT64(-r->kn * D, err);
            /* Moving exactly until its increment would not be positive. */
            TEST_ASSERT_EQUAL_INT_MESSAGE(j < r->j, (engine.hold.moving >> axis) & 1, "stopped at the wrong tick");
        }
    }
    TEST_ASSERT_EQUAL_INT(0, engine.hold.moving);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
        int32_t total = (int32_t)(ref[axis].s_t0 + steps[axis]);
        made[axis] = ((m->negative >> axis) & 1) ? -total : total;
        if (!(m->active & (1u << axis)))
            TEST_ASSERT_EQUAL_INT32(0, made[axis]);
    }
    return longest;
}

/* ---- tests ---- */

static void test_the_rescale_is_the_largest_power_of_two_within_n_max(void)
{
    uint16_t n;
    for (n = 1; n <= QS_N_MAX; n++) {
        uint8_t shift = qs_hold_shift(n);
        TEST_ASSERT_TRUE((uint32_t)n << shift <= QS_N_MAX);
        TEST_ASSERT_TRUE((uint32_t)n << (shift + 1) > QS_N_MAX);
        TEST_ASSERT_TRUE((uint32_t)n << shift >= 512); /* so the quantum is at most 2^-22 */
    }
}

/* db = -floor(2knD * a) for a = decel / 2^24, at least one quantum; its
 * magnitude stays below D, inside the segments' own range of db. */
static void test_the_deceleration_quantum_is_the_floor_and_never_zero(void)
{
    uint16_t kn, decel;
    for (kn = 512; kn <= QS_N_MAX; kn += 17) {
        for (decel = 1; decel <= QS_DECEL_MAX; decel++) {
            int64_t exact = ((int64_t)2 * kn * D * decel) >> 24;
            int64_t db = qs_hold_db(kn, decel);
            TEST_ASSERT_EQUAL_INT64(exact > 0 ? -exact : -1, db);
            TEST_ASSERT_TRUE(db < 0 && db > -D);
        }
    }
    TEST_ASSERT_EQUAL_INT64(-((int64_t)QS_N_MAX * QS_DECEL_MAX >> 11), qs_hold_db(QS_N_MAX, QS_DECEL_MAX));
}

/* Holds at random moments of random segments: every tick of every axis
 * equals the closed form, stays within half a step of the ideal
 * deceleration, stops exactly where the increment runs out; the queued
 * segment behind never runs; positions and ticks are exact throughout. */
static void test_random_holds_follow_their_closed_form(void)
{
    int i;
    for (i = 0; i < 600; i++) {
        qs_segment_msg m, behind;
        uint16_t decel[QS_AXIS_COUNT];
        /* The window puts the hold tick 12 decisions after the HOLD, at
         * most two before the segment's end (a cut never leaves one tick). */
        uint16_t n = (uint16_t)(i % 5 == 0 ? 14 + tp_rand(8) : 14 + tp_rand(QS_N_MAX - 13));
        uint16_t t0 = (uint16_t)(i % 7 == 0 ? 12u : i % 7 == 1 ? n - 2u : 12 + tp_rand(n - 13));
        uint16_t t = (uint16_t)(t0 - QS_TRIGGER_TICKS);
        int32_t made[QS_AXIS_COUNT];
        qs_engine_view v;
        int64_t ticks;
        uint8_t axis, outcome;

        qs_engine_init(&engine, QS_QUEUE_CAPACITY);
        random_segment(&m, n);
        random_segment(&behind, (uint16_t)(1 + tp_rand(QS_N_MAX)));
        /* Fast enough to take a few hundred ticks at most to stop. */
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            decel[axis] = (uint16_t)(2000 + tp_rand(QS_DECEL_MAX - 1999));
        if (i % 10 == 0)
            decel[tp_rand(QS_AXIS_COUNT)] = rnd_decel();
        enqueue(&m);
        enqueue(&behind);
        for (ticks = 0; ticks < t; ticks++)
            qs_engine_tick(&engine);
        outcome = hold_through_window(decel, &t);
        TEST_ASSERT_EQUAL_UINT16(t0, t);
        qs_engine_read(&engine, &v);
        TEST_ASSERT_EQUAL_UINT32(t0, v.motion_ticks);
        /* The segment behind stays queued until the hold ends, and never runs. */
        TEST_ASSERT_EQUAL_INT(outcome == QS_HOLD_STARTED ? 2 : 0, v.queue_fill);
        if (outcome == QS_HOLD_AT_REST) {
            ticks = 0;
            for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
                TEST_ASSERT_EQUAL_INT64(0, reference(&m, axis, t0, decel[axis]).j);
                made[axis] = v.position[axis];
            }
            TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, engine.state);
        } else {
            TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, outcome);
            ticks = run_hold_checked(&m, t0, decel, made);
        }
        /* Nothing more: the segment behind never runs. */
        for (axis = 0; axis < 5; axis++)
            TEST_ASSERT_EQUAL_HEX8(0, qs_engine_tick(&engine));
        qs_engine_read(&engine, &v);
        TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, v.state);
        TEST_ASSERT_EQUAL_INT(0, v.queue_fill);
        TEST_ASSERT_EQUAL_UINT32(0, v.segments_done);
        TEST_ASSERT_EQUAL_UINT32(t0 + ticks, v.motion_ticks);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            TEST_ASSERT_EQUAL_INT32(made[axis], v.position[axis]);
        {
            uint32_t hold_tick = 0;
            TEST_ASSERT_EQUAL_INT(1, qs_engine_take_hold_done(&engine, &hold_tick));
            TEST_ASSERT_EQUAL_UINT32(t0, hold_tick);
            TEST_ASSERT_EQUAL_INT(0, qs_engine_take_hold_done(&engine, &hold_tick)); /* once */
        }
    }
}

/* The window's end falls just past a segment's end: its beginning is due
 * in the next segment (of the same length, so the plan holds), a few
 * decisions in, and the increments it begins with are worked out for that
 * segment in a tick of their own, never in the tick that loads it. Random
 * speeds, so b changes every tick. */
static void test_holds_due_just_past_a_segment_boundary_follow_their_closed_form(void)
{
    int i;
    for (i = 0; i < 300; i++) {
        qs_segment_msg a, b;
        uint16_t decel[QS_AXIS_COUNT];
        const uint16_t n = (uint16_t)(20 + tp_rand(QS_N_MAX - 19));
        /* decisions left in a once the increments are due: 0 to 4 */
        const uint16_t left = (uint16_t)tp_rand(5);
        const uint16_t t = (uint16_t)(n - QS_TRIGGER_PREDICT_AT - left);
        /* Whether the increments fell due in a's last decisions or as b
         * begins, b's are worked out at its third decision (its first takes
         * no work, and its second takes up the first's lateness) and the
         * beginning follows as far on as in a window without a boundary. */
        const uint16_t t0 = 3 + QS_TRIGGER_TICKS - QS_TRIGGER_PREDICT_AT;
        uint16_t ticks = t;
        int32_t made[QS_AXIS_COUNT];
        uint8_t axis, outcome;
        uint16_t k;

        qs_engine_init(&engine, QS_QUEUE_CAPACITY);
        random_segment(&a, n);
        random_segment(&b, n);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            decel[axis] = (uint16_t)(2000 + tp_rand(QS_DECEL_MAX - 1999));
        enqueue(&a);
        enqueue(&b);
        for (k = 0; k < t; k++)
            qs_engine_tick(&engine);
        outcome = hold_through_window(decel, &ticks);
        TEST_ASSERT_EQUAL_UINT16(n + t0, ticks);
        if (outcome == QS_HOLD_AT_REST)
            continue; /* b at rest there: nothing to hold */
        TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, outcome);
        run_hold_checked(&b, t0, decel, made);
    }
}

/* A status read at any tick of a hold gives the steps made so far. */
static void test_positions_are_exact_at_every_tick_of_a_hold(void)
{
    qs_segment_msg m = {0};
    uint16_t decel[QS_AXIS_COUNT] = {300, 300, 300, 300};
    int32_t counted = 0;
    uint32_t ticks = 0;
    qs_engine_view v;

    m.n = 1000;
    m.active = 0x1;
    m.negative = 0x1;
    m.v0[0] = 3000;
    m.vn[0] = 3500;
    enqueue(&m);
    while (ticks < 400) {
        counted -= qs_engine_tick(&engine) & 1;
        ticks++;
    }
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decel, 0));
    while (engine.state == QS_STATE_HOLDING || engine.trigger_window) {
        qs_engine_read(&engine, &v);
        TEST_ASSERT_EQUAL_INT32(counted, v.position[0]);
        TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
        counted -= qs_engine_tick(&engine) & 1;
        ticks++;
        qs_engine_retire(&engine);
    }
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT32(counted, v.position[0]);
    TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
    TEST_ASSERT_TRUE(ticks > 1000); /* it ran past where the segment would have ended */
}

/* Holds long enough (about 100,000 ticks) that the main loop works their
 * steps out the long way (a hold past 2^16 ticks): positions and ticks are
 * exact all through, read every 997 ticks and at the end. */
static void test_positions_are_exact_through_long_holds(void)
{
    static const uint16_t decels[2][4] = {{100, 150, 120, 90}, {130, 90, 110, 140}};
    int c;

    for (c = 0; c < 2; c++) {
        qs_segment_msg m = {0};
        int32_t counted[QS_AXIS_COUNT] = {0};
        uint32_t ticks = 0;
        qs_engine_view v;
        uint8_t axis, bits;

        qs_engine_init(&engine, QS_QUEUE_CAPACITY);
        m.n = 1000;
        m.active = (1u << QS_AXIS_COUNT) - 1;
        m.negative = 0x5 & m.active;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++) {
            m.v0[axis] = (uint16_t)(D - 300 * axis - c);
            m.vn[axis] = (uint16_t)(D - 200 * axis - 7 * c);
        }
        enqueue(&m);
        TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decels[c], 0));
        while (engine.state == QS_STATE_HOLDING || engine.trigger_window) {
            if (ticks % 997 == 0) {
                qs_engine_read(&engine, &v);
                TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
                for (axis = 0; axis < QS_AXIS_COUNT; axis++)
                    TEST_ASSERT_EQUAL_INT32(counted[axis], v.position[axis]);
            }
            bits = qs_engine_tick(&engine);
            for (axis = 0; axis < QS_AXIS_COUNT; axis++)
                if (bits & (1u << axis))
                    counted[axis] += (m.negative >> axis) & 1 ? -1 : 1;
            ticks++;
            qs_engine_retire(&engine);
        }
        qs_engine_read(&engine, &v);
        TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            TEST_ASSERT_EQUAL_INT32(counted[axis], v.position[axis]);
        TEST_ASSERT_TRUE(ticks > 0x10000u + 1000u); /* past 2^16 */
    }
}

static int64_t mag(int64_t x)
{
    return x < 0 ? -x : x;
}

/* Hold a one-axis segment after t0 of its ticks and run the hold to its
 * end, checking every value it computes against 2knD + |db|, including
 * h - 2knD after a step. Returns the largest magnitude seen. */
static int64_t largest_hold_value(const qs_segment_msg *m, uint16_t t0, uint16_t decel)
{
    uint16_t decels[QS_AXIS_COUNT];
    int64_t worst = 0, limit;
    uint16_t t;
    uint8_t a;

    for (a = 0; a < QS_AXIS_COUNT; a++)
        decels[a] = decel;
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    enqueue(m);
    for (t = 0; t < t0; t++)
        qs_engine_tick(&engine);
    if (hold_through_window(decels, &t) != QS_HOLD_STARTED || !engine.hold.moving)
        return 0;
    limit = engine.hold.two_c2 - engine.hold.db[0];
    for (;;) {
        int64_t h = engine.hold.h[0];
        int64_t big = mag(h) > mag(engine.hold.inc[0]) ? mag(h) : mag(engine.hold.inc[0]);
        if (h >= 0 && mag(h - engine.hold.two_c2) > big)
            big = mag(h - engine.hold.two_c2);
        TEST_ASSERT_LESS_OR_EQUAL_INT64(limit, big);
        if (big > worst)
            worst = big;
        if (!engine.hold.moving)
            return worst;
        qs_engine_tick(&engine);
    }
}

/* Every segment length with extreme speeds and residuals, held at its
 * first, middle and last tick at the largest deceleration, and the longest
 * holds (the smallest decelerations) from a few: no value the hold
 * computes leaves 2knD + |db| < 2^23, and the bound is nearly reached. */
static void test_hold_values_stay_within_24_bits(void)
{
    static const uint16_t speeds[] = {0, 1, 4095, 4096};
    static const int16_t residuals[] = {-4096, 0, 4096};
    static const uint16_t long_n[] = {1, QS_N_MAX};
    int64_t worst = 0, big;
    uint16_t n;
    unsigned i, j, k, p;

    for (n = 1; n <= QS_N_MAX; n++)
        for (i = 0; i < 4; i++)
            for (j = 0; j < 4; j++)
                for (k = 0; k < 3; k++)
                    for (p = 0; p < 3; p++) {
                        qs_segment_msg m = {0};
                        m.n = n;
                        m.active = 1;
                        m.v0[0] = speeds[i];
                        m.vn[0] = speeds[j];
                        m.r[0] = residuals[k];
                        if (m.r[0] == 4096 && m.v0[0] == 4096 && m.vn[0] == 4096)
                            continue;
                        big = largest_hold_value(&m, p == 0 ? 0 : p == 1 ? n / 2 : n - 1, QS_DECEL_MAX);
                        if (big > worst)
                            worst = big;
                    }
    for (n = 0; n < 2; n++)
        for (i = 0; i < 3; i++)
            for (p = 0; p < 2; p++)
                for (k = 0; k < 2; k++) {
                    qs_segment_msg m = {0};
                    m.n = long_n[n];
                    m.active = 1;
                    m.v0[0] = i == 2 ? 0 : 4096;
                    m.vn[0] = i == 1 ? 0 : 4096;
                    big = largest_hold_value(&m, p == 0 ? 0 : m.n - 1, k == 0 ? 1 : 64);
                    if (big > worst)
                        worst = big;
                }
    TEST_ASSERT_TRUE(worst < BUDGET);
    TEST_ASSERT_TRUE(worst >= 2L * QS_N_MAX * D - 8192);
    printf("largest hold value: %lld of %ld\n", (long long)worst, (long)BUDGET);
}

/* An axis at rest at the hold tick does not move; one whose increment runs
 * out after a single tick makes one decision. */
static void test_stop_detection_at_the_edges(void)
{
    qs_segment_msg m = {0};
    uint16_t decel[QS_AXIS_COUNT] = {8191, 8191, 8191, 8191};
    qs_engine_view v;
    uint16_t t = 1;

    m.n = 1022;
    m.active = 0x3;
    m.v0[0] = 0; /* axis 0 at rest for the whole segment */
    m.vn[0] = 0;
    m.v0[1] = 1; /* axis 1 barely moving: increment 2044 quanta < |db| */
    m.vn[1] = 1;
    enqueue(&m);
    qs_engine_tick(&engine);
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, hold_through_window(decel, &t));
    TEST_ASSERT_EQUAL_HEX8(0x2, engine.hold.moving);
    qs_engine_tick(&engine);
    TEST_ASSERT_EQUAL_HEX8(0, engine.hold.moving);
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, v.state);
    TEST_ASSERT_EQUAL_UINT32(1 + QS_TRIGGER_TICKS + 1, v.motion_ticks);
    /* Every axis at rest: done at once, no tick. */
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    m.active = 0x1;
    enqueue(&m);
    qs_engine_tick(&engine);
    t = 1;
    TEST_ASSERT_EQUAL_INT(QS_HOLD_AT_REST, hold_through_window(decel, &t));
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, v.state);
    TEST_ASSERT_EQUAL_INT(0, v.queue_fill);
    TEST_ASSERT_EQUAL_UINT32(1 + QS_TRIGGER_TICKS, v.motion_ticks);
    TEST_ASSERT_EQUAL_UINT32(1 + QS_TRIGGER_TICKS, engine.hold_tick);
    TEST_ASSERT_TRUE(engine.hold_report);
}

/* Between two segments the hold begins the next one at its tick 0, as the
 * tick would have; with nothing queued after a segment that ends moving it
 * holds from where that one ended;
 * idle, a hold is done at once; in ALARM nothing changes; a second hold
 * while holding changes nothing. */
static void test_hold_at_boundaries_and_in_every_state(void)
{
    qs_segment_msg a = {0}, b = {0};
    uint16_t decel[QS_AXIS_COUNT] = {4000, 4000, 4000, 4000};
    int32_t made[QS_AXIS_COUNT];
    qs_engine_view v;
    uint16_t t;

    TEST_ASSERT_EQUAL_INT(QS_HOLD_AT_REST, qs_engine_hold(&engine, decel, 0));
    TEST_ASSERT_TRUE(engine.hold_report);
    engine.hold_report = 0;

    a.n = 10; a.active = 1; a.v0[0] = 4096; a.vn[0] = 4096;
    b.n = 300; b.active = 1; b.negative = 1; b.v0[0] = 4096; b.vn[0] = 2000;
    enqueue(&a);
    enqueue(&b);
    for (t = 0; t < 10; t++)
        qs_engine_tick(&engine);
    TEST_ASSERT_EQUAL_INT(0, engine.left); /* a is done, b not begun */
    /* The window begins b and holds it after its first 12 decisions. */
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, hold_through_window(decel, &t));
    TEST_ASSERT_EQUAL_UINT16(10 + QS_TRIGGER_TICKS, t);
    TEST_ASSERT_EQUAL_INT(QS_HOLD_UNDER_WAY, qs_engine_hold(&engine, decel, 0));
    run_hold_checked(&b, QS_TRIGGER_TICKS, decel, made);
    qs_engine_retire(&engine);
    TEST_ASSERT_EQUAL_UINT32(10 + QS_TRIGGER_TICKS, engine.hold_tick);
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT32(10 + made[0], v.position[0]);
    TEST_ASSERT_TRUE(made[0] < -QS_TRIGGER_TICKS + 2);
    TEST_ASSERT_EQUAL_UINT32(1, v.segments_done);

    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    enqueue(&a);
    for (t = 0; t < 10; t++)
        qs_engine_tick(&engine);
    TEST_ASSERT_TRUE(engine.kept);
    /* From a kept slot's end: the next tick begins the hold there. */
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decel, 0));
    run_hold_from(&a, 10, decel, made, 1);
    qs_engine_retire(&engine);
    TEST_ASSERT_EQUAL_UINT32(10, engine.hold_tick);
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, v.state);
    TEST_ASSERT_EQUAL_INT32(made[0], v.position[0]);
    TEST_ASSERT_TRUE(made[0] > 10);
    TEST_ASSERT_EQUAL_UINT32(1, v.segments_done); /* it ran whole before the hold */

    qs_engine_halt(&engine, QS_STATE_ALARM, QS_ALARM_REJECTED_SEGMENT);
    TEST_ASSERT_EQUAL_INT(QS_HOLD_IN_ALARM, qs_engine_hold(&engine, decel, 0));
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, engine.state);
}

/* The queue runs dry after random segments that end moving, from any
 * state: the tick that would have begun the next segment begins a hold
 * from where the last one ended at the underrun decelerations, every tick
 * of it the closed form at t0 = n; at rest the engine is STARVED (no
 * alarm) with the exact positions and a HOLD_DONE to report, also when
 * nothing would move one tick on. A segment that arrives in time goes on
 * as usual. */
static void test_an_underrun_holds_from_the_end_of_the_last_segment(void)
{
    int i;
    for (i = 0; i < 300; i++) {
        qs_segment_msg m, late;
        uint16_t decel[QS_AXIS_COUNT];
        int32_t made[QS_AXIS_COUNT];
        qs_engine_view v;
        uint16_t t;
        uint8_t axis, moving_axis = 0;

        qs_engine_init(&engine, QS_QUEUE_CAPACITY);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            engine.stop_decel[axis] = decel[axis] = rnd_decel();
        random_segment(&m, (uint16_t)(1 + tp_rand(i % 4 == 0 ? 8 : QS_N_MAX)));
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            if ((m.active >> axis) & 1)
                moving_axis |= m.vn[axis] != 0;
        if (!moving_axis) {
            m.vn[0] = (uint16_t)(1 + tp_rand(4096));
            m.active |= 1;
            if (m.r[0] == 4096 && m.v0[0] == 4096 && m.vn[0] == 4096)
                m.r[0] = 0;
        }
        enqueue(&m);
        for (t = 0; t < m.n; t++)
            qs_engine_tick(&engine);
        TEST_ASSERT_TRUE(engine.kept);
        TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, engine.state);
        if (i % 10 == 0) {
            /* In time: the kept slot goes and the next one runs. */
            random_segment(&late, 5);
            enqueue(&late);
            qs_engine_tick(&engine);
            TEST_ASSERT_FALSE(engine.kept);
            TEST_ASSERT_EQUAL_INT(4, engine.left);
            continue;
        }
        run_hold_from(&m, m.n, decel, made, 1);
        TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, engine.state); /* until the main loop folds it */
        TEST_ASSERT_EQUAL_HEX8(0, qs_engine_tick(&engine));
        qs_engine_retire(&engine);
        TEST_ASSERT_TRUE(engine.hold_report);
        qs_engine_read(&engine, &v);
        TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, v.state);
        TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, v.alarm);
        TEST_ASSERT_EQUAL_INT(0, v.queue_fill);
        TEST_ASSERT_EQUAL_HEX8(0, qs_engine_tick(&engine)); /* nothing moves while starved */
        TEST_ASSERT_EQUAL_UINT32(1, v.segments_done);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            TEST_ASSERT_EQUAL_INT32(made[axis], v.position[axis]);
        TEST_ASSERT_EQUAL_UINT32(m.n, engine.hold_tick);
    }
}

/* STOP during a hold stops at once; the steps made stay counted. */
static void test_halt_during_a_hold_keeps_exact_positions(void)
{
    qs_segment_msg m = {0};
    uint16_t decel[QS_AXIS_COUNT] = {1, 1, 1, 1};
    int32_t counted = 0;
    qs_engine_view v;
    int i;

    m.n = 500;
    m.active = 0x4;
    m.v0[2] = 4096;
    m.vn[2] = 4096;
    enqueue(&m);
    for (i = 0; i < 100; i++)
        counted += (qs_engine_tick(&engine) >> 2) & 1;
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decel, 0));
    for (i = 0; i < 5000; i++)
        counted += (qs_engine_tick(&engine) >> 2) & 1;
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, engine.state);
    qs_engine_halt(&engine, QS_STATE_IDLE, QS_ALARM_NONE);
    TEST_ASSERT_EQUAL_HEX8(0, qs_engine_tick(&engine));
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT32(counted, v.position[2]);
    /* Decelerating at one quantum per tick: barely slower after 5000 ticks. */
    {
        ref_hold r = reference(&m, 2, 100 + QS_TRIGGER_TICKS, 1); /* begun after its window */
        TEST_ASSERT_EQUAL_INT32(100 + ref_steps(&r, 5000 - QS_TRIGGER_TICKS) + QS_TRIGGER_TICKS, counted);
        TEST_ASSERT_TRUE(counted > 5090 && counted < 5100);
    }
    TEST_ASSERT_EQUAL_UINT32(5100, v.motion_ticks);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, v.state);
    TEST_ASSERT_FALSE(engine.hold_report);
}

/* An alarm (a hard limit) freezes the engine in the tick during a hold,
 * some axes still moving and one stopped: they stopped at the freeze, not by
 * running out of increment, and the halt that follows counts the steps and
 * ticks exactly as they were made. */
static void test_an_alarm_during_a_hold_keeps_exact_positions(void)
{
    qs_segment_msg m = {0};
    uint16_t decel[QS_AXIS_COUNT] = {8191, 40, 40, 40};
    int32_t counted[QS_AXIS_COUNT] = {0};
    uint32_t ticks = 0;
    qs_engine_view v;
    uint8_t axis, bits;

    m.n = 500;
    m.active = 0x7;
    m.v0[0] = m.vn[0] = 300; /* stops early in the hold */
    m.v0[1] = m.vn[1] = 4000;
    m.v0[2] = m.vn[2] = 2500;
    enqueue(&m);
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decel, 0));
    while (ticks < 400) {
        bits = qs_engine_tick(&engine);
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            counted[axis] += (bits >> axis) & 1;
        ticks++;
    }
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, engine.state);
    TEST_ASSERT_EQUAL_HEX8(0x6, engine.hold.moving); /* axis 0 has stopped, 1 and 2 move */
    qs_engine_freeze_in_tick(&engine, QS_ALARM_HARD_LIMIT);
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        TEST_ASSERT_EQUAL_INT32(counted[axis], v.position[axis]);
    TEST_ASSERT_EQUAL_HEX8(0, qs_engine_tick(&engine));
    qs_engine_finish_freeze_slow(&engine);
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, v.state);
    TEST_ASSERT_EQUAL_UINT32(ticks, v.motion_ticks);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        TEST_ASSERT_EQUAL_INT32(counted[axis], v.position[axis]);
}

/* HOLD_ALONG's decelerations are taken only where the hold begins in a
 * segment they name: in the running one when its window opens with
 * QS_TRIGGER_TICKS + 2 ticks of it left or more; with fewer, in the next one
 * if that is named too and lasts QS_PATH_NEXT_MIN (32) ticks, or at the
 * running one's end with nothing after it. Done counts compare mod 2^16. */
static void hold_along_from(uint16_t left, const qs_segment_msg *next, const qs_path_hold *path,
                            uint8_t along, uint8_t held_slot)
{
    static const uint16_t decel[QS_PROTOCOL_AXES] = {3000, 3000, 3000, 3000};
    qs_segment_msg a = {0};
    uint16_t ran;
    uint8_t axis;

    a.n = 100;
    a.active = 1;
    a.v0[0] = a.vn[0] = 2000;
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    engine.segments_done = 65536; /* 0 mod 2^16 */
    enqueue(&a);
    if (next)
        enqueue(next);
    for (ran = 0; ran < a.n - left; ran++)
        qs_engine_tick(&engine);
    TEST_ASSERT_EQUAL_UINT16(left, engine.left);
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&engine, decel, path));
    TEST_ASSERT_EQUAL_INT(along, engine.hold_along);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        TEST_ASSERT_EQUAL_UINT16(along ? path->hold.decel[axis] : decel[axis], engine.trigger_decel[axis]);
    while (engine.trigger_window)
        qs_engine_tick(&engine);
    /* where the hold began: the slot it holds */
    TEST_ASSERT_TRUE(engine.held == &engine.queue.slot[held_slot]);
}

static void test_hold_along_takes_its_decelerations_only_in_the_segments_it_names(void)
{
    const qs_path_hold both = {{{1000, 333, 1, 2000}}, 65535, 1}, first_only = {{{1000, 333, 1, 2000}}, 0, 0};
    qs_segment_msg b = {0}, short_b;
    uint16_t left;

    b.n = QS_PATH_NEXT_MIN;
    b.active = 1;
    b.v0[0] = b.vn[0] = 2000;
    short_b = b;
    short_b.n = QS_PATH_NEXT_MIN - 1;
    for (left = 1; left <= 16; left++) {
        const uint8_t inside = left >= QS_TRIGGER_TICKS + 2;
        hold_along_from(left, &b, &both, 1, inside ? 0 : 1);
        hold_along_from(left, &b, &first_only, inside, inside ? 0 : 1);
        hold_along_from(left, &short_b, &both, inside, inside ? 0 : 1);
    }
    /* Nothing after the running segment: its hold begins in it (at its end). */
    hold_along_from(5, 0, &first_only, 1, 0);
    /* A running segment the path does not name: the HOLD's own. */
    hold_along_from(50, &b, &(qs_path_hold){{{1000, 333, 1, 2000}}, 1, 9}, 0, 0);
    /* Segments queued after a hold: the next stop is the board's own until a HOLD_ALONG says otherwise. */
    engine.hold_along = 1;
    qs_engine_note_prepared(&engine, qs_queue_back(&engine.queue));
    TEST_ASSERT_EQUAL_INT(0, engine.hold_along);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_rescale_is_the_largest_power_of_two_within_n_max);
    RUN_TEST(test_the_deceleration_quantum_is_the_floor_and_never_zero);
    RUN_TEST(test_random_holds_follow_their_closed_form);
    RUN_TEST(test_positions_are_exact_through_long_holds);
    RUN_TEST(test_an_alarm_during_a_hold_keeps_exact_positions);
    RUN_TEST(test_holds_due_just_past_a_segment_boundary_follow_their_closed_form);
    RUN_TEST(test_positions_are_exact_at_every_tick_of_a_hold);
    RUN_TEST(test_hold_values_stay_within_24_bits);
    RUN_TEST(test_stop_detection_at_the_edges);
    RUN_TEST(test_hold_at_boundaries_and_in_every_state);
    RUN_TEST(test_an_underrun_holds_from_the_end_of_the_last_segment);
    RUN_TEST(test_halt_during_a_hold_keeps_exact_positions);
    RUN_TEST(test_hold_along_takes_its_decelerations_only_in_the_segments_it_names);
    return UNITY_END();
}
