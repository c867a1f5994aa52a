/* SPDX-License-Identifier: MIT */
/* The float dense kernel (internal/lidet_nn.h) on aarch64 (Raspberry Pi 4/5, Jetson, any Armv8-A core): the NEON
 * variant, register-tiled with fused multiply-adds (FMLA). Compiled only where LIDET_NN_NEON is 1 (lidet_opt.h: by
 * default on aarch64 targets with NEON and FMA; CMake option LIDET_NN_NEON, ON; OFF passes 0 and keeps the
 * portable kernel, lidet_nn_f32.c, which stays the test oracle); an empty unit elsewhere (x86-64 hosts, Cortex-M,
 * RISC-V). No run-time dispatch: Advanced SIMD and FMA are part of every Armv8-A core.
 *
 * Arithmetic (the contract of the x86-64 FMA kernel, lidet_nn_f32_x86.c): each output is o = b, then
 * o = fma(in[i], w[i], o) for i = 0 .. n_in - 1 in order (one rounding per multiply-add), then the ReLU
 * (v > 0 ? v : +0: NaN and -0 give +0, as the portable kernel's). Every tile and every tail below computes each
 * output by that same chain, so an aarch64 build gives the same bits as the x86-64 hosts with FMA (ctest
 * aarch64_linux compares the CLI's float dumps byte for byte); against the portable kernel, which rounds the
 * products and sums four at a time, the last bits differ, within the float tolerances of the tests.
 *
 * Shape: the weights are [in][out], so a vector of 4 outputs is one load of a weight row. A band of 8 rows
 * (LIDET_PN_BLOCK's default: the shared per-point layers) keeps an 8-row x 8-output tile in 16 accumulators
 * over all the inputs: four inputs of each row are loaded as one vector and used lane by lane (FMLA by
 * element), so each pair of weight vectors serves 8 rows (26 of the 32 vector registers). Then 8 rows x 4
 * outputs, and the last 1-3 outputs row by row. Rows left over (fewer than 8, the heads' single vectors) run
 * 16 outputs at a time in 4 accumulators (the 4 weight vectors of an input in one LD1), then 4, 2 and 1.
 *
 * Measured in instructions (exact, QEMU; the bare-metal Cortex-A72 image virt-aarch64, -O2, the VLP-16 sample
 * scan: docs/FIRMWARE.md, "Linux on ARM (aarch64)"): the classifier 9.25 M and the box net 4.36 M per scan
 * against the portable kernel's 58.1 M and 29.1 M (0.16x); the whole scan 28.2 M against 101.8 M. The 8 x 8
 * tile's loop takes 92 instructions per four inputs, 64 of them FMLA. Time on silicon is not measured. */
#include "internal/lidet_nn.h"

#if LIDET_NN_NEON
#include <arm_neon.h>
#include <stddef.h>

/* the ReLU on 4 and on 2 lanes: the lane where v > 0, else +0 (the compare is false for NaN and for -0) */
static inline float32x4_t relu4(float32x4_t v, int relu)
{
    return relu ? vreinterpretq_f32_u32(vandq_u32(vcgtzq_f32(v), vreinterpretq_u32_f32(v))) : v;
}

static inline float32x2_t relu2(float32x2_t v, int relu)
{
    return relu ? vreinterpret_f32_u32(vand_u32(vcgtz_f32(v), vreinterpret_u32_f32(v))) : v;
}

/* ---- one row: outputs [k, n_out) ------------------------------------------------------------------------ */

static void row_from(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out,
                     int relu, float *o, uint32_t k)
{
    uint32_t i;
    for (; k + 16u <= n_out; k += 16u)
    {
        /* four chains in flight; one LD1 fetches the 16 weights of an input */
        float32x4_t a0 = vld1q_f32(b + k), a1 = vld1q_f32(b + k + 4u);
        float32x4_t a2 = vld1q_f32(b + k + 8u), a3 = vld1q_f32(b + k + 12u);
        const float *w = w_t + k;
        for (i = 0; i + 4u <= n_in; i += 4u)
        {
            const float32x4_t p = vld1q_f32(x + i);
            float32x4x4_t v = vld1q_f32_x4(w);
            a0 = vfmaq_laneq_f32(a0, v.val[0], p, 0);
            a1 = vfmaq_laneq_f32(a1, v.val[1], p, 0);
            a2 = vfmaq_laneq_f32(a2, v.val[2], p, 0);
            a3 = vfmaq_laneq_f32(a3, v.val[3], p, 0);
            v = vld1q_f32_x4(w + n_out);
            a0 = vfmaq_laneq_f32(a0, v.val[0], p, 1);
            a1 = vfmaq_laneq_f32(a1, v.val[1], p, 1);
            a2 = vfmaq_laneq_f32(a2, v.val[2], p, 1);
            a3 = vfmaq_laneq_f32(a3, v.val[3], p, 1);
            v = vld1q_f32_x4(w + 2u * n_out);
            a0 = vfmaq_laneq_f32(a0, v.val[0], p, 2);
            a1 = vfmaq_laneq_f32(a1, v.val[1], p, 2);
            a2 = vfmaq_laneq_f32(a2, v.val[2], p, 2);
            a3 = vfmaq_laneq_f32(a3, v.val[3], p, 2);
            v = vld1q_f32_x4(w + 3u * n_out);
            a0 = vfmaq_laneq_f32(a0, v.val[0], p, 3);
            a1 = vfmaq_laneq_f32(a1, v.val[1], p, 3);
            a2 = vfmaq_laneq_f32(a2, v.val[2], p, 3);
            a3 = vfmaq_laneq_f32(a3, v.val[3], p, 3);
            w += 4u * n_out;
        }
        for (; i < n_in; ++i)
        {
            const float32x4x4_t v = vld1q_f32_x4(w);
            a0 = vfmaq_n_f32(a0, v.val[0], x[i]);
            a1 = vfmaq_n_f32(a1, v.val[1], x[i]);
            a2 = vfmaq_n_f32(a2, v.val[2], x[i]);
            a3 = vfmaq_n_f32(a3, v.val[3], x[i]);
            w += n_out;
        }
        vst1q_f32(o + k, relu4(a0, relu));
        vst1q_f32(o + k + 4u, relu4(a1, relu));
        vst1q_f32(o + k + 8u, relu4(a2, relu));
        vst1q_f32(o + k + 12u, relu4(a3, relu));
    }
    for (; k + 4u <= n_out; k += 4u)
    {
        float32x4_t a = vld1q_f32(b + k);
        const float *w = w_t + k;
        for (i = 0; i + 4u <= n_in; i += 4u)
        {
            const float32x4_t p = vld1q_f32(x + i);
            a = vfmaq_laneq_f32(a, vld1q_f32(w), p, 0);
            a = vfmaq_laneq_f32(a, vld1q_f32(w + n_out), p, 1);
            a = vfmaq_laneq_f32(a, vld1q_f32(w + 2u * n_out), p, 2);
            a = vfmaq_laneq_f32(a, vld1q_f32(w + 3u * n_out), p, 3);
            w += 4u * n_out;
        }
        for (; i < n_in; ++i)
        {
            a = vfmaq_n_f32(a, vld1q_f32(w), x[i]);
            w += n_out;
        }
        vst1q_f32(o + k, relu4(a, relu));
    }
    if (k + 2u <= n_out)
    {
        float32x2_t a = vld1_f32(b + k);
        const float *w = w_t + k;
        for (i = 0; i < n_in; ++i)
        {
            a = vfma_n_f32(a, vld1_f32(w), x[i]);
            w += n_out;
        }
        vst1_f32(o + k, relu2(a, relu));
        k += 2u;
    }
    if (k < n_out)
    {
        /* the last output: one weight loaded into both lanes (never a read past a weight row), lane 0 stored */
        float32x2_t a = vld1_dup_f32(b + k);
        const float *w = w_t + k;
        for (i = 0; i < n_in; ++i)
        {
            a = vfma_n_f32(a, vld1_dup_f32(w), x[i]);
            w += n_out;
        }
        vst1_lane_f32(o + k, relu2(a, relu), 0);
    }
}

/* ---- a band of 8 rows ------------------------------------------------------------------------------------ */

/* inputs i .. i + 3 of row r, one vector (a pointer per row: no index arithmetic in the loops) */
#define LOAD_X(r) const float32x4_t p##r = vld1q_f32(x##r + i)

/* input i + l of the 8 rows into the 8 x 8 tile: weight vectors w0 (outputs k .. k + 3) and w1 (k + 4 .. k + 7) */
#define TILE8x8_LANE(l)                                                                                      \
    do                                                                                                       \
    {                                                                                                        \
        const float32x4_t w0 = vld1q_f32(w), w1 = vld1q_f32(w + 4);                                          \
        w += n_out;                                                                                          \
        a00 = vfmaq_laneq_f32(a00, w0, p0, l);                                                               \
        a01 = vfmaq_laneq_f32(a01, w1, p0, l);                                                               \
        a10 = vfmaq_laneq_f32(a10, w0, p1, l);                                                               \
        a11 = vfmaq_laneq_f32(a11, w1, p1, l);                                                               \
        a20 = vfmaq_laneq_f32(a20, w0, p2, l);                                                               \
        a21 = vfmaq_laneq_f32(a21, w1, p2, l);                                                               \
        a30 = vfmaq_laneq_f32(a30, w0, p3, l);                                                               \
        a31 = vfmaq_laneq_f32(a31, w1, p3, l);                                                               \
        a40 = vfmaq_laneq_f32(a40, w0, p4, l);                                                               \
        a41 = vfmaq_laneq_f32(a41, w1, p4, l);                                                               \
        a50 = vfmaq_laneq_f32(a50, w0, p5, l);                                                               \
        a51 = vfmaq_laneq_f32(a51, w1, p5, l);                                                               \
        a60 = vfmaq_laneq_f32(a60, w0, p6, l);                                                               \
        a61 = vfmaq_laneq_f32(a61, w1, p6, l);                                                               \
        a70 = vfmaq_laneq_f32(a70, w0, p7, l);                                                               \
        a71 = vfmaq_laneq_f32(a71, w1, p7, l);                                                               \
    } while (0)

/* input i + l of the 8 rows into the 8 x 4 tile (weight vector w0) */
#define TILE8x4_LANE(l)                                                                                      \
    do                                                                                                       \
    {                                                                                                        \
        const float32x4_t w0 = vld1q_f32(w);                                                                 \
        w += n_out;                                                                                          \
        a0 = vfmaq_laneq_f32(a0, w0, p0, l);                                                                 \
        a1 = vfmaq_laneq_f32(a1, w0, p1, l);                                                                 \
        a2 = vfmaq_laneq_f32(a2, w0, p2, l);                                                                 \
        a3 = vfmaq_laneq_f32(a3, w0, p3, l);                                                                 \
        a4 = vfmaq_laneq_f32(a4, w0, p4, l);                                                                 \
        a5 = vfmaq_laneq_f32(a5, w0, p5, l);                                                                 \
        a6 = vfmaq_laneq_f32(a6, w0, p6, l);                                                                 \
        a7 = vfmaq_laneq_f32(a7, w0, p7, l);                                                                 \
    } while (0)

static void band8(const float *x, uint32_t n_in, const float *w_t, const float *b, uint32_t n_out, int relu,
                  float *o)
{
    const float *x0 = x, *x1 = x + n_in, *x2 = x1 + n_in, *x3 = x2 + n_in;
    const float *x4 = x3 + n_in, *x5 = x4 + n_in, *x6 = x5 + n_in, *x7 = x6 + n_in;
    uint32_t k = 0, i, r;
    for (; k + 8u <= n_out; k += 8u)
    {
        const float32x4_t b0 = vld1q_f32(b + k), b1 = vld1q_f32(b + k + 4u);
        float32x4_t a00 = b0, a01 = b1, a10 = b0, a11 = b1, a20 = b0, a21 = b1, a30 = b0, a31 = b1;
        float32x4_t a40 = b0, a41 = b1, a50 = b0, a51 = b1, a60 = b0, a61 = b1, a70 = b0, a71 = b1;
        const float *w = w_t + k;
        for (i = 0; i + 4u <= n_in; i += 4u)
        {
            LOAD_X(0);
            LOAD_X(1);
            LOAD_X(2);
            LOAD_X(3);
            LOAD_X(4);
            LOAD_X(5);
            LOAD_X(6);
            LOAD_X(7);
            TILE8x8_LANE(0);
            TILE8x8_LANE(1);
            TILE8x8_LANE(2);
            TILE8x8_LANE(3);
        }
        for (; i < n_in; ++i)
        {
            const float32x4_t w0 = vld1q_f32(w), w1 = vld1q_f32(w + 4);
            w += n_out;
            a00 = vfmaq_n_f32(a00, w0, x0[i]);
            a01 = vfmaq_n_f32(a01, w1, x0[i]);
            a10 = vfmaq_n_f32(a10, w0, x1[i]);
            a11 = vfmaq_n_f32(a11, w1, x1[i]);
            a20 = vfmaq_n_f32(a20, w0, x2[i]);
            a21 = vfmaq_n_f32(a21, w1, x2[i]);
            a30 = vfmaq_n_f32(a30, w0, x3[i]);
            a31 = vfmaq_n_f32(a31, w1, x3[i]);
            a40 = vfmaq_n_f32(a40, w0, x4[i]);
            a41 = vfmaq_n_f32(a41, w1, x4[i]);
            a50 = vfmaq_n_f32(a50, w0, x5[i]);
            a51 = vfmaq_n_f32(a51, w1, x5[i]);
            a60 = vfmaq_n_f32(a60, w0, x6[i]);
            a61 = vfmaq_n_f32(a61, w1, x6[i]);
            a70 = vfmaq_n_f32(a70, w0, x7[i]);
            a71 = vfmaq_n_f32(a71, w1, x7[i]);
        }
        vst1q_f32(o + k, relu4(a00, relu));
        vst1q_f32(o + k + 4u, relu4(a01, relu));
        vst1q_f32(o + n_out + k, relu4(a10, relu));
        vst1q_f32(o + n_out + k + 4u, relu4(a11, relu));
        vst1q_f32(o + 2u * n_out + k, relu4(a20, relu));
        vst1q_f32(o + 2u * n_out + k + 4u, relu4(a21, relu));
        vst1q_f32(o + 3u * n_out + k, relu4(a30, relu));
        vst1q_f32(o + 3u * n_out + k + 4u, relu4(a31, relu));
        vst1q_f32(o + 4u * n_out + k, relu4(a40, relu));
        vst1q_f32(o + 4u * n_out + k + 4u, relu4(a41, relu));
        vst1q_f32(o + 5u * n_out + k, relu4(a50, relu));
        vst1q_f32(o + 5u * n_out + k + 4u, relu4(a51, relu));
        vst1q_f32(o + 6u * n_out + k, relu4(a60, relu));
        vst1q_f32(o + 6u * n_out + k + 4u, relu4(a61, relu));
        vst1q_f32(o + 7u * n_out + k, relu4(a70, relu));
        vst1q_f32(o + 7u * n_out + k + 4u, relu4(a71, relu));
    }
    if (k + 4u <= n_out)
    {
        const float32x4_t bb = vld1q_f32(b + k);
        float32x4_t a0 = bb, a1 = bb, a2 = bb, a3 = bb, a4 = bb, a5 = bb, a6 = bb, a7 = bb;
        const float *w = w_t + k;
        for (i = 0; i + 4u <= n_in; i += 4u)
        {
            LOAD_X(0);
            LOAD_X(1);
            LOAD_X(2);
            LOAD_X(3);
            LOAD_X(4);
            LOAD_X(5);
            LOAD_X(6);
            LOAD_X(7);
            TILE8x4_LANE(0);
            TILE8x4_LANE(1);
            TILE8x4_LANE(2);
            TILE8x4_LANE(3);
        }
        for (; i < n_in; ++i)
        {
            const float32x4_t w0 = vld1q_f32(w);
            w += n_out;
            a0 = vfmaq_n_f32(a0, w0, x0[i]);
            a1 = vfmaq_n_f32(a1, w0, x1[i]);
            a2 = vfmaq_n_f32(a2, w0, x2[i]);
            a3 = vfmaq_n_f32(a3, w0, x3[i]);
            a4 = vfmaq_n_f32(a4, w0, x4[i]);
            a5 = vfmaq_n_f32(a5, w0, x5[i]);
            a6 = vfmaq_n_f32(a6, w0, x6[i]);
            a7 = vfmaq_n_f32(a7, w0, x7[i]);
        }
        vst1q_f32(o + k, relu4(a0, relu));
        vst1q_f32(o + n_out + k, relu4(a1, relu));
        vst1q_f32(o + 2u * n_out + k, relu4(a2, relu));
        vst1q_f32(o + 3u * n_out + k, relu4(a3, relu));
        vst1q_f32(o + 4u * n_out + k, relu4(a4, relu));
        vst1q_f32(o + 5u * n_out + k, relu4(a5, relu));
        vst1q_f32(o + 6u * n_out + k, relu4(a6, relu));
        vst1q_f32(o + 7u * n_out + k, relu4(a7, relu));
        k += 4u;
    }
    if (k < n_out)
    {
        /* the last 1-3 outputs, row by row (the same chains) */
        for (r = 0; r < 8u; ++r)
        {
            row_from(x + r * n_in, n_in, w_t, b, n_out, relu, o + r * n_out, k);
        }
    }
}

void lidet__nn_dense_f32(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                         uint32_t n_out, int relu, float *out)
{
    uint32_t r = 0;
    for (; r + 8u <= n_rows; r += 8u)
    {
        band8(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out);
    }
    for (; r < n_rows; ++r)
    {
        row_from(in + (size_t)r * n_in, n_in, w_t, b, n_out, relu, out + (size_t)r * n_out, 0u);
    }
}

#else
typedef int lidet__nn_f32_neon_empty; /* ISO C: a translation unit holds at least one declaration */
#endif
