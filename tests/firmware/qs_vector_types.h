/* One test vector of protocol/vectors.json, as the generated header
 * (gen_vectors.py) lays it out. */
#ifndef QS_VECTOR_TYPES_H
#define QS_VECTOR_TYPES_H

#include <stdint.h>
#include "qs_messages.h"

typedef struct {
    const char *name;
    uint8_t to_firmware;
    const uint8_t *frame; /* wire bytes, delimiter included */
    uint16_t frame_len;
    uint8_t axis_count;   /* the firmware axis count the outcome assumes */
    /* A valid vector: the message. */
    uint8_t type;
    uint8_t seq;
    union {
        qs_segment_msg segment;
        qs_cubic_msg cubic;
        qs_set_position_msg set_position;
        qs_hold_msg hold;
        qs_hold_along_msg hold_along;
        qs_probe_msg probe;
        qs_config_msg config;
        qs_watchdog_msg watchdog;
        qs_outputs_msg outputs;
    } host;
    /* RASTER: its fields, and the SEGMENT a fresh firmware runs before it (its chain). */
    struct {
        uint16_t n;
        uint8_t axes, pixel;
        uint16_t phase, pitch;
        uint8_t count;
        uint8_t power[64];
    } raster;
    uint8_t has_after;
    qs_segment_msg after;
    /* SEGMENTS and CUBIC_SEGMENTS: what its records mean to a freshly started firmware. */
    uint8_t expands_count;
    qs_segment_msg expands[QS_SEGMENTS_MAX];
    qs_cubic_msg cubic_expands[QS_SEGMENTS_MAX];
    qs_input_status input_status;
    qs_ack ack;
    qs_identity identity;
    qs_status status;
    qs_error_report error;
    qs_alarm_report alarm;
    struct { /* EVENT: HOLD_DONE, HOLD_DONE_ALONG, INPUT or PROBE_MISSED, by kind */
        uint8_t kind;
        uint32_t hold_tick;
        uint32_t motion_ticks;
        uint16_t active;
        uint16_t changed;
        uint8_t cause;
        uint8_t axis_count;
        int32_t position[QS_PROTOCOL_AXES];
    } event;
    /* A malformed vector: why decoding fails. */
    uint8_t has_error;
    uint8_t error_code;
    uint8_t error_field;
    uint8_t error_axis;
} qs_vector;

/* A name of the JSON's name tables, the firmware's constant, the JSON's value. */
typedef struct {
    const char *name;
    int firmware;
    int json;
} qs_vector_name;

#endif
