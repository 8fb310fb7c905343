#include "machine.h"

#include <math.h>
#include <string.h>

#define PROBE_INPUT 8

/* xorshift64*: the same sequence wherever the machine runs. */
static uint64_t next_random(machine *m)
{
    m->rng ^= m->rng >> 12;
    m->rng ^= m->rng << 25;
    m->rng ^= m->rng >> 27;
    return m->rng * 2685821657736338717ull;
}

static double uniform(machine *m)
{
    return (double)(next_random(m) >> 11) / 9007199254740992.0;
}

static uint8_t level_of(const machine_pin *p, int actuated)
{
    /* Pulled up; a normally open switch grounds the pin when actuated, a
     * normally closed one when at rest. */
    return (uint8_t)(p->normally_closed ? actuated : !actuated);
}

static void log_event(machine *m, int input, char cause)
{
    machine_event *e;
    int axis;

    if (m->events == MACHINE_EVENTS) {
        m->events_dropped++;
        return;
    }
    e = &m->event[m->events++];
    e->sample = m->sample;
    e->tick = m->motion_tick;
    e->input = (uint8_t)input;
    e->level = m->pin[input].level;
    e->active = (uint8_t)m->pin[input].actuated;
    e->cause = cause;
    for (axis = 0; axis < MACHINE_AXES; axis++)
        e->carriage[axis] = axis < m->axes ? m->axis[axis].carriage : 0.0;
}

static void set_level(machine *m, int input, uint8_t level, char cause)
{
    if (m->pin[input].level == level)
        return;
    m->pin[input].level = level;
    log_event(m, input, cause);
}

/* The mechanics say input is (or is not) actuated: the pin follows at
 * once (the first contact is exact), then bounces. */
static void actuate(machine *m, int input, int actuated, const machine_switch *sw)
{
    machine_pin *p = &m->pin[input];

    if (p->actuated == actuated)
        return;
    p->actuated = actuated;
    p->glitch_until = 0;
    set_level(m, input, level_of(p, actuated), sw ? 's' : 'p');
    p->bounce_left = sw && sw->bounce > 0 ? 2 * sw->bounce : 0;
    if (p->bounce_left) {
        const int gap = sw->bounce_ticks / (2 * sw->bounce) > 1 ? sw->bounce_ticks / (2 * sw->bounce) : 1;
        p->next_toggle = m->sample + 1 + next_random(m) % (uint64_t)gap;
    }
}

/* One switch of an axis against its carriage: closes at its point (moved
 * by the jitter each time it opens), opens the hysteresis back. */
static int switch_closed(machine *m, machine_switch *sw, double carriage, int is_min)
{
    if (!sw->present)
        return 0;
    if (!sw->closed) {
        if (is_min ? carriage <= sw->point : carriage >= sw->point)
            sw->closed = 1;
    } else if (is_min ? carriage >= sw->point + sw->hysteresis : carriage <= sw->point - sw->hysteresis) {
        sw->closed = 0;
        sw->point = sw->at + (sw->jitter > 0 ? (2 * uniform(m) - 1) * sw->jitter : 0);
    }
    return sw->closed;
}

static int scripted(const machine *m, int input)
{
    int i;
    for (i = 0; i < m->scripts; i++)
        if (m->script[i].input == input && m->script[i].state == 1)
            return 1;
    return 0;
}

/* How far the tool is into a target (negative: that far clear of it). */
static double penetration(const machine *m, const machine_target *t)
{
    const double x = m->axis[m->probe_axis[0]].carriage, y = m->axis[m->probe_axis[1]].carriage;
    const double z = m->axis[m->probe_axis[2]].carriage;
    double depth = t->z - z;

    switch (t->kind) {
    case TARGET_PLATE:
        if (t->bounded) {
            depth = fmin(depth, fmin(fmin(x - t->x_min, t->x_max - x), fmin(y - t->y_min, t->y_max - y)));
        }
        return depth;
    case TARGET_BLOCK:
        return fmin(depth, fmin(fmin(x - t->x_min, t->x_max - x), fmin(y - t->y_min, t->y_max - y)));
    case TARGET_BORE: {
        /* Inside the hole the tool is free; the wall is where the ellipse
         * reaches 1. In steps of the smaller radius. */
        const double dx = (x - t->x) / t->radius_x, dy = (y - t->y) / t->radius_y;
        const double r = fmin(t->radius_x, t->radius_y);
        return fmin(depth, (sqrt(dx * dx + dy * dy) - 1.0) * r);
    }
    }
    return -1e300;
}

static void update_probe(machine *m)
{
    double deepest = -1e300;
    int i;

    if (!m->probe_present)
        return;
    for (i = 0; i < m->targets; i++)
        deepest = fmax(deepest, penetration(m, &m->target[i]));
    if (!m->probe.closed && deepest >= 0)
        m->probe.closed = 1;
    else if (m->probe.closed && deepest < -m->probe.hysteresis)
        m->probe.closed = 0;
    actuate(m, PROBE_INPUT, m->probe.closed || scripted(m, PROBE_INPUT), &m->probe);
}

static void update_switches(machine *m, int axis)
{
    machine_axis *a = &m->axis[axis];
    const int lo = switch_closed(m, &a->min, a->carriage, 1);
    const int hi = switch_closed(m, &a->max, a->carriage, 0);

    if (m->shared_limits) {
        if (a->min.present || a->max.present)
            actuate(m, axis, lo || hi || scripted(m, axis), lo ? &a->min : &a->max);
    } else {
        if (a->min.present)
            actuate(m, axis, lo || scripted(m, axis), &a->min);
        if (a->max.present)
            actuate(m, 4 + axis, hi || scripted(m, 4 + axis), &a->max);
    }
}

static const machine_switch *switch_of(const machine *m, int input)
{
    if (input == PROBE_INPUT)
        return m->probe_present ? &m->probe : NULL;
    if (input < 4)
        return input < m->axes ? &m->axis[input].min : NULL;
    if (input < 8)
        return input - 4 < m->axes ? &m->axis[input - 4].max : NULL;
    return NULL;
}

void machine_step(machine *m, int axis, int direction)
{
    machine_axis *a = &m->axis[axis];
    const double half = a->backlash / 2;
    long motor = a->motor + direction;
    int input;

    a->pulses++;
    a->steps += direction;
    /* The carriage moves only once the motor has crossed the dead band;
     * against a hard stop the motor stalls and the pulse is lost. */
    if (direction > 0) {
        if (a->has_hard_max && motor - half > a->hard_max) {
            a->lost++;
            motor = a->motor;
        }
        if (motor - a->carriage > half)
            a->carriage = motor - half;
    } else {
        if (a->has_hard_min && motor + half < a->hard_min) {
            a->lost++;
            motor = a->motor;
        }
        if (a->carriage - motor > half)
            a->carriage = motor + half;
    }
    a->motor = motor;
    update_switches(m, axis);
    update_probe(m);
    /* Step pulses induce false pulses on the switch lines now and then. */
    for (input = 0; input < MACHINE_INPUTS; input++) {
        const machine_switch *sw = switch_of(m, input);
        machine_pin *p = &m->pin[input];
        if (sw && sw->present && sw->glitch > 0 && !p->glitch_until && !p->bounce_left && uniform(m) < sw->glitch) {
            p->glitch_until = m->sample + (uint64_t)(sw->glitch_ticks > 0 ? sw->glitch_ticks : 1);
            set_level(m, input, (uint8_t)!p->level, 'g');
        }
    }
}

void machine_tick(machine *m, uint32_t motion_tick)
{
    int i;

    m->sample++;
    m->motion_tick = motion_tick;
    for (i = 0; i < m->scripts; i++) {
        machine_script *s = &m->script[i];
        if (s->state == 0 && motion_tick >= s->at_tick) {
            s->state = 1;
            s->pressed_at = m->sample;
        } else if (s->state == 1 && m->sample >= s->pressed_at + s->ticks) {
            s->state = 2;
        } else {
            continue;
        }
        if (s->input < 8 && switch_of(m, s->input) && switch_of(m, s->input)->present)
            update_switches(m, s->input % 4);
        else if (s->input == PROBE_INPUT && m->probe_present)
            update_probe(m);
        else
            actuate(m, s->input, s->state == 1, NULL);
    }
    for (i = 0; i < MACHINE_INPUTS; i++) {
        machine_pin *p = &m->pin[i];
        const machine_switch *sw = switch_of(m, i);
        if (p->glitch_until && m->sample >= p->glitch_until) {
            p->glitch_until = 0;
            set_level(m, i, level_of(p, p->actuated), 'g');
        }
        if (p->bounce_left && m->sample >= p->next_toggle) {
            const int gap = sw && sw->bounce ? (sw->bounce_ticks / (2 * sw->bounce) > 1 ? sw->bounce_ticks / (2 * sw->bounce) : 1) : 1;
            p->bounce_left--;
            set_level(m, i, p->bounce_left % 2 ? (uint8_t)!level_of(p, p->actuated) : level_of(p, p->actuated), 'b');
            p->next_toggle = m->sample + 1 + next_random(m) % (uint64_t)gap;
        }
    }
}

uint16_t machine_levels(const machine *m)
{
    uint16_t levels = 0;
    int i;
    for (i = 0; i < MACHINE_INPUTS; i++)
        if (m->pin[i].level)
            levels |= (uint16_t)(1u << i);
    return levels;
}

int machine_busy(const machine *m)
{
    int i;
    for (i = 0; i < MACHINE_INPUTS; i++)
        if (m->pin[i].bounce_left || m->pin[i].glitch_until)
            return 1;
    for (i = 0; i < m->scripts; i++)
        if (m->script[i].state == 1)
            return 1;
    return 0;
}

/* ---- the summary ---- */

static const char *input_name(int input)
{
    static const char *const names[MACHINE_INPUTS] = {
        "limit_0", "limit_1", "limit_2", "limit_3", "limit_max_0", "limit_max_1",
        "limit_max_2", "limit_max_3", "probe", "abort", "feed_hold", "cycle_start"};
    return names[input];
}

void machine_write_json(const machine *m, FILE *f)
{
    uint32_t i;
    int axis;

    fprintf(f, "{\"file\": \"%s\", \"seed\": %llu, \"shared_limits\": %s, \"axes\": [", m->path,
            (unsigned long long)m->seed, m->shared_limits ? "true" : "false");
    for (axis = 0; axis < m->axes; axis++) {
        const machine_axis *a = &m->axis[axis];
        fprintf(f,
                "%s{\"pulses\": %llu, \"steps\": %lld, \"motor\": %ld, \"carriage\": %.17g, \"lost_steps\": %llu, "
                "\"backlash\": %.17g, \"start\": %ld}",
                axis ? ", " : "", (unsigned long long)a->pulses, (long long)a->steps, a->motor, a->carriage,
                (unsigned long long)a->lost, a->backlash, a->start);
    }
    fprintf(f, "], \"levels\": %u, \"events_dropped\": %u, \"events\": [", machine_levels(m), m->events_dropped);
    for (i = 0; i < m->events; i++) {
        const machine_event *e = &m->event[i];
        fprintf(f, "%s{\"sample\": %llu, \"tick\": %u, \"input\": \"%s\", \"level\": %u, \"active\": %s, "
                   "\"cause\": \"%s\", \"carriage\": [",
                i ? ", " : "", (unsigned long long)e->sample, e->tick, input_name(e->input), e->level,
                e->active ? "true" : "false",
                e->cause == 's' ? "switch" : e->cause == 'b' ? "bounce" : e->cause == 'g' ? "glitch" : "press");
        for (axis = 0; axis < m->axes; axis++)
            fprintf(f, "%s%.17g", axis ? ", " : "", e->carriage[axis]);
        fprintf(f, "]}");
    }
    fprintf(f, "]}");
}

/* ---- the initial state (machine_file.c reads the settings) ---- */

void machine_start(machine *m)
{
    int axis, i;

    m->rng = m->seed ? m->seed : 0x9E3779B97F4A7C15ull;
    for (i = 0; i < MACHINE_INPUTS; i++) {
        const machine_switch *sw = switch_of(m, i);
        m->pin[i].normally_closed = sw ? sw->normally_closed : 0;
        m->pin[i].actuated = 0;
        m->pin[i].level = level_of(&m->pin[i], 0);
    }
    if (m->shared_limits)
        for (axis = 0; axis < m->axes; axis++)
            m->pin[axis].normally_closed = m->axis[axis].min.present ? m->axis[axis].min.normally_closed
                                                                     : m->axis[axis].max.normally_closed;
    for (i = 0; i < MACHINE_INPUTS; i++)
        m->pin[i].level = level_of(&m->pin[i], 0);
    for (axis = 0; axis < m->axes; axis++) {
        machine_axis *a = &m->axis[axis];
        a->motor = a->start;
        a->carriage = a->carriage0;
        a->min.point = a->min.at;
        a->max.point = a->max.at;
        a->min.closed = a->max.closed = 0;
    }
    /* Switches already closed at power-up are a state: no event. */
    m->events = 0;
    for (axis = 0; axis < m->axes; axis++)
        update_switches(m, axis);
    update_probe(m);
    m->events = 0;
    for (i = 0; i < MACHINE_INPUTS; i++)
        m->pin[i].bounce_left = 0;
}
