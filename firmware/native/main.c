/* quadstep-emu: the firmware core on the host, behind a pseudo-terminal or
 * a TCP socket, so the host software runs against the real firmware code
 * without a board. See README.md in this directory. */
#ifndef PIO_UNIT_TESTING

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "emu_events.h"
#include "emu_faults.h"
#include "emu_link.h"
#include "emu_options.h"
#include "emu_outputs.h"
#include "emu_port.h"
#include "emu_trace.h"
#include "machine.h"
#include "qs_core.h"
#include "qs_engine_tick.h"
#include "qs_raster_tick.h"
#include "qs_frame.h"
#include "qs_inputs_tick.h"

#define UNDERRUN_GRACE_NS 2000000000ull /* free-running: wait this long for the host (a loaded test machine pauses) */
#define FREE_BATCH 4096u               /* free-running: ticks between input checks */
#define PACED_POLL_MS 1
#define MAX_LAG_MS 50u /* paced: the most the clock catches up at once (drop_lag) */

typedef struct {
    emu_options opts;
    emu_link link;
    emu_faults faults;
    emu_trace trace;
    emu_outputs outputs;
    emu_events events;
    qs_core core;
    machine *machine;       /* --machine, or NULL */
    uint16_t inputs_idle;   /* pin levels without a machine: all high, nothing active */
    uint16_t inputs_seen;   /* the last sample (qs_inputs_tick.h) */
    uint32_t motion_tick;   /* ticks that made decisions: the trace's clock */
    uint64_t steps[QS_AXIS_COUNT];
    uint8_t last_state;
    /* Paced time: ticks run since clock_ref. */
    uint64_t clock_ref_ns;
    uint64_t clock_ticks;
    uint32_t stalls; /* times the paced clock dropped a lag (drop_lag) */
    /* Free-running: when the engine began waiting at an underrun. */
    uint64_t underrun_since_ns;
    /* At rest while the inputs settle: ticks sampled since idle_ref_ns (0: not settling). */
    uint64_t idle_ref_ns;
    uint64_t idle_ticks;
} emulator;

static emulator emu;
static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

/* A board makes a new boot id at each reset; the emulator a random one at
 * each start (--boot-id N for tests). */
static uint16_t random_boot_id(void)
{
    uint16_t id = 0;
    FILE *f = fopen("/dev/urandom", "rb");

    if (!f || fread(&id, sizeof id, 1, f) != 1)
        id = (uint16_t)(now_ns() ^ (uint64_t)getpid());
    if (f)
        fclose(f);
    return id;
}

static const char *state_name(uint8_t state)
{
    static const char *const names[] = {"IDLE", "RUNNING", "ALARM", "HOLDING", "STARVED"};
    return state < 5 ? names[state] : "?";
}

static const char *alarm_name(uint8_t alarm)
{
    static const char *const names[] = {"NONE", "UNDERRUN", "REJECTED_SEGMENT", "HARD_LIMIT",
                                        "HOST_LOST", "E_STOP"};
    return alarm < 6 ? names[alarm] : "?";
}

/* Ticks run while RUNNING or HOLDING. */
static int in_motion(const qs_engine *e)
{
    return e->state == QS_STATE_RUNNING || e->state == QS_STATE_HOLDING;
}

/* The engine came to a stop (idle, alarm, or stopped): make the trace
 * readable now, and check that the trace clock agrees with the core. */
static void on_settled(emulator *m)
{
    qs_status st;

    emu_trace_flush(&m->trace);
    emu_outputs_flush(&m->outputs);
    qs_core_status(&m->core, &st);
    if (st.motion_ticks != m->motion_tick) {
        fprintf(stderr, "quadstep-emu: internal error: trace tick %lu, core motion_ticks %lu\n",
                (unsigned long)m->motion_tick, (unsigned long)st.motion_ticks);
        exit(3);
    }
}

/* The outputs as the board's pins would show them, from this motion tick
 * on: looked at after every tick and every message (a board looks once per
 * PWM period, and its tick sets a RASTER's pixels). */
static void watch_outputs(emulator *m)
{
    qs_output_level level;

    qs_core_outputs(&m->core, &level, 0); /* after every tick: the pixel now */
    emu_outputs_update(&m->outputs, m->motion_tick, &level);
}

static void watch_state(emulator *m)
{
    uint8_t state = m->core.engine.state;

    if (!in_motion(&m->core.engine)
        && (m->last_state == QS_STATE_RUNNING || m->last_state == QS_STATE_HOLDING))
        on_settled(m);
    if (state == QS_STATE_RUNNING && m->last_state != QS_STATE_RUNNING) {
        m->clock_ref_ns = now_ns();
        m->clock_ticks = 0;
    }
    m->last_state = state;
    watch_outputs(m);
}

/* The inputs, sampled as the board samples its pins at the start of each
 * tick: the machine's levels after the previous tick's steps. */
static void sample_inputs(emulator *m)
{
    const uint16_t raw = m->machine ? (uint16_t)(machine_levels(m->machine) & m->core.inputs.present)
                                    : m->inputs_idle;

    qs_inputs_tick(&m->core.inputs, &m->core.engine, &m->inputs_seen, raw);
}

/* The machine's clock moves on a tick, then the steps just decided move
 * it: the order the board's pins give in the simavr harness (the next
 * tick begins, its first instructions raise these steps, then it samples). */
static void move_machine(emulator *m, uint8_t bits, uint8_t negative)
{
    uint8_t axis;

    if (!m->machine)
        return;
    machine_tick(m->machine, m->motion_tick);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        if ((bits >> axis) & 1u)
            machine_step(m->machine, axis, ((negative >> axis) & 1u) ? -1 : 1);
}

/* The ticks the engine's hold has run, 0 without one: worked out as the
 * main loop does (a few divisions: the emulator's tick can afford them). */
static uint32_t hold_ticks(const qs_engine *e)
{
    const qs_segment *s = e->held;
    qs_hold_origin origin;
    uint32_t ticks = 0;
    uint8_t axis;

    if (!s)
        return 0;
    qs_hold_origin_of(&e->hold, s, e->held_t0 == s->n, &origin);
    for (axis = 0; axis < QS_AXIS_COUNT; axis++)
        qs_hold_axis_made(&e->hold, &origin, axis, e->hold.h[axis], e->hold.inc[axis], e->hold.moving, &ticks);
    return ticks;
}

static void run_tick(emulator *m)
{
    qs_engine *e = &m->core.engine;
    uint16_t left_before;
    uint8_t tail_before, hold_ticks_before, holds_before, kept_before;
    int hold_begins, hold_began, hold_of_no_ticks;
    uint8_t bits, axis;

    left_before = e->left;
    tail_before = e->queue.tail;
    hold_ticks_before = e->hold.tick_byte;
    holds_before = e->holds_begun;
    kept_before = e->kept;
    sample_inputs(m); /* may freeze the engine or begin a hold (a trigger), before the decisions */
    hold_begins = e->hold.moving && hold_ticks(e) == 0; /* begun in the main loop or by a trigger */
    bits = qs_engine_tick(e);
#if QS_RASTER_BYTES
    qs_raster_tick(&m->core.raster, &m->core.outputs, e, bits);
#endif
    /* A hold begun in this tick or just before has made its first decision
     * (an underrun's begins inside the tick). */
    hold_began = holds_before != e->holds_begun && hold_ticks(e) == 1;
    if (hold_begins || hold_began)
        emu_events_hold(&m->events, m->motion_tick, now_ns()); /* ticks before its first decision: its hold_tick */
    /* An underrun's hold, begun at a kept slot's end, that finds nothing
     * moving one tick on (the segment ended too slow to step again) gives
     * the slot back, so the tail moves, but it makes no decision. */
    hold_of_no_ticks = kept_before && left_before == 0 && holds_before != e->holds_begun && hold_ticks(e) == 0;
    /* A decision was made if a segment ran a tick (left moved on, or a
     * one-tick segment began and ended: tail moved, or its slot was kept
     * for a hold from its end) or a hold did (its
     * tick count moved on, or one began in this tick: its count restarted).
     * A frozen tick makes none. */
    if (!hold_of_no_ticks
        && (left_before != e->left || e->queue.tail != tail_before || e->hold.tick_byte != hold_ticks_before
            || hold_began || (!kept_before && e->kept))) {
        m->motion_tick++;
        for (axis = 0; axis < QS_AXIS_COUNT; axis++)
            m->steps[axis] += (bits >> axis) & 1u;
    }
    move_machine(m, bits, e->dir_bits);
    if (bits)
        emu_trace_steps(&m->trace, m->motion_tick, bits, e->dir_bits, m->machine);
    qs_core_poll(&m->core);
    watch_state(m);
}

static int inputs_settling(const emulator *m)
{
    return qs_inputs_settling(&m->core.inputs) || (m->machine && machine_busy(m->machine));
}

/* At rest the board still samples its inputs every tick: while the
 * machine has a bounce or a press under way, or the firmware a debounce
 * window open, do the same, at the tick rate in real time (free-running
 * too: a press lasts as long as on a board). */
static void settle_inputs(emulator *m)
{
    uint64_t now, due;

    if (!inputs_settling(m)) {
        m->idle_ref_ns = 0;
        return;
    }
    now = now_ns();
    if (m->idle_ref_ns == 0) {
        m->idle_ref_ns = now;
        m->idle_ticks = 0;
    }
    due = (now - m->idle_ref_ns) / 1000ull * m->opts.tick_hz / 1000000ull;
    while (m->idle_ticks < due && !in_motion(&m->core.engine) && inputs_settling(m)) {
        move_machine(m, 0, 0);
        sample_inputs(m);
        qs_core_poll(&m->core);
        watch_state(m);
        m->idle_ticks++;
    }
}

/* Running, a segment ended moving with nothing behind it: the next tick
 * would be an underrun. */
static int at_underrun(const qs_engine *e)
{
    return e->state == QS_STATE_RUNNING && e->left == 0 && e->kept && qs_queue_count(&e->queue) == 1;
}

/* --hold-at: a HOLD as if the host had sent it, once the motion tick is
 * reached with a segment to hold (seq = next_seq, so the host's sequence
 * is undisturbed). */
static void inject_hold(emulator *m)
{
    const qs_engine *e = &m->core.engine;
    uint8_t body[2 + QS_LEN_HOLD + 2]; /* room for the CRC */
    uint8_t wire[QS_MAX_WIRE];
    uint8_t len, i;

    if (!m->opts.hold_at_set || m->motion_tick < m->opts.hold_at_tick || e->state != QS_STATE_RUNNING
        || (e->left == 0 && qs_queue_empty(&e->queue)))
        return;
    m->opts.hold_at_set = 0;
    body[0] = QS_TYPE_HOLD;
    body[1] = m->core.next_seq;
    for (i = 0; i < 4; i++) {
        body[2 + 2 * i] = (uint8_t)m->opts.hold_at_decel[i];
        body[3 + 2 * i] = (uint8_t)(m->opts.hold_at_decel[i] >> 8);
    }
    len = qs_frame_encode(body, 2 + QS_LEN_HOLD, wire);
    for (i = 0; i < len; i++)
        qs_core_rx(&m->core, wire[i]);
}

static void to_core(void *ctx, uint8_t byte)
{
    qs_core_rx((qs_core *)ctx, byte);
}

static void read_input(emulator *m)
{
    uint8_t buf[4096];
    size_t got, i;

    while ((got = emu_link_read(&m->link, buf, sizeof buf)) > 0)
        for (i = 0; i < got; i++)
            emu_faults_rx(&m->faults, buf[i], to_core, &m->core);
    qs_core_poll(&m->core);
    watch_state(m);
}

static void write_output(emulator *m)
{
    size_t len;
    const uint8_t *data = emu_port_pending(&len);
    size_t put;

    while (len > 0 && (put = emu_link_write(&m->link, data, len)) > 0) {
        emu_port_consume(put);
        data = emu_port_pending(&len);
    }
}

/* Ticks due by now on the paced clock. */
static uint64_t ticks_due(const emulator *m)
{
    uint64_t elapsed = now_ns() - m->clock_ref_ns;

    return elapsed / 1000000ull * m->opts.tick_hz / 1000ull
           + elapsed % 1000000ull * m->opts.tick_hz / 1000000000ull;
}

/* More than MAX_LAG_MS behind, the emulator's process was not run (a loaded
 * computer): a board never stops, and would have read the host's frames all
 * along, so catching the whole lag up without the line would run the queue
 * dry where a board would not. The board stands still for the time past
 * MAX_LAG_MS instead: its clock moves on by that much. */
static void drop_lag(emulator *m)
{
    const uint64_t most = m->opts.tick_hz * MAX_LAG_MS / 1000u;
    uint64_t due = ticks_due(m), lag, ns;

    if (due <= m->clock_ticks + most)
        return;
    lag = due - m->clock_ticks - most;
    ns = lag / m->opts.tick_hz * 1000000000ull + lag % m->opts.tick_hz * 1000000000ull / m->opts.tick_hz;
    m->clock_ref_ns += ns + 1;
    m->stalls++;
}

static void run_paced(emulator *m)
{
    uint64_t due, limit = m->opts.tick_hz / 10 + 1; /* then look at the line again */

    drop_lag(m);
    due = ticks_due(m);
    while (m->clock_ticks < due && limit-- && in_motion(&m->core.engine)) {
        inject_hold(m);
        run_tick(m);
        m->clock_ticks++;
    }
    /* Keep the arithmetic small over long runs: move the reference on. */
    while (m->clock_ticks >= m->opts.tick_hz) {
        m->clock_ticks -= m->opts.tick_hz;
        m->clock_ref_ns += 1000000000ull;
    }
}

/* Returns 1 while waiting for the host at an underrun. */
static int run_free(emulator *m)
{
    uint32_t n;

    if (at_underrun(&m->core.engine)) {
        uint64_t now = now_ns();
        if (m->underrun_since_ns == 0)
            m->underrun_since_ns = now;
        if (now - m->underrun_since_ns < UNDERRUN_GRACE_NS)
            return 1;
    }
    m->underrun_since_ns = 0;
    for (n = 0; n < FREE_BATCH && in_motion(&m->core.engine); n++) {
        inject_hold(m);
        run_tick(m);
        if (at_underrun(&m->core.engine))
            break;
    }
    return 0;
}

static int poll_timeout_ms(emulator *m, int waiting_at_underrun)
{
    uint64_t left;

    if (!in_motion(&m->core.engine))
        return inputs_settling(m) || qs_core_watching_at_rest(&m->core) ? PACED_POLL_MS : -1;
    if (!m->opts.free_running)
        return PACED_POLL_MS;
    if (!waiting_at_underrun)
        return 0;
    left = UNDERRUN_GRACE_NS - (now_ns() - m->underrun_since_ns);
    return (int)(left / 1000000ull) + 1;
}

/* The exit summary: one JSON object on one line of stderr (README.md). */
static void summary(emulator *m)
{
    qs_status st;
    uint8_t axis;
    FILE *f = stderr;

    qs_core_status(&m->core, &st);
    fprintf(f, "{\"state\": \"%s\", \"alarm\": \"%s\", \"motion_ticks\": %lu, \"segments_done\": %lu, ",
            state_name(st.state), alarm_name(st.alarm), (unsigned long)st.motion_ticks,
            (unsigned long)st.segments_done);
    fprintf(f, "\"queue_fill\": %u, \"next_seq\": %u, ", st.queue_fill, st.next_seq);
    fprintf(f, "\"stalls\": %lu, ", (unsigned long)m->stalls);
    for (axis = 0; axis < m->opts.axes; axis++)
        fprintf(f, "\"position_%u\": %ld, \"steps_%u\": %llu, ", axis, (long)st.position[axis], axis,
                (unsigned long long)m->steps[axis]);
    fprintf(f,
            "\"rx_overrun\": %u, \"bad_frame\": %u, \"bad_crc\": %u, \"seq_gap\": %u, \"seq_dup\": %u, "
            "\"rejected\": %u, ",
            st.counters.rx_overrun, st.counters.bad_frame, st.counters.bad_crc, st.counters.seq_gap,
            st.counters.seq_dup, st.counters.rejected);
    fprintf(f,
            "\"frames_received\": %lu, \"frames_sent\": %lu, \"rx_frames_dropped\": %lu, "
            "\"rx_frames_corrupted\": %lu, \"tx_frames_dropped\": %lu, \"tx_bytes_discarded\": %lu, ",
            (unsigned long)m->faults.rx_frames, (unsigned long)emu_port_frames_sent(),
            (unsigned long)m->faults.rx_dropped, (unsigned long)m->faults.rx_corrupted,
            (unsigned long)m->faults.tx_dropped, (unsigned long)emu_port_bytes_discarded());
    fprintf(f, "\"inputs_active\": %u, \"latches_lost\": %u, \"output_pins\": %u, \"output_duty\": %u, ",
            m->core.inputs.active, m->core.engine.latches.lost, m->outputs.last.pins, m->outputs.last.duty);
    fprintf(f, "\"machine\": ");
    if (m->machine)
        machine_write_json(m->machine, f);
    else
        fputs("null", f);
    fputs("}\n", f);
}

int main(int argc, char **argv)
{
    emulator *m = &emu;
    struct sigaction sa;

    if (!emu_options_parse(&m->opts, argc, argv))
        return 2;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal; /* no SA_RESTART: poll returns at once */
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

    qs_core_init(&m->core);
    qs_core_configure(&m->core, m->opts.axes, m->opts.queue, m->opts.tick_hz);
    m->core.boot_id = m->opts.boot_id_set ? m->opts.boot_id : random_boot_id();
    {
        /* The inputs of a board with these axes: a min and a max limit per
         * axis, or one shared (--limit-pins 1), the probe and the buttons. */
        const uint16_t limits = (uint16_t)((1u << m->opts.axes) - 1u);
        const uint16_t present = (uint16_t)(0x0F00u | limits | (m->opts.limit_pins == 2 ? limits << 4 : 0));
        qs_inputs_init(&m->core.inputs, present);
        m->inputs_idle = present;
        m->inputs_seen = QS_INPUTS_RESAMPLE;
    }
    if (m->opts.machine_path) {
        static machine sim;
        char why[512];
        if (!machine_load(&sim, m->opts.machine_path, m->opts.axes, m->opts.limit_pins == 1, why, sizeof why)) {
            fprintf(stderr, "quadstep-emu: --machine %s\n", why);
            return 2;
        }
        m->machine = &sim;
    }
    emu_faults_init(&m->faults, &m->opts);
    emu_port_init(&m->faults);
    m->last_state = QS_STATE_IDLE;
    if (!emu_trace_open(&m->trace, m->opts.trace_path, m->machine != NULL)
        || !emu_outputs_open(&m->outputs, m->opts.outputs_path)
        || !emu_events_open(&m->events, m->opts.events_path) || !emu_link_open(&m->link, &m->opts))
        return 1;

    sample_inputs(m); /* the power-up sample: switches already closed are a state */
    while (!stop_requested) {
        struct pollfd fds[2];
        size_t pending;
        int waiting = m->opts.free_running && m->underrun_since_ns != 0;
        int n;

        emu_port_pending(&pending);
        n = emu_link_poll_setup(&m->link, fds, pending > 0);
        if (poll(fds, (nfds_t)n, poll_timeout_ms(m, waiting)) < 0 && errno != EINTR) {
            perror("quadstep-emu: poll");
            break;
        }
        if (emu_link_accept(&m->link, fds, n))
            emu_port_discard(); /* the previous client's unread reports */
        read_input(m);
        if (in_motion(&m->core.engine)) {
            m->idle_ref_ns = 0;
            if (m->opts.free_running)
                run_free(m);
            else
                run_paced(m);
        } else {
            m->underrun_since_ns = 0;
            settle_inputs(m);
            if (qs_core_watching_at_rest(&m->core)) {
                qs_core_poll(&m->core); /* the watchdog, as a board's resting ticks wake its loop */
                watch_state(m);
            }
        }
        write_output(m);
    }
    write_output(m);
    emu_trace_close(&m->trace);
    emu_outputs_close(&m->outputs);
    emu_events_close(&m->events);
    summary(m);
    emu_link_close(&m->link);
    return 0;
}

#endif
