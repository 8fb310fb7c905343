/* The per-tick input sample, inlined into the tick (qs_inputs.h). A
 * target with pins of its own replaces it by reading them
 * (firmware/avr/inputs_tick.h); the emulator passes the simulated
 * machine's levels. */
#ifndef QS_INPUTS_TICK_H
#define QS_INPUTS_TICK_H

#include "qs_inputs.h"

/* raw: bit i is input i's pin level (1 high), bits of absent inputs 0;
 * *seen: the caller's last sample, QS_INPUTS_RESAMPLE at first (and after
 * qs_inputs_configure). Call before qs_engine_tick, so that a change seen
 * now acts on the tick's decisions: the latched positions are those after
 * the previous tick's steps, and a freeze leaves no step after them. */
static QS_ALWAYS_INLINE void qs_inputs_tick(qs_inputs *in, qs_engine *e, uint16_t *seen, uint16_t raw)
{
    if (QS_UNLIKELY(raw != *seen))
        *seen = qs_inputs_update(in, e, raw) ? QS_INPUTS_RESAMPLE : raw;
}

#endif
