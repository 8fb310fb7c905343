#include "qs_dispatch.h"
#include "qs_cubic_records.h"
#include "qs_reports.h"
#include "qs_retransmit.h"
#include "qs_segments.h"
#include "qs_watchdog.h"

/* Consume a sequenced frame that cannot be executed. */
static void reject(qs_core *c, const qs_host_msg *m, const qs_fault *f)
{
    qs_count_error(c, f->code);
    qs_report_error(c, m->seq, m->type, f);
    c->next_seq++;
    qs_report_ack(c, m->seq, QS_ACK_REJECTED);
}

/* Whether a segment may be taken in this state; refused (consumed) if not. */
static uint8_t may_queue(qs_core *c, const qs_host_msg *m)
{
    qs_fault f;

    if (c->engine.state == QS_STATE_ALARM) {
        qs_fault_code(&f, QS_ERR_ALARM_ACTIVE);
        reject(c, m, &f);
        return 0;
    }
    if (c->engine.state == QS_STATE_HOLDING || c->engine.state == QS_STATE_STARVED || c->engine.trigger_window) {
        /* The host learns of the hold's end from HOLD_DONE: a segment sent
         * before that was planned for motion the hold discarded, and must
         * not start from rest. After an underrun's stop (STARVED) a HOLD
         * takes the board to IDLE first. */
        qs_fault_code(&f, QS_ERR_BUSY);
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
    qs_report_alarm(c);
}

static void queued(qs_core *c, const qs_host_msg *m)
{
    qs_queue_publish(&c->engine.queue);
    qs_engine_wake(&c->engine);
    c->next_seq++;
    qs_report_ack(c, m->seq, QS_ACK_ACCEPTED);
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

void qs_on_segment(qs_core *c, const qs_host_msg *m)
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
        qs_report_ack(c, m->seq, QS_ACK_QUEUE_FULL);
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
        qs_report_ack(c, m->seq, QS_ACK_QUEUE_FULL);
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
#if QS_QUADRATIC_RUNS
            qs_segment_msg *const s = &m->as.segment;

            refused = qs_segments_next(&run, &e->chain, c->axis_count, s, &f) != QS_ERR_NONE
                      || qs_msg_check_segment(s, c->axis_count, &f) != QS_ERR_NONE
                      || beyond_positions(c, s->active, s->n, &f);
            if (!refused) {
                qs_segment_prepare(slot, s);
                qs_cubic_follow_quadratic(&e->chain, slot, s);
            }
#else
            return; /* never: without quadratic runs no SEGMENTS frame is dispatched */
#endif
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
    qs_report_ack(c, m->seq, QS_ACK_ACCEPTED);
}

#if QS_RASTER_BYTES
/* RASTER: its motion is the chain's cruise, read as a SEGMENTS record that
 * says nothing but n and the axes; then the line's own checks, and its
 * powers into the ring beside the slot. */
static QS_NOINLINE void on_raster(qs_core *c, qs_host_msg *m)
{
    const qs_raster_msg kept = m->as.raster; /* m's room is the record's below */
    const qs_raster_msg *const line = &kept;
    qs_engine *e = &c->engine;
    qs_segment_msg *const s = &m->as.segment;
    qs_segment *slot;
    qs_segments_msg run;
    uint8_t record[3];
    qs_fault f;

    if (!may_queue(c, m))
        return;
    if (qs_queue_free(&e->queue) == 0 || !qs_raster_room(&c->raster, &e->queue, line->count)) {
        qs_report_ack(c, m->seq, QS_ACK_QUEUE_FULL);
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
#endif

/* A cubic segment is checked against the chain as it prepares its slot,
 * which moves the chain on: so the queue's room is asked first. */
void qs_on_cubic_segment(qs_core *c, const qs_host_msg *m)
{
    qs_engine *e = &c->engine;
    qs_fault f;

    if (!may_queue(c, m))
        return;
    if (qs_queue_free(&e->queue) == 0) {
        qs_report_ack(c, m->seq, QS_ACK_QUEUE_FULL);
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
        qs_fault_code(&f, QS_ERR_BUSY);
        reject(c, m, &f);
        return;
    }
    c->next_seq++;
    qs_report_ack(c, m->seq, QS_ACK_ACCEPTED);
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
        qs_report_ack(c, m->seq, QS_ACK_QUEUE_FULL);
        return;
    }
    c->next_seq++;
    qs_report_ack(c, m->seq, QS_ACK_ACCEPTED);
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
    qs_report_status(c, m->seq, 1);
}

/* Refused: nothing changes. In ALARM nothing moves; STOP clears it. */
static void refuse_immediate(qs_core *c, const qs_host_msg *m, const qs_fault *f)
{
    qs_count_error(c, f->code);
    qs_report_error(c, m->seq, m->type, f);
}

/* HOLD, and HOLD_ALONG (its path's decelerations checked as HOLD's). */
static void on_hold(qs_core *c, const qs_host_msg *m)
{
    const qs_path_hold *path = m->type == QS_TYPE_HOLD_ALONG ? &m->as.hold_along.path : 0;
    qs_fault f;

    if (qs_msg_check_hold(&m->as.hold, c->axis_count, &f) != QS_ERR_NONE
        || (path && qs_msg_check_hold(&path->hold, c->axis_count, &f) != QS_ERR_NONE)) {
        refuse_immediate(c, m, &f);
        return;
    }
    if (c->engine.state == QS_STATE_ALARM) {
        qs_fault_code(&f, QS_ERR_ALARM_ACTIVE);
        refuse_immediate(c, m, &f);
        return;
    }
    /* After an underrun's stop the host takes the job up again with HOLD:
     * at rest, a HOLD at IDLE (its HOLD_DONE repeats the starvation's);
     * during the stop, it ends IDLE. STARVED is left only here and by
     * STOP, never by the tick. */
    qs_engine_end_starved(&c->engine);
    /* Unless an alarm was raised meanwhile, which the answer then shows. */
    qs_engine_hold(&c->engine, m->as.hold.decel, path);
    c->next_seq = m->seq;
    c->parked = 0;
    /* The answer first, then a HOLD_DONE if the hold is already over. */
    qs_report_status(c, m->seq, 0);
    qs_report_pending_hold(c);
}

/* WATCHDOG: in force at once, in any state. */
static void on_watchdog(qs_core *c, const qs_host_msg *m)
{
    qs_fault f;

    if (qs_msg_check_watchdog(&m->as.watchdog, &f) != QS_ERR_NONE) {
        refuse_immediate(c, m, &f);
        return;
    }
    qs_watchdog_start(c, m->as.watchdog.timeout_ms);
    qs_report_status(c, m->seq, 1);
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
        qs_fault_code(&f, e->state == QS_STATE_ALARM ? QS_ERR_ALARM_ACTIVE : QS_ERR_BUSY);
        reject(c, m, &f);
        return;
    }
    if (qs_inputs_is_active(&c->inputs, pr->input) == pr->level) {
        qs_fault_code(&f, QS_ERR_INPUT_AT_LEVEL);
        reject(c, m, &f);
        return;
    }
    qs_engine_arm_trigger(e, pr->input, pr->level, pr->hold.decel);
    c->next_seq++;
    qs_report_ack(c, m->seq, QS_ACK_ACCEPTED);
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
        qs_fault_code(&f, QS_ERR_BUSY);
        reject(c, m, &f);
        return;
    }
    qs_inputs_configure(&c->inputs, &c->engine, cf->invert, cf->enabled, cf->hard_limits, cf->debounce, cf->hold.decel);
    c->next_seq++;
    qs_report_ack(c, m->seq, QS_ACK_ACCEPTED);
}

/* ---- the messages ----
 * Every host message (PROTOCOL.md section 5) is one row of HOST_MESSAGES
 * below: its type, whether it is sequenced, its parser and its handler. A
 * new message is a parser, a handler and a row. */

/* The parsers in one form: the payload into the message's own member.
 * These forms and the handlers' are inlined, so that the switch compiles
 * as a written-out one would. */
static QS_ALWAYS_INLINE uint8_t parse_empty(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    (void)p;
    (void)m;
    return qs_msg_parse_empty(len);
}

/* HOLD and HOLD_ALONG, which begins with a HOLD's payload. */
static QS_ALWAYS_INLINE uint8_t parse_hold(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return m->type == QS_TYPE_HOLD ? qs_msg_parse_hold(p, len, &m->as.hold)
                                   : qs_msg_parse_hold_along(p, len, &m->as.hold_along);
}

static QS_ALWAYS_INLINE uint8_t parse_watchdog(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_watchdog(p, len, &m->as.watchdog);
}

static QS_ALWAYS_INLINE uint8_t parse_probe(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_probe(p, len, &m->as.probe);
}

static QS_ALWAYS_INLINE uint8_t parse_config(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_config(p, len, &m->as.config);
}

static QS_ALWAYS_INLINE uint8_t parse_outputs(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_outputs(p, len, &m->as.outputs);
}

static QS_ALWAYS_INLINE uint8_t parse_segment(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_segment(p, len, &m->as.segment);
}

static QS_ALWAYS_INLINE uint8_t parse_cubic_segment(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_cubic(p, len, &m->as.cubic);
}

static QS_ALWAYS_INLINE uint8_t parse_segments(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_segments(p, len, &m->as.segments);
}

static QS_ALWAYS_INLINE uint8_t parse_cubic_segments(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_cubic_segments(p, len, &m->as.segments);
}

static QS_ALWAYS_INLINE uint8_t parse_set_position(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_msg_parse_set_position(p, len, &m->as.set_position);
}

#if QS_RASTER_BYTES
static QS_ALWAYS_INLINE uint8_t parse_raster(const uint8_t *p, uint8_t len, qs_host_msg *m)
{
    return qs_raster_parse(p, len, &m->as.raster);
}
#endif

/* The handlers that only answer, and the two kinds of SEGMENTS. */
static QS_ALWAYS_INLINE void on_identify(qs_core *c, const qs_host_msg *m)
{
    qs_report_identify(c, m->seq);
}

static QS_ALWAYS_INLINE void on_status(qs_core *c, const qs_host_msg *m)
{
    qs_report_status(c, m->seq, 1);
}

static QS_ALWAYS_INLINE void on_inputs(qs_core *c, const qs_host_msg *m)
{
    qs_report_input_status(c, m->seq);
}

static QS_ALWAYS_INLINE void on_quadratic_segments(qs_core *c, qs_host_msg *m)
{
    on_segments(c, m, 0);
}

static QS_ALWAYS_INLINE void on_cubic_segments(qs_core *c, qs_host_msg *m)
{
    on_segments(c, m, 1);
}

/* Type, sequenced (taken only as the seq expected next, qs_in_sequence),
 * parser, handler. The rows expand into the switch of qs_dispatch_frame,
 * so every call is direct: the AVR build then keeps the core's address a
 * constant in each handler, which a table of function pointers would lose
 * (1.6 KB more flash on the Uno). */
#if QS_RASTER_BYTES
#define RASTER_ROW(X) X(QS_TYPE_RASTER, 1, parse_raster, on_raster)
#else
#define RASTER_ROW(X)
#endif
#if QS_QUADRATIC_RUNS
#define SEGMENTS_ROW(X) X(QS_TYPE_SEGMENTS, 1, parse_segments, on_quadratic_segments)
#else
#define SEGMENTS_ROW(X)
#endif
#if QS_CUBIC
#define CUBIC_ROWS(X)                                                     \
    X(QS_TYPE_CUBIC_SEGMENT, 1, parse_cubic_segment, qs_on_cubic_segment) \
    X(QS_TYPE_CUBIC_SEGMENTS, 1, parse_cubic_segments, on_cubic_segments)
#else
#define CUBIC_ROWS(X)
#endif
/* One case for both: HOLD_ALONG is a HOLD with more to it. */
#define HOLD_TYPES QS_TYPE_HOLD: case QS_TYPE_HOLD_ALONG
#define HOST_MESSAGES(X)                                                  \
    X(QS_TYPE_IDENTIFY, 0, parse_empty, on_identify)                      \
    X(QS_TYPE_STATUS, 0, parse_empty, on_status)                          \
    X(QS_TYPE_STOP, 0, parse_empty, on_stop)                              \
    X(HOLD_TYPES, 0, parse_hold, on_hold)                                 \
    X(QS_TYPE_WATCHDOG, 0, parse_watchdog, on_watchdog)                   \
    X(QS_TYPE_INPUTS, 0, parse_empty, on_inputs)                          \
    X(QS_TYPE_PROBE, 1, parse_probe, on_probe)                            \
    X(QS_TYPE_CONFIG, 1, parse_config, on_config)                         \
    X(QS_TYPE_OUTPUTS, 1, parse_outputs, on_outputs)                      \
    X(QS_TYPE_SEGMENT, 1, parse_segment, qs_on_segment)                   \
    CUBIC_ROWS(X)                                                         \
    SEGMENTS_ROW(X)                                                       \
    RASTER_ROW(X)                                                         \
    X(QS_TYPE_SET_POSITION, 1, parse_set_position, on_set_position)

#define DISPATCH_CASE(type, sequenced, parse, handle)                    \
    case type:                                                           \
        code = parse(p, plen, &m);                                       \
        if (code == QS_ERR_NONE && (!(sequenced) || qs_in_sequence(c, &m))) \
            handle(c, &m);                                               \
        break;

QS_NOINLINE void qs_dispatch_frame(qs_core *c, const uint8_t *body, uint8_t len)
{
    const uint8_t *p = body + 2;
    uint8_t plen = (uint8_t)(len - 2);
    qs_host_msg m;
    qs_fault f;
    uint8_t code;

    m.type = body[0];
    m.seq = body[1];
    if (c->engine.resequence)
        qs_end_stream(c);
    qs_report_pending_hold(c);
    switch (m.type) {
        HOST_MESSAGES(DISPATCH_CASE)
    default:
        code = QS_ERR_UNKNOWN_TYPE;
        break;
    }
    if (code != QS_ERR_NONE) {
        qs_count_error(c, code);
        qs_fault_code(&f, code);
        qs_report_error(c, m.seq, m.type, &f);
    }
}
