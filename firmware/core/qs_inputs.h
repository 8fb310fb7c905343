/* The board's inputs: limit switches, the probe and the control buttons
 * (abort, feed hold, cycle start), sampled once per tick.
 *
 * Every tick the target compares its raw pin levels with the last sample
 * (qs_inputs_tick.h; the AVR reads its pins in a few instructions,
 * firmware/avr/inputs_tick.h); only when they differ, or while a debounce
 * window is open, does it call qs_inputs_update, the rare path, still in
 * the tick. There each input's level becomes active or inactive by its
 * polarity; a change is accepted at once (debounce 0) or when the input
 * is still changed `debounce` ticks after its first edge, and either way
 * the latch is taken at the first edge's tick (qs_latch.h). What an
 * accepted change does, in the same tick:
 *
 *   abort becomes active              freeze: ALARM E_STOP
 *   the armed input reaches its level a hold begins (the armed PROBE)
 *   a limit becomes active            freeze: ALARM HARD_LIMIT (if enabled)
 *   feed hold becomes active          the main loop begins a HOLD
 *   anything else                     reported only
 *
 * Inputs are numbered as on the wire (PROTOCOL.md, inputs). */
#ifndef QS_INPUTS_H
#define QS_INPUTS_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_engine.h"
#include "qs_protocol.h"

/* Input numbers (QS_INPUT_* in qs_protocol.h): bit i of every input mask. */
#define QS_INPUT_LIMIT QS_INPUT_LIMIT_0         /* + axis: the axis's limit (its min switch, or both on one pin) */
#define QS_INPUT_LIMIT_MAX QS_INPUT_LIMIT_MAX_0 /* + axis: its max switch, where it has a pin of its own */
#define QS_INPUT_COUNT 12
#define QS_INPUT_NONE 0xFF

#define QS_INPUTS_LIMITS 0x00FFu
#define QS_INPUTS_ALL 0x0FFFu

/* What the main loop is asked to do (hold_request). */
#define QS_INPUTS_HOLD_FEED 1    /* feed hold: HOLD at the engine's stop_decel */
#define QS_INPUTS_HOLD_TRIGGER 2 /* the trigger fired with nothing moving: report it at rest */

#define QS_INPUTS_RESAMPLE 0xFFFFu /* `seen` that no sample equals: the next tick looks again */

typedef struct {
    /* Configuration: the main loop writes it with the tick locked out. */
    uint16_t present;      /* inputs this target has */
    uint16_t invert;       /* bit set: active when the pin is high (default: low, a switch to ground) */
    uint16_t enabled;      /* inputs acted on and reported; the others are ignored */
    uint8_t hard_limits;   /* a limit becoming active outside an armed PROBE alarms */
    uint8_t debounce[QS_INPUT_COUNT]; /* ticks an edge must last */
    uint16_t at_once;      /* inputs with debounce 0 */
    /* The tick's side. */
    uint16_t raw;          /* raw levels, bit set: pin high; QS_INPUTS_RESAMPLE before the first sample */
    uint16_t active;       /* accepted states, bit set: active */
    uint16_t window;       /* inputs whose edge is being debounced */
    uint8_t countdown;     /* ticks left in the window */
    uint8_t tentative;     /* the window's latch entry, QS_INPUT_NONE if the ring was full */
    volatile uint8_t hold_request; /* QS_INPUTS_HOLD_*, for the main loop */
} qs_inputs;

void qs_inputs_init(qs_inputs *in, uint16_t present);

/* The rare path, in the tick: the raw levels differ from the last sample
 * or a window is open. Returns nonzero while a window is open (the caller
 * then samples again next tick whatever the pins say). */
uint8_t qs_inputs_update(qs_inputs *in, qs_engine *e, uint16_t raw);

/* Main loop: new settings (checked by the caller), applied at once; the
 * accepted states follow the new polarity without events. */
void qs_inputs_configure(qs_inputs *in, qs_engine *e, uint16_t invert, uint16_t enabled, uint8_t hard_limits,
                         const uint8_t *debounce, const uint16_t *hold_decel);

/* Main loop: the state of one input now (1 active). */
static inline uint8_t qs_inputs_is_active(const qs_inputs *in, uint8_t input)
{
    return (uint8_t)((in->active >> input) & 1u);
}

/* Main loop: a debounce window is open (an edge may still be accepted). */
static inline uint8_t qs_inputs_settling(const qs_inputs *in)
{
    return in->window != 0;
}

#endif
