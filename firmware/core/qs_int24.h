/* The per-tick integer type. Every per-tick value of the step engine stays
 * within +-(2*n*D + 3*D) = +-8,384,512 < 2^23 (docs/FIXED_POINT.md), so the
 * AVR uses its native 24-bit integer: a third cheaper than 32 bits. */
#ifndef QS_INT24_H
#define QS_INT24_H

#include <stdint.h>

#if defined(__AVR__)
typedef __int24 qs_i24;
typedef __uint24 qs_u24; /* counts below 2^24: steps and ticks of a hold */
#else
typedef int32_t qs_i24;
typedef uint32_t qs_u24;
#endif

#define QS_I24_MAX 8388607L
#define QS_I24_MIN (-8388608L)

/* A 24-bit pattern (bits above 23 ignored) as the signed value it holds:
 * the AVR's type wraps by itself, a 32-bit one needs bit 23 copied up. */
static inline qs_i24 qs_i24_from_bits(qs_u24 u)
{
#if defined(__AVR__)
    return (qs_i24)u;
#else
    return (qs_i24)((u & 0xFFFFFFu) ^ 0x800000u) - (qs_i24)0x800000;
#endif
}

#endif
