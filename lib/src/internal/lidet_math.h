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

/* The azimuth window of half-width half_rad around straight ahead, as columns [*c_lo, *c_hi) of an image of cols
 * columns (column c spans azimuths pi (1 - 2 (c + 1) / n) .. pi (1 - 2 c / n), straight ahead at c = n / 2),
 * one more column on each side; half_rad outside (0, pi): every column. The projection's window and the
 * clustering's use this one rule (mirrored by lidet_ref/cluster.py). */
static inline void lidet__azimuth_window_cols(float half_rad, uint32_t cols, uint32_t *c_lo, uint32_t *c_hi)
{
    float half, lo, hi;
    if (!(half_rad > 0.0f && half_rad < LIDET_PI_F))
    {
        *c_lo = 0u;
        *c_hi = cols;
        return;
    }
    half = half_rad * (float)cols / (2.0f * LIDET_PI_F);
    lo = 0.5f * (float)cols - half - 1.0f;
    hi = 0.5f * (float)cols + half + 1.0f;
    *c_lo = lo > 0.0f ? (uint32_t)lo : 0u;
    *c_hi = hi < (float)cols ? (uint32_t)hi + 1u : cols;
}

/* horizontal range R of a point: the one expression the projection (when it keeps R) and the ground
 * stage (when it computes R itself) share, so both give the same bits */
static inline float lidet__rxy(float x, float y)
{
    return sqrtf(x * x + y * y);
}

#endif
