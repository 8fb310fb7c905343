/* The spindle, laser and coolant outputs (PROTOCOL.md 5.5): in effect in
 * stream order, at once at rest, off after STOP and alarms, refused while
 * holding and in ALARM; a power that follows an axis's speed, checked tick
 * by tick against the closed form (2n*v(t) = 2n*v0 + 2*(vn - v0)*t) and
 * through a hold to rest. */
#include <string.h>

#include "qs_core.h"
#include "qs_engine_tick.h"
#include "qs_test_support.h"
#include "unity.h"

static qs_core core;
static tp_report reports[TP_MAX_REPORTS];

void setUp(void)
{
    qs_core_init(&core);
    tp_clear_sent();
}

void tearDown(void)
{
    tp_check_unlocked();
}

static void send_outputs(uint8_t seq, uint8_t bits, uint16_t power, uint8_t axis, uint16_t speed)
{
    uint8_t body[2 + QS_LEN_OUTPUTS] = {QS_TYPE_OUTPUTS, seq, bits, (uint8_t)power, (uint8_t)(power >> 8), axis,
                                        (uint8_t)speed, (uint8_t)(speed >> 8)};
    tp_send(&core, body, sizeof body);
}

static qs_output_level level(void)
{
    qs_output_level out;
    qs_core_outputs(&core, &out, 0);
    return out;
}

/* The last report: an ACK with this reason, or an ERROR with this code. */
static void expect_ack(uint8_t reason)
{
    uint16_t count = tp_take_reports(reports, TP_MAX_REPORTS);
    TEST_ASSERT_TRUE(count >= 1);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_ACK, reports[count - 1].type);
    TEST_ASSERT_EQUAL_INT(reason, tp_ack(&reports[count - 1]).reason);
}

static void run(uint32_t ticks)
{
    while (ticks--) {
        qs_engine_tick(&core.engine);
        qs_core_poll(&core);
    }
}

/* What the duty must be: power * ratio(num, den) >> 16 (qs_outputs_ratio). */
static uint16_t expected_duty(uint16_t power, uint32_t num, uint32_t den)
{
    return (uint16_t)(((uint32_t)power * qs_outputs_ratio(num, den)) >> 16);
}

static void test_at_rest_an_outputs_message_applies_at_once(void)
{
    TEST_ASSERT_EQUAL_INT(0, level().pins);
    send_outputs(0, QS_OUT_ON | QS_OUT_REVERSE | QS_OUT_FLOOD, 30000, 0, 0);
    expect_ack(QS_ACK_ACCEPTED);
    TEST_ASSERT_EQUAL_HEX8(QS_OUT_ON | QS_OUT_REVERSE | QS_OUT_FLOOD, level().pins);
    TEST_ASSERT_EQUAL_UINT16(30000, level().duty);
    send_outputs(1, QS_OUT_MIST, 30000, 0, 0); /* off, but mist */
    TEST_ASSERT_EQUAL_HEX8(QS_OUT_MIST, level().pins);
    TEST_ASSERT_EQUAL_UINT16(0, level().duty);
}

/* Segments queued before an OUTPUTS run with what was in effect; those
 * queued after it with the new one; at rest the latest applies. */
static void test_outputs_take_effect_in_stream_order(void)
{
    const tp_axis move = {1000, 1000, 0}, stop = {1000, 0, 0};

    send_outputs(0, QS_OUT_ON, 10000, 0, 0);
    tp_send_segment(&core, 1, 100, 0x01, 0, &move);
    send_outputs(2, QS_OUT_ON, 20000, 0, 0);
    tp_send_segment(&core, 3, 100, 0x01, 0, &stop);
    send_outputs(4, 0, 0, 0, 0);
    tp_clear_sent();
    run(1);
    TEST_ASSERT_EQUAL_UINT16(10000, level().duty);
    run(99);
    TEST_ASSERT_EQUAL_UINT16(20000, level().duty); /* the second segment is next */
    run(50);
    TEST_ASSERT_EQUAL_UINT16(20000, level().duty);
    run(50);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, core.engine.state);
    TEST_ASSERT_EQUAL_INT(0, level().pins); /* the M5 after the last segment, at rest */
}

/* The power follows the reference axis's speed through ramps, tick by tick:
 * 2n*v(t) against 2n*speed. */
static void test_a_dynamic_power_follows_the_speed_exactly(void)
{
    const tp_axis ramp_up[2] = {{0, 3000, 0}, {0, 1500, 0}};
    const tp_axis ramp_down[2] = {{3000, 0, 0}, {1500, 0, 0}};
    const uint16_t n = 700, speed = 2500, power = 50000;
    uint32_t t;

    send_outputs(0, QS_OUT_ON | QS_OUT_DYNAMIC, power, 0, speed);
    tp_send_segment(&core, 1, n, 0x03, 0x02, ramp_up);
    tp_send_segment(&core, 2, n, 0x03, 0x02, ramp_down);
    TEST_ASSERT_EQUAL_UINT16(0, level().duty); /* about to start, at rest */
    for (t = 1; t <= n; t++) {
        run(1);
        /* after the last tick the next segment is about to begin: its start */
        uint32_t v2n = t < n ? 2u * 3000u * t : 2u * n * 3000u;
        TEST_ASSERT_EQUAL_UINT16(expected_duty(power, v2n, 2u * n * speed), level().duty);
    }
    TEST_ASSERT_EQUAL_UINT16(power, level().duty); /* 3000 is above the reference speed: capped */
    for (t = 1; t < n; t++) {
        run(1);
        TEST_ASSERT_EQUAL_UINT16(expected_duty(power, 2u * n * 3000u - 2u * 3000u * t, 2u * n * speed),
                                 level().duty);
    }
    run(1);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, core.engine.state);
    TEST_ASSERT_EQUAL_HEX8(QS_OUT_ON, level().pins);
    TEST_ASSERT_EQUAL_UINT16(0, level().duty);
}

/* An axis not moving in a segment has no speed: the power it governs is 0. */
static void test_a_dynamic_power_follows_only_its_axis(void)
{
    const tp_axis move = {2000, 2000, 0};

    send_outputs(0, QS_OUT_ON | QS_OUT_DYNAMIC, 40000, 1, 2000);
    tp_send_segment(&core, 1, 10, 0x01, 0, &move);
    run(3);
    TEST_ASSERT_EQUAL_UINT16(0, level().duty);
    TEST_ASSERT_EQUAL_HEX8(QS_OUT_ON, level().pins);
}

/* In a hold the power follows the deceleration down to rest. */
static void test_a_dynamic_power_follows_a_hold_to_rest(void)
{
    const tp_axis cruise = {4096, 4096, 0};
    uint8_t body[2 + QS_LEN_HOLD] = {QS_TYPE_HOLD, 9, 0x00, 0x10, 0, 0, 0, 0, 0, 0}; /* 4096: about 4096 ticks */
    uint16_t previous, now;
    uint32_t ticks = 0;

    core.axis_count = 1;
    send_outputs(0, QS_OUT_ON | QS_OUT_DYNAMIC, 65535, 0, 4096);
    tp_send_segment(&core, 1, 1000, 0x01, 0, &cruise);
    tp_send_segment(&core, 2, 1000, 0x01, 0, &cruise);
    run(500);
    TEST_ASSERT_EQUAL_UINT16(65535, level().duty);
    tp_send(&core, body, sizeof body);
    run(QS_TRIGGER_TICKS); /* the hold's window: the motion runs on, then decelerates */
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, core.engine.state);
    previous = level().duty;
    while (core.engine.state == QS_STATE_HOLDING && ticks < 100000) {
        run(1);
        ticks++;
        now = level().duty;
        TEST_ASSERT_TRUE_MESSAGE(now <= previous, "the power never rises while decelerating");
        previous = now;
    }
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, core.engine.state);
    TEST_ASSERT_TRUE(ticks > 100); /* a real deceleration, not a cut */
    TEST_ASSERT_EQUAL_UINT16(0, level().duty);
    TEST_ASSERT_EQUAL_HEX8(QS_OUT_ON, level().pins);
}

static void test_stop_and_alarms_turn_everything_off(void)
{
    const tp_axis cruise = {4096, 4096, 0};
    uint8_t stop[2] = {QS_TYPE_STOP, 7};

    send_outputs(0, QS_OUT_ON | QS_OUT_FLOOD, 1000, 0, 0);
    tp_send(&core, stop, sizeof stop);
    TEST_ASSERT_EQUAL_INT(0, level().pins);

    send_outputs(7, QS_OUT_ON | QS_OUT_MIST, 1000, 0, 0);
    tp_send_segment(&core, 8, 10, 0x01, 0, &cruise); /* ends moving with nothing behind: an underrun */
    {
        uint32_t ticks = 0;
        while (core.engine.state != QS_STATE_STARVED && ticks++ < 200000)
            run(1); /* the underrun's hold to rest: paused, no alarm */
    }
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, core.engine.state);
    TEST_ASSERT_EQUAL_INT(QS_OUT_ON | QS_OUT_MIST, level().pins); /* as after any hold */
    tp_clear_sent();
    send_outputs(9, QS_OUT_ON, 1000, 0, 0); /* refused while starved, consumed */
    {
        uint16_t count = tp_take_reports(reports, TP_MAX_REPORTS);
        TEST_ASSERT_EQUAL_INT(2, count);
        TEST_ASSERT_EQUAL_INT(QS_ERR_BUSY, tp_error(&reports[0]).code);
        TEST_ASSERT_EQUAL_INT(QS_ACK_REJECTED, tp_ack(&reports[1]).reason);
    }
    TEST_ASSERT_EQUAL_INT(QS_OUT_ON | QS_OUT_MIST, level().pins);

    stop[1] = 10;
    tp_send(&core, stop, sizeof stop);
    send_outputs(10, QS_OUT_ON | QS_OUT_MIST, 1000, 0, 0);
    tp_send_segment(&core, 11, 0, 0x01, 0, &cruise); /* n = 0: refused, ALARM REJECTED_SEGMENT */
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, core.engine.state);
    TEST_ASSERT_EQUAL_INT(0, level().pins);
    tp_clear_sent();
    send_outputs(12, QS_OUT_ON, 1000, 0, 0); /* refused in ALARM, consumed */
    {
        uint16_t count = tp_take_reports(reports, TP_MAX_REPORTS);
        TEST_ASSERT_EQUAL_INT(2, count);
        TEST_ASSERT_EQUAL_INT(QS_ERR_ALARM_ACTIVE, tp_error(&reports[0]).code);
        TEST_ASSERT_EQUAL_INT(QS_ACK_REJECTED, tp_ack(&reports[1]).reason);
    }
    tp_send(&core, stop, sizeof stop);
    TEST_ASSERT_EQUAL_INT(0, level().pins); /* STOP leaves them off: nothing was let through */
}

/* Run dry with the laser on: at rest, STARVED, the output stays on for a
 * host that takes the stop up at once. One silent past the watchdog is
 * gone: ALARM HOST_LOST, every output off. With every output off the board
 * stays STARVED whatever the silence (test_dispatch). */
static void test_a_host_silent_after_an_underrun_leaves_no_output_on(void)
{
    const tp_axis cruise = {4096, 4096, 0};
    const uint8_t watchdog[] = {QS_TYPE_WATCHDOG, 0x40, 100, 0};
    const uint16_t counts = (100 * 1000 + QS_PORT_CLOCK_US - 1) / QS_PORT_CLOCK_US;
    uint32_t ticks = 0;
    uint16_t count, i;

    tp_send(&core, watchdog, sizeof watchdog);
    send_outputs(0, QS_OUT_ON | QS_OUT_FLOOD, 40000, 0, 0);
    tp_send_segment(&core, 1, 10, 0x01, 0, &cruise); /* ends moving with nothing behind: an underrun */
    while (core.engine.state != QS_STATE_STARVED && ticks++ < 200000)
        run(1);
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, core.engine.state);
    TEST_ASSERT_EQUAL_HEX8(QS_OUT_ON | QS_OUT_FLOOD, level().pins);
    tp_clear_sent();
    test_clock = (uint16_t)(test_clock + counts + 1);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, core.engine.state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_HOST_LOST, core.engine.alarm);
    TEST_ASSERT_EQUAL_INT(0, level().pins);
    TEST_ASSERT_EQUAL_UINT16(0, level().duty);
    qs_core_poll(&core); /* the alarm is reported on the loop's next round */
    count = tp_take_reports(reports, TP_MAX_REPORTS);
    for (i = 0; i < count && reports[i].type != QS_TYPE_ALARM; i++)
        ;
    TEST_ASSERT_TRUE(i < count); /* the alarm is reported */
    TEST_ASSERT_EQUAL_INT(QS_ALARM_HOST_LOST, reports[i].payload[0]);
}

static void test_a_bad_outputs_message_changes_nothing(void)
{
    send_outputs(0, QS_OUT_ON, 1234, 0, 0);
    tp_clear_sent();
    core.axis_count = 3;
    send_outputs(1, QS_OUT_ON | QS_OUT_DYNAMIC, 999, 3, 100); /* axis 3 on a 3-axis firmware */
    {
        uint16_t count = tp_take_reports(reports, TP_MAX_REPORTS);
        TEST_ASSERT_EQUAL_INT(2, count);
        TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, tp_error(&reports[0]).code);
        TEST_ASSERT_EQUAL_INT(QS_FIELD_REFERENCE, tp_error(&reports[0]).field);
    }
    TEST_ASSERT_EQUAL_UINT16(1234, level().duty);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, core.engine.state); /* no alarm: nothing moved */
}

static void test_the_ratio_is_exact_where_it_fits_and_capped(void)
{
    TEST_ASSERT_EQUAL_UINT32(32768, qs_outputs_ratio(1, 2));
    TEST_ASSERT_EQUAL_UINT32(0x10000, qs_outputs_ratio(5, 5));
    TEST_ASSERT_EQUAL_UINT32(0x10000, qs_outputs_ratio(9, 5));
    TEST_ASSERT_EQUAL_UINT32(0, qs_outputs_ratio(0, 1));
    /* den above 16 bits: both shifted, 3 bits here */
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(((uint64_t)(300000 >> 3) << 16) / (400000 >> 3)),
                             qs_outputs_ratio(300000, 400000));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_at_rest_an_outputs_message_applies_at_once);
    RUN_TEST(test_outputs_take_effect_in_stream_order);
    RUN_TEST(test_a_dynamic_power_follows_the_speed_exactly);
    RUN_TEST(test_a_dynamic_power_follows_only_its_axis);
    RUN_TEST(test_a_dynamic_power_follows_a_hold_to_rest);
    RUN_TEST(test_stop_and_alarms_turn_everything_off);
    RUN_TEST(test_a_host_silent_after_an_underrun_leaves_no_output_on);
    RUN_TEST(test_a_bad_outputs_message_changes_nothing);
    RUN_TEST(test_the_ratio_is_exact_where_it_fits_and_capped);
    return UNITY_END();
}
