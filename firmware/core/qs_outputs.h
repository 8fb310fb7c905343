/* The spindle (or laser) and coolant outputs (PROTOCOL.md section 5.5).
 *
 * An OUTPUTS message takes effect in stream order: every segment queued
 * after it carries it (an index into a small ring of settings, in three
 * spare bits of the slot), those queued before keep what
 * they carry, and at rest the latest one applies. What the pins should be
 * now — which outputs are on and the duty — is computed from the engine's
 * running state, so a power that follows the speed follows what the axes
 * actually do: the ramps of a segment, a cubic segment, a hold. Nothing
 * here runs in the tick: a target asks at its own pace (the AVR once per
 * PWM period, the emulator every tick) and drives its pins; a RASTER
 * line's pixels are the tick's (qs_raster_tick.h). */
#ifndef QS_OUTPUTS_H
#define QS_OUTPUTS_H

#include <stdint.h>
#include "qs_engine.h"
#include "qs_messages.h"

/* Distinct settings that queued segments can carry at once; one more
 * waits (QUEUE_FULL) until the oldest is no longer queued. Three on a
 * board with a short queue (the Uno's RAM), eight otherwise. */
#ifndef QS_OUTPUT_SETTINGS
#define QS_OUTPUT_SETTINGS (QS_QUEUE_CAPACITY < 16 ? 3 : 8)
#endif

/* An OUTPUTS message kept in 5 bytes: the reference axis in bits 6-7. */
typedef struct {
    uint8_t bits;
    uint16_t power;
    uint16_t speed;
} qs_output_setting;

#define QS_OUT_AXIS_SHIFT 6

typedef struct {
    qs_output_setting setting[QS_OUTPUT_SETTINGS];
    uint8_t latest; /* what segments queued now carry, and what applies at rest */
} qs_outputs;

/* The outputs as the pins should show them. */
typedef struct {
    uint8_t pins;  /* QS_OUT_ON, QS_OUT_REVERSE, QS_OUT_MIST, QS_OUT_FLOOD */
    uint16_t duty; /* the spindle or laser output's duty, 0 ... 65535 (0 when off) */
} qs_output_level;

_Static_assert(QS_OUTPUT_SETTINGS <= 8, "a slot keeps the setting's index in 3 bits");

/* The slot just prepared carries the latest setting. */
static inline void qs_outputs_carry(const qs_outputs *o, qs_segment *slot)
{
    slot->ends_moving = (uint8_t)((slot->ends_moving & QS_ENDS_MOVING) | (o->latest << QS_SLOT_OUTPUTS_SHIFT));
}

static inline uint8_t qs_outputs_carried(const qs_segment *slot)
{
    return (uint8_t)(slot->ends_moving >> QS_SLOT_OUTPUTS_SHIFT);
}

/* Everything off: at reset, and what STOP and every alarm leave. */
void qs_outputs_off(qs_outputs *o);

/* A new latest setting (main loop); 0 when every other entry is carried by
 * a segment still queued or running. */
uint8_t qs_outputs_take(qs_outputs *o, qs_engine *e, const qs_outputs_msg *m);

/* Every setting off: whatever runs, every output is off. */
static inline uint8_t qs_outputs_all_off(const qs_outputs *o)
{
    uint8_t i, bits = 0;

    for (i = 0; i < QS_OUTPUT_SETTINGS; i++)
        bits |= o->setting[i].bits;
    return (uint8_t)((bits & (QS_OUT_ON | QS_OUT_REVERSE | QS_OUT_MIST | QS_OUT_FLOOD)) == 0);
}

/* The level now: the running (or held) segment's setting while moving,
 * the latest when idle, everything off in an alarm. */
void qs_outputs_level(const qs_engine *e, const qs_outputs *o, qs_output_level *out);

/* floor(65536 * num / den), at most 65536, for 0 <= num and 0 < den, with
 * both shifted right together until den fits 16 bits (PROTOCOL.md 5.5). */
uint32_t qs_outputs_ratio(uint32_t num, uint32_t den);

#endif
