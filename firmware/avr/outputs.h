/* The spindle (or laser) PWM, its direction and the coolant pins. */
#ifndef QS_OUTPUTS_AVR_H
#define QS_OUTPUTS_AVR_H

#include <avr/io.h>

/* Timer2 in fast PWM at 16 MHz / 64 / 256 = 976.6 Hz (GRBL's spindle
 * rate), every output off. */
void outputs_init(void);

/* The pins as the core says they should be now (qs_core_outputs). */
void outputs_update(void);

/* From the main loop: once per PWM period (Timer2's overflow flag), the
 * update; otherwise one bit test. The step interrupt never does this work. */
static inline void outputs_poll(void)
{
    if (TIFR2 & _BV(TOV2))
        outputs_update();
}

#endif
