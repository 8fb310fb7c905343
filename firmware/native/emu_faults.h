/* Fault injection that simulates a bad wire, for testing the host's
 * retransmission: a received frame can vanish or arrive with one bit
 * flipped, a sent frame can vanish. Frames are counted from 1 in each
 * direction; a frame is the bytes up to and including a 0x00, empty frames
 * (a lone 0x00) not counted. */
#ifndef EMU_FAULTS_H
#define EMU_FAULTS_H

#include <stddef.h>
#include <stdint.h>

#include "emu_options.h"

#define EMU_RX_FRAME_MAX 1024 /* longer garbage runs pass through unfaulted */

typedef void emu_byte_sink(void *ctx, uint8_t byte);

typedef struct {
    const emu_options *opts;
    /* Receiving: bytes of the frame in progress, held until its delimiter. */
    uint8_t rx_buf[EMU_RX_FRAME_MAX];
    size_t rx_len;
    int rx_passing;       /* this frame overflowed rx_buf and passes through */
    uint32_t rx_frames;   /* frames received so far */
    uint32_t rx_dropped;
    uint32_t rx_corrupted;
    /* Sending. */
    uint32_t tx_frames;   /* frames sent (or dropped) so far */
    int tx_in_frame;      /* a frame has started and not ended */
    uint32_t tx_dropped;
} emu_faults;

void emu_faults_init(emu_faults *f, const emu_options *opts);

/* A received byte; what survives goes to sink, frame by frame. */
void emu_faults_rx(emu_faults *f, uint8_t byte, emu_byte_sink *sink, void *ctx);

/* Bytes to send; what survives goes to sink. */
void emu_faults_tx(emu_faults *f, const uint8_t *bytes, size_t len, emu_byte_sink *sink,
                   void *ctx);

#endif
