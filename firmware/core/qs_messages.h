/* Message payloads (PROTOCOL.md section 5): parsing and validating what the
 * host sends, encoding the reports the firmware sends. Bodies are
 * type, seq, payload; framing is qs_frame's job. */
#ifndef QS_MESSAGES_H
#define QS_MESSAGES_H

#include <stdint.h>
#include "qs_protocol.h"

#define QS_PROTOCOL_AXES 4 /* axes the wire format can name */

typedef struct {
    uint16_t n;
    uint8_t active;   /* bit i: axis i has fields in this segment */
    uint8_t negative; /* bit i: axis i moves in the negative direction */
    uint16_t v0[QS_PROTOCOL_AXES]; /* indexed by axis, valid where active */
    uint16_t vn[QS_PROTOCOL_AXES];
    int16_t r[QS_PROTOCOL_AXES];
} qs_segment_msg;

/* CUBIC_SEGMENT: n ticks; per axis an optional state set (speed and
 * acceleration) and an optional jerk, the rest carried from the segment
 * before (PROTOCOL.md section 5.2, docs/CUBIC.md). */
typedef struct {
    uint16_t n;
    uint8_t jerk;     /* bit i: axis i has a jerk field */
    uint8_t set;      /* bit i: axis i has a state set */
    uint8_t negative; /* bit i: a set axis moves in the negative direction */
    uint32_t speed[QS_PROTOCOL_AXES]; /* set: I, the advance over the first tick, 2^-31 step (< 2^31) */
    int32_t accel[QS_PROTOCOL_AXES];  /* set: its change per tick, 2^-31 step per tick^2 (24 bits) */
    int16_t r[QS_PROTOCOL_AXES];      /* jerk: the change of that per tick; 0 where absent */
} qs_cubic_msg;

/* SEGMENTS and CUBIC_SEGMENTS: 1 ... QS_SEGMENTS_MAX records of chained
 * segments, read one by one against the chain (qs_segments.h,
 * qs_cubic_records.h) once the frame is taken; parsing only checks that
 * every record is whole. */
typedef struct {
    const uint8_t *next; /* the next record, in the frame's body */
    uint8_t count;       /* records */
    /* per axis, from the frame's records so far: SEGMENTS, vn - v0 of the
     * last that changed it; CUBIC_SEGMENTS, the last jerk it was given */
    int16_t last[QS_PROTOCOL_AXES];
} qs_segments_msg;

typedef struct {
    uint8_t mask;
    int32_t position[QS_PROTOCOL_AXES]; /* indexed by axis, valid where in mask */
} qs_set_position_msg;

/* HOLD: a deceleration for each axis the wire names, in 2^-24 step per
 * tick^2 (0 for axes the firmware does not have). */
typedef struct {
    uint16_t decel[QS_PROTOCOL_AXES];
} qs_hold_msg;

/* HOLD_ALONG's own part: the decelerations (worked out by the host from the
 * segments' direction) that stop the segments whose segments_done (mod
 * 2^16) lies in first ... last together, on their line. */
typedef struct {
    qs_hold_msg hold;
    uint16_t first;
    uint16_t last;
} qs_path_hold;

/* HOLD_ALONG: a HOLD's payload first (hold), then its path. */
typedef struct {
    qs_hold_msg hold;
    qs_path_hold path;
} qs_hold_along_msg;

/* WATCHDOG: stop (a hold, then ALARM HOST_LOST) when no frame has come
 * for timeout_ms while moving; 0 turns it off. */
typedef struct {
    uint16_t timeout_ms;
} qs_watchdog_msg;

/* PROBE: the motion that follows ends where input reaches level (1
 * active, 0 inactive), with a hold at these decelerations (HOLD's). */
typedef struct {
    uint8_t input;
    uint8_t level;
    qs_hold_msg hold;
} qs_probe_msg;

#define QS_WIRE_INPUTS 12 /* inputs the wire names (QS_INPUT_*) */

/* CONFIG: the inputs' settings. */
typedef struct {
    uint16_t invert;
    uint16_t enabled;
    uint8_t hard_limits;
    uint8_t debounce[QS_WIRE_INPUTS];
    qs_hold_msg hold; /* the feed hold input's decelerations (hold_decel) */
} qs_config_msg;

/* OUTPUTS: the spindle (or laser) and coolant outputs from the next segment
 * on (PROTOCOL.md section 5.5). power is the output's duty, 0 ... 65535;
 * with QS_OUT_DYNAMIC it is the duty at `speed` (1/4096 step per tick) of
 * `axis`, and the duty follows that axis's speed below it. */
typedef struct {
    uint8_t outputs; /* QS_OUT_* */
    uint8_t axis;
    uint16_t power;
    uint16_t speed;
} qs_outputs_msg;

/* RASTER: a laser line at one speed, a power per pixel (qs_raster.h). */
typedef struct {
    uint16_t n;
    uint8_t axes;  /* as SEGMENT's: active axes, their directions */
    uint8_t pixel; /* bits 0-1: the axis whose steps count the pixels; others 0 */
    uint16_t phase;
    uint16_t pitch;
    uint8_t count;        /* pixels, 1 ... QS_RASTER_PIXELS_MAX */
    const uint8_t *power; /* in the frame's body */
} qs_raster_msg;

typedef struct {
    uint8_t type;
    uint8_t seq;
    union {
        qs_segment_msg segment;
        qs_cubic_msg cubic;
        qs_segments_msg segments;
        qs_set_position_msg set_position;
        qs_hold_msg hold;
        qs_hold_along_msg hold_along; /* begins with a HOLD's: as.hold reads it */
        qs_probe_msg probe;
        qs_config_msg config;
        qs_watchdog_msg watchdog;
        qs_outputs_msg outputs;
        qs_raster_msg raster;
    } as;
} qs_host_msg;

/* Why a message was refused: an ERROR code and, for BAD_FIELD, which. */
typedef struct {
    uint8_t code;
    uint8_t field;
    uint8_t axis;
} qs_fault;

/* Parsing a host message's payload (after type and seq), one function per
 * message: the length check (code 7 of section 2), then the fields as they
 * are. Return QS_ERR_NONE or QS_ERR_BAD_LENGTH. Which function a type
 * needs is the table in qs_dispatch.c. */
uint8_t qs_msg_parse_empty(uint8_t len);
uint8_t qs_msg_parse_cubic(const uint8_t *p, uint8_t len, qs_cubic_msg *c);
uint8_t qs_msg_parse_segment(const uint8_t *p, uint8_t len, qs_segment_msg *s);
uint8_t qs_msg_parse_segments(const uint8_t *p, uint8_t len, qs_segments_msg *s);
uint8_t qs_msg_parse_cubic_segments(const uint8_t *p, uint8_t len, qs_segments_msg *s);
uint8_t qs_msg_parse_set_position(const uint8_t *p, uint8_t len, qs_set_position_msg *sp);
uint8_t qs_msg_parse_hold(const uint8_t *p, uint8_t len, qs_hold_msg *h);
uint8_t qs_msg_parse_hold_along(const uint8_t *p, uint8_t len, qs_hold_along_msg *h);
uint8_t qs_msg_parse_probe(const uint8_t *p, uint8_t len, qs_probe_msg *pr);
uint8_t qs_msg_parse_config(const uint8_t *p, uint8_t len, qs_config_msg *cf);
uint8_t qs_msg_parse_watchdog(const uint8_t *p, uint8_t len, qs_watchdog_msg *w);
uint8_t qs_msg_parse_outputs(const uint8_t *p, uint8_t len, qs_outputs_msg *o);

/* f filled in for BAD_FIELD of field (QS_FIELD_*) and axis; returns QS_ERR_BAD_FIELD. */
uint8_t qs_msg_bad_field(qs_fault *f, uint8_t field, uint8_t axis);

/* Content checks in the order of section 5.2. Return QS_ERR_NONE or
 * QS_ERR_BAD_FIELD with f filled in. */
uint8_t qs_msg_check_segment(const qs_segment_msg *s, uint8_t axis_count, qs_fault *f);
uint8_t qs_msg_check_set_position(const qs_set_position_msg *p, uint8_t axis_count, qs_fault *f);
uint8_t qs_msg_check_hold(const qs_hold_msg *h, uint8_t axis_count, qs_fault *f);
/* present: the inputs the firmware has. */
uint8_t qs_msg_check_probe(const qs_probe_msg *pr, uint8_t axis_count, uint16_t present, qs_fault *f);
uint8_t qs_msg_check_config(const qs_config_msg *cf, uint8_t axis_count, qs_fault *f);
uint8_t qs_msg_check_watchdog(const qs_watchdog_msg *w, qs_fault *f);
uint8_t qs_msg_check_outputs(const qs_outputs_msg *o, uint8_t axis_count, qs_fault *f);

typedef struct {
    uint8_t next_seq;
    uint8_t free;
    uint8_t reason;
    uint16_t done;
} qs_ack;

typedef struct {
    uint8_t protocol_version;
    uint8_t fw_major, fw_minor, fw_patch;
    uint8_t board;
    uint8_t axis_count;
    uint8_t queue_capacity;
    uint8_t speed_shift;
    uint16_t n_max;
    uint32_t tick_hz;
    uint16_t capabilities;
    uint8_t next_seq;
    uint16_t boot_id; /* made at each reset: a host tells a board reset since it last asked */
    uint16_t raster_ring; /* pixel powers RASTER lines may hold queued; 0 without RASTER */
} qs_identity;

/* The STATUS_REPORT counters; each saturates at 65535. */
typedef struct {
    uint16_t rx_overrun;
    uint16_t bad_frame;
    uint16_t bad_crc;
    uint16_t seq_gap;
    uint16_t seq_dup;
    uint16_t rejected;
} qs_counters;

typedef struct {
    uint8_t state;
    uint8_t alarm;
    uint8_t queue_fill;
    uint8_t next_seq;
    uint32_t segments_done;
    uint32_t motion_ticks;
    qs_counters counters;
    uint8_t axis_count;
    int32_t position[QS_PROTOCOL_AXES];
} qs_status;

typedef struct {
    uint8_t code;
    uint8_t type;
    uint8_t seq;
    uint8_t field;
    uint8_t axis;
} qs_error_report;

typedef struct {
    uint8_t code;
    uint32_t motion_ticks;
    uint8_t axis_count;
    int32_t position[QS_PROTOCOL_AXES];
} qs_alarm_report;

typedef struct {
    uint16_t present;
    uint16_t active;
    uint16_t raw;
    uint16_t invert;
    uint16_t enabled;
    uint8_t hard_limits;
    uint8_t armed; /* the armed PROBE's input, QS_AXIS_NONE (0xFF) when none */
    uint8_t level;
    uint16_t latches_lost;
} qs_input_status;

/* Report encoders: write type, seq and payload into body (QS_MAX_FRAME
 * bytes) and return the body length. */
uint8_t qs_msg_encode_ack(uint8_t *body, uint8_t seq, const qs_ack *a);
uint8_t qs_msg_encode_identify_reply(uint8_t *body, uint8_t seq, const qs_identity *id);
uint8_t qs_msg_encode_status_report(uint8_t *body, uint8_t seq, const qs_status *st);
uint8_t qs_msg_encode_error(uint8_t *body, uint8_t seq, const qs_error_report *e);
uint8_t qs_msg_encode_alarm(uint8_t *body, uint8_t seq, const qs_alarm_report *a);
/* EVENT HOLD_DONE (kind QS_EVENT_HOLD_DONE, or QS_EVENT_HOLD_DONE_ALONG
 * for a hold begun with a HOLD_ALONG's path decelerations): where a hold
 * began, when and where everything rests. */
uint8_t qs_msg_encode_hold_done(uint8_t *body, uint8_t seq, uint8_t kind, uint32_t hold_tick,
                                uint32_t motion_ticks, uint8_t axis_count, const int32_t *position);

uint8_t qs_msg_encode_input_status(uint8_t *body, uint8_t seq, const qs_input_status *st);
/* EVENT INPUT: an input's accepted change, latched at motion_ticks. */
uint8_t qs_msg_encode_input_event(uint8_t *body, uint8_t seq, uint32_t motion_ticks, uint16_t active,
                                  uint16_t changed, uint8_t cause, uint8_t axis_count, const int32_t *position);
/* EVENT PROBE_MISSED: the armed motion came to rest without its edge. */
uint8_t qs_msg_encode_probe_missed(uint8_t *body, uint8_t seq, uint32_t motion_ticks, uint8_t axis_count,
                                   const int32_t *position);

#endif
