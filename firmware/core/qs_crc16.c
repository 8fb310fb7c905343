#include "qs_crc16.h"

/* Byte-wise and branch-free: the eight shift-and-xor rounds of the bit-wise
 * CRC collapse into three shifted copies of one nibble-folded byte, so no
 * 512-byte table is needed on the AVR. */
uint16_t qs_crc16_update(uint16_t crc, uint8_t byte)
{
    uint8_t x = (uint8_t)((crc >> 8) ^ byte);
    x ^= (uint8_t)(x >> 4);
    return (uint16_t)((crc << 8) ^ ((uint16_t)x << 12) ^ ((uint16_t)x << 5) ^ x);
}

uint16_t qs_crc16(const uint8_t *bytes, uint8_t len)
{
    uint16_t crc = QS_CRC16_INIT;
    while (len--)
        crc = qs_crc16_update(crc, *bytes++);
    return crc;
}
