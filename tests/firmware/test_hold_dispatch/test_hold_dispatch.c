/* HOLD as the host sees it (PROTOCOL.md 5.1, 5.3): the answer, the state
 * HOLDING, HOLD_DONE with the exact rest position, segments refused while
 * holding, next_seq, STOP during a hold, refusals that change nothing. */
#include <string.h>

#include "qs_core.h"
#include "qs_engine_tick.h"
#include "qs_test_support.h"
#include "unity.h"

static qs_core core;
static tp_report reports[TP_MAX_REPORTS];

static const tp_axis cruise = {4096, 4096, 0}; /* a step every tick, ends moving */
static const tp_axis cruise2[2] = {{4096, 4096, 0}, {4096, 4096, 0}};
static const tp_axis half2[2] = {{2048, 2048, 0}, {2048, 2048, 0}};

void setUp(void)
{
    qs_core_init(&core);
    tp_clear_sent();
}

void tearDown(void)
{
    tp_check_unlocked();
}

static uint16_t sent(void)
{
    return tp_take_reports(reports, TP_MAX_REPORTS);
}

static void send_hold(uint8_t seq, uint16_t d0, uint16_t d1, uint16_t d2, uint16_t d3)
{
    uint8_t body[2 + QS_LEN_HOLD];
    const uint16_t d[4] = {d0, d1, d2, d3};
    uint8_t i;

    body[0] = QS_TYPE_HOLD;
    body[1] = seq;
    for (i = 0; i < 4; i++) {
        body[2 + 2 * i] = (uint8_t)d[i];
        body[3 + 2 * i] = (uint8_t)(d[i] >> 8);
    }
    tp_send(&core, body, sizeof body);
}

typedef struct {
    uint8_t kind;
    uint32_t hold_tick;
    uint32_t motion_ticks;
    int32_t position[4];
} hold_done;

static hold_done event(const tp_report *r, uint8_t axis_count)
{
    hold_done ev;
    uint8_t axis;
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_EVENT, r->type);
    TEST_ASSERT_EQUAL_UINT8(QS_SEQ_UNSOLICITED, r->seq);
    TEST_ASSERT_EQUAL_INT(QS_LEN_HOLD_DONE_HEAD + QS_LEN_HOLD_DONE_AXIS * axis_count, r->len);
    ev.kind = r->payload[0];
    ev.hold_tick = tp_u32(r->payload + 1);
    ev.motion_ticks = tp_u32(r->payload + 5);
    for (axis = 0; axis < axis_count; axis++)
        ev.position[axis] = (int32_t)tp_u32(r->payload + 9 + 4 * axis);
    return ev;
}

static qs_status status(void)
{
    qs_status st;
    qs_core_status(&core, &st);
    return st;
}

/* Run the tick until the hold is over, polling like a main loop; returns
 * the steps each axis made (signed) and the ticks taken. */
static uint32_t run_until_rest(int32_t *moved)
{
    uint32_t ticks = 0;
    while (core.engine.state == QS_STATE_HOLDING || core.engine.trigger_window) {
        uint8_t bits = qs_engine_tick(&core.engine);
        uint8_t axis;
        for (axis = 0; axis < 4; axis++)
            if (bits & (1u << axis))
                moved[axis] += ((core.engine.dir_bits >> axis) & 1) ? -1 : 1;
        ticks++;
        qs_core_poll(&core);
        TEST_ASSERT_TRUE(ticks < 1000000);
    }
    return ticks;
}

static void test_hold_while_idle_answers_and_reports_done_at_once(void)
{
    const uint8_t *p;
    hold_done ev;
    qs_core_configure(&core, 3, 8, QS_TICK_HZ);
    send_hold(40, 1, 2, 3, 0);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_STATUS_REPORT, reports[0].type);
    TEST_ASSERT_EQUAL_UINT8(40, reports[0].seq);
    p = reports[0].payload;
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, p[0]);
    TEST_ASSERT_EQUAL_INT(40, p[3]); /* next_seq is the HOLD's seq */
    ev = event(&reports[1], 3);
    TEST_ASSERT_EQUAL_INT(QS_EVENT_HOLD_DONE, ev.kind);
    TEST_ASSERT_EQUAL_UINT32(0, ev.hold_tick);
    TEST_ASSERT_EQUAL_UINT32(0, ev.motion_ticks);
    TEST_ASSERT_EQUAL_INT32(0, ev.position[0]);
}

/* The full story: running, HOLD, HOLDING (the motion runs on through the
 * hold's window, the queued tail is discarded when the hold ends) and
 * segments refused, then HOLD_DONE with the steps really made. */
static void test_hold_while_running_decelerates_and_reports_where_it_rests(void)
{
    int32_t moved[4] = {0, 0, 0, 0};
    uint32_t ticks;
    const uint8_t *p;
    hold_done ev;
    qs_error_report e;
    qs_ack a;
    qs_status st;
    uint8_t seq;

    for (seq = 0; seq < 5; seq++)
        tp_send_segment(&core, seq, 1000, 0x5, 0x4, seq % 2 ? half2 : cruise2);
    sent();
    ticks = 1500;
    moved[0] = (int32_t)tp_ticks(&core, ticks) / 2;
    moved[2] = -moved[0];
    TEST_ASSERT_EQUAL_INT32(moved[0], status().position[0]);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(QS_ACK_SPACE, tp_ack(&reports[sent() - 1]).reason); /* segment 0 done */
    send_hold(99, 4000, 4000, 100, 4000);
    TEST_ASSERT_EQUAL_INT(1, sent());
    p = reports[0].payload;
    TEST_ASSERT_EQUAL_UINT8(99, reports[0].seq);
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, p[0]);
    TEST_ASSERT_EQUAL_INT(4, p[2]);  /* the tail goes when the hold ends */
    TEST_ASSERT_EQUAL_INT(99, p[3]);
    TEST_ASSERT_EQUAL_UINT32(1500, tp_u32(p + 8));
    /* A segment while holding: refused, consumed, no alarm. */
    tp_send_segment(&core, 99, 10, 0x1, 0, &cruise);
    TEST_ASSERT_EQUAL_INT(2, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_BUSY, e.code);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_SEGMENT, e.type);
    a = tp_ack(&reports[1]);
    TEST_ASSERT_EQUAL_INT(QS_ACK_REJECTED, a.reason);
    TEST_ASSERT_EQUAL_INT(100, a.next_seq);
    /* A second HOLD changes nothing and is answered alone. */
    send_hold(100, 1, 1, 1, 1);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, reports[0].payload[0]);
    ticks += run_until_rest(moved);
    TEST_ASSERT_EQUAL_INT(1, sent());
    ev = event(&reports[0], 4);
    TEST_ASSERT_EQUAL_UINT32(1500 + QS_TRIGGER_TICKS, ev.hold_tick);
    TEST_ASSERT_EQUAL_UINT32(ticks, ev.motion_ticks);
    TEST_ASSERT_EQUAL_INT32(moved[0], ev.position[0]);
    TEST_ASSERT_EQUAL_INT32(0, ev.position[1]);
    TEST_ASSERT_EQUAL_INT32(moved[2], ev.position[2]);
    /* From half a step per tick, v^2/2a: axis 0 (decel 4000) about 524
     * steps, axis 2 (decel 100) about 21,000 in some 85,000 ticks. */
    TEST_ASSERT_TRUE(moved[0] - 1250 > 500 && moved[0] - 1250 < 550);
    TEST_ASSERT_TRUE(-moved[2] - 1250 > 20000 && -moved[2] - 1250 < 22000);
    TEST_ASSERT_TRUE(ticks - 1500 > 80000 && ticks - 1500 < 90000);
    st = status();
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, st.state);
    TEST_ASSERT_EQUAL_INT(0, st.queue_fill);
    TEST_ASSERT_EQUAL_UINT32(1, st.segments_done);
    TEST_ASSERT_EQUAL_UINT32(ticks, st.motion_ticks);
    /* Nothing queued before the hold ever runs; new segments do. */
    TEST_ASSERT_EQUAL_UINT32(0, tp_ticks(&core, 3000));
    tp_send_segment(&core, 100, 10, 0x1, 0, &cruise);
    TEST_ASSERT_EQUAL_INT(QS_ACK_ACCEPTED, tp_ack(&reports[sent() - 1]).reason);
}

/* HOLD_DONE goes out before anything else the core sends after the hold
 * ends, even when the main loop has not polled. */
static void test_hold_done_comes_before_any_later_answer(void)
{
    int32_t moved[4] = {0, 0, 0, 0};
    tp_send_segment(&core, 0, 500, 0x2, 0, &cruise);
    tp_ticks(&core, 100);
    send_hold(1, 8191, 8191, 8191, 8191);
    sent();
    while (core.engine.hold.moving || core.engine.trigger_window)
        tp_ticks(&core, 1);
    tp_send_simple(&core, QS_TYPE_STATUS, 7);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_EVENT, reports[0].type);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_STATUS_REPORT, reports[1].type);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, reports[1].payload[0]);
    TEST_ASSERT_EQUAL_INT32(event(&reports[0], 4).position[1], (int32_t)tp_u32(reports[1].payload + 28));
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent()); /* reported once */
    TEST_ASSERT_EQUAL_UINT32(0, run_until_rest(moved));
}

static void test_stop_during_a_hold_stops_at_once(void)
{
    const uint8_t *p;
    tp_send_segment(&core, 0, 1000, 0x1, 0, &cruise);
    tp_ticks(&core, 10);
    send_hold(1, 1, 1, 1, 1);
    tp_ticks(&core, 20);
    sent();
    tp_send_simple(&core, QS_TYPE_STOP, 50);
    TEST_ASSERT_EQUAL_INT(1, sent()); /* no HOLD_DONE: the hold did not finish */
    p = reports[0].payload;
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, p[0]);
    TEST_ASSERT_EQUAL_UINT32(30, tp_u32(p + 8));
    TEST_ASSERT_EQUAL_INT32(30, (int32_t)tp_u32(p + 24));
    TEST_ASSERT_EQUAL_UINT32(0, tp_ticks(&core, 10));
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(0, sent());
}

/* A HOLD that breaks a limit, or arrives in ALARM, is refused with an ERROR
 * naming why, and nothing changes: the job runs on, next_seq stays. */
static void test_refused_holds_change_nothing(void)
{
    qs_error_report e;
    qs_core_configure(&core, 3, 8, QS_TICK_HZ);
    tp_send_segment(&core, 0, 100, 0x1, 0, &cruise);
    tp_send_segment(&core, 1, 100, 0x1, 0, &cruise);
    sent();
    tp_ticks(&core, 10);
    send_hold(60, 10, 8192, 10, 0);
    TEST_ASSERT_EQUAL_INT(1, sent());
    e = tp_error(&reports[0]);
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, e.code);
    TEST_ASSERT_EQUAL_INT(QS_FIELD_DECEL, e.field);
    TEST_ASSERT_EQUAL_INT(1, e.axis);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_HOLD, e.type);
    TEST_ASSERT_EQUAL_UINT8(60, e.seq);
    send_hold(61, 10, 10, 10, 10); /* axis 3 on a 3-axis firmware */
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(3, tp_error(&reports[0]).axis);
    TEST_ASSERT_EQUAL_INT(QS_STATE_RUNNING, status().state);
    TEST_ASSERT_EQUAL_INT(2, status().next_seq);
    TEST_ASSERT_EQUAL_INT(2, status().queue_fill);
    TEST_ASSERT_EQUAL_UINT32(2, status().counters.rejected);
    TEST_ASSERT_EQUAL_UINT32(190, tp_ticks(&core, 190));
    tp_ticks(&core, 1);
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, status().state); /* the underrun's hold */
    tp_ticks(&core, 70000);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, status().state); /* then paused */
    sent();
    send_hold(62, 10, 8192, 10, 0); /* a bad HOLD leaves it so */
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(QS_ERR_BAD_FIELD, tp_error(&reports[0]).code);
    TEST_ASSERT_EQUAL_INT(QS_STATE_STARVED, status().state);
    TEST_ASSERT_EQUAL_INT(2, status().next_seq);
    tp_send_simple(&core, QS_TYPE_STOP, 3);
    tp_send_segment(&core, 3, 0, 0x1, 0, &cruise); /* n = 0: ALARM REJECTED_SEGMENT */
    sent();
    send_hold(63, 10, 10, 10, 0); /* in ALARM: refused */
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(QS_ERR_ALARM_ACTIVE, tp_error(&reports[0]).code);
    TEST_ASSERT_EQUAL_INT(4, status().next_seq);
    TEST_ASSERT_EQUAL_INT(QS_STATE_ALARM, status().state);
}

/* A hold finds the queue run dry while moving: it holds from where the
 * last segment ended (hold_tick at its end), to rest, with no alarm. */
static void test_hold_at_an_underrun_holds_from_the_last_segment_end(void)
{
    tp_send_segment(&core, 0, 10, 0x1, 0, &cruise);
    tp_ticks(&core, 10);
    sent();
    send_hold(5, 8191, 8191, 8191, 8191);
    TEST_ASSERT_EQUAL_INT(1, sent());
    TEST_ASSERT_EQUAL_INT(QS_STATE_HOLDING, reports[0].payload[0]);
    tp_ticks(&core, 5000);
    qs_core_poll(&core);
    TEST_ASSERT_EQUAL_INT(2, sent());
    TEST_ASSERT_EQUAL_INT(QS_ACK_SPACE, tp_ack(&reports[0]).reason);
    TEST_ASSERT_EQUAL_HEX8(QS_TYPE_EVENT, reports[1].type);
    TEST_ASSERT_EQUAL_INT(QS_EVENT_HOLD_DONE, reports[1].payload[0]);
    TEST_ASSERT_EQUAL_UINT32(10, tp_u32(reports[1].payload + 1));
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, status().state);
    TEST_ASSERT_EQUAL_INT(QS_ALARM_NONE, status().alarm);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_hold_while_idle_answers_and_reports_done_at_once);
    RUN_TEST(test_hold_while_running_decelerates_and_reports_where_it_rests);
    RUN_TEST(test_hold_done_comes_before_any_later_answer);
    RUN_TEST(test_stop_during_a_hold_stops_at_once);
    RUN_TEST(test_refused_holds_change_nothing);
    RUN_TEST(test_hold_at_an_underrun_holds_from_the_last_segment_end);
    return UNITY_END();
}
