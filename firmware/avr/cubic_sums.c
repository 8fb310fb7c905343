/* The wide sums of qs_cubic_sums.h written out for the AVR: the 48-bit
 * sum in r18..r23, the factors' bytes loaded one at a time, each 8 x 8-bit
 * product (mul: r1:r0) added in with its carry run to the top (r24 holds
 * zero). A signed factor's top byte is multiplied as unsigned and the
 * difference, the other factor shifted, taken off after. The host build
 * has the same sums in C (firmware/core/qs_cubic.c); the simavr tests hold
 * the board's steps and positions to the host's model. */
#include <stddef.h>

#include "qs_cubic_sums.h"

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
        [last] "n"(offsetof(qs_cubic_terms, last)), [twice] "n"(offsetof(qs_cubic_terms, twice))

_Static_assert(offsetof(qs_cubic_terms, twice) + 5 <= 63, "ldd and std reach 63 bytes past Z");
_Static_assert(offsetof(qs_cubic_terms, c3.hi) == offsetof(qs_cubic_terms, c3) + 4, "c3 is 6 bytes in a row");
_Static_assert(offsetof(qs_cubic_terms, last.hi) == offsetof(qs_cubic_terms, last) + 4, "last is 6 bytes in a row");
_Static_assert(offsetof(qs_cubic_terms, twice.hi) == offsetof(qs_cubic_terms, twice) + 4, "twice is 6 bytes in a row");

void qs_cubic_last(qs_cubic_terms *t)
{
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
        "clr __zero_reg__"
        :
        : [t] "z"(t), OPERANDS
        : "r18", "r19", "r20", "r21", "r22", "r23", "r24", "r25", "r26", "r27", "memory");
}

void qs_cubic_twice(qs_cubic_terms *t)
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
        "clr __zero_reg__"
        :
        : [t] "z"(t), OPERANDS
        : "r18", "r19", "r20", "r21", "r22", "r23", "r24", "r25", "r26", "r27", "memory");
}
