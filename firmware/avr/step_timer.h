/* Timer1 tick: one interrupt per motion tick that pulses the step pins. */
#ifndef QS_STEP_TIMER_H
#define QS_STEP_TIMER_H

void step_timer_init(void);

#endif
