/* SPDX-License-Identifier: MIT */
/* Portable int8 dense kernels of the integer PointNets (internal/lidet_pointnet_q_internal.h); reference:
 * codegen/lidet_codegen/ref/pointnet_q.py (dense_acc, requant). Plain C99, integers only: int8 x int8 (or
 * int16 x int8) products summed in int32 (one 32-bit multiply-add per weight on a Cortex-M0+), one 64-bit
 * requantization per output value. Weights [in][out] as the float kernel: the innermost loop runs over the
 * output channels of one weight row (unit stride; compilers vectorise it on hosts, and x86-64 host builds also
 * get an AVX2 variant, LIDET_NN_KERNEL: integer sums are exact, so every variant gives the same bits). */
#include "internal/lidet_q_gpr.h" /* first: no FPU register for 64-bit integers */
#include "internal/lidet_nn.h"
#include "internal/lidet_pointnet_q_internal.h"
#include "internal/lidet_qmath.h"

/* rows r..r+3 of acc += in rows * W: four rows share each weight load */
static inline void rows4_s8(const int8_t *x, uint32_t n_in, const int8_t *w_t, uint32_t n_out, int32_t *restrict a0)
{
    int32_t *restrict a1 = a0 + n_out;
    int32_t *restrict a2 = a1 + n_out;
    int32_t *restrict a3 = a2 + n_out;
    uint32_t i, o;
    for (i = 0; i < n_in; ++i)
    {
        const int8_t *restrict w = w_t + i * n_out;
        const int32_t x0 = x[i], x1 = x[n_in + i], x2 = x[2u * n_in + i], x3 = x[3u * n_in + i];
        for (o = 0; o < n_out; ++o)
        {
            const int32_t wv = w[o];
            a0[o] += x0 * wv;
            a1[o] += x1 * wv;
            a2[o] += x2 * wv;
            a3[o] += x3 * wv;
        }
    }
}

LIDET_NN_KERNEL void lidet__nn_acc_s8(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                                      const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
    for (r = 0; r < n_rows; ++r)
    {
        for (o = 0; o < n_out; ++o)
        {
            acc[r * n_out + o] = b[o];
        }
    }
    for (r = 0; r + 4u <= n_rows; r += 4u)
    {
        rows4_s8(in + r * n_in, n_in, w_t, n_out, acc + r * n_out);
    }
    for (; r < n_rows; ++r)
    {
        int32_t *a = acc + r * n_out;
        const int8_t *x = in + r * n_in;
        for (i = 0; i < n_in; ++i)
        {
            const int32_t x0 = x[i];
            const int8_t *w0 = w_t + i * n_out;
            for (o = 0; o < n_out; ++o)
            {
                a[o] += x0 * (int32_t)w0[o];
            }
        }
    }
}

LIDET_NN_KERNEL void lidet__nn_acc_s16(const int16_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t,
                                       const int32_t *b, uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
    for (r = 0; r < n_rows; ++r)
    {
        int32_t *a = acc + r * n_out;
        const int16_t *x = in + r * n_in;
        for (o = 0; o < n_out; ++o)
        {
            a[o] = b[o];
        }
        for (i = 0; i < n_in; ++i)
        {
            const int32_t x0 = x[i];
            const int8_t *w0 = w_t + i * n_out;
            for (o = 0; o < n_out; ++o)
            {
                a[o] += x0 * (int32_t)w0[o];
            }
        }
    }
}

LIDET_NN_KERNEL void lidet__nn_requant_s8(const int32_t *acc, uint32_t n_rows, uint32_t n_out,
                                          const int32_t *mult, const uint8_t *shift, int32_t zp, int32_t lo,
                                          int8_t *out)
{
    uint32_t r, o;
    for (r = 0; r < n_rows; ++r)
    {
        for (o = 0; o < n_out; ++o)
        {
            int64_t v = lidet__q_rshift_round((int64_t)acc[r * n_out + o] * mult[o], shift[o]) + zp;
            v = v < lo ? lo : (v > 127 ? 127 : v);
            out[r * n_out + o] = (int8_t)v;
        }
    }
}

void lidet__nn_requant_q16(const int32_t *acc, uint32_t n_out, const int32_t *mult, const uint8_t *shift,
                           int32_t *out)
{
    uint32_t o;
    for (o = 0; o < n_out; ++o)
    {
        const int64_t v = lidet__q_rshift_round((int64_t)acc[o] * mult[o], shift[o]);
        out[o] = v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : (int32_t)v);
    }
}

LIDET_NN_KERNEL void lidet__nn_max_rows_s32(const int32_t *acc, uint32_t n_rows, uint32_t n, int32_t *vmax)
{
    uint32_t r, o;
    for (r = 0; r < n_rows; ++r)
    {
        const int32_t *a = acc + r * n;
        for (o = 0; o < n; ++o)
        {
            vmax[o] = a[o] > vmax[o] ? a[o] : vmax[o];
        }
    }
}
