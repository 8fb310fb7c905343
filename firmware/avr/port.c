/* What the core needs from the board (qs_port.h). */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "qs_port.h"
#include "uart.h"

void qs_port_send(const uint8_t *bytes, uint8_t len)
{
    uart_write(bytes, len);
}

/* The step tick is the firmware's only interrupt (it also serves the
 * USART), so holding it off is clearing the global interrupt flag: one
 * cycle, and a tick that falls due meanwhile runs as soon as the section
 * ends. Sections must stay well under a tick. The memory clobbers (in cli()
 * and here) keep the compiler from moving the core's shared-data accesses
 * out of the section. */
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
