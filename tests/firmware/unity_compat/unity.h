/* A small stand-in for the Unity test framework (ThrowTheSwitch), covering
 * only the part of its API the firmware tests use, with the same names and
 * meanings. The build uses it only when no real Unity is found; with
 * PlatformIO (`pio test -e native`) the real Unity is used instead. */
#ifndef UNITY_COMPAT_H
#define UNITY_COMPAT_H

#include <stdint.h>

void setUp(void);
void tearDown(void);

void UnityBegin(const char *file);
int UnityEnd(void);
void UnityDefaultTestRun(void (*func)(void), const char *name, int line);
void UnityFail(const char *message, int line);
void UnityMessage(const char *message, int line);
void UnityAssertEqualNumber(int64_t expected, int64_t actual, const char *message, int line);
void UnityAssertEqualUnsigned(uint64_t expected, uint64_t actual, const char *message, int line);
void UnityAssertOrder(int64_t threshold, int64_t actual, int want_actual_le, const char *message,
                      int line);
void UnityAssertEqualMemory(const uint8_t *expected, const uint8_t *actual, uint32_t len,
                            const char *message, int line);
void UnityAssertEqualString(const char *expected, const char *actual, const char *message,
                            int line);

#define UNITY_BEGIN() UnityBegin(__FILE__)
#define UNITY_END() UnityEnd()
#define RUN_TEST(func) UnityDefaultTestRun(func, #func, __LINE__)

#define TEST_FAIL_MESSAGE(m) UnityFail((m), __LINE__)
#define TEST_FAIL() UnityFail(0, __LINE__)
#define TEST_MESSAGE(m) UnityMessage((m), __LINE__)

#define TEST_ASSERT_MESSAGE(c, m) do { if (!(c)) UnityFail((m), __LINE__); } while (0)
#define TEST_ASSERT(c) TEST_ASSERT_MESSAGE((c), "Expression Evaluated To FALSE")
#define TEST_ASSERT_TRUE(c) TEST_ASSERT_MESSAGE((c), "Expected TRUE Was FALSE")
#define TEST_ASSERT_FALSE(c) TEST_ASSERT_MESSAGE(!(c), "Expected FALSE Was TRUE")
#define TEST_ASSERT_TRUE_MESSAGE(c, m) TEST_ASSERT_MESSAGE((c), (m))
#define TEST_ASSERT_FALSE_MESSAGE(c, m) TEST_ASSERT_MESSAGE(!(c), (m))
#define TEST_ASSERT_NOT_NULL(p) TEST_ASSERT_MESSAGE((p) != 0, "Expected Non-NULL")

#define TEST_ASSERT_EQUAL_INT_MESSAGE(e, a, m) UnityAssertEqualNumber((int64_t)(e), (int64_t)(a), (m), __LINE__)
#define TEST_ASSERT_EQUAL_INT(e, a) TEST_ASSERT_EQUAL_INT_MESSAGE((e), (a), 0)
#define TEST_ASSERT_EQUAL_INT8(e, a) TEST_ASSERT_EQUAL_INT((int8_t)(e), (int8_t)(a))
#define TEST_ASSERT_EQUAL_INT16(e, a) TEST_ASSERT_EQUAL_INT((int16_t)(e), (int16_t)(a))
#define TEST_ASSERT_EQUAL_INT32(e, a) TEST_ASSERT_EQUAL_INT((int32_t)(e), (int32_t)(a))
#define TEST_ASSERT_EQUAL_INT64(e, a) TEST_ASSERT_EQUAL_INT((int64_t)(e), (int64_t)(a))
#define TEST_ASSERT_EQUAL_INT32_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_INT_MESSAGE((int32_t)(e), (int32_t)(a), (m))
#define TEST_ASSERT_EQUAL_INT64_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_INT_MESSAGE((int64_t)(e), (int64_t)(a), (m))
#define TEST_ASSERT_EQUAL(e, a) TEST_ASSERT_EQUAL_INT((e), (a))
#define TEST_ASSERT_EQUAL_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_INT_MESSAGE((e), (a), (m))

#define TEST_ASSERT_EQUAL_UINT_MESSAGE(e, a, m) UnityAssertEqualUnsigned((uint64_t)(e), (uint64_t)(a), (m), __LINE__)
#define TEST_ASSERT_EQUAL_UINT(e, a) TEST_ASSERT_EQUAL_UINT_MESSAGE((e), (a), 0)
#define TEST_ASSERT_EQUAL_UINT8(e, a) TEST_ASSERT_EQUAL_UINT((uint8_t)(e), (uint8_t)(a))
#define TEST_ASSERT_EQUAL_UINT16(e, a) TEST_ASSERT_EQUAL_UINT((uint16_t)(e), (uint16_t)(a))
#define TEST_ASSERT_EQUAL_UINT32(e, a) TEST_ASSERT_EQUAL_UINT((uint32_t)(e), (uint32_t)(a))
#define TEST_ASSERT_EQUAL_UINT8_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_UINT_MESSAGE((uint8_t)(e), (uint8_t)(a), (m))
#define TEST_ASSERT_EQUAL_UINT16_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_UINT_MESSAGE((uint16_t)(e), (uint16_t)(a), (m))
#define TEST_ASSERT_EQUAL_UINT32_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_UINT_MESSAGE((uint32_t)(e), (uint32_t)(a), (m))
#define TEST_ASSERT_EQUAL_HEX8(e, a) TEST_ASSERT_EQUAL_UINT8((e), (a))
#define TEST_ASSERT_EQUAL_HEX16(e, a) TEST_ASSERT_EQUAL_UINT16((e), (a))
#define TEST_ASSERT_EQUAL_HEX32(e, a) TEST_ASSERT_EQUAL_UINT32((e), (a))
#define TEST_ASSERT_EQUAL_HEX8_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_UINT8_MESSAGE((e), (a), (m))

/* Unity's order: the threshold first, then the actual value. */
#define TEST_ASSERT_LESS_OR_EQUAL_INT64(t, a) UnityAssertOrder((int64_t)(t), (int64_t)(a), 1, 0, __LINE__)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT64(t, a) UnityAssertOrder((int64_t)(t), (int64_t)(a), 0, 0, __LINE__)
#define TEST_ASSERT_LESS_OR_EQUAL_INT(t, a) TEST_ASSERT_LESS_OR_EQUAL_INT64((t), (a))
#define TEST_ASSERT_GREATER_OR_EQUAL_INT(t, a) TEST_ASSERT_GREATER_OR_EQUAL_INT64((t), (a))

#define TEST_ASSERT_EQUAL_UINT8_ARRAY_MESSAGE(e, a, n, m) UnityAssertEqualMemory((const uint8_t *)(e), (const uint8_t *)(a), (uint32_t)(n), (m), __LINE__)
#define TEST_ASSERT_EQUAL_UINT8_ARRAY(e, a, n) TEST_ASSERT_EQUAL_UINT8_ARRAY_MESSAGE((e), (a), (n), 0)
#define TEST_ASSERT_EQUAL_HEX8_ARRAY(e, a, n) TEST_ASSERT_EQUAL_UINT8_ARRAY((e), (a), (n))
#define TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(e, a, n, m) TEST_ASSERT_EQUAL_UINT8_ARRAY_MESSAGE((e), (a), (n), (m))

#define TEST_ASSERT_EQUAL_STRING(e, a) UnityAssertEqualString((e), (a), 0, __LINE__)

#endif
