/* Frames: COBS(body || crc16) || 0x00. Receiving keeps a frame's wire bytes
 * as they come (a store per byte) and checks the whole frame at its
 * delimiter, in the order of PROTOCOL.md section 2, for everything that
 * does not depend on the message type; sending seals a body with its CRC
 * and stuffs it. */
#ifndef QS_FRAME_H
#define QS_FRAME_H

#include <stdint.h>
#include "qs_cobs.h"

/* qs_frame_rx_byte result besides an ERROR code (1..7). */
#define QS_FRAME_NOTHING 0
#define QS_FRAME_READY 0xFF

/* Wire bytes of the longest frame, delimiter excluded: QS_MAX_FRAME decoded
 * bytes and one code byte (a frame this short needs no other overhead).
 * One more means more than QS_MAX_FRAME decoded bytes. */
#define QS_FRAME_WIRE_MAX (QS_MAX_WIRE - 1)

typedef struct {
    uint8_t buf[QS_FRAME_WIRE_MAX]; /* wire bytes; decoded in place (from buf[1]) at the delimiter */
    uint8_t len;                    /* wire bytes stored */
    uint8_t too_long;               /* more came than buf holds */
    uint8_t overrun;                /* bytes were lost while this frame arrived */
    uint8_t decoded;                /* the last good frame's decoded length */
} qs_frame_rx;

void qs_frame_rx_init(qs_frame_rx *rx);

/* The receiver lost bytes: the frame in progress will be rejected. */
void qs_frame_rx_overrun(qs_frame_rx *rx);

/* A delimiter: check the frame and start the next (see qs_frame_rx_byte). */
uint8_t qs_frame_rx_end(qs_frame_rx *rx);

/* A wire byte other than the delimiter: stored (a frame too long to store
 * is noted and refused at its delimiter). Inline: it runs for every byte. */
static inline void qs_frame_rx_store(qs_frame_rx *rx, uint8_t byte)
{
    const uint8_t n = rx->len;

    if (n < QS_FRAME_WIRE_MAX) {
        rx->buf[n] = byte;
        rx->len = (uint8_t)(n + 1);
    } else {
        rx->too_long = 1;
    }
}

/* Store the wire bytes of a run up to the first delimiter among them that
 * ends a frame (not taken); returns how many were taken. Delimiters with
 * nothing before them (empty frames: ignored, unless bytes were lost) are
 * taken here too, so a line full of them costs the receive loop little.
 * What the receive loop of a target runs for bytes that arrived together:
 * one loop, no call per byte. */
static inline uint8_t qs_frame_rx_copy(qs_frame_rx *rx, const uint8_t *bytes, uint8_t len)
{
    /* pointers, not indices: the AVR walks them with ld X+ and st Z+ */
    const uint8_t *from = bytes;
    const uint8_t *const stop = bytes + len;
    uint8_t *to = rx->buf + rx->len;
    const uint8_t *const full = rx->buf + QS_FRAME_WIRE_MAX;

    while (from != stop) {
        const uint8_t byte = *from;
        if (byte == 0) {
            if (to == rx->buf && !rx->too_long && !rx->overrun) {
                from++;
                continue;
            }
            break;
        }
        from++;
        if (to != full)
            *to++ = byte;
        else
            rx->too_long = 1;
    }
    rx->len = (uint8_t)(to - rx->buf);
    return (uint8_t)(from - bytes);
}

/* Feed one wire byte. Returns QS_FRAME_NOTHING, QS_FRAME_READY (the body,
 * without CRC, is qs_frame_body(rx) / qs_frame_body_len(rx) until the next
 * call) or the framing error code of a rejected frame. */
static inline uint8_t qs_frame_rx_byte(qs_frame_rx *rx, uint8_t byte)
{
    if (byte == 0)
        return qs_frame_rx_end(rx);
    qs_frame_rx_store(rx, byte);
    return QS_FRAME_NOTHING;
}

static inline const uint8_t *qs_frame_body(const qs_frame_rx *rx) { return rx->buf + 1; }
static inline uint8_t qs_frame_body_len(const qs_frame_rx *rx) { return (uint8_t)(rx->decoded - 2); }

/* Where a body goes in a frame buffer of QS_MAX_WIRE bytes: after the
 * place of the first code byte, so that it is sealed and stuffed in place. */
#define QS_FRAME_BODY(frame) ((frame) + 1)

/* Seal the body of body_len <= QS_MAX_BODY bytes at QS_FRAME_BODY(frame):
 * the CRC is appended, the whole stuffed in place and the delimiter put
 * after it. Returns the wire length, delimiter included. */
uint8_t qs_frame_seal(uint8_t *frame, uint8_t body_len);

/* The same for a body elsewhere: buf holds the body and has room for 2
 * more bytes; wire needs QS_MAX_WIRE bytes. */
uint8_t qs_frame_encode(uint8_t *buf, uint8_t body_len, uint8_t *wire);

#endif
