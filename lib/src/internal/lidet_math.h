/* SPDX-License-Identifier: MIT */
/* Small float helpers shared by the stages (never installed). Single precision only. */
#ifndef LIDET_MATH_H
#define LIDET_MATH_H

#include <math.h> /* fabsf, sqrtf for the stages that include this header */
#include <stdint.h>
#include <string.h>

#define LIDET_PI_F 3.14159265f
#define LIDET_HALF_PI_F 1.57079633f
#define LIDET_DEG2RAD_F 0.0174532925f /* pi / 180 */

/* finite test without libm or the C99 classification macros (those may promote to double on some
 * toolchains): a float is finite iff its exponent bits are not all ones. */
static inline int lidet__isfinite(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return (u & 0x7F800000u) != 0x7F800000u;
}

/* horizontal range R of a point: the one expression the projection (when it keeps R) and the ground
 * stage (when it computes R itself) share, so both give the same bits */
static inline float lidet__rxy(float x, float y)
{
    return sqrtf(x * x + y * y);
}

#endif
