/* What each target (AVR board, native emulator, test runner) provides to the
 * portable core. The core calls nothing else outside itself. */
#ifndef QS_PORT_H
#define QS_PORT_H

#include <stdint.h>

/* Queue bytes for transmission to the host. Called from the main loop only;
 * a target with a bounded transmit buffer waits for room, never drops. */
void qs_port_send(const uint8_t *bytes, uint8_t len);

/* Enter and leave a section that the step tick cannot interrupt. */
uint8_t qs_port_lock(void);
void qs_port_unlock(uint8_t saved);

/* A target's tick may rest while the engine has nothing to do
 * (QS_ENGINE_RESTING, qs_engine_tick.h): the core calls this, with the
 * tick locked out, when it gives the engine work (a segment published
 * while IDLE), so that the next tick runs it as it would have run anyway. */
void qs_port_tick_wake(void);

/* A RASTER line's pixel power (0 dark), from the step tick at the decision
 * that crosses its pixel's boundary (qs_raster_tick.h): a target that
 * drives a laser's PWM from its main loop (qs_core_outputs) takes this one
 * at once, and leaves the duty alone while the tick has a line lit. */
void qs_port_laser_power(uint8_t power);

/* The laser PWM's period in ticks (0: a target whose power changes at
 * once). The tick switches the pixels of a line only where each lasts a
 * period or more: a shorter pixel begun by restarting the period would be
 * high for all of it at most powers, where a period left to run shows the
 * pixels' powers on average (qs_raster_level looks them up ahead). Main
 * loop. */
uint8_t qs_port_laser_period_ticks(void);

/* A free-running count of QS_PORT_CLOCK_US microseconds each, wrapping at
 * 2^16, for the host watchdog. Main loop only. */
uint16_t qs_port_clock(void);

#ifndef QS_PORT_CLOCK_US
#define QS_PORT_CLOCK_US 64 /* 2^16 counts: 4.19 s */
#endif

#endif
