/* The serial line to the board's USART0, behaving like a real wire:
 * host bytes arrive one per frame time (10 bits at the baud rate the
 * firmware programmed), and a byte the real chip would lose (two unread
 * bytes in its receive buffer and a third complete in the shift register)
 * is lost here too, with the DOR flag set, instead of waiting in simavr's
 * deep input FIFO. Board bytes go to a sink as the firmware writes them. */
#ifndef SIM_WIRE_H
#define SIM_WIRE_H

#include <stddef.h>
#include <stdint.h>

#include "sim_avr.h"

typedef void (*sim_wire_sink)(void *ctx, uint8_t byte);

typedef struct {
    uint64_t host_bytes;  /* queued by the host side */
    uint64_t delivered;   /* reached the chip's receiver */
    uint64_t lost;        /* dropped as the real receiver would */
    uint64_t board_bytes; /* written by the firmware */
} sim_wire_stats;

typedef struct sim_wire sim_wire;

sim_wire *sim_wire_attach(avr_t *avr, sim_wire_sink sink, void *sink_ctx);

/* Queue bytes from the host; they go out at the line rate. */
void sim_wire_send(sim_wire *w, const uint8_t *bytes, size_t len);

/* Bytes queued but not yet on the line. */
size_t sim_wire_backlog(const sim_wire *w);

/* Cycle at which the last host byte started on the line. */
uint64_t sim_wire_last_start(const sim_wire *w);

/* Cycles per byte on the line (0 until the firmware set the baud rate). */
uint32_t sim_wire_cycles_per_byte(const sim_wire *w);

sim_wire_stats sim_wire_get_stats(const sim_wire *w);

#endif
