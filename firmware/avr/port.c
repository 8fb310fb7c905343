/* What the core needs from the board (qs_port.h). */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "qs_port.h"
#include "step_timer.h"
#include "uart.h"

void qs_port_send(const uint8_t *bytes, uint8_t len)
{
    uart_write(bytes, len);
}

/* The step tick is the firmware's only interrupt (it also serves the
 * USART; at rest compare B stands in for it: step_timer.c), so holding it off is clearing the global interrupt flag: one
 * cycle, and a tick that falls due meanwhile runs as soon as the section
 * ends. Sections must stay well under a tick. The memory clobbers (in cli()
 * and here) keep the compiler from moving the core's shared-data accesses
 * out of the section. */
/* Timer0 runs free at F_CPU/1024 (64 us a count at 16 MHz) with no
 * interrupt; the main loop, which reads it far more often than every 256
 * counts, keeps the high byte. */
_Static_assert(F_CPU == 16000000L, "the port clock counts 64 us at 16 MHz");

static uint8_t clock_high;

void port_clock_init(void)
{
    TCCR0A = 0;
    TCCR0B = _BV(CS02) | _BV(CS00); /* clk/1024 */
    TIFR0 = _BV(TOV0);
}

uint16_t qs_port_clock(void)
{
    uint8_t low = TCNT0;

    if (TIFR0 & _BV(TOV0)) {
        TIFR0 = _BV(TOV0); /* written with a one, as the chip clears flags */
        clock_high++;
        low = TCNT0; /* after the wrap */
    }
    return (uint16_t)((uint16_t)clock_high << 8 | low);
}

void qs_port_tick_wake(void)
{
    step_timer_wake();
}

uint8_t qs_port_lock(void)
{
    const uint8_t saved = SREG;
    cli();
    return saved;
}

void qs_port_unlock(uint8_t saved)
{
    __asm__ __volatile__("" ::: "memory");
    SREG = saved;
}
