/* The step engine: runs queued segments one tick at a time (the loop of
 * qs_segment.h) and keeps exact step positions. The tick is in
 * qs_engine_tick.h so that it compiles into the timer interrupt; it does
 * 24-bit work only. The 32-bit bookkeeping (positions, tick and segment
 * totals) is done by the main loop when it retires finished slots.
 *
 * A hold (qs_engine_hold) freezes the running slot where it is and
 * decelerates from there in e->hold (qs_hold.h); when every axis is at
 * rest the tick releases the slot, and retiring it folds the segment's
 * steps up to the hold and the hold's own steps into the positions. */
#ifndef QS_ENGINE_H
#define QS_ENGINE_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_cubic.h"
#include "qs_protocol.h"
#include "qs_hold.h"
#include "qs_latch.h"
#include "qs_queue.h"

typedef struct {
    qs_queue queue;
    /* Tick side. */
    qs_segment *seg;          /* the running slot, valid while left > 0 */
    uint16_t left;            /* ticks left in it; 0 between segments */
    uint8_t slow_path;        /* 0: a quadratic segment runs; QS_PATH_CUBIC:
                               * a cubic one; QS_PATH_RASTER: a segment has
                               * just begun that qs_raster_tick.h looks at;
                               * else left == 0 or a hold */
    uint8_t dir_bits;         /* bit i: axis i's pending steps are negative */
    volatile uint8_t state;   /* QS_STATE_* */
    volatile uint8_t alarm;   /* QS_ALARM_*, nonzero only in ALARM */
    uint8_t kept;             /* the slot at tail has finished moving, nothing behind it: kept
                               * for a hold from its end (qs_engine_finish) */
#if QS_RASTER_BYTES
    uint8_t line_lit;         /* a RASTER line's pixels are the tick's (qs_raster_tick.h): the
                               * first tick of every segment is marked for it, not only a line's */
#endif
    /* Main loop side: the cubic chain after the last slot prepared, */
    qs_cubic_chain chain;
    /* and totals over retired slots, */
    int32_t base[QS_AXIS_COUNT];
    /* and the steps of the slots prepared and not yet retired, so that no
     * segment is taken that could carry a position past QS_POSITION_MAX. */
    int32_t pending[QS_AXIS_COUNT];
    uint32_t completed_ticks;
    uint32_t segments_done;
    /* A hold: the tick runs hold instead of seg while hold.moving != 0. */
    qs_hold hold;
    const qs_segment *held;  /* main loop: the frozen slot, until folded */
    uint16_t held_t0;        /* ticks of it run before the hold */
    uint32_t hold_tick;      /* motion tick at which the deceleration began */
    uint32_t hold_end_tick;  /* motion tick at which the last hold ended */
    uint8_t hold_report;     /* a hold has ended and is not yet reported */
    uint8_t hold_alarm;      /* the alarm the running hold ends in (a silent host), or 0 */
    uint8_t hold_starves;    /* the running hold is an underrun's: it ends in STARVED */
    uint8_t holds_begun;     /* holds begun so far (mod 256), for the emulator's event log */
    /* Inputs (qs_inputs.h) act on the engine from the tick: */
    qs_latch_ring latches;   /* exact positions at input edges */
    volatile uint8_t frozen; /* QS_FROZEN_*: the tick stopped everything, the main loop completes it */
    uint8_t trigger;         /* armed (PROBE): an edge of trigger_input to trigger_level holds */
    uint8_t trigger_input;   /* QS_INPUT_* index (qs_inputs.h) */
    uint8_t trigger_level;   /* 1: until it becomes active, 0: until it becomes inactive */
    uint8_t held_by_tick;    /* the hold was begun by the tick: drop the queue when it ends */
    volatile uint8_t resequence; /* the tick ended the stream at a trigger: the core moves next_seq on */
    uint16_t trigger_decel[QS_AXIS_COUNT];
    /* A trigger's window (qs_engine_trigger_in_tick): the motion runs on
     * for QS_TRIGGER_TICKS decisions while its hold is planned, then the
     * hold begins. The window cuts the running segment's count where the
     * rare work is due (left runs out there, trigger_rest ticks of the
     * segment are still to come), so the ticks in between pay nothing. */
    uint8_t trigger_window;  /* 0: no window; else the work due (QS_TRIGGER_PLAN, _PREDICT or _BEGIN) and, in
                              * QS_TRIGGER_WAIT bits, the decisions from the current cut's end to it */
    union {
        uint16_t trigger_since; /* armed: segments_done then (low bits): the armed motion has run once it moves on */
        uint16_t trigger_rest;  /* in a trigger's window (disarmed): ticks of the running segment after the cut */
    };
    /* The decelerations of the holds the firmware begins itself (the feed
     * hold button, an underrun, a silent host): CONFIG's hold_decel. */
    uint16_t stop_decel[QS_AXIS_COUNT];
    uint8_t hold_along;      /* the last hold began with a HOLD_ALONG's path decelerations: its HOLD_DONE says so */
} qs_engine;

#define QS_PATH_CUBIC 2 /* slow_path while a cubic segment runs */
#define QS_PATH_RASTER 4 /* slow_path after the first decision of a RASTER line the tick switches (or of
                          * any segment while one is lit), until qs_raster_tick.h looks */
#if QS_RASTER_BYTES
#define QS_ENGINE_LINE_LIT(e) ((e)->line_lit)
#else
#define QS_ENGINE_LINE_LIT(e) 0
#endif

/* What qs_engine_hold did. */
#define QS_HOLD_STARTED 0    /* decelerating: state HOLDING */
#define QS_HOLD_AT_REST 1    /* nothing was moving: IDLE, a HOLD_DONE is pending */
#define QS_HOLD_UNDER_WAY 2  /* a hold was already running or just finished */
#define QS_HOLD_IN_ALARM 4   /* nothing changed */

#ifndef QS_DEFAULT_STOP_DECEL
#define QS_DEFAULT_STOP_DECEL 256 /* 2^-16 step per tick^2, until CONFIG says */
#endif

/* Positions stay within +-QS_POSITION_MAX (qs_protocol.h) steps before any
 * segment is taken, so that neither the queue behind it (at most 127
 * segments of 65535 steps) nor a hold (at most 2^22 steps) can carry one
 * past 2^31. */

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

/* Fold the slots the tick has finished into the totals and free them.
 * The main loop asks often, and usually there are none: that answer costs
 * a compare here. */
void qs_engine_retire_slots(qs_engine *e);

static QS_ALWAYS_INLINE void qs_engine_retire(qs_engine *e)
{
    if (e->queue.retired != e->queue.tail)
        qs_engine_retire_slots(e);
}

/* A segment was published: leave IDLE so the next tick starts it. */
void qs_engine_wake(qs_engine *e);

/* Stop at once (no deceleration): count the steps made, flush the queue,
 * enter state with alarm (QS_ALARM_NONE for IDLE). */
void qs_engine_halt(qs_engine *e, uint8_t state, uint8_t alarm);

/* Set the positions of the axes in mask (below QS_AXIS_COUNT), all or
 * none: only when IDLE with an empty queue. Returns 0 when refused. */
uint8_t qs_engine_set_positions(qs_engine *e, uint8_t mask, const int32_t *position);

void qs_engine_read(qs_engine *e, qs_engine_view *v);

/* A hold's window opened with QS_PATH_LEFT_MIN decisions or more left in
 * the running slot begins the hold inside that slot (QS_TRIGGER_TICKS on,
 * and each cut before it leaves more than a decision); with fewer, in the
 * next slot, within its first 20 decisions (its work waits for the third,
 * and a plan for its length, then the increments, take 3 more each), so
 * inside it where it lasts QS_PATH_NEXT_MIN ticks; or at the running slot's
 * end where none follows. */
#define QS_PATH_LEFT_MIN (QS_TRIGGER_TICKS + 2)
#define QS_PATH_NEXT_MIN 32

/* Decelerate every moving axis to rest, decel[axis] in 2^-24 step per
 * tick^2 (checked by qs_msg_check_hold), starting at the current tick
 * boundary, and discard the queued segments; with HOLD_ALONG's decelerations
 * (path, or 0) instead where the hold begins in one of its segments. Returns
 * QS_HOLD_*. */
uint8_t qs_engine_hold(qs_engine *e, const uint16_t *decel, const qs_path_hold *path);

/* Whether a segment of n ticks moving the axes in active may be taken:
 * 0 with *axis set to the first axis it could carry past
 * QS_POSITION_MAX. Main loop. */
uint8_t qs_engine_room_for(const qs_engine *e, uint8_t active, uint16_t n, uint8_t *axis);

/* A slot was prepared (before it is published): its steps join pending. */
void qs_engine_note_prepared(qs_engine *e, const qs_segment *s);

/* Whether a hold has ended and is not yet reported, once: returns 1 and its
 * hold_tick, or 0. Until it is taken nothing moves (segments are refused
 * while holding and the core takes it before it handles the next frame),
 * so base and completed_ticks are where and when the hold came to rest. */
static QS_ALWAYS_INLINE uint8_t qs_engine_take_hold_done(qs_engine *e, uint32_t *hold_tick)
{
    qs_engine_retire(e); /* retiring the held slot ends the hold */
    if (!e->hold_report)
        return 0;
    e->hold_report = 0;
    *hold_tick = e->hold_tick;
    return 1;
}

/* ---- what inputs do, from the tick (interrupts off) ---- */

/* A latch entry with a snapshot of the running or held slot taken now, or
 * 0 when the ring is full (counted in latches.lost). The caller fills in
 * active, changed and cause, then sets its state. */
qs_latch *qs_engine_latch_in_tick(qs_engine *e);

/* Stop every axis at this tick: no further step, ALARM with alarm. The
 * running slot stays as it is, so positions stay exact; the main loop
 * completes the halt (qs_engine_finish_freeze). */
void qs_engine_freeze_in_tick(qs_engine *e, uint8_t alarm);

/* The armed trigger fired (its latch is taken): disarm, and if a segment
 * runs or is queued open the trigger's window and return 1: the motion
 * goes on for QS_TRIGGER_TICKS decisions, this tick's included, then a
 * hold begins with the armed decelerations, exactly the hold a HOLD at
 * that tick boundary would begin; the queued segments are dropped when it
 * ends. The window spreads the hold's work so that no tick runs long: its
 * plan after QS_TRIGGER_PLAN_AT decisions, the increments it will begin
 * with after QS_TRIGGER_PREDICT_AT, its beginning at the end. Else
 * (nothing to hold) 0. */
uint8_t qs_engine_trigger_in_tick(qs_engine *e);

/* The window's rare work, from the tick where its cut (or the segment's
 * end) makes left run out (qs_engine_finish), and where a segment begins in
 * it (qs_engine_begin). */
void qs_engine_trigger_split_in_tick(qs_engine *e);

#ifndef QS_TRIGGER_TICKS
#define QS_TRIGGER_TICKS 12
#endif
#define QS_TRIGGER_PLAN_AT (QS_TRIGGER_TICKS / 2)
#define QS_TRIGGER_PREDICT_AT ((QS_TRIGGER_PLAN_AT + QS_TRIGGER_TICKS) / 2)
#define QS_TRIGGER_PLAN 0x40    /* trigger_window: the hold's plan is due */
#define QS_TRIGGER_BEGIN 0x80   /* the hold's beginning is due */
#define QS_TRIGGER_PREDICT 0xC0 /* its increments, for the tick that begins it (qs_hold_predict) */
#define QS_TRIGGER_WAIT 0x3F
_Static_assert(QS_TRIGGER_TICKS <= QS_TRIGGER_WAIT, "a window's length fits its count");

/* The queue ran dry after a segment that ends moving (in the tick, out of
 * line: QS_ENGINE_UNDERRUN): every moving axis decelerates from where it
 * ended, at stop_decel, and the hold ends in STARVED, with its HOLD_DONE;
 * if nothing would move, it is a hold of no ticks at the segment's end,
 * ending so too. */
void qs_engine_underrun_in_tick(qs_engine *e);

/* STARVED becomes IDLE (the host's HOLD takes the motion up again), and an
 * underrun's stop still under way will end IDLE; any other state stays.
 * Main loop. */
void qs_engine_end_starved(qs_engine *e);

/* ---- main loop ---- */

/* Arm (decel per axis, as qs_msg_check_hold accepts) or disarm the
 * trigger. HOLD and STOP disarm it too. */
void qs_engine_arm_trigger(qs_engine *e, uint8_t input, uint8_t level, const uint16_t *decel);
void qs_engine_disarm_trigger(qs_engine *e);

#define QS_FROZEN_ALARM 1   /* an alarm: flush, the alarm stays */
#define QS_FROZEN_AT_REST 2 /* a trigger with nothing moving: flush, IDLE, HOLD_DONE */

void qs_engine_finish_freeze_slow(qs_engine *e);

/* The tick froze the engine: flush the queue and settle. */
static QS_ALWAYS_INLINE void qs_engine_finish_freeze(qs_engine *e)
{
    if (e->frozen)
        qs_engine_finish_freeze_slow(e);
}

/* The oldest latch, confirmed and resolved to positions (u.at), or 0 when
 * there is none yet; qs_engine_free_latch lets it go once reported. */
const qs_latch *qs_engine_oldest_latch(qs_engine *e);
void qs_engine_free_latch(qs_engine *e);

static QS_ALWAYS_INLINE uint8_t qs_engine_latch_waiting(const qs_engine *e)
{
    /* a ring of one (the Uno's) has its oldest entry at 0 always: no index
     * to multiply out on every look of the main loop */
    return e->latches.entry[QS_LATCH_RING == 1 ? 0 : e->latches.oldest].state != QS_LATCH_FREE;
}

/* Speed numerator of an axis of the running segment times 2n (see
 * qs_segment_speed_2n), 0 between segments and during a hold. Call with
 * the tick locked out. */
int32_t qs_engine_speed_2n_locked(const qs_engine *e, uint8_t axis);

#endif
