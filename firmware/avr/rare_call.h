/* The engine's rare work from the step interrupt (QS_ENGINE_UNDERRUN and
 * QS_ENGINE_TRIGGER_SPLIT in qs_engine_tick.h, a RASTER line's begin and end
 * in qs_raster_tick.h): one `call` in the
 * interrupt to a small trampoline (step_timer.c, QS_AVR_RARE_TRAMPOLINE)
 * that saves every call-clobbered register the interrupt does not, then
 * calls the C. So the interrupt's prologue (run every tick) saves no more
 * than before, and its body grows by two words a call, which keeps its
 * common paths' branches short. Each runs a few times per underrun or
 * trigger. */
#ifndef QS_RARE_CALL_AVR_H
#define QS_RARE_CALL_AVR_H

/* The core's functions on the one engine (step_timer.c). */
void underrun_in_tick(void);
void trigger_split_in_tick(void);
void raster_watch_in_tick(void);

#define QS_AVR_RARE_CALL(trampoline) __asm__ __volatile__("call " #trampoline ::: "memory")

#define QS_AVR_RARE_TRAMPOLINE(trampoline, fn)                                                                \
    __asm__(".section .text." #trampoline ",\"ax\",@progbits\n"                                            \
            ".global " #trampoline "\n" #trampoline ":\n\t"                                                   \
            "push r18\n\tpush r19\n\tpush r20\n\tpush r21\n\tpush r22\n\tpush r23\n\t"                       \
            "push r24\n\tpush r25\n\tpush r26\n\tpush r27\n\tpush r30\n\tpush r31\n\t"                       \
            "call " #fn "\n\t"                                                                                \
            "pop r31\n\tpop r30\n\tpop r27\n\tpop r26\n\tpop r25\n\tpop r24\n\t"                             \
            "pop r23\n\tpop r22\n\tpop r21\n\tpop r20\n\tpop r19\n\tpop r18\n\t"                             \
            "ret\n\t"                                                                                         \
            ".previous")

#define QS_ENGINE_UNDERRUN(e) QS_AVR_RARE_CALL(underrun_rare)
#define QS_ENGINE_TRIGGER_SPLIT(e) QS_AVR_RARE_CALL(trigger_split_rare)
#define QS_RASTER_WATCH(r, o, e) QS_AVR_RARE_CALL(raster_watch_rare)

#endif
