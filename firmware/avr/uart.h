/* USART0 driver with bounded receive and transmit rings.
 *
 * The step tick interrupt services the USART (uart_service) once or twice
 * per tick (step_timer.c), so the gaps between looks stay shorter than the
 * time the receiver can hold bytes (two in its buffer while a third shifts
 * in) and nothing is lost; a byte costs about 20 cycles there instead of
 * about 80 in an interrupt of its own (docs/AVR.md has the figures).
 * Received bytes lost to a hardware overrun (DOR) or a full ring are never
 * dropped silently: the byte read after the loss carries a mark. */
#ifndef QS_UART_H
#define QS_UART_H

#include <stdint.h>

#include <avr/io.h>

/* The receive ring holds a burst of frames while the main loop catches up:
 * the host may send a whole window of them back to back. */
#ifndef QS_UART_RX_RING
#define QS_UART_RX_RING 256
#endif
#ifndef QS_UART_TX_RING
#define QS_UART_TX_RING 64
#endif

void uart_init(void);

/* Nonzero when a received byte is waiting. */
uint8_t uart_rx_ready(void);

/* Takes the oldest received byte (only after uart_rx_ready()). Returns
 * nonzero if bytes were lost on the line just before this one. */
uint8_t uart_rx_take(uint8_t *byte);

/* The oldest received bytes that lie one after another in the ring with
 * no loss marked before any of them: *bytes and how many (0 when none, or
 * when the oldest carries a mark: take it with uart_rx_take). The main
 * loop reads them in place and gives them back with uart_rx_release. */
uint8_t uart_rx_run(const uint8_t **bytes);

/* Queues bytes for transmission, waiting for room; never drops. */
void uart_write(const uint8_t *bytes, uint8_t len);

/* Ring state shared with uart_service (defined in uart.c). The service
 * side writes rx_head and tx_tail, the main loop rx_tail and tx_head. */
#define UART_RX_MASK ((uint8_t)(QS_UART_RX_RING - 1))
#define UART_TX_MASK ((uint8_t)(QS_UART_TX_RING - 1))
extern volatile uint8_t uart_rx_ring[QS_UART_RX_RING];
/* Bit (slot & 7) of byte (slot >> 3) set: bytes were lost on the line just
 * before the byte that goes into that slot. A bit per slot: RAM is short,
 * and only a loss pays for finding the bit. */
extern volatile uint8_t uart_rx_lost_before[QS_UART_RX_RING / 8];

static inline __attribute__((always_inline)) uint8_t uart_slot_bit(uint8_t slot)
{
    return (uint8_t)(1u << (slot & 7u));
}
/* Marks set so far (mod 256), so that the main loop can tell without
 * looking at every slot that none awaits it. */
extern volatile uint8_t uart_rx_marks;
extern volatile uint8_t uart_rx_head, uart_rx_tail;
extern volatile uint8_t uart_tx_ring[QS_UART_TX_RING];
extern volatile uint8_t uart_tx_head, uart_tx_tail;

/* Gives back the first count bytes of a run (uart_rx_run). */
static inline void uart_rx_release(uint8_t count)
{
    uart_rx_tail = (uint8_t)((uint8_t)(uart_rx_tail + count) & UART_RX_MASK);
}

/* Set while the transmit ring holds bytes, in a general-purpose I/O register
 * that the service tests in one instruction: the main loop sets it after
 * the bytes it queues, the service clears it when the ring runs empty. */
#define uart_tx_pending GPIOR2

/* Moves received bytes into the receive ring and, if the transmitter has
 * room and the ring has bytes, one byte out of the transmit ring. Called
 * from the step tick interrupt only; inline so it shares the interrupt's
 * saved registers. With nothing to move it costs a load and two tests. */
static inline __attribute__((always_inline)) void uart_service(void)
{
    uint8_t status;
    while ((status = UCSR0A) & _BV(RXC0)) { /* the flags describe the byte in UDR0 */
        const uint8_t byte = UDR0;
        const uint8_t head = uart_rx_head;
        uint8_t head_bit = head;
        const uint8_t next = (uint8_t)((head + 1u) & UART_RX_MASK);
        const uint8_t full = next == uart_rx_tail;
        if (full || (status & _BV(DOR0))) {
            /* The line lost bytes (DOR), or the ring is full and this byte
             * is lost: either way before whatever lands in slot head. */
            /* written out: the compiler's version of this rare path took
             * two more registers, which every tick would save */
            __asm__ __volatile__(
                "mov r30, %[head]\n\t"
                "lsr r30\n\t"
                "lsr r30\n\t"
                "lsr r30\n\t"
                "ldi r31, 0\n\t"
                "subi r30, lo8(-(%[lost]))\n\t"
                "sbci r31, hi8(-(%[lost]))\n\t"
                "mov r0, %[head]\n\t"
                "ldi %[head], 1\n\t"
                "sbrc r0, 1\n\t"
                "ldi %[head], 4\n\t"
                "sbrc r0, 0\n\t"
                "lsl %[head]\n\t"
                "sbrc r0, 2\n\t"
                "swap %[head]\n\t"
                "ld r0, Z\n\t"
                "and r0, %[head]\n\t"
                "brne 1f\n\t"
                "ld r0, Z\n\t"
                "or r0, %[head]\n\t"
                "st Z, r0\n\t"
                "lds r0, %[marks]\n\t"
                "inc r0\n\t"
                "sts %[marks], r0\n"
                "1:"
                : [head] "+d"(head_bit)
                : [lost] "i"(uart_rx_lost_before), [marks] "i"(&uart_rx_marks)
                : "r30", "r31", "memory");
            if (full) {
                continue;
            }
        }
        uart_rx_ring[head] = byte;
        uart_rx_head = next;
    }
    if (uart_tx_pending && (status & _BV(UDRE0))) {
        const uint8_t tail = uart_tx_tail;
        const uint8_t next = (uint8_t)((tail + 1u) & UART_TX_MASK);
        UDR0 = uart_tx_ring[tail];
        uart_tx_tail = next;
        if (next == uart_tx_head) {
            uart_tx_pending = 0;
        }
    }
}

#endif
