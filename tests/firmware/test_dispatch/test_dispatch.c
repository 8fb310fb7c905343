/* The core as the host sees it: sequence numbers, acknowledgements, flow
 * control, STOP, SET_POSITION, alarms and counters (PROTOCOL.md 3-6). */
#include <string.h>

#include "qs_core.h"
#include "qs_test_support.h"
#include "unity.h"

static qs_core core;
static tp_report reports[TP_MAX_REPORTS];

static const tp_axis cruise = {4096, 4096, 0}; /* a step every tick, ends moving */
static const tp_axis to_rest = {4096, 0, 0};   /* decelerates to rest */

void setUp(void)
{
    qs_core_init(&core);
    tp_clear_sent();
}

void tearDown(void)
{
    tp_check_unlocked();
}

/* Reports sent since the last call. */
static uint16_t sent(void)
{
    return tp_take_reports(reports, TP_MAX_REPORTS);
}

static qs_ack only_ack(void)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, sent(), "expected exactly one report");
    return tp_ack(&reports[0]);
}

static qs_status status(void)
{
    qs_status st;
    qs_core_status(&core, &st);
    return st;
}

/* An EVENT HOLD_DONE: hold_tick, motion_ticks and axis 0's position. */
typedef struct {
    uint32_t hold_tick, motion_ticks;
    int32_t position;
} hold_done;

static hold_done hold_done_of(const tp_report *r)
{
    hold_done ev;
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_EVENT, r->type);
    TEST_ASSERT_EQUAL_UINT8(QS_SEQ_UNSOLICITED, r->seq);
    TEST_ASSERT_EQUAL_INT(QS_EVENT_HOLD_DONE, r->payload[0]);
    ev.hold_tick = tp_u32(r->payload + 1);
    ev.motion_ticks = tp_u32(r->payload + 5);
    ev.position = (int32_t)tp_u32(r->payload + 9);
    return ev;
}

/* SEGMENTS: three chained records, X accelerating, cruising, stopping. */
static void send_three_records(uint8_t seq)
{
    const uint8_t body[] = {QS_TYPE_SEGMENTS, seq,
                            QS_RECORD_AXES, 100, 0x01, 0xD0, 0x0F,        /* 0 -> 1000 */
                            QS_RECORD_CRUISE, 100,                        /* 1000 */
                            0, 100, 0xCF, 0x0F};                          /* 1000 -> 0 */
    tp_send(&core, body, sizeof body);
}

static void test_segments_take_a_slot_each_all_or_none(void)
{
    qs_ack a;
    qs_core_configure(&core, 4, 4, QS_TICK_HZ);
    tp_send_segment(&core, 0, 50, 0x2, 0, &to_rest);
    tp_send_segment(&core, 1, 50, 0x2, 0, &to_rest);
    sent();
    send_three_records(2); /* two slots free: refused whole, seq kept */
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_QUEUE_FULL, a.reason);
    TEST_ASSERT_EQUAL_INT(2, a.next_seq);
    TEST_ASSERT_EQUAL_INT(2, qs_queue_count(&core.engine.queue));
    TEST_ASSERT_EQUAL_UINT32(25, tp_ticks(&core, 50)); /* the first ends (25 steps): three free */
    qs_core_poll(&core);
    sent();
    send_three_records(2);
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, a.reason);
    TEST_ASSERT_EQUAL_INT(3, a.next_seq);
    TEST_ASSERT_EQUAL_INT(0, a.free);
    TEST_ASSERT_EQUAL_INT(4, qs_queue_count(&core.engine.queue));
    /* X: 0 -> 1000 -> 1000 -> 0 over 300 ticks, 100 * (1000 + 2000 + 1000) / 8192 = 48.8 steps */
    tp_ticks(&core, 1000);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
    TEST_ASSERT_EQUAL_INT32(49, status().position[0]);
    TEST_ASSERT_EQUAL_INT32(50, status().position[1]);
}

/* CUBIC_SEGMENTS: a ramp move on X, 100 ticks a phase, jerks +J, -J, -J, +J
 * (J = 20000: given, then negated, the same, negated). */
static void send_ramp_records(uint8_t seq)
{
    const uint8_t body[] = {QS_TYPE_CUBIC_SEGMENTS, seq,
                            QS_CUBIC_JERK_GIVEN, 0x90, 0x03, 0xC0, 0xB8, 0x02,
                            QS_CUBIC_JERK_NEGATE, 0x90, 0x03,
                            QS_CUBIC_JERK_SAME, 0x90, 0x03,
                            QS_CUBIC_JERK_NEGATE, 0x90, 0x03};
    tp_send(&core, body, sizeof body);
}

static void test_cubic_records_take_a_slot_each_all_or_none(void)
{
    qs_ack a;
    qs_core_configure(&core, 4, 4, QS_TICK_HZ);
    tp_send_segment(&core, 0, 50, 0x2, 0, &to_rest);
    sent();
    send_ramp_records(1); /* three slots free: refused whole, seq kept */
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_QUEUE_FULL, a.reason);
    TEST_ASSERT_EQUAL_INT(1, a.next_seq);
    TEST_ASSERT_EQUAL_INT(1, qs_queue_count(&core.engine.queue));
    tp_ticks(&core, 60);
    qs_core_poll(&core);
    sent();
    send_ramp_records(1);
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, a.reason);
    TEST_ASSERT_EQUAL_INT(2, a.next_seq);
    TEST_ASSERT_EQUAL_INT(4, qs_queue_count(&core.engine.queue));
    tp_ticks(&core, 1000);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
    TEST_ASSERT_EQUAL_INT32(19, status().position[0]); /* cubic_model.py's steps for this ramp */
}

static void test_a_refused_cubic_record_runs_nothing_of_its_frame(void)
{
    const uint8_t body[] = {QS_TYPE_CUBIC_SEGMENTS, 0,
                            QS_CUBIC_JERK_GIVEN, 0xC0, 0x0C, 0xC0, 0xB8, 0x02, /* X: 400 ticks at jerk 20000, some 99 steps */
                            QS_CUBIC_JERK_GIVEN << 2, 0x0C, 0x05};            /* Y: 3 ticks at jerk -3 from rest */
    uint16_t n = 0;
    tp_send(&core, body, sizeof body);
    n = sent();
    TEST_ASSERT_TRUE(n >= 2);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_ERROR, reports[0].type);
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, reports[0].payload[0]);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_SPEED, reports[0].payload[3]);
    TEST_ASSERT_EQUAL_INT(1, reports[0].payload[4]);
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, status().state);
    TEST_ASSERT_EQUAL_INT(0, qs_queue_count(&core.engine.queue));
    tp_ticks(&core, 1000);
    TEST_ASSERT_EQUAL_INT32(0, status().position[0]);
}

static void test_identify_reports_what_the_firmware_is(void)
{
    const uint8_t *p;
    qs_core_configure(&core, 3, 12, 40000);
    core.next_seq = 9;
    core.boot_id = 0xBEEF;
    tp_send_simple(&core, QS_TYPE_IDENTIFY, 200);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_IDENTIFY_REPLY, reports[0].type);
    TEST_ASSERT_EQUAL_UINT8(200, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_LEN_IDENTIFY_REPLY, reports[0].len);
    p = reports[0].payload;
    TEST_ASSERT_EQUAL_INT(3, p[0]);
    TEST_ASSERT_EQUAL_INT(QS_FW_MAJOR, p[1]);
    TEST_ASSERT_EQUAL_INT(QS_BOARD, p[4]);
    TEST_ASSERT_EQUAL_INT(3, p[5]);
    TEST_ASSERT_EQUAL_INT(12, p[6]);
    TEST_ASSERT_EQUAL_INT(12, p[7]);
    TEST_ASSERT_EQUAL_INT(1022, tp_u16(p + 8));
    TEST_ASSERT_EQUAL_UINT32(40000, tp_u32(p + 10));
    /* quadratic, set position, hold; limit, probe and control inputs, homing; cubic; controlled stops;
     * outputs; chained segments (SEGMENTS, CUBIC_SEGMENTS); starvation pauses; RASTER where it is built;
     * stops along the path */
    TEST_ASSERT_EQUAL_HEX16(QS_RASTER_BYTES ? 0xFFF7 : 0xBFF7, tp_u16(p + 14));
    TEST_ASSERT_EQUAL_INT(9, p[16]);
    TEST_ASSERT_EQUAL_HEX16(0xBEEF, tp_u16(p + 17));
    TEST_ASSERT_EQUAL_INT(QS_RASTER_BYTES, tp_u16(p + 19));
}

static void test_in_order_segments_are_accepted_and_counted_free(void)
{
    qs_ack a;
    qs_core_configure(&core, 4, 5, QS_TICK_HZ);
    tp_send_segment(&core, 0, 10, 0x1, 0, &cruise);
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, a.reason);
    TEST_ASSERT_EQUAL_INT(1, a.next_seq);
    TEST_ASSERT_EQUAL_INT(4, a.free);
    TEST_ASSERT_EQUAL_UINT8(0, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state);
}

/* Selective repeat: segments after a lost one wait, parsed, in the slots
 * they will take (ACK PARKED); when it comes they all run in order, each
 * once; one too far ahead for the queue's room is dropped (GAP); a
 * sequenced frame without a slot in between sends them all back (GAP
 * again when resent, then they run); STOP forgets them. */
static void test_parked_segments_run_in_order_once_the_lost_one_arrives(void)
{
    static const tp_axis slow = {100, 100, 0}, slowing = {100, 0, 0};
    qs_status st;
    uint8_t seq;

    qs_core_configure(&core, 4, 6, QS_TICK_HZ);
    tp_send_segment(&core, 0, 100, 0x1, 0, &slow);
    only_ack();
    for (seq = 2; seq <= 5; seq++) {
        tp_send_segment(&core, seq, 100, 0x1, 0, seq == 5 ? &slowing : &slow);
        TEST_ASSERT_EQUAL_INT(QS_ACK_PARKED, only_ack().reason);
    }
    tp_send_segment(&core, 6, 100, 0x1, 0, &slow); /* 5 ahead: no room (5 slots free) */
    TEST_ASSERT_EQUAL_INT(QS_ACK_GAP, only_ack().reason);
    tp_send_segment(&core, 3, 100, 0x1, 0, &slow); /* parked again: the same */
    TEST_ASSERT_EQUAL_INT(QS_ACK_PARKED, only_ack().reason);
    TEST_ASSERT_EQUAL_INT(1, status().queue_fill);
    tp_send_segment(&core, 1, 100, 0x1, 0, &slow);
    TEST_ASSERT_EQUAL_INT(5, sent()); /* 1, then 2..5 */
    for (seq = 0; seq < 5; seq++) {
        qs_ack a = tp_ack(&reports[seq]);
        TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, a.reason);
        TEST_ASSERT_EQUAL_UINT8(1 + seq, reports[seq].seq);
        TEST_ASSERT_EQUAL_INT(2 + seq, a.next_seq);
    }
    st = status();
    TEST_ASSERT_EQUAL_INT(6, st.queue_fill);
    TEST_ASSERT_EQUAL_INT(6, st.next_seq);
    tp_ticks(&core, 600);
    qs_core_poll(&core);
    sent();
    TEST_ASSERT_EQUAL_UINT32(6, status().segments_done);
    /* A SET_POSITION in between takes no slot: what waited behind it goes. */
    tp_send_segment(&core, 8, 100, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_PARKED, only_ack().reason);
    {
        uint8_t body[] = {QS_TYPE_SET_POSITION, 6, 0x00};
        tp_send(&core, body, sizeof body);
        TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
    }
    tp_send_segment(&core, 7, 100, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason); /* and nothing else runs */
    TEST_ASSERT_EQUAL_INT(8, status().next_seq);
    tp_send_segment(&core, 9, 100, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_PARKED, only_ack().reason);
    tp_send_simple(&core, QS_TYPE_STOP, 8);
    sent();
    tp_send_segment(&core, 8, 100, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(1, sent()); /* 9 was forgotten by the STOP */
    TEST_ASSERT_EQUAL_INT(9, status().next_seq);
}

static void test_a_gap_is_refused_and_a_duplicate_never_runs_twice(void)
{
    qs_ack a;
    tp_send_segment(&core, 0, 10, 0x1, 0, &to_rest);
    only_ack();
    /* seq 2 while 1 is expected: frame 1 was lost; 2 waits for it. */
    tp_send_segment(&core, 2, 10, 0x1, 0, &to_rest);
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_PARKED, a.reason);
    TEST_ASSERT_EQUAL_INT(1, a.next_seq);
    TEST_ASSERT_EQUAL_UINT8(2, reports[0].seq);
    /* seq 0 again: its ACK was lost and the host resent it. */
    tp_send_segment(&core, 0, 10, 0x1, 0, &to_rest);
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_DUPLICATE, a.reason);
    TEST_ASSERT_EQUAL_INT(1, a.next_seq);
    TEST_ASSERT_EQUAL_INT(1, status().queue_fill);
    /* The edges: 127 ahead is a gap, 128 ahead a duplicate. */
    tp_send_segment(&core, 128, 10, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_GAP, only_ack().reason);
    tp_send_segment(&core, 129, 10, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_DUPLICATE, only_ack().reason);
    TEST_ASSERT_EQUAL_INT(2, status().counters.seq_gap);
    TEST_ASSERT_EQUAL_INT(2, status().counters.seq_dup);
    TEST_ASSERT_EQUAL_INT(1, status().queue_fill);
    /* Sequenced SET_POSITION follows the same rule. */
    {
        uint8_t body[] = {QS_TYPE_SET_POSITION, 5, 0x00};
        tp_send(&core, body, sizeof body);
        TEST_ASSERT_EQUAL_INT(QS_ACK_GAP, only_ack().reason);
    }
}

static void test_queue_full_keeps_the_seq_and_space_reports_free_slots(void)
{
    qs_ack a;
    qs_core_configure(&core, 4, 2, QS_TICK_HZ);
    tp_send_segment(&core, 0, 3, 0x1, 0, &cruise);
    tp_send_segment(&core, 1, 3, 0x1, 0, &to_rest);
    sent();
    tp_send_segment(&core, 2, 3, 0x1, 0, &to_rest);
    a = only_ack();
    TEST_ASSERT_EQUAL_INT(QS_ACK_QUEUE_FULL, a.reason);
    TEST_ASSERT_EQUAL_INT(2, a.next_seq);
    TEST_ASSERT_EQUAL_INT(0, a.free);
    /* The first segment ends: an unsolicited SPACE ack says so. */
    TEST_ASSERT_EQUAL_UINT32(3, tp_ticks(&core, 3));
    qs_core_poll(&core);
    a = only_ack();
    TEST_ASSERT_EQUAL_UINT8(QS_SEQ_UNSOLICITED, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_ACK_SPACE, a.reason);
    TEST_ASSERT_EQUAL_INT(1, a.free);
    TEST_ASSERT_EQUAL_INT(1, a.done);
    TEST_ASSERT_EQUAL_INT(2, a.next_seq);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent()); /* nothing new, nothing sent */
    tp_send_segment(&core, 2, 3, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
}

static void test_one_space_ack_covers_segments_finished_together(void)
{
    tp_send_segment(&core, 0, 2, 0x1, 0, &cruise);
    tp_send_segment(&core, 1, 2, 0x1, 0, &to_rest);
    sent();
    tp_ticks(&core, 4);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(2, only_ack().done);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
}

static void test_stop_halts_flushes_and_sets_next_seq(void)
{
    qs_status st;
    const uint8_t *p;
    uint32_t steps;
    tp_send_segment(&core, 0, 100, 0x1, 0x1, &cruise);
    tp_send_segment(&core, 1, 100, 0x1, 0x1, &cruise);
    sent();
    steps = tp_ticks(&core, 30);
    tp_send_simple(&core, QS_TYPE_STOP, 77);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_STATUS_REPORT, reports[0].type);
    TEST_ASSERT_EQUAL_UINT8(77, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_LEN_STATUS_REPORT_HEAD + QS_LEN_STATUS_REPORT_AXIS * 4, reports[0].len);
    p = reports[0].payload;
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, p[0]);
    TEST_ASSERT_EQUAL_INT(0, p[2]);  /* queue_fill */
    TEST_ASSERT_EQUAL_INT(77, p[3]); /* next_seq */
    TEST_ASSERT_EQUAL_UINT32(30, tp_u32(p + 8)); /* motion_ticks: the ticks that ran */
    TEST_ASSERT_EQUAL_INT32(-(int32_t)steps, (int32_t)tp_u32(p + 24)); /* steps made stay made */
    TEST_ASSERT_EQUAL_UINT32(30, steps);
    TEST_ASSERT_EQUAL_UINT32(0, tp_ticks(&core, 50));
    st = status();
    TEST_ASSERT_EQUAL_INT32(-30, st.position[0]);
    tp_send_segment(&core, 77, 10, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
}

static void test_status_while_running_reads_the_steps_made_so_far(void)
{
    tp_axis slow = {1000, 3000, 0};
    uint32_t steps;
    tp_send_segment(&core, 0, 1000, 0x2, 0x2, &slow);
    sent();
    steps = tp_ticks(&core, 600);
    TEST_ASSERT_TRUE(steps > 0);
    TEST_ASSERT_EQUAL_INT32(-(int32_t)steps, status().position[1]);
    TEST_ASSERT_EQUAL_UINT32(600, status().motion_ticks);
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state);
}

/* The queue runs dry at full speed and the board rests STARVED: returns
 * the steps made and the ticks the hold took. The next tick begins a hold
 * from the last segment's end at the configured decelerations; at rest
 * HOLD_DONE (hold_tick 10) with the exact rest positions, and no alarm. */
static uint32_t starve(uint32_t *hold_ticks)
{
    uint32_t steps, ticks = 0, hold_steps;
    hold_done ev;
    uint8_t axis;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        core.engine.stop_decel[axis] = 8191;
    tp_send_segment(&core, 0, 10, 0x1, 0, &cruise);
    sent();
    TEST_ASSERT_EQUAL_UINT32(10, tp_ticks(&core, 10));
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state); /* the host may still catch up */
    hold_steps = tp_ticks(&core, 1);
    TEST_ASSERT_EQUAL_UINT32(1, hold_steps); /* at the end speed, one step a tick */
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, status().state);
    while (core.engine.hold.moving && ticks < 10000) {
        hold_steps += tp_ticks(&core, 1);
        ticks++;
    }
    /* From one step a tick at 8191 * 2^-24 step per tick^2: about 2048 ticks, 1024 steps. */
    TEST_ASSERT_TRUE(ticks > 1900 && ticks < 2200);
    TEST_ASSERT_TRUE(hold_steps > 950 && hold_steps < 1100);
    steps = 10 + hold_steps;
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_INT(QS_ACK_SPACE, tp_ack(&reports[0]).reason);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_EVENT, reports[1].type);
    ev = hold_done_of(&reports[1]);
    TEST_ASSERT_EQUAL_UINT32(10, ev.hold_tick);
    TEST_ASSERT_EQUAL_UINT32(11 + ticks, ev.motion_ticks);
    TEST_ASSERT_EQUAL_INT32((int32_t)steps, ev.position);
    TEST_ASSERT_EQUAL_INT32((int32_t)steps, status().position[0]);
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, status().state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, status().alarm);
    TEST_ASSERT_EQUAL_INT(1, status().next_seq);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent()); /* reported once, no ALARM */
    *hold_ticks = ticks;
    return steps;
}

/* STARVED refuses what would take a slot or move, BUSY, consumed, and
 * runs nothing; so SET_POSITION, PROBE and CONFIG. The watchdog stays
 * quiet: nothing moves. */
static void test_an_underrun_ends_starved_and_refuses_motion(void)
{
    const uint8_t watchdog[] = {QS_TYPE_WATCHDOG, 0x40, 100, 0};
    const uint8_t set_position[] = {QS_TYPE_SET_POSITION, 2, 0x1, 0, 0, 0, 0};
    uint32_t ticks, steps = starve(&ticks);
    qs_ack a;

    tp_send(&core, watchdog, sizeof watchdog);
    sent();
    tp_send_segment(&core, 1, 10, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_INT(QS_ERR_BUSY, tp_error(&reports[0]).code);
    a = tp_ack(&reports[1]);
    TEST_ASSERT_EQUAL_INT(QS_ACK_REJECTED, a.reason);
    TEST_ASSERT_EQUAL_INT(2, a.next_seq);
    tp_send(&core, set_position, sizeof set_position);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_INT(QS_ERR_BUSY, tp_error(&reports[0]).code);
    TEST_ASSERT_EQUAL_INT(0, status().queue_fill);
    test_clock = (uint16_t)(test_clock + 60000u); /* far past the watchdog's timeout */
    TEST_ASSERT_EQUAL_UINT32(0, tp_ticks(&core, 1000));
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent());
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, status().state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, status().alarm);
    TEST_ASSERT_EQUAL_INT32((int32_t)steps, status().position[0]);
    TEST_ASSERT_EQUAL_UINT32(11 + ticks, status().motion_ticks);
    TEST_ASSERT_EQUAL_UINT32(1, status().segments_done);
}

/* HOLD takes a starved board up again: IDLE, next_seq the HOLD's seq, the
 * answer and then the starvation's HOLD_DONE repeated; a segment runs. */
static void test_hold_in_starved_returns_to_idle_with_the_hold_done_repeat(void)
{
    uint8_t body[2 + QS_LEN_HOLD] = {QS_TYPE_HOLD, 77, 1, 0, 1, 0, 1, 0, 1, 0};
    uint32_t ticks, steps = starve(&ticks);
    hold_done ev;

    tp_send_segment(&core, 1, 10, 0x1, 0, &to_rest); /* in flight: refused */
    sent();
    tp_send(&core, body, sizeof body);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_STATUS_REPORT, reports[0].type);
    TEST_ASSERT_EQUAL_UINT8(77, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, reports[0].payload[0]);
    TEST_ASSERT_EQUAL_INT(77, reports[0].payload[3]);
    ev = hold_done_of(&reports[1]);
    TEST_ASSERT_EQUAL_UINT32(10, ev.hold_tick);
    TEST_ASSERT_EQUAL_UINT32(11 + ticks, ev.motion_ticks);
    TEST_ASSERT_EQUAL_INT32((int32_t)steps, ev.position);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
    tp_send_segment(&core, 76, 10, 0x1, 0, &to_rest); /* sent before the HOLD: a duplicate */
    TEST_ASSERT_EQUAL_INT(QS_ACK_DUPLICATE, only_ack().reason);
    tp_send_segment(&core, 77, 10, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state);
    TEST_ASSERT_EQUAL_UINT32(5, tp_ticks(&core, 10));
    TEST_ASSERT_EQUAL_INT32((int32_t)steps + 5, status().position[0]);
}

/* A HOLD during the underrun's stop answers for it: the stop ends IDLE. */
static void test_hold_during_the_underrun_stop_ends_idle(void)
{
    uint8_t body[2 + QS_LEN_HOLD] = {QS_TYPE_HOLD, 30, 1, 0, 1, 0, 1, 0, 1, 0};
    uint8_t axis;
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        core.engine.stop_decel[axis] = 8191;
    tp_send_segment(&core, 0, 10, 0x1, 0, &cruise);
    tp_ticks(&core, 12);
    sent();
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, status().state);
    tp_send(&core, body, sizeof body);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, reports[0].payload[0]);
    tp_ticks(&core, 5000);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(10, hold_done_of(&reports[sent() - 1]).hold_tick);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
    TEST_ASSERT_EQUAL_INT(30, status().next_seq);
}

/* STOP in STARVED: IDLE at once, positions kept. */
static void test_stop_in_starved_returns_to_idle(void)
{
    uint32_t ticks, steps = starve(&ticks);

    tp_send_simple(&core, QS_TYPE_STOP, 2);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_STATUS_REPORT, reports[0].type);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, reports[0].payload[0]);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, status().alarm);
    TEST_ASSERT_EQUAL_INT32((int32_t)steps, status().position[0]);
    tp_send_segment(&core, 2, 10, 0x1, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
}

/* A segment that ends moving too slowly for the hold's scale (a cubic one
 * creeping at 100 * 2^-31 step a tick): the underrun's hold has no ticks,
 * and still ends STARVED with its HOLD_DONE at the segment's end. */
static void test_an_underrun_with_nothing_to_decelerate_ends_starved(void)
{
    const uint8_t creep[] = {QS_TYPE_CUBIC_SEGMENT, 0, 20, 0, 0x10, 100, 0, 0, 0, 0, 0, 0};
    hold_done ev;

    tp_send(&core, creep, sizeof creep);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
    TEST_ASSERT_EQUAL_UINT32(0, tp_ticks(&core, 21));
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_INT(QS_ACK_SPACE, tp_ack(&reports[0]).reason);
    ev = hold_done_of(&reports[1]);
    TEST_ASSERT_EQUAL_UINT32(20, ev.hold_tick);
    TEST_ASSERT_EQUAL_UINT32(20, ev.motion_ticks);
    TEST_ASSERT_EQUAL_INT32(0, ev.position);
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, status().state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, status().alarm);
    TEST_ASSERT_EQUAL_UINT32(1, status().segments_done);
}

/* WATCHDOG: while moving, no good frame for the timeout stops at
 * stop_decel; at rest HOLD_DONE, then ALARM HOST_LOST. Any good frame,
 * whatever its seq, keeps it quiet; idle it never fires; 0 turns it off;
 * past 4000 ms it is refused. */
static void test_a_silent_host_stops_the_motion_under_control(void)
{
    const uint8_t set100[] = {QS_TYPE_WATCHDOG, 0x40, 100, 0}, too_long[] = {QS_TYPE_WATCHDOG, 0x41, 0xA1, 0x0F};
    const uint16_t counts = (100 * 1000 + QS_PORT_CLOCK_US - 1) / QS_PORT_CLOCK_US;
    uint8_t axis;
    uint16_t i;

    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        core.engine.stop_decel[axis] = 8191;
    test_clock = 60000; /* wraps during the test */
    tp_send(&core, too_long, sizeof too_long);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(QS_FIELD_TIMEOUT, tp_error(&reports[0]).field);
    tp_send(&core, set100, sizeof set100);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_STATUS_REPORT, reports[0].type);
    test_clock = (uint16_t)(test_clock + 10 * counts); /* idle: nothing to stop */
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent());
    tp_send_segment(&core, 0, 1000, 0x1, 0, &cruise);
    tp_send_segment(&core, 1, 1000, 0x1, 0, &cruise);
    sent();
    for (i = 0; i < 20; i++) { /* a STATUS every half timeout keeps it quiet */
        tp_ticks(&core, 10);
        test_clock = (uint16_t)(test_clock + counts / 2);
        tp_send_simple(&core, QS_TYPE_STATUS, 0x50);
        qs_core_poll(&core);
    }
    sent();
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state);
    test_clock = (uint16_t)(test_clock + counts + 1);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, status().state);
    TEST_ASSERT_EQUAL_INT(0, sent()); /* nothing until it rests */
    tp_ticks(&core, 3000);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_EVENT, reports[0].type);
    TEST_ASSERT_EQUAL_INT(QS_EVENT_HOLD_DONE, reports[0].payload[0]);
    TEST_ASSERT_EQUAL_UINT32(200 + QS_TRIGGER_TICKS, tp_u32(reports[0].payload + 1)); /* after its window */
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_ALARM, reports[1].type);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_HOST_LOST, reports[1].payload[0]);
    TEST_ASSERT_EQUAL_INT32(status().position[0], (int32_t)tp_u32(reports[1].payload + 5));
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, status().state);
    tp_send_simple(&core, QS_TYPE_STOP, 9);
    sent();
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
}

/* No position ever wraps: SET_POSITION past POSITION_MAX is refused, and a
 * segment that could carry an axis past it, with the axis named. */
static void test_positions_cannot_wrap(void)
{
    uint8_t body[2 + 1 + 4];
    int32_t near = QS_POSITION_MAX - 999;
    qs_error_report e;

    body[0] = QS_TYPE_SET_POSITION;
    body[1] = 0;
    body[2] = 0x2;
    body[3] = (uint8_t)near; body[4] = (uint8_t)(near >> 8); body[5] = (uint8_t)(near >> 16); body[6] = (uint8_t)(near >> 24);
    tp_send(&core, body, sizeof body);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
    near = QS_POSITION_MAX + 1;
    body[1] = 1;
    body[3] = (uint8_t)near; body[4] = (uint8_t)(near >> 8); body[5] = (uint8_t)(near >> 16); body[6] = (uint8_t)(near >> 24);
    tp_send(&core, body, sizeof body);
    TEST_ASSERT_EQUAL_INT(2, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_POSITION, e.field);
    TEST_ASSERT_EQUAL_INT(1, e.axis);
    /* 999 ticks fit (they move it 500), then 500 more could pass the limit */
    tp_send_segment(&core, 2, 999, 0x2, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
    tp_send_segment(&core, 3, 500, 0x2, 0, &to_rest);
    TEST_ASSERT_EQUAL_INT(3, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_POSITION, e.field);
    TEST_ASSERT_EQUAL_INT(1, e.axis);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_ALARM, reports[2].type);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_REJECTED_SEGMENT, reports[2].payload[0]);
}

static void test_a_segment_ending_at_rest_returns_to_idle(void)
{
    tp_send_segment(&core, 0, 10, 0x1, 0, &to_rest);
    tp_ticks(&core, 10);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, status().alarm);
    TEST_ASSERT_EQUAL_INT32(5, status().position[0]); /* (0 + 10*(4096+0) + 4096) / 8192 */
}

static void test_a_rejected_segment_halts_everything_and_raises_an_alarm(void)
{
    tp_axis bad = {5000, 0, 0};
    tp_axis two[2];
    const uint8_t *p;
    uint32_t made;
    qs_error_report e;

    tp_send_segment(&core, 0, 100, 0x1, 0, &cruise);
    tp_send_segment(&core, 1, 100, 0x1, 0, &cruise);
    sent();
    made = tp_ticks(&core, 20);
    two[0] = cruise;
    two[1] = bad;
    tp_send_segment(&core, 2, 100, 0x3, 0, two);
    TEST_ASSERT_EQUAL_INT(3, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, e.code);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_V0, e.field);
    TEST_ASSERT_EQUAL_INT(1, e.axis);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_SEGMENT, e.type);
    TEST_ASSERT_EQUAL_UINT8(2, e.seq);
    TEST_ASSERT_EQUAL_INT(QS_ACK_REJECTED, tp_ack(&reports[1]).reason);
    TEST_ASSERT_EQUAL_INT(3, tp_ack(&reports[1]).next_seq);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_ALARM, reports[2].type);
    p = reports[2].payload;
    TEST_ASSERT_EQUAL_INT(QS_ALARM_REJECTED_SEGMENT, p[0]);
    TEST_ASSERT_EQUAL_UINT32(20, tp_u32(p + 1));
    TEST_ASSERT_EQUAL_INT32((int32_t)made, (int32_t)tp_u32(p + 5));
    TEST_ASSERT_EQUAL_UINT32(0, tp_ticks(&core, 100));
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, status().state);
    TEST_ASSERT_EQUAL_INT(0, status().queue_fill);
    TEST_ASSERT_EQUAL_INT(1, status().counters.rejected);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent()); /* the alarm was reported once */
}

static void test_set_position_only_when_idle(void)
{
    uint8_t body[QS_MAX_FRAME] = {QS_TYPE_SET_POSITION, 0, 0x05,
                                  0x10, 0x00, 0x00, 0x00,  /* axis 0: 16 */
                                  0xFE, 0xFF, 0xFF, 0xFF}; /* axis 2: -2 */
    qs_error_report e;

    tp_send_segment(&core, 0, 10, 0x1, 0, &to_rest);
    sent();
    body[1] = 1;
    tp_send(&core, body, 11);
    TEST_ASSERT_EQUAL_INT(2, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_BUSY, e.code);
    TEST_ASSERT_EQUAL_INT(QS_ACK_REJECTED, tp_ack(&reports[1]).reason);
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state); /* no alarm */
    tp_ticks(&core, 10);
    body[1] = 2;
    tp_send(&core, body, 11);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, only_ack().reason);
    TEST_ASSERT_EQUAL_INT32(16, status().position[0]);
    TEST_ASSERT_EQUAL_INT32(0, status().position[1]);
    TEST_ASSERT_EQUAL_INT32(-2, status().position[2]);
    /* A mask bit beyond the axis count. */
    qs_core_configure(&core, 2, QS_QUEUE_CAPACITY, QS_TICK_HZ);
    body[1] = 3;
    tp_send(&core, body, 11);
    TEST_ASSERT_EQUAL_INT(2, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, e.code);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_AXES, e.field);
    TEST_ASSERT_EQUAL_INT32(16, status().position[0]);
}

static void test_message_errors_name_the_frame_and_count(void)
{
    uint8_t body[] = {0x3E, 44};
    qs_error_report e;
    tp_send(&core, body, sizeof body);
    TEST_ASSERT_EQUAL_INT(1, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_UNKNOWN_TYPE, e.code);
    TEST_ASSERT_EQUAL_HEX8(0x3E, e.type);
    TEST_ASSERT_EQUAL_UINT8(44, e.seq);
    TEST_ASSERT_EQUAL_UINT8(44, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_NONE, e.field);
    TEST_ASSERT_EQUAL_HEX8(QS_AXIS_NONE, e.axis);
    TEST_ASSERT_EQUAL_INT(1, status().counters.rejected);
    TEST_ASSERT_EQUAL_INT(0, core.next_seq); /* not consumed */
}

static void test_counters_saturate(void)
{
    static const uint8_t bad_crc[] = {0x05, 0x02, 0x01, 0x12, 0x34, 0x00};
    uint32_t i, j;
    for (i = 0; i < 65540; i++) {
        for (j = 0; j < sizeof bad_crc; j++)
            qs_core_rx(&core, bad_crc[j]);
        if (i % 1024 == 0)
            tp_clear_sent();
    }
    for (i = 0; i < 70000; i++) {
        qs_core_rx_overrun(&core);
        qs_core_rx(&core, 0);
        if (i % 1024 == 0)
            tp_clear_sent();
    }
    tp_clear_sent();
    TEST_ASSERT_EQUAL_INT(65535, status().counters.bad_crc);
    TEST_ASSERT_EQUAL_INT(65535, status().counters.rx_overrun);
    TEST_ASSERT_EQUAL_INT(0, status().counters.bad_frame);
}

static void test_an_overrun_discards_the_frame_in_progress(void)
{
    uint8_t body[QS_MAX_FRAME] = {QS_TYPE_STATUS, 3};
    uint8_t wire[QS_MAX_WIRE];
    uint8_t n = qs_frame_encode(body, 2, wire), i;
    qs_error_report e;

    for (i = 0; i < n; i++) {
        if (i == 1)
            qs_core_rx_overrun(&core);
        qs_core_rx(&core, wire[i]);
    }
    TEST_ASSERT_EQUAL_INT(1, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_RX_OVERRUN, e.code);
    TEST_ASSERT_EQUAL_HEX8(0xFF, e.type);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_identify_reports_what_the_firmware_is);
    RUN_TEST(test_in_order_segments_are_accepted_and_counted_free);
    RUN_TEST(test_a_gap_is_refused_and_a_duplicate_never_runs_twice);
    RUN_TEST(test_parked_segments_run_in_order_once_the_lost_one_arrives);
    RUN_TEST(test_queue_full_keeps_the_seq_and_space_reports_free_slots);
    RUN_TEST(test_segments_take_a_slot_each_all_or_none);
    RUN_TEST(test_cubic_records_take_a_slot_each_all_or_none);
    RUN_TEST(test_a_refused_cubic_record_runs_nothing_of_its_frame);
    RUN_TEST(test_one_space_ack_covers_segments_finished_together);
    RUN_TEST(test_stop_halts_flushes_and_sets_next_seq);
    RUN_TEST(test_status_while_running_reads_the_steps_made_so_far);
    RUN_TEST(test_an_underrun_ends_starved_and_refuses_motion);
    RUN_TEST(test_hold_in_starved_returns_to_idle_with_the_hold_done_repeat);
    RUN_TEST(test_stop_in_starved_returns_to_idle);
    RUN_TEST(test_hold_during_the_underrun_stop_ends_idle);
    RUN_TEST(test_an_underrun_with_nothing_to_decelerate_ends_starved);
    RUN_TEST(test_a_silent_host_stops_the_motion_under_control);
    RUN_TEST(test_positions_cannot_wrap);
    RUN_TEST(test_a_segment_ending_at_rest_returns_to_idle);
    RUN_TEST(test_a_rejected_segment_halts_everything_and_raises_an_alarm);
    RUN_TEST(test_set_position_only_when_idle);
    RUN_TEST(test_message_errors_name_the_frame_and_count);
    RUN_TEST(test_counters_saturate);
    RUN_TEST(test_an_overrun_discards_the_frame_in_progress);
    return UNITY_END();
}
