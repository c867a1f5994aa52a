/* SPDX-License-Identifier: MIT */
/* The float dense kernel lidet__nn_dense_f32 as this build links it: the portable kernel (lib/src/nn/lidet_nn_f32.c),
 * on x86-64 hosts with FMA the register-tiled one (lidet_nn_f32_x86.c, 8 x 32 / 4 x 16 tiles and their tails), on
 * aarch64 the NEON one (lidet_nn_f32_neon.c, 8 x 8 / 8 x 4 tiles, single rows by 16, 4, 2, 1).
 * On every shape (rows, inputs and outputs around the tile and vector widths) the result is within float rounding of
 * a double loop, and bit for bit one of the two stated arithmetics, the same one for every shape:
 *   portable: o = b, then o += x[i] w[i] + x[i+1] w[i+1] + x[i+2] w[i+2] + x[i+3] w[i+3] per four inputs (left to
 *             right), then o += x[i] w[i] for the rest;
 *   fused:    o = b, then o = fmaf(x[i], w[i], o) for every input in order.
 * ReLU maps NaN and -0 to +0 in both. The kernels with fused multiply-adds (x86-64 FMA, aarch64 NEON) are also
 * compared with the portable kernel itself on the layer shapes of the shipped models, and on NaN and -0 inputs. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal/lidet_nn.h"
#include "test_util.h"

/* the RISC-V F kernel (lib/src/nn/lidet_nn_f32_rv.c: chunks of 64 inputs, 16 / 8 / 1 outputs a sweep, the zero inputs
 * of ReLU layers skipped) is plain C with fmaf: compiled here for the host as rv_dense_host, so that every host checks
 * its logic bit for bit against the fused arithmetic */
#define NN_F32_RV_HOST_TEST 1
#define lidet__nn_dense_f32 rv_dense_host
#include "../../lib/src/nn/lidet_nn_f32_rv.c"
#undef lidet__nn_dense_f32
void rv_dense_host(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                   uint32_t n_out, int relu, float *out);

#define MAX_R 17
#define MAX_I 200
#define MAX_O 160

static uint32_t g_rng = 987654321u;

static float next_f(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return (float)(int32_t)(g_rng % 20001u - 10000) / 4096.0f; /* [-2.44, 2.44], many bits */
}

void setUp(void)
{
}

void tearDown(void)
{
}

static float portable_one(const float *x, uint32_t n_in, const float *w_t, uint32_t n_out, uint32_t o,
                          float b)
{
    float s = b;
    uint32_t i = 0;
    for (; i + 4u <= n_in; i += 4u)
    {
        s += x[i] * w_t[i * n_out + o] + x[i + 1u] * w_t[(i + 1u) * n_out + o] +
             x[i + 2u] * w_t[(i + 2u) * n_out + o] + x[i + 3u] * w_t[(i + 3u) * n_out + o];
    }
    for (; i < n_in; ++i)
    {
        s += x[i] * w_t[i * n_out + o];
    }
    return s;
}

static float fused_one(const float *x, uint32_t n_in, const float *w_t, uint32_t n_out, uint32_t o, float b)
{
    float s = b;
    uint32_t i;
    for (i = 0; i < n_in; ++i)
    {
        s = fmaf(x[i], w_t[i * n_out + o], s);
    }
    return s;
}

static float relu_of(float v, int relu)
{
    return relu && !(v > 0.0f) ? 0.0f : v;
}

static int g_kind = -1; /* 0 portable, 1 fused: fixed by the first shape whose two arithmetics differ */
static uint32_t g_shapes, g_decisive;

typedef void dense_fn_t(const float *, uint32_t, uint32_t, const float *, const float *, uint32_t, int,
                        float *);

/* fn on one shape; want: -1 either arithmetic (the same for every shape), else 0 portable / 1 fused */
static void check_shape(dense_fn_t *fn, int want, uint32_t rows, uint32_t n_in, uint32_t n_out, int relu)
{
    static float in[MAX_R * MAX_I], w[MAX_I * MAX_O], b[MAX_O], out[MAX_R * MAX_O + 1];
    uint32_t r, i, o, k, same_p = 1, same_f = 1, differ = 0;
    for (k = 0; k < rows * n_in; ++k)
        in[k] = next_f();
    for (k = 0; k < n_in * n_out; ++k)
        w[k] = next_f();
    for (k = 0; k < n_out; ++k)
        b[k] = next_f();
    out[rows * n_out] = 12345.0f; /* a guard: nothing is written past the rows */
    fn(in, rows, n_in, w, b, n_out, relu, out);
    TEST_ASSERT_EQUAL_FLOAT(12345.0f, out[rows * n_out]);
    for (r = 0; r < rows; ++r)
    {
        for (o = 0; o < n_out; ++o)
        {
            const float *x = in + r * n_in;
            const float got = out[r * n_out + o];
            const float p = relu_of(portable_one(x, n_in, w, n_out, o, b[o]), relu);
            const float f = relu_of(fused_one(x, n_in, w, n_out, o, b[o]), relu);
            double s = b[o], mag = fabs((double)b[o]);
            for (i = 0; i < n_in; ++i)
            {
                s += (double)x[i] * (double)w[i * n_out + o];
                mag += fabs((double)x[i] * (double)w[i * n_out + o]);
            }
            s = relu && s < 0.0 ? 0.0 : s;
            /* float rounding: n_in + 1 roundings of at most half an ulp of the running magnitude each */
            TEST_ASSERT_TRUE_MESSAGE(fabs((double)got - s) <= 1.2e-7 * (double)(n_in + 2u) * mag + 1e-30,
                                     "far from the double loop");
            same_p &= memcmp(&got, &p, sizeof got) == 0;
            same_f &= memcmp(&got, &f, sizeof got) == 0;
            differ |= memcmp(&p, &f, sizeof p) != 0;
        }
    }
    ++g_shapes;
    TEST_ASSERT_TRUE_MESSAGE(same_p || same_f, "neither the portable nor the fused arithmetic, bit for bit");
    if (differ)
    {
        const int kind = same_f ? 1 : 0;
        ++g_decisive;
        if (want >= 0)
        {
            TEST_ASSERT_EQUAL_INT_MESSAGE(want, kind, "not the stated arithmetic");
            return;
        }
        if (g_kind < 0)
            g_kind = kind;
        TEST_ASSERT_EQUAL_INT_MESSAGE(g_kind, kind, "the kernel switched arithmetic between shapes");
    }
}

static const uint32_t k_rows[] = {1, 2, 3, 4, 5, 7, 8, 9, 12, 13, 16, 17};
static const uint32_t k_ins[] = {1, 3, 4, 5, 8, 17, 32, 64, 70};
static const uint32_t k_outs[] = {1, 3, 7, 8, 9, 15, 16, 17, 24, 31, 32, 33, 48, 63, 64, 65, 96, 128, 133};

static void every_shape(dense_fn_t *fn, int want)
{
    uint32_t a, c, d;
    g_shapes = g_decisive = 0;
    for (a = 0; a < sizeof k_rows / sizeof k_rows[0]; ++a)
        for (c = 0; c < sizeof k_ins / sizeof k_ins[0]; ++c)
            for (d = 0; d < sizeof k_outs / sizeof k_outs[0]; ++d)
                check_shape(fn, want, k_rows[a], k_ins[c], k_outs[d], (int)((a + c + d) & 1u));
    TEST_ASSERT_EQUAL_UINT32(12u * 9u * 19u, g_shapes);
    TEST_ASSERT_TRUE(g_decisive > 100u); /* the two arithmetics told apart on many shapes */
}

/* in (rows x n_in, its zeros set by the caller) with row 1 all zeros, fresh weights and biases, through fn: each output
 * the unskipped fused chain's, bit for bit (the kernels that leave zero inputs out) */
static void zero_inputs_fused(dense_fn_t *fn, float *in, uint32_t rows, uint32_t n_in, uint32_t n_out, int relu,
                              const char *msg)
{
    static float w[MAX_I * MAX_O], b[MAX_O], got[MAX_R * MAX_O];
    uint32_t r, o, k;
    if (rows > 2u)
        memset(in + n_in, 0, n_in * sizeof in[0]); /* row 1: no nonzero input at all */
    for (k = 0; k < n_in * n_out; ++k)
        w[k] = next_f();
    for (k = 0; k < n_out; ++k)
        b[k] = next_f();
    fn(in, rows, n_in, w, b, n_out, relu, got);
    for (r = 0; r < rows; ++r)
        for (o = 0; o < n_out; ++o)
        {
            const float want = relu_of(fused_one(in + r * n_in, n_in, w, n_out, o, b[o]), relu);
            TEST_ASSERT_TRUE_MESSAGE(memcmp(&want, &got[r * n_out + o], sizeof want) == 0, msg);
        }
}

/* the RISC-V kernel on every shape: the fused arithmetic bit for bit; then with zero inputs (+0 and -0, a ReLU
 * layer's skipped inputs, whole rows of them too, and runs past a 64-input chunk) against the unskipped chain */
void test_riscv_kernel_on_the_host(void)
{
    static float in[MAX_R * MAX_I];
    uint32_t a, c, d, k, n_zero = 0;
    every_shape(rv_dense_host, 1);
    for (a = 0; a < sizeof k_rows / sizeof k_rows[0]; ++a)
        for (c = 0; c < sizeof k_ins / sizeof k_ins[0]; ++c)
            for (d = 0; d < sizeof k_outs / sizeof k_outs[0]; ++d)
            {
                const uint32_t rows = k_rows[a], n_in = k_ins[c], n_out = k_outs[d];
                const int relu = (int)((a + c + d) & 1u);
                for (k = 0; k < rows * n_in; ++k)
                {
                    const uint32_t u = (g_rng = g_rng * 1664525u + 1013904223u) >> 24;
                    in[k] = u < 96u ? 0.0f : u < 128u ? -0.0f : next_f(); /* half of them zeros */
                    n_zero += u < 128u;
                }
                zero_inputs_fused(rv_dense_host, in, rows, n_in, n_out, relu,
                                  "the RISC-V kernel with zero inputs is not the fused chain");
            }
    TEST_ASSERT_TRUE(n_zero > 10000u);
}

/* the AVX-512 kernel with zero inputs (+0 and -0; inputs that are zero in every row of an 8-row band, which a
 * ReLU layer's band leaves out, and whole rows of them) against the unskipped fused chain, bit for bit */
void test_avx512_zero_inputs(void)
{
#if LIDET_NN_FMA
    static float in[MAX_R * MAX_I];
    uint32_t a, c, d, r, k, i, n_skip = 0;
    if (!__builtin_cpu_supports("avx512f"))
    {
        TEST_IGNORE_MESSAGE("no AVX-512 here");
    }
    for (a = 0; a < sizeof k_rows / sizeof k_rows[0]; ++a)
        for (c = 0; c < sizeof k_ins / sizeof k_ins[0]; ++c)
            for (d = 0; d < sizeof k_outs / sizeof k_outs[0]; ++d)
            {
                const uint32_t rows = k_rows[a], n_in = k_ins[c], n_out = k_outs[d];
                const int relu = (int)((a + c + d) & 1u);
                for (k = 0; k < rows * n_in; ++k)
                {
                    const uint32_t u = (g_rng = g_rng * 1664525u + 1013904223u) >> 24;
                    in[k] = u < 64u ? 0.0f : u < 96u ? -0.0f : next_f();
                }
                for (i = 0; i < n_in; ++i)
                {
                    const uint32_t u = (g_rng = g_rng * 1664525u + 1013904223u) >> 24;
                    if (u < 96u) /* input i zero in every row (+0 or -0 by row) */
                    {
                        for (r = 0; r < rows; ++r)
                            in[r * n_in + i] = ((r + i) & 1u) ? -0.0f : 0.0f;
                        n_skip += rows >= 8u;
                    }
                }
                zero_inputs_fused(lidet__nn_dense_f32_avx512, in, rows, n_in, n_out, relu,
                                  "the AVX-512 kernel with zero inputs is not the fused chain");
            }
    TEST_ASSERT_TRUE(n_skip > 1000u);
#else
    TEST_IGNORE_MESSAGE("no FMA kernels in this build");
#endif
}

void test_every_shape_one_arithmetic(void)
{
    every_shape(lidet__nn_dense_f32, -1);
    printf("this build's float dense kernel: %s (%u of %u shapes tell the two apart)\n",
           g_kind == 1 ? "fused (FMA)" : "portable", (unsigned)g_decisive, (unsigned)g_shapes);
}

/* each variant of the FMA kernel this CPU can run (x86-64) or the NEON kernel (aarch64), and the portable one,
 * called directly */
void test_each_variant(void)
{
#if LIDET_NN_FMA
    every_shape(lidet__nn_dense_f32_portable, 0);
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        every_shape(lidet__nn_dense_f32_avx2fma, 1);
    else
        printf("no AVX2 + FMA here: that variant not run\n");
    if (__builtin_cpu_supports("avx512f"))
        every_shape(lidet__nn_dense_f32_avx512, 1);
    else
        printf("no AVX-512 here: that variant not run\n");
#elif LIDET_NN_NEON
    every_shape(lidet__nn_dense_f32_portable, 0);
    every_shape(lidet__nn_dense_f32, 1); /* the NEON kernel */
    printf("aarch64: the portable and the NEON kernel run\n");
#else
    TEST_IGNORE_MESSAGE(
        "no FMA or NEON kernels in this build (LIDET_NN_FMA / LIDET_NN_NEON off, or another target)");
#endif
}

/* the fused kernel of this build (x86-64 with FMA, aarch64 with NEON) and the portable one, called directly; NULL
 * where the build has no fused kernel */
static dense_fn_t *fused_kernel(void)
{
#if LIDET_NN_FMA
    if (__builtin_cpu_supports("avx512f"))
        return lidet__nn_dense_f32_avx512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        return lidet__nn_dense_f32_avx2fma;
    return 0;
#elif LIDET_NN_NEON
    return lidet__nn_dense_f32;
#else
    return 0;
#endif
}

#if LIDET_NN_FMA || LIDET_NN_NEON
#define PORTABLE_KERNEL lidet__nn_dense_f32_portable
#else
#define PORTABLE_KERNEL lidet__nn_dense_f32
#endif

/* fn and the portable kernel on one shape: each output within the float tolerance of the other (twice the
 * rounding bound of check_shape: each side within one bound of the exact sum) */
static void near_portable(dense_fn_t *fn, uint32_t rows, uint32_t n_in, uint32_t n_out, int relu)
{
    static float in[MAX_R * MAX_I], w[MAX_I * MAX_O], b[MAX_O], got[MAX_R * MAX_O], ref[MAX_R * MAX_O];
    uint32_t r, i, o, k;
    for (k = 0; k < rows * n_in; ++k)
        in[k] = next_f();
    for (k = 0; k < n_in * n_out; ++k)
        w[k] = next_f();
    for (k = 0; k < n_out; ++k)
        b[k] = next_f();
    fn(in, rows, n_in, w, b, n_out, relu, got);
    PORTABLE_KERNEL(in, rows, n_in, w, b, n_out, relu, ref);
    for (r = 0; r < rows; ++r)
    {
        for (o = 0; o < n_out; ++o)
        {
            double mag = fabs((double)b[o]);
            for (i = 0; i < n_in; ++i)
                mag += fabs((double)in[r * n_in + i] * (double)w[i * n_out + o]);
            TEST_ASSERT_TRUE_MESSAGE(fabs((double)got[r * n_out + o] - (double)ref[r * n_out + o]) <=
                                         2.4e-7 * (double)(n_in + 2u) * mag + 1e-30,
                                     "beyond the float tolerance of the portable kernel");
        }
    }
}

/* the layers of the shipped models (weights/: n_in x n_out of the classifiers and box nets of the hdl64, vlp16 and
 * vlp16s families), at the row counts the forward pass uses (LIDET_PN_BLOCK 8, the heads' single vectors) and
 * around them (a short last block, a band plus a row) */
static const uint32_t k_model_layers[][2] = {
    {3, 32},   {32, 64},   {64, 128}, {32, 32}, {160, 64}, {64, 3},  {99, 64}, {3, 48},  {48, 96},
    {96, 160}, {195, 128}, {128, 64}, {64, 39}, {3, 3},    {3, 16},  {16, 32}, {32, 64}, {16, 16},
    {80, 32},  {32, 3},    {51, 32},  {3, 24},  {24, 40},  {40, 64}, {83, 64}, {64, 32}, {32, 39}};
static const uint32_t k_model_rows[] = {1, 3, 7, 8, 9, 16};

void test_model_shapes(void)
{
    dense_fn_t *fused = fused_kernel();
    uint32_t l, r;
    g_shapes = g_decisive = 0;
    for (l = 0; l < sizeof k_model_layers / sizeof k_model_layers[0]; ++l)
    {
        for (r = 0; r < sizeof k_model_rows / sizeof k_model_rows[0]; ++r)
        {
            const int relu = (int)((l + r) & 1u);
            check_shape(lidet__nn_dense_f32, -1, k_model_rows[r], k_model_layers[l][0], k_model_layers[l][1],
                        relu);
            if (fused != 0)
            {
                check_shape(fused, 1, k_model_rows[r], k_model_layers[l][0], k_model_layers[l][1], relu);
                near_portable(fused, k_model_rows[r], k_model_layers[l][0], k_model_layers[l][1], relu);
                near_portable(fused, k_model_rows[r], k_model_layers[l][0], k_model_layers[l][1], !relu);
            }
        }
    }
    if (fused == 0)
        printf("no fused kernel in this build or on this CPU: the model shapes checked on the portable "
               "kernel\n");
}

/* NaN and -0 through every tile and tail of the fused kernel: 10 rows (a band of 8, two single rows) x 31 outputs
 * (band: 3 x 8, 4, 3 row by row; row: 16, 8 as 2 x 4, 2, 1) x 6 inputs (4 by lanes, 2 one by one). Weights
 * positive, so a row of -0 inputs with a -0 bias sums to -0. Without the ReLU each output is the fused chain bit for
 * bit (NaN for NaN); with it, +0 for NaN, -0 and every sum not above 0. */
void test_fused_nan_and_negative_zero(void)
{
    enum
    {
        R = 10,
        I = 6,
        O = 31
    };
    static float in[R * I], w[I * O], b[O], out[R * O + 1];
    dense_fn_t *fused = fused_kernel();
    uint32_t r, i, o, k, n_neg0 = 0, n_nan = 0;
    int relu;
    if (fused == 0)
        TEST_IGNORE_MESSAGE("no fused kernel in this build or on this CPU");
    for (k = 0; k < R * I; ++k)
        in[k] = next_f();
    for (k = 0; k < I * O; ++k)
        w[k] = fabsf(next_f()) + 0.125f;
    for (k = 0; k < O; ++k)
        b[k] = k % 3u == 0u ? -0.0f : next_f();
    in[2u * I + 1u] = NAN; /* the band, an input taken by lane */
    in[8u * I + 5u] = NAN; /* a single row, an input taken one by one */
    for (i = 0; i < I; ++i)
    {
        in[5u * I + i] = -0.0f; /* -0 sums where the bias is -0: in the band, */
        in[9u * I + i] = -0.0f; /* and in a single row */
    }
    for (relu = 0; relu <= 1; ++relu)
    {
        out[R * O] = 12345.0f;
        fused(in, R, I, w, b, O, relu, out);
        TEST_ASSERT_EQUAL_FLOAT(12345.0f, out[R * O]);
        for (r = 0; r < R; ++r)
        {
            for (o = 0; o < O; ++o)
            {
                const float want = fused_one(in + r * I, I, w, O, o, b[o]), got = out[r * O + o];
                if (relu)
                {
                    const float z = 0.0f, rw = want > 0.0f ? want : z;
                    TEST_ASSERT_TRUE_MESSAGE(memcmp(&got, &rw, sizeof got) == 0, "ReLU: not v > 0 ? v : +0");
                }
                else if (want != want)
                {
                    TEST_ASSERT_TRUE_MESSAGE(got != got, "a NaN input did not give NaN");
                    ++n_nan;
                }
                else
                {
                    TEST_ASSERT_TRUE_MESSAGE(memcmp(&got, &want, sizeof got) == 0,
                                             "not the fused chain bit for bit");
                    n_neg0 += want == 0.0f && signbit(want);
                }
            }
        }
    }
    TEST_ASSERT_TRUE(n_nan >= 2u * O);    /* rows 2 and 8 */
    TEST_ASSERT_TRUE(n_neg0 >= 2u * 11u); /* rows 5 and 9 where the bias is -0 */
}

void test_relu_of_nan_and_negative_zero(void)
{
    /* 3 outputs x 8 rows: NaN input, a sum of exactly -0, a positive sum */
    float in[8 * 2], w[2 * 3] = {1.0f, -1.0f, 1.0f, 1.0f, 0.0f, 1.0f}, b[3] = {0.0f, -0.0f, 0.5f}, out[8 * 3];
    uint32_t r;
    for (r = 0; r < 8u; ++r)
    {
        in[2u * r] = r == 3u ? NAN : 0.0f;
        in[2u * r + 1u] = -0.0f;
    }
    lidet__nn_dense_f32(in, 8u, 2u, w, b, 3u, 1, out);
    for (r = 0; r < 8u; ++r)
    {
        TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)signbit(out[3u * r])); /* +0, also from NaN (row 3) */
        TEST_ASSERT_EQUAL_FLOAT(0.0f, out[3u * r]);
        TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)signbit(out[3u * r + 1u])); /* -0 -> +0 */
        if (r != 3u)
            TEST_ASSERT_EQUAL_FLOAT(0.5f, out[3u * r + 2u]);
    }
    lidet__nn_dense_f32(in, 1u, 2u, w, b, 3u, 0, out); /* no ReLU: the sums themselves */
    TEST_ASSERT_EQUAL_FLOAT(0.0f, out[0]);
    TEST_ASSERT_EQUAL_FLOAT(0.5f, out[2]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_every_shape_one_arithmetic);
    RUN_TEST(test_each_variant);
    RUN_TEST(test_riscv_kernel_on_the_host);
    RUN_TEST(test_avx512_zero_inputs);
    RUN_TEST(test_model_shapes);
    RUN_TEST(test_fused_nan_and_negative_zero);
    RUN_TEST(test_relu_of_nan_and_negative_zero);
    return UNITY_END();
}
