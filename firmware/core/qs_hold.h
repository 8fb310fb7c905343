/* A controlled stop (HOLD): every moving axis of the running segment
 * decelerates to rest at its own constant deceleration, as g/f motion in
 * the segment's own loop; docs/FIXED_POINT.md section 8 derives it.
 *
 * In the loop of qs_segment.h, inc = b + 2C2 is what the ideal position
 * (times 2nD) gains over the tick after the next decision, and it changes
 * by db = 2*C1 per tick. A hold keeps the loop and changes only db: a
 * constant deceleration a (steps per tick^2) is db = -2nD*a. First the
 * state is rescaled by k = 2^shift, the largest power of two with
 * k*n <= N_MAX, which refines the quantum of a to 1/(2knD) without a
 * division; then an axis runs until the increment after its decision would
 * be <= 0, and stops there: at rest, within half a step of the ideal. The
 * hold keeps inc rather than b: its stop test is then a sign test. The tick
 * side is qs_hold_tick.h. */
#ifndef QS_HOLD_H
#define QS_HOLD_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_int24.h"
#include "qs_segment.h"

typedef struct {
    /* Tick side, valid while moving != 0; in the scale 2knD. */
    qs_i24 h[QS_AXIS_COUNT];
    qs_i24 inc[QS_AXIS_COUNT];   /* h gains it after the next decision */
    qs_i24 db[QS_AXIS_COUNT];    /* -max(1, floor(2knD * decel)) */
    qs_i24 two_c2;               /* 2knD: h loses it with a step */
    volatile uint8_t moving;     /* bit i: axis i still decelerates */
    uint8_t tick_byte;           /* moves on with each tick of a hold: for watchers */
    uint8_t moving_at_freeze;    /* the axes still moving when an alarm froze the engine */
    /* Main loop side: the segment length the plan is for (0: none). */
    uint16_t planned_n;
    uint8_t shift;
    uint8_t bits_k;              /* 2^(shift mod 8): the rescale's multiplier */
    /* A trigger's hold predicted in its window (qs_hold_predict): inc is
     * set already for a hold begun in this slot with this count left. */
    const qs_segment *predicted_slot; /* 0: none */
    uint16_t predicted_left;
    uint8_t predicted_moving;
} qs_hold;

/* A cubic segment's hold runs in the scale 2^22 = 2*512*D: planned as for
 * a quadratic segment of 512 ticks (k = 1), so that one closed form serves
 * both (PROTOCOL.md section 8.1). */
#define QS_HOLD_CUBIC_N 512
#define QS_HOLD_CUBIC_SHIFT 9 /* 2^31 / 2^22 */

/* log2 k: the largest shift with (n << shift) <= QS_N_MAX, 1 <= n <= N_MAX. */
uint8_t qs_hold_shift(uint16_t n);

/* db for a deceleration of decel * 2^-24 step per tick^2 in the scale
 * 2*kn*D: -floor(kn * decel / 2^11), but at least one quantum. */
qs_i24 qs_hold_db(uint16_t kn, uint16_t decel);

/* Everything that depends only on the segment length n and the
 * decelerations (decel[axis] for every axis the engine has), and the
 * counts set to 0: the least left for the lock. Main loop, before the hold
 * tick, while moving == 0. */
void qs_hold_plan(qs_hold *hd, uint16_t n, const uint16_t *decel);

/* At the hold tick, with the tick locked out: take over the running state
 * of s (planned for s->n) after t < n of its ticks, or after all n (at_end:
 * the hold's first tick then runs at the speed the segment ended with),
 * rescaled. Returns the axes that move (an axis whose next increment is 0
 * is at rest already); setting moving, which starts the tick on the hold,
 * is the caller's. */
uint8_t qs_hold_begin(qs_hold *hd, const qs_segment *s, uint8_t at_end);

/* In a trigger's window, a few decisions before its hold begins (the tick,
 * with the plan made for s): the increments a hold begun `decisions`
 * decisions on in the quadratic slot s will start from (b gains db with
 * each), set in inc now, so that the tick that begins it rescales h alone
 * (qs_hold_begin_predicted), with `left` of the slot's count then to go.
 * qs_hold_plan drops a prediction. */
void qs_hold_predict(qs_hold *hd, const qs_segment *s, uint8_t decisions, uint16_t left);

/* Whether the hold beginning now in s, with `left` of its count to go, is
 * the one predicted. */
static inline uint8_t qs_hold_is_predicted(const qs_hold *hd, const qs_segment *s, uint16_t left)
{
    return s == hd->predicted_slot && left == hd->predicted_left;
}

/* qs_hold_begin for the predicted hold: the positions h rescaled. */
uint8_t qs_hold_begin_predicted(qs_hold *hd, const qs_segment *s);

/* Where a hold began: its state then, from which qs_hold_axis_made counts
 * its ticks and steps, so that the tick counts neither. */
typedef struct {
    qs_i24 h[QS_AXIS_COUNT];
    qs_i24 inc[QS_AXIS_COUNT];
    uint8_t axes; /* the axes that moved */
} qs_hold_origin;

/* Where the hold begun in slot s (at its end: at_end) began, worked out
 * again from the slot, which stays as it was until the hold is folded.
 * Main loop. */
void qs_hold_origin_of(const qs_hold *hd, const qs_segment *s, uint8_t at_end, qs_hold_origin *o);

/* The steps an axis has made in the hold begun at o, from its h and inc now
 * and the axes still moving (the hold's own, or a snapshot of them); *ticks
 * rises to the ticks the hold has run if this axis has run more. Main
 * loop: a few divisions. */
uint32_t qs_hold_axis_made(const qs_hold *hd, const qs_hold_origin *o, uint8_t axis, qs_i24 h, qs_i24 inc,
                           uint8_t moving, uint32_t *ticks);

#endif
