/* SPDX-License-Identifier: MIT */
/* Integer sqrt, sin/cos and atan2 of the fixed-point path (internal/lidet_qmath.h). */
#include "internal/lidet_qmath.h"

uint32_t lidet__q_isqrt64(uint64_t v)
{
    uint64_t rem = v, res = 0, bit = (uint64_t)1 << 62;
    /* v < 2^60 (the ground fits' normals, the proposals' ranges): the top 16 bits of the root from a 32-bit root,
     * the rest by one Newton step in 32 bits, one compare. About 45 instructions on a Cortex-M4 instead of the
     * digits' 590; on the cores without a divide instruction or a 32 x 32 -> 64 multiply (ARMv6-M: the division a
     * library call of about 60 instructions, the last product lidet__q_umul32's 16-bit halves) about 200 instead
     * of about 500. Why it is exact:
     * - s = k + 1 with 4^k <= v / 2^32 < 4^(k+1) puts v / 4^s in [2^30, 2^32): x0 = isqrt(v / 4^s) is in
     *   [2^15, 2^16) and X = x0 2^s <= sqrt(v) = X + d with 0 <= d < 2^s; e = v - X^2 < (2 x0 + 1) 4^s, so
     *   e / 2^s < 2^31 and q = floor(floor(e / 2^s) / (2 x0)) is a 32-bit division;
     * - never below: with t = floor(sqrt(v)) - X, e >= (X + t)^2 - X^2 >= 2 X t, so floor(e / 2^s) >= 2 x0 t;
     * - at most one above: q <= e / 2X = d + d^2 / 2X < d + 1/4 (d^2 / 2X < 4^s / 2^(s+16) <= 1/4, s <= 14).
     * tests/python/test_qmath.py checks it on every bit length, exact squares and their neighbours. */
    if ((v >> 32) == 0u)
    {
        return lidet__q_isqrt32_inl((uint32_t)v);
    }
    if ((v >> 60) == 0u)
    {
        const unsigned s = lidet__q_half_log4((uint32_t)(v >> 32)) + 1u; /* 1..14 */
        const uint32_t x0 = lidet__q_isqrt32_inl((uint32_t)(v >> (2u * s)));
        /* X^2 = x0^2 4^s, x0 < 2^16: a 32-bit square */
        const uint32_t e = (uint32_t)((v - ((uint64_t)(x0 * x0) << (2u * s))) >> s);
        const uint32_t r = (x0 << s) + e / (2u * x0); /* floor(sqrt(v)) or one above, < 2^30 + 1 */
        return r - (uint32_t)(lidet__q_umul32(r, r) > v);
    }
    /* digit by digit, two bits of v per step: exact, no division, 32 steps at most */
    while ((bit >> 16) > v) /* the highest power of 4 <= v: 8 bits of the result at a time, then 1 */
    {
        bit >>= 16;
    }
    while (bit > v)
    {
        bit >>= 2;
    }
    while (bit != 0)
    {
        /* without a branch: the bits of a root are unpredictable (the integer projection, one isqrt per pixel:
         * 63 -> 37 ns/point on a real KITTI scan, x86-64) */
        const uint64_t t = res + bit;
        const uint64_t take = 0u - (uint64_t)(rem >= t); /* all ones when this bit of the root is 1 */
        rem -= t & take;
        res = (res >> 1) + (bit & take);
        bit >>= 2;
    }
    return (uint32_t)res;
}

uint32_t lidet__q_isqrt32(uint32_t v)
{
    return lidet__q_isqrt32_inl(v);
}

uint32_t lidet__q_sqrt_round64(uint64_t v)
{
    uint64_t r = lidet__q_isqrt64(v);
    /* (r + 1/2)^2 = r^2 + r + 1/4: round up when v - r^2 > r */
    return (uint32_t)(v - r * r > r ? r + 1 : r);
}

/* sin of p in [0, 2^30] (a quarter turn, both ends included), Q30 */
static int32_t quarter_sin(uint32_t p)
{
    uint32_t i = p >> 20; /* 1024 steps of 2^20 */
    int64_t frac = (int64_t)(p & 0xFFFFFu);
    int64_t s0 = lidet__q_sin_q30[i];
    if (i == LIDET_Q_SIN_STEPS)
    {
        return (int32_t)s0;
    }
#if LIDET_Q_HAVE_MUL64
    return (int32_t)(s0 + lidet__q_rshift_round((lidet__q_sin_q30[i + 1] - s0) * frac, 20));
#else
    return (int32_t)s0 + lidet__q_mul_r20_split((int32_t)(lidet__q_sin_q30[i + 1] - s0), (uint32_t)frac);
#endif
}

int32_t lidet__q_sin(uint32_t a)
{
    uint32_t quadrant = a >> 30, p = a & (LIDET_Q_BAM_QUARTER - 1u);
    switch (quadrant)
    {
    case 0u:
        return quarter_sin(p);
    case 1u:
        return quarter_sin(LIDET_Q_BAM_QUARTER - p);
    case 2u:
        return -quarter_sin(p);
    default:
        return -quarter_sin(LIDET_Q_BAM_QUARTER - p);
    }
}

int32_t lidet__q_cos(uint32_t a)
{
    return lidet__q_sin(a + LIDET_Q_BAM_QUARTER);
}

/* atan(n / d) for 0 <= n <= d, d > 0, in BAM32 (0 .. 2^29) */
static uint32_t octant_atan(uint32_t n, uint32_t d)
{
    uint64_t t = ((uint64_t)n << 24) / d; /* Q24 ratio in [0, 2^24] */
    uint32_t i = (uint32_t)(t >> 14);     /* 1024 steps of 2^14 */
    int64_t frac = (int64_t)(t & 0x3FFFu);
    int64_t a0 = lidet__q_atan_bam[i];
    if (i == LIDET_Q_SIN_STEPS)
    {
        return (uint32_t)a0;
    }
    return (uint32_t)(a0 + lidet__q_rshift_round((lidet__q_atan_bam[i + 1] - a0) * frac, 14));
}

int32_t lidet__q_atan2(int32_t y, int32_t x)
{
    /* magnitudes as uint32: |INT32_MIN| fits */
    uint32_t ax = x < 0 ? 0u - (uint32_t)x : (uint32_t)x;
    uint32_t ay = y < 0 ? 0u - (uint32_t)y : (uint32_t)y;
    uint32_t a;
    if (ax == 0u && ay == 0u)
    {
        return 0;
    }
    a = ay <= ax ? octant_atan(ay, ax) : (LIDET_Q_BAM_QUARTER - octant_atan(ax, ay)); /* [0, pi/2] */
    if (x < 0)
    {
        a = LIDET_Q_BAM_HALF - a; /* (pi/2, pi] */
    }
    if (y < 0)
    {
        a = 0u - a;
    }
    /* uint32 -> int32 without the implementation-defined conversion: pi (2^31) becomes -2^31 */
    return a < LIDET_Q_BAM_HALF ? (int32_t)a : (int32_t)(a - LIDET_Q_BAM_HALF) - INT32_MAX - 1;
}

int32_t lidet__q_urad_to_bam(int32_t urad)
{
    /* 2^32 / (2 pi 1e6) = 683.5652754... BAM32 per microradian, as round(683.5652754 * 2^24) */
    return (int32_t)lidet__q_rshift_round((int64_t)urad * INT64_C(11468322278), 24);
}
