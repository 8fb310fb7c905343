/* Timer1 tick: one interrupt per motion tick that pulses the step pins and
 * serves the USART.
 *
 * Each tick: raise the step pins decided by the previous tick (their
 * direction pins are already set), serve the USART, sample the inputs
 * (inputs_tick.h), run the engine for the
 * next decisions, hold the pulse to its minimum width, lower the step pins,
 * then set the direction pins the new decisions need. So a direction pin
 * never changes during a pulse and always settles a whole tick before the
 * step it governs. */
#include "step_timer.h"

#include <avr/interrupt.h>
#include <avr/io.h>

#include "board.h"
#include "firmware.h"
#include "outputs.h"
#include "uart.h"

#ifndef QS_STEP_PULSE_US
#define QS_STEP_PULSE_US 2
#endif

#define CYCLES_PER_US (F_CPU / 1000000UL)
#define TICK_CYCLES (F_CPU / (QS_TICK_HZ))
#define PULSE_CYCLES ((uint8_t)(CYCLES_PER_US * (QS_STEP_PULSE_US)))

/* Motion port value for the next tick: the step pins it raises and the
 * direction pins already set for them. Kept in a general-purpose I/O
 * register, which `in`/`out` reach in one cycle. */
#define next_pins GPIOR0
/* Timer1's count when this tick's pulse went out, parked in another such
 * register so it holds no CPU register across the engine's work. */
#define pulse_start GPIOR1

/* Hold the step pins up until the pulse is QS_STEP_PULSE_US long (Timer1's
 * count). The low byte alone repeats every 256 cycles; a tick that has run
 * past that (TCNT1H, latched as TCNT1L is read, is not 0) waits for
 * nothing. */
#define HOLD_PULSE()                                                                                          \
    do {                                                                                                      \
        if (QS_STEP_PULSE_US > 0 && (next_pins & QS_STEP_PINS)) {                                              \
            while ((uint8_t)(TCNT1L - pulse_start) < PULSE_CYCLES && !TCNT1H) {                               \
            }                                                                                                 \
        }                                                                                                     \
    } while (0)

/* A running segment's decisions take longer than the shortest pulse: from
 * reading pulse_start to the falling edge, a quadratic tick of one axis at
 * a steady speed takes over 50 cycles (the tests measure every pulse from
 * the pin edges). So only the ticks that run none (between segments, idle,
 * a hold) look at the timer; with a longer pulse, every tick does. */
#define PULSE_OUTLASTED_BY_DECISIONS (F_CPU / 1000000UL * (QS_STEP_PULSE_US) <= 40)
#if PULSE_OUTLASTED_BY_DECISIONS
#define QS_ENGINE_UNDECIDED() HOLD_PULSE()
#endif

/* At rest: in a tick that finds the engine with nothing to do, with no
 * byte left to send and no input changed or being debounced, hand the next
 * ticks to compare B (the resting tick, below). Its flag is stale (set at
 * every match while A ran): cleared first. Not if the next match has come
 * already (this tick ran long, as one that takes an input's latch can): A's
 * flag holds it, and A serves it; A's flag is looked at again after B's is
 * cleared, as a match between the two would leave only A's up. The rest
 * ends in the resting tick (a byte received, an input changed) or by
 * step_timer_wake. The resting tick looks for a byte once a tick, the whole
 * one twice where bytes come faster than one a tick (uart.c): so the tick
 * rests only where a tick and the look after the rest end take less than
 * two byte times (the receiver holds two bytes); else (25 kHz at 500000
 * baud, the Mega's default) a byte could come in as the third while two
 * wait, and be lost. */
#define BYTE_CYCLES (F_CPU * 10UL / (QS_BAUD))
#define REST_LOOK_CYCLES 32 /* from the resting tick's match to the whole tick's first look */
#if TICK_CYCLES + REST_LOOK_CYCLES < 2UL * BYTE_CYCLES
#define QS_ENGINE_RESTING()                                                                                   \
    do {                                                                                                      \
        if (!uart_tx_pending && !(PCIFR & QS_INPUT_FLAGS) && !(TIFR1 & _BV(OCF1A))) {                         \
            TIFR1 = _BV(OCF1B);                                                                               \
            if (!(TIFR1 & _BV(OCF1A))) {                                                                      \
                TIMSK1 = _BV(OCIE1B);                                                                         \
                step_timer_woke = 1; /* the main loop looks once more */                                      \
            }                                                                                                 \
        }                                                                                                     \
    } while (0)
#endif

/* axis_tick.h first: it puts the AVR's own per-axis decisions in place of
 * the core's (the QS_*_AXIS_TICK hooks of qs_engine_tick.h). */
#include "axis_tick.h"
#include "inputs_tick.h"
#include "rare_call.h"
#include "qs_engine_tick.h"
#include "qs_raster_tick.h"

/* Direction changes wait this long after the step pins fall (driver hold time). */
#define DIR_HOLD_CYCLES (CYCLES_PER_US)

_Static_assert(F_CPU % (QS_TICK_HZ) == 0, "QS_TICK_HZ must divide F_CPU: the tick rate is exact");
_Static_assert(TICK_CYCLES >= 128 && TICK_CYCLES <= 65536UL, "QS_TICK_HZ out of Timer1's range");
_Static_assert(CYCLES_PER_US * (QS_STEP_PULSE_US) <= 64, "QS_STEP_PULSE_US at most 4 us at 16 MHz");

/* The USART receiver holds two bytes while a third shifts in, so the gap
 * between two looks must stay under two byte times. One look per tick, at
 * its start, does that while at most one byte arrives per tick; up to two,
 * a second look at the end of the tick splits the gap (uart.c refuses more). */
#define UART_LOOKS_TWICE ((QS_BAUD) / 10UL > (QS_TICK_HZ))


volatile uint8_t step_timer_woke;

void step_timer_init(void)
{
    TCCR1A = 0;
    TCCR1B = 0;
    TCNT1 = 0;
    OCR1A = (uint16_t)(TICK_CYCLES - 1UL);
    OCR1B = (uint16_t)(TICK_CYCLES - 1UL); /* the resting tick: the same matches */
    TIFR1 = _BV(OCF1A) | _BV(OCF1B);
    TIMSK1 = _BV(OCIE1A);
    TCCR1B = _BV(WGM12) | _BV(CS10); /* CTC on OCR1A, clock undivided */
}

/* Called from the interrupt's asm only (rare_call.h): kept by `used`. */
__attribute__((used, externally_visible)) void underrun_in_tick(void)
{
    qs_engine_underrun_in_tick(&core.engine);
}

__attribute__((used, externally_visible)) void trigger_split_in_tick(void)
{
    qs_engine_trigger_split_in_tick(&core.engine);
}

#if QS_RASTER_BYTES
__attribute__((used, externally_visible)) void raster_watch_in_tick(void)
{
    qs_raster_watch(&core.raster, &core.outputs, &core.engine);
}

QS_AVR_RARE_TRAMPOLINE(raster_watch_rare, raster_watch_in_tick);
#endif

QS_AVR_RARE_TRAMPOLINE(underrun_rare, underrun_in_tick);
QS_AVR_RARE_TRAMPOLINE(trigger_split_rare, trigger_split_in_tick);

ISR(TIMER1_COMPA_vect)
{
    QS_MOTION_PORT = next_pins; /* rising edges */
    uart_service();
#if QS_STEP_PULSE_US > 0
    pulse_start = TCNT1L; /* a little after the edge: the pulse can only grow */
#endif
    inputs_tick(); /* sees the steps just raised; may freeze or hold before the decisions */

    const uint8_t steps = qs_engine_tick(&core.engine);
#if QS_RASTER_BYTES
    qs_raster_tick(&core.raster, &core.outputs, &core.engine, steps); /* a RASTER's pixels: the laser's PWM */
#endif
    const uint8_t pulse = next_pins; /* what went out above */
    const uint8_t dir_pins = (uint8_t)(core.engine.dir_bits << QS_DIR_SHIFT) & QS_DIR_PINS;
    const uint8_t held_dir = pulse & QS_DIR_PINS;

#if !PULSE_OUTLASTED_BY_DECISIONS
    HOLD_PULSE();
#endif
    QS_MOTION_PORT = held_dir; /* falling edges */
    if (dir_pins != held_dir) {
        __builtin_avr_delay_cycles(DIR_HOLD_CYCLES);
        QS_MOTION_PORT = dir_pins;
    }
    next_pins = (uint8_t)(dir_pins | ((uint8_t)(steps << QS_STEP_SHIFT) & QS_STEP_PINS));
#if UART_LOOKS_TWICE
    uart_service();
#endif
}

#define STRINGIFY_(x) #x
#define STRINGIFY(x) STRINGIFY_(x)

/* The resting tick (compare B, while nothing moves): the whole tick would
 * find nothing to do unless an input's pin-change flag is up or a byte has
 * been received. Then it hands the ticks back to compare A and runs the
 * whole tick now, for this very match, so that a byte or an input is seen
 * at the same tick as without the rest. Otherwise it returns: 23 cycles
 * with the interrupt's entry and exit. SREG is untouched: skips, loads and
 * stores only. The whole tick's ISR is entered by a jump, with this
 * interrupt's return address on the stack, and ends in its own RETI. */
ISR(TIMER1_COMPB_vect, ISR_NAKED)
{
    __asm__ __volatile__(
        "sbic %[pcifr], %[limit_pcif]\n\t"
        "rjmp 1f\n\t"
        "sbic %[pcifr], %[control_pcif]\n\t"
        "rjmp 1f\n\t"
        "push r24\n\t"
        "lds r24, %[ucsra]\n\t"
        "sbrc r24, %[rxc]\n\t"
        "rjmp 2f\n\t"
        "pop r24\n\t"
        "reti\n"
        "1:\n\t"
        "push r24\n"
        "2:\n\t"
        "ldi r24, %[ocf_a]\n\t" /* A's flag is stale: this match is served now */
        "out %[tifr], r24\n\t"
        "ldi r24, %[ocie_a]\n\t"
        "sts %[timsk], r24\n\t"
        "sts %[woke], r24\n\t" /* nonzero: the main loop looks */
        "pop r24\n\t"
        "jmp " STRINGIFY(TIMER1_COMPA_vect)
        :
        : [pcifr] "I"(_SFR_IO_ADDR(PCIFR)), [limit_pcif] "I"(QS_LIMIT_PCIF),
          [control_pcif] "I"(QS_CONTROL_PCIF), [ucsra] "n"(_SFR_MEM_ADDR(UCSR0A)), [rxc] "I"(RXC0),
          [ocf_a] "M"(_BV(OCF1A)), [tifr] "I"(_SFR_IO_ADDR(TIFR1)), [ocie_a] "M"(_BV(OCIE1A)),
          [timsk] "n"(_SFR_MEM_ADDR(TIMSK1)), [woke] "i"(&step_timer_woke));
}
