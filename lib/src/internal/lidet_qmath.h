/* SPDX-License-Identifier: MIT */
/* Integer math of the fixed-point stages (docs/FIXED_POINT.md), shared by every integer kernel. No float:
 * these functions are compiled in both builds and are the only trig/sqrt the integer path uses.
 *
 * Conventions (the numpy reference codegen/lidet_ref/qmath.py mirrors them bit for bit):
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

#include "lidet/lidet_opt.h" /* LIDET_Q_HAVE_DIV, LIDET_Q_HAVE_MUL64 */

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

/** round(n / d), halves away from zero; d > 0, |n| + d / 2 < 2^63. A 32-bit division where the rounded dividend
 *  and the divisor fit 32 bits (cluster means, plane fits: one UDIV on a Cortex-M3/M4 instead of a 64-bit library
 *  call of about 90 instructions); the same quotient either way */
static inline int64_t lidet__q_div_round(int64_t n, int64_t d)
{
    const uint64_t a = (uint64_t)(n >= 0 ? n : -n) + (uint64_t)(d / 2);
    const uint64_t q = (a >> 32) == 0u && ((uint64_t)d >> 32) == 0u ? (uint64_t)((uint32_t)a / (uint32_t)d)
                                                                    : a / (uint64_t)d;
    return n >= 0 ? (int64_t)q : -(int64_t)q;
}

/** floor(sqrt(v)), exact */
uint32_t lidet__q_isqrt64(uint64_t v);

/* LIDET_Q_HAVE_DIV (lidet_opt.h): 1 on cores with a divide instruction, where the integer square roots use
 * Newton's iteration; digit by digit elsewhere. LIDET_Q_HAVE_MUL64: 1 where a 32 x 32 -> 64 multiply is one
 * instruction, which the integer path then writes directly; split into 32-bit products elsewhere. Same values
 * either way. */

/* a * b exact in 64 bits from four 16 x 16 -> 32 products (the form of cores without a 32 x 32 -> 64 multiply,
 * compiled everywhere so that the host tests check it) */
static inline uint64_t lidet__q_umul32_split(uint32_t a, uint32_t b)
{
    const uint32_t al = a & 0xFFFFu, ah = a >> 16, bl = b & 0xFFFFu, bh = b >> 16;
    const uint32_t ll = al * bl, lh = al * bh, hl = ah * bl;
    const uint32_t mid = (ll >> 16) + (lh & 0xFFFFu) + (hl & 0xFFFFu); /* < 3 * 2^16 */
    const uint32_t hi = ah * bh + (lh >> 16) + (hl >> 16) + (mid >> 16);
    return ((uint64_t)hi << 32) | (uint32_t)((mid << 16) | (ll & 0xFFFFu));
}

/* a * b exact in 64 bits: one instruction where LIDET_Q_HAVE_MUL64; elsewhere (ARMv6-M) the split form, about
 * 20 instructions where the compiler's 64 x 64 helper (__muldi3) took about three times that */
static inline uint64_t lidet__q_umul32(uint32_t a, uint32_t b)
{
#if LIDET_Q_HAVE_MUL64
    return (uint64_t)a * b;
#else
    return lidet__q_umul32_split(a, b);
#endif
}

/* The row of pixel p < rows cols as (p m) >> 26 in 32 bits, for the cores without a divide instruction (where
 * p / cols is a library call of about 40 instructions: lidet_qpix.h's decode) or without a 32 x 32 -> 64 multiply
 * (the clustering's fill, whose row is otherwise the high word of a 64-bit product): m = ceil(2^26 / cols), e =
 * m cols - 2^26 in [0, cols). With p = q cols + t (t < cols), p m / 2^26 = q + (t + p e / 2^26) / cols, so the
 * floor is q while p e < 2^26; and p m must fit 32 bits. Returns m where both hold for every p < rows cols, else
 * 0 (then the row is divided) */
static inline uint32_t lidet__q_row_m26(uint32_t rows, uint32_t cols)
{
    const uint64_t last = (uint64_t)rows * cols - 1u; /* the last pixel */
    uint32_t m, e;
    if (cols == 0u || cols > 0xFFFFu || rows == 0u)
    {
        return 0u;
    }
    m = ((1u << 26) + cols - 1u) / cols;
    e = m * cols - (1u << 26);
    return last * e < ((uint64_t)1 << 26) && last * m <= 0xFFFFFFFFu ? m : 0u;
}

/* round((c x + s y) / 2^28), lidet__q_rshift_round of the exact sum, from 32-bit products (the cores without a
 * 32 x 32 -> 64 multiply, where the 64-bit products are library calls): c = ch 2^15 + cl and s = sh 2^15 + sl
 * with |cl|, |sl| <= 2^14 (ch = (c + 2^14) >> 15), x and y int16. With a = ch x + sh y and b = cl x + sl y,
 * c x + s y + 2^27 = (a + floor((b + 2^27) / 2^15)) 2^15 + ((b + 2^27) mod 2^15), so the result is
 * floor((a + ((b + 2^27) >> 15)) / 2^13). In int32 while |ch| + |sh| <= 65000 (|a| <= 65000 2^15, |b| <= 2^30),
 * which the caller checks (compiled everywhere so that the host tests check it) */
static inline int32_t lidet__q_dot2_r28_split(int32_t ch, int32_t cl, int32_t sh, int32_t sl, int32_t x,
                                              int32_t y)
{
    const int32_t a = ch * x + sh * y, b = cl * x + sl * y;
    return (a + ((b + (1 << 27)) >> 15)) >> 13;
}

/* round(d f / 2^20), lidet__q_rshift_round of the exact product, for 0 <= d < 2^21 and f < 2^20 (the sine
 * table's interpolation: d the step between two entries, at most 1,647,089, f the fraction) from 32-bit
 * products: f = fh 2^10 + fl, d f + 2^19 = (d fh + floor((d fl + 2^19) / 2^10)) 2^10 + ((d fl + 2^19) mod 2^10), so
 * the result is floor((d fh + ((d fl + 2^19) >> 10)) / 2^10); d fh < 2^31 (compiled everywhere so that the host
 * tests check it) */
static inline int32_t lidet__q_mul_r20_split(int32_t d, uint32_t f)
{
    const int32_t fh = (int32_t)(f >> 10), fl = (int32_t)(f & 0x3FFu);
    return (d * fh + ((d * fl + (1 << 19)) >> 10)) >> 10;
}

/* floor(a * b / 2^32), the high word of the exact signed product, from 16-bit halves: a = ah 2^16 + al (al in
 * [0, 2^16), ah signed), the cross products' high halves by arithmetic shifts (floor), the low halves' carries
 * summed in 32 bits (compiled everywhere so that the host tests check it) */
static inline int32_t lidet__q_smulhi32_split(int32_t a, int32_t b)
{
    const uint32_t al = (uint32_t)a & 0xFFFFu, bl = (uint32_t)b & 0xFFFFu;
    const int32_t ah = a >> 16, bh = b >> 16;
    const uint32_t ll = al * bl;
    const int32_t c1 = ah * (int32_t)bl, c2 = (int32_t)al * bh; /* |c| < 2^31 */
    const uint32_t mid = (ll >> 16) + ((uint32_t)c1 & 0xFFFFu) + ((uint32_t)c2 & 0xFFFFu);
    return ah * bh + (c1 >> 16) + (c2 >> 16) + (int32_t)(mid >> 16);
}

/* floor(a * b / 2^32): one long multiply where LIDET_Q_HAVE_MUL64; elsewhere (ARMv6-M) the split form, about 15
 * instructions where the compiler called its 64 x 64 helper (__muldi3) */
/* the same where |a| <= 2^15 (the requantization's usual accumulators): from two products, b = bh 2^16 + bl
 * (bl in [0, 2^16), bh signed): a b = a bh 2^16 + a bl with |a bh| <= 2^30 and |a bl| < 2^31, so
 * floor(a b / 2^32) = floor((a bh + floor(a bl / 2^16)) / 2^16) in 32 bits (compiled everywhere so that the host
 * tests check it) */
static inline int32_t lidet__q_smulhi32_short(int32_t a, int32_t b)
{
    return (a * (b >> 16) + ((a * (int32_t)((uint32_t)b & 0xFFFFu)) >> 16)) >> 16;
}

static inline int32_t lidet__q_smulhi32(int32_t a, int32_t b)
{
#if LIDET_Q_HAVE_MUL64
    return (int32_t)(((int64_t)a * b) >> 32);
#else
    /* two products where |a| <= 2^15, four elsewhere */
    return (uint32_t)a + 0x8000u <= 0x10000u ? lidet__q_smulhi32_short(a, b) : lidet__q_smulhi32_split(a, b);
#endif
}

/** floor(sqrt(v)), exact, 32-bit arithmetic only */
uint32_t lidet__q_isqrt32(uint32_t v);

static inline unsigned lidet__q_half_log4(uint32_t v) /* k with 4^k <= v < 4^(k+1), v > 0 */
{
#if defined(__GNUC__) &&                                                                                     \
    (defined(__ARM_FEATURE_CLZ) || defined(__x86_64__) || defined(__i386__) || defined(__riscv_zbb))
    return (31u - (unsigned)__builtin_clz(v)) >> 1;
#else
    unsigned k = 0;
    if (v >= (1u << 16))
    {
        v >>= 16;
        k += 8;
    }
    if (v >= (1u << 8))
    {
        v >>= 8;
        k += 4;
    }
    if (v >= (1u << 4))
    {
        v >>= 4;
        k += 2;
    }
    if (v >= (1u << 2))
    {
        k += 1;
    }
    return k;
#endif
}

/* lidet__q_isqrt32 inline, for the per-pixel loops (the projection's range, the ground stage's R) */
#if LIDET_Q_HAVE_DIV
/* Cores with a divide instruction: Newton's iteration from above, x <- (x + v / x) / 2 in integers, never goes
 * below floor(sqrt(v)) (AM-GM on the integer parts). Started at 2^(k-1) + v / 2^(k+1) for v in [4^k, 4^(k+1))
 * (one real Newton step from 2^k: at most 1.25 times the root), three steps leave at most 1.00000005 times it,
 * i.e. floor(sqrt(v)) or one above; a last compare settles it. About 20 instructions on a Cortex-M4 instead of
 * the digits' 80. Exhaustively checked against the digit version (every v < 2^32: a throwaway harness);
 * tests/python/test_proj_q.py checks it against numpy's exact root. */
static inline uint32_t lidet__q_isqrt32_inl(uint32_t v)
{
    unsigned k;
    uint32_t x;
    if (v < 4u)
    {
        return v != 0u;
    }
    k = lidet__q_half_log4(v);
    x = (1u << (k - 1u)) + (v >> (k + 1u)); /* >= sqrt(v), <= 1.25 sqrt(v) + 1 */
    x = (x + v / x) >> 1;
    x = (x + v / x) >> 1;
    x = (x + v / x) >> 1;
    x = x < 65535u ? x : 65535u; /* the root of a 32-bit value is below 2^16 */
    return x - (uint32_t)(x * x > v);
}
#else
static inline uint32_t lidet__q_isqrt32_inl(uint32_t v)
{
    /* the root's 16 bits from the top, each kept when its square still fits: one 16 x 16 -> 32 product per bit
     * (a single instruction on Cortex-M0+), no 64-bit arithmetic and no division (cores without a divide) */
    uint32_t r = 0, bit = v < (1u << 24) ? 1u << 11 : 1u << 15; /* v < 2^24: the root < 2^12 */
    while (bit != 0u)
    {
        const uint32_t t = r | bit;
        r = t * t <= v ? t : r;
        bit >>= 1;
    }
    return r;
}
#endif

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
