/* SPDX-License-Identifier: MIT */
/* The C library functions a virt-aarch64 image needs. The image is linked without a C library (-nostdlib: the
 * toolchain is the GNU/Linux cross compiler, whose glibc does not run bare metal), so it carries these, written for
 * lidet: the string functions the compiler and the library call, and the float math functions of the float
 * detector (expf, logf, sinf, cosf, sincosf, tanf, atan2f, fmodf).
 *
 * The math functions compute in double precision (the core's double unit; the port is not lib/, whose float code
 * stays single precision) with series that converge far below a float's rounding, then round once to float: each
 * result is within an ulp of the exact value, nearly always the correctly rounded one, as glibc's, newlib's and
 * picolibc's are (the firmware comparison allows for that, tools/firmware/run_fw.py). Special values follow C99
 * Annex F (NaN in, NaN out; infinities and signed zeros). sinf / cosf / sincosf / tanf reduce their argument by
 * pi/2 split in three parts, exact for |x| < 1.6e6 rad; beyond, the reduction loses accuracy, and beyond 3.5e15
 * they return sin 0 and cos 0 (no angle lidet computes comes near). fmodf is exact (integer long division of the
 * significands).
 *
 * Built with -ffreestanding (ports/firmware/CMakeLists.txt), so that the compiler does not turn these loops into
 * calls to themselves. */
#include <stddef.h>
#include <stdint.h>

/* ---- strings and memory ------------------------------------------------------------------------------------ */

/* unaligned 8-byte words (the MMU maps the RAM as Normal memory, where the core allows unaligned accesses) */
typedef uint64_t u64_unaligned __attribute__((aligned(1), may_alias));

void *memcpy(void *restrict dst, const void *restrict src, size_t n);
void *memmove(void *dst, const void *src, size_t n);
void *memset(void *dst, int c, size_t n);
int memcmp(const void *a, const void *b, size_t n);
int strcmp(const char *a, const char *b);

/* forward, 16 bytes per step, each step's loads before its stores: also right for overlaps with dst < src */
static void copy_forward(unsigned char *d, const unsigned char *s, size_t n)
{
    for (; n >= 16u; n -= 16u, d += 16, s += 16)
    {
        const uint64_t a = *(const u64_unaligned *)s, b = *(const u64_unaligned *)(s + 8);
        *(u64_unaligned *)d = a;
        *(u64_unaligned *)(d + 8) = b;
    }
    for (; n > 0u; --n)
        *d++ = *s++;
}

void *memcpy(void *restrict dst, const void *restrict src, size_t n)
{
    copy_forward((unsigned char *)dst, (const unsigned char *)src, n);
    return dst;
}

void *memmove(void *dst, const void *src, size_t n)
{
    unsigned char *d = (unsigned char *)dst;
    const unsigned char *s = (const unsigned char *)src;
    if ((uintptr_t)d <= (uintptr_t)s || (uintptr_t)d >= (uintptr_t)s + n)
    {
        copy_forward(d, s, n);
        return dst;
    }
    /* dst overlaps the end of src: backward, each step's loads before its stores */
    d += n;
    s += n;
    for (; n >= 16u; n -= 16u)
    {
        uint64_t a, b;
        d -= 16;
        s -= 16;
        a = *(const u64_unaligned *)s;
        b = *(const u64_unaligned *)(s + 8);
        *(u64_unaligned *)d = a;
        *(u64_unaligned *)(d + 8) = b;
    }
    while (n-- > 0u)
        *--d = *--s;
    return dst;
}

void *memset(void *dst, int c, size_t n)
{
    unsigned char *d = (unsigned char *)dst;
    const uint64_t v = 0x0101010101010101u * (uint8_t)c;
    for (; n >= 16u; n -= 16u, d += 16)
    {
        *(u64_unaligned *)d = v;
        *(u64_unaligned *)(d + 8) = v;
    }
    for (; n > 0u; --n)
        *d++ = (unsigned char)c;
    return dst;
}

int memcmp(const void *a, const void *b, size_t n)
{
    const unsigned char *p = (const unsigned char *)a, *q = (const unsigned char *)b;
    for (; n > 0u; --n, ++p, ++q)
        if (*p != *q)
            return *p < *q ? -1 : 1;
    return 0;
}

int strcmp(const char *a, const char *b)
{
    const unsigned char *p = (const unsigned char *)a, *q = (const unsigned char *)b;
    while (*p != 0u && *p == *q)
    {
        ++p;
        ++q;
    }
    return (int)*p - (int)*q;
}

/* ---- float math, computed in double -------------------------------------------------------------------------- */

float expf(float x);
float logf(float x);
float sinf(float x);
float cosf(float x);
void sincosf(float x, float *s, float *c);
float tanf(float x);
float atan2f(float y, float x);
float fmodf(float x, float y);

typedef union
{
    double d;
    uint64_t u;
} dbits_t;

typedef union
{
    float f;
    uint32_t u;
} fbits_t;

static uint32_t f_bits(float x)
{
    fbits_t b;
    b.f = x;
    return b.u;
}

static float f_of(uint32_t u)
{
    fbits_t b;
    b.u = u;
    return b.f;
}

/* x rounded to the nearest integer (ties away from zero), for |x| < 2^52 */
static double round_d(double x)
{
    return (double)(int64_t)(x + (x >= 0.0 ? 0.5 : -0.5));
}

/* 2^k for -1022 <= k <= 1023 */
static double pow2_d(int k)
{
    dbits_t b;
    b.u = (uint64_t)(k + 1023) << 52;
    return b.d;
}

#define LN2_HI 0x1.62e42fee00000p-1 /* ln 2 in two parts: k * LN2_HI is exact for |k| < 2^20 */
#define LN2_LO 0x1.a39ef35793c76p-33
#define LN2 0x1.62e42fefa39efp-1
#define INV_LN2 0x1.71547652b82fep+0

float expf(float x)
{
    double r, p;
    int k;
    if (x != x)
        return x + x;
    if (x > 89.0f)
        return x * 0x1p127f * 0x1p127f; /* overflow: +inf */
    if (x < -104.0f)
        return 0x1p-126f * 0x1p-126f; /* underflow: +0 */
    /* x = k ln 2 + r, |r| <= ln 2 / 2; e^r by its Taylor series to r^13 / 13! (relative error < 1e-17) */
    k = (int)round_d((double)x * INV_LN2);
    r = ((double)x - (double)k * LN2_HI) - (double)k * LN2_LO;
    p = 1.0 / 6227020800.0;
    p = p * r + 1.0 / 479001600.0;
    p = p * r + 1.0 / 39916800.0;
    p = p * r + 1.0 / 3628800.0;
    p = p * r + 1.0 / 362880.0;
    p = p * r + 1.0 / 40320.0;
    p = p * r + 1.0 / 5040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    return (float)(p * pow2_d(k));
}

float logf(float x)
{
    dbits_t b;
    double m, s, z, p;
    int e;
    if (x != x)
        return x + x;
    if (x < 0.0f)
        return (x - x) / (x - x); /* NaN, invalid */
    if (x == 0.0f)
        return -1.0f / (x * x); /* -inf, divide by zero */
    if (x > 0x1.fffffep127f)
        return x; /* +inf */
    /* x = m 2^e with m in [sqrt(1/2), sqrt(2)) (float subnormals are normal doubles); ln m = 2 atanh(s),
       s = (m - 1) / (m + 1), |s| < 0.172: the odd series to s^23 (relative error < 1e-18) */
    b.d = (double)x;
    e = (int)((b.u >> 52) & 0x7FFu) - 1023;
    b.u = (b.u & 0x000FFFFFFFFFFFFFu) | 0x3FF0000000000000u;
    m = b.d;
    if (m > 0x1.6a09e667f3bcdp+0)
    {
        m *= 0.5;
        ++e;
    }
    s = (m - 1.0) / (m + 1.0);
    z = s * s;
    p = 1.0 / 23.0;
    p = p * z + 1.0 / 21.0;
    p = p * z + 1.0 / 19.0;
    p = p * z + 1.0 / 17.0;
    p = p * z + 1.0 / 15.0;
    p = p * z + 1.0 / 13.0;
    p = p * z + 1.0 / 11.0;
    p = p * z + 1.0 / 9.0;
    p = p * z + 1.0 / 7.0;
    p = p * z + 1.0 / 5.0;
    p = p * z + 1.0 / 3.0;
    p = p * z + 1.0;
    return (float)((double)e * LN2 + 2.0 * s * p);
}

/* pi / 2 in three parts of 33, 33 and 53 bits: k * PIO2_1 and k * PIO2_2 are exact for |k| < 2^20 */
#define PIO2_1 0x1.921fb54400000p+0
#define PIO2_2 0x1.0b4611a600000p-34
#define PIO2_3 0x1.3198a2e037073p-69
#define TWO_OVER_PI 0x1.45f306dc9c883p-1

/* sin and cos of a finite x (as double); the quadrant's signs applied */
static void sincos_d(float xf, double *s_out, double *c_out)
{
    const double x = (double)xf;
    double t = x * TWO_OVER_PI, k, r, z, s, c;
    uint32_t q;
    if (t > 0x1p51 || t < -0x1p51)
    {
        k = r = 0.0; /* |x| beyond 3.5e15 (no reduction here): sin 0 and cos 0, defined but meaningless */
    }
    else
    {
        k = round_d(t);
        r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    }
    q = (uint32_t)(int64_t)k & 3u;
    /* |r| <= pi / 4: the Taylor series to r^17 / 17! and r^18 / 18! (error < 1e-17) */
    z = r * r;
    s = -1.0 / 355687428096000.0;
    s = s * z + 1.0 / 1307674368000.0;
    s = s * z - 1.0 / 6227020800.0;
    s = s * z + 1.0 / 39916800.0;
    s = s * z - 1.0 / 362880.0;
    s = s * z + 1.0 / 5040.0;
    s = s * z - 1.0 / 120.0;
    s = s * z + 1.0 / 6.0;
    s = r - r * z * s;
    c = 1.0 / 6402373705728000.0;
    c = c * z - 1.0 / 20922789888000.0;
    c = c * z + 1.0 / 87178291200.0;
    c = c * z - 1.0 / 479001600.0;
    c = c * z + 1.0 / 3628800.0;
    c = c * z - 1.0 / 40320.0;
    c = c * z + 1.0 / 720.0;
    c = c * z - 1.0 / 24.0;
    c = c * z + 0.5;
    c = 1.0 - z * c;
    switch (q)
    {
    case 0u:
        *s_out = s;
        *c_out = c;
        break;
    case 1u:
        *s_out = c;
        *c_out = -s;
        break;
    case 2u:
        *s_out = -s;
        *c_out = -c;
        break;
    default:
        *s_out = -c;
        *c_out = s;
        break;
    }
}

void sincosf(float x, float *s, float *c)
{
    double sd, cd;
    if (x != x || x - x != 0.0f)
    {
        *s = *c = x - x; /* NaN; an infinity: NaN, invalid */
        return;
    }
    if (x == 0.0f)
    {
        *s = x; /* sin(+-0) = +-0 */
        *c = 1.0f;
        return;
    }
    sincos_d(x, &sd, &cd);
    *s = (float)sd;
    *c = (float)cd;
}

float sinf(float x)
{
    float s, c;
    sincosf(x, &s, &c);
    return s;
}

float cosf(float x)
{
    float s, c;
    sincosf(x, &s, &c);
    return c;
}

float tanf(float x)
{
    double sd, cd;
    if (x != x || x - x != 0.0f)
        return x - x;
    if (x == 0.0f)
        return x;
    sincos_d(x, &sd, &cd);
    return (float)(sd / cd);
}

#define PI_D 0x1.921fb54442d18p+1
#define PIO2_D 0x1.921fb54442d18p+0
#define PIO6_D 0x1.0c152382d7366p-1
#define SQRT3_D 0x1.bb67ae8584caap+0
#define TAN_PI12_D 0x1.126145e9ecd56p-2

/* atan(t) for 0 <= t <= 1 */
static double atan01(double t)
{
    double base = 0.0, z, p;
    if (t > TAN_PI12_D)
    {
        /* atan t = pi/6 + atan((t sqrt 3 - 1) / (t + sqrt 3)), the new argument within +-tan(pi/12) */
        base = PIO6_D;
        t = (t * SQRT3_D - 1.0) / (t + SQRT3_D);
    }
    /* |t| <= tan(pi/12) = 0.268: the odd series to t^31 / 31 (relative error < 1e-19) */
    z = t * t;
    p = -1.0 / 31.0;
    p = p * z + 1.0 / 29.0;
    p = p * z - 1.0 / 27.0;
    p = p * z + 1.0 / 25.0;
    p = p * z - 1.0 / 23.0;
    p = p * z + 1.0 / 21.0;
    p = p * z - 1.0 / 19.0;
    p = p * z + 1.0 / 17.0;
    p = p * z - 1.0 / 15.0;
    p = p * z + 1.0 / 13.0;
    p = p * z - 1.0 / 11.0;
    p = p * z + 1.0 / 9.0;
    p = p * z - 1.0 / 7.0;
    p = p * z + 1.0 / 5.0;
    p = p * z - 1.0 / 3.0;
    return base + (t + t * z * p);
}

float atan2f(float y, float x)
{
    const int y_neg = (f_bits(y) >> 31) != 0u, x_neg = (f_bits(x) >> 31) != 0u;
    const float ax = f_of(f_bits(x) & 0x7FFFFFFFu), ay = f_of(f_bits(y) & 0x7FFFFFFFu);
    double a;
    if (x != x || y != y)
        return x + y;
    if (ay == 0.0f)
        a = x_neg ? PI_D : 0.0; /* y = +-0: +-0 for x = +0 or x > 0, +-pi for x = -0 or x < 0 */
    else if (ax == 0.0f)
        a = PIO2_D;
    else if (ax > 0x1.fffffep127f)
        a = ay > 0x1.fffffep127f ? (x_neg ? 3.0 * PIO2_D / 2.0 : PIO2_D / 2.0) : (x_neg ? PI_D : 0.0);
    else if (ay > 0x1.fffffep127f)
        a = PIO2_D;
    else
    {
        a = ay <= ax ? atan01((double)ay / (double)ax) : PIO2_D - atan01((double)ax / (double)ay);
        if (x_neg)
            a = PI_D - a;
    }
    return y_neg ? -(float)a : (float)a;
}

float fmodf(float x, float y)
{
    const uint32_t ux = f_bits(x), uy = f_bits(y), sign = ux & 0x80000000u;
    uint32_t ax = ux & 0x7FFFFFFFu, ay = uy & 0x7FFFFFFFu, mx, my;
    int ex, ey;
    if (ay == 0u || ax >= 0x7F800000u || ay > 0x7F800000u)
        return (x * y) / (x * y); /* y = 0, x infinite, or a NaN: NaN */
    if (ax < ay)
        return x; /* |x| < |y| (and y infinite) */
    if (ax == ay)
        return f_of(sign); /* +-0 */
    /* significands with the implicit bit, exponents (subnormals normalised) */
    ex = (int)(ax >> 23);
    mx = ax & 0x7FFFFFu;
    if (ex == 0)
    {
        ex = 1;
        while ((mx & 0x800000u) == 0u)
        {
            mx <<= 1;
            --ex;
        }
    }
    else
        mx |= 0x800000u;
    ey = (int)(ay >> 23);
    my = ay & 0x7FFFFFu;
    if (ey == 0)
    {
        ey = 1;
        while ((my & 0x800000u) == 0u)
        {
            my <<= 1;
            --ey;
        }
    }
    else
        my |= 0x800000u;
    /* long division: the remainder of mx 2^(ex - ey) by my, one bit of the quotient per step (mx < 2^25) */
    for (; ex > ey; --ex)
    {
        if (mx >= my)
            mx -= my;
        mx <<= 1;
    }
    if (mx >= my)
        mx -= my;
    if (mx == 0u)
        return f_of(sign);
    while ((mx & 0x800000u) == 0u)
    {
        mx <<= 1;
        --ex;
    }
    if (ex >= 1)
        return f_of(sign | ((uint32_t)ex << 23) | (mx & 0x7FFFFFu));
    return f_of(sign | (mx >> (1 - ex))); /* subnormal: exact (the remainder is a multiple of y's ulp) */
}
