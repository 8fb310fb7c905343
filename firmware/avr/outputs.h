/* The spindle (or laser) PWM, its direction and the coolant pins. */
#ifndef QS_OUTPUTS_AVR_H
#define QS_OUTPUTS_AVR_H

#include <avr/io.h>

#include "board.h"

/* Timer2 in fast PWM at 16 MHz / 64 / 256 = 976.6 Hz (GRBL's spindle
 * rate), every output off. */
void outputs_init(void);

/* The pins as the core says they should be now (qs_core_outputs). */
void outputs_update(void);

/* From the main loop: once per PWM period (Timer2's overflow flag), the
 * update; otherwise one bit test. The step interrupt does none of it, but
 * for a RASTER line of pixels a period or longer (outputs_laser_power). */
static inline void outputs_poll(void)
{
    if (TIFR2 & _BV(TOV2))
        outputs_update();
}

/* A RASTER's pixel, from the step tick (qs_port_laser_power, written in
 * place there: QS_LASER_POWER in qs_raster_tick.h). The period restarts
 * (TCNT2 at its top: the next count, within 64 cycles, is the bottom,
 * where the buffered OCR2A takes the new duty), so the pixel's power
 * begins at its boundary's decision, not at the end of a period of up to
 * 1 ms. A power of 0 disconnects the pin, which then stays low. */
static inline __attribute__((always_inline)) void outputs_laser_power(uint8_t power)
{
    OCR2A = power;
    if (power) {
        TCCR2A = _BV(COM2A1) | _BV(WGM21) | _BV(WGM20);
        TCNT2 = 0xFF;
    } else {
        TCCR2A = _BV(WGM21) | _BV(WGM20);
        /* low already (the chip's pin follows it at once): written for
         * simulators that show a disconnected pin's level only then */
        QS_PWM_PORT &= (uint8_t)~_BV(QS_PWM_BIT);
    }
}

#define QS_LASER_POWER(power) outputs_laser_power(power)

#endif
