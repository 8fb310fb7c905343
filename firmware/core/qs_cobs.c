#include "qs_cobs.h"

void qs_cobs_decoder_reset(qs_cobs_decoder *d)
{
    d->len = 0;
    d->block_left = 0;
    d->zero_pending = 0;
    d->started = 0;
    d->too_long = 0;
}

static void store(qs_cobs_decoder *d, uint8_t byte)
{
    if (d->len == QS_MAX_FRAME)
        d->too_long = 1;
    else
        d->buf[d->len++] = byte;
}

uint8_t qs_cobs_feed(qs_cobs_decoder *d, uint8_t byte)
{
    uint8_t result;

    if (byte == 0) {
        if (d->too_long)
            result = QS_COBS_TOO_LONG;
        else if (!d->started)
            result = QS_COBS_EMPTY;
        else if (d->block_left != 0)
            result = QS_COBS_BAD;
        else
            result = QS_COBS_DONE;
        /* Keep buf and len for the caller; the next byte starts afresh. */
        d->block_left = 0;
        d->zero_pending = 0;
        d->started = 0;
        d->too_long = 0;
        return result;
    }
    if (!d->started) {
        d->started = 1;
        d->len = 0;
    }
    if (d->too_long)
        return QS_COBS_MORE;
    if (d->block_left == 0) {
        /* A code byte: the previous block's implied zero is real only now
         * that more data follows it. */
        if (d->zero_pending)
            store(d, 0);
        d->block_left = (uint8_t)(byte - 1);
        d->zero_pending = (byte != 0xFF);
    } else {
        store(d, byte);
        d->block_left--;
    }
    return QS_COBS_MORE;
}

uint8_t qs_cobs_encode(const uint8_t *in, uint8_t len, uint8_t *out)
{
    uint8_t code_at = 0; /* where the current block's code byte goes */
    uint8_t o = 1;
    uint8_t code = 1;
    uint8_t i;

    for (i = 0; i < len; i++) {
        if (in[i] == 0) {
            out[code_at] = code;
            code_at = o++;
            code = 1;
        } else {
            out[o++] = in[i];
            if (++code == 0xFF) {
                out[code_at] = code;
                code_at = o++;
                code = 1;
            }
        }
    }
    out[code_at] = code;
    return o;
}
