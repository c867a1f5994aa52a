/* SPDX-License-Identifier: MIT */
/* The int8 accumulation kernels (lib/src/nn/lidet_nn_s8.c): the host kernel, the output-inner loop and the 2 x 2
 * and 4 x 2 register-blocked kernels and the list kernel give the same int32 sums on every shape, odd row and channel counts included, and
 * equal a plain triple loop; the extreme int8 values too. */
#include <string.h>

#include "internal/lidet_pointnet_q_internal.h"
#include "internal/lidet_qmath.h"
#include "test_util.h"

#define MAX_R 11
#define MAX_I 140
#define MAX_O 37

static uint32_t g_rng = 12345u;

static uint32_t next(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return g_rng;
}

void setUp(void)
{
}

void tearDown(void)
{
}

/* the exact int32 sums, point by point: b[o] + sum_i in[r][i] w[i][o] */
static void ref_acc(const int8_t *in, uint32_t rows, uint32_t n_in, const int8_t *w, const int32_t *b, uint32_t n_out,
                    int32_t *ref)
{
    uint32_t r, o, i;
    for (r = 0; r < rows; ++r)
        for (o = 0; o < n_out; ++o)
        {
            int32_t s = b[o];
            for (i = 0; i < n_in; ++i)
                s += (int32_t)in[r * n_in + i] * (int32_t)w[i * n_out + o];
            ref[r * n_out + o] = s;
        }
}

/* b - 128 sum_i w[i][o]: the list kernel's starting sums (lidet_pointnet_q_layer_t.b_list) */
static void list_bias_of(const int8_t *w, uint32_t n_in, const int32_t *b, uint32_t n_out, int32_t *b_list)
{
    uint32_t i, o;
    for (o = 0; o < n_out; ++o)
    {
        b_list[o] = b[o];
        for (i = 0; i < n_in; ++i)
            b_list[o] -= 128 * (int32_t)w[i * n_out + o];
    }
}

static void check_shape(uint32_t rows, uint32_t n_in, uint32_t n_out, int extreme)
{
    static int8_t in[MAX_R * MAX_I], w[MAX_I * MAX_O];
    static uint32_t w_pk[MAX_I * MAX_O / 2u + 1u];
    static int32_t b[MAX_O], b_list[MAX_O], ref[MAX_R * MAX_O], got[MAX_R * MAX_O], vmax[MAX_O], refmax[MAX_O];
    uint32_t r, o, k;
    for (k = 0; k < rows * n_in; ++k)
    {
        in[k] = extreme == 1 ? (int8_t)((k & 1u) ? -128 : 127) : (int8_t)(next() & 0xFFu);
        if (extreme == 2 && next() % 5u < 3u) /* a ReLU layer's output: most inputs at its zero point */
            in[k] = -128;
        if (extreme == 3) /* every input at the zero point: nothing left to add */
            in[k] = -128;
    }
    for (k = 0; k < n_in * n_out; ++k)
        w[k] = extreme == 1 ? (int8_t)-128 : (int8_t)(next() & 0xFFu);
    for (o = 0; o < n_out; ++o)
        b[o] = (int32_t)(next() % 2000001u) - 1000000;
    ref_acc(in, rows, n_in, w, b, n_out, ref);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_cols(in, rows, n_in, w, b, n_out, n_out, got, n_out);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_skip(in, rows, n_in, w, b, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_rows4(in, rows, n_in, w, b, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_r2o2(in, rows, n_in, w, b, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_r4o2(in, rows, n_in, w, b, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_list(in, rows, n_in, w, b, 0, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    /* with the starting sums given (b_list: b - 128 sum w, as the generated models carry them) */
    list_bias_of(w, n_in, b, n_out, b_list);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_list(in, rows, n_in, w, b, b_list, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    /* the list kernel folding its rows into a running maximum (4 rows or more on the host), acc its scratch; with
     * and without b_list */
    for (k = 0; k < 2u; ++k)
    {
        for (o = 0; o < n_out; ++o)
        {
            vmax[o] = refmax[o] = (int32_t)(next() % 4000001u) - 2000000;
            for (r = 0; r < rows; ++r)
                refmax[o] = ref[r * n_out + o] > refmax[o] ? ref[r * n_out + o] : refmax[o];
        }
        memset(got, 0x5A, sizeof got);
        if (lidet__nn_acc_s8_list_max(in, rows, n_in, w, b, k ? b_list : 0, n_out, got, vmax))
            TEST_ASSERT_EQUAL_INT32_ARRAY(refmax, vmax, n_out);
        else
            TEST_ASSERT_TRUE(rows < 4u);
    }
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_dsp(in, rows, n_in, w, b, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8(in, rows, n_in, w, b, 0, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
    /* the packed DSP kernel (n_in not a multiple of 4: it takes w_t, never reading w_pk) */
    memset(w_pk, 0xA5, sizeof w_pk);
    if (n_in % 4u == 0u)
        lidet__nn_pack_s8_pk(w, n_in, n_out, w_pk);
    memset(got, 0x5A, sizeof got);
    lidet__nn_acc_s8_pk(in, rows, n_in, w_pk, w, b, n_out, got);
    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
}

/* the cores without a 32 x 32 -> 64 multiply (ARMv6-M) take these from 16-bit halves: exact against int64 on the
 * corners of the ranges and on random operands */
static void test_split_multiplies_are_exact(void)
{
    static const int32_t edge[] = {0, 1, -1, 2, -2, 65535, 65536, -65536, -65537, 32767, -32768, 0x7FFFFFFF,
                                   -0x7FFFFFFF - 1, 0x40000000, -0x40000000, 123456789, -987654321};
    const uint32_t ne = (uint32_t)(sizeof edge / sizeof edge[0]);
    uint32_t i, j, k;
    for (i = 0; i < ne; ++i)
        for (j = 0; j < ne; ++j)
        {
            const int32_t a = edge[i], b = edge[j];
            TEST_ASSERT_EQUAL_INT32((int32_t)(((int64_t)a * b) >> 32), lidet__q_smulhi32_split(a, b));
            TEST_ASSERT_TRUE((uint64_t)(uint32_t)a * (uint32_t)b == lidet__q_umul32_split((uint32_t)a, (uint32_t)b));
        }
    /* the short form on its whole range of a (|a| <= 2^15) against the corners of b and random b */
    for (k = 0; k <= 65536u; ++k)
    {
        const int32_t a = (int32_t)k - 32768;
        for (j = 0; j < ne; ++j)
        {
            TEST_ASSERT_EQUAL_INT32((int32_t)(((int64_t)a * edge[j]) >> 32), lidet__q_smulhi32_short(a, edge[j]));
        }
        {
            const int32_t b = (int32_t)(next() ^ (next() << 16));
            TEST_ASSERT_EQUAL_INT32((int32_t)(((int64_t)a * b) >> 32), lidet__q_smulhi32_short(a, b));
        }
    }
    for (k = 0; k < 200000u; ++k)
    {
        const uint32_t ua = next() ^ (next() << 16), ub = next() ^ (next() << 16);
        const int32_t a = (int32_t)ua >> (k % 17u), b = (int32_t)ub >> (k % 13u);
        TEST_ASSERT_EQUAL_INT32((int32_t)(((int64_t)a * b) >> 32), lidet__q_smulhi32_split(a, b));
        TEST_ASSERT_TRUE((uint64_t)ua * ub == lidet__q_umul32_split(ua, ub));
    }
}

/* the PointNets' rotation into the model frame on those cores: round((c x + s y) / 2^28) from 15-bit halves of
 * c and s, exact against the int64 sum wherever |ch| + |sh| <= 65000 (every rotation of a Q30 unit vector, and
 * beyond), on the corners of the int16 inputs and on random operands */
static void check_dot2(int32_t c, int32_t s, int32_t x, int32_t y)
{
    const int32_t ch = (int32_t)(((int64_t)c + (1 << 14)) >> 15), sh = (int32_t)(((int64_t)s + (1 << 14)) >> 15);
    const int32_t cl = c - (int32_t)((uint32_t)ch << 15), sl = s - (int32_t)((uint32_t)sh << 15);
    const int64_t ref = lidet__q_rshift_round((int64_t)c * x + (int64_t)s * y, 28);
    TEST_ASSERT_TRUE(cl >= -16384 && cl < 16384 && sl >= -16384 && sl < 16384);
    if ((ch < 0 ? -ch : ch) + (sh < 0 ? -sh : sh) > 65000)
        return;
    TEST_ASSERT_EQUAL_INT64(ref, lidet__q_dot2_r28_split(ch, cl, sh, sl, x, y));
}

static void test_rotation_split_is_exact(void)
{
    static const int32_t cs[] = {0, 1, -1, 1 << 30, -(1 << 30), 759250125, -759250125, 16383, 16384, -16385,
                                 1065000000, -1065000000, 2129000000, -2129000000};
    static const int32_t xy[] = {0, 1, -1, 32767, -32768, 16384, -16383, 255, -1000};
    const uint32_t nc = (uint32_t)(sizeof cs / sizeof cs[0]), nx = (uint32_t)(sizeof xy / sizeof xy[0]);
    uint32_t a, b, i, j, k, checked = 0;
    for (a = 0; a < nc; ++a)
        for (b = 0; b < nc; ++b)
            for (i = 0; i < nx; ++i)
                for (j = 0; j < nx; ++j)
                    check_dot2(cs[a], cs[b], xy[i], xy[j]);
    for (k = 0; k < 300000u; ++k)
    {
        /* a unit vector at a random angle (as the frame's cos, sin), scaled by up to 1.4, and any int16 point */
        const uint32_t t = next() ^ (next() << 16);
        const int32_t scale = 65536 + (int32_t)(next() % 26000u);
        const int32_t c = (int32_t)(((int64_t)lidet__q_cos(t) * scale) >> 16);
        const int32_t s = (int32_t)(((int64_t)lidet__q_sin(t) * scale) >> 16);
        const int32_t x = (int32_t)(int16_t)next(), y = (int32_t)(int16_t)next();
        const int32_t ch = (c + (1 << 14)) >> 15, sh = (s + (1 << 14)) >> 15;
        check_dot2(c, s, x, y);
        checked += (ch < 0 ? -ch : ch) + (sh < 0 ? -sh : sh) <= 65000;
    }
    TEST_ASSERT_TRUE(checked > 290000u); /* the bound leaves out none of these but the largest scales */
}

/* the sine table's interpolation on those cores: every step of the table against every 61st fraction and the
 * fractions' ends, exact against the int64 product */
static void test_sine_interpolation_split_is_exact(void)
{
    uint32_t i, f;
    for (i = 0; i < LIDET_Q_SIN_STEPS; ++i)
    {
        const int32_t d = lidet__q_sin_q30[i + 1] - lidet__q_sin_q30[i];
        TEST_ASSERT_TRUE(d >= 0 && d < (1 << 21));
        for (f = 0; f < (1u << 20); f += f < 2048u || f > (1u << 20) - 2048u ? 1u : 61u)
            TEST_ASSERT_EQUAL_INT64(lidet__q_rshift_round((int64_t)d * f, 20), lidet__q_mul_r20_split(d, f));
    }
}

static void test_kernels_agree_on_every_shape(void)
{
    uint32_t rows, n_in, n_out;
    for (rows = 1; rows <= MAX_R; ++rows)
        for (n_in = 1; n_in <= MAX_I; n_in += 7u)
            for (n_out = 1; n_out <= MAX_O; n_out += 3u)
            {
                check_shape(rows, n_in, n_out, 0);
                check_shape(rows, n_in, n_out, 2); /* 3 in 5 inputs at -128: the skipped products */
                if (n_in % 3u == 1u)
                    check_shape(rows, n_in, n_out, 3); /* all at -128 */
            }
}

/* the packed kernel's cases: one group, several, exactly one 64-input pass, two and three passes */
static void test_packed_kernel_on_multiples_of_4(void)
{
    static const uint32_t n_ins[] = {4u, 12u, 64u, 68u, 136u};
    uint32_t rows, k, n_out;
    for (k = 0; k < sizeof n_ins / sizeof n_ins[0]; ++k)
        for (rows = 1; rows <= MAX_R; ++rows)
            for (n_out = 1; n_out <= MAX_O; n_out += 4u)
                check_shape(rows, n_ins[k], n_out, 0);
}

/* the fused pass (requantized, or folded into a running maximum) equals the accumulation followed by
 * lidet__nn_requant_s8 or lidet__nn_max_rows_s32, on every row count, both shift paths and both clamps; and it
 * declines (touching nothing) where it does not apply */
static void test_fused_pass_equals_acc_then_requant_or_max(void)
{
    static int8_t in[MAX_R * 64], w[64 * 32], out[MAX_R * 32], ref8[MAX_R * 32];
    static uint32_t w_pk[64 * 32 / 2];
    static int32_t b[32], acc[MAX_R * 32], mult[32], vmax[32], refmax[32];
    static uint8_t shift[32];
    static const uint32_t n_ins[] = {4u, 16u, 48u, 64u};
    uint32_t k, rows, n_out, i, rep;
    for (rep = 0; rep < 8u; ++rep)
        for (k = 0; k < sizeof n_ins / sizeof n_ins[0]; ++k)
            for (rows = 1; rows <= MAX_R; ++rows)
                for (n_out = 2; n_out <= 32u; n_out += 10u)
                {
                    const uint32_t n_in = n_ins[k];
                    const int32_t zp = rep & 1u ? -128 : 0, lo = rep & 2u ? zp : -128;
                    for (i = 0; i < rows * n_in; ++i)
                        in[i] = (int8_t)(next() & 0xFFu);
                    for (i = 0; i < n_in * n_out; ++i)
                        w[i] = (int8_t)(next() & 0xFFu);
                    for (i = 0; i < n_out; ++i)
                    {
                        b[i] = (int32_t)(next() % 200001u) - 100000;
                        mult[i] = (int32_t)(((uint32_t)1 << 30) | (next() & 0x3FFFFFFFu));
                        /* 20..62: every path; or all in [33, 48], the fast requantization where lo is -128 */
                        shift[i] = (uint8_t)(rep & 4u ? 33u + next() % 16u : 20u + next() % 43u);
                        refmax[i] = vmax[i] = (int32_t)(next() % 2000001u) - 1000000;
                    }
                    lidet__nn_pack_s8_pk(w, n_in, n_out, w_pk);
                    lidet__nn_acc_s8(in, rows, n_in, w, b, 0, n_out, acc);
                    lidet__nn_requant_s8(acc, rows, n_out, mult, shift, zp, lo, ref8);
                    lidet__nn_max_rows_s32(acc, rows, n_out, refmax);
                    memset(out, 0x5A, sizeof out);
                    TEST_ASSERT_EQUAL_INT(1, lidet__nn_acc_s8_pk_fused(in, rows, n_in, w_pk, b, n_out, mult, shift,
                                                                       zp, lo, out, 0));
                    TEST_ASSERT_EQUAL_INT8_ARRAY(ref8, out, rows * n_out);
                    TEST_ASSERT_EQUAL_INT(1, lidet__nn_acc_s8_pk_fused(in, rows, n_in, w_pk, b, n_out, mult, shift,
                                                                       zp, lo, 0, vmax));
                    TEST_ASSERT_EQUAL_INT32_ARRAY(refmax, vmax, n_out);
                }
    /* declined: odd n_out, n_in not a multiple of 4 or above 64, no weights, neither or both outputs */
    memset(out, 0x5A, sizeof out);
    TEST_ASSERT_EQUAL_INT(0, lidet__nn_acc_s8_pk_fused(in, 2u, 16u, w_pk, b, 3u, mult, shift, 0, -128, out, 0));
    TEST_ASSERT_EQUAL_INT(0, lidet__nn_acc_s8_pk_fused(in, 2u, 18u, w_pk, b, 4u, mult, shift, 0, -128, out, 0));
    TEST_ASSERT_EQUAL_INT(0, lidet__nn_acc_s8_pk_fused(in, 2u, 68u, w_pk, b, 4u, mult, shift, 0, -128, out, 0));
    TEST_ASSERT_EQUAL_INT(0, lidet__nn_acc_s8_pk_fused(in, 2u, 16u, 0, b, 4u, mult, shift, 0, -128, out, 0));
    TEST_ASSERT_EQUAL_INT(0, lidet__nn_acc_s8_pk_fused(in, 2u, 16u, w_pk, b, 4u, mult, shift, 0, -128, 0, 0));
    TEST_ASSERT_EQUAL_INT(0, lidet__nn_acc_s8_pk_fused(in, 2u, 16u, w_pk, b, 4u, mult, shift, 0, -128, out, vmax));
    for (i = 0; i < sizeof out; ++i)
        TEST_ASSERT_EQUAL_INT8((int8_t)0x5A, out[i]);
}

/* the first layer in one pass equals lidet__nn_acc_s16 + lidet__nn_requant_s8 (x, y, z up to the int16 limits) */
static void test_first_layer_in_one_pass(void)
{
    static int16_t in[MAX_R * 3];
    static int8_t w[3 * 40], out[MAX_R * 40], ref8[MAX_R * 40];
    static int32_t b[40], acc[MAX_R * 40], mult[40];
    static uint8_t shift[40];
    uint32_t rows, n_out, i, rep;
    for (rep = 0; rep < 8u; ++rep)
        for (rows = 1; rows <= MAX_R; ++rows)
            for (n_out = 1; n_out <= 40u; n_out += 13u)
            {
                const int32_t zp = rep & 1u ? -128 : 0, lo = rep & 2u ? zp : -128;
                for (i = 0; i < 3u * rows; ++i)
                    in[i] = rep & 4u ? (int16_t)((i & 1u) ? -32768 : 32767) : (int16_t)(next() & 0xFFFFu);
                for (i = 0; i < 3u * n_out; ++i)
                    w[i] = (int8_t)(next() & 0xFFu);
                for (i = 0; i < n_out; ++i)
                {
                    b[i] = (int32_t)(next() % 2000001u) - 1000000;
                    mult[i] = (int32_t)(((uint32_t)1 << 30) | (next() & 0x3FFFFFFFu));
                    shift[i] = (uint8_t)(20u + next() % 43u); /* 20..62: both paths and both sides of 32 */
                }
                lidet__nn_acc_s16(in, rows, 3u, w, b, n_out, acc);
                lidet__nn_requant_s8(acc, rows, n_out, mult, shift, zp, lo, ref8);
                memset(out, 0x5A, sizeof out);
                lidet__nn_acc_s16_3_requant(in, rows, w, b, n_out, mult, shift, zp, lo, out);
                TEST_ASSERT_EQUAL_INT8_ARRAY(ref8, out, rows * n_out);
            }
}

/* the list kernel past 16-bit weight offsets (n_in n_out > 65536: it hands the layer on) and up to them */
static void test_list_kernel_on_large_layers(void)
{
    static int8_t in[9 * 300], w[300 * 224];
    static int32_t b[256], b_list[256], ref[9 * 256], got[9 * 256], vmax[256], refmax[256];
    static const uint32_t shapes[][2] = {{300u, 224u}, {256u, 256u}, {257u, 255u}};
    uint32_t k, rows, r, i, o;
    for (k = 0; k < sizeof shapes / sizeof shapes[0]; ++k)
        for (rows = 1; rows <= 9u; rows += 4u)
        {
            const uint32_t n_in = shapes[k][0], n_out = shapes[k][1];
            for (i = 0; i < rows * n_in; ++i)
                in[i] = next() % 2u ? (int8_t)-128 : (int8_t)(next() & 0xFFu);
            for (i = 0; i < n_in * n_out; ++i)
                w[i] = (int8_t)(next() & 0xFFu);
            for (o = 0; o < n_out; ++o)
                b[o] = (int32_t)(next() % 2000001u) - 1000000;
            ref_acc(in, rows, n_in, w, b, n_out, ref);
            memset(got, 0x5A, sizeof got);
            lidet__nn_acc_s8_list(in, rows, n_in, w, b, 0, n_out, got);
            TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
            list_bias_of(w, n_in, b, n_out, b_list);
            memset(got, 0x5A, sizeof got);
            lidet__nn_acc_s8_list(in, rows, n_in, w, b, b_list, n_out, got);
            TEST_ASSERT_EQUAL_INT32_ARRAY(ref, got, rows * n_out);
            /* folded into a maximum: 3 lists a row (n_in > 128), or declined past 16-bit offsets */
            for (o = 0; o < n_out; ++o)
            {
                vmax[o] = refmax[o] = INT32_MIN;
                for (r = 0; r < rows; ++r)
                    refmax[o] = ref[r * n_out + o] > refmax[o] ? ref[r * n_out + o] : refmax[o];
            }
            if (lidet__nn_acc_s8_list_max(in, rows, n_in, w, b, b_list, n_out, got, vmax))
                TEST_ASSERT_EQUAL_INT32_ARRAY(refmax, vmax, n_out);
            else
                TEST_ASSERT_TRUE(rows < 4u || n_in * n_out > 65536u);
        }
}

static void test_kernels_agree_at_the_extremes(void)
{
    check_shape(8, 136, MAX_O, 1);
    check_shape(8, MAX_I, MAX_O, 1);
    check_shape(9, 64, 33, 1);
}

/* the requantization's fast paths (shift > 32, = 32) against the plain int64 rule, on every shift and the
 * accumulators' extremes: round_half_up(acc * m / 2^s), then zp and the clamp (int8) or the int32 saturation */
static void test_requant_equals_the_int64_rule(void)
{
    enum
    {
        N = 64
    };
    static const int32_t edge[] = {0, 1, -1, 2, -2, INT32_MAX, INT32_MIN, INT32_MAX - 1, INT32_MIN + 1,
                                   1 << 30, -(1 << 30), 12345, -12345, 1 << 20, -(1 << 20), 65535};
    int32_t acc[N], mult[N], q16[N];
    uint8_t shift[N];
    int8_t out[N], out_c[N];
    uint32_t s, k, rep;
    for (rep = 0; rep < 40u; ++rep)
    {
        for (s = 1; s <= 62u; ++s)
        {
            for (k = 0; k < N; ++k)
            {
                acc[k] = k < sizeof edge / sizeof edge[0] ? edge[k] : (int32_t)next();
                mult[k] = (int32_t)(((uint32_t)1 << 30) | (next() & 0x3FFFFFFFu)); /* [2^30, 2^31) */
                if (k == N - 1u)
                    mult[k] = INT32_MAX;
                shift[k] = (uint8_t)s;
            }
            lidet__nn_requant_s8(acc, 1u, N, mult, shift, -128, -128, out);
            lidet__nn_requant_s8_by_channel(acc, 1u, N, mult, shift, -128, -128, out_c);
            lidet__nn_requant_q16(acc, N, mult, shift, q16);
            for (k = 0; k < N; ++k)
            {
                const int64_t v = ((int64_t)acc[k] * mult[k] + ((int64_t)1 << (s - 1u))) >> s;
                const int64_t y = v - 128 < -128 ? -128 : (v - 128 > 127 ? 127 : v - 128);
                const int64_t z = v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : v);
                TEST_ASSERT_EQUAL_INT32((int32_t)y, out[k]);
                TEST_ASSERT_EQUAL_INT32((int32_t)y, out_c[k]);
                TEST_ASSERT_EQUAL_INT32((int32_t)z, q16[k]);
            }
        }
    }
}

/* both requantization loops on several rows, mixed shifts per channel, other zero points and lower bounds */
static void test_requant_rows_and_channels_agree(void)
{
    enum
    {
        R = 7,
        N = 40
    };
    int32_t acc[R * N], mult[N];
    uint8_t shift[N];
    int8_t a[R * N], b[R * N];
    uint32_t rep, k, n_rows, n_out;
    for (rep = 0; rep < 2000u; ++rep)
    {
        const int32_t zp = (int32_t)(next() % 256u) - 128, lo = -128 + (int32_t)(next() % 64u);
        n_rows = 1u + next() % R;
        n_out = 1u + next() % N;
        for (k = 0; k < n_out; ++k)
        {
            mult[k] = (int32_t)(((uint32_t)1 << 30) | (next() & 0x3FFFFFFFu));
            shift[k] = (uint8_t)(1u + next() % 62u);
        }
        for (k = 0; k < n_rows * n_out; ++k)
        {
            acc[k] = (int32_t)next() >> (next() % 24u);
        }
        lidet__nn_requant_s8(acc, n_rows, n_out, mult, shift, zp, lo, a);
        lidet__nn_requant_s8_by_channel(acc, n_rows, n_out, mult, shift, zp, lo, b);
        for (k = 0; k < n_rows * n_out; ++k)
        {
            const uint32_t o = k % n_out, sh = shift[o];
            const int64_t v = (((int64_t)acc[k] * mult[o] + ((int64_t)1 << (sh - 1u))) >> sh) + zp;
            const int64_t y = v < lo ? lo : (v > 127 ? 127 : v);
            TEST_ASSERT_EQUAL_INT32((int32_t)y, a[k]);
            TEST_ASSERT_EQUAL_INT32((int32_t)y, b[k]);
        }
    }
}

/* the int16 first layer (both loop orders) and the max over the points against a plain reference, on every small
 * shape (3 inputs: the special case) and int16 inputs at their limits */
static void test_s16_layer_and_max_agree(void)
{
    enum
    {
        R = 9,
        I = 8,
        O = 40
    };
    static int16_t in[R * I];
    static int8_t w[I * O];
    static int32_t b[O], ref[R * O], a1[R * O], a2[R * O], m_ref[O], m1[O];
    uint32_t rows, n_in, n_out, r, i, o, rep;
    for (rep = 0; rep < 3u; ++rep)
        for (rows = 1; rows <= R; ++rows)
            for (n_in = 1; n_in <= I; ++n_in)
                for (n_out = 1; n_out <= O; n_out += 3u)
                {
                    for (i = 0; i < rows * n_in; ++i)
                        in[i] = rep == 2u ? (int16_t)((i & 1u) ? -32768 : 32767) : (int16_t)(next() & 0xFFFFu);
                    for (i = 0; i < n_in * n_out; ++i)
                        w[i] = rep == 2u ? (int8_t)-128 : (int8_t)(next() & 0xFFu);
                    for (o = 0; o < n_out; ++o)
                    {
                        b[o] = (int32_t)(next() % 2000001u) - 1000000;
                        m_ref[o] = m1[o] = (int32_t)(next() % 2000001u) - 1000000; /* running maxima */
                    }
                    for (r = 0; r < rows; ++r)
                        for (o = 0; o < n_out; ++o)
                        {
                            int32_t s = b[o];
                            for (i = 0; i < n_in; ++i)
                                s += (int32_t)in[r * n_in + i] * (int32_t)w[i * n_out + o];
                            ref[r * n_out + o] = s;
                            m_ref[o] = s > m_ref[o] ? s : m_ref[o];
                        }
                    memset(a1, 0x5A, sizeof a1);
                    memset(a2, 0x5A, sizeof a2);
                    lidet__nn_acc_s16(in, rows, n_in, w, b, n_out, a1);
                    lidet__nn_acc_s16_by_out(in, rows, n_in, w, b, n_out, a2);
                    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, a1, rows * n_out);
                    TEST_ASSERT_EQUAL_INT32_ARRAY(ref, a2, rows * n_out);
                    lidet__nn_max_rows_s32(ref, rows, n_out, m1);
                    TEST_ASSERT_EQUAL_INT32_ARRAY(m_ref, m1, n_out);
                }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_split_multiplies_are_exact);
    RUN_TEST(test_rotation_split_is_exact);
    RUN_TEST(test_sine_interpolation_split_is_exact);
    RUN_TEST(test_kernels_agree_on_every_shape);
    RUN_TEST(test_packed_kernel_on_multiples_of_4);
    RUN_TEST(test_fused_pass_equals_acc_then_requant_or_max);
    RUN_TEST(test_first_layer_in_one_pass);
    RUN_TEST(test_kernels_agree_at_the_extremes);
    RUN_TEST(test_list_kernel_on_large_layers);
    RUN_TEST(test_requant_equals_the_int64_rule);
    RUN_TEST(test_requant_rows_and_channels_agree);
    RUN_TEST(test_s16_layer_and_max_agree);
    return UNITY_END();
}
