/* Watches the motion pins and the step interrupt.
 *
 * Step and direction edges are recorded with their cycle. Steps are
 * numbered in motion ticks exactly as the emulator's trace numbers them
 * (PROTOCOL.md section 8). Motion ticks are the tick calls that made
 * decisions: a segment ran a tick (`left` moved on), or began and ended
 * in it (n = 1: the queue's `tail` moved), or a hold ran one (its tick
 * count moved on); a tick the inputs froze makes none. The harness reads both before and after every tick
 * interrupt (their addresses are published in flash by the firmware as
 * qs_debug_probe) and counts by the emulator's own rule: the count
 * STATUS_REPORT gives as motion_ticks. The steps a tick interrupt raises were decided by the
 * previous one, so they carry the count after that one: a decision made by
 * call t-1 of a segment starting at S gets S + t.
 *
 * Each interrupt's cost is binned by how many axes its decisions step
 * (known when the next interrupt raises them), or as idle when it ran no
 * segment. */
#ifndef SIM_MOTION_H
#define SIM_MOTION_H

#include <stdint.h>
#include <stdio.h>

#include "sim_avr.h"
#include "sim_board.h"
#include "sim_inputs.h"
#include "sim_isr.h"

#define SIM_MAX_AXES 4

/* Data addresses of engine state (firmware/avr/debug_probe.c). */
typedef struct {
    uint16_t left;  /* uint16_t */
    uint16_t tail;  /* uint8_t */
    uint16_t state; /* uint8_t */
    uint16_t latches_taken; /* uint8_t: latches taken (mod 256) */
    uint16_t hold_ticks; /* low byte of the hold's tick count */
    uint16_t resequence; /* uint8_t: a trigger began a hold in the tick */
    uint16_t hold_moving; /* uint8_t */
} sim_probe;

typedef struct {
    uint64_t steps[SIM_MAX_AXES];
    uint32_t motion_ticks;
    uint8_t state;
    uint32_t min_pulse;     /* shortest step pulse, cycles (0 if none) */
    uint32_t min_dir_setup; /* shortest dir change -> the next rising step edge of that axis */
    uint32_t min_dir_after_fall; /* shortest previous falling step edge -> dir change */
    uint64_t dir_changes;
    uint32_t tick_late_max; /* latest tick interrupt entry after its timer match, cycles */
    uint64_t ticks_missed;  /* timer matches that never got their interrupt */
    sim_cost idle;                 /* interrupts that ran no segment */
    sim_cost running[SIM_MAX_AXES + 1]; /* by axes whose steps they decided */
} sim_motion_stats;

typedef struct sim_motion sim_motion;

/* trace and edges may be NULL; inputs is moved by the steps (its machine,
 * if any, adds motor and carriage columns to the trace). */
sim_motion *sim_motion_attach(avr_t *avr, const sim_board *board, const sim_probe *probe,
                              FILE *trace, FILE *edges, sim_inputs *inputs, const machine *mach);

/* The step interrupt starts, and returns after `cycles` (wire to sim_isr_watch). */
void sim_motion_tick_enter(void *motion);
void sim_motion_tick_done(void *motion, uint32_t cycles);

sim_motion_stats sim_motion_get_stats(const sim_motion *m);

/* The engine's state (QS_STATE_*) right now. */
uint8_t sim_motion_state(const sim_motion *m);

#endif
