/* quadstep board firmware: feeds received bytes to the core and lets the
 * Timer1 interrupt run the step engine. */
#include <avr/interrupt.h>
#include <avr/sleep.h>

#include "board.h"
#include "boot_id.h"
#include "firmware.h"
#include "frame_rx.h"
#include "inputs_tick.h"
#include "outputs.h"
#include "pins.h"
#include "step_timer.h"
#include "uart.h"

qs_core core;

/* Hands every received byte to the core: a run of them at a time, read in
 * place; byte by byte only while a loss mark is near. A frame's delimiter
 * is handled after its slots are free again. */
static void receive(void)
{
    for (;;) {
        const uint8_t *bytes;
        uint8_t count = uart_rx_run(&bytes);

        if (count == 0) {
            uint8_t byte;
            if (!uart_rx_ready()) {
                return;
            }
            if (uart_rx_take(&byte)) {
                qs_core_rx_overrun(&core);
            }
            qs_core_rx(&core, byte);
            continue;
        }
        while (count) {
            const uint8_t taken = frame_rx_copy(&core.rx, bytes, count); /* qs_core_rx_copy, written out */
            if (taken == count) {
                uart_rx_release(taken);
                break;
            }
            /* A delimiter follows what was taken. */
            uart_rx_release((uint8_t)(taken + 1));
            bytes += taken + 1;
            count = (uint8_t)(count - taken - 1);
            qs_core_rx_end(&core);
        }
    }
}

int main(void)
{
    pins_init();
    outputs_init();
    qs_core_init(&core);
    core.boot_id = boot_id_next();
    qs_inputs_init(&core.inputs, QS_INPUTS_PRESENT);
    inputs_changed(); /* the power-up state: switches already closed are a state, not an edge */
    uart_init();
    port_clock_init();
    step_timer_init();
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();

    for (;;) {
        step_timer_woke = 0; /* before looking: a tick from now on sets it again */
        receive();
        qs_core_poll(&core); /* a few compares unless the tick left work */
        outputs_poll();      /* a flag test, but once per PWM period */

        /* Sleep until the next interrupt (a tick or a byte). Interrupts stay
         * off between the check and the sleep so a byte cannot slip in
         * unnoticed; `sei` takes effect only after `sleep`. */
        cli();
        if (!uart_rx_ready()) {
            /* At rest the resting ticks wake the loop for nothing: it sleeps
             * on until a whole tick ran (a byte, an input, the rest's end)
             * or the outputs' period came round. */
            do {
                sleep_enable();
                sei();
                sleep_cpu();
                sleep_disable();
                cli();
            } while (step_timer_resting() && !step_timer_woke && !(TIFR2 & _BV(TOV2)));
        }
        sei();
    }
}
