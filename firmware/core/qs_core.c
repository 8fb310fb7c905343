#include "qs_core.h"
#include "qs_port.h"
#include "qs_protocol.h"
#include "qs_cubic_records.h"
#include "qs_segments.h"
#include "qs_raster.h"

/* ---- sending ----
 * Every report is built in c->tx, after the byte that stuffing needs in
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

static void send_ack(qs_core *c, uint8_t seq, uint8_t reason)
{
    qs_ack a;

    qs_engine_retire(&c->engine);
    a.done = (uint16_t)c->engine.segments_done;
    a.next_seq = c->next_seq;
    a.free = qs_queue_free(&c->engine.queue);
    a.reason = reason;
    send_body(c, qs_msg_encode_ack(tx_body(c), seq, &a));
}

static void send_error(qs_core *c, uint8_t seq, uint8_t type, const qs_fault *f)
{
    qs_error_report e;

    e.code = f->code;
    e.type = type;
    e.seq = seq;
    e.field = f->field;
    e.axis = f->axis;
    send_body(c, qs_msg_encode_error(tx_body(c), seq, &e));
}

static void send_identify_reply(qs_core *c, uint8_t seq)
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
                      | QS_CAP_CUBIC_SEGMENTS | QS_CAP_CONTROLLED_STOPS | QS_CAP_OUTPUTS | QS_CAP_SEGMENTS
                      | (QS_RASTER_BYTES ? QS_CAP_RASTER : 0)
                      | QS_CAP_CUBIC_RUNS | QS_CAP_STARVATION_PAUSES;
    id.next_seq = c->next_seq;
    id.boot_id = c->boot_id;
    send_body(c, qs_msg_encode_identify_reply(tx_body(c), seq, &id));
}

/* The EVENT HOLD_DONE of a finished hold, once. Sent before anything else
 * is handled and before any status that shows the hold over, so a host
 * learns where the axes rest before it sees them idle. */
static void report_pending_hold(qs_core *c);

/* EVENT INPUT for every latched input change, oldest first, before
 * anything else is reported (a trigger's latch precedes its HOLD_DONE). */
static void report_pending_inputs(qs_core *c)
{
    const qs_latch *l;

    while (qs_engine_latch_waiting(&c->engine) && (l = qs_engine_oldest_latch(&c->engine)) != 0) {
        send_body(c, qs_msg_encode_input_event(tx_body(c), QS_SEQ_UNSOLICITED, l->u.at.tick, l->active, l->changed,
                                               l->cause, c->axis_count, l->u.at.position));
        qs_engine_free_latch(&c->engine);
    }
}

static void report_pending_hold(qs_core *c)
{
    qs_engine *e = &c->engine;
    uint32_t hold_tick;

    report_pending_inputs(c);
    if (qs_engine_take_hold_done(e, &hold_tick))
        send_body(c, qs_msg_encode_hold_done(tx_body(c), QS_SEQ_UNSOLICITED, hold_tick, e->completed_ticks,
                                             c->axis_count, e->base));
}

/* The answer to seq. With hold_first, a hold that ended while the status
 * was read is reported first. */
static void send_status_report(qs_core *c, uint8_t seq, uint8_t hold_first)
{
    qs_status st;

    qs_core_status(c, &st);
    if (hold_first)
        report_pending_hold(c);
    send_body(c, qs_msg_encode_status_report(tx_body(c), seq, &st));
}

static void send_alarm(qs_core *c)
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

/* ---- bookkeeping ---- */

static void count(uint16_t *counter)
{
    if (*counter != 0xFFFF)
        (*counter)++;
}

static void count_error(qs_core *c, uint8_t code)
{
    switch (code) {
    case QS_ERR_RX_OVERRUN:
        count(&c->counters.rx_overrun);
        break;
    case QS_ERR_FRAME_TOO_LONG:
    case QS_ERR_BAD_COBS:
    case QS_ERR_FRAME_TOO_SHORT:
        count(&c->counters.bad_frame);
        break;
    case QS_ERR_BAD_CRC:
        count(&c->counters.bad_crc);
        break;
    default: /* UNKNOWN_TYPE, BAD_LENGTH and every content error */
        count(&c->counters.rejected);
        break;
    }
}

static void fault(qs_fault *f, uint8_t code)
{
    f->code = code;
    f->field = QS_FIELD_NONE;
    f->axis = QS_AXIS_NONE;
}

/* Consume a sequenced frame that cannot be executed. */
static void reject(qs_core *c, const qs_host_msg *m, const qs_fault *f)
{
    count_error(c, f->code);
    send_error(c, m->seq, m->type, f);
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_REJECTED);
}

/* ---- messages ---- */

/* Whether a segment may be taken in this state; refused (consumed) if not. */
static uint8_t may_queue(qs_core *c, const qs_host_msg *m)
{
    qs_fault f;

    if (c->engine.state == QS_STATE_ALARM) {
        fault(&f, QS_ERR_ALARM_ACTIVE);
        reject(c, m, &f);
        return 0;
    }
    if (c->engine.state == QS_STATE_HOLDING || c->engine.state == QS_STATE_STARVED || c->engine.trigger_window) {
        /* The host learns of the hold's end from HOLD_DONE: a segment sent
         * before that was planned for motion the hold discarded, and must
         * not start from rest. After an underrun's stop (STARVED) a HOLD
         * takes the board to IDLE first. */
        fault(&f, QS_ERR_BUSY);
        reject(c, m, &f);
        return 0;
    }
    return 1;
}

/* A segment the engine could not run exactly: later segments were planned
 * from where this one would have left the axes, so everything stops. */
static void refuse_segment(qs_core *c, const qs_host_msg *m, const qs_fault *f)
{
    qs_engine_halt(&c->engine, QS_STATE_ALARM, QS_ALARM_REJECTED_SEGMENT);
    c->alarm_announced = 0;
    reject(c, m, f);
    send_alarm(c);
}

static void queued(qs_core *c, const qs_host_msg *m)
{
    qs_queue_publish(&c->engine.queue);
    qs_engine_wake(&c->engine);
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_ACCEPTED);
}

/* Whether the segment could carry a position past QS_POSITION_MAX; if so f
 * names the axis. */
static uint8_t beyond_positions(qs_core *c, uint8_t active, uint16_t n, qs_fault *f)
{
    uint8_t axis;

    if (qs_engine_room_for(&c->engine, active, n, &axis))
        return 0;
    f->code = QS_ERR_BAD_FIELD;
    f->field = QS_FIELD_POSITION;
    f->axis = axis;
    return 1;
}

static void on_segment(qs_core *c, const qs_host_msg *m)
{
    qs_engine *e = &c->engine;
    qs_segment *slot;
    qs_fault f;

    if (!may_queue(c, m))
        return;
    if (qs_msg_check_segment(&m->as.segment, c->axis_count, &f) != QS_ERR_NONE
        || beyond_positions(c, m->as.segment.active, m->as.segment.n, &f)) {
        refuse_segment(c, m, &f);
        return;
    }
    if (qs_queue_free(&e->queue) == 0) {
        send_ack(c, m->seq, QS_ACK_QUEUE_FULL);
        return;
    }
    slot = qs_queue_back(&e->queue);
    qs_segment_prepare(slot, &m->as.segment);
    qs_cubic_follow_quadratic(&e->chain, slot, &m->as.segment);
    qs_engine_note_prepared(e, slot);
    qs_outputs_carry(&c->outputs, slot);
    queued(c, m);
}

/* SEGMENTS and CUBIC_SEGMENTS: all or none. Each record is read against
 * the chain, checked and prepared into the next free slot in turn (which
 * moves the chain on); the slots are published together after the last,
 * so a refused record runs nothing of the frame. */
static QS_NOINLINE void on_segments(qs_core *c, qs_host_msg *m, uint8_t cubic)
{
    qs_engine *e = &c->engine;
    qs_segments_msg run = m->as.segments; /* each record in turn goes to the message's own room (the Uno's stack) */
    qs_fault f;
    uint8_t head, left;

    if (!may_queue(c, m))
        return;
    if (qs_queue_free(&e->queue) < run.count) {
        send_ack(c, m->seq, QS_ACK_QUEUE_FULL);
        return;
    }
    head = e->queue.head;
    for (left = run.count; left; left--) {
        qs_segment *slot = qs_queue_at(&e->queue, head);
        uint8_t refused;

        if (cubic) {
            qs_cubic_msg *const s = &m->as.cubic;

            refused = qs_cubic_records_next(&run, &e->chain, c->axis_count, s, &f) != QS_ERR_NONE
                      || qs_cubic_prepare(&e->chain, slot, s, c->axis_count, &f) != QS_ERR_NONE
                      || beyond_positions(c, (uint8_t)((1u << c->axis_count) - 1u), s->n, &f);
        } else {
            qs_segment_msg *const s = &m->as.segment;

            refused = qs_segments_next(&run, &e->chain, c->axis_count, s, &f) != QS_ERR_NONE
                      || qs_msg_check_segment(s, c->axis_count, &f) != QS_ERR_NONE
                      || beyond_positions(c, s->active, s->n, &f);
            if (!refused) {
                qs_segment_prepare(slot, s);
                qs_cubic_follow_quadratic(&e->chain, slot, s);
            }
        }
        if (refused) {
            refuse_segment(c, m, &f);
            return;
        }
        qs_engine_note_prepared(e, slot);
        qs_outputs_carry(&c->outputs, slot);
        head = qs_queue_next(&e->queue, head);
    }
    qs_queue_publish_to(&e->queue, head);
    qs_engine_wake(e);
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_ACCEPTED);
}

#if QS_RASTER_BYTES
static uint8_t in_sequence(qs_core *c, const qs_host_msg *m);

/* RASTER: its motion is the chain's cruise, read as a SEGMENTS record that
 * says nothing but n and the axes; then the line's own checks, and its
 * powers into the ring beside the slot. */
static QS_NOINLINE void take_raster(qs_core *c, qs_host_msg *m, const qs_raster_msg *line)
{
    qs_engine *e = &c->engine;
    qs_segment_msg *const s = &m->as.segment;
    qs_segment *slot;
    qs_segments_msg run;
    uint8_t record[3];
    qs_fault f;

    if (!may_queue(c, m))
        return;
    if (qs_queue_free(&e->queue) == 0 || !qs_raster_room(&c->raster, &e->queue, line->count)) {
        send_ack(c, m->seq, QS_ACK_QUEUE_FULL);
        return;
    }
    record[0] = (uint8_t)(QS_RECORD_AXES | QS_RECORD_CRUISE | ((line->n >> 8) & QS_RECORD_N_HIGH));
    record[1] = (uint8_t)line->n;
    record[2] = line->axes;
    run.next = record;
    if ((line->n >> 8) > QS_RECORD_N_HIGH) {
        qs_msg_bad_field(&f, QS_FIELD_N, QS_AXIS_NONE);
        refuse_segment(c, m, &f);
        return;
    }
    if (qs_segments_next(&run, &e->chain, c->axis_count, s, &f) != QS_ERR_NONE
        || qs_msg_check_segment(s, c->axis_count, &f) != QS_ERR_NONE || qs_raster_check(line, s, &f) != QS_ERR_NONE
        || beyond_positions(c, s->active, s->n, &f)) {
        refuse_segment(c, m, &f);
        return;
    }
    slot = qs_queue_back(&e->queue);
    qs_segment_prepare(slot, s);
    qs_cubic_follow_quadratic(&e->chain, slot, s);
    qs_engine_note_prepared(e, slot);
    qs_outputs_carry(&c->outputs, slot);
    qs_raster_store(&c->raster, slot, line);
    queued(c, m);
}

static uint8_t on_raster(qs_core *c, qs_host_msg *m, const uint8_t *p, uint8_t plen)
{
    qs_raster_msg line;
    const uint8_t code = qs_raster_parse(p, plen, &line);

    if (code == QS_ERR_NONE && in_sequence(c, m))
        take_raster(c, m, &line);
    return code;
}
#endif

/* A cubic segment is checked against the chain as it prepares its slot,
 * which moves the chain on: so the queue's room is asked first. */
static void on_cubic_segment(qs_core *c, const qs_host_msg *m)
{
    qs_engine *e = &c->engine;
    qs_fault f;

    if (!may_queue(c, m))
        return;
    if (qs_queue_free(&e->queue) == 0) {
        send_ack(c, m->seq, QS_ACK_QUEUE_FULL);
        return;
    }
    /* Every axis may move: one the segment does not name keeps its speed. */
    if (qs_cubic_prepare(&e->chain, qs_queue_back(&e->queue), &m->as.cubic, c->axis_count, &f) != QS_ERR_NONE
        || beyond_positions(c, (uint8_t)((1u << c->axis_count) - 1u), m->as.cubic.n, &f)) {
        refuse_segment(c, m, &f);
        return;
    }
    qs_engine_note_prepared(e, qs_queue_back(&e->queue));
    qs_outputs_carry(&c->outputs, qs_queue_back(&e->queue));
    queued(c, m);
}

static void on_set_position(qs_core *c, const qs_host_msg *m)
{
    const qs_set_position_msg *p = &m->as.set_position;
    qs_fault f;

    if (qs_msg_check_set_position(p, c->axis_count, &f) != QS_ERR_NONE) {
        reject(c, m, &f);
        return;
    }
    if (!qs_engine_set_positions(&c->engine, p->mask, p->position)) {
        fault(&f, QS_ERR_BUSY);
        reject(c, m, &f);
        return;
    }
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_ACCEPTED);
}

/* OUTPUTS: refused, like a segment, in ALARM and while holding; else the
 * setting the segments queued from now on carry, in effect at once at rest
 * (QUEUE_FULL while every setting entry is carried by a queued segment). */
static QS_NOINLINE void on_outputs(qs_core *c, const qs_host_msg *m)
{
    qs_fault f;

    if (qs_msg_check_outputs(&m->as.outputs, c->axis_count, &f) != QS_ERR_NONE) {
        reject(c, m, &f);
        return;
    }
    if (!may_queue(c, m))
        return;
    if (!qs_outputs_take(&c->outputs, &c->engine, &m->as.outputs)) {
        send_ack(c, m->seq, QS_ACK_QUEUE_FULL);
        return;
    }
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_ACCEPTED);
}

static void on_stop(qs_core *c, const qs_host_msg *m)
{
    /* An abort input still active keeps the alarm: nothing moves until it
     * is released. */
    if (qs_inputs_is_active(&c->inputs, QS_INPUT_ABORT))
        qs_engine_halt(&c->engine, QS_STATE_ALARM, QS_ALARM_E_STOP);
    else
        qs_engine_halt(&c->engine, QS_STATE_IDLE, QS_ALARM_NONE);
    c->inputs.hold_request = 0;
    c->alarm_announced = 0;
    qs_outputs_off(&c->outputs);
    c->next_seq = m->seq;
    c->parked = 0;
    send_status_report(c, m->seq, 1);
}

/* Refused: nothing changes. In ALARM nothing moves; STOP clears it. */
static void refuse_immediate(qs_core *c, const qs_host_msg *m, const qs_fault *f)
{
    count_error(c, f->code);
    send_error(c, m->seq, m->type, f);
}

static void on_hold(qs_core *c, const qs_host_msg *m)
{
    qs_fault f;

    if (qs_msg_check_hold(&m->as.hold, c->axis_count, &f) != QS_ERR_NONE) {
        refuse_immediate(c, m, &f);
        return;
    }
    if (c->engine.state == QS_STATE_ALARM) {
        fault(&f, QS_ERR_ALARM_ACTIVE);
        refuse_immediate(c, m, &f);
        return;
    }
    /* After an underrun's stop the host takes the job up again with HOLD:
     * at rest, a HOLD at IDLE (its HOLD_DONE repeats the starvation's);
     * during the stop, it ends IDLE. STARVED is left only here and by
     * STOP, never by the tick. */
    qs_engine_end_starved(&c->engine);
    /* Unless an alarm was raised meanwhile, which the answer then shows. */
    qs_engine_hold(&c->engine, m->as.hold.decel);
    c->next_seq = m->seq;
    c->parked = 0;
    /* The answer first, then a HOLD_DONE if the hold is already over. */
    send_status_report(c, m->seq, 0);
    report_pending_hold(c);
}

/* WATCHDOG: in force at once, in any state. */
static void on_watchdog(qs_core *c, const qs_host_msg *m)
{
    qs_fault f;

    if (qs_msg_check_watchdog(&m->as.watchdog, &f) != QS_ERR_NONE) {
        refuse_immediate(c, m, &f);
        return;
    }
    /* ms to clock counts, rounded up: a nonzero timeout stays nonzero. */
    c->watchdog = (uint16_t)(((uint32_t)m->as.watchdog.timeout_ms * 1000u + QS_PORT_CLOCK_US - 1u) / QS_PORT_CLOCK_US);
    c->heard = qs_port_clock();
    send_status_report(c, m->seq, 1);
}

static void send_input_status(qs_core *c, uint8_t seq)
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

/* PROBE: only at rest with nothing queued, for an input not already where
 * the motion is to end. */
static void on_probe(qs_core *c, const qs_host_msg *m)
{
    const qs_probe_msg *pr = &m->as.probe;
    qs_engine *e = &c->engine;
    qs_fault f;

    if (qs_msg_check_probe(pr, c->axis_count, c->inputs.present, &f) != QS_ERR_NONE) {
        reject(c, m, &f);
        return;
    }
    qs_engine_retire(e);
    if (e->state != QS_STATE_IDLE || !qs_queue_empty(&e->queue)) {
        fault(&f, e->state == QS_STATE_ALARM ? QS_ERR_ALARM_ACTIVE : QS_ERR_BUSY);
        reject(c, m, &f);
        return;
    }
    if (qs_inputs_is_active(&c->inputs, pr->input) == pr->level) {
        fault(&f, QS_ERR_INPUT_AT_LEVEL);
        reject(c, m, &f);
        return;
    }
    qs_engine_arm_trigger(e, pr->input, pr->level, pr->hold.decel);
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_ACCEPTED);
}

/* CONFIG: not while moving, nor while a motion is paused (STARVED). */
static void on_config(qs_core *c, const qs_host_msg *m)
{
    const qs_config_msg *cf = &m->as.config;
    qs_fault f;

    if (qs_msg_check_config(cf, c->axis_count, &f) != QS_ERR_NONE) {
        reject(c, m, &f);
        return;
    }
    if (c->engine.state == QS_STATE_RUNNING || c->engine.state == QS_STATE_HOLDING
        || c->engine.state == QS_STATE_STARVED) {
        fault(&f, QS_ERR_BUSY);
        reject(c, m, &f);
        return;
    }
    qs_inputs_configure(&c->inputs, &c->engine, cf->invert, cf->enabled, cf->hard_limits, cf->debounce, cf->hold.decel);
    c->next_seq++;
    send_ack(c, m->seq, QS_ACK_ACCEPTED);
}

/* ---- selective repeat ---- */

#define PARK_MAX 32 /* frames ahead that can wait (the bits of parked) */

_Static_assert(sizeof(qs_host_msg) <= sizeof(qs_segment), "a parked frame waits in a queue slot");

/* Bring the parked frames' bookkeeping to next_seq and the queue's head:
 * every frame consumed since must have taken a slot (else the slots they
 * wait in are not theirs any more: all go, the host sends them again). */
static void rebase_parked(qs_core *c)
{
    const uint8_t frames = (uint8_t)(c->next_seq - c->parked_seq);
    const uint8_t slots = qs_queue_distance(&c->engine.queue, c->parked_head, c->engine.queue.head);

    if (frames != slots || frames >= PARK_MAX)
        c->parked = 0;
    else
        c->parked >>= frames;
    c->parked_seq = c->next_seq;
    c->parked_head = c->engine.queue.head;
}

static qs_segment *slot_ahead(qs_queue *q, uint8_t d)
{
    uint8_t i = q->head;

    while (d--)
        i = qs_queue_next(q, i);
    return qs_queue_at(q, i);
}

/* A segment d frames ahead of next_seq: kept in the slot it will take, if
 * there is room, and while segments may run. Returns whether it was. */
static uint8_t park(qs_core *c, const qs_host_msg *m, uint8_t d)
{
    const uint8_t state = c->engine.state;
    const uint8_t *from = (const uint8_t *)m;
    uint8_t *to;
    uint8_t i;

    if ((m->type != QS_TYPE_SEGMENT && m->type != QS_TYPE_CUBIC_SEGMENT) || d >= PARK_MAX
        || (state != QS_STATE_IDLE && state != QS_STATE_RUNNING))
        return 0;
    rebase_parked(c);
    if (d >= qs_queue_free(&c->engine.queue))
        return 0;
    to = (uint8_t *)slot_ahead(&c->engine.queue, d);
    for (i = 0; i < sizeof *m; i++)
        to[i] = from[i];
    c->parked |= (uint32_t)1 << d;
    return 1;
}

/* The frames parked behind the one just taken, now in order. One message
 * buffer, outside the frame's own call, keeps the stack as it was. */
static QS_NOINLINE void run_parked(qs_core *c)
{
    qs_host_msg m;

    for (;;) {
        const uint8_t *from;
        uint8_t *to = (uint8_t *)&m;
        uint8_t i;

        rebase_parked(c);
        if (!(c->parked & 1u))
            return;
        c->parked &= ~(uint32_t)1;
        from = (const uint8_t *)qs_queue_back(&c->engine.queue);
        for (i = 0; i < sizeof m; i++)
            to[i] = from[i];
        if (m.type == QS_TYPE_SEGMENT)
            on_segment(c, &m);
        else
            on_cubic_segment(c, &m);
    }
}

/* Whether a sequenced frame is the one expected next. A later frame means
 * some were lost: a segment is parked to run after them if it can be, else
 * dropped; an earlier one is a resend of a frame already consumed. The
 * answer says which. */
static uint8_t in_sequence(qs_core *c, const qs_host_msg *m)
{
    uint8_t delta = (uint8_t)(m->seq - c->next_seq);

    if (delta == 0)
        return 1;
    if (delta <= 127) {
        count(&c->counters.seq_gap);
        send_ack(c, m->seq, park(c, m, delta) ? QS_ACK_PARKED : QS_ACK_GAP);
    } else {
        count(&c->counters.seq_dup);
        send_ack(c, m->seq, QS_ACK_DUPLICATE);
    }
    return 0;
}

/* A hold the firmware began itself (a trigger, the feed hold button) ends
 * the stream: frames the host sent before it learns of it must not run once
 * the hold is over. Moving next_seq on by half the sequence space makes
 * every one of them a duplicate (PROTOCOL.md 5.4); the host adopts next_seq
 * from a status at rest. */
static void end_stream(qs_core *c)
{
    c->engine.resequence = 0;
    c->parked = 0;
    c->next_seq = (uint8_t)(c->next_seq + 128);
}

/* Every host message, by type (PROTOCOL.md section 5): its parser, then
 * what it does. A new message is one case here. */
static QS_NOINLINE void on_frame(qs_core *c, const uint8_t *body, uint8_t len)
{
    const uint8_t *p = body + 2;
    uint8_t plen = (uint8_t)(len - 2);
    qs_host_msg m;
    qs_fault f;
    uint8_t code;

    m.type = body[0];
    m.seq = body[1];
    if (c->engine.resequence)
        end_stream(c);
    report_pending_hold(c);
    switch (m.type) {
    case QS_TYPE_IDENTIFY:
        code = qs_msg_parse_empty(plen);
        if (code == QS_ERR_NONE)
            send_identify_reply(c, m.seq);
        break;
    case QS_TYPE_STATUS:
        code = qs_msg_parse_empty(plen);
        if (code == QS_ERR_NONE)
            send_status_report(c, m.seq, 1);
        break;
    case QS_TYPE_STOP:
        code = qs_msg_parse_empty(plen);
        if (code == QS_ERR_NONE)
            on_stop(c, &m);
        break;
    case QS_TYPE_HOLD:
        code = qs_msg_parse_hold(p, plen, &m.as.hold);
        if (code == QS_ERR_NONE)
            on_hold(c, &m);
        break;
    case QS_TYPE_WATCHDOG:
        code = qs_msg_parse_watchdog(p, plen, &m.as.watchdog);
        if (code == QS_ERR_NONE)
            on_watchdog(c, &m);
        break;
    case QS_TYPE_INPUTS:
        code = qs_msg_parse_empty(plen);
        if (code == QS_ERR_NONE)
            send_input_status(c, m.seq);
        break;
    case QS_TYPE_PROBE:
        code = qs_msg_parse_probe(p, plen, &m.as.probe);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_probe(c, &m);
        break;
    case QS_TYPE_CONFIG:
        code = qs_msg_parse_config(p, plen, &m.as.config);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_config(c, &m);
        break;
    case QS_TYPE_OUTPUTS:
        code = qs_msg_parse_outputs(p, plen, &m.as.outputs);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_outputs(c, &m);
        break;
    case QS_TYPE_SEGMENT:
        code = qs_msg_parse_segment(p, plen, &m.as.segment);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_segment(c, &m);
        break;
    case QS_TYPE_CUBIC_SEGMENT:
        code = qs_msg_parse_cubic(p, plen, &m.as.cubic);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_cubic_segment(c, &m);
        break;
    case QS_TYPE_SEGMENTS:
        code = qs_msg_parse_segments(p, plen, &m.as.segments);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_segments(c, &m, 0);
        break;
    case QS_TYPE_CUBIC_SEGMENTS:
        code = qs_msg_parse_cubic_segments(p, plen, &m.as.segments);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_segments(c, &m, 1);
        break;
#if QS_RASTER_BYTES
    case QS_TYPE_RASTER:
        code = on_raster(c, &m, p, plen);
        break;
#endif
    case QS_TYPE_SET_POSITION:
        code = qs_msg_parse_set_position(p, plen, &m.as.set_position);
        if (code == QS_ERR_NONE && in_sequence(c, &m))
            on_set_position(c, &m);
        break;
    default:
        code = QS_ERR_UNKNOWN_TYPE;
        break;
    }
    if (code != QS_ERR_NONE) {
        count_error(c, code);
        fault(&f, code);
        send_error(c, m.seq, m.type, &f);
    }
}

/* ---- public ---- */

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
        on_frame(c, qs_frame_body(&c->rx), qs_frame_body_len(&c->rx));
        if (c->parked)
            run_parked(c);
        return;
    }
    /* Nothing in a frame that failed these checks can be trusted. */
    count_error(c, result);
    fault(&f, result);
    send_error(c, QS_SEQ_UNSOLICITED, QS_SEQ_UNSOLICITED, &f);
}

void qs_core_rx_overrun(qs_core *c)
{
    qs_frame_rx_overrun(&c->rx);
}

/* The armed motion came to rest without its edge. Out of line: its
 * snapshot stays off the main loop's deepest paths. */
static QS_NOINLINE void report_probe_missed(qs_core *c)
{
    qs_engine_view v;

    qs_engine_disarm_trigger(&c->engine);
    qs_engine_read(&c->engine, &v);
    send_body(c, qs_msg_encode_probe_missed(tx_body(c), QS_SEQ_UNSOLICITED, v.motion_ticks, c->axis_count,
                                            v.position));
}

/* The host went silent while moving: a hold at stop_decel, ending in ALARM
 * HOST_LOST (at once if nothing moves). Out of line: rare. */
static QS_NOINLINE void stop_for_silence(qs_core *c)
{
    qs_engine *e = &c->engine;
    const uint8_t outcome = qs_engine_hold(e, e->stop_decel);

    if (outcome == QS_HOLD_STARTED || (outcome == QS_HOLD_UNDER_WAY && !e->hold_alarm))
        e->hold_alarm = QS_ALARM_HOST_LOST;
    else if (outcome == QS_HOLD_AT_REST)
        qs_engine_halt(e, QS_STATE_ALARM, QS_ALARM_HOST_LOST);
}

/* What the inputs left for the main loop: a hold to begin, an armed
 * motion that ended without its edge. */
static void serve_inputs(qs_core *c)
{
    qs_engine *e = &c->engine;
    const uint8_t request = c->inputs.hold_request;

    if (e->resequence)
        end_stream(c);
    if (qs_core_host_silent(c))
        stop_for_silence(c);
    if (request) {
        c->inputs.hold_request = 0;
        qs_engine_hold(e, request == QS_INPUTS_HOLD_FEED ? e->stop_decel : e->trigger_decel);
        end_stream(c);
    }
    if (e->trigger && e->state == QS_STATE_IDLE && qs_queue_empty(&e->queue)
        && (uint16_t)e->segments_done != e->trigger_since && !qs_inputs_settling(&c->inputs))
        report_probe_missed(c);
}

QS_NOINLINE void qs_core_poll_work(qs_core *c)
{
    qs_engine_finish_freeze(&c->engine);
    qs_engine_retire(&c->engine);
    report_pending_inputs(c);
    /* One SPACE ack covers every segment finished since the last one. */
    if ((uint16_t)c->engine.segments_done != c->space_announced) {
        c->space_announced = (uint16_t)c->engine.segments_done;
        send_ack(c, QS_SEQ_UNSOLICITED, QS_ACK_SPACE);
    }
    /* A hold that ends in an alarm (a silent host) is reported first:
     * HOLD_DONE says when it began and where it rests. */
    report_pending_hold(c);
    if (c->engine.alarm != QS_ALARM_NONE && !c->alarm_announced)
        send_alarm(c);
    serve_inputs(c);
    report_pending_hold(c);
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
