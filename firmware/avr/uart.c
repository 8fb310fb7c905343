/* USART0 driver with bounded receive and transmit rings (see uart.h). */
#include "uart.h"

#include <avr/interrupt.h>
#include <avr/io.h>

#include "step_timer.h"

#ifndef QS_BAUD
#define QS_BAUD 500000UL
#endif

/* Double-speed mode (U2X): 8 clocks per bit, so 16 MHz gives 1 Mbaud,
 * 500 kbaud and 250 kbaud exactly and 115200 within 2.1 %. */
#define UBRR_VALUE ((F_CPU + 4UL * (QS_BAUD)) / (8UL * (QS_BAUD)) - 1UL)
#define BAUD_REAL (F_CPU / (8UL * (UBRR_VALUE + 1UL)))
_Static_assert(UBRR_VALUE <= 4095UL, "QS_BAUD too low for UBRR");
_Static_assert(BAUD_REAL * 1000UL <= (QS_BAUD) * 1025UL &&
               BAUD_REAL * 1000UL >= (QS_BAUD) * 975UL,
               "QS_BAUD is more than 2.5 % off what F_CPU can make");
/* The tick looks at the receiver once per tick: no more than two bytes
 * (its buffer) may arrive in that time. A frame is 10 bits. */
_Static_assert((QS_BAUD) / 10UL <= 2UL * (QS_TICK_HZ),
               "QS_BAUD too fast for QS_TICK_HZ: more than two bytes would arrive per tick");

/* Indices are bytes: up to 256 slots, a power of two so they wrap by mask. */
_Static_assert(QS_UART_RX_RING >= 8 && QS_UART_RX_RING <= 256 &&
               (QS_UART_RX_RING & (QS_UART_RX_RING - 1)) == 0,
               "QS_UART_RX_RING must be a power of two, 8..256");
_Static_assert(QS_UART_TX_RING >= 8 && QS_UART_TX_RING <= 256 &&
               (QS_UART_TX_RING & (QS_UART_TX_RING - 1)) == 0,
               "QS_UART_TX_RING must be a power of two, 8..256");

volatile uint8_t uart_rx_ring[QS_UART_RX_RING];
/* The service marks slot head, the main loop clears slot tail: never the
 * same slot at once, but perhaps the same byte, which the main loop
 * therefore changes with the tick locked out. */
volatile uint8_t uart_rx_lost_before[QS_UART_RX_RING / 8];
volatile uint8_t uart_rx_marks;
static uint8_t rx_marks_taken; /* main loop: marks cleared by uart_rx_take */
volatile uint8_t uart_rx_head; /* next slot the service fills */
volatile uint8_t uart_rx_tail; /* next slot the main loop takes */

volatile uint8_t uart_tx_ring[QS_UART_TX_RING];
volatile uint8_t uart_tx_head; /* next slot the main loop fills */
volatile uint8_t uart_tx_tail; /* next slot the service sends */

void uart_init(void)
{
    /* U2X first: the baud rate generator (and simavr) use it when UBRR is written. */
    UCSR0A = _BV(U2X0);
    UBRR0 = (uint16_t)UBRR_VALUE;
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00); /* 8N1 */
    UCSR0B = _BV(RXEN0) | _BV(TXEN0);    /* no USART interrupts: the tick services it */
    uart_tx_pending = 0;
}

uint8_t uart_rx_ready(void)
{
    return uart_rx_head != uart_rx_tail;
}

uint8_t uart_rx_take(uint8_t *byte)
{
    const uint8_t tail = uart_rx_tail;
    const uint8_t bit = uart_slot_bit(tail);
    const uint8_t lost = (uart_rx_lost_before[tail >> 3] & bit) != 0;
    if (lost) {
        const uint8_t sreg = SREG;
        cli();
        uart_rx_lost_before[tail >> 3] &= (uint8_t)~bit;
        SREG = sreg;
        rx_marks_taken++;
    }
    *byte = uart_rx_ring[tail];
    uart_rx_tail = (uint8_t)((tail + 1u) & UART_RX_MASK);
    return lost;
}

uint8_t uart_rx_run(const uint8_t **bytes)
{
    /* head before marks: a mark set after head was read stands at head
     * or later, outside the run. */
    const uint8_t head = uart_rx_head;
    const uint8_t marks = uart_rx_marks;
    const uint8_t tail = uart_rx_tail;
    uint8_t count;

    count = (uint8_t)((uint8_t)(head - tail) & UART_RX_MASK);
    /* It wraps: up to the ring's end. In 8 bits: the slots after tail's to
     * the end, 0 ... 255 (the ring may have 256). */
    const uint8_t after = (uint8_t)(QS_UART_RX_RING - 1u - tail);
    if (count && (uint8_t)(count - 1u) > after) {
        count = (uint8_t)(after + 1u);
    }
    if (marks != rx_marks_taken) {
        /* A loss is marked somewhere ahead: the run ends before the first
         * mark, which uart_rx_take then reports. */
        uint8_t clean = 0;
        while (clean < count
               && !(uart_rx_lost_before[(uint8_t)(tail + clean) >> 3] & uart_slot_bit((uint8_t)(tail + clean)))) {
            clean++;
        }
        count = clean;
    }
    /* The service writes no slot from tail to head: no longer volatile. */
    *bytes = (const uint8_t *)&uart_rx_ring[tail];
    return count;
}

void uart_write(const uint8_t *bytes, uint8_t len)
{
    uint8_t head = uart_tx_head;

    while (len) {
        /* Free slots: all but one, so that a full ring differs from an empty one. */
        uint8_t room = (uint8_t)((uint8_t)(uart_tx_tail - head - 1u) & UART_TX_MASK);
        if (room > len) {
            room = len;
        }
        len = (uint8_t)(len - room);
        if (room) {
            /* 11 cycles a byte: a walking pointer, back to the ring's
             * start when head wraps */
            volatile uint8_t *to = &uart_tx_ring[head];
            __asm__ __volatile__(
                "1:\n\t"
                "ld __tmp_reg__, X+\n\t"
                "st Z+, __tmp_reg__\n\t"
                "subi %[head], 0xFF\n\t"
                "andi %[head], %[mask]\n\t"
                "brne 2f\n\t"
                "ldi r30, lo8(%[ring])\n\t"
                "ldi r31, hi8(%[ring])\n"
                "2:\n\t"
                "dec %[room]\n\t"
                "brne 1b"
                : "+x"(bytes), "+z"(to), [head] "+d"(head), [room] "+r"(room)
                : [mask] "M"(UART_TX_MASK), [ring] "i"(uart_tx_ring)
                : "memory");
        }
        uart_tx_head = head;
        {
            /* after head: the service may just have cleared it; and a
             * resting tick wakes to send (locked: no resting tick between) */
            const uint8_t saved = SREG;
            cli();
            uart_tx_pending = 1;
            step_timer_wake();
            SREG = saved;
        }
        /* A full ring waits here for the tick to send, a byte per tick. */
    }
}
