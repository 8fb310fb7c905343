/* The two wide sums of one axis over a cubic segment, the main loop's
 * per-segment arithmetic (qs_cubic.c; docs/CUBIC.md derives them), and
 * what the second leaves in the slot and the chain:
 *
 *   last  = I(n) = i + (n-1)*d + C(n-1, 2)*r
 *   twice = 2*(e + Sigma/2) + n*(i + I(n)) - C(n, 3)*r
 *
 * (twice is 2*(e + Sigma/2 + X(n)), X(n) the travel: the trapezoid
 * n*(I(1) + I(n))/2 less the curvature C(n, 3)*r/2.) Both are kept modulo
 * 2^48: a valid segment's values are below 2^47, and for one whose advance
 * per tick is out of range last still shows it (|last| < 2^47 whatever the
 * fields). i and I(n) are at most Sigma when twice is asked for.
 *
 * firmware/core/qs_cubic_sums.c has the portable versions of these
 * functions (the host build's, and the reference); on the AVR,
 * firmware/avr/cubic_sums.c has them written out with the 8 x 8-bit
 * multiplier, which avr-gcc 5.4 does not use well for sums wider than 32
 * bits (tests/simavr/test_avr_forms.py holds the two together). */
#ifndef QS_CUBIC_SUMS_H
#define QS_CUBIC_SUMS_H

#include <stdint.h>

#include "qs_config.h"
#include "qs_cubic.h"
#include "qs_segment.h"
#include "qs_wide.h"

typedef struct {
    /* the axis */
    uint32_t i;     /* the advance over the segment's first tick */
    int32_t d;      /* its change per tick (24 bits, sign-extended) */
    int16_t r;      /* the segment's jerk */
    uint32_t ahead; /* e + Sigma/2, 0 ... Sigma */
    /* the segment's counts */
    uint16_t n;
    uint16_t n_less; /* n - 1 */
    uint32_t c2_less; /* C(n-1, 2) */
    qs_w48 c3;        /* C(n, 3) */
    /* the sums */
    qs_w48 last;
    qs_w48 twice;
    int32_t nr; /* n*r: the change of d over the segment */
} qs_cubic_terms;

/* The chain's end state of every axis, laid out as qs_cubic_chain begins,
 * so that a valid segment's ends move into the chain in one copy. */
typedef struct {
    int32_t e[QS_AXIS_COUNT];
    uint32_t i[QS_AXIS_COUNT];
    int32_t d[QS_AXIS_COUNT];
} qs_cubic_ends;

/* The axis's start from the chain (or from m's state set: a set that turns
 * the axis round measures the error the other way) and its jerk: i, d, r
 * and ahead. */
void qs_cubic_load(qs_cubic_terms *t, const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis);

/* What qs_cubic_check finds (0: the axis fails; else these bits). */
#define QS_CUBIC_VALID 1   /* its acceleration fits (|d| < 2^23 at both ends), 0 <= i <= Sigma */
#define QS_CUBIC_MOVING 2  /* not at rest (i, d or r nonzero) */
#define QS_CUBIC_CURVED 4  /* d or r nonzero: last is needed */
#define QS_CUBIC_EXTREME 8 /* I(k) has an extreme inside the segment, to be checked too */

/* nr, and the checks of the axis that need no wide sum. */
uint8_t qs_cubic_check(qs_cubic_terms *t);

/* last, from the axis and the counts; returns whether 0 <= last <= Sigma. */
uint8_t qs_cubic_last(qs_cubic_terms *t);

/* For an axis that passed every check (0 <= i, last <= Sigma; nr set):
 * twice, then from it and the terms the axis's fields of the slot (its
 * running state, steps and flags) and its end state (e, I(n+1), d + nr)
 * in end. */
void qs_cubic_finish(qs_cubic_terms *t, qs_segment *slot, uint8_t axis, qs_cubic_ends *end);

#endif
