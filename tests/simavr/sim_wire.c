/* The serial line to the board's USART0 (see sim_wire.h). */
#include "sim_wire.h"

#include <stdlib.h>
#include <string.h>

#include "avr_uart.h"
#include "sim_io.h"
#include "sim_regbit.h"

/* USART0 registers: the same data addresses on the ATmega328P and 2560. */
#define REG_UCSR0A 0xC0
#define REG_UCSR0B 0xC1
#define REG_UBRR0L 0xC4
#define REG_UBRR0H 0xC5
#define BIT_U2X0 1
#define BIT_RXEN0 4
#define BITS_PER_FRAME 10 /* start, 8 data, stop */
#define RX_HOLD 3         /* 2-byte receive buffer + the shift register */
#define WAIT_FOR_RXEN 1000

DEFINE_FIFO(uint16_t, uart_fifo); /* accessors for simavr's receive FIFO */

struct sim_wire {
    avr_t *avr;
    avr_uart_t *uart;
    avr_irq_t *input;
    sim_wire_sink sink;
    void *sink_ctx;
    uint8_t *queue; /* host bytes not yet on the line: queue[head..tail) */
    size_t head, tail, size;
    int timer_armed;
    uint64_t last_start;
    uint32_t cycles_per_byte;
    sim_wire_stats stats;
};

static avr_uart_t *find_uart0(avr_t *avr)
{
    for (avr_io_t *io = avr->io_port; io; io = io->next) {
        if (strcmp(io->kind, "uart") == 0 && ((avr_uart_t *)io)->name == '0') {
            return (avr_uart_t *)io;
        }
    }
    return NULL;
}

/* Frame time from the firmware's UBRR and U2X. simavr assumes 11 bits per
 * byte; an 8N1 frame is 10, so the harness sets the figure itself (it also
 * paces the firmware's transmitter). */
static void sync_baud(sim_wire *w)
{
    const uint8_t *d = w->avr->data;
    const uint32_t ubrr = d[REG_UBRR0L] | ((uint32_t)(d[REG_UBRR0H] & 0x0F) << 8);
    const uint32_t clocks_per_bit = (ubrr + 1) * ((d[REG_UCSR0A] >> BIT_U2X0) & 1 ? 8 : 16);
    w->cycles_per_byte = clocks_per_bit * BITS_PER_FRAME;
    w->uart->cycles_per_byte = w->cycles_per_byte;
}

static avr_cycle_count_t inject(avr_t *avr, avr_cycle_count_t when, void *param)
{
    sim_wire *w = param;

    if (!((avr->data[REG_UCSR0B] >> BIT_RXEN0) & 1)) {
        return when + WAIT_FOR_RXEN; /* the board is not listening yet: hold the bytes */
    }
    sync_baud(w);
    if (w->head == w->tail) {
        w->timer_armed = 0;
        return 0;
    }
    const uint8_t byte = w->queue[w->head++];
    const int dor = avr_regbit_get(avr, w->uart->dor);
    if (dor || uart_fifo_get_read_size(&w->uart->input) >= RX_HOLD) {
        /* The real receiver overruns: the byte is gone and DOR tells the firmware. */
        avr_regbit_setto(avr, w->uart->dor, 1);
        w->stats.lost++;
    } else {
        avr_raise_irq(w->input, byte);
        w->stats.delivered++;
    }
    w->last_start = when;
    if (w->head == w->tail) {
        w->head = w->tail = 0;
        w->timer_armed = 0;
        return 0;
    }
    return when + w->cycles_per_byte;
}

static void on_board_byte(avr_irq_t *irq, uint32_t value, void *param)
{
    sim_wire *w = param;
    (void)irq;
    w->stats.board_bytes++;
    w->sink(w->sink_ctx, (uint8_t)value);
}

sim_wire *sim_wire_attach(avr_t *avr, sim_wire_sink sink, void *sink_ctx)
{
    sim_wire *w = calloc(1, sizeof *w);
    if (!w) {
        return NULL;
    }
    w->avr = avr;
    w->uart = find_uart0(avr);
    if (!w->uart) {
        free(w);
        return NULL;
    }
    /* No console echo, no usleep when the firmware polls the status register. */
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    w->input = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            on_board_byte, w);
    w->sink = sink;
    w->sink_ctx = sink_ctx;
    return w;
}

void sim_wire_send(sim_wire *w, const uint8_t *bytes, size_t len)
{
    if (len == 0) {
        return;
    }
    if (w->tail + len > w->size) {
        const size_t live = w->tail - w->head;
        memmove(w->queue, w->queue + w->head, live);
        w->head = 0;
        w->tail = live;
        if (live + len > w->size) {
            w->size = (live + len) * 2;
            w->queue = realloc(w->queue, w->size);
            if (!w->queue) {
                abort();
            }
        }
    }
    memcpy(w->queue + w->tail, bytes, len);
    w->tail += len;
    w->stats.host_bytes += len;
    if (!w->timer_armed) {
        /* The next byte starts one frame time after the previous one. */
        avr_cycle_count_t delay = 1;
        if (w->cycles_per_byte && w->last_start + w->cycles_per_byte > w->avr->cycle) {
            delay = w->last_start + w->cycles_per_byte - w->avr->cycle;
        }
        avr_cycle_timer_register(w->avr, delay, inject, w);
        w->timer_armed = 1;
    }
}

size_t sim_wire_backlog(const sim_wire *w)
{
    return w->tail - w->head;
}

uint64_t sim_wire_last_start(const sim_wire *w)
{
    return w->last_start;
}

uint32_t sim_wire_cycles_per_byte(const sim_wire *w)
{
    return w->cycles_per_byte;
}

sim_wire_stats sim_wire_get_stats(const sim_wire *w)
{
    return w->stats;
}
