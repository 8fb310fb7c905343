/* qs-simavr: runs the real AVR firmware ELF in simavr with its serial line
 * on a pseudo-terminal (or stdin/stdout, a byte file, or a flow-controlled
 * frame feeder), recording step/direction edges, a step trace in the
 * emulator's format, interrupt costs and the stack high-water mark.
 * README.md in this directory describes the options and outputs. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim_avr.h"
#include "sim_elf.h"

#include "sim_board.h"
#include "sim_feed.h"
#include "sim_isr.h"
#include "sim_link.h"
#include "sim_motion.h"
#include "sim_outputs.h"
#include "sim_profile.h"
#include "sim_stack.h"
#include "sim_wire.h"

#define PROBE_SYMBOL "qs_debug_probe"
#define PROBE_VERSION 5
#define PROBE_WORDS 8
#define SERVICE_HZ 2000   /* host I/O and pacing checks per simulated second */
#define IDLE_QUIET_MS 5   /* --exit-when-idle: line quiet this long first */
#define LONGEST_TICK_STEPS 1024 /* --longest-tick: instructions kept per interrupt */

typedef struct {
    const char *mcu;
    const char *elf;
    int pty, stdio_link;
    const char *input, *feed, *output, *trace, *edges, *outputs, *stats, *profile, *profile_pc, *longest, *machine;
    uint32_t input_delay;
    uint64_t max_cycles;
    int realtime; /* -1: default for the link */
    int exit_when_idle;
    uint32_t frequency;
} options;

typedef struct {
    avr_t *avr;
    const sim_board *board;
    sim_wire *wire;
    sim_link *link;
    sim_feed *feed;
    FILE *output;
    sim_motion *motion;
    machine *mach;
    sim_inputs *inputs;
    sim_isr *isr_timer, *isr_rx, *isr_udre;
    FILE *trace, *edges, *outputs;
    sim_profile *profile;    /* symbols always; cycles only with --profile */
    int profiling;
    uint16_t static_end;
    uint64_t sleep_cycles;
    uint64_t irq_off_max;    /* longest stretch with interrupts off outside the tick */
    uint32_t irq_off_max_pc; /* where it began */
    /* --longest-tick: the instructions of the tick interrupt running now,
     * and those of the longest so far, with the cycles each took */
    uint32_t tick_pc[LONGEST_TICK_STEPS], longest_pc[LONGEST_TICK_STEPS];
    uint8_t tick_cycles_of[LONGEST_TICK_STEPS], longest_cycles_of[LONGEST_TICK_STEPS];
    uint32_t tick_steps, longest_steps;
    uint64_t longest_total, longest_at;
} harness;

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

/* --longest-tick: keep the instructions of every tick interrupt while it
 * runs, and those of the longest one. */
static void note_tick_step(harness *h, int was_inside, uint32_t pc, uint64_t cycles)
{
    if (sim_isr_inside(h->isr_timer) || was_inside) {
        if (h->tick_steps < LONGEST_TICK_STEPS) {
            h->tick_pc[h->tick_steps] = pc;
            h->tick_cycles_of[h->tick_steps] = (uint8_t)cycles;
            h->tick_steps++;
        }
    }
    if (was_inside && !sim_isr_inside(h->isr_timer)) {
        uint64_t total = 0;
        for (uint32_t i = 0; i < h->tick_steps; i++) {
            total += h->tick_cycles_of[i];
        }
        if (total > h->longest_total) {
            h->longest_total = total;
            h->longest_at = h->avr->cycle;
            h->longest_steps = h->tick_steps;
            memcpy(h->longest_pc, h->tick_pc, sizeof h->tick_pc[0] * h->tick_steps);
            memcpy(h->longest_cycles_of, h->tick_cycles_of, sizeof h->tick_cycles_of[0] * h->tick_steps);
        }
        h->tick_steps = 0;
    }
}

/* CSV `address,function,cycles`, in the order they ran. */
static void write_longest_tick(const harness *h, FILE *out)
{
    fprintf(out, "# longest tick interrupt: %llu cycles, ended at cycle %llu\n",
            (unsigned long long)h->longest_total, (unsigned long long)h->longest_at);
    fprintf(out, "address,function,cycles\n");
    for (uint32_t i = 0; i < h->longest_steps; i++) {
        fprintf(out, "0x%05x,%s,%u\n", (unsigned)h->longest_pc[i], sim_profile_name(h->profile, h->longest_pc[i]),
                (unsigned)h->longest_cycles_of[i]);
    }
}

/* The chip takes an interrupt whose flag is already up when its enable bit
 * is set; simavr makes one pending only as its flag rises while enabled.
 * The firmware ends the tick's rest so (step_timer_wake: a match that fell
 * due meanwhile runs at once), so the harness raises the tick's vector
 * then, as the chip would. */
static avr_int_vector_t *find_vector(avr_t *avr, uint8_t number)
{
    for (uint8_t i = 0; i < avr->interrupts.vector_count; i++) {
        if (avr->interrupts.vector[i]->vector == number) {
            return avr->interrupts.vector[i];
        }
    }
    return NULL;
}

static void take_flag_up_when_enabled(avr_t *avr, avr_int_vector_t *v)
{
    if (!v->pending && avr_regbit_get(avr, v->enable) && avr_regbit_get(avr, v->raised)) {
        avr_raise_interrupt(avr, v);
    }
}

static void usage(void)
{
    fprintf(stderr,
            "usage: qs-simavr --mcu atmega328p|atmega2560 --elf FILE\n"
            "        [--pty | --stdio | --input FILE | --feed FILE] [--output FILE]\n"
            "        [--trace FILE] [--edges FILE] [--outputs FILE] [--stats FILE] [--profile FILE] [--profile-pc FILE]\n"
            "        [--longest-tick FILE] [--max-cycles N] [--realtime | --free] [--exit-when-idle] [--freq HZ]\n"
            "        [--machine FILE.toml] [--input-delay CYCLES]\n");
}

static int parse_options(int argc, char **argv, options *o)
{
    *o = (options){.realtime = -1, .frequency = 16000000};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        const char **text = NULL;
        if (!strcmp(a, "--pty")) {
            o->pty = 1;
        } else if (!strcmp(a, "--stdio")) {
            o->stdio_link = 1;
        } else if (!strcmp(a, "--realtime")) {
            o->realtime = 1;
        } else if (!strcmp(a, "--free")) {
            o->realtime = 0;
        } else if (!strcmp(a, "--exit-when-idle")) {
            o->exit_when_idle = 1;
        } else if (!strcmp(a, "--mcu")) {
            text = &o->mcu;
        } else if (!strcmp(a, "--elf")) {
            text = &o->elf;
        } else if (!strcmp(a, "--input")) {
            text = &o->input;
        } else if (!strcmp(a, "--feed")) {
            text = &o->feed;
        } else if (!strcmp(a, "--output")) {
            text = &o->output;
        } else if (!strcmp(a, "--trace")) {
            text = &o->trace;
        } else if (!strcmp(a, "--edges")) {
            text = &o->edges;
        } else if (!strcmp(a, "--outputs")) {
            text = &o->outputs;
        } else if (!strcmp(a, "--stats")) {
            text = &o->stats;
        } else if (!strcmp(a, "--profile")) {
            text = &o->profile;
        } else if (!strcmp(a, "--profile-pc")) {
            text = &o->profile_pc;
        } else if (!strcmp(a, "--longest-tick")) {
            text = &o->longest;
        } else if (!strcmp(a, "--machine")) {
            text = &o->machine;
        } else if (!strcmp(a, "--input-delay") && v) {
            o->input_delay = (uint32_t)strtoul(v, NULL, 0);
            i++;
        } else if (!strcmp(a, "--max-cycles") && v) {
            o->max_cycles = strtoull(v, NULL, 0);
            i++;
        } else if (!strcmp(a, "--freq") && v) {
            o->frequency = (uint32_t)strtoul(v, NULL, 0);
            i++;
        } else {
            fprintf(stderr, "qs-simavr: unknown or incomplete option %s\n", a);
            return -1;
        }
        if (text) {
            if (!v) {
                fprintf(stderr, "qs-simavr: %s needs a value\n", a);
                return -1;
            }
            *text = v;
            i++;
        }
    }
    if (!o->mcu || !o->elf) {
        fprintf(stderr, "qs-simavr: --mcu and --elf are required\n");
        return -1;
    }
    if (o->pty + o->stdio_link + (o->input != NULL) + (o->feed != NULL) > 1) {
        fprintf(stderr, "qs-simavr: choose one of --pty, --stdio, --input, --feed\n");
        return -1;
    }
    if (o->realtime < 0) {
        o->realtime = o->pty || o->stdio_link;
    }
    return 0;
}

static uint32_t find_symbol(const elf_firmware_t *fw, const char *name, int *found)
{
    for (uint32_t i = 0; i < fw->symbolcount; i++) {
        if (!strcmp(fw->symbol[i]->symbol, name)) {
            *found = 1;
            return fw->symbol[i]->addr;
        }
    }
    *found = 0;
    return 0;
}

static int read_probe(const avr_t *avr, const elf_firmware_t *fw, sim_probe *p)
{
    int found;
    const uint32_t at = find_symbol(fw, PROBE_SYMBOL, &found);
    if (!found || at + 2 * PROBE_WORDS > avr->flashend) {
        fprintf(stderr, "qs-simavr: %s not in the ELF (the firmware publishes it)\n", PROBE_SYMBOL);
        return -1;
    }
    uint16_t word[PROBE_WORDS];
    for (int i = 0; i < PROBE_WORDS; i++) {
        word[i] = (uint16_t)(avr->flash[at + 2 * i] | (avr->flash[at + 2 * i + 1] << 8));
    }
    if (word[0] != PROBE_VERSION) {
        fprintf(stderr, "qs-simavr: %s layout %u, expected %u\n", PROBE_SYMBOL, word[0], PROBE_VERSION);
        return -1;
    }
    *p = (sim_probe){word[1], word[2], word[3], word[4], word[5], word[6], word[7]};
    return 0;
}

static void on_board_byte(void *ctx, uint8_t byte)
{
    harness *h = ctx;
    if (h->link) {
        sim_link_put(h->link, byte);
    }
    if (h->output) {
        fputc(byte, h->output);
    }
    if (h->feed) {
        sim_feed_board_byte(h->feed, byte);
    }
}

/* simavr's default sleep callback keeps wall time by sleeping; pacing is
 * done here instead (or not at all when running free). */
/* simavr's messages go to stderr, errors only: stdout carries the PORT
 * line (or, with --stdio, the board's bytes). */
static void log_errors(avr_t *avr, const int level, const char *format, va_list ap)
{
    (void)avr;
    if (level <= LOG_ERROR) {
        vfprintf(stderr, format, ap);
    }
}

static void sleep_nothing(avr_t *avr, avr_cycle_count_t how_long)
{
    (void)avr;
    (void)how_long;
}

static FILE *open_out(const char *path)
{
    if (!path) {
        return NULL;
    }
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(2);
    }
    return f;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

static int load_input(harness *h, const char *path)
{
    FILE *in = fopen(path, "rb");
    if (!in) {
        perror(path);
        return -1;
    }
    uint8_t buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0) {
        sim_wire_send(h->wire, buf, n);
    }
    fclose(in);
    return 0;
}

static void json_cost(FILE *f, const char *name, sim_cost c, const char *end)
{
    fprintf(f, "\"%s\": {\"count\": %llu, \"total\": %llu, \"min\": %u, \"max\": %u, \"mean\": %.3f}%s", name,
            (unsigned long long)c.count, (unsigned long long)c.total, c.count ? c.min : 0, c.max,
            c.count ? (double)c.total / (double)c.count : 0.0, end);
}

static void write_stats(const harness *h, const char *path)
{
    FILE *f = open_out(path);
    const sim_motion_stats m = sim_motion_get_stats(h->motion);
    const sim_wire_stats w = sim_wire_get_stats(h->wire);
    const sim_stack_stats s = sim_stack_measure(h->avr, h->static_end);
    /* Timer1's period as the firmware set it: OCR1A + 1 (same address on both chips). */
    const unsigned tick_cycles = (h->avr->data[0x88] | (h->avr->data[0x89] << 8)) + 1u;
    fprintf(f, "{\n\"mcu\": \"%s\", \"frequency\": %u, \"tick_cycles\": %u, \"cycles\": %llu, "
               "\"sleep_cycles\": %llu,\n",
            h->board->mcu, h->avr->frequency, tick_cycles, (unsigned long long)h->avr->cycle,
            (unsigned long long)h->sleep_cycles);
    fprintf(f, "\"isr\": {");
    json_cost(f, "timer", sim_isr_cost(h->isr_timer), ", ");
    json_cost(f, "uart_rx", sim_isr_cost(h->isr_rx), ", ");
    json_cost(f, "uart_udre", sim_isr_cost(h->isr_udre), "},\n");
    fprintf(f, "\"tick_isr\": {");
    json_cost(f, "idle", m.idle, ", ");
    for (int k = 0; k <= h->board->axes; k++) {
        char name[16];
        snprintf(name, sizeof name, "steps%d", k);
        json_cost(f, name, m.running[k], k == h->board->axes ? "},\n" : ", ");
    }
    fprintf(f, "\"motion\": {\"motion_ticks\": %u, \"state\": %u, \"steps\": [",
            m.motion_ticks, m.state);
    for (int k = 0; k < h->board->axes; k++) {
        fprintf(f, "%llu%s", (unsigned long long)m.steps[k], k + 1 < h->board->axes ? ", " : "], ");
    }
    fprintf(f, "\"min_pulse\": %u, \"min_dir_setup\": %u, \"min_dir_after_fall\": %u, \"dir_changes\": %llu, "
               "\"tick_late_max\": %u, \"ticks_missed\": %llu},\n",
            m.min_pulse, m.min_dir_setup, m.min_dir_after_fall, (unsigned long long)m.dir_changes,
            m.tick_late_max, (unsigned long long)m.ticks_missed);
    fprintf(f, "\"wire\": {\"cycles_per_byte\": %u, \"host_bytes\": %llu, \"delivered\": %llu, \"lost\": %llu, \"board_bytes\": %llu},\n",
            sim_wire_cycles_per_byte(h->wire), (unsigned long long)w.host_bytes,
            (unsigned long long)w.delivered, (unsigned long long)w.lost, (unsigned long long)w.board_bytes);
    fprintf(f, "\"irq_off\": {\"max\": %llu, \"from\": \"%s\"},\n", (unsigned long long)h->irq_off_max,
            h->irq_off_max ? sim_profile_name(h->profile, h->irq_off_max_pc) : "");
    fprintf(f, "\"stack\": {\"static_end\": %u, \"ram_end\": %u, \"deepest\": %u, \"max_bytes\": %u},\n",
            s.static_end, s.ram_end, s.deepest, s.max_bytes);
    sim_inputs_write_json(h->inputs, f);
    if (h->feed) {
        const sim_feed_stats fs = sim_feed_get_stats(h->feed);
        fprintf(f, ",\n\"feed\": {\"frames\": %llu, \"sent\": %llu, \"accepted\": %llu, \"rejected\": %llu, "
                   "\"gap\": %llu, \"duplicate\": %llu, \"queue_full\": %llu, \"space\": %llu, "
                   "\"alarms\": %llu, \"holds\": %llu, \"errors\": %llu, \"bad_replies\": %llu, "
                   "\"first_accept_cycle\": %llu, \"last_accept_cycle\": %llu, "
                   "\"first_alarm_cycle\": %llu, \"first_alarm_code\": %u}",
                (unsigned long long)fs.frames, (unsigned long long)fs.sent,
                (unsigned long long)fs.accepted, (unsigned long long)fs.rejected,
                (unsigned long long)fs.gap, (unsigned long long)fs.duplicate,
                (unsigned long long)fs.queue_full, (unsigned long long)fs.space,
                (unsigned long long)fs.alarms, (unsigned long long)fs.holds, (unsigned long long)fs.errors,
                (unsigned long long)fs.bad_replies, (unsigned long long)fs.first_accept_cycle,
                (unsigned long long)fs.last_accept_cycle, (unsigned long long)fs.first_alarm_cycle,
                fs.first_alarm_code);
    }
    fprintf(f, "\n}\n");
    fclose(f);
}

static void print_summary(const harness *h)
{
    const sim_motion_stats m = sim_motion_get_stats(h->motion);
    const sim_wire_stats w = sim_wire_get_stats(h->wire);
    const sim_stack_stats s = sim_stack_measure(h->avr, h->static_end);
    const sim_cost t = sim_isr_cost(h->isr_timer);
    fprintf(stderr, "cycles=%llu\n", (unsigned long long)h->avr->cycle);
    fprintf(stderr, "motion_ticks=%u\nstate=%u\n", m.motion_ticks, m.state);
    for (int k = 0; k < h->board->axes; k++) {
        fprintf(stderr, "steps_%d=%llu\n", k, (unsigned long long)m.steps[k]);
    }
    fprintf(stderr, "tick_isr_max=%u\n", t.max);
    fprintf(stderr, "wire_lost=%llu\n", (unsigned long long)w.lost);
    fprintf(stderr, "stack_max_bytes=%u\n", s.max_bytes);
}

/* Host I/O, pacing and the exit checks; returns 0 to stop. */
static int service(harness *h, const options *o, double wall_start, int *stdin_ended)
{
    if (h->link) {
        uint8_t buf[4096];
        size_t n;
        while ((n = sim_link_read(h->link, buf, sizeof buf, stdin_ended)) > 0) {
            sim_wire_send(h->wire, buf, n);
        }
        sim_link_flush(h->link);
    }
    if (o->realtime) {
        /* Never run ahead of the wall clock: a real board doesn't. */
        const double ahead = (double)h->avr->cycle / h->avr->frequency - (now_seconds() - wall_start);
        if (ahead > 0.0005) {
            struct timespec ts = {0, (long)(ahead * 1e9)};
            nanosleep(&ts, NULL);
        }
    }
    if (o->max_cycles && h->avr->cycle >= o->max_cycles) {
        return 0;
    }
    if (o->exit_when_idle || h->feed) {
        const uint64_t quiet = (uint64_t)h->avr->frequency / 1000 * IDLE_QUIET_MS;
        const int line_quiet = sim_wire_backlog(h->wire) == 0 &&
                               h->avr->cycle > sim_wire_last_start(h->wire) + quiet;
        const uint8_t state = sim_motion_state(h->motion);
        const int engine_rests = state != 1 && state != 3; /* not RUNNING, not HOLDING */
        const int feed_done = !h->feed || sim_feed_finished(h->feed);
        const int host_done = !o->stdio_link || *stdin_ended;
        if (line_quiet && engine_rests && feed_done && host_done) {
            return 0;
        }
    }
    if (sim_motion_state(h->motion) != 1) { /* at rest: make the files complete so far */
        if (h->trace) {
            fflush(h->trace);
        }
        if (h->edges) {
            fflush(h->edges);
        }
    }
    return !stop_requested;
}

int main(int argc, char **argv)
{
    options o;
    if (parse_options(argc, argv, &o) != 0) {
        usage();
        return 2;
    }
    harness h = {0};
    h.board = sim_board_find(o.mcu);
    if (!h.board) {
        fprintf(stderr, "qs-simavr: unknown MCU %s (atmega328p or atmega2560)\n", o.mcu);
        return 2;
    }
    avr_global_logger_set(log_errors);
    elf_firmware_t fw;
    if (elf_read_firmware(o.elf, &fw) != 0) {
        fprintf(stderr, "qs-simavr: cannot read %s\n", o.elf);
        return 2;
    }
    h.avr = avr_make_mcu_by_name(o.mcu);
    if (!h.avr) {
        fprintf(stderr, "qs-simavr: simavr does not know %s\n", o.mcu);
        return 2;
    }
    avr_init(h.avr);
    h.avr->log = LOG_NONE;
    h.avr->frequency = o.frequency;
    h.avr->sleep = sleep_nothing;
    avr_load_firmware(h.avr, &fw);
    h.avr->frequency = o.frequency;

    sim_probe probe;
    if (read_probe(h.avr, &fw, &probe) != 0) {
        return 2;
    }
    int found;
    /* End of .data/.bss; ELF data addresses carry a 0x800000 offset. */
    h.static_end = (uint16_t)(find_symbol(&fw, "__bss_end", &found) & 0xFFFF);
    if (!found) {
        fprintf(stderr, "qs-simavr: __bss_end not in the ELF\n");
        return 2;
    }
    sim_stack_paint(h.avr, h.static_end);

    h.trace = open_out(o.trace);
    h.edges = open_out(o.edges);
    h.outputs = open_out(o.outputs);
    h.output = open_out(o.output);
    h.wire = sim_wire_attach(h.avr, on_board_byte, &h);
    if (o.machine) {
        static machine mach;
        char why[512];
        if (!machine_load(&mach, o.machine, h.board->axes, h.board->shared_limits, why, sizeof why)) {
            fprintf(stderr, "qs-simavr: --machine %s\n", why);
            return 2;
        }
        h.mach = &mach;
    }
    h.inputs = sim_inputs_attach(h.avr, h.board, h.mach, o.input_delay);
    h.motion = sim_motion_attach(h.avr, h.board, &probe, h.trace, h.edges, h.inputs, h.mach);
    h.isr_timer = sim_isr_watch(h.avr, h.board->timer_vector, sim_motion_tick_enter,
                                sim_motion_tick_done, h.motion);
    h.isr_rx = sim_isr_watch(h.avr, h.board->rx_vector, NULL, NULL, NULL);
    h.isr_udre = sim_isr_watch(h.avr, h.board->udre_vector, NULL, NULL, NULL);
    if (!h.wire || !h.inputs || !h.motion || !h.isr_timer || !h.isr_rx || !h.isr_udre
        || sim_isr_watch_also(h.isr_timer, h.board->rest_vector) != 0
        || sim_outputs_attach(h.avr, h.board, h.outputs) != 0) {
        fprintf(stderr, "qs-simavr: cannot attach to the simulated %s\n", o.mcu);
        return 2;
    }
    if (o.pty) {
        h.link = sim_link_open_pty();
    } else if (o.stdio_link) {
        h.link = sim_link_open_stdio();
    }
    if ((o.pty || o.stdio_link) && !h.link) {
        return 2;
    }
    if (o.input && load_input(&h, o.input) != 0) {
        return 2;
    }
    if (o.feed) {
        h.feed = sim_feed_open(h.avr, h.wire, o.feed);
        if (!h.feed) {
            return 2;
        }
        sim_feed_start(h.feed);
    }

    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    const uint64_t service_every = h.avr->frequency / SERVICE_HZ;
    uint64_t next_service = 0;
    const double wall_start = now_seconds();
    int stdin_ended = 0;
    int crashed = 0;
    h.profile = sim_profile_new(&fw, h.avr);
    h.profiling = o.profile != NULL || o.profile_pc != NULL;
    avr_int_vector_t *tick_vector = find_vector(h.avr, h.board->timer_vector);
    if (!tick_vector) {
        fprintf(stderr, "qs-simavr: no timer vector %u\n", h.board->timer_vector);
        return 2;
    }
    int irq_on = 0;
    uint64_t irq_off_since = 0;
    uint32_t irq_off_pc = 0;
    for (;;) {
        const int was_sleeping = h.avr->state == cpu_Sleeping;
        const uint64_t before = h.avr->cycle;
        const uint32_t pc = h.avr->pc;
        const int in_tick = o.longest && sim_isr_inside(h.isr_timer);
        const int state = avr_run(h.avr);
        take_flag_up_when_enabled(h.avr, tick_vector);
        if (o.longest) {
            note_tick_step(&h, in_tick, pc, h.avr->cycle - before);
        }
        if (was_sleeping) {
            h.sleep_cycles += h.avr->cycle - before;
        } else if (h.profiling) {
            sim_profile_add(h.profile, pc, h.avr->cycle - before);
        }
        /* Interrupts held off by the main loop (the tick's own run is
         * excluded: it is measured as the tick's cost). */
        if (h.avr->sreg[S_I] != irq_on) {
            irq_on = h.avr->sreg[S_I];
            if (!irq_on && !sim_isr_inside(h.isr_timer)) {
                irq_off_since = before;
                irq_off_pc = pc;
            } else if (irq_on && irq_off_since) {
                if (before - irq_off_since > h.irq_off_max) {
                    h.irq_off_max = before - irq_off_since;
                    h.irq_off_max_pc = irq_off_pc;
                }
                irq_off_since = 0;
            }
        }
        if (state == cpu_Done || state == cpu_Crashed) {
            crashed = state == cpu_Crashed;
            fprintf(stderr, "qs-simavr: the firmware %s at cycle %llu\n",
                    crashed ? "crashed" : "stopped", (unsigned long long)h.avr->cycle);
            break;
        }
        if (h.avr->cycle >= next_service) {
            next_service = h.avr->cycle + service_every;
            if (!service(&h, &o, wall_start, &stdin_ended)) {
                break;
            }
        }
    }

    if (h.trace) {
        fclose(h.trace);
    }
    if (h.outputs) {
        fclose(h.outputs);
    }
    if (h.edges) {
        fclose(h.edges);
    }
    if (h.output) {
        fclose(h.output);
    }
    if (h.link) {
        sim_link_flush(h.link);
    }
    if (o.stats) {
        write_stats(&h, o.stats);
    }
    if (o.profile) {
        FILE *f = open_out(o.profile);
        sim_profile_write(h.profile, f);
        fclose(f);
    }
    if (o.longest) {
        FILE *f = open_out(o.longest);
        write_longest_tick(&h, f);
        fclose(f);
    }
    if (o.profile_pc) {
        FILE *f = open_out(o.profile_pc);
        sim_profile_write_pc(h.profile, f);
        fclose(f);
    }
    print_summary(&h);
    return crashed ? 1 : 0;
}
