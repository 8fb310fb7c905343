/* Cubic segments: an exact step decision for jerk-limited motion
 * (docs/CUBIC.md derives it and bounds every width).
 *
 * Per axis, in its direction of motion and in the scale Sigma = 2^31 (one
 * step), I(k) is the ideal's advance over tick k, and its second difference
 * is a segment's constant r: I(k) = I + (k-1)*d + C(k-1, 2)*r. The running
 * state (qs_cubic_run) is h = e + I(t+1) - Sigma/2, b = I(t+2) - Sigma,
 * q = I(t+2) - I(t+1), where e is the ideal ahead of the stepper; a tick is
 *     step iff h >= 0;  h += b (+ Sigma without a step);  q += r;  b += q
 * in wrapping 32-bit arithmetic. The stepper stays within half a step of the
 * ideal while 0 <= I(k) <= Sigma on every tick.
 *
 * The main loop keeps the chain (qs_cubic_chain): the exact state after the
 * last segment prepared. A CUBIC_SEGMENT carries only what changes: per axis
 * an optional state set (I and d, with the direction) and an optional r; the
 * rest is carried, so a chain never drifts. */
#ifndef QS_CUBIC_H
#define QS_CUBIC_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_messages.h"
#include "qs_segment.h"

#define QS_SIGMA 0x80000000UL
#define QS_HALF_SIGMA 0x40000000UL

typedef struct {
    int32_t e[QS_AXIS_COUNT];  /* the ideal ahead of the stepper, in its direction */
    uint32_t i[QS_AXIS_COUNT]; /* I(1) of the next segment, mod 2^32 (valid: <= Sigma) */
    int32_t d[QS_AXIS_COUNT];  /* I(2) - I(1) */
    uint8_t negative;          /* bit i: axis i's direction is negative */
    /* After a quadratic segment, its end state is worked out only when a
     * cubic one follows (quadratic streams pay for a few bytes kept): the
     * slot (its end residuals stay there until the ring comes round to it,
     * and every segment prepared in between replaces this) and its end
     * speeds. */
    const qs_segment *after;
    uint16_t after_vn[QS_AXIS_COUNT];
    uint8_t after_active, after_negative;
} qs_cubic_chain;

/* At rest, on the ideal: after reset, STOP, a hold, an alarm. */
void qs_cubic_reset(qs_cubic_chain *c);

/* The axes in mask have new step positions: they rest on the ideal. */
void qs_cubic_rest_on_ideal(qs_cubic_chain *c, uint8_t mask);

/* After a quadratic segment (slot prepared from m): its exact end state,
 * kept to be worked out when needed. Axes it does not name stop. */
void qs_cubic_follow_quadratic(qs_cubic_chain *c, const qs_segment *slot, const qs_segment_msg *m);

/* Where the chain leaves an axis, as a quadratic segment in the direction
 * `negative` (0 or 1) would start from it: its speed in 1/4096 step per
 * tick and its residual in 1/8192 step, each given only where it lies on
 * that grid (the bits QS_CHAIN_SPEED and QS_CHAIN_RESIDUAL of the result);
 * after a cubic segment either may not. */
#define QS_CHAIN_SPEED 0x01
#define QS_CHAIN_RESIDUAL 0x02
uint8_t qs_cubic_quadratic_start(qs_cubic_chain *c, uint8_t axis, uint8_t negative, uint16_t *speed, int16_t *r);

/* The chain's I for an axis (mod 2^32: valid while <= Sigma) and its
 * direction (1: negative). */
uint32_t qs_cubic_speed(qs_cubic_chain *c, uint8_t axis, uint8_t *negative);

/* Check m against the chain (field by field as PROTOCOL.md section 5.2 lists
 * them) and, if every axis can run it exactly, fill slot and advance the
 * chain. Returns QS_ERR_NONE, or QS_ERR_BAD_FIELD with f filled in and
 * nothing changed. */
uint8_t qs_cubic_prepare(qs_cubic_chain *c, qs_segment *slot, const qs_cubic_msg *m, uint8_t axis_count,
                         qs_fault *f);

/* Steps an active axis of a cubic slot has made after t ticks (0 <= t <=
 * n), from its running state after those ticks (h, b, q). */
uint16_t qs_cubic_steps(const qs_segment *s, uint8_t axis, uint16_t t, uint32_t h, uint32_t b, qs_i24 q);

#endif
