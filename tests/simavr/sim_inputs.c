/* The board's input pins, driven from the simulated machine (sim_inputs.h). */
#include "sim_inputs.h"

#include <stdlib.h>

#include "avr_ioport.h"
#include "sim_cycle_timers.h"
#include "sim_io.h"

#define PCIFR_ADDR 0x3B /* I/O 0x1B on both chips */

#define MAX_EDGES 4096
#define MAX_PENDING 64
#define INPUTS 12

typedef struct {
    uint64_t cycle;       /* the pin changed */
    uint32_t tick;        /* motion ticks decided by then */
    uint8_t input, level;
    uint64_t latch_cycle; /* entry of the tick interrupt that latched it (0: none) */
    uint64_t latch_done;  /* ... and the end of it */
    uint32_t latch_tick;  /* the motion tick it latched */
    uint64_t last_step;   /* the last rising step edge after it, before the next edge (0: none) */
} edge;

typedef struct {
    uint64_t due;
    uint8_t input, level;
} pending;

struct sim_inputs {
    avr_t *avr;
    const sim_board *board;
    machine *m;
    uint32_t delay;
    avr_irq_t *pin[INPUTS];
    uint16_t wanted;  /* levels the machine gives */
    uint16_t driven;  /* levels on the pins */
    pending queue[MAX_PENDING];
    int queued;
    uint32_t motion_tick;
    uint64_t entry_cycle;
    uint8_t latches_taken;
    int awaiting_latch;   /* index of the oldest edge not latched yet, -1 none */
    edge edges[MAX_EDGES];
    uint32_t count, dropped;
};

static void set_pin(sim_inputs *in, int input, uint8_t level)
{
    const uint16_t bit = (uint16_t)(1u << input);

    if (((in->driven & bit) != 0) == level)
        return;
    in->driven = level ? (uint16_t)(in->driven | bit) : (uint16_t)(in->driven & ~bit);
    avr_raise_irq(in->pin[input], level);
    if (in->count == MAX_EDGES) {
        in->dropped++;
        return;
    }
    in->edges[in->count] = (edge){in->avr->cycle, in->motion_tick, (uint8_t)input, level, 0, 0, 0, 0};
    if (in->awaiting_latch < 0)
        in->awaiting_latch = (int)in->count;
    in->count++;
}

static avr_cycle_count_t apply_due(avr_t *avr, avr_cycle_count_t when, void *param)
{
    sim_inputs *in = param;
    int i, kept = 0;
    (void)avr;
    for (i = 0; i < in->queued; i++) {
        if (in->queue[i].due <= when)
            set_pin(in, in->queue[i].input, in->queue[i].level);
        else
            in->queue[kept++] = in->queue[i];
    }
    in->queued = kept;
    return 0;
}

/* The machine's levels to the pins, at once or after the delay. */
static void drive(sim_inputs *in)
{
    const uint16_t levels = in->m ? machine_levels(in->m) : 0xFFFF;
    int input;

    for (input = 0; input < INPUTS; input++) {
        const uint16_t bit = (uint16_t)(1u << input);
        const uint8_t level = (levels & bit) != 0;
        if (!in->pin[input] || ((in->wanted & bit) != 0) == level)
            continue;
        in->wanted = level ? (uint16_t)(in->wanted | bit) : (uint16_t)(in->wanted & ~bit);
        if (in->delay == 0 || in->queued == MAX_PENDING) {
            set_pin(in, input, level);
        } else {
            in->queue[in->queued++] = (pending){in->avr->cycle + in->delay, (uint8_t)input, level};
            avr_cycle_timer_register(in->avr, in->delay, apply_due, in);
        }
    }
}

/* The chip clears a pin-change flag written with a one (the datasheet's
 * PCIFR); simavr 1.6 stores the one instead, so the harness does what the
 * chip does. */
static void pcifr_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
    (void)param;
    avr->data[addr] &= (uint8_t)~v;
}

sim_inputs *sim_inputs_attach(avr_t *avr, const sim_board *board, machine *m, uint32_t delay)
{
    sim_inputs *in = calloc(1, sizeof *in);
    int input;

    if (!in)
        return NULL;
    in->avr = avr;
    in->board = board;
    in->m = m;
    in->delay = delay;
    in->awaiting_latch = -1;
    avr_register_io_write(avr, PCIFR_ADDR, pcifr_write, in);
    for (input = 0; input < INPUTS; input++) {
        const char port = input < 8 ? board->limit_port : board->control_port;
        if (board->input_bit[input] >= 0)
            in->pin[input] = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), board->input_bit[input]);
    }
    /* Power-up levels, before the firmware runs: no edge recorded. */
    {
        const uint16_t levels = m ? machine_levels(m) : 0xFFFF;
        for (input = 0; input < INPUTS; input++)
            if (in->pin[input])
                avr_raise_irq(in->pin[input], (levels >> input) & 1u);
        in->wanted = in->driven = levels;
    }
    return in;
}

void sim_inputs_tick_enter(sim_inputs *in, uint32_t motion_tick)
{
    in->motion_tick = motion_tick;
    in->entry_cycle = in->avr->cycle;
    if (in->m) {
        machine_tick(in->m, motion_tick);
        drive(in);
    }
}

void sim_inputs_tick_done(sim_inputs *in, uint8_t latches_taken)
{
    if (latches_taken == in->latches_taken)
        return;
    in->latches_taken = latches_taken;
    /* The oldest edge not latched yet is the one this latch is of. */
    if (in->awaiting_latch >= 0) {
        edge *e = &in->edges[in->awaiting_latch];
        e->latch_cycle = in->entry_cycle;
        e->latch_done = in->avr->cycle;
        e->latch_tick = in->motion_tick;
        in->awaiting_latch = in->awaiting_latch + 1 < (int)in->count ? in->awaiting_latch + 1 : -1;
    }
}

void sim_inputs_step(sim_inputs *in, int axis, int direction)
{
    if (in->count)
        in->edges[in->count - 1].last_step = in->avr->cycle;
    if (in->m) {
        machine_step(in->m, axis, direction);
        drive(in);
    }
}

void sim_inputs_write_json(const sim_inputs *in, FILE *f)
{
    uint32_t i;

    fprintf(f, "\"machine\": ");
    if (in->m)
        machine_write_json(in->m, f);
    else
        fputs("null", f);
    fprintf(f, ",\n\"input_delay\": %u, \"input_edges_dropped\": %u, \"input_edges\": [", in->delay, in->dropped);
    for (i = 0; i < in->count; i++) {
        const edge *e = &in->edges[i];
        fprintf(f,
                "%s{\"cycle\": %llu, \"tick\": %u, \"input\": %u, \"level\": %u, \"latch_cycle\": %llu, "
                "\"latch_done_cycle\": %llu, \"latch_tick\": %u, \"last_step_cycle\": %llu}",
                i ? ", " : "", (unsigned long long)e->cycle, e->tick, e->input, e->level,
                (unsigned long long)e->latch_cycle, (unsigned long long)e->latch_done, e->latch_tick,
                (unsigned long long)e->last_step);
    }
    fprintf(f, "]");
}
