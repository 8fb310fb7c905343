/* The events log (--events FILE): CSV "event,tick,monotonic_ns", one line
 * per event as it happens. "hold" lines give the motion tick at which a
 * hold's first deceleration tick ran and the CLOCK_MONOTONIC time, in ns,
 * at which it ran (Python's time.monotonic_ns() reads the same clock), so
 * a host can measure how long a HOLD took to act. */
#ifndef EMU_EVENTS_H
#define EMU_EVENTS_H

#include <stdint.h>
#include <stdio.h>

typedef struct {
    FILE *file; /* NULL: no log */
} emu_events;

int emu_events_open(emu_events *ev, const char *path);
void emu_events_hold(emu_events *ev, uint32_t hold_tick, uint64_t monotonic_ns);
void emu_events_close(emu_events *ev);

#endif
