#include "qs_watchdog.h"

void qs_watchdog_start(qs_core *c, uint16_t timeout_ms)
{
    /* ms to clock counts, rounded up: a nonzero timeout stays nonzero. */
    c->watchdog = (uint16_t)(((uint32_t)timeout_ms * 1000u + QS_PORT_CLOCK_US - 1u) / QS_PORT_CLOCK_US);
    c->heard = qs_port_clock();
}

QS_NOINLINE void qs_watchdog_expire(qs_core *c)
{
    qs_engine *e = &c->engine;
    const uint8_t outcome = qs_engine_hold(e, e->stop_decel, 0);

    if (outcome == QS_HOLD_STARTED || (outcome == QS_HOLD_UNDER_WAY && !e->hold_alarm))
        e->hold_alarm = QS_ALARM_HOST_LOST;
    else if (outcome == QS_HOLD_AT_REST)
        qs_engine_halt(e, QS_STATE_ALARM, QS_ALARM_HOST_LOST);
}

