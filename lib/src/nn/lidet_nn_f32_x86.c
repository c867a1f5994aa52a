/* SPDX-License-Identifier: MIT */
/* The float dense kernel (internal/lidet_nn.h) on x86-64 hosts whose CPU has FMA: register-tiled, fused
 * multiply-adds, an AVX-512 and an AVX2 variant chosen when the program loads (ifunc, as the clones of
 * internal/lidet_simd.h); CPUs without FMA get the portable kernel (lidet_nn_f32.c). Compiled only where
 * LIDET_NN_FMA is 1 (CMake LIDET_NN_CLONES and LIDET_NN_FMA, both on by default on x86-64 GCC/clang hosts);
 * an empty unit elsewhere (every firmware).
 *
 * Arithmetic: each output is o = b, then o = fma(in[i], w[i], o) for i = 0 .. n_in - 1 (one rounding per
 * multiply-add), then the ReLU. Every variant and every tail computes each output by that same chain, so all
 * FMA hosts get the same bits; they differ from the portable kernel's (which rounds the products and sums four
 * at a time) in the last bits, like any two float implementations: the tests compare float paths with the
 * float64 reference within tolerances. CMake LIDET_NN_FMA=OFF keeps the portable kernel everywhere.
 *
 * Why (measured on the host, 8 rows, the shared layers' shapes 32 x 64, 64 x 128, 128 x 256): the portable
 * kernel keeps its sums in memory and needs a multiply and an add per multiply-add, 33-38 GMAC/s with AVX-512;
 * an 8-row x 32-output tile held in 16 registers over all the inputs, each weight load shared by 8 rows and one
 * FMA per multiply-add, 68-77 GMAC/s (docs/benchmarks/pointnet.md: the classifier and the box net end to
 * end). */
#include "internal/lidet_nn.h"

#if LIDET_NN_FMA
#include <immintrin.h>

#define T512 __attribute__((target("avx512f")))
#define T256 __attribute__((target("avx2,fma")))

/* ---- AVX-512: 8 rows x 32 outputs per tile (16 accumulators), then 16 and masked tails ------------------ */

/* one input of an 8-row band: row rr's two accumulators (outputs [k, k + 32)) */
#define ACC8_2(rr)                                                                                           \
    do                                                                                                       \
    {                                                                                                        \
        const __m512 p_ = _mm512_set1_ps(x[(rr)*n_in + i]);                                                  \
        a##rr##0 = _mm512_fmadd_ps(p_, w0, a##rr##0);                                                        \
        a##rr##1 = _mm512_fmadd_ps(p_, w1, a##rr##1);                                                        \
    } while (0)

/* the ReLU: max(v, 0) returns its second operand for NaN and for -0, as the portable `v > 0 ? v : 0` */
static inline T512 __m512 relu512(__m512 v, int relu)
{
    return relu ? _mm512_max_ps(v, _mm512_setzero_ps()) : v;
}

/* the inputs of an 8-row band that are not zero in every row, in order, into act (n_in <= BAND_MAX_IN); returns
 * their count. An input that is +0 or -0 in all eight rows is left out of a ReLU layer's chains: fma(0, w, o) is
 * o but for the sign of a zero o (-0 + +0 = +0), which the ReLU erases (max(-0, 0) and max(+0, 0) are both +0),
 * so every output keeps its bits (the firmware kernels' argument, lidet_nn_f32_cm.c, per band instead of per
 * row). A NaN input is kept (it compares unequal to 0). On real KITTI scans 13-19 % of the band inputs of the
 * classifier are zero in all eight rows (the rows of a band are points of one proposal, whose ReLU channels are
 * often off together), and about 40 % of a single row's (row_512). Measured on the 17 real KITTI scans (HDL-64,
 * 360 degrees, Intel Xeon, one core, AVX-512; mean of the per-scan medians of `lidet detect --repeat 15
 * --cpu-clock`, interleaved with the build before): classify 1.35 -> 1.29 ms, box net 0.41 -> 0.39 ms */
#define BAND_MAX_IN 1024u
static inline T512 uint32_t band_active_512(const float *x, uint32_t n_in, uint32_t rows, uint32_t *act)
{
    const __m512 z = _mm512_setzero_ps();
    const __m512i step = _mm512_set1_epi32(16);
    __m512i idx = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    uint32_t i = 0, n = 0, r;
    for (; i + 16u <= n_in; i += 16u)
    {
        __mmask16 m = 0;
        for (r = 0; r < rows; ++r)
        {
            m = (__mmask16)(m | _mm512_cmp_ps_mask(_mm512_loadu_ps(x + r * n_in + i), z, _CMP_NEQ_UQ));
        }
        _mm512_mask_compressstoreu_epi32(act + n, m, idx);
        n += (uint32_t)__builtin_popcount((unsigned)m);
        idx = _mm512_add_epi32(idx, step);
    }
    for (; i < n_in; ++i)
    {
        uint32_t nz = 0u;
        for (r = 0; r < rows; ++r)
        {
            nz |= (uint32_t)(x[r * n_in + i] != 0.0f);
        }
        act[n] = i;
        n += nz;
    }
    return n;
}

static T512 void band8_512(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out,
                           int relu, float *o)
{
    uint32_t k = 0, i, r, j, n_act = n_in;
    uint32_t act[BAND_MAX_IN]; /* n_in <= BAND_MAX_IN (lidet__nn_dense_f32_avx512) */
    if (relu)
    {
        n_act = band_active_512(x, n_in, 8u, act);
    }
    else
    {
        for (i = 0; i < n_in; ++i)
        {
            act[i] = i;
        }
    }
    for (; k + 32u <= n_out; k += 32u)
    {
        const __m512 b0 = _mm512_loadu_ps(b + k), b1 = _mm512_loadu_ps(b + k + 16u);
        __m512 a00 = b0, a01 = b1, a10 = b0, a11 = b1, a20 = b0, a21 = b1, a30 = b0, a31 = b1;
        __m512 a40 = b0, a41 = b1, a50 = b0, a51 = b1, a60 = b0, a61 = b1, a70 = b0, a71 = b1;
        for (j = 0; j < n_act; ++j)
        {
            i = act[j];
            {
                const float *w = w_t + (size_t)i * n_out + k;
                const __m512 w0 = _mm512_loadu_ps(w), w1 = _mm512_loadu_ps(w + 16);
                ACC8_2(0);
                ACC8_2(1);
                ACC8_2(2);
                ACC8_2(3);
                ACC8_2(4);
                ACC8_2(5);
                ACC8_2(6);
                ACC8_2(7);
            }
        }
        _mm512_storeu_ps(o + k, relu512(a00, relu));
        _mm512_storeu_ps(o + k + 16u, relu512(a01, relu));
        _mm512_storeu_ps(o + n_out + k, relu512(a10, relu));
        _mm512_storeu_ps(o + n_out + k + 16u, relu512(a11, relu));
        _mm512_storeu_ps(o + 2u * n_out + k, relu512(a20, relu));
        _mm512_storeu_ps(o + 2u * n_out + k + 16u, relu512(a21, relu));
        _mm512_storeu_ps(o + 3u * n_out + k, relu512(a30, relu));
        _mm512_storeu_ps(o + 3u * n_out + k + 16u, relu512(a31, relu));
        _mm512_storeu_ps(o + 4u * n_out + k, relu512(a40, relu));
        _mm512_storeu_ps(o + 4u * n_out + k + 16u, relu512(a41, relu));
        _mm512_storeu_ps(o + 5u * n_out + k, relu512(a50, relu));
        _mm512_storeu_ps(o + 5u * n_out + k + 16u, relu512(a51, relu));
        _mm512_storeu_ps(o + 6u * n_out + k, relu512(a60, relu));
        _mm512_storeu_ps(o + 6u * n_out + k + 16u, relu512(a61, relu));
        _mm512_storeu_ps(o + 7u * n_out + k, relu512(a70, relu));
        _mm512_storeu_ps(o + 7u * n_out + k + 16u, relu512(a71, relu));
    }
    for (; k < n_out; k += 16u)
    {
        /* 16 outputs or the masked rest */
        const __mmask16 m = n_out - k >= 16u ? (__mmask16)0xFFFFu : (__mmask16)((1u << (n_out - k)) - 1u);
        const __m512 bb = _mm512_maskz_loadu_ps(m, b + k);
        __m512 a[8];
        for (r = 0; r < 8u; ++r)
        {
            a[r] = bb;
        }
        for (j = 0; j < n_act; ++j)
        {
            const __m512 w = _mm512_maskz_loadu_ps(m, w_t + (size_t)act[j] * n_out + k);
            for (r = 0; r < 8u; ++r)
            {
                a[r] = _mm512_fmadd_ps(_mm512_set1_ps(x[r * n_in + act[j]]), w, a[r]);
            }
        }
        for (r = 0; r < 8u; ++r)
        {
            _mm512_mask_storeu_ps(o + r * n_out + k, m, relu512(a[r], relu));
        }
    }
}

/* 4 rows x 64 outputs per tile (16 accumulators; each input: 4 weight loads and 4 broadcasts for 16 FMAs), for ReLU
 * layers with n_out a multiple of 64: a band of 4 rows has more inputs that are zero in all its rows than one of 8
 * (24-27 % against 13-19 % of the classifier's on real KITTI scans), left out the same way. Measured on the 17 real
 * KITTI scans (HDL-64, 360 degrees, Intel Xeon, one core, AVX-512), after the 8-row skip: classify 1.27 -> 1.23 ms,
 * box net 0.38 -> 0.38 ms */
static T512 void band4_512(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out,
                           int relu, float *o)
{
    uint32_t k, j;
    uint32_t act[BAND_MAX_IN]; /* n_in <= BAND_MAX_IN (lidet__nn_dense_f32_avx512) */
    const uint32_t n_act = band_active_512(x, n_in, 4u, act);
    for (k = 0; k < n_out; k += 64u)
    {
        const __m512 b0 = _mm512_loadu_ps(b + k), b1 = _mm512_loadu_ps(b + k + 16u);
        const __m512 b2 = _mm512_loadu_ps(b + k + 32u), b3 = _mm512_loadu_ps(b + k + 48u);
        __m512 a00 = b0, a01 = b1, a02 = b2, a03 = b3, a10 = b0, a11 = b1, a12 = b2, a13 = b3;
        __m512 a20 = b0, a21 = b1, a22 = b2, a23 = b3, a30 = b0, a31 = b1, a32 = b2, a33 = b3;
        for (j = 0; j < n_act; ++j)
        {
            const uint32_t i = act[j];
            const float *w = w_t + (size_t)i * n_out + k;
            const __m512 w0 = _mm512_loadu_ps(w), w1 = _mm512_loadu_ps(w + 16);
            const __m512 w2 = _mm512_loadu_ps(w + 32), w3 = _mm512_loadu_ps(w + 48);
            __m512 p = _mm512_set1_ps(x[i]);
            a00 = _mm512_fmadd_ps(p, w0, a00);
            a01 = _mm512_fmadd_ps(p, w1, a01);
            a02 = _mm512_fmadd_ps(p, w2, a02);
            a03 = _mm512_fmadd_ps(p, w3, a03);
            p = _mm512_set1_ps(x[n_in + i]);
            a10 = _mm512_fmadd_ps(p, w0, a10);
            a11 = _mm512_fmadd_ps(p, w1, a11);
            a12 = _mm512_fmadd_ps(p, w2, a12);
            a13 = _mm512_fmadd_ps(p, w3, a13);
            p = _mm512_set1_ps(x[2u * n_in + i]);
            a20 = _mm512_fmadd_ps(p, w0, a20);
            a21 = _mm512_fmadd_ps(p, w1, a21);
            a22 = _mm512_fmadd_ps(p, w2, a22);
            a23 = _mm512_fmadd_ps(p, w3, a23);
            p = _mm512_set1_ps(x[3u * n_in + i]);
            a30 = _mm512_fmadd_ps(p, w0, a30);
            a31 = _mm512_fmadd_ps(p, w1, a31);
            a32 = _mm512_fmadd_ps(p, w2, a32);
            a33 = _mm512_fmadd_ps(p, w3, a33);
        }
        _mm512_storeu_ps(o + k, relu512(a00, relu));
        _mm512_storeu_ps(o + k + 16u, relu512(a01, relu));
        _mm512_storeu_ps(o + k + 32u, relu512(a02, relu));
        _mm512_storeu_ps(o + k + 48u, relu512(a03, relu));
        _mm512_storeu_ps(o + n_out + k, relu512(a10, relu));
        _mm512_storeu_ps(o + n_out + k + 16u, relu512(a11, relu));
        _mm512_storeu_ps(o + n_out + k + 32u, relu512(a12, relu));
        _mm512_storeu_ps(o + n_out + k + 48u, relu512(a13, relu));
        _mm512_storeu_ps(o + 2u * n_out + k, relu512(a20, relu));
        _mm512_storeu_ps(o + 2u * n_out + k + 16u, relu512(a21, relu));
        _mm512_storeu_ps(o + 2u * n_out + k + 32u, relu512(a22, relu));
        _mm512_storeu_ps(o + 2u * n_out + k + 48u, relu512(a23, relu));
        _mm512_storeu_ps(o + 3u * n_out + k, relu512(a30, relu));
        _mm512_storeu_ps(o + 3u * n_out + k + 16u, relu512(a31, relu));
        _mm512_storeu_ps(o + 3u * n_out + k + 32u, relu512(a32, relu));
        _mm512_storeu_ps(o + 3u * n_out + k + 48u, relu512(a33, relu));
    }
}

/* one row (the heads' vectors, the last rows of a block): 64 outputs at a time, four chains in flight (one
 * chain alone waits on each FMA's latency), then 16 and the masked rest */
static T512 void row_512(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out,
                         int relu, float *o)
{
    uint32_t k = 0, i, j, n_act = n_in;
    uint32_t act[BAND_MAX_IN]; /* n_in <= BAND_MAX_IN (lidet__nn_dense_f32_avx512) */
    if (relu)
    {
        n_act = band_active_512(x, n_in, 1u, act); /* the row's zero inputs left out, as a band's */
    }
    else
    {
        for (i = 0; i < n_in; ++i)
        {
            act[i] = i;
        }
    }
    for (; k + 64u <= n_out; k += 64u)
    {
        __m512 a0 = _mm512_loadu_ps(b + k), a1 = _mm512_loadu_ps(b + k + 16u);
        __m512 a2 = _mm512_loadu_ps(b + k + 32u), a3 = _mm512_loadu_ps(b + k + 48u);
        for (j = 0; j < n_act; ++j)
        {
            const float *w = w_t + (size_t)act[j] * n_out + k;
            const __m512 p = _mm512_set1_ps(x[act[j]]);
            a0 = _mm512_fmadd_ps(p, _mm512_loadu_ps(w), a0);
            a1 = _mm512_fmadd_ps(p, _mm512_loadu_ps(w + 16), a1);
            a2 = _mm512_fmadd_ps(p, _mm512_loadu_ps(w + 32), a2);
            a3 = _mm512_fmadd_ps(p, _mm512_loadu_ps(w + 48), a3);
        }
        _mm512_storeu_ps(o + k, relu512(a0, relu));
        _mm512_storeu_ps(o + k + 16u, relu512(a1, relu));
        _mm512_storeu_ps(o + k + 32u, relu512(a2, relu));
        _mm512_storeu_ps(o + k + 48u, relu512(a3, relu));
    }
    for (; k < n_out; k += 16u)
    {
        const __mmask16 m = n_out - k >= 16u ? (__mmask16)0xFFFFu : (__mmask16)((1u << (n_out - k)) - 1u);
        __m512 a = _mm512_maskz_loadu_ps(m, b + k);
        for (j = 0; j < n_act; ++j)
        {
            a = _mm512_fmadd_ps(_mm512_set1_ps(x[act[j]]),
                                _mm512_maskz_loadu_ps(m, w_t + (size_t)act[j] * n_out + k), a);
        }
        _mm512_mask_storeu_ps(o + k, m, relu512(a, relu));
    }
}

T256 void lidet__nn_dense_f32_avx2fma(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                      const float *b, uint32_t n_out, int relu, float *out);

T512 void lidet__nn_dense_f32_avx512(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                     const float *b, uint32_t n_out, int relu, float *out)
{
    uint32_t r = 0;
    if (n_in > BAND_MAX_IN)
    {
        /* wider than the input lists (the shipped models' layers have 195 inputs at most): the AVX2 kernel, the same
         * chains */
        lidet__nn_dense_f32_avx2fma(in, n_rows, n_in, w_t, b, n_out, relu, out);
        return;
    }
    if (relu && n_out % 64u == 0u)
    {
        /* the ReLU layers 64 outputs wide: 4-row bands (band4_512) */
        for (; r + 4u <= n_rows; r += 4u)
        {
            band4_512(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out);
        }
    }
    for (; r + 8u <= n_rows; r += 8u)
    {
        band8_512(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out);
    }
    for (; r < n_rows; ++r)
    {
        row_512(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out);
    }
}

/* ---- AVX2 + FMA: 4 rows x 16 outputs per tile (8 accumulators), then 8, then one output at a time -------- */

static inline T256 __m256 relu256(__m256 v, int relu)
{
    return relu ? _mm256_max_ps(v, _mm256_setzero_ps()) : v;
}

/* the chain of one output (the tails): the same fused operations, one lane */
static inline T256 float chain1(const float *x, uint32_t n_in, const float *w_t, uint32_t n_out, float b)
{
    uint32_t i;
    float a = b;
    for (i = 0; i < n_in; ++i)
    {
        a = __builtin_fmaf(x[i], w_t[(size_t)i * n_out], a);
    }
    return a;
}

static T256 void band4_256(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out,
                           int relu, float *o)
{
    uint32_t k = 0, i, r;
    for (; k + 16u <= n_out; k += 16u)
    {
        const __m256 b0 = _mm256_loadu_ps(b + k), b1 = _mm256_loadu_ps(b + k + 8u);
        __m256 a00 = b0, a01 = b1, a10 = b0, a11 = b1, a20 = b0, a21 = b1, a30 = b0, a31 = b1;
        for (i = 0; i < n_in; ++i)
        {
            const float *w = w_t + (size_t)i * n_out + k;
            const __m256 w0 = _mm256_loadu_ps(w), w1 = _mm256_loadu_ps(w + 8);
            __m256 p = _mm256_set1_ps(x[i]);
            a00 = _mm256_fmadd_ps(p, w0, a00);
            a01 = _mm256_fmadd_ps(p, w1, a01);
            p = _mm256_set1_ps(x[n_in + i]);
            a10 = _mm256_fmadd_ps(p, w0, a10);
            a11 = _mm256_fmadd_ps(p, w1, a11);
            p = _mm256_set1_ps(x[2u * n_in + i]);
            a20 = _mm256_fmadd_ps(p, w0, a20);
            a21 = _mm256_fmadd_ps(p, w1, a21);
            p = _mm256_set1_ps(x[3u * n_in + i]);
            a30 = _mm256_fmadd_ps(p, w0, a30);
            a31 = _mm256_fmadd_ps(p, w1, a31);
        }
        _mm256_storeu_ps(o + k, relu256(a00, relu));
        _mm256_storeu_ps(o + k + 8u, relu256(a01, relu));
        _mm256_storeu_ps(o + n_out + k, relu256(a10, relu));
        _mm256_storeu_ps(o + n_out + k + 8u, relu256(a11, relu));
        _mm256_storeu_ps(o + 2u * n_out + k, relu256(a20, relu));
        _mm256_storeu_ps(o + 2u * n_out + k + 8u, relu256(a21, relu));
        _mm256_storeu_ps(o + 3u * n_out + k, relu256(a30, relu));
        _mm256_storeu_ps(o + 3u * n_out + k + 8u, relu256(a31, relu));
    }
    for (; k + 8u <= n_out; k += 8u)
    {
        const __m256 bb = _mm256_loadu_ps(b + k);
        __m256 a0 = bb, a1 = bb, a2 = bb, a3 = bb;
        for (i = 0; i < n_in; ++i)
        {
            const __m256 w = _mm256_loadu_ps(w_t + (size_t)i * n_out + k);
            a0 = _mm256_fmadd_ps(_mm256_set1_ps(x[i]), w, a0);
            a1 = _mm256_fmadd_ps(_mm256_set1_ps(x[n_in + i]), w, a1);
            a2 = _mm256_fmadd_ps(_mm256_set1_ps(x[2u * n_in + i]), w, a2);
            a3 = _mm256_fmadd_ps(_mm256_set1_ps(x[3u * n_in + i]), w, a3);
        }
        _mm256_storeu_ps(o + k, relu256(a0, relu));
        _mm256_storeu_ps(o + n_out + k, relu256(a1, relu));
        _mm256_storeu_ps(o + 2u * n_out + k, relu256(a2, relu));
        _mm256_storeu_ps(o + 3u * n_out + k, relu256(a3, relu));
    }
    for (; k < n_out; ++k)
    {
        for (r = 0; r < 4u; ++r)
        {
            const float a = chain1(x + r * n_in, n_in, w_t + k, n_out, b[k]);
            o[r * n_out + k] = relu && !(a > 0.0f) ? 0.0f : a;
        }
    }
}

static T256 void row_256(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out,
                         int relu, float *o)
{
    uint32_t k = 0, i;
    for (; k + 32u <= n_out; k += 32u)
    {
        /* four chains in flight (as row_512) */
        __m256 a0 = _mm256_loadu_ps(b + k), a1 = _mm256_loadu_ps(b + k + 8u);
        __m256 a2 = _mm256_loadu_ps(b + k + 16u), a3 = _mm256_loadu_ps(b + k + 24u);
        for (i = 0; i < n_in; ++i)
        {
            const float *w = w_t + (size_t)i * n_out + k;
            const __m256 p = _mm256_set1_ps(x[i]);
            a0 = _mm256_fmadd_ps(p, _mm256_loadu_ps(w), a0);
            a1 = _mm256_fmadd_ps(p, _mm256_loadu_ps(w + 8), a1);
            a2 = _mm256_fmadd_ps(p, _mm256_loadu_ps(w + 16), a2);
            a3 = _mm256_fmadd_ps(p, _mm256_loadu_ps(w + 24), a3);
        }
        _mm256_storeu_ps(o + k, relu256(a0, relu));
        _mm256_storeu_ps(o + k + 8u, relu256(a1, relu));
        _mm256_storeu_ps(o + k + 16u, relu256(a2, relu));
        _mm256_storeu_ps(o + k + 24u, relu256(a3, relu));
    }
    for (; k + 8u <= n_out; k += 8u)
    {
        __m256 a = _mm256_loadu_ps(b + k);
        for (i = 0; i < n_in; ++i)
        {
            a = _mm256_fmadd_ps(_mm256_set1_ps(x[i]), _mm256_loadu_ps(w_t + (size_t)i * n_out + k), a);
        }
        _mm256_storeu_ps(o + k, relu256(a, relu));
    }
    for (; k < n_out; ++k)
    {
        const float a = chain1(x, n_in, w_t + k, n_out, b[k]);
        o[k] = relu && !(a > 0.0f) ? 0.0f : a;
    }
}

T256 void lidet__nn_dense_f32_avx2fma(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                      const float *b, uint32_t n_out, int relu, float *out)
{
    uint32_t r = 0;
    for (; r + 4u <= n_rows; r += 4u)
    {
        band4_256(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out);
    }
    for (; r < n_rows; ++r)
    {
        row_256(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out);
    }
}

/* ---- the choice, once, when the program loads --------------------------------------------------------- */

typedef void dense_fn_t(const float *, uint32_t, uint32_t, const float *, const float *, uint32_t, int,
                        float *);

/* the ifunc resolver: runs once, when the program loads, before any sanitizer runtime or thread-local storage is
 * set up, so nothing in it is instrumented (clang's fuzzer coverage would call into libFuzzer and read TLS) */
#if defined(__clang__)
#define NN_RESOLVER_ATTR __attribute__((used, no_sanitize("address", "undefined", "coverage")))
#else
#define NN_RESOLVER_ATTR __attribute__((used, no_sanitize_address, no_sanitize_undefined))
#endif
NN_RESOLVER_ATTR static dense_fn_t *resolve_dense(void)
{
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f"))
    {
        return lidet__nn_dense_f32_avx512;
    }
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    {
        return lidet__nn_dense_f32_avx2fma;
    }
    return lidet__nn_dense_f32_portable;
}

void lidet__nn_dense_f32(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                         uint32_t n_out, int relu, float *out) __attribute__((ifunc("resolve_dense")));

#else
typedef int lidet__nn_f32_x86_empty; /* ISO C: a translation unit holds at least one declaration */
#endif
