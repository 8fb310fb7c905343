/* Consistent Overhead Byte Stuffing: block decoding in place and encoding. */
#ifndef QS_COBS_H
#define QS_COBS_H

#include <stdint.h>
#include "qs_protocol.h"

/* What decoding found. */
#define QS_COBS_DONE 2      /* a well-formed block */
#define QS_COBS_BAD 4       /* a code byte pointed past the end */

/* Decode the len encoded bytes in buf (no delimiter; len < 255) in place:
 * the decoded bytes are buf[1 .. len), len - 1 of them (valid only on
 * DONE). Shorter than 255 bytes, a well-formed block has no 0xFF code
 * (that would announce 254 data bytes), so every code byte after the
 * first stands where its block's implied zero goes: decoding only walks
 * the chain of code bytes and writes those zeros, and moves no data. */
uint8_t qs_cobs_decode(uint8_t *buf, uint8_t len);

/* Encode in place the len bytes (len < 254) at buf[1 .. len]: buf[0] and
 * every zero among them become code bytes. No delimiter is written; the
 * encoded block is buf[0 .. len]. */
void qs_cobs_stuff(uint8_t *buf, uint8_t len);

/* The same from in to out, which needs len + 1 bytes. Returns len + 1. */
uint8_t qs_cobs_encode(const uint8_t *in, uint8_t len, uint8_t *out);

_Static_assert(QS_MAX_FRAME < 254, "frames short enough for COBS blocks that never fill up");

#endif
