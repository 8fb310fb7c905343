/* Every vector of protocol/vectors.json (PROTOCOL.md section 9), through
 * the firmware's own code: frames the host sends must decode to the listed
 * message or fail with the listed error, both alone and through a whole
 * core; reports must encode to exactly the listed bytes. The vectors come
 * from a header generated at build time (gen_vectors.py). */
#include <stdio.h>
#include <string.h>

#include "qs_core.h"
#include "qs_frame.h"
#include "qs_messages.h"
#include "qs_cubic_records.h"
#include "qs_raster.h"
#include "qs_segments.h"
#include "qs_test_support.h"
#include "qs_vectors.h"
#include "unity.h"

static qs_core core;
static char where[160];
/* A SEGMENTS or CUBIC_SEGMENTS frame's records as segments, read while its
 * frame is at hand. */
static qs_segment_msg expanded[QS_SEGMENTS_MAX];
static qs_cubic_msg cubic_expanded[QS_SEGMENTS_MAX];
static uint8_t expanded_count;
/* A RASTER frame's fields, read while its frame is at hand. */
static qs_raster_msg raster_line;

void setUp(void)
{
    tp_clear_sent();
}

void tearDown(void)
{
}

static const char *at(const qs_vector *v, const char *what)
{
    snprintf(where, sizeof where, "vector '%s': %s", v->name, what);
    return where;
}

static uint8_t is_framing(uint8_t code)
{
    return code == QS_ERR_FRAME_TOO_LONG || code == QS_ERR_FRAME_TOO_SHORT
           || code == QS_ERR_BAD_COBS || code == QS_ERR_BAD_CRC || code == QS_ERR_RX_OVERRUN;
}

/* Feed the wire bytes; returns the last result and checks nothing happened
 * before the final delimiter except what a delimiter may end. */
static uint8_t feed(const qs_vector *v, qs_frame_rx *rx)
{
    uint8_t result = QS_FRAME_NOTHING;
    uint16_t i;

    qs_frame_rx_init(rx);
    for (i = 0; i < v->frame_len; i++) {
        result = qs_frame_rx_byte(rx, v->frame[i]);
        if (i + 1 < v->frame_len)
            TEST_ASSERT_EQUAL_INT_MESSAGE(QS_FRAME_NOTHING, result, at(v, "frame ended early"));
    }
    return result;
}

/* The parser of each host message type, as the core's dispatch uses them. */
static uint8_t parse(const uint8_t *body, uint8_t len, qs_host_msg *m)
{
    const uint8_t *p = body + 2;
    uint8_t plen = (uint8_t)(len - 2);

    m->type = body[0];
    m->seq = body[1];
    switch (m->type) {
    case QS_TYPE_IDENTIFY:
    case QS_TYPE_STATUS:
    case QS_TYPE_STOP:
    case QS_TYPE_INPUTS:
        return qs_msg_parse_empty(plen);
    case QS_TYPE_HOLD:
        return qs_msg_parse_hold(p, plen, &m->as.hold);
    case QS_TYPE_HOLD_ALONG:
        return qs_msg_parse_hold_along(p, plen, &m->as.hold_along);
    case QS_TYPE_WATCHDOG:
        return qs_msg_parse_watchdog(p, plen, &m->as.watchdog);
    case QS_TYPE_PROBE:
        return qs_msg_parse_probe(p, plen, &m->as.probe);
    case QS_TYPE_CONFIG:
        return qs_msg_parse_config(p, plen, &m->as.config);
    case QS_TYPE_OUTPUTS:
        return qs_msg_parse_outputs(p, plen, &m->as.outputs);
    case QS_TYPE_SEGMENT:
        return qs_msg_parse_segment(p, plen, &m->as.segment);
    case QS_TYPE_SET_POSITION:
        return qs_msg_parse_set_position(p, plen, &m->as.set_position);
    case QS_TYPE_CUBIC_SEGMENT:
        return qs_msg_parse_cubic(p, plen, &m->as.cubic);
    case QS_TYPE_SEGMENTS:
        return qs_msg_parse_segments(p, plen, &m->as.segments);
    case QS_TYPE_CUBIC_SEGMENTS:
        return qs_msg_parse_cubic_segments(p, plen, &m->as.segments);
    case QS_TYPE_RASTER:
        return qs_raster_parse(p, plen, &raster_line);
    default:
        return QS_ERR_UNKNOWN_TYPE;
    }
}

/* Every record of a SEGMENTS frame, against the chain of a freshly started
 * firmware that follows each, and checked as a SEGMENT. */
static uint8_t expand_segments(qs_segments_msg *run, uint8_t axis_count, qs_fault *f)
{
    static qs_cubic_chain chain;
    static qs_segment slots[QS_SEGMENTS_MAX];
    qs_segment_msg s;
    uint8_t code;

    qs_cubic_reset(&chain);
    for (expanded_count = 0; expanded_count < run->count; expanded_count++) {
        code = qs_segments_next(run, &chain, axis_count, &s, f);
        if (code == QS_ERR_NONE)
            code = qs_msg_check_segment(&s, axis_count, f);
        if (code != QS_ERR_NONE)
            return code;
        qs_segment_prepare(&slots[expanded_count], &s);
        qs_cubic_follow_quadratic(&chain, &slots[expanded_count], &s);
        expanded[expanded_count] = s;
    }
    return QS_ERR_NONE;
}

/* Every record of a CUBIC_SEGMENTS frame, against the chain of a freshly
 * started firmware that each moves on, and checked as a CUBIC_SEGMENT. */
static uint8_t expand_cubic_segments(qs_segments_msg *run, uint8_t axis_count, qs_fault *f)
{
    static qs_cubic_chain chain;
    static qs_segment slot;
    uint8_t code;

    qs_cubic_reset(&chain);
    for (expanded_count = 0; expanded_count < run->count; expanded_count++) {
        qs_cubic_msg *s = &cubic_expanded[expanded_count];

        code = qs_cubic_records_next(run, &chain, axis_count, s, f);
        if (code == QS_ERR_NONE)
            code = qs_cubic_prepare(&chain, &slot, s, axis_count, f);
        if (code != QS_ERR_NONE)
            return code;
    }
    return QS_ERR_NONE;
}

/* A fresh core, moving after the vector's SEGMENT (sent with the seq
 * before seq) if it has one, expecting seq next; reports cleared. */
static void fresh_core(const qs_vector *v, uint8_t seq)
{
    tp_axis axes[QS_PROTOCOL_AXES];
    uint8_t axis, j = 0;

    qs_core_init(&core);
    qs_core_configure(&core, v->axis_count, QS_QUEUE_CAPACITY, QS_TICK_HZ);
    core.next_seq = seq;
    if (v->has_after) {
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
            if (v->after.active & (1u << axis)) {
                axes[j].v0 = v->after.v0[axis];
                axes[j].vn = v->after.vn[axis];
                axes[j].r = v->after.r[axis];
                j++;
            }
        core.next_seq = (uint8_t)(seq - 1u);
        tp_send_segment(&core, (uint8_t)(seq - 1u), v->after.n, v->after.active, v->after.negative, axes);
    }
    tp_clear_sent();
}

/* A RASTER's content is read against the chain the segment before left:
 * what a core with that segment queued answers. */
static uint8_t raster_content(const qs_vector *v, uint8_t seq, qs_fault *f)
{
    tp_report r[4];
    qs_error_report e;
    uint16_t i;

    fresh_core(v, seq);
    for (i = 0; i < v->frame_len; i++)
        qs_core_rx(&core, v->frame[i]);
    if (tp_reports(r, 4) == 0 || r[0].type != QS_TYPE_ERROR)
        return QS_ERR_NONE;
    e = tp_error(&r[0]);
    f->field = e.field;
    f->axis = e.axis;
    return e.code;
}

/* What decoding a host frame gives: 0 and the message, or an error. */
static uint8_t decode(const qs_vector *v, qs_host_msg *m, qs_fault *f)
{
    qs_frame_rx rx;
    uint8_t result = feed(v, &rx);

    f->field = QS_FIELD_NONE;
    f->axis = QS_AXIS_NONE;
    if (result != QS_FRAME_READY)
        return result;
    result = parse(qs_frame_body(&rx), qs_frame_body_len(&rx), m);
    if (result != QS_ERR_NONE)
        return result;
    if (m->type == QS_TYPE_SEGMENTS)
        return expand_segments(&m->as.segments, v->axis_count, f);
    if (m->type == QS_TYPE_CUBIC_SEGMENTS)
        return expand_cubic_segments(&m->as.segments, v->axis_count, f);
    if (m->type == QS_TYPE_SEGMENT)
        return qs_msg_check_segment(&m->as.segment, v->axis_count, f);
    if (m->type == QS_TYPE_SET_POSITION)
        return qs_msg_check_set_position(&m->as.set_position, v->axis_count, f);
    if (m->type == QS_TYPE_CUBIC_SEGMENT) {
        /* against the chain of a freshly started firmware */
        static qs_cubic_chain chain;
        static qs_segment slot;
        qs_cubic_reset(&chain);
        return qs_cubic_prepare(&chain, &slot, &m->as.cubic, v->axis_count, f);
    }
    if (m->type == QS_TYPE_HOLD_ALONG && qs_msg_check_hold(&m->as.hold_along.hold, v->axis_count, f) != QS_ERR_NONE)
        return f->code;
    if (m->type == QS_TYPE_HOLD_ALONG)
        return qs_msg_check_hold(&m->as.hold_along.path.hold, v->axis_count, f);
    if (m->type == QS_TYPE_HOLD)
        return qs_msg_check_hold(&m->as.hold, v->axis_count, f);
    if (m->type == QS_TYPE_PROBE)
        return qs_msg_check_probe(&m->as.probe, v->axis_count, QS_INPUTS_ALL, f);
    if (m->type == QS_TYPE_CONFIG)
        return qs_msg_check_config(&m->as.config, v->axis_count, f);
    if (m->type == QS_TYPE_WATCHDOG)
        return qs_msg_check_watchdog(&m->as.watchdog, f);
    if (m->type == QS_TYPE_OUTPUTS)
        return qs_msg_check_outputs(&m->as.outputs, v->axis_count, f);
    if (m->type == QS_TYPE_RASTER)
        return raster_content(v, m->seq, f);
    return QS_ERR_NONE;
}

static void check_cubic(const qs_vector *v, const qs_cubic_msg *e, const qs_cubic_msg *a)
{
    uint8_t axis;

    TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->n, a->n, at(v, "n"));
    TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->jerk, a->jerk, at(v, "jerk axes"));
    TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->set, a->set, at(v, "set axes"));
    TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->negative, a->negative, at(v, "directions"));
    for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(e->speed[axis], a->speed[axis], at(v, "speed"));
        TEST_ASSERT_EQUAL_INT_MESSAGE(e->accel[axis], a->accel[axis], at(v, "accel"));
        TEST_ASSERT_EQUAL_INT_MESSAGE(e->r[axis], a->r[axis], at(v, "jerk"));
    }
}

static void check_host_message(const qs_vector *v, const qs_host_msg *m)
{
    uint8_t axis;

    TEST_ASSERT_EQUAL_HEX8_MESSAGE(v->type, m->type, at(v, "type"));
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->seq, m->seq, at(v, "seq"));
    if (m->type == QS_TYPE_SEGMENTS) {
        uint8_t k;
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->expands_count, expanded_count, at(v, "records"));
        for (k = 0; k < expanded_count; k++) {
            const qs_segment_msg *e = &v->expands[k], *a = &expanded[k];
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->n, a->n, at(v, "record n"));
            TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->active, a->active, at(v, "record axes"));
            TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->negative, a->negative, at(v, "record directions"));
            for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
                TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->v0[axis], a->v0[axis], at(v, "record v0"));
                TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->vn[axis], a->vn[axis], at(v, "record vn"));
                TEST_ASSERT_EQUAL_INT_MESSAGE(e->r[axis], a->r[axis], at(v, "record r"));
            }
        }
    } else if (m->type == QS_TYPE_SEGMENT) {
        const qs_segment_msg *e = &v->host.segment, *a = &m->as.segment;
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->n, a->n, at(v, "n"));
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->active, a->active, at(v, "active axes"));
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->negative, a->negative, at(v, "directions"));
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->v0[axis], a->v0[axis], at(v, "v0"));
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->vn[axis], a->vn[axis], at(v, "vn"));
            TEST_ASSERT_EQUAL_INT_MESSAGE(e->r[axis], a->r[axis], at(v, "r"));
        }
    } else if (m->type == QS_TYPE_CUBIC_SEGMENTS) {
        uint8_t k;
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->expands_count, expanded_count, at(v, "records"));
        for (k = 0; k < expanded_count; k++)
            check_cubic(v, &v->cubic_expands[k], &cubic_expanded[k]);
    } else if (m->type == QS_TYPE_CUBIC_SEGMENT) {
        check_cubic(v, &v->host.cubic, &m->as.cubic);
    } else if (m->type == QS_TYPE_SET_POSITION) {
        const qs_set_position_msg *e = &v->host.set_position, *a = &m->as.set_position;
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->mask, a->mask, at(v, "mask"));
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
            TEST_ASSERT_EQUAL_INT_MESSAGE(e->position[axis], a->position[axis], at(v, "position"));
    } else if (m->type == QS_TYPE_HOLD || m->type == QS_TYPE_HOLD_ALONG) {
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(v->host.hold.decel[axis], m->as.hold.decel[axis], at(v, "decel"));
        if (m->type == QS_TYPE_HOLD_ALONG) {
            const qs_path_hold *e = &v->host.hold_along.path, *a = &m->as.hold_along.path;
            for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
                TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->hold.decel[axis], a->hold.decel[axis], at(v, "path decel"));
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->first, a->first, at(v, "first"));
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->last, a->last, at(v, "last"));
        }
    } else if (m->type == QS_TYPE_PROBE) {
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->host.probe.input, m->as.probe.input, at(v, "input"));
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->host.probe.level, m->as.probe.level, at(v, "level"));
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(v->host.probe.hold.decel[axis], m->as.probe.hold.decel[axis],
                                             at(v, "decel"));
    } else if (m->type == QS_TYPE_WATCHDOG) {
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(v->host.watchdog.timeout_ms, m->as.watchdog.timeout_ms, at(v, "timeout_ms"));
    } else if (m->type == QS_TYPE_CONFIG) {
        const qs_config_msg *e = &v->host.config, *a = &m->as.config;
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->invert, a->invert, at(v, "invert"));
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->enabled, a->enabled, at(v, "enabled"));
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(e->hard_limits, a->hard_limits, at(v, "hard_limits"));
        TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(e->debounce, a->debounce, QS_WIRE_INPUTS, at(v, "debounce"));
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++)
            TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->hold.decel[axis], a->hold.decel[axis], at(v, "hold_decel"));
    } else if (m->type == QS_TYPE_RASTER) {
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(v->raster.n, raster_line.n, at(v, "n"));
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(v->raster.axes, raster_line.axes, at(v, "axes"));
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(v->raster.pixel, raster_line.pixel, at(v, "pixel"));
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(v->raster.phase, raster_line.phase, at(v, "phase"));
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(v->raster.pitch, raster_line.pitch, at(v, "pitch"));
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->raster.count, raster_line.count, at(v, "pixels"));
        TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(v->raster.power, raster_line.power, v->raster.count, at(v, "powers"));
    } else if (m->type == QS_TYPE_OUTPUTS) {
        const qs_outputs_msg *e = &v->host.outputs, *a = &m->as.outputs;
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(e->outputs, a->outputs, at(v, "outputs"));
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->power, a->power, at(v, "power"));
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(e->axis, a->axis, at(v, "axis"));
        TEST_ASSERT_EQUAL_UINT16_MESSAGE(e->speed, a->speed, at(v, "speed"));
    }
}

/* The firmware's answer to a valid host frame, through a fresh core that
 * expects its seq. A HOLD finds it idle: the answer, then HOLD_DONE. */
static void check_core_accepts(const qs_vector *v)
{
    tp_report r[4];
    uint16_t count;
    uint8_t expect = v->type == QS_TYPE_IDENTIFY ? QS_TYPE_IDENTIFY_REPLY
                     : v->type == QS_TYPE_INPUTS     ? QS_TYPE_INPUT_STATUS
                     : QS_TYPE_IS_IMMEDIATE(v->type) ? QS_TYPE_STATUS_REPORT
                                                     : QS_TYPE_ACK;
    uint16_t i;

    fresh_core(v, v->seq);
    /* A PROBE until an input is released finds it active. */
    if (v->type == QS_TYPE_PROBE && v->host.probe.level == 0)
        core.inputs.active = (uint16_t)(1u << v->host.probe.input);
    for (i = 0; i < v->frame_len; i++)
        qs_core_rx(&core, v->frame[i]);
    count = tp_reports(r, 4);
    TEST_ASSERT_EQUAL_INT_MESSAGE(v->type == QS_TYPE_HOLD || v->type == QS_TYPE_HOLD_ALONG ? 2 : 1, count, at(v, "number of reports"));
    TEST_ASSERT_EQUAL_HEX8_MESSAGE(expect, r[0].type, at(v, "report type"));
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(v->seq, r[0].seq, at(v, "report seq"));
    if (expect == QS_TYPE_ACK)
        TEST_ASSERT_EQUAL_INT_MESSAGE(QS_ACK_ACCEPTED, tp_ack(&r[0]).reason, at(v, "ack reason"));
    if (v->type == QS_TYPE_HOLD || v->type == QS_TYPE_HOLD_ALONG) {
        /* at rest: nothing to scale, an ordinary HOLD_DONE */
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(QS_TYPE_EVENT, r[1].type, at(v, "HOLD_DONE"));
        TEST_ASSERT_EQUAL_INT_MESSAGE(QS_EVENT_HOLD_DONE, r[1].payload[0], at(v, "event kind"));
    }
}

/* The firmware's answer to a malformed host frame: an ERROR naming why. */
static void check_core_refuses(const qs_vector *v)
{
    tp_report r[4];
    qs_error_report e;
    uint16_t count;
    uint16_t i;
    uint8_t seq = 0;

    /* Reach the content checks: expect the frame's own seq. */
    {
        qs_frame_rx rx;
        if (feed(v, &rx) == QS_FRAME_READY)
            seq = qs_frame_body(&rx)[1];
    }
    fresh_core(v, seq);
    for (i = 0; i < v->frame_len; i++)
        qs_core_rx(&core, v->frame[i]);
    count = tp_reports(r, 4);
    TEST_ASSERT_TRUE_MESSAGE(count >= 1, at(v, "no report"));
    e = tp_error(&r[0]);
    TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_code, e.code, at(v, "error code reported"));
    TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_field, e.field, at(v, "field reported"));
    TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_axis, e.axis, at(v, "axis reported"));
    if (is_framing(v->error_code)) {
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(0xFF, e.type, at(v, "type of a framing error"));
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(0xFF, e.seq, at(v, "seq of a framing error"));
        TEST_ASSERT_EQUAL_INT_MESSAGE(1, count, at(v, "reports after a framing error"));
    }
    /* Nothing of a refused segment runs (nor the one before it, with the alarm it raises). */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, qs_queue_count(&core.engine.queue), at(v, "queued"));
}

static void test_frames_to_the_firmware_decode_as_listed(void)
{
    int i, checked = 0;

    for (i = 0; i < VECTOR_COUNT; i++) {
        const qs_vector *v = &vectors[i];
        qs_host_msg m;
        qs_fault f;
        uint8_t code;

        if (!v->to_firmware)
            continue;
        code = decode(v, &m, &f);
        if (v->has_error) {
            TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_code, code, at(v, "error code"));
            if (code == QS_ERR_BAD_FIELD) {
                TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_field, f.field, at(v, "field"));
                TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_axis, f.axis, at(v, "axis"));
            }
            check_core_refuses(v);
        } else {
            TEST_ASSERT_EQUAL_INT_MESSAGE(QS_ERR_NONE, code, at(v, "decoding failed"));
            check_host_message(v, &m);
            check_core_accepts(v);
        }
        checked++;
    }
    TEST_ASSERT_TRUE_MESSAGE(checked > 0, "no to_firmware vectors");
}

/* Encoding the body of a valid frame gives the frame back: the COBS and CRC
 * encoder against the vectors. */
static void test_valid_frames_encode_back_to_their_bytes(void)
{
    int i;
    for (i = 0; i < VECTOR_COUNT; i++) {
        const qs_vector *v = &vectors[i];
        qs_frame_rx rx;
        uint8_t body[QS_MAX_FRAME];
        uint8_t wire[QS_MAX_WIRE];
        uint8_t len, n;

        if (v->has_error)
            continue;
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(QS_FRAME_READY, feed(v, &rx), at(v, "frame"));
        len = qs_frame_body_len(&rx);
        memcpy(body, qs_frame_body(&rx), len);
        n = qs_frame_encode(body, len, wire);
        TEST_ASSERT_EQUAL_INT_MESSAGE(v->frame_len, n, at(v, "encoded length"));
        TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(v->frame, wire, n, at(v, "encoded bytes"));
    }
}

static void test_reports_encode_to_exactly_the_listed_bytes(void)
{
    int i, checked = 0;

    for (i = 0; i < VECTOR_COUNT; i++) {
        const qs_vector *v = &vectors[i];
        uint8_t body[QS_MAX_FRAME];
        uint8_t wire[QS_MAX_WIRE];
        uint8_t len, n;

        if (v->to_firmware || v->has_error)
            continue;
        switch (v->type) {
        case QS_TYPE_ACK:
            len = qs_msg_encode_ack(body, v->seq, &v->ack);
            break;
        case QS_TYPE_IDENTIFY_REPLY:
            len = qs_msg_encode_identify_reply(body, v->seq, &v->identity);
            break;
        case QS_TYPE_STATUS_REPORT:
            len = qs_msg_encode_status_report(body, v->seq, &v->status);
            break;
        case QS_TYPE_ERROR:
            len = qs_msg_encode_error(body, v->seq, &v->error);
            break;
        case QS_TYPE_ALARM:
            len = qs_msg_encode_alarm(body, v->seq, &v->alarm);
            break;
        case QS_TYPE_INPUT_STATUS:
            len = qs_msg_encode_input_status(body, v->seq, &v->input_status);
            break;
        case QS_TYPE_EVENT:
            if (v->event.kind == QS_EVENT_INPUT) {
                len = qs_msg_encode_input_event(body, v->seq, v->event.motion_ticks, v->event.active,
                                                v->event.changed, v->event.cause, v->event.axis_count,
                                                v->event.position);
            } else if (v->event.kind == QS_EVENT_PROBE_MISSED) {
                len = qs_msg_encode_probe_missed(body, v->seq, v->event.motion_ticks, v->event.axis_count,
                                                 v->event.position);
            } else {
                TEST_ASSERT_TRUE_MESSAGE(v->event.kind == QS_EVENT_HOLD_DONE || v->event.kind == QS_EVENT_HOLD_DONE_ALONG,
                                         at(v, "event kind"));
                len = qs_msg_encode_hold_done(body, v->seq, v->event.kind, v->event.hold_tick, v->event.motion_ticks,
                                              v->event.axis_count, v->event.position);
            }
            break;
        default:
            TEST_FAIL_MESSAGE(at(v, "a report type the firmware does not send"));
            return;
        }
        n = qs_frame_encode(body, len, wire);
        TEST_ASSERT_EQUAL_INT_MESSAGE(v->frame_len, n, at(v, "encoded length"));
        TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(v->frame, wire, n, at(v, "encoded bytes"));
        checked++;
    }
    TEST_ASSERT_TRUE_MESSAGE(checked > 0, "no to_host vectors");
}

/* Malformed reports: the framing errors are the same in both directions and
 * the firmware's receiver must find them; the others (a report's type or
 * length) are for the host's decoder, and must at least pass framing. */
static void test_malformed_reports_fail_framing_as_listed(void)
{
    int i;
    for (i = 0; i < VECTOR_COUNT; i++) {
        const qs_vector *v = &vectors[i];
        qs_frame_rx rx;
        uint8_t result;

        if (v->to_firmware || !v->has_error)
            continue;
        result = feed(v, &rx);
        if (is_framing(v->error_code))
            TEST_ASSERT_EQUAL_INT_MESSAGE(v->error_code, result, at(v, "framing error"));
        else
            TEST_ASSERT_EQUAL_HEX8_MESSAGE(QS_FRAME_READY, result, at(v, "should pass framing"));
    }
}

/* The JSON's name tables give the same numbers as the firmware's constants. */
static void test_names_agree_with_the_firmware_constants(void)
{
    int i;
    TEST_ASSERT_EQUAL_INT_MESSAGE(QS_PROTOCOL_VERSION, VECTORS_PROTOCOL_VERSION,
                                  "the vectors are for another protocol version");
    for (i = 0; i < VECTOR_NAME_COUNT; i++)
        TEST_ASSERT_EQUAL_INT_MESSAGE(vector_names[i].json, vector_names[i].firmware,
                                      vector_names[i].name);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_frames_to_the_firmware_decode_as_listed);
    RUN_TEST(test_valid_frames_encode_back_to_their_bytes);
    RUN_TEST(test_reports_encode_to_exactly_the_listed_bytes);
    RUN_TEST(test_malformed_reports_fail_framing_as_listed);
    RUN_TEST(test_names_agree_with_the_firmware_constants);
    printf("%d vectors\n", VECTOR_COUNT);
    return UNITY_END();
}
