/* CRC, COBS and the frame receiver: check values, round trips, and the
 * order of PROTOCOL.md section 2 in which a bad frame is rejected. */
#include <string.h>

#include "qs_cobs.h"
#include "qs_crc16.h"
#include "qs_frame.h"
#include "qs_test_support.h"
#include "unity.h"

static qs_frame_rx rx;

void setUp(void)
{
    qs_frame_rx_init(&rx);
}

void tearDown(void)
{
}

/* Feed bytes; return the result of the last one. */
static uint8_t feed(const uint8_t *bytes, uint16_t len)
{
    uint8_t result = QS_FRAME_NOTHING;
    uint16_t i;
    for (i = 0; i < len; i++)
        result = qs_frame_rx_byte(&rx, bytes[i]);
    return result;
}

/* The bit-wise definition, to check the byte-wise formulation against. */
static uint16_t crc_bitwise(const uint8_t *p, uint16_t len)
{
    uint16_t crc = 0xFFFF;
    uint8_t bit;
    while (len--) {
        crc ^= (uint16_t)(*p++ << 8);
        for (bit = 0; bit < 8; bit++)
            crc = (uint16_t)(crc & 0x8000 ? (crc << 1) ^ 0x1021 : crc << 1);
    }
    return crc;
}

static void test_crc_check_value_and_every_byte_from_every_state(void)
{
    uint32_t crc;
    uint16_t byte;

    TEST_ASSERT_EQUAL_HEX16(0x29B1, qs_crc16((const uint8_t *)"123456789", 9));
    for (crc = 0; crc <= 0xFFFF; crc += 7)
        for (byte = 0; byte < 256; byte++) {
            uint8_t b = (uint8_t)byte;
            uint16_t expect = (uint16_t)crc;
            uint8_t bit;
            expect ^= (uint16_t)(b << 8);
            for (bit = 0; bit < 8; bit++)
                expect = (uint16_t)(expect & 0x8000 ? (expect << 1) ^ 0x1021 : expect << 1);
            TEST_ASSERT_EQUAL_HEX16(expect, qs_crc16_update((uint16_t)crc, b));
        }
    TEST_ASSERT_EQUAL_HEX16(crc_bitwise((const uint8_t *)"quadstep", 8),
                            qs_crc16((const uint8_t *)"quadstep", 8));
}

static void test_cobs_round_trips_every_length_and_zero_pattern(void)
{
    uint8_t in[QS_MAX_FRAME], out[QS_MAX_FRAME + 2];
    uint8_t len, i, n;
    uint32_t pattern;

    for (len = 1; len <= QS_MAX_FRAME; len++) {
        for (pattern = 0; pattern < 64; pattern++) {
            for (i = 0; i < len; i++) /* zeros where the pattern says, at varying places */
                in[i] = ((pattern >> (i % 6)) & 1) && (i * 7 + pattern) % 5 == 0 ? 0 : (uint8_t)(i + 1 + pattern);
            n = qs_cobs_encode(in, len, out);
            TEST_ASSERT_EQUAL_INT(len + 1, n);
            for (i = 0; i < n; i++)
                TEST_ASSERT_TRUE_MESSAGE(out[i] != 0, "zero inside an encoded block");
            TEST_ASSERT_EQUAL_INT(QS_COBS_DONE, qs_cobs_decode(out, n));
            TEST_ASSERT_EQUAL_HEX8_ARRAY(in, out + 1, len);
        }
    }
}

static void test_cobs_refuses_a_block_that_runs_past_the_end(void)
{
    uint8_t block[] = {0x03, 0x11, 0x02, 0x22};
    uint8_t ff[] = {0xFF, 0x01, 0x02};

    TEST_ASSERT_EQUAL_INT(QS_COBS_BAD, qs_cobs_decode(block, 2));
    TEST_ASSERT_EQUAL_INT(QS_COBS_BAD, qs_cobs_decode(block, 1));
    /* Ending right after a block it is well formed. */
    TEST_ASSERT_EQUAL_INT(QS_COBS_DONE, qs_cobs_decode(block, 3));
    TEST_ASSERT_EQUAL_HEX8(0x11, block[1]);
    TEST_ASSERT_EQUAL_HEX8(0x02, block[2]);
    /* A second block (code 0x22 at [3]) that runs past the end. */
    TEST_ASSERT_EQUAL_INT(QS_COBS_BAD, qs_cobs_decode(block, 4));
    /* Two blocks: the second code byte becomes the first block's zero. */
    block[3] = 0x01;
    TEST_ASSERT_EQUAL_INT(QS_COBS_DONE, qs_cobs_decode(block, 4));
    TEST_ASSERT_EQUAL_HEX8(0x00, block[3]);
    /* A 254-byte block cannot end a block this short. */
    TEST_ASSERT_EQUAL_INT(QS_COBS_BAD, qs_cobs_decode(ff, sizeof ff));
}

static void test_a_good_frame_and_resynchronisation_after_garbage(void)
{
    uint8_t body[QS_MAX_FRAME] = {0x02, 0x07};
    uint8_t wire[QS_MAX_WIRE];
    uint8_t n = qs_frame_encode(body, 2, wire);
    static const uint8_t garbage[] = {0x05, 0x33, 0x00};

    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_READY, feed(wire, n));
    TEST_ASSERT_EQUAL_INT(2, qs_frame_body_len(&rx));
    TEST_ASSERT_EQUAL_HEX8(0x07, qs_frame_body(&rx)[1]);
    /* Garbage costs only its own frame. */
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_BAD_COBS, feed(garbage, sizeof garbage));
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_READY, feed(wire, n));
    /* Empty frames are ignored. */
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_NOTHING, qs_frame_rx_byte(&rx, 0));
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_NOTHING, qs_frame_rx_byte(&rx, 0));
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_READY, feed(wire, n));
}

static void test_each_framing_error_and_their_order(void)
{
    uint8_t long_frame[80];
    uint8_t body[QS_MAX_FRAME] = {0x02, 0x01};
    uint8_t wire[QS_MAX_WIRE];
    uint8_t n;
    static const uint8_t too_short[] = {0x04, 0x01, 0x02, 0x03, 0x00};
    static const uint8_t bad_cobs_short[] = {0x05, 0x01, 0x00};

    /* 1. More than 64 decoded bytes, even with a lost byte and bad COBS. */
    memset(long_frame, 0x11, sizeof long_frame);
    long_frame[0] = 0xFF; /* a block of 254 that the delimiter cuts short */
    long_frame[79] = 0;
    qs_frame_rx_overrun(&rx);
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_FRAME_TOO_LONG, feed(long_frame, sizeof long_frame));
    /* The bound is exact: 65 wire bytes are 64 decoded ones, 66 are more. */
    memset(long_frame, 0x11, sizeof long_frame);
    long_frame[0] = 0x41;
    long_frame[QS_MAX_WIRE - 1] = 0;
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_BAD_CRC, feed(long_frame, QS_MAX_WIRE));
    long_frame[0] = 0x42;
    long_frame[QS_MAX_WIRE - 1] = 0x11;
    long_frame[QS_MAX_WIRE] = 0;
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_FRAME_TOO_LONG, feed(long_frame, QS_MAX_WIRE + 1));
    /* Exactly 64 decoded bytes are fine as far as length goes. */
    memset(body, 0x22, sizeof body);
    n = qs_frame_encode(body, QS_MAX_BODY, wire);
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_READY, feed(wire, n));
    TEST_ASSERT_EQUAL_INT(QS_MAX_BODY, qs_frame_body_len(&rx));
    /* 2. Overrun beats bad COBS and a bad CRC. */
    qs_frame_rx_overrun(&rx);
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_RX_OVERRUN, feed(bad_cobs_short, sizeof bad_cobs_short));
    /* ...and is reported for the frame it hit only. */
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_READY, feed(wire, n));
    /* 3. Bad COBS beats too short. */
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_BAD_COBS, feed(bad_cobs_short, sizeof bad_cobs_short));
    /* 4. Too short. */
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_FRAME_TOO_SHORT, feed(too_short, sizeof too_short));
    /* 5. One flipped bit anywhere in the body or CRC: a bad CRC. */
    body[0] = 0x02;
    body[1] = 0x09;
    n = qs_frame_encode(body, 2, wire);
    wire[2] ^= 0x10;
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_BAD_CRC, feed(wire, n));
}

static void test_overrun_between_frames_is_reported_at_the_next_delimiter(void)
{
    qs_frame_rx_overrun(&rx);
    TEST_ASSERT_EQUAL_HEX8(QS_ERR_RX_OVERRUN, qs_frame_rx_byte(&rx, 0));
    TEST_ASSERT_EQUAL_HEX8(QS_FRAME_NOTHING, qs_frame_rx_byte(&rx, 0));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_crc_check_value_and_every_byte_from_every_state);
    RUN_TEST(test_cobs_round_trips_every_length_and_zero_pattern);
    RUN_TEST(test_cobs_refuses_a_block_that_runs_past_the_end);
    RUN_TEST(test_a_good_frame_and_resynchronisation_after_garbage);
    RUN_TEST(test_each_framing_error_and_their_order);
    RUN_TEST(test_overrun_between_frames_is_reported_at_the_next_delimiter);
    return UNITY_END();
}
