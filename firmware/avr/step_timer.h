/* Timer1 tick: one interrupt per motion tick that pulses the step pins. */
#ifndef QS_STEP_TIMER_H
#define QS_STEP_TIMER_H

#include <avr/io.h>

void step_timer_init(void);

/* While nothing moves the tick rests (step_timer.c): Timer1's compare B,
 * matched at the same count as A, runs a tick of a few cycles that only
 * looks for a received byte or an input's change. This ends the rest, with
 * interrupts off: the next match runs the whole tick, as it would have.
 * A match that fell due meanwhile set both flags (B's unserved): A's then
 * runs at once; else A's flag is stale (the resting ticks served every
 * match so far) and goes. A match between that look and the clear would
 * lose its tick, so both happen away from a match: a wake in the last
 * cycles of a tick, or the first few of the next, waits them out. */
#define STEP_TIMER_WAKE_BEFORE_MATCH 32 /* cycles: the last look at the count to the clear, 18 */
#define STEP_TIMER_WAKE_AFTER_MATCH 8   /* cycles: the flags are up by then */
static inline __attribute__((always_inline)) void step_timer_wake(void)
{
    if (TIMSK1 & _BV(OCIE1B)) {
        uint16_t count;
        do
            count = TCNT1;
        while (count < STEP_TIMER_WAKE_AFTER_MATCH || OCR1A - count < STEP_TIMER_WAKE_BEFORE_MATCH);
        if (!(TIFR1 & _BV(OCF1B)))
            TIFR1 = _BV(OCF1A);
        TIMSK1 = _BV(OCIE1A);
    }
}

/* Set by the tick when it begins to rest or runs whole from the resting
 * tick: there may be work for the main loop. The main loop clears it before
 * it looks. */
extern volatile uint8_t step_timer_woke;

/* Whether the resting tick runs the ticks. */
static inline __attribute__((always_inline)) uint8_t step_timer_resting(void)
{
    return TIMSK1 & _BV(OCIE1B);
}

#endif
