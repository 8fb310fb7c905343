/* Latches: where every axis was, exactly, at the tick an input changed.
 *
 * The tick counts no steps (the main loop recovers them from the closed
 * form), so at an input's edge the tick takes a snapshot of what the
 * running or held slot has done (a few bytes, qs_progress) and the slot's
 * place in the queue. The main loop turns the snapshot into positions when
 * its retirement reaches that slot (its base then holds the positions at
 * the slot's start) and before it folds the slot, so a latch is exact
 * however late the main loop gets to it. Entries are a small ring: the
 * tick fills them, the main loop resolves, reports and frees them. */
#ifndef QS_LATCH_H
#define QS_LATCH_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_int24.h"
#include "qs_segment.h"

/* What the running or held slot has done, in a few bytes. */
typedef struct {
    const qs_segment *seg; /* 0: between segments or at rest */
    uint16_t t;            /* ticks of it run (before the hold, if held) */
    uint8_t held;
    union {
        qs_i24 b[QS_AXIS_COUNT]; /* running quadratic: its b after t ticks */
        struct {                 /* held: the hold's state (qs_hold_axis_made) */
            qs_i24 h[QS_AXIS_COUNT];
            qs_i24 inc[QS_AXIS_COUNT];
            uint8_t moving;
        } hold;
        struct {                 /* running cubic: its state after t ticks */
            uint32_t h[QS_AXIS_COUNT];
            uint32_t b[QS_AXIS_COUNT];
            qs_i24 q[QS_AXIS_COUNT];
        } c;
    } at;
} qs_progress;

/* Ring entry states. The tick moves FREE to TENTATIVE or CONFIRMED and
 * TENTATIVE to CONFIRMED or DISCARDED; the main loop moves CONFIRMED and
 * DISCARDED back to FREE. Each side writes only its own transitions. */
#define QS_LATCH_FREE 0
#define QS_LATCH_TENTATIVE 1 /* taken at an edge still being debounced */
#define QS_LATCH_CONFIRMED 2
#define QS_LATCH_DISCARDED 3 /* the edge was a glitch */

#ifndef QS_LATCH_RING
#define QS_LATCH_RING 2
#endif

typedef struct {
    union {
        qs_progress progress; /* tick: the snapshot */
        struct {              /* main loop: resolved from it */
            uint32_t tick;
            int32_t position[QS_AXIS_COUNT];
        } at;
    } u;
    uint16_t active;  /* inputs active once this change is accepted */
    uint16_t changed; /* inputs that changed */
    uint8_t slot;     /* queue index of the slot the snapshot is of */
    uint8_t cause;    /* QS_CAUSE_* (qs_inputs.h): what the firmware did */
    uint8_t resolved; /* main loop: u.at holds the positions */
    volatile uint8_t state;
} qs_latch;

typedef struct {
    qs_latch entry[QS_LATCH_RING];
    volatile uint8_t next; /* tick: the entry the next edge takes */
    volatile uint8_t taken; /* tick: latches taken (mod 256), for a debugger to time them */
    uint8_t oldest;        /* main loop: the oldest entry not yet freed */
    uint16_t lost;         /* edges with no free entry (saturates) */
} qs_latch_ring;

#endif
