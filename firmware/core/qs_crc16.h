/* CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection. */
#ifndef QS_CRC16_H
#define QS_CRC16_H

#include <stdint.h>

#define QS_CRC16_INIT 0xFFFFu

uint16_t qs_crc16_update(uint16_t crc, uint8_t byte);
uint16_t qs_crc16(const uint8_t *bytes, uint8_t len);

#endif
