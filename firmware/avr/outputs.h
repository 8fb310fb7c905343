/* The spindle (or laser) PWM, its direction and the coolant pins. */
#ifndef QS_OUTPUTS_AVR_H
#define QS_OUTPUTS_AVR_H

/* Timer2 in fast PWM at 16 MHz / 64 / 256 = 976.6 Hz (GRBL's spindle
 * rate), every output off. */
void outputs_init(void);

/* Once per PWM period (Timer2's overflow flag), from the main loop: the
 * pins as the core says they should be now (qs_core_outputs). The step
 * interrupt never does this work. */
void outputs_poll(void);

#endif
