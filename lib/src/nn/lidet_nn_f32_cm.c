/* SPDX-License-Identifier: MIT */
/* The float dense kernel and the max-pool over points (internal/lidet_nn.h) on Cortex-M cores with a single-precision
 * FPU (Armv7E-M: Cortex-M4F, Cortex-M7; GCC or clang). Compiled where LIDET_NN_F32_CM is 1 (internal/lidet_nn.h:
 * __ARM_ARCH_7EM__ with __ARM_FP, no x86 FMA or NEON kernel); an empty unit elsewhere. The portable kernels
 * (lidet_nn_f32.c) stay, as lidet__nn_dense_f32_portable and lidet__nn_max_rows_f32_portable: the unfused kernel's and
 * the max-pool's fallback for widths that are not a multiple of 8, and the tests' oracle. Two arithmetics, chosen by
 * lidet_opt.h's LIDET_NN_CM_FMA:
 *
 * - 0 (the default): exactly the portable kernel's. Each output is o = b, then o = o + t per group of four inputs,
 *   t = ((x[i] w[i] + x[i+1] w[i+1]) + x[i+2] w[i+2]) + x[i+3] w[i+3], each product and each sum rounded (VMUL, VADD;
 *   never VFMA); then o = o + x[i] w[i] for the last n_in % 4 inputs; then the ReLU (v > 0 ? v : +0, so NaN and -0
 *   give +0). Per 8 outputs and a group of c = 1..4 inputs: one VLDM per weight row fetches 8 weights, 8 VMUL (the
 *   first input) and 8 VMUL + 8 VADD per further input form the group sums t in s0-s7, one VLDM fetches the 8
 *   running sums (from the bias at the row's first group), 8 VADD, the ReLU at the row's last nonzero group only,
 *   one VSTM: 4 + 17 c instructions, 2.3-2.6 per multiply-add kept.
 * - 1 (where the target has VFMA): the contract of the x86-64 FMA kernel (lidet_nn_f32_x86.c) and the aarch64 NEON
 *   one: o = b, then o = fma(in[i], w[i], o) for i = 0 .. n_in - 1 in order (one rounding per multiply-add), then
 *   the ReLU; so the image's dense layers give the bits of an x86-64 host with FMA. Per 8 outputs and c = 1..4
 *   inputs (the next four, in order): one VLDM of the running sums, per input one VLDM of 8 weights and 8 VFMA, the
 *   ReLU at the row's last sweep, one VSTM: 4 + 9 c instructions, 1.25 per multiply-add at c = 4; widths that are
 *   not a multiple of 8 (the heads' 3 and 39 outputs) take the same chain one output at a time (fmaf: VFMA.F32).
 *   Fewer instructions, not always fewer cycles: the Cortex-M4 TRM prices VFMA at 3 cycles against 1 each for VMUL
 *   and VADD, so on an M4F the fused sweep of four inputs takes about 153 cycles against 121 (zero wait states,
 *   VLDM/VSTM 1 + 8), while the Cortex-M7's FPU issues a VFMA per cycle. Hence 0 by default and 1 for the M7 images
 *   (ports/firmware/CMakeLists.txt); docs/journal/firmware.md has the figures.
 *
 * Zero inputs are skipped in layers with a ReLU, with either arithmetic. A zero input times a finite weight (the
 * models' weights are finite) is a zero; v + (+-0) = v and fma(+-0, w, v) = v for every v but a zero, and a zero
 * plus a zero is a zero. So dropping the zero products leaves each partial sum the same value or a zero of the other
 * sign, the next nonzero term rounds the same onto either zero, and the ReLU maps both zeros to +0: the outputs are
 * the unskipped kernel's bit for bit. Layers without a ReLU keep every product (their outputs could differ in the
 * sign of a zero). The PointNets' hidden activations are 42-50 % zeros on the VLP-16 sample scan.
 *
 * The max-pool keeps 8 columns in s0-s7 over the rows: 4.5 instructions per value against 9. */
#include "internal/lidet_nn.h"

#if LIDET_NN_F32_CM
#include <math.h>

#include "internal/lidet_nn_skip.h"

#if LIDET_NN_CM_FMA && defined(__ARM_FEATURE_FMA)
#define LIDET__NN_CM_FUSED 1
#else
#define LIDET__NN_CM_FUSED 0
#endif

/* the ReLU of one sum: +0 (the register z) where !(v > 0): negative, -0, +0, NaN (unordered: le holds) */
#define CM_RELU1(r)                                                                                          \
    "vcmpe.f32 " r ", #0\n\t"                                                                                \
    "vmrs APSR_nzcv, fpscr\n\t"                                                                              \
    "it le\n\t"                                                                                              \
    "vmovle.f32 " r ", %[z]\n\t"
#define CM_CLOBBER                                                                                           \
    "s0", "s1", "s2", "s3", "s4", "s5", "s6", "s7", "s8", "s9", "s10", "s11", "s12", "s13", "s14", "s15",    \
        "cc", "memory"

#if LIDET__NN_CM_FUSED
/* o = o + x * w for 8 outputs: the running sums in s0-s7, the weights of input x fetched into s8-s15 */
#define CM_FMA8(wp, x)                                                                                       \
    "vldmia %[" wp "]!, {s8-s15}\n\t"                                                                        \
    "vfma.f32 s0, %[" x "], s8\n\t"                                                                          \
    "vfma.f32 s1, %[" x "], s9\n\t"                                                                          \
    "vfma.f32 s2, %[" x "], s10\n\t"                                                                         \
    "vfma.f32 s3, %[" x "], s11\n\t"                                                                         \
    "vfma.f32 s4, %[" x "], s12\n\t"                                                                         \
    "vfma.f32 s5, %[" x "], s13\n\t"                                                                         \
    "vfma.f32 s6, %[" x "], s14\n\t"                                                                         \
    "vfma.f32 s7, %[" x "], s15\n\t"
/* the running sums from src (the bias, or the row itself) into s0-s7 */
#define CM_LOAD8 "1:\n\tvldmia %[src]!, {s0-s7}\n\t"
#define CM_RELU8                                                                                             \
    CM_RELU1("s0")                                                                                           \
    CM_RELU1("s1")                                                                                           \
    CM_RELU1("s2") CM_RELU1("s3") CM_RELU1("s4") CM_RELU1("s5") CM_RELU1("s6") CM_RELU1("s7")
/* the sums to dst, next 8 outputs */
#define CM_STORE8                                                                                            \
    "vstmia %[dst]!, {s0-s7}\n\t"                                                                            \
    "subs %[n], %[n], #1\n\t"                                                                                \
    "bne 1b\n\t"
/* the products of c = 1..4 inputs: weights of input j from w<j> */
#define CM_G1 CM_LOAD8 CM_FMA8("w0", "x0")
#define CM_G2 CM_G1 CM_FMA8("w1", "x1")
#define CM_G3 CM_G2 CM_FMA8("w2", "x2")
#define CM_G4 CM_G3 CM_FMA8("w3", "x3")
/* one sweep: the running sums, the products added in order, the ReLU where relu, stored; operands named w0..,
 * x0.., src, dst, n, z */
#define CM_SWEEP(G, OUTS, INS)                                                                               \
    do                                                                                                       \
    {                                                                                                        \
        if (relu)                                                                                            \
        {                                                                                                    \
            __asm__ volatile(G CM_RELU8 CM_STORE8:OUTS : INS, [z] "t"(zero) : CM_CLOBBER);                   \
        }                                                                                                    \
        else                                                                                                 \
        {                                                                                                    \
            __asm__ volatile(G CM_STORE8:OUTS:INS : CM_CLOBBER);                                             \
        }                                                                                                    \
    } while (0)

#else /* the portable kernel's arithmetic */
/* the group sums of the first remaining input: t = x * w for 8 outputs (weights in s8-s15) */
#define CM_MUL8(x)                                                                                           \
    "vmul.f32 s0, %[" x "], s8\n\t"                                                                          \
    "vmul.f32 s1, %[" x "], s9\n\t"                                                                          \
    "vmul.f32 s2, %[" x "], s10\n\t"                                                                         \
    "vmul.f32 s3, %[" x "], s11\n\t"                                                                         \
    "vmul.f32 s4, %[" x "], s12\n\t"                                                                         \
    "vmul.f32 s5, %[" x "], s13\n\t"                                                                         \
    "vmul.f32 s6, %[" x "], s14\n\t"                                                                         \
    "vmul.f32 s7, %[" x "], s15\n\t"
/* a further input: t = t + x * w (the product rounded, then the sum) */
#define CM_MAC8(x)                                                                                           \
    "vmul.f32 s8, %[" x "], s8\n\t"                                                                          \
    "vadd.f32 s0, s0, s8\n\t"                                                                                \
    "vmul.f32 s9, %[" x "], s9\n\t"                                                                          \
    "vadd.f32 s1, s1, s9\n\t"                                                                                \
    "vmul.f32 s10, %[" x "], s10\n\t"                                                                        \
    "vadd.f32 s2, s2, s10\n\t"                                                                               \
    "vmul.f32 s11, %[" x "], s11\n\t"                                                                        \
    "vadd.f32 s3, s3, s11\n\t"                                                                               \
    "vmul.f32 s12, %[" x "], s12\n\t"                                                                        \
    "vadd.f32 s4, s4, s12\n\t"                                                                               \
    "vmul.f32 s13, %[" x "], s13\n\t"                                                                        \
    "vadd.f32 s5, s5, s13\n\t"                                                                               \
    "vmul.f32 s14, %[" x "], s14\n\t"                                                                        \
    "vadd.f32 s6, s6, s14\n\t"                                                                               \
    "vmul.f32 s15, %[" x "], s15\n\t"                                                                        \
    "vadd.f32 s7, s7, s15\n\t"
/* o = o + t: the running sums from src (the bias, or the row itself) into s8-s15 */
#define CM_ACC8                                                                                              \
    "vldmia %[src]!, {s8-s15}\n\t"                                                                           \
    "vadd.f32 s8, s8, s0\n\t"                                                                                \
    "vadd.f32 s9, s9, s1\n\t"                                                                                \
    "vadd.f32 s10, s10, s2\n\t"                                                                              \
    "vadd.f32 s11, s11, s3\n\t"                                                                              \
    "vadd.f32 s12, s12, s4\n\t"                                                                              \
    "vadd.f32 s13, s13, s5\n\t"                                                                              \
    "vadd.f32 s14, s14, s6\n\t"                                                                              \
    "vadd.f32 s15, s15, s7\n\t"
#define CM_RELU8                                                                                             \
    CM_RELU1("s8")                                                                                           \
    CM_RELU1("s9")                                                                                           \
    CM_RELU1("s10") CM_RELU1("s11") CM_RELU1("s12") CM_RELU1("s13") CM_RELU1("s14") CM_RELU1("s15")
/* the sums to dst, next 8 outputs */
#define CM_STORE8                                                                                            \
    "vstmia %[dst]!, {s8-s15}\n\t"                                                                           \
    "subs %[n], %[n], #1\n\t"                                                                                \
    "bne 1b\n\t"
/* the group sums of c = 1..4 inputs: weights of input j from w<j> */
#define CM_G1 "1:\n\tvldmia %[w0]!, {s8-s15}\n\t" CM_MUL8("x0")
#define CM_G2 CM_G1 "vldmia %[w1]!, {s8-s15}\n\t" CM_MAC8("x1")
#define CM_G3 CM_G2 "vldmia %[w2]!, {s8-s15}\n\t" CM_MAC8("x2")
#define CM_G4 CM_G3 "vldmia %[w3]!, {s8-s15}\n\t" CM_MAC8("x3")
/* one sweep: the group sums, o = o + t, the ReLU where relu, stored; operands named w0.., x0.., src, dst, n, z */
#define CM_SWEEP(G, OUTS, INS)                                                                               \
    do                                                                                                       \
    {                                                                                                        \
        if (relu)                                                                                            \
        {                                                                                                    \
            __asm__ volatile(G CM_ACC8 CM_RELU8 CM_STORE8:OUTS : INS, [z] "t"(zero) : CM_CLOBBER);           \
        }                                                                                                    \
        else                                                                                                 \
        {                                                                                                    \
            __asm__ volatile(G CM_ACC8 CM_STORE8:OUTS:INS : CM_CLOBBER);                                     \
        }                                                                                                    \
    } while (0)

#endif

/* an operand list through a macro argument */
#define CM_ARGS(...) __VA_ARGS__

/* one sweep of 8 n8 outputs by c = 1..4 inputs (x[j], weight rows w[j]; j < c) from the running sums src into
 * dst: fused, dst[k] = fma(x[c-1], w[c-1][k], ... fma(x[0], w[0][k], src[k])); unfused, dst[k] = src[k] + the
 * group sum of the products; then the ReLU where relu */
static void sweep(uint32_t c, const float *const *w, const float *x, const float *src, float *dst,
                  uint32_t n8, int relu)
{
    const float zero = 0.0f;
    const float *w0 = w[0], *w1, *w2, *w3;
    const float x0 = x[0];
    float x1, x2, x3;
    if (c == 1u)
    {
        CM_SWEEP(CM_G1, CM_ARGS([w0] "+r"(w0), [src] "+r"(src), [dst] "+r"(dst), [n] "+r"(n8)),
                 CM_ARGS([x0] "t"(x0)));
        return;
    }
    w1 = w[1];
    x1 = x[1];
    if (c == 2u)
    {
        CM_SWEEP(CM_G2, CM_ARGS([w0] "+r"(w0), [w1] "+r"(w1), [src] "+r"(src), [dst] "+r"(dst), [n] "+r"(n8)),
                 CM_ARGS([x0] "t"(x0), [x1] "t"(x1)));
        return;
    }
    w2 = w[2];
    x2 = x[2];
    if (c == 3u)
    {
        CM_SWEEP(CM_G3,
                 CM_ARGS([w0] "+r"(w0), [w1] "+r"(w1), [w2] "+r"(w2), [src] "+r"(src), [dst] "+r"(dst),
                         [n] "+r"(n8)),
                 CM_ARGS([x0] "t"(x0), [x1] "t"(x1), [x2] "t"(x2)));
        return;
    }
    w3 = w[3];
    x3 = x[3];
    CM_SWEEP(CM_G4,
             CM_ARGS([w0] "+r"(w0), [w1] "+r"(w1), [w2] "+r"(w2), [w3] "+r"(w3), [src] "+r"(src),
                     [dst] "+r"(dst), [n] "+r"(n8)),
             CM_ARGS([x0] "t"(x0), [x1] "t"(x1), [x2] "t"(x2), [x3] "t"(x3)));
}

#if LIDET__NN_CM_FUSED
/* the same chain one output at a time (widths that are not a multiple of 8); fmaf is VFMA.F32 on these cores */
static void dense_fma_rows(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                           uint32_t n_out, int relu, float *out)
{
    uint32_t r, i, k;
    for (r = 0; r < n_rows; ++r)
    {
        const float *x = in + (uint32_t)r * n_in;
        float *o = out + (uint32_t)r * n_out;
        for (k = 0; k < n_out; ++k)
        {
            float v = b[k];
            for (i = 0; i < n_in; ++i)
            {
                v = fmaf(x[i], w_t[(uint32_t)i * n_out + k], v);
            }
            o[k] = relu && !(v > 0.0f) ? 0.0f : v;
        }
    }
}

#endif

void lidet__nn_dense_f32(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                         uint32_t n_out, int relu, float *out)
{
    const uint32_t n8 = n_out / 8u, n4 = n_in & ~3u;
    uint32_t r, i, k;
    if (n8 == 0u || (n_out & 7u) != 0u)
    {
#if LIDET__NN_CM_FUSED
        dense_fma_rows(in, n_rows, n_in, w_t, b, n_out, relu, out);
#else
        lidet__nn_dense_f32_portable(in, n_rows, n_in, w_t, b, n_out, relu, out);
#endif
        return;
    }
    for (r = 0; r < n_rows; ++r)
    {
        const float *x = in + (uint32_t)r * n_in;
        float *o = out + (uint32_t)r * n_out;
        const float *src = b;
        const float *wp[4];
        float xv[4];
        /* past the last nonzero input nothing is added: the ReLU goes with the last sweep */
        const uint32_t last = lidet__nn_inputs_used(x, n_in, relu);
        /* fused: the next four inputs, in order; unfused: the portable kernel's groups of four, then the last
         * n_in % 4 inputs one by one (each a group of one); in a ReLU layer only the nonzero inputs */
        for (i = 0; i < last;)
        {
            const uint32_t end = LIDET__NN_CM_FUSED ? last : i < n4 ? i + 4u : i + 1u;
            const float *w = w_t + (uint32_t)i * n_out;
            uint32_t c = 0;
            for (; i < end && (!LIDET__NN_CM_FUSED || c < 4u); ++i, w += n_out)
            {
                const float v = x[i];
                if (!relu || !lidet__nn_is_zero(v))
                {
                    wp[c] = w;
                    xv[c] = v;
                    ++c;
                }
            }
            if (c != 0u)
            {
                sweep(c, wp, xv, src, o, n8, relu && i >= last);
                src = o;
            }
        }
        if (src == b)
        {
            /* no input, or every input zero: the bias */
            for (k = 0; k < n_out; ++k)
            {
                o[k] = relu && !(b[k] > 0.0f) ? 0.0f : b[k];
            }
        }
    }
}

/* the running maximum of one column: m = x where x > m (false for NaN: m stays) */
#define CM_MAXSEL(m, x)                                                                                      \
    "vcmp.f32 " x ", " m "\n\t"                                                                              \
    "vmrs APSR_nzcv, fpscr\n\t"                                                                              \
    "it gt\n\t"                                                                                              \
    "vmovgt.f32 " m ", " x "\n\t"
/* vmax[k] = max(vmax[k], in[r n + k]) (lidet_nn_f32.c's comparison, x > vmax ? x : vmax): 8 columns in s0-s7 over
 * all the rows, one VLDM per row; 4.5 instructions per value against the portable loop's 9 */
void lidet__nn_max_rows_f32(const float *in, uint32_t n_rows, uint32_t n, float *vmax)
{
    uint32_t k;
    if (n_rows == 0u || n == 0u || (n & 7u) != 0u)
    {
        lidet__nn_max_rows_f32_portable(in, n_rows, n, vmax);
        return;
    }
    for (k = 0; k < n; k += 8u)
    {
        const float *x = in + k;
        float *v = vmax + k;
        uint32_t m = n_rows;
        const uint32_t stride = n * (uint32_t)sizeof(float);
        __asm__ volatile("vldmia %[v], {s0-s7}\n\t"
                         "1:\n\t"
                         "vldmia %[x], {s8-s15}\n\t"
                         "add %[x], %[x], %[stride]\n\t" CM_MAXSEL("s0", "s8") CM_MAXSEL("s1", "s9")
                             CM_MAXSEL("s2", "s10") CM_MAXSEL("s3", "s11") CM_MAXSEL("s4", "s12")
                                 CM_MAXSEL("s5", "s13") CM_MAXSEL("s6", "s14")
                                     CM_MAXSEL("s7", "s15") "subs %[m], %[m], #1\n\t"
                                                            "bne 1b\n\t"
                                                            "vstmia %[v], {s0-s7}\n\t"
                         : [x] "+r"(x), [m] "+r"(m)
                         : [v] "r"(v), [stride] "r"(stride)
                         : CM_CLOBBER);
    }
}

#else
typedef int lidet__nn_f32_cm_empty; /* ISO C: a translation unit holds at least one declaration */
#endif
