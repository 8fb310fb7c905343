/* The output trace: CSV "tick,pins,duty", a line each time the spindle,
 * laser or coolant outputs change (qs_outputs.h): from motion tick `tick`
 * on, `pins` (QS_OUT_ON 1, REVERSE 2, MIST 16, FLOOD 32) and the spindle
 * or laser duty, 0 ... 65535 (README.md). */
#ifndef EMU_OUTPUTS_H
#define EMU_OUTPUTS_H

#include <stdint.h>
#include <stdio.h>

#include "qs_outputs.h"

typedef struct {
    FILE *file; /* NULL: not traced */
    qs_output_level last;
} emu_outputs;

int emu_outputs_open(emu_outputs *o, const char *path);
/* The level in effect from motion tick `tick` on; written when it changed. */
void emu_outputs_update(emu_outputs *o, uint32_t tick, const qs_output_level *level);
void emu_outputs_flush(emu_outputs *o);
void emu_outputs_close(emu_outputs *o);

#endif
