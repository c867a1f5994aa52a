/* SPDX-License-Identifier: MIT */
/* Portable float32 dense kernels (see internal/lidet_nn.h); reference: codegen/lidet_ref/pointnet.py
 * dense(). Plain C99, no intrinsics: the port layer may replace this file, and it stays the test oracle.
 *
 * Why this shape (measured on the host, gcc -O3, SSE2 only, 8 rows x 64 -> 128 layer): the weights are
 * stored [in][out], so the innermost loop runs over the output channels of one weight row, a unit-stride
 * loop every compiler vectorises. Four rows share each weight load and four inputs are folded per pass
 * (one load/store of the output row per four multiply-adds): 12-18 GMAC/s, against 2-3 GMAC/s for an
 * output-stationary tile the compiler vectorised across the inputs with gathers, and 9 GMAC/s for one
 * input per pass. Sums run over the inputs in order, four at a time: x0 w0 + x1 w1 + x2 w2 + x3 w3 is
 * added to the running sum (the numpy reference sums in float64 and is compared with a tolerance). */
#include "internal/lidet_nn.h"

/* Host builds on x86-64 (CMake option LIDET_NN_CLONES, on by default there): GCC/clang also compile these
 * kernels for AVX2 and AVX-512 and pick the variant when the program loads (ifunc, LIDET_NN_KERNEL_F32 in
 * internal/lidet_nn.h), the way onnxruntime dispatches its kernels. Same C source, same results: no FMA
 * contraction (-ffp-contract=off), each sum in the same order (the four trained models' outputs on 300 random
 * proposals each are bit-identical with a build without the clones). Measured (8 x 64 -> 128): 19 GMAC/s SSE2,
 * 39 GMAC/s AVX2; the whole classifier and box net 1.5x faster with AVX-512 than with AVX2 on a Zen 4 host.
 * Firmware builds never define it. Hosts with FMA run lidet_nn_f32_x86.c's kernel instead (LIDET_NN_FMA), aarch64
 * targets lidet_nn_f32_neon.c's (LIDET_NN_NEON). */

/* rows r..r+3 of out += in rows * W over inputs [0, n_in), 4 inputs per pass */
static inline void rows4(const float *x, uint32_t n_in, const float *w_t, uint32_t n_out, float *restrict o0)
{
    float *restrict o1 = o0 + n_out;
    float *restrict o2 = o1 + n_out;
    float *restrict o3 = o2 + n_out;
    const float *x1 = x + n_in, *x2 = x + 2u * n_in, *x3 = x + 3u * n_in;
    uint32_t i = 0, k;
    for (; i + 4u <= n_in; i += 4u)
    {
        const float *restrict w0 = w_t + (uint32_t)i * n_out;
        const float *restrict w1 = w0 + n_out;
        const float *restrict w2 = w1 + n_out;
        const float *restrict w3 = w2 + n_out;
        const float a0 = x[i], a1 = x[i + 1u], a2 = x[i + 2u], a3 = x[i + 3u];
        const float b0 = x1[i], b1 = x1[i + 1u], b2 = x1[i + 2u], b3 = x1[i + 3u];
        const float c0 = x2[i], c1 = x2[i + 1u], c2 = x2[i + 2u], c3 = x2[i + 3u];
        const float d0 = x3[i], d1 = x3[i + 1u], d2 = x3[i + 2u], d3 = x3[i + 3u];
        for (k = 0; k < n_out; ++k)
        {
            const float p = w0[k], q = w1[k], r = w2[k], s = w3[k];
            o0[k] += a0 * p + a1 * q + a2 * r + a3 * s;
            o1[k] += b0 * p + b1 * q + b2 * r + b3 * s;
            o2[k] += c0 * p + c1 * q + c2 * r + c3 * s;
            o3[k] += d0 * p + d1 * q + d2 * r + d3 * s;
        }
    }
    for (; i < n_in; ++i)
    {
        const float *restrict w0 = w_t + (uint32_t)i * n_out;
        const float a0 = x[i], b0 = x1[i], c0 = x2[i], d0 = x3[i];
        for (k = 0; k < n_out; ++k)
        {
            const float p = w0[k];
            o0[k] += a0 * p;
            o1[k] += b0 * p;
            o2[k] += c0 * p;
            o3[k] += d0 * p;
        }
    }
}

/* one row of out += in row * W, 4 inputs per pass */
static inline void rows1(const float *x, uint32_t n_in, const float *w_t, uint32_t n_out, float *restrict o0)
{
    uint32_t i = 0, k;
    for (; i + 4u <= n_in; i += 4u)
    {
        const float *restrict w0 = w_t + (uint32_t)i * n_out;
        const float *restrict w1 = w0 + n_out;
        const float *restrict w2 = w1 + n_out;
        const float *restrict w3 = w2 + n_out;
        const float a0 = x[i], a1 = x[i + 1u], a2 = x[i + 2u], a3 = x[i + 3u];
        for (k = 0; k < n_out; ++k)
        {
            o0[k] += a0 * w0[k] + a1 * w1[k] + a2 * w2[k] + a3 * w3[k];
        }
    }
    for (; i < n_in; ++i)
    {
        const float *restrict w0 = w_t + (uint32_t)i * n_out;
        const float a0 = x[i];
        for (k = 0; k < n_out; ++k)
        {
            o0[k] += a0 * w0[k];
        }
    }
}

/* on x86-64 hosts with FMA dispatch (LIDET_NN_FMA) lidet_nn_f32_x86.c defines lidet__nn_dense_f32 and falls back
 * to this kernel, under another name, on CPUs without FMA; on aarch64 (LIDET_NN_NEON) lidet_nn_f32_neon.c defines it,
 * and this kernel stays under that name for the tests; on Cortex-M4F/M7 (LIDET_NN_F32_CM) lidet_nn_f32_cm.c defines it
 * with this kernel's arithmetic (or, with LIDET_NN_CM_FMA, the fused one) and falls back to this one for widths not a
 * multiple of 8; on RISC-V with F (LIDET_NN_F32_RV) lidet_nn_f32_rv.c defines it */
#if LIDET_NN_FMA || LIDET_NN_NEON || LIDET_NN_F32_CM || LIDET_NN_F32_RV
#define NN_DENSE_F32 lidet__nn_dense_f32_portable
#else
#define NN_DENSE_F32 lidet__nn_dense_f32
#endif
LIDET_NN_KERNEL_F32 void NN_DENSE_F32(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                      const float *b, uint32_t n_out, int relu, float *out)
{
    uint32_t r, k;
    for (r = 0; r < n_rows; ++r)
    {
        float *o = out + (uint32_t)r * n_out;
        for (k = 0; k < n_out; ++k)
        {
            o[k] = b[k];
        }
    }
    for (r = 0; r + 4u <= n_rows; r += 4u)
    {
        rows4(in + (uint32_t)r * n_in, n_in, w_t, n_out, out + (uint32_t)r * n_out);
    }
    for (; r < n_rows; ++r)
    {
        rows1(in + (uint32_t)r * n_in, n_in, w_t, n_out, out + (uint32_t)r * n_out);
    }
    if (relu)
    {
        const uint32_t n = n_rows * n_out;
        for (k = 0; k < n; ++k)
        {
            out[k] = out[k] > 0.0f ? out[k] : 0.0f;
        }
    }
}

/* on Cortex-M4F/M7 (LIDET_NN_F32_CM) lidet_nn_f32_cm.c defines lidet__nn_max_rows_f32, 8 columns per pass, the same
 * comparisons; this one is its fallback for widths not a multiple of 8. On x86-64 hosts cloned as the dense kernel
 * (AVX2, AVX-512; each comparison the same): measured on the 17 real KITTI scans (HDL-64, 360 degrees, Intel Xeon,
 * one core, AVX-512), classify 1.31 -> 1.27 ms, box net 0.39 -> 0.38 ms (SSE2 before) */
#if LIDET_NN_F32_CM
#define NN_MAX_ROWS_F32 lidet__nn_max_rows_f32_portable
#else
#define NN_MAX_ROWS_F32 lidet__nn_max_rows_f32
#endif
LIDET_NN_KERNEL_F32 void NN_MAX_ROWS_F32(const float *in, uint32_t n_rows, uint32_t n, float *vmax)
{
    uint32_t r, k;
    for (r = 0; r < n_rows; ++r)
    {
        const float *x = in + (uint32_t)r * n;
        for (k = 0; k < n; ++k)
        {
            vmax[k] = x[k] > vmax[k] ? x[k] : vmax[k];
        }
    }
}
