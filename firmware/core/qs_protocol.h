/* Wire protocol constants (protocol/PROTOCOL.md, version 2).
 * tests/protocol/test_protocol_c_header.py parses this file and holds every
 * number here equal to the host's (host/quadstep/protocol/): names are
 * QS_<TABLE>_<NAME>, payload lengths QS_LEN_<MESSAGE>[_HEAD|_AXIS]. */
#ifndef QS_PROTOCOL_H
#define QS_PROTOCOL_H

#define QS_PROTOCOL_VERSION 3

/* Fixed-point step model (section 1, 5.2; docs/FIXED_POINT.md). */
#define QS_SPEED_SHIFT 12
#define QS_D 4096            /* speed denominator: v/4096 steps per tick */
#define QS_N_MAX 1022        /* longest segment in ticks */
#define QS_V_MAX 4096        /* one step per tick */
#define QS_R_MAX 4096        /* residual limit, in 1/8192 step */

/* Controlled deceleration (section 5.1, HOLD; docs/FIXED_POINT.md section 8):
 * decelerations in 2^-24 step per tick^2, 1 ... QS_DECEL_MAX. */
#define QS_DECEL_SHIFT 24
#define QS_DECEL_MAX 8191

/* Cubic segments (section 5.2, CUBIC_SEGMENT; docs/CUBIC.md): the ideal's
 * advance per tick in 2^-QS_CUBIC_SHIFT step, its change per tick under
 * QS_CUBIC_ACCEL_LIMIT in magnitude, segments up to QS_CUBIC_N_MAX ticks. */
#define QS_CUBIC_SHIFT 31
#define QS_CUBIC_ACCEL_LIMIT 8388608L /* 2^23 */
#define QS_CUBIC_N_MAX 65535

/* Framing (section 2). */
#define QS_MAX_FRAME 64      /* decoded body + crc16 */
#define QS_MIN_FRAME 4       /* type, seq, crc16 */
#define QS_MAX_BODY (QS_MAX_FRAME - 2)
/* COBS(body || crc) || 0x00: at most one code byte per 254 data bytes. */
#define QS_MAX_WIRE (QS_MAX_FRAME + 2)

/* Message types (sections 3, 5). Each host message is one row of
 * HOST_MESSAGES in qs_dispatch.c, each report one encoder in
 * qs_messages.c. */
#define QS_TYPE_IDENTIFY 0x01
#define QS_TYPE_STATUS 0x02
#define QS_TYPE_STOP 0x03
#define QS_TYPE_HOLD 0x04
#define QS_TYPE_INPUTS 0x06
#define QS_TYPE_WATCHDOG 0x07
#define QS_TYPE_HOLD_ALONG 0x08 /* HOLD with decelerations for a stop along the path */
#define QS_TYPE_SEGMENT 0x10
#define QS_TYPE_SET_POSITION 0x11
#define QS_TYPE_PROBE 0x15
#define QS_TYPE_CONFIG 0x16
#define QS_TYPE_CUBIC_SEGMENT 0x12
#define QS_TYPE_OUTPUTS 0x17
#define QS_TYPE_SEGMENTS 0x18
#define QS_TYPE_CUBIC_SEGMENTS 0x19
#define QS_TYPE_RASTER 0x1A
#define QS_TYPE_ACK 0x80
#define QS_TYPE_IDENTIFY_REPLY 0x81
#define QS_TYPE_STATUS_REPORT 0x82
#define QS_TYPE_ERROR 0x83
#define QS_TYPE_ALARM 0x84
#define QS_TYPE_EVENT 0x85
#define QS_TYPE_INPUT_STATUS 0x86

#define QS_TYPE_IS_IMMEDIATE(t) ((t) <= 0x0F)
#define QS_SEQ_UNSOLICITED 0xFF

/* Payload lengths: a fixed payload, or a fixed head and then a number of
 * bytes per axis. */
#define QS_LEN_HOLD 8 /* decel:u16 for each of the 4 axes the wire names */
#define QS_LEN_HOLD_ALONG 20 /* HOLD's, the path's decel:u16 x 4, first:u16, last:u16 */
#define QS_LEN_WATCHDOG 2 /* timeout_ms:u16 */
#define QS_LEN_SEGMENT_HEAD 3
#define QS_LEN_SEGMENT_AXIS 6
#define QS_LEN_CUBIC_SEGMENT_HEAD 3 /* n, fields; then per axis a set and a jerk, each if named */
#define QS_LEN_CUBIC_SEGMENT_SET 7  /* speed:u32, accel:i24 */
#define QS_LEN_CUBIC_SEGMENT_JERK 2 /* r:i16 */
#define QS_LEN_SET_POSITION_HEAD 1
#define QS_LEN_SET_POSITION_AXIS 4
#define QS_LEN_ACK 5
#define QS_LEN_IDENTIFY_REPLY 21
#define QS_LEN_STATUS_REPORT_HEAD 24
#define QS_LEN_STATUS_REPORT_AXIS 4
#define QS_LEN_ERROR 5
#define QS_LEN_ALARM_HEAD 5
#define QS_LEN_ALARM_AXIS 4
#define QS_LEN_HOLD_DONE_HEAD 9 /* EVENT HOLD_DONE: kind, hold_tick, motion_ticks */
#define QS_LEN_HOLD_DONE_AXIS 4
#define QS_LEN_HOLD_DONE_ALONG_HEAD 9 /* EVENT HOLD_DONE_ALONG: as HOLD_DONE */
#define QS_LEN_HOLD_DONE_ALONG_AXIS 4
#define QS_LEN_PROBE 10 /* input, level, decel:u16 x 4 */
#define QS_LEN_CONFIG 25 /* invert, enabled, hard_limits, debounce:u8 x 12, hold_decel:u16 x 4 */
#define QS_LEN_OUTPUTS 6 /* outputs, power:u16, axis, speed:u16 */
#define QS_LEN_RASTER 8 /* n:u16, axes, pixel, phase:u16, pitch:u16; then a power per pixel */
#define QS_LEN_INPUT_STATUS 15
#define QS_LEN_INPUT_HEAD 10 /* EVENT INPUT: kind, motion_ticks, active, changed, cause */
#define QS_LEN_INPUT_AXIS 4
#define QS_LEN_PROBE_MISSED_HEAD 5 /* EVENT PROBE_MISSED: kind, motion_ticks */
#define QS_LEN_PROBE_MISSED_AXIS 4

/* ACK reasons. */
#define QS_ACK_ACCEPTED 0
#define QS_ACK_GAP 1
#define QS_ACK_DUPLICATE 2
#define QS_ACK_QUEUE_FULL 3
#define QS_ACK_REJECTED 4
#define QS_ACK_SPACE 5
#define QS_ACK_PARKED 6 /* after a gap: kept, to run once the frames before it arrive */

/* ERROR codes (section 6). */
#define QS_ERR_NONE 0
#define QS_ERR_FRAME_TOO_LONG 1
#define QS_ERR_FRAME_TOO_SHORT 2
#define QS_ERR_BAD_COBS 3
#define QS_ERR_BAD_CRC 4
#define QS_ERR_UNKNOWN_TYPE 5
#define QS_ERR_BAD_LENGTH 6
#define QS_ERR_RX_OVERRUN 7
#define QS_ERR_BAD_FIELD 16
#define QS_ERR_BUSY 17
#define QS_ERR_ALARM_ACTIVE 18
#define QS_ERR_INPUT_AT_LEVEL 19 /* PROBE: the input is already where the motion is to end */

/* BAD_FIELD field ids. */
#define QS_FIELD_NONE 0
#define QS_FIELD_N 1
#define QS_FIELD_AXES 2
#define QS_FIELD_DIRECTION 3
#define QS_FIELD_V0 4
#define QS_FIELD_VN 5
#define QS_FIELD_RESIDUAL 6
#define QS_FIELD_DECEL 7
#define QS_FIELD_INPUT 8
#define QS_FIELD_LEVEL 9
#define QS_FIELD_INPUTS 10
#define QS_FIELD_HARD_LIMITS 11
#define QS_FIELD_SPEED 12 /* cubic: an advance per tick outside 0 ... 1 step */
#define QS_FIELD_ACCEL 13 /* cubic: an acceleration outside 24 bits */
#define QS_FIELD_POSITION 14 /* a position past QS_POSITION_MAX, or a segment that could carry one there */
#define QS_FIELD_TIMEOUT 15 /* WATCHDOG: a timeout above QS_WATCHDOG_MAX_MS */
#define QS_FIELD_OUTPUTS 16 /* OUTPUTS: a bit no output has */
#define QS_FIELD_REFERENCE 17 /* OUTPUTS: a power following no axis, or a speed outside 1 ... 4096 */
#define QS_FIELD_JERK 18 /* CUBIC_SEGMENTS: a jerk outside 16 bits */
#define QS_FIELD_RASTER_AXIS 19 /* RASTER: the pixel axis not moving, or not the one with most steps */
#define QS_FIELD_PIXELS 20 /* RASTER: a pixel under a step, or a boundary past the line's steps */
#define QS_AXIS_NONE 0xFF

/* ALARM codes. */
#define QS_ALARM_NONE 0
#define QS_ALARM_UNDERRUN 1 /* no longer raised: an underrun ends STARVED */
#define QS_ALARM_REJECTED_SEGMENT 2
#define QS_ALARM_HARD_LIMIT 3
#define QS_ALARM_HOST_LOST 4  /* the host went silent while moving (WATCHDOG) */
#define QS_ALARM_E_STOP 5

/* Machine states. */
#define QS_STATE_IDLE 0
#define QS_STATE_RUNNING 1
#define QS_STATE_ALARM 2
#define QS_STATE_HOLDING 3 /* decelerating to rest after a HOLD */
#define QS_STATE_STARVED 4 /* at rest after an underrun's stop: motion refused until HOLD or STOP */

/* EVENT kinds. */
#define QS_EVENT_HOLD_DONE 1
#define QS_EVENT_INPUT 2
#define QS_EVENT_PROBE_MISSED 3
#define QS_EVENT_HOLD_DONE_ALONG 4 /* HOLD_DONE of a hold that stopped along the path */

/* Inputs (section 5.4): bit i of every input mask. */
#define QS_INPUT_LIMIT_0 0
#define QS_INPUT_LIMIT_1 1
#define QS_INPUT_LIMIT_2 2
#define QS_INPUT_LIMIT_3 3
#define QS_INPUT_LIMIT_MAX_0 4
#define QS_INPUT_LIMIT_MAX_1 5
#define QS_INPUT_LIMIT_MAX_2 6
#define QS_INPUT_LIMIT_MAX_3 7
#define QS_INPUT_PROBE 8
#define QS_INPUT_ABORT 9
#define QS_INPUT_FEED_HOLD 10
#define QS_INPUT_CYCLE_START 11

/* What an input's accepted change did (EVENT INPUT). */
#define QS_CAUSE_REPORT 0
#define QS_CAUSE_HARD_LIMIT 1
#define QS_CAUSE_TRIGGER 2
#define QS_CAUSE_E_STOP 3
#define QS_CAUSE_FEED_HOLD 4
#define QS_CAUSE_CYCLE_START 5

/* IDENTIFY board codes. */
#define QS_BOARD_EMULATOR 0
#define QS_BOARD_ATMEGA328P 1
#define QS_BOARD_ATMEGA2560 2

/* IDENTIFY capability bits. */
#define QS_CAP_QUADRATIC_SEGMENTS 0x0001
#define QS_CAP_SET_POSITION 0x0002
#define QS_CAP_HOLD 0x0004
#define QS_CAP_JOG 0x0008
#define QS_CAP_LIMIT_INPUTS 0x0010
#define QS_CAP_PROBE_INPUT 0x0020
#define QS_CAP_HOMING 0x0040
#define QS_CAP_CUBIC_SEGMENTS 0x0080
#define QS_CAP_CONTROL_INPUTS 0x0100
#define QS_CAP_CONTROLLED_STOPS 0x0200 /* an underrun and a silent host end in a hold; WATCHDOG */

/* WATCHDOG (section 5.1): the longest timeout, in ms. */
#define QS_WATCHDOG_MAX_MS 4000
/* Positions (section 5.2): the firmware keeps every position within this. */
#define QS_POSITION_MAX 2130706432L /* 2^31 - 2^24 */
#define QS_CAP_OUTPUTS 0x0400 /* spindle, laser and coolant outputs (OUTPUTS) */
#define QS_CAP_SEGMENTS 0x0800 /* chained quadratic segments, several to a frame (SEGMENTS) */
#define QS_CAP_CUBIC_RUNS 0x1000 /* chained cubic segments, several to a frame (CUBIC_SEGMENTS) */
#define QS_CAP_STARVATION_PAUSES 0x2000 /* an underrun ends in STARVED, not in an alarm */
#define QS_CAP_RASTER 0x4000 /* laser lines with a power per pixel (RASTER) */
#define QS_CAP_STOPS_ALONG 0x8000 /* holds along the path (HOLD_ALONG, EVENT HOLD_DONE_ALONG) */

/* SEGMENTS (section 5.2): records of chained quadratic segments. A record's
 * head byte holds bits 8-9 of n and what follows it. */
#define QS_SEGMENTS_MAX 16      /* records in one frame */
#define QS_RECORD_N_HIGH 0x03   /* n's bits 8-9; its low byte follows the head */
#define QS_RECORD_AXES 0x04     /* an axes byte follows (as SEGMENT's) */
#define QS_RECORD_START 0x08    /* per axis: v0 less the chain's speed */
#define QS_RECORD_RESIDUAL 0x10 /* per axis: r */
#define QS_RECORD_CRUISE 0x20   /* vn = v0 on every axis: no vn field */
#define QS_RECORD_REPEAT 0x40   /* the record before again, alone in its head */
#define QS_RECORD_MIRROR 0x80   /* vn fields less the negated last change in the frame */

/* CUBIC_SEGMENTS (section 5.2): records of chained cubic segments. A record
 * is a jerks byte (2 bits per axis, axis 0 lowest), a varint n*4 + flags,
 * the sets where flagged, then a varint per axis whose jerk is given. */
#define QS_CUBIC_JERK_NONE 0   /* no jerk */
#define QS_CUBIC_JERK_GIVEN 1  /* a zigzag varint follows */
#define QS_CUBIC_JERK_NEGATE 2 /* minus the axis's last jerk in the frame */
#define QS_CUBIC_JERK_SAME 3   /* the axis's last jerk in the frame */
#define QS_CUBIC_RECORD_SETS 0x01  /* a sets byte follows: bits 0-3 axes set, 4-7 their directions */
#define QS_CUBIC_RECORD_ACCEL 0x02 /* each set axis has an acceleration after its speed */

/* OUTPUTS bits (section 5.5). */
#define QS_OUT_ON 0x01      /* the spindle or laser output is on */
#define QS_OUT_REVERSE 0x02 /* the spindle turns the other way (direction pin) */
#define QS_OUT_DYNAMIC 0x04 /* the power follows the speed of an axis */
#define QS_OUT_MIST 0x10    /* coolant: mist */
#define QS_OUT_FLOOD 0x20   /* coolant: flood */
#define QS_OUT_BITS (QS_OUT_ON | QS_OUT_REVERSE | QS_OUT_DYNAMIC | QS_OUT_MIST | QS_OUT_FLOOD)

#endif
