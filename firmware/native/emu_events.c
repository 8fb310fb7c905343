#include "emu_events.h"

#include <errno.h>
#include <string.h>

int emu_events_open(emu_events *ev, const char *path)
{
    ev->file = NULL;
    if (!path)
        return 1;
    ev->file = fopen(path, "w");
    if (!ev->file) {
        fprintf(stderr, "quadstep-emu: cannot write events '%s': %s\n", path, strerror(errno));
        return 0;
    }
    fputs("event,tick,monotonic_ns\n", ev->file);
    fflush(ev->file);
    return 1;
}

void emu_events_hold(emu_events *ev, uint32_t hold_tick, uint64_t monotonic_ns)
{
    if (!ev->file)
        return;
    /* Rare: written through at once, so a reader never waits for it. */
    fprintf(ev->file, "hold,%lu,%llu\n", (unsigned long)hold_tick, (unsigned long long)monotonic_ns);
    fflush(ev->file);
}

void emu_events_close(emu_events *ev)
{
    if (ev->file)
        fclose(ev->file);
    ev->file = NULL;
}
