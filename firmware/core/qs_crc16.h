/* CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection. */
#ifndef QS_CRC16_H
#define QS_CRC16_H

#include <stdint.h>

#define QS_CRC16_INIT 0xFFFFu

/* Byte-wise and branch-free: the eight shift-and-xor rounds of the bit-wise
 * CRC collapse into three shifted copies of one nibble-folded byte, so no
 * 512-byte table is needed on the AVR. Written on the two bytes apart,
 * which avr-gcc turns into about 20 single-cycle instructions. */
static inline uint16_t qs_crc16_update(uint16_t crc, uint8_t byte)
{
    uint8_t x = (uint8_t)((crc >> 8) ^ byte);
    uint8_t hi, lo;

    x ^= (uint8_t)(x >> 4);
    hi = (uint8_t)((uint8_t)crc ^ (uint8_t)(x << 4) ^ (uint8_t)(x >> 3));
    lo = (uint8_t)(x ^ (uint8_t)(x << 5));
    return (uint16_t)((uint16_t)(hi << 8) | lo);
}

uint16_t qs_crc16(const uint8_t *bytes, uint8_t len);

#endif
