/* Frames: COBS(body || crc16) || 0x00. Receiving checks, in the order of
 * PROTOCOL.md section 2, everything that does not depend on the message
 * type; sending seals a body with its CRC and stuffs it. */
#ifndef QS_FRAME_H
#define QS_FRAME_H

#include <stdint.h>
#include "qs_cobs.h"

/* qs_frame_rx_byte result besides an ERROR code (1..7). */
#define QS_FRAME_NOTHING 0
#define QS_FRAME_READY 0xFF

typedef struct {
    qs_cobs_decoder cobs;
    uint8_t overrun; /* bytes were lost while this frame arrived */
} qs_frame_rx;

void qs_frame_rx_init(qs_frame_rx *rx);

/* The receiver lost bytes: the frame in progress will be rejected. */
void qs_frame_rx_overrun(qs_frame_rx *rx);

/* Feed one wire byte. Returns QS_FRAME_NOTHING, QS_FRAME_READY (the body,
 * without CRC, is qs_frame_body(rx) / qs_frame_body_len(rx) until the next
 * call) or the framing error code of a rejected frame. */
uint8_t qs_frame_rx_byte(qs_frame_rx *rx, uint8_t byte);

static inline const uint8_t *qs_frame_body(const qs_frame_rx *rx) { return rx->cobs.buf; }
static inline uint8_t qs_frame_body_len(const qs_frame_rx *rx) { return (uint8_t)(rx->cobs.len - 2); }

/* Seal and stuff a body. buf holds the body and has room for 2 more bytes
 * (the CRC is appended in place); body_len <= QS_MAX_BODY. wire needs
 * QS_MAX_WIRE bytes. Returns the wire length, delimiter included. */
uint8_t qs_frame_encode(uint8_t *buf, uint8_t body_len, uint8_t *wire);

#endif
