/* The stand-in's runner: counts tests and failures, prints Unity's report
 * format, and leaves a failing test at its first failed assertion. */
#include "unity.h"

#include <inttypes.h>
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

static struct {
    const char *file;
    const char *test;
    int tests;
    int failures;
    int failed;
    jmp_buf abort_test;
} unity;

void UnityBegin(const char *file)
{
    unity.file = file;
    unity.tests = 0;
    unity.failures = 0;
}

int UnityEnd(void)
{
    printf("\n-----------------------\n%d Tests %d Failures 0 Ignored\n%s\n", unity.tests,
           unity.failures, unity.failures ? "FAIL" : "OK");
    return unity.failures;
}

void UnityDefaultTestRun(void (*func)(void), const char *name, int line)
{
    unity.test = name;
    unity.failed = 0;
    unity.tests++;
    if (setjmp(unity.abort_test) == 0) {
        setUp();
        func();
    }
    if (setjmp(unity.abort_test) == 0)
        tearDown();
    if (unity.failed)
        unity.failures++;
    else
        printf("%s:%d:%s:PASS\n", unity.file, line, name);
    fflush(stdout);
}

static void fail(int line, const char *what, const char *message)
{
    printf("%s:%d:%s:FAIL: %s", unity.file, line, unity.test, what);
    if (message)
        printf(". %s", message);
    printf("\n");
    unity.failed = 1;
    longjmp(unity.abort_test, 1);
}

void UnityFail(const char *message, int line)
{
    fail(line, message ? message : "Fail", 0);
}

void UnityMessage(const char *message, int line)
{
    printf("%s:%d:%s:INFO: %s\n", unity.file, line, unity.test, message);
}

void UnityAssertEqualNumber(int64_t expected, int64_t actual, const char *message, int line)
{
    char what[96];
    if (expected == actual)
        return;
    snprintf(what, sizeof what, "Expected %" PRId64 " Was %" PRId64, expected, actual);
    fail(line, what, message);
}

void UnityAssertEqualUnsigned(uint64_t expected, uint64_t actual, const char *message, int line)
{
    char what[96];
    if (expected == actual)
        return;
    snprintf(what, sizeof what, "Expected %" PRIu64 " Was %" PRIu64, expected, actual);
    fail(line, what, message);
}

void UnityAssertOrder(int64_t threshold, int64_t actual, int want_actual_le, const char *message,
                      int line)
{
    char what[96];
    if (want_actual_le ? actual <= threshold : actual >= threshold)
        return;
    snprintf(what, sizeof what, "Expected %s %" PRId64 " Was %" PRId64,
             want_actual_le ? "less than or equal to" : "greater than or equal to", threshold,
             actual);
    fail(line, what, message);
}

void UnityAssertEqualMemory(const uint8_t *expected, const uint8_t *actual, uint32_t len,
                            const char *message, int line)
{
    char what[96];
    uint32_t i;
    for (i = 0; i < len; i++) {
        if (expected[i] != actual[i]) {
            snprintf(what, sizeof what, "Element %" PRIu32 " Expected 0x%02X Was 0x%02X", i,
                     expected[i], actual[i]);
            fail(line, what, message);
        }
    }
}

void UnityAssertEqualString(const char *expected, const char *actual, const char *message,
                            int line)
{
    char what[160];
    if (expected && actual && strcmp(expected, actual) == 0)
        return;
    snprintf(what, sizeof what, "Expected '%s' Was '%s'", expected ? expected : "(null)",
             actual ? actual : "(null)");
    fail(line, what, message);
}
