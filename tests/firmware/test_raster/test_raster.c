/* RASTER (PROTOCOL.md 5.2): a line at the chain's speed whose power
 * changes at the step that crosses each pixel boundary, set by the tick
 * (qs_raster_tick.h). Lines of several pitches and phases, between a ramp
 * up and a ramp down, checked tick by tick against the boundaries counted
 * from the steps the engine made. */
#include <string.h>

#include "qs_core.h"
#include "qs_engine_tick.h"
#include "qs_raster_tick.h"
#include "qs_test_support.h"
#include "unity.h"

static qs_core core;
static tp_report reports[TP_MAX_REPORTS];

void setUp(void)
{
    qs_core_init(&core);
    tp_clear_sent();
    test_laser_power = -1;
    test_laser_period = 0;
}

void tearDown(void)
{
    tp_check_unlocked();
}

typedef struct {
    uint16_t n;
    uint16_t phase, pitch;
    uint8_t count;
    uint8_t power[QS_RASTER_PIXELS_MAX];
} line;

static void send_raster(uint8_t seq, uint8_t axes, uint8_t pixel, const line *l)
{
    uint8_t body[2 + QS_LEN_RASTER_HEAD + QS_RASTER_PIXELS_MAX] = {
        QS_TYPE_RASTER, seq, (uint8_t)l->n, (uint8_t)(l->n >> 8), axes, pixel,
        (uint8_t)l->phase, (uint8_t)(l->phase >> 8), (uint8_t)l->pitch, (uint8_t)(l->pitch >> 8)};
    memcpy(body + 2 + QS_LEN_RASTER_HEAD, l->power, l->count);
    tp_send(&core, body, (uint8_t)(2 + QS_LEN_RASTER_HEAD + l->count));
}

static void send_outputs_on(uint8_t seq)
{
    uint8_t body[2 + QS_LEN_OUTPUTS] = {QS_TYPE_OUTPUTS, seq, QS_OUT_ON, 0, 0, 0, 0, 0};
    tp_send(&core, body, sizeof body);
}

static void expect_ack(uint8_t reason)
{
    uint16_t count = tp_take_reports(reports, TP_MAX_REPORTS);
    TEST_ASSERT_TRUE(count >= 1);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_ACK, reports[count - 1].type);
    TEST_ASSERT_EQUAL_INT(reason, tp_ack(&reports[count - 1]).reason);
}

/* The boundaries at or before `steps`: floor((phase + (k-1)*pitch) / 256) <= steps. */
static uint8_t pixel_at(const line *l, uint32_t steps)
{
    uint8_t k = 0;
    while (k + 1 < l->count && ((uint32_t)l->phase + (uint32_t)k * l->pitch) / 256u <= steps)
        k++;
    return k;
}

static uint16_t duty_ahead(uint16_t ahead)
{
    qs_output_level out;
    qs_core_outputs(&core, &out, ahead);
    return out.duty;
}

static uint16_t duty_now(void)
{
    return duty_ahead(0);
}

static uint8_t tick(void)
{
    uint8_t bits = qs_engine_tick(&core.engine);
    qs_raster_tick(&core.raster, &core.outputs, &core.engine, bits);
    return bits;
}

#define LINES 4
#define AHEAD 40        /* ticks a board looks ahead (shorter than any line here) */
#define RUN_TICKS 2182u /* 200 + 300 + 397 + 494 + 591 + 200 */

/* A ramp to speed, four lines on X (and Y slower along), a ramp to rest.
 * With no PWM period (period 0) the tick switches every line's pixels:
 * after every tick the duty is the power of the pixel under X counted
 * from the start of the line whose decision it made, 0 on the ramps, and
 * the tick set that power itself (qs_port_laser_power). With a period
 * longer than these pixels, the main loop looks them up: after every tick
 * the pixel under X counted from the start of the line that runs (from
 * the tick before its first decision), and looked up AHEAD ticks ahead
 * the duty AHEAD ticks later while a line runs (the next line's pixel, or
 * dark past the last line), 0 on the ramps; the tick lights none. */
static void run_lines(uint8_t axes, uint16_t vx, uint16_t vy, uint8_t period)
{
    static uint16_t now[RUN_TICKS + AHEAD], ahead[RUN_TICKS];
    static uint8_t in_line[RUN_TICKS];
    static line lines[LINES];
    const uint16_t phases[LINES] = {256, 700, 1000, 1203};
    const uint16_t pitches[LINES] = {256, 700, 1000, 1203};
    tp_axis up[2] = {{0, vx, 0}, {0, vy, 0}}, down[2] = {{vx, 0, 0}, {vy, 0, 0}};
    uint16_t n[LINES + 2], j, ticks_in = 0, seg = 0;
    uint32_t steps = 0, checked = 0;
    uint8_t seq = 0, k, lit = 0;

    test_laser_period = period;
    send_outputs_on(seq++);
    tp_send_segment(&core, seq++, 200, axes & 0x0F, (uint8_t)(axes >> 4), up);
    expect_ack(QS_ACK_ACCEPTED);
    n[0] = 200;
    for (j = 0; j < LINES; j++) {
        line *l = &lines[j];
        l->n = (uint16_t)(300 + 97 * j);
        l->phase = phases[j];
        l->pitch = pitches[(j + 1) % LINES];
        if (l->phase > l->pitch)
            l->phase = l->pitch;
        l->count = 0;
        /* as many pixels as the line's steps hold (at least 1) */
        while (l->count < QS_RASTER_PIXELS_MAX
               && ((uint32_t)l->phase + (uint32_t)l->count * l->pitch) / 256u
                      <= (uint32_t)l->n * vx / QS_D - 1u)
            l->count++;
        if (l->count == 0)
            l->count = 1;
        for (k = 0; k < l->count; k++)
            l->power[k] = (uint8_t)(37 * k + 11 * j + 1);
        send_raster(seq++, axes, 0, l);
        expect_ack(QS_ACK_ACCEPTED);
        n[j + 1] = l->n;
    }
    tp_send_segment(&core, seq++, 200, axes & 0x0F, (uint8_t)(axes >> 4), down);
    expect_ack(QS_ACK_ACCEPTED);
    n[LINES + 1] = 200;
    TEST_ASSERT_EQUAL_UINT16(0, duty_now()); /* the ramp up starts dark */
    for (;;) {
        uint8_t bits = tick();
        uint16_t expected = 0;

        qs_core_poll(&core);
        if (bits & 1u)
            steps++;
        ticks_in++;
        if (period == 0 && seg >= 1 && seg <= LINES) /* the line whose decision this was */
            expected = (uint16_t)(lines[seg - 1].power[pixel_at(&lines[seg - 1], steps)] * 257u);
        lit |= period == 0 && seg >= 1;
        if (ticks_in == n[seg]) { /* the next segment begins */
            ticks_in = 0;
            steps = 0;
            seg++;
        }
        if (period != 0 && seg >= 1 && seg <= LINES) /* the line that runs, or begins next */
            expected = (uint16_t)(lines[seg - 1].power[pixel_at(&lines[seg - 1], steps)] * 257u);
        TEST_ASSERT_EQUAL_UINT16(expected, duty_now());
        TEST_ASSERT_EQUAL_INT(lit ? (int)(expected / 257u) : -1, test_laser_power);
        now[checked] = expected;
        ahead[checked] = duty_ahead(AHEAD);
        in_line[checked] = seg >= 1 && seg <= LINES;
        checked++;
        if (seg == LINES + 2)
            break;
    }
    TEST_ASSERT_EQUAL_UINT32(RUN_TICKS, checked);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, core.engine.state);
    TEST_ASSERT_FALSE(qs_raster_lit(&core.raster));
    for (j = 0; period != 0 && j + 1u < RUN_TICKS; j++) {
        TEST_ASSERT_EQUAL_UINT16(in_line[j] ? now[j + AHEAD] : 0, ahead[j]);
    }
}

static void test_the_power_changes_at_the_step_of_each_boundary(void)
{
    run_lines(0x01, 1000, 0, 0);
}

static void test_a_diagonal_line_counts_its_pixels_on_the_faster_axis(void)
{
    run_lines(0x13, 3000, 1234, 0); /* X negative, Y positive */
}

/* Pixels of 1 to 4.7 steps at 1000/4096 step a tick last 4 to 20 ticks:
 * with a PWM period of 40 ticks the main loop looks them up (ahead). */
static void test_pixels_shorter_than_a_pwm_period_are_looked_up_ahead(void)
{
    run_lines(0x01, 1000, 0, 40);
}

/* Off, the raster's powers show nothing: a line's duty needs the setting it carries on. */
static void test_a_line_under_outputs_off_stays_dark(void)
{
    tp_axis up = {0, 2000, 0};
    line l = {500, 256, 512, 3, {255, 255, 255}};
    uint16_t t;

    tp_send_segment(&core, 0, 100, 0x01, 0, &up);
    send_raster(1, 0x01, 0, &l);
    expect_ack(QS_ACK_ACCEPTED);
    for (t = 0; t < 300; t++) {
        tick();
        qs_core_poll(&core);
        TEST_ASSERT_EQUAL_UINT16(0, duty_now());
        TEST_ASSERT_FALSE(qs_raster_lit(&core.raster));
    }
}

/* A HOLD inside a line: the pixels go on through the hold's window, at the
 * line's speed, and the hold's first decelerating tick gives the duty back
 * to the setting (ON at power 0: dark); nothing lights again at rest. */
static void test_a_hold_in_a_line_goes_dark_where_it_begins(void)
{
    tp_axis up = {0, 2000, 0};
    const uint16_t decel[QS_AXIS_COUNT] = {8000, 8000, 8000, 8000}; /* to rest in about 1,000 ticks */
    line l = {600, 256, 2560, 4, {40, 80, 120, 160}};
    uint16_t t, lit = 0;

    send_outputs_on(0);
    tp_send_segment(&core, 1, 100, 0x01, 0, &up);
    send_raster(2, 0x01, 0, &l);
    expect_ack(QS_ACK_ACCEPTED);
    for (t = 0; t < 150; t++) { /* the ramp, and into the first pixels */
        tick();
        qs_core_poll(&core);
    }
    TEST_ASSERT_TRUE(qs_raster_lit(&core.raster));
    TEST_ASSERT_EQUAL_INT(QS_HOLD_STARTED, qs_engine_hold(&core.engine, decel, 0));
    while (core.engine.state == QS_STATE_RUNNING) {
        TEST_ASSERT_TRUE(qs_raster_lit(&core.raster)); /* the window: still the line's */
        TEST_ASSERT_TRUE(test_laser_power > 0);
        tick();
        qs_core_poll(&core);
        lit++;
    }
    TEST_ASSERT_TRUE(lit > 0 && lit <= QS_TRIGGER_TICKS + 4);
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, core.engine.state);
    TEST_ASSERT_FALSE(qs_raster_lit(&core.raster));
    TEST_ASSERT_EQUAL_INT(0, test_laser_power);
    TEST_ASSERT_EQUAL_UINT16(0, duty_now());
    for (t = 0; t < 2000; t++) { /* the hold, to rest and past */
        tick();
        qs_core_poll(&core);
        TEST_ASSERT_EQUAL_UINT16(0, duty_now());
    }
    TEST_ASSERT_FALSE(core.engine.hold.moving);
    TEST_ASSERT_FALSE(qs_raster_lit(&core.raster));
    TEST_ASSERT_EQUAL_INT(0, test_laser_power);
}

/* The ring keeps QS_RASTER_BYTES powers: a line with no room is QUEUE_FULL (not consumed), and
 * is taken once a line before it has run. */
static void test_a_line_without_room_in_the_ring_waits(void)
{
    tp_axis up = {0, QS_D, 0};
    line l = {60, 256, 256, QS_RASTER_PIXELS_MAX, {0}};
    uint8_t seq = 0, k, fit = (uint8_t)(QS_RASTER_BYTES / QS_RASTER_PIXELS_MAX);

    for (k = 0; k < l.count; k++)
        l.power[k] = k;
    tp_send_segment(&core, seq++, 100, 0x01, 0, &up);
    expect_ack(QS_ACK_ACCEPTED);
    for (k = 0; k < fit; k++) {
        send_raster(seq++, 0x01, 0, &l);
        expect_ack(QS_ACK_ACCEPTED);
    }
    send_raster(seq, 0x01, 0, &l);
    expect_ack(QS_ACK_QUEUE_FULL);
    tp_ticks(&core, 100 + 60 + 1); /* the ramp and the first line run */
    qs_core_poll(&core);
    tp_take_reports(reports, TP_MAX_REPORTS);
    send_raster(seq, 0x01, 0, &l);
    expect_ack(QS_ACK_ACCEPTED);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_power_changes_at_the_step_of_each_boundary);
    RUN_TEST(test_a_diagonal_line_counts_its_pixels_on_the_faster_axis);
    RUN_TEST(test_pixels_shorter_than_a_pwm_period_are_looked_up_ahead);
    RUN_TEST(test_a_line_under_outputs_off_stays_dark);
    RUN_TEST(test_a_hold_in_a_line_goes_dark_where_it_begins);
    RUN_TEST(test_a_line_without_room_in_the_ring_waits);
    return UNITY_END();
}
