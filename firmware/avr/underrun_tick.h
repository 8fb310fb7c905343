/* The underrun's hold (QS_ENGINE_UNDERRUN in qs_engine_tick.h), begun from
 * the step interrupt as the inputs' rare path is (inputs_tick.h): the call
 * is made inside the asm, with every call-clobbered register the interrupt
 * does not save pushed around it, so that the interrupt's prologue (run
 * every tick) saves no more than before. It runs once per underrun. */
#ifndef QS_UNDERRUN_TICK_AVR_H
#define QS_UNDERRUN_TICK_AVR_H

/* qs_engine_underrun_in_tick on the one core (step_timer.c). */
void underrun_in_tick(void);

#define QS_ENGINE_UNDERRUN(e)                                                                                 \
    __asm__ __volatile__("push r18\n\tpush r19\n\tpush r20\n\tpush r21\n\tpush r22\n\tpush r23\n\t"         \
                         "push r24\n\tpush r25\n\tpush r26\n\tpush r27\n\tpush r30\n\tpush r31\n\t"         \
                         "call underrun_in_tick\n\t"                                                          \
                         "pop r31\n\tpop r30\n\tpop r27\n\tpop r26\n\tpop r25\n\tpop r24\n\t"               \
                         "pop r23\n\tpop r22\n\tpop r21\n\tpop r20\n\tpop r19\n\tpop r18" ::: "memory")

#endif
