/* SPDX-License-Identifier: MIT */
/* A float planted on purpose: the check_nofloat self-test compiles this with the integer-only sources and
 * expects tools/firmware/check_nofloat.py to find it (so the check is known to bite). Never part of a library. */
#include <stdint.h>

int32_t lidet_planted_float(int32_t a, int32_t b)
{
    volatile float x = (float)a;
    return (int32_t)(x / (float)b + 0.5f);
}
