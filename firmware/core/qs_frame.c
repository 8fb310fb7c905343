#include "qs_frame.h"
#include "qs_crc16.h"
#include "qs_protocol.h"

void qs_frame_rx_init(qs_frame_rx *rx)
{
    qs_cobs_decoder_reset(&rx->cobs);
    rx->overrun = 0;
}

void qs_frame_rx_overrun(qs_frame_rx *rx)
{
    rx->overrun = 1;
}

static uint8_t check_frame(const qs_cobs_decoder *d)
{
    uint16_t crc;

    if (d->len < QS_MIN_FRAME)
        return QS_ERR_FRAME_TOO_SHORT;
    crc = qs_crc16(d->buf, (uint8_t)(d->len - 2));
    if (d->buf[d->len - 2] != (uint8_t)crc || d->buf[d->len - 1] != (uint8_t)(crc >> 8))
        return QS_ERR_BAD_CRC;
    return QS_FRAME_READY;
}

uint8_t qs_frame_rx_byte(qs_frame_rx *rx, uint8_t byte)
{
    uint8_t cobs = qs_cobs_feed(&rx->cobs, byte);
    uint8_t overrun;

    if (cobs == QS_COBS_MORE)
        return QS_FRAME_NOTHING;
    overrun = rx->overrun;
    rx->overrun = 0;
    if (cobs == QS_COBS_TOO_LONG)
        return QS_ERR_FRAME_TOO_LONG;
    if (overrun)
        return QS_ERR_RX_OVERRUN; /* even for an empty frame: bytes were lost */
    if (cobs == QS_COBS_EMPTY)
        return QS_FRAME_NOTHING;
    if (cobs == QS_COBS_BAD)
        return QS_ERR_BAD_COBS;
    return check_frame(&rx->cobs);
}

uint8_t qs_frame_encode(uint8_t *buf, uint8_t body_len, uint8_t *wire)
{
    uint16_t crc = qs_crc16(buf, body_len);
    uint8_t n;

    buf[body_len] = (uint8_t)crc;
    buf[body_len + 1] = (uint8_t)(crc >> 8);
    n = qs_cobs_encode(buf, (uint8_t)(body_len + 2), wire);
    wire[n] = 0;
    return (uint8_t)(n + 1);
}
