#include "qs_varint.h"

const uint8_t *qs_varint_skip(const uint8_t *p, const uint8_t *end, uint8_t most)
{
    while (p != end && most--)
        if (!(*p++ & 0x80u))
            return p;
    return 0;
}

uint32_t qs_varint_read(const uint8_t **at)
{
    const uint8_t *p = *at;
    uint32_t u = 0;
    uint8_t shift = 0;

    do {
        u |= (uint32_t)(*p & 0x7Fu) << shift;
        shift = (uint8_t)(shift + 7);
    } while (*p++ & 0x80u);
    *at = p;
    return u;
}

int32_t qs_varint_read_signed(const uint8_t **at)
{
    const uint32_t u = qs_varint_read(at);

    return (int32_t)((u >> 1) ^ (uint32_t)-(int32_t)(u & 1u));
}

int16_t qs_varint_read_signed16(const uint8_t **at)
{
    const uint8_t *p = *at;
    uint16_t u = p[0] & 0x7Fu;

    if (p[0] & 0x80u) {
        u |= (uint16_t)((uint16_t)p[1] << 7);
        p++;
    }
    *at = p + 1;
    return (int16_t)((u >> 1) ^ (uint16_t)-(int16_t)(u & 1u));
}
