/* The tick's input sample, written out for the AVR (qs_inputs.h). Every
 * input pin is masked into its port's pin-change flag (the pin-change
 * interrupts themselves stay off), which the hardware sets on any change:
 * the tick looks only at the flags, 3 cycles when nothing changed. A
 * change calls the rare path (inputs.c) as C: the call is made inside the
 * asm, with every call-clobbered register the interrupt does not save
 * pushed around it there, so that the interrupt's prologue (run every
 * tick) saves no more than before. While a debounce window is open the
 * rare path leaves the flags set, so the next tick comes back. */
#ifndef QS_INPUTS_TICK_AVR_H
#define QS_INPUTS_TICK_AVR_H

#include <avr/io.h>
#include <stdint.h>

#include "board.h"

/* The rare path (inputs.c): reads the pins, acts, clears the flags. */
void inputs_changed(void);

/* The flags of pins not masked in never rise: PCIFR is 0 unless an input
 * changed. In the common case `in` and a `cpse` that skips the jump: 3
 * cycles. The rare block sits out of the way, at the end of the
 * interrupt's section (.subsection 1), and jumps back. */
static inline __attribute__((always_inline)) void inputs_tick(void)
{
    uint8_t x;

    __asm__ __volatile__(
        "in %[x], %[flags]\n\t"
        "cpse %[x], __zero_reg__\n\t"
        "rjmp 1f\n"
        "2:\n\t"
        ".subsection 1\n"
        "1:\n\t"
        "push r18\n\tpush r19\n\tpush r20\n\tpush r21\n\tpush r22\n\tpush r23\n\t"
        "push r24\n\tpush r25\n\tpush r26\n\tpush r27\n\tpush r30\n\tpush r31\n\t"
        "call inputs_changed\n\t"
        "pop r31\n\tpop r30\n\tpop r27\n\tpop r26\n\tpop r25\n\tpop r24\n\t"
        "pop r23\n\tpop r22\n\tpop r21\n\tpop r20\n\tpop r19\n\tpop r18\n\t"
        "rjmp 2b\n\t"
        ".subsection 0"
        : [x] "=&r"(x)
        : [flags] "I"(_SFR_IO_ADDR(PCIFR))
        : "memory");
}

#endif
