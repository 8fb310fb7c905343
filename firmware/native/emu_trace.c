#include "emu_trace.h"

#include "emu_csv.h"

int emu_trace_open(emu_trace *t, const char *path, int with_machine)
{
    return emu_csv_open(&t->file, path, "trace",
                        with_machine ? "tick,axis,direction,motor,carriage" : "tick,axis,direction",
                        (size_t)1 << 16);
}

void emu_trace_steps(emu_trace *t, uint32_t tick, uint8_t steps, uint8_t negative, const machine *m)
{
    uint8_t axis;

    if (!t->file)
        return;
    for (axis = 0; steps; axis++, steps >>= 1, negative >>= 1) {
        if (!(steps & 1))
            continue;
        if (m)
            fprintf(t->file, "%lu,%u,%d,%ld,%.17g\n", (unsigned long)tick, axis, (negative & 1) ? -1 : 1,
                    m->axis[axis].motor, m->axis[axis].carriage);
        else
            fprintf(t->file, "%lu,%u,%d\n", (unsigned long)tick, axis, (negative & 1) ? -1 : 1);
    }
}

void emu_trace_flush(emu_trace *t)
{
    if (t->file)
        fflush(t->file);
}

void emu_trace_close(emu_trace *t)
{
    emu_csv_close(&t->file);
}
