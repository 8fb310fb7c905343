/* The segment ring: filling, wrapping, full, flushing, and that a slot is
 * free again only once the main loop has retired it. */
#include "qs_engine.h"
#include "qs_engine_tick.h"
#include "qs_queue.h"
#include "qs_test_support.h"
#include "unity.h"

static qs_engine engine;

void setUp(void)
{
}

void tearDown(void)
{
}

static qs_segment *push(uint16_t n)
{
    qs_segment_msg m = {0};
    qs_segment *slot = qs_queue_back(&engine.queue);
    m.n = n;
    qs_segment_prepare(slot, &m);
    qs_queue_publish(&engine.queue);
    qs_engine_wake(&engine);
    return slot;
}

static void test_fill_to_capacity_then_full(void)
{
    uint8_t i;
    qs_engine_init(&engine, 3);
    TEST_ASSERT_TRUE(qs_queue_empty(&engine.queue));
    TEST_ASSERT_EQUAL_INT(3, qs_queue_free(&engine.queue));
    for (i = 1; i <= 3; i++) {
        push(5);
        TEST_ASSERT_EQUAL_INT(i, qs_queue_count(&engine.queue));
        TEST_ASSERT_EQUAL_INT(3 - i, qs_queue_free(&engine.queue));
    }
    TEST_ASSERT_FALSE(qs_queue_empty(&engine.queue));
}

static void test_a_slot_is_free_again_only_when_retired(void)
{
    qs_engine_init(&engine, 2);
    push(1);
    push(1);
    TEST_ASSERT_EQUAL_INT(0, qs_queue_free(&engine.queue));
    qs_engine_tick(&engine); /* the first segment runs and ends */
    TEST_ASSERT_EQUAL_INT(1, qs_queue_count(&engine.queue));
    TEST_ASSERT_EQUAL_INT(0, qs_queue_free(&engine.queue)); /* not retired yet */
    qs_engine_retire(&engine);
    TEST_ASSERT_EQUAL_INT(1, qs_queue_free(&engine.queue));
    TEST_ASSERT_EQUAL_UINT32(1, engine.segments_done);
    TEST_ASSERT_EQUAL_UINT32(1, engine.completed_ticks);
}

/* Many laps: slots are used in order, every index stays in range, and
 * counts stay right across the wrap of the indices. */
static void test_wraps_around_many_times_in_order(void)
{
    static const uint8_t capacities[] = {1, 2, 3, QS_QUEUE_CAPACITY};
    unsigned c;

    for (c = 0; c < sizeof capacities; c++) {
        uint8_t cap = capacities[c];
        uint32_t k;
        qs_engine_init(&engine, cap);
        for (k = 0; k < 10u * cap + 3; k++) {
            qs_segment *expect = &engine.queue.slot[k % cap];
            TEST_ASSERT_TRUE(push((uint16_t)(1 + k % 3)) == expect);
            TEST_ASSERT_TRUE(qs_queue_front(&engine.queue) == expect);
            while (qs_queue_count(&engine.queue))
                qs_engine_tick(&engine);
            qs_engine_retire(&engine);
            TEST_ASSERT_EQUAL_INT(cap, qs_queue_free(&engine.queue));
            TEST_ASSERT_TRUE(engine.queue.head < 2 * cap);
            TEST_ASSERT_EQUAL_UINT32(k + 1, engine.segments_done);
        }
        /* Full laps with the ring full each time. */
        for (k = 0; k < 5; k++) {
            uint8_t i;
            for (i = 0; i < cap; i++)
                push(2);
            TEST_ASSERT_EQUAL_INT(0, qs_queue_free(&engine.queue));
            TEST_ASSERT_EQUAL_INT(cap, qs_queue_count(&engine.queue));
            while (qs_queue_count(&engine.queue))
                qs_engine_tick(&engine);
            qs_engine_retire(&engine);
            TEST_ASSERT_EQUAL_INT(cap, qs_queue_free(&engine.queue));
        }
    }
}

static void test_flush_empties_the_ring_and_halts(void)
{
    qs_engine_view v;
    qs_engine_init(&engine, 4);
    push(10);
    push(10);
    push(10);
    qs_engine_tick(&engine);
    qs_engine_tick(&engine);
    qs_engine_halt(&engine, QS_STATE_IDLE, QS_ALARM_NONE);
    tp_check_unlocked();
    TEST_ASSERT_TRUE(qs_queue_empty(&engine.queue));
    TEST_ASSERT_EQUAL_INT(4, qs_queue_free(&engine.queue));
    TEST_ASSERT_EQUAL_HEX8(0, qs_engine_tick(&engine));
    qs_engine_read(&engine, &v);
    TEST_ASSERT_EQUAL_INT(QS_STATE_IDLE, v.state);
    TEST_ASSERT_EQUAL_UINT32(2, v.motion_ticks); /* the ticks that ran count */
    TEST_ASSERT_EQUAL_UINT32(0, v.segments_done); /* none finished */
    /* The ring works on from where it was. */
    push(1);
    TEST_ASSERT_EQUAL_INT(1, qs_queue_count(&engine.queue));
    qs_engine_tick(&engine);
    qs_engine_retire(&engine);
    TEST_ASSERT_EQUAL_UINT32(1, engine.segments_done);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_fill_to_capacity_then_full);
    RUN_TEST(test_a_slot_is_free_again_only_when_retired);
    RUN_TEST(test_wraps_around_many_times_in_order);
    RUN_TEST(test_flush_empties_the_ring_and_halts);
    return UNITY_END();
}
