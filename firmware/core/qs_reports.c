#include "qs_reports.h"

/* Every report is built in c->tx, after the byte that stuffing needs in
 * front (QS_FRAME_BODY), and sealed and stuffed there in place: no second
 * buffer and no copy. One report at a time: each is sent before the next
 * is built. */

static uint8_t *tx_body(qs_core *c)
{
    return QS_FRAME_BODY(c->tx);
}

static void send_body(qs_core *c, uint8_t len)
{
    qs_port_send(c->tx, qs_frame_seal(c->tx, len));
}

void qs_report_ack(qs_core *c, uint8_t seq, uint8_t reason)
{
    qs_ack a;

    qs_engine_retire(&c->engine);
    a.done = (uint16_t)c->engine.segments_done;
    a.next_seq = c->next_seq;
    a.free = qs_queue_free(&c->engine.queue);
    a.reason = reason;
    send_body(c, qs_msg_encode_ack(tx_body(c), seq, &a));
}

void qs_report_error(qs_core *c, uint8_t seq, uint8_t type, const qs_fault *f)
{
    qs_error_report e;

    e.code = f->code;
    e.type = type;
    e.seq = seq;
    e.field = f->field;
    e.axis = f->axis;
    send_body(c, qs_msg_encode_error(tx_body(c), seq, &e));
}

void qs_report_identify(qs_core *c, uint8_t seq)
{
    qs_identity id;

    id.protocol_version = QS_PROTOCOL_VERSION;
    id.fw_major = QS_FW_MAJOR;
    id.fw_minor = QS_FW_MINOR;
    id.fw_patch = QS_FW_PATCH;
    id.board = QS_BOARD;
    id.axis_count = c->axis_count;
    id.queue_capacity = c->engine.queue.capacity;
    id.speed_shift = QS_SPEED_SHIFT;
    id.n_max = QS_N_MAX;
    id.tick_hz = c->tick_hz;
    id.capabilities = QS_CAP_QUADRATIC_SEGMENTS | QS_CAP_SET_POSITION | QS_CAP_HOLD | QS_CAP_LIMIT_INPUTS
                      | QS_CAP_PROBE_INPUT | QS_CAP_HOMING | QS_CAP_CONTROL_INPUTS
                      | QS_CAP_CONTROLLED_STOPS | QS_CAP_OUTPUTS | QS_CAP_STARVATION_PAUSES
                      | (QS_CUBIC ? QS_CAP_CUBIC_SEGMENTS | QS_CAP_CUBIC_RUNS : 0)
                      | (QS_QUADRATIC_RUNS ? QS_CAP_SEGMENTS : 0) | (QS_RASTER_BYTES ? QS_CAP_RASTER : 0)
                      | QS_CAP_STOPS_ALONG;
    id.next_seq = c->next_seq;
    id.boot_id = c->boot_id;
    id.raster_ring = QS_RASTER_BYTES;
    send_body(c, qs_msg_encode_identify_reply(tx_body(c), seq, &id));
}

void qs_report_pending_inputs(qs_core *c)
{
    const qs_latch *l;

    while (qs_engine_latch_waiting(&c->engine) && (l = qs_engine_oldest_latch(&c->engine)) != 0) {
        send_body(c, qs_msg_encode_input_event(tx_body(c), QS_SEQ_UNSOLICITED, l->u.at.tick, l->active, l->changed,
                                               l->cause, c->axis_count, l->u.at.position));
        qs_engine_free_latch(&c->engine);
    }
}

void qs_report_pending_hold(qs_core *c)
{
    qs_engine *e = &c->engine;
    uint32_t hold_tick;

    qs_report_pending_inputs(c);
    if (qs_engine_take_hold_done(e, &hold_tick))
        send_body(c, qs_msg_encode_hold_done(tx_body(c), QS_SEQ_UNSOLICITED,
                                             e->hold_along ? QS_EVENT_HOLD_DONE_ALONG : QS_EVENT_HOLD_DONE,
                                             hold_tick, e->completed_ticks, c->axis_count, e->base));
}

void qs_report_status(qs_core *c, uint8_t seq, uint8_t hold_first)
{
    qs_status st;

    qs_core_status(c, &st);
    if (hold_first)
        qs_report_pending_hold(c);
    send_body(c, qs_msg_encode_status_report(tx_body(c), seq, &st));
}

void qs_report_alarm(qs_core *c)
{
    qs_alarm_report a;
    qs_engine_view v;
    uint8_t axis;

    qs_engine_read(&c->engine, &v);
    a.code = v.alarm;
    a.motion_ticks = v.motion_ticks;
    a.axis_count = c->axis_count;
    for (axis = 0; axis < c->axis_count; axis++)
        a.position[axis] = v.position[axis];
    c->alarm_announced = 1;
    qs_outputs_off(&c->outputs); /* an alarm leaves every output off until the host sets them again */
    send_body(c, qs_msg_encode_alarm(tx_body(c), QS_SEQ_UNSOLICITED, &a));
}

void qs_report_input_status(qs_core *c, uint8_t seq)
{
    const qs_inputs *in = &c->inputs;
    const qs_engine *e = &c->engine;
    qs_input_status st;

    st.present = in->present;
    st.active = in->active;
    st.raw = in->raw;
    st.invert = in->invert;
    st.enabled = in->enabled;
    st.hard_limits = in->hard_limits;
    st.armed = e->trigger ? e->trigger_input : QS_AXIS_NONE;
    st.level = e->trigger ? e->trigger_level : 0;
    st.latches_lost = e->latches.lost;
    send_body(c, qs_msg_encode_input_status(tx_body(c), seq, &st));
}

QS_NOINLINE void qs_report_probe_missed(qs_core *c)
{
    qs_engine_view v;

    qs_engine_disarm_trigger(&c->engine);
    qs_engine_read(&c->engine, &v);
    send_body(c, qs_msg_encode_probe_missed(tx_body(c), QS_SEQ_UNSOLICITED, v.motion_ticks, c->axis_count,
                                            v.position));
}

void qs_count(uint16_t *counter)
{
    if (*counter != 0xFFFF)
        (*counter)++;
}

void qs_count_error(qs_core *c, uint8_t code)
{
    switch (code) {
    case QS_ERR_RX_OVERRUN:
        qs_count(&c->counters.rx_overrun);
        break;
    case QS_ERR_FRAME_TOO_LONG:
    case QS_ERR_BAD_COBS:
    case QS_ERR_FRAME_TOO_SHORT:
        qs_count(&c->counters.bad_frame);
        break;
    case QS_ERR_BAD_CRC:
        qs_count(&c->counters.bad_crc);
        break;
    default: /* UNKNOWN_TYPE, BAD_LENGTH and every content error */
        qs_count(&c->counters.rejected);
        break;
    }
}

