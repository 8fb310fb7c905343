/* The engine's per-axis decisions (qs_engine_axis_tick in
 * qs_engine_tick.h, and qs_hold_axis_tick in qs_hold_tick.h for a hold)
 * written out for the AVR, with the same effect.
 *
 * avr-gcc compiles the C version into much the same instructions, but
 * spreads the 24-bit values of successive axes over different registers,
 * and the step interrupt must save every register it touches: 4 cycles
 * each, every tick. Here every axis uses the same six scratch registers
 * (r18..r20 and r22..r24, call-clobbered), so the interrupt saves few. The tests in
 * tests/simavr hold the board's steps to the emulator's, which runs the C
 * version, step for step. */
#ifndef QS_AXIS_TICK_H
#define QS_AXIS_TICK_H

#include <stddef.h>
#include <stdint.h>

#include "qs_hold.h"
#include "qs_segment.h"

/* steps | (1 << axis) if the axis steps at the next tick; s in Z, axes
 * its tick_axes. */
static inline __attribute__((always_inline)) uint8_t axis_tick(qs_segment *s, uint8_t axis, uint8_t axes,
                                                               uint8_t steps)
{
    register qs_u24 x __asm__("r18");
    register qs_u24 y __asm__("r22");

    __asm__ __volatile__(
        "sbrs %[axes], %[axis]\n\t"
        "rjmp 3f\n\t"
        /* x = h; a step if h >= 0, else h += 2*C2 */
        "ldd %A[x], Z+%[h]\n\t"
        "ldd %B[x], Z+%[h]+1\n\t"
        "ldd %C[x], Z+%[h]+2\n\t"
        "sbrs %C[x], 7\n\t"
        "rjmp 1f\n\t"
        "ldd %A[y], Z+%[c2]\n\t"
        "ldd %B[y], Z+%[c2]+1\n\t"
        "ldd %C[y], Z+%[c2]+2\n\t"
        "add %A[x], %A[y]\n\t"
        "adc %B[x], %B[y]\n\t"
        "adc %C[x], %C[y]\n\t"
        "rjmp 2f\n"
        "1:\n\t"
        "ori %[steps], %[bit]\n"
        "2:\n\t"
        /* h += b */
        "ldd %A[y], Z+%[b]\n\t"
        "ldd %B[y], Z+%[b]+1\n\t"
        "ldd %C[y], Z+%[b]+2\n\t"
        "add %A[x], %A[y]\n\t"
        "adc %B[x], %B[y]\n\t"
        "adc %C[x], %C[y]\n\t"
        "std Z+%[h], %A[x]\n\t"
        "std Z+%[h]+1, %B[x]\n\t"
        "std Z+%[h]+2, %C[x]\n\t"
        /* b += db, unless the speed is steady */
        "sbrc %[axes], %[axis]+4\n\t"
        "rjmp 3f\n\t"
        "ldd %A[x], Z+%[db]\n\t"
        "ldd %B[x], Z+%[db]+1\n\t"
        "ldd %C[x], Z+%[db]+2\n\t"
        "add %A[y], %A[x]\n\t"
        "adc %B[y], %B[x]\n\t"
        "adc %C[y], %C[x]\n\t"
        "std Z+%[b], %A[y]\n\t"
        "std Z+%[b]+1, %B[y]\n\t"
        "std Z+%[b]+2, %C[y]\n"
        "3:"
        : [x] "=&r"(x), [y] "=&r"(y), [steps] "+d"(steps)
        : [s] "z"(s), [axes] "r"(axes), [axis] "n"(axis), [bit] "n"(1u << axis),
          [h] "n"(offsetof(qs_segment, h) + 3u * axis), [b] "n"(offsetof(qs_segment, b) + 3u * axis),
          [db] "n"(offsetof(qs_segment, db) + 3u * axis), [c2] "n"(offsetof(qs_segment, two_c2))
        : "memory");
    return steps;
}

/* steps | (1 << axis) if the axis steps at the next tick of a hold, and
 * the axis's bit cleared in moving when it stops; hd in Z. */
static inline __attribute__((always_inline)) uint8_t hold_axis_tick(qs_hold *hd, uint8_t axis, uint8_t *moving,
                                                                    uint8_t steps)
{
    register qs_u24 x __asm__("r18");
    register qs_u24 y __asm__("r22");
    uint8_t m = *moving;

    __asm__ __volatile__(
        "sbrs %[m], %[axis]\n\t"
        "rjmp 9f\n\t"
        /* x = h; a step if h >= 0: h -= 2knD */
        "ldd %A[x], Z+%[h]\n\t"
        "ldd %B[x], Z+%[h]+1\n\t"
        "ldd %C[x], Z+%[h]+2\n\t"
        "sbrc %C[x], 7\n\t"
        "rjmp 2f\n\t"
        "ori %[steps], %[bit]\n\t"
        "ldd %A[y], Z+%[c2]\n\t"
        "ldd %B[y], Z+%[c2]+1\n\t"
        "ldd %C[y], Z+%[c2]+2\n\t"
        "sub %A[x], %A[y]\n\t"
        "sbc %B[x], %B[y]\n\t"
        "sbc %C[x], %C[y]\n"
        "2:\n\t"
        /* h += inc */
        "ldd %A[y], Z+%[inc]\n\t"
        "ldd %B[y], Z+%[inc]+1\n\t"
        "ldd %C[y], Z+%[inc]+2\n\t"
        "add %A[x], %A[y]\n\t"
        "adc %B[x], %B[y]\n\t"
        "adc %C[x], %C[y]\n\t"
        "std Z+%[h], %A[x]\n\t"
        "std Z+%[h]+1, %B[x]\n\t"
        "std Z+%[h]+2, %C[x]\n\t"
        /* inc <= 0: stop; else inc += db */
        "sbrc %C[y], 7\n\t"
        "rjmp 3f\n\t"
        "mov %A[x], %A[y]\n\t"
        "or %A[x], %B[y]\n\t"
        "or %A[x], %C[y]\n\t"
        "breq 3f\n\t"
        "ldd %A[x], Z+%[db]\n\t"
        "ldd %B[x], Z+%[db]+1\n\t"
        "ldd %C[x], Z+%[db]+2\n\t"
        "add %A[y], %A[x]\n\t"
        "adc %B[y], %B[x]\n\t"
        "adc %C[y], %C[x]\n\t"
        "std Z+%[inc], %A[y]\n\t"
        "std Z+%[inc]+1, %B[y]\n\t"
        "std Z+%[inc]+2, %C[y]\n\t"
        "rjmp 9f\n"
        "3:\n\t"
        "andi %[m], %[clear]\n"
        "9:"
        : [x] "=&r"(x), [y] "=&r"(y), [steps] "+d"(steps), [m] "+d"(m)
        : [hd] "z"(hd), [axis] "n"(axis), [bit] "n"(1u << axis), [clear] "n"((uint8_t)~(1u << axis)),
          [h] "n"(offsetof(qs_hold, h) + 3u * axis), [inc] "n"(offsetof(qs_hold, inc) + 3u * axis),
          [db] "n"(offsetof(qs_hold, db) + 3u * axis),
          [c2] "n"(offsetof(qs_hold, two_c2))
        : "memory");
    *moving = m;
    return steps;
}

_Static_assert(offsetof(qs_segment, two_c2) + 2u <= 63u, "ldd reaches 63 bytes past Z");
_Static_assert(offsetof(qs_hold, two_c2) + 2u <= 63u, "ldd reaches 63 bytes past Z");
_Static_assert(sizeof(qs_i24) == 3, "24-bit engine values");


/* The cubic segment's decisions for every axis at once (qs_cubic_axis_tick
 * in qs_engine_tick.h, the same effect), in one block so that the steps
 * can build up in r0 (each axis writes its bit with bst/bld: the bit is set
 * when the axis does NOT step, and the block ends with a complement) and
 * the slot's tick_axes stays in r24. Per axis the 32-bit h and b and the
 * 24-bit q and r stream through r18..r25 (r's bytes through r1, cleared
 * after) and are added byte by byte from memory: ldd/std leave the carry
 * alone. Without a step h gains Sigma = 2^31, with one nothing: either way
 * its top bit ends clear (andi). q is sign-extended into b's top byte with
 * adc 0 and a conditional dec. The rarer paths (r = 0, steady) branch out
 * of line, so a jerk phase runs straight through: 71 cycles per axis. */
#define QS_STR_(x) #x
#define QS_STR(x) QS_STR_(x)
#define QS_CUBIC_AXIS_ASM(A)                                                                                  \
    "sbrs r24, " QS_STR(A) "\n\t"                                                                             \
    "rjmp .Ldone%=_" QS_STR(A) "\n\t"                                                                         \
    "ldd r18, Z+%[h" QS_STR(A) "]+3\n\t"                                                                      \
    "bst r18, 7\n\t"                                                                                          \
    "bld r0, " QS_STR(A) "\n\t"                                                                               \
    "andi r18, 0x7F\n\t"                                                                                      \
    "ldd r19, Z+%[b" QS_STR(A) "]\n\t"                                                                        \
    "ldd r20, Z+%[b" QS_STR(A) "]+1\n\t"                                                                      \
    "ldd r22, Z+%[b" QS_STR(A) "]+2\n\t"                                                                      \
    "ldd r23, Z+%[b" QS_STR(A) "]+3\n\t"                                                                      \
    "ldd r25, Z+%[h" QS_STR(A) "]\n\t"                                                                        \
    "add r25, r19\n\t"                                                                                        \
    "std Z+%[h" QS_STR(A) "], r25\n\t"                                                                        \
    "ldd r25, Z+%[h" QS_STR(A) "]+1\n\t"                                                                      \
    "adc r25, r20\n\t"                                                                                        \
    "std Z+%[h" QS_STR(A) "]+1, r25\n\t"                                                                      \
    "ldd r25, Z+%[h" QS_STR(A) "]+2\n\t"                                                                      \
    "adc r25, r22\n\t"                                                                                        \
    "std Z+%[h" QS_STR(A) "]+2, r25\n\t"                                                                      \
    "adc r18, r23\n\t"                                                                                        \
    "std Z+%[h" QS_STR(A) "]+3, r18\n\t"                                                                      \
    "sbrc r24, " QS_STR(A) "+4\n\t"                                                                           \
    "rjmp .Lnoj%=_" QS_STR(A) "\n\t"                                                                          \
    "ldd r18, Z+%[q" QS_STR(A) "]\n\t"                                                                        \
    "ldd r1, Z+%[r" QS_STR(A) "]\n\t"                                                                         \
    "add r18, r1\n\t"                                                                                         \
    "std Z+%[q" QS_STR(A) "], r18\n\t"                                                                        \
    "ldd r21, Z+%[q" QS_STR(A) "]+1\n\t"                                                                      \
    "ldd r1, Z+%[r" QS_STR(A) "]+1\n\t"                                                                       \
    "adc r21, r1\n\t"                                                                                         \
    "std Z+%[q" QS_STR(A) "]+1, r21\n\t"                                                                      \
    "ldd r25, Z+%[q" QS_STR(A) "]+2\n\t"                                                                      \
    "ldd r1, Z+%[r" QS_STR(A) "]+2\n\t"                                                                       \
    "adc r25, r1\n\t"                                                                                         \
    "std Z+%[q" QS_STR(A) "]+2, r25\n\t"                                                                      \
    "clr __zero_reg__\n"                                                                                       \
    ".Lbq%=_" QS_STR(A) ":\n\t"                                                                               \
    "add r19, r18\n\t"                                                                                        \
    "adc r20, r21\n\t"                                                                                        \
    "adc r22, r25\n\t"                                                                                        \
    "adc r23, __zero_reg__\n\t"                                                                               \
    "sbrc r25, 7\n\t"                                                                                         \
    "dec r23\n\t"                                                                                             \
    "std Z+%[b" QS_STR(A) "], r19\n\t"                                                                        \
    "std Z+%[b" QS_STR(A) "]+1, r20\n\t"                                                                      \
    "std Z+%[b" QS_STR(A) "]+2, r22\n\t"                                                                      \
    "std Z+%[b" QS_STR(A) "]+3, r23\n"                                                                         \
    ".Ldone%=_" QS_STR(A) ":\n\t"

/* Out of line: r = 0 (q stays), and steady (b stays too). */
#define QS_CUBIC_AXIS_RARE_ASM(A)                                                                             \
    ".Lnoj%=_" QS_STR(A) ":\n\t"                                                                              \
    "ldd r18, Z+%[st]\n\t"                                                                                    \
    "sbrc r18, " QS_STR(A) "\n\t"                                                                             \
    "rjmp .Ldone%=_" QS_STR(A) "\n\t"                                                                         \
    "ldd r18, Z+%[q" QS_STR(A) "]\n\t"                                                                        \
    "ldd r21, Z+%[q" QS_STR(A) "]+1\n\t"                                                                      \
    "ldd r25, Z+%[q" QS_STR(A) "]+2\n\t"                                                                      \
    "rjmp .Lbq%=_" QS_STR(A) "\n\t"

#define QS_CUBIC_OFF(field, axis) (offsetof(qs_segment, c) + offsetof(qs_cubic_run, field) + sizeof(((qs_cubic_run *)0)->field[0]) * (axis))
#define QS_CUBIC_AXIS_OPERANDS(A)                                                                             \
    [h##A] "n"(QS_CUBIC_OFF(h, A)), [b##A] "n"(QS_CUBIC_OFF(b, A)), [q##A] "n"(QS_CUBIC_OFF(q, A)),           \
        [r##A] "n"(QS_CUBIC_OFF(r, A))

#if QS_AXIS_COUNT == 3
#define QS_CUBIC_AXES_ASM QS_CUBIC_AXIS_ASM(0) QS_CUBIC_AXIS_ASM(1) QS_CUBIC_AXIS_ASM(2)
#define QS_CUBIC_RARE_ASM QS_CUBIC_AXIS_RARE_ASM(0) QS_CUBIC_AXIS_RARE_ASM(1) QS_CUBIC_AXIS_RARE_ASM(2)
#define QS_CUBIC_OPERANDS QS_CUBIC_AXIS_OPERANDS(0), QS_CUBIC_AXIS_OPERANDS(1), QS_CUBIC_AXIS_OPERANDS(2)
#elif QS_AXIS_COUNT == 4
#define QS_CUBIC_AXES_ASM QS_CUBIC_AXIS_ASM(0) QS_CUBIC_AXIS_ASM(1) QS_CUBIC_AXIS_ASM(2) QS_CUBIC_AXIS_ASM(3)
#define QS_CUBIC_RARE_ASM                                                                                     \
    QS_CUBIC_AXIS_RARE_ASM(0) QS_CUBIC_AXIS_RARE_ASM(1) QS_CUBIC_AXIS_RARE_ASM(2) QS_CUBIC_AXIS_RARE_ASM(3)
#define QS_CUBIC_OPERANDS                                                                                     \
    QS_CUBIC_AXIS_OPERANDS(0), QS_CUBIC_AXIS_OPERANDS(1), QS_CUBIC_AXIS_OPERANDS(2), QS_CUBIC_AXIS_OPERANDS(3)
#else
#error "the AVR cubic tick is written for 3 or 4 axes"
#endif

static inline __attribute__((always_inline)) uint8_t cubic_axes_tick(qs_segment *s)
{
    register uint8_t steps __asm__("r24");

    __asm__ __volatile__(
        "clr r0\n\t"
        "com r0\n\t"
        "ldd r24, Z+%[ta]\n\t"
        QS_CUBIC_AXES_ASM
        "rjmp .Lend%=\n\t"
        QS_CUBIC_RARE_ASM
        ".Lend%=:\n\t"
        "mov r24, r0\n\t"
        "com r24"
        : "=&r"(steps)
        : [s] "z"(s), [ta] "n"(offsetof(qs_segment, tick_axes)), [st] "n"(offsetof(qs_segment, cubic)),
          QS_CUBIC_OPERANDS
        : "r18", "r19", "r20", "r21", "r22", "r23", "r25", "memory");
    return steps;
}

_Static_assert(QS_CUBIC_OFF(r, QS_AXIS_COUNT - 1) + 2u <= 63u, "ldd reaches 63 bytes past Z");

#define QS_CUBIC_AXES_TICK(s, axes, steady) cubic_axes_tick(s)

#define QS_ENGINE_AXIS_TICK(s, axis, axes, steps) axis_tick(s, axis, axes, steps)
#define QS_HOLD_AXIS_TICK(hd, axis, moving, steps) hold_axis_tick(hd, axis, &(moving), steps)

#endif
