/* SPDX-License-Identifier: MIT */
/* The float dense kernel (internal/lidet_nn.h) on RISC-V cores with the F extension (RV32F, RV64F; GCC or clang):
 * fused multiply-adds (fmadd.s). Compiled where LIDET_NN_F32_RV is 1 (internal/lidet_nn.h: a RISC-V target with
 * single-precision floats in registers, lidet_opt.h's LIDET_NN_RV_FMA, 1 by default there); an empty unit elsewhere.
 * The portable kernel (lidet_nn_f32.c) stays, as lidet__nn_dense_f32_portable, the tests' oracle.
 *
 * Arithmetic (the contract of the x86-64 FMA kernel, lidet_nn_f32_x86.c, and of the aarch64 and Cortex-M7 ones): each
 * output is o = b, then o = fma(in[i], w[i], o) for i = 0 .. n_in - 1 in order (one rounding per multiply-add), then
 * the ReLU (v > 0 ? v : +0: NaN and -0 give +0). So a RISC-V board gives the dense layers' bits of an x86-64 host with
 * FMA; against the portable kernel, which rounds the products and sums four at a time, the last bits differ, within
 * the float tolerances of the tests. Zero inputs of ReLU layers are skipped: fma(+-0, w, v) = v for every v but a
 * zero, a zero for a zero, and the ReLU maps both zeros to +0, so the outputs are the unskipped chain's bit for bit
 * (lidet_nn_f32_cm.c says it at length).
 *
 * Shape: one row (point) at a time. Its inputs (in a ReLU layer its nonzero ones), RV_CHUNK at a time, are gathered
 * in order as (value, weight row) pairs; the outputs are swept 16 at a time with 16 accumulators in registers over
 * the gathered inputs (one flw of the value, 16 flw of the weights and 16 fmadd.s per input), the running sums in the
 * row between chunks, the ReLU at the last chunk; then 8 at a time, and the outputs past the last multiple of 8 (the
 * heads' 3 and 39) the same chain one at a time. The fused arithmetic costs no more cycles than a multiply on the
 * RISC-V cores with F that pipeline their floating-point unit, and saves the separate add. */
#include "internal/lidet_nn.h"

/* NN_F32_RV_HOST_TEST: tests/unit/test_nn_f32.c compiles this file into the host test under another name (plain C:
 * its logic is checked bit for bit on every host; the RISC-V images run it for real) */
#if LIDET_NN_F32_RV || defined(NN_F32_RV_HOST_TEST)
#include <math.h>

#include "internal/lidet_nn_skip.h"

/* inputs gathered at a time (stack: RV_CHUNK values and pointers) */
#define RV_CHUNK 64u

static inline float rv_relu(float v, int relu)
{
    return relu && !(v > 0.0f) ? 0.0f : v;
}

/* 8 running sums p0..p7 of outputs k + off .. k + off + 7 from src, the products of one input added, stored */
#define RV_LOAD8(p, off)                                                                                     \
    float p##0 = src[k + (off)], p##1 = src[k + (off) + 1u], p##2 = src[k + (off) + 2u],                     \
          p##3 = src[k + (off) + 3u], p##4 = src[k + (off) + 4u], p##5 = src[k + (off) + 5u],                \
          p##6 = src[k + (off) + 6u], p##7 = src[k + (off) + 7u]
#define RV_FMA8(p, off)                                                                                      \
    do                                                                                                       \
    {                                                                                                        \
        p##0 = fmaf(x, w[(off)], p##0);                                                                      \
        p##1 = fmaf(x, w[(off) + 1], p##1);                                                                  \
        p##2 = fmaf(x, w[(off) + 2], p##2);                                                                  \
        p##3 = fmaf(x, w[(off) + 3], p##3);                                                                  \
        p##4 = fmaf(x, w[(off) + 4], p##4);                                                                  \
        p##5 = fmaf(x, w[(off) + 5], p##5);                                                                  \
        p##6 = fmaf(x, w[(off) + 6], p##6);                                                                  \
        p##7 = fmaf(x, w[(off) + 7], p##7);                                                                  \
    } while (0)
#define RV_STORE8(p, off)                                                                                    \
    do                                                                                                       \
    {                                                                                                        \
        o[k + (off)] = rv_relu(p##0, relu);                                                                  \
        o[k + (off) + 1u] = rv_relu(p##1, relu);                                                             \
        o[k + (off) + 2u] = rv_relu(p##2, relu);                                                             \
        o[k + (off) + 3u] = rv_relu(p##3, relu);                                                             \
        o[k + (off) + 4u] = rv_relu(p##4, relu);                                                             \
        o[k + (off) + 5u] = rv_relu(p##5, relu);                                                             \
        o[k + (off) + 6u] = rv_relu(p##6, relu);                                                             \
        o[k + (off) + 7u] = rv_relu(p##7, relu);                                                             \
    } while (0)

/* o[k] = the chain over the c gathered inputs from src[k], the ReLU where relu: 16 outputs at a time (16 of the 32
 * float registers hold the sums, so each input's value and weight row pointer are loaded once per 16 outputs), then
 * 8, then one by one */
static void rv_sweep(const float *xv, const float *const *wv, uint32_t c, const float *src, float *o,
                     uint32_t n_out, int relu)
{
    uint32_t k = 0, j;
    for (; k + 16u <= n_out; k += 16u)
    {
        RV_LOAD8(a, 0u);
        RV_LOAD8(b, 8u);
        for (j = 0; j < c; ++j)
        {
            const float x = xv[j];
            const float *w = wv[j] + k;
            RV_FMA8(a, 0);
            RV_FMA8(b, 8);
        }
        RV_STORE8(a, 0u);
        RV_STORE8(b, 8u);
    }
    for (; k + 8u <= n_out; k += 8u)
    {
        RV_LOAD8(a, 0u);
        for (j = 0; j < c; ++j)
        {
            const float x = xv[j];
            const float *w = wv[j] + k;
            RV_FMA8(a, 0);
        }
        RV_STORE8(a, 0u);
    }
    for (; k < n_out; ++k)
    {
        float a = src[k];
        for (j = 0; j < c; ++j)
        {
            a = fmaf(xv[j], wv[j][k], a);
        }
        o[k] = rv_relu(a, relu);
    }
}

void lidet__nn_dense_f32(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                         uint32_t n_out, int relu, float *out)
{
    float xv[RV_CHUNK];
    const float *wv[RV_CHUNK];
    uint32_t r, i;
    for (r = 0; r < n_rows; ++r)
    {
        const float *x = in + (size_t)r * n_in;
        float *o = out + (size_t)r * n_out;
        const float *src = b;
        /* past the last nonzero input nothing is added: the ReLU goes with the last sweep */
        const uint32_t last = lidet__nn_inputs_used(x, n_in, relu);
        i = 0;
        do
        {
            uint32_t c = 0;
            for (; i < last && c < RV_CHUNK; ++i)
            {
                if (!relu || !lidet__nn_is_zero(x[i]))
                {
                    xv[c] = x[i];
                    wv[c] = w_t + (size_t)i * n_out;
                    ++c;
                }
            }
            /* the first sweep starts from the bias (also a row of no nonzero input), the others from the row */
            rv_sweep(xv, wv, c, src, o, n_out, relu && i >= last);
            src = o;
        } while (i < last);
    }
}

#else
typedef int lidet__nn_f32_rv_empty; /* ISO C: a translation unit holds at least one declaration */
#endif
