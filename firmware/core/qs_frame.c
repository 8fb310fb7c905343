#include "qs_frame.h"
#include "qs_crc16.h"
#include "qs_protocol.h"

void qs_frame_rx_init(qs_frame_rx *rx)
{
    rx->len = 0;
    rx->too_long = 0;
    rx->overrun = 0;
    rx->decoded = 0;
}

void qs_frame_rx_overrun(qs_frame_rx *rx)
{
    rx->overrun = 1;
}

static uint8_t check_frame(qs_frame_rx *rx, uint8_t len)
{
    const uint8_t *body = rx->buf + 1;
    const uint8_t decoded = (uint8_t)(len - 1);
    uint16_t crc;

    if (qs_cobs_decode(rx->buf, len) != QS_COBS_DONE)
        return QS_ERR_BAD_COBS;
    if (decoded < QS_MIN_FRAME)
        return QS_ERR_FRAME_TOO_SHORT;
    crc = qs_crc16(body, (uint8_t)(decoded - 2));
    if (body[decoded - 2] != (uint8_t)crc || body[decoded - 1] != (uint8_t)(crc >> 8))
        return QS_ERR_BAD_CRC;
    rx->decoded = decoded;
    return QS_FRAME_READY;
}

uint8_t qs_frame_rx_end(qs_frame_rx *rx)
{
    const uint8_t len = rx->len, too_long = rx->too_long, overrun = rx->overrun;

    /* The next byte starts afresh. */
    rx->len = 0;
    rx->too_long = 0;
    rx->overrun = 0;
    if (too_long)
        return QS_ERR_FRAME_TOO_LONG;
    if (overrun)
        return QS_ERR_RX_OVERRUN; /* even for an empty frame: bytes were lost */
    if (len == 0)
        return QS_FRAME_NOTHING;
    return check_frame(rx, len);
}

uint8_t qs_frame_seal(uint8_t *frame, uint8_t body_len)
{
    uint8_t *body = QS_FRAME_BODY(frame);
    const uint16_t crc = qs_crc16(body, body_len);
    const uint8_t len = (uint8_t)(body_len + 2);

    body[body_len] = (uint8_t)crc;
    body[body_len + 1] = (uint8_t)(crc >> 8);
    qs_cobs_stuff(frame, len);
    frame[len + 1] = 0;
    return (uint8_t)(len + 2);
}

uint8_t qs_frame_encode(uint8_t *buf, uint8_t body_len, uint8_t *wire)
{
    uint8_t i;

    for (i = 0; i < body_len; i++)
        QS_FRAME_BODY(wire)[i] = buf[i];
    return qs_frame_seal(wire, body_len);
}
