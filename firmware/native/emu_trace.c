#include "emu_trace.h"

#include <errno.h>
#include <string.h>

int emu_trace_open(emu_trace *t, const char *path)
{
    t->file = NULL;
    if (!path)
        return 1;
    t->file = fopen(path, "w");
    if (!t->file) {
        fprintf(stderr, "quadstep-emu: cannot write trace '%s': %s\n", path, strerror(errno));
        return 0;
    }
    setvbuf(t->file, NULL, _IOFBF, 1 << 16);
    fputs("tick,axis,direction\n", t->file);
    return 1;
}

void emu_trace_steps(emu_trace *t, uint32_t tick, uint8_t steps, uint8_t negative)
{
    uint8_t axis;

    if (!t->file)
        return;
    for (axis = 0; steps; axis++, steps >>= 1, negative >>= 1)
        if (steps & 1)
            fprintf(t->file, "%lu,%u,%d\n", (unsigned long)tick, axis, (negative & 1) ? -1 : 1);
}

void emu_trace_flush(emu_trace *t)
{
    if (t->file)
        fflush(t->file);
}

void emu_trace_close(emu_trace *t)
{
    if (t->file)
        fclose(t->file);
    t->file = NULL;
}
