/* The emulator's serial line: a pseudo-terminal the host opens as a serial
 * port, or a TCP socket on 127.0.0.1 (one client at a time). */
#ifndef EMU_LINK_H
#define EMU_LINK_H

#include <poll.h>
#include <stddef.h>
#include <stdint.h>

#include "emu_options.h"

typedef struct {
    int tcp;
    int listen_fd; /* TCP: the listening socket */
    int fd;        /* pty master, or the TCP client; -1 when none */
    int slave_fd;  /* pty: held open so the host can close and reopen it */
    uint32_t clients; /* TCP clients accepted so far */
} emu_link;

/* Open the line and print exactly one line "PORT <name>" on stdout. */
int emu_link_open(emu_link *l, const emu_options *o);
void emu_link_close(emu_link *l);

/* Fill up to two pollfd entries; returns how many. */
int emu_link_poll_setup(const emu_link *l, struct pollfd *p, int want_write);

/* After poll: accept a waiting TCP client. Returns 1 if one arrived. */
int emu_link_accept(emu_link *l, const struct pollfd *p, int n);

/* Non-blocking; return bytes moved, 0 if none could be. A TCP client that
 * hung up is dropped (the next one is accepted later). */
size_t emu_link_read(emu_link *l, uint8_t *buf, size_t cap);
size_t emu_link_write(emu_link *l, const uint8_t *buf, size_t len);

#endif
