/* The step engine: runs queued segments one tick at a time (the loop of
 * qs_segment.h) and keeps exact step positions. The tick is in
 * qs_engine_tick.h so that it compiles into the timer interrupt; it does
 * 24-bit work only. The 32-bit bookkeeping (positions, tick and segment
 * totals) is done by the main loop when it retires finished slots. */
#ifndef QS_ENGINE_H
#define QS_ENGINE_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_protocol.h"
#include "qs_queue.h"

typedef struct {
    qs_queue queue;
    /* Tick side. */
    qs_segment *seg;          /* the running slot, valid while left > 0 */
    uint16_t left;            /* ticks left in it; 0 between segments */
    uint8_t dir_bits;         /* bit i: axis i's pending steps are negative */
    volatile uint8_t state;   /* QS_STATE_* */
    volatile uint8_t alarm;   /* QS_ALARM_*, nonzero only in ALARM */
    uint8_t ends_moving;      /* the last finished segment left an axis moving */
    /* Main loop side: totals over retired slots. */
    int32_t base[QS_AXIS_COUNT];
    uint32_t completed_ticks;
    uint32_t segments_done;
} qs_engine;

/* What a status report needs, taken at one instant. */
typedef struct {
    uint8_t state;
    uint8_t alarm;
    uint8_t queue_fill;
    uint32_t segments_done;
    uint32_t motion_ticks;
    int32_t position[QS_AXIS_COUNT];
} qs_engine_view;

void qs_engine_init(qs_engine *e, uint8_t queue_capacity);

/* Fold the slots the tick has finished into the totals and free them. */
void qs_engine_retire(qs_engine *e);

/* A segment was published: leave IDLE so the next tick starts it. */
void qs_engine_wake(qs_engine *e);

/* Stop at once (no deceleration): count the steps made, flush the queue,
 * enter state with alarm (QS_ALARM_NONE for IDLE). */
void qs_engine_halt(qs_engine *e, uint8_t state, uint8_t alarm);

/* Set the positions of the axes in mask (below QS_AXIS_COUNT), all or
 * none: only when IDLE with an empty queue. Returns 0 when refused. */
uint8_t qs_engine_set_positions(qs_engine *e, uint8_t mask, const int32_t *position);

void qs_engine_read(qs_engine *e, qs_engine_view *v);

/* Speed numerator of an axis of the running segment times 2n (see
 * qs_segment_speed_2n), 0 between segments: where a controlled
 * deceleration would start from. Call with the tick locked out. */
int32_t qs_engine_speed_2n_locked(const qs_engine *e, uint8_t axis);

#endif
