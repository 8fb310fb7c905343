#include "qs_crc16.h"

#if !defined(__AVR__) /* the AVR's is table-driven: firmware/avr/crc16.c */

/* qs_crc16_update with the two bytes kept apart across the loop. */
uint16_t qs_crc16(const uint8_t *bytes, uint8_t len)
{
    uint8_t hi = (uint8_t)(QS_CRC16_INIT >> 8), lo = (uint8_t)QS_CRC16_INIT;

    while (len--) {
        uint8_t x = (uint8_t)(hi ^ *bytes++);
        x ^= (uint8_t)(x >> 4);
        hi = (uint8_t)(lo ^ (uint8_t)(x << 4) ^ (uint8_t)(x >> 3));
        lo = (uint8_t)(x ^ (uint8_t)(x << 5));
    }
    return (uint16_t)((uint16_t)(hi << 8) | lo);
}
#endif
