#include "emu_events.h"

#include "emu_csv.h"

int emu_events_open(emu_events *ev, const char *path)
{
    return emu_csv_open(&ev->file, path, "events", "event,tick,monotonic_ns", 0);
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
    emu_csv_close(&ev->file);
}
