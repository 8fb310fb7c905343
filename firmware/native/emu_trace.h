/* The step trace: CSV "tick,axis,direction", one line per step, where tick
 * is the motion tick of the step (PROTOCOL.md section 8); with a simulated
 * machine also "motor,carriage": where the rotor and the carriage are
 * after the step (README.md). */
#ifndef EMU_TRACE_H
#define EMU_TRACE_H

#include <stdint.h>
#include <stdio.h>

#include "machine.h"

typedef struct {
    FILE *file; /* NULL: tracing off */
} emu_trace;

int emu_trace_open(emu_trace *t, const char *path, int with_machine);
/* m: the machine after these steps, or NULL. */
void emu_trace_steps(emu_trace *t, uint32_t tick, uint8_t steps, uint8_t negative, const machine *m);
void emu_trace_flush(emu_trace *t);
void emu_trace_close(emu_trace *t);

#endif
