/* SPDX-License-Identifier: MIT */
#include "test_util.h"

#include <math.h>

int lidet_test_close(double a, double e, double atol, double rtol)
{
    return fabs(a - e) <= atol + rtol * fabs(e);
}

void lidet_canary_fill(uint32_t *pre, uint32_t *post)
{
    int i;
    for (i = 0; i < LIDET_CANARY_WORDS; ++i)
    {
        pre[i] = LIDET_CANARY;
        post[i] = LIDET_CANARY;
    }
}

int lidet_canary_ok(const uint32_t *pre, const uint32_t *post)
{
    int i;
    for (i = 0; i < LIDET_CANARY_WORDS; ++i)
    {
        if (pre[i] != LIDET_CANARY || post[i] != LIDET_CANARY)
        {
            return 0;
        }
    }
    return 1;
}
