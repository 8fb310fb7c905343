/* Interrupt service cost per vector (see sim_isr.h). */
#include "sim_isr.h"

#include <stdlib.h>

#include "sim_interrupts.h"

struct sim_isr {
    avr_t *avr;
    uint64_t entered;
    int inside;
    sim_cost cost;
    sim_isr_enter enter;
    sim_isr_done done;
    void *ctx;
};

void sim_cost_add(sim_cost *c, uint32_t cycles)
{
    if (c->count == 0 || cycles < c->min) {
        c->min = cycles;
    }
    if (cycles > c->max) {
        c->max = cycles;
    }
    c->count++;
    c->total += cycles;
}

static void on_running(avr_irq_t *irq, uint32_t value, void *param)
{
    sim_isr *w = param;
    (void)irq;
    if (value) {
        if (!w->inside) {
            w->entered = w->avr->cycle;
            w->inside = 1;
            if (w->enter) {
                w->enter(w->ctx);
            }
        }
        return;
    }
    if (!w->inside) {
        return; /* repeated notification */
    }
    w->inside = 0;
    const uint32_t cycles = (uint32_t)(w->avr->cycle - w->entered) + SIM_ISR_OVERHEAD;
    sim_cost_add(&w->cost, cycles);
    if (w->done) {
        w->done(w->ctx, cycles);
    }
}

sim_isr *sim_isr_watch(avr_t *avr, uint8_t vector, sim_isr_enter enter, sim_isr_done done,
                       void *ctx)
{
    sim_isr *w = calloc(1, sizeof *w);
    if (!w) {
        return NULL;
    }
    w->avr = avr;
    w->enter = enter;
    w->done = done;
    w->ctx = ctx;
    avr_irq_t *irq = avr_get_interrupt_irq(avr, vector);
    if (!irq) {
        free(w);
        return NULL;
    }
    avr_irq_register_notify(irq + AVR_INT_IRQ_RUNNING, on_running, w);
    return w;
}

int sim_isr_watch_also(sim_isr *w, uint8_t vector)
{
    avr_irq_t *irq = avr_get_interrupt_irq(w->avr, vector);
    if (!irq) {
        return -1;
    }
    avr_irq_register_notify(irq + AVR_INT_IRQ_RUNNING, on_running, w);
    return 0;
}

sim_cost sim_isr_cost(const sim_isr *w)
{
    return w->cost;
}

int sim_isr_inside(const sim_isr *w)
{
    return w->inside;
}
