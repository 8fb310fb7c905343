/* Consistent Overhead Byte Stuffing: an incremental decoder fed one byte at a
 * time into a bounded buffer, and a block encoder. */
#ifndef QS_COBS_H
#define QS_COBS_H

#include <stdint.h>
#include "qs_protocol.h"

/* What a byte completed. */
#define QS_COBS_MORE 0      /* inside a frame, or discarding */
#define QS_COBS_EMPTY 1     /* delimiter with nothing before it: ignore */
#define QS_COBS_DONE 2      /* a well-formed block: buf[0..len) */
#define QS_COBS_TOO_LONG 3  /* more than QS_MAX_FRAME decoded bytes */
#define QS_COBS_BAD 4       /* a code byte pointed past the delimiter */

typedef struct {
    uint8_t buf[QS_MAX_FRAME];
    uint8_t len;          /* decoded bytes stored */
    uint8_t block_left;   /* data bytes still due in this block; 0: next is a code byte */
    uint8_t zero_pending; /* the block ends in an implied zero, if more follows */
    uint8_t started;      /* a byte arrived since the last delimiter */
    uint8_t too_long;     /* overflowed: discard until the delimiter */
} qs_cobs_decoder;

void qs_cobs_decoder_reset(qs_cobs_decoder *d);

/* Feed one wire byte; on DONE the block is in d->buf, d->len, valid until
 * the next call. */
uint8_t qs_cobs_feed(qs_cobs_decoder *d, uint8_t byte);

/* Encode len bytes (len <= 254) into out, which needs len + 1 bytes; no
 * delimiter is written. Returns the encoded length. */
uint8_t qs_cobs_encode(const uint8_t *in, uint8_t len, uint8_t *out);

#endif
