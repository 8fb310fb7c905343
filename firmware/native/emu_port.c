#include "emu_port.h"

#include <string.h>
#include <time.h>

#include "qs_port.h"

static struct {
    emu_faults *faults;
    uint8_t buf[EMU_OUT_MAX];
    size_t start;
    size_t end;
    uint32_t frames;
    uint32_t discarded;
} out;

void emu_port_init(emu_faults *faults)
{
    out.faults = faults;
    out.start = out.end = 0;
    out.frames = 0;
    out.discarded = 0;
}

static void append(void *ctx, uint8_t byte)
{
    (void)ctx;
    out.buf[out.end++] = byte;
}

void qs_port_send(const uint8_t *bytes, uint8_t len)
{
    if (out.end + len > EMU_OUT_MAX && out.start > 0) {
        memmove(out.buf, out.buf + out.start, out.end - out.start);
        out.end -= out.start;
        out.start = 0;
    }
    if (out.end + len > EMU_OUT_MAX) {
        out.discarded += len;
        return;
    }
    out.frames++;
    emu_faults_tx(out.faults, bytes, len, append, 0);
}

/* The emulator's tick never rests. */
void qs_port_tick_wake(void)
{
}

/* The emulator reads the power after every tick (qs_core_outputs). */
void qs_port_laser_power(uint8_t power)
{
    (void)power;
}

uint8_t qs_port_laser_period_ticks(void)
{
    return 0; /* every line's pixels switched by the tick */
}

uint16_t qs_port_clock(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint16_t)(((uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u) / QS_PORT_CLOCK_US);
}

uint8_t qs_port_lock(void)
{
    return 0;
}

void qs_port_unlock(uint8_t saved)
{
    (void)saved;
}

const uint8_t *emu_port_pending(size_t *len)
{
    *len = out.end - out.start;
    return out.buf + out.start;
}

void emu_port_consume(size_t len)
{
    out.start += len;
    if (out.start == out.end)
        out.start = out.end = 0;
}

void emu_port_discard(void)
{
    out.discarded += (uint32_t)(out.end - out.start);
    out.start = out.end = 0;
}

uint32_t emu_port_frames_sent(void)
{
    return out.frames;
}

uint32_t emu_port_bytes_discarded(void)
{
    return out.discarded;
}
