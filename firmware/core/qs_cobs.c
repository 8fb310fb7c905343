#include "qs_cobs.h"
#include "qs_config.h"

QS_NOINLINE uint8_t qs_cobs_decode(uint8_t *buf, uint8_t len)
{
    uint8_t at = buf[0]; /* where the next code byte stands */

    if (at > len)
        return QS_COBS_BAD;
    while (at != len) {
        const uint8_t code = buf[at];
        buf[at] = 0;
        if (code > (uint8_t)(len - at))
            return QS_COBS_BAD; /* the block runs past the delimiter */
        at = (uint8_t)(at + code);
    }
    return QS_COBS_DONE;
}

/* Shorter than 254 bytes, no block fills up (254 data bytes), so a code
 * byte stands only where a zero is or where the data begin: each holds the
 * distance to the next zero, or to the end. */
void qs_cobs_stuff(uint8_t *buf, uint8_t len)
{
    /* pointers, not indices: the AVR walks them with ld X+ */
    uint8_t *code = buf, *p = buf + 1;
    const uint8_t *const end = buf + len + 1;

    for (; p != end; p++) {
        if (*p == 0) {
            *code = (uint8_t)(p - code);
            code = p;
        }
    }
    *code = (uint8_t)(end - code);
}

uint8_t qs_cobs_encode(const uint8_t *in, uint8_t len, uint8_t *out)
{
    uint8_t i;

    for (i = 0; i < len; i++)
        out[i + 1] = in[i];
    qs_cobs_stuff(out, len);
    return (uint8_t)(len + 1);
}
