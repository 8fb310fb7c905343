#include "qs_inputs.h"
#include "qs_port.h"
#include "qs_protocol.h"

#define BIT(input) ((uint16_t)(1u << (input)))


void qs_inputs_init(qs_inputs *in, uint16_t present)
{
    uint8_t i;

    in->present = present;
    in->invert = 0;
    in->enabled = present;
    in->hard_limits = 1;
    for (i = 0; i < QS_INPUT_COUNT; i++)
        in->debounce[i] = 0;
    in->at_once = QS_INPUTS_ALL;
    in->raw = QS_INPUTS_RESAMPLE;
    in->active = 0;
    in->window = 0;
    in->countdown = 0;
    in->tentative = QS_INPUT_NONE;
    in->hold_request = 0;
}

static uint16_t active_levels(const qs_inputs *in, uint16_t raw)
{
    /* Active low unless inverted: a switch to ground closes the input. */
    return (uint16_t)(~(raw ^ in->invert) & in->enabled);
}

/* The longest debounce among the inputs in mask. */
static uint8_t longest_debounce(const qs_inputs *in, uint16_t mask)
{
    uint8_t i, most = 0;

    for (i = 0; i < QS_INPUT_COUNT; i++, mask >>= 1)
        if ((mask & 1u) && in->debounce[i] > most)
            most = in->debounce[i];
    return most;
}

/* An accepted change of the inputs in changed: act on it (see
 * qs_inputs.h) and say what was done. */
static uint8_t act(qs_inputs *in, qs_engine *e, uint16_t changed)
{
    const uint16_t rising = changed & in->active;
    uint16_t limits = rising & QS_INPUTS_LIMITS;
    uint8_t cause = QS_CAUSE_REPORT;

    if (e->state == QS_STATE_ALARM)
        return cause; /* nothing moves until STOP */
    if (rising & BIT(QS_INPUT_ABORT)) {
        qs_engine_freeze_in_tick(e, QS_ALARM_E_STOP);
        return QS_CAUSE_E_STOP;
    }
    if (e->trigger && (changed & BIT(e->trigger_input))
        && qs_inputs_is_active(in, e->trigger_input) == e->trigger_level) {
        /* The armed input is where the motion was to end: not a limit. */
        limits &= (uint16_t)~BIT(e->trigger_input);
        if (!qs_engine_trigger_in_tick(e))
            in->hold_request = QS_INPUTS_HOLD_TRIGGER;
        cause = QS_CAUSE_TRIGGER;
    }
    if (limits && in->hard_limits) {
        qs_engine_freeze_in_tick(e, QS_ALARM_HARD_LIMIT);
        return QS_CAUSE_HARD_LIMIT;
    }
    if (cause != QS_CAUSE_REPORT)
        return cause;
    if (rising & BIT(QS_INPUT_FEED_HOLD)) {
        in->hold_request = QS_INPUTS_HOLD_FEED;
        return QS_CAUSE_FEED_HOLD;
    }
    if (rising & BIT(QS_INPUT_CYCLE_START))
        return QS_CAUSE_CYCLE_START;
    return cause;
}

static void accept(qs_inputs *in, qs_engine *e, qs_latch *l, uint16_t changed)
{
    uint8_t cause;

    in->active ^= changed;
    cause = act(in, e, changed);
    if (l) {
        l->active = in->active;
        l->changed = changed;
        l->cause = cause;
        l->state = QS_LATCH_CONFIRMED;
    }
}

QS_NOINLINE uint8_t qs_inputs_update(qs_inputs *in, qs_engine *e, uint16_t raw)
{
    const uint16_t now = active_levels(in, raw);
    const uint8_t first = in->raw == QS_INPUTS_RESAMPLE;
    uint16_t changed, at_once, later;

    in->raw = raw;
    if (first) {
        /* Power-up: inputs already closed are a state, not an edge. */
        in->active = now;
        return 0;
    }
    if (in->window && --in->countdown == 0) {
        /* The window closes: accept what is still changed, with the latch
         * of its first edge; an edge that went back was a glitch. */
        const uint16_t confirmed = in->window & (now ^ in->active);
        qs_latch *l = in->tentative == QS_INPUT_NONE ? 0 : &e->latches.entry[in->tentative];
        in->window = 0;
        in->tentative = QS_INPUT_NONE;
        if (confirmed)
            accept(in, e, l, confirmed);
        else if (l)
            l->state = QS_LATCH_DISCARDED;
    }
    changed = (now ^ in->active) & (uint16_t)~in->window;
    if (!changed)
        return in->window != 0;
    at_once = changed & in->at_once;
    later = changed & (uint16_t)~at_once;
    if (at_once)
        accept(in, e, qs_engine_latch_in_tick(e), at_once);
    if (later) {
        const uint8_t wait = longest_debounce(in, later);
        if (!in->window) {
            /* Latched now, reported if the window confirms it. */
            qs_latch *l = qs_engine_latch_in_tick(e);
            in->tentative = QS_INPUT_NONE;
            if (l) {
                l->state = QS_LATCH_TENTATIVE;
                in->tentative = (uint8_t)(l - e->latches.entry);
            }
            in->countdown = wait;
        } else if (wait > in->countdown) {
            in->countdown = wait; /* joins the open window, latched at its first edge */
        }
        in->window |= later;
    }
    return in->window != 0;
}

void qs_inputs_configure(qs_inputs *in, qs_engine *e, uint16_t invert, uint16_t enabled, uint8_t hard_limits,
                         const uint8_t *debounce, const uint16_t *hold_decel)
{
    uint16_t at_once = 0, bit = 1;
    uint8_t saved, i;

    /* Worked out before the lock, which holds the tick off: under a tick's length. */
    for (i = 0; i < QS_INPUT_COUNT; i++, bit = (uint16_t)(bit << 1))
        if (debounce[i] == 0)
            at_once |= bit;
    saved = qs_port_lock();
    in->invert = invert & in->present;
    in->enabled = enabled & in->present;
    in->hard_limits = hard_limits;
    for (i = 0; i < QS_INPUT_COUNT; i++)
        in->debounce[i] = debounce[i];
    in->at_once = at_once;
    for (i = 0; i < QS_AXIS_COUNT; i++)
        e->stop_decel[i] = hold_decel[i]; /* every hold the firmware begins itself */
    if (in->tentative != QS_INPUT_NONE)
        e->latches.entry[in->tentative].state = QS_LATCH_DISCARDED;
    in->tentative = QS_INPUT_NONE;
    in->window = 0;
    in->countdown = 0;
    in->active = active_levels(in, in->raw);
    qs_port_unlock(saved);
}
