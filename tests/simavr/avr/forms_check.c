/* The AVR's written-out forms of core functions against their C forms:
 * - the cubic sums (firmware/avr/cubic_sums.c; firmware/core/qs_cubic_sums.c
 *   built here for the AVR as ref_*), on pseudo-random axes weighted to the
 *   edges of every check: the widths of d, n*r and d + n*r, i around Sigma,
 *   the signs that make an extreme, at rest;
 * - the receive loop's copy (firmware/avr/frame_rx.h; qs_frame_rx_copy),
 *   on random runs of bytes with delimiters among them, into frames empty,
 *   part-filled and full, clean or marked too long or overrun.
 * Run in simavr (test_avr_forms.py); prints two lines:
 *     cubic-sums trials T checked C mismatches M [first: ...]
 *     rx-copy runs R mismatches M [first: ...]
 * then stops the CPU. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <string.h>

#include "frame_rx.h"
#include "qs_cubic_sums.h"
#include "qs_frame.h"

#ifndef TRIALS
#define TRIALS 6000u
#endif
#ifndef RX_RUNS
#define RX_RUNS 20000u
#endif

void ref_load(qs_cubic_terms *t, const qs_cubic_chain *c, const qs_cubic_msg *m, uint8_t axis);
uint8_t ref_check(qs_cubic_terms *t);
uint8_t ref_last(qs_cubic_terms *t);
void ref_finish(qs_cubic_terms *t, qs_segment *slot, uint8_t axis, qs_cubic_ends *end);

static uint32_t seed = 0x2545F491u;

static uint32_t rnd(void)
{
    seed ^= seed << 13;
    seed ^= seed >> 17;
    seed ^= seed << 5;
    return seed;
}

static void put(char ch)
{
    while (!(UCSR0A & _BV(UDRE0))) {
    }
    UDR0 = (uint8_t)ch;
}

static void put_text(const char *s)
{
    while (*s)
        put(*s++);
}

static void put_hex(const void *p, uint8_t len)
{
    const uint8_t *b = p;
    while (len--) {
        put("0123456789abcdef"[*b >> 4]);
        put("0123456789abcdef"[*b & 15]);
        b++;
    }
}

static void put_u32(uint32_t v)
{
    char buf[11];
    uint8_t k = 0;
    do {
        buf[k++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (k)
        put(buf[--k]);
}

/* A 32-bit value near one of the edges the checks test, or anywhere. */
static uint32_t edgy(uint32_t edge)
{
    switch (rnd() & 7) {
    case 0:
        return 0;
    case 1:
    case 2:
        return edge + (uint32_t)(int32_t)(int8_t)rnd(); /* a few either side */
    case 3:
        return (uint32_t)0 - edge + (uint32_t)(int32_t)(int8_t)rnd();
    case 4:
        return rnd() >> (rnd() & 31);
    case 5:
        return (uint32_t)0 - (rnd() >> (rnd() & 31));
    default:
        return rnd();
    }
}

static uint16_t some_n(void)
{
    switch (rnd() & 3) {
    case 0:
        return (uint16_t)(1 + (rnd() & 7));
    case 1:
        return (uint16_t)(rnd() | 1u); /* anything but 0 */
    default:
        return (uint16_t)(1 + (rnd() & 1023));
    }
}

static void counts(qs_cubic_terms *t, uint16_t n)
{
    const uint64_t m = n;
    const uint64_t c3 = m < 3 ? 0 : m * (m - 1) * (m - 2) / 6;
    t->n = n;
    t->n_less = (uint16_t)(n - 1);
    t->c2_less = n < 3 ? 0 : (uint32_t)((m - 1) * (m - 2) / 2);
    t->c3.lo = (uint32_t)c3;
    t->c3.hi = (uint16_t)(c3 >> 32);
}

static uint32_t mismatches, checked;

static void mismatch(const char *what, uint32_t trial, const void *a, const void *b, uint8_t len)
{
    if (mismatches++ == 0) {
        put_text(" first: ");
        put_text(what);
        put_text(" trial ");
        put_u32(trial);
        put(' ');
        put_hex(a, len);
        put(' ');
        put_hex(b, len);
    }
}

int main(void)
{
    uint32_t trial;

    UCSR0A = _BV(U2X0);
    UBRR0 = 3; /* 500 kbaud */
    UCSR0B = _BV(TXEN0);
    put_text("cubic-sums");
    for (trial = 0; trial < TRIALS; trial++) {
        static qs_cubic_chain chain;
        static qs_cubic_msg msg;
        static qs_cubic_terms a, b;
        static qs_segment slot_a, slot_b;
        static qs_cubic_ends end_a, end_b;
        uint8_t axis = (uint8_t)(rnd() % QS_AXIS_COUNT), kind_a, kind_b, k;

        /* load: a chain and a message, every field random */
        for (k = 0; k < sizeof chain; k++)
            ((uint8_t *)&chain)[k] = (uint8_t)rnd();
        for (k = 0; k < sizeof msg; k++)
            ((uint8_t *)&msg)[k] = (uint8_t)rnd();
        memset(&a, 0x5A, sizeof a);
        memset(&b, 0x5A, sizeof b);
        ref_load(&a, &chain, &msg, axis);
        qs_cubic_load(&b, &chain, &msg, axis);
        if (memcmp(&a, &b, sizeof a) != 0)
            mismatch("load", trial, &a, &b, sizeof a);

        /* check: the axis's fields near their edges */
        counts(&a, some_n());
        a.i = (rnd() & 1) ? edgy(QS_SIGMA) : (rnd() >> 1);
        a.d = (int32_t)((rnd() & 1) ? edgy(QS_CUBIC_ACCEL_LIMIT) : ((rnd() & 1) ? 0 : edgy(rnd() >> (rnd() & 31))));
        a.r = (int16_t)((rnd() & 3) == 0 ? 0 : (rnd() & 1) ? (int16_t)(rnd() >> (rnd() & 15)) : (int16_t)rnd());
        if ((rnd() & 7) == 0) {
            /* d + n*r at the edge of the width */
            a.d = (int32_t)((uint32_t)((rnd() & 1) ? QS_CUBIC_ACCEL_LIMIT : -QS_CUBIC_ACCEL_LIMIT)
                            - (uint32_t)((int32_t)a.n * a.r) + (uint32_t)(int32_t)(int8_t)(rnd() & 3));
        }
        if ((rnd() & 7) == 1) {
            /* d + (n-2)*r, the last difference, at or near 0 */
            a.d = (int32_t)(-(int32_t)((int32_t)(a.n - 2) * a.r) + (int32_t)(int8_t)(rnd() & 3) - 1);
        }
        if ((rnd() & 15) == 2) {
            /* n*r = +-2^24 exactly */
            const uint8_t k = (uint8_t)(9 + rnd() % 7);
            counts(&a, (uint16_t)(1u << (24 - k)));
            a.r = (int16_t)((k == 15 || (rnd() & 1)) ? -(int32_t)(1L << k) : (int32_t)(1L << k));
            a.d = (int32_t)(int8_t)rnd();
        }
        if ((rnd() & 15) == 0) {
            a.i = 0;
            a.d = 0;
            a.r = 0;
        }
        a.ahead = rnd() % (QS_SIGMA + 1u);
        b = a;
        kind_a = ref_check(&a);
        kind_b = qs_cubic_check(&b);
        if (kind_a != kind_b || memcmp(&a, &b, sizeof a) != 0) {
            uint8_t both[2] = {kind_a, kind_b};
            mismatch("check", trial, &a, &b, sizeof a);
            mismatch("check kind", trial, &both[0], &both[1], 1);
            continue;
        }
        if (!(kind_a & QS_CUBIC_MOVING))
            continue;
        if (kind_a & QS_CUBIC_CURVED) {
            const uint8_t ok_a = ref_last(&a), ok_b = qs_cubic_last(&b);
            if (ok_a != ok_b || memcmp(&a, &b, sizeof a) != 0) {
                mismatch("last", trial, &a, &b, sizeof a);
                continue;
            }
            if (!ok_a)
                continue;
        } else {
            a.last = qs_w48_of(a.i);
            b.last = a.last;
        }
        /* finish: into slots and ends of the same random bytes */
        for (k = 0; k < sizeof slot_a; k++)
            ((uint8_t *)&slot_a)[k] = (uint8_t)rnd();
        for (k = 0; k < sizeof end_a; k++)
            ((uint8_t *)&end_a)[k] = (uint8_t)rnd();
        slot_b = slot_a;
        end_b = end_a;
        ref_finish(&a, &slot_a, axis, &end_a);
        qs_cubic_finish(&b, &slot_b, axis, &end_b);
        if (memcmp(&a, &b, sizeof a) != 0)
            mismatch("finish terms", trial, &a, &b, sizeof a);
        else if (memcmp(&slot_a, &slot_b, sizeof slot_a) != 0)
            mismatch("finish slot", trial, &slot_a, &slot_b, sizeof slot_a);
        else if (memcmp(&end_a, &end_b, sizeof end_a) != 0)
            mismatch("finish end", trial, &end_a, &end_b, sizeof end_a);
        checked++;
    }
    put_text(" trials ");
    put_u32(TRIALS);
    put_text(" checked ");
    put_u32(checked);
    put_text(" mismatches ");
    put_u32(mismatches);
    put('\n');

    mismatches = 0;
    put_text("rx-copy");
    for (trial = 0; trial < RX_RUNS; trial++) {
        static qs_frame_rx rx_a, rx_b;
        static uint8_t run[40];
        const uint8_t len = (uint8_t)(rnd() % (sizeof run + 1));
        uint8_t k, taken_a, taken_b;

        for (k = 0; k < sizeof rx_a; k++)
            ((uint8_t *)&rx_a)[k] = (uint8_t)rnd();
        switch (rnd() & 3) {
        case 0:
            rx_a.len = 0;
            break;
        case 1:
            rx_a.len = (uint8_t)(QS_FRAME_WIRE_MAX - (rnd() & 3));
            break;
        default:
            rx_a.len = (uint8_t)(rnd() % (QS_FRAME_WIRE_MAX + 1));
            break;
        }
        rx_a.too_long = (rnd() & 3) == 0;
        rx_a.overrun = (rnd() & 3) == 0;
        for (k = 0; k < len; k++)
            run[k] = (rnd() & 3) == 0 ? 0 : (uint8_t)rnd();
        rx_b = rx_a;
        taken_a = qs_frame_rx_copy(&rx_a, run, len);
        taken_b = frame_rx_copy(&rx_b, run, len);
        if (taken_a != taken_b)
            mismatch("taken", trial, &taken_a, &taken_b, 1);
        else if (memcmp(&rx_a, &rx_b, sizeof rx_a) != 0)
            mismatch("frame", trial, &rx_a, &rx_b, sizeof rx_a);
    }
    put_text(" runs ");
    put_u32(RX_RUNS);
    put_text(" mismatches ");
    put_u32(mismatches);
    put('\n');
    while (!(UCSR0A & _BV(TXC0))) {
    }
    cli();
    sleep_cpu();
    for (;;) {
    }
}
