/* The firmware core: everything a target runs, in one struct. The target
 * feeds received bytes to qs_core_rx, calls qs_core_poll from its main loop
 * and qs_engine_tick(&core.engine) (qs_engine_tick.h) from its timer
 * interrupt, and provides qs_port.h. */
#ifndef QS_CORE_H
#define QS_CORE_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_engine.h"
#include "qs_frame.h"
#include "qs_inputs.h"
#include "qs_messages.h"
#include "qs_port.h"
#include "qs_outputs.h"
#include "qs_raster.h"

/* The longest report, STATUS_REPORT with every axis, as it goes on the wire:
 * the code byte stuffing needs, type and seq, the payload, CRC, delimiter. */
#define QS_TX_WIRE (1 + 2 + QS_LEN_STATUS_REPORT_HEAD + QS_LEN_STATUS_REPORT_AXIS * QS_AXIS_COUNT + 2 + 1)
_Static_assert(QS_LEN_INPUT_HEAD + QS_LEN_INPUT_AXIS * QS_AXIS_COUNT <= QS_TX_WIRE - 6
                   && QS_LEN_HOLD_DONE_HEAD + QS_LEN_HOLD_DONE_AXIS * QS_AXIS_COUNT <= QS_TX_WIRE - 6
                   && QS_LEN_ALARM_HEAD + QS_LEN_ALARM_AXIS * QS_AXIS_COUNT <= QS_TX_WIRE - 6
                   && QS_LEN_PROBE_MISSED_HEAD + QS_LEN_PROBE_MISSED_AXIS * QS_AXIS_COUNT <= QS_TX_WIRE - 6
                   && QS_LEN_IDENTIFY_REPLY <= QS_TX_WIRE - 6 && QS_LEN_INPUT_STATUS <= QS_TX_WIRE - 6
                   && QS_LEN_ACK <= QS_TX_WIRE - 6 && QS_LEN_ERROR <= QS_TX_WIRE - 6,
               "every report fits the transmit buffer");

typedef struct {
    qs_engine engine;
    qs_inputs inputs;         /* the target sets the inputs it has (qs_inputs_init) */
    qs_frame_rx rx;
    qs_counters counters;
    uint8_t next_seq;         /* the sequenced seq expected next */
    uint8_t axis_count;       /* as reported; at most QS_AXIS_COUNT */
    uint32_t tick_hz;         /* as reported */
    uint16_t space_announced; /* segments_done of the last SPACE ack, mod 65536 as the ACK carries it */
    uint8_t alarm_announced;  /* the current alarm has been reported */
    /* Selective repeat: segments that arrived after a lost frame wait,
     * parsed, in the queue slots they will take, until it comes. */
    uint32_t parked;          /* bit d: the frame parked_seq + d waits in the slot parked_head + d */
    uint8_t parked_seq;
    uint8_t parked_head;
    uint16_t watchdog;        /* WATCHDOG: silence that stops motion, in port clock counts; 0 off */
    uint16_t heard;           /* port clock at the last good frame */
    qs_outputs outputs;       /* the OUTPUTS settings: segments queued from now on carry the latest */
#if QS_RASTER_BYTES
    qs_raster raster;         /* the powers of the RASTER lines queued */
#endif
    uint16_t boot_id;         /* IDENTIFY_REPLY's: the target sets it after qs_core_init, new at each reset */
    uint8_t tx[QS_TX_WIRE];   /* the report being sent, built and sealed in place */
} qs_core;

void qs_core_init(qs_core *c);

/* Narrow the build-time limits at run time (the emulator's options):
 * 1 <= axis_count <= QS_AXIS_COUNT, 1 <= queue_capacity <=
 * QS_QUEUE_CAPACITY. Call right after qs_core_init. Returns 0 if out of
 * range (nothing changed). */
uint8_t qs_core_configure(qs_core *c, uint8_t axis_count, uint8_t queue_capacity, uint32_t tick_hz);

/* A frame's delimiter: check the frame and act on it. */
void qs_core_rx_frame(qs_core *c);

/* The delimiter that ends a frame. A lone one (an empty frame, which hosts
 * send to resynchronise or to idle the line) costs only this test. */
static QS_ALWAYS_INLINE void qs_core_rx_end(qs_core *c)
{
    if (c->rx.len != 0 || c->rx.too_long || c->rx.overrun)
        qs_core_rx_frame(c);
}

/* One received byte; acts when it ends a frame. Every other byte is only
 * stored, here, inline in the target's receive loop. */
static QS_ALWAYS_INLINE void qs_core_rx(qs_core *c, uint8_t byte)
{
    if (byte == 0)
        qs_core_rx_end(c);
    else
        qs_frame_rx_store(&c->rx, byte);
}

/* Received bytes that arrived together: stored up to the first delimiter
 * among them that ends a frame, which is not taken; returns how many were
 * taken. The caller then takes the delimiter itself with qs_core_rx_end.
 * The same as qs_core_rx byte by byte, without a call per byte. */
static inline uint8_t qs_core_rx_copy(qs_core *c, const uint8_t *bytes, uint8_t len)
{
    return qs_frame_rx_copy(&c->rx, bytes, len);
}

/* The target lost received bytes: the frame in progress is rejected. */
void qs_core_rx_overrun(qs_core *c);

/* Deferred work: SPACE acks for completed segments, ALARM reports raised
 * by the tick, the HOLD_DONE of a hold the tick finished, the inputs'
 * latches (EVENT INPUT), holds and ends of armed motion. Call often from
 * the main loop (at least whenever queue.tail has changed): with nothing
 * to do it costs a few compares. */
void qs_core_poll_work(qs_core *c);

/* At rest after an underrun's stop with an output on, and the watchdog
 * set: a host takes such a stop up at once, so one silent there is gone,
 * and the spindle or laser must not run on. A target that sleeps at rest
 * keeps looking (qs_core_poll) while this holds. */
static QS_ALWAYS_INLINE uint8_t qs_core_watching_at_rest(const qs_core *c)
{
    return c->watchdog && c->engine.state == QS_STATE_STARVED && !qs_outputs_all_off(&c->outputs);
}

/* No good frame for longer than the watchdog allows, while moving or
 * watching at rest (the alarm switches every output off). */
static QS_ALWAYS_INLINE uint8_t qs_core_host_silent(const qs_core *c)
{
    return c->watchdog && (c->engine.state == QS_STATE_RUNNING || qs_core_watching_at_rest(c))
           && (uint16_t)(qs_port_clock() - c->heard) > c->watchdog;
}

static QS_ALWAYS_INLINE void qs_core_poll(qs_core *c)
{
    const qs_engine *e = &c->engine;

    if (e->queue.retired != e->queue.tail || (uint16_t)e->segments_done != c->space_announced
        || (e->alarm != QS_ALARM_NONE && !c->alarm_announced) || e->hold_report || e->frozen
        || qs_engine_latch_waiting(e) || c->inputs.hold_request || e->resequence
        || (e->trigger && e->state == QS_STATE_IDLE) || qs_core_host_silent(c))
        qs_core_poll_work(c);
}

/* A consistent snapshot of what STATUS_REPORT carries. */
void qs_core_status(qs_core *c, qs_status *st);

/* The spindle, laser and coolant outputs as the pins should show them now
 * (qs_outputs.h); main loop, at the target's own pace. A RASTER's pixel
 * (qs_raster_level): the tick's where it switches them, else the one under
 * the axis `ahead` ticks from now. */
static inline void qs_core_outputs(qs_core *c, qs_output_level *out, uint16_t ahead)
{
    qs_outputs_level(&c->engine, &c->outputs, out);
#if QS_RASTER_BYTES
    qs_raster_level(&c->raster, &c->engine, out, ahead);
#else
    (void)ahead;
#endif
}

#endif
