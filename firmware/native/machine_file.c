/* Reading the simulated machine's file (machine.md) into a machine. */
#include "machine.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "toml_lite.h"

typedef struct {
    toml_doc *doc;
    const char *file;
    char *err;
    size_t errlen;
    int ok;
} reader;

static void refuse(reader *r, const toml_entry *e, const char *why)
{
    if (!r->ok)
        return;
    r->ok = 0;
    if (e)
        snprintf(r->err, r->errlen, "%s:%d: %s = %g: %s", r->file, e->line, e->path, e->number, why);
    else
        snprintf(r->err, r->errlen, "%s: %s", r->file, why);
}

static double number(reader *r, const char *path, double fallback, double low, double high, int integer)
{
    toml_entry *e = toml_get(r->doc, path);
    char why[128];
    if (!e)
        return fallback;
    if (e->kind != TOML_NUMBER) {
        snprintf(why, sizeof why, "%s:%d: %s must be a number", r->file, e->line, path);
        if (r->ok) {
            r->ok = 0;
            snprintf(r->err, r->errlen, "%s", why);
        }
        return fallback;
    }
    if (integer && !e->is_integer) {
        refuse(r, e, "must be a whole number");
        return fallback;
    }
    if (e->number < low || e->number > high) {
        snprintf(why, sizeof why, "must be within %g .. %g", low, high);
        refuse(r, e, why);
        return fallback;
    }
    return e->number;
}

static int flag(reader *r, const char *path, int fallback)
{
    toml_entry *e = toml_get(r->doc, path);
    if (!e)
        return fallback;
    if (e->kind != TOML_BOOL && r->ok) {
        r->ok = 0;
        snprintf(r->err, r->errlen, "%s:%d: %s must be true or false", r->file, e->line, path);
    }
    return e->kind == TOML_BOOL ? (int)e->number : fallback;
}

static const char *text(reader *r, const char *path)
{
    toml_entry *e = toml_get(r->doc, path);
    if (!e)
        return NULL;
    if (e->kind != TOML_STRING && r->ok) {
        r->ok = 0;
        snprintf(r->err, r->errlen, "%s:%d: %s must be a \"string\"", r->file, e->line, path);
        return NULL;
    }
    return e->text;
}

static int has_table(reader *r, const char *prefix)
{
    size_t n = strlen(prefix);
    int i;
    for (i = 0; i < r->doc->count; i++)
        if (strncmp(r->doc->entry[i].path, prefix, n) == 0 && r->doc->entry[i].path[n] == '.')
            return 1;
    return 0;
}

#define BIG 1e9

static void read_switch(reader *r, const char *prefix, machine_switch *sw)
{
    char key[TOML_MAX_PATH];
#define KEY(name) (snprintf(key, sizeof key, "%s.%s", prefix, name), key)
    sw->present = has_table(r, prefix);
    if (!sw->present)
        return;
    if (!toml_get(r->doc, KEY("at"))) {
        snprintf(key, sizeof key, "%s needs `at` (the carriage position where it closes)", prefix);
        refuse(r, NULL, key);
    }
    sw->at = number(r, KEY("at"), 0, -BIG, BIG, 0);
    sw->hysteresis = number(r, KEY("hysteresis"), 0, 0, 1e6, 0);
    sw->normally_closed = flag(r, KEY("normally_closed"), 0);
    sw->bounce = (int)number(r, KEY("bounce"), 0, 0, 100, 1);
    sw->bounce_ticks = (int)number(r, KEY("bounce_ticks"), 20, 1, 100000, 1);
    sw->jitter = number(r, KEY("jitter"), 0, 0, 1e6, 0);
    sw->glitch = number(r, KEY("glitch"), 0, 0, 1, 0);
    sw->glitch_ticks = (int)number(r, KEY("glitch_ticks"), 1, 1, 100000, 1);
#undef KEY
}

static int input_number(const char *name)
{
    static const char *const names[] = {"limit_0", "limit_1", "limit_2", "limit_3", "limit_max_0",
                                        "limit_max_1", "limit_max_2", "limit_max_3", "probe", "abort",
                                        "feed_hold", "cycle_start"};
    int i;
    for (i = 0; i < MACHINE_INPUTS; i++)
        if (strcmp(names[i], name) == 0)
            return i;
    return -1;
}

static void read_axis(reader *r, machine *m, int i)
{
    machine_axis *a = &m->axis[i];
    char key[TOML_MAX_PATH];
#define KEY(name) (snprintf(key, sizeof key, "axis[%d].%s", i, name), key)
    a->backlash = number(r, KEY("backlash"), 0, 0, 1e6, 0);
    a->start = (long)number(r, KEY("start"), 0, -BIG, BIG, 1);
    a->carriage0 = number(r, KEY("carriage"), (double)a->start, -BIG, BIG, 0);
    if (fabs(a->carriage0 - (double)a->start) > a->backlash / 2 + 1e-9) {
        toml_entry *e = toml_get(r->doc, KEY("carriage"));
        refuse(r, e, "must be within half the backlash of `start` (the carriage sits in the dead band)");
    }
    a->has_hard_min = toml_get(r->doc, KEY("hard_min")) != NULL;
    a->hard_min = number(r, KEY("hard_min"), -BIG, -BIG, BIG, 0);
    a->has_hard_max = toml_get(r->doc, KEY("hard_max")) != NULL;
    a->hard_max = number(r, KEY("hard_max"), BIG, -BIG, BIG, 0);
    snprintf(key, sizeof key, "axis[%d].limit_min", i);
    read_switch(r, key, &a->min);
    snprintf(key, sizeof key, "axis[%d].limit_max", i);
    read_switch(r, key, &a->max);
#undef KEY
}

static void read_target(reader *r, machine *m, int i)
{
    machine_target *t = &m->target[i];
    char key[TOML_MAX_PATH];
    const char *kind;
#define KEY(name) (snprintf(key, sizeof key, "probe.target[%d].%s", i, name), key)
    kind = text(r, KEY("kind"));
    t->z = number(r, KEY("z"), 0, -BIG, BIG, 0);
    if (!kind || strcmp(kind, "plate") == 0) {
        t->kind = TARGET_PLATE;
        t->bounded = toml_get(r->doc, KEY("x_min")) != NULL;
    } else if (strcmp(kind, "block") == 0) {
        t->kind = TARGET_BLOCK;
    } else if (strcmp(kind, "bore") == 0) {
        t->kind = TARGET_BORE;
    } else {
        snprintf(key, sizeof key, "probe.target[%d].kind = \"%s\": must be \"plate\", \"block\" or \"bore\"", i, kind);
        refuse(r, NULL, key);
        return;
    }
    if (t->kind == TARGET_BORE) {
        t->x = number(r, KEY("x"), 0, -BIG, BIG, 0);
        t->y = number(r, KEY("y"), 0, -BIG, BIG, 0);
        t->radius_x = number(r, KEY("radius_x"), 1, 1e-6, BIG, 0);
        t->radius_y = number(r, KEY("radius_y"), t->radius_x, 1e-6, BIG, 0);
    } else {
        t->x_min = number(r, KEY("x_min"), -BIG, -BIG, BIG, 0);
        t->x_max = number(r, KEY("x_max"), BIG, -BIG, BIG, 0);
        t->y_min = number(r, KEY("y_min"), -BIG, -BIG, BIG, 0);
        t->y_max = number(r, KEY("y_max"), BIG, -BIG, BIG, 0);
    }
#undef KEY
}

int machine_load(machine *m, const char *path, int axes, int shared_limits, char *err, size_t errlen)
{
    static toml_doc doc;
    reader r = {&doc, path, err, errlen, 1};
    const toml_entry *extra;
    int i, n;

    memset(m, 0, sizeof *m);
    snprintf(m->path, sizeof m->path, "%s", path);
    if (!toml_read(&doc, path, err, errlen))
        return 0;
    m->axes = axes;
    m->shared_limits = shared_limits;
    m->seed = (uint64_t)number(&r, "seed", 1, 0, 9007199254740992.0, 1);
    n = toml_array_length(&doc, "axis");
    if (n > axes) {
        snprintf(err, errlen, "%s: %d [[axis]] tables for %d axes", path, n, axes);
        return 0;
    }
    for (i = 0; i < n; i++)
        read_axis(&r, m, i);
    m->probe_present = has_table(&r, "probe");
    if (m->probe_present) {
        m->probe.present = 1;
        m->probe.hysteresis = number(&r, "probe.hysteresis", 0, 0, 1e6, 0);
        m->probe.normally_closed = flag(&r, "probe.normally_closed", 0);
        m->probe.bounce = (int)number(&r, "probe.bounce", 0, 0, 100, 1);
        m->probe.bounce_ticks = (int)number(&r, "probe.bounce_ticks", 20, 1, 100000, 1);
        m->probe.glitch = number(&r, "probe.glitch", 0, 0, 1, 0);
        m->probe.glitch_ticks = (int)number(&r, "probe.glitch_ticks", 1, 1, 100000, 1);
        m->probe_axis[0] = (int)number(&r, "probe.x", 0, 0, axes - 1, 1);
        m->probe_axis[1] = (int)number(&r, "probe.y", axes > 1 ? 1 : 0, 0, axes - 1, 1);
        m->probe_axis[2] = (int)number(&r, "probe.z", axes > 2 ? 2 : axes - 1, 0, axes - 1, 1);
        m->targets = toml_array_length(&doc, "probe.target");
        if (m->targets > MACHINE_TARGETS) {
            snprintf(err, errlen, "%s: at most %d [[probe.target]] tables", path, MACHINE_TARGETS);
            return 0;
        }
        for (i = 0; i < m->targets; i++)
            read_target(&r, m, i);
    }
    m->scripts = toml_array_length(&doc, "press");
    if (m->scripts > MACHINE_SCRIPTS) {
        snprintf(err, errlen, "%s: at most %d [[press]] tables", path, MACHINE_SCRIPTS);
        return 0;
    }
    for (i = 0; i < m->scripts && r.ok; i++) {
        char key[128];
        const char *name;
        snprintf(key, sizeof key, "press[%d].input", i);
        name = text(&r, key);
        m->script[i].input = name ? input_number(name) : -1;
        if (m->script[i].input < 0) {
            snprintf(key, sizeof key, "press[%d].input: name an input (abort, feed_hold, probe, limit_0, ...)", i);
            refuse(&r, NULL, key);
            break;
        }
        snprintf(key, sizeof key, "press[%d].at_tick", i);
        m->script[i].at_tick = (uint32_t)number(&r, key, 0, 0, 4294967295.0, 1);
        snprintf(key, sizeof key, "press[%d].ticks", i);
        m->script[i].ticks = (uint32_t)number(&r, key, 1, 1, 4294967295.0, 1);
    }
    if (r.ok && (extra = toml_unused(&doc)) != NULL) {
        snprintf(err, errlen, "%s:%d: unknown key %s (machine.md lists them)", path, extra->line, extra->path);
        return 0;
    }
    if (!r.ok)
        return 0;
    machine_start(m);
    return 1;
}
