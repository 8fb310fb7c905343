#include "qs_test_support.h"

#include <string.h>

#include "qs_engine_tick.h"
#include "qs_frame.h"
#include "qs_port.h"
#include "qs_raster_tick.h"
#include "unity.h"

static uint8_t sent[1u << 16];
static uint32_t sent_len;
static int lock_depth;
static uint64_t rng_state;

void qs_port_send(const uint8_t *bytes, uint8_t len)
{
    TEST_ASSERT_TRUE_MESSAGE(sent_len + len <= sizeof sent, "test port buffer full");
    TEST_ASSERT_TRUE_MESSAGE(lock_depth == 0, "qs_port_send called with the tick locked out");
    memcpy(sent + sent_len, bytes, len);
    sent_len += len;
}

uint16_t test_clock; /* the port clock, moved by the tests */

/* The tests drive the tick themselves. */
void qs_port_tick_wake(void)
{
}

int test_laser_power = -1; /* the last power the tick set (-1: none yet) */

void qs_port_laser_power(uint8_t power)
{
    test_laser_power = power;
}

uint8_t test_laser_period; /* the laser PWM's period in ticks (0: every line's pixels switched by the tick) */

uint8_t qs_port_laser_period_ticks(void)
{
    return test_laser_period;
}

uint16_t qs_port_clock(void)
{
    return test_clock;
}

uint8_t qs_port_lock(void)
{
    lock_depth++;
    return (uint8_t)lock_depth;
}

void qs_port_unlock(uint8_t saved)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(lock_depth, saved, "unlock does not match lock");
    lock_depth--;
}

void tp_check_unlocked(void)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, lock_depth, "tick left locked out");
}

void tp_clear_sent(void)
{
    sent_len = 0;
}

uint16_t tp_reports(tp_report *out, uint16_t max)
{
    qs_frame_rx rx;
    uint16_t count = 0;
    uint32_t i;

    qs_frame_rx_init(&rx);
    for (i = 0; i < sent_len; i++) {
        uint8_t result = qs_frame_rx_byte(&rx, sent[i]);
        if (result == QS_FRAME_NOTHING)
            continue;
        TEST_ASSERT_EQUAL_HEX8_MESSAGE(QS_FRAME_READY, result, "the core sent a bad frame");
        TEST_ASSERT_TRUE_MESSAGE(count < max, "more reports than expected");
        out[count].type = qs_frame_body(&rx)[0];
        out[count].seq = qs_frame_body(&rx)[1];
        out[count].len = (uint8_t)(qs_frame_body_len(&rx) - 2);
        memcpy(out[count].payload, qs_frame_body(&rx) + 2, out[count].len);
        count++;
    }
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(0, i ? sent[i - 1] : 0, "the core left a frame unfinished");
    return count;
}

uint16_t tp_take_reports(tp_report *out, uint16_t max)
{
    uint16_t n = tp_reports(out, max);
    tp_clear_sent();
    return n;
}

void tp_send(qs_core *c, const uint8_t *body, uint8_t len)
{
    uint8_t buf[QS_MAX_FRAME];
    uint8_t wire[QS_MAX_WIRE];
    uint8_t n, i;

    memcpy(buf, body, len);
    n = qs_frame_encode(buf, len, wire);
    for (i = 0; i < n; i++)
        qs_core_rx(c, wire[i]);
    tp_check_unlocked();
}

void tp_send_simple(qs_core *c, uint8_t type, uint8_t seq)
{
    uint8_t body[2];
    body[0] = type;
    body[1] = seq;
    tp_send(c, body, 2);
}

uint8_t tp_segment_body(uint8_t *body, uint8_t seq, uint16_t n, uint8_t active,
                        uint8_t negative, const tp_axis *axes)
{
    uint8_t len = 0;
    uint8_t axis, j = 0;

    body[len++] = QS_TYPE_SEGMENT;
    body[len++] = seq;
    body[len++] = (uint8_t)n;
    body[len++] = (uint8_t)(n >> 8);
    body[len++] = (uint8_t)((active & 0x0F) | (negative << 4));
    for (axis = 0; axis < 4; axis++) {
        if (!(active & (1u << axis)))
            continue;
        body[len++] = (uint8_t)axes[j].v0;
        body[len++] = (uint8_t)(axes[j].v0 >> 8);
        body[len++] = (uint8_t)axes[j].vn;
        body[len++] = (uint8_t)(axes[j].vn >> 8);
        body[len++] = (uint8_t)axes[j].r;
        body[len++] = (uint8_t)((uint16_t)axes[j].r >> 8);
        j++;
    }
    return len;
}

void tp_send_segment(qs_core *c, uint8_t seq, uint16_t n, uint8_t active, uint8_t negative,
                     const tp_axis *axes)
{
    uint8_t body[QS_MAX_FRAME];
    tp_send(c, body, tp_segment_body(body, seq, n, active, negative, axes));
}

uint16_t tp_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

uint32_t tp_u32(const uint8_t *p)
{
    return tp_u16(p) | ((uint32_t)tp_u16(p + 2) << 16);
}

qs_ack tp_ack(const tp_report *r)
{
    qs_ack a;
    TEST_ASSERT_EQUAL_HEX8_MESSAGE(QS_TYPE_ACK, r->type, "expected an ACK");
    TEST_ASSERT_EQUAL_INT(QS_LEN_ACK, r->len);
    a.next_seq = r->payload[0];
    a.free = r->payload[1];
    a.reason = r->payload[2];
    a.done = tp_u16(r->payload + 3);
    return a;
}

qs_error_report tp_error(const tp_report *r)
{
    qs_error_report e;
    TEST_ASSERT_EQUAL_HEX8_MESSAGE(QS_TYPE_ERROR, r->type, "expected an ERROR");
    TEST_ASSERT_EQUAL_INT(QS_LEN_ERROR, r->len);
    e.code = r->payload[0];
    e.type = r->payload[1];
    e.seq = r->payload[2];
    e.field = r->payload[3];
    e.axis = r->payload[4];
    return e;
}

uint32_t tp_ticks(qs_core *c, uint32_t n)
{
    uint32_t steps = 0;
    while (n--) {
        uint8_t bits = qs_engine_tick(&c->engine);
#if QS_RASTER_BYTES
        qs_raster_tick(&c->raster, &c->outputs, &c->engine, bits);
#endif
        for (; bits; bits &= (uint8_t)(bits - 1))
            steps++;
    }
    return steps;
}

void tp_seed(uint64_t seed)
{
    rng_state = seed;
}

uint32_t tp_rand(uint32_t limit)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)((rng_state >> 33) % limit);
}

int64_t tp_floor_div(int64_t num, int64_t den)
{
    return num >= 0 ? num / den : -((-num + den - 1) / den);
}

int64_t tp_ideal_2nd(const qs_segment_msg *m, uint8_t axis, int64_t t)
{
    int64_t n = m->n;
    return n * m->r[axis] + ((int64_t)m->vn[axis] - m->v0[axis]) * t * t + 2 * n * m->v0[axis] * t;
}

int64_t tp_closed_form(const qs_segment_msg *m, uint8_t axis, int64_t t)
{
    int64_t n = m->n;
    if (t == 0)
        return 0;
    return tp_floor_div(tp_ideal_2nd(m, axis, t) + n * QS_D, 2 * n * QS_D);
}
