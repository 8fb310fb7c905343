#include "emu_options.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qs_config.h"
#include "qs_protocol.h"

static const char usage[] =
    "usage: quadstep-emu [--pty | --tcp PORT] [--free] [--tick-hz N] [--axes N]\n"
    "                    [--queue N] [--trace FILE] [--outputs FILE] [--events FILE]\n"
    "                    [--machine FILE.toml] [--limit-pins 1|2] [--boot-id N]\n"
    "                    [--hold-at TICK:DECEL[,DECEL...]] [--drop-rx-frame K]...\n"
    "                    [--corrupt-rx-frame K]... [--drop-tx-frame K]...\n"
    "See firmware/native/README.md.\n";

/* A whole decimal number within [low, high]. */
static int number(const char *option, const char *text, unsigned long low, unsigned long high,
                  unsigned long *out)
{
    char *end;
    unsigned long value;

    if (!text) {
        fprintf(stderr, "quadstep-emu: %s needs a value (%lu..%lu)\n", option, low, high);
        return 0;
    }
    value = strtoul(text, &end, 10);
    if (*text < '0' || *text > '9' || *end != '\0' || value < low || value > high) {
        fprintf(stderr, "quadstep-emu: %s must be a whole number from %lu to %lu, got '%s'\n",
                option, low, high, text);
        return 0;
    }
    *out = value;
    return 1;
}

static int add_fault(emu_fault_list *list, const char *option, const char *text)
{
    unsigned long k;

    if (!number(option, text, 1, 0xFFFFFFFFul, &k))
        return 0;
    if (list->count == EMU_MAX_FAULTS) {
        fprintf(stderr, "quadstep-emu: at most %d %s options\n", EMU_MAX_FAULTS, option);
        return 0;
    }
    list->at[list->count++] = (uint32_t)k;
    return 1;
}

/* TICK:D or TICK:D0,D1,... (one deceleration for every axis, or one per
 * axis of --axes, checked once every option is known). */
static int hold_at(emu_options *o, const char *option, const char *text, int *count)
{
    char buf[128];
    char *colon, *item, *save = NULL;
    unsigned long v;

    if (!text || strlen(text) >= sizeof buf || !(colon = strchr(strcpy(buf, text), ':'))) {
        fprintf(stderr, "quadstep-emu: %s needs TICK:DECEL[,DECEL...], got '%s'\n", option,
                text ? text : "");
        return 0;
    }
    *colon = '\0';
    if (!number(option, buf, 0, 0xFFFFFFFFul, &v))
        return 0;
    o->hold_at_tick = (uint32_t)v;
    *count = 0;
    for (item = strtok_r(colon + 1, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        if (*count == 4) {
            fprintf(stderr, "quadstep-emu: %s takes at most 4 decelerations\n", option);
            return 0;
        }
        if (!number(option, item, 1, QS_DECEL_MAX, &v))
            return 0;
        o->hold_at_decel[(*count)++] = (uint16_t)v;
    }
    if (*count == 0) {
        fprintf(stderr, "quadstep-emu: %s needs a deceleration after the ':' (1..%d)\n", option,
                QS_DECEL_MAX);
        return 0;
    }
    o->hold_at_set = 1;
    return 1;
}

/* Spread one deceleration over every axis, or check there is one per axis. */
static int finish_hold_at(emu_options *o, int count)
{
    int axis;

    if (!o->hold_at_set)
        return 1;
    if (count != 1 && count != o->axes) {
        fprintf(stderr, "quadstep-emu: --hold-at gives %d decelerations for %d axes (give 1 or %d)\n",
                count, o->axes, o->axes);
        return 0;
    }
    for (axis = 0; axis < 4; axis++)
        o->hold_at_decel[axis] = axis >= o->axes ? 0 : o->hold_at_decel[count == 1 ? 0 : axis];
    return 1;
}

int emu_options_parse(emu_options *o, int argc, char **argv)
{
    int i, hold_count = 0;

    memset(o, 0, sizeof *o);
    o->tick_hz = 50000;
    o->axes = 4;
    o->queue = 32;
    o->limit_pins = 2;
    for (i = 1; i < argc; i++) {
        const char *opt = argv[i];
        const char *arg = i + 1 < argc ? argv[i + 1] : NULL;
        unsigned long v;

        if (strcmp(opt, "--pty") == 0) {
            o->tcp = 0;
            continue;
        }
        if (strcmp(opt, "--free") == 0) {
            o->free_running = 1;
            continue;
        }
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0) {
            fputs(usage, stdout);
            exit(0);
        }
        i++; /* every other option takes a value */
        if (strcmp(opt, "--tcp") == 0) {
            if (!number(opt, arg, 0, 65535, &v))
                return 0;
            o->tcp = 1;
            o->tcp_port = (uint16_t)v;
        } else if (strcmp(opt, "--tick-hz") == 0) {
            if (!number(opt, arg, 1, 10000000, &v))
                return 0;
            o->tick_hz = (uint32_t)v;
        } else if (strcmp(opt, "--axes") == 0) {
            if (!number(opt, arg, 1, QS_AXIS_COUNT, &v))
                return 0;
            o->axes = (uint8_t)v;
        } else if (strcmp(opt, "--queue") == 0) {
            if (!number(opt, arg, 1, QS_QUEUE_CAPACITY, &v))
                return 0;
            o->queue = (uint8_t)v;
        } else if (strcmp(opt, "--trace") == 0) {
            if (!arg) {
                fprintf(stderr, "quadstep-emu: --trace needs a file name\n");
                return 0;
            }
            o->trace_path = arg;
        } else if (strcmp(opt, "--outputs") == 0) {
            if (!arg) {
                fprintf(stderr, "quadstep-emu: --outputs needs a file name\n");
                return 0;
            }
            o->outputs_path = arg;
        } else if (strcmp(opt, "--events") == 0) {
            if (!arg) {
                fprintf(stderr, "quadstep-emu: --events needs a file name\n");
                return 0;
            }
            o->events_path = arg;
        } else if (strcmp(opt, "--machine") == 0) {
            if (!arg) {
                fprintf(stderr, "quadstep-emu: --machine needs a file name\n");
                return 0;
            }
            o->machine_path = arg;
        } else if (strcmp(opt, "--limit-pins") == 0) {
            if (!number(opt, arg, 1, 2, &v))
                return 0;
            o->limit_pins = (uint8_t)v;
        } else if (strcmp(opt, "--boot-id") == 0) {
            if (!number(opt, arg, 0, 65535, &v))
                return 0;
            o->boot_id_set = 1;
            o->boot_id = (uint16_t)v;
        } else if (strcmp(opt, "--hold-at") == 0) {
            if (!hold_at(o, opt, arg, &hold_count))
                return 0;
        } else if (strcmp(opt, "--drop-rx-frame") == 0) {
            if (!add_fault(&o->drop_rx, opt, arg))
                return 0;
        } else if (strcmp(opt, "--corrupt-rx-frame") == 0) {
            if (!add_fault(&o->corrupt_rx, opt, arg))
                return 0;
        } else if (strcmp(opt, "--drop-tx-frame") == 0) {
            if (!add_fault(&o->drop_tx, opt, arg))
                return 0;
        } else {
            fprintf(stderr, "quadstep-emu: unknown option '%s'\n%s", opt, usage);
            return 0;
        }
    }
    return finish_hold_at(o, hold_count);
}
