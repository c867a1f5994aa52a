/* SPDX-License-Identifier: MIT */
/* Integer math of the fixed-point stages (docs/FIXED_POINT.md), shared by every integer kernel. No float:
 * these functions are compiled in both builds and are the only trig/sqrt the integer path uses.
 *
 * Conventions (the numpy reference codegen/lidet_codegen/ref/qmath.py mirrors them bit for bit):
 * - BAM32 angles: 2^32 is one full turn; uint32 for "any angle" (wraps), int32 for a signed one
 *   (-2^31 = -pi .. 2^31 - 1). 1 BAM32 = 1.46e-9 rad.
 * - sin/cos in Q30 (2^30 = 1.0) from a 1025-entry quarter-wave table (lidet_qmath_tables.c, generated) with
 *   linear interpolation; |error| <= 3e-7 (about 320 Q30 LSBs, the interpolation error (pi/2048)^2/8).
 * - atan2 in BAM32 from the ratio min/max in Q24 and a 1025-entry table of atan on [0, 1], interpolated;
 *   |error| <= 2e-7 rad.
 * - Rounding: every right shift that drops bits rounds half up (towards +inf): (v + 2^(s-1)) >> s, an
 *   arithmetic shift (lidet_opt.h checks the compiler shifts negative values arithmetically). Divisions
 *   round half away from zero (lidet__q_div_round). */
#ifndef LIDET_QMATH_H
#define LIDET_QMATH_H

#include <stdint.h>

#define LIDET_Q_SIN_STEPS 1024
#define LIDET_Q_ONE_Q30 (1 << 30)
#define LIDET_Q_BAM_QUARTER 0x40000000u /* pi/2 */
#define LIDET_Q_BAM_HALF 0x80000000u    /* pi */

extern const int32_t lidet__q_sin_q30[LIDET_Q_SIN_STEPS + 1];
extern const int32_t lidet__q_atan_bam[LIDET_Q_SIN_STEPS + 1];

/** round(v / 2^s), halves up; s in [1, 62] */
static inline int64_t lidet__q_rshift_round(int64_t v, unsigned s)
{
    return (v + ((int64_t)1 << (s - 1))) >> s;
}

/** round(n / d), halves away from zero; d > 0 */
static inline int64_t lidet__q_div_round(int64_t n, int64_t d)
{
    return n >= 0 ? (n + d / 2) / d : -((-n + d / 2) / d);
}

/** floor(sqrt(v)), exact */
uint32_t lidet__q_isqrt64(uint64_t v);

/** floor(sqrt(v)), exact, 32-bit arithmetic only */
uint32_t lidet__q_isqrt32(uint32_t v);

/** round(sqrt(v)) (halves cannot occur for integers), exact */
uint32_t lidet__q_sqrt_round64(uint64_t v);

/** sin(a) in Q30, a in BAM32 */
int32_t lidet__q_sin(uint32_t a);

/** cos(a) in Q30, a in BAM32 */
int32_t lidet__q_cos(uint32_t a);

/** atan2(y, x) in signed BAM32 (pi = 2^31 wraps to -2^31); atan2(0, 0) = 0 */
int32_t lidet__q_atan2(int32_t y, int32_t x);

/** microradians -> BAM32 (signed), rounded; |urad| <= 3141592 (pi) */
int32_t lidet__q_urad_to_bam(int32_t urad);

#endif
