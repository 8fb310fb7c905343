/* The emulator's side of qs_port.h: what the core sends goes through the
 * fault injection into an output buffer that the main loop writes to the
 * line as the host reads it. One thread runs both the core and the tick,
 * so the lock has nothing to exclude. */
#ifndef EMU_PORT_H
#define EMU_PORT_H

#include <stddef.h>
#include <stdint.h>

#include "emu_faults.h"

/* Output the host has not read. Beyond this (no host reading at all) new
 * frames are discarded whole and counted, so the emulator never stalls. */
#define EMU_OUT_MAX (256u * 1024u)

void emu_port_init(emu_faults *faults);

const uint8_t *emu_port_pending(size_t *len);
void emu_port_consume(size_t len);

/* Forget pending output (a new TCP client should not get the old one's). */
void emu_port_discard(void);

uint32_t emu_port_frames_sent(void);
uint32_t emu_port_bytes_discarded(void);

#endif
