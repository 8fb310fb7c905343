/* qs_crc16 (qs_crc16.h) for the AVR, from two 256-byte tables in flash:
 * about 14 cycles a byte against the 22 of the table-free byte step in
 * the core (firmware/core/qs_crc16.c, the host build's). The tables are
 * that step's closed form for each value of the byte it folds in, made by
 * the preprocessor, and sit on 256-byte boundaries, the low one right
 * after the high one, so that a byte's entries are one `lpm` apart. */
#include <avr/pgmspace.h>
#include <stdint.h>

#include "qs_crc16.h"

/* For x = the CRC's high byte xor the byte: the CRC of x shifted through
 * eight rounds, as its two bytes (the core's qs_crc16_update with 0 in). */
#define FOLD(x) ((x) ^ ((x) >> 4))
#define HI(x) ((uint8_t)((FOLD(x) << 4) ^ (FOLD(x) >> 3)))
#define LO(x) ((uint8_t)(FOLD(x) ^ (FOLD(x) << 5)))
#define ROW(F, x)                                                                                             \
    F(x), F(x + 1), F(x + 2), F(x + 3), F(x + 4), F(x + 5), F(x + 6), F(x + 7), F(x + 8), F(x + 9),          \
        F(x + 10), F(x + 11), F(x + 12), F(x + 13), F(x + 14), F(x + 15)
#define TABLE(F)                                                                                              \
    ROW(F, 0), ROW(F, 16), ROW(F, 32), ROW(F, 48), ROW(F, 64), ROW(F, 80), ROW(F, 96), ROW(F, 112),          \
        ROW(F, 128), ROW(F, 144), ROW(F, 160), ROW(F, 176), ROW(F, 192), ROW(F, 208), ROW(F, 224), ROW(F, 240)

static const uint8_t crc_tables[2][256] __attribute__((aligned(256))) PROGMEM = {{TABLE(HI)}, {TABLE(LO)}};

uint16_t qs_crc16(const uint8_t *bytes, uint8_t len)
{
    uint8_t hi = (uint8_t)(QS_CRC16_INIT >> 8), lo = (uint8_t)QS_CRC16_INIT;
    const uint8_t *table = crc_tables[0];

    if (!len)
        return QS_CRC16_INIT;
    __asm__ __volatile__(
        "1:\n\t"
        "ld r30, X+\n\t" /* the byte, xor the high byte: the entries' index */
        "eor r30, %[hi]\n\t"
        "mov r31, %B[table]\n\t"
        "lpm %[hi], Z\n\t"
        "eor %[hi], %[lo]\n\t"
        "inc r31\n\t"
        "lpm %[lo], Z\n\t"
        "dec %[len]\n\t"
        "brne 1b"
        : [hi] "+r"(hi), [lo] "+r"(lo), [len] "+r"(len), [p] "+x"(bytes)
        : [table] "r"(table)
        : "r30", "r31");
    return (uint16_t)((uint16_t)(hi << 8) | lo);
}
