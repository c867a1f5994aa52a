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

/* The two per-point keys of the projection from one division and one square root:
 *   tan(elevation) t = z / rxy, and the pseudo-azimuth ("diamond angle") in [0, 4]
 *   d = 1 + x/(|x|+|y|) for y >= 0, 3 - x/(|x|+|y|) for y < 0,
 * monotonic in azimuth: 0 at +-pi, 1 at +pi/2, 2 at 0, 3 at -pi/2, -> 4 towards -pi.
 * With inv = 1 / ((|x|+|y|) rxy): x/(|x|+|y|) = x rxy inv and z/rxy = z (|x|+|y|) inv.
 * Also returns rxy = sqrt(rxy2). For x = y = 0, t is NaN (callers reject it as out of the field of view) and d = 2.
 * lidet_proj.c's hot loop and lidet_proj_azimuth_key() both use this, so tests measure exactly
 * what the projection bins on. */
static inline void lidet__proj_keys(float x, float y, float z, float rxy2, float *t, float *d, float *rxy_out)
{
    const float s = fabsf(x) + fabsf(y); /* fabsf is a sign-bit mask, inlined by compilers */
    const float rxy = sqrtf(rxy2);
    const float den = s * rxy;
    *rxy_out = rxy;
    if (den > 0.0f)
    {
        const float inv = 1.0f / den;
        const float q = x * rxy * inv; /* |q| <= 1 up to rounding: d in [0, 4] +- a few ulp */
        *d = y >= 0.0f ? 1.0f + q : 3.0f - q;
        *t = z * s * inv;
    }
    else
    {
        *d = 2.0f;
        *t = z / den; /* +-inf, or NaN for z = 0: outside any field of view */
    }
}

#endif
