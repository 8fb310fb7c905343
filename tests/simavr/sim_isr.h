/* Interrupt service cost per vector, in CPU cycles from the hardware's
 * response to the end of RETI. simavr signals vector entry and RETI; the
 * 4-cycle interrupt response and the 4 cycles of RETI itself are not in
 * that span and are added here. */
#ifndef SIM_ISR_H
#define SIM_ISR_H

#include <stdint.h>

#include "sim_avr.h"

#define SIM_ISR_OVERHEAD 8

typedef struct {
    uint64_t count;
    uint64_t total;
    uint32_t min;
    uint32_t max;
} sim_cost;

void sim_cost_add(sim_cost *c, uint32_t cycles);

/* Called when a watched interrupt starts, and when it returns with its cost. */
typedef void (*sim_isr_enter)(void *ctx);
typedef void (*sim_isr_done)(void *ctx, uint32_t cycles);

typedef struct sim_isr sim_isr;

/* enter and done may be NULL. */
sim_isr *sim_isr_watch(avr_t *avr, uint8_t vector, sim_isr_enter enter, sim_isr_done done,
                       void *ctx);

/* Count a second vector as the same interrupt (the two never nest): the
 * step tick runs from compare A, or from compare B while it rests. */
int sim_isr_watch_also(sim_isr *w, uint8_t vector);

sim_cost sim_isr_cost(const sim_isr *w);

/* Nonzero while the interrupt runs. */
int sim_isr_inside(const sim_isr *w);

#endif
