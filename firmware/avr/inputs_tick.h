/* The tick's input sample, written out for the AVR (qs_inputs.h): both
 * input ports read, masked and compared with the last sample, in 13
 * cycles on the Uno when nothing changed. Only a change (or an open
 * debounce window, which makes the last control sample 0xFF, a value no
 * masked sample takes) calls the rare path, inputs.c, as C: the call is
 * made inside the asm, with every call-clobbered register the interrupt
 * does not save pushed around it there, so that the interrupt's prologue
 * (run every tick) saves no more than before. */
#ifndef QS_INPUTS_TICK_AVR_H
#define QS_INPUTS_TICK_AVR_H

#include <avr/io.h>
#include <stdint.h>

#include "board.h"

/* The last samples of the two ports (the general-purpose I/O registers,
 * one cycle faster, are taken: step_timer.c, uart.h). */
extern volatile uint8_t inputs_seen_limits;
extern volatile uint8_t inputs_seen_control;

/* The rare path (inputs.c); called only from the asm below. */
void inputs_changed(void);

static inline __attribute__((always_inline)) void inputs_tick(void)
{
    uint8_t x;

    __asm__ __volatile__(
        QS_LIMIT_PIN_READ "\n\t"
        "andi %[x], %[limit_mask]\n\t"
        "lds __tmp_reg__, %[seen_limits]\n\t"
        "cp %[x], __tmp_reg__\n\t"
        "brne 1f\n\t"
        QS_CONTROL_PIN_READ "\n\t"
        "andi %[x], %[control_mask]\n\t"
        "lds __tmp_reg__, %[seen_control]\n\t"
        "cp %[x], __tmp_reg__\n\t"
        "breq 2f\n"
        "1:\n\t"
        "push r18\n\tpush r19\n\tpush r20\n\tpush r21\n\tpush r22\n\tpush r23\n\t"
        "push r24\n\tpush r25\n\tpush r26\n\tpush r27\n\tpush r30\n\tpush r31\n\t"
        "call inputs_changed\n\t"
        "pop r31\n\tpop r30\n\tpop r27\n\tpop r26\n\tpop r25\n\tpop r24\n\t"
        "pop r23\n\tpop r22\n\tpop r21\n\tpop r20\n\tpop r19\n\tpop r18\n"
        "2:"
        : [x] "=&d"(x)
        : [limit_pin] QS_LIMIT_PIN_ADDR, [control_pin] QS_CONTROL_PIN_ADDR,
          [limit_mask] "M"(QS_LIMIT_MASK), [control_mask] "M"(QS_CONTROL_MASK),
          [seen_limits] "i"(&inputs_seen_limits), [seen_control] "i"(&inputs_seen_control)
        : "memory");
}

#endif
