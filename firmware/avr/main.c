/* quadstep board firmware: feeds received bytes to the core and lets the
 * Timer1 interrupt run the step engine. */
#include <avr/interrupt.h>
#include <avr/sleep.h>

#include "firmware.h"
#include "pins.h"
#include "step_timer.h"
#include "uart.h"

qs_core core;

/* qs_core_poll's work comes from the tick, which then has released a
 * segment slot (a segment or a hold ended) or raised an alarm. Checking
 * that here costs a few cycles; calling poll with nothing to do costs over
 * a hundred, and the loop runs on every tick (docs/AVR.md, "Where the
 * cycles go"). Every 256th pass polls anyway, so work of any other origin
 * waits at most that long. */
static uint8_t poll_due(uint8_t *seen_tail, uint8_t *passes)
{
    const uint8_t tail = core.engine.queue.tail;
    if (tail != *seen_tail || core.engine.alarm != QS_ALARM_NONE || ++*passes == 0) {
        *seen_tail = tail;
        return 1;
    }
    return 0;
}

int main(void)
{
    pins_init();
    qs_core_init(&core);
    uart_init();
    step_timer_init();
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();

    uint8_t seen_tail = core.engine.queue.tail;
    uint8_t passes = 0;
    for (;;) {
        while (uart_rx_ready()) {
            uint8_t byte;
            if (uart_rx_take(&byte)) {
                qs_core_rx_overrun(&core);
            }
            qs_core_rx(&core, byte);
        }
        if (poll_due(&seen_tail, &passes)) {
            qs_core_poll(&core);
        }

        /* Sleep until the next interrupt (a tick or a byte). Interrupts stay
         * off between the check and the sleep so a byte cannot slip in
         * unnoticed; `sei` takes effect only after `sleep`. */
        cli();
        if (!uart_rx_ready()) {
            sleep_enable();
            sei();
            sleep_cpu();
            sleep_disable();
        }
        sei();
    }
}
