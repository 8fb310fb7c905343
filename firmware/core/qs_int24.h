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

#endif
