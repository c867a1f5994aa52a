/* SPDX-License-Identifier: MIT */
/* Small float helpers shared by the stages (never installed). Single precision only. */
#ifndef LIDET_MATH_H
#define LIDET_MATH_H

#include <stdint.h>
#include <math.h>
#include <string.h>

#define LIDET_PI_F 3.14159265f
#define LIDET_HALF_PI_F 1.57079633f

/* finite test without libm or the C99 classification macros (those may promote to double on some
 * toolchains): a float is finite iff its exponent bits are not all ones. */
static inline int lidet__isfinite(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return (u & 0x7F800000u) != 0x7F800000u;
}

/* Pseudo-azimuth in [0, 4] ("diamond angle"): monotonic in azimuth, 0 at +-pi, 1 at +pi/2, 2 at 0,
 * 3 at -pi/2, -> 4 towards -pi. One division instead of an atan2 (lidet_proj.h). */
static inline float lidet__azimuth_key(float x, float y)
{
    const float s = fabsf(x) + fabsf(y); /* fabsf is a sign-bit mask, inlined by compilers */
    float q;
    if (s == 0.0f)
    {
        return 2.0f;
    }
    q = x / s; /* in [-1, 1]: |x| <= |x| + |y| holds in IEEE arithmetic too */
    return y >= 0.0f ? 1.0f + q : 3.0f - q;
}

#endif
