/* Step engine speed on the build machine, free-running: queued random
 * segments on 3 axes run back to back through the real core code (segment
 * preparation, the tick, retiring), and the figures are printed. Nothing is
 * asserted about time. Run with `make bench-engine`. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "qs_engine.h"
#include "qs_engine_tick.h"
#include "qs_messages.h"
#include "qs_port.h"

#define SEGMENTS 20000
#define AXES 3

void qs_port_send(const uint8_t *bytes, uint8_t len)
{
    (void)bytes;
    (void)len;
}

/* The bench drives the tick itself. */
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
    return 0;
}

uint8_t qs_port_lock(void)
{
    return 0;
}

void qs_port_unlock(uint8_t saved)
{
    (void)saved;
}

static qs_engine engine;
static qs_segment_msg plan[SEGMENTS];

static uint32_t rnd(uint32_t *state, uint32_t limit)
{
    *state = *state * 1664525u + 1013904223u;
    return (*state >> 8) % limit;
}

static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int main(void)
{
    uint32_t state = 12345;
    uint64_t ticks = 0, steps = 0;
    uint32_t next = 0;
    double start, elapsed;
    int i, axis;

    for (i = 0; i < SEGMENTS; i++) {
        plan[i].n = (uint16_t)(1 + rnd(&state, QS_N_MAX));
        plan[i].active = (1u << AXES) - 1;
        plan[i].negative = (uint8_t)rnd(&state, 1u << AXES);
        for (axis = 0; axis < QS_PROTOCOL_AXES; axis++) {
            plan[i].v0[axis] = axis < AXES ? (uint16_t)rnd(&state, 4097) : 0;
            plan[i].vn[axis] = axis < AXES ? (uint16_t)(1 + rnd(&state, 4096)) : 0;
            plan[i].r[axis] = 0;
        }
    }
    qs_engine_init(&engine, QS_QUEUE_CAPACITY);
    start = seconds();
    while (next < SEGMENTS || !qs_queue_empty(&engine.queue)) {
        qs_engine_retire(&engine);
        while (next < SEGMENTS && qs_queue_free(&engine.queue) > 0) {
            qs_segment_prepare(qs_queue_back(&engine.queue), &plan[next++]);
            qs_queue_publish(&engine.queue);
            qs_engine_wake(&engine);
        }
        /* Run the queued segments, leaving the last one for the loop to
         * top up before it ends (every segment ends moving). */
        while (qs_queue_count(&engine.queue) > (next < SEGMENTS ? 1 : 0)) {
            uint8_t bits = qs_engine_tick(&engine);
            ticks++;
            for (; bits; bits &= (uint8_t)(bits - 1))
                steps++;
        }
        if (next == SEGMENTS && qs_queue_empty(&engine.queue))
            break;
    }
    elapsed = seconds() - start;
    qs_engine_retire(&engine);
    if (engine.state == QS_STATE_ALARM || engine.segments_done != SEGMENTS) {
        fprintf(stderr, "bench_engine: the run did not complete (%lu segments)\n",
                (unsigned long)engine.segments_done);
        return 1;
    }
    printf("bench_engine: %d segments on %d axes, %llu ticks, %llu steps in %.3f s\n", SEGMENTS,
           AXES, (unsigned long long)ticks, (unsigned long long)steps, elapsed);
    printf("bench_engine: %.1f M ticks/s, %.1f M axis-ticks/s, %.1f M steps/s\n",
           ticks / elapsed / 1e6, ticks * AXES / elapsed / 1e6, steps / elapsed / 1e6);
    return 0;
}
