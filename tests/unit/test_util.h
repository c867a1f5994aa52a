/* SPDX-License-Identifier: MIT */
/* Shared helpers of the Unity tests: tolerance comparison and canary-guarded workspaces. */
#ifndef LIDET_TEST_UTIL_H
#define LIDET_TEST_UTIL_H

#include <stdint.h>

#include "unity.h"

#ifndef M_PI /* not in strict C99 */
#define M_PI 3.14159265358979323846
#endif

/** |a - e| <= atol + rtol * |e| (Unity's relative-only float check fails at 0). */
int lidet_test_close(double a, double e, double atol, double rtol);

#define TEST_ASSERT_CLOSE(e, a, atol, rtol)                                                                  \
    TEST_ASSERT_TRUE_MESSAGE(lidet_test_close((double)(a), (double)(e), (atol), (rtol)), "value not within tolerance")

/** Canaries around a workspace: declare `LIDET_GUARDED(type, name)` at file scope (static). */
#define LIDET_CANARY_WORDS 16
#define LIDET_CANARY 0xDEADBEEFu
#define LIDET_GUARDED(type, name)                                                                            \
    static struct                                                                                            \
    {                                                                                                        \
        uint32_t pre[LIDET_CANARY_WORDS];                                                                     \
        type ws;                                                                                             \
        uint32_t post[LIDET_CANARY_WORDS];                                                                    \
    } name

void lidet_canary_fill(uint32_t *pre, uint32_t *post);
int lidet_canary_ok(const uint32_t *pre, const uint32_t *post);

#define CANARY_FILL(g) lidet_canary_fill((g).pre, (g).post)
#define CANARY_CHECK(g) TEST_ASSERT_TRUE_MESSAGE(lidet_canary_ok((g).pre, (g).post), "workspace canary overwritten")

#endif
