/* Watches the motion pins and the step interrupt (see sim_motion.h). */
#include "sim_motion.h"

#include <stdlib.h>

#include "avr_ioport.h"
#include "sim_interrupts.h"

#define NONE UINT64_MAX

struct sim_motion {
    avr_t *avr;
    const sim_board *board;
    sim_probe probe;
    FILE *trace;
    FILE *edges;
    sim_inputs *inputs;
    const machine *mach;
    uint8_t port;             /* last value written to the motion port */
    uint64_t matched;         /* the unserved timer match of the tick, 0 if none */
    uint16_t left_before;     /* engine state at the current interrupt's entry */
    uint8_t tail_before;
    uint8_t hold_ticks_before;
    uint8_t resequence_before;
    uint32_t ticks;           /* motion ticks so far */
    int prev_ran;             /* the previous interrupt ran a segment */
    uint32_t prev_cost;       /* and cost this much */
    int have_prev;
    uint8_t raised;           /* step pins raised during the current interrupt */
    uint64_t rise[SIM_MAX_AXES];     /* cycle of the axis's last rising step edge */
    uint64_t fall[SIM_MAX_AXES];     /* ... falling step edge */
    uint64_t dir_change[SIM_MAX_AXES]; /* last dir change not yet followed by a step */
    sim_motion_stats stats;
};

static uint16_t read_u16(const uint8_t *d, uint16_t a)
{
    return (uint16_t)(d[a] | (d[a + 1] << 8));
}

static void min_update(uint32_t *slot, uint64_t value)
{
    if (*slot == 0 || value < *slot) {
        *slot = (uint32_t)value;
    }
}

static void on_port(avr_irq_t *irq, uint32_t value, void *param)
{
    sim_motion *m = param;
    const uint64_t now = m->avr->cycle;
    const uint8_t old = m->port;
    const uint8_t now_bits = (uint8_t)value;
    (void)irq;
    if (old == now_bits) {
        return;
    }
    m->port = now_bits;
    for (uint8_t axis = 0; axis < m->board->axes; axis++) {
        const uint8_t step_bit = (uint8_t)(1u << (m->board->step_shift + axis));
        const uint8_t dir_bit = (uint8_t)(1u << (m->board->dir_shift + axis));
        if ((old ^ now_bits) & dir_bit) {
            const int level = (now_bits & dir_bit) != 0;
            if (m->edges) {
                fprintf(m->edges, "%llu,dir,%u,%d\n", (unsigned long long)now, axis, level);
            }
            if (m->fall[axis] != NONE) {
                min_update(&m->stats.min_dir_after_fall, now - m->fall[axis]);
            }
            m->dir_change[axis] = now;
            m->stats.dir_changes++;
        }
        if ((old ^ now_bits) & step_bit) {
            const int level = (now_bits & step_bit) != 0;
            if (m->edges) {
                fprintf(m->edges, "%llu,step,%u,%d\n", (unsigned long long)now, axis, level);
            }
            if (level) {
                const int direction = (now_bits & dir_bit) ? -1 : 1;
                sim_inputs_step(m->inputs, axis, direction);
                m->rise[axis] = now;
                m->raised |= (uint8_t)(1u << axis);
                m->stats.steps[axis]++;
                if (m->dir_change[axis] != NONE) {
                    min_update(&m->stats.min_dir_setup, now - m->dir_change[axis]);
                    m->dir_change[axis] = NONE;
                }
                if (m->trace && m->mach) {
                    fprintf(m->trace, "%u,%u,%d,%ld,%.17g\n", m->ticks, axis, direction,
                            m->mach->axis[axis].motor, m->mach->axis[axis].carriage);
                } else if (m->trace) {
                    fprintf(m->trace, "%u,%u,%d\n", m->ticks, axis, direction);
                }
            } else {
                m->fall[axis] = now;
                if (m->rise[axis] != NONE) {
                    min_update(&m->stats.min_pulse, now - m->rise[axis]);
                }
            }
        }
    }
}

/* A timer match set the tick's interrupt flag (value 1); the first one not
 * yet served is the one the next interrupt serves. */
static void on_pending(avr_irq_t *irq, uint32_t value, void *param)
{
    sim_motion *m = param;
    (void)irq;
    if (value && !m->matched) {
        m->matched = m->avr->cycle;
    }
}

/* Timer1's period in cycles (OCR1A + 1, CTC mode; the same address on
 * both chips). */
static uint32_t tick_period(const avr_t *avr)
{
    return (uint32_t)(avr->data[0x88] | (avr->data[0x89] << 8)) + 1u;
}

void sim_motion_tick_enter(void *motion)
{
    sim_motion *m = motion;
    if (m->matched) {
        const uint64_t late = m->avr->cycle - m->matched;
        if (late > m->stats.tick_late_max) {
            m->stats.tick_late_max = (uint32_t)late;
        }
        /* Every match while this one waited found the flag set already:
         * the flag holds one, so those ticks are lost for good. (simavr
         * does not signal a match that finds the flag set.) */
        m->stats.ticks_missed += (uint32_t)(late / tick_period(m->avr));
        m->matched = 0;
    }
    m->left_before = read_u16(m->avr->data, m->probe.left);
    m->tail_before = m->avr->data[m->probe.tail];
    m->hold_ticks_before = m->avr->data[m->probe.hold_ticks];
    m->resequence_before = m->avr->data[m->probe.resequence];
    sim_inputs_tick_enter(m->inputs, m->ticks);
}

void sim_motion_tick_done(void *motion, uint32_t cycles)
{
    sim_motion *m = motion;
    /* A decision was made if a segment ran a tick, began and ended (n = 1)
     * or a hold ran one in this call: the rule the emulator counts by. */
    const int ran = m->left_before != read_u16(m->avr->data, m->probe.left) ||
                    m->avr->data[m->probe.tail] != m->tail_before ||
                    m->avr->data[m->probe.hold_ticks] != m->hold_ticks_before ||
                    (!m->resequence_before && m->avr->data[m->probe.resequence] && m->avr->data[m->probe.hold_moving]);

    /* The previous interrupt's decisions are the steps this one raised. */
    if (m->have_prev) {
        if (m->prev_ran) {
            int count = 0;
            for (uint8_t axis = 0; axis < SIM_MAX_AXES; axis++) {
                count += (m->raised >> axis) & 1;
            }
            sim_cost_add(&m->stats.running[count], m->prev_cost);
        } else {
            sim_cost_add(&m->stats.idle, m->prev_cost);
        }
    }
    m->have_prev = 1;
    m->prev_ran = ran;
    m->prev_cost = cycles;
    m->raised = 0;
    m->ticks += (uint32_t)ran;
    sim_inputs_tick_done(m->inputs, m->avr->data[m->probe.latches_taken]);
}

sim_motion *sim_motion_attach(avr_t *avr, const sim_board *board, const sim_probe *probe,
                              FILE *trace, FILE *edges, sim_inputs *inputs, const machine *mach)
{
    sim_motion *m = calloc(1, sizeof *m);
    if (!m) {
        return NULL;
    }
    m->avr = avr;
    m->board = board;
    m->probe = *probe;
    m->trace = trace;
    m->edges = edges;
    m->inputs = inputs;
    m->mach = mach;
    for (int axis = 0; axis < SIM_MAX_AXES; axis++) {
        m->rise[axis] = m->fall[axis] = m->dir_change[axis] = NONE;
    }
    if (trace) {
        fprintf(trace, mach ? "tick,axis,direction,motor,carriage\n" : "tick,axis,direction\n");
    }
    if (edges) {
        fprintf(edges, "cycle,pin,axis,level\n");
    }
    avr_irq_t *port = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(board->motion_port),
                                    IOPORT_IRQ_REG_PORT);
    avr_irq_register_notify(port, on_port, m);
    avr_irq_register_notify(avr_get_interrupt_irq(avr, board->timer_vector) + AVR_INT_IRQ_PENDING,
                            on_pending, m);
    return m;
}

sim_motion_stats sim_motion_get_stats(const sim_motion *m)
{
    sim_motion_stats s = m->stats;
    s.motion_ticks = m->ticks;
    s.state = m->avr->data[m->probe.state];
    return s;
}

uint8_t sim_motion_state(const sim_motion *m)
{
    return m->avr->data[m->probe.state];
}
