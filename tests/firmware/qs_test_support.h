/* Shared by the firmware test suites: the port the core sends through (it
 * records everything), and helpers that talk to a core as a host would. */
#ifndef QS_TEST_SUPPORT_H
#define QS_TEST_SUPPORT_H

#include <stdint.h>
#include "qs_core.h"

#define TP_MAX_REPORTS 512

typedef struct {
    uint8_t type;
    uint8_t seq;
    uint8_t len; /* payload length */
    uint8_t payload[QS_MAX_FRAME];
} tp_report;

/* Per-axis fields of a SEGMENT as the host writes them. */
typedef struct {
    uint16_t v0;
    uint16_t vn;
    int16_t r;
} tp_axis;

/* Forget what was sent so far. */
void tp_clear_sent(void);

/* Decode everything sent since the last clear into reports (the test fails
 * if anything is not a valid frame). Returns the number of reports. */
uint16_t tp_reports(tp_report *out, uint16_t max);

/* tp_reports, then tp_clear_sent: the reports sent since the last take. */
uint16_t tp_take_reports(tp_report *out, uint16_t max);

/* Fails the test unless locks and unlocks have been balanced. */
void tp_check_unlocked(void);

/* Frame a body and feed its wire bytes to the core. */
void tp_send(qs_core *c, const uint8_t *body, uint8_t len);
void tp_send_simple(qs_core *c, uint8_t type, uint8_t seq);

/* SEGMENT body: axes[j] for the j-th active axis in axis order. */
uint8_t tp_segment_body(uint8_t *body, uint8_t seq, uint16_t n, uint8_t active,
                        uint8_t negative, const tp_axis *axes);
void tp_send_segment(qs_core *c, uint8_t seq, uint16_t n, uint8_t active, uint8_t negative,
                     const tp_axis *axes);

/* Payload readers. */
qs_ack tp_ack(const tp_report *r);
qs_error_report tp_error(const tp_report *r);
uint32_t tp_u32(const uint8_t *p);
uint16_t tp_u16(const uint8_t *p);

/* Run the tick n times (the engine's, then a RASTER line's pixels); returns how many steps axis 0..3 made in
 * total (sum over axes). */
uint32_t tp_ticks(qs_core *c, uint32_t n);

/* A reproducible pseudo-random sequence for the randomised tests:
 * tp_rand(limit) is in 0 .. limit-1. */
void tp_seed(uint64_t seed);
uint32_t tp_rand(uint32_t limit);

/* The reference arithmetic, in 64 bits: floor(num / den) for den > 0, and
 * a segment's exact ideal position times 2nD at tick t,
 * X(t) = n*r + (vn - v0)*t^2 + 2*n*v0*t, and its steps by tick t, the
 * closed form s(t) of PROTOCOL.md section 8. */
int64_t tp_floor_div(int64_t num, int64_t den);
int64_t tp_ideal_2nd(const qs_segment_msg *m, uint8_t axis, int64_t t);
int64_t tp_closed_form(const qs_segment_msg *m, uint8_t axis, int64_t t);

/* qs_port_clock() reads this; tests move it. */
extern uint16_t test_clock;
extern int test_laser_power;
extern uint8_t test_laser_period;

#endif
