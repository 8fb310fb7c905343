/* 48-bit sums built from 16-bit products, for the main loop's per-segment
 * work on cubic segments (qs_cubic.c).
 *
 * A cubic segment's sums (an advance of up to n steps in 2^-31 step, terms
 * up to C(n, 3)*r) need more than 32 bits but only modulo 2^48: a valid
 * segment's totals are below 2^47, and the advance over any tick, whose
 * range is checked, below 2^47 in magnitude whatever the fields. The AVR
 * multiplies 8 x 8 bits in hardware; avr-gcc 5.4 widens sums like these to
 * 64 bits and calls its library routines for them, so on the AVR the
 * products and carry chains are written out (the host build, and the
 * tests, use the plain C beside each). */
#ifndef QS_WIDE_H
#define QS_WIDE_H

#include <stdint.h>
#include "qs_config.h"

typedef struct {
    uint32_t lo; /* bits 0-31 */
    uint16_t hi; /* bits 32-47 */
} qs_w48;

static QS_ALWAYS_INLINE qs_w48 qs_w48_of(uint32_t x)
{
    qs_w48 a;
    a.lo = x;
    a.hi = 0;
    return a;
}

#if !defined(__AVR__)
static inline uint64_t qs_w48_value(qs_w48 a)
{
    return (uint64_t)a.lo | (uint64_t)a.hi << 32;
}

static inline qs_w48 qs_w48_from(uint64_t v)
{
    qs_w48 a;
    a.lo = (uint32_t)v;
    a.hi = (uint16_t)(v >> 32);
    return a;
}
#endif

/* a += p, p signed (sign-extended). */
static QS_ALWAYS_INLINE void qs_w48_add(qs_w48 *a, int32_t p)
{
#if defined(__AVR__)
    uint8_t sign;
    __asm__("mov %2, %D3\n\t"
            "lsl %2\n\t"
            "sbc %2, %2\n\t" /* 0 or 0xFF */
            "add %A0, %A3\n\t"
            "adc %B0, %B3\n\t"
            "adc %C0, %C3\n\t"
            "adc %D0, %D3\n\t"
            "adc %A1, %2\n\t"
            "adc %B1, %2"
            : "+r"(a->lo), "+r"(a->hi), "=&r"(sign)
            : "r"(p));
#else
    *a = qs_w48_from(qs_w48_value(*a) + (uint64_t)(int64_t)p);
#endif
}

/* a += p * 2^16 (p a 32-bit pattern: bits past 47 drop, so signed or not
 * is the same). */
static QS_ALWAYS_INLINE void qs_w48_add_16(qs_w48 *a, uint32_t p)
{
#if defined(__AVR__)
    __asm__("add %C0, %A2\n\t"
            "adc %D0, %B2\n\t"
            "adc %A1, %C2\n\t"
            "adc %B1, %D2"
            : "+r"(a->lo), "+r"(a->hi)
            : "r"(p));
#else
    *a = qs_w48_from(qs_w48_value(*a) + ((uint64_t)p << 16));
#endif
}

/* a -= b */
static QS_ALWAYS_INLINE void qs_w48_sub(qs_w48 *a, qs_w48 b)
{
#if defined(__AVR__)
    __asm__("sub %A0, %A2\n\t"
            "sbc %B0, %B2\n\t"
            "sbc %C0, %C2\n\t"
            "sbc %D0, %D2\n\t"
            "sbc %A1, %A3\n\t"
            "sbc %B1, %B3"
            : "+r"(a->lo), "+r"(a->hi)
            : "r"(b.lo), "r"(b.hi));
#else
    *a = qs_w48_from(qs_w48_value(*a) - qs_w48_value(b));
#endif
}

/* a += x * y, both unsigned: eight 8 x 8-bit products, each added in with
 * its carry run to the top (about 50 cycles on the AVR). */
static QS_ALWAYS_INLINE void qs_w48_mac(qs_w48 *a, uint32_t x, uint16_t y)
{
#if defined(__AVR__)
    uint8_t zero;
    __asm__("clr %[z]\n\t"
            "mul %A[x], %A[y]\n\t"
            "add %A[lo], r0\n\t"
            "adc %B[lo], r1\n\t"
            "adc %C[lo], %[z]\n\t"
            "adc %D[lo], %[z]\n\t"
            "adc %A[hi], %[z]\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %A[x], %B[y]\n\t"
            "add %B[lo], r0\n\t"
            "adc %C[lo], r1\n\t"
            "adc %D[lo], %[z]\n\t"
            "adc %A[hi], %[z]\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %B[x], %A[y]\n\t"
            "add %B[lo], r0\n\t"
            "adc %C[lo], r1\n\t"
            "adc %D[lo], %[z]\n\t"
            "adc %A[hi], %[z]\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %B[x], %B[y]\n\t"
            "add %C[lo], r0\n\t"
            "adc %D[lo], r1\n\t"
            "adc %A[hi], %[z]\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %C[x], %A[y]\n\t"
            "add %C[lo], r0\n\t"
            "adc %D[lo], r1\n\t"
            "adc %A[hi], %[z]\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %C[x], %B[y]\n\t"
            "add %D[lo], r0\n\t"
            "adc %A[hi], r1\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %D[x], %A[y]\n\t"
            "add %D[lo], r0\n\t"
            "adc %A[hi], r1\n\t"
            "adc %B[hi], %[z]\n\t"
            "mul %D[x], %B[y]\n\t"
            "add %A[hi], r0\n\t"
            "adc %B[hi], r1\n\t"
            "clr __zero_reg__"
            : [lo] "+r"(a->lo), [hi] "+r"(a->hi), [z] "=&r"(zero)
            : [x] "r"(x), [y] "r"(y));
#else
    *a = qs_w48_from(qs_w48_value(*a) + (uint64_t)x * y);
#endif
}

/* a += x * y for a signed x or y: the unsigned product of the patterns,
 * less the other factor times 2^32 (x < 0) or times 2^16 (y < 0). */
static QS_ALWAYS_INLINE void qs_w48_mac_sx(qs_w48 *a, int32_t x, uint16_t y)
{
    qs_w48_mac(a, (uint32_t)x, y);
    if (x < 0)
        a->hi = (uint16_t)(a->hi - y);
}

static QS_ALWAYS_INLINE void qs_w48_mac_sy(qs_w48 *a, uint32_t x, int16_t y)
{
    qs_w48_mac(a, x, (uint16_t)y);
    if (y < 0)
        qs_w48_add_16(a, (uint32_t)0 - x);
}

/* a += x * y for a 48-bit x and a signed y (|y| <= 2^15: y = 2^15 is
 * allowed, as the negation of the least 16-bit value). */
static QS_ALWAYS_INLINE void qs_w48_mac_48(qs_w48 *a, qs_w48 x, int32_t y)
{
    qs_w48_mac(a, x.lo, (uint16_t)y);
    if (y < 0)
        qs_w48_add_16(a, (uint32_t)0 - x.lo);
    a->hi = (uint16_t)(a->hi + (uint16_t)(x.hi * (uint16_t)y));
}

/* a * b, the 32-bit product of two 16-bit factors (four 8 x 8-bit ones). */
static QS_ALWAYS_INLINE uint32_t qs_umul16(uint16_t a, uint16_t b)
{
#if defined(__AVR__)
    uint32_t p;
    __asm__("mul %A1, %A2\n\t"
            "mov %A0, r0\n\t"
            "mov %B0, r1\n\t"
            "mul %B1, %B2\n\t"
            "mov %C0, r0\n\t"
            "mov %D0, r1\n\t"
            "mul %A1, %B2\n\t"
            "add %B0, r0\n\t"
            "adc %C0, r1\n\t"
            "clr __zero_reg__\n\t" /* leaves the carry */
            "adc %D0, __zero_reg__\n\t"
            "mul %B1, %A2\n\t"
            "add %B0, r0\n\t"
            "adc %C0, r1\n\t"
            "clr __zero_reg__\n\t"
            "adc %D0, __zero_reg__"
            : "=&r"(p)
            : "r"(a), "r"(b));
    return p;
#else
    return (uint32_t)a * b;
#endif
}

/* a * b for a signed b: the unsigned product less a * 2^16 when b < 0. */
static QS_ALWAYS_INLINE int32_t qs_usmul16(uint16_t a, int16_t b)
{
    uint32_t p = qs_umul16(a, (uint16_t)b);
    if (b < 0)
        p -= (uint32_t)a << 16;
    return (int32_t)p;
}

#endif
