/* The host's end of the serial line: a pseudo-terminal (the host opens the
 * printed /dev/pts/N with pyserial exactly as it opens a board), or the
 * harness's stdin/stdout. */
#ifndef SIM_LINK_H
#define SIM_LINK_H

#include <stddef.h>
#include <stdint.h>

typedef struct sim_link sim_link;

/* Opens a pseudo-terminal and prints "PORT /dev/pts/N" on stdout. */
sim_link *sim_link_open_pty(void);

sim_link *sim_link_open_stdio(void);

/* Reads what the host has sent, without blocking; returns the byte count
 * (0 when nothing is waiting). *eof is set when stdin has ended. */
size_t sim_link_read(sim_link *l, uint8_t *buf, size_t cap, int *eof);

/* Queues a board byte for the host; sim_link_flush writes what it can. */
void sim_link_put(sim_link *l, uint8_t byte);
void sim_link_flush(sim_link *l);

#endif
