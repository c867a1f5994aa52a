/* SPDX-License-Identifier: MIT */
/* The C library functions of the bare-metal aarch64 image (ports/aarch64/virt_libc.c), built for the host under other
 * names (port_expf, port_memcpy, ...: tests/firmware.cmake) and compared with the host's C library: the float math
 * functions within 2 ulps on random arguments over the ranges lidet uses and over every float, identical on the
 * special values of C99 Annex F (zeros with their signs, infinities, NaN), fmodf exactly everywhere; the string
 * functions byte for byte (memmove with overlaps both ways). Prints the largest difference per function.
 * Exit status 0: pass. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

float port_expf(float x);
float port_logf(float x);
float port_sinf(float x);
float port_cosf(float x);
void port_sincosf(float x, float *s, float *c);
float port_tanf(float x);
float port_atan2f(float y, float x);
float port_fmodf(float x, float y);
void *port_memcpy(void *dst, const void *src, size_t n);
void *port_memmove(void *dst, const void *src, size_t n);
void *port_memset(void *dst, int c, size_t n);
int port_memcmp(const void *a, const void *b, size_t n);
int port_strcmp(const char *a, const char *b);

static uint32_t g_rng = 2463534242u;

static uint32_t next_u32(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return g_rng;
}

static float any_float(void)
{
    const uint32_t u = next_u32();
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static float in_range(float lim)
{
    return (float)(int32_t)next_u32() / 2147483648.0f * lim;
}

/* distance in ulps; 0 for two NaNs; huge for a NaN against a number or zeros of different signs */
static int64_t ulps(float a, float b)
{
    int32_t ia, ib;
    int64_t oa, ob;
    if (a != a || b != b)
        return a != a && b != b ? 0 : INT64_MAX;
    if (a == 0.0f && b == 0.0f)
        return signbit(a) == signbit(b) ? 0 : INT64_MAX;
    memcpy(&ia, &a, sizeof ia);
    memcpy(&ib, &b, sizeof ib);
    oa = ia < 0 ? (int64_t)INT32_MIN - ia : ia;
    ob = ib < 0 ? (int64_t)INT32_MIN - ib : ib;
    return oa > ob ? oa - ob : ob - oa;
}

enum
{
    F_EXP,
    F_LOG,
    F_SIN,
    F_COS,
    F_TAN,
    F_ATAN2,
    F_FMOD,
    N_F
};
static const char *const k_names[N_F] = {"expf", "logf", "sinf", "cosf", "tanf", "atan2f", "fmodf"};
static const int64_t k_tol[N_F] = {2, 2, 2, 2, 2, 2, 0};
static int64_t g_worst[N_F];
static float g_worst_x[N_F], g_worst_y[N_F];
static int g_fail;

static void check(int f, float x, float y, float got, float want, int special)
{
    const int64_t u = ulps(got, want);
    if (u > g_worst[f])
    {
        g_worst[f] = u;
        g_worst_x[f] = x;
        g_worst_y[f] = y;
    }
    if (u > (special ? 0 : k_tol[f]))
    {
        if (g_fail < 20)
            printf("FAIL %s(%a, %a): %a, the host's %a\n", k_names[f], (double)x, (double)y, (double)got,
                   (double)want);
        ++g_fail;
    }
}

static void one_argument(float x, int special)
{
    float s, c;
    check(F_EXP, x, 0.0f, port_expf(x), expf(x), special);
    check(F_LOG, x, 0.0f, port_logf(x), logf(x), special);
    if (fabsf(x) < 1.6e6f || isinf(x) || x != x)
    {
        /* the argument reduction is exact below 1.6e6 rad (virt_libc.c) */
        port_sincosf(x, &s, &c);
        check(F_SIN, x, 0.0f, port_sinf(x), sinf(x), special);
        check(F_COS, x, 0.0f, port_cosf(x), cosf(x), special);
        check(F_SIN, x, 0.0f, s, sinf(x), special);
        check(F_COS, x, 0.0f, c, cosf(x), special);
        check(F_TAN, x, 0.0f, port_tanf(x), tanf(x), special);
    }
}

static void two_arguments(float y, float x, int special)
{
    check(F_ATAN2, x, y, port_atan2f(y, x), atan2f(y, x), special);
    check(F_FMOD, x, y, port_fmodf(x, y), fmodf(x, y), special);
}

static void strings(void)
{
    static unsigned char a[300], b[300], r[300];
    size_t n, off, k;
    for (k = 0; k < sizeof a; ++k)
        a[k] = (unsigned char)next_u32();
    for (n = 0; n < 80u; ++n)
    {
        for (off = 0; off < 20u; ++off)
        {
            /* memcpy / memset at every alignment */
            memset(b, 0xA5, sizeof b);
            memset(r, 0xA5, sizeof r);
            port_memcpy(b + off, a + 3, n);
            memcpy(r + off, a + 3, n);
            g_fail += memcmp(b, r, sizeof b) != 0;
            port_memset(b + off, (int)(off * 37u), n);
            memset(r + off, (int)(off * 37u), n);
            g_fail += memcmp(b, r, sizeof b) != 0;
            /* memmove forwards and backwards over overlaps */
            memcpy(b, a, sizeof b);
            memcpy(r, a, sizeof r);
            port_memmove(b + off, b + 40, n);
            memmove(r + off, r + 40, n);
            g_fail += memcmp(b, r, sizeof b) != 0;
            port_memmove(b + 40, b + off, n);
            memmove(r + 40, r + off, n);
            g_fail += memcmp(b, r, sizeof b) != 0;
            port_memmove(b + 100 + off, b + 100, n);
            memmove(r + 100 + off, r + 100, n);
            g_fail += memcmp(b, r, sizeof b) != 0;
        }
        memcpy(b, a, sizeof b);
        if (n > 0u)
            b[n - 1u] ^= 1u;
        g_fail += (port_memcmp(a, b, n) > 0) != (memcmp(a, b, n) > 0);
        g_fail += (port_memcmp(a, b, n) < 0) != (memcmp(a, b, n) < 0);
    }
    g_fail += port_strcmp("lidet", "lidet") != 0;
    g_fail += port_strcmp("lidet", "lidar") <= 0;
    g_fail += port_strcmp("li", "lidet") >= 0;
    g_fail += port_strcmp("", "") != 0;
    if (g_fail)
        printf("FAIL the string functions\n");
}

int main(void)
{
    static const float special[] = {0.0f,      -0.0f,       INFINITY,   -INFINITY, NAN,        1.0f,
                                    -1.0f,     0x1p-149f,   -0x1p-149f, 0x1p-126f, 3.4e38f,    -3.4e38f,
                                    88.72283f, 88.7228394f, -103.9f,    -87.3f,    1.5707964f, 3.1415927f,
                                    0.5f,      2.0f,        1e-30f};
    const size_t n_sp = sizeof special / sizeof special[0];
    size_t i, j;
    long k;
    for (i = 0; i < n_sp; ++i)
    {
        /* the Annex F values where both sides are exact (the rest are ordinary arguments) */
        const float x = special[i];
        const int exact = x == 0.0f || isinf(x) || x != x || x == 1.0f || x == -1.0f;
        one_argument(x, exact);
        for (j = 0; j < n_sp; ++j)
        {
            const float y = special[j];
            two_arguments(y, x, (x == 0.0f || isinf(x) || x != x) && (y == 0.0f || isinf(y) || y != y));
        }
    }
    for (k = 0; k < 400000; ++k)
    {
        one_argument(in_range(10.0f), 0);
        one_argument(in_range(100.0f), 0);
        one_argument(any_float(), 0);
        two_arguments(in_range(100.0f), in_range(100.0f), 0);
        two_arguments(any_float(), any_float(), 0);
    }
    strings();
    for (i = 0; i < N_F; ++i)
        printf("%-7s largest difference from the host's: %lld ulp (at %a, %a)\n", k_names[i],
               (long long)g_worst[i], (double)g_worst_x[i], (double)g_worst_y[i]);
    printf(g_fail ? "virt_libc: FAIL (%d)\n" : "virt_libc: PASS\n", g_fail);
    return g_fail != 0;
}
