/* The board's input pins, driven from the simulated machine
 * (firmware/native/machine.h) as the step pins move it: the same
 * mechanics the emulator runs. Without a machine every input pin is held
 * high (pulled up, open). Each pin change is recorded with its cycle,
 * and with the latch the firmware took for it (the latch ring's index
 * moving on in a tick interrupt) and the last step pulse after it, so
 * the latencies from an edge to its latch and to the last step are
 * measured in cycles. */
#ifndef SIM_INPUTS_H
#define SIM_INPUTS_H

#include <stdint.h>
#include <stdio.h>

#include "machine.h"
#include "sim_avr.h"
#include "sim_board.h"

typedef struct sim_inputs sim_inputs;

/* machine may be NULL; delay: cycles from a change in the machine to the
 * pin (0: at once, within the same instruction as the step edge). */
sim_inputs *sim_inputs_attach(avr_t *avr, const sim_board *board, machine *m, uint32_t delay);

/* A tick interrupt begins; motion_tick: ticks decided so far. */
void sim_inputs_tick_enter(sim_inputs *in, uint32_t motion_tick);
/* It ended; latches_taken: the firmware's count of latches taken (mod 256). */
void sim_inputs_tick_done(sim_inputs *in, uint8_t latches_taken);
/* A rising step edge. */
void sim_inputs_step(sim_inputs *in, int axis, int direction);

/* "machine" (or null) and "input_edges" members of the stats JSON. */
void sim_inputs_write_json(const sim_inputs *in, FILE *f);

#endif
