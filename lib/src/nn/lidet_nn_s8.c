/* SPDX-License-Identifier: MIT */
/* Portable int8 dense kernels of the integer PointNets (internal/lidet_pointnet_q_internal.h); reference:
 * codegen/lidet_codegen/ref/pointnet_q.py (dense_acc, requant). Plain C99, integers only: int8 x int8 (or
 * int16 x int8) products summed in int32 (one 32-bit multiply-add per weight on a Cortex-M0+), one 64-bit
 * requantization per output value. Weights [in][out] as the float kernel: the innermost loop runs over the
 * output channels of one weight row (unit stride; compilers vectorise it on hosts). */
#include "internal/lidet_pointnet_q_internal.h"
#include "internal/lidet_qmath.h"

void lidet__nn_acc_s8(const int8_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t, const int32_t *b,
                      uint32_t n_out, int32_t *acc)
{
    uint32_t r, i, o;
    for (r = 0; r < n_rows; ++r)
    {
        int32_t *a = acc + r * n_out;
        const int8_t *x = in + r * n_in;
        for (o = 0; o < n_out; ++o)
        {
            a[o] = b[o];
        }
        for (i = 0; i + 2u <= n_in; i += 2u)
        {
            const int32_t x0 = x[i], x1 = x[i + 1u];
            const int8_t *w0 = w_t + i * n_out;
            const int8_t *w1 = w0 + n_out;
            for (o = 0; o < n_out; ++o)
            {
                a[o] += x0 * (int32_t)w0[o] + x1 * (int32_t)w1[o];
            }
        }
        for (; i < n_in; ++i)
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

void lidet__nn_acc_s16(const int16_t *in, uint32_t n_rows, uint32_t n_in, const int8_t *w_t, const int32_t *b,
                       uint32_t n_out, int32_t *acc)
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

void lidet__nn_requant_s8(const int32_t *acc, uint32_t n_rows, uint32_t n_out, const int32_t *mult,
                          const uint8_t *shift, int32_t zp, int32_t lo, int8_t *out)
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

void lidet__nn_max_rows_s32(const int32_t *acc, uint32_t n_rows, uint32_t n, int32_t *vmax)
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
