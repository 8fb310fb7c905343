/* qs_cubic_sums.h written out for the AVR: an axis's start, its checks,
 * and the wide sums with what they leave in the slot and the chain. The
 * 48-bit sums in r18..r23, the factors' bytes loaded one at a time, each
 * 8 x 8-bit product (mul: r1:r0) added in with its carry run to the top
 * (r24 holds zero). A signed factor's top byte is multiplied as unsigned
 * and the difference, the other factor shifted, taken off after. The host
 * build has the same in C (firmware/core/qs_cubic_sums.c), which
 * tests/simavr/test_avr_forms.py holds these to byte for byte; the simavr
 * step tests hold the board's steps and positions to the host's model. */
#include <stddef.h>

#include "qs_cubic_sums.h"
#include "qs_segment.h"

#define Q_(x) #x
#define Q(x) Q_(x)

/* r1:r0 into the sum at byte k, the carry run on to byte 5. */
#define ADD0 "add r18, r0\n\tadc r19, r1\n\tadc r20, r24\n\tadc r21, r24\n\tadc r22, r24\n\tadc r23, r24\n\t"
#define ADD1 "add r19, r0\n\tadc r20, r1\n\tadc r21, r24\n\tadc r22, r24\n\tadc r23, r24\n\t"
#define ADD2 "add r20, r0\n\tadc r21, r1\n\tadc r22, r24\n\tadc r23, r24\n\t"
#define ADD3 "add r21, r0\n\tadc r22, r1\n\tadc r23, r24\n\t"
#define ADD4 "add r22, r0\n\tadc r23, r1\n\t"
#define SUB0 "sub r18, r0\n\tsbc r19, r1\n\tsbc r20, r24\n\tsbc r21, r24\n\tsbc r22, r24\n\tsbc r23, r24\n\t"
#define SUB1 "sub r19, r0\n\tsbc r20, r1\n\tsbc r21, r24\n\tsbc r22, r24\n\tsbc r23, r24\n\t"
#define SUB2 "sub r20, r0\n\tsbc r21, r1\n\tsbc r22, r24\n\tsbc r23, r24\n\t"
#define SUB3 "sub r21, r0\n\tsbc r22, r1\n\tsbc r23, r24\n\t"
#define SUB4 "sub r22, r0\n\tsbc r23, r1\n\t"
#define SUB5 "sub r23, r0\n\t"

/* The byte at field+j times the factor in r27:r26, into (or out of) the
 * sum at bytes j and j + 1. */
#define MAC(field, j, lo, hi) "ldd r25, Z+%[" field "]+" Q(j) "\n\tmul r25, r26\n\t" lo "mul r25, r27\n\t" hi
#define STORE(field)                                                                                          \
    "std Z+%[" field "]+0, r18\n\tstd Z+%[" field "]+1, r19\n\tstd Z+%[" field "]+2, r20\n\t"                \
    "std Z+%[" field "]+3, r21\n\tstd Z+%[" field "]+4, r22\n\tstd Z+%[" field "]+5, r23\n\t"

#define OPERANDS                                                                                              \
    [i] "n"(offsetof(qs_cubic_terms, i)), [d] "n"(offsetof(qs_cubic_terms, d)),                               \
        [r] "n"(offsetof(qs_cubic_terms, r)), [ahead] "n"(offsetof(qs_cubic_terms, ahead)),                   \
        [n] "n"(offsetof(qs_cubic_terms, n)), [n_less] "n"(offsetof(qs_cubic_terms, n_less)),                 \
        [c2] "n"(offsetof(qs_cubic_terms, c2_less)), [c3] "n"(offsetof(qs_cubic_terms, c3)),                  \
        [last] "n"(offsetof(qs_cubic_terms, last)), [twice] "n"(offsetof(qs_cubic_terms, twice)),          \
        [nr] "n"(offsetof(qs_cubic_terms, nr))

_Static_assert(offsetof(qs_cubic_terms, nr) + 3 <= 63, "ldd and std reach 63 bytes past Z");
_Static_assert(offsetof(qs_cubic_terms, c3.hi) == offsetof(qs_cubic_terms, c3) + 4, "c3 is 6 bytes in a row");
_Static_assert(offsetof(qs_cubic_terms, last.hi) == offsetof(qs_cubic_terms, last) + 4, "last is 6 bytes in a row");
_Static_assert(offsetof(qs_cubic_terms, twice.hi) == offsetof(qs_cubic_terms, twice) + 4, "twice is 6 bytes in a row");

/* i, d, r and ahead lie one after another in t: stored through X as they
 * are loaded through Z. */
_Static_assert(offsetof(qs_cubic_terms, d) == 4 && offsetof(qs_cubic_terms, r) == 8
                   && offsetof(qs_cubic_terms, ahead) == 10,
               "i, d, r, ahead in a row from t");
#define CHAIN(f) ((uint16_t)offsetof(qs_cubic_chain, f))
#define MSG(f) ((uint16_t)offsetof(qs_cubic_msg, f))
_Static_assert(CHAIN(negative) <= 63 && MSG(r) <= 63 && MSG(accel) <= 63, "ldd reaches them");

void qs_cubic_load(qs_cubic_terms *t, const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis)
{
    __asm__ __volatile__(
        "mov r24, %[axis]\n\t"
        "lsl r24\n\t"
        "lsl r24\n\t" /* 4 * axis: the stride of the 32-bit arrays */
        "ldi r25, 1\n\t"
        "sbrc %[axis], 1\n\t"
        "ldi r25, 4\n\t"
        "sbrc %[axis], 0\n\t"
        "lsl r25\n\t" /* 1 << axis */
        "clr r23\n\t" /* the error's sign: kept */
        "movw r30, %[m]\n\t"
        "ldd r22, Z+%[set]\n\t"
        "and r22, r25\n\t"
        "breq 1f\n\t"
        /* a state set: the speed and acceleration of m, and the error
         * turned round if the direction changes */
        "ldd r23, Z+%[m_negative]\n\t"
        "movw r30, %[c]\n\t"
        "ldd r22, Z+%[c_negative]\n\t"
        "eor r23, r22\n\t"
        "and r23, r25\n\t"
        "movw r30, %[m]\n\t"
        "add r30, r24\n\t"
        "adc r31, __zero_reg__\n\t"
        "ldd r18, Z+%[speed]+0\n\tldd r19, Z+%[speed]+1\n\tldd r20, Z+%[speed]+2\n\tldd r21, Z+%[speed]+3\n\t"
        "st X+, r18\n\tst X+, r19\n\tst X+, r20\n\tst X+, r21\n\t"
        "ldd r18, Z+%[accel]+0\n\tldd r19, Z+%[accel]+1\n\tldd r20, Z+%[accel]+2\n\tldd r21, Z+%[accel]+3\n\t"
        "rjmp 2f\n"
        "1:\n\t"
        /* carried: the chain's */
        "movw r30, %[c]\n\t"
        "add r30, r24\n\t"
        "adc r31, __zero_reg__\n\t"
        "ldd r18, Z+%[c_i]+0\n\tldd r19, Z+%[c_i]+1\n\tldd r20, Z+%[c_i]+2\n\tldd r21, Z+%[c_i]+3\n\t"
        "st X+, r18\n\tst X+, r19\n\tst X+, r20\n\tst X+, r21\n\t"
        "ldd r18, Z+%[c_d]+0\n\tldd r19, Z+%[c_d]+1\n\tldd r20, Z+%[c_d]+2\n\tldd r21, Z+%[c_d]+3\n"
        "2:\n\t"
        "st X+, r18\n\tst X+, r19\n\tst X+, r20\n\tst X+, r21\n\t"
        /* the jerk */
        "movw r30, %[m]\n\t"
        "mov r22, %[axis]\n\t"
        "lsl r22\n\t"
        "add r30, r22\n\t"
        "adc r31, __zero_reg__\n\t"
        "ldd r18, Z+%[r]+0\n\tldd r19, Z+%[r]+1\n\t"
        "st X+, r18\n\tst X+, r19\n\t"
        /* ahead = e + Sigma/2 */
        "movw r30, %[c]\n\t"
        "add r30, r24\n\t"
        "adc r31, __zero_reg__\n\t"
        "ldd r18, Z+%[c_e]+0\n\tldd r19, Z+%[c_e]+1\n\tldd r20, Z+%[c_e]+2\n\tldd r21, Z+%[c_e]+3\n\t"
        "tst r23\n\t"
        "breq 3f\n\t"
        "com r21\n\t"
        "com r20\n\t"
        "com r19\n\t"
        "neg r18\n\t"
        "sbci r19, 0xFF\n\t"
        "sbci r20, 0xFF\n\t"
        "sbci r21, 0xFF\n"
        "3:\n\t"
        "subi r21, 0xC0\n\t"
        "st X+, r18\n\tst X+, r19\n\tst X+, r20\n\tst X+, r21"
        : "+x"(t)
        : [c] "r"(c), [m] "r"(m), [axis] "r"(axis), [set] "n"(MSG(set)), [m_negative] "n"(MSG(negative)),
          [c_negative] "n"(CHAIN(negative)), [speed] "n"(MSG(speed)), [accel] "n"(MSG(accel)), [r] "n"(MSG(r)),
          [c_e] "n"(CHAIN(e)), [c_i] "n"(CHAIN(i)), [c_d] "n"(CHAIN(d))
        : "r18", "r19", "r20", "r21", "r22", "r23", "r24", "r25", "r30", "r31", "memory");
}

/* The top byte of the 32-bit q (b0 ... b3, b2 and b3 upper registers) is
 * the sign of its bits 0-23, and q is not -2^23: -2^23 < q < 2^23. Else
 * to 9 (r25 is spoiled). */
#define FITS(b0, b1, b2, b3, k)                                                                               \
    "mov r25, " b2 "\n\tlsl r25\n\tsbc r25, r25\n\tcpse r25, " b3 "\n\trjmp 9f\n\t"                        \
    "cpi " b3 ", 0xFF\n\tbrne " k "f\n\tcpi " b2 ", 0x80\n\tbrne " k "f\n\t"                                \
    "mov r25, " b0 "\n\tor r25, " b1 "\n\tbrne " k "f\n\trjmp 9f\n" k ":\n\t"

uint8_t qs_cubic_check(qs_cubic_terms *t)
{
    register uint8_t kind __asm__("r24");

    __asm__ __volatile__(
        /* nr = n * r: the unsigned product, less n * 2^16 for r < 0 */
        "clr r22\n\t"
        "ldd r26, Z+%[n]\n\t"
        "ldd r27, Z+%[n]+1\n\t"
        "ldd r24, Z+%[r]\n\t"
        "ldd r25, Z+%[r]+1\n\t"
        "mul r26, r24\n\t"
        "movw r18, r0\n\t"
        "mul r27, r25\n\t"
        "movw r20, r0\n\t"
        "mul r26, r25\n\t"
        "add r19, r0\n\t"
        "adc r20, r1\n\t"
        "adc r21, r22\n\t"
        "mul r27, r24\n\t"
        "add r19, r0\n\t"
        "adc r20, r1\n\t"
        "adc r21, r22\n\t"
        "sbrs r25, 7\n\t"
        "rjmp 1f\n\t"
        "sub r20, r26\n\t"
        "sbc r21, r27\n"
        "1:\n\t"
        "std Z+%[nr]+0, r18\n\tstd Z+%[nr]+1, r19\n\tstd Z+%[nr]+2, r20\n\tstd Z+%[nr]+3, r21\n\t"
        /* -2^24 < nr < 2^24 */
        "tst r21\n\t"
        "breq 2f\n\t"
        "cpi r21, 0xFF\n\t"
        "breq 3f\n\t"
        "rjmp 9f\n"
        "3:\n\t"
        "mov r23, r18\n\t"
        "or r23, r19\n\t"
        "or r23, r20\n\t"
        "brne 2f\n\t"
        "rjmp 9f\n"
        "2:\n\t"
        /* d (r22, r23, r26, r27) fits, and so does d + nr (r18 ... r21) */
        "ldd r22, Z+%[d]+0\n\tldd r23, Z+%[d]+1\n\tldd r26, Z+%[d]+2\n\tldd r27, Z+%[d]+3\n\t"
        FITS("r22", "r23", "r26", "r27", "4")
        "add r18, r22\n\tadc r19, r23\n\tadc r20, r26\n\tadc r21, r27\n\t"
        FITS("r18", "r19", "r20", "r21", "5")
        /* d + (n-2)*r = d + nr - 2r, the difference between I(n-1) and
         * I(n); r in r25:r0, its sign in r1 */
        "ldd r25, Z+%[r]\n\t"
        "ldd r0, Z+%[r]+1\n\t"
        "mov r1, r0\n\t"
        "lsl r1\n\t"
        "sbc r1, r1\n\t"
        "sub r18, r25\n\tsbc r19, r0\n\tsbc r20, r1\n\tsbc r21, r1\n\t"
        "sub r18, r25\n\tsbc r19, r0\n\tsbc r20, r1\n\tsbc r21, r1\n\t"
        "ldi r24, %[valid]\n\t"
        /* an extreme inside: d and r nonzero and of opposite signs, that
         * difference of r's sign (and nonzero for r > 0) */
        "mov r1, r22\n\tor r1, r23\n\tor r1, r26\n\tor r1, r27\n\t"
        "breq 6f\n\t"
        "mov r1, r25\n\tor r1, r0\n\t"
        "breq 6f\n\t"
        "mov r1, r27\n\teor r1, r0\n\t"
        "brpl 6f\n\t"
        "mov r1, r21\n\teor r1, r0\n\t"
        "brmi 6f\n\t"
        "sbrc r0, 7\n\t"
        "rjmp 7f\n\t"
        "mov r1, r18\n\tor r1, r19\n\tor r1, r20\n\tor r1, r21\n\t"
        "breq 6f\n"
        "7:\n\t"
        "ori r24, %[extreme]\n"
        "6:\n\t"
        /* moving: curved if d or r is nonzero; else steady, or at rest
         * (i = 0: done) */
        "mov r1, r22\n\tor r1, r23\n\tor r1, r26\n\tor r1, r27\n\tor r1, r25\n\tor r1, r0\n\t"
        "breq 6f\n\t"
        "ori r24, %[moving] | %[curved]\n\t"
        "rjmp 8f\n"
        "6:\n\t"
        "ldd r18, Z+%[i]+0\n\tldd r19, Z+%[i]+1\n\tldd r20, Z+%[i]+2\n\tldd r21, Z+%[i]+3\n\t"
        "or r18, r19\n\tor r18, r20\n\tor r18, r21\n\t"
        "breq 10f\n\t"
        "ori r24, %[moving]\n"
        "8:\n\t"
        /* i <= Sigma */
        "ldd r21, Z+%[i]+3\n\t"
        "cpi r21, 0x80\n\t"
        "brlo 10f\n\t"
        "brne 9f\n\t"
        "ldd r18, Z+%[i]+0\n\tldd r19, Z+%[i]+1\n\tldd r20, Z+%[i]+2\n\t"
        "or r18, r19\n\tor r18, r20\n\t"
        "breq 10f\n"
        "9:\n\t"
        "clr r24\n"
        "10:\n\t"
        "clr __zero_reg__"
        : "=&r"(kind)
        : [t] "z"(t), OPERANDS, [valid] "n"(QS_CUBIC_VALID), [moving] "n"(QS_CUBIC_MOVING),
          [curved] "n"(QS_CUBIC_CURVED), [extreme] "n"(QS_CUBIC_EXTREME)
        : "r18", "r19", "r20", "r21", "r22", "r23", "r25", "r26", "r27", "memory");
    return kind;
}

uint8_t qs_cubic_last(qs_cubic_terms *t)
{
    register uint8_t ok __asm__("r24");

    __asm__ __volatile__(
        "ldd r18, Z+%[i]+0\n\t"
        "ldd r19, Z+%[i]+1\n\t"
        "ldd r20, Z+%[i]+2\n\t"
        "ldd r21, Z+%[i]+3\n\t"
        "clr r22\n\t"
        "clr r23\n\t"
        "clr r24\n\t"
        /* + (n-1) * d, d's three bytes */
        "ldd r26, Z+%[n_less]\n\t"
        "ldd r27, Z+%[n_less]+1\n\t"
        MAC("d", 0, ADD0, ADD1)
        MAC("d", 1, ADD1, ADD2)
        MAC("d", 2, ADD2, ADD3)
        "sbrs r25, 7\n\t" /* d < 0: less (n-1) * 2^24 */
        "rjmp 1f\n\t"
        "sub r21, r26\n\t"
        "sbc r22, r27\n\t"
        "sbc r23, r24\n"
        "1:\n\t"
        /* + C(n-1, 2) * r */
        "ldd r26, Z+%[r]\n\t"
        "ldd r27, Z+%[r]+1\n\t"
        "mov r25, r26\n\t"
        "or r25, r27\n\t"
        "breq 2f\n\t"
        MAC("c2", 0, ADD0, ADD1)
        MAC("c2", 1, ADD1, ADD2)
        MAC("c2", 2, ADD2, ADD3)
        MAC("c2", 3, ADD3, ADD4)
        "sbrs r27, 7\n\t" /* r < 0: less C(n-1, 2) * 2^16 */
        "rjmp 2f\n\t"
        "ldd r25, Z+%[c2]+0\n\t"
        "sub r20, r25\n\t"
        "ldd r25, Z+%[c2]+1\n\t"
        "sbc r21, r25\n\t"
        "ldd r25, Z+%[c2]+2\n\t"
        "sbc r22, r25\n\t"
        "ldd r25, Z+%[c2]+3\n\t"
        "sbc r23, r25\n"
        "2:\n\t"
        STORE("last")
        "clr __zero_reg__\n\t"
        /* 0 <= last <= Sigma: bits 32-47 clear, and below 2^31 or Sigma */
        "ldi r24, 0\n\t"
        "or r22, r23\n\t"
        "brne 3f\n\t"
        "cpi r21, 0x80\n\t"
        "brlo 4f\n\t"
        "brne 3f\n\t"
        "or r18, r19\n\t"
        "or r18, r20\n\t"
        "brne 3f\n"
        "4:\n\t"
        "ldi r24, 1\n"
        "3:"
        : "=&r"(ok)
        : [t] "z"(t), OPERANDS
        : "r18", "r19", "r20", "r21", "r22", "r23", "r25", "r26", "r27", "memory");
    return ok;
}

/* Where finish puts an axis's fields: from the slot (or end) plus the axis
 * times each array's stride. */
#define SLOT(f) ((uint16_t)offsetof(qs_segment, f))
_Static_assert(SLOT(c.b) - SLOT(c.h) == 4 * QS_AXIS_COUNT && SLOT(c.h) <= 63, "h, then b, 4 bytes an axis");
_Static_assert(SLOT(c.r) - SLOT(c.q) == 3 * QS_AXIS_COUNT && SLOT(c.q) <= 63, "q, then r, 3 bytes an axis");
_Static_assert(SLOT(c.e_top) <= 63 && SLOT(active) <= 63 && SLOT(tick_axes) <= 63 && SLOT(cubic) <= 63
                   && SLOT(ends_moving) <= 63,
               "adiw and ldd reach them");
_Static_assert(sizeof(qs_i24) == 3 && sizeof(((qs_segment *)0)->total[0]) == 2, "the widths written");
_Static_assert(offsetof(qs_cubic_ends, i) == 4 * QS_AXIS_COUNT && offsetof(qs_cubic_ends, d) == 8 * QS_AXIS_COUNT,
               "e, i, d, 4 bytes an axis");

void qs_cubic_finish(qs_cubic_terms *t, qs_segment *slot, uint8_t axis, qs_cubic_ends *end)
{
    __asm__ __volatile__(
        /* i + I(n), 33 bits: parked in twice (bit 32 in T) until the sum
         * is built there */
        "ldd r18, Z+%[i]+0\n\t"
        "ldd r19, Z+%[i]+1\n\t"
        "ldd r20, Z+%[i]+2\n\t"
        "ldd r21, Z+%[i]+3\n\t"
        "ldd r25, Z+%[last]+0\n\t"
        "add r18, r25\n\t"
        "ldd r25, Z+%[last]+1\n\t"
        "adc r19, r25\n\t"
        "ldd r25, Z+%[last]+2\n\t"
        "adc r20, r25\n\t"
        "ldd r25, Z+%[last]+3\n\t"
        "adc r21, r25\n\t"
        "clr r22\n\t" /* leaves the carry */
        "adc r22, r22\n\t"
        "bst r22, 0\n\t"
        "std Z+%[twice]+0, r18\n\t"
        "std Z+%[twice]+1, r19\n\t"
        "std Z+%[twice]+2, r20\n\t"
        "std Z+%[twice]+3, r21\n\t"
        /* 2 * (e + Sigma/2) */
        "ldd r18, Z+%[ahead]+0\n\t"
        "ldd r19, Z+%[ahead]+1\n\t"
        "ldd r20, Z+%[ahead]+2\n\t"
        "ldd r21, Z+%[ahead]+3\n\t"
        "clr r22\n\t"
        "clr r23\n\t"
        "clr r24\n\t"
        "lsl r18\n\t"
        "rol r19\n\t"
        "rol r20\n\t"
        "rol r21\n\t"
        "rol r22\n\t"
        /* + n * (i + I(n)) */
        "ldd r26, Z+%[n]\n\t"
        "ldd r27, Z+%[n]+1\n\t"
        MAC("twice", 0, ADD0, ADD1)
        MAC("twice", 1, ADD1, ADD2)
        MAC("twice", 2, ADD2, ADD3)
        MAC("twice", 3, ADD3, ADD4)
        "brtc 1f\n\t"
        "add r22, r26\n\t"
        "adc r23, r27\n"
        "1:\n\t"
        /* - C(n, 3) * r: six bytes of C(n, 3), the products past 2^48 left out */
        "ldd r26, Z+%[r]\n\t"
        "ldd r27, Z+%[r]+1\n\t"
        "mov r25, r26\n\t"
        "or r25, r27\n\t"
        "breq 2f\n\t"
        MAC("c3", 0, SUB0, SUB1)
        MAC("c3", 1, SUB1, SUB2)
        MAC("c3", 2, SUB2, SUB3)
        MAC("c3", 3, SUB3, SUB4)
        "ldd r25, Z+%[c3]+4\n\t"
        "mul r25, r26\n\t"
        SUB4
        "mul r25, r27\n\t"
        SUB5
        "ldd r25, Z+%[c3]+5\n\t"
        "mul r25, r26\n\t"
        SUB5
        "sbrs r27, 7\n\t" /* r < 0: C(n, 3) * (r + 2^16) came off: give back C(n, 3) * 2^16 */
        "rjmp 2f\n\t"
        "ldd r25, Z+%[c3]+0\n\t"
        "add r20, r25\n\t"
        "ldd r25, Z+%[c3]+1\n\t"
        "adc r21, r25\n\t"
        "ldd r25, Z+%[c3]+2\n\t"
        "adc r22, r25\n\t"
        "ldd r25, Z+%[c3]+3\n\t"
        "adc r23, r25\n"
        "2:\n\t"
        STORE("twice")
        "clr __zero_reg__\n\t"
        /* r0 the axis, X the end state, Y the slot (saved: it may be the
         * frame pointer) */
        "mov r0, %[axis]\n\t"
        "movw r26, %[end]\n\t"
        "push r28\n\t"
        "push r29\n\t"
        "movw r28, %[slot]\n\t"
        "mov r24, r0\n\t"
        "lsl r24\n\t"
        "lsl r24\n\t"
        "add r26, r24\n\t"
        "adc r27, __zero_reg__\n\t"
        /* e = twice's bits 1-31, less Sigma/2 */
        "lsr r21\n\t"
        "ror r20\n\t"
        "ror r19\n\t"
        "ror r18\n\t"
        "subi r21, 0x40\n\t"
        "st X+, r18\n\tst X+, r19\n\tst X+, r20\n\tst X+, r21\n\t"
        /* d + nr */
        "ldd r18, Z+%[d]+0\n\tldd r19, Z+%[d]+1\n\tldd r20, Z+%[d]+2\n\tldd r21, Z+%[d]+3\n\t"
        "ldd r22, Z+%[nr]+0\n\tldd r23, Z+%[nr]+1\n\tldd r24, Z+%[nr]+2\n\tldd r25, Z+%[nr]+3\n\t"
        "add r22, r18\n\tadc r23, r19\n\tadc r24, r20\n\tadc r25, r21\n\t"
        "adiw r26, %[to_d]\n\t"
        "st X+, r22\n\tst X+, r23\n\tst X+, r24\n\tst X+, r25\n\t"
        "sbiw r26, %[back_i]\n\t"
        /* I(n+1) = last + (d + nr) - r */
        "ldd r18, Z+%[last]+0\n\tldd r19, Z+%[last]+1\n\tldd r20, Z+%[last]+2\n\tldd r21, Z+%[last]+3\n\t"
        "add r18, r22\n\tadc r19, r23\n\tadc r20, r24\n\tadc r21, r25\n\t"
        "or r22, r23\n\tor r22, r24\n\tor r22, r25\n\t"
        "ldd r24, Z+%[r]\n\tldd r25, Z+%[r]+1\n\t"
        "clr r23\n\tsbrc r25, 7\n\tcom r23\n\t"
        "sub r18, r24\n\tsbc r19, r25\n\tsbc r20, r23\n\tsbc r21, r23\n\t"
        "st X+, r18\n\tst X+, r19\n\tst X+, r20\n\tst X+, r21\n\t"
        "or r22, r18\n\tor r22, r19\n\tor r22, r20\n\tor r22, r21\n\t"
        "breq 3f\n\t" /* it ends moving */
        "ldi r22, %[moving]\n\t"
        "std Y+%[ends_moving], r22\n"
        "3:\n\t"
        /* h = ahead + i - Sigma, b = i + d - Sigma */
        "movw r26, r28\n\t"
        "mov r24, r0\n\t"
        "lsl r24\n\t"
        "lsl r24\n\t"
        "add r26, r24\n\t"
        "adc r27, __zero_reg__\n\t"
        "adiw r26, %[h]\n\t"
        "ldd r18, Z+%[i]+0\n\tldd r19, Z+%[i]+1\n\tldd r20, Z+%[i]+2\n\tldd r21, Z+%[i]+3\n\t"
        "ldd r22, Z+%[ahead]+0\n\tldd r23, Z+%[ahead]+1\n\tldd r24, Z+%[ahead]+2\n\tldd r25, Z+%[ahead]+3\n\t"
        "add r22, r18\n\tadc r23, r19\n\tadc r24, r20\n\tadc r25, r21\n\t"
        "subi r25, 0x80\n\t"
        "st X+, r22\n\tst X+, r23\n\tst X+, r24\n\tst X+, r25\n\t"
        "adiw r26, %[to_b]\n\t"
        "ldd r22, Z+%[d]+0\n\tldd r23, Z+%[d]+1\n\tldd r24, Z+%[d]+2\n\tldd r25, Z+%[d]+3\n\t"
        "add r22, r18\n\tadc r23, r19\n\tadc r24, r20\n\tadc r25, r21\n\t"
        "subi r25, 0x80\n\t"
        "st X+, r22\n\tst X+, r23\n\tst X+, r24\n\tst X+, r25\n\t"
        /* q = d and r, 24 bits each */
        "movw r26, r28\n\t"
        "mov r24, r0\n\t"
        "lsl r24\n\t"
        "add r24, r0\n\t"
        "add r26, r24\n\t"
        "adc r27, __zero_reg__\n\t"
        "adiw r26, %[q]\n\t"
        "ldd r22, Z+%[d]+0\n\tldd r23, Z+%[d]+1\n\tldd r24, Z+%[d]+2\n\t"
        "st X+, r22\n\tst X+, r23\n\tst X+, r24\n\t"
        "adiw r26, %[to_r]\n\t"
        "ldd r22, Z+%[r]\n\tldd r23, Z+%[r]+1\n\t"
        "clr r24\n\tsbrc r23, 7\n\tcom r24\n\t"
        "st X+, r22\n\tst X+, r23\n\tst X+, r24\n\t"
        /* e's top byte: ahead's, less Sigma/2 */
        "movw r26, r28\n\t"
        "add r26, r0\n\t"
        "adc r27, __zero_reg__\n\t"
        "adiw r26, %[e_top]\n\t"
        "ldd r24, Z+%[ahead]+3\n\t"
        "subi r24, 0x40\n\t"
        "st X, r24\n\t"
        /* the steps: twice's bits 32-47 */
        "movw r26, r28\n\t"
        "mov r24, r0\n\t"
        "lsl r24\n\t"
        "add r26, r24\n\t"
        "adc r27, __zero_reg__\n\t"
        "subi r26, lo8(-(%[total]))\n\t"
        "sbci r27, hi8(-(%[total]))\n\t"
        "ldd r24, Z+%[twice]+4\n\t"
        "st X+, r24\n\t"
        "ldd r24, Z+%[twice]+5\n\t"
        "st X, r24\n\t"
        /* the flags: r25 = 1 << axis (axis 0 ... 3) */
        "ldi r25, 1\n\t"
        "sbrc r0, 1\n\t"
        "ldi r25, 4\n\t"
        "sbrc r0, 0\n\t"
        "lsl r25\n\t"
        "ldd r24, Y+%[active]\n\t"
        "or r24, r25\n\t"
        "std Y+%[active], r24\n\t"
        "ldd r24, Y+%[tick_axes]\n\t"
        "or r24, r25\n\t"
        "ldd r22, Z+%[r]\n\t"
        "ldd r23, Z+%[r]+1\n\t"
        "or r22, r23\n\t"
        "brne 4f\n\t" /* r = 0: q never changes */
        "mov r23, r25\n\t"
        "swap r23\n\t"
        "or r24, r23\n\t"
        "ldd r18, Z+%[d]+0\n\tldd r19, Z+%[d]+1\n\tldd r20, Z+%[d]+2\n\tldd r21, Z+%[d]+3\n\t"
        "or r18, r19\n\tor r18, r20\n\tor r18, r21\n\t"
        "brne 4f\n\t" /* and d = 0: nor does b */
        "ldd r23, Y+%[cubic]\n\t"
        "or r23, r25\n\t"
        "std Y+%[cubic], r23\n"
        "4:\n\t"
        "std Y+%[tick_axes], r24\n\t"
        "pop r29\n\t"
        "pop r28"
        :
        : [t] "z"(t), [slot] "r"(slot), [end] "r"(end), [axis] "r"(axis), OPERANDS,
          [to_d] "n"(8 * QS_AXIS_COUNT - 4), [back_i] "n"(4 * QS_AXIS_COUNT + 4), [moving] "n"(QS_ENDS_MOVING),
          [h] "n"(SLOT(c.h)), [to_b] "n"(4 * QS_AXIS_COUNT - 4), [q] "n"(SLOT(c.q)),
          [to_r] "n"(3 * QS_AXIS_COUNT - 3), [e_top] "n"(SLOT(c.e_top)), [total] "n"(SLOT(total)),
          [active] "n"(SLOT(active)), [tick_axes] "n"(SLOT(tick_axes)), [cubic] "n"(SLOT(cubic)),
          [ends_moving] "n"(SLOT(ends_moving))
        : "r18", "r19", "r20", "r21", "r22", "r23", "r24", "r25", "r26", "r27", "memory");
}
