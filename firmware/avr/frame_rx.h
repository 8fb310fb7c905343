/* qs_frame_rx_copy (qs_frame.h) written out for the AVR: the receive
 * loop's per-byte work, about 12 cycles a byte against the compiler's 22.
 * Same contract and results; the core's C form is the reference (the
 * emulator's, and tests/simavr/avr/forms_check.c holds the two
 * together on random runs). */
#ifndef QS_FRAME_RX_AVR_H
#define QS_FRAME_RX_AVR_H

#include <stdint.h>

#include "qs_frame.h"

_Static_assert(QS_FRAME_WIRE_MAX >= 1 && QS_FRAME_WIRE_MAX <= 255, "room counts in a byte");

static inline __attribute__((always_inline)) uint8_t frame_rx_copy(qs_frame_rx *rx, const uint8_t *bytes,
                                                                   uint8_t len)
{
    uint8_t *to = rx->buf + rx->len;
    uint8_t room = (uint8_t)(QS_FRAME_WIRE_MAX - rx->len);
    const uint8_t clean = (uint8_t)!(rx->too_long | rx->overrun);
    uint8_t left = len, full = 0;

    if (!len)
        return 0;
    __asm__ __volatile__(
        "1:\n\t"
        "ld __tmp_reg__, X+\n\t"
        "tst __tmp_reg__\n\t"
        "breq 3f\n\t"
        "tst %[room]\n\t"
        "breq 4f\n\t"
        "st Z+, __tmp_reg__\n\t"
        "dec %[room]\n"
        "2:\n\t"
        "dec %[left]\n\t"
        "brne 1b\n\t"
        "rjmp 5f\n"
        "4:\n\t" /* no room: the frame is too long */
        "ldi %[full], 1\n\t"
        "rjmp 2b\n"
        "3:\n\t" /* a delimiter: an empty frame's is taken, else it ends the run */
        "cpi %[room], %[max]\n\t"
        "brne 6f\n\t"
        "tst %[clean]\n\t"
        "brne 2b\n"
        "6:\n\t"
        "sbiw r26, 1\n"
        "5:"
        : "+x"(bytes), "+z"(to), [room] "+d"(room), [left] "+r"(left), [full] "+d"(full)
        : [clean] "r"(clean), [max] "n"(QS_FRAME_WIRE_MAX)
        : "memory");
    rx->len = (uint8_t)(QS_FRAME_WIRE_MAX - room);
    if (full)
        rx->too_long = 1;
    return (uint8_t)(len - left);
}

#endif
