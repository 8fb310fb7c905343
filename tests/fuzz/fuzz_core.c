/* libFuzzer over the firmware core's receive path (ASan and UBSan in the
 * build, tests/fuzz/fuzz.mk): every input byte goes to qs_core_rx as from
 * the wire; after each frame's delimiter the engine ticks while it moves
 * (a count taken from the byte before it, up to a segment's length, so
 * accepted segments and holds run) with the main loop's poll between, and
 * the port clock moves on (so the watchdog fires too). At the end the
 * engine runs until it rests or 5,000 ticks, and the core's own invariants are checked: positions
 * within the range the firmware keeps, a report never longer than a frame.
 * Seeds: every frame of protocol/vectors.json (seeds.py). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "qs_core.h"
#include "qs_engine_tick.h"
#include "qs_inputs_tick.h"
#include "qs_port.h"

static uint16_t clock_now;
static uint8_t locked;

void qs_port_send(const uint8_t *bytes, uint8_t len)
{
    (void)bytes;
    if (len > QS_MAX_WIRE || locked)
        abort(); /* a report longer than a frame, or sent with the tick locked out */
}

uint8_t qs_port_lock(void)
{
    return locked++;
}

void qs_port_unlock(uint8_t saved)
{
    locked = saved;
}

/* The fuzzer drives the tick itself. */
void qs_port_tick_wake(void)
{
}

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
    return clock_now;
}

static qs_core core;

static void run(uint32_t ticks, uint16_t *seen, uint16_t pins)
{
    while (ticks-- && (core.engine.state == QS_STATE_RUNNING || core.engine.state == QS_STATE_HOLDING)) {
        qs_inputs_tick(&core.inputs, &core.engine, seen, pins);
        qs_engine_tick(&core.engine);
        qs_core_poll(&core);
    }
}

static void check_positions(void)
{
    qs_status st;
    uint8_t axis;

    qs_core_status(&core, &st);
    for (axis = 0; axis < st.axis_count; axis++)
        if (st.position[axis] > QS_POSITION_MAX + (1L << 23) || st.position[axis] < -QS_POSITION_MAX - (1L << 23))
            abort(); /* past the range the checks keep, by more than a queue and a hold could carry */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint16_t seen = QS_INPUTS_RESAMPLE, pins = 0x0FFF; /* every input open */
    uint8_t previous = 0;
    size_t i;

    qs_core_init(&core);
    qs_core_configure(&core, 4, 8, QS_TICK_HZ);
    clock_now = 0;
    for (i = 0; i < size; i++) {
        const uint8_t byte = data[i];
        qs_core_rx(&core, byte);
        if (byte == 0) {
            run((uint32_t)previous * 4u, &seen, pins);
            clock_now = (uint16_t)(clock_now + previous * 64u);
            if (previous == 0xA5)
                pins ^= (uint16_t)(1u << (i % 12)); /* now and then an input changes */
            qs_core_poll(&core);
            check_positions();
        }
        previous = byte;
    }
    run(5000, &seen, pins);
    check_positions();
    return 0;
}
