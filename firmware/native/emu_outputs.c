#include "emu_outputs.h"

#include "emu_csv.h"

int emu_outputs_open(emu_outputs *o, const char *path)
{
    o->last.pins = 0;
    o->last.duty = 0;
    return emu_csv_open(&o->file, path, "outputs", "tick,pins,duty", (size_t)1 << 14);
}

void emu_outputs_update(emu_outputs *o, uint32_t tick, const qs_output_level *level)
{
    if (level->pins == o->last.pins && level->duty == o->last.duty)
        return;
    o->last = *level;
    if (o->file)
        fprintf(o->file, "%lu,%u,%u\n", (unsigned long)tick, level->pins, level->duty);
}

void emu_outputs_flush(emu_outputs *o)
{
    if (o->file)
        fflush(o->file);
}

void emu_outputs_close(emu_outputs *o)
{
    emu_csv_close(&o->file);
}
