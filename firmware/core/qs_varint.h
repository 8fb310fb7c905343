/* The varints of SEGMENTS and CUBIC_SEGMENTS records (PROTOCOL.md section
 * 5): 7 bits a byte, lowest first, the top bit set on every byte but the
 * last; signed values zigzag-coded (0, -1, 1, -2, ... as 0, 1, 2, 3, ...).
 * Parsing checks that each is whole (qs_varint_skip); the readers, used
 * once a frame is taken, trust that. */
#ifndef QS_VARINT_H
#define QS_VARINT_H

#include <stdint.h>

/* Past a varint of at most `most` bytes that ends before end, or 0. */
const uint8_t *qs_varint_skip(const uint8_t *p, const uint8_t *end, uint8_t most);

/* A varint of at most 5 bytes, under 2^32; *at moves past it. */
uint32_t qs_varint_read(const uint8_t **at);

/* The same, zigzag-decoded. */
int32_t qs_varint_read_signed(const uint8_t **at);

/* A zigzag varint of one or two bytes (SEGMENTS' fields), in 16 bits:
 * no 32-bit shifts on the AVR's path of every quadratic record. */
int16_t qs_varint_read_signed16(const uint8_t **at);

#endif
