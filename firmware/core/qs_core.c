#include "qs_core.h"
#include "qs_dispatch.h"
#include "qs_reports.h"
#include "qs_retransmit.h"
#include "qs_watchdog.h"

void qs_core_init(qs_core *c)
{
    qs_engine_init(&c->engine, QS_QUEUE_CAPACITY);
    qs_inputs_init(&c->inputs, QS_INPUTS_ALL);
    qs_frame_rx_init(&c->rx);
    c->counters.rx_overrun = 0;
    c->counters.bad_frame = 0;
    c->counters.bad_crc = 0;
    c->counters.seq_gap = 0;
    c->counters.seq_dup = 0;
    c->counters.rejected = 0;
    c->next_seq = 0;
    c->axis_count = QS_AXIS_COUNT;
    c->tick_hz = QS_TICK_HZ;
    c->space_announced = 0;
    c->alarm_announced = 0;
    c->watchdog = 0;
    c->heard = 0;
    c->parked = 0;
    c->parked_seq = 0;
    c->parked_head = 0;
    c->boot_id = 0;
    qs_outputs_off(&c->outputs);
#if QS_RASTER_BYTES
    c->raster.write = 0;
    c->raster.line = 0;
    c->raster.bit = 0;
#endif
}

uint8_t qs_core_configure(qs_core *c, uint8_t axis_count, uint8_t queue_capacity, uint32_t tick_hz)
{
    if (axis_count < 1 || axis_count > QS_AXIS_COUNT || queue_capacity < 1
        || queue_capacity > QS_QUEUE_CAPACITY || tick_hz == 0)
        return 0;
    c->axis_count = axis_count;
    c->tick_hz = tick_hz;
    qs_queue_init(&c->engine.queue, queue_capacity);
    return 1;
}

QS_NOINLINE void qs_core_rx_frame(qs_core *c)
{
    uint8_t result = qs_frame_rx_end(&c->rx);
    qs_fault f;

    if (result == QS_FRAME_NOTHING)
        return;
    if (result == QS_FRAME_READY) {
        c->heard = qs_port_clock(); /* the host is there */
        qs_dispatch_frame(c, qs_frame_body(&c->rx), qs_frame_body_len(&c->rx));
        if (c->parked)
            qs_run_parked(c);
        return;
    }
    /* Nothing in a frame that failed these checks can be trusted. */
    qs_count_error(c, result);
    qs_fault_code(&f, result);
    qs_report_error(c, QS_SEQ_UNSOLICITED, QS_SEQ_UNSOLICITED, &f);
}

void qs_core_rx_overrun(qs_core *c)
{
    qs_frame_rx_overrun(&c->rx);
}

/* What the inputs left for the main loop: a hold to begin, an armed
 * motion that ended without its edge. */
static void serve_inputs(qs_core *c)
{
    qs_engine *e = &c->engine;
    const uint8_t request = c->inputs.hold_request;

    if (e->resequence)
        qs_end_stream(c);
    if (qs_core_host_silent(c))
        qs_watchdog_expire(c);
    if (request) {
        c->inputs.hold_request = 0;
        qs_engine_hold(e, request == QS_INPUTS_HOLD_FEED ? e->stop_decel : e->trigger_decel, 0);
        qs_end_stream(c);
    }
    if (e->trigger && e->state == QS_STATE_IDLE && qs_queue_empty(&e->queue)
        && (uint16_t)e->segments_done != e->trigger_since && !qs_inputs_settling(&c->inputs))
        qs_report_probe_missed(c);
}

QS_NOINLINE void qs_core_poll_work(qs_core *c)
{
    qs_engine_finish_freeze(&c->engine);
    qs_engine_retire(&c->engine);
    qs_report_pending_inputs(c);
    /* One SPACE ack covers every segment finished since the last one. */
    if ((uint16_t)c->engine.segments_done != c->space_announced) {
        c->space_announced = (uint16_t)c->engine.segments_done;
        qs_report_ack(c, QS_SEQ_UNSOLICITED, QS_ACK_SPACE);
    }
    /* A hold that ends in an alarm (a silent host) is reported first:
     * HOLD_DONE says when it began and where it rests. */
    qs_report_pending_hold(c);
    if (c->engine.alarm != QS_ALARM_NONE && !c->alarm_announced)
        qs_report_alarm(c);
    serve_inputs(c);
    qs_report_pending_hold(c);
}

void qs_core_status(qs_core *c, qs_status *st)
{
    qs_engine_view v;
    uint8_t axis;

    qs_engine_read(&c->engine, &v);
    st->state = v.state;
    st->alarm = v.alarm;
    st->queue_fill = v.queue_fill;
    st->segments_done = v.segments_done;
    st->motion_ticks = v.motion_ticks;
    st->axis_count = c->axis_count;
    for (axis = 0; axis < c->axis_count; axis++)
        st->position[axis] = v.position[axis];
    st->next_seq = c->next_seq;
    st->counters = c->counters;
}
