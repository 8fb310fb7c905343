/* A segment ready to run: the step engine's integer state for each axis,
 * computed once in the main loop so the tick does additions only.
 *
 * Per axis, with C1 = vn - v0, C2 = n*D, C3 = C1 + 2*n*v0 - n*D
 * (the seed's constants with both time bases equal to D, divided by D):
 *   h  = n*r + C3           the sign test of the next decision
 *   b  = C3 + 2*C1 - C2     what h gains after a step
 *   db = 2*C1               what b gains every tick
 * and per segment two_c2 = 2*n*D, what h gains extra without a step.
 * At a steady speed (vn = v0) db is 0 and the tick leaves b alone.
 * docs/FIXED_POINT.md derives these and bounds them by 2*n*D + 3*D. */
#ifndef QS_SEGMENT_H
#define QS_SEGMENT_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_int24.h"
#include "qs_messages.h"

/* A cubic segment's running state (qs_cubic.h), per axis, in the scale
 * Sigma = 2^31: h the sign test, b = I(t+2) - Sigma, q = I(t+2) - I(t+1)
 * (I(k): the ideal's advance over tick k), r the constant third
 * difference; e_top the top byte of the error at the segment's start, for
 * reading positions back mid-segment. */
typedef struct {
    uint32_t h[QS_AXIS_COUNT];
    uint32_t b[QS_AXIS_COUNT];
    qs_i24 q[QS_AXIS_COUNT];
    qs_i24 r[QS_AXIS_COUNT];
    int8_t e_top[QS_AXIS_COUNT];
} qs_cubic_run;

/* A RASTER's pixels (qs_raster.h): their powers at start in the core's
 * ring, and where the boundaries between them fall. */
typedef struct {
    uint16_t where; /* bits 0-9: the first power's index in the ring; 10-15: pixels */
    uint16_t phase; /* the first boundary, in 1/256 step from the segment's start */
    uint16_t pitch; /* the steps between boundaries, in 1/256 step */
} qs_raster_pixels;

typedef struct {
    /* First, so that the tick reaches them from the slot with ldd. */
    uint16_t n;
    uint8_t active;        /* bit i: axis i runs the loop */
    uint8_t tick_axes;     /* for the tick: active in bits 0-3, and in bits
                            * 4-7 the active axes whose b (quadratic: db = 0)
                            * or q (cubic: r = 0) never changes */
    uint8_t negative;      /* bit i: axis i steps in the negative direction */
    uint8_t ends_moving;   /* bit 0 (QS_ENDS_MOVING): some active axis is
                            * moving at the end; bits 5-7: the outputs
                            * while it runs, an index of qs_outputs.setting
                            * (kept here for the Uno's RAM) */
    uint8_t cubic;         /* 0: a quadratic segment; else a cubic one, with
                            * bit i set for axes whose b never changes
                            * (q = r = 0), and bit 7 always */
    union {
        struct { /* quadratic (SEGMENT) */
            qs_i24 h[QS_AXIS_COUNT];
            qs_i24 b[QS_AXIS_COUNT];
            qs_i24 db[QS_AXIS_COUNT];
            qs_i24 two_c2;
            int16_t r[QS_AXIS_COUNT]; /* the segment's residuals */
            qs_raster_pixels px;      /* a RASTER's pixels (QS_SLOT_RASTER) */
        };
        qs_cubic_run c; /* cubic (CUBIC_SEGMENT) */
    };
    uint16_t total[QS_AXIS_COUNT]; /* steps over the segment, for the positions */
} qs_segment;

#define QS_CUBIC_KIND 0x80

/* A cubic segment: never, in a build without them, so their code drops out. */
#define QS_IS_CUBIC(s) (QS_CUBIC && (s)->cubic)
#define QS_ENDS_MOVING 0x01
#define QS_SLOT_OUTPUTS_SHIFT 5
#define QS_SLOT_RASTER 0x02          /* a RASTER: px holds its pixels */
#define QS_SLOT_RASTER_AXIS_SHIFT 2 /* bits 2-3: the axis that counts them */
#define QS_SLOT_RASTER_TICK 0x10    /* its pixels last a PWM period or more: the tick switches them */

/* Fill a slot from a segment that passed qs_msg_check_segment. */
void qs_segment_prepare(qs_segment *slot, const qs_segment_msg *m);

/* Steps an active axis has made after t ticks of the segment (0 <= t <=
 * n), from the closed form of PROTOCOL.md section 8 and the running state,
 * so the tick need not count them. */
uint16_t qs_segment_steps(const qs_segment *s, uint8_t axis, uint16_t t);

/* The same from b, the axis's b after t ticks, taken earlier (so that the
 * division need not run with the tick locked out). */
uint16_t qs_segment_steps_from(const qs_segment *s, uint8_t axis, uint16_t t, qs_i24 b);

/* Speed numerator of an active axis, v(t) = v0 + (vn - v0)*t/n, after t
 * ticks of the segment, recovered from the running state as 2*n*v(t)
 * = b + 2*C2 - 3*C1 (what a controlled stop needs to plan from). */
int32_t qs_segment_speed_2n(const qs_segment *s, uint8_t axis);

#endif
